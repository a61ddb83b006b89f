//! How the reports write numbers: milliseconds, timings, plain numbers,
//! squared biases and efficiencies, the same in tables, findings, plots
//! and panels. A leaf of the crate: it uses only the statistics' types.

use crate::stats::{ImageError, Timing};

/// Formats milliseconds as a person reads them.
pub fn format_ms(ms: f64) -> String {
    if ms >= 100.0 {
        format!("{ms:.0}")
    } else if ms >= 1.0 {
        format!("{ms:.2}")
    } else {
        format!("{ms:.4}")
    }
}

/// `median (min–max)` of a timing, in ms.
pub fn format_timing(t: &Timing) -> String {
    format!("{} ({}–{})", format_ms(t.median_ms), format_ms(t.min_ms), format_ms(t.max_ms))
}

/// The efficiency `1/(MSE·s)` for a table cell, or "— (biased)" where the
/// bias is resolved: a biased estimator has none.
pub fn format_efficiency(error: &ImageError, time: &Timing) -> String {
    if error.bias_resolved() { "— (biased)".to_owned() } else { format_number(error.efficiency(time.median_ms)) }
}

/// The squared bias, or that it is below what the seeds resolve.
pub fn format_bias(error: &ImageError) -> String {
    if error.bias_resolved() {
        format_number(error.bias2)
    } else if error.seeds < 2 {
        "— (1 seed)".to_owned()
    } else {
        format!("not resolved (< {})", format_number(error.bias_resolution))
    }
}

/// A number in about 4 significant digits, in scientific notation when small or large.
pub fn format_number(x: f64) -> String {
    if x == 0.0 {
        "0".to_owned()
    } else if (1e-3..1e5).contains(&x.abs()) {
        let decimals = (3 - x.abs().log10().floor() as i32).clamp(0, 6) as usize;
        let text = format!("{x:.decimals$}");
        if text.contains('.') { text.trim_end_matches('0').trim_end_matches('.').to_owned() } else { text }
    } else {
        format!("{x:.3e}")
    }
}
