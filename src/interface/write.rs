//! Inspection outputs of the tagger: one JSON for all joints, one VTU per joint
//! (fields, units and meaning: `docs/tagger.md`). Both are written to a temporary file and renamed.

use super::{Csr, Face, Joint};
use crate::error::OutputError;
use crate::mesh::{CellKind, Mesh};
use crate::vtk::vtu::{Field, Grid, write_vtu};
use serde::{Serialize, Serializer};
use std::io::Write;
use std::path::Path;

/// Version of the JSON layout; bump when a field changes meaning.
pub const JOINT_JSON_VERSION: u32 = 1;

struct Rows<'a>(&'a Csr);
impl Serialize for Rows<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq((0..self.0.rows()).map(|i| self.0.row(i)))
    }
}

#[derive(Serialize)]
struct FacesJson<'a> {
    /// Gmsh element tag of each face cell.
    elements: Vec<u64>,
    /// Gmsh element tag of the volume cell each face bounds.
    volume_elements: Vec<u64>,
    kind: Vec<&'static str>,
    /// Mesh node indices, outward order.
    nodes: Vec<&'a [u32]>,
}

impl<'a> FacesJson<'a> {
    fn new(mesh: &Mesh, faces: &'a [Face]) -> Self {
        FacesJson {
            elements: faces.iter().map(|f| mesh.cells[f.cell].tag).collect(),
            volume_elements: faces.iter().map(|f| mesh.cells[f.volume_cell].tag).collect(),
            kind: faces.iter().map(|f| f.kind.name()).collect(),
            nodes: faces.iter().map(|f| f.nodes()).collect(),
        }
    }
}

#[derive(Serialize)]
struct SlaveNodesJson<'a> {
    node: &'a [usize],
    tag: Vec<u64>,
    x: &'a [[f64; 3]],
    normal: &'a [[f64; 3]],
    area: &'a [f64],
    o: Vec<usize>,
    o_tag: Vec<u64>,
    o_distance: &'a [f64],
    ntn_conforming: Vec<bool>,
    surface_distance: &'a [f64],
    layer1: Rows<'a>,
    layer2: Rows<'a>,
}

#[derive(Serialize)]
struct JointJson<'a> {
    name: &'a str,
    master_group: &'a str,
    slave_group: &'a str,
    swapped: bool,
    size: f64,
    tolerance: f64,
    master_area: f64,
    slave_area: f64,
    n_slave_nodes: usize,
    ntn_max_distance: f64,
    ntn_max_slave_node: usize,
    ntn_max_slave_node_tag: u64,
    conforming_distance: f64,
    ntn_conforming_count: usize,
    max_surface_distance: f64,
    master_faces: FacesJson<'a>,
    slave_faces: FacesJson<'a>,
    slave_nodes: SlaveNodesJson<'a>,
}

#[derive(Serialize)]
struct FileJson<'a> {
    format: &'static str,
    version: u32,
    length_unit: &'static str,
    mesh: String,
    joints: Vec<JointJson<'a>>,
}

fn joint_json<'a>(mesh: &Mesh, j: &'a Joint) -> JointJson<'a> {
    let n = j.n_slave();
    let o: Vec<usize> = (0..n).map(|i| j.nearest_master_node(i)).collect();
    JointJson {
        name: &j.name,
        master_group: &j.master.group,
        slave_group: &j.slave.group,
        swapped: j.swapped,
        size: j.size,
        tolerance: j.tolerance,
        master_area: j.master.area,
        slave_area: j.slave.area,
        n_slave_nodes: n,
        ntn_max_distance: j.ntn_max_distance,
        ntn_max_slave_node: j.slave.nodes.get(j.ntn_max_slave).copied().unwrap_or(0),
        ntn_max_slave_node_tag: j.slave.nodes.get(j.ntn_max_slave).map(|&k| mesh.node_tags[k]).unwrap_or(0),
        conforming_distance: j.conforming_distance(),
        ntn_conforming_count: j.ntn_conforming_count(),
        max_surface_distance: j.surface_distance.iter().copied().fold(0.0, f64::max),
        master_faces: FacesJson::new(mesh, &j.master.faces),
        slave_faces: FacesJson::new(mesh, &j.slave.faces),
        slave_nodes: SlaveNodesJson {
            node: &j.slave.nodes,
            tag: j.slave.nodes.iter().map(|&k| mesh.node_tags[k]).collect(),
            x: &j.slave.points,
            normal: &j.normals,
            area: &j.areas,
            o_tag: o.iter().map(|&k| mesh.node_tags[k]).collect(),
            o,
            o_distance: &j.nearest_distance,
            ntn_conforming: (0..n).map(|i| j.is_ntn_conforming(i)).collect(),
            surface_distance: &j.surface_distance,
            layer1: Rows(&j.layer1),
            layer2: Rows(&j.layer2),
        },
    }
}

/// Write every joint's tagging to one JSON file (layout in `docs/tagger.md`), atomically.
pub fn write_joint_json(path: &Path, mesh: &Mesh, joints: &[Joint]) -> Result<(), OutputError> {
    let doc = FileJson {
        format: "jointquake-joints",
        version: JOINT_JSON_VERSION,
        length_unit: "m",
        mesh: mesh.source.display().to_string(),
        joints: joints.iter().map(|j| joint_json(mesh, j)).collect(),
    };
    let tmp = path.with_extension("json.tmp");
    let file = std::fs::File::create(&tmp).map_err(|e| OutputError::write(path, e))?;
    let mut w = std::io::BufWriter::new(file);
    serde_json::to_writer(&mut w, &doc).map_err(|e| OutputError::write(path, e))?;
    w.flush().map_err(|e| OutputError::write(path, e))?;
    drop(w);
    std::fs::rename(&tmp, path).map_err(|e| OutputError::write(path, e))
}

/// Write both surfaces of `joint` to a VTU with the slave-node fields (names, units and meaning in
/// `docs/tagger.md`). Points: the master nodes first, then the slave nodes; cells: master faces,
/// then slave faces. Slave-only fields are 0 on master points.
pub fn write_joint_vtu(path: &Path, mesh: &Mesh, joint: &Joint) -> Result<(), OutputError> {
    let (m, s) = (&joint.master, &joint.slave);
    let nm = m.nodes.len();
    let np = nm + s.nodes.len();
    let points: Vec<[f64; 3]> = m.points.iter().chain(s.points.iter()).copied().collect();
    let conn: Vec<[u32; 4]> = m
        .faces
        .iter()
        .map(|f| (f, 0u32))
        .chain(s.faces.iter().map(|f| (f, nm as u32)))
        .map(|(f, off)| {
            let mut c = [0u32; 4];
            for (a, &l) in c.iter_mut().zip(f.local_nodes()) {
                *a = l + off;
            }
            c
        })
        .collect();
    let kinds: Vec<CellKind> = m.faces.iter().chain(s.faces.iter()).map(|f| f.kind).collect();
    let grid = Grid { points: &points, cells: conn.iter().zip(&kinds).map(|(c, &k)| (k, &c[..k.n_nodes()])).collect() };

    let mut normal = vec![0.0; 3 * np];
    let mut area = vec![0.0; np];
    let mut o_distance = vec![0.0; np];
    let mut surface_distance = vec![0.0; np];
    let mut layer1 = vec![0i32; np];
    let mut layer2 = vec![0i32; np];
    let mut conforming = vec![0i32; np];
    let mut is_slave = vec![0i32; np];
    let mut o_of = vec![0i32; np];
    let node_tag: Vec<i32> =
        m.nodes.iter().chain(s.nodes.iter()).map(|&k| i32::try_from(mesh.node_tags[k]).unwrap_or(-1)).collect();
    for i in 0..s.nodes.len() {
        let p = nm + i;
        normal[3 * p..3 * p + 3].copy_from_slice(&joint.normals[i]);
        area[p] = joint.areas[i];
        o_distance[p] = joint.nearest_distance[i];
        surface_distance[p] = joint.surface_distance[i];
        layer1[p] = joint.layer1.row_len(i) as i32;
        layer2[p] = joint.layer2.row_len(i) as i32;
        conforming[p] = joint.is_ntn_conforming(i) as i32;
        is_slave[p] = 1;
        o_of[joint.nearest[i] as usize] += 1;
    }
    let cell_slave: Vec<i32> = (0..kinds.len()).map(|c| (c >= m.faces.len()) as i32).collect();
    let cell_tag: Vec<i32> = m
        .faces
        .iter()
        .chain(s.faces.iter())
        .map(|f| i32::try_from(mesh.cells[f.cell].tag).unwrap_or(-1))
        .collect();
    write_vtu(
        path,
        &grid,
        &[
            Field::f64("normal", 3, &normal),
            Field::f64("tributary_area", 1, &area),
            Field::f64("o_distance", 1, &o_distance),
            Field::f64("surface_distance", 1, &surface_distance),
            Field::i32("layer1_count", 1, &layer1),
            Field::i32("layer2_count", 1, &layer2),
            Field::i32("ntn_conforming", 1, &conforming),
            Field::i32("is_slave", 1, &is_slave),
            Field::i32("o_of_count", 1, &o_of),
            Field::i32("node_tag", 1, &node_tag),
        ],
        &[Field::i32("is_slave", 1, &cell_slave), Field::i32("element_tag", 1, &cell_tag)],
    )
}
