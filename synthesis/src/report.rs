//! One synthesis run end to end (design + verification) and its serialisable report,
//! as the `synthesize` CLI prints it and writes it with `--json`.

use std::fmt::Write as _;
use std::time::Instant;

use nalgebra::DMatrix;
use serde::Serialize;

use crate::design::{
    min_h2, min_hinf, pareto_sweep, pole_placement_baseline, weighted, Design, ParetoSweep, SweepOptions,
    SweepProgress, SynthesisError, SynthesisOptions,
};
use crate::lmi::SolverStats;
use crate::plant::{Architecture, PlantSpec, TrackingSpec, TrackingWeights};
use crate::region::{PoleRegion, Region};
use crate::tracking::{
    design_tracking, offset_recovery, servo_loop_max_real_part, tracking_region, wind_step, ResponsePeaks,
    TrackingDesign,
};
use crate::verify::{verify_design, PointCheck, VerificationReport, VerifyOptions};

/// Wheel names in the order of the rows of the full 4x2 gain.
pub const WHEEL_NAMES: [&str; 4] = ["FL", "FR", "RL", "RR"];

/// What to design.
#[derive(Clone, Debug, PartialEq)]
pub enum Objective {
    /// The authors' Pareto sweep (the paper's controller).
    Pareto,
    /// Minimum H-inf bound `gamma*` with D-stability.
    Hinf,
    /// Minimum H2 bound, optionally under an H-inf bound.
    H2 {
        /// Optional `gamma <= hinf_bound`.
        hinf_bound: Option<f64>,
    },
    /// `min a gamma^2 + b nu^2`.
    Weighted {
        /// `a`, the weight of `gamma^2`.
        weight_hinf: f64,
        /// `b`, the weight of `nu^2`.
        weight_h2: f64,
    },
    /// The non-robust pole-placement baseline (nominal `mu`, half-plane `Re(s) < alpha`).
    Baseline {
        /// Nominal friction (paper: 0.4).
        mu_nominal: f64,
        /// Half-plane abscissa (paper: -2).
        alpha: f64,
    },
}

impl Objective {
    /// Short name (`pareto`, `hinf`, `h2`, `weighted`, `baseline`).
    pub fn name(&self) -> &'static str {
        match self {
            Objective::Pareto => "pareto",
            Objective::Hinf => "hinf",
            Objective::H2 { .. } => "h2",
            Objective::Weighted { .. } => "weighted",
            Objective::Baseline { .. } => "baseline",
        }
    }
}

/// A complete request.
#[derive(Clone, Debug, PartialEq)]
pub struct Request {
    /// The design model.
    pub spec: PlantSpec,
    /// The pole region (the paper's by default).
    pub region: PoleRegion,
    /// What to design.
    pub objective: Objective,
    /// Grid of the Pareto sweep.
    pub sweep: SweepOptions,
    /// Margin and solver settings.
    pub options: SynthesisOptions,
    /// Verification settings.
    pub verify: VerifyOptions,
}

impl Request {
    /// The paper's 4WD4WS Pareto design.
    pub fn paper(architecture: Architecture) -> Self {
        Request {
            spec: PlantSpec::paper(architecture),
            region: PoleRegion::paper(),
            objective: Objective::Pareto,
            sweep: SweepOptions::default(),
            options: SynthesisOptions::default(),
            verify: VerifyOptions::default(),
        }
    }
}

/// The plant part of the report.
#[derive(Clone, Debug, Serialize)]
pub struct PlantReport {
    /// Steering architecture.
    pub architecture: Architecture,
    /// Disturbance variant (`paper` or `physical`).
    pub d2: &'static str,
    /// Design speed (m/s).
    pub speed: f64,
    /// Lower friction bound.
    pub mu_min: f64,
    /// Upper friction bound.
    pub mu_max: f64,
    /// Mass (kg).
    pub m: f64,
    /// Yaw inertia (kg m2).
    pub i_z: f64,
    /// CG to front axle (m).
    pub l_f: f64,
    /// CG to rear axle (m).
    pub l_r: f64,
    /// Track width (m).
    pub track: f64,
    /// Cornering stiffness per wheel FL, FR, RL, RR (N/rad).
    pub cornering_stiffness: [f64; 4],
    /// `B_w = [d1, d2]`.
    pub bw: [f64; 2],
    /// Number of polytope vertices (16).
    pub n_vertices: usize,
    /// Names of the steered wheels (the inputs).
    pub steered_wheels: Vec<&'static str>,
}

/// One grid point of the sweep.
#[derive(Clone, Debug, Serialize)]
pub struct ParetoEntry {
    /// Grid index.
    pub k: usize,
    /// H-inf bound imposed (the L2-gain bound).
    pub g: f64,
    /// `null` if the point failed.
    pub nu: Option<f64>,
    /// `sqrt(g^2 + nu^2)`.
    pub distance: Option<f64>,
    /// `null` if solved, else why not.
    pub error: Option<String>,
    /// Solver statistics of the point.
    pub solver: Option<SolverStats>,
}

/// The chosen (or only) design point.
#[derive(Clone, Debug, Serialize)]
pub struct ChosenPoint {
    /// Grid index (Pareto only).
    pub k: Option<usize>,
    /// Certified H-inf bound (L2 gain), if any.
    pub g: Option<f64>,
    /// Certified H2 bound, if any.
    pub nu: Option<f64>,
}

/// Certified bounds against actual norms, worst case over vertices and interior points.
#[derive(Clone, Debug, Serialize)]
pub struct ActualNorms {
    /// Certified bound on the induced L2 gain (`null` if not constrained).
    pub hinf_bound: Option<f64>,
    /// Worst actual H-inf norm (Hamiltonian bisection).
    pub hinf_worst: f64,
    /// Worst actual H-inf norm (frequency sweep).
    pub hinf_worst_sweep: f64,
    /// Certified H2 bound (`null` if not constrained).
    pub h2_bound: Option<f64>,
    /// Worst actual H2 norm (Lyapunov).
    pub h2_worst: f64,
    /// Worst actual H2 norm (Gramian integration).
    pub h2_worst_integrated: f64,
    /// Largest relative difference between the two H-inf computations.
    pub hinf_methods_rel_diff: f64,
    /// Largest relative difference between the H2 computations.
    pub h2_methods_rel_diff: f64,
}

/// Verification summary.
#[derive(Clone, Debug, Serialize)]
pub struct VerificationSummary {
    /// Every check holds.
    pub passed: bool,
    /// Every checked plant is stable.
    pub all_stable: bool,
    /// Every checked pole is inside the region.
    pub poles_in_region: bool,
    /// Actual H-inf <= certified bound.
    pub hinf_within_bound: bool,
    /// Actual H2 <= certified bound.
    pub h2_within_bound: bool,
    /// Smallest region margin of any checked pole.
    pub worst_region_margin: f64,
    /// Largest real part of any checked pole.
    pub max_real_part: f64,
    /// Number of random interior points checked.
    pub interior_points: usize,
    /// Their seed.
    pub seed: u64,
}

/// Solver totals.
#[derive(Clone, Debug, Serialize)]
pub struct SolverSummary {
    /// Solver statistics of the point.
    pub solver: &'static str,
    /// Number of SDPs solved.
    pub n_solves: usize,
    /// Interior-point iterations, all solves.
    pub total_iterations: u64,
    /// Clarabel's solve time, all solves (s).
    pub total_solve_time_s: f64,
    /// Distinct clarabel statuses seen.
    pub statuses: Vec<String>,
    /// Statistics of the `gamma*` solve (Pareto and hinf).
    pub gamma_star: Option<SolverStats>,
    /// Statistics of the solve that produced `K`.
    pub design: SolverStats,
    /// Worst constraint violation at any returned point (checked by us).
    pub max_constraint_violation: f64,
    /// `max_constraint_violation < margin`: every returned point satisfies its *strict*
    /// LMIs (`F < 0`) when evaluated in floating point, so the certificates hold as stated.
    pub strict_lmis_hold: bool,
}

/// Wall times.
#[derive(Clone, Debug, Serialize)]
pub struct Timings {
    /// Synthesis wall time (s).
    pub design_s: f64,
    /// Verification wall time (s).
    pub verification_s: f64,
    /// Total wall time (s).
    pub total_s: f64,
}

/// Baseline extras.
#[derive(Clone, Debug, Serialize)]
pub struct BaselineReport {
    /// Nominal friction of the design model.
    pub mu_nominal: f64,
    /// Half-plane abscissa `Re(s) < alpha` at the nominal model.
    pub alpha: f64,
    /// Whether the gain stabilises all 16 vertices.
    pub stabilises_all_vertices: bool,
    /// Largest closed-loop real part over the vertices.
    pub max_real_part_over_vertices: f64,
}

/// Everything a run produced (what `--json` writes).
#[derive(Clone, Debug, Serialize)]
pub struct SynthesisReport {
    /// Producer (`nigel-synthesis`).
    pub tool: &'static str,
    /// Crate version.
    pub version: &'static str,
    /// Objective name.
    pub objective: &'static str,
    /// The design model.
    pub plant: PlantReport,
    /// The pole region (intersection of these parts).
    pub region: Vec<Region>,
    /// The region in words.
    pub region_description: String,
    /// Strictness margin `eps` (`F < 0` imposed as `F <= -eps I`).
    pub margin: f64,
    /// What `gamma`/`g` means.
    pub gamma_meaning: &'static str,
    /// `gamma*` (Pareto and hinf objectives).
    pub gamma_star: Option<f64>,
    /// The Pareto grid (Pareto objective only).
    pub pareto: Vec<ParetoEntry>,
    /// The chosen point (or the single design).
    pub chosen: ChosenPoint,
    /// `K` as 4 rows (FL, FR, RL, RR) x 2 columns (beta, r); rows of unsteered wheels are 0.
    #[serde(rename = "K")]
    pub k: Vec<[f64; 2]>,
    /// Row names of `K`.
    #[serde(rename = "K_rows")]
    pub k_rows: [&'static str; 4],
    /// Column names of `K` (the states).
    #[serde(rename = "K_columns")]
    pub k_columns: [&'static str; 2],
    /// The Lyapunov matrix `X`.
    #[serde(rename = "X")]
    pub x: [[f64; 2]; 2],
    /// Closed-loop poles and norms at the 16 vertices.
    pub vertices: Vec<PointCheck>,
    /// Certified bounds and actual worst-case norms.
    pub actual: ActualNorms,
    /// The independent verification.
    pub verification: VerificationSummary,
    /// Solver statistics of the point.
    pub solver: SolverSummary,
    /// Wall times.
    pub timings: Timings,
    /// Baseline extras (baseline objective only).
    pub baseline: Option<BaselineReport>,
}

fn full_gain(arch: Architecture, k: &DMatrix<f64>) -> Vec<[f64; 2]> {
    let mut rows = vec![[0.0; 2]; 4];
    for (i, &w) in arch.steered_wheels().iter().enumerate() {
        rows[w] = [k[(i, 0)], k[(i, 1)]];
    }
    rows
}

/// Runs a request: design, then verification. `progress` gets one call per grid point
/// of a Pareto sweep.
pub fn run(
    req: &Request,
    progress: Option<&(dyn Fn(SweepProgress) + Sync)>,
) -> Result<SynthesisReport, SynthesisError> {
    let t0 = Instant::now();
    let poly = req.spec.polytope()?;
    req.region.validate()?;
    let mut pareto = Vec::new();
    let mut gamma_star = None;
    let mut gamma_star_stats = None;
    let mut chosen = ChosenPoint { k: None, g: None, nu: None };
    let mut all_stats: Vec<SolverStats> = Vec::new();
    let mut baseline = None;
    let mut region = req.region.clone();
    let design: Design = match &req.objective {
        Objective::Pareto => {
            let sweep = pareto_sweep(&poly, &req.region, &req.sweep, &req.options, progress)?;
            gamma_star = Some(sweep.gamma_star());
            gamma_star_stats = Some(sweep.hinf_optimum.stats.clone());
            pareto = pareto_entries(&sweep, &mut all_stats);
            let c = sweep.chosen_point();
            chosen = ChosenPoint { k: Some(c.k), g: Some(c.g), nu: c.nu() };
            sweep
                .chosen_design()
                .cloned()
                .ok_or_else(|| SynthesisError::Invalid("chosen point has no design".into()))?
        }
        Objective::Hinf => {
            let d = min_hinf(&poly, &req.region, &req.options)?;
            gamma_star = d.gamma;
            gamma_star_stats = Some(d.stats.clone());
            all_stats.push(d.stats.clone());
            chosen = ChosenPoint { k: None, g: d.gamma, nu: None };
            d
        }
        Objective::H2 { hinf_bound } => {
            let d = min_h2(&poly, &req.region, *hinf_bound, &req.options)?;
            all_stats.push(d.stats.clone());
            chosen = ChosenPoint { k: None, g: d.gamma, nu: d.nu };
            d
        }
        Objective::Weighted { weight_hinf, weight_h2 } => {
            let d = weighted(&poly, &req.region, *weight_hinf, *weight_h2, &req.options)?;
            all_stats.push(d.stats.clone());
            chosen = ChosenPoint { k: None, g: d.gamma, nu: d.nu };
            d
        }
        Objective::Baseline { mu_nominal, alpha } => {
            let b = pole_placement_baseline(&poly, *mu_nominal, *alpha, &req.options)?;
            all_stats.push(b.design.stats.clone());
            baseline = Some(BaselineReport {
                mu_nominal: b.mu_nominal,
                alpha: b.alpha,
                stabilises_all_vertices: b.stabilises_all_vertices,
                max_real_part_over_vertices: b.max_real_part_over_vertices,
            });
            // the baseline is checked against its own (nominal) region only for the
            // record; over the polytope only stability is claimed
            region = PoleRegion::none();
            b.design
        }
    };
    let design_s = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let v = verify_design(&poly, &region, &design.gain, design.gamma, design.nu, &req.verify);
    let verification_s = t1.elapsed().as_secs_f64();
    let spec = &req.spec;
    let x = &design.lyapunov;
    Ok(SynthesisReport {
        tool: "nigel-synthesis",
        version: env!("CARGO_PKG_VERSION"),
        objective: req.objective.name(),
        plant: PlantReport::new(spec, [poly.bw[(0, 0)], poly.bw[(1, 0)]], poly.vertices.len()),
        region: region.parts.clone(),
        region_description: region.describe(),
        margin: req.options.margin,
        gamma_meaning: "bound on the induced L2 gain (H-inf norm) from w = F_sw to z = [beta, r, u], not squared",
        gamma_star,
        pareto,
        chosen,
        k: full_gain(spec.architecture, &design.gain),
        k_rows: WHEEL_NAMES,
        k_columns: ["beta", "r"],
        x: [[x[(0, 0)], x[(0, 1)]], [x[(1, 0)], x[(1, 1)]]],
        vertices: v.vertices.clone(),
        actual: ActualNorms::of(&v),
        verification: VerificationSummary::of(&v, req.verify.seed),
        solver: SolverSummary::of(&all_stats, gamma_star_stats, &design.stats, req.options.margin),
        timings: Timings { design_s, verification_s, total_s: t0.elapsed().as_secs_f64() },
        baseline,
    })
}

impl PlantReport {
    /// The design model `spec` with its disturbance column `bw = [d1, d2]`.
    fn new(spec: &PlantSpec, bw: [f64; 2], n_vertices: usize) -> PlantReport {
        PlantReport {
            architecture: spec.architecture,
            d2: spec.disturbance.name(),
            speed: spec.speed,
            mu_min: spec.mu_min,
            mu_max: spec.mu_max,
            m: spec.params.m,
            i_z: spec.params.i_z,
            l_f: spec.params.l_f,
            l_r: spec.params.l_r,
            track: spec.params.track,
            cornering_stiffness: spec.params.c,
            bw,
            n_vertices,
            steered_wheels: spec.architecture.steered_wheels().iter().map(|&w| WHEEL_NAMES[w]).collect(),
        }
    }

    fn architecture_name(&self) -> &'static str {
        self.architecture.name()
    }
}

/// The grid of a Pareto sweep as the report lists it; appends the statistics of every
/// solve (the `gamma*` solve first, then each solved grid point) to `all_stats`.
fn pareto_entries(sweep: &ParetoSweep, all_stats: &mut Vec<SolverStats>) -> Vec<ParetoEntry> {
    all_stats.push(sweep.hinf_optimum.stats.clone());
    sweep
        .points
        .iter()
        .map(|p| {
            let stats = p.result.as_ref().ok().map(|d| d.stats.clone());
            all_stats.extend(stats.iter().cloned());
            ParetoEntry {
                k: p.k,
                g: p.g,
                nu: p.nu(),
                distance: p.distance(),
                error: p.result.as_ref().err().map(|e| e.to_string()),
                solver: stats,
            }
        })
        .collect()
}

impl ActualNorms {
    /// The certified bounds and worst actual norms of a verification (vertices and
    /// interior points).
    fn of(v: &VerificationReport) -> ActualNorms {
        let all = || v.vertices.iter().chain(v.interior.iter());
        ActualNorms {
            hinf_bound: v.gamma_bound,
            hinf_worst: v.worst_hinf,
            hinf_worst_sweep: all().map(|p| p.hinf_sweep).fold(0.0, f64::max),
            h2_bound: v.nu_bound,
            h2_worst: v.worst_h2,
            h2_worst_integrated: all().map(|p| p.h2_integrated).fold(0.0, f64::max),
            hinf_methods_rel_diff: v.hinf_methods_rel_diff,
            h2_methods_rel_diff: v.h2_methods_rel_diff,
        }
    }
}

impl VerificationSummary {
    /// The verdicts of a verification whose interior points came from `seed`.
    fn of(v: &VerificationReport, seed: u64) -> VerificationSummary {
        VerificationSummary {
            passed: v.passed(),
            all_stable: v.all_stable,
            poles_in_region: v.poles_in_region,
            hinf_within_bound: v.hinf_within_bound,
            h2_within_bound: v.h2_within_bound,
            worst_region_margin: v.worst_region_margin,
            max_real_part: v.max_real_part,
            interior_points: v.interior.len(),
            seed,
        }
    }
}

impl SolverSummary {
    /// Totals over `all_stats`; `margin` is the strictness margin the LMIs were posed with.
    fn of(
        all_stats: &[SolverStats],
        gamma_star: Option<SolverStats>,
        design: &SolverStats,
        margin: f64,
    ) -> SolverSummary {
        let max_violation = all_stats.iter().map(|s| s.max_constraint_violation).fold(0.0, f64::max);
        let mut statuses: Vec<String> = all_stats.iter().map(|s| s.status.clone()).collect();
        statuses.sort();
        statuses.dedup();
        SolverSummary {
            solver: "clarabel 0.11",
            n_solves: all_stats.len(),
            total_iterations: all_stats.iter().map(|s| s.iterations as u64).sum(),
            total_solve_time_s: all_stats.iter().map(|s| s.solve_time_s).sum(),
            statuses,
            gamma_star,
            design: design.clone(),
            max_constraint_violation: max_violation,
            strict_lmis_hold: max_violation < margin,
        }
    }
}

/// The Pareto grid table, the chosen point marked.
fn write_pareto(s: &mut String, pareto: &[ParetoEntry], chosen: Option<usize>) {
    let _ = writeln!(s, "\n   k        g        nu   sqrt(g^2+nu^2)  iters");
    for e in pareto {
        let mark = if Some(e.k) == chosen { "  <- chosen" } else { "" };
        match &e.error {
            None => {
                let _ = writeln!(
                    s,
                    "  {:2}  {:.5}  {:.5}  {:.6}        {:3}{mark}",
                    e.k,
                    e.g,
                    e.nu.unwrap_or(f64::NAN),
                    e.distance.unwrap_or(f64::NAN),
                    e.solver.as_ref().map_or(0, |s| s.iterations)
                );
            }
            Some(err) => {
                let _ = writeln!(s, "  {:2}  {:.5}  failed: {err}", e.k, e.g);
            }
        }
    }
}

/// `chosen: k = .., g = .., nu = ..`.
fn write_chosen(s: &mut String, c: &ChosenPoint) {
    let _ = writeln!(
        s,
        "\nchosen: k = {}, g = {}, nu = {}",
        c.k.map_or("-".to_string(), |k| k.to_string()),
        opt(c.g, 5),
        opt(c.nu, 5)
    );
}

/// The verdict, the H-inf and H2 norms against their bounds and the poles (against the
/// region unless `region_imposed` is false).
fn write_verification(s: &mut String, a: &ActualNorms, v: &VerificationSummary, region_imposed: bool) {
    let _ = writeln!(
        s,
        "\nverification (16 vertices + {} interior points, seed {:#x}): {}",
        v.interior_points,
        v.seed,
        if v.passed { "PASSED" } else { "FAILED" }
    );
    let _ = writeln!(
        s,
        "  H-inf: certified bound {}, actual worst {:.6} (Hamiltonian) / {:.6} (frequency sweep), rel. diff {:.1e}{}",
        opt(a.hinf_bound, 6),
        a.hinf_worst,
        a.hinf_worst_sweep,
        a.hinf_methods_rel_diff,
        if v.hinf_within_bound { "" } else { "  EXCEEDS BOUND" }
    );
    let _ = writeln!(
        s,
        "  H2:    certified bound {}, actual worst {:.6} (Lyapunov) / {:.6} (Gramian integration), rel. diff {:.1e}{}",
        opt(a.h2_bound, 6),
        a.h2_worst,
        a.h2_worst_integrated,
        a.h2_methods_rel_diff,
        if v.h2_within_bound { "" } else { "  EXCEEDS BOUND" }
    );
    if region_imposed {
        let _ = writeln!(
            s,
            "  poles: max real part {:.4}, smallest margin inside the region {:.4}{}",
            v.max_real_part,
            v.worst_region_margin,
            if v.poles_in_region { "" } else { "  OUTSIDE THE REGION" }
        );
    } else {
        let _ = writeln!(s, "  poles: max real part {:.4} (no pole region imposed)", v.max_real_part);
    }
}

/// The solver totals line.
fn write_solver(s: &mut String, r: &SolverSummary) {
    let _ = writeln!(
        s,
        "\nsolver: {} solves, {} iterations, {:.3} s in clarabel, statuses {:?}, max constraint violation {:.1e} ({})",
        r.n_solves,
        r.total_iterations,
        r.total_solve_time_s,
        r.statuses,
        r.max_constraint_violation,
        if r.strict_lmis_hold { "< margin: the strict LMIs hold" } else { "NOT below the margin" }
    );
}

fn opt(v: Option<f64>, prec: usize) -> String {
    v.map_or("-".to_string(), |x| format!("{x:.prec$}"))
}

/// The readable table the CLI prints.
pub fn render_text(r: &SynthesisReport) -> String {
    let mut s = String::new();
    let p = &r.plant;
    let _ = writeln!(
        s,
        "nigel-synthesis: {} {}, d2 = {} (d = [{:.5}, {:.5}]), v = {} m/s, mu in [{}, {}], {} vertices",
        p.architecture_name(),
        r.objective,
        p.d2,
        p.bw[0],
        p.bw[1],
        p.speed,
        p.mu_min,
        p.mu_max,
        p.n_vertices
    );
    let _ = writeln!(s, "pole region: {}", r.region_description);
    let _ = writeln!(s, "strictness margin eps = {:e}; gamma = {}", r.margin, r.gamma_meaning);
    if let Some(g) = r.gamma_star {
        let _ = writeln!(s, "gamma* = {g:.6}");
    }
    if !r.pareto.is_empty() {
        write_pareto(&mut s, &r.pareto, r.chosen.k);
    }
    write_chosen(&mut s, &r.chosen);
    let _ = writeln!(s, "\nK (u = K [beta; r]):        beta           r");
    for (name, row) in r.k_rows.iter().zip(&r.k) {
        let _ = writeln!(s, "  {name}               {:>12.6} {:>12.6}", row[0], row[1]);
    }
    write_verification(&mut s, &r.actual, &r.verification, !r.region.is_empty());
    if let Some(b) = &r.baseline {
        let _ = writeln!(
            s,
            "  baseline (Re(s) < {} at mu = {}): {} all 16 vertices (max real part {:.4})",
            b.alpha,
            b.mu_nominal,
            if b.stabilises_all_vertices { "stabilises" } else { "does NOT stabilise" },
            b.max_real_part_over_vertices
        );
    }
    write_solver(&mut s, &r.solver);
    let _ = writeln!(
        s,
        "time: design {:.3} s, verification {:.3} s, total {:.3} s",
        r.timings.design_s, r.timings.verification_s, r.timings.total_s
    );
    s
}

/// A tracking-design request (the `synthesize --model tracking` run).
#[derive(Clone, Debug, PartialEq)]
pub struct TrackingRequest {
    /// The tracking design model.
    pub spec: TrackingSpec,
    /// The pole region ([`tracking_region`] by default).
    pub region: PoleRegion,
    /// Margin and solver settings.
    pub options: SynthesisOptions,
    /// Verification settings.
    pub verify: VerifyOptions,
    /// Threads for the Pareto grid (0 = all cores).
    pub threads: usize,
}

impl Default for TrackingRequest {
    fn default() -> Self {
        TrackingRequest {
            spec: TrackingSpec::default_design(),
            region: tracking_region(),
            options: SynthesisOptions::default(),
            verify: VerifyOptions::default(),
            threads: 0,
        }
    }
}

/// The linear closed-loop figures of the tracking gain at the 16 vertices (worst case).
#[derive(Clone, Debug, Serialize)]
pub struct TrackingStudy {
    /// Step of lateral force (wind) for the first figure \[N\].
    pub wind_step_force: f64,
    /// Response to that step from zero error, 10 s.
    pub wind_step: ResponsePeaks,
    /// Initial lateral offset of the second figure \[m\] (2 cm, the study's criterion).
    pub offset: f64,
    /// Recovery from that offset, no wind, 2 s.
    pub offset_recovery: ResponsePeaks,
    /// Steering servo time constant inserted for the servo check \[s\].
    pub servo_time_constant: f64,
    /// Largest real part of the closed loop with the servo inserted, over the vertices.
    pub servo_loop_max_real_part: f64,
}

/// Everything a tracking run produced (what `synthesize --model tracking --json` writes).
#[derive(Clone, Debug, Serialize)]
pub struct TrackingReport {
    /// Producer (`nigel-synthesis`).
    pub tool: &'static str,
    /// Crate version.
    pub version: &'static str,
    /// `tracking`.
    pub model: &'static str,
    /// `pareto`.
    pub objective: &'static str,
    /// The vehicle and friction box (`bw` here is `[d1, d2]`, the last two rows of `B_w`).
    pub plant: PlantReport,
    /// `B_w` of the tracking model, `[0, 0, d1, d2]`.
    pub bw_tracking: [f64; 4],
    /// The output weights `z = [q_y e_y; q_psi e_psi; r_u u]`.
    pub weights: TrackingWeights,
    /// How to apply `K`.
    pub control_law: &'static str,
    /// The sign conventions of the errors.
    pub sign_conventions: &'static str,
    /// The pole region (intersection of these parts).
    pub region: Vec<Region>,
    /// The region in words.
    pub region_description: String,
    /// Strictness margin `eps`.
    pub margin: f64,
    /// What `gamma`/`g` means.
    pub gamma_meaning: &'static str,
    /// `gamma*`.
    pub gamma_star: f64,
    /// The Pareto grid.
    pub pareto: Vec<ParetoEntry>,
    /// The chosen point.
    pub chosen: ChosenPoint,
    /// `K_track`, 4 rows (FL, FR, RL, RR) x 4 columns; rows of unsteered wheels are 0.
    #[serde(rename = "K")]
    pub k: [[f64; 4]; 4],
    /// Row names of `K`.
    #[serde(rename = "K_rows")]
    pub k_rows: [&'static str; 4],
    /// Column names of `K` (the states).
    #[serde(rename = "K_columns")]
    pub k_columns: [&'static str; 4],
    /// The Lyapunov matrix `X` (4x4).
    #[serde(rename = "X")]
    pub x: Vec<Vec<f64>>,
    /// Closed-loop poles and norms at the 16 vertices.
    pub vertices: Vec<PointCheck>,
    /// Certified bounds and actual worst-case norms.
    pub actual: ActualNorms,
    /// The independent verification.
    pub verification: VerificationSummary,
    /// The linear closed-loop figures.
    pub study: TrackingStudy,
    /// Solver totals (over every solve of the sweep, including the grid points next to the
    /// feasibility boundary, which the solver may return with reduced accuracy).
    pub solver: SolverSummary,
    /// Worst constraint violation of the chosen design's own solve (checked by us).
    pub design_max_constraint_violation: f64,
    /// `design_max_constraint_violation < margin`: the chosen design satisfies its strict
    /// LMIs in floating point, so its certificate holds as stated.
    pub design_strict_lmis_hold: bool,
    /// Wall times (`design_s` includes the verification, `verification_s` is the linear study).
    pub timings: Timings,
}

/// The control law, as the report states it.
pub const TRACKING_CONTROL_LAW: &str =
    "delta = delta_ff + K e, e = [e_y, e_psi, beta - beta_ref, r - r_ref] of the car relative to the reference car \
     (nigel_vehicle::tracking_errors), delta_ff the reference car's steering; rows FL, FR, RL, RR; rad, m, rad/s";

/// The sign conventions, as the report states them.
pub const TRACKING_SIGN_CONVENTIONS: &str =
    "errors in the reference car's body frame (x forward, y left): e_y > 0 car left of the reference [m]; \
     e_psi = psi - psi_ref wrapped to (-pi, pi] > 0 car turned counter-clockwise [rad]; beta = atan2(v_y, v_x); \
     steering angles positive counter-clockwise (to the left), as the plant";

/// Runs the tracking design, its verification and its linear study.
pub fn run_tracking(
    req: &TrackingRequest,
    progress: Option<&(dyn Fn(SweepProgress) + Sync)>,
) -> Result<TrackingReport, SynthesisError> {
    let t0 = Instant::now();
    req.region.validate()?;
    let d = design_tracking(&req.spec, &req.region, &req.options, &req.verify, req.threads, progress)?;
    tracking_report(req, &d, t0.elapsed().as_secs_f64())
}

/// The report of a finished tracking design `d` made from `req` (adds the linear study);
/// `design_s` is the wall time the design and its verification took.
pub fn tracking_report(
    req: &TrackingRequest,
    d: &TrackingDesign,
    design_s: f64,
) -> Result<TrackingReport, SynthesisError> {
    let poly = req.spec.polytope()?;
    let chosen_design =
        d.sweep.chosen_design().ok_or_else(|| SynthesisError::Invalid("chosen point has no design".into()))?;
    let gain = &chosen_design.gain;
    let t1 = Instant::now();
    let v = &d.verification;
    // the study's common criterion (see crate::tracking): recovery from a 2 cm offset
    let offset = 0.02;
    let study = TrackingStudy {
        wind_step_force: 0.25,
        wind_step: wind_step(&poly, gain, 0.25, 10.0),
        offset,
        offset_recovery: offset_recovery(&poly, gain, offset, 2.0),
        servo_time_constant: req.spec.plant.params.servo_time_constant,
        servo_loop_max_real_part: servo_loop_max_real_part(&poly, gain, req.spec.plant.params.servo_time_constant),
    };
    let verification_s = t1.elapsed().as_secs_f64();
    let mut all_stats = Vec::new();
    let pareto = pareto_entries(&d.sweep, &mut all_stats);
    let spec = &req.spec.plant;
    let x = &chosen_design.lyapunov;
    Ok(TrackingReport {
        tool: "nigel-synthesis",
        version: env!("CARGO_PKG_VERSION"),
        model: "tracking",
        objective: "pareto",
        plant: PlantReport::new(spec, [poly.bw[(2, 0)], poly.bw[(3, 0)]], poly.vertices.len()),
        bw_tracking: [poly.bw[(0, 0)], poly.bw[(1, 0)], poly.bw[(2, 0)], poly.bw[(3, 0)]],
        weights: req.spec.weights,
        control_law: TRACKING_CONTROL_LAW,
        sign_conventions: TRACKING_SIGN_CONVENTIONS,
        region: req.region.parts.clone(),
        region_description: req.region.describe(),
        margin: req.options.margin,
        gamma_meaning:
            "bound on the induced L2 gain (H-inf norm) from w = F_sw [N] to z = [q_y e_y, q_psi e_psi, r_u u], \
                        not squared",
        gamma_star: d.sweep.gamma_star(),
        pareto,
        chosen: ChosenPoint { k: Some(d.sweep.chosen_point().k), g: Some(d.gamma), nu: Some(d.nu) },
        k: d.k_track,
        k_rows: WHEEL_NAMES,
        k_columns: nigel_vehicle::TRACKING_STATE_NAMES,
        x: (0..x.nrows()).map(|i| (0..x.ncols()).map(|j| x[(i, j)]).collect()).collect(),
        vertices: v.vertices.clone(),
        actual: ActualNorms::of(v),
        verification: VerificationSummary::of(v, req.verify.seed),
        study,
        solver: SolverSummary::of(
            &all_stats,
            Some(d.sweep.hinf_optimum.stats.clone()),
            &chosen_design.stats,
            req.options.margin,
        ),
        design_max_constraint_violation: chosen_design.stats.max_constraint_violation,
        design_strict_lmis_hold: chosen_design.stats.max_constraint_violation < req.options.margin,
        timings: Timings { design_s, verification_s, total_s: design_s + verification_s },
    })
}

/// The readable table `synthesize --model tracking` prints.
pub fn render_tracking_text(r: &TrackingReport) -> String {
    let mut s = String::new();
    let p = &r.plant;
    let w = &r.weights;
    let _ = writeln!(
        s,
        "nigel-synthesis: tracking model [e_y, e_psi, beta - beta_ref, r - r_ref], {} pareto, d2 = {} \
         (B_w = [0, 0, {:.5}, {:.5}]), v = {} m/s, mu in [{}, {}], {} vertices",
        p.architecture_name(),
        p.d2,
        r.bw_tracking[2],
        r.bw_tracking[3],
        p.speed,
        p.mu_min,
        p.mu_max,
        p.n_vertices
    );
    let _ = writeln!(
        s,
        "weights: z = [{:.4} e_y; {:.4} e_psi; {:.4} u] (allowances {:.4} m, {:.4} rad, {:.4} rad)",
        w.lateral,
        w.heading,
        w.steering,
        1.0 / w.lateral,
        1.0 / w.heading,
        1.0 / w.steering
    );
    let _ = writeln!(s, "pole region: {}", r.region_description);
    let _ = writeln!(s, "strictness margin eps = {:e}; gamma = {}", r.margin, r.gamma_meaning);
    let _ = writeln!(s, "gamma* = {:.6}", r.gamma_star);
    write_pareto(&mut s, &r.pareto, r.chosen.k);
    write_chosen(&mut s, &r.chosen);
    let _ = writeln!(s, "\nK_track (delta = delta_ff + K e):  e_y [rad/m]  e_psi [-]  e_beta [-]  e_r [s]");
    for (name, row) in r.k_rows.iter().zip(&r.k) {
        let _ = writeln!(s, "  {name}  {:>12.6} {:>12.6} {:>12.6} {:>12.6}", row[0], row[1], row[2], row[3]);
    }
    let _ = writeln!(s, "  signs: {}", r.sign_conventions);
    write_verification(&mut s, &r.actual, &r.verification, !r.region.is_empty());
    let st = &r.study;
    let _ = writeln!(
        s,
        "\nlinear study (worst of the 16 vertices):\n  {} N wind step: e_y peak {:.5} m, after 10 s {:.5} m, e_psi peak {:.5} rad, \
         steering peak {:.4} rad, rate peak {:.4} rad/s",
        st.wind_step_force,
        st.wind_step.lateral_peak,
        st.wind_step.lateral_final,
        st.wind_step.heading_peak,
        st.wind_step.steering_peak,
        st.wind_step.steering_rate_peak
    );
    let _ = writeln!(
        s,
        "  {} m lateral offset: steering peak {:.4} rad, rate peak {:.4} rad/s, e_y after 2 s {:.5} m",
        st.offset,
        st.offset_recovery.steering_peak,
        st.offset_recovery.steering_rate_peak,
        st.offset_recovery.lateral_final
    );
    let _ = writeln!(
        s,
        "  with the {} s steering servo in the loop: max real part {:.4}",
        st.servo_time_constant, st.servo_loop_max_real_part
    );
    write_solver(&mut s, &r.solver);
    let _ = writeln!(
        s,
        "chosen design: max constraint violation {:.1e} ({})",
        r.design_max_constraint_violation,
        if r.design_strict_lmis_hold { "< margin: its strict LMIs hold" } else { "NOT below the margin" }
    );
    let _ = writeln!(
        s,
        "time: design and verification {:.3} s, linear study {:.3} s, total {:.3} s",
        r.timings.design_s, r.timings.verification_s, r.timings.total_s
    );
    s
}
