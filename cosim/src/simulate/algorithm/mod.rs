//! The communication algorithms: how the instances are stepped and their connections
//! carried over one communication step. Each is one file implementing [`Communication`];
//! the execution (`simulate/execution.rs`) initializes the run, then hands the steps to the
//! algorithm, which tells the observers after each step.

mod jacobi;
mod ordered;
mod threads;

pub(crate) use jacobi::Jacobi;
pub(crate) use ordered::Ordered;
pub(crate) use threads::ThreadedJacobi;

use crate::error::Result;
use crate::me::Solver;
use crate::simulate::clock::{Clock, Point};
use crate::simulate::lane::Lane;
use crate::simulate::me_group::MeGroup;
use crate::simulate::observer::Observers;
use crate::simulate::profiler::Profiler;
use std::ops::Range;

/// What an algorithm works on: the instances, the value buffer of the plan, the coupled
/// Model Exchange group and the time base.
pub(crate) struct Core {
    /// One lane per instance, in the system's order.
    pub(crate) lanes: Vec<Lane>,
    /// The value buffer of the plan (one slot per connected output or recorded variable).
    pub(crate) values: Vec<f64>,
    /// The Model Exchange instances connected to each other, advanced together.
    pub(crate) group: Option<MeGroup>,
    pub(crate) solver: Solver,
    pub(crate) clock: Clock,
    /// Lanes measure the time of their calls (`jacobi` with the profile asked for).
    pub(crate) profile: bool,
    /// Steps run with the instances spread over threads.
    pub(crate) parallel_steps: u64,
    /// Connections from output clocks to triggered input clocks: (instance, clock) pairs.
    pub(crate) clock_links: Vec<crate::system::ClockConnection>,
    /// Some instance has clocks (its steps are split at their ticks).
    pub(crate) clocked: bool,
}

impl Core {
    /// The first tick of any instance's input clocks after `from` and before `until`.
    #[inline]
    pub(crate) fn next_tick_inside(&self, from: f64, until: f64) -> Option<f64> {
        if !self.clocked {
            return None;
        }
        next_tick_inside(self.lanes.iter(), from, until)
    }

    /// The ticks of output clocks in the step that ends at `t_next` carried to the
    /// triggered input clocks connected to them (see [`carry_clock_ticks`]).
    pub(crate) fn carry_clock_ticks(&mut self, t_next: f64) {
        if self.clock_links.is_empty() {
            return;
        }
        carry_clock_ticks(self.lanes.iter_mut(), &self.clock_links, t_next);
    }
}

/// The first tick of the input clocks of any of `lanes` after `from` and before `until`.
pub(crate) fn next_tick_inside<'a>(lanes: impl Iterator<Item = &'a Lane>, from: f64, until: f64) -> Option<f64> {
    lanes.filter_map(|l| l.ticks.as_ref()?.next_inside(from, until)).reduce(f64::min)
}

/// The ticks of output clocks in the step that ends at `t_next` carried to the triggered
/// input clocks connected to them (`links`): each ticks at `t_next` (the start of the next
/// step), as `jacobi` carries every connection one step late.
pub(crate) fn carry_clock_ticks<'a>(
    lanes: impl Iterator<Item = &'a mut Lane>,
    links: &[crate::system::ClockConnection],
    t_next: f64,
) {
    let mut lanes: Vec<&mut Lane> = lanes.collect();
    let fired: Vec<(usize, Vec<u32>)> =
        lanes.iter_mut().filter_map(|l| Some((l.index, l.ticks.as_mut()?.take_fired()))).collect();
    for (index, vrs) in fired {
        for link in links.iter().filter(|c| c.from.0 == index && vrs.contains(&c.from.1)) {
            if let Some(ticks) = lanes.iter_mut().find(|l| l.index == link.to.0).and_then(|l| l.ticks.as_mut()) {
                ticks.trigger(link.to.1, t_next);
            }
        }
    }
}

/// A communication algorithm.
pub(crate) trait Communication {
    /// Carries every connection once (at initialization, before and after
    /// `fmi2ExitInitializationMode`).
    fn propagate(&mut self, core: &mut Core) -> Result<()>;

    /// Communication step `p`: every instance advanced from `p.t` to `p.t_next` and the
    /// connections carried; at an output point every recorded slot is current after it.
    /// `calls`: the profiler to tell after each call, when one is attached.
    fn step(&mut self, core: &mut Core, p: Point, calls: Option<&mut Profiler>) -> Result<()>;

    /// After the last step.
    fn finish(&mut self, _core: &mut Core) -> Result<()> {
        Ok(())
    }

    /// The steps `steps` of the run, the observers told after each (the caller calls
    /// `finish` after the last step of the run).
    fn run(&mut self, core: &mut Core, observers: &mut Observers, steps: Range<u64>) -> Result<()> {
        for n in steps {
            let p = core.clock.point(n);
            // FMI 3.0 clocks: the step split at every tick inside it, a row recorded there
            // (the values before the tick, whose event starts the next part)
            let mut from = p.t;
            while let Some(tick) = core.next_tick_inside(from, p.t_next) {
                self.step(core, Point { t: from, t_next: tick, output_point: true, ..p }, observers.calls())?;
                core.carry_clock_ticks(tick);
                observers.recorder.push_row(tick, &core.values);
                from = tick;
            }
            let p = Point { t: from, ..p };
            self.step(core, p, observers.calls())?;
            core.carry_clock_ticks(p.t_next);
            if p.output_point && observers.recorder.reads_exact() {
                observers.recorder.read_exact(&mut core.lanes)?;
            }
            observers.step_complete(&p, &core.values)?;
        }
        Ok(())
    }
}
