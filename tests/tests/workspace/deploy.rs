//! The cluster scripts in deploy/, run as far as this machine allows without
//! a scheduler: the Slurm array and merge scripts with the variables Slurm
//! would set, `submit.sh` against a stand-in `sbatch` that records what it
//! was asked, and the Kubernetes manifests' commands and environments read
//! from their YAML and run with the index the Job controller would give.
//! Merged images must be the single render's bytes. (`slurm_cluster.rs`
//! does the same on a real Slurm where one is installed.)

use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

use rtgi_tests::{Run, scratch_dir, workspace_root};

const RTGI: &str = env!("CARGO_BIN_EXE_rtgi-under-test");

const SCENE: &str = "scenes/cornell-box.toml";
const SPP: &str = "24";
const OPTIONS: &str = "--width 40 --height 30 --seed 4";

fn script(path: &str, parts: &Path, env: &[(&str, &str)]) -> Run {
    script_command(path, parts, env).output().expect("cannot run bash").into()
}

fn script_command(path: &str, parts: &Path, env: &[(&str, &str)]) -> Command {
    let mut command = Command::new("bash");
    command
        .arg(workspace_root().join(path))
        .current_dir(workspace_root())
        .env("RTGI", RTGI)
        .env("SCENE", SCENE)
        .env("SPP", SPP)
        .env("PARTS", parts)
        .env("RTGI_ARGS", OPTIONS)
        .env("DEPLOY_DIR", workspace_root().join("deploy"))
        .env_remove("SLURM_JOB_ID")
        .env_remove("RTGI_THREADS")
        .envs(env.iter().copied());
    command
}

/// Task `index` of `count` of render.sbatch, as Slurm would start it.
fn task(parts: &Path, index: &str, count: &str, env: &[(&str, &str)]) -> Run {
    let mut all = vec![("SLURM_ARRAY_TASK_ID", index), ("ARRAY_COUNT", count)];
    all.extend_from_slice(env);
    script("deploy/slurm/render.sbatch", parts, &all)
}

fn single_render(dir: &Path, options: &str) -> Vec<u8> {
    let out = dir.join("single.exr");
    let mut args = vec!["render", SCENE, "--spp", SPP, "-o", out.to_str().unwrap()];
    args.extend(options.split(' '));
    let run = rtgi_tests::run_cli(RTGI, &args);
    assert!(run.success, "{run:?}");
    std::fs::read(out).unwrap()
}

fn merge(parts: &Path, output: &Path, count: Option<&str>) -> Run {
    let mut env = vec![("OUTPUT", output.to_str().unwrap())];
    env.extend(count.map(|c| ("ARRAY_COUNT", c)));
    script("deploy/slurm/merge.sbatch", parts, &env)
}

#[test]
fn a_slurm_array_of_five_tasks_merges_to_the_single_render() {
    let dir = scratch_dir("deploy-slurm");
    let expected = single_render(&dir, OPTIONS);
    let parts: PathBuf = dir.join("parts");
    // Task 2 first stops at a time limit too short for its share (exit 75,
    // checkpoint kept, no part), then is run again and resumes.
    let stopped = task(&parts, "2", "5", &[("TIME_LIMIT", "0.001")]);
    assert_eq!(stopped.code, Some(75), "{stopped:?}");
    assert!(stopped.stderr.contains("run it again to resume"), "{stopped:?}");
    assert!(parts.join("part-2.checkpoint.accum").exists(), "{stopped:?}");
    assert!(!parts.join("part-2.accum").exists());
    let early = merge(&parts, &dir.join("early.exr"), Some("5"));
    assert!(!early.success, "merged without the parts: {early:?}");
    // Slurm's own count is the tasks of this submission; with the whole array it is the render's.
    for index in ["0", "1", "2", "3", "4"] {
        let run = script(
            "deploy/slurm/render.sbatch",
            &parts,
            &[("SLURM_ARRAY_TASK_ID", index), ("SLURM_ARRAY_TASK_COUNT", "5"), ("SLURM_CPUS_PER_TASK", "2")],
        );
        assert!(run.success, "task {index}: {run:?}");
    }
    assert!(!parts.join("part-2.checkpoint.accum").exists(), "the finished task keeps its checkpoint");
    // Submitting the array again checks finished tasks and skips them.
    let again = task(&parts, "0", "5", &[]);
    assert!(again.success && again.stdout.contains("already done, and is of this render"), "{again:?}");
    // Each run of a task is in its log, one after the other (item 9: the log was overwritten).
    let log = std::fs::read_to_string(parts.join("logs/part-0.log")).unwrap();
    assert_eq!(log.matches("== ").count(), 2, "{log}");
    let log = std::fs::read_to_string(parts.join("logs/part-2.log")).unwrap();
    assert!(log.contains("stopped") && log.contains("resuming"), "{log}");
    let output = dir.join("merged.exr");
    let run = merge(&parts, &output, Some("5"));
    assert!(run.success, "{run:?}");
    assert_eq!(std::fs::read(&output).unwrap(), expected);
}

#[test]
fn a_folder_of_another_render_is_refused_not_merged_as_the_old_image() {
    // Item 1: the same command with seed 8 in a folder of seed 7's parts wrote seed 7's image.
    let dir = scratch_dir("deploy-stale");
    let parts = dir.join("parts");
    for index in ["0", "1"] {
        let run = task(&parts, index, "2", &[("RTGI_ARGS", "--width 40 --height 30 --seed 7")]);
        assert!(run.success, "{run:?}");
    }
    let run = task(&parts, "0", "2", &[("RTGI_ARGS", "--width 40 --height 30 --seed 8")]);
    assert_eq!(run.code, Some(3), "{run:?}");
    assert!(run.stdout.contains("seed") && run.stdout.contains("another render"), "{run:?}");
    assert!(run.stderr.contains("folder of its own") && run.stderr.contains("rm -r"), "{run:?}");
    // A stale checkpoint is refused the same way.
    std::fs::rename(parts.join("part-1.accum"), parts.join("part-1.checkpoint.accum")).unwrap();
    let run = task(&parts, "1", "2", &[("RTGI_ARGS", "--width 40 --height 30 --seed 8")]);
    assert_eq!(run.code, Some(3), "{run:?}");
}

#[test]
fn a_single_index_can_be_submitted_again_on_its_own() {
    // Item 6: 'sbatch --array=1' made Slurm's task count 1, and index 1 was refused.
    let dir = scratch_dir("deploy-one-index");
    let expected = single_render(&dir, OPTIONS);
    let parts = dir.join("parts");
    for index in ["0", "2"] {
        assert!(task(&parts, index, "3", &[]).success);
    }
    let missing = merge(&parts, &dir.join("early.exr"), Some("3"));
    assert_eq!(missing.code, Some(1), "{missing:?}");
    assert!(missing.stderr.contains("parts 1 of 3 are missing"), "{missing:?}");
    assert!(missing.stderr.contains("--array=1"), "{missing:?}");
    let run = script(
        "deploy/slurm/render.sbatch",
        &parts,
        &[("SLURM_ARRAY_TASK_ID", "1"), ("SLURM_ARRAY_TASK_COUNT", "1"), ("ARRAY_COUNT", "3")],
    );
    assert!(run.success, "{run:?}");
    let output = dir.join("merged.exr");
    assert!(merge(&parts, &output, Some("3")).success);
    assert_eq!(std::fs::read(&output).unwrap(), expected);
}

#[test]
fn failures_say_whether_running_again_helps() {
    // Item 8: every failure said "run it again to resume".
    let dir = scratch_dir("deploy-messages");
    let parts = dir.join("parts");
    let run = task(&parts, "0", "2", &[("SCENE", "scenes/no-such-scene.toml")]);
    assert_eq!(run.code, Some(2), "{run:?}");
    assert!(run.stderr.contains("no-such-scene.toml: no such file"), "{run:?}");
    assert!(!run.stderr.contains("run it again"), "{run:?}");
    let run = task(&parts, "0", "2", &[("RTGI_ARGS", "--width 40 --height 30 --max-depth nine")]);
    assert_eq!(run.code, Some(2), "{run:?}");
    assert!(run.stderr.contains("running again cannot help"), "{run:?}");
    let run = task(&parts, "0", "2", &[("RTGI", "/no/such/rtgi")]);
    assert_eq!(run.code, Some(2), "{run:?}");
    assert!(run.stderr.contains("set RTGI"), "{run:?}");
    let run = task(&parts, "5", "2", &[]);
    assert_eq!(run.code, Some(2), "{run:?}");
    assert!(run.stderr.contains("not in 0..1"), "{run:?}");
}

#[test]
fn options_of_the_scripts_own_are_refused_before_they_collide() {
    // Item 7: --threads in the user's options collided with the one render.sbatch adds.
    let dir = scratch_dir("deploy-collide");
    let parts = dir.join("parts");
    let run = task(&parts, "0", "2", &[("RTGI_ARGS", "--threads 2"), ("SLURM_CPUS_PER_TASK", "2")]);
    assert_eq!(run.code, Some(2), "{run:?}");
    assert!(run.stderr.contains("RTGI_THREADS"), "{run:?}");
    for option in ["--spp 8", "-o x.exr", "--samples 0..2", "--checkpoint c.accum"] {
        let run = task(&parts, "0", "2", &[("RTGI_ARGS", option)]);
        assert_eq!(run.code, Some(2), "{option}: {run:?}");
        assert!(run.stderr.contains("sets itself"), "{option}: {run:?}");
    }
    // Without Slurm's CPU count, a user's --threads is the threads.
    let run = task(&parts, "0", "2", &[("RTGI_ARGS", "--width 40 --height 30 --threads 1")]);
    assert!(run.success, "{run:?}");
}

#[test]
fn a_signal_to_the_job_script_reaches_the_render_which_saves_its_checkpoint() {
    // Item 2: the batch script got the signal and rtgi did not, until the hard limit.
    let dir = scratch_dir("deploy-signal");
    let parts = dir.join("parts");
    let child = script_command(
        "deploy/render-part.sh",
        &parts,
        &[("RTGI_ARGS", "--width 256 --height 256"), ("SPP", "100000")],
    )
    .args(["0", "1"])
    .stdout(Stdio::piped())
    .stderr(Stdio::piped())
    .spawn()
    .unwrap();
    std::thread::sleep(Duration::from_millis(2500));
    let status = Command::new("kill").args(["-TERM", &child.id().to_string()]).status().unwrap();
    assert!(status.success());
    let run: Run = child.wait_with_output().unwrap().into();
    assert_eq!(run.code, Some(143), "{run:?}");
    assert!(run.stdout.contains("stopped     by SIGTERM"), "{run:?}");
    assert!(run.stderr.contains("run it again to resume"), "{run:?}");
    assert!(parts.join("part-0.checkpoint.accum").exists(), "{run:?}");
}

/// A folder with stand-ins for `sbatch` and `sinfo`: sbatch appends its
/// arguments and the variables the job scripts read to `sbatch.log`, one
/// line each, and prints a job id; sinfo says the largest node has 4 CPUs.
fn fake_slurm(dir: &Path) -> PathBuf {
    let bin = dir.join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    let log = dir.join("sbatch.log");
    let sbatch = format!(
        "#!/usr/bin/env bash\n\
         echo \"ARGS $* ENV SCENE=$SCENE SPP=$SPP PARTS=$PARTS ARRAY_COUNT=$ARRAY_COUNT RTGI_ARGS=$RTGI_ARGS\" >> {}\n\
         echo $((RANDOM + 100))\n",
        log.display()
    );
    for (name, text) in [("sbatch", sbatch.as_str()), ("sinfo", "#!/bin/sh\necho 4\necho 2\n")] {
        std::fs::write(bin.join(name), text).unwrap();
        std::fs::set_permissions(bin.join(name), std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    bin
}

fn submit(dir: &Path, bin: &Path, args: &[&str]) -> (Run, String) {
    let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap_or_default());
    let run: Run = Command::new("bash")
        .arg(workspace_root().join("deploy/slurm/submit.sh"))
        .args(args)
        .current_dir(workspace_root())
        .env("PATH", path)
        .env("PARTS", dir.join("parts"))
        .env("RTGI", RTGI)
        .output()
        .unwrap()
        .into();
    let log = std::fs::read_to_string(dir.join("sbatch.log")).unwrap_or_default();
    let _ = std::fs::remove_file(dir.join("sbatch.log"));
    (run, log)
}

#[test]
fn submit_passes_cpus_and_sbatch_options_and_queues_a_merge_that_cannot_pend_forever() {
    let dir = scratch_dir("deploy-submit");
    let bin = fake_slurm(&dir);
    let output = dir.join("out.exr");
    let output = output.to_str().unwrap();
    let (run, log) = submit(
        &dir,
        &bin,
        &["--cpus", "3", "--time", "00:20:00", "--sbatch", "--account=lab", "4", SCENE, "64", output, "--seed", "2"],
    );
    assert!(run.success, "{run:?}");
    let lines: Vec<&str> = log.lines().collect();
    assert_eq!(lines.len(), 2, "{log}");
    let (array, merge) = (lines[0], lines[1]);
    // Item 3: CPUs (and any other sbatch option) are the user's.
    assert!(array.contains("--cpus-per-task=3") && array.contains("--time=00:20:00"), "{array}");
    assert!(array.contains("--account=lab") && merge.contains("--account=lab"), "{log}");
    let sbatch = std::fs::read_to_string(workspace_root().join("deploy/slurm/render.sbatch")).unwrap();
    assert!(!sbatch.contains("#SBATCH --cpus-per-task"), "render.sbatch fixes the CPUs again");
    // Item 4: the merge waits for the array to end however it ends, and fails naming what is missing.
    assert!(merge.contains("--dependency=afterany:") && merge.contains("--kill-on-invalid-dep=yes"), "{merge}");
    // Item 9: Slurm's logs go to the parts folder.
    let parts = dir.join("parts");
    assert!(array.contains(&format!("--output={}/logs/render-%A_%a.log", parts.display())), "{array}");
    assert!(merge.contains(&format!("--output={}/logs/merge-%j.log", parts.display())), "{merge}");
    assert!(array.contains("ARRAY_COUNT=4") && array.contains("--array=0-3"), "{array}");
    // Item 6: one task again, of the same render.
    let (run, log) = submit(&dir, &bin, &["--cpus", "3", "--only", "2", "4", SCENE, "64", output, "--seed", "2"]);
    assert!(run.success, "{run:?}");
    assert!(log.contains("--array=2 ") && log.contains("ARRAY_COUNT=4"), "{log}");
    // Item 1, at submission: another render into the same folder.
    let (run, log) = submit(&dir, &bin, &["4", SCENE, "64", output, "--seed", "3"]);
    assert_eq!(run.code, Some(2), "{run:?}");
    assert!(run.stderr.contains("another render") && run.stderr.contains("folder of its own"), "{run:?}");
    assert!(log.is_empty(), "submitted anyway: {log}");
}

#[test]
fn submit_checks_the_request_before_queueing_anything() {
    // Items 7 and 10: options that collide, and requests that cannot run, are refused at once.
    let dir = scratch_dir("deploy-submit-checks");
    let bin = fake_slurm(&dir);
    let output = dir.join("out.exr");
    let output = output.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["4", SCENE, "64", output, "--threads", "8"], "give --cpus N"),
        (&["4", SCENE, "64", output, "--spp", "8"], "SPP, the third argument"),
        (&["4", "scenes/nothing.toml", "64", output], "does not exist"),
        (&["0", SCENE, "64", output], "TASKS '0'"),
        (&["8", SCENE, "4", output], "would have no samples"),
        (&["4", SCENE, "64", "/no/such/folder/out.exr"], "cannot write OUTPUT"),
        (&["4", SCENE, "64", "out.txt"], "not an image"),
        (&["--cpus", "8", "4", SCENE, "64", output], "no node has more than 4 CPUs"),
        (&["--only", "7", "4", SCENE, "64", output], "the tasks are 0..3"),
    ];
    for (args, message) in cases {
        let (run, log) = submit(&dir, &bin, args);
        assert_eq!(run.code, Some(2), "{args:?}: {run:?}");
        assert!(run.stderr.contains(message), "{args:?}: {run:?}");
        assert!(log.is_empty(), "{args:?} submitted anyway: {log}");
    }
}

/// The value of `key` in a YAML mapping.
fn get<'a>(node: &'a yaml_rust2::Yaml, key: &str) -> &'a yaml_rust2::Yaml {
    &node[key]
}

/// The first container of a Job manifest: its command (command + args) and environment.
fn pod(manifest: &str) -> (Vec<String>, Vec<(String, String)>) {
    let text = std::fs::read_to_string(workspace_root().join("deploy/kubernetes").join(manifest)).unwrap();
    let docs = yaml_rust2::YamlLoader::load_from_str(&text).unwrap_or_else(|e| panic!("{manifest}: {e}"));
    let container = &get(get(get(get(&docs[0], "spec"), "template"), "spec"), "containers")[0];
    let strings = |node: &yaml_rust2::Yaml| -> Vec<String> {
        node.as_vec().map(|v| v.iter().map(|s| s.as_str().unwrap().to_owned()).collect()).unwrap_or_default()
    };
    let mut command = strings(get(container, "command"));
    // Kubernetes writes a literal $ as $$ in command and args.
    command.extend(strings(get(container, "args")).into_iter().map(|a| a.replace("$$", "$")));
    let env = get(container, "env")
        .as_vec()
        .map(|v| {
            v.iter()
                .map(|e| (e["name"].as_str().unwrap().to_owned(), e["value"].as_str().unwrap().to_owned()))
                .collect()
        })
        .unwrap_or_default();
    (command, env)
}

#[test]
fn the_kubernetes_jobs_commands_and_environments_render_and_merge() {
    let dir = scratch_dir("deploy-kubernetes");
    // The volume, /data in the pods: its scenes/ are the project's.
    let data = dir.join("data");
    std::fs::create_dir_all(&data).unwrap();
    std::os::unix::fs::symlink(workspace_root().join("scenes"), data.join("scenes")).unwrap();
    let (command, env) = pod("render-job.yaml");
    let on_volume = |value: &str| value.replace("/data", data.to_str().unwrap());
    let mut env: Vec<(String, String)> = env.into_iter().map(|(k, v)| (k, on_volume(&v))).collect();
    let value = |env: &[(String, String)], key: &str| env.iter().find(|(k, _)| k == key).map(|(_, v)| v.clone());
    let count: usize = value(&env, "COUNT").expect("COUNT in render-job.yaml").parse().unwrap();
    let manifest = std::fs::read_to_string(workspace_root().join("deploy/kubernetes/render-job.yaml")).unwrap();
    assert!(manifest.contains(&format!("completions: {count} ")), "completions and COUNT differ");
    // A small render with the manifest's options otherwise: the size and samples are the test's.
    for (key, small) in [("SPP", SPP), ("RTGI_ARGS", OPTIONS), ("RTGI_THREADS", "1")] {
        let entry = env.iter_mut().find(|(k, _)| k == key).unwrap_or_else(|| panic!("{key} in render-job.yaml"));
        entry.1 = small.to_owned();
    }
    let scene = value(&env, "SCENE").unwrap();
    let expected = single_render(&dir, OPTIONS);
    // The image has render-part.sh on its PATH; here it is in deploy/.
    let path = format!("{}:{}", workspace_root().join("deploy").display(), std::env::var("PATH").unwrap_or_default());
    for index in 0..count {
        let run: Run = Command::new(&command[0])
            .args(&command[1..])
            .current_dir(&dir)
            .env("PATH", &path)
            .env("RTGI", RTGI)
            .envs(env.iter().map(|(k, v)| (k, v)))
            .env("JOB_COMPLETION_INDEX", index.to_string())
            .output()
            .unwrap()
            .into();
        assert!(run.success, "index {index} of {count}, scene {scene}: {run:?}");
    }
    // The merge Job's command, rtgi being on the image's PATH.
    let rtgi_dir = dir.join("image-bin");
    std::fs::create_dir_all(&rtgi_dir).unwrap();
    std::os::unix::fs::symlink(RTGI, rtgi_dir.join("rtgi")).unwrap();
    let (merge_command, _) = pod("merge-job.yaml");
    let merge_command: Vec<String> = merge_command.iter().map(|a| on_volume(a)).collect();
    let run: Run = Command::new(&merge_command[0])
        .args(&merge_command[1..])
        .current_dir(&dir)
        .env("PATH", format!("{}:{path}", rtgi_dir.display()))
        .output()
        .unwrap()
        .into();
    assert!(run.success, "{run:?}");
    let merged = std::fs::read_dir(&data)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "exr"))
        .expect("the merge Job's image on the volume");
    assert_eq!(std::fs::read(merged).unwrap(), expected);
}
