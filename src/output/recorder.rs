//! The run's recorder: what a run writes and watches while it steps (an observer of a
//! [`Simulation`]).
//!
//! - **Clock**: every output (history row, volume frame, joint frame) carries the state at the
//!   time it is stamped with, t[m] = m dt for output index m = 0 … N (N = duration / dt): the
//!   monitors and volume frames from the kinematics after step m (u[m−1], u[m], u[m+1]), the
//!   joints from the contact state after step m − 1 (the state at t[m]; at m = 0 the
//!   equilibrium). The last row and frame are at t[N] = duration.
//! - **Schedule**: a history row every `output.history_stride` steps or `history_interval`
//!   seconds (default [`DEFAULT_HISTORY_INTERVAL`], at least [`MIN_HISTORY_ROWS`] rows over the
//!   run), a frame every `output.frame_stride` steps, or every `frame_interval` seconds, or
//!   about 100 frames over the run; t[0] and t[N] always get both. A run of no steps writes the
//!   equilibrium state as its one frame.
//! - **Interruption**: Ctrl-C or SIGTERM ([`install_interrupt_handler`]) ends the run at the
//!   next output index: its row and frames are written whole and the summary says
//!   `interrupted`.
//! - **Monitors**: the scene's points snapped to nodes ([`snap_monitors`]).
//! - **Peaks**: |u|, |v|, |a| of any node, sampled every [`PEAK_STRIDE`] steps and at the last.
//! - **Displacement reference**: peaks and monitors report u relative to the free field, the
//!   same frame for every foundation model (`problem::foundation::free_field::Frame`): the
//!   integrated u of the massless and massed_fixed models already is; a radiating run's total
//!   u has its free field taken off. v and a are reported as integrated.
//! - **Progress**: a bar on stderr when asked for and stderr is a terminal; nothing otherwise.
//! - **Envelopes**: stress envelopes on face groups ([`super::envelope`], `output.envelope`);
//!   per-node joint envelopes of opening and net slip ([`super::joint_envelope`]).
//! - **Summary**: [`Recorder::summary`] gathers the [`RunSummary`].
//!
//! Velocities and accelerations are the scheme's central differences at t[n]
//! ([`crate::dynamics::Kinematics`]).

use super::envelope::EnvelopeWriter;
use super::frames::FrameWriter;
use super::history::{HistoryWriter, Monitor};
use super::joints::{JointPeaks, JointWriter};
use super::summary::{Peak, RunSummary};
use crate::contact::joint::Method;
use crate::dynamics::Kinematics;
use crate::error::{Error, ModelError, OutputError};
use crate::model::Model;
use crate::problem::foundation::free_field::{FreeField, Frame};
use crate::problem::Problem;
use crate::scene::Scene;
use crate::simulation::{Observer, Simulation};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};

/// Steps between two samples of the peak |u|, |v|, |a|. Default 10: a scan of every node costs
/// about a step's nodal update; one in ten keeps it under 10 % and still samples a 10 Hz
/// response 40 times a period at the wedge's dt (2.6e-4 s).
pub const PEAK_STRIDE: usize = 10;

/// Default time between two history rows [s] when the scene gives neither `history_stride` nor
/// `history_interval`: 1 ms, 1000 rows a second, 10 samples a period at 100 Hz (beyond the
/// content of any earthquake record) at about 200 B a row for a monitor (250 B for a joint):
/// 2 MB per monitor for a 10 s run, whatever its step (every step wrote 1.37 GB for a 5 M-step
/// run).
pub const DEFAULT_HISTORY_INTERVAL: f64 = 1e-3;

/// With the default interval, a run gets at least this many rows (short runs: impacts, waves):
/// the interval is min(1 ms, duration / 1000), never below one step.
pub const MIN_HISTORY_ROWS: f64 = 1000.0;

/// A joint whose lost node-steps (no master face: no contact force) exceed this fraction of its
/// slave node-steps gets a warning: 1 %. A lost node is force-free, so a block whose contact is
/// lost sinks into or falls through its base with the run still "passing" (`on_exit: "report"`
/// let a block sink 3.7 m); counted over the nodes lost inside the master's outline (those beyond
/// its free edge are a note, `contact::free_edge`); 1 % is far above the few edge nodes of a sliding wedge that daylight
/// near the end of a run, and far below a face that lost its contact.
pub const LOST_WARN_FRACTION: f64 = 0.01;

/// A joint whose re-entries (nodes finding a master face again after lost steps, pushed out
/// of the penetration they took while lost: `JointSceneSpec::reentry`) did positive work above
/// this fraction of the run's energy scale gets a warning: 1 %. The energy check stops a run
/// whose contact work turns positive by 5 % of the scale (`time.energy_tolerance`); a warning at
/// a fifth of that names the joint and the remedy before the numbers are trusted. The study
/// meshes of the dam at 3× design PGA stay below it (default mesh: 0.5 % in all, 0.4 % at its
/// worst joint); the boxes sliding out and back of the re-entry test are far above it.
pub const REENTRY_WARN_FRACTION: f64 = 0.01;

/// A joint whose Gauss–Seidel stopped at `gs_max_sweeps` with a residual (largest node change
/// of the last sweep) above this factor times its tolerance gets a warning: 10. Below it the
/// fixed point is within one decade of the requested accuracy, which the runs at the cap (wedge,
/// 1.5 g) reach; above it the contact forces of those steps are not converged.
pub const GS_WARN_FACTOR: f64 = 10.0;

/// A joint whose largest penetration (lost nodes included, measured against the master surface
/// they left) exceeds this fraction of its slave face size gets a warning, and the run ends
/// with an error (nonzero exit) after writing its outputs unless the scene sets
/// `output.allow_penetration` ([`penetration_excess`]): 0.1. A contact that
/// works keeps penetration at round-off (NTS) or at the penalty's F/k (a few µm on the incline
/// at k = 1e10 Pa/m); a tenth of an element is a block sinking into its base.
pub const PENETRATION_WARN_FRACTION: f64 = 0.1;

/// The joints whose largest penetration exceeds [`PENETRATION_WARN_FRACTION`] of their slave
/// face size, in one message (`None`: none). The run's warning, and the error that ends a run
/// with a nonzero exit unless the scene sets `output.allow_penetration` (issue 34: the incline
/// block sank 3.73 m into its base and the run ended with exit 0). Nodes lost beyond the
/// master's free edge do not count (they slid off the surface: nothing is there to penetrate).
pub fn penetration_excess(peaks: &[JointPeaks]) -> Option<String> {
    let over: Vec<String> = peaks
        .iter()
        .filter(|pk| pk.max_penetration > PENETRATION_WARN_FRACTION * pk.face_size)
        .map(|pk| format!("joint {}: the largest penetration is {:.3e} m, {:.0} % of the slave face size {:.3e} m", pk.name, pk.max_penetration, 100.0 * pk.max_penetration / pk.face_size, pk.face_size))
        .collect();
    if over.is_empty() {
        return None;
    }
    Some(format!(
        "{} (above {:.0} %; lost nodes are measured against the master surface they left): the joint does not hold its blocks apart",
        over.join("; "),
        100.0 * PENETRATION_WARN_FRACTION
    ))
}

/// An NTN joint whose largest slave-to-O distance exceeds this fraction of the slave face size
/// gets a warning: 0.1. NTN pairs each slave node with one master point O fixed at tagging; on a
/// non-conforming mesh the offset is a lever arm of the contact force (39–135 % stress error on a
/// patch test): use NTS there.
pub const NTN_WARN_FRACTION: f64 = 0.1;

/// Make Ctrl-C, SIGTERM and SIGHUP end a run cleanly ([`crate::interrupt`]): during the time
/// loop the run stops at its next output (row and frames written, `summary.json` marked
/// `interrupted`); before it, at the end of the phase it is in; a second signal quits at once
/// (exit status 130). For the CLI; call once.
pub fn install_interrupt_handler() -> Result<(), String> {
    crate::interrupt::install_handler()
}

/// The steps between two volume frames for `spec` at step `dt` over `n_steps` steps.
pub fn frame_stride(spec: &crate::scene::OutputSpec, dt: f64, n_steps: usize) -> usize {
    match (spec.frame_stride, spec.frame_interval) {
        (Some(k), _) => k,
        (None, Some(fi)) => ((fi / dt).round() as usize).max(1),
        (None, None) => (n_steps / 100).max(1),
    }
}

/// Most volume frames a run may write: 100 000 (34 GB of the demo wedge's 0.34 MB frames);
/// `frame_interval` 1e-9 s asked for one every step of a million-step run.
pub const MAX_FRAMES: usize = 100_000;
/// Most history rows a run may write per monitor and joint: 10⁸ (20 GB a monitor at 200 B a
/// row).
pub const MAX_HISTORY_ROWS: usize = 100_000_000;

/// The checks of a run's outputs that need the model and the step but write nothing, made
/// before the static state (`pipeline`) and again when the recorder is created: every output
/// file name unique within the run (a monitor `joint_J` and a joint `J` both wrote
/// `histories/joint_J.csv`, issue 34), no planned file an existing non-regular file (device,
/// fifo, symlink), the frame and history-row counts within [`MAX_FRAMES`] and
/// [`MAX_HISTORY_ROWS`], and the envelope's face groups valid (it was checked only after the
/// other outputs were written).
pub fn check_outputs(sim: &Simulation<'_>, out_dir: &Path) -> Result<(), Error> {
    let p: &Problem = sim.problem;
    let (model, scene) = (&p.model, &p.scene);
    let invalid = |m: String| -> Error { ModelError::Invalid(m).into() };
    let mut files: std::collections::BTreeMap<String, String> = std::collections::BTreeMap::new();
    let mut claim = |file: String, owner: String| -> Result<(), Error> {
        if let Some(other) = files.get(&file) {
            return Err(invalid(format!("output file {file} would be written by both {other} and {owner}: rename one of them (output file names must be unique within a run)")));
        }
        files.insert(file, owner);
        Ok(())
    };
    let stem = crate::files::file_stem;
    claim("summary.json".into(), "the run summary".into())?;
    if scene.output.frames {
        claim(format!("{}.pvd", stem(scene.name())), format!("the scene \"{}\"", scene.name()))?;
    }
    for m in &scene.output.monitor {
        claim(format!("histories/{}.csv", stem(&m.name)), format!("monitor \"{}\"", m.name))?;
    }
    if !p.joints.is_empty() {
        claim(super::joint_envelope::JOINT_ENVELOPE_FILE.into(), "the joints' per-node envelopes".into())?;
    }
    for j in &p.joints {
        let (s, who) = (stem(&j.tag.name), format!("joint \"{}\"", j.tag.name));
        claim(format!("histories/joint_{s}.csv"), who.clone())?;
        if scene.output.joint_forces {
            claim(format!("histories/joint_{s}_forces.csv"), who.clone())?;
        }
        if scene.output.frames {
            claim(format!("joints/{s}.pvd"), who)?;
        }
    }
    for f in files.keys() {
        crate::files::check_regular_target(&out_dir.join(f)).map_err(|m| invalid(format!("output: {m}")))?;
    }
    let (dt, n) = (sim.dt(), sim.n_steps());
    let frames = if scene.output.frames { n / frame_stride(&scene.output, dt, n).max(1) + 2 } else { 0 };
    if frames > MAX_FRAMES {
        return Err(invalid(format!("output: {frames} volume frames ({n} steps of {dt:.4e} s), above the limit of {MAX_FRAMES}: raise output.frame_interval or frame_stride, or set \"frames\": false")));
    }
    let rows = n / history_stride(&scene.output, dt, scene.time.duration) + 2;
    if rows > MAX_HISTORY_ROWS {
        return Err(invalid(format!("output: {rows} history rows ({n} steps of {dt:.4e} s), above the limit of {MAX_HISTORY_ROWS}: raise output.history_interval or history_stride")));
    }
    if let Some(spec) = &scene.output.envelope {
        EnvelopeWriter::create(model, spec)?;
    }
    Ok(())
}

/// The steps between two history rows for `spec` at step `dt` over `duration` [s].
pub fn history_stride(spec: &crate::scene::OutputSpec, dt: f64, duration: f64) -> usize {
    match (spec.history_stride, spec.history_interval) {
        (Some(k), _) => k.max(1),
        (None, Some(hi)) => ((hi / dt).round() as usize).max(1),
        (None, None) => {
            let hi = DEFAULT_HISTORY_INTERVAL.min(duration / MIN_HISTORY_ROWS);
            ((hi / dt).floor() as usize).max(1)
        }
    }
}

/// Snap monitored points to nodes (optionally of a group; else the nearest node with inertia).
pub fn snap_monitors(model: &Model, scene: &Scene) -> Result<Vec<Monitor>, Error> {
    let mut out = Vec::new();
    for m in &scene.output.monitor {
        let candidates: Vec<usize> = match &m.group {
            Some(g) => model.mesh.group_nodes(g)?,
            None => (0..model.n_nodes()).filter(|&n| model.mass.inertial[n] > 0.0).collect(),
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

/// The running maxima of |u|, |v|, |a| over the nodes.
#[derive(Clone, Debug, Default)]
pub struct Peaks {
    pub displacement: Peak,
    pub velocity: Peak,
    pub acceleration: Peak,
}

impl Peaks {
    /// Update with the kinematics at t[n]; the displacement relative to `reference` (node, t)
    /// when given (a radiating foundation's free field, [`FreeFieldRef`]).
    pub fn update(&mut self, model: &Model, kin: &Kinematics<'_>, reference: Option<FreeFieldRef<'_>>) {
        for n in 0..model.n_nodes() {
            let r = reference.map(|f| f.displacement(n, kin.t)).unwrap_or([0.0; 3]);
            let m2 = (kin.u[3 * n] - r[0]).powi(2) + (kin.u[3 * n + 1] - r[1]).powi(2) + (kin.u[3 * n + 2] - r[2]).powi(2);
            if m2 > self.displacement.value * self.displacement.value {
                self.displacement = Peak { value: m2.sqrt(), t: kin.t, node_tag: model.mesh.node_tags[n] };
            }
            let (mut v2, mut a2) = (0.0, 0.0);
            for i in 3 * n..3 * n + 3 {
                v2 += kin.velocity(i).powi(2);
                a2 += kin.acceleration(i).powi(2);
            }
            if v2 > self.velocity.value * self.velocity.value {
                self.velocity = Peak { value: v2.sqrt(), t: kin.t, node_tag: model.mesh.node_tags[n] };
            }
            if a2 > self.acceleration.value * self.acceleration.value {
                self.acceleration = Peak { value: a2.sqrt(), t: kin.t, node_tag: model.mesh.node_tags[n] };
            }
        }
    }
}

/// The free field a radiating foundation's displacements are reported against
/// (`problem::foundation::free_field::Frame`: the one reference of every foundation model).
#[derive(Clone, Copy)]
pub struct FreeFieldRef<'a> {
    pub field: &'a FreeField,
    pub frame: &'a Frame,
}

impl FreeFieldRef<'_> {
    fn displacement(&self, node: usize, t: f64) -> [f64; 3] {
        self.frame.displacement(self.field, node, t)
    }
}

/// Everything a run writes: frames, histories, joint series, peaks, progress.
pub struct Recorder {
    pub out_dir: PathBuf,
    pub monitors: Vec<Monitor>,
    history: HistoryWriter,
    frames: Option<FrameWriter>,
    joints: Option<JointWriter>,
    envelope: Option<EnvelopeWriter>,
    pub peaks: Peaks,
    /// The free-field frame of a radiating foundation (displacements reported relative to it).
    free_field: Option<Frame>,
    frame_stride: usize,
    hist_stride: usize,
    rows: Vec<[f64; 9]>,
    bar: indicatif::ProgressBar,
    /// The last output index after an interruption.
    stop: Option<usize>,
}

impl Recorder {
    /// Create the output directory and the writers for `sim`'s problem, with a progress bar if
    /// `progress` and stderr is a terminal.
    pub fn create(sim: &Simulation<'_>, out_dir: &Path, progress: bool) -> Result<Recorder, Error> {
        let p: &Problem = sim.problem;
        let (model, scene) = (&p.model, &p.scene);
        std::fs::create_dir_all(out_dir).map_err(|e| OutputError::write(out_dir, e))?;
        check_outputs(sim, out_dir)?;
        let monitors = snap_monitors(model, scene)?;
        let history = HistoryWriter::create(&out_dir.join("histories"), &monitors)?;
        let frames = if scene.output.frames { Some(FrameWriter::create(out_dir, scene.name(), model)?) } else { None };
        let mut joints = if p.joints.is_empty() { None } else { Some(JointWriter::create(out_dir, &p.joints, scene.output.frames, scene.output.joint_forces)?) };
        if let (Some(jw), Some(c)) = (joints.as_mut(), sim.contact.as_ref()) {
            for (pk, j) in jw.peaks.iter_mut().zip(&p.joints) {
                pk.gs_tolerance = if matches!(j.method, Method::Penalty { .. }) { 0.0 } else { c.gs_tolerance };
            }
        }
        let envelope = match &scene.output.envelope { Some(spec) => Some(EnvelopeWriter::create(model, spec)?), None => None };
        let dt = sim.dt();
        let n_steps = sim.n_steps();
        let frame_stride = frame_stride(&scene.output, dt, n_steps);
        let bar = if progress && std::io::stderr().is_terminal() {
            let b = indicatif::ProgressBar::new(n_steps as u64);
            b.set_style(
                indicatif::ProgressStyle::with_template("{prefix} [{bar:40}] {pos}/{len} steps, t = {msg} s, eta {eta}")
                    .expect("a valid progress template")
                    .progress_chars("=> "),
            );
            b.set_prefix(scene.name().to_string());
            b
        } else {
            indicatif::ProgressBar::hidden()
        };
        let rows = vec![[0.0; 9]; monitors.len()];
        Ok(Recorder {
            out_dir: out_dir.to_path_buf(),
            monitors,
            history,
            frames,
            joints,
            envelope,
            peaks: Peaks::default(),
            free_field: p.far_boundary.as_ref().map(|f| Frame::new(&f.free_field, model.mesh.nodes.iter().map(|x| x[2]))),
            frame_stride,
            hist_stride: history_stride(&scene.output, dt, scene.time.duration),
            rows,
            bar,
            stop: None,
        })
    }

    /// The monitors' rows [u; v; a] at `kin`, u relative to `reference` when given.
    fn monitor_rows(&mut self, kin: &Kinematics<'_>, reference: Option<FreeFieldRef<'_>>) {
        for (r, m) in self.rows.iter_mut().zip(&self.monitors) {
            let u0 = reference.map(|f| f.displacement(m.node, kin.t)).unwrap_or([0.0; 3]);
            for c in 0..3 {
                let i = 3 * m.node + c;
                r[c] = kin.u[i] - u0[c];
                r[3 + c] = kin.velocity(i);
                r[6 + c] = kin.acceleration(i);
            }
        }
    }

    /// The summary of the finished run `sim` (mesh file, stage timings and wall time from the
    /// caller).
    pub fn summary(&self, sim: &Simulation<'_>, mesh: PathBuf, timings: Vec<(String, f64)>, wall_time: f64) -> RunSummary {
        let (model, scene) = (&sim.problem.model, &sim.problem.scene);
        RunSummary {
            scene: scene.name().to_string(),
            mesh,
            nodes: model.n_nodes(),
            elements: model.n_elements(),
            tets: model.tets.nodes.len(),
            hexes: model.hexes.nodes.len(),
            hex_shapes: model.hexes.shapes.len(),
            dt: sim.time.dt,
            dt_stable: sim.time.dt_stable,
            critical_element: model.critical.tag,
            critical_group: model.critical.group.clone(),
            critical_scaled_jacobian: Some(model.critical.scaled_jacobian),
            critical_step_ratio: Some(model.critical.step_ratio),
            mass_scaling: model.mass_scaling.clone(),
            steps: sim.n_steps(),
            duration: scene.time.duration,
            threads: rayon::current_num_threads(),
            equilibrium: sim.equilibrium.clone(),
            energy: sim.state.energy.clone(),
            peak_displacement: self.peaks.displacement.clone(),
            peak_velocity: self.peaks.velocity.clone(),
            peak_acceleration: self.peaks.acceleration.clone(),
            monitors: self.monitors.clone(),
            frames: self.frames.as_ref().map(|f| f.series.len()).unwrap_or(0),
            blocks: model.materials.iter().map(|m| m.group.clone()).collect(),
            pvd: self.frames.as_ref().map(|f| f.series.path().to_path_buf()),
            histories: self.history.paths().into_iter().chain(self.joints.as_ref().map(|j| j.csv_paths()).unwrap_or_default()).collect(),
            joint_series: self.joints.as_ref().map(|j| j.pvd_paths()).unwrap_or_default(),
            joints: self.joints.as_ref().map(|j| j.peaks.clone()).unwrap_or_default(),
            out_dir: self.out_dir.clone(),
            notes: sim.notes.iter().cloned().chain(self.lost_notes(sim)).collect(),
            timings,
            wall_time,
            provenance: Some(crate::output::summary::Provenance::of_this_process()),
            interrupted: self.stop.map(|m| m as f64 * sim.dt()),
            interrupted_phase: None,
            history_rows_every: self.hist_stride as f64 * sim.dt(),
            warnings: self.warnings(sim),
            water: sim.water.as_ref().map(|w| w.stats.clone()),
        }
    }

    /// What the run got through but should not be trusted without a look: a sliver setting the
    /// stable step ([`crate::mesh::quality::SLIVER_SCALED_JACOBIAN`]), mass scaling that added
    /// more than [`crate::model::mass_scaling::ADDED_MASS_WARN_FRACTION`] of the mass, lost contact
    /// ([`LOST_WARN_FRACTION`]), energy created by re-entries ([`REENTRY_WARN_FRACTION`]), an
    /// unconverged Gauss–Seidel ([`GS_WARN_FACTOR`]), NTN on a non-conforming joint
    /// ([`NTN_WARN_FRACTION`]).
    fn warnings(&self, sim: &Simulation<'_>) -> Vec<String> {
        let mut w = Vec::new();
        let c = &sim.problem.model.critical;
        w.extend(sim.problem.warnings.iter().cloned());
        w.extend(sim.problem.model.mass_scaling.as_ref().and_then(|m| m.warning()));
        // a sliver whose inertia was scaled sets the scaling's target step, not its own
        if c.is_sliver() && c.mass_factor == 1.0 {
            w.push(format!(
                "the stable step is set by a sliver: element {} in \"{}\" has a scaled Jacobian of {:.3} (below {}) and a step {:.2} × its block's mean element step; a better shaped mesh would allow a larger step (gmsh: Mesh.Algorithm3D = 10 (HXT), or Mesh.OptimizeNetgen = 1 with the default Delaunay; else time.mass_scaling; docs/elements.md, \"Mesh quality\")",
                c.tag,
                c.group,
                c.scaled_jacobian,
                crate::mesh::quality::SLIVER_SCALED_JACOBIAN,
                c.step_ratio
            ));
        }
        let Some(jw) = self.joints.as_ref() else { return w };
        let steps = self.stop.unwrap_or(sim.n_steps()).max(1) as f64;
        // (steps, residual, tolerance, joints) of the Gauss–Seidel warnings
        let mut gs: Vec<(u64, f64, f64, Vec<String>)> = Vec::new();
        let mut worst_cap = None;
        let joint_names: Vec<&str> = sim.problem.joints.iter().map(|j| j.tag.name.as_str()).collect();
        for (pk, j) in jw.peaks.iter().zip(&sim.problem.joints) {
            let node_steps = pk.slave_nodes.max(1) as f64 * steps;
            // lost inside the master's outline (not beyond its free edge: `lost_notes`)
            let inside = pk.events.lost.saturating_sub(pk.events.lost_beyond_edge);
            let lost = inside as f64 / node_steps;
            if lost > LOST_WARN_FRACTION {
                let hint = if matches!(j.on_exit, crate::contact::joint::OnExit::Widen) { "" } else { " (on_exit \"report\": the candidate set never follows the node; use \"widen\")" };
                w.push(format!(
                    "joint {}: {} node-steps lost inside the master surface's outline ({:.1} % of its slave node-steps, above {:.0} %): lost nodes carry no contact force, so a block can sink into or fall through its base; the largest lost travel was {:.3e} m{hint}",
                    pk.name, inside, 100.0 * lost, 100.0 * LOST_WARN_FRACTION, pk.max_lost_travel
                ));
            }
            w.extend(penetration_excess(std::slice::from_ref(pk)));
            let scale = sim.state.energy.scale;
            if pk.reentry_work > REENTRY_WARN_FRACTION * scale && scale > 0.0 {
                w.push(format!(
                    "joint {}: {} re-entries (nodes that found a master face again after lost steps) were pushed out of the penetration they took while lost, doing {:.3e} J of positive work, {:.1} % of the energy scale {:.3e} J (above {:.0} %): energy created at the joint, which the energy check stops at {:.0} %; set the joint's `reentry` to \"hold\" (docs/contact.md, \"Re-entry\")",
                    pk.name,
                    pk.reentries,
                    pk.reentry_work,
                    100.0 * pk.reentry_work / scale,
                    scale,
                    100.0 * REENTRY_WARN_FRACTION,
                    100.0 * sim.problem.scene.time.energy_tolerance
                ));
            }
            if pk.unconverged_steps > 0 && pk.gs_tolerance > 0.0 && pk.max_gs_residual > GS_WARN_FACTOR * pk.gs_tolerance {
                // the joints' pairs are swept together, so joints sharing the sweeps report the
                // same numbers: one warning for them all (a dam's 28 joints gave 28 equal lines)
                let (steps, residual, tolerance) = (pk.unconverged_steps, pk.max_gs_residual, pk.gs_tolerance);
                worst_cap = worst_cap.or(pk.worst_cap.as_ref());
                match gs.iter_mut().find(|g| (g.0, g.1, g.2) == (steps, residual, tolerance)) {
                    Some(g) => g.3.push(pk.name.clone()),
                    None => gs.push((steps, residual, tolerance, vec![pk.name.clone()])),
                }
            }
            if matches!(j.method, Method::Ntn) && pk.ntn_max_distance > NTN_WARN_FRACTION * pk.face_size {
                w.push(format!(
                    "joint {}: NTN on a non-conforming joint: a slave node is {:.3e} m from its master point O, {:.0} % of the face size {:.3e} m (above {:.0} %): the offset acts as a lever arm (stress errors of tens of %); use method \"nts\"",
                    pk.name, pk.ntn_max_distance, 100.0 * pk.ntn_max_distance / pk.face_size, pk.face_size, 100.0 * NTN_WARN_FRACTION
                ));
            }
        }
        for (steps, residual, tolerance, names) in gs {
            let who = if names.len() == 1 { format!("joint {}", names[0]) } else { format!("joints {} ({} joints, swept together)", names.join(", "), names.len()) };
            let laws: Vec<&crate::contact::law::JointLaw> = sim.problem.joints.iter().map(|j| &j.law).collect();
            let worst = worst_cap.map(|c| format!("; {}{}", c.describe(&joint_names), cone_cycle_hint(c, &laws))).unwrap_or_default();
            w.push(format!(
                "{who}: Gauss–Seidel stopped at gs_max_sweeps in {steps} steps with a residual up to {residual:.2e} m, {:.0} × its tolerance {tolerance:.1e} m (above {GS_WARN_FACTOR}×): the contact forces of those steps are not converged (cap: ContactSolver::gs_max_sweeps, 200 sweeps){worst}",
                residual / tolerance
            ));
        }
        w
    }

    /// Notes of the slave nodes that slid beyond their master's free edge (the projection outside
    /// the master surface's outer boundary, `contact::free_edge`): no contact there, as expected
    /// when a block slides out past the end of what it rests on; one note per joint with any.
    fn lost_notes(&self, sim: &Simulation<'_>) -> Vec<String> {
        let Some(jw) = self.joints.as_ref() else { return Vec::new() };
        let steps = self.stop.unwrap_or(sim.n_steps()).max(1) as f64;
        jw.peaks
            .iter()
            .filter(|pk| pk.events.lost_beyond_edge > 0)
            .map(|pk| {
                let b = pk.events.lost_beyond_edge;
                format!(
                    "joint {}: {b} node-steps ({:.1} % of its slave node-steps) beyond the master's free edge: the slave nodes slid past the end of the master surface (their projection lies outside its outer boundary), so they touch nothing there; expected where a block slides out; {} node-steps lost inside its outline",
                    pk.name,
                    100.0 * b as f64 / (pk.slave_nodes.max(1) as f64 * steps),
                    pk.events.lost - b
                )
            })
            .collect()
    }

    /// Whether output index `m` gets a history row (`last`: the run's last index).
    fn history_due(&self, m: usize, last: usize) -> bool {
        m % self.hist_stride == 0 || m == last
    }

    /// Whether output index `m` gets a frame.
    fn frame_due(&self, m: usize, last: usize) -> bool {
        m % self.frame_stride == 0 || m == last
    }
}

impl Observer for Recorder {
    fn start(&mut self, sim: &Simulation<'_>) -> Result<(), Error> {
        let p = sim.problem;
        if sim.n_steps() > 0 {
            // the joints at t[0]: the equilibrium's contact state (the volume's t[0] comes with
            // the first step, which gives its velocity)
            if let Some(jw) = self.joints.as_mut() {
                jw.unsearched = sim.equilibrium.is_none();
                jw.record(0.0, &p.joints, &sim.state.contact, &sim.state.u)?;
                jw.write_frame(0.0, &p.joints, &sim.state.contact, &sim.state.u)?;
                jw.unsearched = false;
            }
            return Ok(());
        }
        // `duration: 0` runs only the equilibrium: write that state (at rest) as the one frame
        let kin = sim.kinematics_at_rest();
        let kin = Kinematics { t: 0.0, ..kin };
        for (r, m) in self.rows.iter_mut().zip(&self.monitors) {
            r[..3].copy_from_slice(&kin.u[3 * m.node..3 * m.node + 3]);
        }
        self.history.row(0.0, &self.rows);
        self.history.flush()?;
        if let Some(f) = self.frames.as_mut() {
            f.write(&p.model, &kin)?;
        }
        if let Some(e) = self.envelope.as_mut() {
            e.sample(&p.model, kin.u, 0.0);
        }
        if let Some(jw) = self.joints.as_mut() {
            jw.unsearched = sim.equilibrium.is_none();
            jw.record(0.0, &p.joints, &sim.state.contact, &sim.state.u)?;
            jw.write_frame(0.0, &p.joints, &sim.state.contact, &sim.state.u)?;
            jw.unsearched = false;
        }
        Ok(())
    }

    /// The foundation's displacements (Schur-complement condensation, docs/dam_physics.md) are
    /// read by frames, the last output and monitors on condensed nodes; the peaks in between see
    /// them as 0 (the interface nodes, which bound them in practice, are always sampled).
    fn full_state_due(&self, sim: &Simulation<'_>, k: usize, last: usize) -> bool {
        let condensed = &sim.problem.model.condensed;
        k == last || (self.frames.is_some() && self.frame_due(k, last)) || (self.history_due(k, last) && self.monitors.iter().any(|m| condensed[m.node] != 0))
    }

    fn observe(&mut self, sim: &Simulation<'_>, k: usize, last: usize) -> Result<(), Error> {
        let p = sim.problem;
        let state = &sim.state;
        let dt = sim.dt();
        if self.stop.is_none() && k < last && crate::interrupt::interrupted() {
            self.stop = Some(k + 1);
        }
        let last = self.stop.map_or(last, |s| s.min(last));
        // the step just taken gives u[k−1], u[k], u[k+1]: the volume and monitors at t[k]
        let kin = Kinematics { t: k as f64 * dt, ..sim.kinematics() };
        // the frame taken out while its reference is lent to the monitors and the peaks
        let frame = self.free_field.take();
        let reference = p.far_boundary.as_ref().zip(frame.as_ref()).map(|(f, frame)| FreeFieldRef { field: &f.free_field, frame });
        if self.history_due(k, last) {
            self.monitor_rows(&kin, reference);
            self.history.row(kin.t, &self.rows);
        }
        if let Some(e) = self.envelope.as_mut() {
            if k % e.stride == 0 || k == last {
                e.sample(&p.model, kin.u, kin.t);
            }
        }
        if k % PEAK_STRIDE == 0 || k == last {
            self.peaks.update(&p.model, &kin, reference);
        }
        self.free_field = frame;
        if self.frame_due(k, last) {
            if let Some(f) = self.frames.as_mut() {
                f.write(&p.model, &kin)?;
            }
            self.history.flush()?;
        }
        // ... and the contact state at t[k + 1], with u[k+1]
        if k < last {
            let t1 = (k + 1) as f64 * dt;
            let (row, frame) = (self.history_due(k + 1, last), self.frame_due(k + 1, last));
            if let Some(jw) = self.joints.as_mut() {
                if row {
                    jw.record(t1, &p.joints, &state.contact, &state.u)?;
                }
                if frame {
                    jw.write_frame(t1, &p.joints, &state.contact, &state.u)?;
                }
            }
        }
        if k % 64 == 0 {
            self.bar.set_position(k as u64);
            self.bar.set_message(format!("{:.4}", kin.t));
        }
        Ok(())
    }

    fn stop_after(&self) -> Option<usize> {
        self.stop
    }

    fn finish(&mut self, sim: &Simulation<'_>) -> Result<(), Error> {
        self.bar.finish_and_clear();
        self.history.flush()?;
        if let Some(e) = &self.envelope {
            e.write(&sim.problem.model, &self.out_dir)?;
        }
        if let Some(jw) = self.joints.as_mut() {
            jw.flush()?;
            jw.envelope.write(&self.out_dir)?;
        }
        Ok(())
    }
}

/// The cure to name when a Gauss–Seidel cap's worst node has pairs on two joints or more whose
/// laws are the seed's truncated Mohr–Coulomb cone with cohesion (no tensile strength, no
/// asperity envelope): a closed pair at r_n → 0 still carries c A and an open one nothing, so
/// the node's pairs can have no consistent state (docs/contact.md, "The bilinear envelope");
/// empty otherwise.
pub fn cone_cycle_hint(cap: &crate::contact::state::CapStep, laws: &[&crate::contact::law::JointLaw]) -> String {
    let mut joints: Vec<usize> = cap.pairs.iter().map(|p| p.0).collect();
    joints.sort_unstable();
    joints.dedup();
    let cone = |j: &usize| laws.get(*j).is_some_and(|l| !l.tied && l.cohesion > 0.0 && l.tensile_strength == 0.0 && l.asperity_friction.is_none());
    if joints.len() >= 2 && joints.iter().all(cone) {
        "; under the truncated Mohr–Coulomb cone (cohesion, no tensile strength) a closed pair at zero normal force still carries c A and an open one nothing, so such a node can have no consistent state: the opt-in bilinear envelope joints[].asperity_angle converges there (docs/contact.md, \"The bilinear envelope\"), as a different law".into()
    } else {
        String::new()
    }
}

#[cfg(test)]
mod cone_hint_tests {
    use super::cone_cycle_hint;
    use crate::contact::law::{JointLaw, PairState};
    use crate::contact::state::CapStep;

    /// The Gauss–Seidel warning names the bilinear envelope exactly when the capped node is shared
    /// by joints that all carry the seed's cohesive cone (the demo wedge's joints A and B: c 24 and
    /// 48 kPa, no tensile strength), and not for one joint, a tensile bond or an envelope.
    #[test]
    fn gs_cap_warning_names_the_envelope_only_for_a_node_shared_by_cohesive_cone_joints() {
        let cone = |c: f64| JointLaw { cohesion: c, keep_cohesion: true, ..JointLaw::coulomb(0.36) };
        let (a, b) = (cone(24e3), cone(48e3));
        let shared = CapStep { t: 24.39, node: 18, residual: 1.03e-6, pairs: vec![(0, 18, PairState::Slip), (1, 18, PairState::Open)] };
        assert!(cone_cycle_hint(&shared, &[&a, &b]).contains("asperity_angle"));
        let single = CapStep { pairs: vec![(1, 18, PairState::Slip)], ..shared.clone() };
        assert!(cone_cycle_hint(&single, &[&a, &b]).is_empty());
        let bonded = JointLaw { tensile_strength: 1e5, ..b };
        assert!(cone_cycle_hint(&shared, &[&a, &bonded]).is_empty());
        let envelope = JointLaw { asperity_friction: Some(1.0), ..b };
        assert!(cone_cycle_hint(&shared, &[&a, &envelope]).is_empty());
        let frictional = JointLaw::coulomb(0.36);
        assert!(cone_cycle_hint(&shared, &[&a, &frictional]).is_empty());
    }
}
