//! Sparse linear algebra of the model: the global stiffness K as a faer sparse matrix, its
//! restriction to a set of unknowns, a sparse Cholesky factorisation (symbolic once with AMD or
//! METIS nested dissection ([`FillOrdering`]), numeric once or again on the same pattern, solves
//! repeated), restarted GMRES for unsymmetric
//! systems preconditioned by such a factorisation, and the lowest modes of K φ = ω² M φ.
//!
//! Owns: nothing that changes during a run. Inputs: the immutable [`Model`](crate::model::Model)
//! (its element kernels: Hooke's law and the B matrices are not written again here).
//! Outputs: [`Csc`] matrices, [`SparseCholesky`], [`Modes`], [`gmres_into`]'s solutions.
//!
//! Conventions (written once, here):
//! - Degrees of freedom are the model's, `3 * node + component`. A *dof map* sends a model dof
//!   to its index in a sub-problem (`NONE` = not in it); maps built by [`dof_map`] are
//!   increasing, so a restricted matrix keeps sorted row indices.
//! - Matrices are stored with both triangles (symmetric K, M), column-compressed (faer
//!   `SparseColMat<usize, f64>`); factorisations read the lower triangle only.
//! - Element stiffness is taken column by column from the element's internal-force kernel
//!   (`K_e e_j = f_int(e_j)`), so every K here is exactly the operator the explicit step applies.

pub mod assemble;
pub mod cholesky;
pub mod eigen;
pub mod krylov;
pub mod ordering;

pub use assemble::{add_entries, dof_map, from_columns, mass_matrix, restrict, stiffness, stiffness_of, Csc, NONE};
pub use cholesky::{analyse, lu_solve_in_place, CholeskyAnalysis, SparseCholesky};
pub use eigen::{lowest_modes, Modes, ModesOptions};
pub use krylov::{gmres_into, GmresInfo, GmresOptions};
pub use ordering::{nested_dissection, FillOrdering};

/// Failures of the sparse linear algebra, each with what to change.
#[derive(Debug, thiserror::Error)]
pub enum LinalgError {
    #[error("{what}: the stiffness matrix is not positive definite (Cholesky pivot {pivot} of {n} failed). The model can move without deforming: fix it (boundary conditions on the far boundary, `bc:fixed`), or bond the blocks that float")]
    NotPositiveDefinite { what: String, pivot: usize, n: usize },
    #[error("{what}: out of memory in the sparse factorisation of {n} unknowns")]
    OutOfMemory { what: String, n: usize },
    #[error("{0}")]
    Invalid(String),
}
