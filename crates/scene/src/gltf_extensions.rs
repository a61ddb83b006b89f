//! What rtgi makes of each glTF extension a file may use: simulated as its
//! specification describes, approximated (and how), or unsupported (and
//! what the image lacks). The importer refuses a file that *requires* an
//! extension marked unsupported, and warns about one it merely uses.

use std::fmt;

/// How rtgi treats one glTF extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExtensionSupport {
    /// Rendered as its specification describes.
    Simulated,
    /// Rendered, with the simplification the text names.
    Approximated(&'static str),
    /// Read but with nothing to render (metadata).
    NotVisual,
    /// Ignored: the text says what the image lacks.
    Unsupported(&'static str),
}

impl ExtensionSupport {
    /// Whether a file that requires the extension can be rendered.
    pub fn is_supported(self) -> bool {
        !matches!(self, ExtensionSupport::Unsupported(_))
    }

    /// One word: simulated, approximated, not visual, unsupported.
    pub fn label(self) -> &'static str {
        match self {
            ExtensionSupport::Simulated => "simulated",
            ExtensionSupport::Approximated(_) => "approximated",
            ExtensionSupport::NotVisual => "not visual",
            ExtensionSupport::Unsupported(_) => "unsupported",
        }
    }

    /// The simplification, or what the image lacks; empty where there is nothing to say.
    pub fn detail(self) -> &'static str {
        match self {
            ExtensionSupport::Approximated(how) | ExtensionSupport::Unsupported(how) => how,
            ExtensionSupport::Simulated | ExtensionSupport::NotVisual => "",
        }
    }
}

impl fmt::Display for ExtensionSupport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.detail() {
            "" => f.write_str(self.label()),
            detail => write!(f, "{}: {detail}", self.label()),
        }
    }
}

/// Every extension rtgi knows, with how it treats it, in the order the
/// README's feature table lists them.
pub const GLTF_EXTENSIONS: &[(&str, ExtensionSupport)] = {
    use ExtensionSupport::*;
    &[
        ("KHR_lights_punctual", Simulated),
        ("KHR_materials_emissive_strength", Simulated),
        ("KHR_materials_ior", Simulated),
        ("KHR_materials_transmission", Simulated),
        (
            "KHR_materials_volume",
            Approximated(
                "refraction through the mesh's real geometry with Beer-Lambert absorption; a medium inside \
                 another is not tracked (the inner one replaces it)",
            ),
        ),
        ("KHR_materials_specular", Simulated),
        ("KHR_materials_clearcoat", Simulated),
        ("KHR_materials_sheen", Simulated),
        ("KHR_materials_iridescence", Simulated),
        ("KHR_materials_anisotropy", Simulated),
        ("KHR_materials_unlit", Simulated),
        ("KHR_materials_variants", Simulated),
        (
            "KHR_materials_dispersion",
            Approximated("light refracts at the material's one index, so there are no colour fringes"),
        ),
        ("KHR_texture_transform", Simulated),
        ("KHR_mesh_quantization", Simulated),
        ("KHR_xmp_json_ld", NotVisual),
        ("KHR_xmp", NotVisual),
        ("KHR_draco_mesh_compression", Unsupported("its compressed meshes are missing")),
        ("EXT_meshopt_compression", Unsupported("its compressed meshes are missing")),
        ("KHR_texture_basisu", Unsupported("its KTX2 textures are missing")),
        ("EXT_texture_webp", Unsupported("its WebP textures are missing")),
        ("MSFT_texture_dds", Unsupported("its DDS textures are missing")),
        ("KHR_materials_pbrSpecularGlossiness", Unsupported("its specular-glossiness materials render as grey")),
        ("KHR_materials_diffuse_transmission", Unsupported("light does not pass through its thin diffuse surfaces")),
        ("KHR_animation_pointer", Unsupported("animation: the still shows the file's rest pose")),
        ("EXT_mesh_gpu_instancing", Unsupported("its instanced copies of meshes are missing")),
        ("EXT_lights_image_based", Unsupported("its image-based lighting is replaced by the default lighting")),
    ]
};

/// How rtgi treats the extension `name`; an extension it does not know is unsupported.
pub fn gltf_extension_support(name: &str) -> ExtensionSupport {
    GLTF_EXTENSIONS
        .iter()
        .find(|(known, _)| *known == name)
        .map_or(ExtensionSupport::Unsupported("whatever it adds to the file is ignored"), |(_, support)| *support)
}

/// The extensions rtgi renders (simulated or approximated), for messages.
pub fn supported_gltf_extensions() -> impl Iterator<Item = &'static str> {
    GLTF_EXTENSIONS.iter().filter(|(_, support)| support.is_supported()).map(|(name, _)| *name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_extension_is_listed_once_and_unknown_ones_are_unsupported() {
        for (i, (name, _)) in GLTF_EXTENSIONS.iter().enumerate() {
            assert!(!GLTF_EXTENSIONS[..i].iter().any(|(other, _)| other == name), "{name} is listed twice");
        }
        assert_eq!(gltf_extension_support("KHR_texture_transform"), ExtensionSupport::Simulated);
        assert!(!gltf_extension_support("EXT_never_heard_of").is_supported());
        assert!(supported_gltf_extensions().any(|e| e == "KHR_materials_unlit"));
        assert!(!supported_gltf_extensions().any(|e| e == "KHR_draco_mesh_compression"));
    }
}
