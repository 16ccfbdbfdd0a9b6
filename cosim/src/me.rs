//! Model Exchange FMUs integrated by the master: fixed-step RK4 and adaptive
//! Dormand-Prince 5(4); time events, state events (event indicators changing sign,
//! located by the Illinois method to [`EVENT_TIME_TOLERANCE`]) and step events.
//!
//! Over a communication step the FMU's inputs are held (as for a Co-Simulation FMU),
//! so an ME instance takes part in `jacobi` and `ordered` systems like a CS one; its
//! events are handled (event iteration to a fixed point) inside its own step, unless it
//! is connected to another ME instance: then all ME instances advance together and
//! iterate their events together (`coupled.rs`).

#![allow(clippy::needless_range_loop)] // index loops read like the formulas

use crate::error::{Error, Result};
use crate::fmu::Instance;

/// Width of the time bracket an event is located to, s.
pub const EVENT_TIME_TOLERANCE: f64 = 1e-11;

/// The integration method for Model Exchange instances.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Solver {
    /// Classical 4th-order Runge-Kutta, fixed step (at most `max_step`, else the
    /// communication step).
    Rk4 {
        /// Largest internal step, s (`None`: the communication step).
        max_step: Option<f64>,
    },
    /// Dormand-Prince 5(4), adaptive, error per state below `atol + rtol |x|`.
    Dopri5 {
        /// Relative tolerance.
        rtol: f64,
        /// Absolute tolerance.
        atol: f64,
    },
}

impl Default for Solver {
    fn default() -> Self {
        Solver::Rk4 { max_step: None }
    }
}

/// One located event.
#[derive(Clone, Debug, PartialEq)]
pub struct Event {
    /// Instance name.
    pub instance: String,
    /// Time, s.
    pub time: f64,
    /// "time", "state" or "step".
    pub kind: &'static str,
}

/// Integration state of one ME instance; buffers allocated once.
#[derive(Debug)]
pub struct MeUnit {
    pub(crate) x: Vec<f64>,
    pub(crate) x0: Vec<f64>,
    pub(crate) xt: Vec<f64>,
    k: [Vec<f64>; 7],
    pub(crate) z0: Vec<f64>,
    pub(crate) z: Vec<f64>,
    pub(crate) next_time_event: Option<f64>,
    pub(crate) h_adaptive: f64,
    /// Events so far.
    pub events: Vec<Event>,
    /// Accepted internal steps.
    pub steps: u64,
    /// Rejected internal steps (dopri5).
    pub rejected: u64,
    /// The FMU asked to terminate.
    pub terminated: bool,
}

fn event_iteration(inst: &mut Instance, unit: &mut MeUnit) -> Result<()> {
    // FMI 2.0 section 3.2.3: iterate fmi2NewDiscreteStates until no new discrete states
    for _ in 0..1000 {
        let info = inst.new_discrete_states()?;
        if info.terminate_simulation != 0 {
            unit.terminated = true;
        }
        unit.next_time_event = (info.next_event_time_defined != 0).then_some(info.next_event_time);
        if info.new_discrete_states_needed == 0 {
            inst.enter_continuous_time_mode()?;
            inst.get_continuous_states(&mut unit.x)?;
            inst.get_event_indicators(&mut unit.z0)?;
            return Ok(());
        }
    }
    Err(Error::Experiment(format!("{}: event iteration did not converge in 1000 rounds", inst.name())))
}

impl MeUnit {
    /// After `fmi2ExitInitializationMode` (the instance is in event mode): event
    /// iteration, continuous-time mode, initial states and indicators.
    pub fn initialize(inst: &mut Instance) -> Result<MeUnit> {
        let mut unit = MeUnit::new(inst);
        event_iteration(inst, &mut unit)?;
        Ok(unit)
    }

    /// The integration state of `inst`, before any event iteration (the instance stays in
    /// event mode).
    pub(crate) fn new(inst: &Instance) -> MeUnit {
        let md = inst.fmu().description();
        let n = md.states().len();
        let m = md.number_of_event_indicators as usize;
        MeUnit {
            x: vec![0.0; n],
            x0: vec![0.0; n],
            xt: vec![0.0; n],
            k: std::array::from_fn(|_| vec![0.0; n]),
            z0: vec![0.0; m],
            z: vec![0.0; m],
            next_time_event: None,
            h_adaptive: 0.0,
            events: Vec::new(),
            steps: 0,
            rejected: 0,
            terminated: false,
        }
    }

    /// The start of a step at `t`: x0 = x and the derivatives there (k1).
    pub(crate) fn begin_step(&mut self, inst: &mut Instance, t: f64) -> Result<()> {
        self.x0.copy_from_slice(&self.x);
        let (x0, k) = (&self.x0, &mut self.k[0]);
        Self::derivatives(inst, t, x0, k)
    }

    /// After an event iteration that ended in continuous-time mode: the states and event
    /// indicators as the FMU now has them.
    pub(crate) fn resume(&mut self, inst: &mut Instance) -> Result<()> {
        inst.get_continuous_states(&mut self.x)?;
        inst.get_event_indicators(&mut self.z0)
    }

    pub(crate) fn derivatives(inst: &mut Instance, t: f64, x: &[f64], dx: &mut [f64]) -> Result<()> {
        inst.set_time(t)?;
        inst.set_continuous_states(x)?;
        inst.get_derivatives(dx)
    }

    /// One RK4 step of size `h` from (t, x0) into `xt` (k1 given in k[0]).
    pub(crate) fn rk4(&mut self, inst: &mut Instance, t: f64, h: f64) -> Result<()> {
        let n = self.x0.len();
        let [k1, k2, k3, k4, ..] = &mut self.k;
        for j in 0..n {
            self.xt[j] = self.x0[j] + 0.5 * h * k1[j];
        }
        Self::derivatives(inst, t + 0.5 * h, &self.xt, k2)?;
        for j in 0..n {
            self.xt[j] = self.x0[j] + 0.5 * h * k2[j];
        }
        Self::derivatives(inst, t + 0.5 * h, &self.xt, k3)?;
        for j in 0..n {
            self.xt[j] = self.x0[j] + h * k3[j];
        }
        Self::derivatives(inst, t + h, &self.xt, k4)?;
        for j in 0..n {
            self.xt[j] = self.x0[j] + h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
        }
        Ok(())
    }

    /// One Dormand-Prince step of size `h` from (t, x0) into `xt` (k1 given in k[0]);
    /// returns the scaled error norm (<= 1: accept). k[6] holds f(t+h, xt) afterwards.
    pub(crate) fn dopri(&mut self, inst: &mut Instance, t: f64, h: f64, rtol: f64, atol: f64) -> Result<f64> {
        const C: [f64; 6] = [1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];
        const A: [[f64; 6]; 6] = [
            [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
            [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
            [19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0, 0.0, 0.0],
            [9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0, 0.0],
            [35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0],
        ];
        // error coefficients: 5th-order weights minus 4th-order weights
        const E: [f64; 7] =
            [71.0 / 57600.0, 0.0, -71.0 / 16695.0, 71.0 / 1920.0, -17253.0 / 339200.0, 22.0 / 525.0, -1.0 / 40.0];
        let n = self.x0.len();
        for s in 0..6 {
            for j in 0..n {
                let mut acc = 0.0;
                for (r, a) in A[s].iter().enumerate().take(s + 1) {
                    acc += a * self.k[r][j];
                }
                self.xt[j] = self.x0[j] + h * acc;
            }
            let (head, tail) = self.k.split_at_mut(s + 1);
            Self::derivatives(inst, t + C[s] * h, &self.xt, &mut tail[0])?;
            let _ = head;
        }
        // xt is the 5th-order solution (stage 7 = FSAL point), k[6] = f(t + h, xt)
        let mut err = 0.0f64;
        for j in 0..n {
            let mut e = 0.0;
            for (r, c) in E.iter().enumerate() {
                e += c * self.k[r][j];
            }
            let scale = atol + rtol * self.x0[j].abs().max(self.xt[j].abs());
            err = err.max((h * e / scale).abs());
        }
        Ok(err)
    }

    pub(crate) fn one_step(&mut self, inst: &mut Instance, solver: Solver, t: f64, h: f64) -> Result<()> {
        match solver {
            Solver::Rk4 { .. } => self.rk4(inst, t, h),
            Solver::Dopri5 { rtol, atol } => self.dopri(inst, t, h, rtol, atol).map(|_| ()),
        }
    }

    /// Event indicators at (t, xt) into `z`.
    pub(crate) fn indicators_at(&mut self, inst: &mut Instance, t: f64) -> Result<()> {
        inst.set_time(t)?;
        inst.set_continuous_states(&self.xt)?;
        inst.get_event_indicators(&mut self.z)
    }

    pub(crate) fn crossed(z0: &[f64], z: &[f64]) -> bool {
        z0.iter().zip(z).any(|(a, b)| (*a > 0.0 && *b <= 0.0) || (*a < 0.0 && *b >= 0.0))
    }

    /// A step of `h` from (t, x0) crossed an event indicator (`z0` to `z`): the offset
    /// `hi` just after the first crossing, found by the Illinois method on the step size
    /// (re-integrating from (t, x0)) to [`EVENT_TIME_TOLERANCE`].
    pub(crate) fn locate_crossing(&mut self, inst: &mut Instance, solver: Solver, t: f64, h: f64) -> Result<f64> {
        let (mut lo, mut hi) = (0.0, h);
        let zi = self
            .z0
            .iter()
            .zip(&self.z)
            .position(|(a, b)| (*a > 0.0 && *b <= 0.0) || (*a < 0.0 && *b >= 0.0))
            .unwrap_or(0);
        let (mut f_lo, mut f_hi) = (self.z0[zi], self.z[zi]);
        let mut side = 0i32;
        let mut iterations = 0;
        while hi - lo > EVENT_TIME_TOLERANCE && iterations < 200 {
            iterations += 1;
            let mut s = hi - f_hi * (hi - lo) / (f_hi - f_lo);
            if !(s > lo && s < hi && s.is_finite()) {
                s = 0.5 * (lo + hi);
            }
            self.one_step(inst, solver, t, s)?;
            self.indicators_at(inst, t + s)?;
            // any indicator crossing in (0, s]?
            if Self::crossed(&self.z0, &self.z) {
                hi = s;
                f_hi = self.z[zi];
                if side == 1 {
                    f_lo *= 0.5;
                }
                side = 1;
            } else {
                lo = s;
                f_lo = self.z[zi];
                if side == -1 {
                    f_hi *= 0.5;
                }
                side = -1;
            }
        }
        Ok(hi)
    }

    /// Integrates from `t` to `t_end` with the inputs as set, handling events.
    pub fn advance(&mut self, inst: &mut Instance, solver: Solver, t: f64, t_end: f64) -> Result<()> {
        let mut t = t;
        let span = t_end - t;
        let eps = 1e-13 * t_end.abs().max(1.0);
        if self.h_adaptive <= 0.0 {
            self.h_adaptive = span * 0.1;
        }
        while t < t_end - eps && !self.terminated {
            // a time event due now
            if let Some(te) = self.next_time_event {
                if te <= t + eps {
                    inst.enter_event_mode()?;
                    self.events.push(Event { instance: inst.name().to_string(), time: t, kind: "time" });
                    event_iteration(inst, self)?;
                    if self.next_time_event.is_some_and(|n| n <= t + eps) {
                        return Err(Error::Experiment(format!(
                            "{}: time event at {te} repeats at the same time",
                            inst.name()
                        )));
                    }
                    continue;
                }
            }
            // the end of this stretch: the next time event or the end of the step
            let mut target = t_end;
            let mut time_event = false;
            if let Some(te) = self.next_time_event {
                if te <= t_end + eps {
                    target = te.max(t);
                    time_event = true;
                }
            }
            // one internal step
            let h_max = target - t;
            let h = match solver {
                Solver::Rk4 { max_step } => {
                    let hm = max_step.unwrap_or(span).max(1e-300);
                    let n = ((h_max / hm) * (1.0 - 1e-12)).ceil().max(1.0);
                    h_max / n
                }
                Solver::Dopri5 { .. } => self.h_adaptive.min(h_max),
            };
            self.x0.copy_from_slice(&self.x);
            {
                let (x0, k) = (&self.x0, &mut self.k[0]);
                Self::derivatives(inst, t, x0, k)?;
            }
            let mut h = h;
            if let Solver::Dopri5 { rtol, atol } = solver {
                loop {
                    let err = self.dopri(inst, t, h, rtol, atol)?;
                    let factor = if err == 0.0 { 5.0 } else { (0.9 * err.powf(-0.2)).clamp(0.2, 5.0) };
                    if err <= 1.0 || h <= 1e-14 * t_end.abs().max(1.0) {
                        self.h_adaptive = (h * factor).min(span.max(h));
                        break;
                    }
                    self.rejected += 1;
                    h *= factor.min(0.9);
                }
            } else {
                self.rk4(inst, t, h)?;
            }
            let t_new = if (t + h - target).abs() <= eps { target } else { t + h };
            self.indicators_at(inst, t_new)?;
            if Self::crossed(&self.z0, &self.z) {
                let hi = self.locate_crossing(inst, solver, t, t_new - t)?;
                // the event is handled just after the crossing, at t + hi
                self.one_step(inst, solver, t, hi)?;
                let te = t + hi;
                inst.set_time(te)?;
                inst.set_continuous_states(&self.xt)?;
                self.x.copy_from_slice(&self.xt);
                self.steps += 1;
                inst.completed_integrator_step()?;
                inst.enter_event_mode()?;
                self.events.push(Event { instance: inst.name().to_string(), time: te, kind: "state" });
                event_iteration(inst, self)?;
                if let Solver::Dopri5 { .. } = solver {
                    self.h_adaptive = self.h_adaptive.min(span * 0.1);
                }
                t = te;
                continue;
            }
            // accepted step without state event
            self.x.copy_from_slice(&self.xt);
            inst.set_time(t_new)?;
            inst.set_continuous_states(&self.x)?;
            self.steps += 1;
            std::mem::swap(&mut self.z0, &mut self.z);
            let (step_event, terminate) = inst.completed_integrator_step()?;
            if terminate {
                self.terminated = true;
            }
            t = t_new;
            let at_time_event = time_event && t >= target - eps;
            if step_event || at_time_event {
                inst.enter_event_mode()?;
                let kind = if at_time_event { "time" } else { "step" };
                self.events.push(Event { instance: inst.name().to_string(), time: t, kind });
                event_iteration(inst, self)?;
            }
        }
        Ok(())
    }
}
