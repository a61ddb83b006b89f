//! HDR float RGB images and their output.
//!
//! Renderers accumulate linear radiance in an [`HdrImage`]; writing it picks
//! the format from the file's extension: `.exr` keeps the linear floats
//! (OpenEXR), `.png` applies an exposure, a tone map and the sRGB transfer
//! function and stores 8 bits per channel. Files are written to a temporary
//! name beside the target and renamed into place, so a failed write never
//! leaves a partial file or destroys an earlier good one.
//!
//! ```no_run
//! use rtgi_image::{HdrImage, ToneMap};
//! use rtgi_math::Vec3;
//!
//! let mut image = HdrImage::new(64, 32);
//! image.set(10, 5, Vec3::new(4.0, 1.0, 0.25));
//! image.write("out.png".as_ref(), &ToneMap::default())?;
//! image.write("out.exr".as_ref(), &ToneMap::default())?;
//! # Ok::<(), rtgi_image::ImageError>(())
//! ```

#![warn(missing_docs)]

// The README's examples are compiled and run as doctests.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;

mod atomic;
mod compare;
mod exposure;
mod floats;
mod sheet;
mod tonemap;
mod write;

pub use atomic::{unusable_folder, write_atomically, write_atomically_with};
pub use compare::{Difference, compare};
pub use exposure::{Legibility, auto_exposure, legibility};
pub use sheet::{contact_sheet, heat_map};
pub use tonemap::{ToneMap, ToneOperator, heat_colour, linear_to_srgb, srgb_to_linear};
pub use write::{ImageError, MAX_READ_PIXELS, OutputFormat, check_writable};

use rtgi_math::Vec3;

/// A width × height grid of linear RGB radiance, row by row from the top.
#[derive(Clone, Debug, PartialEq)]
pub struct HdrImage {
    width: u32,
    height: u32,
    pixels: Vec<Vec3>,
}

impl HdrImage {
    /// A black image.
    pub fn new(width: u32, height: u32) -> Self {
        Self { width, height, pixels: vec![Vec3::ZERO; width as usize * height as usize] }
    }

    /// An image from its pixels, row by row from the top; `None` if the count is not width × height.
    pub fn from_pixels(width: u32, height: u32, pixels: Vec<Vec3>) -> Option<Self> {
        (pixels.len() == width as usize * height as usize).then_some(Self { width, height, pixels })
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The pixels row by row from the top left, linear RGB.
    pub fn pixels(&self) -> &[Vec3] {
        &self.pixels
    }

    /// The pixels row by row from the top left, to change in place.
    pub fn pixels_mut(&mut self) -> &mut [Vec3] {
        &mut self.pixels
    }

    #[inline]
    /// The pixel in column `x` of row `y` (row 0 at the top); panics outside the image.
    pub fn get(&self, x: u32, y: u32) -> Vec3 {
        self.pixels[y as usize * self.width as usize + x as usize]
    }

    #[inline]
    /// Sets the pixel in column `x` of row `y` (row 0 at the top); panics outside the image.
    pub fn set(&mut self, x: u32, y: u32, value: Vec3) {
        self.pixels[y as usize * self.width as usize + x as usize] = value;
    }

    /// The mean of all pixels.
    pub fn mean(&self) -> Vec3 {
        let sum = self.pixels.iter().fold(rtgi_math::glam::DVec3::ZERO, |s, p| s + p.as_dvec3());
        (sum / self.pixels.len().max(1) as f64).as_vec3()
    }

    /// 8-bit sRGB bytes, RGB interleaved, after exposure and tone mapping.
    pub fn to_srgb8(&self, tone_map: &ToneMap) -> Vec<u8> {
        self.pixels
            .iter()
            .flat_map(|&p| {
                let mapped = tone_map.apply(p);
                [mapped.x, mapped.y, mapped.z].map(|c| (linear_to_srgb(c) * 255.0 + 0.5) as u8)
            })
            .collect()
    }
}
