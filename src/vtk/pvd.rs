//! ParaView `.pvd` collections, rewritten whole (temp file + rename) after every frame, so a run
//! killed at any time leaves a valid series of the frames written so far.

use crate::error::OutputError;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// A time series of VTU files.
pub struct PvdSeries {
    path: PathBuf,
    entries: Vec<(f64, String)>,
}

impl PvdSeries {
    /// A series written to `path`; dataset file names are stored relative to its directory.
    pub fn new(path: PathBuf) -> PvdSeries {
        PvdSeries { path, entries: Vec::new() }
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    pub fn len(&self) -> usize {
        self.entries.len()
    }

    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Add a dataset at time `t` [s] and rewrite the `.pvd`.
    pub fn push(&mut self, t: f64, file: &Path) -> Result<(), OutputError> {
        let dir = self.path.parent().unwrap_or(Path::new("."));
        let rel = file.strip_prefix(dir).unwrap_or(file).to_string_lossy().replace('\\', "/");
        self.entries.push((t, rel));
        let mut s = String::from("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n");
        for (t, f) in &self.entries {
            let _ = writeln!(s, "    <DataSet timestep=\"{t:.9e}\" group=\"\" part=\"0\" file=\"{f}\"/>");
        }
        s.push_str("  </Collection>\n</VTKFile>\n");
        crate::files::write_whole(&self.path, s.as_bytes()).map_err(|(p, m)| OutputError::write(p, m))
    }
}
