//! Adaptive sampling: samples go where the image is still noisy.
//!
//! The render proceeds in rounds that double every pixel's samples (8,
//! 16, 32, … up to the render's samples per pixel). Each round's samples
//! are as many as all before it, so after each round a pixel has two
//! halves of its samples, A (the earlier rounds) and B (this round), whose
//! means differ by chance only: the squared error of their average is
//! about (A − B)² / 4. Unlike a variance estimated from single samples,
//! this sees what stratified and low-discrepancy samples gain (their
//! error falls faster than independent samples'), and what a firefly
//! costs. One pixel's (A − B)² is itself noisy, so it is averaged over the
//! pixel's 3 × 3 neighbourhood. The noise is that error's square root
//! relative to the pixel's mean luminance, or to a tenth of the image's
//! mean where the pixel is darker (near-black pixels, whose relative noise
//! no one sees, would otherwise take every sample). A pixel stops once
//! its noise is at or below the target, from 16 samples on.
//!
//! **Deterministic.** A sample's value depends on the seed, the pixel and
//! its index only, and which pixels go on depends on those values only; so
//! the same seed and settings give the same image, bit for bit, on any
//! number of threads. A time bound ([`AdaptiveSampling::seconds`]) cuts
//! the round predicted to overrun it to the samples that fit, and ends the
//! render there; the image is then the one the noise target alone gives
//! with the samples per pixel reached ([`AdaptiveOutcome::samples_reached`]).
//!
//! **Samplers.** Rounds take the first samples of the pixel's sequence, so
//! the sequence must be good at every power of two and must not depend on
//! its length: the Owen-scrambled Sobol sampler is (and so are the
//! uniform and centre samplers, trivially). The stratified and R2 samplers
//! lay their patterns out for the full count, and are refused
//! ([`AdaptiveError::Sampler`]).
//!
//! **Not split.** Whether a pixel goes on depends on all its samples so
//! far, so an adaptive render cannot be cut into sample ranges, bands of
//! rows or checkpoints and merged (`rtgi render` refuses the combination).

use std::time::Instant;

use rtgi_accel::Accel;
use rtgi_image::HdrImage;
use rtgi_math::luminance;
use rtgi_scene::{Camera, Scene};

use crate::accumulation::{PixelSum, add, mean};
use crate::{PassControl, PixelSampler, RenderSettings, render_sums_of};

/// The samples every pixel takes before any may stop, in two rounds of
/// half as many: fewer give noise estimates too rough to trust (a pixel
/// whose first samples missed the rare bright paths looks converged).
pub const FIRST_ROUND: u32 = 16;

/// Pixels darker than this fraction of the image's mean luminance have
/// their noise measured against that fraction of the mean instead of
/// their own value.
pub const DARK_FRACTION: f64 = 0.1;

/// When an adaptive render stops.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AdaptiveSampling {
    /// A pixel stops once the standard error of its mean luminance is at
    /// most this fraction of that mean (0.02: 2%).
    pub noise: Option<f32>,
    /// The render ends by this long after its start, as predicted from the
    /// rounds so far: the round that would overrun is cut to what fits.
    /// The first round always runs.
    pub seconds: Option<f64>,
}

/// Why an adaptive render cannot run as asked.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AdaptiveError {
    /// The sampler's first samples depend on the total count.
    #[error(
        "adaptive sampling takes the first 16, 32, 64, ... samples of each pixel, which the {0} sampler spreads \
         for the full count only: use the sobol sampler (the default with a noise target or time bound), \
         uniform or center"
    )]
    Sampler(PixelSampler),
    /// Neither a noise target nor a time bound.
    #[error("adaptive sampling needs a noise target, a time bound or both")]
    NoTarget,
    /// A noise target that is not a positive number.
    #[error("the noise target is a relative standard error above 0 (0.02 for 2%), not {0}")]
    Noise(f32),
    /// A time bound that is not a positive number of seconds.
    #[error("the time bound is a number of seconds above 0, not {0}")]
    Seconds(f64),
}

/// One round of an adaptive render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Round {
    /// Samples per pixel of the pixels still going, after this round.
    pub samples_per_pixel: u32,
    /// Pixels this round rendered.
    pub pixels: u64,
    /// Pixels at or below the noise target after it (all but `pixels` are).
    pub converged: u64,
    /// Rays the round traced.
    pub rays: u64,
    /// Its wall time.
    pub seconds: f64,
}

/// What an adaptive render did.
#[derive(Clone, Debug, PartialEq)]
pub struct AdaptiveOutcome {
    /// Every pixel's samples.
    pub samples: Vec<u32>,
    /// The rounds, in order.
    pub rounds: Vec<Round>,
    /// The most samples any pixel took: the noise target with this as the
    /// samples per pixel gives the same image.
    pub samples_reached: u32,
    /// Whether the time bound ended the render (rather than the noise
    /// target or the samples per pixel).
    pub stopped_by_time: bool,
}

impl AdaptiveOutcome {
    /// Samples taken, over all pixels.
    pub fn total_samples(&self) -> u64 {
        self.samples.iter().map(|&n| n as u64).sum()
    }

    /// Rays traced, over all rounds.
    pub fn rays(&self) -> u64 {
        self.rounds.iter().map(|r| r.rays).sum()
    }

    /// Wall time of all rounds.
    pub fn seconds(&self) -> f64 {
        self.rounds.iter().map(|r| r.seconds).sum()
    }
}

impl AdaptiveSampling {
    /// Checks the targets and the sampler of `settings`.
    pub fn check(&self, settings: &RenderSettings) -> Result<(), AdaptiveError> {
        if self.noise.is_none() && self.seconds.is_none() {
            return Err(AdaptiveError::NoTarget);
        }
        if let Some(noise) = self.noise.filter(|n| !(n.is_finite() && *n > 0.0)) {
            return Err(AdaptiveError::Noise(noise));
        }
        if let Some(seconds) = self.seconds.filter(|s| !(s.is_finite() && *s > 0.0)) {
            return Err(AdaptiveError::Seconds(seconds));
        }
        match settings.sampler {
            PixelSampler::Sobol | PixelSampler::Uniform | PixelSampler::Center => Ok(()),
            other => Err(AdaptiveError::Sampler(other)),
        }
    }
}

/// Renders `scene` with up to `settings.samples_per_pixel` samples a
/// pixel, in rounds, each pixel stopping as `settings.adaptive` says (see
/// the module's documentation; without it, [`AdaptiveError::NoTarget`]).
/// `on_round` hears of each round as it ends.
pub fn render_adaptive(
    scene: &Scene,
    accel: &dyn Accel,
    camera: &Camera,
    settings: &RenderSettings,
    on_round: &mut dyn FnMut(&Round),
) -> Result<(HdrImage, AdaptiveOutcome), AdaptiveError> {
    let adaptive = settings.adaptive.ok_or(AdaptiveError::NoTarget)?;
    adaptive.check(settings)?;
    let (width, height) = (settings.width, settings.height);
    let pixels = width as usize * height as usize;
    let last = settings.samples_per_pixel.max(1);
    let mut sums: Vec<PixelSum> = vec![[0; 3]; pixels];
    let mut samples = vec![0u32; pixels];
    let mut active = vec![true; pixels];
    let mut rounds: Vec<Round> = Vec::new();
    let mut stopped_by_time = false;
    let started = Instant::now();
    let control = PassControl { progress: &|_| {}, cancelled: &|| false };
    let mut done = 0;
    while done < last && !stopped_by_time {
        let mut next = if done == 0 { (FIRST_ROUND / 2).clamp(1, last) } else { done.saturating_mul(2).min(last) };
        let going = active.iter().filter(|&&a| a).count() as u64;
        if let (Some(bound), Some(_)) = (adaptive.seconds, rounds.last()) {
            // Time per pixel sample so far: a round that would overrun the
            // bound is cut to the samples that fit, and is the last. (The
            // noise target with this round's end as the samples per pixel
            // renders the same image: its last round is cut there too.)
            let spent: f64 = rounds.iter().map(|r| r.seconds).sum();
            let taken: u64 = samples.iter().map(|&n| n as u64).sum();
            let per_sample = spent / taken.max(1) as f64;
            let left = bound - started.elapsed().as_secs_f64();
            if left < per_sample * (going * (next - done) as u64) as f64 {
                let fit = (left / (per_sample * going.max(1) as f64)).floor().max(0.0) as u32;
                stopped_by_time = true;
                if fit == 0 {
                    break;
                }
                next = done + fit.min(next - done);
            }
        }
        let round_start = Instant::now();
        let (round, stats) =
            render_sums_of(scene, accel, camera, settings, 0..height, done..next, Some(&active), &control)
                .expect("a render that cannot be cancelled finishes");
        // Per pixel still going: its squared half difference (A − B)² / 4,
        // with A the mean before this round and B the round's own.
        let mut half_difference = vec![0.0f64; pixels];
        for i in (0..pixels).filter(|&i| active[i]) {
            if done > 0 {
                let before = luminance(mean(&sums[i], done)) as f64;
                let this_round = luminance(mean(&round[i], next - done)) as f64;
                half_difference[i] = (before - this_round).powi(2) / 4.0;
            }
            add(&mut sums[i], &round[i]);
            samples[i] = next;
        }
        done = next;
        let noisy = match adaptive.noise {
            // Halves are unequal when `last` or the time bound cut the last
            // round short; it is the last, so nothing is decided on it.
            Some(target) if done >= FIRST_ROUND && done < last && !stopped_by_time => {
                still_noisy(&sums, &samples, &half_difference, &active, width, height, target as f64)
            }
            _ => active.clone(),
        };
        let converged = noisy.iter().filter(|&&n| !n).count() as u64;
        let round = Round {
            samples_per_pixel: next,
            pixels: going,
            converged,
            rays: stats.rays,
            seconds: round_start.elapsed().as_secs_f64(),
        };
        on_round(&round);
        rounds.push(round);
        active = noisy;
        if !active.contains(&true) {
            break;
        }
    }
    let mut image = HdrImage::new(width, height);
    for ((pixel, sum), &n) in image.pixels_mut().iter_mut().zip(&sums).zip(&samples) {
        *pixel = mean(sum, n);
    }
    let samples_reached = samples.iter().copied().max().unwrap_or(0);
    Ok((image, AdaptiveOutcome { samples, rounds, samples_reached, stopped_by_time }))
}

/// The pixels that go on: those still going whose noise, the square root
/// of the squared half differences averaged over their 3 × 3
/// neighbourhood relative to their mean (or the floor), is above `target`.
fn still_noisy(
    sums: &[PixelSum],
    samples: &[u32],
    half_difference: &[f64],
    active: &[bool],
    width: u32,
    height: u32,
    target: f64,
) -> Vec<bool> {
    let means: Vec<f64> = sums.iter().zip(samples).map(|(s, &n)| luminance(mean(s, n)) as f64).collect();
    let image_mean = means.iter().sum::<f64>() / means.len().max(1) as f64;
    let floor = (DARK_FRACTION * image_mean).max(f64::MIN_POSITIVE);
    let (w, h) = (width as usize, height as usize);
    (0..w * h)
        .map(|i| {
            if !active[i] {
                return false;
            }
            let (x, y) = (i % w, i / w);
            // Neighbours that stopped earlier have no half difference of
            // this round; those still going stand in for them.
            let (mut total, mut count) = (0.0, 0usize);
            for ny in y.saturating_sub(1)..(y + 2).min(h) {
                for nx in x.saturating_sub(1)..(x + 2).min(w) {
                    let j = ny * w + nx;
                    if active[j] {
                        total += half_difference[j];
                        count += 1;
                    }
                }
            }
            relative_error(total / count.max(1) as f64, means[i], floor) > target
        })
        .collect()
}

/// The standard error `sqrt(squared_error)` relative to `mean` or `floor`, whichever is larger.
fn relative_error(squared_error: f64, mean: f64, floor: f64) -> f64 {
    squared_error.max(0.0).sqrt() / mean.abs().max(floor)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accumulation::to_fixed;
    use rtgi_math::Vec3;

    #[test]
    fn relative_error_is_over_the_mean_or_the_floor() {
        assert!((relative_error(0.25, 2.0, 0.1) - 0.25).abs() < 1e-12);
        assert!((relative_error(1e-6, 2e-3, 0.1) - 1e-3 / 0.1).abs() < 1e-12);
        assert_eq!(relative_error(0.0, 2.0, 0.1), 0.0);
    }

    #[test]
    fn a_noisy_pixel_keeps_its_neighbours_going_and_stopped_pixels_stay_stopped() {
        let (width, height) = (5, 4);
        let sums = vec![to_fixed(Vec3::ONE * 16.0); 20];
        let samples = vec![16; 20];
        let mut half_difference = vec![0.0; 20];
        // Pixel (1, 1) differs between its halves by 0.4 (of a mean of 1).
        half_difference[6] = 0.04;
        let mut active = vec![true; 20];
        active[0] = false;
        let going = still_noisy(&sums, &samples, &half_difference, &active, width, height, 0.05);
        let expected: Vec<bool> = (0..20).map(|i: usize| i != 0 && i % 5 <= 2 && i / 5 <= 2).collect();
        assert_eq!(going, expected);
    }
}
