//! Images put together: a contact sheet of pictures, and a false-colour
//! map of one channel of counts.

use rtgi_math::Vec3;

use crate::{HdrImage, ToneMap, heat_colour};

/// A contact sheet: `pictures` (each with the tone map that makes it
/// displayable) in a grid of `columns`, each in a `width` × `height` cell
/// (cropped to it), `gap` pixels apart on grey; a missing picture leaves
/// its cell empty. The sheet is tone-mapped already: write it with the
/// identity map ([`ToneMap::default`]).
pub fn contact_sheet(
    pictures: &[Option<(HdrImage, ToneMap)>],
    width: u32,
    height: u32,
    columns: u32,
    gap: u32,
) -> HdrImage {
    let columns = columns.min(pictures.len() as u32).max(1);
    let rows = (pictures.len() as u32).div_ceil(columns);
    let mut sheet = HdrImage::new(columns * width + (columns + 1) * gap, rows * height + (rows + 1) * gap);
    sheet.pixels_mut().fill(Vec3::splat(0.2));
    for (index, picture) in pictures.iter().enumerate() {
        let Some((image, tone_map)) = picture else { continue };
        let column = index as u32 % columns;
        let (x0, y0) = (gap + column * (width + gap), gap + (index as u32 / columns) * (height + gap));
        for y in 0..height.min(image.height()) {
            for x in 0..width.min(image.width()) {
                sheet.set(x0 + x, y0 + y, tone_map.apply(image.get(x, y)));
            }
        }
    }
    sheet
}

/// Channel `channel` (0, 1 or 2) of `counts` in false colour
/// ([`heat_colour`]), from 0 to `scale` (the channel's maximum, at least 1,
/// when `None`); returns the map, the scale used and the maximum.
pub fn heat_map(counts: &HdrImage, channel: usize, scale: Option<f32>) -> (HdrImage, f32, f32) {
    let maximum = counts.pixels().iter().map(|p| p[channel]).fold(0.0f32, f32::max);
    let scale = scale.unwrap_or(maximum.max(1.0));
    let pixels = counts.pixels().iter().map(|p| heat_colour(p[channel] / scale)).collect();
    let map = HdrImage::from_pixels(counts.width(), counts.height(), pixels).expect("one colour per pixel");
    (map, scale, maximum)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pictures_land_in_their_cells_and_counts_in_colour() {
        let red = HdrImage::from_pixels(2, 1, vec![Vec3::X; 2]).unwrap();
        let sheet = contact_sheet(
            &[Some((red.clone(), ToneMap::default())), None, Some((red, ToneMap::default()))],
            2,
            1,
            2,
            1,
        );
        assert_eq!((sheet.width(), sheet.height()), (7, 5));
        assert_eq!(sheet.get(1, 1), ToneMap::default().apply(Vec3::X));
        assert_eq!(sheet.get(4, 1), Vec3::splat(0.2), "the missing picture's cell stays empty");
        assert_eq!(sheet.get(1, 3), ToneMap::default().apply(Vec3::X));
        let counts = HdrImage::from_pixels(2, 1, vec![Vec3::new(0.0, 4.0, 0.0), Vec3::new(0.0, 8.0, 0.0)]).unwrap();
        let (map, scale, maximum) = heat_map(&counts, 1, None);
        assert_eq!((scale, maximum), (8.0, 8.0));
        assert_eq!((map.get(0, 0), map.get(1, 0)), (heat_colour(0.5), heat_colour(1.0)));
        assert_eq!(heat_map(&counts, 1, Some(16.0)).0.get(1, 0), heat_colour(0.5));
    }
}
