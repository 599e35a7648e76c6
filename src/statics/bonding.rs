//! Joints bonded as exact linear constraints (master–slave elimination) for the linear
//! analyses: the modes with the joints bonded (`modes`) and the linear stages of a static
//! construction sequence (`construction`).
//!
//! Constraint (written once, here): every slave node s of a bonded joint moves with its master
//! point, u_s = Σ_I N_I u_I, with N_I the shape functions of the master face hit by the line
//! from X_s along the slave normal on the **initial** configuration (the tagger's surfaces and
//! candidate faces; `contact::query::select_projection`). The same weights act on x, y and z.
//! A joint with `method: "mortar"` is tied by its dual mortar condition instead, D u_s = M u_m
//! over the overlaps of its faces on the initial configuration: D is diagonal (dual shape
//! functions), so each slave node's row is u_s = Σ_k c_k u_k with c_k = M_sk / D_ss, the
//! node's mortar master point (`ContactSolver::mortar_master_points`, docs/contact.md "Dual
//! mortar"; the weights sum to one). It passes the patch test on non-matching meshes (a
//! uniform stress is transmitted exactly), which the node-to-segment tie does not. A slave node
//! below the mortar cover (near the master's free edge) is tied by the projection rule below.
//! The eliminated unknowns give the transformation u = T û; a matrix A of the model becomes
//! Â = Tᵀ A T and a load F becomes Tᵀ F (exact: no penalty, the frequencies and the static
//! state are those of the constrained model).
//!
//! Choices, in order of use:
//! - projection: inside test with the joint's `edge_tolerance` on Layer2 of the slave node;
//!   failing that with a tolerance of half a face (a node on a curved edge cut into chords lies
//!   just outside the other side's chord: docs/dam.md, "Joint sides coincide"); failing that
//!   the nearest master node O (weight 1). The counts are reported ([`TieInfo`]).
//! - a node that is the slave of two joints keeps the first constraint: tied joints are taken
//!   first (the dam–rock base before the contraction joints), then the others in scene order.
//! - a master node that is itself a slave is replaced by its own masters (chains resolve
//!   recursively; a cycle is an error naming the joint).
//! - a fixed master component contributes nothing (it is 0); a fixed slave component stays
//!   fixed.

use crate::contact::force::ContactSolver;
use crate::contact::joint::{ContactJoint, Method};
use crate::contact::query::select_projection;
use crate::contact::ContactState;
use crate::error::ModelError;
use crate::linalg::{Csc, NONE};
use crate::model::Model;
use nalgebra::Vector3;

/// How the slave nodes of the bonded joints were tied.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct TieInfo {
    /// Joints bonded.
    pub joints: usize,
    /// Slave nodes tied (each once).
    pub tied: usize,
    /// Of those, projected with the joint's edge tolerance / with half a face / tied to O.
    pub projected: usize,
    pub widened: usize,
    pub nearest_node: usize,
    /// Slave nodes already tied by an earlier joint (their second constraint is dropped).
    pub already_tied: usize,
    /// Slave nodes of mortar joints tied by their mortar master point (not counted in
    /// `projected`, `widened`, `nearest_node`, which count the node-to-segment ties, a mortar
    /// node below the cover among them).
    pub mortar: usize,
}

/// The transformation u = T û of a model with bonded joints, on its free dofs.
#[derive(Clone, Debug)]
pub struct Bonding {
    /// Model dofs (3 × nodes).
    pub n_dofs: usize,
    /// Reduced unknowns.
    pub n: usize,
    /// Per model dof: its reduced index (`NONE`: fixed, inactive or a slave).
    pub map: Vec<usize>,
    /// Per model dof: the row of T, (reduced index, weight); empty for a fixed dof.
    pub rows: Vec<Vec<(usize, f64)>>,
    pub info: TieInfo,
}

/// How a slave node found its master point ([`master_point`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MasterHit {
    /// On a Layer2 face within the joint's `edge_tolerance`.
    Projected,
    /// On a Layer2 face within half a face.
    Widened,
    /// No face: the nearest master node O (weight 1).
    NearestNode,
}

/// The master point of slave node `i` of joint `j` on the initial configuration, as the
/// model nodes of its face and their weights N_I (the rule of this module's header: the
/// joint's edge tolerance, then half a face, then O).
pub fn master_point(model: &Model, j: &ContactJoint, i: usize) -> Result<(Vec<(usize, f64)>, MasterHit), ModelError> {
    let m = &j.tag.master;
    let s = j.tag.slave_nodes()[i];
    let xs = Vector3::from(model.mesh.nodes[s]);
    let n = j.frames[i][0];
    let faces: Vec<(usize, Vec<Vector3<f64>>)> = j
        .tag
        .layer2
        .row(i)
        .iter()
        .map(|&f| {
            let (x, k) = m.face_points(f as usize);
            (f as usize, x[..k].iter().map(|p| Vector3::from(*p)).collect())
        })
        .collect();
    let project = |tol: f64| -> Result<Option<(usize, crate::contact::query::Projection)>, ModelError> {
        select_projection(&xs, &n, faces.iter().map(|(f, x)| (*f, x.as_slice())), tol)
            .map_err(|e| ModelError::Invalid(format!("joint \"{}\", slave node {}: {e}", j.tag.name, model.mesh.node_tags[s])))
    };
    let on_face = |f: usize, p: crate::contact::query::Projection| m.faces[f].nodes().iter().zip(p.weights).map(|(&nd, w)| (nd as usize, w)).collect();
    Ok(if let Some((f, p)) = project(j.edge_tolerance)? {
        (on_face(f, p), MasterHit::Projected)
    } else if let Some((f, p)) = project(0.5)? {
        (on_face(f, p), MasterHit::Widened)
    } else {
        (vec![(j.tag.nearest_master_node(i), 1.0)], MasterHit::NearestNode)
    })
}

/// Per slave node of the mortar joint `j`, its mortar master point on the initial
/// configuration: model nodes and weights c_k = M_jk / D_jj (module header); `None` below the
/// mortar cover. The contact solver is scratch for this joint's integrals (one per joint: the
/// joints bonded here are not one slice of the problem's).
fn mortar_ties(model: &Model, j: &ContactJoint) -> Result<Vec<Option<Vec<(usize, f64)>>>, ModelError> {
    let one = std::slice::from_ref(j);
    let state = ContactState::new(one);
    let zero = vec![0.0; 3 * model.n_nodes()];
    let points = ContactSolver::new(model, one).mortar_master_points(model, 0, &state.joints[0], &zero).map_err(|e| ModelError::Invalid(format!("bonding joint \"{}\": {e}", j.tag.name)))?;
    Ok(points.into_iter().map(|p| p.map(|(masters, _)| masters)).collect())
}

/// Per slave node its masters (model nodes) and weights, for the joints `bonded`.
fn tie_nodes(model: &Model, joints: &[&ContactJoint]) -> Result<(Vec<Option<Vec<(usize, f64)>>>, TieInfo), ModelError> {
    let mut ties: Vec<Option<Vec<(usize, f64)>>> = vec![None; model.n_nodes()];
    let mut info = TieInfo { joints: joints.len(), ..Default::default() };
    let mut order: Vec<&&ContactJoint> = joints.iter().filter(|j| j.law.tied).collect();
    order.extend(joints.iter().filter(|j| !j.law.tied));
    for j in order {
        let mut mortar = if j.method == Method::Mortar { mortar_ties(model, j)? } else { Vec::new() };
        for (i, &s) in j.tag.slave_nodes().iter().enumerate() {
            if ties[s].is_some() {
                info.already_tied += 1;
                continue;
            }
            if let Some(masters) = mortar.get_mut(i).and_then(Option::take) {
                ties[s] = Some(masters);
                info.mortar += 1;
                info.tied += 1;
                continue;
            }
            let (masters, hit) = master_point(model, j, i)?;
            match hit {
                MasterHit::Projected => info.projected += 1,
                MasterHit::Widened => info.widened += 1,
                MasterHit::NearestNode => info.nearest_node += 1,
            }
            ties[s] = Some(masters);
            info.tied += 1;
        }
    }
    Ok((ties, info))
}

impl Bonding {
    /// T for `model` with the joints `bonded` tied, on the dofs for which `active(dof)` holds
    /// (free dofs of nodes with stiffness; the others are 0).
    pub fn build(model: &Model, bonded: &[&ContactJoint], active: impl Fn(usize) -> bool) -> Result<Bonding, ModelError> {
        let n_dofs = 3 * model.n_nodes();
        let (ties, info) = tie_nodes(model, bonded)?;
        let mut map = vec![NONE; n_dofs];
        let mut n = 0;
        for d in 0..n_dofs {
            if active(d) && ties[d / 3].is_none() {
                map[d] = n;
                n += 1;
            }
        }
        // rows of T: a kept dof is itself; a slave dof Σ N_I (row of master dof), recursively
        let mut rows: Vec<Option<Vec<(usize, f64)>>> = (0..n_dofs).map(|d| if map[d] != NONE { Some(vec![(map[d], 1.0)]) } else if !active(d) { Some(Vec::new()) } else { None }).collect();
        fn resolve(d: usize, depth: usize, ties: &[Option<Vec<(usize, f64)>>], rows: &mut [Option<Vec<(usize, f64)>>]) -> Result<(), usize> {
            if rows[d].is_some() {
                return Ok(());
            }
            if depth > 16 {
                return Err(d);
            }
            let c = d % 3;
            let mut acc: Vec<(usize, f64)> = Vec::new();
            for &(m, w) in ties[d / 3].as_ref().expect("an unresolved active dof is a slave dof") {
                let md = 3 * m + c;
                resolve(md, depth + 1, ties, rows)?;
                for &(r, v) in rows[md].as_ref().unwrap() {
                    match acc.iter_mut().find(|e| e.0 == r) {
                        Some(e) => e.1 += w * v,
                        None => acc.push((r, w * v)),
                    }
                }
            }
            acc.retain(|e| e.1 != 0.0);
            rows[d] = Some(acc);
            Ok(())
        }
        for d in 0..n_dofs {
            resolve(d, 0, &ties, &mut rows).map_err(|e| {
                ModelError::Invalid(format!("bonding the joints: the constraints of node {} form a cycle (a slave whose master point depends on itself); bond fewer joints or check the joint pairs", model.mesh.node_tags[e / 3]))
            })?;
        }
        let rows = rows.into_iter().map(|r| r.unwrap()).collect();
        Ok(Bonding { n_dofs, n, map, rows, info })
    }

    /// Â = Tᵀ A T for a matrix A over every model dof (both triangles stored).
    pub fn reduce(&self, a: &Csc) -> Csc {
        let mut cols: Vec<Vec<(usize, f64)>> = vec![Vec::new(); self.n];
        for j in 0..a.n_cols {
            let tj = &self.rows[j];
            if tj.is_empty() {
                continue;
            }
            for p in a.col_ptr[j]..a.col_ptr[j + 1] {
                let v = a.val[p];
                if v == 0.0 {
                    continue;
                }
                let ti = &self.rows[a.row[p]];
                for &(s, wj) in tj {
                    for &(r, wi) in ti {
                        cols[s].push((r, wi * wj * v));
                    }
                }
            }
        }
        crate::linalg::from_columns(self.n, cols)
    }

    /// Tᵀ f for a vector over every model dof.
    pub fn reduce_vector(&self, f: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.n];
        for (d, r) in self.rows.iter().enumerate() {
            for &(k, w) in r {
                out[k] += w * f[d];
            }
        }
        out
    }

    /// u = T û over every model dof (0 at fixed dofs).
    pub fn expand_into(&self, uh: &[f64], u: &mut [f64]) {
        for (d, r) in self.rows.iter().enumerate() {
            u[d] = r.iter().map(|&(k, w)| w * uh[k]).sum();
        }
    }
}
