//! Inputs of the `bvh_build` fuzz target (`fuzz/`) that once crashed,
//! decoded as that target decodes them (`tests/corpus/bvh_build/`), built
//! with every structure and the target's build parameters: each must build,
//! and answer every ray exactly as the linear scan does.

use rtgi_accel::{Accel as _, AccelKind, BuildParams, Intersector, LinearScan, Traversal};
use rtgi_math::{Ray, Vec3};
use rtgi_tests::corpus::corpus_dir;
use rtgi_tests::{differences_from_linear_scan, for_every_variant};

const SPECIAL: [f32; 12] = [
    f32::NAN,
    f32::INFINITY,
    f32::NEG_INFINITY,
    0.0,
    -0.0,
    f32::MAX,
    f32::MIN,
    f32::MIN_POSITIVE,
    1e-40,
    1e30,
    -1e30,
    1.0,
];

/// As `fuzz/fuzz_targets/bvh_build.rs`.
fn coordinate(bytes: &[u8]) -> f32 {
    match bytes[0] % 8 {
        0 => SPECIAL[bytes[1] as usize % SPECIAL.len()],
        1 => f32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]),
        _ => i16::from_le_bytes([bytes[1], bytes[2]]) as f32 / (1 << (bytes[3] % 16)) as f32,
    }
}

/// Rays at the soup: from the origin and from outside its corners' range
/// towards every corner and every centroid, so that each triangle is aimed
/// at through its vertices (where watertightness is decided) and its inside.
fn rays_at(triangles: &[[Vec3; 3]]) -> Vec<Ray> {
    let origins = [Vec3::ZERO, Vec3::new(-3e4, 1e4, 2e4), Vec3::new(1.5, -2.5, -7.0)];
    let mut rays = Vec::new();
    for t in triangles {
        let targets = [t[0], t[1], t[2], (t[0] + t[1] + t[2]) / 3.0];
        for origin in origins {
            rays.extend(targets.iter().map(|&target| Ray::new(origin, target - origin)));
        }
    }
    rays
}

#[test]
fn crashing_triangle_soups_build_and_answer_as_the_linear_scan() {
    let dir = corpus_dir().join("bvh_build");
    let (mut inputs, mut hits) = (0, 0);
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let data = std::fs::read(&path).unwrap();
        let Some((&first, data)) = data.split_first() else { continue };
        inputs += 1;
        let coordinates: Vec<f32> = data.chunks_exact(4).map(coordinate).collect();
        let triangles: Vec<[Vec3; 3]> = coordinates
            .chunks_exact(9)
            .map(|c| [Vec3::new(c[0], c[1], c[2]), Vec3::new(c[3], c[4], c[5]), Vec3::new(c[6], c[7], c[8])])
            .collect();
        let rays = rays_at(&triangles);
        let references: Vec<LinearScan> = Intersector::ALL.iter().map(|&i| LinearScan::new(&triangles, i)).collect();
        let reference = |intersector: Intersector| {
            &references[Intersector::ALL.iter().position(|&i| i == intersector).expect("every intersector")]
        };
        hits += rays.iter().filter(|r| references[0].intersect(r).is_some()).count();
        let mut differences = Vec::new();
        // Every variant with the spread of parameters all structures are tested with ...
        for_every_variant(&triangles, |label, accel, params| {
            differences.extend(differences_from_linear_scan(label, accel, reference(params.intersector), &rays));
        });
        // ... and with the parameters the fuzz target derived from the input's first byte.
        for &kind in AccelKind::ALL {
            let varied = BuildParams {
                max_leaf_size: 1 + first as usize % 8,
                sah_bins: 2 + (first as usize >> 3) % 30,
                intersector: [Intersector::Watertight, Intersector::MollerTrumbore, Intersector::WatertightF64]
                    [first as usize % 3],
                traversal: if first & 0x80 == 0 { Traversal::Robust } else { Traversal::Fast },
                ..kind.default_params()
            };
            let accel =
                kind.try_build(&triangles, &varied).unwrap_or_else(|e| panic!("{}: {kind}: {e}", path.display()));
            // The fast slab test trades exactness for speed (`rtgi experiment
            // traversal`): it must answer, but may differ.
            if varied.traversal == Traversal::Robust {
                let label = format!("{kind} with the fuzz target's parameters {varied:?}");
                differences.extend(differences_from_linear_scan(
                    &label,
                    accel.as_ref(),
                    reference(varied.intersector),
                    &rays,
                ));
            } else {
                for ray in &rays {
                    let _ = (accel.intersect(ray), accel.occluded(ray));
                }
            }
        }
        assert!(
            differences.is_empty(),
            "{}: {} differences from the linear scan, the first: {:#?}",
            path.display(),
            differences.len(),
            &differences[..differences.len().min(8)]
        );
    }
    assert!(inputs > 0, "no inputs in {}", dir.display());
    // Answers to compare: rays that only miss would agree with anything.
    assert!(hits > 0, "no ray at the inputs of {} hits anything", dir.display());
}
