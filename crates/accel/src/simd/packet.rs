//! The rays of a packet, structure-of-arrays, and the two box tests they
//! take together: which of them enter a box ([`PacketRays::enter_box`],
//! with an intrinsic twin in `dispatch.rs`), and which of a node's boxes
//! any of them may enter, tested once for all by the interval ray that
//! bounds them ([`IntervalRay`]). The packet traversal (`wide/packet.rs`)
//! walks a wide BVH with them.

use rtgi_math::glam::BVec4A;
use rtgi_math::{Mat4, Ray, Vec4};

use super::boxes::{WideBoxes, enter_planes};
use crate::slab::{EXIT_FOLD, later_exit};

/// Rays in a packet.
pub(crate) const PACKET: usize = 16;

/// The rays of a packet, structure-of-arrays; all have the same direction
/// signs, so that each axis has one near plane for the whole packet.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(crate) struct PacketRays {
    pub(crate) origin: [Lanes; 3],
    /// The directions, for the packet triangle test's shears
    /// ([`crate::simd::packet_triangles::WatertightPacket::of_packet`]).
    pub(crate) direction: [Lanes; 3],
    pub(crate) inv_direction: [Lanes; 3],
    /// The inverses for exit distances ahead of and behind each ray's
    /// origin ([`crate::slab::exit_inverses`]).
    pub(crate) inv_exit: [Lanes; 3],
    pub(crate) inv_exit_behind: [Lanes; 3],
    pub(crate) t_min: Lanes,
    /// Index of each axis's near plane in a node's planes (see `WideBoxes`).
    pub(crate) near: [usize; 3],
}

/// One number for each ray of a packet, aligned for 512-bit loads.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(crate) struct Lanes(pub(crate) [f32; PACKET]);

impl Lanes {
    /// Lanes `4 chunk .. 4 chunk + 4`.
    #[inline(always)]
    pub(crate) fn chunk(&self, chunk: usize) -> Vec4 {
        Vec4::from_slice(&self.0[chunk * 4..chunk * 4 + 4])
    }

    /// The least and the greatest lane.
    #[inline(always)]
    fn range(&self) -> (f32, f32) {
        let (mut least, mut greatest) = (Vec4::INFINITY, Vec4::NEG_INFINITY);
        for chunk in 0..PACKET / 4 {
            least = least.min(self.chunk(chunk));
            greatest = greatest.max(self.chunk(chunk));
        }
        (least.min_element(), greatest.max_element())
    }

    /// The greatest of the lanes in `mask`, or -∞ for an empty mask.
    /// Four lanes at a time, the others masked to -∞: the traversal asks
    /// after every leaf and stack entry, and a loop over the mask's bits
    /// took a tenth of the packets' time.
    #[inline(always)]
    pub(crate) fn latest(&self, mask: u32) -> f32 {
        let mut latest = Vec4::NEG_INFINITY;
        for chunk in 0..PACKET / 4 {
            let bits = mask >> (chunk * 4);
            let selected = BVec4A::new(bits & 1 != 0, bits & 2 != 0, bits & 4 != 0, bits & 8 != 0);
            latest = latest.max(Vec4::select(selected, self.chunk(chunk), Vec4::NEG_INFINITY));
        }
        latest.max_element()
    }
}

impl std::ops::Index<usize> for Lanes {
    type Output = f32;
    #[inline(always)]
    fn index(&self, lane: usize) -> &f32 {
        &self.0[lane]
    }
}

/// Smallest cosine between the first ray's direction and any other's for
/// a batch of rays to be traced as a packet: about 8°. Beyond that the
/// rays part ways soon and single rays are faster.
const COHERENT_COSINE: f32 = 0.99;

impl PacketRays {
    /// The packet of `rays` (at most [`PACKET`]), or `None` if they are
    /// not coherent: an invalid ray, direction signs that differ, or
    /// directions too far apart.
    ///
    /// Four rays at a time are transposed to structure-of-arrays and
    /// checked together, with vector instructions.
    #[inline(always)]
    pub(crate) fn new(rays: &[Ray]) -> Option<Self> {
        debug_assert!(rays.len() <= PACKET);
        let first = rays.first()?;
        let axis = Vec4::from((first.direction, 0.0));
        let min_cosine2 = Vec4::splat(COHERENT_COSINE * COHERENT_COSINE * axis.length_squared());
        let signs = first.direction.is_negative_bitmask();
        let mut packet = PacketRays {
            origin: [Lanes([0.0; PACKET]); 3],
            direction: [Lanes([0.0; PACKET]); 3],
            inv_direction: [Lanes([0.0; PACKET]); 3],
            inv_exit: [Lanes([0.0; PACKET]); 3],
            inv_exit_behind: [Lanes([0.0; PACKET]); 3],
            t_min: Lanes([0.0; PACKET]),
            near: [0, 1, 2].map(|axis| if signs >> axis & 1 == 1 { axis + 3 } else { axis }),
        };
        let mut coherent = true;
        for chunk in 0..PACKET / 4 {
            // Lanes past the end repeat the first ray; their answers are dropped.
            // (Written out: array maps of closures were left as calls.)
            let ray = |lane: usize| rays.get(chunk * 4 + lane).unwrap_or(first);
            let (r0, r1, r2, r3) = (ray(0), ray(1), ray(2), ray(3));
            let first_half = |r: &Ray| Vec4::new(r.origin.x, r.origin.y, r.origin.z, r.direction.x);
            let second_half = |r: &Ray| Vec4::new(r.direction.y, r.direction.z, r.t_min, r.t_max);
            let a = Mat4::from_cols(first_half(r0), first_half(r1), first_half(r2), first_half(r3)).transpose();
            let b = Mat4::from_cols(second_half(r0), second_half(r1), second_half(r2), second_half(r3)).transpose();
            let (ox, oy, oz, dx) = (a.x_axis, a.y_axis, a.z_axis, a.w_axis);
            let (dy, dz, t_min, t_max) = (b.x_axis, b.y_axis, b.z_axis, b.w_axis);
            let finite = |v: Vec4| v.abs().cmplt(Vec4::INFINITY);
            let along = dx * axis.x + dy * axis.y + dz * axis.z;
            let length2 = dx * dx + dy * dy + dz * dz;
            // As `Ray::is_valid`: finite origin and direction, a non-zero
            // direction and a non-empty range (NaN compares false).
            let valid = finite(ox)
                & finite(oy)
                & finite(oz)
                & finite(dx)
                & finite(dy)
                & finite(dz)
                & (dx.cmpne(Vec4::ZERO) | dy.cmpne(Vec4::ZERO) | dz.cmpne(Vec4::ZERO))
                & t_min.cmple(t_max);
            let same_signs = [dx, dy, dz]
                .iter()
                .enumerate()
                .all(|(axis, d)| d.is_negative_bitmask() == if signs >> axis & 1 == 1 { 0b1111 } else { 0 });
            // cos(d, axis) ≥ c, squared: (d · axis)² ≥ c² |d|² |axis|², with d · axis ≥ 0.
            let close = along.cmpge(Vec4::ZERO) & (along * along).cmpge(min_cosine2 * length2);
            coherent &= (valid & close).all() & same_signs;
            let lanes = chunk * 4..chunk * 4 + 4;
            for (axis, (o, d)) in [(ox, dx), (oy, dy), (oz, dz)].into_iter().enumerate() {
                o.write_to_slice(&mut packet.origin[axis].0[lanes.clone()]);
                d.write_to_slice(&mut packet.direction[axis].0[lanes.clone()]);
                // As `BoxRay` computes them, so that the box tests agree with the scalar one.
                let inv = Vec4::ONE / d;
                let ahead = inv * EXIT_FOLD;
                let behind = Vec4::select(t_min.cmpge(Vec4::ZERO), ahead, inv / EXIT_FOLD);
                inv.write_to_slice(&mut packet.inv_direction[axis].0[lanes.clone()]);
                ahead.write_to_slice(&mut packet.inv_exit[axis].0[lanes.clone()]);
                behind.write_to_slice(&mut packet.inv_exit_behind[axis].0[lanes.clone()]);
            }
            t_min.write_to_slice(&mut packet.t_min.0[lanes]);
        }
        coherent.then_some(packet)
    }
}

impl PacketRays {
    /// Which of the rays in `active` enter the box whose near planes (for
    /// the packet's direction signs) are `near` and far planes `far`, no
    /// later than their `t_max`; and a distance no later than the earliest
    /// entry among them. The robust slab test's arithmetic, ray by ray.
    #[inline(always)]
    pub(crate) fn enter_box(&self, near: [f32; 3], far: [f32; 3], t_max: &Lanes, active: u32) -> (u32, f32) {
        let entries = self.enter_box_lanes(near, far, t_max);
        let mut mask = 0;
        let mut earliest = Vec4::INFINITY;
        for chunk in 0..PACKET / 4 {
            // A lane holds +∞ exactly where its ray misses the box.
            let entry = entries.chunk(chunk);
            earliest = earliest.min(entry);
            mask |= entry.cmplt(Vec4::INFINITY).bitmask() << (chunk * 4);
        }
        (mask & active, earliest.min_element())
    }
}

impl PacketRays {
    /// The near and far planes, for the packet's direction signs, of the
    /// box `[min, max]`: the arguments of [`PacketRays::enter_box`] and
    /// [`PacketRays::enter_box_lanes`].
    #[inline(always)]
    pub(crate) fn near_far(&self, min: [f32; 3], max: [f32; 3]) -> ([f32; 3], [f32; 3]) {
        let planes = [min, max];
        // `near[axis]` is `axis` (the minimum) or `axis + 3` (the maximum).
        let plane = |axis: usize, far: bool| planes[(self.near[axis] >= 3) as usize ^ far as usize][axis];
        ([plane(0, false), plane(1, false), plane(2, false)], [plane(0, true), plane(1, true), plane(2, true)])
    }

    /// Where each ray enters the box whose near planes (for the packet's
    /// direction signs) are `near` and far planes `far`, within its
    /// `[t_min, t_max]`, or +∞ for a ray that misses it: lane by lane the
    /// bits of [`crate::slab::RobustSlabs`]'s test of that ray (the
    /// arithmetic of [`PacketRays::enter_box`], each lane kept).
    #[inline(always)]
    pub(crate) fn enter_box_lanes(&self, near: [f32; 3], far: [f32; 3], t_max: &Lanes) -> Lanes {
        let mut entries = Lanes([f32::INFINITY; PACKET]);
        for chunk in 0..PACKET / 4 {
            let lanes = chunk * 4..chunk * 4 + 4;
            let mut enter = Vec4::from_slice(&self.t_min.0[lanes.clone()]);
            let mut exit = Vec4::from_slice(&t_max.0[lanes.clone()]);
            for axis in 0..3 {
                let origin = Vec4::from_slice(&self.origin[axis].0[lanes.clone()]);
                let inv = Vec4::from_slice(&self.inv_direction[axis].0[lanes.clone()]);
                let ahead = Vec4::from_slice(&self.inv_exit[axis].0[lanes.clone()]);
                let behind = Vec4::from_slice(&self.inv_exit_behind[axis].0[lanes.clone()]);
                let t_near = (Vec4::splat(near[axis]) - origin) * inv;
                let t_far = later_exit(Vec4::splat(far[axis]) - origin, ahead, behind, Vec4::max);
                enter = Vec4::select(t_near.cmpgt(enter), t_near, enter);
                exit = Vec4::select(t_far.cmplt(exit), t_far, exit);
            }
            let entered = enter.cmple(exit) & enter.cmplt(Vec4::INFINITY);
            Vec4::select(entered, enter, Vec4::INFINITY).write_to_slice(&mut entries.0[lanes]);
        }
        entries
    }
}

/// The rays of a packet as one ray with interval coordinates: for each
/// axis, the range of the origins and of the inverse directions. Its box
/// test bounds every ray's: the distance at which it enters a box is no
/// later than any ray's entry, and the exit no earlier than any ray's
/// exit, so a box it misses is missed by every ray of the packet.
///
/// Why the bounds hold, bit for bit. A ray computes the distance to a
/// plane `p` as `fl(fl(p - o) * i)`. Rounding is monotone, so
/// `fl(p - o)` lies between its values at the extreme origins, and the
/// product's exact value over the rectangle of differences and inverses
/// is least (or greatest) at a corner, which the rounded corner product
/// then bounds too. The inverses of a packet share one sign, so the
/// corner is picked by the sign of the difference alone (below). A ray
/// with a zero direction component (an infinite inverse) on a plane
/// through its origin gets NaN, which drops the axis from its test; the
/// corner product is then NaN or infinite too, and drops it from the
/// bound (see [`IntervalRay::enter_boxes`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct IntervalRay {
    /// Per axis, the origin coordinate furthest along the direction: the
    /// one whose near plane distance is least.
    pub(super) origin_ahead: [f32; 3],
    /// Per axis, the origin coordinate least far along the direction.
    pub(super) origin_behind: [f32; 3],
    /// Per axis, the inverse direction of least magnitude.
    pub(super) inv_small: [f32; 3],
    /// Per axis, the inverse direction of greatest magnitude.
    pub(super) inv_big: [f32; 3],
    /// Per axis, the least and greatest magnitude of the rays' inverses
    /// for exits ahead of their origins, and of those for exits behind.
    pub(super) exit_small: [f32; 3],
    pub(super) exit_big: [f32; 3],
    pub(super) exit_behind_small: [f32; 3],
    pub(super) exit_behind_big: [f32; 3],
    /// Per axis, 1 for a positive direction and -1 for a negative one.
    pub(super) sign: [f32; 3],
    pub(super) near: [usize; 3],
    /// The least `t_min` of the rays.
    pub(super) t_min: f32,
}

impl IntervalRay {
    #[inline(always)]
    pub(crate) fn new(packet: &PacketRays) -> Self {
        let mut ray = IntervalRay {
            origin_ahead: [0.0; 3],
            origin_behind: [0.0; 3],
            inv_small: [0.0; 3],
            inv_big: [0.0; 3],
            exit_small: [0.0; 3],
            exit_big: [0.0; 3],
            exit_behind_small: [0.0; 3],
            exit_behind_big: [0.0; 3],
            sign: [1.0; 3],
            near: packet.near,
            t_min: packet.t_min.range().0,
        };
        for axis in 0..3 {
            let (origin_min, origin_max) = packet.origin[axis].range();
            let (inv_min, inv_max) = packet.inv_direction[axis].range();
            let (exit_min, exit_max) = packet.inv_exit[axis].range();
            let (behind_min, behind_max) = packet.inv_exit_behind[axis].range();
            if packet.near[axis] == axis {
                ray.origin_ahead[axis] = origin_max;
                ray.origin_behind[axis] = origin_min;
                (ray.inv_small[axis], ray.inv_big[axis]) = (inv_min, inv_max);
                (ray.exit_small[axis], ray.exit_big[axis]) = (exit_min, exit_max);
                (ray.exit_behind_small[axis], ray.exit_behind_big[axis]) = (behind_min, behind_max);
            } else {
                ray.origin_ahead[axis] = origin_min;
                ray.origin_behind[axis] = origin_max;
                (ray.inv_small[axis], ray.inv_big[axis]) = (inv_max, inv_min);
                (ray.exit_small[axis], ray.exit_big[axis]) = (exit_max, exit_min);
                (ray.exit_behind_small[axis], ray.exit_behind_big[axis]) = (behind_max, behind_min);
                ray.sign[axis] = -1.0;
            }
        }
        ray
    }

    /// For each of the `W` boxes, a distance no later than the one at
    /// which any ray of the packet enters it within `[t_min, t_max]`
    /// (`t_max` being the latest of the rays'), or +∞ where no ray can
    /// enter it; and a mask of the boxes that some ray may enter.
    ///
    /// The near plane's least distance takes the origin ahead, and then
    /// the smallest inverse where the difference points along the
    /// direction (all distances are positive) and the biggest otherwise.
    /// The far plane's greatest distance takes the origin behind, the
    /// biggest inverse where the difference points along the direction or
    /// is zero, and the smallest otherwise. At a zero difference the
    /// biggest inverse gives NaN when it is infinite, which drops the axis,
    /// as it does for the ray that has it.
    #[inline(always)]
    pub(crate) fn enter_boxes<const W: usize>(&self, boxes: &WideBoxes<W>, t_max: f32) -> (u32, [f32; W]) {
        boxes.enter_with(self.near, self.t_min, t_max, |axis, near, far| self.distances(axis, near, far))
    }

    /// [`IntervalRay::enter_boxes`] on `W` boxes whose planes
    /// `plane(k, first)` gives (see [`enter_planes`]).
    #[inline(always)]
    pub(crate) fn enter_planes<const W: usize>(
        &self,
        plane: impl Fn(usize, usize) -> Vec4,
        t_max: f32,
    ) -> (u32, [f32; W]) {
        enter_planes(plane, self.near, self.t_min, t_max, |axis, near, far| self.distances(axis, near, far))
    }

    /// The least distance to four boxes' near planes along `axis`, and the
    /// greatest (enlarged) to their far planes, over the packet's rays.
    #[inline(always)]
    fn distances(&self, axis: usize, near: Vec4, far: Vec4) -> (Vec4, Vec4) {
        let (small, big, sign) =
            (Vec4::splat(self.inv_small[axis]), Vec4::splat(self.inv_big[axis]), Vec4::splat(self.sign[axis]));
        let to_near = near - Vec4::splat(self.origin_ahead[axis]);
        let to_far = far - Vec4::splat(self.origin_behind[axis]);
        let t_near = to_near * Vec4::select((to_near * sign).cmpgt(Vec4::ZERO), small, big);
        // Each ray's exit is the larger of two products, one with each of
        // its exit inverses (`crate::slab::later_exit`); each product is
        // bounded at its own corner, and so is their maximum.
        let backwards = (to_far * sign).cmplt(Vec4::ZERO);
        let pick = |small: f32, big: f32| Vec4::select(backwards, Vec4::splat(small), Vec4::splat(big));
        let ahead = pick(self.exit_small[axis], self.exit_big[axis]);
        let behind = pick(self.exit_behind_small[axis], self.exit_behind_big[axis]);
        (t_near, later_exit(to_far, ahead, behind, Vec4::max))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::boxes::FAR_OF_NEAR;
    use rtgi_math::{Rng, Vec3};

    /// A coordinate that often lies on a box plane or is zero.
    fn coordinate(rng: &mut Rng) -> f32 {
        match rng.next_u32() % 8 {
            0 => 0.0,
            1 => 1.0,
            2 => -1.0,
            3 => -0.0,
            _ => rng.next_f32() * 8.0 - 4.0,
        }
    }

    /// Sixteen rays with one set of direction signs: directions near a
    /// common one, each component sometimes zero (of the common sign),
    /// origins near a common one and sometimes on a box plane.
    fn packet(rng: &mut Rng) -> Vec<Ray> {
        let base_origin = Vec3::from([0; 3].map(|_| coordinate(rng)));
        let signs = [0; 3].map(|_| rng.next_u32().is_multiple_of(2));
        // An axis the rays nearly lie across: components zero or tiny.
        let across = [0; 3].map(|_| rng.next_u32().is_multiple_of(3));
        let base = [0; 3].map(|_| 0.3 + rng.next_f32());
        let spread = [0.0, 0.01, 0.5][rng.next_u32() as usize % 3];
        let t_min = [0.0, -2.0, 0.5][rng.next_u32() as usize % 3];
        (0..PACKET)
            .map(|_| {
                let direction = Vec3::from([0, 1, 2].map(|axis| {
                    let magnitude = match (across[axis], rng.next_u32() % 2) {
                        (true, 0) => 0.0,
                        (true, _) => rng.next_f32() * 1e-3,
                        (false, _) => base[axis] * (1.0 + 0.02 * rng.next_f32()),
                    };
                    if signs[axis] { -magnitude } else { magnitude }
                }));
                let direction = if direction.abs() == Vec3::ZERO { Vec3::new(0.0, 0.0, 1.0) } else { direction };
                let jitter = Vec3::from([0; 3].map(|_| (rng.next_f32() - 0.5) * spread));
                let origin = if rng.next_u32().is_multiple_of(3) { base_origin } else { base_origin + jitter };
                Ray { t_min, ..Ray::new(origin, direction) }
            })
            .collect()
    }

    #[test]
    fn the_interval_ray_enters_every_box_a_ray_of_its_packet_enters_no_later() {
        let mut rng = Rng::new(31, 4);
        let (mut packets, mut entries) = (0, 0);
        for _ in 0..20_000 {
            let rays = packet(&mut rng);
            let Some(packet) = PacketRays::new(&rays) else { continue };
            packets += 1;
            let interval = IntervalRay::new(&packet);
            let mut boxes = WideBoxes::<8>::EMPTY;
            for lane in 0..8 {
                let a = Vec3::from([0; 3].map(|_| coordinate(&mut rng)));
                let b = Vec3::from([0; 3].map(|_| coordinate(&mut rng)));
                boxes.set(lane, a.min(b).to_array(), a.max(b).to_array());
            }
            let t_max = Lanes(std::array::from_fn(|_| {
                if rng.next_u32().is_multiple_of(2) { f32::INFINITY } else { rng.next_f32() * 6.0 - 1.0 }
            }));
            let (maybe, bounds) = interval.enter_boxes(&boxes, t_max.latest(u32::MAX >> 16));
            for (lane, bound) in bounds.iter().enumerate() {
                let near = [0, 1, 2].map(|axis| boxes.planes[packet.near[axis]][lane]);
                let far = [0, 1, 2].map(|axis| boxes.planes[packet.near[axis] ^ FAR_OF_NEAR[axis]][lane]);
                for (lane_of_ray, ray) in rays.iter().enumerate() {
                    let (entered, enter) = packet.enter_box(near, far, &t_max, 1 << lane_of_ray);
                    if entered != 0 {
                        entries += 1;
                        assert!(maybe >> lane & 1 == 1, "box {lane} entered by {ray:?} but culled");
                        assert!(*bound <= enter, "box {lane}: bound {bound} after the entry {enter} of {ray:?}");
                    }
                }
            }
        }
        assert!(
            packets > 5_000 && entries > 50_000,
            "{packets} packets, {entries} entries: the generator lost its cases"
        );
    }
}
