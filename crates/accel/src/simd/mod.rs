//! SIMD kernels of the wide BVHs, and the run-time choice of instruction
//! set: [`SimdLevel`], detected once ([`active_simd_level`]) and lowered
//! on request ([`limit_simd_level`]), to compare levels.
//!
//! Inside the crate: `boxes.rs` tests one ray against the `W` child boxes
//! of a wide node, stored structure-of-arrays, with the robust slab test's
//! arithmetic lane by lane, and `packet.rs` sixteen rays against one box
//! and, through the interval ray that bounds them, against a node's boxes;
//! `triangles.rs` tests one ray against a block of
//! four triangles, stored structure-of-arrays, and `packet_triangles.rs`
//! one triangle against a packet's sixteen rays; `arith.rs` holds the
//! ray/triangle arithmetic written once, generic over one lane (`f32`) or
//! four (`Vec4`), so that the scalar tests and the block tests compute the
//! same values, bit for bit; `dispatch.rs` (with the Embree binding, one of
//! the two modules allowed `unsafe`) runs each hot loop compiled for the
//! widest level the CPU has, with intrinsic kernels beside portable twins.

pub(crate) mod arith;
pub(crate) mod boxes;
mod dispatch;
pub(crate) mod packet;
pub(crate) mod packet_triangles;
pub(crate) mod triangles;

pub(crate) use dispatch::{Isa, Kernel, Portable, dispatch, prefetch};
pub use dispatch::{SimdLevel, active_simd_level, limit_simd_level};
