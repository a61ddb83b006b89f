//! `--threads N` means N: a command given one thread uses one core, its
//! loading, building and rendering included. Work that ran outside the
//! command's pool (a render's passes, once) ran on rayon's global pool, one
//! thread per core, and `--threads 1` took two cores while saying "1 threads".
//!
//! The CPU time of a child is read from bash's `times`, which reports the
//! user and system time of the processes the shell waited for. A second
//! core shows only when it is free, so this file is a test binary of its
//! own with one test: nothing else of the suite runs beside it.

use std::path::Path;
use std::process::Command;
use std::time::Instant;

use rtgi_tests::{scratch_dir, workspace_root};

const RTGI: &str = env!("CARGO_BIN_EXE_rtgi-under-test");

/// A process that ran with one worker thread may use this much more CPU
/// time than wall time (the signal and progress threads, the kernel).
const MOST_CPU_PER_WALL: f64 = 1.2;

/// Seconds from a `times` figure such as `0m1.234s`.
fn seconds(figure: &str) -> f64 {
    let (minutes, rest) = figure.split_once('m').unwrap_or_else(|| panic!("not a time: {figure}"));
    minutes.parse::<f64>().unwrap() * 60.0 + rest.trim_end_matches('s').parse::<f64>().unwrap()
}

/// Runs `rtgi args` with `envs`, returning its CPU time (user and system)
/// and its wall time in seconds; fails the test if it fails.
fn cpu_and_wall(args: &[&str], envs: &[(&str, &str)]) -> (f64, f64) {
    let started = Instant::now();
    let output = Command::new("bash")
        .args(["-c", r#""$@" >/dev/null 2>"$STDERR_FILE"; status=$?; times; exit $status"#, "bash", RTGI])
        .args(args)
        .envs(envs.iter().copied())
        .env("STDERR_FILE", std::env::temp_dir().join(format!("rtgi-threads-{}.err", std::process::id())))
        .current_dir(workspace_root())
        .output()
        .expect("cannot start bash");
    let wall = started.elapsed().as_secs_f64();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "rtgi {args:?} failed: {stdout}");
    // The second line of `times`: the user and system time of the children.
    let children = stdout.lines().nth(1).unwrap_or_else(|| panic!("no times in {stdout:?}"));
    let cpu: f64 = children.split_whitespace().map(seconds).sum();
    (cpu, wall)
}

/// Checks that `rtgi args` works on one core: CPU time at most
/// [`MOST_CPU_PER_WALL`] of its wall time, over work long enough that two
/// cores could not hide in the timer's resolution.
fn uses_one_core(what: &str, args: &[&str], envs: &[(&str, &str)]) {
    let (cpu, wall) = cpu_and_wall(args, envs);
    assert!(wall > 0.2, "{what}: {wall:.2} s is too short a run to tell one core from two");
    assert!(
        cpu <= MOST_CPU_PER_WALL * wall,
        "{what}: {cpu:.2} s of CPU in {wall:.2} s: more than one core at one thread ({:.2}x)",
        cpu / wall
    );
}

fn s(path: &Path) -> &str {
    path.to_str().expect("scratch paths are UTF-8")
}

#[test]
fn render_trace_bench_and_experiment_with_one_thread_use_one_core() {
    let dir = scratch_dir("threads");
    let out = dir.join("box.exr");
    let render =
        ["render", "scenes/cornell-box.toml", "-o", s(&out), "--width", "160", "--height", "160", "--spp", "24"];
    uses_one_core("render --threads 1", &[&render[..], &["--threads", "1"]].concat(), &[]);
    uses_one_core("render with RTGI_THREADS=1", &render, &[("RTGI_THREADS", "1")]);
    // Four million rays: 1.5 million took 0.20 s once traversal got faster,
    // too short a run for the check below.
    let rays = dir.join("rays.bin");
    let made = Command::new(RTGI)
        .args(["rays", "scenes/cornell-box.toml", "--kind", "surface", "--count", "4000000", "-o", s(&rays)])
        .current_dir(workspace_root())
        .output()
        .unwrap();
    assert!(made.status.success(), "{made:?}");
    let hits = dir.join("hits.bin");
    uses_one_core(
        "trace --threads 1",
        &["trace", "scenes/cornell-box.toml", "--rays", s(&rays), "-o", s(&hits), "--threads", "1"],
        &[],
    );
    uses_one_core(
        "bench --threads 1",
        &[
            "bench",
            "scenes/cornell-box.toml",
            "--accel",
            "sah",
            "--width",
            "64",
            "--height",
            "64",
            "--rays",
            "30000",
            "--repeats",
            "1",
            "--threads",
            "1",
        ],
        &[],
    );
    let out = dir.join("experiment");
    uses_one_core(
        "experiment --threads 1",
        &["experiment", "depth", "--quick", "--repeats", "1", "--out", s(&out), "--threads", "1"],
        &[],
    );
}
