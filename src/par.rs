//! Parallel regions of the explicit step: how many fork-joins a run opens.
//!
//! Owns: the process-wide count of the parallel regions (rayon fork-joins) that the step's loops
//! open ([`region`], [`fork_joins`]). Every loop of the step that hands work to rayon's threads
//! (the element loop's colours, the nodal loops, the condensed foundation's product, the contact
//! search and the sweeps' colours) calls [`region`] once per fork-join it opens, so that a
//! benchmark can read the fork-joins per step (`benches/dam.rs`) and weigh them against the
//! measured cost of one (`benches/forkjoin.rs`, docs/performance.md §7).
//!
//! Invariants: counting never changes a result (a relaxed atomic add, about 5 ns, a few dozen a
//! step); the count is of the whole process (all threads, all runs), so read it as a difference
//! around the steps timed.
//!
//! A leaf (std only).

use std::sync::atomic::{AtomicU64, Ordering};

static FORK_JOINS: AtomicU64 = AtomicU64::new(0);

/// Count one parallel region (a rayon fork-join) about to be opened.
#[inline]
pub fn region() {
    FORK_JOINS.fetch_add(1, Ordering::Relaxed);
}

/// Parallel regions opened so far by this process.
pub fn fork_joins() -> u64 {
    FORK_JOINS.load(Ordering::Relaxed)
}
