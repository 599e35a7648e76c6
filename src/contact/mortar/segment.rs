//! The mortar integrals of one (slave face, master face) pair over their overlap (conventions
//! in the module doc of `contact::mortar`).

use super::clip::{clip_convex, signed_area, Polygon};
use super::dual::{dual_coefficients, dual_shape, shape, shape_derivatives, tangents, triangle_rule};
use crate::contact::query::tangent_frame;
use nalgebra::Vector3;

/// A slave face ready for the overlap integrals: its auxiliary plane, its nodes in the plane
/// and its dual coefficients.
#[derive(Clone, Copy, Debug)]
pub struct SlaveFace {
    pub x: [Vector3<f64>; 4],
    pub n_nodes: usize,
    /// Centre and unit outward normal: the auxiliary plane.
    pub centre: Vector3<f64>,
    pub normal: Vector3<f64>,
    axes: (Vector3<f64>, Vector3<f64>),
    /// The nodes projected on the plane (counter-clockwise about `normal`) [m].
    plane: [[f64; 2]; 4],
    /// Dual coefficients `A_jl` and nodal areas `∫ N_j` [m²].
    dual: [[f64; 4]; 4],
    pub nodal_area: [f64; 4],
    /// Area of the projected face [m²].
    pub plane_area: f64,
}

/// One (slave face, master face) pair's share of the mortar integrals [m²]: per slave face node
/// j, `d[j] = ∫ Φ_j` and per master face node k, `m[j][k] = ∫ Φ_j N_k`, over the overlap.
#[derive(Clone, Copy, Debug, Default)]
pub struct Overlap {
    pub d: [f64; 4],
    pub m: [[f64; 4]; 4],
    /// Area of the overlap in the plane [m²].
    pub area: f64,
}

/// Below this fraction of the slave face's area an overlap is taken as a touch (no integrals):
/// 1e-12, far above the round-off of the clipping (1e-16 relative) and far below any physical
/// overlap.
const TOUCH_FRACTION: f64 = 1e-12;

/// Each triangle of an overlap's fan is cut into this many squared congruent sub-triangles when
/// the slave or the master face is a quad that is not a parallelogram (its local coordinates are
/// then not polynomial in the plane, so the degree-5 rule is not exact): 6. The rule's error on a
/// smooth integrand falls as the sixth power of the triangle size, so by 6⁶ ≈ 5·10⁴. Measured on
/// the turned hex patch (quads blended from square to turned 15°): σ moved by 4e-6 of p (4.7301e-3
/// → 4.7341e-3; that error itself is the distorted hex8 elements', as turned tets pass to 1.2e-8).
/// Only such faces pay the 36 × cost, at their evaluations (kept between steps).
const SUBDIVISIONS: usize = 6;

/// The unit normal of a face at its centre (a quad's diagonals, a triangle's edges).
fn face_normal(x: &[Vector3<f64>]) -> Vector3<f64> {
    let m = if x.len() == 4 { (x[2] - x[0]).cross(&(x[3] - x[1])) } else { (x[1] - x[0]).cross(&(x[2] - x[0])) };
    m / m.norm()
}

impl SlaveFace {
    /// `None` for a degenerate face (zero area or non-finite positions).
    pub fn new(x: &[Vector3<f64>]) -> Option<SlaveFace> {
        let n = x.len();
        let centre = x.iter().sum::<Vector3<f64>>() / n as f64;
        let normal = face_normal(x);
        if !normal.iter().all(|v| v.is_finite()) {
            return None;
        }
        let axes = tangent_frame(&normal);
        let (dual, nodal_area) = dual_coefficients(x)?;
        let mut s = SlaveFace { x: [Vector3::zeros(); 4], n_nodes: n, centre, normal, axes, plane: [[0.0; 2]; 4], dual, nodal_area, plane_area: 0.0 };
        for k in 0..n {
            s.x[k] = x[k];
            s.plane[k] = s.to_plane(&x[k]);
        }
        s.plane_area = signed_area(&s.plane[..n]);
        (s.plane_area > 0.0).then_some(s)
    }

    #[inline]
    fn to_plane(&self, x: &Vector3<f64>) -> [f64; 2] {
        let d = x - self.centre;
        [d.dot(&self.axes.0), d.dot(&self.axes.1)]
    }
}

/// Local coordinates of the point `p` of the plane in the face whose projected nodes are `q`
/// (3 or 4): the linear map of a triangle inverted directly, a quad's bilinear map by Newton
/// from the centre (to 1e-14 in ξ, at most 30 iterations). `None` if that does not converge (a
/// face folded in the plane).
fn local_coordinates(q: &[[f64; 2]], p: [f64; 2]) -> Option<[f64; 2]> {
    let solve = |j: [[f64; 2]; 2], r: [f64; 2]| -> Option<[f64; 2]> {
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        let x = [(r[0] * j[1][1] - r[1] * j[0][1]) / det, (j[0][0] * r[1] - j[1][0] * r[0]) / det];
        (x[0].is_finite() && x[1].is_finite()).then_some(x)
    };
    // columns of the Jacobian: j[0] = [dx/dξ1, dx/dξ2], j[1] = [dy/dξ1, dy/dξ2]
    let jac = |xi: [f64; 2]| {
        let d = shape_derivatives(q.len(), xi);
        let mut j = [[0.0; 2]; 2];
        for (k, qk) in q.iter().enumerate() {
            for r in 0..2 {
                j[r][0] += qk[r] * d[k][0];
                j[r][1] += qk[r] * d[k][1];
            }
        }
        j
    };
    let map = |xi: [f64; 2]| {
        let nn = shape(q.len(), xi);
        let mut x = [0.0; 2];
        for (k, qk) in q.iter().enumerate() {
            x[0] += qk[0] * nn[k];
            x[1] += qk[1] * nn[k];
        }
        x
    };
    if q.len() == 3 {
        return solve(jac([0.0, 0.0]), [p[0] - q[0][0], p[1] - q[0][1]]);
    }
    let mut xi = [0.0; 2];
    for _ in 0..30 {
        let x = map(xi);
        let d = solve(jac(xi), [p[0] - x[0], p[1] - x[1]])?;
        xi = [xi[0] + d[0], xi[1] + d[1]];
        if d[0].abs().max(d[1].abs()) < 1e-14 {
            return Some(xi);
        }
    }
    None
}

/// The mortar integrals of slave face `s` and the master face with nodes `master` (3 or 4,
/// outward order) over their overlap in the slave face's auxiliary plane; `None` when they do
/// not overlap, when the master face does not face the slave (its normal not against the
/// slave's), or when a local coordinate solve fails.
pub fn overlap_integrals(s: &SlaveFace, master: &[Vector3<f64>]) -> Option<Overlap> {
    if face_normal(master).dot(&s.normal) >= 0.0 {
        return None;
    }
    let nm = master.len();
    let mut q = [[0.0; 2]; 4];
    for k in 0..nm {
        q[k] = s.to_plane(&master[k]);
    }
    let q = &q[..nm];
    // the master's outward order is clockwise seen along the slave normal: reversed to clip
    let mut ccw = [[0.0; 2]; 4];
    for k in 0..nm {
        ccw[k] = q[nm - 1 - k];
    }
    let poly = clip_convex(&Polygon::from_points(&s.plane[..s.n_nodes]), &ccw[..nm]);
    let area = if poly.len >= 3 { poly.signed_area() } else { 0.0 };
    if !(area > TOUCH_FRACTION * s.plane_area) {
        return None;
    }
    let mut out = Overlap { area, ..Default::default() };
    let rule = triangle_rule();
    // the rule on one triangle of the plane (corners a, b, c; area > 0)
    let mut integrate = |a: [f64; 2], b: [f64; 2], c: [f64; 2], tri_area: f64| -> Option<()> {
        for &(l, w) in &rule {
            let p = [l[0] * a[0] + l[1] * b[0] + l[2] * c[0], l[0] * a[1] + l[1] * b[1] + l[2] * c[1]];
            let xs = local_coordinates(&s.plane[..s.n_nodes], p)?;
            let xm = local_coordinates(q, p)?;
            // the slave face's area element over the plane's (1 on a flat face)
            let (t1, t2) = tangents(&s.x[..s.n_nodes], xs);
            let m = t1.cross(&t2);
            let ratio = m.norm() / m.dot(&s.normal).abs();
            let wt = w * tri_area * ratio;
            let phi = dual_shape(&s.dual, s.n_nodes, xs);
            let nn = shape(nm, xm);
            for j in 0..s.n_nodes {
                let pj = wt * phi[j];
                out.d[j] += pj;
                for kk in 0..nm {
                    out.m[j][kk] += pj * nn[kk];
                }
            }
        }
        Some(())
    };
    let n = if is_affine(&s.plane[..s.n_nodes]) && is_affine(q) { 1 } else { SUBDIVISIONS };
    let v = poly.points();
    for k in 1..v.len() - 1 {
        let (a, b, c) = (v[0], v[k], v[k + 1]);
        let tri_area = 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
        if !(tri_area > 0.0) {
            continue;
        }
        if n == 1 {
            integrate(a, b, c, tri_area)?;
            continue;
        }
        // n² congruent sub-triangles: the grid a + (i/n)(b − a) + (j/n)(c − a)
        let at = |i: usize, j: usize| {
            let (fi, fj) = (i as f64 / n as f64, j as f64 / n as f64);
            [a[0] + fi * (b[0] - a[0]) + fj * (c[0] - a[0]), a[1] + fi * (b[1] - a[1]) + fj * (c[1] - a[1])]
        };
        let sub = tri_area / (n * n) as f64;
        for i in 0..n {
            for j in 0..n - i {
                integrate(at(i, j), at(i + 1, j), at(i, j + 1), sub)?;
                if i + j + 2 <= n {
                    integrate(at(i + 1, j), at(i + 1, j + 1), at(i, j + 1), sub)?;
                }
            }
        }
    }
    Some(out)
}

/// Whether a face projected on the plane (3 or 4 nodes) maps its reference element affinely: a
/// triangle, or a parallelogram (x0 − x1 + x2 − x3 = 0 to 1e-12 of its size).
fn is_affine(q: &[[f64; 2]]) -> bool {
    if q.len() == 3 {
        return true;
    }
    let d = [q[0][0] - q[1][0] + q[2][0] - q[3][0], q[0][1] - q[1][1] + q[2][1] - q[3][1]];
    let size = (q[2][0] - q[0][0]).abs() + (q[2][1] - q[0][1]).abs() + (q[3][0] - q[1][0]).abs() + (q[3][1] - q[1][1]).abs();
    d[0].abs() + d[1].abs() <= 1e-12 * size
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad(x0: f64, y0: f64, h: f64, z: f64, up: bool) -> Vec<Vector3<f64>> {
        let p = [Vector3::new(x0, y0, z), Vector3::new(x0 + h, y0, z), Vector3::new(x0 + h, y0 + h, z), Vector3::new(x0, y0 + h, z)];
        if up { p.to_vec() } else { vec![p[0], p[3], p[2], p[1]] }
    }

    /// A slave quad (normal −z, the upper block's bottom) fully covered by four master quads
    /// (normal +z) shifted against it: Σ over the masters of D_j equals ∫ N_j (biorthogonality,
    /// module doc), Σ_k M_jk = D_j per overlap, and the total overlap area is the face's.
    /// Tolerance 1e-14 relative (round-off; the rule is exact for these parallelograms).
    #[test]
    fn overlaps_sum_to_the_slave_face() {
        let s = SlaveFace::new(&quad(0.0, 0.0, 1.0, 0.0, false)).unwrap();
        let mut d = [0.0; 4];
        let mut area = 0.0;
        for (x0, y0) in [(-0.3, -0.6), (0.7, -0.6), (-0.3, 0.4), (0.7, 0.4)] {
            let m = quad(x0, y0, 1.0, 0.0, true);
            let o = overlap_integrals(&s, &m).unwrap();
            for j in 0..4 {
                d[j] += o.d[j];
                let row: f64 = o.m[j].iter().sum();
                assert!((row - o.d[j]).abs() < 1e-14, "Σ_k M_jk = {row} ≠ D_j = {}", o.d[j]);
            }
            area += o.area;
        }
        assert!((area - 1.0).abs() < 1e-14);
        for j in 0..4 {
            assert!((d[j] - s.nodal_area[j]).abs() < 1e-14, "D_{j} = {} ≠ ∫N_j = {}", d[j], s.nodal_area[j]);
        }
        // a master face on the same side (normal along the slave's) is not an opposite face
        assert!(overlap_integrals(&s, &quad(0.0, 0.0, 1.0, 0.0, false)).is_none());
    }
}
