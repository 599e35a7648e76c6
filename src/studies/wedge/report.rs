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

use super::{StudySsr, WedgeKind};
use crate::dynamics::loads::base_motions;
use crate::error::{Error, OutputError};
use crate::output::history::HistoryTable;
use crate::report::{fmt_percent, fmt_sig, pareto_front, Axis, Chart, Series, Table};
use crate::rigid::wedge::{analyse_wedge, build_wedge, HeightDef, WedgeInput};
use crate::scene::Scene;
use crate::study::rigid_level::{rigid_wedge_slip, sample_ground_motion, Bond, RigidWedgeRun};
use crate::study::{scene_for, KindReport, RunCharts, RunResult, StudyResults, Variation};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;

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
    /// Rock nodes fixed (FEM wedge on a rigid rock).
    pub rigid_rock: bool,
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
        let weighted = scene.loads.gravity.as_ref().and_then(|g| g.groups.clone()).unwrap_or_default();
        let rock: Vec<&str> = scene.materials.iter().filter(|m| !weighted.contains(&m.group)).map(|m| m.group.as_str()).collect();
        Ok(WedgeRunSpec {
            id: run.spec.id.clone(),
            mesh,
            method: j.method().as_str().to_string(),
            layer: j.layer.unwrap_or(1),
            pga,
            e_factor: e / e0,
            rigid_rock: scene.boundary.iter().any(|b| rock.contains(&b.group.as_str())),
        })
    }
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
    /// (cohesion lost at first slide) [m]: the rigid level with the FEM's site response.
    pub rigid_on_rock_slip: Option<f64>,
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
            if let Ok(r) = rigid_wedge_slip(&kind.wedge_of(scene), &abs, dt, Bond::Brittle, false) {
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

fn m(x: f64) -> String {
    fmt_sig(x, 4)
}

/// A number in its shortest form with at most 4 significant digits (20 → "20", 24.5 → "24.5").
fn fmt_sig_short(x: f64) -> String {
    let r = format!("{}", (x * 1e4).round() / 1e4);
    r
}

fn opt(x: Option<f64>) -> String {
    x.map_or_else(|| "–".to_string(), m)
}

/// The wedge study's part of the report (`report.md`, the `report` of `report.json`, the
/// charts in `<out>/charts/`).
pub fn write(kind: &WedgeKind, results: &StudyResults) -> Result<KindReport, Error> {
    let prm = &kind.params;
    let study = results.study;
    let out = results.plan.out.clone();
    let base = &results.base;
    let geom = build_wedge(&prm.wedge)?;
    let e = geom.e;
    let line_length = (geom.p[0].powi(2) + geom.p[1].powi(2) + geom.p[2].powi(2)).sqrt();
    let mut runs = Vec::new();
    let mut unreadable = Vec::new();
    // failed runs whose histories cannot be read (stopped before the first step): listed
    // with the stopped runs
    let mut stopped_early = Vec::new();
    for res in results.runs.iter().filter(|r| r.has_results()) {
        match (read_run(kind, res, base, e, line_length), res.failed()) {
            (Ok(r), _) => runs.push(r),
            (Err(_), Some(f)) => stopped_early.push((res.spec.id.clone(), f.to_string())),
            (Err(err), None) => unreadable.push((res.spec.id.clone(), err.to_string())),
        }
    }
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
    let charts_dir = out.join("charts");
    let mut charts = Vec::new();
    let sweep = prm.sweep_mesh.clone();
    let reference = prm.reference.mesh.clone();
    let rigid_of = |pga: f64| rigid.iter().find(|r| r.pga == pga).expect("rigid level of every PGA");
    let rr = kind.main_rigid_rock();
    let (main_rock, other_rock) = if rr { ("rigid rock", "elastic rock") } else { ("elastic rock", "rigid rock") };
    let is_ref = |s: &WedgeRunSpec| s.mesh == reference && s.method == "nts" && s.layer == prm.reference.layer && s.e_factor == 1.0 && s.rigid_rock == rr;
    let plain = |s: &WedgeRunSpec| s.e_factor == 1.0 && s.rigid_rock == rr;

    // ---- chart: slip against PGA (finished runs only; a failed run is listed in the tables)
    let pts = |method: &str, mesh: &str, layer: u8, rigid_rock: bool| -> Vec<(f64, f64)> {
        pgas
            .iter()
            .filter_map(|&p| {
                find(&runs, |s| s.e_factor == 1.0 && s.rigid_rock == rigid_rock && s.pga == p && s.method == method && s.mesh == mesh && s.layer == layer)
                    .filter(|r| r.failed.is_none())
                    .map(|r| (p, r.residual_slip.abs()))
            })
            .collect()
    };
    let nts_sweep = pts("nts", &sweep, 1, rr);
    let ntn_sweep = pts("ntn", &sweep, 1, rr);
    let nts_other = pts("nts", &sweep, 1, !rr);
    let ntn_other = pts("ntn", &sweep, 1, !rr);
    let reference_pts = pts("nts", &reference, prm.reference.layer, rr);
    let mut c = Chart::new(format!("Residual slip at P2 against PGA ({})", base.name()), "horizontal PGA [g]", "residual slip along the line of intersection [m]");
    c.series.push(Series::line_markers(format!("NTS-L1, {sweep} mesh, {main_rock}"), nts_sweep.clone()));
    c.series.push(Series::line_markers(format!("NTN, {sweep} mesh, {main_rock}"), ntn_sweep.clone()));
    if reference != sweep {
        c.series.push(Series::line_markers(format!("NTS-L{}, {reference} mesh, {main_rock} (reference)", prm.reference.layer), reference_pts.clone()));
    }
    let rigid_lost: Vec<(f64, f64)> = pgas.iter().map(|&p| (p, rigid_of(p).brittle.result.residual_displacement)).collect();
    let rigid_kept: Vec<(f64, f64)> = pgas.iter().map(|&p| (p, rigid_of(p).kept.result.residual_displacement)).collect();
    c.series.push(Series::line_markers("rigid block, cohesion lost at first slide", rigid_lost.clone()));
    c.series.push(Series::line_markers("rigid block, cohesion kept", rigid_kept.clone()));
    charts.push(c.write_png_svg(&charts_dir.join("slip_vs_pga"))?.png);
    if !nts_other.is_empty() {
        // the other rock model on its own chart: its slips can be an order of magnitude apart
        let mut c = Chart::new(format!("Residual slip at P2 against PGA: {other_rock} and {main_rock}"), "horizontal PGA [g]", "residual slip along the line of intersection [m]");
        c.series.push(Series::line_markers(format!("NTS-L1, {sweep} mesh, {other_rock}"), nts_other.clone()));
        c.series.push(Series::line_markers(format!("NTN, {sweep} mesh, {other_rock}"), ntn_other.clone()));
        c.series.push(Series::line_markers(format!("NTS-L1, {sweep} mesh, {main_rock}"), nts_sweep.clone()));
        c.series.push(Series::line_markers("rigid block, cohesion lost at first slide", rigid_lost));
        charts.push(c.write_png_svg(&charts_dir.join("slip_vs_pga_other_rock"))?.png);
    }

    // ---- chart: slip history at the accuracy PGA
    let acc = prm.accuracy_pga;
    let nts_acc = find(&runs, |s| plain(s) && s.pga == acc && s.method == "nts" && s.mesh == sweep && s.layer == 1);
    let ntn_acc = find(&runs, |s| plain(s) && s.pga == acc && s.method == "ntn" && s.mesh == sweep);
    let ref_acc = find(&runs, |s| is_ref(s) && s.pga == acc);
    let mut c = Chart::new(format!("Slip history at P2, PGA {acc} g"), "t [s]", "slip along the line of intersection [m]");
    for (r, name) in [(nts_acc, format!("NTS-L1, {sweep}")), (ntn_acc, format!("NTN, {sweep}")), (ref_acc, format!("reference NTS-L{}, {reference}", prm.reference.layer))] {
        if let Some(r) = r {
            c.series.push(Series::line(name, r.slip_history.clone()));
        }
    }
    let ra = rigid_of(acc);
    if let Some(h) = &ra.brittle.result.history {
        c.series.push(Series::line("rigid block (cohesion lost)", sampled_history(h, ra.brittle.dt)));
    }
    charts.push(c.write_png_svg(&charts_dir.join("slip_history"))?.png);

    // ---- chart: P1 displacement at the accuracy PGA
    let mut c = Chart::new(format!("Displacement of P1 (wedge, slope face), PGA {acc} g"), "t [s]", "displacement [m]");
    for (r, tag) in [(nts_acc, "NTS"), (ntn_acc, "NTN")] {
        if let Some(r) = r {
            for (k, axis) in ["x (east)", "y (north)", "z (up)"].iter().enumerate() {
                c.series.push(Series::line(format!("{tag} {axis}"), r.p1_history.iter().map(|(t, u)| (*t, u[k])).collect::<Vec<_>>()));
            }
        }
    }
    charts.push(c.write_png_svg(&charts_dir.join("p1_history"))?.png);

    // ---- speed against accuracy at the accuracy PGA
    let ref_slip = ref_acc.map(|r| r.residual_slip).unwrap_or(f64::NAN);
    let mut sa: Vec<(String, f64, f64, f64)> = Vec::new(); // (level, wall, slip, error)
    sa.push(("rigid block".into(), ra.wall_time.max(1e-4), ra.brittle.result.residual_displacement, (ra.brittle.result.residual_displacement - ref_slip).abs() / ref_slip.abs()));
    for r in runs.iter().filter(|r| plain(&r.spec) && r.spec.pga == acc && !is_ref(&r.spec) && r.failed.is_none()) {
        let Some(wall) = r.wall_time else { continue };
        sa.push((r.level.clone(), wall, r.residual_slip, (r.residual_slip - ref_slip).abs() / ref_slip.abs()));
    }
    let pts_sa: Vec<(f64, f64)> = sa.iter().map(|x| (x.1, x.3.max(1e-4))).collect();
    let front = pareto_front(&pts_sa);
    let mut c = Chart::new(format!("Speed against accuracy, PGA {acc} g (reference: NTS-L{} {reference})", prm.reference.layer), "wall time, one thread [s]", "|slip − reference| / reference [-]");
    c.x_axis = Axis::Log;
    c.y_axis = Axis::Log;
    c.series.push(Series::markers("model levels", pts_sa.clone()).with_labels(sa.iter().map(|x| x.0.clone())));
    c.series.push(Series::line_markers("Pareto front", front.iter().map(|&i| pts_sa[i])));
    charts.push(c.write_png_svg(&charts_dir.join("speed_accuracy"))?.png);

    // ---- strength reduction chart
    if let Some(s) = &ssr {
        let mut t: Vec<(f64, f64)> = s.result.trials.iter().map(|t| (t.factor, t.monitor_displacement.max(1e-9))).collect();
        t.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut c = Chart::new("Strength reduction: displacement of P1 against F", "strength reduction factor F [-]", "|u| of P1 after relaxation [m]");
        c.y_axis = Axis::Log;
        c.series.push(Series::line_markers(format!("FEM ({} mesh)", s.mesh), t));
        charts.push(c.write_png_svg(&charts_dir.join("ssr"))?.png);
    }

    // ---- cheapest level per PGA
    let mut cheapest = Vec::new();
    for &p in &pgas {
        let Some(r) = find(&runs, |s| is_ref(s) && s.pga == p) else { continue };
        if r.failed.is_some() {
            cheapest.push((p, "none: the reference run failed".to_string(), f64::NAN, f64::NAN));
            continue;
        }
        let refv = r.residual_slip;
        let rg = rigid_of(p);
        let mut cands: Vec<(String, f64, f64)> = vec![("rigid block".into(), rg.wall_time, rg.brittle.result.residual_displacement)];
        for x in runs.iter().filter(|x| plain(&x.spec) && x.spec.pga == p && !is_ref(&x.spec) && x.failed.is_none()) {
            if let Some(wall) = x.wall_time {
                cands.push((x.level.clone(), wall, x.residual_slip));
            }
        }
        if let Some(wall) = r.wall_time {
            cands.push((r.level.clone() + " (reference)", wall, refv));
        }
        cands.sort_by(|a, b| a.1.total_cmp(&b.1));
        let tol = prm.enough * refv.abs().max(0.01);
        if let Some(c) = cands.iter().find(|c| (c.2 - refv).abs() <= tol) {
            cheapest.push((p, c.0.clone(), c.1, c.2));
        }
    }

    // ---- trend against the seed, for each rock model
    let mut trend = Vec::new();
    for (label, nts, ntn) in [(main_rock, &nts_sweep, &ntn_sweep), (other_rock, &nts_other, &ntn_other)] {
        let pairs: Vec<(f64, f64, f64)> = pgas
            .iter()
            .filter_map(|&p| {
                let a = nts.iter().find(|x| x.0 == p)?.1;
                let b = ntn.iter().find(|x| x.0 == p)?.1;
                Some((p, a, b))
            })
            .collect();
        if pairs.is_empty() {
            continue;
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
        if let Some(d) = diffs.iter().find(|x| x.0 == 1.0) {
            trend.push(format!("{label}: at 1.0 g (NTS − NTN)/NTN = {} (seed: +26.5 % with the Koyna record, 18.6 cm vs 14.7 cm).", fmt_percent(d.1, 1)));
        }
        let none_below: Vec<f64> = pairs.iter().filter(|x| x.1.max(x.2) < 0.01).map(|x| x.0).collect();
        trend.push(format!(
            "{label}: no significant sliding (< 1 cm) at {} (seed: none at 0.5 g and below).",
            if none_below.is_empty() { "no PGA".to_string() } else { none_below.iter().map(|p| format!("{p} g")).collect::<Vec<_>>().join(", ") }
        ));
    }

    // ---- report.md
    let mut md = String::new();
    let _ = writeln!(md, "# Wedge study: the Hoek & Bray wedge (seed paper, section 4)\n");
    let _ = writeln!(md, "Generated by `jointquake study report` from `{}`. Units SI; slip and displacements in m.\n", results.plan.study.display());
    let _ = writeln!(md, "## Model\n");
    let mat = base.materials.iter().map(|mm| format!("`{}` E = {} GPa, ν = {}, ρ = {} kg/m³", mm.group, mm.e / 1e9, mm.nu, mm.rho)).collect::<Vec<_>>().join("; ");
    let w = &prm.wedge;
    let plane = |p: &crate::rigid::wedge::PlaneOrientation| format!("{}/{}", p.dip, p.dip_direction);
    let levels = study
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
    let dc = base.joints.iter().filter_map(|j| j.softening_slip).fold(0.0, f64::max);
    let loss = if dc > 0.0 {
        format!("Cohesion is lost after slip: it softens linearly to zero over d_c = {} mm of a pair's accumulated slip (and an opening beyond d_c breaks it)", dc * 1e3)
    } else {
        "Cohesion is lost at a pair's first slip or opening (brittle)".to_string()
    };
    let strength = base
        .joints
        .iter()
        .filter(|j| [&prm.joints.a, &prm.joints.b].contains(&&j.name))
        .map(|j| {
            let phi = match (j.mu, j.phi) {
                (Some(mu), _) => mu.atan().to_degrees(),
                (None, Some(p)) => p,
                (None, None) => 0.6f64.atan().to_degrees(),
            };
            format!("{} φ = {}°, c = {} kPa", j.name, fmt_sig_short(phi), fmt_sig_short(j.cohesion.unwrap_or(0.0) / 1e3))
        })
        .collect::<Vec<_>>()
        .join("; ");
    let _ = writeln!(md, "- Joints: {strength} (seed table 1). {loss}; during gravity equilibrium bonds are kept (`equilibrium.joint_bonds = \"kept\"`).");
    let grav = base.loads.gravity.as_ref().and_then(|g| g.groups.clone()).map(|g| g.join(", ")).unwrap_or_else(|| "all".into());
    let _ = writeln!(md, "- Gravity on: {grav} (the rock is a weightless support, as in limit equilibrium); brought to equilibrium before the record.");
    let _ = writeln!(
        md,
        "- Rock of the main runs: {main_rock}{}. The PGA sweep is repeated with the {other_rock} (tables and the slip-against-PGA chart).",
        if rr { " (its nodes fixed: the wedge slides on its joints under the base motion itself, as on a stiff massless foundation; the elastic rock box, without absorbing boundaries, rings: see \"The rock's response\")" } else { "" }
    );
    let recs = base.loads.base.iter().map(|b| format!("`{}` along ({}, {}, {}) × {}", b.record.as_ref().and_then(|r| r.file_name()).map(|f| f.to_string_lossy().into_owned()).unwrap_or_else(|| b.synth.as_ref().map(|s| format!("synth seed {} {}", s.seed, s.component)).unwrap_or_default()), b.direction[0], b.direction[1], b.direction[2], b.pga.map(|p| format!("PGA {p} g")).or(b.scale.map(|s| format!("scale {s}"))).unwrap_or_else(|| "1".into()))).collect::<Vec<_>>().join("; ");
    let _ = writeln!(md, "- Base motion (base scene): {recs}. Every record is scaled by one factor so that the horizontal PGA takes the study values: by default the committed El Centro 1940 NS record horizontally (y, north) and 2/3 of the same record vertically (z), in phase. The seed used the Koyna record, which is not public.");
    let _ = writeln!(md, "- Damping: {}. Duration {} s per run (record plus free vibration).\n", damping_text(base), base.time.duration);

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
            "\nFEM against limit equilibrium for the same geometry: {} ({}). Failure criterion: {}. The seed's 1.66 and 1.68 match our limit equilibrium with H read as the crest height on plane A ({}); its own 1.60 is below both readings.\n",
            fmt_percent(dev, 1),
            if dev.abs() <= 0.03 { "within the 3 % required" } else { "outside 3 %" },
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

    let _ = writeln!(md, "## Seismic runs\n");
    let joint_names = base.joints.iter().map(|j| j.name.as_str()).collect::<Vec<_>>().join(" / ");
    let mut t = Table::new(["PGA [g]".to_string(), "level".into(), "P1 ux".into(), "P1 uy".into(), "P1 uz".into(), "slip at P2".into(), "still sliding".into(), "failure mode".into(), format!("max opening {joint_names}")]);
    for &p in &pgas {
        for r in runs.iter().filter(|r| r.spec.e_factor == 1.0 && r.spec.pga == p && r.spec.mesh == sweep && r.spec.layer == 1) {
            let op = r.max_opening.iter().map(|(_, v)| m(*v)).collect::<Vec<_>>().join(" / ");
            let level = format!("{}, {}", r.level, if r.spec.rigid_rock { "rigid rock" } else { "elastic rock" });
            let (slip, mode) = match &r.failed {
                Some(_) => (format!("≥ {} (stopped at t = {} s, see below)", m(r.max_slip), m(r.slip_history.last().map(|x| x.0).unwrap_or(0.0))), r.mode.clone()),
                None => (m(r.residual_slip), r.mode.clone()),
            };
            let _ = t.push_row([m(p), level, m(r.p1_residual[0]), m(r.p1_residual[1]), m(r.p1_residual[2]), slip, (if r.still_sliding { "yes" } else { "no" }).into(), mode, op]);
        }
        let rg = rigid_of(p);
        let _ = t.push_row([m(p), "rigid block, cohesion lost".into(), "".into(), "".into(), "".into(), m(rg.brittle.result.residual_displacement), (if rg.brittle.result.still_sliding { "yes" } else { "no" }).into(), format!("{} sliding episodes", rg.brittle.result.n_episodes), "".into()]);
        let _ = t.push_row([m(p), "rigid block, cohesion kept".into(), "".into(), "".into(), "".into(), m(rg.kept.result.residual_displacement), (if rg.kept.result.still_sliding { "yes" } else { "no" }).into(), format!("{} sliding episodes", rg.kept.result.n_episodes), "".into()]);
    }
    md.push_str(&t.to_markdown());
    let stopped: Vec<&WedgeRun> = runs.iter().filter(|r| r.failed.is_some()).collect();
    if !stopped.is_empty() || !stopped_early.is_empty() {
        let _ = writeln!(md, "\nRuns stopped by their checks (the slip they had reached is a lower bound):\n");
        for r in stopped {
            let _ = writeln!(md, "- `{}`: {}", r.spec.id, r.failed.as_deref().unwrap_or("").trim_start_matches("error: "));
        }
        for (id, f) in &stopped_early {
            let _ = writeln!(md, "- `{id}` (before its first history row): {f}");
        }
    }
    let _ = writeln!(md, "\n![slip against PGA](charts/slip_vs_pga.svg)\n");
    if !nts_other.is_empty() {
        let _ = writeln!(md, "![slip against PGA, other rock model](charts/slip_vs_pga_other_rock.svg)\n");
    }
    let _ = writeln!(md, "![slip history](charts/slip_history.svg)\n\n![P1 displacement](charts/p1_history.svg)\n");
    let _ = writeln!(md, "### Against the seed's trend\n");
    for s in &trend {
        let _ = writeln!(md, "- {s}");
    }
    let _ = writeln!(md);

    let _ = writeln!(md, "## The rock's response under the wedge\n");
    let _ = writeln!(md, "Peak absolute acceleration of the rock node `{}` below the line of intersection (NTS-L1 runs on the elastic rock, {sweep} mesh) against the PGA, and the rigid block driven by that computed motion instead of the base record (cohesion lost at the first slide): the part of the elastic-rock slip that the rock's own response explains. The rock box of `geo/wedge.geo` has fixed sides and bottom and no absorbing boundary, so its response is that of a closed box (resonant), not of a slope in a half-space.\n", prm.monitors.rock);
    let mut t = Table::new(["PGA [g]", "rock peak x / y / z [g]", "amplification y / PGA", "rigid block on the base record", "rigid block on the rock's motion", "FEM NTS-L1"]);
    for &p in &pgas {
        if let Some(r) = find(&runs, |s| s.e_factor == 1.0 && !s.rigid_rock && s.pga == p && s.method == "nts" && s.mesh == sweep && s.layer == 1) {
            let pk = r.rock_peak_accel.map(|a| format!("{} / {} / {}", m(a[0]), m(a[1]), m(a[2]))).unwrap_or_else(|| "–".into());
            let amp = r.rock_peak_accel.map(|a| m(a[1] / p)).unwrap_or_else(|| "–".into());
            let _ = t.push_row([m(p), pk, amp, m(rigid_of(p).brittle.result.residual_displacement), r.rigid_on_rock_slip.map(m).unwrap_or_else(|| "–".into()), m(r.residual_slip)]);
        }
    }
    md.push_str(&t.to_markdown());
    let _ = writeln!(md);

    let _ = writeln!(md, "## Stiffness and rock model (PGA {acc} g, NTS-L1, {sweep} mesh; the main runs: {main_rock})\n");
    let mut t = Table::new(["variant", "slip at P2", "change"]);
    let base_slip = nts_acc.map(|r| r.residual_slip).unwrap_or(f64::NAN);
    let _ = t.push_row(["E as given".to_string(), m(base_slip), "–".into()]);
    for r in runs.iter().filter(|r| r.spec.pga == acc && r.spec.method == "nts" && r.spec.mesh == sweep && r.spec.layer == 1 && (r.spec.e_factor != 1.0 || r.spec.rigid_rock != rr)) {
        let name = if r.spec.rigid_rock != rr { other_rock.to_string() } else { format!("E × {}", r.spec.e_factor) };
        let _ = t.push_row([name, m(r.residual_slip), fmt_percent(r.residual_slip / base_slip - 1.0, 1)]);
    }
    md.push_str(&t.to_markdown());
    let _ = writeln!(md);

    let _ = writeln!(md, "## Speed against accuracy (PGA {acc} g)\n");
    let mut t = Table::new(["level", "wall time [s]", "slip [m]", "error vs reference", "Pareto front"]);
    for (i, x) in sa.iter().enumerate() {
        let _ = t.push_row([x.0.clone(), m(x.1), m(x.2), fmt_percent(x.3, 1), (if front.contains(&i) { "yes" } else { "" }).into()]);
    }
    if let Some(r) = ref_acc {
        let _ = t.push_row([format!("{} (reference)", r.level), opt(r.wall_time), m(r.residual_slip), "0".into(), "".into()]);
    }
    md.push_str(&t.to_markdown());
    let _ = writeln!(md, "\n![speed against accuracy](charts/speed_accuracy.svg)\n");
    let _ = writeln!(md, "Cheapest level whose residual slip is within {} of the reference (or of 1 cm when the reference is smaller), for each PGA:\n", fmt_percent(prm.enough, 0));
    let mut t = Table::new(["PGA [g]", "cheapest sufficient level", "wall time [s]", "slip [m]"]);
    for (p, l, w, s) in &cheapest {
        let num = |x: f64| if x.is_finite() { m(x) } else { "–".to_string() };
        let _ = t.push_row([m(*p), l.clone(), num(*w), num(*s)]);
    }
    md.push_str(&t.to_markdown());
    if ssr.is_some() {
        let _ = writeln!(md, "\n![strength reduction](charts/ssr.svg)\n");
    }
    let _ = writeln!(md, "\n## Runs\n");
    let mut t = Table::new(["run".to_string(), "nodes".into(), "elements".into(), "dt [s]".into(), "steps".into(), "wall time [s]".into(), "slip [m]".into(), format!("lost node-steps {joint_names}")]);
    for r in &runs {
        let lost = r.lost_node_steps.iter().map(|(_, v)| v.map_or_else(|| "–".to_string(), |v| v.to_string())).collect::<Vec<_>>().join(" / ");
        let slip = if r.failed.is_some() { format!("failed (≥ {})", m(r.max_slip)) } else { m(r.residual_slip) };
        let count = |x: Option<usize>| x.map_or_else(|| "–".to_string(), |x| x.to_string());
        let _ = t.push_row([r.spec.id.clone(), count(r.nodes), count(r.elements), r.dt.map_or_else(|| "–".to_string(), |x| fmt_sig(x, 3)), count(r.steps), opt(r.wall_time), slip, lost]);
    }
    md.push_str(&t.to_markdown());
    let lines = trend.clone();
    let rep = WedgeReport { le, ssr, runs, rigid, cheapest, trend };
    Ok(KindReport { markdown: md, json: serde_json::to_value(&rep).expect("the report serialises"), charts, lines, unreadable, lists_failed: true })
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
