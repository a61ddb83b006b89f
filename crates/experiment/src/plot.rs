//! SVG line plots with error bars, drawn by `plotters` (its SVG backend
//! only: no fonts are read, the viewer renders the text).

use plotters::coord::ranged1d::ValueFormatter;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::ExperimentError;
use crate::format::format_number;
use crate::machine::Machine;

/// One line of a plot.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    /// The curve's name in the legend.
    pub label: String,
    /// `(x, y)`, in the order they are joined.
    pub points: Vec<(f64, f64)>,
    /// Per point, the `(low, high)` of an error bar (the min and max of the
    /// repeats), or none.
    pub bars: Vec<Option<(f64, f64)>>,
    /// Per point, the `(low, high)` of a horizontal error bar (a time's min
    /// and max, where time is on the x axis), or none.
    pub x_bars: Vec<Option<(f64, f64)>>,
    /// A guide (a fitted or expected law) rather than measurements: drawn dashed, without markers.
    pub guide: bool,
    /// Markers (and bars) without a line joining them: configurations that are not a sequence.
    pub markers_only: bool,
    /// Per point, whether it is an upper bound rather than a measurement
    /// (a rate never seen, at [`rate_or_bound`]'s bound): drawn as a shaded
    /// column from the axis up to the bound, never joined to the curve.
    pub bounds: Vec<bool>,
    /// Per point, a short text drawn beside its marker (empty: none).
    pub point_labels: Vec<String>,
}

impl Curve {
    /// A curve of measurements through `points`, without error bars.
    pub fn new(label: impl Into<String>, points: Vec<(f64, f64)>) -> Curve {
        Curve {
            label: label.into(),
            bars: vec![None; points.len()],
            x_bars: vec![None; points.len()],
            bounds: vec![false; points.len()],
            point_labels: vec![String::new(); points.len()],
            points,
            guide: false,
            markers_only: false,
        }
    }

    /// The curve with, per point, whether it is an upper bound rather than
    /// a measurement; panics unless there is one per point.
    pub fn with_bounds(mut self, bounds: Vec<bool>) -> Curve {
        assert_eq!(bounds.len(), self.points.len(), "one flag per point");
        self.bounds = bounds;
        self
    }

    /// The curve with a text beside each point's marker (empty for none);
    /// panics unless there is one per point.
    pub fn with_point_labels(mut self, labels: Vec<String>) -> Curve {
        assert_eq!(labels.len(), self.points.len(), "one label per point");
        self.point_labels = labels;
        self
    }

    /// Whether point `i` is an upper bound.
    fn is_bound(&self, i: usize) -> bool {
        self.bounds.get(i).copied().unwrap_or(false)
    }

    /// The curve with an error bar per point; panics unless there is one per point.
    pub fn with_bars(mut self, bars: Vec<Option<(f64, f64)>>) -> Curve {
        assert_eq!(bars.len(), self.points.len(), "one bar per point");
        self.bars = bars;
        self
    }

    /// The curve with a horizontal error bar per point; panics unless there is one per point.
    pub fn with_x_bars(mut self, bars: Vec<Option<(f64, f64)>>) -> Curve {
        assert_eq!(bars.len(), self.points.len(), "one bar per point");
        self.x_bars = bars;
        self
    }

    /// A curve of error against time with spread in both directions: each
    /// point is `(time, error)` with the time's min–max and the error's min–max.
    pub fn error_against_time(label: impl Into<String>, points: &[(crate::stats::Timing, f64, f64, f64)]) -> Curve {
        Curve::new(label, points.iter().map(|(t, e, _, _)| (t.median_ms, *e)).collect())
            .with_bars(points.iter().map(|(_, _, lo, hi)| Some((*lo, *hi))).collect())
            .with_x_bars(points.iter().map(|(t, _, _, _)| Some((t.min_ms, t.max_ms))).collect())
    }

    /// A guide (a fitted or expected law) through `points`, drawn dashed.
    pub fn guide(label: impl Into<String>, points: Vec<(f64, f64)>) -> Curve {
        Curve { guide: true, ..Curve::new(label, points) }
    }
}

/// A rate of `count` events in `trials`, for a log axis: the rate itself,
/// or when none was seen, `3 / trials`, the 95% upper bound on a rate never
/// seen in that many trials (the "rule of three"). Zero has no place on a
/// log axis, and the bound says what the check resolves.
pub fn rate_or_bound(count: f64, trials: f64) -> f64 {
    if count > 0.0 { count / trials.max(1.0) } else { 3.0 / trials.max(1.0) }
}

/// Whether [`rate_or_bound`] of `count` events is a bound (none seen)
/// rather than a measured rate: for [`Curve::with_bounds`].
pub fn is_bound(count: f64) -> bool {
    count <= 0.0
}

/// An estimate with its standard error for a legend: `0.75 ± 0.012`, with
/// as many decimals as the error's first significant digit needs (two at
/// least, six at most), or the value alone when the error is unknown or
/// rounds to zero at six decimals.
pub fn with_standard_error(value: f64, standard_error: Option<f64>) -> String {
    match standard_error.filter(|se| se.is_finite() && *se >= 0.5e-6) {
        Some(se) => {
            let decimals = (-se.log10().floor()).clamp(2.0, 6.0) as usize;
            format!("{value:.decimals$} ± {se:.decimals$}")
        }
        None => format!("{value:.2}"),
    }
}

/// What an axis of [`rate_or_bound`] values says of its zeros.
pub const BOUND_NOTE: &str = "none seen: at the 95% bound 3/N";

#[derive(Clone, Debug, PartialEq)]
/// One SVG plot: curves on linear or logarithmic axes.
pub struct Plot {
    /// File name, `*.svg`.
    pub file: String,
    /// The title above the plot.
    pub title: String,
    /// Axis labels, with units.
    pub x_label: String,
    /// The y axis's label, with units.
    pub y_label: String,
    /// Whether the x axis is logarithmic.
    pub log_x: bool,
    /// Whether the y axis is logarithmic.
    pub log_y: bool,
    /// The curves, drawn in order.
    pub curves: Vec<Curve>,
    /// Where the legend goes: the corner the curves leave free.
    pub legend: Corner,
    /// The y axis's range when it is set rather than fitted to the curves:
    /// room for the legend beside lines that span the whole width.
    pub y_range: Option<(f64, f64)>,
}

/// A corner of the plotting area.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Corner {
    #[default]
    /// Top right.
    UpperRight,
    /// Top left.
    UpperLeft,
    /// Bottom right.
    LowerRight,
    /// Bottom left.
    LowerLeft,
}

const SIZE: (u32, u32) = (760, 500);

/// The title's font size and line height, and how many characters fit a
/// line of the canvas's width at that size (about 0.55 em a character).
const TITLE_FONT: u32 = 17;
const TITLE_LINE_HEIGHT: u32 = 22;
const TITLE_CHARS_PER_LINE: usize = 78;

/// `text` broken at spaces into lines of at most `width` characters (a
/// longer word gets a line of its own).
fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for word in text.split_whitespace() {
        match lines.last_mut() {
            Some(line) if line.chars().count() + 1 + word.chars().count() <= width => {
                line.push(' ');
                line.push_str(word);
            }
            _ => lines.push(word.to_owned()),
        }
    }
    lines
}

/// `text` broken at spaces into lines of at most `width` characters, for
/// other drawings' titles (the equal-time panels').
pub(crate) fn wrap_text(text: &str, width: usize) -> Vec<String> {
    wrap(text, width)
}

/// A tick's label: as [`format_number`] writes it, but `2e-5` rather than
/// `2.000e-5` for small and large values.
fn format_tick(v: f64) -> String {
    let text = format_number(v);
    match text.split_once('e') {
        Some((mantissa, exponent)) if mantissa.contains('.') => {
            format!("{}e{exponent}", mantissa.trim_end_matches('0').trim_end_matches('.'))
        }
        _ => text,
    }
}

/// Labelled ticks for a log axis from `lo` to `hi`: powers of ten, then 1,
/// 2 and 5 times them, then every integer mantissa, then every half, fifth
/// and tenth of one, whichever first gives at least three ticks inside the
/// range (so a narrow range, 305 to 575, gets 350, 400, … 550, not 27
/// labels that run into each other).
fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    // Within the doubles' range, whatever the axis was given (a range of a
    // thousand decades would otherwise ask for billions of ticks).
    let (first, last) = (lo.log10().floor().clamp(-310.0, 310.0) as i32, hi.log10().ceil().clamp(-310.0, 310.0) as i32);
    if last - first > 12 {
        // Many decades: every few powers of ten.
        let step = ((last - first) / 6).max(1) as usize;
        return (first..=last).step_by(step).map(|e| 10f64.powi(e)).filter(|v| *v >= lo && *v <= hi).collect();
    }
    let steps = |step: usize| -> Vec<f64> { (10..100).step_by(step).map(|m| m as f64 / 10.0).collect() };
    let (halves, fifths, tenths) = (steps(5), steps(2), steps(1));
    for mantissas in
        [&[1.0][..], &[1.0, 2.0, 5.0], &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0], &halves, &fifths, &tenths]
    {
        let ticks: Vec<f64> = (first..=last)
            .flat_map(|e| mantissas.iter().map(move |m| m * 10f64.powi(e)))
            // Rounded as printed, so that 0.3 is 0.3 and not 0.30000000000000004.
            .map(|v| format!("{v:.12e}").parse::<f64>().unwrap_or(v))
            .filter(|v| *v >= lo && *v <= hi)
            .collect();
        if ticks.len() >= 3 {
            return ticks;
        }
    }
    // Less than a hundredth of a decade: the ends and the middle, on a log scale.
    vec![lo, (lo * hi).sqrt(), hi]
}

/// The range of `values` on an axis, padded; on a log axis only positive values count.
fn axis_range(values: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && (!log || *v > 0.0)) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return if log { (0.1, 10.0) } else { (0.0, 1.0) };
    }
    if log {
        let pad = (hi / lo).powf(0.05).max(1.2);
        (lo / pad, hi * pad)
    } else {
        let pad = ((hi - lo) * 0.05).max(hi.abs().max(1e-12) * 0.05);
        (if lo >= 0.0 && lo - pad < 0.0 { 0.0 } else { lo - pad }, hi + pad)
    }
}

/// Labelled ticks for a linear axis from `lo` to `hi`: the multiples of 1,
/// 2 or 5 times a power of ten that give three to nine ticks.
fn linear_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let span = hi - lo;
    if !(span.is_finite() && span > 0.0) {
        return vec![lo, hi];
    }
    let raw = span / 8.0;
    let magnitude = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0].iter().map(|m| m * magnitude).find(|s| *s >= raw).unwrap_or(10.0 * magnitude);
    let (first, last) = ((lo / step).ceil(), (hi / step).floor());
    if !(first.is_finite() && last.is_finite()) || last - first > 100.0 {
        return vec![lo, hi];
    }
    (first as i64..=last as i64)
        .map(|k| format!("{:.12e}", k as f64 * step).parse().unwrap_or(k as f64 * step))
        .collect()
}

/// The labelled ticks of an axis over `range`.
fn ticks(range: (f64, f64), log: bool) -> Vec<f64> {
    if log { log_ticks(range.0, range.1) } else { linear_ticks(range.0, range.1) }
}

/// `range` with its top moved up to the next labelled tick when the
/// largest datum `max` lies above its last one (on a log axis the next
/// decade or 1-2-5 tick), so that every point sits below a labelled tick;
/// with the ticks.
fn reach_past(range: (f64, f64), max: f64, log: bool) -> ((f64, f64), Vec<f64>) {
    let mut range = range;
    for _ in 0..8 {
        let now = ticks(range, log);
        if !max.is_finite() || now.last().is_some_and(|&last| last >= max) {
            return (range, now);
        }
        // The first tick above the datum, on an axis wide enough to have one.
        let wider = if log { (range.0, range.1.max(max) * 10.0) } else { (range.0, max + (max - range.0).abs()) };
        let Some(next) = ticks(wider, log).into_iter().find(|&v| v >= max) else { break };
        // A little room above that tick, so that it is not the frame itself.
        range.1 = if log { next * (next / range.0).powf(0.02) } else { next + 0.02 * (next - range.0) };
    }
    (range, ticks(range, log))
}

/// Series colours: mid and dark tones that read on white (no pale yellow,
/// cream or mint), Tableau-like first, then darker ones for crowded plots.
pub const PALETTE: [RGBColor; 20] = [
    RGBColor(0x1f, 0x77, 0xb4), // blue
    RGBColor(0xd6, 0x27, 0x28), // red
    RGBColor(0x2c, 0xa0, 0x2c), // green
    RGBColor(0xff, 0x7f, 0x0e), // orange
    RGBColor(0x94, 0x67, 0xbd), // purple
    RGBColor(0x8c, 0x56, 0x4b), // brown
    RGBColor(0xe3, 0x77, 0xc2), // pink
    RGBColor(0x4d, 0x4d, 0x4d), // dark grey
    RGBColor(0x9a, 0x9a, 0x1a), // olive
    RGBColor(0x12, 0x9d, 0xad), // cyan
    RGBColor(0x39, 0x3b, 0x79), // indigo
    RGBColor(0x63, 0x79, 0x39), // moss
    RGBColor(0x8c, 0x6d, 0x31), // ochre
    RGBColor(0x84, 0x3c, 0x39), // maroon
    RGBColor(0x7b, 0x41, 0x73), // plum
    RGBColor(0x00, 0x6d, 0x2c), // dark green
    RGBColor(0xb1, 0x59, 0x28), // rust
    RGBColor(0x6a, 0x3d, 0x9a), // violet
    RGBColor(0x1b, 0x9e, 0x77), // teal
    RGBColor(0xe7, 0x29, 0x8a), // magenta
];

/// Series whose colour is pinned, so that the ones compared most often
/// look the same everywhere whatever the hash says.
const PINNED: [(&str, usize); 6] = [("linear", 7), ("embree", 1), ("sah", 0), ("bvh4", 2), ("bvh8", 3), ("sbvh8", 4)];

/// What a curve's colour is keyed by: its label without a trailing
/// parenthesis (a fitted slope or a count, which differ from plot to plot).
fn colour_key(label: &str) -> &str {
    match label.find(" (") {
        Some(at) if label.ends_with(')') => &label[..at],
        _ => label,
    }
}

/// The palette entry a label prefers: pinned, or a stable hash (FNV-1a)
/// of its key, the same in every plot and every run.
fn preferred_colour(label: &str) -> usize {
    let key = colour_key(label).trim().to_lowercase();
    if let Some(&(_, index)) = PINNED.iter().find(|(name, _)| *name == key) {
        return index;
    }
    let hash = key.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ b as u64).wrapping_mul(0x0100_0000_01b3));
    (hash % PALETTE.len() as u64) as usize
}

/// The palette entry of each of a plot's curves: each its label's
/// preferred one, or when an earlier curve of the plot took it, the next
/// free one (entries repeat only past the palette's size).
pub fn series_colours<'a>(labels: impl IntoIterator<Item = &'a str>) -> Vec<usize> {
    let mut used = [false; PALETTE.len()];
    labels
        .into_iter()
        .enumerate()
        .map(|(i, label)| {
            if i >= PALETTE.len() {
                return preferred_colour(label);
            }
            let mut index = preferred_colour(label);
            while used[index] {
                index = (index + 1) % PALETTE.len();
            }
            used[index] = true;
            index
        })
        .collect()
}

/// The legend's text size and the width of one of its characters, in pixels
/// (the SVG backend writes 12 as about 9.7 px; 0.6 em a character, generous).
const LEGEND_FONT: u32 = 12;
const LEGEND_CHAR: f64 = 6.0;
/// Height of one legend row and the legend's inner margin, in pixels.
const LEGEND_ROW: u32 = 16;
const LEGEND_PAD: u32 = 6;
/// The legend's text for bounds drawn as bounds.
pub const BOUND_LEGEND: &str = "≤ bound (none seen)";
/// How many characters of the y axis's label fit one line along the plot's height.
const Y_LABEL_CHARS: usize = 62;

/// Where the legend goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Placement {
    /// In a corner of the plotting area, which covers no data there.
    Inside(Corner),
    /// Right of the plotting area: every corner would cover data.
    Outside,
}

/// The axes' ranges and ticks and the legend's place.
#[derive(Clone, Debug)]
struct Layout {
    x_range: (f64, f64),
    y_range: (f64, f64),
    x_ticks: Vec<f64>,
    y_ticks: Vec<f64>,
    legend: Placement,
}

/// What a legend row shows beside its text.
#[derive(Clone, Copy, Debug)]
enum Sample {
    Line,
    Markers,
    Guide,
    Bound,
}

impl Plot {
    /// A log-log plot of RMSE against render time, each curve's points with
    /// their spread in both directions ([`Curve::error_against_time`]).
    pub fn error_against_time(file: impl Into<String>, title: impl Into<String>, curves: Vec<Curve>) -> Plot {
        Plot {
            file: file.into(),
            title: title.into(),
            x_label: "render time (ms, median; bars: min–max)".into(),
            y_label: "RMSE of linear radiance (radiance; bars: seeds' min–max)".into(),
            log_x: true,
            log_y: true,
            curves,
            legend: Corner::UpperRight,
            y_range: None,
        }
    }

    /// The plot as an SVG document; the scene (unless empty) and the machine go into the title.
    pub fn to_svg(&self, scene: &str, machine: &Machine) -> Result<String, ExperimentError> {
        let mut svg = String::new();
        self.draw(&mut svg, scene, machine)
            .map_err(|message| ExperimentError::Plot { file: self.file.clone(), message })?;
        Ok(svg)
    }

    /// The legend's rows: each curve with its palette entry, then the note on bounds if any curve has one.
    fn legend_rows(&self) -> Vec<(Sample, Option<usize>, String)> {
        let colours = series_colours(self.curves.iter().map(|c| c.label.as_str()));
        let mut rows: Vec<(Sample, Option<usize>, String)> = self
            .curves
            .iter()
            .zip(colours)
            .map(|(c, colour)| {
                let sample = if c.guide {
                    Sample::Guide
                } else if c.markers_only {
                    Sample::Markers
                } else {
                    Sample::Line
                };
                (sample, Some(colour), c.label.clone())
            })
            .collect();
        if self.curves.iter().any(|c| c.bounds.iter().any(|b| *b)) {
            rows.push((Sample::Bound, None, BOUND_LEGEND.to_owned()));
        }
        rows
    }

    /// The legend's width and height in pixels.
    fn legend_pixels(&self) -> (u32, u32) {
        let rows = self.legend_rows();
        let longest = rows.iter().map(|r| r.2.chars().count()).max().unwrap_or(0) as f64;
        ((longest * LEGEND_CHAR) as u32 + 34 + 2 * LEGEND_PAD, rows.len() as u32 * LEGEND_ROW + 2 * LEGEND_PAD)
    }

    /// The axes' ranges and ticks, fitted to the curves (or the plot's
    /// own y range) and reaching a labelled tick past the largest datum,
    /// and the legend's place: the corner whose legend covers no data, or
    /// right of the plotting area when every corner's would.
    fn layout(&self) -> Layout {
        let xs = || {
            self.curves.iter().flat_map(|c| {
                c.points.iter().map(|p| p.0).chain(c.x_bars.iter().flatten().flat_map(|&(lo, hi)| [lo, hi]))
            })
        };
        let ys = || {
            self.curves.iter().flat_map(|c| {
                c.points.iter().map(|p| p.1).chain(c.bars.iter().flatten().flat_map(|&(lo, hi)| [lo, hi]))
            })
        };
        let largest = |values: &mut dyn Iterator<Item = f64>, log: bool| {
            values.filter(|v| v.is_finite() && (!log || *v > 0.0)).fold(f64::NEG_INFINITY, f64::max)
        };
        let (x_range, x_ticks) = reach_past(axis_range(xs(), self.log_x), largest(&mut xs(), self.log_x), self.log_x);
        let y_fitted = self.y_range.unwrap_or_else(|| axis_range(ys(), self.log_y));
        let (y_range, y_ticks) = reach_past(y_fitted, largest(&mut ys(), self.log_y), self.log_y);
        let (corner, covered) = self.legend_place(x_range, y_range);
        let (_, h) = self.legend_size();
        let legend = if covered == 0 && h <= 0.6 { Placement::Inside(corner) } else { Placement::Outside };
        Layout { x_range, y_range, x_ticks, y_ticks, legend }
    }

    fn draw(&self, svg: &mut String, scene: &str, machine: &Machine) -> Result<(), String> {
        let layout = self.layout();
        let root = SVGBackend::with_string(svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        // A scene file is named by its file name (the folder says nothing in
        // a title), a built-in scene by its name without the explanation.
        let path = std::path::Path::new(scene);
        let scene = match path.file_name() {
            Some(name) if path.is_file() => name.to_string_lossy().into_owned(),
            _ => scene.split(" (").next().unwrap_or(scene).to_owned(),
        };
        let caption = if scene.is_empty() {
            format!("{} ({})", self.title, machine.short())
        } else {
            format!("{}, {scene} ({})", self.title, machine.short())
        };
        // A title never runs off the canvas: it is wrapped into lines that fit.
        let lines = wrap(&caption, TITLE_CHARS_PER_LINE);
        let title_height = TITLE_LINE_HEIGHT * lines.len() as u32 + 10;
        let (title_area, chart_area) = root.split_vertically(title_height);
        for (i, line) in lines.iter().enumerate() {
            title_area
                .draw(&Text::new(
                    line.clone(),
                    (SIZE.0 as i32 / 2, 8 + (i as u32 * TITLE_LINE_HEIGHT) as i32),
                    TextStyle::from(("sans-serif", TITLE_FONT).into_font()).pos(Pos::new(HPos::Center, VPos::Top)),
                ))
                .map_err(|e| e.to_string())?;
        }
        // The y axis's label in as many lines as it needs, beside tick
        // labels as wide as the longest one: none is clipped.
        let y_lines = wrap(&self.y_label, Y_LABEL_CHARS);
        let tick_chars = layout.y_ticks.iter().map(|t| format_tick(*t).chars().count()).max().unwrap_or(1);
        let y_area = (tick_chars as f64 * LEGEND_CHAR) as u32 + 12 + 14 * y_lines.len() as u32 + 6;
        let legend_size = self.legend_pixels();
        let mut builder = ChartBuilder::on(&chart_area);
        builder.margin(14).x_label_area_size(44).y_label_area_size(y_area);
        if layout.legend == Placement::Outside {
            builder.margin_right(14 + legend_size.0.min(SIZE.0 / 2) + 8);
        }
        let (x_range, y_range) = (layout.x_range, layout.y_range);
        // The four combinations of linear and log axes are different types;
        // every axis carries its own key points, so that the ticks are the
        // ones the range was made to reach.
        let log = |(lo, hi): (f64, f64), t: &[f64]| Ticked((lo..hi).log_scale().with_key_points(t.to_vec()));
        let lin = |(lo, hi): (f64, f64), t: &[f64]| Ticked((lo..hi).with_key_points(t.to_vec()));
        let (xt, yt) = (&layout.x_ticks, &layout.y_ticks);
        let area = match (self.log_x, self.log_y) {
            (false, false) => self.fill(
                builder.build_cartesian_2d(lin(x_range, xt), lin(y_range, yt)).map_err(|e| e.to_string())?,
                y_range,
            ),
            (true, false) => self.fill(
                builder.build_cartesian_2d(log(x_range, xt), lin(y_range, yt)).map_err(|e| e.to_string())?,
                y_range,
            ),
            (false, true) => self.fill(
                builder.build_cartesian_2d(lin(x_range, xt), log(y_range, yt)).map_err(|e| e.to_string())?,
                y_range,
            ),
            (true, true) => self.fill(
                builder.build_cartesian_2d(log(x_range, xt), log(y_range, yt)).map_err(|e| e.to_string())?,
                y_range,
            ),
        }?;
        let (px, py) = area;
        let middle = (py.start + py.end) / 2;
        for (i, line) in y_lines.iter().enumerate() {
            root.draw(&Text::new(
                line.clone(),
                (20 + 14 * i as i32, middle),
                TextStyle::from(("sans-serif", LEGEND_FONT).into_font().transform(FontTransform::Rotate270))
                    .pos(Pos::new(HPos::Center, VPos::Center)),
            ))
            .map_err(|e| e.to_string())?;
        }
        let (w, h) = (legend_size.0 as i32, legend_size.1 as i32);
        let corner = match layout.legend {
            Placement::Inside(Corner::UpperRight) => (px.end - w - 8, py.start + 8),
            Placement::Inside(Corner::UpperLeft) => (px.start + 8, py.start + 8),
            Placement::Inside(Corner::LowerRight) => (px.end - w - 8, py.end - h - 8),
            Placement::Inside(Corner::LowerLeft) => (px.start + 8, py.end - h - 8),
            Placement::Outside => (px.end + 12, py.start),
        };
        self.draw_legend(&root, corner, (w, h))?;
        root.present().map_err(|e| e.to_string())?;
        Ok(())
    }

    /// Draws the legend with its top left corner at `at` (pixels).
    fn draw_legend<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, plotters::coord::Shift>,
        at: (i32, i32),
        (w, h): (i32, i32),
    ) -> Result<(), String> {
        let fail = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        root.draw(&Rectangle::new([at, (at.0 + w, at.1 + h)], WHITE.mix(0.9).filled())).map_err(fail)?;
        root.draw(&Rectangle::new([at, (at.0 + w, at.1 + h)], BLACK.mix(0.4))).map_err(fail)?;
        for (row, (sample, colour, label)) in self.legend_rows().into_iter().enumerate() {
            let y = at.1 + (LEGEND_PAD + LEGEND_ROW * row as u32 + LEGEND_ROW / 2) as i32;
            let x = at.0 + LEGEND_PAD as i32;
            let colour = colour.map_or(RGBColor(0x60, 0x60, 0x60), |c| PALETTE[c]);
            match sample {
                Sample::Line => {
                    root.draw(&PathElement::new(vec![(x, y), (x + 24, y)], colour.stroke_width(2))).map_err(fail)?;
                    root.draw(&Circle::new((x + 12, y), 3, colour.filled())).map_err(fail)?;
                }
                Sample::Markers => root.draw(&Circle::new((x + 12, y), 3, colour.filled())).map_err(fail)?,
                Sample::Guide => {
                    root.draw(&PathElement::new(vec![(x, y), (x + 9, y)], colour.stroke_width(1))).map_err(fail)?;
                    root.draw(&PathElement::new(vec![(x + 14, y), (x + 24, y)], colour.stroke_width(1)))
                        .map_err(fail)?;
                }
                Sample::Bound => {
                    root.draw(&Polygon::new(
                        vec![(x + 6, y - 3), (x + 18, y - 3), (x + 18, y + 7), (x + 6, y + 7)],
                        colour.mix(0.25).filled(),
                    ))
                    .map_err(fail)?;
                    root.draw(&PathElement::new(down_triangle((x + 12, y - 3)), colour.stroke_width(1)))
                        .map_err(fail)?;
                }
            }
            root.draw(&Text::new(
                label,
                (x + 32, y),
                TextStyle::from(("sans-serif", LEGEND_FONT).into_font()).pos(Pos::new(HPos::Left, VPos::Center)),
            ))
            .map_err(fail)?;
        }
        Ok(())
    }

    /// The corner whose legend box covers the fewest points and bars (the
    /// plot's preferred corner on ties).
    #[cfg(test)]
    fn legend_corner(&self, x_range: (f64, f64), y_range: (f64, f64)) -> Corner {
        self.legend_place(x_range, y_range).0
    }

    /// The legend's width and height as fractions of the plotting area.
    fn legend_size(&self) -> (f64, f64) {
        let (area_w, area_h) = (SIZE.0 as f64 - 130.0, SIZE.1 as f64 - 130.0);
        let (w, h) = self.legend_pixels();
        ((w as f64 + 8.0) / area_w, (h as f64 + 8.0) / area_h)
    }

    /// [`Plot::legend_corner`], with how many points it covers there.
    fn legend_place(&self, x_range: (f64, f64), y_range: (f64, f64)) -> (Corner, usize) {
        let fraction = |v: f64, (lo, hi): (f64, f64), log: bool| {
            if log { (v.max(1e-300).ln() - lo.ln()) / (hi.ln() - lo.ln()) } else { (v - lo) / (hi - lo) }
        };
        let (w, h) = self.legend_size();
        // Every curve as points in the plotting area's fractions, with points
        // along each segment taken in those fractions (a line under the
        // legend hides as much as a marker; on a log axis a segment is
        // straight in the fractions, not in the values).
        let to_area = |(x, y): (f64, f64)| (fraction(x, x_range, self.log_x), fraction(y, y_range, self.log_y));
        let shown: Vec<(f64, f64)> = self
            .curves
            .iter()
            .flat_map(|c| {
                let finite = |(_, p): &(usize, &(f64, f64))| p.0.is_finite() && p.1.is_finite();
                let points: Vec<(f64, f64)> = c
                    .points
                    .iter()
                    .enumerate()
                    .filter(finite)
                    .filter(|(i, _)| !c.is_bound(*i))
                    .map(|(_, &p)| to_area(p))
                    .collect();
                // A bound's shaded column, from the axis up to the bound.
                let columns: Vec<(f64, f64)> = c
                    .points
                    .iter()
                    .enumerate()
                    .filter(finite)
                    .filter(|(i, _)| c.is_bound(*i))
                    .flat_map(|(_, &p)| {
                        let (fx, fy) = to_area(p);
                        (0..=8).map(move |k| (fx, fy * k as f64 / 8.0))
                    })
                    .collect();
                let along: Vec<(f64, f64)> = if c.markers_only {
                    Vec::new()
                } else {
                    points
                        .windows(2)
                        .flat_map(|p| {
                            (1..16).map(move |k| {
                                let t = k as f64 / 16.0;
                                (p[0].0 + t * (p[1].0 - p[0].0), p[0].1 + t * (p[1].1 - p[0].1))
                            })
                        })
                        .collect()
                };
                // Error bars hide under a legend too: their ends and middles.
                let bars = c.points.iter().zip(&c.bars).filter_map(|(&(x, _), bar)| {
                    bar.map(|(lo, hi)| {
                        [(x, lo), (x, hi), (x, if self.log_y { (lo * hi).sqrt() } else { (lo + hi) / 2.0 })]
                    })
                });
                let bars: Vec<(f64, f64)> =
                    bars.flatten().filter(|(x, y)| x.is_finite() && y.is_finite()).map(to_area).collect();
                points.into_iter().chain(columns).chain(along).chain(bars)
            })
            .collect();
        let covered = |corner: Corner| -> usize {
            let (right, top) = match corner {
                Corner::UpperRight => (true, true),
                Corner::UpperLeft => (false, true),
                Corner::LowerRight => (true, false),
                Corner::LowerLeft => (false, false),
            };
            let inside = |&&(fx, fy): &&(f64, f64)| {
                (if right { fx >= 1.0 - w } else { fx <= w }) && (if top { fy >= 1.0 - h } else { fy <= h })
            };
            shown.iter().filter(inside).count()
        };
        let mut corners =
            vec![self.legend, Corner::UpperRight, Corner::UpperLeft, Corner::LowerRight, Corner::LowerLeft];
        corners.dedup();
        corners.into_iter().map(|c| (c, covered(c))).min_by_key(|&(_, n)| n).unwrap_or((self.legend, 0))
    }

    /// Draws the mesh and the curves; returns the plotting area's pixels.
    fn fill<'a, X, Y>(
        &self,
        mut chart: ChartContext<'a, SVGBackend<'a>, Cartesian2d<X, Y>>,
        y_range: (f64, f64),
    ) -> Result<(std::ops::Range<i32>, std::ops::Range<i32>), String>
    where
        X: Ranged<ValueType = f64> + ValueFormatter<f64>,
        Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        chart
            .configure_mesh()
            .x_desc(self.x_label.as_str())
            // One light line between labelled ticks at most: denser ones drew grey bands.
            .max_light_lines(1)
            .light_line_style(RGBColor(242, 242, 242))
            .x_label_formatter(&|v| format_tick(*v))
            .y_label_formatter(&|v| format_tick(*v))
            .draw()
            .map_err(|e| e.to_string())?;
        let colours = series_colours(self.curves.iter().map(|c| c.label.as_str()));
        for (index, curve) in self.curves.iter().enumerate() {
            let colour = PALETTE[colours[index]];
            let finite = |p: &(f64, f64)| p.0.is_finite() && p.1.is_finite();
            if curve.guide {
                let points = curve.points.iter().copied().filter(finite);
                chart
                    .draw_series(DashedLineSeries::new(points, 6, 4, colour.stroke_width(1)))
                    .map_err(|e| e.to_string())?;
                continue;
            }
            // The line joins runs of measured points only: a bound is no measurement.
            if !curve.markers_only {
                let mut runs: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
                for (i, p) in curve.points.iter().enumerate() {
                    if curve.is_bound(i) || !finite(p) {
                        runs.push(Vec::new());
                    } else if let Some(run) = runs.last_mut() {
                        run.push(*p);
                    }
                }
                for run in runs.into_iter().filter(|r| r.len() >= 2) {
                    chart.draw_series(LineSeries::new(run, colour.stroke_width(2))).map_err(|e| e.to_string())?;
                }
            }
            let measured = curve.points.iter().enumerate().filter(|(i, p)| !curve.is_bound(*i) && finite(p));
            chart.draw_series(measured.map(|(_, &p)| Circle::new(p, 3, colour.filled()))).map_err(|e| e.to_string())?;
            // A bound: a shaded column from the axis up to it, capped by an open downward triangle.
            let bottom = |x: f64| chart.backend_coord(&(x, y_range.0)).1;
            let bounds: Vec<((f64, f64), i32)> = curve
                .points
                .iter()
                .enumerate()
                .filter(|(i, p)| curve.is_bound(*i) && finite(p))
                .map(|(_, &p)| (p, (bottom(p.0) - chart.backend_coord(&p).1).max(0)))
                .collect();
            chart
                .draw_series(bounds.iter().map(|&(p, h)| {
                    EmptyElement::at(p)
                        + Polygon::new(vec![(-5, 0), (5, 0), (5, h), (-5, h)], colour.mix(0.22).filled())
                        + PathElement::new(vec![(-7, 0), (7, 0)], colour.stroke_width(2))
                        + PathElement::new(down_triangle((0, 0)), colour.stroke_width(1))
                }))
                .map_err(|e| e.to_string())?;
            let bars =
                curve.points.iter().zip(&curve.bars).enumerate().filter_map(|(i, (&(x, y), bar))| {
                    bar.filter(|_| !curve.is_bound(i)).map(|(lo, hi)| (x, y, lo, hi))
                });
            chart
                .draw_series(bars.map(|(x, y, lo, hi)| ErrorBar::new_vertical(x, lo, y, hi, colour.stroke_width(1), 8)))
                .map_err(|e| e.to_string())?;
            let x_bars =
                curve.points.iter().zip(&curve.x_bars).filter_map(|(&(x, y), bar)| bar.map(|(lo, hi)| (x, y, lo, hi)));
            chart
                .draw_series(
                    x_bars.map(|(x, y, lo, hi)| ErrorBar::new_horizontal(y, lo, x, hi, colour.stroke_width(1), 8)),
                )
                .map_err(|e| e.to_string())?;
            // Point labels beside their markers: above for even curves, below for odd ones, so that two
            // curves through nearby points do not write over each other.
            let offset = if index % 2 == 0 { (5, -14) } else { (5, 3) };
            let labelled = curve.points.iter().zip(&curve.point_labels).filter(|(p, l)| finite(p) && !l.is_empty());
            chart
                .draw_series(labelled.map(|(&p, label)| {
                    EmptyElement::at(p)
                        + Text::new(
                            label.clone(),
                            offset,
                            TextStyle::from(("sans-serif", 11).into_font()).color(&colour),
                        )
                }))
                .map_err(|e| e.to_string())?;
        }
        Ok(chart.plotting_area().get_pixel_range())
    }
}

/// An axis with the given ticks, formatted by the plot's own formatter (a
/// linear axis with key points has no formatter of its own in plotters).
struct Ticked<R: Ranged>(plotters::coord::combinators::WithKeyPoints<R>);

impl<R: Ranged<ValueType = f64>> Ranged for Ticked<R> {
    type FormatOption = plotters::coord::ranged1d::DefaultFormatting;
    type ValueType = f64;

    fn range(&self) -> std::ops::Range<f64> {
        self.0.range()
    }

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.0.map(value, limit)
    }

    fn key_points<Hint: plotters::coord::ranged1d::KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        self.0.key_points(hint)
    }

    fn axis_pixel_range(&self, limit: (i32, i32)) -> std::ops::Range<i32> {
        self.0.axis_pixel_range(limit)
    }
}

/// An open triangle pointing down with its tip 7 pixels below `(x, y)`: a bound's marker.
fn down_triangle((x, y): (i32, i32)) -> Vec<(i32, i32)> {
    vec![(x - 5, y), (x + 5, y), (x, y + 7), (x - 5, y)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_axes_have_at_least_three_labelled_ticks() {
        assert_eq!(log_ticks(0.05, 200.0), vec![0.1, 1.0, 10.0, 100.0]);
        // Less than a decade (the depth knob's RMSE): 1-2-5 mantissas, then every integer, then halves, fifths, tenths.
        assert_eq!(log_ticks(0.011, 0.06), vec![0.02, 0.03, 0.04, 0.05, 0.06]);
        assert_eq!(log_ticks(0.109, 0.1616), vec![0.12, 0.14, 0.16]);
        assert_eq!(log_ticks(305.0, 575.0), vec![350.0, 400.0, 450.0, 500.0, 550.0]);
        assert_eq!(log_ticks(0.01211, 0.01219).len(), 3);
        // Hundreds of decades (a degenerate value on the axis): a handful of powers of ten.
        assert!(log_ticks(1e-300, 1e300).len() <= 8);
        assert!(log_ticks(f64::MIN_POSITIVE, f64::INFINITY).len() <= 8);
        for (lo, hi) in [(1e-5, 2e-5), (3.0, 7.0), (0.9, 1.1), (1.0, 1e6), (1e-30, 1.0)] {
            let ticks = log_ticks(lo, hi);
            assert!(ticks.len() >= 3 && ticks.iter().all(|t| (lo..=hi).contains(t)), "{lo}..{hi}: {ticks:?}");
        }
    }

    #[test]
    fn a_rate_never_seen_is_drawn_at_its_bound() {
        assert_eq!(rate_or_bound(2.0, 100.0), 0.02);
        assert_eq!(rate_or_bound(0.0, 300.0), 0.01);
        assert_eq!(rate_or_bound(0.0, 0.0), 3.0);
    }

    #[test]
    fn tick_labels_are_short() {
        assert_eq!(format_tick(1e-4), "1e-4");
        assert_eq!(format_tick(2.5e6), "2.5e6");
        assert_eq!(format_tick(0.02), "0.02");
        assert_eq!(format_tick(1000.0), "1000");
    }

    #[test]
    fn long_titles_wrap_and_fit() {
        let title = "how far are t and the barycentrics from the exact answer in single and double precision, \
                     on near-degenerate and far-from-origin triangles";
        let lines = wrap(title, TITLE_CHARS_PER_LINE);
        assert!(lines.len() == 2 && lines.iter().all(|l| l.chars().count() <= TITLE_CHARS_PER_LINE), "{lines:?}");
        assert_eq!(lines.join(" "), title.split_whitespace().collect::<Vec<_>>().join(" "));
        // And in the SVG every line is its own text element.
        let plot = Plot {
            file: "t.svg".into(),
            title: title.into(),
            x_label: "x".into(),
            y_label: "y".into(),
            log_x: false,
            log_y: false,
            curves: vec![Curve::new("a", vec![(0.0, 1.0), (1.0, 2.0)])],
            legend: Corner::UpperRight,
            y_range: None,
        };
        let machine = Machine::this(1);
        let svg = plot.to_svg("scene", &machine).unwrap();
        assert!(svg.contains(&lines[0]) && svg.contains("near-degenerate"), "{svg}");
    }

    #[test]
    fn the_legend_goes_where_it_covers_the_fewest_points() {
        // A curve that falls from the upper left to the lower right leaves the other two corners free;
        // one rising through the lower left and upper right leaves the upper left and lower right.
        let plot = |points: Vec<(f64, f64)>, legend| Plot {
            file: "t.svg".into(),
            title: "t".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            log_x: true,
            log_y: true,
            curves: vec![Curve::new("a curve", points)],
            legend,
            y_range: None,
        };
        let falling = plot(vec![(1.0, 100.0), (10.0, 10.0), (100.0, 1.0)], Corner::UpperLeft);
        let chosen = falling.legend_corner((0.8, 120.0), (0.8, 120.0));
        assert!(matches!(chosen, Corner::UpperRight | Corner::LowerLeft), "{chosen:?}");
        let rising = plot(vec![(1.0, 1.0), (10.0, 10.0), (100.0, 100.0)], Corner::UpperRight);
        let chosen = rising.legend_corner((0.8, 120.0), (0.8, 120.0));
        assert!(matches!(chosen, Corner::UpperLeft | Corner::LowerRight), "{chosen:?}");
        // With nothing in the way, the preferred corner stays.
        let middle = plot(vec![(9.0, 9.0), (11.0, 11.0)], Corner::LowerRight);
        assert_eq!(middle.legend_corner((0.8, 120.0), (0.8, 120.0)), Corner::LowerRight);
        // Lines across the whole width at the top and the bottom leave no
        // corner free: the legend goes outside the plotting area, right of it.
        let mut crowded = plot(vec![(1.0, 1.0), (100.0, 1.0)], Corner::LowerLeft);
        crowded.curves.push(Curve::guide("top", vec![(1.0, 100.0), (100.0, 100.0)]));
        let layout = crowded.layout();
        assert!(crowded.legend_place(layout.x_range, layout.y_range).1 > 0);
        assert_eq!(layout.legend, Placement::Outside);
        let svg = crowded.to_svg("", &Machine::this(1)).unwrap();
        // The legend's box starts right of the plotting area's right edge.
        let rects: Vec<Vec<f64>> = svg
            .lines()
            .filter(|l| l.contains("<rect") && l.contains("opacity=\"0.9\""))
            .map(|l| attributes(l, &["x"]))
            .collect();
        assert!(rects.iter().any(|r| r[0] > 500.0), "{rects:?}");
    }

    /// The numbers of `names` in an SVG element's text.
    fn attributes(element: &str, names: &[&str]) -> Vec<f64> {
        names
            .iter()
            .map(|name| {
                let start = element.find(&format!(" {name}=\"")).expect(name) + name.len() + 3;
                element[start..].split('"').next().unwrap().parse().unwrap()
            })
            .collect()
    }

    fn plot_of(curves: Vec<Curve>, log_x: bool, log_y: bool) -> Plot {
        Plot {
            file: "t.svg".into(),
            title: "t".into(),
            x_label: "x (units)".into(),
            y_label: "y (units)".into(),
            log_x,
            log_y,
            curves,
            legend: Corner::UpperRight,
            y_range: None,
        }
    }

    /// The luminance of an sRGB colour, 0 black to 1 white.
    fn luminance(c: RGBColor) -> f64 {
        let linear = |v: u8| {
            let v = v as f64 / 255.0;
            if v <= 0.04045 { v / 12.92 } else { ((v + 0.055) / 1.055).powf(2.4) }
        };
        0.2126 * linear(c.0) + 0.7152 * linear(c.1) + 0.0722 * linear(c.2)
    }

    #[test]
    fn a_series_has_one_colour_in_every_plot_and_none_shares_one_in_a_plot() {
        // The same label keeps its colour whatever else is in the plot and wherever it comes.
        let one = series_colours(["embree", "bvh4", "sah"]);
        let two = series_colours(["sah", "object-median", "embree (n^0.31)", "linear"]);
        assert_eq!(one[0], two[2]);
        assert_eq!(one[2], two[0]);
        let (a, b) = (series_colours(["roulette on", "roulette off"]), series_colours(["x", "roulette off"]));
        assert_eq!(a[1], b[1]);
        // Two labels that prefer the same entry: the second probes to the next free one.
        let labels: Vec<String> = (0..200).map(|i| format!("series {i}")).collect();
        let clash = labels
            .iter()
            .enumerate()
            .find_map(|(i, a)| {
                labels[i + 1..].iter().find(|b| preferred_colour(a) == preferred_colour(b)).map(|b| (a, b))
            })
            .expect("200 labels in 20 colours collide");
        let colours = series_colours([clash.0.as_str(), clash.1.as_str()]);
        assert_ne!(colours[0], colours[1]);
        // A crowded plot (the packets plot has 16 curves): all different.
        let crowded = series_colours(labels.iter().take(PALETTE.len()).map(String::as_str));
        let mut unique = crowded.clone();
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(unique.len(), PALETTE.len(), "{crowded:?}");
        // Every colour reads on white: no pale yellow, cream or mint.
        for c in PALETTE {
            assert!(luminance(c) < 0.5, "{c:?}: {}", luminance(c));
        }
        // And the SVG draws them: two curves, two colours.
        let plot = plot_of(
            vec![Curve::new("embree", vec![(1.0, 1.0), (2.0, 2.0)]), Curve::new("sah", vec![(1.0, 2.0), (2.0, 1.0)])],
            false,
            false,
        );
        let svg = plot.to_svg("", &Machine::this(1)).unwrap();
        for c in [PALETTE[preferred_colour("embree")], PALETTE[preferred_colour("sah")]] {
            let hex = format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2);
            assert!(svg.contains(&hex), "{hex}");
        }
    }

    #[test]
    fn a_bound_is_a_shaded_column_not_a_joined_point() {
        // Two measured rates, then one never seen: drawn at its bound, as a bound.
        let curve =
            Curve::new("embree", vec![(1.0, 0.01), (2.0, 0.02), (4.0, 0.003)]).with_bounds(vec![false, false, true]);
        let svg = plot_of(vec![curve], true, true).to_svg("", &Machine::this(1)).unwrap();
        let colour = PALETTE[preferred_colour("embree")];
        let hex = format!("#{:02X}{:02X}{:02X}", colour.0, colour.1, colour.2);
        // One line, through the two measured points only.
        let lines: Vec<&str> = svg.lines().filter(|l| l.contains("<polyline") && l.contains(&hex)).collect();
        let joined: Vec<usize> = lines
            .iter()
            .map(|l| l.split("points=\"").nth(1).unwrap().split('"').next().unwrap().split_whitespace().count())
            .collect();
        assert!(joined.contains(&2) && joined.iter().all(|n| *n <= 4), "{lines:?}");
        // The shaded column, in the curve's colour, and the legend's note.
        assert!(svg.lines().any(|l| l.contains("<polygon") && l.contains(&hex)), "{svg}");
        assert!(svg.contains(BOUND_LEGEND), "{svg}");
        // Without bounds the same points are one line of three, and no note.
        let measured = Curve::new("embree", vec![(1.0, 0.01), (2.0, 0.02), (4.0, 0.003)]);
        let svg = plot_of(vec![measured], true, true).to_svg("", &Machine::this(1)).unwrap();
        assert!(!svg.contains(BOUND_LEGEND) && !svg.lines().any(|l| l.contains("<polygon") && l.contains(&hex)));
        assert!(is_bound(0.0) && !is_bound(1.0));
    }

    #[test]
    fn every_datum_sits_below_the_last_labelled_tick() {
        for (values, log) in [
            (vec![1.0, 9.7], true),
            (vec![0.011, 0.0587], true),
            (vec![3.0, 95.0, 7000.0], true),
            (vec![305.0, 575.0], true),
            (vec![0.0, 9.6], false),
            (vec![-3.0, 47.2], false),
            (vec![0.1, 0.1049], false),
            (vec![1.0, 1.0001], true),
            (vec![12.0, 19.99], false),
        ] {
            let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let (range, ticks) = reach_past(axis_range(values.iter().copied(), log), max, log);
            let last = *ticks.last().unwrap();
            assert!(max <= last && last <= range.1, "{values:?}: {ticks:?} in {range:?}");
            assert!(ticks.len() >= 2, "{values:?}: {ticks:?}");
        }
        // Through the plot: the y axis's top tick is above the largest point.
        let plot = plot_of(vec![Curve::new("a", vec![(1.0, 1.0), (10.0, 97.0)])], true, true);
        let layout = plot.layout();
        assert!(layout.y_ticks.last().is_some_and(|&t| t >= 97.0), "{:?}", layout.y_ticks);
        assert!(layout.x_ticks.last().is_some_and(|&t| t >= 10.0), "{:?}", layout.x_ticks);
    }

    #[test]
    fn points_carry_their_labels_and_long_axis_labels_wrap() {
        let curve = Curve::new("roulette on", vec![(1.0, 0.5), (2.0, 0.3), (4.0, 0.2)]).with_point_labels(vec![
            "depth 1".into(),
            "depth 2".into(),
            String::new(),
        ]);
        let mut plot = plot_of(vec![curve], true, true);
        plot.y_label = "rays through shared edges and from inside closed meshes that escape \
                        (none seen: at the 95% bound 3/N)"
            .into();
        let svg = plot.to_svg("", &Machine::this(1)).unwrap();
        assert!(svg.contains(">\ndepth 1\n") || svg.contains(">depth 1<"), "{svg}");
        assert!(svg.contains("depth 2") && !svg.contains("depth 3"));
        // The y label in two lines, each its own text, neither longer than fits.
        let lines = wrap(&plot.y_label, Y_LABEL_CHARS);
        assert_eq!(lines.len(), 2);
        assert!(lines.iter().all(|l| svg.contains(l.as_str())), "{svg}");
    }

    #[test]
    fn a_standard_error_that_rounds_to_zero_is_left_out() {
        assert_eq!(with_standard_error(-0.746, Some(0.012)), "-0.75 ± 0.01");
        assert_eq!(with_standard_error(-0.7461, Some(0.0004)), "-0.7461 ± 0.0004");
        assert_eq!(with_standard_error(-0.5, Some(1e-9)), "-0.50");
        assert_eq!(with_standard_error(-0.5, None), "-0.50");
        assert_eq!(with_standard_error(-0.5, Some(f64::NAN)), "-0.50");
        assert!(!with_standard_error(0.998, Some(0.0031)).contains("± 0.00 "));
    }
}
