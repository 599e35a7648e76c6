//! Filled maps written as PNG and SVG with plotters: polygons coloured by a value in bands (a
//! filled contour map at the polygons' resolution), side-by-side panels on one colour scale
//! with one colour bar, overlay polylines (outlines, traces) and marked points with a label.
//!
//! A [`Map`] is plain data, validated whole before any file is touched ([`Map::check`]); it
//! knows nothing of what the polygons are. Conventions: the panels share the x and y ranges
//! (the union of their polygons) and the value range (`range`, or the values' extent), so two
//! panels compare at a glance; `bands` equal bands over the value range, coloured from
//! [`BAND_COLOURS`] resampled; a value outside a fixed range takes the end band.

use std::path::Path;

use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::chart::{ChartFiles, Ticked};
use super::file::{write_atomic, write_via_temp};
use super::font::{FAMILY, ensure_registered};
use super::scale::{Along, Axis, auto_range, fmt_tick, ticks};
use crate::error::ReportError;

/// The colour scale, low to high: viridis at 9 stops (perceptually uniform, readable in grey
/// and by colour-blind readers); bands interpolate between the stops.
pub const BAND_COLOURS: [RGBColor; 9] = [
    RGBColor(68, 1, 84),
    RGBColor(71, 44, 122),
    RGBColor(59, 81, 139),
    RGBColor(44, 113, 142),
    RGBColor(33, 144, 141),
    RGBColor(39, 173, 129),
    RGBColor(92, 200, 99),
    RGBColor(170, 220, 50),
    RGBColor(253, 231, 37),
];

/// Default number of bands: 10 reads to a tenth of the range without bands too alike to tell.
pub const DEFAULT_BANDS: usize = 10;
/// Default panel size, px: 760 × 560 holds a dam face's width-to-height ratio of about 2.
pub const PANEL_WIDTH: u32 = 760;
pub const PANEL_HEIGHT: u32 = 560;
/// Width of the colour bar's area, px (bar, tick labels and the rotated value label).
const BAR_AREA: u32 = 150;
const FONT_TITLE: u32 = 24;
const FONT_PANEL: u32 = 20;
const FONT_AXIS_LABEL: u32 = 18;
const FONT_TICKS: u32 = 15;
const FONT_MARK: u32 = 16;

/// One panel: polygons with their values, overlay polylines, marked points.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MapPanel {
    pub title: String,
    /// (vertices, value): each polygon filled with its value's band colour.
    pub polygons: Vec<(Vec<(f64, f64)>, f64)>,
    /// Drawn in black over the fill (outlines, traces).
    pub lines: Vec<Vec<(f64, f64)>>,
    /// A marker at the point with its text beside it (e.g. the maximum and its value).
    pub marks: Vec<((f64, f64), String)>,
}

/// A map: one or more panels on one colour scale, with a colour bar on the right.
#[derive(Debug, Clone, PartialEq)]
pub struct Map {
    pub title: String,
    /// Axis descriptions with units, shared by the panels.
    pub x_label: String,
    pub y_label: String,
    /// The colour bar's description with its unit, e.g. `"σ1 [MPa]"`.
    pub value_label: String,
    pub panels: Vec<MapPanel>,
    /// Fixed value range; `None`: the values' extent.
    pub range: Option<(f64, f64)>,
    pub bands: usize,
    /// Size of one panel, px (the image is `panels × panel_width + bar` wide).
    pub panel_width: u32,
    pub panel_height: u32,
}

/// A validated map: resolved ranges.
#[derive(Debug, Clone)]
pub struct MapPlan {
    pub x_range: (f64, f64),
    pub y_range: (f64, f64),
    pub value_range: (f64, f64),
}

impl Map {
    pub fn new(title: impl Into<String>, x_label: impl Into<String>, y_label: impl Into<String>, value_label: impl Into<String>) -> Map {
        Map {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            value_label: value_label.into(),
            panels: Vec::new(),
            range: None,
            bands: DEFAULT_BANDS,
            panel_width: PANEL_WIDTH,
            panel_height: PANEL_HEIGHT,
        }
    }

    /// Image size, px.
    pub fn size(&self) -> (u32, u32) {
        (self.panel_width * self.panels.len().max(1) as u32 + BAR_AREA, self.panel_height + 50)
    }

    /// Validates the map: a non-finite vertex or value is [`ReportError::NonFinite`] naming
    /// the panel and the polygon; no polygon at all is [`ReportError::NoData`].
    pub fn check(&self) -> Result<MapPlan, ReportError> {
        let (mut xb, mut yb, mut vb): (Option<(f64, f64)>, Option<(f64, f64)>, Option<(f64, f64)>) = (None, None, None);
        let grow = |b: &mut Option<(f64, f64)>, v: f64| *b = Some(b.map_or((v, v), |(a, c)| (a.min(v), c.max(v))));
        for p in &self.panels {
            for (index, (poly, v)) in p.polygons.iter().enumerate() {
                let bad = poly.iter().find(|q| !q.0.is_finite() || !q.1.is_finite()).copied().or((!v.is_finite()).then_some((*v, *v)));
                if let Some((x, y)) = bad {
                    return Err(ReportError::NonFinite { chart: self.title.clone(), series: format!("panel \"{}\", polygon value {v}", p.title), index, x, y });
                }
                for q in poly {
                    grow(&mut xb, q.0);
                    grow(&mut yb, q.1);
                }
                grow(&mut vb, *v);
            }
        }
        let (Some(xb), Some(yb), Some(vb)) = (xb, yb, vb) else { return Err(ReportError::NoData { chart: self.title.clone() }) };
        let value_range = match self.range {
            Some((lo, hi)) if lo.is_finite() && hi.is_finite() && lo < hi => (lo, hi),
            Some((lo, hi)) => return Err(ReportError::InvalidRange { chart: self.title.clone(), axis: 'v', lo, hi, reason: "the value range must be finite with lo < hi".into() }),
            None if vb.1 > vb.0 => vb,
            None => auto_range(Axis::Linear, vb.0, vb.1),
        };
        Ok(MapPlan { x_range: auto_range(Axis::Linear, xb.0, xb.1), y_range: auto_range(Axis::Linear, yb.0, yb.1), value_range })
    }

    /// The band colour of value `v` in `range`.
    pub fn colour(&self, v: f64, range: (f64, f64)) -> RGBColor {
        let n = self.bands.max(1);
        let k = (((v - range.0) / (range.1 - range.0)) * n as f64).floor().clamp(0.0, (n - 1) as f64) as usize;
        // the band's centre on the stops
        let u = (k as f64 + 0.5) / n as f64 * (BAND_COLOURS.len() - 1) as f64;
        let (i, f) = (u.floor() as usize, u.fract());
        let (a, b) = (BAND_COLOURS[i], BAND_COLOURS[(i + 1).min(BAND_COLOURS.len() - 1)]);
        let mix = |p: u8, q: u8| (p as f64 + f * (q as f64 - p as f64)).round() as u8;
        RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
    }

    /// Writes `<stem>.png` and `<stem>.svg`, each atomically; nothing when the map is invalid.
    pub fn write_png_svg(&self, stem: &Path) -> Result<ChartFiles, ReportError> {
        let plan = self.check()?;
        ensure_registered()?;
        let s = stem.as_os_str().to_string_lossy();
        let files = ChartFiles { png: format!("{s}.png").into(), svg: format!("{s}.svg").into() };
        let size = self.size();
        let err = |target: &Path, e: String| ReportError::Draw { chart: self.title.clone(), target: target.display().to_string(), message: e };
        write_via_temp(&files.png, |tmp| {
            let root = BitMapBackend::new(tmp, size).into_drawing_area();
            self.draw(&plan, &root).map_err(|e| err(&files.png, e))
        })?;
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
            self.draw(&plan, &root).map_err(|e| err(&files.svg, e))?;
        }
        write_atomic(&files.svg, svg.as_bytes())?;
        Ok(files)
    }

    fn draw<DB: DrawingBackend>(&self, plan: &MapPlan, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        root.fill(&WHITE).map_err(e)?;
        let root = root.titled(&self.title, (FAMILY, FONT_TITLE)).map_err(e)?;
        let (w, _) = root.dim_in_pixel();
        let (panels, bar) = root.split_horizontally(w.saturating_sub(BAR_AREA));
        let areas = panels.split_evenly((1, self.panels.len().max(1)));
        for (p, area) in self.panels.iter().zip(&areas) {
            self.draw_panel(plan, p, area).map_err(e)?;
        }
        self.draw_bar(plan, &bar).map_err(e)?;
        root.present().map_err(e)
    }

    /// Ticked linear coordinates for `range` over `pixels`.
    fn coord(range: (f64, f64), pixels: f64, along: Along) -> Ticked<RangedCoordf64> {
        Ticked { inner: RangedCoordf64::from(range.0..range.1), ticks: ticks(Axis::Linear, range, pixels, FONT_TICKS as f64, along) }
    }

    fn draw_panel<DB: DrawingBackend>(&self, plan: &MapPlan, p: &MapPanel, area: &DrawingArea<DB, Shift>) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let (aw, ah) = area.dim_in_pixel();
        let (xl, yl) = (55u32, 80u32);
        let x = Self::coord(plan.x_range, aw as f64 - yl as f64 - 30.0, Along::Horizontal);
        let y = Self::coord(plan.y_range, ah as f64 - xl as f64 - 50.0, Along::Vertical);
        let mut chart = ChartBuilder::on(area)
            .caption(&p.title, (FAMILY, FONT_PANEL))
            .margin(15)
            .x_label_area_size(xl)
            .y_label_area_size(yl)
            .build_cartesian_2d(x, y)?;
        let tick = |v: &f64| fmt_tick(*v, 0.0);
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(&self.x_label)
            .y_desc(&self.y_label)
            .label_style((FAMILY, FONT_TICKS))
            .axis_desc_style((FAMILY, FONT_AXIS_LABEL))
            .x_label_formatter(&tick)
            .y_label_formatter(&tick)
            .draw()?;
        chart.draw_series(p.polygons.iter().map(|(poly, v)| Polygon::new(poly.clone(), self.colour(*v, plan.value_range).filled())))?;
        chart.draw_series(p.lines.iter().map(|l| PathElement::new(l.clone(), BLACK.stroke_width(1))))?;
        let font = (FAMILY, FONT_MARK).into_font().color(&BLACK);
        for (q, text) in &p.marks {
            chart.draw_series(std::iter::once(EmptyElement::at(*q) + Cross::new((0, 0), 7, RED.stroke_width(3)) + Text::new(text.clone(), (10, -20), font.clone())))?;
        }
        Ok(())
    }

    fn draw_bar<DB: DrawingBackend>(&self, plan: &MapPlan, area: &DrawingArea<DB, Shift>) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let (_, ah) = area.dim_in_pixel();
        let v = Self::coord(plan.value_range, ah as f64 - 120.0, Along::Vertical);
        let mut chart = ChartBuilder::on(area)
            .margin_top(50)
            .margin_bottom(70)
            .margin_right(10)
            .y_label_area_size(95)
            .build_cartesian_2d(RangedCoordf64::from(0.0..1.0), v)?;
        let tick = |x: &f64| fmt_tick(*x, 1e-9 * (plan.value_range.1 - plan.value_range.0));
        chart
            .configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_desc(&self.value_label)
            .label_style((FAMILY, FONT_TICKS))
            .axis_desc_style((FAMILY, FONT_AXIS_LABEL))
            .y_label_formatter(&tick)
            .draw()?;
        let (lo, hi) = plan.value_range;
        let n = self.bands.max(1);
        chart.draw_series((0..n).map(|k| {
            let (a, b) = (lo + (hi - lo) * k as f64 / n as f64, lo + (hi - lo) * (k + 1) as f64 / n as f64);
            Rectangle::new([(0.0, a), (1.0, b)], self.colour(0.5 * (a + b), plan.value_range).filled())
        }))?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bands_run_from_the_first_colour_to_the_last_and_clamp_outside() {
        let m = Map { bands: 4, ..Map::new("m", "x [m]", "y [m]", "v [-]") };
        let r = (0.0, 1.0);
        assert_ne!(m.colour(0.1, r), m.colour(0.3, r));
        assert_eq!(m.colour(-5.0, r), m.colour(0.0, r));
        assert_eq!(m.colour(5.0, r), m.colour(0.99, r));
        // darker at the low end (viridis): the sum of channels grows
        let sum = |c: RGBColor| c.0 as u32 + c.1 as u32 + c.2 as u32;
        assert!(sum(m.colour(0.0, r)) < sum(m.colour(0.99, r)));
    }

    #[test]
    fn a_nan_value_is_an_error_naming_the_panel() {
        let mut m = Map::new("m", "x [m]", "y [m]", "v [-]");
        m.panels.push(MapPanel { title: "left".into(), polygons: vec![(vec![(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)], f64::NAN)], ..Default::default() });
        let e = m.check().unwrap_err().to_string();
        assert!(e.contains("left"), "{e}");
        assert!(matches!(Map::new("m", "x", "y", "v").check(), Err(ReportError::NoData { .. })));
    }
}
