//! `cosim run`'s arguments as the library's run preparation (`nigel_cosim::run_setup`) takes
//! them: each malformed one refused with exit status 1 and a message naming the option as
//! typed, and a single FMU's variables named bare or as `model.<name>` alike.

mod common;
use common::{plant_fmu, work_dir};
use std::process::Command;

/// (exit status, standard error) of `cosim run <plant> args`.
fn cosim_run(args: &[&str]) -> (Option<i32>, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_cosim")).arg("run").arg(plant_fmu()).args(args).output().unwrap();
    (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
}

#[test]
fn malformed_arguments_are_refused_by_their_option() {
    let refused = [
        (vec!["--interface", "xx"], "cosim: experiment: unknown interface \"xx\" (cs, me, se)\n"),
        (vec!["--set", "mu_fl"], "cosim: experiment: --set \"mu_fl\": expected NAME=VALUE\n"),
        (vec!["--set-at", "soon", "mu_fl=1"], "cosim: experiment: --set-at soon mu_fl=1: TIME is no number\n"),
        (vec!["--set-at", "1", "mu_fl"], "cosim: experiment: --set-at 1 mu_fl: expected NAME=VALUE\n"),
        (
            vec!["--check", "max(abs(nope)) < 1"],
            "cosim: --check \"max(abs(nope)) < 1\": instance \"model\" has no variable \"nope\" (`cosim info` lists \
             the variables)\n",
        ),
    ];
    for (args, message) in refused {
        assert_eq!(cosim_run(&args), (Some(1), message.to_string()), "cosim run {args:?}");
    }
    // a value set during the run is set by the stepping master in this process only
    #[cfg(target_os = "linux")]
    assert_eq!(
        cosim_run(&["--set-at", "1", "mu_fl=1", "--isolate"]),
        (
            Some(1),
            "cosim: experiment: --set-at is run in process by the stepping master (not with --isolate, not in \
             Scheduled Execution)\n"
                .to_string()
        )
    );
}

#[test]
fn a_single_fmus_variables_are_named_bare_or_qualified() {
    let dir = work_dir("run_arguments_names");
    let csv = dir.join("out.csv");
    // x qualified, y bare: both columns bare; the check's v_x is recorded for the check but
    // left out of the file (it was not asked for)
    let mut args: Vec<&str> = "--stop-time 0.002 --record model.x --record y".split(' ').collect();
    args.extend(["--check", "max(abs(v_x)) < 1", "--output", csv.to_str().unwrap()]);
    let (status, stderr) = cosim_run(&args);
    assert_eq!(status, Some(0), "{stderr}");
    let text = std::fs::read_to_string(&csv).unwrap();
    assert_eq!(text.lines().next(), Some("\"time\",\"x\",\"y\""));
    // 0 to 0.002 s every 1e-3 s (the plant's DefaultExperiment step): 3 rows
    assert_eq!(text.lines().count(), 1 + 3);
    let _ = std::fs::remove_dir_all(dir);
}
