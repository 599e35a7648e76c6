//! Massless foundation: static condensation of the unknowns of massless volume groups.
//!
//! A massless block keeps its stiffness and has no mass, so its interior unknowns u_f follow
//! the nodes that carry mass (u_b: the nodes it shares with massive elements) statically at
//! every instant: K_ff u_f + K_fb u_b = 0 (no load acts on them: no inertia, no weight, no base
//! force). [`Condensation`] factorises K_ff once (faer sparse Cholesky, AMD ordering) and, after
//! each explicit step's prediction (and the contact correction), sets
//! u_f[n+1] = −K_ff⁻¹ K_fb u_b[n+1]. The next step's element loop then gives the massive nodes
//! the force of the condensed foundation, K_bb u_b + K_bf u_f = S u_b with the Schur complement
//! S = K_bb − K_bf K_ff⁻¹ K_fb, without forming S.
//!
//! Why a solve per step and not S: measured in `benches/foundation.rs` (docs/dam_physics.md):
//! S is dense on the interface (n_b² entries: 650 MB for a 3000-node dam footprint) and its
//! product costs about as much as the solve at 10⁵ foundation unknowns, while the solve keeps
//! the foundation's displacements and stresses for the output at no extra cost.
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

use crate::constraint::{Constraint, ConstraintInfo, StepContext};
use crate::error::StepError;
use crate::linalg::{dof_map, restrict, stiffness_of, Csc, LinalgError, SparseCholesky, NONE};
use crate::model::Model;
use faer::Par;

/// The condensation of a model's massless blocks (built once, solves every step).
pub struct Condensation {
    /// Model dofs of the condensed unknowns, in their order.
    pub f_dofs: Vec<usize>,
    /// Model dofs of the interface, in their order.
    pub b_dofs: Vec<usize>,
    /// K_fb (n_f × n_b).
    pub kfb: Csc,
    chol: SparseCholesky,
    ub: Vec<f64>,
    rhs: Vec<f64>,
    omega2: f64,
}

impl std::fmt::Debug for Condensation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Condensation {{ condensed: {}, interface: {}, {:?} }}", self.f_dofs.len(), self.b_dofs.len(), self.chol)
    }
}

/// What the condensation reports once (in the run's notes and the modes table).
#[derive(Clone, Debug, serde::Serialize)]
pub struct CondensationInfo {
    pub condensed_unknowns: usize,
    pub interface_unknowns: usize,
    pub factor_entries: usize,
    /// Bound of the foundation's ω² on the interface [1/s²].
    pub omega2_bound: f64,
    /// Wall time of assembly and factorisation [s].
    pub setup_time: f64,
}

impl Condensation {
    /// The condensation of `model`'s massless blocks; `None` when it has none.
    /// `par`: parallelism of faer's factorisation and solves.
    pub fn build(model: &Model, par: Par) -> Result<Option<Condensation>, LinalgError> {
        if !model.massless.iter().any(|&m| m) {
            return Ok(None);
        }
        let t0 = std::time::Instant::now();
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
        let f_dofs = (0..n).filter(|&d| fmap[d] != NONE).collect();
        let b_dofs: Vec<usize> = (0..n).filter(|&d| bmap[d] != NONE).collect();
        let _ = t0;
        Ok(Some(Condensation { f_dofs, ub: vec![0.0; nb], rhs: vec![0.0; nf], b_dofs, kfb, chol, omega2 }))
    }

    /// ω² bound of the foundation on the interface [1/s²] (see the module doc).
    pub fn omega2_bound(&self) -> f64 {
        self.omega2
    }

    pub fn info(&self, setup_time: f64) -> CondensationInfo {
        CondensationInfo {
            condensed_unknowns: self.f_dofs.len(),
            interface_unknowns: self.b_dofs.len(),
            factor_entries: self.chol.factor_entries(),
            omega2_bound: self.omega2,
            setup_time,
        }
    }

    /// u_f ← −K_ff⁻¹ K_fb u_b on the model displacement vector `u`.
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
}

impl<H: ?Sized> Constraint<H> for Condensation {
    /// The condensed displacements of the predicted (and contact-corrected) u[n+1]; no work is
    /// done (the condensed unknowns carry no load, and the strain energy ½ uᵀKu of the
    /// condensed state is ½ u_bᵀ S u_b).
    fn correct(&mut self, _model: &Model, _history: &mut H, _step: &StepContext<'_>, u_next: &mut [f64]) -> Result<ConstraintInfo, StepError> {
        self.condense_into(u_next);
        Ok(ConstraintInfo::default())
    }
}
