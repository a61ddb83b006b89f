use std::fs::{self, File};
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::atomic::{temporary_path, write_atomically};
use crate::{HdrImage, ToneMap};

/// What can go wrong writing an image; every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    /// The file name ends in neither `.png` nor `.exr`.
    #[error("{path}: unsupported image format (use a .png or .exr file name)")]
    UnsupportedFormat {
        /// The file asked for.
        path: PathBuf,
    },
    /// The file could not be created, written or renamed into place.
    #[error("{path}: cannot write: {source}")]
    Io {
        /// The file being written.
        path: PathBuf,
        /// What the operating system said.
        source: std::io::Error,
    },
    /// The encoder refused the pixels.
    #[error("{path}: cannot encode: {message}")]
    Encode {
        /// The file being written.
        path: PathBuf,
        /// The encoder's message.
        message: String,
    },
    /// The file could not be read or decoded, or holds no usable image.
    #[error("{path}: cannot read image: {message}")]
    Read {
        /// The file being read.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
}

/// The file formats images are written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputFormat {
    /// OpenEXR, linear 32-bit float RGB.
    Exr,
    /// PNG, 8-bit sRGB after exposure and tone mapping.
    Png,
}

impl OutputFormat {
    /// The format a path's extension asks for (case-insensitive).
    pub fn from_path(path: &Path) -> Result<Self, ImageError> {
        let extension = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        match extension.as_deref() {
            Some("exr") => Ok(OutputFormat::Exr),
            Some("png") => Ok(OutputFormat::Png),
            _ => Err(ImageError::UnsupportedFormat { path: path.to_owned() }),
        }
    }
}

impl HdrImage {
    /// Writes the image in the format of `path`'s extension, atomically: the
    /// data goes to a temporary file beside `path`, which is renamed over
    /// `path` only once complete.
    pub fn write(&self, path: &Path, tone_map: &ToneMap) -> Result<(), ImageError> {
        let bytes = match OutputFormat::from_path(path)? {
            OutputFormat::Png => self.encode_png(path, tone_map)?,
            OutputFormat::Exr => self.encode_exr(path)?,
        };
        write_atomically(path, &bytes).map_err(|source| ImageError::Io { path: path.to_owned(), source })
    }

    fn encode_png(&self, path: &Path, tone_map: &ToneMap) -> Result<Vec<u8>, ImageError> {
        use image::ImageEncoder;
        let bytes = self.to_srgb8(tone_map);
        let mut encoded = Vec::new();
        image::codecs::png::PngEncoder::new(&mut encoded)
            .write_image(&bytes, self.width, self.height, image::ExtendedColorType::Rgb8)
            .map_err(|e| ImageError::Encode { path: path.to_owned(), message: e.to_string() })?;
        Ok(encoded)
    }

    fn encode_exr(&self, path: &Path) -> Result<Vec<u8>, ImageError> {
        use exr::prelude::*;
        let width = self.width as usize;
        let channels = SpecificChannels::rgb(|position: Vec2<usize>| {
            let p = self.pixels[position.y() * width + position.x()];
            (p.x, p.y, p.z)
        });
        let image = Image::from_channels((width, self.height as usize), channels);
        let mut encoded = std::io::Cursor::new(Vec::new());
        image.write().to_buffered(&mut encoded).map_err(|e| match e {
            exr::error::Error::Io(source) => ImageError::Io { path: path.to_owned(), source },
            other => ImageError::Encode { path: path.to_owned(), message: other.to_string() },
        })?;
        Ok(encoded.into_inner())
    }

    /// Reads an OpenEXR file's RGB channels (alpha ignored) as linear floats.
    ///
    /// Layers of more than [`MAX_READ_PIXELS`] pixels are refused before
    /// any pixel memory is allocated: a header of a few bytes can declare
    /// any size, and a 1 MB file claiming 50,000 × 50,000 pixels would
    /// otherwise ask for 30 GB.
    pub fn read_exr(path: &Path) -> Result<HdrImage, ImageError> {
        use exr::prelude::*;
        let read_error = |e: exr::error::Error| ImageError::Read { path: path.to_owned(), message: e.to_string() };
        let meta = exr::meta::MetaData::read_from_file(path, false).map_err(read_error)?;
        for header in &meta.headers {
            let (width, height) = (header.layer_size.width(), header.layer_size.height());
            if width.checked_mul(height).is_none_or(|pixels| pixels > MAX_READ_PIXELS) {
                return Err(ImageError::Read {
                    path: path.to_owned(),
                    message: format!(
                        "{width}x{height} pixels is more than the {MAX_READ_PIXELS} pixels rtgi reads (32768x16384)"
                    ),
                });
            }
        }
        let image = read_first_rgba_layer_from_file(
            path,
            |resolution, _| HdrImage::new(resolution.width() as u32, resolution.height() as u32),
            |image: &mut HdrImage, position, (r, g, b, _a): (f32, f32, f32, f32)| {
                image.set(position.x() as u32, position.y() as u32, rtgi_math::Vec3::new(r, g, b));
            },
        )
        .map_err(read_error)?;
        Ok(image.layer_data.channel_data.pixels)
    }
}

/// Most pixels [`HdrImage::read_exr`] reads from one layer: 32768 × 16384
/// (an environment map at the largest size in common use), 6 GiB of f32 RGB.
pub const MAX_READ_PIXELS: usize = 1 << 29;

/// Checks before a long render that `path` names a supported format in a
/// writable folder, by creating and removing a temporary file there.
pub fn check_writable(path: &Path) -> Result<OutputFormat, ImageError> {
    let format = OutputFormat::from_path(path)?;
    if path.is_dir() {
        return Err(ImageError::Io {
            path: path.to_owned(),
            source: std::io::Error::new(std::io::ErrorKind::IsADirectory, "is a directory"),
        });
    }
    if let Some(why) = crate::unusable_folder(path) {
        return Err(ImageError::Io {
            path: path.to_owned(),
            source: std::io::Error::new(std::io::ErrorKind::NotFound, why),
        });
    }
    let probe = temporary_path(path);
    let created = File::create(&probe).and_then(|mut f| f.write_all(b""));
    let _ = fs::remove_file(&probe);
    created.map_err(|source| ImageError::Io { path: path.to_owned(), source })?;
    Ok(format)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rtgi_math::Vec3;

    /// A path in `dir`, a temporary folder that is removed when the test ends.
    fn scratch(dir: &tempfile::TempDir, name: &str) -> PathBuf {
        dir.path().join(name)
    }

    fn gradient() -> HdrImage {
        let mut image = HdrImage::new(7, 3);
        for y in 0..3 {
            for x in 0..7 {
                image.set(x, y, Vec3::new(x as f32 * 0.5, y as f32, 100.0));
            }
        }
        image
    }

    #[test]
    fn exr_round_trips_exactly() {
        let dir = tempfile::tempdir().unwrap();
        let path = scratch(&dir, "round.exr");
        let image = gradient();
        image.write(&path, &ToneMap::default()).unwrap();
        assert_eq!(HdrImage::read_exr(&path).unwrap(), image);
    }

    #[test]
    fn png_is_written_with_srgb_values() {
        let dir = tempfile::tempdir().unwrap();
        let path = scratch(&dir, "gradient.png");
        gradient().write(&path, &ToneMap::default()).unwrap();
        let decoded = image::open(&path).unwrap().to_rgb8();
        assert_eq!(decoded.dimensions(), (7, 3));
        assert_eq!(decoded.get_pixel(0, 0).0, [0, 0, 255]);
        assert_eq!(decoded.get_pixel(2, 1).0, [255, 255, 255]);
        assert_eq!(decoded.get_pixel(1, 2).0[0], 188); // sRGB(0.5) = 0.735
    }

    #[test]
    fn unknown_extension_and_missing_folder_are_errors() {
        let dir = tempfile::tempdir().unwrap();
        let image = gradient();
        let err = image.write(&scratch(&dir, "x.bmp"), &ToneMap::default()).unwrap_err();
        assert!(err.to_string().contains("x.bmp"), "{err}");
        let missing = scratch(&dir, "no-such-folder").join("x.png");
        let err = check_writable(&missing).unwrap_err().to_string();
        assert!(err.ends_with("no-such-folder does not exist"), "{err}");
        assert!(image.write(&missing, &ToneMap::default()).is_err());
        // A file where the folder should be.
        std::fs::write(scratch(&dir, "a-file"), b"").unwrap();
        let err = check_writable(&scratch(&dir, "a-file").join("x.png")).unwrap_err().to_string();
        assert!(err.ends_with("a-file is not a folder"), "{err}");
        assert!(!missing.exists());
    }

    #[test]
    fn failed_write_keeps_the_old_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = scratch(&dir, "keep.png");
        gradient().write(&path, &ToneMap::default()).unwrap();
        let before = fs::read(&path).unwrap();
        // A zero-sized image cannot be encoded as PNG; the earlier file must survive.
        assert!(HdrImage::new(0, 0).write(&path, &ToneMap::default()).is_err());
        assert_eq!(fs::read(&path).unwrap(), before);
    }
}
