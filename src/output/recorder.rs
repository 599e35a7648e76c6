//! The run's recorder: what a run writes and watches while it steps (an observer of a
//! [`Simulation`]).
//!
//! - **Schedule**: a history row every `output.history_stride` steps (monitors and joints), a
//!   frame every `output.frame_stride` steps, or every `frame_interval` seconds, or about 100
//!   frames over the run; the last step always writes a frame. A run of no steps writes the
//!   equilibrium state as its one frame.
//! - **Monitors**: the scene's points snapped to nodes ([`snap_monitors`]).
//! - **Peaks**: |u|, |v|, |a| of any node, sampled every [`PEAK_STRIDE`] steps and at the last.
//! - **Progress**: a bar on stderr when asked for and stderr is a terminal; nothing otherwise.
//! - **Envelopes**: stress envelopes on face groups ([`super::envelope`], `output.envelope`).
//! - **Summary**: [`Recorder::summary`] gathers the [`RunSummary`].
//!
//! Velocities and accelerations are the scheme's central differences at t[n]
//! ([`crate::dynamics::Kinematics`]).

use super::envelope::EnvelopeWriter;
use super::frames::FrameWriter;
use super::history::{HistoryWriter, Monitor};
use super::joints::JointWriter;
use super::summary::{Peak, RunSummary};
use crate::contact::joint::Method;
use crate::dynamics::Kinematics;
use crate::error::{Error, ModelError, OutputError};
use crate::model::Model;
use crate::problem::Problem;
use crate::scene::Scene;
use crate::simulation::{Observer, Simulation};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};

/// Steps between two samples of the peak |u|, |v|, |a|. Default 10: a scan of every node costs
/// about a step's nodal update; one in ten keeps it under 10 % and still samples a 10 Hz
/// response 40 times a period at the wedge's dt (2.6e-4 s).
pub const PEAK_STRIDE: usize = 10;

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
    /// Update with the kinematics at t[n].
    pub fn update(&mut self, model: &Model, kin: &Kinematics<'_>) {
        for n in 0..model.n_nodes() {
            let m2 = kin.u[3 * n].powi(2) + kin.u[3 * n + 1].powi(2) + kin.u[3 * n + 2].powi(2);
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

/// Everything a run writes: frames, histories, joint series, peaks, progress.
pub struct Recorder {
    pub out_dir: PathBuf,
    pub monitors: Vec<Monitor>,
    history: HistoryWriter,
    frames: Option<FrameWriter>,
    joints: Option<JointWriter>,
    envelope: Option<EnvelopeWriter>,
    pub peaks: Peaks,
    frame_stride: usize,
    hist_stride: usize,
    rows: Vec<[f64; 9]>,
    bar: indicatif::ProgressBar,
}

impl Recorder {
    /// Create the output directory and the writers for `sim`'s problem, with a progress bar if
    /// `progress` and stderr is a terminal.
    pub fn create(sim: &Simulation<'_>, out_dir: &Path, progress: bool) -> Result<Recorder, Error> {
        let p: &Problem = sim.problem;
        let (model, scene) = (&p.model, &p.scene);
        std::fs::create_dir_all(out_dir).map_err(|e| OutputError::write(out_dir, e))?;
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
        let frame_stride = match (scene.output.frame_stride, scene.output.frame_interval) {
            (Some(k), _) => k,
            (None, Some(fi)) => ((fi / dt).round() as usize).max(1),
            (None, None) => (n_steps / 100).max(1),
        };
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
            frame_stride,
            hist_stride: scene.output.history_stride.max(1),
            rows,
            bar,
        })
    }

    /// The monitors' rows [u; v; a] at `kin`.
    fn monitor_rows(&mut self, kin: &Kinematics<'_>) {
        for (r, m) in self.rows.iter_mut().zip(&self.monitors) {
            for c in 0..3 {
                let i = 3 * m.node + c;
                r[c] = kin.u[i];
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
            pvd: self.frames.as_ref().map(|f| f.series.path().to_path_buf()),
            histories: self.history.paths().into_iter().chain(self.joints.as_ref().map(|j| j.csv_paths()).unwrap_or_default()).collect(),
            joint_series: self.joints.as_ref().map(|j| j.pvd_paths()).unwrap_or_default(),
            joints: self.joints.as_ref().map(|j| j.peaks.clone()).unwrap_or_default(),
            out_dir: self.out_dir.clone(),
            notes: sim.notes.clone(),
            timings,
            wall_time,
        }
    }
}

impl Observer for Recorder {
    fn start(&mut self, sim: &Simulation<'_>) -> Result<(), Error> {
        if sim.n_steps() > 0 {
            return Ok(());
        }
        // `duration: 0` runs only the equilibrium: write that state (at rest) as the one frame
        let p = sim.problem;
        let kin = sim.kinematics_at_rest();
        let kin = Kinematics { t: 0.0, ..kin };
        for (r, m) in self.rows.iter_mut().zip(&self.monitors) {
            r[..3].copy_from_slice(&kin.u[3 * m.node..3 * m.node + 3]);
        }
        self.history.row(0.0, &self.rows)?;
        if let Some(f) = self.frames.as_mut() {
            f.write(&p.model, &kin)?;
        }
        if let Some(e) = self.envelope.as_mut() {
            e.sample(&p.model, kin.u, 0.0);
        }
        if let Some(jw) = self.joints.as_mut() {
            jw.record(0.0, &p.joints, &sim.state.contact)?;
            jw.write_frame(0.0, &p.joints, &sim.state.contact, &sim.state.u)?;
        }
        Ok(())
    }

    fn observe(&mut self, sim: &Simulation<'_>, k: usize, n_steps: usize) -> Result<(), Error> {
        let p = sim.problem;
        let state = &sim.state;
        // the step just taken gives u[n−1], u[n], u[n+1]: outputs are at t[n] = t − dt
        let kin = sim.kinematics();
        if k % self.hist_stride == 0 {
            self.monitor_rows(&kin);
            self.history.row(kin.t, &self.rows)?;
            if let Some(jw) = self.joints.as_mut() {
                jw.record(state.t, &p.joints, &state.contact)?;
            }
        }
        if let Some(e) = self.envelope.as_mut() {
            if k % e.stride == 0 || k + 1 == n_steps {
                e.sample(&p.model, kin.u, kin.t);
            }
        }
        if k % PEAK_STRIDE == 0 || k + 1 == n_steps {
            self.peaks.update(&p.model, &kin);
        }
        if k % self.frame_stride == 0 || k + 1 == n_steps {
            if let Some(f) = self.frames.as_mut() {
                f.write(&p.model, &kin)?;
            }
            if let Some(jw) = self.joints.as_mut() {
                jw.write_frame(state.t, &p.joints, &state.contact, &state.u)?;
            }
            self.history.flush()?;
        }
        if k % 64 == 0 {
            self.bar.set_position(k as u64);
            self.bar.set_message(format!("{:.4}", kin.t));
        }
        Ok(())
    }

    fn finish(&mut self, sim: &Simulation<'_>) -> Result<(), Error> {
        self.bar.finish_and_clear();
        self.history.flush()?;
        if let Some(e) = &self.envelope {
            e.write(&sim.problem.model, &self.out_dir)?;
        }
        if let Some(jw) = self.joints.as_mut() {
            // the last step already wrote its frame (k + 1 == n_steps in `observe`)
            jw.flush()?;
        }
        Ok(())
    }
}
