//! Scene files (`pipelines/*.json`): serde types, loading and validation.
//!
//! Every field is documented in `docs/scenes.md` with its unit and default. Unknown keys are
//! errors (`deny_unknown_fields`). Relative paths inside a scene are relative to the scene
//! file's directory. Units: SI (m, kg, s, Pa, N); record amplitudes are in g.

pub mod foundation;
pub mod patterns;
pub mod reservoir;
mod validate;

pub use validate::*;

use crate::error::SceneError;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A whole scene.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Name used for output files. Default: the scene file's stem.
    #[serde(default)]
    pub name: Option<String>,
    pub geometry: Geometry,
    /// Elastic materials per volume group.
    pub materials: Vec<MaterialSpec>,
    /// Fixed displacement components on groups (relative displacement 0).
    #[serde(default)]
    pub boundary: Vec<BoundarySpec>,
    #[serde(default)]
    pub loads: Loads,
    #[serde(default)]
    pub damping: Damping,
    pub time: TimeSpec,
    #[serde(default)]
    pub equilibrium: EquilibriumSpec,
    #[serde(default)]
    pub output: OutputSpec,
    /// Joints (contact interfaces); see docs/scenes.md.
    #[serde(default)]
    pub joints: Vec<JointSceneSpec>,
    /// Standard gravity used to convert records from g [m/s²]. Default 9.81.
    #[serde(default = "default_g")]
    pub g: f64,
    /// Reservoir on wet face groups: hydrostatic pressure and added mass (docs/dam_physics.md).
    #[serde(default)]
    pub reservoir: Option<ReservoirScene>,
    /// The rock model: massless (default, the seed's), massed_fixed or radiating ([`foundation`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub foundation: Option<foundation::FoundationScene>,
}

/// The reservoir of a dam (incompressible water; module problem::reservoir).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ReservoirScene {
    /// Wet face groups (dim 2) on the outer surface of the dam, e.g. `["dam:upstream"]`.
    pub faces: Vec<String>,
    /// Pool level z_w [m] (z up).
    pub level: f64,
    /// Water density ρw [kg/m³]. Default 1000 (fresh water).
    #[serde(default = "default_rho_w")]
    pub rho_w: f64,
    /// Reservoir bottom at the dam z_b [m] (depth H = z_w − z_b). Default: the lowest node of
    /// the wet faces.
    #[serde(default)]
    pub bottom: Option<f64>,
    /// Hydrostatic pressure ρw g (z_w − z), applied with gravity before the record and kept on.
    /// Default true.
    #[serde(default = "yes")]
    pub hydrostatic: bool,
    /// Westergaard/Kuo added mass along the face normal (inertia, not weight). Default true.
    #[serde(default = "yes")]
    pub added_mass: bool,
    /// The depth H in the added mass (7/8) ρw √(H (z_w − z)): `"reservoir"` (default: the depth
    /// at the dam, Kuo's generalised Westergaard as usually applied) or `"local"` (the depth of
    /// the node's own section, above the nearest point of the face's foot: smaller on an arch
    /// dam's banks; docs/dam.md, "Modes").
    #[serde(default)]
    pub added_mass_depth: AddedMassDepth,
    /// The hydrodynamic model (`reservoir::ReservoirModel`): `"westergaard"` (default, the
    /// seed's), `"westergaard_local"`, `"fe_incompressible"` (needs `fluid`). docs/scenes.md.
    #[serde(default)]
    pub model: reservoir::ReservoirModel,
    /// The meshed water of `"fe_incompressible"` (`reservoir::FluidScene`). Default: none.
    #[serde(default)]
    pub fluid: Option<reservoir::FluidScene>,
}

/// `reservoir.added_mass_depth`: which depth H enters the added mass.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum AddedMassDepth {
    /// The depth at the dam, z_w − z_b (the default).
    #[default]
    Reservoir,
    /// The depth of the node's own section.
    Local,
}

fn default_rho_w() -> f64 {
    1000.0
}

fn default_g() -> f64 {
    9.81
}

/// Where the mesh comes from: a `.geo` run through gmsh, or a ready `.msh`.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Geometry {
    /// A Gmsh script; meshed with `gmsh -3`, numbers passed with `-setnumber`.
    #[serde(default)]
    pub geo: Option<PathBuf>,
    /// `-setnumber NAME VALUE` parameters for the `.geo`.
    #[serde(default)]
    pub set: BTreeMap<String, f64>,
    /// A ready MSH 4.1 mesh (instead of `geo`).
    #[serde(default)]
    pub msh: Option<PathBuf>,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Physical volume group, e.g. `block:wedge`.
    pub group: String,
    /// Young's modulus [Pa].
    #[serde(rename = "E")]
    pub e: f64,
    /// Poisson's ratio [-], 0 ≤ ν < 0.5.
    pub nu: f64,
    /// Density [kg/m³]. With `massless` it is used only by the thin layer of elements along a
    /// joint face on the block (docs/dam_physics.md).
    pub rho: f64,
    /// Massless block (foundation): stiffness only, no mass, no weight, no base force, no stable
    /// step; its unknowns are condensed statically every step. Default false.
    #[serde(default)]
    pub massless: bool,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct BoundarySpec {
    /// Physical group (any dimension) whose nodes are fixed.
    pub group: String,
    /// Components fixed: any of "x", "y", "z". Default all three.
    #[serde(default = "all_components")]
    pub fix: Vec<String>,
}

fn all_components() -> Vec<String> {
    vec!["x".into(), "y".into(), "z".into()]
}

#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Loads {
    /// Gravity (body force ρ g), brought to equilibrium before the record starts.
    #[serde(default)]
    pub gravity: Option<Gravity>,
    /// Uniform base acceleration, up to three records.
    #[serde(default)]
    pub base: Vec<BaseRecord>,
    /// Surface tractions on face groups (for tests and static loads).
    #[serde(default)]
    pub traction: Vec<TractionSpec>,
    /// Nodal forces at the node nearest to a point.
    #[serde(default)]
    pub nodal: Vec<NodalForceSpec>,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Gravity {
    /// Acceleration of gravity [m/s²]. Default 9.81.
    #[serde(default = "default_g")]
    pub g: f64,
    /// Unit direction. Default [0, 0, -1] (z up).
    #[serde(default = "down")]
    pub direction: [f64; 3],
    /// Volume groups that carry their weight. Default: all. E.g. `["block:wedge"]` makes the
    /// rock a weightless support, the assumption of limit equilibrium.
    #[serde(default)]
    pub groups: Option<Vec<String>>,
}

fn down() -> [f64; 3] {
    [0.0, 0.0, -1.0]
}

/// One component of the base motion: a record file or a generated (synthetic) record, a
/// direction, a scale and an explicit baseline correction (docs/scenes.md, docs/motion.md).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct BaseRecord {
    /// Two-column text (t [s], a [g], `#` comments) or a PEER `.AT2` file. Exclusive with `synth`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub record: Option<PathBuf>,
    /// A spectrum-compatible record generated in memory (the same code as `record synth`,
    /// deterministic per seed). Exclusive with `record`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub synth: Option<BaseSynth>,
    /// Direction of the ground acceleration (normalised on load).
    pub direction: [f64; 3],
    /// Multiplier on the record. Default 1. Exclusive with `pga`.
    #[serde(default)]
    pub scale: Option<f64>,
    /// Target peak ground acceleration [g]: the record is scaled so that max |a| = pga (after
    /// the baseline correction, so the applied PGA is this one).
    #[serde(default)]
    pub pga: Option<f64>,
    /// Baseline correction applied before scaling: "none" (default: the record as given),
    /// "mean", "polynomial" (degree 5), {"highpass": corner_hz} (order 4, or "order"), or the
    /// `record correct` form {"method": …}. Never applied unless asked; the drift left is a note.
    #[serde(default)]
    pub baseline: BaseCorrection,
}

impl BaseRecord {
    /// Apply `f` to every file path of the entry (the record, a spectrum table or UHS file).
    pub fn map_paths(&mut self, f: impl Fn(&mut PathBuf)) {
        if let Some(r) = self.record.as_mut() {
            f(r);
        }
        if let Some(s) = self.synth.as_mut() {
            use crate::motion::TargetSpec;
            if let TargetSpec::Table { file: Some(p), .. } | TargetSpec::Uhs { file: Some(p), .. } = &mut s.spectrum {
                f(p);
            }
        }
    }

    /// How errors and notes name entry `k`: `loads.base[k] (record FILE)` or `(synth seed N h1)`.
    pub fn label(&self, k: usize) -> String {
        match (&self.record, &self.synth) {
            (Some(r), _) => format!("loads.base[{k}] (record {})", r.display()),
            (None, Some(s)) => format!("loads.base[{k}] (synth seed {} {})", s.seed, s.component),
            (None, None) => format!("loads.base[{k}]"),
        }
    }
}

/// A generated base record: one component of the set `jointquake record synth` makes from a
/// target spectrum and a seed (`--components 3`, so `h1`, `h2`, `v` are the components of
/// that command's files, byte for byte before scaling).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct BaseSynth {
    /// Target spectrum, the options of `record synth` (`{"kind": "code", "structure": "arch",
    /// "site_class": "I"}`, `{"kind": "table", "points": [[T, Sa], …]}` or `"file"`, `"uhs"`).
    pub spectrum: crate::motion::TargetSpec,
    /// Seed of the random phases (ChaCha8): the same seed gives the same record.
    pub seed: u64,
    /// "h1", "h2" (horizontal) or "v" (vertical, 2/3 of the target and PGA). Default "h1".
    #[serde(default)]
    pub component: SynthComponent,
    /// Record length [s]. Default 20 (the default envelope's 2 + 8 + 10 s).
    #[serde(default = "default_synth_duration")]
    pub duration: f64,
    /// Sample interval [s]. Default 0.01 (100 Hz, as `record synth`).
    #[serde(default = "default_synth_dt")]
    pub dt: f64,
    /// Horizontal design PGA of the set [g] (the code spectrum is a_h β(T)). Default: the
    /// entry's `pga` (divided by the vertical ratio 2/3 for "v"), so the generated component
    /// already has the requested peak.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pga: Option<f64>,
}

/// `loads.base[].synth.component`: which component of the seed's three-component set.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SynthComponent {
    /// First horizontal component (the default).
    #[default]
    H1,
    /// Second horizontal component.
    H2,
    /// Vertical component (2/3 of the target and PGA).
    V,
}

impl SynthComponent {
    /// The scene's spelling (`"h1"`, `"h2"`, `"v"`), also the name in `record synth`'s files.
    pub fn as_str(self) -> &'static str {
        match self {
            SynthComponent::H1 => "h1",
            SynthComponent::H2 => "h2",
            SynthComponent::V => "v",
        }
    }

    /// Index in the set (`motion::synth::COMPONENT_NAMES`).
    pub fn index(self) -> usize {
        self as usize
    }
}

impl std::fmt::Display for SynthComponent {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}
fn default_synth_duration() -> f64 {
    20.0
}
fn default_synth_dt() -> f64 {
    0.01
}

/// The `baseline` of a base entry (see [`BaseRecord::baseline`]).
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(untagged)]
pub enum BaseCorrection {
    /// "none", "mean" or "polynomial".
    Named(String),
    /// {"highpass": corner [Hz], "order": n (default 4)}.
    HighPass(HighPassCorner),
    /// The full form of `record correct`: {"method": "polynomial", "degree": 7}, ….
    Method(crate::motion::Baseline),
}

#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct HighPassCorner {
    pub highpass: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub order: Option<u32>,
}

impl Default for BaseCorrection {
    fn default() -> Self {
        BaseCorrection::Named("none".into())
    }
}

impl BaseCorrection {
    /// The correction to apply (`None`: the record as given), or what to write instead.
    pub fn resolve(&self) -> Result<Option<crate::motion::Baseline>, String> {
        use crate::motion::Baseline;
        match self {
            BaseCorrection::Named(n) => match n.as_str() {
                "none" => Ok(None),
                "mean" => Ok(Some(Baseline::Mean)),
                "polynomial" => Ok(Some(Baseline::Polynomial { degree: 5 })),
                other => Err(format!("baseline = \"{other}\" is not a correction: give \"none\", \"mean\", \"polynomial\" or {{\"highpass\": corner_hz}}")),
            },
            BaseCorrection::HighPass(h) => Ok(Some(Baseline::HighPass { corner: h.highpass, order: h.order.unwrap_or(4) })),
            BaseCorrection::Method(b) => Ok(Some(b.clone())),
        }
    }
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct TractionSpec {
    /// Face group (tri3/quad4) carrying the traction.
    pub group: String,
    /// Traction vector [Pa] (force per unit area, global axes).
    pub traction: [f64; 3],
    /// Time history: linear ramp from 0 over `ramp` seconds, then constant. Default 0 (step load).
    #[serde(default)]
    pub ramp: f64,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct NodalForceSpec {
    /// Point [m]; the force acts on the nearest node (snap distance reported).
    pub point: [f64; 3],
    /// Force [N].
    pub force: [f64; 3],
    /// Ramp duration [s]. Default 0 (step).
    #[serde(default)]
    pub ramp: f64,
}

/// Rayleigh damping C = αM + βK, given directly or as a damping ratio at two frequencies.
#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Damping {
    /// Mass-proportional coefficient α [1/s]. Default 0.
    #[serde(default)]
    pub alpha: Option<f64>,
    /// Stiffness-proportional coefficient β [s]. Default 0.
    #[serde(default)]
    pub beta: Option<f64>,
    /// Damping ratio ξ [-] reached at `f1` and `f2` (exclusive with alpha/beta).
    #[serde(default)]
    pub ratio: Option<f64>,
    /// First frequency [Hz] for `ratio`.
    #[serde(default)]
    pub f1: Option<f64>,
    /// Second frequency [Hz] for `ratio`.
    #[serde(default)]
    pub f2: Option<f64>,
    /// Volume groups whose nodes carry the mass-proportional term αM. Default: all.
    /// In the relative-displacement form αM v is a dashpot to the moving ground: it damps the
    /// deformation of a supported body, but it also brakes a block that slides as a whole
    /// (at α = 2 s⁻¹ a block sliding at 0.5 m/s feels 0.1 g). Naming only the supported
    /// groups (e.g. `["block:rock"]`) damps the rock mass without resisting the sliding wedge.
    #[serde(default)]
    pub mass_groups: Option<Vec<String>>,
}

impl Damping {
    /// (α, β) from the given form. Two-frequency form: α = 2ξ ω1ω2/(ω1+ω2), β = 2ξ/(ω1+ω2).
    pub fn coefficients(&self) -> Result<(f64, f64), String> {
        match (self.ratio, self.alpha, self.beta) {
            (Some(xi), None, None) => {
                let (f1, f2) = match (self.f1, self.f2) {
                    (Some(a), Some(b)) if a > 0.0 && b > 0.0 && a != b => (a, b),
                    _ => return Err("damping: `ratio` needs two distinct positive frequencies `f1` and `f2` [Hz]".into()),
                };
                if !(0.0..1.0).contains(&xi) {
                    return Err(format!("damping: ratio {xi} must be in [0, 1)"));
                }
                let (w1, w2) = (2.0 * std::f64::consts::PI * f1, 2.0 * std::f64::consts::PI * f2);
                Ok((2.0 * xi * w1 * w2 / (w1 + w2), 2.0 * xi / (w1 + w2)))
            }
            (None, a, b) => {
                let (a, b) = (a.unwrap_or(0.0), b.unwrap_or(0.0));
                if a < 0.0 || b < 0.0 || !a.is_finite() || !b.is_finite() {
                    return Err(format!("damping: alpha = {a} and beta = {b} must be finite and ≥ 0"));
                }
                Ok((a, b))
            }
            _ => Err("damping: give either `ratio` with `f1`, `f2`, or `alpha`/`beta`, not both".into()),
        }
    }
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct TimeSpec {
    /// Duration of the dynamic stage [s].
    pub duration: f64,
    /// Time step [s]. Must not exceed the stability limit (the run stops with the limit quoted).
    #[serde(default)]
    pub dt: Option<f64>,
    /// Fraction of the stable step used when `dt` is not given. Default 0.9.
    #[serde(default)]
    pub courant: Option<f64>,
    /// Energy-balance tolerance (relative to the energy scale) above which the run stops. Default 0.05.
    #[serde(default = "default_energy_tol")]
    pub energy_tolerance: f64,
    /// Largest number of dynamic steps a run may take. Default 10⁸ (`DEFAULT_MAX_STEPS`): about
    /// 30 minutes of a 10⁴-element model on one core, and far beyond any run the pipelines
    /// make; a run that would take more (a tiny dt, a huge duration) is refused up front with its
    /// count, instead of running for ever. Raise it to allow such a run.
    #[serde(default = "default_max_steps")]
    pub max_steps: u64,
    /// Selective mass scaling (docs/elements.md "Mass scaling"). Default: none (off), because
    /// it changes the dynamics: the scaled elements' inertia is larger than their material's.
    #[serde(default)]
    pub mass_scaling: Option<MassScalingSpec>,
}

/// Fraction of the stable step used when a scene gives neither `dt` nor `courant`. Default 0.9:
/// a margin of 10 % for the element-eigenvalue estimate, which bounds ω_max from above for
/// linear elements but not for contact stiffening or the round-off of very distorted elements.
pub const DEFAULT_COURANT: f64 = 0.9;

impl TimeSpec {
    /// `courant`, or [`DEFAULT_COURANT`] when the scene gives none.
    pub fn courant_or_default(&self) -> f64 {
        self.courant.unwrap_or(DEFAULT_COURANT)
    }
}

/// `time.mass_scaling`: raise the inertial density of the elements whose own stable step is below
/// `target_dt / courant` until it reaches it (their weight is unchanged).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MassScalingSpec {
    /// The time step the run should be able to use [s] (no default: required). Each element's
    /// own stable step is raised to `target_dt / courant` (`courant` of this `time`, 0.9 by
    /// default, also when `dt` is given), so that `courant` × the model's stable step reaches
    /// `target_dt` unless penalty springs or a condensed foundation lower it.
    pub target_dt: f64,
}

/// Default of `time.max_steps`.
pub const DEFAULT_MAX_STEPS: u64 = 100_000_000;

fn default_max_steps() -> u64 {
    DEFAULT_MAX_STEPS
}

fn default_energy_tol() -> f64 {
    0.05
}

/// Gravity equilibrium before the dynamic stage (dynamic relaxation with kinetic damping).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct EquilibriumSpec {
    /// "relaxation" (default when gravity is on): bring gravity to equilibrium before the
    /// dynamic stage; "none": gravity acts from t = 0 in the dynamic stage (sliding from rest).
    #[serde(default)]
    pub method: EquilibriumMethod,
    /// Relative residual ‖F − K u‖/‖F‖ at which relaxation stops. Default 1e-6.
    #[serde(default = "default_eq_tol")]
    pub tolerance: f64,
    /// Largest residual accepted when `max_steps` is reached (else the run stops). Default 1e-3.
    #[serde(default = "default_eq_max_res")]
    pub max_residual: f64,
    /// Step budget of the relaxation. Default 200000.
    #[serde(default = "default_eq_steps")]
    pub max_steps: usize,
    /// Joint bonds (cohesion, tensile strength) while gravity is brought to equilibrium:
    /// "kept" (default) or "brittle". "kept": every joint behaves as `keep_cohesion` during
    /// relaxation and the dynamic stage starts with every bond intact (bar tensile ruptures).
    /// Why the default: the in-situ state predates the earthquake; switching gravity on at once
    /// concentrates elastic shear at joint edges, and a brittle bond would be lost there by the
    /// loading path alone (on the seed wedge 80 % of the pairs of joint A lose their cohesion
    /// that way, leaving the friction-only FS 1.11 instead of 1.85 before any shaking).
    /// "brittle": the joints' own law applies during relaxation too.
    #[serde(default)]
    pub joint_bonds: JointBonds,
    /// How the static loads meet the joints (module `construction`): "simultaneous" (default:
    /// gravity and the reservoir at once, the joints in contact with their gaps as meshed),
    /// "grouted" (the same, the joints grouted first: zero gap where their sides are at the
    /// start), "construction" (self-weight with the joints that are not `tied` open, then
    /// grouting at the deformed state, then the reservoir with the joints active).
    #[serde(default)]
    pub sequence: StaticSequence,
}

/// `equilibrium.method`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum EquilibriumMethod {
    /// Dynamic relaxation of the static loads before the dynamic stage (the default).
    #[default]
    Relaxation,
    /// No static stage: gravity acts from t = 0 in the dynamic stage.
    None,
}

/// `equilibrium.joint_bonds`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum JointBonds {
    /// Every joint keeps its bonds during relaxation (the default).
    #[default]
    Kept,
    /// The joints' own law applies during relaxation too.
    Brittle,
}

/// `equilibrium.sequence`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum StaticSequence {
    /// Static loads at once, joints in contact with their gaps as meshed (the default).
    #[default]
    Simultaneous,
    /// The same after grouting the joints on the initial configuration.
    Grouted,
    /// Self-weight with open joints, grouting, then the reservoir with the joints active.
    Construction,
}

impl StaticSequence {
    /// The scene's spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            StaticSequence::Simultaneous => "simultaneous",
            StaticSequence::Grouted => "grouted",
            StaticSequence::Construction => "construction",
        }
    }
}
fn default_eq_tol() -> f64 {
    1e-6
}
fn default_eq_max_res() -> f64 {
    1e-3
}
fn default_eq_steps() -> usize {
    200_000
}

impl Default for EquilibriumSpec {
    fn default() -> Self {
        EquilibriumSpec {
            method: EquilibriumMethod::default(),
            tolerance: default_eq_tol(),
            max_residual: default_eq_max_res(),
            max_steps: default_eq_steps(),
            joint_bonds: JointBonds::default(),
            sequence: StaticSequence::default(),
        }
    }
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Output directory. Default `out/<scene name>`.
    #[serde(default)]
    pub dir: Option<PathBuf>,
    /// A VTU frame every `frame_stride` steps (exclusive with `frame_interval`).
    #[serde(default)]
    pub frame_stride: Option<usize>,
    /// A VTU frame every `frame_interval` seconds. Default: duration / 100 (about 100 frames).
    #[serde(default)]
    pub frame_interval: Option<f64>,
    /// History rows every `history_stride` steps (exclusive with `history_interval`; 0 counts
    /// as 1).
    #[serde(default)]
    pub history_stride: Option<usize>,
    /// History rows every `history_interval` seconds. Default (neither given):
    /// `output::recorder::DEFAULT_HISTORY_INTERVAL`, finer for short runs (docs/scenes.md).
    #[serde(default)]
    pub history_interval: Option<f64>,
    /// Monitored points, snapped to the nearest node (snap distance reported).
    #[serde(default)]
    pub monitor: Vec<MonitorSpec>,
    /// Write VTU frames at all. Default true (studies switch it off for sweeps).
    #[serde(default = "yes")]
    pub frames: bool,
    /// Also write the per-joint force diagnostic `histories/joint_<joint>_forces.csv` (pairs in
    /// contact, lost and slipping, open/close transitions, resultant normal and tangential
    /// force, Mohr-Coulomb capacity and cohesion carried, Gauss–Seidel residual; one row per
    /// history row, docs/contact.md). Default false: a research diagnostic, not an output an
    /// ordinary run needs.
    #[serde(default)]
    pub joint_forces: bool,
    /// Stress envelopes over time on face groups (`envelope.vtu`, `envelope.json`;
    /// `output::envelope`). Default none.
    #[serde(default)]
    pub envelope: Option<EnvelopeSpec>,
    /// Accept a run whose joints penetrate more than a tenth of their slave face size
    /// (`output::recorder::PENETRATION_WARN_FRACTION`, lost nodes included): it then ends with
    /// exit 0 and the warning. Default false: such a run writes its outputs and summary, then
    /// ends with an error (the incline block of issue 34 sank 3.73 m into its base with exit
    /// 0). For a study of a method known to lose contact (`on_exit: "report"`). Not written
    /// when false (planned scenes unchanged).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub allow_penetration: bool,
}

/// `output.envelope`: the largest and smallest principal stress over the run of the elements
/// under face groups (e.g. a dam's upstream and downstream faces).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct EnvelopeSpec {
    /// Face groups (dimension 2) on the outer surface of volume groups.
    pub faces: Vec<String>,
    /// Steps between two samples (and the last step). Default 10.
    #[serde(default = "ten")]
    pub stride: usize,
    /// Also linearise the stresses through the thickness between two of `faces`
    /// (`output::linearise`): a cut from each face of `from` to the nearest point of `to`.
    /// Default none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub linearise: Option<LineariseSpec>,
}

/// `output.envelope.linearise`: the face groups a through-thickness cut joins (both in
/// `output.envelope.faces`), e.g. a dam's upstream (`from`) and downstream (`to`) faces.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LineariseSpec {
    pub from: String,
    pub to: String,
}

fn ten() -> usize {
    10
}

fn yes() -> bool {
    true
}

impl Default for OutputSpec {
    fn default() -> Self {
        OutputSpec { dir: None, frame_stride: None, frame_interval: None, history_stride: None, history_interval: None, monitor: vec![], frames: true, joint_forces: false, envelope: None, allow_penetration: false }
    }
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MonitorSpec {
    pub name: String,
    /// Point [m].
    pub point: [f64; 3],
    /// Restrict the snap to nodes of this group (e.g. a block). Default: any node.
    #[serde(default)]
    pub group: Option<String>,
}

/// A joint as written in a scene (tagging and contact options).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct JointSceneSpec {
    pub name: String,
    /// Face group of the master side, or of one side when `auto`.
    pub master: String,
    /// Face group of the slave side.
    pub slave: String,
    /// Let the tagger choose: the finer side becomes the slave. Default false.
    #[serde(default)]
    pub auto: bool,
    /// Largest distance [m] between the two sides accepted by the tagger. Default 1e-6 × model size.
    #[serde(default)]
    pub tolerance: Option<f64>,
    /// Contact method: "nts" (default) or "ntn" or "penalty".
    #[serde(default)]
    pub method: Option<ContactMethod>,
    /// Candidate layer: 1 (default) or 2.
    #[serde(default)]
    pub layer: Option<u8>,
    /// When a projection leaves the candidate set: "widen" (default) or "report".
    #[serde(default)]
    pub on_exit: Option<OnExitSpec>,
    /// Friction coefficient μ [-]. Default 0.6 ([`DEFAULT_FRICTION`]); give `mu` or `phi`.
    #[serde(default)]
    pub mu: Option<f64>,
    /// Friction angle [deg] (instead of mu).
    #[serde(default)]
    pub phi: Option<f64>,
    /// Cohesion [Pa]. Default 0.
    #[serde(default)]
    pub cohesion: Option<f64>,
    /// Tensile strength [Pa] while intact. Default 0.
    #[serde(default)]
    pub tensile_strength: Option<f64>,
    /// Keep cohesion after slip/opening. Default false.
    #[serde(default)]
    pub keep_cohesion: Option<bool>,
    /// Softening length [m]: cohesion falls linearly to 0 over this accumulated slip (and an
    /// opening beyond it breaks the bond). Default 0: brittle, lost at the first slip or opening.
    #[serde(default)]
    pub softening_slip: Option<f64>,
    /// Asperity angle i [deg] of the bilinear (Patton 1966) shear envelope
    /// τ ≤ min(tan(φ + i) σ, c + σ tan φ): below the knee σ_k = c / (tan(φ + i) − tan φ) the
    /// joint shears by riding up its first-order asperities (through the origin: no shear
    /// without compression), above it along the cohesive Coulomb line. A measured property of
    /// the joint's roughness (Patton 1966; Barton & Choubey 1977: first-order i of rock joints
    /// typically 5–20°), stated by the scene, never chosen for the solver's convergence.
    /// Default none: the seed's truncated Mohr–Coulomb cone (c + σ tan φ for σ ≥ 0). Needs
    /// 0 < i < 90° − φ, cohesion > 0, no tensile strength, not tied (docs/contact.md, "The
    /// bilinear envelope").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub asperity_angle: Option<f64>,
    /// Tied (bonded, never opens or slides). Default false.
    #[serde(default)]
    pub tied: Option<bool>,
    /// Perimeter tolerance as a fraction of the master face size [-]. Default 1e-3. A slave node
    /// that finds no face with the strict inside test (1e-8) is tried on its candidate faces with
    /// this tolerance before widening: where both sides of a joint end on the same line (a line of
    /// intersection, a crest, blocks of the same plan) round-off or lateral elastic strain puts the
    /// edge nodes just outside the master, and without it they are lost and sink into it.
    /// 1e-3 h is above elastic lateral mismatches of rock and concrete joints (strain ≤ 1e-3).
    #[serde(default)]
    pub edge_tolerance: Option<f64>,
    /// A slave node that finds a master face again after a step lost (its *re-entry*), with a
    /// penetration it took while lost (it slid back over the master's free edge after the
    /// joint closed, or was lost inside the outline): `"push"` (default) closes it in that one
    /// step, as every contact step does, and so gives the node a relative velocity of
    /// penetration / dt, energy the joint creates (the joint histories' `reentry_work`);
    /// `"hold"` takes that penetration as closed and releases it as the node moves out (it
    /// never deepens), so a re-entry creates no energy, the treatment of initial penetrations
    /// of LS-DYNA's contacts (IGNORE) and Abaqus' strain-free adjustment. Default "push": the
    /// seed's dynamic contact force, whose results the committed studies hold.
    #[serde(default)]
    pub reentry: Option<ReentrySpec>,
    /// Penalty stiffness per unit area [Pa/m] for method "penalty".
    #[serde(default)]
    pub penalty_stiffness: Option<f64>,
}

/// A joint's contact method as written in a scene (`"nts"`, `"ntn"`, `"penalty"`, `"mortar"`), checked when
/// the scene is read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ContactMethod {
    /// Node-to-segment, dynamic contact force (the default).
    Nts,
    /// Node-to-node with the tagger's nearest master node O.
    Ntn,
    /// Node-to-segment geometry with penalty springs (`penalty_stiffness`).
    Penalty,
    /// Dual mortar, segment-to-segment (docs/contact.md, "Dual mortar").
    Mortar,
}

impl ContactMethod {
    /// The scene's spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            ContactMethod::Nts => "nts",
            ContactMethod::Ntn => "ntn",
            ContactMethod::Penalty => "penalty",
            ContactMethod::Mortar => "mortar",
        }
    }
}

impl std::str::FromStr for ContactMethod {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "nts" => Ok(ContactMethod::Nts),
            "ntn" => Ok(ContactMethod::Ntn),
            "penalty" => Ok(ContactMethod::Penalty),
            "mortar" => Ok(ContactMethod::Mortar),
            other => Err(format!("contact method \"{other}\" is not one of \"nts\", \"ntn\", \"penalty\", \"mortar\"")),
        }
    }
}

/// What to do when a slave node's projection leaves its candidate set (`"widen"`, `"report"`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum OnExitSpec {
    Widen,
    Report,
}

/// What a re-entering slave node's penetration does (`"push"`, `"hold"`: `JointSceneSpec::reentry`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ReentrySpec {
    Push,
    Hold,
}

/// Friction coefficient of a joint that gives neither `mu` nor `phi`. Default 0.6 (φ ≈ 31°, the
/// middle of the range of rock joints and concrete lift joints; the seed paper's joints).
pub const DEFAULT_FRICTION: f64 = 0.6;

/// A joint's friction as the scene gives it: the one rule for μ or φ (both given is an error,
/// checked in [`Scene::validate`]; neither: μ = [`DEFAULT_FRICTION`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Friction {
    /// Coefficient μ [-].
    Mu(f64),
    /// Angle φ [deg].
    Phi(f64),
}

impl Friction {
    /// μ = tan φ [-].
    pub fn mu(self) -> f64 {
        match self {
            Friction::Mu(m) => m,
            Friction::Phi(p) => p.to_radians().tan(),
        }
    }

    /// φ = atan μ [deg].
    pub fn phi_deg(self) -> f64 {
        match self {
            Friction::Mu(m) => m.atan().to_degrees(),
            Friction::Phi(p) => p,
        }
    }
}

impl JointSceneSpec {
    /// The joint's friction (see [`Friction`]); call on a validated scene (both `mu` and `phi`
    /// given reads as `mu`).
    pub fn friction(&self) -> Friction {
        match (self.mu, self.phi) {
            (Some(m), _) => Friction::Mu(m),
            (None, Some(p)) => Friction::Phi(p),
            (None, None) => Friction::Mu(DEFAULT_FRICTION),
        }
    }

    /// The friction of the asperity envelope's first branch, tan(φ + i) [-] (`asperity_angle`
    /// i), or `None` (the Mohr–Coulomb cone); call on a validated scene.
    pub fn asperity_friction(&self) -> Option<f64> {
        self.asperity_angle.map(|i| (self.friction().phi_deg() + i).to_radians().tan())
    }

    /// The joint's contact method (default node-to-segment).
    pub fn method(&self) -> ContactMethod {
        self.method.unwrap_or(ContactMethod::Nts)
    }
}



impl Scene {
    /// Read and validate a scene file; relative paths are resolved against its directory.
    /// Resolve the scene's relative file paths (geometry `.geo`/`.msh`, base records and
    /// spectrum tables) against `dir`: the directory of the file that wrote them (the scene
    /// file itself, or the study file whose axis patched them in).
    pub fn resolve_paths_against(&mut self, dir: &Path) {
        let resolve = |p: &mut PathBuf| {
            if p.is_relative() {
                *p = dir.join(&*p);
            }
        };
        if let Some(g) = self.geometry.geo.as_mut() {
            resolve(g);
        }
        if let Some(m) = self.geometry.msh.as_mut() {
            resolve(m);
        }
        for b in &mut self.loads.base {
            b.map_paths(&resolve);
        }
    }

    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let text = crate::files::read_text_bounded(path, crate::files::MAX_TEXT_INPUT).map_err(|source| SceneError::Io { path: path.to_path_buf(), source })?;
        let mut scene: Scene = serde_json::from_str(&text).map_err(|e| SceneError::Parse {
            path: path.to_path_buf(),
            message: format!("{e} (see docs/scenes.md for the fields)"),
        })?;
        scene.resolve_paths_against(path.parent().unwrap_or(Path::new(".")));
        if scene.name.is_none() {
            // From the file name, with the characters a name may not hold replaced by `_`.
            let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
            scene.name = Some(if stem.is_empty() { "scene".into() } else { crate::files::file_stem(&stem) });
        }
        scene.validate().map_err(|message| SceneError::Invalid { path: path.to_path_buf(), message })?;
        Ok(scene)
    }

    /// The scene's name (set by `load`).
    pub fn name(&self) -> &str {
        self.name.as_deref().unwrap_or("scene")
    }

    /// Output directory: `output.dir` or `out/<name>`.
    pub fn output_dir(&self) -> PathBuf {
        self.output.dir.clone().unwrap_or_else(|| PathBuf::from("out").join(self.name()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn knob_enums_keep_their_json_spelling_and_defaults() {
        // The string knobs became enums (issue 27): the JSON spelling and the defaults must be
        // those of the strings they replace, so every existing scene reads the same.
        let eq: EquilibriumSpec = serde_json::from_str(r#"{"method": "none", "joint_bonds": "brittle", "sequence": "construction"}"#).unwrap();
        assert_eq!((eq.method, eq.joint_bonds, eq.sequence), (EquilibriumMethod::None, JointBonds::Brittle, StaticSequence::Construction));
        let d = EquilibriumSpec::default();
        assert_eq!((d.method, d.joint_bonds, d.sequence), (EquilibriumMethod::Relaxation, JointBonds::Kept, StaticSequence::Simultaneous));
        let from_empty: EquilibriumSpec = serde_json::from_str("{}").unwrap();
        assert_eq!((from_empty.method, from_empty.joint_bonds, from_empty.sequence), (d.method, d.joint_bonds, d.sequence));
        for (text, c) in [("h1", SynthComponent::H1), ("h2", SynthComponent::H2), ("v", SynthComponent::V)] {
            assert_eq!(serde_json::from_str::<SynthComponent>(&format!("\"{text}\"")).unwrap(), c);
            assert_eq!(c.as_str(), text);
            assert_eq!(crate::motion::synth::COMPONENT_NAMES[c.index()], text);
        }
        assert_eq!(serde_json::from_str::<AddedMassDepth>("\"local\"").unwrap(), AddedMassDepth::Local);
        assert_eq!(AddedMassDepth::default(), AddedMassDepth::Reservoir);
        assert!(serde_json::from_str::<StaticSequence>("\"sequential\"").unwrap_err().to_string().contains("simultaneous"));
        for s in [StaticSequence::Simultaneous, StaticSequence::Grouted, StaticSequence::Construction] {
            assert_eq!(serde_json::to_string(&s).unwrap(), format!("\"{}\"", s.as_str()));
        }
    }
}
