//! The input table: signals over time as fmpy's `simulate_fmu(input=...)` takes them, a
//! time column and one column per input variable, and their values at a time as fmpy's
//! `Input.interpolate` computes them. How a run applies them is `input`'s.

use crate::error::{Error, Result};
use std::path::Path;

/// An input table: times ascending (equal neighbours allowed, a jump), one column of
/// values per named variable.
#[derive(Clone, Debug, PartialEq)]
pub struct InputTable {
    /// Variable names, as `--set` names them (`instance.variable`, or the bare name for a
    /// one-instance system).
    pub names: Vec<String>,
    /// The times, s.
    pub time: Vec<f64>,
    /// `columns[j][k]`: variable `j` at `time[k]`.
    pub columns: Vec<Vec<f64>>,
    /// `integers[j]`: column `j` as written, when every value of it is an integer (read
    /// from a file), so that a 64-bit integer input gets the value itself, not the nearest
    /// f64; `None` for the others.
    pub integers: Vec<Option<Vec<i128>>>,
}

impl InputTable {
    /// A table from its parts, checked: times finite and not decreasing, every column as
    /// long as the time column, values finite.
    pub fn new(names: Vec<String>, time: Vec<f64>, columns: Vec<Vec<f64>>) -> Result<InputTable> {
        let bad = |m: String| Error::Experiment(format!("input: {m}"));
        if time.is_empty() {
            return Err(bad("the table has no rows".into()));
        }
        if names.len() != columns.len() {
            return Err(bad(format!("{} names for {} columns", names.len(), columns.len())));
        }
        if let Some(t) = time.iter().find(|t| !t.is_finite()) {
            return Err(bad(format!("time {t} is not finite")));
        }
        if let Some(k) = time.windows(2).position(|w| w[1] < w[0]) {
            return Err(bad(format!("time goes back from {} to {} s at row {}", time[k], time[k + 1], k + 2)));
        }
        for (name, c) in names.iter().zip(&columns) {
            if c.len() != time.len() {
                return Err(bad(format!("column {name:?} has {} values for {} times", c.len(), time.len())));
            }
            if let Some(k) = c.iter().position(|v| !v.is_finite()) {
                return Err(bad(format!("{name} = {} at t = {} s is not finite", c[k], time[k])));
            }
        }
        let integers = vec![None; columns.len()];
        Ok(InputTable { names, time, columns, integers })
    }

    /// Reads a CSV file in fmpy's format: a header of names (quoted or not, the first
    /// being the time column), then rows of numbers separated by commas.
    pub fn read_csv(path: &Path) -> Result<InputTable> {
        let text = crate::unpack::read_text_file(path, "the input file", 1 << 30)?;
        let bad = |line: usize, m: String| Error::Experiment(format!("{}:{line}: {m}", path.display()));
        let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty());
        let (_, header) = lines.next().ok_or_else(|| bad(1, "empty file, expected a header of names".into()))?;
        let cells = |l: &str| -> Vec<String> {
            l.split(',').map(|c| c.trim().trim_matches('"').replace("\"\"", "\"")).collect()
        };
        let names = cells(header);
        if names.len() < 2 {
            return Err(bad(1, "expected a time column and at least one input column".into()));
        }
        let mut time = Vec::new();
        let mut columns = vec![Vec::new(); names.len() - 1];
        let mut integers: Vec<Option<Vec<i128>>> = vec![Some(Vec::new()); names.len() - 1];
        for (k, line) in lines {
            let row = cells(line);
            if row.len() != names.len() {
                return Err(bad(k + 1, format!("{} values, the header has {} names", row.len(), names.len())));
            }
            let num = |j: usize| {
                row[j]
                    .parse::<f64>()
                    .map_err(|_| bad(k + 1, format!("{:?} (column {:?}) is not a number", row[j], names[j])))
            };
            time.push(num(0)?);
            for (j, c) in columns.iter_mut().enumerate() {
                c.push(num(j + 1)?);
                if let Some(ints) = &mut integers[j] {
                    match row[j + 1].parse::<i128>() {
                        Ok(i) => ints.push(i),
                        Err(_) => integers[j] = None,
                    }
                }
            }
        }
        let mut table = InputTable::new(names[1..].to_vec(), time, columns)?;
        table.integers = integers;
        Ok(table)
    }

    /// The index `i0` of the first time at or after `t` (numpy's `searchsorted`, left).
    fn search(&self, t: f64) -> usize {
        self.time.partition_point(|x| *x < t)
    }

    /// The row whose values a discrete column holds at `t` (fmpy's `Input.interpolate`).
    pub(crate) fn discrete_row(&self, t: f64, after_event: bool) -> usize {
        let (time, n) = (&self.time, self.time.len());
        let i0 = self.search(t);
        if n < 2 || i0 == 0 {
            return 0;
        }
        if i0 == n {
            return n - 1;
        }
        let mut i = i0 - 1;
        if after_event {
            while i + 1 < n && (time[i + 1] < t || isclose(t, time[i + 1])) {
                i += 1;
            }
        }
        i
    }

    /// Column `j` at `t` as written, if it is a discrete column of integers.
    pub(crate) fn integer(&self, j: usize, t: f64, after_event: bool) -> Option<i128> {
        let ints = self.integers.get(j)?.as_ref()?;
        ints.get(self.discrete_row(t, after_event)).copied()
    }

    /// The value of column `j` at `t`, as fmpy's `Input.interpolate` computes it.
    pub fn value(&self, j: usize, t: f64, discrete: bool, after_event: bool) -> f64 {
        let (time, v) = (&self.time, &self.columns[j]);
        let n = time.len();
        if n < 2 {
            return v[0];
        }
        let i0 = self.search(t);
        if i0 == 0 {
            return v[0];
        }
        if i0 == n {
            return v[n - 1];
        }
        if discrete {
            return v[self.discrete_row(t, after_event)];
        }
        let mut i0 = i0;
        if isclose(t, time[i0]) && i0 < n - 1 && isclose(time[i0], time[i0 + 1]) {
            if after_event {
                while i0 < n - 1 && isclose(time[i0], time[i0 + 1]) {
                    i0 += 1;
                }
            }
            return v[i0];
        }
        let (t0, t1) = (time[i0 - 1], time[i0]);
        let w0 = (t1 - t) / (t1 - t0);
        let w1 = 1.0 - w0;
        w0 * v[i0 - 1] + w1 * v[i0]
    }
}

/// Python's `math.isclose` with its defaults (relative tolerance 1e-9, no absolute one),
/// which fmpy uses to compare times.
pub(crate) fn isclose(a: f64, b: f64) -> bool {
    a == b || (a - b).abs() <= 1e-9 * a.abs().max(b.abs())
}
