//! Converged references, rendered once and cached on disk.
//!
//! A reference is the average of two renders with seeds of their own,
//! independent of the seeds of the renders measured against it (a
//! reference with the same seed shares their first samples, and the
//! error looks smaller than it is). The two halves also give the
//! reference's own noise: if each half has variance `σ²` per pixel, their
//! difference has `2σ²` and their average `σ²/2`, so the average's RMSE
//! against the truth is about `RMSE(half₁, half₂) / 2`.

use std::path::Path;

use rtgi_image::HdrImage;
use rtgi_render::RenderSettings;
use serde::{Deserialize, Serialize};

use crate::report::ReferenceInfo;
use crate::{ExperimentError, Subject};

/// Seeds of the two halves: far from the small seeds (0, 1, 2, ...) of the measured renders.
const SEEDS: [u64; 2] = [0x5eed_0000_0000_0001, 0x5eed_0000_0000_0002];

/// What the cache keeps beside each reference image.
#[derive(Serialize, Deserialize)]
struct Meta {
    key: String,
    samples_per_pixel: u32,
    noise_rmse: f64,
    settings: String,
}

/// A reference image and what is known of it.
#[derive(Debug)]
pub struct Reference {
    /// The converged image, linear radiance.
    pub image: HdrImage,
    /// How it was made: samples, seeds, its own noise, whether it was cached.
    pub info: ReferenceInfo,
}

/// FNV-1a, 64 bits: a stable hash for cache keys (std's hasher may change between Rust versions).
#[derive(Clone, Copy)]
struct Fnv(u64);

impl Fnv {
    fn new() -> Fnv {
        Fnv(0xcbf2_9ce4_8422_2325)
    }

    fn bytes(mut self, bytes: &[u8]) -> Fnv {
        for &b in bytes {
            self.0 = (self.0 ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3);
        }
        self
    }
}

/// A key for the scene's geometry and materials, the camera, and the
/// settings that decide what the reference converges to.
fn key(subject: &Subject, settings: &RenderSettings) -> String {
    let scene = &subject.scene;
    let mut hash = Fnv::new();
    for v in &scene.vertices {
        for c in v.position.to_array().into_iter().chain(v.normal.to_array()).chain(v.uv.to_array()) {
            hash = hash.bytes(&c.to_bits().to_le_bytes());
        }
    }
    for t in &scene.triangles {
        for i in t.vertices {
            hash = hash.bytes(&i.to_le_bytes());
        }
        hash = hash.bytes(&t.material.to_le_bytes());
    }
    let described = format!("{:?}|{:?}|{:?}|{}", scene.materials, scene.lights, subject.camera, describe(settings));
    hash = hash.bytes(described.as_bytes());
    format!("{:016x}", hash.0)
}

/// The settings that change what a render converges to (not its noise).
pub(crate) fn describe(settings: &RenderSettings) -> String {
    format!(
        "{}x{} {} depth {} background {:?} clamp {:?} environment {:?} effects {:?}",
        settings.width,
        settings.height,
        settings.integrator,
        settings.max_depth,
        settings.background,
        settings.indirect_clamp,
        settings.environment.as_ref().map(|e| match e {
            rtgi_render::Environment::Uniform(radiance) => format!("uniform {radiance:?}"),
            rtgi_render::Environment::Map(_) => format!("map of mean {:?}", e.mean_radiance()),
        }),
        settings.effects
    )
}

/// The reference for `settings` at `samples_per_pixel`, from `cache` if it
/// holds one, otherwise rendered (stratified, MIS, Russian roulette) and stored there.
pub(crate) fn reference(
    subject: &Subject,
    settings: &RenderSettings,
    samples_per_pixel: u32,
    cache: Option<&Path>,
    progress: &dyn Fn(&str),
) -> Result<Reference, ExperimentError> {
    let mut settings = settings.clone();
    settings.samples_per_pixel = samples_per_pixel.div_ceil(2).max(1);
    settings.sampler = rtgi_render::PixelSampler::Stratified;
    settings.direct_strategy = rtgi_render::DirectStrategy::Mis;
    settings.russian_roulette = true;
    let key = format!("{}-{}", key(subject, &settings), settings.samples_per_pixel * 2);
    let paths = cache.map(|folder| (folder.join(format!("{key}.exr")), folder.join(format!("{key}.json"))));
    let info = |meta: &Meta, cached| ReferenceInfo {
        samples_per_pixel: meta.samples_per_pixel,
        seeds: SEEDS,
        noise_rmse: meta.noise_rmse,
        settings: meta.settings.clone(),
        cached,
    };
    if let Some((image_path, meta_path)) = &paths
        && let (Ok(image), Ok(text)) = (HdrImage::read_exr(image_path), std::fs::read_to_string(meta_path))
        && let Ok(meta) = serde_json::from_str::<Meta>(&text)
        && meta.key == key
        && image.width() == settings.width
        && image.height() == settings.height
    {
        return Ok(Reference { info: info(&meta, true), image });
    }
    progress(&format!("rendering a reference of {} spp ({})", settings.samples_per_pixel * 2, describe(&settings)));
    let halves: Vec<HdrImage> = SEEDS
        .iter()
        .map(|&seed| crate::runner::render(subject, &RenderSettings { seed, ..settings.clone() }).0)
        .collect();
    let noise = rtgi_image::compare(&halves[0], &halves[1]).expect("same size").rmse / 2.0;
    let pixels = halves[0].pixels().iter().zip(halves[1].pixels()).map(|(a, b)| (*a + *b) * 0.5).collect();
    let image = HdrImage::from_pixels(settings.width, settings.height, pixels).expect("sizes agree");
    let meta = Meta {
        key: key.clone(),
        samples_per_pixel: settings.samples_per_pixel * 2,
        noise_rmse: noise,
        settings: describe(&settings),
    };
    if let Some((image_path, meta_path)) = &paths {
        store(&image, image_path, meta_path, &meta)?;
    }
    Ok(Reference { info: info(&meta, false), image })
}

fn store(image: &HdrImage, image_path: &Path, meta_path: &Path, meta: &Meta) -> Result<(), ExperimentError> {
    let folder = image_path.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(folder).map_err(|source| ExperimentError::Write { path: folder.to_owned(), source })?;
    image
        .write(image_path, &rtgi_image::ToneMap::default())
        .map_err(|e| ExperimentError::Image { path: image_path.to_owned(), message: e.to_string() })?;
    let json = serde_json::to_string_pretty(meta).expect("metadata serialises");
    std::fs::write(meta_path, json).map_err(|source| ExperimentError::Write { path: meta_path.to_owned(), source })
}
