//! Equal-time image panels: the same crop of renders that took about the
//! same time, beside a false-colour map of each one's error against the
//! reference, so that what the numbers say can be seen.
//!
//! The panel is a PNG; its labels (configuration, time, RMSE) and the error
//! scale are written in the report beside it (the caption is a finding, so
//! the JSON holds it): text in the image would need a font, which no
//! dependency of ours carries.

use std::path::Path;

use rtgi_image::{HdrImage, ToneMap, ToneOperator, auto_exposure, heat_colour};
use rtgi_math::Vec3;

use crate::ExperimentError;

/// One render of a panel.
#[derive(Debug)]
pub struct Entry {
    /// The configuration.
    pub label: String,
    /// Its render.
    pub image: HdrImage,
    /// How long it took, in ms.
    pub time_ms: f64,
    /// Its RMSE against the reference.
    pub rmse: f64,
}

/// A crop of an image: its corner and side, in pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Crop {
    /// Left column.
    pub x: u32,
    /// Top row.
    pub y: u32,
    /// Width and height.
    pub side: u32,
}

/// Each tile is the crop enlarged this many times, pixel for pixel.
const ZOOM: u32 = 3;
/// White between tiles, in panel pixels.
const GAP: u32 = 4;
/// Errors are mapped to colour up to this quantile of all entries' errors (the rest saturate).
const SCALE_QUANTILE: f64 = 0.99;

/// The absolute error of each pixel (mean over channels).
fn errors(image: &HdrImage, reference: &HdrImage) -> Vec<f32> {
    image.pixels().iter().zip(reference.pixels()).map(|(a, b)| ((*a - *b).abs()).element_sum() / 3.0).collect()
}

/// The square crop, half the image's shorter side, where the entries' mean
/// squared error is largest: where they differ most from the reference,
/// and so from each other.
pub fn choose_crop(reference: &HdrImage, entries: &[Entry]) -> Crop {
    let (w, h) = (reference.width(), reference.height());
    let side = (w.min(h) / 2).max(1);
    let step = (side / 4).max(1);
    let squared: Vec<f64> = (0..(w * h) as usize)
        .map(|i| entries.iter().map(|e| ((e.image.pixels()[i] - reference.pixels()[i]).length_squared()) as f64).sum())
        .collect();
    let mut best = (Crop { x: 0, y: 0, side }, f64::NEG_INFINITY);
    for y in (0..=h - side).step_by(step as usize) {
        for x in (0..=w - side).step_by(step as usize) {
            let sum: f64 = (y..y + side)
                .flat_map(|row| (x..x + side).map(move |col| (row * w + col) as usize))
                .map(|i| squared[i])
                .sum();
            if sum > best.1 {
                best = (Crop { x, y, side }, sum);
            }
        }
    }
    best.0
}

/// The top of the error scale: a high quantile of every entry's error in the crop.
fn error_scale(reference: &HdrImage, entries: &[Entry], crop: Crop) -> f64 {
    let mut sorted: Vec<f32> = entries
        .iter()
        .flat_map(|e| {
            let errors = errors(&e.image, reference);
            (crop.y..crop.y + crop.side)
                .flat_map(|y| (crop.x..crop.x + crop.side).map(move |x| (y * reference.width() + x) as usize))
                .map(move |i| errors[i])
                .collect::<Vec<_>>()
        })
        .filter(|e| e.is_finite())
        .collect();
    sorted.sort_by(f32::total_cmp);
    sorted.get(((sorted.len() as f64 - 1.0) * SCALE_QUANTILE) as usize).copied().unwrap_or(1.0).max(1e-12) as f64
}

/// An equal-time panel of a report: renders of several configurations in
/// about the same time, the reference, the crop and the error scale.
#[derive(Debug)]
pub struct Panel {
    /// The PNG's file name.
    pub file: String,
    /// What it shows.
    pub title: String,
    /// The reference the errors are of.
    pub reference: HdrImage,
    /// The renders, left to right after the reference.
    pub entries: Vec<Entry>,
    /// The crop shown.
    pub crop: Crop,
    /// The error that saturates the colour scale.
    pub scale: f64,
}

impl Panel {
    /// A panel of `entries` against `reference`, its crop where they err most.
    pub fn new(file: impl Into<String>, title: impl Into<String>, reference: HdrImage, entries: Vec<Entry>) -> Panel {
        let crop = choose_crop(&reference, &entries);
        let scale = error_scale(&reference, &entries, crop);
        Panel { file: file.into(), title: title.into(), reference, entries, crop, scale }
    }

    /// What the panel shows, left to right, with the figures: for the report's findings.
    pub fn caption(&self) -> String {
        let entries: Vec<String> = self
            .entries
            .iter()
            .map(|e| {
                format!(
                    "{} ({} ms, RMSE {})",
                    e.label,
                    crate::report::format_ms(e.time_ms),
                    crate::report::format_number(e.rmse)
                )
            })
            .collect();
        format!(
            "{} ({}): top, the reference then {}; below, each one's absolute error, black 0 to pale yellow {} \
             (inferno scale); crop {}×{} at ({}, {})",
            self.title,
            self.file,
            entries.join(", "),
            crate::report::format_number(self.scale),
            self.crop.side,
            self.crop.side,
            self.crop.x,
            self.crop.y
        )
    }

    /// Writes the PNG to `path`: the reference's crop and each entry's in
    /// the top row, tone-mapped alike (ACES at the reference's automatic
    /// exposure), and each entry's error map below (`heat_colour`, one scale for all).
    pub fn write(&self, path: &Path) -> Result<(), ExperimentError> {
        let (reference, crop) = (&self.reference, self.crop);
        let tone = ToneMap { exposure: auto_exposure(reference), operator: ToneOperator::Aces };
        let tile = crop.side * ZOOM;
        let columns = 1 + self.entries.len() as u32;
        let (width, height) = (columns * tile + (columns + 1) * GAP, 2 * tile + 3 * GAP);
        let mut pixels = vec![Vec3::ONE; (width * height) as usize];
        let mut put = |column: u32, row: u32, value: &dyn Fn(u32, u32) -> Vec3| {
            let (left, top) = (GAP + column * (tile + GAP), GAP + row * (tile + GAP));
            for ty in 0..tile {
                for tx in 0..tile {
                    let (x, y) = (crop.x + tx / ZOOM, crop.y + ty / ZOOM);
                    pixels[((top + ty) * width + left + tx) as usize] = value(x, y);
                }
            }
        };
        let at = |image: &HdrImage, x: u32, y: u32| image.pixels()[(y * image.width() + x) as usize];
        put(0, 0, &|x, y| tone.apply(at(reference, x, y)));
        for (i, entry) in self.entries.iter().enumerate() {
            let column = 1 + i as u32;
            put(column, 0, &|x, y| tone.apply(at(&entry.image, x, y)));
            let errors = errors(&entry.image, reference);
            let scale = self.scale as f32;
            put(column, 1, &|x, y| heat_colour(errors[(y * reference.width() + x) as usize] / scale));
        }
        let panel = HdrImage::from_pixels(width, height, pixels).expect("the sizes agree");
        panel
            .write(path, &ToneMap::default())
            .map_err(|e| ExperimentError::Image { path: path.to_owned(), message: e.to_string() })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat(value: f32) -> HdrImage {
        HdrImage::from_pixels(16, 16, vec![Vec3::splat(value); 256]).unwrap()
    }

    #[test]
    fn the_crop_goes_where_the_errors_are_and_the_panel_has_its_layout() {
        let reference = flat(0.5);
        let mut noisy = flat(0.5);
        for y in 10..14 {
            for x in 11..15 {
                noisy.set(x, y, Vec3::splat(2.0));
            }
        }
        let entries = vec![
            Entry { label: "exact".into(), image: flat(0.5), time_ms: 1.0, rmse: 0.0 },
            Entry { label: "noisy".into(), image: noisy, time_ms: 1.0, rmse: 0.1 },
        ];
        let panel = Panel::new("panel.png", "a test", reference, entries);
        let crop = panel.crop;
        assert_eq!(crop.side, 8);
        assert!(crop.x + crop.side >= 15 && crop.x <= 11 && crop.y + crop.side >= 14 && crop.y <= 10, "{crop:?}");
        let dir = std::env::temp_dir().join(format!("rtgi-panel-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("panel.png");
        panel.write(&path).unwrap();
        assert!((panel.scale - 1.5).abs() < 1e-6, "{}", panel.scale);
        assert!(panel.caption().contains("noisy (1.00 ms, RMSE 0.1)"), "{}", panel.caption());
        let png = image::open(&path).unwrap().to_rgb8();
        let tile = crop.side * ZOOM;
        assert_eq!((png.width(), png.height()), (3 * tile + 4 * GAP, 2 * tile + 3 * GAP));
        // The exact entry's error map is the scale's zero everywhere; the noisy one's is bright where it errs.
        let zero = heat_colour(0.0).to_array().map(|c| (rtgi_image::linear_to_srgb(c) * 255.0 + 0.5) as u8);
        let exact_error = png.get_pixel(2 * GAP + tile + 1, 2 * GAP + tile + 1).0;
        assert_eq!(exact_error, zero);
        let (ex, ey) = ((12 - crop.x) * ZOOM + 1, (11 - crop.y) * ZOOM + 1);
        let noisy_error = png.get_pixel(3 * GAP + 2 * tile + ex, 2 * GAP + tile + ey).0;
        assert!(noisy_error.iter().map(|&c| c as u32).sum::<u32>() > 500, "{noisy_error:?}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
