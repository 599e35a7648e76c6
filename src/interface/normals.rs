//! Face normals, slave-node normals and tributary areas (design.md §3 item 1).
//!
//! - Face normal: tri3 (x1 − x0) × (x2 − x0); quad4 at its centre, (x2 − x0) × (x3 − x1) (the
//!   cross product of the diagonals, which is 4 × x_ξ × x_η at ξ = η = 0). Outward because face
//!   nodes are in outward order ([`super::Surface`]).
//! - Node normal: the normalised (unweighted) average of the outward unit normals of the faces
//!   around the node.
//! - Tributary area of node I: ∫ N_I dA over its faces. Tri3: area/3 per node (exact). Quad4:
//!   2×2 Gauss on the bilinear map, exact for planar quads (N_I·detJ is then of degree ≤ 2 per
//!   direction) and a consistent approximation for warped ones. The areas of a surface sum to its
//!   area as computed by [`face_area`]. One kernel computes these nodal weights of a face,
//!   [`face_nodal_weights_into`], for every caller (the tagger here, the scene's tractions, the
//!   reservoir's added mass).

use super::{Surface, invalid};
use crate::error::InterfaceError;
use crate::mesh::CellKind;
use nalgebra::Vector3;

/// A point or vector of the mesh's `[f64; 3]` storage as a nalgebra vector.
#[inline]
pub(crate) fn vec3(a: [f64; 3]) -> Vector3<f64> {
    Vector3::from(a)
}

/// Unnormalised outward normal of a face with nodes `x` (outward order; 3 or 4 points used).
#[inline]
pub(crate) fn face_normal_raw(kind: CellKind, x: &[[f64; 3]]) -> Vector3<f64> {
    let p = |i: usize| vec3(x[i]);
    match kind {
        CellKind::Quad4 => (p(2) - p(0)).cross(&(p(3) - p(1))),
        _ => (p(1) - p(0)).cross(&(p(2) - p(0))),
    }
}

/// Outward unit normal of a face (quad4: at its centre). Zero vector for a degenerate face.
pub fn face_unit_normal(kind: CellKind, x: &[[f64; 3]]) -> [f64; 3] {
    let n = face_normal_raw(kind, x);
    let l = n.norm();
    if l > 0.0 { (n * (1.0 / l)).into() } else { [0.0; 3] }
}

/// 2×2 Gauss points ±1/√3 (weights 1).
const G: f64 = 0.577_350_269_189_625_8;
const QREF: [[f64; 2]; 4] = crate::mesh::cell::QUAD4_REF;

/// The nodal weights of one face (see [`face_nodal_weights_into`]); entries past the face's
/// nodes are 0.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FaceWeights {
    /// ∫ N_I dA of each node I [m²] (its tributary area on this face).
    pub area: [f64; 4],
    /// ∫ N_I n dA of each node I [m²]: the area-weighted outward normal (n the unit normal of the
    /// face where it is integrated; equal to the face normal × `area` on a planar face).
    pub vector: [[f64; 3]; 4],
}

/// The one face-integration kernel (the tagger's tributary areas, the scene's tractions in
/// `dynamics::loads`, the reservoir's added mass in `problem::reservoir`): the nodal weights
/// ∫ N_I dA and ∫ N_I n dA of each node I of a face with points `x` (Gmsh node order, outward;
/// 3 points of a tri3, 4 of a quad4) into `w`.
///
/// - tri3: exact, a third of the area each (N_I integrates to A/3), along the face normal.
/// - quad4: 2×2 Gauss on the bilinear map, exact for planar quads (N_I · det J has degree ≤ 2
///   per direction) and a consistent approximation for warped ones; the weights sum to the
///   face's area as [`face_area`] computes it.
/// - any other kind (not a face): all 0.
pub fn face_nodal_weights_into(kind: CellKind, x: &[[f64; 3]], w: &mut FaceWeights) {
    *w = FaceWeights::default();
    match kind {
        CellKind::Quad4 => {
            // (the operations in this order give the scene's traction loads of before the
            // kernel bit for bit: the contact bench's state hash, whose load is a traction on
            // quads, is kept; the tagger's areas moved by at most 6e-16 relative)
            for xi in [-G, G] {
                for eta in [-G, G] {
                    let mut dxi = Vector3::zeros();
                    let mut deta = Vector3::zeros();
                    for (i, r) in QREF.iter().enumerate() {
                        dxi += vec3(x[i]) * 0.25 * r[0] * (1.0 + eta * r[1]);
                        deta += vec3(x[i]) * 0.25 * r[1] * (1.0 + xi * r[0]);
                    }
                    let j = dxi.cross(&deta);
                    let det = j.norm();
                    for (i, r) in QREF.iter().enumerate() {
                        w.area[i] += det * 0.25 * (1.0 + xi * r[0]) * (1.0 + eta * r[1]);
                        let v = j * (0.25 * (1.0 + xi * r[0]) * (1.0 + eta * r[1]));
                        for c in 0..3 {
                            w.vector[i][c] += v[c];
                        }
                    }
                }
            }
        }
        CellKind::Tri3 => {
            let j = face_normal_raw(kind, x);
            let third = (0.5 * j.norm()) / 3.0;
            let v = (j * 0.5) / 3.0;
            for i in 0..3 {
                w.area[i] = third;
                w.vector[i] = [v[0], v[1], v[2]];
            }
        }
        CellKind::Tet4 | CellKind::Hex8 => {}
    }
}

/// Area of a face [m²]: tri3 exact, quad4 by 2×2 Gauss (exact when planar).
pub fn face_area(kind: CellKind, x: &[[f64; 3]]) -> f64 {
    match kind {
        CellKind::Quad4 => {
            let mut w = FaceWeights::default();
            face_nodal_weights_into(kind, x, &mut w);
            w.area.iter().sum()
        }
        _ => 0.5 * face_normal_raw(kind, x).norm(),
    }
}

/// Outward unit normal at every node of `surface` (local node order) into `out`.
///
/// Error (naming the joint, the group and the node) when the face normals around a node cancel,
/// which happens only on a folded surface.
pub fn slave_normals_into(joint: &str, surface: &Surface, out: &mut [[f64; 3]]) -> Result<(), InterfaceError> {
    assert_eq!(out.len(), surface.nodes.len());
    let face_normals: Vec<Vector3<f64>> = (0..surface.faces.len())
        .map(|f| {
            let (x, n) = surface.face_points(f);
            vec3(face_unit_normal(surface.faces[f].kind, &x[..n]))
        })
        .collect();
    for (l, o) in out.iter_mut().enumerate() {
        let s = surface.faces_of_node(l).iter().fold(Vector3::zeros(), |s, &f| s + face_normals[f as usize]);
        let len = s.norm();
        if !(len > 1e-12) {
            let p = surface.points[l];
            return Err(invalid(
                joint,
                format!(
                    "the faces of group \"{}\" around mesh node index {} at ({:.4}, {:.4}, {:.4}) have cancelling normals (a folded surface); \
                     a joint side must be a surface with a consistent outward side",
                    surface.group, surface.nodes[l], p[0], p[1], p[2]
                ),
            ));
        }
        *o = (s * (1.0 / len)).into();
    }
    Ok(())
}

/// Tributary area [m²] of every node of `surface` (local node order) into `out`.
pub fn tributary_areas_into(surface: &Surface, out: &mut [f64]) {
    assert_eq!(out.len(), surface.nodes.len());
    out.iter_mut().for_each(|a| *a = 0.0);
    let mut w = FaceWeights::default();
    for (f, face) in surface.faces.iter().enumerate() {
        let (x, n) = surface.face_points(f);
        face_nodal_weights_into(face.kind, &x[..n], &mut w);
        for (k, &l) in face.local_nodes().iter().enumerate().take(n) {
            out[l as usize] += w.area[k];
        }
    }
}

/// Area vector of every node of `surface` (local node order) into `out`: Σ over its faces of
/// n_f ∫ N_I dA (n_f the face's outward unit normal, ∫ N_I dA as in [`tributary_areas_into`];
/// exact for planar faces). A uniform stress σ loads node I with σ · (its area vector), whatever
/// the shape of the surface: the exact nodal force of a patch test on a curved joint.
pub fn tributary_vectors_into(surface: &Surface, out: &mut [[f64; 3]]) {
    assert_eq!(out.len(), surface.nodes.len());
    out.iter_mut().for_each(|a| *a = [0.0; 3]);
    let mut w = FaceWeights::default();
    for (f, face) in surface.faces.iter().enumerate() {
        let (x, n) = surface.face_points(f);
        face_nodal_weights_into(face.kind, &x[..n], &mut w);
        let nf = face_unit_normal(face.kind, &x[..n]);
        for (k, &l) in face.local_nodes().iter().enumerate().take(n) {
            for c in 0..3 {
                out[l as usize][c] += nf[c] * w.area[k];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reference: 3×3 Gauss-Legendre (exact for degree ≤ 5 per direction) of N_I·|x_ξ × x_η| on a
    /// planar trapezoid, where the integrand has degree ≤ 2 per direction. Tolerance 1e-14 relative.
    #[test]
    fn quad_nodal_weights_match_3x3_gauss_on_planar_trapezoid() {
        let x = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.5, 1.0, 0.0], [0.3, 1.2, 0.0]];
        let mut w = FaceWeights::default();
        face_nodal_weights_into(CellKind::Quad4, &x, &mut w);
        let t = w.area;
        let g3 = [(-(0.6f64).sqrt(), 5.0 / 9.0), (0.0, 8.0 / 9.0), ((0.6f64).sqrt(), 5.0 / 9.0)];
        let mut r = [0.0; 4];
        for &(xi, wx) in &g3 {
            for &(eta, we) in &g3 {
                let mut dxi = Vector3::zeros();
                let mut deta = Vector3::zeros();
                for (i, q) in QREF.iter().enumerate() {
                    dxi += vec3(x[i]) * (0.25 * q[0] * (1.0 + eta * q[1]));
                    deta += vec3(x[i]) * (0.25 * q[1] * (1.0 + xi * q[0]));
                }
                let det = dxi.cross(&deta).norm();
                for (i, q) in QREF.iter().enumerate() {
                    r[i] += wx * we * 0.25 * (1.0 + xi * q[0]) * (1.0 + eta * q[1]) * det;
                }
            }
        }
        // shoelace area of the trapezoid
        let shoelace = 0.5 * (0..4).map(|i| x[i][0] * x[(i + 1) % 4][1] - x[(i + 1) % 4][0] * x[i][1]).sum::<f64>();
        for i in 0..4 {
            assert!((t[i] - r[i]).abs() < 1e-14 * shoelace, "node {i}: {} vs {}", t[i], r[i]);
        }
        assert!((t.iter().sum::<f64>() - shoelace).abs() < 1e-14 * shoelace);
        // not the naive quarter: the trapezoid's nodes carry different shares
        assert!((t[0] - t[2]).abs() > 1e-3);
    }

    /// The quad normal at the centre (cross product of the diagonals) of a warped quad equals
    /// x_ξ × x_η at ξ = η = 0 up to the factor 4 (definition), checked on a hyperbolic paraboloid patch.
    #[test]
    fn quad_normal_is_centre_normal() {
        let x = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.1], [1.0, 1.0, 0.0], [0.0, 1.0, 0.1]];
        let n = face_unit_normal(CellKind::Quad4, &x);
        let mut dxi = Vector3::zeros();
        let mut deta = Vector3::zeros();
        for (i, q) in QREF.iter().enumerate() {
            dxi += vec3(x[i]) * (0.25 * q[0]);
            deta += vec3(x[i]) * (0.25 * q[1]);
        }
        let c = dxi.cross(&deta).normalize();
        assert!((vec3(n) - c).norm() < 1e-15);
    }
}
