use rtgi_math::Vec3;

/// How linear radiance becomes a displayable value in `[0, 1]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum ToneOperator {
    /// Clip at 1: faithful for albedo-like images whose values are already in `[0, 1]`.
    Clamp,
    /// `c / (1 + c)` per channel (Reinhard et al. 2002, the simple global operator).
    Reinhard,
    /// Narkowicz's fit of the ACES filmic curve (2015): a gentle shoulder for bright lights.
    Aces,
}

impl ToneOperator {
    /// Every operator, in the order command-line help lists them.
    pub const ALL: &'static [ToneOperator] = &[ToneOperator::Clamp, ToneOperator::Reinhard, ToneOperator::Aces];

    /// The operator's name on command lines and in reports (`clamp`, `reinhard`, `aces`).
    pub fn name(self) -> &'static str {
        match self {
            ToneOperator::Clamp => "clamp",
            ToneOperator::Reinhard => "reinhard",
            ToneOperator::Aces => "aces",
        }
    }

    #[inline]
    fn map(self, c: f32) -> f32 {
        let c = c.max(0.0);
        match self {
            ToneOperator::Clamp => c.min(1.0),
            ToneOperator::Reinhard => c / (1.0 + c),
            ToneOperator::Aces => {
                let (a, b, cc, d, e) = (2.51, 0.03, 2.43, 0.59, 0.14);
                ((c * (a * c + b)) / (c * (cc * c + d) + e)).clamp(0.0, 1.0)
            }
        }
    }
}

impl rtgi_math::NamedChoice for ToneOperator {
    const KIND: &'static str = "tone map";
    const ALL: &'static [Self] = ToneOperator::ALL;
    fn name(self) -> &'static str {
        ToneOperator::name(self)
    }
}

impl std::fmt::Display for ToneOperator {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Exposure followed by a tone operator; used for 8-bit output only.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToneMap {
    /// Exposure in stops: values are multiplied by `2^exposure` first.
    pub exposure: f32,
    /// The curve applied after the exposure, per channel.
    pub operator: ToneOperator,
}

impl Default for ToneMap {
    fn default() -> Self {
        Self { exposure: 0.0, operator: ToneOperator::Clamp }
    }
}

impl ToneMap {
    /// Maps linear radiance to linear display values in `[0, 1]`; NaN becomes 0.
    #[inline]
    pub fn apply(&self, radiance: Vec3) -> Vec3 {
        let scaled = radiance * self.exposure.exp2();
        let channel = |c: f32| {
            if c.is_nan() { 0.0 } else { self.operator.map(c) }
        };
        Vec3::new(channel(scaled.x), channel(scaled.y), channel(scaled.z))
    }
}

/// The sRGB transfer function (IEC 61966-2-1), for values in `[0, 1]`.
#[inline]
pub fn linear_to_srgb(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.003_130_8 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 }
}

/// The inverse of [`linear_to_srgb`].
#[inline]
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.040_45 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// A false-colour scale for `t` in `[0, 1]` (clamped), dark blue through
/// purple, red and orange to pale yellow: monotonic in lightness, so that it
/// reads in grey too. Returns linear RGB, ready for an [`HdrImage`](crate::HdrImage)
/// written with the clamp tone map. The stops approximate matplotlib's
/// "inferno" map.
pub fn heat_colour(t: f32) -> Vec3 {
    const STOPS: [[f32; 3]; 6] = [
        [0.001, 0.000, 0.014],
        [0.258, 0.039, 0.406],
        [0.578, 0.148, 0.404],
        [0.865, 0.317, 0.226],
        [0.988, 0.645, 0.040],
        [0.988, 0.998, 0.645],
    ];
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let scaled = t * (STOPS.len() - 1) as f32;
    let i = (scaled as usize).min(STOPS.len() - 2);
    let f = scaled - i as f32;
    let srgb = Vec3::from(STOPS[i]).lerp(Vec3::from(STOPS[i + 1]), f);
    Vec3::new(srgb_to_linear(srgb.x), srgb_to_linear(srgb.y), srgb_to_linear(srgb.z))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trip_and_endpoints() {
        assert_eq!(linear_to_srgb(0.0), 0.0);
        assert!((linear_to_srgb(1.0) - 1.0).abs() < 1e-6);
        assert!((linear_to_srgb(0.214_041) - 0.5).abs() < 1e-4);
        for i in 0..=100 {
            let c = i as f32 / 100.0;
            assert!((srgb_to_linear(linear_to_srgb(c)) - c).abs() < 1e-5);
        }
    }

    #[test]
    fn heat_colours_get_lighter() {
        let luminance = |c: Vec3| c.dot(Vec3::new(0.2126, 0.7152, 0.0722));
        let mut last = -1.0;
        for i in 0..=50 {
            let l = luminance(heat_colour(i as f32 / 50.0));
            assert!(l > last, "{i}: {l} after {last}");
            last = l;
        }
        assert_eq!(heat_colour(-1.0), heat_colour(0.0));
        assert_eq!(heat_colour(f32::NAN), heat_colour(0.0));
    }

    #[test]
    fn operators_are_monotonic_and_bounded() {
        for op in ToneOperator::ALL {
            let tm = ToneMap { exposure: 0.0, operator: *op };
            let mut last = -1.0;
            for i in 0..200 {
                let v = tm.apply(Vec3::splat(i as f32 * 0.1)).x;
                assert!((0.0..=1.0).contains(&v) && v >= last, "{op}: {v} after {last}");
                last = v;
            }
        }
        let tm = ToneMap { exposure: 1.0, operator: ToneOperator::Clamp };
        assert_eq!(tm.apply(Vec3::splat(0.25)), Vec3::splat(0.5));
        assert_eq!(tm.apply(Vec3::new(f32::NAN, -1.0, 9.0)), Vec3::new(0.0, 0.0, 1.0));
    }
}
