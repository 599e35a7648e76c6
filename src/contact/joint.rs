//! A joint ready for contact mechanics: the tagged interface, its law, method and options.
//! The joints are their own stage ([`build_joints`]): tagged once from the mesh, never
//! re-tagged; a strength-reduction trial changes only their laws ([`ContactJoint::law`]).

use super::law::{JointLaw, OPEN_TOLERANCE_RELATIVE};
use crate::error::{Error, ModelError};
use crate::interface::{tag_joint_in, Joint, JointSpec};
use crate::mesh::topology::Blocks;
use crate::mesh::Mesh;
use crate::scene::{ContactMethod, JointSceneSpec, OnExitSpec, ReentrySpec, Scene};
use nalgebra::Vector3;

pub use super::query::tangent_frame;

/// How pairs are formed and forced.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub enum Method {
    /// Node-to-segment: inside-outside search along the slave normal, dynamic contact force.
    Nts,
    /// Node-to-node: each slave node paired with its initial nearest master node O (N = [1]).
    Ntn,
    /// Dual mortar (segment-to-segment): each slave node's pair has as master the combination
    /// `Σ_k (M_jk / D_jj) x_k` of the master nodes its dual shape function overlaps
    /// (`contact::mortar`; the force, the law and the Gauss–Seidel as NTS).
    Mortar,
    /// Node-to-segment geometry with penalty springs instead of the dynamic contact force:
    /// normal `kn` and tangential `kt` stiffness per unit area [Pa/m].
    Penalty { kn: f64, kt: f64 },
}

/// What to do when a slave node's projection leaves its candidate set.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub enum OnExit {
    /// Layer2 around the current centre, then a fresh nearest-master-node search from the
    /// current relative position (the centre then follows the node).
    Widen,
    /// Count and report the node; it carries no force that step.
    Report,
}

/// One joint of the model.
#[derive(Clone, Debug)]
pub struct ContactJoint {
    pub tag: Joint,
    pub law: JointLaw,
    pub method: Method,
    /// Candidate layer used first: 1 or 2.
    pub layer: u8,
    pub on_exit: OnExit,
    /// Inside-test tolerance, fraction of the face size (see the scene field `edge_tolerance`).
    pub edge_tolerance: f64,
    /// Hold a re-entering node's penetration as closed instead of pushing it out (the scene
    /// field `reentry`: "hold" true, "push" false).
    pub hold_reentry: bool,
    /// Local frame (n, t1, t2) per slave node; n is the tagger's slave normal.
    pub frames: Vec<[Vector3<f64>; 3]>,
}

impl ContactJoint {
    /// Tag a scene joint on the mesh (whose blocks are `blocks`) and resolve its law and options
    /// (an `asperity_angle` i becomes the law's `asperity_friction` tan(φ + i)).
    pub fn build(mesh: &Mesh, blocks: &Blocks, spec: &JointSceneSpec, model_size: f64) -> Result<ContactJoint, Error> {
        let bad = |m: String| -> Error { ModelError::Invalid(format!("joint \"{}\": {m}", spec.name)).into() };
        let mu = spec.friction().mu();
        let mut law = JointLaw {
            mu,
            cohesion: spec.cohesion.unwrap_or(0.0),
            tensile_strength: spec.tensile_strength.unwrap_or(0.0),
            keep_cohesion: spec.keep_cohesion.unwrap_or(false),
            tied: spec.tied.unwrap_or(false),
            open_tolerance: 0.0,
            softening_slip: spec.softening_slip.unwrap_or(0.0),
            asperity_friction: spec.asperity_friction(),
        };
        law.validate().map_err(|e| bad(e.to_string()))?;
        let method = match spec.method() {
            ContactMethod::Nts => Method::Nts,
            ContactMethod::Ntn => Method::Ntn,
            ContactMethod::Mortar => Method::Mortar,
            ContactMethod::Penalty => {
                let kn = spec.penalty_stiffness.ok_or_else(|| bad("method \"penalty\" needs `penalty_stiffness` [Pa/m]".into()))?;
                if !(kn > 0.0 && kn.is_finite()) {
                    return Err(bad(format!("penalty_stiffness = {kn} must be positive [Pa/m]")));
                }
                Method::Penalty { kn, kt: kn }
            }
        };
        let layer = spec.layer.unwrap_or(1);
        if layer != 1 && layer != 2 {
            return Err(bad(format!("layer = {layer} must be 1 or 2")));
        }
        let on_exit = match spec.on_exit.unwrap_or(OnExitSpec::Widen) {
            OnExitSpec::Widen => OnExit::Widen,
            OnExitSpec::Report => OnExit::Report,
        };
        let edge_tolerance = spec.edge_tolerance.unwrap_or(1e-3);
        if !(edge_tolerance > 0.0 && edge_tolerance < 0.5) {
            return Err(bad(format!("edge_tolerance = {edge_tolerance} must be in (0, 0.5) (fraction of the face size)")));
        }
        let (tol, _) = joint_tolerance(spec.tolerance, model_size);
        let js = JointSpec { name: spec.name.clone(), master: spec.master.clone(), slave: spec.slave.clone(), auto: spec.auto };
        let tag = tag_joint_in(mesh, blocks, &js, tol)?;
        // a pair "opens" (and loses its bond) only beyond the round-off of its gap
        let coord = tag.slave.nodes.iter().chain(&tag.master.nodes).flat_map(|&n| mesh.nodes[n]).fold(0.0f64, |m, x| m.max(x.abs()));
        law.open_tolerance = OPEN_TOLERANCE_RELATIVE * (coord + tag.size);
        let frames = tag
            .normals
            .iter()
            .map(|n| {
                let n = Vector3::from(*n);
                let (t1, t2) = tangent_frame(&n);
                [n, t1, t2]
            })
            .collect();
        let hold_reentry = spec.reentry == Some(ReentrySpec::Hold);
        Ok(ContactJoint { tag, law, method, layer, on_exit, edge_tolerance, hold_reentry, frames })
    }
}

/// Per joint (scene order) and slave node (the tag's order): whether its pair is **not
/// formed**.
///
/// The rule, written once here: **a node that is the slave of a tied joint is the slave of no
/// other joint**; a pair of another joint on it is not formed (the dynamic contact force,
/// `force::ContactSolver`, and the static contact of the construction sequence,
/// `static_contact`; the linear analyses, `bonded`, eliminate the ties exactly and need no
/// rule). A node that is the slave of several tied joints keeps the tie of the **last** of
/// them in scene order (the dam scenes list the contraction joints first and the dam–rock base
/// last, so a monolithic dam's base nodes stay tied to the rock, whose reactions the reports
/// read). Why: the tie already fixes the node's motion, so a second constraint on it is
/// redundant — at a contraction joint's bottom edge, where the two monoliths meet the tied
/// base, nearly so: the slave's master point lies on the bottom edge of a master face whose
/// bottom nodes are tied too, so the pair holds the face's upper nodes through weights near 0.
/// Such pairs fought the ties: the coarse dam's NTN joints (slave and O both on the base) grew a
/// motion from rest, ×1.8 a step, until the energy check stopped them at step 70 (regression
/// `dam_ntn_static_state_stays_at_rest`); the NTS pairs on the bottom edge made the
/// Gauss–Seidel sweeps crawl (about 0.5 % a sweep: the dam study's NTS runs hit the 200-sweep
/// cap in 2 steps out of 3; 5 sweeps a step without them, regression
/// `dam_gauss_seidel_converges_without_the_pairs_on_tied_nodes`), and the monolithic dam's
/// tied contraction joints on the tied base did the same until its 3× runs lost their energy
/// balance (regression `monolithic_dam_ties_each_base_node_once`).
pub fn unformed_pairs(joints: &[ContactJoint]) -> Vec<Vec<bool>> {
    // per node, the last tied joint (scene order) it is a slave of
    let mut last_tie: std::collections::HashMap<usize, usize> = std::collections::HashMap::new();
    for (ji, j) in joints.iter().enumerate().filter(|(_, j)| j.law.tied) {
        for &s in j.tag.slave_nodes() {
            last_tie.insert(s, ji);
        }
    }
    joints.iter().enumerate().map(|(ji, j)| j.tag.slave_nodes().iter().map(|s| last_tie.get(s).is_some_and(|&t| t != ji)).collect()).collect()
}

/// Default joint tolerance as a fraction of the mesh bounding-box diagonal, used when a joint
/// gives no `tolerance`. 1e-6: far above the round-off of coordinates written by Gmsh (≈1e-16
/// relative) and far below any gap a real model would want closed silently.
pub const DEFAULT_JOINT_TOLERANCE_RELATIVE: f64 = 1e-6;

/// The tagging tolerance of a joint [m], the one rule (the run's joints and `jointquake tag`):
/// the joint's `tolerance` when the scene gives it, else [`DEFAULT_JOINT_TOLERANCE_RELATIVE`] ×
/// `model_size` (the mesh's bounding-box diagonal [m]); with where it came from, "scene" or
/// "default".
pub fn joint_tolerance(tolerance: Option<f64>, model_size: f64) -> (f64, &'static str) {
    match tolerance {
        Some(t) => (t, "scene"),
        None => (DEFAULT_JOINT_TOLERANCE_RELATIVE * model_size, "default"),
    }
}

/// The joints stage: tag every joint of the scene on the mesh (once, on the initial
/// configuration) and resolve its law and options, in scene order. The tagging tolerance:
/// [`joint_tolerance`].
pub fn build_joints(mesh: &Mesh, scene: &Scene) -> Result<Vec<ContactJoint>, Error> {
    let size = mesh.diagonal();
    if scene.joints.is_empty() {
        return Ok(Vec::new());
    }
    let blocks = Blocks::of(mesh);
    scene.joints.iter().map(|js| ContactJoint::build(mesh, &blocks, js, size)).collect()
}
