//! Single-ray traversal of a wide BVH: all children of a node are tested
//! at once, those the ray enters are visited nearest first, and the others
//! wait on a stack with their entry distance, so that they are dropped
//! without a second test once a hit lies in front of them.

use std::marker::PhantomData;

use rtgi_math::Ray;

use super::node::{ChildRef, NodeLayout};
use super::{WideBvh, insert_far_to_near};
use crate::contract::{Best, HitFilter, PreparedRay, QueryKind, lane_hit};
use crate::simd::boxes::PlaneRay;
use crate::simd::triangles::TriangleBlock;
use crate::simd::{Isa, Kernel, Portable, dispatch, prefetch};
use crate::slab::BoxRay;
use crate::triangle::{TriangleTest, with_triangle_test};
use crate::{Counter, Hit};

/// Children waiting to be visited, with the distance at which the ray
/// enters each, packed into 64 bits (so that a new stack is cleared with
/// a plain memset). `INLINE` entries live in an array on the call stack; a
/// deeper stack (only degenerate trees need one) continues on the heap.
pub(crate) struct TraversalStack<const INLINE: usize> {
    entries: [u64; INLINE],
    len: usize,
    spill: Vec<u64>,
}

impl<const INLINE: usize> TraversalStack<INLINE> {
    #[inline(always)]
    pub(crate) fn new() -> Self {
        Self { entries: [0; INLINE], len: 0, spill: Vec::new() }
    }

    #[inline(always)]
    pub(crate) fn clear(&mut self) {
        self.len = 0;
        self.spill.clear();
    }

    /// A child and its entry distance as one stack entry: the distance's
    /// bits above the child's, so that entries of distances `≥ +0` compare
    /// as integers as their distances do.
    #[inline(always)]
    pub(crate) fn entry(child: ChildRef, enter: f32) -> u64 {
        (enter.to_bits() as u64) << 32 | child.to_bits() as u64
    }

    /// The child of an [`TraversalStack::entry`].
    #[inline(always)]
    pub(crate) fn child_of(entry: u64) -> ChildRef {
        ChildRef::from_bits(entry as u32)
    }

    /// Pushes an [`TraversalStack::entry`].
    #[inline(always)]
    pub(crate) fn push(&mut self, entry: u64) {
        if self.len < INLINE {
            self.entries[self.len] = entry;
            self.len += 1;
        } else {
            self.spill.push(entry);
        }
    }

    #[inline(always)]
    pub(crate) fn pop(&mut self) -> Option<(ChildRef, f32)> {
        let entry = if let Some(entry) = self.spill.pop() {
            entry
        } else if self.len > 0 {
            self.len -= 1;
            self.entries[self.len]
        } else {
            return None;
        };
        Some((ChildRef::from_bits(entry as u32), f32::from_bits((entry >> 32) as u32)))
    }
}

/// Two stack entries, nearer first (see [`TraversalStack::entry`]).
#[inline(always)]
fn order(a: u64, b: u64) -> (u64, u64) {
    (a.min(b), a.max(b))
}

/// Entries kept on the call stack: enough for every tree but degenerate ones.
const INLINE_STACK: usize = 32;

impl<const W: usize, N: NodeLayout<W>> WideBvh<W, N> {
    /// The query compiled for the intersector and run at the active SIMD level.
    pub(super) fn query_dispatched<Q: QueryKind, C: Counter, F: HitFilter>(
        &self,
        ray: &Ray,
        counter: &mut C,
        filter: &F,
    ) -> Option<Hit> {
        if BoxRay::starts_behind(ray) {
            // Before dispatching, not in the traversal: a call there, even
            // one never made, cost about 65 instructions a ray on the bunny
            // (cachegrind), more than the folded exit saves.
            return with_triangle_test!(self.intersector, |T| self
                .traverse_portable::<Q, C, T, F>(ray, counter, filter));
        }
        with_triangle_test!(self.intersector, |T| dispatch(SingleRay::<W, N, Q, C, T, F> {
            bvh: self,
            ray,
            counter,
            filter,
            test: PhantomData
        }))
    }

    /// Closest hit, or with [`crate::contract::AnyHit`] the first hit found.
    #[inline(always)]
    pub(super) fn traverse<Q: QueryKind, C: Counter, T: TriangleTest, F: HitFilter, I: Isa, const S: usize>(
        &self,
        isa: I,
        ray: &Ray,
        stack: &mut TraversalStack<S>,
        counter: &mut C,
        filter: &F,
    ) -> Option<Hit> {
        if !ray.is_valid() || self.nodes.is_empty() {
            return None;
        }
        let box_ray = BoxRay::new(ray);
        debug_assert!(
            I::NODES_TAKE_RAYS_STARTING_BEHIND || !box_ray.starts_behind,
            "the caller sends rays whose range starts behind the origin to `traverse_portable`"
        );
        let plane_ray = PlaneRay::new(&box_ray);
        // The triangle test's preparation waits for the first leaf: most
        // camera rays of a framed object never reach one.
        let mut prepared: Option<PreparedRay<T>> = None;
        let mut best = Best::new(ray);
        stack.clear();
        let mut current = ChildRef::node(0);
        loop {
            if current.is_leaf() {
                let prepared = prepared.get_or_insert_with(|| PreparedRay::with_boxes(ray, box_ray));
                if self.visit_leaf::<Q, C, T, F>(current, prepared, &mut best, counter, filter) {
                    return best.hit;
                }
            } else {
                let node = &self.nodes[current.node_index()];
                counter.node_visited();
                let children = node.children();
                // The children's references are read only once the box test
                // says which: asked for now, their cache line arrives with
                // the boxes' instead of after them.
                prefetch(children, std::mem::size_of_val(children));
                let (entered, enter) = node.enter(isa, &plane_ray, best.t_max);
                if entered != 0 {
                    let first = entered.trailing_zeros() as usize;
                    if entered & (entered - 1) == 0 {
                        current = children[first];
                        continue;
                    }
                    if Q::STOP_AT_FIRST_HIT {
                        // Any hit ends the search, wherever it is: no order
                        // pays for sorting. The first child is visited now.
                        let mut lanes = entered & (entered - 1);
                        while lanes != 0 {
                            let lane = lanes.trailing_zeros() as usize;
                            lanes &= lanes - 1;
                            self.push_prefetched(stack, TraversalStack::<S>::entry(children[lane], enter[lane]));
                        }
                        current = children[first];
                        continue;
                    }
                    // Children entered, nearest first, as stack entries
                    // (`TraversalStack::entry`), whose order as integers is
                    // their entry distances' order: sorted by minima and
                    // maxima that compile to conditional moves, since which
                    // child is nearer is a coin toss the branch predictor
                    // loses. (Entries behind the origin, of rays whose range
                    // starts there, sort as far: that changes the order of
                    // visits, never the answer.)
                    let entry = |lane: usize| TraversalStack::<S>::entry(children[lane], enter[lane]);
                    let mut lanes = entered & (entered - 1);
                    let mut next = || {
                        let lane = lanes.trailing_zeros() as usize;
                        lanes &= lanes - 1;
                        entry(lane)
                    };
                    let (a, b) = order(entry(first), next());
                    let nearest = match entered.count_ones() as usize {
                        2 => {
                            self.push_prefetched(stack, b);
                            a
                        }
                        3 => {
                            let (b, c) = order(b, next());
                            let (a, b) = order(a, b);
                            self.push_prefetched(stack, c);
                            self.push_prefetched(stack, b);
                            a
                        }
                        4 => {
                            let (c, d) = order(next(), next());
                            let (a, c) = order(a, c);
                            let (b, d) = order(b, d);
                            let (b, c) = order(b, c);
                            self.push_prefetched(stack, d);
                            self.push_prefetched(stack, c);
                            self.push_prefetched(stack, b);
                            a
                        }
                        count => {
                            let mut sorted = [0u64; W];
                            [sorted[0], sorted[1]] = [b, a];
                            for at in 2..count {
                                insert_far_to_near(&mut sorted, at, next(), |&e| e);
                            }
                            for &far in &sorted[..count - 1] {
                                self.push_prefetched(stack, far);
                            }
                            sorted[count - 1]
                        }
                    };
                    current = TraversalStack::<S>::child_of(nearest);
                    continue;
                }
            }
            // Next from the stack; a child entered beyond the best hit is
            // dropped (one entered at exactly its distance may hold a tie).
            loop {
                let Some((child, enter)) = stack.pop() else {
                    return best.hit;
                };
                if enter <= best.t_max {
                    current = child;
                    break;
                }
            }
        }
    }

    /// [`WideBvh::traverse`] at the portable level, for a ray whose range
    /// starts behind its origin when the active level's node kernels do
    /// not take those ([`Isa::NODES_TAKE_RAYS_STARTING_BEHIND`]). Not
    /// inlined: such rays are rare, and a second copy of the loop in every
    /// level's traversal would only cost build time. It has a stack of its
    /// own: lending it the caller's lets that stack's address escape, which
    /// kept its length in memory and cost about 30 instructions a ray.
    #[inline(never)]
    pub(super) fn traverse_portable<Q: QueryKind, C: Counter, T: TriangleTest, F: HitFilter>(
        &self,
        ray: &Ray,
        counter: &mut C,
        filter: &F,
    ) -> Option<Hit> {
        let mut stack = TraversalStack::<INLINE_STACK>::new();
        self.traverse::<Q, C, T, F, Portable, INLINE_STACK>(Portable, ray, &mut stack, counter, filter)
    }

    /// Pushes a stack entry, first asking for its child's memory.
    #[inline(always)]
    fn push_prefetched<const S: usize>(&self, stack: &mut TraversalStack<S>, entry: u64) {
        self.prefetch(TraversalStack::<S>::child_of(entry));
        stack.push(entry);
    }

    /// Starts loading the memory of a child that will be visited soon.
    #[inline(always)]
    fn prefetch(&self, child: ChildRef) {
        if child.is_leaf() {
            let blocks = child.blocks();
            if let Some(first) = self.blocks.get(blocks.start) {
                prefetch(first, blocks.len() * std::mem::size_of::<TriangleBlock>());
            }
        } else if let Some(node) = self.nodes.get(child.node_index()) {
            prefetch(node, std::mem::size_of::<N>());
        }
    }

    /// Tests the triangles of a leaf, offering hits to `best`; returns
    /// whether the query is answered (an any-hit query found a hit).
    #[inline(always)]
    pub(super) fn visit_leaf<Q: QueryKind, C: Counter, T: TriangleTest, F: HitFilter>(
        &self,
        leaf: ChildRef,
        ray: &PreparedRay<T>,
        best: &mut Best,
        counter: &mut C,
        filter: &F,
    ) -> bool {
        for block in &self.blocks[leaf.blocks()] {
            counter.triangles_tested(block.len());
            let hits = T::intersect_block(&ray.triangles, ray.boxes.t_min, best.t_max, block);
            let mut lanes = hits.exact | hits.rescan;
            while lanes != 0 {
                let lane = lanes.trailing_zeros() as usize;
                lanes &= lanes - 1;
                if let Some(hit) = lane_hit(ray, &block.triangle(lane), &hits, lane, best.t_max)
                    && best.offer(block.ids[lane], hit, filter)
                    && Q::STOP_AT_FIRST_HIT
                {
                    return true;
                }
            }
        }
        false
    }
}

/// One query as a [`Kernel`], so that it runs compiled for the active SIMD level.
struct SingleRay<'a, const W: usize, N, Q, C, T, F> {
    bvh: &'a WideBvh<W, N>,
    ray: &'a Ray,
    counter: &'a mut C,
    filter: &'a F,
    test: PhantomData<(Q, T)>,
}

impl<const W: usize, N: NodeLayout<W>, Q: QueryKind, C: Counter, T: TriangleTest, F: HitFilter> Kernel
    for SingleRay<'_, W, N, Q, C, T, F>
{
    type Output = Option<Hit>;

    #[inline(always)]
    fn run<I: Isa>(self, isa: I) -> Option<Hit> {
        let mut stack = TraversalStack::<INLINE_STACK>::new();
        self.bvh.traverse::<Q, C, T, F, I, INLINE_STACK>(isa, self.ray, &mut stack, self.counter, self.filter)
    }
}
