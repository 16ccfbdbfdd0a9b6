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
use crate::simulate::observer::{Observers, Profiler};
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
            self.step(core, p, observers.calls())?;
            if p.output_point && observers.recorder.reads_exact() {
                observers.recorder.read_exact(&mut core.lanes)?;
            }
            observers.step_complete(&p, &core.values)?;
        }
        Ok(())
    }
}
