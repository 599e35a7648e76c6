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
