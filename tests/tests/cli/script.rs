//! `rtgi script` and `rtgi repl`: the course framework's command language.
//! A script renders the bytes of the `rtgi render` command it prints, for
//! every algorithm; the framework's error rules hold, with messages naming
//! the file, the line and the command; every command of the language is
//! understood; and the scripts of the course's stages, in `scenes/course/`,
//! run on the shared scenes.

use std::path::{Path, PathBuf};
use std::process::Command;

use super::RTGI;
use rtgi_tests::{Run, run_cli, run_cli_with_input, scratch_dir, shared_scenes, workspace_root};

/// The team's Cornell box (millimetres), from the workspace root.
const BOX: &str = "scenes/cornell-box/cornell-box.obj";

/// Writes `text` as `NAME.rtgi` in `dir` and runs it with `extra` options.
fn script(dir: &Path, name: &str, text: &str, extra: &[&str]) -> Run {
    let path = dir.join(format!("{name}.rtgi"));
    std::fs::write(&path, text).unwrap();
    let mut args = vec!["script", path.to_str().unwrap()];
    args.extend(extra);
    run_cli(RTGI, &args)
}

/// A camera on the team's box, its structure committed, small and quick.
fn boxed(dir: &Path, body: &str) -> String {
    format!(
        "at 278 273 -800\nlook 0 0 1\nup 0 1 0\nload {BOX}\nraytracer bbvh sah 4\ncommit\nresolution 40 30\n\
         sppx 4\n{body}\noutfile {}\nrun\n",
        dir.join("script.png").display()
    )
}

#[test]
fn a_script_writes_the_bytes_of_the_render_command_it_prints_for_every_algorithm() {
    let dir = scratch_dir("script-identity");
    let light = "pointlight pos 278 500 280 col 40000 40000 40000";
    let cases = [
        ("primary", "algo primary".to_owned()),
        ("local", format!("{light}\nalgo local")),
        ("direct-uniform", "algo direct\nis uniform".to_owned()),
        ("direct-cosine", "algo direct\nis cosine".to_owned()),
        ("direct-light", format!("{light}\nalgo direct\nis light")),
        ("direct-brdf", "algo direct\nis brdf".to_owned()),
        ("direct-mis", "algo direct/mis".to_owned()),
        ("simple-pt", "algo simple-pt\npath len 5\npath rr-start 1\npath bounce cosine".to_owned()),
        ("pt", "algo pt\npath mis on\npath len 6".to_owned()),
        ("pt-no-mis", format!("{light}\nalgo pt\npath bounce uniform")),
        ("pt-denoised", "denoise on\nalgo pt\npath len 6".to_owned()),
    ];
    for (name, body) in cases {
        let run = script(&dir, name, &boxed(&dir, &body), &[]);
        assert!(run.success, "{name}: {run:?}");
        let line = run.stdout.lines().find_map(|l| l.strip_prefix("the same as  rtgi ")).unwrap_or_else(|| {
            panic!("{name}: the script prints its rtgi render command: {run:?}");
        });
        // The course's images keep their noise unless `denoise on` asks otherwise.
        let denoise = if name == "pt-denoised" { "--denoise on" } else { "--denoise off" };
        assert!(line.contains(denoise), "{name}: {line}");
        let script_image = std::fs::read(dir.join("script.png")).unwrap();
        let rays = |stdout: &str| {
            stdout.lines().find_map(|l| l.strip_prefix("rays")).map(|r| r.split_whitespace().next().unwrap().to_owned())
        };
        let script_rays = rays(&run.stdout);
        // The printed command, writing elsewhere.
        let cli_output = dir.join(format!("{name}-cli.png"));
        let mut args: Vec<String> = line.split_whitespace().map(str::to_owned).collect();
        let at = args.iter().position(|a| a == "--output").unwrap();
        args[at + 1] = cli_output.display().to_string();
        let run = run_cli(RTGI, &args.iter().map(String::as_str).collect::<Vec<_>>());
        assert!(run.success, "{name}: {run:?}");
        assert!(script_image == std::fs::read(&cli_output).unwrap(), "{name}: the script and `rtgi {line}` differ");
        // And what it measures is the same work: the rays it traced.
        assert!(
            script_rays.is_some() && script_rays == rays(&run.stdout),
            "{name}: rays {script_rays:?} against {run:?}"
        );
    }
}

#[test]
fn a_script_renders_the_same_bytes_on_one_thread_and_on_all() {
    let dir = scratch_dir("script-threads");
    let text = boxed(&dir, "algo pt\npath mis on");
    let mut images = Vec::new();
    for threads in ["1", "2"] {
        let run = script(&dir, "pt", &text, &["--threads", threads]);
        assert!(run.success, "{run:?}");
        images.push(std::fs::read(dir.join("script.png")).unwrap());
    }
    assert!(images[0] == images[1]);
    // 'omp off' is one thread too, and an EXR output keeps the floats.
    let exr = dir.join("pt.exr");
    let run = script(&dir, "omp", &format!("omp off\n{text}outfile {}\nrun\n", exr.display()), &[]);
    assert!(run.success && run.stdout.contains("--threads 1"), "{run:?}");
    assert!(exr.is_file());
}

#[test]
fn run_is_refused_until_a_scene_a_tracer_a_commit_and_an_algorithm_exist() {
    let dir = scratch_dir("script-run-rules");
    let run = script(&dir, "bare", "echo start\nrun\necho never\n", &[]);
    assert_eq!(run.code, Some(1), "{run:?}");
    assert!(run.stdout.contains("start") && !run.stdout.contains("never"), "{run:?}");
    assert!(
        run.stderr.contains(
            "bare.rtgi:2: 'run': run needs a scene loaded (load FILE), a ray tracer set (raytracer \
             ...), an acceleration structure built (commit), an algorithm set (algo ...) first"
        ),
        "{run:?}"
    );
    // Loading, changing the tracer or its BVH options after commit
    // out-dates the structure; the camera, the algorithm and materials do not.
    let head = format!("load {BOX}\nraytracer bbvh\ncommit\nalgo primary\nresolution 8 8\n");
    for (change, what) in [
        (format!("load {BOX}"), "the scene changed"),
        ("raytracer seq".to_owned(), "the ray tracer changed"),
        ("bvh sm".to_owned(), "the ray tracer changed"),
        ("bvh triangles multiple 4".to_owned(), "the ray tracer changed"),
    ] {
        let run = script(&dir, "stale", &format!("{head}{change}\nrun\n"), &[]);
        assert_eq!(run.code, Some(1), "{change}: {run:?}");
        let expected = format!(
            "stale.rtgi:7: 'run': {what} after the last commit: acceleration structure is out-dated: commit again"
        );
        assert!(run.stderr.contains(&expected), "{change}: {run:?}");
        let run = script(
            &dir,
            "fresh",
            &format!("{head}{change}\ncommit\nrun\n"),
            &["-o", dir.join("x.png").to_str().unwrap()],
        );
        assert!(run.success, "{change}, committed again: {run:?}");
    }
    let run = script(
        &dir,
        "camera",
        &format!("{head}at 1 2 3\nalgo direct\nmaterial select white\nmaterial albedo 0 1 0\nrun\n"),
        &["-o", dir.join("x.png").to_str().unwrap()],
    );
    assert!(run.success, "{run:?}");
    // Commit needs a scene and a tracer; local needs a point light.
    let run = script(&dir, "commit", "raytracer seq\ncommit\n", &[]);
    assert!(run.stderr.contains("commit.rtgi:2: 'commit': there is no scene data to work with"), "{run:?}");
    let run = script(&dir, "commit", &format!("load {BOX}\ncommit\n"), &[]);
    assert!(run.stderr.contains("there is no ray tracer to commit the scene data to"), "{run:?}");
    let run = script(&dir, "local", &format!("{head}algo local\nrun\n"), &[]);
    assert!(run.stderr.contains("algo local shades with a point light"), "{run:?}");
}

#[test]
fn a_bad_line_names_the_file_the_line_and_the_command_and_stops_the_script() {
    let dir = scratch_dir("script-bad-lines");
    for (line, expected) in [
        ("at 1 2", "expects 3 numbers, X Y Z (got '1 2')"),
        ("teleport 1 2 3", "unknown command"),
        ("raytracer kd-tree", "there is no ray tracer called 'kd-tree'"),
        ("algo photon-map", "there is no gi algorithm called 'photon-map'"),
        ("is light", "'is' chooses how algo direct samples (select it first)"),
        ("path len 4", "'path' sets up the path tracers"),
        ("bvh statistics", "'bvh' sets up the course's BVH tracers"),
        ("material albedo 1 0 0", "no material selected"),
        ("material select nothing-called-so", "no material called 'nothing-called-so'"),
        ("load no/such/scene.obj", "no/such/scene.obj: no such file"),
        ("skylight scale 2", "there is no skylight to scale"),
        ("up 0 1 0\nup 0 0 1", "cannot set the scene's up vector twice; did you mean camup?"),
        ("material brdf velvet", "No such brdf defined: velvet"),
        ("laod scenes/cornell-box.toml", "unknown command; did you mean 'load'?"),
        ("algo direct/mis\nis light", "algo direct/mis samples the light and the BRDF and weighs them"),
        (
            "raytracer naive-bvh\nbvh triangles multiple 4",
            "naive-bvh splits at the object median with one triangle a leaf",
        ),
        ("camup 0 0 0", "the direction must not be 0 0 0"),
        ("with optix {\necho skipped", "the block has no closing '}' on a line of its own"),
    ] {
        let text = format!("echo first\n{line}\necho never\n");
        let run = script(&dir, "bad", &text, &[]);
        assert_eq!(run.code, Some(1), "{line}: {run:?}");
        // The line at fault: the last, or the block that never closes.
        let last = line.lines().find(|l| l.starts_with("with")).unwrap_or_else(|| line.lines().last().unwrap());
        let number = text.lines().position(|l| l == last).unwrap() + 1;
        let named = format!("bad.rtgi:{number}: '{last}': ");
        assert!(run.stderr.contains(&named) && run.stderr.contains(expected), "{line}: {run:?}");
        assert!(run.stdout.contains("first") && !run.stdout.contains("never"), "{line}: the script stops there");
        assert!(!run.stderr.contains("panicked"), "{line}: {run:?}");
    }
    let run = run_cli(RTGI, &["script", "no-such-script.rtgi"]);
    assert_eq!(run.code, Some(1), "{run:?}");
    assert!(run.stderr.contains("no-such-script.rtgi: cannot read"), "{run:?}");
}

#[test]
fn features_rtgi_lacks_are_said_in_one_line_and_the_script_goes_on() {
    let dir = scratch_dir("script-unavailable");
    let text = "with cuda {\necho inside\nplatform cuda\n}\ndenoise on\ndenoise on\nplatform opengl\npreview-offset 4\n\
                algo primary-wf\nmove-speed 3\nskytest sky.png 100\nadd-scene-step x\ndisable gl\nwith gl {\n}\necho after\n";
    let run = script(&dir, "lacks", text, &[]);
    assert!(run.success, "{run:?}");
    assert!(!run.stdout.contains("inside") && run.stdout.contains("after"), "{run:?}");
    assert!(run.stdout.contains("Skipping a block due to missing cuda"), "{run:?}");
    for said in [
        "platform opengl: rtgi has no GPU or wavefront platforms",
        "preview-offset: rtgi has no preview window",
        "algo primary-wf: rtgi has no wavefront algorithms; algo primary renders what it renders",
        "skytest: rtgi has no debug images of the sky's distribution",
        "add-scene-step: rtgi has no wavefront steps",
    ] {
        assert!(run.stderr.contains(said), "{said}: {run:?}");
    }
    // The preview is said once, for both of its commands.
    assert!(!run.stderr.contains("move-speed"), "{run:?}");
}

#[test]
fn the_prompt_reports_a_bad_line_and_goes_on() {
    let input = b"at 1\necho still here\nat 1 2 3\nat\nhistory\nquit\necho gone\n";
    let run = run_cli_with_input(RTGI, &["repl"], input);
    assert!(run.success, "{run:?}");
    assert!(run.stderr.contains("error: 'at 1': expects 3 numbers"), "{run:?}");
    assert!(run.stdout.contains("still here\n1 2 3\n"), "{run:?}");
    // History holds the lines that ran, bad ones too (the framework's).
    assert!(run.stdout.contains("at 1\necho still here\nat 1 2 3\nat\n"), "{run:?}");
    assert!(!run.stdout.contains("gone"), "{run:?}");
}

#[test]
fn older_and_other_spellings_of_the_course_are_taken_as_it_meant_them() {
    let dir = scratch_dir("script-spellings");
    // `is mis` (older scripts), a wavefront algorithm, a byte-order mark.
    let text =
        format!("{}# saved by an editor that marks UTF-8\n{}", "\u{feff}", boxed(&dir, "algo direct-wf\nis mis"));
    let run = script(&dir, "older", &text, &[]);
    assert!(run.success, "{run:?}");
    assert!(run.stderr.contains("algo direct-wf: rtgi has no wavefront algorithms; algo direct renders"), "{run:?}");
    assert!(run.stderr.contains("is mis: algo direct now weighs light and BRDF samples"), "{run:?}");
    // MIS is `rtgi render`'s default strategy: the printed command names no other.
    let command = run.stdout.lines().find(|l| l.starts_with("the same as")).unwrap_or_default();
    assert!(command.contains("--integrator direct") && !command.contains("--direct-strategy"), "{run:?}");
    // Under direct/mis, `is mis` says what it already does.
    let run = script(&dir, "mis", &boxed(&dir, "algo direct/mis\nis mis"), &[]);
    assert!(run.success && !run.stderr.contains("is mis:"), "{run:?}");
}

#[test]
fn a_script_error_before_the_prompt_is_reported_and_the_prompt_opens() {
    let dir = scratch_dir("script-then-prompt");
    let path = dir.join("bad.rtgi");
    std::fs::write(&path, "at 1 2 3\nat 1 2\n").unwrap();
    let run = run_cli_with_input(RTGI, &["script", path.to_str().unwrap(), "-l"], b"at\nquit\n");
    assert!(run.success, "{run:?}");
    assert!(run.stderr.contains("bad.rtgi:2: 'at 1 2': expects 3 numbers"), "{run:?}");
    assert!(run.stdout.contains("1 2 3"), "the prompt goes on in the script's session: {run:?}");
}

#[test]
fn warnings_in_a_script_name_its_commands() {
    let dir = scratch_dir("script-phrasing");
    // The box's lamp switched off, no other light: black.
    let run = script(&dir, "dark", &boxed(&dir, "material select light\nmaterial emissive 0 0 0\nalgo direct"), &[]);
    assert!(run.success, "{run:?}");
    assert!(
        run.stderr.contains("almost black") && run.stderr.contains("add light (pointlight or skylight load)"),
        "{run:?}"
    );
    assert!(run.stderr.contains("move the camera (at (and look))") && !run.stderr.contains("--"), "{run:?}");
}

#[test]
fn every_command_of_the_language_is_understood() {
    let dir = scratch_dir("script-every-command");
    // A course sky: bright towards +X, as the course's longitude puts it.
    let mut sky = Vec::new();
    let (w, h) = (8i32, 4i32);
    sky.extend_from_slice(&w.to_le_bytes());
    sky.extend_from_slice(&h.to_le_bytes());
    for _y in 0..h {
        for x in 0..w {
            let v: f32 = if x == 0 { 4.0 } else { 0.5 };
            for _ in 0..3 {
                sky.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    std::fs::write(dir.join("sky.floats"), sky).unwrap();
    let texture = image::RgbImage::from_pixel(4, 4, image::Rgb([255, 0, 0]));
    texture.save(dir.join("red.png")).unwrap();
    let out = |name: &str| dir.join(name).display().to_string();
    let text = format!(
        "# every command, in the course's style
// comments either way

at
at 278 273 -800
look 0 0 1
up 0 1 0
camup 0 1 0
at
look
up
camup
print-cam
modelpath {folder}
modelmatrix 1 0 0 0  0 1 0 0  0 0 1 0  0 0 0 1
modeltrafo shift 0 0 0
modeltrafo translate 0 0 0
modeltrafo rotate y 0
modeltrafo scale 1 1 1
material blacklist nothing
default-brdf lambert
load {BOX} box
default-brdf layered-phong
material list
material select white
material albedo 0.2 0.6 0.2
material emissive 0 0 0
material roughness 0.1
material ior 1.4
material texture red.png
material texture drop
material brdf phong
material show
pointlight pos 278 500 280 col 40000 40000 40000
pointlight replace pos 278 540 280 col 50000 50000 50000
skylight load sky.floats 2
skylight scale 3
resolution 24 18
sppx 2
outfile {first}
raytracer seq
raytracer naive-bvh
raytracer bbvh
raytracer bbvh om
raytracer bbvh sm
raytracer bbvh sah
raytracer bbvh sah 16
raytracer embree
raytracer sah
raytracer bbvh indexed
bvh om
bvh sm
bvh sah 12
bvh triangles single
bvh triangles multiple 3
commit
bvh statistics
bvh export 2 {boxes}
algo primary
run
algo info
algo local
algo direct
is uniform
is cosine
is brdf
is light
algo direct/mis
algo simple-pt
path len 3
path rr-start 1
path bounce uniform
path bounce cosine
path bounce brdf
algo pt
path mis on
path mis off
path mis on
outfile {second}
run
echo done with the runs
stats print
stats clear
stats print
mem-stats
omp off
omp on
platform
platform none
denoise off
history
exit
echo after exit
",
        folder = dir.display(),
        first = out("first.png"),
        second = out("second.png"),
        boxes = out("boxes.obj"),
    );
    let run = script(&dir, "every", &text, &[]);
    assert!(run.success, "{run:?}");
    let o = &run.stdout;
    // The camera prints as the course prints it.
    assert!(
        o.contains("0 0 0\n278 273 -800\n0 0 1\n0 1 0\n0 1 0\nat 278 273 -800\nlook 0 0 1\nup 0 1 0\ncamup 0 1 0\n"),
        "{o}"
    );
    assert!(o.contains("white\nred\ngreen\nlight\n"), "material list: {o}");
    assert!(
        o.contains("albedo     0.2 0.6 0.2\nalbedo-tex none\nemissive   0 0 0\nroughness  0.1")
            && o.contains("brdf       phong"),
        "material show: {o}"
    );
    let per_leaf = o.lines().find_map(|l| l.strip_prefix("triangles   per leaf: min ")).expect("bvh statistics");
    let max: usize = per_leaf.split(", max ").nth(1).unwrap().split(',').next().unwrap().parse().unwrap();
    assert!(o.contains("leaves      ") && (1..=3).contains(&max), "bvh triangles multiple 3: {per_leaf}");
    assert!(o.contains("wrote 7 boxes of levels 0 to 2"), "{o}");
    assert!(std::fs::read_to_string(dir.join("boxes.obj")).unwrap().contains("g level_2"));
    assert!(
        o.contains("run 1: ") && o.contains("run 2: ") && o.contains("no runs since the last 'stats clear'"),
        "{o}"
    );
    assert!(o.contains("vertices") && o.contains("structure   sah"), "mem-stats: {o}");
    assert!(o.contains("platform: none"), "{o}");
    assert!(o.contains("mem-stats\nomp off\nomp on\nplatform\nplatform none\ndenoise off\n"), "history: {o}");
    assert!(!o.contains("after exit"), "{o}");
    // The second run lit by the point light that replaced the first and by the scaled sky.
    assert!(o.contains("--light point:278,540,280:1:50000,50000,50000") && !o.contains("point:278,500,280"), "{o}");
    assert!(o.contains(&format!("--environment {} --environment-scale 3", dir.join("sky.floats").display())), "{o}");
    assert!(o.contains("--sah-bins 13 --sah-axes longest") && o.contains("--leaf-size 3"), "{o}");
    assert!(dir.join("first.png").is_file() && dir.join("second.png").is_file());
    // Said once each: BRDFs that differ from the course's, and algo info.
    assert_eq!(run.stderr.matches("brdf phong: rtgi has no Phong lobe").count(), 1, "{run:?}");
    assert!(run.stderr.contains("algo info: rtgi has no pixel inspector"), "{run:?}");
    assert!(run.stderr.contains("algo local: rtgi shades with the point light's intensity"), "{run:?}");
}

#[test]
fn material_edits_and_model_transforms_change_what_is_rendered() {
    let dir = scratch_dir("script-edits");
    let mean = |path: &Path| {
        let image = image::open(path).unwrap().to_rgb8();
        let sum: u64 = image.pixels().map(|p| p.0.iter().map(|&c| c as u64).sum::<u64>()).sum();
        sum as f64 / (3 * image.width() * image.height()) as f64
    };
    let render = |name: &str, before_load: &str, after_load: &str| {
        let out = dir.join(format!("{name}.png"));
        let text = format!(
            "at 278 273 -800\nlook 0 0 1\nup 0 1 0\n{before_load}\nload {BOX}\n{after_load}\nraytracer bvh8\ncommit\n\
             algo primary\nresolution 32 32\noutfile {}\nrun\n",
            out.display()
        );
        let run = script(&dir, name, &text, &[]);
        assert!(run.success, "{name}: {run:?}");
        (mean(&out), run)
    };
    let (plain, run) = render("plain", "", "");
    assert!(run.stdout.contains("the same as  rtgi render"), "{run:?}");
    // The whole box moved out of view: black.
    let (moved, run) = render("moved", "modeltrafo shift 0 5000 0", "");
    assert!(moved < 0.05 * plain, "{moved} against {plain}");
    assert!(run.stdout.contains("(with model transforms, which no option expresses)"), "{run:?}");
    // The same move as a matrix, column by column as the framework reads it.
    let (matrix, _) = render("matrix", "modelmatrix 1 0 0 0  0 1 0 0  0 0 1 0  0 5000 0 1", "");
    assert_eq!(matrix, moved);
    // A quarter turn about y keeps the box in view, turned: another image.
    let (turned, _) =
        render("turned", "modeltrafo translate 278 0 280\nmodeltrafo rotate y 90\nmodeltrafo shift -278 0 -280", "");
    assert!(turned > 0.2 * plain && turned != plain, "{turned} against {plain}");
    // The walls and blocks black: darker.
    let all_black = "material select white\nmaterial albedo 0 0 0\nmaterial select red\nmaterial albedo 0 0 0\n\
                     material select green\nmaterial albedo 0 0 0";
    let (darker, _) = render("darker", "", all_black);
    assert!(darker < plain, "{darker} against {plain}");
    // Blacklisted before the load, the white walls and blocks are gone.
    let (blacklisted, run) = render("blacklisted", "material blacklist white", "");
    assert!(blacklisted < plain && run.stdout.contains("blacklisted materials"), "{blacklisted}: {run:?}");
}

/// The course's stages, as `scenes/course/*.rtgi` write them: each runs on
/// the shared scenes, and the four structures of stage 2 give the same image.
#[test]
fn the_course_stage_scripts_run_on_the_shared_scenes() {
    let scenes = shared_scenes();
    if !scenes.join("cornell-box/CornellBox-Original.obj").is_file()
        || !scenes.join("sponza-dabrovic/sponza.obj").is_file()
    {
        rtgi_tests::skip_without(
            rtgi_tests::Requirement::Scenes,
            &format!("the shared scenes are not at {} (set {})", scenes.display(), rtgi_tests::SCENES_VARIABLE),
        );
        return;
    }
    let dir = scratch_dir("script-stages");
    let folder = workspace_root().join("scenes/course");
    let mut stages: Vec<PathBuf> = std::fs::read_dir(&folder)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "rtgi"))
        .collect();
    stages.sort();
    assert_eq!(stages.len(), 6, "one script a stage: {stages:?}");
    for stage in &stages {
        let run: Run = Command::new(RTGI)
            .args(["script", stage.to_str().unwrap(), "--modelpath", scenes.to_str().unwrap()])
            .current_dir(&*dir)
            .output()
            .unwrap()
            .into();
        assert!(run.success, "{}: {run:?}", stage.display());
        assert!(!run.stderr.contains("almost white"), "{}: {run:?}", stage.display());
    }
    let written: Vec<String> =
        std::fs::read_dir(&*dir).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    for stage in 1..=6 {
        assert!(
            written.iter().any(|f| f.starts_with(&format!("stage{stage}-")) && f.ends_with(".png")),
            "stage {stage} wrote no image: {written:?}"
        );
    }
    let bvh: Vec<Vec<u8>> = ["naive-bvh", "bbvh-sm", "bbvh-sah", "bvh8"]
        .iter()
        .map(|name| std::fs::read(dir.join(format!("stage2-{name}.png"))).unwrap())
        .collect();
    assert!(bvh.iter().all(|image| *image == bvh[0]), "every structure finds the linear scan's hits");
}
