//! Geometry and rays that probe the numerical robustness of ray tracing:
//! rays exactly through shared edges, and rays from inside closed meshes.
//! `rtgi bench` measures failure rates with them; the hard-case tests use
//! the same generators.

use rtgi_math::{Ray, Vec3};

pub use rtgi_accel::verify::shapes::{ClosedMesh, icosphere, quad, rays_through_diagonal};

/// The shared-edge probe at unit size, 2^20 and 2^24 from the origin, and
/// at 2^-40 size: every ray must hit one of the two triangles of its
/// quad. Returns the triangles of all quads and the rays.
pub fn shared_edge_probe() -> (Vec<[Vec3; 3]>, Vec<Ray>) {
    let mut triangles = Vec::new();
    let mut rays = Vec::new();
    // Far enough apart that a ray aimed at one quad meets no other first;
    // the tiny one sits at the origin, where its coordinates are exact.
    // (size, offset, bits): the grid of size / 2^bits is at least the ulp there.
    for (size, offset, bits) in [
        (1.0, Vec3::new(8.0, 8.0, 0.0), 20),
        (1024.0, Vec3::splat(1_048_576.0), 13),
        (65536.0, Vec3::splat(16_777_216.0), 15),
        (2f32.powi(-40), Vec3::ZERO, 20),
    ] {
        triangles.extend(quad(size, offset));
        rays.extend(rays_through_diagonal(size, offset, bits, 5000, size.to_bits() as u64));
    }
    (triangles, rays)
}

/// The closed-mesh probe: `count` rays from random points inside an
/// icosphere of 1,280 triangles (see [`ClosedMesh::leak_rays`]).
pub fn closed_mesh_probe(count: usize, seed: u64) -> (Vec<[Vec3; 3]>, Vec<Ray>) {
    let sphere = icosphere(3);
    let rays = sphere.leak_rays(|r| Vec3::new(r.next_f32(), r.next_f32(), r.next_f32()) * 0.9 - 0.45, count, seed);
    (sphere.triangles(), rays)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn probes_have_their_sizes() {
        assert_eq!(shared_edge_probe().1.len(), 20_000);
        assert_eq!(closed_mesh_probe(100, 1).1.len(), 100);
    }
}
