//! Colour arithmetic shared by the renderer and the image crate.

use crate::Vec3;

/// The luminance of a linear Rec. 709 (sRGB primaries) colour: how bright
/// it looks, as one number (weights of ITU-R BT.709).
///
/// ```
/// use rtgi_math::{Vec3, luminance};
/// assert!((luminance(Vec3::ONE) - 1.0).abs() < 1e-6);
/// assert!(luminance(Vec3::Y) > luminance(Vec3::X) && luminance(Vec3::X) > luminance(Vec3::Z));
/// ```
pub fn luminance(colour: Vec3) -> f32 {
    colour.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}
