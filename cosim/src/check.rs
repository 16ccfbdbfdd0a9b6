//! Checks of a run: a metric ([`crate::metric`]) compared with a number or another metric,
//! `max(abs(plant.y)) < 0.6`, `final(plant.x) > 1`, `rms_diff(plant.y, maneuver.y_ref) <= 0.05`,
//! evaluated over every recorded row of a run (`cosim run --check`, a campaign's `[checks]`).
//! A check whose value is not a number (NaN) fails.

use crate::metric::{Accumulators, Metric, Parser};
use crate::simulate::number_text as num;

/// A comparison operator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cmp {
    /// `<`
    Less,
    /// `<=`
    LessEqual,
    /// `>`
    Greater,
    /// `>=`
    GreaterEqual,
    /// `==`
    Equal,
    /// `!=`
    NotEqual,
}

impl Cmp {
    /// The operator as written.
    pub fn as_str(self) -> &'static str {
        match self {
            Cmp::Less => "<",
            Cmp::LessEqual => "<=",
            Cmp::Greater => ">",
            Cmp::GreaterEqual => ">=",
            Cmp::Equal => "==",
            Cmp::NotEqual => "!=",
        }
    }

    /// Whether `a op b` holds (false when either is NaN).
    pub fn holds(self, a: f64, b: f64) -> bool {
        match self {
            Cmp::Less => a < b,
            Cmp::LessEqual => a <= b,
            Cmp::Greater => a > b,
            Cmp::GreaterEqual => a >= b,
            // NaN != NaN is true in IEEE arithmetic; a check on a NaN fails all the same
            Cmp::Equal => a == b,
            Cmp::NotEqual => a != b && !a.is_nan() && !b.is_nan(),
        }
    }
}

/// A parsed check: `left op right`.
#[derive(Clone, Debug, PartialEq)]
pub struct Check {
    /// The expression as given (trimmed).
    pub text: String,
    /// The metric on the left.
    pub left: Metric,
    /// The comparison.
    pub cmp: Cmp,
    /// The metric (often a number) on the right.
    pub right: Metric,
}

/// A check's outcome.
#[derive(Clone, Debug, PartialEq)]
pub struct Verdict {
    /// The check as written.
    pub text: String,
    /// The left side's value.
    pub left: f64,
    /// The comparison.
    pub cmp: Cmp,
    /// The right side's value.
    pub right: f64,
    /// Whether it holds.
    pub holds: bool,
}

impl Verdict {
    /// One line: `check max(abs(plant.y)) < 0.6: 0.41 < 0.6 holds` (`fails`; NaN named).
    pub fn line(&self) -> String {
        let op = self.cmp.as_str();
        let nan = if self.left.is_nan() || self.right.is_nan() { " (not a number)" } else { "" };
        format!(
            "check {}: {} {op} {} {}{nan}",
            self.text,
            num(self.left),
            num(self.right),
            if self.holds { "holds" } else { "FAILS" }
        )
    }

    /// The failure message of a check that does not hold: `max(abs(plant.y)) < 0.6 fails: 0.71 < 0.6 is false`.
    pub fn failure(&self) -> String {
        format!("{} fails: {} {} {} is false", self.text, num(self.left), self.cmp.as_str(), num(self.right))
    }
}

impl Check {
    /// Parses `METRIC OP METRIC` (`OP`: `<`, `<=`, `>`, `>=`, `==`, `!=`); one-line error
    /// naming the column.
    pub fn parse(text: &str) -> Result<Check, String> {
        let mut p = Parser::new(text);
        let left = p.metric()?;
        p.skip();
        let rest = p.rest();
        let (cmp, n) = [
            ("<=", Cmp::LessEqual),
            (">=", Cmp::GreaterEqual),
            ("==", Cmp::Equal),
            ("!=", Cmp::NotEqual),
            ("<", Cmp::Less),
            (">", Cmp::Greater),
        ]
        .iter()
        .find(|(s, _)| rest.starts_with(s))
        .map(|(s, c)| (*c, s.len()))
        .ok_or_else(|| p.err("expected a comparison (<, <=, >, >=, ==, !=) after the metric"))?;
        p.advance(n);
        if p.at_end() {
            return Err(p.err("expected a number or a metric after the comparison"));
        }
        let right = p.metric()?;
        if !p.at_end() {
            return Err(p.err("unexpected text after the check"));
        }
        Ok(Check { text: text.trim().to_string(), left, cmp, right })
    }

    /// The variables the check reads, in order of first use.
    pub fn variables(&self) -> Vec<String> {
        let mut out = Vec::new();
        self.left.collect(&mut out);
        self.right.collect(&mut out);
        out
    }
}

/// The accumulators of a list of checks over the rows of one run.
#[derive(Clone, Debug)]
pub struct CheckAccumulators {
    checks: Vec<Check>,
    acc: Accumulators,
}

impl CheckAccumulators {
    /// For rows whose values are named `slots` (an `Err` names a variable not among them).
    pub fn new(checks: &[Check], slots: &[String]) -> Result<CheckAccumulators, String> {
        let metrics: Vec<&Metric> = checks.iter().flat_map(|c| [&c.left, &c.right]).collect();
        let acc = Accumulators::try_new(metrics, slots)?;
        Ok(CheckAccumulators { checks: checks.to_vec(), acc })
    }

    /// Adds one row.
    #[inline]
    pub fn push(&mut self, row: &[f64]) {
        self.acc.push(row);
    }

    /// The verdicts, in the checks' order.
    pub fn verdicts(&self) -> Vec<Verdict> {
        let v = self.acc.values();
        self.checks
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let (left, right) = (v[2 * i], v[2 * i + 1]);
                Verdict { text: c.text.clone(), left, cmp: c.cmp, right, holds: c.cmp.holds(left, right) }
            })
            .collect()
    }
}

/// The verdicts of `checks` over every row of `results` (variables named as its columns;
/// `rename` maps a check's variable to its column name, e.g. a one-instance system's
/// `model.x` to `x`).
pub fn evaluate(
    checks: &[Check],
    results: &crate::Results,
    rename: impl Fn(&str) -> String,
) -> Result<Vec<Verdict>, String> {
    let renamed: Vec<Check> = checks.iter().map(|c| c.renamed(&rename)).collect();
    let mut acc = CheckAccumulators::new(&renamed, &results.names)?;
    for k in 0..results.rows() {
        acc.push(&results.row(k)[1..]);
    }
    Ok(acc.verdicts())
}

impl Check {
    /// The check with its variables renamed (the text stays as written).
    fn renamed(&self, rename: &impl Fn(&str) -> String) -> Check {
        Check {
            text: self.text.clone(),
            left: self.left.renamed(rename),
            cmp: self.cmp,
            right: self.right.renamed(rename),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_issue_examples_and_names_what_is_malformed() {
        let c = Check::parse("max(abs(plant.y)) < 0.6").unwrap();
        assert_eq!((c.cmp, c.right.clone()), (Cmp::Less, Metric::Const(0.6)));
        assert_eq!(c.variables(), ["plant.y"]);
        assert_eq!(Check::parse("final(plant.x) > 1").unwrap().cmp, Cmp::Greater);
        let c = Check::parse(" rms_diff(plant.y, maneuver.y_ref) <= 0.05 ").unwrap();
        assert_eq!((c.cmp, c.text.as_str()), (Cmp::LessEqual, "rms_diff(plant.y, maneuver.y_ref) <= 0.05"));
        assert_eq!(c.variables(), ["plant.y", "maneuver.y_ref"]);
        // metrics on both sides
        let c = Check::parse("max(a) >= 2 * mean(b)").unwrap();
        assert_eq!((c.cmp, c.variables()), (Cmp::GreaterEqual, vec!["a".to_string(), "b".to_string()]));
        let e = Check::parse("max(abs(plant.y))").unwrap_err();
        assert!(e.contains("expected a comparison") && e.contains("column 18"), "{e}");
        let e = Check::parse("max(plant.y) <").unwrap_err();
        assert!(e.contains("expected a number or a metric after the comparison"), "{e}");
        let e = Check::parse("max(plant.y) < 1 < 2").unwrap_err();
        assert!(e.contains("unexpected text after the check") && e.contains("column 18"), "{e}");
        let e = Check::parse("plant.y < 1").unwrap_err();
        assert!(e.contains("needs an aggregate"), "{e}");
    }

    #[test]
    fn verdicts_over_rows_against_hand_values() {
        let checks: Vec<Check> =
            ["max(abs(a)) < 3", "max(abs(a)) <= 3", "final(b) == 2", "mean(a) != 0", "min(b) > -1"]
                .iter()
                .map(|t| Check::parse(t).unwrap())
                .collect();
        let mut acc = CheckAccumulators::new(&checks, &["a".to_string(), "b".to_string()]).unwrap();
        for row in [[1.0, 0.0], [-3.0, 1.0], [2.0, 2.0]] {
            acc.push(&row);
        }
        // by hand: max |a| = 3 (3 < 3 false, 3 <= 3 true), final b = 2, mean a = 0, min b = 0
        let got: Vec<(f64, bool)> = acc.verdicts().iter().map(|v| (v.left, v.holds)).collect();
        assert_eq!(got, [(3.0, false), (3.0, true), (2.0, true), (0.0, false), (0.0, true)]);
        let v = &acc.verdicts()[0];
        assert_eq!(v.line(), "check max(abs(a)) < 3: 3 < 3 FAILS");
        assert_eq!(v.failure(), "max(abs(a)) < 3 fails: 3 < 3 is false");
        assert_eq!(acc.verdicts()[1].line(), "check max(abs(a)) <= 3: 3 <= 3 holds");
    }

    #[test]
    fn a_nan_fails_every_comparison() {
        let checks: Vec<Check> =
            ["max(a) < 1", "max(a) != 1", "max(a) == 1"].iter().map(|t| Check::parse(t).unwrap()).collect();
        let mut acc = CheckAccumulators::new(&checks, &["a".to_string()]).unwrap();
        acc.push(&[0.0]);
        acc.push(&[f64::NAN]);
        let v = acc.verdicts();
        assert!(v.iter().all(|v| !v.holds && v.left.is_nan()));
        assert_eq!(v[0].line(), "check max(a) < 1: NaN < 1 FAILS (not a number)");
    }
}
