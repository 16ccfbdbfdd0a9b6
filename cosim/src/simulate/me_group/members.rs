//! The members of a Model Exchange group as the group's loop sees them: each one's
//! instance and integration state, from the lanes of a run or an instance on its own.

use crate::fmu::Instance;
use crate::me::MeUnit;
use crate::simulate::plan::Instances;

/// Access to the members of a group: each one's instance and integration state.
pub(crate) trait Members: Instances {
    /// Member `m` (an instance index of the system), if it has its integration state.
    fn member(&mut self, m: usize) -> Option<(&mut Instance, &mut MeUnit)>;
}

/// One ME instance on its own: the members of its group of one.
pub(crate) struct Solo<'a> {
    pub(crate) inst: &'a mut Instance,
    pub(crate) unit: &'a mut MeUnit,
}

impl Instances for Solo<'_> {
    fn instance(&mut self, _: usize) -> &mut Instance {
        self.inst
    }
}

impl Members for Solo<'_> {
    fn member(&mut self, _: usize) -> Option<(&mut Instance, &mut MeUnit)> {
        Some((&mut *self.inst, &mut *self.unit))
    }
}
