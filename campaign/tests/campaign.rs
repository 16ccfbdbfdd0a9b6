//! The campaign against its contract: the documented example, run values independent of
//! threads and shards, merged shards equal to a local run byte for byte, `--resume` after
//! a killed run, metrics equal to those computed from `cosim run`'s CSV, epsilon equal to
//! table3's, and one-line errors naming the culprit.

use std::path::{Path, PathBuf};
use std::process::Command;

use nigel_campaign::results::{Target, STATUS_OK};
use nigel_campaign::run::{run, Options, Worker};
use nigel_campaign::spec::Spec;

mod common;
use common::{campaign_run, root, target_dir};
#[path = "../../cosim/tests/common/mod.rs"]
mod cosim_common;
use cosim_common::read_csv as read_cosim_csv;

fn ssp() -> PathBuf {
    target_dir().join("ssp").join("nigel_closed_loop.ssp")
}

const CAMPAIGN: &str = env!("CARGO_BIN_EXE_campaign");

/// The example's campaign with a shorter horizon (`stop` s) and `samples` draws, written
/// into `dir` (the system by absolute path).
fn small(dir: &Path, stop: f64, samples: u64) -> PathBuf {
    let text = std::fs::read_to_string(root().join("campaigns/example.toml")).unwrap();
    let text = text
        .replace(
            "system = \"target/ssp/nigel_closed_loop.ssp\"",
            &format!("system = {:?}", ssp().display().to_string()),
        )
        .replace("stop_time = 30.0", &format!("stop_time = {stop:?}"))
        .replace("samples = 20 ", &format!("samples = {samples} "));
    let path = dir.join("small.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn quiet(out: &Path) -> Options {
    Options { progress: false, ..Options::new(out.to_path_buf()) }
}

#[test]
fn the_example_is_accepted_as_written_and_its_first_run_runs() {
    // relative paths from the repository root
    std::env::set_current_dir(root()).unwrap();
    let spec = Spec::load("campaigns/example.toml".as_ref()).unwrap();
    assert_eq!(spec.runs(), 2 * 2 * 20);
    assert_eq!(
        spec.header(),
        [
            "run",
            "status",
            "message",
            "maneuver.maneuver",
            "controller.controller",
            "maneuver.seed",
            "plant.m",
            "epsilon",
            "y_final",
            "max_delta"
        ]
    );
    let mut worker = Worker::new(&spec).unwrap();
    let row = worker.run(0);
    assert_eq!((row.status, row.message.as_str()), (STATUS_OK, ""));
    // run 0: maneuver 2, controller 1 (open loop); its draws inside their ranges
    assert_eq!(&row.values[..2], &[2.0, 1.0]);
    assert!((0.0..=1000.0).contains(&row.values[2]) && row.values[2].fract() == 0.0);
    assert!((2.4..3.0).contains(&row.values[3]));
    // open loop: the front-left steering is the feed-forward alone, whose largest value on
    // the lane change is the program's amplitude pi / 6 (maneuvers.md; as f64 the quotient
    // of the rounded pi, one ulp below the correctly rounded FRAC_PI_6); epsilon of the open
    // loop on the lane change is a few centimetres (Table III: 0.05 .. 0.06)
    assert_eq!(row.values[6], std::f64::consts::PI / 6.0);
    assert!((0.03..0.1).contains(&row.values[4]), "{}", row.values[4]);
}

#[test]
fn run_values_depend_only_on_seed_and_run() {
    let dir = tempfile::tempdir().unwrap();
    let spec = Spec::load(&small(dir.path(), 0.1, 7)).unwrap();
    let all: Vec<_> = (0..spec.runs()).map(|i| spec.values(i)).collect();
    // in reverse order, and from a second parse of the description
    let again = Spec::load(&small(dir.path(), 0.1, 7)).unwrap();
    for i in (0..spec.runs()).rev() {
        assert_eq!(again.values(i), all[i as usize]);
    }
    // the grid: first key slowest, the last fastest; samples innermost
    assert_eq!(all[0].numbers[..2], [2.0, 1.0]);
    assert_eq!(all[7].numbers[..2], [2.0, 3.0]);
    assert_eq!(all[14].numbers[..2], [3.0, 1.0]);
    // draws differ between the samples of a grid point; every grid point gets the same
    // draws for its sample s (common random numbers)
    assert_ne!(all[0].numbers[3], all[1].numbers[3]);
    for i in 0..spec.runs() as usize {
        assert_eq!(all[i].numbers[2..], all[i % 7].numbers[2..]);
    }
    // another seed, other draws
    let text = std::fs::read_to_string(dir.path().join("small.toml")).unwrap().replace("seed = 1 ", "seed = 2 ");
    std::fs::write(dir.path().join("seed2.toml"), text).unwrap();
    let other = Spec::load(&dir.path().join("seed2.toml")).unwrap();
    assert_ne!(other.values(0).numbers[3], all[0].numbers[3]);

    // every thread count and every shard split writes the same rows
    let one = dir.path().join("one");
    run(&spec, &Options { threads: Some(1), ..quiet(&one) }).unwrap();
    let reference = std::fs::read(one.join("results.csv")).unwrap();
    for threads in [2, 3] {
        let out = dir.path().join(format!("t{threads}"));
        run(&spec, &Options { threads: Some(threads), ..quiet(&out) }).unwrap();
        assert_eq!(std::fs::read(out.join("results.csv")).unwrap(), reference, "{threads} threads");
    }
    for count in [3u64, 5] {
        let out = dir.path().join(format!("s{count}"));
        // shards in reverse order, each with 2 threads
        for i in (0..count).rev() {
            run(&spec, &Options { shard: Some((i, count)), threads: Some(2), ..quiet(&out) }).unwrap();
        }
        let m = nigel_campaign::merge::merge(&out, &spec).unwrap();
        assert_eq!((m.shards, m.runs), (count as usize, spec.runs()));
        assert_eq!(std::fs::read(out.join("results.csv")).unwrap(), reference, "merged {count} shards");
    }
}

/// `campaign run SPEC --out OUT --threads 1` in the background, with a TMPDIR of its own
/// (`OUT.tmp`, returned) and standard error piped.
fn spawn_campaign(spec: &Path, out: &Path) -> (std::process::Child, PathBuf) {
    let tmp = out.with_extension("tmp");
    std::fs::create_dir(&tmp).unwrap();
    let child = Command::new(CAMPAIGN)
        .arg("run")
        .arg(spec)
        .arg("--out")
        .arg(out)
        .args(["--threads", "1"])
        .env("TMPDIR", &tmp)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    (child, tmp)
}

/// Whether the folder `tmp` is empty within 10 s.
fn tmp_empties(tmp: &Path) -> bool {
    let start = std::time::Instant::now();
    while start.elapsed() < std::time::Duration::from_secs(10) {
        if std::fs::read_dir(tmp).unwrap().count() == 0 {
            return true;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    false
}

/// Waits until `results.csv` in `out` holds `rows` rows; fails (killing the child) when the
/// campaign ends before that or writes none within two minutes (a full disk, say), so that a
/// test never waits forever.
fn wait_for_rows(child: &mut std::process::Child, out: &Path, rows: usize) {
    let start = std::time::Instant::now();
    while rows_in(out) < rows {
        if let Some(status) = child.try_wait().unwrap() {
            let mut stderr = String::new();
            if let Some(mut e) = child.stderr.take() {
                use std::io::Read;
                let _ = e.read_to_string(&mut stderr);
            }
            panic!("the campaign ended ({status}) before it wrote {rows} rows: {stderr}");
        }
        if start.elapsed() > std::time::Duration::from_secs(120) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("the campaign wrote {} of {rows} rows within 120 s", rows_in(out));
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
}

/// The rows `results.csv` in `out` holds so far.
fn rows_in(out: &Path) -> usize {
    std::fs::read_to_string(out.join("results.csv")).map_or(0, |t| t.lines().count().saturating_sub(1))
}

#[test]
fn resume_after_a_killed_run_completes_it() {
    let dir = tempfile::tempdir().unwrap();
    let spec_path = small(dir.path(), 3.0, 10);
    let spec = Spec::load(&spec_path).unwrap();
    let local = dir.path().join("local");
    run(&spec, &quiet(&local)).unwrap();
    let out = dir.path().join("killed");
    let (mut child, _tmp) = spawn_campaign(&spec_path, &out);
    let rows = out.join("results.csv");
    let count = || rows_in(&out);
    wait_for_rows(&mut child, &out, 3);
    child.kill().unwrap();
    child.wait().unwrap();
    // SIGKILL of the campaign ends its worker processes too (SIGTERM to each, which
    // removes what it unpacked)
    assert!(
        tmp_empties(&_tmp),
        "a worker process outlived the campaign: {:?}",
        std::fs::read_dir(&_tmp).unwrap().map(|e| e.unwrap().path()).collect::<Vec<_>>()
    );
    let kept = count();
    assert!((3..40).contains(&kept), "{kept} rows when killed");
    // without --resume the folder is refused, naming what to do
    let e = run(&spec, &quiet(&out)).unwrap_err().to_string();
    assert!(e.contains("already holds") && e.contains("--resume"), "{e}");
    let done = run(&spec, &Options { resume: true, ..quiet(&out) }).unwrap();
    assert_eq!(done.kept + done.ran, 40);
    assert!(done.kept >= kept as u64 - 1 && done.ran > 0);
    assert_eq!(std::fs::read(&rows).unwrap(), std::fs::read(local.join("results.csv")).unwrap());
}

#[test]
fn metrics_equal_those_of_cosim_runs_csv() {
    let dir = tempfile::tempdir().unwrap();
    let spec = Spec::load(&small(dir.path(), 4.0, 3)).unwrap();
    let mut worker = Worker::new(&spec).unwrap();
    let cosim = target_dir().join("release").join("cosim");
    assert!(cosim.exists(), "{} (cargo build --release -p nigel-cosim)", cosim.display());
    for i in [1u64, 10] {
        let row = worker.run(i);
        let values = spec.values(i);
        let csv = dir.path().join(format!("cosim-{i}.csv"));
        let mut cmd = Command::new(&cosim);
        cmd.arg("run")
            .arg(ssp())
            .args(["--stop-time", "4", "--step", "1e-3", "--algorithm", "ordered", "--output"])
            .arg(&csv);
        for (var, x) in &values.assignments {
            let text = match x {
                nigel_campaign::spec::Scalar::Real(v) => format!("{v:?}"),
                nigel_campaign::spec::Scalar::Integer(v) => v.to_string(),
                nigel_campaign::spec::Scalar::Boolean(v) => v.to_string(),
            };
            cmd.arg("--set").arg(format!("{var}={text}"));
        }
        let st = cmd.status().unwrap();
        assert!(st.success());
        let (names, rows) = read_cosim_csv(&csv);
        let col = |n: &str| -> Vec<f64> {
            let j = names.iter().position(|x| x == n).unwrap();
            rows.iter().map(|r| r[j]).collect()
        };
        // t_1 .. t_N: every row but the first
        let n = rows.len() - 1;
        assert_eq!(n, 4000);
        let rms_diff = |a: &[f64], b: &[f64]| ((1..=n).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>() / n as f64).sqrt();
        let eps = [("plant.x", "maneuver.x_ref"), ("plant.y", "maneuver.y_ref"), ("plant.psi", "maneuver.psi_ref")]
            .iter()
            .map(|(a, b)| rms_diff(&col(a), &col(b)).powi(2))
            .sum::<f64>()
            .sqrt();
        let y_final = col("plant.y")[n];
        let max_delta = col("controller.delta_fl")[1..].iter().fold(0.0f64, |m, d| m.max(d.abs()));
        // the CSV holds every value in shortest round-trip form, and both sums run over
        // k = 1 .. N in the same order: equal to the last bit on any machine
        assert_eq!(row.values[4..], [eps, y_final, max_delta], "run {i}");
    }
}

#[test]
fn epsilon_equals_table3_for_the_same_seed_maneuver_and_controller() {
    use nigel_table3::{Controller, Engine, Fidelity, FmuEngine, Job, Maneuver, Metric};
    let dir = tempfile::tempdir().unwrap();
    let engine = FmuEngine::load_dir(&target_dir().join("fmu")).unwrap();
    // the description's variables as table3 sets them: maneuver 2 = lane_change,
    // 3 = skidpad; controller 3 = robust, 1 = open loop; seeds 0 and 7
    let text = format!(
        r#"system = {:?}
stop_time = 30.0
step = 1e-3
[grid]
"maneuver.maneuver" = [2, 3]
"controller.controller" = [3, 1]
"maneuver.seed" = [0, 7]
[metrics]
epsilon = "norm(rms_diff(plant.x, maneuver.x_ref), rms_diff(plant.y, maneuver.y_ref), rms_diff(plant.psi, maneuver.psi_ref))"
max_delta = "max_abs(controller.delta_fl)"
"#,
        ssp().display().to_string()
    );
    let path = dir.path().join("eps.toml");
    std::fs::write(&path, text).unwrap();
    let spec = Spec::load(&path).unwrap();
    let mut worker = Worker::new(&spec).unwrap();
    for (i, (maneuver, controller, seed)) in [
        (Maneuver::LaneChange, Controller::Robust, 0),
        (Maneuver::LaneChange, Controller::Robust, 7),
        (Maneuver::LaneChange, Controller::OpenLoop, 0),
        (Maneuver::Skidpad, Controller::Robust, 7),
    ]
    .into_iter()
    .enumerate()
    {
        let run_index = [0u64, 1, 2, 5][i];
        let row = worker.run(run_index);
        let job = Job::new(seed, Fidelity::Paper, maneuver, controller);
        let metric = Metric::of(&engine.run(&job).unwrap());
        // the same FMUs, the same master and the same sums in the same order: bit for bit
        assert_eq!(row.values[3], metric.eps, "{}", job.label());
    }
}

fn load_err(dir: &Path, name: &str, text: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, text.replace("SSP", &ssp().display().to_string())).unwrap();
    Spec::load(&path).unwrap_err().to_string()
}

#[test]
fn bad_input_is_a_one_line_error_naming_the_culprit() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let head = "system = \"SSP\"\nstop_time = 1.0\nstep = 1e-3\n";
    let cases = [
        ("[random]\n\"plant.mass\" = { uniform = [2.4, 3.0] }\n", "unknown variable plant.mass"),
        ("[grid]\n\"maneuver.maneuver\" = [2, 7]\n", "7 is outside maneuver.maneuver's declared range [1, 6]"),
        (
            "[random]\n\"maneuver.speed_target\" = { uniform = [0.2, 12.0] }\n",
            "[0.2, 12] is outside maneuver.speed_target's declared range [",
        ),
        (
            "[random]\n\"maneuver.seed\" = { uniform = [0, 10] }\n",
            "maneuver.seed is Integer, uniform (Real draws) cannot set it",
        ),
        ("[grid]\n\"plant.friction_circle\" = [1.5]\n", "plant.friction_circle is Boolean but the value is 1.5 (Real)"),
        ("[grid]\n\"maneuver.maneuver\" = [2.5]\n", "maneuver.maneuver is Integer but the value is 2.5 (Real)"),
        ("[metrics]\ne = \"rms_diff(plant.x maneuver.x_ref)\"\n", "[metrics] \"e\": malformed expression"),
        ("[metrics]\ne = \"rms(plant.speeed)\"\n", "[metrics] \"e\": unknown variable plant.speeed"),
        ("[random]\n\"plant.m\" = { triangular = [1, 2] }\n", "unknown key \"triangular\""),
        ("[random]\n\"maneuver.speed_target\" = { normal = [0.35, 0.1] }\n", "give the normal min / max inside it"),
    ];
    for (k, (body, want)) in cases.iter().enumerate() {
        let e = load_err(d, &format!("bad{k}.toml"), &format!("{head}{body}"));
        assert!(e.contains(want), "case {k}: {e}");
        assert!(!e.contains('\n'), "case {k} is not one line: {e}");
        assert!(e.contains(&format!("bad{k}.toml")), "case {k} does not name the file: {e}");
    }
    let e = load_err(d, "syntax.toml", "system = \"SSP\"\nstop_time = = 1\n");
    assert!(e.contains("syntax.toml") && !e.contains('\n'), "{e}");

    // shards: a missing one named with the command that completes it; a foreign one refused
    let spec_path = small(d, 0.05, 4);
    let spec = Spec::load(&spec_path).unwrap();
    let out = d.join("out");
    for i in [0, 2] {
        run(&spec, &Options { shard: Some((i, 3)), ..quiet(&out) }).unwrap();
    }
    let e = nigel_campaign::merge::merge(&out, &spec).unwrap_err().to_string();
    let block = spec.shard_range(1, 3);
    assert!(e.contains(&format!("{} of 16 runs missing: {}", block.end - block.start, block.start)), "{e}");
    assert!(e.contains("shard 1/3") && e.contains("--resume"), "{e}");
    // a shard of another description (another seed) copied in
    let other_path = d.join("other.toml");
    std::fs::write(&other_path, std::fs::read_to_string(&spec_path).unwrap().replace("seed = 1 ", "seed = 9 "))
        .unwrap();
    let other = Spec::load(&other_path).unwrap();
    let other_out = d.join("other");
    run(&other, &Options { shard: Some((1, 3)), ..quiet(&other_out) }).unwrap();
    for f in ["1-of-3.csv", "1-of-3.json", "1-of-3.messages.csv"] {
        std::fs::copy(other_out.join("shards").join(f), out.join("shards").join(f)).unwrap();
    }
    let e = nigel_campaign::merge::merge(&out, &spec).unwrap_err().to_string();
    assert!(e.contains("1-of-3.json is a shard of another description"), "{e}");
    // an output folder holding another campaign
    let e = run(&other, &quiet(&out)).unwrap_err().to_string();
    assert!(e.contains("holds another campaign") && e.contains("choose another --out"), "{e}");
    // the CLI prints the same line and fails
    let o = campaign_run(&other_path, &out).output().unwrap();
    assert!(!o.status.success());
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.starts_with("campaign: ") && stderr.contains("holds another campaign"), "{stderr}");
    let o = Command::new(CAMPAIGN).arg("run").arg(&spec_path).args(["--out", "x", "--shard", "3/3"]).output().unwrap();
    assert!(String::from_utf8_lossy(&o.stderr).contains("--shard 3/3: expected I/N with 0 <= I < N"));
}

/// Writes the spec `text` of three runs to `path` and runs it into `out`: all three ran,
/// `failed` of them failed; the rows.
fn run_three_of_which_fail(path: &Path, text: &str, out: &Path, failed: u64) -> Vec<nigel_campaign::results::Row> {
    std::fs::write(path, text).unwrap();
    let spec = Spec::load(path).unwrap();
    let done = run(&spec, &quiet(out)).unwrap();
    assert_eq!((done.ran, done.failed), (3, failed));
    nigel_campaign::results::read_rows(&Target::whole(out), &spec, false).unwrap()
}

#[test]
fn a_failing_run_is_a_row_and_the_campaign_goes_on() {
    // a test bench whose reference ends at 0.02 s, before the stop time: the description
    // accepts the value (inside its declared range), the test bench refuses the run with a
    // message naming duration; the other runs complete
    let dir = tempfile::tempdir().unwrap();
    let text = format!(
        "system = {:?}\nstop_time = 0.05\nstep = 1e-3\n[grid]\n\"maneuver.duration\" = [30.0, 0.02, 30.0]\n[metrics]\ny = \"final(plant.y)\"\n",
        ssp().display().to_string()
    );
    let path = dir.path().join("fail.toml");
    let out = dir.path().join("out");
    let rows = run_three_of_which_fail(&path, &text, &out, 1);
    assert_eq!(rows.iter().map(|r| r.status).collect::<Vec<_>>(), [0, 1, 0]);
    assert!(rows[1].message.contains("duration"), "{}", rows[1].message);
    assert!(rows[1].values[1].is_nan() && rows[0].values[1].is_finite());
    let text = std::fs::read_to_string(out.join("results.csv")).unwrap();
    assert!(text.lines().nth(2).unwrap().starts_with("1,1,1,0.02,NaN"), "{text}");
    // a time limit no run can meet: every run fails with the master's timeout, none is lost
    let text = std::fs::read_to_string(&path).unwrap().replace("step = 1e-3\n", "step = 1e-3\ntimeout = 1e-9\n");
    let rows = run_three_of_which_fail(&path, &text, &dir.path().join("timeout"), 3);
    // status 5: timed out (the middle run may fail for its duration first, status 1)
    assert!(rows[0].status == 5 && rows[2].status == 5 && rows[1].status != 0, "{rows:?}");
    assert!(rows[0].message.contains("time limit") && rows[2].message.contains("time limit"), "{:?}", rows[0].message);
}

#[test]
fn only_prints_one_run_by_name_and_writes_its_every_output() {
    let dir = tempfile::tempdir().unwrap();
    let spec_path = small(dir.path(), 1.0, 2);
    let out = dir.path().join("out");
    let o = campaign_run(&spec_path, &out).args(["--only", "3"]).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8(o.stdout).unwrap();
    let lines: Vec<(&str, &str)> = text.lines().map(|l| l.split_once(" = ").unwrap()).collect();
    // the names right-aligned to one column
    let column = lines[0].0.len();
    assert!(lines.iter().all(|(name, _)| name.len() == column), "{text}");
    let field = |name: &str| lines.iter().find(|(n, _)| n.trim() == name).unwrap_or_else(|| panic!("{name}: {text}")).1;
    assert_eq!(field("run"), "3");
    assert_eq!(field("status"), "0 (ok)");
    // the printed numbers are the worker's row, bit for bit ({} of an f64 round-trips)
    let spec = Spec::load(&spec_path).unwrap();
    let row = Worker::new(&spec).unwrap().run(3);
    for (name, v) in spec.header().iter().skip(3).zip(&row.values) {
        assert_eq!(field(name).split(' ').next().unwrap().parse::<f64>().unwrap(), *v, "{name}");
    }
    let (header, rows) = read_cosim_csv(&out.join("run-3.csv"));
    assert_eq!(header[0], "time");
    assert_eq!(rows.len(), 1001, "1 s at 1 ms, both ends");
}

#[test]
fn sigterm_removes_the_unpacked_fmus_and_keeps_the_rows_written() {
    let dir = tempfile::tempdir().unwrap();
    let spec_path = small(dir.path(), 30.0, 10);
    let out = dir.path().join("stopped");
    let (mut child, tmp) = spawn_campaign(&spec_path, &out);
    let count = || rows_in(&out);
    wait_for_rows(&mut child, &out, 2);
    assert!(std::fs::read_dir(&tmp).unwrap().count() > 0, "the FMUs are unpacked while the campaign runs");
    let kill = Command::new("kill").args(["-TERM", &child.id().to_string()]).status().unwrap();
    assert!(kill.success());
    let o = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    // 128 + 15, as a shell reports a process ended by SIGTERM
    assert_eq!(o.status.code(), Some(143), "{stderr}");
    assert!(stderr.contains("campaign: stopped by SIGTERM; temporary folders removed"), "{stderr}");
    // the worker processes get SIGTERM as the campaign ends (PR_SET_PDEATHSIG) and remove
    // their own unpacked FMUs: within a few seconds on a loaded machine
    assert!(tmp_empties(&tmp), "TMPDIR left with unpacked FMUs");
    // the rows written before the signal are complete lines, and --resume completes the rest
    let kept = count();
    assert!(kept >= 2, "{kept}");
    let spec = Spec::load(&spec_path).unwrap();
    let done = run(&spec, &Options { resume: true, ..quiet(&out) }).unwrap();
    assert_eq!(done.kept + done.ran, 40);
}

#[test]
fn the_report_names_enumerated_values_and_draws_its_figures() {
    use nigel_campaign::report::{value_names, Axis, Report};
    let dir = tempfile::tempdir().unwrap();
    let spec = Spec::load(&small(dir.path(), 0.2, 2)).unwrap();
    let out = dir.path().join("out");
    run(&spec, &quiet(&out)).unwrap();
    // the names come from the controller FMU's and the test bench's model descriptions
    let system = nigel_campaign::spec::load_system(&ssp()).unwrap();
    let controller = value_names(&system, "controller.controller");
    assert_eq!(
        controller.values().map(String::as_str).collect::<Vec<_>>(),
        ["open_loop", "pole_placement", "robust", "custom", "robust_tracking"]
    );
    assert_eq!(controller.keys().copied().collect::<Vec<_>>(), [1, 2, 3, 4, 5]);
    assert_eq!(value_names(&system, "maneuver.maneuver").get(&2).map(String::as_str), Some("lane_change"));
    assert!(value_names(&system, "plant.m").is_empty() && value_names(&system, "maneuver.seed").is_empty());
    let by = ["maneuver.maneuver".to_string(), "controller.controller".to_string()];
    let report = Report::load(spec, &out, &by).unwrap();
    let legends: Vec<String> = report.cdf_series(0).into_iter().map(|(l, _)| l).collect();
    assert_eq!(
        legends,
        [
            "maneuver = lane_change, controller = open_loop",
            "maneuver = lane_change, controller = robust",
            "maneuver = skidpad, controller = open_loop",
            "maneuver = skidpad, controller = robust"
        ]
    );
    let json = report.json(0, 3);
    assert_eq!(json["groups"][1]["group"]["controller.controller"], "robust");
    // the random column of numbers keeps its name and numbers
    assert_eq!(report.legend_key(2), "maneuver.seed");
    assert_eq!(report.label(3, 2.5), "2.5");
    // epsilon over 0.2 s spans less than two decades here: a linear axis, padded
    let eps: Vec<f64> = report.cdf_series(0).into_iter().flat_map(|(_, v)| v).collect();
    let (lo, hi) = eps.iter().fold((f64::INFINITY, 0.0f64), |(a, b), x| (a.min(*x), b.max(*x)));
    match Axis::of(&eps) {
        Axis::Log(a, b) => assert!(hi / lo > 100.0 && a < lo && b > hi),
        Axis::Linear(a, b) => assert!(hi / lo <= 100.0 && a < lo && b > hi),
    }
    let pngs = report.pngs(0, &out.join("png")).unwrap();
    // the CDF and epsilon against the random column plant.m; none against maneuver.seed,
    // a noise seed, whose value orders nothing
    let names: Vec<String> = pngs.iter().map(|p| p.file_name().unwrap().to_string_lossy().into_owned()).collect();
    assert_eq!(names, ["cdf_epsilon.png", "epsilon_vs_plant_m.png"]);
    for p in &pngs {
        assert_eq!(&std::fs::read(p).unwrap()[..8], b"\x89PNG\r\n\x1a\n", "{}", p.display());
    }
}
