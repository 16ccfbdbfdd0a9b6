//! The table as markdown (ours beside the paper's) and as the JSON of the contract:
//! `{"seed", "gains": {"robust", "pole_placement", "robust_tracking"}, "results": {"sim"|"real":
//! {maneuver: {controller: {"eps", "rmse": [x, y, psi], "eps_state", "max_delta"}}}}, "wall_s"}`.
//! The paper's gains are 4x2 (columns beta, yaw_rate), `robust_tracking`'s `K_track` 4x4
//! (columns e_y, e_psi, beta - beta_ref, yaw_rate - yaw_rate_ref); rows FL, FR, RL, RR.

use std::fmt::Write;

use serde_json::{json, Map, Value};

use crate::{paper, Controller, Table};

/// The gain as printed: the paper's controllers their `[beta, yaw_rate]` columns, the
/// tracking controller all four.
fn gain_columns(c: Controller, k: &[[f64; 4]; 4]) -> Vec<Vec<f64>> {
    let from = if c.uses_pose() { 0 } else { 2 };
    k.iter().map(|row| row[from..].to_vec()).collect()
}

fn gain_json(c: Controller, k: &[[f64; 4]; 4]) -> Value {
    json!(gain_columns(c, k))
}

/// The JSON of the contract (keys sorted; numbers in shortest round-trip form).
pub fn json(table: &Table) -> Value {
    let mut v = json_without_wall(table);
    if let Value::Object(m) = &mut v {
        m.insert("wall_s".into(), json!(table.wall_s));
    }
    v
}

/// [`json()`] without `wall_s`: equal for two runs of the same seed, bit for bit.
pub fn json_without_wall(table: &Table) -> Value {
    let mut gains = Map::new();
    for (c, k) in &table.gains {
        gains.insert(c.name().into(), gain_json(*c, k));
    }
    let mut results = Map::new();
    for f in table.fidelities() {
        let mut column = Map::new();
        for m in table.maneuvers() {
            let mut row = Map::new();
            for cell in table.cells.iter().filter(|c| c.fidelity == f && c.maneuver == m) {
                let r = &cell.metric;
                row.insert(
                    cell.controller.name().into(),
                    json!({
                        "eps": r.eps,
                        "rmse": [r.rmse[0], r.rmse[1], r.rmse[2]],
                        "eps_state": r.eps_state,
                        "max_delta": r.max_delta,
                    }),
                );
            }
            column.insert(m.name().into(), Value::Object(row));
        }
        results.insert(f.column().into(), Value::Object(column));
    }
    json!({"seed": table.seed, "gains": gains, "results": results})
}

fn heading(c: Controller) -> &'static str {
    match c {
        Controller::OpenLoop => "open-loop",
        Controller::PolePlacement => "non-robust",
        Controller::Robust => "robust",
        Controller::Custom(_) => "custom",
        Controller::RobustTracking => "robust tracking",
    }
}

/// `3.081e-2` (four significant digits; the paper prints three).
pub fn sci(x: f64) -> String {
    format!("{x:.3e}")
}

/// The start of a table's heading row: the column (`fidelity`) and one heading per controller.
fn write_heading_start(s: &mut String, fidelity: &str, controllers: &[Controller]) {
    let _ = write!(s, "| {fidelity} | ");
    for &c in controllers {
        let _ = write!(s, "{} | ", heading(c));
    }
}

/// One cell per controller: its `value` (bold for the `lowest` controller), `-` where it
/// has none.
fn write_cells(
    s: &mut String,
    controllers: &[Controller],
    lowest: Option<Controller>,
    value: impl Fn(Controller) -> Option<f64>,
) {
    for &c in controllers {
        match value(c) {
            Some(v) if Some(c) == lowest => {
                let _ = write!(s, "**{}** | ", sci(v));
            }
            Some(v) => {
                let _ = write!(s, "{} | ", sci(v));
            }
            None => s.push_str("- | "),
        }
    }
}

/// The markdown report: per column Table III (ours and the paper's, the lowest of each
/// row), the auxiliary `||(RMSE_beta, RMSE_r)||`, and the gains.
pub fn markdown(table: &Table) -> String {
    let mut s = String::new();
    let controllers = table.controllers();
    // the paper has only its three controllers
    let paper: Vec<Controller> = controllers.iter().copied().filter(|c| Controller::TABLE.contains(c)).collect();
    let _ = writeln!(
        s,
        "Table III, seed {} ({}), epsilon = ||(RMSE_X, RMSE_Y, RMSE_psi)||_2 [m, m, rad]",
        table.seed, table.engine
    );
    let _ = writeln!(s);
    for f in table.fidelities() {
        write_heading_start(&mut s, f.column(), &controllers);
        let _ = write!(s, "lowest | ");
        for &c in &paper {
            let _ = write!(s, "paper {} | ", heading(c));
        }
        let _ = writeln!(s, "paper lowest |");
        let _ = writeln!(s, "|---|{}", "---:|".repeat(controllers.len() + paper.len() + 2));
        for m in table.maneuvers() {
            let _ = write!(s, "| {} | ", m.name());
            let lowest = table.lowest(f, m);
            write_cells(&mut s, &controllers, lowest, |c| table.get(f, m, c).map(|cell| cell.metric.eps));
            let _ = write!(s, "{} | ", lowest.map_or("-", heading));
            let mut paper_best: Option<(Controller, f64)> = None;
            for &c in &paper {
                match paper::epsilon(f, m, c) {
                    Some(e) => {
                        let _ = write!(s, "{} | ", sci(e));
                        if paper_best.map_or(true, |(_, b)| e < b) {
                            paper_best = Some((c, e));
                        }
                    }
                    None => s.push_str("- | "),
                }
            }
            let _ = writeln!(s, "{} |", paper_best.map_or("-", |(c, _)| heading(c)));
        }
        let _ = writeln!(s);
    }
    let _ = writeln!(s, "Auxiliary: ||(RMSE_beta, RMSE_r)||_2 [rad, rad/s] (what the controllers regulate)");
    let _ = writeln!(s);
    for f in table.fidelities() {
        write_heading_start(&mut s, f.column(), &controllers);
        let _ = writeln!(s, "lowest |");
        let _ = writeln!(s, "|---|{}", "---:|".repeat(controllers.len() + 1));
        for m in table.maneuvers() {
            let _ = write!(s, "| {} | ", m.name());
            let cells: Vec<_> = controllers.iter().filter_map(|&c| table.get(f, m, c)).collect();
            let lowest =
                cells.iter().min_by(|a, b| a.metric.eps_state.total_cmp(&b.metric.eps_state)).map(|c| c.controller);
            write_cells(&mut s, &controllers, lowest, |c| table.get(f, m, c).map(|cell| cell.metric.eps_state));
            let _ = writeln!(s, "{} |", lowest.map_or("-", heading));
        }
        let _ = writeln!(s);
    }
    let _ = write!(s, "Largest steering command |delta| over the runs [rad] (limit delta_max = pi/2 = 1.5708):");
    for &c in &controllers {
        let m = table.cells.iter().filter(|x| x.controller == c).fold(0.0f64, |m, x| m.max(x.metric.max_delta));
        let _ = write!(s, " {} {m:.4};", c.name());
    }
    let _ = writeln!(s);
    let _ = writeln!(s);
    for (c, k) in &table.gains {
        let columns = if c.uses_pose() { "[k_e_y, k_e_psi, k_beta, k_yaw_rate]" } else { "[k_beta, k_yaw_rate]" };
        let _ = writeln!(s, "K {} (rows FL, FR, RL, RR; {columns}):", c.name());
        for (w, row) in ["FL", "FR", "RL", "RR"].iter().zip(k) {
            let text: Vec<String> = gain_columns(*c, &[*row; 4])[0].iter().map(|v| format!("{v:+.6}")).collect();
            let _ = writeln!(s, "  {w}: [{}]", text.join(", "));
        }
    }
    let _ = writeln!(s, "{} runs in {:.3} s wall", table.cells.len(), table.wall_s);
    s
}
