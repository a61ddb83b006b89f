//! Front-to-back traversal with an explicit stack, generic over the
//! ray/triangle test and the slab test so that every combination runs as
//! its own monomorphised loop.

use std::marker::PhantomData;

use rtgi_math::Ray;

use super::{Bvh, BvhNode};
use crate::contract::{Best, HitFilter, PreparedRay, QueryKind, test_triangles};
use crate::slab::{BoxRay, FastSlabs, RobustSlabs, SlabTest};
use crate::triangle::{TriangleTest, with_triangle_test};
use crate::{Counter, Hit};

/// Entries of the largest traversal stack. A stack holds at most one entry
/// per level of the tree, and builds never exceed 64 + 32 levels (see
/// `split::HEURISTIC_DEPTH_LIMIT`), so it cannot overflow. Shallower trees
/// use smaller stacks (see [`Bvh::closest`]): the stack is an array that is
/// zeroed for every ray, and zeroing 512 bytes costs a tenth of the time of
/// a primary ray on the bunny.
pub(crate) const STACK_SIZE: usize = 128;

/// How a BVH tests rays against its boxes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Traversal {
    /// Conservative: never drops a box the ray touches.
    ///
    /// Exit distances computed with the inverse direction enlarged by `1 + 2⁻²¹` (Ize 2013; reduced for
    /// exits behind the origin of a range that starts there),
    /// near and far planes chosen by the direction's sign bit, and the NaN
    /// of `0 · ∞` (an origin on a slab plane along a zero direction
    /// component) ignored. Never drops a box the ray touches.
    #[default]
    Robust,
    /// The textbook slab test: can drop boxes that rays graze.
    ///
    /// The common textbook slab test: `min`/`max` of the two plane
    /// distances, no enlargement. Rounding can drop boxes that rays graze,
    /// and NaN can drop boxes whose planes contain the origin.
    Fast,
}

impl Traversal {
    /// Both slab tests, the robust one first.
    pub const ALL: &'static [Traversal] = &[Traversal::Robust, Traversal::Fast];

    /// The name on command lines and in reports (`robust`, `fast`).
    pub fn name(self) -> &'static str {
        match self {
            Traversal::Robust => "robust",
            Traversal::Fast => "fast",
        }
    }
}

impl rtgi_math::NamedChoice for Traversal {
    const KIND: &'static str = "traversal";
    const ALL: &'static [Self] = Traversal::ALL;
    fn name(self) -> &'static str {
        Traversal::name(self)
    }
}

impl std::fmt::Display for Traversal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Calls `$method` monomorphised for the structure's intersector, slab test
/// and stack size (32, 64 or 128 entries, the smallest the depth allows):
/// one branch per ray picks among the eighteen compiled loops.
macro_rules! monomorphise {
    ($self:ident, $method:ident, $q:ty, $c:ty, $f:ty, $($arg:expr),*) => {{
        macro_rules! sized {
            ($t:ty, $s:ty) => {
                match $self.stats.depth {
                    0..=32 => $self.$method::<$q, $c, $t, $s, $f, 32>($($arg),*),
                    33..=64 => $self.$method::<$q, $c, $t, $s, $f, 64>($($arg),*),
                    _ => $self.$method::<$q, $c, $t, $s, $f, STACK_SIZE>($($arg),*),
                }
            };
        }
        with_triangle_test!($self.intersector, |T| match $self.traversal {
            Traversal::Robust => sized!(T, RobustSlabs),
            Traversal::Fast => sized!(T, FastSlabs),
        })
    }};
}

impl BvhNode {
    /// The distance at which the ray enters this node's box, or +∞.
    #[inline(always)]
    fn enter<S: SlabTest>(&self, ray: &BoxRay, t_max: f32) -> f32 {
        let (min, max) = self.corners();
        S::enter(ray, min, max, t_max)
    }
}

impl Bvh {
    /// One query, closest or any hit: front to back, leaves tested as soon
    /// as their box is hit, the farther child of two pushed on a fixed-size
    /// stack no larger than the tree's depth needs.
    pub(crate) fn traverse<Q: QueryKind, C: Counter, F: HitFilter>(
        &self,
        ray: &Ray,
        counter: &mut C,
        filter: &F,
    ) -> Option<Hit> {
        monomorphise!(self, traverse_with_stack, Q, C, F, ray, counter, filter)
    }

    /// Tests the triangles of a leaf (see [`test_triangles`]); returns
    /// whether the query is answered.
    #[inline(always)]
    fn visit_leaf<Q: QueryKind, C: Counter, T: TriangleTest, F: HitFilter>(
        &self,
        leaf: &BvhNode,
        ray: &PreparedRay<T>,
        best: &mut Best,
        counter: &mut C,
        filter: &F,
    ) -> bool {
        let range = leaf.first() as usize..(leaf.first() + leaf.count()) as usize;
        test_triangles::<Q, C, T, F>(
            &self.triangles[range.clone()],
            &self.triangle_ids[range],
            ray,
            best,
            counter,
            filter,
        )
    }

    fn traverse_with_stack<Q: QueryKind, C: Counter, T: TriangleTest, S: SlabTest, F: HitFilter, const STACK: usize>(
        &self,
        ray: &Ray,
        counter: &mut C,
        filter: &F,
    ) -> Option<Hit> {
        if !ray.is_valid() || self.nodes.is_empty() {
            return None;
        }
        let mut query = TriangleQuery::<Q, C, T, S, F> {
            bvh: self,
            prepared: PreparedRay::<T>::new(ray),
            best: Best::new(ray),
            counter,
            filter,
            kinds: PhantomData,
        };
        traverse_binary::<_, STACK>(&self.nodes, &mut query);
        query.best.hit
    }
}

/// A query during [`traverse_binary`]: how it tests boxes and leaves, and
/// the distance beyond which nothing can improve its answer.
pub(crate) trait BinaryQuery {
    /// The distance at which the ray enters `node`'s box within
    /// `[t_min, t_max]`, or +∞.
    fn enter(&self, node: &BvhNode, t_max: f32) -> f32;
    /// The best hit's distance so far (the ray's `t_max` before any).
    fn t_max(&self) -> f32;
    /// Tests the primitives of a leaf; returns whether the query is
    /// answered (an any-hit query found a hit).
    fn visit_leaf(&mut self, leaf: &BvhNode) -> bool;
    /// Counts a box tested.
    #[inline(always)]
    fn node_visited(&mut self) {}
}

/// Front-to-back traversal of a binary BVH's `nodes` (the root first, the
/// two children of a node side by side), shared by the triangle BVH and
/// [`crate::PrimitiveBvh`]. Both children's boxes are tested together, the
/// nearer visited first; a child that is a leaf is tested at once, and the
/// farther child waits on a stack of `STACK` entries (one per level) when
/// both are to be descended. A box entered at exactly the best distance is
/// still visited, as it may hold a tie with a lower index; a missed box
/// enters at +∞, which an unbounded `t_max` does not exclude.
#[inline(always)]
pub(crate) fn traverse_binary<B: BinaryQuery, const STACK: usize>(nodes: &[BvhNode], query: &mut B) {
    let Some(root) = nodes.first() else { return };
    query.node_visited();
    if query.enter(root, query.t_max()) == f32::INFINITY {
        return;
    }
    if root.is_leaf() {
        query.visit_leaf(root);
        return;
    }
    let mut stack = [0u32; STACK];
    let mut stack_len = 0;
    let mut children = root.first();
    loop {
        let pair = &nodes[children as usize..children as usize + 2];
        query.node_visited();
        query.node_visited();
        let (mut near, mut far) = (&pair[0], &pair[1]);
        let t_max = query.t_max();
        let (mut enter_near, mut enter_far) = (query.enter(near, t_max), query.enter(far, t_max));
        if enter_far < enter_near {
            std::mem::swap(&mut near, &mut far);
            std::mem::swap(&mut enter_near, &mut enter_far);
        }
        let mut descend_near = enter_near < f32::INFINITY;
        if descend_near && near.is_leaf() {
            if query.visit_leaf(near) {
                return;
            }
            descend_near = false;
        }
        // The near leaf may have found a hit in front of the far box.
        let mut descend_far = enter_far < f32::INFINITY && enter_far <= query.t_max();
        if descend_far && far.is_leaf() {
            if query.visit_leaf(far) {
                return;
            }
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
                    return;
                }
                stack_len -= 1;
                stack[stack_len]
            }
        };
    }
}

/// A triangle query on a [`Bvh`], for [`traverse_binary`].
struct TriangleQuery<'a, Q, C, T: TriangleTest, S, F> {
    bvh: &'a Bvh,
    prepared: PreparedRay<T>,
    best: Best,
    counter: &'a mut C,
    filter: &'a F,
    kinds: PhantomData<(Q, S)>,
}

impl<Q: QueryKind, C: Counter, T: TriangleTest, S: SlabTest, F: HitFilter> BinaryQuery
    for TriangleQuery<'_, Q, C, T, S, F>
{
    #[inline(always)]
    fn enter(&self, node: &BvhNode, t_max: f32) -> f32 {
        node.enter::<S>(&self.prepared.boxes, t_max)
    }

    #[inline(always)]
    fn t_max(&self) -> f32 {
        self.best.t_max
    }

    #[inline(always)]
    fn visit_leaf(&mut self, leaf: &BvhNode) -> bool {
        self.bvh.visit_leaf::<Q, C, T, F>(leaf, &self.prepared, &mut self.best, self.counter, self.filter)
    }

    #[inline(always)]
    fn node_visited(&mut self) {
        self.counter.node_visited();
    }
}
