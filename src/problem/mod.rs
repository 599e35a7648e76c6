//! A problem: everything a run needs that does not change while it runs.
//!
//! `Scene + Mesh → Problem { scene, model, joints, loads }`, built once: the [`Model`] (elements,
//! masses, supports), the joints as their own stage ([`build_joints`]: tagged once from the
//! mesh; a strength-reduction trial changes only their laws), and the [`Loads`]. A
//! `simulation::Simulation` borrows it.
//!
//! Where the dam's stages go: the reservoir's added mass is added to `model` here
//! (`Model::add_inertia`), the massless foundation becomes one more constraint of the run.

pub mod foundation;
pub mod reservoir;

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
    /// What the build accepted but a user should look at (a pool level far above the wet
    /// faces): copied into the run summary's warnings.
    pub warnings: Vec<String>,
    /// The radiating foundation's far boundary (`None` for the other foundation models).
    pub far_boundary: Option<foundation::radiating::FarBoundary>,
    /// The acoustic water of `reservoir.model: "acoustic"` (`None` for the other models).
    pub water: Option<reservoir::acoustic::AcousticWater>,
}

impl Problem {
    /// Build the model, the joints and the loads of `scene` on `mesh`.
    pub fn build(scene: Scene, mesh: Mesh) -> Result<Problem, Error> {
        let scene = foundation::massed::scene_for_model(scene);
        let mut model = Model::build(mesh, &scene)?;
        let mut notes = Vec::new();
        if let Some(r) = scene.reservoir.as_ref().filter(|r| r.added_mass) {
            notes.push(add_reservoir_mass(&mut model, &scene, r)?);
        }
        let mut p = Problem::from_model(scene, model)?;
        p.notes.extend(notes);
        Ok(p)
    }

    /// The joints and loads of `scene` on a built model.
    pub fn from_model(scene: Scene, model: Model) -> Result<Problem, Error> {
        let joints = build_joints(&model.mesh, &scene)?;
        let (mut loads, mut notes) = Loads::build(&model, &scene)?;
        let mut warnings = Vec::new();
        if let Some(r) = scene.reservoir.as_ref().filter(|r| r.hydrostatic || r.added_mass) {
            let (faces, spec) = reservoir::wet_faces_of_scene(&model.mesh, &scene, r)?;
            warnings.extend(reservoir::pool_level_warning(&model.mesh, &faces, &spec));
            if r.hydrostatic {
                loads.static_forces = reservoir::hydrostatic_forces(&model.mesh, &faces, &spec);
                let total: f64 = loads.static_forces.iter().map(|(_, f)| (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt()).sum();
                notes.push(format!("reservoir: pool level {:.3} m, depth {:.3} m, hydrostatic on {} nodes (Σ|f| {:.4e} N)", spec.level, spec.depth(), loads.static_forces.len(), total));
            }
        }
        let far_boundary = foundation::massed::prepare_loads(&scene, &model, &mut loads, &mut notes)?;
        let water = reservoir::acoustic_water_of_scene(&model.mesh, &scene)?;
        Ok(Problem { scene, model, joints, loads, notes, warnings, far_boundary, water })
    }
}

/// Add the reservoir's Westergaard/Kuo added mass m_a n nᵀ (`crate::problem::reservoir`) to the inertia
/// of the wet nodes (no weight); a note with the total.
pub fn add_reservoir_mass(model: &mut Model, scene: &Scene, r: &crate::scene::ReservoirScene) -> Result<String, Error> {
    let (faces, spec) = reservoir::wet_faces_of_scene(&model.mesh, scene, r)?;
    let (added, which) = reservoir::added_masses_of_scene(&model.mesh, r, &faces, &spec)?;
    let mut total = 0.0;
    for a in &added {
        if model.mass.inertial[a.node] == 0.0 {
            return Err(ModelError::Invalid(format!(
                "reservoir: wet node {} has no structural mass (is the wet face on a massless block?): the added mass goes on the dam's face",
                model.mesh.node_tags[a.node]
            ))
            .into());
        }
        let n = nalgebra::Vector3::from(a.normal);
        model.add_inertia(a.node, n * n.transpose() * a.mass);
        total += a.mass;
    }
    Ok(format!("reservoir: added mass {:.4e} kg on {} wet nodes (depth {:.3} m, {which})", total, added.len(), spec.depth()))
}
