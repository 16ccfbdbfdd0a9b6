//! Per-run metrics: expressions such as
//! `norm(rms_diff(plant.x, maneuver.x_ref), rms_diff(plant.y, maneuver.y_ref))`, evaluated
//! over the communication points after the start, `t_1 .. t_N` (as Table III's metric),
//! by accumulators fed one point at a time.
//!
//! Functions of a variable `v` (and `w`): `final(v)` (its value at `t_N`), `max_abs(v)`,
//! `max(v)`, `min(v)`, `mean(v)`, `rms(v)`, `rms_diff(v, w)` (root mean square of `v - w`),
//! `max_abs_diff(v, w)`; of metrics: `norm(m1, m2, ...)` (the 2-norm).

/// An accumulated quantity over `t_1 .. t_N`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Aggregate {
    /// Value at `t_N`.
    Final,
    /// `max |v|`.
    MaxAbs,
    /// `max v`.
    Max,
    /// `min v`.
    Min,
    /// `sum v / N`.
    Mean,
    /// `sqrt(sum v^2 / N)`.
    Rms,
    /// `sqrt(sum (v - w)^2 / N)`.
    RmsDiff,
    /// `max |v - w|`.
    MaxAbsDiff,
}

impl Aggregate {
    fn of(name: &str) -> Option<(Aggregate, usize)> {
        Some(match name {
            "final" => (Aggregate::Final, 1),
            "max_abs" => (Aggregate::MaxAbs, 1),
            "max" => (Aggregate::Max, 1),
            "min" => (Aggregate::Min, 1),
            "mean" => (Aggregate::Mean, 1),
            "rms" => (Aggregate::Rms, 1),
            "rms_diff" => (Aggregate::RmsDiff, 2),
            "max_abs_diff" => (Aggregate::MaxAbsDiff, 2),
            _ => return None,
        })
    }
}

/// A parsed metric expression.
#[derive(Clone, Debug, PartialEq)]
pub enum Metric {
    /// An aggregate of one or two variables (`instance.variable`).
    Of(Aggregate, Vec<String>),
    /// The 2-norm of metrics.
    Norm(Vec<Metric>),
}

struct Parser<'a> {
    text: &'a str,
    pos: usize,
}

impl Parser<'_> {
    fn skip(&mut self) {
        while self.text[self.pos..].starts_with(char::is_whitespace) {
            self.pos += 1;
        }
    }

    fn err(&self, what: &str) -> String {
        format!("malformed expression {:?}: {what} at column {}", self.text, self.pos + 1)
    }

    fn word(&mut self) -> Result<String, String> {
        self.skip();
        let rest = &self.text[self.pos..];
        let n = rest.find(|c: char| !(c.is_alphanumeric() || "_.[]".contains(c))).unwrap_or(rest.len());
        if n == 0 {
            return Err(self.err("expected a name"));
        }
        self.pos += n;
        Ok(rest[..n].to_string())
    }

    fn eat(&mut self, c: char) -> bool {
        self.skip();
        if self.text[self.pos..].starts_with(c) {
            self.pos += c.len_utf8();
            true
        } else {
            false
        }
    }

    fn call(&mut self) -> Result<Metric, String> {
        let start = self.pos;
        let name = self.word()?;
        if !self.eat('(') {
            self.pos = start;
            return Err(self.err(&format!(
                "expected a function (final, max_abs, max, min, mean, rms, rms_diff, max_abs_diff, norm) before {name:?}"
            )));
        }
        if name == "norm" {
            let mut args = vec![self.call()?];
            while self.eat(',') {
                args.push(self.call()?);
            }
            if !self.eat(')') {
                return Err(self.err("expected ',' or ')'"));
            }
            return Ok(Metric::Norm(args));
        }
        let (agg, arity) = Aggregate::of(&name).ok_or_else(|| {
            self.pos = start;
            self.err(&format!(
                "unknown function {name:?} (expected final, max_abs, max, min, mean, rms, rms_diff, max_abs_diff, norm)"
            ))
        })?;
        let mut vars = vec![self.word()?];
        while self.eat(',') {
            vars.push(self.word()?);
        }
        if !self.eat(')') {
            return Err(self.err("expected ',' or ')'"));
        }
        if vars.len() != arity {
            return Err(self.err(&format!("{name} takes {arity} variable(s), got {}", vars.len())));
        }
        Ok(Metric::Of(agg, vars))
    }
}

impl Metric {
    /// Parses an expression (one-line error naming the column).
    pub fn parse(text: &str) -> Result<Metric, String> {
        let mut p = Parser { text, pos: 0 };
        let m = p.call()?;
        p.skip();
        if p.pos != text.len() {
            return Err(p.err("unexpected text after the expression"));
        }
        Ok(m)
    }

    /// The variables the metric reads, in order of first use.
    pub fn variables(&self) -> Vec<String> {
        let mut out = Vec::new();
        self.collect(&mut out);
        out
    }

    fn collect(&self, out: &mut Vec<String>) {
        match self {
            Metric::Of(_, vars) => {
                for v in vars {
                    if !out.contains(v) {
                        out.push(v.clone());
                    }
                }
            }
            Metric::Norm(ms) => ms.iter().for_each(|m| m.collect(out)),
        }
    }
}

/// One accumulator: an aggregate over the slots `a` (and `b`) of a row.
#[derive(Clone, Debug)]
struct Leaf {
    agg: Aggregate,
    a: usize,
    b: usize,
    acc: f64,
}

/// The accumulators of a list of metrics over the rows of one run.
#[derive(Clone, Debug)]
pub struct Accumulators {
    leaves: Vec<Leaf>,
    trees: Vec<Tree>,
    n: u64,
}

#[derive(Clone, Debug)]
enum Tree {
    Leaf(usize),
    Norm(Vec<Tree>),
}

impl Accumulators {
    /// Accumulators of `metrics` whose variables are at the positions of `slots` in a row.
    pub fn new<'a>(metrics: impl IntoIterator<Item = &'a Metric>, slots: &[String]) -> Accumulators {
        let mut leaves = Vec::new();
        fn build(m: &Metric, slots: &[String], leaves: &mut Vec<Leaf>) -> Tree {
            match m {
                Metric::Of(agg, vars) => {
                    let pos = |v: &String| slots.iter().position(|s| s == v).expect("metric variable among the slots");
                    let a = pos(&vars[0]);
                    let b = vars.get(1).map_or(a, pos);
                    let acc = match agg {
                        Aggregate::Max => f64::NEG_INFINITY,
                        Aggregate::Min => f64::INFINITY,
                        _ => 0.0,
                    };
                    leaves.push(Leaf { agg: *agg, a, b, acc });
                    Tree::Leaf(leaves.len() - 1)
                }
                Metric::Norm(ms) => Tree::Norm(ms.iter().map(|m| build(m, slots, leaves)).collect()),
            }
        }
        let trees = metrics.into_iter().map(|m| build(m, slots, &mut leaves)).collect();
        Accumulators { leaves, trees, n: 0 }
    }

    /// Adds the row of one communication point `t_k`, `k >= 1`.
    #[inline]
    pub fn push(&mut self, row: &[f64]) {
        self.n += 1;
        for l in self.leaves.iter_mut() {
            let (a, b) = (row[l.a], row[l.b]);
            match l.agg {
                Aggregate::Final => l.acc = a,
                Aggregate::MaxAbs => l.acc = l.acc.max(a.abs()),
                Aggregate::Max => l.acc = l.acc.max(a),
                Aggregate::Min => l.acc = l.acc.min(a),
                Aggregate::Mean => l.acc += a,
                Aggregate::Rms => l.acc += a * a,
                Aggregate::RmsDiff => {
                    let e = a - b;
                    l.acc += e * e;
                }
                Aggregate::MaxAbsDiff => l.acc = l.acc.max((a - b).abs()),
            }
            // a NaN makes every aggregate NaN (f64::max would drop it)
            if a.is_nan() || b.is_nan() {
                l.acc = f64::NAN;
            }
        }
    }

    /// The metrics' values (NaN before any point).
    pub fn values(&self) -> Vec<f64> {
        let n = self.n as f64;
        let leaf = |l: &Leaf| -> f64 {
            if self.n == 0 {
                return f64::NAN;
            }
            match l.agg {
                Aggregate::Mean => l.acc / n,
                Aggregate::Rms | Aggregate::RmsDiff => (l.acc / n).sqrt(),
                _ => l.acc,
            }
        };
        fn eval(t: &Tree, leaves: &[f64]) -> f64 {
            match t {
                Tree::Leaf(i) => leaves[*i],
                Tree::Norm(ts) => ts.iter().map(|t| eval(t, leaves)).map(|x| x * x).sum::<f64>().sqrt(),
            }
        }
        let leaves: Vec<f64> = self.leaves.iter().map(leaf).collect();
        self.trees.iter().map(|t| eval(t, &leaves)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_example_and_names_what_is_malformed() {
        let m = Metric::parse("norm(rms_diff(plant.x, maneuver.x_ref), rms(plant.y))").unwrap();
        assert_eq!(m.variables(), ["plant.x", "maneuver.x_ref", "plant.y"]);
        let e = Metric::parse("rms_diff(plant.x maneuver.x_ref)").unwrap_err();
        assert!(e.contains("expected ',' or ')'") && e.contains("column 18"), "{e}");
        assert!(Metric::parse("rmse(plant.x)").unwrap_err().contains("unknown function \"rmse\""));
        assert!(Metric::parse("rms(plant.x, plant.y)").unwrap_err().contains("rms takes 1"));
        assert!(Metric::parse("final(plant.x))").unwrap_err().contains("unexpected text"));
        assert!(Metric::parse("plant.x").unwrap_err().contains("expected a function"));
    }

    #[test]
    fn aggregates_against_hand_sums() {
        let slots: Vec<String> = ["a", "b"].map(String::from).to_vec();
        let ms: Vec<Metric> = [
            "final(a)",
            "max_abs(a)",
            "mean(a)",
            "rms(a)",
            "rms_diff(a, b)",
            "norm(final(a), mean(b))",
            "min(a)",
            "max_abs_diff(a, b)",
        ]
        .iter()
        .map(|t| Metric::parse(t).unwrap())
        .collect();
        let mut acc = Accumulators::new(&ms, &slots);
        for row in [[1.0, 0.0], [-3.0, 1.0], [2.0, 2.0]] {
            acc.push(&row);
        }
        // by hand: final 2, max |a| 3, mean 0, rms sqrt(14/3), diffs 1, -4, 0 -> sqrt(17/3),
        // norm(2, 1) = sqrt(5), min -3, max |a - b| 4
        let want = [2.0, 3.0, 0.0, (14.0f64 / 3.0).sqrt(), (17.0f64 / 3.0).sqrt(), 5f64.sqrt(), -3.0, 4.0];
        assert_eq!(acc.values(), want);
    }
}
