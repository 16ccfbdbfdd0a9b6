//! The campaign description (TOML): the system, the experiment, what varies and the
//! metrics; checked against the system's variables before anything runs.
//!
//! Runs are numbered `0 .. grid points x samples`: run `i` is grid point `i / samples`
//! (the grid's first key varies slowest, its last fastest, as nested loops in the order
//! written) and sample `i % samples`; its random values are drawn from `(seed, column,
//! i % samples)` only ([`crate::rng`]), so they never depend on threads, shards or order.
//! Every grid point gets the same draws for its sample `s` (common random numbers): two
//! controllers, say, meet the same masses, speeds and seeds, and are compared run by run.

use std::path::{Path, PathBuf};

use model_description::VariableType;
use nigel_cosim::{Algorithm, BaseType, System, SystemBuilder, Value};
use sha2::{Digest, Sha256};

use crate::rng;
use crate::Error;
use nigel_cosim::check::Check;
use nigel_cosim::metric::Metric;

pub use crate::rng::Distribution;
pub use crate::scalar::Scalar;

/// What a column's values are.
#[derive(Clone, Debug, PartialEq)]
pub enum Domain {
    /// A grid dimension: these values, each run of the grid point gets one.
    Grid(Vec<Scalar>),
    /// Named cases, a grid dimension: each case sets its own variables (the column holds
    /// the case's index, its name is in [`Column::case_names`]).
    Cases(Vec<(String, Vec<(String, Scalar)>)>),
    /// Drawn per run.
    Random(Distribution),
}

/// One varied quantity: a results column, the variables it sets and its domain.
#[derive(Clone, Debug, PartialEq)]
pub struct Column {
    /// The column's name (the TOML key).
    pub name: String,
    /// The variables that receive the value (several: one value applied to all; for
    /// cases, the variables of each case are in the domain).
    pub targets: Vec<String>,
    /// Its values.
    pub domain: Domain,
}

impl Column {
    /// The case names of a [`Domain::Cases`] column (empty otherwise).
    pub fn case_names(&self) -> Vec<String> {
        match &self.domain {
            Domain::Cases(c) => c.iter().map(|(n, _)| n.clone()).collect(),
            _ => Vec::new(),
        }
    }
}

/// A parsed, checked campaign description.
#[derive(Clone, Debug)]
pub struct Spec {
    /// The description file.
    pub path: PathBuf,
    /// The system (`.ssp` / `.ssd`), resolved.
    pub system: PathBuf,
    /// Start time, s: the SSD's `DefaultExperiment` `startTime` (SSP 1.0), else 0, as
    /// `cosim run` starts it.
    pub start_time: f64,
    /// Stop time, s.
    pub stop_time: f64,
    /// Communication step, s.
    pub step: f64,
    /// The master's algorithm.
    pub algorithm: Algorithm,
    /// Wall-clock limit of one run (`timeout = 10.0`, seconds): a run past it fails with
    /// its message and the campaign goes on.
    pub timeout: Option<std::time::Duration>,
    /// The campaign's random seed.
    pub seed: u64,
    /// Random draws per grid point.
    pub samples: u64,
    /// The varied columns: grid dimensions first (in the order written), then random ones.
    pub columns: Vec<Column>,
    /// The metrics, in the order written.
    pub metrics: Vec<(String, Metric)>,
    /// The checks (`[checks]`, name = "max(abs(plant.y)) < 0.6"), in the order written: a
    /// run whose check fails is a failed run ([`crate::results::STATUS_CHECK_FAILED`]).
    pub checks: Vec<(String, Check)>,
    /// SHA-256 of the description's text and of the system file's bytes (hex): what a
    /// shard and an output folder are checked against.
    pub hash: String,
}

/// One run's values: per column its number in the results and the variables it sets.
#[derive(Clone, Debug, PartialEq)]
pub struct RunValues {
    /// The run's number.
    pub run: u64,
    /// Per column (as [`Spec::columns`]) its value in the results.
    pub numbers: Vec<f64>,
    /// The start values to set, `instance.variable` and value.
    pub assignments: Vec<(String, Scalar)>,
}

fn scalar(v: &toml::Value, what: &str) -> Result<Scalar, String> {
    match v {
        toml::Value::Float(x) => Ok(Scalar::Real(*x)),
        toml::Value::Integer(i) => Ok(Scalar::Integer(*i)),
        toml::Value::Boolean(b) => Ok(Scalar::Boolean(*b)),
        other => Err(format!("{what}: {other} is not a number or a Boolean")),
    }
}

fn number(v: &toml::Value, what: &str) -> Result<f64, String> {
    match v {
        toml::Value::Float(x) => Ok(*x),
        toml::Value::Integer(i) => Ok(*i as f64),
        other => Err(format!("{what}: {other} is not a number")),
    }
}

fn pair(v: &toml::Value, what: &str) -> Result<(f64, f64), String> {
    match v.as_array().map(|a| a.as_slice()) {
        Some([a, b]) => Ok((number(a, what)?, number(b, what)?)),
        _ => Err(format!("{what}: expected [low, high], got {v}")),
    }
}

fn distribution(key: &str, v: &toml::Value) -> Result<(Distribution, Vec<String>), String> {
    let what = format!("[random] {key:?}");
    let t = v.as_table().ok_or_else(|| format!("{what}: expected a table such as {{ uniform = [0, 1] }}, got {v}"))?;
    let mut dist = None;
    let mut targets = None;
    let (mut min, mut max) = (None, None);
    for (k, x) in t {
        let d = match k.as_str() {
            "uniform" => {
                let (a, b) = pair(x, &format!("{what} uniform"))?;
                if !(a.is_finite() && b.is_finite() && a < b) {
                    return Err(format!("{what} uniform: need finite low < high, got [{a}, {b}]"));
                }
                Some(Distribution::Uniform(a, b))
            }
            "normal" => {
                let (mean, std) = pair(x, &format!("{what} normal ([mean, std])"))?;
                if !(mean.is_finite() && std.is_finite() && std > 0.0) {
                    return Err(format!("{what} normal: need a finite mean and std > 0, got [{mean}, {std}]"));
                }
                Some(Distribution::Normal { mean, std, min: None, max: None })
            }
            "integers" => match x.as_array().map(|a| a.as_slice()) {
                Some([toml::Value::Integer(a), toml::Value::Integer(b)]) if a <= b => {
                    Some(Distribution::Integers(*a, *b))
                }
                _ => return Err(format!("{what} integers: expected [low, high] (integers, low <= high), got {x}")),
            },
            "choice" => {
                let a = x
                    .as_array()
                    .filter(|a| !a.is_empty())
                    .ok_or_else(|| format!("{what} choice: expected a non-empty list, got {x}"))?;
                Some(Distribution::Choice(
                    a.iter().map(|e| scalar(e, &format!("{what} choice"))).collect::<Result<_, _>>()?,
                ))
            }
            "min" => {
                min = Some(number(x, &format!("{what} min"))?);
                None
            }
            "max" => {
                max = Some(number(x, &format!("{what} max"))?);
                None
            }
            "set" => {
                targets = Some(names(x, &what)?);
                None
            }
            other => {
                return Err(format!(
                    "{what}: unknown key {other:?} (expected uniform, normal, integers, choice, min, max, set)"
                ))
            }
        };
        if let Some(d) = d {
            if dist.is_some() {
                return Err(format!("{what}: more than one distribution"));
            }
            dist = Some(d);
        }
    }
    let mut dist = dist.ok_or_else(|| format!("{what}: no distribution (uniform, normal, integers or choice)"))?;
    match &mut dist {
        Distribution::Normal { min: lo, max: hi, mean, std } => {
            if let (Some(a), Some(b)) = (min, max) {
                if a >= b {
                    return Err(format!("{what} normal: min {a} must be below max {b}"));
                }
            }
            // the rejection loop must find a value: at least 1 % of the mass inside
            let p = normal_mass(*mean, *std, min, max);
            if p < 0.01 {
                return Err(format!("{what} normal: [min, max] holds only {p:.1e} of the distribution"));
            }
            *lo = min;
            *hi = max;
        }
        _ if min.is_some() || max.is_some() => return Err(format!("{what}: min / max apply to normal only")),
        _ => {}
    }
    Ok((dist, targets.unwrap_or_else(|| vec![key.to_string()])))
}

/// P(min <= X <= max) for X ~ N(mean, std^2).
fn normal_mass(mean: f64, std: f64, min: Option<f64>, max: Option<f64>) -> f64 {
    let cdf = |x: f64| 0.5 * erfc(-(x - mean) / (std * std::f64::consts::SQRT_2));
    max.map_or(1.0, cdf) - min.map_or(0.0, cdf)
}

/// The complementary error function (Numerical Recipes' Chebyshev fit, |error| < 1.2e-7:
/// enough to decide whether a truncation leaves any mass).
fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let r = t
        * (-z * z - 1.26551223
            + t * (1.00002368
                + t * (0.37409196
                    + t * (0.09678418
                        + t * (-0.18628806
                            + t * (0.27886807
                                + t * (-1.13520398 + t * (1.48851587 + t * (-0.82215223 + t * 0.17087277)))))))))
            .exp();
    if x >= 0.0 {
        r
    } else {
        2.0 - r
    }
}

fn names(x: &toml::Value, what: &str) -> Result<Vec<String>, String> {
    let a = x
        .as_array()
        .filter(|a| !a.is_empty())
        .ok_or_else(|| format!("{what} set: expected a list of variable names"))?;
    a.iter()
        .map(|n| n.as_str().map(String::from).ok_or_else(|| format!("{what} set: {n} is not a variable name")))
        .collect()
}

fn grid_column(key: &str, v: &toml::Value) -> Result<Column, String> {
    let what = format!("[grid] {key:?}");
    let (values, targets) = match v {
        toml::Value::Array(a) => (a.clone(), vec![key.to_string()]),
        toml::Value::Table(t) => {
            for k in t.keys() {
                if k != "values" && k != "set" {
                    return Err(format!("{what}: unknown key {k:?} (expected values, set)"));
                }
            }
            let values = t
                .get("values")
                .and_then(|x| x.as_array())
                .cloned()
                .ok_or_else(|| format!("{what}: no values = [...]"))?;
            let targets = match t.get("set") {
                Some(s) => names(s, &what)?,
                None => vec![key.to_string()],
            };
            (values, targets)
        }
        other => return Err(format!("{what}: expected a list of values, got {other}")),
    };
    if values.is_empty() {
        return Err(format!("{what}: no values"));
    }
    let values = values.iter().map(|x| scalar(x, &what)).collect::<Result<Vec<_>, _>>()?;
    Ok(Column { name: key.to_string(), targets, domain: Domain::Grid(values) })
}

fn cases_column(key: &str, v: &toml::Value) -> Result<Column, String> {
    let what = format!("[cases] {key:?}");
    let t = v.as_table().filter(|t| !t.is_empty()).ok_or_else(|| {
        format!(
            "{what}: expected named cases, e.g. {key} = {{ sim = {{ \"maneuver.fidelity\" = 1 }}, real = {{ ... }} }}"
        )
    })?;
    let mut cases = Vec::new();
    let mut targets: Vec<String> = Vec::new();
    for (name, sets) in t {
        let sets = sets.as_table().ok_or_else(|| format!("{what} {name:?}: expected a table of variable = value"))?;
        let mut list = Vec::new();
        for (var, x) in sets {
            list.push((var.clone(), scalar(x, &format!("{what} {name:?} {var:?}"))?));
            if !targets.contains(var) {
                targets.push(var.clone());
            }
        }
        cases.push((name.clone(), list));
    }
    Ok(Column { name: key.to_string(), targets, domain: Domain::Cases(cases) })
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// The declared type and bounds of a variable, as the description's values are checked.
struct Declared {
    base: BaseType,
    min: f64,
    max: f64,
}

fn declared(system: &System, name: &str) -> Result<Declared, String> {
    let r = system.resolve(name).map_err(|e| format!("unknown variable {name}: {e}"))?;
    let v = system.variable(&r);
    let (min, max) = match &v.variable_type {
        VariableType::Real { min, max, .. } => (min.unwrap_or(f64::NEG_INFINITY), max.unwrap_or(f64::INFINITY)),
        VariableType::Integer { min, max, .. } | VariableType::Enumeration { min, max, .. } => {
            (min.map_or(i32::MIN as f64, f64::from), max.map_or(i32::MAX as f64, f64::from))
        }
        _ => (f64::NEG_INFINITY, f64::INFINITY),
    };
    Ok(Declared { base: r.base_type, min, max })
}

fn check_scalar(system: &System, var: &str, x: &Scalar, what: &str) -> Result<(), String> {
    let d = declared(system, var).map_err(|e| format!("{what}: {e}"))?;
    let ok_type = matches!(
        (d.base, x),
        (BaseType::Real, Scalar::Real(_) | Scalar::Integer(_))
            | (BaseType::Integer, Scalar::Integer(_))
            | (BaseType::Boolean, Scalar::Boolean(_))
    );
    if !ok_type {
        return Err(format!("{what}: {var} is {} but the value is {}", d.base.as_str(), x.describe()));
    }
    if let Scalar::Real(_) | Scalar::Integer(_) = x {
        let n = x.number();
        if !(d.min <= n && n <= d.max) {
            return Err(format!("{what}: {} is outside {var}'s declared range [{}, {}]", n, d.min, d.max));
        }
    }
    if let Scalar::Integer(i) = x {
        if d.base == BaseType::Integer && i32::try_from(*i).is_err() {
            return Err(format!("{what}: {i} does not fit {var} (a 32-bit Integer)"));
        }
    }
    Ok(())
}

fn check_distribution(system: &System, var: &str, dist: &Distribution, what: &str) -> Result<(), String> {
    let d = declared(system, var).map_err(|e| format!("{what}: {e}"))?;
    let need = |ok: bool, kind: &str| {
        if ok {
            Ok(())
        } else {
            Err(format!("{what}: {var} is {}, {kind} cannot set it", d.base.as_str()))
        }
    };
    let range = |a: f64, b: f64| {
        if d.min <= a && b <= d.max {
            Ok(())
        } else {
            Err(format!("{what}: [{a}, {b}] is outside {var}'s declared range [{}, {}]", d.min, d.max))
        }
    };
    match dist {
        Distribution::Uniform(a, b) => {
            need(d.base == BaseType::Real, "uniform (Real draws)")?;
            range(*a, *b)
        }
        Distribution::Normal { min, max, .. } => {
            need(d.base == BaseType::Real, "normal (Real draws)")?;
            range(min.unwrap_or(f64::NEG_INFINITY), max.unwrap_or(f64::INFINITY)).map_err(|e| {
                if min.is_none() || max.is_none() {
                    format!("{e}: give the normal min / max inside it")
                } else {
                    e
                }
            })
        }
        Distribution::Integers(a, b) => {
            need(matches!(d.base, BaseType::Integer | BaseType::Real), "integers")?;
            range(*a as f64, *b as f64)
        }
        Distribution::Choice(values) => values.iter().try_for_each(|x| check_scalar(system, var, x, what)),
    }
}

impl Spec {
    /// Reads and checks the description at `path` (its system loaded to check the
    /// variables: every error is one line naming the key and the reason).
    pub fn load(path: &Path) -> Result<Spec, Error> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::Spec(format!("{}: {e}", path.display())))?;
        let (spec, system) = Spec::parse(path, &text)?;
        let bad = |m: String| Error::Spec(format!("{}: {m}", path.display()));
        spec.check(&system).map_err(bad)?;
        Ok(spec)
    }

    /// Parses `text` (the description at `path`) and reads its system (the model
    /// descriptions, no library loaded).
    pub fn parse(path: &Path, text: &str) -> Result<(Spec, System), Error> {
        let bad = |m: String| Error::Spec(format!("{}: {m}", path.display()));
        let doc: toml::Table = text.parse().map_err(|e: toml::de::Error| {
            bad(e.message().trim().replace('\n', "; ")
                + &e.span().map_or(String::new(), |s| format!(" (at byte {})", s.start)))
        })?;
        let get_f = |k: &str| -> Result<f64, Error> {
            doc.get(k).ok_or_else(|| bad(format!("missing {k}"))).and_then(|v| number(v, k).map_err(bad))
        };
        for k in doc.keys() {
            if ![
                "system",
                "stop_time",
                "step",
                "algorithm",
                "timeout",
                "seed",
                "samples",
                "grid",
                "cases",
                "random",
                "metrics",
                "checks",
            ]
            .contains(&k.as_str())
            {
                return Err(bad(format!(
                    "unknown key {k:?} (expected system, stop_time, step, algorithm, timeout, seed, samples, grid, cases, random, metrics, checks)"
                )));
            }
        }
        let system_text =
            doc.get("system").and_then(|v| v.as_str()).ok_or_else(|| bad("missing system = \"...ssp\"".into()))?;
        let system = resolve_system(path, system_text).map_err(bad)?;
        let stop_time = get_f("stop_time")?;
        let step = get_f("step")?;
        if !(step > 0.0 && step.is_finite() && stop_time.is_finite()) {
            return Err(bad(format!("need 0 < step, a finite stop_time, got step {step}, stop_time {stop_time}")));
        }
        let algorithm = match doc.get("algorithm").map(|v| v.as_str()) {
            None | Some(Some("ordered")) => Algorithm::Ordered,
            Some(Some("jacobi")) => Algorithm::Jacobi,
            Some(_) => return Err(bad("algorithm: expected \"ordered\" or \"jacobi\"".into())),
        };
        let timeout = match doc.get("timeout") {
            None => None,
            Some(v) => {
                let t = number(v, "timeout").map_err(bad)?;
                if !(t.is_finite() && t > 0.0) {
                    return Err(bad(format!("timeout: expected seconds > 0, got {t}")));
                }
                Some(std::time::Duration::from_secs_f64(t))
            }
        };
        let uint = |k: &str, default: u64| -> Result<u64, Error> {
            match doc.get(k) {
                None => Ok(default),
                Some(toml::Value::Integer(i)) if *i >= 0 => Ok(*i as u64),
                Some(v) => Err(bad(format!("{k}: expected a non-negative integer, got {v}"))),
            }
        };
        let seed = uint("seed", 0)?;
        let samples = uint("samples", 1)?;
        if samples == 0 {
            return Err(bad("samples must be at least 1".into()));
        }
        let section = |k: &str| -> Result<Option<&toml::Table>, Error> {
            match doc.get(k) {
                None => Ok(None),
                Some(toml::Value::Table(t)) => Ok(Some(t)),
                Some(v) => Err(bad(format!("[{k}] must be a table, got {v}"))),
            }
        };
        let mut columns = Vec::new();
        if let Some(t) = section("grid")? {
            for (k, v) in t {
                columns.push(grid_column(k, v).map_err(bad)?);
            }
        }
        if let Some(t) = section("cases")? {
            for (k, v) in t {
                columns.push(cases_column(k, v).map_err(bad)?);
            }
        }
        if let Some(t) = section("random")? {
            for (k, v) in t {
                let (d, targets) = distribution(k, v).map_err(bad)?;
                columns.push(Column { name: k.clone(), targets, domain: Domain::Random(d) });
            }
        }
        let mut seen = std::collections::HashSet::new();
        for c in &columns {
            if !seen.insert(c.name.clone()) {
                return Err(bad(format!("{:?} is varied twice", c.name)));
            }
        }
        let mut metrics = Vec::new();
        if let Some(t) = section("metrics")? {
            for (k, v) in t {
                let e = v
                    .as_str()
                    .ok_or_else(|| bad(format!("[metrics] {k:?}: expected an expression string, got {v}")))?;
                let m = Metric::parse(e).map_err(|m| bad(format!("[metrics] {k:?}: {m}")))?;
                if seen.contains(k) || ["run", "status", "message"].contains(&k.as_str()) {
                    return Err(bad(format!("[metrics] {k:?}: the name is already a column")));
                }
                metrics.push((k.clone(), m));
            }
        }
        let mut checks = Vec::new();
        if let Some(t) = section("checks")? {
            for (k, v) in t {
                let e = v.as_str().ok_or_else(|| {
                    bad(format!("[checks] {k:?}: expected a check such as \"max(abs(plant.y)) < 0.6\", got {v}"))
                })?;
                let c = Check::parse(e).map_err(|m| bad(format!("[checks] {k:?}: {m}")))?;
                checks.push((k.clone(), c));
            }
        }
        let mut hasher = Sha256::new();
        hasher.update(text.as_bytes());
        let system_bytes = std::fs::read(&system).map_err(|e| bad(format!("{}: {e}", system.display())))?;
        hasher.update(Sha256::digest(&system_bytes));
        let hash = hex(&hasher.finalize());
        // only the model descriptions are needed here: the FMUs' libraries are not loaded
        // (a library that crashes while loading ends a worker process, not the campaign)
        let (loaded, start_time) = load_system_and_start(&system, true).map_err(bad)?;
        if !start_time.is_finite() || stop_time < start_time + step {
            return Err(bad(format!(
                "need start time + step <= stop_time, got start time {start_time} s{}, step {step}, stop_time {stop_time}",
                if start_time != 0.0 { " (the SSD's DefaultExperiment)" } else { "" }
            )));
        }
        Ok((
            Spec {
                path: path.to_path_buf(),
                system,
                start_time,
                stop_time,
                step,
                algorithm,
                timeout,
                seed,
                samples,
                columns,
                metrics,
                checks,
                hash,
            },
            loaded,
        ))
    }

    /// Checks every variable, type and range of the description against `system`, and
    /// that every metric's variables exist.
    pub fn check(&self, system: &System) -> Result<(), String> {
        for c in &self.columns {
            match &c.domain {
                Domain::Grid(values) => {
                    let what = format!("[grid] {:?}", c.name);
                    for t in &c.targets {
                        for x in values {
                            check_scalar(system, t, x, &what)?;
                        }
                    }
                }
                Domain::Cases(cases) => {
                    for (name, sets) in cases {
                        for (var, x) in sets {
                            check_scalar(system, var, x, &format!("[cases] {:?} {name:?}", c.name))?;
                        }
                    }
                }
                Domain::Random(d) => {
                    let what = format!("[random] {:?}", c.name);
                    for t in &c.targets {
                        check_distribution(system, t, d, &what)?;
                    }
                }
            }
        }
        for (name, m) in &self.metrics {
            for v in m.variables() {
                system.resolve(&v).map_err(|e| format!("[metrics] {name:?}: unknown variable {v}: {e}"))?;
            }
        }
        for (name, c) in &self.checks {
            for v in c.variables() {
                system.resolve(&v).map_err(|e| format!("[checks] {name:?}: unknown variable {v}: {e}"))?;
            }
        }
        // the first run's values go through the master's own checks (causality, settable)
        if self.runs() > 0 {
            self.system_of(system, &self.values(0)).map_err(|e| format!("run 0: {e}"))?;
        }
        Ok(())
    }

    /// Grid points (the product of the grid and case dimensions).
    pub fn grid_points(&self) -> u64 {
        self.columns
            .iter()
            .map(|c| match &c.domain {
                Domain::Grid(v) => v.len() as u64,
                Domain::Cases(v) => v.len() as u64,
                Domain::Random(_) => 1,
            })
            .product()
    }

    /// Number of runs: grid points x samples.
    pub fn runs(&self) -> u64 {
        self.grid_points() * self.samples
    }

    /// The values of run `i` (a pure function of the description and `i`).
    pub fn values(&self, i: u64) -> RunValues {
        let mut point = i / self.samples;
        // the last grid dimension varies fastest
        let mut grid_index = vec![0usize; self.columns.len()];
        for (k, c) in self.columns.iter().enumerate().rev() {
            let n = match &c.domain {
                Domain::Grid(v) => v.len() as u64,
                Domain::Cases(v) => v.len() as u64,
                Domain::Random(_) => continue,
            };
            grid_index[k] = (point % n) as usize;
            point /= n;
        }
        let mut numbers = Vec::with_capacity(self.columns.len());
        let mut assignments = Vec::new();
        for (k, c) in self.columns.iter().enumerate() {
            match &c.domain {
                Domain::Grid(v) => {
                    let x = &v[grid_index[k]];
                    numbers.push(x.number());
                    assignments.extend(c.targets.iter().map(|t| (t.clone(), x.clone())));
                }
                Domain::Cases(cases) => {
                    numbers.push(grid_index[k] as f64);
                    assignments.extend(cases[grid_index[k]].1.iter().cloned());
                }
                Domain::Random(d) => {
                    let x = rng::draw(d, self.seed, &c.name, i % self.samples);
                    numbers.push(x.number());
                    assignments.extend(c.targets.iter().map(|t| (t.clone(), x.clone())));
                }
            }
        }
        RunValues { run: i, numbers, assignments }
    }

    /// `base` with run `values` set as start values (each checked by the master).
    pub fn system_of(&self, base: &System, values: &RunValues) -> Result<System, String> {
        let mut b = SystemBuilder::from_system(base.clone());
        for (var, x) in &values.assignments {
            let value = match x {
                Scalar::Real(v) => Value::Real(*v),
                Scalar::Integer(i) => match base.resolve(var).map(|r| r.base_type) {
                    Ok(BaseType::Real) => Value::Real(*i as f64),
                    _ => Value::Integer(
                        i32::try_from(*i).map_err(|_| format!("{var}: {i} does not fit a 32-bit Integer"))?,
                    ),
                },
                Scalar::Boolean(v) => Value::Boolean(*v),
            };
            b.set(var, value).map_err(|e| format!("{var}: {e}"))?;
        }
        Ok(b.build())
    }

    /// The names of the results columns: `run`, `status`, `message`, each varied column,
    /// each metric.
    pub fn header(&self) -> Vec<String> {
        let mut h: Vec<String> = ["run", "status", "message"].into_iter().map(String::from).collect();
        h.extend(self.columns.iter().map(|c| c.name.clone()));
        h.extend(self.metrics.iter().map(|(n, _)| n.clone()));
        h
    }

    /// The block of runs of shard `index` of `count` (contiguous, sizes differing by at
    /// most one).
    pub fn shard_range(&self, index: u64, count: u64) -> std::ops::Range<u64> {
        let n = self.runs();
        (index * n / count)..((index + 1) * n / count)
    }
}

fn resolve_system(spec: &Path, text: &str) -> Result<PathBuf, String> {
    let p = Path::new(text);
    if p.is_absolute() {
        return if p.exists() { Ok(p.to_path_buf()) } else { Err(format!("system {text}: no such file")) };
    }
    // relative paths are from the repository root (the working folder) or, failing
    // that, from the description's folder and its parents
    let mut tried = vec![PathBuf::from(text)];
    if p.exists() {
        return Ok(std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf()));
    }
    let abs = std::path::absolute(spec).unwrap_or_else(|_| spec.to_path_buf());
    for dir in abs.ancestors().skip(1) {
        let c = dir.join(p);
        if c.exists() {
            return Ok(c);
        }
        tried.push(c);
    }
    Err(format!(
        "system {text}: no such file (looked in {}; build it with `cargo run --release -p build-fmu` or give its path)",
        tried.iter().take(3).map(|t| t.display().to_string()).collect::<Vec<_>>().join(", ")
    ))
}

/// Reads an `.ssp` / `.ssd` (or a single `.fmu` as instance `model`).
pub fn load_system(path: &Path) -> Result<System, String> {
    load_system_with(path, false)
}

/// [`load_system`]; `isolated`: without loading the FMUs' libraries (their model
/// descriptions and the functions their symbol tables list; such a system is checked, not
/// run in this process).
pub fn load_system_with(path: &Path, isolated: bool) -> Result<System, String> {
    load_system_and_start(path, isolated).map(|(system, _)| system)
}

/// [`load_system_with`] and the run's start time: an SSD's `DefaultExperiment`
/// `startTime`, else 0 (a single FMU starts at 0, as `cosim run` starts it).
pub fn load_system_and_start(path: &Path, isolated: bool) -> Result<(System, f64), String> {
    let opts = nigel_cosim::ImportOptions { isolated, ..nigel_cosim::ImportOptions::default() };
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if ext == "fmu" {
        let fmu = nigel_cosim::Fmu::load_with(path, &opts).map_err(|e| format!("{}: {e}", path.display()))?;
        Ok((System::single("model", fmu).map_err(|e| format!("{}: {e}", path.display()))?, 0.0))
    } else {
        let ssp = nigel_cosim::read_ssp(path, &opts).map_err(|e| format!("{}: {e}", path.display()))?;
        Ok((ssp.system, ssp.default_start_stop.0.unwrap_or(0.0)))
    }
}
