//! A structural parameter as a campaign's sweep dimension: the C FMU
//! `cosim/tests/cfmu/fmi3_sized.c` (n sizes k and y, set in Configuration Mode; y[i] =
//! k[i] u t after each step, k all 1 and u = 1 by default) swept over n = 1, 2, 3. Each run
//! configures its own instance and records y with n elements: the run's CSV (`--only`)
//! has the columns y[1] .. y[n], each 1 at 1 s (k[i] u t = 1 * 1 * 1); the metric
//! final(model.y[1]) is 1 in every run.

#[path = "../../cosim/tests/common/mod.rs"]
#[allow(dead_code, unused_imports)]
mod cosim_common;

mod common;
use common::{campaign_run, write_spec};
use std::path::{Path, PathBuf};

/// The description of the C FMU (shared with cosim's Configuration Mode tests).
const XML: &str = include_str!("../../cosim/tests/cfmu/fmi3_sized.xml");

/// `fmi3_sized.fmu` built in `dir`; `None` (skipped) without fmpy's FMI 3.0 headers.
fn sized_fmu(dir: &Path) -> Option<PathBuf> {
    cosim_common::fmi3_c::build(dir, "fmi3_sized", XML)
}

#[test]
fn a_structural_parameter_is_a_sweep_dimension_and_sizes_each_runs_arrays() {
    let dir = tempfile::tempdir().unwrap();
    let Some(fmu) = sized_fmu(dir.path()) else { return };
    let spec = dir.path().join("sized.toml");
    // n = 1, 2, 3: the sweep; y[1] exists in every run
    let sweep =
        "stop_time = 1.0\nstep = 0.5\n\n[grid]\n\"model.n\" = [1, 2, 3]\n\n[metrics]\ny1 = \"final(model.y[1])\"\n";
    write_spec(&spec, &fmu, sweep);
    let out = dir.path().join("out");
    let o = campaign_run(&spec, &out).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let spec_loaded = nigel_campaign::spec::Spec::load(&spec).unwrap();
    let mut worker = nigel_campaign::run::Worker::new(&spec_loaded).unwrap();
    for run in 0..3u64 {
        let n = run as usize + 1;
        let row = worker.run(run);
        assert_eq!(row.status, nigel_campaign::results::STATUS_OK, "run {run}: {:?}", row.message);
        assert_eq!(row.values, [n as f64, 1.0], "run {run}: n, then y1");
        // the run's every output: y with n elements
        let o = campaign_run(&spec, &out).args(["--only", &run.to_string()]).output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let text = std::fs::read_to_string(out.join(format!("run-{run}.csv"))).unwrap();
        let header: Vec<&str> = text.lines().next().unwrap().split(',').map(|h| h.trim_matches('"')).collect();
        let ys: Vec<String> = (1..=n).map(|i| format!("y[{i}]")).collect();
        assert_eq!(header[1..], ys, "run {run}");
        let last: Vec<f64> = text.lines().last().unwrap().split(',').map(|x| x.parse().unwrap()).collect();
        assert_eq!(last, [[1.0].as_slice(), &vec![1.0; n]].concat(), "run {run}: t = 1 s, y = k u t = 1");
    }
}
