//! Reading a results CSV file: ours and fmpy's (`write_csv`), Dymola's and OpenModelica's
//! CSV exports: a header of names (quoted or not; the first column is time, whatever its
//! name), then rows of numbers separated by commas. `true` / `false` read as 1 / 0, `NaN`
//! and `inf` as themselves.

use crate::Results;
use std::path::Path;

/// The cells of one line: commas separate, double quotes enclose (`""` inside is a quote).
fn cells(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cell = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                cell.push('"');
                chars.next();
            }
            '"' => quoted = !quoted,
            ',' if !quoted => out.push(std::mem::take(&mut cell).trim().to_string()),
            _ => cell.push(c),
        }
    }
    out.push(cell.trim().to_string());
    out
}

fn number(text: &str) -> Option<f64> {
    match text.to_ascii_lowercase().as_str() {
        "true" => Some(1.0),
        "false" => Some(0.0),
        _ => text.parse().ok(),
    }
}

/// Reads the results CSV at `path` (every message names the file, the line and the column).
pub fn read_results_csv(path: &Path) -> Result<Results, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    parse_results_csv(&text).map_err(|e| format!("{}:{e}", path.display()))
}

/// Parses results CSV text; errors start with the line number.
pub fn parse_results_csv(text: &str) -> Result<Results, String> {
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty());
    let (_, header) = lines.next().ok_or("1: empty file, expected a header of names")?;
    let names = cells(header);
    if names.len() < 2 {
        return Err("1: expected a time column and at least one signal".into());
    }
    let mut values = Vec::new();
    for (k, line) in lines {
        let row = cells(line);
        if row.len() != names.len() {
            return Err(format!("{}: {} values, the header has {} names", k + 1, row.len(), names.len()));
        }
        for (j, c) in row.iter().enumerate() {
            values.push(number(c).ok_or_else(|| format!("{}: {c:?} (column {:?}) is not a number", k + 1, names[j]))?);
        }
    }
    Ok(Results { names: names[1..].to_vec(), values, exact: Vec::new() })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_ours_and_fmpys_and_names_the_bad_cell() {
        let r = parse_results_csv("\"time\",\"a,b\",\"say \"\"hi\"\"\"\n0,1,true\n0.5,NaN,false\n").unwrap();
        assert_eq!(r.names, ["a,b", "say \"hi\""]);
        assert_eq!(r.rows(), 2);
        assert_eq!(r.row(0), [0.0, 1.0, 1.0]);
        assert!(r.row(1)[1].is_nan());
        // fmpy writes the names unquoted
        let r = parse_results_csv("time,x\n0,1e-3\n").unwrap();
        assert_eq!((r.names.as_slice(), r.row(0)), (["x".to_string()].as_slice(), [0.0, 1e-3].as_slice()));
        assert_eq!(parse_results_csv("time,x\n0,1\n1,one\n").unwrap_err(), "3: \"one\" (column \"x\") is not a number");
        assert_eq!(parse_results_csv("time,x\n0\n").unwrap_err(), "2: 1 values, the header has 2 names");
        assert_eq!(parse_results_csv("").unwrap_err(), "1: empty file, expected a header of names");
    }
}
