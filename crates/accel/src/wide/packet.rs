//! Packet traversal: sixteen coherent rays (a 4×4 tile of camera rays,
//! say) walk a wide BVH together. An inner node's children are tested
//! once for the whole packet, by the interval ray that bounds its rays
//! ([`IntervalRay`]: eight boxes in one test, as for a single ray); a leaf
//! it may enter is then tested against each of the sixteen rays. The rays
//! that enter it take its triangles together, each triangle against all
//! of them in one test ([`crate::simd::packet_triangles`]), where the CPU
//! has AVX-512 and the watertight test's rays share their permutation of
//! axes; elsewhere each ray takes them on its own, with the block tests of
//! single rays.
//!
//! The answers are those of single-ray traversal, bit for bit: every ray
//! is tested against every leaf its own traversal would test (the interval
//! ray enters every box any of its rays enters, no later; the leaf test is
//! the robust slab test's arithmetic, lane by lane; and a child is dropped
//! only when it is entered beyond the best hit of every ray that may enter
//! it), and sometimes against more, which cannot change its answer: the
//! hit rule is a function of the ray and the triangle alone, and the best
//! hit is the least in the order (distance, triangle index) whichever
//! order hits are found in.
//!
//! Measured on the bunny's and the conference room's camera rays (one
//! thread), the interval test of inner nodes, with the packet's set-up
//! vectorised and its buffers kept across packets, made packets 1.74× as
//! fast as testing every child against all sixteen rays. Testing leaves
//! triangle against packet made them 1.13× as fast again on the bunny
//! (AVX-512, one thread, 1024² camera rays: 23.4 → 26.4 Mrays/s).
//! Two later steps, the same rays and hits, one thread, alternating runs:
//! the interval test in eight lanes ([`Isa::enter_interval`]) took 0.94
//! (0.89–1.00) of the time on the bunny and 0.96 (0.94–1.00) on the
//! conference room; the box rule decided for the whole packet
//! ([`Isa::enter_box_lanes`]) took 0.82 (0.80–0.86) on the bunny; and
//! the packet triangle test prepared from the packet's lanes rather than
//! ray by ray took 0.92 (0.86–0.97) on the conference room (0.97,
//! 0.91–1.05, on the bunny, within its spread).

use std::marker::PhantomData;

use rtgi_math::Ray;

use super::node::{ChildRef, NodeLayout};
use super::traverse::TraversalStack;
use super::{WideBvh, insert_far_to_near};
use crate::contract::{Best, HitFilter, PreparedRay, QueryKind, box_rule_at, hit_triangle};
use crate::simd::packet::{IntervalRay, Lanes, PACKET, PacketRays};
use crate::simd::packet_triangles::WatertightPacket;
use crate::simd::triangles::TriangleBlock;
use crate::simd::{Isa, Kernel, dispatch};
use crate::slab::BoxRay;
use crate::triangle::{TriangleTest, with_triangle_test};
use crate::{Hit, NoCounter};

/// An entry of the packet's stack: a child, the rays that entered it,
/// and the least distance at which one of them did.
#[derive(Clone, Copy)]
struct PacketEntry {
    child: ChildRef,
    rays: u32,
    enter: f32,
}

const PACKET_STACK: usize = 64;

/// What a packet's traversal works in, kept from one packet to the next
/// so that a batch allocates and initialises it once.
struct PacketScratch<T: TriangleTest> {
    /// Each ray prepared for the triangle tests, valid for the lanes of
    /// the packet's `prepared` mask.
    prepared: [PreparedRay<T>; PACKET],
    stack: Vec<PacketEntry>,
}

/// The rays of a packet prepared for the triangle tests, each when it
/// is first needed (most camera rays of a framed object reach no leaf).
struct PreparedRays<'a, T: TriangleTest> {
    rays: &'a mut [PreparedRay<T>; PACKET],
    /// Bit `i` set once `rays[i]` is prepared.
    ready: u32,
}

impl<T: TriangleTest> PreparedRays<'_, T> {
    /// Ray `lane` of the packet `rays`, prepared.
    #[inline(always)]
    fn get(&mut self, rays: &[Ray], lane: usize) -> &PreparedRay<T> {
        if self.ready & 1 << lane == 0 {
            self.rays[lane] = PreparedRay::new(&rays[lane]);
            self.ready |= 1 << lane;
        }
        &self.rays[lane]
    }
}

impl<const W: usize, N: NodeLayout<W>> WideBvh<W, N> {
    /// Answers every ray of `rays`: packets where sixteen consecutive rays
    /// are coherent, single rays elsewhere.
    pub(super) fn query_batch_dispatched<Q: QueryKind, F: HitFilter>(
        &self,
        rays: &[Ray],
        answer: &mut dyn FnMut(usize, Option<Hit>),
        filter: &F,
    ) {
        with_triangle_test!(self.intersector, |T| dispatch(Batch::<W, N, Q, T, F> {
            bvh: self,
            rays,
            answer,
            filter,
            kinds: PhantomData
        }))
    }

    #[inline(always)]
    fn traverse_packet<Q: QueryKind, T: TriangleTest, F: HitFilter, I: Isa>(
        &self,
        isa: I,
        rays: &[Ray],
        packet: &PacketRays,
        scratch: &mut PacketScratch<T>,
        answer: &mut dyn FnMut(usize, Option<Hit>),
        filter: &F,
    ) {
        let mut best = [Best::new(&rays[0]); PACKET];
        let mut t_max = Lanes([rays[0].t_max; PACKET]);
        for (lane, ray) in rays.iter().enumerate().skip(1) {
            best[lane] = Best::new(ray);
            t_max.0[lane] = ray.t_max;
        }
        // Rays are prepared for the triangle tests when they reach their
        // first leaf; the packet, for testing triangles against all its
        // rays at once, when its first leaf is reached.
        let mut packet_tests: Option<Option<WatertightPacket>> = None;
        let PacketScratch { prepared: prepared_rays, stack } = scratch;
        let mut prepared = PreparedRays { rays: prepared_rays, ready: 0 };
        stack.clear();
        let all = if rays.len() == PACKET { u32::MAX >> (32 - PACKET) } else { (1 << rays.len()) - 1 };
        let interval = IntervalRay::new(packet);
        let mut done = 0u32;
        // The latest `t_max` of the rays still searching: inner nodes are
        // culled against it, by the interval ray.
        let mut latest = t_max.latest(all);
        let mut current = PacketEntry { child: ChildRef::node(0), rays: all, enter: 0.0 };
        loop {
            if current.child.is_leaf() {
                let packet_tests =
                    packet_tests.get_or_insert_with(|| if I::PACKET_TRIANGLES { T::packet(packet) } else { None });
                let rays_in = current.rays & !done;
                done |= match packet_tests {
                    Some(packet_tests) => self.visit_leaf_packet::<Q, T, F, I>(
                        isa,
                        current.child,
                        (rays, rays_in, packet, packet_tests),
                        &mut prepared,
                        (&mut best, &mut t_max),
                        filter,
                    ),
                    None => self.visit_leaf_ray_by_ray::<Q, T, F>(
                        current.child,
                        (rays, rays_in),
                        &mut prepared,
                        (&mut best, &mut t_max),
                        filter,
                    ),
                };
                latest = t_max.latest(all & !done);
            } else {
                // Inner nodes are tested once, by the interval ray; a leaf
                // the interval ray enters is then tested against each ray,
                // so that only the rays that enter it take its triangles.
                let node = &self.nodes[current.child.node_index()];
                let active = all & !done;
                let (maybe, enter) = node.enter_interval(isa, &interval, latest);
                let children = node.children();
                let mut entered = [PacketEntry { child: ChildRef::NONE, rays: 0, enter: 0.0 }; W];
                let mut count = 0;
                let mut lanes = maybe;
                while lanes != 0 {
                    let lane = lanes.trailing_zeros() as usize;
                    lanes &= lanes - 1;
                    let child = children[lane];
                    let entry = if child.is_leaf() {
                        let (min, max) = node.child_box(lane);
                        let (near, far) = packet.near_far(min, max);
                        let (rays_in, enter) = isa.enter_box_packet(near, far, packet, &t_max, active);
                        if rays_in == 0 {
                            continue;
                        }
                        PacketEntry { child, rays: rays_in, enter }
                    } else {
                        PacketEntry { child, rays: active, enter: enter[lane] }
                    };
                    insert_far_to_near(&mut entered, count, entry, |e| e.enter);
                    count += 1;
                }
                if count > 0 {
                    stack.extend_from_slice(&entered[..count - 1]);
                    current = entered[count - 1];
                    continue;
                }
            }
            // Next from the stack, dropped when every ray that entered it
            // has since found a hit in front of it (or is done).
            loop {
                let Some(entry) = stack.pop() else {
                    for (lane, best) in best.iter().enumerate().take(rays.len()) {
                        answer(lane, best.hit);
                    }
                    return;
                };
                if entry.enter <= t_max.latest(entry.rays & !done) {
                    current = entry;
                    break;
                }
            }
        }
    }
}

impl<const W: usize, N: NodeLayout<W>> WideBvh<W, N> {
    /// Tests `leaf` ray by ray, for each ray of `rays_in` with the block
    /// tests of single rays; offers each ray's hits to its `best`,
    /// keeping `t_max` in step. Returns the rays whose query is answered
    /// (any-hit queries that found a hit).
    #[inline(always)]
    fn visit_leaf_ray_by_ray<Q: QueryKind, T: TriangleTest, F: HitFilter>(
        &self,
        leaf: ChildRef,
        (rays, rays_in): (&[Ray], u32),
        prepared: &mut PreparedRays<T>,
        (best, t_max): (&mut [Best; PACKET], &mut Lanes),
        filter: &F,
    ) -> u32 {
        let mut answered = 0;
        let mut lanes = rays_in;
        while lanes != 0 {
            let lane = lanes.trailing_zeros() as usize;
            lanes &= lanes - 1;
            if self.visit_leaf::<Q, NoCounter, T, F>(
                leaf,
                prepared.get(rays, lane),
                &mut best[lane],
                &mut NoCounter,
                filter,
            ) {
                answered |= 1 << lane;
            }
            t_max.0[lane] = best[lane].t_max;
        }
        answered
    }

    /// Tests each triangle of `leaf` against the rays `rays_in` of the
    /// packet at once ([`Isa::watertight_packet`]), and offers each ray's
    /// hits to its `best`, keeping `t_max` in step; the scalar test
    /// decides the lanes the packet test hands back. Returns the rays
    /// whose query is answered.
    ///
    /// The box rule (`crate::contract::box_rule`) of the lanes the packet
    /// test decides is one slab test of the triangle's box for the whole
    /// packet ([`Isa::enter_box_lanes`]), so that only the lanes handed
    /// back need their ray prepared for the scalar tests: preparing each
    /// ray that found a hit, and its box rule, took a fifth of the packets'
    /// time on the bunny's camera rays.
    #[inline(always)]
    fn visit_leaf_packet<Q: QueryKind, T: TriangleTest, F: HitFilter, I: Isa>(
        &self,
        isa: I,
        leaf: ChildRef,
        (rays, mut rays_in, packet_rays, packet): (&[Ray], u32, &PacketRays, &WatertightPacket),
        prepared: &mut PreparedRays<T>,
        (best, t_max): (&mut [Best; PACKET], &mut Lanes),
        filter: &F,
    ) -> u32 {
        let mut answered = 0;
        for block in &self.blocks[leaf.blocks()] {
            for (triangle_lane, &id) in block.ids.iter().enumerate() {
                if rays_in == 0 {
                    return answered;
                }
                if id == TriangleBlock::NO_TRIANGLE {
                    continue;
                }
                let hits = isa.watertight_packet(packet, t_max, block.corners(triangle_lane));
                let mut lanes = (hits.exact | hits.rescan) & rays_in;
                if lanes == 0 {
                    continue;
                }
                let triangle = block.triangle(triangle_lane);
                let entries = if lanes & !hits.rescan != 0 {
                    let [a, b, c] = triangle;
                    let (near, far) = packet_rays.near_far(a.min(b).min(c).to_array(), a.max(b).max(c).to_array());
                    isa.enter_box_lanes(near, far, packet_rays, t_max)
                } else {
                    Lanes([f32::INFINITY; PACKET])
                };
                while lanes != 0 {
                    let lane = lanes.trailing_zeros() as usize;
                    lanes &= lanes - 1;
                    let hit = if hits.rescan & 1 << lane != 0 {
                        hit_triangle(prepared.get(rays, lane), &triangle, best[lane].t_max)
                    } else {
                        box_rule_at(hits.hit(lane), entries[lane])
                    };
                    if let Some(hit) = hit
                        && best[lane].offer(id, hit, filter)
                    {
                        t_max.0[lane] = best[lane].t_max;
                        if Q::STOP_AT_FIRST_HIT {
                            answered |= 1 << lane;
                            rays_in &= !(1 << lane);
                        }
                    }
                }
            }
        }
        answered
    }
}

/// A batch of queries as one [`Kernel`].
struct Batch<'a, const W: usize, N, Q, T, F> {
    bvh: &'a WideBvh<W, N>,
    rays: &'a [Ray],
    answer: &'a mut dyn FnMut(usize, Option<Hit>),
    filter: &'a F,
    kinds: PhantomData<(Q, T)>,
}

impl<const W: usize, N: NodeLayout<W>, Q: QueryKind, T: TriangleTest, F: HitFilter> Kernel
    for Batch<'_, W, N, Q, T, F>
{
    type Output = ();

    #[inline(always)]
    fn run<I: Isa>(self, isa: I) {
        let Batch { bvh, rays, answer, filter, .. } = self;
        if bvh.nodes.is_empty() || rays.is_empty() {
            (0..rays.len()).for_each(|index| answer(index, None));
            return;
        }
        let mut stack = TraversalStack::<32>::new();
        let mut scratch = PacketScratch::<T> {
            prepared: std::array::from_fn(|_| PreparedRay::new(&rays[0])),
            stack: Vec::with_capacity(PACKET_STACK),
        };
        for (chunk_index, chunk) in rays.chunks(PACKET).enumerate() {
            let offset = chunk_index * PACKET;
            match PacketRays::new(chunk) {
                Some(packet) => bvh.traverse_packet::<Q, T, F, I>(
                    isa,
                    chunk,
                    &packet,
                    &mut scratch,
                    &mut |lane, hit| answer(offset + lane, hit),
                    filter,
                ),
                None => {
                    for (lane, ray) in chunk.iter().enumerate() {
                        let hit = if I::NODES_TAKE_RAYS_STARTING_BEHIND || !BoxRay::starts_behind(ray) {
                            bvh.traverse::<Q, NoCounter, T, F, I, 32>(isa, ray, &mut stack, &mut NoCounter, filter)
                        } else {
                            bvh.traverse_portable::<Q, NoCounter, T, F>(ray, &mut NoCounter, filter)
                        };
                        answer(offset + lane, hit);
                    }
                }
            }
        }
    }
}
