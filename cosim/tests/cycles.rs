//! 1000 load / run / drop cycles of a system with the plant and two C FMUs: no growth in
//! open files or resident memory, no temporary folder left. (Alone in its test binary so
//! that nothing else opens files meanwhile.)

mod common;
use common::{build_fmu, plant_fmu, work_dir, Model};
use nigel_cosim::{simulate, Algorithm, Experiment, Fmu, SystemBuilder};

fn open_files() -> usize {
    std::fs::read_dir("/proc/self/fd").map(|d| d.count()).unwrap_or(0)
}

fn resident_kib() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .unwrap_or(0)
}

fn cycle(plant: &std::path::Path, source: &std::path::Path, gain: &std::path::Path) {
    let mut b = SystemBuilder::new();
    b.add_instance("plant", Fmu::load(plant).unwrap()).unwrap();
    b.add_instance("src", Fmu::load(source).unwrap()).unwrap();
    b.add_instance("k", Fmu::load(gain).unwrap()).unwrap();
    b.connect("src.y", "k.u").unwrap();
    b.connect("k.y", "plant.mu_fl").unwrap(); // unitless input: no unit check
    b.set_text("k.k", "0.1").unwrap();
    b.set_text("plant.v_x_start", "0.3").unwrap();
    let mut e = Experiment::new(0.05, 1e-3);
    e.algorithm = Algorithm::Ordered;
    e.record = Some(vec!["plant.mu_fl".into(), "plant.x".into()]);
    let (r, _) = simulate(&b.build(), &e).unwrap();
    assert_eq!(r.rows(), 51);
    // mu_fl = 0.1 t, no delay in ordered mode
    let d = r.column("plant.mu_fl").unwrap();
    let t = r.column("time").unwrap();
    assert!((d[50] - 0.1 * t[50]).abs() < 1e-15, "{} vs {}", d[50], 0.1 * t[50]);
}

#[test]
fn thousand_load_run_drop_cycles_do_not_grow() {
    let dir = work_dir("cycles");
    let tmp = dir.join("tmp");
    std::fs::create_dir_all(&tmp).unwrap();
    std::env::set_var("TMPDIR", &tmp);
    let (plant, source, gain) = (plant_fmu(), build_fmu(Model::Source, &dir, &[]), build_fmu(Model::Gain, &dir, &[]));
    for _ in 0..20 {
        cycle(&plant, &source, &gain); // warm up allocator and loader caches
    }
    let (files, rss) = (open_files(), resident_kib());
    for _ in 0..1000 {
        cycle(&plant, &source, &gain);
    }
    let (files_after, rss_after) = (open_files(), resident_kib());
    eprintln!("open files {files} -> {files_after}, resident {rss} KiB -> {rss_after} KiB");
    assert_eq!(files_after, files, "open files grew");
    assert!(rss_after < rss + 2048, "resident memory grew from {rss} KiB to {rss_after} KiB");
    assert_eq!(std::fs::read_dir(&tmp).unwrap().count(), 0, "temporary folders left behind");
}
