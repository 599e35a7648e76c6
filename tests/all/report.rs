//! Report module: charts written as PNG + SVG, their failure modes, Pareto fronts, tables.
//! Files go to target/test-scratch/report_*; each test writes its own directory.

use std::collections::HashSet;
use std::path::Path;

use jointquake::error::{Error, ReportError};
use jointquake::report::{Axis, Chart, Series, Table, pareto_front, series_color};

use crate::common::scratch;

/// Decodes a PNG and returns (width, height, set of distinct RGB colours).
fn png_colours(path: &Path) -> (u32, u32, HashSet<[u8; 3]>) {
    let img = image::open(path).unwrap_or_else(|e| panic!("{} does not decode: {e}", path.display())).to_rgb8();
    let colours = img.pixels().map(|p| p.0).collect();
    (img.width(), img.height(), colours)
}

fn slip_chart() -> Chart {
    let pga = [0.1, 0.2, 0.3, 0.4, 0.5];
    Chart {
        series: vec![
            Series::line_markers("slip, mu = 0.6", pga.iter().map(|&a| (a, 0.02 * (a / 0.1f64).powi(2)))),
            Series::line("slip, mu = 0.7", pga.iter().map(|&a| (a, 0.01 * (a / 0.1f64).powi(2)))),
            Series::step("threshold", [(0.1, 0.1), (0.25, 0.2), (0.5, 0.2)]),
        ],
        ..Chart::new("Seismic slip against PGA", "PGA [g]", "slip [m]")
    }
}

#[test]
fn chart_writes_a_png_of_the_requested_size_and_an_svg_naming_everything() {
    let dir = scratch("report_chart");
    let chart = Chart { width: 640, height: 400, ..slip_chart() };
    let files = chart.write_png_svg(&dir.join("slip_vs_pga")).unwrap();
    assert_eq!(files.png, dir.join("slip_vs_pga.png"));
    assert_eq!(files.svg, dir.join("slip_vs_pga.svg"));

    let (w, h, colours) = png_colours(&files.png);
    assert_eq!((w, h), (640, 400));
    // Something was drawn, and in the series' colours (lines are drawn in their exact colour).
    assert!(colours.len() >= 2, "blank PNG");
    for i in 0..3 {
        let c = series_color(i);
        assert!(colours.contains(&[c.0, c.1, c.2]), "series {i} colour {c:?} not in the PNG");
    }

    let svg = std::fs::read_to_string(&files.svg).unwrap();
    assert!(svg.contains("<svg") && svg.trim_end().ends_with("</svg>"));
    for needle in ["Seismic slip against PGA", "PGA [g]", "slip [m]", "slip, mu = 0.6", "slip, mu = 0.7", "threshold"] {
        assert!(svg.contains(needle), "SVG lacks {needle:?}");
    }
    // Atomic writes leave no temporary files behind.
    let names: Vec<String> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert_eq!(names.len(), 2, "{names:?}");
}

#[test]
fn log_log_pareto_chart_with_labels() {
    let dir = scratch("report_pareto");
    // (run time [s], error [-]) of some configurations; the front is 0, 2, 3, 5.
    let runs = [(1.0, 0.3), (2.0, 0.35), (4.0, 0.05), (30.0, 0.004), (50.0, 0.01), (300.0, 0.001)];
    let names = ["a", "b", "c", "d", "e", "f"];
    let front = pareto_front(&runs);
    assert_eq!(front, vec![0, 2, 3, 5]);
    let chart = Chart {
        x_axis: Axis::Log,
        y_axis: Axis::Log,
        series: vec![
            Series::markers("all runs", runs).with_labels(names),
            Series::line_markers("Pareto front", front.iter().map(|&i| runs[i])),
        ],
        ..Chart::new("Speed against accuracy", "run time [s]", "relative error [-]")
    };
    let files = chart.write_png_svg(&dir.join("pareto")).unwrap();
    let (w, h, colours) = png_colours(&files.png);
    assert_eq!((w, h), (900, 600));
    assert!(colours.len() >= 2);
    let svg = std::fs::read_to_string(&files.svg).unwrap();
    for needle in ["all runs", "Pareto front", "run time [s]", "relative error [-]", "\nf\n"] {
        assert!(svg.contains(needle), "SVG lacks {needle:?}");
    }
}

#[test]
fn non_positive_value_on_a_log_axis_is_an_error_naming_series_and_point() {
    let dir = scratch("report_log_error");
    let chart = Chart {
        y_axis: Axis::Log,
        series: vec![Series::line("fine", [(0.0, 1.0), (1.0, 2.0)]), Series::line("history", [(0.0, 1e-3), (0.5, 0.0)])],
        ..Chart::new("Slip history", "t [s]", "slip [m]")
    };
    let e = chart.write_png_svg(&dir.join("history")).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, ReportError::NonPositiveOnLog { index: 1, axis: 'y', .. }), "{msg}");
    assert!(msg.contains("\"history\"") && msg.contains("point 1") && msg.contains("(0.5, 0)"), "{msg}");
    // Nothing written, not even one of the two files.
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
    // Converts into the crate error.
    let e: Error = e.into();
    assert!(matches!(e, Error::Report(_)));
}

#[test]
fn nan_is_an_error_naming_the_series() {
    let dir = scratch("report_nan");
    let chart = Chart { series: vec![Series::markers("ssr curve", [(1.0, 0.1), (1.2, f64::NAN)])], ..Chart::new("SSR", "SRF [-]", "u [m]") };
    let e = chart.write_png_svg(&dir.join("ssr")).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, ReportError::NonFinite { index: 1, .. }), "{msg}");
    assert!(msg.contains("\"ssr curve\"") && msg.contains("point 1"), "{msg}");
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
}

#[test]
fn flat_data_and_fixed_ranges_still_draw() {
    let dir = scratch("report_flat");
    // All values equal: the automatic range must still be a proper interval.
    let flat = Chart { series: vec![Series::line_markers("const", [(1.0, 2.0), (1.0, 2.0)])], ..Chart::new("flat", "x [-]", "y [-]") };
    let plan = flat.check().unwrap();
    assert!(plan.x_range.0 < 1.0 && plan.x_range.1 > 1.0 && plan.y_range.0 < 2.0 && plan.y_range.1 > 2.0, "{plan:?}");
    flat.write_png_svg(&dir.join("flat")).unwrap();
    // A zoom that leaves most of a line outside: clipped, drawn, no error.
    let zoom = Chart {
        x_range: Some((0.4, 0.6)),
        y_range: Some((0.0, 1.0)),
        series: vec![Series::line("ramp", [(0.0, 0.0), (1.0, 1.0)]), Series::markers("outside", [(5.0, 5.0)])],
        ..Chart::new("zoom", "x [-]", "y [-]")
    };
    let files = zoom.write_png_svg(&dir.join("zoom")).unwrap();
    let (_, _, colours) = png_colours(&files.png);
    let c = series_color(0);
    assert!(colours.contains(&[c.0, c.1, c.2]));
}

#[test]
fn markdown_table_for_a_report() {
    let dir = scratch("report_table");
    let mut t = Table::new(["PGA [g]", "slip [m]", "change"])
        .with_align(&[jointquake::report::Align::Right, jointquake::report::Align::Right, jointquake::report::Align::Right])
        .unwrap();
    for (a, s, r) in [(0.1, 0.0123456, 0.0), (0.2, 0.049876, 3.04)] {
        t.push_row([jointquake::report::fmt_sig(a, 2), jointquake::report::fmt_sig(s, 4), jointquake::report::fmt_percent(r, 1)]).unwrap();
    }
    let path = dir.join("slip.md");
    t.write_markdown(&path).unwrap();
    let md = std::fs::read_to_string(&path).unwrap();
    assert_eq!(md.lines().count(), 4, "{md}");
    assert!(md.contains(" 0.01235 |") && md.contains("| 304.0 % |"), "{md}");
}

#[test]
fn same_chart_gives_identical_files() {
    let dir = scratch("report_determinism");
    let a = slip_chart().write_png_svg(&dir.join("a")).unwrap();
    let b = slip_chart().write_png_svg(&dir.join("b")).unwrap();
    assert_eq!(std::fs::read(&a.png).unwrap(), std::fs::read(&b.png).unwrap());
    assert_eq!(std::fs::read(&a.svg).unwrap(), std::fs::read(&b.svg).unwrap());
}

/// A text element of an SVG written by plotters: position, font size [px], anchor, rotated, text.
#[derive(Debug, Clone)]
pub struct SvgText {
    pub x: f64,
    pub y: f64,
    pub size: f64,
    pub anchor: String,
    pub rotated: bool,
    pub text: String,
}

/// The `<text>` elements of an SVG (plotters writes one per label, its content on its own line).
pub fn svg_texts(svg: &str) -> Vec<SvgText> {
    let attr = |head: &str, name: &str| -> Option<String> {
        let k = head.find(&format!(" {name}=\""))? + name.len() + 3;
        Some(head[k..].split('"').next()?.to_string())
    };
    svg.split("<text ")
        .skip(1)
        .filter_map(|t| {
            let (head, rest) = t.split_once('>')?;
            let head = &format!(" {head}");
            let text = rest.split("</text>").next()?.trim().to_string();
            Some(SvgText {
                x: attr(head, "x")?.parse().ok()?,
                y: attr(head, "y")?.parse().ok()?,
                size: attr(head, "font-size")?.parse().ok()?,
                anchor: attr(head, "text-anchor").unwrap_or_default(),
                rotated: head.contains("transform="),
                text,
            })
        })
        .collect()
}

/// Boxes (x0, y0, x1, y1) [px] of the tick labels of a chart SVG: unrotated numbers, x-axis
/// labels centred under their tick (anchor middle, hanging below y), y-axis labels ending left of
/// theirs (anchor end, centred on y). Width: 0.636 em per character (DejaVu Sans's digit advance,
/// 1303 of 2048 units, its widest tick character), height 1 em.
pub fn tick_label_boxes(svg: &str) -> (Vec<[f64; 4]>, Vec<[f64; 4]>) {
    let (mut xs, mut ys) = (Vec::new(), Vec::new());
    for t in svg_texts(svg).into_iter().filter(|t| !t.rotated && t.text.parse::<f64>().is_ok()) {
        let w = 0.636 * t.size * t.text.chars().count() as f64;
        match t.anchor.as_str() {
            "middle" => xs.push([t.x - 0.5 * w, t.y, t.x + 0.5 * w, t.y + t.size]),
            "end" => ys.push([t.x - w, t.y - 0.5 * t.size, t.x, t.y + 0.5 * t.size]),
            _ => {}
        }
    }
    (xs, ys)
}

/// The first pair of overlapping boxes, if any.
pub fn overlapping(boxes: &[[f64; 4]]) -> Option<([f64; 4], [f64; 4])> {
    for (i, a) in boxes.iter().enumerate() {
        for b in &boxes[i + 1..] {
            if a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3] {
                return Some((*a, *b));
            }
        }
    }
    None
}

/// Asserts a chart SVG's tick labels: at least two on each axis, none overlapping, and the
/// axis descriptions (rotated y, and the x one under the plot) carrying a unit in brackets.
pub fn assert_readable_svg(svg: &str, what: &str) {
    let (xs, ys) = tick_label_boxes(svg);
    assert!(xs.len() >= 2 && ys.len() >= 2, "{what}: {} x and {} y tick labels", xs.len(), ys.len());
    for b in [&xs, &ys] {
        assert!(overlapping(b).is_none(), "{what}: tick labels overlap: {:?}", overlapping(b));
    }
    let texts = svg_texts(svg);
    let y_desc: Vec<&SvgText> = texts.iter().filter(|t| t.rotated).collect();
    assert!(!y_desc.is_empty() && y_desc.iter().all(|t| t.text.contains('[')), "{what}: y axis description without a unit: {y_desc:?}");
    // the x description: the lowest text (largest y) that is not a number
    let x_desc = texts.iter().filter(|t| !t.rotated && t.text.parse::<f64>().is_err()).max_by(|a, b| a.y.total_cmp(&b.y));
    assert!(x_desc.is_some_and(|t| t.text.contains('[')), "{what}: x axis description without a unit: {x_desc:?}");
    assert!(texts.iter().all(|t| t.size >= 12.0), "{what}: text below 12 px: {:?}", texts.iter().find(|t| t.size < 12.0));
}

#[test]
fn log_axes_of_a_narrow_speed_accuracy_chart_have_labelled_ticks_that_do_not_overlap() {
    // issue 32: the dam report's speed-against-accuracy chart, wall times 700–1000 s and errors
    // 1–40 %, read "700800901000" on x and had one label on y
    let runs = [(1000.0, 0.01), (905.0, 0.03), (810.0, 0.12), (700.0, 0.4)];
    let mut c = Chart::new("Speed against accuracy at 3×", "wall time [s]", "relative error against the reference [-]");
    c.x_axis = Axis::Log;
    c.y_axis = Axis::Log;
    for (i, &p) in runs.iter().enumerate() {
        c.series.push(Series::markers(format!("run {i}"), [p]));
    }
    c.series.push(Series::line("Pareto front", runs));
    let mut svg = String::new();
    c.render_svg_into(&mut svg).unwrap();
    assert_readable_svg(&svg, "speed_accuracy");
    let (xs, ys) = tick_label_boxes(&svg);
    assert!(xs.len() >= 3 && ys.len() >= 3, "{xs:?} {ys:?}");
    let labels: Vec<String> = svg_texts(&svg).into_iter().map(|t| t.text).collect();
    for v in ["700", "800", "900", "1000", "0.01", "0.1"] {
        assert!(labels.iter().any(|l| l == v), "no tick label {v}: {labels:?}");
    }
}

#[test]
fn a_legend_that_would_cover_data_in_every_corner_goes_outside_the_plot() {
    // data in all four corners and the middle: no inner corner is free
    let pts: Vec<(f64, f64)> = (0..=20).flat_map(|i| (0..=20).map(move |j| (i as f64, j as f64))).collect();
    let c = Chart { series: vec![Series::markers("grid", pts), Series::line("diagonal", [(0.0, 0.0), (20.0, 20.0)])], ..Chart::new("Full", "x [m]", "y [m]") };
    let plan = c.check().unwrap();
    assert_eq!(plan.legend, Some(jointquake::report::Legend::Outside));
    assert!(plan.outside_legend_px > 50);
    let mut svg = String::new();
    c.render_svg_into(&mut svg).unwrap();
    // the legend's entries are right of every data marker's x
    let texts = svg_texts(&svg);
    let legend_x = texts.iter().find(|t| t.text == "grid").unwrap().x;
    assert!(legend_x > 900.0 - 20.0 - plan.outside_legend_px as f64, "legend at x = {legend_x}");
}
