//! Packet traversal: sixteen coherent rays (a 4×4 tile of camera rays,
//! say) walk a wide BVH together. A node is visited when any ray of the
//! packet enters one of its children; each child's box is tested against
//! all sixteen rays at once, and each ray then tests the leaves it reaches
//! on its own, with the same block tests as single rays.
//!
//! The answers are those of single-ray traversal, bit for bit: every ray
//! is tested against every leaf its own traversal would test (the box
//! tests are the robust slab test's arithmetic, lane by lane, and a child
//! is dropped for a ray only when that ray misses it or enters it beyond
//! its best hit), and sometimes against more, which cannot change its
//! answer: the hit rule is a function of the ray and the triangle alone,
//! and the best hit is the least in the order (distance, triangle index)
//! whichever order hits are found in.

use std::marker::PhantomData;

use rtgi_math::Ray;

use super::node::ChildRef;
use super::traverse::TraversalStack;
use super::{WideBvh, insert_far_to_near};
use crate::contract::{Best, HitFilter, PreparedRay, QueryKind};
use crate::simd::boxes::FAR_OF_NEAR;
use crate::simd::packet::{Lanes, PACKET, PacketRays};
use crate::simd::{Isa, Kernel, dispatch};
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

impl<const W: usize> WideBvh<W> {
    /// Answers every ray of `rays`: packets where sixteen consecutive rays
    /// are coherent, single rays elsewhere.
    pub(super) fn query_batch_dispatched<Q: QueryKind, F: HitFilter>(
        &self,
        rays: &[Ray],
        answer: &mut dyn FnMut(usize, Option<Hit>),
        filter: &F,
    ) {
        with_triangle_test!(self.intersector, |T| dispatch(Batch::<W, Q, T, F> {
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
        answer: &mut dyn FnMut(usize, Option<Hit>),
        filter: &F,
    ) {
        let mut best: [Best; PACKET] = std::array::from_fn(|lane| Best::new(rays.get(lane).unwrap_or(&rays[0])));
        let mut t_max = Lanes(std::array::from_fn(|lane| best[lane].t_max));
        // Prepared for the triangle tests when the ray reaches its first leaf.
        let mut prepared: [Option<PreparedRay<T>>; PACKET] = std::array::from_fn(|_| None);
        let all = if rays.len() == PACKET { u32::MAX >> (32 - PACKET) } else { (1 << rays.len()) - 1 };
        let mut done = 0u32;
        let mut stack: Vec<PacketEntry> = Vec::with_capacity(PACKET_STACK);
        let mut current = PacketEntry { child: ChildRef::node(0), rays: all, enter: 0.0 };
        loop {
            if current.child.is_leaf() {
                let mut lanes = current.rays & !done;
                while lanes != 0 {
                    let lane = lanes.trailing_zeros() as usize;
                    lanes &= lanes - 1;
                    let ray = prepared[lane].get_or_insert_with(|| PreparedRay::new(&rays[lane]));
                    let answered = self.visit_leaf::<Q, NoCounter, T, F>(
                        current.child,
                        ray,
                        &mut best[lane],
                        &mut NoCounter,
                        filter,
                    );
                    t_max.0[lane] = best[lane].t_max;
                    if answered {
                        done |= 1 << lane;
                    }
                }
            } else {
                let node = &self.nodes[current.child.node_index()];
                let active = current.rays & !done;
                let mut entered = [PacketEntry { child: ChildRef::NONE, rays: 0, enter: 0.0 }; W];
                let mut count = 0;
                for lane in 0..W {
                    let child = node.children[lane];
                    if child == ChildRef::NONE {
                        break;
                    }
                    let planes = &node.boxes.planes;
                    let near = [0, 1, 2].map(|axis| planes[packet.near[axis]][lane]);
                    let far = [0, 1, 2].map(|axis| planes[packet.near[axis] ^ FAR_OF_NEAR[axis]][lane]);
                    let (rays_in, enter) = isa.enter_box_packet(near, far, packet, &t_max, active);
                    if rays_in != 0 {
                        let entry = PacketEntry { child, rays: rays_in, enter };
                        insert_far_to_near(&mut entered, count, entry, |e| e.enter);
                        count += 1;
                    }
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
                let mut lanes = entry.rays & !done;
                let mut farthest = f32::NEG_INFINITY;
                while lanes != 0 {
                    let lane = lanes.trailing_zeros() as usize;
                    lanes &= lanes - 1;
                    farthest = farthest.max(t_max.0[lane]);
                }
                if entry.enter <= farthest {
                    current = entry;
                    break;
                }
            }
        }
    }
}

/// A batch of queries as one [`Kernel`].
struct Batch<'a, const W: usize, Q, T, F> {
    bvh: &'a WideBvh<W>,
    rays: &'a [Ray],
    answer: &'a mut dyn FnMut(usize, Option<Hit>),
    filter: &'a F,
    kinds: PhantomData<(Q, T)>,
}

impl<const W: usize, Q: QueryKind, T: TriangleTest, F: HitFilter> Kernel for Batch<'_, W, Q, T, F> {
    type Output = ();

    #[inline(always)]
    fn run<I: Isa>(self, isa: I) {
        let Batch { bvh, rays, answer, filter, .. } = self;
        if bvh.nodes.is_empty() {
            (0..rays.len()).for_each(|index| answer(index, None));
            return;
        }
        let mut stack = TraversalStack::<32>::new();
        for (chunk_index, chunk) in rays.chunks(PACKET).enumerate() {
            let offset = chunk_index * PACKET;
            match PacketRays::new(chunk) {
                Some(packet) => bvh.traverse_packet::<Q, T, F, I>(
                    isa,
                    chunk,
                    &packet,
                    &mut |lane, hit| answer(offset + lane, hit),
                    filter,
                ),
                None => {
                    for (lane, ray) in chunk.iter().enumerate() {
                        let hit =
                            bvh.traverse::<Q, NoCounter, T, F, I, 32>(isa, ray, &mut stack, &mut NoCounter, filter);
                        answer(offset + lane, hit);
                    }
                }
            }
        }
    }
}
