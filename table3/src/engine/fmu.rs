//! The FMU engine: the three `.fmu` archives built by `build-fmu`, imported through the C
//! ABI by the `nigel_cosim` master and co-simulated with fixed 1 ms steps for 30 s
//! (`ordered` by default: every output reaches its inputs at the same communication
//! point along the direct-feedthrough chain plant -> test bench -> controller -> plant).
//! The controller gets the pose too (plant `x, y, psi`, test bench `x_ref, y_ref,
//! psi_ref`), for every controller; only `robust_tracking` reads it.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use nigel_benchmark::fmu_system::{self, StartValue};
use nigel_benchmark::{Controller, Fidelity, Maneuver, N_SAMPLES, SAMPLE_PERIOD};
use nigel_cosim::{simulate, Algorithm, Experiment, Fmu, Results, System, SystemBuilder, Value};

use super::{Engine, Job, Run};
use crate::Error;
use nigel_benchmark::WHEELS;

/// File names of the plant, the controller and the test bench in `target/fmu/`.
pub const FMU_FILES: [&str; 3] = ["nigel_plant.fmu", "nigel_controller.fmu", "nigel_maneuver.fmu"];

/// The closed loop of Table III from the three FMUs.
pub struct FmuEngine {
    plant: Arc<Fmu>,
    controller: Arc<Fmu>,
    maneuver: Arc<Fmu>,
    maneuver_values: [i32; 6],
    fidelity_values: [i32; 2],
    controller_values: [i32; 4],
    /// The controller FMU's value of `custom` (the tunable `k_*` gain).
    custom_value: i32,
    gains: [[[f64; 4]; 4]; 4],
    /// How the master exchanges values (`Ordered`, the table's; `Jacobi` delays every
    /// connection by one step).
    pub algorithm: Algorithm,
}

/// The folder `build-fmu` writes to: `$CARGO_TARGET_DIR/fmu`, else `<workspace>/target/fmu`.
pub fn default_fmu_dir() -> PathBuf {
    match std::env::var_os("CARGO_TARGET_DIR") {
        Some(t) if Path::new(&t).is_absolute() => PathBuf::from(t).join("fmu"),
        Some(t) => Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(t).join("fmu"),
        None => Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/fmu"),
    }
}

fn load(path: &Path) -> Result<Arc<Fmu>, Error> {
    if !path.is_file() {
        return Err(Error::MissingFmu { path: path.to_path_buf() });
    }
    Fmu::load(path)
        .map_err(|source| Error::Cosim { context: format!("loading {}", path.display()), source: source.into() })
}

/// The value of each name of `names` for the switch `variable` of `fmu`.
///
/// Our FMUs declare their switches (`maneuver`, `fidelity`, `controller`) as plain Integer
/// parameters whose values are the 1-based positions of `names` (the contract written in
/// each variable's description and the FMU documentation): the declared `min`/`max` must
/// cover them. An FMU that declares the switch as an Enumeration (our FMUs before the
/// switches became Integers, or a user's own FMU) is read by item name instead.
fn switch_values<const N: usize>(fmu: &Fmu, file: &str, variable: &str, names: [&str; N]) -> Result<[i32; N], Error> {
    use model_description::VariableType;
    let bad = |reason: String| Error::BadRun { run: format!("{file}: {variable}"), reason };
    let md = fmu.description();
    let v = md.variable(variable).ok_or_else(|| bad("no such variable".into()))?;
    let mut out = [0; N];
    match &v.variable_type {
        VariableType::Integer { min, max, .. } => {
            let (lo, hi) = (min.unwrap_or(i32::MIN), max.unwrap_or(i32::MAX));
            if lo > 1 || hi < N as i32 {
                return Err(bad(format!(
                    "declared in {lo} ..= {hi}, but the values of {names:?} are 1 ..= {N}: not the switch this \
                     engine sets"
                )));
            }
            for (k, o) in out.iter_mut().enumerate() {
                *o = k as i32 + 1;
            }
        }
        VariableType::Enumeration { declared_type, .. } => {
            let t = md
                .type_definitions
                .iter()
                .find(|t| &t.name == declared_type)
                .ok_or_else(|| bad(format!("enumeration type {declared_type:?} is not defined")))?;
            for (o, name) in out.iter_mut().zip(names) {
                *o = t.items.iter().find(|i| i.name == name).map(|i| i.value).ok_or_else(|| {
                    bad(format!(
                        "has no item {name:?} (items: {:?})",
                        t.items.iter().map(|i| i.name.as_str()).collect::<Vec<_>>()
                    ))
                })?;
            }
        }
        other => return Err(bad(format!("is a {}, not an Integer", other.type_name()))),
    }
    Ok(out)
}

/// The calculated parameters `gain_*` of the controller FMU with `controller = value`
/// (columns `e_y, e_psi, beta, yaw_rate`), read after initialization by the master (a run
/// of zero steps).
fn controller_gain(fmu: &Arc<Fmu>, value: i32) -> Result<[[f64; 4]; 4], Error> {
    let ctx = |source| Error::Cosim { context: format!("reading the gains of {}", FMU_FILES[1]), source };
    let mut b = SystemBuilder::new();
    b.add_instance("controller", fmu.clone()).map_err(ctx)?;
    b.set("controller.controller", Value::Integer(value)).map_err(ctx)?;
    let names: Vec<String> = WHEELS
        .iter()
        .flat_map(|w| ["e_y", "e_psi", "beta", "yaw_rate"].map(|c| format!("controller.gain_{c}_{w}")))
        .collect();
    let experiment = Experiment { record: Some(names.clone()), ..Experiment::new(0.0, SAMPLE_PERIOD) };
    let (results, _) = simulate(&b.build(), &experiment).map_err(ctx)?;
    let mut k = [[0.0; 4]; 4];
    for (i, name) in names.iter().enumerate() {
        let bare = name.trim_start_matches("controller.");
        let v = results
            .column(bare)
            .and_then(|c| c.first().copied())
            .ok_or_else(|| Error::BadRun { run: FMU_FILES[1].into(), reason: format!("no value of {name}") })?;
        k[i / 4][i % 4] = v;
    }
    Ok(k)
}

fn index<T: PartialEq>(all: &[T], x: &T) -> usize {
    all.iter().position(|a| a == x).unwrap_or(0)
}

impl FmuEngine {
    /// Loads `nigel_plant.fmu`, `nigel_controller.fmu` and `nigel_maneuver.fmu` from `dir`.
    pub fn load_dir(dir: &Path) -> Result<FmuEngine, Error> {
        FmuEngine::load(&dir.join(FMU_FILES[0]), &dir.join(FMU_FILES[1]), &dir.join(FMU_FILES[2]))
    }

    /// Loads the three archives from the default folder ([`default_fmu_dir`]).
    pub fn load_default() -> Result<FmuEngine, Error> {
        FmuEngine::load_dir(&default_fmu_dir())
    }

    /// Loads the three archives and resolves the values of the switches it sets.
    pub fn load(plant: &Path, controller: &Path, maneuver: &Path) -> Result<FmuEngine, Error> {
        let (p, c, m) = (load(plant)?, load(controller)?, load(maneuver)?);
        let maneuver_values = switch_values(&m, FMU_FILES[2], "maneuver", Maneuver::ALL.map(|x| x.name()))?;
        let fidelity_values = switch_values(&m, FMU_FILES[2], "fidelity", Fidelity::ALL.map(|x| x.name()))?;
        // the controller FMU's values are the positions in its whole list, `custom` (4)
        // included: robust_tracking is 5, not the 4th of the controllers run here
        let all = switch_values(
            &c,
            FMU_FILES[1],
            "controller",
            ["open_loop", "pole_placement", "robust", "custom", "robust_tracking"],
        )?;
        let controller_values = [all[0], all[1], all[2], all[4]];
        let mut gains = [[[0.0; 4]; 4]; 4];
        for (g, value) in gains.iter_mut().zip(controller_values) {
            *g = controller_gain(&c, value)?;
        }
        Ok(FmuEngine {
            plant: p,
            controller: c,
            maneuver: m,
            maneuver_values,
            fidelity_values,
            controller_values,
            custom_value: all[3],
            gains,
            algorithm: Algorithm::Ordered,
        })
    }

    /// The gain the controller FMU uses for each controller of [`Controller::WITH_TRACKING`]
    /// (its calculated parameters `gain_e_y_fl .. gain_yaw_rate_rr` after initialization).
    pub fn gains(&self) -> [[[f64; 4]; 4]; 4] {
        self.gains
    }

    /// The same engine with another communication algorithm.
    pub fn with_algorithm(mut self, algorithm: Algorithm) -> FmuEngine {
        self.algorithm = algorithm;
        self
    }

    /// The system of one job: three instances `plant`, `controller`, `maneuver`, their
    /// parameters and the closed-loop connections, as [`nigel_benchmark::fmu_system`]
    /// describes them (docs/closed-loop.svg); the switches take the values read from these
    /// FMUs' declarations.
    pub fn system(&self, job: &Job) -> Result<System, Error> {
        let ctx = |source| Error::Cosim { context: format!("building the system of {}", job.label()), source };
        // the controller FMU's switch value; a custom gain runs as `custom` with its k_* set
        let controller_value = match job.controller {
            Controller::Custom(_) => self.custom_value,
            c => {
                let i = Controller::WITH_TRACKING.iter().position(|x| *x == c).ok_or_else(|| {
                    Error::Usage(format!(
                        "the controller FMU runs open_loop, pole_placement, robust, robust_tracking and custom gains, not {c}"
                    ))
                })?;
                self.controller_values[i]
            }
        };
        let description = fmu_system::closed_loop(job.fidelity, job.maneuver, job.controller, job.seed, job.disturbed)
            .map_err(Error::Usage)?;
        let mut b = SystemBuilder::new();
        for (instance, fmu) in description.instances.iter().zip([&self.plant, &self.controller, &self.maneuver]) {
            b.add_instance(instance.0, fmu.clone()).map_err(ctx)?;
        }
        for (name, value) in &description.parameters {
            let value = match (name.as_str(), *value) {
                ("maneuver.maneuver", _) => Value::Integer(self.maneuver_values[index(&Maneuver::ALL, &job.maneuver)]),
                ("maneuver.fidelity", _) => Value::Integer(self.fidelity_values[index(&Fidelity::ALL, &job.fidelity)]),
                ("controller.controller", _) => Value::Integer(controller_value),
                (_, StartValue::Real(x)) => Value::Real(x),
                (_, StartValue::Integer(n)) => Value::Integer(n),
                (_, StartValue::Boolean(v)) => Value::Boolean(v),
            };
            b.set(name, value).map_err(ctx)?;
        }
        for (from, to) in &description.connections {
            b.connect(from, to).map_err(ctx)?;
        }
        Ok(b.build())
    }

    /// Writes the closed loop of `job` as an SSP 1.0 archive (`SystemStructure.ssd` and the
    /// three FMUs; parameters as inline bindings), to run in other tools (fmpy's
    /// `simulate_ssp`, ecos, libcosim). Its default experiment is 0 .. 30 s.
    pub fn write_ssp(&self, job: &Job, path: &Path) -> Result<(), Error> {
        let system = self.system(job)?;
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(crate::error::io(dir))?;
        }
        nigel_cosim::write_ssp(&system, "nigel_closed_loop", Some(N_SAMPLES as f64 * SAMPLE_PERIOD), path)
            .map_err(|source| Error::Cosim { context: format!("writing {}", path.display()), source })
    }

    /// The variables a run records.
    pub fn recorded() -> Vec<String> {
        let mut v: Vec<String> = ["plant.x", "plant.y", "plant.psi", "plant.beta", "plant.yaw_rate"]
            .into_iter()
            .chain([
                "maneuver.x_ref",
                "maneuver.y_ref",
                "maneuver.psi_ref",
                "maneuver.beta_ref",
                "maneuver.yaw_rate_ref",
            ])
            .map(String::from)
            .collect();
        for stem in ["controller.delta", "maneuver.mu"] {
            v.extend(WHEELS.iter().map(|w| format!("{stem}_{w}")));
        }
        v
    }
}

/// The columns `names` of `results` (as [`Results::column`] gives them), read in one pass
/// over the rows: one column at a time would walk the whole row-major table once per
/// column.
fn columns(results: &Results, names: &[String], job: &Job) -> Result<Vec<Vec<f64>>, Error> {
    let index = names
        .iter()
        .map(|name| {
            let j = results.names.iter().position(|n| n == name).ok_or_else(|| Error::BadRun {
                run: job.label(),
                reason: format!("no column {name} in the results"),
            })?;
            Ok(j + 1)
        })
        .collect::<Result<Vec<usize>, Error>>()?;
    let rows = results.rows();
    let mut columns: Vec<Vec<f64>> = names.iter().map(|_| Vec::with_capacity(rows)).collect();
    for k in 0..rows {
        let row = results.row(k);
        for (column, &j) in columns.iter_mut().zip(&index) {
            column.push(row[j]);
        }
    }
    Ok(columns)
}

impl Engine for FmuEngine {
    fn name(&self) -> String {
        let alg = match self.algorithm {
            Algorithm::Ordered => "ordered",
            Algorithm::Jacobi => "jacobi",
        };
        format!("FMUs via nigel_cosim ({alg}, 1 ms)")
    }

    fn run(&self, job: &Job) -> Result<Run, Error> {
        self.run_system(&self.system(job)?, job)
    }
}

impl FmuEngine {
    /// Runs `system` (instances `plant`, `controller`, `maneuver` wired for `job`, e.g. an
    /// SSP read back with `nigel_cosim::read_ssp`) over the benchmark horizon and records it.
    pub fn run_system(&self, system: &System, job: &Job) -> Result<Run, Error> {
        let recorded = FmuEngine::recorded();
        let experiment = Experiment {
            algorithm: self.algorithm,
            record: Some(recorded.clone()),
            ..Experiment::new(N_SAMPLES as f64 * SAMPLE_PERIOD, SAMPLE_PERIOD)
        };
        let (results, _summary) =
            simulate(system, &experiment).map_err(|source| Error::Cosim { context: job.label(), source })?;
        let mut all = columns(&results, &recorded, job)?;
        let mut col = |name: &str| -> Result<Vec<f64>, Error> {
            let i = recorded
                .iter()
                .position(|r| r == name)
                .ok_or_else(|| Error::BadRun { run: job.label(), reason: format!("{name} is not recorded") })?;
            Ok(std::mem::take(&mut all[i]))
        };
        let n = results.rows().saturating_sub(1);
        let (x, y, psi, beta, yaw_rate) =
            (col("plant.x")?, col("plant.y")?, col("plant.psi")?, col("plant.beta")?, col("plant.yaw_rate")?);
        let (x_ref, y_ref, psi_ref, beta_ref, yaw_rate_ref) = (
            col("maneuver.x_ref")?,
            col("maneuver.y_ref")?,
            col("maneuver.psi_ref")?,
            col("maneuver.beta_ref")?,
            col("maneuver.yaw_rate_ref")?,
        );
        let mut wheels = |stem: &str| -> Result<Vec<[f64; 4]>, Error> {
            let c: Vec<Vec<f64>> = WHEELS.iter().map(|w| col(&format!("{stem}_{w}"))).collect::<Result<_, _>>()?;
            Ok((0..n).map(|k| [c[0][k], c[1][k], c[2][k], c[3][k]]).collect())
        };
        let (delta, mu) = (wheels("controller.delta")?, wheels("maneuver.mu")?);
        let gain = match job.controller {
            // the custom gain is the one set above (the FMU applies k_* as given)
            Controller::Custom(_) => job.controller.feedback_gain(),
            c => self.gains[index(&Controller::WITH_TRACKING, &c)],
        };
        let run = Run {
            job: *job,
            gain,
            x,
            y,
            psi,
            beta,
            yaw_rate,
            x_ref,
            y_ref,
            psi_ref,
            beta_ref,
            yaw_rate_ref,
            delta,
            mu,
        };
        run.check()?;
        Ok(run)
    }
}
