use rtgi_accel::Hit;
use rtgi_math::{Ray, Vec3};
use rtgi_scene::Scene;

/// The part of the light that a surface facing away from the viewer still
/// reflects in the simple shading, so that such faces stay readable.
const AMBIENT: f32 = 0.2;

/// Shades the closest hit for the primary-hit view: the surface's albedo
/// (material colour times texture) scaled by the cosine between the
/// interpolated normal and the direction back to the viewer, plus the
/// surface's own emission (times its texture). Both sides of a surface are lit.
pub fn shade_primary(scene: &Scene, ray: &Ray, hit: &Hit) -> Vec3 {
    let triangle = &scene.triangles[hit.triangle as usize];
    let material = &scene.materials[triangle.material as usize];
    let uv = scene.interpolate(triangle, hit.beta, hit.gamma, |v| v.uv);
    let texture = |id: Option<rtgi_scene::TextureId>| {
        id.map_or(Vec3::ONE, |t| scene.textures[t.0 as usize].sample(uv).truncate())
    };
    let albedo = material.base_color * texture(material.base_color_texture);
    let emission = material.emission * texture(material.emission_texture);
    let normal = shading_normal(scene, hit);
    let cosine = normal.dot(-ray.direction.normalize()).abs();
    albedo * (AMBIENT + (1.0 - AMBIENT) * cosine) + emission
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
