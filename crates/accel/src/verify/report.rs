//! The verification of a scene, as a report: every structure's answers
//! against the linear scan's, bit for bit, on each kind of probe ray,
//! summed by ray kind and by structure (what `rtgi verify` prints).

use std::collections::BTreeMap;

use serde::Serialize;

use super::{Answer, Case, ProbeRay, Tally};
use crate::{Accel, AccelKind, BuildError, BuildParams, Intersector, LinearScan, Traversal};

/// One row of the table: a ray kind, summed over scenes and structures.
#[derive(Clone, Debug, Default, Serialize)]
pub struct KindRow {
    /// The ray kind's name.
    pub kind: String,
    /// Rays of this kind (per structure).
    pub rays: usize,
    /// Of those, the rays the linear scan answered; the rest were compared
    /// with the first structure checked.
    pub linear_rays: usize,
    /// Summed over the structures (the linear scan included for leaks and self-hits).
    pub tally: Tally,
    /// Summed over the peers' backends (Embree): their differences from
    /// the reference, which are not failures.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub peers: Option<Tally>,
}

impl KindRow {
    /// Adds one structure's failures on this kind's rays (the row counts
    /// its rays itself); leaks only of a test that claims watertightness:
    /// Möller-Trumbore's are reported per structure.
    pub fn add_failures(&mut self, tally: &Tally, watertight: bool) {
        let leaks = if watertight { tally.leaks } else { 0 };
        self.tally.add(&Tally { rays: 0, compared: 0, leaks, ..tally.clone() });
    }
}

/// The totals of one structure over every scene and kind.
#[derive(Clone, Debug, Serialize)]
pub struct StructureRow {
    /// The structure's label ([`label`]).
    pub structure: String,
    /// Whether it claims watertightness (its leaks are failures).
    pub watertight: bool,
    /// A peer's backend (Embree), not held to the exactness contract: its
    /// differences, leaks and self-hits are reported, not failures.
    pub peer: bool,
    /// Its answers, summed.
    pub tally: Tally,
}

/// A verification: rows by ray kind and by structure.
#[derive(Clone, Debug, Serialize)]
pub struct VerifyReport {
    /// The scene checked (a file, or the built-in adversarial scenes).
    pub scene: String,
    /// The seed of its rays.
    pub seed: u64,
    /// One row per ray kind, summed over scenes and structures.
    pub kinds: Vec<KindRow>,
    /// One row per structure, summed over scenes and ray kinds.
    pub structures: Vec<StructureRow>,
}

impl VerifyReport {
    /// An empty report of `scene`'s rays drawn with `seed`.
    pub fn new(scene: String, seed: u64) -> Self {
        Self { scene, seed, kinds: Vec::new(), structures: Vec::new() }
    }

    /// Whether a structure held to the contract disagreed with the
    /// reference, hit the triangle its ray left, or (claiming
    /// watertightness) let a ray leak.
    pub fn failed(&self) -> bool {
        self.structures.iter().filter(|s| !s.peer).any(|s| {
            let t = &s.tally;
            t.closest_disagreements + t.any_disagreements + t.self_hits > 0 || (s.watertight && t.leaks > 0)
        })
    }
}

/// A structure's name in the report: its kind and the parameters that shape it.
pub fn label(kind: AccelKind, params: &BuildParams) -> String {
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

/// Checks every configuration on one scene's rays, adding to the kind rows
/// and the structure totals.
///
/// `linear_rays` bounds the rays of each kind the linear scan answers
/// (the rest are compared with the first structure); `progress` is called
/// with a description of the step done, which it may ignore.
pub fn check_case(
    report: &mut VerifyReport,
    case: &Case,
    rays: &[(&'static str, Vec<ProbeRay>)],
    configurations: &[(AccelKind, BuildParams)],
    intersectors: &[Intersector],
    linear_rays: usize,
    progress: &mut dyn FnMut(&dyn Fn() -> String),
) -> Result<(), BuildError> {
    let mut kinds: BTreeMap<String, KindRow> = report.kinds.drain(..).map(|row| (row.kind.clone(), row)).collect();
    let structures = &mut report.structures;
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
                progress(&|| format!("{}: built {name}", case.name));
                Ok((*kind, name, accel))
            })
            .collect::<Result<_, BuildError>>()?;
        for (kind, probes) in rays {
            let ray_kind = *kind;
            let checked = probes.len().min(linear_rays);
            // In chunks, for the progress line: on a large scene the scan is most of the time.
            let mut linear_answers = Vec::with_capacity(checked);
            for chunk in probes[..checked].chunks(4096) {
                linear_answers.extend(Answer::all(&linear, chunk));
                progress(&|| {
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
                progress(&|| format!("{}: {ray_kind} rays: {} through {name}", case.name, probes.len()));
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
    report.kinds = kinds.into_values().collect();
    Ok(())
}

/// The tables `rtgi verify` prints: by ray kind (and the peers' by ray
/// kind), by structure, what the columns mean, and the examples of failures.
impl std::fmt::Display for VerifyReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "rtgi verify: {} (seed {})", self.scene, self.seed)?;
        let kind_table = |f: &mut std::fmt::Formatter<'_>, tally: &dyn Fn(&KindRow) -> Tally| {
            writeln!(f)?;
            writeln!(
                f,
                "{:<15} {:>10} {:>12} {:>14} {:>14} {:>8} {:>10}",
                "ray kind", "rays", "linear rays", "closest diff.", "any-hit diff.", "leaks", "self-hits"
            )?;
            for row in &self.kinds {
                let t = tally(row);
                writeln!(
                    f,
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
            Ok(())
        };
        kind_table(f, &|row| row.tally.clone())?;
        if self.kinds.iter().any(|row| row.peers.is_some()) {
            writeln!(f)?;
            write!(f, "peers by ray kind (peer: differences are not failures)")?;
            kind_table(f, &|row| row.peers.clone().unwrap_or_default())?;
        }
        writeln!(f)?;
        writeln!(
            f,
            "{:<44} {:>10} {:>14} {:>14} {:>8} {:>10}",
            "structure", "rays", "closest diff.", "any-hit diff.", "leaks", "self-hits"
        )?;
        for s in &self.structures {
            let t = &s.tally;
            let leaks = if s.watertight || t.leaks == 0 { t.leaks.to_string() } else { format!("({})", t.leaks) };
            writeln!(
                f,
                "{:<44} {:>10} {:>14} {:>14} {:>8} {:>10}",
                s.structure, t.rays, t.closest_disagreements, t.any_disagreements, leaks, t.self_hits
            )?;
        }
        writeln!(f)?;
        writeln!(
            f,
            "Disagreements are differences in any bit of the closest hit (triangle, t, beta, gamma) or in the any-hit \
             answer, against the linear scan (on big scenes the linear scan answers the first rays of each kind; the \
             rest are compared with the first structure). Leaks are rays aimed inside a closed surface that hit nothing \
             by the point aimed at; leaks in parentheses are those of a test that does not claim watertightness \
             (moller-trumbore). Self-hits are rays leaving a triangle that hit it again."
        )?;
        if self.structures.iter().any(|s| s.peer) {
            writeln!(
                f,
                "Structures marked (peer) are other people's backends (Embree), not held to the exactness contract: \
                 they break ties between triangles at equal t in their own order and round differently on grazing \
                 rays. peer: differences are not failures, and do not change the exit status."
            )?;
        }
        for s in &self.structures {
            let t = &s.tally;
            let failed =
                t.closest_disagreements + t.any_disagreements + t.self_hits > 0 || (s.watertight && t.leaks > 0);
            let note = if s.peer { " (a difference, not a failure)" } else { "" };
            if (s.peer && !t.is_clean()) || (!s.peer && failed) {
                for example in &t.examples {
                    writeln!(f, "  {}{note}: {example}", s.structure)?;
                }
            }
        }
        Ok(())
    }
}
