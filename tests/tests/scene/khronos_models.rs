//! Khronos' glTF test models (`tests/data/khronos/`), checked for what
//! their screenshots make checkable, on the imported scene: the texture
//! lookups the renderer makes at each point of a tile.

use std::path::PathBuf;

use rtgi_math::{Vec2, Vec3, Vec4};
use rtgi_scene::{Material, Scene, TextureId};
use rtgi_tests::workspace_root;

/// Which texture of a material a row of TextureTransformMultiTest tests.
type Slot = fn(&Material) -> Option<TextureId>;

fn khronos(name: &str) -> PathBuf {
    workspace_root().join(format!("tests/data/khronos/{name}/glTF/{name}.gltf"))
}

/// The texture of one slot of `material` looked up over a grid of points
/// across the tile drawn with it (its triangles seen along the axis in
/// which the tile is thinnest), through the texture's coordinate set and
/// transform, or, with `transformed` false, at the raw TEXCOORD_0 as an
/// importer without KHR_texture_transform would.
fn tile_lookups(scene: &Scene, material: &str, slot: Slot, transformed: bool) -> Vec<Vec4> {
    let index = scene.materials.iter().position(|m| m.name == material).unwrap_or_else(|| panic!("no {material}"));
    let texture =
        &scene.textures[slot(&scene.materials[index]).unwrap_or_else(|| panic!("{material}: no texture")).0 as usize];
    let triangles: Vec<_> = scene.triangles.iter().filter(|t| t.material as usize == index).collect();
    let corners = |t: &rtgi_scene::Triangle| t.vertices.map(|v| scene.vertices[v as usize].position);
    let (mut low, mut high) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for t in &triangles {
        for p in corners(t) {
            (low, high) = (low.min(p), high.max(p));
        }
    }
    let extent = high - low;
    let thin = extent.min_position();
    let [a, b] = [(thin + 1) % 3, (thin + 2) % 3];
    let flat = |p: Vec3| Vec2::new(p[a], p[b]);
    const SIDE: usize = 24;
    let mut lookups = Vec::new();
    for i in 0..SIDE {
        for j in 0..SIDE {
            let along = |k: usize| 0.08 + 0.84 * (k as f32 + 0.5) / SIDE as f32;
            let point = Vec2::new(low[a] + along(i) * extent[a], low[b] + along(j) * extent[b]);
            let hit = triangles.iter().find_map(|t| {
                let [p0, p1, p2] = corners(t).map(flat);
                let area = (p1 - p0).perp_dot(p2 - p0);
                let beta = (point - p0).perp_dot(p2 - p0) / area;
                let gamma = (p1 - p0).perp_dot(point - p0) / area;
                (beta >= 0.0 && gamma >= 0.0 && beta + gamma <= 1.0).then_some((*t, beta, gamma))
            });
            let Some((t, beta, gamma)) = hit else { continue };
            let coords = scene.texture_coords(t, beta, gamma);
            lookups.push(if transformed { texture.lookup(coords) } else { texture.sample(coords[0]) });
        }
    }
    assert!(lookups.len() > SIDE * SIDE / 2, "{material}: the grid missed the tile");
    lookups
}

fn mean_difference(x: &[Vec4], y: &[Vec4]) -> f32 {
    assert_eq!(x.len(), y.len());
    x.iter().zip(y).map(|(p, q)| (p.truncate() - q.truncate()).abs().element_sum() / 3.0).sum::<f32>() / x.len() as f32
}

/// TextureTransformMultiTest: "an implementation should render rows of
/// checkmarks, where each of the three tiles in a row look virtually
/// identical" (its README). The tiles of the UV 0 and UV 1 columns read
/// their texture through TEXCOORD_0 and TEXCOORD_1 with a transform; the
/// Sample column untransformed. Every row whose input rtgi reads (all but
/// occlusion) is compared, and, as a control, the same tiles read without
/// the transform show the crossed-out circle instead, far from the sample.
#[test]
fn texture_transform_multi_test_tiles_match_their_sample_in_every_slot() {
    let scene = Scene::load(&khronos("TextureTransformMultiTest")).unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let rows: [(&str, Slot); 8] = [
        ("BaseColor", |m| m.base_color_texture),
        ("Emission", |m| m.emission_texture),
        ("Normal", |m| m.normal_texture.map(|(t, _)| t)),
        ("MetalRough", |m| m.metallic_roughness_texture),
        ("Unlit", |m| m.base_color_texture),
        ("Clearcoat", |m| m.clearcoat.as_ref()?.factor_texture),
        ("ClearcoatRough", |m| m.clearcoat.as_ref()?.roughness_texture),
        ("ClearcoatNormal", |m| m.clearcoat.as_ref()?.normal_texture.map(|(t, _)| t)),
    ];
    for (row, slot) in rows {
        let sample = tile_lookups(&scene, &format!("{row}SampleMat"), slot, true);
        for column in ["Test0", "Test1"] {
            let material = format!("{row}{column}Mat");
            let tile = tile_lookups(&scene, &material, slot, true);
            // The model's own coordinates put the tiles' checkmarks 3% of a
            // tile apart, so alike means within 0.1 on sharp edges (0.03 to
            // 0.08 measured), while the untransformed tile differs 3 to 6
            // times as much (0.1 to 0.5).
            let difference = mean_difference(&tile, &sample);
            assert!(difference < 0.1, "{material}: differs from the sample by {difference}");
            let untransformed = tile_lookups(&scene, &material, slot, false);
            let control = mean_difference(&untransformed, &sample);
            assert!(
                control > 2.5 * difference,
                "{material}: untransformed it differs by {control}, transformed by {difference}: the check cannot tell"
            );
        }
    }
}

/// The centres of the marker quads drawn with `material` (each marker is
/// two triangles, in order).
fn marker_centres(scene: &Scene, material: &str) -> Vec<Vec3> {
    let index = scene.materials.iter().position(|m| m.name == material).unwrap_or_else(|| panic!("no {material}"));
    let triangles: Vec<_> = scene.triangles.iter().filter(|t| t.material as usize == index).collect();
    triangles
        .chunks(2)
        .map(|pair| {
            let corners = pair.iter().flat_map(|t| t.vertices.map(|v| scene.vertices[v as usize].position));
            corners.fold(Vec3::ZERO, |sum, p| sum + p) / (3 * pair.len()) as f32
        })
        .collect()
}

/// Points of the quad drawn with `material` where its texture shows the
/// arrow's dark ink, on a fine grid in the xy plane.
fn arrow_ink(scene: &Scene, material: &str, transformed: bool) -> Vec<Vec2> {
    let index = scene.materials.iter().position(|m| m.name == material).unwrap();
    let texture = &scene.textures[scene.materials[index].base_color_texture.unwrap().0 as usize];
    let triangles: Vec<_> = scene.triangles.iter().filter(|t| t.material as usize == index).collect();
    let flat = |t: &rtgi_scene::Triangle| t.vertices.map(|v| scene.vertices[v as usize].position.truncate());
    let (mut low, mut high) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
    for t in &triangles {
        for p in flat(t) {
            (low, high) = (low.min(p), high.max(p));
        }
    }
    let mut ink = Vec::new();
    const SIDE: usize = 96;
    for i in 0..SIDE {
        for j in 0..SIDE {
            let point = low + (high - low) * Vec2::new(i as f32 + 0.5, j as f32 + 0.5) / SIDE as f32;
            for t in &triangles {
                let [p0, p1, p2] = flat(t);
                let area = (p1 - p0).perp_dot(p2 - p0);
                let (beta, gamma) = ((point - p0).perp_dot(p2 - p0) / area, (p1 - p0).perp_dot(point - p0) / area);
                if beta >= 0.0 && gamma >= 0.0 && beta + gamma <= 1.0 {
                    let coords = scene.texture_coords(t, beta, gamma);
                    let texel = if transformed { texture.lookup(coords) } else { texture.sample(coords[0]) };
                    if texel.w > 0.5 && texel.truncate().element_sum() < 0.6 {
                        ink.push(point);
                    }
                    break;
                }
            }
        }
    }
    ink
}

/// TextureTransformTest: in the bottom row the arrow texture is rotated,
/// scaled, and both and offset; "the green marker indicates the correct
/// rotation. The yellow marker indicates the rotation was not applied"
/// (its README). The arrow's ink must reach the green marker of its quad
/// and not the yellow one; read untransformed, it reaches the yellow one.
#[test]
fn texture_transform_test_arrows_point_at_their_green_markers() {
    let scene = Scene::load(&khronos("TextureTransformTest")).unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let (correct, not_supported) = (marker_centres(&scene, "Correct"), marker_centres(&scene, "NotSupported"));
    // The arrow points down and to the right (in Arrow.png and on every
    // quad, turned by at most 40°): its tip is the ink farthest that way.
    let tip = |ink: &[Vec2]| {
        let towards = Vec2::new(1.0, -1.0).normalize();
        ink.iter().copied().max_by(|a, b| a.dot(towards).total_cmp(&b.dot(towards))).expect("the arrow has ink")
    };
    // A quad's markers lie within 0.6 of its centre (the quads are 1.1 apart).
    let centres =
        [("Rotation", Vec2::new(-1.1, -0.55)), ("Scale", Vec2::new(0.0, -0.55)), ("All", Vec2::new(1.1, -0.55))];
    for (quad, centre) in centres {
        let own = |markers: &[Vec3]| markers.iter().map(|m| m.truncate()).find(|m| m.distance(centre) < 0.6);
        let green = own(&correct).unwrap_or_else(|| panic!("{quad}: no green marker"));
        let tip_at = tip(&arrow_ink(&scene, quad, true));
        let to_green = tip_at.distance(green);
        assert!(to_green < 0.15, "{quad}: the arrow's tip {tip_at} is {to_green} from the green marker");
        if let Some(yellow) = own(&not_supported) {
            assert!(tip_at.distance(yellow) > 2.0 * to_green, "{quad}: the arrow's tip is as near the yellow marker");
            // The control: read untransformed, the arrow points at the yellow marker.
            let untransformed = tip(&arrow_ink(&scene, quad, false));
            assert!(
                untransformed.distance(yellow) < untransformed.distance(green),
                "{quad}: untransformed, the arrow's tip {untransformed} is not nearer the yellow marker: the check cannot tell"
            );
        }
    }
}
