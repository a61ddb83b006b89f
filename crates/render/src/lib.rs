//! Ray casting and shading: from a scene, an acceleration structure and a
//! camera to an HDR image.
//!
//! Rendering is parallel over square tiles with rayon. Every sample draws
//! its random numbers from a generator seeded by (seed, pixel, sample), and
//! each pixel sums its samples in sample order, so the image is
//! bit-identical whatever the number of threads.
//!
//! ```no_run
//! use rtgi_accel::{AccelKind, BuildParams};
//! use rtgi_render::{RenderSettings, default_camera, render};
//! use rtgi_scene::Scene;
//!
//! let scene = Scene::load("scenes/cornell-box.toml".as_ref())?;
//! let accel = AccelKind::Linear.build(&scene.triangle_positions(), &BuildParams::default());
//! let settings = RenderSettings { width: 256, height: 256, ..RenderSettings::default() };
//! // The scene's first camera, or a view framing it if it has none.
//! let camera = default_camera(&scene, accel.as_ref(), 1.0);
//! let (image, stats) = render(&scene, accel.as_ref(), &camera, &settings, &|_| {});
//! println!("{} rays in {:.1} ms", stats.rays, stats.render_ms);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![warn(missing_docs)]

// The README's examples are compiled and run as doctests.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;

mod accumulation;
mod accumulation_file;
pub mod adaptive;
mod alpha;
mod automatic_view;
mod bounce_sampling;
pub mod bsdf;
mod camera;
pub mod camera_choice;
mod default_lighting;
mod denoise;
mod distribution;
mod effect_set;
pub mod effects;
mod framing;
mod identity;
mod integrator;
pub mod layered;
pub mod lights;
pub mod probes;
pub mod rays;
pub mod recipe;
mod regularisation;
mod sampler;
mod shade;
mod shading_normal;
mod surface_layers;
pub mod up_axis;
pub mod view_lighting;

pub use accumulation::{Accumulation, FIXED_POINT_BITS, MergeError, PartSpan, PixelSum, SAMPLE_LIMIT};
pub use accumulation_file::{AccumulationFileError, MergeFilesError};
pub use adaptive::{AdaptiveSampling, render_adaptive};
pub use alpha::{AlphaTest, alpha_accepts, has_alpha};
pub use automatic_view::{AutomaticView, ModelSide, SideReason};
pub use bounce_sampling::BounceSampling;
pub use camera::CameraRays;
pub use default_lighting::{ENCLOSED, default_sky, default_sun, flat_view_sun, room_light, sky_visibility};
pub use denoise::{
    DenoiseError, DenoiseSettings, FIREFLY_FROM_SAMPLES, GUIDE_SAMPLES, Guides, denoise, render_denoised,
};
pub use distribution::Distribution1D;
pub use effect_set::EffectSet;
pub use effects::{Effect, EffectOverrides, EffectPlan, PlannedEffect, Reversal};
pub use framing::{
    DEFAULT_VERTICAL_FOV_DEGREES, camera_blocked, default_camera, frame_scene, frame_scene_explained, frame_scene_up,
    framed_tightly, three_quarter_view,
};
pub use identity::{Difference, RenderIdentity, scene_fingerprint};
pub use integrator::{DirectStrategy, Integrator, ROULETTE_START};
pub use lights::{Environment, EnvironmentMap, EnvironmentSpec, EnvironmentSpecError, LightSet};
pub use regularisation::FilterGlossy;
pub use sampler::{PixelPattern, PixelSample, PixelSampler, VertexNumbers};
pub use shade::{albedo, emission, shade_primary, shading_normal};

use std::ops::Range;
use std::time::Instant;

use rayon::prelude::*;
use rtgi_accel::{Accel, Hit, TraversalCounters};
use rtgi_image::HdrImage;
use rtgi_math::{Ray, Rng, Vec2, Vec3};
use rtgi_scene::{Camera, Scene};
use serde::Serialize;

use crate::accumulation::{image_of_sums, to_fixed};
use crate::effects::SPECIALISED;
use crate::integrator::Transport;

/// Side of the square tiles that threads take one at a time.
pub const TILE_SIZE: u32 = 16;

/// What to render and how.
///
/// The default is what the `rtgi` command renders: a 512 × 512 path-traced
/// image of 16 stratified samples per pixel (antialiased), MIS for direct
/// light, up to 8 bounces with Russian roulette.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel.
    pub samples_per_pixel: u32,
    /// Where in its pixel each sample's camera ray passes.
    pub sampler: PixelSampler,
    /// Seed of the random numbers: every sample draws from `(seed, pixel, sample)`, so one seed gives one image.
    pub seed: u64,
    /// Radiance of camera rays that hit nothing, when no environment is seen.
    pub background: Vec3,
    /// What a camera ray's sample computes: an AOV, direct light, or full paths.
    pub integrator: Integrator,
    /// Bounces a path may take after the camera ray (1 = direct light only).
    pub max_depth: u32,
    /// How direct light is sampled: from the lights, from the BSDF, or both weighted by MIS.
    pub direct_strategy: DirectStrategy,
    /// Largest value (brightest channel) of the light one path brings in
    /// after two or more bounces: removes the fireflies of caustics at the
    /// price of a bias (darker caustics and highlights). `None` keeps every path exact.
    pub indirect_clamp: Option<f32>,
    /// Path regularisation ([`FilterGlossy`]): after a diffuse or rough
    /// bounce, sharp lobes are widened to a GGX width of up to 0.5, so that
    /// caustics seen through diffuse bounces are found by light sampling
    /// instead of as fireflies. Biased (blurrier caustics); `None` keeps
    /// every lobe as the material says.
    pub filter_glossy: Option<FilterGlossy>,
    /// Russian roulette: after two bounces, end paths that carry little
    /// light with a probability that grows as they dim, and weigh the
    /// survivors up. Unbiased; off, every path runs to `max_depth`.
    pub russian_roulette: bool,
    /// The bounce from which Russian roulette may end paths (after the
    /// second, [`ROULETTE_START`], by default).
    pub roulette_start: u32,
    /// Where bounce directions (and the BSDF strategy's direct-light rays)
    /// come from: the BSDF, or the cosine or uniform hemisphere.
    pub bounce_sampling: BounceSampling,
    /// Light from far away; `None` leaves it to the planner (a white sky
    /// when the scene has no light of its own).
    pub environment: Option<Environment>,
    /// Effects forced on or off, whatever the scene needs.
    pub effects: EffectOverrides,
    /// Whether the planner may add the default sky and sun (and the lamp of
    /// an enclosed camera), and whether a probe of the view found the
    /// scene's own lights too weak for it.
    pub default_lighting: DefaultLighting,
    /// Which way is up in the scene: the zenith of the default sky and the
    /// side the default sun shines from ([`up_axis`]; +Y by default, +Z
    /// for a model found standing on a base across Z).
    pub up: Vec3,
    /// The direction towards the default sun (a unit vector), where the
    /// view asks for its own ([`default_lighting::flat_view_sun`]: a flat
    /// model seen straight on); `None` puts it at the upper front right of
    /// the model, by `up`.
    pub sun_towards: Option<Vec3>,
    /// Adaptive sampling: `samples_per_pixel` is then the most a pixel
    /// takes, in rounds, each pixel stopping at the noise target or all at
    /// the time bound ([`adaptive`]); `None` renders every pixel's samples.
    pub adaptive: Option<AdaptiveSampling>,
}

/// Light the planner adds to scenes that bring too little of their own.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum DefaultLighting {
    /// The default sky and sun for scenes without lights or with emitters
    /// too weak to light them (judged by their power).
    #[default]
    Auto,
    /// As `Auto`, and the view was probed
    /// ([`view_lighting::view_light`]): the scene's own lights
    /// give the surfaces in view this fraction of the default sky and
    /// sun's light, too little, so those are added.
    ViewUnlit(f32),
    /// As `Auto`, and the view was probed: the scene's lights are all
    /// punctual and light it, and glossy or metal surfaces in view would
    /// reflect black, so a dim grey environment of this radiance is set
    /// ([`view_lighting::REFLECTED_SHARE`] of their light) for them to reflect.
    Reflections(f32),
    /// Never: only the scene's lights and the options' light it.
    Off,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            width: 512,
            height: 512,
            samples_per_pixel: 16,
            sampler: PixelSampler::Stratified,
            seed: 0,
            background: Vec3::new(0.05, 0.05, 0.06),
            integrator: Integrator::Path,
            max_depth: 8,
            direct_strategy: DirectStrategy::Mis,
            indirect_clamp: None,
            filter_glossy: None,
            russian_roulette: true,
            roulette_start: ROULETTE_START,
            bounce_sampling: BounceSampling::Bsdf,
            environment: None,
            effects: EffectOverrides::default(),
            default_lighting: DefaultLighting::Auto,
            up: Vec3::Y,
            sun_towards: None,
            adaptive: None,
        }
    }
}

/// What a render did and how long it took.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct RenderStats {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel rendered.
    pub samples_per_pixel: u32,
    /// Rays traced, of all kinds.
    pub rays: u64,
    /// Wall-clock time of the render, in milliseconds.
    pub render_ms: f64,
}

impl RenderStats {
    /// Rays traced per second of wall-clock time.
    pub fn rays_per_second(&self) -> f64 {
        self.rays as f64 / (self.render_ms * 1e-3).max(1e-9)
    }
}

/// The rectangles that make up rows `rows` of an image, in row-major order.
fn tiles(width: u32, rows: Range<u32>) -> Vec<(u32, u32, u32, u32)> {
    let mut tiles = Vec::new();
    for y0 in rows.clone().step_by(TILE_SIZE as usize) {
        for x0 in (0..width).step_by(TILE_SIZE as usize) {
            tiles.push((x0, y0, (x0 + TILE_SIZE).min(width), (y0 + TILE_SIZE).min(rows.end)));
        }
    }
    tiles
}

/// Renders `scene` as `settings.integrator` says: each pixel averages its
/// samples. For the light-transport integrators the effects planner
/// ([`EffectPlan::new`]) decides what is simulated.
///
/// `progress` is called from the worker threads with the number of pixels
/// finished since its last call; it must be cheap.
///
/// Any structure is passed as `&dyn Accel` (a `&Bvh8` coerces to it), as
/// to the other functions that trace a whole view ([`render_pass`],
/// [`render_adaptive`], [`render_denoised`], [`Guides::render`],
/// [`view_lighting::view_light`], [`render_traversal_cost`]): the renderer is compiled
/// once, in this crate, rather than again in every crate that renders, and
/// one virtual call a ray is nothing beside the ray's traversal.
///
/// The image has the same bits as any progressive or split render of the
/// same settings ([`render_pass`], [`Accumulation::merge`]). With
/// [`RenderSettings::adaptive`], pixels take samples in rounds until their
/// noise is low enough ([`render_adaptive`], which also says how each
/// round went); such renders are not split.
///
/// # Panics
/// If `settings.adaptive` cannot run ([`AdaptiveSampling::check`]: a
/// sampler laid out for a fixed count, or no target).
pub fn render(
    scene: &Scene,
    accel: &dyn Accel,
    camera: &Camera,
    settings: &RenderSettings,
    progress: &(dyn Fn(u64) + Sync),
) -> (HdrImage, RenderStats) {
    if settings.adaptive.is_some() {
        let start = Instant::now();
        let (image, outcome) = render_adaptive(scene, accel, camera, settings, &mut |_| {})
            .unwrap_or_else(|e| panic!("adaptive sampling as the settings ask cannot run: {e}"));
        progress(settings.width as u64 * settings.height as u64);
        let stats = RenderStats {
            width: settings.width,
            height: settings.height,
            samples_per_pixel: outcome.samples_reached,
            rays: outcome.rays(),
            render_ms: start.elapsed().as_secs_f64() * 1e3,
        };
        return (image, stats);
    }
    let spp = settings.samples_per_pixel.max(1);
    let per_pixel = |done: u64| progress(done / spp as u64);
    let control = PassControl { progress: &per_pixel, cancelled: &|| false };
    let (sums, stats) = render_sums(scene, accel, camera, settings, 0..settings.height, 0..spp, &control)
        .expect("a render that cannot be cancelled finishes");
    (image_of_sums(settings.width, settings.height, 0, &sums, spp), stats)
}

/// How a pass of [`render_pass`] reports its progress and is told to stop.
#[derive(Clone, Copy)]
pub struct PassControl<'a> {
    /// Called from the worker threads with the pixel samples finished since
    /// its last call (pixels × samples); it must be cheap.
    pub progress: &'a (dyn Fn(u64) + Sync),
    /// Polled from the worker threads between samples; once it returns
    /// true the pass is abandoned.
    pub cancelled: &'a (dyn Fn() -> bool + Sync),
}

impl std::fmt::Debug for PassControl<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PassControl").finish_non_exhaustive()
    }
}

/// A pass stopped by [`PassControl::cancelled`]; the accumulation is as it was before it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("the pass was cancelled")]
pub struct Cancelled;

/// Renders the next `count` samples of every pixel of `accumulation`'s
/// rows and adds them to it: one pass of a progressive render, or a job of
/// a split one. However a render is cut into passes, ranges of samples
/// ([`Accumulation::new`] at a first sample other than 0) and bands of rows,
/// the sums come out the same, bit for bit, as those of [`render`].
///
/// If `control` cancels the pass, `accumulation` is left untouched.
///
/// # Panics
/// If `accumulation` is of another size, seed or sample count than
/// `settings`, `count` goes past the render's samples, or the settings are
/// adaptive.
pub fn render_pass(
    scene: &Scene,
    accel: &dyn Accel,
    camera: &Camera,
    settings: &RenderSettings,
    accumulation: &mut Accumulation,
    count: u32,
    control: &PassControl<'_>,
) -> Result<RenderStats, Cancelled> {
    assert!(settings.adaptive.is_none(), "adaptive renders are rendered in one go, not in passes");
    let identity = accumulation.identity();
    assert!(
        (identity.width, identity.height, identity.samples_per_pixel, identity.seed)
            == (settings.width, settings.height, settings.samples_per_pixel.max(1), settings.seed),
        "the accumulation is of another render"
    );
    let samples = accumulation.samples();
    assert!(
        samples.end + count <= identity.samples_per_pixel,
        "samples past the render's {}",
        identity.samples_per_pixel
    );
    let range = samples.end..samples.end + count;
    let (sums, mut stats) = render_sums(scene, accel, camera, settings, accumulation.rows(), range, control)?;
    accumulation.add_pass(sums, count);
    stats.samples_per_pixel = count;
    Ok(stats)
}

/// The fixed-point sums of samples `samples` of every pixel of rows
/// `rows`, and what rendering them took.
fn render_sums<A: Accel + ?Sized>(
    scene: &Scene,
    accel: &A,
    camera: &Camera,
    settings: &RenderSettings,
    rows: Range<u32>,
    samples: Range<u32>,
    control: &PassControl<'_>,
) -> Result<(Vec<PixelSum>, RenderStats), Cancelled> {
    render_sums_of(scene, accel, camera, settings, rows, samples, None, control)
}

/// [`render_sums`] of the pixels `active` marks (all without it; indexed
/// by `y · width + x`); the other pixels' sums are zero.
#[allow(clippy::too_many_arguments)]
pub(crate) fn render_sums_of<A: Accel + ?Sized>(
    scene: &Scene,
    accel: &A,
    camera: &Camera,
    settings: &RenderSettings,
    rows: Range<u32>,
    samples: Range<u32>,
    active: Option<&[bool]>,
    control: &PassControl<'_>,
) -> Result<(Vec<PixelSum>, RenderStats), Cancelled> {
    let start = Instant::now();
    // The views of the closest hit follow the plan for alpha and textures too.
    let plan = EffectPlan::new(scene, settings);
    let (alpha, textures) = (plan.has(Effect::Alpha), plan.has(Effect::Textures));
    // The light-transport integrators prepare their own.
    let cut_outs = (alpha && !settings.integrator.simulates_light()).then(|| AlphaTest::new(scene));
    // The primary integrator's camera rays, all its work, are traced
    // together, a 4×4 block of pixels at a time, unless alpha masks need the
    // filtered query. Paths trace theirs one at a time, as their other rays:
    // there, packets took as many instructions per ray as single rays but
    // more time: without them the Cornell box, the bunny and the conference
    // room rendered in 0.90-0.96 of the time, every pair faster (1 thread,
    // alternating pairs), Sponza in 0.955 (0.945-1.002); the primary
    // integrator gains up to 17% from them (Sponza, 1.14-1.23).
    let batch = |rays: &[Ray], hits: &mut [Option<Hit>]| accel.intersect_batch(rays, hits);
    let packets = settings.integrator == Integrator::Primary && !alpha;
    let first_hits: Option<&FirstHits> = if packets { Some(&batch) } else { None };
    let pass = Pass { camera, settings, rows: rows.clone(), samples: samples.clone(), active, control, first_hits };
    let (sums, rays) = match settings.integrator {
        Integrator::Primary => render_samples(&pass, |start, rng, rays| {
            *rays += 1;
            let hit = match start.first_hit {
                Some(hit) => hit,
                None => shade::closest_hit(accel, &start.ray, cut_outs.as_ref().map(|test| (test, rng.next_f32()))),
            };
            match hit {
                Some(hit) => shade_primary(scene, &start.ray, &hit, textures),
                None => settings.background,
            }
        }),
        Integrator::Direct | Integrator::Path => render_transport(scene, accel, &plan, &pass),
        aov => render_samples(&pass, |start, rng, rays| {
            *rays += 1;
            shade::aov(aov, scene, accel, (cut_outs.as_ref(), textures), &start.ray, rng)
        }),
    }
    .ok_or(Cancelled)?;
    let stats = RenderStats {
        width: settings.width,
        height: rows.end - rows.start,
        samples_per_pixel: samples.end - samples.start,
        rays,
        render_ms: start.elapsed().as_secs_f64() * 1e3,
    };
    Ok((sums, stats))
}

/// What one pass renders: which rows and samples, with which camera and
/// settings, and how camera rays are traced.
#[derive(Clone)]
struct Pass<'a> {
    camera: &'a Camera,
    settings: &'a RenderSettings,
    rows: Range<u32>,
    samples: Range<u32>,
    /// With `Some`, only the pixels it marks are rendered (by `y · width + x`).
    active: Option<&'a [bool]>,
    control: &'a PassControl<'a>,
    /// With `Some`, camera rays are traced in blocks through it.
    first_hits: Option<&'a FirstHits<'a>>,
}

/// Light transport, specialised to the plan's effects: one compiled
/// version of the path loop per subset of [`SPECIALISED`].
fn render_transport<A: Accel + ?Sized>(
    scene: &Scene,
    accel: &A,
    plan: &EffectPlan,
    pass: &Pass<'_>,
) -> Option<(Vec<PixelSum>, u64)> {
    let sky = plan.default_environment.then(|| default_sky(pass.settings.up));
    let environment = sky.as_deref().or(pass.settings.environment.as_ref());
    let transport = Transport::new(scene, accel, plan, environment, pass.settings);
    fn run<const S: u16, A: Accel + ?Sized>(
        transport: &Transport<'_, A>,
        pass: &Pass<'_>,
    ) -> Option<(Vec<PixelSum>, u64)> {
        render_samples(pass, |start, rng, rays| transport.radiance::<S>(start, rng, rays))
    }
    // Decides the specialised effects one at a time, each both ways: the
    // leaves are the 2^n loops, one per subset, each compiled for its set's bits.
    macro_rules! specialised {
        (for $set:ident over [$($effect:expr),*]) => {{
            const _: () = assert!(
                EffectSet::of(&[$($effect),*]).bits() == SPECIALISED.bits(),
                "the loops must be dispatched over exactly the specialised effects"
            );
            specialised!($set; [] [$($effect),*])
        }};
        ($set:ident; [$($chosen:expr),*] []) => {
            run::<{ EffectSet::of(&[$($chosen),*]).bits() }, A>(&transport, pass)
        };
        ($set:ident; [$($chosen:expr),*] [$next:expr $(, $rest:expr)*]) => {
            if $set.contains($next) {
                specialised!($set; [$($chosen,)* $next] [$($rest),*])
            } else {
                specialised!($set; [$($chosen),*] [$($rest),*])
            }
        };
    }
    let specialisation = plan.specialisation();
    specialised!(for specialisation over [Effect::Alpha, Effect::Textures, Effect::Glossy, Effect::DirectLight, Effect::Emission])
}

/// Where a sample's path starts: its camera ray, the ray's closest hit if
/// it was traced with others of its block (`None` if not), and which sample
/// of its pixel it is, for the sampler's numbers of the first vertex.
pub(crate) struct PathStart<'a> {
    pub(crate) ray: Ray,
    pub(crate) first_hit: Option<Option<Hit>>,
    pub(crate) pattern: &'a PixelPattern,
    pub(crate) index: u32,
}

/// Closest hits of a batch of camera rays ([`Accel::intersect_batch`]).
type FirstHits<'a> = dyn Fn(&[Ray], &mut [Option<Hit>]) + Sync + 'a;

/// Sums, for each pixel of the pass's rows, the values of the pass's
/// samples `sample(camera ray, its closest hit, generator, ray counter)`,
/// in fixed point ([`accumulation`]). Each sample has its own generator,
/// seeded by (seed, pixel, sample index), and its position in the pixel
/// depends on its index and the render's total samples only, so a sample
/// has the same value in whatever pass or job it is taken. `None` if the
/// pass was cancelled.
///
/// With `first_hits`, the camera rays of each sample of a 4×4 block of
/// pixels are traced together through it and `sample` is handed the hit
/// (`Some`); without, `sample` traces its camera ray itself (`None`). The
/// hits are the same bits either way, and so is the image.
fn render_samples(
    pass: &Pass<'_>,
    sample: impl Fn(&PathStart, &mut Rng, &mut u64) -> Vec3 + Sync,
) -> Option<(Vec<PixelSum>, u64)> {
    let settings = pass.settings;
    let width = settings.width;
    let camera_rays = CameraRays::new(pass.camera, width, settings.height);
    let spp = settings.samples_per_pixel.max(1);
    let first_hits = pass.first_hits;
    render_blocks(width, pass.rows.clone(), pass.control, |pixels, values: &mut [PixelSum]| {
        let pixel_index = |(x, y): (u32, u32)| y as u64 * width as u64 + x as u64;
        // Under a mask, the block's pixels still going, and where their
        // sums go; without one (every other render), the block as it is.
        let chosen: Option<Vec<usize>> =
            pass.active.map(|active| (0..pixels.len()).filter(|&i| active[pixel_index(pixels[i]) as usize]).collect());
        let masked: Vec<(u32, u32)>;
        let pixels = match &chosen {
            None => pixels,
            Some(chosen) => {
                masked = chosen.iter().map(|&i| pixels[i]).collect();
                &masked[..]
            }
        };
        if pixels.is_empty() {
            return Some(0);
        }
        // One more generator per pixel, past every sample's: its shift of the pixel's pattern.
        let patterns: Vec<PixelPattern> = pixels
            .iter()
            .map(|&pixel| {
                let mut shift = Rng::for_sample(settings.seed, pixel_index(pixel), u64::MAX);
                settings.sampler.pattern(spp, Vec2::new(shift.next_f32(), shift.next_f32()))
            })
            .collect();
        let mut traced = 0;
        let mut generators = Vec::with_capacity(pixels.len());
        let mut rays = Vec::with_capacity(pixels.len());
        let mut hits = vec![None; pixels.len()];
        for index in pass.samples.clone() {
            if (pass.control.cancelled)() {
                return None;
            }
            generators.clear();
            rays.clear();
            for (&(x, y), pattern) in pixels.iter().zip(&patterns) {
                let mut rng = Rng::for_sample(settings.seed, pixel_index((x, y)), index as u64);
                rays.push(camera_rays.ray(x, y, pattern.offset(index, &mut rng)));
                generators.push(rng);
            }
            if let Some(first_hits) = first_hits {
                first_hits(&rays, &mut hits);
            }
            for (i, (ray, rng)) in rays.iter().zip(&mut generators).enumerate() {
                let start =
                    PathStart { ray: *ray, first_hit: first_hits.map(|_| hits[i]), pattern: &patterns[i], index };
                let value = sample(&start, rng, &mut traced);
                let slot = chosen.as_ref().map_or(i, |chosen| chosen[i]);
                accumulation::add(&mut values[slot], &to_fixed(value));
            }
        }
        (pass.control.progress)(pixels.len() as u64 * pass.samples.len() as u64);
        Some(traced)
    })
}

/// Renders what tracing costs: per pixel, the boxes tested (red channel)
/// and ray/triangle tests (green channel) of the ray through the pixel's
/// centre, and 1 in blue where it hit something. Parallel and
/// deterministic like [`render`]; also returns the totals.
pub fn render_traversal_cost(
    accel: &dyn Accel,
    camera: &Camera,
    width: u32,
    height: u32,
    progress: &(dyn Fn(u64) + Sync),
) -> (HdrImage, TraversalCounters) {
    let rays = CameraRays::new(camera, width, height);
    let control = PassControl { progress, cancelled: &|| false };
    let (values, _) = render_blocks(width, 0..height, &control, |pixels, values: &mut [Vec3]| {
        for (&(x, y), value) in pixels.iter().zip(values) {
            let mut counters = TraversalCounters::default();
            let hit = accel.intersect_counted(&rays.ray(x, y, Vec2::splat(0.5)), &mut counters);
            *value =
                Vec3::new(counters.nodes_visited as f32, counters.triangles_tested as f32, hit.is_some() as u32 as f32);
        }
        progress(pixels.len() as u64);
        Some(0)
    })
    .expect("never cancelled");
    let image = HdrImage::from_pixels(width, height, values).expect("one value per pixel");
    let mut total = TraversalCounters { rays: width as u64 * height as u64, ..TraversalCounters::default() };
    for p in image.pixels() {
        total.nodes_visited += p.x as u64;
        total.triangles_tested += p.y as u64;
    }
    (image, total)
}

/// Computes the values of every pixel of rows `rows`, tile by tile in
/// parallel: each tile is cut into blocks of up to
/// [`rays::TILE`]×[`rays::TILE`] pixels, and `block(pixels, values)` fills
/// in the values of its pixels (which start as `T::default()`) and returns
/// the rays traced, or `None` when `control` cancelled it. The value of a
/// pixel depends only on its coordinates, so the result is the same for
/// any number of threads. Returns the values row by row and the total of
/// the rays, or `None` if cancelled.
fn render_blocks<T: Clone + Default + Send>(
    width: u32,
    rows: Range<u32>,
    control: &PassControl<'_>,
    block: impl Fn(&[(u32, u32)], &mut [T]) -> Option<u64> + Sync,
) -> Option<(Vec<T>, u64)> {
    // Per tile: its pixels, their values, and the rays traced.
    type Tile<T> = (Vec<(u32, u32)>, Vec<T>, u64);
    let step = rays::TILE as usize;
    let tile_values: Vec<Tile<T>> = tiles(width, rows.clone())
        .into_par_iter()
        .map(|(x0, y0, x1, y1)| {
            if (control.cancelled)() {
                return None;
            }
            let (mut pixels, mut values, mut traced) = (Vec::new(), Vec::new(), 0);
            for by in (y0..y1).step_by(step) {
                for bx in (x0..x1).step_by(step) {
                    let start = pixels.len();
                    pixels.extend(
                        (by..(by + rays::TILE).min(y1))
                            .flat_map(|y| (bx..(bx + rays::TILE).min(x1)).map(move |x| (x, y))),
                    );
                    values.resize(pixels.len(), T::default());
                    traced += block(&pixels[start..], &mut values[start..])?;
                }
            }
            Some((pixels, values, traced))
        })
        .collect::<Option<_>>()?;
    let mut all = vec![T::default(); (rows.end - rows.start) as usize * width as usize];
    let mut rays = 0;
    for (pixels, values, traced) in tile_values {
        rays += traced;
        for ((x, y), value) in pixels.into_iter().zip(values) {
            all[(y - rows.start) as usize * width as usize + x as usize] = value;
        }
    }
    Some((all, rays))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_the_image_once() {
        let mut covered = vec![0u8; 37 * 21];
        for (x0, y0, x1, y1) in tiles(37, 0..21) {
            for y in y0..y1 {
                for x in x0..x1 {
                    covered[(y * 37 + x) as usize] += 1;
                }
            }
        }
        assert!(covered.iter().all(|&c| c == 1));
    }
}
