//! FEM strength reduction (SSR): the factor F by which c and tan φ of every joint can be
//! divided before the model fails under gravity.
//!
//! The problem (model, joints tagged once, loads) is built once; each trial F sets c/F and
//! tan φ/F on every joint's law (cohesion kept after slip or opening: perfectly plastic
//! Mohr-Coulomb, the assumption of limit equilibrium) and runs gravity relaxation with contact
//! on a fresh [`Simulation`] (the scene's time step, [`crate::dynamics::time::TimeStep`]). **Failure criterion**: the
//! relaxation does not reach its residual tolerance within `max_steps`, or any slave node of
//! the joints has slipped more than `slip_limit` (the block is sliding, not settling). F is
//! bisected between a stable and a failed value until the bracket is narrower than `tolerance`.

use crate::contact::law::JointLaw;
use crate::error::{Error, ModelError};
use crate::mesh::Mesh;
use crate::problem::Problem;
use crate::scene::Scene;
use crate::simulation::Simulation;
use serde::{Deserialize, Serialize};

/// Settings of a strength-reduction search.
#[derive(Clone, Debug, Serialize)]
pub struct SsrOptions {
    /// Initial bracket [F_low, F_high]: F_low must be stable, F_high must fail. Default [0.5, 4].
    pub bracket: [f64; 2],
    /// Stop when F_high − F_low < tolerance. Default 0.005.
    pub tolerance: f64,
    /// Relaxation step budget per trial. Default 40 000.
    pub max_steps: usize,
    /// Relative residual of the relaxation. Default 1e-5.
    pub residual: f64,
    /// Slip [m] above which a trial counts as failed. Default 0.05 m.
    pub slip_limit: f64,
    /// Node whose displacement is recorded per trial (e.g. P1), if any.
    pub monitor: Option<[f64; 3]>,
}

impl Default for SsrOptions {
    fn default() -> Self {
        SsrOptions { bracket: [0.5, 4.0], tolerance: 0.005, max_steps: 40_000, residual: 1e-5, slip_limit: 0.05, monitor: None }
    }
}

/// One trial of the search.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SsrTrial {
    pub factor: f64,
    pub failed: bool,
    pub converged: bool,
    pub steps: usize,
    pub residual: f64,
    /// Largest slip of any slave node [m].
    pub max_slip: f64,
    /// |u| of the monitored node [m].
    pub monitor_displacement: f64,
}

/// Result: the bracket and every trial (in the order run).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SsrResult {
    pub factor: f64,
    pub bracket: [f64; 2],
    pub trials: Vec<SsrTrial>,
    pub criterion: String,
}

/// The problem of a strength-reduction search on `scene`: built once, with gravity.
pub fn ssr_problem(mesh: &Mesh, scene: &Scene) -> Result<Problem, Error> {
    let problem = Problem::build(scene.clone(), mesh.clone())?;
    if problem.loads.gravity.is_none() {
        return Err(ModelError::Invalid("strength reduction needs gravity in the scene's loads".into()).into());
    }
    Ok(problem)
}

/// The joints' laws of trial `f`: μ/F and c/F on the scene's laws, cohesion kept; an asperity
/// envelope's tan(φ + i)/F too, so that the whole envelope min(tan(φ + i) σ, c + μ σ) is
/// divided by F (its knee stays at the same σ).
fn reduced_laws(scene: &Scene, base: &[JointLaw], f: f64) -> Vec<JointLaw> {
    scene
        .joints
        .iter()
        .zip(base)
        .map(|(j, law)| JointLaw { mu: j.friction().mu() / f, cohesion: j.cohesion.unwrap_or(0.0) / f, asperity_friction: j.asperity_friction().map(|s| s / f), keep_cohesion: true, ..*law })
        .collect()
}

/// Run one trial at factor `f` on `problem` (its joints' laws are set for the trial; `base` are
/// the scene's laws).
pub fn ssr_trial(problem: &mut Problem, base: &[JointLaw], f: f64, opts: &SsrOptions) -> Result<SsrTrial, Error> {
    for (j, law) in problem.joints.iter_mut().zip(reduced_laws(&problem.scene, base, f)) {
        law.validate().map_err(|e| ModelError::Invalid(format!("joint \"{}\": {e}", j.tag.name)))?;
        j.law = law;
    }
    let problem = &*problem;
    let mut sim = Simulation::new(problem)?;
    let eq = sim.relax(opts.residual, opts.max_steps)?;
    let state = &sim.state;
    let max_slip = state.contact.joints.iter().flat_map(|j| j.pairs.iter()).map(|p| p.slip).fold(0.0, f64::max);
    let monitor_displacement = match opts.monitor {
        Some(p) => {
            let (n, _) = problem.model.mesh.nearest_node(p).ok_or_else(|| ModelError::Invalid("empty mesh".into()))?;
            (state.u[3 * n].powi(2) + state.u[3 * n + 1].powi(2) + state.u[3 * n + 2].powi(2)).sqrt()
        }
        None => 0.0,
    };
    let failed = !eq.converged || max_slip > opts.slip_limit;
    Ok(SsrTrial { factor: f, failed, converged: eq.converged, steps: eq.steps, residual: eq.residual, max_slip, monitor_displacement })
}

/// Bisection on F (see the module doc for the failure criterion).
pub fn strength_reduction(mesh: &Mesh, scene: &Scene, opts: &SsrOptions) -> Result<SsrResult, Error> {
    let mut trials = Vec::new();
    let [mut lo, mut hi] = opts.bracket;
    let mut problem = ssr_problem(mesh, scene)?;
    let base: Vec<JointLaw> = problem.joints.iter().map(|j| j.law).collect();
    let t_lo = ssr_trial(&mut problem, &base, lo, opts)?;
    let lo_failed = t_lo.failed;
    trials.push(t_lo);
    if lo_failed {
        return Err(ModelError::Invalid(format!("strength reduction: the model already fails at F = {lo} (lower the bracket)")).into());
    }
    let t_hi = ssr_trial(&mut problem, &base, hi, opts)?;
    let hi_failed = t_hi.failed;
    trials.push(t_hi);
    if !hi_failed {
        return Err(ModelError::Invalid(format!("strength reduction: the model is still stable at F = {hi} (raise the bracket)")).into());
    }
    while hi - lo > opts.tolerance {
        let mid = 0.5 * (lo + hi);
        let t = ssr_trial(&mut problem, &base, mid, opts)?;
        if t.failed {
            hi = mid;
        } else {
            lo = mid;
        }
        trials.push(t);
    }
    Ok(SsrResult {
        factor: 0.5 * (lo + hi),
        bracket: [lo, hi],
        trials,
        criterion: format!(
            "failed = relaxation not converged to {:.0e} within {} steps, or slip > {} m",
            opts.residual, opts.max_steps, opts.slip_limit
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::law::PairHistory;

    #[test]
    fn strength_reduction_divides_the_whole_bilinear_envelope_by_f() {
        // Reference: τ_F(σ) = min(tan(φ + i) σ, c + σ tan φ) / F at every σ, so the knee stays at
        // the same σ (a reduction of tan φ and c alone would move it). φ = 30°, i = 15°,
        // c = 48 kPa on 1 m², F = 1.5; tolerance round-off (1e-12 relative).
        let scene: Scene = serde_json::from_value(serde_json::json!({
            "geometry": {"msh": "unused.msh"},
            "materials": [{"group": "all", "E": 1e10, "nu": 0.25, "rho": 2500}],
            "time": {"duration": 1.0},
            "joints": [{"name": "B", "master": "m", "slave": "s", "phi": 30, "cohesion": 48000, "asperity_angle": 15}]
        }))
        .unwrap();
        scene.validate().unwrap();
        let j = &scene.joints[0];
        let base = JointLaw { cohesion: 48e3, asperity_friction: j.asperity_friction(), ..JointLaw::coulomb(j.friction().mu()) };
        let f = 1.5;
        let reduced = reduced_laws(&scene, &[base], f)[0];
        let h = PairHistory::default();
        for sigma in [0.0, 1e4, 5e4, 1.136e5, 2e5, 1e6] {
            let (a, b) = (reduced.shear_limit(sigma, &h, 1.0), base.shear_limit(sigma, &h, 1.0) / f);
            assert!((a - b).abs() <= 1e-12 * b.max(1.0), "σ = {sigma}: {a} vs {b}");
        }
        assert!((reduced.knee_force(1.0).unwrap() - base.knee_force(1.0).unwrap()).abs() < 1e-6);
    }
}
