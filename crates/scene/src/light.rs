use rtgi_math::Vec3;

/// A light that is not a surface (emissive surfaces are materials).
#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    pub name: String,
    pub kind: LightKind,
    /// Where a point or spot light is.
    pub position: Vec3,
    /// The unit direction light travels in, for spot and directional lights.
    pub direction: Vec3,
    /// Linear RGB colour.
    pub color: Vec3,
    /// In glTF's units: candela (lm/sr) for point and spot lights, lux (lm/m²) for directional lights.
    pub intensity: f32,
    /// Distance beyond which the light has no effect, if limited.
    pub range: Option<f32>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightKind {
    Point,
    /// Full intensity inside `inner_cone`, none outside `outer_cone` (half-angles in radians).
    Spot {
        inner_cone: f32,
        outer_cone: f32,
    },
    Directional,
}
