//! A problem: everything a run needs that does not change while it runs.
//!
//! `Scene + Mesh → Problem { scene, model, joints, loads }`, built once: the [`Model`] (elements,
//! masses, supports), the joints as their own stage ([`build_joints`]: tagged once from the
//! mesh; a strength-reduction trial changes only their laws), and the [`Loads`]. A
//! `simulation::Simulation` borrows it.
//!
//! Where the dam's stages go: the reservoir's added mass is added to `model` here
//! (`Model::add_inertia`), the massless foundation becomes one more constraint of the run.

use crate::contact::joint::{build_joints, ContactJoint};
use crate::dynamics::loads::Loads;
use crate::error::{Error, ModelError};
use crate::mesh::Mesh;
use crate::model::Model;
use crate::scene::Scene;

/// The immutable input of a run.
#[derive(Debug)]
pub struct Problem {
    pub scene: Scene,
    pub model: Model,
    /// The joints in scene order (empty: no contact).
    pub joints: Vec<ContactJoint>,
    pub loads: Loads,
    /// Notes of the build (records read and scaled, snapped loads).
    pub notes: Vec<String>,
}

impl Problem {
    /// Build the model, the joints and the loads of `scene` on `mesh`.
    pub fn build(scene: Scene, mesh: Mesh) -> Result<Problem, Error> {
        for ms in &scene.materials {
            if ms.rho == 0.0 {
                return Err(ModelError::Invalid(format!(
                    "material \"{}\": rho = 0 (massless foundation) needs static condensation, which this version does not provide; give the foundation a density",
                    ms.group
                ))
                .into());
            }
        }
        let model = Model::build(mesh, &scene)?;
        Problem::from_model(scene, model)
    }

    /// The joints and loads of `scene` on a built model.
    pub fn from_model(scene: Scene, model: Model) -> Result<Problem, Error> {
        let joints = build_joints(&model.mesh, &scene)?;
        let (loads, notes) = Loads::build(&model, &scene)?;
        Ok(Problem { scene, model, joints, loads, notes })
    }
}
