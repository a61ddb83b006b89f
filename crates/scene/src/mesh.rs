use std::collections::HashMap;

use rtgi_math::{Vec2, Vec3};

use crate::{Scene, Triangle, Vertex};

/// Normals of faces meeting at a vertex are averaged only if they differ by
/// less than this angle, so that smooth surfaces shade smoothly while the
/// corners of boxes stay sharp.
const CREASE_ANGLE_DEGREES: f32 = 60.0;

/// One triangle as an importer sees it: indices into the builder's attribute
/// arrays, the normal and texture indices optional.
#[derive(Clone, Copy, Debug)]
struct Face {
    positions: [u32; 3],
    uvs: Option<[u32; 3]>,
    normals: Option<[u32; 3]>,
    material: u32,
}

/// Collects indexed triangles from an importer and turns them into scene
/// vertices: missing normals are computed (area-weighted, within a crease
/// angle), and each distinct (position, uv, normal) becomes one vertex.
#[derive(Debug, Default)]
pub struct MeshBuilder {
    positions: Vec<Vec3>,
    uvs: Vec<Vec2>,
    normals: Vec<Vec3>,
    faces: Vec<Face>,
    crease_angle_degrees: f32,
}

impl MeshBuilder {
    pub fn new(positions: Vec<Vec3>, uvs: Vec<Vec2>, normals: Vec<Vec3>) -> Self {
        Self { positions, uvs, normals, faces: Vec::new(), crease_angle_degrees: CREASE_ANGLE_DEGREES }
    }

    /// Computed normals are the faces' own (glTF's rule for meshes without normals).
    pub fn with_flat_normals(mut self) -> Self {
        self.crease_angle_degrees = 0.0;
        self
    }

    /// Adds a triangle. Indices must be in range of the arrays given to [`MeshBuilder::new`].
    pub fn push(&mut self, positions: [u32; 3], uvs: Option<[u32; 3]>, normals: Option<[u32; 3]>, material: u32) {
        self.faces.push(Face { positions, uvs, normals, material });
    }

    /// Appends the triangles, in the order pushed, to `scene`.
    pub fn finish_into(self, scene: &mut Scene) {
        let face_normals: Vec<Vec3> = self
            .faces
            .iter()
            .map(|f| {
                let [a, b, c] = f.positions.map(|i| self.positions[i as usize]);
                (b - a).cross(c - a)
            })
            .collect();
        let adjacency = self.faces_by_position(&face_normals);
        let cos_crease = self.crease_angle_degrees.to_radians().cos();

        let mut vertex_of: HashMap<(u32, u32, [u32; 3]), u32> = HashMap::new();
        scene.triangles.reserve(self.faces.len());
        for (face_index, face) in self.faces.iter().enumerate() {
            let own = face_normals[face_index].normalize_or_zero();
            let mut vertices = [0u32; 3];
            for corner in 0..3 {
                let position_index = face.positions[corner];
                let neighbours = || adjacency.faces_at(position_index).iter().map(|&g| face_normals[g as usize]);
                let normal = match face.normals {
                    Some(n) => self.normals[n[corner] as usize].normalize_or_zero(),
                    None => neighbours()
                        .filter(|n| n.normalize_or_zero().dot(own) >= cos_crease)
                        .sum::<Vec3>()
                        .normalize_or_zero(),
                };
                // Zero-length file normals and degenerate faces still get a unit
                // normal: the face's own, else its neighbours' mean, else +Z.
                let normal = [normal, own, neighbours().sum::<Vec3>().normalize_or_zero(), Vec3::Z]
                    .into_iter()
                    .find(|n| *n != Vec3::ZERO)
                    .unwrap_or(Vec3::Z);
                let uv_index = face.uvs.map_or(u32::MAX, |u| u[corner]);
                let key = (position_index, uv_index, normal.to_array().map(f32::to_bits));
                vertices[corner] = *vertex_of.entry(key).or_insert_with(|| {
                    scene.vertices.push(Vertex {
                        position: self.positions[position_index as usize],
                        normal,
                        uv: face.uvs.map_or(Vec2::ZERO, |u| self.uvs[u[corner] as usize]),
                    });
                    scene.vertices.len() as u32 - 1
                });
            }
            scene.triangles.push(Triangle { vertices, material: face.material });
        }
    }

    /// For each position, the faces using it, in compressed-row form. Faces
    /// with their own normals are left out: they never need computed ones.
    fn faces_by_position(&self, face_normals: &[Vec3]) -> Adjacency {
        let mut offsets = vec![0u32; self.positions.len() + 1];
        let needed = |f: &Face| f.normals.is_none();
        for face in self.faces.iter().filter(|f| needed(f)) {
            for p in face.positions {
                offsets[p as usize + 1] += 1;
            }
        }
        for i in 1..offsets.len() {
            offsets[i] += offsets[i - 1];
        }
        let mut fill = offsets.clone();
        let mut faces = vec![0u32; *offsets.last().unwrap_or(&0) as usize];
        for (index, face) in self.faces.iter().enumerate().filter(|(_, f)| needed(f)) {
            debug_assert!(index < face_normals.len());
            for p in face.positions {
                faces[fill[p as usize] as usize] = index as u32;
                fill[p as usize] += 1;
            }
        }
        Adjacency { offsets, faces }
    }
}

struct Adjacency {
    offsets: Vec<u32>,
    faces: Vec<u32>,
}

impl Adjacency {
    fn faces_at(&self, position: u32) -> &[u32] {
        let p = position as usize;
        &self.faces[self.offsets[p] as usize..self.offsets[p + 1] as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit cube's 8 corners and 12 outward-facing triangles.
    fn cube() -> MeshBuilder {
        let positions = (0..8).map(|i| Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, (i >> 2) as f32)).collect();
        let mut b = MeshBuilder::new(positions, vec![], vec![]);
        let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        for q in quads {
            b.push([q[0], q[1], q[2]], None, None, 0);
            b.push([q[0], q[2], q[3]], None, None, 0);
        }
        b
    }

    #[test]
    fn cube_corners_stay_sharp() {
        let mut scene = Scene::default();
        cube().finish_into(&mut scene);
        assert_eq!(scene.triangles.len(), 12);
        // Each of the 6 faces gets its own 4 vertices: 24 in all.
        assert_eq!(scene.vertices.len(), 24);
        for t in &scene.triangles {
            let [a, b, c] = t.vertices.map(|v| scene.vertices[v as usize]);
            let geometric = (b.position - a.position).cross(c.position - a.position).normalize();
            for v in [a, b, c] {
                assert!((v.normal - geometric).length() < 1e-6);
            }
        }
    }

    #[test]
    fn gentle_folds_are_smoothed() {
        // Two triangles meeting at a 20 degree fold share averaged normals on the fold.
        let z = 20f32.to_radians().tan();
        let positions = vec![Vec3::ZERO, Vec3::Y, Vec3::new(-1.0, 0.0, 0.0), Vec3::new(1.0, 0.0, z)];
        let mut b = MeshBuilder::new(positions, vec![], vec![]);
        b.push([0, 1, 2], None, None, 0);
        b.push([0, 3, 1], None, None, 0);
        let mut scene = Scene::default();
        b.finish_into(&mut scene);
        assert_eq!(scene.vertices.len(), 4);
        let shared = scene.vertices[scene.triangles[0].vertices[0] as usize].normal;
        // About halfway between the two face normals (0 and 20 degrees from +Z).
        assert!(shared.z > 0.98 && shared.x < -0.1 && shared.x > -0.25, "{shared}");
    }
}
