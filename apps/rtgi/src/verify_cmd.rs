//! `rtgi verify`: every chosen structure against the linear scan, bit for
//! bit, on rays of the kinds that expose inexact structures.

use std::collections::BTreeMap;
use std::time::Instant;

use anyhow::{Result, bail};
use rtgi_accel::verify::{Answer, Case, ProbeRay, RayKind, Tally, adversarial_cases};
use rtgi_accel::{Accel, AccelKind, BuildParams, Intersector, LinearScan, Traversal};
use serde::Serialize;

use crate::cli::VerifyArgs;
use crate::common::{check_output_folder, load_scene, write_atomically};
use crate::output::outln;

/// One row of the table: a ray kind, summed over scenes and structures.
#[derive(Debug, Default, Serialize)]
struct KindRow {
    kind: String,
    /// Rays of this kind (per structure).
    rays: usize,
    /// Of those, the rays the linear scan answered; the rest were compared
    /// with the first structure checked.
    linear_rays: usize,
    /// Summed over the structures (the linear scan included for leaks and self-hits).
    tally: Tally,
    /// Summed over the peers' backends (Embree): their differences from
    /// the reference, which are not failures.
    #[serde(skip_serializing_if = "Option::is_none")]
    peers: Option<Tally>,
}

impl KindRow {
    /// Adds one structure's failures on this kind's rays (the row counts
    /// its rays itself); leaks only of a test that claims watertightness:
    /// Möller-Trumbore's are reported per structure.
    fn add_failures(&mut self, tally: &Tally, watertight: bool) {
        let leaks = if watertight { tally.leaks } else { 0 };
        self.tally.add(&Tally { rays: 0, compared: 0, leaks, ..tally.clone() });
    }
}

/// The totals of one structure over every scene and kind.
#[derive(Debug, Serialize)]
struct StructureRow {
    structure: String,
    /// Whether it claims watertightness (its leaks are failures).
    watertight: bool,
    /// A peer's backend (Embree), not held to the exactness contract: its
    /// differences, leaks and self-hits are reported, not failures.
    peer: bool,
    tally: Tally,
}

#[derive(Debug, Serialize)]
struct Report {
    scene: String,
    seed: u64,
    kinds: Vec<KindRow>,
    structures: Vec<StructureRow>,
}

pub(crate) fn run(args: &VerifyArgs) -> Result<()> {
    if let Some(json) = &args.json {
        check_output_folder(json)?;
    }
    // Rays are shared evenly among the scenes and, in each, among the kinds:
    // the generic ones and (for the built-in scenes) the scene's own.
    let kinds_per_case = RayKind::ALL.len() + 1;
    let (scene_name, cases) = match &args.scene {
        Some(path) => {
            let loaded = load_scene(Some(path))?;
            let per_kind = (args.rays as usize).div_ceil(RayKind::ALL.len());
            let case =
                Case { name: loaded.name.clone(), triangles: loaded.scene.triangle_positions(), special_rays: vec![] };
            (loaded.name, vec![(case, per_kind)])
        }
        None => {
            let count = adversarial_cases(0, args.seed.value).len();
            let per_kind = (args.rays as usize).div_ceil(count * kinds_per_case).max(1);
            let cases = adversarial_cases(per_kind, args.seed.value).into_iter().map(|c| (c, per_kind)).collect();
            ("built-in adversarial scenes".to_owned(), cases)
        }
    };
    let configurations = configurations(args);
    // The linear scan of each intersector the structures use; with the
    // linear scan alone, that of the chosen intersector (checked for leaks
    // and self-hits).
    let mut intersectors: Vec<Intersector> =
        Intersector::ALL.iter().copied().filter(|&i| configurations.iter().any(|(_, p)| p.intersector == i)).collect();
    if intersectors.is_empty() {
        intersectors.push(args.build.intersector);
    }
    let pool = args.threads.pool()?;
    let start = Instant::now();

    let mut kinds: BTreeMap<String, KindRow> = BTreeMap::new();
    let mut structures: Vec<StructureRow> = Vec::new();
    for (case, per_kind) in &cases {
        let rays = pool.install(|| case.rays(*per_kind, args.seed.value));
        let budget_rays = (args.linear_budget / case.triangles.len().max(1) as u64) as usize;
        let ray_count: usize = rays.iter().map(|(_, r)| r.len()).sum();
        if cases.len() == 1 {
            eprintln!(
                "{}: {} triangles, {ray_count} rays through {} structures, the linear scan's answers for up to \
                 {budget_rays} of each kind (--linear-budget)",
                case.name,
                case.triangles.len(),
                configurations.len()
            );
        }
        let mut heartbeat = Heartbeat { start, last: Instant::now() };
        pool.install(|| {
            check_case(
                case,
                &rays,
                &configurations,
                &intersectors,
                budget_rays,
                (&mut kinds, &mut structures),
                &mut heartbeat,
            )
        })?;
        eprintln!(
            "{}: {} triangles, {} rays per structure checked ({:.1} s)",
            case.name,
            case.triangles.len(),
            ray_count,
            start.elapsed().as_secs_f64()
        );
    }
    let report = Report { scene: scene_name, seed: args.seed.value, kinds: kinds.into_values().collect(), structures };
    // A reader that stops early (`| head`) must change neither the JSON
    // written nor the exit status that says whether verification failed.
    let printed = print_report(&report);
    if let Some(json) = &args.json {
        write_atomically(json, serde_json::to_string_pretty(&report)?.as_bytes())?;
    }
    let failed = report.structures.iter().filter(|s| !s.peer).any(|s| {
        let t = &s.tally;
        t.closest_disagreements + t.any_disagreements + t.self_hits > 0 || (s.watertight && t.leaks > 0)
    });
    if failed {
        bail!("the structures do not all answer exactly as the linear scan, or rays leaked (see the table)");
    }
    printed
}

/// The structures to check, each with its build parameters; the peers
/// chosen (which have no build parameters to vary) come last.
fn configurations(args: &VerifyArgs) -> Vec<(AccelKind, BuildParams)> {
    let chosen = |kind: &AccelKind| args.accel.0.contains(kind) && *kind != AccelKind::Linear;
    let mut configurations: Vec<(AccelKind, BuildParams)> = if args.exhaustive {
        AccelKind::all_configurations().into_iter().filter(|(kind, _)| chosen(kind)).collect()
    } else {
        AccelKind::ALL.iter().filter(|k| chosen(k)).map(|&kind| (kind, args.build.params_for(kind))).collect()
    };
    configurations
        .extend(AccelKind::PEERS.iter().filter(|k| chosen(k)).map(|&kind| (kind, args.build.params_for(kind))));
    configurations
}

fn label(kind: AccelKind, params: &BuildParams) -> String {
    if kind.is_peer() {
        return format!("{kind} (peer)");
    }
    let mut label = format!("{kind} (leaf {}", params.max_leaf_size);
    if kind == AccelKind::Sah {
        label += &format!(", {} bins", params.sah_bins);
    }
    label += &format!(", {}", params.intersector);
    if params.traversal != Traversal::Robust {
        label += &format!(", {} traversal", params.traversal);
    }
    label + ")"
}

/// A progress line on standard error when a check has been quiet for a
/// while: a large scene takes minutes, and a silent program looks hung.
struct Heartbeat {
    start: Instant,
    last: Instant,
}

impl Heartbeat {
    const QUIET: std::time::Duration = std::time::Duration::from_secs(5);

    fn beat(&mut self, what: impl FnOnce() -> String) {
        if self.last.elapsed() >= Self::QUIET {
            eprintln!("  {} ({:.1} s)", what(), self.start.elapsed().as_secs_f64());
            self.last = Instant::now();
        }
    }
}

/// Checks every configuration on one scene's rays, adding to the kind rows
/// and the structure totals.
fn check_case(
    case: &Case,
    rays: &[(&'static str, Vec<ProbeRay>)],
    configurations: &[(AccelKind, BuildParams)],
    intersectors: &[Intersector],
    linear_rays: usize,
    (kinds, structures): (&mut BTreeMap<String, KindRow>, &mut Vec<StructureRow>),
    heartbeat: &mut Heartbeat,
) -> anyhow::Result<()> {
    let add = |name: String, watertight: bool, peer: bool, tally: &Tally, structures: &mut Vec<StructureRow>| {
        match structures.iter_mut().find(|s| s.structure == name) {
            Some(row) => row.tally.add(tally),
            None => structures.push(StructureRow { structure: name, watertight, peer, tally: tally.clone() }),
        }
    };
    for &intersector in intersectors {
        let watertight = intersector.is_watertight();
        let linear = LinearScan::new(&case.triangles, intersector);
        let chosen: Vec<&(AccelKind, BuildParams)> =
            configurations.iter().filter(|(_, p)| p.intersector == intersector).collect();
        let built: Vec<(AccelKind, String, Box<dyn Accel>)> = chosen
            .iter()
            .map(|(kind, params)| {
                let name = label(*kind, params);
                let accel = kind.try_build(&case.triangles, params)?;
                heartbeat.beat(|| format!("{}: built {name}", case.name));
                Ok((*kind, name, accel))
            })
            .collect::<anyhow::Result<_>>()?;
        for (kind, probes) in rays {
            let ray_kind = *kind;
            let checked = probes.len().min(linear_rays);
            // In chunks, for the progress line: on a large scene the scan is most of the time.
            let mut linear_answers = Vec::with_capacity(checked);
            for chunk in probes[..checked].chunks(4096) {
                linear_answers.extend(Answer::all(&linear, chunk));
                heartbeat.beat(|| {
                    format!(
                        "{}: {ray_kind} rays: {} of {checked} through the linear scan ({intersector})",
                        case.name,
                        linear_answers.len()
                    )
                });
            }
            let linear_tally = Tally::of(&probes[..checked], &linear_answers, None);
            add(format!("linear ({intersector})"), watertight, false, &linear_tally, structures);
            // The reference: the linear scan where it answered, else the
            // first of our structures (never a peer's).
            let mut reference = linear_answers;
            if checked < probes.len()
                && let Some((_, _, first)) = built.iter().find(|(kind, _, _)| !kind.is_peer())
            {
                reference.extend(Answer::all(first.as_ref(), &probes[checked..]));
            }
            let row = kinds
                .entry(kind.to_string())
                .or_insert_with(|| KindRow { kind: kind.to_string(), ..KindRow::default() });
            row.rays += probes.len();
            row.linear_rays += checked;
            row.add_failures(&linear_tally, watertight);
            for (kind, name, accel) in &built {
                let tally = Tally::of(probes, &Answer::all(accel.as_ref(), probes), Some(&reference));
                add(name.clone(), watertight, kind.is_peer(), &tally, structures);
                heartbeat.beat(|| format!("{}: {ray_kind} rays: {} through {name}", case.name, probes.len()));
                if kind.is_peer() {
                    row.peers.get_or_insert_with(Tally::default).add(&Tally { rays: 0, compared: 0, ..tally });
                    continue;
                }
                row.add_failures(&tally, watertight);
                // The wide BVHs trace batches as packets: those answers too.
                if kind.node_width().is_some_and(|width| width > 2) {
                    let batched = Tally::of(probes, &Answer::all_batched(accel.as_ref(), probes), Some(&reference));
                    add(format!("{name} batch"), watertight, false, &batched, structures);
                    row.add_failures(&batched, watertight);
                }
            }
        }
    }
    Ok(())
}

fn print_report(report: &Report) -> Result<()> {
    outln!("rtgi verify: {} (seed {})", report.scene, report.seed)?;
    outln!()?;
    outln!(
        "{:<15} {:>10} {:>12} {:>14} {:>14} {:>8} {:>10}",
        "ray kind",
        "rays",
        "linear rays",
        "closest diff.",
        "any-hit diff.",
        "leaks",
        "self-hits"
    )?;
    for row in &report.kinds {
        let t = &row.tally;
        outln!(
            "{:<15} {:>10} {:>12} {:>14} {:>14} {:>8} {:>10}",
            row.kind,
            row.rays,
            row.linear_rays,
            t.closest_disagreements,
            t.any_disagreements,
            t.leaks,
            t.self_hits
        )?;
    }
    if report.kinds.iter().any(|row| row.peers.is_some()) {
        outln!()?;
        outln!("peers by ray kind (peer: differences are not failures)")?;
        outln!(
            "{:<15} {:>10} {:>12} {:>14} {:>14} {:>8} {:>10}",
            "ray kind",
            "rays",
            "linear rays",
            "closest diff.",
            "any-hit diff.",
            "leaks",
            "self-hits"
        )?;
        for row in &report.kinds {
            let t = row.peers.clone().unwrap_or_default();
            outln!(
                "{:<15} {:>10} {:>12} {:>14} {:>14} {:>8} {:>10}",
                row.kind,
                row.rays,
                row.linear_rays,
                t.closest_disagreements,
                t.any_disagreements,
                t.leaks,
                t.self_hits
            )?;
        }
    }
    outln!()?;
    outln!(
        "{:<44} {:>10} {:>14} {:>14} {:>8} {:>10}",
        "structure",
        "rays",
        "closest diff.",
        "any-hit diff.",
        "leaks",
        "self-hits"
    )?;
    for s in &report.structures {
        let t = &s.tally;
        let leaks = if s.watertight || t.leaks == 0 { t.leaks.to_string() } else { format!("({})", t.leaks) };
        outln!(
            "{:<44} {:>10} {:>14} {:>14} {:>8} {:>10}",
            s.structure,
            t.rays,
            t.closest_disagreements,
            t.any_disagreements,
            leaks,
            t.self_hits
        )?;
    }
    outln!()?;
    outln!(
        "Disagreements are differences in any bit of the closest hit (triangle, t, beta, gamma) or in the any-hit \
         answer, against the linear scan (on big scenes the linear scan answers the first rays of each kind; the \
         rest are compared with the first structure). Leaks are rays aimed inside a closed surface that hit nothing \
         by the point aimed at; leaks in parentheses are those of a test that does not claim watertightness \
         (moller-trumbore). Self-hits are rays leaving a triangle that hit it again."
    )?;
    if report.structures.iter().any(|s| s.peer) {
        outln!(
            "Structures marked (peer) are other people's backends (Embree), not held to the exactness contract: \
             they break ties between triangles at equal t in their own order and round differently on grazing rays. \
             peer: differences are not failures, and do not change the exit status."
        )?;
    }
    for s in &report.structures {
        let t = &s.tally;
        if s.peer && !t.is_clean() {
            for example in &t.examples {
                outln!("  {} (a difference, not a failure): {example}", s.structure)?;
            }
        } else if t.closest_disagreements + t.any_disagreements + t.self_hits > 0 || (s.watertight && t.leaks > 0) {
            for example in &t.examples {
                outln!("  {}: {example}", s.structure)?;
            }
        }
    }
    Ok(())
}
