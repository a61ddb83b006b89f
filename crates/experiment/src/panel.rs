//! Equal-time image panels: the same crop of renders that took about the
//! same time, beside a false-colour map of each one's error against the
//! reference, so that what the numbers say can be seen.
//!
//! The panel is a PNG that carries its labels (the title above; under each
//! column its configuration, time, RMSE and, where its error clips, how
//! much; the error scale's colour bar with its range), rasterised with an
//! 8×8 bitmap font, so that it reads alone; and an SVG that shows the
//! unlabelled tiles with the same labels as text the viewer draws. The
//! error scale is one per panel: the labels and the caption say which
//! entries clip on it. The caption, with the same figures, is a finding, so
//! the JSON holds it too.

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
    /// How long it took, in ms: in an equal-time panel, its fastest run
    /// of the rounds it was timed in alternation with the budget's render.
    pub time_ms: f64,
    /// In an equal-time panel, the budget's render's fastest run of the
    /// same rounds: the time this entry was held to. Timed alongside, so
    /// that the machine's speed, which drifts between the entries, cancels
    /// in their ratio.
    pub budget_ms: Option<f64>,
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

/// How far an equal-time entry's time may be from the budget, as a fraction of it.
pub(crate) const EQUAL_TIME_TOLERANCE: f64 = 0.05;

/// Each tile is the crop enlarged this many times, pixel for pixel.
const ZOOM: u32 = 3;
/// White between tiles, in panel pixels.
const GAP: u32 = 4;
/// Errors are mapped to colour up to this quantile of an entry's errors (the rest saturate).
const SCALE_QUANTILE: f64 = 0.99;
/// Height of the SVG's title band and of its label band under the tiles, in pixels.
const TITLE_BAND: u32 = 30;
/// Height of one line of the labels under the tiles, in pixels (13-pixel text).
const LABEL_LINE: u32 = 17;
/// The average width of a character of the 13-pixel sans-serif labels, in
/// pixels, a little generous: labels wider than their tile are wrapped.
const LABEL_CHAR_WIDTH: f32 = 7.4;
/// The narrowest a tile is shown in the SVG, in pixels: room for its label.
const MIN_LABELLED_TILE: u32 = 170;
/// Height of the colour bar band at the SVG's foot.
const BAR_BAND: u32 = 40;

/// `label` in lines of at most `width` characters where it can be, broken
/// after its commas ("depth 32, roulette on, 55 spp" under a narrow tile
/// becomes "depth 32, roulette on," and "55 spp"); a part longer than
/// `width` keeps a line of its own.
fn wrapped(label: &str, width: usize) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for part in label.split_inclusive(", ") {
        match lines.last_mut() {
            Some(line) if line.chars().count() + part.trim_end().chars().count() <= width => line.push_str(part),
            _ => lines.push(part.to_owned()),
        }
    }
    lines.iter().map(|line| line.trim_end().to_owned()).collect()
}

/// Text drawn into the PNG: black on white.
const INK: Vec3 = Vec3::ZERO;
/// An entry whose error exceeds the panel's scale in more than this
/// fraction of its crop's pixels is said to clip (the scale is a median of
/// the entries' 99th percentiles, so about 1% is the norm).
const CLIP_NOTE: f64 = 0.01;

/// The 8×8 glyph of `c`: ASCII from the font, a few other characters as
/// their nearest ASCII, anything else as `?`.
fn glyph(c: char) -> [u8; 8] {
    let c = match c {
        '×' => 'x',
        '≤' => '<',
        '–' | '—' | '−' => '-',
        '²' => '2',
        'µ' => 'u',
        c => c,
    };
    let index = if c.is_ascii() { c as usize } else { '?' as usize };
    font8x8::legacy::BASIC_LEGACY[index]
}

/// Width in pixels of `text` at `scale` (8 pixels a character, times the scale).
fn text_width(text: &str, scale: u32) -> u32 {
    text.chars().count() as u32 * 8 * scale
}

/// Draws `text` into `pixels` (an image `width` wide) with its top left at
/// `(x, y)`, each font pixel `scale` pixels square; what falls outside is cut.
fn draw_text(pixels: &mut [Vec3], width: u32, (x, y): (u32, u32), text: &str, scale: u32) {
    let height = pixels.len() as u32 / width.max(1);
    for (i, c) in text.chars().enumerate() {
        let left = x + i as u32 * 8 * scale;
        for (row, bits) in glyph(c).iter().enumerate() {
            for col in 0..8u32 {
                // Bit 0 is the glyph's leftmost pixel.
                if bits & (1 << col) == 0 {
                    continue;
                }
                for dy in 0..scale {
                    for dx in 0..scale {
                        let (px, py) = (left + col * scale + dx, y + row as u32 * scale + dy);
                        if px < width && py < height {
                            pixels[(py * width + px) as usize] = INK;
                        }
                    }
                }
            }
        }
    }
}

/// Draws `text` centred on column `centre`.
fn draw_centred(pixels: &mut [Vec3], width: u32, (centre, y): (u32, u32), text: &str, scale: u32) {
    draw_text(pixels, width, (centre.saturating_sub(text_width(text, scale) / 2), y), text, scale);
}

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

/// The top of the error scale: the median over the entries of each one's
/// high quantile of error in the crop. One entry full of fireflies (BSDF
/// sampling of a small light) would otherwise set a scale on which every
/// other entry is black.
fn error_scale(reference: &HdrImage, entries: &[Entry], crop: Crop) -> f64 {
    let mut quantiles: Vec<f32> = entries
        .iter()
        .filter_map(|e| {
            let errors = errors(&e.image, reference);
            let mut sorted: Vec<f32> = (crop.y..crop.y + crop.side)
                .flat_map(|y| (crop.x..crop.x + crop.side).map(move |x| (y * reference.width() + x) as usize))
                .map(|i| errors[i])
                .filter(|e| e.is_finite())
                .collect();
            sorted.sort_by(f32::total_cmp);
            sorted.get(((sorted.len() as f64 - 1.0) * SCALE_QUANTILE) as usize).copied()
        })
        .collect();
    quantiles.sort_by(f32::total_cmp);
    let median = match quantiles.len() {
        0 => 1.0,
        n if n % 2 == 1 => quantiles[n / 2],
        n => 0.5 * (quantiles[n / 2 - 1] + quantiles[n / 2]),
    };
    median.max(1e-12) as f64
}

/// `text` with the characters XML gives a meaning escaped.
fn xml_escaped(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// The SVG's name for a panel's PNG file: the same stem, `.svg`.
pub fn labelled_file(file: &str) -> String {
    match file.strip_suffix(".png") {
        Some(stem) => format!("{stem}.svg"),
        None => format!("{file}.svg"),
    }
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
    /// The time every entry was given, in ms, if the panel is an equal-time one.
    pub budget_ms: Option<f64>,
}

impl Panel {
    /// A panel of `entries` against `reference`, its crop where they err most.
    pub fn new(file: impl Into<String>, title: impl Into<String>, reference: HdrImage, entries: Vec<Entry>) -> Panel {
        let crop = choose_crop(&reference, &entries);
        let scale = error_scale(&reference, &entries, crop);
        Panel { file: file.into(), title: title.into(), reference, entries, crop, scale, budget_ms: None }
    }

    /// An entry's time over the budget, for an equal-time panel: over the
    /// budget timed alongside it where it was, else over the panel's.
    pub fn budget_share(&self, entry: &Entry) -> Option<f64> {
        self.budget_ms.map(|budget| entry.time_ms / entry.budget_ms.unwrap_or(budget).max(1e-9))
    }

    /// Per entry, the fraction of its crop's pixels whose error is above
    /// the panel's one error scale (drawn saturated: they clip).
    pub fn clipped(&self) -> Vec<f64> {
        let crop = self.crop;
        let width = self.reference.width();
        self.entries
            .iter()
            .map(|e| {
                let errors = errors(&e.image, &self.reference);
                let above = (crop.y..crop.y + crop.side)
                    .flat_map(|y| (crop.x..crop.x + crop.side).map(move |x| (y * width + x) as usize))
                    .filter(|&i| errors[i].is_nan() || errors[i] as f64 > self.scale)
                    .count();
                above as f64 / (crop.side * crop.side).max(1) as f64
            })
            .collect()
    }

    /// The note on an entry that clips: `clips 12%` (of its crop's pixels), or none.
    fn clip_note(fraction: f64) -> Option<String> {
        (fraction > CLIP_NOTE).then(|| format!("clips {:.0}%", 100.0 * fraction))
    }

    /// What the panel shows, left to right, with the figures: for the report's findings.
    pub fn caption(&self) -> String {
        let entries: Vec<String> = self
            .entries
            .iter()
            .zip(self.clipped())
            .map(|(e, clipped)| {
                let clips = Self::clip_note(clipped)
                    .map(|_| format!(", {:.0}% of its crop above the scale", 100.0 * clipped))
                    .unwrap_or_default();
                format!(
                    "{} ({} ms{}, RMSE {}{clips})",
                    e.label,
                    crate::format::format_ms(e.time_ms),
                    self.budget_share(e).map_or(String::new(), |share| {
                        let off = share - 1.0;
                        if off.abs() <= EQUAL_TIME_TOLERANCE {
                            format!(", {:+.1}% of the budget", 100.0 * off)
                        } else {
                            format!(", {:+.1}% of the budget: outside ±5%", 100.0 * off)
                        }
                    }),
                    crate::format::format_number(e.rmse)
                )
            })
            .collect();
        let clipping: Vec<&str> = self
            .entries
            .iter()
            .zip(self.clipped())
            .filter(|(_, c)| Self::clip_note(*c).is_some())
            .map(|(e, _)| e.label.as_str())
            .collect();
        let clipping = if clipping.is_empty() {
            "no entry clips on it".to_owned()
        } else {
            format!("clipping on it: {}", clipping.join(", "))
        };
        let timing = if self.budget_ms.is_some() {
            "; each time is the entry's fastest run of rounds alternated with the budget's render, and its share \
             is over that render's fastest run of the same rounds"
        } else {
            ""
        };
        format!(
            "{} ({}): top, the reference then {}; below, each one's absolute error, black 0 to pale yellow {} \
             (inferno scale, one error scale per panel; {clipping}); crop {}×{} at ({}, {}){timing}",
            self.title,
            self.file,
            entries.join(", "),
            crate::format::format_number(self.scale),
            self.crop.side,
            self.crop.side,
            self.crop.x,
            self.crop.y
        )
    }

    /// How many panel pixels a pixel of the crop takes: [`ZOOM`], or more
    /// for a small crop, so that each column is wide enough for its label.
    fn zoom(&self) -> u32 {
        ZOOM * MIN_LABELLED_TILE.div_ceil(self.crop.side * ZOOM).max(1)
    }

    /// The tiles without labels: the reference's crop and each entry's in
    /// the top row, tone-mapped alike (ACES at the reference's automatic
    /// exposure), and each entry's error map below (`heat_colour`, one scale for all).
    fn tiles(&self) -> HdrImage {
        let (reference, crop, zoom) = (&self.reference, self.crop, self.zoom());
        let tone = ToneMap { exposure: auto_exposure(reference), operator: ToneOperator::Aces };
        let tile = crop.side * zoom;
        let columns = 1 + self.entries.len() as u32;
        let (width, height) = (columns * tile + (columns + 1) * GAP, 2 * tile + 3 * GAP);
        let mut pixels = vec![Vec3::ONE; (width * height) as usize];
        let mut put = |column: u32, row: u32, value: &dyn Fn(u32, u32) -> Vec3| {
            let (left, top) = (GAP + column * (tile + GAP), GAP + row * (tile + GAP));
            for ty in 0..tile {
                for tx in 0..tile {
                    let (x, y) = (crop.x + tx / zoom, crop.y + ty / zoom);
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
        HdrImage::from_pixels(width, height, pixels).expect("the sizes agree")
    }

    /// Each column's labels: the configuration (wrapped to `chars` a line),
    /// its time, its RMSE and, where its error clips on the panel's scale, how much.
    fn column_labels(&self, chars: usize) -> Vec<Vec<String>> {
        std::iter::once(vec!["reference".to_owned()])
            .chain(self.entries.iter().zip(self.clipped()).map(|(e, clipped)| {
                let mut lines = wrapped(&e.label, chars.max(1));
                lines.push(format!("{} ms", crate::format::format_ms(e.time_ms)));
                lines.push(format!("RMSE {}", crate::format::format_number(e.rmse)));
                lines.extend(Self::clip_note(clipped));
                lines
            }))
            .collect()
    }

    /// The font's scale for the labels under columns `tile` pixels wide:
    /// twice its size where every label line fits its column so (a label
    /// breaks only after commas), else its own size.
    fn label_scale(&self, tile: u32) -> u32 {
        let fits = |scale: u32| {
            tile >= 12 * 8 * scale
                && self
                    .column_labels((tile / (8 * scale)) as usize)
                    .iter()
                    .flatten()
                    .all(|text| text_width(text, scale) <= tile)
        };
        if fits(2) { 2 } else { 1 }
    }

    /// `tiles` with the labels drawn in: the title in a band above, each
    /// column's labels under it, and the colour bar of the error scale with
    /// its range at the foot; with the row at which the tiles start.
    fn labelled(&self, tiles: &HdrImage) -> (HdrImage, u32) {
        let (width, tiles_height) = (tiles.width(), tiles.height());
        let tile = self.crop.side * self.zoom();
        let scale = self.label_scale(tile);
        let line = 8 * scale + 4;
        let title_scale = if text_width(&self.title, 2) + 2 * GAP <= width { 2 } else { 1 };
        let title = crate::plot::wrap_text(&self.title, ((width - 2 * GAP) / (8 * title_scale)).max(1) as usize);
        let title_band = 6 + title.len() as u32 * (8 * title_scale + 4) + 4;
        let columns = self.column_labels((tile / (8 * scale)) as usize);
        let label_lines = columns.iter().map(Vec::len).max().unwrap_or(1) as u32;
        let label_band = 4 + label_lines * line + 4;
        let bar_band = 12 + line + 6;
        let height = title_band + tiles_height + label_band + bar_band;
        let mut pixels = vec![Vec3::ONE; (width * height) as usize];
        for y in 0..tiles_height {
            let row = (y * width) as usize;
            let to = ((title_band + y) * width) as usize;
            pixels[to..to + width as usize].copy_from_slice(&tiles.pixels()[row..row + width as usize]);
        }
        for (i, text) in title.iter().enumerate() {
            draw_centred(&mut pixels, width, (width / 2, 6 + i as u32 * (8 * title_scale + 4)), text, title_scale);
        }
        let label_top = title_band + tiles_height + 4;
        for (column, lines) in columns.iter().enumerate() {
            let centre = GAP + column as u32 * (tile + GAP) + tile / 2;
            for (i, text) in lines.iter().enumerate() {
                draw_centred(&mut pixels, width, (centre, label_top + i as u32 * line), text, scale);
            }
        }
        // The colour bar across the middle half, 0 at its left end, the scale at its right.
        let (bar_left, bar_width, bar_top) = (width / 4, (width / 2).max(1), title_band + tiles_height + label_band);
        for x in bar_left..bar_left + bar_width {
            let colour = heat_colour((x - bar_left) as f32 / bar_width as f32);
            for y in bar_top..bar_top + 8 {
                pixels[(y * width + x) as usize] = colour;
            }
        }
        let top = format!("{}+", crate::format::format_number(self.scale));
        draw_text(&mut pixels, width, (bar_left, bar_top + 10), "0", scale);
        let right = (bar_left + bar_width).saturating_sub(text_width(&top, scale));
        draw_text(&mut pixels, width, (right, bar_top + 10), &top, scale);
        (HdrImage::from_pixels(width, height, pixels).expect("the sizes agree"), title_band)
    }

    /// Writes the PNG to `path`, with its labels drawn in (`Panel::labelled`),
    /// and the SVG beside it, which shows the tiles with its labels as text.
    pub fn write(&self, path: &Path) -> Result<(), ExperimentError> {
        let image_error = |message: String| ExperimentError::Image { path: path.to_owned(), message };
        let tiles = self.tiles();
        let (panel, _) = self.labelled(&tiles);
        panel.write(path, &ToneMap::default()).map_err(|e| image_error(e.to_string()))?;
        let mut png = Vec::new();
        image::ImageEncoder::write_image(
            image::codecs::png::PngEncoder::new(&mut png),
            &tiles.to_srgb8(&ToneMap::default()),
            tiles.width(),
            tiles.height(),
            image::ExtendedColorType::Rgb8,
        )
        .map_err(|e| image_error(e.to_string()))?;
        self.write_labelled(path, &png, tiles.width(), tiles.height())
    }

    /// Writes the SVG beside the PNG at `png`: the unlabelled tiles (a PNG,
    /// embedded, so the SVG stands alone), the title above them, under each column its label,
    /// time and RMSE, and at the foot the error scale as a colour bar.
    fn write_labelled(&self, png: &Path, tiles: &[u8], width: u32, height: u32) -> Result<(), ExperimentError> {
        use base64::Engine;
        use std::fmt::Write;
        let encoded = base64::engine::general_purpose::STANDARD.encode(tiles);
        // Small crops are shown larger, so that each column is wide enough for its label.
        let scale = MIN_LABELLED_TILE.div_ceil(self.crop.side * self.zoom()).max(1);
        let (width, height) = (width * scale, height * scale);
        let (tile, gap) = (self.crop.side * self.zoom() * scale, GAP * scale);
        let columns = self.column_labels((tile as f32 / LABEL_CHAR_WIDTH) as usize);
        let label_lines = columns.iter().map(Vec::len).max().unwrap_or(1) as u32;
        let label_band = 8 + LABEL_LINE * label_lines + 8;
        let total_height = TITLE_BAND + height + label_band + BAR_BAND;
        let mut svg = String::new();
        let _ = writeln!(
            svg,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{total_height}" viewBox="0 0 {width} {total_height}" font-family="sans-serif">"#
        );
        let _ = writeln!(svg, r#"<rect width="100%" height="100%" fill="white"/>"#);
        let _ = writeln!(
            svg,
            r#"<text x="{}" y="20" font-size="15" text-anchor="middle">{}</text>"#,
            width / 2,
            xml_escaped(&self.title)
        );
        let _ = writeln!(
            svg,
            r#"<image x="0" y="{TITLE_BAND}" width="{width}" height="{height}" style="image-rendering:pixelated" href="data:image/png;base64,{encoded}"/>"#
        );
        let label_top = TITLE_BAND + height + 16;
        for (column, lines) in columns.iter().enumerate() {
            let centre = gap + column as u32 * (tile + gap) + tile / 2;
            for (line, text) in lines.iter().enumerate() {
                let _ = writeln!(
                    svg,
                    r#"<text x="{centre}" y="{}" font-size="13" text-anchor="middle">{}</text>"#,
                    label_top + line as u32 * LABEL_LINE,
                    xml_escaped(text)
                );
            }
        }
        // The colour bar: the error scale from 0 to the saturating error, in steps.
        let (bar_left, bar_width, bar_top, steps) = (width / 4, width / 2, TITLE_BAND + height + label_band, 64u32);
        for step in 0..steps {
            let colour = heat_colour((step as f32 + 0.5) / steps as f32).to_array();
            let [r, g, b] = colour.map(|c| (rtgi_image::linear_to_srgb(c) * 255.0 + 0.5) as u8);
            let x = bar_left as f64 + step as f64 * bar_width as f64 / steps as f64;
            let _ = writeln!(
                svg,
                r##"<rect x="{x:.2}" y="{bar_top}" width="{:.2}" height="12" fill="#{r:02x}{g:02x}{b:02x}"/>"##,
                bar_width as f64 / steps as f64 + 0.3
            );
        }
        let _ = writeln!(
            svg,
            r#"<text x="{}" y="{}" font-size="12" text-anchor="end">absolute error 0</text>"#,
            bar_left - 6,
            bar_top + 11
        );
        let _ = writeln!(
            svg,
            r#"<text x="{}" y="{}" font-size="12">{} and above</text>"#,
            bar_left + bar_width + 6,
            bar_top + 11,
            crate::format::format_number(self.scale)
        );
        let _ = writeln!(svg, "</svg>");
        let path = png.with_file_name(labelled_file(&png.file_name().unwrap_or_default().to_string_lossy()));
        rtgi_image::write_atomically(&path, svg.as_bytes())
            .map_err(|source| ExperimentError::Write { path: path.clone(), source })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_labels_break_after_commas_to_fit_their_tile() {
        assert_eq!(wrapped("depth 32, roulette on, 55 spp", 23), ["depth 32, roulette on,", "55 spp"]);
        assert_eq!(wrapped("depth 32, roulette on, 55 spp", 40), ["depth 32, roulette on, 55 spp"]);
        assert_eq!(wrapped("stratified, 16 spp", 23), ["stratified, 16 spp"]);
        assert_eq!(wrapped("a-very-long-single-part-label", 10), ["a-very-long-single-part-label"]);
        assert_eq!(wrapped("a, b, c", 1), ["a,", "b,", "c"]);
    }

    /// How many of the rows `rows` of `png` are dark (text) pixels.
    fn dark_pixels(png: &image::RgbImage, rows: std::ops::Range<u32>) -> usize {
        rows.flat_map(|y| (0..png.width()).map(move |x| (x, y)))
            .filter(|&(x, y)| png.get_pixel(x, y).0.iter().all(|&c| c < 60))
            .count()
    }

    #[test]
    fn the_png_carries_its_labels() {
        let reference = flat(0.5);
        let entries = vec![
            Entry { label: "a".into(), image: flat(0.6), time_ms: 1.0, budget_ms: None, rmse: 0.1 },
            Entry { label: "b".into(), image: flat(0.7), time_ms: 2.0, budget_ms: None, rmse: 0.2 },
        ];
        let panel = Panel::new("labels.png", "TITLE", reference, entries);
        let tiles = panel.tiles();
        let (labelled, top) = panel.labelled(&tiles);
        let bytes = labelled.to_srgb8(&ToneMap::default());
        let png = image::RgbImage::from_raw(labelled.width(), labelled.height(), bytes).unwrap();
        // The title band and the label band under the tiles have text in them; the tiles are where they were.
        assert!(dark_pixels(&png, 0..top) > 40, "title");
        let below = top + tiles.height();
        assert!(dark_pixels(&png, below..png.height()) > 200, "labels");
        assert_eq!(labelled.get(GAP + 1, top + GAP + 1), tiles.get(GAP + 1, GAP + 1));
        // The glyphs are the font's: "T" is a bar across the top of its cell.
        let mut pixels = vec![Vec3::ONE; 8 * 8];
        draw_text(&mut pixels, 8, (0, 0), "T", 1);
        let row = |y: usize| (0..8).filter(|&x| pixels[y * 8 + x] == INK).count();
        assert!(row(0) >= 6 && row(4) <= 2, "{}", (0..8).map(row).map(|n| n.to_string()).collect::<String>());
        // And an empty title band when there is nothing to say is still white.
        assert_eq!(dark_pixels(&png, 0..2), 0);
    }

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
            Entry { label: "exact".into(), image: flat(0.5), time_ms: 1.0, budget_ms: None, rmse: 0.0 },
            Entry { label: "noisy".into(), image: noisy, time_ms: 1.0, budget_ms: None, rmse: 0.1 },
        ];
        let panel = Panel::new("panel.png", "a test", reference, entries);
        let crop = panel.crop;
        assert_eq!(crop.side, 8);
        assert!(crop.x + crop.side >= 15 && crop.x <= 11 && crop.y + crop.side >= 14 && crop.y <= 10, "{crop:?}");
        let dir = std::env::temp_dir().join(format!("rtgi-panel-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("panel.png");
        panel.write(&path).unwrap();
        // The median of the two entries' 99th percentiles in the crop: 0 for the exact one, 1.5 for the noisy one.
        assert!((panel.scale - 0.75).abs() < 1e-6, "{}", panel.scale);
        let svg = std::fs::read_to_string(dir.join("panel.svg")).unwrap();
        assert!(
            svg.contains("data:image/png;base64,") && svg.contains(">noisy<") && svg.contains(">RMSE 0.1<"),
            "{svg}"
        );
        assert!(panel.caption().contains("noisy (1.00 ms, RMSE 0.1, "), "{}", panel.caption());
        let png = image::open(&path).unwrap().to_rgb8();
        let tile = crop.side * panel.zoom();
        let tiles = panel.tiles();
        assert_eq!((tiles.width(), tiles.height()), (3 * tile + 4 * GAP, 2 * tile + 3 * GAP));
        let (labelled, top) = panel.labelled(&tiles);
        assert_eq!((png.width(), png.height()), (labelled.width(), labelled.height()));
        assert!(top > 0 && png.height() > top + tiles.height());
        // The exact entry's error map is the scale's zero everywhere; the noisy one's is bright where it errs.
        let zero = heat_colour(0.0).to_array().map(|c| (rtgi_image::linear_to_srgb(c) * 255.0 + 0.5) as u8);
        let exact_error = png.get_pixel(2 * GAP + tile + 1, top + 2 * GAP + tile + 1).0;
        assert_eq!(exact_error, zero);
        let (ex, ey) = ((12 - crop.x) * panel.zoom() + 1, (11 - crop.y) * panel.zoom() + 1);
        let noisy_error = png.get_pixel(3 * GAP + 2 * tile + ex, top + 2 * GAP + tile + ey).0;
        assert!(noisy_error.iter().map(|&c| c as u32).sum::<u32>() > 500, "{noisy_error:?}");
        // The noisy entry clips on the one scale (its 4×4 error block is 1.5, the scale 0.75), and says so.
        let clipped = panel.clipped();
        assert_eq!(clipped[0], 0.0);
        assert!((clipped[1] - 16.0 / 64.0).abs() < 1e-9, "{clipped:?}");
        assert!(
            panel.caption().contains("25% of its crop above the scale")
                && panel.caption().contains("clipping on it: noisy")
        );
        assert!(svg.contains(">clips 25%<"), "{svg}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn an_entry_is_held_to_the_budget_timed_alongside_it_and_a_miss_is_said() {
        let entry = |label: &str, time_ms: f64, budget_ms: Option<f64>| Entry {
            label: label.into(),
            image: flat(0.6),
            time_ms,
            budget_ms,
            rmse: 0.1,
        };
        let entries =
            vec![entry("held", 102.0, Some(100.0)), entry("over", 110.0, Some(100.0)), entry("old", 97.0, None)];
        let mut panel = Panel::new("p.png", "t", flat(0.5), entries);
        panel.budget_ms = Some(120.0);
        let shares: Vec<f64> = panel.entries.iter().map(|e| panel.budget_share(e).unwrap()).collect();
        assert_eq!(shares, vec![1.02, 1.1, 97.0 / 120.0]);
        let caption = panel.caption();
        assert!(caption.contains("held (102 ms, +2.0% of the budget, RMSE"), "{caption}");
        assert!(caption.contains("over (110 ms, +10.0% of the budget: outside ±5%, RMSE"), "{caption}");
        assert!(caption.contains("fastest run of rounds alternated with the budget's render"), "{caption}");
    }

    #[test]
    fn labels_too_wide_for_their_column_at_twice_the_size_are_drawn_at_the_font_s_own() {
        let entries = |label: &str| {
            vec![Entry { label: label.into(), image: flat(0.6), time_ms: 1.0, budget_ms: None, rmse: 0.1 }]
        };
        let short = Panel::new("a.png", "t", flat(0.5), entries("none, 16 spp"));
        let long = Panel::new("b.png", "t", flat(0.5), entries("clamp 0.25× mean, 16 spp"));
        let tile = short.crop.side * short.zoom();
        // 192 pixels hold 12 characters at twice the size: "clamp 0.25× mean," has 17.
        assert_eq!((tile, short.label_scale(tile), long.label_scale(tile)), (192, 2, 1));
    }
}
