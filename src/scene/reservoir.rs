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
    /// Compressible water on the meshed volume (`reservoir.fluid`), advanced explicitly with the
    /// dam (module problem::reservoir::acoustic): the dynamic pressure, coupled both ways
    /// through the wet face; the hydrostatic part stays the `hydrostatic` load. Explicit runs
    /// only (`jointquake modes` refuses it: compressible water has no frequency-independent
    /// added mass).
    Acoustic,
}

impl ReservoirModel {
    /// The scene spelling.
    pub fn name(self) -> &'static str {
        match self {
            ReservoirModel::Westergaard => "westergaard",
            ReservoirModel::WestergaardLocal => "westergaard_local",
            ReservoirModel::FeIncompressible => "fe_incompressible",
            ReservoirModel::Acoustic => "acoustic",
        }
    }

    /// Whether the model needs the meshed water (`reservoir.fluid`).
    pub fn meshed(self) -> bool {
        matches!(self, ReservoirModel::FeIncompressible | ReservoirModel::Acoustic)
    }
}

/// The meshed water of `fe_incompressible` and `acoustic`: Gmsh physical-group names in the scene's mesh. The
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
    /// The far end of the water at the length Lw upstream (dim 2). `fe_incompressible`: p = 0
    /// there (stated choice: on a rigid wall the resultant is then tanh(π Lw / 2H) of the
    /// semi-infinite one's first term, −0.02 % at Lw = 3H). `acoustic`: the Sommerfeld
    /// (plane-wave radiation) condition ∂p/∂t = −c ∂p/∂n. Empty: ∂p/∂n = 0 there too (a closed
    /// basin).
    #[serde(default)]
    pub far_end: Vec<String>,
    /// `acoustic` only: the reservoir bottom and banks that absorb (dim 2), e.g.
    /// `["water:bed"]`, with the wave-reflection coefficient `reflection`. Default none (every
    /// face not named is rigid, ∂p/∂n = 0).
    #[serde(default)]
    pub bottom: Vec<String>,
    /// `acoustic` only: Fenves & Chopra's wave-reflection coefficient α of `bottom` [-], in [0,
    /// 1]: 1 rigid (no absorption), 0 fully absorbing; the bottom is a dashpot of impedance
    /// ρw c (1 + α)/(1 − α) per unit area. Default 1 (rigid: the seed has no absorption; a
    /// stated choice, the safe side for the dam).
    #[serde(default)]
    pub reflection: Option<f64>,
    /// `acoustic` only: the speed of sound in water c [m/s]. Default 1440 (fresh water near
    /// 10 °C; Fenves & Chopra use 1440).
    #[serde(default)]
    pub sound_speed: Option<f64>,
    /// `acoustic` only: cavitation: the total pressure (hydrostatic + dynamic, gauge) is
    /// floored at this vapour pressure [Pa], e.g. −99000 (2.3 kPa absolute under a 101.3 kPa
    /// atmosphere). Default none: no cavitation (linear water, the usual analysis).
    #[serde(default)]
    pub vapour_pressure: Option<f64>,
}

/// Speed of sound in water [m/s] when `reservoir.fluid.sound_speed` is not given.
pub const DEFAULT_SOUND_SPEED: f64 = 1440.0;

impl FluidScene {
    /// c [m/s].
    pub fn sound_speed(&self) -> f64 {
        self.sound_speed.unwrap_or(DEFAULT_SOUND_SPEED)
    }

    /// α of the bottom [-] (1: rigid).
    pub fn reflection(&self) -> f64 {
        self.reflection.unwrap_or(1.0)
    }
}

/// Checks of the reservoir fields this module owns (called from `Scene::validate`).
pub fn validate(model: ReservoirModel, fluid: Option<&FluidScene>, added_mass_depth: super::AddedMassDepth) -> Result<(), String> {
    match (model, fluid) {
        (ReservoirModel::FeIncompressible | ReservoirModel::Acoustic, None) => {
            return Err(format!("reservoir.model \"{}\" needs `reservoir.fluid` (the water's volume, wet, free_surface and far_end groups of the mesh; docs/scenes.md)", model.name()))
        }
        (ReservoirModel::Westergaard | ReservoirModel::WestergaardLocal, Some(_)) => {
            return Err(format!(
                "reservoir.fluid is given but reservoir.model is \"{}\", which does not use a water mesh: set \"model\": \"fe_incompressible\" or \"acoustic\", or remove `fluid`",
                model.name()
            ))
        }
        _ => {}
    }
    if model.meshed() && added_mass_depth != super::AddedMassDepth::Reservoir {
        return Err(format!("reservoir.added_mass_depth \"local\" applies to the Westergaard models only; remove it with \"model\": \"{}\"", model.name()));
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
        validate_acoustic_fields(model, f)?;
    }
    Ok(())
}

/// The acoustic-only fields of `fluid`: given with another model, an error; their ranges.
fn validate_acoustic_fields(model: ReservoirModel, f: &FluidScene) -> Result<(), String> {
    if model != ReservoirModel::Acoustic {
        let given: Vec<&str> = [("bottom", !f.bottom.is_empty()), ("reflection", f.reflection.is_some()), ("sound_speed", f.sound_speed.is_some()), ("vapour_pressure", f.vapour_pressure.is_some())]
            .iter()
            .filter(|(_, g)| *g)
            .map(|(n, _)| *n)
            .collect();
        if !given.is_empty() {
            return Err(format!("reservoir.fluid: {} appl{} to \"model\": \"acoustic\" only (the water of \"{}\" is incompressible, its bottom rigid); remove {}", given.join(", "), if given.len() == 1 { "ies" } else { "y" }, model.name(), if given.len() == 1 { "it" } else { "them" }));
        }
        return Ok(());
    }
    if let Some(a) = f.reflection {
        if !(0.0..=1.0).contains(&a) {
            return Err(format!("reservoir.fluid.reflection {a}: the wave-reflection coefficient α is in [0, 1] (1 rigid bottom, 0 fully absorbing; Fenves & Chopra use 0.5 to 1)"));
        }
        if a < 1.0 && f.bottom.is_empty() {
            return Err(format!("reservoir.fluid.reflection {a} < 1 but no `bottom` face group is named: name the absorbing bottom and banks, e.g. [\"water:bed\"]"));
        }
    }
    if let Some(c) = f.sound_speed {
        if !(c.is_finite() && c > 0.0) {
            return Err(format!("reservoir.fluid.sound_speed {c}: give the speed of sound in water in m/s (> 0; default {DEFAULT_SOUND_SPEED})"));
        }
    }
    if let Some(pv) = f.vapour_pressure {
        if !(pv.is_finite() && pv <= 0.0) {
            return Err(format!("reservoir.fluid.vapour_pressure {pv} Pa: the floor of the total gauge pressure must be ≤ 0 (e.g. −99000: water at 2.3 kPa absolute under the atmosphere)"));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn model_names_parse_and_print_the_same() {
        for m in [ReservoirModel::Westergaard, ReservoirModel::WestergaardLocal, ReservoirModel::FeIncompressible, ReservoirModel::Acoustic] {
            let parsed: ReservoirModel = serde_json::from_str(&format!("\"{}\"", m.name())).unwrap();
            assert_eq!(parsed, m);
        }
        assert!(serde_json::from_str::<ReservoirModel>("\"acoustic_typo\"").is_err());
    }

    #[test]
    fn fe_model_without_a_water_mesh_is_refused_with_the_fix() {
        let e = validate(ReservoirModel::FeIncompressible, None, super::super::AddedMassDepth::Reservoir).unwrap_err();
        assert!(e.contains("reservoir.fluid"), "{e}");
        let f = FluidScene { volume: "block:water".into(), wet: vec!["water:dam".into()], free_surface: vec![], far_end: vec![], bottom: vec![], reflection: None, sound_speed: None, vapour_pressure: None };
        let e = validate(ReservoirModel::FeIncompressible, Some(&f), super::super::AddedMassDepth::Reservoir).unwrap_err();
        assert!(e.contains("free_surface"), "{e}");
        let e = validate(ReservoirModel::Westergaard, Some(&f), super::super::AddedMassDepth::Reservoir).unwrap_err();
        assert!(e.contains("fe_incompressible"), "{e}");
    }

    #[test]
    fn acoustic_fields_are_refused_with_another_model_and_checked_in_range() {
        let f = |reflection: Option<f64>, bottom: bool| FluidScene {
            volume: "block:water".into(),
            wet: vec!["water:dam".into()],
            free_surface: vec!["water:surface".into()],
            far_end: vec![],
            bottom: if bottom { vec!["water:bed".into()] } else { vec![] },
            reflection,
            sound_speed: None,
            vapour_pressure: None,
        };
        let depth = super::super::AddedMassDepth::Reservoir;
        let e = validate(ReservoirModel::FeIncompressible, Some(&f(Some(0.5), true)), depth).unwrap_err();
        assert!(e.contains("bottom, reflection") && e.contains("acoustic"), "{e}");
        assert!(validate(ReservoirModel::Acoustic, Some(&f(Some(0.5), true)), depth).is_ok());
        let e = validate(ReservoirModel::Acoustic, Some(&f(Some(1.5), true)), depth).unwrap_err();
        assert!(e.contains("[0, 1]"), "{e}");
        let e = validate(ReservoirModel::Acoustic, Some(&f(Some(0.5), false)), depth).unwrap_err();
        assert!(e.contains("bottom"), "{e}");
        let e = validate(ReservoirModel::Acoustic, None, depth).unwrap_err();
        assert!(e.contains("acoustic") && e.contains("fluid"), "{e}");
        let mut g = f(None, false);
        g.vapour_pressure = Some(1000.0);
        assert!(validate(ReservoirModel::Acoustic, Some(&g), depth).unwrap_err().contains("vapour_pressure"));
    }
}
