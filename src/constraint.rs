//! The trait the explicit step calls after its contact-free prediction (design §4–5).
//!
//! A constraint corrects the predicted displacements u[n+1] in place: the dynamic contact force
//! (`contact::force::ContactSolver`) and, next, the static condensation of a massless
//! foundation. The step (`dynamics::ExplicitSolver::step`) calls the constraints in the
//! order given, each on the prediction corrected by the ones before it.
//!
//! Owns nothing: a leaf. Inputs: the model, the step's kinematics u[n−1], u[n], the time step,
//! and the history the constraint may update (`H`: the run's `contact::ContactState`
//! for the dynamic stepping of this crate; a constraint without history ignores it and
//! implements `Constraint<H>` for every `H`). Output: the corrected u[n+1] and a
//! [`ConstraintInfo`] (work done, iterations).
//!
//! Invariants: a constraint never writes a fixed component (supports keep relative displacement
//! 0); the work it reports is Δu_c · R with Δu_c = (u[n+1] − u[n−1]) / 2, the central-difference
//! increment the energy account uses.

use crate::error::StepError;
use crate::model::Model;

/// What a constraint sees of the step it corrects.
#[derive(Clone, Copy, Debug)]
pub struct StepContext<'a> {
    /// t[n+1] [s].
    pub t_next: f64,
    /// The step [s].
    pub dt: f64,
    /// u[n−1] and u[n] [m], 3 per node.
    pub u_prev: &'a [f64],
    pub u: &'a [f64],
}

/// Result of one constraint's correction of one step (non-fatal diagnostics).
#[derive(Clone, Debug, Default)]
pub struct ConstraintInfo {
    /// Work of the correction forces over the step, Δu_c · R [J].
    pub work: f64,
    /// Iterations used (Gauss–Seidel sweeps for contact; 0 for a direct solve).
    pub iterations: usize,
}

impl ConstraintInfo {
    /// The sum of two corrections of one step (work added, iterations added).
    pub fn merged(self, other: ConstraintInfo) -> ConstraintInfo {
        ConstraintInfo { work: self.work + other.work, iterations: self.iterations + other.iterations }
    }
}

/// A correction of the contact-free prediction u[n+1].
pub trait Constraint<H: ?Sized> {
    /// Correct `u_next` (the predicted u[n+1]) in place; `history` is the part of the run's
    /// state the constraint may update.
    fn correct(&mut self, model: &Model, history: &mut H, step: &StepContext<'_>, u_next: &mut [f64]) -> Result<ConstraintInfo, StepError>;

    /// Whether this constraint stands for the stiffness of the massless elements (the condensed
    /// foundation's Schur complement): the step's element loop then leaves those elements out
    /// and adds [`Constraint::add_internal_force_into`] instead. Default false.
    fn replaces_massless_elements(&self) -> bool {
        false
    }

    /// f += the internal force of what this constraint stands for, at the displacements `u`
    /// (only called when [`Constraint::replaces_massless_elements`]). Default: nothing.
    fn add_internal_force_into(&mut self, _u: &[f64], _f: &mut [f64]) {}

    /// f += the inertia-free loads this constraint applies at t[n] (`step.t_next` − dt), before
    /// the prediction: called every step, `dynamic` false during gravity relaxation. The step
    /// counts them as external work. Default: nothing (e.g. the radiating foundation's held
    /// reactions, free-field forces and springs, `problem::foundation::radiating`).
    fn add_external_force_into(&mut self, _model: &Model, _step: &StepContext<'_>, _dynamic: bool, _f: &mut [f64]) {}
}
