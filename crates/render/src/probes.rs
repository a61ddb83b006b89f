//! Geometry and rays that probe the numerical robustness of ray tracing:
//! rays exactly through shared edges, and rays from inside closed meshes.
//! `rtgi bench` measures failure rates with them; the hard-case tests use
//! the same generators.

use rtgi_math::{Ray, Rng, Vec3};

use crate::rays::uniform_sphere;

/// A square of side `size` at `offset` in the plane z = offset.z, as two
/// triangles sharing the diagonal from its first corner to its third.
/// Powers of two keep every corner exact.
pub fn quad(size: f32, offset: Vec3) -> Vec<[Vec3; 3]> {
    let p = |x: f32, y: f32| offset + Vec3::new(x * size, y * size, 0.0);
    vec![[p(0.0, 0.0), p(1.0, 0.0), p(1.0, 1.0)], [p(0.0, 0.0), p(1.0, 1.0), p(0.0, 1.0)]]
}

/// `count` rays from random points above and below [`quad`]`(size,
/// offset)` to random points exactly on its diagonal. Every coordinate is
/// a multiple of `size / 2^bits` within a few `size` of `offset`, so (with
/// `size` a power of two, and `size / 2^bits` no smaller than the ulp of
/// `offset`) origin and direction are exact and `origin + direction` lies
/// exactly on the shared edge. More bits make the intersection arithmetic
/// round more, which is what exposes tests that are not watertight.
pub fn rays_through_diagonal(size: f32, offset: Vec3, bits: u32, count: usize, seed: u64) -> Vec<Ray> {
    let steps = 1u32 << bits;
    let grid = size / steps as f32;
    let mut rng = Rng::new(seed, 0xd1a9);
    (0..count)
        .map(|_| {
            let k = (1 + rng.next_below(steps - 1)) as f32;
            let target = offset + Vec3::new(k, k, 0.0) * grid;
            let a = rng.next_below(5 * steps) as f32 - (2 * steps) as f32;
            let b = rng.next_below(5 * steps) as f32 - (2 * steps) as f32;
            let c = (steps / 2 + rng.next_below(3 * steps / 2)) as f32;
            let side = if rng.next_f32() < 0.5 { 1.0 } else { -1.0 };
            let origin = offset + Vec3::new(a, b, side * c) * grid;
            Ray::new(origin, target - origin)
        })
        .collect()
}

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

/// A closed mesh: vertex positions and triangles as indices.
#[derive(Clone, Debug)]
pub struct ClosedMesh {
    pub vertices: Vec<Vec3>,
    pub faces: Vec<[u32; 3]>,
}

impl ClosedMesh {
    pub fn triangles(&self) -> Vec<[Vec3; 3]> {
        self.faces.iter().map(|f| f.map(|i| self.vertices[i as usize])).collect()
    }

    /// Vertices and edge midpoints: where rays are most likely to slip through.
    pub fn features(&self) -> Vec<Vec3> {
        let mut points = self.vertices.clone();
        for f in &self.faces {
            for e in 0..3 {
                points.push(0.5 * (self.vertices[f[e] as usize] + self.vertices[f[(e + 1) % 3] as usize]));
            }
        }
        points
    }

    /// `count` rays from points `inside` draws: half aimed at vertices and
    /// edge midpoints, half in uniformly random directions. In a closed
    /// mesh every one must hit.
    pub fn leak_rays(&self, inside: impl Fn(&mut Rng) -> Vec3, count: usize, seed: u64) -> Vec<Ray> {
        let features = self.features();
        let mut rng = Rng::new(seed, 7);
        (0..count)
            .map(|i| {
                let origin = inside(&mut rng);
                let direction = if i % 2 == 0 {
                    features[rng.next_below(features.len() as u32) as usize] - origin
                } else {
                    uniform_sphere(rng.next_f32(), rng.next_f32())
                };
                Ray::new(origin, direction)
            })
            .collect()
    }
}

/// An icosphere: an icosahedron subdivided `levels` times, on the unit
/// sphere, with shared vertices (so it is closed).
pub fn icosphere(levels: u32) -> ClosedMesh {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let corners = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ];
    let mut vertices: Vec<Vec3> = corners.iter().map(|&(x, y, z)| Vec3::new(x, y, z).normalize()).collect();
    let mut faces: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut midpoint = std::collections::HashMap::new();
        let mut mid = |a: u32, b: u32, vertices: &mut Vec<Vec3>| {
            *midpoint.entry((a.min(b), a.max(b))).or_insert_with(|| {
                vertices.push((vertices[a as usize] + vertices[b as usize]).normalize());
                vertices.len() as u32 - 1
            })
        };
        faces = faces
            .iter()
            .flat_map(|&[a, b, c]| {
                let (ab, bc, ca) = (mid(a, b, &mut vertices), mid(b, c, &mut vertices), mid(c, a, &mut vertices));
                [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
            })
            .collect();
    }
    ClosedMesh { vertices, faces }
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
    fn diagonal_rays_are_exact() {
        let (_, rays) = shared_edge_probe();
        assert_eq!(rays.len(), 20_000);
        for ray in rays {
            let end = ray.origin + ray.direction;
            assert_eq!(end.z, (end - ray.direction).z + ray.direction.z);
            assert_eq!(end - ray.direction, ray.origin, "{ray:?}");
            // On the diagonal of its quad: x and y equal.
            assert_eq!(end.x, end.y, "{ray:?}");
        }
    }

    #[test]
    fn icosphere_is_closed() {
        let sphere = icosphere(2);
        let mut edges = std::collections::HashMap::new();
        for f in &sphere.faces {
            for e in 0..3 {
                let (a, b) = (f[e], f[(e + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        assert!(edges.values().all(|&n| n == 2));
        assert_eq!(sphere.faces.len(), 320);
    }
}
