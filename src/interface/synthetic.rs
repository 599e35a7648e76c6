//! A generated flat joint for scaling checks and benches (no Gmsh needed).

use crate::mesh::{Cell, CellKind, Group, Mesh};
use std::path::PathBuf;

/// Two stacked unit-square blocks of hex8 (one element thick) meeting at z = 0:
/// `block:master` (z ∈ [−0.1, 0], `n_master`² hexes) and `block:slave` (z ∈ [0, 0.1], `n_slave`² hexes),
/// with the quad4 faces at z = 0 of each block in `joint:master` and `joint:slave`.
/// Face cells are written counter-clockwise seen from +z, so the master's are outward and the
/// slave's inward (the tagger must reorient them). Node and element tags are index + 1.
pub fn flat_joint_mesh(n_master: usize, n_slave: usize) -> Mesh {
    let mut mesh = Mesh { source: PathBuf::from("<flat_joint_mesh>"), nodes: vec![], node_tags: vec![], cells: vec![], groups: vec![] };
    push_block(&mut mesh, "master", n_master, -0.1, 0.0, 1);
    push_block(&mut mesh, "slave", n_slave, 0.0, 0.1, 0);
    mesh.node_tags = (1..=mesh.nodes.len() as u64).collect();
    mesh
}

/// One block of n×n×1 hexes on [0,1]² × [z0, z1]; the faces on layer `joint_layer` (0: z0, 1: z1)
/// go to group `joint:<name>`.
fn push_block(mesh: &mut Mesh, name: &str, n: usize, z0: f64, z1: f64, joint_layer: usize) {
    let base = mesh.nodes.len();
    let h = 1.0 / n as f64;
    for k in 0..2 {
        let z = if k == 0 { z0 } else { z1 };
        for j in 0..=n {
            for i in 0..=n {
                mesh.nodes.push([i as f64 * h, j as f64 * h, z]);
            }
        }
    }
    let id = |i: usize, j: usize, k: usize| base + k * (n + 1) * (n + 1) + j * (n + 1) + i;
    let mut vols = Vec::with_capacity(n * n);
    let mut faces = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            let c = mesh.cells.len();
            let tag = c as u64 + 1;
            let hex = [id(i, j, 0), id(i + 1, j, 0), id(i + 1, j + 1, 0), id(i, j + 1, 0), id(i, j, 1), id(i + 1, j, 1), id(i + 1, j + 1, 1), id(i, j + 1, 1)];
            mesh.cells.push(Cell::new(CellKind::Hex8, tag, &hex));
            vols.push(c);
        }
    }
    for j in 0..n {
        for i in 0..n {
            let c = mesh.cells.len();
            let k = joint_layer;
            let quad = [id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k)];
            mesh.cells.push(Cell::new(CellKind::Quad4, c as u64 + 1, &quad));
            faces.push(c);
        }
    }
    let tag = mesh.groups.len() as i32 + 1;
    mesh.groups.push(Group { name: format!("block:{name}"), dim: 3, tag, cells: vols });
    mesh.groups.push(Group { name: format!("joint:{name}"), dim: 2, tag: tag + 1, cells: faces });
}
