//! An OBJ whose faces crowd around one vertex loads, with the right normals
//! (issue 12: a fan of 100,000 triangles without normals took minutes,
//! computing smooth normals in a time quadratic in the valence of its
//! centre). That the work is linear is counted, not timed, by the unit
//! tests of `MeshBuilder` (`crates/scene/src/mesh.rs`), which every
//! importer's triangles go through.

use std::fmt::Write as _;

use rtgi_math::Vec3;
use rtgi_scene::Scene;
use rtgi_tests::scratch_dir;

/// OBJ text of a closed fan of `count` triangles around the origin, its rim
/// the unit circle in the xy plane: positions and faces, no normals.
fn fan_obj(count: u32) -> String {
    let mut obj = String::from("v 0 0 0\n");
    for i in 0..count {
        let angle = std::f64::consts::TAU * f64::from(i) / f64::from(count);
        writeln!(obj, "v {:.9} {:.9} 0", angle.cos(), angle.sin()).unwrap();
    }
    for i in 0..count {
        writeln!(obj, "f 1 {} {}", i + 2, (i + 1) % count + 2).unwrap();
    }
    obj
}

#[test]
fn a_fan_of_100000_triangles_without_normals_loads_with_the_fan_s_normal() {
    let dir = scratch_dir("loading_scale");
    let path = dir.join("fan.obj");
    std::fs::write(&path, fan_obj(100_000)).unwrap();

    let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.triangles.len(), 100_000);
    // One centre vertex, whose normal is the fan's (+z, as every face's).
    let centre = scene.triangles[0].vertices[0];
    assert!(scene.triangles.iter().all(|t| t.vertices[0] == centre));
    let centre = scene.vertices[centre as usize];
    assert_eq!(centre.position, Vec3::ZERO);
    assert!((centre.normal - Vec3::Z).length() < 1e-6, "{}", centre.normal);
}
