//! Whole-file writes: every report file appears complete or not at all.
//!
//! Content goes to a temporary file in the destination directory (same file system, so the
//! rename is atomic), which is then renamed over the destination. A crash or an error
//! mid-write leaves at most a hidden `.<name>.tmp-*` file, never a truncated chart or table.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::ReportError;

/// Distinguishes temporary names of concurrent writers in one process (the pid separates
/// processes), so two threads writing the same file never share a temporary file.
static TEMP_SEQ: AtomicU64 = AtomicU64::new(0);

/// A fresh temporary path next to `path`: `.<name>.tmp-<pid>-<n>.<ext>`. The extension is
/// kept because some writers (plotters' bitmap backend) choose the format from it.
pub fn temp_path_for(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let n = TEMP_SEQ.fetch_add(1, Ordering::Relaxed);
    let mut tmp = format!(".{name}.tmp-{}-{n}", std::process::id());
    if let Some(ext) = path.extension() {
        tmp.push('.');
        tmp.push_str(&ext.to_string_lossy());
    }
    path.with_file_name(tmp)
}

/// Creates the parent directory of `path` if it is missing (report directories are made on
/// demand, like the output writers' directories).
pub fn ensure_parent(path: &Path) -> Result<(), ReportError> {
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => {
            std::fs::create_dir_all(dir).map_err(|source| ReportError::Io { path: dir.to_path_buf(), source })
        }
        _ => Ok(()),
    }
}

/// Lets `write` produce the file at a temporary path, then renames it to `path`. On any
/// error the temporary file is removed (best effort) and `path` is left untouched.
pub fn write_via_temp<F>(path: &Path, write: F) -> Result<(), ReportError>
where
    F: FnOnce(&Path) -> Result<(), ReportError>,
{
    ensure_parent(path)?;
    let tmp = temp_path_for(path);
    let result = write(&tmp).and_then(|()| {
        std::fs::rename(&tmp, path).map_err(|source| ReportError::Io { path: path.to_path_buf(), source })
    });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Writes `bytes` to `path` atomically (see the module doc).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), ReportError> {
    write_via_temp(path, |tmp| std::fs::write(tmp, bytes).map_err(|source| ReportError::Io { path: tmp.to_path_buf(), source }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temp_names_are_hidden_siblings_with_the_extension() {
        let a = temp_path_for(Path::new("out/study/slip.png"));
        let b = temp_path_for(Path::new("out/study/slip.png"));
        assert_ne!(a, b);
        assert_eq!(a.parent(), Some(Path::new("out/study")));
        let name = a.file_name().unwrap().to_string_lossy().into_owned();
        assert!(name.starts_with(".slip.png.tmp-") && name.ends_with(".png"), "{name}");
    }

    #[test]
    fn failed_write_leaves_no_file_and_no_temp() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/test-scratch/report_file_unit");
        let _ = std::fs::remove_dir_all(&dir);
        let path = dir.join("t.md");
        let e = write_via_temp(&path, |tmp| {
            std::fs::write(tmp, b"half").unwrap();
            Err(ReportError::Font { font: "test".into() })
        });
        assert!(e.is_err());
        assert!(!path.exists());
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
        write_atomic(&path, b"whole").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"whole");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
