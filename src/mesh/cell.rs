//! Cell kinds and their node order, drawn once.
//!
//! Node order is Gmsh's (identical to VTK's for these four kinds):
//!
//! ```text
//! tet4  : 0 (0,0,0)  1 (1,0,0)  2 (0,1,0)  3 (0,0,1)            (reference coordinates)
//! hex8  : 0 (-1,-1,-1) 1 (1,-1,-1) 2 (1,1,-1) 3 (-1,1,-1)
//!         4 (-1,-1, 1) 5 (1,-1, 1) 6 (1,1, 1) 7 (-1,1, 1)
//! tri3  : 0 (0,0) 1 (1,0) 2 (0,1)        quad4 : 0 (-1,-1) 1 (1,-1) 2 (1,1) 3 (-1,1)
//! ```
//!
//! A well-formed volume cell has a positive Jacobian everywhere. [`CellKind::faces`]
//! lists each volume's faces with their nodes ordered so that the right-hand
//! normal points **out** of the cell.

/// The element kinds jointquake reads.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, serde::Serialize)]
pub enum CellKind {
    Tet4,
    Hex8,
    Tri3,
    Quad4,
}

/// Reference coordinates of the hex8 corners (Gmsh order).
pub const HEX8_REF: [[f64; 3]; 8] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
];

/// Reference coordinates of the quad4 corners (Gmsh order).
pub const QUAD4_REF: [[f64; 2]; 4] = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];

const TET4_FACES: [&[usize]; 4] = [&[0, 2, 1], &[0, 1, 3], &[0, 3, 2], &[1, 2, 3]];
const HEX8_FACES: [&[usize]; 6] = [
    &[0, 3, 2, 1],
    &[4, 5, 6, 7],
    &[0, 1, 5, 4],
    &[1, 2, 6, 5],
    &[2, 3, 7, 6],
    &[3, 0, 4, 7],
];

impl CellKind {
    /// Number of nodes of the cell.
    pub const fn n_nodes(self) -> usize {
        match self {
            CellKind::Tet4 => 4,
            CellKind::Hex8 => 8,
            CellKind::Tri3 => 3,
            CellKind::Quad4 => 4,
        }
    }

    /// Topological dimension (3 for volumes, 2 for faces).
    pub const fn dim(self) -> usize {
        match self {
            CellKind::Tet4 | CellKind::Hex8 => 3,
            CellKind::Tri3 | CellKind::Quad4 => 2,
        }
    }

    /// Local faces of a volume cell, nodes ordered with the outward right-hand normal.
    /// Empty for face cells.
    pub fn faces(self) -> &'static [&'static [usize]] {
        match self {
            CellKind::Tet4 => &TET4_FACES,
            CellKind::Hex8 => &HEX8_FACES,
            _ => &[],
        }
    }

    /// VTK cell type number.
    pub const fn vtk_type(self) -> u8 {
        match self {
            CellKind::Tet4 => 10,
            CellKind::Hex8 => 12,
            CellKind::Tri3 => 5,
            CellKind::Quad4 => 9,
        }
    }

    pub const fn name(self) -> &'static str {
        match self {
            CellKind::Tet4 => "tet4",
            CellKind::Hex8 => "hex8",
            CellKind::Tri3 => "tri3",
            CellKind::Quad4 => "quad4",
        }
    }
}

/// One cell: its kind, its Gmsh element tag and its nodes (indices into `Mesh::nodes`).
#[derive(Clone, Debug, PartialEq)]
pub struct Cell {
    pub kind: CellKind,
    /// Gmsh element tag, quoted in error messages.
    pub tag: u64,
    nodes: [u32; 8],
}

impl Cell {
    /// Build a cell; `nodes.len()` must equal `kind.n_nodes()`.
    pub fn new(kind: CellKind, tag: u64, nodes: &[usize]) -> Self {
        assert_eq!(nodes.len(), kind.n_nodes(), "cell node count");
        let mut n = [u32::MAX; 8];
        for (a, &b) in n.iter_mut().zip(nodes) {
            *a = u32::try_from(b).expect("node index fits in u32");
        }
        Cell { kind, tag, nodes: n }
    }

    /// Node indices, in Gmsh order.
    pub fn nodes(&self) -> &[u32] {
        &self.nodes[..self.kind.n_nodes()]
    }

    /// Node index `i` as usize.
    pub fn node(&self, i: usize) -> usize {
        self.nodes[i] as usize
    }
}
