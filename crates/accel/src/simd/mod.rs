//! SIMD kernels of the wide BVHs, and the run-time choice of instruction
//! set ([`dispatch`](self::dispatch), the crate's one module with `unsafe`).
//!
//! - [`boxes`](self::boxes): one ray against the `W` child boxes of a wide
//!   node, stored structure-of-arrays, with the robust slab test's
//!   arithmetic lane by lane.
//! - [`triangles`](self::triangles): one ray against a block of four
//!   triangles, stored structure-of-arrays.
//! - [`arith`](self::arith): the ray/triangle arithmetic written once,
//!   generic over one lane (`f32`) or four (`Vec4`), so that the scalar
//!   tests and the block tests compute the same values, bit for bit.

pub(crate) mod arith;
pub(crate) mod boxes;
mod dispatch;
pub(crate) mod triangles;

pub(crate) use dispatch::{Isa, Kernel, dispatch, prefetch};
pub use dispatch::{SimdLevel, active_simd_level, limit_simd_level};
