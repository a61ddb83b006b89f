//! The exactness contract, implemented once for every structure.
//!
//! Every structure answers a query with the same triangle, and the same
//! bits of `t`, `beta` and `gamma`, as the linear scan:
//!
//! - **Hittable.** Only triangles for which [`is_hittable`] holds can be
//!   hit (finite corners, non-zero area); structures may leave the others
//!   out, and the linear scan skips them too.
//! - **The hit rule.** Whether a ray hits a triangle, and where, is a pure
//!   function of the ray and the triangle ([`hit_triangle`]): the
//!   triangle test's answer within `[t_min, t_max]`, kept only if the ray
//!   also passes the robust slab test of the triangle's own bounding box,
//!   with `t` raised to that box's entry distance if rounding put it
//!   below. Because the slab test is monotone in the box, a node box that
//!   holds the triangle is then entered no later than the hit and not left
//!   before it, so culling a box whose entry lies beyond the best hit so
//!   far never loses a hit, nor a tie (boxes entered at exactly the best
//!   `t` are still visited).
//! - **Closest hit.** Among the hittable triangles hit, the smallest `t`;
//!   at equal `t`, the lowest triangle index ([`Best::offer`]).
//! - **Any hit.** True exactly when the closest hit would return a hit.
//!
//! This holds for the linear scan, every BVH variant, leaf size and bin
//! count with the robust traversal, at any thread count, with every
//! intersector, and for rays in every direction, including axis-parallel
//! ones and directions with zero or negative-zero components. (The fast
//! traversal drops boxes that rays graze and is outside the contract.)
//!
//! Structures implement [`Structure`], one traversal generic over the
//! [`QueryKind`]; the [`Accel`] methods come from one blanket
//! implementation.

use rtgi_math::{Ray, Vec3, Vec3A};

use crate::slab::{BoxRay, RobustSlabs, SlabTest};
use crate::triangle::{TriangleTest, with_triangle_test};
use crate::triangle_hit::{LaneHits, TriangleHit};
use crate::{Accel, BuildStats, Counter, Hit, Intersector, NoCounter, TraversalCounters};

/// Whether a triangle can ever be hit: all corners finite and a non-zero
/// area. The area is measured in double precision, where the cross product
/// of single-precision edges neither underflows nor overflows, so a
/// triangle counts as degenerate only when its corners are (very nearly
/// exactly) collinear or repeated.
pub fn is_hittable(triangle: &[Vec3; 3]) -> bool {
    if !triangle.iter().all(|v| v.is_finite()) {
        return false;
    }
    let [a, b, c] = triangle.map(|v| v.as_dvec3());
    (b - a).cross(c - a) != rtgi_math::glam::DVec3::ZERO
}

impl Intersector {
    /// Intersects one ray with one triangle under the structures' hit rule
    /// (see the crate's exactness contract): the hit if the triangle can be
    /// hit at all ([`crate::is_hittable`]), its `t` lies in `[t_min, t_max]`
    /// and the point is inside the triangle, edges included, with exactly
    /// the bits every structure reports for it. Both sides are hit;
    /// triangles of zero area and rays in a triangle's plane never are.
    pub fn intersect(
        self,
        origin: Vec3,
        direction: Vec3,
        t_min: f32,
        t_max: f32,
        v: &[Vec3; 3],
    ) -> Option<TriangleHit> {
        let ray = Ray::with_range(origin, direction, t_min, t_max);
        if !ray.is_valid() || !is_hittable(v) {
            return None;
        }
        let v = v.map(Vec3A::from);
        with_triangle_test!(self, |T| hit_triangle(&PreparedRay::<T>::new(&ray), &v, t_max))
    }
}

/// A ray prepared once for the triangle test `T` and for box tests.
pub(crate) struct PreparedRay<T: TriangleTest> {
    pub(crate) triangles: T::Ray,
    pub(crate) boxes: BoxRay,
}

impl<T: TriangleTest> PreparedRay<T> {
    #[inline(always)]
    pub(crate) fn new(ray: &Ray) -> Self {
        Self::with_boxes(ray, BoxRay::new(ray))
    }

    /// The ray prepared for triangles, with its box preparation done already.
    #[inline(always)]
    pub(crate) fn with_boxes(ray: &Ray, boxes: BoxRay) -> Self {
        Self { triangles: T::prepare(ray.origin.into(), ray.direction.into()), boxes }
    }
}

/// The hit rule: where `ray` hits `triangle` with the triangle test `T`,
/// or `None`. `t_max` may be lowered below the ray's own to skip hits that
/// cannot win, which never changes a hit that is reported: the answer
/// within the ray's range is a function of the ray and the triangle alone.
#[inline(always)]
pub(crate) fn hit_triangle<T: TriangleTest>(
    ray: &PreparedRay<T>,
    triangle: &[Vec3A; 3],
    t_max: f32,
) -> Option<TriangleHit> {
    let hit = T::intersect(&ray.triangles, ray.boxes.t_min, t_max, triangle)?;
    box_rule(&ray.boxes, triangle, hit, t_max)
}

/// The second half of the hit rule: `hit`, found by the triangle test on
/// `triangle`, counts only if the ray passes the robust slab test of the
/// triangle's own box, and no earlier than it enters that box.
#[inline(always)]
pub(crate) fn box_rule(ray: &BoxRay, triangle: &[Vec3A; 3], hit: TriangleHit, t_max: f32) -> Option<TriangleHit> {
    let [a, b, c] = *triangle;
    box_rule_at(hit, RobustSlabs::enter(ray, a.min(b).min(c), a.max(b).max(c), t_max))
}

/// [`box_rule`] for a ray that enters the triangle's box at `enter` (its
/// [`RobustSlabs`] test: +∞ when the box is missed, otherwise a distance
/// in `[t_min, t_max]`).
#[inline(always)]
pub(crate) fn box_rule_at(hit: TriangleHit, enter: f32) -> Option<TriangleHit> {
    (enter != f32::INFINITY).then_some(TriangleHit { t: hit.t.max(enter), ..hit })
}

/// The hit rule for one ray and `triangle`, held in lane `lane` of a lane
/// test's `hits` (a block test's triangle lane, or a packet test's ray
/// lane): a lane the test handed back is decided by the scalar test, and
/// a lane it hit passes the box rule.
#[inline(always)]
pub(crate) fn lane_hit<T: TriangleTest, L: std::ops::Index<usize, Output = f32>>(
    ray: &PreparedRay<T>,
    triangle: &[Vec3A; 3],
    hits: &LaneHits<L>,
    lane: usize,
    t_max: f32,
) -> Option<TriangleHit> {
    if hits.rescan & 1 << lane != 0 {
        hit_triangle(ray, triangle, t_max)
    } else {
        box_rule(&ray.boxes, triangle, hits.hit(lane), t_max)
    }
}

/// Tests `triangles` (whose input indices are `ids`) in order, offering
/// each hit to `best`, and counts the tests; returns whether the query is
/// answered (an any-hit query that found a hit). The linear scan runs it
/// over all triangles, a BVH over each leaf it reaches.
#[inline(always)]
pub(crate) fn test_triangles<Q: QueryKind, C: Counter, T: TriangleTest, F: HitFilter>(
    triangles: &[[Vec3A; 3]],
    ids: &[u32],
    ray: &PreparedRay<T>,
    best: &mut Best,
    counter: &mut C,
    filter: &F,
) -> bool {
    for (tested, (triangle, &id)) in triangles.iter().zip(ids).enumerate() {
        if let Some(hit) = hit_triangle(ray, triangle, best.t_max)
            && best.offer(id, hit, filter)
            && Q::STOP_AT_FIRST_HIT
        {
            counter.triangles_tested(tested as u32 + 1);
            return true;
        }
    }
    counter.triangles_tested(triangles.len() as u32);
    false
}

/// Closest hit or any hit: the one difference between the two queries is
/// whether the first accepted hit ends the search.
pub(crate) trait QueryKind {
    const STOP_AT_FIRST_HIT: bool;
}

/// The closest hit.
pub(crate) struct Closest;

impl QueryKind for Closest {
    const STOP_AT_FIRST_HIT: bool = false;
}

/// Any hit.
pub(crate) struct AnyHit;

impl QueryKind for AnyHit {
    const STOP_AT_FIRST_HIT: bool = true;
}

/// The best hit found so far, and the distance beyond which nothing can
/// beat it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Best {
    pub(crate) hit: Option<Hit>,
    pub(crate) t_max: f32,
}

impl Best {
    #[inline(always)]
    pub(crate) fn new(ray: &Ray) -> Self {
        Self { hit: None, t_max: ray.t_max }
    }

    /// Takes `hit` on triangle `triangle` if it comes first in the order
    /// `(t, triangle index)` and the filter accepts it; returns whether it did.
    #[inline(always)]
    pub(crate) fn offer<F: HitFilter>(&mut self, triangle: u32, hit: TriangleHit, filter: &F) -> bool {
        let precedes = self.hit.is_none_or(|b| hit.t < b.t || (hit.t == b.t && triangle < b.triangle));
        if precedes && filter.accept(triangle, hit.beta, hit.gamma) {
            self.t_max = hit.t;
            self.hit = Some(Hit { t: hit.t, triangle, beta: hit.beta, gamma: hit.gamma });
            true
        } else {
            false
        }
    }
}

/// Decides whether a candidate hit counts; monomorphised, so the default
/// [`AcceptAll`] costs nothing.
pub(crate) trait HitFilter {
    fn accept(&self, triangle: u32, beta: f32, gamma: f32) -> bool;
}

pub(crate) struct AcceptAll;

impl HitFilter for AcceptAll {
    #[inline(always)]
    fn accept(&self, _triangle: u32, _beta: f32, _gamma: f32) -> bool {
        true
    }
}

impl HitFilter for &dyn Fn(u32, f32, f32) -> bool {
    #[inline(always)]
    fn accept(&self, triangle: u32, beta: f32, gamma: f32) -> bool {
        self(triangle, beta, gamma)
    }
}

/// A ray query structure: one traversal for both query kinds, from which
/// the [`Accel`] methods follow.
pub(crate) trait Structure: Send + Sync + std::fmt::Debug {
    /// The closest hit, or with [`AnyHit`] the first hit found.
    fn query<Q: QueryKind, C: Counter, F: HitFilter>(&self, ray: &Ray, counter: &mut C, filter: &F) -> Option<Hit>;

    /// [`Structure::query`] for every ray of `rays`, handing each answer
    /// to `answer(index, hit)`. Structures that trace coherent rays
    /// together override it.
    fn query_batch<Q: QueryKind, F: HitFilter>(
        &self,
        rays: &[Ray],
        answer: &mut dyn FnMut(usize, Option<Hit>),
        filter: &F,
    ) {
        for (index, ray) in rays.iter().enumerate() {
            answer(index, self.query::<Q, _, _>(ray, &mut NoCounter, filter));
        }
    }

    fn stats(&self) -> &BuildStats;
}

impl<S: Structure> Accel for S {
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.query::<Closest, _, _>(ray, &mut NoCounter, &AcceptAll)
    }

    fn occluded(&self, ray: &Ray) -> bool {
        self.query::<AnyHit, _, _>(ray, &mut NoCounter, &AcceptAll).is_some()
    }

    fn intersect_counted(&self, ray: &Ray, counters: &mut TraversalCounters) -> Option<Hit> {
        counters.rays += 1;
        self.query::<Closest, _, _>(ray, counters, &AcceptAll)
    }

    fn occluded_counted(&self, ray: &Ray, counters: &mut TraversalCounters) -> bool {
        counters.rays += 1;
        self.query::<AnyHit, _, _>(ray, counters, &AcceptAll).is_some()
    }

    fn intersect_filtered(&self, ray: &Ray, accept: &dyn Fn(u32, f32, f32) -> bool) -> Option<Hit> {
        self.query::<Closest, _, _>(ray, &mut NoCounter, &accept)
    }

    fn occluded_filtered(&self, ray: &Ray, accept: &dyn Fn(u32, f32, f32) -> bool) -> bool {
        self.query::<AnyHit, _, _>(ray, &mut NoCounter, &accept).is_some()
    }

    fn build_stats(&self) -> &BuildStats {
        self.stats()
    }

    fn intersect_batch(&self, rays: &[Ray], hits: &mut [Option<Hit>]) {
        assert_eq!(rays.len(), hits.len(), "one hit slot per ray");
        self.query_batch::<Closest, _>(rays, &mut |index, hit| hits[index] = hit, &AcceptAll);
    }

    fn occluded_batch(&self, rays: &[Ray], occluded: &mut [bool]) {
        assert_eq!(rays.len(), occluded.len(), "one answer slot per ray");
        self.query_batch::<AnyHit, _>(rays, &mut |index, hit| occluded[index] = hit.is_some(), &AcceptAll);
    }

    fn intersect_batch_filtered(&self, rays: &[Ray], hits: &mut [Option<Hit>], accept: &dyn Fn(u32, f32, f32) -> bool) {
        assert_eq!(rays.len(), hits.len(), "one hit slot per ray");
        self.query_batch::<Closest, _>(rays, &mut |index, hit| hits[index] = hit, &accept);
    }

    fn occluded_batch_filtered(&self, rays: &[Ray], occluded: &mut [bool], accept: &dyn Fn(u32, f32, f32) -> bool) {
        assert_eq!(rays.len(), occluded.len(), "one answer slot per ray");
        self.query_batch::<AnyHit, _>(rays, &mut |index, hit| occluded[index] = hit.is_some(), &accept);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ray whose range starts behind its origin finds hits there too,
    /// on axis-aligned triangles as well: their boxes are flat, entered and
    /// left at the same distance, and the robust test's enlarged exit must
    /// not fall below that distance when it is negative.
    #[test]
    fn flat_triangles_behind_the_origin_are_hit_within_a_negative_range() {
        let wall = [Vec3::new(-1.0, -1.0, -1.0), Vec3::new(-1.0, 1.0, -1.0), Vec3::new(-1.0, 0.0, 1.0)];
        for intersector in Intersector::ALL {
            let hit = intersector.intersect(Vec3::ZERO, Vec3::X, -10.0, 10.0, &wall);
            assert_eq!(hit.map(|h| h.t), Some(-1.0), "{intersector}");
            let ahead = wall.map(|v| v * Vec3::new(-1.0, 1.0, 1.0));
            assert_eq!(intersector.intersect(Vec3::ZERO, Vec3::X, -10.0, 10.0, &ahead).map(|h| h.t), Some(1.0));
        }
    }

    #[test]
    fn hittable_means_finite_with_area() {
        let good = [Vec3::ZERO, Vec3::X, Vec3::Y];
        assert!(is_hittable(&good));
        // Tiny, but not degenerate: its area underflows in single precision.
        assert!(is_hittable(&good.map(|v| v * 1e-30)));
        assert!(!is_hittable(&[Vec3::ZERO, Vec3::X, 2.0 * Vec3::X]));
        assert!(!is_hittable(&[Vec3::ZERO, Vec3::ZERO, Vec3::Y]));
        assert!(!is_hittable(&[Vec3::new(f32::NAN, 0.0, 0.0), Vec3::X, Vec3::Y]));
        assert!(!is_hittable(&[Vec3::new(0.0, f32::INFINITY, 0.0), Vec3::X, Vec3::Y]));
    }
}
