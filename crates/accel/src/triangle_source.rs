//! Where a build reads its triangles from: any [`TriangleSource`], so that
//! a caller with an indexed mesh ([`crate::IndexedMesh`]) never has to
//! expand it into a triangle soup first.

use rtgi_math::Vec3;

/// Triangles a structure can be built from, read by index: a soup
/// (`[[Vec3; 3]]`, arrays and vectors of them) or an indexed mesh
/// ([`crate::IndexedMesh`]).
///
/// Builds read each triangle's corners through [`TriangleSource::corners`],
/// possibly from several threads at once (hence `Sync`), and copy them
/// into their own leaf order; the source is not kept. Hits name triangles
/// by their index here. A source and the soup of its corners give every
/// structure bit-identical answers: builds see nothing but the corners.
pub trait TriangleSource: Sync {
    /// Number of triangles.
    fn len(&self) -> usize;

    /// The three corners of triangle `index` (`index < self.len()`).
    ///
    /// # Panics
    /// May panic if `index` is out of range.
    fn corners(&self, index: usize) -> [Vec3; 3];

    /// Whether there are no triangles.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl TriangleSource for [[Vec3; 3]] {
    fn len(&self) -> usize {
        <[[Vec3; 3]]>::len(self)
    }

    #[inline]
    fn corners(&self, index: usize) -> [Vec3; 3] {
        self[index]
    }
}

impl<const N: usize> TriangleSource for [[Vec3; 3]; N] {
    fn len(&self) -> usize {
        N
    }

    #[inline]
    fn corners(&self, index: usize) -> [Vec3; 3] {
        self[index]
    }
}

impl TriangleSource for Vec<[Vec3; 3]> {
    fn len(&self) -> usize {
        Vec::len(self)
    }

    #[inline]
    fn corners(&self, index: usize) -> [Vec3; 3] {
        self[index]
    }
}

impl<S: TriangleSource + ?Sized> TriangleSource for &S {
    fn len(&self) -> usize {
        S::len(self)
    }

    #[inline]
    fn corners(&self, index: usize) -> [Vec3; 3] {
        S::corners(self, index)
    }
}
