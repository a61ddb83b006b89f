//! Every shared glTF model is seen the way its upstream screenshot shows
//! it: same up, same handedness. Each is rendered small from its
//! recommended view (the file's camera, else straight from the front, +Z,
//! the side glTF models face) and compared with the screenshot beside it
//! in coarse features that a flip or a wrong up axis changes: which half
//! of the frame holds more of the model, left or right, top or bottom, and
//! the proportions of the model's outline.

use std::path::Path;

use rtgi_accel::{AccelKind, BuildParams};
use rtgi_render::{Integrator, PixelSampler, RenderSettings, render};
use rtgi_scene::{Camera, Scene};
use rtgi_tests::shared_scenes;

/// Coarse features of a silhouette: the share of its pixels in the right
/// half and in the bottom half, and its bounding box's width over height.
#[derive(Debug)]
struct Silhouette {
    right: f32,
    bottom: f32,
    aspect: f32,
}

fn silhouette(width: u32, height: u32, covered: impl Fn(u32, u32) -> bool) -> Option<Silhouette> {
    let (mut count, mut right, mut bottom) = (0u32, 0u32, 0u32);
    let (mut x0, mut x1, mut y0, mut y1) = (u32::MAX, 0, u32::MAX, 0);
    for y in 0..height {
        for x in 0..width {
            if covered(x, y) {
                count += 1;
                right += (2 * x >= width) as u32;
                bottom += (2 * y >= height) as u32;
                (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
            }
        }
    }
    (count > 20).then(|| Silhouette {
        right: right as f32 / count as f32,
        bottom: bottom as f32 / count as f32,
        aspect: (x1 - x0 + 1) as f32 / (y1 - y0 + 1) as f32,
    })
}

/// The screenshot's silhouette: pixels that differ from the background,
/// taken from the corners; `None` when the corners disagree (a gradient or
/// a scene behind the model), where no silhouette can be read.
fn screenshot_silhouette(path: &Path) -> Option<Silhouette> {
    let image = image::open(path).ok()?.to_rgba8();
    let (w, h) = image.dimensions();
    let pixel = |x: u32, y: u32| {
        let p = image.get_pixel(x, y).0;
        // Transparent pixels are background whatever their colour.
        if p[3] < 128 { None } else { Some([p[0] as i32, p[1] as i32, p[2] as i32]) }
    };
    let corners = [pixel(0, 0), pixel(w - 1, 0), pixel(0, h - 1), pixel(w - 1, h - 1)];
    let distance = |a: [i32; 3], b: [i32; 3]| (0..3).map(|i| (a[i] - b[i]).abs()).max().unwrap_or(0);
    let background = corners[0];
    if corners.iter().any(|c| match (c, background) {
        (Some(c), Some(b)) => distance(*c, b) > 12,
        (None, None) => false,
        _ => true,
    }) {
        return None;
    }
    silhouette(w, h, |x, y| match (pixel(x, y), background) {
        (None, _) => false,
        (Some(p), Some(b)) => distance(p, b) > 40,
        (Some(_), None) => true,
    })
}

fn rendered_silhouette(scene: &Scene, width: u32, height: u32) -> Option<Silhouette> {
    let accel = AccelKind::Bvh8.build(&scene.triangle_positions(), &BuildParams::default());
    let camera = scene
        .cameras
        .first()
        .copied()
        .unwrap_or_else(|| Camera::framing(&scene.bounds(), 40f32.to_radians(), width as f32 / height as f32));
    let settings = RenderSettings {
        width,
        height,
        samples_per_pixel: 1,
        sampler: PixelSampler::Center,
        integrator: Integrator::Depth,
        ..RenderSettings::default()
    };
    let (image, _) = render(scene, accel.as_ref(), &camera, &settings, &|_| {});
    silhouette(width, height, |x, y| image.get(x, y).x > 0.0)
}

#[test]
fn every_glb_and_gltf_model_faces_as_in_its_screenshot() {
    let root = shared_scenes().join("gltf");
    let Ok(models) = std::fs::read_dir(&root) else {
        rtgi_tests::skip_without(
            rtgi_tests::Requirement::Scenes,
            &format!("{} not found (set {})", root.display(), rtgi_tests::SCENES_VARIABLE),
        );
        return;
    };
    let mut compared = 0;
    for model in models.flatten() {
        let folder = model.path();
        let name = model.file_name().to_string_lossy().into_owned();
        let Some(file) = ["glTF", "glTF-Binary"].iter().find_map(|sub| {
            std::fs::read_dir(folder.join(sub))
                .ok()?
                .flatten()
                .map(|f| f.path())
                .find(|p| p.extension().is_some_and(|e| e == "gltf" || e == "glb"))
        }) else {
            continue;
        };
        let Some(shot) =
            std::fs::read_dir(folder.join("screenshot")).ok().and_then(|d| d.flatten().map(|f| f.path()).next())
        else {
            continue;
        };
        let Some(expected) = screenshot_silhouette(&shot) else {
            eprintln!("{name}: the screenshot's background is not plain; compared by eye only");
            continue;
        };
        let scene = Scene::load(&file).unwrap_or_else(|e| panic!("{e}"));
        let (w, h) = image::image_dimensions(&shot).unwrap();
        let height = 72;
        let width = (height as f32 * w as f32 / h as f32).round() as u32;
        let actual = rendered_silhouette(&scene, width, height).unwrap_or_else(|| panic!("{name}: nothing in view"));
        eprintln!("{name}: screenshot {expected:?}, render {actual:?}");
        // Halves compared only where both are clearly lopsided: a symmetric
        // model (a cube seen head-on) shows nothing of its orientation, and
        // a screenshot taken from an angle makes a symmetric one look lopsided.
        for (what, e, a) in [("right", expected.right, actual.right), ("bottom", expected.bottom, actual.bottom)] {
            if (e - 0.5).abs() > 0.08 && (a - 0.5).abs() > 0.02 {
                assert_eq!(
                    e > 0.5,
                    a > 0.5,
                    "{name}: the {what} half holds {e:.2} of the screenshot's model, {a:.2} of ours"
                );
            }
        }
        let ratio = actual.aspect / expected.aspect;
        assert!(
            (1.0 / 1.6..1.6).contains(&ratio),
            "{name}: outline {:.2} wide per high, screenshot {:.2}",
            actual.aspect,
            expected.aspect
        );
        compared += 1;
    }
    eprintln!("{compared} models compared with their screenshots");
}
