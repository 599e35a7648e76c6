//! The scene's `foundation`: which rock model a run uses (issue 29; docs/scenes.md,
//! docs/dam_physics.md "Foundation models").
//!
//! Absent (or `"model": "massless"`): the seed's configuration, unchanged (the rock material
//! marked `massless` is condensed statically, the record moves the fixed far boundary
//! rigidly). `"massed_fixed"`: the rock's materials keep their density (mass, no weight by
//! default), the far boundary stays fixed and the record is the same rigid base motion: the
//! reflecting case. `"radiating"`: massed rock, Lysmer dashpots (optionally springs) on the far
//! boundary faces, and the records taken as the surface free field, deconvolved through a 1-D
//! column (`crate::motion::column`) and applied as effective forces on the far faces.

use super::{Damping, MaterialSpec};
use serde::{Deserialize, Serialize};

/// The rock model (see the module doc).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FoundationModel {
    #[default]
    Massless,
    MassedFixed,
    Radiating,
}

impl FoundationModel {
    pub fn as_str(self) -> &'static str {
        match self {
            FoundationModel::Massless => "massless",
            FoundationModel::MassedFixed => "massed_fixed",
            FoundationModel::Radiating => "radiating",
        }
    }

    /// Whether the rock carries mass (every model but the seed's).
    pub fn massed(self) -> bool {
        self != FoundationModel::Massless
    }
}

/// The massed rock's Rayleigh damping (issue 29 §3; docs/dam_physics.md "Foundation models").
/// With "as_dam" and "stiffness_only" the explicit step applies the scene's one pair (α, β):
/// βK on every element, αM on the nodes of `damping.mass_groups`; the rock's choice is whether
/// its nodes carry αM. A pair of its own (`Own`) gives the rock's elements their own β and the
/// rock's nodes their own α (`Model::rock_damping`).
#[derive(Clone, Debug, Default)]
pub enum RockDamping {
    /// The scene's Rayleigh pair on the rock as on the dam (its volume groups join
    /// `damping.mass_groups`). Default. Why: with βK alone the dam study's β = 3.0e-5 s (5 % at
    /// 1.5 and 526 Hz) damps the rock by ξ = βω/2 = 0.01 % at 1 Hz, and a rock box ringing at
    /// its first modes (c_s / 4D: 1.3 Hz under the valley floor, 0.9 Hz under the plateaus of
    /// the default dam) next to the dam's f1 (0.85–1.1 Hz) is then undamped: the massed_fixed
    /// run of the last `make dam` grew to 8.2 m at the crest (docs/dam_physics.md). The dam's
    /// ratio (5 % at 1.5 Hz, 6–7.5 % at 1 Hz with α = 0.94 1/s) is the one damping of the whole
    /// dam–rock system, as the seed's single ratio intends; and every run made before the
    /// rock's own pair existed keeps its numbers bit for bit.
    #[default]
    AsDam,
    /// βK only, the rock left out of αM (the state before "as_dam"; a lower bound of the
    /// rock's damping). Needs `damping.mass_groups` naming the dam's groups (otherwise every
    /// node carries αM and the rock cannot be left out).
    StiffnessOnly,
    /// The rock's own Rayleigh pair, written as the scene's `damping` (`{"ratio", "f1", "f2"}`
    /// or `{"alpha", "beta"}`; the same rule [`Damping::coefficients`] turns it into (α, β);
    /// no `mass_groups`: the rock's nodes carry its α, except those of the dam's mass-damped
    /// groups). A rock's material damping (1–3 %, e.g. 2 % from its first mode up) apart from
    /// the concrete's 5 %.
    Own(Damping),
}

impl RockDamping {
    pub fn as_str(&self) -> &'static str {
        match self {
            RockDamping::AsDam => "as_dam",
            RockDamping::StiffnessOnly => "stiffness_only",
            RockDamping::Own(_) => "own pair",
        }
    }

    /// The rock's own (α [1/s], β [s]) (`None` for "as_dam" and "stiffness_only"); an error
    /// names the field and the fix.
    pub fn own_pair(&self) -> Result<Option<(f64, f64)>, String> {
        match self {
            RockDamping::Own(d) => d.coefficients().map(Some).map_err(|e| format!("foundation.{e}")),
            _ => Ok(None),
        }
    }

    /// The checks of the rock's own pair that need no mesh: the scene's `damping` rule, and
    /// no `mass_groups`, and `f1` < `f2` (the band between them is where the ratio holds).
    fn validate(&self) -> Result<(), String> {
        let RockDamping::Own(d) = self else { return Ok(()) };
        self.own_pair()?;
        if d.mass_groups.is_some() {
            return Err("foundation.damping.mass_groups: the rock's pair applies to the rock's nodes; leave mass_groups out (the dam's are the scene's damping.mass_groups)".into());
        }
        if let (Some(f1), Some(f2)) = (d.f1, d.f2) {
            if f2 <= f1 {
                return Err(format!("foundation.damping: f2 = {f2} Hz must be above f1 = {f1} Hz (the ratio holds at both and below it between them: give f1 near the rock's first mode and f2 above it)"));
            }
        }
        Ok(())
    }
}

impl<'de> Deserialize<'de> for RockDamping {
    /// `"as_dam"`, `"stiffness_only"`, or an object of the scene's `damping` form.
    fn deserialize<D: serde::Deserializer<'de>>(de: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = RockDamping;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("\"as_dam\", \"stiffness_only\", or the rock's own Rayleigh pair {\"ratio\", \"f1\", \"f2\"} or {\"alpha\", \"beta\"}")
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<RockDamping, E> {
                match v {
                    "as_dam" => Ok(RockDamping::AsDam),
                    "stiffness_only" => Ok(RockDamping::StiffnessOnly),
                    _ => Err(E::invalid_value(serde::de::Unexpected::Str(v), &self)),
                }
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(self, map: A) -> Result<RockDamping, A::Error> {
                Damping::deserialize(serde::de::value::MapAccessDeserializer::new(map)).map(RockDamping::Own)
            }
        }
        de.deserialize_any(V)
    }
}

impl Serialize for RockDamping {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            RockDamping::Own(d) => d.serialize(s),
            other => s.serialize_str(other.as_str()),
        }
    }
}

/// `foundation` of a scene (field docs: docs/scenes.md).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct FoundationScene {
    /// "massless" (default), "massed_fixed" or "radiating".
    #[serde(default)]
    pub model: FoundationModel,
    /// The rock's volume groups. Default: the materials marked `massless` (the seed's rock).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rock: Option<Vec<String>>,
    /// Far-boundary face groups or group patterns (radiating: where the dashpots and the free
    /// field's forces act). Default `["bc:far*"]` (the dam's bottom and four sides).
    #[serde(default = "default_far")]
    pub far: Vec<String>,
    /// Add springs to the dashpots (the viscous-spring boundary of Liu et al. 2006:
    /// k_n = 4/3 G/R, k_t = 2/3 G/R per unit area). Default false (pure Lysmer dashpots: no
    /// static stiffness, the far boundary's static reactions are held as constant forces).
    #[serde(default)]
    pub springs: bool,
    /// R of the springs [m]: distance from the scattering source (the dam) to the far boundary.
    /// Default: each far face's distance to the centre of the rock's top.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spring_distance: Option<f64>,
    /// Elevation of the free surface where the records were taken [m]. Default: the top of the
    /// rock (the highest rock node; the canyon is ignored in the free field).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surface: Option<f64>,
    /// Highest frequency of the free field [Hz]: the records are low-passed there before the
    /// deconvolution. Default 25 (`problem::foundation::free_field::DEFAULT_MAX_FREQUENCY`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_frequency: Option<f64>,
    /// Whether the massed rock carries its weight. Default false: the rock's in-situ state
    /// predates the dam (as with the massless rock), so the static state is the same in every
    /// model and only the dam's loads strain the rock.
    #[serde(default)]
    pub rock_weight: bool,
    /// The massed rock's damping ([`RockDamping`]): "as_dam" (default), "stiffness_only" or the
    /// rock's own pair. Nothing for the massless rock (condensed statically: no velocity to damp).
    #[serde(default)]
    pub damping: RockDamping,
}

fn default_far() -> Vec<String> {
    vec!["bc:far*".into()]
}

impl Default for FoundationScene {
    fn default() -> Self {
        FoundationScene { model: FoundationModel::Massless, rock: None, far: default_far(), springs: false, spring_distance: None, surface: None, max_frequency: None, rock_weight: false, damping: RockDamping::AsDam }
    }
}

impl FoundationScene {
    /// The rock's material entries: those named by `rock`, else those marked `massless`.
    pub fn rock_materials<'a>(&self, materials: &'a [MaterialSpec]) -> Vec<&'a MaterialSpec> {
        match &self.rock {
            Some(groups) => materials.iter().filter(|m| groups.iter().any(|g| *g == m.group)).collect(),
            None => materials.iter().filter(|m| m.massless).collect(),
        }
    }

    /// The checks that need no mesh (`materials`: the scene's): each names the field and the fix.
    pub fn validate(&self, materials: &[MaterialSpec]) -> Result<(), String> {
        if self.model.massed() {
            let rock = self.rock_materials(materials);
            if rock.is_empty() {
                return Err(format!(
                    "foundation.model \"{}\": no rock material: mark the rock's material `massless` (the seed's rock) or name its volume groups in foundation.rock",
                    self.model.as_str()
                ));
            }
            if let Some(m) = rock.iter().find(|m| m.rho <= 0.0) {
                return Err(format!("foundation.model \"{}\": the rock material \"{}\" has rho = 0; a massed rock needs its density [kg/m³]", self.model.as_str(), m.group));
            }
        }
        let radiating_only = |set: bool, field: &str| -> Result<(), String> {
            if set && self.model != FoundationModel::Radiating {
                return Err(format!("foundation.{field}: only with \"model\": \"radiating\" (the model is \"{}\")", self.model.as_str()));
            }
            Ok(())
        };
        if !matches!(self.damping, RockDamping::AsDam) && !self.model.massed() {
            return Err(format!(
                "foundation.damping \"{}\": only with a massed rock (\"model\": \"massed_fixed\" or \"radiating\"; the model is \"{}\", whose condensed rock has no velocity to damp): set the model or leave foundation.damping out",
                self.damping.as_str(),
                self.model.as_str()
            ));
        }
        self.damping.validate()?;
        radiating_only(self.springs, "springs")?;
        radiating_only(self.spring_distance.is_some(), "spring_distance")?;
        radiating_only(self.surface.is_some(), "surface")?;
        radiating_only(self.max_frequency.is_some(), "max_frequency")?;
        if let Some(f) = self.max_frequency {
            if !(f > 0.0 && f.is_finite()) {
                return Err(format!("foundation.max_frequency = {f}: must be a frequency > 0 [Hz]"));
            }
        }
        if self.far.is_empty() {
            return Err("foundation.far: give at least one far-boundary face group (default [\"bc:far*\"])".into());
        }
        if let Some(r) = self.spring_distance {
            if !(r > 0.0 && r.is_finite()) {
                return Err(format!("foundation.spring_distance = {r}: must be a distance > 0 [m]"));
            }
            if !self.springs {
                return Err("foundation.spring_distance: only with \"springs\": true".into());
            }
        }
        if let Some(z) = self.surface {
            if !z.is_finite() {
                return Err(format!("foundation.surface = {z}: must be a finite elevation [m]"));
            }
        }
        if let Some(r) = &self.rock {
            if r.is_empty() {
                return Err("foundation.rock: give the rock's volume groups, or leave it out (the massless materials)".into());
            }
        }
        Ok(())
    }
}
