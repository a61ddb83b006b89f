//! What makes two renders the same render: the image's size, the samples
//! and seed, the scene, the camera and every setting. Checkpoints and the
//! parts of a split render carry it, so that resuming or merging refuses
//! anything that would not add up to the render asked for.

use std::collections::BTreeMap;

use rtgi_scene::{Camera, Scene};
use serde::{Deserialize, Serialize};

use crate::{Environment, RenderSettings};

/// The identity of a render. Two accumulations can be added together only
/// when their identities are equal.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct RenderIdentity {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel of the whole render (the stratified sampler's
    /// pattern depends on it, so a part of a render knows its total).
    pub samples_per_pixel: u32,
    /// The seed of every sample's random numbers.
    pub seed: u64,
    /// FNV-1a of the geometry, materials, textures and lights, in hex.
    pub scene: String,
    /// The camera, exactly (the bits of every number).
    pub camera: String,
    /// Every other setting, by name, as text.
    pub settings: BTreeMap<String, String>,
    /// The version of rtgi that rendered it: another version may compute other bits.
    pub version: String,
}

impl RenderIdentity {
    /// The identity of rendering `scene` through `camera` with `settings`.
    pub fn new(scene: &Scene, camera: &Camera, settings: &RenderSettings) -> Self {
        // Destructured without `..`, so that a new setting cannot be forgotten here.
        let RenderSettings {
            width,
            height,
            samples_per_pixel,
            sampler,
            seed,
            background,
            integrator,
            max_depth,
            direct_strategy,
            indirect_clamp,
            filter_glossy,
            russian_roulette,
            roulette_start,
            bounce_sampling,
            environment,
            effects,
            default_lighting,
            up,
            sun_towards,
            // Adaptive renders are never accumulated ([`crate::render_pass`] refuses them).
            adaptive: _,
        } = settings;
        let environment = match environment {
            None => "planned".to_owned(),
            Some(Environment::Uniform(radiance)) => format!("uniform {radiance:?}"),
            Some(Environment::Map(map)) => {
                let bits =
                    map.image().pixels().iter().flat_map(|p| p.to_array()).flat_map(|c| c.to_bits().to_le_bytes());
                let (w, h) = (map.image().width(), map.image().height());
                format!("map {w}x{h} {:016x} turned {:?}", Fnv::new().bytes(bits).0, map.turn())
            }
        };
        let settings = [
            ("sampler", sampler.name().to_owned()),
            ("background", format!("{background:?}")),
            ("integrator", integrator.to_string()),
            ("max depth", max_depth.to_string()),
            ("direct strategy", format!("{direct_strategy:?}")),
            ("indirect clamp", format!("{indirect_clamp:?}")),
            ("filter glossy", format!("{filter_glossy:?}")),
            ("russian roulette", russian_roulette.to_string()),
            ("roulette start", roulette_start.to_string()),
            ("bounce sampling", bounce_sampling.to_string()),
            ("environment", environment),
            ("effects", format!("{effects:?}")),
            ("up", format!("{up:?}")),
            ("default lighting", format!("{default_lighting:?}")),
        ];
        // Only where a view set it, so that other renders keep their identity.
        let sun = sun_towards.map(|towards| ("sun towards".to_owned(), format!("{towards:?}")));
        Self {
            width: *width,
            height: *height,
            samples_per_pixel: (*samples_per_pixel).max(1),
            seed: *seed,
            scene: format!("{:016x}", scene_fingerprint(scene)),
            camera: format!("{camera:?}"),
            settings: settings.into_iter().map(|(k, v)| (k.to_owned(), v)).chain(sun).collect(),
            version: env!("CARGO_PKG_VERSION").to_owned(),
        }
    }

    /// What differs between `self` and `other`; empty if they are the same render.
    pub fn differences(&self, other: &RenderIdentity) -> Vec<Difference> {
        let mut differences = Vec::new();
        let mut compare = |what: &str, ours: String, theirs: String| {
            if ours != theirs {
                differences.push(Difference { what: what.to_owned(), ours, theirs });
            }
        };
        compare("size", format!("{}x{}", self.width, self.height), format!("{}x{}", other.width, other.height));
        compare("samples per pixel", self.samples_per_pixel.to_string(), other.samples_per_pixel.to_string());
        compare("seed", self.seed.to_string(), other.seed.to_string());
        compare("scene", self.scene.clone(), other.scene.clone());
        compare("camera", self.camera.clone(), other.camera.clone());
        compare("rtgi version", self.version.clone(), other.version.clone());
        let names: std::collections::BTreeSet<&String> = self.settings.keys().chain(other.settings.keys()).collect();
        for name in names {
            let value = |map: &BTreeMap<String, String>| map.get(name).cloned().unwrap_or_else(|| "(none)".into());
            compare(name, value(&self.settings), value(&other.settings));
        }
        differences
    }

    #[cfg(test)]
    pub(crate) fn for_tests(width: u32, height: u32, samples_per_pixel: u32) -> Self {
        Self {
            width,
            height,
            samples_per_pixel,
            seed: 0,
            scene: "0".into(),
            camera: "camera".into(),
            settings: BTreeMap::new(),
            version: "test".into(),
        }
    }
}

/// One way two renders differ: what, and its value in each.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Difference {
    /// What differs, like `seed` or `camera`.
    pub what: String,
    /// Its value in this render.
    pub ours: String,
    /// Its value in the other.
    pub theirs: String,
}

impl std::fmt::Display for Difference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} {} vs {}", self.what, self.ours, self.theirs)
    }
}

/// A stable 64-bit hash of what a scene renders: positions, normals,
/// texture coordinates and tangents of every vertex, the triangles, and
/// the materials, textures (name, size, encoding and average) and lights.
/// Stable across runs and Rust versions (FNV-1a), unlike std's hasher.
pub fn scene_fingerprint(scene: &Scene) -> u64 {
    let mut hash = Fnv::new();
    for v in &scene.vertices {
        let numbers = v.position.to_array().into_iter().chain(v.normal.to_array()).chain(v.uv.to_array());
        hash = hash.bytes(numbers.chain(v.tangent.to_array()).flat_map(|c| c.to_bits().to_le_bytes()));
    }
    for t in &scene.triangles {
        hash = hash.bytes(t.vertices.iter().chain([&t.material]).flat_map(|i| i.to_le_bytes()));
    }
    let textures: Vec<String> = scene.textures.iter().map(|t| format!("{t:?} {:?}", t.average())).collect();
    let described = format!("{:?}|{:?}|{textures:?}", scene.materials, scene.lights);
    hash.bytes(described.bytes()).0
}

/// FNV-1a, 64 bits: the scene fingerprint here, and the checksum of
/// accumulation files.
#[derive(Clone, Copy)]
pub(crate) struct Fnv(pub(crate) u64);

impl Fnv {
    pub(crate) fn new() -> Fnv {
        Fnv(0xcbf2_9ce4_8422_2325)
    }

    /// Feeds `bytes` in.
    pub(crate) fn update(&mut self, bytes: impl IntoIterator<Item = u8>) {
        for b in bytes {
            self.0 = (self.0 ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }

    fn bytes(mut self, bytes: impl IntoIterator<Item = u8>) -> Fnv {
        self.update(bytes);
        self
    }
}
