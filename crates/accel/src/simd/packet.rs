//! The rays of a packet, structure-of-arrays, and the one test they take
//! together: which of them enter a box. The packet traversal
//! (`wide/packet.rs`) walks a wide BVH with them; the box test has an
//! intrinsic twin in `dispatch.rs`.

use rtgi_math::{Ray, Vec4};

use crate::slab::later_exit;

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
                let t_far = later_exit((Vec4::splat(far[axis]) - origin) * inv, Vec4::max);
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
