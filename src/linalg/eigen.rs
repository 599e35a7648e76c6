//! The lowest modes of K φ = ω² M φ by shift-invert Lanczos on a sparse Cholesky factor.
//!
//! Operator: Op = (K − σM)⁻¹ M, self-adjoint in the M inner product; its largest eigenvalues
//! θ = 1/(ω² − σ) are the modes nearest above the shift σ. Lanczos with full
//! M-reorthogonalisation (twice, "twice is enough") builds T = QᵀM Op Q; its eigenpairs give
//! ω² = σ + 1/θ and φ = Q s, converged when the Lanczos residual |β_m s_m| ≤ tol θ. The subspace
//! grows (from max(2n, n + 20) vectors, doubled) until the n lowest pairs converge.
//!
//! Why this and not a crate: faer 0.24 has dense eigen-solvers and the sparse Cholesky, but no
//! sparse generalised eigen-solver; the Rust ARPACK bindings need Fortran and a system ARPACK
//! (not on a fresh Debian with only Rust and python3). Shift-invert Lanczos with full
//! reorthogonalisation is the textbook method for a few lowest modes (Ericsson & Ruhe 1980;
//! what Abaqus and ANSYS call Lanczos) and needs only the factorisation we already have.
//!
//! M may be singular (massless dofs: the massless foundation): the starting vector is Op r,
//! in the range of Op, so the Krylov space never meets M's null space and the modes are those
//! of the statically condensed problem (the infinite eigenvalues have θ = 0 and never appear).

use super::{Csc, LinalgError, SparseCholesky};
use faer::Par;

/// Knobs of [`lowest_modes`].
#[derive(Clone, Debug)]
pub struct ModesOptions {
    /// Modes wanted. Default 6.
    pub count: usize,
    /// Shift σ [1/s²]. Default 0 (K must be positive definite on the dofs: supported models);
    /// a negative shift also finds rigid-body modes (ω² = 0) of an unsupported model.
    pub shift: f64,
    /// Relative Lanczos residual at which a pair is converged. Default 1e-10 (ω² to about
    /// 1e-10 relative: well past any use of a frequency).
    pub tolerance: f64,
}

impl Default for ModesOptions {
    fn default() -> Self {
        ModesOptions { count: 6, shift: 0.0, tolerance: 1e-10 }
    }
}

/// Modes, lowest first.
#[derive(Clone, Debug)]
pub struct Modes {
    /// ω² [1/s²].
    pub omega2: Vec<f64>,
    /// Mode shapes on the problem's dofs, M-normalised (φᵀ M φ = 1).
    pub shapes: Vec<Vec<f64>>,
    /// Lanczos vectors used.
    pub lanczos_steps: usize,
    /// Relative residual ‖K φ − ω² M φ‖ / ‖K φ‖ of each mode (checked after the solve).
    pub residual: Vec<f64>,
}

impl Modes {
    /// Natural frequency of mode i [Hz].
    pub fn frequency(&self, i: usize) -> f64 {
        self.omega2[i].max(0.0).sqrt() / (2.0 * std::f64::consts::PI)
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The `opts.count` lowest modes of K φ = ω² M φ (K, M on the same dofs).
pub fn lowest_modes(k: &Csc, m: &Csc, opts: &ModesOptions) -> Result<Modes, LinalgError> {
    let n = k.n_rows;
    if m.n_rows != n || k.n_cols != n || m.n_cols != n {
        return Err(LinalgError::Invalid(format!("modes: K is {}×{} and M {}×{}", k.n_rows, k.n_cols, m.n_rows, m.n_cols)));
    }
    let mut mdiag_pos = 0usize;
    for j in 0..n {
        if m.get(j, j) > 0.0 {
            mdiag_pos += 1;
        }
    }
    let wanted = opts.count.min(mdiag_pos);
    if wanted == 0 {
        return Err(LinalgError::Invalid("modes: the model has no free dof with mass".into()));
    }
    // K − σ M on the pattern of K ∪ M
    let shifted = if opts.shift == 0.0 { k.clone() } else { add_scaled(k, m, -opts.shift) };
    let mut chol = SparseCholesky::factor(&shifted, "modes: K − σM", Par::Seq)?;
    let mut mv = vec![0.0; n];
    let mut dim = (2 * wanted).max(wanted + 20).min(mdiag_pos);
    loop {
        // deterministic start: a smooth, sign-varying vector mapped into the range of Op
        let r0: Vec<f64> = (0..n).map(|i| 1.0 + (0.7 * i as f64).sin()).collect();
        m.mul_into(&r0, &mut mv);
        let mut q0 = mv.clone();
        chol.solve_in_place(&mut q0);
        let mut qs: Vec<Vec<f64>> = Vec::with_capacity(dim);
        let mut mqs: Vec<Vec<f64>> = Vec::with_capacity(dim);
        let mut alpha = Vec::with_capacity(dim);
        let mut beta: Vec<f64> = Vec::with_capacity(dim);
        m.mul_into(&q0, &mut mv);
        let nrm = dot(&q0, &mv).sqrt();
        if !(nrm > 0.0) {
            return Err(LinalgError::Invalid("modes: the start vector has no mass (no dof with mass is coupled to the rest)".into()));
        }
        q0.iter_mut().for_each(|v| *v /= nrm);
        let mut mq: Vec<f64> = mv.iter().map(|v| v / nrm).collect();
        let mut q = q0;
        let mut w = Vec::with_capacity(n);
        let mut last_beta = 0.0;
        for j in 0..dim {
            // w = Op q = (K − σM)⁻¹ M q
            w.clear();
            w.extend_from_slice(&mq);
            chol.solve_in_place(&mut w);
            let a = dot(&w, &mq);
            alpha.push(a);
            qs.push(std::mem::take(&mut q));
            mqs.push(std::mem::take(&mut mq));
            for _ in 0..2 {
                for (qi, mqi) in qs.iter().zip(&mqs) {
                    let c = dot(&w, mqi);
                    w.iter_mut().zip(qi).for_each(|(x, y)| *x -= c * y);
                }
            }
            m.mul_into(&w, &mut mv);
            let b = dot(&w, &mv).max(0.0).sqrt();
            last_beta = b;
            if j + 1 == dim || b <= 1e-14 * a.abs() {
                break;
            }
            beta.push(b);
            q = w.iter().map(|v| v / b).collect();
            mq = mv.iter().map(|v| v / b).collect();
        }
        let steps = alpha.len();
        let mut t = nalgebra::DMatrix::<f64>::zeros(steps, steps);
        for i in 0..steps {
            t[(i, i)] = alpha[i];
            if i + 1 < steps {
                t[(i, i + 1)] = beta[i];
                t[(i + 1, i)] = beta[i];
            }
        }
        let eig = nalgebra::SymmetricEigen::new(t);
        let mut idx: Vec<usize> = (0..steps).collect();
        idx.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
        let take = wanted.min(steps);
        let converged = idx[..take].iter().all(|&i| {
            let th = eig.eigenvalues[i];
            th > 0.0 && (last_beta * eig.eigenvectors[(steps - 1, i)]).abs() <= opts.tolerance * th
        });
        let exhausted = steps < dim || dim >= mdiag_pos;
        if converged || exhausted {
            let mut omega2 = Vec::with_capacity(take);
            let mut shapes = Vec::with_capacity(take);
            let mut residual = Vec::with_capacity(take);
            let mut kp = vec![0.0; n];
            for &i in &idx[..take] {
                let th = eig.eigenvalues[i];
                if !(th > 0.0) {
                    break;
                }
                let w2 = opts.shift + 1.0 / th;
                let mut phi = vec![0.0; n];
                for (s, qv) in qs.iter().enumerate() {
                    let c = eig.eigenvectors[(s, i)];
                    phi.iter_mut().zip(qv).for_each(|(p, v)| *p += c * v);
                }
                m.mul_into(&phi, &mut mv);
                let nm = dot(&phi, &mv).sqrt();
                phi.iter_mut().for_each(|v| *v /= nm);
                mv.iter_mut().for_each(|v| *v /= nm);
                k.mul_into(&phi, &mut kp);
                let r = kp.iter().zip(&mv).map(|(a, b)| (a - w2 * b).powi(2)).sum::<f64>().sqrt();
                residual.push(r / dot(&kp, &kp).sqrt().max(1e-300));
                omega2.push(w2);
                shapes.push(phi);
            }
            if !converged && steps < take {
                return Err(LinalgError::Invalid(format!("modes: only {steps} modes exist on these dofs ({take} asked)")));
            }
            return Ok(Modes { omega2, shapes, lanczos_steps: steps, residual });
        }
        dim = (2 * dim).min(mdiag_pos);
    }
}

/// A + c B (patterns merged).
fn add_scaled(a: &Csc, b: &Csc, c: f64) -> Csc {
    let mut col_ptr = vec![0];
    let mut row = Vec::new();
    let mut val = Vec::new();
    for j in 0..a.n_cols {
        let (mut p, pe) = (a.col_ptr[j], a.col_ptr[j + 1]);
        let (mut q, qe) = (b.col_ptr[j], b.col_ptr[j + 1]);
        while p < pe || q < qe {
            let ra = if p < pe { a.row[p] } else { usize::MAX };
            let rb = if q < qe { b.row[q] } else { usize::MAX };
            if ra == rb {
                row.push(ra);
                val.push(a.val[p] + c * b.val[q]);
                p += 1;
                q += 1;
            } else if ra < rb {
                row.push(ra);
                val.push(a.val[p]);
                p += 1;
            } else {
                row.push(rb);
                val.push(c * b.val[q]);
                q += 1;
            }
        }
        col_ptr.push(row.len());
    }
    Csc { n_rows: a.n_rows, n_cols: a.n_cols, col_ptr, row, val }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::assemble::{dof_map, mass_matrix, restrict, stiffness};

    #[test]
    fn lanczos_matches_a_dense_generalised_solve() {
        // Reference: the dense problem L⁻¹ K L⁻ᵀ y = ω² y (M = L Lᵀ, nalgebra SymmetricEigen) on
        // a clamped 4×2×2 tet box, with a 3×3 mass block on one node; the 6 lowest ω² to 1e-9
        // relative (both are direct to round-off)
        let m = crate::linalg::assemble::tests::box_model(true, [4, 2, 2]);
        let k = stiffness(&m, &[true]);
        let n = 3 * m.n_nodes();
        let (map, nf) = dof_map(n, |d| m.is_free(d / 3, d % 3));
        let kff = restrict(&k, &map, nf, &map, nf);
        let node = m.n_nodes() - 1;
        let nv = nalgebra::Vector3::new(0.6, 0.0, 0.8);
        let block: [[f64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| 500.0 * nv[i] * nv[j]));
        let mff = mass_matrix(&m.mass.inertial, &[(node, block)], &map, nf);
        let modes = lowest_modes(&kff, &mff, &ModesOptions { count: 6, ..Default::default() }).unwrap();
        let kd = kff.to_dense();
        let md = mff.to_dense();
        let l = md.clone().cholesky().unwrap().l();
        let li = l.clone().try_inverse().unwrap();
        let a = &li * kd * li.transpose();
        let a = (&a + a.transpose()) * 0.5;
        let mut ev: Vec<f64> = nalgebra::SymmetricEigen::new(a).eigenvalues.iter().copied().collect();
        ev.sort_by(|a, b| a.total_cmp(b));
        assert_eq!(modes.omega2.len(), 6);
        for i in 0..6 {
            assert!((modes.omega2[i] - ev[i]).abs() < 1e-9 * ev[i], "mode {i}: {} vs dense {}", modes.omega2[i], ev[i]);
            assert!(modes.residual[i] < 1e-8, "mode {i} residual {}", modes.residual[i]);
        }
        // M-orthonormal shapes
        let mut mp = vec![0.0; nf];
        mff.mul_into(&modes.shapes[1], &mut mp);
        assert!((dot(&modes.shapes[1], &mp) - 1.0).abs() < 1e-10);
        assert!(dot(&modes.shapes[0], &mp).abs() < 1e-8);
    }

    #[test]
    fn negative_shift_finds_rigid_modes_of_a_free_body() {
        // an unsupported box: six ω² = 0 (rigid motions), then the first elastic mode > 0
        let m = crate::linalg::assemble::tests::box_model(false, [2, 1, 1]);
        let k = stiffness(&m, &[true]);
        let n = 3 * m.n_nodes();
        let (map, nf) = dof_map(n, |_| true);
        let kk = restrict(&k, &map, nf, &map, nf);
        let mm = mass_matrix(&m.mass.inertial, &[], &map, nf);
        let modes = lowest_modes(&kk, &mm, &ModesOptions { count: 7, shift: -1e3, ..Default::default() }).unwrap();
        for i in 0..6 {
            assert!(modes.omega2[i].abs() < 1e-6 * modes.omega2[6], "rigid mode {i}: {}", modes.omega2[i]);
        }
        assert!(modes.omega2[6] > 1e3);
    }

    #[test]
    fn cantilever_bending_frequencies_match_euler_bernoulli() {
        // Reference: Euler–Bernoulli cantilever, ω_i = (β_i L)² √(E I / (ρ A L⁴)) with
        // β1 L = 1.875104, β2 L = 4.694091. Beam 20 × 1 × 0.5 m (L/h = 40 in the weak
        // direction, 20 in the strong: shear and rotary inertia lower ω by < 0.5 %), ν = 0
        // (no Poisson stiffening at the clamp), hex8 40 × 2 × 2 (QM6 bending, lumped mass).
        // Tolerance 3 % on the first two bending modes about each axis.
        let (l, b, h) = (20.0, 1.0, 0.5);
        let m = crate::linalg::assemble::tests::box_model_of([l, b, h], false, [40, 2, 2], 0.0);
        let k = stiffness(&m, &[true]);
        let n = 3 * m.n_nodes();
        let (map, nf) = dof_map(n, |d| m.is_free(d / 3, d % 3));
        let kff = restrict(&k, &map, nf, &map, nf);
        let mff = mass_matrix(&m.mass.inertial, &[], &map, nf);
        let modes = lowest_modes(&kff, &mff, &ModesOptions { count: 6, ..Default::default() }).unwrap();
        let (e, rho, a) = (1e9, 2000.0, b * h);
        let eb = |bl: f64, i: f64| bl * bl * (e * i / (rho * a * l.powi(4))).sqrt();
        let (iz_weak, iy_strong) = (b * h.powi(3) / 12.0, h * b.powi(3) / 12.0);
        let mut expect = vec![eb(1.875104, iz_weak), eb(1.875104, iy_strong), eb(4.694091, iz_weak), eb(4.694091, iy_strong)];
        expect.sort_by(|a, b| a.total_cmp(b));
        // the lowest four modes of the solid are these four bending modes (torsion and the
        // axial mode are higher for this section)
        for (i, w) in expect.iter().enumerate() {
            let got = modes.omega2[i].sqrt();
            let err = (got - w).abs() / w;
            println!("bending mode {i}: {got:.4} rad/s, Euler–Bernoulli {w:.4} ({:+.2} %)", 100.0 * (got / w - 1.0));
            assert!(err < 0.03, "mode {i}: ω = {got}, Euler–Bernoulli {w}, error {:.2} %", 100.0 * err);
        }
    }
}
