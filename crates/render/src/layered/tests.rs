//! The layered model as a whole: sampling agrees with evaluation and the
//! density, the sampled directions follow the density (χ²), energy is
//! conserved (white furnace), and anisotropy and iridescence reduce to the
//! plain model where they should.

use std::f32::consts::TAU;

use rtgi_math::glam::DVec3;
use rtgi_math::{Rng, Vec2, Vec3};

use super::chi_square::chi_square_test;
use super::*;

fn direction(theta: f32, phi: f32) -> Vec3 {
    Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
}

/// A base with no lobe of its own, for a layer alone: black, no specular.
fn black() -> PbrLayers {
    PbrLayers { specular_factor: 0.0, ..PbrLayers::isotropic(Vec3::ZERO, 0.0, 0.5) }
}

fn film(factor: f32) -> Option<Iridescence> {
    Some(Iridescence { factor, ior: 1.3, thickness_nm: 380.0 })
}

fn tilted_normal() -> Vec3 {
    direction(0.35, 0.8)
}

/// Every combination the tests run over, named.
fn configurations() -> Vec<(&'static str, PbrLayers)> {
    let red = Vec3::new(0.8, 0.1, 0.05);
    let gold = Vec3::new(1.0, 0.77, 0.34);
    vec![
        (
            "pure diffuse",
            PbrLayers { specular_factor: 0.0, ..PbrLayers::isotropic(Vec3::new(0.7, 0.5, 0.3), 0.0, 0.5) },
        ),
        ("smooth metal", PbrLayers::isotropic(gold, 1.0, 0.02)),
        ("rough metal", PbrLayers::isotropic(gold, 1.0, 0.6)),
        ("anisotropic metal", PbrLayers { alpha_x: 0.05, alpha_y: 0.5, ..PbrLayers::isotropic(gold, 1.0, 0.05) }),
        ("specular 0", PbrLayers { specular_factor: 0.0, ..PbrLayers::isotropic(red, 0.0, 0.2) }),
        (
            "tinted specular",
            PbrLayers {
                specular_color: Vec3::new(2.0, 0.5, 0.1),
                specular_factor: 0.7,
                ior: 1.8,
                ..PbrLayers::isotropic(red, 0.0, 0.15)
            },
        ),
        (
            "sheen on black",
            PbrLayers { sheen: Some(Sheen { color: Vec3::new(0.9, 0.6, 0.8), roughness: 0.4 }), ..black() },
        ),
        (
            "tilted coat on red",
            PbrLayers {
                specular_factor: 0.0,
                clearcoat: Some(Clearcoat { factor: 1.0, alpha: 0.03, normal: tilted_normal() }),
                ..PbrLayers::isotropic(red, 0.0, 0.5)
            },
        ),
        ("iridescent dielectric", PbrLayers { iridescence: film(1.0), ..PbrLayers::isotropic(red, 0.0, 0.1) }),
        ("iridescent metal", PbrLayers { iridescence: film(0.8), ..PbrLayers::isotropic(gold, 1.0, 0.25) }),
        (
            "everything",
            PbrLayers {
                base_color: Vec3::new(0.6, 0.4, 0.9),
                metallic: 0.3,
                alpha_x: 0.08,
                alpha_y: 0.3,
                ior: 1.6,
                specular_factor: 0.8,
                specular_color: Vec3::new(1.0, 0.9, 0.7),
                iridescence: Some(Iridescence { factor: 0.6, ior: 1.4, thickness_nm: 520.0 }),
                sheen: Some(Sheen { color: Vec3::new(0.3, 0.5, 0.4), roughness: 0.5 }),
                clearcoat: Some(Clearcoat { factor: 0.8, alpha: 0.01, normal: tilted_normal() }),
            },
        ),
    ]
}

fn configuration(name: &str) -> PbrLayers {
    configurations().into_iter().find(|(n, _)| *n == name).map(|(_, material)| material).expect("a named configuration")
}

fn views() -> Vec<Vec3> {
    let mut views = Vec::new();
    for (theta, phi) in [(0.0f32, 0.0f32), (0.4, 0.3), (1.0, 2.2), (1.45, -1.1)] {
        let wo = direction(theta, phi);
        views.push(wo);
        views.push(Vec3::new(wo.x, wo.y, -wo.z));
    }
    views
}

#[test]
fn samples_agree_with_eval_and_pdf() {
    let mut rng = Rng::new(41, 42);
    for (name, material) in configurations() {
        for wo in views() {
            let mut found = 0;
            for _ in 0..1000 {
                let Some(s) = material.sample(wo, Vec2::new(rng.next_f32(), rng.next_f32())) else { continue };
                found += 1;
                assert!(s.wi.z * wo.z > 0.0, "{name} at {wo}: sampled {} through the surface", s.wi);
                assert!((s.wi.length() - 1.0).abs() < 1e-4, "{name}: {}", s.wi);
                assert_eq!(s.pdf, material.pdf(wo, s.wi), "{name} at {wo}, {}", s.wi);
                assert_eq!(s.value, material.eval(wo, s.wi), "{name} at {wo}, {}", s.wi);
                assert!(s.pdf > 0.0 && s.pdf.is_finite(), "{name}: pdf {}", s.pdf);
                assert!(s.value.is_finite() && s.value.min_element() >= 0.0, "{name}: value {}", s.value);
                assert!(!s.delta && s.eta == 1.0);
            }
            // (A tilted coat seen at grazing sends half its samples below the surface.)
            assert!(found > 300, "{name} at {wo}: only {found} of 1000 samples succeeded");
        }
    }
}

#[test]
fn degenerate_directions_give_zero_and_never_nan() {
    let tangent = Vec3::new(1.0, 0.0, 0.0);
    for (name, material) in configurations() {
        for (wo, wi) in [
            (tangent, Vec3::Z),
            (Vec3::Z, tangent),
            (Vec3::Z, -Vec3::Z),
            (direction(0.5, 0.0), -direction(0.5, 0.0)),
            (Vec3::NAN, Vec3::Z),
            (Vec3::Z, Vec3::NAN),
        ] {
            assert_eq!(material.eval(wo, wi), Vec3::ZERO, "{name}: {wo}, {wi}");
            assert_eq!(material.pdf(wo, wi), 0.0, "{name}: {wo}, {wi}");
        }
        for u in [Vec2::ZERO, Vec2::new(0.999_999_9, 0.999_999_9), Vec2::new(0.5, 0.0)] {
            assert!(material.sample(tangent, u).is_none() && material.sample(Vec3::NAN, u).is_none(), "{name}");
            if let Some(s) = material.sample(Vec3::Z, u) {
                assert!(s.value.is_finite() && s.pdf.is_finite(), "{name}: {s:?}");
            }
        }
        // Grazing but not degenerate: finite.
        let grazing = Vec3::new((1.0f32 - 1e-8).sqrt(), 0.0, 1e-4);
        assert!(material.eval(grazing, direction(0.3, 2.0)).is_finite(), "{name}");
        assert!(material.pdf(grazing, grazing).is_finite(), "{name}");
    }
}

#[test]
fn evaluation_is_reciprocal() {
    // Albedo scaling by both directions keeps f(wo, wi) = f(wi, wo); a
    // tilted coat normal does not (it takes light by its own cosine).
    let mut rng = Rng::new(43, 44);
    for (name, material) in configurations() {
        let untilted = |coat: Clearcoat| Clearcoat { normal: Vec3::Z, ..coat };
        let material = PbrLayers { clearcoat: material.clearcoat.map(untilted), ..material };
        for _ in 0..300 {
            let wo = direction(1.5 * rng.next_f32(), TAU * rng.next_f32());
            let wi = direction(1.5 * rng.next_f32(), TAU * rng.next_f32());
            let (a, b) = (material.eval(wo, wi), material.eval(wi, wo));
            assert!((a - b).abs().max_element() <= 1e-4 * a.max_element().max(1.0), "{name}: {a} vs {b}");
        }
    }
}

#[test]
fn absent_lobes_are_never_chosen() {
    // A lobe that is not there has no share of the samples; one that is has at least the floor.
    let lobes = |material: PbrLayers| material.view(direction(0.6, 0.2)).unwrap().choice.map(|p| p > 0.0);
    assert_eq!(lobes(configuration("pure diffuse")), [true, false, false, false]);
    assert_eq!(lobes(PbrLayers::isotropic(Vec3::ONE, 1.0, 0.3)), [false, true, false, false]);
    assert_eq!(lobes(configuration("sheen on black")), [false, false, true, false]);
    assert_eq!(lobes(configuration("tilted coat on red")), [true, false, false, true]);
    let zero_layers = PbrLayers {
        sheen: Some(Sheen { color: Vec3::ZERO, roughness: 0.5 }),
        clearcoat: Some(Clearcoat { factor: 0.0, alpha: 0.1, normal: Vec3::Z }),
        iridescence: Some(Iridescence { factor: 0.0, ior: 1.3, thickness_nm: 400.0 }),
        ..PbrLayers::isotropic(Vec3::ONE, 0.5, 0.3)
    };
    assert_eq!(lobes(zero_layers), [true, true, false, false]);
    let everything = configuration("everything").view(direction(0.6, 0.2)).unwrap().choice;
    assert!(everything.iter().all(|&p| p >= LOBE_FLOOR), "{everything:?}");
    assert!((everything.iter().sum::<f32>() - 1.0).abs() < 1e-6);
    assert!(black().sample(Vec3::Z, Vec2::splat(0.5)).is_none());
}

#[test]
fn chi_square_of_each_lobe_and_the_mixture() {
    // Lobes alone, then together. 100k samples each; significance 0.01
    // overall, Šidák-corrected for the number of tests.
    let wo = direction(0.8, 0.4);
    let cases: Vec<(&str, PbrLayers)> = vec![
        ("diffuse", configuration("pure diffuse")),
        ("isotropic specular", PbrLayers::isotropic(Vec3::ONE, 1.0, 0.3)),
        ("anisotropic specular", configuration("anisotropic metal")),
        ("sheen", PbrLayers { sheen: Some(Sheen { color: Vec3::ONE, roughness: 0.3 }), ..black() }),
        (
            "tilted coat",
            PbrLayers { clearcoat: Some(Clearcoat { factor: 1.0, alpha: 0.2, normal: tilted_normal() }), ..black() },
        ),
        ("mixture", configuration("everything")),
    ];
    let alpha = 1.0 - 0.99f64.powf(1.0 / cases.len() as f64);
    let mut rng = Rng::new(45, 46);
    let mut failures = Vec::new();
    for (name, material) in cases {
        let outcome = chi_square_test(
            |u| material.sample(wo, u).map(|s| s.wi),
            |wi| material.pdf(wo, wi),
            100_000,
            &mut rng,
            alpha,
        );
        println!("{name}: {}", outcome.summary());
        if !outcome.passed() {
            failures.push(format!("{name}: {}", outcome.summary()));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The importance-sampled directional albedo ∫ f cos θi dωi at `wo` and
/// its standard error, per channel: batches of `batch` samples until the
/// error is below 0.003 or eight batches are taken.
fn albedo(material: &PbrLayers, wo: Vec3, batch: usize, rng: &mut Rng) -> (Vec3, Vec3) {
    let (mut sum, mut sum2, mut n) = (DVec3::ZERO, DVec3::ZERO, 0usize);
    loop {
        for _ in 0..batch {
            if let Some(s) = material.sample(wo, Vec2::new(rng.next_f32(), rng.next_f32())) {
                let x = (s.value * s.wi.z.abs() / s.pdf).as_dvec3();
                sum += x;
                sum2 += x * x;
            }
        }
        n += batch;
        let mean = sum / n as f64;
        let sigma = ((sum2 / n as f64 - mean * mean) / n as f64).max(DVec3::ZERO).map(f64::sqrt);
        if sigma.max_element() < 0.003 || n >= 8 * batch {
            return (mean.as_vec3(), sigma.as_vec3());
        }
    }
}

/// What a white Lambertian base reflects from `wo` under a layer of
/// directional albedo `layer_albedo(cos θ)` (times its weight), dimmed as
/// [`PbrLayers::eval`] dims it: ∫ (1 − max(E(wo), E(wi))) cos θi / π dωi,
/// by the midpoint rule over cos θi.
fn diffuse_below(layer_albedo: impl Fn(f32) -> f32, cos_o: f32) -> f32 {
    let steps = 4000;
    let albedo_o = layer_albedo(cos_o);
    (0..steps)
        .map(|k| {
            let mu = (k as f32 + 0.5) / steps as f32;
            2.0 * mu * (1.0 - albedo_o.max(layer_albedo(mu)))
        })
        .sum::<f32>()
        / steps as f32
}

#[test]
fn white_furnace_never_gains_energy() {
    let white = Vec3::ONE;
    let sheen = Some(Sheen { color: white, roughness: 0.3 });
    let smooth_sheen = Some(Sheen { color: white, roughness: 0.07 });
    let coat = Some(Clearcoat { factor: 1.0, alpha: 0.3, normal: Vec3::Z });
    let cases = [
        ("dielectric", PbrLayers::isotropic(white, 0.0, 0.3)),
        ("smooth dielectric", PbrLayers::isotropic(white, 0.0, 0.02)),
        ("anisotropic dielectric", PbrLayers { alpha_x: 0.02, alpha_y: 0.6, ..PbrLayers::isotropic(white, 0.0, 0.3) }),
        (
            "dense tinted dielectric",
            PbrLayers { ior: 2.5, specular_color: Vec3::new(1.5, 1.0, 0.2), ..PbrLayers::isotropic(white, 0.0, 0.2) },
        ),
        ("iridescent dielectric", PbrLayers { iridescence: film(1.0), ..PbrLayers::isotropic(white, 0.0, 0.2) }),
        ("metal", PbrLayers::isotropic(white, 1.0, 0.3)),
        ("iridescent metal", PbrLayers { iridescence: film(1.0), ..PbrLayers::isotropic(white, 1.0, 0.2) }),
        ("sheen alone", PbrLayers { sheen: smooth_sheen, ..black() }),
        ("sheen on dielectric", PbrLayers { sheen, ..PbrLayers::isotropic(white, 0.0, 0.3) }),
        (
            "smooth sheen on diffuse",
            PbrLayers { sheen: smooth_sheen, specular_factor: 0.0, ..PbrLayers::isotropic(white, 0.0, 0.3) },
        ),
        ("coat on dielectric", PbrLayers { clearcoat: coat, ..PbrLayers::isotropic(white, 0.0, 0.3) }),
        ("sheen and coat on metal", PbrLayers { sheen, clearcoat: coat, ..PbrLayers::isotropic(white, 1.0, 0.4) }),
        (
            "sheen and coat on dielectric",
            PbrLayers {
                sheen,
                clearcoat: Some(Clearcoat { factor: 1.0, alpha: 0.01, normal: Vec3::Z }),
                ..PbrLayers::isotropic(white, 0.0, 0.5)
            },
        ),
        (
            "tilted coat on diffuse",
            PbrLayers {
                clearcoat: Some(Clearcoat { factor: 1.0, alpha: 0.2, normal: tilted_normal() }),
                specular_factor: 0.0,
                ..PbrLayers::isotropic(white, 0.0, 0.3)
            },
        ),
        ("everything, white", PbrLayers { base_color: white, metallic: 0.3, sheen, ..configuration("everything") }),
    ];
    let mut rng = Rng::new(47, 48);
    for (name, material) in cases {
        for theta in [0.0f32, 0.7, 1.2, 1.5] {
            let (e, sigma) = albedo(&material, direction(theta, 0.9), 20_000, &mut rng);
            println!("{name} at θ = {theta}: {:.4} ± {:.4}", e.max_element(), sigma.max_element());
            assert!(e.max_element() <= 1.01, "{name} at {theta}: albedo {e} ± {sigma}");
            assert!(sigma.max_element() < 0.003, "{name} at {theta}: too noisy to tell, ± {sigma}");
        }
    }
}

#[test]
fn white_furnace_losses_are_the_expected_ones() {
    let mut rng = Rng::new(49, 50);
    let n = 20_000;
    // A smooth white metal keeps nearly everything.
    let (smooth, _) = albedo(&PbrLayers::isotropic(Vec3::ONE, 1.0, 0.03), direction(0.4, 0.0), n, &mut rng);
    assert!(smooth.min_element() > 0.98, "{smooth}");
    // Rough GGX loses what single scattering leaves out: 1 − ln 2 at
    // normal incidence for width 1 (D = 1/π, G2 = 2 cos θi / (1 + cos θi)),
    // more than 5% at grazing.
    let rough = PbrLayers::isotropic(Vec3::ONE, 1.0, 1.0);
    let (normal, _) = albedo(&rough, Vec3::Z, n, &mut rng);
    assert!((normal.x - (1.0 - 2f32.ln())).abs() < 0.01, "{normal}");
    let (grazing, _) = albedo(&rough, direction(1.4, 0.0), n, &mut rng);
    assert!(grazing.max_element() < 0.95, "{grazing}");
    // A layer over a black base reflects its own albedo, as tabulated.
    for theta in [0.2f32, 0.9, 1.35] {
        let wo = direction(theta, 0.5);
        for (color, roughness) in [(0.8f32, 0.3f32), (1.0, 0.07), (0.5, 0.9)] {
            let material = PbrLayers { sheen: Some(Sheen { color: Vec3::splat(color), roughness }), ..black() };
            let (e, sigma) = albedo(&material, wo, n, &mut rng);
            let expected = color * sheen_albedo(wo.z, roughness);
            assert!((e.x - expected).abs() < 0.005 + 3.0 * sigma.x, "sheen {roughness} at {theta}: {e} vs {expected}");
        }
        for (factor, alpha) in [(1.0f32, 0.1f32), (0.6, 0.5)] {
            let material = PbrLayers { clearcoat: Some(Clearcoat { factor, alpha, normal: Vec3::Z }), ..black() };
            let (e, sigma) = albedo(&material, wo, n, &mut rng);
            let expected = factor * coat_albedo(wo.z, alpha);
            assert!((e.x - expected).abs() < 0.005 + 3.0 * sigma.x, "coat {alpha} at {theta}: {e} vs {expected}");
        }
    }
    // Albedo scaling passes on to a white diffuse base what the layer does
    // not reflect, less what the layer reflects of the light arriving
    // (both directions dim the base, for reciprocity).
    for theta in [0.0f32, 0.8, 1.4] {
        let wo = direction(theta, 2.0);
        let (color, roughness) = (0.9, 0.5);
        let sheen = Sheen { color: Vec3::splat(color), roughness };
        let material =
            PbrLayers { sheen: Some(sheen), specular_factor: 0.0, ..PbrLayers::isotropic(Vec3::ONE, 0.0, 0.5) };
        let layer = |cos: f32| color * sheen_albedo(cos, roughness);
        let expected = layer(wo.z) + diffuse_below(layer, wo.z);
        let (e, sigma) = albedo(&material, wo, n, &mut rng);
        assert!((e.x - expected).abs() < 0.005 + 3.0 * sigma.x, "sheen over white at {theta}: {e} vs {expected}");
        let (factor, alpha) = (0.8, 0.25);
        let coat = Clearcoat { factor, alpha, normal: Vec3::Z };
        let material =
            PbrLayers { clearcoat: Some(coat), specular_factor: 0.0, ..PbrLayers::isotropic(Vec3::ONE, 0.0, 0.5) };
        let layer = |cos: f32| factor * coat_albedo(cos, alpha);
        let expected = layer(wo.z) + diffuse_below(layer, wo.z);
        let (e, sigma) = albedo(&material, wo, n, &mut rng);
        assert!((e.x - expected).abs() < 0.005 + 3.0 * sigma.x, "coat over white at {theta}: {e} vs {expected}");
    }
}

#[test]
fn anisotropy_reduces_to_isotropy_and_turns_with_its_axes() {
    let turn = |w: Vec3| Vec3::new(-w.y, w.x, w.z);
    let everything = configuration("everything");
    // The coat's normal is turned with the directions.
    let untilted =
        PbrLayers { clearcoat: Some(Clearcoat { normal: Vec3::Z, ..everything.clearcoat.unwrap() }), ..everything };
    let swapped = PbrLayers { alpha_x: untilted.alpha_y, alpha_y: untilted.alpha_x, ..untilted };
    let equal = PbrLayers { alpha_x: 0.2, alpha_y: 0.2, ..untilted };
    let isotropic = PbrLayers { iridescence: None, sheen: None, clearcoat: None, ..equal };
    let mut rng = Rng::new(51, 52);
    for _ in 0..500 {
        let wo = direction(1.5 * rng.next_f32(), TAU * rng.next_f32());
        let wi = direction(1.5 * rng.next_f32(), TAU * rng.next_f32());
        let (a, b) = (untilted.eval(wo, wi), swapped.eval(turn(wo), turn(wi)));
        assert!((a - b).abs().max_element() <= 1e-4 * a.max_element().max(1.0), "{a} vs {b}");
        let (p, q) = (untilted.pdf(wo, wi), swapped.pdf(turn(wo), turn(wi)));
        assert!((p - q).abs() <= 1e-4 * p.max(1.0), "{p} vs {q}");
        // Equal widths: the same whatever the azimuth.
        for material in [equal, isotropic] {
            let (a, b) = (material.eval(wo, wi), material.eval(turn(wo), turn(wi)));
            assert!((a - b).abs().max_element() <= 1e-4 * a.max_element().max(1.0), "{a} vs {b}");
        }
    }
}

#[test]
fn iridescence_without_a_film_is_the_plain_fresnel() {
    let mut rng = Rng::new(53, 54);
    for (_, material) in configurations() {
        let plain = PbrLayers { iridescence: None, ..material };
        let no_film = |iridescence| PbrLayers { iridescence, ..material };
        for iridescence in [
            Some(Iridescence { factor: 1.0, ior: 1.3, thickness_nm: 0.0 }),
            Some(Iridescence { factor: 0.0, ior: 1.3, thickness_nm: 400.0 }),
        ] {
            let film = no_film(iridescence);
            for _ in 0..50 {
                let (wo, wi) =
                    (direction(1.5 * rng.next_f32(), TAU * rng.next_f32()), direction(1.5 * rng.next_f32(), 1.0));
                assert_eq!(film.eval(wo, wi), plain.eval(wo, wi));
                assert_eq!(film.pdf(wo, wi), plain.pdf(wo, wi));
            }
        }
    }
    // With a film, the mirror-like reflection at normal incidence follows
    // the film's Fresnel: its colour changes with the thickness.
    let (mut lowest, mut highest) = (Vec3::ONE, Vec3::ZERO);
    for step in 2..=16 {
        let material = PbrLayers {
            iridescence: Some(Iridescence { factor: 1.0, ior: 1.3, thickness_nm: 50.0 * step as f32 }),
            ..PbrLayers::isotropic(Vec3::ZERO, 0.0, 0.001)
        };
        let reflectance = material.nominal_albedo();
        (lowest, highest) = (lowest.min(reflectance), highest.max(reflectance));
    }
    assert!((highest - lowest).min_element() > 0.02 && highest.max_element() < 0.1, "{lowest} .. {highest}");
}

#[test]
fn nominal_albedo_and_regularisation() {
    let lambert = PbrLayers { specular_factor: 0.0, ..PbrLayers::isotropic(Vec3::new(0.7, 0.5, 0.3), 0.0, 0.5) };
    assert!((lambert.nominal_albedo() - Vec3::new(0.7, 0.5, 0.3)).abs().max_element() < 1e-6);
    let mirror = PbrLayers::isotropic(Vec3::new(0.9, 0.6, 0.3), 1.0, 0.001);
    assert!(
        (mirror.nominal_albedo() - Vec3::new(0.9, 0.6, 0.3)).abs().max_element() < 0.01,
        "{}",
        mirror.nominal_albedo()
    );
    let coated = PbrLayers { clearcoat: Some(Clearcoat { factor: 1.0, alpha: 0.001, normal: Vec3::Z }), ..black() };
    assert!((coated.nominal_albedo() - Vec3::splat(0.04)).abs().max_element() < 0.002, "{}", coated.nominal_albedo());

    let sharp = PbrLayers {
        alpha_x: 0.01,
        alpha_y: 0.4,
        clearcoat: Some(Clearcoat { factor: 1.0, alpha: 0.001, normal: Vec3::Z }),
        ..PbrLayers::isotropic(Vec3::ONE, 0.0, 0.01)
    };
    let wide = sharp.regularised(0.2);
    assert_eq!((wide.alpha_x, wide.alpha_y, wide.clearcoat.unwrap().alpha), (0.2, 0.4, 0.2));
    assert_eq!(sharp.regularised(0.0), sharp);
}
