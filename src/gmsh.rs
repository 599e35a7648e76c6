//! Running the gmsh command line (no shell) and caching its `.msh`.
//!
//! Which gmsh: the `GMSH` environment variable (a path to an executable, or to the wheel's
//! `.venv/bin/gmsh` script, which is then run by the `python` beside it) if set; otherwise the
//! PyPI wheel in a project-local `.venv` (its `bin/gmsh` script run by the venv's python),
//! looked up from the current directory and from the directory of this executable; otherwise
//! `gmsh` on the PATH.
//!
//! Cache: the mesh goes to `<cache>/<stem>-<key>.msh`, where the key hashes the `.geo` text and
//! the `-setnumber` parameters; an existing file with that key is reused. The gmsh log is kept
//! beside it (`.log`). (Files pulled in by `Include` are not part of the key.)

use crate::error::GmshError;
use std::collections::BTreeMap;
use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The gmsh command: program and leading arguments.
pub fn gmsh_command() -> Vec<String> {
    if let Ok(g) = std::env::var("GMSH") {
        if !g.trim().is_empty() {
            return wheel_script_command(Path::new(&g)).unwrap_or_else(|| vec![g]);
        }
    }
    let mut roots = vec![PathBuf::from(".")];
    if let Ok(exe) = std::env::current_exe() {
        // target/{release,debug}/jointquake → project root
        if let Some(root) = exe.parent().and_then(|p| p.parent()).and_then(|p| p.parent()) {
            roots.push(root.to_path_buf());
        }
    }
    for r in roots {
        let py = r.join(".venv/bin/python");
        let script = r.join(".venv/bin/gmsh");
        if py.exists() && script.exists() {
            return vec![py.to_string_lossy().into_owned(), script.to_string_lossy().into_owned()];
        }
    }
    vec!["gmsh".into()]
}

/// `GMSH=.venv/bin/gmsh` names the PyPI wheel's launcher, a Python script whose `#!` line runs
/// whatever `python` is first on the PATH (which then lacks the gmsh module). Run such a script
/// with the `python` beside it when there is one (the venv's), as the default lookup does.
fn wheel_script_command(g: &Path) -> Option<Vec<String>> {
    let mut head = [0u8; 128];
    let n = std::io::Read::read(&mut std::fs::File::open(g).ok()?, &mut head).ok()?;
    let first = head[..n].split(|&b| b == b'\n').next()?;
    if !(first.starts_with(b"#!") && first.windows(6).any(|w| w == b"python")) {
        return None;
    }
    let py = g.parent()?.join("python");
    py.exists().then(|| vec![py.to_string_lossy().into_owned(), g.to_string_lossy().into_owned()])
}

/// Cache key of a `.geo` and its parameters.
fn cache_key(geo_text: &str, set: &BTreeMap<String, f64>) -> String {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    geo_text.hash(&mut h);
    for (k, v) in set {
        k.hash(&mut h);
        v.to_bits().hash(&mut h);
    }
    format!("{:016x}", h.finish())
}

/// Mesh `geo` in 3-D with the given `-setnumber` parameters into `cache_dir`, reusing a cached
/// mesh when the `.geo` text and parameters are unchanged. Returns the `.msh` path.
pub fn mesh_geo(geo: &Path, set: &BTreeMap<String, f64>, cache_dir: &Path) -> Result<PathBuf, GmshError> {
    let text = std::fs::read_to_string(geo).map_err(|_| GmshError::MissingGeo { path: geo.to_path_buf() })?;
    std::fs::create_dir_all(cache_dir).map_err(|source| GmshError::Io { path: cache_dir.to_path_buf(), source })?;
    let stem = geo.file_stem().and_then(|s| s.to_str()).unwrap_or("mesh");
    let key = cache_key(&text, set);
    let msh = cache_dir.join(format!("{stem}-{key}.msh"));
    let log = cache_dir.join(format!("{stem}-{key}.log"));
    if msh.exists() {
        return Ok(msh);
    }
    let cmd = gmsh_command();
    // per-process temporary name: two runs meshing the same scene at once (`make -j`) must not
    // write into one file; the rename below is atomic and both produce the same mesh
    let tmp = cache_dir.join(format!("{stem}-{key}.{}.tmp.msh", std::process::id()));
    let mut c = Command::new(&cmd[0]);
    c.args(&cmd[1..]).arg(geo).arg("-3").arg("-format").arg("msh41").arg("-o").arg(&tmp);
    for (k, v) in set {
        c.arg("-setnumber").arg(k).arg(format!("{v}"));
    }
    let out = c.output().map_err(|source| GmshError::Spawn { exe: cmd.join(" "), source })?;
    let mut all = String::from_utf8_lossy(&out.stdout).into_owned();
    all.push_str(&String::from_utf8_lossy(&out.stderr));
    std::fs::write(&log, &all).map_err(|source| GmshError::Io { path: log.clone(), source })?;
    let errors: Vec<&str> = all.lines().filter(|l| l.starts_with("Error")).collect();
    if !out.status.success() || !errors.is_empty() || !tmp.exists() {
        let _ = std::fs::remove_file(&tmp);
        let message = if errors.is_empty() {
            let tail: Vec<&str> = all.lines().rev().take(8).collect();
            tail.into_iter().rev().collect::<Vec<_>>().join("\n")
        } else {
            errors.join("\n")
        };
        return Err(GmshError::Failed { geo: geo.to_path_buf(), log, message });
    }
    std::fs::rename(&tmp, &msh).map_err(|source| GmshError::Io { path: msh.clone(), source })?;
    Ok(msh)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gmsh_env_naming_the_wheel_script_runs_it_with_the_venv_python() {
        // Regression: `GMSH=.venv/bin/gmsh` ran the script's `#!/usr/bin/env python`, i.e. the
        // PATH's python without the gmsh module (ModuleNotFoundError).
        let d = std::env::temp_dir().join(format!("jq-gmsh-wheel-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let script = d.join("gmsh");
        std::fs::write(&script, "#!/usr/bin/env python\nimport gmsh\n").unwrap();
        std::fs::write(d.join("python"), "").unwrap();
        let cmd = wheel_script_command(&script).expect("a python launcher beside its python");
        assert_eq!(cmd, vec![d.join("python").to_string_lossy().into_owned(), script.to_string_lossy().into_owned()]);
        // A real executable (not a python script) is run as it is.
        let exe = d.join("gmsh-bin");
        std::fs::write(&exe, b"\x7fELF\x02\x01\x01").unwrap();
        assert!(wheel_script_command(&exe).is_none());
        let _ = std::fs::remove_dir_all(&d);
    }
}
