//! The loop of docs/benchmark.md in process: the plant (`nigel_vehicle`, RK4 with two 0.5 ms
//! sub-steps per sample) under the sampled controller with zero-order hold; the nominal
//! reference run, the figure-8 switching table, closed-loop runs and the metric.

use core::f64::consts::PI;
use std::sync::Arc;

use nigel_vehicle::dynamics::idx;
use nigel_vehicle::{integrate, straight_running, Inputs, State, VehicleParams};

use crate::control::{Controller, ControllerInputs, ControllerSettings, SampledController};
use crate::scenario::{
    DisturbanceSequence, Disturbances, Fidelity, Maneuver, Program, Scenario, SettingError, SAMPLE_PERIOD,
};

/// Largest RK4 sub-step inside a sample (two per 1 ms sample) \[s\].
pub const SUBSTEP: f64 = 0.5e-3;

/// Samples at the start of the trajectory, `t_0 .. t_n` (`n + 1` entries each).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trajectory {
    /// World X \[m\].
    pub x: Vec<f64>,
    /// World Y \[m\].
    pub y: Vec<f64>,
    /// Heading, unwrapped (the integral of the yaw rate) \[rad\].
    pub psi: Vec<f64>,
    /// True body slip angle `atan2(v_y, v_x)` \[rad\].
    pub beta: Vec<f64>,
    /// True yaw rate [rad/s].
    pub yaw_rate: Vec<f64>,
    /// True speed `hypot(v_x, v_y)` [m/s].
    pub speed: Vec<f64>,
    /// Steering commanded over `[t_k, t_k+1)`, `n` entries \[rad\].
    pub delta: Vec<[f64; 4]>,
    /// Torque per wheel over `[t_k, t_k+1)`, `n` entries [N.m].
    pub tau: Vec<f64>,
}

impl Trajectory {
    fn with_capacity(n: usize) -> Self {
        Trajectory {
            x: Vec::with_capacity(n + 1),
            y: Vec::with_capacity(n + 1),
            psi: Vec::with_capacity(n + 1),
            beta: Vec::with_capacity(n + 1),
            yaw_rate: Vec::with_capacity(n + 1),
            speed: Vec::with_capacity(n + 1),
            delta: Vec::with_capacity(n),
            tau: Vec::with_capacity(n),
        }
    }

    fn record(&mut self, s: &State<f64>) {
        let (v_x, v_y) = (s[idx::V_X], s[idx::V_Y]);
        self.x.push(s[idx::X]);
        self.y.push(s[idx::Y]);
        self.psi.push(s[idx::PSI]);
        self.beta.push(v_y.atan2(v_x));
        self.yaw_rate.push(s[idx::YAW_RATE]);
        self.speed.push(v_x.hypot(v_y));
    }

    /// Number of samples run (`x.len() - 1`).
    pub fn n_samples(&self) -> usize {
        self.x.len().saturating_sub(1)
    }

    /// Time of entry `k` \[s\].
    pub fn time(k: usize) -> f64 {
        k as f64 * SAMPLE_PERIOD
    }
}

/// Where the steering program comes from inside the loop.
enum Steer<'a> {
    /// A fixed program.
    Program(&'a Program),
    /// The figure-8 of the nominal run: decide the switches from the state (amplitude).
    Figure8Online { amplitude: f64, switches: &'a mut Vec<usize> },
}

/// The one loop every run uses. `reference = None` means `x_ref = x_meas` (only valid with
/// `K = 0`: the reference run itself).
fn run_loop(
    params: &VehicleParams,
    mut steer: Steer<'_>,
    disturbances: &Disturbances,
    settings: ControllerSettings,
    reference: Option<&Reference>,
    speed_ref: f64,
    n: usize,
) -> Result<Trajectory, SettingError> {
    params.validate().map_err(|e| SettingError { name: e.name, value: e.value, reason: e.reason })?;
    let mut controller = SampledController::new(settings)?;
    // the seed's disturbances from the process-wide table (the same numbers as the formulas)
    let disturbances = DisturbanceSequence::new(*disturbances, n);
    let mut s = straight_running(speed_ref);
    let mut traj = Trajectory::with_capacity(n);
    traj.record(&s);
    let mut psi_last = 0.0;
    for k in 0..n {
        let (beta, yaw_rate, speed) = (traj.beta[k], traj.yaw_rate[k], traj.speed[k]);
        let delta_ff = match &mut steer {
            Steer::Program(p) => p.steering(k),
            Steer::Figure8Online { amplitude, switches } => {
                // switch at k iff |psi_k - psi_last| >= 3 pi/2 and |P_k| > |P_(k-1)|
                if k >= 1 {
                    let turned = (traj.psi[k] - psi_last).abs() >= 1.5 * PI;
                    let receding = traj.x[k].hypot(traj.y[k]) > traj.x[k - 1].hypot(traj.y[k - 1]);
                    if turned && receding {
                        switches.push(k);
                        psi_last = traj.psi[k];
                    }
                }
                let f = crate::scenario::figure8_sign(switches, k) * *amplitude;
                [f, f, -f, -f]
            }
        };
        let (beta_meas, yaw_rate_meas) = disturbances.measure(k, beta, yaw_rate);
        let (x, y, psi) = (traj.x[k], traj.y[k], traj.psi[k]);
        let (beta_ref, yaw_rate_ref, x_ref, y_ref, psi_ref) = match reference {
            Some(r) => {
                let t = &r.trajectory;
                (t.beta[k], t.yaw_rate[k], t.x[k], t.y[k], t.psi[k])
            }
            None => (beta_meas, yaw_rate_meas, x, y, psi),
        };
        let out = controller.step(&ControllerInputs {
            beta: beta_meas,
            yaw_rate: yaw_rate_meas,
            speed,
            beta_ref,
            yaw_rate_ref,
            speed_ref,
            delta_ff,
            x,
            y,
            psi,
            x_ref,
            y_ref,
            psi_ref,
        });
        let mut u = Inputs::<f64>::coasting(0.0);
        u.delta = out.delta;
        u.tau = out.tau;
        u.mu = disturbances.friction(k);
        [u.wind_x, u.wind_y] = disturbances.wind(k);
        s = integrate(params, &s, &u, SAMPLE_PERIOD, SUBSTEP);
        traj.delta.push(out.delta);
        traj.tau.push(out.tau[0]);
        traj.record(&s);
    }
    Ok(traj)
}

/// The figure-8 switching table: the samples at which the nominal paper-fidelity car
/// (open loop, the speed loop, `mu = 0.4`, no wind, no noise) flips its steering, one
/// sample after its closest approach to the origin once it has turned `3 pi/2` since the
/// last flip. Computed once and replayed everywhere.
pub fn figure8_switches(amplitude: f64, speed_ref: f64, n_samples: usize) -> Result<Vec<usize>, SettingError> {
    Ok(figure8_nominal_run(amplitude, speed_ref, n_samples)?.0)
}

/// The run behind [`figure8_switches`]: the table and the nominal car's trajectory. That
/// trajectory is the paper-fidelity figure-8 reference itself: the reference run replays
/// the same steering (`figure8_sign(switches, k) * a` at every sample) on the same plant
/// with the same loop, so it reproduces it bit for bit and need not be run again.
fn figure8_nominal_run(
    amplitude: f64,
    speed_ref: f64,
    n_samples: usize,
) -> Result<(Vec<usize>, Trajectory), SettingError> {
    let mut scenario = Scenario::new(Maneuver::Figure8, Fidelity::Paper).undisturbed();
    scenario.steer_amplitude = amplitude;
    scenario.speed_ref = speed_ref;
    scenario.n_samples = n_samples;
    scenario.validate()?;
    let mut switches = Vec::new();
    let trajectory = run_loop(
        &Fidelity::Paper.params(),
        Steer::Figure8Online { amplitude, switches: &mut switches },
        &Disturbances::none(),
        ControllerSettings::with_gain([[0.0; 2]; 4]),
        None,
        speed_ref,
        n_samples,
    )?;
    Ok((switches, trajectory))
}

/// The reference of a column: the open-loop run (`K = 0`, same speed loop) of the column's
/// own plant at `mu_i = 0.4`, no wind, no noise.
#[derive(Clone, Debug, PartialEq)]
pub struct Reference {
    /// The program that drove it.
    pub program: Program,
    /// `t_0 .. t_n`: `beta_ref`, `yaw_rate_ref` and the pose `x_ref, y_ref, psi_ref` per sample.
    pub trajectory: Trajectory,
}

/// Mean-square errors against the reference over the samples `t = 1 ms .. n ms`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metric {
    /// RMSE of world X \[m\].
    pub rmse_x: f64,
    /// RMSE of world Y \[m\].
    pub rmse_y: f64,
    /// RMSE of the unwrapped heading \[rad\].
    pub rmse_psi: f64,
    /// RMSE of the true beta \[rad\].
    pub rmse_beta: f64,
    /// RMSE of the true yaw rate [rad/s].
    pub rmse_yaw_rate: f64,
    /// `epsilon = ||(RMSE_X, RMSE_Y, RMSE_psi)||_2` (Table III).
    pub epsilon: f64,
    /// `||(RMSE_beta, RMSE_r)||_2`, what the controller regulates.
    pub epsilon_state: f64,
}

impl Metric {
    /// The metric of a trajectory against a reference (over the trajectory's samples 1..=n).
    pub fn of(run: &Trajectory, reference: &Trajectory) -> Metric {
        let n = run.n_samples().min(reference.n_samples());
        let rmse = |a: &[f64], b: &[f64]| {
            if n == 0 {
                return 0.0;
            }
            let sum: f64 = (1..=n).map(|k| (a[k] - b[k]) * (a[k] - b[k])).sum();
            (sum / n as f64).sqrt()
        };
        let rmse_x = rmse(&run.x, &reference.x);
        let rmse_y = rmse(&run.y, &reference.y);
        let rmse_psi = rmse(&run.psi, &reference.psi);
        let rmse_beta = rmse(&run.beta, &reference.beta);
        let rmse_yaw_rate = rmse(&run.yaw_rate, &reference.yaw_rate);
        Metric {
            rmse_x,
            rmse_y,
            rmse_psi,
            rmse_beta,
            rmse_yaw_rate,
            epsilon: (rmse_x * rmse_x + rmse_y * rmse_y + rmse_psi * rmse_psi).sqrt(),
            epsilon_state: rmse_beta.hypot(rmse_yaw_rate),
        }
    }
}

/// One closed-loop run: its trajectory and metric.
#[derive(Clone, Debug, PartialEq)]
pub struct ClosedLoopRun {
    /// The controller that ran.
    pub controller: Controller,
    /// What the car did.
    pub trajectory: Trajectory,
    /// Against the reference.
    pub metric: Metric,
}

/// How many references [`Benchmark::prepare`] keeps (about 2.6 MB each for 30 s).
pub const REFERENCE_CACHE_SIZE: usize = 16;

/// Only references of at most this many samples (60 s) are kept, so the cache stays
/// below some 80 MB.
pub const REFERENCE_CACHE_MAX_SAMPLES: usize = 60_000;

/// What a reference depends on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct ReferenceKey {
    maneuver: Maneuver,
    fidelity: Fidelity,
    steer_amplitude: u64,
    speed_ref: u64,
    n_samples: usize,
}

impl ReferenceKey {
    fn of(s: &Scenario) -> Self {
        ReferenceKey {
            maneuver: s.maneuver,
            fidelity: s.fidelity,
            steer_amplitude: s.steer_amplitude.to_bits(),
            speed_ref: s.speed_ref.to_bits(),
            n_samples: s.n_samples,
        }
    }
}

/// One reference of the cache: empty while (or if) it is being computed. Its own lock
/// makes a second thread asking for the same reference wait for the first one's result
/// instead of computing it again (the runs of Table III come in threes per reference).
type ReferenceSlot = Arc<std::sync::Mutex<Option<Arc<Reference>>>>;

/// The most recently used references, newest last.
struct ReferenceCache(std::sync::Mutex<Vec<(ReferenceKey, ReferenceSlot)>>);

impl ReferenceCache {
    /// The slot of `key` (now the most recently used), made (empty) if there is none; the
    /// least recently used slot goes when the cache is full.
    fn slot(&self, key: ReferenceKey) -> ReferenceSlot {
        let mut entries = self.0.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        if let Some(i) = entries.iter().position(|(k, _)| *k == key) {
            let entry = entries.remove(i);
            let slot = entry.1.clone();
            entries.push(entry);
            return slot;
        }
        if entries.len() >= REFERENCE_CACHE_SIZE {
            entries.remove(0);
        }
        let slot = ReferenceSlot::default();
        entries.push((key, slot.clone()));
        slot
    }
}

fn reference_cache() -> &'static ReferenceCache {
    static CACHE: std::sync::OnceLock<ReferenceCache> = std::sync::OnceLock::new();
    CACHE.get_or_init(|| ReferenceCache(std::sync::Mutex::new(Vec::new())))
}

/// A scenario made ready: its program (with the figure-8 table) and its reference.
#[derive(Clone, Debug, PartialEq)]
pub struct Benchmark {
    /// The scenario.
    pub scenario: Scenario,
    /// The column's reference (its program is the one every run uses).
    pub reference: Reference,
}

impl Benchmark {
    /// Validates the scenario, computes the figure-8 table (figure-8 only) and the reference.
    ///
    /// The reference depends only on the maneuver, the fidelity, the amplitude, the speed and
    /// the length (not on the seed or the disturbance switches), and a 30 s reference costs as
    /// much as a closed-loop run: the last [`REFERENCE_CACHE_SIZE`] references are kept for
    /// the process and handed out again (bit-identical, they are the same numbers), so that
    /// 36 runs of Table III, or many instances of the test-bench FMU, compute 12 of them.
    pub fn prepare(scenario: Scenario) -> Result<Benchmark, SettingError> {
        Ok(Benchmark { scenario, reference: Reference::clone(&*Self::shared_reference(scenario)?) })
    }

    /// The reference of [`Benchmark::prepare`] without a copy: the one the process cache
    /// holds (computed first if need be; a thread asking for a reference another thread is
    /// computing waits for that one instead of computing it again).
    pub fn shared_reference(scenario: Scenario) -> Result<Arc<Reference>, SettingError> {
        scenario.validate()?;
        if scenario.n_samples > REFERENCE_CACHE_MAX_SAMPLES {
            return Ok(Arc::new(Self::prepare_uncached(scenario)?.reference));
        }
        let slot = reference_cache().slot(ReferenceKey::of(&scenario));
        // held while computing: a concurrent request for the same reference waits for it
        let mut cached = slot.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        if let Some(reference) = cached.as_ref() {
            return Ok(reference.clone());
        }
        let reference = Arc::new(Self::prepare_uncached(scenario)?.reference);
        *cached = Some(reference.clone());
        Ok(reference)
    }

    /// [`Benchmark::prepare`] without the cache. The paper-fidelity figure-8 reference is
    /// the trajectory of the run that finds its switching table ([`figure8_nominal_run`]);
    /// the real-fidelity one takes its table from that reference, through the cache (so
    /// that it is computed once, and waited for if another thread is computing it).
    fn prepare_uncached(scenario: Scenario) -> Result<Benchmark, SettingError> {
        if scenario.maneuver != Maneuver::Figure8 {
            return Self::prepare_with_switches(scenario, Vec::new());
        }
        let (amplitude, speed, n) = (scenario.steer_amplitude, scenario.speed_ref, scenario.n_samples);
        match scenario.fidelity {
            Fidelity::Paper => {
                let (switches, trajectory) = figure8_nominal_run(amplitude, speed, n)?;
                let program = Program::new(scenario.maneuver, amplitude, switches);
                Ok(Benchmark { scenario, reference: Reference { program, trajectory } })
            }
            Fidelity::Real => {
                let paper = Scenario { fidelity: Fidelity::Paper, ..scenario };
                let switches = Self::shared_reference(paper)?.program.switches.clone();
                Self::prepare_with_switches(scenario, switches)
            }
        }
    }

    /// As [`Benchmark::prepare`] with a figure-8 table given (e.g. shared between columns).
    pub fn prepare_with_switches(scenario: Scenario, switches: Vec<usize>) -> Result<Benchmark, SettingError> {
        scenario.validate()?;
        let program = Program::new(scenario.maneuver, scenario.steer_amplitude, switches);
        let trajectory = run_loop(
            &scenario.fidelity.params(),
            Steer::Program(&program),
            &Disturbances::none(),
            ControllerSettings::with_gain([[0.0; 2]; 4]),
            None,
            scenario.speed_ref,
            scenario.n_samples,
        )?;
        Ok(Benchmark { scenario, reference: Reference { program, trajectory } })
    }

    /// The program every run of this benchmark uses.
    pub fn program(&self) -> &Program {
        &self.reference.program
    }

    /// A closed-loop run with `controller`'s settings ([`Controller::settings`]: its gains,
    /// the speed loop of docs/benchmark.md, and for the tracking controller the along-track loop).
    pub fn run(&self, controller: Controller) -> Result<ClosedLoopRun, SettingError> {
        self.run_with(controller, controller.settings())
    }

    /// A closed-loop run with any settings (the gains in `settings` are the ones used).
    pub fn run_with(
        &self,
        controller: Controller,
        settings: ControllerSettings,
    ) -> Result<ClosedLoopRun, SettingError> {
        let s = &self.scenario;
        let trajectory = run_loop(
            &s.fidelity.params(),
            Steer::Program(&self.reference.program),
            &s.disturbances(),
            settings,
            Some(&self.reference),
            s.speed_ref,
            s.n_samples,
        )?;
        let metric = Metric::of(&trajectory, &self.reference.trajectory);
        Ok(ClosedLoopRun { controller, trajectory, metric })
    }
}

/// Everything the test bench puts out at sample `k` (held over `[t_k, t_k+1)`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BenchSample {
    /// Feed-forward steering, the program \[rad\], FL, FR, RL, RR.
    pub delta_ff: [f64; 4],
    /// Reference body slip angle \[rad\].
    pub beta_ref: f64,
    /// Reference yaw rate [rad/s].
    pub yaw_rate_ref: f64,
    /// Speed to hold [m/s].
    pub speed_ref: f64,
    /// Reference pose: world X \[m\].
    pub x_ref: f64,
    /// Reference pose: world Y \[m\].
    pub y_ref: f64,
    /// Reference pose: heading, unwrapped \[rad\].
    pub psi_ref: f64,
    /// Road friction per wheel [-].
    pub mu: [f64; 4],
    /// Wind along world X \[N\] (always 0 in docs/benchmark.md).
    pub wind_x: f64,
    /// Wind along world Y \[N\].
    pub wind_y: f64,
    /// What the controller measures: beta \[rad\].
    pub beta_meas: f64,
    /// What the controller measures: yaw rate [rad/s].
    pub yaw_rate_meas: f64,
}

impl Benchmark {
    /// Number of samples the reference covers: outputs exist for `k = 0 ..= n_samples`.
    pub fn horizon(&self) -> usize {
        self.reference.trajectory.n_samples()
    }

    /// The test bench at sample 0 without computing anything: the reference starts at the
    /// origin, heading +X, at `speed_ref` (so `beta_ref = r_ref = 0`), and every program's
    /// first sample is known (the figure-8 starts with front +a). Equal to
    /// `Benchmark::prepare(scenario)?.sample(0, beta, yaw_rate)`.
    pub fn initial_sample(scenario: &Scenario, beta: f64, yaw_rate: f64) -> BenchSample {
        let program = Program::new(scenario.maneuver, scenario.steer_amplitude, Vec::new());
        let d = scenario.disturbances();
        let (beta_meas, yaw_rate_meas) = d.measure(0, beta, yaw_rate);
        BenchSample {
            delta_ff: program.steering(0),
            beta_ref: 0.0,
            yaw_rate_ref: 0.0,
            speed_ref: scenario.speed_ref,
            x_ref: 0.0,
            y_ref: 0.0,
            psi_ref: 0.0,
            mu: d.friction(0),
            wind_x: d.wind(0)[0],
            wind_y: d.wind(0)[1],
            beta_meas,
            yaw_rate_meas,
        }
    }

    /// The test bench at sample `k` given the plant's true `beta` and `yaw_rate` there;
    /// `None` beyond the reference ([`Benchmark::horizon`]).
    pub fn sample(&self, k: usize, beta: f64, yaw_rate: f64) -> Option<BenchSample> {
        let d = self.scenario.disturbances();
        bench_sample(&self.scenario, &self.reference, k, d.friction(k), d.wind(k), d.measure(k, beta, yaw_rate))
    }
}

/// A benchmark as the test bench plays it, sample by sample: the reference shared with the
/// process cache ([`Benchmark::shared_reference`], no copy) and the disturbances read from
/// the seed's table ([`DisturbanceSequence`]). [`BenchSampler::sample`] is exactly (bit for
/// bit) [`Benchmark::sample`], without drawing the noise again at every sample.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchSampler {
    scenario: Scenario,
    reference: Arc<Reference>,
    disturbances: DisturbanceSequence,
}

impl BenchSampler {
    /// Validates the scenario and takes its reference (computed if need be, see
    /// [`Benchmark::prepare`]) and its disturbance table.
    pub fn prepare(scenario: Scenario) -> Result<BenchSampler, SettingError> {
        let reference = Benchmark::shared_reference(scenario)?;
        let disturbances = DisturbanceSequence::new(scenario.disturbances(), scenario.n_samples);
        Ok(BenchSampler { scenario, reference, disturbances })
    }

    /// The scenario.
    pub fn scenario(&self) -> &Scenario {
        &self.scenario
    }

    /// The column's reference and program.
    pub fn reference(&self) -> &Reference {
        &self.reference
    }

    /// [`Benchmark::horizon`].
    pub fn horizon(&self) -> usize {
        self.reference.trajectory.n_samples()
    }

    /// [`Benchmark::sample`].
    pub fn sample(&self, k: usize, beta: f64, yaw_rate: f64) -> Option<BenchSample> {
        let d = &self.disturbances;
        bench_sample(&self.scenario, &self.reference, k, d.friction(k), d.wind(k), d.measure(k, beta, yaw_rate))
    }
}

/// The test bench's outputs at sample `k` of `scenario` (`None` past the reference's end):
/// the program's steering and the reference, with the sample's disturbances (friction
/// `mu`, wind `[wind_x, wind_y]`, the measured `(beta, yaw_rate)`) as given.
#[inline]
fn bench_sample(
    scenario: &Scenario,
    reference: &Reference,
    k: usize,
    mu: [f64; 4],
    [wind_x, wind_y]: [f64; 2],
    (beta_meas, yaw_rate_meas): (f64, f64),
) -> Option<BenchSample> {
    let r = &reference.trajectory;
    if k > r.n_samples() {
        return None;
    }
    Some(BenchSample {
        delta_ff: reference.program.steering(k),
        beta_ref: r.beta[k],
        yaw_rate_ref: r.yaw_rate[k],
        speed_ref: scenario.speed_ref,
        x_ref: r.x[k],
        y_ref: r.y[k],
        psi_ref: r.psi[k],
        mu,
        wind_x,
        wind_y,
        beta_meas,
        yaw_rate_meas,
    })
}

/// One cell of Table III.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TableCell {
    /// The column.
    pub fidelity: Fidelity,
    /// The row.
    pub maneuver: Maneuver,
    /// The controller.
    pub controller: Controller,
    /// `epsilon` and the rest.
    pub metric: Metric,
}

/// Table III of docs/benchmark.md for one seed: every fidelity, maneuver and controller of
/// `controllers` (the figure-8 table computed once), on up to `threads` threads (0 = all
/// cores). Cells come in the order fidelity, maneuver, controller.
pub fn table3(seed: u64, controllers: &[Controller], threads: usize) -> Result<Vec<TableCell>, SettingError> {
    let scenario = |fidelity, maneuver| Scenario { seed, ..Scenario::new(maneuver, fidelity) };
    scenario(Fidelity::Paper, Maneuver::Straight).validate()?;
    let switches = figure8_switches(crate::DEFAULT_STEER_AMPLITUDE, crate::DEFAULT_SPEED, crate::N_SAMPLES)?;
    let jobs: Vec<(Fidelity, Maneuver)> =
        Fidelity::ALL.iter().flat_map(|&f| Maneuver::ALL.iter().map(move |&m| (f, m))).collect();
    let work = |&(fidelity, maneuver): &(Fidelity, Maneuver)| -> Result<Vec<TableCell>, SettingError> {
        let sw = if maneuver == Maneuver::Figure8 { switches.clone() } else { Vec::new() };
        let bench = Benchmark::prepare_with_switches(scenario(fidelity, maneuver), sw)?;
        controllers
            .iter()
            .map(|&controller| Ok(TableCell { fidelity, maneuver, controller, metric: bench.run(controller)?.metric }))
            .collect()
    };
    let threads = match threads {
        0 => std::thread::available_parallelism().map_or(1, |n| n.get()),
        t => t,
    }
    .clamp(1, jobs.len());
    let next = std::sync::atomic::AtomicUsize::new(0);
    type Slot = std::sync::Mutex<Option<Result<Vec<TableCell>, SettingError>>>;
    let slots: Vec<Slot> = jobs.iter().map(|_| std::sync::Mutex::new(None)).collect();
    std::thread::scope(|s| {
        for _ in 0..threads {
            s.spawn(|| loop {
                let i = next.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
                let Some(job) = jobs.get(i) else { break };
                let result = work(job);
                if let Ok(mut slot) = slots[i].lock() {
                    *slot = Some(result);
                }
            });
        }
    });
    let mut cells = Vec::with_capacity(jobs.len() * controllers.len());
    for slot in slots {
        let unfinished = SettingError { name: "table3", value: f64::NAN, reason: "a worker thread did not finish" };
        let result = slot.into_inner().ok().flatten().unwrap_or(Err(unfinished));
        cells.extend(result?);
    }
    Ok(cells)
}
