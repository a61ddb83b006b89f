//! Long renders as a user on a cluster runs them: stopped by a time limit
//! or a signal, checkpointed, resumed, split into jobs and merged. Every
//! way of cutting a render up must end with the bytes of the render in one go.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use super::{RTGI, path_str, rtgi};
use rtgi_tests::{Run, ScratchDir, scratch_dir};

/// The built-in Cornell box, small, at many samples: a few seconds of work.
const RENDER: &[&str] = &["render", "--width", "64", "--height", "48", "--spp", "192", "--seed", "11"];

fn render_args<'a>(extra: &[&'a str]) -> Vec<&'a str> {
    RENDER.iter().copied().chain(extra.iter().copied()).collect()
}

fn uninterrupted(dir: &Path) -> Vec<u8> {
    let whole = dir.join("whole.exr");
    let run = rtgi(&render_args(&["-o", path_str(&whole)]));
    assert!(run.success, "{run:?}");
    std::fs::read(&whole).unwrap()
}

/// Starts `rtgi` with `args` in the workspace root, its output captured.
fn spawn(args: &[&str]) -> std::process::Child {
    Command::new(RTGI)
        .args(args)
        .current_dir(rtgi_tests::workspace_root())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Sends `signal` (a name kill(1) knows) to a process.
fn send(signal: &str, pid: u32) {
    let status = Command::new("kill").args([&format!("-{signal}"), &pid.to_string()]).status().unwrap();
    assert!(status.success(), "kill -{signal} {pid}");
}

/// A delay between 0.2 and 2.2 seconds that differs from run to run; printed, so a failure can be repeated.
fn random_moment() -> Duration {
    let nanos = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap().subsec_nanos();
    let delay = Duration::from_millis(200 + (nanos as u64 % 2000));
    eprintln!("interrupting after {delay:?}");
    delay
}

#[test]
fn a_render_interrupted_at_a_random_moment_resumes_to_the_same_bytes() {
    let dir = scratch_dir("interrupted");
    let expected = uninterrupted(&dir);
    let (image, checkpoint) = (dir.join("image.exr"), dir.join("render.accum"));
    let mut args = render_args(&["-o", path_str(&image), "--checkpoint", path_str(&checkpoint)]);
    args.extend(["--checkpoint-every", "0.3"]);
    let child = spawn(&args);
    std::thread::sleep(random_moment());
    send("INT", child.id());
    let run: Run = child.wait_with_output().unwrap().into();
    // Either the signal came in time (130) or the render had already finished (0).
    assert!(matches!(run.code, Some(130) | Some(0)), "{run:?}");
    if run.code == Some(130) {
        assert!(run.stdout.contains("stopped     by SIGINT"), "{run:?}");
        assert!(run.stderr.contains("stopped by SIGINT"), "{run:?}");
        assert!(checkpoint.exists(), "{run:?}");
        if image.exists() {
            // A valid image of the samples done so far.
            assert!(rtgi_image::HdrImage::read_exr(&image).is_ok());
        }
        // Resumed, interrupted once more with SIGTERM, and resumed to the end.
        let mut resume = render_args(&["-o", path_str(&image), "--resume", path_str(&checkpoint)]);
        resume.extend(["--checkpoint-every", "0.3"]);
        let child = spawn(&resume);
        std::thread::sleep(Duration::from_millis(400));
        send("TERM", child.id());
        let run: Run = child.wait_with_output().unwrap().into();
        assert!(matches!(run.code, Some(143) | Some(0)), "{run:?}");
        let run = rtgi(&resume);
        assert!(run.success, "{run:?}");
    }
    assert_eq!(std::fs::read(&image).unwrap(), expected, "the resumed render differs from the render in one go");
}

#[test]
fn a_second_interrupt_ends_the_render_at_once() {
    let dir = scratch_dir("second-interrupt");
    let image = dir.join("never.exr");
    let args: Vec<&str> =
        ["render", "--width", "256", "--height", "256", "--spp", "4096", "-o", path_str(&image)].into();
    let child = spawn(&args);
    // Once the first pass (one sample) is done, the render is in its long second pass.
    std::thread::sleep(Duration::from_millis(1500));
    send("INT", child.id());
    // Later than a repeat of the same request (250 ms), as a person presses it.
    std::thread::sleep(Duration::from_millis(400));
    send("INT", child.id());
    let start = Instant::now();
    let run: Run = child.wait_with_output().unwrap().into();
    assert_eq!(run.code, Some(130), "{run:?}");
    assert!(start.elapsed() < Duration::from_secs(5), "took {:?} to stop", start.elapsed());
    assert!(!run.stderr.contains("panicked"), "{run:?}");
}

/// A checkpointed render sent SIGTERM once it is under way and again `gap`
/// later: what it printed, and its scratch folder (kept while the caller
/// looks) with where its checkpoint should be.
fn sigterm_twice(name: &str, gap: Duration) -> (Run, ScratchDir, PathBuf) {
    let dir = scratch_dir(name);
    let (image, checkpoint) = (dir.join("image.exr"), dir.join("render.accum"));
    let mut args = vec!["render", "--width", "256", "--height", "256", "--spp", "4096"];
    args.extend(["-o", path_str(&image), "--checkpoint", path_str(&checkpoint)]);
    let child = spawn(&args);
    std::thread::sleep(Duration::from_millis(1500));
    send("TERM", child.id());
    std::thread::sleep(gap);
    // Until it is waited for, an exited child is still there to signal.
    send("TERM", child.id());
    (child.wait_with_output().unwrap().into(), dir, checkpoint)
}

#[test]
fn the_same_signal_delivered_twice_at_once_still_saves_the_checkpoint() {
    // A scheduler signals every process of a job, and the job's script forwards the signal too:
    // rtgi gets it twice within milliseconds, and must take it as one request to stop and save.
    let (run, _dir, checkpoint) = sigterm_twice("signal-twice", Duration::ZERO);
    assert_eq!(run.code, Some(143), "{run:?}");
    assert!(run.stdout.contains("stopped     by SIGTERM"), "{run:?}");
    assert!(checkpoint.exists(), "no checkpoint after a doubled SIGTERM: {run:?}");
}

#[test]
fn a_later_sigterm_does_not_cut_the_stop_short() {
    // On a loaded node a job script's forwarded copy of the scheduler's SIGTERM can come
    // long after the first; only SIGKILL may end the render without its checkpoint. Here
    // the stop is often over before the second signal: the rule itself is unit-tested in
    // apps/rtgi/src/interrupt.rs, and this checks the real process either way.
    let (run, _dir, checkpoint) = sigterm_twice("sigterm-later", Duration::from_millis(300));
    assert_eq!(run.code, Some(143), "{run:?}");
    assert!(run.stdout.contains("stopped     by SIGTERM"), "{run:?}");
    assert!(checkpoint.exists(), "no checkpoint after a second, later SIGTERM: {run:?}");
}

#[test]
fn a_time_limit_stops_with_the_samples_done_and_says_how_many() {
    let dir = scratch_dir("time-limit");
    let (limited, range) = (dir.join("limited.accum"), dir.join("range.accum"));
    let args = ["render", "--width", "128", "--height", "128", "--spp", "4096", "--seed", "2"];
    let mut timed = args.to_vec();
    timed.extend(["--time-limit", "2.5", "-o", path_str(&limited)]);
    let start = Instant::now();
    let run = rtgi(&timed);
    let took = start.elapsed();
    assert!(run.success, "{run:?}");
    assert!(took < Duration::from_secs(5), "a 2.5 s limit took {took:?}");
    let line = run.stdout.lines().find(|l| l.starts_with("stopped     by the time limit")).expect("says it stopped");
    let done: u32 = line.split(" with ").nth(1).and_then(|r| r.split(' ').next()?.parse().ok()).expect(line);
    assert!(done > 0 && done < 4096, "{line}");
    // What it wrote is exactly samples 0..done of the full render.
    let mut ranged = args.to_vec();
    let samples = format!("0..{done}");
    ranged.extend(["--samples", &samples, "-o", path_str(&range)]);
    let run = rtgi(&ranged);
    assert!(run.success, "{run:?}");
    assert_eq!(std::fs::read(&limited).unwrap(), std::fs::read(&range).unwrap());
}

#[test]
fn four_sample_ranges_and_three_bands_merge_to_the_same_bytes() {
    let dir = scratch_dir("merge");
    let expected = uninterrupted(&dir);
    let mut parts: Vec<PathBuf> = Vec::new();
    for range in ["0..40", "40..41", "41..150", "150..192"] {
        let part = dir.join(format!("samples-{range}.accum"));
        let run = rtgi(&render_args(&["--samples", range, "-o", path_str(&part)]));
        assert!(run.success, "{run:?}");
        parts.push(part);
    }
    let merged = dir.join("merged.exr");
    let mut merge = vec!["merge"];
    merge.extend(parts.iter().rev().map(|p| path_str(p)));
    merge.extend(["-o", path_str(&merged)]);
    let run = rtgi(&merge);
    assert!(run.success, "{run:?}");
    assert_eq!(std::fs::read(&merged).unwrap(), expected, "4 sample ranges merged");

    let mut bands = Vec::new();
    for tile in ["0/3", "1/3", "2/3"] {
        let part = dir.join(format!("band-{}.accum", &tile[..1]));
        let run = rtgi(&render_args(&["--tile", tile, "-o", path_str(&part)]));
        assert!(run.success, "{run:?}");
        bands.push(part);
    }
    let mut merge = vec!["merge"];
    merge.extend(bands.iter().map(|p| path_str(p)));
    merge.extend(["-o", path_str(&merged)]);
    let run = rtgi(&merge);
    assert!(run.success, "{run:?}");
    assert_eq!(std::fs::read(&merged).unwrap(), expected, "3 bands merged");

    // A missing part, another render's part, and a part written over: refused, naming the problem.
    let run = rtgi(&["merge", path_str(&parts[0]), path_str(&parts[2]), "-o", path_str(&merged)]);
    assert_eq!(run.code, Some(1));
    assert!(run.stderr.contains("no part holds samples 40..41"), "{run:?}");
    // Without the first or the last part the rest is contiguous, but not the render: refused unless
    // --allow-incomplete says that a partial image is what is wanted.
    for (kept, missing) in [(&parts[1..], "samples 0..40"), (&parts[..3], "samples 150..192")] {
        let mut merge = vec!["merge"];
        merge.extend(kept.iter().map(|p| path_str(p)));
        merge.extend(["-o", path_str(&merged)]);
        std::fs::remove_file(&merged).unwrap();
        let run = rtgi(&merge);
        assert_eq!(run.code, Some(1), "{run:?}");
        assert!(run.stderr.contains("incomplete") && run.stderr.contains(missing), "{missing}: {run:?}");
        assert!(!merged.exists(), "an incomplete merge wrote {}", merged.display());
        merge.push("--allow-incomplete");
        let run = rtgi(&merge);
        assert!(run.success && run.stdout.contains("incomplete"), "{run:?}");
    }
    let other = dir.join("other.accum");
    let run = rtgi(&[
        "render",
        "--width",
        "64",
        "--height",
        "48",
        "--spp",
        "192",
        "--samples",
        "40..41",
        "-o",
        path_str(&other),
    ]);
    assert!(run.success, "{run:?}");
    let run = rtgi(&["merge", path_str(&parts[0]), path_str(&other), "-o", path_str(&merged)]);
    assert_eq!(run.code, Some(1));
    assert!(run.stderr.contains("other.accum is of another render") && run.stderr.contains("seed 11 vs 0"), "{run:?}");
    let run = rtgi(&["merge", path_str(&parts[0]), path_str(&parts[1]), "-o", path_str(&parts[1])]);
    assert_eq!(run.code, Some(1));
    assert!(run.stderr.contains("is also one of the parts"), "{run:?}");
}

#[test]
fn resuming_with_other_options_is_refused_naming_them() {
    let dir = scratch_dir("resume-other");
    let part = dir.join("part.accum");
    let run = rtgi(&render_args(&["--samples", "0..2", "-o", path_str(&part)]));
    assert!(run.success, "{run:?}");
    let image = dir.join("more.accum");
    let mut args = render_args(&["--max-depth", "3", "--resume", path_str(&part), "-o", path_str(&image)]);
    args.extend(["--samples", "0..4"]);
    let run = rtgi(&args);
    // Exit 3: a job script tells a foreign checkpoint from a failure that running again may cure.
    assert_eq!(run.code, Some(3), "{run:?}");
    assert!(run.stderr.contains("max depth: 3 now, 8 in the file"), "{run:?}");
    assert!(!image.exists());
}

#[test]
fn progress_lines_go_to_logs_when_standard_error_is_not_a_terminal() {
    let dir = scratch_dir("progress-lines");
    let image = dir.join("image.png");
    let output = Command::new(RTGI)
        .args(render_args(&["-o", path_str(&image)]))
        .env("RTGI_PROGRESS_SECONDS", "0")
        .current_dir(rtgi_tests::workspace_root())
        .output()
        .unwrap();
    let run: Run = output.into();
    assert!(run.success, "{run:?}");
    let line = run.stderr.lines().find(|l| l.starts_with("rtgi: ")).expect("a progress line");
    assert!(line.contains("samples per pixel") && line.contains("M samples/s") && line.contains("left"), "{line}");
}
