//! Standard and dual shape functions of a slave face (tri3, quad4; conventions in the module
//! doc of `contact::mortar`).

use nalgebra::{Matrix4, Vector3};

/// Standard shape functions at local coordinates `xi`: tri3 `[1 − ξ1 − ξ2, ξ1, ξ2]` on the unit
/// triangle, quad4 `¼ (1 ± ξ1)(1 ± ξ2)` on `[−1, 1]²` (Gmsh order); unused entries 0.
#[inline]
pub fn shape(n_nodes: usize, xi: [f64; 2]) -> [f64; 4] {
    let [a, b] = xi;
    if n_nodes == 3 {
        [1.0 - a - b, a, b, 0.0]
    } else {
        [0.25 * (1.0 - a) * (1.0 - b), 0.25 * (1.0 + a) * (1.0 - b), 0.25 * (1.0 + a) * (1.0 + b), 0.25 * (1.0 - a) * (1.0 + b)]
    }
}

/// Derivatives of [`shape`]: `[dN/dξ1, dN/dξ2]` per node.
#[inline]
pub fn shape_derivatives(n_nodes: usize, xi: [f64; 2]) -> [[f64; 2]; 4] {
    let [a, b] = xi;
    if n_nodes == 3 {
        [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0], [0.0, 0.0]]
    } else {
        [
            [-0.25 * (1.0 - b), -0.25 * (1.0 - a)],
            [0.25 * (1.0 - b), -0.25 * (1.0 + a)],
            [0.25 * (1.0 + b), 0.25 * (1.0 + a)],
            [-0.25 * (1.0 + b), 0.25 * (1.0 - a)],
        ]
    }
}

/// The tangent vectors `x_ξ1`, `x_ξ2` of a face with nodes `x` at `xi`.
#[inline]
pub fn tangents(x: &[Vector3<f64>], xi: [f64; 2]) -> (Vector3<f64>, Vector3<f64>) {
    let d = shape_derivatives(x.len(), xi);
    let mut a = Vector3::zeros();
    let mut b = Vector3::zeros();
    for (k, xk) in x.iter().enumerate() {
        a += xk * d[k][0];
        b += xk * d[k][1];
    }
    (a, b)
}

/// The 7-point degree-5 rule of Dunavant (1985) on a triangle: barycentric coordinates and
/// weights (summing to 1; multiply by the triangle's area).
pub fn triangle_rule() -> [([f64; 3], f64); 7] {
    let s = 15f64.sqrt();
    let (a, b) = ((6.0 - s) / 21.0, (6.0 + s) / 21.0);
    let (wa, wb) = ((155.0 - s) / 1200.0, (155.0 + s) / 1200.0);
    [
        ([1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0], 9.0 / 40.0),
        ([a, a, 1.0 - 2.0 * a], wa),
        ([a, 1.0 - 2.0 * a, a], wa),
        ([1.0 - 2.0 * a, a, a], wa),
        ([b, b, 1.0 - 2.0 * b], wb),
        ([b, 1.0 - 2.0 * b, b], wb),
        ([1.0 - 2.0 * b, b, b], wb),
    ]
}

/// Points `xi` and weights (reference measure included) of a rule exact for degree 5 on the
/// face's reference element: the Dunavant rule on the unit triangle (area ½), 3 × 3
/// Gauss–Legendre on `[−1, 1]²`. Returns the count used (7 or 9).
fn reference_rule(n_nodes: usize) -> ([([f64; 2], f64); 9], usize) {
    let mut out = [([0.0; 2], 0.0); 9];
    if n_nodes == 3 {
        for (k, (l, w)) in triangle_rule().into_iter().enumerate() {
            out[k] = ([l[1], l[2]], 0.5 * w);
        }
        (out, 7)
    } else {
        let g = (0.6f64).sqrt();
        let pts = [(-g, 5.0 / 9.0), (0.0, 8.0 / 9.0), (g, 5.0 / 9.0)];
        for (a, &(p, wp)) in pts.iter().enumerate() {
            for (b, &(q, wq)) in pts.iter().enumerate() {
                out[3 * a + b] = ([p, q], wp * wq);
            }
        }
        (out, 9)
    }
}

/// The dual coefficients `A` (rows j, columns l: `Φ_j = Σ_l A_jl N_l`) of a slave face with
/// nodes `x` (3 or 4), from its geometry (`A = D_e M_e⁻¹`, module doc), and its nodal areas
/// `∫_e N_j` (m²). `None` for a degenerate face (zero area). Unused rows and columns are 0.
pub fn dual_coefficients(x: &[Vector3<f64>]) -> Option<([[f64; 4]; 4], [f64; 4])> {
    let n = x.len();
    let (rule, count) = reference_rule(n);
    // unused entries: identity in M_e, zero in D_e, so the unused row of A is 0
    let mut me = Matrix4::<f64>::identity();
    for k in 0..n {
        me[(k, k)] = 0.0;
    }
    let mut de = [0.0; 4];
    for &(xi, w) in &rule[..count] {
        let (a, b) = tangents(x, xi);
        let da = a.cross(&b).norm() * w;
        let nn = shape(n, xi);
        for j in 0..n {
            de[j] += nn[j] * da;
            for l in 0..n {
                me[(j, l)] += nn[j] * nn[l] * da;
            }
        }
    }
    if de.iter().take(n).any(|&d| !(d > 0.0)) {
        return None;
    }
    let inv = me.try_inverse()?;
    let mut a = [[0.0; 4]; 4];
    for j in 0..n {
        for l in 0..n {
            a[j][l] = de[j] * inv[(j, l)];
        }
    }
    Some((a, de))
}

/// Dual shape functions at `xi` from the coefficients of [`dual_coefficients`].
#[inline]
pub fn dual_shape(a: &[[f64; 4]; 4], n_nodes: usize, xi: [f64; 2]) -> [f64; 4] {
    let nn = shape(n_nodes, xi);
    let mut phi = [0.0; 4];
    for j in 0..n_nodes {
        for l in 0..n_nodes {
            phi[j] += a[j][l] * nn[l];
        }
    }
    phi
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Biorthogonality ∫ Φ_j N_l = δ_jl ∫ N_j (Wohlmuth 2000, the defining property), checked with
    /// the same exact rule on a skewed quad and a triangle; and the known closed forms on the
    /// unit square (Φ_1 = 4N_1 − 2N_2 + N_3 − 2N_4) and triangle (Φ_j = 3N_j − N_k − N_l).
    /// Tolerance 1e-13 (round-off).
    #[test]
    fn dual_functions_are_biorthogonal() {
        let quad = [Vector3::new(0.0, 0.0, 0.0), Vector3::new(2.0, 0.1, 0.0), Vector3::new(2.3, 1.2, 0.0), Vector3::new(-0.2, 1.0, 0.0)];
        let tri = [Vector3::new(0.0, 0.0, 1.0), Vector3::new(1.0, 0.2, 1.0), Vector3::new(0.3, 0.9, 1.0)];
        for x in [&quad[..], &tri[..]] {
            let n = x.len();
            let (a, de) = dual_coefficients(x).unwrap();
            let (rule, count) = reference_rule(n);
            let mut m = [[0.0; 4]; 4];
            for &(xi, w) in &rule[..count] {
                let (t1, t2) = tangents(x, xi);
                let da = t1.cross(&t2).norm() * w;
                let phi = dual_shape(&a, n, xi);
                let nn = shape(n, xi);
                for j in 0..n {
                    for l in 0..n {
                        m[j][l] += phi[j] * nn[l] * da;
                    }
                }
            }
            for j in 0..n {
                for l in 0..n {
                    let want = if j == l { de[j] } else { 0.0 };
                    assert!((m[j][l] - want).abs() < 1e-13, "{n} nodes: ∫Φ_{j} N_{l} = {} ≠ {want}", m[j][l]);
                }
            }
        }
        let square = [Vector3::new(0.0, 0.0, 0.0), Vector3::new(1.0, 0.0, 0.0), Vector3::new(1.0, 1.0, 0.0), Vector3::new(0.0, 1.0, 0.0)];
        let (a, _) = dual_coefficients(&square).unwrap();
        for (got, want) in a[0].iter().zip([4.0, -2.0, 1.0, -2.0]) {
            assert!((got - want).abs() < 1e-12, "{:?}", a[0]);
        }
        let (a, _) = dual_coefficients(&tri).unwrap();
        for (got, want) in a[1].iter().zip([-1.0, 3.0, -1.0, 0.0]) {
            assert!((got - want).abs() < 1e-12, "{:?}", a[1]);
        }
    }
}
