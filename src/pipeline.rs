//! The recipe: the only function that sequences the stages (scene → mesh → model → loads →
//! equilibrium → dynamic run → outputs). Each stage is timed into `summary.json`.

use crate::contact::force::ContactSolver;
use crate::dynamics::{relax_gravity, loads::Loads, Correction, EquilibriumInfo, ExplicitSolver, Stage, State};
use crate::output::joints::{JointPeaks, JointWriter};
use crate::error::{Error, ModelError};
use crate::mesh::Mesh;
use crate::model::Model;
use crate::output::frames::{FrameWriter, Kinematics};
use crate::output::history::{HistoryWriter, Monitor};
use crate::scene::Scene;
use serde::Serialize;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Options of a run that are not part of the scene.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// Override the output directory.
    pub out_dir: Option<PathBuf>,
    /// Where gmsh meshes are cached. Default `build/mesh`.
    pub mesh_cache: Option<PathBuf>,
    /// Show a progress bar (only drawn when stderr is a terminal). Default false.
    pub progress: bool,
    /// Replace the scene's `time.duration` [s]. Default: the scene's.
    pub duration: Option<f64>,
    /// Threads of the run. Default `None`: [`default_threads`] (one thread below
    /// [`SERIAL_BELOW_ELEMENTS`] elements, else all of rayon's pool).
    pub threads: Option<usize>,
}

/// Peak of a quantity and where it happened.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Peak {
    pub value: f64,
    pub t: f64,
    pub node_tag: u64,
}

/// What a run reports (written as `summary.json`).
#[derive(Clone, Debug, Serialize)]
pub struct RunSummary {
    pub scene: String,
    pub mesh: PathBuf,
    pub nodes: usize,
    pub elements: usize,
    pub tets: usize,
    pub hexes: usize,
    pub hex_shapes: usize,
    pub dt: f64,
    pub dt_stable: f64,
    pub critical_element: u64,
    pub critical_group: String,
    pub steps: usize,
    pub duration: f64,
    pub threads: usize,
    pub equilibrium: Option<EquilibriumInfo>,
    pub energy: crate::dynamics::Energy,
    pub peak_displacement: Peak,
    /// Peak |v| [m/s] and |a| [m/s²] of any node (relative to the base, central differences;
    /// sampled every 10 steps, as the peak displacement).
    pub peak_velocity: Peak,
    pub peak_acceleration: Peak,
    pub monitors: Vec<Monitor>,
    pub frames: usize,
    pub out_dir: PathBuf,
    pub pvd: Option<PathBuf>,
    pub histories: Vec<PathBuf>,
    /// Joint-surface series (one `.pvd` per joint).
    pub joint_series: Vec<PathBuf>,
    /// Joint maxima and search/Gauss–Seidel diagnostics.
    pub joints: Vec<JointPeaks>,
    pub notes: Vec<String>,
    /// Stage wall times [s].
    pub timings: Vec<(String, f64)>,
    pub wall_time: f64,
}

/// Produce the mesh of a scene (gmsh for a `.geo`, or the given `.msh`) and read it.
pub fn load_mesh(scene: &Scene, opts: &RunOptions) -> Result<Mesh, Error> {
    let path = match (&scene.geometry.geo, &scene.geometry.msh) {
        (Some(geo), _) => {
            let cache = opts.mesh_cache.clone().unwrap_or_else(|| PathBuf::from("build/mesh"));
            crate::gmsh::mesh_geo(geo, &scene.geometry.set, &cache)?
        }
        (None, Some(msh)) => msh.clone(),
        (None, None) => unreachable!("validated"),
    };
    Ok(Mesh::from_msh(path)?)
}

/// Snap monitored points to nodes (optionally of a group).
pub fn snap_monitors(model: &Model, scene: &Scene) -> Result<Vec<Monitor>, Error> {
    let mut out = Vec::new();
    for m in &scene.output.monitor {
        let candidates: Vec<usize> = match &m.group {
            Some(g) => model.mesh.group_nodes(g)?,
            None => (0..model.n_nodes()).filter(|&n| model.mass[n] > 0.0).collect(),
        };
        let d = |n: usize| {
            let x = model.mesh.nodes[n];
            ((x[0] - m.point[0]).powi(2) + (x[1] - m.point[1]).powi(2) + (x[2] - m.point[2]).powi(2)).sqrt()
        };
        let node = candidates
            .iter()
            .copied()
            .min_by(|&a, &b| d(a).total_cmp(&d(b)).then(a.cmp(&b)))
            .ok_or_else(|| ModelError::Invalid(format!("monitor \"{}\": no node to snap to", m.name)))?;
        out.push(Monitor {
            name: m.name.clone(),
            requested: m.point,
            node,
            node_tag: model.mesh.node_tags[node],
            position: model.mesh.nodes[node],
            snap_distance: d(node),
        });
    }
    Ok(out)
}

/// Run a scene file end to end.
pub fn run(scene_path: &Path, opts: &RunOptions) -> Result<RunSummary, Error> {
    let t_all = Instant::now();
    let mut laps = Laps::start();
    let mut scene = Scene::load(scene_path)?;
    if let Some(d) = opts.duration {
        if !(d.is_finite() && d >= 0.0) {
            return Err(crate::error::SceneError::Invalid { path: scene_path.to_path_buf(), message: format!("--duration {d}: must be a finite time ≥ 0 [s]") }.into());
        }
        scene.time.duration = d;
    }
    let mesh = load_mesh(&scene, opts)?;
    let mesh_path = mesh.source.clone();
    laps.lap("mesh");
    let model = Model::build(mesh, &scene)?;
    let (loads, notes) = Loads::build(&model, &scene)?;
    laps.lap("model");
    let threads = opts.threads.unwrap_or_else(|| default_threads(model.n_elements(), rayon::current_num_threads()));
    if threads == rayon::current_num_threads() {
        simulate(opts, scene, &model, mesh_path, loads, notes, laps, t_all)
    } else {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().map_err(|e| ModelError::Invalid(format!("cannot start {threads} threads: {e}")))?;
        pool.install(|| simulate(opts, scene, &model, mesh_path, loads, notes, laps, t_all))
    }
}

/// Wall time of a run's stages [s], in order.
struct Laps {
    timings: Vec<(String, f64)>,
    t: Instant,
}

impl Laps {
    fn start() -> Laps {
        Laps { timings: Vec::new(), t: Instant::now() }
    }

    /// Close the stage `name` and start the next.
    fn lap(&mut self, name: &str) {
        self.timings.push((name.to_string(), self.t.elapsed().as_secs_f64()));
        self.t = Instant::now();
    }
}

/// Below this many elements a run uses one thread unless told otherwise (`RunOptions::threads`,
/// `jointquake run --threads`). Measured on the 2-core machine (docs/performance.md §1, Two
/// threads): the wedge's medium mesh (13 941 tet4, two joints) stepped 12 s of El Centro in
/// 24.1 s on one thread and 28.2 s on two; the fine mesh (26 849 tet4) 46.0 s and 45.6 s. The
/// contact correction is serial and a model this small does not pay for the threads' start.
pub const SERIAL_BELOW_ELEMENTS: usize = 30_000;

/// The thread count of a run when none is given: one below [`SERIAL_BELOW_ELEMENTS`], else all
/// of rayon's (`available`).
pub fn default_threads(elements: usize, available: usize) -> usize {
    if elements < SERIAL_BELOW_ELEMENTS { 1 } else { available }
}

/// The time integration of a built model: equilibrium, dynamic stage, output, summary.
#[allow(clippy::too_many_arguments)]
fn simulate(
    opts: &RunOptions,
    scene: Scene,
    model: &Model,
    mesh_path: PathBuf,
    loads: Loads,
    mut notes: Vec<String>,
    mut laps: Laps,
    t_all: Instant,
) -> Result<RunSummary, Error> {
    let mut contact = if model.joints.is_empty() { None } else { Some(ContactSolver::new(&model, &model.joints)) };
    // ---- massless blocks: condensed statically every step (after the contact correction)
    let t_cond = Instant::now();
    let mut condensation = crate::foundation::Condensation::build(model, faer::Par::Seq).map_err(|e| ModelError::Invalid(e.to_string()))?;
    if let Some(c) = condensation.as_ref() {
        let i = c.info(t_cond.elapsed().as_secs_f64());
        notes.push(format!(
            "massless blocks: {} unknowns condensed on {} interface unknowns (factor {} entries, {:.2} s); foundation ω² bound {:.4e} 1/s²",
            i.condensed_unknowns, i.interface_unknowns, i.factor_entries, i.setup_time, i.omega2_bound
        ));
    }

    // ---- time step (penalty springs and the condensed foundation add their stiffness to the
    // highest frequency)
    let pen_w2 = contact.as_ref().map(|c| c.penalty_omega2_bound(&model)).unwrap_or(0.0);
    let found_w2 = condensation.as_ref().map(|c| c.omega2_bound()).unwrap_or(0.0);
    let dt_stable = if pen_w2 + found_w2 > 0.0 {
        if pen_w2 > 0.0 {
            notes.push(format!("penalty springs: stable step reduced from {:.4e} s", model.stable_dt()));
        }
        model.stable_dt_with(pen_w2 + found_w2)
    } else {
        model.stable_dt()
    };
    // the step's correction: the contact force, then the condensation
    let correction_of = |contact: &mut Option<ContactSolver>, condensation: &mut Option<crate::foundation::Condensation>, f: &mut dyn FnMut(Option<&mut dyn Correction>) -> Result<(), Error>| -> Result<(), Error> {
        match (contact.as_mut(), condensation.as_mut()) {
            (Some(a), Some(b)) => f(Some(&mut crate::foundation::CorrectionPair { first: a, second: b })),
            (Some(a), None) => f(Some(a)),
            (None, Some(b)) => f(Some(b)),
            (None, None) => f(None),
        }
    };
    let dt = match scene.time.dt {
        Some(dt) => {
            if dt > dt_stable {
                return Err(ModelError::UnstableStep { dt, limit: dt_stable, element: model.critical.tag, group: model.critical.group.clone() }.into());
            }
            dt
        }
        None => scene.time.courant.unwrap_or(0.9) * dt_stable,
    };
    let mut solver = ExplicitSolver::new(&model, dt, scene.time.energy_tolerance);
    let mut state = State::at_rest(&model);

    // ---- gravity equilibrium
    let equilibrium = if (loads.gravity.is_some() || !loads.static_forces.is_empty()) && scene.equilibrium.method == "relaxation" {
        if let Some(c) = contact.as_mut() {
            c.keep_bonds = scene.equilibrium.joint_bonds == "kept";
        }
        let mut eq = None;
        correction_of(&mut contact, &mut condensation, &mut |corr| {
            eq = Some(relax_gravity(&model, &loads, &mut solver, &mut state, corr, scene.equilibrium.tolerance, scene.equilibrium.max_steps)?);
            Ok(())
        })?;
        let eq = eq.expect("relaxation ran");
        if !eq.converged && eq.residual > scene.equilibrium.max_residual {
            return Err(ModelError::Invalid(format!(
                "gravity equilibrium not reached in {} steps: residual {:.2e} > max_residual {:.1e}. Raise equilibrium.max_steps or check supports (a block without supports or contact falls freely).",
                eq.steps, eq.residual, scene.equilibrium.max_residual
            ))
            .into());
        }
        if !eq.converged {
            notes.push(format!("gravity equilibrium residual {:.2e} above tolerance {:.1e} (accepted below max_residual)", eq.residual, scene.equilibrium.tolerance));
        }
        if let Some(c) = contact.as_mut() {
            c.keep_bonds = false;
        }
        state.step = 0;
        state.t = 0.0;
        // slip during equilibration is not seismic slip: restart the joint counters from here
        for r in &mut state.contact.joints {
            for p in &mut r.pairs {
                p.slip = 0.0;
                p.d_t = [0.0; 2];
                // the softening of a bond counts the slip of the earthquake, not of settling
                p.hist.slip = 0.0;
            }
        }
        Some(eq)
    } else {
        None
    };
    laps.lap("equilibrium");

    // ---- outputs
    let out_dir = opts.out_dir.clone().unwrap_or_else(|| scene.output_dir());
    std::fs::create_dir_all(&out_dir).map_err(|e| crate::error::OutputError::write(&out_dir, e))?;
    let monitors = snap_monitors(&model, &scene)?;
    let mut history = HistoryWriter::create(&out_dir.join("histories"), &monitors)?;
    let mut frames = if scene.output.frames { Some(FrameWriter::create(&out_dir, scene.name(), &model)?) } else { None };
    let mut joint_out = if model.joints.is_empty() { None } else { Some(JointWriter::create(&out_dir, &model.joints, scene.output.frames)?) };
    if let (Some(jw), Some(c)) = (joint_out.as_mut(), contact.as_ref()) {
        for (p, j) in jw.peaks.iter_mut().zip(&model.joints) {
            p.gs_tolerance = if matches!(j.method, crate::contact::joint::Method::Penalty { .. }) { 0.0 } else { c.gs_tolerance };
        }
    }
    let n_steps = (scene.time.duration / dt).round() as usize;
    let frame_stride = match (scene.output.frame_stride, scene.output.frame_interval) {
        (Some(k), _) => k,
        (None, Some(fi)) => ((fi / dt).round() as usize).max(1),
        (None, None) => (n_steps / 100).max(1),
    };
    let hist_stride = scene.output.history_stride.max(1);

    // ---- dynamic stage
    solver.start_energy(&model, &mut state);
    let bar = if opts.progress && std::io::stderr().is_terminal() {
        let b = indicatif::ProgressBar::new(n_steps as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template("{prefix} [{bar:40}] {pos}/{len} steps, t = {msg} s, eta {eta}")
                .unwrap()
                .progress_chars("=> "),
        );
        b.set_prefix(scene.name().to_string());
        b
    } else {
        indicatif::ProgressBar::hidden()
    };
    let mut peak = Peak::default();
    let mut peak_v = Peak::default();
    let mut peak_a = Peak::default();
    let mut rows = vec![[0.0; 9]; monitors.len()];
    if n_steps == 0 {
        // `duration: 0` runs only the equilibrium: write that state (at rest) as the one frame
        let kin = Kinematics { t: 0.0, dt, u_prev: &state.u, u: &state.u, u_next: &state.u };
        for (r, m) in rows.iter_mut().zip(&monitors) {
            r[..3].copy_from_slice(&kin.u[3 * m.node..3 * m.node + 3]);
        }
        history.row(0.0, &rows)?;
        if let Some(f) = frames.as_mut() {
            f.write(&model, &kin)?;
        }
        if let Some(jw) = joint_out.as_mut() {
            jw.record(0.0, &model.joints, &state.contact)?;
            jw.write_frame(0.0, &model.joints, &state.contact, &state.u)?;
        }
    }
    for k in 0..n_steps {
        correction_of(&mut contact, &mut condensation, &mut |corr| {
            solver.step(&model, &loads, &mut state, Stage::Dynamic, corr)?;
            Ok(())
        })?;
        // the step just taken gives u[n−1], u[n], u[n+1]: outputs are at t[n] = t − dt
        let kin = Kinematics { t: state.t - dt, dt, u_prev: &solver.u_nm1, u: &state.u_prev, u_next: &state.u };
        if k % hist_stride == 0 {
            for (r, m) in rows.iter_mut().zip(&monitors) {
                for c in 0..3 {
                    let i = 3 * m.node + c;
                    r[c] = kin.u[i];
                    r[3 + c] = (kin.u_next[i] - kin.u_prev[i]) / (2.0 * dt);
                    r[6 + c] = (kin.u_next[i] - 2.0 * kin.u[i] + kin.u_prev[i]) / (dt * dt);
                }
            }
            history.row(kin.t, &rows)?;
            if let Some(jw) = joint_out.as_mut() {
                jw.record(state.t, &model.joints, &state.contact)?;
            }
        }
        if k % 10 == 0 || k + 1 == n_steps {
            for n in 0..model.n_nodes() {
                let m2 = kin.u[3 * n].powi(2) + kin.u[3 * n + 1].powi(2) + kin.u[3 * n + 2].powi(2);
                if m2 > peak.value * peak.value {
                    peak = Peak { value: m2.sqrt(), t: kin.t, node_tag: model.mesh.node_tags[n] };
                }
                let (mut v2, mut a2) = (0.0, 0.0);
                for i in 3 * n..3 * n + 3 {
                    v2 += ((kin.u_next[i] - kin.u_prev[i]) / (2.0 * dt)).powi(2);
                    a2 += ((kin.u_next[i] - 2.0 * kin.u[i] + kin.u_prev[i]) / (dt * dt)).powi(2);
                }
                if v2 > peak_v.value * peak_v.value {
                    peak_v = Peak { value: v2.sqrt(), t: kin.t, node_tag: model.mesh.node_tags[n] };
                }
                if a2 > peak_a.value * peak_a.value {
                    peak_a = Peak { value: a2.sqrt(), t: kin.t, node_tag: model.mesh.node_tags[n] };
                }
            }
        }
        if k % frame_stride == 0 || k + 1 == n_steps {
            if let Some(f) = frames.as_mut() {
                f.write(&model, &kin)?;
            }
            if let Some(jw) = joint_out.as_mut() {
                jw.write_frame(state.t, &model.joints, &state.contact, &state.u)?;
            }
            history.flush()?;
        }
        if k % 64 == 0 {
            bar.set_position(k as u64);
            bar.set_message(format!("{:.4}", kin.t));
        }
    }
    bar.finish_and_clear();
    history.flush()?;
    if let Some(jw) = joint_out.as_mut() {
        // the last step already wrote its frame (k + 1 == n_steps above)
        jw.flush()?;
    }
    laps.lap("dynamic");

    let summary = RunSummary {
        scene: scene.name().to_string(),
        mesh: mesh_path,
        nodes: model.n_nodes(),
        elements: model.n_elements(),
        tets: model.tets.nodes.len(),
        hexes: model.hexes.nodes.len(),
        hex_shapes: model.hexes.shapes.len(),
        dt,
        dt_stable,
        critical_element: model.critical.tag,
        critical_group: model.critical.group.clone(),
        steps: n_steps,
        duration: scene.time.duration,
        threads: rayon::current_num_threads(),
        equilibrium,
        energy: state.energy.clone(),
        peak_displacement: peak,
        peak_velocity: peak_v,
        peak_acceleration: peak_a,
        monitors,
        frames: frames.as_ref().map(|f| f.series.len()).unwrap_or(0),
        pvd: frames.as_ref().map(|f| f.series.path().to_path_buf()),
        histories: history.paths().into_iter().chain(joint_out.as_ref().map(|j| j.csv_paths()).unwrap_or_default()).collect(),
        joint_series: joint_out.as_ref().map(|j| j.pvd_paths()).unwrap_or_default(),
        joints: joint_out.as_ref().map(|j| j.peaks.clone()).unwrap_or_default(),
        out_dir: out_dir.clone(),
        notes,
        timings: laps.timings,
        wall_time: t_all.elapsed().as_secs_f64(),
    };
    let sp = out_dir.join("summary.json");
    std::fs::write(&sp, serde_json::to_string_pretty(&summary).expect("summary serialises"))
        .map_err(|e| crate::error::OutputError::write(&sp, e))?;
    Ok(summary)
}

impl RunSummary {
    /// One screen of text for the end of a run.
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        use std::fmt::Write as _;
        let _ = writeln!(s, "scene {}: {} nodes, {} elements ({} tet4, {} hex8 in {} shapes)", self.scene, self.nodes, self.elements, self.tets, self.hexes, self.hex_shapes);
        let _ = writeln!(s, "  mesh            {}", self.mesh.display());
        let _ = writeln!(
            s,
            "  time step       dt = {:.4e} s ({:.0}% of the stable {:.4e} s; critical element {} in \"{}\")",
            self.dt,
            100.0 * self.dt / self.dt_stable,
            self.dt_stable,
            self.critical_element,
            self.critical_group
        );
        let _ = writeln!(s, "  steps           {} over {} s on {} thread{}", self.steps, self.duration, self.threads, if self.threads == 1 { "" } else { "s" });
        if let Some(eq) = &self.equilibrium {
            let _ = writeln!(s, "  gravity         equilibrium in {} steps, residual {:.2e}{}", eq.steps, eq.residual, if eq.converged { "" } else { " (NOT converged)" });
        }
        let _ = writeln!(s, "  energy          max balance error {:.2e} of the energy scale {:.3e} J", self.energy.max_error, self.energy.scale);
        let _ = writeln!(s, "  peak |u|        {:.4e} m at t = {:.4} s, node {}", self.peak_displacement.value, self.peak_displacement.t, self.peak_displacement.node_tag);
        let _ = writeln!(s, "  peak |v|, |a|   {:.4e} m/s (t = {:.4} s, node {}), {:.4e} m/s² (t = {:.4} s, node {})", self.peak_velocity.value, self.peak_velocity.t, self.peak_velocity.node_tag, self.peak_acceleration.value, self.peak_acceleration.t, self.peak_acceleration.node_tag);
        for m in &self.monitors {
            let _ = writeln!(s, "  monitor {:8} node {} ({:.3e} m from the requested point)", m.name, m.node_tag, m.snap_distance);
        }
        for j in &self.joints {
            let _ = writeln!(
                s,
                "  joint {:8} {} slave {} ({} nodes): max opening {:.3e} m, max slip {:.3e} m, max |d_t| {:.3e} m, max penetration {:.1e} m, GS sweeps ≤ {} (tolerance {:.1e} m){}",
                j.name, j.method, j.slave_group, j.slave_nodes, j.max_opening, j.max_slip, j.max_tangential_displacement, j.max_penetration, j.max_sweeps, j.gs_tolerance,
                if j.unconverged_steps > 0 { format!(" ({} steps unconverged)", j.unconverged_steps) } else { String::new() }
            );
            let e = &j.events;
            if e.widened_layer2 + e.fresh_searches + e.lost + e.projection_failures + e.recentred + e.perimeter_kept > 0 {
                let _ = writeln!(
                    s,
                    "                 search: {} re-centrings, {} kept at the perimeter, {} Layer2 widenings, {} fresh searches, {} node-steps lost, {} projection failures",
                    e.recentred, e.perimeter_kept, e.widened_layer2, e.fresh_searches, e.lost, e.projection_failures
                );
            }
        }
        for n in &self.notes {
            let _ = writeln!(s, "  note            {n}");
        }
        let t: Vec<String> = self.timings.iter().map(|(k, v)| format!("{k} {v:.2} s")).collect();
        let _ = writeln!(s, "  wall time       {:.2} s ({})", self.wall_time, t.join(", "));
        let _ = writeln!(s, "results in {}", self.out_dir.display());
        if let Some(p) = &self.pvd {
            let _ = writeln!(s, "  ParaView series {} ({} frames)", p.display(), self.frames);
        }
        for p in &self.joint_series {
            let _ = writeln!(s, "  joint series    {}", p.display());
        }
        for h in &self.histories {
            let _ = writeln!(s, "  history         {}", h.display());
        }
        let _ = writeln!(s, "  summary         {}", self.out_dir.join("summary.json").display());
        s
    }
}

// ---------------------------------------------------------------------------------------------
// `jointquake tag`: tag the joints of a scene and write them for inspection (no time stepping).

/// Default joint tolerance as a fraction of the mesh bounding-box diagonal, used when a joint
/// gives no `tolerance`. 1e-6: far above the round-off of coordinates written by Gmsh (≈1e-16
/// relative) and far below any gap a real model would want closed silently.
pub const DEFAULT_JOINT_TOLERANCE_RELATIVE: f64 = 1e-6;

/// What `tag` found for one joint (lengths in m, areas in m²).
#[derive(Clone, Debug, Serialize)]
pub struct JointTagSummary {
    pub name: String,
    /// Group that became the slave / master (after `auto`).
    pub slave_group: String,
    pub master_group: String,
    /// `auto` as written in the scene, and whether it exchanged the named roles.
    pub auto: bool,
    pub swapped: bool,
    /// Tolerance used [m] and where it came from ("scene" or "default").
    pub tolerance: f64,
    pub tolerance_source: String,
    pub slave_nodes: usize,
    pub slave_faces: usize,
    pub master_nodes: usize,
    pub master_faces: usize,
    pub slave_area: f64,
    pub master_area: f64,
    /// Mean number of master faces in Layer1 / Layer2 per slave node.
    pub layer1_mean: f64,
    pub layer2_mean: f64,
    /// Largest slave-node-to-O distance [m] (the NTN error) and the Gmsh tag of that slave node.
    pub ntn_max_distance: f64,
    pub ntn_max_node_tag: u64,
    /// Slave nodes whose O coincides with them (within 1e-9 × joint size).
    pub ntn_conforming: usize,
    /// Largest slave-node-to-master-surface distance [m].
    pub max_surface_distance: f64,
    /// The joint's VTU file.
    pub vtu: PathBuf,
}

/// What `tag` reports (also written as `<out>/tagging/summary.json`).
#[derive(Clone, Debug, Serialize)]
pub struct TagSummary {
    pub scene: String,
    pub mesh: PathBuf,
    pub nodes: usize,
    /// Mesh bounding-box diagonal [m] (scale of the default tolerance).
    pub model_size: f64,
    pub joints: Vec<JointTagSummary>,
    /// `joints.json` (all joints, layout in docs/tagger.md).
    pub json: PathBuf,
    pub out_dir: PathBuf,
    pub wall_time: f64,
}

/// A joint name made safe for a file name: characters other than letters, digits, `-`, `_` and
/// `.` become `_`.
fn joint_file_stem(name: &str) -> String {
    name.chars().map(|c| if c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.') { c } else { '_' }).collect()
}

/// Tag every joint of a scene: load the scene, mesh it, tag `scene.joints` in order (tolerance:
/// the joint's `tolerance`, else [`DEFAULT_JOINT_TOLERANCE_RELATIVE`] × the mesh bounding-box
/// diagonal), and write `<out>/tagging/joints.json`, one `<out>/tagging/<joint>.vtu` per joint and
/// `<out>/tagging/summary.json`. `<out>` is `opts.out_dir`, else the scene's output directory.
pub fn tag(scene_path: &Path, opts: &RunOptions) -> Result<TagSummary, Error> {
    use crate::error::InterfaceError;
    use crate::interface::{tag_joint, write_joint_json, write_joint_vtu, JointSpec};
    let t_all = Instant::now();
    let scene = Scene::load(scene_path)?;
    if scene.joints.is_empty() {
        return Err(crate::error::SceneError::Invalid {
            path: scene_path.to_path_buf(),
            message: "no joints to tag: add a `joints` list with `name`, `master` and `slave` face groups (see docs/scenes.md)".into(),
        }
        .into());
    }
    let mut stems: Vec<(String, &str)> = Vec::new();
    for j in &scene.joints {
        if j.name.is_empty() {
            return Err(crate::error::SceneError::Invalid { path: scene_path.to_path_buf(), message: "joints: a joint has an empty `name`".into() }.into());
        }
        let stem = joint_file_stem(&j.name);
        if let Some((_, other)) = stems.iter().find(|(s, _)| *s == stem) {
            return Err(InterfaceError::Invalid {
                joint: j.name.clone(),
                message: format!("its output file name \"{stem}.vtu\" is also that of joint \"{other}\"; give the joints distinct names"),
            }
            .into());
        }
        stems.push((stem, &j.name));
    }
    let mesh = load_mesh(&scene, opts)?;
    let model_size = mesh_diagonal(&mesh);
    let out_dir = opts.out_dir.clone().unwrap_or_else(|| scene.output_dir());
    let dir = out_dir.join("tagging");
    std::fs::create_dir_all(&dir).map_err(|e| crate::error::OutputError::write(&dir, e))?;

    let mut joints = Vec::with_capacity(scene.joints.len());
    let mut rows = Vec::with_capacity(scene.joints.len());
    for (j, (stem, _)) in scene.joints.iter().zip(&stems) {
        let spec = JointSpec { name: j.name.clone(), master: j.master.clone(), slave: j.slave.clone(), auto: j.auto };
        let (tolerance, source) = match j.tolerance {
            Some(t) => (t, "scene"),
            None => (DEFAULT_JOINT_TOLERANCE_RELATIVE * model_size, "default"),
        };
        let joint = tag_joint(&mesh, &spec, tolerance)?;
        let vtu = dir.join(format!("{stem}.vtu"));
        write_joint_vtu(&vtu, &mesh, &joint)?;
        let n = joint.n_slave().max(1) as f64;
        rows.push(JointTagSummary {
            name: joint.name.clone(),
            slave_group: joint.slave.group.clone(),
            master_group: joint.master.group.clone(),
            auto: j.auto,
            swapped: joint.swapped,
            tolerance,
            tolerance_source: source.to_string(),
            slave_nodes: joint.n_slave(),
            slave_faces: joint.slave.faces.len(),
            master_nodes: joint.master.nodes.len(),
            master_faces: joint.master.faces.len(),
            slave_area: joint.slave.area,
            master_area: joint.master.area,
            layer1_mean: joint.layer1.items.len() as f64 / n,
            layer2_mean: joint.layer2.items.len() as f64 / n,
            ntn_max_distance: joint.ntn_max_distance,
            ntn_max_node_tag: joint.slave.nodes.get(joint.ntn_max_slave).map(|&m| mesh.node_tags[m]).unwrap_or(0),
            ntn_conforming: joint.ntn_conforming_count(),
            max_surface_distance: joint.surface_distance.iter().copied().fold(0.0, f64::max),
            vtu,
        });
        joints.push(joint);
    }
    let json = dir.join("joints.json");
    write_joint_json(&json, &mesh, &joints)?;
    let summary = TagSummary {
        scene: scene.name().to_string(),
        mesh: mesh.source.clone(),
        nodes: mesh.nodes.len(),
        model_size,
        joints: rows,
        json,
        out_dir: dir.clone(),
        wall_time: t_all.elapsed().as_secs_f64(),
    };
    let sp = dir.join("summary.json");
    std::fs::write(&sp, serde_json::to_string_pretty(&summary).expect("tag summary serialises"))
        .map_err(|e| crate::error::OutputError::write(&sp, e))?;
    Ok(summary)
}

/// Diagonal of the bounding box of all mesh nodes [m] (0 for an empty mesh).
fn mesh_diagonal(mesh: &Mesh) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in &mesh.nodes {
        for d in 0..3 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    if mesh.nodes.is_empty() {
        return 0.0;
    }
    ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt()
}

impl TagSummary {
    /// A per-joint table for the terminal.
    pub fn to_text(&self) -> String {
        use std::fmt::Write as _;
        let mut s = String::new();
        let plural = if self.joints.len() == 1 { "" } else { "s" };
        let _ = writeln!(s, "scene {}: {} joint{plural} tagged on {} ({} nodes, model size {:.4} m)", self.scene, self.joints.len(), self.mesh.display(), self.nodes, self.model_size);
        for j in &self.joints {
            let _ = writeln!(s, "joint {}", j.name);
            let choice = match (j.auto, j.swapped) {
                (false, _) => "as named (auto off)".to_string(),
                (true, false) => "auto: kept the named roles (the named slave is the finer side, or a tie)".to_string(),
                (true, true) => "auto: swapped the named roles (the named master is the finer side)".to_string(),
            };
            let _ = writeln!(s, "  slave           \"{}\": {} nodes, {} faces, {:.4} m²", j.slave_group, j.slave_nodes, j.slave_faces, j.slave_area);
            let _ = writeln!(s, "  master          \"{}\": {} nodes, {} faces, {:.4} m²", j.master_group, j.master_nodes, j.master_faces, j.master_area);
            let _ = writeln!(s, "  roles           {choice}");
            let _ = writeln!(s, "  tolerance       {:.3e} m ({})", j.tolerance, if j.tolerance_source == "scene" { "from the scene" } else { "default: 1e-6 × model size" });
            let _ = writeln!(s, "  candidates      Layer1 {:.2}, Layer2 {:.2} master faces per slave node (mean)", j.layer1_mean, j.layer2_mean);
            let _ = writeln!(
                s,
                "  NTN             max distance to O {:.4e} m (slave node {}); {} of {} slave nodes conforming",
                j.ntn_max_distance, j.ntn_max_node_tag, j.ntn_conforming, j.slave_nodes
            );
            let _ = writeln!(s, "  surface gap     max {:.4e} m", j.max_surface_distance);
            let _ = writeln!(s, "  VTU             {}", j.vtu.display());
        }
        let _ = writeln!(s, "joints.json     {}", self.json.display());
        let _ = writeln!(s, "summary         {}", self.out_dir.join("summary.json").display());
        s
    }
}
