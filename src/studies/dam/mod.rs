//! The arch dam study (seed paper section 5): the 28 contraction joints' opening and slip and
//! the face stresses at 1×, 2×, 3× the design PGA with NTS and NTN, the monolithic dam, the
//! coarse mesh and NTS-Layer2 as cheaper or reference levels.
//!
//! Its runs are plain study-file data (`pipelines/dam_study.json`); this module reads each run
//! through the typed readers and makes the tables and charts ([`report`]).
//!
//! What it reads from a run: its level (the run's PGA over `design_pga`), its mesh label
//! (`mesh_axis`), its method from its scene's contraction-joint entry (`joints`: tied → the
//! monolithic dam; `ntn` → NTN; `nts` with `layer` 2 → NTS-Layer2, else NTS), per joint the
//! largest opening, net slip and slip path over the record (`histories/joint_<J>.csv`, columns
//! `max_opening`, `max_tangential_displacement` = the net slip |d_t| the report calls "slip",
//! `max_slip` = the path Σ|Δd_t|: also for a run that stopped, up to where it stopped), the search
//! and Gauss–Seidel diagnostics per joint (`summary.json`), the face stress envelopes
//! (`envelope.json`, [`crate::output::envelope`]) and the crest monitors' histories.
//!
//! Conventions: joints numbered 1… in the natural order of their names (J01 … J28, from the
//! left bank); opening and slip in m (reported in mm); stresses in Pa (reported in MPa),
//! tension positive; crest radial displacement positive downstream, along the horizontal
//! normal of the upstream crest arch y = x² / (2 Rc) at the monitor, (−x/Rc, 1, 0) normalised.

pub mod convergence;
pub mod decay;
pub mod face_maps;
pub mod joint_maps;
pub mod models_table;
pub mod paraview_state;
pub mod reference;
pub mod report;
pub mod static_table;

use crate::error::{Error, OutputError, StudyError};
use crate::mesh::pattern::{GroupPattern, natural_cmp};
use crate::output::envelope::{Extreme, FaceEnvelope, OBJECTIVE_BAND, ObjectiveStress, StressEnvelope, TENSION_THRESHOLDS};
use crate::output::linearise::{LinearisedEnvelope, LinearisedExtremes};
use crate::output::history::HistoryTable;
use crate::scene::{ContactMethod, Scene};
use crate::study::{KindReport, RunResult, Study, StudyKind, StudyResults, kind_params};
use serde::{Deserialize, Serialize};

/// The dam study's parameters: the study file's `report` object (`"kind": "dam"`).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct DamParams {
    /// Design PGA [g]; a run's level is its PGA over it. Default 0.5575 (the seed's dam).
    #[serde(default = "design_pga")]
    pub design_pga: f64,
    /// Name of the scene's joint entry of the contraction joints (a pattern: `J{J}`).
    #[serde(default = "joint_entry")]
    pub joints: String,
    /// The axis of mesh levels and the label of the main mesh.
    #[serde(default = "mesh_axis")]
    pub mesh_axis: String,
    pub main_mesh: String,
    /// Face groups of the stress envelopes.
    #[serde(default)]
    pub faces: Faces,
    /// The scene's crest monitors.
    #[serde(default)]
    pub monitors: Monitors,
    /// Crown radius Rc [m] of the upstream crest arch y = x² / (2 Rc) (the radial direction).
    /// Default 270 (`geo/arch_dam.geo`).
    #[serde(default = "crest_radius")]
    pub crest_radius: f64,
    /// Material group of the rock, hidden in the ParaView state of the run with frames
    /// (`paraview_state`). Default `block:rock` (`geo/arch_dam.geo`).
    #[serde(default = "rock")]
    pub rock: String,
    /// Relative error within which a cheaper level "is enough". Default 0.10.
    #[serde(default = "enough")]
    pub enough: f64,
    /// The seed paper's numbers the tables compare with.
    pub seed: SeedNumbers,
    /// Free-vibration runs after a pulse (f1 and the first mode's damping per model,
    /// [`models_table`]). Default: none (no run is a pulse run).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pulse: Option<PulseParams>,
    /// Representative element size h [m] of each mesh label (the dam's `h`), for the
    /// convergence study's extrapolation ([`reference`]). Default: none.
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub mesh_sizes: std::collections::BTreeMap<String, f64>,
    /// The extrapolated reference the report's verdicts and speed-against-accuracy chart read
    /// (`jointquake study extrapolate`, [`reference::DamReference`]), relative to the study
    /// file. Default: none (the report then judges without error bands and says so).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference: Option<std::path::PathBuf>,
}

/// The study's free-vibration runs: which runs they are and where their decay is fitted
/// ([`decay`]).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PulseParams {
    /// The axis label of the pulse runs (a value of any axis, e.g. of `level`, that replaces the
    /// records by a pulse and sets no `pga`).
    pub label: String,
    /// Start of the fitted window [s]: after the pulse has passed the dam (its length plus,
    /// for a radiating rock, the free field's delay). Default 1.2 (the 0.6 s pulse of
    /// pipelines/records/pulse_sin4_T0.6.txt, the 0.285 s delay of the dam's 630 m column and
    /// 0.3 s for the rock's scattered waves to leave).
    #[serde(default = "pulse_start")]
    pub start: f64,
    /// Band searched for f1 [Hz]. Default [0.4, 2.5]: the dam's first mode, 0.88 Hz full to
    /// 1.37 Hz empty (docs/dam.md "Modes"), with room either side.
    #[serde(default = "pulse_band")]
    pub band: [f64; 2],
}

fn pulse_start() -> f64 {
    1.2
}
fn pulse_band() -> [f64; 2] {
    [0.4, 2.5]
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Faces {
    pub upstream: String,
    pub downstream: String,
}

impl Default for Faces {
    fn default() -> Self {
        Faces {
            upstream: "face:upstream".into(),
            downstream: "face:downstream".into(),
        }
    }
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Monitors {
    pub crown: String,
    pub quarter_left: String,
    pub quarter_right: String,
    /// The dam's foot under the crown (on the rock's side of the base): the pulse runs' crown
    /// motion is taken relative to it (a radiating rock's displacements are total, and with
    /// dashpots alone it may drift as a whole). Default "dam_foot"; only the pulse runs need it.
    #[serde(default = "foot")]
    pub foot: String,
}

fn foot() -> String {
    "dam_foot".into()
}

impl Default for Monitors {
    fn default() -> Self {
        Monitors {
            crown: "crest_crown".into(),
            quarter_left: "crest_quarter_left".into(),
            quarter_right: "crest_quarter_right".into(),
            foot: foot(),
        }
    }
}

/// The seed's published values (Zhong 2022, section 5), in the units it gives them.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SeedNumbers {
    /// Where the numbers come from.
    pub source: String,
    /// Levels (× design PGA) of the opening values.
    pub levels: Vec<f64>,
    /// Largest joint opening over all joints per level [mm].
    pub opening_nts_mm: Vec<f64>,
    pub opening_ntn_mm: Vec<f64>,
    /// NTS's largest slip over NTN's at the highest level, minus 1 (0.088: NTS 8.8 % above).
    pub slip_nts_over_ntn: f64,
    /// Largest principal tension and compression at the highest level [MPa].
    pub tension_nts_mpa: f64,
    pub tension_ntn_mpa: f64,
    pub compression_nts_mpa: f64,
    pub compression_ntn_mpa: f64,
}

fn design_pga() -> f64 {
    0.5575
}
fn joint_entry() -> String {
    "J{J}".into()
}
fn mesh_axis() -> String {
    "mesh".into()
}
fn crest_radius() -> f64 {
    270.0
}
fn rock() -> String {
    "block:rock".into()
}
fn enough() -> f64 {
    0.10
}

/// The contact model of a run's contraction joints.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
pub enum Method {
    #[serde(rename = "NTS")]
    Nts,
    #[serde(rename = "NTN")]
    Ntn,
    #[serde(rename = "NTS-Layer2")]
    NtsLayer2,
    #[serde(rename = "monolithic")]
    Monolithic,
    #[serde(rename = "penalty")]
    Penalty,
    #[serde(rename = "mortar")]
    Mortar,
}

impl Method {
    pub fn name(self) -> &'static str {
        match self {
            Method::Nts => "NTS",
            Method::Ntn => "NTN",
            Method::NtsLayer2 => "NTS-Layer2",
            Method::Monolithic => "monolithic",
            Method::Penalty => "penalty",
            Method::Mortar => "mortar",
        }
    }
}

/// Search and Gauss–Seidel diagnostics of one joint over a run (`summary.json`).
#[derive(Clone, Debug, Default, Serialize)]
pub struct JointDiagnostics {
    pub lost: u64,
    /// Of `lost`, the node-steps beyond the master's free edge (a note; the rest, lost inside
    /// its outline, are the warning's: `output::recorder::LOST_WARN_FRACTION`).
    pub lost_beyond_edge: u64,
    /// The joint's slave nodes (the scale of the lost fraction).
    pub slave_nodes: usize,
    pub widened_layer2: u64,
    pub fresh_searches: u64,
    pub max_sweeps: usize,
    pub unconverged_steps: u64,
}

/// The face stresses of one run: the envelope's extremes per face.
#[derive(Clone, Debug, Serialize)]
pub struct FaceStress {
    pub upstream_tension: Extreme,
    pub upstream_compression: Extreme,
    pub downstream_tension: Extreme,
    pub downstream_compression: Extreme,
    /// The mesh-objective stress of each face: outside [`OBJECTIVE_BAND`] of the contact with
    /// the rock (`None`: an envelope without face corners).
    pub upstream_objective: Option<ObjectiveStress>,
    pub downstream_objective: Option<ObjectiveStress>,
    /// Per threshold of [`TENSION_THRESHOLDS`]: (threshold [Pa], upstream area, downstream
    /// area [m²]) of the faces whose σ1 exceeded it.
    pub areas_above: Vec<(f64, f64, f64)>,
    /// The stresses linearised through the thickness (`None`: an envelope without them).
    pub linearised: Option<LinearisedStress>,
}

/// The arch and cantilever stresses linearised through the thickness from the upstream to the
/// downstream face ([`crate::output::linearise`]): extremes over all cuts, and over the cuts
/// whose upstream face is outside [`OBJECTIVE_BAND`] of the rock ("start" = upstream, "end" =
/// downstream).
#[derive(Clone, Debug, Serialize)]
pub struct LinearisedStress {
    pub arch: LinearisedExtremes,
    pub cantilever: LinearisedExtremes,
    pub arch_outside_band: Option<LinearisedExtremes>,
    pub cantilever_outside_band: Option<LinearisedExtremes>,
    /// Cuts made, and upstream faces without a cut (less than `MIN_COVERAGE` in the dam).
    pub cuts: usize,
    pub dropped: usize,
}

impl LinearisedStress {
    /// From the envelope's linearised part; `upstream` is the cuts' `from` face group.
    fn of(l: &LinearisedEnvelope, upstream: &FaceEnvelope) -> Option<LinearisedStress> {
        let band = (upstream.corners.len() == upstream.elements.len() && !upstream.corners.is_empty()).then(|| upstream.in_band(OBJECTIVE_BAND));
        let outside = |arch: bool| band.as_ref().and_then(|b| l.extremes(arch, |f| !b[f]));
        Some(LinearisedStress {
            arch: l.extremes(true, |_| true)?,
            cantilever: l.extremes(false, |_| true)?,
            arch_outside_band: outside(true),
            cantilever_outside_band: outside(false),
            cuts: l.cuts.len(),
            dropped: l.dropped,
        })
    }
}

impl FaceStress {
    /// From a run's `envelope.json` (`dir` is the run directory).
    fn read(p: &DamParams, dir: &std::path::Path) -> Result<FaceStress, Error> {
        let env = StressEnvelope::read(dir)?;
        let face = |g: &str| {
            env.face(g).ok_or_else(|| OutputError::read(dir.join("envelope.json"), format!("no envelope of face group \"{g}\" (the scene's `output.envelope.faces` must name it)")))
        };
        let (u, d) = (face(&p.faces.upstream)?, face(&p.faces.downstream)?);
        Ok(FaceStress {
            upstream_tension: u.max_tension.clone(),
            upstream_compression: u.max_compression.clone(),
            downstream_tension: d.max_tension.clone(),
            downstream_compression: d.max_compression.clone(),
            upstream_objective: u.objective(OBJECTIVE_BAND),
            downstream_objective: d.objective(OBJECTIVE_BAND),
            areas_above: TENSION_THRESHOLDS.iter().map(|&t| (t, u.area_above(t), d.area_above(t))).collect(),
            linearised: env.linearised.as_ref().filter(|l| l.from == p.faces.upstream).and_then(|l| LinearisedStress::of(l, u)),
        })
    }

    /// Largest tension over both faces [Pa].
    pub fn tension(&self) -> f64 {
        self.upstream_tension
            .value
            .max(self.downstream_tension.value)
    }
    /// Most compressive σ3 over both faces [Pa] (negative).
    pub fn compression(&self) -> f64 {
        self.upstream_compression
            .value
            .min(self.downstream_compression.value)
    }
    /// Largest tension over both faces outside the band [Pa].
    pub fn objective_tension(&self) -> Option<f64> {
        let (u, d) = (self.upstream_objective.as_ref()?, self.downstream_objective.as_ref()?);
        Some(u.max_tension.max(d.max_tension))
    }
    /// Most compressive σ3 over both faces outside the band [Pa] (negative).
    pub fn objective_compression(&self) -> Option<f64> {
        let (u, d) = (self.upstream_objective.as_ref()?, self.downstream_objective.as_ref()?);
        Some(u.max_compression.min(d.max_compression))
    }
}

/// What the report uses of one run.
#[derive(Clone, Debug, Serialize)]
pub struct DamRun {
    pub id: String,
    pub method: Method,
    /// The reservoir model of its scene ([`reservoir_label`]) and its foundation model.
    pub reservoir: String,
    pub foundation: String,
    /// A free-vibration run after a pulse (`report.pulse`): level 0, read by the models table
    /// only.
    pub pulse: bool,
    /// PGA over the design PGA.
    pub level: f64,
    pub mesh: String,
    /// Wall time [s] (finished runs).
    pub wall_time: Option<f64>,
    /// The error of a run that stopped (its histories end there).
    pub failed: Option<String>,
    /// Record time reached [s] (last joint-history row).
    pub t_end: f64,
    pub joints: Vec<String>,
    /// Per joint: largest opening and largest net slip |d_t| over the record [m] (design §7:
    /// slip is the net tangential displacement, as the seed's "maximum tangential slip").
    pub opening: Vec<f64>,
    pub slip: Vec<f64>,
    /// Per joint: largest slip path Σ|Δd_t| over the record [m] (the second slip column).
    pub slip_path: Vec<f64>,
    /// Per joint (finished runs).
    pub diagnostics: Option<Vec<JointDiagnostics>>,
    /// From `envelope.json` (finished runs that asked for it).
    pub stress: Option<FaceStress>,
    /// Crest radial displacement histories (crown, left and right quarter points): (t, u_r) [s, m].
    #[serde(skip)]
    pub crest: Vec<(String, Vec<(f64, f64)>)>,
    /// Pulse runs: the crown monitor's cross-stream displacement relative to the dam's foot,
    /// (t, u_x − u_x,foot) [s, m] (the antisymmetric first mode moves the crown along the
    /// crest; the decay is fitted to it). Empty for the other runs.
    #[serde(skip)]
    pub crown_x: Vec<(f64, f64)>,
    /// The opening history (largest over the joint) of the joint with the largest opening.
    #[serde(skip)]
    pub worst_joint_history: Vec<(f64, f64)>,
}

impl DamRun {
    pub fn max_opening(&self) -> (usize, f64) {
        argmax(&self.opening)
    }
    pub fn max_slip(&self) -> (usize, f64) {
        argmax(&self.slip)
    }
    pub fn max_slip_path(&self) -> (usize, f64) {
        argmax(&self.slip_path)
    }
    /// Largest |u_r| of the crest monitors over the record [m].
    pub fn max_crest(&self) -> f64 {
        self.crest.iter().flat_map(|(_, h)| h.iter().map(|(_, u)| u.abs())).fold(0.0, f64::max)
    }
    pub fn is_main(&self, p: &DamParams) -> bool {
        self.mesh == p.main_mesh
    }
    /// The seed's model (westergaard reservoir, massless rock) under an earthquake: the runs
    /// every section but the models table reads.
    pub fn is_seed_model(&self) -> bool {
        !self.pulse && self.reservoir == SEED_RESERVOIR && self.foundation == SEED_FOUNDATION
    }
}

/// The seed's reservoir and foundation models (the scene defaults).
pub const SEED_RESERVOIR: &str = "westergaard";
pub const SEED_FOUNDATION: &str = "massless";

/// The reservoir model of a scene: `"none"` without a reservoir, `"empty"` without its added
/// mass, `"westergaard_local"` for Westergaard with each section's depth (either spelling),
/// else the model's name.
pub fn reservoir_label(scene: &Scene) -> String {
    use crate::scene::reservoir::ReservoirModel;
    match &scene.reservoir {
        None => "none".into(),
        Some(r) if !r.added_mass => "empty".into(),
        Some(r) if r.model == ReservoirModel::Westergaard && r.added_mass_depth == crate::scene::AddedMassDepth::Local => ReservoirModel::WestergaardLocal.name().into(),
        Some(r) => r.model.name().into(),
    }
}

/// (index, value) of the largest value (the first on ties; (0, −∞) when empty).
pub fn argmax(v: &[f64]) -> (usize, f64) {
    v.iter().copied().enumerate().fold(
        (0, f64::NEG_INFINITY),
        |a, (i, x)| if x > a.1 { (i, x) } else { a },
    )
}

pub struct DamKind {
    pub params: DamParams,
    /// `params.reference` resolved against the study file's directory.
    pub reference_path: Option<std::path::PathBuf>,
}

impl DamKind {
    pub fn new(study: &Study) -> Result<DamKind, Error> {
        let params: DamParams = kind_params(study)?;
        let dir = study.path.parent().unwrap_or(std::path::Path::new("."));
        let reference_path = params.reference.as_ref().map(|r| dir.join(r));
        let k = DamKind { params, reference_path };
        k.check(study)?;
        Ok(k)
    }

    /// The contact model of a scene's contraction joints.
    fn method_of(&self, scene: &Scene) -> Result<Method, String> {
        let j = scene
            .joints
            .iter()
            .find(|j| j.name == self.params.joints)
            .ok_or_else(|| {
                format!(
                    "its scene has no joint entry \"{}\" (entries: {})",
                    self.params.joints,
                    scene
                        .joints
                        .iter()
                        .map(|j| j.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            })?;
        Ok(
            match (
                j.tied.unwrap_or(false),
                j.method.unwrap_or(ContactMethod::Nts),
                j.layer.unwrap_or(1),
            ) {
                (true, _, _) => Method::Monolithic,
                (false, ContactMethod::Ntn, _) => Method::Ntn,
                (false, ContactMethod::Penalty, _) => Method::Penalty,
                (false, ContactMethod::Mortar, _) => Method::Mortar,
                (false, ContactMethod::Nts, 2) => Method::NtsLayer2,
                (false, ContactMethod::Nts, _) => Method::Nts,
            },
        )
    }

    /// The contraction joints' names in a run directory (from its joint histories), in natural order.
    fn joint_names(&self, r: &RunResult) -> Result<Vec<String>, OutputError> {
        let pat = GroupPattern::parse(&self.params.joints).map_err(|e| {
            OutputError::read(
                &r.dir,
                format!("`joints` = \"{}\": {e}", self.params.joints),
            )
        })?;
        let dir = r.dir.join("histories");
        let rd = std::fs::read_dir(&dir).map_err(|e| OutputError::read(&dir, e))?;
        let mut names: Vec<String> = rd
            .filter_map(|e| e.ok())
            .filter_map(|e| {
                e.file_name()
                    .to_str()
                    .and_then(|n| n.strip_prefix("joint_"))
                    .and_then(|n| n.strip_suffix(".csv"))
                    .map(str::to_string)
            })
            .filter(|n| matches!(pat.match_name(n), Ok(Some(_))))
            .collect();
        names.sort_by(|a, b| natural_cmp(a, b));
        if names.is_empty() {
            return Err(OutputError::read(
                &dir,
                format!("no joint history matches \"{}\"", self.params.joints),
            ));
        }
        Ok(names)
    }

    /// Crest radial displacement of monitor `name`: (t, u · n_r).
    fn crest_history(&self, r: &RunResult, name: &str) -> Result<Vec<(f64, f64)>, OutputError> {
        let h: HistoryTable = r.history(name)?;
        let pos = r.summary.as_ref().and_then(|s| {
            s.monitors
                .iter()
                .find(|m| m.name == name)
                .map(|m| m.position)
        });
        let x = match (
            pos,
            r.scene
                .as_ref()
                .and_then(|s| s.output.monitor.iter().find(|m| m.name == name)),
        ) {
            (Some(p), _) => p[0],
            (None, Some(m)) => m.point[0],
            (None, None) => {
                return Err(OutputError::read(
                    &h.path,
                    format!("the run's scene has no monitor \"{name}\""),
                ));
            }
        };
        let (nx, ny) = (-x / self.params.crest_radius, 1.0);
        let n = nx.hypot(ny);
        let (t, ux, uy) = (h.column("t")?, h.column("ux")?, h.column("uy")?);
        Ok((0..h.len())
            .map(|i| (t[i], (ux[i] * nx + uy[i] * ny) / n))
            .collect())
    }

    /// Read one run.
    pub fn run(&self, r: &RunResult) -> Result<DamRun, Error> {
        let p = &self.params;
        let scene = r
            .scene
            .as_ref()
            .ok_or_else(|| OutputError::read(&r.dir, "its scene cannot be read"))?;
        let method = self
            .method_of(scene)
            .map_err(|m| OutputError::read(&r.dir, m))?;
        let pulse = p.pulse.as_ref().is_some_and(|q| r.spec.labels.iter().any(|(_, l)| *l == q.label));
        let pga = match (r.spec.pga, pulse) {
            (_, true) => 0.0,
            (Some(pga), false) => pga,
            (None, false) => {
                return Err(OutputError::read(&r.dir, "the run sets no `pga` (the level axis must set `pga`; a pulse run must carry `report.pulse.label`)").into());
            }
        };
        let mesh = r
            .spec
            .label(&p.mesh_axis)
            .unwrap_or(&p.main_mesh)
            .to_string();
        let joints = self.joint_names(r)?;
        let (mut opening, mut slip, mut slip_path) = (Vec::new(), Vec::new(), Vec::new());
        let mut t_end = 0.0f64;
        let mut worst: Option<(f64, Vec<(f64, f64)>)> = None;
        for j in &joints {
            let h = r.joint_history(j)?;
            let (t, o, s, net) = (
                h.column("t")?,
                h.column("max_opening")?,
                h.column("max_slip")?,
                h.column("max_tangential_displacement")?,
            );
            let mo = o.iter().copied().fold(0.0f64, f64::max);
            opening.push(mo);
            slip.push(net.iter().copied().fold(0.0f64, f64::max));
            slip_path.push(s.iter().copied().fold(0.0f64, f64::max));
            t_end = t_end.max(t.last().copied().unwrap_or(0.0));
            if worst.as_ref().is_none_or(|w| mo > w.0) {
                worst = Some((mo, t.iter().copied().zip(o.iter().copied()).collect()));
            }
        }
        let diagnostics = r.summary.as_ref().map(|s| {
            joints
                .iter()
                .map(|j| {
                    s.joints
                        .iter()
                        .find(|pk| &pk.name == j)
                        .map(|pk| JointDiagnostics {
                            lost: pk.events.lost,
                            lost_beyond_edge: pk.events.lost_beyond_edge,
                            slave_nodes: pk.slave_nodes,
                            widened_layer2: pk.events.widened_layer2,
                            fresh_searches: pk.events.fresh_searches,
                            max_sweeps: pk.max_sweeps,
                            unconverged_steps: pk.unconverged_steps,
                        })
                        .unwrap_or_default()
                })
                .collect()
        });
        let stress = if r.failed().is_none() { Some(FaceStress::read(p, &r.dir)?) } else { None };
        let mut crest = Vec::new();
        for m in [
            &p.monitors.crown,
            &p.monitors.quarter_left,
            &p.monitors.quarter_right,
        ] {
            crest.push((m.clone(), self.crest_history(r, m)?));
        }
        // the pulse runs: the crown's u_x relative to the dam's foot
        let crown_x = if pulse {
            let (h, f): (HistoryTable, HistoryTable) = (r.history(&p.monitors.crown)?, r.history(&p.monitors.foot)?);
            let (t, ux, fx) = (h.column("t")?, h.column("ux")?, f.column("ux")?);
            t.iter().zip(ux).zip(fx).map(|((&t, &u), &f)| (t, u - f)).collect()
        } else {
            Vec::new()
        };
        Ok(DamRun {
            crown_x,
            id: r.spec.id.clone(),
            method,
            reservoir: reservoir_label(scene),
            foundation: scene.foundation.as_ref().map(|f| f.model.as_str()).unwrap_or(SEED_FOUNDATION).to_string(),
            pulse,
            level: pga / p.design_pga,
            mesh,
            wall_time: r.summary.as_ref().map(|s| s.wall_time),
            failed: r.failed().map(str::to_string),
            t_end,
            joints,
            opening,
            slip,
            slip_path,
            diagnostics,
            stress,
            crest,
            worst_joint_history: worst.map(|w| w.1).unwrap_or_default(),
        })
    }
}

impl StudyKind for DamKind {
    fn check(&self, study: &Study) -> Result<(), Error> {
        let p = &self.params;
        let invalid = |message: String| -> Error {
            StudyError::Invalid {
                path: study.path.clone(),
                message: format!("`report` (kind \"dam\"): {message}"),
            }
            .into()
        };
        if !(p.design_pga.is_finite() && p.design_pga > 0.0) {
            return Err(invalid(format!(
                "`design_pga` = {} must be positive [g]",
                p.design_pga
            )));
        }
        if !(p.crest_radius.is_finite() && p.crest_radius > 0.0) {
            return Err(invalid(format!(
                "`crest_radius` = {} must be positive [m]",
                p.crest_radius
            )));
        }
        if !(p.enough.is_finite() && p.enough > 0.0) {
            return Err(invalid(format!("`enough` = {} must be positive", p.enough)));
        }
        if let Some(q) = &p.pulse {
            if !(q.start.is_finite() && q.start >= 0.0) {
                return Err(invalid(format!("`pulse.start` = {} must be a time ≥ 0 [s]", q.start)));
            }
            if !(q.band[0] > 0.0 && q.band[1] > q.band[0] && q.band[1].is_finite()) {
                return Err(invalid(format!("`pulse.band` = {:?} must be [low, high] with 0 < low < high [Hz]", q.band)));
            }
            if !study.axes.iter().any(|a| a.values.iter().any(|v| v.label == q.label)) {
                return Err(invalid(format!("`pulse.label` = \"{}\" is the label of no axis value", q.label)));
            }
        }
        let s = &p.seed;
        if s.opening_nts_mm.len() != s.levels.len() || s.opening_ntn_mm.len() != s.levels.len() {
            return Err(invalid(format!(
                "`seed`: {} levels but {} NTS and {} NTN openings",
                s.levels.len(),
                s.opening_nts_mm.len(),
                s.opening_ntn_mm.len()
            )));
        }
        if let Some(a) = study.axes.iter().find(|a| a.name == p.mesh_axis) {
            if !a.values.iter().any(|v| v.label == p.main_mesh) {
                return Err(invalid(format!(
                    "`main_mesh` = \"{}\" is not a label of axis \"{}\"",
                    p.main_mesh, p.mesh_axis
                )));
            }
        }
        let base = Scene::load(&study.scene)?;
        self.method_of(&base)
            .map_err(|m| invalid(format!("`joints`: {m}")))?;
        for m in [
            &p.monitors.crown,
            &p.monitors.quarter_left,
            &p.monitors.quarter_right,
        ] {
            if !base.output.monitor.iter().any(|x| &x.name == m) {
                return Err(invalid(format!(
                    "`monitors`: the base scene has no monitor \"{m}\""
                )));
            }
        }
        match &base.output.envelope {
            Some(e)
                if e.faces.contains(&p.faces.upstream) && e.faces.contains(&p.faces.downstream) => {
            }
            _ => {
                return Err(invalid(format!(
                    "the base scene's `output.envelope.faces` must name \"{}\" and \"{}\" (the stress envelopes the report reads)",
                    p.faces.upstream, p.faces.downstream
                )));
            }
        }
        Ok(())
    }

    fn report(&self, results: &StudyResults) -> Result<KindReport, Error> {
        report::report(self, results)
    }
}
