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
