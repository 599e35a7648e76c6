//! Running a generated case in memory and measuring it against its exact reference.
//!
//! - `patch` is solved **statically** by dynamic relaxation with adaptive critical damping
//!   (Underwood 1983, `dynamics::relax_gravity`: C = αM with α = 2 ω_min, ω_min² the Rayleigh
//!   quotient uᵀKu / uᵀMu of the current displacement, re-estimated every step, so the lowest
//!   mode is critically damped without a damping chosen by hand). The patch tractions are
//!   handed to it as static forces (the loads relaxation applies with gravity), ramped in over
//!   `RELAXATION_RAMP_STEPS` steps; it stops when the out-of-balance force ‖M a‖ (elastic and
//!   contact forces together) is below `residual` × ‖F‖ (default 1e-10). With
//!   `pressure_first` the pressure's tractions are relaxed so first, then the shear's are ramped
//!   in over as many steps on top of them and relaxed again (`relax_shear_at_full_pressure`).
//! - `slide` runs the dynamic stage from rest with gravity for `duration`.
//! - `newmark` relaxes gravity (the scene's `equilibrium`), then runs the record; the slip is
//!   measured from the relaxed state.
//! - `impact` starts the lower bar at v0 (central differences carry v[n−½] = (u[n] − u[n−1])/dt,
//!   so u[−1] = −v0 dt on its nodes) and runs 3 L/c.
//!
//! Error measures (all relative; the module docs of [`super`] give the frame):
//! - patch: `stress_joint` = max over the elements whose centroid lies within one element layer
//!   of the joint (of the cylinder of a curved joint) of max_ij |σ_ij − σ_ij exact| / s with s = max(p, |τ|); `szz_joint` the same for
//!   σzz alone / p (the measure quoted for CalculiX; the headline of a flat pressure patch, of a
//!   curved one `stress_joint`, as its σxx = −p too); `stress_all` over every element;
//!   `pressure` = max over slave nodes of |r_n − r_n exact| / (s A_s), r_n exact = −n_s · σ V_s with
//!   V_s = Σ_f n_f ∫ N_s dA the node's area vector (p A_s on a flat joint) (`pressure_interior`: nodes
//!   off the joint's perimeter); `shear` = max |r_t − (σ V_s)_t| / (s A_s) (τ A_s e_x when flat);
//!   `total` = Σ r_n / Σ r_n exact − 1 (exact on the meshed joint), `normal_force` = Σ r_n / ∫ n · σ n dA − 1
//!   (over the exact joint: the cylinder of a curved one); `displacement` = max over the nodes of
//!   |u − u_exact| / max |u_exact| (u_exact linear, so exact on the meshed geometry too).
//! - slide: (s_FEM − s) / s with s_FEM the mean displacement of the slider's nodes down the
//!   slope at the end.
//! - impact: plateau mean, min and max of the contact force over 0.2–1.8 L/c / F − 1, and the
//!   contact duration / (2L/c) − 1.

use super::{Case, Kind, Reference, BAR_L, BAR_V0, PATCH_SIDE};
use crate::error::{CaseError, Error};
use crate::problem::Problem;
use crate::scene::Scene;
use crate::simulation::Simulation;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// What a case measured (written as `result.json` and as a study step's output).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CaseResult {
    pub label: String,
    pub spec: super::Resolved,
    /// h_slave / h_master (in-plane element sizes).
    pub mesh_ratio: f64,
    pub nodes: usize,
    pub elements: usize,
    /// Slave nodes (pairs) of the joint.
    pub pairs: usize,
    pub dt: f64,
    pub steps: usize,
    /// Wall time of the solve [s] (model build excluded).
    pub wall_time: f64,
    /// The headline error and what it measures.
    pub error: f64,
    pub error_of: String,
    pub errors: Errors,
    /// Node-steps without a master face (NTS search), summed over the run.
    pub lost: u64,
}

/// The measures of each kind (see the module docs).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Errors {
    Patch {
        stress_joint: f64,
        szz_joint: f64,
        stress_all: f64,
        pressure: f64,
        pressure_interior: f64,
        shear: f64,
        total: f64,
        /// max over the nodes of |u − u_exact| / max |u_exact| (the uniform state's linear
        /// displacement, exact on the meshed geometry too; [`super::Resolved::exact_patch_displacement`]).
        #[serde(default)]
        displacement: f64,
        /// The same in the L2 norm with lumped-mass weights: (Σ m_i |u_i − u_exact,i|² /
        /// Σ m_i |u_exact,i|²)^½ (ρ uniform, so the lumped L2 norm over the volume; a massless
        /// block's nodes weigh nothing).
        #[serde(default)]
        displacement_l2: f64,
        /// Σ r_n / ∫ n · σ n dA − 1, the integral over the exact joint surface (the cylinder of
        /// a curved joint; [`super::Resolved::exact_normal_force`]).
        #[serde(default)]
        normal_force: f64,
        /// Relaxation: converged, its residual ‖M a‖ / ‖F‖.
        converged: bool,
        residual: f64,
    },
    Slide {
        slip: f64,
        exact: f64,
        relative: f64,
    },
    Impact {
        force_mean: f64,
        force_min: f64,
        force_max: f64,
        duration: f64,
        /// Work of the contact forces over the run over the bar's initial kinetic energy (> 0:
        /// the contact created energy; exact closure does no work, 0 to round-off).
        contact_work: f64,
    },
}

fn failed(message: String) -> Error {
    CaseError::Invalid { option: "run".into(), message }.into()
}

/// Build the problem of `case`, run it and measure it.
pub fn run_case(case: &Case) -> Result<CaseResult, Error> {
    let scene: Scene = serde_json::from_value(case.scene.clone()).map_err(|e| failed(format!("generated scene does not parse: {e}")))?;
    let mut pb = Problem::build(scene, case.mesh.clone())?;
    // the pressure-first path's shear forces, ramped in after the pressure's equilibrium
    let mut shear_forces = Vec::new();
    if case.spec.kind == Kind::Patch {
        // the tractions act as static loads (what relaxation applies), not as dynamic patterns
        for p in std::mem::take(&mut pb.loads.patterns) {
            pb.loads.static_forces.extend(p.forces);
        }
        if case.spec.pressure_first {
            let (f_p, f_tau) = pressure_and_shear_forces(case, &pb)?;
            pb.loads.static_forces = f_p;
            shear_forces = f_tau;
        }
    }
    let mut sim = Simulation::new(&pb)?;
    let t0 = std::time::Instant::now();
    let (errors, steps) = match (&case.reference, case.spec.kind) {
        (Reference::Patch { .. }, Kind::Patch) => {
            if case.spec.curvature.is_some() && (case.spec.method == super::ContactMethod::Mortar || case.spec.slave_on_cylinder) {
                // The slave's joint nodes sit on the master's facets: the node-to-segment gap is
                // zero, but mortar's weighted gap sees the two faceted surfaces apart (of order
                // h²/R where a slave face spans a master kink). Grouted on the initial
                // configuration, the mortar joint starts closed, as the others (module doc).
                // With both sides' nodes on the cylinder every method sees the chords' sags
                // (up to h²/(8R)) as gaps, so every method is grouted.
                let zero = vec![0.0; sim.state.u.len()];
                crate::statics::sequence::grout_pairs(&pb, &mut sim.state.contact, &zero, |_, _| true)?;
            }
            let mut eq = sim.relax(case.spec.residual, 400_000)?;
            if case.spec.pressure_first {
                let shear = relax_shear_at_full_pressure(&mut sim, &shear_forces, case.spec.residual, 400_000)?;
                eq = crate::dynamics::EquilibriumInfo { steps: eq.steps + shear.steps, converged: eq.converged && shear.converged, residual: shear.residual };
            }
            (measure_patch(case, &sim, eq.converged, eq.residual), eq.steps)
        }
        (Reference::Slide { slip, .. }, Kind::Slide) => {
            let n = sim.n_steps();
            for _ in 0..n {
                sim.step()?;
            }
            let rot = case.spec.rotation();
            let nodes = pb.model.mesh.group_nodes("block:upper")?;
            let down = -(rot * Vector3::x());
            let s = nodes.iter().map(|&i| Vector3::new(sim.state.u[3 * i], sim.state.u[3 * i + 1], sim.state.u[3 * i + 2]).dot(&down)).sum::<f64>() / nodes.len() as f64;
            let relative = if *slip > 0.0 { s / slip - 1.0 } else { s };
            (Errors::Slide { slip: s, exact: *slip, relative }, n)
        }
        (Reference::Newmark { slip, .. }, Kind::Newmark) => {
            sim.equilibrate()?;
            let nodes = pb.model.mesh.group_nodes("block:upper")?;
            let down = -(case.spec.rotation() * Vector3::x());
            let along = |u: &[f64]| nodes.iter().map(|&i| Vector3::new(u[3 * i], u[3 * i + 1], u[3 * i + 2]).dot(&down)).sum::<f64>() / nodes.len() as f64;
            let s0 = along(&sim.state.u);
            let n = sim.n_steps();
            for _ in 0..n {
                sim.step()?;
            }
            let s = along(&sim.state.u) - s0;
            let relative = if *slip > 1e-6 { s / slip - 1.0 } else { s };
            (Errors::Slide { slip: s, exact: *slip, relative }, n)
        }
        (Reference::Impact { force, duration, .. }, Kind::Impact) => run_impact(case, &mut sim, *force, *duration)?,
        _ => return Err(failed("reference and kind disagree".into())),
    };
    let wall_time = t0.elapsed().as_secs_f64();
    let (error, error_of) = match &errors {
        Errors::Patch { szz_joint, stress_joint, .. } => {
            if case.spec.pressure > 0.0 && case.spec.shear == 0.0 && case.spec.curvature.is_none() {
                (*szz_joint, "σzz next to the joint".to_string())
            } else {
                (*stress_joint, "σ next to the joint".to_string())
            }
        }
        Errors::Slide { relative, .. } if case.spec.kind == Kind::Newmark => (relative.abs(), "residual slip vs rigid Newmark".to_string()),
        Errors::Slide { relative, .. } => (relative.abs(), "slip at the end".to_string()),
        Errors::Impact { force_mean, .. } => (force_mean.abs(), "plateau contact force".to_string()),
    };
    let joint = &pb.joints[0];
    Ok(CaseResult {
        label: case.spec.label(),
        spec: case.spec.clone(),
        mesh_ratio: case.spec.mesh_ratio(),
        nodes: pb.model.n_nodes(),
        elements: pb.model.n_elements(),
        pairs: joint.tag.slave_nodes().len(),
        dt: sim.dt(),
        steps,
        wall_time,
        error,
        error_of,
        errors,
        lost: sim.state.contact.joints[0].events.lost,
    })
}

/// The patch's nodal forces split for the pressure-first path: (F_p, F − F_p), F_p the
/// tractions of the pressure-only state (the case with τ = 0) on the same model, F the case's
/// (already in `pb.loads.static_forces`). Tractions are linear in (p, τ), so F − F_p is the
/// shear state's.
fn pressure_and_shear_forces(case: &Case, pb: &Problem) -> Result<(NodeForces, NodeForces), Error> {
    let mut r0 = case.spec.clone();
    r0.shear = 0.0;
    let mut scene = case.scene.clone();
    scene["loads"]["traction"] = serde_json::Value::Array(super::patch_tractions(&r0).into_iter().map(|(g, t)| serde_json::json!({"group": g, "traction": t})).collect());
    let scene: Scene = serde_json::from_value(scene).map_err(|e| failed(format!("pressure-only scene does not parse: {e}")))?;
    let (loads, _) = crate::dynamics::loads::Loads::build(&pb.model, &scene)?;
    let n = pb.model.n_nodes();
    let (mut full, mut fp) = (vec![[0.0; 3]; n], vec![[0.0; 3]; n]);
    for &(i, f) in &pb.loads.static_forces {
        (0..3).for_each(|c| full[i][c] += f[c]);
    }
    for &(i, f) in loads.patterns.iter().flat_map(|p| p.forces.iter()) {
        (0..3).for_each(|c| fp[i][c] += f[c]);
    }
    let sparse = |v: Vec<[f64; 3]>| v.into_iter().enumerate().filter(|(_, f)| f.iter().any(|&x| x != 0.0)).collect::<NodeForces>();
    let tau: Vec<[f64; 3]> = full.iter().zip(&fp).map(|(a, b)| [a[0] - b[0], a[1] - b[1], a[2] - b[2]]).collect();
    Ok((sparse(fp), sparse(tau)))
}

/// (node, force [N]) lists.
type NodeForces = Vec<(usize, [f64; 3])>;

/// The second stage of the pressure-first path: from the pressure's equilibrium, the shear
/// forces `f_tau` ramped in over `RELAXATION_RAMP_STEPS` steps on top of the full pressure
/// forces (`static_forces` of the problem), relaxed by the same adaptive dynamic relaxation as
/// `dynamics::relax_gravity` (its balance and damping rules, `relaxation_balance` and
/// `relaxation_damping`) until ‖M a‖ < `tol` ‖F‖, F the full load.
fn relax_shear_at_full_pressure(sim: &mut Simulation<'_>, f_tau: &[(usize, [f64; 3])], tol: f64, max_steps: usize) -> Result<crate::dynamics::EquilibriumInfo, Error> {
    use crate::constraint::Constraint;
    use crate::contact::ContactState;
    use crate::dynamics::{relaxation_balance, relaxation_damping, Stage, RELAXATION_RAMP_STEPS};
    let pb = sim.problem;
    let model = &pb.model;
    let mut loads = pb.loads.clone();
    let mut f = vec![0.0; 3 * model.n_nodes()];
    for &(i, v) in pb.loads.static_forces.iter().chain(f_tau) {
        (0..3).for_each(|c| f[3 * i + c] += v[c]);
    }
    let norm_f = f.iter().enumerate().filter(|(i, _)| model.is_free(i / 3, i % 3)).map(|(_, x)| x * x).sum::<f64>().sqrt();
    let (dt, mut alpha, mut residual) = (sim.solver.dt, 0.0, f64::INFINITY);
    for k in 0..max_steps {
        crate::interrupt::check_every(k, "the patch's shear stage (relaxation)")?;
        let s = ((k + 1) as f64 / RELAXATION_RAMP_STEPS as f64).min(1.0);
        loads.static_forces.clear();
        loads.static_forces.extend(pb.loads.static_forces.iter().copied().chain(f_tau.iter().map(|&(i, v)| (i, [s * v[0], s * v[1], s * v[2]]))));
        let mut cs: Vec<&mut dyn Constraint<ContactState>> = Vec::with_capacity(2);
        if let Some(c) = sim.contact.as_mut() {
            cs.push(c);
        }
        if let Some(fd) = sim.foundation.as_mut() {
            cs.push(fd);
        }
        sim.solver.step(model, &loads, &mut sim.state, Stage::Relaxation(alpha, 1.0), &mut cs)?;
        let (r2, ukb, umu) = relaxation_balance(model, &sim.solver, &sim.state, alpha, 1.0);
        residual = r2.max(0.0).sqrt() / norm_f;
        alpha = relaxation_damping(ukb, umu, dt, alpha);
        if residual < tol && k + 1 >= RELAXATION_RAMP_STEPS {
            sim.state.u_prev.copy_from_slice(&sim.state.u);
            sim.complete_state()?;
            return Ok(crate::dynamics::EquilibriumInfo { steps: k + 1, residual, converged: true });
        }
    }
    sim.state.u_prev.copy_from_slice(&sim.state.u);
    sim.complete_state()?;
    Ok(crate::dynamics::EquilibriumInfo { steps: max_steps, residual, converged: false })
}

fn measure_patch(case: &Case, sim: &Simulation<'_>, converged: bool, residual: f64) -> Errors {
    let r = &case.spec;
    let pb = sim.problem;
    let model = &pb.model;
    let rot = r.rotation();
    let exact = super::patch_stress(r);
    let s_ref = r.pressure.max(r.shear.abs());
    let mut stress = Vec::new();
    model.element_stress_into(&sim.state.u, &mut stress);
    let blocks = model.element_blocks();
    let layer = [super::PATCH_HEIGHT / r.lower.layers as f64, super::PATCH_HEIGHT / r.upper.layers as f64];
    let (mut stress_joint, mut szz_joint, mut stress_all) = (0.0f64, 0.0f64, 0.0f64);
    for (e, (_, nodes)) in model.element_cells().iter().enumerate() {
        let c = nodes.iter().map(|&n| model.mesh.x(n as usize)).sum::<Vector3<f64>>() / nodes.len() as f64;
        let cl = rot.transpose() * c;
        // height above the joint surface (the cylinder of a curved joint)
        let z = cl[2] - r.joint_height(cl[0]);
        let s = stress[e];
        let g = nalgebra::Matrix3::new(s[0], s[3], s[5], s[3], s[1], s[4], s[5], s[4], s[2]);
        let l = rot.transpose() * g * rot;
        let local = [l[(0, 0)], l[(1, 1)], l[(2, 2)], l[(0, 1)], l[(1, 2)], l[(0, 2)]];
        let dev = (0..6).map(|i| (local[i] - exact[i]).abs()).fold(0.0, f64::max) / s_ref;
        stress_all = stress_all.max(dev);
        let b = blocks[e] as usize;
        if z.abs() < layer[b.min(1)] {
            stress_joint = stress_joint.max(dev);
            if r.pressure > 0.0 {
                szz_joint = szz_joint.max((local[2] - exact[2]).abs() / r.pressure);
            }
        }
    }
    // contact forces on the slave nodes: exact σ · V_s, V_s = Σ_f n_f ∫ N_s dA the slave node's
    // area vector (n_f out of the slave; = n_s A_s on a flat joint), normal part along the slave
    // normal n_s (compression r_n = −n_s · σ V_s), tangential part the rest
    let joint = &pb.joints[0];
    let pairs = &sim.state.contact.joints[0].pairs;
    let sig_g = rot * super::sym(&exact) * rot.transpose();
    let mut vectors = vec![[0.0; 3]; joint.tag.slave.nodes.len()];
    crate::interface::tributary_vectors_into(&joint.tag.slave, &mut vectors);
    let (mut pressure, mut pressure_interior, mut shear, mut total, mut total_exact) = (0.0f64, 0.0f64, 0.0f64, 0.0, 0.0);
    for (i, p) in pairs.iter().enumerate() {
        let a = joint.tag.areas[i];
        let node = joint.tag.slave_nodes()[i];
        let n_s = Vector3::from(joint.tag.normals[i]);
        let f_exact = sig_g * Vector3::from(vectors[i]);
        let rn_exact = -n_s.dot(&f_exact);
        let t_exact = f_exact + n_s * rn_exact;
        let dp = (p.r_n - rn_exact).abs() / (s_ref * a);
        pressure = pressure.max(dp);
        let x = rot.transpose() * model.mesh.x(node);
        let tol = 1e-9 * PATCH_SIDE;
        if [x[0], x[1]].iter().all(|&c| c > tol && c < PATCH_SIDE - tol) {
            pressure_interior = pressure_interior.max(dp);
        }
        let f = &joint.frames[i];
        let ft = f[1] * p.r_t[0] + f[2] * p.r_t[1];
        shear = shear.max((ft - t_exact).norm() / (s_ref * a));
        total += p.r_n;
        total_exact += rn_exact;
    }
    let area: f64 = joint.tag.areas.iter().sum();
    let normal_force = if r.pressure > 0.0 { total / r.exact_normal_force() - 1.0 } else { total / (s_ref * area) };
    let total = if r.pressure > 0.0 { total / total_exact - 1.0 } else { total / (s_ref * area) };
    let (displacement, displacement_l2) = patch_displacement_errors(case, sim);
    Errors::Patch { stress_joint, szz_joint, stress_all, pressure, pressure_interior, shear, total, displacement, displacement_l2, normal_force, converged, residual }
}

/// The displacement errors (max, lumped L2) against u_exact, the uniform state's, exact on any
/// meshed geometry ([`super::Resolved::exact_patch_displacement`], in the local frame).
fn patch_displacement_errors(case: &Case, sim: &Simulation<'_>) -> (f64, f64) {
    let r = &case.spec;
    let model = &sim.problem.model;
    let rot = r.rotation();
    let (mut err, mut scale, mut err2, mut scale2) = (0.0f64, 0.0f64, 0.0, 0.0);
    for i in 0..model.n_nodes() {
        let exact = rot * r.exact_patch_displacement(&(rot.transpose() * model.mesh.x(i)));
        let u = Vector3::new(sim.state.u[3 * i], sim.state.u[3 * i + 1], sim.state.u[3 * i + 2]);
        let m = model.mass.inertial[i];
        err = err.max((u - exact).norm());
        scale = scale.max(exact.norm());
        err2 += m * (u - exact).norm_squared();
        scale2 += m * exact.norm_squared();
    }
    (err / scale, (err2 / scale2).sqrt())
}

fn run_impact(case: &Case, sim: &mut Simulation<'_>, force: f64, duration: f64) -> Result<(Errors, usize), Error> {
    let pb = sim.problem;
    let model = &pb.model;
    let dt = sim.dt();
    let dir = case.spec.rotation() * Vector3::z();
    let bar = model.mesh.group_nodes("block:lower")?;
    for &n in &bar {
        for c in 0..3 {
            sim.state.u_prev[3 * n + c] = -BAR_V0 * dt * dir[c];
        }
    }
    sim.solver.start_energy(model, &mut sim.state);
    let e0: f64 = bar.iter().map(|&n| 0.5 * model.mass.inertial[n] * BAR_V0 * BAR_V0).sum();
    sim.state.energy.initial = e0;
    sim.state.energy.scale = e0;
    let lc = duration / 2.0;
    let _ = BAR_L;
    let steps = (3.0 * lc / dt).round() as usize;
    let (mut first, mut last) = (f64::NAN, f64::NAN);
    let (mut sum, mut count, mut f_min, mut f_max) = (0.0, 0usize, f64::INFINITY, f64::NEG_INFINITY);
    for _ in 0..steps {
        let t = sim.state.t;
        sim.step()?;
        let f: f64 = sim.state.contact.joints[0].pairs.iter().map(|p| p.r_n).sum();
        if f > 1e-6 * force {
            if first.is_nan() {
                first = t;
            }
            last = t;
        }
        if t > 0.2 * lc && t < 1.8 * lc {
            sum += f;
            count += 1;
            f_min = f_min.min(f);
            f_max = f_max.max(f);
        }
    }
    if count == 0 || first.is_nan() {
        return Err(failed("impact: no contact force during the plateau (the bars never touched)".into()));
    }
    let contact_work = sim.state.energy.contact_work / e0;
    Ok((Errors::Impact { force_mean: sum / count as f64 / force - 1.0, force_min: f_min / force - 1.0, force_max: f_max / force - 1.0, duration: (last - first + dt) / duration - 1.0, contact_work }, steps))
}
