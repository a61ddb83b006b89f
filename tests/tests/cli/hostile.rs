//! The `rtgi` command given hostile input: option values out of range, a
//! standard output whose reader goes away, ray files that are not ray
//! files. It must never panic, and its errors must say what to do instead.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Stdio};

use super::{RTGI, path_str, rtgi};
use rtgi_accel::{Accel, LinearScan};
use rtgi_image::HdrImage;
use rtgi_math::{Ray, Rng, Vec3};
use rtgi_render::rays::uniform_sphere;
use rtgi_scene::Scene;
use rtgi_tests::{Run, run_cli_with_input, scratch_dir, workspace_root};

const BOX: &str = "scenes/cornell-box.toml";

/// Each value is refused by the parser, as clap refuses (exit status 2),
/// before the scene is read: the scene given does not exist, so any later
/// refusal would name it instead. The one line names the option and the
/// values it takes.
#[test]
fn out_of_range_option_values_are_refused_with_the_allowed_range() {
    let dir = scratch_dir("hostile-options");
    let png = dir.join("out.png");
    let missing = "no-such-scene.obj";
    let render = |extra: &[&str]| -> Vec<String> {
        let mut args = vec!["render", missing, "-o", path_str(&png), "--width", "8", "--height", "8", "--spp", "1"];
        args.extend_from_slice(extra);
        args.into_iter().map(str::to_owned).collect()
    };
    let owned = |args: &[&str]| -> Vec<String> { args.iter().map(|a| (*a).to_owned()).collect() };
    let heatmap = dir.join("heat.png");
    let cases: Vec<(Vec<String>, &str, &str)> = vec![
        (render(&["--exposure", "nan"]), "--exposure", "from -64 to 64"),
        (render(&["--exposure", "inf"]), "--exposure", "from -64 to 64"),
        (render(&["--exposure", "-1e9"]), "--exposure", "from -64 to 64"),
        (render(&["--traversal-cost", "-5"]), "--traversal-cost", "greater than 0"),
        (render(&["--traversal-cost", "nan"]), "--traversal-cost", "greater than 0"),
        (render(&["--traversal-cost", "0"]), "--traversal-cost", "greater than 0"),
        (render(&["--fov", "inf"]), "--fov", "less than 180"),
        (render(&["--fov", "-10"]), "--fov", "greater than 0"),
        (render(&["--fov", "180"]), "--fov", "less than 180"),
        (render(&["--background", "nan,0,0"]), "--background", "finite"),
        (render(&["--background", "-1,0,0"]), "--background", "at least 0"),
        (render(&["--clamp-indirect", "-1"]), "--clamp-indirect", "greater than 0"),
        (render(&["--clamp-indirect", "inf"]), "--clamp-indirect", "greater than 0"),
        (render(&["--at", "nan,0,0"]), "--at", "finite"),
        (render(&["--look", "0,inf,0"]), "--look", "finite"),
        (render(&["--up", "0,0,0"]), "--up", "not all 0"),
        (render(&["--environment", "-1,0,0"]), "--environment", "negative"),
        (render(&["--light", "point:nan,0,0:1"]), "--light", "finite"),
        (render(&["--light", "point:0,1,0:nan"]), "--light", "non-negative"),
        (render(&["--light", "point:0,1,0:-3"]), "--light", "non-negative"),
        (render(&["--light", "point:0,1,0:5:-1,0,0"]), "--light", "at least 0"),
        (render(&["--light", "directional:0,0,0:1"]), "--light", "zero"),
        (render(&["--light", "spot:0,1,0:0,-1,0:5:30:inf"]), "--light", "non-negative"),
        (
            owned(&["heatmap", missing, "-o", path_str(&heatmap), "--width", "8", "--height", "8", "--scale", "nan"]),
            "--scale",
            "greater than 0",
        ),
        (
            owned(&["heatmap", missing, "-o", path_str(&heatmap), "--width", "8", "--height", "8", "--scale", "-2"]),
            "--scale",
            "greater than 0",
        ),
        (owned(&["bench", missing, "--traversal-cost", "inf"]), "--traversal-cost", "greater than 0"),
        (owned(&["info", missing, "--clamp-indirect", "nan"]), "--clamp-indirect", "greater than 0"),
        (owned(&["verify", missing, "--traversal-cost", "-1"]), "--traversal-cost", "greater than 0"),
    ];
    let mut failures = Vec::new();
    for (args, option, allowed) in &cases {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let run = rtgi(&args);
        let lines: Vec<&str> = run.stderr.lines().filter(|l| !l.trim().is_empty()).collect();
        let ok = run.code == Some(2)
            && lines.len() == 1
            && lines[0].contains(option)
            && lines[0].contains(allowed)
            && !lines[0].contains(missing);
        if !ok {
            failures.push(format!("{args:?}: exit {:?}, stderr {:?}", run.code, run.stderr));
        }
    }
    assert!(!png.exists() && !heatmap.exists());
    assert!(failures.is_empty(), "{} of {} cases:\n{}", failures.len(), cases.len(), failures.join("\n"));
}

/// Runs `rtgi` with its standard output in a pipe whose read end is closed
/// after `lines` lines (at once for 0), as `rtgi ... | head -1` does; the
/// command must end with success, without a panic or an error. Returns what
/// it wrote to standard error (progress, for the commands that show it).
fn assert_quiet_when_the_pipe_closes(args: &[&str], lines: usize) -> String {
    let mut child = Command::new(RTGI)
        .args(args)
        .current_dir(workspace_root())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("cannot start the rtgi binary");
    let stdout = child.stdout.take().expect("stdout is piped");
    let mut reader = BufReader::new(stdout);
    for _ in 0..lines {
        let mut line = String::new();
        reader.read_line(&mut line).expect("cannot read the first lines");
        assert!(!line.is_empty(), "{args:?}: fewer than {lines} lines");
    }
    drop(reader);
    let output = child.wait_with_output().expect("cannot wait for rtgi");
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    let noise = ["panicked", "Broken pipe", "error"].iter().any(|n| stderr.contains(n));
    assert!(output.status.success() && !noise, "{args:?}: {:?}, stderr {stderr:?}", output.status);
    stderr
}

/// `rtgi bench` shows progress on standard error, and its table on
/// standard output only at the end: the reader is long gone by then.
#[test]
fn bench_ends_quietly_when_its_reader_goes_away() {
    let args = [
        "bench",
        "--accel",
        "sah",
        "--width",
        "8",
        "--height",
        "8",
        "--rays",
        "64",
        "--repeats",
        "1",
        "--leak-rays",
        "64",
        "--linear-rays",
        "16",
    ];
    let stderr = assert_quiet_when_the_pipe_closes(&args, 0);
    assert!(stderr.contains("measuring sah"), "{stderr}");
    // The JSON file asked for is written all the same.
    let json_dir = scratch_dir("hostile-pipe-bench");
    let json = json_dir.join("bench.json");
    let with_json = [&args[..], &["--json", path_str(&json)]].concat();
    assert_quiet_when_the_pipe_closes(&with_json, 0);
    let report: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert!(report["variants"].as_array().is_some_and(|v| v.len() == 1), "{report}");
}

/// A reader that stops early must not turn a failed verification into a
/// success: the failure is still reported, on standard error, with a
/// failing status.
#[test]
fn verify_still_fails_when_its_reader_goes_away() {
    let mut child = Command::new(RTGI)
        .args(["verify", "--rays", "20000", "--accel", "sah", "--traversal", "fast"])
        .current_dir(workspace_root())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let run: Run = child.wait_with_output().unwrap().into();
    assert_eq!(run.code, Some(1), "{run:?}");
    assert!(run.stderr.contains("do not all answer exactly") && !run.stderr.contains("panicked"), "{}", run.stderr);
}

/// An OBJ scene with one material per triangle: `rtgi info` prints a line
/// for each, far more than a pipe holds (64 KiB on Linux), so that the
/// command is still writing when the reader goes away.
fn scene_with_many_materials(dir: &Path, count: usize) -> std::path::PathBuf {
    let (mut obj, mut mtl) = (String::from("mtllib many.mtl\n"), String::new());
    for i in 0..count {
        let x = i as f32;
        obj += &format!("v {x} 0 0\nv {} 0 0\nv {x} 1 0\nusemtl material_{i}\nf -3 -2 -1\n", x + 1.0);
        mtl += &format!("newmtl material_{i}\nKd 0.5 0.5 0.5\n");
    }
    std::fs::write(dir.join("many.mtl"), mtl).unwrap();
    let path = dir.join("many.obj");
    std::fs::write(&path, obj).unwrap();
    path
}

#[test]
fn info_ends_quietly_when_its_reader_goes_away() {
    let dir = scratch_dir("hostile-pipe-info");
    let scene = scene_with_many_materials(&dir, 4000);
    assert_eq!(assert_quiet_when_the_pipe_closes(&["info", path_str(&scene)], 1), "");
    assert_eq!(assert_quiet_when_the_pipe_closes(&["info", path_str(&scene), "--json"], 1), "");
}

#[test]
fn compare_ends_quietly_when_its_reader_goes_away() {
    let dir = scratch_dir("hostile-pipe-compare");
    let (a, b) = (dir.join("a.exr"), dir.join("b.exr"));
    let mut image = HdrImage::new(4, 3);
    image.write(&a, &Default::default()).unwrap();
    image.set(1, 1, Vec3::ONE);
    image.write(&b, &Default::default()).unwrap();
    assert_eq!(assert_quiet_when_the_pipe_closes(&["compare", path_str(&a), path_str(&b)], 0), "");
    assert_eq!(assert_quiet_when_the_pipe_closes(&["compare", path_str(&a), path_str(&b), "--json"], 0), "");
}

fn encode(rays: &[Ray]) -> Vec<u8> {
    rays.iter()
        .flat_map(|r| {
            [r.origin.x, r.origin.y, r.origin.z, r.direction.x, r.direction.y, r.direction.z, r.t_min, r.t_max]
                .map(f32::to_le_bytes)
        })
        .flatten()
        .collect()
}

fn random_rays(count: usize) -> Vec<Ray> {
    let mut rng = Rng::new(11, 0);
    (0..count)
        .map(|_| {
            let origin = Vec3::new(rng.next_f32() * 550.0, rng.next_f32() * 540.0, rng.next_f32() * 550.0);
            Ray::new(origin, uniform_sphere(rng.next_f32(), rng.next_f32()))
        })
        .collect()
}

/// Asserts that a failed run wrote one line containing every `expected`
/// and left no hit file, finished or partial.
fn assert_refused(run: &Run, expected: &[&str], out: &Path) {
    assert!(run.code == Some(1), "exit {:?} (101 is a panic): {run:?}", run.code);
    let lines: Vec<&str> = run.stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "{:?}", run.stderr);
    for e in expected {
        assert!(lines[0].contains(e), "'{}' does not mention '{e}'", lines[0]);
    }
    assert!(!out.exists(), "{} was written", out.display());
    let leftovers: Vec<_> = std::fs::read_dir(out.parent().unwrap())
        .unwrap()
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().contains("partial"))
        .collect();
    assert!(leftovers.is_empty(), "left {leftovers:?}");
}

/// `/dev/zero` is an endless stream of rays with a zero direction: refused
/// at its first record, not read until memory runs out.
#[test]
fn trace_refuses_dev_zero_at_its_first_ray() {
    let dir = scratch_dir("hostile-zero");
    let out = dir.join("hits.bin");
    let run = rtgi(&["trace", BOX, "--rays", "/dev/zero", "--out", path_str(&out)]);
    assert_refused(&run, &["/dev/zero", "ray 0 ", "direction is zero"], &out);
}

/// A record that is no ray is refused, naming its index, and nothing is
/// written, not even the hits of the valid rays before it.
#[test]
fn trace_refuses_invalid_rays_naming_the_record() {
    let dir = scratch_dir("hostile-records");
    let good = random_rays(5);
    let bad = [
        (Ray::new(Vec3::new(f32::NAN, 1.0, 1.0), Vec3::Z), "origin"),
        (Ray::new(Vec3::new(1.0, f32::INFINITY, 1.0), Vec3::Z), "origin"),
        (Ray::new(Vec3::splat(100.0), Vec3::new(0.0, f32::NEG_INFINITY, 0.0)), "direction"),
        (Ray::new(Vec3::splat(100.0), Vec3::ZERO), "direction is zero"),
        (Ray::with_range(Vec3::splat(100.0), Vec3::Y, f32::NAN, 1.0), "range"),
        (Ray::with_range(Vec3::splat(100.0), Vec3::Y, 0.0, f32::NAN), "range"),
    ];
    for (i, (ray, what)) in bad.into_iter().enumerate() {
        let mut rays = good.clone();
        rays.push(ray);
        rays.extend(random_rays(3));
        let path = dir.join(format!("bad{i}.bin"));
        std::fs::write(&path, encode(&rays)).unwrap();
        let out = dir.join("hits.bin");
        let run = rtgi(&["trace", BOX, "--rays", path_str(&path), "--out", path_str(&out)]);
        assert_refused(&run, &[&format!("bad{i}.bin"), "ray 5 ", what], &out);
    }
}

/// A stream's size is known only at its end: a trailing part of a record
/// is refused there, with the size and the record size.
#[test]
fn trace_refuses_a_stream_that_ends_inside_a_record() {
    let dir = scratch_dir("hostile-stream");
    let out = dir.join("hits.bin");
    let mut bytes = encode(&random_rays(2));
    bytes.extend_from_slice(&[0; 8]);
    let run = run_cli_with_input(RTGI, &["trace", BOX, "--rays", "/dev/stdin", "--out", path_str(&out)], &bytes);
    assert_refused(&run, &["72 bytes", "multiple of 32"], &out);
}

/// A file of more rays than one chunk is read, traced and written in
/// parts; the hits are those of the linear scan, in order.
#[test]
fn trace_streams_a_file_of_many_chunks_exactly() {
    let dir = scratch_dir("hostile-chunks");
    let scene = Scene::load(&workspace_root().join(BOX)).unwrap();
    let rays = random_rays(3 * 65536 + 123);
    let path = dir.join("rays.bin");
    std::fs::write(&path, encode(&rays)).unwrap();
    let out = dir.join("hits.bin");
    let run = rtgi(&["trace", BOX, "--rays", path_str(&path), "--out", path_str(&out), "--threads", "2"]);
    assert!(run.success, "{run:?}");
    assert!(run.stderr.contains(&format!("{} rays", rays.len())), "{}", run.stderr);
    let bytes = std::fs::read(&out).unwrap();
    assert_eq!(bytes.len(), rays.len() * 16);
    let reference = LinearScan::new(&scene.triangle_positions(), rtgi_accel::Intersector::default());
    for (i, (ray, hit)) in rays.iter().zip(bytes.chunks_exact(16)).enumerate() {
        let word = |k: usize| [hit[k], hit[k + 1], hit[k + 2], hit[k + 3]];
        let got = (f32::from_le_bytes(word(0)), u32::from_le_bytes(word(4)));
        let expected = reference.intersect(ray).map_or((f32::INFINITY, u32::MAX), |h| (h.t, h.triangle));
        assert_eq!(got, expected, "ray {i}");
    }
}

/// Files that are not what a command expects: refused with one line that
/// names them, never a panic.
#[test]
fn files_that_are_not_files_are_refused_cleanly() {
    let dir = scratch_dir("hostile-files");
    let empty = dir.join("empty.exr");
    std::fs::write(&empty, b"").unwrap();
    let out = dir.join("hits.bin");
    let fifo = dir.join("fifo.exr");
    let made = Command::new("mkfifo").arg(&fifo).status().is_ok_and(|status| status.success());
    let folder = path_str(&dir);
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["compare", "/dev/null", path_str(&empty)], "/dev/null: cannot read: not a file"),
        (vec!["compare", path_str(&empty), path_str(&empty)], "empty.exr"),
        (vec!["compare", folder, path_str(&empty)], folder),
        (vec!["info", folder], folder),
        (vec!["info", "/dev/null"], "/dev/null"),
        (vec!["trace", BOX, "--rays", folder, "--out", path_str(&out)], folder),
        // Refused before measuring, not after.
        (vec!["experiment", "spp", "--quick", "--out", path_str(&empty)], "--out"),
        (vec!["experiment", "spp", "--quick", "--out", folder, "--cache", "/dev/null"], "--cache /dev/null"),
    ];
    let cases = if made {
        // Refused at once, not read (which would wait for a writer forever).
        [cases, vec![(vec!["compare", path_str(&fifo), path_str(&empty)], "not a file")]].concat()
    } else {
        eprintln!("mkfifo failed: skipping the FIFO case");
        cases
    };
    for (args, expected) in cases {
        let run = rtgi(&args);
        let lines: Vec<&str> = run.stderr.lines().filter(|l| !l.trim().is_empty()).collect();
        assert!(run.code == Some(1), "{args:?}: exit {:?} (101 is a panic): {}", run.code, run.stderr);
        assert!(lines.len() == 1 && lines[0].contains(expected), "{args:?}: {:?}", run.stderr);
    }
    assert!(!out.exists());
}

/// An uncompressed scan-line OpenEXR file that declares `side` × `side`
/// pixels of RGB f32 but holds one line of them: its offset table points
/// every line at that one (about 20 bytes per line of file for 12 × side
/// bytes per line of image).
fn exr_claiming(side: i32) -> Vec<u8> {
    fn attribute(out: &mut Vec<u8>, name: &str, kind: &str, data: &[u8]) {
        for text in [name, kind] {
            out.extend_from_slice(text.as_bytes());
            out.push(0);
        }
        out.extend_from_slice(&(data.len() as i32).to_le_bytes());
        out.extend_from_slice(data);
    }
    let ints = |v: &[i32]| -> Vec<u8> { v.iter().flat_map(|i| i.to_le_bytes()).collect() };
    let mut channels = Vec::new();
    for name in ["B", "G", "R"] {
        channels.extend_from_slice(name.as_bytes());
        channels.extend_from_slice(&[0, 2, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0]);
    }
    channels.push(0);
    let mut file = ints(&[20000630, 2]);
    attribute(&mut file, "channels", "chlist", &channels);
    attribute(&mut file, "compression", "compression", &[0]);
    attribute(&mut file, "dataWindow", "box2i", &ints(&[0, 0, side - 1, side - 1]));
    attribute(&mut file, "displayWindow", "box2i", &ints(&[0, 0, side - 1, side - 1]));
    attribute(&mut file, "lineOrder", "lineOrder", &[0]);
    attribute(&mut file, "pixelAspectRatio", "float", &1f32.to_le_bytes());
    attribute(&mut file, "screenWindowCenter", "v2f", &[0; 8]);
    attribute(&mut file, "screenWindowWidth", "float", &1f32.to_le_bytes());
    file.push(0);
    let line_at = (file.len() + 8 * side as usize) as u64;
    for _ in 0..side {
        file.extend_from_slice(&line_at.to_le_bytes());
    }
    file.extend_from_slice(&ints(&[0, 12 * side]));
    file.resize(file.len() + 12 * side as usize, 0);
    file
}

/// A small file that declares an absurd size is refused by its header,
/// not by a failed allocation of that size (30 GB here), which aborts.
#[test]
fn compare_refuses_images_of_absurd_size_before_allocating() {
    let dir = scratch_dir("hostile-huge-exr");
    let huge = dir.join("huge.exr");
    std::fs::write(&huge, exr_claiming(50_000)).unwrap();
    let small = dir.join("small.exr");
    HdrImage::new(4, 4).write(&small, &Default::default()).unwrap();
    for args in [["compare", path_str(&huge), path_str(&small)], ["compare", path_str(&small), path_str(&huge)]] {
        let run = rtgi(&args);
        assert!(run.code == Some(1), "{args:?}: exit {:?} (134 is an abort): {}", run.code, run.stderr);
        assert_eq!(run.stderr.trim().lines().count(), 1, "{}", run.stderr);
        assert!(run.stderr.contains("huge.exr") && run.stderr.contains("50000x50000"), "{}", run.stderr);
    }
}

/// Hits written to a FIFO go down the FIFO, as they are produced; the
/// FIFO stays a FIFO. (Writing through a temporary file renamed over the
/// output would replace it with a plain file, and as root would do the
/// same to `/dev/null`.)
#[cfg(unix)]
#[test]
fn trace_writes_into_a_fifo_without_replacing_it() {
    use std::os::unix::fs::FileTypeExt;
    let dir = scratch_dir("hostile-fifo-out");
    let fifo = dir.join("hits.fifo");
    if !Command::new("mkfifo").arg(&fifo).status().is_ok_and(|status| status.success()) {
        eprintln!("mkfifo failed: skipping");
        return;
    }
    let rays = random_rays(3000);
    let path = dir.join("rays.bin");
    std::fs::write(&path, encode(&rays)).unwrap();
    // The reader opens the FIFO before the command does, and reads to its end.
    let (sender, receiver) = std::sync::mpsc::channel();
    let reader_path = fifo.clone();
    std::thread::spawn(move || {
        let _ = sender.send(std::fs::read(&reader_path).map(|b| b.len()).map_err(|e| e.to_string()));
    });
    let run = rtgi(&["trace", BOX, "--rays", path_str(&path), "--out", path_str(&fifo)]);
    assert!(run.success, "{run:?}");
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo(), "the FIFO was replaced");
    // A reader still waiting means the command never opened the FIFO.
    let read = receiver.recv_timeout(std::time::Duration::from_secs(10)).expect("nothing was written to the FIFO");
    assert_eq!(read, Ok(rays.len() * 16));
}
