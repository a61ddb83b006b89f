//! The raw float images of the course framework this toolkit comes from
//! (its `.floats` sky files): a little-endian 32-bit width and height, then
//! width × height RGB triples of little-endian 32-bit floats, row by row
//! from the top. No header names the format, so the sizes are checked
//! against the file's length before anything is allocated.

use std::path::Path;

use rtgi_math::Vec3;

use crate::{HdrImage, ImageError, MAX_READ_PIXELS};

impl HdrImage {
    /// Reads a `.floats` file (see the module's documentation).
    pub fn read_floats(path: &Path) -> Result<HdrImage, ImageError> {
        let bytes =
            std::fs::read(path).map_err(|e| ImageError::Read { path: path.to_owned(), message: e.to_string() })?;
        Self::decode_floats(&bytes).map_err(|message| ImageError::Read { path: path.to_owned(), message })
    }

    /// Decodes the bytes of a `.floats` file.
    pub fn decode_floats(bytes: &[u8]) -> Result<HdrImage, String> {
        let int = |at: usize| bytes.get(at..at + 4).map(|b| i32::from_le_bytes([b[0], b[1], b[2], b[3]]));
        let (Some(width), Some(height)) = (int(0), int(4)) else {
            return Err(format!("{} bytes: too short for a .floats image (width and height take 8)", bytes.len()));
        };
        if width <= 0 || height <= 0 {
            return Err(format!("width {width} and height {height}: both must be positive"));
        }
        let pixels = width as usize * height as usize;
        if pixels > MAX_READ_PIXELS {
            return Err(format!("{width}x{height} pixels is more than the {MAX_READ_PIXELS} pixels rtgi reads"));
        }
        let expected = 8 + pixels * 12;
        if bytes.len() != expected {
            return Err(format!(
                "{width}x{height} RGB floats take {expected} bytes with the 8 of the sizes, the file has {}",
                bytes.len()
            ));
        }
        let float = |at: usize| f32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
        let pixels =
            (0..pixels).map(|i| 8 + 12 * i).map(|at| Vec3::new(float(at), float(at + 4), float(at + 8))).collect();
        Ok(HdrImage::from_pixels(width as u32, height as u32, pixels).expect("width × height pixels"))
    }

    /// The bytes of this image as a `.floats` file.
    pub fn encode_floats(&self) -> Vec<u8> {
        let mut bytes = Vec::with_capacity(8 + self.pixels().len() * 12);
        bytes.extend_from_slice(&(self.width() as i32).to_le_bytes());
        bytes.extend_from_slice(&(self.height() as i32).to_le_bytes());
        for pixel in self.pixels() {
            for channel in pixel.to_array() {
                bytes.extend_from_slice(&channel.to_le_bytes());
            }
        }
        bytes
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_and_refuses_wrong_sizes() {
        let mut image = HdrImage::new(3, 2);
        image.set(2, 1, Vec3::new(1.5, 2.0, 0.25));
        image.set(0, 0, Vec3::new(7.0, 0.0, 3.0));
        let bytes = image.encode_floats();
        assert_eq!(bytes.len(), 8 + 6 * 12);
        assert_eq!(HdrImage::decode_floats(&bytes).unwrap(), image);
        let error = HdrImage::decode_floats(&bytes[..bytes.len() - 4]).unwrap_err();
        assert!(error.contains("take 80 bytes") && error.contains("has 76"), "{error}");
        assert!(HdrImage::decode_floats(&bytes[..6]).unwrap_err().contains("too short"));
        let mut negative = bytes.clone();
        negative[0..4].copy_from_slice(&(-3i32).to_le_bytes());
        assert!(HdrImage::decode_floats(&negative).unwrap_err().contains("must be positive"));
    }
}
