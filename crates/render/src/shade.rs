use rtgi_accel::{Accel, Hit, TraversalCounters};
use rtgi_math::{Ray, Rng, Vec3};
use rtgi_scene::Scene;

use crate::Integrator;
use crate::alpha::AlphaTest;

/// The part of the light that a surface facing away from the viewer still
/// reflects in the simple shading, so that such faces stay readable.
const AMBIENT: f32 = 0.2;

/// Shades the closest hit for the primary-hit view: the surface's albedo
/// (material colour times texture) scaled by the cosine between the
/// interpolated normal and the direction back to the viewer, plus the
/// surface's own emission (times its texture). Both sides of a surface are
/// lit. `textures` says whether to look textures up (the plan's choice).
pub fn shade_primary(scene: &Scene, ray: &Ray, hit: &Hit, textures: bool) -> Vec3 {
    let emission = emission(scene, hit, textures);
    let albedo = albedo(scene, hit, textures);
    // An unlit surface shows its colour as it is (KHR_materials_unlit).
    if scene.materials[scene.triangles[hit.triangle as usize].material as usize].unlit {
        return albedo + emission;
    }
    let normal = shading_normal(scene, hit);
    let cosine = normal.dot(-ray.direction.normalize()).abs();
    albedo * (AMBIENT + (1.0 - AMBIENT) * cosine) + emission
}

/// The light the surface emits at the hit: emission times its texture (if `textures`).
pub fn emission(scene: &Scene, hit: &Hit, textures: bool) -> Vec3 {
    let triangle = &scene.triangles[hit.triangle as usize];
    let material = &scene.materials[triangle.material as usize];
    material.emission
        * material.emission_texture.filter(|_| textures).map_or(Vec3::ONE, |t| {
            let coords = scene.texture_coords(triangle, hit.beta, hit.gamma);
            scene.textures[t.0 as usize].lookup(coords).truncate()
        })
}

/// The surface colour at the hit: base colour times vertex colour, times
/// texture (if `textures`).
pub fn albedo(scene: &Scene, hit: &Hit, textures: bool) -> Vec3 {
    let triangle = &scene.triangles[hit.triangle as usize];
    let material = &scene.materials[triangle.material as usize];
    let texture = material.base_color_texture.filter(|_| textures).map_or(Vec3::ONE, |t| {
        let coords = scene.texture_coords(triangle, hit.beta, hit.gamma);
        scene.textures[t.0 as usize].lookup(coords).truncate()
    });
    let vertex_color = scene.interpolate(triangle, hit.beta, hit.gamma, |v| v.color).truncate();
    material.base_color * vertex_color * texture
}

/// The closest hit of `ray`; with `cut_outs`, the alpha test and the
/// sample's uniform number, surfaces with alpha let it through.
#[inline]
pub(crate) fn closest_hit<A: Accel + ?Sized>(
    accel: &A,
    ray: &Ray,
    cut_outs: Option<(&AlphaTest<'_>, f32)>,
) -> Option<Hit> {
    match cut_outs {
        Some((test, u)) => accel.intersect_filtered(ray, &|t, b, g| test.accepts(t, b, g, u)),
        None => accel.intersect(ray),
    }
}

/// One sample of an arbitrary output variable (an AOV integrator) for a
/// camera ray; zero where the ray hits nothing.
pub(crate) fn aov<A: Accel + ?Sized>(
    kind: Integrator,
    scene: &Scene,
    accel: &A,
    (cut_outs, textures): (Option<&AlphaTest<'_>>, bool),
    ray: &Ray,
    rng: &mut Rng,
) -> Vec3 {
    let mut counters = TraversalCounters::default();
    let hit = if kind == Integrator::Cost {
        accel.intersect_counted(ray, &mut counters)
    } else {
        closest_hit(accel, ray, cut_outs.map(|test| (test, rng.next_f32())))
    };
    if kind == Integrator::Cost {
        return Vec3::new(counters.nodes_visited as f32, counters.triangles_tested as f32, hit.is_some() as u32 as f32);
    }
    let Some(hit) = hit else { return Vec3::ZERO };
    match kind {
        Integrator::Albedo => albedo(scene, &hit, textures),
        Integrator::Normal => shading_normal(scene, &hit),
        Integrator::Depth => Vec3::splat(hit.t * ray.direction.length()),
        Integrator::Position => ray.at(hit.t),
        Integrator::Emission => emission(scene, &hit, textures),
        other => unreachable!("{other} is not an AOV"),
    }
}

/// The interpolated vertex normal at the hit, or the triangle's geometric
/// normal where interpolation degenerates (opposite normals cancelling).
pub fn shading_normal(scene: &Scene, hit: &Hit) -> Vec3 {
    let triangle = &scene.triangles[hit.triangle as usize];
    let interpolated = scene.interpolate(triangle, hit.beta, hit.gamma, |v| v.normal);
    interpolated.try_normalize().unwrap_or_else(|| {
        let [a, b, c] = triangle.vertices.map(|v| scene.vertices[v as usize].position);
        (b - a).cross(c - a).normalize_or(Vec3::Z)
    })
}
