//! Cut-outs: which hits on surfaces with alpha count.
//!
//! The test runs for every candidate hit on such a surface, inside the
//! traversal, so its cost is that of the memory it reads. [`alpha_accepts`]
//! reads the scene as it is: the triangle, its three vertices (in lines of
//! their own, far apart in a large scene) and four texels of each texture.
//! [`AlphaTest`] answers the same, bit for bit, from what it prepared: one
//! 32-byte entry a triangle with its corners' texture coordinates and its
//! material, and the textures' bounds around the hit
//! ([`Texture::channel_bounds`]), which decide wherever the texels around
//! it are all opaque or all clear; only at a hole's rim are texels filtered.

use rtgi_math::Vec2;
use rtgi_scene::{AlphaMode, Material, Scene, Texture};

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
///
/// For one test, or as the definition; tracing many rays, prepare an
/// [`AlphaTest`], which answers the same with less memory traffic.
pub fn alpha_accepts(scene: &Scene, triangle: u32, beta: f32, gamma: f32, u: f32) -> bool {
    let triangle = &scene.triangles[triangle as usize];
    let material = &scene.materials[triangle.material as usize];
    let set = coordinate_set(scene, material);
    decide(scene, material, u, || scene.texture_coords(triangle, beta, gamma)[set])
}

/// The texture coordinate set the alpha of `material` is read with: its
/// base colour texture's (an MTL mask reads set 0, as MTL has no other).
fn coordinate_set(scene: &Scene, material: &Material) -> usize {
    material.base_color_texture.map_or(0, |t| scene.textures[t.0 as usize].uv_map().set.min(1) as usize)
}

/// [`alpha_accepts`] prepared for a scene: the corners' texture
/// coordinates and the material of every triangle, side by side.
#[derive(Debug)]
pub struct AlphaTest<'a> {
    scene: &'a Scene,
    /// A bit a triangle: whether its material has alpha. Most candidate
    /// hits are on opaque surfaces, and these bits (a 256th of the memory
    /// of `triangles`) stay in the cache.
    with_alpha: Vec<u64>,
    triangles: Vec<AlphaTriangle>,
}

/// What the alpha test reads of one triangle, in half a cache line.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
struct AlphaTriangle {
    uv: [Vec2; 3],
    material: u32,
}

impl<'a> AlphaTest<'a> {
    /// The test for `scene`'s triangles as they are now.
    pub fn new(scene: &'a Scene) -> Self {
        let mut with_alpha = vec![0u64; scene.triangles.len().div_ceil(64)];
        let mut triangles = Vec::with_capacity(scene.triangles.len());
        for (i, t) in scene.triangles.iter().enumerate() {
            if scene.materials[t.material as usize].alpha_mode != AlphaMode::Opaque {
                with_alpha[i / 64] |= 1 << (i % 64);
            }
            let set = coordinate_set(scene, &scene.materials[t.material as usize]);
            let uv = t.vertices.map(|v| {
                let vertex = &scene.vertices[v as usize];
                if set == 1 { vertex.uv1 } else { vertex.uv }
            });
            triangles.push(AlphaTriangle { uv, material: t.material });
        }
        Self { scene, with_alpha, triangles }
    }

    /// [`alpha_accepts`]`(scene, triangle, beta, gamma, u)`, with the same answer.
    #[inline]
    pub fn accepts(&self, triangle: u32, beta: f32, gamma: f32, u: f32) -> bool {
        let i = triangle as usize;
        if self.with_alpha[i / 64] & (1 << (i % 64)) == 0 {
            return true;
        }
        let AlphaTriangle { uv: [a, b, c], material } = self.triangles[i];
        let material = &self.scene.materials[material as usize];
        // The arithmetic of `Scene::texture_coords`, for the same bits.
        decide(self.scene, material, u, || a * (1.0 - beta - gamma) + b * beta + c * gamma)
    }
}

/// The texture and channel of `material`'s alpha mask, if it has one that
/// is not the base colour's alpha itself: an MTL `map_d` naming the RGBA
/// file of `map_Kd` means that file's alpha, which the base colour already
/// brings, and counted twice it would be squared (a rim texel of alpha 0.6
/// would fall below a cutoff of one half).
#[inline(always)]
fn mask_lookup<'s>(scene: &'s Scene, material: &Material) -> Option<(&'s Texture, usize)> {
    let id = material.alpha_texture?;
    let mask = &scene.textures[id.0 as usize];
    let channel = if mask.has_alpha() { 3 } else { 0 };
    (material.base_color_texture != Some(id) || channel != 3).then_some((mask, channel))
}

/// Whether `material` at the texture coordinates `uv()` (of the set
/// [`coordinate_set`] names, before the textures' transforms) counts as
/// hit for the uniform number `u`.
#[inline(always)]
fn decide(scene: &Scene, material: &Material, u: f32, uv: impl FnOnce() -> Vec2) -> bool {
    // Both modes accept from a threshold up, so bounds that fall on one
    // side of it decide.
    let accepts = |alpha: f32| match material.alpha_mode {
        AlphaMode::Opaque => true,
        AlphaMode::Mask { cutoff } => alpha >= cutoff,
        AlphaMode::Blend => alpha > u,
    };
    if material.alpha_mode == AlphaMode::Opaque {
        return true;
    }
    let (base, mask) = (material.base_color_texture, material.alpha_texture);
    if base.is_none() && mask.is_none() {
        return accepts(material.opacity);
    }
    // Interpolated once, and one channel read from each texture.
    let uv = uv();
    let base = base.map(|t| (&scene.textures[t.0 as usize], 3));
    let mask = mask_lookup(scene, material);
    let bounds = |lookup: Option<(&Texture, usize)>| {
        lookup.map_or(Some((1.0, 1.0)), |(t, c)| t.channel_bounds(t.uv_map().transform(uv), c))
    };
    if let (Some((base_low, base_high)), Some((mask_low, mask_high))) = (bounds(base), bounds(mask))
        && (0.0..=f32::MAX).contains(&material.opacity)
    {
        // The value's two products below round by at most an ulp each.
        let low = material.opacity * base_low * mask_low * (1.0 - 4.0 * f32::EPSILON);
        let high = material.opacity * base_high * mask_high * (1.0 + 4.0 * f32::EPSILON);
        let (low_accepted, high_accepted) = (accepts(low), accepts(high));
        if low_accepted == high_accepted {
            return low_accepted;
        }
    }
    let value =
        |lookup: Option<(&Texture, usize)>| lookup.map_or(1.0, |(t, c)| t.sample_channel(t.uv_map().transform(uv), c));
    accepts(material.opacity * value(base) * value(mask))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rtgi_math::{Vec3, Vec4};
    use rtgi_scene::{ColorEncoding, TextureId, Triangle, Vertex, Wrap};

    /// The filtered value's test, as it was before bounds decided: the definition.
    fn filtered(scene: &Scene, triangle: u32, beta: f32, gamma: f32, u: f32) -> bool {
        let triangle = &scene.triangles[triangle as usize];
        let material = &scene.materials[triangle.material as usize];
        let uv = scene.interpolate(triangle, beta, gamma, |v| v.uv);
        let texture = material.base_color_texture.map_or(1.0, |t| scene.textures[t.0 as usize].sample_channel(uv, 3));
        let mask = material.alpha_texture.map_or(1.0, |t| {
            let mask = &scene.textures[t.0 as usize];
            if material.base_color_texture == Some(t) && mask.has_alpha() {
                return 1.0; // the base colour's own alpha, counted once
            }
            mask.sample_channel(uv, if mask.has_alpha() { 3 } else { 0 })
        });
        let alpha = material.opacity * texture * mask;
        match material.alpha_mode {
            AlphaMode::Opaque => true,
            AlphaMode::Mask { cutoff } => alpha >= cutoff,
            AlphaMode::Blend => alpha > u,
        }
    }

    #[test]
    fn bounds_and_the_prepared_test_answer_as_the_filtered_value() {
        // A texture of clear and opaque blocks with rims of every value,
        // and a grey mask without alpha; cutoffs and opacities at and
        // between texel values, where rounding decides.
        let (width, height) = (16u32, 16u32);
        let texels: Vec<[u8; 4]> = (0..width * height)
            .map(|i| {
                let (x, y) = (i % width, i / width);
                let alpha = match (x / 4 + y / 4) % 3 {
                    0 => 0,
                    1 => 255,
                    _ => (i * 61 % 256) as u8,
                };
                [(i * 29 % 256) as u8, 0, 0, alpha]
            })
            .collect();
        let mut scene = Scene::default();
        scene.textures.push(Texture::from_rgba8("alpha", width, height, texels.clone(), ColorEncoding::Srgb).unwrap());
        let grey = texels.iter().map(|t| [t[0], t[0], t[0], 255]).collect();
        scene.textures.push(
            Texture::from_rgba8("mask", width, height, grey, ColorEncoding::Srgb)
                .unwrap()
                .with_wrap(Wrap::MirroredRepeat, Wrap::ClampToEdge),
        );
        let modes = [AlphaMode::Mask { cutoff: 0.5 }, AlphaMode::Mask { cutoff: 128.0 / 255.0 }, AlphaMode::Blend];
        for alpha_mode in modes {
            // With the same texture as base and mask too: its alpha, or
            // (without alpha) its red channel as the mask.
            let pairs = [
                (Some(0), None),
                (None, Some(1)),
                (Some(0), Some(1)),
                (None, None),
                (Some(0), Some(0)),
                (Some(1), Some(1)),
            ];
            for (base, mask) in pairs {
                for opacity in [1.0, 0.5, 1.0 / 3.0, 0.0] {
                    scene.materials.push(Material {
                        alpha_mode,
                        opacity,
                        base_color_texture: base.map(TextureId),
                        alpha_texture: mask.map(TextureId),
                        ..Material::default()
                    });
                }
            }
        }
        // One triangle per material, spanning a few repeats of the textures.
        for (m, _) in scene.materials.iter().enumerate() {
            let first = scene.vertices.len() as u32;
            for uv in [Vec2::new(-1.3, -0.7), Vec2::new(2.1, -0.2), Vec2::new(0.4, 1.9)] {
                scene.vertices.push(Vertex {
                    position: Vec3::ZERO,
                    normal: Vec3::Z,
                    uv,
                    uv1: Vec2::ZERO,
                    color: Vec4::ONE,
                    tangent: Vec4::X,
                });
            }
            scene.triangles.push(Triangle { vertices: [first, first + 1, first + 2], material: m as u32 });
        }
        let prepared = AlphaTest::new(&scene);
        let mut counts = [0usize; 2];
        for triangle in 0..scene.triangles.len() as u32 {
            for k in 0..4000u32 {
                let beta = (k % 61) as f32 / 61.0 * 0.97;
                let gamma = (k / 61) as f32 / 66.0 * (1.0 - beta);
                let u = (k * 7919 % 4001) as f32 / 4001.0;
                let expected = filtered(&scene, triangle, beta, gamma, u);
                assert_eq!(alpha_accepts(&scene, triangle, beta, gamma, u), expected, "{triangle} {beta} {gamma} {u}");
                assert_eq!(prepared.accepts(triangle, beta, gamma, u), expected, "{triangle} {beta} {gamma} {u}");
                counts[expected as usize] += 1;
            }
        }
        assert!(counts[0] > 10_000 && counts[1] > 10_000, "{counts:?}");
    }

    #[test]
    fn a_mask_naming_the_base_colour_texture_counts_its_alpha_once() {
        // An MTL material with `map_Kd leaf.png` and `map_d leaf.png`: one
        // texture, alpha 0.6 everywhere. Squared (0.36), it would be a hole
        // under the cutoff of one half; counted once, it is solid.
        let mut scene = Scene::default();
        let texels = vec![[40, 120, 30, 153]; 4];
        scene.textures.push(Texture::from_rgba8("leaf", 2, 2, texels, ColorEncoding::Srgb).unwrap());
        for (base, mask) in [(Some(0), Some(0)), (None, Some(0)), (Some(0), None)] {
            scene.materials.push(Material {
                alpha_mode: AlphaMode::Mask { cutoff: 0.5 },
                base_color_texture: base.map(TextureId),
                alpha_texture: mask.map(TextureId),
                ..Material::default()
            });
            let first = scene.vertices.len() as u32;
            for uv in [Vec2::ZERO, Vec2::X, Vec2::Y] {
                scene.vertices.push(Vertex {
                    position: Vec3::ZERO,
                    normal: Vec3::Z,
                    uv,
                    uv1: Vec2::ZERO,
                    color: Vec4::ONE,
                    tangent: Vec4::X,
                });
            }
            let material = scene.materials.len() as u32 - 1;
            scene.triangles.push(Triangle { vertices: [first, first + 1, first + 2], material });
        }
        let prepared = AlphaTest::new(&scene);
        for triangle in 0..3 {
            assert!(alpha_accepts(&scene, triangle, 0.3, 0.3, 0.5), "material {triangle}");
            assert!(prepared.accepts(triangle, 0.3, 0.3, 0.5), "material {triangle}");
        }
    }
}
