//! The file of an [`Accumulation`]: checkpoints of progressive renders and
//! the parts of split renders.
//!
//! Layout: the line `rtgi accumulation 1\n`; a little-endian `u32` length
//! and that many bytes of JSON (the [`RenderIdentity`], the rows and the
//! samples); the three fixed-point channel sums of every pixel of the
//! band, row by row, each as a zigzag LEB128 varint (most sums are far
//! smaller than 128 bits); and a little-endian `u64` FNV-1a of those sum
//! bytes, which catches a truncated or damaged file. Files are written
//! atomically ([`rtgi_image::write_atomically_with`]), so an interrupted
//! write never leaves half a checkpoint.

use std::fs::File;
use std::io::{BufReader, Read};
use std::ops::Range;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::accumulation::{Accumulation, MergeError, MergePlan, PartSpan, PixelSum};
use crate::identity::{Fnv, RenderIdentity};

const MAGIC: &[u8] = b"rtgi accumulation 1\n";

/// Longest header accepted: a real one is well under a kilobyte.
const MAX_HEADER: u32 = 1 << 20;

/// Why an accumulation file cannot be read or written.
#[derive(Debug, thiserror::Error)]
pub enum AccumulationFileError {
    /// The file could not be read, written or renamed into place.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        source: std::io::Error,
    },
    /// The file is not an accumulation: bad header, truncated, or a wrong checksum.
    #[error("{path}: not an rtgi accumulation file: {message}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
}

#[derive(Serialize, Deserialize)]
struct Header {
    identity: RenderIdentity,
    rows: Range<u32>,
    samples: Range<u32>,
}

impl Accumulation {
    /// Writes the accumulation to `path`, atomically.
    pub fn write(&self, path: &Path) -> Result<(), AccumulationFileError> {
        let header = Header { identity: self.identity().clone(), rows: self.rows(), samples: self.samples() };
        let header = serde_json::to_vec(&header).expect("the header is plain data");
        rtgi_image::write_atomically_with(path, |out| {
            out.write_all(MAGIC)?;
            out.write_all(&(header.len() as u32).to_le_bytes())?;
            out.write_all(&header)?;
            let mut checksum = Fnv::new();
            let mut bytes = Vec::with_capacity(3 * 19);
            for sum in self.sums() {
                bytes.clear();
                for &channel in sum {
                    encode(channel, &mut bytes);
                }
                checksum.update(bytes.iter().copied());
                out.write_all(&bytes)?;
            }
            out.write_all(&checksum.0.to_le_bytes())
        })
        .map_err(|source| AccumulationFileError::Io { path: path.to_owned(), source })
    }

    /// Reads an accumulation written by [`Accumulation::write`].
    pub fn read(path: &Path) -> Result<Accumulation, AccumulationFileError> {
        let mut file = PartFile::open(path)?;
        let pixels = file.pixels();
        let mut sums: Vec<PixelSum> = Vec::new();
        sums.try_reserve_exact(pixels as usize)
            .map_err(|_| file.invalid(format!("{pixels} pixels do not fit in memory")))?;
        file.read_sums(|_, sum| sums.push(sum))?;
        let PartSpan { identity, rows, samples } = file.span;
        Accumulation::from_parts(identity, rows, samples, sums)
            .map_err(|message| AccumulationFileError::Invalid { path: path.to_owned(), message })
    }

    /// [`Accumulation::merge`] of the parts in these files, reading one
    /// part's sums at a time: the headers are checked first, then each
    /// file's sums are added straight into the result, so memory is the
    /// result's, whatever the number of parts.
    pub fn merge_files(paths: &[PathBuf]) -> Result<Accumulation, MergeFilesError> {
        let spans = paths.iter().map(|path| PartSpan::read(path)).collect::<Result<Vec<_>, _>>()?;
        let plan = MergePlan::new(&spans).map_err(|error| MergeFilesError::Merge { error, paths: paths.to_vec() })?;
        let mut merged = plan.empty();
        for (path, offset) in paths.iter().zip(&plan.offsets) {
            let mut file = PartFile::open(path)?;
            file.read_sums(|pixel, sum| merged.add_to_pixel(offset + pixel, &sum))?;
        }
        Ok(merged)
    }
}

/// Why the parts in files cannot be merged.
#[derive(Debug, thiserror::Error)]
pub enum MergeFilesError {
    /// A part could not be read.
    #[error(transparent)]
    File(#[from] AccumulationFileError),
    /// The parts do not make one render; the message names the parts by their files.
    #[error("cannot merge: {}", error.naming(&|part| paths[part].display().to_string()))]
    Merge {
        /// Why, with the parts numbered in the order of `paths`.
        error: MergeError,
        /// The parts' files.
        paths: Vec<PathBuf>,
    },
}

impl PartSpan {
    /// What the accumulation file at `path` holds, from its header alone.
    pub fn read(path: &Path) -> Result<PartSpan, AccumulationFileError> {
        Ok(PartFile::open(path)?.span)
    }
}

/// An accumulation file whose header has been read and checked, positioned at its sums.
struct PartFile {
    path: PathBuf,
    input: BufReader<File>,
    span: PartSpan,
}

impl PartFile {
    fn open(path: &Path) -> Result<PartFile, AccumulationFileError> {
        let io = |source| AccumulationFileError::Io { path: path.to_owned(), source };
        let invalid = |message: String| AccumulationFileError::Invalid { path: path.to_owned(), message };
        let mut input = BufReader::new(File::open(path).map_err(io)?);
        let mut magic = [0u8; MAGIC.len()];
        read_exact(&mut input, &mut magic).map_err(|e| invalid(format!("{e} in its first line")))?;
        if magic != MAGIC {
            return Err(invalid("it does not start with 'rtgi accumulation 1'".into()));
        }
        let mut length = [0u8; 4];
        read_exact(&mut input, &mut length).map_err(|e| invalid(format!("{e} in the header's length")))?;
        let length = u32::from_le_bytes(length);
        if length > MAX_HEADER {
            return Err(invalid(format!("a header of {length} bytes (at most {MAX_HEADER})")));
        }
        let mut header = vec![0u8; length as usize];
        read_exact(&mut input, &mut header).map_err(|e| invalid(format!("{e} in the header")))?;
        let header: Header =
            serde_json::from_slice(&header).map_err(|e| invalid(format!("its header is not valid: {e}")))?;
        let Header { identity, rows, samples } = header;
        if rows.start > rows.end || rows.end > identity.height {
            return Err(invalid(format!("rows {rows:?} outside an image of height {}", identity.height)));
        }
        if samples.start > samples.end || samples.end > identity.samples_per_pixel {
            return Err(invalid(format!("samples {samples:?} outside 0..{}", identity.samples_per_pixel)));
        }
        let file = PartFile { path: path.to_owned(), input, span: PartSpan { identity, rows, samples } };
        let pixels = file.pixels();
        // Every pixel takes at least three bytes: a file shorter than that is
        // refused before its sums are allocated.
        if let Ok(metadata) = std::fs::metadata(path)
            && metadata.len() < pixels.saturating_mul(3)
        {
            return Err(invalid(format!("{} bytes cannot hold {pixels} pixels", metadata.len())));
        }
        Ok(file)
    }

    fn pixels(&self) -> u64 {
        let rows = &self.span.rows;
        (rows.end - rows.start) as u64 * self.span.identity.width as u64
    }

    fn invalid(&self, message: String) -> AccumulationFileError {
        AccumulationFileError::Invalid { path: self.path.clone(), message }
    }

    /// Reads every pixel's sums in order, giving each to `pixel` with its
    /// index, then checks the checksum and the end of the file. An error
    /// may come after some pixels were given.
    fn read_sums(&mut self, mut pixel: impl FnMut(usize, PixelSum)) -> Result<(), AccumulationFileError> {
        let pixels = self.pixels();
        let mut checksum = Fnv::new();
        for index in 0..pixels {
            let mut sum = [0i128; 3];
            for channel in &mut sum {
                *channel = decode(&mut self.input, &mut checksum)
                    .map_err(|e| self.invalid(format!("pixel {index} of {pixels}: {e}")))?;
            }
            pixel(index as usize, sum);
        }
        let mut stored = [0u8; 8];
        read_exact(&mut self.input, &mut stored).map_err(|e| self.invalid(format!("{e} in the checksum")))?;
        if u64::from_le_bytes(stored) != checksum.0 {
            return Err(self.invalid("the checksum does not match: the file is damaged".into()));
        }
        let extra = self
            .input
            .read(&mut [0u8; 1])
            .map_err(|source| AccumulationFileError::Io { path: self.path.clone(), source })?;
        if extra != 0 {
            return Err(self.invalid("there are bytes after the checksum".into()));
        }
        Ok(())
    }
}

/// `read_exact`, with an end of file said in words.
fn read_exact(input: &mut impl Read, buffer: &mut [u8]) -> Result<(), String> {
    input.read_exact(buffer).map_err(|e| match e.kind() {
        std::io::ErrorKind::UnexpectedEof => "the file ends early".to_owned(),
        _ => e.to_string(),
    })
}

/// Appends `value` as a zigzag LEB128 varint.
fn encode(value: i128, out: &mut Vec<u8>) {
    let mut zigzag = ((value << 1) ^ (value >> 127)) as u128;
    loop {
        let byte = (zigzag & 0x7f) as u8;
        zigzag >>= 7;
        if zigzag == 0 {
            out.push(byte);
            return;
        }
        out.push(byte | 0x80);
    }
}

/// Reads a zigzag LEB128 varint, adding its bytes to `checksum`.
fn decode(input: &mut impl Read, checksum: &mut Fnv) -> Result<i128, String> {
    let mut zigzag = 0u128;
    for shift in (0..128).step_by(7) {
        let mut byte = [0u8; 1];
        read_exact(input, &mut byte)?;
        checksum.update(byte);
        let bits = (byte[0] & 0x7f) as u128;
        if shift == 126 && bits > 0b11 {
            return Err("a sum longer than 128 bits".into());
        }
        zigzag |= bits << shift;
        if byte[0] & 0x80 == 0 {
            return Ok(((zigzag >> 1) as i128) ^ -((zigzag & 1) as i128));
        }
    }
    Err("a sum longer than 128 bits".into())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A path in `dir`, a temporary folder that is removed when the test ends.
    fn scratch(dir: &tempfile::TempDir, name: &str) -> PathBuf {
        dir.path().join(name)
    }

    #[test]
    fn varints_round_trip_the_extremes() {
        for value in [0i128, 1, -1, 63, -64, 64, 1 << 100, -(1 << 100), i128::MAX, i128::MIN] {
            let mut bytes = Vec::new();
            encode(value, &mut bytes);
            assert!(bytes.len() <= 19);
            let decoded = decode(&mut bytes.as_slice(), &mut Fnv::new()).unwrap();
            assert_eq!(decoded, value);
        }
        let too_long = [0xffu8; 19];
        assert!(decode(&mut too_long.as_slice(), &mut Fnv::new()).is_err());
    }

    #[test]
    fn files_round_trip_and_damage_is_found() {
        let dir = tempfile::tempdir().unwrap();
        let identity = RenderIdentity::for_tests(3, 5, 8);
        let sums: Vec<PixelSum> = (0..6).map(|i| [i * 1_000_000_007, -i, (i << 90) + 3]).collect();
        let accumulation = Accumulation::from_parts(identity, 2..4, 0..5, sums).unwrap();
        let path = scratch(&dir, "round-trip.accum");
        accumulation.write(&path).unwrap();
        assert_eq!(Accumulation::read(&path).unwrap(), accumulation);

        let bytes = std::fs::read(&path).unwrap();
        let damaged = scratch(&dir, "damaged.accum");
        let mut flipped = bytes.clone();
        let last = flipped.len() - 9;
        flipped[last] ^= 1;
        std::fs::write(&damaged, &flipped).unwrap();
        let error = Accumulation::read(&damaged).unwrap_err().to_string();
        assert!(error.contains("damaged") || error.contains("pixel"), "{error}");
        std::fs::write(&damaged, &bytes[..bytes.len() - 3]).unwrap();
        let error = Accumulation::read(&damaged).unwrap_err().to_string();
        assert!(error.contains("ends early"), "{error}");
        std::fs::write(&damaged, b"P6 not this").unwrap();
        let error = Accumulation::read(&damaged).unwrap_err().to_string();
        assert!(error.contains("not an rtgi accumulation file"), "{error}");
    }

    #[test]
    fn merging_files_streams_to_the_bits_of_merging_in_memory() {
        let dir = tempfile::tempdir().unwrap();
        let identity = RenderIdentity::for_tests(3, 6, 12);
        let part = |rows: Range<u32>, samples: Range<u32>, seed: i128| {
            let pixels = (rows.end - rows.start) as i128 * 3;
            let sums = (0..pixels).map(|i| [i * seed, -(i << 70) + seed, seed << 100]).collect();
            Accumulation::from_parts(identity.clone(), rows, samples, sums).unwrap()
        };
        let parts = vec![part(3..6, 4..12, 5), part(0..3, 0..7, 1), part(3..6, 0..4, 2), part(0..3, 7..12, 3)];
        let paths: Vec<PathBuf> = (0..parts.len()).map(|i| scratch(&dir, &format!("stream-{i}.accum"))).collect();
        for (part, path) in parts.iter().zip(&paths) {
            part.write(path).unwrap();
        }
        let streamed = Accumulation::merge_files(&paths).unwrap();
        assert_eq!(streamed, Accumulation::merge(parts).unwrap());
        assert!(streamed.is_complete());
        // The headers are checked before any sums are read: an overlap is refused as in memory.
        let overlap = Accumulation::merge_files(&[paths[0].clone(), paths[0].clone()]).unwrap_err();
        assert!(matches!(overlap, MergeFilesError::Merge { error: MergeError::Overlap { .. }, .. }), "{overlap:?}");
        // A damaged part fails the merge, naming the file.
        let bytes = std::fs::read(&paths[2]).unwrap();
        std::fs::write(&paths[2], &bytes[..bytes.len() - 1]).unwrap();
        let damaged = Accumulation::merge_files(&paths).unwrap_err().to_string();
        assert!(damaged.contains("stream-2.accum"), "{damaged}");
    }
}
