//! SVG line plots with error bars, drawn by `plotters` (its SVG backend
//! only: no fonts are read, the viewer renders the text).

use plotters::coord::ranged1d::ValueFormatter;
use plotters::prelude::*;

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
    /// A guide (a fitted or expected law) rather than measurements: drawn dashed, without markers.
    pub guide: bool,
}

impl Curve {
    /// A curve of measurements through `points`, without error bars.
    pub fn new(label: impl Into<String>, points: Vec<(f64, f64)>) -> Curve {
        Curve { label: label.into(), bars: vec![None; points.len()], points, guide: false }
    }

    /// The curve with an error bar per point; panics unless there is one per point.
    pub fn with_bars(mut self, bars: Vec<Option<(f64, f64)>>) -> Curve {
        assert_eq!(bars.len(), self.points.len(), "one bar per point");
        self.bars = bars;
        self
    }

    /// A guide (a fitted or expected law) through `points`, drawn dashed.
    pub fn guide(label: impl Into<String>, points: Vec<(f64, f64)>) -> Curve {
        Curve { guide: true, ..Curve::new(label, points) }
    }
}

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
    /// The plot as an SVG document; the scene and the machine go into the title.
    pub fn to_svg(&self, scene: &str, machine: &Machine) -> Result<String, ExperimentError> {
        let mut svg = String::new();
        self.draw(&mut svg, scene, machine)
            .map_err(|message| ExperimentError::Plot { file: self.file.clone(), message })?;
        Ok(svg)
    }

    fn draw(&self, svg: &mut String, scene: &str, machine: &Machine) -> Result<(), String> {
        let xs = self.curves.iter().flat_map(|c| c.points.iter().map(|p| p.0));
        let ys = self
            .curves
            .iter()
            .flat_map(|c| c.points.iter().map(|p| p.1).chain(c.bars.iter().flatten().flat_map(|&(lo, hi)| [lo, hi])));
        let x_range = axis_range(xs, self.log_x);
        let y_range = axis_range(ys, self.log_y);
        let root = SVGBackend::with_string(svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        // A scene file is named by its file name (the folder says nothing in
        // a title), a built-in scene by its name without the explanation.
        let path = std::path::Path::new(scene);
        let scene = match path.file_name() {
            Some(name) if path.is_file() => name.to_string_lossy().into_owned(),
            _ => scene.split(" (").next().unwrap_or(scene).to_owned(),
        };
        let caption = format!("{}, {scene} ({})", self.title, machine.short());
        let mut builder = ChartBuilder::on(&root);
        builder.caption(caption, ("sans-serif", 18)).margin(14).x_label_area_size(44).y_label_area_size(70);
        // The four combinations of linear and log axes are different types.
        match (self.log_x, self.log_y) {
            (false, false) => self.fill(
                builder.build_cartesian_2d(x_range.0..x_range.1, y_range.0..y_range.1).map_err(|e| e.to_string())?,
            ),
            (true, false) => self.fill(
                builder
                    .build_cartesian_2d((x_range.0..x_range.1).log_scale(), y_range.0..y_range.1)
                    .map_err(|e| e.to_string())?,
            ),
            (false, true) => self.fill(
                builder
                    .build_cartesian_2d(x_range.0..x_range.1, (y_range.0..y_range.1).log_scale())
                    .map_err(|e| e.to_string())?,
            ),
            (true, true) => self.fill(
                builder
                    .build_cartesian_2d((x_range.0..x_range.1).log_scale(), (y_range.0..y_range.1).log_scale())
                    .map_err(|e| e.to_string())?,
            ),
        }?;
        root.present().map_err(|e| e.to_string())?;
        Ok(())
    }

    fn fill<'a, X, Y>(&self, mut chart: ChartContext<'a, SVGBackend<'a>, Cartesian2d<X, Y>>) -> Result<(), String>
    where
        X: Ranged<ValueType = f64> + ValueFormatter<f64>,
        Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        chart
            .configure_mesh()
            .x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .light_line_style(RGBColor(235, 235, 235))
            .x_label_formatter(&|v| format_number(*v))
            .y_label_formatter(&|v| format_number(*v))
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
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(1)));
                continue;
            }
            chart
                .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label(curve.label.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2)));
            chart.draw_series(points.map(|p| Circle::new(p, 3, colour.filled()))).map_err(|e| e.to_string())?;
            let bars =
                curve.points.iter().zip(&curve.bars).filter_map(|(&(x, y), bar)| bar.map(|(lo, hi)| (x, y, lo, hi)));
            chart
                .draw_series(bars.map(|(x, y, lo, hi)| ErrorBar::new_vertical(x, lo, y, hi, colour.stroke_width(1), 8)))
                .map_err(|e| e.to_string())?;
        }
        chart
            .configure_series_labels()
            .position(match self.legend {
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
