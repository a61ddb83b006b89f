//! The bottom layer of rtgi: rays, axis-aligned boxes, orthonormal frames and
//! a deterministic random number generator.
//!
//! [`glam`] is re-exported so that every crate of the workspace, and every
//! user of it, sees one version of the vector types.
//!
//! ```
//! use rtgi_math::{Aabb, Ray, Vec3};
//!
//! let unit_box = Aabb::new(Vec3::ZERO, Vec3::ONE);
//! let ray = Ray::new(Vec3::new(0.5, 0.5, -1.0), Vec3::Z);
//! let (t_enter, t_exit) = unit_box.intersect(&ray.with_inverse()).unwrap();
//! assert_eq!(t_enter, 1.0);
//! assert!(t_exit >= 2.0);
//! ```

#![warn(missing_docs)]

// The README's examples are compiled and run as doctests.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;

mod aabb;
mod choices;
mod colour;
mod float;
mod frame;
mod ray;
mod rng;
mod spawn;

pub use aabb::Aabb;
pub use choices::{NamedChoice, parse_choice, parse_vec3};
pub use colour::luminance;
pub use float::{EXIT_FOLD, exit_inverses, gamma, later_exit, next_float_down, next_float_up, starts_behind};
pub use frame::{Frame, uniform_sphere};
pub use glam;
pub use glam::{BVec3A, Mat3, Mat4, Vec2, Vec3, Vec3A, Vec4, vec2, vec3};
pub use ray::{Ray, RayWithInverse};
pub use rng::{Rng, hash_u64};
pub use spawn::{MAX_ELONGATION, SurfacePoint, TriangleShape, elongation, geometric_normal, offset_ray_origin};
