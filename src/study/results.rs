//! Reading a study's results back, typed, run by run, and writing the report scaffold.
//!
//! Each planned run is one of: finished (its `summary.json` read as a
//! [`RunSummary`](crate::pipeline::RunSummary)), failed (the run stopped with an error:
//! `failed.txt`; its histories end there), or without results (never run, stale because its
//! scene changed after it ran, or a result file that does not parse). Nothing is filled in:
//! a study reads histories by column name ([`HistoryTable`]) and reports what it cannot read,
//! by run, instead of a zero or a NaN.

use super::file::Study;
use super::plan::{load_base, Plan, PlannedRun, PlannedStep, RunFreshness, RunSpec};
use super::{KindReport, StudyKind};
use crate::error::{Error, OutputError};
use crate::output::history::HistoryTable;
use crate::pipeline::RunSummary;
use crate::report::Table;
use crate::scene::Scene;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::PathBuf;

/// What became of a run.
#[derive(Clone, Debug, Serialize)]
#[serde(rename_all = "snake_case", tag = "status", content = "message")]
pub enum RunStatus {
    Finished,
    /// Stopped with this error (its histories end there).
    Failed(String),
    /// No usable result: why.
    Missing(String),
}

/// One run's results.
#[derive(Clone, Debug)]
pub struct RunResult {
    pub spec: RunSpec,
    pub dir: PathBuf,
    /// The run's scene (as planned).
    pub scene: Option<Scene>,
    /// Its summary (finished runs only).
    pub summary: Option<RunSummary>,
    pub status: RunStatus,
}

impl RunResult {
    pub fn id(&self) -> &str {
        &self.spec.id
    }

    /// The history of monitor `name` (`histories/<name>.csv`).
    pub fn history(&self, name: &str) -> Result<HistoryTable, OutputError> {
        HistoryTable::read(&self.dir.join("histories").join(format!("{name}.csv")))
    }

    /// The history of joint `name` (`histories/joint_<name>.csv`).
    pub fn joint_history(&self, name: &str) -> Result<HistoryTable, OutputError> {
        HistoryTable::read(&self.dir.join("histories").join(format!("joint_{name}.csv")))
    }

    /// Whether the run has results to read (finished, or failed with partial histories).
    pub fn has_results(&self) -> bool {
        !matches!(self.status, RunStatus::Missing(_))
    }

    pub fn failed(&self) -> Option<&str> {
        match &self.status {
            RunStatus::Failed(e) => Some(e),
            _ => None,
        }
    }

    fn read(p: &PlannedRun) -> RunResult {
        let scene = Scene::load(&p.scene);
        let failed = p.dir.join("failed.txt");
        let summary = p.dir.join("summary.json");
        let log = p.log();
        let (scene, mut status) = match scene {
            Ok(s) => (Some(s), RunStatus::Finished),
            Err(e) => (None, RunStatus::Missing(format!("its scene cannot be read: {e} (re-run `jointquake study plan`)"))),
        };
        let mut sum = None;
        if matches!(status, RunStatus::Finished) {
            status = match p.freshness() {
                RunFreshness::NotDone if !summary.exists() && !failed.exists() => RunStatus::Missing(if log.exists() {
                    format!("not finished: started (log {}) but no results yet in {}: still running, or killed (out of time or memory)", log.display(), p.dir.display())
                } else {
                    format!("not run (no results in {})", p.dir.display())
                }),
                RunFreshness::Stale => RunStatus::Missing("stale: its scene changed after it ran".into()),
                _ => match std::fs::read_to_string(&failed) {
                    Ok(t) => {
                        let e = t.trim().trim_start_matches("error: ").to_string();
                        RunStatus::Failed(if log.exists() && !e.contains(&*log.to_string_lossy()) { format!("{e} (log {})", log.display()) } else { e })
                    }
                    Err(_) => match RunSummary::read(&summary) {
                        // a run stopped by Ctrl-C or SIGTERM writes its summary marked
                        // `interrupted`: whole outputs up to there, but not a finished run
                        Ok(s) if s.interrupted.is_some() => {
                            let t = s.interrupted.unwrap_or(f64::NAN);
                            sum = Some(s);
                            RunStatus::Failed(format!("interrupted at t = {t} s (Ctrl-C or SIGTERM; log {}): its outputs end there", log.display()))
                        }
                        Ok(s) => {
                            sum = Some(s);
                            RunStatus::Finished
                        }
                        Err(e) => RunStatus::Missing(e.to_string()),
                    },
                },
            };
        }
        RunResult { spec: p.spec.clone(), dir: p.dir.clone(), scene, summary: sum, status }
    }
}

/// A study step's result file, if it is there.
#[derive(Clone, Debug)]
pub struct StepResult {
    pub step: PlannedStep,
    /// The file's text, or why there is none (failed, not run).
    pub text: Result<String, String>,
}

/// Everything a study's report reads.
pub struct StudyResults<'a> {
    pub study: &'a Study,
    pub plan: Plan,
    /// The base scene (absolute paths).
    pub base: Scene,
    pub runs: Vec<RunResult>,
    pub steps: Vec<StepResult>,
}

impl<'a> StudyResults<'a> {
    /// Read the plan of `study` and every run and step it names.
    pub fn read(study: &'a Study) -> Result<StudyResults<'a>, Error> {
        let plan = Plan::read(&study.out)?;
        let base = load_base(study)?;
        let runs = plan.runs.iter().map(RunResult::read).collect();
        let steps = plan
            .steps
            .iter()
            .map(|s| {
                let failed = PathBuf::from(format!("{}.failed.txt", s.output.display()));
                let text = match std::fs::read_to_string(&s.output) {
                    Ok(t) => Ok(t),
                    Err(_) => Err(match std::fs::read_to_string(&failed) {
                        Ok(f) => format!("failed: {}", f.trim().trim_start_matches("error: ")),
                        Err(_) => format!("not run (no {}; see {})", s.output.display(), s.log.display()),
                    }),
                };
                StepResult { step: s.clone(), text }
            })
            .collect();
        Ok(StudyResults { study, plan, base, runs, steps })
    }

    pub fn run(&self, id: &str) -> Option<&RunResult> {
        self.runs.iter().find(|r| r.spec.id == id)
    }

    /// The result of step `name`, typed: `Ok(None)` when it has no result (the reason is in
    /// the report's status section), an error when the file is there but does not parse.
    pub fn step<T: serde::de::DeserializeOwned>(&self, name: &str) -> Result<Option<T>, OutputError> {
        match self.steps.iter().find(|s| s.step.name == name) {
            Some(StepResult { text: Ok(t), step }) => serde_json::from_str(t).map(Some).map_err(|e| OutputError::read(&step.output, format!("not a `{name}` result: {e}"))),
            _ => Ok(None),
        }
    }
}

/// Files and messages of a written report.
#[derive(Clone, Debug, Serialize)]
pub struct ReportFiles {
    pub report: PathBuf,
    pub json: PathBuf,
    pub charts: Vec<PathBuf>,
    /// One-line findings of the study for the terminal.
    pub lines: Vec<String>,
    /// Runs and steps without results, or whose results the study could not read: (id, why).
    pub problems: Vec<(String, String)>,
}

#[derive(Serialize)]
struct RunStatusJson<'a> {
    id: &'a str,
    labels: &'a [(String, String)],
    #[serde(flatten)]
    status: &'a RunStatus,
}

/// Read the results of `study`, let its kind write its part, and write `<out>/report.md` (the
/// kind's Markdown, then the runs and steps without results) and `<out>/report.json`.
pub fn write_report(study: &Study, kind: &dyn StudyKind) -> Result<ReportFiles, Error> {
    let results = StudyResults::read(study)?;
    let KindReport { mut markdown, json, charts, lines, unreadable, lists_failed } = kind.report(&results)?;
    let mut problems: Vec<(String, String)> = Vec::new();
    for r in &results.runs {
        match &r.status {
            RunStatus::Missing(m) => problems.push((r.spec.id.clone(), m.clone())),
            RunStatus::Failed(m) if !lists_failed => problems.push((r.spec.id.clone(), format!("failed: {m}"))),
            _ => {}
        }
    }
    for s in &results.steps {
        if let Err(m) = &s.text {
            problems.push((format!("step {}", s.step.name), m.clone()));
        }
    }
    problems.extend(unreadable);
    if !problems.is_empty() {
        let _ = writeln!(markdown, "\n## Runs without results\n");
        let _ = writeln!(markdown, "These are left out of the tables and charts above; `make -f {} all` runs what is missing.\n", results.plan.out.join("runs.mk").display());
        for (id, why) in &problems {
            let _ = writeln!(markdown, "- `{id}`: {why}");
        }
    }
    let cost = StudyCost::of(&results.runs);
    if cost.runs > 0 {
        let _ = writeln!(markdown, "\n## Cost\n\n{}", cost.to_text());
    }
    let out = &results.plan.out;
    let report = out.join("report.md");
    crate::report::file::write_atomic(&report, markdown.as_bytes())?;
    let status: Vec<RunStatusJson> = results.runs.iter().map(|r| RunStatusJson { id: &r.spec.id, labels: &r.spec.labels, status: &r.status }).collect();
    let doc = serde_json::json!({
        "study": results.plan.study,
        "kind": results.plan.kind,
        "runs": status,
        "problems": problems,
        "cost": cost,
        "report": json,
    });
    let jpath = out.join("report.json");
    crate::report::file::write_atomic(&jpath, serde_json::to_string_pretty(&doc).expect("the report serialises").as_bytes())?;
    Ok(ReportFiles { report, json: jpath, charts, lines, problems })
}

/// What a study's finished runs cost, from their summaries (`wall_time`, `threads`,
/// `provenance`): `report.json` → `cost` and the report's "Cost" section.
#[derive(Clone, Debug, Serialize)]
pub struct StudyCost {
    /// Finished runs counted.
    pub runs: usize,
    /// Sum of their wall times [s].
    pub wall_time: f64,
    /// Sum of wall time × threads [core-s].
    pub core_time: f64,
    /// The longest run's wall time [s].
    pub longest: f64,
    /// Where they ran, and the jointquake builds (version and commit), each once.
    pub hosts: Vec<String>,
    pub builds: Vec<String>,
}

impl StudyCost {
    pub fn of(runs: &[RunResult]) -> StudyCost {
        let mut c = StudyCost { runs: 0, wall_time: 0.0, core_time: 0.0, longest: 0.0, hosts: Vec::new(), builds: Vec::new() };
        for s in runs.iter().filter_map(|r| r.summary.as_ref()) {
            c.runs += 1;
            c.wall_time += s.wall_time;
            c.core_time += s.wall_time * s.threads as f64;
            c.longest = c.longest.max(s.wall_time);
            let (host, build) = match &s.provenance {
                Some(p) => (p.host.clone(), format!("{} ({})", p.version, p.commit)),
                None => ("not recorded".to_string(), "not recorded".to_string()),
            };
            if !c.hosts.contains(&host) {
                c.hosts.push(host);
            }
            if !c.builds.contains(&build) {
                c.builds.push(build);
            }
        }
        c
    }

    /// One paragraph for the report.
    pub fn to_text(&self) -> String {
        let f = |x: f64| crate::report::fmt_sig(x, 4);
        format!(
            "{} finished run{}: {} s of wall time in all ({} core-seconds: wall time × threads; {} h), the longest {} s; on {}; jointquake {}.",
            self.runs,
            if self.runs == 1 { "" } else { "s" },
            f(self.wall_time),
            f(self.core_time),
            f(self.core_time / 3600.0),
            f(self.longest),
            self.hosts.join(", "),
            self.builds.join(", ")
        )
    }
}

/// The table every study can show: each run's status, size, step, wall time and joint maxima.
pub fn run_table(results: &StudyResults) -> Table {
    let mut t = Table::new(["run", "status", "nodes", "elements", "dt [s]", "steps", "wall time [s]", "joint maxima: opening / slip [m]"]);
    let f = |x: f64| crate::report::fmt_sig(x, 4);
    for r in &results.runs {
        let status = match &r.status {
            RunStatus::Finished => "finished".to_string(),
            RunStatus::Failed(e) => format!("failed: {e}"),
            RunStatus::Missing(e) => format!("no results: {e}"),
        };
        let row = match &r.summary {
            Some(s) => {
                let joints = s.joints.iter().map(|j| format!("{} {} / {}", j.name, f(j.max_opening), f(j.max_slip))).collect::<Vec<_>>().join("; ");
                [r.spec.id.clone(), status, s.nodes.to_string(), s.elements.to_string(), crate::report::fmt_sig(s.dt, 3), s.steps.to_string(), f(s.wall_time), joints]
            }
            None => [r.spec.id.clone(), status, "–".into(), "–".into(), "–".into(), "–".into(), "–".into(), "–".into()],
        };
        let _ = t.push_row(row);
    }
    t
}
