//! A static load increment on a structure whose joints are active (Mohr–Coulomb contact):
//! the stage of a construction sequence that brings the reservoir onto the grouted dam
//! (`construction`, stage c).
//!
//! Method: a penalty contact law solved by Newton's method with direct solves, as implicit
//! static codes do it (e.g. Abaqus/Standard's penalty contact with its contact-state
//! iterations). Each pair of a joint that is not tied carries a force q(w) that is a continuous,
//! piecewise-linear function of its relative motion w; the out-of-balance force of the model
//! with these forces is driven to zero by u ← u + K_T⁻¹ R(u), with K_T the stiffness plus each
//! pair's tangent, on the model with the tied joints eliminated (`bonded`). Each direction
//! K_T⁻¹ R is solved by GMRES preconditioned by the sparse Cholesky factorisation of K_T
//! without the friction coupling (symmetric positive definite), analysed once and factorised
//! again only when GMRES needs many products ([`TangentSolver`]), to an Eisenstat–Walker
//! forcing term ([`forcing_term`]); a sparse LU of the assembled K_T is
//! the fallback when GMRES does not converge. The LU on every iteration, as first written, took
//! 1243 s and 11 GB on the fine dam mesh (faer's LU orders the columns by COLAMD and bounds
//! the fill by the pattern of AᵀA: docs/performance.md, "Static state").
//!
//! Conventions (written once, here): w = Σ_I N_I Δu_I − Δu_s is the master point's motion
//! relative to the slave node over the increment, with N_I the weights of the pair's master
//! point (`bonded::master_point` for node-to-segment joints, the nearest master node O for
//! node-to-node, the mortar weights c_k = M_jk / D_jj of the initial configuration for dual
//! mortar, whose pair then has the area D_jj); n is the slave normal (towards the master), so the gap is g = n · w (the
//! increment starts from a grouted joint: gap 0 with no force), w_t = w − g n, and the normal
//! force is r_n = −k g (compressive positive). q is the force on the slave node (−N_I q on the
//! masters). Forces in N, displacements in m.
//! - **open** (r_n < −σ_t A: tension beyond the tensile strength, 0 for the dam): q = 0;
//! - **stick** (k_t |w_t| ≤ L, L = `JointLaw::shear_limit`(r_n), k_t = [`STICK_TANGENTIAL`] k):
//!   q = k g n + k_t w_t, tangent k n nᵀ + k_t (I − n nᵀ);
//! - **slip**: q = k g n + L w_t/|w_t|, tangent k n nᵀ + (L/|w_t|)(I − n nᵀ − t̂ t̂ᵀ) − L' k t̂ nᵀ
//!   (L' = ∂L/∂r_n: μ, or tan(φ + i) below an asperity envelope's knee),
//!   t̂ = w_t/|w_t|. The last term (the limit grows with the normal force) makes K_T
//!   unsymmetric (hence GMRES, not CG); without it Newton diverged on the coarse dam
//!   (it is of the penalty's size).
//!
//! This friction law is holonomic (deformation theory): the increment is one proportional
//! load, applied at once, so the slip direction is that of the total relative tangential
//! motion, as in a one-increment implicit step.
//!
//! Penalty: k = [`PENALTY_FACTOR`] × the mean diagonal stiffness of the slave node's dofs. The
//! springs' compliance is then 1/1000 of the node's own, so the joint moves by that fraction
//! more than a rigid contact would: the displacements and stresses carry an error of that order,
//! far below the mesh's discretisation error (measured on the coarse dam: docs/dam.md).
//!
//! The residual is ‖R‖ / ‖F‖ on the free unknowns with the contact forces included (converged
//! below [`TOLERANCE`]); the report adds the largest penetration, the pairs in each state and
//! the pairs held closed ([`CHATTER_CHANGES`]).

use crate::statics::bonding::{master_point, Bonding, MasterHit};
use crate::contact::joint::{ContactJoint, Method};
use crate::contact::force::ContactSolver;
use crate::contact::law::{PairHistory, PairState};
use crate::contact::ContactState;
use crate::error::{Error, ModelError};
use crate::linalg::{add_entries, cpu_seconds, gmres_into, lu_solve_in_place, run_par, stiffness, Csc, FactorPrecision, FillOrdering, GmresOptions, LinalgError, SparseCholesky};
use crate::problem::Problem;
use nalgebra::{Matrix3, Vector3};

/// Penalty stiffness of a pair, as a multiple of the mean diagonal stiffness of its slave
/// node (dimensionless): 1000. Why: stiff enough that the joint's compliance is 1e-3 of the
/// mesh's next to it (the error it adds), soft enough that the condition number stays within
/// 1e3 of the model's (the solves keep a residual near 1e-11).
pub const PENALTY_FACTOR: f64 = 1e3;

/// Converged when ‖R‖ / ‖F‖ (the out-of-balance force with the contact forces, relative to
/// the load) is below this (dimensionless): 1e-8. Why: six orders below what the stresses
/// need, two above the solves' round-off.
pub const TOLERANCE: f64 = 1e-8;

/// Largest number of Newton iterations: 200. Why: on the coarse dam the iteration converges
/// in a few tens (docs/dam.md); more means the states cycle, reported as a failure.
pub const MAX_ITERATIONS: usize = 200;

/// Halvings of a Newton step in the line search: 12 (the smallest step is 2.4e-4 of the
/// Newton step; it is taken even if it does not lower the residual, so the iteration cannot
/// stall at a kink).
pub const LINE_SEARCH_HALVINGS: usize = 12;

/// A pair that has opened or closed this many times is held closed (it may then carry a
/// small tension): 4. Why: a pair at the border of the two states (closed with a vanishing
/// tensile force, open with a vanishing gap; on the coarse dam a few pairs at the joints'
/// edges) would otherwise flip between them every iteration. Their largest violation is
/// reported ([`StaticContactInfo::condition_violation`]).
pub const CHATTER_CHANGES: usize = 4;

/// How the increment was solved.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct StaticContactInfo {
    /// Newton iterations (one direct solve each).
    pub iterations: usize,
    /// Whether ‖R‖/‖F‖ fell below [`TOLERANCE`].
    pub converged: bool,
    /// ‖R‖ / ‖F‖ at the end (contact forces included).
    pub residual: f64,
    /// Pairs stick, slip, open at the end; pairs left out (a node-to-segment slave node with
    /// no master face on the initial configuration, even within half a face).
    pub stick: usize,
    pub slip: usize,
    pub open: usize,
    pub left_out: usize,
    /// Pairs not formed because their slave node is the slave of a tied joint
    /// (`contact::joint::unformed_pairs`).
    pub on_tied: usize,
    /// Pairs held closed because they kept opening and closing.
    pub held: usize,
    /// Largest penetration −g of a closed pair [m] and the largest |Δu| of the increment [m].
    pub max_penetration: f64,
    pub max_displacement: f64,
    /// Largest normal force of a pair [N].
    pub max_normal_force: f64,
    /// Largest tension of a closed pair beyond its tensile strength (only held pairs can have
    /// one), relative to the largest normal force.
    pub condition_violation: f64,
    /// How the Newton directions were solved (GMRES on the preconditioner's factorisations).
    pub solver: DirectionStats,
    /// Wall time of the whole increment and of its setup (stiffness, ties, pairs) [s].
    pub seconds: f64,
    pub setup_seconds: f64,
}

impl StaticContactInfo {
    /// One line.
    pub fn line(&self) -> String {
        format!(
            "{} Newton iterations ({} factorisations in {:.1} s ({:.1} s CPU on {} thread(s)), {} GMRES products in {:.1} s ({:.1} s CPU; preconditioner {:.1} s, operator {:.1} s){}; {:.1} s in all, setup {:.1} s; factor {:.0} MB{}, {} {:.1} s, {:.2e} flops, a factorisation worth {:.0} products{}; directions {}), residual {:.1e}{}, pairs stick {} / slip {} / open {}{}{}, largest penetration {:.2e} m ({:.1e} of the largest displacement){}",
            self.iterations,
            self.solver.factorisations,
            self.solver.factor_seconds,
            self.solver.factor_cpu_seconds,
            self.solver.threads,
            self.solver.krylov_products,
            self.solver.krylov_seconds,
            self.solver.krylov_cpu_seconds,
            self.solver.precondition_seconds,
            self.solver.operator_seconds,
            if self.solver.lu_fallbacks > 0 { format!(", {} LU solves", self.solver.lu_fallbacks) } else { String::new() },
            self.seconds,
            self.setup_seconds,
            self.solver.factor_bytes as f64 * 1e-6,
            if self.solver.single { " in f32" } else if self.solver.single_fallback { " in f64 (the f32 factorisation lost a pivot)" } else { "" },
            if self.solver.nested_dissection { "nested dissection" } else { "AMD" },
            self.solver.analysis_seconds,
            self.solver.factor_flops,
            products_per_factorisation(self.solver.factor_flops, self.solver.product_flops),
            match self.solver.split {
                Some([a, b, top]) => format!("; solves split {:.0} % / {:.0} % / top {:.0} %", 100.0 * a as f64 / (a + b + top).max(1) as f64, 100.0 * b as f64 / (a + b + top).max(1) as f64, 100.0 * top as f64 / (a + b + top).max(1) as f64),
                None => String::new(),
            },
            self.solver.trace.trim(),
            self.residual,
            if self.converged { "" } else { " (NOT converged)" },
            self.stick,
            self.slip,
            self.open,
            if self.left_out > 0 { format!(" / left out {}", self.left_out) } else { String::new() },
            if self.on_tied > 0 { format!(" / on tied nodes {}", self.on_tied) } else { String::new() },
            self.max_penetration,
            if self.max_displacement > 0.0 { self.max_penetration / self.max_displacement } else { 0.0 },
            if self.held > 0 { format!(", {} pairs held closed (largest tension {:.1e} of the largest normal force)", self.held, self.condition_violation) } else { String::new() }
        )
    }
}

struct Pair {
    joint: usize,
    index: usize,
    /// w_c as sparse vectors over the reduced unknowns, c = x, y, z.
    w: [Vec<(usize, f64)>; 3],
    n: Vector3<f64>,
    k: f64,
    area: f64,
    /// Closed at the last evaluation, and how many times it opened or closed.
    closed: bool,
    changes: usize,
}

/// w (3-vector) of a pair at the reduced solution `uh`.
fn relative_motion(p: &Pair, uh: &[f64]) -> Vector3<f64> {
    Vector3::from_fn(|c, _| p.w[c].iter().map(|&(r, v)| v * uh[r]).sum())
}

/// A pair's tangent ∂q/∂w split as `spd + coupling`: `spd` symmetric positive semi-definite
/// (k n nᵀ + k_t (I − n nᵀ) stick; k n nᵀ + (L/|w_t|)(I − n nᵀ − t̂ t̂ᵀ) slip; 0 open), `coupling` the friction
/// limit's growth with the normal force (−L' k t̂ nᵀ while slipping, L' = ∂L/∂r_n, else 0), and
/// the state.
#[derive(Clone, Copy, Debug)]
struct PairTangent {
    state: PairState,
    spd: Matrix3<f64>,
    coupling: Matrix3<f64>,
}

/// The law of the module header at w: state, force q on the slave, tangent ∂q/∂w.
fn pair_force(p: &Pair, w: &Vector3<f64>, law: &crate::contact::law::JointLaw, hold_closed: bool) -> (PairState, Vector3<f64>, PairTangent) {
    let history = PairHistory::default();
    let g = p.n.dot(w);
    let r_n = -p.k * g;
    if r_n < -law.tensile_strength * p.area && !hold_closed {
        return (PairState::Open, Vector3::zeros(), PairTangent { state: PairState::Open, spd: Matrix3::zeros(), coupling: Matrix3::zeros() });
    }
    let wt = w - p.n * g;
    let (limit, slope) = law.shear_limit_with_slope(r_n, &history, p.area);
    let nn = p.n * p.n.transpose();
    let kt = STICK_TANGENTIAL * p.k;
    if kt * wt.norm() <= limit {
        (PairState::Stick, p.n * (p.k * g) + wt * kt, PairTangent { state: PairState::Stick, spd: nn * p.k + (Matrix3::identity() - nn) * kt, coupling: Matrix3::zeros() })
    } else {
        let t = wt / wt.norm();
        let ks = limit / wt.norm();
        // ∂L/∂w = −(∂L/∂r_n) k nᵀ while the limit is above its floor 0: μ on the Coulomb line,
        // tan(φ + i) on an asperity envelope's first branch, 0 at the floor
        let coupling = if limit > 0.0 { t * p.n.transpose() * (-slope * p.k) } else { Matrix3::zeros() };
        let spd = nn * p.k + (Matrix3::identity() - nn - t * t.transpose()) * ks;
        (PairState::Slip, p.n * (p.k * g) + t * limit, PairTangent { state: PairState::Slip, spd, coupling })
    }
}

/// The stick spring's tangential stiffness as a fraction of the penalty k (dimensionless): 0.1.
/// Why: like k, a regularisation of sticking, not a joint property (the earthquake's contact
/// is the dynamic contact force, not springs); with k_t = k the stiff stick turns the holonomic
/// slip direction t̂ = w_t/|w_t| at every Newton step and node-to-node joints, with 3× NTS's
/// slipping pairs, crawled through 5× NTS's iterations (the dam's h 2.5 m NTN static state 37
/// min). 0.1 k cuts NTN's iterations about 3× (coarse / default / fine 116 / 107 / 139 → 36 /
/// 43 / 48) while the stick's tangential compliance stays 1 % of the mesh's next to it
/// ([`PENALTY_FACTOR`]); measured: the default dam's static table moves by at most 0.4 %, the
/// default 3× runs' peaks (opening, net slip, path, crest, face stresses) by at most 3e-5
/// (docs/performance.md, "NTN's static state"). 0.01 k was faster still (24 / 27) with a
/// 10 % compliance. Penalty codes commonly set k_s below k_n (3DEC: k_n/2 – k_n/10).
pub const STICK_TANGENTIAL: f64 = 0.1;

/// Smallest relative tolerance of a Newton direction's GMRES solve, ‖K_T d − R‖ ≤ η ‖R‖
/// (dimensionless): 1e-9. Why: below it the solve is at the factorisation's round-off; the
/// forcing term η of each iteration ([`forcing_term`]) is never asked below this.
pub const DIRECTION_TOLERANCE: f64 = 1e-9;

/// Largest forcing term η of an inexact Newton step (dimensionless): 1e-2. Why: the contact law
/// is only piecewise smooth and far from the solution the line search cuts most steps, so a
/// direction 1 % off finds the pairs' states as well as an exact one (on the coarse dam: 12
/// Newton iterations against 11 with 1e-9, half the GMRES products); looser ones
/// (Eisenstat and Walker allow 0.9) were not tried.
pub const FORCING_MAX: f64 = 1e-2;

/// The forcing term of the Newton iteration at the relative residual `res` after one of
/// `res_prev` (`None` at the first) with the forcing term `eta_prev`: Eisenstat and Walker's
/// choice 2 (SIAM J. Sci. Comput. 17, 1996), η = γ (res / res_prev)², γ = 0.9, with their
/// safeguard max(η, γ η_prev²) when γ η_prev² > 0.1, capped by [`FORCING_MAX`]; and never
/// tighter than needed to reach [`TOLERANCE`] in this step (0.1 × TOLERANCE / res, so the
/// linear residual left is a tenth of the one asked of Newton) nor than
/// [`DIRECTION_TOLERANCE`]. The iteration's convergence test on the true residual is unchanged.
fn forcing_term(res: f64, res_prev: Option<f64>, eta_prev: f64) -> f64 {
    const GAMMA: f64 = 0.9;
    let ew = match res_prev {
        None => FORCING_MAX,
        Some(rp) if rp > 0.0 => {
            let e = GAMMA * (res / rp).powi(2);
            let safeguard = GAMMA * eta_prev * eta_prev;
            if safeguard > 0.1 { e.max(safeguard) } else { e }
        }
        Some(_) => DIRECTION_TOLERANCE,
    };
    let enough = if res > 0.0 { 0.1 * TOLERANCE / res } else { 1.0 };
    ew.min(FORCING_MAX).max(enough.min(FORCING_MAX)).max(DIRECTION_TOLERANCE)
}

/// How the Newton directions were solved: factorisations of the preconditioner, GMRES
/// products, direct LU solves (the fallback), and the seconds each took.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct DirectionStats {
    pub factorisations: usize,
    pub krylov_products: usize,
    pub lu_fallbacks: usize,
    /// Entries of the preconditioner's Cholesky factor, and their bytes (8 each in f64, 4 in
    /// f32); whether the factor is f32 ([`SINGLE_FROM`]), and whether an f32 factorisation
    /// lost a pivot so that f64 was used from then on.
    pub factor_entries: usize,
    pub factor_bytes: usize,
    pub single: bool,
    pub single_fallback: bool,
    pub factor_seconds: f64,
    pub krylov_seconds: f64,
    /// Flops of one numeric factorisation and of one GMRES product (the refactorisation rule's
    /// estimates, [`products_per_factorisation`]).
    pub factor_flops: f64,
    pub product_flops: f64,
    /// Seconds of the symbolic analysis (ordering included) and whether it was nested
    /// dissection (else AMD).
    pub analysis_seconds: f64,
    pub nested_dissection: bool,
    /// CPU seconds (all threads) of the factorisations and of the GMRES solves, and the wall
    /// seconds of the GMRES solves spent in the preconditioner's triangular solves and in the
    /// operator's products (the rest: Gram–Schmidt and GMRES's bookkeeping).
    pub factor_cpu_seconds: f64,
    pub krylov_cpu_seconds: f64,
    pub precondition_seconds: f64,
    pub operator_seconds: f64,
    /// Threads of the numeric factorisations (`linalg::run_par`).
    pub threads: usize,
    /// The preconditioner's solves split over its elimination tree
    /// (`SparseCholesky::split_solves`): factor entries of the two halves solved at once and
    /// of the part above them.
    pub split: Option<[usize; 3]>,
    /// Per Newton direction (separated by spaces) its GMRES products, an `F` before the count
    /// of an attempt on a fresh factorisation, a `>` after an attempt on a stale one that did
    /// not converge within its cap, a `!` after one given up before its cap because its
    /// residual could not reach the forcing term by then ([`GIVE_UP_WINDOW`]) (e.g.
    /// "F2 5 35>F3 9!F2 14"), so the rule's choices can be read.
    pub trace: String,
    /// Attempts on a stale factor given up before their cap ([`GIVE_UP_WINDOW`]).
    pub given_up: usize,
}

/// The Newton direction d = K_T⁻¹ R with K_T = K̂ + Σ_p B_pᵀ (S_p + C_p) B_p (the pair tangents
/// of [`PairTangent`], applied pair by pair, never assembled): GMRES
/// (`linalg::krylov::gmres_into`) preconditioned by the sparse Cholesky factorisation of the
/// symmetric positive definite P = K̂ + Σ_p B_pᵀ S_p B_p. P's pattern (K̂ and every pair's block,
/// open or not) is analysed once ([`STATIC_ORDERING`]); P is factorised again only when the
/// GMRES products since its last factorisation cost as much as a factorisation
/// ([`products_per_factorisation`]), not on every change of a pair's state: K_T − P is then the friction couplings C_p (one rank-one
/// term per slipping pair) and the changed blocks of the pairs that opened, slipped or moved
/// since the factorisation, a correction of low rank that GMRES absorbs in a few products
/// (on the fine dam a numeric factorisation costs as much as some hundred products). P is also
/// factorised first when the pairs that changed state since its factorisation are expected to
/// take the rest of its worth ([`PRODUCTS_PER_CHANGED_PAIR`]). An
/// attempt on a stale factor is capped at that many products and given up earlier when its
/// residual's contraction cannot reach the forcing term by the cap ([`give_up_window`]); the
/// direction is then solved on a fresh factorisation. From [`SINGLE_FROM`] unknowns the factor
/// is f32 (GMRES stays f64 on the true operator).
/// GMRES starts each direction from 0: the Newton directions of successive iterations are not
/// close (the residual changes by orders of magnitude), so the last one is no better a start.
struct TangentSolver {
    p: Csc,
    /// Per entry of K̂, its position in `p.val`.
    k0_pos: Vec<usize>,
    /// Per pair-block entry (pair, c, d, entry a of w_c, entry b of w_d, in that order), its
    /// position in `p.val`.
    pair_pos: Vec<usize>,
    chol: Option<SparseCholesky>,
    /// The fill-reducing ordering of P's analysis, and the precision of its factor
    /// ([`SINGLE_FROM`]).
    ordering: FillOrdering,
    precision: FactorPrecision,
    /// GMRES products since the last factorisation, and what one factorisation is worth in
    /// products ([`products_per_factorisation`]).
    products_since: usize,
    budget: f64,
    stats: DirectionStats,
    y: Vec<f64>,
    /// Each pair's state at the last factorisation ([`PRODUCTS_PER_CHANGED_PAIR`]).
    states_at_factor: Vec<PairState>,
}

/// Unknowns from which the preconditioner P is factorised in f32 (its solves rounding the
/// vector to f32; GMRES, the operator and the Newton residual stay f64; if an f32
/// factorisation loses a pivot, f64 from then on, said in the stage's note): 20 000. Why:
/// measured on the dam (docs/performance.md §7b), the f32 factor halves P's memory and cut the
/// CPU of a factorisation by a third (fine: 2.0 s against 3.0 s) and of a GMRES product by 38 %
/// (0.068 s against 0.110 s), with the products per direction about the same and the static
/// table equal to the f64 one to 2e-9 (the Newton tolerance is 1e-8); below 20 000 unknowns
/// (the coarse dam, the tests' models) a factorisation takes a fraction of a second, and f64
/// keeps their static states as they were.
pub const SINGLE_FROM: usize = 20_000;

/// How many times faster, in flops per second, a numeric factorisation runs than a GMRES
/// product (dimensionless): 7. Why: the factorisation's supernodes are dense blocks
/// (matrix–matrix kernels, compute-bound), a product is two triangular solves with the factor
/// and a sparse product (each entry read once: memory-bound). Measured on one core of this
/// machine (4 December, nested dissection; docs/performance.md §7b): seconds per factorisation
/// / seconds per product against [`SparseCholesky::factor_flops`] / [`product_flops`] gave 7.9
/// on the coarse dam mesh, 7.3 on the default, 7.0 on the fine.
pub const FACTOR_SPEEDUP: f64 = 7.0;

/// The least number of products over which a GMRES attempt on a stale preconditioner
/// measures its residual's contraction, to give up before its cap when that contraction kept
/// up to the cap would not reach the forcing term (`linalg::krylov::cannot_converge`; the
/// preconditioner is then factorised at the current states and the direction solved again, as
/// after an attempt that ran to its cap): 5 products. Why: a stale attempt's residual drops by
/// a first product, then creeps on a plateau for a few products before it falls or stalls
/// (docs/performance.md §7b); fewer than 5 products cannot tell the two apart (with 2 or 3 the
/// coarse dam gave up attempts that would have converged: one factorisation more).
pub const GIVE_UP_WINDOW: usize = 5;

/// The window of a stale attempt with the cap `cap` (products): [`GIVE_UP_WINDOW`], or a
/// quarter of the cap if more, so that the contraction is never extrapolated over more than
/// three windows when first judged. Why: on the fine dam (cap 35) the plateaus are longer and a
/// window of 5 extrapolated over 30 products gave up attempts that converged in 20–30: 16
/// factorisations and 30 Newton iterations against 14 and 22 with 8 (docs/performance.md §7b).
fn give_up_window(cap: usize) -> usize {
    GIVE_UP_WINDOW.max(cap / 4)
}

/// GMRES products an attempt on a stale preconditioner is expected to take per pair whose
/// state (open / stick / slip) changed since the factorisation (dimensionless): 2. The
/// preconditioner is factorised again before a direction when the products since its last
/// factorisation plus this expectation reach a factorisation's worth
/// ([`products_per_factorisation`]), instead of trying the stale factor and giving the
/// attempt up. Why: each such pair changes its block of P, a correction of rank ≤ 3, and GMRES
/// needs about one product per independent direction of the correction (at most rank + 1);
/// measured on the NTN dam's stage c, an attempt on a stale factor that converged took at most
/// about 1 product per changed pair plus 10 on the h 2.5 m mesh and 8–24 products for 1–17
/// changed pairs on the fine mesh, and the attempts given up were mostly those the
/// expectation puts past the budget (the first iterations change 140–6 000 pairs). 2: below
/// the rank's 3, above the h 2.5 m slope, as a wasted attempt (up to the give-up window, a
/// quarter of the budget) costs more than an early factorisation. With it the h 2.5 m static
/// states took 14 min 19 s (NTN) and 9 min 23 s (NTS) against 16 min 10 s and 13 min 48 s, the
/// static table moving by 5e-7 (docs/performance.md §7b, "A stale factor is not tried…").
pub const PRODUCTS_PER_CHANGED_PAIR: f64 = 2.0;

/// Floating-point operations of one GMRES product with the preconditioner: the sparse product
/// with P's pattern (2 per entry; the pair terms are of the same order), the two triangular
/// solves with its factor (4 per factor entry), and the Gram–Schmidt against about 10 Krylov
/// vectors (4 n each way).
fn product_flops(p_entries: usize, factor_entries: usize, n: usize) -> f64 {
    2.0 * p_entries as f64 + 4.0 * factor_entries as f64 + 40.0 * n as f64
}

/// The refactorisation rule, written once: GMRES products that cost as much as one numeric
/// factorisation of the preconditioner, factor_flops / [`FACTOR_SPEEDUP`] / product_flops
/// (at least 1). The preconditioner is factorised again before a direction when the products
/// made since its last factorisation reach this (ski rental: the products a stale
/// preconditioner costs beyond a fresh one's 1–3 are never more than one factorisation's
/// worth, so the total is within 2× of the best choice made knowing the future); a direction
/// on a stale preconditioner that needs more than this many products is stopped and redone on
/// a fresh one. Why not a fixed count (15 before): one factorisation costs about 14 products on
/// the default dam mesh but about 50 on the fine one, so a fixed count refactorised the fine
/// mesh too often (docs/performance.md §7b).
fn products_per_factorisation(factor_flops: f64, product_flops: f64) -> f64 {
    (factor_flops / FACTOR_SPEEDUP / product_flops.max(1.0)).max(1.0)
}

impl TangentSolver {
    fn new(k0: &Csc, pairs: &[Pair], ordering: FillOrdering, precision: FactorPrecision) -> TangentSolver {
        let mut entries = Vec::new();
        for p in pairs {
            for wc in &p.w {
                for wd in &p.w {
                    for &(a, _) in wc {
                        for &(b, _) in wd {
                            entries.push((a, b, 0.0));
                        }
                    }
                }
            }
        }
        let p = add_entries(k0, &entries);
        let pos = |i: usize, j: usize| p.col_ptr[j] + p.row[p.col_ptr[j]..p.col_ptr[j + 1]].binary_search(&i).expect("P's pattern holds K̂ and the pair blocks");
        let mut k0_pos = Vec::with_capacity(k0.nnz());
        for j in 0..k0.n_cols {
            for q in k0.col_ptr[j]..k0.col_ptr[j + 1] {
                k0_pos.push(pos(k0.row[q], j));
            }
        }
        let pair_pos = entries.iter().map(|&(a, b, _)| pos(a, b)).collect();
        let n = k0.n_rows;
        TangentSolver { p, k0_pos, pair_pos, chol: None, ordering, precision, products_since: 0, budget: 1.0, stats: DirectionStats::default(), y: vec![0.0; n], states_at_factor: Vec::new() }
    }

    /// The GMRES products an attempt on the current (stale) factor is expected to take at the
    /// pairs' states `tangents`: [`PRODUCTS_PER_CHANGED_PAIR`] per pair whose state (open,
    /// stick, slip) differs from the one it had at the factorisation.
    fn stale_products_expected(&self, tangents: &[PairTangent]) -> f64 {
        let changed = tangents.iter().zip(&self.states_at_factor).filter(|(t, s)| t.state != **s).count();
        PRODUCTS_PER_CHANGED_PAIR * changed as f64
    }

    /// P's values for the tangents `tangents`, then its numeric factorisation.
    fn factorise(&mut self, k0: &Csc, pairs: &[Pair], tangents: &[PairTangent]) -> Result<(), Error> {
        let (start, cpu0) = (std::time::Instant::now(), cpu_seconds());
        self.p.val.fill(0.0);
        for (q, &v) in self.k0_pos.iter().zip(&k0.val) {
            self.p.val[*q] += v;
        }
        let mut e = 0;
        for (p, tg) in pairs.iter().zip(tangents) {
            for (c, wc) in p.w.iter().enumerate() {
                for (d, wd) in p.w.iter().enumerate() {
                    let s = tg.spd[(c, d)];
                    for &(_, va) in wc {
                        for &(_, vb) in wd {
                            self.p.val[self.pair_pos[e]] += s * va * vb;
                            e += 1;
                        }
                    }
                }
            }
        }
        let what = "static stage with the joints active: the Newton preconditioner K + the pairs' stiffness";
        let mut done = self.numeric(what, self.precision);
        if matches!(done, Err(LinalgError::NotPositiveDefinite { .. })) && self.precision == FactorPrecision::Single {
            // f32 lost a pivot: f64 from now on (on the same analysis after the first)
            self.precision = FactorPrecision::Double;
            self.stats.single_fallback = true;
            done = self.numeric(what, FactorPrecision::Double);
        }
        done.map_err(|e| ModelError::Invalid(e.to_string()))?;
        self.products_since = 0;
        self.states_at_factor.clear();
        self.states_at_factor.extend(tangents.iter().map(|t| t.state));
        self.stats.factorisations += 1;
        if let Some(ch) = self.chol.as_ref() {
            self.stats.factor_entries = ch.factor_entries();
            self.stats.factor_bytes = ch.factor_bytes();
            self.stats.single = ch.precision() == FactorPrecision::Single;
            self.stats.factor_flops = ch.factor_flops();
            self.stats.product_flops = product_flops(self.p.nnz(), ch.factor_entries(), ch.n());
            self.stats.analysis_seconds = ch.analysis_seconds();
            self.stats.nested_dissection = ch.ordering() == FillOrdering::NestedDissection;
            self.budget = products_per_factorisation(self.stats.factor_flops, self.stats.product_flops);
        }
        self.stats.factor_seconds += start.elapsed().as_secs_f64();
        self.stats.factor_cpu_seconds += cpu_seconds() - cpu0;
        self.stats.threads = run_par().degree();
        self.stats.trace.push('F');
        Ok(())
    }

    /// P's numeric factorisation in `precision`: on its analysis, or the first (analysis
    /// included; the solves then split over the elimination tree).
    fn numeric(&mut self, what: &str, precision: FactorPrecision) -> Result<(), LinalgError> {
        if let Some(ch) = self.chol.as_mut() {
            return ch.refactor_in(&self.p, what, precision);
        }
        let mut ch = SparseCholesky::factor_in(&self.p, what, run_par(), self.ordering, precision)?;
        // the GMRES products' solves in two halves of the elimination tree at once
        self.stats.split = ch.split_solves();
        self.chol = Some(ch);
        Ok(())
    }

    /// r ← K_T⁻¹ r, to the relative residual `eta` (the forcing term).
    fn direction_in_place(&mut self, k0: &Csc, pairs: &[Pair], tangents: &[PairTangent], r: &mut [f64], eta: f64) -> Result<(), Error> {
        let changed = self.chol.is_none() || self.products_since as f64 + self.stale_products_expected(tangents) >= self.budget;
        if changed {
            self.factorise(k0, pairs, tangents)?;
        }
        for attempt in 0..2 {
            // a preconditioner made at older states gets a few times the products that call for
            // a refactorisation, then is refactorised at these states
            let fresh = changed || attempt > 0;
            let stale_cap = self.budget.ceil() as usize;
            let opts = if fresh {
                GmresOptions { tolerance: eta, ..Default::default() }
            } else {
                GmresOptions { tolerance: eta, max_iterations: stale_cap, give_up_window: give_up_window(stale_cap), ..Default::default() }
            };
            let (start, cpu0) = (std::time::Instant::now(), cpu_seconds());
            let chol = self.chol.as_mut().expect("factorised above");
            self.y.fill(0.0);
            let (mut precondition_s, mut operator_s) = (0.0, 0.0);
            let apply = |x: &[f64], out: &mut [f64]| {
                let t = std::time::Instant::now();
                k0.mul_into(x, out);
                for (p, tg) in pairs.iter().zip(tangents) {
                    if tg.state == PairState::Open {
                        continue;
                    }
                    let w = relative_motion(p, x);
                    let q = (tg.spd + tg.coupling) * w;
                    for (c, wc) in p.w.iter().enumerate() {
                        for &(a, va) in wc {
                            out[a] += q[c] * va;
                        }
                    }
                }
                operator_s += t.elapsed().as_secs_f64();
            };
            let precondition = |v: &mut [f64]| {
                let t = std::time::Instant::now();
                chol.solve_in_place(v);
                precondition_s += t.elapsed().as_secs_f64();
            };
            let g = gmres_into(apply, precondition, r, &mut self.y, &opts);
            self.stats.krylov_products += g.iterations;
            self.stats.krylov_seconds += start.elapsed().as_secs_f64();
            self.stats.krylov_cpu_seconds += cpu_seconds() - cpu0;
            self.stats.precondition_seconds += precondition_s;
            self.stats.operator_seconds += operator_s;
            self.stats.trace.push_str(&format!("{}{}", g.iterations, if g.converged { " " } else if g.gave_up { "!" } else { ">" }));
            if g.gave_up {
                self.stats.given_up += 1;
            }
            self.products_since += g.iterations;
            if g.converged {
                r.copy_from_slice(&self.y);
                return Ok(());
            }
            if !fresh {
                // a stale preconditioner: factorise at this state and try again
                self.factorise(k0, pairs, tangents)?;
                continue;
            }
            break;
        }
        // the fallback: the assembled tangent, sparse LU
        self.stats.lu_fallbacks += 1;
        let mut extra = Vec::new();
        for (p, tg) in pairs.iter().zip(tangents) {
            let t = tg.spd + tg.coupling;
            for (c, wc) in p.w.iter().enumerate() {
                for (d, wd) in p.w.iter().enumerate() {
                    if t[(c, d)] == 0.0 {
                        continue;
                    }
                    for &(a, va) in wc {
                        for &(b, vb) in wd {
                            extra.push((a, b, t[(c, d)] * va * vb));
                        }
                    }
                }
            }
        }
        lu_solve_in_place(&add_entries(k0, &extra), r, "static stage with the joints active").map_err(|e| ModelError::Invalid(e.to_string()))?;
        Ok(())
    }
}

/// Dual mortar joint `ji`: each slave node's mortar master point (model nodes, weights
/// c_k = M_jk / D_jj) and its area D_jj on the initial configuration
/// (`ContactSolver::mortar_master_points`; `None` below the mortar cover); empty for the other
/// methods. `solver` is the static solve's one contact solver (scratch only: each call
/// evaluates the joint's integrals afresh), built on its first mortar joint.
#[allow(clippy::type_complexity)]
fn mortar_points<'p>(problem: &'p Problem, solver: &mut Option<ContactSolver<'p>>, contact: &ContactState, ji: usize) -> Result<Vec<Option<(Vec<(usize, f64)>, f64)>>, Error> {
    let (model, j) = (&problem.model, &problem.joints[ji]);
    if j.method != Method::Mortar {
        return Ok(Vec::new());
    }
    let zero = vec![0.0; 3 * model.n_nodes()];
    let solver = solver.get_or_insert_with(|| ContactSolver::new(model, &problem.joints));
    let points = solver.mortar_master_points(model, ji, &contact.joints[ji], &zero);
    Ok(points.map_err(|e| ModelError::Invalid(format!("static contact, joint \"{}\": {e}", j.tag.name)))?)
}

/// Solve the increment `f` (forces over every model dof) on `problem`'s model with the tied
/// joints bonded and the other joints active, from grouted joints (gap 0, no force), with the
/// penalty `penalty_factor` × the slave node's diagonal stiffness ([`PENALTY_FACTOR`]). Returns
/// Δu over every model dof and the report, and writes each pair's state, forces and gap into
/// `contact`.
pub fn solve_static_increment(problem: &Problem, f: &[f64], contact: &mut ContactState, penalty_factor: f64) -> Result<(Vec<f64>, StaticContactInfo), Error> {
    solve_static_increment_ordered(problem, f, contact, penalty_factor, STATIC_ORDERING)
}

/// The fill-reducing ordering of the static stages' Cholesky factorisations: `Auto`, nested
/// dissection from `linalg::ordering::NESTED_DISSECTION_FROM` unknowns, AMD below. Why: on the
/// fine dam METIS's factor of stage c's preconditioner is smaller and cheaper than AMD's
/// (docs/performance.md §7b), and on the h 2.5 m mesh AMD's does not fit in memory.
pub const STATIC_ORDERING: FillOrdering = FillOrdering::Auto;

/// [`solve_static_increment`] with the preconditioner's fill-reducing ordering `ordering`.
pub fn solve_static_increment_ordered(problem: &Problem, f: &[f64], contact: &mut ContactState, penalty_factor: f64, ordering: FillOrdering) -> Result<(Vec<f64>, StaticContactInfo), Error> {
    solve_static_increment_in(problem, f, contact, penalty_factor, ordering, None)
}

/// [`solve_static_increment_ordered`] with the preconditioner's factor in `precision` (`None`:
/// the rule, [`SINGLE_FROM`]).
pub fn solve_static_increment_in(problem: &Problem, f: &[f64], contact: &mut ContactState, penalty_factor: f64, ordering: FillOrdering, precision: Option<FactorPrecision>) -> Result<(Vec<f64>, StaticContactInfo), Error> {
    let start = std::time::Instant::now();
    let model = &problem.model;
    let k_full = stiffness(model, &vec![true; model.materials.len()]);
    let tied: Vec<&ContactJoint> = problem.joints.iter().filter(|j| j.law.tied).collect();
    let t = Bonding::build(model, &tied, |d| model.is_free(d / 3, d % 3) && k_full.col_ptr[d + 1] > k_full.col_ptr[d])?;
    let k0 = t.reduce(&k_full);
    let f0 = t.reduce_vector(f);
    let mut info = StaticContactInfo::default();
    let mut pairs = active_pairs(problem, &t, &k_full, contact, penalty_factor, &mut info)?;
    let residual = Residual { k0: &k0, f0: &f0, joints: &problem.joints, nf: norm(&f0) };
    info.setup_seconds = start.elapsed().as_secs_f64();
    let precision = precision.unwrap_or(if t.n >= SINGLE_FROM { FactorPrecision::Single } else { FactorPrecision::Double });
    let uh = newton(&residual, &mut pairs, t.n, (ordering, precision), &mut info)?;
    // the result and the pairs' records
    let mut du = vec![0.0; t.n_dofs];
    t.expand_into(&uh, &mut du);
    info.max_displacement = (0..model.n_nodes()).map(|n| Vector3::new(du[3 * n], du[3 * n + 1], du[3 * n + 2]).norm()).fold(0.0, f64::max);
    record_pairs_into(problem, &pairs, &uh, contact, &mut info);
    info.seconds = start.elapsed().as_secs_f64();
    Ok((du, info))
}

/// The matrices the static stages factorise, for measuring their fill without factorising
/// them: stage a's K̂ (the stiffness with the tied joints bonded, `bonding::Bonding`) and the
/// pattern of stage c's preconditioner P (K̂ plus every pair's block, with zeros there), with
/// the pairs of the initial configuration.
pub fn static_matrices(problem: &Problem) -> Result<(Csc, Csc), Error> {
    let model = &problem.model;
    let k_full = stiffness(model, &vec![true; model.materials.len()]);
    let tied: Vec<&ContactJoint> = problem.joints.iter().filter(|j| j.law.tied).collect();
    let t = Bonding::build(model, &tied, |d| model.is_free(d / 3, d % 3) && k_full.col_ptr[d + 1] > k_full.col_ptr[d])?;
    let k0 = t.reduce(&k_full);
    let contact = ContactState::new(&problem.joints);
    let pairs = active_pairs(problem, &t, &k_full, &contact, PENALTY_FACTOR, &mut StaticContactInfo::default())?;
    let p = TangentSolver::new(&k0, &pairs, STATIC_ORDERING, FactorPrecision::Double).p;
    Ok((k0, p))
}

/// The pairs of the joints that are not tied, with their relative motion over the reduced
/// unknowns of `t` and their penalty (`penalty_factor` × the slave node's mean diagonal of
/// `k_full`; a mortar slave node pairs with its mortar master point and area from `contact`);
/// counts the pairs on tied nodes and those left out into `info`.
fn active_pairs(problem: &Problem, t: &Bonding, k_full: &Csc, contact: &ContactState, penalty_factor: f64, info: &mut StaticContactInfo) -> Result<Vec<Pair>, Error> {
    let model = &problem.model;
    let mut pairs = Vec::new();
    let unformed = crate::contact::joint::unformed_pairs(&problem.joints);
    let mut solver = None;
    for (ji, j) in problem.joints.iter().enumerate() {
        if j.law.tied {
            continue;
        }
        let mut mortar = mortar_points(problem, &mut solver, contact, ji)?;
        for (i, &s) in j.tag.slave_nodes().iter().enumerate() {
            if unformed[ji][i] {
                // the slave of a tied joint is the slave of no other joint (the rule: `unformed_pairs`)
                info.on_tied += 1;
                continue;
            }
            let found = match j.method {
                Method::Ntn => Some((vec![(j.tag.nearest_master_node(i), 1.0)], j.tag.areas[i])),
                Method::Mortar => mortar[i].take(),
                _ => match master_point(model, j, i)? {
                    (_, MasterHit::NearestNode) => None,
                    (m, _) => Some((m, j.tag.areas[i])),
                },
            };
            let Some((masters, area)) = found else {
                info.left_out += 1;
                continue;
            };
            let w = pair_motion_weights(t, &masters, s);
            let diag = (0..3).map(|c| k_full.get(3 * s + c, 3 * s + c)).sum::<f64>() / 3.0;
            pairs.push(Pair { joint: ji, index: i, w, n: j.frames[i][0], k: penalty_factor * diag, area, closed: true, changes: 0 });
        }
    }
    Ok(pairs)
}

/// w_c = Σ_I N_I u_I,c − u_s,c over the reduced unknowns of `t` (the masters `(node, N_I)`,
/// the slave node `s`), zero weights dropped.
fn pair_motion_weights(t: &Bonding, masters: &[(usize, f64)], s: usize) -> [Vec<(usize, f64)>; 3] {
    let mut w: [Vec<(usize, f64)>; 3] = Default::default();
    for (c, wc) in w.iter_mut().enumerate() {
        let mut add = |d: usize, scale: f64| {
            for &(r, v) in &t.rows[d] {
                match wc.iter_mut().find(|e| e.0 == r) {
                    Some(e) => e.1 += scale * v,
                    None => wc.push((r, scale * v)),
                }
            }
        };
        for &(m, nw) in masters {
            add(3 * m + c, nw);
        }
        add(3 * s + c, -1.0);
        wc.retain(|e| e.1 != 0.0);
    }
    w
}

/// The Euclidean norm.
fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// The out-of-balance force of the reduced model: K̂ `k0`, the reduced load `f0` and its norm
/// `nf`, the joints' laws.
struct Residual<'a> {
    k0: &'a Csc,
    f0: &'a [f64],
    joints: &'a [ContactJoint],
    nf: f64,
}

impl Residual<'_> {
    /// R(u) = F − K u − Σ Bᵀ q into `r`, each pair's state and tangent into `tangents` when
    /// asked, and each pair's closed flag; returns ‖R‖ / ‖F‖ (0 without load).
    fn evaluate_into(&self, uh: &[f64], pairs: &[Pair], r: &mut Vec<f64>, tangents: Option<&mut Vec<PairTangent>>, closed: &mut Vec<bool>) -> f64 {
        self.k0.mul_into(uh, r);
        for (ri, fi) in r.iter_mut().zip(self.f0) {
            *ri = fi - *ri;
        }
        closed.clear();
        let mut tangents = tangents;
        if let Some(t) = tangents.as_deref_mut() {
            t.clear();
        }
        for p in pairs {
            let w = relative_motion(p, uh);
            let (state, q, tangent) = pair_force(p, &w, &self.joints[p.joint].law, p.changes >= CHATTER_CHANGES);
            closed.push(state != PairState::Open);
            for (c, wc) in p.w.iter().enumerate() {
                for &(a, va) in wc {
                    r[a] -= q[c] * va;
                }
            }
            if let Some(t) = tangents.as_deref_mut() {
                t.push(tangent);
            }
        }
        if self.nf > 0.0 { norm(r) / self.nf } else { 0.0 }
    }
}

/// Newton's iteration on the `n` reduced unknowns from 0, with a backtracking line search;
/// counts each pair's state changes, writes the iterations, residual and solver statistics
/// into `info`. Returns the reduced solution.
fn newton(residual: &Residual, pairs: &mut [Pair], n: usize, (ordering, precision): (FillOrdering, FactorPrecision), info: &mut StaticContactInfo) -> Result<Vec<f64>, Error> {
    let k0 = residual.k0;
    let mut uh = vec![0.0; n];
    let (mut r, mut r_try) = (vec![0.0; n], vec![0.0; n]);
    let (mut closed, mut closed_try) = (Vec::new(), Vec::new());
    let mut tangents = Vec::with_capacity(pairs.len());
    let mut u_try = vec![0.0; n];
    let mut solver = TangentSolver::new(k0, pairs, ordering, precision);
    let (mut res_prev, mut eta) = (None, FORCING_MAX);
    for it in 0..=MAX_ITERATIONS {
        crate::interrupt::check("the static state (Newton iterations with contact)")?;
        info.residual = residual.evaluate_into(&uh, pairs, &mut r, Some(&mut tangents), &mut closed);
        info.iterations = it;
        for (p, &c) in pairs.iter_mut().zip(&closed) {
            if c != p.closed {
                p.changes += 1;
                p.closed = c;
            }
        }
        if info.residual < TOLERANCE || it == MAX_ITERATIONS {
            info.converged = info.residual < TOLERANCE;
            break;
        }
        eta = forcing_term(info.residual, res_prev, eta);
        res_prev = Some(info.residual);
        solver.direction_in_place(k0, pairs, &tangents, &mut r, eta)?;
        // backtracking line search on ‖R‖ (Armijo, halving): the law is only piecewise smooth
        let mut step = 1.0;
        for _ in 0..LINE_SEARCH_HALVINGS {
            for ((ut, u), d) in u_try.iter_mut().zip(&uh).zip(&r) {
                *ut = u + step * d;
            }
            let res = residual.evaluate_into(&u_try, pairs, &mut r_try, None, &mut closed_try);
            if res <= (1.0 - 1e-4 * step) * info.residual {
                break;
            }
            step *= 0.5;
        }
        uh.copy_from_slice(&u_try);
    }
    info.solver = solver.stats;
    Ok(uh)
}

/// Each pair's state, gap and forces at the reduced solution `uh` into `contact` (cohesion
/// lost where it slid or opened, unless kept), and the pair counts, largest penetration,
/// normal force and condition violation into `info`.
fn record_pairs_into(problem: &Problem, pairs: &[Pair], uh: &[f64], contact: &mut ContactState, info: &mut StaticContactInfo) {
    let mut tension = 0.0f64;
    for p in pairs {
        let w = relative_motion(p, uh);
        let j = &problem.joints[p.joint];
        let held = p.changes >= CHATTER_CHANGES;
        let (state, q, _) = pair_force(p, &w, &j.law, held);
        let g = p.n.dot(&w);
        let r_n = -p.k * g;
        let [_, t1, t2] = j.frames[p.index];
        let rec = &mut contact.joints[p.joint].pairs[p.index];
        rec.gap = g;
        rec.state = state;
        match state {
            PairState::Open => info.open += 1,
            PairState::Slip => info.slip += 1,
            _ => info.stick += 1,
        }
        if held {
            info.held += 1;
        }
        if state != PairState::Open {
            info.max_penetration = info.max_penetration.max(-g);
            info.max_normal_force = info.max_normal_force.max(r_n);
            tension = tension.max(-r_n - j.law.tensile_strength * p.area);
        }
        let qt = q - p.n * p.n.dot(&q);
        rec.r_n = if state == PairState::Open { 0.0 } else { r_n };
        rec.r_t = [qt.dot(&t1), qt.dot(&t2)];
        if state != PairState::Stick && !j.law.keep_cohesion {
            rec.hist.intact = false;
        }
    }
    info.condition_violation = if info.max_normal_force > 0.0 { tension.max(0.0) / info.max_normal_force } else { 0.0 };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_factorisation_is_worth_its_flops_in_products() {
        // the rule's arithmetic: factor_flops / FACTOR_SPEEDUP / product_flops, at least 1
        // (never refactorise before a product was made), and more products for a denser factor
        let p = product_flops(1_000, 10_000, 100);
        assert_eq!(p, 2_000.0 + 40_000.0 + 4_000.0);
        assert_eq!(products_per_factorisation(20.0 * FACTOR_SPEEDUP * p, p), 20.0);
        assert_eq!(products_per_factorisation(0.0, p), 1.0);
        assert_eq!(products_per_factorisation(1.0, 0.0), 1.0);
    }

    /// `m` pairs each tying one node of a diagonal stiffness (k0 = I on 3 m unknowns) to the
    /// ground along z (normal z, k = 1).
    fn grounded_pairs(m: usize) -> (Csc, Vec<Pair>) {
        let n = 3 * m;
        let k0 = Csc { n_rows: n, n_cols: n, col_ptr: (0..=n).collect(), row: (0..n).collect(), val: vec![1.0; n] };
        let pairs = (0..m)
            .map(|i| Pair { joint: 0, index: i, w: [vec![(3 * i, 1.0)], vec![(3 * i + 1, 1.0)], vec![(3 * i + 2, 1.0)]], n: Vector3::z(), k: 1.0, area: 1.0, closed: true, changes: 0 })
            .collect();
        (k0, pairs)
    }

    /// The tangents of [`grounded_pairs`]: stick (k I) for the first m − `slipping`, slip
    /// (k n nᵀ: no tangential stiffness) for the rest.
    fn grounded_tangents(m: usize, slipping: usize) -> Vec<PairTangent> {
        let normal = Vector3::z();
        (0..m)
            .map(|i| {
                let (state, spd) = if i < m - slipping { (PairState::Stick, Matrix3::identity()) } else { (PairState::Slip, normal * normal.transpose()) };
                PairTangent { state, spd, coupling: Matrix3::zeros() }
            })
            .collect()
    }

    #[test]
    fn a_stale_factor_is_not_tried_when_the_changed_pairs_would_take_the_budget() {
        // The rule of PRODUCTS_PER_CHANGED_PAIR: with a factorisation worth 10 products and
        // none made since it, 4 changed pairs (8 products expected) are tried on the stale
        // factor, 5 (10 expected) are refactorised first. Exact counts.
        let m = 12;
        let (k0, pairs) = grounded_pairs(m);
        let stick = grounded_tangents(m, 0);
        for (slipping, refactorised) in [(0, false), (4, false), (5, true), (12, true)] {
            let mut solver = TangentSolver::new(&k0, &pairs, FillOrdering::Amd, FactorPrecision::Double);
            solver.factorise(&k0, &pairs, &stick).unwrap();
            solver.budget = 10.0;
            let tangents = grounded_tangents(m, slipping);
            assert_eq!(solver.stale_products_expected(&tangents), PRODUCTS_PER_CHANGED_PAIR * slipping as f64);
            let mut r = vec![1.0; 3 * m];
            solver.direction_in_place(&k0, &pairs, &tangents, &mut r, 1e-10).unwrap();
            assert_eq!(solver.stats.factorisations, if refactorised { 2 } else { 1 }, "{slipping} pairs slipping");
            // the direction: (I + the pairs' stiffness)⁻¹ 1 = 1/2 on stuck dofs and on the
            // slipping pairs' z, 1 on their x and y
            for (i, v) in r.iter().enumerate() {
                let slips = i / 3 >= m - slipping;
                let want = if slips && i % 3 < 2 { 1.0 } else { 0.5 };
                assert!((v - want).abs() < 1e-9, "unknown {i}: {v} against {want}");
            }
        }
    }

    #[test]
    fn forcing_term_follows_eisenstat_walker_within_its_bounds() {
        // Reference: Eisenstat & Walker 1996, choice 2, η = 0.9 (res/res_prev)² with the
        // safeguard max(η, 0.9 η_prev²) when 0.9 η_prev² > 0.1; exact to round-off (1e-15).
        // first iteration: the cap
        assert_eq!(forcing_term(1.0, None, 0.0), FORCING_MAX);
        // slow progress: 0.9 × 0.5² = 0.225, capped at FORCING_MAX
        assert_eq!(forcing_term(0.5, Some(1.0), FORCING_MAX), FORCING_MAX);
        // fast progress far from the tolerance: 0.9 × 1e-2² = 9e-5
        assert!((forcing_term(1e-3, Some(1e-1), FORCING_MAX) - 9e-5).abs() < 1e-15);
        // near the tolerance: never tighter than 0.1 × TOLERANCE / res (1e-9 / 1e-6 = 1e-3)
        assert!((forcing_term(1e-6, Some(1e-2), 1e-3) - 1e-3).abs() < 1e-15);
        // very fast progress: floored at 0.1 × TOLERANCE / res (1e-8 here), never below DIRECTION_TOLERANCE
        assert_eq!(forcing_term(1e-1, Some(1e6), 1e-3), DIRECTION_TOLERANCE.max(0.1 * TOLERANCE / 1e-1));
    }
}
