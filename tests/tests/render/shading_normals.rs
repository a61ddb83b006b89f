//! Smooth shading without black fringes: where an interpolated normal
//! faces away from a viewer who sees the true surface from the front, the
//! renderer bends it back (`shading_normal.rs`). A low-poly sphere with
//! smooth normals must be about as bright along its silhouette as the same
//! sphere shaded flat, under a uniform sky where a flat white sphere is
//! exactly as bright everywhere.

use rtgi_accel::{AccelKind, BuildParams};
use rtgi_image::HdrImage;
use rtgi_math::{Vec3, luminance};
use rtgi_render::lights::Environment;
use rtgi_render::{Integrator, PixelSampler, RenderSettings, render};
use rtgi_scene::{Camera, Scene};

const SIZE: u32 = 96;
const MTL: &str = "newmtl white\nKd 0.8 0.8 0.8\n";

/// A UV sphere of radius 1 with `slices` × `stacks` facets, with a normal
/// per vertex (smooth) or per facet (flat).
fn sphere(slices: u32, stacks: u32, smooth: bool) -> Scene {
    let point = |i: u32, j: u32| {
        let (theta, phi) =
            (std::f32::consts::PI * j as f32 / stacks as f32, std::f32::consts::TAU * i as f32 / slices as f32);
        Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin())
    };
    let mut obj = String::from("mtllib s.mtl\nusemtl white\n");
    let mut faces = Vec::new();
    for j in 0..stacks {
        for i in 0..slices {
            let (a, b, c, d) = (point(i, j), point(i + 1, j), point(i + 1, j + 1), point(i, j + 1));
            // Counter-clockwise seen from outside; the poles' degenerate halves left out.
            if j > 0 {
                faces.push([a, c, b]);
            }
            if j + 1 < stacks {
                faces.push([a, d, c]);
            }
        }
    }
    for (k, corners) in faces.iter().enumerate() {
        let facet = (corners[1] - corners[0]).cross(corners[2] - corners[0]).normalize();
        for p in corners {
            obj += &format!("v {} {} {}\n", p.x, p.y, p.z);
            let n = if smooth { *p } else { facet };
            obj += &format!("vn {} {} {}\n", n.x, n.y, n.z);
        }
        let v = 3 * k + 1;
        obj += &format!("f {v}//{v} {}//{} {}//{}\n", v + 1, v + 1, v + 2, v + 2);
    }
    rtgi_scene::obj::load_from_text(&obj, MTL, "sphere.obj").expect("the sphere loads")
}

fn render_sphere(scene: &Scene, integrator: Integrator, samples_per_pixel: u32) -> HdrImage {
    let accel = AccelKind::Bvh8.build(&scene.triangle_positions(), &BuildParams::default());
    let camera = Camera::look_at(Vec3::new(0.0, 0.3, 4.0), Vec3::ZERO, Vec3::Y, 0.6);
    let settings = RenderSettings {
        width: SIZE,
        height: SIZE,
        samples_per_pixel,
        sampler: PixelSampler::Stratified,
        integrator,
        environment: Some(Environment::Uniform(Vec3::ONE)),
        ..RenderSettings::default()
    };
    render(scene, accel.as_ref(), &camera, &settings, &|_| {}).0
}

/// The mean luminance of `image` over the pixels of `band`.
fn mean_over(image: &HdrImage, band: &[(u32, u32)]) -> f32 {
    band.iter().map(|&(x, y)| luminance(image.get(x, y))).sum::<f32>() / band.len() as f32
}

#[test]
fn a_smooth_low_poly_sphere_has_no_dark_fringe_along_its_silhouette() {
    let (smooth, flat) = (sphere(8, 5, true), sphere(8, 5, false));
    // The silhouette band: pixels fully covered by the sphere (albedo 0.8
    // at every sample) beside an uncovered pixel.
    let albedo = render_sphere(&flat, Integrator::Albedo, 4);
    let covered = |x: i64, y: i64| {
        (0..SIZE as i64).contains(&x)
            && (0..SIZE as i64).contains(&y)
            && (albedo.get(x as u32, y as u32).x - 0.8).abs() < 1e-4
    };
    let mut band = Vec::new();
    for y in 0..SIZE as i64 {
        for x in 0..SIZE as i64 {
            let near_edge = (-1..=1).any(|dy| (-1..=1).any(|dx| !covered(x + dx, y + dy)));
            if covered(x, y) && near_edge {
                band.push((x as u32, y as u32));
            }
        }
    }
    assert!(band.len() > 100, "the band is {} pixels", band.len());

    let flat_band = mean_over(&render_sphere(&flat, Integrator::Path, 64), &band);
    let smooth_image = render_sphere(&smooth, Integrator::Path, 64);
    let smooth_band = mean_over(&smooth_image, &band);
    // Without the bend: 0.56 against 0.80, and 69 of the 300 band pixels
    // darker than 0.3; with it 0.79, and none.
    let dark = band.iter().filter(|&&(x, y)| luminance(smooth_image.get(x, y)) < 0.3).count();
    assert!(dark <= band.len() / 100, "{dark} of {} silhouette pixels are dark", band.len());
    // A white convex Lambertian sphere under a uniform sky of 1 reflects
    // its albedo, 0.8, wherever its normal is the true one.
    assert!((flat_band - 0.8).abs() < 0.03, "flat silhouette band: {flat_band}");
    // Smooth normals lean away from the facets, so rays leaving below the
    // true surface are lost: somewhat darker, never black.
    assert!(
        smooth_band > 0.85 * flat_band,
        "smooth silhouette band {smooth_band} against flat {flat_band}: a dark fringe"
    );
}

/// What a file gives per vertex reaches the path tracer, which reads a
/// flat face's normal once per triangle and skips vertex colours where a
/// scene has none: a flat sphere whose normals are three times too long
/// and whose vertices are red is a red Lambertian sphere of albedo 0.8
/// under the uniform sky, so it reflects (0.8, 0, 0) wherever it covers a
/// pixel, green and blue exactly 0.
#[test]
fn flat_faces_with_long_normals_and_red_vertices_reflect_red_at_their_albedo() {
    let mut scene = sphere(8, 5, false);
    for vertex in &mut scene.vertices {
        vertex.normal *= 3.0;
        vertex.color = rtgi_math::Vec4::new(1.0, 0.0, 0.0, 1.0);
    }
    let albedo = render_sphere(&scene, Integrator::Albedo, 4);
    let red = |x: u32, y: u32| (albedo.get(x, y) - Vec3::new(0.8, 0.0, 0.0)).abs().max_element() < 1e-4;
    // Pixels inside the sphere's outline, a pixel away from it: the path
    // tracer's samples there cannot see the sky past the silhouette.
    let covered: Vec<(u32, u32)> = (1..SIZE - 1)
        .flat_map(|y| (1..SIZE - 1).map(move |x| (x, y)))
        .filter(|&(x, y)| (y - 1..=y + 1).all(|y| (x - 1..=x + 1).all(|x| red(x, y))))
        .collect();
    assert!(covered.len() > 1000, "the sphere covers {} pixels", covered.len());
    let image = render_sphere(&scene, Integrator::Path, 16);
    let mean = covered.iter().map(|&(x, y)| image.get(x, y)).sum::<Vec3>() / covered.len() as f32;
    assert!((mean.x - 0.8).abs() < 0.01, "mean over the sphere {mean}");
    let brightest_other = covered.iter().map(|&(x, y)| image.get(x, y).y.max(image.get(x, y).z)).fold(0.0, f32::max);
    assert_eq!(brightest_other, 0.0, "green or blue reflected by a red sphere");
}
