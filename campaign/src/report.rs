//! A finished campaign summarised: per group (the distinct values of the `--by` columns)
//! the count, the failures, and of each metric the mean, median, 95th percentile and worst
//! (the largest; percentiles by nearest rank over the runs that completed), as markdown
//! and JSON; the worst runs with the command that reruns one; PNG figures: the empirical
//! CDF of a metric per group, and the metric against each random column.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use plotters::prelude::*;
use serde_json::json;

use model_description::VariableType;
use nigel_cosim::System;

use crate::results::{Row, Target, STATUS_OK};
use crate::spec::{Domain, Spec};
use crate::Error;

/// The names of the values of variable `name` (`instance.variable`) of `system`: an
/// Enumeration's items, or the items an Integer's description lists as `N name`, the way our
/// FMUs describe the switches they keep Integer so that every importer can set them
/// (`which steering feedback: 1 open_loop (...), 2 pole_placement (...), 3 robust ...`).
/// Empty when the variable has neither.
pub fn value_names(system: &System, name: &str) -> BTreeMap<i64, String> {
    let Ok(r) = system.resolve(name) else { return BTreeMap::new() };
    let v = system.variable(&r);
    match &v.variable_type {
        VariableType::Enumeration { declared_type, .. } => system
            .description(r.instance)
            .type_definitions
            .iter()
            .find(|t| &t.name == declared_type)
            .map(|t| t.items.iter().map(|i| (i64::from(i.value), i.name.clone())).collect())
            .unwrap_or_default(),
        VariableType::Integer { .. } => v.description.as_deref().and_then(items_in_description).unwrap_or_default(),
        _ => BTreeMap::new(),
    }
}

/// The items of a description `[text: ]N name [(note)], N name [(note)], ...`: every part
/// (split at the commas outside parentheses) an integer, one identifier and an optional note
/// in parentheses, at least two parts, each value once; `None` for any other text.
pub fn items_in_description(text: &str) -> Option<BTreeMap<i64, String>> {
    let list = text.split_once(": ").map_or(text, |(_, l)| l);
    let mut parts = Vec::new();
    let (mut depth, mut start) = (0i32, 0usize);
    for (i, c) in list.char_indices() {
        match c {
            '(' => depth += 1,
            ')' => depth -= 1,
            ',' if depth == 0 => {
                parts.push(&list[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    parts.push(&list[start..]);
    let mut items = BTreeMap::new();
    for part in &parts {
        let part = part.trim();
        let head = match part.find('(') {
            Some(k) if part.ends_with(')') => part[..k].trim_end(),
            Some(_) => return None,
            None => part,
        };
        let mut words = head.split(' ');
        let (Some(n), Some(id), None) = (words.next(), words.next(), words.next()) else { return None };
        let n: i64 = n.parse().ok()?;
        let ident = id.chars().next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
            && id.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
        if !ident || items.insert(n, id.to_string()).is_some() {
            return None;
        }
    }
    (items.len() >= 2).then_some(items)
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
    /// Per `--by` column its name and the value's label.
    pub key: Vec<(String, String)>,
    /// The legend text, `controller = robust, maneuver = lane_change` (see [`Report::legend_key`]).
    pub legend: String,
    /// The rows.
    pub rows: Vec<Row>,
}

impl Group {
    /// The legend text (`all` for a report without `--by`).
    pub fn name(&self) -> String {
        if self.key.is_empty() {
            return "all".into();
        }
        self.legend.clone()
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
    /// Per column the names of its values: a case's name by its index, else the items of
    /// the enumerated variable it sets ([`value_names`]); empty for a column of numbers.
    pub value_names: Vec<BTreeMap<i64, String>>,
}

/// The value names of every column of `spec`: a column of cases by the case index; a column
/// that sets variables all naming the same items ([`value_names`]) by those items.
fn column_value_names(spec: &Spec, system: &System) -> Vec<BTreeMap<i64, String>> {
    spec.columns
        .iter()
        .map(|c| match &c.domain {
            Domain::Cases(cases) => cases.iter().enumerate().map(|(k, (n, _))| (k as i64, n.clone())).collect(),
            _ => {
                let mut names = c.targets.iter().map(|t| value_names(system, t));
                let first = names.next().unwrap_or_default();
                if names.all(|n| n == first) {
                    first
                } else {
                    BTreeMap::new()
                }
            }
        })
        .collect()
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

/// Draws the mesh of a report chart: axis descriptions `$x_desc` and `$y_desc`, ticks as
/// [`tick`] writes them, light grey grid lines; a drawing error returns from the function
/// as `$err` makes it (a macro: the charts' coordinate types differ).
/// Labels asked of plotters on a linear axis (its default) and on a log axis: a log axis
/// over one and a half decades needs every 1 .. 9 multiple labelled (15 and more), else
/// plotters labels one decade and leaves the other bare.
const LINEAR_LABELS: usize = 10;
const LOG_LABELS: usize = 30;

macro_rules! draw_mesh {
    ($chart:expr, $x_desc:expr, $y_desc:expr, $err:expr, $x_log:expr, $y_log:expr) => {
        $chart
            .configure_mesh()
            .x_labels(if $x_log { LOG_LABELS } else { LINEAR_LABELS })
            .y_labels(if $y_log { LOG_LABELS } else { LINEAR_LABELS })
            .x_desc($x_desc)
            .y_desc($y_desc)
            .label_style(("sans-serif", 15))
            .axis_desc_style(("sans-serif", 16))
            .x_label_formatter(&|v: &f64| if $x_log { log_tick(*v) } else { tick(*v) })
            .y_label_formatter(&|v: &f64| if $y_log { log_tick(*v) } else { tick(*v) })
            .light_line_style(RGBColor(235, 235, 235))
            .bold_line_style(RGBColor(200, 200, 200))
            .draw()
            .map_err(|e| $err(&e))?
    };
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
        // the item names come from the system's model descriptions (the description was
        // checked against the same file: its hash is the folder's)
        let system = crate::spec::load_system(&spec.system).map_err(Error::Spec)?;
        let value_names = column_value_names(&spec, &system);
        let mut report = Report { spec, dir: dir.to_path_buf(), rows: Vec::new(), groups: Vec::new(), value_names };
        let mut groups: BTreeMap<Vec<u64>, Group> = BTreeMap::new();
        for r in &rows {
            // sort by the values' bits of non-negative numbers is not numeric: use total order keys
            let k: Vec<u64> = by.iter().map(|&c| order_key(r.values[c])).collect();
            let g = groups.entry(k).or_insert_with(|| Group {
                key: by.iter().map(|&c| (report.spec.columns[c].name.clone(), report.label(c, r.values[c]))).collect(),
                legend: report.legend(&by, &r.values),
                rows: Vec::new(),
            });
            g.rows.push(r.clone());
        }
        report.rows = rows;
        report.groups = groups.into_values().collect();
        Ok(report)
    }

    /// Column `column`'s value `v` as a label: its name ([`Report::value_names`]), else the number.
    pub fn label(&self, column: usize, v: f64) -> String {
        let names = &self.value_names[column];
        if v.fract() == 0.0 {
            if let Some(n) = names.get(&(v as i64)) {
                return n.clone();
            }
        }
        format!("{v}")
    }

    /// The name a legend gives column `column`: the variable's own name (`controller`) for a
    /// column named after the one enumerated variable it sets (`controller.controller`),
    /// which its item names then explain, else the column's name.
    pub fn legend_key(&self, column: usize) -> String {
        let c = &self.spec.columns[column];
        match c.targets.as_slice() {
            [t] if *t == c.name && !self.value_names[column].is_empty() => {
                t.split_once('.').map_or(t.as_str(), |(_, v)| v).to_string()
            }
            _ => c.name.clone(),
        }
    }

    /// `controller = robust, maneuver = lane_change` for the columns `by` of a row's values.
    pub fn legend(&self, by: &[usize], values: &[f64]) -> String {
        by.iter()
            .map(|&c| format!("{} = {}", self.legend_key(c), self.label(c, values[c])))
            .collect::<Vec<_>>()
            .join(", ")
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
            .map(|(k, c)| format!("{}={}", c.name, self.label(k, r.values[k])))
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
            if matches!(c.domain, crate::spec::Domain::Random(_)) && !is_seed(c) {
                let path = dir.join(format!("{}_vs_{}.png", file_safe(name), file_safe(&c.name)));
                self.scatter(m, k, &path)?;
                out.push(path);
            }
        }
        Ok(out)
    }

    /// The empirical CDF of metric `m` per group: the legend labels and each group's sorted
    /// finite values, as [`Report::pngs`] draws them.
    pub fn cdf_series(&self, m: usize) -> Vec<(String, Vec<f64>)> {
        self.groups
            .iter()
            .map(|g| {
                let mut v = self.metric_values(&g.rows, m);
                v.retain(|x| x.is_finite());
                v.sort_by(f64::total_cmp);
                (g.name(), v)
            })
            .collect()
    }

    fn cdf(&self, m: usize, path: &Path) -> Result<(), Error> {
        let err = |e: &dyn std::fmt::Display| Error::Plot(format!("{}: {e}", path.display()));
        let name = &self.spec.metrics[m].0;
        let series = self.cdf_series(m);
        let all: Vec<f64> = series.iter().flat_map(|(_, v)| v.iter().copied()).collect();
        let axis = Axis::of(&all);
        let labels: Vec<String> = series.iter().map(|(g, _)| g.clone()).collect();
        let caption = format!("empirical CDF of {name} ({} runs{})", all.len(), axis.caption());
        let (root, chart_area) = figure_with_legend(path, &caption, &labels, true).map_err(|e| err(&e))?;
        let mut builder = ChartBuilder::on(&chart_area);
        builder.margin(16).x_label_area_size(48).y_label_area_size(64);
        // y from -0.03 to 1.03: the curves' ends do not sit on the frame
        let ys = -0.03..1.03;
        macro_rules! draw {
            ($chart:expr) => {{
                let mut chart = $chart;
                let x_log = matches!(axis, Axis::Log(..));
                draw_mesh!(chart, name.as_str(), "fraction of runs <= value", err, x_log, false);
                for (i, (_, v)) in series.iter().enumerate() {
                    let n = v.len() as f64;
                    let pts: Vec<(f64, f64)> = v.iter().enumerate().map(|(k, x)| (*x, (k + 1) as f64 / n)).collect();
                    let color = PALETTE[i % PALETTE.len()];
                    chart
                        .draw_series(LineSeries::new(pts.iter().copied(), color.stroke_width(2)))
                        .map_err(|e| err(&e))?;
                    // a marker at each decile tells the groups apart without colour
                    let deciles: Vec<(f64, f64)> = (1..10)
                        .filter_map(|d| pts.get(((d as f64 / 10.0 * n).ceil() as usize).max(1) - 1).copied())
                        .collect();
                    chart
                        .draw_series(deciles.into_iter().map(|p| {
                            let (shape, fill) = marker_shape(i, 5);
                            EmptyElement::at(p) + Polygon::new(shape, fill)
                        }))
                        .map_err(|e| err(&e))?;
                }
            }};
        }
        match axis {
            Axis::Log(lo, hi) => draw!(builder.build_cartesian_2d((lo..hi).log_scale(), ys).map_err(|e| err(&e))?),
            Axis::Linear(lo, hi) => draw!(builder.build_cartesian_2d(lo..hi, ys).map_err(|e| err(&e))?),
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
        let Axis::Linear(x0, x1) = Axis::linear(&xs) else { unreachable!("Axis::linear is linear") };
        let y_axis = Axis::of(&ys);
        let labels: Vec<String> = series.iter().map(|(g, _)| g.clone()).collect();
        let caption =
            format!("{name} against {} ({} runs{})", self.spec.columns[column].name, ys.len(), y_axis.caption());
        let (root, chart_area) = figure_with_legend(path, &caption, &labels, false).map_err(|e| err(&e))?;
        let mut builder = ChartBuilder::on(&chart_area);
        builder.margin(16).x_label_area_size(48).y_label_area_size(72);
        macro_rules! draw {
            ($chart:expr) => {{
                let mut chart = $chart;
                let y_log = matches!(y_axis, Axis::Log(..));
                draw_mesh!(chart, self.spec.columns[column].name.as_str(), name.as_str(), err, false, y_log);
                for (i, (_, pts)) in series.iter().enumerate() {
                    chart
                        .draw_series(pts.iter().map(|p| {
                            let (shape, fill) = marker_shape(i, 3);
                            EmptyElement::at(*p) + Polygon::new(shape, fill)
                        }))
                        .map_err(|e| err(&e))?;
                }
            }};
        }
        match y_axis {
            Axis::Log(y0, y1) => {
                draw!(builder.build_cartesian_2d(x0..x1, (y0..y1).log_scale()).map_err(|e| err(&e))?)
            }
            Axis::Linear(y0, y1) => draw!(builder.build_cartesian_2d(x0..x1, y0..y1).map_err(|e| err(&e))?),
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
                    self.legend(&by, &r.values)
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
                        a: self.label(col, values[a]),
                        b: self.label(col, values[b]),
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

/// A metric axis of a figure and its range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Axis {
    /// Linear from the first to the second value.
    Linear(f64, f64),
    /// Logarithmic from the first to the second value (both positive).
    Log(f64, f64),
}

/// A random column that is a noise seed (integers drawn into a variable named `seed`): its
/// values are labels of random streams with no order, so a metric plotted against it shows
/// nothing; [`Report::pngs`] draws no scatter for it.
fn is_seed(c: &crate::spec::Column) -> bool {
    let named_seed = |n: &str| n.rsplit(['.', '_']).next().is_some_and(|last| last.eq_ignore_ascii_case("seed"));
    matches!(c.domain, crate::spec::Domain::Random(crate::spec::Distribution::Integers(..)))
        && (named_seed(&c.name) || c.targets.iter().any(|v| named_seed(v)))
}

/// More than this ratio of the largest to the smallest value (one decade) draws a log axis:
/// a metric such as epsilon spans a decade between maneuvers, and on a linear axis the
/// groups of the small values are squashed against zero.
pub const LOG_AXIS_RATIO: f64 = 10.0;

/// Share of the span (of the decades on a log axis) left free at each end of an axis, so
/// that no point sits on the frame.
pub const AXIS_PAD: f64 = 0.04;

impl Axis {
    /// The axis of `values` (non-finite ones left out): logarithmic when all are positive
    /// and span more than a decade ([`LOG_AXIS_RATIO`]), else linear; padded by
    /// [`AXIS_PAD`] at each end.
    pub fn of(values: &[f64]) -> Axis {
        let v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
        let (lo, hi) = v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(*x), b.max(*x)));
        if lo > 0.0 && hi / lo > LOG_AXIS_RATIO {
            let pad = AXIS_PAD * (hi / lo).log10();
            let (mut lo, hi) = (lo / 10f64.powf(pad), hi * 10f64.powf(pad));
            // plotters labels a log axis from its first power of ten up: where the values
            // reach more than a factor 2 below it, the axis starts at the power of ten below
            // (else those values would have no label at all)
            let below = 10f64.powf(lo.log10().floor());
            if 10.0 * below / lo > 2.0 {
                // a hair below it, so that plotters' ceil(log10(lo)) is that power of ten
                // (log10(0.01) in floating point may come out a hair above -2)
                lo = below * (1.0 - 1e-9);
            }
            return Axis::Log(lo, hi);
        }
        Axis::linear(&v)
    }

    /// A linear axis over `values` (non-finite ones left out), padded by [`AXIS_PAD`].
    pub fn linear(values: &[f64]) -> Axis {
        let (lo, hi) = values
            .iter()
            .filter(|x| x.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(*x), b.max(*x)));
        if !lo.is_finite() {
            return Axis::Linear(0.0, 1.0);
        }
        let pad = if hi > lo { AXIS_PAD * (hi - lo) } else { 0.5 * lo.abs().max(1e-3) };
        Axis::Linear(lo - pad, hi + pad)
    }

    /// `, log axis` for a caption.
    fn caption(&self) -> &'static str {
        match self {
            Axis::Log(..) => ", log axis",
            Axis::Linear(..) => "",
        }
    }
}

/// A log axis's label: 1, 2 and 5 times a power of ten (the other multiples get grid lines
/// but no label: nine labels a decade run into each other at the decade's top).
fn log_tick(v: f64) -> String {
    let mantissa = v / 10f64.powf(v.log10().floor());
    if [1.0, 2.0, 5.0, 10.0].iter().any(|m| (mantissa - m).abs() < 1e-6) {
        tick(v)
    } else {
        String::new()
    }
}

/// Tick label: up to 4 significant digits without trailing zeros (`0.001`, `10`, `2.5`),
/// magnitudes beyond 1e-4 .. 1e5 as `1e-5`; never `-0`.
fn tick(v: f64) -> String {
    nigel_cosim::compare::plot::tick_label(v, 1e-4)
}

/// Group colours: the Okabe-Ito palette without its yellow (which vanishes on white),
/// distinguishable with the common colour-vision deficiencies.
pub const PALETTE: [RGBColor; 7] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
];

type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

/// A 1000-pixel-wide white figure at `path` titled `title`, with the legend of `labels` (group `i`'s colour
/// and marker, with a line sample when `line`) in rows of two above the chart, where it hides
/// no data; returns the whole figure and the chart's area.
fn figure_with_legend<'a>(
    path: &'a Path,
    title: &str,
    labels: &[String],
    line: bool,
) -> Result<(Area<'a>, Area<'a>), DrawingAreaErrorKind<<BitMapBackend<'a> as DrawingBackend>::ErrorType>> {
    const ROW: u32 = 24;
    let rows = labels.len().div_ceil(2) as u32;
    let legend_h = if labels.len() > 1 { rows * ROW + 14 } else { 0 };
    let root = BitMapBackend::new(path, (1000, 640 + legend_h)).into_drawing_area();
    root.fill(&WHITE)?;
    let body = root.titled(title, ("sans-serif", 24))?;
    let (legend, chart) = body.split_vertically(legend_h);
    let style = TextStyle::from(("sans-serif", 15).into_font());
    if labels.len() > 1 {
        for (i, label) in labels.iter().enumerate() {
            let (x, y) = (90 + 460 * (i % 2) as i32, 10 + (i / 2) as i32 * ROW as i32 + ROW as i32 / 2);
            let color = PALETTE[i % PALETTE.len()];
            if line {
                legend.draw(&PathElement::new(vec![(x, y), (x + 30, y)], color.stroke_width(2)))?;
            }
            let (shape, fill) = marker_shape(i, 5);
            legend.draw(&(EmptyElement::at((x + 15, y)) + Polygon::new(shape, fill)))?;
            legend.draw(&Text::new(label.clone(), (x + 40, y - 8), style.clone()))?;
        }
    }
    Ok((root, chart))
}

/// Group `i`'s marker, `size` pixels across its centre: circle, triangle, square, plus,
/// diamond in turn (with the colours, 35 groups are told apart); a polygon in pixels around
/// the point, and its fill.
fn marker_shape(i: usize, size: i32) -> (Vec<(i32, i32)>, ShapeStyle) {
    let s = size as f64;
    let fill = PALETTE[i % PALETTE.len()].mix(0.8).filled();
    let round = |v: Vec<(f64, f64)>| v.into_iter().map(|(x, y)| (x.round() as i32, y.round() as i32)).collect();
    let shape = match (i / PALETTE.len() + i) % 5 {
        0 => (0..16).map(|k| k as f64 * std::f64::consts::PI / 8.0).map(|a| (s * a.cos(), s * a.sin())).collect(),
        1 => vec![(0.0, -1.2 * s), (1.1 * s, 0.8 * s), (-1.1 * s, 0.8 * s)],
        2 => vec![(-0.85 * s, -0.85 * s), (0.85 * s, -0.85 * s), (0.85 * s, 0.85 * s), (-0.85 * s, 0.85 * s)],
        3 => {
            let (a, b) = (0.35 * s, 1.1 * s);
            vec![
                (-a, -b),
                (a, -b),
                (a, -a),
                (b, -a),
                (b, a),
                (a, a),
                (a, b),
                (-a, b),
                (-a, a),
                (-b, a),
                (-b, -a),
                (-a, -a),
            ]
        }
        _ => vec![(0.0, -1.2 * s), (1.2 * s, 0.0), (0.0, 1.2 * s), (-1.2 * s, 0.0)],
    };
    (round(shape), fill)
}

fn file_safe(s: &str) -> String {
    s.chars().map(|c| if c.is_alphanumeric() || c == '_' || c == '-' { c } else { '_' }).collect()
}

/// The bundled font as the master's comparison plots register it (the same figures on every
/// machine).
fn register_font() -> Result<(), Error> {
    nigel_cosim::compare::plot::register_font().map_err(Error::Plot)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_axis_is_logarithmic_when_the_values_span_more_than_a_decade() {
        // 1e-3 .. 1: three decades, padded by 4 % of them (10^0.12) at each end
        let Axis::Log(lo, hi) = Axis::of(&[1e-3, 0.02, 1.0]) else { panic!("log expected") };
        assert!((lo - 1e-3 / 10f64.powf(0.12)).abs() < 1e-15 && (hi - 10f64.powf(0.12)).abs() < 1e-12);
        // exactly one decade, a zero, a negative value: linear, padded by 4 % of the span
        assert_eq!(Axis::of(&[0.1, 1.0]), Axis::Linear(0.1 - 0.036, 1.0 + 0.036));
        // a decade and a half (the example's lane change against its skidpad): log, from 0.01,
        // the power of ten below the values (0.04 is a factor 2.5 below the first one, 0.1)
        let Axis::Log(lo, _) = Axis::of(&[0.04, 1.3]) else { panic!("log expected") };
        assert_eq!(lo, 0.01 * (1.0 - 1e-9));
        assert!(matches!(Axis::of(&[0.0, 1e-6, 1.0]), Axis::Linear(..)));
        assert!(matches!(Axis::of(&[-1e-3, 1e-5, 10.0]), Axis::Linear(..)));
        // non-finite values are left out; nothing left: [0, 1]
        assert!(matches!(Axis::of(&[f64::NAN, 1e-4, 1.0, f64::INFINITY]), Axis::Log(..)));
        assert_eq!(Axis::of(&[f64::NAN]), Axis::Linear(0.0, 1.0));
        // one value: a range around it
        assert_eq!(Axis::of(&[2.0, 2.0]), Axis::Linear(1.0, 3.0));
    }

    #[test]
    fn a_noise_seed_gets_no_scatter() {
        use crate::spec::{Column, Distribution, Domain, Scalar};
        let column = |name: &str, targets: &[&str], domain: Domain| Column {
            name: name.into(),
            targets: targets.iter().map(|t| t.to_string()).collect(),
            domain,
        };
        let ints = || Domain::Random(Distribution::Integers(0, 1000));
        // the example's and the robustness study's test-bench seed
        assert!(is_seed(&column("maneuver.seed", &["maneuver.seed"], ints())));
        assert!(is_seed(&column("noise", &["plant.noise_seed"], ints())));
        // a drawn quantity, an integer that is not a seed, a seed given on a grid
        assert!(!is_seed(&column("plant.m", &["plant.m"], Domain::Random(Distribution::Uniform(2.4, 3.0)))));
        assert!(!is_seed(&column("maneuver.maneuver", &["maneuver.maneuver"], ints())));
        assert!(!is_seed(&column("maneuver.seed", &["maneuver.seed"], Domain::Grid(vec![Scalar::Integer(1)]))));
        assert!(!is_seed(&column("seeds_per_cell", &["x.seeds"], ints())));
    }

    #[test]
    fn items_are_read_from_a_description_only_when_every_part_is_one() {
        let controller = "which steering feedback: 1 open_loop (K = 0, the feed-forward alone), 2 pole_placement \
                          (non-robust baseline, Re(s) < -2 at mu = 0.4), 3 robust (mixed H2/H-inf gain, the default)";
        let items = items_in_description(controller).unwrap();
        assert_eq!(
            items.into_iter().collect::<Vec<_>>(),
            [(1, "open_loop".to_string()), (2, "pole_placement".to_string()), (3, "robust".to_string())]
        );
        assert_eq!(items_in_description("1 paper, 2 real").unwrap().len(), 2);
        for not in ["the mass of the car", "1 open_loop", "1 a, 1 b", "1 a, two b", "1 a b, 2 c", "1 a (x, 2 b"] {
            assert_eq!(items_in_description(not), None, "{not}");
        }
    }

    #[test]
    fn a_log_axis_labels_1_2_and_5_times_a_power_of_ten() {
        let t: Vec<String> =
            [0.01, 0.02, 0.03, 0.05, 0.07, 0.1, 0.2 + 1e-12, 0.9, 50.0].iter().map(|v| log_tick(*v)).collect();
        assert_eq!(t, ["0.01", "0.02", "", "0.05", "", "0.1", "0.2", "", "50"]);
    }

    #[test]
    fn tick_labels_are_short() {
        let t: Vec<String> = [0.0, 1e-5, 1e-4, 0.001, 0.25, 1.0, 10.0, 2e5, -0.5].iter().map(|v| tick(*v)).collect();
        assert_eq!(t, ["0", "1e-5", "0.0001", "0.001", "0.25", "1", "10", "2e5", "-0.5"]);
    }
}
