//! Sparse linear algebra of the model: the global stiffness K as a faer sparse matrix, its
//! restriction to a set of unknowns, a sparse Cholesky factorisation (symbolic once with AMD or
//! METIS nested dissection ([`FillOrdering`]), numeric once or again on the same pattern, solves
//! repeated), restarted GMRES for unsymmetric
//! systems preconditioned by such a factorisation, and the lowest modes of K φ = ω² M φ.
//!
//! Owns: nothing that changes during a run. Inputs: the immutable [`Model`](crate::model::Model)
//! (its element kernels: Hooke's law and the B matrices are not written again here).
//! Outputs: [`Csc`] matrices, [`SparseCholesky`], [`Modes`], [`gmres_into`]'s solutions.
//! The threads of a factorisation: [`run_par`], written once.
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
pub mod tree_solve;

pub use assemble::{add_entries, dof_map, from_columns, mass_matrix, restrict, stiffness, stiffness_of, Csc, NONE};
pub use cholesky::{analyse, lu_solve_in_place, CholeskyAnalysis, FactorPrecision, SparseCholesky};
pub use eigen::{lowest_modes, Modes, ModesOptions};
pub use krylov::{gmres_into, GmresInfo, GmresOptions};
pub use ordering::{nested_dissection, FillOrdering};

/// The threads of a run's sparse Cholesky factorisations (faer's `Par`), one rule for every
/// caller: those of the rayon pool the caller runs in, which is the run's thread count
/// (`pipeline::default_threads`: one below 30 000 elements, else all cores; or `--threads`);
/// `Par::Seq` on one. Measured, the two-thread factor of the coarse, default and fine dam's
/// preconditioner is bit-identical to the one-thread factor (faer's parallel dense kernels
/// split the output blocks between the threads, not the sums); faer does not promise it, so
/// the test `dam_static_state_on_two_threads_equals_one_thread` holds the static state to
/// round-off (docs/performance.md §7b).
pub fn run_par() -> faer::Par {
    match rayon::current_num_threads() {
        0 | 1 => faer::Par::Seq,
        n => faer::Par::rayon(n),
    }
}

/// CPU seconds (user + system) of this process so far, all its threads (getrusage); 0 if the
/// call fails. For the solvers' cost notes: on a loaded machine the wall time is inflated,
/// the CPU time much less.
pub fn cpu_seconds() -> f64 {
    // SAFETY: a zeroed rusage is a valid value, and getrusage writes only the struct it is given
    let (r, status) = unsafe {
        let mut r: libc::rusage = std::mem::zeroed();
        let status = libc::getrusage(libc::RUSAGE_SELF, &mut r);
        (r, status)
    };
    if status != 0 {
        return 0.0;
    }
    let s = |t: libc::timeval| t.tv_sec as f64 + 1e-6 * t.tv_usec as f64;
    s(r.ru_utime) + s(r.ru_stime)
}

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
