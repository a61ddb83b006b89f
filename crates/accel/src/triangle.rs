//! Ray/triangle intersection tests.

use rtgi_math::Vec3A;

use crate::exact;
use crate::simd::arith;
use crate::simd::packet::PacketRays;
use crate::simd::packet_triangles::WatertightPacket;
use crate::simd::triangles::{self, BlockHits, TriangleBlock};
use crate::triangle_hit::TriangleHit;

/// The ray/triangle tests on offer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Intersector {
    /// Watertight: no ray slips through a shared edge or vertex.
    ///
    /// Woop, Benthin and Wald, "Watertight Ray/Triangle Intersection" (JCGT
    /// 2013): a ray through a shared edge or vertex of a closed mesh always
    /// hits at least one of the triangles that share it.
    #[default]
    Watertight,
    /// Möller-Trumbore: rays can slip through shared edges.
    ///
    /// Möller and Trumbore (JGT 1997), the course's Cramer's rule: faster to
    /// write, but rounding lets rays slip through shared edges.
    MollerTrumbore,
    /// The watertight test in double precision.
    ///
    /// The watertight test evaluated in double precision from the same
    /// single-precision inputs, rounding `t`, `beta` and `gamma` to single
    /// precision only at the end: what the extra precision buys in accuracy
    /// and costs in time (`rtgi experiment precision`).
    WatertightF64,
}

impl Intersector {
    /// Every intersector, the default first.
    pub const ALL: &'static [Intersector] =
        &[Intersector::Watertight, Intersector::MollerTrumbore, Intersector::WatertightF64];

    /// The name on command lines and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Intersector::Watertight => "watertight",
            Intersector::MollerTrumbore => "moller-trumbore",
            Intersector::WatertightF64 => "watertight-f64",
        }
    }

    /// Whether a ray through a shared edge or vertex of a closed mesh
    /// always hits one of the triangles sharing it (no leaks).
    pub fn is_watertight(self) -> bool {
        match self {
            Intersector::Watertight | Intersector::WatertightF64 => true,
            Intersector::MollerTrumbore => false,
        }
    }
}

impl rtgi_math::NamedChoice for Intersector {
    const KIND: &'static str = "intersector";
    const ALL: &'static [Self] = Intersector::ALL;
    fn name(self) -> &'static str {
        Intersector::name(self)
    }
}

impl std::fmt::Display for Intersector {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A ray/triangle test with per-ray precomputation, for the structures'
/// inner loops (monomorphised, so the choice costs nothing per triangle).
///
/// `intersect` must compute `t` without looking at `t_max` and then keep
/// the hit exactly when `t_min <= t <= t_max`: structures lower `t_max` to
/// the best hit so far, and that must never turn away a hit that ties it.
pub(crate) trait TriangleTest {
    type Ray;
    fn prepare(origin: Vec3A, direction: Vec3A) -> Self::Ray;
    fn intersect(ray: &Self::Ray, t_min: f32, t_max: f32, v: &[Vec3A; 3]) -> Option<TriangleHit>;

    /// The same test on the four triangles of a block at once: lanes in
    /// [`BlockHits::exact`] hold the bits `intersect` computes for their
    /// triangle, and lanes in [`BlockHits::rescan`] must be decided by
    /// `intersect` itself (the watertight test's double-precision cases).
    fn intersect_block(ray: &Self::Ray, t_min: f32, t_max: f32, block: &TriangleBlock) -> BlockHits;

    /// The rays of a packet prepared to be tested against one triangle at
    /// a time ([`crate::simd::packet_triangles`]), or `None` where the test
    /// has no such kernel or these rays cannot share one: they are then
    /// tested ray by ray.
    #[inline(always)]
    fn packet(_rays: &PacketRays) -> Option<WatertightPacket> {
        None
    }
}

/// Evaluates `$body` with `$test` naming the [`TriangleTest`] that the
/// run-time choice `$intersector` ([`Intersector`]) stands for: the one
/// place where that choice becomes a type, so that the structures' loops
/// are monomorphised for it and a new test is added in one match.
///
/// ```ignore
/// with_triangle_test!(self.intersector, |T| self.scan::<Q, C, T, F>(ray, counter, filter))
/// ```
macro_rules! with_triangle_test {
    ($intersector:expr, |$test:ident| $body:expr) => {
        match $intersector {
            $crate::Intersector::Watertight => {
                type $test = $crate::triangle::Watertight;
                $body
            }
            $crate::Intersector::MollerTrumbore => {
                type $test = $crate::triangle::MollerTrumbore;
                $body
            }
            $crate::Intersector::WatertightF64 => {
                type $test = $crate::triangle::WatertightF64;
                $body
            }
        }
    };
}
pub(crate) use with_triangle_test;

pub(crate) struct MollerTrumbore;

pub(crate) struct MollerTrumboreRay {
    origin: Vec3A,
    direction: Vec3A,
}

impl TriangleTest for MollerTrumbore {
    type Ray = MollerTrumboreRay;

    #[inline(always)]
    fn prepare(origin: Vec3A, direction: Vec3A) -> Self::Ray {
        MollerTrumboreRay { origin, direction }
    }

    /// Solves `o + t d = v0 + beta (v1 - v0) + gamma (v2 - v0)` by Cramer's rule.
    #[inline(always)]
    fn intersect(ray: &Self::Ray, t_min: f32, t_max: f32, v: &[Vec3A; 3]) -> Option<TriangleHit> {
        let [det, beta, gamma, t] =
            arith::moller_trumbore(ray.origin.to_array(), ray.direction.to_array(), v.map(|corner| corner.to_array()));
        if det == 0.0 || !det.is_finite() || !(0.0..=1.0).contains(&beta) || gamma < 0.0 || beta + gamma > 1.0 {
            return None;
        }
        (t >= t_min && t <= t_max && t.is_finite()).then_some(TriangleHit { t, beta, gamma })
    }

    #[inline(always)]
    fn intersect_block(ray: &Self::Ray, t_min: f32, t_max: f32, block: &TriangleBlock) -> BlockHits {
        triangles::moller_trumbore_block(ray.origin.to_array(), ray.direction.to_array(), t_min, t_max, block)
    }
}

pub(crate) struct Watertight;

/// The ray in the watertight test's frame: the axis where the direction is
/// largest becomes z, and a shear maps the direction onto +z.
pub(crate) struct WatertightRay {
    pub(crate) origin: Vec3A,
    /// The direction as given, for the exact signs of edges near the ray.
    pub(crate) direction: Vec3A,
    /// Source axes of the permuted x, y and z.
    pub(crate) axes: [usize; 3],
    pub(crate) shear: [f32; 3],
}

impl TriangleTest for Watertight {
    type Ray = WatertightRay;

    /// The axes of [`arith::watertight_axes`] and the shear that maps the
    /// direction onto +z.
    #[inline(always)]
    fn prepare(origin: Vec3A, direction: Vec3A) -> Self::Ray {
        let d = direction.to_array();
        let [kx, ky, kz] = arith::watertight_axes(d);
        WatertightRay { origin, direction, axes: [kx, ky, kz], shear: [d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]] }
    }

    #[inline(always)]
    fn intersect(ray: &Self::Ray, t_min: f32, t_max: f32, v: &[Vec3A; 3]) -> Option<TriangleHit> {
        let [kx, ky, kz] = ray.axes;
        // The corners relative to the origin, permuted. Every corner goes
        // through the same arithmetic whichever triangle it belongs to, so
        // neighbours see the same transformed edge.
        let relative = v.map(|corner| {
            let r = (corner - ray.origin).to_array();
            [r[kx], r[ky], r[kz]]
        });
        let [xs, ys, zs] = arith::watertight_shear(relative, ray.shear);
        let uvw = arith::watertight_edges(xs, ys);
        // Near an edge, rounding may have given an edge function the wrong
        // sign; neighbours would still agree, but the hit could fall outside
        // the triangle's box and be lost to the box rule. Decide those exactly.
        let bound = arith::watertight_edge_bound(xs, ys, relative.map(|r| r[2]), ray.shear);
        if uvw.iter().any(|e| e.abs() <= bound) {
            return exact_hit(ray, t_min, t_max, v, uvw, bound);
        }
        if uvw.iter().any(|&e| e < 0.0) && uvw.iter().any(|&e| e > 0.0) {
            return None;
        }
        let (det, t_scaled) = arith::watertight_det_and_scaled_t(uvw, zs);
        if t_scaled.abs() <= arith::watertight_t_bound(det, zs, bound) {
            return exact_hit(ray, t_min, t_max, v, uvw, bound);
        }
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        // The distance is computed in full before it is compared with the
        // range (see `TriangleTest`): comparing the scaled distance with the
        // scaled range first would round differently for different `t_max`.
        let t = t_scaled / det;
        if !(t >= t_min && t <= t_max && t.is_finite()) {
            return None;
        }
        Some(TriangleHit { t, beta: uvw[1] / det, gamma: uvw[2] / det })
    }

    #[inline(always)]
    fn intersect_block(ray: &Self::Ray, t_min: f32, t_max: f32, block: &TriangleBlock) -> BlockHits {
        triangles::watertight_block(ray.origin.to_array(), ray.axes, ray.shear, t_min, t_max, block)
    }

    /// Packets whose rays share the permutation of axes.
    #[inline(always)]
    fn packet(rays: &PacketRays) -> Option<WatertightPacket> {
        WatertightPacket::of_packet(rays)
    }
}

pub(crate) struct WatertightF64;

/// [`WatertightRay`] in double precision: the same axes, the shear
/// computed in f64 from the single-precision direction.
pub(crate) struct WatertightF64Ray {
    origin: [f64; 3],
    axes: [usize; 3],
    shear: [f64; 3],
}

impl TriangleTest for WatertightF64 {
    type Ray = WatertightF64Ray;

    /// The axes of [`Watertight::prepare`] (they depend only on signs and
    /// magnitudes, not on rounding), the shear in double precision.
    #[inline(always)]
    fn prepare(origin: Vec3A, direction: Vec3A) -> Self::Ray {
        let axes = Watertight::prepare(origin, direction).axes;
        let [kx, ky, kz] = axes;
        let d = direction.to_array().map(f64::from);
        WatertightF64Ray {
            origin: origin.to_array().map(f64::from),
            axes,
            shear: [d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]],
        }
    }

    /// Section 3 of Woop et al. in f64. Each corner still goes through
    /// arithmetic that depends on the corner alone, so neighbours compute
    /// exactly negated edge functions and the test stays watertight
    /// without the single-precision test's fallback for exact zeros.
    #[inline(always)]
    fn intersect(ray: &Self::Ray, t_min: f32, t_max: f32, v: &[Vec3A; 3]) -> Option<TriangleHit> {
        let [kx, ky, kz] = ray.axes;
        let [sx, sy, sz] = ray.shear;
        let sheared = v.map(|corner| {
            let c = corner.to_array().map(f64::from);
            let r = [c[kx] - ray.origin[kx], c[ky] - ray.origin[ky], c[kz] - ray.origin[kz]];
            [r[0] - sx * r[2], r[1] - sy * r[2], r[2] * sz]
        });
        let (xs, ys, zs) = (sheared.map(|c| c[0]), sheared.map(|c| c[1]), sheared.map(|c| c[2]));
        let uvw = [xs[2] * ys[1] - ys[2] * xs[1], xs[0] * ys[2] - ys[0] * xs[2], xs[1] * ys[0] - ys[1] * xs[0]];
        if uvw.iter().any(|&e| e < 0.0) && uvw.iter().any(|&e| e > 0.0) {
            return None;
        }
        let det = (uvw[0] + uvw[1]) + uvw[2];
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let t_scaled = (uvw[0] * zs[0] + uvw[1] * zs[1]) + uvw[2] * zs[2];
        // Rounded to single precision before the range check, as the
        // structures compare the `t` they report (see `TriangleTest`).
        let t = (t_scaled / det) as f32;
        if !(t >= t_min && t <= t_max && t.is_finite()) {
            return None;
        }
        Some(TriangleHit { t, beta: (uvw[1] / det) as f32, gamma: (uvw[2] / det) as f32 })
    }

    /// No four-lane f64 kernel: every lane goes back to the scalar test, so
    /// the wide BVHs report its bits; the f32 tests' blocks are untouched.
    #[inline(always)]
    fn intersect_block(_ray: &Self::Ray, _t_min: f32, _t_max: f32, block: &TriangleBlock) -> BlockHits {
        BlockHits::scalar_only(block)
    }
}

/// The watertight test where an edge function is within rounding of zero:
/// each such edge's sign is decided exactly ([`exact::edge_sign`]), the
/// others keep the sign single precision gave them (certain, being above
/// `bound`). A ray exactly through an edge or corner hits (zero counts as
/// inside), so the test stays watertight, and every hit it reports is a
/// hit of the exact ray, inside the triangle's box. The distance comes
/// from the triangle's plane and the barycentrics from the edge functions
/// in double precision, with the decided signs.
#[inline(never)]
fn exact_hit(
    ray: &WatertightRay,
    t_min: f32,
    t_max: f32,
    v: &[Vec3A; 3],
    uvw: [f32; 3],
    bound: f32,
) -> Option<TriangleHit> {
    let (o, d) = (ray.origin, ray.direction);
    let edges = [(2, 1), (0, 2), (1, 0)];
    // Everything that rejects the hit whatever the uncertain signs turn out
    // to be comes first, as the exact signs are the costly part: two
    // certain signs that differ, a degenerate or non-finite plane (most
    // degenerate triangles of scanned meshes end here), a distance out of
    // range.
    let certain = uvw.map(|value| if value.abs() > bound { value.signum() as i32 } else { 0 });
    if certain.contains(&1) && certain.contains(&-1) {
        return None;
    }
    let corners = v.map(|corner| corner.as_dvec3());
    let [a, b, c] = corners;
    let (origin, direction) = (o.as_dvec3(), d.as_dvec3());
    let normal = (b - a).cross(c - a);
    let along = direction.dot(normal);
    if along == 0.0 || !along.is_finite() {
        return None;
    }
    let t = ((a - origin).dot(normal) / along) as f32;
    if !(t >= t_min && t <= t_max && t.is_finite()) {
        return None;
    }
    let mut signs = certain;
    for (i, &(p, q)) in edges.iter().enumerate() {
        if certain[i] != 0 {
            continue;
        }
        signs[i] = exact::edge_sign(v[p], v[q], o, d);
        if signs.contains(&1) && signs.contains(&-1) {
            return None;
        }
    }
    if signs == [0; 3] {
        return None;
    }
    let facing = if signs.contains(&1) { 1.0 } else { -1.0 };
    // Barycentrics: the edge functions' magnitudes in double precision
    // (the signed volumes over the ray), zero where the sign is.
    let weights: [f64; 3] = std::array::from_fn(|i| {
        let (p, q) = edges[i];
        let (p, q) = (corners[p] - origin, corners[q] - origin);
        if signs[i] == 0 { 0.0 } else { (p.cross(q).dot(direction) * facing).max(0.0) }
    });
    let total = weights[0] + weights[1] + weights[2];
    let (beta, gamma) = if total > 0.0 && total.is_finite() {
        ((weights[1] / total) as f32, (weights[2] / total) as f32)
    } else {
        // Every magnitude rounded away: the corners whose edges are not zero share the hit.
        let nonzero = signs.map(|s| (s != 0) as u32 as f32);
        let count = nonzero.iter().sum::<f32>();
        (nonzero[1] / count, nonzero[2] / count)
    };
    Some(TriangleHit { t, beta, gamma })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rtgi_math::Vec3;

    const TRI: [Vec3; 3] = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];

    /// Within a few units in the last place: the tests compute t and the
    /// barycentrics by different formulas, each rounded differently.
    fn close(a: f32, b: f32) -> bool {
        (a - b).abs() <= 4.0 * f32::EPSILON * a.abs().max(b.abs()).max(1.0)
    }

    #[test]
    fn barycentrics_reproduce_the_hit_point() {
        for test in Intersector::ALL {
            let o = Vec3::new(0.25, 0.5, -2.0);
            let hit = test.intersect(o, Vec3::Z, 0.0, f32::INFINITY, &TRI).unwrap();
            assert!(close(hit.t, 2.0) && close(hit.beta, 0.25) && close(hit.gamma, 0.5), "{test}: {hit:?}");
        }
    }

    #[test]
    fn both_sides_hit_and_range_respected() {
        for test in Intersector::ALL {
            let o = Vec3::new(0.2, 0.2, 3.0);
            assert!(close(test.intersect(o, -Vec3::Z, 0.0, 10.0, &TRI).unwrap().t, 3.0), "{test}");
            assert!(test.intersect(o, -Vec3::Z, 0.0, 2.9, &TRI).is_none(), "{test}");
            assert!(test.intersect(o, -Vec3::Z, 3.1, 9.0, &TRI).is_none(), "{test}");
            assert!(test.intersect(o, Vec3::Z, 0.0, 10.0, &TRI).is_none(), "{test}");
            // A reversed triangle (the other winding) is hit the same way.
            let reversed = [TRI[0], TRI[2], TRI[1]];
            let hit = test.intersect(o, -Vec3::Z, 0.0, 10.0, &reversed).unwrap();
            assert!(close(hit.t, 3.0) && close(hit.beta, 0.2) && close(hit.gamma, 0.2), "{test}: {hit:?}");
        }
    }

    #[test]
    fn misses_outside_degenerate_and_in_plane() {
        for test in Intersector::ALL {
            assert!(test.intersect(Vec3::new(0.8, 0.8, -1.0), Vec3::Z, 0.0, 9.0, &TRI).is_none());
            let line = [Vec3::ZERO, Vec3::X, 2.0 * Vec3::X];
            assert!(test.intersect(Vec3::new(0.5, 0.0, -1.0), Vec3::Z, 0.0, 9.0, &line).is_none(), "{test}");
            assert!(test.intersect(Vec3::new(-1.0, 0.2, 0.0), Vec3::X, 0.0, 9.0, &TRI).is_none(), "{test}");
        }
    }

    #[test]
    fn watertight_counts_edges_and_vertices_as_inside() {
        for w in Intersector::ALL.iter().filter(|i| i.is_watertight()) {
            // On the hypotenuse, on a leg and on a corner.
            for p in [Vec3::new(0.5, 0.5, -1.0), Vec3::new(0.5, 0.0, -1.0), Vec3::new(0.0, 0.0, -1.0)] {
                assert!(w.intersect(p, Vec3::Z, 0.0, 9.0, &TRI).is_some(), "{w}: {p}");
            }
        }
    }

    #[test]
    fn every_direction_axis_and_sign() {
        // The test permutes axes by the largest direction component; try each.
        for axis in 0..3 {
            for sign in [1.0f32, -1.0] {
                let mut d = [0.1f32, 0.2, 0.15];
                d[axis] = sign;
                let d = Vec3::from(d);
                // A big triangle across the ray, 5 units ahead.
                let centre = 5.0 * d;
                let frame = rtgi_math::Frame::from_z(d.normalize());
                let tri = [centre + frame.x * 3.0, centre + frame.y * 3.0, centre - (frame.x + frame.y) * 3.0];
                for test in Intersector::ALL {
                    let hit = test.intersect(Vec3::ZERO, d, 0.0, f32::INFINITY, &tri).unwrap();
                    assert!((hit.t - 5.0).abs() < 1e-5, "{test} axis {axis} sign {sign}: {}", hit.t);
                }
            }
        }
    }

    #[test]
    fn edge_functions_above_their_bound_have_the_exact_sign() {
        // Triangles at offsets up to 2^23 and scales down to 2^-20, rays from
        // nearby in every direction, many nearly along an edge: wherever the
        // single-precision edge function is trusted (above its bound), its
        // sign is the exact one; the rest are decided exactly.
        let mut rng = rtgi_math::Rng::new(3, 0);
        let mut next = || rng.next_f32() * 2.0 - 1.0;
        let (mut trusted, mut decided) = (0u32, 0u32);
        for case in 0..40_000 {
            let offset = Vec3::splat(2f32.powi(case % 24)) * Vec3::new(next(), next(), next());
            let scale = 2f32.powi((case % 11) * 3 - 20).max(offset.abs().max_element() * 1e-4);
            let v = [0; 3].map(|_| Vec3A::from(offset + Vec3::new(next(), next(), next()) * scale));
            let origin = Vec3A::from(offset + Vec3::new(next(), next(), next()) * scale * 4.0);
            let toward = if case % 2 == 0 { v[case as usize % 3] } else { (v[0] + v[1]) * 0.5 };
            let direction = (toward - origin) + Vec3A::new(next(), next(), next()) * scale * 1e-3;
            if direction.abs().max_element() == 0.0 {
                continue;
            }
            let ray = Watertight::prepare(origin, direction);
            let [kx, ky, kz] = ray.axes;
            let relative = v.map(|corner| {
                let r = (corner - ray.origin).to_array();
                [r[kx], r[ky], r[kz]]
            });
            let [xs, ys, _] = arith::watertight_shear(relative, ray.shear);
            let uvw = arith::watertight_edges(xs, ys);
            let bound = arith::watertight_edge_bound(xs, ys, relative.map(|r| r[2]), ray.shear);
            for (i, (p, q)) in [(2, 1), (0, 2), (1, 0)].into_iter().enumerate() {
                let exact = exact::edge_sign(v[p], v[q], origin, direction);
                if uvw[i].abs() > bound {
                    trusted += 1;
                    assert_eq!(uvw[i].signum() as i32, exact, "case {case}, edge {i}: {} (bound {bound})", uvw[i]);
                } else {
                    decided += 1;
                }
            }
        }
        assert!(trusted > 100_000 && decided > 100, "trusted {trusted}, decided exactly {decided}");
    }
}
