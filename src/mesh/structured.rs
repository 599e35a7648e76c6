//! Structured box meshes built in memory (tests and benchmarks need no gmsh).
//!
//! A box [x0, x0+lx] × [y0, y0+ly] × [z0, z0+lz] split into nx × ny × nz hexahedra, or each hexahedron
//! split into 6 tetrahedra along its main diagonal (Kuhn split: conforming across the grid), or
//! both (`mixed`): the cells of the first ⌈nx/2⌉ columns along x are hexahedra, the others tets.
//! In a mixed box a hex face meets the two triangles of the Kuhn split on the same four nodes (no
//! pyramids: the element library has tet4 and hex8 only), so the displacement is continuous at
//! the nodes and for every linear field (what a patch test exercises), not for general fields.
//! Groups: `block:<name>` (volume) and the six boundary faces `<name>:x0`, `<name>:x1`,
//! `<name>:y0`, `<name>:y1`, `<name>:z0`, `<name>:z1` (quad4 or tri3, outward orientation).

use super::{topology, Cell, CellKind, Group, Mesh};
use std::path::PathBuf;

/// Parameters of a structured box.
#[derive(Clone, Debug)]
pub struct BoxSpec {
    pub name: String,
    pub origin: [f64; 3],
    pub size: [f64; 3],
    pub divisions: [usize; 3],
    pub tets: bool,
    /// Hexes in the first ⌈nx/2⌉ columns along x, Kuhn tets in the rest (module doc).
    pub mixed: bool,
}

impl BoxSpec {
    pub fn new(name: &str, size: [f64; 3], divisions: [usize; 3]) -> BoxSpec {
        BoxSpec { name: name.into(), origin: [0.0; 3], size, divisions, tets: false, mixed: false }
    }
    pub fn tets(mut self, yes: bool) -> Self {
        self.tets = yes;
        self
    }
    pub fn mixed(mut self, yes: bool) -> Self {
        self.mixed = yes;
        self
    }
    /// True when the cell in column `i` (along x) is split into tets.
    pub fn is_tet_column(&self, i: usize) -> bool {
        self.tets || (self.mixed && i >= self.divisions[0].div_ceil(2))
    }
    pub fn at(mut self, origin: [f64; 3]) -> Self {
        self.origin = origin;
        self
    }
}

/// Append a structured box to `mesh` (new nodes; nothing shared with existing blocks).
pub fn add_box(mesh: &mut Mesh, spec: &BoxSpec) {
    let [nx, ny, nz] = spec.divisions;
    let base = mesh.nodes.len();
    let id = |i: usize, j: usize, k: usize| base + i + (nx + 1) * (j + (ny + 1) * k);
    let mut tag = mesh.node_tags.last().copied().unwrap_or(0);
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                mesh.nodes.push([
                    spec.origin[0] + spec.size[0] * i as f64 / nx as f64,
                    spec.origin[1] + spec.size[1] * j as f64 / ny as f64,
                    spec.origin[2] + spec.size[2] * k as f64 / nz as f64,
                ]);
                tag += 1;
                mesh.node_tags.push(tag);
            }
        }
    }
    let mut etag = mesh.cells.iter().map(|c| c.tag).max().unwrap_or(0);
    let first_cell = mesh.cells.len();
    // grid cell (i, j, k) of each volume cell (6 per grid cell where split)
    let mut grid: Vec<(usize, usize, usize)> = Vec::new();
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let h = [
                    id(i, j, k),
                    id(i + 1, j, k),
                    id(i + 1, j + 1, k),
                    id(i, j + 1, k),
                    id(i, j, k + 1),
                    id(i + 1, j, k + 1),
                    id(i + 1, j + 1, k + 1),
                    id(i, j + 1, k + 1),
                ];
                if spec.is_tet_column(i) {
                    // Kuhn split: paths 0 → 6 along the three axes in every order
                    let step = |v: usize, axis: usize| -> usize {
                        // local hex ids by (x,y,z) bits
                        const BITS: [[usize; 3]; 8] = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]];
                        let mut b = BITS[v];
                        b[axis] = 1;
                        BITS.iter().position(|x| *x == b).unwrap()
                    };
                    for perm in [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]] {
                        let v1 = step(0, perm[0]);
                        let v2 = step(v1, perm[1]);
                        let mut t = [h[0], h[v1], h[v2], h[6]];
                        let x = |n: usize| nalgebra::Vector3::from(mesh.nodes[n]);
                        if (x(t[1]) - x(t[0])).cross(&(x(t[2]) - x(t[0]))).dot(&(x(t[3]) - x(t[0]))) < 0.0 {
                            t.swap(1, 2);
                        }
                        etag += 1;
                        mesh.cells.push(Cell::new(CellKind::Tet4, etag, &t));
                        grid.push((i, j, k));
                    }
                } else {
                    etag += 1;
                    mesh.cells.push(Cell::new(CellKind::Hex8, etag, &h));
                    grid.push((i, j, k));
                }
            }
        }
    }
    let vol_cells: Vec<usize> = (first_cell..mesh.cells.len()).collect();
    let next_tag = |mesh: &Mesh, dim: usize| mesh.groups.iter().filter(|g| g.dim == dim).map(|g| g.tag).max().unwrap_or(0) + 1;
    let t3 = next_tag(mesh, 3);
    // boundary faces classified by plane: the faces of the cells of the outer layer of the grid
    // (only they can have a face on a plane of the box) whose nodes all lie on a plane, in
    // (cell, local face) order, with the outward node order of `CellKind::faces`: the faces, order
    // and orientation of `topology::boundary_faces` over the whole block followed by the plane
    // test below, without a face map of the whole block (test
    // `boundary_groups_equal_a_search_over_every_cell`).
    let tol = 1e-9 * spec.size.iter().fold(0.0f64, |a, &b| a.max(b));
    let planes = [("x0", 0, spec.origin[0]), ("x1", 0, spec.origin[0] + spec.size[0]), ("y0", 1, spec.origin[1]), ("y1", 1, spec.origin[1] + spec.size[1]), ("z0", 2, spec.origin[2]), ("z1", 2, spec.origin[2] + spec.size[2])];
    let on_plane = |mesh: &Mesh, nodes: &[usize]| planes.iter().any(|&(_, axis, value)| nodes.iter().all(|&n| (mesh.nodes[n][axis] - value).abs() <= tol));
    let mut faces = Vec::new();
    for &c in &vol_cells {
        let (i, j, k) = grid[c - first_cell];
        if !(i == 0 || j == 0 || k == 0 || i + 1 == nx || j + 1 == ny || k + 1 == nz) {
            continue;
        }
        let cell = &mesh.cells[c];
        for (local, f) in cell.kind.faces().iter().enumerate() {
            let nodes: Vec<usize> = f.iter().map(|&a| cell.node(a)).collect();
            if on_plane(mesh, &nodes) {
                faces.push(topology::VolumeFace { cell: c, local, nodes });
            }
        }
    }
    mesh.groups.push(Group { name: format!("block:{}", spec.name), dim: 3, tag: t3, cells: vol_cells });
    for (pname, axis, value) in planes {
        let mut cells = Vec::new();
        for f in &faces {
            if f.nodes.iter().all(|&n| (mesh.nodes[n][axis] - value).abs() <= tol) {
                etag += 1;
                let kind = if f.nodes.len() == 3 { CellKind::Tri3 } else { CellKind::Quad4 };
                mesh.cells.push(Cell::new(kind, etag, &f.nodes));
                cells.push(mesh.cells.len() - 1);
            }
        }
        let t2 = next_tag(mesh, 2);
        mesh.groups.push(Group { name: format!("{}:{}", spec.name, pname), dim: 2, tag: t2, cells });
    }
}

/// A mesh of one structured box.
pub fn box_mesh(spec: &BoxSpec) -> Mesh {
    let mut m = Mesh { source: PathBuf::from(format!("<structured box {}>", spec.name)), nodes: vec![], node_tags: vec![], cells: vec![], groups: vec![] };
    add_box(&mut m, spec);
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tet_split_is_conforming_and_positive() {
        // 2×2×2 box split in tets: 48 tets, every tet positive; boundary = 6 faces × 4 quads × 2 tris.
        let m = box_mesh(&BoxSpec::new("b", [1.0, 1.0, 1.0], [2, 2, 2]).tets(true));
        let g = m.group("block:b").unwrap();
        assert_eq!(g.cells.len(), 48);
        assert!(g.cells.iter().all(|&c| m.min_corner_jacobian(c) > 0.0));
        let faces = topology::boundary_faces(&m, &g.cells);
        assert_eq!(faces.len(), 6 * 4 * 2);
        assert_eq!(m.group("b:z1").unwrap().cells.len(), 8);
    }

    #[test]
    fn tet_and_hex_volumes_sum_to_the_box_volume() {
        // Kuhn split: 6 positive tets per cell (volume = corner Jacobian / 6), together the box
        for tets in [true, false] {
            let m = box_mesh(&BoxSpec::new("b", [1.5, 0.7, 2.0], [3, 4, 5]).tets(tets).at([1.0, -2.0, 0.5]));
            let g = m.group("block:b").unwrap();
            assert_eq!(g.cells.len(), 60 * if tets { 6 } else { 1 });
            let vol: f64 = if tets {
                g.cells.iter().map(|&c| m.min_corner_jacobian(c) / 6.0).sum()
            } else {
                // cells of a structured box are bricks: volume = product of the edge lengths
                g.cells
                    .iter()
                    .map(|&c| {
                        let n = m.cells[c].nodes();
                        (0..3).map(|i| m.nodes[n[6] as usize][i] - m.nodes[n[0] as usize][i]).product::<f64>()
                    })
                    .sum()
            };
            assert!((vol - 1.5 * 0.7 * 2.0).abs() < 1e-12, "tets {tets}: volume {vol}");
        }
    }

    #[test]
    fn mixed_box_has_hex_then_tet_columns_filling_the_box() {
        // 3 columns along x: 2 of hexes, 1 of Kuhn tets; every cell positive, the volumes sum to the
        // box's, the top face has 2×2 quads and 1×2×2 triangles
        let m = box_mesh(&BoxSpec::new("b", [1.5, 1.0, 0.5], [3, 2, 2]).mixed(true));
        let g = m.group("block:b").unwrap();
        let hexes = g.cells.iter().filter(|&&c| m.cells[c].kind == CellKind::Hex8).count();
        let tets = g.cells.iter().filter(|&&c| m.cells[c].kind == CellKind::Tet4).count();
        assert_eq!((hexes, tets), (2 * 2 * 2, 6 * 2 * 2));
        assert!(g.cells.iter().all(|&c| m.min_corner_jacobian(c) > 0.0));
        let vol: f64 = g
            .cells
            .iter()
            .map(|&c| match m.cells[c].kind {
                CellKind::Tet4 => m.min_corner_jacobian(c) / 6.0,
                _ => {
                    let n = m.cells[c].nodes();
                    (0..3).map(|i| m.nodes[n[6] as usize][i] - m.nodes[n[0] as usize][i]).product::<f64>()
                }
            })
            .sum();
        assert!((vol - 0.75).abs() < 1e-12, "volume {vol}");
        let top = &m.group("b:z1").unwrap().cells;
        let quads = top.iter().filter(|&&c| m.cells[c].kind == CellKind::Quad4).count();
        assert_eq!((quads, top.len() - quads), (4, 4));
        // every x0 face is a quad (hex column), every x1 face a triangle (tet column)
        assert!(m.group("b:x0").unwrap().cells.iter().all(|&c| m.cells[c].kind == CellKind::Quad4));
        assert!(m.group("b:x1").unwrap().cells.iter().all(|&c| m.cells[c].kind == CellKind::Tri3));
    }

    #[test]
    fn boundary_groups_equal_a_search_over_every_cell() {
        // the outer-layer search of add_box gives the faces of a search over all cells
        for tets in [true, false] {
            let spec = BoxSpec::new("b", [1.0, 2.0, 3.0], [3, 4, 5]).tets(tets).at([-1.0, 0.5, 2.0]);
            let m = box_mesh(&spec);
            let all = topology::boundary_faces(&m, &m.group("block:b").unwrap().cells);
            assert_eq!(all.len(), 2 * (12 + 15 + 20) * if tets { 2 } else { 1 });
            let from_groups: usize = ["x0", "x1", "y0", "y1", "z0", "z1"].iter().map(|p| m.group(&format!("b:{p}")).unwrap().cells.len()).sum();
            assert_eq!(from_groups, all.len());
            // the same faces, nodes (outward order) and order, plane by plane
            let tol = 1e-9 * 3.0;
            let planes = [("x0", 0, -1.0), ("x1", 0, 0.0), ("y0", 1, 0.5), ("y1", 1, 2.5), ("z0", 2, 2.0), ("z1", 2, 5.0)];
            for (p, axis, value) in planes {
                let expect: Vec<Vec<usize>> =
                    all.iter().filter(|f| f.nodes.iter().all(|&n| (m.nodes[n][axis] - value).abs() <= tol)).map(|f| f.nodes.clone()).collect();
                let got: Vec<Vec<usize>> =
                    m.group(&format!("b:{p}")).unwrap().cells.iter().map(|&c| m.cells[c].nodes().iter().map(|&n| n as usize).collect()).collect();
                assert_eq!(got, expect, "plane {p}");
            }
        }
    }
}
