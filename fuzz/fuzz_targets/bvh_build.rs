#![no_main]
//! Triangle soups, NaN and infinite coordinates included, built with every
//! structure of `AccelKind::ALL` (Embree, a peer, is not in it) and a few
//! build parameters, then queried with a few rays: nothing may panic.

use libfuzzer_sys::fuzz_target;
use rtgi_accel::{AccelKind, BuildParams, Intersector, Traversal};
use rtgi_math::{Ray, Vec3};

/// Values that make geometry degenerate or extreme.
const SPECIAL: [f32; 12] =
    [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.0, -0.0, f32::MAX, f32::MIN, f32::MIN_POSITIVE, 1e-40, 1e30, -1e30, 1.0];

/// One coordinate from 4 bytes: mostly small values on a grid (so that
/// triangles share edges and vertices), sometimes a special value, sometimes raw bits.
fn coordinate(bytes: &[u8]) -> f32 {
    match bytes[0] % 8 {
        0 => SPECIAL[bytes[1] as usize % SPECIAL.len()],
        1 => f32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]),
        _ => i16::from_le_bytes([bytes[1], bytes[2]]) as f32 / (1 << (bytes[3] % 16)) as f32,
    }
}

fuzz_target!(|data: &[u8]| {
    let Some((&first, data)) = data.split_first() else { return };
    let coordinates: Vec<f32> = data.chunks_exact(4).map(coordinate).collect();
    let triangles: Vec<[Vec3; 3]> = coordinates
        .chunks_exact(9)
        .take(4096)
        .map(|c| [Vec3::new(c[0], c[1], c[2]), Vec3::new(c[3], c[4], c[5]), Vec3::new(c[6], c[7], c[8])])
        .collect();
    // Rays from fixed points towards every triangle's first corner, and along the axes.
    let mut rays = Vec::new();
    for origin in [Vec3::ZERO, Vec3::new(0.5, 0.25, -10.0), Vec3::splat(1e6)] {
        for t in triangles.iter().take(8) {
            rays.push(Ray::new(origin, t[0] - origin));
        }
        for direction in [Vec3::X, -Vec3::Y, Vec3::Z, Vec3::new(1.0, -0.0, 0.0)] {
            rays.push(Ray::new(origin, direction));
        }
    }
    for &kind in AccelKind::ALL {
        let defaults = kind.default_params();
        let params = [
            defaults.clone(),
            BuildParams {
                max_leaf_size: 1 + first as usize % 8,
                sah_bins: 2 + (first as usize >> 3) % 30,
                intersector: [Intersector::Watertight, Intersector::MollerTrumbore, Intersector::WatertightF64]
                    [first as usize % 3],
                traversal: if first & 0x80 == 0 { Traversal::Robust } else { Traversal::Fast },
                ..defaults
            },
        ];
        for params in &params {
            let Ok(accel) = kind.try_build(&triangles, params) else { continue };
            let mut hits = vec![None; rays.len()];
            let mut occluded = vec![false; rays.len()];
            for ray in &rays {
                let _ = accel.intersect(ray);
                let _ = accel.occluded(ray);
            }
            accel.intersect_batch(&rays, &mut hits);
            accel.occluded_batch(&rays, &mut occluded);
        }
    }
});
