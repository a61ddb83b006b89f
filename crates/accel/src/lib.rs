//! Closest-hit and any-hit ray queries over a set of triangles, and over
//! primitives of the user's own.
//!
//! This crate knows nothing about scene files, materials or shading: it is given
//! triangle corner positions, in an order of the caller's choosing (a soup
//! of corners, or an [`IndexedMesh`] of shared positions and index triples
//! borrowed as they are: any [`TriangleSource`]), and
//! answers which triangle a ray hits first ([`Accel::intersect`]) or whether
//! it hits any ([`Accel::occluded`]). Hits name the triangle by its index in
//! that input order and carry the barycentric coordinates `(beta, gamma)` of
//! the hit point, so that the caller can interpolate its own vertex data:
//! `p = (1 - beta - gamma) * v0 + beta * v1 + gamma * v2`.
//!
//! The structures ([`AccelKind`]): the linear scan ([`LinearScan`]), binary
//! BVHs ([`Bvh`]) and wide BVHs ([`Bvh4`], [`Bvh8`]) whose nodes and leaves
//! are tested with SIMD instructions chosen at run time ([`simd`]). Many
//! rays can be answered at once ([`Accel::intersect_batch`],
//! [`Accel::occluded_batch`]); the wide BVHs then trace coherent runs of
//! sixteen rays as packets, with the same answers.
//!
//! ```
//! use rtgi_accel::{Accel, AccelKind, BuildParams, Ray, Vec3};
//!
//! let triangles = [[Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)]];
//! let accel = AccelKind::Linear.build(&triangles, &BuildParams::default());
//! let ray = Ray::new(Vec3::new(0.0, 0.0, -2.0), Vec3::Z);
//! let hit = accel.intersect(&ray).expect("the ray points at the triangle");
//! assert_eq!((hit.t, hit.triangle), (2.0, 0));
//! assert!(accel.occluded(&ray));
//! ```
//!
//! An indexed mesh is read where it lies, with no soup built first, and
//! gives every structure the answers of the equivalent soup, bit for bit:
//!
//! ```
//! use rtgi_accel::{Accel, AccelKind, IndexedMesh, Ray, Vec3};
//!
//! let positions = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
//! let indices = [[0, 1, 2], [0, 2, 3]];
//! let mesh = IndexedMesh::new(&positions, &indices).expect("every index names a vertex");
//! let bvh = AccelKind::Bvh8.build(&mesh, &AccelKind::Bvh8.default_params());
//! let hit = bvh.intersect(&Ray::new(Vec3::new(0.75, 0.25, 1.0), -Vec3::Z)).unwrap();
//! assert_eq!((hit.t, hit.triangle), (1.0, 0));
//! ```
//!
//! Batches of rays from other programs, and their hits, travel as binary
//! files read and written by [`ray_file`] (rays a chunk at a time, so a
//! file of any size or a stream fits in memory).
//!
//! Primitives of the user's own (spheres, boxes, curves) implement
//! [`Primitive`] (a box, optionally a centroid, and a ray test returning
//! a distance and a payload of their choosing); a [`PrimitiveBvh`] is
//! built over them by the same builders and split methods as [`Bvh`],
//! and answers closest-hit and any-hit queries under the same rules as
//! the triangle structures (see [`PrimitiveBvh`]'s contract).
//!
//! # The exactness contract
//!
//! The structure is a pure speed choice: swapping it changes the time,
//! never the answer. Every structure (the linear scan, every BVH variant,
//! leaf size and bin count with the robust traversal, and every structure
//! added later), at any thread count and with every intersector, returns
//! for every ray, in any direction including axis-parallel ones and
//! directions with zero or negative-zero components:
//!
//! - **closest hit**: among the *hittable* triangles ([`is_hittable`]:
//!   finite corners, non-zero area) hit with `t_min <= t <= t_max`, the
//!   smallest `t`, and at equal `t` the lowest triangle index. `t`, `beta`
//!   and `gamma` are those of that triangle's own test, so two structures
//!   that agree on the triangle agree on every bit;
//! - **any hit**: true exactly when the closest hit would return a hit.
//!
//! A triangle's test is the intersector's (watertight by default) followed
//! by the robust slab test of the triangle's own bounding box, which must
//! pass, with `t` raised to the box's entry distance if rounding put it
//! below: the slab test is monotone in the box, so every node box holding
//! the triangle is entered no later than the hit and left no earlier, and
//! traversal can cull boxes that lie beyond the best hit without ever
//! losing a hit or a tie ([`Intersector::intersect`] applies the same rule
//! to one triangle). The [`verify`] module checks the contract on any
//! scene, and `rtgi verify` runs it from the command line; the fast
//! traversal ([`Traversal::Fast`]) drops boxes that rays graze and is
//! outside the contract.
//!
//! # Peers
//!
//! With the `embree` feature (and the system's Embree 3,
//! `apt install libembree-dev`), `EmbreeBackend` puts Intel Embree behind
//! [`Accel`] as `AccelKind::Embree`, to compare against. It is a peer
//! ([`AccelKind::PEERS`]), outside the contract: it breaks ties in its own
//! order and rounds differently on grazing rays, so it is not in
//! [`AccelKind::ALL`]. Its module is the one place of the workspace where
//! `unsafe` code is allowed.

#![warn(missing_docs)]

// The README's examples are compiled and run as doctests.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;

mod boxa;
mod boxes_obj;
mod bvh;
mod contract;
mod counters;
#[cfg(feature = "embree")]
mod embree;
mod exact;
mod indexed_mesh;
mod kind;
mod linear;
pub mod parallel;
mod primitive;
pub mod ray_file;
pub mod simd;
mod slab;
mod triangle;
mod triangle_hit;
mod triangle_source;
pub mod verify;
mod wide;

pub use boxes_obj::boxes_obj;
pub use bvh::{Bvh, BvhNode, PrimitiveBvh, SplitMethod, Traversal};

/// The peer libraries this build can measure beside our structures, each
/// with its version and how it builds ("Embree 3.13.5, build quality
/// medium"), or why it cannot run; empty without the `embree` feature.
pub fn peer_libraries() -> Vec<String> {
    #[cfg(feature = "embree")]
    {
        vec![EmbreeBackend::library().unwrap_or_else(|e| format!("Embree, unavailable: {e}"))]
    }
    #[cfg(not(feature = "embree"))]
    {
        Vec::new()
    }
}
pub use contract::is_hittable;
pub use counters::{Counter, NoCounter, TraversalCounters};
#[cfg(feature = "embree")]
pub use embree::{EmbreeBackend, EmbreeError};
pub use indexed_mesh::{IndexedMesh, IndexedMeshError};
pub use kind::{AccelKind, BuildError, BuildParams, SahAxes};
pub use linear::LinearScan;
pub use primitive::{Primitive, PrimitiveHit, intersect_primitive};
pub use triangle::Intersector;
pub use triangle_hit::TriangleHit;
pub use triangle_source::TriangleSource;
pub use wide::{Bvh4, Bvh8, Bvh8Quantised, QuantisedNode, WideBvh, WideNode};

/// The math types this crate takes and returns, re-exported so that a user
/// needs one dependency and sees the same glam version as the crate.
pub use rtgi_math::{Aabb, Ray, Rng, Vec3};

use serde::Serialize;

/// The closest hit of a ray: its distance `t` along the ray, the index of
/// the triangle in the order the structure was built from, and the
/// barycentric coordinates of the hit point on that triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance along the ray, in multiples of its direction, within `[t_min, t_max]`.
    pub t: f32,
    /// Index of the triangle in the order the structure was built from.
    pub triangle: u32,
    /// Barycentric coordinate of the triangle's second corner.
    pub beta: f32,
    /// Barycentric coordinate of the triangle's third corner.
    pub gamma: f32,
}

/// What a build produced and what it cost; every structure reports one.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct BuildStats {
    /// Name of the variant, as [`AccelKind::name`] gives it.
    pub variant: String,
    /// Triangles given to the build (primitives, for a [`PrimitiveBvh`]).
    pub triangles: usize,
    /// Triangles left out because they can never be hit (zero area, or a
    /// NaN or infinite coordinate); for a [`PrimitiveBvh`], primitives
    /// whose box is empty or not finite.
    pub excluded_triangles: usize,
    /// Wall-clock time of the build, in milliseconds.
    pub build_ms: f64,
    /// Nodes of the tree, leaves included (0 for the linear scan).
    pub nodes: usize,
    /// Leaves of the tree.
    pub leaves: usize,
    /// Edges on the longest path from the root to a leaf.
    pub depth: usize,
    /// `leaf_size_histogram[k]` leaves hold `k` triangles.
    pub leaf_size_histogram: Vec<usize>,
    /// The tree's SAH cost in units of one leaf test (one triangle, or for
    /// the wide BVHs one block of four triangles tested at once), with the
    /// build's traversal cost: the quality number of a tree (lower is
    /// better; compare it between builds of one structure).
    pub sah_cost: f32,
    /// Bytes of nodes, triangles and index tables.
    pub memory_bytes: usize,
}

/// A ray query structure over triangles.
///
/// The trait is object safe so that the variant can be chosen at run time
/// (`Box<dyn Accel>`); implementations keep their hot loops generic over a
/// [`Counter`], so counting nodes and triangle tests costs nothing when the
/// uncounted methods are used.
pub trait Accel: Send + Sync + std::fmt::Debug {
    /// The closest hit in `[ray.t_min, ray.t_max]`, or `None`.
    /// At equal `t`, the triangle with the lower index wins (see the
    /// exactness contract in the crate's documentation).
    fn intersect(&self, ray: &Ray) -> Option<Hit>;

    /// Whether anything is hit in `[ray.t_min, ray.t_max]`: exactly when
    /// [`Accel::intersect`] would return a hit. Stops at the first hit found.
    fn occluded(&self, ray: &Ray) -> bool;

    /// [`Accel::intersect`], adding the work done to `counters`.
    fn intersect_counted(&self, ray: &Ray, counters: &mut TraversalCounters) -> Option<Hit>;

    /// [`Accel::occluded`], adding the work done to `counters`.
    fn occluded_counted(&self, ray: &Ray, counters: &mut TraversalCounters) -> bool;

    /// [`Accel::intersect`], counting only hits that `accept(triangle,
    /// beta, gamma)` agrees to: the others are passed through, as alpha-masked
    /// holes are. The filter is called for candidate hits only.
    fn intersect_filtered(&self, ray: &Ray, accept: &dyn Fn(u32, f32, f32) -> bool) -> Option<Hit>;

    /// [`Accel::occluded`] with the same filter as [`Accel::intersect_filtered`].
    fn occluded_filtered(&self, ray: &Ray, accept: &dyn Fn(u32, f32, f32) -> bool) -> bool;

    /// The statistics of the build.
    fn build_stats(&self) -> &BuildStats;

    /// Closest hits of many rays at once: `hits[i]` becomes
    /// `self.intersect(&rays[i])`, bit for bit. Structures that trace
    /// coherent rays together (packets) override it; the default traces
    /// one ray at a time. Rays that start close together and point in
    /// similar directions (a tile of camera rays) gain most.
    ///
    /// # Panics
    /// If the two slices differ in length.
    fn intersect_batch(&self, rays: &[Ray], hits: &mut [Option<Hit>]) {
        assert_eq!(rays.len(), hits.len(), "one hit slot per ray");
        for (ray, hit) in rays.iter().zip(hits) {
            *hit = self.intersect(ray);
        }
    }

    /// Any-hit queries of many rays at once: `occluded[i]` becomes
    /// `self.occluded(&rays[i])`.
    ///
    /// # Panics
    /// If the two slices differ in length.
    fn occluded_batch(&self, rays: &[Ray], occluded: &mut [bool]) {
        assert_eq!(rays.len(), occluded.len(), "one answer slot per ray");
        for (ray, answer) in rays.iter().zip(occluded) {
            *answer = self.occluded(ray);
        }
    }

    /// [`Accel::intersect_batch`] with the filter of
    /// [`Accel::intersect_filtered`]: `hits[i]` becomes
    /// `self.intersect_filtered(&rays[i], accept)`, bit for bit. The wide
    /// BVHs trace coherent runs as packets here too, so cut-outs (alpha
    /// masks) cost a filter call per candidate hit, not a slower path.
    ///
    /// # Panics
    /// If the two slices differ in length.
    fn intersect_batch_filtered(&self, rays: &[Ray], hits: &mut [Option<Hit>], accept: &dyn Fn(u32, f32, f32) -> bool) {
        assert_eq!(rays.len(), hits.len(), "one hit slot per ray");
        for (ray, hit) in rays.iter().zip(hits) {
            *hit = self.intersect_filtered(ray, accept);
        }
    }

    /// [`Accel::occluded_batch`] with the filter of
    /// [`Accel::intersect_filtered`]: `occluded[i]` becomes
    /// `self.occluded_filtered(&rays[i], accept)`.
    ///
    /// # Panics
    /// If the two slices differ in length.
    fn occluded_batch_filtered(&self, rays: &[Ray], occluded: &mut [bool], accept: &dyn Fn(u32, f32, f32) -> bool) {
        assert_eq!(rays.len(), occluded.len(), "one answer slot per ray");
        for (ray, answer) in rays.iter().zip(occluded) {
            *answer = self.occluded_filtered(ray, accept);
        }
    }
}
