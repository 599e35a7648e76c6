//! Two-column record files (t [s], a [g]) with a `#` header; the reader is
//! `dynamics::record::Record::read`, which reads what this writes.
//!
//! Values are written with ten significant digits so that the file's PGA is the requested one
//! to 1e-10 and a seed always gives the same bytes.

use super::MotionError;
use std::fmt::Write as _;
use std::path::Path;

/// The file text: `# ` + each header line, then `t a` rows (t from `t0` [s] at `dt`).
pub fn two_column_text(header: &[String], t0: f64, dt: f64, accel_g: &[f64]) -> String {
    let mut s = String::with_capacity(32 * (accel_g.len() + header.len()));
    for h in header {
        let _ = writeln!(s, "# {h}");
    }
    for (i, a) in accel_g.iter().enumerate() {
        let t = t0 + dt * i as f64;
        // -0 prints as 0, so a sign flip of a zero never changes the bytes
        let a = if *a == 0.0 { 0.0 } else { *a };
        let _ = writeln!(s, "{t:.4} {a:.9e}");
    }
    s
}

/// Write [`two_column_text`] to `path` (whole, through a temporary file in the same directory).
pub fn write_two_column(path: &Path, header: &[String], t0: f64, dt: f64, accel_g: &[f64]) -> Result<(), MotionError> {
    let text = two_column_text(header, t0, dt, accel_g);
    if let Some(d) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(d).map_err(|source| MotionError::Write { path: d.to_path_buf(), source })?;
    }
    // whole, and never over a device, fifo or symlink (`--out /dev/null`, issue 34)
    crate::files::write_whole(path, text.as_bytes()).map_err(|(path, message)| MotionError::Write { path, source: std::io::Error::other(message) })
}
