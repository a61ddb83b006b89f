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

use rtgi_math::{Ray, Vec4};

use super::node::ChildRef;
use super::traverse::TraversalStack;
use super::{WideBvh, insert_far_to_near};
use crate::contract::{AcceptAll, Best, PreparedRay, QueryKind};
use crate::simd::boxes::FAR_OF_NEAR;
use crate::simd::{Isa, Kernel, dispatch};
use crate::slab::ROBUST_FAR_SCALE;
use crate::triangle::{MollerTrumbore, TriangleTest, Watertight, WatertightF64};
use crate::{Hit, Intersector, NoCounter};

/// Rays in a packet.
pub(crate) const PACKET: usize = 16;

/// The rays of a packet, structure-of-arrays; all have the same direction
/// signs, so that each axis has one near plane for the whole packet.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(crate) struct PacketRays {
    pub(crate) origin: [Lanes; 3],
    pub(crate) inv_direction: [Lanes; 3],
    pub(crate) t_min: Lanes,
    /// Index of each axis's near plane in a node's planes (see `WideBoxes`).
    pub(crate) near: [usize; 3],
}

/// One number for each ray of a packet, aligned for 512-bit loads.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(crate) struct Lanes(pub(crate) [f32; PACKET]);

/// Smallest cosine between the first ray's direction and any other's for
/// a batch of rays to be traced as a packet: about 8°. Beyond that the
/// rays part ways soon and single rays are faster.
const COHERENT_COSINE: f32 = 0.99;

impl PacketRays {
    /// The packet of `rays` (at most [`PACKET`]), or `None` if they are
    /// not coherent: an invalid ray, direction signs that differ, or
    /// directions too far apart.
    pub(crate) fn new(rays: &[Ray]) -> Option<Self> {
        debug_assert!(rays.len() <= PACKET);
        let first = rays.first()?;
        let sign_bits = |ray: &Ray| ray.direction.is_negative_bitmask();
        let (axis, first_signs) = (first.direction, sign_bits(first));
        let axis_length2 = axis.length_squared();
        // cos(d, axis) ≥ c, squared: (d · axis)² ≥ c² |d|² |axis|², with d · axis ≥ 0.
        let coherent = rays.iter().all(|ray| {
            let along = ray.direction.dot(axis);
            ray.is_valid()
                && sign_bits(ray) == first_signs
                && along >= 0.0
                && along * along >= COHERENT_COSINE * COHERENT_COSINE * ray.direction.length_squared() * axis_length2
        });
        if !coherent {
            return None;
        }
        // Lanes past the end repeat the first ray; their answers are dropped.
        let mut packet = PacketRays {
            origin: [Lanes([0.0; PACKET]); 3],
            inv_direction: [Lanes([0.0; PACKET]); 3],
            t_min: Lanes([first.t_min; PACKET]),
            near: [0, 1, 2].map(|axis| if first_signs >> axis & 1 == 1 { axis + 3 } else { axis }),
        };
        for lane in 0..PACKET {
            let ray = rays.get(lane).unwrap_or(first);
            // As `BoxRay` computes it, so that the box tests agree with the scalar one.
            let (origin, inv) = (ray.origin.to_array(), (1.0 / rtgi_math::Vec3A::from(ray.direction)).to_array());
            for axis in 0..3 {
                packet.origin[axis].0[lane] = origin[axis];
                packet.inv_direction[axis].0[lane] = inv[axis];
            }
            packet.t_min.0[lane] = ray.t_min;
        }
        Some(packet)
    }
}

impl PacketRays {
    /// Which of the rays in `active` enter the box whose near planes (for
    /// the packet's direction signs) are `near` and far planes `far`, no
    /// later than their `t_max`; and a distance no later than the earliest
    /// entry among them. The robust slab test's arithmetic, ray by ray.
    #[inline(always)]
    pub(crate) fn enter_box(&self, near: [f32; 3], far: [f32; 3], t_max: &Lanes, active: u32) -> (u32, f32) {
        let mut mask = 0;
        let mut earliest = Vec4::INFINITY;
        for chunk in 0..PACKET / 4 {
            let lanes = chunk * 4..chunk * 4 + 4;
            let mut enter = Vec4::from_slice(&self.t_min.0[lanes.clone()]);
            let mut exit = Vec4::from_slice(&t_max.0[lanes.clone()]);
            for axis in 0..3 {
                let origin = Vec4::from_slice(&self.origin[axis].0[lanes.clone()]);
                let inv = Vec4::from_slice(&self.inv_direction[axis].0[lanes.clone()]);
                let t_near = (Vec4::splat(near[axis]) - origin) * inv;
                let t_far = (Vec4::splat(far[axis]) - origin) * inv * Vec4::splat(ROBUST_FAR_SCALE);
                // A NaN compares false and leaves the bound as it was.
                enter = Vec4::select(t_near.cmpgt(enter), t_near, enter);
                exit = Vec4::select(t_far.cmplt(exit), t_far, exit);
            }
            let entered = enter.cmple(exit) & enter.cmplt(Vec4::INFINITY);
            earliest = earliest.min(Vec4::select(entered, enter, Vec4::INFINITY));
            mask |= entered.bitmask() << (chunk * 4);
        }
        (mask & active, earliest.min_element())
    }
}

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
    pub(super) fn query_batch_dispatched<Q: QueryKind>(
        &self,
        rays: &[Ray],
        answer: &mut dyn FnMut(usize, Option<Hit>),
    ) {
        match self.intersector {
            Intersector::Watertight => {
                dispatch(Batch::<W, Q, Watertight> { bvh: self, rays, answer, kinds: PhantomData })
            }
            Intersector::MollerTrumbore => {
                dispatch(Batch::<W, Q, MollerTrumbore> { bvh: self, rays, answer, kinds: PhantomData })
            }
            Intersector::WatertightF64 => {
                dispatch(Batch::<W, Q, WatertightF64> { bvh: self, rays, answer, kinds: PhantomData })
            }
        }
    }

    #[inline(always)]
    fn traverse_packet<Q: QueryKind, T: TriangleTest, I: Isa>(
        &self,
        isa: I,
        rays: &[Ray],
        packet: &PacketRays,
        answer: &mut dyn FnMut(usize, Option<Hit>),
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
                    let answered = self.visit_leaf::<Q, NoCounter, T, AcceptAll>(
                        current.child,
                        ray,
                        &mut best[lane],
                        &mut NoCounter,
                        &AcceptAll,
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
struct Batch<'a, const W: usize, Q, T> {
    bvh: &'a WideBvh<W>,
    rays: &'a [Ray],
    answer: &'a mut dyn FnMut(usize, Option<Hit>),
    kinds: PhantomData<(Q, T)>,
}

impl<const W: usize, Q: QueryKind, T: TriangleTest> Kernel for Batch<'_, W, Q, T> {
    type Output = ();

    #[inline(always)]
    fn run<I: Isa>(self, isa: I) {
        let Batch { bvh, rays, answer, .. } = self;
        if bvh.nodes.is_empty() {
            (0..rays.len()).for_each(|index| answer(index, None));
            return;
        }
        let mut stack = TraversalStack::<32>::new();
        for (chunk_index, chunk) in rays.chunks(PACKET).enumerate() {
            let offset = chunk_index * PACKET;
            match PacketRays::new(chunk) {
                Some(packet) => {
                    bvh.traverse_packet::<Q, T, I>(isa, chunk, &packet, &mut |lane, hit| answer(offset + lane, hit))
                }
                None => {
                    for (lane, ray) in chunk.iter().enumerate() {
                        let hit = bvh.traverse::<Q, NoCounter, T, AcceptAll, I, 32>(
                            isa,
                            ray,
                            &mut stack,
                            &mut NoCounter,
                            &AcceptAll,
                        );
                        answer(offset + lane, hit);
                    }
                }
            }
        }
    }
}
