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

/// The parameters a `.geo` declares: the names before `=` at the top level of each
/// `DefineConstant[ … ];` list (`H = {20, Min 1, Name "Parameters/H"}` gives `H`), the only
/// names `-setnumber` changes.
pub fn geo_parameters(text: &str) -> std::collections::BTreeSet<String> {
    let mut out = std::collections::BTreeSet::new();
    let mut rest = text;
    while let Some(i) = rest.find("DefineConstant") {
        rest = &rest[i + "DefineConstant".len()..];
        let Some(open) = rest.find('[') else { break };
        let body = &rest[open + 1..];
        let (mut depth, mut end, mut entry_start) = (0i32, body.len(), 0usize);
        let mut entries = Vec::new();
        for (k, c) in body.char_indices() {
            match c {
                '{' | '(' => depth += 1,
                '}' | ')' => depth -= 1,
                ',' if depth == 0 => {
                    entries.push(&body[entry_start..k]);
                    entry_start = k + 1;
                }
                ']' if depth == 0 => {
                    end = k;
                    break;
                }
                _ => {}
            }
        }
        entries.push(&body[entry_start..end]);
        for e in entries {
            if let Some((name, _)) = e.split_once('=') {
                let name = name.trim();
                if !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
                    out.insert(name.to_string());
                }
            }
        }
        rest = &body[end.min(body.len())..];
    }
    out
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
    let text = match crate::files::read_text_bounded(geo, crate::files::MAX_TEXT_INPUT) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Err(GmshError::MissingGeo { path: geo.to_path_buf() }),
        Err(e) => return Err(GmshError::Failed { geo: geo.to_path_buf(), log: geo.to_path_buf(), message: format!("cannot read the script: {e}") }),
    };
    let declared = geo_parameters(&text);
    if let Some(unknown) = set.keys().find(|k| !declared.contains(k.as_str())) {
        let known = declared.into_iter().collect::<Vec<_>>().join(", ");
        return Err(GmshError::Failed {
            geo: geo.to_path_buf(),
            log: geo.to_path_buf(),
            message: format!("not meshed: geometry.set names \"{unknown}\", which the script does not declare in a DefineConstant (gmsh would ignore it silently). Its parameters: {}", if known.is_empty() { "none".into() } else { known }),
        });
    }
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
    let (status, all) = run_child(&mut c).map_err(|source| GmshError::Spawn { exe: cmd.join(" "), source })?;
    std::fs::write(&log, &all).map_err(|source| GmshError::Io { path: log.clone(), source })?;
    if crate::interrupt::interrupted() {
        let _ = std::fs::remove_file(&tmp);
        return Err(crate::interrupt::Interrupted { phase: format!("meshing {} (gmsh was stopped; its log: {})", geo.display(), log.display()) }.into());
    }
    let errors: Vec<&str> = all.lines().filter(|l| l.starts_with("Error")).collect();
    if !status.success() || !errors.is_empty() || !tmp.exists() {
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

/// Run gmsh as a child that ends with the run: in its own process group (a terminal's Ctrl-C
/// reaches only jointquake, which decides), killed when jointquake's interrupt flag is set
/// (polled every [`CHILD_POLL`]) and, through `PR_SET_PDEATHSIG`, when jointquake itself dies,
/// even by SIGKILL (the gmsh child outlived its parent, issue 34). Its output is collected by
/// two reader threads (a full pipe would block it). Returns the exit status and stdout+stderr.
fn run_child(c: &mut Command) -> std::io::Result<(std::process::ExitStatus, String)> {
    use std::io::Read;
    use std::os::unix::process::CommandExt;
    c.process_group(0).stdin(std::process::Stdio::null()).stdout(std::process::Stdio::piped()).stderr(std::process::Stdio::piped());
    // SAFETY: prctl is async-signal-safe and touches no memory of the parent.
    unsafe {
        c.pre_exec(|| {
            if libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    let mut child = c.spawn()?;
    let reader = |r: Option<Box<dyn Read + Send>>| {
        std::thread::spawn(move || {
            let mut s = Vec::new();
            if let Some(mut r) = r {
                let _ = r.read_to_end(&mut s);
            }
            s
        })
    };
    let out = reader(child.stdout.take().map(|r| Box::new(r) as Box<dyn Read + Send>));
    let err = reader(child.stderr.take().map(|r| Box::new(r) as Box<dyn Read + Send>));
    let status = loop {
        if let Some(s) = child.try_wait()? {
            break s;
        }
        if crate::interrupt::interrupted() {
            let _ = child.kill();
            break child.wait()?;
        }
        std::thread::sleep(CHILD_POLL);
    };
    let mut all = String::from_utf8_lossy(&out.join().unwrap_or_default()).into_owned();
    all.push_str(&String::from_utf8_lossy(&err.join().unwrap_or_default()));
    Ok((status, all))
}

/// How often a running gmsh child is checked for the interrupt flag: 50 ms (an interrupt ends
/// it within that; the poll costs nothing next to meshing).
const CHILD_POLL: std::time::Duration = std::time::Duration::from_millis(50);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unknown_geometry_set_name_is_refused_before_meshing() {
        // Regression (issue 34): a misspelt `geometry.set` name was passed to gmsh, which
        // ignored it. Reference: the DefineConstant names of geo/column.geo.
        let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/geo/column.geo")).unwrap();
        let names: Vec<String> = geo_parameters(&text).into_iter().collect();
        assert_eq!(names, ["H", "nw", "nz", "tets", "w"]);
        let d = std::env::temp_dir().join(format!("jq-gmsh-set-{}", std::process::id()));
        let mut set = BTreeMap::new();
        set.insert("Hh".to_string(), 20.0);
        let e = mesh_geo(Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/geo/column.geo")), &set, &d).unwrap_err().to_string();
        assert!(e.contains("\"Hh\"") && e.contains("H, nw, nz, tets, w"), "{e}");
        assert!(!d.exists(), "nothing written before the check");
    }

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
