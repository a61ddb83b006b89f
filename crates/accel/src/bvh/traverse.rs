//! Front-to-back traversal with an explicit stack, generic over the
//! ray/triangle test and the slab test so that every combination runs as
//! its own monomorphised loop.

use rtgi_math::{BVec3A, Ray, Vec3A, gamma};

use super::{Bvh, BvhNode};
use crate::triangle::{MollerTrumbore, TriangleTest, Watertight};
use crate::{Counter, Hit, HitFilter, Intersector};

/// Entries of the largest traversal stack. A stack holds at most one entry
/// per level of the tree, and builds never exceed 64 + 32 levels (see
/// `build::HEURISTIC_DEPTH_LIMIT`), so it cannot overflow. Shallower trees
/// use smaller stacks (see [`Bvh::closest`]): the stack is an array that is
/// zeroed for every ray, and zeroing 512 bytes costs a tenth of the time of
/// a primary ray on the bunny.
pub(crate) const STACK_SIZE: usize = 128;

/// `1 + 2γ(3)`: slab exit distances are enlarged by this factor so that
/// rounding never drops a box the ray touches (Ize, "Robust BVH Ray
/// Traversal", JCGT 2013; pbrt-v4 `Bounds3::IntersectP`).
const ROBUST_FAR_SCALE: f32 = 1.0 + 2.0 * gamma(3);

/// How a BVH tests rays against its boxes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Traversal {
    /// Conservative: exit distances enlarged by `1 + 2γ(3)` (Ize 2013),
    /// near and far planes chosen by the direction's sign bit, and the NaN
    /// of `0 · ∞` (an origin on a slab plane along a zero direction
    /// component) ignored. Never drops a box the ray touches.
    #[default]
    Robust,
    /// The common textbook slab test: `min`/`max` of the two plane
    /// distances, no enlargement. Rounding can drop boxes that rays graze,
    /// and NaN can drop boxes whose planes contain the origin.
    Fast,
}

impl Traversal {
    pub const ALL: &'static [Traversal] = &[Traversal::Robust, Traversal::Fast];

    pub fn name(self) -> &'static str {
        match self {
            Traversal::Robust => "robust",
            Traversal::Fast => "fast",
        }
    }
}

rtgi_math::named_choices!(Traversal, "traversal");

/// A ray prepared for box tests.
struct PreparedRay {
    origin: Vec3A,
    inv_direction: Vec3A,
    /// Lanes where the direction's sign bit is set (so -0 counts as negative):
    /// there the box's max plane is entered first.
    negative: BVec3A,
    t_min: f32,
}

impl PreparedRay {
    #[inline(always)]
    fn new(ray: &Ray) -> Self {
        let direction = Vec3A::from(ray.direction);
        Self {
            origin: ray.origin.into(),
            inv_direction: Vec3A::ONE / direction,
            negative: BVec3A::new(
                direction.x.is_sign_negative(),
                direction.y.is_sign_negative(),
                direction.z.is_sign_negative(),
            ),
            t_min: ray.t_min,
        }
    }
}

/// A slab test: the distance at which the ray enters the node's box within
/// `[t_min, t_max]`, or +∞ if it misses.
trait SlabTest {
    fn enter(ray: &PreparedRay, node: &BvhNode, t_max: f32) -> f32;
}

struct RobustSlabs;

impl SlabTest for RobustSlabs {
    #[inline(always)]
    fn enter(ray: &PreparedRay, node: &BvhNode, t_max: f32) -> f32 {
        let (min, max) = node.corners();
        let t_min_planes = (min - ray.origin) * ray.inv_direction;
        let t_max_planes = (max - ray.origin) * ray.inv_direction;
        let near = Vec3A::select(ray.negative, t_max_planes, t_min_planes);
        let far = Vec3A::select(ray.negative, t_min_planes, t_max_planes) * ROBUST_FAR_SCALE;
        let (enter, exit) = clip_nan_ignoring(near, far, Vec3A::splat(ray.t_min), Vec3A::splat(t_max));
        if enter <= exit && enter < f32::INFINITY { enter } else { f32::INFINITY }
    }
}

struct FastSlabs;

impl SlabTest for FastSlabs {
    #[inline(always)]
    fn enter(ray: &PreparedRay, node: &BvhNode, t_max: f32) -> f32 {
        let (min, max) = node.corners();
        let t1 = (min - ray.origin) * ray.inv_direction;
        let t2 = (max - ray.origin) * ray.inv_direction;
        let enter = t1.min(t2).max(Vec3A::splat(ray.t_min)).max_element();
        let exit = t1.max(t2).min(Vec3A::splat(t_max)).min_element();
        if enter <= exit { enter } else { f32::INFINITY }
    }
}

/// `max(near, lower)` and `min(far, upper)` reduced over the three axes,
/// where a NaN in `near` or `far` yields the bound instead.
///
/// On x86, SSE's `maxps`/`minps` return their second operand when either is
/// NaN, and glam passes `self` first, so the plain methods already ignore
/// NaNs in `near` and `far`. Elsewhere (NEON propagates NaN) a
/// compare-and-select does the same. The unit tests of the slab test cover
/// origins on the planes with zero direction components on every platform.
#[inline(always)]
fn clip_nan_ignoring(near: Vec3A, far: Vec3A, lower: Vec3A, upper: Vec3A) -> (f32, f32) {
    #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
    {
        (near.max(lower).max_element(), far.min(upper).min_element())
    }
    #[cfg(not(any(target_arch = "x86", target_arch = "x86_64")))]
    {
        let enter = Vec3A::select(near.cmpgt(lower), near, lower).max_element();
        let exit = Vec3A::select(far.cmplt(upper), far, upper).min_element();
        (enter, exit)
    }
}

/// Calls `$method` monomorphised for the structure's intersector, slab test
/// and stack size (32, 64 or 128 entries, the smallest the depth allows):
/// one branch per ray picks among the twelve compiled loops.
macro_rules! monomorphise {
    ($self:ident, $method:ident, $c:ty, $f:ty, $($arg:expr),*) => {{
        macro_rules! sized {
            ($t:ty, $s:ty) => {
                match $self.stats.depth {
                    0..=32 => $self.$method::<$c, $t, $s, $f, 32>($($arg),*),
                    33..=64 => $self.$method::<$c, $t, $s, $f, 64>($($arg),*),
                    _ => $self.$method::<$c, $t, $s, $f, STACK_SIZE>($($arg),*),
                }
            };
        }
        match ($self.intersector, $self.traversal) {
            (Intersector::Watertight, Traversal::Robust) => sized!(Watertight, RobustSlabs),
            (Intersector::Watertight, Traversal::Fast) => sized!(Watertight, FastSlabs),
            (Intersector::MollerTrumbore, Traversal::Robust) => sized!(MollerTrumbore, RobustSlabs),
            (Intersector::MollerTrumbore, Traversal::Fast) => sized!(MollerTrumbore, FastSlabs),
        }
    }};
}

impl Bvh {
    /// Tests the triangles of a leaf for the closest hit, updating `best`
    /// and shrinking `t_max`. At equal distances the triangle with the lower
    /// input index wins, so every variant and leaf size gives the same answer.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn leaf_closest<C: Counter, T: TriangleTest, F: HitFilter>(
        &self,
        leaf: &BvhNode,
        test_ray: &T::Ray,
        t_min: f32,
        t_max: &mut f32,
        best: &mut Option<Hit>,
        counter: &mut C,
        filter: &F,
    ) {
        let range = leaf.first() as usize..(leaf.first() + leaf.count()) as usize;
        counter.triangles_tested(leaf.count());
        for (triangle, &id) in self.triangles[range.clone()].iter().zip(&self.triangle_ids[range]) {
            let Some(h) = T::intersect(test_ray, t_min, *t_max, triangle) else {
                continue;
            };
            // The test only reports t <= t_max, the best distance so far.
            if best.is_none_or(|b| h.t < b.t || id < b.triangle) && filter.accept(id, h.beta, h.gamma) {
                *t_max = h.t;
                *best = Some(Hit { t: h.t, triangle: id, beta: h.beta, gamma: h.gamma });
            }
        }
    }

    /// Closest hit: front to back, leaves tested as soon as their box is
    /// hit, the farther child of two pushed on a fixed-size stack no larger
    /// than the tree's depth needs.
    pub(crate) fn closest<C: Counter, F: HitFilter>(&self, ray: &Ray, counter: &mut C, filter: &F) -> Option<Hit> {
        monomorphise!(self, closest_with_stack, C, F, ray, counter, filter)
    }

    /// Any hit: stops at the first triangle found.
    pub(crate) fn any<C: Counter, F: HitFilter>(&self, ray: &Ray, counter: &mut C, filter: &F) -> bool {
        monomorphise!(self, any_with_stack, C, F, ray, counter, filter)
    }

    fn closest_with_stack<C: Counter, T: TriangleTest, S: SlabTest, F: HitFilter, const STACK: usize>(
        &self,
        ray: &Ray,
        counter: &mut C,
        filter: &F,
    ) -> Option<Hit> {
        if !ray.is_valid() || self.nodes.is_empty() {
            return None;
        }
        let prepared = PreparedRay::new(ray);
        let test_ray = T::prepare(ray.origin.into(), ray.direction.into());
        let mut best: Option<Hit> = None;
        let mut t_max = ray.t_max;
        let root = &self.nodes[0];
        counter.node_visited();
        if S::enter(&prepared, root, t_max) == f32::INFINITY {
            return None;
        }
        if root.is_leaf() {
            self.leaf_closest::<C, T, F>(root, &test_ray, ray.t_min, &mut t_max, &mut best, counter, filter);
            return best;
        }
        let mut stack = [0u32; STACK];
        let mut stack_len = 0;
        let mut children = root.first();
        loop {
            let pair = &self.nodes[children as usize..children as usize + 2];
            counter.node_visited();
            counter.node_visited();
            let (mut near, mut far) = (&pair[0], &pair[1]);
            let (mut enter_near, mut enter_far) = (S::enter(&prepared, near, t_max), S::enter(&prepared, far, t_max));
            if enter_far < enter_near {
                std::mem::swap(&mut near, &mut far);
                std::mem::swap(&mut enter_near, &mut enter_far);
            }
            let mut descend_near = enter_near < f32::INFINITY;
            if descend_near && near.is_leaf() {
                self.leaf_closest::<C, T, F>(near, &test_ray, ray.t_min, &mut t_max, &mut best, counter, filter);
                descend_near = false;
            }
            // The near leaf may have found a hit in front of the far box. (A
            // missed box enters at +∞, which an unbounded t_max does not exclude.)
            let mut descend_far = enter_far < f32::INFINITY && enter_far <= t_max;
            if descend_far && far.is_leaf() {
                self.leaf_closest::<C, T, F>(far, &test_ray, ray.t_min, &mut t_max, &mut best, counter, filter);
                descend_far = false;
            }
            children = match (descend_near, descend_far) {
                (true, true) => {
                    stack[stack_len] = far.first();
                    stack_len += 1;
                    near.first()
                }
                (true, false) => near.first(),
                (false, true) => far.first(),
                (false, false) => {
                    if stack_len == 0 {
                        return best;
                    }
                    stack_len -= 1;
                    stack[stack_len]
                }
            };
        }
    }

    fn any_with_stack<C: Counter, T: TriangleTest, S: SlabTest, F: HitFilter, const STACK: usize>(
        &self,
        ray: &Ray,
        counter: &mut C,
        filter: &F,
    ) -> bool {
        if !ray.is_valid() || self.nodes.is_empty() {
            return false;
        }
        let prepared = PreparedRay::new(ray);
        let test_ray = T::prepare(ray.origin.into(), ray.direction.into());
        let t_max = ray.t_max;
        let leaf_hit = |leaf: &BvhNode, counter: &mut C| {
            let range = leaf.first() as usize..(leaf.first() + leaf.count()) as usize;
            let ids = &self.triangle_ids[range.clone()];
            for (tested, (triangle, &id)) in self.triangles[range].iter().zip(ids).enumerate() {
                if let Some(h) = T::intersect(&test_ray, ray.t_min, t_max, triangle) {
                    if filter.accept(id, h.beta, h.gamma) {
                        counter.triangles_tested(tested as u32 + 1);
                        return true;
                    }
                }
            }
            counter.triangles_tested(leaf.count());
            false
        };
        let root = &self.nodes[0];
        counter.node_visited();
        if S::enter(&prepared, root, t_max) == f32::INFINITY {
            return false;
        }
        if root.is_leaf() {
            return leaf_hit(root, counter);
        }
        let mut stack = [0u32; STACK];
        let mut stack_len = 0;
        let mut children = root.first();
        loop {
            let pair = &self.nodes[children as usize..children as usize + 2];
            counter.node_visited();
            counter.node_visited();
            let mut descend = [false; 2];
            for (side, node) in pair.iter().enumerate() {
                if S::enter(&prepared, node, t_max) < f32::INFINITY {
                    if node.is_leaf() {
                        if leaf_hit(node, counter) {
                            return true;
                        }
                    } else {
                        descend[side] = true;
                    }
                }
            }
            children = match descend {
                [true, true] => {
                    stack[stack_len] = pair[1].first();
                    stack_len += 1;
                    pair[0].first()
                }
                [true, false] => pair[0].first(),
                [false, true] => pair[1].first(),
                [false, false] => {
                    if stack_len == 0 {
                        return false;
                    }
                    stack_len -= 1;
                    stack[stack_len]
                }
            };
        }
    }
}
