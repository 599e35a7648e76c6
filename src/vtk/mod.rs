//! The VTK writers shared by every stage that writes for ParaView: VTU unstructured grids
//! ([`vtu`], binary zlib-compressed) and `.pvd` time series ([`pvd`]). A leaf: the tagger's inspection
//! files (`interface`) and the run's frames and joint surfaces (`output`) both use it.
//!
//! Invariants: every file is written whole (temp file + rename), and a `.pvd` is rewritten after
//! every frame, so a run killed at any point leaves a readable series.

pub mod pvd;
pub mod vtu;
