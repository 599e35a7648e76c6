//! The static state of a dam before the earthquake, and the linear analyses on the bonded model.
//!
//! Owns: the construction sequence ([`sequence`]: self-weight on ungrouted monoliths, grouting,
//! the reservoir on the grouted dam), the static contact increments it solves with direct
//! solves ([`contact`]), the exact master–slave bonding of joints for linear analyses
//! ([`bonding`]), and natural frequencies and mode shapes ([`modes`]).
//! Inputs: a built `problem::Problem` and, for the sequence, the run object
//! `simulation::Simulation` whose state it sets. Outputs: the static displacement and contact
//! history in that state; modes as VTU + PVD. Invariant: the problem is never changed (the
//! sequence builds its gravity-only copy of the loads).

pub mod bonding;
pub mod contact;
pub mod modes;
pub mod sequence;
