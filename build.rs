//! Build script: embeds the git commit jointquake is built from as `JQ_GIT_COMMIT`
//! (`git rev-parse HEAD`; "unknown" outside a git checkout or without git), recorded in every
//! run's `summary.json` (`provenance.commit`).
use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let o = Command::new("git").args(args).output().ok()?;
    let s = String::from_utf8(o.stdout).ok()?.trim().to_string();
    (o.status.success() && !s.is_empty()).then_some(s)
}

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    let commit = git(&["rev-parse", "HEAD"]).unwrap_or_else(|| "unknown".into());
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
