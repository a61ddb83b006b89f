//! Every acceleration structure answers exactly as the linear scan does, bit
//! for bit (triangle, `t`, `beta`, `gamma`), on random soups; the
//! adversarial inputs are in `exactness.rs`.

use proptest::prelude::*;
use rtgi_accel::verify::same_hit;
use rtgi_accel::{Accel, Intersector, LinearScan};
use rtgi_math::{Ray, Vec3};
use rtgi_tests::for_every_variant;

fn vec3(range: std::ops::Range<f32>) -> impl Strategy<Value = Vec3> {
    (range.clone(), range.clone(), range).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

/// Soups of triangles of mixed sizes, from slivers to large ones, some overlapping.
fn soup() -> impl Strategy<Value = Vec<[Vec3; 3]>> {
    prop::collection::vec((vec3(-10.0..10.0), vec3(-3.0..3.0), vec3(-3.0..3.0)), 1..300)
        .prop_map(|ts| ts.into_iter().map(|(a, e1, e2)| [a, a + e1, a + e2]).collect())
}

/// Rays from anywhere, some with ranges that start behind their origin (a
/// negative `t_min`), half of them bounded.
fn rays() -> impl Strategy<Value = Vec<Ray>> {
    prop::collection::vec((vec3(-14.0..14.0), vec3(-1.0..1.0), -3.0f32..2.0, prop::bool::ANY), 64).prop_map(|rs| {
        rs.into_iter()
            .map(|(o, d, t_min, bounded)| {
                let t_max = if bounded { t_min + 8.0 } else { f32::INFINITY };
                Ray::with_range(o, d, t_min, t_max)
            })
            .collect()
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn every_variant_matches_the_linear_scan(triangles in soup(), rays in rays()) {
        let references: Vec<(Intersector, Vec<_>)> = Intersector::ALL
            .iter()
            .map(|&i| {
                let reference = LinearScan::new(&triangles, i);
                (i, rays.iter().map(|r| (reference.intersect(r), reference.occluded(r))).collect())
            })
            .collect();
        let references_linear: Vec<(Intersector, LinearScan)> =
            Intersector::ALL.iter().map(|&i| (i, LinearScan::new(&triangles, i))).collect();
        let mut failures = Vec::new();
        for_every_variant(&triangles, |label, accel, params| {
            let expected = &references.iter().find(|(i, _)| *i == params.intersector).expect("every intersector").1;
            for (ray, (closest, any)) in rays.iter().zip(expected) {
                let got = accel.intersect(ray);
                if !same_hit(got, *closest) {
                    failures.push(format!("{label}: closest {got:?} != {closest:?} for {ray:?}"));
                }
                if accel.occluded(ray) != *any {
                    failures.push(format!("{label}: any-hit differs for {ray:?}"));
                }
                // With a filter that passes through every third triangle.
                let reference = references_linear.iter().find(|(i, _)| *i == params.intersector).expect("every intersector");
                let holes = |t: u32, _: f32, _: f32| !t.is_multiple_of(3);
                let (got, expected) = (accel.intersect_filtered(ray, &holes), reference.1.intersect_filtered(ray, &holes));
                if !same_hit(got, expected) {
                    failures.push(format!("{label}: filtered closest {got:?} != {expected:?}"));
                }
                if accel.occluded_filtered(ray, &holes) != reference.1.occluded_filtered(ray, &holes) {
                    failures.push(format!("{label}: filtered any-hit differs for {ray:?}"));
                }
            }
        });
        prop_assert!(failures.is_empty(), "{}", failures.join("\n"));
    }
}

/// Runs of sixteen rays from nearby origins in nearby directions, as a
/// tile of camera rays is, so that the wide BVHs' batch queries trace them
/// as packets; the last run is scattered, for the single-ray fallback.
fn coherent_runs() -> impl Strategy<Value = Vec<Ray>> {
    let run = (vec3(-14.0..14.0), vec3(-1.0..1.0), prop::collection::vec((vec3(-0.3..0.3), vec3(-0.05..0.05)), 16));
    (prop::collection::vec(run, 3), rays()).prop_map(|(runs, scattered)| {
        let mut rays: Vec<Ray> = runs
            .into_iter()
            .flat_map(|(origin, direction, jitters)| {
                jitters.into_iter().map(move |(dp, dd)| Ray::new(origin + dp, direction + dd))
            })
            .collect();
        rays.extend(scattered.into_iter().take(16));
        rays
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// The batch queries with a filter (cut-outs in `rtgi trace`) answer
    /// as the linear scan's single filtered queries, bit for bit, packets
    /// included.
    #[test]
    fn filtered_batches_match_the_linear_scan(triangles in soup(), rays in coherent_runs()) {
        let holes = |t: u32, beta: f32, _: f32| !t.is_multiple_of(3) || beta > 0.5;
        let references: Vec<(Intersector, Vec<_>)> = Intersector::ALL
            .iter()
            .map(|&i| {
                let reference = LinearScan::new(&triangles, i);
                (i, rays.iter().map(|r| (reference.intersect_filtered(r, &holes), reference.occluded_filtered(r, &holes))).collect())
            })
            .collect();
        let mut failures = Vec::new();
        for_every_variant(&triangles, |label, accel, params| {
            let expected = &references.iter().find(|(i, _)| *i == params.intersector).expect("every intersector").1;
            let mut closest = vec![None; rays.len()];
            let mut any = vec![false; rays.len()];
            accel.intersect_batch_filtered(&rays, &mut closest, &holes);
            accel.occluded_batch_filtered(&rays, &mut any, &holes);
            for (i, (ray, (want_closest, want_any))) in rays.iter().zip(expected).enumerate() {
                if !same_hit(closest[i], *want_closest) {
                    failures.push(format!("{label}: batch filtered closest {:?} != {want_closest:?} for ray {i} {ray:?}", closest[i]));
                }
                if any[i] != *want_any {
                    failures.push(format!("{label}: batch filtered any-hit differs for ray {i} {ray:?}"));
                }
            }
        });
        prop_assert!(failures.is_empty(), "{}", failures.join("\n"));
    }
}

#[test]
fn helper_covers_every_variant() {
    let mut labels = Vec::new();
    for_every_variant(&[[Vec3::ZERO, Vec3::X, Vec3::Y]], |label, _, _| labels.push(label.to_owned()));
    for kind in rtgi_accel::AccelKind::ALL {
        assert!(labels.iter().any(|l| l.starts_with(kind.name())), "{kind} is not tested");
    }
    // Labels tell configurations apart, so that answers can be matched by label.
    let distinct: std::collections::HashSet<&String> = labels.iter().collect();
    assert_eq!(distinct.len(), labels.len(), "two configurations share a label");
}
