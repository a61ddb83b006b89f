//! Inputs of the `bvh_build` fuzz target (`fuzz/`) that once crashed,
//! decoded as that target decodes them (`tests/corpus/bvh_build/`), built
//! with every structure and the target's build parameters.

use rtgi_accel::{AccelKind, BuildParams, Intersector, Traversal};
use rtgi_math::{Ray, Vec3};
use rtgi_tests::corpus::corpus_dir;

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

#[test]
fn crashing_triangle_soups_build_and_answer() {
    let dir = corpus_dir().join("bvh_build");
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let data = std::fs::read(&path).unwrap();
        let Some((&first, data)) = data.split_first() else { continue };
        let coordinates: Vec<f32> = data.chunks_exact(4).map(coordinate).collect();
        let triangles: Vec<[Vec3; 3]> = coordinates
            .chunks_exact(9)
            .map(|c| [Vec3::new(c[0], c[1], c[2]), Vec3::new(c[3], c[4], c[5]), Vec3::new(c[6], c[7], c[8])])
            .collect();
        for &kind in AccelKind::ALL {
            let defaults = kind.default_params();
            let varied = BuildParams {
                max_leaf_size: 1 + first as usize % 8,
                sah_bins: 2 + (first as usize >> 3) % 30,
                intersector: [Intersector::Watertight, Intersector::MollerTrumbore, Intersector::WatertightF64]
                    [first as usize % 3],
                traversal: if first & 0x80 == 0 { Traversal::Robust } else { Traversal::Fast },
                ..defaults.clone()
            };
            for params in [defaults, varied] {
                let accel = kind.try_build(&triangles, &params).unwrap();
                for t in &triangles {
                    let _ = accel.intersect(&Ray::new(Vec3::ZERO, t[0]));
                }
            }
            eprintln!("{}: {} ok", path.display(), kind.name());
        }
    }
}
