//! The public types of a run: what to simulate ([`Experiment`], [`Algorithm`]) and what
//! comes back ([`Results`], [`Summary`]).

use std::time::Duration;

/// How connections are updated at communication points.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Algorithm {
    /// Every connection delayed by one step (all outputs read, then all inputs set), as
    /// fmpy `simulate_ssp`, libcosim and ecos do.
    Jacobi,
    /// Outputs flow along direct-feedthrough chains in topological order, so an input sees
    /// its source at the same communication point; algebraic loops are refused by name.
    Ordered,
}

impl std::str::FromStr for Algorithm {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "jacobi" => Ok(Algorithm::Jacobi),
            "ordered" => Ok(Algorithm::Ordered),
            _ => Err(format!("unknown algorithm {s:?} (jacobi, ordered)")),
        }
    }
}

/// The default of [`Experiment::max_steps`]: a thousand million steps (about half an
/// hour of the closed loop at its speed).
pub const DEFAULT_MAX_STEPS: u64 = 1_000_000_000;

/// What to simulate.
#[derive(Clone, Debug)]
pub struct Experiment {
    /// Start time t0, s.
    pub start_time: f64,
    /// Stop time, s.
    pub stop_time: f64,
    /// Communication step h, s.
    pub step: f64,
    /// Algorithm.
    pub algorithm: Algorithm,
    /// Output interval (a whole multiple of `step`); `None`: every step.
    pub output_interval: Option<f64>,
    /// Variables to record (`instance.variable`); `None`: every output of every instance.
    pub record: Option<Vec<String>>,
    /// Measure the time spent in each FMU (one clock read per call boundary).
    pub profile: bool,
    /// Threads stepping the instances of a `jacobi` system (1: all in the calling
    /// thread). Each instance is called by one thread at a time; the results are the
    /// same for any number. `ordered` always runs in one thread.
    pub threads: usize,
    /// Integration method of Model Exchange instances.
    pub solver: crate::me::Solver,
    /// On fmi2Discard from `fmi2DoStep` of an FMU that can get and set its state and
    /// handle variable steps: restore the state and retry in halves (at most 2^10
    /// sub-steps). Costs one `fmi2GetFMUstate` per step of those FMUs. Off: a Discard
    /// stops the run with [`Error::Fmi`](crate::Error::Fmi).
    pub retry_discard: bool,
    /// Input signals over time (fmpy's `input=`), applied before every communication
    /// step; the variables they drive must not be connected.
    pub input: Option<std::sync::Arc<crate::simulate::input_table::InputTable>>,
    /// The cap on the steps of a run: communication steps, and the internal steps
    /// (accepted and rejected) of the Model Exchange integrator; a run that would take
    /// more stops with [`Error::Experiment`](crate::Error::Experiment) (an adaptive step that shrinks without end
    /// never hangs the run).
    pub max_steps: u64,
    /// Instances in host processes of their own (`None`: all in this process).
    pub isolation: Option<crate::isolate::Isolation>,
    /// The wall-clock limit of the whole run ([`Error::Timeout`](crate::Error::Timeout), or
    /// [`Error::Host`](crate::Error::Host) when it passes during a call of an isolated instance).
    pub timeout: Option<Duration>,
    /// The relative tolerance told to the Co-Simulation FMUs (`fmi2SetupExperiment`,
    /// `fmi3EnterInitializationMode`) for their internal solvers; `None`: each FMU's
    /// DefaultExperiment tolerance, else none (fmpy's rule). Model Exchange FMUs are told
    /// none (the master's solver has its own, [`Experiment::solver`]).
    pub co_simulation_tolerance: Option<f64>,
}

impl Experiment {
    /// `stop_time` with step `h` from 0, jacobi, every step recorded.
    pub fn new(stop_time: f64, step: f64) -> Experiment {
        Experiment {
            start_time: 0.0,
            stop_time,
            step,
            algorithm: Algorithm::Jacobi,
            output_interval: None,
            record: None,
            profile: false,
            threads: 1,
            solver: crate::me::Solver::default(),
            retry_discard: false,
            input: None,
            max_steps: DEFAULT_MAX_STEPS,
            isolation: None,
            timeout: None,
            co_simulation_tolerance: None,
        }
    }
}

/// Results: one row per output point, `time` first.
#[derive(Clone, Debug, Default)]
pub struct Results {
    /// Column names after `time` (`instance.variable`, or the bare name for a one-instance system).
    pub names: Vec<String>,
    /// Row-major values: `time, v1, v2, ...` per row.
    pub values: Vec<f64>,
    /// The columns whose values an f64 does not hold (FMI 3.0 Int64 and UInt64, Binary,
    /// String), each with the text of every row as fmpy writes it (an integer in decimal,
    /// a Binary in hex, a String as it is); [`Results::values`] holds the nearest f64 there
    /// (a Binary its size in bytes, a String NaN). The CSV file has the text.
    pub exact: Vec<ExactColumn>,
}

/// The text of one column of [`Results`] whose values an f64 does not hold.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ExactColumn {
    /// The column (0-based among [`Results::names`]).
    pub column: usize,
    /// One text per row.
    pub rows: Vec<String>,
}

impl Results {
    /// Number of columns including time.
    pub fn width(&self) -> usize {
        self.names.len() + 1
    }
    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.values.len() / self.width()
    }
    /// Row `k` (time first).
    pub fn row(&self, k: usize) -> &[f64] {
        &self.values[k * self.width()..(k + 1) * self.width()]
    }
    /// The column called `name` (`"time"` for time).
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let j = if name == "time" { 0 } else { self.names.iter().position(|n| n == name)? + 1 };
        Some((0..self.rows()).map(|k| self.row(k)[j]).collect())
    }

    /// The columns called `names` (others left out), in this table's order, time first.
    pub fn select(&self, names: &[String]) -> Results {
        let keep: Vec<usize> = (0..self.names.len()).filter(|j| names.contains(&self.names[*j])).collect();
        let mut values = Vec::with_capacity(self.rows() * (keep.len() + 1));
        for k in 0..self.rows() {
            let row = self.row(k);
            values.push(row[0]);
            values.extend(keep.iter().map(|j| row[j + 1]));
        }
        let exact = self
            .exact
            .iter()
            .filter_map(|e| {
                let column = keep.iter().position(|j| *j == e.column)?;
                Some(ExactColumn { column, rows: e.rows.clone() })
            })
            .collect();
        Results { names: keep.iter().map(|j| self.names[*j].clone()).collect(), values, exact }
    }

    /// The text of column `column` (0-based among the names) in every row, if an f64 does
    /// not hold its values ([`Results::exact`]).
    pub fn exact_column(&self, column: usize) -> Option<&[String]> {
        self.exact.iter().find(|e| e.column == column).map(|e| e.rows.as_slice())
    }

    /// Writes CSV as fmpy does: comma-separated, quoted names, `time` first; numbers
    /// in the shortest form that reads back to the same f64.
    pub fn write_csv<W: std::io::Write>(&self, mut w: W) -> std::io::Result<()> {
        let mut line = String::from("\"time\"");
        for n in &self.names {
            line.push_str(",\"");
            line.push_str(&n.replace('"', "\"\""));
            line.push('"');
        }
        line.push('\n');
        w.write_all(line.as_bytes())?;
        // the text of the columns an f64 does not hold, by column (time first)
        let mut text: Vec<Option<&[String]>> = vec![None; self.width()];
        for e in &self.exact {
            if let Some(t) = text.get_mut(e.column + 1) {
                *t = Some(&e.rows);
            }
        }
        for k in 0..self.rows() {
            line.clear();
            for (j, v) in self.row(k).iter().enumerate() {
                if j > 0 {
                    line.push(',');
                }
                match text[j].and_then(|rows| rows.get(k)) {
                    Some(t) => push_text(&mut line, t),
                    None => push_number(&mut line, *v),
                }
            }
            line.push('\n');
            w.write_all(line.as_bytes())?;
        }
        w.flush()
    }
}

/// A text cell: as it is, or quoted (quotes doubled) when it holds a comma, a quote or a
/// line break.
fn push_text(out: &mut String, t: &str) {
    if t.contains([',', '"', '\n', '\r']) {
        out.push('"');
        out.push_str(&t.replace('"', "\"\""));
        out.push('"');
    } else {
        out.push_str(t);
    }
}

/// Shortest round-trip text of `v` (exponent form for very small or large magnitudes): Rust's
/// `{v}` for magnitudes in [1e-5, 1e16), zero and the non-finite, `{v:e}` for the others.
/// `ryu` prints the same digits in a tenth of the instructions of core::fmt, in the same forms
/// (`0.35`, `1e-7`, `1.5e20`; its decimal form of an integer ends in `.0`, cut here) switched
/// at the same magnitudes (10^-5 and 10^16, by the printed digits, which round to v), except
/// where two shortest texts are equally near v (ryu takes the even, core::fmt the larger):
/// that needs v's exact value to have at most 18 significant digits, which it has only when
/// v = m·2^e (m odd) with e >= -25 (m·5^-e < 10^18 for e < 0); those, rare in results, are
/// printed by core::fmt (tests push_number_prints_as_rust_display_and_lower_exp).
pub fn push_number(out: &mut String, v: f64) {
    if v == 0.0 || !v.is_finite() || odd_exponent(v) >= -25 {
        use std::fmt::Write;
        let a = v.abs();
        if v == 0.0 || (1e-5..1e16).contains(&a) || !v.is_finite() {
            let _ = write!(out, "{v}");
        } else {
            let _ = write!(out, "{v:e}");
        }
        return;
    }
    let mut buffer = ryu::Buffer::new();
    let text = buffer.format_finite(v);
    out.push_str(text.strip_suffix(".0").unwrap_or(text));
}

/// The exponent e of finite, nonzero `v` = m·2^e with m odd.
fn odd_exponent(v: f64) -> i32 {
    let bits = v.to_bits();
    let biased = ((bits >> 52) & 0x7ff) as i32;
    let fraction = bits & ((1u64 << 52) - 1);
    let (mantissa, exponent) = if biased == 0 { (fraction, -1074) } else { (fraction | 1 << 52, biased - 1075) };
    exponent + mantissa.trailing_zeros() as i32
}

/// [`push_number`]'s text of `v` (`0.35`, `1.6940658945086007e-21`).
pub fn number_text(v: f64) -> String {
    let mut s = String::new();
    push_number(&mut s, v);
    s
}

/// A JSON-able run summary.
#[derive(Clone, Debug, Default)]
pub struct Summary {
    /// Communication steps completed.
    pub steps: u64,
    /// Wall time of initialization + loop.
    pub wall_time: Duration,
    /// Per instance: name and time spent in its fmi2 calls (zero unless profiling).
    pub instance_time: Vec<(String, Duration)>,
    /// Warnings the FMUs logged (instance, message).
    pub warnings: Vec<(String, String)>,
    /// Events of Model Exchange instances.
    pub events: Vec<crate::me::Event>,
    /// Internal integrator steps of Model Exchange instances (accepted, rejected).
    pub integrator_steps: (u64, u64),
    /// The work of the bdf solver (right-hand sides, Jacobians, factorizations; zero
    /// with the other solvers).
    pub stiff: crate::bdf::Work,
    /// Steps redone in halves after an fmi2Discard.
    pub discard_retries: u64,
    /// `jacobi` steps run with the instances spread over threads (0 in one thread).
    pub parallel_steps: u64,
    /// The FMU that ended the run itself (FMI's fmi2Terminated / terminateSimulation):
    /// its instance, the time the run ended, and how it said so.
    pub ended_by: Option<(String, f64, &'static str)>,
    /// What the master did that a reader of the inputs may not expect (e.g. an input
    /// event between communication points applied at the next one), one sentence each.
    pub notes: Vec<String>,
    /// FMI 3.0 clocks: every clock's ticks in the run (`instance.clock`, or the clock's
    /// name in a one-instance system), input clocks ticked by the master and output clocks
    /// the FMU said ticked; empty when no FMU has clocks.
    pub clock_ticks: Vec<(String, u64)>,
}

impl Summary {
    /// As a JSON value.
    pub fn to_json(&self) -> serde_json::Value {
        let mut json = serde_json::json!({
            "steps": self.steps,
            "events": self.events.len(),
            "event_times": self.events.iter().map(|e| serde_json::json!({"instance": e.instance, "time": e.time, "kind": e.kind})).collect::<Vec<_>>(),
            "discard_retries": self.discard_retries,
            "parallel_steps": self.parallel_steps,
            "ended_by": self.ended_by.as_ref().map(|(i, t, r)| serde_json::json!({"instance": i, "time": t, "reason": r})),
            "integrator_steps": {"accepted": self.integrator_steps.0, "rejected": self.integrator_steps.1},
            "bdf": {"rhs": self.stiff.rhs, "jacobian_rhs": self.stiff.jacobian_rhs, "jacobians": self.stiff.jacobians, "factorizations": self.stiff.factorizations},
            "wall_time_s": self.wall_time.as_secs_f64(),
            "instances": self.instance_time.iter().map(|(n, d)| serde_json::json!({"name": n, "time_s": d.as_secs_f64()})).collect::<Vec<_>>(),
            "warnings": self.warnings.iter().map(|(n, m)| serde_json::json!({"instance": n, "message": m})).collect::<Vec<_>>(),
            "notes": self.notes,
        });
        if !self.clock_ticks.is_empty() {
            json["clock_ticks"] =
                self.clock_ticks.iter().map(|(n, k)| serde_json::json!({"clock": n, "ticks": k})).collect();
        }
        json
    }
}

#[cfg(test)]
mod tests {
    use super::push_number;

    /// The text Rust's core::fmt gives (the CSV's numbers before `ryu`): `{v}` in
    /// [1e-5, 1e16), at zero and for the non-finite, else `{v:e}`.
    fn rust_text(v: f64) -> String {
        let a = v.abs();
        if v == 0.0 || (1e-5..1e16).contains(&a) || !v.is_finite() {
            format!("{v}")
        } else {
            format!("{v:e}")
        }
    }

    #[test]
    fn push_number_prints_as_rust_display_and_lower_exp() {
        // the edges of the two forms, their neighbours, integers, the extremes
        let mut cases = vec![
            0.0,
            -0.0,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MIN_POSITIVE,
            f64::MAX,
            f64::MIN,
            f64::EPSILON,
            5e-324,
            1.0,
            10.0,
            100.0,
            1e-3,
            0.35,
            1.6940658945086007e-21,
            9007199254740993.0,
            // two shortest texts equally near (800142170491632.2 and .3): core::fmt's
            800142170491632.25,
            0.5,
            1.25,
            2.0f64.powi(-25) * 3.0,
            2.0f64.powi(-26) * 3.0,
        ];
        for edge in [1e-5f64, 1e-4, 1e15, 1e16, 1e17] {
            cases.extend([edge, f64::from_bits(edge.to_bits() - 1), f64::from_bits(edge.to_bits() + 1)]);
        }
        // a communication grid's times (k ms); from an xorshift, 400,000 bit patterns (every
        // exponent and mantissa) and 400,000 numbers of 1e-6 to 1e16 (the decimal form's)
        cases.extend((0..30_001).map(|k| k as f64 * 1e-3));
        let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
        for _ in 0..400_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            cases.push(f64::from_bits(x));
            cases.push((x >> 11) as f64 / (1u64 << 53) as f64 * 10f64.powi((x % 23) as i32 - 6));
        }
        for v in cases.iter().flat_map(|v| [*v, -*v]) {
            let mut text = String::new();
            push_number(&mut text, v);
            assert_eq!(text, rust_text(v), "bits {:#018x}", v.to_bits());
        }
    }
}
