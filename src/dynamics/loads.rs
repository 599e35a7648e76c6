//! External loads: gravity, uniform base acceleration (relative form), tractions, nodal forces.
//!
//! Relative form: with the base moving with acceleration a_g(t), the displacements solved for are
//! relative to the base, fixed boundary nodes have relative displacement 0, and every node with
//! inertia carries the effective force −M a_g(t) (inertial mass, added inertia included);
//! gravity acts on the gravitational mass (`model::mass`). Records are already in m/s² ([`super::record`]).

use super::record::Record;
use crate::error::{Error, ModelError};
use crate::mesh::CellKind;
use crate::model::Model;
use crate::scene::Scene;
use nalgebra::Vector3;

/// One component of the base motion: a record times a direction (unit vector × scale).
#[derive(Clone, Debug)]
pub struct BaseMotion {
    pub record: Record,
    /// Direction × scale factor (dimensionless): a_g += dir · record(t).
    pub dir: [f64; 3],
    pub scale: f64,
}

/// The base motions of a scene: each record read, converted to m/s² and scaled as the scene says
/// (`scale`, or `pga` [g] on the record's own peak), with a note per record. Used by the FEM
/// loads and by the rigid-block level alike, so both see the same ground motion.
pub fn base_motions(scene: &Scene) -> Result<(Vec<BaseMotion>, Vec<String>), Error> {
    let mut base = Vec::new();
    let mut notes = Vec::new();
    for b in &scene.loads.base {
        let record = Record::read(&b.record, scene.g)?;
        let d = Vector3::from(b.direction).normalize();
        let scale = match (b.scale, b.pga) {
            (_, Some(pga)) => {
                let peak = record.peak();
                if peak == 0.0 {
                    return Err(ModelError::Invalid(format!("record {} is all zeros: cannot scale it to pga {pga} g", b.record.display())).into());
                }
                pga * scene.g / peak
            }
            (Some(s), None) => s,
            (None, None) => 1.0,
        };
        notes.push(format!(
            "record {}: {} samples, dt {} s, PGA {:.4} g × {:.4} along ({:.3}, {:.3}, {:.3})",
            b.record.display(),
            record.accel.len(),
            record.dt,
            record.peak() / scene.g,
            scale,
            d[0],
            d[1],
            d[2]
        ));
        base.push(BaseMotion { record, dir: [d[0] * scale, d[1] * scale, d[2] * scale], scale });
    }
    Ok((base, notes))
}

/// Ground acceleration a_g(t) [m/s²] of a set of base motions.
pub fn ground_acceleration_of(base: &[BaseMotion], t: f64) -> [f64; 3] {
    let mut a = [0.0; 3];
    for b in base {
        let v = b.record.at(t);
        for i in 0..3 {
            a[i] += b.dir[i] * v;
        }
    }
    a
}

/// A fixed nodal force pattern with a linear ramp [s] (0 = step).
#[derive(Clone, Debug)]
pub struct ForcePattern {
    /// (node, force [N])
    pub forces: Vec<(usize, [f64; 3])>,
    pub ramp: f64,
}

/// All loads of a scene, resolved against the model.
#[derive(Clone, Debug, Default)]
pub struct Loads {
    /// Gravity acceleration vector [m/s²].
    pub gravity: Option<[f64; 3]>,
    /// Nodes that carry weight when gravity is restricted to some groups (None: all nodes).
    pub gravity_nodes: Option<Vec<bool>>,
    pub base: Vec<BaseMotion>,
    pub patterns: Vec<ForcePattern>,
    /// Forces that act with gravity (before the record, ramped in with it during relaxation,
    /// and kept on): the reservoir's hydrostatic pressure [N] per node.
    pub static_forces: Vec<(usize, [f64; 3])>,
}

impl Loads {
    /// Resolve the scene's loads on the model (groups, records, snapping).
    pub fn build(model: &Model, scene: &Scene) -> Result<(Loads, Vec<String>), Error> {
        let mut notes = Vec::new();
        let gravity = scene.loads.gravity.as_ref().map(|g| {
            let d = Vector3::from(g.direction).normalize() * g.g;
            [d[0], d[1], d[2]]
        });
        let mut gravity_nodes = None;
        if let Some(groups) = scene.loads.gravity.as_ref().and_then(|g| g.groups.as_ref()) {
            let mut mask = vec![false; model.n_nodes()];
            for g in groups {
                for n in model.mesh.group_nodes(&model.mesh.group_of_dim(g, 3)?.name)? {
                    mask[n] = true;
                }
            }
            gravity_nodes = Some(mask);
        }
        let (base, base_notes) = base_motions(scene)?;
        notes.extend(base_notes);
        let mut patterns = Vec::new();
        for t in &scene.loads.traction {
            let g = model.mesh.group_of_dim(&t.group, 2)?;
            let mut forces: Vec<(usize, [f64; 3])> = Vec::new();
            for &c in &g.cells {
                let cell = &model.mesh.cells[c];
                let x: Vec<Vector3<f64>> = cell.nodes().iter().map(|&n| model.mesh.x(n as usize)).collect();
                let w = face_node_areas(cell.kind, &x);
                for (a, &n) in cell.nodes().iter().enumerate() {
                    forces.push((n as usize, [t.traction[0] * w[a], t.traction[1] * w[a], t.traction[2] * w[a]]));
                }
            }
            patterns.push(ForcePattern { forces, ramp: t.ramp });
        }
        for nf in &scene.loads.nodal {
            let (node, dist) = model.mesh.nearest_node(nf.point).ok_or_else(|| ModelError::Invalid("empty mesh".into()))?;
            notes.push(format!("nodal force at ({:?}) snapped to node {} at distance {:.3e} m", nf.point, model.mesh.node_tags[node], dist));
            patterns.push(ForcePattern { forces: vec![(node, nf.force)], ramp: nf.ramp });
        }
        let mut static_forces = Vec::new();
        if let Some(r) = scene.reservoir.as_ref().filter(|r| r.hydrostatic) {
            let volume: Vec<usize> = scene.materials.iter().map(|m| model.mesh.group_of_dim(&m.group, 3).map(|g| g.cells.clone())).collect::<Result<Vec<_>, _>>()?.concat();
            let mut faces = Vec::new();
            for g in &r.faces {
                faces.extend(crate::reservoir::wet_faces(&model.mesh, g, &volume)?);
            }
            let spec = crate::model::reservoir_spec(&model.mesh, r, &faces, scene);
            static_forces = crate::reservoir::hydrostatic_forces(&model.mesh, &faces, &spec);
            let total: f64 = static_forces.iter().map(|(_, f)| (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt()).sum();
            notes.push(format!("reservoir: pool level {:.3} m, depth {:.3} m, hydrostatic on {} nodes (Σ|f| {:.4e} N)", spec.level, spec.depth(), static_forces.len(), total));
        }
        Ok((Loads { gravity, gravity_nodes, base, patterns, static_forces }, notes))
    }

    /// Ground acceleration vector a_g(t) [m/s²].
    pub fn ground_acceleration(&self, t: f64) -> [f64; 3] {
        ground_acceleration_of(&self.base, t)
    }

    /// End of the longest record [s] (0 without records).
    pub fn record_end(&self) -> f64 {
        self.base.iter().map(|b| b.record.t_end()).fold(0.0, f64::max)
    }

    /// f = F_ext(t) (overwritten): m (g − a_g(t)) on every node plus the force patterns.
    /// `with_gravity`/`with_dynamic` select the parts (gravity alone during relaxation).
    pub fn external_force_into(&self, model: &Model, t: f64, with_gravity: bool, with_dynamic: bool, f: &mut [f64]) {
        let g = if with_gravity { self.gravity.unwrap_or([0.0; 3]) } else { [0.0; 3] };
        let ag = if with_dynamic { self.ground_acceleration(t) } else { [0.0; 3] };
        let mass = &model.mass;
        let weight = |n: usize| match &self.gravity_nodes {
            Some(mask) if !mask[n] => 0.0,
            _ => 1.0,
        };
        match &mass.gravitational {
            // weight = inertia: one vector, m (w g − a_g)
            None => {
                for (n, &m) in mass.inertial.iter().enumerate() {
                    let w = weight(n);
                    f[3 * n] = m * (w * g[0] - ag[0]);
                    f[3 * n + 1] = m * (w * g[1] - ag[1]);
                    f[3 * n + 2] = m * (w * g[2] - ag[2]);
                }
            }
            // weight and inertia apart: m_g w g − m a_g
            Some(gm) => {
                for (n, (&m, &mg)) in mass.inertial.iter().zip(gm).enumerate() {
                    let w = weight(n);
                    for c in 0..3 {
                        f[3 * n + c] = mg * w * g[c] - m * ag[c];
                    }
                }
            }
        }
        if with_dynamic && ag != [0.0; 3] {
            // the added inertia's base force −A a_g (no weight)
            let agv = Vector3::from(ag);
            for b in &mass.blocks {
                let fb = b.added * agv;
                for c in 0..3 {
                    f[3 * b.node as usize + c] -= fb[c];
                }
            }
        }
        if with_gravity {
            for &(n, fv) in &self.static_forces {
                for i in 0..3 {
                    f[3 * n + i] += fv[i];
                }
            }
        }
        if with_dynamic {
            for p in &self.patterns {
                let s = if p.ramp > 0.0 { (t / p.ramp).clamp(0.0, 1.0) } else { 1.0 };
                for &(n, fv) in &p.forces {
                    for i in 0..3 {
                        f[3 * n + i] += s * fv[i];
                    }
                }
            }
        }
    }
}

/// ∫ N_a dA for each node of a tri3 / quad4 face (2×2 Gauss for quads, exact for bilinear).
pub fn face_node_areas(kind: CellKind, x: &[Vector3<f64>]) -> Vec<f64> {
    match kind {
        CellKind::Tri3 => {
            let a = 0.5 * (x[1] - x[0]).cross(&(x[2] - x[0])).norm();
            vec![a / 3.0; 3]
        }
        CellKind::Quad4 => {
            let gp = 1.0 / 3f64.sqrt();
            let r = crate::mesh::cell::QUAD4_REF;
            let mut w = vec![0.0; 4];
            for &s in &[-gp, gp] {
                for &t in &[-gp, gp] {
                    let mut dxs = Vector3::zeros();
                    let mut dxt = Vector3::zeros();
                    for a in 0..4 {
                        dxs += x[a] * 0.25 * r[a][0] * (1.0 + t * r[a][1]);
                        dxt += x[a] * 0.25 * r[a][1] * (1.0 + s * r[a][0]);
                    }
                    let j = dxs.cross(&dxt).norm();
                    for a in 0..4 {
                        w[a] += j * 0.25 * (1.0 + s * r[a][0]) * (1.0 + t * r[a][1]);
                    }
                }
            }
            w
        }
        _ => vec![0.0; x.len()],
    }
}
