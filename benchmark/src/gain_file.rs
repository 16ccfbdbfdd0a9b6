//! The gain file: the JSON that `synthesize --json` writes, read back for the benchmark.
//!
//! One spelling for every tool (`table3 --gain`, `cosim run --gains`): the synthesis report's
//! `"K"` (4 rows FL, FR, RL, RR; 2 columns beta, r), with its `"K_rows"` and `"K_columns"`
//! checked, so that a tracking design (4 columns) or a hand-edited file with the rows in
//! another order is refused instead of run with the wrong meaning.

use serde::Deserialize;

/// The part of a synthesis report the benchmark reads.
#[derive(Deserialize)]
struct GainFile {
    #[serde(rename = "K")]
    k: Vec<Vec<f64>>,
    #[serde(rename = "K_rows")]
    rows: Vec<String>,
    #[serde(rename = "K_columns")]
    columns: Vec<String>,
}

/// Reads the gain `K` (`delta = delta_ff + K ([beta, r] - [beta_ref, r_ref])`, rows FL, FR,
/// RL, RR) of a `synthesize --json` report. `source` names the file in the messages.
pub fn read_gain_json(text: &str, source: &str) -> Result<[[f64; 2]; 4], String> {
    let file: GainFile = serde_json::from_str(text)
        .map_err(|e| format!("{source}: not a synthesis report with \"K\", \"K_rows\", \"K_columns\" ({e})"))?;
    if file.rows != ["FL", "FR", "RL", "RR"] {
        return Err(format!("{source}: K_rows must be [\"FL\", \"FR\", \"RL\", \"RR\"], not {:?}", file.rows));
    }
    if file.columns != ["beta", "r"] {
        return Err(format!(
            "{source}: K_columns must be [\"beta\", \"r\"] (the paper's state feedback), not {:?}; \
             a tracking gain (synthesize --model tracking) is not a custom gain",
            file.columns
        ));
    }
    let mut k = [[0.0; 2]; 4];
    if file.k.len() != 4 {
        return Err(format!("{source}: K has {} rows, expected 4", file.k.len()));
    }
    for (i, row) in file.k.iter().enumerate() {
        if row.len() != 2 {
            return Err(format!("{source}: K row {} has {} entries, expected 2", file.rows[i], row.len()));
        }
        for (j, &v) in row.iter().enumerate() {
            if !v.is_finite() {
                return Err(format!("{source}: K[{}][{}] = {v} is not finite", file.rows[i], file.columns[j]));
            }
            k[i][j] = v;
        }
    }
    Ok(k)
}

#[cfg(test)]
mod tests {
    use super::*;

    const REPORT: &str = r#"{"tool": "nigel-synthesis", "K": [[-0.1, -0.3], [-0.11, -0.31], [-0.14, 0.4], [-0.15, 0.41]],
        "K_rows": ["FL", "FR", "RL", "RR"], "K_columns": ["beta", "r"], "gamma_star": 0.117}"#;

    #[test]
    fn reads_the_rows_in_wheel_order() {
        let k = read_gain_json(REPORT, "k.json").unwrap();
        assert_eq!(k, [[-0.1, -0.3], [-0.11, -0.31], [-0.14, 0.4], [-0.15, 0.41]]);
    }

    #[test]
    fn refuses_what_would_be_misread() {
        let tracking = REPORT.replace(r#"["beta", "r"]"#, r#"["e_y", "e_psi", "beta - beta_ref", "r - r_ref"]"#);
        assert!(read_gain_json(&tracking, "t.json").unwrap_err().contains("tracking"));
        let reordered = REPORT.replace(r#"["FL", "FR", "RL", "RR"]"#, r#"["FR", "FL", "RL", "RR"]"#);
        assert!(read_gain_json(&reordered, "k.json").unwrap_err().contains("K_rows"));
        let short = REPORT.replace("[-0.15, 0.41]", "[-0.15]");
        assert!(read_gain_json(&short, "k.json").unwrap_err().contains("K row RR has 1 entries"));
        assert!(read_gain_json("{}", "k.json").unwrap_err().starts_with("k.json: not a synthesis report"));
    }
}
