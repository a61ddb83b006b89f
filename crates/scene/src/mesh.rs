use std::collections::HashMap;

use rtgi_math::{Frame, Vec2, Vec3, Vec4};

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
    /// Tangents given by the file, indexed like the normals.
    tangents: Vec<Vec4>,
}

impl MeshBuilder {
    pub fn new(positions: Vec<Vec3>, uvs: Vec<Vec2>, normals: Vec<Vec3>) -> Self {
        Self {
            positions,
            uvs,
            normals,
            faces: Vec::new(),
            crease_angle_degrees: CREASE_ANGLE_DEGREES,
            tangents: Vec::new(),
        }
    }

    /// Tangents from the file, one per normal; they are used where faces
    /// use the file's normals, and computed elsewhere.
    pub fn with_tangents(mut self, tangents: Vec<Vec4>) -> Self {
        self.tangents = tangents;
        self
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
        let first_vertex = scene.vertices.len();
        let first_triangle = scene.triangles.len();
        // Vertices whose tangent the file gave.
        let mut given_tangent: Vec<bool> = Vec::new();
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
                    let tangent = face.normals.and_then(|n| self.tangents.get(n[corner] as usize).copied());
                    given_tangent.push(tangent.is_some());
                    scene.vertices.push(Vertex {
                        position: self.positions[position_index as usize],
                        normal,
                        uv: face.uvs.map_or(Vec2::ZERO, |u| self.uvs[u[corner] as usize]),
                        tangent: tangent.unwrap_or(Vec4::ZERO),
                    });
                    scene.vertices.len() as u32 - 1
                });
            }
            scene.triangles.push(Triangle { vertices, material: face.material });
        }
        compute_tangents(scene, first_vertex, first_triangle, &given_tangent);
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

/// Tangents for the vertices from `first_vertex` on that the file gave none,
/// from the texture coordinates of the triangles from `first_triangle` on
/// (Lengyel 2001): each triangle adds the directions of increasing u and v
/// to its corners; the sum along u is made perpendicular to the normal, and
/// the sign of w says whether the v direction agrees with `normal × tangent`.
fn compute_tangents(scene: &mut Scene, first_vertex: usize, first_triangle: usize, given: &[bool]) {
    let count = scene.vertices.len() - first_vertex;
    let mut along_u = vec![Vec3::ZERO; count];
    let mut along_v = vec![Vec3::ZERO; count];
    for triangle in &scene.triangles[first_triangle..] {
        let [a, b, c] = triangle.vertices.map(|v| scene.vertices[v as usize]);
        let (e1, e2) = (b.position - a.position, c.position - a.position);
        let (d1, d2) = (b.uv - a.uv, c.uv - a.uv);
        let det = d1.x * d2.y - d2.x * d1.y;
        if det == 0.0 || !det.is_finite() {
            continue;
        }
        let u = (e1 * d2.y - e2 * d1.y) / det;
        let v = (e2 * d1.x - e1 * d2.x) / det;
        for &index in &triangle.vertices {
            let local = index as usize - first_vertex;
            along_u[local] += u;
            along_v[local] += v;
        }
    }
    for (local, vertex) in scene.vertices[first_vertex..].iter_mut().enumerate() {
        if given.get(local).copied().unwrap_or(false) {
            continue;
        }
        let n = vertex.normal;
        let t = (along_u[local] - n * n.dot(along_u[local])).normalize_or_zero();
        let t = if t == Vec3::ZERO { Frame::from_z(n).x } else { t };
        let w = if n.cross(t).dot(along_v[local]) < 0.0 { -1.0 } else { 1.0 };
        vertex.tangent = t.extend(w);
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
    fn tangents_follow_increasing_u_and_are_perpendicular() {
        // A quad in the xy plane with u along +x and v along -y (top-left origin).
        let positions = vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let uvs = vec![Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.0), Vec2::new(0.0, 0.0)];
        let mut b = MeshBuilder::new(positions, uvs, vec![]);
        b.push([0, 1, 2], Some([0, 1, 2]), None, 0);
        b.push([0, 2, 3], Some([0, 2, 3]), None, 0);
        let mut scene = Scene::default();
        b.finish_into(&mut scene);
        for v in &scene.vertices {
            assert!((v.tangent.truncate() - Vec3::X).length() < 1e-6, "{:?}", v.tangent);
            // v grows towards -y, and normal × tangent = +z × +x = +y: opposite.
            assert_eq!(v.tangent.w, -1.0);
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
