//! The reservoir's model in a scene (`reservoir.model`, `reservoir.fluid`; docs/scenes.md,
//! docs/dam_physics.md "Reservoir models"). Serde types and their validation only: the
//! mechanics are in module problem::reservoir.
//!
//! Default: `"westergaard"`, the seed's configuration (Kuo's generalised Westergaard added mass
//! with the depth at the dam), so a scene without these fields behaves exactly as before.

use serde::{Deserialize, Serialize};

/// How the reservoir's hydrodynamic pressure enters the dam's inertia.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ReservoirModel {
    /// m_a = (7/8) ρw √(H (z_w − z)) A along the nodal normal, H the depth at the dam (Kuo 1982).
    /// The default: the seed's configuration.
    #[default]
    Westergaard,
    /// The same with each node's own section depth (the same as `added_mass_depth: "local"`).
    WestergaardLocal,
    /// Potential flow on a meshed water volume (`reservoir.fluid`): the exact incompressible
    /// added-mass operator on the wet face, condensed once. `jointquake modes` uses the full
    /// operator; the explicit run its row-sum lumping along the nodal normals (docs/dam_physics.md).
    FeIncompressible,
}

impl ReservoirModel {
    /// The scene spelling.
    pub fn name(self) -> &'static str {
        match self {
            ReservoirModel::Westergaard => "westergaard",
            ReservoirModel::WestergaardLocal => "westergaard_local",
            ReservoirModel::FeIncompressible => "fe_incompressible",
        }
    }
}

/// The meshed water of `fe_incompressible`: Gmsh physical-group names in the scene's mesh. The
/// water volume is meshed on its own (it need not conform with the dam face) and carries no
/// material: its nodes are not structural unknowns.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct FluidScene {
    /// The water's volume group (dim 3, tet4 and/or hex8), e.g. `"block:water"`.
    pub volume: String,
    /// The water's faces against the dam (dim 2), e.g. `["water:dam"]`: ∂p/∂n = ρw a·n_dam.
    pub wet: Vec<String>,
    /// The free surface (dim 2): p = 0.
    pub free_surface: Vec<String>,
    /// The far end of the water at the length Lw upstream (dim 2): p = 0 there (stated choice:
    /// on a rigid wall the resultant is then tanh(π Lw / 2H) of the semi-infinite one's first
    /// term, −0.02 % at Lw = 3H). Empty: ∂p/∂n = 0 there too (a closed basin).
    #[serde(default)]
    pub far_end: Vec<String>,
}

/// Checks of the reservoir fields this module owns (called from `Scene::validate`).
pub fn validate(model: ReservoirModel, fluid: Option<&FluidScene>, added_mass_depth: super::AddedMassDepth) -> Result<(), String> {
    match (model, fluid) {
        (ReservoirModel::FeIncompressible, None) => {
            return Err("reservoir.model \"fe_incompressible\" needs `reservoir.fluid` (the water's volume, wet, free_surface and far_end groups of the mesh; docs/scenes.md)".into())
        }
        (ReservoirModel::Westergaard | ReservoirModel::WestergaardLocal, Some(_)) => {
            return Err(format!(
                "reservoir.fluid is given but reservoir.model is \"{}\", which does not use a water mesh: set \"model\": \"fe_incompressible\" or remove `fluid`",
                model.name()
            ))
        }
        _ => {}
    }
    if model == ReservoirModel::FeIncompressible && added_mass_depth != super::AddedMassDepth::Reservoir {
        return Err(format!("reservoir.added_mass_depth \"local\" applies to the Westergaard models only; remove it with \"model\": \"fe_incompressible\""));
    }
    if let Some(f) = fluid {
        if f.volume.is_empty() {
            return Err("reservoir.fluid.volume: name the water's volume group (dim 3), e.g. \"block:water\"".into());
        }
        if f.wet.is_empty() {
            return Err("reservoir.fluid.wet: name at least one face group of the water against the dam".into());
        }
        if f.free_surface.is_empty() {
            return Err("reservoir.fluid.free_surface: name the free surface's face group (p = 0 there; without it the pressure is not defined)".into());
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn model_names_parse_and_print_the_same() {
        for m in [ReservoirModel::Westergaard, ReservoirModel::WestergaardLocal, ReservoirModel::FeIncompressible] {
            let parsed: ReservoirModel = serde_json::from_str(&format!("\"{}\"", m.name())).unwrap();
            assert_eq!(parsed, m);
        }
        assert!(serde_json::from_str::<ReservoirModel>("\"acoustic_typo\"").is_err());
    }

    #[test]
    fn fe_model_without_a_water_mesh_is_refused_with_the_fix() {
        let e = validate(ReservoirModel::FeIncompressible, None, super::super::AddedMassDepth::Reservoir).unwrap_err();
        assert!(e.contains("reservoir.fluid"), "{e}");
        let f = FluidScene { volume: "block:water".into(), wet: vec!["water:dam".into()], free_surface: vec![], far_end: vec![] };
        let e = validate(ReservoirModel::FeIncompressible, Some(&f), super::super::AddedMassDepth::Reservoir).unwrap_err();
        assert!(e.contains("free_surface"), "{e}");
        let e = validate(ReservoirModel::Westergaard, Some(&f), super::super::AddedMassDepth::Reservoir).unwrap_err();
        assert!(e.contains("fe_incompressible"), "{e}");
    }
}
