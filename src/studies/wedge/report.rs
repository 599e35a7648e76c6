//! The wedge study's metrics, tables and charts: reads the runs through the engine's typed
//! results ([`crate::study::StudyResults`]), adds the rigid-block and limit-equilibrium levels,
//! and returns the Markdown and JSON of the report; charts go to `<out>/charts/*.png` and `.svg`.
//!
//! Quantities (SI; slip and displacements in m, times in s):
//! - residual slip: relative displacement of the wedge and rock nodes at P2 along the line of
//!   intersection (positive down it) at the end of the run, from its value after gravity;
//! - P1 residual displacement: the wedge node's displacement at the end minus after gravity;
//! - still sliding: the slip rate over the last 0.5 s of the run exceeds 1 mm/s;
//! - failure mode, from the joint histories over the samples where the slip grows by more than
//!   1 mm/s: "none" (residual slip < 1 cm), "sliding on both planes", "sliding on plane A only" /
//!   "on plane B only" (the other joint fully open during more than 20 % of the sliding
//!   samples), "lift-off" (both joints fully open during more than 1 % of all samples); "large"
//!   is added when the slip exceeds 10 % of the line of intersection (the wedge has moved out
//!   of its bed: contact area and support are no longer those of limit equilibrium).

use super::{StudySsr, WedgeKind, WedgeParams};
use crate::dynamics::loads::base_motions;
use crate::error::{Error, OutputError};
use crate::output::history::HistoryTable;
use crate::report::{fmt_percent, fmt_sig, pareto_front, Axis, Chart, Series, Table};
use crate::rigid::wedge::{analyse_wedge, build_wedge, HeightDef, WedgeInput};
use crate::scene::Scene;
use crate::studies::wedge::rigid_level::{rigid_wedge_slip, sample_ground_motion, Bond, RigidWedgeRun};
use crate::study::{scene_for, KindReport, RunCharts, RunResult, StudyResults, Variation};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// A monitored point's history: time, displacement and acceleration (relative to the base).
#[derive(Clone, Debug, Default)]
pub struct PointHistory {
    pub t: Vec<f64>,
    pub u: Vec<[f64; 3]>,
    pub a: Vec<[f64; 3]>,
}

impl PointHistory {
    /// The columns `t`, `ux..uz`, `ax..az` of a monitor history, by name.
    pub fn from_table(h: &HistoryTable) -> Result<PointHistory, OutputError> {
        if h.is_empty() {
            return Err(OutputError::read(&h.path, "no history rows (did the run stop before its first step?)"));
        }
        Ok(PointHistory { t: h.column("t")?.to_vec(), u: h.vectors(["ux", "uy", "uz"])?, a: h.vectors(["ax", "ay", "az"])? })
    }

    /// Read a monitor history file (`histories/<name>.csv`).
    pub fn read(path: &Path) -> Result<PointHistory, OutputError> {
        PointHistory::from_table(&HistoryTable::read(path)?)
    }
}

/// Per-sample counts of a joint history (columns `t`, `open`, `stick`, `slip`, `bonded`,
/// `max_opening`).
#[derive(Clone, Debug, Default)]
pub struct JointCounts {
    pub t: Vec<f64>,
    pub open: Vec<u32>,
    pub in_contact: Vec<u32>,
    pub max_opening: f64,
}

fn joint_counts(h: &HistoryTable) -> Result<JointCounts, OutputError> {
    let (t, open, stick, slip, bonded, mo) = (h.column("t")?, h.column("open")?, h.column("stick")?, h.column("slip")?, h.column("bonded")?, h.column("max_opening")?);
    Ok(JointCounts {
        t: t.to_vec(),
        open: open.iter().map(|&x| x as u32).collect(),
        in_contact: (0..h.len()).map(|i| (stick[i] + slip[i] + bonded[i]) as u32).collect(),
        max_opening: mo.iter().copied().fold(0.0, f64::max),
    })
}

/// The rock model of a run (see the module doc of [`super`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RockModel {
    /// The rock's nodes fixed: the wedge feels the base motion itself.
    Rigid,
    /// The rock elastic and massless (condensed statically, docs/dam_physics.md §1), with the
    /// weightless massive layer of elements along the joint faces.
    Massless,
    /// The rock elastic with its mass (a closed box without absorbing boundaries).
    Elastic,
}

impl RockModel {
    pub fn describe(self) -> &'static str {
        match self {
            RockModel::Rigid => "rigid rock",
            RockModel::Massless => "massless elastic rock",
            RockModel::Elastic => "elastic rock with mass",
        }
    }
}

/// The cohesion law of a run's joints (its first joint; the study sets every joint alike).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CohesionLaw {
    /// Mohr-Coulomb with the cohesion kept after slip and opening (the seed's law).
    Kept,
    /// Cohesion softening linearly to zero over `slip` [m] of a pair's accumulated slip.
    Softening { slip: f64 },
    /// Cohesion lost at a pair's first slip or opening.
    Brittle,
    /// The bilinear (Patton 1966) envelope min(tan(φ + i) σ, c + σ tan φ) of the joints'
    /// `asperity_angle` i [deg], with the cohesion kept (`kept`) or lost after slip.
    Patton { asperity_angle: f64, kept: bool },
}

impl CohesionLaw {
    fn of(j: &crate::scene::JointSceneSpec) -> CohesionLaw {
        if let Some(i) = j.asperity_angle {
            return CohesionLaw::Patton { asperity_angle: i, kept: j.keep_cohesion == Some(true) };
        }
        match (j.keep_cohesion, j.softening_slip) {
            (Some(true), _) => CohesionLaw::Kept,
            (_, Some(d)) if d > 0.0 => CohesionLaw::Softening { slip: d },
            _ => CohesionLaw::Brittle,
        }
    }

    pub fn describe(self) -> String {
        match self {
            CohesionLaw::Kept => "cohesion kept (Mohr-Coulomb, no softening: the seed's law)".into(),
            CohesionLaw::Softening { slip } => format!("cohesion lost after slip (softening to zero over {} mm)", fmt_sig_short(slip * 1e3)),
            CohesionLaw::Brittle => "cohesion lost at the first slip (brittle)".into(),
            CohesionLaw::Patton { asperity_angle, kept } => format!("bilinear (Patton) envelope, asperity angle i = {}°, cohesion {}", fmt_sig_short(asperity_angle), if kept { "kept" } else { "lost after slip" }),
        }
    }

    /// The rigid block's bond for this law: kept, or lost at the first slide (the rigid block
    /// has the Mohr–Coulomb cone; with the Patton envelope, that of its cohesion).
    pub fn bond(self) -> Bond {
        match self {
            CohesionLaw::Kept | CohesionLaw::Patton { kept: true, .. } => Bond::Kept,
            _ => Bond::Brittle,
        }
    }

    /// The rigid block's label for this law's bond.
    pub fn rigid_label(self) -> &'static str {
        if self.bond() == Bond::Kept { "cohesion kept" } else { "cohesion lost at first slide" }
    }
}

/// What a FEM run of the wedge study is, read from its scene and its labels (see the module
/// doc of [`super`]).
#[derive(Clone, Debug, Serialize)]
pub struct WedgeRunSpec {
    pub id: String,
    /// Label on the mesh axis.
    pub mesh: String,
    /// Contact method of its joints ("nts", "ntn", "penalty") and candidate layer.
    pub method: String,
    pub layer: u8,
    /// Horizontal PGA [g].
    pub pga: f64,
    /// Factor on the Young's modulus (run scene over base scene).
    pub e_factor: f64,
    /// The rock model.
    pub rock: RockModel,
    /// The joints' cohesion law.
    pub law: CohesionLaw,
    /// Stiffness-proportional Rayleigh coefficient β of the run [s].
    pub beta: f64,
}

impl WedgeRunSpec {
    /// Short label of the model level, e.g. "NTS-L1 medium".
    pub fn level(&self) -> String {
        let m = if self.method == "nts" { format!("NTS-L{}", self.layer) } else { self.method.to_uppercase() };
        format!("{m} {}", self.mesh)
    }

    fn of(kind: &WedgeKind, run: &RunResult, base: &Scene) -> Result<WedgeRunSpec, String> {
        let scene = run.scene.as_ref().ok_or("its scene cannot be read")?;
        let mesh = run.spec.label(&kind.params.mesh_axis).ok_or_else(|| format!("no label on the mesh axis \"{}\"", kind.params.mesh_axis))?.to_string();
        let pga = run.spec.pga.ok_or("the run sets no `pga`")?;
        let j = scene.joints.first().ok_or("its scene has no joints")?;
        let e0 = base.materials.first().map(|m| m.e).ok_or("the base scene has no material")?;
        let e = scene.materials.first().map(|m| m.e).ok_or("its scene has no material")?;
        Ok(WedgeRunSpec {
            id: run.spec.id.clone(),
            mesh,
            method: j.method().as_str().to_string(),
            layer: j.layer.unwrap_or(1),
            pga,
            e_factor: e / e0,
            rock: rock_model(scene),
            law: CohesionLaw::of(j),
            beta: stiffness_damping(scene),
        })
    }
}

/// The rock model of `scene`: its rock is the volumes outside `loads.gravity.groups`.
pub fn rock_model(scene: &Scene) -> RockModel {
    let weighted = scene.loads.gravity.as_ref().and_then(|g| g.groups.clone()).unwrap_or_default();
    let rock: Vec<&crate::scene::MaterialSpec> = scene.materials.iter().filter(|m| !weighted.contains(&m.group)).collect();
    if scene.boundary.iter().any(|b| rock.iter().any(|m| m.group == b.group)) {
        RockModel::Rigid
    } else if rock.iter().any(|m| m.massless) {
        RockModel::Massless
    } else {
        RockModel::Elastic
    }
}

/// The stiffness-proportional damping coefficient β [s] of `scene` (0 when its damping is
/// invalid: the scene was validated when it was planned).
fn stiffness_damping(scene: &Scene) -> f64 {
    scene.damping.coefficients().map(|c| c.1).unwrap_or(0.0)
}

/// The outcome of one FEM run, as the report uses it.
#[derive(Clone, Debug, Serialize)]
pub struct WedgeRun {
    pub spec: WedgeRunSpec,
    pub level: String,
    /// The error that stopped the run (its histories end there), if any.
    pub failed: Option<String>,
    /// Size, step and cost from the run's summary (none for a failed run).
    pub nodes: Option<usize>,
    pub elements: Option<usize>,
    pub dt: Option<f64>,
    pub steps: Option<usize>,
    /// Wall time of the whole run (mesh read, model, equilibrium, dynamics) on one thread [s].
    pub wall_time: Option<f64>,
    pub residual_slip: f64,
    pub max_slip: f64,
    pub p1_residual: [f64; 3],
    pub still_sliding: bool,
    pub mode: String,
    /// Largest joint opening of each joint [m] (name, value).
    pub max_opening: Vec<(String, f64)>,
    /// Slave node-steps that found no master face (search event `lost`), per joint (from the
    /// summary: none for a failed run).
    pub lost_node_steps: Vec<(String, Option<u64>)>,
    /// Peak absolute acceleration of the rock monitor (x, y, z) [g], if the scene has it: the
    /// motion the rock delivers under the wedge, to compare with the PGA.
    pub rock_peak_accel: Option<[f64; 3]>,
    /// Residual slip of the rigid block driven by the rock monitor's computed absolute motion
    /// (with the run's bond: kept, or lost at the first slide) [m]: the rigid level with the
    /// FEM's site response.
    pub rigid_on_rock_slip: Option<f64>,
    /// First time at which the slip exceeds 1 mm [s] (none if it never does).
    pub onset: Option<f64>,
    /// Slip history (t, slip) sampled for charts (at most about 2000 points).
    #[serde(skip)]
    pub slip_history: Vec<(f64, f64)>,
    #[serde(skip)]
    pub p1_history: Vec<(f64, [f64; 3])>,
}

/// Slip along `e` of the P2 pair, from its first sample.
fn slip_series(w: &PointHistory, r: &PointHistory, e: [f64; 3]) -> Vec<(f64, f64)> {
    let n = w.t.len().min(r.t.len());
    let s = |i: usize| (0..3).map(|c| (w.u[i][c] - r.u[i][c]) * e[c]).sum::<f64>();
    let s0 = s(0);
    (0..n).map(|i| (w.t[i], s(i) - s0)).collect()
}

/// A history sampled every `dt` from t = 0 as (t, value) points for a chart (thinned).
fn sampled_history(h: &[f64], dt: f64) -> Vec<(f64, f64)> {
    thin(&h.iter().enumerate().map(|(i, &d)| (i as f64 * dt, d)).collect::<Vec<_>>(), 2000)
}

/// Every `stride`-th sample so that at most about `max` remain, always with the last one.
fn thin<T: Copy>(v: &[T], max: usize) -> Vec<T> {
    let stride = v.len().div_ceil(max.max(1)).max(1);
    let mut out: Vec<T> = v.iter().step_by(stride).copied().collect();
    if let Some(last) = v.last()
        && (v.len() - 1) % stride != 0
    {
        out.push(*last);
    }
    out
}

fn classify_mode(slip: &[(f64, f64)], joints: &[(String, JointCounts)], residual: f64, line_length: f64) -> String {
    if residual.abs() < 0.01 {
        return "none".into();
    }
    let n = slip.len();
    let mut sliding = vec![false; n];
    for i in 1..n {
        let dt = slip[i].0 - slip[i - 1].0;
        sliding[i] = dt > 0.0 && (slip[i].1 - slip[i - 1].1) / dt > 1e-3;
    }
    let nslide = sliding.iter().filter(|&&s| s).count().max(1);
    let fully_open = |c: &JointCounts, i: usize| c.in_contact.get(i).is_some_and(|&k| k == 0);
    let mut both_open = 0;
    let m = joints.iter().map(|(_, c)| c.t.len()).min().unwrap_or(0);
    for i in 0..m {
        if joints.iter().all(|(_, c)| fully_open(c, i)) {
            both_open += 1;
        }
    }
    let mut mode = if m > 0 && both_open as f64 > 0.01 * m as f64 {
        "lift-off".to_string()
    } else {
        let mut one = None;
        for (k, (name, c)) in joints.iter().enumerate() {
            let open_sliding = (0..n.min(c.t.len())).filter(|&i| sliding[i] && fully_open(c, i)).count();
            if open_sliding as f64 > 0.2 * nslide as f64 {
                let other = joints.iter().enumerate().find(|(o, _)| *o != k).map(|(_, j)| j.0.clone()).unwrap_or_default();
                one = Some(format!("sliding on plane {other} only ({name} open)"));
            }
        }
        one.unwrap_or_else(|| "sliding on both planes".into())
    };
    if residual.abs() > 0.1 * line_length {
        mode.push_str(", large (slip > 10 % of the line of intersection)");
    }
    mode
}

/// Read one run's results (finished, or failed with its histories up to the error).
fn read_run(kind: &WedgeKind, res: &RunResult, base: &Scene, e: [f64; 3], line_length: f64) -> Result<WedgeRun, Error> {
    let spec = WedgeRunSpec::of(kind, res, base).map_err(|m| OutputError::read(&res.dir, m))?;
    let mons = &kind.params.monitors;
    let hist = |name: &str| -> Result<PointHistory, OutputError> { PointHistory::from_table(&res.history(name)?) };
    let (w, r, p1) = (hist(&mons.p2_wedge)?, hist(&mons.p2_rock)?, hist(&mons.p1)?);
    let slip = slip_series(&w, &r, e);
    let (residual, t_end) = slip.last().map(|s| (s.1, s.0)).expect("non-empty history");
    let max_slip = slip.iter().map(|s| s.1.abs()).fold(0.0, f64::max);
    let still_sliding = slip.iter().find(|s| s.0 >= t_end - 0.5).map(|s0| {
        let dt = t_end - s0.0;
        dt > 0.0 && ((residual - s0.1) / dt).abs() > 1e-3
    }) == Some(true);
    let u0 = p1.u[0];
    let ue = *p1.u.last().expect("non-empty history");
    let p1_residual = [ue[0] - u0[0], ue[1] - u0[1], ue[2] - u0[2]];
    let mut joints = Vec::new();
    let mut max_opening = Vec::new();
    let mut lost = Vec::new();
    // the joints: from the summary of a finished run, else (a failed run has none) the scene's
    let scene = res.scene.as_ref().expect("a run with a spec has its scene");
    let names: Vec<String> = match &res.summary {
        Some(s) => s.joints.iter().map(|j| j.name.clone()).collect(),
        None => scene.joints.iter().map(|j| j.name.clone()).collect(),
    };
    for name in names {
        let c = joint_counts(&res.joint_history(&name)?)?;
        let peaks = res.summary.as_ref().and_then(|s| s.joints.iter().find(|j| j.name == name));
        max_opening.push((name.clone(), peaks.map_or(c.max_opening, |j| j.max_opening)));
        lost.push((name.clone(), peaks.map(|j| j.events.lost)));
        joints.push((name, c));
    }
    let mode = classify_mode(&slip, &joints, residual, line_length);
    // the rock's own motion under the wedge (absolute = relative + ground)
    let (mut rock_peak_accel, mut rigid_on_rock_slip) = (None, None);
    if scene.output.monitor.iter().any(|m| m.name == mons.rock) {
        let rh = hist(&mons.rock)?;
        let (motions, _) = base_motions(scene)?;
        let abs: Vec<[f64; 3]> = rh
            .t
            .iter()
            .zip(&rh.a)
            .map(|(&t, a)| {
                let g = crate::dynamics::loads::ground_acceleration_of(&motions, t);
                [a[0] + g[0], a[1] + g[1], a[2] + g[2]]
            })
            .collect();
        let mut pk = [0.0f64; 3];
        for a in &abs {
            for c in 0..3 {
                pk[c] = pk[c].max(a[c].abs() / scene.g);
            }
        }
        rock_peak_accel = Some(pk);
        if rh.t.len() > 2 {
            let dt = rh.t[1] - rh.t[0];
            // a wedge that the rock's motion lifts off its planes has no rigid-block answer
            if let Ok(r) = rigid_wedge_slip(&kind.wedge_of(scene), &abs, dt, spec.law.bond(), false) {
                rigid_on_rock_slip = Some(r.result.residual_displacement);
            }
        }
    }
    let p1_h: Vec<(f64, [f64; 3])> = p1.t.iter().zip(&p1.u).map(|(&t, u)| (t, [u[0] - u0[0], u[1] - u0[1], u[2] - u0[2]])).collect();
    let s = res.summary.as_ref();
    Ok(WedgeRun {
        level: spec.level(),
        spec,
        failed: res.failed().map(str::to_string),
        nodes: s.map(|s| s.nodes),
        elements: s.map(|s| s.elements),
        dt: s.map(|s| s.dt),
        steps: s.map(|s| s.steps),
        wall_time: s.map(|s| s.wall_time),
        residual_slip: residual,
        max_slip,
        p1_residual,
        still_sliding,
        mode,
        max_opening,
        lost_node_steps: lost,
        rock_peak_accel,
        rigid_on_rock_slip,
        onset: slip.iter().find(|x| x.1 > 1e-3).map(|x| x.0),
        slip_history: thin(&slip, 2000),
        p1_history: thin(&p1_h, 2000),
    })
}

/// The rigid level at one PGA.
#[derive(Clone, Debug, Serialize)]
pub struct RigidAtPga {
    pub pga: f64,
    pub brittle: RigidWedgeRun,
    pub kept: RigidWedgeRun,
    /// Compute time of the brittle run [s] (for the speed-against-accuracy chart).
    pub wall_time: f64,
}

impl RigidAtPga {
    /// The rigid block with `bond`.
    pub fn of_bond(&self, bond: Bond) -> &RigidWedgeRun {
        match bond {
            Bond::Kept => &self.kept,
            Bond::Brittle => &self.brittle,
        }
    }

    /// The rigid block that goes with the joints' `law` (kept, or lost at the first slide).
    pub fn bond(&self, law: CohesionLaw) -> &RigidWedgeRun {
        self.of_bond(law.bond())
    }
}

/// The rigid level at one PGA: the scene of the study at that PGA (the other axes at their
/// first value: the rigid level reads only the records, the duration and the joints).
fn rigid_at(kind: &WedgeKind, results: &StudyResults, pga: f64, label: Option<&str>) -> Result<RigidAtPga, Error> {
    let scene = match label {
        Some(l) => scene_for(results.study, &results.base, &[(kind.params.pga_axis.as_str(), l)], &[], "rigid")?,
        None => scene_for(results.study, &results.base, &[], &[Variation { pga: Some(pga), ..Default::default() }], "rigid")?,
    };
    let (motions, _) = base_motions(&scene)?;
    let dt = motions.iter().map(|b| b.record.dt).fold(f64::INFINITY, f64::min);
    let t0 = std::time::Instant::now();
    let a = sample_ground_motion(&motions, dt, scene.time.duration);
    let wedge = kind.wedge_of(&scene);
    let brittle = rigid_wedge_slip(&wedge, &a, dt, Bond::Brittle, true)?;
    let wall_time = t0.elapsed().as_secs_f64();
    let kept = rigid_wedge_slip(&wedge, &a, dt, Bond::Kept, true)?;
    Ok(RigidAtPga { pga, brittle, kept, wall_time })
}

/// Everything the report states, also written as `report.json`.
#[derive(Clone, Debug, Serialize)]
pub struct WedgeReport {
    pub le: LeTable,
    pub ssr: Option<StudySsr>,
    pub runs: Vec<WedgeRun>,
    pub rigid: Vec<RigidAtPga>,
    /// For each PGA: the cheapest level within `enough` of the reference slip.
    pub cheapest: Vec<(f64, String, f64, f64)>,
    pub trend: Vec<String>,
    /// The seed's claims against the headline runs.
    pub claims: Vec<SeedClaim>,
    /// The headline's joint law and stiffness-proportional damping β [s] (the base scene's).
    pub headline_law: CohesionLaw,
    pub headline_beta: f64,
}

/// Limit-equilibrium numbers of the report.
#[derive(Clone, Debug, Serialize)]
pub struct LeTable {
    pub fs_intersection: f64,
    pub fs_crest_on_a: f64,
    pub fs_friction_only: f64,
    pub kc_intact: Option<f64>,
    pub kc_residual: Option<f64>,
    pub line_length: f64,
}

fn find(runs: &[WedgeRun], pred: impl Fn(&WedgeRunSpec) -> bool) -> Option<&WedgeRun> {
    runs.iter().find(|r| pred(&r.spec))
}

/// A number with 4 significant digits; values below 1e-12 in magnitude (round-off of a
/// slip that did not happen) print as 0.
fn m(x: f64) -> String {
    if x.abs() < 1e-12 { "0".into() } else { fmt_sig(x, 4) }
}

/// A number in its shortest form with at most 4 significant digits (20 → "20", 24.5 → "24.5").
fn fmt_sig_short(x: f64) -> String {
    let r = format!("{}", (x * 1e4).round() / 1e4);
    r
}

fn opt(x: Option<f64>) -> String {
    x.map_or_else(|| "–".to_string(), m)
}

/// The seed's quoted results (seed paper, section 4, Koyna record): residual slip at P2 at
/// 1.0 g [m], NTS and NTN; P1 residual displacement at 1.0 g [m] (x, y, z); the time at which
/// the wedge starts to slide at 1.0 g [s]; the PGA at and below which it does not slide
/// noticeably [g]; its strength-reduction factor and the DDA and FEM factors it quotes.
pub mod seed {
    pub const SLIP_NTS_1G: f64 = 0.186;
    pub const SLIP_NTN_1G: f64 = 0.147;
    pub const P1_NTS_1G: [f64; 3] = [0.072, -0.143, -0.102];
    pub const P1_NTN_1G: [f64; 3] = [0.056, -0.113, -0.082];
    pub const ONSET_1G: f64 = 2.4;
    pub const NO_SLIDING_UP_TO: f64 = 0.5;
    pub const PGA: f64 = 1.0;
}

/// One of the seed's claims and what our runs give.
#[derive(Clone, Debug, Serialize)]
pub struct SeedClaim {
    pub claim: String,
    pub seed: String,
    pub ours: String,
    /// Reproduced (true), not (false), or not decidable from the runs (none).
    pub reproduced: Option<bool>,
}

/// Angle between two vectors [deg].
fn angle_deg(a: [f64; 3], b: [f64; 3]) -> f64 {
    let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let na = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    let nb = (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]).sqrt();
    (dot / (na * nb)).clamp(-1.0, 1.0).acos().to_degrees()
}

fn cm3(u: [f64; 3]) -> String {
    format!("({}, {}, {}) cm", fmt_sig(u[0] * 100.0, 3), fmt_sig(u[1] * 100.0, 3), fmt_sig(u[2] * 100.0, 3))
}

/// What the sections of the wedge report share: the study, its runs as read, the rigid level
/// at every PGA, and the headline's choices. Built once by [`write`].
struct Ctx<'a> {
    prm: &'a WedgeParams,
    results: &'a StudyResults<'a>,
    base: &'a Scene,
    runs: Vec<WedgeRun>,
    /// Failed runs whose histories cannot be read (stopped before the first step): listed with
    /// the stopped runs.
    stopped_early: Vec<(String, String)>,
    rigid: Vec<RigidAtPga>,
    pgas: Vec<f64>,
    /// The mesh level of the PGA sweep and of the reference.
    sweep: String,
    reference: String,
    /// The headline: the base scene's rock, law and stiffness-proportional damping β [s].
    main_rock: RockModel,
    main_law: CohesionLaw,
    main_beta: f64,
    /// The variant laws (the laws of the runs that are not the headline's, in the order of the
    /// runs), if any.
    other_laws: Vec<CohesionLaw>,
    /// The accuracy PGA [g].
    acc: f64,
    charts_dir: PathBuf,
}

impl Ctx<'_> {
    fn rigid_of(&self, pga: f64) -> &RigidAtPga {
        self.rigid.iter().find(|r| r.pga == pga).expect("rigid level of every PGA")
    }

    /// The rigid block's residual slip at `pga` with the headline's law [m].
    fn rigid_main(&self, pga: f64) -> f64 {
        self.rigid_of(pga).bond(self.main_law).result.residual_displacement
    }

    /// A headline run (the main rock, law and damping, E as given).
    fn plain(&self, s: &WedgeRunSpec) -> bool {
        s.e_factor == 1.0 && s.rock == self.main_rock && s.law == self.main_law && s.beta == self.main_beta
    }

    /// The reference level's headline run.
    fn is_ref(&self, s: &WedgeRunSpec) -> bool {
        self.plain(s) && s.mesh == self.reference && s.method == "nts" && s.layer == self.prm.reference.layer
    }

    /// A run of the variant law `law` (otherwise as the headline).
    fn variant(&self, s: &WedgeRunSpec, law: CohesionLaw) -> bool {
        s.law == law && s.e_factor == 1.0 && s.rock == self.main_rock && s.beta == self.main_beta
    }

    /// The first run that did not fail among those `pred` selects.
    fn run_of(&self, pred: &dyn Fn(&WedgeRunSpec) -> bool) -> Option<&WedgeRun> {
        find(&self.runs, pred).filter(|r| r.failed.is_none())
    }

    /// |residual slip| against PGA of the runs of one level (`method`, `mesh`, `layer`) that
    /// `sel` selects.
    fn pts(&self, method: &str, mesh: &str, layer: u8, sel: &dyn Fn(&WedgeRunSpec) -> bool) -> Vec<(f64, f64)> {
        self.pgas
            .iter()
            .filter_map(|&p| self.run_of(&|s| sel(s) && s.pga == p && s.method == method && s.mesh == mesh && s.layer == layer).map(|r| (p, r.residual_slip.abs())))
            .collect()
    }

    /// The runs on a rock model other than the headline's.
    fn other_rock(&self) -> Vec<&WedgeRun> {
        self.runs.iter().filter(|r| r.spec.rock != self.main_rock).collect()
    }

    /// The other rock models, in the order of the runs.
    fn other_rocks(&self) -> Vec<RockModel> {
        self.other_rock().iter().fold(Vec::new(), |mut v, r| {
            if !v.contains(&r.spec.rock) {
                v.push(r.spec.rock);
            }
            v
        })
    }

    /// The joint names as the tables' column heads write them ("A / B").
    fn joint_names(&self) -> String {
        self.base.joints.iter().map(|j| j.name.as_str()).collect::<Vec<_>>().join(" / ")
    }
}

/// Residual slip against PGA of the headline's levels, the rigid block and the variant laws.
struct Curves {
    nts_sweep: Vec<(f64, f64)>,
    ntn_sweep: Vec<(f64, f64)>,
    nts2_sweep: Vec<(f64, f64)>,
    reference_pts: Vec<(f64, f64)>,
    rigid_kept_pts: Vec<(f64, f64)>,
    /// Per variant law (`Ctx::other_laws`' order): its NTS-L1 and NTN curves on the sweep mesh.
    variants: Vec<VariantCurves>,
}

/// The slip against PGA of one variant law: NTS-L1 and NTN on the sweep mesh.
struct VariantCurves {
    law: CohesionLaw,
    nts: Vec<(f64, f64)>,
    ntn: Vec<(f64, f64)>,
}

impl VariantCurves {
    /// Whether the variant law has runs to report.
    fn has_runs(&self) -> bool {
        !self.nts.is_empty() || !self.ntn.is_empty()
    }

    /// The stem of its chart: `slip_vs_pga_variant` for the first variant, then
    /// `slip_vs_pga_variant2`, ...
    fn chart_stem(k: usize) -> String {
        if k == 0 { "slip_vs_pga_variant".into() } else { format!("slip_vs_pga_variant{}", k + 1) }
    }
}

impl Curves {
    fn of(ctx: &Ctx<'_>) -> Curves {
        let plain = |s: &WedgeRunSpec| ctx.plain(s);
        let sweep = &ctx.sweep;
        let variants = ctx
            .other_laws
            .iter()
            .map(|&law| {
                let variant = |s: &WedgeRunSpec| ctx.variant(s, law);
                VariantCurves { law, nts: ctx.pts("nts", sweep, 1, &variant), ntn: ctx.pts("ntn", sweep, 1, &variant) }
            })
            .collect();
        Curves {
            nts_sweep: ctx.pts("nts", sweep, 1, &plain),
            ntn_sweep: ctx.pts("ntn", sweep, 1, &plain),
            nts2_sweep: ctx.pts("nts", sweep, 2, &plain),
            reference_pts: ctx.pts("nts", &ctx.reference, ctx.prm.reference.layer, &plain),
            rigid_kept_pts: ctx.pgas.iter().map(|&p| (p, ctx.rigid_main(p))).collect(),
            variants,
        }
    }
}

/// The headline runs at the accuracy PGA: NTS-L1 and NTN on the sweep mesh, the reference.
struct AtAcc<'r> {
    nts: Option<&'r WedgeRun>,
    ntn: Option<&'r WedgeRun>,
    reference: Option<&'r WedgeRun>,
}

impl<'r> AtAcc<'r> {
    fn of(ctx: &'r Ctx<'_>) -> AtAcc<'r> {
        let acc = ctx.acc;
        AtAcc {
            nts: ctx.run_of(&|s| ctx.plain(s) && s.pga == acc && s.method == "nts" && s.mesh == ctx.sweep && s.layer == 1),
            ntn: ctx.run_of(&|s| ctx.plain(s) && s.pga == acc && s.method == "ntn" && s.mesh == ctx.sweep),
            reference: ctx.run_of(&|s| ctx.is_ref(s) && s.pga == acc),
        }
    }
}

/// The levels' cost and error at the accuracy PGA: (level, wall time [s], slip [m], |error|
/// against the reference [-]) and the indices of the Pareto front.
struct SpeedAccuracy {
    levels: Vec<(String, f64, f64, f64)>,
    front: Vec<usize>,
}

/// The wedge study's part of the report (`report.md`, the `report` of `report.json`, the
/// charts in `<out>/charts/`). One function per section: the charts (`chart_*`) in the order
/// the report lists them, then the Markdown sections (`section_*`) in the order of the page.
pub fn write(kind: &WedgeKind, results: &StudyResults) -> Result<KindReport, Error> {
    let prm = &kind.params;
    let study = results.study;
    let base = &results.base;
    let geom = build_wedge(&prm.wedge)?;
    let line_length = (geom.p[0].powi(2) + geom.p[1].powi(2) + geom.p[2].powi(2)).sqrt();
    let (runs, stopped_early, mut unreadable) = read_runs(kind, results, geom.e, line_length);
    let ssr: Option<StudySsr> = match results.step::<StudySsr>("ssr") {
        Ok(s) => s,
        Err(e) => {
            unreadable.push(("step ssr".into(), e.to_string()));
            None
        }
    };
    let pga_list = kind.pgas(study);
    let pgas: Vec<f64> = pga_list.iter().map(|p| p.0).collect();
    let le_wedge = kind.wedge_of(base);
    let le_res = analyse_wedge(&le_wedge)?;
    let le_crest = analyse_wedge(&WedgeInput { height_def: HeightDef::CrestOnA, ..le_wedge.clone() })?;
    let mut rigid = Vec::new();
    for &(pga, label) in &pga_list {
        rigid.push(rigid_at(kind, results, pga, Some(label))?);
    }
    if !pgas.contains(&prm.accuracy_pga) {
        rigid.push(rigid_at(kind, results, prm.accuracy_pga, None)?);
    }
    let le = LeTable {
        fs_intersection: le_res.fs,
        fs_crest_on_a: le_crest.fs,
        fs_friction_only: le_res.fs_friction_only,
        kc_intact: rigid[0].brittle.kc_intact,
        kc_residual: rigid[0].brittle.kc_residual,
        line_length,
    };
    // the headline: the base scene's law, damping and stiffness on the main rock
    let main_law = base.joints.first().map(CohesionLaw::of).unwrap_or(CohesionLaw::Brittle);
    let mut other_laws: Vec<CohesionLaw> = Vec::new();
    for l in runs.iter().map(|r| r.spec.law).filter(|l| *l != main_law) {
        if !other_laws.contains(&l) {
            other_laws.push(l);
        }
    }
    let ctx = Ctx {
        prm,
        results,
        base,
        runs,
        stopped_early,
        rigid,
        pgas,
        sweep: prm.sweep_mesh.clone(),
        reference: prm.reference.mesh.clone(),
        main_rock: kind.main_rock(),
        main_law,
        main_beta: stiffness_damping(base),
        other_laws,
        acc: prm.accuracy_pga,
        charts_dir: results.plan.out.join("charts"),
    };
    let curves = Curves::of(&ctx);
    let at = AtAcc::of(&ctx);
    let sa = speed_accuracy(&ctx, &at);
    let mut charts = vec![chart_slip_vs_pga(&ctx, &curves)?];
    charts.extend(chart_slip_vs_pga_variants(&ctx, &curves)?);
    charts.extend(chart_slip_vs_pga_rock(&ctx)?);
    charts.push(chart_slip_history(&ctx, &at)?);
    charts.push(chart_p1_history(&ctx, &at)?);
    charts.push(chart_speed_accuracy(&ctx, &sa)?);
    charts.extend(chart_ssr(&ctx, ssr.as_ref())?);
    let cheapest = cheapest_levels(&ctx);
    let trend = trends(&ctx, &curves);
    let claims = seed_claims(&ctx, &curves, &at);

    let mut md = String::new();
    section_model(&mut md, &ctx);
    section_static_fs(&mut md, &le, ssr.as_ref());
    section_headline(&mut md, &ctx, &curves, &at);
    section_claims(&mut md, &claims, &trend);
    section_headline_detail(&mut md, &ctx);
    section_variant(&mut md, &ctx, &curves);
    section_rock(&mut md, &ctx);
    section_stiffness(&mut md, &ctx);
    section_speed_accuracy(&mut md, &ctx, &sa, at.reference, &cheapest, ssr.is_some());
    section_runs(&mut md, &ctx, ssr.as_ref());
    let mut lines = trend.clone();
    lines.extend(claims.iter().map(|c| format!("seed: {} — seed {}, ours {} ({})", c.claim, c.seed, c.ours, match c.reproduced {
        Some(true) => "reproduced",
        Some(false) => "not reproduced",
        None => "compare",
    })));
    let Ctx { runs, rigid, main_law, main_beta, .. } = ctx;
    let rep = WedgeReport { le, ssr, runs, rigid, cheapest, trend, claims, headline_law: main_law, headline_beta: main_beta };
    Ok(KindReport { markdown: md, json: serde_json::to_value(&rep).expect("the report serialises"), charts, lines, unreadable, lists_failed: true })
}

/// The runs with results, read: (the runs read, failed runs whose histories cannot be read as
/// (id, why), unreadable runs as (id, why)).
#[allow(clippy::type_complexity)]
fn read_runs(kind: &WedgeKind, results: &StudyResults, e: [f64; 3], line_length: f64) -> (Vec<WedgeRun>, Vec<(String, String)>, Vec<(String, String)>) {
    let mut runs = Vec::new();
    let mut unreadable = Vec::new();
    let mut stopped_early = Vec::new();
    for res in results.runs.iter().filter(|r| r.has_results()) {
        match (read_run(kind, res, &results.base, e, line_length), res.failed()) {
            (Ok(r), _) => runs.push(r),
            (Err(_), Some(f)) => stopped_early.push((res.spec.id.clone(), f.to_string())),
            (Err(err), None) => unreadable.push((res.spec.id.clone(), err.to_string())),
        }
    }
    (runs, stopped_early, unreadable)
}

// ---- charts ---------------------------------------------------------------------------------

/// Chart: slip against PGA, the headline's levels, the rigid block and the seed's values.
fn chart_slip_vs_pga(ctx: &Ctx<'_>, cv: &Curves) -> Result<PathBuf, Error> {
    let (sweep, reference, main_law) = (&ctx.sweep, &ctx.reference, ctx.main_law);
    let mut c = Chart::new(format!("Residual slip at P2 against PGA — {}", main_law.describe()), "horizontal PGA [g]", "residual slip along the line of intersection [m]");
    c.series.push(Series::line_markers(format!("NTS-L1, {sweep} mesh"), cv.nts_sweep.clone()));
    c.series.push(Series::line_markers(format!("NTN, {sweep} mesh"), cv.ntn_sweep.clone()));
    if !cv.nts2_sweep.is_empty() {
        c.series.push(Series::line_markers(format!("NTS-L2, {sweep} mesh"), cv.nts2_sweep.clone()));
    }
    if reference != sweep && !cv.reference_pts.is_empty() {
        c.series.push(Series::markers(format!("NTS-L{}, {reference} mesh (reference)", ctx.prm.reference.layer), cv.reference_pts.clone()));
    }
    c.series.push(Series::line_markers(format!("rigid block, {}", main_law.rigid_label()), cv.rigid_kept_pts.clone()));
    c.series.push(Series::markers("seed NTS (Koyna record)", [(seed::PGA, seed::SLIP_NTS_1G)]));
    c.series.push(Series::markers("seed NTN (Koyna record)", [(seed::PGA, seed::SLIP_NTN_1G)]));
    Ok(c.write_png_svg(&ctx.charts_dir.join("slip_vs_pga"))?.png)
}

/// Charts: slip against PGA with each variant law that has runs
/// ([`VariantCurves::chart_stem`]).
fn chart_slip_vs_pga_variants(ctx: &Ctx<'_>, cv: &Curves) -> Result<Vec<PathBuf>, Error> {
    let (sweep, main_law) = (&ctx.sweep, ctx.main_law);
    let mut out = Vec::new();
    for (k, v) in cv.variants.iter().enumerate().filter(|(_, v)| v.has_runs()) {
        let law = v.law;
        let mut c = Chart::new(format!("Residual slip at P2 against PGA — variant: {}", law.describe()), "horizontal PGA [g]", "residual slip along the line of intersection [m]");
        c.series.push(Series::line_markers(format!("NTS-L1, {sweep} mesh"), v.nts.clone()));
        c.series.push(Series::line_markers(format!("NTN, {sweep} mesh"), v.ntn.clone()));
        c.series.push(Series::line_markers(format!("rigid block, {}", law.rigid_label()), ctx.pgas.iter().map(|&p| (p, ctx.rigid_of(p).bond(law).result.residual_displacement))));
        c.series.push(Series::line_markers(format!("NTS-L1, {sweep} mesh, {} (headline)", if main_law == CohesionLaw::Kept { "cohesion kept" } else { "headline law" }), cv.nts_sweep.clone()));
        out.push(c.write_png_svg(&ctx.charts_dir.join(VariantCurves::chart_stem(k)))?.png);
    }
    Ok(out)
}

/// Chart: slip against PGA of the other rock models against the main rock (none without
/// other rock models).
fn chart_slip_vs_pga_rock(ctx: &Ctx<'_>) -> Result<Option<PathBuf>, Error> {
    let other_rock = ctx.other_rock();
    if other_rock.is_empty() {
        return Ok(None);
    }
    let mut c = Chart::new("Residual slip at P2 against PGA: rock models", "horizontal PGA [g]", "residual slip along the line of intersection [m]");
    let mut keys: Vec<(String, String, u8, RockModel)> = Vec::new();
    for r in &other_rock {
        let k = (r.spec.method.clone(), r.spec.mesh.clone(), r.spec.layer, r.spec.rock);
        if !keys.contains(&k) {
            keys.push(k);
        }
    }
    for (method, mesh, layer, rock) in keys {
        let same = |s: &WedgeRunSpec, rk: RockModel| s.rock == rk && s.law == ctx.main_law && s.beta == ctx.main_beta && s.e_factor == 1.0;
        let name = if method == "nts" { format!("NTS-L{layer}") } else { method.to_uppercase() };
        c.series.push(Series::line_markers(format!("{name}, {mesh} mesh, {}", rock.describe()), ctx.pts(&method, &mesh, layer, &|s| same(s, rock))));
        c.series.push(Series::line_markers(format!("{name}, {mesh} mesh, {}", ctx.main_rock.describe()), ctx.pts(&method, &mesh, layer, &|s| same(s, ctx.main_rock))));
    }
    Ok(Some(c.write_png_svg(&ctx.charts_dir.join("slip_vs_pga_rock"))?.png))
}

/// Chart: slip history at the accuracy PGA, the headline's levels and the rigid block.
fn chart_slip_history(ctx: &Ctx<'_>, at: &AtAcc<'_>) -> Result<PathBuf, Error> {
    let (acc, sweep, reference) = (ctx.acc, &ctx.sweep, &ctx.reference);
    let mut c = Chart::new(format!("Slip history at P2, PGA {acc} g — {}", ctx.main_law.describe()), "t [s]", "slip along the line of intersection [m]");
    for (r, name) in [(at.nts, format!("NTS-L1, {sweep}")), (at.ntn, format!("NTN, {sweep}")), (at.reference, format!("reference NTS-L{}, {reference}", ctx.prm.reference.layer))] {
        if let Some(r) = r {
            c.series.push(Series::line(name, r.slip_history.clone()));
        }
    }
    let ra = ctx.rigid_of(acc);
    for (bond, name) in [(Bond::Kept, "rigid block, cohesion kept"), (Bond::Brittle, "rigid block, cohesion lost at first slide")] {
        let rb = ra.of_bond(bond);
        if let Some(h) = &rb.result.history {
            c.series.push(Series::line(name, sampled_history(h, rb.dt)));
        }
    }
    Ok(c.write_png_svg(&ctx.charts_dir.join("slip_history"))?.png)
}

/// Chart: P1 displacement at the accuracy PGA, NTS and NTN.
fn chart_p1_history(ctx: &Ctx<'_>, at: &AtAcc<'_>) -> Result<PathBuf, Error> {
    let mut c = Chart::new(format!("Displacement of P1 (wedge, slope face), PGA {} g", ctx.acc), "t [s]", "displacement [m]");
    for (r, tag) in [(at.nts, "NTS"), (at.ntn, "NTN")] {
        if let Some(r) = r {
            for (k, axis) in ["x (east)", "y (north)", "z (up)"].iter().enumerate() {
                c.series.push(Series::line(format!("{tag} {axis}"), r.p1_history.iter().map(|(t, u)| (*t, u[k])).collect::<Vec<_>>()));
            }
        }
    }
    Ok(c.write_png_svg(&ctx.charts_dir.join("p1_history"))?.png)
}

/// The levels' cost and error at the accuracy PGA (headline runs), the rigid block first.
fn speed_accuracy(ctx: &Ctx<'_>, at: &AtAcc<'_>) -> SpeedAccuracy {
    let acc = ctx.acc;
    let ref_slip = at.reference.map(|r| r.residual_slip).unwrap_or(f64::NAN);
    let ra = ctx.rigid_of(acc);
    let rigid_acc = ra.bond(ctx.main_law);
    let mut sa: Vec<(String, f64, f64, f64)> = Vec::new(); // (level, wall, slip, error)
    sa.push(("rigid block".into(), ra.wall_time.max(1e-4), rigid_acc.result.residual_displacement, (rigid_acc.result.residual_displacement - ref_slip).abs() / ref_slip.abs()));
    for r in ctx.runs.iter().filter(|r| ctx.plain(&r.spec) && r.spec.pga == acc && !ctx.is_ref(&r.spec) && r.failed.is_none()) {
        let Some(wall) = r.wall_time else { continue };
        sa.push((r.level.clone(), wall, r.residual_slip, (r.residual_slip - ref_slip).abs() / ref_slip.abs()));
    }
    let pts_sa: Vec<(f64, f64)> = sa.iter().map(|x| (x.1, x.3.max(1e-4))).collect();
    let front = pareto_front(&pts_sa);
    SpeedAccuracy { levels: sa, front }
}

/// Chart: speed against accuracy at the accuracy PGA, with the Pareto front.
fn chart_speed_accuracy(ctx: &Ctx<'_>, sa: &SpeedAccuracy) -> Result<PathBuf, Error> {
    let pts_sa: Vec<(f64, f64)> = sa.levels.iter().map(|x| (x.1, x.3.max(1e-4))).collect();
    let mut c = Chart::new(format!("Speed against accuracy, PGA {} g (reference: NTS-L{} {})", ctx.acc, ctx.prm.reference.layer, ctx.reference), "wall time, one thread [s]", "|slip − reference| / reference [-]");
    c.x_axis = Axis::Log;
    c.y_axis = Axis::Log;
    c.series.push(Series::markers("model levels", pts_sa.clone()).with_labels(sa.levels.iter().map(|x| x.0.clone())));
    c.series.push(Series::line_markers("Pareto front", sa.front.iter().map(|&i| pts_sa[i])));
    Ok(c.write_png_svg(&ctx.charts_dir.join("speed_accuracy"))?.png)
}

/// Chart: the strength reduction's trials, displacement of P1 against F (none without it).
fn chart_ssr(ctx: &Ctx<'_>, ssr: Option<&StudySsr>) -> Result<Option<PathBuf>, Error> {
    let Some(s) = ssr else { return Ok(None) };
    let mut t: Vec<(f64, f64)> = s.result.trials.iter().map(|t| (t.factor, t.monitor_displacement.max(1e-9))).collect();
    t.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut c = Chart::new("Strength reduction: displacement of P1 against F", "strength reduction factor F [-]", "|u| of P1 after relaxation [m]");
    c.y_axis = Axis::Log;
    c.series.push(Series::line_markers(format!("FEM ({} mesh)", s.mesh), t));
    Ok(Some(c.write_png_svg(&ctx.charts_dir.join("ssr"))?.png))
}

// ---- numbers of the text ----------------------------------------------------------------------

/// The cheapest level per PGA (where the reference ran) whose slip is within `enough` of the
/// reference's: (PGA, level, wall time, slip).
fn cheapest_levels(ctx: &Ctx<'_>) -> Vec<(f64, String, f64, f64)> {
    let mut cheapest = Vec::new();
    for &p in &ctx.pgas {
        let Some(r) = find(&ctx.runs, |s| ctx.is_ref(s) && s.pga == p) else { continue };
        if r.failed.is_some() {
            cheapest.push((p, "none: the reference run failed".to_string(), f64::NAN, f64::NAN));
            continue;
        }
        let refv = r.residual_slip;
        let rg = ctx.rigid_of(p);
        let mut cands: Vec<(String, f64, f64)> = vec![("rigid block".into(), rg.wall_time, rg.bond(ctx.main_law).result.residual_displacement)];
        for x in ctx.runs.iter().filter(|x| ctx.plain(&x.spec) && x.spec.pga == p && !ctx.is_ref(&x.spec) && x.failed.is_none()) {
            if let Some(wall) = x.wall_time {
                cands.push((x.level.clone(), wall, x.residual_slip));
            }
        }
        if let Some(wall) = r.wall_time {
            cands.push((r.level.clone() + " (reference)", wall, refv));
        }
        cands.sort_by(|a, b| a.1.total_cmp(&b.1));
        let tol = ctx.prm.enough * refv.abs().max(0.01);
        if let Some(c) = cands.iter().find(|c| (c.2 - refv).abs() <= tol) {
            cheapest.push((p, c.0.clone(), c.1, c.2));
        }
    }
    cheapest
}

/// The trend of NTS against NTN, for the headline and the variant.
fn trends(ctx: &Ctx<'_>, cv: &Curves) -> Vec<String> {
    let mut trend = Vec::new();
    let variants = cv.variants.iter().map(|v| (format!("variant ({})", v.law.describe()), &v.nts, &v.ntn));
    for (label, nts, ntn) in std::iter::once((format!("headline ({})", ctx.main_law.describe()), &cv.nts_sweep, &cv.ntn_sweep)).chain(variants) {
        trend.extend(nts_ntn_trend(&label, &ctx.pgas, nts, ntn));
    }
    trend
}

/// The seed's claims against the headline runs.
fn seed_claims(ctx: &Ctx<'_>, cv: &Curves, at: &AtAcc<'_>) -> Vec<SeedClaim> {
    let mut claims = slip_claims(&ctx.pgas, &cv.nts_sweep, &cv.ntn_sweep);
    let acc = ctx.acc;
    for (r, tag, s) in [(at.nts, "NTS", seed::P1_NTS_1G), (at.ntn, "NTN", seed::P1_NTN_1G)] {
        if let Some(r) = r.filter(|_| acc == seed::PGA) {
            let ang = angle_deg(r.p1_residual, s);
            let ratio = (r.p1_residual.iter().map(|x| x * x).sum::<f64>() / s.iter().map(|x| x * x).sum::<f64>()).sqrt();
            claims.push(SeedClaim {
                claim: format!("P1 residual displacement at {} g, {tag}", seed::PGA),
                seed: cm3(s),
                ours: format!("{}: {}° from the seed's direction, {} × its length", cm3(r.p1_residual), fmt_sig(ang, 2), fmt_sig(ratio, 3)),
                reproduced: Some(ang <= 15.0 && (ratio - 1.0).abs() <= 0.5),
            });
        }
    }
    if let Some(r) = at.nts.filter(|_| acc == seed::PGA) {
        claims.push(SeedClaim {
            claim: format!("the wedge starts to slide at about {} s and is at rest when the shaking ends ({} g)", seed::ONSET_1G, seed::PGA),
            seed: format!("{} s; at rest", seed::ONSET_1G),
            ours: format!("slip exceeds 1 mm at {} s (NTS); {}", r.onset.map(|t| fmt_sig(t, 3)).unwrap_or_else(|| "never".into()), if r.still_sliding { "still sliding at the end" } else { "at rest at the end" }),
            reproduced: None,
        });
        claims.push(SeedClaim {
            claim: "failure mode: sliding along the line of intersection on both planes, the same for NTS and NTN".into(),
            seed: "stated (figure 8)".into(),
            ours: format!("NTS: {}; NTN: {}", r.mode, at.ntn.map(|x| x.mode.as_str()).unwrap_or("–")),
            reproduced: Some(r.mode.starts_with("sliding on both planes") && at.ntn.is_none_or(|x| x.mode.starts_with("sliding on both planes"))),
        });
    }
    claims
}

/// The seed's claims on the residual slip against PGA (NTS and NTN on the sweep mesh): no
/// sliding at low PGA, the values at 1 g, NTS above NTN and the growth of the difference.
fn slip_claims(pgas: &[f64], nts_sweep: &[(f64, f64)], ntn_sweep: &[(f64, f64)]) -> Vec<SeedClaim> {
    let mut claims = Vec::new();
    let low: Vec<(f64, f64)> = pgas
        .iter()
        .filter(|&&p| p <= seed::NO_SLIDING_UP_TO)
        .filter_map(|&p| {
            let a = nts_sweep.iter().chain(ntn_sweep).filter(|x| x.0 == p).map(|x| x.1).fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.max(v))))?;
            Some((p, a))
        })
        .collect();
    if !low.is_empty() {
        let ok = low.iter().all(|x| x.1 < 0.01);
        claims.push(SeedClaim {
            claim: format!("no obvious sliding at {} g and below", seed::NO_SLIDING_UP_TO),
            seed: "stated (figure 11)".into(),
            ours: low.iter().map(|(p, s)| format!("largest NTS/NTN slip {} m at {p} g", m(*s))).collect::<Vec<_>>().join("; "),
            reproduced: Some(ok),
        });
    }
    let at = |v: &[(f64, f64)]| v.iter().find(|x| x.0 == seed::PGA).map(|x| x.1);
    if let (Some(a), Some(b)) = (at(nts_sweep), at(ntn_sweep)) {
        claims.push(SeedClaim {
            claim: format!("residual slip at {} g, NTS / NTN", seed::PGA),
            seed: format!("{} / {} m", seed::SLIP_NTS_1G, seed::SLIP_NTN_1G),
            ours: format!("{} / {} m ({} / {} of the seed's)", m(a), m(b), fmt_sig(a / seed::SLIP_NTS_1G, 3), fmt_sig(b / seed::SLIP_NTN_1G, 3)),
            reproduced: Some((a / seed::SLIP_NTS_1G - 1.0).abs() <= 0.5 && (b / seed::SLIP_NTN_1G - 1.0).abs() <= 0.5),
        });
        let d = (a - b) / b;
        let ds = (seed::SLIP_NTS_1G - seed::SLIP_NTN_1G) / seed::SLIP_NTN_1G;
        claims.push(SeedClaim { claim: format!("NTS slides more than NTN at {} g", seed::PGA), seed: fmt_percent(ds, 1), ours: fmt_percent(d, 1), reproduced: Some(d > 0.0) });
    }
    let sliding: Vec<(f64, f64, f64)> = pgas
        .iter()
        .filter_map(|&p| {
            let a = nts_sweep.iter().find(|x| x.0 == p)?.1;
            let b = ntn_sweep.iter().find(|x| x.0 == p)?.1;
            Some((p, a, b))
        })
        .filter(|x| x.1.max(x.2) >= 0.01)
        .collect();
    if sliding.len() >= 2 {
        let diffs: Vec<f64> = sliding.iter().map(|x| (x.1 - x.2) / x.2.max(1e-12)).collect();
        claims.push(SeedClaim {
            claim: "NTS above NTN at every PGA that slides, the difference growing with PGA".into(),
            seed: "stated (figure 11)".into(),
            ours: sliding.iter().zip(&diffs).map(|(x, d)| format!("{} g {}", x.0, fmt_percent(*d, 1))).collect::<Vec<_>>().join(", "),
            reproduced: Some(diffs.iter().all(|&d| d > 0.0) && diffs.windows(2).all(|w| w[1] >= w[0])),
        });
    }
    claims
}

// ---- report.md, section by section -------------------------------------------------------------

/// Section: the title and "Model" (geometry, materials, joints, gravity, rock, base motion,
/// damping).
fn section_model(md: &mut String, ctx: &Ctx<'_>) {
    let (prm, base, main_rock) = (ctx.prm, ctx.base, ctx.main_rock);
    let _ = writeln!(md, "# Wedge study: the Hoek & Bray wedge (seed paper, section 4)\n");
    let _ = writeln!(md, "Generated by `jointquake study report` from `{}`. Units SI; slip and displacements in m.\n", ctx.results.plan.study.display());
    let _ = writeln!(md, "## Model\n");
    let mat = base.materials.iter().map(|mm| format!("`{}` E = {} GPa, ν = {}, ρ = {} kg/m³", mm.group, mm.e / 1e9, mm.nu, mm.rho)).collect::<Vec<_>>().join("; ");
    let w = &prm.wedge;
    let plane = |p: &crate::rigid::wedge::PlaneOrientation| format!("{}/{}", p.dip, p.dip_direction);
    let levels = ctx
        .results
        .study
        .axis(&prm.mesh_axis)
        .map(|a| a.values.iter().map(|l| format!("{} ({})", l.label, l.variation.set.iter().map(|(k, v)| format!("{k} = {v}")).collect::<Vec<_>>().join(", "))).collect::<Vec<_>>().join("; "))
        .unwrap_or_default();
    let _ = writeln!(
        md,
        "- Geometry `{}` (planes A {}, B {}, face {}, upper slope {}; H = {} m as the {}); mesh levels: {levels}.",
        base.geometry.geo.as_ref().or(base.geometry.msh.as_ref()).and_then(|g| g.file_name()).map(|f| format!("geo/{}", f.to_string_lossy())).unwrap_or_default(),
        plane(&w.plane_a),
        plane(&w.plane_b),
        plane(&w.face),
        plane(&w.upper),
        w.height,
        match w.height_def {
            HeightDef::Intersection => "vertical rise of the line of intersection",
            HeightDef::CrestOnA => "height of the crest point on plane A above the toe",
        }
    );
    let _ = writeln!(md, "- Materials: {mat}. The seed gives no elastic constants; these are chosen (a moderately jointed rock mass) and the sensitivity to E is below.");
    let strength = base
        .joints
        .iter()
        .filter(|j| [&prm.joints.a, &prm.joints.b].contains(&&j.name))
        .map(|j| {
            let phi = j.friction().phi_deg();
            format!("{} φ = {}°, c = {} kPa", j.name, fmt_sig_short(phi), fmt_sig_short(j.cohesion.unwrap_or(0.0) / 1e3))
        })
        .collect::<Vec<_>>()
        .join("; ");
    let _ = writeln!(md, "- Joints: {strength} (seed table 1). Headline: {}{}; during gravity equilibrium bonds are kept (`equilibrium.joint_bonds = \"kept\"`).", ctx.main_law.describe(), ctx.other_laws.iter().map(|l| format!("; variant: {}", l.describe())).collect::<String>());
    let grav = base.loads.gravity.as_ref().and_then(|g| g.groups.clone()).map(|g| g.join(", ")).unwrap_or_else(|| "all".into());
    let _ = writeln!(md, "- Gravity on: {grav} (the rock is a weightless support, as in limit equilibrium); brought to equilibrium before the record.");
    let others = ctx.other_rocks();
    let _ = writeln!(
        md,
        "- Rock of the main runs: {}{}.{}",
        main_rock.describe(),
        if main_rock == RockModel::Rigid { " (its nodes fixed: the wedge slides on its joints under the base motion itself)" } else { "" },
        if others.is_empty() { String::new() } else { format!(" Compared with: {} (section \"Rock model\").", others.iter().map(|r| r.describe()).collect::<Vec<_>>().join(", ")) }
    );
    let recs = base.loads.base.iter().map(|b| format!("`{}` along ({}, {}, {}) × {}", b.record.as_ref().and_then(|r| r.file_name()).map(|f| f.to_string_lossy().into_owned()).unwrap_or_else(|| b.synth.as_ref().map(|s| format!("synth seed {} {}", s.seed, s.component)).unwrap_or_default()), b.direction[0], b.direction[1], b.direction[2], b.pga.map(|p| format!("PGA {p} g")).or(b.scale.map(|s| format!("scale {s}"))).unwrap_or_else(|| "1".into()))).collect::<Vec<_>>().join("; ");
    let _ = writeln!(md, "- Base motion (base scene): {recs}. Every record is scaled by one factor so that the horizontal PGA takes the study values: by default the committed El Centro 1940 NS record horizontally (y, north) and 2/3 of the same record vertically (z), in phase. The seed used the Koyna record, which is not public.");
    let _ = writeln!(md, "- Damping: {}. Duration {} s per run (record plus free vibration).\n", damping_text(base), base.time.duration);
}

/// Section: "Static factor of safety" (limit equilibrium, FEM strength reduction, the seed's
/// factors) and the pseudo-static critical acceleration.
fn section_static_fs(md: &mut String, le: &LeTable, ssr: Option<&StudySsr>) {
    let _ = writeln!(md, "## Static factor of safety\n");
    let mut t = Table::new(["method", "geometry (what H = 39.624 m measures)", "FS"]);
    let _ = t.push_row(["limit equilibrium (Hoek & Bray), ours", "vertical rise of the line of intersection", &m(le.fs_intersection)]);
    let _ = t.push_row(["limit equilibrium, ours", "height of the crest point on plane A", &m(le.fs_crest_on_a)]);
    let _ = t.push_row(["limit equilibrium, ours, c = 0", "line of intersection", &m(le.fs_friction_only)]);
    if let Some(s) = &ssr {
        let _ = t.push_row([format!("FEM strength reduction, ours ({} mesh, {} elements)", s.mesh, s.elements), "line of intersection".into(), format!("{} (bracket {}–{})", m(s.result.factor), m(s.result.bracket[0]), m(s.result.bracket[1]))]);
    }
    let _ = t.push_row(["seed: FEM strength reduction", "not stated", "1.60"]);
    let _ = t.push_row(["seed, quoting DDA", "not stated", "1.66"]);
    let _ = t.push_row(["seed, quoting FEM", "not stated", "1.68"]);
    md.push_str(&t.to_markdown());
    if let Some(s) = &ssr {
        let dev = s.result.factor / le.fs_intersection - 1.0;
        let _ = writeln!(
            md,
            "\nFEM against limit equilibrium for the same geometry: {} ({}). Rock of the strength reduction: {} (`ssr.run`). Failure criterion: {}. The seed's 1.66 and 1.68 match our limit equilibrium with H read as the crest height on plane A ({}); its own 1.60 is below both readings.\n",
            fmt_percent(dev, 1),
            if dev.abs() <= 0.03 { "within the 3 % required" } else { "outside 3 %" },
            s.rock.map(|r| r.describe()).unwrap_or("not recorded"),
            s.result.criterion,
            m(le.fs_crest_on_a)
        );
    }
    let _ = writeln!(
        md,
        "Pseudo-static critical horizontal ground acceleration (towards north, kv = 0): {} g with cohesion, {} g once cohesion is lost.\n",
        le.kc_intact.map(m).unwrap_or_else(|| "none".into()),
        le.kc_residual.map(m).unwrap_or_else(|| "none".into())
    );

}

/// A value of a slip-against-PGA curve at `p`, or "–".
fn val(v: &[(f64, f64)], p: f64) -> String {
    v.iter().find(|x| x.0 == p).map(|x| m(x.1)).unwrap_or_else(|| "–".into())
}

/// Section: "Seismic runs — headline" (the slip-against-PGA table with the seed's values and
/// its chart; P1's residual displacement at the accuracy PGA when that is the seed's).
fn section_headline(md: &mut String, ctx: &Ctx<'_>, cv: &Curves, at: &AtAcc<'_>) {
    let (prm, sweep, reference, main_law, main_rock, main_beta, acc, pgas): (_, &str, &str, _, _, _, _, _) = (ctx.prm, &ctx.sweep, &ctx.reference, ctx.main_law, ctx.main_rock, ctx.main_beta, ctx.acc, &ctx.pgas);
    let Curves { nts_sweep, ntn_sweep, nts2_sweep, reference_pts, .. } = cv;
    let (nts_acc, ntn_acc) = (at.nts, at.ntn);
    let rigid_main = |p: f64| ctx.rigid_main(p);
    // ---- 1. the headline
    let _ = writeln!(md, "## Seismic runs — headline: {}\n", main_law.describe());
    let _ = writeln!(md, "{}, β = {} s, E as given; residual slip at P2 [m]. The seed's values are from its figures 10–11 and text (Koyna record).\n", main_rock.describe(), fmt_sig(main_beta, 3));
    let has_nts2 = !nts2_sweep.is_empty();
    let has_ref = reference != sweep && !reference_pts.is_empty();
    let mut head = vec![format!("PGA [g]"), format!("NTS-L1 {sweep}"), format!("NTN {sweep}")];
    if has_nts2 {
        head.push(format!("NTS-L2 {sweep}"));
    }
    if has_ref {
        head.push(format!("NTS-L{} {reference}", prm.reference.layer));
    }
    head.extend([format!("rigid block ({})", if main_law.bond() == Bond::Kept { "cohesion kept" } else { "cohesion lost" }), "(NTS − NTN)/NTN".into(), "seed NTS / NTN".into()]);
    let mut t = Table::new(head);
    for &p in pgas {
        let mut row = vec![fmt_sig_short(p), val(&nts_sweep, p), val(&ntn_sweep, p)];
        if has_nts2 {
            row.push(val(&nts2_sweep, p));
        }
        if has_ref {
            row.push(val(&reference_pts, p));
        }
        let d = match (nts_sweep.iter().find(|x| x.0 == p), ntn_sweep.iter().find(|x| x.0 == p)) {
            (Some(a), Some(b)) if a.1.max(b.1) >= 0.01 => fmt_percent((a.1 - b.1) / b.1, 1),
            (Some(_), Some(_)) => "(< 1 cm)".into(),
            _ => "–".into(),
        };
        let s = if p == seed::PGA {
            format!("{} / {} ({})", seed::SLIP_NTS_1G, seed::SLIP_NTN_1G, fmt_percent((seed::SLIP_NTS_1G - seed::SLIP_NTN_1G) / seed::SLIP_NTN_1G, 1))
        } else if p <= seed::NO_SLIDING_UP_TO {
            "no obvious sliding".into()
        } else {
            "figure 11 only".into()
        };
        row.extend([m(rigid_main(p)), d, s]);
        let _ = t.push_row(row);
    }
    md.push_str(&t.to_markdown());
    let _ = writeln!(md, "\n![slip against PGA](charts/slip_vs_pga.svg)\n");
    if acc == seed::PGA {
        let _ = writeln!(md, "P1 residual displacement at {acc} g (x east, y north, z up):\n");
        let mut t = Table::new(["level", "P1 ux", "P1 uy", "P1 uz", "seed", "angle to the seed's [°]", "onset of sliding [s]"]);
        for (r, s) in [(nts_acc, seed::P1_NTS_1G), (ntn_acc, seed::P1_NTN_1G)] {
            if let Some(r) = r {
                let _ = t.push_row([r.level.clone(), m(r.p1_residual[0]), m(r.p1_residual[1]), m(r.p1_residual[2]), cm3(s), fmt_sig(angle_deg(r.p1_residual, s), 2), r.onset.map(|x| fmt_sig(x, 3)).unwrap_or_else(|| "–".into())]);
            }
        }
        md.push_str(&t.to_markdown());
        let _ = writeln!(md);
    }
}

/// Section: "The seed's claims" (the table, what "reproduced" means, the NTS − NTN trend).
fn section_claims(md: &mut String, claims: &[SeedClaim], trend: &[String]) {
    let _ = writeln!(md, "### The seed's claims\n");
    let mut t = Table::new(["claim", "seed", "ours", "reproduced"]);
    for c in claims {
        let _ = t.push_row([c.claim.clone(), c.seed.clone(), c.ours.clone(), match c.reproduced {
            Some(true) => "yes".to_string(),
            Some(false) => "no".into(),
            None => "compare".into(),
        }]);
    }
    md.push_str(&t.to_markdown());
    let _ = writeln!(md, "\n\"Reproduced\": within 50 % for magnitudes, within 15° for the direction of P1; NTS − NTN as a sign and its growth with PGA. Why the numbers differ (record, duration, damping) is discussed in docs/wedge.md.\n");
    for s in trend {
        let _ = writeln!(md, "- {s}");
    }
    let _ = writeln!(md);

}

/// Section: "Headline runs in detail" (every headline run and the rigid block per PGA) and the
/// history charts.
fn section_headline_detail(md: &mut String, ctx: &Ctx<'_>) {
    let _ = writeln!(md, "### Headline runs in detail\n");
    detail_table(md, ctx, &|s| ctx.plain(s), ctx.main_law);
    let _ = writeln!(md, "\n![slip history](charts/slip_history.svg)\n\n![P1 displacement](charts/p1_history.svg)\n");
}

/// The table of the runs `sel` selects on the sweep mesh, PGA by PGA, each PGA closed by the
/// rigid block with the bond of `law`.
fn detail_table(md: &mut String, ctx: &Ctx<'_>, sel: &dyn Fn(&WedgeRunSpec) -> bool, law: CohesionLaw) {
    let joint_names = ctx.joint_names();
    let mut t = Table::new(["PGA [g]".to_string(), "level".into(), "P1 ux".into(), "P1 uy".into(), "P1 uz".into(), "slip at P2".into(), "still sliding".into(), "failure mode".into(), format!("max opening {joint_names}")]);
    for &p in &ctx.pgas {
        if !ctx.runs.iter().any(|r| sel(&r.spec) && r.spec.pga == p && r.spec.mesh == ctx.sweep) {
            continue;
        }
        for r in ctx.runs.iter().filter(|r| sel(&r.spec) && r.spec.pga == p && r.spec.mesh == ctx.sweep) {
            let op = r.max_opening.iter().map(|(_, v)| m(*v)).collect::<Vec<_>>().join(" / ");
            let slip = match &r.failed {
                Some(_) => format!("≥ {} (stopped at t = {} s, see below)", m(r.max_slip), m(r.slip_history.last().map(|x| x.0).unwrap_or(0.0))),
                None => m(r.residual_slip),
            };
            let _ = t.push_row([fmt_sig_short(p), r.level.clone(), m(r.p1_residual[0]), m(r.p1_residual[1]), m(r.p1_residual[2]), slip, (if r.still_sliding { "yes" } else { "no" }).into(), r.mode.clone(), op]);
        }
        let rg = ctx.rigid_of(p).bond(law);
        let _ = t.push_row([fmt_sig_short(p), format!("rigid block, {}", law.rigid_label()), "".into(), "".into(), "".into(), m(rg.result.residual_displacement), (if rg.result.still_sliding { "yes" } else { "no" }).into(), format!("{} sliding episodes", rg.result.n_episodes), "".into()]);
    }
    md.push_str(&t.to_markdown());
}

/// Section: "Variant" per variant law (its slip against PGA, its chart and its runs in detail;
/// nothing for a law without runs).
fn section_variant(md: &mut String, ctx: &Ctx<'_>, cv: &Curves) {
    let (sweep, main_rock, main_beta, pgas): (&str, _, _, _) = (&ctx.sweep, ctx.main_rock, ctx.main_beta, &ctx.pgas);
    let nts_sweep = &cv.nts_sweep;
    let rigid_of = |p: f64| ctx.rigid_of(p);
    // ---- 2. the variant laws
    for (k, v) in cv.variants.iter().enumerate().filter(|(_, v)| v.has_runs()) {
        let (law, nts_var, ntn_var) = (v.law, &v.nts, &v.ntn);
        let _ = writeln!(md, "## Variant: {}\n", law.describe());
        let rigid_note = if matches!(law, CohesionLaw::Patton { .. }) { " (the rigid block keeps the Mohr–Coulomb cone)" } else { "" };
        let _ = writeln!(md, "The same runs ({}, {sweep} mesh, β = {} s) with the joints' law changed to: {}; not the seed's law{rigid_note}; residual slip at P2 [m].\n", main_rock.describe(), fmt_sig(main_beta, 3), law.describe());
        let mut t = Table::new(["PGA [g]".to_string(), format!("NTS-L1 {sweep}"), format!("NTN {sweep}"), "(NTS − NTN)/NTN".into(), format!("rigid block, {}", law.rigid_label()), format!("NTS-L1 {sweep}, headline")]);
        for &p in pgas.iter().filter(|&&p| nts_var.iter().chain(ntn_var.iter()).any(|x| x.0 == p)) {
            let d = match (nts_var.iter().find(|x| x.0 == p), ntn_var.iter().find(|x| x.0 == p)) {
                (Some(a), Some(b)) if a.1.max(b.1) >= 0.01 => fmt_percent((a.1 - b.1) / b.1, 1),
                (Some(_), Some(_)) => "(< 1 cm)".into(),
                _ => "–".into(),
            };
            let _ = t.push_row([fmt_sig_short(p), val(nts_var, p), val(ntn_var, p), d, m(rigid_of(p).bond(law).result.residual_displacement), val(nts_sweep, p)]);
        }
        md.push_str(&t.to_markdown());
        let _ = writeln!(md, "\n![slip against PGA, variant](charts/{}.svg)\n", VariantCurves::chart_stem(k));
        let _ = writeln!(md, "### Variant runs in detail\n");
        detail_table(md, ctx, &|s| ctx.variant(s, law), law);
        let _ = writeln!(md);
    }
}

/// Section: "Rock model" (each run on another rock against its main-rock twin; nothing without
/// other rock models).
fn section_rock(md: &mut String, ctx: &Ctx<'_>) {
    let (prm, main_rock) = (ctx.prm, ctx.main_rock);
    let other_rock = ctx.other_rock();
    let others = ctx.other_rocks();
    let rigid_of = |p: f64| ctx.rigid_of(p);
    let twin_of = |r: &WedgeRun| {
        ctx.run_of(&|s: &WedgeRunSpec| s.rock == main_rock && s.pga == r.spec.pga && s.method == r.spec.method && s.layer == r.spec.layer && s.mesh == r.spec.mesh && s.law == r.spec.law && s.e_factor == r.spec.e_factor && s.beta == r.spec.beta)
    };
    // ---- 3. rock models
    if !other_rock.is_empty() {
        let _ = writeln!(md, "## Rock model: {} against the {}\n", others.iter().map(|r| r.describe()).collect::<Vec<_>>().join(", "), main_rock.describe());
        let _ = writeln!(md, "Each run against the same run on the {} (residual slip at P2 [m]). Rock peak: the absolute acceleration of the rock node `{}` (peak over the run, x / y / z [g]); the rigid block driven by that computed motion (with the run's bond) shows how much of the change the rock's motion under the wedge explains.\n", main_rock.describe(), prm.monitors.rock);
        let mut t = Table::new(["run", "slip", format!("slip, {}", main_rock.describe()).as_str(), "change", "rock peak x / y / z [g]", "rigid block on the rock's motion", "rigid block on the base record"]);
        for r in &other_rock {
            let tw = twin_of(r);
            let pk = r.rock_peak_accel.map(|a| format!("{} / {} / {}", m(a[0]), m(a[1]), m(a[2]))).unwrap_or_else(|| "–".into());
            let slip = if r.failed.is_some() { format!("failed (≥ {})", m(r.max_slip)) } else { m(r.residual_slip) };
            let change = match tw {
                Some(tw) if r.failed.is_none() && tw.residual_slip.abs().max(r.residual_slip.abs()) >= 0.01 => fmt_percent(r.residual_slip / tw.residual_slip - 1.0, 1),
                Some(_) if r.failed.is_none() => "(< 1 cm)".into(),
                _ => "–".into(),
            };
            let rb = rigid_of(r.spec.pga).bond(r.spec.law).result.residual_displacement;
            let _ = t.push_row([r.spec.id.clone(), slip, tw.map(|x| m(x.residual_slip)).unwrap_or_else(|| "–".into()), change, pk, r.rigid_on_rock_slip.map(m).unwrap_or_else(|| "–".into()), m(rb)]);
        }
        md.push_str(&t.to_markdown());
        let _ = writeln!(md, "\n![slip against PGA, rock models](charts/slip_vs_pga_rock.svg)\n");
    }

}

/// Section: "Stiffness and damping" (E × factor and β variants at the accuracy PGA against the
/// headline run).
fn section_stiffness(md: &mut String, ctx: &Ctx<'_>) {
    let (sweep, main_rock, main_law, main_beta, acc, runs): (&str, _, _, _, _, _) = (&ctx.sweep, ctx.main_rock, ctx.main_law, ctx.main_beta, ctx.acc, &ctx.runs);
    let plain = |s: &WedgeRunSpec| ctx.plain(s);
    let run_of = |pred: &dyn Fn(&WedgeRunSpec) -> bool| ctx.run_of(pred);
    // ---- 4. stiffness and damping
    let _ = writeln!(md, "## Stiffness and damping (PGA {acc} g, {sweep} mesh, {})\n", main_rock.describe());
    let mut t = Table::new(["run", "variant", "slip at P2", "same run, headline", "change"]);
    for r in runs.iter().filter(|r| r.spec.pga == acc && r.spec.mesh == sweep && r.spec.rock == main_rock && r.spec.law == main_law && (r.spec.e_factor != 1.0 || r.spec.beta != main_beta)) {
        let tw = run_of(&|s: &WedgeRunSpec| plain(s) && s.pga == acc && s.mesh == sweep && s.method == r.spec.method && s.layer == r.spec.layer);
        let mut what = Vec::new();
        if r.spec.e_factor != 1.0 {
            what.push(format!("E × {}", r.spec.e_factor));
        }
        if r.spec.beta != main_beta {
            what.push(if r.spec.beta == 0.0 { "undamped (β = 0)".to_string() } else { format!("β = {} s", fmt_sig(r.spec.beta, 3)) });
        }
        let _ = t.push_row([r.spec.id.clone(), what.join(", "), m(r.residual_slip), tw.map(|x| m(x.residual_slip)).unwrap_or_else(|| "–".into()), tw.map(|x| fmt_percent(r.residual_slip / x.residual_slip - 1.0, 1)).unwrap_or_else(|| "–".into())]);
    }
    md.push_str(&t.to_markdown());
    let _ = writeln!(md);

}

/// Section: "Speed against accuracy" (the levels at the accuracy PGA with the Pareto front and
/// its chart, the cheapest sufficient level per PGA, the strength-reduction chart), then the
/// runs stopped by their checks.
fn section_speed_accuracy(md: &mut String, ctx: &Ctx<'_>, sa: &SpeedAccuracy, ref_acc: Option<&WedgeRun>, cheapest: &[(f64, String, f64, f64)], has_ssr: bool) {
    let (prm, acc, runs) = (ctx.prm, ctx.acc, &ctx.runs);
    let _ = writeln!(md, "## Speed against accuracy (PGA {acc} g, headline)\n");
    let mut t = Table::new(["level", "wall time [s]", "slip [m]", "error vs reference", "Pareto front"]);
    for (i, x) in sa.levels.iter().enumerate() {
        let _ = t.push_row([x.0.clone(), m(x.1), m(x.2), fmt_percent(x.3, 1), (if sa.front.contains(&i) { "yes" } else { "" }).into()]);
    }
    if let Some(r) = ref_acc {
        let _ = t.push_row([format!("{} (reference)", r.level), opt(r.wall_time), m(r.residual_slip), "0".into(), "".into()]);
    }
    md.push_str(&t.to_markdown());
    let _ = writeln!(md, "\n![speed against accuracy](charts/speed_accuracy.svg)\n");
    let _ = writeln!(md, "Cheapest level whose residual slip is within {} of the reference (or of 1 cm when the reference is smaller), at each PGA with a reference run:\n", fmt_percent(prm.enough, 0));
    let mut t = Table::new(["PGA [g]", "cheapest sufficient level", "wall time [s]", "slip [m]"]);
    for (p, l, w, s) in cheapest {
        let num = |x: f64| if x.is_finite() { m(x) } else { "–".to_string() };
        let _ = t.push_row([fmt_sig_short(*p), l.clone(), num(*w), num(*s)]);
    }
    md.push_str(&t.to_markdown());
    if has_ssr {
        let _ = writeln!(md, "\n![strength reduction](charts/ssr.svg)\n");
    }
    let stopped: Vec<&WedgeRun> = runs.iter().filter(|r| r.failed.is_some()).collect();
    if !stopped.is_empty() || !ctx.stopped_early.is_empty() {
        let _ = writeln!(md, "\nRuns stopped by their checks (the slip they had reached is a lower bound):\n");
        for r in stopped {
            let _ = writeln!(md, "- `{}`: {}", r.spec.id, r.failed.as_deref().unwrap_or("").trim_start_matches("error: "));
        }
        for (id, f) in &ctx.stopped_early {
            let _ = writeln!(md, "- `{id}` (before its first history row): {f}");
        }
    }
}

/// Section: "Runs" (every run's size, step, cost, slip and lost node-steps) and the total
/// wall time.
fn section_runs(md: &mut String, ctx: &Ctx<'_>, ssr: Option<&StudySsr>) {
    let (runs, joint_names) = (&ctx.runs, ctx.joint_names());
    let _ = writeln!(md, "\n## Runs\n");
    let mut t = Table::new(["run".to_string(), "nodes".into(), "elements".into(), "dt [s]".into(), "steps".into(), "wall time [s]".into(), "slip [m]".into(), format!("lost node-steps {joint_names}")]);
    for r in runs {
        let lost = r.lost_node_steps.iter().map(|(_, v)| v.map_or_else(|| "–".to_string(), |v| v.to_string())).collect::<Vec<_>>().join(" / ");
        let slip = if r.failed.is_some() { format!("failed (≥ {})", m(r.max_slip)) } else { m(r.residual_slip) };
        let count = |x: Option<usize>| x.map_or_else(|| "–".to_string(), |x| x.to_string());
        let _ = t.push_row([r.spec.id.clone(), count(r.nodes), count(r.elements), r.dt.map_or_else(|| "–".to_string(), |x| fmt_sig(x, 3)), count(r.steps), opt(r.wall_time), slip, lost]);
    }
    md.push_str(&t.to_markdown());
    let total: f64 = runs.iter().filter_map(|r| r.wall_time).sum::<f64>() + ssr.as_ref().map_or(0.0, |s| s.wall_time);
    let _ = writeln!(md, "\nSum of the runs' and the strength reduction's wall times (one thread each): {} s.", fmt_sig(total, 4));
}

/// (NTS − NTN)/NTN by PGA and how it compares with the seed's trend.
fn nts_ntn_trend(label: &str, pgas: &[f64], nts: &[(f64, f64)], ntn: &[(f64, f64)]) -> Vec<String> {
    let mut trend = Vec::new();
    let pairs: Vec<(f64, f64, f64)> = pgas
        .iter()
        .filter_map(|&p| {
            let a = nts.iter().find(|x| x.0 == p)?.1;
            let b = ntn.iter().find(|x| x.0 == p)?.1;
            Some((p, a, b))
        })
        .collect();
    if pairs.is_empty() {
        return trend;
    }
    let sliding: Vec<&(f64, f64, f64)> = pairs.iter().filter(|x| x.1.max(x.2) >= 0.01).collect();
    let above = sliding.iter().filter(|x| x.1 >= x.2).count();
    trend.push(format!("{label}: NTS ≥ NTN at {above} of the {} PGAs with slip ≥ 1 cm (seed: NTS above NTN at every PGA that slides).", sliding.len()));
    let diffs: Vec<(f64, f64)> = sliding.iter().map(|x| (x.0, (x.1 - x.2) / x.2.max(1e-12))).collect();
    if !diffs.is_empty() {
        let growing = diffs.windows(2).all(|w| w[1].1 >= w[0].1);
        trend.push(format!(
            "{label}: (NTS − NTN)/NTN by PGA: {} — {} (seed: the difference grows with PGA).",
            diffs.iter().map(|(p, d)| format!("{p} g: {}", fmt_percent(*d, 1))).collect::<Vec<_>>().join(", "),
            if growing { "grows with PGA" } else { "does not grow monotonically with PGA" }
        ));
    }
    let none_below: Vec<f64> = pairs.iter().filter(|x| x.1.max(x.2) < 0.01).map(|x| x.0).collect();
    trend.push(format!(
        "{label}: no significant sliding (< 1 cm) at {} (seed: none at 0.5 g and below).",
        if none_below.is_empty() { "no PGA".to_string() } else { none_below.iter().map(|p| format!("{p} g")).collect::<Vec<_>>().join(", ") }
    ));
    trend
}

fn damping_text(s: &Scene) -> String {
    let d = &s.damping;
    match d.coefficients() {
        Ok((a, b)) => format!(
            "Rayleigh α = {a} 1/s{}, β = {b} s",
            d.mass_groups.as_ref().map(|g| format!(" on {} only", g.join(", "))).unwrap_or_default()
        ),
        Err(e) => e,
    }
}

/// Charts of one wedge run (e.g. the demo): slip at P2 against time next to the rigid block
/// under the same scene's records, and the displacement of P1, in `<run_dir>/charts/`.
pub fn run_charts(kind: &WedgeKind, scene_path: &Path, run_dir: &Path) -> Result<RunCharts, Error> {
    let prm = &kind.params;
    let scene = Scene::load(scene_path)?;
    let geom = build_wedge(&prm.wedge)?;
    let hist = |name: &str| PointHistory::read(&run_dir.join("histories").join(format!("{name}.csv")));
    let (w, r, p1) = (hist(&prm.monitors.p2_wedge)?, hist(&prm.monitors.p2_rock)?, hist(&prm.monitors.p1)?);
    let slip = slip_series(&w, &r, geom.e);
    let (motions, _) = base_motions(&scene)?;
    let dt = motions.iter().map(|b| b.record.dt).fold(f64::INFINITY, f64::min);
    let mut charts = Vec::new();
    let dir = run_dir.join("charts");
    let mut c = Chart::new(format!("Slip at P2 along the line of intersection — {}", scene.name()), "t [s]", "slip [m]");
    c.series.push(Series::line(format!("FEM ({})", scene.joints.first().map_or("nts", |j| j.method().as_str()).to_uppercase()), thin(&slip, 2000)));
    if dt.is_finite() {
        let a = sample_ground_motion(&motions, dt, scene.time.duration);
        for (bond, name) in [(Bond::Brittle, "rigid block, cohesion lost at first slide"), (Bond::Kept, "rigid block, cohesion kept")] {
            let rg = rigid_wedge_slip(&kind.wedge_of(&scene), &a, dt, bond, true)?;
            if let Some(h) = rg.result.history {
                c.series.push(Series::line(name, sampled_history(&h, dt)));
            }
        }
    }
    charts.push(c.write_png_svg(&dir.join("slip_history"))?.png);
    let u0 = p1.u[0];
    let mut c = Chart::new(format!("Displacement of P1 — {}", scene.name()), "t [s]", "displacement [m]");
    for (k, axis) in ["x (east)", "y (north)", "z (up)"].iter().enumerate() {
        c.series.push(Series::line(*axis, thin(&p1.t.iter().zip(&p1.u).map(|(&t, u)| (t, u[k] - u0[k])).collect::<Vec<_>>(), 2000)));
    }
    charts.push(c.write_png_svg(&dir.join("p1_history"))?.png);
    let residual = slip.last().map(|s| s.1).expect("a history has rows");
    Ok(RunCharts { charts, lines: vec![format!("residual slip at P2: {residual:.4} m")] })
}
