//! The paper's Fig. 7 as PNG: per column, the XY paths of the reference and the three
//! controllers for every maneuver (`fig7_sim.png`, `fig7_real.png`), and per column and
//! maneuver the time plots of beta, yaw rate, the front-left and rear-left steering
//! commands and the friction (`time_sim_skidpad.png`, ...). Text is drawn with the bundled
//! DejaVu Sans (no system font needed).

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::prelude::*;
use rayon::prelude::*;

use crate::{Controller, Error, Fidelity, Maneuver, Run};

static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

fn register_font() -> Result<(), String> {
    static DONE: OnceLock<Result<(), String>> = OnceLock::new();
    DONE.get_or_init(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
            .map_err(|_| "the bundled DejaVu Sans font is invalid".to_string())
    })
    .clone()
}

/// Points kept per series: every `STRIDE`-th sample (10 ms; 3001 points for 30 s).
pub const STRIDE: usize = 10;

const REFERENCE: RGBColor = RGBColor(0, 0, 0);
const WHEEL_COLORS: [RGBColor; 4] =
    [RGBColor(213, 94, 0), RGBColor(0, 114, 178), RGBColor(0, 158, 115), RGBColor(204, 121, 167)];

/// The colour of a controller's lines (colour-blind safe).
pub fn color(c: Controller) -> RGBColor {
    match c {
        Controller::OpenLoop => RGBColor(213, 94, 0),
        Controller::PolePlacement => RGBColor(0, 114, 178),
        Controller::Robust => RGBColor(0, 158, 115),
        Controller::Custom(_) => RGBColor(120, 120, 120),
        Controller::RobustTracking => RGBColor(204, 121, 167),
    }
}

fn label(c: Controller) -> &'static str {
    match c {
        Controller::OpenLoop => "open-loop",
        Controller::PolePlacement => "non-robust (pole placement)",
        Controller::Robust => "robust",
        Controller::Custom(_) => "custom",
        Controller::RobustTracking => "robust tracking (pose feedback)",
    }
}

fn plot_err<E: std::fmt::Display>(path: &Path) -> impl Fn(E) -> Error + '_ {
    move |e| Error::Plot { path: path.to_path_buf(), reason: e.to_string() }
}

/// Tick label: at most three decimals, no trailing zeros, never `-0`.
fn tick(v: &f64) -> String {
    let s = format!("{v:.3}");
    let s = if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.').to_string() } else { s };
    if s == "-0" {
        "0".into()
    } else {
        s
    }
}

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if !lo.is_finite() || !hi.is_finite() {
        return (-1.0, 1.0);
    }
    let pad = ((hi - lo) * 0.05).max(1e-3);
    (lo - pad, hi + pad)
}

fn runs_of(runs: &[Run], fidelity: Fidelity, maneuver: Maneuver) -> Vec<&Run> {
    runs.iter().filter(|r| r.job.fidelity == fidelity && r.job.maneuver == maneuver).collect()
}

fn sampled(n: usize) -> impl Iterator<Item = usize> + Clone {
    (0..=n).step_by(STRIDE).chain(if n % STRIDE == 0 { None } else { Some(n) })
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;

/// Draws one XY panel: equal scale on both axes unless that would squash the paths to a
/// line (straight, lane change, slalom), then Y is stretched and the caption says so.
fn xy_panel(area: &Area, maneuver: Maneuver, runs: &[&Run], path: &Path) -> Result<(), Error> {
    let err = plot_err(path);
    let Some(first) = runs.first() else { return Ok(()) };
    let n = first.n_samples();
    let xs = runs.iter().flat_map(|r| r.x.iter().chain(&first.x_ref).copied());
    let ys = runs.iter().flat_map(|r| r.y.iter().chain(&first.y_ref).copied());
    let (mut x0, mut x1) = range(xs);
    let (mut y0, mut y1) = range(ys);
    let (w, h) = area.dim_in_pixel();
    let (pw, ph) = ((w as f64 - 75.0).max(10.0), (h as f64 - 80.0).max(10.0));
    let (sx, sy) = ((x1 - x0) / pw, (y1 - y0) / ph);
    let equal = sx.max(sy) / sx.min(sy) < 6.0;
    if equal {
        let scale = sx.max(sy);
        let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
        (x0, x1) = (cx - scale * pw / 2.0, cx + scale * pw / 2.0);
        (y0, y1) = (cy - scale * ph / 2.0, cy + scale * ph / 2.0);
    }
    let caption = if equal { maneuver.name().to_string() } else { format!("{} (axes not to scale)", maneuver.name()) };
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 22))
        .margin(8)
        .x_label_area_size(38)
        .y_label_area_size(55)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(&err)?;
    chart
        .configure_mesh()
        .x_desc("X [m]")
        .y_desc("Y [m]")
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 15))
        .light_line_style(WHITE.mix(0.0))
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .draw()
        .map_err(&err)?;
    for r in runs {
        let c = color(r.job.controller);
        chart.draw_series(LineSeries::new(sampled(n).map(|k| (r.x[k], r.y[k])), c.stroke_width(2))).map_err(&err)?;
    }
    chart
        .draw_series(DashedLineSeries::new(
            sampled(n).map(|k| (first.x_ref[k], first.y_ref[k])),
            6,
            4,
            REFERENCE.stroke_width(2),
        ))
        .map_err(&err)?;
    Ok(())
}

/// Fig. 7 for one column: the XY paths of every maneuver in `runs` (2 x 3 panels for six).
pub fn xy_figure(runs: &[Run], fidelity: Fidelity, path: &Path) -> Result<(), Error> {
    register_font().map_err(plot_err(path))?;
    let err = plot_err(path);
    let maneuvers: Vec<Maneuver> = Maneuver::ALL
        .into_iter()
        .filter(|m| runs.iter().any(|r| r.job.fidelity == fidelity && r.job.maneuver == *m))
        .collect();
    let (rows, cols) = if maneuvers.len() <= 3 { (1, maneuvers.len().max(1)) } else { (2, 3) };
    let root = BitMapBackend::new(path, (1800, 90 + 555 * rows as u32)).into_drawing_area();
    root.fill(&WHITE).map_err(&err)?;
    let title = format!(
        "Fig. 7 ({} column, seed {}): paths of the reference and the controllers",
        fidelity.column(),
        runs.first().map_or(0, |r| r.job.seed)
    );
    let root = root.titled(&title, ("sans-serif", 28)).map_err(&err)?;
    let (top, body) = root.split_vertically(36);
    let column: Vec<&Run> = runs.iter().filter(|r| r.job.fidelity == fidelity).collect();
    legend_strip(&top, &controller_legend(&column), path)?;
    let panels = body.split_evenly((rows, cols));
    for (panel, &m) in panels.iter().zip(&maneuvers) {
        let rs = runs_of(runs, fidelity, m);
        xy_panel(panel, m, &rs, path)?;
    }
    root.present().map_err(&err)?;
    Ok(())
}

struct Series {
    label: String,
    color: RGBColor,
    dashed: bool,
    points: Vec<(f64, f64)>,
}

/// A legend row across the top of a figure: a line sample and the label of each entry.
fn legend_strip(area: &Area, entries: &[(&str, RGBColor, bool)], path: &Path) -> Result<(), Error> {
    let err = plot_err(path);
    let (w, h) = area.dim_in_pixel();
    let y = h as i32 / 2;
    let style = TextStyle::from(("sans-serif", 18).into_font());
    let widths: Vec<i32> = entries
        .iter()
        .map(|(l, _, _)| 40 + area.estimate_text_size(l, &style).map_or(8 * l.len() as i32, |s| s.0 as i32) + 30)
        .collect();
    let mut x = (w as i32 - widths.iter().sum::<i32>()).max(0) / 2;
    for ((label, c, dashed), wd) in entries.iter().zip(widths) {
        if *dashed {
            for k in 0..4 {
                let x0 = x + k * 9;
                area.draw(&PathElement::new(vec![(x0, y), (x0 + 5, y)], c.stroke_width(3))).map_err(&err)?;
            }
        } else {
            area.draw(&PathElement::new(vec![(x, y), (x + 32, y)], c.stroke_width(3))).map_err(&err)?;
        }
        area.draw(&Text::new(label.to_string(), (x + 40, y - 9), style.clone())).map_err(&err)?;
        x += wd;
    }
    Ok(())
}

fn controller_legend(runs: &[&Run]) -> Vec<(&'static str, RGBColor, bool)> {
    let mut v: Vec<(&'static str, RGBColor, bool)> = Vec::new();
    for c in crate::CONTROLLERS {
        if runs.iter().any(|r| r.job.controller == c) {
            v.push((label(c), color(c), false));
        }
    }
    v.push(("reference", REFERENCE, true));
    v
}

fn time_panel(
    area: &Area,
    title: &str,
    y_desc: &str,
    series: &[Series],
    legend: bool,
    path: &Path,
) -> Result<(), Error> {
    let err = plot_err(path);
    let t0 = series.iter().flat_map(|s| s.points.first().map(|p| p.0)).fold(f64::INFINITY, f64::min).min(0.0);
    let t1 = series.iter().flat_map(|s| s.points.last().map(|p| p.0)).fold(0.0, f64::max).max(1e-3);
    let (y0, y1) = range(series.iter().flat_map(|s| s.points.iter().map(|p| p.1)));
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 18))
        .margin(6)
        .x_label_area_size(34)
        .y_label_area_size(62)
        .build_cartesian_2d(t0..t1, y0..y1)
        .map_err(&err)?;
    chart
        .configure_mesh()
        .x_desc("t [s]")
        .y_desc(y_desc)
        .label_style(("sans-serif", 13))
        .axis_desc_style(("sans-serif", 14))
        .light_line_style(WHITE.mix(0.0))
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .draw()
        .map_err(&err)?;
    for s in series {
        let c = s.color;
        let style = c.stroke_width(if s.dashed { 2 } else { 1 });
        let anno = if s.dashed {
            chart.draw_series(DashedLineSeries::new(s.points.iter().copied(), 6, 4, style)).map_err(&err)?
        } else {
            chart.draw_series(LineSeries::new(s.points.iter().copied(), style)).map_err(&err)?
        };
        if legend {
            anno.label(s.label.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 22, y)], c.stroke_width(3)));
        }
    }
    if legend {
        chart
            .configure_series_labels()
            .label_font(("sans-serif", 14))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(&err)?;
    }
    Ok(())
}

/// The time plots of one column and maneuver: beta, yaw rate (reference and each
/// controller), front-left and rear-left steering commands, and the friction per wheel.
pub fn time_figure(runs: &[Run], fidelity: Fidelity, maneuver: Maneuver, path: &Path) -> Result<(), Error> {
    register_font().map_err(plot_err(path))?;
    let err = plot_err(path);
    let rs = runs_of(runs, fidelity, maneuver);
    let Some(first) = rs.first() else { return Ok(()) };
    let n = first.n_samples();
    let deg = 180.0 / std::f64::consts::PI;
    let state = |get: &dyn Fn(&Run, usize) -> f64, get_ref: &dyn Fn(&Run, usize) -> f64| {
        let mut v: Vec<Series> = rs
            .iter()
            .map(|r| Series {
                label: label(r.job.controller).into(),
                color: color(r.job.controller),
                dashed: false,
                points: sampled(n).map(|k| (Run::time(k), get(r, k))).collect(),
            })
            .collect();
        v.push(Series {
            label: "reference".into(),
            color: REFERENCE,
            dashed: true,
            points: sampled(n).map(|k| (Run::time(k), get_ref(first, k))).collect(),
        });
        v
    };
    let steer = |wheel: usize| -> Vec<Series> {
        rs.iter()
            .map(|r| Series {
                label: label(r.job.controller).into(),
                color: color(r.job.controller),
                dashed: false,
                points: sampled(n - 1).map(|k| (Run::time(k), r.delta[k][wheel] * deg)).collect(),
            })
            .collect()
    };
    // the friction has 75 periods in 30 s: show the first 3 s
    let mu_n = (n - 1).min(3000);
    let mu: Vec<Series> = ["FL", "FR", "RL", "RR"]
        .iter()
        .enumerate()
        .map(|(i, w)| Series {
            label: format!("mu {w}"),
            color: WHEEL_COLORS[i],
            dashed: false,
            points: (0..mu_n).step_by(2).map(|k| (Run::time(k), first.mu[k][i])).collect(),
        })
        .collect();
    let root = BitMapBackend::new(path, (1500, 1600)).into_drawing_area();
    root.fill(&WHITE).map_err(&err)?;
    let title = format!(
        "{} column, {}: states, commands and friction (seed {})",
        fidelity.column(),
        maneuver.name(),
        first.job.seed
    );
    let root = root.titled(&title, ("sans-serif", 24)).map_err(&err)?;
    let (top, body) = root.split_vertically(32);
    legend_strip(&top, &controller_legend(&rs), path)?;
    let panels = body.split_evenly((5, 1));
    time_panel(
        &panels[0],
        "body slip angle beta",
        "beta [deg]",
        &state(&|r, k| r.beta[k] * deg, &|r, k| r.beta_ref[k] * deg),
        false,
        path,
    )?;
    time_panel(
        &panels[1],
        "yaw rate r",
        "r [deg/s]",
        &state(&|r, k| r.yaw_rate[k] * deg, &|r, k| r.yaw_rate_ref[k] * deg),
        false,
        path,
    )?;
    time_panel(&panels[2], "steering command, front left", "delta_FL [deg]", &steer(0), false, path)?;
    time_panel(&panels[3], "steering command, rear left", "delta_RL [deg]", &steer(2), false, path)?;
    time_panel(
        &panels[4],
        "road friction per wheel, first 3 s of 30 (the same for every controller)",
        "mu [-]",
        &mu,
        true,
        path,
    )?;
    root.present().map_err(&err)?;
    Ok(())
}

/// Every figure of `runs` into `dir` (created if needed), drawn in parallel: `fig7_<column>.png`
/// and `time_<column>_<maneuver>.png`. Returns the files written.
pub fn write_all(runs: &[Run], dir: &Path) -> Result<Vec<PathBuf>, Error> {
    std::fs::create_dir_all(dir).map_err(crate::error::io(dir))?;
    let mut tasks: Vec<(Fidelity, Option<Maneuver>)> = Vec::new();
    for f in Fidelity::ALL {
        let ms: Vec<Maneuver> = Maneuver::ALL
            .into_iter()
            .filter(|m| runs.iter().any(|r| r.job.fidelity == f && r.job.maneuver == *m))
            .collect();
        if ms.is_empty() {
            continue;
        }
        tasks.push((f, None));
        tasks.extend(ms.into_iter().map(|m| (f, Some(m))));
    }
    tasks
        .par_iter()
        .map(|&(f, m)| {
            let path = match m {
                None => dir.join(format!("fig7_{}.png", f.column())),
                Some(m) => dir.join(format!("time_{}_{}.png", f.column(), m.name())),
            };
            match m {
                None => xy_figure(runs, f, &path)?,
                Some(m) => time_figure(runs, f, m, &path)?,
            }
            Ok(path)
        })
        .collect()
}
