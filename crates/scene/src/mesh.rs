use std::collections::HashMap;

use rtgi_math::{Frame, Vec2, Vec3, Vec4};

use crate::{Scene, Triangle, Vertex};

/// Faces sharing an edge are smoothed together only if their normals differ
/// by at most this angle, so that smooth surfaces shade smoothly while the
/// edges of boxes stay sharp.
const CREASE_ANGLE_DEGREES: f32 = 60.0;

/// How many faces of different directions one edge remembers when forming
/// smoothing groups (see [`MeshBuilder::smoothing_groups`]); a plain edge
/// needs one, the edge of a two-sided sheet two.
const DIRECTIONS_PER_EDGE: usize = 4;

/// An empty place in an edge's list of faces.
const NO_FACE: u32 = u32::MAX;

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
/// vertices: missing normals are computed (area-weighted, over smoothing
/// groups bounded by a crease angle), and each distinct (position, uv,
/// normal) becomes one vertex.
#[derive(Debug, Default)]
pub struct MeshBuilder {
    positions: Vec<Vec3>,
    uvs: Vec<Vec2>,
    normals: Vec<Vec3>,
    faces: Vec<Face>,
    crease_angle_degrees: f32,
    /// Tangents given by the file, indexed like the normals.
    tangents: Vec<Vec4>,
    /// A second texture coordinate set, indexed like the positions (glTF's
    /// `TEXCOORD_1`, whose index is the position's); empty where there is none.
    second_uvs: Vec<Vec2>,
    /// Vertex colours, indexed like the positions; empty where there are none.
    colors: Vec<Vec4>,
}

impl MeshBuilder {
    /// A builder over a mesh's positions, texture coordinates and normals, which faces index into.
    pub fn new(positions: Vec<Vec3>, uvs: Vec<Vec2>, normals: Vec<Vec3>) -> Self {
        Self {
            positions,
            uvs,
            normals,
            faces: Vec::new(),
            crease_angle_degrees: CREASE_ANGLE_DEGREES,
            tangents: Vec::new(),
            second_uvs: Vec::new(),
            colors: Vec::new(),
        }
    }

    /// A second texture coordinate set and vertex colours, one per
    /// position (either may be empty): formats such as glTF index every
    /// attribute of a vertex with the position's index.
    pub fn with_per_position(mut self, second_uvs: Vec<Vec2>, colors: Vec<Vec4>) -> Self {
        self.second_uvs = second_uvs;
        self.colors = colors;
        self
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
        let face_normals = self.face_normals();
        let smooth = self.smooth_corner_normals(&face_normals);
        let mean_at_position = self.mean_normals_by_position(&face_normals);

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
                let normal = match face.normals {
                    Some(n) => self.normals[n[corner] as usize].normalize_or_zero(),
                    None => smooth[3 * face_index + corner],
                };
                // Zero-length file normals and degenerate faces still get a unit
                // normal: the face's own, else its neighbours' mean, else +Z.
                let normal = [normal, own, mean_at_position[position_index as usize], Vec3::Z]
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
                        uv1: self.second_uvs.get(position_index as usize).copied().unwrap_or(Vec2::ZERO),
                        color: self.colors.get(position_index as usize).copied().unwrap_or(Vec4::ONE),
                        tangent: tangent.unwrap_or(Vec4::ZERO),
                    });
                    scene.vertices.len() as u32 - 1
                });
            }
            scene.triangles.push(Triangle { vertices, material: face.material });
        }
        compute_tangents(scene, first_vertex, first_triangle, &given_tangent);
    }

    /// Each face's normal, its length twice the face's area.
    fn face_normals(&self) -> Vec<Vec3> {
        self.faces
            .iter()
            .map(|f| {
                let [a, b, c] = f.positions.map(|i| self.positions[i as usize]);
                (b - a).cross(c - a)
            })
            .collect()
    }

    /// The computed normal of every corner (corner `c` of face `f` at index
    /// `3 f + c`) of the faces without file normals: the normalised sum of
    /// the area-weighted normals of the faces in its smoothing group (see
    /// [`MeshBuilder::smoothing_groups`]); zero where that sum is zero.
    /// Corners of faces with file normals are left zero.
    fn smooth_corner_normals(&self, face_normals: &[Vec3]) -> Vec<Vec3> {
        let (mut groups, _comparisons) = self.smoothing_groups(face_normals);
        let computed = |corner: usize| self.faces[corner / 3].normals.is_none();
        let mut sums = vec![Vec3::ZERO; 3 * self.faces.len()];
        for corner in (0..sums.len()).filter(|&c| computed(c)) {
            sums[groups.find(corner)] += face_normals[corner / 3];
        }
        (0..sums.len())
            .map(|corner| if computed(corner) { sums[groups.find(corner)].normalize_or_zero() } else { Vec3::ZERO })
            .collect()
    }

    /// The smoothing groups of the corners of faces without file normals,
    /// by the "auto smooth" rule of Blender and most modelling tools: around
    /// each position, two faces sharing an edge (the same two position
    /// indices) join when their normals differ by at most the crease angle,
    /// and joins chain, so a finely tessellated curved surface is one group
    /// however far its ends turn. Faces that meet only at the position, or
    /// across a sharper bend, stay apart.
    ///
    /// The edges are found through a hash map and the groups kept in a
    /// union-find over corners, so the work is linear in the number of
    /// faces (expected), whatever the valence of a position; comparing each
    /// corner with every face at its position was quadratic in the valence.
    ///
    /// An edge remembers the first face of each direction met on it, up to
    /// [`DIRECTIONS_PER_EDGE`], and a later face joins the first of those
    /// within the crease angle, else is remembered itself (if there is
    /// room). A manifold edge so joins its two faces; the front and back of
    /// a two-sided sheet sharing positions each stay smooth without joining
    /// each other; and an edge shared by many faces (non-manifold) costs
    /// constant time per face. Degenerate faces join nothing.
    ///
    /// Also returns how many pairs of face normals it compared: the work
    /// that was quadratic, counted so that a test can keep it linear.
    fn smoothing_groups(&self, face_normals: &[Vec3]) -> (UnionFind, u64) {
        let cos_crease = self.crease_angle_degrees.to_radians().cos();
        let unit: Vec<Vec3> = face_normals.iter().map(|n| n.normalize_or_zero()).collect();
        let comparisons = std::cell::Cell::new(0u64);
        let bend_gently = |f: usize, g: usize| {
            comparisons.set(comparisons.get() + 1);
            unit[f] != Vec3::ZERO && unit[g] != Vec3::ZERO && unit[f].dot(unit[g]) >= cos_crease
        };
        let mut groups = UnionFind::new(3 * self.faces.len());
        let mut faces_on_edge: HashMap<(u32, u32), [u32; DIRECTIONS_PER_EDGE]> = HashMap::new();
        for (f, face) in self.faces.iter().enumerate().filter(|(_, f)| f.normals.is_none()) {
            for corner in 0..3 {
                let (p, q) = (face.positions[corner], face.positions[(corner + 1) % 3]);
                let remembered = faces_on_edge.entry((p.min(q), p.max(q))).or_insert([NO_FACE; DIRECTIONS_PER_EDGE]);
                let known = remembered.iter().position(|&g| g == NO_FACE).unwrap_or(DIRECTIONS_PER_EDGE);
                match remembered[..known].iter().copied().find(|&g| bend_gently(f, g as usize)) {
                    Some(g) => {
                        for position in [p, q] {
                            groups.union(self.corner_at(f, position), self.corner_at(g as usize, position));
                        }
                    }
                    None if known < DIRECTIONS_PER_EDGE => remembered[known] = f as u32,
                    // The edge remembers no more directions: the face stays apart across it.
                    None => {}
                }
            }
        }
        (groups, comparisons.get())
    }

    /// The index (`3 f + c`) of the corner of face `f` at `position`, which
    /// the face must use.
    fn corner_at(&self, f: usize, position: u32) -> usize {
        let corner = self.faces[f].positions.iter().position(|&p| p == position);
        3 * f + corner.expect("the face uses the position")
    }

    /// For each position, the normalised sum of the normals of the faces
    /// without file normals that use it: the fallback for corners whose own
    /// face is degenerate.
    fn mean_normals_by_position(&self, face_normals: &[Vec3]) -> Vec<Vec3> {
        let mut sums = vec![Vec3::ZERO; self.positions.len()];
        for (face, normal) in self.faces.iter().zip(face_normals).filter(|(f, _)| f.normals.is_none()) {
            for p in face.positions {
                sums[p as usize] += *normal;
            }
        }
        sums.iter().map(|s| s.normalize_or_zero()).collect()
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

/// Disjoint sets of the indices `0..n`, with path halving and union by
/// size, so that any sequence of operations takes nearly linear time.
struct UnionFind {
    parent: Vec<u32>,
    size: Vec<u32>,
}

impl UnionFind {
    fn new(n: usize) -> Self {
        Self { parent: (0..n as u32).collect(), size: vec![1; n] }
    }

    /// The representative of `i`'s set.
    fn find(&mut self, mut i: usize) -> usize {
        while self.parent[i] as usize != i {
            let grandparent = self.parent[self.parent[i] as usize];
            self.parent[i] = grandparent;
            i = grandparent as usize;
        }
        i
    }

    /// Merges the sets of `a` and `b`.
    fn union(&mut self, a: usize, b: usize) {
        let (a, b) = (self.find(a), self.find(b));
        if a == b {
            return;
        }
        let (small, large) = if self.size[a] < self.size[b] { (a, b) } else { (b, a) };
        self.parent[small] = large as u32;
        self.size[large] += self.size[small];
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

    /// A closed fan of `count` triangles around position 0, at `centre`,
    /// whose rim is the unit circle in the xy plane; counter-clockwise seen
    /// from +z.
    fn fan(count: u32, centre: Vec3) -> MeshBuilder {
        let rim = (0..count).map(|i| {
            let angle = std::f32::consts::TAU * i as f32 / count as f32;
            Vec3::new(angle.cos(), angle.sin(), 0.0)
        });
        let mut b = MeshBuilder::new(std::iter::once(centre).chain(rim).collect(), vec![], vec![]);
        for i in 0..count {
            b.push([0, 1 + i, 1 + (i + 1) % count], None, None, 0);
        }
        b
    }

    /// The most face normals smoothing may compare per face: each of its
    /// three edges remembers at most [`DIRECTIONS_PER_EDGE`] faces.
    const MOST_COMPARISONS_PER_FACE: u64 = 3 * DIRECTIONS_PER_EDGE as u64;

    /// Builds the scene of `b` after checking that smoothing it compares a
    /// bounded number of face normals per face: work linear in the faces,
    /// whatever the valence of a vertex. Counted, not timed: comparing each
    /// corner with every face at its position (as once) took minutes for a
    /// fan of 100,000 faces, and a timer would see that only on a quiet machine.
    fn finish_in_linear_work(b: MeshBuilder) -> Scene {
        let (_, comparisons) = b.smoothing_groups(&b.face_normals());
        let faces = b.faces.len() as u64;
        assert!(
            comparisons <= MOST_COMPARISONS_PER_FACE * faces,
            "{comparisons} comparisons of face normals for {faces} faces: more than {MOST_COMPARISONS_PER_FACE} a face"
        );
        let mut scene = Scene::default();
        b.finish_into(&mut scene);
        scene
    }

    /// The one vertex that every triangle of a fan has as its first corner.
    fn fan_centre(scene: &Scene) -> Vertex {
        let centre = scene.triangles[0].vertices[0];
        assert!(scene.triangles.iter().all(|t| t.vertices[0] == centre), "the centre was split");
        scene.vertices[centre as usize]
    }

    #[test]
    fn a_flat_fan_of_100000_triangles_is_smoothed_with_linear_work() {
        let scene = finish_in_linear_work(fan(100_000, Vec3::ZERO));
        assert_eq!(scene.triangles.len(), 100_000);
        assert_eq!(scene.vertices.len(), 100_001);
        // Every face normal is exactly along +z, and so is their sum.
        for v in &scene.vertices {
            assert_eq!((v.normal.x, v.normal.y), (0.0, 0.0), "{}", v.normal);
            assert!((v.normal.z - 1.0).abs() < 1e-6, "{}", v.normal);
        }
        assert_eq!(fan_centre(&scene).position, Vec3::ZERO);
    }

    #[test]
    fn a_cone_of_100000_triangles_is_smoothed_with_linear_work() {
        // Faces tilt 45 degrees out from the axis, so faces on opposite sides
        // differ by 90 degrees; neighbours differ by a tiny angle and chain
        // into one smoothing group around the apex.
        let scene = finish_in_linear_work(fan(100_000, Vec3::Z));
        assert_eq!(scene.vertices.len(), 100_001);
        let apex = fan_centre(&scene);
        assert_eq!(apex.position, Vec3::Z);
        assert!((apex.normal - Vec3::Z).length() < 1e-4, "{}", apex.normal);
        // A rim vertex averages its two faces: 45 degrees from the axis.
        let rim = scene.vertices[scene.triangles[0].vertices[1] as usize];
        assert!((rim.normal.z - std::f32::consts::FRAC_1_SQRT_2).abs() < 1e-4, "{}", rim.normal);
    }

    #[test]
    fn an_edge_shared_by_100000_faces_is_handled_with_linear_work() {
        // A book of pages around the edge from position 0 to position 1.
        let count = 100_000u32;
        let pages = (0..count).map(|i| {
            let angle = std::f32::consts::TAU * i as f32 / count as f32;
            Vec3::new(angle.cos(), angle.sin(), 0.5)
        });
        let positions = [Vec3::ZERO, Vec3::Z].into_iter().chain(pages).collect();
        let mut b = MeshBuilder::new(positions, vec![], vec![]);
        for i in 0..count {
            b.push([0, 1, 2 + i], None, None, 0);
        }
        let scene = finish_in_linear_work(b);
        assert_eq!(scene.triangles.len(), count as usize);
        assert!(scene.vertices.iter().all(|v| (v.normal.length() - 1.0).abs() < 1e-5));
    }

    #[test]
    fn both_sides_of_a_two_sided_sheet_stay_smooth() {
        // Two triangles meeting at a 20 degree fold, and the same two wound
        // the other way, on the same positions: the edge has four faces.
        let z = 20f32.to_radians().tan();
        let positions = vec![Vec3::ZERO, Vec3::Y, Vec3::new(-1.0, 0.0, 0.0), Vec3::new(1.0, 0.0, z)];
        let mut b = MeshBuilder::new(positions, vec![], vec![]);
        b.push([0, 1, 2], None, None, 0);
        b.push([0, 2, 1], None, None, 0);
        b.push([0, 3, 1], None, None, 0);
        b.push([0, 1, 3], None, None, 0);
        let mut scene = Scene::default();
        b.finish_into(&mut scene);
        let normal_at = |t: usize, corner: usize| scene.vertices[scene.triangles[t].vertices[corner] as usize].normal;
        // Each side shares one normal on the fold, the back's opposite the front's.
        assert_eq!(normal_at(0, 0), normal_at(2, 0));
        assert_eq!(normal_at(1, 0), normal_at(3, 0));
        assert!((normal_at(0, 0) + normal_at(1, 0)).length() < 1e-6);
        assert!(normal_at(0, 0).z > 0.98, "{}", normal_at(0, 0));
    }

    #[test]
    fn faces_meeting_only_at_a_vertex_are_not_smoothed_together() {
        // Two triangles 20 degrees apart that share position 0 and no edge.
        let z = 20f32.to_radians().tan();
        let positions =
            vec![Vec3::ZERO, Vec3::Y, Vec3::new(-1.0, 0.0, 0.0), Vec3::new(1.0, 0.0, z), Vec3::new(0.0, -1.0, 0.0)];
        let mut b = MeshBuilder::new(positions, vec![], vec![]);
        b.push([0, 1, 2], None, None, 0);
        b.push([0, 4, 3], None, None, 0);
        let mut scene = Scene::default();
        b.finish_into(&mut scene);
        assert_eq!(scene.vertices.len(), 6);
        assert_eq!(scene.vertices[scene.triangles[0].vertices[0] as usize].normal, Vec3::Z);
    }

    #[test]
    fn degenerate_faces_take_their_neighbours_mean() {
        // A zero-area triangle (0 1 3) beside a tilted proper one (0 1 2).
        let positions = vec![Vec3::ZERO, Vec3::X, Vec3::new(0.0, 1.0, 1.0), Vec3::new(2.0, 0.0, 0.0)];
        let mut b = MeshBuilder::new(positions, vec![], vec![]);
        b.push([0, 1, 2], None, None, 0);
        b.push([0, 1, 3], None, None, 0);
        let mut scene = Scene::default();
        b.finish_into(&mut scene);
        let proper = scene.vertices[scene.triangles[0].vertices[0] as usize].normal;
        assert!((proper - Vec3::new(0.0, -1.0, 1.0).normalize()).length() < 1e-6, "{proper}");
        let degenerate = scene.triangles[1].vertices.map(|v| scene.vertices[v as usize].normal);
        // Positions 0 and 1 take the proper face's normal; position 3 has
        // only the degenerate face: +Z as the last resort.
        assert_eq!(degenerate, [proper, proper, Vec3::Z]);
    }
}
