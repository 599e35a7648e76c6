//! Running a study's runs on a Slurm cluster (`jointquake study submit --slurm`, docs/cluster.md).
//!
//! After the plan (written as by `study plan`), `<out>/slurm/` gets two batch scripts:
//! `runs.sbatch`, a job array with one task per run to do (task `k` runs `plan.runs[k]`, so a
//! task's number is the run's place in `plan.json` whatever is left to do), and
//! `collect.sbatch`, the study's own steps and its report, submitted to start after the array
//! whatever became of its tasks (`--dependency=afterany:<array job>`). Each task runs the same
//! commands as the run's target in `runs.mk` ([`run_recipe`]), so results land in the same
//! layout as a local `make -j`, and `study report` reads them the same way on any machine.
//! Which runs are to do is the rule `runs.mk` gives make ([`PlannedRun::freshness`]): a
//! re-submit runs only the runs never done, stale, or killed before they ended.
//!
//! Conventions: times are Slurm's `[D-]HH:MM:SS`; paths in the scripts are absolute (the
//! cluster's nodes share the file system the study is on); the jobs are named
//! `jq-<study name>` and `jq-<study name>-report`; a task killed by Slurm (`scancel`, time or
//! memory limit) writes `failed.txt` naming its job and task and leaves no `.done`.

use super::plan::{absolute, mk_path, run_recipe, Plan, RecipeVars, RunFreshness};
use crate::error::{Error, OutputError, StudyError};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Options of `study submit --slurm` (each is a CLI option, docs/cli.md).
#[derive(Clone, Debug)]
pub struct SlurmOptions {
    /// `--partition`: the partition of both jobs. Default: the cluster's default partition.
    pub partition: Option<String>,
    /// `--time`: time limit of each task and of the report job, `[D-]HH:MM:SS`. Default: the
    /// partition's.
    pub time: Option<String>,
    /// `--cpus-per-run`: cores of each task, and `--threads` of its run. Default 1.
    pub cpus_per_run: usize,
    /// `--max-parallel`: at most this many tasks at once (`%K`). Default: no limit.
    pub max_parallel: Option<usize>,
    /// The jointquake binary the tasks run (absolute).
    pub bin: PathBuf,
    /// The mesh cache (absolute in the scripts).
    pub cache: PathBuf,
}

fn slurm_err(message: impl Into<String>) -> Error {
    StudyError::Slurm(message.into()).into()
}

/// Seconds of a Slurm time limit `[D-]HH:MM:SS` (minutes and seconds below 60, hours below
/// 24 after a day count); an error that shows the form otherwise.
pub fn parse_time_limit(s: &str) -> Result<u64, Error> {
    let bad = |why: &str| slurm_err(format!("--time {s:?}: {why}; give HH:MM:SS or D-HH:MM:SS, e.g. 02:00:00 or 1-12:00:00"));
    let (days, hms) = match s.split_once('-') {
        Some((d, rest)) => (Some(d.parse::<u64>().map_err(|_| bad("the day count is not a whole number"))?), rest),
        None => (None, s),
    };
    let parts: Vec<&str> = hms.split(':').collect();
    if parts.len() != 3 || parts.iter().any(|p| p.is_empty() || !p.bytes().all(|b| b.is_ascii_digit()) || p.len() > 4) {
        return Err(bad("not three numbers separated by `:`"));
    }
    let n: Vec<u64> = parts.iter().map(|p| p.parse().expect("digits")).collect();
    if n[1] >= 60 || n[2] >= 60 {
        return Err(bad("minutes and seconds must be below 60"));
    }
    if days.is_some() && n[0] >= 24 {
        return Err(bad("hours must be below 24 after a day count"));
    }
    let total = days.unwrap_or(0).saturating_mul(86_400).saturating_add(n[0] * 3600 + n[1] * 60 + n[2]);
    if total == 0 {
        return Err(bad("a time limit of zero"));
    }
    Ok(total)
}

impl SlurmOptions {
    /// Refuse what `sbatch` would refuse, or misread, with the option's name and the fix.
    pub fn check(&self) -> Result<(), Error> {
        if self.cpus_per_run == 0 {
            return Err(slurm_err("--cpus-per-run 0: give at least 1 (the cores of each run)"));
        }
        if self.max_parallel == Some(0) {
            return Err(slurm_err("--max-parallel 0: give at least 1 (or leave it out: no limit)"));
        }
        if let Some(t) = &self.time {
            parse_time_limit(t)?;
        }
        if let Some(p) = &self.partition
            && (p.is_empty() || !p.chars().all(|c| c.is_ascii_alphanumeric() || "_.,-".contains(c)))
        {
            return Err(slurm_err(format!("--partition {p:?}: a partition name (letters, digits, `_`, `.`, `-`; a comma-separated list)")));
        }
        Ok(())
    }
}

/// What `study submit` wrote and will run.
#[derive(Clone, Debug)]
pub struct Submission {
    pub runs_script: PathBuf,
    pub collect_script: PathBuf,
    /// Runs to do: (array index, id, why: not run / stale / not finished).
    pub todo: Vec<(usize, String, &'static str)>,
    /// Runs in the plan.
    pub total: usize,
    /// The `--array` value (indices, `%K`), if any run is to do.
    pub array: Option<String>,
}

/// Compact `--array` indices: `0-3,7,9-10`.
fn index_ranges(ix: &[usize]) -> String {
    let mut out: Vec<String> = Vec::new();
    let mut i = 0;
    while i < ix.len() {
        let mut j = i;
        while j + 1 < ix.len() && ix[j + 1] == ix[j] + 1 {
            j += 1;
        }
        out.push(if j == i { ix[i].to_string() } else { format!("{}-{}", ix[i], ix[j]) });
        i = j + 1;
    }
    out.join(",")
}

/// `#SBATCH` lines common to both jobs.
fn common_header(t: &mut String, opts: &SlurmOptions) {
    let _ = writeln!(t, "#SBATCH --ntasks=1\n#SBATCH --cpus-per-task={}", opts.cpus_per_run);
    if let Some(p) = &opts.partition {
        let _ = writeln!(t, "#SBATCH --partition={p}");
    }
    if let Some(x) = &opts.time {
        let _ = writeln!(t, "#SBATCH --time={x}");
    }
}

/// The name of a study's jobs (`jq-<name>`; the report job adds `-report`).
pub fn job_name(plan: &Plan) -> String {
    format!("jq-{}", plan.name)
}

/// Write `<out>/slurm/runs.sbatch` and `collect.sbatch` for the runs of `plan` not done yet
/// (the plan must have been written just before: `write_plan`).
pub fn write_scripts(plan: &Plan, opts: &SlurmOptions) -> Result<Submission, Error> {
    opts.check()?;
    let out = mk_path(&plan.out)?;
    let bin = mk_path(&absolute(&opts.bin))?;
    let cache = mk_path(&absolute(&opts.cache))?;
    let study_path = mk_path(&plan.study)?;
    let cwd = mk_path(&absolute(Path::new(".")))?;
    let dir = plan.out.join("slurm");
    std::fs::create_dir_all(&dir).map_err(|e| OutputError::write(&dir, e))?;
    let todo: Vec<(usize, String, &'static str)> = plan
        .runs
        .iter()
        .enumerate()
        .filter_map(|(k, r)| match r.freshness() {
            RunFreshness::Done => None,
            RunFreshness::Stale => Some((k, r.spec.id.clone(), "stale")),
            RunFreshness::NotDone if r.log().exists() => Some((k, r.spec.id.clone(), "not finished")),
            RunFreshness::NotDone => Some((k, r.spec.id.clone(), "not run")),
        })
        .collect();
    let array = (!todo.is_empty()).then(|| {
        let ix: Vec<usize> = todo.iter().map(|(k, _, _)| *k).collect();
        let mut a = index_ranges(&ix);
        if let Some(k) = opts.max_parallel {
            let _ = write!(a, "%{k}");
        }
        a
    });
    let name = job_name(plan);

    let mut t = String::from("#!/bin/bash\n");
    let _ = writeln!(t, "#SBATCH --job-name={name}");
    if let Some(a) = &array {
        let _ = writeln!(t, "#SBATCH --array={a}");
    }
    common_header(&mut t, opts);
    let _ = writeln!(t, "#SBATCH --chdir={cwd}\n#SBATCH --output={out}/slurm/%A_%a.out");
    if array.is_none() {
        t.push_str("# Every run was done when this was written: nothing to run (`study submit` again after a change).\nexit 0\n");
    }
    let _ = writeln!(t, "# Generated by `jointquake study submit --slurm` for {study_path}:");
    let _ = writeln!(t, "# task k runs RUNS[k] (the runs of plan.json, in order); --array holds the runs not done when");
    let _ = writeln!(t, "# it was written. Each task runs the run's commands of runs.mk (log: runs/<id>.log).");
    let _ = writeln!(t, "set -u\nBIN={bin}\nOUT={out}\nCACHE={cache}\nTHREADS={}", opts.cpus_per_run);
    t.push_str("RUNS=(");
    for r in &plan.runs {
        let _ = write!(t, "\n  {}", r.spec.id);
    }
    t.push_str("\n)\nID=${RUNS[${SLURM_ARRAY_TASK_ID:?not a Slurm array task}]:?task index outside the plan}\n");
    t.push_str("# Killed before the end (scancel, time or memory limit): say so in failed.txt and leave no\n");
    t.push_str("# .done, so that the report names the run as failed and a re-submit runs it again.\n");
    t.push_str("trap 'echo \"killed by Slurm before it ended (job ${SLURM_ARRAY_JOB_ID}_${SLURM_ARRAY_TASK_ID} on $(hostname): cancelled, or out of time or memory)\" > \"$OUT/runs/$ID/failed.txt\"; echo \"run $ID KILLED\"; exit 143' TERM INT\n");
    let vars = RecipeVars { bin: "$BIN", out: "$OUT", id: "$ID", cache: "$CACHE", threads: "$THREADS", dollar: "$" };
    for line in run_recipe(&vars) {
        t.push_str(&line);
        t.push('\n');
    }
    let runs_script = dir.join("runs.sbatch");
    crate::report::file::write_atomic(&runs_script, t.as_bytes())?;

    let mut c = String::from("#!/bin/bash\n");
    let _ = writeln!(c, "#SBATCH --job-name={name}-report");
    common_header(&mut c, opts);
    let _ = writeln!(c, "#SBATCH --chdir={cwd}\n#SBATCH --output={out}/slurm/report-%j.out");
    let _ = writeln!(c, "# Generated by `jointquake study submit --slurm`: after the runs' array job (afterany), the");
    let _ = writeln!(c, "# study's own steps not done yet (runs.mk), then the report (status 1 when runs have no results).");
    c.push_str("set -u\n");
    if !plan.steps.is_empty() {
        let _ = writeln!(c, "make --no-print-directory -j{} -f {out}/runs.mk steps BIN={bin}", opts.cpus_per_run);
    }
    let _ = writeln!(c, "{bin} study report {study_path}");
    let collect_script = dir.join("collect.sbatch");
    crate::report::file::write_atomic(&collect_script, c.as_bytes())?;
    Ok(Submission { runs_script, collect_script, todo, total: plan.runs.len(), array })
}

/// The commands that submit `sub` (`$JOB` is the array job's id when there is one).
pub fn commands(sub: &Submission) -> Vec<String> {
    let mut v = Vec::new();
    if sub.array.is_some() {
        v.push(format!("JOB=$(sbatch --parsable {} | cut -d';' -f1)", sub.runs_script.display()));
        v.push(format!("sbatch --parsable --dependency=afterany:$JOB {}", sub.collect_script.display()));
    } else {
        v.push(format!("sbatch --parsable {}", sub.collect_script.display()));
    }
    v
}

/// Job ids of a submission.
#[derive(Clone, Debug)]
pub struct Submitted {
    /// The runs' array job (none when every run was done).
    pub array_job: Option<String>,
    pub report_job: String,
}

fn sbatch(args: &[&str], script: &Path) -> Result<String, Error> {
    let o = Command::new("sbatch").args(args).arg(script).output().map_err(|e| {
        slurm_err(format!("cannot start `sbatch` ({e}): run this on a machine of the Slurm cluster (a login node), or add --dry-run to write the scripts and print the commands"))
    })?;
    let stdout = String::from_utf8_lossy(&o.stdout);
    let id = stdout.trim().split(';').next().unwrap_or("").to_string();
    if !o.status.success() || id.is_empty() || !id.bytes().all(|b| b.is_ascii_digit()) {
        return Err(slurm_err(format!("`sbatch {} {}` failed ({}): {}{}", args.join(" "), script.display(), o.status, String::from_utf8_lossy(&o.stderr).trim(), stdout.trim())));
    }
    Ok(id)
}

/// Jobs of this user named `name` still queued or running (`squeue --me`); none when `squeue`
/// cannot be asked.
pub fn queued_jobs(name: &str) -> Vec<String> {
    match Command::new("squeue").args(["--me", "--noheader", "--name", name, "--format", "%i"]).output() {
        Ok(o) if o.status.success() => String::from_utf8_lossy(&o.stdout).split_whitespace().map(str::to_string).collect(),
        _ => Vec::new(),
    }
}

/// Submit the array job and the report job after it. Refuses while jobs of the same study are
/// queued or running (they would run the same runs twice).
pub fn submit(plan: &Plan, sub: &Submission) -> Result<Submitted, Error> {
    let name = job_name(plan);
    let queued: Vec<String> = [queued_jobs(&name), queued_jobs(&format!("{name}-report"))].concat();
    if !queued.is_empty() {
        return Err(slurm_err(format!(
            "jobs of this study ({name}) are still queued or running: {}; wait for them (`squeue --me --name {name}`) or cancel them (`scancel {}`), then submit again",
            queued.join(", "),
            queued.join(" ")
        )));
    }
    let array_job = match &sub.array {
        Some(_) => Some(sbatch(&["--parsable"], &sub.runs_script)?),
        None => None,
    };
    let dep = array_job.as_ref().map(|j| format!("--dependency=afterany:{j}"));
    let mut args = vec!["--parsable"];
    if let Some(d) = &dep {
        args.push(d);
    }
    let report_job = sbatch(&args, &sub.collect_script)?;
    let log = plan.out.join("slurm").join("submitted.txt");
    let line = format!(
        "array job {} ({} of {} runs: {}), report job {}\n",
        array_job.as_deref().unwrap_or("none"),
        sub.todo.len(),
        sub.total,
        sub.array.as_deref().unwrap_or("-"),
        report_job
    );
    use std::io::Write as _;
    std::fs::OpenOptions::new().create(true).append(true).open(&log).and_then(|mut f| f.write_all(line.as_bytes())).map_err(|e| OutputError::write(&log, e))?;
    Ok(Submitted { array_job, report_job })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_limits_parse_or_name_the_form() {
        assert_eq!(parse_time_limit("02:00:00").unwrap(), 7200);
        assert_eq!(parse_time_limit("1-12:00:30").unwrap(), 86_400 + 43_200 + 30);
        assert_eq!(parse_time_limit("48:00:00").unwrap(), 48 * 3600);
        for bad in ["", "2", "1:30", "00:00:00", "01:60:00", "01:00:61", "1-24:00:00", "x-01:00:00", "01:-1:00", "1:2:3:4", " 01:00:00"] {
            let e = parse_time_limit(bad).unwrap_err().to_string();
            assert!(e.contains("--time") && e.contains("HH:MM:SS"), "{bad:?}: {e}");
        }
    }

    #[test]
    fn array_indices_are_compact_ranges() {
        assert_eq!(index_ranges(&[0, 1, 2, 3, 7, 9, 10]), "0-3,7,9-10");
        assert_eq!(index_ranges(&[4]), "4");
        assert_eq!(index_ranges(&[]), "");
    }

    #[test]
    fn options_are_checked() {
        let ok = SlurmOptions { partition: Some("batch".into()), time: Some("00:10:00".into()), cpus_per_run: 2, max_parallel: Some(4), bin: "jq".into(), cache: "c".into() };
        ok.check().unwrap();
        let e = |o: SlurmOptions| o.check().unwrap_err().to_string();
        assert!(e(SlurmOptions { cpus_per_run: 0, ..ok.clone() }).contains("--cpus-per-run 0"));
        assert!(e(SlurmOptions { max_parallel: Some(0), ..ok.clone() }).contains("--max-parallel 0"));
        assert!(e(SlurmOptions { partition: Some("a b".into()), ..ok.clone() }).contains("--partition"));
        assert!(e(SlurmOptions { time: Some("10".into()), ..ok.clone() }).contains("--time"));
    }
}
