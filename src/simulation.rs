//! One run in memory: `Simulation::new(&problem)?` → `.equilibrate()?` → `.run(&mut recorder)?`.
//!
//! The same object serves the CLI (`pipeline::run`), strength reduction (`study::ssr`), the
//! tests and the benchmarks, so the rule for dt ([`TimeStep::resolve`]), the gravity
//! equilibrium and the reset after it exist once.
//!
//! Owns: the run's [`State`] (what changes), the solvers' scratch ([`ExplicitSolver`], the
//! contact correction), the resolved [`TimeStep`]. Borrows the [`Problem`] (immutable).
//! Outputs go through an [`Observer`] (`output::recorder::Recorder` writes frames, histories,
//! peaks and the summary; a test can observe with a closure, [`FnObserver`]).
//!
//! Sequence and invariants:
//! - `new`: dt resolved (scene `time.dt` checked against the stable step, penalty bound
//!   included), state at rest at t = 0, energy account started.
//! - `equilibrate`: the one door to the static state: the scene's `equilibrium` (its
//!   `sequence`: the construction sequence's direct solves in `statics::sequence`, or the
//!   relaxation of gravity with the joints' bonds kept or not, residual checked against
//!   `max_residual`), then the reset written once ([`Simulation::restart_after_static`]): the
//!   clock restarts at t = 0 and the joints' slip counters restart (slip while settling is not
//!   seismic slip).
//! - `run`: `duration / dt` = N dynamic steps and one look-ahead step: after step k the
//!   observer sees u[k−1], u[k], u[k+1] and reports at t[k] ([`Simulation::kinematics`]), so the
//!   outputs reach t[N] = duration with central-difference velocity and acceleration; the state
//!   left behind is at t[N + 1]. An observer may end the run early ([`Observer::stop_after`]).

use crate::constraint::Constraint;
use crate::contact::force::ContactSolver;
use crate::contact::ContactState;
use crate::dynamics::time::TimeStep;
use crate::dynamics::{relax_gravity, EquilibriumInfo, ExplicitSolver, Kinematics, Stage, State, StepInfo};
use crate::error::{Error, ModelError, StepError};
use crate::problem::Problem;
use crate::statics::sequence::{SequenceReport, StageReport};

/// What watches a run: called once before the first dynamic step, after every step and at the
/// end.
pub trait Observer {
    /// Before the first dynamic step (the state is the equilibrium, at t = 0).
    fn start(&mut self, _sim: &Simulation<'_>) -> Result<(), Error> {
        Ok(())
    }
    /// After dynamic step `k` (0-based): the kinematics at t[k] and the contact state at
    /// t[k + 1]; `last` is the last output index the run will reach (the scene's N, or the
    /// observer's [`Self::stop_after`]).
    fn observe(&mut self, sim: &Simulation<'_>, k: usize, last: usize) -> Result<(), Error>;
    /// Whether [`Observer::observe`] after step `k` reads the displacements of the condensed
    /// foundation's nodes (frames, monitors there). With the Schur-complement condensation they
    /// are reconstructed only then (one solve) and are 0 in the state otherwise
    /// (`foundation`). Default true (always right; an observer that knows its schedule says
    /// when).
    fn full_state_due(&self, _sim: &Simulation<'_>, _k: usize, _last: usize) -> bool {
        true
    }
    /// The last output index the observer wants (an interrupted run), if earlier than the
    /// scene's; asked after every `observe`.
    fn stop_after(&self) -> Option<usize> {
        None
    }
    /// After the last step.
    fn finish(&mut self, _sim: &Simulation<'_>) -> Result<(), Error> {
        Ok(())
    }
}

/// Steps between two checks that every node's velocity and acceleration are finite
/// ([`Simulation::check_finite_kinematics`]): 100, so the scan of 6 numbers a node costs about
/// 1 % of a step's nodal update while a non-finite state is caught within 100 steps (the
/// displacement itself is checked every step).
pub const FINITE_CHECK_STRIDE: usize = 100;

/// An observer from a closure called after every step with the simulation.
pub struct FnObserver<F>(pub F);

impl<F: FnMut(&Simulation<'_>)> Observer for FnObserver<F> {
    fn observe(&mut self, sim: &Simulation<'_>, _k: usize, _n: usize) -> Result<(), Error> {
        (self.0)(sim);
        Ok(())
    }
}

/// A run of a [`Problem`].
pub struct Simulation<'p> {
    pub problem: &'p Problem,
    pub time: TimeStep,
    pub solver: ExplicitSolver,
    /// The contact correction (`None` without joints).
    pub contact: Option<ContactSolver<'p>>,
    /// The static condensation of the massless blocks (`None` without them); runs after the
    /// contact correction (solve per step) or in the element loop (Schur complement).
    pub foundation: Option<crate::problem::foundation::Condensation>,
    /// The radiating foundation's far boundary (`None` for the other foundation models).
    pub radiating: Option<crate::problem::foundation::radiating::Radiating<'p>>,
    /// The acoustic reservoir's water (`None` for the other reservoir models).
    pub water: Option<crate::problem::reservoir::acoustic::AcousticRun<'p>>,
    pub state: State,
    /// The outcome of [`Self::equilibrate`] (`None` before it, or without a static state).
    pub equilibrium: Option<EquilibriumInfo>,
    /// Notes for the summary (the problem's, then the run's).
    pub notes: Vec<String>,
}

impl<'p> Simulation<'p> {
    /// A run at rest at t = 0 with the scene's time step.
    pub fn new(problem: &'p Problem) -> Result<Simulation<'p>, Error> {
        Self::with_condensation(problem, None)
    }

    /// [`Simulation::new`] with the massless foundation's condensation method given (`None`:
    /// the rule of `foundation::choose_method`); for tests and benchmarks that compare them.
    pub fn with_condensation(problem: &'p Problem, method: Option<crate::problem::foundation::CondensationMethod>) -> Result<Simulation<'p>, Error> {
        let model = &problem.model;
        let contact = (!problem.joints.is_empty()).then(|| ContactSolver::new(model, &problem.joints));
        let penalty = contact.as_ref().map(|c| c.penalty_omega2_bound(model)).unwrap_or(0.0);
        let t0 = std::time::Instant::now();
        let foundation = crate::problem::foundation::Condensation::build(model, faer::Par::Seq, method).map_err(|e| ModelError::Invalid(e.to_string()))?;
        let mut notes = problem.notes.clone();
        notes.extend(model.mass_scaling.as_ref().map(|m| m.note()));
        // the condensed foundation stiffens the interface: its ω² bound adds to the elements'
        let found_w2 = foundation.as_ref().map(|f| f.omega2_bound()).unwrap_or(0.0);
        if let Some(f) = foundation.as_ref() {
            let i = f.info(t0.elapsed().as_secs_f64());
            let how = match i.method {
                crate::problem::foundation::CondensationMethod::Solve => "a solve per step".to_string(),
                crate::problem::foundation::CondensationMethod::Schur => format!("dense Schur complement on the interface, {:.1} MB", i.schur_bytes as f64 / 1e6),
            };
            notes.push(format!(
                "massless blocks: {} unknowns condensed on {} interface unknowns ({how}; factor {} entries; setup {:.2} s); foundation ω² bound {:.4e} 1/s² in the stable step",
                i.condensed_unknowns, i.interface_unknowns, i.factor_entries, i.setup_time, i.omega2_bound
            ));
        }
        let mut radiating = problem.far_boundary.as_ref().map(crate::problem::foundation::radiating::Radiating::new);
        let far_w2 = problem.far_boundary.as_ref().map(|f| f.omega2_bound(model)).unwrap_or(0.0);
        let time = TimeStep::resolve(model, &problem.scene.time, penalty + found_w2 + far_w2)?;
        notes.extend(time.note());
        // the acoustic water: relative to the moving base unless the foundation radiates
        let water = problem.water.as_ref().map(|w| crate::problem::reservoir::acoustic::AcousticRun::new(w, &problem.loads, problem.far_boundary.is_none(), time.dt));
        notes.extend(problem.water.as_ref().map(|w| w.note(time.dt)));
        let mut solver = ExplicitSolver::new(model, time.dt, problem.scene.time.energy_tolerance);
        solver.dynamic_held = problem.far_boundary.as_ref().map(|f| f.dynamic_held.clone());
        let mut state = State::at_rest(model, ContactState::new(&problem.joints));
        solver.start_energy(model, &mut state);
        if let Some(r) = radiating.as_mut() {
            r.start(model, &problem.loads, &state.u);
        }
        Ok(Simulation { problem, time, solver, contact, foundation, radiating, water, state, equilibrium: None, notes })
    }

    /// The step [s].
    pub fn dt(&self) -> f64 {
        self.time.dt
    }

    /// Dynamic steps of the scene's `time.duration`.
    pub fn n_steps(&self) -> usize {
        self.time.steps_for(self.problem.scene.time.duration)
    }

    /// The static state as the scene's `equilibrium` says: the one door to it (the CLI's run,
    /// `dam-static`, the generated joint tests and the tests all come through here).
    ///
    /// - `sequence: "construction"` (with gravity or static forces and `method: "relaxation"`):
    ///   the construction sequence's direct solves ([`crate::statics::sequence::construction_into`]:
    ///   self-weight on ungrouted joints, grouting, the static forces with the joints active).
    /// - otherwise (`"simultaneous"`, `"grouted"`): the tied joints (and, `"grouted"`, every
    ///   joint) grouted on the initial configuration, then the relaxation of gravity and the
    ///   static forces with the joints' bonds kept or not ([`Self::relax`]); an equilibrium not
    ///   reached within `max_residual` is an error, one above `tolerance` only a note. Nothing
    ///   without gravity and static forces, or with `method: "none"`.
    ///
    /// Then [`Self::restart_after_static`] (when a static state was computed). The stages go to
    /// the notes and the returned report; the outcome is kept in [`Self::equilibrium`].
    pub fn equilibrate(&mut self) -> Result<SequenceReport, Error> {
        let p = self.problem;
        let sc = &p.scene;
        let sequence = sc.equilibrium.sequence;
        let loaded = p.loads.gravity.is_some() || !p.loads.static_forces.is_empty();
        let relaxing = loaded && sc.equilibrium.method == crate::scene::EquilibriumMethod::Relaxation;
        let mut stages = Vec::new();
        if sequence == crate::scene::StaticSequence::Construction && relaxing {
            let mut u = vec![0.0; self.state.u.len()];
            let (st, residual) = crate::statics::sequence::construction_into(p, &mut self.state.contact, &mut u)?;
            stages.extend(st);
            self.state.u.copy_from_slice(&u);
            self.state.u_prev.copy_from_slice(&u);
            self.equilibrium = Some(EquilibriumInfo { steps: 0, residual, converged: true });
            self.restart_after_static();
        } else {
            stages.extend(crate::statics::sequence::grout_before_relaxation(p, &mut self.state.contact, sequence == crate::scene::StaticSequence::Grouted)?);
            if relaxing {
                let eq = self.relax_checked()?;
                stages.push(StageReport { name: "all loads, joints in contact".into(), method: "relaxation".into(), residual: eq.residual, steps: eq.steps, note: String::new() });
                self.equilibrium = Some(eq);
                self.restart_after_static();
            }
        }
        let report = SequenceReport { sequence: sequence.as_str().to_string(), stages };
        self.notes.extend(report.lines());
        Ok(report)
    }

    /// The relaxation of the scene's `equilibrium` (tolerance, max_steps, joint_bonds), checked
    /// against `max_residual` (error) and `tolerance` (a note).
    fn relax_checked(&mut self) -> Result<EquilibriumInfo, Error> {
        let sc = &self.problem.scene;
        if let Some(c) = self.contact.as_mut() {
            c.keep_bonds = sc.equilibrium.joint_bonds == crate::scene::JointBonds::Kept;
        }
        let eq = self.relax(sc.equilibrium.tolerance, sc.equilibrium.max_steps)?;
        if !eq.converged && eq.residual > sc.equilibrium.max_residual {
            return Err(ModelError::Invalid(format!(
                "gravity equilibrium not reached in {} steps: residual {:.2e} > max_residual {:.1e}. Raise equilibrium.max_steps or check supports (a block without supports or contact falls freely).",
                eq.steps, eq.residual, sc.equilibrium.max_residual
            ))
            .into());
        }
        if !eq.converged {
            self.notes.push(format!("gravity equilibrium residual {:.2e} above tolerance {:.1e} (accepted below max_residual)", eq.residual, sc.equilibrium.tolerance));
        }
        if let Some(c) = self.contact.as_mut() {
            c.keep_bonds = false;
        }
        Ok(eq)
    }

    /// The reset after the static state, written once: the clock restarts at t = 0 from the
    /// current state (taken as at rest), with the energy account from it, and the joints' slip
    /// counters restart (slip while settling is not seismic slip).
    pub fn restart_after_static(&mut self) {
        self.restart_clock();
        self.state.contact.restart_slip();
    }

    /// Dynamic relaxation of gravity alone ([`relax_gravity`]) with the joints in contact, to a
    /// relative residual `tol` within `max_steps` steps; no check, no restart (strength
    /// reduction reads the state as it ends).
    pub fn relax(&mut self, tol: f64, max_steps: usize) -> Result<EquilibriumInfo, StepError> {
        let p = self.problem;
        let mut cs: Vec<&mut dyn Constraint<ContactState>> = Vec::with_capacity(2);
        if let Some(c) = self.contact.as_mut() {
            cs.push(c);
        }
        if let Some(f) = self.foundation.as_mut() {
            cs.push(f);
        }
        if let Some(r) = self.radiating.as_mut() {
            cs.push(r);
        }
        let eq = relax_gravity(&p.model, &p.loads, &mut self.solver, &mut self.state, &mut cs, tol, max_steps)?;
        self.complete_state()?;
        Ok(eq)
    }

    /// Give the state's displacement vectors (u[n−1], u[n], u[n+1]) the condensed foundation's
    /// part where they lack it (Schur complement: one solve; nothing otherwise). Called after
    /// relaxation and before every observation that reads the foundation.
    pub fn complete_state(&mut self) -> Result<(), StepError> {
        if let Some(f) = self.foundation.as_mut() {
            f.complete_into([&mut self.state.u, &mut self.state.u_prev, &mut self.solver.u_nm1]).map_err(|e| StepError::Foundation(e.to_string()))?;
        }
        Ok(())
    }

    /// Zero the condensed foundation's part of the state's displacement vectors (Schur
    /// complement, when no observer reads it: no stale mixture of reconstructed and zero
    /// vectors); nothing otherwise.
    fn clear_condensed_state(&mut self) {
        if let Some(f) = self.foundation.as_mut() {
            f.clear_into([&mut self.state.u, &mut self.state.u_prev, &mut self.solver.u_nm1]);
        }
    }

    /// Restart the clock at t = 0 from the current state (taken as at rest) and the energy
    /// account from it.
    pub fn restart_clock(&mut self) {
        self.state.step = 0;
        self.state.t = 0.0;
        self.solver.start_energy(&self.problem.model, &mut self.state);
        if let Some(r) = self.radiating.as_mut() {
            r.start(&self.problem.model, &self.problem.loads, &self.state.u);
        }
        if let Some(w) = self.water.as_mut() {
            w.restart();
        }
    }

    /// One dynamic step (gravity, base motion, loads, Rayleigh damping, contact).
    pub fn step(&mut self) -> Result<StepInfo, StepError> {
        let p = self.problem;
        if self.radiating.is_some() || self.water.is_some() {
            let mut cs: Vec<&mut dyn Constraint<ContactState>> = Vec::with_capacity(4);
            if let Some(c) = self.contact.as_mut() {
                cs.push(c);
            }
            if let Some(f) = self.foundation.as_mut() {
                cs.push(f);
            }
            if let Some(r) = self.radiating.as_mut() {
                cs.push(r);
            }
            // last: the water reads the dam's final u[n+1]
            if let Some(w) = self.water.as_mut() {
                cs.push(w);
            }
            return self.solver.step(&p.model, &p.loads, &mut self.state, Stage::Dynamic, &mut cs);
        }
        match (self.contact.as_mut(), self.foundation.as_mut()) {
            (Some(c), None) => self.solver.step(&p.model, &p.loads, &mut self.state, Stage::Dynamic, &mut [c as &mut dyn Constraint<ContactState>]),
            (None, None) => self.solver.step(&p.model, &p.loads, &mut self.state, Stage::Dynamic, &mut []),
            (Some(c), Some(f)) => self.solver.step(&p.model, &p.loads, &mut self.state, Stage::Dynamic, &mut [c as &mut dyn Constraint<ContactState>, f]),
            (None, Some(f)) => self.solver.step(&p.model, &p.loads, &mut self.state, Stage::Dynamic, &mut [f as &mut dyn Constraint<ContactState>]),
        }
    }


    /// u[n−1], u[n], u[n+1] after a step, at t[n] = t − dt (outputs report there, where
    /// central differences give the velocity and acceleration).
    pub fn kinematics(&self) -> Kinematics<'_> {
        Kinematics { t: self.state.t - self.time.dt, dt: self.time.dt, u_prev: &self.solver.u_nm1, u: &self.state.u_prev, u_next: &self.state.u }
    }

    /// The state as it is, as kinematics at rest at its own time (before any step, or for a
    /// run of no steps).
    pub fn kinematics_at_rest(&self) -> Kinematics<'_> {
        Kinematics { t: self.state.t, dt: self.time.dt, u_prev: &self.state.u, u: &self.state.u, u_next: &self.state.u }
    }

    /// Outputs at t[0] … t[n] with `observer` watching: n + 1 dynamic steps (the last only
    /// computes u[n+1] for the velocity and acceleration at t[n]); none when n = 0 (the observer's
    /// `start` sees the state at rest). Fewer when the observer asks to stop.
    pub fn run_steps(&mut self, n: usize, observer: &mut dyn Observer) -> Result<(), Error> {
        observer.start(self)?;
        let mut last = n;
        let mut k = 0;
        while n > 0 && k <= last {
            self.step()?;
            if observer.full_state_due(self, k, last) {
                self.complete_state()?;
            } else {
                self.clear_condensed_state();
            }
            if k % FINITE_CHECK_STRIDE == 0 || k == last {
                self.check_finite_kinematics()?;
            }
            observer.observe(self, k, last)?;
            if let Some(s) = observer.stop_after() {
                last = last.min(s.max(k));
            }
            k += 1;
        }
        observer.finish(self)
    }

    /// The first node whose velocity or acceleration (central differences of the displacements,
    /// which the step itself checks every step) is not finite, as an error naming it, the step
    /// and the time: displacements near f64's limit gave inf/NaN peaks in a run that ended with
    /// exit 0 (issue 33). Called every [`FINITE_CHECK_STRIDE`] steps and at the last.
    fn check_finite_kinematics(&self) -> Result<(), StepError> {
        let kin = self.kinematics();
        let Some(i) = (0..kin.u.len()).find(|&i| !(kin.velocity(i).is_finite() && kin.acceleration(i).is_finite())) else {
            return Ok(());
        };
        let (mesh, node) = (&self.problem.model.mesh, i / 3);
        Err(StepError::NonFinite {
            what: "velocity or acceleration".into(),
            step: self.state.step,
            t: kin.t,
            node: mesh.node_tags[node] as usize,
            x: mesh.nodes[node],
            cause: "a load, record or gravity far beyond physical values (the displacements reached the limit of floating point)".into(),
        })
    }

    /// The scene's duration ([`Self::n_steps`] dynamic steps, outputs up to t = duration) with
    /// `observer` watching.
    pub fn run(&mut self, observer: &mut dyn Observer) -> Result<(), Error> {
        self.run_steps(self.n_steps(), observer)
    }
}
