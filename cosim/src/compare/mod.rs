//! Comparing results with a baseline, signal by signal, in tolerance tubes ([`tube`]):
//! `cosim compare`, `cosim run --baseline`, `nigel_cosim.compare`.
//!
//! Every signal of the baseline (or those named) is judged at the result's own points:
//! a point is a violation when its value lies outside the tube of the baseline at its
//! time; the signal passes when none is. The time grids may differ (the baseline is the
//! polyline through its points). A baseline signal missing from the result fails; a
//! result signal missing from the baseline is named and not compared; result points
//! beyond the baseline's span by more than the time tolerance, and a result that stops
//! short of the baseline's end, fail the signal.

pub mod csv;
pub mod plot;
pub mod tube;

pub use tube::Tolerance;

use crate::simulate::number_text as num;
use crate::Results;
use tube::Baseline;

/// The largest violation of a signal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Violation {
    /// The result's time, s.
    pub time: f64,
    /// The result's value there.
    pub value: f64,
    /// The tube there.
    pub lower: f64,
    /// The tube there.
    pub upper: f64,
    /// How far outside the tube (NaN when the value or the baseline is not a number).
    pub excess: f64,
}

/// One signal's verdict.
#[derive(Clone, Debug, PartialEq)]
pub struct SignalReport {
    /// The column name.
    pub name: String,
    /// Whether it passed.
    pub passed: bool,
    /// Result points judged.
    pub points: usize,
    /// Of them, outside the tube.
    pub violations: usize,
    /// The largest violation (a non-number counts as the largest).
    pub worst: Option<Violation>,
    /// Why it failed apart from violations (missing, not covered), if it did.
    pub problem: Option<String>,
}

impl SignalReport {
    /// The verdict in one line (without the name).
    pub fn detail(&self) -> String {
        let mut parts = Vec::new();
        if let Some(p) = &self.problem {
            parts.push(p.clone());
        }
        if let Some(w) = &self.worst {
            parts.push(format!(
                "{} of {} points outside the tube; largest violation {} at t = {} s (value {}, tube {} .. {})",
                self.violations,
                self.points,
                if w.excess.is_nan() { "(not a number)".to_string() } else { num(w.excess) },
                num(w.time),
                num(w.value),
                num(w.lower),
                num(w.upper)
            ));
        } else if self.problem.is_none() {
            parts.push(format!("{} points inside the tube", self.points));
        }
        parts.join("; ")
    }
}

/// A whole comparison.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// The tolerances used.
    pub tolerance: Tolerance,
    /// Per signal, in the baseline's column order.
    pub signals: Vec<SignalReport>,
    /// What was not compared, and how the grids differ.
    pub notes: Vec<String>,
}

impl Comparison {
    /// Whether every signal passed (and there was one).
    pub fn passed(&self) -> bool {
        !self.signals.is_empty() && self.signals.iter().all(|s| s.passed)
    }

    /// The report: the tolerances, a line per signal, the notes, the count.
    pub fn lines(&self) -> Vec<String> {
        let t = &self.tolerance;
        let mut out =
            vec![format!("tolerances: rtol {}, atol {}, time-tol {} s", num(t.rtol), num(t.atol), num(t.time_tol))];
        let width = self.signals.iter().map(|s| s.name.len()).max().unwrap_or(0);
        for s in &self.signals {
            out.push(format!("{:<width$}  {}  {}", s.name, if s.passed { "pass" } else { "FAIL" }, s.detail()));
        }
        out.extend(self.notes.iter().map(|n| format!("note: {n}")));
        let failed = self.signals.iter().filter(|s| !s.passed).count();
        out.push(if self.signals.is_empty() {
            "no signal compared: the result and the baseline have no signal in common".to_string()
        } else {
            let n = self.signals.len();
            format!("{n} signal{} compared: {} passed, {failed} failed", if n == 1 { "" } else { "s" }, n - failed)
        });
        out
    }
}

/// A result's or baseline's checked time column and its span.
fn times(r: &Results, what: &str) -> Result<Vec<f64>, String> {
    let t = r.column("time").unwrap_or_default();
    if t.is_empty() {
        return Err(format!("the {what} has no rows"));
    }
    if let Some(k) = t.iter().position(|x| !x.is_finite()) {
        return Err(format!("the {what}'s time {} at row {} is not finite", t[k], k + 1));
    }
    if let Some(k) = t.windows(2).position(|w| w[1] < w[0]) {
        return Err(format!("the {what}'s time goes back from {} to {} s at row {}", t[k], t[k + 1], k + 2));
    }
    Ok(t)
}

/// Compares `result` with `baseline` (both with `time` first), all of the baseline's
/// signals or those in `signals`. `Err`: a file that cannot be compared (no rows, time
/// not finite or going back, bad tolerances).
pub fn compare(
    result: &Results,
    baseline: &Results,
    tolerance: &Tolerance,
    signals: Option<&[String]>,
) -> Result<Comparison, String> {
    tolerance.check()?;
    let rt = times(result, "result")?;
    let bt = times(baseline, "baseline")?;
    let (r0, r1) = (rt[0], rt[rt.len() - 1]);
    let (b0, b1) = (bt[0], bt[bt.len() - 1]);
    let mut notes = Vec::new();
    let names: Vec<String> = match signals {
        Some(s) => s.to_vec(),
        None => {
            let left_out: Vec<&str> =
                result.names.iter().filter(|n| !baseline.names.contains(n)).map(|n| n.as_str()).collect();
            // a run records every output: the first few named, the rest counted
            const NAMED: usize = 8;
            if !left_out.is_empty() {
                let more = left_out.len().saturating_sub(NAMED);
                let tail = if more > 0 { format!(" and {more} more") } else { String::new() };
                notes.push(format!(
                    "not in the baseline, not compared: {}{tail}",
                    left_out[..left_out.len().min(NAMED)].join(", ")
                ));
            }
            baseline.names.clone()
        }
    };
    if rt != bt {
        notes.push(format!(
            "the time grids differ (result: {} points from {r0} to {r1} s, baseline: {} points from {b0} to {b1} s): \
             the baseline is interpolated linearly between its points",
            rt.len(),
            bt.len()
        ));
    }
    // coverage, with the tube's slack of 1e-9 of the baseline's span
    let slack = tolerance.time_tol + 1e-9 * (b1 - b0).abs();
    let short = (r1 < b1 - slack).then(|| {
        format!("the result ends at t = {r1} s, the baseline at {b1} s (more than the time tolerance earlier)")
    });
    let late = (r0 > b0 + slack).then(|| {
        format!("the result starts at t = {r0} s, the baseline at {b0} s (more than the time tolerance later)")
    });
    let mut out = Vec::new();
    for name in &names {
        let report = |problem: String| SignalReport {
            name: name.clone(),
            passed: false,
            points: 0,
            violations: 0,
            worst: None,
            problem: Some(problem),
        };
        let (Some(y), Some(b)) = (result.column(name), baseline.column(name)) else {
            let problem = match (result.names.contains(name), baseline.names.contains(name)) {
                (false, false) => "in neither the result nor the baseline",
                (false, true) => "missing in the result",
                _ => "not in the baseline",
            };
            out.push(report(problem.to_string()));
            continue;
        };
        let base = Baseline { time: &bt, value: &b };
        let mut s =
            SignalReport { name: name.clone(), passed: true, points: 0, violations: 0, worst: None, problem: None };
        let mut uncovered = Vec::new();
        for (t, v) in rt.iter().zip(&y) {
            let Some((lower, upper)) = base.tube(*t, tolerance) else {
                uncovered.push(*t);
                continue;
            };
            s.points += 1;
            let inside = if lower.is_nan() || upper.is_nan() { v.is_nan() } else { *v >= lower && *v <= upper };
            if inside {
                continue;
            }
            s.violations += 1;
            let excess = if v.is_nan() || lower.is_nan() { f64::NAN } else { (lower - v).max(v - upper) };
            // a non-number is the largest violation; the first of equal ones is kept
            let larger = match &s.worst {
                None => true,
                Some(w) => !w.excess.is_nan() && (excess.is_nan() || excess > w.excess),
            };
            if larger {
                s.worst = Some(Violation { time: *t, value: *v, lower, upper, excess });
            }
        }
        let mut problems: Vec<String> = short.iter().chain(late.iter()).cloned().collect();
        if let (Some(first), Some(last)) = (uncovered.first(), uncovered.last()) {
            problems.push(format!(
                "{} result points outside the baseline's span {b0} .. {b1} s (from t = {first} to {last} s)",
                uncovered.len()
            ));
        }
        if !problems.is_empty() {
            s.problem = Some(problems.join("; "));
        }
        s.passed = s.violations == 0 && s.problem.is_none();
        out.push(s);
    }
    Ok(Comparison { tolerance: *tolerance, signals: out, notes })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn results(names: &[&str], rows: &[&[f64]]) -> Results {
        Results { names: names.iter().map(|s| s.to_string()).collect(), values: rows.concat(), exact: Vec::new() }
    }

    fn tol(rtol: f64, atol: f64, time_tol: f64) -> Tolerance {
        Tolerance { rtol, atol, time_tol }
    }

    /// A step of `y` from 0 to 1 at `at` s on the grid 0, 0.25, ..., 4 s (binary fractions:
    /// the times are exact), as a simulation records an event between points: 0 up to the
    /// point before, 1 from the point at `at` on (the polyline ramps between them).
    fn step(at: f64) -> Results {
        let rows: Vec<Vec<f64>> =
            (0..=16).map(|k| k as f64 * 0.25).map(|t| vec![t, if t >= at { 1.0 } else { 0.0 }]).collect();
        Results { names: vec!["y".into()], values: rows.concat(), exact: Vec::new() }
    }

    #[test]
    fn a_step_shifted_by_less_than_the_time_tolerance_passes_and_by_more_fails() {
        // baseline: 0 up to 1.75 s, 1 from 2 s
        let base = step(2.0);
        // shifted by 0.25 s < time-tol 0.3 s: every result point has a baseline time
        // within 0.3 s at its value (the last 0 at 2 s: the baseline's 0 at 1.75 s)
        let c = compare(&step(2.25), &base, &tol(0.0, 1e-3, 0.3), None).unwrap();
        assert!(c.passed(), "{:?}", c.lines());
        // shifted by 0.5 s > 0.3 s: the result is still 0 at 2.25 s; the window
        // [1.95, 2.55] s starts on the baseline's ramp at (1.95 - 1.75) / 0.25 = 0.8, so
        // the tube is [0.8 - 1e-3, 1 + 1e-3] there: one violation of 0.799
        let c = compare(&step(2.5), &base, &tol(0.0, 1e-3, 0.3), None).unwrap();
        assert!(!c.passed());
        let s = &c.signals[0];
        assert_eq!((s.points, s.violations), (17, 1));
        let w = s.worst.unwrap();
        assert_eq!((w.time, w.value, w.upper), (2.25, 0.0, 1.0 + 1e-3));
        // 1e-12: the window's end 2.25 - 0.3 is rounded in binary
        assert!((w.lower - 0.799).abs() < 1e-12 && (w.excess - 0.799).abs() < 1e-12, "{w:?}");
        // time-tol 0.25 s, shift 0.5 s: the window [2, 2.5] s misses the ramp, the tube at
        // 2.25 s is exactly [1 - 1e-3, 1 + 1e-3]
        let c = compare(&step(2.5), &base, &tol(0.0, 1e-3, 0.25), None).unwrap();
        assert_eq!(
            c.lines()[1],
            "y  FAIL  1 of 17 points outside the tube; largest violation 0.999 at t = 2.25 s (value 0, tube 0.999 .. 1.001)"
        );
        // no time tolerance: a shift by one point fails where the baseline is 1 first (2 s)
        let c = compare(&step(2.25), &base, &tol(0.0, 1e-3, 0.0), None).unwrap();
        assert_eq!(c.signals[0].violations, 1);
    }

    #[test]
    fn values_within_rtol_and_atol_pass_and_outside_fail() {
        // baseline 2 everywhere: rtol 0.01 and atol 0.001 make the tube 2 +- 0.021
        let base = results(&["y"], &[&[0.0, 2.0], &[1.0, 2.0]]);
        let inside = results(&["y"], &[&[0.0, 2.0209], &[1.0, 1.9791]]);
        assert!(compare(&inside, &base, &tol(0.01, 0.001, 0.0), None).unwrap().passed());
        let outside = results(&["y"], &[&[0.0, 2.0], &[1.0, 2.0215]]);
        let c = compare(&outside, &base, &tol(0.01, 0.001, 0.0), None).unwrap();
        let w = c.signals[0].worst.unwrap();
        assert_eq!((c.signals[0].violations, w.time), (1, 1.0));
        assert!((w.excess - 0.0005).abs() < 1e-12, "{}", w.excess);
    }

    #[test]
    fn different_grids_interpolate_the_baseline_and_are_said() {
        // baseline y = t on 0, 1, 2; result on 0, 0.5, 1, 1.5, 2 with y = t + 0.01 at 1.5
        let base = results(&["y"], &[&[0.0, 0.0], &[1.0, 1.0], &[2.0, 2.0]]);
        let r = results(&["y"], &[&[0.0, 0.0], &[0.5, 0.5], &[1.0, 1.0], &[1.5, 1.51], &[2.0, 2.0]]);
        let c = compare(&r, &base, &tol(0.0, 0.02, 0.0), None).unwrap();
        assert!(c.passed());
        assert!(c.notes[0].starts_with("the time grids differ (result: 5 points from 0 to 2 s, baseline: 3 points"));
        // atol 0.005: 1.51 is 0.005 above the tube 1.5 +- 0.005
        let c = compare(&r, &base, &tol(0.0, 0.005, 0.0), None).unwrap();
        let w = c.signals[0].worst.unwrap();
        assert_eq!((w.time, c.signals[0].violations), (1.5, 1));
        assert!((w.excess - 0.005).abs() < 1e-12);
    }

    #[test]
    fn missing_signals_fail_or_are_named_and_a_short_result_fails() {
        let base = results(&["a", "b"], &[&[0.0, 1.0, 1.0], &[1.0, 1.0, 1.0]]);
        let r = results(&["a", "c"], &[&[0.0, 1.0, 5.0], &[1.0, 1.0, 5.0]]);
        let c = compare(&r, &base, &Tolerance::default(), None).unwrap();
        assert_eq!(c.signals.iter().map(|s| s.passed).collect::<Vec<_>>(), [true, false]);
        assert_eq!(c.signals[1].problem.as_deref(), Some("missing in the result"));
        assert_eq!(c.notes, ["not in the baseline, not compared: c"]);
        assert_eq!(c.lines().last().unwrap(), "2 signals compared: 1 passed, 1 failed");
        // named signals: one only in the result
        let c = compare(&r, &base, &Tolerance::default(), Some(&["c".to_string()])).unwrap();
        assert_eq!(c.signals[0].problem.as_deref(), Some("not in the baseline"));
        // a result that stops at 0.5 s of a 1 s baseline fails every signal
        let short = results(&["a", "b"], &[&[0.0, 1.0, 1.0], &[0.5, 1.0, 1.0]]);
        let c = compare(&short, &base, &Tolerance::default(), None).unwrap();
        assert!(!c.passed());
        assert_eq!(
            c.signals[0].detail(),
            "the result ends at t = 0.5 s, the baseline at 1 s (more than the time tolerance earlier)"
        );
        // nothing in common: not a pass
        let other = results(&["z"], &[&[0.0, 1.0]]);
        let c = compare(&other, &results(&[], &[&[0.0]]), &Tolerance::default(), None).unwrap();
        assert!(!c.passed());
    }

    #[test]
    fn a_result_past_the_baseline_and_a_nan_fail() {
        let base = results(&["y"], &[&[0.0, 1.0], &[1.0, 1.0]]);
        let r = results(&["y"], &[&[0.0, 1.0], &[1.0, f64::NAN], &[2.0, 1.0]]);
        let c = compare(&r, &base, &Tolerance::default(), None).unwrap();
        let s = &c.signals[0];
        assert_eq!((s.points, s.violations), (2, 1));
        assert!(s.worst.unwrap().excess.is_nan() && s.worst.unwrap().time == 1.0);
        assert_eq!(
            s.problem.as_deref(),
            Some("1 result points outside the baseline's span 0 .. 1 s (from t = 2 to 2 s)")
        );
        assert!(compare(&r, &base, &tol(-1.0, 0.0, 0.0), None).unwrap_err().contains("--rtol -1"));
    }
}
