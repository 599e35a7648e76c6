//! Output: VTU frames and `.pvd` series for ParaView (through the `vtk` leaf), joint-surface
//! files and their per-node envelopes (`joint_envelope.json`), a ParaView state (`pvsm`), CSV histories, the run's [`recorder::Recorder`] (schedule, monitors, peaks, progress)
//! and its [`summary::RunSummary`] (written and read back as `summary.json`).
//!
//! Owns only writing. Inputs: the immutable model/mesh and read-only views of the state.
//! Invariants: every file is written whole (temp file + rename), and the `.pvd` is
//! rewritten after every frame, so a run killed at any point leaves a readable series.

pub mod envelope;
pub mod frames;
pub mod history;
pub mod joint_envelope;
pub mod pvsm;
pub mod joints;
pub mod linearise;
pub mod recorder;
pub mod summary;

/// Principal stresses σ1 ≥ σ2 ≥ σ3 [Pa] of a Voigt stress (xx, yy, zz, xy, yz, zx).
pub fn principal_stresses(s: &[f64; 6]) -> [f64; 3] {
    let m = nalgebra::Matrix3::new(s[0], s[3], s[5], s[3], s[1], s[4], s[5], s[4], s[2]);
    let mut e: Vec<f64> = nalgebra::SymmetricEigen::new(m).eigenvalues.iter().copied().collect();
    e.sort_by(|a, b| b.total_cmp(a));
    [e[0], e[1], e[2]]
}

/// von Mises equivalent stress [Pa].
pub fn von_mises(s: &[f64; 6]) -> f64 {
    (0.5 * ((s[0] - s[1]).powi(2) + (s[1] - s[2]).powi(2) + (s[2] - s[0]).powi(2))
        + 3.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]))
        .sqrt()
}
