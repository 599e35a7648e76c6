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
    /// Penetration held as closed since the node's re-entry [m], ≤ 0, also subtracted from the
    /// gap: 0 unless the joint holds re-entries (`ContactJoint::hold_reentry`), where a node
    /// that finds a face after a lost step takes its predicted gap then (if negative) and
    /// releases it as it moves out (it never deepens; 0 again when the node is lost).
    pub entry_offset: f64,
    /// Whether the node has been searched once (false in the state a run starts from, whose
    /// NaN gap means "not searched yet", not "lost").
    pub searched: bool,
    /// Whether this step is the node's re-entry: it found a face after a lost step (set by the
    /// search, read by the record; NTS and NTN joints).
    pub reentered: bool,
    /// Whether the node, lost in the last step (gap NaN), lay beyond the master surface's free
    /// edge (`super::free_edge`: it slid off the surface) rather than inside its outline; false
    /// while it finds a face. Its travel then counts as no penetration in the outputs.
    pub beyond_edge: bool,
}

/// A held re-entry penetration after a step (`PairRecord::entry_offset`, ≤ 0 [m]) whose gap,
/// counting the offset as closed, ended at `gap` [m]: released as far as the node moved out
/// (the geometric gap is `gap + offset`), never deepened, 0 once the node is out. A NaN gap (the
/// node lost again) releases it all.
pub fn released_entry_offset(offset: f64, gap: f64) -> f64 {
    if !(offset < 0.0) || gap.is_nan() {
        return 0.0;
    }
    (gap + offset).max(offset).min(0.0)
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


impl SearchEvents {
    /// Add the counts of `o` (a part of the joint's slave nodes searched apart: the counts are
    /// integers, so the sum does not depend on the order of the parts).
    pub fn add(&mut self, o: &SearchEvents) {
        self.widened_layer2 += o.widened_layer2;
        self.fresh_searches += o.fresh_searches;
        self.recentred += o.recentred;
        self.lost += o.lost;
        self.lost_beyond_edge += o.lost_beyond_edge;
        self.projection_failures += o.projection_failures;
        self.perimeter_kept += o.perimeter_kept;
    }
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
    /// That worst step: when, and the node its last sweep moved most (None if none).
    pub worst_cap: Option<CapStep>,
    /// Cumulative work of the joint's dynamic-force pair forces since the clock's start [J]
    /// (the joint's share of `Energy::contact_work`: each pair's force on the central-difference
    /// increment of its slave relative to its master point). Friction and plastic closure make
    /// it negative; a positive trend is energy the joint creates.
    pub work: f64,
    /// Re-entries: pair-steps in which a slave node lost in the step before (no master face)
    /// found a face again (NTS and NTN joints). A node that travelled into the master while lost
    /// is pushed back out in that one step, with a relative velocity of its penetration / dt.
    pub reentries: u64,
    /// The positive part of those pairs' work in their re-entry step, summed [J]: the energy
    /// re-entries created (a re-entry that closes no penetration does no positive work).
    pub reentry_work: f64,
}

/// The step whose Gauss–Seidel stopped at the sweep budget with the largest residual: what a
/// non-convergence warning names (which node, on which joints, when, how far from converged).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CapStep {
    /// t[n+1] of the step [s].
    pub t: f64,
    /// The node the step's last sweep moved most, and by how much (the step's residual) [m].
    pub node: usize,
    pub residual: f64,
    /// The active pairs on that node: (joint index, the pair's slave node, its state).
    pub pairs: Vec<(usize, usize, PairState)>,
}

impl CapStep {
    /// One sentence for the warning: when, which node, on which joints, the pairs' states, and
    /// the class — a node with pairs on two joints or more (where joints meet, e.g. a wedge's
    /// line of intersection: the sweeps update its pairs in turn, each against its own master
    /// plane, and with friction they can cycle instead of converging) or one joint's pairs.
    pub fn describe(&self, joint_names: &[&str]) -> String {
        let name = |j: usize| joint_names.get(j).copied().unwrap_or("?");
        let mut joints: Vec<usize> = self.pairs.iter().map(|p| p.0).collect();
        joints.dedup();
        let pairs: Vec<String> = self.pairs.iter().map(|&(j, slave, st)| format!("{} ({:?}, slave node {slave})", name(j), st).to_string()).collect();
        let class = if joints.len() >= 2 {
            let names: Vec<&str> = joints.iter().map(|&j| name(j)).collect();
            format!("a node shared by joints {} (where they meet): their pairs on it are updated in turn, each against its own master, and cycle instead of converging", names.join(" and "))
        } else {
            "a node of one joint".to_string()
        };
        format!("worst at t = {:.4} s: node {} moved {:.2e} m in the last sweep, pairs {}; {class}", self.t, self.node, self.residual, if pairs.is_empty() { "none".into() } else { pairs.join(", ") })
    }
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
                            entry_offset: 0.0,
                            searched: false,
                            reentered: false,
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
    /// Restart the joints' slip and work counters from the current state (after gravity equilibrium:
    /// slip while settling is not seismic slip, and the softening of a bond counts the slip of
    /// the earthquake, not of settling).
    pub fn restart_slip(&mut self) {
        for r in &mut self.joints {
            for p in &mut r.pairs {
                p.slip = 0.0;
                p.d_t = [0.0; 2];
                p.hist.slip = 0.0;
            }
            r.work = 0.0;
            r.reentries = 0;
            r.reentry_work = 0.0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The hold of a re-entry (docs/contact.md, "Re-entry"): a node held 40 mm deep keeps it
    /// while it stays closed or is pushed further in (never deepened), is released by what it
    /// moves out (10 mm out: held 30 mm), is free once out by more than the hold, and a lost
    /// node holds nothing. Exact arithmetic on these values.
    #[test]
    fn a_held_reentry_penetration_is_released_as_the_node_moves_out_and_never_deepened() {
        assert_eq!(released_entry_offset(-0.04, 0.0), -0.04);
        assert_eq!(released_entry_offset(-0.04, -0.01), -0.04);
        assert!((released_entry_offset(-0.04, 0.01) - -0.03).abs() < 1e-15);
        assert_eq!(released_entry_offset(-0.04, 0.05), 0.0);
        assert_eq!(released_entry_offset(-0.04, f64::NAN), 0.0);
        assert_eq!(released_entry_offset(0.0, -0.02), 0.0);
    }

    /// The wedge demo's Gauss–Seidel warning (issue 32 §4): the unconverged steps of the 1.0 g
    /// wedge were all at slave nodes shared by joints A and B (its line of intersection), whose
    /// two pairs cycled; the warning names that class, and a one-joint node is not given it.
    #[test]
    fn gs_cap_warning_names_a_node_shared_by_two_joints() {
        let shared = CapStep { t: 3.3572, node: 249, residual: 4.45e-7, pairs: vec![(0, 249, PairState::Slip), (1, 249, PairState::Open)] };
        let text = shared.describe(&["A", "B"]);
        assert!(text.contains("shared by joints A and B") && text.contains("t = 3.3572 s") && text.contains("node 249") && text.contains("4.45e-7"), "{text}");
        let single = CapStep { pairs: vec![(1, 249, PairState::Stick)], ..shared };
        let text = single.describe(&["A", "B"]);
        assert!(!text.contains("shared") && text.contains("one joint") && text.contains("B (Stick"), "{text}");
    }
}
