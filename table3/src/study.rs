//! The seed study: for several seeds, how the robust tracking controller
//! compares with the paper's robust controller cell by cell (`eps(robust_tracking) /
//! eps(robust)`), whether it is the lowest of all the controllers run in every row, and
//! the largest steering command over every run (against `delta_max`).

use std::fmt::Write;

use crate::{report::sci, Controller, Fidelity, Maneuver, Table};

/// One row (column, maneuver) of the study over the seeds.
#[derive(Clone, Debug, PartialEq)]
pub struct StudyRow {
    /// The column.
    pub fidelity: Fidelity,
    /// The maneuver.
    pub maneuver: Maneuver,
    /// `eps(robust_tracking) / eps(robust)`, one per seed (in the order of the tables).
    pub ratios: Vec<f64>,
    /// Seeds in which `robust_tracking` is not the lowest of the controllers run.
    pub not_lowest: Vec<u64>,
}

impl StudyRow {
    /// The largest ratio over the seeds.
    pub fn worst(&self) -> f64 {
        self.ratios.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    }

    /// The mean ratio over the seeds.
    pub fn mean(&self) -> f64 {
        self.ratios.iter().sum::<f64>() / self.ratios.len().max(1) as f64
    }
}

/// The study over several tables (one per seed).
#[derive(Clone, Debug, PartialEq)]
pub struct Study {
    /// The seeds, in order.
    pub seeds: Vec<u64>,
    /// One row per (column, maneuver) present in every table.
    pub rows: Vec<StudyRow>,
    /// The largest `|delta|` of any run, per controller present \[rad\].
    pub max_delta: Vec<(Controller, f64)>,
}

impl Study {
    /// The study of `tables`; `None` unless every table has `robust` and `robust_tracking`.
    pub fn of(tables: &[Table]) -> Option<Study> {
        let first = tables.first()?;
        let mut rows = Vec::new();
        for f in first.fidelities() {
            for m in first.maneuvers() {
                let mut row = StudyRow { fidelity: f, maneuver: m, ratios: Vec::new(), not_lowest: Vec::new() };
                for t in tables {
                    let tracking = t.get(f, m, Controller::RobustTracking)?.metric.eps;
                    let robust = t.get(f, m, Controller::Robust)?.metric.eps;
                    row.ratios.push(tracking / robust);
                    if t.lowest(f, m) != Some(Controller::RobustTracking) {
                        row.not_lowest.push(t.seed);
                    }
                }
                rows.push(row);
            }
        }
        let max_delta = first
            .controllers()
            .into_iter()
            .map(|c| {
                let m = tables
                    .iter()
                    .flat_map(|t| t.cells.iter())
                    .filter(|x| x.controller == c)
                    .fold(0.0f64, |m, x| m.max(x.metric.max_delta));
                (c, m)
            })
            .collect();
        Some(Study { seeds: tables.iter().map(|t| t.seed).collect(), rows, max_delta })
    }

    /// Whether `robust_tracking` is the lowest in every row of every seed.
    pub fn tracking_lowest_everywhere(&self) -> bool {
        self.rows.iter().all(|r| r.not_lowest.is_empty())
    }

    /// The study as markdown: the ratios per seed, their worst and mean, and the steering.
    pub fn markdown(&self) -> String {
        let mut s = String::new();
        let seeds: Vec<String> = self.seeds.iter().map(|x| x.to_string()).collect();
        let _ = writeln!(
            s,
            "eps(robust_tracking) / eps(robust) per cell, seeds {} (lower is better; < 1: pose feedback wins)",
            seeds.join(", ")
        );
        let _ = writeln!(s);
        let _ = write!(s, "| column | maneuver |");
        for seed in &self.seeds {
            let _ = write!(s, " {seed} |");
        }
        let _ = writeln!(s, " worst | mean | robust_tracking lowest of all |");
        let _ = writeln!(s, "|---|---|{}---:|---:|---|", "---:|".repeat(self.seeds.len()));
        for r in &self.rows {
            let _ = write!(s, "| {} | {} |", r.fidelity.column(), r.maneuver.name());
            for x in &r.ratios {
                let _ = write!(s, " {x:.3} |");
            }
            let lowest = if r.not_lowest.is_empty() {
                "every seed".to_string()
            } else {
                format!("NOT in seeds {:?}", r.not_lowest)
            };
            let _ = writeln!(s, " {:.3} | {:.3} | {lowest} |", r.worst(), r.mean());
        }
        let _ = writeln!(s);
        let worst = self.rows.iter().map(StudyRow::worst).fold(f64::NEG_INFINITY, f64::max);
        let _ = writeln!(
            s,
            "robust_tracking lowest of all controllers in all {} rows of all {} seeds: {}; worst ratio {}",
            self.rows.len(),
            self.seeds.len(),
            if self.tracking_lowest_everywhere() { "yes" } else { "NO" },
            sci(worst)
        );
        let _ = write!(s, "Largest steering command |delta| over all runs [rad] (delta_max = pi/2 = 1.5708):");
        for (c, m) in &self.max_delta {
            let _ = write!(s, " {} {m:.4};", c.name());
        }
        let _ = writeln!(s);
        s
    }
}
