//! Studies on a Slurm cluster (src/study/slurm.rs, docs/cluster.md) without a cluster: the
//! scripts `study submit --slurm --dry-run` writes, run by hand as Slurm would run one array
//! task, give the same results as `runs.mk`; a re-submit lists only the runs not done or stale
//! (the rule `runs.mk` gives make); the options are checked; every run's summary records where
//! and how it ran, and summaries written before that still read. The real cluster is
//! `make test-slurm` (scripts/slurm/test.sh).
use crate::common::{fixture, scratch};
use jointquake::pipeline::RunSummary;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::Command;

fn manifest(p: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(p)
}

fn jq() -> Command {
    Command::new(env!("CARGO_BIN_EXE_jointquake"))
}

/// A two-run incline study (φ 35°, 40° at 0.5 g, `duration` s of El Centro) in `dir`.
fn small_study(dir: &Path, duration: f64) -> PathBuf {
    let mut s: Value = serde_json::from_str(&std::fs::read_to_string(manifest("pipelines/incline.json")).unwrap()).unwrap();
    s["geometry"]["msh"] = json!(fixture("incline_hex.msh"));
    s["loads"]["base"][0]["record"] = json!(manifest("pipelines/records/elcentro1940_NS_chopra.txt"));
    s["time"]["duration"] = json!(duration);
    std::fs::write(dir.join("scene.json"), serde_json::to_string_pretty(&s).unwrap()).unwrap();
    let study = json!({
        "name": "incline_cluster",
        "scene": "scene.json",
        "out": "out",
        "report": {"kind": "incline", "beta": 30, "monitor": "slider", "joint": "J"},
        "axes": [
            {"name": "phi", "field": "joints.phi", "values": [35, 40]},
            {"name": "pga", "field": "pga", "decimals": 2, "values": [0.5]}
        ]
    });
    let p = dir.join("study.json");
    std::fs::write(&p, serde_json::to_string_pretty(&study).unwrap()).unwrap();
    p
}

fn submit(study: &Path, dir: &Path, extra: &[&str]) -> (bool, String, String) {
    let o = jq().current_dir(dir).args(["study", "submit"]).arg(study).args(["--slurm", "--dry-run", "--cache"]).arg(dir.join("cache")).args(extra).output().unwrap();
    (o.status.success(), String::from_utf8_lossy(&o.stdout).into_owned(), String::from_utf8_lossy(&o.stderr).into_owned())
}

#[test]
fn study_submit_writes_a_job_array_of_the_runs_not_done_with_the_recipe_of_runs_mk() {
    let dir = scratch("cluster/submit");
    let study = small_study(&dir, 1.0);
    let (ok, out, err) = submit(&study, &dir, &["--partition", "batch", "--time", "00:30:00", "--cpus-per-run", "2", "--max-parallel", "1"]);
    assert!(ok, "{out}{err}");
    assert!(out.contains("2 of 2 runs to do (array 0-1%1)") && out.contains("sbatch --parsable --dependency=afterany:$JOB"), "{out}");
    let runs = std::fs::read_to_string(dir.join("out/slurm/runs.sbatch")).unwrap();
    for l in ["#SBATCH --array=0-1%1", "#SBATCH --cpus-per-task=2", "#SBATCH --partition=batch", "#SBATCH --time=00:30:00", "THREADS=2", "  phi35-pga0.50\n  phi40-pga0.50\n"] {
        assert!(runs.contains(l), "runs.sbatch lacks {l:?}:\n{runs}");
    }
    // the run's commands are those of runs.mk, with the script's variables for make's
    let mk = std::fs::read_to_string(dir.join("out/runs.mk")).unwrap();
    let recipe = |v: &jointquake::study::plan::RecipeVars| jointquake::study::plan::run_recipe(v);
    let sh = recipe(&jointquake::study::plan::RecipeVars { bin: "$BIN", out: "$OUT", id: "$ID", cache: "$CACHE", threads: "$THREADS", dollar: "$" });
    let make = recipe(&jointquake::study::plan::RecipeVars { bin: "$(BIN)", out: "$(OUT)", id: "$*", cache: "$(CACHE)", threads: "1", dollar: "$$" });
    for (s, m) in sh.iter().zip(&make) {
        assert!(runs.contains(&format!("\n{s}\n")), "runs.sbatch lacks {s:?}");
        assert!(mk.contains(&format!("\t@{m}\n")), "runs.mk lacks {m:?}");
    }
    let collect = std::fs::read_to_string(dir.join("out/slurm/collect.sbatch")).unwrap();
    assert!(collect.contains("study report ") && collect.contains("#SBATCH --job-name=jq-incline_cluster-report"), "{collect}");

    // task 1 run by hand as Slurm runs it: its results land where runs.mk puts them
    let o = Command::new("bash").arg(dir.join("out/slurm/runs.sbatch")).env("SLURM_ARRAY_TASK_ID", "1").env("SLURM_ARRAY_JOB_ID", "77").env("SLURM_JOB_ID", "78").output().unwrap();
    assert!(o.status.success(), "{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    let s = RunSummary::read(&dir.join("out/runs/phi40-pga0.50")).unwrap();
    let p = s.provenance.expect("provenance");
    let slurm = p.slurm.expect("Slurm ids");
    assert_eq!((slurm.job_id.as_str(), slurm.array_job_id.as_deref(), slurm.array_task_id.as_deref()), ("78", Some("77"), Some("1")));
    assert!(s.threads == 2 || s.threads == std::thread::available_parallelism().unwrap().get(), "--threads of --cpus-per-run: {}", s.threads);
    // a re-submit runs only the run not done; make runs the same one, and then none is left
    let (ok, out, err) = submit(&study, &dir, &[]);
    assert!(ok && out.contains("1 of 2 runs to do (array 0)") && out.contains("phi35-pga0.50 (not run)"), "{out}{err}");
    let o = Command::new("make").args(["-s", "-f"]).arg(dir.join("out/runs.mk")).arg("runs").output().unwrap();
    let made = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success() && made.trim() == "run phi35-pga0.50", "make ran: {made}");
    let (ok, out, _) = submit(&study, &dir, &[]);
    assert!(ok && out.contains("0 of 2 runs to do") && out.contains("sbatch --parsable ") && !out.contains("JOB="), "{out}");
    // a scene newer than its result is stale for both
    std::thread::sleep(std::time::Duration::from_millis(20));
    let f = std::fs::File::options().append(true).open(dir.join("out/scenes/phi40-pga0.50.json")).unwrap();
    f.set_modified(std::time::SystemTime::now()).unwrap();
    let (ok, out, _) = submit(&study, &dir, &[]);
    assert!(ok && out.contains("1 of 2 runs to do (array 1)") && out.contains("phi40-pga0.50 (stale)"), "{out}");
    let o = Command::new("make").args(["-s", "-n", "-f"]).arg(dir.join("out/runs.mk")).arg("runs").output().unwrap();
    let would = String::from_utf8_lossy(&o.stdout);
    assert!(would.contains("phi40-pga0.50") && !would.contains("phi35-pga0.50"), "make -n: {would}");
    // the report, with the cost of the runs
    let o = jq().current_dir(&dir).args(["study", "report"]).arg(&study).output().unwrap();
    assert!(!o.status.success(), "a stale run is a run without results");
    let md = std::fs::read_to_string(dir.join("out/report.md")).unwrap();
    assert!(md.contains("## Cost") && md.contains("1 finished run:"), "{md}");
}

#[test]
fn study_submit_options_are_checked_with_the_option_and_the_form() {
    let dir = scratch("cluster/options");
    let study = small_study(&dir, 0.5);
    for (args, want) in [
        (&["--time", "90"][..], "--time \"90\""),
        (&["--time", "01:75:00"][..], "minutes and seconds must be below 60"),
        (&["--cpus-per-run", "0"][..], "--cpus-per-run 0"),
        (&["--max-parallel", "0"][..], "--max-parallel 0"),
        (&["--partition", "a b"][..], "--partition \"a b\""),
    ] {
        let (ok, out, err) = submit(&study, &dir, args);
        assert!(!ok && err.contains(want) && err.starts_with("error: study submit --slurm: "), "{args:?}: {out}{err}");
    }
    assert!(!dir.join("out").exists(), "nothing is planned before the options are checked");
    let o = jq().args(["study", "submit"]).arg(&study).output().unwrap();
    assert!(!o.status.success() && String::from_utf8_lossy(&o.stderr).contains("--slurm"));
}

#[test]
fn run_summary_records_host_build_and_slurm_ids_and_old_summaries_still_read() {
    let dir = scratch("cluster/provenance");
    small_study(&dir, 0.05); // its scene.json
    let out = dir.join("run");
    let o = jq().args(["run"]).arg(dir.join("scene.json")).arg("--out").arg(&out).args(["--quiet", "--cache"]).arg(dir.join("cache")).env_remove("SLURM_JOB_ID").output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: Value = serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let p = &v["provenance"];
    let host = std::fs::read_to_string("/proc/sys/kernel/hostname").unwrap();
    assert_eq!(p["host"], host.trim());
    assert_eq!(p["version"], env!("CARGO_PKG_VERSION"));
    // built in a git checkout: a commit of this repository (HEAD at build time, which a commit
    // made since without a rebuild would no longer be); else "unknown"
    let git = |args: &[&str]| Command::new("git").args(args).current_dir(env!("CARGO_MANIFEST_DIR")).output().ok().filter(|o| o.status.success()).map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string());
    let commit = p["commit"].as_str().unwrap();
    match git(&["rev-parse", "HEAD"]) {
        Some(_) => {
            // "-dirty" when built from uncommitted sources (build.rs)
            let sha = commit.strip_suffix("-dirty").unwrap_or(commit);
            assert!(sha.len() == 40 && sha.bytes().all(|b| b.is_ascii_hexdigit()), "commit {commit}");
            assert_eq!(git(&["cat-file", "-t", sha]).as_deref(), Some("commit"), "{sha} is not a commit of this repository");
            let dirty = git(&["status", "--porcelain", "--", "src", "build.rs", "Cargo.toml", "Cargo.lock"]).is_some_and(|s| !s.is_empty());
            if !dirty {
                assert!(!commit.ends_with("-dirty"), "clean sources, yet {commit}");
            }
        }
        None => assert_eq!(commit, "unknown"),
    }
    assert!(p.get("slurm").is_none(), "not under Slurm: {p}");
    assert!(String::from_utf8_lossy(&o.stdout).contains(&format!("ran on          {}", host.trim())));
    // a summary written before provenance was recorded reads, without it
    let mut old = v.clone();
    old.as_object_mut().unwrap().remove("provenance");
    std::fs::write(out.join("summary.json"), serde_json::to_string(&old).unwrap()).unwrap();
    let s = RunSummary::read(&out).unwrap();
    assert!(s.provenance.is_none() && s.steps > 0);
}
