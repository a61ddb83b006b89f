//! The cluster examples in deploy/ run as far as this machine allows: the
//! Slurm array and merge scripts are run by hand with the variables Slurm
//! would set, and the Kubernetes pod's command is run with the index the
//! Job controller would give. The merged image must be the single render's bytes.

use std::path::{Path, PathBuf};
use std::process::Command;

use rtgi_tests::{Run, scratch_dir, workspace_root};

const RTGI: &str = env!("CARGO_BIN_EXE_rtgi-under-test");

const SCENE: &str = "scenes/cornell-box.toml";
const SPP: &str = "24";
const OPTIONS: &str = "--width 40 --height 30 --seed 4";

fn script(path: &str, parts: &Path, env: &[(&str, &str)]) -> Run {
    Command::new("bash")
        .arg(workspace_root().join(path))
        .current_dir(workspace_root())
        .env("RTGI", RTGI)
        .env("SCENE", SCENE)
        .env("SPP", SPP)
        .env("PARTS", parts)
        .env("RTGI_ARGS", OPTIONS)
        .env("DEPLOY_DIR", workspace_root().join("deploy"))
        .envs(env.iter().copied())
        .output()
        .expect("cannot run bash")
        .into()
}

fn single_render(dir: &Path) -> Vec<u8> {
    let out = dir.join("single.exr");
    let mut args = vec!["render", SCENE, "--spp", SPP, "-o", out.to_str().unwrap()];
    args.extend(OPTIONS.split(' '));
    let run = rtgi_tests::run_cli(RTGI, &args);
    assert!(run.success, "{run:?}");
    std::fs::read(out).unwrap()
}

fn merge(parts: &Path, output: &Path) -> Run {
    script("deploy/slurm/merge.sbatch", parts, &[("OUTPUT", output.to_str().unwrap())])
}

#[test]
fn a_slurm_array_of_five_tasks_merges_to_the_single_render() {
    let dir = scratch_dir("deploy-slurm");
    let expected = single_render(&dir);
    let parts: PathBuf = dir.join("parts");
    // Task 2 first stops at a time limit too short for its share (exit 75,
    // checkpoint kept, no part), then is run again and resumes.
    let stopped = script(
        "deploy/slurm/render.sbatch",
        &parts,
        &[("SLURM_ARRAY_TASK_ID", "2"), ("ARRAY_COUNT", "5"), ("TIME_LIMIT", "0.001")],
    );
    assert_eq!(stopped.code, Some(75), "{stopped:?}");
    assert!(parts.join("part-2.checkpoint.accum").exists(), "{stopped:?}");
    assert!(!parts.join("part-2.accum").exists());
    let early = merge(&parts, &dir.join("early.exr"));
    assert!(!early.success, "merged without the parts: {early:?}");
    for task in ["0", "1", "2", "3", "4"] {
        let run = script(
            "deploy/slurm/render.sbatch",
            &parts,
            &[("SLURM_ARRAY_TASK_ID", task), ("SLURM_ARRAY_TASK_COUNT", "5")],
        );
        assert!(run.success, "task {task}: {run:?}");
    }
    assert!(!parts.join("part-2.checkpoint.accum").exists(), "the finished task keeps its checkpoint");
    // Submitting the array again skips finished tasks.
    let again =
        script("deploy/slurm/render.sbatch", &parts, &[("SLURM_ARRAY_TASK_ID", "0"), ("SLURM_ARRAY_TASK_COUNT", "5")]);
    assert!(again.success && again.stdout.contains("already done"), "{again:?}");
    let output = dir.join("merged.exr");
    let run = merge(&parts, &output);
    assert!(run.success, "{run:?}");
    assert_eq!(std::fs::read(&output).unwrap(), expected);
}

#[test]
fn the_kubernetes_pods_command_renders_its_index() {
    let dir = scratch_dir("deploy-kubernetes");
    let expected = single_render(&dir);
    let parts = dir.join("parts");
    std::fs::create_dir_all(&parts).unwrap();
    let manifest = std::fs::read_to_string(workspace_root().join("deploy/kubernetes/render-job.yaml")).unwrap();
    let command = manifest
        .lines()
        .find_map(|l| l.trim().strip_prefix("command: [\"/bin/sh\", \"-c\", '")?.strip_suffix("']"))
        .expect("the pod's shell command in render-job.yaml");
    // The image has render-part.sh on its PATH; here it is in deploy/.
    let command =
        command.replace("render-part.sh", &workspace_root().join("deploy/render-part.sh").display().to_string());
    for index in ["0", "1", "2"] {
        let run: Run = Command::new("/bin/sh")
            .args(["-c", &command])
            .current_dir(workspace_root())
            .envs([("RTGI", RTGI), ("SCENE", SCENE), ("SPP", SPP), ("RTGI_ARGS", OPTIONS)])
            .env("PARTS", &parts)
            .envs([("JOB_COMPLETION_INDEX", index), ("COUNT", "3")])
            .output()
            .unwrap()
            .into();
        assert!(run.success, "index {index}: {run:?}");
    }
    let output = dir.join("merged.exr");
    let run = merge(&parts, &output);
    assert!(run.success, "{run:?}");
    assert_eq!(std::fs::read(&output).unwrap(), expected);
}
