//! `jacobi`: per instance, its inputs (from the outputs of the previous step), its step,
//! its connected outputs; then all outputs go to their slots: every connection is one
//! step late, as in fmpy `simulate_ssp`, libcosim and ecos.

use super::{Communication, Core};
use crate::error::{Error, Result};
use crate::simulate::clock::Point;
use crate::simulate::profiler::Profiler;
use std::time::Instant;

/// The `jacobi` algorithm in one thread (each lane holds its own batched calls).
pub(crate) struct Jacobi;

impl Jacobi {
    /// Step `p` of every lane; `profile`: each lane measures the time of its calls.
    #[inline]
    pub(crate) fn step_lanes(core: &mut Core, p: Point, profile: bool) -> Result<()> {
        let solver = core.solver;
        match core.group.as_mut() {
            None => {
                // isolated lanes first: their inputs and steps handed to their hosts, which
                // then step while the master steps the others and collects them in turn
                let mut first: Option<Error> = None;
                for lane in core.lanes.iter_mut() {
                    if !lane.can_post() {
                        continue;
                    }
                    if let Err(e) = lane.jacobi_inputs(&core.values, p) {
                        first = Some(e);
                        break;
                    }
                    lane.post_step(p.t, p.t_next);
                }
                // every posted step is collected, even after an error, so that each
                // instance knows the outcome of its step
                for lane in core.lanes.iter_mut() {
                    if lane.posted || first.is_none() {
                        if let Err(e) = lane.jacobi_step(&core.values, p, profile, solver) {
                            first.get_or_insert(e);
                        }
                    }
                }
                if let Some(e) = first {
                    return Err(e);
                }
            }
            Some(g) => {
                // the group's members: all inputs, the steps together, all outputs
                for lane in core.lanes.iter_mut() {
                    if lane.in_group() {
                        lane.jacobi_inputs(&core.values, p)?;
                    } else {
                        lane.jacobi_step(&core.values, p, profile, solver)?;
                    }
                }
                let start = profile.then(Instant::now);
                g.advance(core.lanes.as_mut_slice(), solver, p.t, p.t_next)?;
                if let Some(start) = start {
                    let share = start.elapsed() / g.members.len().max(1) as u32;
                    for &m in g.members.iter() {
                        core.lanes[m].spent += share;
                    }
                }
                for &m in g.members.iter() {
                    core.lanes[m].jacobi_outputs(p)?;
                }
            }
        }
        for lane in core.lanes.iter() {
            lane.scatter(&mut core.values, p.output_point);
        }
        Ok(())
    }
}

impl Communication for Jacobi {
    fn propagate(&mut self, core: &mut Core) -> Result<()> {
        for lane in core.lanes.iter_mut() {
            lane.get_outputs(&mut core.values)?;
        }
        for lane in core.lanes.iter_mut() {
            lane.set_inputs(&core.values)?;
        }
        Ok(())
    }

    #[inline]
    fn step(&mut self, core: &mut Core, p: Point, _calls: Option<&mut Profiler>) -> Result<()> {
        let profile = core.profile;
        Jacobi::step_lanes(core, p, profile)
    }

    /// The inputs of the last point, as after every other step.
    fn finish(&mut self, core: &mut Core) -> Result<()> {
        if core.clock.steps > 0 {
            for lane in core.lanes.iter_mut() {
                lane.set_inputs(&core.values)?;
            }
        }
        Ok(())
    }
}
