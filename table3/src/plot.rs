//! The paper's Fig. 7 as PNG: per column, the XY paths of the reference and the
//! controllers for every maneuver (`fig7_sim.png`, `fig7_real.png`), and per column and
//! maneuver the time plots of beta, yaw rate, the front-left and rear-left steering
//! commands per controller, and the friction (`time_sim_skidpad.png`, ...). Text is drawn with the bundled
//! DejaVu Sans (no system font needed).

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::coord::types::RangedCoordf64;
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

/// The friction panels' colour: dark grey, none of the controllers' colours, because the
/// road is the same for every controller (the test bench's, not a controller's output).
const FRICTION_COLOR: RGBColor = RGBColor(64, 64, 64);

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

/// The axes of a chart: descriptions `(x, y)`, tick labels of `label_size` px with [`tick`]
/// (`x_labels` of them on x when given), descriptions one px larger, no light grid lines.
fn draw_axes(
    chart: &mut ChartContext<'_, BitMapBackend<'_>, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    (x_desc, y_desc): (&str, &str),
    label_size: u32,
    x_labels: Option<usize>,
    path: &Path,
) -> Result<(), Error> {
    let mut mesh = chart.configure_mesh();
    mesh.x_desc(x_desc)
        .y_desc(y_desc)
        .label_style(("sans-serif", label_size))
        .axis_desc_style(("sans-serif", label_size + 1))
        .light_line_style(WHITE.mix(0.0))
        .x_label_formatter(&tick)
        .y_label_formatter(&tick);
    if let Some(n) = x_labels {
        mesh.x_labels(n);
    }
    mesh.draw().map_err(plot_err(path))
}

/// The reference band: wide and light, drawn first, so that a controller on the reference
/// (robust tracking) stays visible on top of it.
const REFERENCE_BAND: RGBColor = RGBColor(210, 210, 210);
/// Degrees per radian (the time plots show angles in degrees).
const DEG: f64 = 180.0 / std::f64::consts::PI;
/// Seconds between the direction arrows on the reference.
const ARROW_EVERY: f64 = 5.0;

/// What the reference is, for the captions.
const REFERENCE_CAPTION: &str =
    "reference (grey band): the open-loop run of the same plant and program without disturbances (mu = 0.4, no wind, no noise)";

/// The last sample's time [s].
fn duration(run: &Run) -> f64 {
    Run::time(run.n_samples())
}

/// Length of the time plots' window [s]: the 2.5 Hz friction variation (0.4 s a period)
/// and the steering transients stay apart at about 70 pixels a second.
pub const WINDOW: f64 = 8.0;

/// The time window the time plots show, inside `[0, t_end]`: from 1 s before the steering
/// program (`program[k]`: at `t_k`, the command of the wheel steered the most) first reaches its
/// largest magnitude (within 1 %), for [`WINDOW`] seconds or until 3 s after the program's
/// last change if that comes first (at least 4 s): the lane change's impulse and recovery,
/// the skidpad's step, the end of the fishhook's ramp with its hold and release, the
/// slalom's first periods, the figure 8's first switches. The whole run when the program
/// never steers (straight) or the run is shorter than the window.
pub fn focus_window(program: &[f64], t_end: f64) -> (f64, f64) {
    let peak = program.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if peak <= 0.0 || t_end <= WINDOW {
        return (0.0, t_end);
    }
    let k = program.iter().position(|v| v.abs() >= 0.99 * peak).unwrap_or(0);
    let t0 = (Run::time(k) - 1.0).clamp(0.0, t_end - WINDOW);
    let last = (1..program.len()).rev().find(|&j| program[j] != program[j - 1]).unwrap_or(0);
    (t0, (t0 + WINDOW).min((Run::time(last) + 3.0).max(t0 + 4.0)))
}

/// Draws one XY panel. Equal scale on both axes unless that would leave most of the panel
/// empty (straight, lane change, slalom): then Y is stretched and the caption says so. The
/// reference is a grey band under the paths, with a start marker and arrows every 5 s in the
/// direction of travel.
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
    let equal = sx.max(sy) / sx.min(sy) < 1.85;
    if equal {
        let scale = sx.max(sy);
        let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
        (x0, x1) = (cx - scale * pw / 2.0, cx + scale * pw / 2.0);
        (y0, y1) = (cy - scale * ph / 2.0, cy + scale * ph / 2.0);
    }
    let caption = if equal {
        maneuver.name().to_string()
    } else {
        format!("{} (Y stretched: axes not to scale)", maneuver.name())
    };
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 22))
        .margin(8)
        .x_label_area_size(38)
        .y_label_area_size(55)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(&err)?;
    draw_axes(&mut chart, ("X [m]", "Y [m]"), 14, None, path)?;
    chart
        .draw_series(LineSeries::new(
            sampled(n).map(|k| (first.x_ref[k], first.y_ref[k])),
            REFERENCE_BAND.stroke_width(7),
        ))
        .map_err(&err)?;
    for r in runs {
        let c = color(r.job.controller);
        chart.draw_series(LineSeries::new(sampled(n).map(|k| (r.x[k], r.y[k])), c.stroke_width(2))).map_err(&err)?;
    }
    // direction of travel on the reference: a filled triangle every ARROW_EVERY seconds,
    // pointing along the reference heading (drawn in pixels, so it keeps its shape on
    // stretched axes)
    let every = (ARROW_EVERY / Run::time(1)).round() as usize;
    let to_px = |x: f64, y: f64| chart.backend_coord(&(x, y));
    let (c00, c11) = (to_px(x0, y0), to_px(x1, y1));
    let px_per_m = ((c11.0 - c00.0) as f64 / (x1 - x0), (c11.1 - c00.1) as f64 / (y1 - y0));
    let mut arrows = Vec::new();
    for k in (every..n).step_by(every) {
        // the heading psi_ref mapped through the (linear) axes: pixels per metre from the
        // corners (points outside the axes would be clamped)
        let h = first.psi_ref[k];
        let (dx, dy) = (h.cos() * px_per_m.0, h.sin() * px_per_m.1);
        let len = dx.hypot(dy);
        if len < 1e-9 {
            continue;
        }
        let (ux, uy) = (dx / len, dy / len);
        let tip = to_px(first.x_ref[k], first.y_ref[k]);
        let (tx, ty) = (tip.0 as f64 + 7.0 * ux, tip.1 as f64 + 7.0 * uy);
        let back = (tx - 14.0 * ux, ty - 14.0 * uy);
        let p = |sx: f64| ((back.0 - sx * 6.0 * uy) as i32, (back.1 + sx * 6.0 * ux) as i32);
        arrows.push(vec![(tx as i32, ty as i32), p(1.0), p(-1.0)]);
    }
    let start = to_px(first.x_ref[0], first.y_ref[0]);
    let plot_area = chart.plotting_area().strip_coord_spec();
    // backend_coord is in the whole image's pixels, the plotting area draws in its own
    let base = plot_area.get_base_pixel();
    let local = |p: (i32, i32)| (p.0 - base.0, p.1 - base.1);
    let start = local(start);
    let arrows: Vec<Vec<(i32, i32)>> = arrows.into_iter().map(|a| a.into_iter().map(local).collect()).collect();
    for a in arrows {
        plot_area.draw(&Polygon::new(a, BLACK.filled())).map_err(&err)?;
    }
    plot_area.draw(&Circle::new(start, 6, BLACK.filled())).map_err(&err)?;
    plot_area.draw(&Circle::new(start, 3, WHITE.filled())).map_err(&err)?;
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
    let root = BitMapBackend::new(path, (1800, 150 + 555 * rows as u32)).into_drawing_area();
    root.fill(&WHITE).map_err(&err)?;
    let title = format!(
        "Fig. 7 ({} column, seed {}): paths X, Y of the car's centre of gravity under each controller",
        fidelity.column(),
        runs.first().map_or(0, |r| r.job.seed)
    );
    let root = root.titled(&title, ("sans-serif", 28)).map_err(&err)?;
    let (top, body) = root.split_vertically(96);
    let (legend, notes) = top.split_vertically(36);
    let column: Vec<&Run> = runs.iter().filter(|r| r.job.fidelity == fidelity).collect();
    legend_strip(&legend, &controller_legend(&column), path)?;
    caption_lines(
        &notes,
        &[
            REFERENCE_CAPTION,
            "ring: start at the origin; triangles: direction of travel on the reference, every 5 s; 30 s per run, the same disturbances for every controller",
        ],
        path,
    )?;
    let panels = body.split_evenly((rows, cols));
    for (panel, &m) in panels.iter().zip(&maneuvers) {
        let rs = runs_of(runs, fidelity, m);
        xy_panel(panel, m, &rs, path)?;
    }
    root.present().map_err(&err)?;
    Ok(())
}

/// Centered lines of caption text.
fn caption_lines(area: &Area, lines: &[&str], path: &Path) -> Result<(), Error> {
    let err = plot_err(path);
    let (w, h) = area.dim_in_pixel();
    let style = TextStyle::from(("sans-serif", 16).into_font());
    let step = h as i32 / lines.len().max(1) as i32;
    for (i, line) in lines.iter().enumerate() {
        let tw = area.estimate_text_size(line, &style).map_or(8 * line.len() as i32, |s| s.0 as i32);
        area.draw(&Text::new(line.to_string(), ((w as i32 - tw).max(0) / 2, i as i32 * step + 2), style.clone()))
            .map_err(&err)?;
    }
    Ok(())
}

struct Series {
    label: String,
    color: RGBColor,
    /// Line width in pixels.
    width: u32,
    points: Vec<(f64, f64)>,
}

/// A legend row across the top of a figure: a line sample and the label of each entry
/// (`band`: the reference's wide grey band).
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
    for ((label, c, band), wd) in entries.iter().zip(widths) {
        let width = if *band { 7 } else { 3 };
        area.draw(&PathElement::new(vec![(x, y), (x + 32, y)], c.stroke_width(width))).map_err(&err)?;
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
    if let Some(r) = runs.iter().find(|r| matches!(r.job.controller, Controller::Custom(_))) {
        v.push((label(r.job.controller), color(r.job.controller), false));
    }
    v.push(("reference", REFERENCE_BAND, true));
    v
}

/// One time panel over the window `t` with the y range `ys` (shared along a row), a tick
/// every second (every 5 s on a window longer than 10 s).
fn time_panel(
    area: &Area,
    title: &str,
    y_desc: &str,
    series: &[Series],
    t: (f64, f64),
    ys: (f64, f64),
    path: &Path,
) -> Result<(), Error> {
    let err = plot_err(path);
    let t = (t.0, t.1.max(t.0 + 1e-3));
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 17))
        .margin(6)
        .margin_right(14)
        .x_label_area_size(34)
        .y_label_area_size(58)
        .build_cartesian_2d(t.0..t.1, ys.0..ys.1)
        .map_err(&err)?;
    let every = if t.1 - t.0 > 10.0 { 5.0 } else { 1.0 };
    let ticks = ((t.1 - t.0) / every).floor() as usize + 1;
    draw_axes(&mut chart, ("t [s]", y_desc), 13, Some(ticks.max(2)), path)?;
    for s in series {
        chart.draw_series(LineSeries::new(s.points.iter().copied(), s.color.stroke_width(s.width))).map_err(&err)?;
    }
    Ok(())
}

/// The time plots of one column and maneuver as small multiples: one column of panels per
/// controller (beta, yaw rate, front-left and rear-left steering command, each over the
/// reference, the y range shared along a row), and the friction of each wheel below (FL, FR
/// over RL, RR), all over the [`focus_window`] of the maneuver's steering program.
pub fn time_figure(runs: &[Run], fidelity: Fidelity, maneuver: Maneuver, path: &Path) -> Result<(), Error> {
    register_font().map_err(plot_err(path))?;
    let err = plot_err(path);
    let rs = runs_of(runs, fidelity, maneuver);
    let Some(first) = rs.first() else { return Ok(()) };
    let n = first.n_samples();
    let t_end = duration(first);
    let deg = DEG;
    // the program: the open-loop run's command (K = 0); without it the reference run's
    // steering is not recorded and the whole run is shown
    let open_loop = rs.iter().find(|r| r.job.controller == Controller::OpenLoop);
    let program: Vec<f64> = open_loop
        .map(|r| {
            // the command of the wheel steered the most (signed, so that a switch shows)
            let largest = |w: usize| r.delta.iter().fold(0.0f64, |m, d| m.max(d[w].abs()));
            let w = (0..4).fold(0, |b, w| if largest(w) > largest(b) { w } else { b });
            r.delta.iter().map(|d| d[w]).collect()
        })
        .unwrap_or_default();
    let window = focus_window(&program, t_end);
    let in_window = |k: &usize| {
        let t = Run::time(*k);
        window.0 - 1e-9 <= t && t <= window.1 + 1e-9
    };
    // every 2nd sample inside the window (2 ms: 200 points a period of the friction)
    let sampled = |n: usize| (0..=n).step_by(2).filter(in_window);
    let reference_program = |wheel: usize| -> Vec<(f64, f64)> {
        // the reference run's command is the program itself (open loop, K = 0)
        match open_loop {
            Some(r) => sampled(n - 1).map(|k| (Run::time(k), r.delta[k][wheel] * deg)).collect(),
            None => Vec::new(),
        }
    };
    type Getter = dyn Fn(&Run, usize) -> f64;
    let quantity = |r: &Run, get: &Getter, get_ref: Option<&Getter>| -> Vec<Series> {
        let mut v = Vec::new();
        if let Some(g) = get_ref {
            v.push(Series {
                label: "reference".into(),
                color: REFERENCE_BAND,
                width: 5,
                points: sampled(n).map(|k| (Run::time(k), g(first, k))).collect(),
            });
        }
        v.push(Series {
            label: label(r.job.controller).into(),
            color: color(r.job.controller),
            width: 1,
            points: sampled(n).map(|k| (Run::time(k), get(r, k))).collect(),
        });
        v
    };
    let beta: Vec<Vec<Series>> =
        rs.iter().map(|r| quantity(r, &|r, k| r.beta[k] * DEG, Some(&|r, k| r.beta_ref[k] * DEG))).collect();
    let yaw: Vec<Vec<Series>> =
        rs.iter().map(|r| quantity(r, &|r, k| r.yaw_rate[k] * DEG, Some(&|r, k| r.yaw_rate_ref[k] * DEG))).collect();
    let steer = |wheel: usize| -> Vec<Vec<Series>> {
        rs.iter()
            .map(|r| {
                let mut v = vec![Series {
                    label: "program".into(),
                    color: REFERENCE_BAND,
                    width: 5,
                    points: reference_program(wheel),
                }];
                v.push(Series {
                    label: label(r.job.controller).into(),
                    color: color(r.job.controller),
                    width: 1,
                    points: sampled(n - 1).map(|k| (Run::time(k), r.delta[k][wheel] * deg)).collect(),
                });
                v
            })
            .collect()
    };
    let (front, rear) = (steer(0), steer(2));
    let row_range = |row: &[Vec<Series>]| range(row.iter().flatten().flat_map(|s| s.points.iter().map(|p| p.1)));
    let cols = rs.len();
    let root = BitMapBackend::new(path, (560 * cols as u32 + 40, 1720)).into_drawing_area();
    root.fill(&WHITE).map_err(&err)?;
    let title = format!(
        "{} column, {}: states and steering commands per controller, and the road friction (seed {})",
        fidelity.column(),
        maneuver.name(),
        first.job.seed
    );
    let root = root.titled(&title, ("sans-serif", 24)).map_err(&err)?;
    let (top, body) = root.split_vertically(92);
    let (legend, notes) = top.split_vertically(36);
    legend_strip(&legend, &controller_legend(&rs), path)?;
    caption_lines(
        &notes,
        &[
            &format!(
            "{REFERENCE_CAPTION}; under the steering commands: the program (the open-loop command). Angles in degrees."
        ),
            &format!(
                "t = {} .. {} s of the {} s run{}",
                tick(&window.0),
                tick(&window.1),
                tick(&t_end),
                if window == (0.0, t_end) {
                    ""
                } else {
                    ": from 1 s before the steering program first reaches its largest magnitude"
                }
            ),
        ],
        path,
    )?;
    let (grid, bottom) = body.split_vertically(4 * 292);
    let panels = grid.split_evenly((4, cols));
    let rows: [(&str, &str, &[Vec<Series>]); 4] = [
        ("body slip angle beta", "beta [deg]", &beta),
        ("yaw rate r", "r [deg/s]", &yaw),
        ("steering command, front left", "delta_FL [deg]", &front),
        ("steering command, rear left", "delta_RL [deg]", &rear),
    ];
    for (i, (what, y_desc, row)) in rows.iter().enumerate() {
        let ys = row_range(row);
        for (j, series) in row.iter().enumerate() {
            let title = format!("{}: {what}", label(rs[j].job.controller));
            time_panel(&panels[i * cols + j], &title, y_desc, series, window, ys, path)?;
        }
    }
    let (mu_title, mu_grid) = bottom.split_vertically(30);
    caption_lines(
        &mu_title,
        &["road friction per wheel from the test bench (docs/benchmark.md), the same for every controller"],
        path,
    )?;
    let mu: Vec<Vec<Series>> = (0..4)
        .map(|i| {
            vec![Series {
                label: format!("mu {}", ["FL", "FR", "RL", "RR"][i]),
                color: FRICTION_COLOR,
                width: 1,
                points: sampled(n - 1).map(|k| (Run::time(k), first.mu[k][i])).collect(),
            }]
        })
        .collect();
    let ys = range(mu.iter().flatten().flat_map(|s| s.points.iter().map(|p| p.1)));
    for (area, series) in mu_grid.split_evenly((2, 2)).iter().zip(&mu) {
        let title = format!("{} [1]", series[0].label);
        time_panel(area, &title, "mu [1]", series, window, ys, path)?;
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A program sampled at 1 ms over 30 s from `f(t)`.
    fn program(f: impl Fn(f64) -> f64) -> Vec<f64> {
        (0..=30_000).map(|k| f(Run::time(k))).collect()
    }

    #[test]
    fn the_window_holds_where_the_program_steers() {
        let a = 0.5;
        // docs/benchmark.md's programs (the parts that set the window)
        let lane = program(|t| {
            if (14.8..15.0).contains(&t) {
                a
            } else if (15.0..15.2).contains(&t) {
                -a
            } else {
                0.0
            }
        });
        let (t0, t1) = focus_window(&lane, 30.0);
        assert!((t0 - 13.8).abs() < 1e-9 && (t1 - 18.2).abs() < 1e-6, "{t0} {t1}");
        let skidpad = program(|t| if (2.5..27.5).contains(&t) { a } else { 0.0 });
        assert_eq!(focus_window(&skidpad, 30.0), (1.5, 1.5 + WINDOW));
        // fishhook: ramp 2.5 .. 25 s, hold to 27.5 s: the window ends at the run's end
        let fishhook = program(|t| {
            if t < 2.5 || t >= 27.5 {
                0.0
            } else if t < 25.0 {
                a * (t - 2.5) / 22.5
            } else {
                a
            }
        });
        let (t0, t1) = focus_window(&fishhook, 30.0);
        assert!((t0 - (30.0 - WINDOW)).abs() < 1e-9 && (t1 - 30.0).abs() < 1e-9, "{t0} {t1}");
        let figure8 = program(|t| if (t / 3.2).floor() as i64 % 2 == 0 { a } else { -a });
        assert_eq!(focus_window(&figure8, 30.0), (0.0, WINDOW));
        let straight = program(|_| 0.0);
        assert_eq!(focus_window(&straight, 30.0), (0.0, 30.0));
        assert_eq!(focus_window(&skidpad[..5001], 5.0), (0.0, 5.0));
    }
}
