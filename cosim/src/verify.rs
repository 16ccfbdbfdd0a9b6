//! What `cosim run` verifies after a run: its checks ([`crate::check`]) and its
//! comparison with a baseline ([`crate::compare`]); the variables they need recorded, the
//! lines printed, the JUnit test cases and the Markdown summary ([`crate::junit`]).

use crate::check::{self, Check, Verdict};
use crate::compare::{self, Comparison, Tolerance};
use crate::junit::{self, TestCase, TestSuite};
use crate::Results;
use std::path::{Path, PathBuf};

/// The `classname` of the check test cases.
pub const CHECK_CLASS: &str = "cosim.check";
/// The `classname` of the compared signals' test cases.
pub const BASELINE_CLASS: &str = "cosim.baseline";
/// The `classname` of the run's own test case.
pub const RUN_CLASS: &str = "cosim.run";

/// Checks and a baseline to judge a run by.
#[derive(Clone, Debug, Default)]
pub struct Verification {
    /// The checks, as parsed.
    pub checks: Vec<Check>,
    /// The baseline file and its contents.
    pub baseline: Option<(PathBuf, Results)>,
    /// The comparison's tolerances.
    pub tolerance: Tolerance,
    /// The signals to compare (default: all of the baseline's).
    pub signals: Option<Vec<String>>,
}

/// A judged run.
#[derive(Clone, Debug, Default)]
pub struct Judged {
    /// The checks' verdicts.
    pub verdicts: Vec<Verdict>,
    /// The comparison with the baseline.
    pub comparison: Option<Comparison>,
}

impl Verification {
    /// Parses the checks and reads the baseline (one-line errors naming the check or the file).
    pub fn new(
        checks: &[String],
        baseline: Option<&Path>,
        tolerance: Tolerance,
        signals: Option<Vec<String>>,
    ) -> Result<Verification, String> {
        tolerance.check()?;
        let checks = checks
            .iter()
            .map(|c| Check::parse(c).map_err(|e| format!("--check {c:?}: {e}")))
            .collect::<Result<Vec<_>, _>>()?;
        let baseline = match baseline {
            Some(p) => Some((p.to_path_buf(), compare::csv::read_results_csv(p)?)),
            None => None,
        };
        Ok(Verification { checks, baseline, tolerance, signals })
    }

    /// Whether there is anything to verify.
    pub fn is_empty(&self) -> bool {
        self.checks.is_empty() && self.baseline.is_none()
    }

    /// The result columns the verification reads: the checks' variables and the compared
    /// signals, as named in the checks and the baseline's header.
    pub fn columns(&self) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        for c in &self.checks {
            for v in c.variables() {
                if !out.contains(&v) {
                    out.push(v);
                }
            }
        }
        if let Some((_, b)) = &self.baseline {
            for n in self.signals.as_ref().unwrap_or(&b.names) {
                if !out.contains(n) {
                    out.push(n.clone());
                }
            }
        }
        out
    }

    /// Judges `results`; `column` maps a check's variable to the results' column name
    /// (e.g. a one-instance system's `model.x` to `x`). `Err`: a check reads a variable
    /// that was not recorded, or a time column cannot be compared.
    pub fn judge(&self, results: &Results, column: impl Fn(&str) -> String) -> Result<Judged, String> {
        let verdicts = check::evaluate(&self.checks, results, column)?;
        let comparison = match &self.baseline {
            Some((path, b)) => Some(
                compare::compare(results, b, &self.tolerance, self.signals.as_deref())
                    .map_err(|e| format!("--baseline {}: {e}", path.display()))?,
            ),
            None => None,
        };
        Ok(Judged { verdicts, comparison })
    }
}

impl Judged {
    /// Whether every check held and every compared signal passed.
    pub fn passed(&self) -> bool {
        self.verdicts.iter().all(|v| v.holds) && self.comparison.iter().all(Comparison::passed)
    }

    /// The lines to print: one per check, then the comparison's.
    pub fn lines(&self) -> Vec<String> {
        let mut out: Vec<String> = self.verdicts.iter().map(|v| v.line()).collect();
        if let Some(c) = &self.comparison {
            out.extend(c.lines().into_iter().map(|l| format!("baseline: {l}")));
        }
        out
    }

    /// A test case per check and per compared signal.
    pub fn cases(&self) -> Vec<TestCase> {
        let mut out: Vec<TestCase> = self
            .verdicts
            .iter()
            .map(|v| {
                let mut c = if v.holds {
                    TestCase::passed(CHECK_CLASS, &v.text)
                } else {
                    TestCase::failed(CHECK_CLASS, &v.text, &v.failure())
                };
                c.output = Some(v.line());
                c
            })
            .collect();
        if let Some(c) = &self.comparison {
            out.extend(comparison_cases(c));
        }
        out
    }
}

/// A test case per compared signal (a failing one carries its violation or problem, the
/// tolerances and the notes).
pub fn comparison_cases(c: &Comparison) -> Vec<TestCase> {
    let t = &c.tolerance;
    let num = crate::simulate::number_text;
    let tolerances = format!("rtol {}, atol {}, time-tol {} s", num(t.rtol), num(t.atol), num(t.time_tol));
    c.signals
        .iter()
        .map(|s| {
            let mut case = if s.passed {
                TestCase::passed(BASELINE_CLASS, &s.name)
            } else {
                let mut case = TestCase::failed(BASELINE_CLASS, &s.name, &s.detail());
                if let junit::Outcome::Failed { detail, .. } = &mut case.outcome {
                    detail.push_str(&format!("\ntolerances: {tolerances}"));
                }
                case
            };
            case.output = Some(format!("{} ({tolerances})", s.detail()));
            case
        })
        .collect()
}

/// The suite of a run: the run itself (an error when it failed), then its checks and
/// compared signals (errors, not judged, when the run failed).
pub fn run_suite(name: &str, seconds: f64, run_error: Option<&str>, judged: &Judged, v: &Verification) -> TestSuite {
    let mut cases = Vec::new();
    match run_error {
        None => {
            cases.push(TestCase::passed(RUN_CLASS, name));
            cases.extend(judged.cases());
        }
        Some(e) => {
            cases.push(TestCase::error(RUN_CLASS, name, e));
            let why = "not judged: the run failed";
            cases.extend(v.checks.iter().map(|c| TestCase::error(CHECK_CLASS, &c.text, why)));
            if let Some((_, b)) = &v.baseline {
                for n in v.signals.as_ref().unwrap_or(&b.names) {
                    cases.push(TestCase::error(BASELINE_CLASS, n, why));
                }
            }
        }
    }
    TestSuite { name: name.to_string(), time: seconds, cases }
}

/// Writes the JUnit XML and the Markdown summary of `suite` where asked.
pub fn write_reports(suite: &TestSuite, junit_file: Option<&Path>, summary_md: Option<&Path>) -> Result<(), String> {
    let suites = std::slice::from_ref(suite);
    if let Some(p) = junit_file {
        std::fs::write(p, junit::xml(&suite.name, suites)).map_err(|e| format!("--junit {}: {e}", p.display()))?;
    }
    if let Some(p) = summary_md {
        std::fs::write(p, junit::markdown(&suite.name, suites))
            .map_err(|e| format!("--summary-md {}: {e}", p.display()))?;
    }
    Ok(())
}
