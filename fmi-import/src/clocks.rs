//! The clocks of an FMU as the master sees them, whatever the generation (FMI 2.0 has none):
//! each clock's kind, causality, interval and shift as its description declares them, and
//! the variables it governs. The calls on a running instance's clocks are
//! `instance/clocks.rs`.

use model_description::fmi3;

/// How a clock's ticks are given (`intervalVariability`, FMI 3.0 section 2.4.7.1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClockKind {
    /// Periodic, the interval and shift fixed in the description.
    Constant,
    /// Periodic, the interval and shift set before initialization (read after it).
    Fixed,
    /// Periodic, the interval may change at an event (read again at every tick).
    Tunable,
    /// Aperiodic: the FMU gives the next interval at each tick.
    Changing,
    /// Aperiodic: the FMU says in an event when the clock ticks next.
    Countdown,
    /// No interval: ticks when its source says (an output clock, an input file).
    Triggered,
}

impl ClockKind {
    /// The description's spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            ClockKind::Constant => "constant",
            ClockKind::Fixed => "fixed",
            ClockKind::Tunable => "tunable",
            ClockKind::Changing => "changing",
            ClockKind::Countdown => "countdown",
            ClockKind::Triggered => "triggered",
        }
    }

    /// Whether the clock's ticks are at times it has (every kind but triggered).
    pub fn is_time_based(self) -> bool {
        self != ClockKind::Triggered
    }

    pub(crate) fn parse(s: Option<&str>) -> Option<ClockKind> {
        Some(match s? {
            "constant" => ClockKind::Constant,
            "fixed" => ClockKind::Fixed,
            "tunable" => ClockKind::Tunable,
            "changing" => ClockKind::Changing,
            "countdown" => ClockKind::Countdown,
            "triggered" => ClockKind::Triggered,
            _ => return None,
        })
    }
}

/// Who makes a clock tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClockCausality {
    /// The master (`fmi3SetClock`).
    Input,
    /// The FMU (`fmi3GetClock` says it ticked).
    Output,
    /// Inside the FMU only.
    Local,
}

impl ClockCausality {
    /// The description's spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            ClockCausality::Input => "input",
            ClockCausality::Output => "output",
            ClockCausality::Local => "local",
        }
    }
}

/// One clock of an FMU.
#[derive(Clone, Debug, PartialEq)]
pub struct Clock {
    /// The clock variable's name.
    pub name: String,
    /// Its value reference (the FMU's).
    pub value_reference: u32,
    /// How its ticks are given.
    pub kind: ClockKind,
    /// Who makes it tick.
    pub causality: ClockCausality,
    /// The declared interval, s (`intervalDecimal`, or `intervalCounter / resolution`);
    /// `None` when the description gives none (changing, countdown, triggered, or read
    /// from the FMU after initialization).
    pub interval: Option<f64>,
    /// The declared shift of the first tick after the start time, s (0 when not given).
    pub shift: f64,
    /// `priority` (Scheduled Execution orders the partitions by it).
    pub priority: Option<u32>,
    /// The names of the variables it governs (their `clocks` attribute names it).
    pub governs: Vec<String>,
}

/// Why a description's clock cannot be run, for the error at load.
pub(crate) fn unreadable_clock(md: &fmi3::ModelDescription) -> Option<String> {
    for v in md.model_variables.iter().filter(|v| v.value_type == fmi3::ValueType::Clock) {
        let attributes = v.clock.clone().unwrap_or_default();
        if ClockKind::parse(attributes.interval_variability.as_deref()).is_none() {
            return Some(format!(
                "clock {:?} with intervalVariability {:?} (one of constant, fixed, tunable, changing, countdown, \
                 triggered is required)",
                v.name,
                attributes.interval_variability.as_deref().unwrap_or("")
            ));
        }
    }
    None
}

/// The clocks of `md`, in the order of its variables.
pub fn clocks_of(md: &fmi3::ModelDescription) -> Vec<Clock> {
    md.model_variables
        .iter()
        .filter(|v| v.value_type == fmi3::ValueType::Clock)
        .map(|v| {
            let a = v.clock.clone().unwrap_or_default();
            let counted = match (a.interval_counter, a.resolution) {
                (Some(c), Some(r)) if r > 0 => Some(c as f64 / r as f64),
                _ => None,
            };
            let counted_shift = match (a.shift_counter, a.resolution) {
                (Some(c), Some(r)) if r > 0 => Some(c as f64 / r as f64),
                _ => None,
            };
            Clock {
                name: v.name.clone(),
                value_reference: v.value_reference,
                kind: ClockKind::parse(a.interval_variability.as_deref()).unwrap_or(ClockKind::Triggered),
                causality: match v.causality {
                    fmi3::Causality::Input => ClockCausality::Input,
                    fmi3::Causality::Output => ClockCausality::Output,
                    _ => ClockCausality::Local,
                },
                interval: a.interval_decimal.or(counted),
                shift: a.shift_decimal.or(counted_shift).unwrap_or(0.0),
                priority: a.priority,
                governs: md
                    .model_variables
                    .iter()
                    .filter(|g| g.clocks.contains(&v.value_reference))
                    .map(|g| g.name.clone())
                    .collect(),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clocks_are_read_with_kind_interval_shift_and_what_they_govern() {
        let xml = r#"<fmiModelDescription fmiVersion="3.0" modelName="m" instantiationToken="{t}">
  <CoSimulation modelIdentifier="m" hasEventMode="true"/>
  <ModelVariables>
    <Float64 name="time" valueReference="0" causality="independent"/>
    <Clock name="sample" valueReference="1" causality="input" intervalVariability="constant" intervalDecimal="0.25" shiftDecimal="0.1"/>
    <Clock name="counted" valueReference="2" causality="input" intervalVariability="fixed" intervalCounter="3" shiftCounter="1" resolution="10"/>
    <Clock name="done" valueReference="3" causality="output" intervalVariability="triggered"/>
    <Int32 name="n" valueReference="4" causality="output" variability="discrete" clocks="1 3"/>
  </ModelVariables>
  <ModelStructure><Output valueReference="4"/></ModelStructure>
</fmiModelDescription>"#;
        let md = fmi3::ModelDescription::from_xml(xml).unwrap();
        assert_eq!(unreadable_clock(&md), None);
        let c = clocks_of(&md);
        assert_eq!(c.len(), 3);
        assert_eq!(
            (c[0].kind, c[0].causality, c[0].interval, c[0].shift),
            (ClockKind::Constant, ClockCausality::Input, Some(0.25), 0.1)
        );
        assert_eq!(c[0].governs, ["n"]);
        // 3 / 10 and 1 / 10 of a second
        assert_eq!((c[1].kind, c[1].interval, c[1].shift), (ClockKind::Fixed, Some(0.3), 0.1));
        assert!(c[1].governs.is_empty());
        assert_eq!((c[2].kind, c[2].causality, c[2].interval), (ClockKind::Triggered, ClockCausality::Output, None));
        assert_eq!(c[2].governs, ["n"]);
        let bad = xml.replace(r#"intervalVariability="triggered""#, r#"intervalVariability="sometimes""#);
        let md = fmi3::ModelDescription::from_xml(&bad).unwrap();
        assert!(unreadable_clock(&md).unwrap().contains("\"done\""));
    }
}
