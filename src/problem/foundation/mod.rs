//! Massless foundation: static condensation of the unknowns of massless volume groups.
//!
//! A massless block keeps its stiffness and has no mass, so its interior unknowns u_f follow
//! the nodes that carry mass (u_b: the nodes it shares with massive elements) statically at
//! every instant: K_ff u_f + K_fb u_b = 0 (no load acts on them: no inertia, no weight, no base
//! force). [`Condensation`] factorises K_ff once (faer sparse Cholesky, AMD ordering) and gives
//! the massive nodes the force of the condensed foundation, K_bb u_b + K_bf u_f = S u_b with the
//! Schur complement S = K_bb − K_bf K_ff⁻¹ K_fb, by one of two methods
//! ([`CondensationMethod`], chosen by [`choose_method`]):
//!
//! - **Solve**: after each step's prediction (and the contact correction) u_f[n+1] =
//!   −K_ff⁻¹ K_fb u_b[n+1] (one sparse solve per step); the next element loop, massless elements
//!   included, gives S u_b without forming S. The state always holds u_f.
//! - **Schur**: S formed once (dense, n_b × n_b: K_ff⁻¹ K_fb by n_b solves in blocks of
//!   [`SCHUR_BLOCK`] columns, in parallel); the step's element loop leaves the massless elements
//!   out and adds S u_b on the interface (a dense product per step). u_f is not needed by the
//!   step: it is reconstructed (one solve for the vectors that lack it) only when an observer
//!   reads it ([`Condensation::complete_into`]: output frames, monitors on the foundation, the
//!   end of gravity relaxation) and is 0 in the state otherwise ([`Condensation::clear_into`]).
//!
//! Dofs: condensed = the components [`Model::condensed`] marks (nodes of massless blocks with
//! no mass, components not fixed by the boundary conditions: the far boundary is fixed, relative
//! form with a uniform base input); interface b = free components of nodes of massless elements
//! that carry mass. Fixed components keep relative displacement 0.
//!
//! Stable step: the foundation stiffens the interface nodes by S ≤ K_bb (Loewner order), so its
//! contribution to ω²_max is bounded by λ_max(M_b^{-½} K_bb M_b^{-½}) ≤ the largest Gershgorin row
//! sum Σ_j |K_ij| / √(m_i m_j) over the interface dofs ([`Condensation::omega2_bound`]), added to
//! the element bound of the massive elements (λ_max(A + B) ≤ λ_max(A) + λ_max(B)).

pub mod free_field;
pub mod massed;
pub mod radiating;

use crate::constraint::{Constraint, ConstraintInfo, StepContext};
use crate::error::StepError;
use crate::linalg::{dof_map, restrict, stiffness_of, Csc, LinalgError, SparseCholesky, NONE};
use crate::model::Model;
use faer::{Accum, Mat, Par};
use rayon::prelude::*;

/// How the condensed foundation's force S u_b reaches the step (module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum CondensationMethod {
    /// u_f = −K_ff⁻¹ K_fb u_b by a sparse solve every step.
    Solve,
    /// S formed once, S u_b every step, u_f reconstructed on demand.
    Schur,
}

/// Largest memory of a dense Schur complement [bytes]. Default 1 GiB: n_b ≤ 11 585 interface
/// unknowns (3 860 interface nodes, a dam footprint meshed at about 1/60 of its size); a larger
/// interface keeps the solve per step, whose factor is needed anyway.
pub const SCHUR_MEMORY_MAX: f64 = 1024.0 * 1024.0 * 1024.0;

/// Largest n_b² / nnz(L) for which the Schur complement is chosen ([`choose_method`]).
/// Default 4: half the measured break-even's lower bound (S u_b still 8× cheaper than the
/// solve at 1.26, the largest ratio measured), a margin for factors that stream better.
pub const SCHUR_FILL_RATIO: f64 = 4.0;

/// Right-hand sides per block when forming S. Default 32: a block solve reads the factor once
/// for all its columns (the triangular solves are memory-bound), and 32 columns of 10⁵ unknowns
/// (26 MB) per thread keep the working set modest.
pub const SCHUR_BLOCK: usize = 32;

/// Interface rows per task of the parallel product S u_b. Default 256: 256 columns of S
/// (S symmetric: y_i = S[:, i] · u_b) are 2 MB at n_b = 1000, enough work to hand to a thread.
const SCHUR_ROWS: usize = 256;

/// The method of a condensation with `n_b` interface unknowns and `factor_entries` entries in
/// the Cholesky factor of K_ff. Rule: **Schur** when the dense S fits [`SCHUR_MEMORY_MAX`] and
/// n_b² ≤ [`SCHUR_FILL_RATIO`] × nnz(L), else **Solve**. Why: both are memory-bound; a solve per
/// step reads L twice (forward and back substitution, 4 flops per entry) plus K_fb and a
/// scatter, while the product reads S once (2 flops per entry). Measured (benches/foundation.rs,
/// benches/dam.rs; docs/dam_physics.md, docs/performance.md §7): S u_b cheaper than the solve by
/// 8× at n_b²/nnz(L) = 1.26 (arch dam, coarse), 7.5× at 0.41 (default), 25–55× at 0.09 and 0.05
/// (foundation cubes of 10⁴ and 10⁵ unknowns). Forming S costs n_b solves in blocks (measured
/// as much as 250–460 single solves), repaid after as many steps; a run has thousands.
pub fn choose_method(n_b: usize, factor_entries: usize) -> CondensationMethod {
    let nb2 = (n_b as f64) * (n_b as f64);
    if 8.0 * nb2 <= SCHUR_MEMORY_MAX && nb2 <= SCHUR_FILL_RATIO * factor_entries as f64 {
        CondensationMethod::Schur
    } else {
        CondensationMethod::Solve
    }
}

/// The condensation of a model's massless blocks (built once, used every step).
pub struct Condensation {
    /// Model dofs of the condensed unknowns, in their order.
    pub f_dofs: Vec<usize>,
    /// Model dofs of the interface, in their order.
    pub b_dofs: Vec<usize>,
    /// K_fb (n_f × n_b).
    pub kfb: Csc,
    chol: SparseCholesky,
    /// The dense Schur complement (n_b × n_b, symmetric) with [`CondensationMethod::Schur`].
    schur: Option<Mat<f64>>,
    ub: Vec<f64>,
    sub: Vec<f64>,
    rhs: Vec<f64>,
    omega2: f64,
    /// Schur: how many of the state's newest displacement vectors (u[n+1], u[n], u[n−1]) lack
    /// their condensed part (0: all hold u_f; 3: none does, and their condensed entries are 0).
    stale: usize,
}

impl std::fmt::Debug for Condensation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Condensation {{ {:?}, condensed: {}, interface: {}, {:?} }}", self.method(), self.f_dofs.len(), self.b_dofs.len(), self.chol)
    }
}

/// What the condensation reports once (in the run's notes and the modes table).
#[derive(Clone, Debug, serde::Serialize)]
pub struct CondensationInfo {
    pub method: CondensationMethod,
    pub condensed_unknowns: usize,
    pub interface_unknowns: usize,
    pub factor_entries: usize,
    /// Memory of the dense Schur complement [bytes] (0 with the solve per step).
    pub schur_bytes: usize,
    /// Bound of the foundation's ω² on the interface [1/s²].
    pub omega2_bound: f64,
    /// Wall time of assembly, factorisation and (Schur) forming S [s].
    pub setup_time: f64,
}

impl Condensation {
    /// The condensation of `model`'s massless blocks; `None` when it has none. `method`: `None`
    /// chooses by [`choose_method`]. `par`: parallelism of faer's factorisation.
    pub fn build(model: &Model, par: Par, method: Option<CondensationMethod>) -> Result<Option<Condensation>, LinalgError> {
        if !model.massless.iter().any(|&m| m) {
            return Ok(None);
        }
        let k = stiffness_of(model, |c, _| model.massless_cells[c]);
        let n = 3 * model.n_nodes();
        let (fmap, nf) = dof_map(n, |d| model.condensed[d / 3] & (1 << (d % 3)) != 0);
        // interface: free dofs with mass that the massless elements touch (a non-empty column)
        let (bmap, nb) = dof_map(n, |d| model.condensed[d / 3] == 0 && model.is_free(d / 3, d % 3) && k.col_ptr[d + 1] > k.col_ptr[d]);
        let kff = restrict(&k, &fmap, nf, &fmap, nf);
        let kfb = restrict(&k, &fmap, nf, &bmap, nb);
        let chol = SparseCholesky::factor(&kff, "massless foundation: K_ff", par)?;
        // Gershgorin bound on the interface block, scaled by the interface masses
        let mut omega2 = 0.0f64;
        for j in 0..n {
            if bmap[j] == NONE {
                continue;
            }
            let mj = model.mass.inertial[j / 3];
            let mut s = 0.0;
            for p in k.col_ptr[j]..k.col_ptr[j + 1] {
                let i = k.row[p];
                if bmap[i] != NONE {
                    s += k.val[p].abs() / (mj * model.mass.inertial[i / 3]).sqrt();
                }
            }
            omega2 = omega2.max(s);
        }
        let method = method.unwrap_or_else(|| choose_method(nb, chol.factor_entries()));
        let schur = match method {
            CondensationMethod::Solve => None,
            CondensationMethod::Schur => Some(schur_complement(&restrict(&k, &bmap, nb, &bmap, nb), &kfb, &chol)?),
        };
        let f_dofs = (0..n).filter(|&d| fmap[d] != NONE).collect();
        let b_dofs: Vec<usize> = (0..n).filter(|&d| bmap[d] != NONE).collect();
        Ok(Some(Condensation { f_dofs, ub: vec![0.0; nb], sub: vec![0.0; nb], rhs: vec![0.0; nf], b_dofs, kfb, chol, schur, omega2, stale: 0 }))
    }

    /// The method in use.
    pub fn method(&self) -> CondensationMethod {
        if self.schur.is_some() { CondensationMethod::Schur } else { CondensationMethod::Solve }
    }

    /// ω² bound of the foundation on the interface [1/s²] (see the module doc).
    pub fn omega2_bound(&self) -> f64 {
        self.omega2
    }

    pub fn info(&self, setup_time: f64) -> CondensationInfo {
        CondensationInfo {
            method: self.method(),
            condensed_unknowns: self.f_dofs.len(),
            interface_unknowns: self.b_dofs.len(),
            factor_entries: self.chol.factor_entries(),
            schur_bytes: self.schur.as_ref().map(|s| 8 * s.nrows() * s.ncols()).unwrap_or(0),
            omega2_bound: self.omega2,
            setup_time,
        }
    }

    /// u_f ← −K_ff⁻¹ K_fb u_b on the model displacement vector `u` (one solve; either method).
    pub fn condense_into(&mut self, u: &mut [f64]) {
        for (x, &d) in self.ub.iter_mut().zip(&self.b_dofs) {
            *x = u[d];
        }
        self.rhs.fill(0.0);
        self.kfb.mul_add_into(&self.ub, &mut self.rhs);
        self.rhs.iter_mut().for_each(|v| *v = -*v);
        self.chol.solve_in_place(&mut self.rhs);
        for (&x, &d) in self.rhs.iter().zip(&self.f_dofs) {
            u[d] = x;
        }
    }

    /// f += S u_b on the interface dofs (Schur; nothing with the solve per step, where the
    /// element loop gives it). Deterministic whatever the thread count: each entry is one dot
    /// product S[:, i] · u_b (S symmetric).
    pub fn add_schur_force_into(&mut self, u: &[f64], f: &mut [f64]) {
        let Some(s) = self.schur.as_ref() else { return };
        for (x, &d) in self.ub.iter_mut().zip(&self.b_dofs) {
            *x = u[d];
        }
        let ub = faer::ColRef::from_slice(&self.ub);
        let rows = |(k, y): (usize, &mut [f64])| {
            let (r0, len) = (k * SCHUR_ROWS, y.len());
            let yv = faer::ColMut::from_slice_mut(y);
            faer::linalg::matmul::matmul(yv, Accum::Replace, s.subcols(r0, len).transpose(), ub, 1.0, Par::Seq);
        };
        if self.sub.len() >= 4 * SCHUR_ROWS {
            crate::par::region();
            self.sub.par_chunks_mut(SCHUR_ROWS).enumerate().for_each(rows);
        } else {
            self.sub.chunks_mut(SCHUR_ROWS).enumerate().for_each(rows);
        }
        for (&y, &d) in self.sub.iter().zip(&self.b_dofs) {
            f[d] += y;
        }
    }

    /// Schur: one more step taken (the newest vector lacks u_f).
    pub fn step_taken(&mut self) {
        self.stale = (self.stale + 1).min(3);
    }

    /// Schur: set u_f on the state's displacement vectors that lack it (`newest_first` =
    /// [u[n+1], u[n], u[n−1]]): one solve with a right-hand side per vector. The solve method
    /// always holds u_f: nothing to do.
    pub fn complete_into(&mut self, newest_first: [&mut [f64]; 3]) -> Result<(), LinalgError> {
        if self.schur.is_none() || self.stale == 0 {
            self.stale = 0;
            return Ok(());
        }
        let k = self.stale;
        let nf = self.f_dofs.len();
        let mut x = Mat::<f64>::zeros(nf, k);
        for (j, u) in newest_first.iter().take(k).enumerate() {
            for (b, &d) in self.b_dofs.iter().enumerate() {
                let ub = -u[d];
                if ub != 0.0 {
                    for p in self.kfb.col_ptr[b]..self.kfb.col_ptr[b + 1] {
                        x[(self.kfb.row[p], j)] += self.kfb.val[p] * ub;
                    }
                }
            }
        }
        self.chol.solve_block_in_place(x.as_mut())?;
        for (j, u) in newest_first.into_iter().take(k).enumerate() {
            for (i, &d) in self.f_dofs.iter().enumerate() {
                u[d] = x[(i, j)];
            }
        }
        self.stale = 0;
        Ok(())
    }

    /// Schur: zero u_f on the state's vectors (`newest_first` as in [`Self::complete_into`]),
    /// so that no observer reads a stale mixture; a no-op when they are zero already, and with
    /// the solve method.
    pub fn clear_into(&mut self, newest_first: [&mut [f64]; 3]) {
        if self.schur.is_none() || self.stale == 3 {
            return;
        }
        for u in newest_first {
            for &d in &self.f_dofs {
                u[d] = 0.0;
            }
        }
        self.stale = 3;
    }
}

/// S = K_bb − K_bf K_ff⁻¹ K_fb, dense and symmetrised, from `kbb` (n_b × n_b), K_fb and the
/// factor of K_ff: K_ff⁻¹ K_fb by blocks of [`SCHUR_BLOCK`] columns solved in parallel.
fn schur_complement(kbb: &Csc, kfb: &Csc, chol: &SparseCholesky) -> Result<Mat<f64>, LinalgError> {
    let (nf, nb) = (kfb.n_rows, kfb.n_cols);
    if 8.0 * (nb as f64) * (nb as f64) > SCHUR_MEMORY_MAX {
        return Err(LinalgError::OutOfMemory { what: format!("massless foundation: dense Schur complement of {nb} interface unknowns (limit SCHUR_MEMORY_MAX)"), n: nb });
    }
    let blocks: Vec<usize> = (0..nb).step_by(SCHUR_BLOCK).collect();
    let cols: Vec<Vec<f64>> = blocks
        .par_iter()
        .map(|&j0| {
            let bs = SCHUR_BLOCK.min(nb - j0);
            let mut x = Mat::<f64>::zeros(nf, bs);
            for jj in 0..bs {
                for p in kfb.col_ptr[j0 + jj]..kfb.col_ptr[j0 + jj + 1] {
                    x[(kfb.row[p], jj)] = kfb.val[p];
                }
            }
            chol.solve_block_in_place(x.as_mut())?;
            // S[:, j] = K_bb[:, j] − K_fbᵀ X[:, j]
            let mut out = vec![0.0; nb * bs];
            for jj in 0..bs {
                let o = &mut out[jj * nb..(jj + 1) * nb];
                let j = j0 + jj;
                for p in kbb.col_ptr[j]..kbb.col_ptr[j + 1] {
                    o[kbb.row[p]] = kbb.val[p];
                }
                let xc = x.col_as_slice(jj);
                for (i, oi) in o.iter_mut().enumerate() {
                    let mut acc = 0.0;
                    for p in kfb.col_ptr[i]..kfb.col_ptr[i + 1] {
                        acc += kfb.val[p] * xc[kfb.row[p]];
                    }
                    *oi -= acc;
                }
            }
            Ok(out)
        })
        .collect::<Result<_, LinalgError>>()?;
    let mut s = Mat::<f64>::zeros(nb, nb);
    for (&j0, c) in blocks.iter().zip(&cols) {
        for (jj, col) in c.chunks_exact(nb).enumerate() {
            s.col_as_slice_mut(j0 + jj).copy_from_slice(col);
        }
    }
    // symmetrise (round-off): the energy of S u_b is then exactly ½ u_bᵀ S u_b
    for j in 0..nb {
        for i in 0..j {
            let a = 0.5 * (s[(i, j)] + s[(j, i)]);
            s[(i, j)] = a;
            s[(j, i)] = a;
        }
    }
    Ok(s)
}

impl<H: ?Sized> Constraint<H> for Condensation {
    /// Solve method: the condensed displacements of the predicted (and contact-corrected)
    /// u[n+1]; no work is done (the condensed unknowns carry no load, and the strain energy
    /// ½ uᵀKu of the condensed state is ½ u_bᵀ S u_b). Schur: nothing (u_f is left 0 by the
    /// prediction, the step applies S u_b instead, [`Condensation::step_taken`] counts it).
    fn correct(&mut self, _model: &Model, _history: &mut H, _step: &StepContext<'_>, u_next: &mut [f64]) -> Result<ConstraintInfo, StepError> {
        if self.schur.is_none() {
            self.condense_into(u_next);
        } else {
            self.step_taken();
        }
        Ok(ConstraintInfo::default())
    }

    fn replaces_massless_elements(&self) -> bool {
        self.schur.is_some()
    }

    fn add_internal_force_into(&mut self, u: &[f64], f: &mut [f64]) {
        self.add_schur_force_into(u, f);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_method_rule_follows_the_measured_cases() {
        // the cases of docs/performance.md §7: foundation cubes 10⁴ and 10⁵, arch dam coarse and
        // default (all measured faster with S), and the memory limit (n_b = 12 000: 1.15 GB)
        assert_eq!(choose_method(675, 5_015_520), CondensationMethod::Schur);
        assert_eq!(choose_method(3072, 191_401_389), CondensationMethod::Schur);
        assert_eq!(choose_method(282, 63_012), CondensationMethod::Schur);
        assert_eq!(choose_method(516, 647_406), CondensationMethod::Schur);
        assert_eq!(choose_method(12_000, 1_000_000_000_000), CondensationMethod::Solve);
        // a small foundation under a wide interface: S denser than 4 × the factor
        assert_eq!(choose_method(300, 20_000), CondensationMethod::Solve);
    }
}
