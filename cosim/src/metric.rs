//! Metrics of a run: expressions such as
//! `norm(rms_diff(plant.x, maneuver.x_ref), rms_diff(plant.y, maneuver.y_ref))` or
//! `max(abs(plant.y))`, evaluated over rows of results by accumulators fed one row at a
//! time (a campaign's metrics, `cosim run --check`'s and a campaign's checks).
//!
//! Aggregates of a signal `v` (and `w`): `final(v)` (its value at the last row), `max(v)`,
//! `min(v)`, `max_abs(v)`, `mean(v)`, `rms(v)`, `rms_diff(v, w)` (root mean square of
//! `v - w`), `max_abs_diff(v, w)`. A signal is a variable (`instance.variable`), a
//! number, `abs(s)`, or signals joined by `+ - * /` and parentheses, evaluated row by row
//! (`max(abs(plant.y))` is `max_abs(plant.y)`). Of metrics: `norm(m1, m2, ...)` (the
//! 2-norm), `abs(m)`, numbers and `+ - * /` (`final(plant.x) - 1`).

/// An accumulated quantity over the rows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Aggregate {
    /// Value at the last row.
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

/// The aggregates' names, as the parser lists them in its messages.
const FUNCTIONS: &str = "final, max, min, max_abs, mean, rms, rms_diff, max_abs_diff, norm, abs";

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

/// An arithmetic operator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    /// `+`
    Add,
    /// `-`
    Sub,
    /// `*`
    Mul,
    /// `/`
    Div,
}

impl Op {
    fn apply(self, a: f64, b: f64) -> f64 {
        match self {
            Op::Add => a + b,
            Op::Sub => a - b,
            Op::Mul => a * b,
            Op::Div => a / b,
        }
    }
}

/// A value per row: what an aggregate takes.
#[derive(Clone, Debug, PartialEq)]
pub enum Signal {
    /// A variable (`instance.variable`).
    Var(String),
    /// A number.
    Const(f64),
    /// `|s|`.
    Abs(Box<Signal>),
    /// `-s`.
    Neg(Box<Signal>),
    /// `a op b`.
    Bin(Op, Box<Signal>, Box<Signal>),
}

/// A parsed metric expression: one number per run.
#[derive(Clone, Debug, PartialEq)]
pub enum Metric {
    /// An aggregate of one or two signals.
    Of(Aggregate, Vec<Signal>),
    /// The 2-norm of metrics.
    Norm(Vec<Metric>),
    /// A number.
    Const(f64),
    /// `|m|`.
    Abs(Box<Metric>),
    /// `-m`.
    Neg(Box<Metric>),
    /// `a op b`.
    Bin(Op, Box<Metric>, Box<Metric>),
}

/// An expression of either kind while parsing: a metric (aggregated) or a signal (per row).
enum Node {
    Metric(Metric),
    Signal(Signal),
}

pub(crate) struct Parser<'a> {
    text: &'a str,
    pos: usize,
}

impl<'a> Parser<'a> {
    pub(crate) fn new(text: &'a str) -> Parser<'a> {
        Parser { text, pos: 0 }
    }

    pub(crate) fn skip(&mut self) {
        while self.text[self.pos..].starts_with(char::is_whitespace) {
            self.pos += 1;
        }
    }

    pub(crate) fn at_end(&mut self) -> bool {
        self.skip();
        self.pos == self.text.len()
    }

    pub(crate) fn rest(&self) -> &'a str {
        &self.text[self.pos..]
    }

    pub(crate) fn advance(&mut self, n: usize) {
        self.pos += n;
    }

    pub(crate) fn err(&self, what: &str) -> String {
        format!("malformed expression {:?}: {what} at column {}", self.text, self.pos + 1)
    }

    fn word(&mut self) -> Option<String> {
        self.skip();
        let rest = &self.text[self.pos..];
        if !rest.starts_with(|c: char| c.is_alphabetic() || c == '_') {
            return None;
        }
        let n = rest.find(|c: char| !(c.is_alphanumeric() || "_.[]".contains(c))).unwrap_or(rest.len());
        self.pos += n;
        Some(rest[..n].to_string())
    }

    fn number(&mut self) -> Option<f64> {
        self.skip();
        let rest = &self.text[self.pos..];
        let bytes = rest.as_bytes();
        let mut n = 0;
        while n < bytes.len() && (bytes[n].is_ascii_digit() || bytes[n] == b'.') {
            n += 1;
        }
        if n == 0 {
            return None;
        }
        // an exponent: e, an optional sign, digits
        if n < bytes.len() && (bytes[n] == b'e' || bytes[n] == b'E') {
            let mut m = n + 1;
            if m < bytes.len() && (bytes[m] == b'+' || bytes[m] == b'-') {
                m += 1;
            }
            let digits = m;
            while m < bytes.len() && bytes[m].is_ascii_digit() {
                m += 1;
            }
            if m > digits {
                n = m;
            }
        }
        let x = rest[..n].parse().ok()?;
        self.pos += n;
        Some(x)
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

    /// `term (('+' | '-') term)*`
    fn sum(&mut self) -> Result<Node, String> {
        self.left_associative([('+', Op::Add), ('-', Op::Sub)], Self::product)
    }

    /// `factor (('*' | '/') factor)*`
    fn product(&mut self) -> Result<Node, String> {
        self.left_associative([('*', Op::Mul), ('/', Op::Div)], Self::factor)
    }

    /// `operand (op operand)*` with the operators `ops`, joined from the left.
    fn left_associative(
        &mut self,
        ops: [(char, Op); 2],
        operand: fn(&mut Self) -> Result<Node, String>,
    ) -> Result<Node, String> {
        let mut a = operand(self)?;
        loop {
            let Some(op) = ops.iter().find(|(c, _)| self.eat(*c)).map(|(_, op)| *op) else { return Ok(a) };
            let b = operand(self)?;
            a = self.join(op, a, b)?;
        }
    }

    fn join(&self, op: Op, a: Node, b: Node) -> Result<Node, String> {
        Ok(match (a, b) {
            (Node::Metric(a), Node::Metric(b)) => Node::Metric(Metric::Bin(op, Box::new(a), Box::new(b))),
            // a number is either: it joins a signal as a signal
            (Node::Signal(a), Node::Metric(Metric::Const(c))) => {
                Node::Signal(Signal::Bin(op, Box::new(a), Box::new(Signal::Const(c))))
            }
            (Node::Metric(Metric::Const(c)), Node::Signal(b)) => {
                Node::Signal(Signal::Bin(op, Box::new(Signal::Const(c)), Box::new(b)))
            }
            (Node::Signal(a), Node::Signal(b)) => Node::Signal(Signal::Bin(op, Box::new(a), Box::new(b))),
            _ => {
                return Err(self.err(
                    "a variable and an aggregate cannot be combined (a variable is read inside an aggregate such as max(...))",
                ))
            }
        })
    }

    fn factor(&mut self) -> Result<Node, String> {
        if self.eat('-') {
            return Ok(match self.factor()? {
                Node::Metric(Metric::Const(c)) => Node::Metric(Metric::Const(-c)),
                Node::Metric(m) => Node::Metric(Metric::Neg(Box::new(m))),
                Node::Signal(s) => Node::Signal(Signal::Neg(Box::new(s))),
            });
        }
        if self.eat('(') {
            let inner = self.sum()?;
            if !self.eat(')') {
                return Err(self.err("expected ')'"));
            }
            return Ok(inner);
        }
        if let Some(x) = self.number() {
            return Ok(Node::Metric(Metric::Const(x)));
        }
        let start = self.pos;
        let Some(name) = self.word() else {
            return Err(self.err("expected a function, a variable or a number"));
        };
        if !self.eat('(') {
            return Ok(Node::Signal(Signal::Var(name)));
        }
        let mut args = vec![self.sum()?];
        while self.eat(',') {
            args.push(self.sum()?);
        }
        if !self.eat(')') {
            return Err(self.err("expected ',' or ')'"));
        }
        match name.as_str() {
            "abs" => {
                if args.len() != 1 {
                    return Err(self.err(&format!("abs takes 1 argument, got {}", args.len())));
                }
                Ok(match args.pop().expect("one argument") {
                    Node::Metric(Metric::Const(c)) => Node::Metric(Metric::Const(c.abs())),
                    Node::Metric(m) => Node::Metric(Metric::Abs(Box::new(m))),
                    Node::Signal(s) => Node::Signal(Signal::Abs(Box::new(s))),
                })
            }
            "norm" => {
                let ms = args
                    .into_iter()
                    .map(|a| match a {
                        Node::Metric(m) => Ok(m),
                        Node::Signal(_) => Err(self.err("norm takes metrics (such as rms(plant.y)), not variables")),
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                Ok(Node::Metric(Metric::Norm(ms)))
            }
            _ => {
                let (agg, arity) = Aggregate::of(&name).ok_or_else(|| {
                    let at = Parser { text: self.text, pos: start };
                    at.err(&format!("unknown function {name:?} (expected {FUNCTIONS})"))
                })?;
                if args.len() != arity {
                    return Err(self.err(&format!("{name} takes {arity} variable(s), got {}", args.len())));
                }
                let signals = args
                    .into_iter()
                    .map(|a| match a {
                        Node::Signal(s) => Ok(s),
                        Node::Metric(Metric::Const(c)) => Ok(Signal::Const(c)),
                        Node::Metric(_) => Err(self.err(&format!("{name} takes signals, not an aggregate"))),
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                Ok(Node::Metric(Metric::Of(agg, signals)))
            }
        }
    }

    /// A metric expression up to the next comparison operator or the end.
    pub(crate) fn metric(&mut self) -> Result<Metric, String> {
        let start = self.pos;
        match self.sum()? {
            Node::Metric(m) => Ok(m),
            Node::Signal(_) => {
                let at = Parser { text: self.text, pos: start };
                Err(at.err(&format!(
                    "a variable needs an aggregate around it, such as max(...) or final(...) (functions: {FUNCTIONS})"
                )))
            }
        }
    }
}

impl Signal {
    fn collect(&self, out: &mut Vec<String>) {
        match self {
            Signal::Var(v) => {
                if !out.contains(v) {
                    out.push(v.clone());
                }
            }
            Signal::Const(_) => {}
            Signal::Abs(s) | Signal::Neg(s) => s.collect(out),
            Signal::Bin(_, a, b) => {
                a.collect(out);
                b.collect(out);
            }
        }
    }

    fn renamed(&self, rename: &impl Fn(&str) -> String) -> Signal {
        match self {
            Signal::Var(v) => Signal::Var(rename(v)),
            Signal::Const(c) => Signal::Const(*c),
            Signal::Abs(s) => Signal::Abs(Box::new(s.renamed(rename))),
            Signal::Neg(s) => Signal::Neg(Box::new(s.renamed(rename))),
            Signal::Bin(op, a, b) => Signal::Bin(*op, Box::new(a.renamed(rename)), Box::new(b.renamed(rename))),
        }
    }

    /// The signal with its variables replaced by their positions in a row.
    fn slotted(&self, slots: &[String]) -> Result<Slotted, String> {
        Ok(match self {
            Signal::Var(v) => Slotted::Slot(
                slots.iter().position(|s| s == v).ok_or_else(|| format!("{v} is not among the recorded variables"))?,
            ),
            Signal::Const(c) => Slotted::Const(*c),
            Signal::Abs(s) => Slotted::Abs(Box::new(s.slotted(slots)?)),
            Signal::Neg(s) => Slotted::Neg(Box::new(s.slotted(slots)?)),
            Signal::Bin(op, a, b) => Slotted::Bin(*op, Box::new(a.slotted(slots)?), Box::new(b.slotted(slots)?)),
        })
    }
}

/// A signal reading slots of a row.
#[derive(Clone, Debug)]
enum Slotted {
    Slot(usize),
    Const(f64),
    Abs(Box<Slotted>),
    Neg(Box<Slotted>),
    Bin(Op, Box<Slotted>, Box<Slotted>),
}

impl Slotted {
    #[inline]
    fn eval(&self, row: &[f64]) -> f64 {
        match self {
            Slotted::Slot(i) => row[*i],
            Slotted::Const(c) => *c,
            Slotted::Abs(s) => s.eval(row).abs(),
            Slotted::Neg(s) => -s.eval(row),
            Slotted::Bin(op, a, b) => op.apply(a.eval(row), b.eval(row)),
        }
    }
}

impl Metric {
    /// Parses an expression (one-line error naming the column).
    pub fn parse(text: &str) -> Result<Metric, String> {
        let mut p = Parser::new(text);
        let m = p.metric()?;
        if !p.at_end() {
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

    /// The metric with every variable renamed by `rename`.
    pub fn renamed(&self, rename: &impl Fn(&str) -> String) -> Metric {
        match self {
            Metric::Of(agg, signals) => Metric::Of(*agg, signals.iter().map(|s| s.renamed(rename)).collect()),
            Metric::Norm(ms) => Metric::Norm(ms.iter().map(|m| m.renamed(rename)).collect()),
            Metric::Const(c) => Metric::Const(*c),
            Metric::Abs(m) => Metric::Abs(Box::new(m.renamed(rename))),
            Metric::Neg(m) => Metric::Neg(Box::new(m.renamed(rename))),
            Metric::Bin(op, a, b) => Metric::Bin(*op, Box::new(a.renamed(rename)), Box::new(b.renamed(rename))),
        }
    }

    pub(crate) fn collect(&self, out: &mut Vec<String>) {
        match self {
            Metric::Of(_, signals) => signals.iter().for_each(|s| s.collect(out)),
            Metric::Norm(ms) => ms.iter().for_each(|m| m.collect(out)),
            Metric::Const(_) => {}
            Metric::Abs(m) | Metric::Neg(m) => m.collect(out),
            Metric::Bin(_, a, b) => {
                a.collect(out);
                b.collect(out);
            }
        }
    }
}

/// One accumulator: an aggregate over the signals `a` (and `b`) of a row.
#[derive(Clone, Debug)]
struct Leaf {
    agg: Aggregate,
    a: Slotted,
    b: Option<Slotted>,
    acc: f64,
}

/// The accumulators of a list of metrics over the rows of one run.
#[derive(Clone, Debug)]
pub struct Accumulators {
    /// The aggregates of every metric, in the order of the metrics and, within one, of a
    /// depth-first walk (the order [`Accumulators::values`] reads them back in).
    leaves: Vec<Leaf>,
    metrics: Vec<Metric>,
    n: u64,
}

impl Accumulators {
    /// Accumulators of `metrics` whose variables are at the positions of `slots` in a row
    /// (every variable must be among them: see [`Accumulators::try_new`]).
    pub fn new<'a>(metrics: impl IntoIterator<Item = &'a Metric>, slots: &[String]) -> Accumulators {
        Accumulators::try_new(metrics, slots).expect("metric variables among the slots")
    }

    /// [`Accumulators::new`], or the variable that is not among `slots`.
    pub fn try_new<'a>(
        metrics: impl IntoIterator<Item = &'a Metric>,
        slots: &[String],
    ) -> Result<Accumulators, String> {
        let mut leaves = Vec::new();
        fn build(m: &Metric, slots: &[String], leaves: &mut Vec<Leaf>) -> Result<(), String> {
            match m {
                Metric::Of(agg, signals) => {
                    let a = signals[0].slotted(slots)?;
                    let b = signals.get(1).map(|s| s.slotted(slots)).transpose()?;
                    let acc = match agg {
                        Aggregate::Max => f64::NEG_INFINITY,
                        Aggregate::Min => f64::INFINITY,
                        _ => 0.0,
                    };
                    leaves.push(Leaf { agg: *agg, a, b, acc });
                }
                Metric::Norm(ms) => ms.iter().try_for_each(|m| build(m, slots, leaves))?,
                Metric::Const(_) => {}
                Metric::Abs(m) | Metric::Neg(m) => build(m, slots, leaves)?,
                Metric::Bin(_, a, b) => {
                    build(a, slots, leaves)?;
                    build(b, slots, leaves)?;
                }
            }
            Ok(())
        }
        let metrics: Vec<Metric> = metrics.into_iter().cloned().collect();
        metrics.iter().try_for_each(|m| build(m, slots, &mut leaves))?;
        Ok(Accumulators { leaves, metrics, n: 0 })
    }

    /// Adds one row.
    #[inline]
    pub fn push(&mut self, row: &[f64]) {
        self.n += 1;
        for l in self.leaves.iter_mut() {
            let a = l.a.eval(row);
            let b = l.b.as_ref().map_or(a, |b| b.eval(row));
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

    /// The metrics' values (NaN before any row).
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
        // the metric with its aggregates' values read in the depth-first order they were made in
        fn eval(m: &Metric, leaves: &mut impl Iterator<Item = f64>) -> f64 {
            match m {
                Metric::Of(..) => leaves.next().expect("one aggregate per leaf"),
                Metric::Norm(ms) => ms.iter().map(|m| eval(m, leaves)).map(|x| x * x).sum::<f64>().sqrt(),
                Metric::Const(c) => *c,
                Metric::Abs(m) => eval(m, leaves).abs(),
                Metric::Neg(m) => -eval(m, leaves),
                Metric::Bin(op, a, b) => op.apply(eval(a, leaves), eval(b, leaves)),
            }
        }
        let mut leaves = self.leaves.iter().map(leaf);
        self.metrics.iter().map(|m| eval(m, &mut leaves)).collect()
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
        let e = Metric::parse("plant.x").unwrap_err();
        assert!(e.contains("needs an aggregate around it") && e.contains("column 1"), "{e}");
        let e = Metric::parse("max(final(plant.x))").unwrap_err();
        assert!(e.contains("max takes signals, not an aggregate"), "{e}");
        let e = Metric::parse("final(plant.x) + plant.y").unwrap_err();
        assert!(e.contains("cannot be combined"), "{e}");
        assert!(Metric::parse("norm(plant.x)").unwrap_err().contains("norm takes metrics"));
    }

    #[test]
    fn signals_inside_aggregates_are_evaluated_row_by_row() {
        // max(abs(v)) is max_abs(v); abs, -, *, / and numbers inside and outside
        let m = Metric::parse("max(abs(plant.y))").unwrap();
        assert_eq!(m, Metric::Of(Aggregate::Max, vec![Signal::Abs(Box::new(Signal::Var("plant.y".into())))]));
        let metrics = [
            "max(abs(a))",
            "max(a - 2 * b)",
            "mean((a + b) / 2)",
            "final(a) - 1",
            "-min(-a)",
            "abs(final(a) - 3)",
            "2.5e-1 * final(b)",
        ];
        let values = values_over_three_rows(&metrics);
        // by hand: |a| = 1, 3, 2 -> 3; a - 2b = 1, -5, -2 -> 1; (a + b)/2 = 0.5, -1, 2 -> mean 0.5;
        // final a = 2 -> 1; -min(-a) = max a = 2; |2 - 3| = 1; 0.25 * 2 = 0.5
        assert_eq!(values, [3.0, 1.0, 0.5, 1.0, 2.0, 1.0, 0.5]);
        let slots: Vec<String> = ["a", "b"].map(String::from).to_vec();
        let e = Accumulators::try_new(&[Metric::parse("max(c)").unwrap()], &slots).unwrap_err();
        assert_eq!(e, "c is not among the recorded variables");
    }

    #[test]
    fn aggregates_against_hand_sums() {
        let values = values_over_three_rows(&[
            "final(a)",
            "max_abs(a)",
            "mean(a)",
            "rms(a)",
            "rms_diff(a, b)",
            "norm(final(a), mean(b))",
            "min(a)",
            "max_abs_diff(a, b)",
        ]);
        // by hand: final 2, max |a| 3, mean 0, rms sqrt(14/3), diffs 1, -4, 0 -> sqrt(17/3),
        // norm(2, 1) = sqrt(5), min -3, max |a - b| 4
        let want = [2.0, 3.0, 0.0, (14.0f64 / 3.0).sqrt(), (17.0f64 / 3.0).sqrt(), 5f64.sqrt(), -3.0, 4.0];
        assert_eq!(values, want);
    }

    /// The values of `metrics` over the rows (a, b) = (1, 0), (-3, 1), (2, 2).
    fn values_over_three_rows(metrics: &[&str]) -> Vec<f64> {
        let slots: Vec<String> = ["a", "b"].map(String::from).to_vec();
        let ms: Vec<Metric> = metrics.iter().map(|t| Metric::parse(t).unwrap()).collect();
        let mut acc = Accumulators::new(&ms, &slots);
        for row in [[1.0, 0.0], [-3.0, 1.0], [2.0, 2.0]] {
            acc.push(&row);
        }
        acc.values()
    }
}
