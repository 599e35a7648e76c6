//! CSV histories of monitored points: one file per point, one row per history step:
//! `t, ux, uy, uz, vx, vy, vz, ax, ay, az` (SI, relative to the base). Rows are flushed at
//! every frame, so a crash leaves the rows written up to the last frame.

use crate::error::OutputError;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// A monitored point snapped to a node.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Monitor {
    pub name: String,
    pub requested: [f64; 3],
    pub node: usize,
    pub node_tag: u64,
    pub position: [f64; 3],
    /// Distance from the requested point to the node [m].
    pub snap_distance: f64,
}

pub struct HistoryWriter {
    files: Vec<(PathBuf, BufWriter<std::fs::File>)>,
}

impl HistoryWriter {
    pub fn create(dir: &Path, monitors: &[Monitor]) -> Result<HistoryWriter, OutputError> {
        std::fs::create_dir_all(dir).map_err(|e| OutputError::write(dir, e))?;
        let mut files = Vec::new();
        for m in monitors {
            let p = dir.join(format!("{}.csv", m.name));
            let f = std::fs::File::create(&p).map_err(|e| OutputError::write(&p, e))?;
            let mut w = BufWriter::new(f);
            writeln!(w, "# monitor {} at node {} ({:.6}, {:.6}, {:.6}), snapped {:.3e} m from ({}, {}, {})",
                m.name, m.node_tag, m.position[0], m.position[1], m.position[2], m.snap_distance,
                m.requested[0], m.requested[1], m.requested[2]).map_err(|e| OutputError::write(&p, e))?;
            writeln!(w, "t,ux,uy,uz,vx,vy,vz,ax,ay,az").map_err(|e| OutputError::write(&p, e))?;
            files.push((p, w));
        }
        Ok(HistoryWriter { files })
    }

    /// Append one row per monitor: values are [u; v; a] (9) per monitor.
    pub fn row(&mut self, t: f64, values: &[[f64; 9]]) -> Result<(), OutputError> {
        for ((p, w), v) in self.files.iter_mut().zip(values) {
            write!(w, "{t:.9e}").map_err(|e| OutputError::write(p.as_path(), e))?;
            for x in v {
                write!(w, ",{x:.9e}").map_err(|e| OutputError::write(p.as_path(), e))?;
            }
            writeln!(w).map_err(|e| OutputError::write(p.as_path(), e))?;
        }
        Ok(())
    }

    pub fn flush(&mut self) -> Result<(), OutputError> {
        for (p, w) in &mut self.files {
            w.flush().map_err(|e| OutputError::write(p.as_path(), e))?;
        }
        Ok(())
    }

    pub fn paths(&self) -> Vec<PathBuf> {
        self.files.iter().map(|(p, _)| p.clone()).collect()
    }
}
