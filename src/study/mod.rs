//! The study engine: a study is data over runs.
//!
//! Owns: the study file ([`file`]: a base scene, axes of variation, the runs as their product
//! or a listed union of selections, per-run overrides), the plan ([`plan`]: each run's id,
//! scene and directory, `plan.json`, the Makefile `runs.mk` for `make -j`), the typed reading
//! of results and the report scaffold ([`results`]). It owns no physics and knows no
//! particular study: a study kind ([`StudyKind`], registered in the top-level `studies` module) adds only
//! its metrics, tables and charts, and any steps of its own (the wedge's strength reduction).
//! Two procedures studies call live here too: FEM strength reduction ([`ssr`]) and the
//! rigid-block level of a wedge (`studies::wedge::rigid_level`). [`slurm`] runs a plan's runs as a Slurm job
//! array instead of `make` (`study submit --slurm`).
//!
//! Inputs: a study file (`docs/studies.md`). Outputs under the study's `out`:
//! `scenes/<id>.json`, `plan.json`, `runs.mk`, `runs/<id>/` (one `jointquake run` each),
//! the steps' files, `report.md`, `report.json`, `charts/`.
//! Invariants: a run's scene is a valid [`Scene`](crate::scene::Scene) (every variation is
//! applied to the base scene's JSON and the result deserialised and validated); run ids are
//! unique and file-safe; a result is either read typed or reported missing, never defaulted.

pub mod file;
pub mod plan;
pub mod results;
pub mod slurm;
pub mod ssr;

pub use file::{Study, Variation};
pub use plan::{plan_runs, scene_for, write_plan, Plan, RunSpec};
pub use results::{write_report, RunResult, RunStatus, StudyResults};

use crate::error::{Error, StudyError};
use std::path::{Path, PathBuf};

/// A step of a study that is not a scene run (e.g. strength reduction): run by
/// `jointquake study step STUDY NAME`, which writes `<out>/<output>`; `runs.mk` has a target
/// for it.
#[derive(Clone, Debug)]
pub struct StepSpec {
    pub name: String,
    /// Result file, relative to the study's output directory.
    pub output: String,
    /// One line printed by `make` when the step starts.
    pub about: String,
}

/// Options of a step.
#[derive(Clone, Debug)]
pub struct StepOptions {
    pub mesh_cache: PathBuf,
}

/// What a step produced: the JSON written to its output file, and lines for the terminal.
pub struct StepOutput {
    pub json: serde_json::Value,
    pub lines: Vec<String>,
}

/// A study kind's part of the report.
#[derive(Default)]
pub struct KindReport {
    /// Markdown of `report.md` (the engine appends the runs without results).
    pub markdown: String,
    /// The kind's numbers for `report.json`.
    pub json: serde_json::Value,
    /// Charts written (PNG paths; an SVG next to each).
    pub charts: Vec<std::path::PathBuf>,
    /// One-line findings for the terminal.
    pub lines: Vec<String>,
    /// Runs whose results the kind could not read or use: (id, why).
    pub unreadable: Vec<(String, String)>,
    /// Whether the markdown already lists the failed runs with their errors (else the engine
    /// lists them with the runs without results).
    pub lists_failed: bool,
}

/// Charts of one run (e.g. the demo's run of the wedge).
pub struct RunCharts {
    pub charts: Vec<PathBuf>,
    pub lines: Vec<String>,
}

/// What a study kind adds to the engine: its metrics, tables and charts, and its own steps.
/// Its parameters are the study file's `report` object (without `kind`).
pub trait StudyKind {
    /// Check the study against what the kind needs (axes it reads, joints, monitors) at plan
    /// time, so that a study that cannot be reported is refused before its runs.
    fn check(&self, _study: &Study) -> Result<(), Error> {
        Ok(())
    }

    /// Steps of the study besides its runs.
    fn steps(&self) -> Vec<StepSpec> {
        Vec::new()
    }

    /// Run step `name`.
    fn run_step(&self, study: &Study, name: &str, _opts: &StepOptions) -> Result<StepOutput, Error> {
        Err(StudyError::Invalid { path: study.path.clone(), message: format!("a study of kind \"{}\" has no step \"{name}\"", study.kind) }.into())
    }

    /// The kind's report from the study's results.
    fn report(&self, results: &StudyResults) -> Result<KindReport, Error>;

    /// Charts of one run of the study's model (`study chart`).
    fn run_charts(&self, study: &Study, _scene: &Path, _run_dir: &Path) -> Result<RunCharts, Error> {
        Err(StudyError::Invalid { path: study.path.clone(), message: format!("a study of kind \"{}\" has no per-run charts", study.kind) }.into())
    }
}

/// Run step `name` of `study` and write its output file.
pub fn run_step(study: &Study, kind: &dyn StudyKind, name: &str, opts: &StepOptions) -> Result<(PathBuf, StepOutput), Error> {
    let spec = kind.steps().into_iter().find(|s| s.name == name).ok_or_else(|| {
        let known: Vec<String> = kind.steps().into_iter().map(|s| s.name).collect();
        Error::from(StudyError::Invalid { path: study.path.clone(), message: format!("no step \"{name}\" (steps of a {} study: {})", study.kind, if known.is_empty() { "none".into() } else { known.join(", ") }) })
    })?;
    let out = kind.run_step(study, name, opts)?;
    std::fs::create_dir_all(&study.out).map_err(|e| crate::error::OutputError::write(&study.out, e))?;
    let p = study.out.join(&spec.output);
    crate::report::file::write_atomic(&p, serde_json::to_string_pretty(&out.json).expect("a step result serialises").as_bytes())?;
    Ok((p, out))
}

/// Parse a kind's parameters (the study file's `report` object) with the file and the kind in
/// the error.
pub fn kind_params<T: serde::de::DeserializeOwned>(study: &Study) -> Result<T, StudyError> {
    serde_json::from_value(serde_json::Value::Object(study.params.clone()))
        .map_err(|e| StudyError::Invalid { path: study.path.clone(), message: format!("`report` (kind \"{}\"): {e} (docs/studies.md lists its fields)", study.kind) })
}
