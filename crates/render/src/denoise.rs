//! An edge-avoiding denoiser for previews: the render's noise smoothed
//! across each surface but not across its edges, guided by what the camera
//! sees first at each pixel (its albedo, shading normal and distance).
//!
//! The filter is the edge-avoiding à-trous wavelet transform (Dammertz et
//! al., "Edge-Avoiding À-Trous Wavelet Transform for fast Global
//! Illumination Filtering", HPG 2010) with the edge-stopping weights of
//! spatiotemporal variance-guided filtering (Schied et al., HPG 2017),
//! without its temporal part:
//!
//! 1. **Demodulation.** The image is divided by the albedo guide, so that
//!    what is filtered is the light arriving (smooth across a texture's
//!    pattern), and the texture is multiplied back at the end, sharp.
//! 2. **Isolated fireflies.** From [`FIREFLY_FROM_SAMPLES`] samples per
//!    pixel on, a pixel more than [`DenoiseSettings::firefly`]
//!    times as bright as the brightest of its eight neighbours is brought
//!    down to that: one rare path that found a bright light through a
//!    narrow gap would otherwise be spread into a blot. Emitters seen
//!    directly are not fireflies, however small: they and the pixels
//!    bordering them are left as rendered.
//! 3. **Passes.** Each pass averages a 5 × 5 B3-spline kernel whose taps
//!    are `2^pass` pixels apart, so five passes reach 125 pixels across
//!    for the cost of 125 taps a pixel. A tap counts as much as its
//!    normal, albedo, distance and emission agree with the pixel's, and as its
//!    brightness agrees within a few standard deviations of the pixel's
//!    noise (estimated over its 3 × 3 neighbourhood, and filtered along
//!    with the image).
//!
//! The filter biases the image (it trades noise for blur, and step 2
//! removes energy); the `denoise` experiment measures what it gains at
//! equal time. It is for images people look at: `rtgi render` applies it
//! to PNG output by default and never to EXR or accumulations, which keep
//! the unbiased estimate.

use rayon::prelude::*;
use rtgi_accel::Accel;
use rtgi_image::HdrImage;
use rtgi_math::{Rng, Vec2, Vec3, luminance};
use rtgi_scene::{Camera, Scene};

use crate::alpha::AlphaTest;
use crate::effects::{Effect, EffectPlan};
use crate::shade::{albedo, closest_hit, emission, shading_normal};
use crate::{Accumulation, CameraRays, PassControl, RenderIdentity, RenderSettings, render_pass};

/// Samples per pixel of the guides: enough to anti-alias edges the way the
/// render does, a small fraction of a path-traced render's cost.
pub const GUIDE_SAMPLES: u32 = 4;

/// Albedo below this (per channel) is not divided out: black and nearly
/// black surfaces keep their light as it is.
const ALBEDO_FLOOR: f32 = 0.02;

/// The B3-spline kernel of the à-trous passes, one axis.
const KERNEL: [f32; 5] = [1.0 / 16.0, 1.0 / 4.0, 3.0 / 8.0, 1.0 / 4.0, 1.0 / 16.0];

/// How strongly the filter holds to edges.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DenoiseSettings {
    /// À-trous passes: the filter reaches `4 · (2^passes − 1) + 1` pixels across.
    pub passes: u32,
    /// Brightness differences count in multiples of this many standard
    /// deviations of the pixel's noise (larger blurs more).
    pub luminance: f32,
    /// The normals' agreement is `max(0, n · n')` to this power.
    pub normal: i32,
    /// Albedo differences count relative to this (per channel).
    pub albedo: f32,
    /// Distance differences count relative to this many times the change
    /// of distance expected from the surface's slope across the gap.
    pub depth: f32,
    /// A pixel brighter than this many times its brightest neighbour is
    /// brought down to it (`f32::INFINITY` keeps fireflies).
    pub firefly: f32,
}

impl Default for DenoiseSettings {
    fn default() -> Self {
        Self { passes: 5, luminance: 4.0, normal: 64, albedo: 0.25, depth: 2.0, firefly: 2.0 }
    }
}

/// Fewer samples per pixel than this, and fireflies are kept: a mean of a
/// handful of samples is often far brighter than its neighbours without
/// being an outlier of its own samples, and taking those pixels down
/// darkened Sponza by 32% at 1 spp and 8.5% at 4 (`rtgi experiment denoise`),
/// against 1.6% at 16. Below it the brightness tolerance also widens (as
/// the square root of the missing samples): the noise estimate of so few
/// samples is itself so noisy that bright pixels were kept apart from
/// their neighbours, and the filter lost their light (Sponza 20% darker at
/// 1 spp, 9% with the tolerance widened).
pub const FIREFLY_FROM_SAMPLES: u32 = 16;

impl DenoiseSettings {
    /// The settings `rtgi render` uses for an image of `samples_per_pixel`
    /// samples: the defaults; below [`FIREFLY_FROM_SAMPLES`], fireflies kept
    /// and the brightness tolerance widened by `sqrt(16 / spp)`.
    pub fn for_samples(samples_per_pixel: u32) -> Self {
        let defaults = Self::default();
        if samples_per_pixel >= FIREFLY_FROM_SAMPLES {
            return defaults;
        }
        let few = (FIREFLY_FROM_SAMPLES as f32 / samples_per_pixel.max(1) as f32).sqrt();
        Self { firefly: f32::INFINITY, luminance: defaults.luminance * few, ..defaults }
    }
}

/// What the camera sees first at each pixel, which the filter keeps edges
/// of: the mean albedo, shading normal, distance and emission over
/// [`GUIDE_SAMPLES`] samples; zero where the camera sees nothing.
#[derive(Clone, Debug, PartialEq)]
pub struct Guides {
    /// The surface colour (texture included).
    pub albedo: HdrImage,
    /// The shading normal (not renormalised after averaging).
    pub normal: HdrImage,
    /// The distance from the camera, in every channel.
    pub depth: HdrImage,
    /// The light the surface emits: lamps are kept apart from the walls
    /// around them, and a lamp one pixel wide is not a firefly.
    pub emission: HdrImage,
}

impl Guides {
    /// Renders the guides of the view that `settings` (size, seed, effects)
    /// and `camera` render: [`GUIDE_SAMPLES`] camera rays a pixel, spread
    /// over it in a 2 × 2 grid, each giving all four guides at once.
    pub fn render(scene: &Scene, accel: &dyn Accel, camera: &Camera, settings: &RenderSettings) -> Guides {
        let plan = EffectPlan::new(scene, settings);
        let (alpha, textures) = (plan.has(Effect::Alpha), plan.has(Effect::Textures));
        let cut_outs = alpha.then(|| AlphaTest::new(scene));
        let (width, height) = (settings.width, settings.height);
        let rays = CameraRays::new(camera, width, height);
        let pixels: Vec<[Vec3; 4]> = (0..width as u64 * height as u64)
            .into_par_iter()
            .map(|pixel| {
                let (x, y) = ((pixel % width as u64) as u32, (pixel / width as u64) as u32);
                // Past the render's own generators: the guides draw only alpha's numbers.
                let mut rng = Rng::for_sample(settings.seed, pixel, u64::MAX - 1);
                let mut sums = [Vec3::ZERO; 4];
                for sample in 0..GUIDE_SAMPLES {
                    let offset = Vec2::new((sample % 2) as f32 * 0.5 + 0.25, (sample / 2 % 2) as f32 * 0.5 + 0.25);
                    let ray = rays.ray(x, y, offset);
                    let cut_outs = cut_outs.as_ref().map(|test| (test, rng.next_f32()));
                    let Some(hit) = closest_hit(accel, &ray, cut_outs) else { continue };
                    sums[0] += albedo(scene, &hit, textures);
                    sums[1] += shading_normal(scene, &hit);
                    sums[2] += Vec3::splat(hit.t * ray.direction.length());
                    sums[3] += emission(scene, &hit, textures);
                }
                sums.map(|sum| sum / GUIDE_SAMPLES as f32)
            })
            .collect();
        let guide =
            |k: usize| HdrImage::from_pixels(width, height, pixels.iter().map(|p| p[k]).collect()).expect("sized");
        Guides { albedo: guide(0), normal: guide(1), depth: guide(2), emission: guide(3) }
    }
}

/// Renders `settings` and denoises the image as `rtgi render` does for
/// PNG output: the samples in two halves (the image is the same, bit for
/// bit, as [`crate::render`]'s), the guides, then the filter. Returns the
/// denoised image and the samples' mean.
pub fn render_denoised(
    scene: &Scene,
    accel: &dyn Accel,
    camera: &Camera,
    settings: &RenderSettings,
    denoise_settings: &DenoiseSettings,
) -> (HdrImage, HdrImage) {
    let settings = RenderSettings { adaptive: None, ..settings.clone() };
    let spp = settings.samples_per_pixel.max(1);
    let identity = RenderIdentity::new(scene, camera, &settings);
    let mut accumulation = Accumulation::new(identity, 0..settings.height, 0);
    let control = PassControl { progress: &|_| {}, cancelled: &|| false };
    let pass = |accumulation: &mut Accumulation, count: u32| {
        render_pass(scene, accel, camera, &settings, accumulation, count, &control)
            .expect("a render that cannot be cancelled finishes");
    };
    let half = if spp >= 2 {
        pass(&mut accumulation, spp / 2);
        let half = accumulation.image();
        pass(&mut accumulation, spp - spp / 2);
        Some(half)
    } else {
        pass(&mut accumulation, spp);
        None
    };
    let image = accumulation.image();
    let guides = Guides::render(scene, accel, camera, &settings);
    let clean = denoise(&image, half.as_ref(), &guides, denoise_settings).expect("the guides are of the image's size");
    (clean, image)
}

/// Why an image cannot be denoised.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum DenoiseError {
    /// The guides (or the half image) are of another size than the image.
    #[error("the guides are {guides} but the image is {image}")]
    Size {
        /// The image's width × height.
        image: String,
        /// The guides' width × height.
        guides: String,
    },
}

/// One pixel's guides, gathered for the filter.
#[derive(Clone, Copy)]
struct Texel {
    albedo: Vec3,
    /// Unit normal, or zero where the camera sees nothing.
    normal: Vec3,
    /// The length of the mean of the guide rays' normals: 1 where they saw
    /// one surface, less where they saw several (a crease, a silhouette),
    /// whose normals then lie about acos(spread) from `normal`.
    spread: f32,
    depth: f32,
    /// The largest change of distance to a neighbouring pixel.
    slope: f32,
    /// The brightest channel of the emitted light.
    emission: f32,
    /// Whether the pixel shows an emitter or borders one: left as
    /// rendered, and no tap of others. A lamp's bright edge pixels are
    /// covered by the lamp in a fraction the four guide samples cannot
    /// tell, and smoothing them would spread the lamp into the wall.
    fixed: bool,
}

/// `image` filtered by the edge-avoiding à-trous transform (see the
/// module's documentation), its edges kept where the guides have edges.
/// `half`, the mean of the first half of the same samples (the first
/// `spp / 2` of each pixel), tells the filter each pixel's noise, so that
/// it smooths as much as the noise asks and less as samples grow; without
/// it, the noise is estimated from each pixel's neighbourhood.
///
/// ```
/// use rtgi_image::HdrImage;
/// use rtgi_math::Vec3;
/// use rtgi_render::{DenoiseSettings, Guides, denoise};
///
/// let flat = |value: Vec3| HdrImage::from_pixels(8, 8, vec![value; 64]).unwrap();
/// let guides = Guides {
///     albedo: flat(Vec3::splat(0.5)),
///     normal: flat(Vec3::Z),
///     depth: flat(Vec3::ONE),
///     emission: flat(Vec3::ZERO),
/// };
/// let mut noisy = flat(Vec3::splat(0.25));
/// noisy.set(3, 4, Vec3::splat(0.35));
/// noisy.set(4, 4, Vec3::splat(0.15));
/// let clean = denoise(&noisy, None, &guides, &DenoiseSettings::default())?;
/// assert!((clean.get(3, 4).x - 0.25).abs() < 0.05);
/// # Ok::<(), rtgi_render::DenoiseError>(())
/// ```
pub fn denoise(
    image: &HdrImage,
    half: Option<&HdrImage>,
    guides: &Guides,
    settings: &DenoiseSettings,
) -> Result<HdrImage, DenoiseError> {
    let (width, height) = (image.width(), image.height());
    for guide in [&guides.albedo, &guides.normal, &guides.depth, &guides.emission].into_iter().chain(half) {
        if (guide.width(), guide.height()) != (width, height) {
            return Err(DenoiseError::Size {
                image: format!("{width}×{height}"),
                guides: format!("{}×{}", guide.width(), guide.height()),
            });
        }
    }
    let (w, h) = (width as usize, height as usize);
    if w == 0 || h == 0 {
        return Ok(image.clone());
    }
    let depth_at = |x: usize, y: usize| guides.depth.pixels()[y * w + x].x;
    let mut texels: Vec<Texel> = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let depth = depth_at(x, y);
            let mut slope = 0f32;
            for (dx, dy) in [(-1i64, 0i64), (1, 0), (0, -1), (0, 1)] {
                let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                if nx >= 0 && ny >= 0 && (nx as usize) < w && (ny as usize) < h {
                    let other = depth_at(nx as usize, ny as usize);
                    if other > 0.0 {
                        slope = slope.max((other - depth).abs());
                    }
                }
            }
            Texel {
                albedo: guides.albedo.pixels()[i],
                normal: guides.normal.pixels()[i].try_normalize().unwrap_or(Vec3::ZERO),
                spread: guides.normal.pixels()[i].length().clamp(f32::MIN_POSITIVE, 1.0),
                depth,
                slope,
                emission: guides.emission.pixels()[i].max_element(),
                fixed: false,
            }
        })
        .collect();
    let emits: Vec<bool> = texels.iter().map(|t| t.emission > 0.0).collect();
    for (i, texel) in texels.iter_mut().enumerate() {
        texel.fixed = neighbours(i % w, i / w, w, h, 1).any(|j| emits[j]);
    }
    // 1. Demodulated: the light arriving, without the texture.
    let modulation: Vec<Vec3> = texels
        .iter()
        .map(|t| if t.normal == Vec3::ZERO { Vec3::ONE } else { t.albedo.max(Vec3::splat(ALBEDO_FLOOR)) })
        .collect();
    let mut light: Vec<Vec3> = image.pixels().iter().zip(&modulation).map(|(c, m)| sanitised(*c) / *m).collect();
    // 2. Isolated fireflies brought down to their neighbourhood.
    if settings.firefly.is_finite() {
        let brightness: Vec<f32> = light.iter().map(|c| luminance(*c)).collect();
        light = (0..w * h)
            .into_par_iter()
            .map(|i| {
                let (x, y) = (i % w, i / w);
                let brightest =
                    neighbours(x, y, w, h, 1).filter(|&j| j != i).map(|j| brightness[j]).fold(0f32, f32::max);
                let limit = settings.firefly * brightest;
                let firefly = brightness[i] > limit && brightness[i] > 0.0 && !texels[i].fixed;
                if firefly { light[i] * (limit / brightness[i]) } else { light[i] }
            })
            .collect();
    }
    // 3. The noise of each pixel's brightness: from the difference between
    // the first half of its samples and all of them when that is known,
    // else from its neighbourhood's spread (which counts the image's own
    // detail as noise too, and so blurs more).
    let brightness: Vec<f32> = light.iter().map(|c| luminance(*c)).collect();
    let mut variance: Vec<f32> = match half {
        Some(half) => {
            // The mean of all samples is the average of two independent
            // halves A and B, so its variance is about (A − B)² / 4 = (A − mean)².
            // One pixel's (A − mean)² is itself noisy: averaged over its neighbourhood.
            let single: Vec<f32> = (0..w * h)
                .map(|i| {
                    luminance((sanitised(half.pixels()[i]) - sanitised(image.pixels()[i])) / modulation[i]).powi(2)
                })
                .collect();
            neighbourhood_mean(&single, w, h)
        }
        None => {
            let squares: Vec<f32> = brightness.iter().map(|b| b * b).collect();
            let (mean, mean_square) = (neighbourhood_mean(&brightness, w, h), neighbourhood_mean(&squares, w, h));
            mean.iter().zip(&mean_square).map(|(m, m2)| (m2 - m * m).max(0.0)).collect()
        }
    };
    for pass in 0..settings.passes {
        let step = 1usize << pass;
        let brightness: Vec<f32> = light.iter().map(|c| luminance(*c)).collect();
        let filtered: Vec<(Vec3, f32)> = (0..w * h)
            .into_par_iter()
            .map(|i| {
                let (x, y) = (i % w, i / w);
                let centre = &texels[i];
                if centre.fixed {
                    return (light[i], variance[i]);
                }
                let deviation = settings.luminance * variance[i].sqrt() + 1e-6;
                let (mut sum, mut weights, mut variances) = (Vec3::ZERO, 0f32, 0f32);
                for (ky, &kernel_y) in KERNEL.iter().enumerate() {
                    let sy = y as i64 + (ky as i64 - 2) * step as i64;
                    if sy < 0 || sy >= h as i64 {
                        continue;
                    }
                    for (kx, &kernel_x) in KERNEL.iter().enumerate() {
                        let sx = x as i64 + (kx as i64 - 2) * step as i64;
                        if sx < 0 || sx >= w as i64 {
                            continue;
                        }
                        let j = sy as usize * w + sx as usize;
                        let gap = (((kx as f32 - 2.0).powi(2) + (ky as f32 - 2.0).powi(2)).sqrt()) * step as f32;
                        let weight = kernel_x
                            * kernel_y
                            * agreement(centre, &texels[j], gap, settings)
                            * (-(brightness[i] - brightness[j]).abs() / deviation).exp();
                        sum += light[j] * weight;
                        weights += weight;
                        variances += weight * weight * variance[j];
                    }
                }
                // The centre tap always has weight, so the sum is never empty.
                (sum / weights, variances / (weights * weights))
            })
            .collect();
        for (i, (value, noise)) in filtered.into_iter().enumerate() {
            light[i] = value;
            variance[i] = noise;
        }
    }
    let pixels = light.iter().zip(&modulation).map(|(l, m)| *l * *m).collect();
    Ok(HdrImage::from_pixels(width, height, pixels).expect("one pixel each"))
}

/// How far two pixels' guides agree that they show the same surface, in
/// [0, 1]: their normals, albedos and distances, the distances allowed to
/// differ as much as the surface's slope over the `gap` between them.
#[inline]
fn agreement(a: &Texel, b: &Texel, gap: f32, settings: &DenoiseSettings) -> f32 {
    if b.fixed {
        return 0.0;
    }
    match (a.normal == Vec3::ZERO, b.normal == Vec3::ZERO) {
        // Both see nothing (the background): one surface.
        (true, true) => return 1.0,
        (false, false) => {}
        _ => return 0.0,
    }
    // Emitters differing by more than a tenth are different lamps, or a lamp and a wall.
    if (a.emission - b.emission).abs() > 0.1 * a.emission.max(b.emission) {
        return 0.0;
    }
    // A pixel that saw several surfaces (a crease) agrees in full with the
    // normals within its spread: taken as one surface, it would agree with
    // none, keep its noise and show the crease as a dotted line.
    let normal = (a.normal.dot(b.normal) / a.spread).clamp(0.0, 1.0).powi(settings.normal);
    let albedo_difference = (a.albedo - b.albedo).abs().max_element() / settings.albedo;
    let depth_tolerance = settings.depth * a.slope * gap + 1e-3 * a.depth.abs();
    let depth_difference = (a.depth - b.depth).abs() / depth_tolerance.max(f32::MIN_POSITIVE);
    normal * (-(albedo_difference * albedo_difference) - depth_difference).exp()
}

/// Each pixel's mean of `values` over its 3 × 3 neighbourhood (fewer at the image's edges).
fn neighbourhood_mean(values: &[f32], w: usize, h: usize) -> Vec<f32> {
    (0..w * h)
        .into_par_iter()
        .map(|i| {
            let (sum, n) =
                neighbours(i % w, i / w, w, h, 1).fold((0f32, 0f32), |(sum, n), j| (sum + values[j], n + 1.0));
            sum / n
        })
        .collect()
}

/// The indices of the pixels within `radius` of (x, y), the pixel's own included.
fn neighbours(x: usize, y: usize, w: usize, h: usize, radius: usize) -> impl Iterator<Item = usize> {
    let (x0, x1) = (x.saturating_sub(radius), (x + radius).min(w - 1));
    let (y0, y1) = (y.saturating_sub(radius), (y + radius).min(h - 1));
    (y0..=y1).flat_map(move |j| (x0..=x1).map(move |i| j * w + i))
}

/// Infinite and NaN samples (which the accumulation already counts as
/// black) as black, so that no one pixel poisons its neighbourhood.
fn sanitised(value: Vec3) -> Vec3 {
    if value.is_finite() { value } else { Vec3::ZERO }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rtgi_math::Rng;

    const SIDE: u32 = 48;

    fn image(value: impl Fn(u32, u32) -> Vec3) -> HdrImage {
        let pixels = (0..SIDE * SIDE).map(|i| value(i % SIDE, i / SIDE)).collect();
        HdrImage::from_pixels(SIDE, SIDE, pixels).unwrap()
    }

    /// Noise of relative size `amount` (uniform, mean 1) on each pixel of `clean`.
    fn noisy(clean: &HdrImage, amount: f32, seed: u64) -> HdrImage {
        let mut rng = Rng::new(seed, 0);
        let pixels = clean.pixels().iter().map(|&p| p * (1.0 + amount * (2.0 * rng.next_f32() - 1.0))).collect();
        HdrImage::from_pixels(SIDE, SIDE, pixels).unwrap()
    }

    fn rmse(a: &HdrImage, b: &HdrImage) -> f32 {
        let sum: f32 = a.pixels().iter().zip(b.pixels()).map(|(p, q)| (*p - *q).length_squared()).sum();
        (sum / a.pixels().len() as f32).sqrt()
    }

    /// A wall whose left half faces the camera and right half faces up,
    /// lit differently, one albedo: the filter must not mix the halves.
    fn folded_wall() -> (HdrImage, Guides) {
        let left = |x: u32| x < SIDE / 2;
        let clean = image(|x, _| if left(x) { Vec3::splat(0.3) } else { Vec3::splat(0.9) });
        let guides = Guides {
            albedo: image(|_, _| Vec3::splat(0.6)),
            normal: image(|x, _| if left(x) { Vec3::Z } else { Vec3::Y }),
            depth: image(|_, _| Vec3::splat(5.0)),
            emission: image(|_, _| Vec3::ZERO),
        };
        (clean, guides)
    }

    #[test]
    fn noise_on_a_surface_is_smoothed_and_the_fold_between_two_surfaces_stays_sharp() {
        let (clean, guides) = folded_wall();
        let input = noisy(&clean, 0.5, 1);
        let output = denoise(&input, None, &guides, &DenoiseSettings::default()).unwrap();
        let (before, after) = (rmse(&input, &clean), rmse(&output, &clean));
        assert!(after < 0.25 * before, "RMSE {before} before, {after} after");
        // The columns either side of the fold keep their own side's light.
        for y in 0..SIDE {
            let (l, r) = (output.get(SIDE / 2 - 1, y).x, output.get(SIDE / 2, y).x);
            assert!((l - 0.3).abs() < 0.06 && (r - 0.9).abs() < 0.12, "row {y}: {l} | {r}");
        }
        // Without the normals' say, the fold blurs: the test can fail.
        let blind = DenoiseSettings { normal: 0, luminance: 1e6, ..DenoiseSettings::default() };
        let blurred = denoise(&input, None, &guides, &blind).unwrap();
        assert!((blurred.get(SIDE / 2 - 1, SIDE / 2).x - 0.3).abs() > 0.06);
    }

    #[test]
    fn the_pixels_on_a_crease_are_smoothed_with_both_sides() {
        // The fold's middle column saw both halves, in shares that change
        // from row to row as a slanted crease crosses pixels (a quarter, a
        // half, three quarters of the guide rays): its guide normal is the
        // unnormalised mean, its light the same mixture. No two neighbours
        // on the column saw the same mixture.
        let (clean, mut guides) = folded_wall();
        let crease = SIDE / 2;
        let mut clean = clean;
        let share = |y: u32| [0.25f32, 0.5, 0.75][y as usize % 3];
        for y in 0..SIDE {
            guides.normal.set(crease, y, Vec3::Z * share(y) + Vec3::Y * (1.0 - share(y)));
            clean.set(crease, y, Vec3::splat(0.3 * share(y) + 0.9 * (1.0 - share(y))));
        }
        let input = noisy(&clean, 0.5, 2);
        let output = denoise(&input, None, &guides, &DenoiseSettings::default()).unwrap();
        let column_error = |image: &HdrImage| {
            let sum: f32 = (0..SIDE).map(|y| (image.get(crease, y).x - clean.get(crease, y).x).powi(2)).sum();
            (sum / SIDE as f32).sqrt()
        };
        let (before, after) = (column_error(&input), column_error(&output));
        // Without the spread, 0.85 times (measured): the mixed pixels keep their noise.
        assert!(after < 0.75 * before, "the crease's RMSE {before} before, {after} after");
    }

    #[test]
    fn a_texture_under_even_light_comes_out_sharp() {
        // A checkerboard albedo under light that is even but noisy: the
        // light is filtered, the texture multiplied back unblurred.
        let albedo = image(|x, y| if (x / 3 + y / 3) % 2 == 0 { Vec3::splat(0.8) } else { Vec3::new(0.1, 0.2, 0.05) });
        let clean = image(|x, y| albedo.get(x, y) * 2.0);
        let guides = Guides {
            albedo,
            normal: image(|_, _| Vec3::Z),
            depth: image(|_, _| Vec3::ONE),
            emission: image(|_, _| Vec3::ZERO),
        };
        let input = noisy(&clean, 0.4, 2);
        let output = denoise(&input, None, &guides, &DenoiseSettings::default()).unwrap();
        let worst = output.pixels().iter().zip(clean.pixels()).map(|(o, c)| ((*o - *c) / *c).abs().max_element());
        let worst = worst.fold(0f32, f32::max);
        assert!(worst < 0.15, "a texel is off by {worst} of its value");
    }

    #[test]
    fn an_isolated_firefly_is_brought_down_and_the_background_is_not_mixed_with_surfaces() {
        let (clean, mut guides) = folded_wall();
        // The top rows see nothing: background of another brightness.
        for y in 0..8 {
            for x in 0..SIDE {
                guides.normal.set(x, y, Vec3::ZERO);
                guides.albedo.set(x, y, Vec3::ZERO);
                guides.depth.set(x, y, Vec3::ZERO);
            }
        }
        let mut input = clean.clone();
        for x in 0..SIDE {
            for y in 0..8 {
                input.set(x, y, Vec3::new(0.05, 0.05, 0.06));
            }
        }
        let calm = input.clone();
        input.set(10, 30, Vec3::splat(500.0));
        let output = denoise(&input, None, &guides, &DenoiseSettings::default()).unwrap();
        let total = |image: &HdrImage| image.pixels().iter().map(|p| p.x).sum::<f32>();
        let spread = total(&output) - total(&calm);
        assert!(output.get(10, 30).x < 1.0, "the firefly stayed at {}", output.get(10, 30).x);
        assert!(spread.abs() < 10.0, "the firefly's energy spread: {spread}");
        for x in 0..SIDE {
            assert!((output.get(x, 7).x - 0.05).abs() < 1e-4, "the background took light from the wall at {x}");
            assert!(output.get(x, 8).x >= 0.29, "the wall took the background's darkness at {x}");
        }
        // Kept, it spreads into its neighbours.
        let kept =
            denoise(&input, None, &guides, &DenoiseSettings { firefly: f32::INFINITY, ..Default::default() }).unwrap();
        let around = |image: &HdrImage| (8..13).map(|x| image.get(x, 30).x).sum::<f32>() - image.get(10, 30).x;
        assert!(around(&output) < around(&calm) + 0.01);
        assert!(around(&kept) > around(&calm) + 0.2);
    }

    #[test]
    fn light_that_is_detail_rather_than_noise_is_kept_when_the_half_image_says_so() {
        // Stripes of shadow on one flat wall, rendered without noise: the
        // first half of the samples agrees with all of them, so the filter
        // knows there is no noise to take out and keeps the stripes. From
        // the neighbourhood alone, stripes look like noise and are blurred.
        let (_, guides) = folded_wall();
        let guides = Guides { normal: image(|_, _| Vec3::Z), ..guides };
        let striped = image(|x, _| Vec3::splat(if x % 4 < 2 { 0.2 } else { 0.6 }));
        let informed = denoise(&striped, Some(&striped), &guides, &DenoiseSettings::default()).unwrap();
        let guessing = denoise(&striped, None, &guides, &DenoiseSettings::default()).unwrap();
        assert!(rmse(&informed, &striped) < 0.01, "{}", rmse(&informed, &striped));
        assert!(rmse(&guessing, &striped) > 0.05, "{}", rmse(&guessing, &striped));
        // And where the halves disagree by the noise there is, it is taken out.
        let clean = image(|_, _| Vec3::splat(0.4));
        let (first, second) = (noisy(&clean, 0.5, 3), noisy(&clean, 0.5, 4));
        let mean = HdrImage::from_pixels(
            SIDE,
            SIDE,
            first.pixels().iter().zip(second.pixels()).map(|(a, b)| (*a + *b) * 0.5).collect(),
        )
        .unwrap();
        let output = denoise(&mean, Some(&first), &guides, &DenoiseSettings::default()).unwrap();
        assert!(rmse(&output, &clean) < 0.25 * rmse(&mean, &clean));
    }

    #[test]
    fn guides_of_another_size_are_refused() {
        let (clean, guides) = folded_wall();
        let small = HdrImage::new(4, 4);
        let wrong = Guides { albedo: small.clone(), ..guides };
        assert_eq!(
            denoise(&clean, None, &wrong, &DenoiseSettings::default()),
            Err(DenoiseError::Size { image: "48×48".into(), guides: "4×4".into() })
        );
    }
}
