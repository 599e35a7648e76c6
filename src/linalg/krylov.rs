//! Restarted GMRES with right preconditioning (Saad & Schultz 1986; Saad, *Iterative Methods
//! for Sparse Linear Systems*, 2nd ed., algorithm 9.5): x ≈ A⁻¹ b for a square operator A that
//! need not be symmetric, given as a product `apply(x, y)`: y = A x, and a preconditioner
//! `precondition(v)`: v ← M⁻¹ v (M ≈ A; here the Cholesky factorisation of a symmetric
//! positive definite part of A).
//!
//! Right preconditioning solves A M⁻¹ y = b, x = M⁻¹ y, so the residual GMRES minimises is the
//! true residual ‖b − A x‖ (not a preconditioned one): the tolerance means what it says. The
//! Arnoldi basis is orthogonalised by modified Gram–Schmidt, the small least-squares problem
//! by Givens rotations; at a restart the residual is recomputed from x.

/// Knobs of [`gmres_into`].
#[derive(Clone, Debug)]
pub struct GmresOptions {
    /// Krylov vectors kept before a restart. Default 60: 60 vectors of the unknowns' length
    /// (the fine dam's 1.4 × 10⁵ unknowns: 67 MB); enough that a good preconditioner never
    /// restarts.
    pub restart: usize,
    /// Largest number of operator products over all restarts. Default 600.
    pub max_iterations: usize,
    /// Converged when ‖b − A x‖ ≤ tolerance × ‖b‖ (dimensionless). Default 1e-10.
    pub tolerance: f64,
    /// Give up before `max_iterations` when the residual's history predicts that the
    /// tolerance cannot be reached by then ([`cannot_converge`]), measuring the contraction over
    /// this many products. Default 0: never (run to `max_iterations`).
    pub give_up_window: usize,
}

impl Default for GmresOptions {
    fn default() -> Self {
        GmresOptions { restart: 60, max_iterations: 600, tolerance: 1e-10, give_up_window: 0 }
    }
}

/// The early give-up rule of [`gmres_into`], written once: with `history[j]` the relative
/// residual ‖b − A x_j‖ / ‖b‖ after j products (GMRES's estimate; `history[0]` the start's),
/// the solve cannot converge within `cap` products when, after at least `window` products, the
/// last `window` products' contraction ρ = (history[j] / history[j − window])^(1/window), kept
/// up to the cap, leaves history[j] ρ^(cap − j) above `tolerance`. GMRES's residual never
/// grows, and its convergence speeds up rather than slows down as the Krylov space grows
/// (superlinear convergence), so a linear extrapolation is pessimistic only where the
/// contraction is about to speed up: a solve given up by it would have needed close to the cap
/// anyway. A `window` of 0 never gives up.
pub fn cannot_converge(history: &[f64], cap: usize, tolerance: f64, window: usize) -> bool {
    let j = history.len().saturating_sub(1);
    if window == 0 || j < window || j >= cap {
        return false;
    }
    let (now, before) = (history[j], history[j - window]);
    if !(before > 0.0) || now <= tolerance {
        return false;
    }
    let rate = (now / before).min(1.0);
    // log10 of the predicted residual at the cap
    now.log10() + (cap - j) as f64 / window as f64 * rate.log10() > tolerance.log10()
}

/// How a solve went.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct GmresInfo {
    /// Operator products.
    pub iterations: usize,
    /// ‖b − A x‖ / ‖b‖ at the end (recomputed from x; GMRES's estimate if given up).
    pub residual: f64,
    pub converged: bool,
    /// Stopped before `max_iterations` by the give-up rule ([`cannot_converge`]).
    pub gave_up: bool,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// x ← an approximation of A⁻¹ b, starting from the x given (its length is b's). A solve
/// given up ([`GmresOptions::give_up_window`]) returns at once, x as at its last restart.
pub fn gmres_into(mut apply: impl FnMut(&[f64], &mut [f64]), mut precondition: impl FnMut(&mut [f64]), b: &[f64], x: &mut [f64], opts: &GmresOptions) -> GmresInfo {
    let n = b.len();
    assert_eq!(x.len(), n, "gmres: x and b lengths");
    let m = opts.restart.max(1);
    let nb = dot(b, b).sqrt();
    let mut info = GmresInfo::default();
    if nb == 0.0 {
        x.fill(0.0);
        info.converged = true;
        return info;
    }
    let mut r = vec![0.0; n];
    let mut z = vec![0.0; n];
    let mut v: Vec<Vec<f64>> = Vec::with_capacity(m + 1);
    // Hessenberg columns (rotated), rotations (c, s), right-hand side g
    let mut h: Vec<Vec<f64>> = Vec::with_capacity(m);
    let mut rot: Vec<(f64, f64)> = Vec::with_capacity(m);
    let mut g = vec![0.0; m + 1];
    // the relative residual after each product (GMRES's estimate; the true one at a restart)
    let mut history: Vec<f64> = Vec::new();
    loop {
        // r = b − A x
        apply(x, &mut r);
        for (ri, bi) in r.iter_mut().zip(b) {
            *ri = bi - *ri;
        }
        let beta = dot(&r, &r).sqrt();
        info.residual = beta / nb;
        history.truncate(info.iterations);
        history.push(info.residual);
        if info.residual <= opts.tolerance {
            info.converged = true;
            return info;
        }
        if info.iterations >= opts.max_iterations {
            return info;
        }
        v.clear();
        h.clear();
        rot.clear();
        g.fill(0.0);
        g[0] = beta;
        v.push(r.iter().map(|a| a / beta).collect());
        let mut k = 0;
        while k < m && info.iterations < opts.max_iterations {
            // w = A M⁻¹ v_k
            z.copy_from_slice(&v[k]);
            precondition(&mut z);
            let mut w = vec![0.0; n];
            apply(&z, &mut w);
            info.iterations += 1;
            let mut col = vec![0.0; k + 2];
            for (i, vi) in v.iter().enumerate() {
                let c = dot(&w, vi);
                col[i] = c;
                w.iter_mut().zip(vi).for_each(|(a, b)| *a -= c * b);
            }
            let hn = dot(&w, &w).sqrt();
            col[k + 1] = hn;
            for (i, &(c, s)) in rot.iter().enumerate() {
                let (a, b) = (col[i], col[i + 1]);
                col[i] = c * a + s * b;
                col[i + 1] = -s * a + c * b;
            }
            let (a, b) = (col[k], col[k + 1]);
            let d = a.hypot(b);
            let (c, s) = if d == 0.0 { (1.0, 0.0) } else { (a / d, b / d) };
            col[k] = d;
            col[k + 1] = 0.0;
            rot.push((c, s));
            g[k + 1] = -s * g[k];
            g[k] *= c;
            h.push(col);
            k += 1;
            let breakdown = hn <= 1e-14 * beta;
            if g[k].abs() <= opts.tolerance * nb || breakdown {
                break;
            }
            history.push(g[k].abs() / nb);
            if cannot_converge(&history, opts.max_iterations, opts.tolerance, opts.give_up_window) {
                // x is left as it was at the cycle's start (the caller drops it)
                info.gave_up = true;
                info.residual = g[k].abs() / nb;
                return info;
            }
            v.push(w.iter().map(|a| a / hn).collect());
        }
        // y = H⁻¹ g (upper triangular k×k), x += M⁻¹ V y
        let mut y = vec![0.0; k];
        for i in (0..k).rev() {
            let s: f64 = (i + 1..k).map(|j| h[j][i] * y[j]).sum();
            y[i] = if h[i][i] != 0.0 { (g[i] - s) / h[i][i] } else { 0.0 };
        }
        z.fill(0.0);
        for (yi, vi) in y.iter().zip(&v) {
            z.iter_mut().zip(vi).for_each(|(a, b)| *a += yi * b);
        }
        precondition(&mut z);
        x.iter_mut().zip(&z).for_each(|(a, b)| *a += b);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 1-D convection–diffusion operator (tridiagonal, unsymmetric): −u'' + c u' on n
    /// points, central differences, Dirichlet ends.
    fn convection(n: usize, c: f64) -> nalgebra::DMatrix<f64> {
        let h = 1.0 / (n + 1) as f64;
        nalgebra::DMatrix::from_fn(n, n, |i, j| {
            if i == j {
                2.0 / (h * h)
            } else if j + 1 == i {
                -1.0 / (h * h) - c / (2.0 * h)
            } else if i + 1 == j {
                -1.0 / (h * h) + c / (2.0 * h)
            } else {
                0.0
            }
        })
    }

    #[test]
    fn gmres_matches_a_dense_lu_solve_of_an_unsymmetric_system() {
        // Reference: nalgebra's dense LU of the same matrix; GMRES to 1e-12 relative residual
        // with restarts (restart 10 < n = 80, Jacobi preconditioner), solution to 1e-8 relative
        let a = convection(80, 40.0);
        let b: Vec<f64> = (0..80).map(|i| (0.3 * i as f64).sin() + 1.0).collect();
        let exact = a.clone().lu().solve(&nalgebra::DVector::from_vec(b.clone())).unwrap();
        let diag: Vec<f64> = (0..80).map(|i| a[(i, i)]).collect();
        let mut x = vec![0.0; 80];
        let opts = GmresOptions { restart: 10, max_iterations: 5000, tolerance: 1e-12, give_up_window: 0 };
        let info = gmres_into(|u, y| y.copy_from_slice((&a * nalgebra::DVector::from_column_slice(u)).as_slice()), |v| v.iter_mut().zip(&diag).for_each(|(a, d)| *a /= d), &b, &mut x, &opts);
        assert!(info.converged && info.residual <= 1e-12, "{info:?}");
        assert!(info.iterations > 10, "the test must exercise a restart: {info:?}");
        let err = x.iter().zip(exact.iter()).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt() / exact.norm();
        assert!(err < 1e-8, "error {err}");
    }

    #[test]
    fn gmres_with_the_exact_inverse_converges_in_one_product() {
        // M = A: A M⁻¹ = I, so the first Krylov vector solves the system
        let a = convection(30, 5.0);
        let lu = a.clone().lu();
        let b: Vec<f64> = (0..30).map(|i| i as f64).collect();
        let mut x = vec![0.0; 30];
        let info = gmres_into(
            |u, y| y.copy_from_slice((&a * nalgebra::DVector::from_column_slice(u)).as_slice()),
            |v| {
                let s = lu.solve(&nalgebra::DVector::from_column_slice(v)).unwrap();
                v.copy_from_slice(s.as_slice());
            },
            &b,
            &mut x,
            &GmresOptions::default(),
        );
        assert!(info.converged && info.iterations == 1, "{info:?}");
    }

    #[test]
    fn give_up_rule_extrapolates_the_last_windows_contraction() {
        // the rule's arithmetic: after j products with residuals h, it gives up when
        // h_j (h_j / h_{j-w})^((cap - j) / w) > tolerance
        // a contraction of 0.5 per product from 1: 0.5^3 = 0.125 after 3, 0.125 × 0.5^7 ≈ 9.8e-4
        // at a cap of 10: reaches 1e-3, not 1e-4
        let h = [1.0, 0.5, 0.25, 0.125];
        assert!(!cannot_converge(&h, 10, 1e-3, 3));
        assert!(cannot_converge(&h, 10, 1e-4, 3));
        // not judged before `window` products, at or after the cap, with a window of 0, or once
        // converged
        assert!(!cannot_converge(&h[..3], 10, 1e-4, 3));
        assert!(!cannot_converge(&h, 3, 1e-4, 3));
        assert!(!cannot_converge(&h, 10, 1e-4, 0));
        assert!(!cannot_converge(&h, 10, 0.2, 3));
        // a stagnating residual (no contraction over the window) gives up at once
        assert!(cannot_converge(&[1.0, 0.5, 0.5, 0.5], 100, 1e-2, 2));
    }

    #[test]
    fn gmres_gives_up_early_when_it_cannot_reach_the_tolerance_by_its_cap() {
        // no preconditioner on the 400-point Laplacian (condition number 6e4): the residual
        // creeps, so with a cap of 100 and a window of 5 GMRES gives up within 20 products,
        // reporting it; the same solve without the rule runs to the cap unconverged
        let a = convection(400, 0.0);
        let b: Vec<f64> = (0..400).map(|i| (0.37 * i as f64).sin() + 1.0).collect();
        let apply = |u: &[f64], y: &mut [f64]| y.copy_from_slice((&a * nalgebra::DVector::from_column_slice(u)).as_slice());
        let opts = GmresOptions { restart: 120, max_iterations: 100, tolerance: 1e-8, give_up_window: 5 };
        let mut x = vec![0.0; 400];
        let info = gmres_into(apply, |_| {}, &b, &mut x, &opts);
        assert!(info.gave_up && !info.converged && info.iterations < 20, "{info:?}");
        let mut x = vec![0.0; 400];
        let full = gmres_into(apply, |_| {}, &b, &mut x, &GmresOptions { give_up_window: 0, ..opts });
        assert!(!full.gave_up && !full.converged && full.iterations == 100, "{full:?}");
        // a solve that converges well within its cap is not given up: Jacobi-preconditioned
        // convection–diffusion as in the first test, to 1e-12 within 5000 products
        let c = convection(80, 40.0);
        let diag: Vec<f64> = (0..80).map(|i| c[(i, i)]).collect();
        let mut x = vec![0.0; 80];
        let rhs: Vec<f64> = (0..80).map(|i| (0.3 * i as f64).sin() + 1.0).collect();
        let opts = GmresOptions { restart: 10, max_iterations: 5000, tolerance: 1e-12, give_up_window: 5 };
        let info = gmres_into(|u, y| y.copy_from_slice((&c * nalgebra::DVector::from_column_slice(u)).as_slice()), |v| v.iter_mut().zip(&diag).for_each(|(a, d)| *a /= d), &rhs, &mut x, &opts);
        assert!(info.converged && !info.gave_up, "{info:?}");
    }

    #[test]
    fn gmres_reports_no_convergence_when_out_of_iterations() {
        let a = convection(200, 0.0);
        let b = vec![1.0; 200];
        let mut x = vec![0.0; 200];
        let info = gmres_into(|u, y| y.copy_from_slice((&a * nalgebra::DVector::from_column_slice(u)).as_slice()), |_| {}, &b, &mut x, &GmresOptions { restart: 5, max_iterations: 12, tolerance: 1e-12, give_up_window: 0 });
        assert!(!info.converged && info.iterations == 12 && info.residual > 1e-12, "{info:?}");
    }
}
