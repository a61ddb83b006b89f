//! A BVH over primitives of the user's own ([`Primitive`]), built by the
//! same builders and split methods as the triangle [`Bvh`](super::Bvh):
//! they see one box and one centroid per primitive and nothing else.

use std::time::Instant;

use rayon::prelude::*;
use rtgi_math::{Aabb, Ray, Vec3A};

use super::traverse::{BinaryQuery, STACK_SIZE, traverse_binary};
use super::{BvhNode, SplitMethod, build};
use crate::boxa::BoxA;
use crate::primitive::{buildable_bounds, hit_primitive};
use crate::slab::{BoxRay, RobustSlabs, SlabTest};
use crate::{BuildParams, BuildStats, Primitive, PrimitiveHit};

/// A bounding volume hierarchy over primitives of the caller's type.
///
/// It owns the primitives, in the order given ([`PrimitiveBvh::primitives`]);
/// leaves refer to them by index, and hits name them by that index.
///
/// # The contract
///
/// For every ray, [`PrimitiveBvh::intersect`] returns, among the
/// primitives hit under the hit rule of [`crate::intersect_primitive`]
/// (the primitive's answer in `[t_min, t_max]`, kept only if the ray
/// passes the robust slab test of the primitive's own box, `t` raised to
/// that box's entry if below it), the smallest `t`, and at equal `t` the
/// lowest index, with the payload of that primitive's test: exactly what a
/// linear scan applying that rule to every primitive returns, for every
/// split method, leaf size and bin count. [`PrimitiveBvh::occluded`] is
/// true exactly when `intersect` would hit. This holds for any primitive
/// whose `intersect` is a function of the ray and the primitive, as
/// [`Primitive::intersect`] asks, even one whose hits lie outside its box.
///
/// ```
/// use rtgi_accel::{Aabb, BuildParams, Primitive, PrimitiveBvh, Ray, SplitMethod, Vec3};
///
/// /// A box, hit where the ray enters it.
/// struct Cube(Aabb);
///
/// impl Primitive for Cube {
///     type Payload = ();
///
///     fn bounds(&self) -> Aabb {
///         self.0
///     }
///
///     fn intersect(&self, ray: &Ray, t_max: f32) -> Option<(f32, ())> {
///         let near = (self.0.min - ray.origin) / ray.direction;
///         let far = (self.0.max - ray.origin) / ray.direction;
///         let enter = near.min(far).max_element().max(ray.t_min);
///         let exit = near.max(far).min_element().min(t_max);
///         (enter <= exit).then_some((enter, ()))
///     }
/// }
///
/// let cubes: Vec<Cube> = (0..10).map(|i| Cube(Aabb::new(Vec3::splat(i as f32), Vec3::splat(i as f32 + 0.5)))).collect();
/// let bvh = PrimitiveBvh::new(cubes, SplitMethod::BinnedSah, &BuildParams::default());
/// let hit = bvh.intersect(&Ray::new(Vec3::new(3.25, 3.25, -10.0), Vec3::Z)).unwrap();
/// assert_eq!((hit.t, hit.primitive), (13.0, 3));
/// ```
#[derive(Debug)]
pub struct PrimitiveBvh<P> {
    primitives: Vec<P>,
    nodes: Vec<BvhNode>,
    /// For each primitive in leaf order, its index in `primitives`.
    leaf_ids: Vec<u32>,
    /// For each primitive in leaf order, its box as the build saw it: the
    /// box of the hit rule, so the rule never asks the primitive again.
    leaf_bounds: Vec<BoxA>,
    stats: BuildStats,
}

impl<P: Primitive> PrimitiveBvh<P> {
    /// Builds a hierarchy over `primitives` with the given split method and
    /// the parameters' leaf size, SAH bins and traversal cost; its
    /// intersector and traversal do not apply (primitives test themselves,
    /// and the robust slab test is part of the contract).
    ///
    /// Primitives whose box is empty or not finite, or whose centroid is
    /// not finite, are left out of the tree, never hit, and counted in
    /// [`BuildStats::excluded_triangles`].
    pub fn new(primitives: Vec<P>, method: SplitMethod, params: &BuildParams) -> Self {
        let start = Instant::now();
        let (inputs, ids): (Vec<(BoxA, Vec3A)>, Vec<u32>) = primitives
            .par_iter()
            .enumerate()
            .filter_map(|(i, p)| Some(((buildable_bounds(p)?, p.centroid().into()), i as u32)))
            .unzip();
        let tree = build::build_with_centroids(&inputs, method, params);
        let (leaf_ids, leaf_bounds): (Vec<u32>, Vec<BoxA>) =
            tree.order.iter().map(|&p| (ids[p as usize], inputs[p as usize].0)).unzip();
        let leaf_bytes = std::mem::size_of_val(leaf_ids.as_slice()) + std::mem::size_of_val(leaf_bounds.as_slice());
        let variant = format!("primitive-{}", method.name());
        let stats = tree.stats(variant, primitives.len(), primitives.len() - ids.len(), start, leaf_bytes);
        Self { primitives, nodes: tree.nodes, leaf_ids, leaf_bounds, stats }
    }

    /// The closest hit in `[ray.t_min, ray.t_max]`, or `None`; at equal `t`
    /// the primitive with the lower index wins (see the type's contract).
    pub fn intersect(&self, ray: &Ray) -> Option<PrimitiveHit<P::Payload>> {
        self.query::<false>(ray)
    }

    /// Whether anything is hit in `[ray.t_min, ray.t_max]`: exactly when
    /// [`PrimitiveBvh::intersect`] would return a hit. Stops at the first
    /// hit found.
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.query::<true>(ray).is_some()
    }

    /// The primitives, in the order given to [`PrimitiveBvh::new`].
    pub fn primitives(&self) -> &[P] {
        &self.primitives
    }

    /// Gives the primitives back, in the order given to [`PrimitiveBvh::new`].
    pub fn into_primitives(self) -> Vec<P> {
        self.primitives
    }

    /// The flattened nodes; the root is node 0 (absent for an empty tree).
    /// A leaf's primitives are [`PrimitiveBvh::leaf_primitives`].
    pub fn nodes(&self) -> &[BvhNode] {
        &self.nodes
    }

    /// The indices of the primitives of a leaf.
    pub fn leaf_primitives(&self, leaf: &BvhNode) -> &[u32] {
        &self.leaf_ids[leaf.first() as usize..(leaf.first() + leaf.count()) as usize]
    }

    /// The statistics of the build; its `triangles` count the primitives.
    pub fn build_stats(&self) -> &BuildStats {
        &self.stats
    }

    /// The box of the whole tree; empty if no primitive can be hit.
    pub fn bounds(&self) -> Aabb {
        self.nodes.first().map_or(Aabb::EMPTY, BvhNode::bounds)
    }

    /// One query, by the triangle BVH's traversal ([`traverse_binary`])
    /// with the robust slab test; `ANY_HIT` stops at the first hit accepted.
    fn query<const ANY_HIT: bool>(&self, ray: &Ray) -> Option<PrimitiveHit<P::Payload>> {
        if !ray.is_valid() || self.nodes.is_empty() {
            return None;
        }
        let mut query = PrimitiveQuery::<P, ANY_HIT> { bvh: self, ray, box_ray: BoxRay::new(ray), best: None };
        // Builds never exceed 64 + 32 levels, so the stack cannot overflow.
        traverse_binary::<_, STACK_SIZE>(&self.nodes, &mut query);
        query.best
    }
}

/// A query on a [`PrimitiveBvh`], for [`traverse_binary`].
struct PrimitiveQuery<'a, P: Primitive, const ANY_HIT: bool> {
    bvh: &'a PrimitiveBvh<P>,
    ray: &'a Ray,
    box_ray: BoxRay,
    best: Option<PrimitiveHit<P::Payload>>,
}

impl<P: Primitive, const ANY_HIT: bool> BinaryQuery for PrimitiveQuery<'_, P, ANY_HIT> {
    #[inline(always)]
    fn enter(&self, node: &BvhNode, t_max: f32) -> f32 {
        let (min, max) = node.corners();
        RobustSlabs::enter(&self.box_ray, min, max, t_max)
    }

    #[inline(always)]
    fn t_max(&self) -> f32 {
        self.best.as_ref().map_or(self.ray.t_max, |best| best.t)
    }

    /// Offers each primitive's hit; the best is the least in the order
    /// (distance, primitive index), as for triangles.
    fn visit_leaf(&mut self, leaf: &BvhNode) -> bool {
        let range = leaf.first() as usize..(leaf.first() + leaf.count()) as usize;
        for (&id, &bounds) in self.bvh.leaf_ids[range.clone()].iter().zip(&self.bvh.leaf_bounds[range]) {
            let primitive = &self.bvh.primitives[id as usize];
            let Some((t, payload)) = hit_primitive(primitive, bounds, self.ray, &self.box_ray, self.t_max()) else {
                continue;
            };
            let precedes = self.best.as_ref().is_none_or(|b| t < b.t || (t == b.t && id < b.primitive));
            if precedes {
                self.best = Some(PrimitiveHit { t, primitive: id, payload });
                if ANY_HIT {
                    return true;
                }
            }
        }
        false
    }
}
