use rtgi_accel::{Accel, Hit, TraversalCounters};
use rtgi_math::{Ray, Rng, Vec3};
use rtgi_scene::{AlphaMode, Scene};

use crate::Integrator;

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
            let uv = scene.interpolate(triangle, hit.beta, hit.gamma, |v| v.uv);
            scene.textures[t.0 as usize].sample(uv).truncate()
        })
}

/// The surface colour at the hit: base colour times texture (if `textures`).
pub fn albedo(scene: &Scene, hit: &Hit, textures: bool) -> Vec3 {
    let triangle = &scene.triangles[hit.triangle as usize];
    let material = &scene.materials[triangle.material as usize];
    let texture = material.base_color_texture.filter(|_| textures).map_or(Vec3::ONE, |t| {
        let uv = scene.interpolate(triangle, hit.beta, hit.gamma, |v| v.uv);
        scene.textures[t.0 as usize].sample(uv).truncate()
    });
    material.base_color * texture
}

/// The closest hit of `ray`; with `alpha` set to the sample's uniform
/// number, surfaces with alpha let it through ([`alpha_accepts`]).
#[inline]
pub(crate) fn closest_hit<A: Accel + ?Sized>(scene: &Scene, accel: &A, ray: &Ray, alpha: Option<f32>) -> Option<Hit> {
    match alpha {
        Some(u) => accel.intersect_filtered(ray, &|t, b, g| alpha_accepts(scene, t, b, g, u)),
        None => accel.intersect(ray),
    }
}

/// One sample of an arbitrary output variable (an AOV integrator) for a
/// camera ray; zero where the ray hits nothing.
pub(crate) fn aov<A: Accel + ?Sized>(
    kind: Integrator,
    scene: &Scene,
    accel: &A,
    (alpha, textures): (bool, bool),
    ray: &Ray,
    rng: &mut Rng,
) -> Vec3 {
    let mut counters = TraversalCounters::default();
    let hit = if kind == Integrator::Cost {
        accel.intersect_counted(ray, &mut counters)
    } else {
        closest_hit(scene, accel, ray, alpha.then(|| rng.next_f32()))
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

/// Whether any material of the scene has alpha that makes holes: masked
/// or blended surfaces. Renders of scenes without skip the per-hit test.
pub fn has_alpha(scene: &Scene) -> bool {
    scene.materials.iter().any(|m| m.alpha_mode != AlphaMode::Opaque)
}

/// Whether a hit on `triangle` at `(beta, gamma)` counts: masked surfaces
/// are holes where their alpha (base colour alpha times the texture's) is
/// below the cutoff; blended surfaces are hit with probability alpha, decided
/// by comparing it with the sample's uniform number `u` (stochastic
/// transparency, which averages to the blend over samples).
pub fn alpha_accepts(scene: &Scene, triangle: u32, beta: f32, gamma: f32, u: f32) -> bool {
    let triangle = &scene.triangles[triangle as usize];
    let material = &scene.materials[triangle.material as usize];
    let alpha = || {
        // Interpolated once, and one channel read from each texture: this
        // runs for every candidate hit on a cut-out.
        let textured = material.base_color_texture.is_some() || material.alpha_texture.is_some();
        let uv = if textured { scene.interpolate(triangle, beta, gamma, |v| v.uv) } else { Default::default() };
        let texture = material.base_color_texture.map_or(1.0, |t| scene.textures[t.0 as usize].sample_channel(uv, 3));
        let mask = material.alpha_texture.map_or(1.0, |t| {
            let mask = &scene.textures[t.0 as usize];
            mask.sample_channel(uv, if mask.has_alpha() { 3 } else { 0 })
        });
        material.opacity * texture * mask
    };
    match material.alpha_mode {
        AlphaMode::Opaque => true,
        AlphaMode::Mask { cutoff } => alpha() >= cutoff,
        AlphaMode::Blend => alpha() > u,
    }
}
