//! Output files from user-given names: the one rule that turns a name into a file stem, the
//! check that a joined output path stays under its directory, and whole-file writes that never
//! replace what is not a regular file.
//!
//! Owns: [`file_stem`] (every writer that puts a user's name — scene, joint, monitor, study
//! run, record — into a file name calls it), [`path_under`], [`check_regular_target`],
//! [`write_whole`]. Inputs: names, directories, bytes. Outputs: stems, paths, files, or a
//! message naming the path and the fix. Invariants: a stem is 1–[`MAX_STEM_LEN`] bytes of
//! `[A-Za-z0-9_.+-]` and never starts with `.`, so `dir.join(stem + ext)` is a plain file
//! directly in `dir` (no `/`, no `..`, no hidden file); an existing target that is a device, a
//! fifo, a socket, a directory or a symlink is never replaced or opened for writing (`--out
//! /dev/null` run as root would otherwise have replaced `/dev/null` by a regular file).
//!
//! A leaf module (std only): the writers of `output`, `motion`, `vtk`, `study` and the scene's
//! checks all use it, and `output` itself depends on the scene, so the rule cannot live there
//! without an import loop.

use std::path::{Component, Path, PathBuf};

/// Longest file stem [bytes]: 100, so that a stem with its suffix (`joint_<stem>_forces.csv`)
/// stays far below the 255-byte file-name limit of Linux file systems.
pub const MAX_STEM_LEN: usize = 100;

/// Whether `c` may stand in a file stem as it is.
fn stem_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.' | '+')
}

/// The file stem of a user-given name: every character other than ASCII letters, digits, `_`,
/// `-`, `.`, `+` becomes `_`, a leading `.` becomes `_` (no hidden file, no `..`), the result is
/// cut to [`MAX_STEM_LEN`] bytes, and an empty name gives `_`. Names made of allowed characters
/// only (all the pipelines' names) are their own stem.
pub fn file_stem(name: &str) -> String {
    let mut s: String = name.chars().map(|c| if stem_char(c) { c } else { '_' }).take(MAX_STEM_LEN).collect();
    if s.starts_with('.') {
        s.replace_range(0..1, "_");
    }
    if s.is_empty() {
        s.push('_');
    }
    s
}

/// Whether `name` is its own file stem (see [`file_stem`]).
pub fn is_file_stem(name: &str) -> bool {
    file_stem(name) == name
}

/// `dir/rel`, when `rel` is a relative path of plain components (no root, no `..`, no `.`):
/// what a writer joins to its output directory always stays under it.
pub fn path_under(dir: &Path, rel: &str) -> Result<PathBuf, String> {
    let r = Path::new(rel);
    if rel.is_empty() || !r.components().all(|c| matches!(c, Component::Normal(_))) {
        return Err(format!("output file \"{rel}\" would not lie under {}: an output name may not hold `/`, `..` or a root", dir.display()));
    }
    Ok(dir.join(r))
}

/// Refuse to write to `path` when it exists and is not a regular file (device, fifo, socket,
/// directory, symlink): the message names it and says what to give instead. An absent path is
/// fine.
pub fn check_regular_target(path: &Path) -> Result<(), String> {
    match std::fs::symlink_metadata(path) {
        Err(_) => Ok(()),
        Ok(m) if m.file_type().is_file() => Ok(()),
        Ok(m) => {
            let what = if m.file_type().is_symlink() {
                "a symbolic link"
            } else if m.is_dir() {
                "a directory"
            } else {
                "a device, fifo or socket"
            };
            Err(format!("{} is {what}, not a regular file: refusing to replace it. Give the path of a regular file (or a new one)", path.display()))
        }
    }
}

/// Write `bytes` to `path` whole: to a temporary file beside it, then renamed over it; on any
/// error the temporary file is removed and `path` is left as it was. A target that is not a
/// regular file is refused ([`check_regular_target`]). The error is (the path, the message).
pub fn write_whole(path: &Path, bytes: &[u8]) -> Result<(), (PathBuf, String)> {
    check_regular_target(path).map_err(|m| (path.to_path_buf(), m))?;
    let mut name = path.file_name().map(|n| n.to_os_string()).unwrap_or_default();
    name.push(format!(".{}.tmp", std::process::id()));
    let tmp = path.with_file_name(name);
    let result = std::fs::write(&tmp, bytes).map_err(|e| (tmp.clone(), e.to_string())).and_then(|()| std::fs::rename(&tmp, path).map_err(|e| (path.to_path_buf(), e.to_string())));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Largest scene, study or `.geo` file read [bytes]: 16 MiB (the largest scene of the
/// pipelines is 6 kB).
pub const MAX_TEXT_INPUT: u64 = 16 << 20;
/// Largest record file read [bytes]: 256 MiB (10⁷ samples of two columns; the PEER records are
/// under 1 MB).
pub const MAX_RECORD_INPUT: u64 = 256 << 20;
/// Largest mesh file read [bytes]: 2 GiB (the default arch dam's mesh is 6.6 MB; a mesh of
/// 2 GB is beyond what a run on this machine can step).
pub const MAX_MESH_INPUT: u64 = 2 << 30;

/// Read at most `max` bytes of `path`; a longer input (`/dev/zero`, an endless fifo, a wrong
/// file) is an error saying so instead of reading until memory runs out (issue 34).
pub fn read_bounded(path: &Path, max: u64) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let mut buf = Vec::new();
    std::fs::File::open(path)?.take(max + 1).read_to_end(&mut buf)?;
    if buf.len() as u64 > max {
        return Err(std::io::Error::other(format!("longer than {max} bytes, the limit of this input (an endless file such as /dev/zero, or the wrong file?)")));
    }
    Ok(buf)
}

/// [`read_bounded`] as UTF-8 text.
pub fn read_text_bounded(path: &Path, max: u64) -> std::io::Result<String> {
    String::from_utf8(read_bounded(path, max)?).map_err(|_| std::io::Error::new(std::io::ErrorKind::InvalidData, "stream did not contain valid UTF-8"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hostile_names_become_stems_inside_the_directory() {
        // Regression (issue 33): joint names reached histories/joint_<name>.csv raw, so
        // "../../x" wrote outside --out. Reference: the stem rule above.
        for (name, stem) in [("J01", "J01"), ("../../etc/x", "_._.._etc_x"), ("/abs", "_abs"), ("..", "_."), ("", "_"), ("a b:c", "a_b_c"), (".hidden", "_hidden"), ("é", "_")] {
            assert_eq!(file_stem(name), stem, "{name}");
            assert!(path_under(Path::new("out"), &format!("{stem}.csv")).is_ok());
        }
        assert_eq!(file_stem(&"x".repeat(500)).len(), MAX_STEM_LEN);
        assert!(path_under(Path::new("out"), "../x.csv").is_err());
        assert!(path_under(Path::new("out"), "/x.csv").is_err());
        assert!(is_file_stem("J01") && !is_file_stem("a/b"));
    }

    #[test]
    fn dev_zero_as_an_input_is_refused_at_the_bound() {
        // Regression (issue 34): /dev/zero as a record, mesh or scene was read until memory
        // ran out. Reference: the bound, 1 MiB here, read and refused at once.
        let e = read_bounded(Path::new("/dev/zero"), 1 << 20).unwrap_err();
        assert!(e.to_string().contains("longer than 1048576 bytes"), "{e}");
        assert!(read_text_bounded(Path::new("/dev/null"), 10).unwrap().is_empty());
    }

    #[test]
    fn write_whole_refuses_a_symlink_or_directory_target_and_leaves_no_temp_file() {
        // Regression (issue 34): a writer's temp + rename replaced a symlink (or /dev/null)
        // by a regular file.
        let d = std::env::temp_dir().join(format!("jq-files-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        let target = d.join("real.txt");
        std::fs::write(&target, "keep").unwrap();
        let link = d.join("link.txt");
        std::os::unix::fs::symlink(&target, &link).unwrap();
        let e = write_whole(&link, b"new").unwrap_err();
        assert!(e.1.contains("symbolic link"), "{e:?}");
        assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "keep");
        assert!(write_whole(&d, b"x").unwrap_err().1.contains("directory"));
        assert!(check_regular_target(Path::new("/dev/null")).unwrap_err().contains("device"));
        write_whole(&d.join("new.txt"), b"ok").unwrap();
        let left: Vec<_> = std::fs::read_dir(&d).unwrap().filter_map(|e| e.ok()).map(|e| e.file_name().to_string_lossy().into_owned()).filter(|n| n.ends_with(".tmp")).collect();
        assert!(left.is_empty(), "{left:?}");
        let _ = std::fs::remove_dir_all(&d);
    }
}
