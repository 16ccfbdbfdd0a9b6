//! A hand-written SVG figure of a [`SynthesisReport`]: the Pareto curve with the chosen
//! point (left), the closed-loop poles of the 16 vertices with the pole region (middle), and
//! the same region zoomed to the origin, where its half-plane boundary (`Re(s) < -0.1` in the
//! paper) and the sector's apex are (right). [`render_png`] rasterises the SVG with the
//! bundled DejaVu Sans (no system font needed).

use std::fmt::Write as _;

use crate::region::Region;
use crate::report::{ChosenPoint, ParetoEntry, PlantReport, SynthesisReport, TrackingReport, VerificationSummary};
use crate::verify::PointCheck;

const W: f64 = 1560.0;
const H: f64 = 540.0;

struct Frame {
    x0: f64,
    y0: f64,
    w: f64,
    h: f64,
    xmin: f64,
    xmax: f64,
    ymin: f64,
    ymax: f64,
}

impl Frame {
    fn px(&self, x: f64) -> f64 {
        self.x0 + (x - self.xmin) / (self.xmax - self.xmin) * self.w
    }
    fn py(&self, y: f64) -> f64 {
        self.y0 + self.h - (y - self.ymin) / (self.ymax - self.ymin) * self.h
    }
}

fn nice_step(range: f64, target: usize) -> f64 {
    let raw = range / target as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let norm = raw / mag;
    let f = if norm < 1.5 {
        1.0
    } else if norm < 3.0 {
        2.0
    } else if norm < 7.0 {
        5.0
    } else {
        10.0
    };
    f * mag
}

fn fmt_tick(v: f64, step: f64) -> String {
    let digits = (-step.log10().floor()).max(0.0) as usize;
    // a tick that rounds to zero is "0", never "-0.0"
    let v = if v.abs() < 0.5 * step { 0.0 } else { v };
    format!("{v:.digits$}")
}

fn axes(s: &mut String, f: &Frame, title: &str, xlabel: &str, ylabel: &str) {
    let (title, xlabel, ylabel) = (xml_escape(title), xml_escape(xlabel), xml_escape(ylabel));
    let _ = writeln!(
        s,
        r##"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="white" stroke="#333"/>"##,
        f.x0, f.y0, f.w, f.h
    );
    let xs = nice_step(f.xmax - f.xmin, 6);
    let mut v = (f.xmin / xs).ceil() * xs;
    while v <= f.xmax + 1e-12 * xs.abs() {
        let x = f.px(v);
        let _ = writeln!(
            s,
            r##"<line x1="{x:.1}" y1="{:.1}" x2="{x:.1}" y2="{:.1}" stroke="#ddd"/><text x="{x:.1}" y="{:.1}" font-size="11" text-anchor="middle">{}</text>"##,
            f.y0,
            f.y0 + f.h,
            f.y0 + f.h + 14.0,
            fmt_tick(v, xs)
        );
        v += xs;
    }
    let ys = nice_step(f.ymax - f.ymin, 6);
    let mut v = (f.ymin / ys).ceil() * ys;
    while v <= f.ymax + 1e-12 * ys.abs() {
        let y = f.py(v);
        let _ = writeln!(
            s,
            r##"<line x1="{:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#ddd"/><text x="{:.1}" y="{:.1}" font-size="11" text-anchor="end">{}</text>"##,
            f.x0,
            f.x0 + f.w,
            f.x0 - 4.0,
            y + 4.0,
            fmt_tick(v, ys)
        );
        v += ys;
    }
    let _ = writeln!(
        s,
        r##"<text x="{:.1}" y="{:.1}" font-size="14" font-weight="bold" text-anchor="middle">{title}</text>"##,
        f.x0 + f.w / 2.0,
        f.y0 - 10.0
    );
    let _ = writeln!(
        s,
        r##"<text x="{:.1}" y="{:.1}" font-size="12" text-anchor="middle">{xlabel}</text>"##,
        f.x0 + f.w / 2.0,
        f.y0 + f.h + 32.0
    );
    let _ = writeln!(
        s,
        r##"<text x="{:.1}" y="{:.1}" font-size="12" text-anchor="middle" transform="rotate(-90 {:.1} {:.1})">{ylabel}</text>"##,
        f.x0 - 42.0,
        f.y0 + f.h / 2.0,
        f.x0 - 42.0,
        f.y0 + f.h / 2.0
    );
}

/// Clips a convex polygon to the half-plane `a x + b y <= c` (Sutherland-Hodgman).
fn clip(poly: &[(f64, f64)], a: f64, b: f64, c: f64) -> Vec<(f64, f64)> {
    let inside = |p: &(f64, f64)| a * p.0 + b * p.1 <= c;
    let mut out = Vec::new();
    for i in 0..poly.len() {
        let p = poly[i];
        let q = poly[(i + 1) % poly.len()];
        let (ip, iq) = (inside(&p), inside(&q));
        if ip {
            out.push(p);
        }
        if ip != iq {
            let fp = a * p.0 + b * p.1 - c;
            let fq = a * q.0 + b * q.1 - c;
            let t = fp / (fp - fq);
            out.push((p.0 + t * (q.0 - p.0), p.1 + t * (q.1 - p.1)));
        }
    }
    out
}

/// The region intersected with the view box, as a polygon.
fn region_polygon(parts: &[Region], f: &Frame) -> Vec<(f64, f64)> {
    let mut poly = vec![(f.xmin, f.ymin), (f.xmax, f.ymin), (f.xmax, f.ymax), (f.xmin, f.ymax)];
    for part in parts {
        match *part {
            Region::HalfPlane { alpha } => poly = clip(&poly, 1.0, 0.0, alpha),
            Region::Sector { half_angle } => {
                let (sn, cs) = half_angle.sin_cos();
                poly = clip(&poly, sn, cs, 0.0);
                poly = clip(&poly, sn, -cs, 0.0);
            }
            Region::Disk { center, radius } => {
                let n = 256;
                for i in 0..n {
                    let t = 2.0 * std::f64::consts::PI * i as f64 / n as f64;
                    let (a, b) = (t.cos(), t.sin());
                    // tangent half-plane of the circumscribed polygon is slightly larger
                    // than the disk; use the inscribed one (conservative)
                    let c = a * center + radius * (std::f64::consts::PI / n as f64).cos();
                    poly = clip(&poly, a, b, c);
                }
            }
        }
        if poly.is_empty() {
            break;
        }
    }
    poly
}

/// What the figure shows, borrowed from a report.
struct PlotView<'a> {
    plant: &'a PlantReport,
    objective: &'a str,
    pareto: &'a [ParetoEntry],
    chosen: &'a ChosenPoint,
    gamma_star: Option<f64>,
    vertices: &'a [PointCheck],
    region: &'a [Region],
    region_description: &'a str,
    verification: &'a VerificationSummary,
}

/// Renders the figure of the paper's (2-state) design as an SVG document.
pub fn render_svg(r: &SynthesisReport) -> String {
    render(&PlotView {
        plant: &r.plant,
        objective: r.objective,
        pareto: &r.pareto,
        chosen: &r.chosen,
        gamma_star: r.gamma_star,
        vertices: &r.vertices,
        region: &r.region,
        region_description: &r.region_description,
        verification: &r.verification,
    })
}

/// Renders the figure of the tracking design (Pareto curve, poles of the 4-state closed
/// loop at the 16 vertices) as an SVG document.
pub fn render_tracking_svg(r: &TrackingReport) -> String {
    render(&PlotView {
        plant: &r.plant,
        objective: "tracking pareto",
        pareto: &r.pareto,
        chosen: &r.chosen,
        gamma_star: Some(r.gamma_star),
        vertices: &r.vertices,
        region: &r.region,
        region_description: &r.region_description,
        verification: &r.verification,
    })
}

fn render(r: &PlotView) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" viewBox="0 0 {W} {H}" font-family="DejaVu Sans, sans-serif">"##
    );
    let _ = writeln!(s, r##"<rect width="{W}" height="{H}" fill="#fafafa"/>"##);
    let _ = writeln!(
        s,
        r##"<text x="{:.1}" y="22" font-size="15" text-anchor="middle">{} {}, d2 = {}, v = {} m/s, mu in [{}, {}]</text>"##,
        W / 2.0,
        r.plant.architecture.name(),
        r.objective,
        r.plant.d2,
        r.plant.speed,
        r.plant.mu_min,
        r.plant.mu_max
    );

    // ---- left: Pareto curve
    let pts: Vec<(f64, f64)> = r.pareto.iter().filter_map(|e| e.nu.map(|nu| (e.g, nu))).collect();
    let chosen = match (r.chosen.g, r.chosen.nu) {
        (Some(g), Some(nu)) => Some((g, nu)),
        _ => None,
    };
    let mut refs: Vec<(f64, f64, &str)> = Vec::new();
    if r.plant.d2 == "paper" && r.objective == "pareto" {
        match r.plant.architecture {
            crate::plant::Architecture::FourWheelSteering => refs.push((0.198, 0.556, "paper (0.198, 0.556)")),
            crate::plant::Architecture::Ackermann => refs.push((0.261, 0.645, "paper (0.261, 0.645)")),
        }
    }
    let all: Vec<(f64, f64)> = pts.iter().copied().chain(chosen).chain(refs.iter().map(|r| (r.0, r.1))).collect();
    let left = Frame { x0: 80.0, y0: 60.0, w: 400.0, h: 380.0, xmin: 0.0, xmax: 1.0, ymin: 0.0, ymax: 1.0 };
    if all.is_empty() {
        axes(&mut s, &left, "Pareto curve (not computed for this objective)", "g (H-inf bound)", "nu (H2 bound)");
    } else {
        let gx = all.iter().map(|p| p.0);
        let ny = all.iter().map(|p| p.1);
        let (gmin, gmax) = (gx.clone().fold(f64::INFINITY, f64::min), gx.fold(f64::NEG_INFINITY, f64::max));
        let (nmin, nmax) = (ny.clone().fold(f64::INFINITY, f64::min), ny.fold(f64::NEG_INFINITY, f64::max));
        let padx = ((gmax - gmin) * 0.06).max(0.01);
        let pady = ((nmax - nmin) * 0.06).max(0.01);
        let f = Frame { xmin: gmin - padx, xmax: gmax + padx, ymin: nmin - pady, ymax: nmax + pady, ..left };
        axes(
            &mut s,
            &f,
            "Pareto curve: min nu subject to gamma ≤ g",
            "g (bound on the L2 gain from F_w to z)",
            "nu (H2 bound)",
        );
        if let Some(gs) = r.gamma_star {
            if gs >= f.xmin && gs <= f.xmax {
                let x = f.px(gs);
                let _ = writeln!(
                    s,
                    r##"<line x1="{x:.1}" y1="{:.1}" x2="{x:.1}" y2="{:.1}" stroke="#888" stroke-dasharray="4 3"/><text x="{:.1}" y="{:.1}" font-size="11" fill="#555">gamma* = {gs:.5}</text>"##,
                    f.y0,
                    f.y0 + f.h,
                    x + 4.0,
                    f.y0 + 14.0
                );
            }
        }
        if pts.len() > 1 {
            let path: Vec<String> = pts.iter().map(|p| format!("{:.1},{:.1}", f.px(p.0), f.py(p.1))).collect();
            let _ = writeln!(
                s,
                r##"<polyline points="{}" fill="none" stroke="#1f77b4" stroke-width="1.5"/>"##,
                path.join(" ")
            );
        }
        for p in &pts {
            let _ = writeln!(s, r##"<circle cx="{:.1}" cy="{:.1}" r="2.5" fill="#1f77b4"/>"##, f.px(p.0), f.py(p.1));
        }
        for (g, nu, label) in &refs {
            // the label on the side of the marker with room for it, inside the axes
            // below and right of the marker: under the falling curve, inside the axes
            let (x, anchor) =
                if f.x0 + f.w - f.px(*g) > 140.0 { (f.px(*g) + 6.0, "start") } else { (f.px(*g) - 6.0, "end") };
            let y = (f.py(*nu) + 34.0).min(f.y0 + f.h - 6.0);
            let _ = writeln!(
                s,
                r##"<rect x="{:.1}" y="{:.1}" width="9" height="9" fill="none" stroke="#2ca02c" stroke-width="1.5"/><text x="{x:.1}" y="{y:.1}" font-size="11" fill="#2ca02c" text-anchor="{anchor}">{label}</text>"##,
                f.px(*g) - 4.5,
                f.py(*nu) - 4.5,
            );
        }
        if let Some((g, nu)) = chosen {
            let label = match r.chosen.k {
                Some(k) => format!("chosen k = {k}: ({g:.4}, {nu:.4})"),
                None => format!("design ({g:.4}, {nu:.4})"),
            };
            let (x, anchor) =
                if f.x0 + f.w - f.px(g) > 200.0 { (f.px(g) + 10.0, "start") } else { (f.px(g) - 10.0, "end") };
            let y = (f.py(nu) - 22.0).max(f.y0 + 14.0);
            let _ = writeln!(
                s,
                r##"<circle cx="{:.1}" cy="{:.1}" r="6" fill="none" stroke="#d62728" stroke-width="2"/><text x="{x:.1}" y="{y:.1}" font-size="12" fill="#d62728" text-anchor="{anchor}">{label}</text>"##,
                f.px(g),
                f.py(nu),
            );
        }
    }

    // ---- right: pole map
    let poles: Vec<[f64; 2]> = r.vertices.iter().flat_map(|v| v.poles.iter().copied()).collect();
    let mut xmin = poles.iter().map(|p| p[0]).fold(0.0, f64::min);
    let mut xmax: f64 = poles.iter().map(|p| p[0]).fold(0.0, f64::max);
    let mut yabs = poles.iter().map(|p| p[1].abs()).fold(0.0, f64::max);
    for part in r.region {
        if let Region::HalfPlane { alpha } = part {
            xmin = xmin.min(*alpha);
            xmax = xmax.max(*alpha);
        }
        if let Region::Disk { center, radius } = part {
            if radius.is_finite() && *radius < 10.0 * (xmax - xmin).max(1.0) {
                xmin = xmin.min(center - radius);
                xmax = xmax.max(center + radius);
                yabs = yabs.max(*radius);
            }
        }
    }
    let span = (xmax - xmin).max(1.0);
    xmin -= 0.08 * span;
    xmax += 0.12 * span;
    let yabs = yabs.max(0.45 * (xmax - xmin)) * 1.05;
    let f = Frame { x0: 590.0, y0: 60.0, w: 420.0, h: 380.0, xmin, xmax, ymin: -yabs, ymax: yabs };
    pole_panel(&mut s, &f, "Closed-loop poles at the 16 vertices", &poles, r.region);
    // the zoom: the half-plane boundary and the sector's apex, at a scale where they show
    let alpha = r.region.iter().find_map(|p| if let Region::HalfPlane { alpha } = p { Some(*alpha) } else { None });
    let reach = alpha.map_or(1.0, |a| (12.0 * a.abs()).max(0.5));
    let zoom = Frame {
        x0: 1100.0,
        y0: 60.0,
        w: 420.0,
        h: 380.0,
        xmin: -reach,
        xmax: 0.25 * reach,
        ymin: -0.45 * reach * 380.0 / 420.0 * 1.25,
        ymax: 0.45 * reach * 380.0 / 420.0 * 1.25,
    };
    pole_panel(&mut s, &zoom, "The region near the origin (zoom)", &poles, r.region);
    if let Some(a) = alpha {
        let x = zoom.px(a);
        let _ = writeln!(
            s,
            r##"<line x1="{x:.1}" y1="{:.1}" x2="{x:.1}" y2="{:.1}" stroke="#2ca02c" stroke-width="2" stroke-dasharray="6 3"/><text x="{:.1}" y="{:.1}" font-size="12" fill="#2ca02c" text-anchor="end">Re(s) = {a} 1/s</text>"##,
            zoom.y0,
            zoom.y0 + zoom.h,
            x - 5.0,
            zoom.y0 + 18.0
        );
    }
    let nearest = poles.iter().map(|p| p[0]).fold(f64::NEG_INFINITY, f64::max);
    let in_view = poles.iter().filter(|p| p[0] >= zoom.xmin && p[1].abs() <= zoom.ymax).count();
    let note = if in_view == 0 && nearest.is_finite() {
        format!("no pole in this view: the slowest is at Re(s) = {nearest:.2} 1/s")
    } else {
        format!("{in_view} poles in this view; the slowest at Re(s) = {nearest:.2} 1/s")
    };
    let _ = writeln!(
        s,
        r##"<text x="{:.1}" y="{:.1}" font-size="11" fill="#333">{}</text>"##,
        zoom.x0 + 8.0,
        zoom.y0 + zoom.h - 10.0,
        xml_escape(&note)
    );
    // legend under the axes, clear of the data
    let legend =
        if r.region.is_empty() { "no pole region".to_string() } else { format!("region: {}", r.region_description) };
    let ly = f.y0 + f.h + 62.0;
    let _ = writeln!(
        s,
        r##"<rect x="{:.1}" y="{:.1}" width="16" height="10" fill="#2ca02c" fill-opacity="0.13" stroke="#2ca02c"/><text x="{:.1}" y="{:.1}" font-size="12" fill="#2ca02c">{} (shaded)</text>"##,
        f.x0,
        ly - 9.0,
        f.x0 + 22.0,
        ly,
        xml_escape(&legend),
    );
    let _ = writeln!(
        s,
        r##"<text x="{:.1}" y="{:.1}" font-size="12" fill="#d62728">x closed-loop poles of the 16 friction vertices (worst distance inside the region {:.3} 1/s)</text>"##,
        f.x0,
        ly + 18.0,
        r.verification.worst_region_margin
    );
    let _ = writeln!(s, "</svg>");
    s
}

/// One pole map: the region shaded, the axes through the origin, the poles as crosses
/// (those outside the view left out).
fn pole_panel(s: &mut String, f: &Frame, title: &str, poles: &[[f64; 2]], region: &[Region]) {
    axes(s, f, title, "Re(s) [1/s]", "Im(s) [rad/s]");
    let region_poly = region_polygon(region, f);
    if region_poly.len() >= 3 && !region.is_empty() {
        let pts: Vec<String> = region_poly.iter().map(|p| format!("{:.1},{:.1}", f.px(p.0), f.py(p.1))).collect();
        let _ = writeln!(
            s,
            r##"<polygon points="{}" fill="#2ca02c" fill-opacity="0.13" stroke="#2ca02c" stroke-width="1.2"/>"##,
            pts.join(" ")
        );
    }
    if f.xmin < 0.0 && f.xmax > 0.0 {
        let _ = writeln!(
            s,
            r##"<line x1="{0:.1}" y1="{1:.1}" x2="{0:.1}" y2="{2:.1}" stroke="#555"/>"##,
            f.px(0.0),
            f.y0,
            f.y0 + f.h
        );
    }
    let _ = writeln!(
        s,
        r##"<line x1="{0:.1}" y1="{1:.1}" x2="{2:.1}" y2="{1:.1}" stroke="#555"/>"##,
        f.x0,
        f.py(0.0),
        f.x0 + f.w
    );
    for p in poles.iter().filter(|p| p[0] >= f.xmin && p[0] <= f.xmax && p[1] >= f.ymin && p[1] <= f.ymax) {
        let (x, y) = (f.px(p[0]), f.py(p[1]));
        let _ = writeln!(
            s,
            r##"<path d="M{:.1},{:.1} L{:.1},{:.1} M{:.1},{:.1} L{:.1},{:.1}" stroke="#d62728" stroke-width="1.6"/>"##,
            x - 4.0,
            y - 4.0,
            x + 4.0,
            y + 4.0,
            x - 4.0,
            y + 4.0,
            x + 4.0,
            y - 4.0
        );
    }
}

static FONT: &[u8] = include_bytes!("../../table3/assets/DejaVuSans.ttf");

/// Rasterises an SVG of this module to PNG (`scale` pixels per SVG unit), with the bundled
/// DejaVu Sans as the only font, so the PNG looks the same on every machine.
pub fn render_png(svg: &str, scale: f32) -> Result<Vec<u8>, String> {
    let mut options = resvg::usvg::Options { font_family: "DejaVu Sans".into(), ..Default::default() };
    options.fontdb_mut().load_font_data(FONT.to_vec());
    let tree = resvg::usvg::Tree::from_str(svg, &options).map_err(|e| format!("SVG: {e}"))?;
    let size = tree.size().to_int_size().scale_by(scale).ok_or("empty figure")?;
    let mut pixmap = resvg::tiny_skia::Pixmap::new(size.width(), size.height()).ok_or("figure too large")?;
    resvg::render(&tree, resvg::tiny_skia::Transform::from_scale(scale, scale), &mut pixmap.as_mut());
    pixmap.encode_png().map_err(|e| format!("PNG: {e}"))
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}
