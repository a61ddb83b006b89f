//! A triangle mesh given as shared vertex positions and index triples,
//! borrowed from the caller: builds read it directly, with no soup of
//! corners built first.

use std::fmt;

use rtgi_math::Vec3;

use crate::TriangleSource;

/// An indexed triangle mesh: triangle `i` has the corners
/// `positions[indices[i][0]]`, `positions[indices[i][1]]` and
/// `positions[indices[i][2]]`. Both buffers are the caller's, borrowed;
/// every structure builds from it as from the equivalent soup, with
/// bit-identical answers, and hits name triangles by their index in
/// `indices`.
///
/// ```
/// use rtgi_accel::{AccelKind, IndexedMesh, Ray, Vec3};
///
/// // A unit square in the plane z = 0: four shared vertices, two triangles.
/// let positions = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
/// let indices = [[0, 1, 2], [0, 2, 3]];
/// let mesh = IndexedMesh::new(&positions, &indices).expect("every index names a vertex");
/// let bvh = AccelKind::Sah.build(&mesh, &AccelKind::Sah.default_params());
/// let hit = bvh.intersect(&Ray::new(Vec3::new(0.25, 0.75, 1.0), -Vec3::Z)).unwrap();
/// assert_eq!((hit.t, hit.triangle), (1.0, 1));
/// ```
#[derive(Clone, Copy, Debug)]
pub struct IndexedMesh<'a> {
    positions: &'a [Vec3],
    indices: &'a [[u32; 3]],
}

impl<'a> IndexedMesh<'a> {
    /// A mesh over the caller's buffers, once every index is checked to
    /// name a vertex of `positions`. Degenerate triangles (a repeated
    /// index) are allowed: like every triangle of zero area they are never
    /// hit ([`crate::is_hittable`]).
    ///
    /// # Errors
    /// [`IndexedMeshError`] for the first triangle with an index of
    /// `positions.len()` or more.
    pub fn new(positions: &'a [Vec3], indices: &'a [[u32; 3]]) -> Result<Self, IndexedMeshError> {
        let vertex_count = positions.len();
        for (triangle, corners) in indices.iter().enumerate() {
            for (corner, &index) in corners.iter().enumerate() {
                if index as usize >= vertex_count {
                    return Err(IndexedMeshError { triangle, corner, index, vertex_count });
                }
            }
        }
        Ok(Self { positions, indices })
    }

    /// The vertex positions the indices refer to.
    pub fn positions(&self) -> &'a [Vec3] {
        self.positions
    }

    /// One index triple per triangle.
    pub fn indices(&self) -> &'a [[u32; 3]] {
        self.indices
    }
}

impl TriangleSource for IndexedMesh<'_> {
    fn len(&self) -> usize {
        self.indices.len()
    }

    #[inline]
    fn corners(&self, index: usize) -> [Vec3; 3] {
        self.indices[index].map(|vertex| self.positions[vertex as usize])
    }
}

/// An index of an [`IndexedMesh`] that names no vertex.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct IndexedMeshError {
    /// The triangle (its position in the index buffer).
    pub triangle: usize,
    /// Which of its three indices (0, 1 or 2).
    pub corner: usize,
    /// The index found.
    pub index: u32,
    /// The number of vertices; valid indices are below it.
    pub vertex_count: usize,
}

impl fmt::Display for IndexedMeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "triangle {} has index {} at corner {}, but the mesh has only {} vertices",
            self.triangle, self.index, self.corner, self.vertex_count
        )
    }
}

impl std::error::Error for IndexedMeshError {}
