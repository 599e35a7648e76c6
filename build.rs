//! Build script: embeds the git commit jointquake is built from as `JQ_GIT_COMMIT`
//! (`git rev-parse HEAD`; "unknown" outside a git checkout or without git), recorded in every
//! run's `summary.json` (`provenance.commit`), with `-dirty` appended when the sources that make
//! the binary (`src/`, `build.rs`, `Cargo.toml`, `Cargo.lock`) differ from that commit: a run of
//! uncommitted code must not be credited to the commit it started from (the h 2.5 m dam run of
//! 5 December recorded 36428fb while it ran the re-entry hold of a1c348d).
use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let o = Command::new("git").args(args).output().ok()?;
    let s = String::from_utf8(o.stdout).ok()?.trim().to_string();
    (o.status.success() && !s.is_empty()).then_some(s)
}

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    // the sources scanned for changes (a directory is scanned whole by cargo)
    const SOURCES: [&str; 4] = ["src", "build.rs", "Cargo.toml", "Cargo.lock"];
    for p in SOURCES {
        println!("cargo:rerun-if-changed={p}");
    }
    let commit = match git(&["rev-parse", "HEAD"]) {
        Some(head) => {
            let mut args = vec!["status", "--porcelain", "--untracked-files=normal", "--"];
            args.extend(SOURCES);
            // `git` gives None for an empty output: clean
            match git(&args) {
                Some(_) => format!("{head}-dirty"),
                None => head,
            }
        }
        None => "unknown".into(),
    };
    println!("cargo:rustc-env=JQ_GIT_COMMIT={commit}");
    // build again when HEAD moves: HEAD itself (a checkout) and the branch it points to (a commit)
    if let Some(dir) = git(&["rev-parse", "--git-dir"]) {
        println!("cargo:rerun-if-changed={dir}/HEAD");
    }
    if let (Some(common), Some(branch)) = (git(&["rev-parse", "--git-common-dir"]), git(&["symbolic-ref", "-q", "HEAD"])) {
        for p in [format!("{common}/{branch}"), format!("{common}/packed-refs")] {
            if std::path::Path::new(&p).exists() {
                println!("cargo:rerun-if-changed={p}");
            }
        }
    }
}
