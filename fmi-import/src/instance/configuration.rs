//! Configuration Mode (FMI 3.0 section 3.2.2): the structural parameters an FMU was
//! configured with ([`crate::Fmu::configured`]) set between `fmi3EnterConfigurationMode`
//! and `fmi3ExitConfigurationMode`, right after instantiation (and after a reset), before
//! any other value is set: an FMU sizes its arrays when it leaves Configuration Mode.

use super::core::{call, Core};
use super::fmi3::Fmi3;
use crate::error::{Error, Result};

impl Fmi3 {
    /// Enters Configuration Mode, sets the configured structural parameters and leaves it;
    /// nothing when the FMU was configured with none.
    pub(super) fn configure_structural(&mut self, core: &mut Core) -> Result<()> {
        let configuration = self.abi().configuration.clone();
        if configuration.is_empty() {
            return Ok(());
        }
        if core.host.is_some() {
            return Err(Error::Instance {
                name: core.name.clone(),
                reason: "its FMU has structural parameters set, and Configuration Mode is not forwarded to a host process: run it without isolation",
            });
        }
        let enter = core.optional(self.abi().functions.enter_configuration_mode, "fmi3EnterConfigurationMode")?;
        let exit = core.optional(self.abi().functions.exit_configuration_mode, "fmi3ExitConfigurationMode")?;
        let c = core.component;
        call!(core, "fmi3EnterConfigurationMode", None, enter(c))?;
        for (access, value) in configuration {
            self.set_all(core, access, &[value])?;
        }
        call!(core, "fmi3ExitConfigurationMode", None, exit(c))
    }
}
