//! Generated joint test cases with exact references (`jointquake testcase KIND`, issue 20).
//!
//! A case is two structured blocks (`mesh::structured`, no gmsh) meeting at a flat joint, each
//! side meshed on its own (element type, in-plane divisions, layers), so the joint is
//! non-conforming whenever the two sides differ. From a [`CaseSpec`] the module builds the
//! mesh, the scene and the exact reference ([`Case`]), writes them ([`write_case`]: `case.msh`,
//! `scene.json`, `reference.json`) and runs them in memory ([`run::run_case`]) to the error
//! against the reference.
//!
//! Conventions (written once here):
//! - **Local frame.** Every case is built in a local frame whose joint is the plane z = 0: the
//!   `lower` block below (z < 0), the `upper` block above. The whole model is then rotated by
//!   the joint inclination β about the y axis, R = [[cos β, 0, −sin β], [0, 1, 0], [sin β, 0,
//!   cos β]] (local x rises at β, the joint normal tilts towards −x). Global = R · local; errors
//!   are measured in the local frame (stresses σ_local = Rᵀ σ R).
//! - **Groups** (from `mesh::structured`): `block:lower`, `block:upper`; faces `lower:z1` and
//!   `upper:z0` are the two sides of joint `J`; `lower:z0` is fixed (base); the other faces
//!   `<block>:x0 … z1` carry the tractions of the exact state.
//! - **Sides**: `ELEMENT:N[:LAYERS]`, e.g. `hex8:4`, `tet4:3:2`, `mixed:4`: hex8, tet4 (each grid
//!   cell split into 6 tets, Kuhn) or mixed (hex8 in the first ⌈N/2⌉ columns along x, tet4 in the
//!   rest: the joint face is half quads, half triangles; `mesh::structured`), N divisions per unit length in x and y, LAYERS element layers
//!   through the block (default 2).
//! - **Slave**: the side whose nodes are paired (`lower` or `upper`); default the finer side
//!   (more in-plane divisions; `upper` on a tie), the tagger's own rule.
//! - Units SI. The sign of pressure p: compression positive (σzz = −p).
//!
//! Kinds and their exact solutions:
//! - `patch`: 1 × 1 m blocks, 0.5 m each, E = 1 GPa, ν = 0 (so the exact state is uniform
//!   whatever the lateral faces do), base fixed; uniform σzz = −p and σxz = τ (`shear`), applied
//!   as the tractions σ·n of that state on every free face. Exact: that stress in every
//!   element, contact pressure p and shear traction τ at every slave node (r = p A_s). Solved
//!   statically (dynamic relaxation with adaptive critical damping, [`run`]).
//!   With `curvature` R the joint is a cylinder (axis along y, [`CaseSpec::curvature`]) under
//!   the same pressure state σzz = −p: it is exactly linear (u = −(p/E)(z + H) e_z), so a
//!   conforming mesh reproduces it to round-off whatever the joint's shape, and on the cylinder it
//!   is the traction σ n = −p n_z e_z, normal p n_z² and shear p n_z |n_x| (stick needs μ above the
//!   steepest slope, tan α = ½ / √(R² − ¼)); the exact force at a slave node is σ · Σ_f n_f ∫ N_I dA.
//!   (A Lamé solution of concentric cylinders under radial pressure would mix the elements' own
//!   error into the contact's, and needs rollers on joint nodes, which the contact force treats as
//!   fixed nodes (`contact::force`, inverse mass 0 for any fixed component); this state keeps the
//!   patch test's property that any error is the joint's.)
//! - `slide`: a 1 × 0.5 × 0.5 m block on a 4 × 1 × 0.5 m base inclined at β, μ < tan β, gravity
//!   from rest: s(t) = ½ g (sin β − μ cos β) t² down the slope (refs/analytic.py B).
//! - `newmark`: the `slide` geometry with μ ≥ tan β (the block holds under gravity), gravity
//!   relaxed, then a horizontal base record along the rising direction (default El Centro 1940
//!   N–S scaled to 0.5 g, 10 s): the residual slip down the slope against the rigid-block
//!   Newmark integration of `rigid::newmark::slide_block` (one-way, cohesionless) under the same
//!   ground motion (docs/validation.md §6).
//! - `impact`: two bars 0.1 × 0.1 × 1 m along the local z axis (E = 2 GPa, ρ = 2000 kg/m³,
//!   c = 1000 m/s, ν = 0), the lower one moving at v0 = 1 m/s into the upper one at rest:
//!   contact force ρ c A v0 / 2 for 2L/c (refs/analytic.py C; docs/validation.md §1).

pub mod run;

use crate::error::{CaseError, Error};
use crate::mesh::structured::{add_box, BoxSpec};
use crate::mesh::Mesh;
use crate::scene::ContactMethod;
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// Which case.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    Patch,
    Slide,
    Newmark,
    Impact,
}

impl std::str::FromStr for Kind {
    type Err = String;
    fn from_str(s: &str) -> Result<Kind, String> {
        match s {
            "patch" => Ok(Kind::Patch),
            "slide" => Ok(Kind::Slide),
            "newmark" => Ok(Kind::Newmark),
            "impact" => Ok(Kind::Impact),
            _ => Err(format!("\"{s}\" is not a testcase kind (patch, slide, newmark, impact)")),
        }
    }
}

/// Element type of one side.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Element {
    Hex8,
    Tet4,
    /// Hex8 in the first ⌈N/2⌉ columns along x, tet4 (Kuhn split) in the rest
    /// (`mesh::structured`), so the joint face is half quads, half triangles.
    Mixed,
}

/// One side's mesh: `ELEMENT:N[:LAYERS]` (see the module conventions).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SideSpec {
    pub element: Element,
    /// Divisions per unit length in x and y (the patch's 1 m side; per metre for `slide`).
    pub n: usize,
    /// Element layers through the block (along the bar for `impact`).
    pub layers: usize,
}

impl std::str::FromStr for SideSpec {
    type Err = String;
    fn from_str(s: &str) -> Result<SideSpec, String> {
        let parts: Vec<&str> = s.split(':').collect();
        let bad = || format!("\"{s}\": write ELEMENT:N[:LAYERS], e.g. hex8:4 or tet4:3:2 (ELEMENT hex8, tet4 or mixed, N and LAYERS whole numbers from 1 to 200)");
        if parts.len() < 2 || parts.len() > 3 {
            return Err(bad());
        }
        let element = match parts[0] {
            "hex8" => Element::Hex8,
            "tet4" => Element::Tet4,
            "mixed" => Element::Mixed,
            _ => return Err(bad()),
        };
        let num = |t: &str| t.parse::<usize>().ok().filter(|&v| (1..=200).contains(&v)).ok_or_else(bad);
        let n = num(parts[1])?;
        let layers = if parts.len() == 3 { num(parts[2])? } else { 2 };
        Ok(SideSpec { element, n, layers })
    }
}

impl std::fmt::Display for SideSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let e = match self.element {
            Element::Hex8 => "hex8",
            Element::Tet4 => "tet4",
            Element::Mixed => "mixed",
        };
        write!(f, "{e}:{}:{}", self.n, self.layers)
    }
}

impl Serialize for SideSpec {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.to_string())
    }
}

impl<'de> Deserialize<'de> for SideSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<SideSpec, D::Error> {
        let s = String::deserialize(d)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}

/// Which block carries the slave face.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Side {
    Lower,
    Upper,
}

/// Everything that defines a case; the CLI options of `jointquake testcase` and one line of a
/// joint-test study (`pipelines/joint_tests_study.json`). Defaults per kind are in
/// [`CaseSpec::resolved`] and docs/cli.md.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CaseSpec {
    pub kind: Kind,
    /// Lower side (the master of `slide`; the moving bar of `impact`). Default hex8:4 (patch),
    /// hex8:2:2 (slide: 2 per metre, 8 along the 4 m base), hex8:1:100 (impact).
    #[serde(default)]
    pub lower: Option<SideSpec>,
    /// Upper side. Default hex8:3 (patch), hex8:4:2 (slide), hex8:1:100 (impact).
    #[serde(default)]
    pub upper: Option<SideSpec>,
    /// Slave side. Default: the finer side (upper on a tie; always the slider for `slide`).
    #[serde(default)]
    pub slave: Option<Side>,
    /// Contact method. Default nts.
    #[serde(default)]
    pub method: Option<ContactMethod>,
    /// Penalty stiffness as a multiple k of E/h (h the slave's in-plane element size): kn =
    /// k E / h [Pa/m]. Default 1. Only with method penalty.
    #[serde(default)]
    pub penalty: Option<f64>,
    /// Candidate layer 1 or 2. Default 1.
    #[serde(default)]
    pub layer: Option<u8>,
    /// Friction coefficient. Default 0.6 (patch, impact: 0), 0.3 (slide).
    #[serde(default)]
    pub mu: Option<f64>,
    /// Bonded joint (never opens or slides). Default false.
    #[serde(default)]
    pub tied: bool,
    /// Patch: pressure p [Pa]. Default 1e6.
    #[serde(default)]
    pub pressure: Option<f64>,
    /// Patch: shear stress τ along local x [Pa]. Default 0 (pressure only). Without `tied` keep
    /// |τ| < μ p so that the joint sticks.
    #[serde(default)]
    pub shear: Option<f64>,
    /// Joint inclination β [deg] about the y axis. Default 0 (slide: 30).
    #[serde(default)]
    pub inclination: Option<f64>,
    /// Patch: the lower block is massless (`materials[].massless`, condensed statically; the
    /// layer touching the joint keeps its mass, docs/dam_physics.md). Default false.
    #[serde(default)]
    pub massless_lower: bool,
    /// Patch: the load path. false (default): p and τ ramped in together from zero (over
    /// `dynamics::RELAXATION_RAMP_STEPS` steps of the static solve); true: p first, relaxed to
    /// equilibrium, then τ ramped in over as many steps at full p and relaxed again — the path
    /// of a joint closed by its overburden before it is sheared. On the proportional path a
    /// frictional joint's pairs carry shear at nearly no pressure in the first steps and some
    /// slip (1.5e-4 of σ on hex 4/3 with mortar, μ = 0.6, τ = 0.3 p); on this one a joint with
    /// |τ| < μ p sticks throughout ([`run`]). Needs p > 0 and τ ≠ 0. Only the in-memory static
    /// solve (`--run`, the studies) takes it; the written scene keeps the proportional ramp.
    #[serde(default)]
    pub pressure_first: bool,
    /// Slide: simulated time [s]. Default 1 (1.18 m at β = 30°, μ = 0.3: 2.4 base elements of
    /// 0.5 m). Impact: ignored (3 L/c).
    #[serde(default)]
    pub duration: Option<f64>,
    /// Patch: relaxation residual ‖M a‖ / ‖F‖ at which the static solve stops. Default 1e-10.
    #[serde(default)]
    pub residual: Option<f64>,
    /// Newmark: the base record (two columns t [s], a [g]; docs/scenes.md `loads.base`). Default
    /// `pipelines/records/elcentro1940_NS_chopra.txt` (relative to the current directory).
    #[serde(default)]
    pub record: Option<PathBuf>,
    /// Newmark: the record's PGA [g]. Default 0.5.
    #[serde(default)]
    pub pga: Option<f64>,
    /// The joint's `edge_tolerance` (fraction of the master face size; docs/scenes.md). Default:
    /// the scene's default (1e-3). A bonded or sticking slave node on the joint's perimeter that
    /// carries a tangential force is searched at its contact-free prediction, which leaves the
    /// master by dt² F/m; above this tolerance it is lost (docs/validation.md §8).
    #[serde(default)]
    pub edge_tolerance: Option<f64>,
    /// Shift of the upper side's mesh in the joint plane, as a fraction s of its element size h:
    /// its interior grid lines (x and y) move by s·h, its outline stays (the joint is the same
    /// rectangle on both sides, which the exact references need), so its first row of elements
    /// is (1 + s) h wide and its last (1 − s) h. |s| < 1; needs N ≥ 2. Default 0.
    #[serde(default)]
    pub offset: Option<f64>,
    /// Turn of the upper side's mesh about the joint normal [deg]: every node at "square radius"
    /// ρ = max(|x − x_c|/(l_x/2), |y − y_c|/(l_y/2)) from the joint's centre turns by θ·w(ρ), w = 1
    /// for ρ ≤ ½ (the inner half is the grid rigidly turned by θ) and 2 (1 − ρ) beyond, so the
    /// outline stays. |θ| ≤ 45; an element turned inside out is refused. Default 0.
    #[serde(default)]
    pub rotate: Option<f64>,
    /// Patch: a cylindrical joint of radius R [m], axis along local y through the joint's edges
    /// x = 0 and x = 1 m: z = f(x) = sgn R (√(R² − (x − ½)²) − √(R² − ¼)) (R > 0: the lower block
    /// bulges into the upper one; R < 0: a trough). The master side's joint nodes lie on the
    /// cylinder, the slave side's on the master's facets (the initial gap is zero, as CalculiX and
    /// Abaqus adjust slave nodes; a mortar joint, whose weighted gap sees the two faceted
    /// surfaces apart, is grouted on this configuration, [`run`]); every node column is moved by
    /// f(1 − |z|/H). The pressure state
    /// σzz = −p is unchanged (module doc); μ must exceed the steepest slope ½/√(R² − ¼) unless
    /// tied. |R| > 0.5 m; default flat.
    #[serde(default)]
    pub curvature: Option<f64>,
    /// Patch with `curvature`: the slave side's joint nodes on the exact cylinder too, as a
    /// mesher puts both sides of a curved joint on the one CAD surface (default false: on the
    /// master's facets). The two faceted surfaces then differ by the chords' sags, up to
    /// h²/(8|R|) each (14 mm for h = 1/3 m, R = 1 m, against 0.5 mm of displacement under p), so
    /// the joint, whatever its method, is grouted on the initial configuration ([`run`]). Both
    /// sides then approximate the same exact surface to O(h²) at every level: the geometry of
    /// the mortar convergence study (docs/validation.md §8). Default false.
    #[serde(default)]
    pub slave_on_cylinder: bool,
}

/// Patch material and geometry (module conventions).
pub const PATCH_E: f64 = 1e9;
pub const PATCH_RHO: f64 = 1000.0;
pub const PATCH_SIDE: f64 = 1.0;
pub const PATCH_HEIGHT: f64 = 0.5;
/// Slide material (stiff blocks, as the incline validation, docs/validation.md §4).
pub const SLIDE_E: f64 = 1e10;
pub const SLIDE_NU: f64 = 0.2;
pub const SLIDE_RHO: f64 = 2500.0;
/// Impact bars (docs/validation.md §1).
pub const BAR_E: f64 = 2e9;
pub const BAR_RHO: f64 = 2000.0;
pub const BAR_L: f64 = 1.0;
pub const BAR_A: f64 = 0.1;
pub const BAR_V0: f64 = 1.0;
/// Standard gravity of the slide [m/s²].
pub const G: f64 = 9.81;

/// A [`CaseSpec`] with every default filled in.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Resolved {
    pub kind: Kind,
    pub lower: SideSpec,
    pub upper: SideSpec,
    pub slave: Side,
    pub method: ContactMethod,
    pub penalty: f64,
    pub layer: u8,
    pub mu: f64,
    pub tied: bool,
    pub pressure: f64,
    pub shear: f64,
    pub inclination: f64,
    pub massless_lower: bool,
    /// Patch: p relaxed first, then τ (see [`CaseSpec`]).
    #[serde(default)]
    pub pressure_first: bool,
    pub duration: f64,
    pub residual: f64,
    pub edge_tolerance: Option<f64>,
    /// Upper side's in-plane shift (fraction of its element) and turn [deg] (see [`CaseSpec`]).
    #[serde(default)]
    pub offset: f64,
    #[serde(default)]
    pub rotate: f64,
    /// Patch: radius of the cylindrical joint [m] (see [`CaseSpec`]); None: flat.
    #[serde(default)]
    pub curvature: Option<f64>,
    /// Patch: the slave side's joint nodes on the exact cylinder too (see [`CaseSpec`]).
    #[serde(default)]
    pub slave_on_cylinder: bool,
    /// Newmark: the record (absolute path) and its PGA [g].
    pub record: Option<PathBuf>,
    pub pga: f64,
}

fn invalid(option: &str, message: impl Into<String>) -> Error {
    CaseError::Invalid { option: option.into(), message: message.into() }.into()
}

/// The numeric command-line options of `jointquake testcase`, each finite when given: a NaN
/// or inf option became JSON `null` on its way to [`CaseSpec`] and so silently the default
/// (issue 34). The error names the option.
pub fn check_finite_options(opts: &[(&str, Option<f64>)]) -> Result<(), Error> {
    match opts.iter().find(|(_, v)| v.is_some_and(|x| !x.is_finite())) {
        Some((name, Some(v))) => Err(invalid(name, format!("{v}: give a finite number"))),
        _ => Ok(()),
    }
}

impl CaseSpec {
    /// Defaults filled in and every option checked (an error names the option and the fix).
    pub fn resolved(&self) -> Result<Resolved, Error> {
        let k = self.kind;
        let (dl, du) = match k {
            Kind::Patch => ("hex8:4:2", "hex8:3:2"),
            Kind::Slide | Kind::Newmark => ("hex8:2:2", "hex8:4:2"),
            Kind::Impact => ("hex8:1:100", "hex8:1:100"),
        };
        let lower = self.lower.unwrap_or_else(|| dl.parse().expect("default side"));
        let upper = self.upper.unwrap_or_else(|| du.parse().expect("default side"));
        let finer = if lower.n > upper.n { Side::Lower } else { Side::Upper };
        let slave = match (k, self.slave) {
            (Kind::Slide | Kind::Newmark, Some(Side::Lower)) => return Err(invalid("slave", "slide, newmark: the slave must be the slider (upper): its nodes stay on the base while it slides")),
            (Kind::Slide | Kind::Newmark, _) => Side::Upper,
            (_, Some(s)) => s,
            (_, None) => finer,
        };
        let method = self.method.unwrap_or(ContactMethod::Nts);
        let penalty = self.penalty.unwrap_or(1.0);
        if self.penalty.is_some() && method != ContactMethod::Penalty {
            return Err(invalid("penalty", "a penalty factor needs method penalty"));
        }
        if !(penalty.is_finite() && penalty > 0.0) {
            return Err(invalid("penalty", format!("{penalty}: give a factor k > 0 (kn = k E/h)")));
        }
        let layer = self.layer.unwrap_or(1);
        if layer != 1 && layer != 2 {
            return Err(invalid("layer", format!("{layer}: use 1 or 2")));
        }
        let mu = self.mu.unwrap_or(match k {
            Kind::Patch => crate::scene::DEFAULT_FRICTION,
            Kind::Slide => 0.3,
            Kind::Newmark => 35f64.to_radians().tan(),
            Kind::Impact => 0.0,
        });
        if !(mu.is_finite() && mu >= 0.0) {
            return Err(invalid("mu", format!("{mu}: give μ ≥ 0")));
        }
        let pressure = self.pressure.unwrap_or(1e6);
        let shear = self.shear.unwrap_or(0.0);
        if k != Kind::Patch && (self.pressure.is_some() || self.shear.is_some() || self.massless_lower || self.residual.is_some() || self.pressure_first) {
            return Err(invalid("pressure/shear/massless_lower/residual/pressure_first", "only the patch kind takes these"));
        }
        if self.pressure_first && (pressure <= 0.0 || shear == 0.0) {
            return Err(invalid("pressure_first", format!("p = {pressure}, τ = {shear}: the pressure-first path needs p > 0 and τ ≠ 0 (without shear the two paths are one)")));
        }
        if !(pressure.is_finite() && shear.is_finite()) || (pressure == 0.0 && shear == 0.0) || pressure < 0.0 {
            return Err(invalid("pressure", format!("p = {pressure}, τ = {shear}: give p ≥ 0 (compression) and τ, not both 0")));
        }
        if k == Kind::Patch && !self.tied && (shear.abs() >= mu * pressure) {
            return Err(invalid("shear", format!("|τ| = {} ≥ μ p = {}: the joint would slide (no static solution); lower τ or use tied", shear.abs(), mu * pressure)));
        }
        let inclination = self.inclination.unwrap_or(if matches!(k, Kind::Slide | Kind::Newmark) { 30.0 } else { 0.0 });
        if !(inclination.is_finite() && inclination.abs() < 80.0) {
            return Err(invalid("inclination", format!("{inclination}: give |β| < 80 deg")));
        }
        if matches!(k, Kind::Slide | Kind::Newmark) && inclination <= 0.0 {
            return Err(invalid("inclination", "slide, newmark: give β > 0 (the slope)"));
        }
        if k == Kind::Newmark && mu < inclination.to_radians().tan() {
            return Err(invalid("mu", format!("newmark: μ = {mu} < tan β = {:.4}: the block slides under gravity alone (use the slide kind)", inclination.to_radians().tan())));
        }
        if k != Kind::Newmark && (self.record.is_some() || self.pga.is_some()) {
            return Err(invalid("record/pga", "only the newmark kind takes a base record"));
        }
        let pga = self.pga.unwrap_or(0.5);
        if !(pga.is_finite() && pga > 0.0 && pga <= 3.0) {
            return Err(invalid("pga", format!("{pga}: give 0 < PGA ≤ 3 g")));
        }
        let record = if k == Kind::Newmark {
            let p = self.record.clone().unwrap_or_else(|| PathBuf::from("pipelines/records/elcentro1940_NS_chopra.txt"));
            Some(std::fs::canonicalize(&p).map_err(|e| invalid("record", format!("{}: {e} (give --record FILE, two columns t [s], a [g]; the default is relative to the repository root)", p.display())))?)
        } else {
            None
        };
        let duration = self.duration.unwrap_or(if k == Kind::Newmark { 10.0 } else { 1.0 });
        if !(duration.is_finite() && duration > 0.0 && duration <= 60.0) {
            return Err(invalid("duration", format!("{duration}: give 0 < duration ≤ 60 s")));
        }
        let residual = self.residual.unwrap_or(1e-10);
        if !(residual.is_finite() && residual > 0.0 && residual < 1e-2) {
            return Err(invalid("residual", format!("{residual}: give 0 < residual < 1e-2")));
        }
        if let Some(e) = self.edge_tolerance.filter(|e| !(e.is_finite() && *e > 0.0 && *e < 1.0)) {
            return Err(invalid("edge_tolerance", format!("{e}: give a fraction of the face size in (0, 1)")));
        }
        let offset = self.offset.unwrap_or(0.0);
        if !(offset.is_finite() && offset.abs() < 1.0) {
            return Err(invalid("offset", format!("{offset}: give a fraction of the upper side's element with |s| < 1 (0.3: its interior grid lines move by 0.3 h)")));
        }
        if offset != 0.0 && upper.n < 2 {
            return Err(invalid("offset", format!("the upper side {upper} has no interior grid line to shift: give N ≥ 2")));
        }
        let rotate = self.rotate.unwrap_or(0.0);
        if !(rotate.is_finite() && rotate.abs() <= 45.0) {
            return Err(invalid("rotate", format!("{rotate}: give |θ| ≤ 45 deg")));
        }
        self.check_curvature(k, mu, pressure, shear, rotate)?;
        if self.massless_lower && slave == Side::Lower && !self.tied && method == ContactMethod::Ntn {
            return Err(invalid("massless_lower", "NTN on a massless side is not a supported combination; use nts"));
        }
        // size of the problem: refuse what would not fit in memory before allocating it
        let cells = |s: &SideSpec, len: usize| s.n * s.n * len * s.layers * if s.element == Element::Hex8 { 1 } else { 6 };
        let total = cells(&lower, if matches!(k, Kind::Slide | Kind::Newmark) { 4 } else { 1 }) + cells(&upper, 1);
        if total > 2_000_000 {
            return Err(invalid("lower/upper", format!("{total} elements: keep a case below 2 million")));
        }
        Ok(Resolved { kind: k, lower, upper, slave, method, penalty, layer, mu, tied: self.tied, pressure, shear, inclination, massless_lower: self.massless_lower, pressure_first: self.pressure_first, duration, residual, edge_tolerance: self.edge_tolerance, offset, rotate, curvature: self.curvature, slave_on_cylinder: self.slave_on_cylinder, record, pga })
    }

    /// The cylindrical joint (`curvature` R), if any: a patch case, |R| above the joint's
    /// half-width, the pressure state only, and μ above the steepest slope unless tied.
    fn check_curvature(&self, k: Kind, mu: f64, pressure: f64, shear: f64, rotate: f64) -> Result<(), Error> {
        let Some(rc) = self.curvature else {
            return if self.slave_on_cylinder { Err(invalid("slave_on_cylinder", "only a cylindrical joint (curvature R) has the cylinder to put the slave's nodes on")) } else { Ok(()) };
        };
        if k != Kind::Patch {
            return Err(invalid("curvature", "only the patch kind has a cylindrical joint"));
        }
        if !(rc.is_finite() && rc.abs() > 0.5 * PATCH_SIDE) {
            return Err(invalid("curvature", format!("R = {rc}: give |R| > {} m (the joint's half-width)", 0.5 * PATCH_SIDE)));
        }
        if shear != 0.0 || rotate != 0.0 || self.massless_lower {
            return Err(invalid("curvature", "a cylindrical joint takes the pressure state only: no shear, rotate or massless_lower"));
        }
        if pressure == 0.0 {
            return Err(invalid("curvature", "give a pressure p > 0"));
        }
        let c = 0.5 * PATCH_SIDE;
        let slope = c / (rc * rc - c * c).sqrt();
        if !self.tied && mu <= slope {
            return Err(invalid("curvature", format!("R = {rc}: the joint's steepest slope tan α = {slope:.4} ≥ μ = {mu}: the blocks would slide (no static solution); raise μ, |R|, or use tied")));
        }
        Ok(())
    }
}

impl Resolved {
    /// R of the module conventions.
    pub fn rotation(&self) -> Matrix3<f64> {
        let (s, c) = self.inclination.to_radians().sin_cos();
        Matrix3::new(c, 0.0, -s, 0.0, 1.0, 0.0, s, 0.0, c)
    }

    /// Height of the exact joint surface above the local plane z = 0 at local x [m] (0 when flat).
    pub fn joint_height(&self, x: f64) -> f64 {
        match self.curvature {
            Some(rc) => {
                let c = 0.5 * PATCH_SIDE;
                rc.signum() * ((rc * rc - (x - c) * (x - c)).max(0.0).sqrt() - (rc * rc - c * c).sqrt())
            }
            None => 0.0,
        }
    }

    /// The patch's exact normal (compressive) force through the joint [N]: ∫ n · σ n dA over
    /// the exact joint surface, σzz = −p. Flat: p A (A = 1 m²). On the cylinder of radius R
    /// (n_z = cos θ, dA = |R| dθ dy, |θ| ≤ α = asin(½ / |R|)): p |R| (α + sin α cos α) L_y
    /// (0.95661 p at R = ±1 m).
    pub fn exact_normal_force(&self) -> f64 {
        let a = PATCH_SIDE;
        match self.curvature {
            Some(rc) => {
                let al = (0.5 * a / rc.abs()).asin();
                self.pressure * rc.abs() * (al + al.sin() * al.cos()) * a
            }
            None => self.pressure * a * a,
        }
    }

    /// The patch's exact displacement at the local position `x` [m]: u = ((2τ/E) e_x − (p/E)
    /// e_z)(z + H), the uniform state of ν = 0 with the base z = −H fixed (simple shear γ = 2τ/E
    /// and the axial strain −p/E; module doc). Linear in x, so it is the exact displacement of
    /// the meshed geometry as well as of the exact one.
    pub fn exact_patch_displacement(&self, x: &Vector3<f64>) -> Vector3<f64> {
        let s = x[2] + PATCH_HEIGHT;
        Vector3::new(2.0 * self.shear / PATCH_E * s, 0.0, -self.pressure / PATCH_E * s)
    }

    /// The slave's and master's face groups.
    pub fn joint_groups(&self) -> (&'static str, &'static str) {
        match self.slave {
            Side::Lower => ("lower:z1", "upper:z0"),
            Side::Upper => ("upper:z0", "lower:z1"),
        }
    }

    /// In-plane element sizes of the slave and the master [m].
    pub fn sizes(&self) -> (f64, f64) {
        let (s, m) = match self.slave {
            Side::Lower => (self.lower, self.upper),
            Side::Upper => (self.upper, self.lower),
        };
        let len = if self.kind == Kind::Impact { BAR_A } else { PATCH_SIDE };
        (len / s.n as f64, len / m.n as f64)
    }

    /// Mesh ratio h_slave / h_master (< 1: finer slave).
    pub fn mesh_ratio(&self) -> f64 {
        let (s, m) = self.sizes();
        s / m
    }

    /// A short label: `patch hex8:4:2/hex8:3:2 slave lower nts`.
    pub fn label(&self) -> String {
        let m = if self.tied { format!("{} tied", self.method.as_str()) } else { self.method.as_str().to_string() };
        let mut l = format!("{:?} {}/{} slave {:?} {m}", self.kind, self.lower, self.upper, self.slave).to_lowercase();
        if self.offset != 0.0 {
            l += &format!(" offset {}", self.offset);
        }
        if self.rotate != 0.0 {
            l += &format!(" rotate {}", self.rotate);
        }
        if let Some(rc) = self.curvature {
            l += &format!(" cylinder R {rc}");
            if self.slave_on_cylinder {
                l += " both on it";
            }
        }
        if self.pressure_first {
            l += " pressure first";
        }
        l
    }
}

/// The exact reference of a case (written to `reference.json`).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Reference {
    /// Uniform stress (local frame, Pa: xx, yy, zz, xy, yz, zx), contact pressure p and shear τ
    /// per unit slave area, displacement u = ε·(z + H_lower) with the base fixed.
    Patch { stress: [f64; 6], pressure: f64, shear: f64, formula: String },
    /// Slip down the slope s(t) = ½ g (sin β − μ cos β) t² at `duration` [m] (0 if μ ≥ tan β).
    Slide { duration: f64, slip: f64, acceleration: f64, formula: String },
    /// Residual slip of the rigid block [m] under the scene's ground motion (Newmark, one-way,
    /// cohesionless, friction angle atan μ), its yield acceleration [g] and sliding episodes.
    Newmark { duration: f64, slip: f64, yield_acceleration: f64, episodes: usize, formula: String },
    /// Contact force ρ c A v0 / 2 [N] for 2L/c [s]; bar velocities after: 0 and v0.
    Impact { force: f64, duration: f64, v0: f64, formula: String },
}

/// A generated case: mesh, scene (as JSON, with `geometry.msh` = `case.msh`), reference.
pub struct Case {
    pub spec: Resolved,
    pub mesh: Mesh,
    pub scene: Value,
    pub reference: Reference,
}

/// Build the case of `spec`.
pub fn build(spec: &CaseSpec) -> Result<Case, Error> {
    let r = spec.resolved()?;
    let mesh = case_mesh(&r)?;
    let scene = case_scene(&r);
    let reference = match r.kind {
        Kind::Newmark => newmark_reference(&r, &scene)?,
        _ => reference(&r),
    };
    Ok(Case { spec: r, mesh, scene, reference })
}

fn side_box(name: &str, side: &SideSpec, size: [f64; 3], origin: [f64; 3], along: [f64; 2]) -> BoxSpec {
    let nx = ((side.n as f64 * along[0]).round() as usize).max(1);
    let ny = ((side.n as f64 * along[1]).round() as usize).max(1);
    BoxSpec::new(name, size, [nx, ny, side.layers]).at(origin).tets(side.element == Element::Tet4).mixed(side.element == Element::Mixed)
}

/// The two blocks in the local frame, the upper side's mesh shifted and turned in the joint
/// plane (`offset`, `rotate`), the whole rotated by R. An element turned inside out by the turn
/// is an error naming `rotate`.
pub fn case_mesh(r: &Resolved) -> Result<Mesh, Error> {
    let mut mesh = Mesh { source: PathBuf::from(format!("<testcase {}>", r.label())), nodes: vec![], node_tags: vec![], cells: vec![], groups: vec![] };
    // the upper box and its footprint in the joint plane (origin, size)
    let upper = match r.kind {
        Kind::Patch => {
            let (a, h) = (PATCH_SIDE, PATCH_HEIGHT);
            add_box(&mut mesh, &side_box("lower", &r.lower, [a, a, h], [0.0, 0.0, -h], [1.0, 1.0]));
            side_box("upper", &r.upper, [a, a, h], [0.0, 0.0, 0.0], [1.0, 1.0])
        }
        Kind::Slide | Kind::Newmark => {
            // base 4 × 1 × 0.5 m from x = −0.5; slider 1 × 0.5 × 0.5 m at x ∈ [2, 3], y ∈ [0.25, 0.75]
            add_box(&mut mesh, &side_box("lower", &r.lower, [4.0, 1.0, 0.5], [-0.5, 0.0, -0.5], [4.0, 1.0]));
            side_box("upper", &r.upper, [1.0, 0.5, 0.5], [2.0, 0.25, 0.0], [1.0, 0.5])
        }
        Kind::Impact => {
            let a = BAR_A;
            let bar = |s: &SideSpec| [s.n, s.n, s.layers];
            let (lo, up) = (r.lower, r.upper);
            add_box(&mut mesh, &BoxSpec::new("lower", [a, a, BAR_L], bar(&lo)).at([0.0, 0.0, -BAR_L]).tets(lo.element == Element::Tet4).mixed(lo.element == Element::Mixed));
            BoxSpec::new("upper", [a, a, BAR_L], bar(&up)).tets(up.element == Element::Tet4).mixed(up.element == Element::Mixed)
        }
    };
    let first_upper = mesh.nodes.len();
    add_box(&mut mesh, &upper);
    if r.offset != 0.0 || r.rotate != 0.0 {
        for x in &mut mesh.nodes[first_upper..] {
            let (px, py) = shift_and_turn(&upper, r.offset, r.rotate, x[0], x[1]);
            x[0] = px;
            x[1] = py;
        }
        let cells = &mesh.group("block:upper").expect("the upper block's group").cells;
        if let Some(&c) = cells.iter().find(|&&c| !(mesh.min_corner_jacobian(c) > 0.0)) {
            let x = mesh.cells[c].nodes().iter().map(|&n| mesh.x(n as usize)).sum::<Vector3<f64>>() / mesh.cells[c].nodes().len() as f64;
            return Err(invalid(
                "rotate",
                format!("θ = {} deg with offset {} turns the upper element at ({:.3}, {:.3}, {:.3}) inside out; use a smaller turn or a coarser upper side", r.rotate, r.offset, x[0], x[1], x[2]),
            ));
        }
    }
    if r.curvature.is_some() {
        curve_joint(r, &mut mesh, first_upper)?;
    }
    let rot = r.rotation();
    if r.inclination != 0.0 {
        for x in mesh.nodes.iter_mut() {
            let y = rot * Vector3::from(*x);
            *x = [y[0], y[1], y[2]];
        }
    }
    Ok(mesh)
}

/// Bend the patch's joint into the cylinder of `curvature`: master nodes by f(x) (1 − |z|/H),
/// slave nodes by g(x) (1 − |z|/H) with g the piecewise-linear interpolant of f at the master's
/// joint node abscissae, so the slave's joint nodes lie on the master's facets (zero initial
/// gap), or by f too with `slave_on_cylinder`. Nodes `first_upper..` are the upper block's.
fn curve_joint(r: &Resolved, mesh: &mut Mesh, first_upper: usize) -> Result<(), Error> {
    let h = PATCH_HEIGHT;
    let n = mesh.nodes.len();
    let (slave, master) = match r.slave {
        Side::Lower => (0..first_upper, first_upper..n),
        Side::Upper => (first_upper..n, 0..first_upper),
    };
    let tol = 1e-9 * PATCH_SIDE;
    let mut xs: Vec<f64> = mesh.nodes[master.clone()].iter().filter(|x| x[2].abs() < tol).map(|x| x[0]).collect();
    xs.sort_by(f64::total_cmp);
    xs.dedup_by(|a, b| (*a - *b).abs() < tol);
    let g = |x: f64| {
        let k = xs.partition_point(|&v| v <= x).clamp(1, xs.len() - 1);
        let (a, b) = (xs[k - 1], xs[k]);
        let t = (x - a) / (b - a);
        (1.0 - t) * r.joint_height(a) + t * r.joint_height(b)
    };
    for i in master {
        let x = &mut mesh.nodes[i];
        x[2] += r.joint_height(x[0]) * (1.0 - x[2].abs() / h);
    }
    for i in slave {
        let x = &mut mesh.nodes[i];
        let z = if r.slave_on_cylinder { r.joint_height(x[0]) } else { g(x[0]) };
        x[2] += z * (1.0 - x[2].abs() / h);
    }
    if let Some(c) = (0..mesh.cells.len()).filter(|&c| matches!(mesh.cells[c].kind, crate::mesh::CellKind::Tet4 | crate::mesh::CellKind::Hex8)).find(|&c| !(mesh.min_corner_jacobian(c) > 0.0)) {
        let x = mesh.cells[c].nodes().iter().map(|&k| mesh.x(k as usize)).sum::<Vector3<f64>>() / mesh.cells[c].nodes().len() as f64;
        return Err(invalid("curvature", format!("R = {:?} turns the element at ({:.3}, {:.3}, {:.3}) inside out: use a larger |R| or more layers", r.curvature, x[0], x[1], x[2])));
    }
    Ok(())
}

/// The in-plane map of `offset` and `rotate` (see [`CaseSpec`]) for the box `b`: interior grid
/// lines moved by s·h, then the turn θ·w(ρ) about the footprint's centre.
fn shift_and_turn(b: &BoxSpec, s: f64, theta_deg: f64, x: f64, y: f64) -> (f64, f64) {
    let (o, l, n) = (b.origin, b.size, b.divisions);
    let tol = 1e-9 * l[0].max(l[1]);
    let shift = |v: f64, axis: usize| {
        let h = l[axis] / n[axis] as f64;
        if v > o[axis] + tol && v < o[axis] + l[axis] - tol { v + s * h } else { v }
    };
    let (x, y) = (shift(x, 0), shift(y, 1));
    let (cx, cy) = (o[0] + 0.5 * l[0], o[1] + 0.5 * l[1]);
    let (dx, dy) = (x - cx, y - cy);
    let rho = (dx.abs() / (0.5 * l[0])).max(dy.abs() / (0.5 * l[1]));
    let w = if rho <= 0.5 { 1.0 } else { (2.0 * (1.0 - rho)).max(0.0) };
    let (sn, cs) = (theta_deg.to_radians() * w).sin_cos();
    (cx + cs * dx - sn * dy, cy + sn * dx + cs * dy)
}

/// The exact local stress of the patch (xx, yy, zz, xy, yz, zx).
pub fn patch_stress(r: &Resolved) -> [f64; 6] {
    [0.0, 0.0, -r.pressure, 0.0, 0.0, r.shear]
}

pub(crate) fn sym(s: &[f64; 6]) -> Matrix3<f64> {
    Matrix3::new(s[0], s[3], s[5], s[3], s[1], s[4], s[5], s[4], s[2])
}

/// The tractions σ·n of the exact patch state on the free faces (global frame): (group, traction).
pub fn patch_tractions(r: &Resolved) -> Vec<(String, [f64; 3])> {
    let rot = r.rotation();
    let s = sym(&patch_stress(r));
    let faces: [(&str, [f64; 3]); 6] = [("x0", [-1.0, 0.0, 0.0]), ("x1", [1.0, 0.0, 0.0]), ("y0", [0.0, -1.0, 0.0]), ("y1", [0.0, 1.0, 0.0]), ("z0", [0.0, 0.0, -1.0]), ("z1", [0.0, 0.0, 1.0])];
    let mut out = Vec::new();
    for block in ["lower", "upper"] {
        for (f, n) in faces {
            // the base and the two joint faces carry no applied traction
            if (block == "lower" && (f == "z0" || f == "z1")) || (block == "upper" && f == "z0") {
                continue;
            }
            let t = rot * (s * Vector3::from(n));
            if t.norm() > 0.0 {
                out.push((format!("{block}:{f}"), [t[0], t[1], t[2]]));
            }
        }
    }
    out
}

/// The rigid block under the scene's own ground motion (its base records as the run applies them).
fn newmark_reference(r: &Resolved, scene: &Value) -> Result<Reference, Error> {
    use crate::rigid::newmark::{slide_block, Direction, Incline, NewmarkOptions};
    let sc: crate::scene::Scene = serde_json::from_value(scene.clone()).map_err(|e| invalid("record", format!("generated scene: {e}")))?;
    let (motions, _) = crate::dynamics::loads::base_motions(&sc)?;
    let dt = motions.iter().map(|b| b.record.dt).fold(f64::INFINITY, f64::min);
    let n = (r.duration / dt).round() as usize + 1;
    let a: Vec<[f64; 3]> = (0..n).map(|i| crate::dynamics::loads::ground_acceleration_of(&motions, i as f64 * dt)).collect();
    // the plane rises along global +x (R e_x = (cos β, 0, sin β)): a_h positive into the hill
    let a_h: Vec<f64> = a.iter().map(|v| v[0]).collect();
    let phi = r.mu.atan().to_degrees();
    let incline = Incline { g: G, ..Incline::frictional(r.inclination, phi) };
    let nm = slide_block(&incline, Direction::OneWay, &a_h, None, &NewmarkOptions::new(dt))?;
    Ok(Reference::Newmark {
        duration: r.duration,
        slip: nm.residual_displacement,
        yield_acceleration: incline.yield_acceleration_down()? / G,
        episodes: nm.n_episodes,
        formula: "rigid block on the incline, one-way Newmark sliding (rigid::newmark::slide_block), φ = atan μ, under the same ground motion".into(),
    })
}

fn reference(r: &Resolved) -> Reference {
    match r.kind {
        Kind::Patch if r.curvature.is_some() => Reference::Patch {
            stress: patch_stress(r),
            pressure: r.pressure,
            shear: 0.0,
            formula: "uniform state of ν = 0: σzz = −p in every element (local frame), u = −(p/E)(z + H) e_z; on the cylindrical joint the traction σ n = −p n_z e_z (normal p n_z², shear p n_z |n_x|, held by friction: μ > the joint's steepest slope); exact force at a slave node σ V_s, V_s = Σ_f n_f ∫ N_I dA its area vector".into(),
        },
        Kind::Patch => Reference::Patch {
            stress: patch_stress(r),
            pressure: r.pressure,
            shear: r.shear,
            formula: "uniform state of ν = 0: σzz = −p, σxz = τ in every element (local frame); contact pressure p and shear τ at every slave node (r = p A_s, |r_t| = |τ| A_s)".into(),
        },
        Kind::Newmark => unreachable!("newmark_reference"),
        Kind::Slide => {
            let b = r.inclination.to_radians();
            let a = (G * (b.sin() - r.mu * b.cos())).max(0.0);
            Reference::Slide {
                duration: r.duration,
                slip: 0.5 * a * r.duration * r.duration,
                acceleration: a,
                formula: "s(t) = ½ g (sin β − μ cos β) t² down the slope, 0 when μ ≥ tan β (refs/analytic.py B)".into(),
            }
        }
        Kind::Impact => {
            let c = (BAR_E / BAR_RHO).sqrt();
            Reference::Impact {
                force: BAR_RHO * c * BAR_A * BAR_A * BAR_V0 / 2.0,
                duration: 2.0 * BAR_L / c,
                v0: BAR_V0,
                formula: "F = ρ c A v0 / 2 for 2L/c, then the moving bar at rest and the other at v0 (refs/analytic.py C)".into(),
            }
        }
    }
}

/// The case's scene (JSON; `geometry.msh` = `case.msh` next to it).
pub fn case_scene(r: &Resolved) -> Value {
    let (slave, master) = r.joint_groups();
    let mut joint = json!({"name": "J", "master": master, "slave": slave, "method": r.method.as_str(), "layer": r.layer, "mu": r.mu});
    if r.tied {
        joint["tied"] = json!(true);
    }
    if let Some(e) = r.edge_tolerance {
        joint["edge_tolerance"] = json!(e);
    }
    if let (Some(rc), true) = (r.curvature, r.slave_on_cylinder) {
        // a slave node on the cylinder lies off the master's chords by up to their sag
        // h_m²/(8|R|): the tagger accepts twice that
        joint["tolerance"] = json!(r.sizes().1.powi(2) / (4.0 * rc.abs()));
    }
    let (e, nu, rho) = match r.kind {
        Kind::Patch => (PATCH_E, 0.0, PATCH_RHO),
        Kind::Slide | Kind::Newmark => (SLIDE_E, SLIDE_NU, SLIDE_RHO),
        Kind::Impact => (BAR_E, 0.0, BAR_RHO),
    };
    if r.method == ContactMethod::Penalty {
        joint["penalty_stiffness"] = json!(r.penalty * e / r.sizes().0);
    }
    let mut lower = json!({"group": "block:lower", "E": e, "nu": nu, "rho": rho});
    if r.massless_lower {
        lower["massless"] = json!(true);
    }
    let materials = json!([lower, {"group": "block:upper", "E": e, "nu": nu, "rho": rho}]);
    let mut sc = json!({
        "name": format!("testcase-{:?}", r.kind).to_lowercase(),
        "geometry": {"msh": "case.msh"},
        "materials": materials,
        "joints": [joint],
    });
    match r.kind {
        Kind::Patch => {
            // `jointquake run` form of the static problem: the tractions ramped over 4 periods of
            // the lowest axial mode ω1 = π c / (2 H) with mass damping α = 2 ω1 (critical for that
            // mode), run for 4 more periods; `testcase --run` solves it statically instead.
            let c = (PATCH_E / PATCH_RHO).sqrt();
            let w1 = std::f64::consts::PI * c / (2.0 * 2.0 * PATCH_HEIGHT);
            let period = 2.0 * std::f64::consts::PI / w1;
            let tr: Vec<Value> = patch_tractions(r).into_iter().map(|(g, t)| json!({"group": g, "traction": t, "ramp": 4.0 * period})).collect();
            sc["boundary"] = json!([{"group": "lower:z0"}]);
            sc["loads"] = json!({"traction": tr});
            sc["damping"] = json!({"alpha": 2.0 * w1});
            sc["time"] = json!({"duration": 8.0 * period, "courant": 0.9});
        }
        Kind::Slide => {
            sc["boundary"] = json!([{"group": "lower:z0"}]);
            sc["loads"] = json!({"gravity": {"g": G}});
            sc["equilibrium"] = json!({"method": "none"});
            sc["time"] = json!({"duration": r.duration, "courant": 0.9});
        }
        Kind::Newmark => {
            // gravity relaxed first (the scene's default equilibrium), then the record along +x
            // (into the hill); stiffness damping ξ ≈ 0.1 % at 10 Hz against chatter (docs/contact.md)
            sc["boundary"] = json!([{"group": "lower:z0"}]);
            sc["loads"] = json!({"gravity": {"g": G}, "base": [{"record": r.record, "direction": [1.0, 0.0, 0.0], "pga": r.pga}]});
            sc["damping"] = json!({"beta": 3.2e-5});
            sc["time"] = json!({"duration": r.duration, "courant": 0.9});
        }
        Kind::Impact => {
            // scenes have no initial velocity: `testcase --run` starts the lower bar at v0
            sc["time"] = json!({"duration": 3.0 * BAR_L / (BAR_E / BAR_RHO).sqrt(), "courant": 0.9});
        }
    }
    sc
}

/// Files written by [`write_case`].
pub struct CaseFiles {
    pub msh: PathBuf,
    pub scene: PathBuf,
    pub reference: PathBuf,
}

/// Write `case.msh`, `scene.json` and `reference.json` (with the resolved options) into `dir`.
pub fn write_case(case: &Case, dir: &Path) -> Result<CaseFiles, Error> {
    let w = |p: &Path, e: std::io::Error| -> Error { crate::error::OutputError::write(p, e).into() };
    std::fs::create_dir_all(dir).map_err(|e| w(dir, e))?;
    let msh = dir.join("case.msh");
    crate::mesh::msh::write_msh41(&case.mesh, &msh).map_err(|e| w(&msh, e))?;
    let scene = dir.join("scene.json");
    std::fs::write(&scene, serde_json::to_string_pretty(&case.scene).expect("a scene serialises")).map_err(|e| w(&scene, e))?;
    let reference = dir.join("reference.json");
    let refj = json!({"case": case.spec, "reference": case.reference});
    std::fs::write(&reference, serde_json::to_string_pretty(&refj).expect("a reference serialises")).map_err(|e| w(&reference, e))?;
    Ok(CaseFiles { msh, scene, reference })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The in-plane map keeps the outline and moves the inside: interior grid lines by s·h, the
    /// inner half turned rigidly by θ about the centre (reference: the definitions on `CaseSpec`).
    #[test]
    fn shift_and_turn_keeps_the_outline_and_turns_the_inner_half() {
        let b = BoxSpec::new("upper", [1.0, 1.0, 0.5], [4, 4, 2]);
        // outline points stay, interior lines move by 0.3 × 0.25
        for (x, y) in [(0.0, 0.0), (1.0, 0.25), (0.5, 1.0), (0.0, 0.75)] {
            let (px, py) = shift_and_turn(&b, 0.3, 15.0, x, y);
            let moved_along = |v: f64, p: f64| if v > 0.0 && v < 1.0 { p - v - 0.075 } else { p - v };
            // on the outline (ρ = 1) the turn is 0 and only the interior coordinate shifts
            assert!(moved_along(x, px).abs() < 1e-12 && moved_along(y, py).abs() < 1e-12, "({x}, {y}) -> ({px}, {py})");
        }
        // (0.5, 0.25) is on an interior line in y: shifted to (0.575, 0.325), ρ = 0.35 ≤ ½: turned by θ
        let (px, py) = shift_and_turn(&b, 0.3, 15.0, 0.5, 0.25);
        let (dx, dy) = (0.075, -0.175);
        let (sn, cs) = 15f64.to_radians().sin_cos();
        assert!((px - (0.5 + cs * dx - sn * dy)).abs() < 1e-12 && (py - (0.5 + sn * dx + cs * dy)).abs() < 1e-12);
    }
}
