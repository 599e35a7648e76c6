//! Joint output: per joint a VTU series of the slave surface (`joints/<joint>.pvd`), a CSV
//! history (`histories/joint_<joint>.csv`) and running maxima for `summary.json`.
//!
//! Point fields on the slave surface (one value per slave node): `displacement` (3, m),
//! `normal` (3), `gap` (m, NaN when the node found no master face), `opening` = max(gap, 0) (m),
//! `slip` (accumulated slip path, m), `tangential_displacement` |d_t| (m), `normal_traction`
//! (Pa, compression positive), `shear_traction` (Pa), `state` (0 open, 1 stick, 2 slip,
//! 3 bonded; the labels are in the file's FieldData as `state_label_<name>`), `lost` (1 where the
//! node found no master face, else 0), `lost_travel` (m), `tributary_area` (m²).
//!
//! Lost nodes (no master face: slid off the master's edge): the contact's own slip and |d_t|
//! stop there, so on a lost node `slip` and `tangential_displacement` go on with `lost_travel`,
//! the distance the node moved relative to the master node it was last near (its candidate
//! set's centre) since the last output where it was in contact. `gap` is NaN there, which
//! ParaView spreads over the node's triangles: colour by `lost` or threshold it away.
//!
//! Time: the contact state after step k is the state at t[k + 1]; the recorder writes it with
//! that time, the same as the volume frame and the monitors' row of t[k + 1].

use crate::vtk::pvd::PvdSeries;
use crate::vtk::vtu::{write_vtu_labelled, Field, Grid};
use crate::contact::state::{ContactState, JointRecord};
use crate::contact::joint::ContactJoint;
use crate::contact::law::PairState;
use crate::error::OutputError;
use crate::mesh::CellKind;
use super::history::CsvLines;
use super::joint_envelope::JointEnvelopeWriter;
use std::fmt::Write as _;
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
    /// Largest `lost_travel` of a lost node [m] (see the module doc).
    #[serde(default)]
    pub max_lost_travel: f64,
    /// The last sweep's residual of the worst step [m] (largest node change left when a step
    /// stopped at the sweep budget; 0 when every step converged).
    #[serde(default)]
    pub max_gs_residual: f64,
    /// The step behind `max_gs_residual`: when, which node, the pairs on it (warning).
    #[serde(default)]
    pub worst_cap: Option<crate::contact::state::CapStep>,
    /// Typical slave face size √(slave area / faces) [m] (the scale of the NTN warning).
    #[serde(default)]
    pub face_size: f64,
    /// The joint's contact work over the run [J], its re-entries and their positive work [J]
    /// (`contact::state::JointRecord::work`, `reentries`, `reentry_work`).
    #[serde(default)]
    pub contact_work: f64,
    #[serde(default)]
    pub reentries: u64,
    #[serde(default)]
    pub reentry_work: f64,
}

/// Header of `histories/joint_<joint>.csv`: maxima over the slave nodes [m], the pairs per
/// state (`open` counts the lost ones too), the step's Gauss–Seidel sweeps, the summed normal
/// (compressive) and |tangential| force [N], the lost pairs and their largest `lost_travel` [m];
/// then, cumulative since the clock's start, the joint's contact work [J], its re-entries and
/// their positive work [J] (`JointRecord::work`, `reentries`, `reentry_work`).
pub const JOINT_HEADER: &str = "t [s],max_opening [m],max_slip [m],max_tangential_displacement [m],max_penetration [m],open,stick,slip,bonded,sweeps,normal_force [N],shear_force [N],lost,max_lost_travel [m],contact_work [J],reentries,reentry_work [J]";

/// The codes of the joint series' `state` array and their names (its FieldData labels).
pub const STATE_LABELS: [(&str, i32); 4] = [("state_label_open", 0), ("state_label_stick", 1), ("state_label_slip", 2), ("state_label_bonded", 3)];

pub struct JointWriter {
    dir: PathBuf,
    series: Vec<PvdSeries>,
    csv: Vec<CsvLines>,
    pub peaks: Vec<JointPeaks>,
    frames: bool,
    /// The opt-in force diagnostic (`output.joint_forces`): per joint its CSV and, per pair,
    /// whether it was closed at the last row (for the open/close transitions).
    forces: Vec<(CsvLines, Vec<bool>)>,
    /// Per joint and slave node: the node's displacement relative to its candidate centre at
    /// the last output where it was in contact (the origin of `lost_travel`).
    anchor: Vec<Vec<[f64; 3]>>,
    /// Set while the contact has not been searched yet (t = 0 of a run without gravity
    /// equilibrium): a pair's gap is then the tagger's distance to the master surface at rest,
    /// and no node counts as lost.
    pub unsearched: bool,
    /// Per slave node: the largest opening and net slip over the history rows
    /// (`joint_envelope.json`, [`super::joint_envelope`]).
    pub envelope: JointEnvelopeWriter,
}

/// `r` as the outputs show it: before the first search, the gaps at rest from the tagger.
fn searched_view<'a>(unsearched: bool, j: &ContactJoint, r: &'a JointRecord) -> std::borrow::Cow<'a, JointRecord> {
    if !unsearched {
        return std::borrow::Cow::Borrowed(r);
    }
    let mut r = r.clone();
    for (p, d) in r.pairs.iter_mut().zip(&j.tag.surface_distance) {
        if !p.gap.is_finite() {
            p.gap = *d;
        }
    }
    std::borrow::Cow::Owned(r)
}

/// Slave node `i`'s displacement relative to its candidate centre on the master.
fn relative_to_centre(j: &ContactJoint, r: &JointRecord, i: usize, u: &[f64]) -> [f64; 3] {
    let s = j.tag.slave.nodes[i];
    let m = j.tag.master.nodes.get(r.pairs[i].center as usize).copied().unwrap_or(s);
    [u[3 * s] - u[3 * m], u[3 * s + 1] - u[3 * m + 1], u[3 * s + 2] - u[3 * m + 2]]
}

/// Whether pair `p` is lost (found no master face).
fn is_lost(p: &crate::contact::state::PairRecord) -> bool {
    !p.gap.is_finite()
}

/// Header of `histories/joint_<joint>_forces.csv` (the opt-in force diagnostic, see
/// [`JointWriter::create`]): per row (the joint's history rows), the pairs in contact
/// (`closed`: state stick, slip or bonded), those that found no master face (`lost`), those
/// at the Mohr-Coulomb limit (`slipping`), the pairs that opened or closed since the last row
/// (`transitions`), the tributary area in contact and lost [m²], the cohesion c A of the lost
/// pairs [N], the sum of the compressive normal forces [N], the resultant normal and tangential
/// forces on the slave side [N, x y z], the sum of |r_t| [N], the sum over the closed pairs of
/// their Mohr-Coulomb limit μ r_n + c A (`capacity`) and of their cohesive part c A
/// (`cohesion`) [N], the step's Gauss–Seidel sweeps and last-sweep residual [m], and the open
/// pairs (not lost) with a gap below 1 nm, 1 µm and 1 mm.
pub const JOINT_FORCES_HEADER: &str = "t,closed,lost,slipping,transitions,area_closed,area_lost,cohesion_lost,normal_sum,nx,ny,nz,tx,ty,tz,shear_sum,capacity,cohesion,sweeps,gs_residual,open_1nm,open_1um,open_1mm";

fn state_counts(r: &JointRecord) -> [usize; 4] {
    let mut c = [0; 4];
    for p in &r.pairs {
        c[p.state.code() as usize] += 1;
    }
    c
}

impl JointWriter {
    /// `forces`: also write the force diagnostic `histories/joint_<joint>_forces.csv`
    /// ([`JOINT_FORCES_HEADER`]; scene `output.joint_forces`, default off: about 200 B per
    /// joint and history row, for studies of what a joint carries).
    pub fn create(out_dir: &Path, joints: &[ContactJoint], frames: bool, forces: bool) -> Result<JointWriter, OutputError> {
        let dir = out_dir.join("joints");
        let hdir = out_dir.join("histories");
        for d in [&dir, &hdir] {
            std::fs::create_dir_all(d).map_err(|e| OutputError::write(d, e))?;
        }
        let mut series = Vec::new();
        let mut csv = Vec::new();
        let mut peaks = Vec::new();
        for j in joints {
            let stem = crate::files::file_stem(&j.tag.name);
            series.push(PvdSeries::new(dir.join(format!("{stem}.pvd"))));
            csv.push(CsvLines::create(hdir.join(format!("joint_{stem}.csv")), JOINT_HEADER)?);
            peaks.push(JointPeaks {
                name: j.tag.name.clone(),
                method: format!("{:?}", j.method),
                slave_group: j.tag.slave.group.clone(),
                master_group: j.tag.master.group.clone(),
                slave_nodes: j.tag.n_slave(),
                ntn_max_distance: j.tag.ntn_max_distance,
                face_size: (j.tag.slave.area / j.tag.slave.faces.len().max(1) as f64).sqrt(),
                ..Default::default()
            });
        }
        let mut fcsv = Vec::new();
        if forces {
            for j in joints {
                fcsv.push((CsvLines::create(hdir.join(format!("joint_{}_forces.csv", crate::files::file_stem(&j.tag.name))), JOINT_FORCES_HEADER)?, vec![false; j.tag.n_slave()]));
            }
        }
        let anchor = joints.iter().map(|j| vec![[f64::NAN; 3]; j.tag.n_slave()]).collect();
        Ok(JointWriter { dir, series, csv, peaks, frames, forces: fcsv, anchor, unsearched: false, envelope: JointEnvelopeWriter::create(joints) })
    }

    /// Per slave node of joint `k`: its `lost_travel` [m] (0 when in contact) at displacement
    /// `u`, and its penetration estimated against the master surface it left: the travel since
    /// it was last in contact along its slave normal n (into the master), max(0, n · Δ) [m],
    /// the gap then taken as closed (0 for a node lost beyond the master's free edge). A lost node has no projection, so its penetration was not
    /// measured at all: a block sank 3.73 m with a summary "max penetration 6.6e-24 m" (issue
    /// 34). Moves the anchors of the nodes in contact.
    fn lost_travel(&mut self, k: usize, j: &ContactJoint, r: &JointRecord, u: &[f64]) -> Vec<(f64, f64)> {
        let anchor = &mut self.anchor[k];
        (0..r.pairs.len())
            .map(|i| {
                let rel = relative_to_centre(j, r, i, u);
                if !is_lost(&r.pairs[i]) || anchor[i][0].is_nan() {
                    // in contact, or lost since before the first output: travel counts from here
                    anchor[i] = rel;
                }
                if is_lost(&r.pairs[i]) {
                    let a = anchor[i];
                    let d = [rel[0] - a[0], rel[1] - a[1], rel[2] - a[2]];
                    let n = j.frames[i][0];
                    // beyond the free edge it slid off the surface: nothing there to penetrate
                    let pen = if r.pairs[i].beyond_edge { 0.0 } else { (n[0] * d[0] + n[1] * d[1] + n[2] * d[2]).max(0.0) };
                    ((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt(), pen)
                } else {
                    (0.0, 0.0)
                }
            })
            .collect()
    }

    /// Update maxima and append a history row per joint at time `t` (the contact `state` and
    /// the displacement `u` of that time).
    pub fn record(&mut self, t: f64, joints: &[ContactJoint], state: &ContactState, u: &[f64]) -> Result<(), OutputError> {
        for (k, (j, r)) in joints.iter().zip(&state.joints).enumerate() {
            let r = &*searched_view(self.unsearched, j, r);
            self.envelope.sample(k, r, t);
            let travel = self.lost_travel(k, j, r, u);
            let lost = r.pairs.iter().filter(|p| is_lost(p)).count();
            let ml = travel.iter().map(|t| t.0).fold(0.0f64, f64::max);
            let mut mo = 0.0f64;
            let mut ms = 0.0f64;
            let mut md = 0.0f64;
            // lost nodes: penetration against the master surface they left (see `lost_travel`)
            let mut mp = travel.iter().map(|t| t.1).fold(0.0f64, f64::max);
            let mut fn_ = 0.0;
            let mut ft = 0.0;
            for p in &r.pairs {
                if p.gap.is_finite() {
                    mo = mo.max(p.gap);
                    // a held re-entry penetration is penetration too
                    mp = mp.max(-p.gap).max(-p.entry_offset);
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
            pk.max_gs_residual = pk.max_gs_residual.max(r.max_gs_residual);
            pk.worst_cap.clone_from(&r.worst_cap);
            pk.events = r.events.clone();
            pk.max_lost_travel = pk.max_lost_travel.max(ml);
            (pk.contact_work, pk.reentries, pk.reentry_work) = (r.work, r.reentries, r.reentry_work);
            let c = state_counts(r);
            let _ = writeln!(self.csv[k].buf(), "{t:.9e},{mo:.9e},{ms:.9e},{md:.9e},{mp:.9e},{},{},{},{},{},{fn_:.9e},{ft:.9e},{lost},{ml:.9e},{:.9e},{},{:.9e}", c[0], c[1], c[2], c[3], r.sweeps, r.work, r.reentries, r.reentry_work);
            if let Some((w, was_closed)) = self.forces.get_mut(k) {
                let row = force_row(j, r, was_closed);
                let _ = writeln!(w.buf(), "{t:.9e},{row}");
            }
        }
        Ok(())
    }

    /// Write the pending history rows (whole lines).
    pub fn flush(&mut self) -> Result<(), OutputError> {
        for w in &mut self.csv {
            w.flush()?;
        }
        for (w, _) in &mut self.forces {
            w.flush()?;
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
            let r = &*searched_view(self.unsearched, j, r);
            let travel: Vec<f64> = self.lost_travel(k, j, r, u).into_iter().map(|t| t.0).collect();
            let surf = &j.tag.slave;
            let np = surf.nodes.len();
            let mut disp = Vec::with_capacity(3 * np);
            let mut normal = Vec::with_capacity(3 * np);
            let (mut gap, mut opening, mut slip, mut dtan, mut sn, mut st, mut area) =
                (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
            let mut code = Vec::with_capacity(np);
            let mut lost = Vec::with_capacity(np);
            for (i, &n) in surf.nodes.iter().enumerate() {
                disp.extend_from_slice(&u[3 * n..3 * n + 3]);
                normal.extend_from_slice(&j.tag.normals[i]);
                let p = &r.pairs[i];
                let a = j.tag.areas[i];
                gap.push(p.gap);
                opening.push(if p.gap.is_finite() { p.gap.max(0.0) } else { 0.0 });
                slip.push(p.slip + travel[i]);
                dtan.push((p.d_t[0] * p.d_t[0] + p.d_t[1] * p.d_t[1]).sqrt() + travel[i]);
                lost.push(is_lost(p) as i32);
                sn.push(p.r_n / a);
                st.push((p.r_t[0] * p.r_t[0] + p.r_t[1] * p.r_t[1]).sqrt() / a);
                area.push(a);
                code.push(if p.face < 0 && p.state == PairState::Open { 0 } else { p.state.code() as i32 });
            }
            let cells: Vec<(CellKind, &[u32])> = surf.faces.iter().map(|f| (f.kind, f.local_nodes())).collect();
            let grid = Grid { points: &surf.points, cells };
            let idx = self.series[k].len();
            let path = self.dir.join(format!("{}_{idx:05}.vtu", crate::files::file_stem(&j.tag.name)));
            write_vtu_labelled(
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
                    Field::i32("lost", 1, &lost),
                    Field::f64("lost_travel", 1, &travel),
                    Field::f64("tributary_area", 1, &area),
                ],
                &[],
                &STATE_LABELS,
            )?;
            self.series[k].push(t, &path)?;
        }
        Ok(())
    }

    pub fn pvd_paths(&self) -> Vec<PathBuf> {
        self.series.iter().map(|s| s.path().to_path_buf()).collect()
    }

    pub fn csv_paths(&self) -> Vec<PathBuf> {
        self.csv.iter().map(|w| w.path().to_path_buf()).chain(self.forces.iter().map(|(w, _)| w.path().to_path_buf())).collect()
    }
}

/// One row of the force diagnostic after `t` (see [`JOINT_FORCES_HEADER`]); `was_closed` is
/// updated to the pairs' current contact.
fn force_row(j: &ContactJoint, r: &JointRecord, was_closed: &mut [bool]) -> String {
    let (mut closed, mut lost, mut slipping, mut transitions) = (0usize, 0usize, 0usize, 0usize);
    let (mut area_closed, mut area_lost, mut coh_lost, mut nsum, mut tabs, mut cap, mut coh) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let (mut fnv, mut ftv) = ([0.0f64; 3], [0.0f64; 3]);
    let mut bins = [0usize; 3];
    for (i, p) in r.pairs.iter().enumerate() {
        let a = j.tag.areas[i];
        let is_closed = p.state != PairState::Open;
        if is_closed != was_closed[i] {
            transitions += 1;
        }
        was_closed[i] = is_closed;
        if !is_closed && p.gap.is_finite() {
            for (b, lim) in [1e-9, 1e-6, 1e-3].iter().enumerate() {
                if p.gap < *lim {
                    bins[b] += 1;
                }
            }
        }
        if !p.gap.is_finite() {
            lost += 1;
            area_lost += a;
            coh_lost += j.law.cohesion_force(&p.hist, a);
        }
        if !is_closed {
            continue;
        }
        closed += 1;
        area_closed += a;
        if p.state == PairState::Slip {
            slipping += 1;
        }
        let [n, t1, t2] = j.frames[i];
        for c in 0..3 {
            fnv[c] -= n[c] * p.r_n;
            ftv[c] += t1[c] * p.r_t[0] + t2[c] * p.r_t[1];
        }
        nsum += p.r_n;
        tabs += (p.r_t[0] * p.r_t[0] + p.r_t[1] * p.r_t[1]).sqrt();
        cap += j.law.shear_limit(p.r_n, &p.hist, a);
        coh += j.law.cohesion_force(&p.hist, a);
    }
    format!(
        "{closed},{lost},{slipping},{transitions},{area_closed:.6e},{area_lost:.6e},{coh_lost:.6e},{nsum:.9e},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e},{tabs:.9e},{cap:.9e},{coh:.9e},{},{:.3e},{},{},{}",
        fnv[0], fnv[1], fnv[2], ftv[0], ftv[1], ftv[2], r.sweeps, r.gs_residual, bins[0], bins[1], bins[2]
    )
}

/// One row of `histories/joint_<joint>_forces.csv` (see [`JOINT_FORCES_HEADER`] for the
/// meaning and units of each column).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct JointForcesRow {
    pub t: f64,
    pub closed: usize,
    pub lost: usize,
    pub slipping: usize,
    pub transitions: usize,
    pub area_closed: f64,
    pub area_lost: f64,
    pub cohesion_lost: f64,
    pub normal_sum: f64,
    pub normal: [f64; 3],
    pub tangential: [f64; 3],
    pub shear_sum: f64,
    pub capacity: f64,
    pub cohesion: f64,
    pub sweeps: usize,
    pub gs_residual: f64,
    /// Open pairs (not lost) with a gap below 1 nm, 1 µm and 1 mm.
    pub open_below: [usize; 3],
}

/// Read a force diagnostic written by [`JointWriter`] with `forces` on. The error names the
/// file and the line.
pub fn read_joint_forces(path: &Path) -> Result<Vec<JointForcesRow>, OutputError> {
    let text = std::fs::read_to_string(path).map_err(|e| OutputError::read(path, e))?;
    // a last line without its line end was cut by a kill or a full disk: not a row
    let whole = text.rfind('\n').map_or("", |i| &text[..=i]);
    let mut lines = whole.lines();
    if lines.next() != Some(JOINT_FORCES_HEADER) {
        return Err(OutputError::read(path, format!("the first line is not the force diagnostic's header `{JOINT_FORCES_HEADER}`")));
    }
    let mut rows = Vec::new();
    for (k, line) in lines.enumerate() {
        let bad = |what: &str| OutputError::read(path, format!("line {}: {what}", k + 2));
        let v: Vec<f64> = line.split(',').map(|s| s.trim().parse::<f64>()).collect::<Result<_, _>>().map_err(|e| bad(&e.to_string()))?;
        if v.len() != 23 {
            return Err(bad(&format!("{} columns, expected 23", v.len())));
        }
        let n = |i: usize| v[i] as usize;
        rows.push(JointForcesRow {
            t: v[0],
            closed: n(1),
            lost: n(2),
            slipping: n(3),
            transitions: n(4),
            area_closed: v[5],
            area_lost: v[6],
            cohesion_lost: v[7],
            normal_sum: v[8],
            normal: [v[9], v[10], v[11]],
            tangential: [v[12], v[13], v[14]],
            shear_sum: v[15],
            capacity: v[16],
            cohesion: v[17],
            sweeps: n(18),
            gs_residual: v[19],
            open_below: [n(20), n(21), n(22)],
        });
    }
    Ok(rows)
}
