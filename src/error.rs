//! Typed errors of the library, one enum per stage, gathered in [`Error`].
//!
//! Every variant carries what the user must fix: the file, the physical group,
//! the element, the line, and where possible the fix itself. `anyhow` context is
//! added only in `main.rs`.

use std::path::PathBuf;
use thiserror::Error;

/// Any failure of a jointquake stage.
#[derive(Debug, Error)]
pub enum Error {
    #[error(transparent)]
    Mesh(#[from] MeshError),
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error(transparent)]
    Record(#[from] RecordError),
    #[error(transparent)]
    Model(#[from] ModelError),
    #[error(transparent)]
    Step(#[from] StepError),
    #[error(transparent)]
    Gmsh(#[from] GmshError),
    #[error(transparent)]
    Interface(#[from] InterfaceError),
    #[error(transparent)]
    Output(#[from] OutputError),
    #[error(transparent)]
    Rigid(#[from] crate::rigid::RigidError),
    #[error(transparent)]
    Report(#[from] ReportError),
    #[error(transparent)]
    Study(#[from] StudyError),
    #[error(transparent)]
    Case(#[from] CaseError),
    /// Ctrl-C, SIGTERM or SIGHUP ended a phase (`crate::interrupt`): not a failure.
    #[error(transparent)]
    Interrupted(#[from] crate::interrupt::Interrupted),
}

impl Error {
    /// The interrupted phase, when a signal (not the input) ended this stage: an
    /// [`Error::Interrupted`], or one raised inside a loop that returns a stage's own error.
    pub fn interrupted(&self) -> Option<&crate::interrupt::Interrupted> {
        match self {
            Error::Interrupted(i) | Error::Step(StepError::Interrupted(i)) | Error::Gmsh(GmshError::Interrupted(i)) => Some(i),
            _ => None,
        }
    }
}

/// Reading a `.msh` file or looking up its parts.
#[derive(Debug, Error)]
pub enum MeshError {
    #[error("cannot read mesh file {path}: {source}. Check the path (`geometry.msh` in a scene is relative to the scene file).")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("{path} is not a valid MSH 4.1 file: {reason}. Re-export it from Gmsh with `-format msh41` (ASCII or binary).")]
    Malformed { path: PathBuf, reason: String },
    #[error("{path}: element {element} has unsupported type {kind}. jointquake reads tet4 and hex8 volumes, tri3 and quad4 faces; mesh with first-order elements (`-order 1`).")]
    UnsupportedElement { path: PathBuf, element: u64, kind: String },
    #[error("{path}: element {element} refers to node {node}, which is not in the $Nodes section")]
    MissingNode { path: PathBuf, element: u64, node: u64 },
    #[error("{}", unknown_group_text(name, *dim, available))]
    UnknownGroup { name: String, dim: Option<usize>, available: Vec<String> },
    #[error("{path}: physical group \"{group}\": element {element} is inverted (Jacobian {jacobian:.3e} at a corner). Fix the node order or the geometry orientation in the .geo (e.g. `ReverseMesh`).")]
    InvertedElement { path: PathBuf, group: String, element: u64, jacobian: f64 },
    #[error("{path}: node {node} has a non-finite coordinate")]
    NonFiniteNode { path: PathBuf, node: u64 },
}

/// Loading and validating a scene file.
#[derive(Debug, Error)]
pub enum SceneError {
    #[error("cannot read scene file {path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("scene {path}: {message}")]
    Parse { path: PathBuf, message: String },
    #[error("scene {path}: {message}")]
    Invalid { path: PathBuf, message: String },
}

/// Reading an acceleration record.
#[derive(Debug, Error)]
pub enum RecordError {
    #[error("cannot read record {path}: {source}. Check the `record` path in the scene (relative paths are relative to the scene file).")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("record {path}, line {line}: {message}")]
    Line { path: PathBuf, line: usize, message: String },
    #[error("record {path}: {message}")]
    Invalid { path: PathBuf, message: String },
}

/// Building the model (materials, elements, boundary conditions, loads).
#[derive(Debug, Error)]
pub enum ModelError {
    #[error("{0}")]
    Invalid(String),
    #[error("time step dt = {dt:.4e} s is above the stability limit {limit:.4e} s (critical element {element} in group \"{group}\"). Use dt <= {limit:.4e} s or `\"courant\": 0.9` in the scene's time section.")]
    UnstableStep { dt: f64, limit: f64, element: u64, group: String },
}

/// Failure during time stepping.
#[derive(Debug, Error)]
pub enum StepError {
    #[error("non-finite {what} at step {step} (t = {t:.6} s), node {node} at ({:.3}, {:.3}, {:.3}). Likely cause: {cause}", x[0], x[1], x[2])]
    NonFinite { what: String, step: usize, t: f64, node: usize, x: [f64; 3], cause: String },
    #[error("energy balance lost at step {step} (t = {t:.6} s): error {error:.3e} of the energy scale, limit {limit:.1e}. Largest velocity at node {node} at ({:.3}, {:.3}, {:.3}). Likely cause: {cause}", x[0], x[1], x[2])]
    EnergyGrowth { step: usize, t: f64, error: f64, limit: f64, node: usize, x: [f64; 3], cause: String },
    #[error("{0}")]
    Contact(String),
    /// Reconstructing the massless foundation's displacements (out of memory for the solve).
    #[error("massless foundation: {0}")]
    Foundation(String),
    /// Ctrl-C or SIGTERM during an iterative static or relaxation loop (`crate::interrupt`).
    #[error(transparent)]
    Interrupted(#[from] crate::interrupt::Interrupted),
}

/// Running the gmsh command line.
#[derive(Debug, Error)]
pub enum GmshError {
    #[error("cannot start gmsh ({exe}): {source}. Run `make venv` to install the gmsh wheel into .venv, or set GMSH=/path/to/gmsh.")]
    Spawn { exe: String, source: std::io::Error },
    #[error("gmsh failed on {geo} (log: {log}):\n{message}")]
    Failed { geo: PathBuf, log: PathBuf, message: String },
    #[error("geometry file {path} does not exist")]
    MissingGeo { path: PathBuf },
    #[error("cannot write {path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    /// Ctrl-C or SIGTERM while gmsh ran: the child was ended (`crate::interrupt`).
    #[error(transparent)]
    Interrupted(#[from] crate::interrupt::Interrupted),
}

/// Building joint interfaces (tagger).
#[derive(Debug, Error)]
pub enum InterfaceError {
    #[error("joint \"{joint}\": {message}")]
    Invalid { joint: String, message: String },
    #[error(transparent)]
    Mesh(#[from] MeshError),
}

/// Loading a study file or planning its runs (the `study` module): names the study file and the
/// field (or the run) to fix.
#[derive(Debug, Error)]
pub enum StudyError {
    #[error("cannot read study file {path}: {message}")]
    Io { path: PathBuf, message: String },
    #[error("study {path}: {message}")]
    Invalid { path: PathBuf, message: String },
    /// `study submit --slurm`: an option, or `sbatch`.
    #[error("study submit --slurm: {0}")]
    Slurm(String),
}

/// A generated joint test case (`testcase` module): names the option to fix.
#[derive(Debug, Error)]
pub enum CaseError {
    #[error("testcase: option `{option}`: {message}")]
    Invalid { option: String, message: String },
}

/// Writing results.
#[derive(Debug, Error)]
pub enum OutputError {
    #[error("cannot write {path}: {message}")]
    Write { path: PathBuf, message: String },
    #[error("cannot read {path}: {message}. Run the stage that writes it first (see docs/cli.md).")]
    Read { path: PathBuf, message: String },
}

impl OutputError {
    pub fn write(path: impl Into<PathBuf>, e: impl std::fmt::Display) -> Self {
        OutputError::Write { path: path.into(), message: e.to_string() }
    }
    /// A result file of an earlier stage that cannot be read.
    pub fn read(path: impl Into<PathBuf>, e: impl std::fmt::Display) -> Self {
        OutputError::Read { path: path.into(), message: e.to_string() }
    }
}

/// Building study reports: charts (PNG + SVG) and Markdown tables (module `report`).
///
/// Chart variants name the chart by its title and the series by its name; point indices
/// are 0-based positions in `report::Series::points`.
#[derive(Debug, Error)]
pub enum ReportError {
    #[error("chart \"{chart}\": series \"{series}\", point {index} = ({x}, {y}) is not finite. Drop the point (a failed run?) or replace it before charting.")]
    NonFinite { chart: String, series: String, index: usize, x: f64, y: f64 },
    #[error("chart \"{chart}\": series \"{series}\", point {index} = ({x}, {y}) has {axis} <= 0, which a logarithmic {axis} axis cannot show. Use a linear {axis} axis, or drop or offset the point.")]
    NonPositiveOnLog { chart: String, series: String, index: usize, x: f64, y: f64, axis: char },
    #[error("chart \"{chart}\": series \"{series}\" has {labels} point labels for {points} points; give one label per point (an empty string draws none).")]
    LabelCount { chart: String, series: String, labels: usize, points: usize },
    #[error("chart \"{chart}\": no points to chart and no explicit x_range and y_range. Add a series with points or set both ranges.")]
    NoData { chart: String },
    #[error("chart \"{chart}\": {axis} range ({lo}, {hi}) is invalid: {reason}")]
    InvalidRange { chart: String, axis: char, lo: f64, hi: f64, reason: String },
    #[error("chart \"{chart}\": size {width} x {height} px is too small; use at least {min} x {min} px.")]
    InvalidSize { chart: String, width: u32, height: u32, min: u32 },
    #[error("chart \"{chart}\": drawing {target} failed: {message}")]
    Draw { chart: String, target: String, message: String },
    #[error("cannot write {path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("the embedded chart font {font} is not a valid TrueType font (a corrupt assets/fonts checkout?)")]
    Font { font: String },
    #[error("table row {row} has {cells} cells but the header has {columns} columns; give one cell per column (an empty string for a blank cell).")]
    RowWidth { row: usize, cells: usize, columns: usize },
    #[error("table alignment has {given} entries but the header has {columns} columns; give one alignment per column.")]
    AlignWidth { given: usize, columns: usize },
}

/// Message of [`MeshError::UnknownGroup`]: a name that is not in the mesh, or a name that is
/// there with another dimension (then the message says which dimension is needed and why).
fn unknown_group_text(name: &str, dim: Option<usize>, available: &[String]) -> String {
    let list = available.join(", ");
    let prefix = format!("\"{name}\" (dim ");
    let other_dims: Vec<&str> = available.iter().filter_map(|a| a.strip_prefix(&prefix)).map(|r| r.trim_end_matches(')')).collect();
    match dim {
        Some(d) if !other_dims.is_empty() => {
            let kind = match d {
                3 => "a volume group (tet4/hex8 elements)",
                2 => "a face group (tri3/quad4 elements)",
                1 => "a curve group",
                _ => "a point group",
            };
            format!(
                "physical group \"{name}\" has dimension {}, but {kind} of dimension {d} is needed here. Groups in the mesh: {list}",
                other_dims.join(" and ")
            )
        }
        Some(d) => format!("unknown physical group \"{name}\" of dimension {d}. Groups in the mesh: {list}"),
        None => format!("unknown physical group \"{name}\". Groups in the mesh: {list}"),
    }
}

pub type Result<T, E = Error> = std::result::Result<T, E>;
