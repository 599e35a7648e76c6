//! Dynamic relaxation of a load increment on a state already in equilibrium (the stages of a
//! construction sequence, module `construction`).
//!
//! The same scheme as [`super::relax_gravity`] (undamped mass, α = 2 ω_min from the Rayleigh
//! quotient, the constraints after each prediction), with gravity kept at its full value from
//! the first step (the state already carries it) and only the static forces (the reservoir's
//! hydrostatic pressure) ramped in over `ramp_steps` steps ([`super::RELAXATION_RAMP_STEPS`]
//! from rest; 0 when the state already carries them, e.g. from a linear solve). Residual:
//! ‖M (a + α v_b)‖ over the free components, relative to ‖F_gravity + F_static‖ (the whole load
//! the state must now carry).

use super::{Constraints, EquilibriumInfo, ExplicitSolver, Stage, State};
use crate::dynamics::loads::Loads;
use crate::error::StepError;
use crate::model::Model;

/// Relax `state` (in equilibrium under gravity alone, or already near the whole load) to
/// equilibrium under gravity plus the static forces of `loads`, ramped in over `ramp_steps`
/// steps (0: the whole load from the first step); `tol` and `max_steps` as for relaxation.
pub fn relax_static_increment(
    model: &Model,
    loads: &Loads,
    solver: &mut ExplicitSolver,
    state: &mut State,
    constraints: Constraints<'_, '_>,
    tol: f64,
    max_steps: usize,
    ramp_steps: usize,
) -> Result<EquilibriumInfo, StepError> {
    let mut f_all = vec![0.0; 3 * model.n_nodes()];
    loads.external_force_into(model, 0.0, true, false, &mut f_all);
    let norm_f: f64 = f_all.iter().enumerate().filter(|(i, _)| model.is_free(i / 3, i % 3)).map(|(_, f)| f * f).sum::<f64>().sqrt();
    if norm_f == 0.0 || loads.static_forces.is_empty() {
        return Ok(EquilibriumInfo { steps: 0, residual: 0.0, converged: true });
    }
    let mut stage = loads.clone();
    let dt = solver.dt;
    let mut residual = f64::INFINITY;
    let mut alpha = 0.0;
    for k in 0..max_steps {
        let scale = if ramp_steps == 0 { 1.0 } else { ((k + 1) as f64 / ramp_steps as f64).min(1.0) };
        for (s, f) in stage.static_forces.iter_mut().zip(&loads.static_forces) {
            s.1 = f.1.map(|v| v * scale);
        }
        solver.step(model, &stage, state, Stage::Relaxation(alpha, 1.0), &mut *constraints)?;
        let (r2, ukb, umu) = super::relaxation_balance(model, solver, state, alpha, 1.0);
        residual = r2.max(0.0).sqrt() / norm_f;
        alpha = super::relaxation_damping(ukb, umu, dt, alpha);
        if residual < tol && k + 1 >= ramp_steps {
            state.u_prev.copy_from_slice(&state.u);
            return Ok(EquilibriumInfo { steps: k + 1, residual, converged: true });
        }
    }
    state.u_prev.copy_from_slice(&state.u);
    Ok(EquilibriumInfo { steps: max_steps, residual, converged: false })
}
