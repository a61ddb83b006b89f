use std::ops::{Add, Mul};
use std::path::Path;
use std::sync::{LazyLock, OnceLock};

use rtgi_math::{Vec2, Vec3, Vec4};

use crate::texel_range::TexelRanges;

/// The widest and tallest texture read, in texels (16384: four times the
/// largest textures of the shared scenes; a 16384² RGBA image takes 1 GiB).
pub const MAX_TEXTURE_SIDE: u32 = 16_384;

/// The most memory the image decoder may allocate for one texture.
pub const MAX_TEXTURE_BYTES: u64 = 1 << 30;

/// Index of a texture in [`Scene::textures`](crate::Scene::textures).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TextureId(pub u32);

/// How a texture's 8-bit values map to linear values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorEncoding {
    /// Colours (base colour, emission): sRGB-encoded.
    Srgb,
    /// Data (normals, roughness): stored linearly.
    Linear,
}

/// How texture coordinates outside `[0, 1]` map into the image.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Wrap {
    #[default]
    /// Tile the image: coordinates are taken modulo 1.
    Repeat,
    /// Coordinates are clamped to `[0, 1]`: the edge texels repeat outwards.
    ClampToEdge,
    /// Tile the image, mirrored every other tile.
    MirroredRepeat,
}

impl Wrap {
    /// The texel index `i` maps to in an axis of `n` texels.
    #[inline]
    fn apply(self, i: i64, n: u32) -> u32 {
        let n = n as i64;
        // Inside the image every mode is the identity; the 64-bit divisions
        // of `rem_euclid` below cost more than the rest of a bilinear
        // lookup, which runs for every shaded hit and every cut-out test.
        if (0..n).contains(&i) {
            return i as u32;
        }
        let index = match self {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::ClampToEdge => i.clamp(0, n - 1),
            Wrap::MirroredRepeat => {
                let m = i.rem_euclid(2 * n);
                if m >= n { 2 * n - 1 - m } else { m }
            }
        };
        index as u32
    }
}

/// Which texture coordinates a texture reads, and how it transforms them
/// (glTF's `texCoord` and KHR_texture_transform): the coordinates of set
/// [`set`](Self::set), mapped by an affine transform.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvMap {
    /// The vertex's texture coordinate set: 0 ([`Vertex::uv`](crate::Vertex::uv)) or 1 ([`Vertex::uv1`](crate::Vertex::uv1)).
    pub set: u8,
    /// Rows of the 2 × 3 affine matrix applied to the coordinates: `u' = m[0] · (u, v, 1)`, `v' = m[1] · (u, v, 1)`.
    pub matrix: [Vec3; 2],
}

impl Default for UvMap {
    fn default() -> Self {
        UvMap::IDENTITY
    }
}

impl UvMap {
    /// Set 0, untransformed.
    pub const IDENTITY: UvMap = UvMap { set: 0, matrix: [Vec3::X, Vec3::Y] };

    /// KHR_texture_transform's `offset`, `rotation` (radians) and `scale`
    /// on set `set`: the matrix translation · rotation · scale of the
    /// extension's specification, where rotation turns (u, v) by
    /// `[cos r, sin r; -sin r, cos r]`.
    pub fn from_offset_rotation_scale(set: u8, offset: Vec2, rotation: f32, scale: Vec2) -> UvMap {
        let (sin, cos) = rotation.sin_cos();
        UvMap {
            set,
            matrix: [
                Vec3::new(cos * scale.x, sin * scale.y, offset.x),
                Vec3::new(-sin * scale.x, cos * scale.y, offset.y),
            ],
        }
    }

    /// Whether the map reads set 0 untransformed.
    pub fn is_identity(&self) -> bool {
        *self == UvMap::IDENTITY
    }

    /// The coordinates a lookup reads, from a point's two coordinate sets.
    #[inline]
    pub fn apply(&self, coords: [Vec2; 2]) -> Vec2 {
        self.transform(coords[(self.set as usize).min(1)])
    }

    /// Coordinates of the map's set, transformed (the identity's bits are kept).
    #[inline]
    pub fn transform(&self, uv: Vec2) -> Vec2 {
        if self.matrix == UvMap::IDENTITY.matrix {
            return uv;
        }
        let uv = uv.extend(1.0);
        Vec2::new(self.matrix[0].dot(uv), self.matrix[1].dot(uv))
    }
}

/// An 8-bit RGBA image, sampled with bilinear filtering and its wrap modes,
/// at the coordinates its [`UvMap`] picks.
///
/// Texels are kept as bytes (a quarter of the memory of floats) and decoded
/// through a table on lookup. (Textures that differ only in their map or
/// wrap modes are copies: sharing the texels through an `Arc` cost a copy
/// of every texture while it was decoded, 47 MB more at the peak of
/// loading DamagedHelmet, for images that are rarely used twice.)
#[derive(Clone, PartialEq)]
pub struct Texture {
    /// Where the texture came from, for messages.
    pub name: String,
    width: u32,
    height: u32,
    texels: Vec<[u8; 4]>,
    encoding: ColorEncoding,
    /// The coordinates it reads.
    uv_map: UvMap,
    /// Wrap modes along u and v.
    wrap: [Wrap; 2],
    /// Whether any texel is less than fully opaque: asked for every
    /// candidate hit on a cut-out surface, so found once.
    has_alpha: bool,
    /// Per channel, the range of its bytes over each 2 × 2 block, made when
    /// [`Texture::channel_bounds`] first asks for that channel.
    ranges: [LazyRanges; 4],
}

/// A [`TexelRanges`] made on first use. It is derived from the texels, so
/// it takes no part in comparing textures.
#[derive(Clone, Default)]
struct LazyRanges(OnceLock<TexelRanges>);

impl PartialEq for LazyRanges {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// Where a bilinear lookup reads: the texels' columns and rows (after the
/// wrap modes) and the weights of the second of each.
struct Footprint {
    columns: [u32; 2],
    rows: [u32; 2],
    fx: f32,
    fy: f32,
}

/// A bilinear value's relative rounding error is below 7 units in the
/// last place (three products and sums per axis, and `1 - f`); bounds
/// from the texels' range are widened by this factor to cover it.
const FILTER_ROUNDING: f32 = 1.0 / (1 << 20) as f32;

impl std::fmt::Debug for Texture {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Texture")
            .field("name", &self.name)
            .field("width", &self.width)
            .field("height", &self.height)
            .field("encoding", &self.encoding)
            .finish_non_exhaustive()
    }
}

static SRGB_TO_LINEAR: LazyLock<[f32; 256]> = LazyLock::new(|| {
    std::array::from_fn(|i| {
        let c = i as f32 / 255.0;
        if c <= 0.040_45 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
    })
});

impl Texture {
    /// A texture from RGBA bytes, row by row from the top; `None` if the sizes disagree or are zero.
    pub fn from_rgba8(
        name: impl Into<String>,
        width: u32,
        height: u32,
        texels: Vec<[u8; 4]>,
        encoding: ColorEncoding,
    ) -> Option<Self> {
        (width > 0 && height > 0 && texels.len() == width as usize * height as usize).then(|| Self {
            name: name.into(),
            width,
            height,
            has_alpha: texels.iter().any(|t| t[3] < 255),
            texels,
            encoding,
            uv_map: UvMap::IDENTITY,
            wrap: [Wrap::Repeat; 2],
            ranges: Default::default(),
        })
    }

    /// This texture with the given wrap modes along u and v.
    #[must_use]
    pub fn with_wrap(mut self, u: Wrap, v: Wrap) -> Self {
        self.wrap = [u, v];
        self
    }

    /// This texture reading the coordinates `map` picks.
    #[must_use]
    pub fn with_uv_map(mut self, map: UvMap) -> Self {
        self.uv_map = map;
        self
    }

    /// The coordinates the texture reads.
    pub fn uv_map(&self) -> &UvMap {
        &self.uv_map
    }

    /// The linear value at a point whose coordinate sets are `coords`
    /// ([`Scene::texture_coords`](crate::Scene::texture_coords)), through the texture's [`UvMap`].
    #[inline]
    pub fn lookup(&self, coords: [Vec2; 2]) -> Vec4 {
        self.sample(self.uv_map.apply(coords))
    }

    /// Decodes a PNG or JPEG file.
    pub fn load(path: &Path, encoding: ColorEncoding) -> Result<Self, String> {
        let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
        Self::decode(&bytes, &path.display().to_string(), encoding)
    }

    /// Decodes PNG or JPEG bytes; `name` is used in messages. Images wider
    /// or taller than [`MAX_TEXTURE_SIDE`] are refused from their header,
    /// before any pixel is allocated, and the decoder may allocate at most
    /// [`MAX_TEXTURE_BYTES`].
    pub fn decode(bytes: &[u8], name: &str, encoding: ColorEncoding) -> Result<Self, String> {
        let reader = || {
            image::ImageReader::new(std::io::Cursor::new(bytes))
                .with_guessed_format()
                .map_err(|e| format!("{name}: {e}"))
        };
        let (width, height) = reader()?.into_dimensions().map_err(|e| format!("{name}: {e}"))?;
        if width > MAX_TEXTURE_SIDE || height > MAX_TEXTURE_SIDE {
            return Err(format!(
                "{name}: the image is {width} x {height} texels, larger than the {MAX_TEXTURE_SIDE} a side that are read"
            ));
        }
        let mut limits = image::Limits::default();
        limits.max_image_width = Some(MAX_TEXTURE_SIDE);
        limits.max_image_height = Some(MAX_TEXTURE_SIDE);
        limits.max_alloc = Some(MAX_TEXTURE_BYTES);
        let mut reader = reader()?;
        reader.limits(limits);
        let decoded = reader.decode().map_err(|e| format!("{name}: {e}"))?.to_rgba8();
        let (width, height) = decoded.dimensions();
        let texels = decoded.pixels().map(|p| p.0).collect();
        Self::from_rgba8(name, width, height, texels, encoding).ok_or_else(|| format!("{name}: empty image"))
    }

    /// A magenta and black checkerboard that stands in for a texture that
    /// could not be loaded: impossible to mistake for real content.
    pub fn missing(name: impl Into<String>) -> Self {
        let texels = (0..64).map(|i| if (i % 8 + i / 8) % 2 == 0 { [255, 0, 255, 255] } else { [0, 0, 0, 255] });
        Self {
            name: name.into(),
            width: 8,
            height: 8,
            texels: texels.collect(),
            encoding: ColorEncoding::Srgb,
            uv_map: UvMap::IDENTITY,
            wrap: [Wrap::Repeat; 2],
            has_alpha: false,
            ranges: Default::default(),
        }
    }

    /// Width in texels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Whether the texels are sRGB-encoded colours or linear data (normals, roughness).
    pub fn encoding(&self) -> ColorEncoding {
        self.encoding
    }

    /// The mean linear value of the texels.
    pub fn average(&self) -> Vec4 {
        let mut sum = rtgi_math::glam::DVec4::ZERO;
        for y in 0..self.height {
            for x in 0..self.width {
                sum += self.texel(x, y).as_dvec4();
            }
        }
        (sum / self.texels.len() as f64).as_vec4()
    }

    /// Whether any texel is less than fully opaque.
    pub fn has_alpha(&self) -> bool {
        self.has_alpha
    }

    #[inline]
    fn texel(&self, x: u32, y: u32) -> Vec4 {
        let [r, g, b, a] = self.texels[(y * self.width + x) as usize];
        let alpha = a as f32 * (1.0 / 255.0);
        match self.encoding {
            ColorEncoding::Srgb => {
                let table = &*SRGB_TO_LINEAR;
                Vec4::new(table[r as usize], table[g as usize], table[b as usize], alpha)
            }
            ColorEncoding::Linear => Vec4::new(r as f32, g as f32, b as f32, a as f32) * (1.0 / 255.0),
        }
    }

    /// One channel of [`Texture::sample`] (0 red, 1 green, 2 blue, 3
    /// alpha), with the same bits, for lookups that need no more: the alpha
    /// test of a cut-out runs for every candidate hit.
    pub fn sample_channel(&self, uv: Vec2, channel: usize) -> f32 {
        self.filtered(uv, |x, y| self.decode_channel(self.texels[(y * self.width + x) as usize][channel], channel))
    }

    /// Bounds `(low, high)` on [`Texture::sample_channel`]`(uv, channel)`,
    /// read from one entry of a table of the channel's range over each 2 × 2
    /// block of texels (made on first use) instead of four texels: where
    /// the texels around `uv` are all alike (a cut-out's wholly opaque or wholly clear
    /// parts), the bounds are as good as the value. `None` where `uv` is
    /// not finite.
    pub fn channel_bounds(&self, uv: Vec2, channel: usize) -> Option<(f32, f32)> {
        let footprint = self.footprint(uv)?;
        let ranges = self.ranges[channel].0.get_or_init(|| TexelRanges::of(&self.texels, self.width as usize, channel));
        let [low, high] = ranges.spanning(footprint.columns, footprint.rows);
        Some((
            self.decode_channel(low, channel) * (1.0 - FILTER_ROUNDING),
            self.decode_channel(high, channel) * (1.0 + FILTER_ROUNDING),
        ))
    }

    /// The linear value of one byte of channel `channel`.
    #[inline(always)]
    fn decode_channel(&self, byte: u8, channel: usize) -> f32 {
        match self.encoding {
            ColorEncoding::Srgb if channel < 3 => SRGB_TO_LINEAR[byte as usize],
            ColorEncoding::Srgb | ColorEncoding::Linear => byte as f32 * (1.0 / 255.0),
        }
    }

    /// The linear value at `uv` (origin top left, one repeat per unit), bilinearly filtered.
    pub fn sample(&self, uv: Vec2) -> Vec4 {
        self.filtered(uv, |x, y| self.texel(x, y))
    }

    /// The texels a bilinear lookup at `uv` blends, with the wrap modes;
    /// `None` where `uv` is not finite.
    #[inline(always)]
    fn footprint(&self, uv: Vec2) -> Option<Footprint> {
        if !uv.is_finite() {
            return None;
        }
        // Texel centres sit at half-integer positions.
        let x = uv.x * self.width as f32 - 0.5;
        let y = uv.y * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let [wrap_u, wrap_v] = self.wrap;
        Some(Footprint {
            columns: [wrap_u.apply(x0 as i64, self.width), wrap_u.apply(x0 as i64 + 1, self.width)],
            rows: [wrap_v.apply(y0 as i64, self.height), wrap_v.apply(y0 as i64 + 1, self.height)],
            fx: x - x0,
            fy: y - y0,
        })
    }

    /// Bilinear filtering of the values `texel(x, y)` around `uv`, with the wrap modes.
    #[inline(always)]
    fn filtered<T: Copy + Mul<f32, Output = T> + Add<Output = T>>(&self, uv: Vec2, texel: impl Fn(u32, u32) -> T) -> T {
        let Some(Footprint { columns: [xa, xb], rows: [ya, yb], fx, fy }) = self.footprint(uv) else {
            return texel(0, 0);
        };
        let top = texel(xa, ya) * (1.0 - fx) + texel(xb, ya) * fx;
        let bottom = texel(xa, yb) * (1.0 - fx) + texel(xb, yb) * fx;
        top * (1.0 - fy) + bottom * fy
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two_by_one() -> Texture {
        Texture::from_rgba8("t", 2, 1, vec![[0, 0, 0, 255], [255, 255, 255, 255]], ColorEncoding::Linear).unwrap()
    }

    #[test]
    fn texel_centres_are_exact_and_between_is_linear() {
        let t = two_by_one();
        assert_eq!(t.sample(Vec2::new(0.25, 0.5)).x, 0.0);
        assert_eq!(t.sample(Vec2::new(0.75, 0.5)).x, 1.0);
        assert!((t.sample(Vec2::new(0.5, 0.5)).x - 0.5).abs() < 1e-6);
    }

    #[test]
    fn coordinates_repeat() {
        let t = two_by_one();
        assert_eq!(t.sample(Vec2::new(1.25, 7.5)), t.sample(Vec2::new(0.25, 0.5)));
        assert_eq!(t.sample(Vec2::new(-0.75, -3.5)), t.sample(Vec2::new(0.25, 0.5)));
    }

    #[test]
    fn clamp_and_mirror_wrap_modes() {
        let clamped = two_by_one().with_wrap(Wrap::ClampToEdge, Wrap::ClampToEdge);
        assert_eq!(clamped.sample(Vec2::new(3.0, 0.5)).x, 1.0);
        assert_eq!(clamped.sample(Vec2::new(-3.0, 0.5)).x, 0.0);
        let mirrored = two_by_one().with_wrap(Wrap::MirroredRepeat, Wrap::Repeat);
        // Just past the right edge the mirror shows the right texel again.
        assert_eq!(mirrored.sample(Vec2::new(1.25, 0.5)).x, 1.0);
        assert_eq!(mirrored.sample(Vec2::new(1.75, 0.5)).x, 0.0);
        assert_eq!(Wrap::MirroredRepeat.apply(-1, 4), 0);
        assert_eq!(Wrap::MirroredRepeat.apply(4, 4), 3);
    }

    #[test]
    fn srgb_texels_are_decoded() {
        let t = Texture::from_rgba8("s", 1, 1, vec![[188, 0, 255, 128]], ColorEncoding::Srgb).unwrap();
        let v = t.sample(Vec2::new(0.5, 0.5));
        assert!((v.x - 0.5029).abs() < 1e-3, "{v}");
        assert_eq!(v.z, 1.0);
        assert!((v.w - 128.0 / 255.0).abs() < 1e-6);
    }

    #[test]
    fn wrong_sizes_are_refused() {
        assert!(Texture::from_rgba8("x", 2, 2, vec![[0; 4]; 3], ColorEncoding::Linear).is_none());
        assert!(Texture::from_rgba8("x", 0, 0, vec![], ColorEncoding::Linear).is_none());
    }

    #[test]
    fn one_channel_has_the_bits_of_all_four() {
        let texels =
            (0..35).map(|i| [(i * 37 % 256) as u8, (i * 91 % 256) as u8, (i * 13 % 256) as u8, (i * 53 % 256) as u8]);
        for encoding in [ColorEncoding::Srgb, ColorEncoding::Linear] {
            let t = Texture::from_rgba8("t", 7, 5, texels.clone().collect(), encoding).unwrap();
            for k in 0..200 {
                let uv = Vec2::new(k as f32 * 0.037 - 2.0, k as f32 * 0.071 - 5.0);
                let all = t.sample(uv);
                for channel in 0..4 {
                    assert_eq!(
                        t.sample_channel(uv, channel).to_bits(),
                        all[channel].to_bits(),
                        "{encoding:?} {uv} {channel}"
                    );
                }
            }
        }
    }

    #[test]
    fn channel_bounds_hold_every_lookup_and_are_tight_where_texels_agree() {
        // Alpha: a clear block, an opaque block and noise between; red noise.
        let (width, height) = (13u32, 9u32);
        let texels: Vec<[u8; 4]> = (0..width * height)
            .map(|i| {
                let x = i % width;
                let alpha = if x < 4 {
                    0
                } else if x > 8 {
                    255
                } else {
                    (i * 97 % 256) as u8
                };
                [(i * 37 % 256) as u8, 0, 0, alpha]
            })
            .collect();
        let wraps = [Wrap::Repeat, Wrap::ClampToEdge, Wrap::MirroredRepeat];
        let mut decided = [0, 0];
        for encoding in [ColorEncoding::Srgb, ColorEncoding::Linear] {
            for (u_wrap, v_wrap) in wraps.iter().flat_map(|u| wraps.iter().map(move |v| (*u, *v))) {
                let t = Texture::from_rgba8("t", width, height, texels.clone(), encoding)
                    .unwrap()
                    .with_wrap(u_wrap, v_wrap);
                for k in 0..3000 {
                    let uv = Vec2::new(k as f32 * 0.0137 - 7.0, (k * 7 % 3000) as f32 * 0.0091 - 11.0);
                    for channel in [0, 3] {
                        let value = t.sample_channel(uv, channel);
                        let (low, high) = t.channel_bounds(uv, channel).unwrap();
                        assert!(low <= value && value <= high, "{encoding:?} {u_wrap:?} {v_wrap:?} {uv} {channel}");
                        if channel == 3 && high == 0.0 {
                            decided[0] += 1;
                        }
                        if channel == 3 && low > 0.99 {
                            decided[1] += 1;
                        }
                    }
                }
            }
        }
        // The clear and the opaque blocks are decided from their bounds alone.
        assert!(decided[0] > 3000 && decided[1] > 3000, "{decided:?}");
        assert_eq!(two_by_one().channel_bounds(Vec2::new(f32::NAN, 0.5), 0), None);
    }
}
