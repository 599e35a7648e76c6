//! Report: charts (PNG + SVG) and Markdown tables for study reports.
//!
//! Owns only presentation. Inputs: numbers the caller already has (series of `(x, y)`
//! points with names, polygons with values for maps, table cells as strings); it knows nothing of scenes, models or
//! studies. Outputs: `<stem>.png` and `<stem>.svg` per [`Chart`] and [`Map`], Markdown text or files
//! per [`Table`].
//!
//! Invariants:
//! - a chart is validated whole before any file is touched; bad data (non-finite values,
//!   values <= 0 on a log axis, label/point count mismatch) is a [`ReportError`] naming the
//!   chart, the series and the point, never a panic or a silently dropped point;
//! - every file is written whole (temporary file in the same directory, then rename);
//! - output is deterministic: colours and markers by series index ([`PALETTE`],
//!   [`MARKERS`]), ranges and the legend corner from the data, and one embedded font
//!   (DejaVu Sans, `assets/fonts/`), so no system font library is used.
//!
//! Developer notes: `docs/report.md`.

pub mod chart;
pub mod file;
pub mod font;
pub mod map;
pub mod pareto;
pub mod scale;
pub mod table;

pub use crate::error::ReportError;
pub use chart::{
    Axis, Chart, ChartFiles, ChartPlan, Legend, Marker, Series, SeriesStyle, DEFAULT_HEIGHT, DEFAULT_WIDTH, MARKERS, MIN_SIZE,
    PALETTE, series_color, series_marker,
};
pub use map::{Map, MapPanel};
pub use pareto::pareto_front;
pub use table::{Align, Table, fmt_percent, fmt_sig};
