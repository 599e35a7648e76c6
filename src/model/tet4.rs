//! Linear tetrahedron (tet4): constant strain, one integration point.
//!
//! Stored per element: 4 node ids, the gradients of N1..N3 (∇N0 = −Σ), the volume.
//! Internal force f_a = V σ ∇N_a (the force the element exerts is −f_a).

use super::material::Lame;
use nalgebra::{Matrix3, Matrix6, SymmetricEigen, Vector3};

/// Geometry of one tet: gradients of N1..N3 (row-major 3×3) and volume.
#[derive(Clone, Copy, Debug)]
pub struct TetGeom {
    pub grad: [f64; 9],
    pub vol: f64,
}

/// Gradients and volume from the 4 corner coordinates; `None` when degenerate or inverted.
pub fn tet_geometry(x: &[Vector3<f64>; 4]) -> Option<TetGeom> {
    let j = Matrix3::from_columns(&[x[1] - x[0], x[2] - x[0], x[3] - x[0]]);
    let det = j.determinant();
    if !(det > 0.0) {
        return None;
    }
    let inv = j.try_inverse()?; // rows of J⁻¹ are ∇N1, ∇N2, ∇N3
    let mut grad = [0.0; 9];
    for a in 0..3 {
        for k in 0..3 {
            grad[3 * a + k] = inv[(a, k)];
        }
    }
    Some(TetGeom { grad, vol: det / 6.0 })
}

/// The four gradients ∇N0..∇N3.
#[inline(always)]
pub fn gradients(g: &[f64; 9]) -> [[f64; 3]; 4] {
    let g1 = [g[0], g[1], g[2]];
    let g2 = [g[3], g[4], g[5]];
    let g3 = [g[6], g[7], g[8]];
    let g0 = [-(g1[0] + g2[0] + g3[0]), -(g1[1] + g2[1] + g3[1]), -(g1[2] + g2[2] + g3[2])];
    [g0, g1, g2, g3]
}

/// Stress (xx, yy, zz, xy, yz, zx) [Pa] from the element's nodal displacements (u[a][i]).
#[inline(always)]
pub fn stress(g: &[f64; 9], u: &[[f64; 3]; 4], m: &Lame) -> [f64; 6] {
    let gr = gradients(g);
    // displacement gradient H_ij = Σ_a u_ai ∂N_a/∂x_j
    let mut h = [[0.0; 3]; 3];
    for a in 0..4 {
        for i in 0..3 {
            for j in 0..3 {
                h[i][j] += u[a][i] * gr[a][j];
            }
        }
    }
    m.stress_of_gradient(&h)
}

/// Internal nodal forces f_a = V σ ∇N_a for nodal displacements u.
#[inline(always)]
pub fn internal_forces(g: &[f64; 9], vol: f64, u: &[[f64; 3]; 4], m: &Lame) -> [[f64; 3]; 4] {
    let s = stress(g, u, m);
    let gr = gradients(g);
    let mut f = [[0.0; 3]; 4];
    for a in 0..4 {
        let [gx, gy, gz] = gr[a];
        f[a][0] = vol * (s[0] * gx + s[3] * gy + s[5] * gz);
        f[a][1] = vol * (s[3] * gx + s[1] * gy + s[4] * gz);
        f[a][2] = vol * (s[5] * gx + s[4] * gy + s[2] * gz);
    }
    f
}

/// Largest eigenvalue of M_e⁻¹ K_e with lumped mass ρV/4 per node [1/s²].
/// Nonzero eigenvalues of K_e = V Bᵀ D B equal those of V L Bᵀ... computed on the 6×6 form
/// V D^{½} B Bᵀ D^{½}, with D^{½} from the material's Cholesky factor (exact, no estimate).
pub fn max_eigenvalue(g: &[f64; 9], vol: f64, rho: f64, m: &Lame) -> f64 {
    let gr = gradients(g);
    // B Bᵀ (6×6) with Voigt rows xx, yy, zz, xy, yz, zx (engineering shear)
    let mut bbt = Matrix6::<f64>::zeros();
    for a in 0..4 {
        let [x, y, z] = gr[a];
        // columns of B for node a (6×3)
        let cols = [[x, 0.0, 0.0, y, 0.0, z], [0.0, y, 0.0, x, z, 0.0], [0.0, 0.0, z, 0.0, y, x]];
        for c in cols.iter() {
            for r in 0..6 {
                for s in 0..6 {
                    bbt[(r, s)] += c[r] * c[s];
                }
            }
        }
    }
    let l = m.d_sqrt();
    let a = l.transpose() * bbt * l * vol;
    let lam = SymmetricEigen::new(a).eigenvalues.max();
    lam / (rho * vol / 4.0)
}
