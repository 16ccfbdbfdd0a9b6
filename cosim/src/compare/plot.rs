//! One PNG per failing signal: the tube (shaded), the baseline, the result, and the
//! result's points outside the tube marked.

use super::tube::{Baseline, Tolerance};
use super::{Comparison, SignalReport};
use crate::Results;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

static FONT: &[u8] = include_bytes!("../../../table3/assets/DejaVuSans.ttf");

/// Registers the bundled DejaVu Sans as plotters' `sans-serif` (once per process), so that
/// the figures look the same on every machine.
pub fn register_font() -> Result<(), String> {
    static DONE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    if *DONE.get_or_init(|| plotters::style::register_font("sans-serif", FontStyle::Normal, FONT).is_ok()) {
        Ok(())
    } else {
        Err("the bundled DejaVu Sans font is invalid".into())
    }
}

/// Colours of the Okabe-Ito palette (told apart with the common colour-vision deficiencies).
const RESULT: RGBColor = RGBColor(0, 114, 178);
const VIOLATION: RGBColor = RGBColor(213, 94, 0);
const TUBE: RGBColor = RGBColor(86, 180, 233);

/// A file name from a signal name (`plant.y` -> `plant.y.png`; other characters than
/// letters, digits, `.`, `_`, `-` become `_`).
pub fn file_name(signal: &str) -> String {
    let s: String = signal.chars().map(|c| if c.is_alphanumeric() || "._-".contains(c) { c } else { '_' }).collect();
    format!("{s}.png")
}

/// The tube of one signal sampled where its shape changes: at the result's and the
/// baseline's times and the baseline's times shifted by the time tolerance.
pub fn tube_samples(result_time: &[f64], base: &Baseline, tol: &Tolerance) -> Vec<(f64, f64, f64)> {
    let mut t: Vec<f64> = result_time.to_vec();
    for s in base.time {
        t.extend([*s - tol.time_tol, *s, *s + tol.time_tol]);
    }
    t.retain(|x| x.is_finite());
    t.sort_by(f64::total_cmp);
    t.dedup();
    t.into_iter().filter_map(|x| base.tube(x, tol).map(|(lo, hi)| (x, lo, hi))).collect()
}

/// Draws the PNGs of the failing signals of `comparison` into `dir` (created); returns
/// their paths. A signal missing on either side has no figure.
pub fn plot_failures(
    result: &Results,
    baseline: &Results,
    comparison: &Comparison,
    dir: &Path,
) -> Result<Vec<PathBuf>, String> {
    let failing: Vec<&SignalReport> = comparison.signals.iter().filter(|s| !s.passed).collect();
    if failing.is_empty() {
        return Ok(Vec::new());
    }
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    register_font()?;
    let rt = result.column("time").unwrap_or_default();
    let bt = baseline.column("time").unwrap_or_default();
    let mut out = Vec::new();
    for s in failing {
        let (Some(y), Some(b)) = (result.column(&s.name), baseline.column(&s.name)) else { continue };
        let path = dir.join(file_name(&s.name));
        draw(&path, s, &rt, &y, &Baseline { time: &bt, value: &b }, &comparison.tolerance)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        out.push(path);
    }
    Ok(out)
}

/// Tick label: 4 significant digits without trailing zeros, `1.5e-9` outside 1e-3 .. 1e5.
fn tick(v: &f64) -> String {
    tick_label(*v, 1e-3)
}

/// A tick label: up to 4 significant digits without trailing zeros (`0.001`, `10`, `2.5`),
/// magnitudes outside `plain_from` .. 1e5 as `1.5e-9`; never `-0`.
pub fn tick_label(v: f64, plain_from: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if !(plain_from..1e5).contains(&a) {
        let s = format!("{v:.3e}");
        let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
        let m = if m.contains('.') { m.trim_end_matches('0').trim_end_matches('.') } else { m };
        return format!("{m}e{e}");
    }
    let decimals = (3 - a.log10().floor() as i32).clamp(0, 8) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) =
        values.filter(|v| v.is_finite()).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let pad = if hi > lo { 0.04 * (hi - lo) } else { 0.5 * lo.abs().max(1e-3) };
    (lo - pad, hi + pad)
}

type Axis = plotters::coord::types::RangedCoordf64;
/// A chart of f64 over f64.
type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<Axis, Axis>>;

/// A chart on `area` over `x` (time) and `y`, with `x_label_area` pixels below for the time
/// axis' labels and 90 at the left for the values' (the two charts' y axes line up).
fn chart_on<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, plotters::coord::Shift>,
    x_label_area: u32,
    (x, y): (std::ops::Range<f64>, std::ops::Range<f64>),
) -> Result<Chart<'a, DB>, DrawingAreaErrorKind<DB::ErrorType>> {
    ChartBuilder::on(area).margin(12).x_label_area_size(x_label_area).y_label_area_size(90).build_cartesian_2d(x, y)
}

fn draw(
    path: &Path,
    s: &SignalReport,
    rt: &[f64],
    y: &[f64],
    base: &Baseline,
    tol: &Tolerance,
) -> Result<(), Box<dyn std::error::Error>> {
    let num = crate::simulate::number_text;
    let tube = tube_samples(rt, base, tol);
    let outside: Vec<(f64, f64)> = rt
        .iter()
        .zip(y)
        .filter(|(t, v)| match base.tube(**t, tol) {
            Some((lo, hi)) => !(**v >= lo && **v <= hi),
            None => true,
        })
        .map(|(t, v)| (*t, *v))
        .collect();
    // the deviations from the baseline at each time: the result's, the tube's edges'
    let at = |t: f64| base.tube(t, &Tolerance { rtol: 0.0, atol: 0.0, time_tol: 0.0 }).map(|(b, _)| b);
    let dev: Vec<(f64, f64)> =
        rt.iter().zip(y).filter_map(|(t, v)| at(*t).map(|b| (*t, v - b))).filter(|(_, d)| d.is_finite()).collect();
    let band_dev: Vec<(f64, f64, f64)> =
        tube.iter().filter_map(|(t, lo, hi)| at(*t).map(|b| (*t, lo - b, hi - b))).collect();
    let (t0, t1) = range(rt.iter().chain(base.time).copied());
    let (v0, v1) = range(y.iter().chain(base.value).copied().chain(tube.iter().flat_map(|(_, lo, hi)| [*lo, *hi])));
    let (d0, d1) = range(dev.iter().map(|(_, d)| *d).chain(band_dev.iter().flat_map(|(_, lo, hi)| [*lo, *hi])));
    let root = BitMapBackend::new(path, (1000, 800)).into_drawing_area();
    root.fill(&WHITE)?;
    let title = format!(
        "{}: {} of {} points outside the tube (rtol {}, atol {}, time-tol {} s)",
        s.name,
        s.violations,
        s.points,
        num(tol.rtol),
        num(tol.atol),
        num(tol.time_tol)
    );
    let root = root.titled(&title, ("sans-serif", 20))?;
    let (upper, lower) = root.split_vertically(430);
    let mut chart = chart_on(&upper, 30, (t0..t1, v0..v1))?;
    chart
        .configure_mesh()
        .y_desc(s.name.as_str())
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .label_style(("sans-serif", 14))
        .draw()?;
    // the tube: its upper edge forward and its lower edge back, one polygon
    let polygon = |edges: &[(f64, f64, f64)]| {
        let mut band: Vec<(f64, f64)> = edges.iter().map(|(t, _, hi)| (*t, *hi)).collect();
        band.extend(edges.iter().rev().map(|(t, lo, _)| (*t, *lo)));
        band.retain(|(_, v)| v.is_finite());
        band
    };
    chart
        .draw_series(std::iter::once(Polygon::new(polygon(&tube), TUBE.mix(0.35).filled())))?
        .label("tube")
        .legend(|(x, y)| Rectangle::new([(x, y - 5), (x + 20, y + 5)], TUBE.mix(0.35).filled()));
    chart
        .draw_series(LineSeries::new(
            base.time.iter().zip(base.value).filter(|(_, v)| v.is_finite()).map(|(t, v)| (*t, *v)),
            BLACK.stroke_width(1),
        ))?
        .label("baseline")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(1)));
    chart
        .draw_series(LineSeries::new(
            rt.iter().zip(y).filter(|(_, v)| v.is_finite()).map(|(t, v)| (*t, *v)),
            RESULT.stroke_width(2),
        ))?
        .label("result")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RESULT.stroke_width(2)));
    // a non-number outside the tube is drawn at the axis' bottom
    let marks = outside.iter().map(|(t, v)| (*t, if v.is_finite() { *v } else { v0 }));
    chart
        .draw_series(marks.map(|p| Cross::new(p, 4, VIOLATION.stroke_width(2))))?
        .label("outside the tube")
        .legend(|(x, y)| Cross::new((x + 10, y), 4, VIOLATION.stroke_width(2)));
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .position(SeriesLabelPosition::UpperLeft)
        .draw()?;
    // below: the same relative to the baseline, where a tube too thin to see above shows
    let mut chart = chart_on(&lower, 40, (t0..t1, d0..d1))?;
    chart
        .configure_mesh()
        .x_desc("time, s")
        .y_desc("minus the baseline")
        .x_label_formatter(&tick)
        // a tick a rounding away from zero is zero
        .y_label_formatter(&|v| tick(&if v.abs() < 1e-9 * (d1 - d0) { 0.0 } else { *v }))
        .label_style(("sans-serif", 14))
        .draw()?;
    chart.draw_series(std::iter::once(Polygon::new(polygon(&band_dev), TUBE.mix(0.35).filled())))?;
    chart.draw_series(LineSeries::new(dev.iter().copied(), RESULT.stroke_width(2)))?;
    let marks = outside.iter().filter_map(|(t, v)| at(*t).map(|b| (*t, v - b))).filter(|(_, d)| d.is_finite());
    chart.draw_series(marks.map(|p| Cross::new(p, 4, VIOLATION.stroke_width(2))))?;
    root.present()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    #[test]
    fn tick_labels_are_short() {
        let t: Vec<String> = [0.0, 1.5e-9, 1e-3, 0.25, 30.0, -0.12, 2e5].iter().map(super::tick).collect();
        assert_eq!(t, ["0", "1.5e-9", "0.001", "0.25", "30", "-0.12", "2e5"]);
        assert_eq!(super::file_name("plant.y[1,2]"), "plant.y_1_2_.png");
    }
}
