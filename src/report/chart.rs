//! Line and scatter charts written as PNG and SVG with plotters.
//!
//! A [`Chart`] is plain data (title, axis labels with units, axis kinds, series). It is
//! validated as a whole before any file is touched ([`Chart::check`]); drawing is then
//! deterministic: colours and marker shapes follow the series index, ranges follow the data,
//! the legend corner follows the data, and the font is the embedded DejaVu Sans.

use std::ffi::OsString;
use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::coord::combinators::LogCoord;
use plotters::coord::ranged1d::{AsRangedCoord, DefaultFormatting, KeyPointHint, Ranged, ValueFormatter};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::file::{write_atomic, write_via_temp};
use super::font::{FAMILY, ensure_registered};
pub use super::scale::Axis;
use super::scale::{Along, Ticks, Window, auto_range, fmt_tick, from_axis, ticks, to_axis};
use crate::error::ReportError;

/// Default image width, px: with [`DEFAULT_HEIGHT`], 3:2, a 6 × 4 in figure at 150 dpi,
/// which fits a report column and keeps 15 px tick labels legible.
pub const DEFAULT_WIDTH: u32 = 900;
/// Default image height, px (see [`DEFAULT_WIDTH`]).
pub const DEFAULT_HEIGHT: u32 = 600;
/// Smallest accepted width and height, px: below this the title, tick labels and legend
/// overlap the plot.
pub const MIN_SIZE: u32 = 200;

/// Series colours, by series index (cycled): the Okabe–Ito colour-blind-safe palette without
/// its yellow (unreadable on white paper), ordered so the first few differ also in grey.
pub const PALETTE: [RGBColor; 7] = [
    RGBColor(0, 114, 178),   // blue
    RGBColor(213, 94, 0),    // vermillion
    RGBColor(0, 158, 115),   // bluish green
    RGBColor(204, 121, 167), // reddish purple
    RGBColor(230, 159, 0),   // orange
    RGBColor(86, 180, 233),  // sky blue
    RGBColor(0, 0, 0),       // black
];

/// Marker shapes, by series index (cycled independently of [`PALETTE`], so up to 42 series
/// differ in colour or shape, and series stay apart in a grey-scale print).
pub const MARKERS: [Marker; 6] = [Marker::Circle, Marker::Square, Marker::TriangleUp, Marker::Diamond, Marker::TriangleDown, Marker::Plus];

/// Line width, px: 2 px survives down-scaling to a report column.
const LINE_WIDTH: u32 = 2;
/// Marker radius, px.
const MARKER_RADIUS: f64 = 5.0;
const FONT_TITLE: u32 = 24;
const FONT_AXIS_LABEL: u32 = 18;
const FONT_TICKS: u32 = 15;
const FONT_LEGEND: u32 = 15;
const FONT_POINT_LABEL: u32 = 15;
/// Outer margin, x tick/label band, y tick/label band, px. The y band holds tick labels
/// like "-1.2345e-5" beside a rotated axis label.
const MARGIN: u32 = 20;
const X_LABEL_AREA: u32 = 55;
const Y_LABEL_AREA: u32 = 90;
/// Gap between the plot's right edge and a legend drawn outside it ([`Legend::Outside`]), px.
const LEGEND_OUTSIDE_GAP: u32 = 10;
/// Offset of a point label from its marker, px, right and up, clear of the marker.
const POINT_LABEL_OFFSET: (i32, i32) = (8, -18);

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SeriesStyle {
    /// Straight segments between consecutive points (a single point draws nothing).
    #[default]
    Line,
    /// A marker at each point, no line (scatter).
    Markers,
    /// Segments and markers.
    LineMarkers,
    /// Staircase: each value holds until the next point's x (`(x0,y0)→(x1,y0)→(x1,y1)…`),
    /// for piecewise-constant histories. No markers.
    Step,
}

impl SeriesStyle {
    fn draws_line(self) -> bool {
        matches!(self, SeriesStyle::Line | SeriesStyle::LineMarkers | SeriesStyle::Step)
    }

    fn draws_markers(self) -> bool {
        matches!(self, SeriesStyle::Markers | SeriesStyle::LineMarkers)
    }
}

/// Marker shape (see [`MARKERS`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Marker {
    Circle,
    Square,
    TriangleUp,
    Diamond,
    TriangleDown,
    Plus,
}

impl Marker {
    /// Vertices of the filled marker around (0, 0), in pixels (y down).
    fn vertices(self) -> Vec<(i32, i32)> {
        let r = MARKER_RADIUS;
        let px = |x: f64, y: f64| (x.round() as i32, y.round() as i32);
        match self {
            Marker::Circle => (0..16).map(|k| std::f64::consts::TAU * k as f64 / 16.0).map(|a| px(r * a.cos(), r * a.sin())).collect(),
            Marker::Square => {
                let s = 0.85 * r;
                vec![px(-s, -s), px(s, -s), px(s, s), px(-s, s)]
            }
            Marker::TriangleUp => vec![px(0.0, -1.15 * r), px(r, 0.75 * r), px(-r, 0.75 * r)],
            Marker::TriangleDown => vec![px(0.0, 1.15 * r), px(r, -0.75 * r), px(-r, -0.75 * r)],
            Marker::Diamond => vec![px(0.0, -1.2 * r), px(r, 0.0), px(0.0, 1.2 * r), px(-r, 0.0)],
            Marker::Plus => {
                let (a, w) = (1.1 * r, 0.35 * r);
                vec![
                    px(-w, -a), px(w, -a), px(w, -w), px(a, -w), px(a, w), px(w, w),
                    px(w, a), px(-w, a), px(-w, w), px(-a, w), px(-a, -w), px(-w, -w),
                ]
            }
        }
    }
}

/// Colour of series `index`.
pub fn series_color(index: usize) -> RGBColor {
    PALETTE[index % PALETTE.len()]
}

/// Marker shape of series `index`.
pub fn series_marker(index: usize) -> Marker {
    MARKERS[index % MARKERS.len()]
}

/// One data series.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Series {
    /// Legend text; an empty name leaves the series out of the legend.
    pub name: String,
    pub points: Vec<(f64, f64)>,
    pub style: SeriesStyle,
    /// One text label per point, drawn right of and above its marker (empty strings draw
    /// nothing). Labels are drawn only where markers are, so only with `Markers` or `LineMarkers`.
    pub labels: Option<Vec<String>>,
}

impl Series {
    pub fn new(name: impl Into<String>, points: impl IntoIterator<Item = (f64, f64)>, style: SeriesStyle) -> Self {
        Series { name: name.into(), points: points.into_iter().collect(), style, labels: None }
    }

    pub fn line(name: impl Into<String>, points: impl IntoIterator<Item = (f64, f64)>) -> Self {
        Series::new(name, points, SeriesStyle::Line)
    }

    pub fn markers(name: impl Into<String>, points: impl IntoIterator<Item = (f64, f64)>) -> Self {
        Series::new(name, points, SeriesStyle::Markers)
    }

    pub fn line_markers(name: impl Into<String>, points: impl IntoIterator<Item = (f64, f64)>) -> Self {
        Series::new(name, points, SeriesStyle::LineMarkers)
    }

    pub fn step(name: impl Into<String>, points: impl IntoIterator<Item = (f64, f64)>) -> Self {
        Series::new(name, points, SeriesStyle::Step)
    }

    /// Adds per-point labels (checked against the point count by [`Chart::check`]).
    pub fn with_labels<S: Into<String>>(mut self, labels: impl IntoIterator<Item = S>) -> Self {
        self.labels = Some(labels.into_iter().map(Into::into).collect());
        self
    }

    /// Vertices of the drawn line in value space: the points, or the staircase for `Step`.
    fn line_vertices(&self) -> Vec<(f64, f64)> {
        match self.style {
            SeriesStyle::Step => {
                let mut v = Vec::with_capacity(2 * self.points.len());
                for (k, &p) in self.points.iter().enumerate() {
                    if k > 0 {
                        v.push((p.0, self.points[k - 1].1));
                    }
                    v.push(p);
                }
                v
            }
            _ => self.points.clone(),
        }
    }
}

/// Where the legend goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Legend {
    /// The inner corner whose area holds the fewest drawn points, lines and labels; ties in
    /// the order upper right, upper left, lower right, lower left. Default, so a legend does
    /// not hide data whichever way the curves run.
    #[default]
    Auto,
    UpperLeft,
    UpperRight,
    LowerLeft,
    LowerRight,
    /// Right of the plot, outside it (the plot narrows to make room): what `Auto` chooses when
    /// every inner corner would cover drawn data.
    Outside,
    /// No legend.
    Hidden,
}

/// A chart: the data to draw and how. Build with [`Chart::new`] and fill the public fields.
#[derive(Debug, Clone, PartialEq)]
pub struct Chart {
    pub title: String,
    /// Axis descriptions, with units as they should read, e.g. `"PGA [g]"`.
    pub x_label: String,
    pub y_label: String,
    pub x_axis: Axis,
    pub y_axis: Axis,
    pub series: Vec<Series>,
    /// Fixed ranges (values, `lo < hi`, both > 0 on a log axis); `None` fits the data (see
    /// [`crate::report::scale::auto_range`]). Parts of series outside a fixed range are clipped.
    pub x_range: Option<(f64, f64)>,
    pub y_range: Option<(f64, f64)>,
    pub legend: Legend,
    /// Image size, px; the SVG has the same nominal size.
    pub width: u32,
    pub height: u32,
}

/// The two files written by [`Chart::write_png_svg`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChartFiles {
    pub png: PathBuf,
    pub svg: PathBuf,
}

/// A validated chart: resolved ranges, window and legend corner. Computed once by
/// [`Chart::check`] and shared by both image writers.
#[derive(Debug, Clone)]
pub struct ChartPlan {
    pub x_range: (f64, f64),
    pub y_range: (f64, f64),
    /// The legend corner, `None` if no legend is drawn.
    pub legend: Option<Legend>,
    /// Extra right margin for a legend outside the plot, px (0 otherwise).
    pub outside_legend_px: u32,
    /// The axes' ticks ([`crate::report::scale::ticks`]), for the plot narrowed by the legend.
    pub x_ticks: Ticks,
    pub y_ticks: Ticks,
    window: Window,
}

impl Chart {
    /// Empty chart with linear axes, automatic ranges, automatic legend, 900 × 600 px
    /// ([`DEFAULT_WIDTH`], [`DEFAULT_HEIGHT`]).
    pub fn new(title: impl Into<String>, x_label: impl Into<String>, y_label: impl Into<String>) -> Self {
        Chart {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            x_axis: Axis::Linear,
            y_axis: Axis::Linear,
            series: Vec::new(),
            x_range: None,
            y_range: None,
            legend: Legend::Auto,
            width: DEFAULT_WIDTH,
            height: DEFAULT_HEIGHT,
        }
    }

    /// Validates the chart and resolves its ranges and legend corner.
    ///
    /// Errors, first found in series order then point order: a non-finite coordinate
    /// ([`ReportError::NonFinite`]), a value <= 0 on a log axis
    /// ([`ReportError::NonPositiveOnLog`]), a label count that differs from the point count,
    /// an invalid fixed range, a size below [`MIN_SIZE`], no data to fit an automatic range.
    pub fn check(&self) -> Result<ChartPlan, ReportError> {
        if self.width < MIN_SIZE || self.height < MIN_SIZE {
            return Err(ReportError::InvalidSize { chart: self.title.clone(), width: self.width, height: self.height, min: MIN_SIZE });
        }
        let mut bounds: Option<((f64, f64), (f64, f64))> = None;
        for s in &self.series {
            if let Some(labels) = &s.labels
                && labels.len() != s.points.len()
            {
                return Err(ReportError::LabelCount { chart: self.title.clone(), series: s.name.clone(), labels: labels.len(), points: s.points.len() });
            }
            for (index, &(x, y)) in s.points.iter().enumerate() {
                let point_error = |axis: Option<char>| match axis {
                    None => ReportError::NonFinite { chart: self.title.clone(), series: s.name.clone(), index, x, y },
                    Some(axis) => ReportError::NonPositiveOnLog { chart: self.title.clone(), series: s.name.clone(), index, x, y, axis },
                };
                if !x.is_finite() || !y.is_finite() {
                    return Err(point_error(None));
                }
                if self.x_axis == Axis::Log && x <= 0.0 {
                    return Err(point_error(Some('x')));
                }
                if self.y_axis == Axis::Log && y <= 0.0 {
                    return Err(point_error(Some('y')));
                }
                bounds = Some(match bounds {
                    None => ((x, x), (y, y)),
                    Some(((x0, x1), (y0, y1))) => ((x0.min(x), x1.max(x)), (y0.min(y), y1.max(y))),
                });
            }
        }
        let x_range = self.resolve_range('x', self.x_axis, self.x_range, bounds.map(|b| b.0))?;
        let y_range = self.resolve_range('y', self.y_axis, self.y_range, bounds.map(|b| b.1))?;
        let window = Window::new(
            (to_axis(self.x_axis, x_range.0), to_axis(self.x_axis, x_range.1)),
            (to_axis(self.y_axis, y_range.0), to_axis(self.y_axis, y_range.1)),
        );
        let mut plan = ChartPlan { x_range, y_range, legend: None, outside_legend_px: 0, x_ticks: Ticks::default(), y_ticks: Ticks::default(), window };
        plan.legend = self.legend_corner(&plan);
        if plan.legend == Some(Legend::Outside) {
            plan.outside_legend_px = self.legend_box_px().0.ceil() as u32 + LEGEND_OUTSIDE_GAP;
        }
        let (pw, ph) = self.plot_pixels();
        let pw = (pw - plan.outside_legend_px as f64).max(1.0);
        plan.x_ticks = ticks(self.x_axis, x_range, pw, FONT_TICKS as f64, Along::Horizontal);
        plan.y_ticks = ticks(self.y_axis, y_range, ph, FONT_TICKS as f64, Along::Vertical);
        Ok(plan)
    }

    fn resolve_range(&self, axis_name: char, axis: Axis, fixed: Option<(f64, f64)>, data: Option<(f64, f64)>) -> Result<(f64, f64), ReportError> {
        let invalid = |lo: f64, hi: f64, reason: &str| ReportError::InvalidRange { chart: self.title.clone(), axis: axis_name, lo, hi, reason: reason.to_string() };
        match (fixed, data) {
            (Some((lo, hi)), _) => {
                if !lo.is_finite() || !hi.is_finite() {
                    Err(invalid(lo, hi, "both bounds must be finite"))
                } else if lo >= hi {
                    Err(invalid(lo, hi, "the lower bound must be below the upper bound"))
                } else if axis == Axis::Log && lo <= 0.0 {
                    Err(invalid(lo, hi, "a logarithmic axis needs both bounds > 0"))
                } else {
                    Ok((lo, hi))
                }
            }
            (None, Some((lo, hi))) => Ok(auto_range(axis, lo, hi)),
            (None, None) => Err(ReportError::NoData { chart: self.title.clone() }),
        }
    }

    /// Pixel size of one axis-space unit, estimated from the image size and the fixed
    /// layout bands (the caption height is taken as 40 px). Used only to place the legend and
    /// to account for label text, where a few pixels do not matter.
    fn plot_pixels(&self) -> (f64, f64) {
        let w = self.width as f64 - 2.0 * MARGIN as f64 - Y_LABEL_AREA as f64;
        let h = self.height as f64 - 2.0 * MARGIN as f64 - X_LABEL_AREA as f64 - 40.0;
        (w.max(1.0), h.max(1.0))
    }

    /// Everything drawn in the plot, as sample points in the window's unit square.
    fn drawn_samples(&self, plan: &ChartPlan) -> Vec<(f64, f64)> {
        let (pw, ph) = self.plot_pixels();
        let mut samples = Vec::new();
        for s in &self.series {
            if s.style.draws_line() {
                for piece in self.clipped_line(s, plan) {
                    for w in piece.windows(2) {
                        let (a, b) = (plan.window.unit(w[0]), plan.window.unit(w[1]));
                        // One sample per 1 % of the plot along the segment, at least the ends.
                        let n = ((((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt() / 0.01).ceil() as usize).max(1);
                        samples.extend((0..=n).map(|k| k as f64 / n as f64).map(|t| (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1))));
                    }
                }
            }
            if s.style.draws_markers() {
                for (k, p) in self.visible_points(s, plan) {
                    let u = plan.window.unit(p);
                    samples.push(u);
                    if let Some(label) = s.labels.as_ref().map(|l| &l[k]).filter(|l| !l.is_empty()) {
                        // Label box: from the offset to its estimated end (0.55 em per char).
                        let x0 = u.0 + POINT_LABEL_OFFSET.0 as f64 / pw;
                        let len = 0.55 * FONT_POINT_LABEL as f64 * label.chars().count() as f64 / pw;
                        let y = u.1 - POINT_LABEL_OFFSET.1 as f64 / ph;
                        let n = (len / 0.01).ceil() as usize;
                        samples.extend((0..=n).map(|j| (x0 + len * j as f64 / n.max(1) as f64, y)));
                    }
                }
            }
        }
        samples
    }

    fn legend_corner(&self, plan: &ChartPlan) -> Option<Legend> {
        let named: Vec<&Series> = self.series.iter().filter(|s| !s.name.is_empty()).collect();
        if named.is_empty() || self.legend == Legend::Hidden {
            return None;
        }
        if self.legend != Legend::Auto {
            return Some(self.legend);
        }
        let (pw, ph) = self.plot_pixels();
        let (bw, bh) = self.legend_box_px();
        let (bw, bh) = ((bw / pw).min(1.0), (bh / ph).min(1.0));
        let samples = self.drawn_samples(plan);
        let corners = [
            (Legend::UpperRight, (1.0 - bw, 1.0), (1.0 - bh, 1.0)),
            (Legend::UpperLeft, (0.0, bw), (1.0 - bh, 1.0)),
            (Legend::LowerRight, (1.0 - bw, 1.0), (0.0, bh)),
            (Legend::LowerLeft, (0.0, bw), (0.0, bh)),
        ];
        let count = |x: (f64, f64), y: (f64, f64)| samples.iter().filter(|p| p.0 >= x.0 && p.0 <= x.1 && p.1 >= y.0 && p.1 <= y.1).count();
        // min_by_key keeps the first of equal counts: the tie order above; outside the plot
        // when every corner covers data
        corners.iter().map(|(c, x, y)| (*c, count(*x, *y))).min_by_key(|c| c.1).map(|(c, n)| if n == 0 { c } else { Legend::Outside })
    }

    /// Estimated legend box (width, height), px: swatch and padding 45 px + 0.6 em per char
    /// wide, 22 px per entry high, plus plotters' 5 px legend margin.
    fn legend_box_px(&self) -> (f64, f64) {
        let named: Vec<&Series> = self.series.iter().filter(|s| !s.name.is_empty()).collect();
        let chars = named.iter().map(|s| s.name.chars().count()).max().unwrap_or(0) as f64;
        (45.0 + 0.6 * FONT_LEGEND as f64 * chars + 10.0, 22.0 * named.len() as f64 + 20.0)
    }

    /// Pieces of the series' line inside the window, in axis space.
    fn clipped_line(&self, s: &Series, plan: &ChartPlan) -> Vec<Vec<(f64, f64)>> {
        let axis_points: Vec<(f64, f64)> = s.line_vertices().iter().map(|&(x, y)| (to_axis(self.x_axis, x), to_axis(self.y_axis, y))).collect();
        plan.window.clip_polyline(&axis_points)
    }

    /// (index, axis-space point) of the series' points inside the window.
    fn visible_points(&self, s: &Series, plan: &ChartPlan) -> Vec<(usize, (f64, f64))> {
        s.points
            .iter()
            .map(|&(x, y)| (to_axis(self.x_axis, x), to_axis(self.y_axis, y)))
            .enumerate()
            .filter(|(_, p)| plan.window.contains(*p))
            .collect()
    }

    /// Axis-space point back to values.
    fn value_point(&self, p: (f64, f64)) -> (f64, f64) {
        (from_axis(self.x_axis, p.0), from_axis(self.y_axis, p.1))
    }

    /// Writes `<stem>.png` and `<stem>.svg` (the suffix is appended, so a stem containing a
    /// dot keeps it), each atomically, creating the directory if needed. The chart is
    /// validated first, so an invalid chart writes nothing.
    pub fn write_png_svg(&self, stem: &Path) -> Result<ChartFiles, ReportError> {
        let plan = self.check()?;
        let files = ChartFiles { png: with_suffix(stem, ".png"), svg: with_suffix(stem, ".svg") };
        self.write_png_planned(&plan, &files.png)?;
        self.write_svg_planned(&plan, &files.svg)?;
        Ok(files)
    }

    /// Writes the chart as a PNG at `path`, atomically.
    pub fn write_png(&self, path: &Path) -> Result<(), ReportError> {
        let plan = self.check()?;
        self.write_png_planned(&plan, path)
    }

    /// Writes the chart as an SVG at `path`, atomically.
    pub fn write_svg(&self, path: &Path) -> Result<(), ReportError> {
        let plan = self.check()?;
        self.write_svg_planned(&plan, path)
    }

    /// Appends the chart as an SVG document to `out`.
    pub fn render_svg_into(&self, out: &mut String) -> Result<(), ReportError> {
        let plan = self.check()?;
        self.render_svg_planned_into(&plan, out)
    }

    fn write_png_planned(&self, plan: &ChartPlan, path: &Path) -> Result<(), ReportError> {
        ensure_registered()?;
        write_via_temp(path, |tmp| {
            // The bitmap backend encodes on `present`, choosing PNG from the temp file's extension.
            let root = BitMapBackend::new(tmp, (self.width, self.height)).into_drawing_area();
            self.draw(plan, &root).map_err(|message| self.draw_error(path.display().to_string(), message))
        })
    }

    fn write_svg_planned(&self, plan: &ChartPlan, path: &Path) -> Result<(), ReportError> {
        let mut svg = String::new();
        self.render_svg_planned_into(plan, &mut svg)?;
        write_atomic(path, svg.as_bytes())
    }

    fn render_svg_planned_into(&self, plan: &ChartPlan, out: &mut String) -> Result<(), ReportError> {
        ensure_registered()?;
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (self.width, self.height)).into_drawing_area();
            self.draw(plan, &root).map_err(|message| self.draw_error("SVG".to_string(), message))?;
        } // the SVG backend completes the document when dropped
        out.push_str(&svg);
        Ok(())
    }

    /// The legend right of the plot ([`Legend::Outside`]): per named series its swatch (line
    /// and/or marker as drawn) and name, from the top of the plot down.
    fn draw_outside_legend<DB: DrawingBackend>(&self, plan: &ChartPlan, root: &DrawingArea<DB, Shift>) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let x0 = self.width as i32 - MARGIN as i32 - plan.outside_legend_px as i32 + LEGEND_OUTSIDE_GAP as i32;
        let mut y = MARGIN as i32 + 50;
        let font = (FAMILY, FONT_LEGEND).into_font().color(&BLACK);
        for (i, s) in self.series.iter().enumerate().filter(|(_, s)| !s.name.is_empty()) {
            let color = series_color(i);
            if s.style.draws_line() {
                root.draw(&PathElement::new(vec![(x0, y), (x0 + 24, y)], ShapeStyle { color: color.to_rgba(), filled: false, stroke_width: LINE_WIDTH }))?;
            }
            if s.style.draws_markers() {
                root.draw(&(EmptyElement::at((x0 + 12, y)) + Polygon::new(series_marker(i).vertices(), color.filled())))?;
            }
            root.draw(&Text::new(s.name.clone(), (x0 + 32, y - 8), font.clone()))?;
            y += 22;
        }
        Ok(())
    }

    fn draw_error(&self, target: String, message: String) -> ReportError {
        ReportError::Draw { chart: self.title.clone(), target, message }
    }

    fn draw<DB: DrawingBackend>(&self, plan: &ChartPlan, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let (x, y) = (plan.x_range.0..plan.x_range.1, plan.y_range.0..plan.y_range.1);
        let (tx, ty) = (plan.x_ticks.clone(), plan.y_ticks.clone());
        let lin = |r: std::ops::Range<f64>, t: Ticks| Ticked { inner: RangedCoordf64::from(r), ticks: t };
        let log = |r: std::ops::Range<f64>, t: Ticks| Ticked { inner: LogCoord::<f64>::from(r.log_scale()), ticks: t };
        match (self.x_axis, self.y_axis) {
            (Axis::Linear, Axis::Linear) => self.draw_on(plan, root, lin(x, tx), lin(y, ty)),
            (Axis::Log, Axis::Linear) => self.draw_on(plan, root, log(x, tx), lin(y, ty)),
            (Axis::Linear, Axis::Log) => self.draw_on(plan, root, lin(x, tx), log(y, ty)),
            (Axis::Log, Axis::Log) => self.draw_on(plan, root, log(x, tx), log(y, ty)),
        }
        .map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())
    }

    fn draw_on<DB, X, Y>(&self, plan: &ChartPlan, root: &DrawingArea<DB, Shift>, x: X, y: Y) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>>
    where
        DB: DrawingBackend,
        X: AsRangedCoord<Value = f64>,
        Y: AsRangedCoord<Value = f64>,
        X::CoordDescType: ValueFormatter<f64>,
        Y::CoordDescType: ValueFormatter<f64>,
    {
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, (FAMILY, FONT_TITLE))
            .margin(MARGIN)
            .margin_right(MARGIN + plan.outside_legend_px)
            .x_label_area_size(X_LABEL_AREA)
            .y_label_area_size(Y_LABEL_AREA)
            .build_cartesian_2d(x, y)?;
        let zero_below = |axis: Axis, range: (f64, f64)| if axis == Axis::Linear { 1e-9 * (range.1 - range.0) } else { 0.0 };
        let (x_zero, y_zero) = (zero_below(self.x_axis, plan.x_range), zero_below(self.y_axis, plan.y_range));
        let x_tick = |v: &f64| fmt_tick(*v, x_zero);
        let y_tick = |v: &f64| fmt_tick(*v, y_zero);
        chart
            .configure_mesh()
            .x_desc(&self.x_label)
            .y_desc(&self.y_label)
            .label_style((FAMILY, FONT_TICKS))
            .axis_desc_style((FAMILY, FONT_AXIS_LABEL))
            .x_label_formatter(&x_tick)
            .y_label_formatter(&y_tick)
            .draw()?;

        for (i, s) in self.series.iter().enumerate() {
            let color = series_color(i);
            let line_style = ShapeStyle { color: color.to_rgba(), filled: false, stroke_width: LINE_WIDTH };
            let marker = series_marker(i);
            let marker_vertices = marker.vertices();
            // Set once the legend entry is registered, on the first drawn part of the series.
            let mut in_legend = s.name.is_empty();
            // Legend swatch: a line and/or a marker as drawn; a part the style lacks is drawn
            // transparent, which both backends skip (an empty path would still emit SVG).
            let transparent = ShapeStyle { color: TRANSPARENT, filled: true, stroke_width: LINE_WIDTH };
            let swatch_line = if s.style.draws_line() { line_style } else { transparent };
            let swatch_marker = if s.style.draws_markers() { color.filled() } else { transparent };
            let swatch_vertices = marker_vertices.clone();
            let legend = move |(lx, ly): (i32, i32)| {
                EmptyElement::at((lx, ly)) + PathElement::new(vec![(-12, 0), (12, 0)], swatch_line) + Polygon::new(swatch_vertices.clone(), swatch_marker)
            };
            if s.style.draws_line() {
                for piece in self.clipped_line(s, plan) {
                    let values: Vec<(f64, f64)> = piece.iter().map(|&p| self.value_point(p)).collect();
                    let anno = chart.draw_series(LineSeries::new(values, line_style))?;
                    if !in_legend {
                        anno.label(&s.name).legend(legend.clone());
                        in_legend = true;
                    }
                }
            }
            let visible = if s.style.draws_markers() { self.visible_points(s, plan) } else { Vec::new() };
            let anno = chart.draw_series(
                visible.iter().map(|&(_, p)| EmptyElement::at(self.value_point(p)) + Polygon::new(marker_vertices.clone(), color.filled())),
            )?;
            if !in_legend {
                // Also when nothing of the series is visible: the legend lists every named series.
                anno.label(&s.name).legend(legend);
            }
            if let Some(labels) = &s.labels {
                let font = (FAMILY, FONT_POINT_LABEL).into_font().color(&BLACK);
                chart.draw_series(visible.iter().filter(|(k, _)| !labels[*k].is_empty()).map(|&(k, p)| {
                    EmptyElement::at(self.value_point(p)) + Text::new(labels[k].clone(), POINT_LABEL_OFFSET, font.clone())
                }))?;
            }
        }

        if let Some(corner) = plan.legend {
            if corner == Legend::Outside {
                // plotters clamps its legend to the plotting area: drawn here on the whole image
                return self.draw_outside_legend(plan, root);
            }
            let position = match corner {
                Legend::UpperLeft => SeriesLabelPosition::UpperLeft,
                Legend::LowerLeft => SeriesLabelPosition::LowerLeft,
                Legend::LowerRight => SeriesLabelPosition::LowerRight,
                _ => SeriesLabelPosition::UpperRight,
            };
            chart
                .configure_series_labels()
                .position(position)
                .background_style(WHITE.mix(0.9))
                .border_style(BLACK)
                .label_font((FAMILY, FONT_LEGEND))
                .draw()?;
        }
        Ok(())
    }
}

/// A plotters coordinate with our ticks ([`ChartPlan::x_ticks`]) instead of its own key points,
/// so log axes get 1-2-5 or decade labels and no axis gets overlapping labels.
pub(crate) struct Ticked<R> {
    pub(crate) inner: R,
    pub(crate) ticks: Ticks,
}

impl<R: Ranged<ValueType = f64>> Ranged for Ticked<R> {
    type ValueType = f64;
    type FormatOption = DefaultFormatting;

    fn range(&self) -> std::ops::Range<f64> {
        self.inner.range()
    }

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.inner.map(value, limit)
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() { self.ticks.light.clone() } else { self.ticks.labelled.clone() }
    }

    fn axis_pixel_range(&self, limit: (i32, i32)) -> std::ops::Range<i32> {
        self.inner.axis_pixel_range(limit)
    }
}

/// `stem` with `suffix` appended to its last component (not replacing an extension).
fn with_suffix(stem: &Path, suffix: &str) -> PathBuf {
    let mut s: OsString = stem.as_os_str().to_owned();
    s.push(suffix);
    PathBuf::from(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chart_with(series: Vec<Series>) -> Chart {
        Chart { series, ..Chart::new("t", "x [m]", "y [s]") }
    }

    #[test]
    fn colours_and_markers_follow_the_index() {
        assert_eq!(series_color(0), PALETTE[0]);
        assert_eq!(series_color(PALETTE.len() + 2), PALETTE[2]);
        assert_eq!(series_marker(MARKERS.len()), Marker::Circle);
        let distinct: std::collections::HashSet<(u8, u8, u8, usize)> =
            (0..42).map(|i| (series_color(i).0, series_color(i).1, series_color(i).2, i % MARKERS.len())).collect();
        assert_eq!(distinct.len(), 42);
    }

    #[test]
    fn step_vertices_hold_each_value() {
        let s = Series::step("s", [(0.0, 1.0), (1.0, 2.0), (3.0, 0.5)]);
        assert_eq!(s.line_vertices(), vec![(0.0, 1.0), (1.0, 1.0), (1.0, 2.0), (3.0, 2.0), (3.0, 0.5)]);
    }

    #[test]
    fn stem_suffix_keeps_dots() {
        assert_eq!(with_suffix(Path::new("out/pga_0.3g"), ".png"), PathBuf::from("out/pga_0.3g.png"));
    }

    #[test]
    fn check_reports_the_first_bad_point_by_series_and_index() {
        let c = Chart { y_axis: Axis::Log, ..chart_with(vec![Series::line("ok", [(0.0, 1.0)]), Series::line("bad", [(1.0, 2.0), (2.0, 0.0)])]) };
        match c.check().unwrap_err() {
            ReportError::NonPositiveOnLog { series, index, axis, .. } => assert_eq!((series.as_str(), index, axis), ("bad", 1, 'y')),
            e => panic!("{e}"),
        }
        let c = chart_with(vec![Series::line("nan", [(1.0, 2.0), (f64::INFINITY, 1.0)])]);
        assert!(matches!(c.check().unwrap_err(), ReportError::NonFinite { index: 1, .. }));
        let c = chart_with(vec![Series::markers("l", [(1.0, 2.0)]).with_labels(["a", "b"])]);
        assert!(matches!(c.check().unwrap_err(), ReportError::LabelCount { labels: 2, points: 1, .. }));
    }

    #[test]
    fn check_validates_ranges_and_size() {
        assert!(matches!(chart_with(vec![]).check().unwrap_err(), ReportError::NoData { .. }));
        let c = Chart { x_range: Some((0.0, 1.0)), y_range: Some((1.0, 2.0)), ..chart_with(vec![]) };
        assert_eq!(c.check().unwrap().x_range, (0.0, 1.0));
        let c = Chart { x_range: Some((1.0, 1.0)), ..chart_with(vec![Series::line("a", [(0.0, 0.0)])]) };
        assert!(matches!(c.check().unwrap_err(), ReportError::InvalidRange { axis: 'x', .. }));
        let c = Chart { y_axis: Axis::Log, y_range: Some((0.0, 1.0)), ..chart_with(vec![Series::line("a", [(0.0, 1.0)])]) };
        assert!(matches!(c.check().unwrap_err(), ReportError::InvalidRange { axis: 'y', .. }));
        let c = Chart { width: 50, ..chart_with(vec![Series::line("a", [(0.0, 1.0)])]) };
        assert!(matches!(c.check().unwrap_err(), ReportError::InvalidSize { width: 50, .. }));
    }

    #[test]
    fn auto_legend_avoids_the_data() {
        // A rising line fills the upper right and lower left: the legend goes upper left.
        let c = chart_with(vec![Series::line("rising", (0..=10).map(|k| (k as f64, k as f64)))]);
        assert_eq!(c.check().unwrap().legend, Some(Legend::UpperLeft));
        // A falling line: upper right is free (first in the tie order).
        let c = chart_with(vec![Series::line("falling", (0..=10).map(|k| (k as f64, 10.0 - k as f64)))]);
        assert_eq!(c.check().unwrap().legend, Some(Legend::UpperRight));
        // No named series, or hidden: no legend.
        assert_eq!(chart_with(vec![Series::line("", [(0.0, 0.0), (1.0, 1.0)])]).check().unwrap().legend, None);
        let c = Chart { legend: Legend::Hidden, ..chart_with(vec![Series::line("a", [(0.0, 0.0)])]) };
        assert_eq!(c.check().unwrap().legend, None);
    }

    #[test]
    fn svg_names_series_and_axes() {
        let c = Chart {
            x_axis: Axis::Log,
            ..chart_with(vec![Series::line_markers("alpha", [(1.0, 1.0), (10.0, 3.0)]), Series::markers("beta & co", [(2.0, 2.0)]).with_labels(["p1"])])
        };
        let mut svg = String::new();
        c.render_svg_into(&mut svg).unwrap();
        for needle in ["<svg", "alpha", "beta &amp; co", "x [m]", "y [s]", "p1", "</svg>"] {
            assert!(svg.contains(needle), "missing {needle}");
        }
    }
}
