//! Trilinear hexahedron (hex8) that does not lock in bending.
//!
//! Formulation ("mean strain + condensed hourglass stiffness"): the nodal displacement field of
//! each component is split exactly into constant, linear and four hourglass parts,
//! u = T c with T = [1, x, y, z, h1..h4] (h_α the ±1 hourglass patterns ξη, ηζ, ζξ, ξηζ at the nodes).
//! The rows of T⁻¹ give the mean gradient operator b (rows 1–3) and the hourglass
//! operator Γ (rows 4–7); Γ is orthogonal to every linear field, so the element passes the
//! patch test exactly. The element stiffness is
//!
//!   K = V bᵀ D b  (one-point, exact for linear fields)  +  Γᵀ H Γ  (12×12 hourglass stiffness),
//!
//! where H is the hourglass block of the **incompatible-modes element** (Wilson–Taylor QM6,
//! 2×2×2 Gauss, Taylor's centre-Jacobian modification, 9 bubble modes condensed). For a
//! parallelepiped the linear–hourglass coupling of QM6 vanishes, so K equals QM6 exactly and
//! pure bending is exact; for distorted elements only that coupling is dropped (H stays
//! positive definite on the hourglass modes, so the element stays stable). The cost per step is
//! a one-point element plus a 12×12 product; H, b, Γ depend only on shape and material, so
//! congruent elements (structured meshes) share one [`HexShape`].

use super::material::Lame;
use crate::mesh::cell::HEX8_REF;
use nalgebra::{DMatrix, Matrix3, SMatrix, SymmetricEigen, Vector3};

/// Shape-and-material data shared by congruent hexahedra.
#[derive(Clone, Debug)]
pub struct HexShape {
    /// Mean gradient operator b[a][j] (node a, direction j), row-major 8×3.
    pub b: [f64; 24],
    /// Hourglass operator Γ[α][a], row-major 4×8.
    pub gamma: [f64; 32],
    /// Hourglass stiffness H[(α,i),(β,j)] (index 3α+i), row-major 12×12 [N/m].
    pub h: [f64; 144],
    /// Volume [m³].
    pub vol: f64,
    /// Lumped mass fractions ∫N_a dV / V (row-sum lumping).
    pub mass_frac: [f64; 8],
}

fn hourglass_patterns() -> [[f64; 8]; 4] {
    let mut h = [[0.0; 8]; 4];
    for a in 0..8 {
        let [x, y, z] = HEX8_REF[a];
        h[0][a] = x * y;
        h[1][a] = y * z;
        h[2][a] = z * x;
        h[3][a] = x * y * z;
    }
    h
}

/// Reference derivatives ∂N_a/∂ξ_k of the 8 shape functions at ξ.
pub(crate) fn dshape(xi: [f64; 3]) -> [[f64; 3]; 8] {
    let mut d = [[0.0; 3]; 8];
    for a in 0..8 {
        let r = HEX8_REF[a];
        let f = [1.0 + xi[0] * r[0], 1.0 + xi[1] * r[1], 1.0 + xi[2] * r[2]];
        d[a][0] = 0.125 * r[0] * f[1] * f[2];
        d[a][1] = 0.125 * r[1] * f[0] * f[2];
        d[a][2] = 0.125 * r[2] * f[0] * f[1];
    }
    d
}

/// J[(i, k)] = ∂x_i/∂ξ_k from the corners and the reference derivatives.
pub(crate) fn jacobian(x: &[Vector3<f64>; 8], d: &[[f64; 3]; 8]) -> Matrix3<f64> {
    let mut j = Matrix3::zeros();
    for a in 0..8 {
        for i in 0..3 {
            for k in 0..3 {
                j[(i, k)] += x[a][i] * d[a][k];
            }
        }
    }
    j
}

/// Strain-displacement rows (6) for a scalar field with physical gradient g, component-wise columns.
fn b_cols(g: Vector3<f64>) -> [[f64; 6]; 3] {
    let (x, y, z) = (g[0], g[1], g[2]);
    [[x, 0.0, 0.0, y, 0.0, z], [0.0, y, 0.0, x, z, 0.0], [0.0, 0.0, z, 0.0, y, x]]
}

/// Build the shape data of one hex from its corner coordinates; `None` if degenerate.
pub fn hex_shape(x: &[Vector3<f64>; 8], m: &Lame) -> Option<HexShape> {
    let d = m.d_matrix();
    let dm = DMatrix::from_fn(6, 6, |i, j| d[(i, j)]);
    // --- QM6 stiffness, 2×2×2 Gauss
    let j0 = jacobian(x, &dshape([0.0; 3]));
    let det0 = j0.determinant();
    if !(det0 > 0.0) {
        return None;
    }
    let j0inv_t = j0.try_inverse()?.transpose();
    let gp = 1.0 / 3f64.sqrt();
    let mut kuu = DMatrix::<f64>::zeros(24, 24);
    let mut kua = DMatrix::<f64>::zeros(24, 9);
    let mut kaa = DMatrix::<f64>::zeros(9, 9);
    let mut vol = 0.0;
    let mut mass = [0.0; 8];
    for &s0 in &[-gp, gp] {
        for &s1 in &[-gp, gp] {
            for &s2 in &[-gp, gp] {
                let xi = [s0, s1, s2];
                let dn = dshape(xi);
                let j = jacobian(x, &dn);
                let det = j.determinant();
                if !(det > 0.0) {
                    return None;
                }
                vol += det;
                for a in 0..8 {
                    let r = HEX8_REF[a];
                    mass[a] += det * 0.125 * (1.0 + xi[0] * r[0]) * (1.0 + xi[1] * r[1]) * (1.0 + xi[2] * r[2]);
                }
                let jit = j.try_inverse()?.transpose();
                let mut b = DMatrix::<f64>::zeros(6, 24);
                for a in 0..8 {
                    let g = jit * Vector3::new(dn[a][0], dn[a][1], dn[a][2]);
                    for (i, col) in b_cols(g).iter().enumerate() {
                        for r in 0..6 {
                            b[(r, 3 * a + i)] = col[r];
                        }
                    }
                }
                // incompatible modes P_k = 1 − ξ_k², gradient with the centre Jacobian (Taylor)
                let mut gm = DMatrix::<f64>::zeros(6, 9);
                for k in 0..3 {
                    let mut dp = Vector3::zeros();
                    dp[k] = -2.0 * xi[k];
                    let g = j0inv_t * dp;
                    for (i, col) in b_cols(g).iter().enumerate() {
                        for r in 0..6 {
                            gm[(r, 3 * k + i)] = col[r];
                        }
                    }
                }
                kuu += b.transpose() * &dm * &b * det;
                kua += b.transpose() * &dm * &gm * det0;
                kaa += gm.transpose() * &dm * &gm * (det0 * det0 / det);
            }
        }
    }
    let kaa_inv = kaa.clone().cholesky()?.inverse();
    let k = &kuu - &kua * kaa_inv * kua.transpose();

    // --- T = [1, x, y, z, h1..h4] (coordinates relative to the centroid for conditioning)
    let c = x.iter().fold(Vector3::zeros(), |s, p| s + p) / 8.0;
    let hp = hourglass_patterns();
    let mut t = SMatrix::<f64, 8, 8>::zeros();
    for a in 0..8 {
        t[(a, 0)] = 1.0;
        for i in 0..3 {
            t[(a, 1 + i)] = x[a][i] - c[i];
        }
        for al in 0..4 {
            t[(a, 4 + al)] = hp[al][a];
        }
    }
    let tinv = t.try_inverse()?;
    let mut b = [0.0; 24];
    let mut gamma = [0.0; 32];
    for a in 0..8 {
        for jd in 0..3 {
            b[3 * a + jd] = tinv[(1 + jd, a)];
        }
        for al in 0..4 {
            gamma[8 * al + a] = tinv[(4 + al, a)];
        }
    }
    // H[(α,i),(β,j)] = h_αᵀ K_ij h_β
    let mut h = [0.0; 144];
    for al in 0..4 {
        for i in 0..3 {
            for be in 0..4 {
                for jd in 0..3 {
                    let mut s = 0.0;
                    for a in 0..8 {
                        for bb in 0..8 {
                            s += hp[al][a] * k[(3 * a + i, 3 * bb + jd)] * hp[be][bb];
                        }
                    }
                    h[12 * (3 * al + i) + 3 * be + jd] = s;
                }
            }
        }
    }
    for v in mass.iter_mut() {
        *v /= vol;
    }
    Some(HexShape { b, gamma, h, vol, mass_frac: mass })
}

/// Stress (xx, yy, zz, xy, yz, zx) [Pa], mean over the element, from nodal displacements.
#[inline(always)]
pub fn stress(s: &HexShape, u: &[[f64; 3]; 8], m: &Lame) -> [f64; 6] {
    let mut h = [[0.0; 3]; 3];
    for a in 0..8 {
        for i in 0..3 {
            for j in 0..3 {
                h[i][j] += u[a][i] * s.b[3 * a + j];
            }
        }
    }
    m.stress_of_gradient(&h)
}

/// Internal nodal forces K u for one hex.
#[inline(always)]
pub fn internal_forces(s: &HexShape, u: &[[f64; 3]; 8], m: &Lame) -> [[f64; 3]; 8] {
    let sig = stress(s, u, m);
    let v = s.vol;
    let mut f = [[0.0; 3]; 8];
    for a in 0..8 {
        let (gx, gy, gz) = (s.b[3 * a], s.b[3 * a + 1], s.b[3 * a + 2]);
        f[a][0] = v * (sig[0] * gx + sig[3] * gy + sig[5] * gz);
        f[a][1] = v * (sig[3] * gx + sig[1] * gy + sig[4] * gz);
        f[a][2] = v * (sig[5] * gx + sig[4] * gy + sig[2] * gz);
    }
    // hourglass amplitudes q[3α+i] = Σ_a Γ[α][a] u[a][i]
    let mut q = [0.0; 12];
    for al in 0..4 {
        for a in 0..8 {
            let g = s.gamma[8 * al + a];
            q[3 * al] += g * u[a][0];
            q[3 * al + 1] += g * u[a][1];
            q[3 * al + 2] += g * u[a][2];
        }
    }
    let mut hq = [0.0; 12];
    for r in 0..12 {
        let row = &s.h[12 * r..12 * r + 12];
        let mut acc = 0.0;
        for c in 0..12 {
            acc += row[c] * q[c];
        }
        hq[r] = acc;
    }
    for al in 0..4 {
        for a in 0..8 {
            let g = s.gamma[8 * al + a];
            f[a][0] += g * hq[3 * al];
            f[a][1] += g * hq[3 * al + 1];
            f[a][2] += g * hq[3 * al + 2];
        }
    }
    f
}

/// Largest eigenvalue of M_e⁻¹ K_e [1/s²] with the lumped masses ρ V mass_frac.
pub fn max_eigenvalue(s: &HexShape, rho: f64, m: &Lame) -> f64 {
    let mut k = DMatrix::<f64>::zeros(24, 24);
    for a in 0..8 {
        for i in 0..3 {
            let mut u = [[0.0; 3]; 8];
            u[a][i] = 1.0;
            let f = internal_forces(s, &u, m);
            for b in 0..8 {
                for j in 0..3 {
                    k[(3 * b + j, 3 * a + i)] = f[b][j];
                }
            }
        }
    }
    let mut sc = [0.0; 24];
    for a in 0..8 {
        for i in 0..3 {
            sc[3 * a + i] = 1.0 / (rho * s.vol * s.mass_frac[a]).sqrt();
        }
    }
    let a = DMatrix::from_fn(24, 24, |r, c| 0.5 * (k[(r, c)] + k[(c, r)]) * sc[r] * sc[c]);
    SymmetricEigen::new(a).eigenvalues.max()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brick(a: f64, b: f64, c: f64) -> [Vector3<f64>; 8] {
        let mut x = [Vector3::zeros(); 8];
        for i in 0..8 {
            let r = HEX8_REF[i];
            x[i] = Vector3::new(0.5 * a * (r[0] + 1.0), 0.5 * b * (r[1] + 1.0), 0.5 * c * (r[2] + 1.0));
        }
        x
    }

    #[test]
    fn rigid_modes_give_no_force_and_linear_fields_exact_stress() {
        let m = Lame::from_e_nu(1e9, 0.25);
        let x = brick(2.0, 1.0, 0.5);
        let s = hex_shape(&x, &m).unwrap();
        assert!((s.vol - 1.0).abs() < 1e-12);
        // rigid rotation about z (small): u = (−θ y, θ x, 0)
        let th = 1e-3;
        let u: [[f64; 3]; 8] = std::array::from_fn(|a| [-th * x[a][1], th * x[a][0], 0.0]);
        let f = internal_forces(&s, &u, &m);
        assert!(f.iter().flatten().all(|v| v.abs() < 1e-3), "{f:?}");
        // uniaxial strain ε_xx = 1e-4: σ_xx = (λ+2μ) ε, σ_yy = λ ε
        let u: [[f64; 3]; 8] = std::array::from_fn(|a| [1e-4 * x[a][0], 0.0, 0.0]);
        let sig = stress(&s, &u, &m);
        assert!((sig[0] - m.p_modulus() * 1e-4).abs() < 1e-6 * m.p_modulus() * 1e-4);
        assert!((sig[1] - m.lambda * 1e-4).abs() < 1e-6 * m.p_modulus() * 1e-4);
    }

    #[test]
    fn pure_bending_is_exact_for_a_brick() {
        // Reference: Euler–Bernoulli pure bending with ν = 0: u = −κ x z, w = κ x²/2 gives
        // strain energy ½ E I κ² L exactly; the QM6 hourglass stiffness reproduces it (tolerance 1e-9).
        let e = 1e9;
        let m = Lame::from_e_nu(e, 0.0);
        let (a, b, c) = (2.0, 1.0, 0.5);
        let x = brick(a, b, c);
        let s = hex_shape(&x, &m).unwrap();
        let kappa = 1e-3;
        let zc = c / 2.0;
        let u: [[f64; 3]; 8] = std::array::from_fn(|i| {
            let (px, pz) = (x[i][0], x[i][2] - zc);
            [-kappa * px * pz, 0.0, 0.5 * kappa * px * px]
        });
        let f = internal_forces(&s, &u, &m);
        let energy: f64 = (0..8).map(|i| 0.5 * (f[i][0] * u[i][0] + f[i][1] * u[i][1] + f[i][2] * u[i][2])).sum();
        let inertia = b * c.powi(3) / 12.0;
        let exact = 0.5 * e * inertia * kappa * kappa * a;
        assert!((energy - exact).abs() < 1e-9 * exact, "energy {energy} exact {exact}");
    }
}
