//! `synthesize`: robust mixed H2/H-inf state feedback for Nigel (thin CLI over
//! `nigel_synthesis`). Run with `--help` for the options.
//!
//! Exit codes: 0 = designed and verified; 1 = no design (infeasible, solver trouble,
//! refused parameters, I/O); 2 = bad command line; 3 = designed but the independent
//! verification failed.

use std::process::ExitCode;

use nigel_synthesis::report::{
    render_text, render_tracking_text, run, run_tracking, Objective, Request, TrackingRequest,
};
use nigel_synthesis::tracking::tracking_region;
use nigel_synthesis::{
    Architecture, DisturbanceVariant, PlantSpec, PoleRegion, Region, SweepProgress, SynthesisError, TrackingSpec,
    TrackingWeights,
};

const USAGE: &str = "\
synthesize: robust mixed H2/H-inf state feedback with D-stability over Nigel's
16-vertex friction polytope (paper Section IV), solved with clarabel and verified
independently (closed-loop poles, Hamiltonian/sweep H-inf, Lyapunov/Gramian H2).

USAGE: synthesize [OPTIONS]

Model:
  --model paper|tracking      paper (default): states [beta, r], z = [x; u] (the paper's
                              design). tracking: states [e_y, e_psi, beta - beta_ref,
                              r - r_ref], z = [e_y/A_y, e_psi/A_psi, u/A_u], Pareto objective
                              on a grid relative to gamma* (gamma* (1 + 0.05 k) up to
                              3 gamma*), default d2 physical, default region Re(s) < -0.5
                              and the 135-degree sector; K_track: delta = delta_ff + K e
  --tracking-allowances A_y,A_psi,A_u
                              tracking: allowed lateral error [m], heading error [rad]
                              and steering correction [rad] (default 0.02,0.1,0.1)
Plant:
  --arch 4ws|ackermann        steering architecture (default 4ws = 4WD4WS)
  --d2 paper|physical         disturbance column and geometry (default paper, tracking: physical;
                              d2 = (l_f - l_r)/2 as printed, l_r = 0.07924;
                              physical: d2 = (l_f - l_r)/(2 I_z), Table II)
  --speed V                   design speed [m/s] (default 0.35)
  --mu-min X, --mu-max X      friction box (default 0.1, 1.0)
Pole region (intersection; the default is Re(s) < -0.1 and the 135-degree sector):
  --half-plane A              add Re(s) < A
  --sector DEG                add a conic sector of inner angle DEG degrees at the origin
  --disk R[,C]                add the disk |s - C| < R (C defaults to 0)
  --no-default-region         drop the paper's default region
Objective:
  --objective pareto|hinf|h2|weighted|baseline   (default pareto)
  --hinf-bound G              h2: also require gamma <= G
  --weight-hinf A, --weight-h2 B                 weighted: min A gamma^2 + B nu^2 (default 1, 1)
  --baseline-alpha A, --baseline-mu M            baseline: Re(s) < A at mu = M (default -2, 0.4)
  --step S, --g-max G         Pareto grid (default 0.01, 0.5)
  --margin EPS                strictness margin of the LMIs (default 1e-7)
  --threads N                 threads for the Pareto grid (default: all cores)
Verification:
  --interior N                random interior points (default 64)
  --seed S                    their seed (default 0x5eed0f4157)
Output:
  --json PATH                 write the full report as JSON
  --plot PATH                 write an SVG figure (Pareto curve, pole map, zoom) and its PNG next to it
  --quiet                     no progress lines on stderr
  -h, --help                  this text

gamma is the bound on the induced L2 gain from w = F_sw to z = [beta, r, u].
Exit codes: 0 ok, 1 no design, 2 bad command line, 3 verification failed.
";

enum Job {
    Paper(Request),
    Tracking(TrackingRequest),
}

struct Cli {
    job: Job,
    json: Option<String>,
    plot: Option<String>,
    quiet: bool,
}

fn parse_f64(opt: &str, v: &str) -> Result<f64, String> {
    let x: f64 = v.trim().parse().map_err(|_| format!("{opt}: '{v}' is not a number"))?;
    if !x.is_finite() {
        return Err(format!("{opt}: '{v}' must be finite"));
    }
    Ok(x)
}

fn parse_args(args: &[String]) -> Result<Option<Cli>, String> {
    let mut arch = Architecture::FourWheelSteering;
    let mut d2 = None;
    let mut tracking = false;
    let mut allowances = None;
    let mut objective_given = false;
    let mut grid_given = false;
    let mut speed = None;
    let mut mu_min = None;
    let mut mu_max = None;
    let mut extra_regions = Vec::new();
    let mut default_region = true;
    let mut objective = "pareto".to_string();
    let mut hinf_bound = None;
    let (mut w_hinf, mut w_h2) = (1.0, 1.0);
    let (mut b_alpha, mut b_mu) = (-2.0, 0.4);
    let mut request = Request::paper(arch);
    let mut json = None;
    let mut plot = None;
    let mut quiet = false;
    let mut i = 0;
    while i < args.len() {
        let a = args[i].as_str();
        // accept --opt=value as well as --opt value
        let (name, inline) = match a.split_once('=') {
            Some((n, v)) if n.starts_with("--") => (n, Some(v.to_string())),
            _ => (a, None),
        };
        const FLAGS: [&str; 4] = ["--no-default-region", "--quiet", "-h", "--help"];
        const WITH_VALUE: [&str; 24] = [
            "--model",
            "--tracking-allowances",
            "--arch",
            "--d2",
            "--speed",
            "--mu-min",
            "--mu-max",
            "--half-plane",
            "--sector",
            "--disk",
            "--objective",
            "--hinf-bound",
            "--weight-hinf",
            "--weight-h2",
            "--baseline-alpha",
            "--baseline-mu",
            "--step",
            "--g-max",
            "--margin",
            "--threads",
            "--interior",
            "--seed",
            "--json",
            "--plot",
        ];
        if !FLAGS.contains(&name) && !WITH_VALUE.contains(&name) {
            return Err(format!("unknown option '{a}'"));
        }
        let takes_value = WITH_VALUE.contains(&name);
        let value = if takes_value {
            match inline {
                Some(v) => v,
                None => {
                    i += 1;
                    args.get(i).cloned().ok_or_else(|| format!("{name} needs a value"))?
                }
            }
        } else {
            if inline.is_some() {
                return Err(format!("{name} takes no value"));
            }
            String::new()
        };
        let v = value.as_str();
        match name {
            "-h" | "--help" => return Ok(None),
            "--model" => {
                tracking = match v {
                    "paper" => false,
                    "tracking" => true,
                    _ => return Err(format!("--model: '{v}' is not one of paper, tracking")),
                }
            }
            "--tracking-allowances" => {
                let parts: Vec<&str> = v.split(',').collect();
                if parts.len() != 3 {
                    return Err(format!("--tracking-allowances: '{v}' is not three numbers A_y,A_psi,A_u"));
                }
                let mut a = [0.0; 3];
                for (slot, part) in a.iter_mut().zip(&parts) {
                    *slot = parse_f64(name, part)?;
                    if *slot <= 0.0 {
                        return Err(format!("--tracking-allowances: '{part}' must be > 0"));
                    }
                }
                allowances = Some(a);
            }
            "--arch" => {
                arch = match v.to_ascii_lowercase().as_str() {
                    "4ws" | "4wd4ws" => Architecture::FourWheelSteering,
                    "ackermann" => Architecture::Ackermann,
                    _ => return Err(format!("--arch: '{v}' is not one of 4ws, ackermann")),
                }
            }
            "--d2" => {
                d2 = Some(match v {
                    "paper" => DisturbanceVariant::Paper,
                    "physical" => DisturbanceVariant::Physical,
                    _ => return Err(format!("--d2: '{v}' is not one of paper, physical")),
                })
            }
            "--speed" => speed = Some(parse_f64(name, v)?),
            "--mu-min" => mu_min = Some(parse_f64(name, v)?),
            "--mu-max" => mu_max = Some(parse_f64(name, v)?),
            "--half-plane" => extra_regions.push(Region::half_plane(parse_f64(name, v)?)),
            "--sector" => extra_regions.push(Region::sector_inner_angle_deg(parse_f64(name, v)?)),
            "--disk" => {
                let (r, c) = match v.split_once(',') {
                    Some((r, c)) => (parse_f64(name, r)?, parse_f64(name, c)?),
                    None => (parse_f64(name, v)?, 0.0),
                };
                extra_regions.push(Region::disk(c, r));
            }
            "--no-default-region" => default_region = false,
            "--objective" => {
                if !matches!(v, "pareto" | "hinf" | "h2" | "weighted" | "baseline") {
                    return Err(format!("--objective: '{v}' is not one of pareto, hinf, h2, weighted, baseline"));
                }
                objective = v.to_string();
                objective_given = true;
            }
            "--hinf-bound" => hinf_bound = Some(parse_f64(name, v)?),
            "--weight-hinf" => w_hinf = parse_f64(name, v)?,
            "--weight-h2" => w_h2 = parse_f64(name, v)?,
            "--baseline-alpha" => b_alpha = parse_f64(name, v)?,
            "--baseline-mu" => b_mu = parse_f64(name, v)?,
            "--step" => {
                request.sweep.step = parse_f64(name, v)?;
                grid_given = true;
            }
            "--g-max" => {
                request.sweep.g_max = parse_f64(name, v)?;
                grid_given = true;
            }
            "--margin" => request.options.margin = parse_f64(name, v)?,
            "--threads" => request.sweep.threads = v.parse().map_err(|_| format!("--threads: '{v}' is not a count"))?,
            "--interior" => {
                request.verify.interior_points = v.parse().map_err(|_| format!("--interior: '{v}' is not a count"))?
            }
            "--seed" => {
                request.verify.seed = match v.strip_prefix("0x") {
                    Some(hex) => u64::from_str_radix(hex, 16),
                    None => v.parse(),
                }
                .map_err(|_| format!("--seed: '{v}' is not an integer"))?
            }
            "--json" => json = Some(value.clone()),
            "--plot" => {
                if !v.to_ascii_lowercase().ends_with(".svg") {
                    return Err(format!("--plot: '{v}': only SVG output is supported (use a .svg name)"));
                }
                plot = Some(value.clone())
            }
            "--quiet" => quiet = true,
            _ => return Err(format!("unknown option '{a}'")),
        }
        i += 1;
    }
    let default_d2 = if tracking { DisturbanceVariant::Physical } else { DisturbanceVariant::Paper };
    let mut spec = PlantSpec::with_variant(arch, d2.unwrap_or(default_d2));
    if let Some(s) = speed {
        spec.speed = s;
    }
    if let Some(m) = mu_min {
        spec.mu_min = m;
    }
    if let Some(m) = mu_max {
        spec.mu_max = m;
    }
    let default = if tracking { tracking_region() } else { PoleRegion::paper() };
    let mut region = if default_region { default } else { PoleRegion::none() };
    region.parts.extend(extra_regions);
    if tracking {
        if objective_given && objective != "pareto" {
            return Err(format!(
                "--objective {objective}: the tracking model is designed with the Pareto objective only"
            ));
        }
        if grid_given {
            return Err("--step/--g-max: the tracking grid is relative to gamma* (see --help)".into());
        }
        let weights =
            allowances.map_or_else(TrackingWeights::chosen, |a| TrackingWeights::from_allowances(a[0], a[1], a[2]));
        let req = TrackingRequest {
            spec: TrackingSpec { plant: spec, weights },
            region,
            options: request.options,
            verify: request.verify,
            threads: request.sweep.threads,
        };
        return Ok(Some(Cli { job: Job::Tracking(req), json, plot, quiet }));
    }
    if allowances.is_some() {
        return Err("--tracking-allowances needs --model tracking".into());
    }
    request.spec = spec;
    request.region = region;
    request.objective = match objective.as_str() {
        "hinf" => Objective::Hinf,
        "h2" => Objective::H2 { hinf_bound },
        "weighted" => Objective::Weighted { weight_hinf: w_hinf, weight_h2: w_h2 },
        "baseline" => Objective::Baseline { mu_nominal: b_mu, alpha: b_alpha },
        _ => Objective::Pareto,
    };
    Ok(Some(Cli { job: Job::Paper(request), json, plot, quiet }))
}

fn write_json<T: serde::Serialize>(path: &str, report: &T) -> Result<(), String> {
    let text = serde_json::to_string_pretty(report).map_err(|e| format!("cannot serialise the report: {e}"))?;
    std::fs::write(path, text + "\n").map_err(|e| format!("cannot write {path}: {e}"))?;
    println!("wrote {path}");
    Ok(())
}

/// Prints the report of a design (`text`) and writes its JSON and its figure (`svg`) where
/// the command line asks; the report, or exit code 1 when there is no design or a file
/// cannot be written.
fn deliver<R: serde::Serialize>(
    cli: &Cli,
    designed: Result<R, SynthesisError>,
    text: fn(&R) -> String,
    svg: fn(&R) -> String,
) -> Result<R, ExitCode> {
    let report = designed.map_err(|e| {
        eprintln!("synthesize: no controller: {e}");
        ExitCode::from(1)
    })?;
    print!("{}", text(&report));
    let json = cli.json.as_ref().map_or(Ok(()), |path| write_json(path, &report));
    let figure = || cli.plot.as_ref().map_or(Ok(()), |path| write_figure(path, &svg(&report)));
    json.and_then(|()| figure()).map_err(|e| {
        eprintln!("synthesize: {e}");
        ExitCode::from(1)
    })?;
    Ok(report)
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let cli = match parse_args(&args) {
        Ok(Some(c)) => c,
        Ok(None) => {
            print!("{USAGE}");
            return ExitCode::SUCCESS;
        }
        Err(e) => {
            eprintln!("synthesize: {e}\n(run 'synthesize --help' for the options)");
            return ExitCode::from(2);
        }
    };
    let progress = |p: SweepProgress| {
        eprintln!(
            "  [{:>2}/{}] k = {:>2}  g = {:.5}  nu = {}",
            p.done,
            p.total,
            p.k,
            p.g,
            p.nu.map_or("failed".to_string(), |nu| format!("{nu:.5}"))
        );
    };
    let progress_ref: Option<&(dyn Fn(SweepProgress) + Sync)> = if cli.quiet { None } else { Some(&progress) };
    let passed = match &cli.job {
        Job::Paper(request) => {
            if !cli.quiet && request.objective == Objective::Pareto {
                eprintln!("synthesize: gamma*, then the Pareto grid ...");
            }
            let designed = run(request, progress_ref);
            match deliver(&cli, designed, render_text, nigel_synthesis::plot::render_svg) {
                Ok(report) => report.verification.passed,
                Err(code) => return code,
            }
        }
        Job::Tracking(request) => {
            if !cli.quiet {
                eprintln!("synthesize: tracking model: gamma*, then the Pareto grid ...");
            }
            let designed = run_tracking(request, progress_ref);
            match deliver(&cli, designed, render_tracking_text, nigel_synthesis::plot::render_tracking_svg) {
                Ok(report) => report.verification.passed,
                Err(code) => return code,
            }
        }
    };
    if !passed {
        eprintln!("synthesize: the independent verification FAILED (see above)");
        return ExitCode::from(3);
    }
    ExitCode::SUCCESS
}

/// Writes the SVG figure to `path` and its PNG next to it (`k.svg` -> `k.png`, 2 pixels per
/// SVG unit), and says so.
fn write_figure(path: &str, svg: &str) -> Result<(), String> {
    std::fs::write(path, svg).map_err(|e| format!("cannot write {path}: {e}"))?;
    println!("wrote {path}");
    let png_path = std::path::Path::new(path).with_extension("png");
    let png = nigel_synthesis::plot::render_png(svg, 2.0).map_err(|e| format!("{}: {e}", png_path.display()))?;
    std::fs::write(&png_path, png).map_err(|e| format!("cannot write {}: {e}", png_path.display()))?;
    println!("wrote {}", png_path.display());
    Ok(())
}
