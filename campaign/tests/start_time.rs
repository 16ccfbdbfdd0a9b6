//! A campaign starts its runs at the SSD's `DefaultExperiment` `startTime`, as `cosim run`
//! does (SSP 1.0: the experiment's start when the user gives none).

use nigel_campaign::results::STATUS_OK;
use nigel_campaign::run::Worker;
use nigel_campaign::spec::Spec;

#[path = "../../cosim/tests/common/mod.rs"]
mod cfmu;
use cfmu::{build_fmu, work_dir, Model};

const SSD: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription" version="1.0" name="t">
<ssd:System name="top">
  <ssd:Elements><ssd:Component name="src" source="source.fmu"/></ssd:Elements>
</ssd:System><ssd:DefaultExperiment startTime="2" stopTime="3"/></ssd:SystemStructureDescription>"#;

#[test]
fn runs_start_at_the_ssds_start_time() {
    let dir = work_dir("campaign-start");
    // the C source FMU: y = slope * t (slope 1 unless set)
    build_fmu(Model::Source, &dir, &[]);
    std::fs::write(dir.join("sys.ssd"), SSD).unwrap();
    let toml = dir.join("start.toml");
    std::fs::write(
        &toml,
        "system = \"sys.ssd\"\nstop_time = 3.0\nstep = 0.25\n[grid]\n\"src.slope\" = [1.0, 2.0]\n\
         [metrics]\ny_final = \"final(src.y)\"\ny_min = \"min(src.y)\"\ny_mean = \"mean(src.y)\"\n",
    )
    .unwrap();
    let spec = Spec::load(&toml).unwrap();
    assert_eq!(spec.start_time, 2.0);
    let mut worker = Worker::new(&spec).unwrap();
    // the metrics see t_1 .. t_N = 2.25, 2.5, 2.75, 3 (from the SSD's start 2 s, not 0):
    // slope 1: final 3, min 2.25, mean (2.25 + 2.5 + 2.75 + 3) / 4 = 2.625;
    // slope 2: twice each. Every value and sum here is a short binary fraction: exact.
    for (run, slope) in [(0u64, 1.0), (1, 2.0)] {
        let row = worker.run(run);
        assert_eq!(row.status, STATUS_OK, "{}", row.message);
        assert_eq!(row.values, [slope, 3.0 * slope, 2.25 * slope, 2.625 * slope], "run {run}");
    }
    // a stop time before the start time + one step is refused naming the SSD's start time
    std::fs::write(&toml, "system = \"sys.ssd\"\nstop_time = 2.1\nstep = 0.25\n").unwrap();
    let e = Spec::load(&toml).unwrap_err().to_string();
    assert!(e.contains("start time 2 s (the SSD's DefaultExperiment)"), "{e}");
}
