//! Shapes whose hard cases are known: squares whose shared diagonal rays
//! pass exactly through, and closed meshes (icosphere, tessellated cube,
//! cylinder) that rays aimed inside must hit, placed at any scale and
//! distance from the origin.

use rtgi_math::{Ray, Rng, Vec3, uniform_sphere};

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

/// A closed mesh: vertex positions and triangles as indices.
#[derive(Clone, Debug)]
pub struct ClosedMesh {
    /// Vertex positions.
    pub vertices: Vec<Vec3>,
    /// Triangles as three indices into `vertices`.
    pub faces: Vec<[u32; 3]>,
}

impl ClosedMesh {
    /// The triangles' corners, in face order, as the structures take them.
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

impl ClosedMesh {
    /// The mesh scaled by `scale` and moved by `offset`. Each vertex is
    /// transformed once, so shared vertices stay shared and the mesh stays
    /// closed, however much rounding moves them.
    pub fn placed(&self, scale: f32, offset: Vec3) -> ClosedMesh {
        ClosedMesh { vertices: self.vertices.iter().map(|&v| v * scale + offset).collect(), faces: self.faces.clone() }
    }
}

/// A cube of side 2 centred at the origin, each face an `n` × `n` grid of
/// quads (two triangles each), with shared vertices.
pub fn tessellated_cube(n: u32) -> ClosedMesh {
    let mut mesh = ClosedMesh { vertices: Vec::new(), faces: Vec::new() };
    let mut index = std::collections::HashMap::new();
    let mut vertex = |p: Vec3, mesh: &mut ClosedMesh| -> u32 {
        *index.entry(p.to_array().map(f32::to_bits)).or_insert_with(|| {
            mesh.vertices.push(p);
            mesh.vertices.len() as u32 - 1
        })
    };
    for axis in 0..3 {
        for side in [-1.0f32, 1.0] {
            let point = |i: u32, j: u32| {
                let (u, v) = (2.0 * i as f32 / n as f32 - 1.0, 2.0 * j as f32 / n as f32 - 1.0);
                let mut p = [0.0; 3];
                p[axis] = side;
                p[(axis + 1) % 3] = u;
                p[(axis + 2) % 3] = v;
                Vec3::from(p)
            };
            for i in 0..n {
                for j in 0..n {
                    let q = [point(i, j), point(i + 1, j), point(i + 1, j + 1), point(i, j + 1)]
                        .map(|p| vertex(p, &mut mesh));
                    // Outward winding on both sides, the diagonal alternating.
                    let (a, b, c, d) = if side > 0.0 { (q[0], q[1], q[2], q[3]) } else { (q[0], q[3], q[2], q[1]) };
                    if (i + j) % 2 == 0 {
                        mesh.faces.extend([[a, b, c], [a, c, d]]);
                    } else {
                        mesh.faces.extend([[a, b, d], [b, c, d]]);
                    }
                }
            }
        }
    }
    mesh
}

/// A closed cylinder of radius 1 around the z axis from z = -1 to 1:
/// `segments` around, `rings` bands along the axis, capped by fans around
/// a centre vertex.
pub fn cylinder(segments: u32, rings: u32) -> ClosedMesh {
    let mut vertices = Vec::new();
    for ring in 0..=rings {
        let z = 2.0 * ring as f32 / rings as f32 - 1.0;
        for s in 0..segments {
            let angle = std::f32::consts::TAU * s as f32 / segments as f32;
            vertices.push(Vec3::new(angle.cos(), angle.sin(), z));
        }
    }
    let at = |ring: u32, s: u32| ring * segments + s % segments;
    let mut faces = Vec::new();
    for ring in 0..rings {
        for s in 0..segments {
            let (a, b, c, d) = (at(ring, s), at(ring, s + 1), at(ring + 1, s + 1), at(ring + 1, s));
            faces.extend([[a, b, c], [a, c, d]]);
        }
    }
    let bottom = vertices.len() as u32;
    vertices.push(Vec3::new(0.0, 0.0, -1.0));
    let top = vertices.len() as u32;
    vertices.push(Vec3::new(0.0, 0.0, 1.0));
    for s in 0..segments {
        faces.push([bottom, at(0, s + 1), at(0, s)]);
        faces.push([top, at(rings, s), at(rings, s + 1)]);
    }
    ClosedMesh { vertices, faces }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_closed(mesh: &ClosedMesh) {
        let mut edges = std::collections::HashMap::new();
        for f in &mesh.faces {
            for e in 0..3 {
                *edges.entry((f[e], f[(e + 1) % 3])).or_insert(0) += 1;
            }
        }
        // Every directed edge once, and its reverse once: closed and consistently wound.
        for (&(a, b), &n) in &edges {
            assert_eq!(n, 1, "edge {a}-{b} used {n} times in one direction");
            assert_eq!(edges.get(&(b, a)), Some(&1), "edge {a}-{b} has no twin");
        }
    }

    #[test]
    fn shapes_are_closed_and_consistently_wound() {
        assert_closed(&icosphere(2));
        assert_eq!(icosphere(2).faces.len(), 320);
        assert_closed(&tessellated_cube(3));
        assert_closed(&cylinder(12, 3));
    }

    #[test]
    fn diagonal_rays_are_exact() {
        for (size, offset, bits) in [(1.0, Vec3::new(8.0, 8.0, 0.0), 20), (1024.0, Vec3::splat(1_048_576.0), 13)] {
            for ray in rays_through_diagonal(size, offset, bits, 1000, 5) {
                let end = ray.origin + ray.direction;
                assert_eq!(end - ray.direction, ray.origin, "{ray:?}");
                assert_eq!(end.x, end.y, "{ray:?}");
            }
        }
    }
}
