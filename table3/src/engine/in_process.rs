//! The in-process engine: `nigel_benchmark`'s own loop (plant, sampled controller, test
//! bench in one Rust function), the independent implementation the FMU run must match.

use std::sync::OnceLock;

use nigel_benchmark::{figure8_switches, Benchmark, Fidelity, Maneuver, Reference, Scenario, SettingError};

use super::{Engine, Job, Run};
use crate::Error;

type Cached<T> = OnceLock<Result<T, SettingError>>;

/// `nigel_benchmark` in process. The figure-8 switching table and the reference of each
/// (column, maneuver) are computed once and shared by the runs that need them.
#[derive(Default)]
pub struct InProcess {
    switches: Cached<Vec<usize>>,
    references: [[Cached<Reference>; 6]; 2],
}

impl InProcess {
    /// An engine with empty caches.
    pub fn new() -> InProcess {
        InProcess::default()
    }

    fn reference(&self, fidelity: Fidelity, maneuver: Maneuver) -> Result<&Reference, Error> {
        let f = Fidelity::ALL.iter().position(|&x| x == fidelity).unwrap_or(0);
        let m = Maneuver::ALL.iter().position(|&x| x == maneuver).unwrap_or(0);
        let cached = self.references[f][m].get_or_init(|| {
            let switches = match maneuver {
                Maneuver::Figure8 => self
                    .switches
                    .get_or_init(|| {
                        figure8_switches(
                            nigel_benchmark::DEFAULT_STEER_AMPLITUDE,
                            nigel_benchmark::DEFAULT_SPEED,
                            nigel_benchmark::N_SAMPLES,
                        )
                    })
                    .clone()?,
                _ => Vec::new(),
            };
            Ok(Benchmark::prepare_with_switches(Scenario::new(maneuver, fidelity), switches)?.reference)
        });
        cached.as_ref().map_err(|e| Error::Setting(e.clone()))
    }
}

impl Engine for InProcess {
    fn name(&self) -> String {
        "in-process (nigel_benchmark)".into()
    }

    fn run(&self, job: &Job) -> Result<Run, Error> {
        let mut scenario = Scenario { seed: job.seed, ..Scenario::new(job.maneuver, job.fidelity) };
        if !job.disturbed {
            scenario = scenario.undisturbed();
        }
        scenario.validate()?;
        let bench = Benchmark { scenario, reference: self.reference(job.fidelity, job.maneuver)?.clone() };
        let run = bench.run(job.controller)?;
        let t = run.trajectory;
        let r = &bench.reference.trajectory;
        let d = scenario.disturbances();
        let n = t.n_samples();
        let run = Run {
            job: *job,
            gain: job.controller.feedback_gain(),
            x: t.x,
            y: t.y,
            psi: t.psi,
            beta: t.beta,
            yaw_rate: t.yaw_rate,
            x_ref: r.x[..=n].to_vec(),
            y_ref: r.y[..=n].to_vec(),
            psi_ref: r.psi[..=n].to_vec(),
            beta_ref: r.beta[..=n].to_vec(),
            yaw_rate_ref: r.yaw_rate[..=n].to_vec(),
            delta: t.delta,
            mu: (0..n).map(|k| d.friction(k)).collect(),
        };
        run.check()?;
        Ok(run)
    }
}
