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

/// A CSV history read back by column name: the monitor histories of [`HistoryWriter`] and
/// the joint histories of [`super::joints`] (`#` comment lines, one header line of column
/// names, then rows of numbers; `NaN` is a number). Every row must have one value per
/// column: a truncated or non-numeric cell is an error naming the file, line and column.
#[derive(Clone, Debug)]
pub struct HistoryTable {
    pub path: PathBuf,
    /// Column names in file order.
    pub columns: Vec<String>,
    /// Values column by column (`data[c][row]`).
    data: Vec<Vec<f64>>,
}

impl HistoryTable {
    /// Read a history file written by this module or by the joint writer.
    pub fn read(path: &Path) -> Result<HistoryTable, OutputError> {
        let text = std::fs::read_to_string(path).map_err(|e| OutputError::read(path, e))?;
        let mut columns: Option<Vec<String>> = None;
        let mut data: Vec<Vec<f64>> = Vec::new();
        for (ln, line) in text.lines().enumerate() {
            if line.starts_with('#') || line.trim().is_empty() {
                continue;
            }
            let Some(cols) = &columns else {
                let c: Vec<String> = line.split(',').map(|s| s.trim().to_string()).collect();
                data = vec![Vec::new(); c.len()];
                columns = Some(c);
                continue;
            };
            let cells: Vec<&str> = line.split(',').collect();
            if cells.len() != cols.len() {
                return Err(OutputError::read(path, format!("line {}: {} values for {} columns (a truncated row?)", ln + 1, cells.len(), cols.len())));
            }
            for (c, cell) in cells.iter().enumerate() {
                let v = cell.trim().parse::<f64>().map_err(|e| OutputError::read(path, format!("line {}, column `{}`: `{cell}`: {e}", ln + 1, cols[c])))?;
                data[c].push(v);
            }
        }
        let columns = columns.ok_or_else(|| OutputError::read(path, "no header line (an empty history)"))?;
        Ok(HistoryTable { path: path.to_path_buf(), columns, data })
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.data.first().map_or(0, |c| c.len())
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The values of column `name`; an error naming the file and the columns it has if absent.
    pub fn column(&self, name: &str) -> Result<&[f64], OutputError> {
        let i = self.columns.iter().position(|c| c == name).ok_or_else(|| {
            OutputError::read(&self.path, format!("no column `{name}` (columns: {})", self.columns.join(", ")))
        })?;
        Ok(&self.data[i])
    }

    /// Three columns as vectors, e.g. `["ux", "uy", "uz"]`.
    pub fn vectors(&self, names: [&str; 3]) -> Result<Vec<[f64; 3]>, OutputError> {
        let (a, b, c) = (self.column(names[0])?, self.column(names[1])?, self.column(names[2])?);
        Ok((0..self.len()).map(|i| [a[i], b[i], c[i]]).collect())
    }
}
