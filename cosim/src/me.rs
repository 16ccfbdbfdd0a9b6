//! Model Exchange FMUs integrated by the master: the solvers ([`Solver`], each an
//! [`Integrator`] of [`crate::integrator`]), the calls of one instance the integration
//! makes (derivatives, event indicators) and its counts, and the Illinois method that
//! locates a state event (an indicator changing sign) to [`EVENT_TIME_TOLERANCE`].
//!
//! Over a communication step the FMU's inputs are held (as for a Co-Simulation FMU),
//! so an ME instance takes part in `jacobi` and `ordered` systems like a CS one. The
//! stepping, the time, state and step events and the event iteration are the master's
//! one integrator of a group of ME instances (`simulate/me_group.rs`): an instance
//! connected to no other ME instance is a group of one.

use crate::error::Result;
use crate::fmu::Instance;
use crate::integrator::{dopri5::Dopri5, rk4::Rk4, switching::Switching, Integrator};

/// Width of the time bracket an event is located to, s.
pub const EVENT_TIME_TOLERANCE: f64 = 1e-11;

/// The integration method for Model Exchange instances.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Solver {
    /// The default: classical 4th-order Runge-Kutta as [`Solver::Rk4`], each step tested
    /// for stiffness (h rho from its stages beyond RK4's stability bound), continuing with
    /// [`Solver::Bdf`] from the start of the first stiff step, with a note
    /// ([`crate::integrator::switching`]). Its steps before a switch are RK4's to the bit.
    Auto {
        /// Largest RK4 step, s (`None`: the communication step).
        max_step: Option<f64>,
        /// Relative tolerance of the bdf it continues with.
        rtol: f64,
        /// Absolute tolerance of the bdf it continues with.
        atol: f64,
    },
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
    /// Variable-order (1 to 5) variable-step BDF (the NDFs of [`crate::bdf`]) for stiff
    /// models, with the Jacobian from the FMU's directional derivatives where it provides
    /// them, else finite differences, both by column groups of its ModelStructure;
    /// error per state below `atol + rtol |x|`.
    Bdf {
        /// Relative tolerance.
        rtol: f64,
        /// Absolute tolerance.
        atol: f64,
    },
}

impl Default for Solver {
    fn default() -> Self {
        Solver::Auto { max_step: None, rtol: DEFAULT_RTOL, atol: DEFAULT_RTOL / 100.0 }
    }
}

impl Solver {
    /// The solver named `name` (`auto`, `rk4`, `dopri5`, `bdf`): dopri5 and bdf (and the bdf
    /// of auto) with the relative tolerance `rtol` and the absolute tolerance `rtol / 100`,
    /// rk4 (and the rk4 of auto) with the largest step `max_step` (`None`: the
    /// communication step). The error names the bad value.
    pub fn named(name: &str, rtol: f64, max_step: Option<f64>) -> std::result::Result<Solver, String> {
        if !(rtol > 0.0 && rtol.is_finite()) {
            return Err(format!("the relative tolerance {rtol} must be positive"));
        }
        if max_step.is_some_and(|m| !(m > 0.0 && m.is_finite())) {
            return Err(format!("the largest step {} s must be positive", max_step.unwrap_or_default()));
        }
        match name {
            "auto" => Ok(Solver::Auto { max_step, rtol, atol: rtol / 100.0 }),
            "rk4" => Ok(Solver::Rk4 { max_step }),
            "dopri5" => Ok(Solver::Dopri5 { rtol, atol: rtol / 100.0 }),
            "bdf" => Ok(Solver::Bdf { rtol, atol: rtol / 100.0 }),
            other => Err(format!("unknown solver {other:?} (auto, rk4, dopri5, bdf)")),
        }
    }
}

impl Solver {
    /// The integrator of this method for a system of `n` states.
    pub fn integrator(&self, n: usize) -> Box<dyn Integrator> {
        match *self {
            Solver::Auto { max_step, rtol, atol } => Box::new(Switching::new(n, max_step, rtol, atol)),
            Solver::Rk4 { max_step } => Box::new(Rk4::new(n, max_step)),
            Solver::Dopri5 { rtol, atol } => Box::new(Dopri5::new(n, rtol, atol)),
            Solver::Bdf { rtol, atol } => Box::new(crate::bdf::Bdf::new(n, rtol, atol)),
        }
    }
}

/// `auto`, `rk4`, `dopri5` or `bdf` with the default tolerance [`DEFAULT_RTOL`].
impl std::str::FromStr for Solver {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        Solver::named(s, DEFAULT_RTOL, None)
    }
}

/// The relative tolerance of `dopri5` and `bdf` where none is given.
pub const DEFAULT_RTOL: f64 = 1e-6;

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
    /// The states (as the FMU has them after a step or an event).
    pub(crate) x: Vec<f64>,
    /// Scratch: the states where the event indicators are read.
    pub(crate) xt: Vec<f64>,
    /// The event indicators at the start of the step, and at its end (or where read).
    pub(crate) z0: Vec<f64>,
    pub(crate) z: Vec<f64>,
    /// The next time event the FMU asked for at its last event iteration: the input of
    /// the group's time events.
    pub(crate) next_time_event: Option<f64>,
    /// Events so far.
    pub events: Vec<Event>,
    /// Accepted internal steps.
    pub steps: u64,
    /// Rejected internal steps (dopri5, bdf; of the group, held by its first member).
    pub rejected: u64,
    /// The FMU asked to terminate.
    pub terminated: bool,
    /// The work of the bdf solver of this instance's group (held by its first member).
    pub stiff: crate::integrator::Work,
    /// What the solver did differently from what the FMU declares (a directional
    /// derivative that disagrees with finite differences, not used), one sentence each.
    pub notes: Vec<String>,
}

impl MeUnit {
    /// The integration state of `inst`, before any event iteration (the instance stays in
    /// event mode).
    pub fn new(inst: &Instance) -> MeUnit {
        let md = inst.fmu().description();
        let n = md.states().len();
        let m = md.number_of_event_indicators as usize;
        MeUnit {
            x: vec![0.0; n],
            xt: vec![0.0; n],
            z0: vec![0.0; m],
            z: vec![0.0; m],
            next_time_event: None,
            events: Vec::new(),
            steps: 0,
            rejected: 0,
            terminated: false,
            stiff: crate::integrator::Work::default(),
            notes: Vec::new(),
        }
    }

    /// After an event iteration that ended in continuous-time mode: the states and event
    /// indicators as the FMU now has them.
    pub(crate) fn resume(&mut self, inst: &mut Instance) -> Result<()> {
        if !self.x.is_empty() {
            inst.get_continuous_states(&mut self.x)?;
        }
        Self::indicators(inst, &mut self.z0)
    }

    /// The time and the derivatives at (t, x); with no continuous states only the time
    /// (the state functions are never called with nx = 0: some FMUs refuse it).
    /// A NaN derivative returned with OK is an error naming the FMU, the call and the time
    /// (integrated on, it would make every later state NaN without a word).
    #[inline]
    pub(crate) fn derivatives(inst: &mut Instance, t: f64, x: &[f64], dx: &mut [f64]) -> Result<()> {
        inst.set_time(t)?;
        if x.is_empty() {
            return Ok(());
        }
        inst.set_continuous_states(x)?;
        inst.get_derivatives(dx)?;
        if dx.iter().any(|d| d.is_nan()) {
            return Err(nan_derivative(inst, t, dx));
        }
        Ok(())
    }

    /// `fmi2SetContinuousStates`, not called with no continuous states.
    pub(crate) fn set_states(inst: &mut Instance, x: &[f64]) -> Result<()> {
        if x.is_empty() {
            return Ok(());
        }
        Ok(inst.set_continuous_states(x)?)
    }

    /// `fmi2GetEventIndicators`, not called with no event indicators.
    pub(crate) fn indicators(inst: &mut Instance, z: &mut [f64]) -> Result<()> {
        if z.is_empty() {
            return Ok(());
        }
        Ok(inst.get_event_indicators(z)?)
    }

    /// Event indicators at (t, xt) into `z`.
    pub(crate) fn indicators_at(&mut self, inst: &mut Instance, t: f64) -> Result<()> {
        inst.set_time(t)?;
        Self::set_states(inst, &self.xt)?;
        Self::indicators(inst, &mut self.z)
    }

    pub(crate) fn crossed(z0: &[f64], z: &[f64]) -> bool {
        z0.iter().zip(z).any(|(a, b)| (*a > 0.0 && *b <= 0.0) || (*a < 0.0 && *b >= 0.0))
    }

    /// An accepted step of a group's method to `t_new`, whose states are in `x`: the FMU at
    /// (t_new, x) (set unless `there`: its indicators were just read at that point), the
    /// indicators of its end kept as the next step's start, and
    /// `fmi2CompletedIntegratorStep`, whose `terminateSimulation` marks the unit terminated.
    /// Whether the FMU asked for a step event.
    pub(crate) fn complete_step(&mut self, inst: &mut Instance, t_new: f64, there: bool) -> Result<bool> {
        if !there {
            inst.set_time(t_new)?;
            Self::set_states(inst, &self.x)?;
        }
        self.steps += 1;
        std::mem::swap(&mut self.z0, &mut self.z);
        let (step_event, terminate) = inst.completed_integrator_step()?;
        if terminate {
            self.terminated = true;
        }
        Ok(step_event)
    }

    /// The first indicator that crossed from `z0` to `z` (0 when none did).
    pub(crate) fn first_crossing(&self) -> usize {
        self.z0.iter().zip(&self.z).position(|(a, b)| (*a > 0.0 && *b <= 0.0) || (*a < 0.0 && *b >= 0.0)).unwrap_or(0)
    }
}

/// The error of a NaN state derivative the FMU returned with OK.
#[cold]
fn nan_derivative(inst: &Instance, t: f64, dx: &[f64]) -> crate::error::Error {
    let k = dx.iter().position(|d| d.is_nan()).unwrap_or(0);
    let md = inst.fmu().description();
    let variable = md
        .state_derivatives()
        .get(k)
        .and_then(|d| md.variable_at(*d))
        .map_or_else(|| format!("state derivative {}", k + 1), |v| v.name.clone());
    let call = if inst.is_fmi3() { "fmi3GetContinuousStateDerivatives" } else { "fmi2GetDerivatives" };
    let ok = if inst.is_fmi3() { "fmi3OK" } else { "fmi2OK" };
    crate::error::Error::Integration(format!(
        "{} ({}): {call} returned {variable} = NaN with {ok} at t = {t} s",
        inst.name(),
        fmu_file(inst)
    ))
}

/// The file name of the instance's FMU.
pub(crate) fn fmu_file(inst: &Instance) -> String {
    inst.fmu().source().file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default()
}

/// The Illinois method on a bracket [lo, hi] of a crossing, to [`EVENT_TIME_TOLERANCE`]:
/// `probe(s)` says whether the crossing lies at or before `s` and gives the indicator's
/// value there; `z_lo`, `z_hi` are its values at the ends. The end just after the
/// crossing.
pub(crate) fn illinois(
    mut lo: f64,
    mut hi: f64,
    mut z_lo: f64,
    mut z_hi: f64,
    mut probe: impl FnMut(f64) -> Result<(bool, f64)>,
) -> Result<f64> {
    let mut side = 0i32;
    let mut iterations = 0;
    while hi - lo > EVENT_TIME_TOLERANCE && iterations < 200 {
        iterations += 1;
        let mut s = hi - z_hi * (hi - lo) / (z_hi - z_lo);
        if !(s > lo && s < hi && s.is_finite()) {
            s = 0.5 * (lo + hi);
        }
        let (crossed, z) = probe(s)?;
        if crossed {
            hi = s;
            z_hi = z;
            if side == 1 {
                z_lo *= 0.5;
            }
            side = 1;
        } else {
            lo = s;
            z_lo = z;
            if side == -1 {
                z_hi *= 0.5;
            }
            side = -1;
        }
    }
    Ok(hi)
}
