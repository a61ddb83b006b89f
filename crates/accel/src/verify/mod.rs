//! Checking the exactness contract on any scene: rays of the kinds that
//! expose inexact structures ([`RayKind`]), adversarial scenes
//! ([`adversarial_cases`]), and the comparison of a structure's answers
//! with a reference's, bit for bit ([`Answer`], [`Tally`]).
//!
//! ```
//! use rtgi_accel::verify::{Answer, RayKind, Tally};
//! use rtgi_accel::{AccelKind, BuildParams};
//!
//! let cube = rtgi_accel::verify::shapes::tessellated_cube(4).triangles();
//! let rays = RayKind::Silhouette.rays(&cube, 1000, 1);
//! let linear = AccelKind::Linear.build(&cube, &BuildParams::default());
//! let bvh = AccelKind::Sah.build(&cube, &BuildParams::default());
//! let reference = Answer::all(linear.as_ref(), &rays);
//! let tally = Tally::of(&rays, &Answer::all(bvh.as_ref(), &rays), Some(&reference));
//! assert_eq!((tally.closest_disagreements, tally.any_disagreements, tally.leaks), (0, 0, 0));
//! ```

mod cases;
mod plan;
mod rays;
mod report;
pub mod shapes;

pub use cases::{Case, Solid, adversarial_cases, hollow_needles, needle, solids};
pub use plan::{cases, configurations, reference_intersectors};
pub use rays::RayKind;
pub use report::{KindRow, StructureRow, VerifyReport, check_case, label};

use rayon::prelude::*;
use rtgi_math::{Ray, Rng, Vec3};
use serde::Serialize;

use crate::{Accel, Hit};

/// A ray and what must be true of its answer, whatever the structure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeRay {
    /// The ray to trace.
    pub ray: Ray,
    /// What its answer must satisfy besides agreeing with the reference.
    pub expect: Expect,
}

/// What a correct answer to a [`ProbeRay`] must satisfy.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Expect {
    /// Nothing beyond agreeing with the reference.
    Nothing,
    /// A hit with `t` at most this: the ray crosses a surface there, so a
    /// miss means it leaked through.
    HitBy(f32),
    /// No hit on this triangle: the ray leaves it.
    NotTriangle(u32),
}

/// A structure's answers to one ray: closest hit and any hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Answer {
    /// The closest hit, if any.
    pub closest: Option<Hit>,
    /// Whether the any-hit query found a hit.
    pub any: bool,
}

impl Answer {
    /// The answers of `accel` to every ray, computed in parallel.
    pub fn all(accel: &dyn Accel, rays: &[ProbeRay]) -> Vec<Answer> {
        rays.par_iter()
            .with_min_len(256)
            .map(|probe| Answer { closest: accel.intersect(&probe.ray), any: accel.occluded(&probe.ray) })
            .collect()
    }

    /// The answers of `accel` through its batch queries
    /// ([`Accel::intersect_batch`], [`Accel::occluded_batch`]) on chunks
    /// of consecutive rays, where packet traversal runs; they must be
    /// those of [`Answer::all`], bit for bit.
    pub fn all_batched(accel: &dyn Accel, rays: &[ProbeRay]) -> Vec<Answer> {
        rays.par_chunks(256)
            .flat_map_iter(|chunk| {
                let rays: Vec<Ray> = chunk.iter().map(|probe| probe.ray).collect();
                let mut closest = vec![None; rays.len()];
                let mut any = vec![false; rays.len()];
                accel.intersect_batch(&rays, &mut closest);
                accel.occluded_batch(&rays, &mut any);
                closest.into_iter().zip(any).map(|(closest, any)| Answer { closest, any })
            })
            .collect()
    }
}

/// Whether two closest hits are the same to the bit: triangle, `t`, `beta`, `gamma`.
pub fn same_hit(a: Option<Hit>, b: Option<Hit>) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(a), Some(b)) => {
            a.triangle == b.triangle
                && a.t.to_bits() == b.t.to_bits()
                && a.beta.to_bits() == b.beta.to_bits()
                && a.gamma.to_bits() == b.gamma.to_bits()
        }
        _ => false,
    }
}

/// How a structure's answers to a set of rays fared.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Tally {
    /// Rays traced.
    pub rays: usize,
    /// Rays compared with the reference (the reference may answer only the first ones).
    pub compared: usize,
    /// Closest hits that differ from the reference's in any bit.
    pub closest_disagreements: usize,
    /// Any-hit answers that differ from the reference's, or from the
    /// structure's own closest hit.
    pub any_disagreements: usize,
    /// Rays that must hit ([`Expect::HitBy`]) and did not, in either query.
    pub leaks: usize,
    /// Rays that hit the triangle they leave ([`Expect::NotTriangle`]).
    pub self_hits: usize,
    /// The first few failures, described for a person.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub examples: Vec<String>,
}

/// Failures described in full, per tally.
const EXAMPLES: usize = 3;

impl Tally {
    /// Checks `answers` (to `rays`, in order) against what each ray expects
    /// and against `reference` (answers to the first `reference.len()` rays).
    pub fn of(rays: &[ProbeRay], answers: &[Answer], reference: Option<&[Answer]>) -> Tally {
        let mut tally = Tally { rays: rays.len(), ..Tally::default() };
        let reference = reference.unwrap_or(&[]);
        tally.compared = reference.len().min(rays.len());
        for (i, (probe, answer)) in rays.iter().zip(answers).enumerate() {
            let mut failure = None;
            if let Some(expected) = reference.get(i) {
                if !same_hit(answer.closest, expected.closest) {
                    tally.closest_disagreements += 1;
                    failure = Some(format!("closest {:?}, reference {:?}", answer.closest, expected.closest));
                }
                if answer.any != expected.any {
                    tally.any_disagreements += 1;
                    failure.get_or_insert_with(|| format!("any hit {}, reference {}", answer.any, expected.any));
                }
            }
            if answer.any != answer.closest.is_some() {
                tally.any_disagreements += 1;
                failure.get_or_insert_with(|| format!("any hit {} but closest {:?}", answer.any, answer.closest));
            }
            match probe.expect {
                Expect::Nothing => {}
                Expect::HitBy(t) => {
                    if !answer.any || answer.closest.is_none_or(|h| h.t > t) {
                        tally.leaks += 1;
                        failure
                            .get_or_insert_with(|| format!("leak: closest {:?}, any {}", answer.closest, answer.any));
                    }
                }
                Expect::NotTriangle(own) => {
                    if answer.closest.is_some_and(|h| h.triangle == own) {
                        tally.self_hits += 1;
                        failure.get_or_insert_with(|| format!("self-hit on triangle {own}"));
                    }
                }
            }
            if let Some(failure) = failure
                && tally.examples.len() < EXAMPLES
            {
                tally.examples.push(format!("{failure} for {:?}", probe.ray));
            }
        }
        tally
    }

    /// Adds another tally's counts (and examples, up to the limit).
    pub fn add(&mut self, other: &Tally) {
        self.rays += other.rays;
        self.compared += other.compared;
        self.closest_disagreements += other.closest_disagreements;
        self.any_disagreements += other.any_disagreements;
        self.leaks += other.leaks;
        self.self_hits += other.self_hits;
        for example in &other.examples {
            if self.examples.len() < EXAMPLES {
                self.examples.push(example.clone());
            }
        }
    }

    /// No disagreement, leak or self-hit.
    pub fn is_clean(&self) -> bool {
        self.closest_disagreements == 0 && self.any_disagreements == 0 && self.leaks == 0 && self.self_hits == 0
    }
}

/// Barycentrics `(u, v)` of a uniformly random point on a triangle.
fn uniform_barycentrics(rng: &mut Rng) -> (f32, f32) {
    let (u, v) = (rng.next_f32(), rng.next_f32());
    if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) }
}

/// A uniformly random point of the cube `[-size, size]³`.
fn point_in_cube(rng: &mut Rng, size: f32) -> Vec3 {
    (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0) * size
}
