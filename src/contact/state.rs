//! The contact history of a run: what changes from step to step for every pair (slave node)
//! and joint. Part of the run's `State` (module `dynamics`); written by the contact correction
//! ([`super::force::ContactSolver`]), read by the outputs. Holds no scratch.

use super::joint::ContactJoint;
use super::law::{PairHistory, PairState};

/// What changes for one pair (slave node) from step to step.
#[derive(Clone, Copy, Debug)]
pub struct PairRecord {
    pub hist: PairHistory,
    pub state: PairState,
    /// Master-local node around which candidate faces are taken (starts at the tagger's O).
    pub center: u32,
    /// Master face of the last projection (−1: none) and the local coordinates on it.
    pub face: i32,
    pub xi: [f64; 2],
    /// Gap at the end of the last step [m] (NaN when the node found no face).
    pub gap: f64,
    /// Normal (compressive, N) and tangential (N, in t1/t2) force of the last step.
    pub r_n: f64,
    pub r_t: [f64; 2],
    /// Accumulated relative tangential displacement vector d_t (t1, t2) [m].
    pub d_t: [f64; 2],
    /// Accumulated tangential relative path Σ|Δd_t| [m] (the joint's slip).
    pub slip: f64,
    /// Gap that counts as closed [m], subtracted from the geometric gap: 0 (the gaps as meshed)
    /// unless the joint was grouted, where it is the gap at grouting (a construction
    /// sequence's stage, `construction`), so the grouted joint starts closed with no force.
    pub gap_offset: f64,
    /// Whether the node, lost in the last step (gap NaN), lay beyond the master surface's free
    /// edge (`super::free_edge`: it slid off the surface) rather than inside its outline; false
    /// while it finds a face. Its travel then counts as no penetration in the outputs.
    pub beyond_edge: bool,
}

/// Counters of search events per joint.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct SearchEvents {
    /// Projections found only in Layer2 after leaving Layer1.
    pub widened_layer2: u64,
    /// Fresh nearest-node searches (the centre moved).
    pub fresh_searches: u64,
    /// Times the centre of a candidate set moved to follow its slave node (`widen` only).
    pub recentred: u64,
    /// Node-steps with no master face found (force-free that step), all of them.
    pub lost: u64,
    /// Of `lost`, those whose projection lay beyond the master surface's free edge
    /// ([`super::free_edge`]): slid past the end of the surface, expected; the rest are lost
    /// inside its outline.
    #[serde(default)]
    pub lost_beyond_edge: u64,
    /// Quad projections that did not converge (the face was skipped).
    pub projection_failures: u64,
    /// Node-steps kept in contact by the joint's `edge_tolerance`: the node was just outside the
    /// master surface's edge, its weights extrapolated.
    pub perimeter_kept: u64,
}


/// Contact history of one joint.
#[derive(Clone, Debug, Default)]
pub struct JointRecord {
    pub pairs: Vec<PairRecord>,
    pub events: SearchEvents,
    /// Gauss–Seidel sweeps of the last step and the largest so far.
    pub sweeps: usize,
    pub max_sweeps: usize,
    /// Steps whose Gauss–Seidel did not reach the tolerance.
    pub unconverged_steps: u64,
    /// The last sweep's largest net node change of the last step [m] (its residual: below
    /// `gs_tolerance` when converged; the amount left when the sweep budget ran out).
    pub gs_residual: f64,
    /// The largest `gs_residual` of the steps that stopped at the sweep budget [m] (0 if none).
    pub max_gs_residual: f64,
}

/// Contact history of all joints (part of the run's `State`).
#[derive(Clone, Debug, Default)]
pub struct ContactState {
    pub joints: Vec<JointRecord>,
}

impl ContactState {
    pub fn new(joints: &[ContactJoint]) -> ContactState {
        ContactState {
            joints: joints
                .iter()
                .map(|j| JointRecord {
                    pairs: (0..j.tag.n_slave())
                        .map(|i| PairRecord {
                            hist: PairHistory::default(),
                            state: PairState::Open,
                            center: j.tag.nearest[i],
                            face: -1,
                            xi: [0.0; 2],
                            gap: f64::NAN,
                            r_n: 0.0,
                            r_t: [0.0; 2],
                            d_t: [0.0; 2],
                            slip: 0.0,
                            gap_offset: 0.0,
                            beyond_edge: false,
                        })
                        .collect(),
                    ..Default::default()
                })
                .collect(),
        }
    }
}

impl ContactState {
    /// Restart the joints' slip counters from the current state (after gravity equilibrium:
    /// slip while settling is not seismic slip, and the softening of a bond counts the slip of
    /// the earthquake, not of settling).
    pub fn restart_slip(&mut self) {
        for r in &mut self.joints {
            for p in &mut r.pairs {
                p.slip = 0.0;
                p.d_t = [0.0; 2];
                p.hist.slip = 0.0;
            }
        }
    }
}
