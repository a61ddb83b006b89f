//! The acceleration structures: every variant answers as the linear scan
//! does, bit for bit, on random soups, adversarial inputs, the fuzzers'
//! finds and the hard cases of single-precision ray tracing.
//!
//! One test binary for the theme, a module a file (each linked binary costs
//! CI a link of the whole renderer).

mod accel_equivalence;
mod bvh_fuzz_regressions;
mod exactness;
mod hard_cases;
mod indexed_mesh;
mod primitives;
