use rtgi_math::{Vec3, Vec3A};

/// Where a ray hits a triangle: distance and barycentric coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    pub t: f32,
    pub beta: f32,
    pub gamma: f32,
}

/// Ray/triangle intersection by Cramer's rule, as in the course and in
/// Möller and Trumbore, "Fast, Minimum Storage Ray/Triangle Intersection"
/// (JGT 1997): solve `o + t d = v0 + beta (v1 - v0) + gamma (v2 - v0)`.
///
/// Returns the hit if `t` lies in `[t_min, t_max]` and the point is inside
/// the triangle, edges included. Both sides of the triangle are hit.
/// Degenerate triangles (zero determinant) and rays in the triangle's plane
/// are never hit.
#[inline]
pub fn intersect_triangle(origin: Vec3, direction: Vec3, t_min: f32, t_max: f32, v: &[Vec3; 3]) -> Option<TriangleHit> {
    moller_trumbore(origin.into(), direction.into(), t_min, t_max, &v.map(Vec3A::from))
}

/// [`intersect_triangle`] on SIMD vectors, as the structures store them.
#[inline(always)]
pub(crate) fn moller_trumbore(
    origin: Vec3A,
    direction: Vec3A,
    t_min: f32,
    t_max: f32,
    v: &[Vec3A; 3],
) -> Option<TriangleHit> {
    let edge1 = v[1] - v[0];
    let edge2 = v[2] - v[0];
    let p = direction.cross(edge2);
    let det = edge1.dot(p);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv_det = 1.0 / det;
    let s = origin - v[0];
    let beta = s.dot(p) * inv_det;
    if !(0.0..=1.0).contains(&beta) {
        return None;
    }
    let q = s.cross(edge1);
    let gamma = direction.dot(q) * inv_det;
    if gamma < 0.0 || beta + gamma > 1.0 {
        return None;
    }
    let t = edge2.dot(q) * inv_det;
    (t >= t_min && t <= t_max).then_some(TriangleHit { t, beta, gamma })
}

#[cfg(test)]
mod tests {
    use super::*;

    const TRI: [Vec3; 3] = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];

    #[test]
    fn barycentrics_reproduce_the_hit_point() {
        let o = Vec3::new(0.25, 0.5, -2.0);
        let hit = intersect_triangle(o, Vec3::Z, 0.0, f32::INFINITY, &TRI).unwrap();
        assert_eq!(hit.t, 2.0);
        let p = (1.0 - hit.beta - hit.gamma) * TRI[0] + hit.beta * TRI[1] + hit.gamma * TRI[2];
        assert!((p - (o + hit.t * Vec3::Z)).length() < 1e-6);
        assert_eq!((hit.beta, hit.gamma), (0.25, 0.5));
    }

    #[test]
    fn both_sides_hit_and_range_respected() {
        let from_above = intersect_triangle(Vec3::new(0.2, 0.2, 3.0), -Vec3::Z, 0.0, 10.0, &TRI);
        assert_eq!(from_above.map(|h| h.t), Some(3.0));
        assert!(intersect_triangle(Vec3::new(0.2, 0.2, 3.0), -Vec3::Z, 0.0, 2.9, &TRI).is_none());
        assert!(intersect_triangle(Vec3::new(0.2, 0.2, 3.0), -Vec3::Z, 3.1, 9.0, &TRI).is_none());
        assert!(intersect_triangle(Vec3::new(0.2, 0.2, 3.0), Vec3::Z, 0.0, 10.0, &TRI).is_none());
    }

    #[test]
    fn misses_outside_and_degenerate() {
        assert!(intersect_triangle(Vec3::new(0.8, 0.8, -1.0), Vec3::Z, 0.0, 9.0, &TRI).is_none());
        let line = [Vec3::ZERO, Vec3::X, 2.0 * Vec3::X];
        assert!(intersect_triangle(Vec3::new(0.5, 0.0, -1.0), Vec3::Z, 0.0, 9.0, &line).is_none());
        // In the triangle's plane.
        assert!(intersect_triangle(Vec3::new(-1.0, 0.2, 0.0), Vec3::X, 0.0, 9.0, &TRI).is_none());
    }
}
