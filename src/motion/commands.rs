//! The `jointquake record info|correct|synth|match` stages as library calls: they take arrays
//! (the CLI reads the record with `dynamics::record::Record::read`), write files and
//! charts, and return the one-screen text the CLI prints.

use super::baseline::{Baseline, correct, drift};
use super::chart::{write_history_charts, write_spectrum_chart};
use super::io::write_two_column;
use super::measures::intensity_measures;
use super::spectrum::{default_periods, response_spectrum};
use super::synth::{MatchOptions, SynthRequest, UPPER_LIMIT, match_record, synthesize_set};
use super::target::TargetSpectrum;
use super::MotionError;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// `record info`: measures, the 5 % spectrum on 0.02–10 s (CSV) and charts in `out`.
///
/// `name` (usually the record file's stem) becomes the files' stem through the one rule
/// `files::file_stem`; `g` [m/s²] must be in `scene::G_RANGE`-like bounds (0.1–100; `--g
/// -9.81` was accepted, issue 34).
pub fn info(name: &str, t0: f64, dt: f64, accel_si: &[f64], g: f64, out: &Path) -> Result<String, MotionError> {
    check_g(g)?;
    let stem = crate::files::file_stem(name);
    let name = stem.as_str();
    let periods = default_periods();
    let psa = response_spectrum(accel_si, dt, &periods, 0.05);
    let m = intensity_measures(accel_si, dt, t0, g, &periods, &psa);
    std::fs::create_dir_all(out).map_err(|source| MotionError::Write { path: out.to_path_buf(), source })?;
    let csv = out.join(format!("{name}_spectrum.csv"));
    let mut s = String::from("period_s,psa_g\n");
    for (t, p) in periods.iter().zip(&psa) {
        let _ = writeln!(s, "{t:.6},{:.6e}", p / g);
    }
    std::fs::write(&csv, s).map_err(|source| MotionError::Write { path: csv.clone(), source })?;
    let json = out.join(format!("{name}_measures.json"));
    std::fs::write(&json, serde_json::to_string_pretty(&m).unwrap_or_default()).map_err(|source| MotionError::Write { path: json.clone(), source })?;
    let ag: Vec<f64> = accel_si.iter().map(|a| a / g).collect();
    let mut charts = write_history_charts(&out.join(name), name, t0, dt, &ag, g)?;
    let psa_g: Vec<f64> = psa.iter().map(|p| p / g).collect();
    charts.push(write_spectrum_chart(&out.join(format!("{name}_spectrum")), &format!("{name}: 5 % response spectrum"), &periods, &[(name.to_string(), psa_g.clone())], None)?);
    let mut t = String::new();
    let _ = writeln!(t, "record {name}: {} samples, dt {dt} s, {:.2} s", accel_si.len(), dt * (accel_si.len().saturating_sub(1)) as f64);
    let _ = writeln!(t, "  PGA {:.4} g at {:.3} s   PGV {:.4} m/s   PGD {:.4} m (from rest, uncorrected)", m.pga_g, m.t_pga, m.pgv, m.pgd);
    let _ = writeln!(t, "  Arias intensity {:.4} m/s   D5-95 {:.2} s ({:.2}–{:.2} s)   predominant period {:.3} s", m.arias, m.d5_95, m.t5, m.t95, m.predominant_period);
    let _ = writeln!(t, "  drift: end velocity {:.4e} m/s, end displacement {:.4e} m", m.v_end, m.d_end);
    let _ = writeln!(t, "  5 % PSA [g] (all {} periods in {}):", periods.len(), csv.display());
    for i in (0..periods.len()).step_by(11) {
        let _ = writeln!(t, "    T {:7.3} s  {:.4}", periods[i], psa_g[i]);
    }
    let _ = writeln!(t, "  measures {}", json.display());
    for c in charts {
        let _ = writeln!(t, "  chart {}.png (and .svg)", c.display());
    }
    Ok(t)
}

/// `record correct`: the corrected record to `out_file`, with the drift before and after.
pub fn correct_file(source: &Path, t0: f64, dt: f64, accel_si: &[f64], g: f64, method: &Baseline, out_file: &Path) -> Result<String, MotionError> {
    check_g(g)?;
    let before = drift(accel_si, dt);
    // the high-pass keeps its padding (the acausal filter's response before t0 is part of it)
    let (t0, c) = match *method {
        Baseline::HighPass { corner, order } => {
            method.check(dt)?;
            let (pad, full) = super::baseline::highpass_padded(accel_si, dt, corner, order);
            (t0 - pad as f64 * dt, full)
        }
        _ => (t0, correct(accel_si, dt, method)?),
    };
    let after = drift(&c, dt);
    let ag: Vec<f64> = c.iter().map(|a| a / g).collect();
    let header = vec![
        format!("jointquake record correct: {} corrected by {}", source.display(), method.describe()),
        format!("command: jointquake record correct {} {} --out {}", source.display(), method_args(method), out_file.display()),
        format!("before: {}", before.describe()),
        format!("after:  {}", after.describe()),
        format!("npts={}  dt={dt} s", c.len()),
        "columns: time [s]   acceleration [g]".into(),
    ];
    write_two_column(out_file, &header, t0, dt, &ag)?;
    Ok(format!("{}\n  before: {}\n  after:  {}\n  written {}\n", header[0], before.describe(), after.describe(), out_file.display()))
}

/// Standard gravity of the record commands (`--g`) accepted [m/s²]: 0.1 to 100 (as a scene's
/// `g`); a negative or non-finite one turned every acceleration around or into NaN.
pub const G_RANGE: (f64, f64) = (0.1, 100.0);

/// `g` within [`G_RANGE`], else an error naming `--g`.
pub fn check_g(g: f64) -> Result<(), MotionError> {
    if !(g >= G_RANGE.0 && g <= G_RANGE.1) {
        return Err(MotionError::invalid("--g", format!("{g} m/s² must be in [{}, {}] (standard gravity 9.81; the sign is not a direction)", G_RANGE.0, G_RANGE.1)));
    }
    Ok(())
}

/// The CLI arguments that select `method`.
pub fn method_args(method: &Baseline) -> String {
    match method {
        Baseline::Mean => "--method mean".into(),
        Baseline::Polynomial { degree } => format!("--method polynomial --degree {degree}"),
        Baseline::HighPass { corner, order } => format!("--method highpass --corner {corner} --order {order}"),
    }
}

/// `record synth`: `<out>/<name>_s<seed>_<component>.txt`, a spectrum chart per component.
/// `name` must be a file stem (`files::is_file_stem`): an absolute or `..` name would write
/// outside `out` (issue 33), so it is refused, naming `--name`.
pub fn synth_files(req: &SynthRequest, out: &Path, name: &str) -> Result<(String, Vec<PathBuf>), MotionError> {
    if !crate::files::is_file_stem(name) {
        return Err(MotionError::invalid(
            "--name",
            format!("\"{name}\" is not a file name: give 1–{} letters, digits, `_`, `-`, `.` or `+`, not starting with `.` (no `/`: the files go to --out)", crate::files::MAX_STEM_LEN),
        ));
    }
    let set = synthesize_set(req)?;
    let periods = default_periods();
    let mut files = Vec::new();
    let mut t = String::new();
    let _ = writeln!(t, "synthetic set {name}, seed {}: {} components, {} s at dt {} s", req.seed, set.components.len(), req.duration, req.dt);
    for c in &set.components {
        let f = out.join(format!("{name}_s{}_{}.txt", req.seed, c.name));
        write_two_column(&f, &c.header, 0.0, c.dt, &c.accel_g)?;
        let psa = response_spectrum(&c.accel_g, c.dt, &periods, 0.05);
        let tgt: Vec<f64> = periods.iter().map(|&p| c.target.sa(p)).collect();
        let stem = out.join(format!("{name}_s{}_{}_spectrum", req.seed, c.name));
        write_spectrum_chart(&stem, &format!("{name} seed {} {}: target and achieved", req.seed, c.name), &periods, &[(format!("{} (achieved)", c.name), psa)], Some((&c.target.label, &tgt, [req.tolerance, UPPER_LIMIT])))?;
        let _ = writeln!(t, "  {} PGA {:.6} g: {}", c.name, c.pga_g, c.check.describe());
        let _ = writeln!(t, "     {}", c.drift.describe());
        let _ = writeln!(t, "     {} ; chart {}.png (and .svg)", f.display(), stem.display());
        files.push(f);
    }
    for (i, j, r) in &set.correlations {
        let _ = writeln!(t, "  correlation {}–{}: {r:+.3}", set.components[*i].name, set.components[*j].name);
    }
    Ok((t, files))
}

/// `record match`: the matched record to `out_file` and its spectrum chart beside it.
pub fn match_file(source: &Path, dt: f64, accel_g: &[f64], target: &TargetSpectrum, pga: f64, opts: &MatchOptions, out_file: &Path) -> Result<String, MotionError> {
    let c = match_record(accel_g, dt, target, pga, opts, &source.display().to_string())?;
    write_two_column(out_file, &c.header, 0.0, dt, &c.accel_g)?;
    let periods = default_periods();
    let before = response_spectrum(accel_g, dt, &periods, 0.05);
    let scale = pga / accel_g.iter().fold(0.0f64, |m, a| m.max(a.abs())).max(1e-300);
    let before: Vec<f64> = before.iter().map(|s| s * scale).collect();
    let after = response_spectrum(&c.accel_g, dt, &periods, 0.05);
    let tgt: Vec<f64> = periods.iter().map(|&p| target.sa(p)).collect();
    let stem = out_file.with_extension("").with_file_name(format!("{}_spectrum", out_file.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default()));
    write_spectrum_chart(&stem, "matched record: target, original (PGA-scaled) and matched", &periods, &[("original, PGA-scaled".into(), before), ("matched".into(), after)], Some((&target.label, &tgt, [opts.tolerance, UPPER_LIMIT])))?;
    Ok(format!("{}\n  {}\n  {}\n  written {} ; chart {}.png (and .svg)\n", c.header[0], c.check.describe(), c.drift.describe(), out_file.display(), stem.display()))
}
