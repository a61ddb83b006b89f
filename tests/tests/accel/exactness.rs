//! The exactness contract (see `rtgi_accel`'s documentation): every
//! structure, leaf size and bin count answers every ray exactly as the
//! linear scan does, bit for bit, on the adversarial scenes of
//! `rtgi_accel::verify`, one ray at a time and through the batch queries
//! (packets); rays aimed inside closed surfaces never leak, and secondary
//! rays never hit the triangle they leave. Every SIMD level the CPU has
//! gives the same answers.

use rtgi_accel::verify::{Answer, Tally, adversarial_cases};
use rtgi_accel::{Intersector, LinearScan};
use rtgi_tests::for_every_variant;

#[test]
fn adversarial_cases_agree_bit_for_bit_with_the_linear_scan() {
    let mut report = Vec::new();
    for case in adversarial_cases(2500, 12) {
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
            for (((kind, probes), expected), query) in rays
                .iter()
                .zip(reference)
                .flat_map(|(rays, expected)| [((rays, expected), "single"), ((rays, expected), "batch")])
            {
                // Every ray alone, and in batches (packets of coherent rays where
                // the structure traces them): both must be the linear scan's answers.
                let answers =
                    if query == "single" { Answer::all(accel, probes) } else { Answer::all_batched(accel, probes) };
                let mut tally = Tally::of(probes, &answers, Some(expected));
                // Möller-Trumbore is not watertight: its leaks are measured
                // elsewhere; it must still agree with its own linear scan.
                if !params.intersector.is_watertight() {
                    tally.leaks = 0;
                }
                if !tally.is_clean() {
                    let Tally { closest_disagreements, any_disagreements, leaks, self_hits, .. } = tally;
                    report.push(format!(
                        "{}: {label}: {kind} ({query}): {closest_disagreements} closest and {any_disagreements} \
                         any-hit disagreements, {leaks} leaks, {self_hits} self-hits of {} rays; first: {:?}",
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

/// The wide BVHs' kernels exist for several instruction sets (portable,
/// AVX2, AVX-512), chosen at run time: each level the CPU supports must
/// answer every adversarial ray as the linear scan does, alone and in
/// batches.
#[test]
fn every_simd_level_gives_the_same_answers() {
    use rtgi_accel::AccelKind;
    use rtgi_accel::simd::{SimdLevel, limit_simd_level};
    let detected = SimdLevel::detected();
    let mut failures = Vec::new();
    let cases = adversarial_cases(1500, 5);
    for &level in SimdLevel::ALL.iter().filter(|&&level| level <= detected) {
        assert_eq!(limit_simd_level(level), level);
        for case in &cases {
            let linear = LinearScan::new(&case.triangles, Intersector::Watertight);
            for kind in [AccelKind::Bvh4, AccelKind::Bvh8] {
                let accel = kind.build(&case.triangles, &kind.default_params());
                for (ray_kind, probes) in case.rays(400, 5) {
                    let expected = Answer::all(&linear, &probes);
                    for answers in [Answer::all(accel.as_ref(), &probes), Answer::all_batched(accel.as_ref(), &probes)]
                    {
                        let tally = Tally::of(&probes, &answers, Some(&expected));
                        if tally.closest_disagreements + tally.any_disagreements > 0 {
                            failures.push(format!("{level}: {}: {kind}: {ray_kind}: {:?}", case.name, tally.examples));
                        }
                    }
                }
            }
        }
    }
    limit_simd_level(detected);
    if detected == SimdLevel::Portable {
        eprintln!("note: this CPU has neither AVX2 nor AVX-512; only the portable kernels were tested");
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
