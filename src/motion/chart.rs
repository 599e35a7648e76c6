//! Charts of the motion stage through [`crate::report`]: a record's acceleration, velocity and
//! displacement histories, and response spectra against their targets (log period axis).

use super::MotionError;
use super::measures::integrate;
use crate::report::{Axis, Chart, Series};
use std::path::{Path, PathBuf};

/// `<stem>_acc`, `<stem>_vel`, `<stem>_disp` (.png + .svg) of `accel_g` [g] at `dt` [s];
/// velocity and displacement from rest, in m/s and m with `g` [m/s²]. Returns the stems written.
pub fn write_history_charts(stem: &Path, title: &str, t0: f64, dt: f64, accel_g: &[f64], g: f64) -> Result<Vec<PathBuf>, MotionError> {
    let si: Vec<f64> = accel_g.iter().map(|a| a * g).collect();
    let (v, d) = integrate(&si, dt);
    let t = |i: usize| t0 + dt * i as f64;
    let mut out = Vec::new();
    for (suffix, what, unit, y) in [("acc", "acceleration", "[g]", accel_g.to_vec()), ("vel", "velocity", "[m/s]", v), ("disp", "displacement", "[m]", d)] {
        let chart = Chart { legend: crate::report::Legend::Hidden, series: vec![Series::line(what, y.iter().enumerate().map(|(i, &a)| (t(i), a)))], ..Chart::new(format!("{title}: {what}"), "time [s]", format!("{what} {unit}")) };
        let s = with_suffix(stem, suffix);
        chart.write_png_svg(&s)?;
        out.push(s);
    }
    Ok(out)
}

/// `<stem>` (.png + .svg): spectra (name, PSA [g]) on `periods` [s], with an optional target
/// and its acceptance lines target × (1 − lower) and target × (1 + upper).
pub fn write_spectrum_chart(stem: &Path, title: &str, periods: &[f64], spectra: &[(String, Vec<f64>)], target: Option<(&str, &[f64], [f64; 2])>) -> Result<PathBuf, MotionError> {
    let mut series = Vec::new();
    if let Some((label, sa, [lower, upper])) = target {
        series.push(Series::line(format!("target: {label}"), periods.iter().copied().zip(sa.iter().copied())));
        if lower > 0.0 || upper > 0.0 {
            series.push(Series::line(format!("target × {:.2} and × {:.2} (acceptance)", 1.0 - lower, 1.0 + upper), periods.iter().copied().zip(sa.iter().map(|s| s * (1.0 + upper)))));
            series.push(Series::line("", periods.iter().copied().zip(sa.iter().map(|s| s * (1.0 - lower)))));
        }
    }
    for (name, sa) in spectra {
        series.push(Series::line(name.clone(), periods.iter().copied().zip(sa.iter().copied())));
    }
    let chart = Chart { x_axis: Axis::Log, series, ..Chart::new(title, "period T [s]", "5 % PSA [g]") };
    chart.write_png_svg(stem)?;
    Ok(stem.to_path_buf())
}

fn with_suffix(stem: &Path, suffix: &str) -> PathBuf {
    let name = stem.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    stem.with_file_name(format!("{name}_{suffix}"))
}
