//! CSV histories of monitored points: one file per point, `histories/<monitor>.csv`, one row
//! per history row: [`MONITOR_HEADER`] (SI, relative to the base). Units are part of the column
//! names (`ux [m]`); the readers find a column by its name with or without the unit.
//! The first line is the header (ParaView's CSV reader and spreadsheets take it as such); where
//! each monitor snapped (node, requested point, distance) is in `histories/monitors.json`
//! (written when the run starts) and in `summary.json`.
//!
//! Crash safety: rows are kept in memory and written as whole lines at frame boundaries
//! ([`CsvLines`]), so a killed run or a full disk leaves at most one incomplete last line, which
//! [`HistoryTable::read`] ignores.

use crate::error::OutputError;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Header of a monitor history.
pub const MONITOR_HEADER: &str = "t [s],ux [m],uy [m],uz [m],vx [m/s],vy [m/s],vz [m/s],ax [m/s^2],ay [m/s^2],az [m/s^2]";

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

/// A CSV file written in whole lines: the header at once, then rows gathered in memory
/// ([`Self::buf`], each ending in `\n`) and written by [`Self::flush`] (and when dropped, so a
/// run stopped by an error keeps its rows).
pub struct CsvLines {
    path: PathBuf,
    file: std::fs::File,
    buf: String,
    /// Bytes of whole lines in the file (the header and the rows written).
    len: u64,
}

impl CsvLines {
    /// Create `path` with its header line.
    pub fn create(path: PathBuf, header: &str) -> Result<CsvLines, OutputError> {
        // a fifo would block the open, a device or symlink would be written through
        crate::files::check_regular_target(&path).map_err(|m| OutputError::write(&path, m))?;
        let mut file = std::fs::File::create(&path).map_err(|e| OutputError::write(&path, e))?;
        writeln!(file, "{header}").map_err(|e| OutputError::write(&path, e))?;
        Ok(CsvLines { path, file, buf: String::new(), len: header.len() as u64 + 1 })
    }

    /// The pending rows; append whole lines ending in `\n`.
    pub fn buf(&mut self) -> &mut String {
        &mut self.buf
    }

    /// Write the pending rows. If the write fails part-way (a full disk), the file is cut back
    /// to its last whole line, so it never ends mid-row (issue 34), and the rows are dropped.
    pub fn flush(&mut self) -> Result<(), OutputError> {
        if !self.buf.is_empty() {
            let written = self.file.write_all(self.buf.as_bytes());
            let n = self.buf.len() as u64;
            self.buf.clear();
            if let Err(e) = written {
                let _ = self.file.set_len(self.len);
                let _ = std::io::Seek::seek(&mut self.file, std::io::SeekFrom::Start(self.len));
                return Err(OutputError::write(&self.path, e));
            }
            self.len += n;
        }
        Ok(())
    }

    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for CsvLines {
    fn drop(&mut self) {
        let _ = self.flush();
    }
}

pub struct HistoryWriter {
    files: Vec<CsvLines>,
}

impl HistoryWriter {
    /// One history per monitor in `dir`, and `dir/monitors.json` (the monitors as snapped).
    pub fn create(dir: &Path, monitors: &[Monitor]) -> Result<HistoryWriter, OutputError> {
        std::fs::create_dir_all(dir).map_err(|e| OutputError::write(dir, e))?;
        let mut files = Vec::new();
        for m in monitors {
            files.push(CsvLines::create(dir.join(format!("{}.csv", crate::files::file_stem(&m.name))), MONITOR_HEADER)?);
        }
        if !monitors.is_empty() {
            let p = dir.join("monitors.json");
            std::fs::write(&p, serde_json::to_string_pretty(monitors).expect("monitors serialise")).map_err(|e| OutputError::write(&p, e))?;
        }
        Ok(HistoryWriter { files })
    }

    /// Append one row per monitor: values are [u; v; a] (9) per monitor.
    pub fn row(&mut self, t: f64, values: &[[f64; 9]]) {
        use std::fmt::Write as _;
        for (f, v) in self.files.iter_mut().zip(values) {
            let b = f.buf();
            let _ = write!(b, "{t:.9e}");
            for x in v {
                let _ = write!(b, ",{x:.9e}");
            }
            b.push('\n');
        }
    }

    /// Write the pending rows (whole lines).
    pub fn flush(&mut self) -> Result<(), OutputError> {
        for f in &mut self.files {
            f.flush()?;
        }
        Ok(())
    }

    pub fn paths(&self) -> Vec<PathBuf> {
        self.files.iter().map(|f| f.path().to_path_buf()).collect()
    }
}

/// Read `histories/monitors.json` (the monitors as snapped, written by [`HistoryWriter::create`]).
pub fn read_monitors(histories_dir: &Path) -> Result<Vec<Monitor>, OutputError> {
    let p = histories_dir.join("monitors.json");
    let text = std::fs::read_to_string(&p).map_err(|e| OutputError::read(&p, e))?;
    serde_json::from_str(&text).map_err(|e| OutputError::read(&p, format!("not a monitor list: {e}")))
}

/// A CSV history read back by column name: the monitor histories of [`HistoryWriter`] and
/// the joint histories of [`super::joints`] (one header line of column names, then rows of
/// numbers; `NaN` is a number; `#` lines, as older runs wrote, are skipped). A column is found
/// by its full name (`ux [m]`) or by its name without the unit (`ux`). An incomplete last line
/// (no line end: a run killed while writing) is ignored; any other row must have one value per
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
        // a last line without its line end was cut by a kill or a full disk: not a row
        let whole = match text.rfind('\n') {
            Some(i) => &text[..=i],
            None => "",
        };
        for (ln, line) in whole.lines().enumerate() {
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
        let bare = |c: &str| c.split(" [").next().unwrap_or(c).to_string();
        let i = self.columns.iter().position(|c| c == name || bare(c) == name).ok_or_else(|| {
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
