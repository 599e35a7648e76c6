//! Acceleration records: reading, checking, scaling. The one place where g becomes m/s².
//!
//! Formats: two-column text (t [s], a [g]; `#` starts a comment; blank lines ignored) and
//! PEER `.AT2` (4 header lines, `NPTS=…, DT=…` on the 4th as in NGA files, or `N DT NPTS, DT` as in
//! the older PEER database; then values in g, several per line).
//! Time steps must be uniform (relative tolerance 1e-6 of dt), times increasing, values finite:
//! anything else is an error naming the line.

use crate::error::RecordError;
use std::path::{Path, PathBuf};

/// A uniformly sampled acceleration record, in m/s².
#[derive(Clone, Debug)]
pub struct Record {
    pub path: PathBuf,
    /// Time of the first sample [s].
    pub t0: f64,
    /// Sample interval [s].
    pub dt: f64,
    /// Accelerations [m/s²] (converted from g on reading).
    pub accel: Vec<f64>,
}

/// Relative tolerance on uneven time steps.
const UNEVEN_TOL: f64 = 1e-6;

/// Smallest sample interval accepted [s]. Default 1e-7 s (10 MHz): accelerographs sample at
/// 50–1000 Hz, so a smaller step means times not in seconds (or a corrupt file), and it would
/// make a run take an unbounded number of steps.
pub const MIN_RECORD_DT: f64 = 1e-7;

impl Record {
    /// Read a record in g and convert to m/s² with `g` [m/s²].
    pub fn read(path: &Path, g: f64) -> Result<Record, RecordError> {
        let text = crate::files::read_text_bounded(path, crate::files::MAX_RECORD_INPUT).map_err(|source| RecordError::Io { path: path.to_path_buf(), source })?;
        // A UTF-8 byte-order mark (spreadsheets on Windows write one) is not part of the data.
        let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
        let is_at2 = path.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("at2"));
        let mut r = if is_at2 { parse_at2(text, path)? } else { parse_two_column(text, path)? };
        if !(r.dt >= MIN_RECORD_DT && r.dt.is_finite()) {
            return Err(RecordError::Invalid {
                path: path.to_path_buf(),
                message: format!("sample interval {:e} s is below {MIN_RECORD_DT:e} s: times must be in seconds (accelerographs sample at 50–1000 Hz)", r.dt),
            });
        }
        for a in &mut r.accel {
            *a *= g;
        }
        Ok(r)
    }

    /// Largest |a| [m/s²].
    pub fn peak(&self) -> f64 {
        self.accel.iter().fold(0.0f64, |m, a| m.max(a.abs()))
    }

    /// End time of the record [s].
    pub fn t_end(&self) -> f64 {
        self.t0 + self.dt * (self.accel.len().saturating_sub(1)) as f64
    }

    /// Acceleration [m/s²] at time t, linearly interpolated; 0 outside the record.
    pub fn at(&self, t: f64) -> f64 {
        let s = (t - self.t0) / self.dt;
        // Also outside: NaN, and any s too large for an index (the cast below saturates).
        if !(s >= 0.0 && s < self.accel.len() as f64) {
            return 0.0;
        }
        let i = s.floor() as usize;
        if i + 1 >= self.accel.len() {
            return if i + 1 == self.accel.len() && (s - i as f64) < 1e-9 { self.accel[i] } else { 0.0 };
        }
        let f = s - i as f64;
        self.accel[i] * (1.0 - f) + self.accel[i + 1] * f
    }
}

fn line_err(path: &Path, line: usize, message: impl Into<String>) -> RecordError {
    RecordError::Line { path: path.to_path_buf(), line, message: message.into() }
}

fn parse_two_column(text: &str, path: &Path) -> Result<Record, RecordError> {
    let mut t = Vec::new();
    let mut a = Vec::new();
    let mut lines = Vec::new();
    for (k, raw) in text.lines().enumerate() {
        let l = raw.split('#').next().unwrap().trim();
        if l.is_empty() {
            continue;
        }
        let mut it = l.split(|c: char| c.is_whitespace() || c == ',').filter(|s| !s.is_empty());
        let (Some(ts), Some(as_)) = (it.next(), it.next()) else {
            return Err(line_err(path, k + 1, format!("expected two columns (t [s], a [g]), found `{l}`")));
        };
        if let Some(extra) = it.next() {
            return Err(line_err(
                path,
                k + 1,
                format!("expected two columns (t [s], a [g]), found a third (`{extra}`) in `{l}`. A record file holds one component: split a multi-component file into one file per component and give each its own `loads.base` entry with its `direction`."),
            ));
        }
        let tv: f64 = ts.parse().map_err(|_| line_err(path, k + 1, format!("time `{ts}` is not a number")))?;
        let av: f64 = as_.parse().map_err(|_| line_err(path, k + 1, format!("acceleration `{as_}` is not a number")))?;
        if !tv.is_finite() || !av.is_finite() {
            return Err(line_err(
                path,
                k + 1,
                format!("non-finite value in `{l}`. Replace it with a number (fill the gap or cut the record before it)."),
            ));
        }
        t.push(tv);
        a.push(av);
        lines.push(k + 1);
    }
    if t.len() < 2 {
        return Err(RecordError::Invalid { path: path.to_path_buf(), message: "fewer than two samples".into() });
    }
    let dt = t[1] - t[0];
    for i in 1..t.len() {
        let d = t[i] - t[i - 1];
        if d <= 0.0 {
            return Err(line_err(path, lines[i], format!("time {} does not increase (previous {})", t[i], t[i - 1])));
        }
        if (d - dt).abs() > UNEVEN_TOL * dt.max(1e-300) * (1.0 + i as f64).sqrt() && (d - dt).abs() > 1e-9 {
            return Err(line_err(
                path,
                lines[i],
                format!("uneven time step {d} s (first step {dt} s). Resample the record to a uniform step."),
            ));
        }
    }
    // Use the mean step over the record so that round-off in the time column does not accumulate.
    let dt = (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64;
    Ok(Record { path: path.to_path_buf(), t0: t[0], dt, accel: a })
}

fn parse_at2(text: &str, path: &Path) -> Result<Record, RecordError> {
    let lines: Vec<&str> = text.lines().collect();
    if lines.len() < 4 {
        return Err(RecordError::Invalid {
            path: path.to_path_buf(),
            message: format!("it has {} lines: an AT2 file has 4 header lines (NPTS and DT on the 4th), then the values", lines.len()),
        });
    }
    let h = lines[3].to_ascii_uppercase();
    let field = |key: &str| -> Option<f64> {
        let i = h.find(key)? + key.len();
        let rest = h[i..].trim_start_matches(|c: char| c == '=' || c.is_whitespace());
        let end = rest.find(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == '+' || c == 'E')).unwrap_or(rest.len());
        rest[..end].parse().ok()
    };
    // NGA format: `NPTS=  5000, DT=   .0050 SEC`; the older PEER database format puts the two
    // numbers first: `  3930    0.01000    NPTS, DT`
    let leading: Vec<f64> = h.split(|c: char| c.is_whitespace() || c == ',').filter(|w| !w.is_empty()).map_while(|w| w.parse().ok()).collect();
    let (npts, dt) = if !h.contains("NPTS=") && h.contains("NPTS") && leading.len() >= 2 {
        (leading[0], leading[1])
    } else {
        let npts = field("NPTS").ok_or_else(|| line_err(path, 4, "header line 4 has no NPTS= (nor `NPTS DT` after the two numbers)"))?;
        (npts, field("DT").ok_or_else(|| line_err(path, 4, "header line 4 has no DT="))?)
    };
    if !(npts >= 1.0 && npts.fract() == 0.0) {
        return Err(line_err(path, 4, format!("NPTS = {npts} must be a positive whole number")));
    }
    // Every value takes at least two bytes (a digit and a separator): a count beyond that cannot
    // be right, and must not size an allocation.
    if npts > (text.len() / 2 + 1) as f64 {
        return Err(line_err(path, 4, format!("NPTS = {npts} is more values than a file of {} bytes can hold", text.len())));
    }
    let npts = npts as usize;
    if !(dt > 0.0 && dt.is_finite()) {
        return Err(line_err(path, 4, format!("DT = {dt} must be positive")));
    }
    let mut a = Vec::with_capacity(npts);
    for (k, l) in lines.iter().enumerate().skip(4) {
        for s in l.split_whitespace() {
            let v: f64 = s.parse().map_err(|_| line_err(path, k + 1, format!("`{s}` is not a number")))?;
            if !v.is_finite() {
                return Err(line_err(
                    path,
                    k + 1,
                    format!("non-finite value `{s}`. Replace it with a number (fill the gap or cut the record before it)."),
                ));
            }
            a.push(v);
        }
    }
    if a.len() != npts {
        return Err(RecordError::Invalid { path: path.to_path_buf(), message: format!("NPTS = {npts} but {} values", a.len()) });
    }
    Ok(Record { path: path.to_path_buf(), t0: 0.0, dt, accel: a })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(name: &str, s: &str) -> PathBuf {
        let d = std::env::temp_dir().join("jq-record-tests");
        std::fs::create_dir_all(&d).unwrap();
        let p = d.join(name);
        std::fs::write(&p, s).unwrap();
        p
    }

    #[test]
    fn two_column_reads_and_converts_g() {
        let p = write("ok.txt", "# header\n0.0 0.0\n0.01 0.5\n0.02 -1.0\n");
        let r = Record::read(&p, 9.81).unwrap();
        assert_eq!(r.accel.len(), 3);
        assert!((r.dt - 0.01).abs() < 1e-15);
        assert!((r.peak() - 9.81).abs() < 1e-12);
        assert!((r.at(0.005) - 0.25 * 9.81).abs() < 1e-12);
        assert_eq!(r.at(1.0), 0.0);
    }

    #[test]
    fn uneven_step_names_the_line() {
        let p = write("uneven.txt", "0.0 0\n0.01 0\n0.025 0\n");
        let e = Record::read(&p, 9.81).unwrap_err().to_string();
        assert!(e.contains("line 3") && e.contains("uneven"), "{e}");
    }

    #[test]
    fn non_monotonic_and_non_finite_are_errors() {
        let p = write("back.txt", "0.0 0\n0.01 0\n0.0 0\n");
        assert!(Record::read(&p, 9.81).unwrap_err().to_string().contains("line 3"));
        let p = write("nan.txt", "0.0 0\n0.01 NaN\n");
        let e = Record::read(&p, 9.81).unwrap_err().to_string();
        assert!(e.contains("line 2") && e.contains("non-finite"), "{e}");
    }

    #[test]
    fn at2_reads() {
        let p = write("x.AT2", "PEER\nx\nACCELERATION TIME SERIES IN UNITS OF G\nNPTS=   5, DT=   .0100 SEC\n 0.1 0.2 0.3\n 0.4 0.5\n");
        let r = Record::read(&p, 10.0).unwrap();
        assert_eq!(r.accel.len(), 5);
        assert!((r.dt - 0.01).abs() < 1e-15);
        assert!((r.accel[4] - 5.0).abs() < 1e-12);
    }

    #[test]
    fn at2_old_peer_header_reads() {
        // the pre-NGA PEER database layout: `NPTS DT` after the two numbers on line 4
        let p = write("old.at2", "PEER STRONG MOTION DATABASE RECORD\nx\nACCELERATION TIME HISTORY IN UNITS OF G\n    4    0.00500    NPTS, DT\n .1 -.2\n .3E+00 -4.0E-01\n");
        let r = Record::read(&p, 1.0).unwrap();
        assert_eq!(r.accel, vec![0.1, -0.2, 0.3, -0.4]);
        assert!((r.dt - 0.005).abs() < 1e-15);
    }

    #[test]
    fn committed_el_centro_reads() {
        // Header: npts=1560, dt=0.02 s, PGA=0.31882 g.
        let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("pipelines/records/elcentro1940_NS_chopra.txt");
        let r = Record::read(&p, 9.81).unwrap();
        assert_eq!(r.accel.len(), 1560);
        assert!((r.dt - 0.02).abs() < 1e-12);
        assert!((r.peak() / 9.81 - 0.31882).abs() < 1e-6);
    }
}
