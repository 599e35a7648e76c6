//! Joint interfaces (the tagger, design.md §3): pairing and candidate sets, built once.
//!
//! Owns: the two [`Surface`]s of each joint, the slave-node normals and tributary areas,
//! the nearest master node O of every slave node (the NTN pair), and the NTS candidate sets
//! Layer1 (master faces containing O) and Layer2 (Layer1 plus the faces sharing a node with it).
//!
//! Inputs: the [`Mesh`] and one [`JointSpec`] per joint (two physical surface-group names,
//! optionally `auto`). Outputs: [`Joint`] (immutable), written for inspection by
//! [`write_joint_json`] and [`write_joint_vtu`] (fields documented in `docs/tagger.md`).
//!
//! Conventions (stated here once):
//! - Units SI: coordinates and distances in m, areas in m².
//! - "Slave node `i`" is position `i` in [`Surface::nodes`] of the slave surface (sorted mesh node
//!   indices); every per-slave-node array of [`Joint`] is indexed that way. Master faces are
//!   addressed by their position in [`Surface::faces`] of the master surface (`u32`), master nodes
//!   by their position in the master's [`Surface::nodes`]. Mesh node indices index `Mesh::nodes`
//!   (0-based); Gmsh tags (`Mesh::node_tags`, `Cell::tag`) appear only in messages and outputs.
//! - Face node order is outward: the right-hand normal points out of the block that owns the face.
//!   The slave normal therefore points from the slave block towards the master.
//! - Candidate lists are sorted ascending and built deterministically (ties in the nearest-node
//!   search go to the lowest master node index).
//!
//! Invariants of a [`Joint`]: every slave node has a unit normal, a positive tributary area, an O,
//! a non-empty Layer1 ⊆ Layer2, and lies within `tolerance` of the master surface.

mod candidates;
mod normals;
mod surface;
mod synthetic;
mod write;

pub use candidates::{
    layer1_candidates, layer2_candidates, master_surface_distances_into, nearest_master_nodes_into,
    point_triangle_distance,
};
pub use normals::{face_area, face_nodal_weights_into, face_unit_normal, slave_normals_into, tributary_areas_into, tributary_vectors_into, FaceWeights};
pub use surface::{Face, Surface};
pub use synthetic::flat_joint_mesh;
pub use write::{JOINT_JSON_VERSION, write_joint_json, write_joint_vtu};

use crate::error::InterfaceError;
use crate::mesh::topology::Blocks;
use crate::mesh::Mesh;

/// A slave node is NTN-conforming when its distance to O is below this fraction of the joint
/// size (bounding-box diagonal of both surfaces). Default 1e-9: well above the round-off of
/// coordinates written by Gmsh (≈1e-16 relative), well below any real mesh offset.
pub const CONFORMING_RELATIVE: f64 = 1e-9;

/// Two master nodes count as equally near to a slave node when their distances differ by less
/// than this fraction of the joint size; the lower master node index wins (determinism).
pub const TIE_RELATIVE: f64 = 1e-9;

/// One joint as the scene names it: two physical surface groups (dim 2, tri3/quad4 faces).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct JointSpec {
    /// Joint name, quoted in messages and outputs.
    pub name: String,
    /// Physical group of the master side.
    pub master: String,
    /// Physical group of the slave side.
    pub slave: String,
    /// When true the finer side (smaller mean face area) becomes the slave, whatever the names say;
    /// on a tie the named roles are kept.
    pub auto: bool,
}

/// Compressed rows of `u32` (CSR): row `i` is `items[offsets[i]..offsets[i + 1]]`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Csr {
    pub offsets: Vec<usize>,
    pub items: Vec<u32>,
}

impl Csr {
    /// An empty CSR ready for `push_row`.
    pub fn with_capacity(rows: usize, items: usize) -> Self {
        let mut offsets = Vec::with_capacity(rows + 1);
        offsets.push(0);
        Csr { offsets, items: Vec::with_capacity(items) }
    }
    /// Append one row.
    pub fn push_row(&mut self, row: &[u32]) {
        self.items.extend_from_slice(row);
        self.offsets.push(self.items.len());
    }
    /// Row `i`.
    pub fn row(&self, i: usize) -> &[u32] {
        &self.items[self.offsets[i]..self.offsets[i + 1]]
    }
    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }
    /// Length of row `i`.
    pub fn row_len(&self, i: usize) -> usize {
        self.offsets[i + 1] - self.offsets[i]
    }
}

/// A tagged joint: both surfaces and everything per slave node (indexed by slave node, see the
/// module conventions). Built once by [`tag_joint`], never mutated.
#[derive(Clone, Debug)]
pub struct Joint {
    pub name: String,
    pub master: Surface,
    pub slave: Surface,
    /// True when `auto` swapped the named roles (the group named `master` became the slave).
    pub swapped: bool,
    /// Bounding-box diagonal of both surfaces [m]; scale for the relative thresholds.
    pub size: f64,
    /// Largest allowed slave-node-to-master-surface distance [m] used when tagging.
    pub tolerance: f64,
    /// Outward unit normal at each slave node (out of the slave block, towards the master).
    pub normals: Vec<[f64; 3]>,
    /// Tributary area of each slave node [m²] (∫ N_I dA over its faces); they sum to the slave area.
    pub areas: Vec<f64>,
    /// O: nearest master node of each slave node, as a master-local node index.
    pub nearest: Vec<u32>,
    /// Distance from each slave node to its O [m] (the NTN pair's offset).
    pub nearest_distance: Vec<f64>,
    /// Distance from each slave node to the master surface [m] (closest point over its Layer2 faces;
    /// quads split into two triangles).
    pub surface_distance: Vec<f64>,
    /// Layer1: master faces containing O, per slave node.
    pub layer1: Csr,
    /// Layer2: Layer1 plus every master face sharing a node with a Layer1 face, per slave node.
    pub layer2: Csr,
    /// Largest `nearest_distance` over the joint [m] (the NTN error) and the slave node where it occurs.
    pub ntn_max_distance: f64,
    pub ntn_max_slave: usize,
}

impl Joint {
    /// Mesh node indices of the slave nodes (slave node `i` is `slave_nodes()[i]`).
    pub fn slave_nodes(&self) -> &[usize] {
        &self.slave.nodes
    }
    /// Number of slave nodes.
    pub fn n_slave(&self) -> usize {
        self.slave.nodes.len()
    }
    /// Mesh node index of O for slave node `i`.
    pub fn nearest_master_node(&self, i: usize) -> usize {
        self.master.nodes[self.nearest[i] as usize]
    }
    /// Distance below which an NTN pair counts as conforming [m].
    pub fn conforming_distance(&self) -> f64 {
        CONFORMING_RELATIVE * self.size
    }
    /// True when slave node `i` coincides with its O (the NTN pair is exact there).
    pub fn is_ntn_conforming(&self, i: usize) -> bool {
        self.nearest_distance[i] < self.conforming_distance()
    }
    /// Number of NTN-conforming slave nodes.
    pub fn ntn_conforming_count(&self) -> usize {
        (0..self.n_slave()).filter(|&i| self.is_ntn_conforming(i)).count()
    }
}

pub(crate) fn invalid(joint: &str, message: impl Into<String>) -> InterfaceError {
    InterfaceError::Invalid { joint: joint.to_string(), message: message.into() }
}

/// Tag one joint: build both surfaces, choose master/slave, then slave normals, tributary areas,
/// O, Layer1, Layer2 and the distances.
///
/// `tolerance` [m]: the largest allowed distance from a slave node to the master surface; a joint
/// whose sides are farther apart is an error that quotes the distance and the node. It must be
/// finite and ≥ 0 (a value like 1e-6 × the model size accepts Gmsh round-off on touching faces).
///
/// The mesh's blocks (element connectivity, [`Blocks`]) are computed here; to tag several joints
/// of one mesh compute them once and call [`tag_joint_in`].
pub fn tag_joint(mesh: &Mesh, spec: &JointSpec, tolerance: f64) -> Result<Joint, InterfaceError> {
    tag_joint_in(mesh, &Blocks::of(mesh), spec, tolerance)
}

/// [`tag_joint`] with the mesh's blocks given. Besides its checks, a joint whose master and slave
/// faces bound one block (volume elements connected through shared nodes) is an error naming
/// the joint and both groups ([`check_two_blocks`]).
pub fn tag_joint_in(mesh: &Mesh, blocks: &Blocks, spec: &JointSpec, tolerance: f64) -> Result<Joint, InterfaceError> {
    let name = spec.name.as_str();
    if !(tolerance.is_finite() && tolerance >= 0.0) {
        return Err(invalid(name, format!("tolerance {tolerance} m must be finite and >= 0")));
    }
    if spec.master == spec.slave {
        return Err(invalid(
            name,
            format!(
                "master and slave are the same group \"{}\"; a joint needs two surface groups, one on each block",
                spec.master
            ),
        ));
    }
    let named_master = Surface::from_group(mesh, name, &spec.master)?;
    let named_slave = Surface::from_group(mesh, name, &spec.slave)?;
    check_two_blocks(mesh, blocks, name, &named_master, &named_slave)?;
    let swapped = spec.auto && named_master.mean_face_area() < named_slave.mean_face_area();
    let (master, slave) = if swapped { (named_slave, named_master) } else { (named_master, named_slave) };

    let size = bounding_diagonal(master.points.iter().chain(slave.points.iter()));
    let n = slave.nodes.len();

    let mut normals = vec![[0.0; 3]; n];
    slave_normals_into(name, &slave, &mut normals)?;
    let mut areas = vec![0.0; n];
    tributary_areas_into(&slave, &mut areas);

    let mut nearest = vec![0u32; n];
    let mut nearest_distance = vec![0.0; n];
    nearest_master_nodes_into(&master, &slave.points, TIE_RELATIVE * size, &mut nearest, &mut nearest_distance);
    let layer1 = layer1_candidates(&master, &nearest);
    let layer2 = layer2_candidates(&master, &layer1);

    let mut surface_distance = vec![0.0; n];
    master_surface_distances_into(&master, &slave.points, &layer2, &mut surface_distance);
    let (far, dmax) = argmax(&surface_distance);
    if dmax > tolerance {
        let count = surface_distance.iter().filter(|&&d| d > tolerance).count();
        let node = slave.nodes[far];
        let x = slave.points[far];
        return Err(invalid(
            name,
            format!(
                "slave group \"{}\" and master group \"{}\" are farther apart than the tolerance {:.3e} m: \
                 {count} of {n} slave nodes are off the master surface, the farthest is node {} at ({:.4}, {:.4}, {:.4}), \
                 {dmax:.6e} m from the master surface (and {:.6e} m from its nearest master node {}). \
                 Check that the two groups face each other, or raise the tolerance.",
                slave.group,
                master.group,
                tolerance,
                mesh.node_tags[node],
                x[0],
                x[1],
                x[2],
                nearest_distance[far],
                mesh.node_tags[master.nodes[nearest[far] as usize]],
            ),
        ));
    }
    let (ntn_max_slave, ntn_max_distance) = argmax(&nearest_distance);

    Ok(Joint {
        name: spec.name.clone(),
        master,
        slave,
        swapped,
        size,
        tolerance,
        normals,
        areas,
        nearest,
        nearest_distance,
        surface_distance,
        layer1,
        layer2,
        ntn_max_distance,
        ntn_max_slave,
    })
}

/// Tag every joint, in order; the first failure is returned.
pub fn tag_joints(mesh: &Mesh, specs: &[JointSpec], tolerance: f64) -> Result<Vec<Joint>, InterfaceError> {
    let blocks = Blocks::of(mesh);
    specs.iter().map(|s| tag_joint_in(mesh, &blocks, s, tolerance)).collect()
}

/// A joint separates two blocks meshed apart: its master and slave faces must bound volume
/// elements of different blocks (no chain of elements sharing nodes joins them). Faces of one
/// block — two names for the same faces, or two faces of one body — would put the contact force
/// inside a body (issue 19: such a joint passed `tag` and `run` then blamed "penalty contact").
/// The dam's monoliths and foundation, meshed apart and tied through non-conforming
/// interfaces, share no node and stay separate blocks (`dam::dam_joints_are_faces_of_two_blocks`).
/// A joint that ends inside a body (its two sides joined beyond its tip) is therefore refused too.
pub fn check_two_blocks(mesh: &Mesh, blocks: &Blocks, joint: &str, master: &Surface, slave: &Surface) -> Result<(), InterfaceError> {
    let mut master_blocks: Vec<(u32, usize)> = master.faces.iter().map(|f| (blocks.block_of(f.volume_cell), f.cell)).collect();
    master_blocks.sort_unstable();
    master_blocks.dedup_by_key(|b| b.0);
    for f in &slave.faces {
        let b = blocks.block_of(f.volume_cell);
        if let Ok(k) = master_blocks.binary_search_by_key(&b, |m| m.0) {
            let m = master_blocks[k].1;
            return Err(invalid(
                joint,
                format!(
                    "master group \"{}\" and slave group \"{}\" are faces of the same block (master face element {} and slave face element {} \
                     bound volume elements connected through shared nodes), so the contact force would act inside one body. \
                     A joint separates two blocks meshed apart: give it a face group of each block (in gmsh, two volumes whose common \
                     surface is not merged: no Coherence or BooleanFragments across the joint), or remove the joint.",
                    master.group, slave.group, mesh.cells[m].tag, mesh.cells[f.cell].tag
                ),
            ));
        }
    }
    Ok(())
}

/// Index and value of the largest entry (first on ties); (0, 0.0) when empty.
fn argmax(v: &[f64]) -> (usize, f64) {
    v.iter().enumerate().fold((0, 0.0), |(bi, bv), (i, &x)| if x > bv { (i, x) } else { (bi, bv) })
}

/// Diagonal of the axis-aligned bounding box of the points [m].
fn bounding_diagonal<'a>(points: impl Iterator<Item = &'a [f64; 3]>) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        for d in 0..3 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    if lo[0] > hi[0] {
        return 0.0;
    }
    ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt()
}
