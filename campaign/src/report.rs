//! A finished campaign summarised: per group (the distinct values of the `--by` columns)
//! the count, the failures, and of each metric the mean, median, 95th percentile and worst
//! (the largest; percentiles by nearest rank over the runs that completed), as markdown
//! and JSON; the worst runs with the command that reruns one; PNG figures: the empirical
//! CDF of a metric per group, and the metric against each random column.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use plotters::prelude::*;
use serde_json::json;

use crate::results::{Row, Target, STATUS_OK};
use crate::spec::Spec;
use crate::Error;

/// A column's value as a group label: a case's name, else the number.
fn label(spec: &Spec, column: usize, v: f64) -> String {
    let names = spec.columns[column].case_names();
    if !names.is_empty() {
        if let Some(n) = names.get(v as usize) {
            return n.clone();
        }
    }
    format!("{v}")
}

/// Statistics of one metric in one group.
#[derive(Clone, Debug, PartialEq)]
pub struct Stats {
    /// Runs with a finite value.
    pub count: usize,
    /// Mean.
    pub mean: f64,
    /// Median (nearest rank).
    pub median: f64,
    /// 95th percentile (nearest rank).
    pub p95: f64,
    /// The largest.
    pub worst: f64,
}

/// Nearest-rank percentile `p` of sorted values.
fn rank(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let k = ((p * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len());
    sorted[k - 1]
}

impl Stats {
    /// Of `values` (non-finite ones left out).
    pub fn of(values: &[f64]) -> Stats {
        let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
        v.sort_by(f64::total_cmp);
        let mean = if v.is_empty() { f64::NAN } else { v.iter().sum::<f64>() / v.len() as f64 };
        Stats {
            count: v.len(),
            mean,
            median: rank(&v, 0.5),
            p95: rank(&v, 0.95),
            worst: v.last().copied().unwrap_or(f64::NAN),
        }
    }
}

/// One group of runs.
#[derive(Clone, Debug)]
pub struct Group {
    /// `column = value` labels.
    pub key: Vec<(String, String)>,
    /// The rows.
    pub rows: Vec<Row>,
}

impl Group {
    /// `controller=robust, maneuver=2`.
    pub fn name(&self) -> String {
        if self.key.is_empty() {
            return "all".into();
        }
        self.key.iter().map(|(k, v)| format!("{k}={v}")).collect::<Vec<_>>().join(", ")
    }
}

/// The report's inputs.
pub struct Report {
    /// The description.
    pub spec: Spec,
    /// The output folder.
    pub dir: PathBuf,
    /// All rows.
    pub rows: Vec<Row>,
    /// The groups.
    pub groups: Vec<Group>,
}

fn column_index(spec: &Spec, name: &str) -> Result<usize, Error> {
    spec.columns.iter().position(|c| c.name == name).ok_or_else(|| {
        Error::Usage(format!(
            "--by {name}: not a varied column (they are: {})",
            spec.columns.iter().map(|c| c.name.as_str()).collect::<Vec<_>>().join(", ")
        ))
    })
}

fn metric_index(spec: &Spec, name: &str) -> Result<usize, Error> {
    spec.metrics.iter().position(|(n, _)| n == name).ok_or_else(|| {
        Error::Usage(format!(
            "--metric {name}: not a metric (they are: {})",
            spec.metrics.iter().map(|(n, _)| n.as_str()).collect::<Vec<_>>().join(", ")
        ))
    })
}

impl Report {
    /// Reads `dir/results.csv` of `spec` and groups it by the columns `by`.
    pub fn load(spec: Spec, dir: &Path, by: &[String]) -> Result<Report, Error> {
        crate::results::claim(dir, &spec)?;
        let rows = crate::results::read_rows(&Target::whole(dir), &spec, false)?;
        if rows.is_empty() {
            return Err(Error::Usage(format!("{}: no results (campaign run first, or campaign merge)", dir.display())));
        }
        let by: Vec<usize> = by.iter().map(|b| column_index(&spec, b)).collect::<Result<_, _>>()?;
        let mut groups: BTreeMap<Vec<u64>, Group> = BTreeMap::new();
        for r in &rows {
            // sort by the values' bits of non-negative numbers is not numeric: use total order keys
            let k: Vec<u64> = by.iter().map(|&c| order_key(r.values[c])).collect();
            let g = groups.entry(k).or_insert_with(|| Group {
                key: by.iter().map(|&c| (spec.columns[c].name.clone(), label(&spec, c, r.values[c]))).collect(),
                rows: Vec::new(),
            });
            g.rows.push(r.clone());
        }
        Ok(Report { spec, dir: dir.to_path_buf(), rows, groups: groups.into_values().collect() })
    }

    fn metric_values(&self, rows: &[Row], m: usize) -> Vec<f64> {
        let c = self.spec.columns.len() + m;
        rows.iter().filter(|r| r.status == STATUS_OK).map(|r| r.values[c]).collect()
    }

    /// The markdown summary.
    pub fn markdown(&self, worst_of: usize, worst_n: usize) -> String {
        let mut s = format!(
            "# Campaign {} ({} runs, {} failed)\n\n",
            self.spec.path.display(),
            self.rows.len(),
            self.rows.iter().filter(|r| r.status != STATUS_OK).count()
        );
        for (m, (name, _)) in self.spec.metrics.iter().enumerate() {
            s += &format!(
                "## {name}\n\n| group | runs | failed | mean | median | p95 | worst |\n|---|---|---|---|---|---|---|\n"
            );
            for g in &self.groups {
                let st = Stats::of(&self.metric_values(&g.rows, m));
                let failed = g.rows.iter().filter(|r| r.status != STATUS_OK).count();
                s += &format!(
                    "| {} | {} | {} | {:.6} | {:.6} | {:.6} | {:.6} |\n",
                    g.name(),
                    g.rows.len(),
                    failed,
                    st.mean,
                    st.median,
                    st.p95,
                    st.worst
                );
            }
            s.push('\n');
        }
        if let Some((name, _)) = self.spec.metrics.get(worst_of) {
            s += &format!("## Worst runs by {name}\n\n| run | {name} | values | rerun |\n|---|---|---|---|\n");
            for r in self.worst(worst_of, worst_n) {
                s += &format!(
                    "| {} | {} | {} | `campaign run {} --out {} --only {}` |\n",
                    r.run,
                    r.values[self.spec.columns.len() + worst_of],
                    self.values_text(r),
                    self.spec.path.display(),
                    self.dir.display(),
                    r.run
                );
            }
            s.push('\n');
        }
        let failed: Vec<&Row> = self.rows.iter().filter(|r| r.status != STATUS_OK).take(worst_n).collect();
        if !failed.is_empty() {
            s += "## Failed runs\n\n| run | status | message |\n|---|---|---|\n";
            for r in failed {
                s += &format!("| {} | {} | {} |\n", r.run, r.status, r.message.replace('|', "/"));
            }
        }
        s
    }

    fn values_text(&self, r: &Row) -> String {
        self.spec
            .columns
            .iter()
            .enumerate()
            .map(|(k, c)| format!("{}={}", c.name, label(&self.spec, k, r.values[k])))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The `n` runs with the largest metric `m` (failed runs first: they are the worst).
    pub fn worst(&self, m: usize, n: usize) -> Vec<&Row> {
        let c = self.spec.columns.len() + m;
        let mut v: Vec<&Row> = self.rows.iter().collect();
        let key = |r: &Row| if r.status != STATUS_OK || !r.values[c].is_finite() { f64::INFINITY } else { r.values[c] };
        v.sort_by(|a, b| key(b).total_cmp(&key(a)).then(a.run.cmp(&b.run)));
        v.truncate(n);
        v
    }

    /// The JSON summary.
    pub fn json(&self, worst_of: usize, worst_n: usize) -> serde_json::Value {
        let st =
            |s: Stats| json!({"count": s.count, "mean": s.mean, "median": s.median, "p95": s.p95, "worst": s.worst});
        let groups: Vec<serde_json::Value> = self
            .groups
            .iter()
            .map(|g| {
                let metrics: serde_json::Map<String, serde_json::Value> = self
                    .spec
                    .metrics
                    .iter()
                    .enumerate()
                    .map(|(m, (n, _))| (n.clone(), st(Stats::of(&self.metric_values(&g.rows, m)))))
                    .collect();
                json!({
                    "group": g.key.iter().map(|(k, v)| (k.clone(), json!(v))).collect::<serde_json::Map<_, _>>(),
                    "runs": g.rows.len(),
                    "failed": g.rows.iter().filter(|r| r.status != STATUS_OK).count(),
                    "metrics": metrics,
                })
            })
            .collect();
        let worst: Vec<serde_json::Value> = self
            .worst(worst_of, worst_n)
            .into_iter()
            .map(|r| {
                json!({
                    "run": r.run, "status": r.status, "message": r.message,
                    "values": self.spec.columns.iter().enumerate().map(|(k, c)| (c.name.clone(), json!(r.values[k]))).collect::<serde_json::Map<_, _>>(),
                    "metrics": self.spec.metrics.iter().enumerate().map(|(m, (n, _))| (n.clone(), json!(r.values[self.spec.columns.len() + m]))).collect::<serde_json::Map<_, _>>(),
                    "rerun": format!("campaign run {} --out {} --only {}", self.spec.path.display(), self.dir.display(), r.run),
                })
            })
            .collect();
        json!({"description": self.spec.path, "hash": self.spec.hash, "runs": self.rows.len(), "groups": groups, "worst": worst})
    }

    /// Writes the PNGs of metric `m` into `dir`: `cdf_<metric>.png` and
    /// `<metric>_vs_<column>.png` for every random column; returns their paths.
    pub fn pngs(&self, m: usize, dir: &Path) -> Result<Vec<PathBuf>, Error> {
        std::fs::create_dir_all(dir).map_err(|e| Error::Io(format!("{}: {e}", dir.display())))?;
        register_font()?;
        let name = &self.spec.metrics[m].0;
        let mut out = Vec::new();
        let path = dir.join(format!("cdf_{}.png", file_safe(name)));
        self.cdf(m, &path)?;
        out.push(path);
        for (k, c) in self.spec.columns.iter().enumerate() {
            if matches!(c.domain, crate::spec::Domain::Random(_)) {
                let path = dir.join(format!("{}_vs_{}.png", file_safe(name), file_safe(&c.name)));
                self.scatter(m, k, &path)?;
                out.push(path);
            }
        }
        Ok(out)
    }

    fn cdf(&self, m: usize, path: &Path) -> Result<(), Error> {
        let err = |e: &dyn std::fmt::Display| Error::Plot(format!("{}: {e}", path.display()));
        let name = &self.spec.metrics[m].0;
        let series: Vec<(String, Vec<f64>)> = self
            .groups
            .iter()
            .map(|g| {
                let mut v = self.metric_values(&g.rows, m);
                v.retain(|x| x.is_finite());
                v.sort_by(f64::total_cmp);
                (g.name(), v)
            })
            .collect();
        let all: Vec<f64> = series.iter().flat_map(|(_, v)| v.iter().copied()).filter(|x| *x > 0.0).collect();
        let (lo, hi) = bounds(&all);
        let log = hi / lo > 50.0 && all.len() == series.iter().map(|(_, v)| v.len()).sum::<usize>();
        let root = BitMapBackend::new(path, (1000, 640)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let caption = format!("empirical CDF of {name} ({} runs)", all.len());
        let mut builder = ChartBuilder::on(&root);
        builder.caption(caption, ("sans-serif", 24)).margin(12).x_label_area_size(45).y_label_area_size(60);
        let style = |i: usize| Palette99::pick(i).stroke_width(2);
        macro_rules! draw {
            ($chart:expr) => {{
                let mut chart = $chart;
                chart
                    .configure_mesh()
                    .x_desc(name.as_str())
                    .y_desc("fraction of runs <= value")
                    .label_style(("sans-serif", 15))
                    .draw()
                    .map_err(|e| err(&e))?;
                for (i, (g, v)) in series.iter().enumerate() {
                    let n = v.len() as f64;
                    let pts: Vec<(f64, f64)> = v.iter().enumerate().map(|(k, x)| (*x, (k + 1) as f64 / n)).collect();
                    chart
                        .draw_series(LineSeries::new(pts, style(i)))
                        .map_err(|e| err(&e))?
                        .label(g.clone())
                        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style(i)));
                }
                chart
                    .configure_series_labels()
                    .position(SeriesLabelPosition::LowerRight)
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK)
                    .label_font(("sans-serif", 14))
                    .draw()
                    .map_err(|e| err(&e))?;
            }};
        }
        if log {
            draw!(builder.build_cartesian_2d((lo..hi).log_scale(), 0.0..1.0).map_err(|e| err(&e))?);
        } else {
            let (lo, hi) = bounds(&series.iter().flat_map(|(_, v)| v.iter().copied()).collect::<Vec<_>>());
            draw!(builder.build_cartesian_2d(lo..hi, 0.0..1.0).map_err(|e| err(&e))?);
        }
        root.present().map_err(|e| err(&e))?;
        Ok(())
    }

    fn scatter(&self, m: usize, column: usize, path: &Path) -> Result<(), Error> {
        let err = |e: &dyn std::fmt::Display| Error::Plot(format!("{}: {e}", path.display()));
        let name = &self.spec.metrics[m].0;
        let c = self.spec.columns.len() + m;
        let series: Vec<(String, Vec<(f64, f64)>)> = self
            .groups
            .iter()
            .map(|g| {
                let pts = g
                    .rows
                    .iter()
                    .filter(|r| r.status == STATUS_OK && r.values[c].is_finite())
                    .map(|r| (r.values[column], r.values[c]))
                    .collect();
                (g.name(), pts)
            })
            .collect();
        let xs: Vec<f64> = series.iter().flat_map(|(_, v)| v.iter().map(|p| p.0)).collect();
        let ys: Vec<f64> = series.iter().flat_map(|(_, v)| v.iter().map(|p| p.1)).collect();
        let (x0, x1) = bounds(&xs);
        let positive: Vec<f64> = ys.iter().copied().filter(|y| *y > 0.0).collect();
        let (y0, y1) = bounds(&positive);
        let log = y1 / y0 > 50.0 && positive.len() == ys.len();
        let root = BitMapBackend::new(path, (1000, 640)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let mut builder = ChartBuilder::on(&root);
        builder
            .caption(format!("{name} against {}", self.spec.columns[column].name), ("sans-serif", 24))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(70);
        let color = |i: usize| Palette99::pick(i).mix(0.6).filled();
        macro_rules! draw {
            ($chart:expr) => {{
                let mut chart = $chart;
                chart
                    .configure_mesh()
                    .x_desc(self.spec.columns[column].name.as_str())
                    .y_desc(name.as_str())
                    .label_style(("sans-serif", 15))
                    .draw()
                    .map_err(|e| err(&e))?;
                for (i, (g, pts)) in series.iter().enumerate() {
                    chart
                        .draw_series(pts.iter().map(|p| Circle::new(*p, 2, color(i))))
                        .map_err(|e| err(&e))?
                        .label(g.clone())
                        .legend(move |(x, y)| Circle::new((x + 10, y), 4, color(i)));
                }
                chart
                    .configure_series_labels()
                    .position(SeriesLabelPosition::UpperRight)
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK)
                    .label_font(("sans-serif", 14))
                    .draw()
                    .map_err(|e| err(&e))?;
            }};
        }
        if log {
            draw!(builder.build_cartesian_2d(x0..x1, (y0..y1).log_scale()).map_err(|e| err(&e))?);
        } else {
            let (y0, y1) = bounds(&ys);
            draw!(builder.build_cartesian_2d(x0..x1, y0..y1).map_err(|e| err(&e))?);
        }
        root.present().map_err(|e| err(&e))?;
        Ok(())
    }

    /// The metric index of `name` (default: the first metric).
    pub fn metric(&self, name: Option<&str>) -> Result<usize, Error> {
        match name {
            Some(n) => metric_index(&self.spec, n),
            None if self.spec.metrics.is_empty() => Err(Error::Usage("the description has no metrics".into())),
            None => Ok(0),
        }
    }
}

/// A paired comparison: for two values `a`, `b` of one column, the runs that differ only
/// in that column (the same other grid values and the same sample, hence the same draws).
#[derive(Clone, Debug, PartialEq)]
pub struct Pairing {
    /// The group (labels of the other `--by` columns).
    pub group: String,
    /// The two values' labels.
    pub a: String,
    /// See `a`.
    pub b: String,
    /// Pairs where both runs completed.
    pub pairs: usize,
    /// Fraction of pairs with metric(a) < metric(b).
    pub p_less: f64,
    /// Fraction of pairs with metric(b) < metric(a).
    pub p_more: f64,
    /// Median of metric(a) / metric(b).
    pub median_ratio: f64,
}

impl Report {
    /// The paired comparisons of metric `m` between the values of column `name`, per group
    /// of the `by` columns other than `name`.
    pub fn pairings(&self, name: &str, by: &[String], m: usize) -> Result<Vec<Pairing>, Error> {
        let col = column_index(&self.spec, name)?;
        let by: Vec<usize> = by
            .iter()
            .map(|b| column_index(&self.spec, b))
            .collect::<Result<Vec<_>, _>>()?
            .into_iter()
            .filter(|&c| c != col)
            .collect();
        let grid: Vec<usize> = (0..self.spec.columns.len())
            .filter(|&c| c != col && !matches!(self.spec.columns[c].domain, crate::spec::Domain::Random(_)))
            .collect();
        let metric = self.spec.columns.len() + m;
        let values: Vec<f64> = match &self.spec.columns[col].domain {
            crate::spec::Domain::Grid(v) => v.iter().map(|x| x.number()).collect(),
            crate::spec::Domain::Cases(c) => (0..c.len()).map(|k| k as f64).collect(),
            crate::spec::Domain::Random(_) => {
                return Err(Error::Usage(format!("--pair {name}: a random column has no values to pair")))
            }
        };
        // (group key, pairing key) -> value index -> metric
        let mut cells: BTreeMap<(Vec<u64>, Vec<u64>), BTreeMap<usize, f64>> = BTreeMap::new();
        let mut labels: BTreeMap<Vec<u64>, String> = BTreeMap::new();
        for r in self.rows.iter().filter(|r| r.status == STATUS_OK && r.values[metric].is_finite()) {
            let gk: Vec<u64> = by.iter().map(|&c| order_key(r.values[c])).collect();
            labels.entry(gk.clone()).or_insert_with(|| {
                if by.is_empty() {
                    "all".into()
                } else {
                    by.iter()
                        .map(|&c| format!("{}={}", self.spec.columns[c].name, label(&self.spec, c, r.values[c])))
                        .collect::<Vec<_>>()
                        .join(", ")
                }
            });
            let mut pk: Vec<u64> = grid.iter().map(|&c| order_key(r.values[c])).collect();
            pk.push(r.run % self.spec.samples);
            let Some(v) = values.iter().position(|x| *x == r.values[col]) else { continue };
            cells.entry((gk, pk)).or_default().insert(v, r.values[metric]);
        }
        let mut out = Vec::new();
        for (gk, glabel) in &labels {
            for a in 0..values.len() {
                for b in a + 1..values.len() {
                    let mut ratios = Vec::new();
                    let (mut less, mut more) = (0usize, 0usize);
                    for ((g, _), m) in cells.range((gk.clone(), Vec::new())..) {
                        if g != gk {
                            break;
                        }
                        if let (Some(x), Some(y)) = (m.get(&a), m.get(&b)) {
                            less += usize::from(x < y);
                            more += usize::from(y < x);
                            ratios.push(x / y);
                        }
                    }
                    ratios.sort_by(f64::total_cmp);
                    out.push(Pairing {
                        group: glabel.clone(),
                        a: label(&self.spec, col, values[a]),
                        b: label(&self.spec, col, values[b]),
                        pairs: ratios.len(),
                        p_less: less as f64 / ratios.len().max(1) as f64,
                        p_more: more as f64 / ratios.len().max(1) as f64,
                        median_ratio: rank(&ratios, 0.5),
                    });
                }
            }
        }
        Ok(out)
    }

    /// The pairings as a markdown table.
    pub fn pairings_markdown(&self, pairings: &[Pairing], metric: &str) -> String {
        let mut s = format!(
            "## Paired: P({metric} of A < {metric} of B), same draws\n\n| group | A | B | pairs | P(A < B) | P(B < A) | median A/B |\n|---|---|---|---|---|---|---|\n"
        );
        for p in pairings {
            s += &format!(
                "| {} | {} | {} | {} | {:.3} | {:.3} | {:.3} |\n",
                p.group, p.a, p.b, p.pairs, p.p_less, p.p_more, p.median_ratio
            );
        }
        s + "\n"
    }
}

/// A sort key giving the numeric order of f64 values.
fn order_key(v: f64) -> u64 {
    let b = v.to_bits();
    if b >> 63 == 1 {
        !b
    } else {
        b | (1 << 63)
    }
}

fn bounds(v: &[f64]) -> (f64, f64) {
    let (lo, hi) = v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(*x), b.max(*x)));
    if !lo.is_finite() || !hi.is_finite() {
        return (0.0, 1.0);
    }
    if hi <= lo {
        return (lo - 0.5 * lo.abs().max(1e-3), hi + 0.5 * hi.abs().max(1e-3));
    }
    (lo, hi)
}

fn file_safe(s: &str) -> String {
    s.chars().map(|c| if c.is_alphanumeric() || c == '_' || c == '-' { c } else { '_' }).collect()
}

static FONT: &[u8] = include_bytes!("../../table3/assets/DejaVuSans.ttf");

fn register_font() -> Result<(), Error> {
    static DONE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    if *DONE.get_or_init(|| plotters::style::register_font("sans-serif", FontStyle::Normal, FONT).is_ok()) {
        Ok(())
    } else {
        Err(Error::Plot("the bundled DejaVu Sans font is invalid".into()))
    }
}
