//! Scenes whose answer is known in closed form, so that an estimator's bias
//! can be measured against the truth instead of against another estimator:
//! the white furnace (inside a closed sphere whose walls reflect `ρ` and
//! emit `Le`, every pixel converges to `Le / (1 − ρ)`).
//!
//! `tests/tests/render/light_transport.rs` checks the renderer against them, and the
//! `analytic` knob reports each estimator's bias against them.

use rtgi_math::Vec3;
use rtgi_render::probes::icosphere;
use rtgi_scene::{Camera, Material, MeshBuilder, Scene};

/// A unit icosphere of one material with flat normals, its faces wound to
/// face outwards or (for a furnace seen from inside) inwards.
pub fn sphere_scene(material: Material, inward: bool) -> Scene {
    let sphere = icosphere(3);
    let mut scene = Scene { materials: vec![material], ..Scene::default() };
    let mut builder = MeshBuilder::new(sphere.vertices.clone(), Vec::new(), Vec::new()).with_flat_normals();
    for face in &sphere.faces {
        let [a, b, c] = face.map(|i| sphere.vertices[i as usize]);
        let outward = (b - a).cross(c - a).dot(a + b + c) > 0.0;
        let face = if outward == inward { [face[0], face[2], face[1]] } else { *face };
        builder.push(face, None, None, 0);
    }
    builder.finish_into(&mut scene);
    scene
}

/// A white furnace: a closed sphere of diffuse walls of albedo `albedo`
/// emitting `emitted`, seen from a point inside it, and its exact radiance
/// `emitted / (1 − albedo)` (for paths of any length).
pub fn white_furnace(albedo: f32, emitted: f32) -> (Scene, Camera, f64) {
    let wall = Material {
        name: "furnace".into(),
        base_color: Vec3::splat(albedo),
        emission: Vec3::splat(emitted),
        ..Material::default()
    };
    let camera = Camera::look_at(Vec3::new(0.1, -0.2, 0.05), Vec3::new(1.0, 0.3, -2.0), Vec3::Y, 1.2);
    (sphere_scene(wall, true), camera, emitted as f64 / (1.0 - albedo as f64))
}
