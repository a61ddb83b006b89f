//! Shading normals that agree with the view.
//!
//! An interpolated (or normal-mapped) normal can face away from a viewer
//! who sees the true surface from its front: near the silhouette of a
//! low-poly smooth mesh the facet faces the camera while the normals of
//! its corners lean past it. The viewing direction then lies below the
//! shading hemisphere, every BSDF in the shading frame answers zero, and
//! the silhouette gets a black fringe. Production renderers bend the
//! normal back (Blender's Cycles in `ensure_valid_reflection`, Iray, see
//! Keller et al., "The Iray Light Transport Simulation and Rendering
//! System", 2017): just far enough that the mirror direction of the view
//! stays above the true surface. This is the same idea, derived as a
//! half-vector: the bent normal is halfway between the view and the
//! mirror direction lifted to just above the surface.

use rtgi_math::Vec3;

/// The shading normal `shading`, bent towards the geometric normal
/// `geometric` (both unit, on the same side) where the view `wo` (unit,
/// towards the viewer, on the geometric normal's side) would be mirrored
/// below the true surface, or less than a small angle above it.
///
/// Unchanged where the mirror direction is above that bound: flat
/// triangles, whose shading normal is the geometric one, keep their bits.
/// The result faces the viewer (`wo · n > 0`).
///
/// Always inlined: called once per bounce, and called out of line its
/// vectors went through memory (as `offset_ray_origin`'s did); inlined with
/// `EmissiveTriangle::radiance`, a Cornell box render took 2.5% less time,
/// with the same bits.
#[inline(always)]
pub(crate) fn bent_towards_view(shading: Vec3, geometric: Vec3, wo: Vec3) -> Vec3 {
    let cos_view = wo.dot(geometric);
    // The lowest the mirror direction may go: 0.01 above the surface, or
    // nine tenths of the view's own height at grazing views.
    let floor = (0.9 * cos_view).min(0.01);
    let mirrored = 2.0 * shading.dot(wo) * shading - wo;
    if mirrored.dot(geometric) >= floor {
        return shading;
    }
    // The mirror direction lifted: its direction along the surface kept,
    // its height set to the floor.
    let along = mirrored - mirrored.dot(geometric) * geometric;
    let along = along.try_normalize().or_else(|| (wo - cos_view * geometric).try_normalize());
    let Some(along) = along else {
        // The view is along the geometric normal: it is its own mirror.
        return geometric;
    };
    let lifted = along * (1.0 - floor * floor).max(0.0).sqrt() + geometric * floor;
    // The mirror of `wo` about the half-vector of `wo` and `lifted` is `lifted`.
    (wo + lifted).try_normalize().unwrap_or(geometric)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mirror(n: Vec3, wo: Vec3) -> Vec3 {
        2.0 * n.dot(wo) * n - wo
    }

    #[test]
    fn a_normal_the_view_agrees_with_is_kept_bit_for_bit() {
        let geometric = Vec3::Z;
        let wo = Vec3::new(0.3, 0.1, 0.9).normalize();
        assert_eq!(bent_towards_view(geometric, geometric, wo), geometric);
        let leaning = Vec3::new(0.2, 0.0, 1.0).normalize();
        assert_eq!(bent_towards_view(leaning, geometric, wo), leaning);
    }

    #[test]
    fn a_normal_facing_away_from_the_view_is_bent_until_the_mirror_is_above_the_surface() {
        let geometric = Vec3::Z;
        let mut rng = rtgi_math::Rng::new(5, 0);
        for _ in 0..10_000 {
            let mut next = || rng.next_f32() * 2.0 - 1.0;
            // Views above the surface, grazing ones included; shading
            // normals leaning up to 80 degrees away from the geometric one.
            let wo = Vec3::new(next(), next(), next().abs() * 0.5 + 1e-3).normalize();
            let shading = (Vec3::new(next(), next(), 0.0) * 5.0 + geometric).normalize();
            let bent = bent_towards_view(shading, geometric, wo);
            assert!((bent.length() - 1.0).abs() < 1e-4, "{bent}");
            assert!(bent.dot(wo) > 0.0, "faces the viewer: {bent} {wo}");
            assert!(bent.dot(geometric) > 0.0, "{bent}");
            let floor = (0.9 * wo.dot(geometric)).min(0.01);
            assert!(mirror(bent, wo).dot(geometric) >= floor - 1e-4, "{shading} {wo} -> {bent}");
            if bent != shading {
                // Bent just enough: the mirror sits at the floor.
                assert!((mirror(bent, wo).dot(geometric) - floor).abs() < 2e-3, "{shading} {wo} -> {bent}");
            }
        }
    }

    #[test]
    fn a_mirror_straight_into_the_surface_gives_the_geometric_normal() {
        // The view along the geometric normal, the shading normal at right
        // angles to it: the mirror direction points straight down, with no
        // direction along the surface to keep.
        let geometric = Vec3::Y;
        assert_eq!(bent_towards_view(Vec3::X, geometric, geometric), geometric);
    }
}
