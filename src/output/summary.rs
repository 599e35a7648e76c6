//! The summary of a run (`summary.json`): written at the end of every run, read back by the
//! studies through [`RunSummary::read`] (typed, next to its writer).

use super::history::Monitor;
use super::joints::JointPeaks;
use crate::dynamics::{Energy, EquilibriumInfo};
use crate::error::OutputError;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Peak of a quantity and where it happened.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Peak {
    pub value: f64,
    pub t: f64,
    pub node_tag: u64,
}

/// What a run reports (written as `summary.json`).
#[derive(Clone, Debug, Serialize, Deserialize)]
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
    /// The critical element's scaled Jacobian (1 regular tet or cube, about 0 a sliver:
    /// `mesh::quality`, docs/elements.md "Mesh quality"); `None` in summaries written before it.
    #[serde(default)]
    pub critical_scaled_jacobian: Option<f64>,
    /// The critical element's step 2/ω over the mean element step of its block; `None` before.
    #[serde(default)]
    pub critical_step_ratio: Option<f64>,
    /// What `time.mass_scaling` did (scaled elements, added mass and its fraction of the total,
    /// largest factor: docs/elements.md "Mass scaling"); `None` without it (and in summaries
    /// written before it).
    #[serde(default)]
    pub mass_scaling: Option<crate::model::mass_scaling::MassScaling>,
    pub steps: usize,
    pub duration: f64,
    pub threads: usize,
    pub equilibrium: Option<EquilibriumInfo>,
    pub energy: Energy,
    pub peak_displacement: Peak,
    /// Peak |v| [m/s] and |a| [m/s²] of any node (relative to the base, central differences;
    /// sampled every 10 steps, as the peak displacement).
    pub peak_velocity: Peak,
    pub peak_acceleration: Peak,
    pub monitors: Vec<Monitor>,
    pub frames: usize,
    /// Per `block_id` of the frames (the material index, scene patterns expanded): its volume
    /// group, so a reader can name or hide a block (the dam's ParaView state hides the rock).
    /// Empty in summaries written before it.
    #[serde(default)]
    pub blocks: Vec<String>,
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
    /// Set when Ctrl-C / SIGTERM ended the run early: the time of its last output [s] (the
    /// outputs up to there are whole).
    #[serde(default)]
    pub interrupted: Option<f64>,
    /// Set when the signal came before the time loop: the phase it ended ("meshing", "the
    /// static state", …). `interrupted` is then 0 and the counts, peaks and outputs are empty
    /// (nothing of them was computed), see [`RunSummary::interrupted_before`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub interrupted_phase: Option<String>,
    /// Time between two history rows [s] (`output.history_stride` / `history_interval`).
    #[serde(default)]
    pub history_rows_every: f64,
    /// What the run got through but should not be trusted without a look (lost contact, an
    /// unconverged Gauss–Seidel, NTN on a non-conforming joint): also printed on the terminal.
    #[serde(default)]
    pub warnings: Vec<String>,
    /// Where and how the run ran (host, jointquake version and commit, Slurm ids); with
    /// `threads` and `wall_time` above, what a study's cost is summed from. `None` in summaries
    /// written before jointquake recorded it.
    #[serde(default)]
    pub provenance: Option<Provenance>,
    /// The acoustic reservoir's water (`reservoir.model: "acoustic"`): its step beside the
    /// solid's, its peak dynamic pressure and cavitation counts; absent for the other models.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub water: Option<crate::problem::reservoir::acoustic::WaterSummary>,
}

/// Where and how a run ran (`summary.json` → `provenance`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    /// Host name of the machine (`/proc/sys/kernel/hostname`, else `$HOSTNAME`, else "unknown").
    pub host: String,
    /// jointquake's version (Cargo.toml).
    pub version: String,
    /// The git commit jointquake was built from (`git rev-parse HEAD` at build time, build.rs),
    /// with `-dirty` when its sources differ from that commit, "unknown" when built outside a
    /// git checkout.
    pub commit: String,
    /// The Slurm job that ran it, when run under Slurm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slurm: Option<SlurmIds>,
}

/// Slurm's ids of the job running this process (from its environment).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SlurmIds {
    /// `SLURM_JOB_ID`.
    pub job_id: String,
    /// `SLURM_ARRAY_JOB_ID` and `SLURM_ARRAY_TASK_ID` for a task of a job array.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub array_job_id: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub array_task_id: Option<String>,
}

impl Provenance {
    /// The provenance of this process: its host, this build, and Slurm's ids if any.
    pub fn of_this_process() -> Provenance {
        let env = |k: &str| std::env::var(k).ok().map(|v| v.trim().to_string()).filter(|v| !v.is_empty());
        let host = std::fs::read_to_string("/proc/sys/kernel/hostname").ok().map(|h| h.trim().to_string()).filter(|h| !h.is_empty()).or_else(|| env("HOSTNAME")).unwrap_or_else(|| "unknown".into());
        let slurm = env("SLURM_JOB_ID").map(|job_id| SlurmIds { job_id, array_job_id: env("SLURM_ARRAY_JOB_ID"), array_task_id: env("SLURM_ARRAY_TASK_ID") });
        Provenance { host, version: env!("CARGO_PKG_VERSION").to_string(), commit: env!("JQ_GIT_COMMIT").to_string(), slurm }
    }

    /// `host`, with `Slurm job <array job>_<task>` (or `<job>`) when it ran under Slurm.
    pub fn place(&self) -> String {
        match &self.slurm {
            Some(SlurmIds { array_job_id: Some(a), array_task_id: Some(t), .. }) => format!("{} (Slurm job {a}_{t})", self.host),
            Some(s) => format!("{} (Slurm job {})", self.host, s.job_id),
            None => self.host.clone(),
        }
    }
}

impl RunSummary {
    /// Write `summary.json` into `out_dir` (whole, pretty-printed: `files::write_whole`, so a
    /// full disk leaves the previous file or none, never half of one).
    pub fn write(&self, out_dir: &Path) -> Result<PathBuf, OutputError> {
        let sp = out_dir.join("summary.json");
        crate::files::write_whole(&sp, serde_json::to_string_pretty(self).expect("summary serialises").as_bytes()).map_err(|(p, m)| OutputError::write(p, m))?;
        Ok(sp)
    }

    /// Read a `summary.json` written by [`Self::write`] (`path` is the file or its run directory).
    pub fn read(path: &Path) -> Result<RunSummary, OutputError> {
        let file = if path.is_dir() { path.join("summary.json") } else { path.to_path_buf() };
        let text = std::fs::read_to_string(&file).map_err(|e| OutputError::read(&file, e))?;
        serde_json::from_str(&text).map_err(|e| OutputError::read(&file, format!("not a run summary: {e}")))
    }

    /// The summary of a run that Ctrl-C or SIGTERM ended before its time loop, during `phase`:
    /// the scene, the output directory, the stage times and the phase; `interrupted` = 0 s and
    /// every count, peak and output empty (none was computed). Written as `summary.json` like a
    /// finished run's, so a study reads the run as interrupted, not as missing.
    pub fn interrupted_before(scene: &str, out_dir: &Path, phase: &str, timings: Vec<(String, f64)>, wall_time: f64) -> RunSummary {
        RunSummary {
            scene: scene.to_string(),
            mesh: PathBuf::new(),
            nodes: 0,
            elements: 0,
            tets: 0,
            hexes: 0,
            hex_shapes: 0,
            dt: 0.0,
            dt_stable: 0.0,
            critical_element: 0,
            critical_group: String::new(),
            critical_scaled_jacobian: None,
            critical_step_ratio: None,
            mass_scaling: None,
            steps: 0,
            duration: 0.0,
            threads: rayon::current_num_threads(),
            equilibrium: None,
            energy: Energy::default(),
            peak_displacement: Peak::default(),
            peak_velocity: Peak::default(),
            peak_acceleration: Peak::default(),
            monitors: Vec::new(),
            frames: 0,
            blocks: Vec::new(),
            out_dir: out_dir.to_path_buf(),
            pvd: None,
            histories: Vec::new(),
            joint_series: Vec::new(),
            joints: Vec::new(),
            notes: Vec::new(),
            timings,
            wall_time,
            interrupted: Some(0.0),
            interrupted_phase: Some(phase.to_string()),
            history_rows_every: 0.0,
            warnings: Vec::new(),
            provenance: Some(Provenance::of_this_process()),
            water: None,
        }
    }

    /// One screen of text for the end of a run.
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        use std::fmt::Write as _;
        if let Some(phase) = &self.interrupted_phase {
            let _ = writeln!(s, "scene {}: INTERRUPTED (Ctrl-C or SIGTERM) during {phase}, before the time loop: nothing after it was computed", self.scene);
            let t: Vec<String> = self.timings.iter().map(|(k, v)| format!("{k} {v:.2} s")).collect();
            let _ = writeln!(s, "  wall time       {:.2} s ({})", self.wall_time, t.join(", "));
            let _ = writeln!(s, "  summary         {}", self.out_dir.join("summary.json").display());
            return s;
        }
        let _ = writeln!(s, "scene {}: {} nodes, {} elements ({} tet4, {} hex8 in {} shapes)", self.scene, self.nodes, self.elements, self.tets, self.hexes, self.hex_shapes);
        let _ = writeln!(s, "  mesh            {}", self.mesh.display());
        let _ = writeln!(
            s,
            "  time step       dt = {:.4e} s ({:.0}% of the stable {:.4e} s; critical element {} in \"{}\"{})",
            self.dt,
            100.0 * self.dt / self.dt_stable,
            self.dt_stable,
            self.critical_element,
            self.critical_group,
            match (self.critical_scaled_jacobian, self.critical_step_ratio) {
                (Some(q), Some(r)) => format!(", scaled Jacobian {q:.3}, its step {r:.2} × its block's mean"),
                _ => String::new(),
            }
        );
        if let Some(w) = &self.water {
            let _ = writeln!(s, "  water           {}", w.line());
        }
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
                if j.unconverged_steps > 0 { format!(" ({} steps unconverged, residual up to {:.1e} m)", j.unconverged_steps, j.max_gs_residual) } else { String::new() }
            );
            if j.method == "Ntn" {
                let _ = writeln!(
                    s,
                    "                 NTN: largest slave-to-O distance {:.3e} m ({:.1} % of the face size {:.3e} m); penetration is measured against O, not the master surface",
                    j.ntn_max_distance, 100.0 * j.ntn_max_distance / j.face_size.max(f64::MIN_POSITIVE), j.face_size
                );
            }
            if j.reentries > 0 {
                let _ = writeln!(s, "                 {} re-entries after lost steps, {:.3e} J of positive work (joint's contact work {:.3e} J)", j.reentries, j.reentry_work, j.contact_work);
            }
            if j.max_lost_travel > 0.0 {
                let _ = writeln!(s, "                 lost nodes travelled up to {:.3e} m off their last master node", j.max_lost_travel);
            }
            let e = &j.events;
            if e.widened_layer2 + e.fresh_searches + e.lost + e.projection_failures + e.recentred + e.perimeter_kept > 0 {
                let _ = writeln!(
                    s,
                    "                 search: {} re-centrings, {} kept at the perimeter, {} Layer2 widenings, {} fresh searches, {} node-steps lost ({} beyond the master's free edge), {} projection failures",
                    e.recentred, e.perimeter_kept, e.widened_layer2, e.fresh_searches, e.lost, e.lost_beyond_edge, e.projection_failures
                );
            }
        }
        for n in &self.notes {
            let _ = writeln!(s, "  note            {n}");
        }
        for w in &self.warnings {
            let _ = writeln!(s, "  WARNING         {w}");
        }
        if let Some(t) = self.interrupted {
            let _ = writeln!(s, "  INTERRUPTED     at t = {t:.6} s of {} s (outputs whole up to there)", self.duration);
        }
        let t: Vec<String> = self.timings.iter().map(|(k, v)| format!("{k} {v:.2} s")).collect();
        let _ = writeln!(s, "  wall time       {:.2} s ({})", self.wall_time, t.join(", "));
        if let Some(p) = &self.provenance {
            let _ = writeln!(s, "  ran on          {} with jointquake {} (commit {})", p.place(), p.version, p.commit);
        }
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

