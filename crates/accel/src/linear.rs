use std::time::Instant;

use rtgi_math::{Ray, Vec3A};

use crate::contract::{Best, HitFilter, PreparedRay, QueryKind, Structure, is_hittable, test_triangles};
use crate::triangle::{TriangleTest, with_triangle_test};
use crate::{BuildStats, Counter, Hit, Intersector, TriangleSource};

/// The reference structure: every ray is tested against every hittable
/// triangle, in index order, O(n) per ray. Slow, simple, and the answer
/// every other structure must reproduce bit for bit.
#[derive(Debug)]
pub struct LinearScan {
    /// The hittable triangles, in input order.
    triangles: Vec<[Vec3A; 3]>,
    /// Input index of each of `triangles`.
    ids: Vec<u32>,
    stats: BuildStats,
    intersector: Intersector,
}

impl LinearScan {
    /// Keeps the hittable triangles ([`crate::is_hittable`]) of `triangles`
    /// (a soup, an [`crate::IndexedMesh`] or any [`TriangleSource`]) in
    /// input order; the others are counted in [`BuildStats::excluded_triangles`].
    pub fn new(triangles: &(impl TriangleSource + ?Sized), intersector: Intersector) -> Self {
        let start = Instant::now();
        let (kept, ids): (Vec<[Vec3A; 3]>, Vec<u32>) = (0..triangles.len())
            .map(|i| (i, triangles.corners(i)))
            .filter(|(_, t)| is_hittable(t))
            .map(|(i, t)| (t.map(Vec3A::from), i as u32))
            .unzip();
        let stats = BuildStats {
            variant: "linear".into(),
            triangles: triangles.len(),
            excluded_triangles: triangles.len() - kept.len(),
            build_ms: start.elapsed().as_secs_f64() * 1e3,
            memory_bytes: std::mem::size_of_val(kept.as_slice()) + std::mem::size_of_val(ids.as_slice()),
            ..BuildStats::default()
        };
        Self { triangles: kept, ids, stats, intersector }
    }

    fn scan<Q: QueryKind, C: Counter, T: TriangleTest, F: HitFilter>(
        &self,
        ray: &Ray,
        counter: &mut C,
        filter: &F,
    ) -> Option<Hit> {
        if !ray.is_valid() {
            return None;
        }
        let mut best = Best::new(ray);
        test_triangles::<Q, C, T, F>(&self.triangles, &self.ids, &PreparedRay::new(ray), &mut best, counter, filter);
        best.hit
    }
}

impl Structure for LinearScan {
    fn query<Q: QueryKind, C: Counter, F: HitFilter>(&self, ray: &Ray, counter: &mut C, filter: &F) -> Option<Hit> {
        with_triangle_test!(self.intersector, |T| self.scan::<Q, C, T, F>(ray, counter, filter))
    }

    fn stats(&self) -> &BuildStats {
        &self.stats
    }
}
