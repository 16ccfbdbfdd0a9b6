//! The table of one seed: every (column) x (maneuver) x (controller) job run in parallel
//! on an [`Engine`], each scored with [`Metric`].

use std::time::Instant;

use rayon::prelude::*;

use crate::{Controller, Engine, Error, Fidelity, Job, Maneuver, Metric, Run};

/// One cell of Table III.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cell {
    /// The column.
    pub fidelity: Fidelity,
    /// The row.
    pub maneuver: Maneuver,
    /// The controller.
    pub controller: Controller,
    /// Its metric.
    pub metric: Metric,
}

/// Table III for one seed.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    /// The seed.
    pub seed: u64,
    /// What ran it ([`Engine::name`]).
    pub engine: String,
    /// The gains the controllers used, read back from the runs (`pole_placement`, `robust`,
    /// `robust_tracking`; columns `[e_y, e_psi, beta, yaw_rate]`, see [`Run::gain`]).
    pub gains: Vec<(Controller, [[f64; 4]; 4])>,
    /// The cells in the order column, maneuver, controller.
    pub cells: Vec<Cell>,
    /// Wall time of the whole table \[s\].
    pub wall_s: f64,
}

impl Table {
    /// The cell of `(fidelity, maneuver, controller)`.
    pub fn get(&self, fidelity: Fidelity, maneuver: Maneuver, controller: Controller) -> Option<&Cell> {
        self.cells.iter().find(|c| c.fidelity == fidelity && c.maneuver == maneuver && c.controller == controller)
    }

    /// The controller of lowest epsilon in a row (`None` for a row not run).
    pub fn lowest(&self, fidelity: Fidelity, maneuver: Maneuver) -> Option<Controller> {
        self.cells
            .iter()
            .filter(|c| c.fidelity == fidelity && c.maneuver == maneuver)
            .min_by(|a, b| a.metric.eps.total_cmp(&b.metric.eps))
            .map(|c| c.controller)
    }

    /// The columns present, in table order.
    pub fn fidelities(&self) -> Vec<Fidelity> {
        Fidelity::ALL.into_iter().filter(|f| self.cells.iter().any(|c| c.fidelity == *f)).collect()
    }

    /// The maneuvers present, in table order.
    pub fn maneuvers(&self) -> Vec<Maneuver> {
        Maneuver::ALL.into_iter().filter(|m| self.cells.iter().any(|c| c.maneuver == *m)).collect()
    }

    /// The controllers present, in table order.
    pub fn controllers(&self) -> Vec<Controller> {
        let mut v: Vec<Controller> =
            crate::CONTROLLERS.into_iter().filter(|k| self.cells.iter().any(|c| c.controller == *k)).collect();
        // custom gains after the named controllers, in the order they ran
        for c in &self.cells {
            if matches!(c.controller, Controller::Custom(_)) && !v.contains(&c.controller) {
                v.push(c.controller);
            }
        }
        v
    }
}

/// What to run.
#[derive(Clone, Debug)]
pub struct Options {
    /// Noise seed.
    pub seed: u64,
    /// Worker threads (0: one per core).
    pub threads: usize,
    /// The columns (default both).
    pub fidelities: Vec<Fidelity>,
    /// The rows (default all six).
    pub maneuvers: Vec<Maneuver>,
    /// The controllers (default the paper's three and `robust_tracking`).
    pub controllers: Vec<Controller>,
    /// Keep every run's recorded series (for CSV and plots; about 4.3 MB a run).
    pub keep_runs: bool,
}

impl Options {
    /// The whole table of `seed` on every core, runs not kept.
    pub fn new(seed: u64) -> Options {
        Options {
            seed,
            threads: 0,
            fidelities: Fidelity::ALL.to_vec(),
            maneuvers: Maneuver::ALL.to_vec(),
            controllers: crate::CONTROLLERS.to_vec(),
            keep_runs: false,
        }
    }

    /// The jobs in table order (column, maneuver, controller).
    pub fn jobs(&self) -> Vec<Job> {
        let mut jobs = Vec::new();
        for &f in &self.fidelities {
            for &m in &self.maneuvers {
                for &c in &self.controllers {
                    jobs.push(Job::new(self.seed, f, m, c));
                }
            }
        }
        jobs
    }
}

/// A table and, when asked for, the runs behind it (in the order of its cells).
#[derive(Clone, Debug)]
pub struct TableRun {
    /// The table.
    pub table: Table,
    /// The runs (empty unless [`Options::keep_runs`]).
    pub runs: Vec<Run>,
}

/// Runs the table (see [`run_table_with`]).
pub fn run_table(engine: &dyn Engine, options: &Options) -> Result<TableRun, Error> {
    run_table_with(engine, options, &|_| {})
}

/// Runs every job of `options` on `engine` on a pool of `options.threads` threads, calling
/// `done` after each job. The results do not depend on the number of threads: each job is
/// a deterministic run of its own, and the cells keep the order of [`Options::jobs`].
pub fn run_table_with(engine: &dyn Engine, options: &Options, done: &(dyn Fn(&Job) + Sync)) -> Result<TableRun, Error> {
    let wall = Instant::now();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(options.threads)
        .thread_name(|i| format!("table3-{i}"))
        .build()
        .map_err(|e| Error::Usage(format!("cannot start {} worker threads: {e}", options.threads)))?;
    let jobs = options.jobs();
    let results: Vec<(Cell, [[f64; 4]; 4], Option<Run>)> = pool.install(|| {
        jobs.par_iter()
            .map(|job| {
                let run = engine.run(job)?;
                run.check()?;
                let cell = Cell {
                    fidelity: job.fidelity,
                    maneuver: job.maneuver,
                    controller: job.controller,
                    metric: Metric::of(&run),
                };
                done(job);
                Ok((cell, run.gain, options.keep_runs.then_some(run)))
            })
            .collect::<Result<_, Error>>()
    })?;
    let mut gains: Vec<(Controller, [[f64; 4]; 4])> = Vec::new();
    for (cell, gain, _) in &results {
        if cell.controller == Controller::OpenLoop {
            continue;
        }
        match gains.iter().find(|(c, _)| *c == cell.controller) {
            None => gains.push((cell.controller, *gain)),
            Some((_, g)) if g == gain => {}
            Some((_, g)) => {
                return Err(Error::BadRun {
                    run: format!("{}/{}/{}", cell.fidelity.column(), cell.maneuver, cell.controller),
                    reason: format!("the controller used the gain {gain:?}, another run of it {g:?}"),
                })
            }
        }
    }
    gains.sort_by_key(|(c, _)| crate::CONTROLLERS.iter().position(|x| x == c).unwrap_or(usize::MAX));
    let mut cells = Vec::with_capacity(results.len());
    let mut runs = Vec::new();
    for (cell, _, run) in results {
        cells.push(cell);
        runs.extend(run);
    }
    let table = Table { seed: options.seed, engine: engine.name(), gains, cells, wall_s: wall.elapsed().as_secs_f64() };
    Ok(TableRun { table, runs })
}
