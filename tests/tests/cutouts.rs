//! Cut-outs at the speed of solid surfaces: a voxel world whose tree
//! canopies are cubes of leaves with holes (MTL `map_d`) and whose ground
//! has crossed grass cards, the everyday input that was 280× slower with
//! alpha than without. Renders and `rtgi trace` with the alpha test on must
//! stay within a small factor of the same scene with it off, and the holes
//! must show.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use rtgi_tests::{Run, run_cli, scratch_dir};

const RTGI: &str = env!("CARGO_BIN_EXE_rtgi-under-test");

/// A hash of three integers to [0, 1): the world's "random" choices, the same on every run.
fn hash(x: i32, y: i32, z: i32) -> f32 {
    let mut h = (x as u32).wrapping_mul(0x9E37_79B1)
        ^ (y as u32).wrapping_mul(0x85EB_CA77)
        ^ (z as u32).wrapping_mul(0xC2B2_AE3D);
    h ^= h >> 15;
    h = h.wrapping_mul(0x2C1B_3C6D);
    h ^= h >> 12;
    (h >> 8) as f32 / (1u32 << 24) as f32
}

/// The materials, each with its tile of the texture atlas (tiles of 16 × 16 texels in the last row).
const TILES: [&str; 5] = ["leaves", "grass", "ground", "dirt", "trunk"];

/// An OBJ being written: positions, texture coordinates and faces by material.
#[derive(Default)]
struct Obj {
    text: String,
    vertices: usize,
    material: &'static str,
}

impl Obj {
    /// A quad showing tile `tile` of the atlas's first row.
    fn quad(&mut self, material: &'static str, corners: [[f32; 3]; 4]) {
        if self.material != material {
            writeln!(self.text, "usemtl {material}").unwrap();
            self.material = material;
        }
        let tile = TILES.iter().position(|t| *t == material).unwrap() as f32;
        let (u0, u1) = (tile / 16.0 + 1e-3, (tile + 1.0) / 16.0 - 1e-3);
        let (v0, v1) = (1e-3, 1.0 / 16.0 - 1e-3);
        for ([x, y, z], [u, v]) in corners.iter().zip([[u0, v0], [u1, v0], [u1, v1], [u0, v1]]) {
            writeln!(self.text, "v {x} {y} {z}\nvt {u} {v}").unwrap();
        }
        let i = self.vertices + 1;
        writeln!(
            self.text,
            "f {i}/{i} {}/{} {}/{}\nf {i}/{i} {}/{} {}/{}",
            i + 1,
            i + 1,
            i + 2,
            i + 2,
            i + 2,
            i + 2,
            i + 3,
            i + 3
        )
        .unwrap();
        self.vertices += 4;
    }

    /// The faces of the unit cube at `(x, y, z)` for which `open(dx, dy, dz)` says the neighbour lets light in.
    fn cube(&mut self, material: &'static str, [x, y, z]: [i32; 3], open: impl Fn(i32, i32, i32) -> bool) {
        let (x0, y0, z0) = (x as f32, y as f32, z as f32);
        let (x1, y1, z1) = (x0 + 1.0, y0 + 1.0, z0 + 1.0);
        let faces: [([i32; 3], [[f32; 3]; 4]); 6] = [
            ([1, 0, 0], [[x1, y0, z1], [x1, y0, z0], [x1, y1, z0], [x1, y1, z1]]),
            ([-1, 0, 0], [[x0, y0, z0], [x0, y0, z1], [x0, y1, z1], [x0, y1, z0]]),
            ([0, 1, 0], [[x0, y1, z1], [x1, y1, z1], [x1, y1, z0], [x0, y1, z0]]),
            ([0, -1, 0], [[x0, y0, z0], [x1, y0, z0], [x1, y0, z1], [x0, y0, z1]]),
            ([0, 0, 1], [[x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]]),
            ([0, 0, -1], [[x1, y0, z0], [x0, y0, z0], [x0, y1, z0], [x1, y1, z0]]),
        ];
        for ([dx, dy, dz], corners) in faces {
            if open(dx, dy, dz) {
                self.quad(material, corners);
            }
        }
    }
}

/// Writes a voxel world of `side × side` columns into `dir`: grass-topped
/// terrain, trees whose canopies are leaf cubes with every face a cut-out
/// (light passes through, so the faces between leaves stay), and crossed
/// grass cards; returns the OBJ's path. About 40 triangles per column.
fn voxel_world(dir: &Path, side: i32) -> PathBuf {
    let height = |x: i32, z: i32| -> i32 {
        let (x, z) = (x as f32, z as f32);
        (4.0 + 2.5 * (x * 0.19).sin() + 2.0 * (z * 0.23 + 1.0).cos() + 1.5 * ((x + z) * 0.11).sin()).round() as i32
    };
    let column = |x: i32, z: i32| if (0..side).contains(&x) && (0..side).contains(&z) { height(x, z) } else { 0 };
    let mut obj = Obj::default();
    writeln!(obj.text, "mtllib world.mtl").unwrap();
    let mut trees = Vec::new();
    for x in 0..side {
        for z in 0..side {
            let h = height(x, z);
            for y in 0..h {
                let material = if y + 1 == h { "ground" } else { "dirt" };
                obj.cube(material, [x, y, z], |dx, dy, dz| {
                    if dy != 0 { y + dy >= h || y + dy < 0 } else { y >= column(x + dx, z + dz) }
                });
            }
            let r = hash(x, h, z);
            if x % 7 == 3 && z % 7 == 3 && r < 0.8 {
                trees.push([x, h, z]);
            } else if r < 0.3 {
                // Two crossed cards, one block tall.
                let (x0, z0, y0) = (x as f32, z as f32, h as f32);
                obj.quad(
                    "grass",
                    [[x0, y0, z0], [x0 + 1.0, y0, z0 + 1.0], [x0 + 1.0, y0 + 1.0, z0 + 1.0], [x0, y0 + 1.0, z0]],
                );
                obj.quad(
                    "grass",
                    [[x0 + 1.0, y0, z0], [x0, y0, z0 + 1.0], [x0, y0 + 1.0, z0 + 1.0], [x0 + 1.0, y0 + 1.0, z0]],
                );
            }
        }
    }
    for [x, h, z] in trees {
        for y in h..h + 4 {
            obj.cube("trunk", [x, y, z], |_, dy, _| dy == 0 || y + dy < h);
        }
        for dx in -2..=2 {
            for dz in -2..=2 {
                for dy in 3..6 {
                    let corner = dx * dx + dz * dz > 5 && dy != 4;
                    if !(corner || dx == 0 && dz == 0 && dy < 4) {
                        obj.cube("leaves", [x + dx, h + dy, z + dz], |_, _, _| true);
                    }
                }
            }
        }
    }
    std::fs::write(dir.join("world.obj"), obj.text).unwrap();
    // One atlas for every block, as voxel worlds have it: 256 × 256 texels,
    // RGBA, the leaves and grass tiles (in its last row) with holes (alpha
    // 0) and the rest opaque. Cut-outs read its alpha (map_d names the same
    // file). A test that scanned the texture for alpha on every candidate
    // hit went through 61,440 opaque texels each time.
    let atlas = image::RgbaImage::from_fn(256, 256, |x, y| {
        let (tile, tx, ty) = (x / 16, x % 16, y % 16);
        let noise = (hash(x as i32, y as i32, 1) * 40.0) as u8;
        let solid = |r: u8, g: u8, b: u8| image::Rgba([r + noise / 2, g + noise, b + noise / 2, 255]);
        match (y / 16, tile) {
            (15, 0) => {
                let open = hash(tx as i32, ty as i32, 7) < 0.5;
                image::Rgba([40, 110 + noise, 30, if open { 0 } else { 255 }])
            }
            (15, 1) => {
                let blade = tx % 4 == 1 && (ty as f32) > 4.0 + 10.0 * hash(tx as i32, 0, 3);
                image::Rgba([70, 150 + noise, 40, if blade { 255 } else { 0 }])
            }
            (15, 2) => solid(70, 130, 40),
            (15, 3) => solid(110, 75, 40),
            (15, 4) => solid(90, 60, 30),
            _ => solid(120, 120, 120),
        }
    });
    atlas.save(dir.join("atlas.png")).unwrap();
    std::fs::write(
        dir.join("world.mtl"),
        "newmtl ground\nKd 1 1 1\nmap_Kd atlas.png\nnewmtl dirt\nKd 1 1 1\nmap_Kd atlas.png\n\
         newmtl trunk\nKd 1 1 1\nmap_Kd atlas.png\nnewmtl leaves\nKd 1 1 1\nmap_Kd atlas.png\nmap_d atlas.png\n\
         newmtl grass\nKd 1 1 1\nmap_Kd atlas.png\nmap_d atlas.png\n",
    )
    .unwrap();
    dir.join("world.obj")
}

fn timed(args: &[&str]) -> (Run, f64) {
    let start = Instant::now();
    let run = run_cli(RTGI, args);
    (run, start.elapsed().as_secs_f64())
}

#[test]
fn a_voxel_world_with_leaf_cut_outs_renders_near_the_speed_of_solid_leaves() {
    let dir = scratch_dir("cutouts");
    let world = voxel_world(&dir, 48);
    let world = world.to_str().unwrap();
    let view = ["--at", "-6,16,-6", "--look", "20,4,20", "--width", "96", "--height", "72", "--spp", "4", "-t", "2"];
    let (with, without) = (dir.join("alpha.exr"), dir.join("solid.exr"));
    let mut args = vec!["render", world, "-o", with.to_str().unwrap()];
    args.extend(view);
    let mut solid = vec!["render", world, "-o", without.to_str().unwrap(), "--effects=-alpha"];
    solid.extend(view);
    // Once each before timing: the first run pays for reading the files.
    assert!(run_cli(RTGI, &args).success);
    assert!(run_cli(RTGI, &solid).success);
    let mut ratios = Vec::new();
    for _ in 0..3 {
        let (run, alpha_s) = timed(&args);
        assert!(run.success, "{run:?}");
        let (run, solid_s) = timed(&solid);
        assert!(run.success, "{run:?}");
        ratios.push(alpha_s / solid_s);
    }
    ratios.sort_by(f64::total_cmp);
    eprintln!("render time with cut-outs / without, 3 runs: {ratios:?}");
    // The goal is 1.5× in release builds (measured in the README); this
    // guards against the 280× of a test that scanned the whole texture per hit.
    assert!(ratios[1] < 3.0, "cut-outs cost {:.1}× the solid render", ratios[1]);
    // And the holes are there: light through the canopies changes the image.
    let a = rtgi_image::HdrImage::read_exr(&with).unwrap();
    let b = rtgi_image::HdrImage::read_exr(&without).unwrap();
    let changed = a.pixels().iter().zip(b.pixels()).filter(|(p, q)| (**p - **q).abs().max_element() > 0.05).count();
    assert!(changed > a.pixels().len() / 50, "only {changed} pixels differ: are the leaves cut out?");
}

/// The trace time `rtgi trace` reports on stderr, in milliseconds (file
/// reading, loading and building excluded).
fn trace_ms(run: &Run) -> f64 {
    let line = run.stderr.lines().find(|l| l.starts_with("trace ")).unwrap_or_else(|| panic!("no trace line: {run:?}"));
    line.split_whitespace().nth(1).and_then(|ms| ms.parse().ok()).unwrap_or_else(|| panic!("unreadable: {line}"))
}

#[test]
fn rtgi_trace_passes_through_cut_outs_at_near_the_speed_of_solid_leaves() {
    let dir = scratch_dir("cutouts-trace");
    let world = voxel_world(&dir, 48);
    let world = world.to_str().unwrap();
    let view = ["--at", "-6,16,-6", "--look", "20,4,20"];
    let mut ray_files = Vec::new();
    for (kind, extra) in
        [("camera", &["--width", "256", "--height", "192"][..]), ("surface", &["--count", "50000"][..])]
    {
        let rays = dir.join(format!("{kind}.rays.bin"));
        let mut args = vec!["rays", world, "--kind", kind, "-o", rays.to_str().unwrap()];
        args.extend(view);
        args.extend_from_slice(extra);
        let run = run_cli(RTGI, &args);
        assert!(run.success, "{run:?}");
        ray_files.push((kind, rays));
    }
    for (kind, rays) in &ray_files {
        let (holes, solid) = (dir.join(format!("{kind}.alpha.bin")), dir.join(format!("{kind}.solid.bin")));
        let trace = |out: &Path, opaque: bool| {
            let mut args =
                vec!["trace", world, "--rays", rays.to_str().unwrap(), "-o", out.to_str().unwrap(), "-t", "2"];
            if opaque {
                args.push("--no-alpha");
            }
            let run = run_cli(RTGI, &args);
            assert!(run.success, "{run:?}");
            run
        };
        let mut ratios = Vec::new();
        for _ in 0..3 {
            let with = trace(&holes, false);
            assert!(with.stderr.contains("materials have cut-outs: rays pass through their holes"), "{with:?}");
            let without = trace(&solid, true);
            assert!(without.stderr.contains("traced solid (--no-alpha)"), "{without:?}");
            ratios.push(trace_ms(&with) / trace_ms(&without));
        }
        ratios.sort_by(f64::total_cmp);
        eprintln!("{kind} rays: trace time with cut-outs / without, 3 runs: {ratios:?}");
        // Rays that pass through holes go on through the canopy, and every
        // candidate hit on a leaf reads its texture: measured in release
        // builds 2.7× to 3.0× (Embree, with the same filter: 6.6×). This
        // guards against a slow path (the 280× of a whole-texture scan),
        // not the 1.5×, which the filter's texture reads alone exceed.
        assert!(ratios[1] < 8.0, "{kind} rays: cut-outs cost {:.1}× the solid trace", ratios[1]);
        // Rays went through holes: some hit something else, or nothing.
        let (a, b) = (std::fs::read(&holes).unwrap(), std::fs::read(&solid).unwrap());
        let differ = a.chunks(16).zip(b.chunks(16)).filter(|(p, q)| p[4..8] != q[4..8]).count();
        assert!(differ > a.len() / 16 / 100, "{kind} rays: only {differ} hit another triangle through the holes");
    }
}
