//! Campaigns that survive bad runs: worker processes over a C FMU that misbehaves on
//! purpose (cosim/tests/cfmu/crash.c: its parameter `mode` makes `fmi2DoStep` at t >= 0.5 s
//! segfault, abort, call `exit(0)` or never return). Every good run completes with its
//! exact row, each bad one is its own row with the reason, the exit status says so
//! (`--allow-failures` accepts it), a stop time past the test bench's end is refused before
//! the first run, and the workers leave nothing in TMPDIR.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

use nigel_campaign::results::{read_rows, Target, STATUS_CRASHED, STATUS_OK, STATUS_TIMEOUT};
use nigel_campaign::run::{run, Options, Workers};
use nigel_campaign::spec::Spec;

const CAMPAIGN: &str = env!("CARGO_BIN_EXE_campaign");

mod common;
use common::{campaign_run, root, target_dir, write_spec};

/// crash.c compiled with the system `cc` and zipped with crash.xml as `<dir>/crash.fmu`.
fn build_crash(dir: &Path) -> PathBuf {
    build_c_fmu(dir, "crash")
}

/// `<id>.c` of cosim/tests/cfmu (crash.c, or ctor.c: crash.c whose library segfaults while
/// it is loaded) with crash.xml as `<dir>/<id>.fmu`.
fn build_c_fmu(dir: &Path, id: &str) -> PathBuf {
    let cfmu = root().join("cosim/tests/cfmu");
    let so = dir.join(format!("{id}.so"));
    let status = Command::new("cc")
        .args(["-shared", "-fPIC", "-O2", "-fvisibility=hidden", "-Wno-unused-parameter"])
        .arg(cfmu.join(format!("{id}.c")))
        .arg("-o")
        .arg(&so)
        .status()
        .expect("run cc");
    assert!(status.success(), "cc failed for crash.c");
    let fmu = dir.join(format!("{id}.fmu"));
    let xml = std::fs::read_to_string(cfmu.join("crash.xml")).unwrap().replace("\"crash\"", &format!("{id:?}"));
    let mut zip = zip::ZipWriter::new(std::fs::File::create(&fmu).unwrap());
    let options = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    for (name, bytes) in [
        ("modelDescription.xml".to_string(), xml.into_bytes()),
        (format!("binaries/linux64/{id}.so"), std::fs::read(&so).unwrap()),
    ] {
        zip.start_file(name, options).unwrap();
        zip.write_all(&bytes).unwrap();
    }
    zip.finish().unwrap();
    fmu
}

/// The modes of the runs: 0 behaves, 1 segfault, 2 abort, 4 exit(0), 5 never returns.
const MODES: [u32; 9] = [0, 1, 0, 5, 4, 0, 2, 0, 0];

/// A campaign of 1 s runs (steps of 0.1 s) over crash.fmu, one run per mode, a 1 s timeout.
fn crash_campaign(dir: &Path) -> PathBuf {
    let fmu = build_crash(dir);
    let modes: Vec<String> = MODES.iter().map(|m| format!("{m}.0")).collect();
    let path = dir.join("crash.toml");
    let rest = format!(
        "stop_time = 1.0\nstep = 0.1\ntimeout = 1.0\n[grid]\n\"model.mode\" = [{}]\n[metrics]\ny = \"final(model.y)\"\n",
        modes.join(", ")
    );
    write_spec(&path, &fmu, &rest);
    path
}

fn campaign(args: &[&str], tmp: &Path) -> std::process::Output {
    Command::new(CAMPAIGN).args(args).env("TMPDIR", tmp).output().unwrap()
}

#[test]
fn crashed_exited_and_hung_runs_are_their_rows_and_every_other_run_completes() {
    let dir = tempfile::tempdir().unwrap();
    let spec_path = crash_campaign(dir.path());
    let out = dir.path().join("out");
    let tmp = dir.path().join("tmp");
    std::fs::create_dir(&tmp).unwrap();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let o = campaign(&["run", &s(&spec_path), "--out", &s(&out), "--threads", "2"], &tmp);
    let stderr = String::from_utf8_lossy(&o.stderr);
    // 3: the campaign completed and runs failed
    assert_eq!(o.status.code(), Some(3), "{stderr}");
    let summary = stderr.lines().find(|l| l.contains("runs, ")).unwrap_or_else(|| panic!("{stderr}"));
    assert!(summary.starts_with("campaign: 9 runs, 4 failed (3 crashed, 1 timed out): run 1 crashed ("), "{summary}");
    assert!(summary.contains("exit status 3 (--allow-failures to accept)"), "{summary}");
    let spec = Spec::load(&spec_path).unwrap();
    let rows = read_rows(&Target::whole(&out), &spec, false).unwrap();
    assert_eq!(rows.iter().map(|r| r.run).collect::<Vec<_>>(), (0..9).collect::<Vec<u64>>());
    // a good run's y is the time its last step reached, computed as the master and the FMU
    // compute it: t = t0 + n h for n = 9, then y = t + h (the same f64 operations: exact)
    let y_end = 9.0f64 * 0.1 + 0.1;
    for (r, mode) in rows.iter().zip(MODES) {
        assert_eq!(r.values[0], mode as f64, "run {}", r.run);
        let expect = match mode {
            0 => (STATUS_OK, ""),
            1 => (STATUS_CRASHED, "was killed by signal 11 (SIGSEGV) during fmi2DoStep of model at t = 0.5 s"),
            2 => (STATUS_CRASHED, "was killed by signal 6 (SIGABRT) during fmi2DoStep of model at t = 0.5 s"),
            // exit(0) inside a call: the worker's atexit handler (nigel_cosim's exit_guard)
            // ends it with status 1, whatever status the FMU gave
            4 => (STATUS_CRASHED, "exited with code 1 during fmi2DoStep of model at t = 0.5 s"),
            5 => (STATUS_TIMEOUT, "timeout of 1 s (fmi2DoStep of model at t = 0.5 s did not return)"),
            _ => unreachable!(),
        };
        assert_eq!(r.status, expect.0, "run {}: {}", r.run, r.message);
        assert!(r.message.contains(expect.1), "run {}: {}", r.run, r.message);
        if mode == 0 {
            assert_eq!(r.values[1], y_end, "run {}", r.run);
        } else {
            assert!(r.values[1].is_nan(), "run {}", r.run);
        }
    }
    // the workers removed their unpacked FMUs, and the killed ones' were removed for them
    let left: Vec<_> = std::fs::read_dir(&tmp).unwrap().map(|e| e.unwrap().path()).collect();
    assert!(left.is_empty(), "left in TMPDIR: {left:?}");

    // the same rows accepted deliberately: exit 0, the summary still printed
    let o = campaign(&["run", &s(&spec_path), "--out", &s(&out), "--resume", "--allow-failures"], &tmp);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{stderr}");
    assert!(stderr.contains("9 runs, 4 failed") && stderr.contains("accepted (--allow-failures)"), "{stderr}");
}

#[test]
fn a_stop_time_past_the_test_bench_is_refused_before_the_first_run() {
    let dir = tempfile::tempdir().unwrap();
    let ssp = target_dir().join("ssp").join("nigel_closed_loop.ssp");
    // the test bench's reference ends at duration = 30 s (its default); 31 s is past it
    let text = format!(
        "system = {:?}\nstop_time = 31.0\nstep = 1e-3\nsamples = 2\n[random]\n\"plant.m\" = {{ uniform = [2.4, 3.0] }}\n[metrics]\ny = \"final(plant.y)\"\n",
        ssp.display().to_string()
    );
    let path = dir.path().join("long.toml");
    std::fs::write(&path, text).unwrap();
    let spec = Spec::load(&path).unwrap();
    let out = dir.path().join("out");
    for workers in [Workers::Threads, Workers::Processes(CAMPAIGN.into())] {
        let e = run(&spec, &Options { progress: false, workers: workers.clone(), ..Options::new(out.clone()) })
            .unwrap_err()
            .to_string();
        assert!(e.contains("stop_time = 31 s is past what the system can run: maneuver refuses it"), "{e}");
        assert!(e.contains("duration") && e.contains("nothing ran") && !e.contains('\n'), "{e}");
        assert_eq!(std::fs::read_to_string(out.join("results.csv")).unwrap().lines().count(), 1, "{workers:?}");
    }
    // run anyway: every run is a failed row naming the cause, and the exit status says so
    let o = campaign_run(&path, &out).output().unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", String::from_utf8_lossy(&o.stderr));
    let o = campaign_run(&path, &out).args(["--allow-failures", "--resume"]).output().unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{stderr}");
    assert!(stderr.contains("warning: stop_time = 31 s is past"), "{stderr}");
    let rows = read_rows(&Target::whole(&out), &spec, false).unwrap();
    assert_eq!(rows.len(), 2);
    assert!(rows.iter().all(|r| r.status == 1 && r.message.contains("stopTime")), "{rows:?}");
}

#[test]
fn process_workers_write_the_rows_threads_write() {
    let dir = tempfile::tempdir().unwrap();
    let ssp = target_dir().join("ssp").join("nigel_closed_loop.ssp");
    let text = std::fs::read_to_string(root().join("campaigns/example.toml"))
        .unwrap()
        .replace("system = \"target/ssp/nigel_closed_loop.ssp\"", &format!("system = {:?}", ssp.display().to_string()))
        .replace("stop_time = 30.0", "stop_time = 0.2")
        .replace("samples = 20 ", "samples = 3 ");
    let path = dir.path().join("small.toml");
    std::fs::write(&path, text).unwrap();
    let spec = Spec::load(&path).unwrap();
    let mut files = Vec::new();
    for (k, workers) in [Workers::Threads, Workers::Processes(CAMPAIGN.into())].into_iter().enumerate() {
        let out = dir.path().join(format!("w{k}"));
        let done =
            run(&spec, &Options { progress: false, threads: Some(2), workers, ..Options::new(out.clone()) }).unwrap();
        assert_eq!((done.ran, done.failed, done.restarts), (12, 0, 0));
        files.push(std::fs::read(out.join("results.csv")).unwrap());
    }
    // the rows cross the pipe as text in shortest round-trip form: bit for bit
    assert_eq!(files[0], files[1]);
}

#[test]
fn a_library_that_crashes_while_loading_is_one_line_and_not_a_crash_of_the_campaign() {
    let dir = tempfile::tempdir().unwrap();
    let fmu = build_c_fmu(dir.path(), "ctor");
    let path = dir.path().join("ctor.toml");
    write_spec(
        &path,
        &fmu,
        "stop_time = 1.0\nstep = 0.1\n[grid]\n\"model.mode\" = [0.0, 1.0]\n[metrics]\ny = \"final(model.y)\"\n",
    );
    // the description is checked without loading the library; the worker that loads it dies
    let tmp = dir.path().join("tmp");
    std::fs::create_dir(&tmp).unwrap();
    let out = dir.path().join("out");
    let o = campaign(&["run", path.to_str().unwrap(), "--out", out.to_str().unwrap()], &tmp);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    let last = stderr.lines().last().unwrap_or("");
    assert!(
        last.starts_with("campaign: a worker process was killed by signal 11 (SIGSEGV) while loading "),
        "{stderr}"
    );
    let left: Vec<_> = std::fs::read_dir(&tmp).unwrap().map(|e| e.unwrap().path()).collect();
    assert!(left.is_empty(), "left in TMPDIR: {left:?}");
}
