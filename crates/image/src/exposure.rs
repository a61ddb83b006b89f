//! Choosing an exposure from the image itself, and noticing images that
//! came out almost black or almost white, so that a first render is
//! neither dark nor clipped and a failed one says so.

use rtgi_math::luminance;

use crate::{HdrImage, ToneMap};

/// The luminance the image's log-average is brought to: the photographic
/// "middle grey" key (Reinhard et al. 2002).
const KEY: f32 = 0.18;

/// Exposures beyond this many stops either way are not chosen automatically.
const LIMIT: f32 = 12.0;

/// Pixels darker than this luminance are left out of the average: the
/// black of a background that sees nothing says nothing about exposure.
const BLACK: f32 = 1e-6;

/// An exposure in stops for `image`: its pixels' log-average luminance
/// brought to middle grey, but lowered if that would push more than 2% of
/// the pixels past 4 (where the filmic curve has all but reached white),
/// and rounded down to a tenth of a stop. 0 for an image with nothing in it.
pub fn auto_exposure(image: &HdrImage) -> f32 {
    let mut luminances: Vec<f32> =
        image.pixels().iter().map(|&p| luminance(p)).filter(|l| l.is_finite() && *l > BLACK).collect();
    if luminances.is_empty() {
        return 0.0;
    }
    let log_average = (luminances.iter().map(|l| (*l as f64).ln()).sum::<f64>() / luminances.len() as f64).exp();
    let mut stops = (KEY as f64 / log_average).log2() as f32;
    let bright = (luminances.len() * 98 / 100).min(luminances.len() - 1);
    let (_, percentile, _) = luminances.select_nth_unstable_by(bright, f32::total_cmp);
    let highlight_limit = (4.0 / *percentile).log2();
    stops = stops.min(highlight_limit).clamp(-LIMIT, LIMIT);
    // Down to a tenth of a stop (never brighter than the limits allow).
    (stops * 10.0 + 1e-3).floor() / 10.0
}

/// How an image looks once tone-mapped, when it would not show much.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Legibility {
    /// Almost every pixel is black (the fraction of them).
    AlmostBlack(f32),
    /// Almost every pixel is white.
    AlmostWhite(f32),
}

/// Whether `image`, mapped by `tone_map`, is almost all black (95% of its
/// pixels below 2% in every channel) or almost all white (95% above 98% in
/// every channel); `None` when it shows something.
pub fn legibility(image: &HdrImage, tone_map: &ToneMap) -> Option<Legibility> {
    let count = image.pixels().len().max(1) as f32;
    let (mut black, mut white) = (0usize, 0usize);
    for &p in image.pixels() {
        let mapped = tone_map.apply(p);
        black += (mapped.max_element() < 0.02) as usize;
        white += (mapped.min_element() > 0.98) as usize;
    }
    let (black, white) = (black as f32 / count, white as f32 / count);
    if black >= 0.95 {
        Some(Legibility::AlmostBlack(black))
    } else if white >= 0.95 {
        Some(Legibility::AlmostWhite(white))
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ToneOperator;

    fn image_of(values: &[f32]) -> HdrImage {
        HdrImage::from_pixels(values.len() as u32, 1, values.iter().map(|&v| rtgi_math::Vec3::splat(v)).collect())
            .unwrap()
    }

    #[test]
    fn a_dim_image_is_brightened_and_a_bright_one_darkened() {
        let dim = image_of(&[0.01, 0.02, 0.015, 0.012]);
        let stops = auto_exposure(&dim);
        assert!(stops > 3.0, "{stops}");
        let bright = image_of(&[40.0, 60.0, 55.0, 50.0]);
        assert!(auto_exposure(&bright) < -7.0);
        // Middle grey stays as it is.
        assert_eq!(auto_exposure(&image_of(&[0.18; 8])), 0.0);
    }

    #[test]
    fn highlights_hold_the_exposure_down_and_black_is_ignored() {
        // A dark image with a bright 5% would be clipped by the log-average alone.
        let mut values = vec![0.01f32; 95];
        values.extend([100.0; 5]);
        let stops = auto_exposure(&image_of(&values));
        assert!(100.0 * stops.exp2() <= 4.05, "{stops}");
        assert_eq!(auto_exposure(&image_of(&[0.0, 0.18, 0.0, 0.18])), 0.0);
        assert_eq!(auto_exposure(&image_of(&[0.0; 4])), 0.0);
        assert_eq!(auto_exposure(&image_of(&[f32::NAN, f32::INFINITY])), 0.0);
    }

    #[test]
    fn black_and_white_images_are_noticed() {
        let tone_map = ToneMap { exposure: 0.0, operator: ToneOperator::Aces };
        assert!(matches!(legibility(&image_of(&[0.0; 40]), &tone_map), Some(Legibility::AlmostBlack(_))));
        assert!(matches!(legibility(&image_of(&[1e4; 40]), &tone_map), Some(Legibility::AlmostWhite(_))));
        let mut mixed = vec![0.0f32; 30];
        mixed.extend([0.5; 10]);
        assert_eq!(legibility(&image_of(&mixed), &tone_map), None);
    }
}
