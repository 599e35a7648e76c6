//! A joint side: the tri3/quad4 faces of one physical surface group, each matched to the one
//! volume cell it bounds and oriented outward of that cell, with a node → faces adjacency.
//!
//! Matching is by sorted node set ([`crate::mesh::topology::face_key`]). Instead of indexing every
//! face of every volume (`topology::volume_faces`, one allocation per face), only volume faces whose
//! nodes all lie on the group are looked up: this keeps 10⁶-face surfaces in the sub-second range.

use super::normals::{face_area, face_normal_raw, vec3};
use nalgebra::Vector3;
use super::{Csr, invalid};
use crate::error::InterfaceError;
use crate::mesh::topology::face_key;
use crate::mesh::{CellKind, Mesh};
use std::collections::HashMap;
use std::collections::hash_map::Entry;
use std::hash::{BuildHasherDefault, Hasher};

/// Multiplicative hash for face keys (the default SipHash is several times slower on 10⁶ keys;
/// keys are node indices, not attacker-controlled).
#[derive(Default)]
struct FaceKeyHasher(u64);

impl Hasher for FaceKeyHasher {
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut w = [0u8; 8];
            w[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(w));
        }
    }
    fn write_u64(&mut self, i: u64) {
        self.0 = (self.0.rotate_left(5) ^ i).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    fn write_usize(&mut self, i: usize) {
        self.write_u64(i as u64);
    }
    fn finish(&self) -> u64 {
        self.0
    }
}

type FaceKeyMap = HashMap<[u32; 4], u32, BuildHasherDefault<FaceKeyHasher>>;

/// One face of a joint side.
#[derive(Clone, Debug, PartialEq)]
pub struct Face {
    /// Tri3 or Quad4.
    pub kind: CellKind,
    /// Index of the face cell in `Mesh::cells`.
    pub cell: usize,
    /// Index in `Mesh::cells` of the volume cell the face bounds (its owner).
    pub volume_cell: usize,
    /// Mesh node indices in outward order (right-hand normal out of `volume_cell`), starting at the
    /// face cell's first node. Unused entries are `u32::MAX`.
    nodes: [u32; 4],
    /// The same nodes as surface-local indices (positions in [`Surface::nodes`]).
    local: [u32; 4],
}

impl Face {
    /// Number of nodes (3 or 4).
    pub fn n_nodes(&self) -> usize {
        self.kind.n_nodes()
    }
    /// Mesh node indices, outward order.
    pub fn nodes(&self) -> &[u32] {
        &self.nodes[..self.n_nodes()]
    }
    /// Surface-local node indices, outward order.
    pub fn local_nodes(&self) -> &[u32] {
        &self.local[..self.n_nodes()]
    }
}

/// The faces of one physical surface group, outward oriented, with their nodes.
#[derive(Clone, Debug)]
pub struct Surface {
    /// Physical group name.
    pub group: String,
    /// Faces in the group's cell order.
    pub faces: Vec<Face>,
    /// Sorted mesh node indices of the faces' nodes; a node's position here is its local index.
    pub nodes: Vec<usize>,
    /// Coordinates of `nodes` [m].
    pub points: Vec<[f64; 3]>,
    /// For each local node, the faces containing it (ascending face indices).
    pub node_faces: Csr,
    /// Total area [m²] (quads by 2×2 Gauss, exact when planar).
    pub area: f64,
}

impl Surface {
    /// Build the surface of physical group `group` (dimension 2) for joint `joint` (named in errors).
    ///
    /// Errors: the group does not exist (the message lists those that do) or is not a surface
    /// group; a face bounds no volume cell or two of them (it is inside a block); a face appears
    /// twice; a face's node order is not a cycle of its volume face; a face is degenerate (zero
    /// area); the owning volume cell is inverted (its outward normal points into it).
    pub fn from_group(mesh: &Mesh, joint: &str, group: &str) -> Result<Surface, InterfaceError> {
        let g = surface_group(mesh, joint, group)?;
        let (key_of, on_group) = group_face_keys(mesh, joint, group, &g.cells)?;
        let owner = face_owners(mesh, &key_of, &on_group, g.cells.len());
        let mut faces = Vec::with_capacity(g.cells.len());
        for (i, &c) in g.cells.iter().enumerate() {
            faces.push(oriented_face(mesh, joint, group, c, owner[i])?);
        }
        let (nodes, points, node_faces) = local_numbering(mesh, on_group, &mut faces);
        let area = checked_area(mesh, joint, group, &faces, &points)?;
        Ok(Surface { group: group.to_string(), faces, nodes, points, node_faces, area })
    }

    /// Surface-local index of mesh node `node`, if it is on this surface.
    pub fn local_index(&self, node: usize) -> Option<usize> {
        self.nodes.binary_search(&node).ok()
    }

    /// Faces (indices into `faces`) containing local node `local`, ascending.
    pub fn faces_of_node(&self, local: usize) -> &[u32] {
        self.node_faces.row(local)
    }

    /// Faces containing mesh node `node`, ascending; empty when the node is not on this surface.
    /// This is the widening step the solver uses when a slave node leaves its candidate set.
    pub fn faces_around_mesh_node(&self, node: usize) -> &[u32] {
        match self.local_index(node) {
            Some(l) => self.faces_of_node(l),
            None => &[],
        }
    }

    /// Coordinates of the nodes of face `f`, outward order (unused slots repeat the last node).
    pub fn face_points(&self, f: usize) -> ([[f64; 3]; 4], usize) {
        let face = &self.faces[f];
        let n = face.n_nodes();
        let mut x = [[0.0; 3]; 4];
        for (k, &l) in face.local_nodes().iter().enumerate() {
            x[k] = self.points[l as usize];
        }
        if n == 3 {
            x[3] = x[2];
        }
        (x, n)
    }

    /// Mean face area [m²]: the size measure `auto` compares (smaller = finer).
    pub fn mean_face_area(&self) -> f64 {
        self.area / self.faces.len() as f64
    }
}

/// No owner yet (in [`face_owners`]' entries).
const NONE: usize = usize::MAX;

/// The surface group `group` of `mesh`, with at least one cell (the steps of
/// [`Surface::from_group`] follow).
fn surface_group<'m>(mesh: &'m Mesh, joint: &str, group: &str) -> Result<&'m crate::mesh::Group, InterfaceError> {
    let g = match mesh.group_of_dim(group, 2) {
        Ok(g) => g,
        Err(e) => {
            return Err(invalid(
                joint,
                match mesh.group(group) {
                    Ok(other) => format!(
                        "physical group \"{group}\" has dimension {}; a joint side must be a surface group (dimension 2) of tri3/quad4 faces",
                        other.dim
                    ),
                    Err(_) => format!("{e}"),
                },
            ));
        }
    };
    if g.cells.is_empty() {
        return Err(invalid(joint, format!("physical group \"{group}\" has no faces")));
    }
    Ok(g)
}

/// Face keys of the group's cells `cells` (key → position in `cells`) and a mark on their nodes.
fn group_face_keys(mesh: &Mesh, joint: &str, group: &str, cells: &[usize]) -> Result<(FaceKeyMap, Vec<bool>), InterfaceError> {
    let mut key_of: FaceKeyMap = FaceKeyMap::with_capacity_and_hasher(cells.len(), Default::default());
    let mut on_group = vec![false; mesh.nodes.len()];
    for (i, &c) in cells.iter().enumerate() {
        let cell = &mesh.cells[c];
        if !matches!(cell.kind, CellKind::Tri3 | CellKind::Quad4) {
            return Err(invalid(
                joint,
                format!("element {} of group \"{group}\" is a {}; joint faces must be tri3 or quad4", cell.tag, cell.kind.name()),
            ));
        }
        match key_of.entry(face_key(cell.nodes())) {
            Entry::Occupied(e) => {
                return Err(invalid(
                    joint,
                    format!(
                        "elements {} and {} of group \"{group}\" have the same nodes (a duplicated face); remove one",
                        mesh.cells[cells[*e.get() as usize]].tag,
                        cell.tag
                    ),
                ));
            }
            Entry::Vacant(v) => {
                v.insert(i as u32);
            }
        }
        for &n in cell.nodes() {
            on_group[n as usize] = true;
        }
    }
    Ok((key_of, on_group))
}

/// Owners of the `n` group faces: volume faces whose nodes all lie on the group and whose key
/// is a group face. Per face (volume cell, its local face, a second owner), [`NONE`] where
/// there is none.
fn face_owners(mesh: &Mesh, key_of: &FaceKeyMap, on_group: &[bool], n: usize) -> Vec<(usize, usize, usize)> {
    let mut owner = vec![(NONE, 0usize, NONE); n];
    let mut buf = [0u32; 4];
    for (c, cell) in mesh.cells.iter().enumerate() {
        for (lf, f) in cell.kind.faces().iter().enumerate() {
            if !f.iter().all(|&k| on_group[cell.node(k)]) {
                continue;
            }
            for (b, &k) in buf.iter_mut().zip(f.iter()) {
                *b = cell.nodes()[k];
            }
            if let Some(&i) = key_of.get(&face_key(&buf[..f.len()])) {
                let o = &mut owner[i as usize];
                if o.0 == NONE {
                    *o = (c, lf, NONE);
                } else if o.2 == NONE {
                    o.2 = c;
                }
            }
        }
    }
    owner
}

/// The face of cell `c` oriented outward of its one owner `(volume cell, local face, second
/// owner)` (mesh node ids; local ids are set by [`local_numbering`]).
fn oriented_face(mesh: &Mesh, joint: &str, group: &str, c: usize, (vc, lf, second): (usize, usize, usize)) -> Result<Face, InterfaceError> {
    let tag = |c: usize| mesh.cells[c].tag;
    if vc == NONE {
        return Err(invalid(
            joint,
            format!(
                "element {} of group \"{group}\" is not a face of any volume element, so it bounds no block; \
                 a joint face must lie on the boundary of a meshed block (is the block's volume in a physical group?)",
                tag(c)
            ),
        ));
    }
    if second != NONE {
        return Err(invalid(
            joint,
            format!(
                "element {} of group \"{group}\" is shared by volume elements {} and {}, so it lies inside a block, \
                 not on its boundary; mesh the two sides of a joint as separate volumes (distinct nodes on each side)",
                tag(c),
                tag(vc),
                tag(second)
            ),
        ));
    }
    let cell = &mesh.cells[c];
    let vol = &mesh.cells[vc];
    let vface: Vec<u32> = vol.kind.faces()[lf].iter().map(|&k| vol.nodes()[k]).collect();
    let fn_ = cell.nodes();
    let m = fn_.len();
    let p0 = vface.iter().position(|&n| n == fn_[0]).expect("same node set");
    let forward = (0..m).all(|k| vface[(p0 + k) % m] == fn_[k]);
    let backward = (0..m).all(|k| vface[(p0 + m - k) % m] == fn_[k]);
    let mut nodes = [u32::MAX; 4];
    if forward {
        nodes[..m].copy_from_slice(fn_);
    } else if backward {
        nodes[0] = fn_[0];
        for k in 1..m {
            nodes[k] = fn_[m - k];
        }
    } else {
        return Err(invalid(
            joint,
            format!(
                "the node order of element {} of group \"{group}\" is not a cycle around the face of volume element {} (a twisted face); \
                 regenerate the mesh",
                tag(c),
                tag(vc)
            ),
        ));
    }
    Ok(Face { kind: cell.kind, cell: c, volume_cell: vc, nodes, local: [u32::MAX; 4] })
}

/// Local numbering of the marked nodes `on_group` through a dense map (cheaper than a binary
/// search per face node): sets the faces' local ids; returns the sorted mesh nodes, their
/// points and the node → faces adjacency.
fn local_numbering(mesh: &Mesh, on_group: Vec<bool>, faces: &mut [Face]) -> (Vec<usize>, Vec<[f64; 3]>, Csr) {
    let mut nodes: Vec<usize> = (0..mesh.nodes.len()).filter(|&n| on_group[n]).collect();
    nodes.shrink_to_fit();
    let mut local_of = vec![u32::MAX; mesh.nodes.len()];
    for (l, &n) in nodes.iter().enumerate() {
        local_of[n] = l as u32;
    }
    drop(on_group);
    let points: Vec<[f64; 3]> = nodes.iter().map(|&n| mesh.nodes[n]).collect();
    let mut counts = vec![0usize; nodes.len() + 1];
    for f in faces.iter_mut() {
        for k in 0..f.n_nodes() {
            f.local[k] = local_of[f.nodes[k] as usize];
            counts[f.local[k] as usize + 1] += 1;
        }
    }
    drop(local_of);
    for l in 0..nodes.len() {
        counts[l + 1] += counts[l];
    }
    let mut items = vec![0u32; counts[nodes.len()]];
    let mut fill = counts.clone();
    for (fi, f) in faces.iter().enumerate() {
        for &l in f.local_nodes() {
            items[fill[l as usize]] = fi as u32;
            fill[l as usize] += 1;
        }
    }
    (nodes, points, Csr { offsets: counts, items })
}

/// The total area of `faces` (local `points`), after checking each face is not degenerate and
/// its owner is not inverted.
fn checked_area(mesh: &Mesh, joint: &str, group: &str, faces: &[Face], points: &[[f64; 3]]) -> Result<f64, InterfaceError> {
    let tag = |c: usize| mesh.cells[c].tag;
    let mut area = 0.0;
    for f in faces {
        let x: Vec<[f64; 3]> = f.local_nodes().iter().map(|&l| points[l as usize]).collect();
        let a = face_area(f.kind, &x);
        if !(a > 0.0) {
            return Err(invalid(
                joint,
                format!("element {} of group \"{group}\" is degenerate (area {a:.3e} m²); fix the mesh", tag(f.cell)),
            ));
        }
        area += a;
        let vol = &mesh.cells[f.volume_cell];
        let centre_vol = vol.nodes().iter().fold(Vector3::zeros(), |s: Vector3<f64>, &n| s + vec3(mesh.nodes[n as usize])) * (1.0 / vol.nodes().len() as f64);
        let centre_face = x.iter().fold(Vector3::zeros(), |s: Vector3<f64>, &p| s + vec3(p)) * (1.0 / x.len() as f64);
        let n = face_normal_raw(f.kind, &x);
        if (centre_vol - centre_face).dot(&n) >= 0.0 {
            return Err(invalid(
                joint,
                format!(
                    "volume element {} (owner of face element {} of group \"{group}\") is inverted: its outward face normal points into it; \
                     fix the node order or the geometry orientation (e.g. `ReverseMesh`)",
                    vol.tag,
                    tag(f.cell)
                ),
            ));
        }
    }
    Ok(area)
}
