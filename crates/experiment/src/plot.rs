//! SVG line plots with error bars, drawn by `plotters` (its SVG backend
//! only: no fonts are read, the viewer renders the text).

use plotters::coord::ranged1d::ValueFormatter;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::ExperimentError;
use crate::machine::Machine;
use crate::report::format_number;

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
}

impl Curve {
    /// A curve of measurements through `points`, without error bars.
    pub fn new(label: impl Into<String>, points: Vec<(f64, f64)>) -> Curve {
        Curve {
            label: label.into(),
            bars: vec![None; points.len()],
            x_bars: vec![None; points.len()],
            points,
            guide: false,
            markers_only: false,
        }
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

impl Plot {
    /// A log-log plot of RMSE against render time, each curve's points with
    /// their spread in both directions ([`Curve::error_against_time`]).
    pub fn error_against_time(file: impl Into<String>, title: impl Into<String>, curves: Vec<Curve>) -> Plot {
        Plot {
            file: file.into(),
            title: title.into(),
            x_label: "render time (ms, median; bars: min–max)".into(),
            y_label: "RMSE of linear radiance (bars: seeds' min–max)".into(),
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

    /// The axes' ranges and the legend's corner: the ranges fit the
    /// curves (or are the plot's own), and when every corner's legend would
    /// cover a curve, the y axis grows on the legend's side by the legend's
    /// height, so that it covers none.
    fn layout(&self) -> ((f64, f64), (f64, f64), Corner) {
        let xs = self
            .curves
            .iter()
            .flat_map(|c| c.points.iter().map(|p| p.0).chain(c.x_bars.iter().flatten().flat_map(|&(lo, hi)| [lo, hi])));
        let ys = || {
            self.curves.iter().flat_map(|c| {
                c.points.iter().map(|p| p.1).chain(c.bars.iter().flatten().flat_map(|&(lo, hi)| [lo, hi]))
            })
        };
        let x_range = axis_range(xs, self.log_x);
        let y_range = self.y_range.unwrap_or_else(|| axis_range(ys(), self.log_y));
        let (legend, covered) = self.legend_place(x_range, y_range);
        let y_range = match (covered, self.y_range) {
            (0, _) | (_, Some(_)) => y_range,
            _ => {
                let h = self.legend_size().1.min(0.6);
                let grow = h / (1.0 - h) * 1.15;
                let top = matches!(legend, Corner::UpperLeft | Corner::UpperRight);
                if self.log_y {
                    let span = (y_range.1 / y_range.0).ln();
                    if top {
                        (y_range.0, y_range.1 * (grow * span).exp())
                    } else {
                        (y_range.0 / (grow * span).exp(), y_range.1)
                    }
                } else {
                    let span = y_range.1 - y_range.0;
                    if top { (y_range.0, y_range.1 + grow * span) } else { (y_range.0 - grow * span, y_range.1) }
                }
            }
        };
        // A range that grew past the doubles (a degenerate fit) keeps its fitted size.
        let y_range = if y_range.0.is_finite() && y_range.1.is_finite() && (!self.log_y || y_range.0 > 0.0) {
            y_range
        } else {
            self.y_range.unwrap_or_else(|| axis_range(ys(), self.log_y))
        };
        (x_range, y_range, legend)
    }

    fn draw(&self, svg: &mut String, scene: &str, machine: &Machine) -> Result<(), String> {
        let (x_range, y_range, legend) = self.layout();
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
        let (title_area, chart_area) = root.split_vertically(TITLE_LINE_HEIGHT * lines.len() as u32 + 10);
        for (i, line) in lines.iter().enumerate() {
            title_area
                .draw(&Text::new(
                    line.clone(),
                    (SIZE.0 as i32 / 2, 8 + (i as u32 * TITLE_LINE_HEIGHT) as i32),
                    TextStyle::from(("sans-serif", TITLE_FONT).into_font()).pos(Pos::new(HPos::Center, VPos::Top)),
                ))
                .map_err(|e| e.to_string())?;
        }
        let mut builder = ChartBuilder::on(&chart_area);
        builder.margin(14).x_label_area_size(44).y_label_area_size(70);
        // The four combinations of linear and log axes are different types;
        // log axes carry their own key points, so a range of less than a
        // decade still has several labelled ticks.
        let log = |(lo, hi): (f64, f64)| (lo..hi).log_scale().with_key_points(log_ticks(lo, hi));
        match (self.log_x, self.log_y) {
            (false, false) => self.fill(
                builder.build_cartesian_2d(x_range.0..x_range.1, y_range.0..y_range.1).map_err(|e| e.to_string())?,
                legend,
            ),
            (true, false) => self.fill(
                builder.build_cartesian_2d(log(x_range), y_range.0..y_range.1).map_err(|e| e.to_string())?,
                legend,
            ),
            (false, true) => self.fill(
                builder.build_cartesian_2d(x_range.0..x_range.1, log(y_range)).map_err(|e| e.to_string())?,
                legend,
            ),
            (true, true) => {
                self.fill(builder.build_cartesian_2d(log(x_range), log(y_range)).map_err(|e| e.to_string())?, legend)
            }
        }?;
        root.present().map_err(|e| e.to_string())?;
        Ok(())
    }

    /// The corner whose legend box covers the fewest points and bars (the
    /// plot's preferred corner on ties).
    #[cfg(test)]
    fn legend_corner(&self, x_range: (f64, f64), y_range: (f64, f64)) -> Corner {
        self.legend_place(x_range, y_range).0
    }

    /// The legend's width and height as fractions of the plotting area
    /// (about 7 px a character plus the sample line, 20 px a row).
    fn legend_size(&self) -> (f64, f64) {
        let (area_w, area_h) = (SIZE.0 as f64 - 100.0, SIZE.1 as f64 - 130.0);
        let longest = self.curves.iter().map(|c| c.label.chars().count()).max().unwrap_or(0) as f64;
        ((longest * 7.0 + 50.0) / area_w, (self.curves.len() as f64 * 20.0 + 12.0) / area_h)
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
                let points: Vec<(f64, f64)> =
                    c.points.iter().copied().filter(|(x, y)| x.is_finite() && y.is_finite()).map(to_area).collect();
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
                points.into_iter().chain(along).chain(bars)
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

    fn fill<'a, X, Y>(
        &self,
        mut chart: ChartContext<'a, SVGBackend<'a>, Cartesian2d<X, Y>>,
        legend: Corner,
    ) -> Result<(), String>
    where
        X: Ranged<ValueType = f64> + ValueFormatter<f64>,
        Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        chart
            .configure_mesh()
            .x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            // One light line between labelled ticks at most: denser ones drew grey bands.
            .max_light_lines(1)
            .light_line_style(RGBColor(242, 242, 242))
            .x_label_formatter(&|v| format_tick(*v))
            .y_label_formatter(&|v| format_tick(*v))
            .draw()
            .map_err(|e| e.to_string())?;
        for (index, curve) in self.curves.iter().enumerate() {
            let colour = Palette99::pick(index).to_rgba();
            let points = curve.points.iter().copied().filter(|(x, y)| x.is_finite() && y.is_finite());
            if curve.guide {
                chart
                    .draw_series(DashedLineSeries::new(points, 6, 4, colour.stroke_width(1)))
                    .map_err(|e| e.to_string())?
                    .label(curve.label.as_str())
                    // Dashed in the legend as on the plot: two dashes.
                    .legend(move |(x, y)| {
                        EmptyElement::at((x, y))
                            + PathElement::new(vec![(0, 0), (8, 0)], colour.stroke_width(1))
                            + PathElement::new(vec![(12, 0), (20, 0)], colour.stroke_width(1))
                    });
                continue;
            }
            let markers_only = curve.markers_only;
            let line = if markers_only { Vec::new() } else { points.clone().collect() };
            chart
                .draw_series(LineSeries::new(line, colour.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label(curve.label.as_str())
                .legend(move |(x, y)| {
                    // A line with the curve's marker, or the marker alone for configurations.
                    let length = if markers_only { 0 } else { 20 };
                    EmptyElement::at((x, y))
                        + PathElement::new(vec![(0, 0), (length, 0)], colour.stroke_width(2))
                        + Circle::new((10, 0), 3, colour.filled())
                });
            chart.draw_series(points.map(|p| Circle::new(p, 3, colour.filled()))).map_err(|e| e.to_string())?;
            let bars =
                curve.points.iter().zip(&curve.bars).filter_map(|(&(x, y), bar)| bar.map(|(lo, hi)| (x, y, lo, hi)));
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
        }
        chart
            .configure_series_labels()
            .position(match legend {
                Corner::UpperRight => SeriesLabelPosition::UpperRight,
                Corner::UpperLeft => SeriesLabelPosition::UpperLeft,
                Corner::LowerRight => SeriesLabelPosition::LowerRight,
                Corner::LowerLeft => SeriesLabelPosition::LowerLeft,
            })
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.4))
            .draw()
            .map_err(|e| e.to_string())?;
        Ok(())
    }
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
        // corner free: the axis grows until the legend's corner is.
        let mut crowded = plot(vec![(1.0, 1.0), (100.0, 1.0)], Corner::LowerLeft);
        crowded.curves.push(Curve::guide("top", vec![(1.0, 100.0), (100.0, 100.0)]));
        let (fitted_x, fitted_y) =
            (axis_range([1.0, 100.0].into_iter(), true), axis_range([1.0, 100.0].into_iter(), true));
        assert!(crowded.legend_place(fitted_x, fitted_y).1 > 0);
        let (x_range, y_range, corner) = crowded.layout();
        assert_eq!(crowded.legend_place(x_range, y_range), (corner, 0));
    }
}
