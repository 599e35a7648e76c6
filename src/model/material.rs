//! Linear elastic isotropic material (small strain). Units: E, λ, μ in Pa; ρ in kg/m³.

use nalgebra::Matrix6;

/// Lamé constants of one material.
#[derive(Clone, Copy, Debug)]
pub struct Lame {
    pub lambda: f64,
    pub mu: f64,
}

impl Lame {
    pub fn from_e_nu(e: f64, nu: f64) -> Lame {
        Lame { lambda: e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), mu: e / (2.0 * (1.0 + nu)) }
    }

    /// Elasticity matrix in Voigt form (xx, yy, zz, xy, yz, zx; engineering shear strains).
    pub fn d_matrix(&self) -> Matrix6<f64> {
        let mut d = Matrix6::zeros();
        for i in 0..3 {
            for j in 0..3 {
                d[(i, j)] = self.lambda;
            }
            d[(i, i)] += 2.0 * self.mu;
            d[(i + 3, i + 3)] = self.mu;
        }
        d
    }

    /// A factor L with D = L Lᵀ (Cholesky).
    pub fn d_sqrt(&self) -> Matrix6<f64> {
        self.d_matrix().cholesky().expect("D is positive definite for 0 ≤ ν < 0.5").l()
    }

    /// Hooke's law, the one place it is written: the stress σ = λ tr(ε) I + 2μ ε (Voigt: xx, yy,
    /// zz, xy, yz, zx) [Pa] of the small strain ε = sym(H) of a displacement gradient
    /// `h[i][j] = ∂u_i/∂x_j`.
    #[inline(always)]
    pub fn stress_of_gradient(&self, h: &[[f64; 3]; 3]) -> [f64; 6] {
        let tr = h[0][0] + h[1][1] + h[2][2];
        let l = self.lambda * tr;
        let mu = self.mu;
        [
            l + 2.0 * mu * h[0][0],
            l + 2.0 * mu * h[1][1],
            l + 2.0 * mu * h[2][2],
            mu * (h[0][1] + h[1][0]),
            mu * (h[1][2] + h[2][1]),
            mu * (h[2][0] + h[0][2]),
        ]
    }

    /// P-wave modulus λ + 2μ [Pa].
    pub fn p_modulus(&self) -> f64 {
        self.lambda + 2.0 * self.mu
    }
}

/// A material assigned to a physical volume group.
#[derive(Clone, Debug)]
pub struct Material {
    pub group: String,
    pub e: f64,
    pub nu: f64,
    pub rho: f64,
    pub lame: Lame,
}

impl Material {
    pub fn new(group: &str, e: f64, nu: f64, rho: f64) -> Material {
        Material { group: group.to_string(), e, nu, rho, lame: Lame::from_e_nu(e, nu) }
    }

    /// P-wave speed [m/s].
    pub fn wave_speed(&self) -> f64 {
        (self.lame.p_modulus() / self.rho).sqrt()
    }
}
