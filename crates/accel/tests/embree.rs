//! The Embree backend against the linear scan (feature `embree`).
//!
//! Embree is a peer, not held to the exactness contract, so it is compared
//! with tolerances rather than bit for bit:
//!
//! - the same triangle on at least 99.9% of the rays both hit: ties (two
//!   triangles hit at the same `t`, as at shared edges of a closed mesh)
//!   are broken by Embree in traversal order, ours by the lowest index;
//! - `t` within a relative 1e-4 of ours (and the barycentrics within
//!   1e-3): both compute them in single precision with different formulas
//!   (Embree's Möller-Trumbore test against our watertight one), which
//!   differ by a few ulps times the problem's conditioning, far below 1e-4
//!   except for rays that graze the triangle's plane, where the error grows
//!   as 1 / cos of the incidence angle: those (|cos| < 1e-2) are exempt;
//! - hit or miss the same, except on rays that graze a triangle: a ray
//!   within a few ulps of an edge may hit in one test and miss in the other.
//!   We count a disagreement as grazing when the answer that hit did so
//!   within 1e-3 of an edge (a barycentric coordinate below 1e-3).

#![cfg(feature = "embree")]

use std::collections::HashSet;

use rtgi_accel::verify::shapes::{icosphere, tessellated_cube};
use rtgi_accel::{Accel, AccelKind, BuildParams, EmbreeBackend, Hit, LinearScan, TraversalCounters};
use rtgi_math::{Ray, Rng, Vec3};

fn random_point(rng: &mut Rng, size: f32) -> Vec3 {
    (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0) * size
}

fn random_direction(rng: &mut Rng) -> Vec3 {
    loop {
        let v = random_point(rng, 1.0);
        if v.length_squared() > 1e-4 && v.length_squared() <= 1.0 {
            return v.normalize();
        }
    }
}

/// Triangles of up to `size` at random places of the cube `[-10, 10]³`.
fn soup(count: usize, size: f32, seed: u64) -> Vec<[Vec3; 3]> {
    let mut rng = Rng::new(seed, 0);
    (0..count)
        .map(|_| {
            let centre = random_point(&mut rng, 10.0);
            [
                centre + random_point(&mut rng, size),
                centre + random_point(&mut rng, size),
                centre + random_point(&mut rng, size),
            ]
        })
        .collect()
}

fn random_rays(count: usize, seed: u64) -> Vec<Ray> {
    let mut rng = Rng::new(seed, 1);
    (0..count).map(|_| Ray::new(random_point(&mut rng, 12.0), random_direction(&mut rng))).collect()
}

/// Rays from random points of the cube `[-size, size]³` aimed at random
/// points of random triangles (so that most hit something).
fn aimed_rays(triangles: &[[Vec3; 3]], size: f32, count: usize, seed: u64) -> Vec<Ray> {
    let mut rng = Rng::new(seed, 2);
    (0..count)
        .map(|_| {
            let [a, b, c] = triangles[rng.next_below(triangles.len() as u32) as usize];
            let (mut u, mut v) = (rng.next_f32(), rng.next_f32());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            let origin = random_point(&mut rng, size);
            Ray::new(origin, a + (b - a) * u + (c - a) * v - origin)
        })
        .collect()
}

/// |cos| of the angle between the ray and the triangle's normal: near 0
/// the ray grazes the plane and `t` is ill-conditioned (its rounding error
/// grows as 1 / cos).
fn incidence(triangle: &[Vec3; 3], ray: &Ray) -> f32 {
    let [a, b, c] = *triangle;
    (b - a).cross(c - a).normalize().dot(ray.direction.normalize()).abs()
}

/// Whether a hit lies within 1e-3 (in barycentrics) of its triangle's edges.
fn grazing(hit: &Hit) -> bool {
    hit.beta.min(hit.gamma).min(1.0 - hit.beta - hit.gamma) < 1e-3
}

/// Compares Embree with the linear scan on `rays`, with the tolerances of
/// the module's documentation; returns the number of rays both hit.
fn assert_agrees(triangles: &[[Vec3; 3]], rays: &[Ray]) -> usize {
    let linear = LinearScan::new(triangles, Default::default());
    let embree = EmbreeBackend::new(triangles).expect("Embree builds");
    let (mut both, mut same_triangle, mut mismatched) = (0, 0, 0);
    for ray in rays {
        let (ours, theirs) = (linear.intersect(ray), embree.intersect(ray));
        match (ours, theirs) {
            (Some(a), Some(b)) => {
                both += 1;
                if a.triangle == b.triangle {
                    same_triangle += 1;
                    let cosine = incidence(&triangles[a.triangle as usize], ray);
                    assert!(
                        (a.t - b.t).abs() <= 1e-4 * a.t.abs() || cosine < 1e-2,
                        "t {} against {} at incidence cosine {cosine} for {ray:?}",
                        b.t,
                        a.t
                    );
                    let close = (a.beta - b.beta).abs() < 1e-3 && (a.gamma - b.gamma).abs() < 1e-3;
                    assert!(close || cosine < 1e-2, "{a:?} {b:?}");
                } else {
                    // Another triangle, so another point: at least at the same distance.
                    assert!((a.t - b.t).abs() <= 1e-4 * a.t.abs(), "{a:?} against {b:?} for {ray:?}");
                }
            }
            (None, None) => {}
            (Some(hit), None) | (None, Some(hit)) => {
                assert!(grazing(&hit), "hit {hit:?} by one only, not at an edge, for {ray:?}");
                mismatched += 1;
            }
        }
        assert_eq!(embree.occluded(ray), theirs.is_some(), "any hit and closest hit disagree for {ray:?}");
    }
    assert!(both > rays.len() / 10, "too few hits to compare: {both}");
    assert!(same_triangle as f64 >= 0.999 * both as f64, "same triangle on {same_triangle} of {both} hits");
    assert!(mismatched as f64 <= 1e-3 * rays.len() as f64, "{mismatched} grazing disagreements");
    both
}

#[test]
fn agrees_with_the_linear_scan_on_a_random_soup() {
    let triangles = soup(2000, 1.5, 7);
    let mut rays = random_rays(10_000, 8);
    rays.extend(aimed_rays(&triangles, 12.0, 10_000, 8));
    assert_agrees(&triangles, &rays);
}

#[test]
fn agrees_with_the_linear_scan_on_a_closed_mesh() {
    let sphere = icosphere(4).placed(5.0, Vec3::new(0.5, -0.25, 0.125)).triangles();
    // Rays from inside and outside, aimed at the surface.
    let rays = aimed_rays(&sphere, 7.0, 20_000, 9);
    assert!(assert_agrees(&sphere, &rays) > 19_000);
    let cube = tessellated_cube(6).triangles();
    let mut rng = Rng::new(3, 3);
    let rays: Vec<Ray> =
        (0..10_000).map(|_| Ray::new(random_point(&mut rng, 0.5), random_direction(&mut rng))).collect();
    // From inside a closed cube every ray hits.
    assert_eq!(assert_agrees(&cube, &rays), rays.len());
}

#[test]
fn the_filter_lets_rays_through_rejected_triangles() {
    // Three parallel squares' worth of triangles at z = 1, 2, 3, each facing the ray.
    let square = |z: f32| [Vec3::new(-1.0, -1.0, z), Vec3::new(1.0, -1.0, z), Vec3::new(0.0, 1.0, z)];
    let triangles = [square(1.0), square(2.0), square(3.0)];
    let embree = EmbreeBackend::new(&triangles).expect("Embree builds");
    let ray = Ray::new(Vec3::new(0.0, 0.0, 0.0), Vec3::Z);
    assert_eq!(embree.intersect(&ray).map(|h| h.triangle), Some(0));
    let hit = embree.intersect_filtered(&ray, &|triangle, _, _| triangle != 0).expect("the one behind");
    assert_eq!((hit.triangle, hit.t), (1, 2.0));
    let hit = embree.intersect_filtered(&ray, &|triangle, _, _| triangle == 2).expect("the last one");
    assert_eq!((hit.triangle, hit.t), (2, 3.0));
    assert_eq!(embree.intersect_filtered(&ray, &|_, _, _| false), None);
    assert!(embree.occluded_filtered(&ray, &|triangle, _, _| triangle == 2));
    assert!(!embree.occluded_filtered(&ray, &|_, _, _| false));
    // The filter sees our triangle indices and Embree's barycentrics.
    let seen = std::sync::Mutex::new(HashSet::new());
    embree.intersect_filtered(&ray, &|triangle, beta, gamma| {
        assert!((0.0..=1.0).contains(&beta) && (0.0..=1.0).contains(&gamma));
        seen.lock().unwrap().insert(triangle);
        false
    });
    assert_eq!(seen.into_inner().unwrap(), HashSet::from([0, 1, 2]));
    // A short ray ends before the triangle behind.
    let short = Ray { t_max: 1.5, ..ray };
    assert_eq!(embree.intersect_filtered(&short, &|triangle, _, _| triangle != 0), None);
}

#[test]
fn a_panicking_filter_unwinds_to_the_caller() {
    let triangles = soup(10, 20.0, 1);
    let embree = EmbreeBackend::new(&triangles).expect("Embree builds");
    let rays = random_rays(1000, 2);
    let ray = rays.iter().find(|r| embree.intersect(r).is_some()).expect("some ray hits");
    let result = std::panic::catch_unwind(|| embree.intersect_filtered(ray, &|_, _, _| panic!("filter failed")));
    assert!(result.is_err());
    // The backend is still usable.
    assert!(embree.intersect(ray).is_some());
}

#[test]
fn batches_agree_with_single_rays() {
    let triangles = soup(3000, 1.0, 11);
    let embree = EmbreeBackend::new(&triangles).expect("Embree builds");
    // Coherent rays (a fan from one point) and incoherent ones, with a
    // count that leaves a partial packet, and some invalid rays among them.
    let mut rays: Vec<Ray> = (0..1000)
        .map(|i| {
            let (x, y) = ((i % 40) as f32 / 40.0 - 0.5, (i / 40) as f32 / 25.0 - 0.5);
            Ray::new(Vec3::new(0.0, 0.0, -15.0), Vec3::new(x, y, 1.0))
        })
        .chain(random_rays(1000, 12))
        .collect();
    rays.truncate(1995);
    rays[3] = Ray::new(Vec3::new(f32::NAN, 0.0, 0.0), Vec3::Z);
    rays[17] = Ray::new(Vec3::ZERO, Vec3::ZERO);
    let mut hits = vec![None; rays.len()];
    embree.intersect_batch(&rays, &mut hits);
    let mut occluded = vec![true; rays.len()];
    embree.occluded_batch(&rays, &mut occluded);
    let mut same = 0;
    for ((ray, batch), any) in rays.iter().zip(&hits).zip(&occluded) {
        let single = embree.intersect(ray);
        assert_eq!(*any, embree.occluded(ray), "{ray:?}");
        match (single, batch) {
            (Some(a), Some(b)) => {
                assert!((a.t - b.t).abs() <= 1e-4 * a.t, "{a:?} {b:?}");
                same += usize::from(a.triangle == b.triangle);
            }
            (None, None) => same += 1,
            (a, b) => panic!("single {a:?}, batch {b:?} for {ray:?}"),
        }
    }
    assert!(same as f64 >= 0.999 * rays.len() as f64, "{same} of {}", rays.len());
    assert!(hits.iter().filter(|h| h.is_some()).count() > 100);
    assert_eq!((hits[3], occluded[3], hits[17], occluded[17]), (None, false, None, false));
}

#[test]
fn filtered_batches_agree_with_filtered_single_rays() {
    let triangles = soup(3000, 1.0, 13);
    let embree = EmbreeBackend::new(&triangles).expect("Embree builds");
    let rays: Vec<Ray> = (0..1024)
        .map(|i| {
            let (x, y) = ((i % 32) as f32 / 32.0 - 0.5, (i / 32) as f32 / 32.0 - 0.5);
            Ray::new(Vec3::new(0.0, 0.0, -15.0), Vec3::new(x, y, 1.0))
        })
        .collect();
    // Every other triangle is a hole, as alpha-masked surfaces are.
    let holes = |triangle: u32, _: f32, _: f32| triangle % 2 == 1;
    let mut hits = vec![None; rays.len()];
    embree.intersect_batch_filtered(&rays, &mut hits, &holes);
    let mut occluded = vec![false; rays.len()];
    embree.occluded_batch_filtered(&rays, &mut occluded, &holes);
    let mut unfiltered = vec![None; rays.len()];
    embree.intersect_batch(&rays, &mut unfiltered);
    let mut same = 0;
    for (i, ray) in rays.iter().enumerate() {
        assert_eq!(occluded[i], embree.occluded_filtered(ray, &holes), "{ray:?}");
        assert!(hits[i].is_none_or(|h| h.triangle % 2 == 1), "a hole was hit: {:?}", hits[i]);
        same += usize::from(hits[i].map(|h| h.triangle) == embree.intersect_filtered(ray, &holes).map(|h| h.triangle));
    }
    assert!(same as f64 >= 0.999 * rays.len() as f64, "{same} of {}", rays.len());
    let through = (0..rays.len()).filter(|&i| hits[i].map(|h| h.triangle) != unfiltered[i].map(|h| h.triangle)).count();
    assert!(through > 50, "only {through} rays went through a hole");
}

#[test]
fn invalid_rays_hit_nothing() {
    let triangles = [[Vec3::new(-1.0, -1.0, 1.0), Vec3::new(1.0, -1.0, 1.0), Vec3::new(0.0, 1.0, 1.0)]];
    let embree = EmbreeBackend::new(&triangles).expect("Embree builds");
    let good = Ray::new(Vec3::ZERO, Vec3::Z);
    assert_eq!(embree.intersect(&good).map(|h| (h.triangle, h.t)), Some((0, 1.0)));
    let invalid = [
        Ray::new(Vec3::new(f32::NAN, 0.0, 0.0), Vec3::Z),
        Ray::new(Vec3::new(f32::INFINITY, 0.0, 0.0), Vec3::Z),
        Ray::new(Vec3::ZERO, Vec3::ZERO),
        Ray::new(Vec3::ZERO, Vec3::new(0.0, f32::NAN, 1.0)),
        Ray { t_min: 2.0, t_max: 1.0, ..good },
        Ray { t_min: f32::NAN, ..good },
    ];
    for ray in &invalid {
        assert!(!ray.is_valid());
        assert_eq!(embree.intersect(ray), None);
        assert!(!embree.occluded(ray));
        assert_eq!(embree.intersect_filtered(ray, &|_, _, _| true), None);
    }
    // The segment is respected: t_max before the triangle, t_min after it.
    assert_eq!(embree.intersect(&Ray { t_max: 0.5, ..good }), None);
    assert_eq!(embree.intersect(&Ray { t_min: 1.5, ..good }), None);
    assert!(!embree.occluded(&Ray { t_max: 0.5, ..good }));
}

#[test]
fn unhittable_triangles_are_excluded_and_indices_kept() {
    let good = |z: f32| [Vec3::new(-1.0, -1.0, z), Vec3::new(1.0, -1.0, z), Vec3::new(0.0, 1.0, z)];
    let triangles = [
        [Vec3::ZERO, Vec3::X, 2.0 * Vec3::X],
        good(3.0),
        [Vec3::new(f32::NAN, 0.0, 0.0), Vec3::X, Vec3::Y],
        good(2.0),
        [Vec3::ZERO, Vec3::ZERO, Vec3::ZERO],
    ];
    let embree = EmbreeBackend::new(&triangles).expect("Embree builds");
    let stats = embree.build_stats();
    assert_eq!((stats.variant.as_str(), stats.triangles, stats.excluded_triangles), ("embree", 5, 3));
    assert!(stats.build_ms > 0.0 && stats.memory_bytes > 0, "{stats:?}");
    let ray = Ray::new(Vec3::ZERO, Vec3::Z);
    assert_eq!(embree.intersect(&ray).map(|h| (h.triangle, h.t)), Some((3, 2.0)));
    assert_eq!(embree.intersect_filtered(&ray, &|t, _, _| t != 3).map(|h| h.triangle), Some(1));
    // Nothing hittable at all: an empty scene that hits nothing.
    let empty = EmbreeBackend::new(&triangles[4..]).expect("Embree builds an empty scene");
    assert_eq!(empty.build_stats().excluded_triangles, 1);
    assert_eq!(empty.intersect(&ray), None);
    let none = EmbreeBackend::new(&[]).expect("Embree builds an empty scene");
    assert!(!none.occluded(&ray));
}

#[test]
fn counted_queries_count_rays_only() {
    let triangles = soup(100, 3.0, 5);
    let embree = EmbreeBackend::new(&triangles).expect("Embree builds");
    let mut counters = TraversalCounters::default();
    for ray in random_rays(50, 6) {
        assert_eq!(embree.intersect_counted(&ray, &mut counters), embree.intersect(&ray));
        assert_eq!(embree.occluded_counted(&ray, &mut counters), embree.occluded(&ray));
    }
    assert_eq!(counters, TraversalCounters { rays: 100, nodes_visited: 0, triangles_tested: 0 });
}

#[test]
fn selectable_by_name_as_a_peer() {
    let kind: AccelKind = "embree".parse().expect("the feature is on");
    assert_eq!(kind, AccelKind::Embree);
    assert_eq!(kind.to_string(), "embree");
    assert!(kind.is_peer() && AccelKind::PEERS.contains(&kind));
    assert!(!AccelKind::ALL.contains(&kind));
    assert!(AccelKind::all_configurations().iter().all(|(k, _)| !k.is_peer()));
    assert!(AccelKind::ALL.iter().all(|k| !k.is_peer()));
    let triangles = soup(50, 3.0, 4);
    let accel = kind.try_build(&triangles, &BuildParams::default()).expect("Embree builds");
    assert_eq!(accel.build_stats().variant, "embree");
    let linear = AccelKind::Linear.build(&triangles, &BuildParams::default());
    let hits =
        random_rays(500, 5).iter().filter(|r| accel.intersect(r).is_some() == linear.intersect(r).is_some()).count();
    assert!(hits >= 499);
}

#[test]
fn builds_from_an_indexed_mesh_as_from_its_soup() {
    // Embree copies the mesh into its own buffers; the scene it builds is
    // the one it builds from the soup, so the answers are the same.
    let mesh = icosphere(3);
    let indexed = rtgi_accel::IndexedMesh::new(&mesh.vertices, &mesh.faces).expect("valid indices");
    let from_mesh = AccelKind::Embree.try_build(&indexed, &BuildParams::default()).expect("Embree builds");
    let from_soup = EmbreeBackend::new(&mesh.triangles()).expect("Embree builds");
    assert_eq!(from_mesh.build_stats().triangles, mesh.faces.len());
    let mut rng = Rng::new(8, 1);
    for _ in 0..500 {
        let origin = random_point(&mut rng, 3.0);
        let ray = Ray::new(origin, random_point(&mut rng, 0.5) - origin);
        assert_eq!(from_mesh.intersect(&ray), from_soup.intersect(&ray), "{ray:?}");
        assert_eq!(from_mesh.occluded(&ray), from_soup.occluded(&ray), "{ray:?}");
    }
}

/// Embree requires `tnear ≥ 0`, and its builds with assertions abort on a
/// ray whose range starts behind its origin. The backend gives it such a
/// ray from the start of its range; the answers, distances included, are
/// ours up to the rounding of the moved origin, singly and in batches.
#[test]
fn ranges_that_start_behind_the_origin_are_traced_from_their_start() {
    let triangles = soup(2000, 1.5, 13);
    let linear = LinearScan::new(&triangles, Default::default());
    let embree = EmbreeBackend::new(&triangles).expect("Embree builds");
    let mut rng = Rng::new(14, 3);
    let rays: Vec<Ray> = random_rays(4000, 15)
        .into_iter()
        .map(|ray| Ray::with_range(ray.origin, ray.direction, -20.0 * rng.next_f32(), f32::INFINITY))
        .collect();
    let mut batch = vec![None; rays.len()];
    embree.intersect_batch(&rays, &mut batch);
    let (mut both, mut same_triangle, mut behind) = (0, 0, 0);
    for (ray, batch) in rays.iter().zip(&batch) {
        let (ours, theirs) = (linear.intersect(ray), embree.intersect(ray));
        assert_eq!(theirs.map(|h| h.triangle), batch.map(|h| h.triangle), "single and batch for {ray:?}");
        assert_eq!(embree.occluded(ray), theirs.is_some(), "any hit and closest hit disagree for {ray:?}");
        match (ours, theirs) {
            (Some(a), Some(b)) => {
                both += 1;
                behind += usize::from(a.t < 0.0);
                same_triangle += usize::from(a.triangle == b.triangle);
                let tolerance = 1e-4 * (a.t.abs() - ray.t_min + 1.0);
                assert!((a.t - b.t).abs() <= tolerance, "{a:?} against {b:?} for {ray:?}");
            }
            (None, None) => {}
            (Some(hit), None) | (None, Some(hit)) => {
                assert!(grazing(&hit), "hit {hit:?} by one only, not at an edge, for {ray:?}")
            }
        }
    }
    assert!(behind > rays.len() / 10, "{behind} hits behind the origin of {both}");
    assert!(same_triangle as f64 >= 0.999 * both as f64, "same triangle on {same_triangle} of {both} hits");
}
