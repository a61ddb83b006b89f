//! Binary ray and hit files: rays in, hits out, to trace batches of rays
//! from other programs and to compare the answers with other ray tracers.
//!
//! Both files are little-endian, without a header, so that any language
//! writes and reads them with a cast:
//!
//! - a **ray** is [`RAY_BYTES`] bytes, 8 × `f32`: origin x y z, direction
//!   x y z, `t_min`, `t_max`;
//! - a **hit** is [`HIT_BYTES`] bytes: `t` (`f32`; `+inf` for a miss),
//!   triangle (`u32`; [`MISS`] for a miss), `beta` (`f32`), `gamma` (`f32`).
//!   An any-hit answer has triangle 0 when the ray is occluded and [`MISS`]
//!   when not, and `t`, `beta` and `gamma` 0.
//!
//! A [`RayReader`] reads rays a chunk at a time from any [`Read`], so a file
//! of any size, or a stream, is traced in bounded memory, and checks every
//! record ([`decode_ray`]); a [`HitWriter`] writes the answers to any
//! [`Write`], and a [`RayWriter`] writes rays.
//!
//! ```
//! use rtgi_accel::ray_file::{HitWriter, RayReader, RayWriter};
//! use rtgi_accel::{Accel, AccelKind, BuildParams, Ray, Vec3};
//!
//! let triangles = [[Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)]];
//! let accel = AccelKind::Linear.build(&triangles, &BuildParams::default());
//!
//! let mut rays = RayWriter::new(Vec::new());
//! rays.write_rays(&[Ray::new(Vec3::new(0.0, 0.0, -2.0), Vec3::Z), Ray::new(Vec3::ZERO, Vec3::X)]).unwrap();
//! let bytes = rays.into_inner();
//!
//! let mut reader = RayReader::new(bytes.as_slice(), 1024);
//! let mut hits = HitWriter::new(Vec::new());
//! let mut chunk = Vec::new();
//! while reader.next_chunk(&mut chunk).unwrap() {
//!     let answers: Vec<_> = chunk.iter().map(|ray| accel.intersect(ray)).collect();
//!     hits.write_closest(&answers).unwrap();
//! }
//! let hits = hits.into_inner();
//! assert_eq!(hits.len(), 2 * 16);
//! assert_eq!(hits[0..4], 2.0f32.to_le_bytes()); // the first ray hits at t = 2
//! assert_eq!(hits[20..24], u32::MAX.to_le_bytes()); // the second misses
//! ```

use std::io::{self, ErrorKind, Read, Write};

use rtgi_math::{Ray, Vec3};

use crate::Hit;

/// Bytes of one ray in a ray file: 8 little-endian `f32`.
pub const RAY_BYTES: usize = 32;

/// Bytes of one hit in a hit file: `t`, triangle, `beta`, `gamma`.
pub const HIT_BYTES: usize = 16;

/// The triangle index of a miss in a hit file.
pub const MISS: u32 = u32::MAX;

/// Why a ray file cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum RayFileError {
    /// Reading failed.
    #[error("cannot read")]
    Io(#[from] io::Error),
    /// The file ends inside a record: its size is no multiple of
    /// [`RAY_BYTES`]. A stream's size is known only at its end, so this is
    /// found there.
    #[error(
        "not a ray file: its size, {bytes} bytes, is not a multiple of {RAY_BYTES} \
         (a ray is 8 little-endian f32: origin, direction, t_min, t_max): \
         the last ray, ray {}, is cut off after {} of its bytes",
        .bytes / RAY_BYTES as u64,
        .bytes % RAY_BYTES as u64
    )]
    PartialRecord {
        /// The size of the whole file, in bytes.
        bytes: u64,
    },
    /// A record holds no valid ray.
    #[error(
        "not a ray file: ray {index} (bytes {} to {}) is not a valid ray: {problem}",
        .index * RAY_BYTES as u64,
        (.index + 1) * RAY_BYTES as u64 - 1
    )]
    InvalidRay {
        /// The ray's index in the file, from 0.
        index: u64,
        /// What is wrong with it.
        problem: InvalidRay,
    },
}

/// What makes a record no ray: a ray that could only answer nonsense. An
/// empty range (`t_min > t_max`) is a ray that misses, and is valid.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum InvalidRay {
    /// The origin has a NaN or infinite coordinate.
    #[error("its origin ({}, {}, {}) is not finite", .0.x, .0.y, .0.z)]
    Origin(Vec3),
    /// The direction has a NaN or infinite component.
    #[error("its direction ({}, {}, {}) is not finite", .0.x, .0.y, .0.z)]
    Direction(Vec3),
    /// The direction is zero: the ray points nowhere.
    #[error("its direction is zero")]
    ZeroDirection,
    /// `t_min` or `t_max` is NaN.
    #[error("its range [{t_min}, {t_max}] is not a number")]
    Range {
        /// The start of the range.
        t_min: f32,
        /// The end of the range.
        t_max: f32,
    },
}

/// The rays in a ray file of `bytes` bytes, or [`RayFileError::PartialRecord`]
/// when it ends inside a record: a regular file can be refused by its size
/// before any work.
pub fn ray_count(bytes: u64) -> Result<u64, RayFileError> {
    if bytes.is_multiple_of(RAY_BYTES as u64) {
        Ok(bytes / RAY_BYTES as u64)
    } else {
        Err(RayFileError::PartialRecord { bytes })
    }
}

/// The record of `ray`. Any ray is encoded, valid or not, so that
/// refusals can be tested.
pub fn encode_ray(ray: &Ray) -> [u8; RAY_BYTES] {
    let numbers = ray.origin.to_array().into_iter().chain(ray.direction.to_array()).chain([ray.t_min, ray.t_max]);
    let mut out = [0u8; RAY_BYTES];
    for (bytes, number) in out.chunks_exact_mut(4).zip(numbers) {
        bytes.copy_from_slice(&number.to_le_bytes());
    }
    out
}

/// The ray in one record, or what makes it no ray ([`InvalidRay`]).
pub fn decode_ray(record: &[u8; RAY_BYTES]) -> Result<Ray, InvalidRay> {
    let f: [f32; 8] = std::array::from_fn(|i| f32::from_le_bytes(word(record, i)));
    let ray = Ray::with_range(Vec3::new(f[0], f[1], f[2]), Vec3::new(f[3], f[4], f[5]), f[6], f[7]);
    if !ray.origin.is_finite() {
        return Err(InvalidRay::Origin(ray.origin));
    }
    if !ray.direction.is_finite() {
        return Err(InvalidRay::Direction(ray.direction));
    }
    if ray.direction == Vec3::ZERO {
        return Err(InvalidRay::ZeroDirection);
    }
    if ray.t_min.is_nan() || ray.t_max.is_nan() {
        return Err(InvalidRay::Range { t_min: ray.t_min, t_max: ray.t_max });
    }
    Ok(ray)
}

/// The record of a closest-hit answer: the hit, or `+inf` and [`MISS`].
pub fn encode_hit(hit: Option<&Hit>) -> [u8; HIT_BYTES] {
    match hit {
        Some(h) => hit_record(h.t, h.triangle, h.beta, h.gamma),
        None => hit_record(f32::INFINITY, MISS, 0.0, 0.0),
    }
}

/// The record of an any-hit answer: triangle 0 when occluded, [`MISS`]
/// when not, and the numbers 0 (an any-hit query finds no closest hit).
pub fn encode_occluded(occluded: bool) -> [u8; HIT_BYTES] {
    hit_record(0.0, if occluded { 0 } else { MISS }, 0.0, 0.0)
}

/// The hit in one record, or `None` for a miss (triangle [`MISS`]). In a
/// file of any-hit answers, a hit is triangle 0 with `t` 0: occluded.
pub fn decode_hit(record: &[u8; HIT_BYTES]) -> Option<Hit> {
    let triangle = u32::from_le_bytes(word(record, 1));
    (triangle != MISS).then(|| Hit {
        t: f32::from_le_bytes(word(record, 0)),
        triangle,
        beta: f32::from_le_bytes(word(record, 2)),
        gamma: f32::from_le_bytes(word(record, 3)),
    })
}

/// The `i`th four bytes of a record.
fn word(record: &[u8], i: usize) -> [u8; 4] {
    [record[4 * i], record[4 * i + 1], record[4 * i + 2], record[4 * i + 3]]
}

fn hit_record(t: f32, triangle: u32, beta: f32, gamma: f32) -> [u8; HIT_BYTES] {
    let mut out = [0u8; HIT_BYTES];
    out[0..4].copy_from_slice(&t.to_le_bytes());
    out[4..8].copy_from_slice(&triangle.to_le_bytes());
    out[8..12].copy_from_slice(&beta.to_le_bytes());
    out[12..16].copy_from_slice(&gamma.to_le_bytes());
    out
}

/// Reads a ray file from any [`Read`] a chunk of rays at a time, checking
/// every record: memory stays bounded whatever the size, and a stream that
/// is no ray file (`/dev/zero`) is refused at its first chunk, not read to
/// its end.
#[derive(Debug)]
pub struct RayReader<R> {
    source: R,
    /// Records read so far: the index of the next one.
    records: u64,
    /// One chunk of records; always read whole, except at the end.
    buffer: Vec<u8>,
}

impl<R: Read> RayReader<R> {
    /// A reader of `source` that returns up to `chunk_rays` rays at a time.
    ///
    /// # Panics
    /// If `chunk_rays` is 0.
    pub fn new(source: R, chunk_rays: usize) -> Self {
        assert!(chunk_rays > 0, "a chunk holds at least one ray");
        RayReader { source, records: 0, buffer: vec![0; chunk_rays * RAY_BYTES] }
    }

    /// Replaces `rays` with the next chunk of the file (as many rays as a
    /// chunk holds, fewer only at the end); false at its end, with `rays`
    /// empty. A file that ends inside a record, or a record that is no ray,
    /// is an error, and so are the records before it in the same chunk:
    /// none of them is returned.
    pub fn next_chunk(&mut self, rays: &mut Vec<Ray>) -> Result<bool, RayFileError> {
        rays.clear();
        let mut filled = 0;
        while filled < self.buffer.len() {
            match self.source.read(&mut self.buffer[filled..]) {
                Ok(0) => break,
                Ok(n) => filled += n,
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) => return Err(e.into()),
            }
        }
        // Only at the end of the file can the buffer hold part of a record.
        ray_count(self.records * RAY_BYTES as u64 + filled as u64)?;
        for record in self.buffer[..filled].chunks_exact(RAY_BYTES) {
            let record = record.try_into().expect("chunks of RAY_BYTES");
            let ray = decode_ray(record).map_err(|problem| {
                rays.clear();
                RayFileError::InvalidRay { index: self.records, problem }
            })?;
            rays.push(ray);
            self.records += 1;
        }
        Ok(!rays.is_empty())
    }

    /// The rays read so far, over every chunk.
    pub fn rays_read(&self) -> u64 {
        self.records
    }
}

/// Records encoded at a time before they are written: few writes to an
/// unbuffered writer, and a scratch buffer of bounded size however many
/// records one call writes.
const WRITE_RECORDS: usize = 4096;

/// Writes rays to any [`Write`], in the format [`RayReader`] reads.
#[derive(Debug)]
pub struct RayWriter<W> {
    out: W,
    /// Up to [`WRITE_RECORDS`] records, encoded before they are written.
    scratch: Vec<u8>,
}

impl<W: Write> RayWriter<W> {
    /// A writer of rays to `out`.
    pub fn new(out: W) -> Self {
        RayWriter { out, scratch: Vec::new() }
    }

    /// Writes the records of `rays`, in order.
    pub fn write_rays(&mut self, rays: &[Ray]) -> io::Result<()> {
        for part in rays.chunks(WRITE_RECORDS) {
            self.scratch.clear();
            self.scratch.extend(part.iter().flat_map(encode_ray));
            self.out.write_all(&self.scratch)?;
        }
        Ok(())
    }

    /// The writer given to [`RayWriter::new`], with everything written.
    pub fn into_inner(self) -> W {
        self.out
    }
}

/// Writes the answers of traced rays to any [`Write`]: one record per ray,
/// in the order of the rays.
#[derive(Debug)]
pub struct HitWriter<W> {
    out: W,
    /// Up to [`WRITE_RECORDS`] records, encoded before they are written.
    scratch: Vec<u8>,
}

impl<W: Write> HitWriter<W> {
    /// A writer of hits to `out`.
    pub fn new(out: W) -> Self {
        HitWriter { out, scratch: Vec::new() }
    }

    /// Writes closest-hit answers ([`encode_hit`]).
    pub fn write_closest(&mut self, hits: &[Option<Hit>]) -> io::Result<()> {
        for part in hits.chunks(WRITE_RECORDS) {
            self.scratch.clear();
            self.scratch.extend(part.iter().flat_map(|hit| encode_hit(hit.as_ref())));
            self.out.write_all(&self.scratch)?;
        }
        Ok(())
    }

    /// Writes any-hit answers ([`encode_occluded`]).
    pub fn write_occluded(&mut self, occluded: &[bool]) -> io::Result<()> {
        for part in occluded.chunks(WRITE_RECORDS) {
            self.scratch.clear();
            self.scratch.extend(part.iter().flat_map(|&o| encode_occluded(o)));
            self.out.write_all(&self.scratch)?;
        }
        Ok(())
    }

    /// The writer given to [`HitWriter::new`], with everything written.
    pub fn into_inner(self) -> W {
        self.out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray(i: usize) -> Ray {
        let x = i as f32;
        Ray::with_range(Vec3::new(x, -x, 0.5), Vec3::new(1.0, x, -2.0), 0.25 * x, 100.0 + x)
    }

    fn file_of(rays: &[Ray]) -> Vec<u8> {
        let mut writer = RayWriter::new(Vec::new());
        writer.write_rays(rays).unwrap();
        writer.into_inner()
    }

    /// Reads `source` with chunks of `chunk_rays`, returning the chunks' sizes and the rays.
    fn read_all<R: Read>(source: R, chunk_rays: usize) -> Result<(Vec<usize>, Vec<Ray>), RayFileError> {
        let mut reader = RayReader::new(source, chunk_rays);
        let (mut sizes, mut all, mut chunk) = (Vec::new(), Vec::new(), Vec::new());
        while reader.next_chunk(&mut chunk)? {
            sizes.push(chunk.len());
            all.extend_from_slice(&chunk);
        }
        assert!(chunk.is_empty());
        assert_eq!(reader.rays_read(), all.len() as u64);
        Ok((sizes, all))
    }

    /// A source that gives at most `step` bytes a read, and is interrupted
    /// between reads: records cross the reads' boundaries.
    struct Trickle<'a> {
        bytes: &'a [u8],
        step: usize,
        interrupt: bool,
    }

    impl Read for Trickle<'_> {
        fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
            self.interrupt = !self.interrupt;
            if self.interrupt {
                return Err(ErrorKind::Interrupted.into());
            }
            let n = self.step.min(buf.len()).min(self.bytes.len());
            buf[..n].copy_from_slice(&self.bytes[..n]);
            self.bytes = &self.bytes[n..];
            Ok(n)
        }
    }

    fn bits(ray: &Ray) -> [u32; 8] {
        let f = [ray.origin.x, ray.origin.y, ray.origin.z, ray.direction.x, ray.direction.y, ray.direction.z];
        let mut out = [0; 8];
        for (o, v) in out.iter_mut().zip(f.into_iter().chain([ray.t_min, ray.t_max])) {
            *o = v.to_bits();
        }
        out
    }

    #[test]
    fn rays_round_trip_bit_for_bit() {
        let mut rays: Vec<Ray> = (0..10).map(ray).collect();
        // Signed zeros, an infinite and an empty range are rays too.
        rays.push(Ray::with_range(Vec3::new(-0.0, 0.0, -0.0), Vec3::new(0.0, -0.0, 1.0), -0.0, f32::INFINITY));
        rays.push(Ray::with_range(Vec3::ONE, Vec3::X, 5.0, 1.0));
        let (_, back) = read_all(file_of(&rays).as_slice(), 4).unwrap();
        assert_eq!(back.iter().map(bits).collect::<Vec<_>>(), rays.iter().map(bits).collect::<Vec<_>>());
        assert_eq!(encode_ray(&rays[3]).as_slice(), &file_of(&rays)[3 * RAY_BYTES..4 * RAY_BYTES]);
    }

    #[test]
    fn the_ray_layout_is_origin_direction_and_range() {
        let record = encode_ray(&Ray::with_range(Vec3::new(1.0, 2.0, 3.0), Vec3::new(4.0, 5.0, 6.0), 7.0, 8.0));
        let numbers: Vec<f32> = record.chunks_exact(4).map(|w| f32::from_le_bytes(w.try_into().unwrap())).collect();
        assert_eq!(numbers, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0]);
    }

    #[test]
    fn hits_round_trip_and_misses_are_infinite() {
        let hit = Hit { t: 2.5, triangle: 7, beta: 0.25, gamma: -0.0 };
        let record = encode_hit(Some(&hit));
        assert_eq!(
            decode_hit(&record).map(|h| (h.t, h.triangle, h.beta, h.gamma.to_bits())),
            Some((2.5, 7, 0.25, (-0.0f32).to_bits()))
        );
        let miss = encode_hit(None);
        assert_eq!(miss[0..4], f32::INFINITY.to_le_bytes());
        assert_eq!(miss[4..8], MISS.to_le_bytes());
        assert_eq!(miss[8..], [0; 8]);
        assert_eq!(decode_hit(&miss), None);
    }

    #[test]
    fn any_hit_answers_are_triangle_zero_or_a_miss_with_zero_numbers() {
        let mut writer = HitWriter::new(Vec::new());
        writer.write_occluded(&[true, false]).unwrap();
        let bytes = writer.into_inner();
        let mut occluded = [0u8; HIT_BYTES];
        occluded[4..8].copy_from_slice(&0u32.to_le_bytes());
        let mut clear = [0u8; HIT_BYTES];
        clear[4..8].copy_from_slice(&MISS.to_le_bytes());
        assert_eq!(bytes, [occluded, clear].concat());
        assert_eq!(decode_hit(&occluded).map(|h| h.triangle), Some(0));
    }

    #[test]
    fn the_hit_writer_writes_one_record_per_ray_in_order() {
        let hits = [Some(Hit { t: 1.0, triangle: 3, beta: 0.5, gamma: 0.25 }), None];
        let mut writer = HitWriter::new(Vec::new());
        writer.write_closest(&hits).unwrap();
        writer.write_closest(&hits[..1]).unwrap();
        let bytes = writer.into_inner();
        assert_eq!(bytes, [encode_hit(hits[0].as_ref()), encode_hit(None), encode_hit(hits[0].as_ref())].concat());
    }

    #[test]
    fn long_slices_are_written_in_parts_with_the_same_bytes() {
        let rays: Vec<Ray> = (0..2 * WRITE_RECORDS + 3).map(ray).collect();
        let bytes = file_of(&rays);
        assert_eq!(bytes, rays.iter().flat_map(encode_ray).collect::<Vec<u8>>());
        let hits: Vec<Option<Hit>> = (0..rays.len())
            .map(|i| (i % 3 != 0).then_some(Hit { t: i as f32, triangle: i as u32, beta: 0.0, gamma: 0.5 }))
            .collect();
        let mut writer = HitWriter::new(Vec::new());
        writer.write_closest(&hits).unwrap();
        let written = writer.into_inner();
        assert_eq!(written.len(), hits.len() * HIT_BYTES);
        let back: Vec<Option<Hit>> =
            written.chunks_exact(HIT_BYTES).map(|r| decode_hit(r.try_into().unwrap())).collect();
        assert_eq!(back, hits);
        let occluded: Vec<bool> = (0..rays.len()).map(|i| i % 2 == 0).collect();
        let mut writer = HitWriter::new(Vec::new());
        writer.write_occluded(&occluded).unwrap();
        let back: Vec<bool> =
            writer.into_inner().chunks_exact(HIT_BYTES).map(|r| decode_hit(r.try_into().unwrap()).is_some()).collect();
        assert_eq!(back, occluded);
    }

    #[test]
    fn chunks_hold_whole_records_across_reads_of_any_size() {
        let rays: Vec<Ray> = (0..7).map(ray).collect();
        let bytes = file_of(&rays);
        for step in [1, 5, 31, 32, 33, 1000] {
            let (sizes, back) = read_all(Trickle { bytes: &bytes, step, interrupt: false }, 3).unwrap();
            assert_eq!(sizes, [3, 3, 1], "reads of {step} bytes");
            assert_eq!(back.iter().map(bits).collect::<Vec<_>>(), rays.iter().map(bits).collect::<Vec<_>>());
        }
        // A file of whole chunks ends with no empty chunk before the end.
        assert_eq!(read_all(file_of(&rays[..6]).as_slice(), 3).unwrap().0, [3, 3]);
        assert_eq!(read_all(&[][..], 3).unwrap().0, Vec::<usize>::new());
    }

    #[test]
    fn a_truncated_final_ray_is_refused_with_the_size_and_the_ray() {
        // The part of a record falls in a chunk of its own, and inside one.
        for (whole, chunk_rays) in [(6, 3), (7, 3), (2, 64)] {
            let mut bytes = file_of(&(0..whole).map(ray).collect::<Vec<_>>());
            bytes.extend_from_slice(&[0; 8]);
            let error = read_all(Trickle { bytes: &bytes, step: 7, interrupt: false }, chunk_rays).unwrap_err();
            let size = (whole * RAY_BYTES + 8) as u64;
            assert!(matches!(error, RayFileError::PartialRecord { bytes } if bytes == size), "{error:?}");
            let message = error.to_string();
            assert!(message.contains(&format!("its size, {size} bytes, is not a multiple of 32")), "{message}");
            assert!(
                message.contains(&format!("the last ray, ray {whole}, is cut off after 8 of its bytes")),
                "{message}"
            );
        }
        assert_eq!(ray_count(64).unwrap(), 2);
        assert!(matches!(ray_count(33), Err(RayFileError::PartialRecord { bytes: 33 })));
    }

    #[test]
    fn each_invalid_ray_is_refused_naming_its_index_and_its_fault() {
        let bad = [
            (Ray::new(Vec3::new(f32::NAN, 1.0, 1.0), Vec3::Z), "its origin (NaN, 1, 1) is not finite"),
            (Ray::new(Vec3::new(1.0, f32::INFINITY, 1.0), Vec3::Z), "its origin (1, inf, 1) is not finite"),
            (Ray::new(Vec3::ONE, Vec3::new(0.0, f32::NEG_INFINITY, 0.0)), "its direction (0, -inf, 0) is not finite"),
            (Ray::new(Vec3::ONE, Vec3::new(f32::NAN, 0.0, 1.0)), "its direction (NaN, 0, 1) is not finite"),
            (Ray::new(Vec3::ONE, Vec3::ZERO), "its direction is zero"),
            (Ray::new(Vec3::ONE, Vec3::new(-0.0, 0.0, -0.0)), "its direction is zero"),
            (Ray::with_range(Vec3::ONE, Vec3::Y, f32::NAN, 1.0), "its range [NaN, 1] is not a number"),
            (Ray::with_range(Vec3::ONE, Vec3::Y, 0.0, f32::NAN), "its range [0, NaN] is not a number"),
        ];
        for (invalid, what) in bad {
            assert_eq!(decode_ray(&encode_ray(&invalid)).unwrap_err().to_string(), what);
            // Ray 4 is the first of the second chunk, ray 5 the second.
            for at in [4, 5] {
                let mut rays: Vec<Ray> = (0..8).map(ray).collect();
                rays[at] = invalid;
                let bytes = file_of(&rays);
                let mut reader = RayReader::new(bytes.as_slice(), 4);
                let mut chunk = Vec::new();
                assert!(reader.next_chunk(&mut chunk).unwrap());
                let error = reader.next_chunk(&mut chunk).unwrap_err();
                assert!(chunk.is_empty(), "no ray of a refused chunk is returned");
                assert!(matches!(error, RayFileError::InvalidRay { index, .. } if index == at as u64), "{error:?}");
                let (first, last) = (at * RAY_BYTES, (at + 1) * RAY_BYTES - 1);
                assert_eq!(
                    error.to_string(),
                    format!("not a ray file: ray {at} (bytes {first} to {last}) is not a valid ray: {what}")
                );
            }
        }
    }

    #[test]
    fn empty_ranges_and_infinite_bounds_are_valid_rays() {
        for r in [
            Ray::with_range(Vec3::ONE, Vec3::Y, 2.0, 1.0),
            Ray::with_range(Vec3::ONE, Vec3::Y, f32::NEG_INFINITY, f32::INFINITY),
        ] {
            assert!(decode_ray(&encode_ray(&r)).is_ok(), "{r:?}");
        }
    }

    #[test]
    fn a_read_error_is_passed_on() {
        struct Broken;
        impl Read for Broken {
            fn read(&mut self, _: &mut [u8]) -> io::Result<usize> {
                Err(io::Error::other("the disk is on fire"))
            }
        }
        let error = RayReader::new(Broken, 4).next_chunk(&mut Vec::new()).unwrap_err();
        assert!(matches!(&error, RayFileError::Io(e) if e.to_string() == "the disk is on fire"), "{error:?}");
        assert_eq!(error.to_string(), "cannot read");
    }
}
