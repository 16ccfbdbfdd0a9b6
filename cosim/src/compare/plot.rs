//! One PNG per failing signal: the tube (shaded), the baseline, the result, and the
//! result's points outside the tube marked.

use super::tube::{Baseline, Tolerance};
use super::{Comparison, SignalReport};
use crate::Results;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

static FONT: &[u8] = include_bytes!("../../../table3/assets/DejaVuSans.ttf");

fn register_font() -> Result<(), String> {
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
    let s: String =
        signal.chars().map(|c| if c.is_alphanumeric() || "._-".contains(c) { c } else { '_' }).collect();
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

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.filter(|v| v.is_finite()).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let pad = if hi > lo { 0.04 * (hi - lo) } else { 0.5 * lo.abs().max(1e-3) };
    (lo - pad, hi + pad)
}

fn draw(
    path: &Path,
    s: &SignalReport,
    rt: &[f64],
    y: &[f64],
    base: &Baseline,
    tol: &Tolerance,
) -> Result<(), Box<dyn std::error::Error>> {
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
    let (t0, t1) = range(rt.iter().chain(base.time).copied());
    let (v0, v1) = range(y.iter().chain(base.value).copied().chain(tube.iter().flat_map(|(_, lo, hi)| [*lo, *hi])));
    let root = BitMapBackend::new(path, (1000, 600)).into_drawing_area();
    root.fill(&WHITE)?;
    let title = format!(
        "{}: {} of {} points outside the tube (rtol {}, atol {}, time-tol {} s)",
        s.name, s.violations, s.points, tol.rtol, tol.atol, tol.time_tol
    );
    let root = root.titled(&title, ("sans-serif", 20))?;
    let mut chart = ChartBuilder::on(&root)
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(80)
        .build_cartesian_2d(t0..t1, v0..v1)?;
    chart.configure_mesh().x_desc("time, s").y_desc(s.name.as_str()).label_style(("sans-serif", 14)).draw()?;
    // the tube: its upper edge forward and its lower edge back, one polygon
    let mut band: Vec<(f64, f64)> = tube.iter().map(|(t, _, hi)| (*t, *hi)).collect();
    band.extend(tube.iter().rev().map(|(t, lo, _)| (*t, *lo)));
    band.retain(|(_, v)| v.is_finite());
    chart
        .draw_series(std::iter::once(Polygon::new(band, TUBE.mix(0.35).filled())))?
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
        .draw_series(marks.map(|p| Cross::new(p, 5, VIOLATION.stroke_width(2))))?
        .label("outside the tube")
        .legend(|(x, y)| Cross::new((x + 10, y), 5, VIOLATION.stroke_width(2)));
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .position(SeriesLabelPosition::UpperRight)
        .draw()?;
    root.present()?;
    Ok(())
}
