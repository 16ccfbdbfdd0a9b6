//! The model partitions of an FMI 3.0 FMU for Scheduled Execution: one per input clock,
//! with its `priority` (smaller first when clocks tick together) and how its ticks come:
//! periodic from `intervalDecimal` and `shiftDecimal`, triggered by the importer, counted
//! down by the FMU (`intervalVariability="countdown"`), or each interval from the FMU after
//! the last activation (`changing`). Its output clocks, whose
//! ticks the FMU signals through `clockUpdate`. Read from the description; the calls are
//! `instance/scheduled.rs`. A `fixed` or `tunable` clock's interval is the FMU's to give
//! (`fmi3GetIntervalDecimal` after initialization, a tunable one again when the FMU signals
//! `clockUpdate`): the description's is what the master uses until then, and may be absent.

use crate::clocks::ClockKind;
use model_description::fmi3;

/// How the ticks of a partition's input clock come.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Ticks {
    /// Every `interval` s from `shift` s after the start (`constant`, `fixed` or `tunable`
    /// clocks with `intervalDecimal`; `fixed` and `tunable` ones also without).
    Periodic {
        /// `intervalDecimal`, s; `None` for a `fixed` or `tunable` clock whose description
        /// gives none (the FMU gives it after initialization).
        interval: Option<f64>,
        /// `shiftDecimal` (0 when absent), s.
        shift: f64,
    },
    /// `triggered`: when the importer says (an input file's clock column).
    Triggered,
    /// `countdown`: when the FMU sets its interval during another partition
    /// (`clockUpdate`, then `fmi3GetIntervalDecimal`), that long after the activation.
    Countdown,
    /// `changing` (aperiodic): the first tick the interval `fmi3GetIntervalDecimal` gives in
    /// Initialization Mode after the start, each next one the interval it gives right after
    /// the partition's activation (`fmi3IntervalChanged`) after that activation.
    Changing,
}

/// A model partition: an input clock with a priority.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelPartition {
    /// The clock's name.
    pub name: String,
    /// The clock's value reference.
    pub clock: u32,
    /// `priority` (smaller first).
    pub priority: u32,
    /// How its ticks come.
    pub ticks: Ticks,
    /// Its `intervalVariability`.
    pub kind: ClockKind,
}

impl ModelPartition {
    /// How its ticks come, in words (`every 1 s from 0 s`, `triggered`, `countdown`).
    pub fn ticks_text(&self) -> String {
        match self.ticks {
            Ticks::Periodic { interval, shift } => {
                let every = match interval {
                    Some(interval) => format!("every {interval} s"),
                    None => "every interval the FMU gives".into(),
                };
                match self.kind {
                    ClockKind::Fixed => {
                        format!("{every} from {shift} s (fixed: the FMU's interval after initialization)")
                    }
                    ClockKind::Tunable => format!("{every} from {shift} s (tunable: the FMU's interval when it says)"),
                    _ => format!("{every} from {shift} s"),
                }
            }
            Ticks::Triggered => "triggered (an input file's clock column)".into(),
            Ticks::Countdown => "countdown (set by the FMU)".into(),
            Ticks::Changing => "changing (each interval from the FMU after an activation)".into(),
        }
    }
}

/// The model partitions of `md` (its input clocks), in document order; the error names a
/// clock whose ticks the master cannot know (no priority, or a periodic interval kind
/// without `intervalDecimal`).
pub fn model_partitions(md: &fmi3::ModelDescription) -> Result<Vec<ModelPartition>, String> {
    let mut out = Vec::new();
    for v in md.model_variables.iter().filter(|v| v.value_type == fmi3::ValueType::Clock) {
        if v.causality != fmi3::Causality::Input {
            continue;
        }
        let attributes = v.clock.clone().unwrap_or_default();
        let priority = attributes
            .priority
            .ok_or_else(|| format!("input clock {:?} has no priority (Scheduled Execution needs one)", v.name))?;
        let kind = ClockKind::parse(attributes.interval_variability.as_deref());
        let shift = attributes.shift_decimal.unwrap_or(0.0);
        let ticks = match kind {
            Some(ClockKind::Triggered) => Ticks::Triggered,
            Some(ClockKind::Countdown) => Ticks::Countdown,
            Some(ClockKind::Changing) => Ticks::Changing,
            kind => match attributes.interval_decimal {
                Some(interval) if interval > 0.0 && interval.is_finite() => {
                    Ticks::Periodic { interval: Some(interval), shift }
                }
                None if matches!(kind, Some(ClockKind::Fixed | ClockKind::Tunable)) => {
                    Ticks::Periodic { interval: None, shift }
                }
                _ => {
                    return Err(format!(
                        "input clock {:?} ({} interval) has no intervalDecimal: its ticks are not known to cosim",
                        v.name,
                        kind.map_or("no", ClockKind::as_str)
                    ))
                }
            },
        };
        let kind = kind.unwrap_or(ClockKind::Constant);
        out.push(ModelPartition { name: v.name.clone(), clock: v.value_reference, priority, ticks, kind });
    }
    Ok(out)
}

/// The output clocks of `md` (name, value reference), in document order.
pub fn output_clocks(md: &fmi3::ModelDescription) -> Vec<(String, u32)> {
    md.model_variables
        .iter()
        .filter(|v| v.value_type == fmi3::ValueType::Clock && v.causality == fmi3::Causality::Output)
        .map(|v| (v.name.clone(), v.value_reference))
        .collect()
}
