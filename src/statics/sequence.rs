//! The static state of a jointed structure as it is built (scene `equilibrium.sequence`).
//!
//! - `"simultaneous"` (default): gravity and the static forces (the reservoir) brought to
//!   equilibrium together with every joint in contact, gaps as meshed
//!   (`simulation::Simulation::equilibrate`).
//! - `"grouted"`: the same, after the joints are grouted on the initial configuration.
//! - `"construction"`, as concrete dams are built (design.md §7):
//!   (a) **self-weight with the joints ungrouted**: the joints that are not `tied` carry
//!   nothing (open, no shear: each monolith is an independent cantilever), the `tied` ones (the
//!   dam–rock base) are bonded. This stage is linear, so it is solved directly: K̂ û = Tᵀ F_g
//!   with the tied joints eliminated (`bonded`: u_s = Σ N_I u_I), the massless foundation
//!   in K (so condensed exactly), one sparse Cholesky. Residual ‖Tᵀ (F − K u)‖ / ‖Tᵀ F‖.
//!   (b) **grouting**: every joint that is not tied closes at the deformed state, with the gap
//!   measured there (`PairRecord::gap_offset` = the gap along the slave normal to the deformed
//!   master surface), so it starts closed with no force and keeps its own law (Mohr–Coulomb).
//!   (c) **the static forces** (the reservoir's hydrostatic pressure) with the joints active
//!   (their Mohr–Coulomb law: pairs may open or slip), gravity kept: an active-set direct
//!   solve from the grouted state (`static_contact`).
//!
//! Grouting: a joint is grouted pair by pair, with the gap its method measures: along the slave
//! normal to the master face for node-to-segment (a slave node that finds no master face, even
//! within half a face, keeps offset 0 and is counted), the weighted gap n_j · (Σ_k c_k x_k − x_j)
//! of the mortar integrals at the grouting state for dual mortar (a node below the mortar
//! cover keeps offset 0 and is counted), to the master node O for node-to-node
//! (regression `dam_ntn_static_state_stays_at_rest`: grouted on the faces, the node-to-node
//! joints started with the chords' gaps to O and the run stopped on its energy check at step
//! 10).
//!
//! Each stage's residual and method are in the returned [`SequenceReport`] and the run's notes.
//!
//! The door: this module has no entry of its own. `simulation::Simulation::equilibrate` (the one
//! door to the static state, written there as plain text because simulation sits above statics)
//! calls [`construction_into`] or [`grout_before_relaxation`] and the relaxation, sets its state
//! and resets the clock and the slip counters once.

use crate::statics::bonding::Bonding;
use crate::contact::joint::ContactJoint;
use crate::contact::query::select_projection;
use crate::contact::ContactState;
use crate::error::{Error, ModelError};
use crate::linalg::{cpu_seconds, run_par, stiffness, FillOrdering, SparseCholesky};
use crate::problem::Problem;
use crate::statics::contact::{solve_static_increment, STATIC_ORDERING};
use nalgebra::Vector3;

/// One stage of the sequence.
#[derive(Clone, Debug, serde::Serialize)]
pub struct StageReport {
    pub name: String,
    /// "direct solve", "relaxation", "grouting".
    pub method: String,
    /// Relative residual at the end of the stage (0 for grouting).
    pub residual: f64,
    /// Relaxation steps (0 for a direct solve).
    pub steps: usize,
    pub note: String,
}

/// The stages of a static sequence, in order.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SequenceReport {
    pub sequence: String,
    pub stages: Vec<StageReport>,
}

impl SequenceReport {
    /// One line per stage.
    pub fn lines(&self) -> Vec<String> {
        self.stages.iter().map(|s| format!("static sequence \"{}\", stage {}: {}, residual {:.2e}{}{}", self.sequence, s.name, s.method, s.residual, if s.steps > 0 { format!(", {} steps", s.steps) } else { String::new() }, if s.note.is_empty() { String::new() } else { format!("; {}", s.note) })).collect()
    }
}

/// The linear static solution u of K u = F with the joints `bonded` tied (the others carry
/// nothing), and its residual ‖Tᵀ (F − K u)‖ / ‖Tᵀ F‖.
pub fn linear_static(problem: &Problem, bonded: &[&ContactJoint], f: &[f64]) -> Result<(Vec<f64>, f64, Bonding), Error> {
    linear_static_ordered(problem, bonded, f, STATIC_ORDERING).map(|(u, r, t, _)| (u, r, t))
}

/// The cost of a linear static solve's factorisation.
#[derive(Clone, Copy, Debug)]
pub struct FactorCost {
    /// Wall seconds of the assembly and ties, of the factorisation (analysis and numeric), of
    /// the analysis alone (the ordering included), and the factorisation's CPU seconds (all
    /// threads).
    pub assembly_s: f64,
    pub factor_s: f64,
    pub analysis_s: f64,
    pub factor_cpu_s: f64,
    /// Entries of the factor (8 B each).
    pub entries: usize,
}

/// [`linear_static`] with the fill-reducing ordering `ordering`, and its cost.
pub fn linear_static_ordered(problem: &Problem, bonded: &[&ContactJoint], f: &[f64], ordering: FillOrdering) -> Result<(Vec<f64>, f64, Bonding, FactorCost), Error> {
    let start = std::time::Instant::now();
    let model = &problem.model;
    let k = stiffness(model, &vec![true; model.materials.len()]);
    let t = Bonding::build(model, bonded, |d| model.is_free(d / 3, d % 3) && k.col_ptr[d + 1] > k.col_ptr[d])?;
    let kh = t.reduce(&k);
    let fh = t.reduce_vector(f);
    let assembled = start.elapsed().as_secs_f64();
    let cpu0 = cpu_seconds();
    let mut chol = SparseCholesky::factor_ordered(&kh, "static stage", run_par(), ordering).map_err(|e| ModelError::Invalid(e.to_string()))?;
    let cost = FactorCost { assembly_s: assembled, factor_s: start.elapsed().as_secs_f64() - assembled, factor_cpu_s: cpu_seconds() - cpu0, analysis_s: chol.analysis_seconds(), entries: chol.factor_entries() };
    let mut uh = fh.clone();
    chol.solve_in_place(&mut uh);
    let mut u = vec![0.0; t.n_dofs];
    t.expand_into(&uh, &mut u);
    let mut ku = vec![0.0; t.n_dofs];
    k.mul_into(&u, &mut ku);
    let r: Vec<f64> = f.iter().zip(&ku).map(|(a, b)| a - b).collect();
    let rh = t.reduce_vector(&r);
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let nf = norm(&fh);
    let residual = if nf > 0.0 { norm(&rh) / nf } else { 0.0 };
    Ok((u, residual, t, cost))
}

/// Stage (a): self-weight with the joints that are not tied open, the tied ones bonded.
/// Returns u and the stage's report.
pub fn self_weight_open_joints(problem: &Problem) -> Result<(Vec<f64>, StageReport), Error> {
    self_weight_open_joints_ordered(problem, STATIC_ORDERING)
}

/// [`self_weight_open_joints`] with the fill-reducing ordering `ordering`.
pub fn self_weight_open_joints_ordered(problem: &Problem, ordering: FillOrdering) -> Result<(Vec<f64>, StageReport), Error> {
    let model = &problem.model;
    let mut gravity_only = problem.loads.clone();
    gravity_only.static_forces.clear();
    let mut f = vec![0.0; 3 * model.n_nodes()];
    gravity_only.external_force_into(model, 0.0, true, false, &mut f);
    let tied: Vec<&ContactJoint> = problem.joints.iter().filter(|j| j.law.tied).collect();
    let (u, residual, t, c) = linear_static_ordered(problem, &tied, &f, ordering)?;
    let note = format!(
        "{} tied joint(s) bonded ({} slave nodes), {} joint(s) open; {} unknowns, assembly {:.1} s, Cholesky {:.1} s ({} {:.1} s; {:.1} s CPU on {} thread(s); factor {:.0} MB)",
        tied.len(),
        t.info.tied,
        problem.joints.len() - tied.len(),
        t.n,
        c.assembly_s,
        c.factor_s,
        if ordering.resolve(t.n) == FillOrdering::NestedDissection { "nested dissection" } else { "AMD" },
        c.analysis_s,
        c.factor_cpu_s,
        run_par().degree(),
        c.entries as f64 * 8e-6
    );
    Ok((u, StageReport { name: "a: self-weight, joints ungrouted".into(), method: "direct solve".into(), residual, steps: 0, note }))
}

/// Stage (b): grout every joint that is not tied at the displacements `u`: each pair's gap
/// offset becomes its gap there. Returns the stage's report (largest |offset|, pairs without
/// a master face).
pub fn grout(problem: &Problem, contact: &mut ContactState, u: &[f64]) -> Result<StageReport, Error> {
    grout_pairs(problem, contact, u, |ji, _| !problem.joints[ji].law.tied)
}

/// Grout the pairs (joint, slave index) for which `which` holds at the displacements `u` (as
/// [`grout`]; a tied joint's pair too when `which` takes it: its tie then holds that gap).
pub fn grout_pairs(problem: &Problem, contact: &mut ContactState, u: &[f64], which: impl Fn(usize, usize) -> bool) -> Result<StageReport, Error> {
    let model = &problem.model;
    let (mut pairs, mut missed, mut largest) = (0usize, 0usize, 0.0f64);
    for (ji, j) in problem.joints.iter().enumerate() {
        if j.method == crate::contact::joint::Method::Mortar {
            // dual mortar: the weighted gap of each slave node (`ContactSolver::mortar_gaps`)
            let gaps = crate::contact::force::ContactSolver::new(model, &problem.joints).mortar_gaps(model, ji, &contact.joints[ji], u).map_err(|e| ModelError::Invalid(format!("grouting joint \"{}\": {e}", j.tag.name)))?;
            for (i, g) in gaps.into_iter().enumerate() {
                if !which(ji, i) {
                    continue;
                }
                match g {
                    Some(g) => {
                        contact.joints[ji].pairs[i].gap_offset = g;
                        largest = largest.max(g.abs());
                        pairs += 1;
                    }
                    None => missed += 1,
                }
            }
            continue;
        }
        let m = &j.tag.master;
        let pos = |node: usize| Vector3::new(model.mesh.nodes[node][0] + u[3 * node], model.mesh.nodes[node][1] + u[3 * node + 1], model.mesh.nodes[node][2] + u[3 * node + 2]);
        for (i, &s) in j.tag.slave_nodes().iter().enumerate() {
            if !which(ji, i) {
                continue;
            }
            let xs = pos(s);
            let n = j.frames[i][0];
            if j.method == crate::contact::joint::Method::Ntn {
                // node-to-node: the gap is measured to the slave's master node O
                let gap = n.dot(&(pos(j.tag.nearest_master_node(i)) - xs));
                contact.joints[ji].pairs[i].gap_offset = gap;
                largest = largest.max(gap.abs());
                pairs += 1;
                continue;
            }
            let faces: Vec<(usize, Vec<Vector3<f64>>)> = j.tag.layer2.row(i).iter().map(|&f| (f as usize, m.faces[f as usize].nodes().iter().map(|&nd| pos(nd as usize)).collect())).collect();
            let project = |tol: f64| select_projection(&xs, &n, faces.iter().map(|(f, x)| (*f, x.as_slice())), tol).map_err(|e| ModelError::Invalid(format!("grouting joint \"{}\": {e}", j.tag.name)));
            let hit = match project(j.edge_tolerance)? {
                Some(h) => Some(h),
                None => project(0.5)?,
            };
            let rec = &mut contact.joints[ji].pairs[i];
            match hit {
                Some((_, p)) => {
                    rec.gap_offset = p.gap;
                    largest = largest.max(p.gap.abs());
                    pairs += 1;
                }
                None => missed += 1,
            }
        }
    }
    let note = format!("{pairs} pairs grouted (largest |gap| closed {largest:.3e} m){}", if missed > 0 { format!(", {missed} slave nodes without a master face left as meshed") } else { String::new() });
    Ok(StageReport { name: "b: grouting".into(), method: "grouting".into(), residual: 0.0, steps: 0, note })
}

/// The construction sequence's stages (a) self-weight with the joints ungrouted, (b) grouting,
/// (c) the static forces with the joints active, from rest: the static displacement is written
/// into `u` and the contact history (gap offsets, pair states and forces) into `contact`.
/// Returns the stages' reports and stage (c)'s relative residual. Called only by the one door,
/// `simulation::Simulation::equilibrate`, which sets its state from `u` and resets the clock.
pub fn construction_into(p: &Problem, contact: &mut ContactState, u: &mut [f64]) -> Result<(Vec<StageReport>, f64), Error> {
    let mut stages = Vec::new();
    let (u_a, a) = self_weight_open_joints(p)?;
    u.copy_from_slice(&u_a);
    stages.push(a);
    stages.push(grout(p, contact, u)?);
    // (c) the static forces with the joints active: an active-set direct solve
    // (`static_contact`). Dynamic relaxation, started from the linear response with
    // every joint bonded, had not converged on the arch dam (residual 2.2e-2 after
    // 40 000 steps; 5.4e-2 ramped in from rest).
    let f_static = p.loads.static_force_vector(u.len());
    let (du, info) = solve_static_increment(p, &f_static, contact, crate::statics::contact::PENALTY_FACTOR)?;
    if !info.converged {
        return Err(ModelError::Invalid(format!(
            "static sequence, stage c (static forces with the joints active): not converged ({}). The joints' contact states cycle: check the joints' friction and the load",
            info.line()
        ))
        .into());
    }
    for (x, d) in u.iter_mut().zip(&du) {
        *x += d;
    }
    // the closed pairs carry the penalty's small penetration (info.max_penetration);
    // the explicit run's contact is exact and would push it out in one step, so they
    // are re-grouted where they are: the dynamic stage starts with them touching.
    // The tied joints too: the static solves tie each slave to its master point with
    // the gap it was meshed with (`bonded`: u_s = Σ N_I u_I), while an explicit tie
    // holds the gap offset, 0 until grouted, and would close the meshed gap (the
    // chords of non-conforming tied joints) in the first step (regression
    // `dam_ties_keep_their_meshed_gap_when_released`).
    let closed: Vec<Vec<bool>> = contact.joints.iter().enumerate().map(|(ji, j)| j.pairs.iter().map(|r| p.joints[ji].law.tied || r.state != crate::contact::law::PairState::Open).collect()).collect();
    grout_pairs(p, contact, u, |ji, i| closed[ji][i])?;
    // (grouting sets only the offsets: the pairs keep their forces and states; a
    // closed pair's gap is 0 from here)
    for (ji, j) in contact.joints.iter_mut().enumerate() {
        for (i, r) in j.pairs.iter_mut().enumerate() {
            if closed[ji][i] {
                r.gap = 0.0;
            }
        }
    }
    stages.push(StageReport {
        name: "c: static forces (reservoir), joints active".into(),
        method: "Newton, direct solves (penalty contact)".into(),
        residual: info.residual,
        steps: 0,
        note: info.line(),
    });
    Ok((stages, info.residual))
}

/// Before the relaxation of a `"simultaneous"` or `"grouted"` sequence (from rest): every joint
/// that is not tied grouted on the initial configuration when `grouted`, and the tied joints
/// grouted there always (a tie holds the gap it was meshed with, as in the static solves,
/// `bonding`, and in the construction sequence). Returns the grouting stage's report when
/// `grouted`.
pub fn grout_before_relaxation(p: &Problem, contact: &mut ContactState, grouted: bool) -> Result<Option<StageReport>, Error> {
    let zero = vec![0.0; 3 * p.model.n_nodes()];
    let stage = if grouted { Some(grout(p, contact, &zero)?) } else { None };
    if p.joints.iter().any(|j| j.law.tied) {
        grout_pairs(p, contact, &zero, |ji, _| p.joints[ji].law.tied)?;
    }
    Ok(stage)
}
