//! Primitives of the user's own (spheres, boxes, curves, instances), for
//! [`crate::PrimitiveBvh`]: the BVH builders need only a box and a
//! centroid per primitive, and traversal only a ray test.

use rtgi_math::{Aabb, Ray, Vec3};

use crate::boxa::BoxA;
use crate::slab::{BoxRay, RobustSlabs, SlabTest};

/// A primitive a [`crate::PrimitiveBvh`] can be built over.
///
/// ```
/// use rtgi_accel::{Aabb, Primitive, Ray, Vec3};
///
/// struct Sphere {
///     centre: Vec3,
///     radius: f32,
/// }
///
/// impl Primitive for Sphere {
///     /// The unit normal at the hit point.
///     type Payload = Vec3;
///
///     fn bounds(&self) -> Aabb {
///         Aabb::new(self.centre - self.radius, self.centre + self.radius)
///     }
///
///     fn intersect(&self, ray: &Ray, t_max: f32) -> Option<(f32, Vec3)> {
///         // |o + t d - c|² = r²: a t² + 2 b t + c = 0.
///         let oc = ray.origin - self.centre;
///         let a = ray.direction.length_squared();
///         let b = oc.dot(ray.direction);
///         let c = oc.length_squared() - self.radius * self.radius;
///         let discriminant = b * b - a * c;
///         if discriminant < 0.0 {
///             return None;
///         }
///         let root = discriminant.sqrt();
///         // The nearer root in range, else the farther (the ray starts inside).
///         let t = [(-b - root) / a, (-b + root) / a].into_iter().find(|&t| t >= ray.t_min && t <= t_max)?;
///         Some((t, (ray.at(t) - self.centre) / self.radius))
///     }
/// }
/// ```
///
/// What a hit counts as is decided by the structure, not by the
/// primitive, and so is the same for every structure and split method
/// (the hit rule of [`intersect_primitive`]): `intersect`'s answer is
/// kept only if its `t` lies in `[ray.t_min, t_max]` (a NaN never does)
/// and the ray passes the robust slab test of the primitive's
/// [`Primitive::bounds`]; `t` is raised to the box's entry distance if it
/// came out below it.
pub trait Primitive: Sync {
    /// What a hit reports besides its distance, as the primitive chooses:
    /// a normal, surface coordinates, or `()`.
    type Payload;

    /// A box holding the primitive. Primitives whose box is empty or not
    /// finite are left out of builds and never hit.
    fn bounds(&self) -> Aabb;

    /// The point the builders sort the primitive by; the centre of its box
    /// unless the primitive knows better (a long thin primitive, say). Any
    /// finite point gives the same answers, only a different tree;
    /// primitives with a centroid that is not finite are left out.
    fn centroid(&self) -> Vec3 {
        self.bounds().centroid()
    }

    /// The nearest hit of `ray` with `ray.t_min <= t <= t_max`: its
    /// distance (in multiples of `ray.direction`) and payload, or `None`.
    ///
    /// Structures pass the best distance found so far as `t_max` (at first
    /// `ray.t_max`), so that the primitive can give up early; the answer
    /// must not otherwise depend on it. A hit at exactly `t_max` must be
    /// reported: it may tie with a hit on a primitive of higher index.
    fn intersect(&self, ray: &Ray, t_max: f32) -> Option<(f32, Self::Payload)>;
}

/// The closest hit found by a [`crate::PrimitiveBvh`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrimitiveHit<P> {
    /// Distance along the ray, in multiples of its direction, within
    /// `[t_min, t_max]` (see the hit rule of [`intersect_primitive`]).
    pub t: f32,
    /// Index of the primitive in the order the structure was built from.
    pub primitive: u32,
    /// What the primitive's [`Primitive::intersect`] reported.
    pub payload: P,
}

/// Intersects one ray with one primitive under the structures' hit rule:
/// the reference a linear scan over primitives applies to each, and what
/// [`crate::PrimitiveBvh`] returns for the primitive it picks.
///
/// The primitive's box ([`Primitive::bounds`]) must be finite and not
/// empty, and the ray must pass the robust slab test of that box within
/// `[ray.t_min, ray.t_max]` (the one BVH traversal applies to its nodes);
/// then [`Primitive::intersect`] is asked, and its `t` kept if it lies in
/// `[ray.t_min, ray.t_max]`, raised to the box's entry distance if it came
/// out below it. A `t` beyond the box's exit is kept as it is. Because
/// the slab test is monotone in the box, every node box holding the
/// primitive is entered no later than the hit, which is what lets
/// traversal cull boxes beyond the best hit without losing a hit or a tie.
pub fn intersect_primitive<P: Primitive + ?Sized>(primitive: &P, ray: &Ray) -> Option<(f32, P::Payload)> {
    if !ray.is_valid() {
        return None;
    }
    let bounds = buildable_bounds(primitive)?;
    hit_primitive(primitive, bounds, ray, &BoxRay::new(ray), ray.t_max)
}

/// The primitive's box for builds and the hit rule, or `None` if the
/// primitive can never be hit (an empty or non-finite box, or a
/// non-finite centroid).
pub(crate) fn buildable_bounds<P: Primitive + ?Sized>(primitive: &P) -> Option<BoxA> {
    let bounds = primitive.bounds();
    let finite = bounds.min.is_finite() && bounds.max.is_finite() && primitive.centroid().is_finite();
    (finite && !bounds.is_empty()).then(|| BoxA { min: bounds.min.into(), max: bounds.max.into() })
}

/// The hit rule with the primitive's stored box and a prepared ray; `t_max`
/// may be lowered below the ray's own to the best hit so far, which never
/// changes a hit that can still win or tie. The box is tested first, which
/// also spares the primitive's own test for rays that miss its box.
#[inline]
pub(crate) fn hit_primitive<P: Primitive + ?Sized>(
    primitive: &P,
    bounds: BoxA,
    ray: &Ray,
    box_ray: &BoxRay,
    t_max: f32,
) -> Option<(f32, P::Payload)> {
    let enter = RobustSlabs::enter(box_ray, bounds.min, bounds.max, t_max);
    if enter == f32::INFINITY {
        return None;
    }
    let (t, payload) = primitive.intersect(ray, t_max)?;
    // Written so that a NaN fails.
    if !(t >= ray.t_min && t <= t_max) {
        return None;
    }
    Some((t.max(enter), payload))
}
