//! A voxel world with cut-outs, written as OBJ + MTL + PNG: the scene of
//! issue 24's cut-out target, generated rather than stored. `tests/tests/render/cutouts.rs`
//! times it, and `cargo run --release -p rtgi-tests --example voxel-world`
//! writes it for `benches/targets.sh` and for anyone who wants to look.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

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
pub fn voxel_world(dir: &Path, side: i32) -> std::io::Result<PathBuf> {
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
    std::fs::write(dir.join("world.obj"), obj.text)?;
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
    atlas.save(dir.join("atlas.png")).map_err(std::io::Error::other)?;
    std::fs::write(
        dir.join("world.mtl"),
        "newmtl ground\nKd 1 1 1\nmap_Kd atlas.png\nnewmtl dirt\nKd 1 1 1\nmap_Kd atlas.png\n\
         newmtl trunk\nKd 1 1 1\nmap_Kd atlas.png\nnewmtl leaves\nKd 1 1 1\nmap_Kd atlas.png\nmap_d atlas.png\n\
         newmtl grass\nKd 1 1 1\nmap_Kd atlas.png\nmap_d atlas.png\n",
    )?;
    Ok(dir.join("world.obj"))
}
