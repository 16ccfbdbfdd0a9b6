//! `ordered`: after the step, outputs flow in the topological order of the variable graph
//! (connections and direct feedthrough), so an input sees its source at the same
//! communication point.

use super::{Communication, Core};
use crate::error::{Error, Result};
use crate::simulate::clock::Point;
use crate::simulate::plan::{run_ops, Op};
use crate::simulate::profiler::Profiler;

/// The `ordered` algorithm: the plan's calls in topological order.
pub(crate) struct Ordered {
    /// The batched calls carrying every connection, in topological order.
    pub(crate) ops: Vec<Op>,
    /// The gets of the recorded variables the propagation does not leave current.
    pub(crate) record_gets: Vec<Op>,
}

impl Communication for Ordered {
    fn propagate(&mut self, core: &mut Core) -> Result<()> {
        run_ops(&mut self.ops, core.lanes.as_mut_slice(), &mut core.values, None)
    }

    #[inline]
    fn step(&mut self, core: &mut Core, p: Point, mut calls: Option<&mut Profiler>) -> Result<()> {
        if let Some(c) = calls.as_deref_mut() {
            c.restart();
        }
        // the isolated lanes' steps handed to their hosts first, which then step while
        // the master steps the others and collects them in turn
        for lane in core.lanes.iter_mut() {
            if lane.can_post() {
                lane.post_step(p.t, p.t_next);
            }
        }
        // every posted step is collected, even after an error, so that each instance
        // knows the outcome of its step
        let mut first: Option<Error> = None;
        for lane in core.lanes.iter_mut() {
            if lane.in_group() || !(lane.posted || first.is_none()) {
                continue;
            }
            if let Err(e) = lane.advance(core.solver, p.t, p.t_next) {
                first.get_or_insert(e);
            }
            if let Some(c) = calls.as_deref_mut() {
                c.charge(lane.index);
            }
        }
        if let Some(e) = first {
            return Err(e);
        }
        if let Some(g) = core.group.as_mut() {
            g.advance(core.lanes.as_mut_slice(), core.solver, p.t, p.t_next)?;
            if let Some(c) = calls.as_deref_mut() {
                c.charge_shared(&g.members);
            }
        }
        run_ops(&mut self.ops, core.lanes.as_mut_slice(), &mut core.values, calls)?;
        if p.output_point {
            run_ops(&mut self.record_gets, core.lanes.as_mut_slice(), &mut core.values, None)?;
        }
        Ok(())
    }
}
