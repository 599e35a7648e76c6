//! Explicit dynamics: the central-difference scheme of design §4, gravity equilibrium, energy.
//!
//! Scheme (lumped M, Rayleigh C = αM + βK, one-sided velocity in the damping term):
//!
//! ```text
//!   M (u[n+1] − 2u[n] + u[n−1]) / dt² + C (u[n] − u[n−1]) / dt + K u[n] = F[n] + R[n]
//! ```
//!
//! so u[n+1] = 2u[n] − u[n−1] + dt² M⁻¹ (F[n] − K (u[n] + β v_b) − α M v_b) with
//! v_b = (u[n] − u[n−1]) / dt, followed by the constraints' corrections (the dynamic contact
//! force u[n+1] += dt² M⁻¹ R, and any other [`Constraint`]). Fixed components keep relative
//! displacement 0; a node without inertia is left at 0 by the prediction, for a constraint to
//! set. M is the inertial mass (`model::mass`): diagonal, except at the few block nodes, which a
//! second pass redoes with their 3×3 inverse.
//!
//! Owns: [`State`] (what changes: t, u[n], u[n−1], energy account) and [`ExplicitSolver`]
//! (scratch buffers only). Energy: E_err = KE + SE + D_α + D_β − E0 − W_ext − W_contact in the
//! discrete energy of central differences (see `check_energy`); energy *appearing* (E_err above
//! `energy_tolerance` × the energy scale) or unbounded growth stops the run.

pub mod loads;
pub mod record;
pub mod time;

pub use crate::constraint::{Constraint, ConstraintInfo, StepContext};
use crate::contact::ContactState;
use crate::error::StepError;
use crate::model::Model;
use loads::Loads;
use rayon::prelude::*;

/// Nodes per block of the parallel nodal loops. Default 1024 (3072 entries, 24 kB per vector):
/// enough work per task to amortise scheduling, small enough to balance two or more threads.
/// Sums over the nodes (energy increments) are summed within a block in node order and the
/// block sums in block order, so they do not depend on the number of threads.
const NODE_BLOCK: usize = 1024;

/// Blocks below which a nodal loop runs on the calling thread. Default 4 (4096 nodes): a
/// smaller loop takes a few µs, about the cost of handing work to the other threads (and of
/// waking them when called from outside the thread pool). The result is the same either way.
const PAR_BLOCKS_MIN: usize = 4;

/// `f` on the blocks of `v` ([`NODE_BLOCK`] nodes, 3 entries each) with the block index,
/// in parallel for large vectors; the results in block order.
fn map_blocks_mut<T: Send>(v: &mut [f64], f: impl Fn(usize, &mut [f64]) -> T + Sync + Send) -> Vec<T> {
    let b = 3 * NODE_BLOCK;
    if v.len() < PAR_BLOCKS_MIN * b {
        v.chunks_mut(b).enumerate().map(|(k, x)| f(k, x)).collect()
    } else {
        crate::par::region();
        v.par_chunks_mut(b).enumerate().map(|(k, x)| f(k, x)).collect()
    }
}

/// Σ over the blocks of entries 0..len of `f(entry range)`, summed in block order (see
/// [`NODE_BLOCK`]), so the sum does not depend on the number of threads.
fn sum_blocks<const K: usize>(len: usize, f: impl Fn(std::ops::Range<usize>) -> [f64; K] + Sync) -> [f64; K] {
    let b = 3 * NODE_BLOCK;
    let n = len.div_ceil(b);
    let parts: Vec<[f64; K]> = if n < PAR_BLOCKS_MIN {
        (0..n).map(|k| f(k * b..((k + 1) * b).min(len))).collect()
    } else {
        crate::par::region();
        (0..n).into_par_iter().map(|k| f(k * b..((k + 1) * b).min(len))).collect()
    };
    add_parts(&parts)
}

fn add_parts<const K: usize>(parts: &[[f64; K]]) -> [f64; K] {
    parts.iter().fold([0.0; K], |mut acc, p| {
        for j in 0..K {
            acc[j] += p[j];
        }
        acc
    })
}

/// `f` on every entry of `v`, in parallel for large vectors.
fn for_each_entry(v: &mut [f64], f: impl Fn(usize, &mut f64) + Sync + Send) {
    map_blocks_mut(v, |k, x| {
        let first = 3 * NODE_BLOCK * k;
        x.iter_mut().enumerate().for_each(|(i, y)| f(first + i, y))
    });
}

/// f = K u of the step: the model's element loop, except when a constraint stands for the
/// massless elements (the condensed foundation's Schur complement S, `foundation`): then the
/// loop leaves them out and the constraint adds S u_b on the interface.
fn internal_forces_into(model: &Model, constraints: &mut [&mut dyn Constraint<ContactState>], u: &[f64], f: &mut [f64]) {
    if constraints.iter().any(|c| c.replaces_massless_elements()) {
        model.internal_forces_of_massive_into(u, f);
        for c in constraints.iter_mut().filter(|c| c.replaces_massless_elements()) {
            c.add_internal_force_into(u, f);
        }
    } else {
        model.internal_forces_into(u, f);
    }
}

/// f = K_p u of the elements of one Rayleigh pair (`rock`: the rock's own; else the scene's,
/// with the part of a constraint standing for the massless elements, as in
/// [`internal_forces_into`]).
fn pair_forces_into(model: &Model, constraints: &mut [&mut dyn Constraint<ContactState>], rock: bool, u: &[f64], f: &mut [f64]) {
    let replaced = constraints.iter().any(|c| c.replaces_massless_elements());
    model.internal_forces_of_pair_into(rock, replaced, u, f);
    if replaced && !rock {
        for c in constraints.iter_mut().filter(|c| c.replaces_massless_elements()) {
            c.add_internal_force_into(u, f);
        }
    }
}

/// w = u[n] + c (u[n] − u[n−1]), c = β/dt: the displacement whose K w is the step's elastic
/// plus stiffness-proportional damping force, K(u[n] + β v_b).
fn stiffness_damped_displacement_into(w: &mut [f64], state: &State, c: f64) {
    for_each_entry(w, |i, w| *w = state.u[i] + c * (state.u[i] - state.u_prev[i]));
}

/// K u[n] from f = K(u[n] + β v_b) = (1 + c) K u[n] − c K u[n−1] (linearity, c = β/dt): exact
/// from K u[n−1], a recursion that damps its own round-off by c/(1+c) < 1 per step.
fn recover_ku_into(ku: &mut [f64], f: &[f64], ku_prev: &[f64], c: f64) {
    for_each_entry(ku, |i, k| *k = (f[i] + c * ku_prev[i]) / (1.0 + c));
}

/// The βK terms of one Rayleigh pair's elements when the pairs' β differ
/// ([`Model::beta_grouped`]): f = K_p (u[n] + β_p v_b), and K_p u[n], K_p u[n−1] recovered from
/// it as the one-β step does for K (see `ExplicitSolver::internal_forces_of_step`).
struct PairForces {
    /// The rock's own pair (else the scene's).
    rock: bool,
    beta: f64,
    f: Vec<f64>,
    ku: Vec<f64>,
    ku_prev: Vec<f64>,
}

/// Running energy account of the dynamic stage [J].
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Energy {
    pub kinetic: f64,
    pub strain: f64,
    pub external_work: f64,
    pub contact_work: f64,
    pub mass_damping: f64,
    /// Work of the stiffness-proportional damping forces βK v [J].
    pub stiffness_damping: f64,
    /// KE + SE at the start of the stage.
    pub initial: f64,
    /// Largest |KE + SE| and |W_ext| seen: the scale of the relative error.
    pub scale: f64,
    /// Latest relative error and its largest value.
    pub error: f64,
    pub max_error: f64,
}

/// What changes during a run.
#[derive(Clone, Debug)]
pub struct State {
    /// Index of the step that produces u[n+1] next.
    pub step: usize,
    /// Time of `u` [s].
    pub t: f64,
    /// u[n] (relative displacements, m), 3 per node.
    pub u: Vec<f64>,
    /// u[n−1].
    pub u_prev: Vec<f64>,
    pub energy: Energy,
    /// Contact history of every joint (empty without joints).
    pub contact: ContactState,
}

impl State {
    /// At rest at t = 0, with the contact history `contact` (`ContactState::new(&joints)`, or
    /// the default without joints).
    pub fn at_rest(model: &Model, contact: ContactState) -> State {
        let n = 3 * model.n_nodes();
        State { step: 0, t: 0.0, u: vec![0.0; n], u_prev: vec![0.0; n], energy: Energy::default(), contact }
    }
}

/// The constraints of a step, applied in order after the prediction (empty: none).
pub type Constraints<'a, 'c> = &'a mut [&'c mut dyn Constraint<ContactState>];

/// Central differences at t[n] from u[n−1], u[n], u[n+1]: the one rule for velocity and
/// acceleration in outputs, monitors and peaks (the scheme's own, design §4).
#[derive(Clone, Copy, Debug)]
pub struct Kinematics<'a> {
    /// t[n] [s] and the step [s].
    pub t: f64,
    pub dt: f64,
    pub u_prev: &'a [f64],
    pub u: &'a [f64],
    pub u_next: &'a [f64],
}

impl Kinematics<'_> {
    /// v[n] = (u[n+1] − u[n−1]) / 2dt of entry `i` [m/s].
    #[inline]
    pub fn velocity(&self, i: usize) -> f64 {
        (self.u_next[i] - self.u_prev[i]) / (2.0 * self.dt)
    }

    /// a[n] = (u[n+1] − 2u[n] + u[n−1]) / dt² of entry `i` [m/s²].
    #[inline]
    pub fn acceleration(&self, i: usize) -> f64 {
        (self.u_next[i] - 2.0 * self.u[i] + self.u_prev[i]) / (self.dt * self.dt)
    }
}

/// Non-fatal information about one step.
#[derive(Clone, Debug, Default)]
pub struct StepInfo {
    /// The constraints' corrections of the step, summed.
    pub correction: ConstraintInfo,
}

/// Which loads a step applies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stage {
    /// Gravity only, scaled by the second value (load ramp), mass-proportional damping α [1/s]
    /// only (dynamic relaxation).
    Relaxation(f64, f64),
    /// Everything: gravity, base motion, force patterns, Rayleigh damping.
    Dynamic,
}

/// Scratch buffers and the step size. Holds nothing that outlives a step except `u_nm1`
/// (u[n−1] after the shift, kept so that outputs can use central differences at t[n]).
pub struct ExplicitSolver {
    pub dt: f64,
    f_int: Vec<f64>,
    f_ext: Vec<f64>,
    /// u + β v_b (allocated only when the model has β > 0).
    w: Vec<f64>,
    u_next: Vec<f64>,
    /// K u[n] and K u[n−1] (recovered from K(u + βv_b) when β > 0, see `step`; allocated only
    /// when the model has β > 0).
    ku: Vec<f64>,
    ku_prev: Vec<f64>,
    /// After a step: u[n−1] of the step just taken (state.u_prev is u[n], state.u is u[n+1]).
    pub u_nm1: Vec<f64>,
    /// Evaluate the energy balance every this many steps. Default 10.
    pub energy_stride: usize,
    /// Relative energy-growth limit (from the scene). Default 0.05.
    pub energy_tolerance: f64,
    /// The βK of each Rayleigh pair (the scene's, the rock's own) when their β differ
    /// ([`Model::beta_grouped`]); empty otherwise (one β: `w`, `ku`, `ku_prev` alone).
    pairs: Vec<PairForces>,
    /// Components held during the dynamic stage when they differ from [`Model::held`] (a
    /// radiating foundation's far boundary: held through gravity, free with its dashpots
    /// after; `problem::foundation::radiating`). `None`: the model's, in every stage.
    pub dynamic_held: Option<Vec<u8>>,
}

impl ExplicitSolver {
    pub fn new(model: &Model, dt: f64, energy_tolerance: f64) -> ExplicitSolver {
        let n = 3 * model.n_nodes();
        let nb = if model.stiffness_damped() { n } else { 0 };
        let pair = |rock: bool, beta: f64| PairForces { rock, beta, f: vec![0.0; n], ku: vec![0.0; n], ku_prev: vec![0.0; n] };
        let pairs = match &model.rock_damping {
            Some(r) if model.beta_grouped() => vec![pair(false, model.beta), pair(true, r.beta)],
            _ => Vec::new(),
        };
        ExplicitSolver {
            dt,
            f_int: vec![0.0; n],
            f_ext: vec![0.0; n],
            w: vec![0.0; nb],
            u_next: vec![0.0; n],
            ku: vec![0.0; nb],
            ku_prev: vec![0.0; nb],
            u_nm1: vec![0.0; n],
            energy_stride: 10,
            energy_tolerance,
            pairs,
            dynamic_held: None,
        }
    }

    /// Internal force of the last step (K u[n], or K(u[n] + β v_b) when β > 0, per element its
    /// pair's β).
    pub fn internal_force(&self) -> &[f64] {
        &self.f_int
    }

    /// Advance `state` from t[n] to t[n+1]: the forces at t[n], the prediction of u[n+1] with
    /// the constraints' corrections and the energy increments, the energy account, the shift.
    pub fn step(&mut self, model: &Model, loads: &Loads, state: &mut State, stage: Stage, constraints: Constraints<'_, '_>) -> Result<StepInfo, StepError> {
        let dynamic = stage == Stage::Dynamic;
        let (alpha, beta) = self.external_forces_of_step(model, loads, state, stage, constraints);
        let k = StepCoefficients { alpha, beta, dynamic, grouped: dynamic && !self.pairs.is_empty() };
        if k.grouped {
            self.pair_internal_forces_of_step(model, state, constraints);
        } else {
            self.internal_forces_of_step(model, state, beta, constraints);
        }
        let (sums, info) = self.update_into(model, state, k, constraints)?;
        if dynamic {
            add_step_energy(&mut state.energy, sums, &info);
        }
        if !sums[3].is_finite() {
            return Err(self.non_finite_error(model, state));
        }
        self.shift_into(state, k.stiffness());
        if dynamic && (state.step % self.energy_stride == 0) {
            self.check_energy(model, state)?;
        }
        Ok(info)
    }

    /// F[n] into `f_ext`: the loads (gravity scaled by the relaxation's ramp), then the
    /// constraints' external forces. Returns the stage's damping (α [1/s], β [s]).
    fn external_forces_of_step(&mut self, model: &Model, loads: &Loads, state: &State, stage: Stage, constraints: Constraints<'_, '_>) -> (f64, f64) {
        let dt = self.dt;
        let dynamic = stage == Stage::Dynamic;
        loads.external_force_into(model, state.t, true, dynamic, &mut self.f_ext);
        let (alpha, beta) = match stage {
            Stage::Dynamic => (model.alpha, model.beta),
            Stage::Relaxation(a, scale) => {
                if scale != 1.0 {
                    for_each_entry(&mut self.f_ext, |_, f| *f *= scale);
                }
                (a, 0.0)
            }
        };
        let ctx = StepContext { t_next: state.t + dt, dt, u_prev: &state.u_prev, u: &state.u };
        for c in constraints.iter_mut() {
            c.add_external_force_into(model, &ctx, dynamic, &mut self.f_ext);
        }
        (alpha, beta)
    }

    /// K u[n] into `f_int`, or with β > 0 K(u[n] + β v_b) into `f_int` and K u[n] into `ku`.
    fn internal_forces_of_step(&mut self, model: &Model, state: &State, beta: f64, constraints: Constraints<'_, '_>) {
        if beta > 0.0 {
            let c = beta / self.dt;
            stiffness_damped_displacement_into(&mut self.w, state, c);
            internal_forces_into(model, constraints, &self.w, &mut self.f_int);
            recover_ku_into(&mut self.ku, &self.f_int, &self.ku_prev, c);
        } else {
            internal_forces_into(model, constraints, &state.u, &mut self.f_int);
        }
    }

    /// With the pairs' β apart ([`Model::beta_grouped`]): per pair p, f_p = K_p(u[n] + β_p v_b)
    /// and K_p u[n] by the one-β recursion; `f_int` = Σ f_p, `ku` = Σ K_p u[n]. The elements are
    /// visited once in all (each pair's loop skips the other's), the nodal passes once per pair.
    fn pair_internal_forces_of_step(&mut self, model: &Model, state: &State, constraints: Constraints<'_, '_>) {
        for p in self.pairs.iter_mut() {
            let c = p.beta / self.dt;
            stiffness_damped_displacement_into(&mut self.w, state, c);
            pair_forces_into(model, constraints, p.rock, &self.w, &mut p.f);
            recover_ku_into(&mut p.ku, &p.f, &p.ku_prev, c);
        }
        let (a, b) = (&self.pairs[0], &self.pairs[1]);
        for_each_entry(&mut self.f_int, |i, f| *f = a.f[i] + b.f[i]);
        for_each_entry(&mut self.ku, |i, k| *k = a.ku[i] + b.ku[i]);
    }

    /// u[n+1] into `u_next`: the prediction, one block of nodes per task, the block nodes,
    /// then the constraints' corrections. Returns the energy increments W_ext, D_α, D_β and
    /// the finiteness probe ([`StepTerms::increments`]) and the corrections' information. With
    /// no constraint and no block node the increments are taken in the prediction's pass
    /// (u[n+1] is final there).
    fn update_into(&mut self, model: &Model, state: &mut State, k: StepCoefficients, constraints: Constraints<'_, '_>) -> Result<([f64; 4], StepInfo), StepError> {
        let held: &[u8] = match (&self.dynamic_held, k.dynamic) {
            (Some(h), true) => h,
            _ => &model.held,
        };
        let terms = StepTerms { model, u: &state.u, u_prev: &state.u_prev, f_ext: &self.f_ext, f_int: &self.f_int, ku: &self.ku, held, dt: self.dt, k };
        let fused = constraints.is_empty() && model.mass.blocks.is_empty();
        let parts: Vec<[f64; 4]> = map_blocks_mut(&mut self.u_next, |b, un| terms.predict_block_into(b, un, fused));
        terms.predict_block_nodes_into(&mut self.u_next);
        let mut info = StepInfo::default();
        if fused {
            return Ok((add_parts(&parts), info));
        }
        let ctx = StepContext { t_next: state.t + self.dt, dt: self.dt, u_prev: &state.u_prev, u: &state.u };
        for c in constraints.iter_mut() {
            let ci = c.correct(model, &mut state.contact, &ctx, &mut self.u_next)?;
            info.correction = std::mem::take(&mut info.correction).merged(ci);
        }
        let mut s = sum_blocks(self.u_next.len(), |r| terms.increments(r.clone(), &self.u_next[r]));
        if k.dynamic {
            terms.add_block_mass_damping(&self.u_next, &mut s[1]);
        }
        Ok((s, info))
    }

    /// The error for a non-finite u[n+1] (`u_next`), at its first non-finite entry's node.
    fn non_finite_error(&self, model: &Model, state: &State) -> StepError {
        let i = self.u_next.iter().position(|v| !v.is_finite()).unwrap_or(0);
        let node = i / 3;
        StepError::NonFinite {
            what: "displacement".into(),
            step: state.step,
            t: state.t,
            node: model.mesh.node_tags[node] as usize,
            x: model.mesh.nodes[node],
            cause: "the time step is too large for the stiffest element or contact, or a load/record holds a non-finite value".into(),
        }
    }

    /// The end of a step: K u[n] becomes K u[n−1] (with βK; per pair too); u_nm1 ← u[n−1],
    /// u_prev ← u[n], u ← u[n+1]; the step index and t advance.
    fn shift_into(&mut self, state: &mut State, stiffness: bool) {
        if stiffness {
            std::mem::swap(&mut self.ku, &mut self.ku_prev);
            for p in self.pairs.iter_mut() {
                std::mem::swap(&mut p.ku, &mut p.ku_prev);
            }
        }
        std::mem::swap(&mut self.u_nm1, &mut state.u_prev);
        std::mem::swap(&mut state.u_prev, &mut state.u);
        std::mem::swap(&mut state.u, &mut self.u_next);
        state.step += 1;
        state.t += self.dt;
    }

    /// Start the energy account of the dynamic stage from the current state (at rest).
    pub fn start_energy(&mut self, model: &Model, state: &mut State) {
        self.u_nm1.copy_from_slice(&state.u_prev);
        // K u into the scratch u_next (overwritten by the next step)
        model.internal_forces_into(&state.u, &mut self.u_next);
        if model.stiffness_damped() {
            self.ku_prev.copy_from_slice(&self.u_next);
        }
        for p in self.pairs.iter_mut() {
            model.internal_forces_of_pair_into(p.rock, false, &state.u, &mut p.ku_prev);
        }
        let se = 0.5 * state.u.iter().zip(&self.u_next).map(|(u, f)| u * f).sum::<f64>();
        state.energy = Energy { strain: se, initial: se, scale: se.abs(), ..Energy::default() };
    }

    /// Energy check after a step (state.u = u[n+1], state.u_prev = u[n]).
    ///
    /// Balance: the discrete energy E = ½ v[n+½]ᵀ M v[n+½] + ½ u[n+1]ᵀ K u[n] of central
    /// differences satisfies E − E0 = W_ext + W_contact − D_α exactly for a correct linear run
    /// (W increments Δu_c·F with Δu_c = (u[n+1] − u[n−1])/2), so any relative error above the
    /// tolerance is energy created by contact or a bug. Instability: E is indefinite beyond the
    /// stability limit, so growth is detected on the positive measure P = ½ v[n+½]ᵀMv[n+½] +
    /// ½ u[n]ᵀKu[n], which stays within a bounded factor of E for a stable run and grows without
    /// bound otherwise (limit: 20 × the energy scale).
    fn check_energy(&mut self, model: &Model, state: &mut State) -> Result<(), StepError> {
        let dt = self.dt;
        // K u[n]: the step's internal force when β = 0, else the recovered one (after the swap
        // at the end of the step it sits in ku_prev)
        let ku: &[f64] = if model.stiffness_damped() { &self.ku_prev } else { &self.f_int };
        let [ke, se_mixed, se] = sum_blocks(state.u.len(), |r| {
            let (mut ke, mut se_mixed, mut se) = (0.0, 0.0, 0.0);
            for i in r {
                let v = (state.u[i] - state.u_prev[i]) / dt;
                ke += 0.5 * model.mass.inertial[i / 3] * v * v;
                se_mixed += 0.5 * state.u[i] * ku[i];
                se += 0.5 * state.u_prev[i] * ku[i];
            }
            [ke, se_mixed, se]
        });
        // the added inertia's kinetic energy ½ vᵀ A v
        let ke = ke + model.mass.blocks.iter().map(|b| {
            let i0 = 3 * b.node as usize;
            let v = nalgebra::Vector3::from_fn(|c, _| (state.u[i0 + c] - state.u_prev[i0 + c]) / dt);
            0.5 * v.dot(&(b.added * v))
        }).sum::<f64>();
        let e = &mut state.energy;
        e.kinetic = ke;
        e.strain = se;
        e.scale = e.scale.max((ke + se).abs()).max(e.external_work.abs()).max(e.contact_work.abs()).max(e.initial.abs());
        let bal = ke + se_mixed + e.mass_damping + e.stiffness_damping - e.initial - e.external_work - e.contact_work;
        e.error = if e.scale > 0.0 { bal / e.scale } else { 0.0 };
        if e.error.abs() > e.max_error.abs() {
            e.max_error = e.error;
        }
        // contact forces only dissipate (friction, plastic closure) or store and return energy
        // (penalty springs): their cumulative work is never positive in a correct run
        let contact_creates = e.contact_work > self.energy_tolerance * e.scale;
        let reference = e.initial.abs() + e.external_work.abs() + e.contact_work.abs() + e.mass_damping.abs() + e.stiffness_damping.abs();
        let growth = reference > 0.0 && ke + se > 20.0 * reference;
        if (e.error > self.energy_tolerance || growth || contact_creates) && e.scale > 1e-300 {
            let (node, _) = (0..model.n_nodes())
                .map(|n| {
                    let v: f64 = (0..3).map(|c| (state.u[3 * n + c] - state.u_prev[3 * n + c]).powi(2)).sum();
                    (n, v)
                })
                .fold((0, -1.0), |a, b| if b.1 > a.1 { b } else { a });
            return Err(StepError::EnergyGrowth {
                step: state.step,
                t: state.t,
                error: if growth {
                    (ke + se) / reference
                } else if contact_creates {
                    e.contact_work / e.scale
                } else {
                    e.error
                },
                limit: if growth { 20.0 } else { self.energy_tolerance },
                node: model.mesh.node_tags[node] as usize,
                x: model.mesh.nodes[node],
                cause: if growth {
                    "instability: the time step is above the limit of the stiffest element, contact or penalty spring".into()
                } else if contact_creates {
                    "contact forces did positive work (energy created at the joints): with penalty contact, lower `time.courant` (e.g. 0.5) or the penalty stiffness".into()
                } else {
                    "contact forces creating energy (check the joint law, penalty stiffness and time step)".into()
                },
            });
        }
        Ok(())
    }
}

/// The damping of a step's stage (α [1/s]: the relaxation's on every node, in the dynamic stage
/// each node's [`Model::node_alpha`]; β [s]: the one β, or with `grouped` each pair's,
/// [`PairForces`]) and whether it is the dynamic stage.
#[derive(Clone, Copy, Debug)]
struct StepCoefficients {
    alpha: f64,
    beta: f64,
    dynamic: bool,
    grouped: bool,
}

impl StepCoefficients {
    /// Whether the step carries βK (`f_int` − `ku` is its force).
    fn stiffness(&self) -> bool {
        self.beta > 0.0 || self.grouped
    }
}

/// What the update of one step reads: u[n], u[n−1], the forces at t[n] (K u[n] in `ku` when
/// β > 0), the held components of the stage.
struct StepTerms<'a> {
    model: &'a Model,
    u: &'a [f64],
    u_prev: &'a [f64],
    f_ext: &'a [f64],
    f_int: &'a [f64],
    ku: &'a [f64],
    held: &'a [u8],
    dt: f64,
    k: StepCoefficients,
}

impl StepTerms<'_> {
    /// Energy increments over the step, Δu_c = (u[n+1] − u[n−1]) / 2: W_ext, D_α, D_β, and
    /// Σ u[n+1]·0 (non-finite when some u[n+1] is), over the entries `r`; `u_next` holds the
    /// entries from r.start on.
    fn increments(&self, r: std::ops::Range<usize>, u_next: &[f64]) -> [f64; 4] {
        let (dt, stiffness) = (self.dt, self.k.stiffness());
        let (mut wext, mut damp, mut sdamp, mut finite) = (0.0, 0.0, 0.0, 0.0);
        let first = r.start;
        for i in r {
            let un = u_next[i - first];
            finite += un * 0.0;
            if self.k.dynamic {
                let du = 0.5 * (un - self.u_prev[i]);
                wext += du * self.f_ext[i];
                if stiffness {
                    sdamp += du * (self.f_int[i] - self.ku[i]);
                }
                let alpha = self.model.node_alpha[i / 3];
                if alpha > 0.0 {
                    let vb = (self.u[i] - self.u_prev[i]) / dt;
                    damp += du * alpha * self.model.mass.inertial[i / 3] * vb;
                }
            }
        }
        [wext, damp, sdamp, finite]
    }

    /// u[n+1] = 2u[n] − u[n−1] + dt² (M⁻¹ (F − K u) − α v_b) on block `b` of the nodes
    /// ([`NODE_BLOCK`]; `un` its entries), 0 on held components; with `fused` the block's
    /// energy increments, else zeros.
    fn predict_block_into(&self, b: usize, un: &mut [f64], fused: bool) -> [f64; 4] {
        let (dt, model) = (self.dt, self.model);
        let dt2 = dt * dt;
        let first = b * NODE_BLOCK;
        for (k, unode) in un.chunks_exact_mut(3).enumerate() {
            let node = first + k;
            let m = model.mass.inertial[node];
            let fx = self.held[node];
            for c in 0..3 {
                let i = 3 * node + c;
                if fx & (1 << c) != 0 {
                    unode[c] = 0.0;
                    continue;
                }
                let vb = (self.u[i] - self.u_prev[i]) / dt;
                let an = if self.k.dynamic { model.node_alpha[node] } else { self.k.alpha };
                let a = (self.f_ext[i] - self.f_int[i]) / m - an * vb;
                unode[c] = 2.0 * self.u[i] - self.u_prev[i] + dt2 * a;
            }
        }
        if fused { self.increments(3 * first..3 * first + un.len(), un) } else { [0.0; 4] }
    }

    /// The block nodes again: a = M⁻¹ (F − K u) − α v_b with their full inverse (on free
    /// components).
    fn predict_block_nodes_into(&self, u_next: &mut [f64]) {
        let (dt, model) = (self.dt, self.model);
        let dt2 = dt * dt;
        for b in &model.mass.blocks {
            let node = b.node as usize;
            let i0 = 3 * node;
            let f = nalgebra::Vector3::from_fn(|c, _| self.f_ext[i0 + c] - self.f_int[i0 + c]);
            let a = b.inverse * f;
            let an = if self.k.dynamic { model.node_alpha[node] } else { self.k.alpha };
            for c in 0..3 {
                let i = i0 + c;
                u_next[i] = if self.held[node] & (1 << c) != 0 {
                    0.0
                } else {
                    let vb = (self.u[i] - self.u_prev[i]) / dt;
                    2.0 * self.u[i] - self.u_prev[i] + dt2 * (a[c] - an * vb)
                };
            }
        }
    }

    /// Mass damping of the added inertia A of the damped block nodes, Δu_c · α A v_b (α the
    /// node's), added to `damp` node by node.
    fn add_block_mass_damping(&self, u_next: &[f64], damp: &mut f64) {
        let dt = self.dt;
        for b in self.model.mass.blocks.iter().filter(|b| self.model.node_alpha[b.node as usize] > 0.0) {
            let i0 = 3 * b.node as usize;
            let du = nalgebra::Vector3::from_fn(|c, _| 0.5 * (u_next[i0 + c] - self.u_prev[i0 + c]));
            let vb = nalgebra::Vector3::from_fn(|c, _| (self.u[i0 + c] - self.u_prev[i0 + c]) / dt);
            *damp += du.dot(&(b.added * vb)) * self.model.node_alpha[b.node as usize];
        }
    }
}

/// Adds a dynamic step's energy increments (W_ext, D_α, D_β of [`StepTerms::increments`]) and
/// its contact work to the account.
fn add_step_energy(e: &mut Energy, sums: [f64; 4], info: &StepInfo) {
    e.external_work += sums[0];
    e.mass_damping += sums[1];
    e.stiffness_damping += sums[2];
    e.contact_work += info.correction.work;
}

/// Outcome of gravity equilibration.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct EquilibriumInfo {
    pub steps: usize,
    /// ‖M a‖ / ‖F_gravity‖ over free components at the end.
    pub residual: f64,
    pub converged: bool,
}

/// Steps over which relaxation ramps gravity from 0 to its full value. Default 1000: a sudden
/// load overshoots dynamically (up to twice the static response) and would make joints slip
/// irreversibly before the static state is reached; a ramp over several lowest periods of
/// typical models keeps the loading quasi-static.
pub const RELAXATION_RAMP_STEPS: usize = 1000;

/// Dynamic relaxation with adaptive viscous damping (Underwood): undamped mass, damping
/// C = αM with α = 2 ω_min, ω_min² estimated every step by the Rayleigh quotient
/// uᵀKu / uᵀMu of the current displacement (dominated by the lowest mode during relaxation),
/// so the lowest mode is critically damped. Gravity is ramped in over
/// [`RELAXATION_RAMP_STEPS`] steps. Stops when the out-of-balance force ‖M a‖ (gravity,
/// elastic and contact forces together) falls below `tol` × ‖F_gravity‖ after the ramp.
pub fn relax_gravity(
    model: &Model,
    loads: &Loads,
    solver: &mut ExplicitSolver,
    state: &mut State,
    constraints: Constraints<'_, '_>,
    tol: f64,
    max_steps: usize,
) -> Result<EquilibriumInfo, StepError> {
    let mut fg = vec![0.0; 3 * model.n_nodes()];
    loads.external_force_into(model, 0.0, true, false, &mut fg);
    let norm_f: f64 = fg.iter().enumerate().filter(|(i, _)| model.is_free(i / 3, i % 3)).map(|(_, f)| f * f).sum::<f64>().sqrt();
    if norm_f == 0.0 {
        return Ok(EquilibriumInfo { steps: 0, residual: 0.0, converged: true });
    }
    let dt = solver.dt;
    let mut residual = f64::INFINITY;
    let mut alpha = 0.0;
    for k in 0..max_steps {
        crate::interrupt::check_every(k, "the static state (gravity relaxation)")?;
        let scale = ((k + 1) as f64 / RELAXATION_RAMP_STEPS as f64).min(1.0);
        solver.step(model, loads, state, Stage::Relaxation(alpha, scale), &mut *constraints)?;
        // after the step: u_nm1 = u[n−1], u_prev = u[n], u = u[n+1]; f_int = K u[n].
        // Out-of-balance force F − K u[n] + R[n] = M a[n] + α M v_b (contact forces included).
        let (r2, ukb, umu) = relaxation_balance(model, solver, state, alpha, scale);
        residual = r2.max(0.0).sqrt() / norm_f;
        alpha = relaxation_damping(ukb, umu, dt, alpha);
        if residual < tol && k + 1 >= RELAXATION_RAMP_STEPS {
            state.u_prev.copy_from_slice(&state.u);
            return Ok(EquilibriumInfo { steps: k + 1, residual, converged: true });
        }
    }
    state.u_prev.copy_from_slice(&state.u);
    Ok(EquilibriumInfo { steps: max_steps, residual, converged: false })
}

/// The out-of-balance measures of a relaxation step ([`relax_gravity`]): after the step (u_nm1 = u[n−1], u_prev = u[n], u = u[n+1],
/// f_int = K u[n]) the squared out-of-balance force ‖M (a[n] + α v_b) / scale‖² over the free
/// components (block nodes with their full inertia; contact forces included), and the Rayleigh
/// quotient's parts u·K u and u·M u.
pub(crate) fn relaxation_balance(model: &Model, solver: &ExplicitSolver, state: &State, alpha: f64, scale: f64) -> (f64, f64, f64) {
    let dt = solver.dt;
    let mut r2 = 0.0;
    let (mut ukb, mut umu) = (0.0, 0.0);
    let f_int = solver.internal_force();
    for i in 0..state.u.len() {
        if model.is_free(i / 3, i % 3) {
            let m = model.mass.inertial[i / 3];
            let a = (state.u[i] - 2.0 * state.u_prev[i] + solver.u_nm1[i]) / (dt * dt);
            let vb = (state.u_prev[i] - solver.u_nm1[i]) / dt;
            let r = m * (a + alpha * vb) / scale;
            r2 += r * r;
            ukb += state.u_prev[i] * f_int[i];
            umu += m * state.u_prev[i] * state.u_prev[i];
        }
    }
    // block nodes: the out-of-balance force is M (a + α v_b) with the full inertia
    for b in &model.mass.blocks {
        let i0 = 3 * b.node as usize;
        let mut av = nalgebra::Vector3::zeros();
        for c in 0..3 {
            let i = i0 + c;
            if model.is_free(i / 3, c) {
                let a = (state.u[i] - 2.0 * state.u_prev[i] + solver.u_nm1[i]) / (dt * dt);
                let vb = (state.u_prev[i] - solver.u_nm1[i]) / dt;
                let r = model.mass.inertial[i / 3] * (a + alpha * vb) / scale;
                r2 -= r * r;
                av[c] = a + alpha * vb;
            }
        }
        let r = b.full * av / scale;
        r2 += (0..3).filter(|&c| model.is_free(b.node as usize, c)).map(|c| r[c] * r[c]).sum::<f64>();
    }
    (r2, ukb, umu)
}

/// The relaxation's damping for the next step: α = 2 ω_min from the Rayleigh quotient, kept
/// below the stability bound α dt < 1 (unchanged while the quotient is not positive).
pub(crate) fn relaxation_damping(ukb: f64, umu: f64, dt: f64, alpha: f64) -> f64 {
    if umu > 0.0 && ukb > 0.0 { (2.0 * (ukb / umu).sqrt()).min(0.5 / dt) } else { alpha }
}
