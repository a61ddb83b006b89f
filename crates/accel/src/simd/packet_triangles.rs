//! One triangle against the sixteen rays of a packet at once.
//!
//! Where a packet's rays reach a leaf together, the watertight test of one
//! triangle against all sixteen takes one 512-bit instruction per step,
//! where testing each ray against the leaf's blocks of four triangles
//! takes a 128-bit one per step for each ray and block. Each lane
//! evaluates the expressions of [`arith`](super::arith) that the scalar
//! test evaluates, in the same order, so it computes the bits the scalar
//! test computes for its ray.
//!
//! The test permutes the axes so that the direction's largest component
//! becomes z. A packet whose rays share that permutation (those of a
//! camera tile nearly always do) is tested this way; the others go ray by
//! ray. The AVX-512 kernel is in `dispatch.rs`;
//! [`WatertightPacket::intersect_portable`] is its twin in plain Rust, lane
//! by lane, which the tests hold it to.

use rtgi_math::Vec4;

use super::arith;
use super::packet::{Lanes, PACKET, PacketRays};
use crate::triangle_hit::LaneHits;

/// What one triangle against a packet's sixteen rays found.
pub(crate) type PacketHits = LaneHits<Lanes>;

/// The rays of a packet prepared for [`Watertight`](crate::triangle::Watertight) against one triangle
/// at a time: they share the permutation of axes, and each lane holds its
/// ray's permuted origin, shear and `t_min`, as `Watertight::prepare`
/// computes them. Lanes past the end repeat the first ray (the traversal
/// drops their answers).
#[derive(Clone, Copy, Debug)]
pub(crate) struct WatertightPacket {
    pub(crate) axes: [usize; 3],
    pub(crate) origin: [Lanes; 3],
    pub(crate) shear: [Lanes; 3],
    pub(crate) t_min: Lanes,
}

impl WatertightPacket {
    /// The rays of `rays` prepared, or `None` when their permutations of
    /// axes differ: [`WatertightPacket::new`]'s packet, from the
    /// structure-of-arrays lanes the packet has already (a scalar loop over
    /// the rays took 6% of the packets' time on the bunny's camera rays).
    /// The rays of a packet are valid and share their direction signs, so
    /// the permutations agree where the largest components' axes do.
    #[inline(always)]
    pub(crate) fn of_packet(rays: &PacketRays) -> Option<Self> {
        let axes = arith::watertight_axes([0, 1, 2].map(|k| rays.direction[k].0[0]));
        for chunk in 0..PACKET / 4 {
            let a = [0, 1, 2].map(|k| rays.direction[k].chunk(chunk).abs());
            // `arith::watertight_axes`'s choice of `kz`, four lanes at a time.
            let x_largest = a[0].cmpge(a[1]) & a[0].cmpge(a[2]);
            let y_over_z = a[1].cmpge(a[2]);
            let chose = match axes[2] {
                0 => x_largest,
                1 => !x_largest & y_over_z,
                _ => !(x_largest | y_over_z),
            };
            if !chose.all() {
                return None;
            }
        }
        let direction = axes.map(|k| rays.direction[k]);
        let mut packet = WatertightPacket {
            axes,
            origin: axes.map(|k| rays.origin[k]),
            shear: [Lanes([0.0; PACKET]); 3],
            t_min: rays.t_min,
        };
        packet.set_shears(&direction);
        Some(packet)
    }

    /// The shears of the permuted directions `direction`, four lanes at a
    /// time, as `Watertight::prepare` divides them one by one.
    #[inline(always)]
    fn set_shears(&mut self, direction: &[Lanes; 3]) {
        for chunk in 0..PACKET / 4 {
            let lanes = chunk * 4..chunk * 4 + 4;
            let (dx, dy, dz) = (direction[0].chunk(chunk), direction[1].chunk(chunk), direction[2].chunk(chunk));
            (dx / dz).write_to_slice(&mut self.shear[0].0[lanes.clone()]);
            (dy / dz).write_to_slice(&mut self.shear[1].0[lanes.clone()]);
            (Vec4::ONE / dz).write_to_slice(&mut self.shear[2].0[lanes]);
        }
    }

    /// The packet of `rays` (1 to [`PACKET`] valid rays), or `None` when
    /// their permutations of axes differ, ray by ray: the reference the
    /// tests hold [`WatertightPacket::of_packet`] to.
    #[cfg(test)]
    pub(crate) fn new(rays: &[rtgi_math::Ray]) -> Option<Self> {
        debug_assert!(!rays.is_empty() && rays.len() <= PACKET);
        let axes = arith::watertight_axes(rays[0].direction.to_array());
        let mut packet = WatertightPacket {
            axes,
            origin: [Lanes([0.0; PACKET]); 3],
            shear: [Lanes([0.0; PACKET]); 3],
            t_min: Lanes([0.0; PACKET]),
        };
        // The permuted directions, until they become shears.
        let mut direction = [Lanes([0.0; PACKET]); 3];
        for lane in 0..PACKET {
            let ray = rays.get(lane).unwrap_or(&rays[0]);
            let [kx, ky, kz] = arith::watertight_axes(ray.direction.to_array());
            if kx != axes[0] || ky != axes[1] || kz != axes[2] {
                return None;
            }
            for k in 0..3 {
                packet.origin[k].0[lane] = ray.origin[axes[k]];
                direction[k].0[lane] = ray.direction[axes[k]];
            }
            packet.t_min.0[lane] = ray.t_min;
        }
        packet.set_shears(&direction);
        Some(packet)
    }

    /// The triangle `corners` (on the original axes) against every ray,
    /// each with its own `t_max`, lane by lane with the scalar test's
    /// arithmetic: lanes in `exact` hold the bits
    /// `Watertight::intersect` computes for their ray, and lanes in
    /// `rescan` are those it decides in exact arithmetic.
    pub(crate) fn intersect_portable(&self, t_max: &Lanes, corners: [[f32; 3]; 3]) -> PacketHits {
        let mut hits = PacketHits {
            exact: 0,
            rescan: 0,
            t: Lanes([0.0; PACKET]),
            beta_scaled: Lanes([0.0; PACKET]),
            gamma_scaled: Lanes([0.0; PACKET]),
            scale: Lanes([1.0; PACKET]),
        };
        for lane in 0..PACKET {
            let origin = [0, 1, 2].map(|k| self.origin[k].0[lane]);
            let shear = [0, 1, 2].map(|k| self.shear[k].0[lane]);
            let relative = corners.map(|corner| [0, 1, 2].map(|k| corner[self.axes[k]] - origin[k]));
            let [xs, ys, zs] = arith::watertight_shear(relative, shear);
            let uvw = arith::watertight_edges(xs, ys);
            let bound = arith::watertight_edge_bound(xs, ys, relative.map(|r| r[2]), shear);
            let near_edge = uvw.iter().any(|e| e.abs() <= bound);
            let one_sided = !(uvw.iter().any(|&e| e < 0.0) && uvw.iter().any(|&e| e > 0.0));
            let (det, t_scaled) = arith::watertight_det_and_scaled_t(uvw, zs);
            let cancels = one_sided && t_scaled.abs() <= arith::watertight_t_bound(det, zs, bound);
            let t = t_scaled / det;
            let in_range = t >= self.t_min.0[lane] && t <= t_max.0[lane] && t.is_finite();
            let hit = one_sided && det != 0.0 && det.is_finite() && in_range;
            let rescan = near_edge || cancels;
            hits.rescan |= (rescan as u32) << lane;
            hits.exact |= ((hit && !rescan) as u32) << lane;
            (hits.t.0[lane], hits.beta_scaled.0[lane], hits.gamma_scaled.0[lane], hits.scale.0[lane]) =
                (t, uvw[1], uvw[2], det);
        }
        hits
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::{Isa, Kernel, SimdLevel, dispatch, limit_simd_level};
    use crate::triangle::{TriangleTest, Watertight};
    use rtgi_math::Vec3A;
    use rtgi_math::{Ray, Rng, Vec3};

    /// One triangle against a packet at the active level.
    struct Test<'a> {
        packet: &'a WatertightPacket,
        t_max: &'a Lanes,
        corners: [[f32; 3]; 3],
    }

    impl Kernel for Test<'_> {
        type Output = PacketHits;

        #[inline(always)]
        fn run<I: Isa>(self, isa: I) -> PacketHits {
            isa.watertight_packet(self.packet, self.t_max, self.corners)
        }
    }

    /// Packets aimed at the corners and edges of a fan of triangles that
    /// share them, at offsets 2^0 … 2^23 and scales 2^-12 … 2^12, some
    /// rays exactly through a shared corner or the middle of a shared edge:
    /// at every SIMD level the CPU has, each lane the packet test decides
    /// holds the scalar test's bits, and the kernels agree bit for bit.
    #[test]
    fn every_lane_is_the_scalar_test_on_its_ray_at_every_level() {
        let detected = SimdLevel::detected();
        let mut rng = Rng::new(57, 3);
        let mut next = || rng.next_f32() * 2.0 - 1.0;
        let (mut exact, mut rescans, mut misses, mut packets, mut coherent) = (0, 0, 0, 0, 0);
        for case in 0..3000 {
            let offset = Vec3::splat(2f32.powi(case % 24)) * Vec3::new(next(), next(), next());
            let scale = 2f32.powi((case % 9) * 3 - 12).max(offset.abs().max_element() * 1e-4);
            let centre = offset;
            // A fan of four triangles round `centre`, sharing it and their sides.
            let rim: Vec<Vec3> = (0..4).map(|_| offset + Vec3::new(next(), next(), next()) * scale).collect();
            let fan: Vec<[Vec3; 3]> = (0..4).map(|i| [centre, rim[i], rim[(i + 1) % 4]]).collect();
            let eye = offset + Vec3::new(next(), next(), next()) * scale * 4.0 + Vec3::splat(scale * 3.0);
            let rays: Vec<Ray> = (0..PACKET)
                .map(|lane| {
                    let target = match lane % 4 {
                        0 => centre,
                        1 => (centre + rim[lane % 3]) * 0.5,
                        _ => centre + Vec3::new(next(), next(), next()) * scale * 0.3,
                    };
                    let t_min = if lane % 5 == 0 { 0.5 } else { 0.0 };
                    Ray { t_min, ..Ray::new(eye, target - eye) }
                })
                .collect();
            let Some(packet) = WatertightPacket::new(&rays) else { continue };
            packets += 1;
            if let Some(rays) = PacketRays::new(&rays) {
                let of_packet = WatertightPacket::of_packet(&rays).expect("the same permutation as ray by ray");
                let bits = |p: &WatertightPacket| {
                    let lanes = |l: &[Lanes; 3]| l.map(|l| l.0.map(f32::to_bits));
                    (p.axes, lanes(&p.origin), lanes(&p.shear), p.t_min.0.map(f32::to_bits))
                };
                assert_eq!(bits(&of_packet), bits(&packet), "case {case}");
                coherent += 1;
            }
            let t_max = Lanes(std::array::from_fn(|lane| if lane % 3 == 0 { 1.0 } else { f32::INFINITY }));
            for triangle in &fan {
                let corners = triangle.map(|c| c.to_array());
                let portable = packet.intersect_portable(&t_max, corners);
                for (lane, ray) in rays.iter().enumerate() {
                    let prepared = Watertight::prepare(Vec3A::from(ray.origin), Vec3A::from(ray.direction));
                    let scalar = Watertight::intersect(&prepared, ray.t_min, t_max.0[lane], &triangle.map(Vec3A::from));
                    if portable.rescan >> lane & 1 == 1 {
                        rescans += 1;
                    } else if portable.exact >> lane & 1 == 1 {
                        exact += 1;
                        let hit = portable.hit(lane);
                        let scalar = scalar.expect("the packet's hit is the scalar test's");
                        assert_eq!(
                            [hit.t, hit.beta, hit.gamma].map(f32::to_bits),
                            [scalar.t, scalar.beta, scalar.gamma].map(f32::to_bits),
                            "case {case}, lane {lane}"
                        );
                    } else {
                        misses += 1;
                        assert_eq!(scalar, None, "case {case}, lane {lane}: the packet missed");
                    }
                }
                for &level in SimdLevel::ALL.iter().filter(|&&level| level <= detected) {
                    limit_simd_level(level);
                    let ours = dispatch(Test { packet: &packet, t_max: &t_max, corners });
                    assert_eq!((ours.exact, ours.rescan), (portable.exact, portable.rescan), "{level}, case {case}");
                    for lane in 0..PACKET {
                        if ours.exact >> lane & 1 == 1 {
                            let (a, b) = (ours.hit(lane), portable.hit(lane));
                            assert_eq!(
                                [a.t, a.beta, a.gamma].map(f32::to_bits),
                                [b.t, b.beta, b.gamma].map(f32::to_bits),
                                "{level}, case {case}, lane {lane}"
                            );
                        }
                    }
                }
                limit_simd_level(detected);
            }
        }
        assert!(
            packets > 2000 && coherent > 1000 && exact > 10_000 && rescans > 1000 && misses > 20_000,
            "{packets} packets ({coherent} coherent): {exact} hits, {rescans} decided exactly, {misses} misses: the generator lost its cases"
        );
    }
}
