//! Converged references, rendered once and cached on disk.
//!
//! A reference is the average of two renders with seeds of their own,
//! independent of the seeds of the renders measured against it (a
//! reference with the same seed shares their first samples, and the
//! error looks smaller than it is). The two halves also give the
//! reference's own noise: if each half has variance `σ²` per pixel, their
//! difference has `2σ²` and their average `σ²/2`, so the average's RMSE
//! against the truth is about `RMSE(half₁, half₂) / 2`.
//!
//! A reference rendered by the estimator it judges would share its bias, and
//! no comparison would show it. So each reference is checked against a
//! second, independent estimator (the uniform sampler, light sampling
//! without MIS, no Russian roulette), rendered the same way in two halves;
//! their difference against their combined noise is reported
//! ([`IndependentCheck`]). The cache keeps references under the code's
//! version, so a change to the renderer renders them again.

use std::path::Path;

use rtgi_image::HdrImage;
use rtgi_render::RenderSettings;
use serde::{Deserialize, Serialize};

use crate::provenance::Build;
use crate::report::{IndependentCheck, ReferenceInfo};
use crate::{ExperimentError, Subject};

/// The depth of every path-traced reference: deeper than any depth
/// measured, and deep enough that what a path brings back after it is below
/// the reference's noise. So every configuration of every knob on a scene
/// is measured against the same converged image, and a shallow default
/// depth shows as the bias it is; the knobs share the cached reference.
pub(crate) const CONVERGED_DEPTH: u32 = 64;

/// Seeds of the two halves: far from the small seeds (0, 1, 2, ...) of the measured renders.
const SEEDS: [u64; 2] = [0x5eed_0000_0000_0001, 0x5eed_0000_0000_0002];

/// Seeds of the independent estimator's halves.
const CHECK_SEEDS: [u64; 2] = [0x5eed_0000_0000_0003, 0x5eed_0000_0000_0004];

/// The independent estimator takes this fraction of the reference's
/// samples: without roulette its paths run to the depth limit.
const CHECK_FRACTION: u32 = 8;

/// What the cache keeps beside each reference image.
#[derive(Serialize, Deserialize)]
struct Meta {
    key: String,
    samples_per_pixel: u32,
    noise_rmse: f64,
    settings: String,
    estimator: String,
    check: Option<IndependentCheck>,
}

/// A reference image and what is known of it.
#[derive(Debug)]
pub struct Reference {
    /// The converged image, linear radiance.
    pub image: HdrImage,
    /// How it was made: samples, seeds, its own noise, whether it was cached.
    pub info: ReferenceInfo,
}

impl Reference {
    /// The mean over pixels of the brightest channel's radiance: the scale
    /// clamps are given in.
    pub fn mean_radiance(&self) -> f64 {
        let pixels = self.image.pixels();
        pixels.iter().map(|p| p.max_element() as f64).sum::<f64>() / pixels.len().max(1) as f64
    }
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
    let described = format!(
        "{:?}|{:?}|{:?}|{}|{}",
        scene.materials,
        scene.lights,
        subject.camera,
        describe(settings),
        Build::this().code_version()
    );
    hash = hash.bytes(described.as_bytes());
    format!("{:016x}", hash.0)
}

/// The settings that change what a render converges to (not its noise).
pub(crate) fn describe(settings: &RenderSettings) -> String {
    format!(
        "{}x{} {} depth {} background {:?} clamp {:?} filter glossy {:?} up {:?} environment {:?} effects {:?}",
        settings.width,
        settings.height,
        settings.integrator,
        settings.max_depth,
        settings.background,
        settings.indirect_clamp,
        settings.filter_glossy,
        settings.up,
        settings.environment.as_ref().map(|e| match e {
            rtgi_render::Environment::Uniform(radiance) => format!("uniform {radiance:?}"),
            rtgi_render::Environment::Map(_) => format!("map of mean {:?}", e.mean_radiance()),
        }),
        settings.effects
    ) + &settings.sun_towards.map_or(String::new(), |towards| format!(" sun towards {towards:?}"))
}

/// The estimator's settings, in words.
fn estimator(settings: &RenderSettings) -> String {
    format!(
        "{} sampler, {} direct light, roulette {}",
        settings.sampler,
        settings.direct_strategy,
        if settings.russian_roulette { "on" } else { "off" }
    )
}

/// Two renders of `settings` with `seeds`: their average and its noise (half their RMSE difference).
fn halves(subject: &Subject, settings: &RenderSettings, seeds: [u64; 2]) -> (HdrImage, f64, [HdrImage; 2]) {
    let [a, b] =
        seeds.map(|seed| crate::measure::render_timed(subject, &RenderSettings { seed, ..settings.clone() }).0);
    let noise = rtgi_image::compare(&a, &b).expect("same size").rmse / 2.0;
    let pixels = a.pixels().iter().zip(b.pixels()).map(|(x, y)| (*x + *y) * 0.5).collect();
    (HdrImage::from_pixels(settings.width, settings.height, pixels).expect("sizes agree"), noise, [a, b])
}

/// The means of `side`×`side` blocks of `image` (partial blocks at the edges are left out).
fn blocks(image: &HdrImage, side: u32) -> HdrImage {
    let (w, h) = ((image.width() / side).max(1), (image.height() / side).max(1));
    let side = side.min(image.width()).min(image.height()).max(1);
    let pixels = (0..w * h)
        .map(|i| {
            let (bx, by) = (i % w, i / w);
            let mut sum = rtgi_math::Vec3::ZERO;
            for y in by * side..(by + 1) * side {
                for x in bx * side..(bx + 1) * side {
                    sum += image.pixels()[(y * image.width() + x) as usize];
                }
            }
            sum / (side * side) as f32
        })
        .collect();
    HdrImage::from_pixels(w, h, pixels).expect("sizes agree")
}

/// Compares the reference (its halves) with the independent estimator's (its halves).
fn check(
    reference: ([&HdrImage; 2], &HdrImage, f64),
    independent: ([&HdrImage; 2], &HdrImage, f64),
    estimator: String,
    samples_per_pixel: u32,
) -> IndependentCheck {
    let rmse = |a: &HdrImage, b: &HdrImage| rtgi_image::compare(a, b).expect("same size").rmse;
    let block_noise = |[a, b]: [&HdrImage; 2]| rmse(&blocks(a, 8), &blocks(b, 8)) / 2.0;
    let (ref_halves, ref_image, ref_noise) = reference;
    let (ind_halves, ind_image, ind_noise) = independent;
    IndependentCheck {
        estimator,
        samples_per_pixel,
        noise_rmse: ind_noise,
        difference_rmse: rmse(ref_image, ind_image),
        expected_rmse: ref_noise.hypot(ind_noise),
        block_difference_rmse: rmse(&blocks(ref_image, 8), &blocks(ind_image, 8)),
        block_expected_rmse: block_noise(ref_halves).hypot(block_noise(ind_halves)),
    }
}

/// The reference for `settings` at `samples_per_pixel`, from `cache` if it
/// holds one of this code, otherwise rendered (stratified, MIS, Russian
/// roulette, paths to [`CONVERGED_DEPTH`]), checked against the independent
/// estimator, and stored there.
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
    if settings.integrator == rtgi_render::Integrator::Path {
        settings.max_depth = settings.max_depth.max(CONVERGED_DEPTH);
    }
    let key = format!("{}-{}", key(subject, &settings), settings.samples_per_pixel * 2);
    let paths = cache.map(|folder| (folder.join(format!("{key}.exr")), folder.join(format!("{key}.json"))));
    let info = |meta: &Meta, cached| ReferenceInfo {
        samples_per_pixel: meta.samples_per_pixel,
        estimator: meta.estimator.clone(),
        seeds: SEEDS,
        noise_rmse: meta.noise_rmse,
        check: meta.check.clone(),
        settings: meta.settings.clone(),
        code_version: Build::this().code_version(),
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
    let (image, noise, [a, b]) = halves(subject, &settings, SEEDS);
    let independent = RenderSettings {
        samples_per_pixel: (settings.samples_per_pixel / CHECK_FRACTION).max(1),
        sampler: rtgi_render::PixelSampler::Uniform,
        direct_strategy: rtgi_render::DirectStrategy::Light,
        russian_roulette: false,
        ..settings.clone()
    };
    progress(&format!(
        "rendering its independent check of {} spp ({})",
        independent.samples_per_pixel * 2,
        estimator(&independent)
    ));
    let (check_image, check_noise, [c, d]) = halves(subject, &independent, CHECK_SEEDS);
    let check = check(
        ([&a, &b], &image, noise),
        ([&c, &d], &check_image, check_noise),
        estimator(&independent),
        independent.samples_per_pixel * 2,
    );
    let meta = Meta {
        key: key.clone(),
        samples_per_pixel: settings.samples_per_pixel * 2,
        noise_rmse: noise,
        settings: describe(&settings),
        estimator: estimator(&settings),
        check: Some(check),
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
