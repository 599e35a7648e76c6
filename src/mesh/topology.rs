//! Face topology: which volume cell a boundary face belongs to, and its outward orientation.
//!
//! Faces are matched by their sorted node set. A face cell (tri3/quad4) of a physical
//! surface group "bounds" a block when exactly one volume cell of that block has a face
//! with the same nodes; the outward normal is that volume face's right-hand normal.

use super::{CellKind, Mesh};
use std::collections::HashMap;

/// Key of a face: its node indices, sorted (up to 4).
pub fn face_key(nodes: &[u32]) -> [u32; 4] {
    let mut k = [u32::MAX; 4];
    k[..nodes.len()].copy_from_slice(nodes);
    k[..nodes.len()].sort_unstable();
    k
}

/// A volume face: owning cell, local face number, nodes in outward order.
#[derive(Clone, Debug, PartialEq)]
pub struct VolumeFace {
    pub cell: usize,
    pub local: usize,
    pub nodes: Vec<usize>,
}

/// Map from face key to the faces of `volume_cells` having that node set.
pub fn volume_faces(mesh: &Mesh, volume_cells: &[usize]) -> HashMap<[u32; 4], Vec<VolumeFace>> {
    let mut map: HashMap<[u32; 4], Vec<VolumeFace>> = HashMap::new();
    for &c in volume_cells {
        let cell = &mesh.cells[c];
        for (lf, f) in cell.kind.faces().iter().enumerate() {
            let nodes: Vec<u32> = f.iter().map(|&i| cell.nodes()[i]).collect();
            map.entry(face_key(&nodes)).or_default().push(VolumeFace {
                cell: c,
                local: lf,
                nodes: nodes.iter().map(|&n| n as usize).collect(),
            });
        }
    }
    map
}

/// Boundary faces of a set of volume cells (faces owned by exactly one of them), outward ordered.
pub fn boundary_faces(mesh: &Mesh, volume_cells: &[usize]) -> Vec<VolumeFace> {
    let mut v: Vec<VolumeFace> =
        volume_faces(mesh, volume_cells).into_values().filter(|f| f.len() == 1).map(|mut f| f.pop().unwrap()).collect();
    v.sort_by_key(|f| (f.cell, f.local));
    v
}

/// Outward-oriented node list of face cell `face` w.r.t. the volume cells indexed in `faces`,
/// or `None` when no volume cell (or more than one) has that face.
pub fn orient_face(mesh: &Mesh, faces: &HashMap<[u32; 4], Vec<VolumeFace>>, face: usize) -> Option<VolumeFace> {
    let cell = &mesh.cells[face];
    debug_assert!(matches!(cell.kind, CellKind::Tri3 | CellKind::Quad4));
    match faces.get(&face_key(cell.nodes())) {
        Some(v) if v.len() == 1 => Some(v[0].clone()),
        _ => None,
    }
}

/// The blocks of a mesh: its volume cells (tet4, hex8) grouped into connected sets, two cells
/// being connected when they share a node (element-to-element connectivity). Blocks meshed
/// apart — the two sides of a joint, a dam's monoliths, a tied interface on non-conforming
/// meshes — share no node and are different blocks.
#[derive(Clone, Debug)]
pub struct Blocks {
    /// Per mesh cell: its block (the smallest index of its nodes' set); `u32::MAX` for a face cell.
    block_of_cell: Vec<u32>,
}

impl Blocks {
    /// Union–find over the nodes of every volume cell (near-linear in the node references).
    pub fn of(mesh: &Mesh) -> Blocks {
        let mut parent: Vec<u32> = (0..mesh.nodes.len() as u32).collect();
        fn root(parent: &mut [u32], mut a: u32) -> u32 {
            while parent[a as usize] != a {
                let p = parent[parent[a as usize] as usize];
                parent[a as usize] = p;
                a = p;
            }
            a
        }
        let is_volume = |k: CellKind| matches!(k, CellKind::Tet4 | CellKind::Hex8);
        for cell in mesh.cells.iter().filter(|c| is_volume(c.kind)) {
            let nodes = cell.nodes();
            let mut r0 = root(&mut parent, nodes[0]);
            for &n in &nodes[1..] {
                let r = root(&mut parent, n);
                if r != r0 {
                    // the smaller root wins: the block id is its smallest node
                    let (lo, hi) = if r < r0 { (r, r0) } else { (r0, r) };
                    parent[hi as usize] = lo;
                    r0 = lo;
                }
            }
        }
        let block_of_cell = mesh.cells.iter().map(|c| if is_volume(c.kind) { root(&mut parent, c.nodes()[0]) } else { u32::MAX }).collect();
        Blocks { block_of_cell }
    }

    /// The block of volume cell `cell` (`u32::MAX` for a face cell).
    pub fn block_of(&self, cell: usize) -> u32 {
        self.block_of_cell[cell]
    }

    /// Number of blocks.
    pub fn count(&self) -> usize {
        let mut ids: Vec<u32> = self.block_of_cell.iter().copied().filter(|&b| b != u32::MAX).collect();
        ids.sort_unstable();
        ids.dedup();
        ids.len()
    }
}
