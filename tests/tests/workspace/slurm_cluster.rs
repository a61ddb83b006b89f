//! The Slurm scripts on a real Slurm: `deploy/slurm/local-cluster.sh`
//! starts a single-node cluster on this machine (munge, slurmctld, slurmd,
//! generated configuration), `submit.sh` queues a split render, one task is
//! signalled as Slurm's `--signal` would, another is cancelled, the merge
//! fails naming both, `submit.sh --only` redoes them and the merged image is
//! the single render's bytes. A task whose time limit is shorter than its
//! render is stopped ahead of the limit with its checkpoint saved.
//!
//! Needs Debian's `slurm-wlm` and `munge` and root; says so and passes
//! otherwise, and fails where `RTGI_REQUIRE_SLURM` is set (as CI sets it).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use rtgi_tests::{Run, scratch_dir, workspace_root};

const RTGI: &str = env!("CARGO_BIN_EXE_rtgi-under-test");
const SCENE: &str = "scenes/cornell-box.toml";
const OPTIONS: [&str; 6] = ["--width", "32", "--height", "24", "--seed", "4"];

/// The cluster, stopped when the test ends however it ends.
struct Cluster {
    dir: PathBuf,
    conf: PathBuf,
}

impl Drop for Cluster {
    fn drop(&mut self) {
        let _ = Command::new("bash")
            .arg(workspace_root().join("deploy/slurm/local-cluster.sh"))
            .args(["stop", self.dir.to_str().unwrap()])
            .output();
    }
}

impl Cluster {
    fn start(dir: &Path) -> Option<Cluster> {
        let run: Run = Command::new("bash")
            .arg(workspace_root().join("deploy/slurm/local-cluster.sh"))
            .args(["start", dir.to_str().unwrap()])
            .output()
            .unwrap()
            .into();
        if run.code == Some(3) {
            rtgi_tests::skip_without(
                rtgi_tests::Requirement::Slurm,
                &format!("no Slurm to test on ({}); apt-get install slurm-wlm munge", run.stderr.trim()),
            );
            return None;
        }
        assert!(run.success, "the local Slurm did not start: {run:?}");
        Some(Cluster { dir: dir.to_owned(), conf: dir.join("slurm.conf") })
    }

    fn command(&self, program: &str) -> Command {
        let mut command = Command::new(program);
        command.current_dir(workspace_root()).env("SLURM_CONF", &self.conf).env("RTGI", RTGI);
        command
    }

    fn run(&self, program: &str, args: &[&str]) -> Run {
        self.command(program).args(args).output().unwrap().into()
    }

    fn submit(&self, parts: &Path, args: &[&str]) -> Run {
        let mut command = self.command("bash");
        command.arg(workspace_root().join("deploy/slurm/submit.sh")).args(args).env("PARTS", parts);
        command.output().unwrap().into()
    }

    /// `scontrol show job`'s field `key` (JobState, ExitCode, ...) of job `id`.
    fn field(&self, id: &str, key: &str) -> String {
        let run = self.run("scontrol", &["show", "job", id]);
        run.stdout
            .split_whitespace()
            .find_map(|word| word.strip_prefix(&format!("{key}=")))
            .map(str::to_owned)
            .unwrap_or_default()
    }

    /// Waits until `done` holds, for at most `limit`.
    fn wait(&self, what: &str, limit: Duration, mut done: impl FnMut(&Cluster) -> bool) {
        let start = Instant::now();
        while !done(self) {
            let queue = self.run("squeue", &["-h", "-o", "%i %T %r"]).stdout;
            assert!(start.elapsed() < limit, "waited {limit:?} for {what}; the queue:\n{queue}");
            std::thread::sleep(Duration::from_millis(300));
        }
    }

    /// Whether job `id` is in one of Slurm's final states. Named rather than
    /// inferred from the running states: a job being sent its `--signal`
    /// passes through SIGNALING, which once let the test read the log
    /// before rtgi had saved (and there are STAGE_OUT, RESIZING, ...).
    fn ended(&self, id: &str) -> bool {
        matches!(
            self.field(id, "JobState").as_str(),
            "COMPLETED"
                | "CANCELLED"
                | "FAILED"
                | "TIMEOUT"
                | "PREEMPTED"
                | "NODE_FAIL"
                | "BOOT_FAIL"
                | "DEADLINE"
                | "OUT_OF_MEMORY"
                | "REVOKED"
                | "SPECIAL_EXIT"
        )
    }
}

/// The array's and the merge's job ids, from submit.sh's first line.
fn job_ids(run: &Run) -> (String, String) {
    let words: Vec<&str> = run.stdout.split_whitespace().collect();
    let after = |word: &str| words.iter().position(|w| *w == word).map(|i| words[i + 1].to_owned());
    (after("array").expect("the array's id"), after("merge").expect("the merge's id"))
}

#[test]
fn a_split_render_on_a_real_slurm_survives_a_signal_a_cancel_and_a_time_limit() {
    let dir = scratch_dir("slurm-cluster");
    let Some(cluster) = Cluster::start(&dir.join("slurm")) else { return };
    let started = Instant::now();

    // A time limit shorter than the render: Slurm's --signal reaches rtgi
    // through its job step, and rtgi saves its checkpoint ahead of the limit.
    let limited = dir.join("limited");
    let output = dir.join("limited.exr");
    let mut args = vec!["--time", "1", "1", SCENE, "1000000", output.to_str().unwrap()];
    args.extend(OPTIONS);
    let run = cluster.submit(&limited, &args);
    assert!(run.success, "{run:?}");
    let (array, _) = job_ids(&run);
    let task = format!("{array}_0");
    cluster.wait("the time-limited task to stop", Duration::from_secs(120), |c| c.ended(&task));
    let log = std::fs::read_to_string(limited.join("logs/part-0.log")).unwrap();
    let slurm_log = std::fs::read_to_string(limited.join(format!("logs/render-{task}.log"))).unwrap_or_default();
    let (state, code) = (cluster.field(&task, "JobState"), cluster.field(&task, "ExitCode"));
    assert!(
        log.contains("stopped     by SIGTERM"),
        "the signal did not reach rtgi, or did not let it save (JobState={state} ExitCode={code}):\n{log}\n\
         Slurm's log of the task:\n{slurm_log}"
    );
    assert!(limited.join("part-0.checkpoint.accum").exists(), "{log}");
    assert_ne!(cluster.field(&task, "JobState"), "TIMEOUT", "killed at the limit, not stopped before it");
    eprintln!("time limit: stopped ahead of it after {:?}", started.elapsed());

    // A split render of three tasks: one signalled, one cancelled.
    let spp = "24000";
    let single = dir.join("single.exr");
    let mut args = vec!["render", SCENE, "--spp", spp, "-o", single.to_str().unwrap()];
    args.extend(OPTIONS);
    let run = rtgi_tests::run_cli(RTGI, &args);
    assert!(run.success, "{run:?}");
    let parts = dir.join("parts");
    let output = dir.join("split.exr");
    let mut args = vec!["3", SCENE, spp, output.to_str().unwrap()];
    args.extend(OPTIONS);
    let run = cluster.submit(&parts, &args);
    assert!(run.success, "{run:?}");
    let (array, merge) = job_ids(&run);
    let (second, third) = (format!("{array}_1"), format!("{array}_2"));
    cluster.wait("task 1 to run", Duration::from_secs(60), |c| c.field(&second, "JobState") == "RUNNING");
    // What --signal=TERM@120 does: signal the job's steps (not the batch shell).
    std::thread::sleep(Duration::from_millis(1500));
    let run = cluster.run("scancel", &["--signal=TERM", &second]);
    assert!(run.success, "{run:?}");
    let run = cluster.run("scancel", &[&third]);
    assert!(run.success, "{run:?}");
    cluster.wait("the merge to run and fail", Duration::from_secs(120), |c| c.ended(&merge));
    let log = std::fs::read_to_string(parts.join("logs/part-1.log")).unwrap();
    assert!(log.contains("stopped     by SIGTERM"), "{log}");
    assert!(parts.join("part-0.accum").exists() && !parts.join("part-1.accum").exists());
    assert_eq!(cluster.field(&merge, "JobState"), "FAILED");
    let merge_log = std::fs::read_to_string(parts.join(format!("logs/merge-{merge}.log"))).unwrap();
    assert!(merge_log.contains("parts 1 2 of 3 are missing") && merge_log.contains("--only 1,2"), "{merge_log}");
    assert!(!output.exists(), "an incomplete render was merged");

    // The merge's advice, followed: the two tasks again.
    let mut args = vec!["--only", "1,2", "3", SCENE, spp, output.to_str().unwrap()];
    args.extend(OPTIONS);
    let run = cluster.submit(&parts, &args);
    assert!(run.success, "{run:?}");
    let (_, merge) = job_ids(&run);
    cluster.wait("the second merge", Duration::from_secs(180), |c| c.ended(&merge));
    let merge_log = std::fs::read_to_string(parts.join(format!("logs/merge-{merge}.log"))).unwrap_or_default();
    assert_eq!(cluster.field(&merge, "JobState"), "COMPLETED", "{merge_log}");
    let log = std::fs::read_to_string(parts.join("logs/part-1.log")).unwrap();
    assert!(log.contains("resuming"), "task 1 started again instead of resuming:\n{log}");
    assert_eq!(std::fs::read(&output).unwrap(), std::fs::read(&single).unwrap(), "merged bytes differ");

    // The same folder for another render: refused at submission.
    let args = ["3", SCENE, spp, output.to_str().unwrap(), "--width", "32", "--height", "24", "--seed", "5"];
    let run = cluster.submit(&parts, &args);
    assert_eq!(run.code, Some(2), "{run:?}");
    assert!(run.stderr.contains("another render"), "{run:?}");
    eprintln!("the whole test took {:?}", started.elapsed());
}
