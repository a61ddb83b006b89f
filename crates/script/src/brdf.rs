//! The course framework's BRDF names, each realised as the nearest of our
//! materials. Our materials are data (colours, roughness, index of
//! refraction) from which the renderer chooses its BSDF, so a course BRDF
//! becomes a setting of those fields; where the result reflects light
//! differently from the course's model, [`CourseBrdf::difference`] says how.

use rtgi_math::Vec3;
use rtgi_scene::{Material, SurfaceModel};

/// A BRDF by the course's name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CourseBrdf {
    /// `lambert`: diffuse.
    Lambert,
    /// `mirror` (also `specular`): a perfect mirror.
    Mirror,
    /// `dielectric-specular`: smooth glass, reflecting and refracting.
    DielectricSpecular,
    /// `thin-dielectric-specular`: a thin sheet of glass, refracting without bending.
    ThinDielectricSpecular,
    /// `phong`: a glossy Phong lobe.
    Phong,
    /// `layered-phong`: a diffuse base under a Phong lobe.
    LayeredPhong,
    /// `gtr2`: a GGX microfacet lobe.
    Gtr2,
    /// `layered-gtr2`: a diffuse base under a GGX lobe.
    LayeredGtr2,
}

/// A BRDF name the course does not have.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("No such brdf defined: {0} (one of {names})", names = CourseBrdf::NAMES)]
pub struct UnknownBrdf(pub String);

impl CourseBrdf {
    /// The names, for messages.
    pub const NAMES: &'static str =
        "lambert, mirror, dielectric-specular, thin-dielectric-specular, phong, layered-phong, gtr2, layered-gtr2";

    /// The BRDF the course calls `name` (and `specular`, an older name of `mirror`).
    pub fn from_name(name: &str) -> Result<Self, UnknownBrdf> {
        Ok(match name {
            "lambert" => CourseBrdf::Lambert,
            "mirror" | "specular" => CourseBrdf::Mirror,
            "dielectric-specular" => CourseBrdf::DielectricSpecular,
            "thin-dielectric-specular" => CourseBrdf::ThinDielectricSpecular,
            "phong" => CourseBrdf::Phong,
            "layered-phong" => CourseBrdf::LayeredPhong,
            "gtr2" => CourseBrdf::Gtr2,
            "layered-gtr2" => CourseBrdf::LayeredGtr2,
            _ => return Err(UnknownBrdf(name.to_owned())),
        })
    }

    /// The course's name of it.
    pub fn name(self) -> &'static str {
        match self {
            CourseBrdf::Lambert => "lambert",
            CourseBrdf::Mirror => "mirror",
            CourseBrdf::DielectricSpecular => "dielectric-specular",
            CourseBrdf::ThinDielectricSpecular => "thin-dielectric-specular",
            CourseBrdf::Phong => "phong",
            CourseBrdf::LayeredPhong => "layered-phong",
            CourseBrdf::Gtr2 => "gtr2",
            CourseBrdf::LayeredGtr2 => "layered-gtr2",
        }
    }

    /// How the material rtgi renders for this BRDF reflects differently
    /// from the course's model; `None` where it is the same model.
    pub fn difference(self) -> Option<&'static str> {
        match self {
            CourseBrdf::Lambert
            | CourseBrdf::Mirror
            | CourseBrdf::DielectricSpecular
            | CourseBrdf::ThinDielectricSpecular => None,
            CourseBrdf::Phong => Some(
                "rtgi has no Phong lobe: a GGX lobe of reflectance albedo and width roughness stands in for it \
                 (highlights of another shape)",
            ),
            CourseBrdf::LayeredPhong => Some(
                "rtgi has no Phong lobe: a Lambertian layer plus a GGX lobe of width roughness stands in, whose \
                 reflectance is Fresnel's at normal incidence for the ior, at every angle",
            ),
            CourseBrdf::Gtr2 => Some(
                "rtgi's GGX lobe has no Fresnel term of its own: its reflectance is albedo times Fresnel's at normal \
                 incidence for the ior, at every angle (grazing highlights are dimmer than the course's)",
            ),
            CourseBrdf::LayeredGtr2 => Some(
                "rtgi's layered GGX is glTF's dielectric: a Lambertian base under a GGX coat with Schlick's Fresnel \
                 for an ior of 1.5, whatever the material's ior",
            ),
        }
    }

    /// Makes `material` reflect as this BRDF with the course's `albedo`
    /// and `roughness` (the GGX width), keeping its index of refraction.
    pub fn realise(self, albedo: Vec3, roughness: f32, material: &mut Material) {
        let ior = material.ior;
        let rough = our_roughness(roughness);
        let normal_incidence = ((ior - 1.0) / (ior + 1.0)).powi(2);
        let (model, base_color, specular, metallic, transmission, roughness) = match self {
            CourseBrdf::Lambert => (SurfaceModel::DiffuseSpecular, albedo, Vec3::ZERO, 0.0, 0.0, rough),
            CourseBrdf::Mirror => (SurfaceModel::DiffuseSpecular, Vec3::ZERO, albedo, 0.0, 0.0, 0.0),
            CourseBrdf::DielectricSpecular => (SurfaceModel::DiffuseSpecular, Vec3::ZERO, Vec3::ZERO, 0.0, 1.0, rough),
            CourseBrdf::ThinDielectricSpecular => (SurfaceModel::MetallicRoughness, albedo, Vec3::ZERO, 0.0, 1.0, 0.0),
            CourseBrdf::Phong => (SurfaceModel::DiffuseSpecular, Vec3::ZERO, albedo, 0.0, 0.0, rough),
            CourseBrdf::LayeredPhong => {
                (SurfaceModel::DiffuseSpecular, albedo, Vec3::splat(normal_incidence), 0.0, 0.0, rough)
            }
            CourseBrdf::Gtr2 => (SurfaceModel::DiffuseSpecular, Vec3::ZERO, albedo * normal_incidence, 0.0, 0.0, rough),
            CourseBrdf::LayeredGtr2 => (SurfaceModel::MetallicRoughness, albedo, Vec3::ZERO, 0.0, 0.0, rough),
        };
        material.model = model;
        material.base_color = base_color;
        material.specular = specular;
        material.metallic = metallic;
        material.transmission = transmission;
        material.roughness = roughness;
        material.metallic_roughness_texture = None;
        material.transmission_texture = None;
    }
}

/// Our roughness (perceptual, the square root of the GGX width) for the
/// course's roughness (the GGX width itself, as its MTL import
/// sqrt(2 / (Ns + 2)) gives it, and as ours gives alpha).
pub fn our_roughness(course: f32) -> f32 {
    course.max(0.0).sqrt()
}

/// The course's roughness for ours.
pub fn course_roughness(ours: f32) -> f32 {
    ours * ours
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_maps_back_and_forth() {
        for name in CourseBrdf::NAMES.split(", ") {
            assert_eq!(CourseBrdf::from_name(name).unwrap().name(), name);
        }
        assert_eq!(CourseBrdf::from_name("specular").unwrap(), CourseBrdf::Mirror);
        assert!(CourseBrdf::from_name("velvet").unwrap_err().to_string().starts_with("No such brdf defined: velvet"));
    }

    #[test]
    fn course_brdfs_set_the_fields_our_bsdfs_are_chosen_by() {
        let albedo = Vec3::new(0.7, 0.5, 0.3);
        let mut m = Material { ior: 1.5, ..Material::default() };
        CourseBrdf::Mirror.realise(albedo, 0.04, &mut m);
        assert_eq!((m.base_color, m.specular, m.roughness), (Vec3::ZERO, albedo, 0.0));
        CourseBrdf::Gtr2.realise(albedo, 0.04, &mut m);
        assert!((m.specular - albedo * 0.04).abs().max_element() < 1e-6 && m.base_color == Vec3::ZERO);
        assert!((course_roughness(m.roughness) - 0.04).abs() < 1e-6);
        CourseBrdf::DielectricSpecular.realise(albedo, 0.04, &mut m);
        assert_eq!((m.transmission, m.model), (1.0, SurfaceModel::DiffuseSpecular));
        CourseBrdf::LayeredGtr2.realise(albedo, 0.04, &mut m);
        assert_eq!(
            (m.model, m.base_color, m.metallic, m.transmission),
            (SurfaceModel::MetallicRoughness, albedo, 0.0, 0.0)
        );
    }
}
