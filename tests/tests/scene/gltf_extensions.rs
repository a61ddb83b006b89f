//! glTF extensions read by hand-written files: a required extension rtgi
//! lacks is refused naming it, material layers and texture transforms
//! carry the values of their JSON, quantized attributes and vertex colours
//! are read, and a material variant is chosen by name.

use rtgi_math::{Vec2, Vec3, Vec4};
use rtgi_scene::{LoadOptions, Scene, SceneError, UvMap};
use rtgi_tests::scratch_dir;

/// One triangle (positions, TEXCOORD_0, TEXCOORD_1 and COLOR_0, all
/// floats) with material 0, and `extra` spliced into the top-level object.
fn triangle(extra: &str, primitive_extra: &str) -> String {
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"TEXCOORD_0":1,"TEXCOORD_1":2,"COLOR_0":3}},"material":0{primitive_extra}}}]}}],
        "buffers":[{{"uri":"tri.bin","byteLength":132}}],
        "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":24}},
                       {{"buffer":0,"byteOffset":60,"byteLength":24}},{{"buffer":0,"byteOffset":84,"byteLength":48}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","max":[1,1,0],"min":[0,0,0]}},
                     {{"bufferView":1,"componentType":5126,"count":3,"type":"VEC2"}},
                     {{"bufferView":2,"componentType":5126,"count":3,"type":"VEC2"}},
                     {{"bufferView":3,"componentType":5126,"count":3,"type":"VEC4"}}]{extra}}}"#
    )
}

fn triangle_bytes() -> Vec<u8> {
    let floats: [f32; 33] = [
        0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, // positions
        0.0, 0.0, 1.0, 0.0, 0.0, 1.0, // uv0
        0.5, 0.5, 0.75, 0.5, 0.5, 0.75, // uv1
        1.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.5, // colours
    ];
    floats.iter().flat_map(|f| f.to_le_bytes()).collect()
}

fn load(name: &str, text: &str, options: &LoadOptions) -> Result<Scene, SceneError> {
    let dir = scratch_dir(&format!("gltf-ext-{name}"));
    std::fs::write(dir.join("tri.bin"), triangle_bytes()).unwrap();
    // A 2 x 1 PNG for the textures.
    let image = image::RgbaImage::from_raw(2, 1, vec![255, 0, 0, 255, 0, 0, 255, 255]).unwrap();
    image.save(dir.join("red-blue.png")).unwrap();
    let path = dir.join(format!("{name}.gltf"));
    std::fs::write(&path, text).unwrap();
    Scene::load_with(&path, options)
}

const PLAIN_MATERIAL: &str = r#","materials":[{"name":"plain"}]"#;

#[test]
fn a_required_extension_rtgi_lacks_is_named_and_one_it_has_is_read() {
    let text = triangle(
        &format!(
            r#"{PLAIN_MATERIAL},"extensionsUsed":["KHR_draco_mesh_compression"],"extensionsRequired":["KHR_draco_mesh_compression"]"#
        ),
        "",
    );
    let error = load("draco", &text, &LoadOptions::default()).unwrap_err();
    let message = error.to_string();
    assert!(matches!(error, SceneError::UnsupportedGltfExtension { .. }), "{message}");
    assert!(message.contains("draco.gltf uses KHR_draco_mesh_compression, which rtgi does not support"), "{message}");
    assert!(message.contains("it supports: ") && message.contains("KHR_texture_transform"), "{message}");
    // Required but supported, including ones the gltf crate has no feature for.
    for extension in ["KHR_texture_transform", "KHR_materials_clearcoat", "KHR_mesh_quantization"] {
        let text = triangle(
            &format!(r#"{PLAIN_MATERIAL},"extensionsUsed":["{extension}"],"extensionsRequired":["{extension}"]"#),
            "",
        );
        let scene = load(extension, &text, &LoadOptions::default()).unwrap_or_else(|e| panic!("{extension}: {e}"));
        assert_eq!(scene.triangles.len(), 1);
    }
    // Used but not required: a warning saying what the image lacks.
    let text = triangle(&format!(r#"{PLAIN_MATERIAL},"extensionsUsed":["EXT_texture_webp"]"#), "");
    let scene = load("webp", &text, &LoadOptions::default()).unwrap();
    assert!(
        scene.warnings.iter().any(|w| w.contains("EXT_texture_webp") && w.contains("WebP textures are missing")),
        "{:?}",
        scene.warnings
    );
}

#[test]
fn second_texture_coordinates_and_vertex_colours_reach_the_vertices() {
    let scene = load("attributes", &triangle(PLAIN_MATERIAL, ""), &LoadOptions::default()).unwrap();
    let corner = |i: usize| scene.vertices[scene.triangles[0].vertices[i] as usize];
    assert_eq!(corner(1).uv1, Vec2::new(0.75, 0.5));
    assert_eq!(corner(2).color, Vec4::new(0.0, 0.0, 1.0, 0.5));
    assert_eq!(corner(0).uv, Vec2::ZERO);
}

#[test]
fn texture_references_keep_their_set_and_transform_in_every_slot() {
    let transform = r#"{"offset":[0.5,0.25],"rotation":1.5707964,"scale":[2,3],"texCoord":1}"#;
    let materials = format!(
        r#","images":[{{"uri":"red-blue.png"}}],"textures":[{{"source":0}}],
        "materials":[{{"name":"layered",
          "pbrMetallicRoughness":{{"baseColorTexture":{{"index":0,"extensions":{{"KHR_texture_transform":{transform}}}}}}},
          "normalTexture":{{"index":0,"texCoord":1,"extensions":{{"KHR_texture_transform":{{"offset":[0.1,0]}}}}}},
          "extensions":{{
            "KHR_materials_clearcoat":{{"clearcoatFactor":0.8,"clearcoatRoughnessFactor":0.3,
               "clearcoatTexture":{{"index":0,"extensions":{{"KHR_texture_transform":{{"scale":[4,4]}}}}}}}},
            "KHR_materials_sheen":{{"sheenColorFactor":[0.5,0.25,1],"sheenRoughnessFactor":0.6}},
            "KHR_materials_specular":{{"specularFactor":0.5,"specularColorFactor":[1,0.5,0.5]}},
            "KHR_materials_iridescence":{{"iridescenceFactor":1,"iridescenceIor":1.8,"iridescenceThicknessMaximum":500}},
            "KHR_materials_anisotropy":{{"anisotropyStrength":0.7,"anisotropyRotation":0.5}},
            "KHR_materials_ior":{{"ior":1.7}},
            "KHR_materials_unlit":{{}}
          }}}}],
        "extensionsUsed":["KHR_texture_transform","KHR_materials_clearcoat","KHR_materials_sheen","KHR_materials_specular",
                          "KHR_materials_iridescence","KHR_materials_anisotropy","KHR_materials_ior","KHR_materials_unlit"]"#
    );
    let scene = load("layers", &triangle(&materials, ""), &LoadOptions::default()).unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let m = &scene.materials[0];
    let map = |id: rtgi_scene::TextureId| *scene.textures[id.0 as usize].uv_map();
    let base = map(m.base_color_texture.unwrap());
    assert_eq!(base.set, 1, "the transform's texCoord overrides the reference's");
    // translation · rotation(π/2) · scale: (u, v) → (3v + 0.5, −2u + 0.25).
    let moved = base.apply([Vec2::ZERO, Vec2::new(1.0, 1.0)]);
    assert!((moved - Vec2::new(3.5, -1.75)).length() < 1e-5, "{moved}");
    let normal = map(m.normal_texture.unwrap().0);
    assert_eq!((normal.set, normal.apply([Vec2::ZERO, Vec2::ZERO])), (1, Vec2::new(0.1, 0.0)));
    let coat = m.clearcoat.as_ref().expect("clearcoat");
    assert_eq!((coat.factor, coat.roughness), (0.8, 0.3));
    assert_eq!(
        map(coat.factor_texture.unwrap()),
        UvMap::from_offset_rotation_scale(0, Vec2::ZERO, 0.0, Vec2::splat(4.0))
    );
    let sheen = m.sheen.as_ref().expect("sheen");
    assert_eq!((sheen.color, sheen.roughness), (Vec3::new(0.5, 0.25, 1.0), 0.6));
    assert_eq!((m.dielectric_specular.factor, m.dielectric_specular.color), (0.5, Vec3::new(1.0, 0.5, 0.5)));
    let film = m.iridescence.as_ref().expect("iridescence");
    assert_eq!((film.factor, film.ior, film.thickness_min, film.thickness_max), (1.0, 1.8, 100.0, 500.0));
    let anisotropy = m.anisotropy.as_ref().expect("anisotropy");
    assert_eq!((anisotropy.strength, anisotropy.rotation), (0.7, 0.5));
    assert_eq!(m.ior, 1.7);
    assert!(m.unlit);
    // One image, three uses: the normal map and the coat's factor (linear,
    // each with its own map) and the base colour (sRGB).
    assert_eq!(scene.textures.len(), 3, "{:?}", scene.textures);
}

#[test]
fn a_variant_is_chosen_by_name_and_an_unknown_one_is_refused_with_the_list() {
    let extra = r#","materials":[{"name":"default"},{"name":"midnight"},{"name":"beach"}],
        "extensionsUsed":["KHR_materials_variants"],
        "extensions":{"KHR_materials_variants":{"variants":[{"name":"Midnight"},{"name":"Beach"}]}}"#;
    let mapping = r#","extensions":{"KHR_materials_variants":{"mappings":[{"material":1,"variants":[0]},{"material":2,"variants":[1]}]}}"#;
    let text = triangle(extra, mapping);
    let material = |variant: Option<&str>| {
        let options = LoadOptions { gltf_variant: variant.map(str::to_owned), ..LoadOptions::default() };
        let scene = load(&format!("variant-{variant:?}"), &text, &options)?;
        assert_eq!(scene.material_variants, ["Midnight", "Beach"]);
        Ok::<_, SceneError>(scene.materials[scene.triangles[0].material as usize].name.clone())
    };
    assert_eq!(material(None).unwrap(), "default");
    assert_eq!(material(Some("Midnight")).unwrap(), "midnight");
    assert_eq!(material(Some("Beach")).unwrap(), "beach");
    let error = material(Some("Dawn")).unwrap_err();
    let message = error.to_string();
    assert!(matches!(error, SceneError::UnknownMaterialVariant { .. }), "{message}");
    assert!(message.contains("has no material variant 'Dawn' (its variants: Midnight, Beach)"), "{message}");
}

#[test]
fn quantized_attributes_are_read_as_their_normalised_values() {
    // KHR_mesh_quantization: positions as unsigned shorts (not normalised,
    // scaled by the node), texture coordinates as normalised unsigned bytes.
    let mut bytes: Vec<u8> = Vec::new();
    for p in [[0u16, 0, 0], [2, 0, 0], [0, 2, 0]] {
        for c in p {
            bytes.extend(c.to_le_bytes());
        }
        bytes.extend([0, 0]); // each element padded to 4-byte alignment
    }
    // Texture coordinates as normalised bytes, each padded to 4 bytes.
    bytes.extend([0u8, 0, 0, 0, 255, 0, 0, 0, 0, 255, 0, 0]);
    let text = r#"{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0,"scale":[0.5,0.5,0.5]}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":1}}]}],
        "buffers":[{"uri":"q.bin","byteLength":36}],
        "bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":24,"byteStride":8},{"buffer":0,"byteOffset":24,"byteLength":12,"byteStride":4}],
        "accessors":[{"bufferView":0,"componentType":5123,"count":3,"type":"VEC3","max":[2,2,0],"min":[0,0,0]},
                     {"bufferView":1,"componentType":5121,"normalized":true,"count":3,"type":"VEC2"}],
        "extensionsUsed":["KHR_mesh_quantization"],"extensionsRequired":["KHR_mesh_quantization"]}"#;
    let dir = scratch_dir("gltf-ext-quantized");
    std::fs::write(dir.join("q.bin"), &bytes).unwrap();
    std::fs::write(dir.join("q.gltf"), text).unwrap();
    let scene = Scene::load(&dir.join("q.gltf")).unwrap();
    let corner = |i: usize| scene.vertices[scene.triangles[0].vertices[i] as usize];
    assert_eq!(corner(1).position, Vec3::new(1.0, 0.0, 0.0));
    assert_eq!(corner(2).position, Vec3::new(0.0, 1.0, 0.0));
    assert_eq!(corner(1).uv, Vec2::new(1.0, 0.0));
    assert_eq!(corner(2).uv, Vec2::new(0.0, 1.0));
}
