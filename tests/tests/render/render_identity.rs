//! Swapping the acceleration structure changes the time of a render, never
//! its bits: path-traced renders of shared scenes (default depth, a few
//! samples) are identical, pixel for pixel and bit for bit, whichever
//! structure traces their rays. The shared Cornell boxes have coincident
//! triangles, where an inexact structure picks another triangle at a tie.

use rtgi_accel::{AccelKind, BuildParams};
use rtgi_render::{PixelSampler, RenderSettings, frame_scene, render};
use rtgi_scene::Scene;
use rtgi_tests::shared_scene;

fn assert_identical_across_structures(relative: &str, size: u32, samples_per_pixel: u32) {
    let Some(path) = shared_scene(relative) else { return };
    let scene = Scene::load(&path).unwrap();
    let triangles = scene.triangle_positions();
    let settings = RenderSettings {
        width: size,
        height: size,
        samples_per_pixel,
        sampler: PixelSampler::Stratified,
        seed: 7,
        ..RenderSettings::default()
    };
    let mut reference: Option<(AccelKind, Vec<u32>)> = None;
    for &kind in AccelKind::ALL {
        let accel = kind.build(&triangles, &BuildParams::default());
        // The framing uses the structure too; it must not differ either.
        let camera = frame_scene(&scene, accel.as_ref(), 40f32.to_radians(), 1.0);
        let image = render(&scene, accel.as_ref(), &camera, &settings, &|_| {}).0;
        let bits: Vec<u32> = image.pixels().iter().flat_map(|p| p.to_array()).map(f32::to_bits).collect();
        match &reference {
            None => reference = Some((kind, bits)),
            Some((first, expected)) => {
                let differing = bits.iter().zip(expected).filter(|(a, b)| a != b).count();
                assert_eq!(differing, 0, "{relative}: {differing} channel values differ between {first} and {kind}");
            }
        }
    }
}

#[test]
fn cornell_box_original_renders_identically_with_every_structure() {
    assert_identical_across_structures("cornell-box/CornellBox-Original.obj", 40, 4);
}

#[test]
fn cornell_box_mirror_renders_identically_with_every_structure() {
    assert_identical_across_structures("cornell-box/CornellBox-Mirror.obj", 40, 4);
}

#[test]
fn bunny_renders_identically_with_every_structure() {
    assert_identical_across_structures("bunny/stanford-bunny.obj", 20, 1);
}
