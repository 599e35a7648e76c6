//! Joint output: per joint a VTU series of the slave surface (`joints/<joint>.pvd`), a CSV
//! history (`histories/joint_<joint>.csv`) and running maxima for `summary.json`.
//!
//! Point fields on the slave surface (one value per slave node): `displacement` (3, m),
//! `normal` (3), `gap` (m, NaN when the node found no master face), `opening` = max(gap, 0) (m),
//! `slip` (accumulated slip path, m), `tangential_displacement` |d_t| (m), `normal_traction`
//! (Pa, compression positive), `shear_traction` (Pa), `state` (0 open, 1 stick, 2 slip,
//! 3 bonded), `tributary_area` (m²).

use crate::vtk::pvd::PvdSeries;
use crate::vtk::vtu::{write_vtu, Field, Grid};
use crate::contact::state::{ContactState, JointRecord};
use crate::contact::joint::ContactJoint;
use crate::contact::law::PairState;
use crate::error::OutputError;
use crate::mesh::CellKind;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Running maxima of one joint (for the summary).
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct JointPeaks {
    pub name: String,
    pub method: String,
    pub slave_group: String,
    pub master_group: String,
    pub slave_nodes: usize,
    /// Largest opening over the run [m] and when.
    pub max_opening: f64,
    pub max_opening_t: f64,
    /// Largest accumulated slip path [m].
    pub max_slip: f64,
    /// Largest |d_t| (net tangential relative displacement) [m].
    pub max_tangential_displacement: f64,
    /// Largest penetration (−gap) seen at the end of a step [m].
    pub max_penetration: f64,
    pub max_sweeps: usize,
    /// Gauss–Seidel tolerance on the largest node displacement change of a sweep [m] (0 for penalty joints, which
    /// are not iterated), and the steps that did not reach it within the sweep budget.
    pub gs_tolerance: f64,
    pub unconverged_steps: u64,
    pub events: crate::contact::state::SearchEvents,
    /// Largest slave-to-O distance (the NTN geometric error) [m].
    pub ntn_max_distance: f64,
}

pub struct JointWriter {
    dir: PathBuf,
    series: Vec<PvdSeries>,
    csv: Vec<(PathBuf, BufWriter<std::fs::File>)>,
    pub peaks: Vec<JointPeaks>,
    frames: bool,
}

fn state_counts(r: &JointRecord) -> [usize; 4] {
    let mut c = [0; 4];
    for p in &r.pairs {
        c[p.state.code() as usize] += 1;
    }
    c
}

impl JointWriter {
    pub fn create(out_dir: &Path, joints: &[ContactJoint], frames: bool) -> Result<JointWriter, OutputError> {
        let dir = out_dir.join("joints");
        let hdir = out_dir.join("histories");
        for d in [&dir, &hdir] {
            std::fs::create_dir_all(d).map_err(|e| OutputError::write(d, e))?;
        }
        let mut series = Vec::new();
        let mut csv = Vec::new();
        let mut peaks = Vec::new();
        for j in joints {
            series.push(PvdSeries::new(dir.join(format!("{}.pvd", j.tag.name))));
            let p = hdir.join(format!("joint_{}.csv", j.tag.name));
            let f = std::fs::File::create(&p).map_err(|e| OutputError::write(&p, e))?;
            let mut w = BufWriter::new(f);
            writeln!(w, "t,max_opening,max_slip,max_tangential_displacement,max_penetration,open,stick,slip,bonded,sweeps,normal_force,shear_force")
                .map_err(|e| OutputError::write(&p, e))?;
            csv.push((p, w));
            peaks.push(JointPeaks {
                name: j.tag.name.clone(),
                method: format!("{:?}", j.method),
                slave_group: j.tag.slave.group.clone(),
                master_group: j.tag.master.group.clone(),
                slave_nodes: j.tag.n_slave(),
                ntn_max_distance: j.tag.ntn_max_distance,
                ..Default::default()
            });
        }
        Ok(JointWriter { dir, series, csv, peaks, frames })
    }

    /// Update maxima and append a history row per joint at time `t`.
    pub fn record(&mut self, t: f64, joints: &[ContactJoint], state: &ContactState) -> Result<(), OutputError> {
        for (k, (j, r)) in joints.iter().zip(&state.joints).enumerate() {
            let mut mo = 0.0f64;
            let mut ms = 0.0f64;
            let mut md = 0.0f64;
            let mut mp = 0.0f64;
            let mut fn_ = 0.0;
            let mut ft = 0.0;
            for p in &r.pairs {
                if p.gap.is_finite() {
                    mo = mo.max(p.gap);
                    mp = mp.max(-p.gap);
                }
                ms = ms.max(p.slip);
                md = md.max((p.d_t[0] * p.d_t[0] + p.d_t[1] * p.d_t[1]).sqrt());
                fn_ += p.r_n;
                ft += (p.r_t[0] * p.r_t[0] + p.r_t[1] * p.r_t[1]).sqrt();
            }
            let pk = &mut self.peaks[k];
            if mo > pk.max_opening {
                pk.max_opening = mo;
                pk.max_opening_t = t;
            }
            pk.max_slip = pk.max_slip.max(ms);
            pk.max_tangential_displacement = pk.max_tangential_displacement.max(md);
            pk.max_penetration = pk.max_penetration.max(mp);
            pk.max_sweeps = r.max_sweeps;
            pk.unconverged_steps = r.unconverged_steps;
            pk.events = r.events.clone();
            let c = state_counts(r);
            let (p, w) = &mut self.csv[k];
            writeln!(w, "{t:.9e},{mo:.9e},{ms:.9e},{md:.9e},{mp:.9e},{},{},{},{},{},{fn_:.9e},{ft:.9e}", c[0], c[1], c[2], c[3], r.sweeps)
                .map_err(|e| OutputError::write(p.as_path(), e))?;
            let _ = j;
        }
        Ok(())
    }

    /// Flush the CSV histories (rows written so far reach the disk).
    pub fn flush(&mut self) -> Result<(), OutputError> {
        for (p, w) in &mut self.csv {
            w.flush().map_err(|e| OutputError::write(p.as_path(), e))?;
        }
        Ok(())
    }

    /// Write one joint-surface frame per joint and flush the histories.
    pub fn write_frame(&mut self, t: f64, joints: &[ContactJoint], state: &ContactState, u: &[f64]) -> Result<(), OutputError> {
        self.flush()?;
        if !self.frames {
            return Ok(());
        }
        for (k, (j, r)) in joints.iter().zip(&state.joints).enumerate() {
            let surf = &j.tag.slave;
            let np = surf.nodes.len();
            let mut disp = Vec::with_capacity(3 * np);
            let mut normal = Vec::with_capacity(3 * np);
            let (mut gap, mut opening, mut slip, mut dtan, mut sn, mut st, mut area) =
                (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
            let mut code = Vec::with_capacity(np);
            for (i, &n) in surf.nodes.iter().enumerate() {
                disp.extend_from_slice(&u[3 * n..3 * n + 3]);
                normal.extend_from_slice(&j.tag.normals[i]);
                let p = &r.pairs[i];
                let a = j.tag.areas[i];
                gap.push(p.gap);
                opening.push(if p.gap.is_finite() { p.gap.max(0.0) } else { 0.0 });
                slip.push(p.slip);
                dtan.push((p.d_t[0] * p.d_t[0] + p.d_t[1] * p.d_t[1]).sqrt());
                sn.push(p.r_n / a);
                st.push((p.r_t[0] * p.r_t[0] + p.r_t[1] * p.r_t[1]).sqrt() / a);
                area.push(a);
                code.push(if p.face < 0 && p.state == PairState::Open { 0 } else { p.state.code() as i32 });
            }
            let cells: Vec<(CellKind, &[u32])> = surf.faces.iter().map(|f| (f.kind, f.local_nodes())).collect();
            let grid = Grid { points: &surf.points, cells };
            let idx = self.series[k].len();
            let path = self.dir.join(format!("{}_{idx:05}.vtu", j.tag.name));
            write_vtu(
                &path,
                &grid,
                &[
                    Field::f64("displacement", 3, &disp),
                    Field::f64("normal", 3, &normal),
                    Field::f64("gap", 1, &gap),
                    Field::f64("opening", 1, &opening),
                    Field::f64("slip", 1, &slip),
                    Field::f64("tangential_displacement", 1, &dtan),
                    Field::f64("normal_traction", 1, &sn),
                    Field::f64("shear_traction", 1, &st),
                    Field::i32("state", 1, &code),
                    Field::f64("tributary_area", 1, &area),
                ],
                &[],
            )?;
            self.series[k].push(t, &path)?;
        }
        Ok(())
    }

    pub fn pvd_paths(&self) -> Vec<PathBuf> {
        self.series.iter().map(|s| s.path().to_path_buf()).collect()
    }

    pub fn csv_paths(&self) -> Vec<PathBuf> {
        self.csv.iter().map(|(p, _)| p.clone()).collect()
    }
}
