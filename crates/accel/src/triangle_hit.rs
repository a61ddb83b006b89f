//! What the ray/triangle tests found: [`TriangleHit`], one ray against
//! one triangle, and `LaneHits`, one test of several lanes at once (one ray
//! against a block of four triangles, or one triangle against a packet of
//! sixteen rays).
//!
//! The scalar tests (`triangle.rs`), the hit rule (`contract.rs`) and the
//! SIMD kernels (`simd/triangles.rs`, `simd/packet_triangles.rs`) all speak
//! of these hits, and the scalar tests call the kernels: the types live here,
//! importing none of them, so that the dependencies between those files
//! point one way.

/// Where a ray hits a triangle: distance and barycentric coordinates of
/// the second and third corners (the first corner's is `1 - beta - gamma`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    /// Distance along the ray, in multiples of its direction.
    pub t: f32,
    /// Barycentric coordinate of the second corner.
    pub beta: f32,
    /// Barycentric coordinate of the third corner.
    pub gamma: f32,
}

/// What a test of several lanes found (one ray against a block's four
/// triangles, `simd::triangles::BlockHits`, or one triangle against a
/// packet's sixteen rays, `simd::packet_triangles::PacketHits`): bit `i` of `exact` says that lane `i` was hit,
/// at `t[i]` with barycentrics `beta[i]`, `gamma[i]` ([`LaneHits::hit`]);
/// bit `i` of `rescan` that the scalar test must decide lane `i`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LaneHits<L> {
    pub(crate) exact: u32,
    pub(crate) rescan: u32,
    pub(crate) t: L,
    /// The barycentrics are `beta_scaled / scale` and `gamma_scaled /
    /// scale`, divided only for the lanes that are hit (the watertight
    /// test's scaled barycentrics and determinant; Möller-Trumbore's
    /// barycentrics over 1, which divides exactly).
    pub(crate) beta_scaled: L,
    pub(crate) gamma_scaled: L,
    pub(crate) scale: L,
}

impl<L: std::ops::Index<usize, Output = f32>> LaneHits<L> {
    /// The hit in lane `lane` of [`LaneHits::exact`]: the bits the scalar
    /// test computes for that lane's ray and triangle.
    #[inline(always)]
    pub(crate) fn hit(&self, lane: usize) -> TriangleHit {
        let scale = self.scale[lane];
        TriangleHit { t: self.t[lane], beta: self.beta_scaled[lane] / scale, gamma: self.gamma_scaled[lane] / scale }
    }
}
