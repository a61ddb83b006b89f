//! What a verification checks: the scenes with the rays each gets, the
//! structures with their parameters, and the linear scans they are
//! compared with. `rtgi verify` and the Python package's `rtgi.verify`
//! plan the same way, here.

use rtgi_math::Vec3;

use super::{Case, RayKind, adversarial_cases};
use crate::{AccelKind, BuildParams, Intersector};

/// The scenes of a verification and the rays of each kind each gets:
/// `scene` (its name and triangles) with `rays` shared among the generic
/// ray kinds, or, when `None`, the built-in adversarial scenes with `rays`
/// shared among them and, in each, among the generic kinds and its own.
/// Returns the name the report gives the set, and the cases.
pub fn cases(scene: Option<(String, Vec<[Vec3; 3]>)>, rays: usize, seed: u64) -> (String, Vec<(Case, usize)>) {
    match scene {
        Some((name, triangles)) => {
            let per_kind = rays.div_ceil(RayKind::ALL.len());
            let case = Case { name: name.clone(), triangles, special_rays: vec![] };
            (name, vec![(case, per_kind)])
        }
        None => {
            let kinds_per_case = RayKind::ALL.len() + 1;
            let count = adversarial_cases(0, seed).len();
            let per_kind = rays.div_ceil(count * kinds_per_case).max(1);
            let cases = adversarial_cases(per_kind, seed).into_iter().map(|c| (c, per_kind)).collect();
            ("built-in adversarial scenes".to_owned(), cases)
        }
    }
}

/// The structures to check of those `chosen` (the linear scan, the
/// reference, is left out): each with `params_for` its kind, or with
/// `exhaustive`, every configuration the tests check
/// ([`AccelKind::all_configurations`]); the peers chosen (which have no
/// build parameters to vary) come last.
pub fn configurations(
    chosen: &[AccelKind],
    exhaustive: bool,
    params_for: impl Fn(AccelKind) -> BuildParams,
) -> Vec<(AccelKind, BuildParams)> {
    let wanted = |kind: &AccelKind| chosen.contains(kind) && *kind != AccelKind::Linear;
    let mut configurations: Vec<(AccelKind, BuildParams)> = if exhaustive {
        AccelKind::all_configurations().into_iter().filter(|(kind, _)| wanted(kind)).collect()
    } else {
        AccelKind::ALL.iter().filter(|k| wanted(k)).map(|&kind| (kind, params_for(kind))).collect()
    };
    configurations.extend(AccelKind::PEERS.iter().filter(|k| wanted(k)).map(|&kind| (kind, params_for(kind))));
    configurations
}

/// The linear scans the configurations are compared with: one per
/// intersector they use, or `alone`'s when there are none (the linear scan
/// alone, checked for leaks and self-hits).
pub fn reference_intersectors(configurations: &[(AccelKind, BuildParams)], alone: Intersector) -> Vec<Intersector> {
    let used: Vec<Intersector> =
        Intersector::ALL.iter().copied().filter(|&i| configurations.iter().any(|(_, p)| p.intersector == i)).collect();
    if used.is_empty() { vec![alone] } else { used }
}
