//! Element shape quality: the scaled Jacobian (docs/elements.md, "Mesh quality").
//!
//! At each corner of a volume element, the determinant of its three edge vectors (in the
//! element's right-handed order) divided by the product of their lengths; the element's value
//! is the smallest over its corners. Normalised so that a regular tetrahedron and a cube give 1
//! (a tet's value is multiplied by √2, as in Verdict and gmsh's `minSJ`); a flat element (a
//! sliver) gives about 0, an inverted one a negative value. It measures shape, not size: a small
//! well-shaped element keeps about 1, while its stable step is small because it is small.

use super::{CellKind, Mesh};

/// Below this scaled Jacobian the element that sets the stable step is called a sliver and the
/// run warns: 0.2. A tet from a split cube (Kuhn) has 0.58, a regular tet 1; gmsh's optimiser
/// (`Mesh.Optimize`, on by default) works on tets below a quality of 0.3 (`Mesh.OptimizeThreshold`),
/// and a sliver below 0.2 costs the explicit step roughly in proportion to its flatness.
pub const SLIVER_SCALED_JACOBIAN: f64 = 0.2;

/// Per corner of a hex8 (Gmsh node order), its three neighbours in right-handed order.
const HEX8_CORNERS: [[usize; 4]; 8] = [[0, 1, 3, 4], [1, 2, 0, 5], [2, 3, 1, 6], [3, 0, 2, 7], [4, 7, 5, 0], [5, 4, 6, 1], [6, 5, 7, 2], [7, 6, 4, 3]];

/// Per corner of a tet4, its three neighbours in right-handed order (Gmsh order: positive
/// volume for det[x1 − x0, x2 − x0, x3 − x0]).
const TET4_CORNERS: [[usize; 4]; 4] = [[0, 1, 2, 3], [1, 0, 3, 2], [2, 0, 1, 3], [3, 0, 2, 1]];

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn corner(x: &[[f64; 3]], c: &[usize; 4]) -> f64 {
    let (e1, e2, e3) = (sub(x[c[1]], x[c[0]]), sub(x[c[2]], x[c[0]]), sub(x[c[3]], x[c[0]]));
    let det = e1[0] * (e2[1] * e3[2] - e2[2] * e3[1]) - e1[1] * (e2[0] * e3[2] - e2[2] * e3[0]) + e1[2] * (e2[0] * e3[1] - e2[1] * e3[0]);
    let len = |e: [f64; 3]| (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt();
    let l = len(e1) * len(e2) * len(e3);
    if l > 0.0 { det / l } else { 0.0 }
}

/// The scaled Jacobian of a volume element of kind `kind` with corner positions `x` (Gmsh
/// order); `None` for a face kind.
pub fn scaled_jacobian(kind: CellKind, x: &[[f64; 3]]) -> Option<f64> {
    match kind {
        CellKind::Tet4 => Some(std::f64::consts::SQRT_2 * TET4_CORNERS.iter().map(|c| corner(x, c)).fold(f64::INFINITY, f64::min)),
        CellKind::Hex8 => Some(HEX8_CORNERS.iter().map(|c| corner(x, c)).fold(f64::INFINITY, f64::min)),
        CellKind::Tri3 | CellKind::Quad4 => None,
    }
}

/// The scaled Jacobian of mesh cell `cell` (`None` for a face cell).
pub fn cell_scaled_jacobian(mesh: &Mesh, cell: usize) -> Option<f64> {
    let c = &mesh.cells[cell];
    let x: Vec<[f64; 3]> = c.nodes().iter().map(|&n| mesh.nodes[n as usize]).collect();
    scaled_jacobian(c.kind, &x)
}

#[cfg(test)]
mod tests {
    use super::*;

    const CUBE: [[f64; 3]; 8] = [[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.], [0., 0., 1.], [1., 0., 1.], [1., 1., 1.], [0., 1., 1.]];

    #[test]
    fn regular_tet_and_cube_give_one_kuhn_tet_and_sliver_less() {
        let s = 3f64.sqrt();
        let regular = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, s / 2.0, 0.0], [0.5, s / 6.0, (2.0f64 / 3.0).sqrt()]];
        assert!((scaled_jacobian(CellKind::Tet4, &regular).unwrap() - 1.0).abs() < 1e-12);
        assert!((scaled_jacobian(CellKind::Hex8, &CUBE).unwrap() - 1.0).abs() < 1e-12);
        // a stretched box is still a perfect shape for this measure (its corners are right angles)
        let boxx: Vec<[f64; 3]> = CUBE.iter().map(|p| [10.0 * p[0], p[1], 0.1 * p[2]]).collect();
        assert!((scaled_jacobian(CellKind::Hex8, &boxx).unwrap() - 1.0).abs() < 1e-12);
        // Kuhn tet of the unit cube: √2 / √6 = 1/√3 at its worst corners
        let kuhn = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 1.0, 1.0]];
        assert!((scaled_jacobian(CellKind::Tet4, &kuhn).unwrap() - 1.0 / 3f64.sqrt()).abs() < 1e-12);
        // a sliver: the four corners of a square lifted alternately by ±h
        let h = 0.01;
        let sliver = [[0.0, 0.0, -h], [1.0, 0.0, h], [1.0, 1.0, -h], [0.0, 1.0, h]];
        let q = scaled_jacobian(CellKind::Tet4, &sliver).unwrap();
        assert!(q.abs() < 0.05 && q.abs() < SLIVER_SCALED_JACOBIAN, "{q}");
        // inverted: swapping two nodes flips the sign
        let inv = [regular[1], regular[0], regular[2], regular[3]];
        assert!((scaled_jacobian(CellKind::Tet4, &inv).unwrap() + 1.0).abs() < 1e-12);
    }
}
