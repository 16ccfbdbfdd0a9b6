//! Whether an FMI 3.0 Co-Simulation FMU is instantiated with `eventModeUsed`: the user's
//! choice ([`EventModeChoice`], `cosim run --event-mode`, fmpy's `use_event_mode`) and the
//! decision taken for one FMU from its description ([`EventMode`]).
//!
//! By default ([`EventModeChoice::Auto`]) Event Mode is used where it is needed only: in an
//! FMU that declares clocks (FMI 3.0 section 4.1.2: "For FMUs that have clocks,
//! `eventModeUsed = fmi3True` is required"; the master drives them, and their clocked
//! variables and connections, in Event Mode). An FMU without clocks instantiated with
//! `eventModeUsed = false` handles its events inside `fmi3DoStep` itself, as fmpy's
//! `simulate_fmu` runs it by default; some FMUs give a worse answer when their events are
//! moved to communication points (Dymola 2025x CoupledClutches with Cvode or Ida).

use crate::clocks::Clock;
use model_description::fmi3::ModelDescription;

/// What the user asks of an FMI 3.0 Co-Simulation FMU's Event Mode.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum EventModeChoice {
    /// Event Mode where it is needed: an FMU with clocks (and `hasEventMode`).
    #[default]
    Auto,
    /// Event Mode for every FMI 3.0 Co-Simulation FMU (each must declare `hasEventMode`).
    On,
    /// No Event Mode (refused for an FMU with clocks, which needs it).
    Off,
}

impl EventModeChoice {
    /// `auto`, `on` or `off`, as `cosim run --event-mode` takes them.
    pub fn as_str(self) -> &'static str {
        match self {
            EventModeChoice::Auto => "auto",
            EventModeChoice::On => "on",
            EventModeChoice::Off => "off",
        }
    }

    /// fmpy's `use_event_mode`: `None` auto, `Some(true)` on, `Some(false)` off.
    pub fn from_flag(flag: Option<bool>) -> EventModeChoice {
        match flag {
            None => EventModeChoice::Auto,
            Some(true) => EventModeChoice::On,
            Some(false) => EventModeChoice::Off,
        }
    }
}

impl std::str::FromStr for EventModeChoice {
    type Err = String;
    fn from_str(text: &str) -> Result<EventModeChoice, String> {
        [EventModeChoice::Auto, EventModeChoice::On, EventModeChoice::Off]
            .into_iter()
            .find(|c| c.as_str() == text)
            .ok_or_else(|| format!("unknown Event Mode choice {text:?} (auto, on, off)"))
    }
}

/// The decision for one FMI 3.0 Co-Simulation FMU: whether it is instantiated with
/// `eventModeUsed`, and why, in words for `cosim info` and the notes of a run.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EventMode {
    /// `eventModeUsed` of `fmi3InstantiateCoSimulation`.
    pub used: bool,
    /// Why, in words.
    pub why: String,
}

/// The decision for an FMI 3.0 Co-Simulation FMU described by `md` under `choice`, or why
/// the choice is refused: `on` for an FMU that declares no `hasEventMode` (it may not be
/// instantiated with `eventModeUsed`), `off` for an FMU with clocks (it needs Event Mode).
pub fn decide(md: &ModelDescription, clocks: &[Clock], choice: EventModeChoice) -> Result<EventMode, String> {
    let has_event_mode = md.co_simulation.as_ref().is_some_and(|cs| cs.has_event_mode);
    let names = || clocks.iter().map(|c| format!("{:?}", c.name)).collect::<Vec<_>>().join(", ");
    let decided = |used: bool, why: String| Ok(EventMode { used, why });
    match choice {
        EventModeChoice::On if !has_event_mode => Err(
            "Event Mode asked for (event mode on), but the FMU declares no hasEventMode for Co-Simulation, so it may \
             not be instantiated with eventModeUsed = true (FMI 3.0 section 4.1.2)"
                .into(),
        ),
        EventModeChoice::On => decided(true, "asked for (event mode on)".into()),
        EventModeChoice::Off if !clocks.is_empty() => Err(format!(
            "no Event Mode asked for (event mode off), but the FMU declares the clocks {}, which the master drives \
             in Event Mode only (FMI 3.0 requires eventModeUsed = true of an FMU with clocks)",
            names()
        )),
        EventModeChoice::Off => {
            decided(false, "not asked for (event mode off): the FMU handles its events inside fmi3DoStep".into())
        }
        EventModeChoice::Auto if !clocks.is_empty() => {
            decided(true, format!("needed (auto): the FMU declares the clocks {}", names()))
        }
        EventModeChoice::Auto if has_event_mode => decided(
            false,
            "not needed (auto): the FMU has Event Mode but no clocks, so it handles its events inside fmi3DoStep \
             (as fmpy's simulate_fmu runs it by default; event mode on to use it)"
                .into(),
        ),
        EventModeChoice::Auto => decided(false, "not available: the FMU declares no hasEventMode".into()),
    }
}
