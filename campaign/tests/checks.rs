//! A campaign's `[checks]`: a run whose check fails is a failed run (status 6) with the
//! check, its value and the threshold in its message, its metrics unchanged; `campaign run
//! --junit / --summary-md` make a test case per run. Two runs of the closed loop, 2 s, that
//! differ in their initial speed; the threshold is put between their final `plant.x`
//! (taken from a first campaign without checks), so exactly the slower one fails.

use std::path::{Path, PathBuf};
use std::process::Command;

use nigel_campaign::results::{Target, STATUS_CHECK_FAILED, STATUS_OK};
use nigel_campaign::run::{run, Options};
use nigel_campaign::spec::Spec;

mod common;
use common::target_dir;

const CAMPAIGN: &str = env!("CARGO_BIN_EXE_campaign");

fn spec(dir: &Path, name: &str, checks: &str) -> PathBuf {
    let ssp = target_dir().join("ssp").join("nigel_closed_loop.ssp");
    assert!(ssp.is_file(), "{} missing: run `cargo run --release -p build-fmu` first", ssp.display());
    let text = format!(
        "system = {:?}\nstop_time = 2.0\nstep = 0.001\n\n[grid]\n\"plant.v_x_start\" = [0.2, 0.35]\n\n[metrics]\nx_final = \"final(plant.x)\"\n{checks}",
        ssp.display().to_string()
    );
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn a_failed_check_fails_its_run_with_the_value_and_the_junit_file_says_so() {
    let dir = target_dir().join("test-campaign-checks");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let plain = Spec::load(&spec(&dir, "plain", "")).unwrap();
    let options = Options { progress: false, ..Options::new(dir.join("plain-out")) };
    let done = run(&plain, &options).unwrap();
    let x: Vec<f64> = done.rows.iter().map(|r| r.values[1]).collect();
    assert!(done.rows.iter().all(|r| r.status == STATUS_OK) && x[0] != x[1], "{x:?}");
    // the run that got less far (the speed controller makes 0.2 m/s overshoot: run 1)
    let (low, high) = if x[0] < x[1] { (0, 1) } else { (1, 0) };
    let threshold = 0.5 * (x[0] + x[1]);
    let checked = spec(&dir, "checked", &format!("\n[checks]\nfar = \"final(plant.x) > {threshold:?}\"\n"));
    let (out, junit, md) = (dir.join("checked-out"), dir.join("junit.xml"), dir.join("summary.md"));
    let o = Command::new(CAMPAIGN)
        .args(["run", checked.to_str().unwrap(), "--out", out.to_str().unwrap(), "--threads", "2"])
        .args(["--junit", junit.to_str().unwrap(), "--summary-md", md.to_str().unwrap()])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(3), "{stderr}");
    let spec = Spec::load(&checked).unwrap();
    let rows = nigel_campaign::results::read_rows(&Target::whole(&out), &spec, false).unwrap();
    let mut want = [STATUS_OK; 2];
    want[low] = STATUS_CHECK_FAILED;
    assert_eq!(rows.iter().map(|r| r.status).collect::<Vec<_>>(), want);
    // the metrics are those of the run without checks, bit for bit
    assert_eq!(rows.iter().map(|r| r.values[1]).collect::<Vec<_>>(), x);
    let message = format!("check far: final(plant.x) > {threshold:?} fails: {} > {threshold:?} is false", x[low]);
    let messages = std::fs::read_to_string(out.join("messages.csv")).unwrap();
    assert!(messages.contains(&message), "{messages}");
    assert!(stderr.contains(&format!("2 runs, 1 failed (1 failed a check): run {low} failed a check")), "{stderr}");
    let xml = std::fs::read_to_string(&junit).unwrap();
    assert!(xml.contains("tests=\"2\" failures=\"1\" errors=\"0\""), "{xml}");
    let speed = ["0.2", "0.35"];
    assert!(xml.contains(&format!(
        "<testcase classname=\"campaign.checked\" name=\"run {low} (plant.v_x_start = {})\">\n      <failure message=\"failed a check: {}\"",
        speed[low],
        message.replace('>', "&gt;")
    )), "{xml}");
    assert!(xml.contains(&format!(
        "<testcase classname=\"campaign.checked\" name=\"run {high} (plant.v_x_start = {})\">\n      <system-out>x_final = {}</system-out>",
        speed[high],
        x[high]
    )), "{xml}");
    let md = std::fs::read_to_string(&md).unwrap();
    assert!(md.contains("FAILED (2 tests, 1 failed, 0 errors)"), "{md}");
}
