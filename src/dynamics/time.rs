//! The time step: the one rule for dt (design §4), used by runs, strength reduction, tests and
//! benchmarks alike.
//!
//! The stable step of central differences with Rayleigh damping at the largest frequency bound
//! ω²_max = ω²_elements + ω²_penalty (element eigenvalue theorem with lumped mass, plus the
//! Gershgorin bound of the penalty springs, λ_max(A + B) ≤ λ_max(A) + λ_max(B)):
//! dt_stable = (−c + √(c² + 4ω²)) / ω² with c = α + βω². The scene's `time.dt` must not exceed
//! it (an error quoting the limit); without `dt`, dt = `time.courant` × dt_stable, courant
//! [`DEFAULT_COURANT`] by default.

use crate::error::ModelError;
use crate::model::Model;
use crate::scene::TimeSpec;

/// Fraction of the stable step used when a scene gives neither `dt` nor `courant` (defined with
/// the scene, where the model's mass scaling reads it too).
pub use crate::scene::DEFAULT_COURANT;

/// The resolved time step of a run.
#[derive(Clone, Debug, PartialEq)]
pub struct TimeStep {
    /// The step used [s].
    pub dt: f64,
    /// The stable step, penalty springs included [s].
    pub dt_stable: f64,
    /// The stable step of the elements alone [s] (equal to `dt_stable` without penalty springs).
    pub dt_elements: f64,
    /// The ω² bound added by penalty springs [1/s²] (0 without).
    pub penalty_omega2: f64,
}

impl TimeStep {
    /// Resolve `time` (dt or courant) on `model` with the penalty springs' ω² bound
    /// `penalty_omega2` [1/s²] (0 without penalty joints).
    pub fn resolve(model: &Model, time: &TimeSpec, penalty_omega2: f64) -> Result<TimeStep, ModelError> {
        let dt_elements = model.stable_dt();
        let dt_stable = if penalty_omega2 > 0.0 { model.stable_dt_with(penalty_omega2) } else { dt_elements };
        let dt = match time.dt {
            Some(dt) => {
                if dt > dt_stable {
                    return Err(ModelError::UnstableStep { dt, limit: dt_stable, element: model.critical.tag, group: model.critical.group.clone() });
                }
                dt
            }
            None if dt_stable.is_finite() => time.courant_or_default() * dt_stable,
            None => return Err(ModelError::Invalid("no element has mass, so none sets a stable step: give `time.dt` [s]".into())),
        };
        let steps = time.duration / dt;
        if !(steps <= time.max_steps as f64) {
            return Err(ModelError::Invalid(format!(
                "time.duration {} s at dt {dt:.4e} s is {steps:.3e} steps, above time.max_steps = {} (stable step {dt_stable:.4e} s, set by element {} in \"{}\", scaled Jacobian {:.3}{}). Shorten the duration, coarsen the critical element, or raise time.max_steps to allow it.",
                time.duration,
                time.max_steps,
                model.critical.tag,
                model.critical.group,
                model.critical.scaled_jacobian,
                if model.critical.is_sliver() { ": a sliver, a better shaped mesh raises the step (docs/elements.md, \"Mesh quality\")" } else { "" }
            )));
        }
        Ok(TimeStep { dt, dt_stable, dt_elements, penalty_omega2 })
    }

    /// A note for the summary when added stiffness (penalty springs, the condensed foundation's
    /// interface bound) lowered the stable step.
    pub fn note(&self) -> Option<String> {
        (self.penalty_omega2 > 0.0).then(|| format!("added stiffness (penalty springs, massless-foundation interface): stable step reduced from {:.4e} s to {:.4e} s", self.dt_elements, self.dt_stable))
    }

    /// Steps of a stage of `duration` [s]: duration / dt, rounded.
    pub fn steps_for(&self, duration: f64) -> usize {
        (duration / self.dt).round() as usize
    }
}
