//! The rigid-block level of a study: the scene's own wedge and base records, slid as one rigid
//! body along its line of intersection (Newmark, [`crate::rigid::newmark`]).
//!
//! Shares the record code with the FEM runs: the ground acceleration is that of
//! [`crate::dynamics::loads::base_motions`] of the very scene the FEM run uses (same files,
//! scales, directions, g), sampled at the records' own step. Horizontal components along x and y are combined exactly for one-way
//! sliding: the down-slope rate is linear in (kx, ky, kv), r = r0 + r_x kx + r_y ky + r_v kv.

use crate::dynamics::loads::{ground_acceleration_of, BaseMotion};
use crate::error::{Error, ModelError};
use crate::rigid::newmark::{slide, slide_with_bond_loss, Direction, NewmarkOptions, NewmarkResult};
use crate::rigid::wedge::{wedge_seismic_coeffs, WedgeInput};
use crate::scene::Scene;
use serde::Serialize;

/// How the rigid wedge treats cohesion during shaking.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Bond {
    /// Cohesion kept throughout (perfectly plastic).
    Kept,
    /// Cohesion lost at the first slide (the FEM joints' default, design §5).
    Brittle,
}

/// The rigid wedge's response to a record set.
#[derive(Clone, Debug, Serialize)]
pub struct RigidWedgeRun {
    pub bond: Bond,
    /// Critical horizontal ground acceleration along +y with cohesion [g] and without [g].
    pub kc_intact: Option<f64>,
    pub kc_residual: Option<f64>,
    /// Sample step of the combined ground motion [s] and its number of samples.
    pub dt: f64,
    pub samples: usize,
    pub result: NewmarkResult,
}

/// Ground acceleration of `base` sampled every `dt` over [0, t_end] [m/s², x y z].
pub fn sample_ground_motion(base: &[BaseMotion], dt: f64, t_end: f64) -> Vec<[f64; 3]> {
    let n = (t_end / dt).round() as usize + 1;
    (0..n).map(|i| ground_acceleration_of(base, i as f64 * dt)).collect()
}

/// Slide the rigid wedge `input` under the ground motion `a` (samples every `dt`, m/s²).
pub fn rigid_wedge_slip(input: &WedgeInput, a: &[[f64; 3]], dt: f64, bond: Bond, keep_history: bool) -> Result<RigidWedgeRun, Error> {
    let law = |keep: bool| -> Result<_, Error> {
        let y = wedge_seismic_coeffs(input, 0.0, keep)?;
        let x = wedge_seismic_coeffs(input, 90.0, keep)?;
        Ok((y, x))
    };
    let (yi, xi) = law(true)?;
    let (yr, _) = law(false)?;
    let ry = yi.rh();
    if ry == 0.0 {
        return Err(ModelError::Invalid("rigid wedge: a north-south ground acceleration does not act along the line of intersection (r_y = 0); the rigid level needs it".into()).into());
    }
    // effective horizontal input along y: k_eff = ky + (r_x / r_y) kx, exact for the down law
    // (cohesion enters r0 only, so the ratio is that of both laws). The lift-off check of the
    // normal forces sees k_eff too, which is exact only without an x component.
    let ratio = xi.rh() / ry;
    let a_h: Vec<f64> = a.iter().map(|v| v[1] + ratio * v[0]).collect();
    let a_v: Vec<f64> = a.iter().map(|v| v[2]).collect();
    let mut opts = NewmarkOptions::new(dt);
    if keep_history {
        opts = opts.with_history();
    }
    let intact = yi.sliding_model(Direction::OneWay);
    let residual = yr.sliding_model(Direction::OneWay);
    let result = match bond {
        Bond::Kept => slide(&intact, &a_h, Some(&a_v), &opts)?,
        Bond::Brittle => slide_with_bond_loss(&intact, &residual, &a_h, Some(&a_v), &opts)?,
    };
    Ok(RigidWedgeRun {
        bond,
        kc_intact: yi.critical_horizontal_acceleration(),
        kc_residual: yr.critical_horizontal_acceleration(),
        dt,
        samples: a.len(),
        result,
    })
}


/// The limit-equilibrium wedge of a FEM scene: `base` (geometry: planes, H) with the friction and
/// cohesion of the scene's joints `joint_a` and `joint_b` (μ or φ by the scene's one friction rule,
/// `JointSceneSpec::friction`; c 0 by default), the density of the scene's `wedge_group` material and the scene's g, so that the rigid
/// level always carries the strength the FEM joints carry. A joint or material the scene does
/// not have keeps `base`'s value.
pub fn wedge_input_from_scene(base: &WedgeInput, scene: &Scene, joint_a: &str, joint_b: &str, wedge_group: &str) -> WedgeInput {
    let mut w = base.clone();
    let strength = |name: &str, old: crate::rigid::wedge::JointStrength| {
        scene.joints.iter().find(|j| j.name == name).map_or(old, |j| {
            crate::rigid::wedge::JointStrength { cohesion: j.cohesion.unwrap_or(0.0), friction: j.friction().phi_deg() }
        })
    };
    w.joint_a = strength(joint_a, w.joint_a);
    w.joint_b = strength(joint_b, w.joint_b);
    if let Some(m) = scene.materials.iter().find(|m| m.group == wedge_group) {
        w.density = m.rho;
    }
    w.g = scene.loads.gravity.as_ref().map_or(scene.g, |g| g.g);
    w
}
