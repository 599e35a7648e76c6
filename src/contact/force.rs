//! The dynamic contact force on the model (design §5): search, pair forces, Gauss–Seidel.
//!
//! Each step, after the contact-free prediction ũ[n+1]:
//! 1. **Search** (per slave node): project x̃_s along its normal n onto the candidate master
//!    faces at their predicted positions (inside-outside, [`super::query`]). Candidates are the
//!    Layer1 (or Layer2) faces around the pair's *centre* master node, initially the tagger's O.
//!    If the projection leaves them: `widen` tries Layer2, then walks the master surface to the
//!    node nearest the slave's current relative position and makes it the new centre; `report`
//!    counts the node and gives it no force that step. NTN pairs the slave with O (N = [1]).
//! 2. **Pair force**: trial gap g̃ and tangential increment Δd̃_t with the pair's own force
//!    removed, then [`super::law::pair_force`] (closes the gap exactly, Mohr-Coulomb in shear).
//! 3. **Gauss–Seidel**: pairs that share master nodes are coupled; sweeps repeat the pair updates,
//!    starting from each pair's force of the last step (`gs_warm_start`), in colour order (pairs
//!    of one colour share no node, `gs_colored`), until the largest node displacement change in
//!    a sweep is below `gs_tolerance` (or `gs_max_sweeps`). Once fewer than half the pairs still
//!    move a node by more than 1 % of the tolerance, a sweep skips the pairs none of whose nodes
//!    moved since their last evaluation (they would give the same force); before, it takes them
//!    all without the bookkeeping. With an asperity envelope (`JointLaw::asperity_friction`),
//!    after the colours of each sweep the pairs of a slave node that has pairs on two such
//!    joints (the line where two joints meet) are solved together ([`shared_node_pass`]).
//!
//! Mobility: w = 1/m_s + Σ N_I²/m_I with 1/m = 0 at a fully fixed node (it does not move under
//! contact forces). **Partly fixed nodes** (a symmetry plane, a roller: some components fixed)
//! take the pair force on their free components only: a node moves by (dt²/m) P r, P the
//! projection on its free components, and the support takes the rest. The pair's mobility is
//! then the diagonal matrix W = Σ c_b² P_b / m_b (global axes), no longer w I; the pair update
//! keeps its scalar form with w = the largest diagonal entry of W (its largest eigenvalue),
//! which the Gauss–Seidel sweeps iterate to the exact fixed point (the update is in residual
//! form: the gap and the stick motion it leaves are those of the actual masked displacements,
//! and a scalar at or above W's spectrum converges monotonically; exact in one update when
//! the normal and the slip direction are free at every node, as on a symmetry plane that the
//! joint crosses at right angles). A pair whose normal is fixed at every node (nᵀ W n = 0)
//! takes no force. Models without partly fixed nodes never enter this path (docs/contact.md,
//! "Partly fixed nodes").
//!
//! **Threads.** The search runs in parallel over chunks of each joint's slave nodes (each pair
//! writes only its own record; the chunks' active pairs are appended in the order one thread
//! lists them, and the event counters are integer sums). The sweeps run each colour's pairs in
//! parallel: two pairs of one colour share no moving node and a pair writes only its moving
//! nodes, so a colour's pass gives the same positions in any order, and its pairs share one tick
//! of the work list's clock (whether a pair is evaluated again depends only on the order of
//! the colours' ticks). A colour is shared out in equal parts, one per thread, in the active
//! order (about the same stretch of the joints in every colour), and each sweep's change, the
//! write-back and the record are taken by parts of the local nodes and of the active pairs, so
//! that a thread keeps its pairs and nodes in its cache through the sweeps.
//! Whether the sweeps run on all threads or on one is chosen by timing both every 512 steps
//! (`ContactSolver::sweep_threads`, `par::ThreadChoice`): where the vCPUs share no cache the
//! parallel sweeps cost more than one thread's. The result is bit-identical on any number of
//! threads and either choice (test
//! `contact_search_and_sweeps_in_parallel_are_bit_identical_to_one_thread`). The mortar pairs,
//! the last colour (pairs past 63 colours), the set-up (listing, warm start, colouring) and the
//! joints' sums of the record stay on one thread.
//!
//! Penalty variant (`Method::Penalty`): same search on the positions at t[n]; normal spring
//! kn A on the gap, tangential elastic spring kt A, with the joint law of the dynamic contact
//! force ([`super::law::penalty_force`]: Mohr-Coulomb, cohesion, tension, tied), applied as an
//! external force of step n (so it is explicit and lowers the stable step).

use super::free_edge;
use super::joint::{ContactJoint, Method, OnExit};
use super::law::{pair_force_with_inverse, penalty_force, JointLaw, PairHistory, PairState};
use super::state::released_entry_offset;
pub use super::state::{ContactState, JointRecord, PairRecord, SearchEvents};
use super::mortar::{overlap_integrals, Overlap, SlaveFace};
use super::query::{project_along_on_quad_from, project_along_on_tri, select_projection, Location, INSIDE_TOL_DEFAULT};
use crate::constraint::{Constraint, ConstraintInfo, StepContext};
use crate::error::StepError;
use crate::model::Model;
use nalgebra::{Matrix3, Vector2, Vector3};
use rayon::prelude::*;

/// The master side of one pair: up to four master nodes (`nm` used) with their weights `N_I`,
/// and the master face (−1 for NTN).
#[derive(Clone, Copy, Debug)]
struct PairMasters<const M: usize = 4> {
    nodes: [u32; M],
    nm: u8,
    weights: [f64; M],
    face: i32,
}

/// A pair's mobility (module doc): the scalar `w` [1/kg], the inverse masses of its slave
/// (`ims`) and masters (`imm`), whether it has a partly fixed or block node, and per node its
/// free components (1 free, 0 fixed; all 1 unless partly fixed).
#[derive(Clone, Copy, Debug)]
struct Mobility<const N: usize = 5> {
    w: f64,
    ims: f64,
    imm: [f64; N],
    partial: bool,
    masks: [Vector3<f64>; N],
}

/// Entries of a mortar pair: its slave node and at most 32 master nodes. A slave node's dual
/// function couples it to the master nodes of every master face that overlaps one of its slave
/// faces: 16 on two shifted structured quad grids, about 20 for triangles on quads or a slave
/// a third coarser than its master; more means a slave side far coarser than the master
/// (an error that says so). 33 entries keep a mortar pair at about 0.8 kB.
const MORTAR_NODES: usize = 33;
const MORTAR_MASTERS: usize = MORTAR_NODES - 1;

/// A slave node's mortar pair is formed only when its weighted area `D_jj` is at least this
/// fraction of its tributary area `∫ N_j` (1 on a fully covered node): 0.25. Below it the node
/// is near the master's free edge with most of its slave faces uncovered, and the master weights
/// `M_jk / D_jj` (which sum to one) grow as 1 / D_jj; such a node is counted lost that step
/// (`SearchEvents::lost`), as an NTS node off the master is.
const MORTAR_MIN_COVER: f64 = 0.25;

/// A slave node's master entries: master-local nodes, `M_jk` [m²], and the count used.
type MortarRow = ([u32; MORTAR_MASTERS], [f64; MORTAR_MASTERS], u8);

/// A slave face's mortar integrals are re-evaluated when one of its nodes has moved, relative to
/// its centre master node and tangentially (along the joint), by more than this fraction of the
/// face size (√ of its projected area) since the face's last evaluation, or when a node's centre
/// (hence the face's candidate set) has changed: 0.05. Between evaluations the weights
/// `M_jk / D_jj` are those of positions up to 0.05 h of sliding back: the master point lags the
/// exact mortar projection by at most that along the surface (no error on a flat joint, where
/// the gap and the relative slip of a weighted point of the master plane do not depend on the
/// weights; a gap error of order (0.05 h)² / R on a joint of radius R). Momentum is kept exactly
/// (the weights always sum to one). A joint that does not slide (a tie, a stuck joint, the
/// static stages) keeps the integrals of its first step: the stick then holds material points,
/// where weights re-evaluated on each step's prediction drift with the prediction's relative
/// motion (docs/contact.md, "Dual mortar").
const MORTAR_REEVALUATE: f64 = 0.05;

/// One slave face's share of the mortar integrals, kept between steps.
#[derive(Clone, Debug, Default)]
struct FaceIntegrals {
    /// False until the face is first evaluated.
    evaluated: bool,
    /// Per face node, at the evaluation: its centre (master-local node) and its displacement
    /// relative to that centre's [m].
    centre: [u32; 4],
    rel: [Vector3<f64>; 4],
    /// √ of the projected face area at the evaluation [m].
    size: f64,
    /// The overlapping master faces and their integrals.
    overlaps: Vec<(u32, Overlap)>,
}

/// The mortar integrals of one joint: per slave face ([`FaceIntegrals`]) and summed per slave
/// node (`d` = `D_jj` [m²], `rows` its master entries).
#[derive(Default)]
struct MortarJoint {
    faces: Vec<FaceIntegrals>,
    d: Vec<f64>,
    rows: Vec<MortarRow>,
}

impl MortarJoint {
    /// Empty integrals sized for joint `j`: a face per slave face, a row per slave node, none
    /// evaluated.
    fn sized(j: &ContactJoint) -> MortarJoint {
        let n_s = j.tag.n_slave();
        MortarJoint { faces: vec![FaceIntegrals::default(); j.tag.slave.faces.len()], d: vec![0.0; n_s], rows: vec![([0; MORTAR_MASTERS], [0.0; MORTAR_MASTERS], 0); n_s] }
    }
}

/// The error of a slave node `i` of mortar joint `j` with more than `MORTAR_MASTERS` master
/// nodes (the dynamic pairs and the static stages alike).
fn mortar_overflow(j: &ContactJoint, i: usize) -> StepError {
    StepError::Contact(format!(
        "joint \"{}\" (mortar): slave node {} couples to more than {MORTAR_MASTERS} master nodes: the slave side is far coarser than the master. Make the finer side the slave (`auto`, or swap `master` and `slave`) or refine the slave side",
        j.tag.name,
        j.tag.slave_nodes()[i]
    ))
}

/// The mortar pairs of the current step and the scratch of their integrals, apart from the
/// node-to-segment pairs because a mortar slave node has more master nodes than a face's four.
#[derive(Default)]
struct MortarScratch {
    active: Vec<Active<MORTAR_NODES>>,
    mob_matrix: Vec<[Matrix3<f64>; MORTAR_NODES]>,
    /// The Gauss–Seidel order (the order of the search) and the tick of each pair's last
    /// evaluation.
    order: Vec<u32>,
    evaluated_at: Vec<u32>,
    /// Per joint (empty for the other methods' joints), its integrals.
    joints: Vec<MortarJoint>,
    /// Slave nodes whose faces were re-evaluated this step (local indices).
    touched: Vec<u32>,
    /// Candidate master faces of one slave face.
    cand: Vec<u32>,
    /// Slave faces evaluated so far (all joints): the cost counter of the caching.
    face_evaluations: u64,
}

/// A penalty pair's force of step n (`Method::Penalty`): slave node, master nodes, their count,
/// weights and the force on the slave [N].
type PenaltyPair = (u32, [u32; 4], u8, [f64; 4], Vector3<f64>);

/// A slice that the threads of one parallel pass read and write at disjoint places: the pairs
/// of one colour ([`ContactSolver::order_by_color`]) and the nodes they move. Two pairs of one
/// colour share no moving node, a pair writes only its moving nodes (mobility ≠ 0), so no
/// entry is written by one thread while another reads or writes it.
#[derive(Clone, Copy)]
struct Shared<T>(*mut T, usize);
// SAFETY: the pointer is only dereferenced at entries that one thread alone writes (above).
unsafe impl<T: Send> Send for Shared<T> {}
unsafe impl<T: Send> Sync for Shared<T> {}

impl<T: Copy> Shared<T> {
    fn of(s: &mut [T]) -> Shared<T> {
        Shared(s.as_mut_ptr(), s.len())
    }

    /// Entry `i` by value. SAFETY: `i` in bounds and no other thread writes it meanwhile.
    #[inline(always)]
    unsafe fn get(self, i: usize) -> T {
        debug_assert!(i < self.1);
        unsafe { *self.0.add(i) }
    }

    /// Entry `i` to write. SAFETY: `i` in bounds and no other thread reads or writes it while
    /// the reference lives.
    #[inline(always)]
    #[allow(clippy::mut_from_ref)]
    unsafe fn at<'a>(self, i: usize) -> &'a mut T {
        debug_assert!(i < self.1);
        unsafe { &mut *self.0.add(i) }
    }
}

/// One task of the search: its candidate-face scratch, and the active pairs (with their
/// mobility matrices), penalty forces and search events of its slave nodes, gathered in task
/// order after the parallel search.
#[derive(Default)]
struct SearchChunk {
    active: Vec<Active>,
    mob_matrix: Vec<[Matrix3<f64>; 5]>,
    penalty: Vec<PenaltyPair>,
    events: SearchEvents,
    cand: Vec<u32>,
}

/// Slave node `i` found no master face this step: counted lost, force-free.
fn lose_pair(p: &mut PairRecord, ev: &mut SearchEvents) {
    ev.lost += 1;
    p.face = -1;
    p.gap = f64::NAN;
    p.entry_offset = 0.0;
    p.r_n = 0.0;
    p.r_t = [0.0; 2];
    p.state = PairState::Open;
}

/// The gap of slave node `i` of joint `j` on master point `pm` at displacement `conf` [m] (the
/// grouting offset subtracted, the held re-entry offset not): the gap it re-enters with.
fn predicted_gap(model: &Model, j: &ContactJoint, pr: &PairRecord, i: usize, pm: &PairMasters, conf: &[f64]) -> f64 {
    let s = j.tag.slave_nodes()[i];
    let mut xbar = Vector3::zeros();
    for a in 0..pm.nm as usize {
        xbar += pos(model, conf, pm.nodes[a] as usize) * pm.weights[a];
    }
    j.frames[i][0].dot(&(xbar - pos(model, conf, s))) - pr.gap_offset
}

/// Slave node `i`'s pair is not formed (`joint::unformed_pairs`: the tie fixes the node):
/// reported bonded, with no force of its own.
fn unform_pair(p: &mut PairRecord) {
    p.state = PairState::Bonded;
    p.r_n = 0.0;
    p.r_t = [0.0; 2];
}

/// The master side of slave node `i` projected at `p` on master face `f`; with `widen`, the
/// node's candidate set is recentred on the face node it is nearest to (`report` keeps the
/// initial set, by definition).
fn masters_on_face(j: &ContactJoint, pr: &mut PairRecord, ev: &mut SearchEvents, f: usize, p: &super::query::Projection) -> PairMasters {
    let local = j.tag.master.faces[f].local_nodes();
    let (mut best, mut wmax) = (local[0], f64::MIN);
    for (a, &l) in local.iter().enumerate() {
        if p.weights[a] > wmax {
            wmax = p.weights[a];
            best = l;
        }
    }
    if j.on_exit == OnExit::Widen && pr.center != best {
        pr.center = best;
        ev.recentred += 1;
    }
    let nodes = j.tag.master.faces[f].nodes();
    let mut ms = [0u32; 4];
    for (a, &nd) in nodes.iter().enumerate() {
        ms[a] = nd;
    }
    pr.xi = p.xi;
    PairMasters { nodes: ms, nm: nodes.len() as u8, weights: p.weights, face: f as i32 }
}

/// Per model node: where it is among the nodes of this step's active pairs.
#[derive(Clone, Copy, Debug, Default)]
struct NodeScratch {
    /// The step (solver's `step_clock`) in which the node was put in the list of local nodes.
    listed: u32,
    /// Its index in that list (valid when `listed` is the current step).
    local: u32,
}

/// A node of the active pairs during the Gauss–Seidel sweeps (scratch).
///
/// The sweeps work on these compact copies of the nodes' predicted displacements (copied in
/// before the warm start, written back after the last sweep; 32 B, two nodes per cache line)
/// instead of the model's displacement vector and a separate per-node clock: an update touches
/// five cache lines instead of ten, in a working set of the contact nodes only.
///
/// The work list, as clocks: each pair update ticks the clock; `moved_at` is the tick at which
/// the node was last moved (by more than the marking tolerance), and a pair's `evaluated_at` the
/// tick of its last evaluation. A sweep evaluates only the pairs one of whose nodes moved since
/// their own last evaluation (in the sweep that starts the list, all: every node is stamped
/// then, every pair's tick is still 0): a pair whose nodes did not change would give
/// the same force, so skipping it is exact. Pairs later in the order are taken in the same
/// sweep, earlier ones in the next. (Reading five clocks per pair is cheaper than marking every
/// pair on a moved node, which an earlier bit set with per-node lists did.)
#[derive(Clone, Copy, Debug)]
struct LocalNode {
    x: Vector3<f64>,
    moved_at: u32,
}

/// One active pair of the current step (scratch).
#[derive(Clone, Copy, Debug)]
struct Active<const N: usize = 5> {
    joint: u32,
    pair: u32,
    nm: u8,
    dt2w: f64,
    /// 1 / dt2w (one division per pair and step, not per update).
    inv_dt2w: f64,
    /// Applied force components (r_n compressive, r_t) of the current Gauss–Seidel iterate.
    r_n: f64,
    r_t: Vector2<f64>,
    hist: PairHistory,
    state: PairState,
    gap: f64,
    /// The slave node's frame (n, t1, t2), tributary area [m²] and history at t[n].
    frame: [Vector3<f64>; 3],
    area: f64,
    hist0: PairHistory,
    /// n · (Σ N_I X_I − X_s) on the reference coordinates X [m]: the gap without displacements.
    gap0: f64,
    /// Σ N_I u_I − u_s at t[n] [m]: the relative displacement before the step.
    rel_u: Vector3<f64>,
    /// The pair's nodes, slave first then its `nm` masters, their coefficients in
    /// Σ N_I u_I − u_s (−1 for the slave, N_I for the masters), and the displacement a unit
    /// pair force gives each over one step (dt²/m_s for the slave, −dt² N_I/m_I for the masters,
    /// 0 at a fixed node). Always five
    /// entries, so that the Gauss–Seidel update has no loop bounds to test: entries past the
    /// masters repeat the slave with coefficient and mobility 0.
    nodes: [u32; N],
    coef: [f64; N],
    mob: [f64; N],
    /// The largest mob² of the five (a full sweep's test of whether the pair moved a node).
    mob2_max: f64,
    /// A pair with a partly fixed node or a node with an inertia block: its nodes move by
    /// `mob_matrix` (per node, `mob` times the node's free components, or its block's
    /// inverse), not by `mob` (module doc, "Partly fixed nodes"; docs/contact.md, "Mobility of
    /// an anisotropic mass").
    partial: bool,
    /// The same nodes as indices into the solver's local nodes ([`LocalNode`]).
    local: [u32; N],
}

impl<const N: usize> Active<N> {
    /// The entries in use: all five of a node-to-segment pair (a constant, so that its loops
    /// have fixed bounds), the slave and its `nm` masters of a mortar pair.
    #[inline(always)]
    fn span(&self) -> usize {
        if N == 5 { 5 } else { self.nm as usize + 1 }
    }

    /// The pair's relative displacement Σ N_I x_I − x_s over the local nodes (five terms
    /// always: unused entries have coefficient 0).
    #[inline(always)]
    fn relative_displacement(&self, local: &[LocalNode]) -> Vector3<f64> {
        self.relative_displacement_with(|l| local[l].x)
    }

    /// [`Self::relative_displacement`] with the local nodes' positions read by `x`.
    #[inline(always)]
    fn relative_displacement_with(&self, x: impl Fn(usize) -> Vector3<f64>) -> Vector3<f64> {
        let mut rel = Vector3::zeros();
        for b in 0..self.span() {
            rel += x(self.local[b] as usize) * self.coef[b];
        }
        rel
    }

    /// Move the pair's local nodes by the displacements a pair force `r` (N, on the slave) makes
    /// over one step (`mob`: 0 at a fixed node or an unused entry; `masked`: this pair's
    /// per-component mobilities when it has a partly fixed node).
    #[inline(always)]
    fn move_nodes_into(&self, local: &mut [LocalNode], r: &Vector3<f64>, matrix: &[[Matrix3<f64>; N]], k: usize) {
        if self.partial {
            for b in 0..self.span() {
                local[self.local[b] as usize].x += matrix[k][b] * r;
            }
        } else {
            for b in 0..self.span() {
                local[self.local[b] as usize].x += r * self.mob[b];
            }
        }
    }
}

/// Wall time spent in the parts of the contact correction, summed over the steps since it was
/// switched on ([`ContactSolver::timings`]); for benchmarks and profiling.
#[derive(Clone, Debug, Default)]
pub struct ContactTimings {
    /// Search and the set-up of the active pairs (and the penalty forces).
    pub search: std::time::Duration,
    /// Warm start, colouring and the Gauss–Seidel lists.
    pub prepare: std::time::Duration,
    /// The Gauss–Seidel sweeps.
    pub sweeps: std::time::Duration,
    /// Writing the pairs' results into the history.
    pub record: std::time::Duration,
    /// Steps timed.
    pub steps: u64,
}

/// Scratch and settings of the contact correction. Holds no history (that is in `ContactState`).
pub struct ContactSolver<'m> {
    pub joints: &'m [ContactJoint],
    /// Gauss–Seidel stops when no node's displacement changed by more than this over a sweep [m]
    /// (the net change of the node, so that two pairs sharing a slave node — a node on the
    /// line where two joints meet — and trading force between their redundant constraints
    /// without moving it count as converged). Default 1e-12 × the largest joint size: far
    /// below any physical gap.
    pub gs_tolerance: f64,
    /// Sweep budget per step. Default 200.
    pub gs_max_sweeps: usize,
    /// Passes over the pairs of one shared slave node in [`shared_node_pass`], at most, per
    /// sweep (a count; only with an asperity envelope). Default 50, as measured on the branch
    /// that first tried it (docs/contact.md, "The bilinear envelope"): the two pairs'
    /// alternating updates settle within it where their problem has a consistent state, and a
    /// node whose pairs still trade force after it is left to the next sweep. 0 switches the
    /// pass off (for measurements).
    pub gs_shared_passes: usize,
    /// Start each pair that was in contact at the last step from its last force (applied to the
    /// prediction before the first sweep) instead of zero. Default true: the same fixed point,
    /// fewer sweeps (12.2 → 10.8 per step on the contact benchmark).
    pub gs_warm_start: bool,
    /// Sweep the pairs in colour order ([`Self::order_by_color`]) instead of the order of the
    /// slave nodes. Default true: the same fixed point in fewer sweeps (10.8 → 8.6 per step on
    /// the contact benchmark).
    pub gs_colored: bool,
    /// While true, every joint keeps its bond (cohesion, tensile strength) after a slip or an
    /// opening, as with `keep_cohesion`; a tensile rupture still ends it. Default false. The
    /// pipeline sets it during gravity equilibrium (scene `equilibrium.joint_bonds = "kept"`).
    pub keep_bonds: bool,
    /// When `Some`, each step adds the time of its parts (default `None`: no clock read).
    pub timings: Option<ContactTimings>,
    active: Vec<Active>,
    /// Scratch of [`Self::order_by_color`]: per local node the colours of its pairs, per pair
    /// its colour.
    color_mask: Vec<u64>,
    colors: Vec<u8>,
    /// The Gauss–Seidel order of the active pairs (indices into `active`).
    order: Vec<u32>,
    penalty: Vec<PenaltyPair>,
    /// Per task of the search (a joint's slave nodes in chunks of `search_chunk`), its
    /// scratch and results, kept between steps.
    search_chunks: Vec<SearchChunk>,
    /// Slave nodes per task of the parallel search. Default 256: the dam's joints (tens to
    /// thousands of slave nodes each) then share out evenly over the threads, and a task
    /// (about 256 × 0.3 µs) costs far more than its hand-over (about 1 µs). The result does not
    /// depend on it (the tasks' pairs are gathered in the order of one thread).
    pub search_chunk: usize,
    /// Pairs of one colour below which the colour is swept on one thread. Default 256: a
    /// smaller colour's pass (about 50 ns a pair) costs no more than waking the other threads.
    /// The result does not depend on it (module doc, "Threads").
    pub sweep_par_min: usize,
    /// Whether the sweeps (and with them the record) run on all threads or on one, chosen by
    /// timing the sweeps both ways every [`crate::par::ThreadChoice::PERIOD`] steps
    /// (docs/performance.md §7, "Two kinds of core pair": on two vCPUs that share no cache the
    /// parallel sweeps cost more than one thread's).
    /// Default: chosen by timing. `None`: always on all threads (tests of the parallel path).
    /// The result does not depend on it (module doc, "Threads").
    pub sweep_threads: Option<crate::par::ThreadChoice>,
    /// The colour runs of `order`: start, end, and whether the run is one colour (false: the
    /// pairs in search order, or the last colour, which takes every pair past 63 colours and
    /// may hold pairs that share a node); swept one after the other.
    color_runs: Vec<(u32, u32, bool)>,
    /// Per node 1/m for the pair mobilities (0 at a fully fixed node or one without inertia; at
    /// a block node its largest inverse mass; a partly fixed node has its 1/m, applied to its
    /// free components only).
    inv_mass: Vec<f64>,
    /// The partly fixed nodes with inertia (some but not all components fixed), ascending;
    /// empty for most models, which then never test for them.
    partial: Vec<u32>,
    /// Per active pair when `partial` is not empty (else empty): its nodes' mobilities per
    /// component (`mob` times each node's free components, 1 or 0).
    mob_matrix: Vec<[Matrix3<f64>; 5]>,
    /// The mortar pairs (`Method::Mortar`) and their scratch.
    mortar: MortarScratch,
    /// The free nodes with a 3×3 inertia block, ascending (empty for most models).
    block_nodes: Vec<u32>,
    /// Per joint and slave node, whether its pair is not formed (`joint::unformed_pairs`: the
    /// slaves of tied joints).
    unformed: Vec<Vec<bool>>,
    cand: Vec<u32>,
    /// Per model node, its place among the local nodes (see [`NodeScratch`]).
    node: Vec<NodeScratch>,
    /// Per active pair: the tick of its last evaluation (see [`LocalNode`]).
    evaluated_at: Vec<u32>,
    /// Count of steps so far (`NodeScratch::listed` compares with it).
    step_clock: u32,
    /// The nodes of the active pairs (fixed ones included: they enter the pairs' relative
    /// displacements), their model indices, and their displacement at the start of the sweep
    /// (the convergence test takes the net change of each node over a sweep).
    local: Vec<LocalNode>,
    local_global: Vec<u32>,
    sweep_start: Vec<Vector3<f64>>,
    /// With the sweeps on all threads: the local nodes of each thread's part of the active pairs
    /// (`local_cuts_of_into`), for the sweeps' change and the record's write-back.
    local_cuts: Vec<usize>,
    /// The record's per-pair results when it runs on all threads: joint, work [J], re-entry,
    /// summed into the joints in pair order after.
    pair_work: Vec<(u32, f64, bool)>,
    /// The shared-node pass ([`shared_node_pass`]): the active pairs (indices into `active`) of
    /// the slave nodes with pairs on two or more joints with an asperity envelope, grouped by
    /// node (`shared_runs`: start and end in `shared_pairs`), in the order of the nodes' local
    /// indices; empty when no joint has an envelope.
    shared_pairs: Vec<u32>,
    shared_runs: Vec<(u32, u32)>,
}

impl<'m> ContactSolver<'m> {
    pub fn new(model: &Model, joints: &'m [ContactJoint]) -> ContactSolver<'m> {
        let size = joints.iter().map(|j| j.tag.size).fold(0.0, f64::max);
        let mass = &model.mass;
        // a node with a free component moves under contact forces (on its free components)
        let movable = |n: usize| model.fixed[n] != ALL_FIXED;
        let mut inv_mass: Vec<f64> = (0..model.n_nodes()).map(|n| if movable(n) && mass.inertial[n] > 0.0 { 1.0 / mass.inertial[n] } else { 0.0 }).collect();
        // a block node: its largest inverse mass (for the penalty bound and the colouring's
        // test of a moving node); the pairs read it as their mobility and move the node by the
        // full block (`mob_matrix`;
        // the block's inverse is already restricted to the free components)
        let block_nodes: Vec<u32> = mass.blocks.iter().filter(|b| movable(b.node as usize)).map(|b| b.node).collect();
        for b in &mass.blocks {
            let n = b.node as usize;
            inv_mass[n] = if movable(n) { b.inverse.symmetric_eigenvalues().max().max(0.0) } else { 0.0 };
        }
        let unformed = super::joint::unformed_pairs(joints);
        let partial: Vec<u32> = (0..model.n_nodes()).filter(|&n| model.fixed[n] != 0 && inv_mass[n] > 0.0).map(|n| n as u32).collect();
        ContactSolver { mortar: MortarScratch::default(), block_nodes, unformed, partial, mob_matrix: Vec::new(), joints, gs_tolerance: 1e-12 * size.max(1e-300), gs_max_sweeps: 200, gs_shared_passes: 50, gs_warm_start: true, keep_bonds: false, timings: None, gs_colored: true, color_mask: Vec::new(), colors: Vec::new(), order: Vec::new(), active: Vec::new(), penalty: Vec::new(), search_chunks: Vec::new(), search_chunk: 256, sweep_par_min: 256, sweep_threads: Some(crate::par::ThreadChoice::default()), color_runs: Vec::new(), node: vec![NodeScratch::default(); model.n_nodes()], evaluated_at: Vec::new(), step_clock: 0, local: Vec::new(), local_global: Vec::new(), sweep_start: Vec::new(), local_cuts: Vec::new(), pair_work: Vec::new(), shared_pairs: Vec::new(), shared_runs: Vec::new(), inv_mass, cand: Vec::new() }
    }

    /// Slave faces whose mortar integrals were evaluated so far, all mortar joints together (the
    /// cost counter of their caching, [`MORTAR_REEVALUATE`]).
    pub fn mortar_face_evaluations(&self) -> u64 {
        self.mortar.face_evaluations
    }

    /// Whether `node` is partly fixed (and moves on its free components only).
    #[inline]
    fn is_partial(&self, node: u32) -> bool {
        !self.partial.is_empty() && self.partial.binary_search(&node).is_ok()
    }

    /// Largest ω² added by penalty springs (Gershgorin bound on M^{-1/2} K_pen M^{-1/2},
    /// with full weights at the nodes of the initial centre's faces) [1/s²]; 0 without penalty joints.
    pub fn penalty_omega2_bound(&self, model: &Model) -> f64 {
        let mut row = vec![0.0; model.n_nodes()];
        for j in self.joints {
            let Method::Penalty { kn, kt } = j.method else { continue };
            let k = kn.max(kt);
            for i in 0..j.tag.n_slave() {
                let s = j.tag.slave_nodes()[i];
                let o = j.tag.nearest_master_node(i);
                let ka = k * j.tag.areas[i];
                // spring between s and o (worst case: all weight on one master node)
                let (bs, bo) = (self.inv_mass[s].sqrt(), self.inv_mass[o].sqrt());
                row[s] += ka * bs * (bs + bo);
                row[o] += ka * bo * (bs + bo);
            }
        }
        row.into_iter().fold(0.0, f64::max)
    }

    /// The joint's law as it applies now: with [`Self::keep_bonds`] its bond is kept.
    fn law_in_force(&self, j: &ContactJoint) -> JointLaw {
        if self.keep_bonds { JointLaw { keep_cohesion: true, ..j.law } } else { j.law }
    }

    /// The sweep order (`order`, indices into `active`) by colour: a greedy colouring in which
    /// no two pairs of one colour share a moving node (pairs in their order of the search, each
    /// the lowest colour none of its nodes has yet; 4 colours on a structured quad master), then
    /// a stable counting sort by colour (of the indices: copying the active pairs into that
    /// order cost more than the sweeps' indirect reads save). The pairs of one colour are uncoupled, so one pass over them solves them
    /// exactly together, and the sweeps converge faster than in the order of the slave nodes
    /// (10.8 → 8.6 sweeps per step on the contact benchmark, and the same 18 on the wedge).
    /// Deterministic: the colours follow from the active pairs alone. Needs the local nodes
    /// listed first (the masks are per local node).
    fn order_by_color(&mut self) {
        let mut count = [0usize; 64];
        self.colors.clear();
        self.color_mask.clear();
        self.color_mask.resize(self.local.len(), 0);
        for a in &self.active {
            let free = |b: &usize| self.inv_mass[a.nodes[*b] as usize] > 0.0;
            let entries = 0..a.nm as usize + 1;
            let used = entries.clone().filter(free).fold(0u64, |m, b| m | self.color_mask[a.local[b] as usize]);
            let c = (!used).trailing_zeros().min(63);
            for b in entries.filter(free) {
                self.color_mask[a.local[b] as usize] |= 1u64 << c;
            }
            self.colors.push(c as u8);
            count[c as usize] += 1;
        }
        let mut start = [0usize; 64];
        for c in 1..64 {
            start[c] = start[c - 1] + count[c - 1];
        }
        self.color_runs.clear();
        for c in 0..64 {
            if count[c] > 0 {
                self.color_runs.push((start[c] as u32, (start[c] + count[c]) as u32, c < 63));
            }
        }
        self.order.clear();
        self.order.resize(self.active.len(), 0);
        for (k, &c) in self.colors.iter().enumerate() {
            self.order[start[c as usize]] = k as u32;
            start[c as usize] += 1;
        }
    }

}

/// The candidate master faces around master-local node `center` into `cand`: its faces
/// (Layer1), with `layer` 2 also the faces of their nodes (Layer2), ascending.
fn candidates_into(cand: &mut Vec<u32>, j: &ContactJoint, center: u32, layer: u8) {
    cand.clear();
    let m = &j.tag.master;
    cand.extend_from_slice(m.faces_of_node(center as usize));
    if layer >= 2 {
        let n1 = cand.len();
        for k in 0..n1 {
            for &v in m.faces[cand[k] as usize].local_nodes() {
                cand.extend_from_slice(m.faces_of_node(v as usize));
            }
        }
        cand.sort_unstable();
        cand.dedup();
    }
}

/// Updates in a row of a pair with a partly fixed node or an inertia-block node within one
/// sweep (stopping early once an update moves no node by more than the marking tolerance): 32.
/// Its scalar mobility is the largest of its directions' (module doc), so when the normal or
/// the slip direction is at an angle to the free components, or the block makes a direction
/// heavier, one update leaves part of the pair's own residual (a fraction m_a/(m + m_a), about
/// 0.7, on the dam's wet joint nodes); repeating it costs nothing elsewhere (other pairs update
/// once). 8 was enough on the slide case with its slave face fixed in x (docs/contact.md,
/// "Partly fixed nodes"); on the coarse dam with a full reservoir released at rest, 8 left the
/// wet pairs' Gauss–Seidel unconverged step after step and the dam went unstable after 1.5 s
/// (crest velocity from 1e-3 to 13 m/s by 2 s), 32 keeps it at rest for 2 s with the energy
/// balance at 4e-15 (regression `dam_stays_at_rest_for_two_seconds_with_a_full_reservoir`).
const PARTIAL_PAIR_UPDATES: usize = 32;

/// `Model::fixed` of a node with all three components fixed.
const ALL_FIXED: u8 = 7;

/// A node's free components as a mask (1 free, 0 fixed).
#[inline]
fn free_mask(model: &Model, node: usize) -> Vector3<f64> {
    Vector3::from_fn(|c, _| if model.is_free(node, c) { 1.0 } else { 0.0 })
}

#[inline]
fn pos(model: &Model, u: &[f64], n: usize) -> Vector3<f64> {
    Vector3::from(model.mesh.nodes[n]) + disp(u, n)
}

#[inline]
fn disp(u: &[f64], n: usize) -> Vector3<f64> {
    let v = &u[3 * n..3 * n + 3];
    Vector3::new(v[0], v[1], v[2])
}

/// The positions at `u` of master face `f`'s nodes (Gmsh order; entries past its node count are
/// zero) and that count.
#[inline]
fn face_positions(model: &Model, j: &ContactJoint, f: usize, u: &[f64]) -> ([Vector3<f64>; 4], usize) {
    let nodes = j.tag.master.faces[f].nodes();
    let mut x = [Vector3::zeros(); 4];
    for (a, &nd) in nodes.iter().enumerate() {
        x[a] = pos(model, u, nd as usize);
    }
    (x, nodes.len())
}

/// Project on one master face `f` (the face of the last step, or a candidate set of one): no
/// candidate buffer, no selection, and a quad's Newton starts from the node's local coordinates
/// of the last step (`xi0`). Also returns the squared length of the face's first edge (the
/// search's test of nearness along the normal).
#[allow(clippy::too_many_arguments)]
fn project_on_face(
    model: &Model,
    j: &ContactJoint,
    f: usize,
    xs: &Vector3<f64>,
    n: &Vector3<f64>,
    u: &[f64],
    failures: &mut u64,
    tol: f64,
    xi0: [f64; 2],
) -> Option<(super::query::Projection, f64)> {
    let (x, k) = face_positions(model, j, f, u);
    let edge2 = (x[1] - x[0]).norm_squared();
    let p = match k {
        3 => project_along_on_tri(xs, n, [&x[0], &x[1], &x[2]], tol),
        4 => match project_along_on_quad_from(xs, n, [&x[0], &x[1], &x[2], &x[3]], tol, xi0) {
            Ok(p) => p,
            Err(_) => {
                *failures += 1;
                None
            }
        },
        _ => {
            *failures += 1;
            None
        }
    };
    p.map(|p| (p, edge2))
}

/// Project slave node `i` of joint `j` on the master faces `faces` at the positions `u` (a
/// quad's Newton from its centre).
#[allow(clippy::too_many_arguments)]
fn project_on(
    model: &Model,
    j: &ContactJoint,
    faces: &[u32],
    xs: &Vector3<f64>,
    n: &Vector3<f64>,
    u: &[f64],
    failures: &mut u64,
    tol: f64,
) -> Option<(usize, super::query::Projection)> {
    if let [f] = faces {
        return project_on_face(model, j, *f as usize, xs, n, u, failures, tol, [0.0, 0.0]).map(|(p, _)| (*f as usize, p));
    }
    // candidate sets are small (Layer2 of a structured quad mesh: 16 faces); the stack buffer
    // avoids an allocation per node and step, larger sets fall back to the heap
    let mut stack: [(usize, [Vector3<f64>; 4], usize); 24] = [(0, [Vector3::zeros(); 4], 0); 24];
    let mut heap: Vec<(usize, [Vector3<f64>; 4], usize)> = Vec::new();
    let mut count = 0;
    for &f in faces {
        let (x, k) = face_positions(model, j, f as usize, u);
        if count < stack.len() {
            stack[count] = (f as usize, x, k);
        } else {
            if heap.is_empty() {
                heap.extend_from_slice(&stack);
            }
            heap.push((f as usize, x, k));
        }
        count += 1;
    }
    let pts: &[(usize, [Vector3<f64>; 4], usize)] = if heap.is_empty() { &stack[..count] } else { &heap };
    match select_projection(xs, n, pts.iter().map(|(f, x, k)| (*f, &x[..*k])), tol) {
        Ok(p) => p,
        Err(_) => {
            // a face whose quad solve failed: retry without the failing faces one by one
            *failures += 1;
            let mut best: Option<(usize, super::query::Projection)> = None;
            for (f, x, k) in pts {
                if let Ok(Some((ff, p))) = select_projection(xs, n, std::iter::once((*f, &x[..*k])), tol) {
                    best = match best {
                        Some((bf, bp)) if bp.t.abs() <= p.t.abs() => Some((bf, bp)),
                        _ => Some((ff, p)),
                    };
                }
            }
            best
        }
    }
}

/// Add the displacement that a pair force `r` (on the slave node, N; the masters take −N_I r)
/// makes over one step, dt² r / m, to `u` (free nodes only: `inv_mass` is 0 at fixed ones).
fn add_pair_force_into(u: &mut [f64], inv_mass: &[f64], dt2: f64, slave: u32, masters: &[u32], weights: &[f64; 4], r: &Vector3<f64>) {
    let s = slave as usize;
    let im = inv_mass[s];
    for c in 0..3 {
        u[3 * s + c] += dt2 * r[c] * im;
    }
    for (a, &m) in masters.iter().enumerate() {
        let mi = m as usize;
        let imi = inv_mass[mi];
        for c in 0..3 {
            u[3 * mi + c] -= dt2 * weights[a] * r[c] * imi;
        }
    }
}

/// The largest squared net change of the local nodes since `start` (their displacements at the
/// start of the sweep), with `start` updated to the current displacements for the next sweep.
/// Four running maxima, so that the loop is not one chain of dependent comparisons (one
/// `f64::max` chain and a separate snapshot pass were a quarter of the Gauss–Seidel time). Like
/// `f64::max`, a NaN change is not taken (the step's finiteness check reports non-finite
/// displacements).
fn sweep_change_into(local: &[LocalNode], start: &mut [Vector3<f64>]) -> f64 {
    let mut m = [0.0f64; 4];
    for (x0s, ls) in start.chunks_mut(4).zip(local.chunks(4)) {
        for (lane, (x0, l)) in x0s.iter_mut().zip(ls).enumerate() {
            let x = l.x;
            let d = (x - *x0).norm_squared();
            if d > m[lane] {
                m[lane] = d;
            }
            *x0 = x;
        }
    }
    m[0].max(m[1]).max(m[2].max(m[3]))
}

/// The local nodes of each part of the active pairs (part p: pairs `n p / parts ..
/// n (p + 1) / parts`, about the stretch of the joints whose pairs [`sweep_colors`] gives part
/// p in each colour): `parts + 1` cuts into the
/// local nodes, the nodes first listed by part p's pairs being `cuts[p]..cuts[p + 1]` (they are
/// numbered in the order the pairs meet them, `list_pairs_into`; the mortar pairs' nodes come
/// last, in the last part). Any cuts give the same result; these keep each thread on its nodes.
fn local_cuts_of_into(cuts: &mut Vec<usize>, active: &[Active], n_local: usize, parts: usize) {
    let n = active.len();
    cuts.clear();
    cuts.resize(parts + 1, 0);
    let mut seen = 0usize;
    let mut k = 0;
    for p in 1..parts {
        let end = n * p / parts;
        while k < end {
            let a = &active[k];
            seen = a.local[..a.span()].iter().fold(seen, |m, &l| m.max(l as usize + 1));
            k += 1;
        }
        cuts[p] = seen.min(n_local);
    }
    cuts[parts] = n_local;
}

/// One Gauss–Seidel pass over the node-to-segment pairs, run by run of `color_runs` (indices
/// into `order`): a run that is one colour gives all its pairs one tick of the clock and, with
/// `parallel` and at least `par_min` pairs, is shared out over the threads in one part per
/// thread, part p being its pairs p L / T .. (p + 1) L / T (L pairs, T threads, in the active
/// order), so that a thread keeps about the same pairs and nodes in its cache from colour to
/// colour (rayon's join gives the caller the first part; equal counts rather than a fixed cut
/// of the active pairs, which left the parts of a colour 14 % apart and the step 1.4 % slower);
/// another run ticks per pair, on one thread. The same result on any number
/// of threads (module doc, "Threads"). Returns what [`sweep_pass`] returns, summed.
#[allow(clippy::too_many_arguments)]
fn sweep_colors<const LISTED: bool>(active: &mut [Active], order: &[u32], color_runs: &[(u32, u32, bool)], local: &mut [LocalNode], evaluated_at: &mut [u32], clock: &mut u32, laws: &[JointLaw], mark_tol2: f64, mob_matrix: &[[Matrix3<f64>; 5]], parallel: bool, par_min: usize) -> usize {
    let (pa, pl, pe) = (Shared::of(active), Shared::of(local), Shared::of(evaluated_at));
    let mut moving = 0;
    for &(start, end, colour) in color_runs {
        let run = &order[start as usize..end as usize];
        if !colour {
            // SAFETY: one thread
            moving += unsafe { sweep_pass::<LISTED, 5>(pa, run, pl, pe, clock, true, laws, mark_tol2, mob_matrix) };
            continue;
        }
        // One tick for the colour: its pairs share no moving node, so none of them moves a node
        // of another, and whether a pair is evaluated again depends only on the ticks of the
        // other colours, which keep their order.
        *clock += LISTED as u32;
        let tick = *clock;
        let pass = |pairs: &[u32]| {
            let mut t = tick;
            // SAFETY: the pairs of one colour, each in one chunk: a pair and its moving nodes are
            // written by the thread of its chunk alone, and the nodes two pairs of the colour
            // share are fixed ones, which no pair writes (`update_pair`)
            unsafe { sweep_pass::<LISTED, 5>(pa, pairs, pl, pe, &mut t, false, laws, mark_tol2, mob_matrix) }
        };
        moving += if parallel && run.len() >= par_min {
            crate::par::region();
            // part p: the colour's pairs p L / T .. (p + 1) L / T (L pairs, T threads); the
            // colour lists its pairs in the active order, so part p is about the same stretch of
            // the joints in every colour and a thread keeps its pairs and nodes
            let parts = rayon::current_num_threads();
            let cut = |p: usize| run.len() * p / parts;
            (0..parts).into_par_iter().with_max_len(1).map(|p| pass(&run[cut(p)..cut(p + 1)])).sum::<usize>()
        } else {
            pass(run)
        };
    }
    moving
}

/// The groups of the shared-node pass: pairs (indices into the active pairs), their runs by
/// slave node, the squared change [m²] below which a node's pairs count as solved together, and
/// the most passes per node (`ContactSolver::gs_shared_passes`).
struct SharedGroups<'a> {
    pairs: &'a [u32],
    runs: &'a [(u32, u32)],
    tol2: f64,
    passes: usize,
}

/// The shared-node pass (after each sweep's colours, only with an asperity envelope): the pairs
/// of each slave node that has pairs on two joints (`shared.runs`) updated in turn, again and
/// again, until a pass over them changes none of their nodes by more than the tolerance, at most
/// `shared.passes` times. Such a node is constrained by two pairs against two master
/// planes; one pair's update undoes part of the other's, and in a sweep they meet once: solved
/// together, the node's two-pair problem is settled before the rest of the joint sees it. With
/// `LISTED` the updates stamp the nodes they move (one tick per pair), so that the work list
/// takes the pairs on them in the next sweep. One thread, in the groups' order: deterministic,
/// and the same on any number of threads.
#[allow(clippy::too_many_arguments)]
fn shared_node_pass<const LISTED: bool>(active: &mut [Active], shared: &SharedGroups<'_>, local: &mut [LocalNode], evaluated_at: &mut [u32], clock: &mut u32, laws: &[JointLaw], mark_tol2: f64, mob_matrix: &[[Matrix3<f64>; 5]]) {
    let mut before: Vec<(u32, Vector3<f64>)> = Vec::new();
    for &(start, end) in shared.runs {
        let group = &shared.pairs[start as usize..end as usize];
        before.clear();
        for &k in group {
            let a = &active[k as usize];
            before.extend(a.local[..a.span()].iter().map(|&l| (l, Vector3::zeros())));
        }
        for _ in 0..shared.passes {
            for (l, x) in before.iter_mut() {
                *x = local[*l as usize].x;
            }
            let (pa, pl, pe) = (Shared::of(active), Shared::of(local), Shared::of(evaluated_at));
            // SAFETY: one thread
            unsafe { sweep_pass::<LISTED, 5>(pa, group, pl, pe, clock, true, laws, mark_tol2, mob_matrix) };
            if before.iter().all(|(l, x)| (local[*l as usize].x - x).norm_squared() <= shared.tol2) {
                break;
            }
        }
    }
}

/// One Gauss–Seidel pass over the active pairs in `order` (see [`ContactSolver::sweep_into`]):
/// with `LISTED`, only the pairs one of whose nodes moved since their last evaluation, stamping
/// the nodes each update moves at `clock` (advanced per pair with `tick_per_pair`); without,
/// every pair and no clocks. Returns how many pairs moved a node by more than the marking
/// tolerance (counted without `LISTED` only). Two copies of the loop rather than a test per
/// pair, so that the full pass carries nothing of the list.
///
/// SAFETY: no other thread reads or writes the pairs in `order` or their moving nodes, nor
/// writes their other nodes, while the pass runs ([`Shared`]).
#[inline(never)] // its own code, whatever the code around it (a sweep is long; one call per sweep)
#[allow(clippy::too_many_arguments)]
unsafe fn sweep_pass<const LISTED: bool, const N: usize>(active: Shared<Active<N>>, order: &[u32], local: Shared<LocalNode>, evaluated_at: Shared<u32>, clock: &mut u32, tick_per_pair: bool, laws: &[JointLaw], mark_tol2: f64, mob_matrix: &[[Matrix3<f64>; N]]) -> usize {
    let mut moving = 0;
    for &k in order.iter() {
        let k = k as usize;
        // SAFETY: pair k is this pass's alone (the function's contract)
        let a = unsafe { active.at(k) };
        if LISTED {
            // SAFETY: as above
            let e = unsafe { evaluated_at.at(k) };
            if !moved_since_with(a, *e, |l| unsafe { local.get(l).moved_at }) {
                continue;
            }
            *clock += tick_per_pair as u32;
            *e = *clock;
        }
        // SAFETY (the updates): the contract, passed on
        if a.partial {
            // a pair with a partly fixed node repeats its update (its scalar mobility is an
            // upper bound of its directions', so one update may leave part of its own
            // residual: `PARTIAL_PAIR_UPDATES`), until an update moves no node
            let moved = unsafe { update_pair::<LISTED, true, N>(a, k, local, *clock, laws, mark_tol2, mob_matrix) };
            moving += moved as usize;
            if moved {
                for _ in 1..PARTIAL_PAIR_UPDATES {
                    if !unsafe { update_pair::<LISTED, true, N>(a, k, local, *clock, laws, mark_tol2, mob_matrix) } {
                        break;
                    }
                }
            }
        } else {
            moving += unsafe { update_pair::<LISTED, false, N>(a, k, local, *clock, laws, mark_tol2, mob_matrix) } as usize;
        }
    }
    if LISTED { 0 } else { moving }
}

/// One update of active pair `a` (index `k`) in a sweep: its force from the current positions
/// of its local nodes with its own force removed, its moving nodes moved by the change (a fixed
/// node or an unused entry, mobility 0, is neither moved nor written), and with `LISTED` the
/// nodes it moves by more than the marking tolerance stamped at `clock`. `PARTIAL`: the pair
/// has a partly fixed node and moves its nodes by `mob_matrix[k]`. Returns whether the update
/// moved a node by more than the marking tolerance.
///
/// SAFETY: no other thread writes the pair's nodes, or reads its moving ones, meanwhile.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
unsafe fn update_pair<const LISTED: bool, const PARTIAL: bool, const N: usize>(a: &mut Active<N>, k: usize, local: Shared<LocalNode>, clock: u32, laws: &[JointLaw], mark_tol2: f64, mob_matrix: &[[Matrix3<f64>; N]]) -> bool {
    let [n, t1, t2] = a.frame;
    // current relative quantities with all forces applied so far
    // SAFETY: the pair's nodes, which no other thread writes (the contract)
    let rel = a.relative_displacement_with(|l| unsafe { local.get(l).x });
    let g_cur = a.gap0 + n.dot(&rel);
    let dd = a.rel_u - rel;
    // remove the pair's own force: g = g̃ + dt²w r_n, Δd = Δd̃ + dt²w R
    let g_trial = g_cur - a.dt2w * a.r_n;
    let dt_trial = Vector2::new(dd.dot(&t1), dd.dot(&t2)) - a.dt2w * a.r_t;
    let resp = pair_force_with_inverse(&laws[a.joint as usize], &a.hist0, g_trial, dt_trial, a.dt2w, a.inv_dt2w, a.area);
    let d_rn = resp.r_n - a.r_n;
    let d_rt = resp.r_t - a.r_t;
    // move the nodes by the force change (a fixed node or an unused entry has
    // mobility 0 and does not move); the pairs on a node moved by more than the
    // marking tolerance must be evaluated again (the clock only grows, so the max
    // marks without a branch)
    let dr = -n * d_rn + t1 * d_rt.x + t2 * d_rt.y;
    // |du|² = |dr|² mob²: one norm per pair instead of one per node
    let dr2 = dr.norm_squared();
    for b in 0..a.span() {
        if a.mob[b] == 0.0 {
            continue;
        }
        // SAFETY: a moving node of this pair, no other thread's (the contract)
        let l = unsafe { local.at(a.local[b] as usize) };
        if LISTED {
            l.moved_at = l.moved_at.max(clock * (dr2 * (a.mob[b] * a.mob[b]) > mark_tol2) as u32);
        }
        if PARTIAL {
            l.x += mob_matrix[k][b] * dr;
        } else {
            l.x += dr * a.mob[b];
        }
    }
    a.gap = g_trial + a.dt2w * resp.r_n;
    a.r_n = resp.r_n;
    a.r_t = resp.r_t;
    a.hist = resp.hist;
    a.state = resp.state;
    dr2 * a.mob2_max > mark_tol2
}

/// Whether active pair `a`, last evaluated at tick `since`, has a node moved after it.
#[inline(always)]
fn moved_since<const N: usize>(local: &[LocalNode], a: &Active<N>, since: u32) -> bool {
    moved_since_with(a, since, |l| local[l].moved_at)
}

/// [`moved_since`] with the local nodes' ticks read by `moved_at`.
#[inline(always)]
fn moved_since_with<const N: usize>(a: &Active<N>, since: u32, moved_at: impl Fn(usize) -> u32) -> bool {
    a.local[..a.span()].iter().fold(0, |m, &l| m.max(moved_at(l as usize))) > since
}

impl ContactSolver<'_> {
    /// Search and set-up (the first part of a step): every slave node's pair on the prediction
    /// `u_next` (or on `u` for a penalty joint), the active list of the dynamic-force pairs,
    /// and the penalty forces of step n applied to the prediction. Returns the penalty work [J].
    #[inline(never)] // out of line, so that profiles show the four parts of a step
    fn search_into(&mut self, model: &Model, history: &mut ContactState, dt2: f64, u_prev: &[f64], u: &[f64], u_next: &mut [f64]) -> Result<f64, StepError> {
        self.active.clear();
        self.mob_matrix.clear();
        self.mortar.active.clear();
        self.mortar.mob_matrix.clear();
        self.penalty.clear();
        let joints = self.joints;
        for (ji, j) in joints.iter().enumerate() {
            if j.method == Method::Mortar {
                self.mortar_search_into(model, j, ji, &mut history.joints[ji], dt2, u, u_next)?;
            }
        }
        // the other joints in chunks of slave nodes, in parallel; each chunk's pairs are
        // appended in the order of the joints and of their slave nodes, as one thread would
        // list them (the pairs are independent in the search: each writes its own record)
        let mut chunks = std::mem::take(&mut self.search_chunks);
        let mut tasks: Vec<(usize, usize, &mut [PairRecord])> = Vec::new();
        let chunk = self.search_chunk.max(1);
        for (ji, rec) in history.joints.iter_mut().enumerate() {
            if joints[ji].method != Method::Mortar {
                tasks.extend(rec.pairs.chunks_mut(chunk).enumerate().map(|(c, pairs)| (ji, c * chunk, pairs)));
            }
        }
        if chunks.len() < tasks.len() {
            chunks.resize_with(tasks.len(), SearchChunk::default);
        }
        let task_joints: Vec<usize> = tasks.iter().map(|t| t.0).collect();
        let this = &*self;
        let prediction: &[f64] = u_next;
        let search = |(ji, first, pairs): &mut (usize, usize, &mut [PairRecord]), out: &mut SearchChunk| this.search_chunk_into(model, *ji, *first, pairs, out, dt2, u_prev, u, prediction);
        if rayon::current_num_threads() > 1 {
            crate::par::region();
            tasks.par_iter_mut().zip(chunks.par_iter_mut()).for_each(|(t, out)| search(t, out));
        } else {
            tasks.iter_mut().zip(chunks.iter_mut()).for_each(|(t, out)| search(t, out));
        }
        // the pairs and their matrices (a few MB on the fine dam) copied on all threads, each
        // task's mostly by the thread that searched it
        crate::par::concat_into(&mut self.active, &mut chunks, |c| &mut c.active);
        crate::par::concat_into(&mut self.mob_matrix, &mut chunks, |c| &mut c.mob_matrix);
        for (out, &ji) in chunks.iter_mut().zip(&task_joints) {
            self.penalty.append(&mut out.penalty);
            history.joints[ji].events.add(&out.events);
            out.events = SearchEvents::default();
        }
        self.search_chunks = chunks;
        Ok(self.apply_penalty_into(model, dt2, u_prev, u_next))
    }

    /// The search of slave nodes `first..first + pairs.len()` of joint `ji` (not a mortar joint),
    /// whose records are `pairs`: their active pairs, mobility matrices, penalty forces and
    /// search events into `out`.
    #[allow(clippy::too_many_arguments)]
    fn search_chunk_into(&self, model: &Model, ji: usize, first: usize, pairs: &mut [PairRecord], out: &mut SearchChunk, dt2: f64, u_prev: &[f64], u: &[f64], u_next: &[f64]) {
        let j = &self.joints[ji];
        let SearchChunk { active, mob_matrix, penalty, events: ev, cand } = out;
        // penalty works on the configuration at t[n]; the dynamic force on the prediction
        let conf: &[f64] = if matches!(j.method, Method::Penalty { .. }) { u } else { u_next };
        for (k, pr) in pairs.iter_mut().enumerate() {
            let i = first + k;
            let s = j.tag.slave_nodes()[i];
            let xs = pos(model, conf, s);
            // lost in the step before (searched, no gap): finding a face now is a re-entry
            let was_lost = pr.searched && pr.gap.is_nan();
            pr.searched = true;
            pr.reentered = false;
            let pm = match j.method {
                Method::Ntn => PairMasters { nodes: [j.tag.nearest_master_node(i) as u32, 0, 0, 0], nm: 1, weights: [1.0, 0.0, 0.0, 0.0], face: -1 },
                _ => match Self::nts_face_into(model, j, pr, ev, cand, i, &xs, conf) {
                    Some((f, p)) => masters_on_face(j, pr, ev, f, &p),
                    None => {
                        lose_pair(pr, ev);
                        // beyond the master's free edge (expected) or lost inside it
                        candidates_into(cand, j, pr.center, 2);
                        let near = free_edge::outline_faces(&j.tag.master, cand, |g| pos(model, conf, g));
                        let beyond = free_edge::lost_where(&near, &xs, &j.frames[i][0]) == free_edge::LostWhere::BeyondFreeEdge;
                        pr.beyond_edge = beyond;
                        ev.lost_beyond_edge += u64::from(beyond);
                        continue;
                    }
                },
            };
            // A pair whose slave node is the slave of a (later) tied joint is not formed
            // (`joint::unformed_pairs`: the tie fixes the node): reported bonded, with no
            // force of its own.
            if self.unformed[ji][i] {
                unform_pair(pr);
                continue;
            }
            let Some(mobility) = self.pair_mobility(model, s, &j.frames[i][0], &pm) else { continue };
            pr.reentered = was_lost && !matches!(j.method, Method::Penalty { .. });
            if j.hold_reentry && pr.reentered {
                // re-entry: its predicted penetration counts as closed (`PairRecord::entry_offset`)
                pr.entry_offset = predicted_gap(model, j, pr, i, &pm, conf).min(0.0);
            }
            if let Method::Penalty { kn, kt } = j.method {
                penalty.push(self.penalty_pair_into(model, j, pr, i, &pm, (kn, kt), &xs, u_prev, u));
            } else {
                // a dynamic-force pair, warm-started from its force of the last step
                let (a, matrix) = self.active_pair(model, j, ji, pr, i, &pm, &mobility, dt2, u, j.tag.areas[i]);
                active.push(a);
                mob_matrix.extend(matrix);
                pr.face = pm.face;
            }
        }
    }

    /// The mortar pairs of joint `j` (`Method::Mortar`) on the prediction `u_next`
    /// (docs/contact.md, "Dual mortar"): the mortar integrals of every slave face with the master
    /// faces of its candidate set (Layer2 around the centres of its nodes), on the predicted
    /// positions, re-evaluated for the faces that slid or changed candidates
    /// ([`MORTAR_REEVALUATE`]); summed per slave node into `D_jj` and `M_jk`; then one pair per
    /// slave node whose master is `Σ_k (M_jk / D_jj) x_k`, forced as a node-to-segment pair is.
    /// Each node's centre follows the master node of its largest weight.
    #[allow(clippy::too_many_arguments)]
    fn mortar_search_into(&mut self, model: &Model, j: &ContactJoint, ji: usize, rec: &mut JointRecord, dt2: f64, u: &[f64], u_next: &[f64]) -> Result<(), StepError> {
        let n_s = j.tag.n_slave();
        if self.mortar.joints.len() <= ji {
            self.mortar.joints.resize_with(ji + 1, MortarJoint::default);
        }
        let mut mj = std::mem::take(&mut self.mortar.joints[ji]);
        if mj.faces.len() != j.tag.slave.faces.len() || mj.d.len() != n_s {
            mj = MortarJoint::sized(j);
        }
        let overflow = self.mortar_integrals_into(model, j, rec, u_next, &mut mj);
        if let Some(i) = overflow {
            return Err(mortar_overflow(j, i));
        }
        let ms = &j.tag.master;
        for i in 0..n_s {
            if self.unformed[ji][i] {
                unform_pair(&mut rec.pairs[i]);
                continue;
            }
            let (ml, mv, cnt) = mj.rows[i];
            let di = mj.d[i];
            if !(di >= MORTAR_MIN_COVER * j.tag.areas[i]) {
                lose_pair(&mut rec.pairs[i], &mut rec.events);
                continue;
            }
            let mut pm = PairMasters::<MORTAR_MASTERS> { nodes: [0; MORTAR_MASTERS], nm: cnt, weights: [0.0; MORTAR_MASTERS], face: -1 };
            let mut best = (f64::MIN, 0u32);
            for k in 0..cnt as usize {
                pm.nodes[k] = ms.nodes[ml[k] as usize] as u32;
                pm.weights[k] = mv[k] / di;
                if pm.weights[k] > best.0 {
                    best = (pm.weights[k], ml[k]);
                }
            }
            if rec.pairs[i].center != best.1 {
                rec.pairs[i].center = best.1;
                rec.events.recentred += 1;
            }
            // the face reported for the pair: a master face at its centre
            pm.face = ms.faces_of_node(best.1 as usize).first().map_or(-1, |&f| f as i32);
            let s = j.tag.slave_nodes()[i];
            let Some(mobility) = self.pair_mobility::<MORTAR_MASTERS, MORTAR_NODES>(model, s, &j.frames[i][0], &pm) else { continue };
            let (a, matrix) = self.active_pair(model, j, ji, &rec.pairs[i], i, &pm, &mobility, dt2, u, di);
            self.mortar.active.push(a);
            self.mortar.mob_matrix.extend(matrix);
            rec.pairs[i].face = pm.face;
        }
        self.mortar.joints[ji] = mj;
        Ok(())
    }

    /// The mortar master point of every slave node of mortar joint `ji` at the displacements
    /// `u`: its master nodes (model indices) with their weights `c_k = M_jk / D_jj`, and `D_jj`
    /// [m²], from integrals evaluated afresh at `u` (the candidate sets around the centres of
    /// `rec`); `None` for a node below the cover of a pair ([`MORTAR_MIN_COVER`]). What the
    /// static stages pair a mortar joint's slave node with (`statics::contact`, and grouting
    /// through [`Self::mortar_gaps`]).
    #[allow(clippy::type_complexity)]
    pub fn mortar_master_points(&mut self, model: &Model, ji: usize, rec: &JointRecord, u: &[f64]) -> Result<Vec<Option<(Vec<(usize, f64)>, f64)>>, StepError> {
        let j = &self.joints[ji];
        let n_s = j.tag.n_slave();
        let mut mj = MortarJoint::sized(j);
        if let Some(i) = self.mortar_integrals_into(model, j, rec, u, &mut mj) {
            return Err(mortar_overflow(j, i));
        }
        Ok((0..n_s)
            .map(|i| {
                let (ml, mv, cnt) = mj.rows[i];
                let di = mj.d[i];
                (di >= MORTAR_MIN_COVER * j.tag.areas[i]).then(|| ((0..cnt as usize).map(|k| (j.tag.master.nodes[ml[k] as usize], mv[k] / di)).collect(), di))
            })
            .collect())
    }

    /// The weighted gap of every slave node of mortar joint `ji` at the displacements `u` [m]:
    /// `n_j · (Σ_k c_k x_k − x_j)` with the master points of [`Self::mortar_master_points`], the
    /// gap offset not subtracted; `None` below the cover. What grouting a mortar joint closes
    /// (`statics::sequence::grout_pairs`): the gap the mortar pairs measure.
    pub fn mortar_gaps(&mut self, model: &Model, ji: usize, rec: &JointRecord, u: &[f64]) -> Result<Vec<Option<f64>>, StepError> {
        let points = self.mortar_master_points(model, ji, rec, u)?;
        let j = &self.joints[ji];
        Ok(points
            .into_iter()
            .enumerate()
            .map(|(i, p)| {
                p.map(|(masters, _)| {
                    let xbar = masters.iter().fold(-pos(model, u, j.tag.slave_nodes()[i]), |x, &(m, c)| x + pos(model, u, m) * c);
                    j.frames[i][0].dot(&xbar)
                })
            })
            .collect())
    }

    /// Whether slave face `f` of joint `j` must be re-evaluated at `u_next`: never evaluated, a
    /// node's centre changed, or a node slid relative to its centre by more than
    /// [`MORTAR_REEVALUATE`] of the face size since the evaluation.
    fn mortar_face_stale(j: &ContactJoint, rec: &JointRecord, fi: &FaceIntegrals, f: usize, u_next: &[f64]) -> bool {
        if !fi.evaluated {
            return true;
        }
        let limit2 = (MORTAR_REEVALUATE * fi.size).powi(2);
        j.tag.slave.faces[f].local_nodes().iter().enumerate().any(|(a, &l)| {
            let c = rec.pairs[l as usize].center;
            if c != fi.centre[a] {
                return true;
            }
            let dr = disp(u_next, j.tag.slave_nodes()[l as usize]) - disp(u_next, j.tag.master.nodes[c as usize]) - fi.rel[a];
            let n = j.frames[l as usize][0];
            (dr - n * n.dot(&dr)).norm_squared() > limit2
        })
    }

    /// Bring the mortar integrals of joint `j` up to date at the positions `u_next`: the stale
    /// faces ([`Self::mortar_face_stale`]) re-evaluated, then `D_jj` and the rows of their
    /// nodes summed again from the faces around them (in the order of the faces and of their
    /// candidates, so the sums do not depend on when each face was evaluated). Returns a slave
    /// node with more than `MORTAR_MASTERS` master nodes, if any.
    fn mortar_integrals_into(&mut self, model: &Model, j: &ContactJoint, rec: &JointRecord, u_next: &[f64], mj: &mut MortarJoint) -> Option<usize> {
        let mut cand = std::mem::take(&mut self.mortar.cand);
        let mut touched = std::mem::take(&mut self.mortar.touched);
        touched.clear();
        let (sl, ms) = (&j.tag.slave, &j.tag.master);
        for (f, face) in sl.faces.iter().enumerate() {
            if !Self::mortar_face_stale(j, rec, &mj.faces[f], f, u_next) {
                continue;
            }
            self.mortar.face_evaluations += 1;
            let fi = &mut mj.faces[f];
            fi.overlaps.clear();
            fi.evaluated = true;
            for (a, &l) in face.local_nodes().iter().enumerate() {
                let c = rec.pairs[l as usize].center;
                fi.centre[a] = c;
                fi.rel[a] = disp(u_next, sl.nodes[l as usize]) - disp(u_next, ms.nodes[c as usize]);
            }
            touched.extend_from_slice(face.local_nodes());
            let nodes = face.nodes();
            let mut x = [Vector3::zeros(); 4];
            for (a, &nd) in nodes.iter().enumerate() {
                x[a] = pos(model, u_next, nd as usize);
            }
            let Some(sf) = SlaveFace::new(&x[..nodes.len()]) else {
                fi.size = 0.0;
                continue;
            };
            fi.size = sf.plane_area.sqrt();
            cand.clear();
            for &l in face.local_nodes() {
                candidates_into(&mut self.cand, j, rec.pairs[l as usize].center, 2);
                cand.extend_from_slice(&self.cand);
            }
            cand.sort_unstable();
            cand.dedup();
            for &mf in &cand {
                let (xm, km) = face_positions(model, j, mf as usize, u_next);
                if let Some(o) = overlap_integrals(&sf, &xm[..km]) {
                    fi.overlaps.push((mf, o));
                }
            }
        }
        touched.sort_unstable();
        touched.dedup();
        let mut overflow = None;
        for &l in &touched {
            let l = l as usize;
            let (mut dl, mut row): (f64, MortarRow) = (0.0, ([0; MORTAR_MASTERS], [0.0; MORTAR_MASTERS], 0));
            for &g in sl.faces_of_node(l) {
                let Some(a) = sl.faces[g as usize].local_nodes().iter().position(|&x| x as usize == l) else { continue };
                for (mf, o) in &mj.faces[g as usize].overlaps {
                    dl += o.d[a];
                    for (b, &ml) in ms.faces[*mf as usize].local_nodes().iter().enumerate() {
                        let cnt = row.2 as usize;
                        match row.0[..cnt].iter().position(|&x| x == ml) {
                            Some(p) => row.1[p] += o.m[a][b],
                            None if cnt < MORTAR_MASTERS => {
                                row.0[cnt] = ml;
                                row.1[cnt] = o.m[a][b];
                                row.2 += 1;
                            }
                            None => overflow = Some(l),
                        }
                    }
                }
            }
            mj.d[l] = dl;
            mj.rows[l] = row;
        }
        self.mortar.cand = cand;
        self.mortar.touched = touched;
        overflow
    }

    /// The master face of slave node `i` of joint `j` (node-to-segment search on `conf`): the
    /// face of the last step when the node is still inside it, else its candidate set, the
    /// master's free edge within `edge_tolerance`, and with `widen` Layer2 and a fresh
    /// nearest-node search (module doc). `None`: the node found no face.
    #[allow(clippy::too_many_arguments)]
    fn nts_face_into(model: &Model, j: &ContactJoint, rec: &mut PairRecord, ev: &mut SearchEvents, cand: &mut Vec<u32>, i: usize, xs: &Vector3<f64>, conf: &[f64]) -> Option<(usize, super::query::Projection)> {
        let n = j.frames[i][0];
        let pr = *rec;
        // Temporal coherence: a node still strictly inside the face it was on at
        // the last step, and near it along its normal (within half the face
        // size, so that no other sheet of a folded master can be nearer), keeps
        // that face: the full search would choose it too (selection rules of
        // `select_projection`: nearest sheet, inside before edge, face id).
        let mut found = None;
        if pr.face >= 0 && j.law.tied {
            // A tied pair keeps the face it was tied to (a tie is made once and
            // kept, as tied contact does in LS-DYNA or Abaqus): the node is
            // projected on that face whatever its location (no inside test), so
            // a bonded node that a shear force carries dt² F / m past the face's
            // edge in the prediction is not lost (regression:
            // `tied_pure_shear_keeps_perimeter_nodes_at_the_default_edge_tolerance`).
            let f = pr.face as usize;
            found = project_on_face(model, j, f, xs, &n, conf, &mut ev.projection_failures, f64::INFINITY, pr.xi).map(|(p, _)| (f, p));
        } else if pr.face >= 0 {
            let f = pr.face as usize;
            if let Some((p, edge2)) = project_on_face(model, j, f, xs, &n, conf, &mut ev.projection_failures, INSIDE_TOL_DEFAULT, pr.xi)
                && p.location == Location::Inside
                && p.t * p.t <= 0.25 * edge2
            {
                found = Some((f, p));
            }
        }
        if found.is_none() {
            candidates_into(cand, j, pr.center, j.layer);
            found = project_on(model, j, cand, xs, &n, conf, &mut ev.projection_failures, INSIDE_TOL_DEFAULT);
        }
        if found.is_none() {
            // a node just off the master's free edge (see `edge_tolerance`)
            found = project_on(model, j, cand, xs, &n, conf, &mut ev.projection_failures, j.edge_tolerance);
            if found.is_some() {
                ev.perimeter_kept += 1;
            }
        }
        if found.is_none() && j.on_exit == OnExit::Widen {
            found = Self::widen_into(model, j, rec, ev, cand, i, xs, conf);
        }
        found
    }

    /// `widen` (slave node `i` left its candidate set): Layer2 around the centre, then a walk on
    /// the master surface to the node nearest the slave's position, which becomes the centre.
    #[allow(clippy::too_many_arguments)]
    fn widen_into(model: &Model, j: &ContactJoint, rec: &mut PairRecord, ev: &mut SearchEvents, cand: &mut Vec<u32>, i: usize, xs: &Vector3<f64>, conf: &[f64]) -> Option<(usize, super::query::Projection)> {
        let n = j.frames[i][0];
        let pr = *rec;
        let mut found = None;
        if j.layer < 2 {
            candidates_into(cand, j, pr.center, 2);
            found = project_on(model, j, cand, xs, &n, conf, &mut ev.projection_failures, INSIDE_TOL_DEFAULT);
            if found.is_some() {
                ev.widened_layer2 += 1;
            }
        }
        if found.is_none() {
            // walk the master surface to the node nearest the slave's position
            let m = &j.tag.master;
            let mut c = pr.center as usize;
            let d = |l: usize| (pos(model, conf, m.nodes[l]) - xs).norm_squared();
            loop {
                let mut best = (d(c), c);
                for &f in m.faces_of_node(c) {
                    for &v in m.faces[f as usize].local_nodes() {
                        let dv = d(v as usize);
                        if dv < best.0 || (dv == best.0 && (v as usize) < best.1) {
                            best = (dv, v as usize);
                        }
                    }
                }
                if best.1 == c {
                    break;
                }
                c = best.1;
            }
            ev.fresh_searches += 1;
            rec.center = c as u32;
            // Layer2 around the new centre; around the old one it was just
            // tried (above, or as the joint's own layer), with the same
            // result: a node that stays lost (outside the master, next to
            // its edge) costs one Layer2 search a step, not two
            if c != pr.center as usize {
                candidates_into(cand, j, c as u32, 2);
                found = project_on(model, j, cand, xs, &n, conf, &mut ev.projection_failures, INSIDE_TOL_DEFAULT);
            }
        }
        found
    }

    /// The pair's mobility (module doc): `None` when the pair can take no force (no node of it
    /// moves along its normal).
    fn pair_mobility<const M: usize, const N: usize>(&self, model: &Model, s: usize, n: &Vector3<f64>, pm: &PairMasters<M>) -> Option<Mobility<N>> {
        let (masters, nm, weights) = (&pm.nodes, pm.nm, &pm.weights);
        let ims = self.inv_mass[s];
        let mut imm = [0.0; N];
        let mut w = ims;
        for a in 0..nm as usize {
            imm[a] = self.inv_mass[masters[a] as usize];
            w += weights[a] * weights[a] * imm[a];
        }
        // a partly fixed node in the pair: the mobility per component, W = Σ c² P / m
        // (diagonal); the update's scalar is its largest entry (module doc)
        let partly_fixed = !self.partial.is_empty() && (self.is_partial(s as u32) || masters[..nm as usize].iter().any(|&m| self.is_partial(m)));
        let is_block = |nd: u32| !self.block_nodes.is_empty() && self.block_nodes.binary_search(&nd).is_ok();
        let on_block = is_block(s as u32) || masters[..nm as usize].iter().any(|&m| is_block(m));
        let mut masks = [Vector3::repeat(1.0); N];
        if partly_fixed {
            masks[0] = free_mask(model, s);
            let mut wv = masks[0] * ims;
            for a in 0..nm as usize {
                masks[a + 1] = free_mask(model, masters[a] as usize);
                wv += masks[a + 1] * (weights[a] * weights[a] * imm[a]);
            }
            if wv.dot(&n.component_mul(n)) == 0.0 {
                // no node of the pair can move along its normal: no contact force
                return None;
            }
            w = wv.max();
        }
        if w == 0.0 {
            return None;
        }
        Some(Mobility { w, ims, imm, partial: partly_fixed || on_block, masks })
    }

    /// A penalty pair (`Method::Penalty`): its force of step n from the configuration at t[n],
    /// recorded in the history and queued in `penalty` for the prediction.
    #[allow(clippy::too_many_arguments)]
    fn penalty_pair_into(&self, model: &Model, j: &ContactJoint, p: &mut PairRecord, i: usize, pm: &PairMasters, (kn, kt): (f64, f64), xs: &Vector3<f64>, u_prev: &[f64], u: &[f64]) -> PenaltyPair {
        let (masters, nm, weights) = (pm.nodes, pm.nm, pm.weights);
        let s = j.tag.slave_nodes()[i];
        let [n, t1, t2] = j.frames[i];
        // current gap and relative displacement on the configuration at t[n]
        let mut xbar = Vector3::zeros();
        let mut um_n = Vector3::zeros();
        for a in 0..nm as usize {
            let mi = masters[a] as usize;
            xbar += pos(model, u, mi) * weights[a];
            um_n += disp(u, mi) * weights[a];
        }
        let gap = n.dot(&(xbar - xs)) - p.gap_offset;
        // explicit penalty at t[n]: tangential increment over the last step
        let mut um_p = Vector3::zeros();
        for a in 0..nm as usize {
            um_p += disp(u_prev, masters[a] as usize) * weights[a];
        }
        let dd = (disp(u, s) - um_n) - (disp(u_prev, s) - um_p);
        let area = j.tag.areas[i];
        let ddt = Vector2::new(dd.dot(&t1), dd.dot(&t2));
        let resp = penalty_force(&self.law_in_force(j), &p.hist, gap, Vector2::new(p.r_t[0], p.r_t[1]), ddt, kn * area, kt * area, area);
        p.hist = resp.hist;
        let (r_n, r_t, state) = (resp.r_n, resp.r_t, resp.state);
        let rvec = -n * r_n + t1 * r_t.x + t2 * r_t.y;
        p.d_t[0] += dd.dot(&t1);
        p.d_t[1] += dd.dot(&t2);
        p.slip += Vector2::new(dd.dot(&t1), dd.dot(&t2)).norm();
        p.gap = gap;
        p.face = pm.face;
        p.r_n = r_n;
        p.r_t = [r_t.x, r_t.y];
        p.state = state;
        (s as u32, masters, nm, weights, rvec)
    }

    /// A dynamic-force pair of slave node `i` (history `pr`) with the masters `pm`, its
    /// mobility and its area `area` [m²] (the law's `A_s`), warm-started from its force of the
    /// last step; with it, its mobility matrix when the model has partly fixed or block nodes
    /// (`mob_matrix`).
    #[allow(clippy::too_many_arguments)]
    fn active_pair<const M: usize, const N: usize>(&self, model: &Model, j: &ContactJoint, ji: usize, pr: &PairRecord, i: usize, pm: &PairMasters<M>, mob_of: &Mobility<N>, dt2: f64, u: &[f64], area: f64) -> (Active<N>, Option<[Matrix3<f64>; N]>) {
        debug_assert!(M + 1 == N);
        let (masters, nm, weights) = (pm.nodes, pm.nm, pm.weights);
        let s = j.tag.slave_nodes()[i];
        let n = j.frames[i][0];
        let warm = self.gs_warm_start && pr.state != PairState::Open;
        let mut xbar0 = -Vector3::from(model.mesh.nodes[s]);
        let mut rel_u = -disp(u, s);
        for a in 0..nm as usize {
            let mi = masters[a] as usize;
            xbar0 += Vector3::from(model.mesh.nodes[mi]) * weights[a];
            rel_u += disp(u, mi) * weights[a];
        }
        let mut nodes5 = [s as u32; N];
        let mut coef = [0.0; N];
        coef[0] = -1.0;
        let mut mob = [0.0; N];
        if mob_of.ims > 0.0 {
            mob[0] = dt2 * mob_of.ims;
        }
        for b in 0..nm as usize {
            nodes5[b + 1] = masters[b];
            coef[b + 1] = weights[b];
            let imi = mob_of.imm[b];
            if imi > 0.0 {
                mob[b + 1] = -dt2 * weights[b] * imi;
            }
        }
        let matrix = (!self.partial.is_empty() || !self.block_nodes.is_empty()).then(|| {
            // one entry per active pair (indexed like `active`), read when `partial`:
            // the displacement a unit pair force gives each node, mob × its free
            // components, or at a node with an inertia block ±dt² N M⁻¹ (the block's
            // inverse, restricted to the free components; docs/contact.md, "Mobility
            // of an anisotropic mass")
            let nodes_b = nodes5;
            let masks = mob_of.masks;
            std::array::from_fn(|b| match model.mass.block_of(nodes_b[b] as usize) {
                Some(blk) if b <= nm as usize && self.inv_mass[nodes_b[b] as usize] > 0.0 => blk.inverse * (mob[b] / self.inv_mass[nodes_b[b] as usize]),
                _ => Matrix3::from_diagonal(&masks[b]) * mob[b],
            })
        });
        let w = mob_of.w;
        let a = Active {
            nodes: nodes5,
            local: [0; N],
            partial: mob_of.partial,
            mob2_max: mob.iter().fold(0.0, |m: f64, &v| if v * v > m { v * v } else { m }),
            coef,
            mob,
            frame: j.frames[i],
            area,
            hist0: pr.hist,
            // the grouted gap and a held re-entry penetration count as closed (0 unless so)
            gap0: n.dot(&xbar0) - pr.gap_offset - pr.entry_offset,
            rel_u,
            joint: ji as u32,
            pair: i as u32,
            nm,
            dt2w: dt2 * w,
            inv_dt2w: 1.0 / (dt2 * w),
            // warm start: a pair in contact at the last step starts from its last force
            r_n: if warm { pr.r_n } else { 0.0 },
            r_t: if warm { Vector2::new(pr.r_t[0], pr.r_t[1]) } else { Vector2::zeros() },
            hist: pr.hist,
            state: PairState::Open,
            // set by the first sweep, which evaluates every pair
            gap: f64::NAN,
        };
        (a, matrix)
    }

    /// The penalty forces of step n applied to the prediction like external forces; returns
    /// their work over the step [J].
    fn apply_penalty_into(&self, model: &Model, dt2: f64, u_prev: &[f64], u_next: &mut [f64]) -> f64 {
        let mut penalty_work = 0.0;
        for &(s, masters, nm, weights, rvec) in &self.penalty {
            add_pair_force_into(u_next, &self.inv_mass, dt2, s, &masters[..nm as usize], &weights, &rvec);
            if !self.block_nodes.is_empty() {
                // a penalty force is an external force: at a block node its displacement is
                // dt² M⁻¹ R with the full inverse, not the scalar of `inv_mass`
                let r = |k: usize| if k == 0 { rvec } else { -rvec * weights[k - 1] };
                for (k, &nd) in std::iter::once(&s).chain(&masters[..nm as usize]).enumerate() {
                    if self.block_nodes.binary_search(&nd).is_ok() {
                        let b = model.mass.block_of(nd as usize).expect("a block node");
                        let i0 = 3 * nd as usize;
                        let exact = b.inverse * r(k) * dt2;
                        let scalar = r(k) * (dt2 * self.inv_mass[nd as usize]);
                        for c in 0..3 {
                            u_next[i0 + c] += exact[c] - scalar[c];
                        }
                    }
                }
            }
        }
        if !self.partial.is_empty() && !self.penalty.is_empty() {
            // a partly fixed node takes a penalty force on its free components only: its fixed
            // ones stay at the prediction's 0 (`Model::held`)
            for &nd in &self.partial {
                let nd = nd as usize;
                for c in 0..3 {
                    if !model.is_free(nd, c) {
                        u_next[3 * nd + c] = 0.0;
                    }
                }
            }
        }
        for &(s, masters, nm, weights, rvec) in &self.penalty {
            let s = s as usize;
            let mut du = (disp(u_next, s) - disp(u_prev, s)) * 0.5;
            for a in 0..nm as usize {
                let mi = masters[a] as usize;
                du -= (disp(u_next, mi) - disp(u_prev, mi)) * (0.5 * weights[a]);
            }
            penalty_work += rvec.dot(&du);
        }
        penalty_work
    }

    /// Warm start (each active pair's force of the last step applied to the prediction),
    /// colour order and the Gauss–Seidel lists of moving nodes.
    #[inline(never)]
    fn prepare_sweeps_into(&mut self, u_next: &mut [f64]) {
        if self.step_clock == u32::MAX {
            self.node.iter_mut().for_each(|ns| ns.listed = 0);
            self.step_clock = 0;
        }
        self.step_clock += 1;
        self.local.clear();
        self.local_global.clear();
        let ContactSolver { active, node, local, local_global, step_clock, mob_matrix, mortar, .. } = self;
        list_pairs_into(active, node, local, local_global, *step_clock, mob_matrix, u_next);
        list_pairs_into(&mut mortar.active, node, local, local_global, *step_clock, &mortar.mob_matrix, u_next);
        if self.gs_colored {
            self.order_by_color();
        } else {
            self.order.clear();
            self.order.extend(0..self.active.len() as u32);
            self.color_runs.clear();
            self.color_runs.push((0, self.active.len() as u32, false));
        }
        // mortar pairs: in the order of the search, after the node-to-segment pairs
        self.mortar.order.clear();
        self.mortar.order.extend(0..self.mortar.active.len() as u32);
        self.group_shared_nodes();
        self.sweep_start.resize(self.local.len(), Vector3::zeros());
        self.evaluated_at.clear();
        self.evaluated_at.resize(self.active.len(), 0);
        self.mortar.evaluated_at.clear();
        self.mortar.evaluated_at.resize(self.mortar.active.len(), 0);
    }

    /// The groups of the shared-node pass (`shared_pairs`, `shared_runs`): the active pairs of
    /// joints with an asperity envelope, by slave node, where a node has two or more. Nothing
    /// (and no cost beyond a test per joint) when no joint has an envelope. Deterministic: the
    /// nodes in the order of their local indices, each node's pairs in the order of `active`.
    fn group_shared_nodes(&mut self) {
        self.shared_pairs.clear();
        self.shared_runs.clear();
        if self.joints.iter().all(|j| j.law.asperity_friction.is_none()) {
            return;
        }
        let mut by_node: Vec<(u32, u32)> = self.active.iter().enumerate().filter(|(_, a)| self.joints[a.joint as usize].law.asperity_friction.is_some()).map(|(k, a)| (a.local[0], k as u32)).collect();
        by_node.sort_unstable();
        for run in by_node.chunk_by(|x, y| x.0 == y.0).filter(|r| r.len() >= 2) {
            let start = self.shared_pairs.len() as u32;
            self.shared_pairs.extend(run.iter().map(|&(_, k)| k));
            self.shared_runs.push((start, self.shared_pairs.len() as u32));
        }
    }

    /// The Gauss–Seidel sweeps over the active pairs (on the local nodes; `record_into` writes
    /// them back into the prediction); returns the sweeps made, whether they reached
    /// `gs_tolerance`, the residual, the node that moved most in a last allowed sweep, and
    /// whether they ran on all threads (the local nodes' parts then in `local_cuts`).
    #[inline(never)]
    fn sweep_into(&mut self) -> (usize, bool, f64, Option<u32>, bool) {
        let mut clock = 1u32;
        // A node moved by less than 1 % of the tolerance does not call its pairs back: their
        // forces would change by a fraction of that (the fixed point is the same to within the
        // tolerance), and on a coarse, heavy master whose nodes carry dozens of pairs those
        // round-off-sized updates otherwise ripple through every sweep.
        let mark_tol2 = (1e-2 * self.gs_tolerance).powi(2);
        let laws: Vec<JointLaw> = self.joints.iter().map(|j| self.law_in_force(j)).collect();
        let ContactSolver { active, order, color_runs, local, evaluated_at, sweep_start, gs_tolerance, gs_max_sweeps, gs_shared_passes, mob_matrix, mortar, sweep_par_min, shared_pairs, shared_runs, sweep_threads, local_cuts, .. } = self;
        let parallel = rayon::current_num_threads() > 1 && sweep_threads.as_mut().is_none_or(|c| c.parallel());
        let mut sweeps = 0;
        let pairs = active.len() + mortar.active.len();
        let mut converged = pairs == 0;
        for (x0, l) in sweep_start.iter_mut().zip(local.iter()) {
            *x0 = l.x;
        }
        // each sweep's change by parts of the local nodes, as the colours share out the pairs
        local_cuts.clear();
        if parallel {
            local_cuts_of_into(local_cuts, active, local.len(), rayon::current_num_threads());
        }
        // Full sweeps first, the work list once it pays: while at least half the pairs moved a
        // node by more than the marking tolerance in the last sweep, a sweep evaluates every pair
        // without reading or stamping clocks (the list would skip few: 8 % on the contact
        // benchmark, where keeping it cost 17 % of the sweeps' time); after that, every node
        // is stamped as moved and the work list takes over (a coarse, heavy master, or the slow
        // pairs on a line of intersection, where most pairs have converged long before the
        // last). The mode depends only on the iterates: deterministic.
        let mut listed = false;
        let mut moving = pairs;
        let mut residual = 0.0;
        let m = mortar;
        // the positions before the last sweep allowed (only in a step that reaches it): which
        // node that sweep moved most, for the warning (`CapStep`)
        let mut before_last: Vec<Vector3<f64>> = Vec::new();
        while !converged && sweeps < *gs_max_sweeps {
            sweeps += 1;
            if sweeps == *gs_max_sweeps {
                before_last.extend(local.iter().map(|l| l.x));
            }
            if !listed && 2 * moving < pairs {
                listed = true;
                clock += 1;
                local.iter_mut().for_each(|l| l.moved_at = clock);
            }
            // the node-to-segment pairs by colour, then the mortar pairs in search order
            moving = if listed {
                sweep_colors::<true>(active, order, color_runs, local, evaluated_at, &mut clock, &laws, mark_tol2, mob_matrix, parallel, *sweep_par_min)
            } else {
                sweep_colors::<false>(active, order, color_runs, local, evaluated_at, &mut clock, &laws, mark_tol2, mob_matrix, parallel, *sweep_par_min)
            };
            if !shared_runs.is_empty() {
                let shared = SharedGroups { pairs: shared_pairs, runs: shared_runs, tol2: *gs_tolerance * *gs_tolerance, passes: *gs_shared_passes };
                if listed {
                    shared_node_pass::<true>(active, &shared, local, evaluated_at, &mut clock, &laws, mark_tol2, mob_matrix);
                } else {
                    shared_node_pass::<false>(active, &shared, local, evaluated_at, &mut clock, &laws, mark_tol2, mob_matrix);
                }
            }
            if !m.active.is_empty() {
                let (pa, pl, pe) = (Shared::of(&mut m.active), Shared::of(local), Shared::of(&mut m.evaluated_at));
                // SAFETY: one thread
                moving += unsafe {
                    if listed {
                        sweep_pass::<true, MORTAR_NODES>(pa, &m.order, pl, pe, &mut clock, true, &laws, mark_tol2, &m.mob_matrix)
                    } else {
                        sweep_pass::<false, MORTAR_NODES>(pa, &m.order, pl, pe, &mut clock, true, &laws, mark_tol2, &m.mob_matrix)
                    }
                };
            }
            let max_du = if local_cuts.len() > 2 {
                crate::par::region();
                let starts = crate::par::split_lengths_mut(sweep_start, local_cuts.windows(2).map(|w| w[1] - w[0]));
                // the largest of the parts' largest changes: the same as one pass's
                starts.into_par_iter().zip(local_cuts.par_windows(2)).with_max_len(1).map(|(s, w)| sweep_change_into(&local[w[0]..w[1]], s)).reduce(|| 0.0, f64::max)
            } else {
                sweep_change_into(local, sweep_start)
            }
            .sqrt();
            residual = max_du;
            converged = max_du <= *gs_tolerance
                || listed && !active.iter().zip(evaluated_at.iter()).any(|(a, &e)| moved_since(local, a, e)) && !m.active.iter().zip(m.evaluated_at.iter()).any(|(a, &e)| moved_since(local, a, e));
        }
        let worst = (!converged && !before_last.is_empty()).then(|| local.iter().zip(&before_last).enumerate().map(|(k, (l, b))| (k as u32, (l.x - b).norm_squared())).fold((0, -1.0), |a, b| if b.1 > a.1 { b } else { a }).0);
        (sweeps, converged, residual, worst, parallel)
    }

    /// The sweeps' local nodes back into the prediction `u_next`, the active pairs' results into
    /// the history; returns the contact work of the step [J]. With `parallel` (the sweeps ran on
    /// all threads), each thread writes back its part's nodes and records its part's pairs (those
    /// it swept, still in its cache), the joints' sums following in pair order on one thread:
    /// the same values as one thread's.
    #[inline(never)]
    #[allow(clippy::too_many_arguments)]
    fn record_into(&mut self, history: &mut ContactState, u_next: &mut [f64], sweeps: usize, converged: bool, residual: f64, u_prev: &[f64], worst: Option<(u32, f64)>, parallel: bool) -> f64 {
        let mut work = 0.0;
        let cap = worst.filter(|_| !converged && history.joints.iter().any(|r| residual > r.max_gs_residual)).map(|(k, t)| self.cap_step(k, t, residual));
        for rec in history.joints.iter_mut() {
            rec.sweeps = sweeps;
            rec.gs_residual = residual;
            rec.max_sweeps = rec.max_sweeps.max(sweeps);
            if !converged {
                rec.unconverged_steps += 1;
                if residual > rec.max_gs_residual {
                    rec.worst_cap = cap.clone();
                }
                rec.max_gs_residual = rec.max_gs_residual.max(residual);
            }
        }
        if parallel && self.local_cuts.len() > 2 {
            work += self.record_parts_into(history, u_next, u_prev);
        } else {
            for (l, &nd) in self.local.iter().zip(self.local_global.iter()) {
                u_next[3 * nd as usize..3 * nd as usize + 3].copy_from_slice(l.x.as_slice());
            }
            for a in &self.active {
                work += record_pair_into(a, history, &self.local, u_prev);
            }
        }
        for a in &self.mortar.active {
            work += record_pair_into(a, history, &self.local, u_prev);
        }
        work
    }

    /// [`Self::record_into`] on all threads: part p writes back local nodes `local_cuts[p]..
    /// local_cuts[p + 1]` and records active pairs `n p / T .. n (p + 1) / T` (the sweeps'
    /// parts); then the joints' sums in pair order. Returns the work of the node-to-segment
    /// pairs [J].
    fn record_parts_into(&mut self, history: &mut ContactState, u_next: &mut [f64], u_prev: &[f64]) -> f64 {
        let parts = self.local_cuts.len() - 1;
        let n = self.active.len();
        self.pair_work.clear();
        self.pair_work.resize(n, (0, 0.0, false));
        let records: Vec<Shared<PairRecord>> = history.joints.iter_mut().map(|r| Shared::of(&mut r.pairs)).collect();
        let u = Shared::of(u_next);
        let (active, local, local_global, cuts) = (&self.active, &self.local, &self.local_global, &self.local_cuts);
        let pieces = crate::par::split_lengths_mut(&mut self.pair_work, (0..parts).map(|p| n * (p + 1) / parts - n * p / parts));
        crate::par::region();
        pieces.into_par_iter().enumerate().with_max_len(1).for_each(|(p, out)| {
            for (l, &nd) in local[cuts[p]..cuts[p + 1]].iter().zip(&local_global[cuts[p]..cuts[p + 1]]) {
                for d in 0..3 {
                    // SAFETY: each local node is one global node, written by its part alone
                    unsafe { *u.at(3 * nd as usize + d) = l.x[d] };
                }
            }
            for (a, w) in active[n * p / parts..n * (p + 1) / parts].iter().zip(out.iter_mut()) {
                // SAFETY: each active pair is one record (its joint's slave node), written by its
                // part alone
                let rec = unsafe { records[a.joint as usize].at(a.pair as usize) };
                let (work, reentry) = record_pair_fields_into(a, rec, local, u_prev);
                *w = (a.joint, work, reentry);
            }
        });
        let mut work = 0.0;
        for &(j, w, reentry) in &self.pair_work {
            add_pair_work(&mut history.joints[j as usize], w, reentry);
            work += w;
        }
        work
    }

    /// The step at t `t` stopped at the sweep budget: local node `k` moved most in its last
    /// sweep (by `residual`); its global node and the active pairs on it (`CapStep`).
    fn cap_step(&self, k: u32, t: f64, residual: f64) -> crate::contact::state::CapStep {
        let on = |span: usize, local: &[u32], joint: u32, slave: u32, state: PairState| local[..span].contains(&k).then_some((joint as usize, slave as usize, state));
        let mut pairs: Vec<(usize, usize, PairState)> = self.active.iter().filter_map(|a| on(a.span(), &a.local, a.joint, a.nodes[0], a.state)).collect();
        pairs.extend(self.mortar.active.iter().filter_map(|a| on(a.span(), &a.local, a.joint, a.nodes[0], a.state)));
        pairs.sort_by_key(|p| (p.0, p.1));
        crate::contact::state::CapStep { t, node: self.local_global[k as usize] as usize, residual, pairs }
    }
}

/// List the nodes of the active pairs among the local nodes (copied from the prediction
/// `u_next` when first met in the step `step_clock`), and apply each pair's warm-start force.
fn list_pairs_into<const N: usize>(active: &mut [Active<N>], node: &mut [NodeScratch], local: &mut Vec<LocalNode>, local_global: &mut Vec<u32>, step_clock: u32, mob_matrix: &[[Matrix3<f64>; N]], u_next: &[f64]) {
    for (k, a) in active.iter_mut().enumerate() {
        // the pair's nodes among the local nodes, copied from the prediction when first met
        for b in 0..a.span() {
            let nd = a.nodes[b] as usize;
            let ns = &mut node[nd];
            if ns.listed != step_clock {
                ns.listed = step_clock;
                ns.local = local.len() as u32;
                // clock 0: the sweeps stamp every node when they start the work list
                local.push(LocalNode { x: disp(u_next, nd), moved_at: 0 });
                local_global.push(nd as u32);
            }
            a.local[b] = ns.local;
        }
        // the warm-start force acts on the prediction before the first sweep (through the
        // pair's mobilities, as a sweep's update does)
        if a.r_n != 0.0 || a.r_t != Vector2::zeros() {
            let [n, t1, t2] = a.frame;
            let r = -n * a.r_n + t1 * a.r_t.x + t2 * a.r_t.y;
            a.move_nodes_into(local, &r, mob_matrix, k);
        }
    }
}

/// Write active pair `a`'s result into the history; returns the work of its force over the
/// step [J].
fn record_pair_into<const N: usize>(a: &Active<N>, history: &mut ContactState, local: &[LocalNode], u_prev: &[f64]) -> f64 {
    let rec = &mut history.joints[a.joint as usize];
    let (work, reentry) = record_pair_fields_into(a, &mut rec.pairs[a.pair as usize], local, u_prev);
    add_pair_work(rec, work, reentry);
    work
}

/// The joint's sums of a recorded pair's work (`record_pair_fields_into`), in the order of the
/// pairs (the sums are floating-point: the order is the result).
fn add_pair_work(rec: &mut JointRecord, work: f64, reentry: bool) {
    rec.work += work;
    if reentry {
        rec.reentries += 1;
        rec.reentry_work += work.max(0.0);
    }
}

/// Write active pair `a`'s result into its record `p`; returns the work of its force over the
/// step [J] and whether it re-entered (for its joint's sums, `add_pair_work`).
fn record_pair_fields_into<const N: usize>(a: &Active<N>, p: &mut PairRecord, local: &[LocalNode], u_prev: &[f64]) -> (f64, bool) {
    let [n, t1, t2] = a.frame;
    let reentry = p.reentered;
    p.hist = a.hist;
    p.state = a.state;
    p.gap = a.gap;
    p.entry_offset = released_entry_offset(p.entry_offset, p.gap);
    p.r_n = a.r_n;
    p.r_t = [a.r_t.x, a.r_t.y];
    // accumulated tangential relative displacement over the step, from the final
    // positions (the sweeps' local copies) and the relative displacement at t[n]:
    // Δd = Δu_s − Σ N_I Δu_I = rel_u − Σ coef_b x_b
    let rel = a.relative_displacement(local);
    let mut rel_prev = Vector3::zeros();
    for b in 0..a.span() {
        rel_prev += disp(u_prev, a.nodes[b] as usize) * a.coef[b];
    }
    let dd = a.rel_u - rel;
    p.d_t[0] += dd.dot(&t1);
    p.d_t[1] += dd.dot(&t2);
    p.slip += Vector2::new(dd.dot(&t1), dd.dot(&t2)).norm();
    // work of the pair force over the step, on the central-difference increment
    // ½ (x[n+1] − x[n−1]) of the slave relative to the master point
    let rvec = -n * a.r_n + t1 * a.r_t.x + t2 * a.r_t.y;
    let du = (rel_prev - rel) * 0.5;
    (rvec.dot(&du), reentry)
}

impl Constraint<ContactState> for ContactSolver<'_> {
    fn correct(&mut self, model: &Model, history: &mut ContactState, step: &StepContext<'_>, u_next: &mut [f64]) -> Result<ConstraintInfo, StepError> {
        let (dt, u_prev, u) = (step.dt, step.u_prev, step.u);
        let dt2 = dt * dt;
        let now_if = |on: bool| on.then(std::time::Instant::now);
        let timed = self.timings.is_some();
        let t_search = now_if(timed);
        let penalty_work = self.search_into(model, history, dt2, u_prev, u, u_next)?;
        let t_prepare = now_if(timed);
        self.prepare_sweeps_into(u_next);
        let t_sweeps = now_if(timed);
        let t0 = std::time::Instant::now();
        let (sweeps, converged, residual, worst, parallel) = self.sweep_into();
        if let Some(c) = self.sweep_threads.as_mut() {
            // the work: pairs × sweeps (the same measure in both modes)
            c.record(t0.elapsed().as_secs_f64(), (sweeps * (self.active.len() + self.mortar.active.len())) as f64);
        }
        let t_record = now_if(timed);
        let work = penalty_work + self.record_into(history, u_next, sweeps, converged, residual, u_prev, worst.map(|k| (k, step.t_next)), parallel);
        if let (Some(t), Some(a), Some(b), Some(c), Some(d)) = (self.timings.as_mut(), t_search, t_prepare, t_sweeps, t_record) {
            t.search += b - a;
            t.prepare += c - b;
            t.sweeps += d - c;
            t.record += d.elapsed();
            t.steps += 1;
        }
        Ok(ConstraintInfo { work, iterations: sweeps })
    }
}
