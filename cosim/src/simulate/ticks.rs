//! The ticks of one instance's input clocks (FMI 3.0 clocks, Co-Simulation with Event
//! Mode): when each ticks, and the counts of every clock's ticks for the summary.
//!
//! - constant, fixed and tunable clocks tick at `t0 + shift + k * interval` (k = 0, 1, ...,
//!   counted, not accumulated), the interval and shift as declared, or as the FMU gives
//!   them after initialization (`fmi3GetIntervalDecimal`, any event: a new interval of a
//!   tunable clock counts from the event that gave it);
//! - changing and countdown clocks tick `interval` after the event in which the FMU gave
//!   a new interval (`fmi3IntervalChanged`), once per interval given;
//! - triggered input clocks tick at the times of an input file's column named for them
//!   (a value of 1 at a row: a tick at its time).
//!
//! A tick within a millionth of a communication step of a point is at the point (the
//! point's time is `t0 + n h`, the tick's `t0 + shift + k i`: the two may differ by an ulp).
//! In Co-Simulation the step that reaches a tick opens its event ([`Ticks::at`],
//! [`Ticks::opened`]): the exchange and the row at that point happen in it, and the next
//! step closes it before it steps (`lane.rs`, docs/clocks.md); the tick at the start time,
//! and a tick that becomes known inside a step, run whole where the step starts or where
//! they fall (a tick inside a step splits it: the lane steps to the tick, runs the clock
//! event there, and goes on). Model Exchange runs every tick whole at the start of the step
//! from it.

use crate::clocks::{Clock, ClockCausality, ClockKind};
use crate::error::{Error, Result};
use crate::fmu::{Instance, Interval};
use crate::simulate::input_table::InputTable;
use crate::system::System;

/// One input clock's schedule.
#[derive(Clone, Debug)]
struct Scheduled {
    /// The clock's value reference.
    vr: u32,
    kind: ClockKind,
    /// The time ticks are counted from, s (the start time + shift, or the event that gave
    /// the interval).
    origin: f64,
    /// s; `None`: the clock is not counting (a countdown clock before the FMU says).
    interval: Option<f64>,
    /// The number of the next tick from `origin`.
    k: u64,
    /// Triggered by an input file: its tick times, ascending, and the next one's index.
    times: Vec<f64>,
    next_time: usize,
}

impl Scheduled {
    /// The time of the next tick, if any.
    fn next(&self) -> Option<f64> {
        match self.kind {
            ClockKind::Triggered => self.times.get(self.next_time).copied(),
            ClockKind::Changing | ClockKind::Countdown => {
                self.interval.filter(|_| self.k == 1).map(|i| self.origin + i)
            }
            _ => self.interval.map(|i| self.origin + self.k as f64 * i),
        }
    }

    fn ticked(&mut self) {
        match self.kind {
            ClockKind::Triggered => self.next_time += 1,
            // one tick per interval the FMU gives
            ClockKind::Changing | ClockKind::Countdown => self.k = 2,
            _ => self.k += 1,
        }
    }
}

/// The input clocks of one lane and the ticks of all its clocks so far.
#[derive(Clone, Debug)]
pub(crate) struct Ticks {
    inputs: Vec<Scheduled>,
    /// Every clock of the instance: (value reference, name, ticks so far).
    pub(crate) counts: Vec<(u32, String, u64)>,
    /// The output clocks that ticked since [`Ticks::take_fired`] (for clock connections).
    fired: Vec<u32>,
    /// A millionth of the communication step, s: ticks this close are one.
    tolerance: f64,
    /// The event of the ticks at the end of the last step is open (Co-Simulation: the
    /// exchange at that point happens in it; the next step closes it).
    open: bool,
}

impl Ticks {
    /// The schedule of `clocks` (an instance's) from `t0`; `triggered`: the tick times of
    /// triggered input clocks by value reference (from the input file). `None` when the
    /// instance has no clock.
    pub(crate) fn new(clocks: &[Clock], t0: f64, h: f64, triggered: &[(u32, Vec<f64>)]) -> Option<Ticks> {
        if clocks.is_empty() {
            return None;
        }
        let inputs = clocks
            .iter()
            .filter(|c| c.causality == ClockCausality::Input)
            .map(|c| Scheduled {
                vr: c.value_reference,
                kind: c.kind,
                origin: t0 + c.shift,
                interval: c
                    .interval
                    .filter(|_| matches!(c.kind, ClockKind::Constant | ClockKind::Fixed | ClockKind::Tunable)),
                k: 0,
                times: triggered
                    .iter()
                    .find(|(vr, _)| *vr == c.value_reference)
                    .map(|(_, t)| t.clone())
                    .unwrap_or_default(),
                next_time: 0,
            })
            .collect();
        let counts = clocks.iter().map(|c| (c.value_reference, c.name.clone(), 0)).collect();
        Some(Ticks { inputs, counts, fired: Vec::new(), tolerance: 1e-6 * h, open: false })
    }

    /// The earliest tick from `after` on and before `until` (a tick within the tolerance of
    /// either is at it: a tick on a communication point belongs to the step that starts
    /// there), and the value references of the clocks ticking then.
    pub(crate) fn due(&self, after: f64, until: f64) -> Option<(f64, Vec<u32>)> {
        // (called at every step: nothing allocated unless a tick is due)
        let first = self.inputs.iter().filter_map(Scheduled::next).fold(f64::INFINITY, f64::min);
        // (no tick: first is infinite)
        if first >= until - self.tolerance {
            return None;
        }
        let at = if (first - after).abs() <= self.tolerance { after } else { first.max(after) };
        let vrs = self
            .inputs
            .iter()
            .filter(|s| s.next().is_some_and(|t| (t - first).abs() <= self.tolerance))
            .map(|s| s.vr)
            .collect();
        Some((at, vrs))
    }

    /// The first tick after `from` (beyond the tolerance) and before `until`, as far as it
    /// is known now (a changing or countdown clock's next tick is known after the event
    /// that gives its interval): where the master splits a communication step.
    pub(crate) fn next_inside(&self, from: f64, until: f64) -> Option<f64> {
        let after = |t: f64| t > from + self.tolerance;
        let mut first = f64::INFINITY;
        for s in &self.inputs {
            let candidate = match s.next() {
                Some(t) if after(t) => Some(t),
                // the tick at `from` is the step's first: the one after it
                Some(_) => match s.kind {
                    ClockKind::Triggered => s.times[s.next_time..].iter().copied().find(|t| after(*t)),
                    ClockKind::Changing | ClockKind::Countdown => None,
                    _ => s.interval.map(|i| s.origin + (s.k + 1) as f64 * i).filter(|t| after(*t)),
                },
                None => None,
            };
            if let Some(t) = candidate {
                first = first.min(t);
            }
        }
        (first < until - self.tolerance).then_some(first)
    }

    /// The input clocks of `clocks` that tick at the start time `t0` (within a millionth of
    /// the communication step `h`): periodic clocks with shift 0, triggered clocks whose
    /// first tick time from the input file is `t0`. Known before the event that ends
    /// initialization (Model Exchange activates them there, before its event iteration).
    pub(crate) fn at_start(clocks: &[Clock], t0: f64, h: f64, triggered: &[(u32, Vec<f64>)]) -> Vec<u32> {
        let at_t0 = |t: f64| (t - t0).abs() <= 1e-6 * h;
        clocks
            .iter()
            .filter(|c| c.causality == ClockCausality::Input)
            .filter(|c| match c.kind {
                ClockKind::Constant | ClockKind::Fixed | ClockKind::Tunable => at_t0(t0 + c.shift),
                ClockKind::Triggered => triggered
                    .iter()
                    .find(|(vr, _)| *vr == c.value_reference)
                    .is_some_and(|(_, times)| times.first().is_some_and(|t| at_t0(*t))),
                _ => false,
            })
            .map(|c| c.value_reference)
            .collect()
    }

    /// Ticks this close are one, s (a millionth of the communication step).
    pub(crate) fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// The input clocks whose next tick is at `t` (within the tolerance), if any: the ticks
    /// at the end of a step, whose event the step opens.
    pub(crate) fn at(&self, t: f64) -> Option<Vec<u32>> {
        let vrs: Vec<u32> = self
            .inputs
            .iter()
            .filter(|s| s.next().is_some_and(|next| (next - t).abs() <= self.tolerance))
            .map(|s| s.vr)
            .collect();
        (!vrs.is_empty()).then_some(vrs)
    }

    /// The clocks `vrs` ticked at the end of a step, their event left open.
    pub(crate) fn opened(&mut self, vrs: &[u32]) {
        self.ticked(vrs);
        self.open = true;
    }

    /// Whether an event is open (and from now on not).
    pub(crate) fn take_open(&mut self) -> bool {
        std::mem::take(&mut self.open)
    }

    /// The clocks `vrs` ticked.
    pub(crate) fn ticked(&mut self, vrs: &[u32]) {
        for s in self.inputs.iter_mut().filter(|s| vrs.contains(&s.vr)) {
            s.ticked();
        }
        self.count(vrs);
    }

    fn count(&mut self, vrs: &[u32]) {
        for c in self.counts.iter_mut().filter(|c| vrs.contains(&c.0)) {
            c.2 += 1;
        }
    }

    /// After the events of `inst` so far (ticks', and those the FMU asked for): the output
    /// clocks that ticked are counted, and the intervals the FMU gave taken (a new interval
    /// counts from the event that gave it). `initial`: the event that ends initialization,
    /// where an unchanged interval of a fixed or tunable clock is its interval from the start.
    pub(crate) fn after_events(&mut self, inst: &mut Instance, initial: bool) -> Result<()> {
        let outputs: Vec<u32> = inst.take_output_ticks().iter().map(|t| t.value_reference).collect();
        self.count(&outputs);
        self.fired.extend(outputs);
        for (time, vr, interval) in inst.take_intervals() {
            let Some(s) = self.inputs.iter_mut().find(|s| s.vr == vr) else { continue };
            let periodic = matches!(s.kind, ClockKind::Fixed | ClockKind::Tunable);
            match interval {
                Interval::Unchanged(i) | Interval::Changed(i) if initial && periodic => s.interval = Some(i),
                Interval::Changed(i) if s.kind != ClockKind::Fixed => {
                    s.origin = time;
                    s.interval = Some(i);
                    s.k = 1;
                }
                _ => {}
            }
        }
        if initial {
            if let Some(s) = self.inputs.iter().find(|s| {
                s.interval.is_none() && matches!(s.kind, ClockKind::Fixed | ClockKind::Tunable | ClockKind::Constant)
            }) {
                return Err(Error::Experiment(format!(
                    "{}: {} clock {} has no interval: its description gives none and fmi3GetIntervalDecimal did not \
                     give one after initialization",
                    inst.name(),
                    s.kind.as_str(),
                    s.vr
                )));
            }
        }
        Ok(())
    }

    /// The output clocks that ticked since the last call.
    pub(crate) fn take_fired(&mut self) -> Vec<u32> {
        std::mem::take(&mut self.fired)
    }

    /// The triggered input clock `vr` ticks at `time` (a connected output clock ticked).
    pub(crate) fn trigger(&mut self, vr: u32, time: f64) {
        if let Some(s) = self.inputs.iter_mut().find(|s| s.vr == vr) {
            let rest = &s.times[s.next_time..];
            if !rest.contains(&time) {
                let at = s.next_time + rest.partition_point(|t| *t < time);
                s.times.insert(at, time);
            }
        }
    }

    /// The ticks of every clock: (name, count).
    pub(crate) fn summary(&self, instance: &str, single: bool) -> Vec<(String, u64)> {
        self.counts
            .iter()
            .map(|(_, name, n)| (if single { name.clone() } else { format!("{instance}.{name}") }, *n))
            .collect()
    }
}

/// Triggered input clocks' tick times from an input file: (instance, clock, times).
pub(crate) type ClockColumns = Vec<(usize, u32, Vec<f64>)>;

/// The columns of `table` that name a triggered input clock (`instance.clock`, or the
/// clock's name in a one-instance system): each clock's tick times (the rows where the
/// column is not 0; a time once), by (instance, clock); and the table without them.
pub(crate) fn clock_columns(system: &System, table: &InputTable) -> Result<(InputTable, ClockColumns)> {
    let single = system.instances.len() == 1;
    let mut rest =
        InputTable { names: Vec::new(), time: table.time.clone(), columns: Vec::new(), integers: Vec::new() };
    let mut clocks = Vec::new();
    for (j, (name, column)) in table.names.iter().zip(&table.columns).enumerate() {
        let found = system.instances.iter().enumerate().find_map(|(i, spec)| {
            let local = if single { name.as_str() } else { name.strip_prefix(&spec.name)?.strip_prefix('.')? };
            spec.fmu.clocks().into_iter().find(|c| c.name == local).map(|c| (i, c))
        });
        let Some((i, clock)) = found else {
            rest.names.push(name.clone());
            rest.columns.push(column.clone());
            rest.integers.push(table.integers.get(j).cloned().flatten());
            continue;
        };
        if clock.causality != ClockCausality::Input || clock.kind != ClockKind::Triggered {
            return Err(Error::Experiment(format!(
                "input: column {name:?} is the {} {} clock {:?}: only triggered input clocks tick from an input file",
                clock.kind.as_str(),
                clock.causality.as_str(),
                clock.name
            )));
        }
        let mut times: Vec<f64> = Vec::new();
        for (t, v) in table.time.iter().zip(column) {
            if *v != 0.0 && times.last() != Some(t) {
                times.push(*t);
            }
        }
        clocks.push((i, clock.value_reference, times));
    }
    Ok((rest, clocks))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn clock(name: &str, vr: u32, kind: ClockKind, interval: Option<f64>, shift: f64) -> Clock {
        Clock {
            name: name.into(),
            value_reference: vr,
            kind,
            causality: ClockCausality::Input,
            interval,
            shift,
            priority: None,
            governs: Vec::new(),
        }
    }

    /// The ticks `due` gives from 0 to `stop` with points every `h` (a lane's loop).
    fn ticks_until(t: &mut Ticks, h: f64, stop: f64) -> Vec<(f64, Vec<u32>)> {
        let mut out = Vec::new();
        let mut n = 0u64;
        while (n as f64) * h < stop - 1e-12 {
            let (mut at, end) = (n as f64 * h, (n + 1) as f64 * h);
            while let Some((tick, vrs)) = t.due(at, end) {
                t.ticked(&vrs);
                out.push((tick, vrs));
                at = tick;
            }
            n += 1;
        }
        out
    }

    #[test]
    fn periodic_ticks_are_counted_from_the_shift_and_belong_to_the_step_from_their_point() {
        // interval 0.3 s, shift 0.1 s, points every 0.2 s, stop 1.0 s: ticks at 0.1 + k 0.3
        // = 0.1, 0.4, 0.7 (0.1 and 0.7 split a step; 0.4 is a point: the step from it
        // starts with it; 1.0 is the stop time, where no step starts)
        let mut t = Ticks::new(&[clock("c", 7, ClockKind::Constant, Some(0.3), 0.1)], 0.0, 0.2, &[]).unwrap();
        let got = ticks_until(&mut t, 0.2, 1.0);
        let times: Vec<f64> = got.iter().map(|(t, _)| *t).collect();
        assert_eq!(times.len(), 3, "{times:?}");
        for (a, b) in times.iter().zip([0.1, 0.4, 0.7]) {
            assert!((a - b).abs() < 1e-15, "{times:?}");
        }
        // the tick on a point is the point's own time (0.4 = 2 * 0.2), not 0.1 + 0.3
        assert_eq!(times[1], 2.0 * 0.2);
        assert_eq!(t.counts[0].2, 3);
    }

    #[test]
    fn two_clocks_tick_together_where_their_times_meet() {
        // 0.2 s and 0.5 s from 0, points every 0.1 s, stop 1.0 s: together at 0 only (1.0
        // is the stop time); a at 0, 0.2, 0.4, 0.6, 0.8; b at 0, 0.5
        let mut t = Ticks::new(
            &[clock("a", 1, ClockKind::Constant, Some(0.2), 0.0), clock("b", 2, ClockKind::Fixed, Some(0.5), 0.0)],
            0.0,
            0.1,
            &[],
        )
        .unwrap();
        let got = ticks_until(&mut t, 0.1, 1.0);
        let both: Vec<f64> = got.iter().filter(|(_, v)| v.len() == 2).map(|(t, _)| *t).collect();
        assert_eq!(both, [0.0]);
        assert_eq!((t.counts[0].2, t.counts[1].2), (5, 2));
    }

    #[test]
    fn triggered_clocks_tick_at_the_input_files_times() {
        let c = clock("trig", 3, ClockKind::Triggered, None, 0.0);
        let mut t = Ticks::new(&[c], 0.0, 0.5, &[(3, vec![0.25, 1.0, 1.7])]).unwrap();
        let got = ticks_until(&mut t, 0.5, 2.0);
        assert_eq!(got.iter().map(|(t, _)| *t).collect::<Vec<_>>(), [0.25, 1.0, 1.7]);
        assert_eq!(t.counts[0].2, 3);
    }
}
