//! The exactness contract (see `rtgi_accel`'s documentation): every
//! structure, leaf size and bin count answers every ray exactly as the
//! linear scan does, bit for bit, on the adversarial scenes of
//! `rtgi_accel::verify`; rays aimed inside closed surfaces never leak, and
//! secondary rays never hit the triangle they leave.

use rtgi_accel::verify::{Answer, Tally, adversarial_cases};
use rtgi_accel::{Intersector, LinearScan};
use rtgi_tests::for_every_variant;

#[test]
fn adversarial_cases_agree_bit_for_bit_with_the_linear_scan() {
    let mut report = Vec::new();
    for case in adversarial_cases(4000, 12) {
        let rays = case.rays(1500, 12);
        let references: Vec<(Intersector, Vec<Vec<Answer>>)> = Intersector::ALL
            .iter()
            .map(|&i| {
                let linear = LinearScan::new(&case.triangles, i);
                (i, rays.iter().map(|(_, r)| Answer::all(&linear, r)).collect())
            })
            .collect();
        for_every_variant(&case.triangles, |label, accel, params| {
            let reference = &references.iter().find(|(i, _)| *i == params.intersector).expect("every intersector").1;
            for ((kind, probes), expected) in rays.iter().zip(reference) {
                let mut tally = Tally::of(probes, &Answer::all(accel, probes), Some(expected));
                // Möller-Trumbore is not watertight: its leaks are measured
                // elsewhere; it must still agree with its own linear scan.
                if params.intersector != Intersector::Watertight {
                    tally.leaks = 0;
                }
                if !tally.is_clean() {
                    let Tally { closest_disagreements, any_disagreements, leaks, self_hits, .. } = tally;
                    report.push(format!(
                        "{}: {label}: {kind}: {closest_disagreements} closest and {any_disagreements} any-hit \
                         disagreements, {leaks} leaks, {self_hits} self-hits of {} rays; first: {:?}",
                        case.name,
                        probes.len(),
                        tally.examples.first()
                    ));
                }
            }
        });
    }
    assert!(
        report.is_empty(),
        "{} failures:\n{}",
        report.len(),
        report.iter().take(40).cloned().collect::<Vec<_>>().join("\n")
    );
}

/// Rays from around closed meshes (sphere, cube, cylinder) aimed at
/// uniformly random points inside them, with the meshes at offsets 2^0 …
/// 2^23 and scales 2^-20 … 2^20: every one must hit by the point aimed at,
/// in the closest-hit and the any-hit query. Two million rays, through two
/// structures (the others answer exactly as these do, by the test above).
#[test]
fn rays_aimed_inside_closed_meshes_never_leak() {
    use rtgi_accel::{AccelKind, BuildParams};
    let mut failures = Vec::new();
    for case in adversarial_cases(700_000, 99).into_iter().filter(|c| c.name.starts_with("closed-")) {
        let (_, inside) =
            case.special_rays.iter().find(|(kind, _)| *kind == "inside").expect("closed meshes have inside rays");
        assert!(inside.len() >= 600_000, "{}: {} rays", case.name, inside.len());
        for kind in [AccelKind::Sah, AccelKind::ObjectMedian] {
            let accel = kind.build(&case.triangles, &BuildParams::default());
            let tally = Tally::of(inside, &Answer::all(accel.as_ref(), inside), None);
            if tally.leaks > 0 {
                failures.push(format!(
                    "{}: {kind}: {} of {} rays leaked: {:?}",
                    case.name,
                    tally.leaks,
                    inside.len(),
                    tally.examples
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
