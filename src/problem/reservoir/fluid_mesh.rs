//! The meshed water of the incompressible reservoir: its pressure unknowns and its Laplacian.
//!
//! Potential flow of incompressible water: ∇²p = 0 in the water, p = 0 on the free surface and
//! on the far end (`reservoir.fluid.far_end`, stated choice), ∂p/∂n = 0 on the bottom and banks
//! (every face not named: the natural condition), ∂p/∂n = ρw a·n_dam on the wet face (module
//! `incompressible`). Weak form: H p = q with H_ij = ∫ ∇N_i·∇N_j dV [m] on the unknowns (the
//! water's nodes off the p = 0 faces), tet4 exact (one point), hex8 by 2×2×2 Gauss (exact for
//! a parallelepiped).

use super::{wet_faces, WetFace};
use crate::error::{Error, ModelError};
use crate::linalg::{from_columns, Csc, NONE};
use crate::mesh::{CellKind, Mesh};
use crate::scene::reservoir::FluidScene;
use nalgebra::{Matrix3, Vector3};

/// The water's pressure unknowns and operator (built once).
#[derive(Clone, Debug)]
pub struct FluidMesh {
    /// The mesh node of each pressure unknown.
    pub nodes: Vec<usize>,
    /// Per mesh node: its pressure unknown, or `NONE` (not in the water, or on a p = 0 face).
    pub unknown: Vec<usize>,
    /// The water's faces against the dam, oriented out of the water.
    pub wet: Vec<WetFace>,
    /// H_ij = ∫ ∇N_i·∇N_j dV on the unknowns [m], both triangles.
    pub laplacian: Csc,
    /// Water elements.
    pub cells: usize,
    /// Water nodes held at p = 0.
    pub zero_pressure_nodes: usize,
}

/// The incompressible water of `fluid` on `mesh`: p = 0 on the free surface and the far end.
/// Errors name the group and element and say what to fix.
pub fn fluid_mesh(mesh: &Mesh, fluid: &FluidScene) -> Result<FluidMesh, Error> {
    let held: Vec<&String> = fluid.free_surface.iter().chain(&fluid.far_end).collect();
    let water = fluid_mesh_held(mesh, fluid, &held)?;
    if water.zero_pressure_nodes == 0 {
        return Err(ModelError::Invalid(format!("reservoir.fluid.free_surface: the groups {:?} have no nodes; the pressure needs p = 0 somewhere", fluid.free_surface)).into());
    }
    Ok(water)
}

/// The water of `fluid` on `mesh` with p = 0 on the face groups `held` only (the acoustic water
/// holds its free surface and radiates at its far end; it needs no p = 0 face).
pub fn fluid_mesh_held(mesh: &Mesh, fluid: &FluidScene, held: &[&String]) -> Result<FluidMesh, Error> {
    let g = mesh.group_of_dim(&fluid.volume, 3)?;
    if g.cells.is_empty() {
        return Err(ModelError::Invalid(format!("reservoir.fluid.volume \"{}\" has no elements", fluid.volume)).into());
    }
    mesh.check_orientation(g)?;
    let cells = g.cells.clone();
    let mut in_water = vec![false; mesh.nodes.len()];
    for &c in &cells {
        for &v in mesh.cells[c].nodes() {
            in_water[v as usize] = true;
        }
    }
    let mut zero = vec![false; mesh.nodes.len()];
    for &name in held {
        let nodes = mesh.group_nodes(name)?;
        if let Some(&v) = nodes.iter().find(|&&v| !in_water[v]) {
            return Err(ModelError::Invalid(format!(
                "reservoir.fluid: face group \"{name}\" has node {} outside the water volume \"{}\": the free surface and the far end must be faces of the water",
                mesh.node_tags[v], fluid.volume
            ))
            .into());
        }
        nodes.into_iter().for_each(|v| zero[v] = true);
    }
    let mut wet = Vec::new();
    for name in &fluid.wet {
        wet.extend(wet_faces(mesh, name, &cells)?);
    }
    let mut unknown = vec![NONE; mesh.nodes.len()];
    let mut nodes = Vec::new();
    for v in 0..mesh.nodes.len() {
        if in_water[v] && !zero[v] {
            unknown[v] = nodes.len();
            nodes.push(v);
        }
    }
    let zero_pressure_nodes = zero.iter().filter(|&&z| z).count();
    let mut cols: Vec<Vec<(usize, f64)>> = vec![Vec::new(); nodes.len()];
    for &c in &cells {
        let cell = &mesh.cells[c];
        let x: Vec<Vector3<f64>> = cell.nodes().iter().map(|&v| mesh.x(v as usize)).collect();
        let ke = element_laplacian(cell.kind, &x).ok_or_else(|| {
            ModelError::Invalid(format!("reservoir.fluid.volume \"{}\": element {} is degenerate (zero or negative volume at a Gauss point)", fluid.volume, cell.tag))
        })?;
        let k = x.len();
        for a in 0..k {
            let ia = unknown[cell.node(a)];
            if ia == NONE {
                continue;
            }
            for b in 0..k {
                let ib = unknown[cell.node(b)];
                if ib != NONE {
                    cols[ib].push((ia, ke[a * k + b]));
                }
            }
        }
    }
    let laplacian = from_columns(nodes.len(), cols);
    Ok(FluidMesh { nodes, unknown, wet, laplacian, cells: cells.len(), zero_pressure_nodes })
}

/// The row-sum lumped volumes ∫ N_a dV [m³] of a tet4 (V/4 each) or hex8 (2×2×2 Gauss);
/// `None` if degenerate.
pub fn element_lumped_volumes(kind: CellKind, x: &[Vector3<f64>]) -> Option<Vec<f64>> {
    match kind {
        CellKind::Tet4 => {
            let g = crate::model::tet4::tet_geometry(&[x[0], x[1], x[2], x[3]])?;
            Some(vec![0.25 * g.vol; 4])
        }
        CellKind::Hex8 => {
            let xs: [Vector3<f64>; 8] = std::array::from_fn(|a| x[a]);
            let gp = 1.0 / 3f64.sqrt();
            let r = crate::mesh::cell::HEX8_REF;
            let mut v = vec![0.0; 8];
            for s in [[-gp, -gp, -gp], [gp, -gp, -gp], [gp, gp, -gp], [-gp, gp, -gp], [-gp, -gp, gp], [gp, -gp, gp], [gp, gp, gp], [-gp, gp, gp]] {
                let det = crate::model::hex8::jacobian(&xs, &crate::model::hex8::dshape(s)).determinant();
                if !(det > 0.0) {
                    return None;
                }
                for a in 0..8 {
                    v[a] += det * 0.125 * (1.0 + s[0] * r[a][0]) * (1.0 + s[1] * r[a][1]) * (1.0 + s[2] * r[a][2]);
                }
            }
            Some(v)
        }
        _ => None,
    }
}

/// The element matrix ∫ ∇N_a·∇N_b dV (row-major k×k) of a tet4 or hex8; `None` if degenerate.
pub fn element_laplacian(kind: CellKind, x: &[Vector3<f64>]) -> Option<Vec<f64>> {
    match kind {
        CellKind::Tet4 => {
            let g = crate::model::tet4::tet_geometry(&[x[0], x[1], x[2], x[3]])?;
            let grad = crate::model::tet4::gradients(&g.grad);
            let mut k = vec![0.0; 16];
            for a in 0..4 {
                for b in 0..4 {
                    k[4 * a + b] = g.vol * (0..3).map(|i| grad[a][i] * grad[b][i]).sum::<f64>();
                }
            }
            Some(k)
        }
        CellKind::Hex8 => {
            let xs: [Vector3<f64>; 8] = std::array::from_fn(|a| x[a]);
            let gp = 1.0 / 3f64.sqrt();
            let mut k = vec![0.0; 64];
            for s in [[-gp, -gp, -gp], [gp, -gp, -gp], [gp, gp, -gp], [-gp, gp, -gp], [-gp, -gp, gp], [gp, -gp, gp], [gp, gp, gp], [-gp, gp, gp]] {
                let d = crate::model::hex8::dshape(s);
                let j: Matrix3<f64> = crate::model::hex8::jacobian(&xs, &d);
                let det = j.determinant();
                if !(det > 0.0) {
                    return None;
                }
                let jit = j.try_inverse()?.transpose();
                let g: Vec<Vector3<f64>> = d.iter().map(|r| jit * Vector3::new(r[0], r[1], r[2])).collect();
                for a in 0..8 {
                    for b in 0..8 {
                        k[8 * a + b] += det * g[a].dot(&g[b]);
                    }
                }
            }
            Some(k)
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn element_laplacians_annihilate_constants_and_integrate_a_linear_field() {
        // Reference: K·1 = 0 (a constant has no gradient) and, for p = x, pᵀ K p = ∫|∇x|² dV =
        // V (exact for tet4 and for a hex8 parallelepiped); tolerance 1e-12 relative.
        let hex: Vec<Vector3<f64>> = crate::mesh::cell::HEX8_REF.iter().map(|r| Vector3::new(1.0 + r[0], 0.5 * (1.0 + r[1]) + 0.2 * r[2], 2.0 * (1.0 + r[2]))).collect();
        let tet = vec![Vector3::new(0.0, 0.0, 0.0), Vector3::new(2.0, 0.0, 0.0), Vector3::new(0.0, 3.0, 0.0), Vector3::new(0.0, 0.0, 1.5)];
        for (kind, x, vol) in [(CellKind::Hex8, hex, 2.0 * 1.0 * 4.0), (CellKind::Tet4, tet, 1.5)] {
            let k = element_laplacian(kind, &x).unwrap();
            let n = x.len();
            for a in 0..n {
                let row: f64 = (0..n).map(|b| k[a * n + b]).sum();
                assert!(row.abs() < 1e-12 * vol, "{kind:?} row {a}: {row}");
            }
            let e: f64 = (0..n).flat_map(|a| (0..n).map(move |b| (a, b))).map(|(a, b)| x[a][0] * k[a * n + b] * x[b][0]).sum();
            assert!((e - vol).abs() < 1e-12 * vol, "{kind:?}: {e} vs {vol}");
        }
    }
}
