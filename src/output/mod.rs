//! Output: VTU frames and `.pvd` series for ParaView, joint-surface files, CSV histories, summary.
//!
//! Owns only writing. Inputs: the immutable model/mesh and read-only views of the state.
//! Invariants: every file is written whole (temp file + rename), and the `.pvd` is
//! rewritten after every frame, so a run killed at any point leaves a readable series.

pub mod vtu;
