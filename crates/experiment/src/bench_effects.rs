//! The quick mode of the effects knob, as `rtgi bench-effects` prints it:
//! the plan's render, then each of its decisions reversed
//! ([`crate::measure::effect_renders`]), with its time and how much the
//! image changes ([`EffectsReport`]'s `Display` is the table).

use std::fmt;

use rtgi_image::{Difference, compare};
use rtgi_render::EffectPlan;
use serde::Serialize;

use crate::Subject;
use crate::measure::effect_renders;

/// One render of the comparison.
#[derive(Clone, Debug, Serialize)]
pub struct EffectsRow {
    /// `plan`, `+effect` or `-effect`.
    pub label: String,
    /// Median time of the render.
    pub median_ms: f64,
    /// Median time over the plan's median time.
    pub relative_time: f64,
    /// Difference from the planned render (same seed); `None` for the plan itself.
    pub difference: Option<Difference>,
}

/// What each decision of the plan costs or saves.
#[derive(Clone, Debug, Serialize)]
pub struct EffectsReport {
    /// The scene's name.
    pub scene: String,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Samples per pixel of each render.
    pub samples_per_pixel: u32,
    /// Worker threads.
    pub threads: usize,
    /// Timed renders per row.
    pub repeats: u32,
    /// The plan of the subject's settings.
    pub plan: EffectPlan,
    /// The plan first, then each reversal.
    pub rows: Vec<EffectsRow>,
}

/// Renders the subject with its plan and with each decision reversed,
/// `repeats` times each, on the current thread pool; `progress` hears each
/// render's label before it is measured.
pub fn bench_effects(subject: &Subject, repeats: usize, progress: &dyn Fn(&str)) -> EffectsReport {
    let settings = &subject.settings;
    let renders = effect_renders(subject, settings, repeats, progress);
    let (planned, reversals) = renders.split_first().expect("the plan is rendered first");
    let planned_ms = planned.time.median_ms;
    let rows = std::iter::once(EffectsRow {
        label: "plan".into(),
        median_ms: planned_ms,
        relative_time: 1.0,
        difference: None,
    })
    .chain(reversals.iter().map(|reversal| EffectsRow {
        label: reversal.label.clone(),
        median_ms: reversal.time.median_ms,
        relative_time: reversal.time.median_ms / planned_ms,
        difference: compare(&reversal.image, &planned.image),
    }))
    .collect();
    EffectsReport {
        scene: subject.name.clone(),
        width: settings.width,
        height: settings.height,
        samples_per_pixel: settings.samples_per_pixel,
        threads: rayon::current_num_threads(),
        repeats: repeats as u32,
        plan: EffectPlan::new(&subject.scene, settings),
        rows,
    }
}

/// The table (the plan is printed before it by the caller, which prints
/// it as the measuring starts).
impl fmt::Display for EffectsReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{}: {}x{} at {} spp, {} threads, median of {}",
            self.scene, self.width, self.height, self.samples_per_pixel, self.threads, self.repeats
        )?;
        writeln!(f, "{:<16} {:>10} {:>9} {:>12} {:>12}", "render", "ms", "x plan", "rmse", "max diff")?;
        for row in &self.rows {
            let (rmse, max) = row
                .difference
                .map_or(("-".into(), "-".into()), |d| (format!("{:.3e}", d.rmse), format!("{:.3e}", d.max_abs)));
            writeln!(
                f,
                "{:<16} {:>10.1} {:>9.2} {:>12} {:>12}",
                row.label, row.median_ms, row.relative_time, rmse, max
            )?;
        }
        writeln!(
            f,
            "+effect: an effect the plan omits, forced on (its difference must be 0: specialising only saves time)"
        )?;
        writeln!(
            f,
            "-effect: an effect the plan simulates, forced off (what it costs, and what the image loses without it)"
        )
    }
}
