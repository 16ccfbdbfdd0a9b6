//! A campaign as a Slurm job array: one array task per shard, each running its block of
//! runs with `campaign run SPEC --out DIR --shard $SLURM_ARRAY_TASK_ID/N --resume`;
//! submitted with `sbatch`, waited for by polling `squeue` (every 0.5 s), each task's end
//! state read with `scontrol -o show job`.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use crate::spec::Spec;
use crate::Error;

/// The fewest runs per array task for Slurm's overhead to stay under 5 %: a task's start
/// and end (allocation, prolog, `campaign` loading the system) measured at 0.6 - 0.9 s of
/// wall time per task on the single-node cluster of `scripts/slurm-local.sh`, 2 tasks at a
/// time; a 30 s closed-loop run is about 64 ms of one core, so 1 s is about 15 runs, and
/// 5 % of a task is 1 s when the task holds 20 x 15 = 300 runs.
pub const RUNS_PER_TASK_MIN: u64 = 300;

/// What to write and how to submit.
#[derive(Clone, Debug)]
pub struct Array {
    /// The output folder.
    pub out: PathBuf,
    /// Array tasks (shards).
    pub tasks: u64,
    /// Slurm partition (`--partition`), default the cluster's.
    pub partition: Option<String>,
    /// CPUs per task (each task runs that many threads).
    pub cpus_per_task: u64,
    /// The `campaign` program the tasks run.
    pub program: PathBuf,
}

fn abs(p: &Path) -> PathBuf {
    std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf())
}

fn sh(p: &Path) -> String {
    format!("'{}'", p.display().to_string().replace('\'', "'\\''"))
}

/// The sbatch script of `spec` as `array`.
pub fn script(spec: &Spec, array: &Array) -> String {
    let out = abs(&array.out);
    let mut s = String::from("#!/bin/bash\n");
    s += &format!("#SBATCH --job-name=campaign-{}\n", crate::results::short(&spec.hash));
    s += &format!("#SBATCH --array=0-{}\n", array.tasks - 1);
    s += &format!("#SBATCH --cpus-per-task={}\n", array.cpus_per_task);
    s += &format!("#SBATCH --output={}/slurm/%A_%a.out\n", out.display());
    if let Some(p) = &array.partition {
        s += &format!("#SBATCH --partition={p}\n");
    }
    s += &format!(
        "# {} runs in {} tasks of about {} runs\n",
        spec.runs(),
        array.tasks,
        spec.runs().div_ceil(array.tasks)
    );
    s += &format!("cd {}\n", sh(&abs(Path::new("."))));
    s += &format!(
        "exec {} run {} --out {} --shard \"$SLURM_ARRAY_TASK_ID/{}\" --resume --allow-failures --threads \"${{SLURM_CPUS_PER_TASK:-1}}\"\n",
        sh(&abs(&array.program)),
        sh(&abs(&spec.path)),
        sh(&out),
        array.tasks
    );
    s
}

/// Writes the script to `DIR/campaign.sbatch` (and makes `DIR/slurm/` for the task logs).
pub fn write(spec: &Spec, array: &Array) -> Result<PathBuf, Error> {
    if array.tasks == 0 {
        return Err(Error::Usage("--tasks must be at least 1".into()));
    }
    crate::results::claim(&array.out, spec)?;
    let logs = array.out.join("slurm");
    std::fs::create_dir_all(&logs).map_err(|e| Error::Io(format!("{}: {e}", logs.display())))?;
    let path = array.out.join("campaign.sbatch");
    std::fs::write(&path, script(spec, array)).map_err(|e| Error::Io(format!("{}: {e}", path.display())))?;
    Ok(path)
}

fn run(cmd: &mut Command) -> Result<String, Error> {
    let what = format!("{cmd:?}");
    let out = cmd
        .output()
        .map_err(|e| Error::Slurm(format!("{what}: {e} (is Slurm installed? scripts/slurm-local.sh start)")))?;
    if !out.status.success() {
        return Err(Error::Slurm(format!("{what}: {}", String::from_utf8_lossy(&out.stderr).trim())));
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

/// Submits the script; returns the job id.
pub fn submit(script: &Path) -> Result<String, Error> {
    let out = run(Command::new("sbatch").arg("--parsable").arg(script))?;
    let id = out.trim().split(';').next().unwrap_or("").to_string();
    if id.is_empty() {
        return Err(Error::Slurm(format!("sbatch gave no job id ({out:?})")));
    }
    Ok(id)
}

/// The end state of every array task of `job` (task id, state), by `scontrol`.
pub fn task_states(job: &str) -> Result<Vec<(u64, String)>, Error> {
    let out = run(Command::new("scontrol").args(["-o", "show", "job", job]))?;
    let mut states = Vec::new();
    for line in out.lines() {
        let field = |k: &str| line.split_whitespace().find_map(|f| f.strip_prefix(k)).map(String::from);
        if let (Some(task), Some(state)) = (field("ArrayTaskId="), field("JobState=")) {
            if let Ok(t) = task.parse() {
                states.push((t, state));
            }
        }
    }
    states.sort();
    Ok(states)
}

/// Waits until no task of `job` is queued or running (`squeue` every 0.5 s); `tick` is
/// called with the number still in the queue.
pub fn wait(job: &str, mut tick: impl FnMut(usize)) -> Result<Duration, Error> {
    let start = Instant::now();
    loop {
        let out = run(Command::new("squeue").args(["-h", "-r", "-j", job, "-o", "%i %T"]))?;
        let n = out.lines().filter(|l| !l.trim().is_empty()).count();
        tick(n);
        if n == 0 {
            return Ok(start.elapsed());
        }
        std::thread::sleep(Duration::from_millis(500));
    }
}
