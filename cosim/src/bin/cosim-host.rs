//! `cosim-host`: the host process of an isolated FMU instance, started by the master
//! (`cosim run --isolate`, `Experiment::isolation`); see `nigel_cosim::isolate`.

fn main() {
    let args: Vec<std::ffi::OsString> = std::env::args_os().collect();
    std::process::exit(nigel_cosim::isolate::host::run(&args));
}
