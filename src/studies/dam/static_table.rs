//! The arch dam's static table (docs/dam.md, "Static state"): crest radial displacement at the
//! crown and the quarter points, and the arch and cantilever stresses at the crown on the
//! upstream and downstream faces, from a displacement field of the dam model
//! (geo/arch_dam.geo: groups `face:crest`, `face:upstream`, `face:downstream`,
//! `block:monolith:KK`).
//!
//! Conventions (written once, here): the **radial** direction at a face node is the horizontal
//! part of the upstream face's normal there, oriented downstream (+y): a positive radial
//! displacement moves the crest downstream. At an element on a face, the **arch** direction is
//! the horizontal tangent of the face (z × n_h) and the **cantilever** direction the face's
//! tangent in its vertical plane (n × arch); stresses are tension positive [Pa]. The quarter
//! points are the upstream crest nodes nearest x = ±X_e/2, with X_e the crest's half-span.

use crate::error::{Error, ModelError, OutputError};
use std::path::{Path, PathBuf};
use crate::model::Model;
use nalgebra::{Matrix3, Vector3};
use std::collections::HashSet;

/// One crest point of the table.
#[derive(Clone, Debug, serde::Serialize)]
pub struct CrestPoint {
    pub name: String,
    /// Its coordinates [m] and radial displacement [m] (positive downstream).
    pub x: [f64; 3],
    pub radial: f64,
}

/// Stresses of one face of the crown monolith [Pa]: the most compressive and the most tensile
/// arch and cantilever stress over its elements on that face, and their elevations [m].
#[derive(Clone, Debug, serde::Serialize)]
pub struct FaceStress {
    pub face: String,
    pub arch_min: (f64, f64),
    pub arch_max: (f64, f64),
    pub cantilever_min: (f64, f64),
    pub cantilever_max: (f64, f64),
}

/// The table.
#[derive(Clone, Debug, serde::Serialize)]
pub struct DamStaticTable {
    pub crest: Vec<CrestPoint>,
    /// The crown monolith's group.
    pub crown_monolith: String,
    pub faces: Vec<FaceStress>,
}

fn face_normals(model: &Model, group: &str) -> Result<Vec<(usize, Vector3<f64>)>, Error> {
    let mesh = &model.mesh;
    let g = mesh.group_of_dim(group, 2)?;
    let mut acc: std::collections::BTreeMap<usize, Vector3<f64>> = Default::default();
    for &c in &g.cells {
        let nd = mesh.cells[c].nodes();
        let x: Vec<Vector3<f64>> = nd.iter().map(|&v| mesh.x(v as usize)).collect();
        let k = x.len();
        let n = if k == 4 { (x[2] - x[0]).cross(&(x[3] - x[1])) } else { (x[1] - x[0]).cross(&(x[2] - x[0])) };
        // oriented downstream (+y) whatever the face's own orientation
        let n = if n[1] < 0.0 { -n } else { n };
        for &v in nd {
            *acc.entry(v as usize).or_insert_with(Vector3::zeros) += n;
        }
    }
    Ok(acc.into_iter().map(|(k, v)| (k, v.normalize())).collect())
}

fn horizontal(n: &Vector3<f64>) -> Vector3<f64> {
    Vector3::new(n[0], n[1], 0.0).normalize()
}

/// The `dam-static` command's table: [`static_table`] of `u`, written as
/// `<dir>/static_table.md` and `<dir>/static_table.json` (the directory is created). Returns the
/// table and the Markdown file's path.
pub fn write_static_table(model: &Model, u: &[f64], dir: &Path) -> Result<(DamStaticTable, PathBuf), Error> {
    let t = static_table(model, u)?;
    std::fs::create_dir_all(dir).map_err(|e| OutputError::write(dir, e))?;
    let md = dir.join("static_table.md");
    std::fs::write(&md, t.to_markdown()).map_err(|e| OutputError::write(&md, e))?;
    let js = dir.join("static_table.json");
    std::fs::write(&js, serde_json::to_string_pretty(&t).expect("the static table serialises")).map_err(|e| OutputError::write(&js, e))?;
    Ok((t, md))
}

/// The table of displacement field `u` (3 per node) of the dam model.
pub fn static_table(model: &Model, u: &[f64]) -> Result<DamStaticTable, Error> {
    let mesh = &model.mesh;
    let up = face_normals(model, "face:upstream")?;
    let up_map: std::collections::HashMap<usize, Vector3<f64>> = up.iter().cloned().collect();
    let crest: HashSet<usize> = mesh.group_nodes("face:crest")?.into_iter().collect();
    let edge: Vec<usize> = up.iter().map(|(n, _)| *n).filter(|n| crest.contains(n)).collect();
    if edge.is_empty() {
        return Err(ModelError::Invalid("dam table: no node on both face:crest and face:upstream".into()).into());
    }
    let xe = edge.iter().map(|&n| mesh.nodes[n][0].abs()).fold(0.0, f64::max);
    let nearest = |x: f64| *edge.iter().min_by(|&&a, &&b| (mesh.nodes[a][0] - x).abs().total_cmp(&(mesh.nodes[b][0] - x).abs())).unwrap();
    let mut points = Vec::new();
    for (name, x) in [("left quarter", -0.5 * xe), ("crown", 0.0), ("right quarter", 0.5 * xe)] {
        let n = nearest(x);
        let r = horizontal(&up_map[&n]);
        let d = Vector3::new(u[3 * n], u[3 * n + 1], u[3 * n + 2]);
        points.push(CrestPoint { name: name.into(), x: mesh.nodes[n], radial: d.dot(&r) });
    }
    // the crown monolith: the volume group holding the crown crest node
    let crown = nearest(0.0);
    let block = mesh
        .groups
        .iter()
        .filter(|g| g.dim == 3 && g.name.starts_with("block:monolith:"))
        .find(|g| g.cells.iter().any(|&c| mesh.cells[c].nodes().contains(&(crown as u32))))
        .ok_or_else(|| ModelError::Invalid("dam table: the crown node is in no block:monolith:KK group".into()))?;
    let mut stress = Vec::new();
    model.element_stress_into(u, &mut stress);
    let mut element_of_cell = std::collections::HashMap::new();
    for (e, &c) in model.tets.cell.iter().enumerate() {
        element_of_cell.insert(c as usize, e);
    }
    let nt = model.tets.cell.len();
    for (e, &c) in model.hexes.cell.iter().enumerate() {
        element_of_cell.insert(c as usize, nt + e);
    }
    let mut faces = Vec::new();
    for face in ["face:upstream", "face:downstream"] {
        let normals: std::collections::HashMap<usize, Vector3<f64>> = face_normals(model, face)?.into_iter().collect();
        let (mut amin, mut amax, mut cmin, mut cmax) = ((f64::MAX, 0.0), (f64::MIN, 0.0), (f64::MAX, 0.0), (f64::MIN, 0.0));
        for &c in &block.cells {
            let nd = mesh.cells[c].nodes();
            let on: Vec<usize> = nd.iter().map(|&v| v as usize).filter(|v| normals.contains_key(v)).collect();
            if on.len() < 3 {
                continue;
            }
            let n = on.iter().map(|v| normals[v]).sum::<Vector3<f64>>().normalize();
            let arch = Vector3::z().cross(&horizontal(&n)).normalize();
            let cant = n.cross(&arch).normalize();
            let Some(&e) = element_of_cell.get(&c) else { continue };
            let s = stress[e];
            let m = Matrix3::new(s[0], s[3], s[5], s[3], s[1], s[4], s[5], s[4], s[2]);
            let (sa, sc) = (arch.dot(&(m * arch)), cant.dot(&(m * cant)));
            let z = on.iter().map(|&v| mesh.nodes[v][2]).sum::<f64>() / on.len() as f64;
            if sa < amin.0 {
                amin = (sa, z);
            }
            if sa > amax.0 {
                amax = (sa, z);
            }
            if sc < cmin.0 {
                cmin = (sc, z);
            }
            if sc > cmax.0 {
                cmax = (sc, z);
            }
        }
        faces.push(FaceStress { face: face.into(), arch_min: amin, arch_max: amax, cantilever_min: cmin, cantilever_max: cmax });
    }
    Ok(DamStaticTable { crest: points, crown_monolith: block.name.clone(), faces })
}

impl DamStaticTable {
    /// The table as Markdown.
    pub fn to_markdown(&self) -> String {
        use std::fmt::Write as _;
        let mut s = String::new();
        let _ = writeln!(s, "| crest point | x [m] | y [m] | radial displacement [mm] (+ downstream) |\n|---|---|---|---|");
        for p in &self.crest {
            let _ = writeln!(s, "| {} | {:.1} | {:.1} | {:.2} |", p.name, p.x[0], p.x[1], 1e3 * p.radial);
        }
        let _ = writeln!(s, "\nCrown monolith `{}` (tension positive; elevation of the element in brackets):\n", self.crown_monolith);
        let _ = writeln!(s, "| face | arch min [MPa] | arch max [MPa] | cantilever min [MPa] | cantilever max [MPa] |\n|---|---|---|---|---|");
        for f in &self.faces {
            let _ = writeln!(
                s,
                "| {} | {:.2} ({:.0} m) | {:.2} ({:.0} m) | {:.2} ({:.0} m) | {:.2} ({:.0} m) |",
                f.face, 1e-6 * f.arch_min.0, f.arch_min.1, 1e-6 * f.arch_max.0, f.arch_max.1, 1e-6 * f.cantilever_min.0, f.cantilever_min.1, 1e-6 * f.cantilever_max.0, f.cantilever_max.1
            );
        }
        s
    }
}
