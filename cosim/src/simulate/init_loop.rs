//! The connections of a system carried in Initialization Mode until they settle: the
//! connected outputs got and the connected inputs set (one Jacobi sweep, every connection
//! carried) until no carried value changes by more than [`RTOL`] of its magnitude, at most
//! [`MAX_SWEEPS`] sweeps. An algebraic loop at initialization (`crate::loops`: connections
//! closed through FMUs whose outputs depend on their inputs at initialization) settles at
//! its fixed point, as OMSimulator solves it; a chain of such FMUs (`a.y -> b.u`, `b.y`
//! depending on `b.u`, `b.y -> c.u`) settles exactly, one sweep per link, so that every
//! input enters `exitInitializationMode` at its source's value, not at a value its source
//! had from its own inputs' start values (carried once, `c.u` would be `b.y` of `b.u`'s start).

use crate::error::{Error, Result};
use crate::simulate::algorithm::Core;

/// The relative change below which a value on the loop has converged: far above the
/// rounding of one sweep (a few ulps, 1e-16 relative), far below what any result shows.
pub(crate) const RTOL: f64 = 1e-10;
/// The sweeps after the first carry of the connections at most.
pub(crate) const MAX_SWEEPS: usize = 100;

/// Sweeps the connections of `core` (carried once already) until their values settle;
/// the sweeps taken, or the error naming the loop `cycle` (none declared: empty) and the
/// largest change left.
/// A value's tolerance is [`RTOL`] of the larger of its old and new magnitude, and of a
/// millionth of the largest magnitude on the loop, so that a value converging to 0 among
/// others of size 1e5 settles at 1e-11 rather than never. The slots `exact` (the integer
/// connections' outputs and their residuals, `integers.rs`) settle only when they no longer
/// change at all (an integer is its value or wrong) and take no part in that magnitude.
pub(crate) fn iterate(core: &mut Core, cycle: &[String], exact: &[usize]) -> Result<usize> {
    let mut is_exact = vec![false; core.values.len()];
    for &s in exact {
        is_exact[s] = true;
    }
    let mut before = core.values.clone();
    let mut worst = 0.0f64;
    for sweep in 1..=MAX_SWEEPS {
        for lane in core.lanes.iter_mut() {
            lane.get_outputs(&mut core.values)?;
        }
        for lane in core.lanes.iter_mut() {
            lane.set_inputs(&core.values)?;
        }
        let scale = core.values.iter().zip(&is_exact).filter(|(_, e)| !**e).fold(0.0f64, |m, (x, _)| m.max(x.abs()));
        worst = 0.0;
        let mut settled = true;
        for ((new, old), exact) in core.values.iter().zip(&before).zip(&is_exact) {
            let change = (new - old).abs();
            let tolerance = if *exact { 0.0 } else { RTOL * (new.abs().max(old.abs()) + 1e-6 * scale) };
            if change > tolerance || change.is_nan() || tolerance.is_nan() {
                settled = false;
                worst = if change.is_nan() { f64::NAN } else { worst.max(change) };
            }
        }
        if settled {
            return Ok(sweep);
        }
        before.copy_from_slice(&core.values);
    }
    let what = if cycle.is_empty() {
        // no loop by the model descriptions: an FMU's outputs depend on its inputs at
        // initialization beyond its declared dependencies
        "the connections at initialization (no algebraic loop by the FMUs' declared dependencies: one of them depends on more than it declares)".to_string()
    } else {
        format!("the algebraic loop at initialization {}", cycle.join(", "))
    };
    Err(Error::Experiment(format!(
        "{what} did not converge: after {MAX_SWEEPS} sweeps of its connections a value still changed by {worst} (more than {RTOL} of its magnitude)"
    )))
}
