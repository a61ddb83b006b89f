use std::time::Instant;

use rtgi_math::{Ray, Vec3, Vec3A};

use crate::triangle::{MollerTrumbore, TriangleTest, Watertight};
use crate::{Accel, AcceptAll, BuildStats, Counter, Hit, HitFilter, Intersector, NoCounter, TraversalCounters};

/// The reference structure: every ray is tested against every triangle, in
/// index order, O(n) per ray. Slow, simple, and the answer every other
/// structure must reproduce.
#[derive(Debug)]
pub struct LinearScan {
    triangles: Vec<[Vec3A; 3]>,
    stats: BuildStats,
    intersector: Intersector,
}

impl LinearScan {
    pub fn new(triangles: &[[Vec3; 3]], intersector: Intersector) -> Self {
        let start = Instant::now();
        let excluded_triangles = triangles.iter().filter(|t| !crate::bvh::is_hittable(t)).count();
        let triangles: Vec<[Vec3A; 3]> = triangles.iter().map(|t| t.map(Vec3A::from)).collect();
        let stats = BuildStats {
            variant: "linear".into(),
            triangles: triangles.len(),
            excluded_triangles,
            build_ms: start.elapsed().as_secs_f64() * 1e3,
            memory_bytes: std::mem::size_of_val(triangles.as_slice()),
            ..BuildStats::default()
        };
        Self { triangles, stats, intersector }
    }

    fn closest<C: Counter, F: HitFilter>(&self, ray: &Ray, counter: &mut C, filter: &F) -> Option<Hit> {
        match self.intersector {
            Intersector::Watertight => self.closest_with::<C, Watertight, F>(ray, counter, filter),
            Intersector::MollerTrumbore => self.closest_with::<C, MollerTrumbore, F>(ray, counter, filter),
        }
    }

    fn any<C: Counter, F: HitFilter>(&self, ray: &Ray, counter: &mut C, filter: &F) -> bool {
        match self.intersector {
            Intersector::Watertight => self.any_with::<C, Watertight, F>(ray, counter, filter),
            Intersector::MollerTrumbore => self.any_with::<C, MollerTrumbore, F>(ray, counter, filter),
        }
    }

    fn closest_with<C: Counter, T: TriangleTest, F: HitFilter>(
        &self,
        ray: &Ray,
        counter: &mut C,
        filter: &F,
    ) -> Option<Hit> {
        if !ray.is_valid() {
            return None;
        }
        let test_ray = T::prepare(ray.origin.into(), ray.direction.into());
        let mut closest: Option<Hit> = None;
        let mut t_max = ray.t_max;
        counter.triangles_tested(self.triangles.len() as u32);
        for (index, triangle) in self.triangles.iter().enumerate() {
            // Strictly closer only: at equal t the lower index, found first, stays.
            if let Some(h) = T::intersect(&test_ray, ray.t_min, t_max, triangle) {
                if closest.is_none_or(|c| h.t < c.t) && filter.accept(index as u32, h.beta, h.gamma) {
                    t_max = h.t;
                    closest = Some(Hit { t: h.t, triangle: index as u32, beta: h.beta, gamma: h.gamma });
                }
            }
        }
        closest
    }

    fn any_with<C: Counter, T: TriangleTest, F: HitFilter>(&self, ray: &Ray, counter: &mut C, filter: &F) -> bool {
        if !ray.is_valid() {
            return false;
        }
        let test_ray = T::prepare(ray.origin.into(), ray.direction.into());
        for (index, triangle) in self.triangles.iter().enumerate() {
            if T::intersect(&test_ray, ray.t_min, ray.t_max, triangle)
                .is_some_and(|h| filter.accept(index as u32, h.beta, h.gamma))
            {
                counter.triangles_tested(index as u32 + 1);
                return true;
            }
        }
        counter.triangles_tested(self.triangles.len() as u32);
        false
    }
}

impl Accel for LinearScan {
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.closest(ray, &mut NoCounter, &AcceptAll)
    }

    fn occluded(&self, ray: &Ray) -> bool {
        self.any(ray, &mut NoCounter, &AcceptAll)
    }

    fn intersect_counted(&self, ray: &Ray, counters: &mut TraversalCounters) -> Option<Hit> {
        counters.rays += 1;
        self.closest(ray, counters, &AcceptAll)
    }

    fn occluded_counted(&self, ray: &Ray, counters: &mut TraversalCounters) -> bool {
        counters.rays += 1;
        self.any(ray, counters, &AcceptAll)
    }

    fn intersect_filtered(&self, ray: &Ray, accept: &dyn Fn(u32, f32, f32) -> bool) -> Option<Hit> {
        self.closest(ray, &mut NoCounter, &accept)
    }

    fn occluded_filtered(&self, ray: &Ray, accept: &dyn Fn(u32, f32, f32) -> bool) -> bool {
        self.any(ray, &mut NoCounter, &accept)
    }

    fn build_stats(&self) -> &BuildStats {
        &self.stats
    }
}
