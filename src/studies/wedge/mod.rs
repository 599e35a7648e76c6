//! The wedge study of the seed paper (Hoek & Bray wedge): static factor of safety (limit
//! equilibrium and FEM strength reduction), seismic slip against PGA with NTS, NTN and the
//! rigid-block level, the rock's stiffness and model, speed against accuracy.
//!
//! A user of the study engine ([`crate::study`]): the runs are the study file's axes
//! (`pipelines/wedge_study.json`); this module adds only the wedge's parameters
//! ([`WedgeParams`], the study file's `report`), its strength-reduction step, its metrics,
//! tables and charts ([`report`]) and the charts of one run (the demo).
//!
//! What it reads from each run, and how:
//! - PGA [g]: the run's `pga` (the pga axis);
//! - mesh level: the run's label on the mesh axis (`mesh_axis`);
//! - contact method and layer: the run scene's joints (the first joint; the study's method
//!   axis sets every joint alike);
//! - stiffness factor: the run scene's first Young's modulus over the base scene's;
//! - rock model ([`report::RockModel`]): the rock is the volumes that carry no weight (not in
//!   `loads.gravity.groups`); "rigid" when the run scene fixes one of them, "massless" when one
//!   of them is `massless` (condensed, with the weightless massive layer under the joints,
//!   docs/dam_physics.md), else "elastic";
//! - joint law ([`report::CohesionLaw`]): the first joint's `asperity_angle` (the bilinear
//!   envelope) / `keep_cohesion` / `softening_slip`; the base scene's law is the headline, every
//!   other is a variant with its own section and chart;
//! - stiffness-proportional damping β: the run scene's `damping` (the base scene's β is the
//!   headline's, any other a variant).
//!
//! Conventions: slip is the relative displacement of the wedge and rock nodes at P2 (middle of
//! the line of intersection) along the line of intersection, positive down it, from its value
//! at the end of gravity equilibrium.

pub mod report;
pub mod rigid_level;

use crate::error::{Error, ModelError, StudyError};
use crate::rigid::wedge::{analyse_wedge, HeightDef, WedgeInput};
use crate::scene::Scene;
use crate::study::{kind_params, scene_for, KindReport, RunCharts, StepOptions, StepOutput, StepSpec, Study, StudyKind, StudyResults};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// Names of the monitored points the report reads.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MonitorNames {
    /// The wedge node on its slope face (residual displacement). Default "P1".
    #[serde(default = "p1")]
    pub p1: String,
    /// The wedge and rock nodes at the middle of the line of intersection (slip). Default
    /// "P2w", "P2r".
    #[serde(default = "p2w")]
    pub p2_wedge: String,
    #[serde(default = "p2r")]
    pub p2_rock: String,
    /// A rock node inside the rock mass under the wedge (off the joint, whose master nodes
    /// carry the contact impulses): the motion the rock delivers to the wedge. Optional in the
    /// scene; default "R".
    #[serde(default = "rock_monitor")]
    pub rock: String,
}

fn p1() -> String {
    "P1".into()
}
fn p2w() -> String {
    "P2w".into()
}
fn p2r() -> String {
    "P2r".into()
}
fn rock_monitor() -> String {
    "R".into()
}

impl Default for MonitorNames {
    fn default() -> Self {
        MonitorNames { p1: p1(), p2_wedge: p2w(), p2_rock: p2r(), rock: rock_monitor() }
    }
}

/// The scene's joints on the two planes of the wedge.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct JointNames {
    /// The joint on plane A (`wedge.plane_a`) and on plane B.
    pub a: String,
    pub b: String,
}

/// The reference run of each PGA.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceSpec {
    /// Mesh level (label on the mesh axis).
    pub mesh: String,
    /// Candidate layer of the reference NTS runs. Default 2 (the wider set cannot lose a node
    /// that Layer1 keeps).
    #[serde(default = "two")]
    pub layer: u8,
}

fn two() -> u8 {
    2
}

/// Strength-reduction step (see [`crate::study::ssr::SsrOptions`]).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SsrSpec {
    /// The scene: labels per axis (axes not named take their first value); its base records
    /// are dropped (gravity only). E.g. `{"mesh": "medium", "rock": "rigidrock"}`.
    #[serde(default)]
    pub run: BTreeMap<String, String>,
    /// Initial bracket [F_low, F_high]. Default [1.0, 3.0] (the seed values lie in 1.6–1.9).
    #[serde(default = "ssr_bracket")]
    pub bracket: [f64; 2],
    /// Bracket width at which bisection stops. Default 0.01 (0.5 % of F ≈ 2).
    #[serde(default = "ssr_tol")]
    pub tolerance: f64,
    /// Slip [m] of any slave node above which a trial has failed. Default 0.05 m: far above the
    /// elastic relative displacement of a stable wedge (≈ 1e-4 m) and far below a sliding one.
    #[serde(default = "ssr_slip")]
    pub slip_limit: f64,
    /// Relaxation steps per trial. Default 60 000.
    #[serde(default = "ssr_steps")]
    pub max_steps: usize,
}

fn ssr_bracket() -> [f64; 2] {
    [1.0, 3.0]
}
fn ssr_tol() -> f64 {
    0.01
}
fn ssr_slip() -> f64 {
    0.05
}
fn ssr_steps() -> usize {
    60_000
}

/// The wedge study's parameters: the study file's `report` object (`"kind": "wedge"`).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct WedgeParams {
    /// The wedge for limit equilibrium and the rigid level (planes, H). Default: the seed
    /// wedge, which is what `geo/wedge.geo` builds with its defaults. Its strength and density
    /// are replaced by those of the scene (`joints`, `wedge_group`).
    #[serde(default)]
    pub wedge: WedgeInput,
    /// The scene's joints on planes A and B.
    pub joints: JointNames,
    /// The wedge's volume group (its density for the rigid level). Default "block:wedge".
    #[serde(default = "wedge_group")]
    pub wedge_group: String,
    #[serde(default)]
    pub monitors: MonitorNames,
    /// The axis of PGAs (values with `pga`). Default "pga".
    #[serde(default = "pga_axis")]
    pub pga_axis: String,
    /// The axis of mesh levels. Default "mesh".
    #[serde(default = "mesh_axis")]
    pub mesh_axis: String,
    /// Mesh level of the NTS/NTN sweep over PGA.
    pub sweep_mesh: String,
    /// The finest run of each PGA (the accuracy reference).
    pub reference: ReferenceSpec,
    /// PGA of the speed-against-accuracy chart and the stiffness table [g]. Default 1.0.
    #[serde(default = "one")]
    pub accuracy_pga: f64,
    /// The rock model of the main runs: "rigid" (default), "massless" or "elastic"; the runs
    /// with another one are compared with their main-rock twins.
    #[serde(default = "rigid")]
    pub rock: String,
    /// Fraction of the reference slip within which a cheaper level "is enough". Default 0.10.
    #[serde(default = "ten_percent")]
    pub enough: f64,
    /// Strength reduction (a step of the study). Default none.
    #[serde(default)]
    pub ssr: Option<SsrSpec>,
}

fn wedge_group() -> String {
    "block:wedge".into()
}
fn pga_axis() -> String {
    "pga".into()
}
fn mesh_axis() -> String {
    "mesh".into()
}
fn one() -> f64 {
    1.0
}
fn rigid() -> String {
    "rigid".into()
}
fn ten_percent() -> f64 {
    0.10
}

/// The wedge study kind.
pub struct WedgeKind {
    pub params: WedgeParams,
}

/// The study's FEM strength reduction (`<out>/ssr.json`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StudySsr {
    /// Mesh level and its size.
    pub mesh: String,
    /// The rock model of its scene (none in a result written before it was recorded).
    #[serde(default)]
    pub rock: Option<report::RockModel>,
    pub nodes: usize,
    pub elements: usize,
    pub result: crate::study::ssr::SsrResult,
    /// Limit equilibrium of the same wedge, and with H read as the crest height on plane A
    /// (the reading that reproduces the seed's quoted 1.68).
    pub le_fs: f64,
    pub le_fs_crest_on_a: f64,
    pub wall_time: f64,
}

impl WedgeKind {
    pub fn new(study: &Study) -> Result<WedgeKind, Error> {
        let params: WedgeParams = kind_params(study)?;
        let k = WedgeKind { params };
        k.check(study)?;
        Ok(k)
    }

    /// The limit-equilibrium / rigid-block wedge of `scene`: the study's `wedge` geometry with
    /// the strength of the scene's joints on planes A and B and the density of the wedge group.
    pub fn wedge_of(&self, scene: &Scene) -> WedgeInput {
        crate::studies::wedge::rigid_level::wedge_input_from_scene(&self.params.wedge, scene, &self.params.joints.a, &self.params.joints.b, &self.params.wedge_group)
    }

    /// The study's PGAs [g] with their labels, in axis order.
    pub fn pgas<'s>(&self, study: &'s Study) -> Vec<(f64, &'s str)> {
        study.axis(&self.params.pga_axis).map(|a| a.values.iter().filter_map(|v| v.variation.pga.map(|p| (p, v.label.as_str()))).collect()).unwrap_or_default()
    }

    /// The rock model of the main runs (`rock`; checked by [`StudyKind::check`]).
    pub fn main_rock(&self) -> report::RockModel {
        match self.params.rock.as_str() {
            "massless" => report::RockModel::Massless,
            "elastic" => report::RockModel::Elastic,
            _ => report::RockModel::Rigid,
        }
    }
}

impl StudyKind for WedgeKind {
    fn check(&self, study: &Study) -> Result<(), Error> {
        let p = &self.params;
        let invalid = |message: String| -> Error { StudyError::Invalid { path: study.path.clone(), message: format!("`report` (kind \"wedge\"): {message}") }.into() };
        let pga = study.axis(&p.pga_axis).ok_or_else(|| invalid(format!("no axis \"{}\" (`pga_axis`): the wedge study needs an axis of PGAs", p.pga_axis)))?;
        if let Some(v) = pga.values.iter().find(|v| v.variation.pga.is_none()) {
            return Err(invalid(format!("axis \"{}\" value \"{}\" sets no `pga`", p.pga_axis, v.label)));
        }
        let mesh = study.axis(&p.mesh_axis).ok_or_else(|| invalid(format!("no axis \"{}\" (`mesh_axis`): the wedge study needs an axis of mesh levels", p.mesh_axis)))?;
        for (what, l) in [("sweep_mesh", &p.sweep_mesh), ("reference.mesh", &p.reference.mesh)] {
            if mesh.value(l).is_none() {
                return Err(invalid(format!("`{what}` = \"{l}\" is not a value of axis \"{}\" ({})", p.mesh_axis, mesh.values.iter().map(|v| v.label.as_str()).collect::<Vec<_>>().join(", "))));
            }
        }
        if !(p.accuracy_pga.is_finite() && p.accuracy_pga > 0.0) {
            return Err(invalid(format!("`accuracy_pga` = {} must be a positive acceleration [g]", p.accuracy_pga)));
        }
        if !(1..=2).contains(&p.reference.layer) {
            return Err(invalid(format!("`reference.layer` = {} must be 1 or 2", p.reference.layer)));
        }
        if !matches!(p.rock.as_str(), "rigid" | "massless" | "elastic") {
            return Err(invalid(format!("`rock` = \"{}\" must be \"rigid\", \"massless\" or \"elastic\"", p.rock)));
        }
        if !(p.enough > 0.0 && p.enough < 1.0) {
            return Err(invalid(format!("`enough` = {} must be a fraction in (0, 1)", p.enough)));
        }
        if let Some(s) = &p.ssr
            && !(s.bracket[0] > 0.0 && s.bracket[0] < s.bracket[1] && s.tolerance > 0.0 && s.slip_limit > 0.0 && s.max_steps > 0)
        {
            return Err(invalid(format!("`ssr`: bracket {:?} must be 0 < low < high, tolerance, slip_limit and max_steps positive", s.bracket)));
        }
        let base = Scene::load(&study.scene)?;
        for j in [&p.joints.a, &p.joints.b] {
            if !base.joints.iter().any(|x| &x.name == j) {
                return Err(invalid(format!("`joints`: the base scene has no joint \"{j}\" (joints: {})", base.joints.iter().map(|x| x.name.as_str()).collect::<Vec<_>>().join(", "))));
            }
        }
        for m in [&p.monitors.p1, &p.monitors.p2_wedge, &p.monitors.p2_rock] {
            if !base.output.monitor.iter().any(|x| &x.name == m) {
                return Err(invalid(format!("`monitors`: the base scene has no monitor \"{m}\"")));
            }
        }
        if base.loads.gravity.as_ref().and_then(|g| g.groups.as_ref()).is_none() {
            return Err(invalid("the base scene's gravity must name the sliding blocks in `loads.gravity.groups` (the other volumes are the rock)".into()));
        }
        Ok(())
    }

    fn steps(&self) -> Vec<StepSpec> {
        match &self.params.ssr {
            Some(_) => vec![StepSpec { name: "ssr".into(), output: "ssr.json".into(), about: "strength reduction".into() }],
            None => vec![],
        }
    }

    fn run_step(&self, study: &Study, name: &str, opts: &StepOptions) -> Result<StepOutput, Error> {
        let Some(spec) = self.params.ssr.as_ref().filter(|_| name == "ssr") else {
            return Err(StudyError::Invalid { path: study.path.clone(), message: format!("the wedge study has no step \"{name}\"") }.into());
        };
        let r = self.run_ssr(study, spec, &opts.mesh_cache)?;
        let mut lines = vec![format!(
            "strength reduction ({} mesh, {} elements): F = {:.4} (bracket {:.4}–{:.4}); limit equilibrium {:.4} → {:+.1} %",
            r.mesh, r.elements, r.result.factor, r.result.bracket[0], r.result.bracket[1], r.le_fs, 100.0 * (r.result.factor / r.le_fs - 1.0)
        )];
        for t in &r.result.trials {
            lines.push(format!(
                "  F = {:.4}: {} (steps {}, residual {:.1e}, max slip {:.3e} m, |u| P1 {:.3e} m)",
                t.factor, if t.failed { "fails" } else { "stable" }, t.steps, t.residual, t.max_slip, t.monitor_displacement
            ));
        }
        lines.push(format!("  in {:.1} s", r.wall_time));
        Ok(StepOutput { json: serde_json::to_value(&r).expect("serialises"), lines })
    }

    fn report(&self, results: &StudyResults) -> Result<KindReport, Error> {
        report::write(self, results)
    }

    fn run_charts(&self, _study: &Study, scene: &Path, run_dir: &Path) -> Result<RunCharts, Error> {
        report::run_charts(self, scene, run_dir)
    }
}

impl WedgeKind {
    /// Strength reduction of the study's wedge: the scene of `spec.run` without its base
    /// records (gravity only), bisection on F (see [`crate::study::ssr`] for the failure
    /// criterion).
    fn run_ssr(&self, study: &Study, spec: &SsrSpec, mesh_cache: &Path) -> Result<StudySsr, Error> {
        let t0 = std::time::Instant::now();
        let base = crate::study::plan::load_base(study)?;
        let labels: Vec<(&str, &str)> = spec.run.iter().map(|(a, l)| (a.as_str(), l.as_str())).collect();
        let level = match spec.run.get(&self.params.mesh_axis) {
            Some(l) => l.clone(),
            None => study.axis(&self.params.mesh_axis).map(|a| a.values[0].label.clone()).unwrap_or_default(),
        };
        let mut scene = scene_for(study, &base, &labels, &[], &format!("ssr-{level}"))?;
        scene.loads.base.clear();
        let mesh = crate::pipeline::load_scene_mesh(&mut scene, &study.scene, Some(mesh_cache))?;
        let p1 = scene.output.monitor.iter().find(|m| m.name == self.params.monitors.p1).map(|m| m.point);
        let ssr_opts = crate::study::ssr::SsrOptions {
            bracket: spec.bracket,
            tolerance: spec.tolerance,
            max_steps: spec.max_steps,
            residual: 1e-5,
            slip_limit: spec.slip_limit,
            monitor: p1,
        };
        let (nodes, elements) = (mesh.nodes.len(), mesh.cells.iter().filter(|c| c.kind.dim() == 3).count());
        let result = crate::study::ssr::strength_reduction(&mesh, &scene, &ssr_opts)?;
        let le_wedge = self.wedge_of(&scene);
        let le_fs = analyse_wedge(&le_wedge)?.fs;
        let le_fs_crest_on_a = analyse_wedge(&WedgeInput { height_def: HeightDef::CrestOnA, ..le_wedge })?.fs;
        if !le_fs.is_finite() {
            return Err(ModelError::Invalid("limit equilibrium of the study's wedge gave no finite FS".into()).into());
        }
        Ok(StudySsr { mesh: level, rock: Some(report::rock_model(&scene)), nodes, elements, result, le_fs, le_fs_crest_on_a, wall_time: t0.elapsed().as_secs_f64() })
    }
}
