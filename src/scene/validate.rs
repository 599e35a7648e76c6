//! Scene::validate: the checks that need no mesh, one function per scene section (group
//! names are checked against the mesh when the model is built).
//!
//! Each section's function returns the first problem as a message naming the field, its value
//! and what is accepted; `Scene::load` wraps it with the scene file's path.

use super::*;

impl Scene {
    /// Checks that need no mesh (group names are checked against the mesh when the model is built).
    pub fn validate(&self) -> Result<(), String> {
        validate_geometry(&self.geometry)?;
        check_file_name("name", self.name())?;
        validate_materials(&self.materials)?;
        validate_boundary(&self.boundary)?;
        self.foundation.as_ref().map_or(Ok(()), |f| f.validate(&self.materials))?;
        validate_base(&self.loads.base)?;
        validate_static_loads(&self.loads)?;
        validate_time(&self.time)?;
        validate_equilibrium(&self.equilibrium)?;
        validate_output(&self.output)?;
        validate_joints(&self.joints)?;
        validate_damping(&self.damping)?;
        if let Some(r) = &self.reservoir {
            validate_reservoir(r)?;
        }
        if !(self.g > 0.0) {
            return Err(format!("g = {} must be positive [m/s²]", self.g));
        }
        check_range("g", self.g, G_RANGE, "m/s²")?;
        Ok(())
    }
}

fn validate_geometry(g: &Geometry) -> Result<(), String> {
    match (&g.geo, &g.msh) {
        (Some(_), Some(_)) => return Err("geometry: give either `geo` or `msh`, not both".into()),
        (None, None) => return Err("geometry: give `geo` (a Gmsh script) or `msh` (a mesh file)".into()),
        _ => {}
    }
    if g.msh.is_some() && !g.set.is_empty() {
        return Err("geometry.set: `-setnumber` parameters apply to a `.geo`, but this scene reads a ready `msh`. Remove `set`, or mesh the `.geo` instead.".into());
    }
    for (k, v) in &g.set {
        if !v.is_finite() {
            return Err(format!("geometry.set.{k} = {v} must be a finite number"));
        }
    }
    Ok(())
}

fn validate_materials(materials: &[MaterialSpec]) -> Result<(), String> {
    if materials.is_empty() {
        return Err("materials: at least one material group is needed".into());
    }
    for m in materials {
        if !(m.e > 0.0 && m.e.is_finite()) {
            return Err(format!("material \"{}\": E = {} must be positive [Pa]", m.group, m.e));
        }
        if !(E_RANGE.0..=E_RANGE.1).contains(&m.e) {
            return Err(format!(
                "material \"{}\": E = {:e} Pa is outside {:e}–{:e} Pa (soft soil to diamond). Young's modulus is in Pa: 30 GPa is 30e9.",
                m.group, m.e, E_RANGE.0, E_RANGE.1
            ));
        }
        if !(0.0..0.5).contains(&m.nu) {
            return Err(format!("material \"{}\": nu = {} must be in [0, 0.5)", m.group, m.nu));
        }
        if !(m.rho >= 0.0 && m.rho.is_finite()) {
            return Err(format!("material \"{}\": rho = {} must be ≥ 0 [kg/m³]", m.group, m.rho));
        }
        if m.rho == 0.0 && !m.massless {
            return Err(format!("material \"{}\": rho = 0; a block without mass is declared with `\"massless\": true` (a massless foundation, condensed statically), else give its density", m.group));
        }
        if m.rho > 0.0 && !(RHO_RANGE.0..=RHO_RANGE.1).contains(&m.rho) {
            return Err(format!(
                "material \"{}\": rho = {:e} kg/m³ is outside {:e}–{:e} kg/m³. Density is in kg/m³ (rock about 2000–3000).",
                m.group, m.rho, RHO_RANGE.0, RHO_RANGE.1
            ));
        }
    }
    Ok(())
}

fn validate_boundary(boundary: &[BoundarySpec]) -> Result<(), String> {
    for b in boundary {
        for c in &b.fix {
            if !matches!(c.as_str(), "x" | "y" | "z") {
                return Err(format!("boundary \"{}\": component \"{c}\" must be \"x\", \"y\" or \"z\"", b.group));
            }
        }
    }
    Ok(())
}

/// The length of a direction vector, when it is a usable (non-zero, finite) one.
fn direction_norm(d: &[f64; 3]) -> Option<f64> {
    let n = (d[0].powi(2) + d[1].powi(2) + d[2].powi(2)).sqrt();
    (n > 0.0 && n.is_finite()).then_some(n)
}

fn validate_base(base: &[BaseRecord]) -> Result<(), String> {
    if base.len() > 3 {
        return Err(format!("loads.base: {} records given, at most 3", base.len()));
    }
    for (k, b) in base.iter().enumerate() {
        let l = b.label(k);
        match (&b.record, &b.synth) {
            (Some(_), Some(_)) => return Err(format!("{l}: give `record` (a file) or `synth` (a generated record), not both")),
            (None, None) => return Err(format!("{l}: give `record` (a two-column or .AT2 file) or `synth` (a target spectrum and a seed)")),
            _ => {}
        }
        if let Some(s) = &b.synth {
            if s.pga.is_none() && b.pga.is_none() {
                return Err(format!("{l}: a synth entry needs the set's design PGA: give the entry's `pga` [g] (or `synth.pga`, the horizontal PGA the spectrum is drawn for, with `scale`)"));
            }
            validate_synth(&l, s)?;
        }
        b.baseline.resolve().map_err(|e| format!("{l}: {e}"))?;
        if b.scale.is_some() && b.pga.is_some() {
            return Err(format!("{l}: give `scale` or `pga`, not both"));
        }
        if direction_norm(&b.direction).is_none() {
            return Err(format!("{l}: direction must be a non-zero vector"));
        }
        if let Some(pga) = b.pga {
            if !(pga > 0.0 && pga.is_finite()) {
                return Err(format!("{l}: pga = {pga} must be positive [g]. To reverse the record's polarity, reverse its `direction`."));
            }
        }
        if let Some(sc) = b.scale {
            if !(sc > 0.0 && sc.is_finite()) {
                return Err(format!("{l}: scale = {sc} must be positive. To reverse the record's polarity, reverse its `direction`."));
            }
            check_range(&format!("{l}: scale"), sc, (0.0, MAX_SCALE), "(multiplier)")?;
        }
        if let Some(pga) = b.pga {
            check_range(&format!("{l}: pga"), pga, (0.0, MAX_PGA), "g")?;
        }
        check_finite_vector(&format!("{l}: direction"), &b.direction, MAX_COORD)?;
    }
    Ok(())
}

/// A generated record's own fields: its PGA, and its length and step through the one rule of
/// `record synth` (`motion::synth::check_sampling`), so a scene is refused as the command is.
fn validate_synth(l: &str, s: &BaseSynth) -> Result<(), String> {
    if let Some(p) = s.pga {
        check_range(&format!("{l}: synth.pga"), p, (f64::MIN_POSITIVE, MAX_PGA), "g")?;
    }
    // the ranges of dt and duration are `record synth`'s, checked when the record is made
    crate::motion::synth::check_sampling(s.duration, s.dt, "synth.dt").map_err(|e| format!("{l}: {e}"))
}

fn validate_static_loads(loads: &Loads) -> Result<(), String> {
    if let Some(g) = &loads.gravity {
        if direction_norm(&g.direction).is_none() {
            return Err(format!("loads.gravity.direction = {:?} must be a non-zero vector (default [0, 0, -1])", g.direction));
        }
        if !(g.g > 0.0 && g.g.is_finite()) {
            return Err(format!("loads.gravity.g = {} must be positive [m/s²] (default 9.81); the direction gives the sense", g.g));
        }
        check_range("loads.gravity.g", g.g, G_RANGE, "m/s²")?;
        check_finite_vector("loads.gravity.direction", &g.direction, MAX_COORD)?;
        if let Some(groups) = &g.groups {
            check_no_repeat("loads.gravity.groups", groups, "its weight would count twice")?;
        }
    }
    for (k, t) in loads.traction.iter().enumerate() {
        check_load(&format!("loads.traction[{k}] (group \"{}\")", t.group), "traction", &t.traction, MAX_TRACTION, "Pa", t.ramp)?;
    }
    for (k, f) in loads.nodal.iter().enumerate() {
        check_load(&format!("loads.nodal[{k}]"), "force", &f.force, MAX_FORCE, "N", f.ramp)?;
        check_finite_vector(&format!("loads.nodal[{k}].point"), &f.point, MAX_COORD)?;
    }
    Ok(())
}

fn validate_time(time: &TimeSpec) -> Result<(), String> {
    if !(time.duration >= 0.0 && time.duration.is_finite()) {
        return Err(format!("time.duration = {} must be ≥ 0 [s]", time.duration));
    }
    if let Some(dt) = time.dt {
        if !(dt > 0.0 && dt.is_finite()) {
            return Err(format!("time.dt = {dt} must be positive [s]"));
        }
    }
    if let Some(c) = time.courant {
        if !(c > 0.0 && c <= 1.0) {
            return Err(format!("time.courant = {c} must be in (0, 1]"));
        }
    }
    if let Some(ms) = &time.mass_scaling {
        if !(ms.target_dt > 0.0 && ms.target_dt.is_finite()) {
            return Err(format!("time.mass_scaling.target_dt = {} must be positive and finite [s] (the step the scaled elements should allow; remove `mass_scaling` to run without)", ms.target_dt));
        }
    }
    if !(time.energy_tolerance > 0.0 && time.energy_tolerance.is_finite()) {
        return Err(format!("time.energy_tolerance = {} must be positive (default 0.05)", time.energy_tolerance));
    }
    if time.dt.is_some() && time.courant.is_some() {
        return Err("time: give `dt` or `courant`, not both".into());
    }
    check_range("time.energy_tolerance", time.energy_tolerance, (0.0, MAX_ENERGY_TOLERANCE), "(fraction of the energy scale)")?;
    if let Some(ms) = &time.mass_scaling {
        check_range("time.mass_scaling.target_dt", ms.target_dt, (0.0, MAX_DT), "s")?;
    }
    if let Some(dt) = time.dt {
        check_range("time.dt", dt, (0.0, MAX_DT), "s")?;
        if time.duration > 0.0 && dt > 2.0 * time.duration {
            return Err(format!(
                "time.dt = {dt} s is more than twice time.duration = {} s: the run would take no dynamic step. Give a smaller dt (or leave it out: the stable step is used), or a longer duration",
                time.duration
            ));
        }
    }
    if time.max_steps > MAX_MAX_STEPS {
        return Err(format!("time.max_steps = {} is above the limit {MAX_MAX_STEPS:e} (weeks of computing on one core)", time.max_steps));
    }
    Ok(())
}

fn validate_equilibrium(eq: &EquilibriumSpec) -> Result<(), String> {
    if !(eq.tolerance > 0.0 && eq.tolerance.is_finite()) {
        return Err(format!("equilibrium.tolerance = {} must be positive (default 1e-6)", eq.tolerance));
    }
    if !(eq.max_residual > 0.0 && eq.max_residual.is_finite()) {
        return Err(format!("equilibrium.max_residual = {} must be positive (default 1e-3)", eq.max_residual));
    }
    check_range("equilibrium.tolerance", eq.tolerance, (0.0, 1.0), "(relative residual)")?;
    check_range("equilibrium.max_residual", eq.max_residual, (0.0, 1.0), "(relative residual)")?;
    if eq.max_steps > MAX_RELAX_STEPS {
        return Err(format!("equilibrium.max_steps = {} is above the limit {MAX_RELAX_STEPS:e}", eq.max_steps));
    }
    Ok(())
}

fn validate_output(out: &OutputSpec) -> Result<(), String> {
    if let Some(e) = &out.envelope {
        if e.faces.is_empty() || e.stride == 0 {
            return Err("output.envelope: give at least one face group in `faces` and a `stride` ≥ 1 [steps]".into());
        }
        check_no_repeat("output.envelope.faces", &e.faces, "its envelope would be written twice")?;
    }
    if out.frame_stride.is_some() && out.frame_interval.is_some() {
        return Err("output: give `frame_stride` or `frame_interval`, not both".into());
    }
    if let Some(fi) = out.frame_interval {
        if !(fi > 0.0 && fi.is_finite()) {
            return Err(format!("output.frame_interval = {fi} must be positive [s]"));
        }
    }
    if out.history_stride.is_some() && out.history_interval.is_some() {
        return Err("output: give `history_stride` or `history_interval`, not both".into());
    }
    if let Some(hi) = out.history_interval {
        if !(hi.is_finite() && hi > 0.0) {
            return Err(format!("output.history_interval = {hi} must be a positive time [s]"));
        }
    }
    if out.frame_stride == Some(0) {
        return Err("output.frame_stride must be at least 1".into());
    }
    for (name, v) in [("output.frame_interval", out.frame_interval), ("output.history_interval", out.history_interval)] {
        if let Some(x) = v {
            check_range(name, x, (0.0, MAX_DURATION), "s")?;
        }
    }
    let mut monitors = std::collections::BTreeSet::new();
    for m in &out.monitor {
        check_file_name("output.monitor name", &m.name)?;
        check_finite_vector(&format!("output.monitor \"{}\": point", m.name), &m.point, MAX_COORD)?;
        if !monitors.insert(m.name.as_str()) {
            return Err(format!("output.monitor: two monitors are named \"{}\" (each writes histories/{}.csv): give each its own name", m.name, m.name));
        }
    }
    Ok(())
}

fn validate_joints(joints: &[JointSceneSpec]) -> Result<(), String> {
    for j in joints {
        if j.mu.is_some() && j.phi.is_some() {
            return Err(format!("joint \"{}\": give `mu` or `phi`, not both", j.name));
        }
    }
    let mut joint_stems: BTreeMap<String, &str> = BTreeMap::new();
    let mut joint_sides = BTreeMap::new();
    for j in joints {
        if j.name.is_empty() {
            return Err("joints: a joint has an empty `name`".into());
        }
        let stem = crate::files::file_stem(&j.name);
        if let Some(other) = joint_stems.get(&stem) {
            return Err(format!("joint \"{}\": its output file name \"{stem}.vtu\" is also that of joint \"{other}\"; give the joints distinct names", j.name));
        }
        joint_stems.insert(stem, j.name.as_str());
        let key = if j.master <= j.slave { (j.master.as_str(), j.slave.as_str()) } else { (j.slave.as_str(), j.master.as_str()) };
        if let Some(other) = joint_sides.insert(key, j.name.as_str()) {
            return Err(format!(
                "joints \"{other}\" and \"{}\" both join \"{}\" and \"{}\": the contact would be applied twice. Keep one.",
                j.name, key.0, key.1
            ));
        }
        if j.master == j.slave {
            return Err(format!("joint \"{}\": master and slave are the same group \"{}\"", j.name, j.master));
        }
        validate_joint_numbers(j)?;
    }
    Ok(())
}

/// The numbers of one joint within their physical ranges (the signs and the layer are checked
/// again where the law is built, `contact::joint`).
fn validate_joint_numbers(j: &JointSceneSpec) -> Result<(), String> {
    let f = |field: &str| format!("joint \"{}\": {field}", j.name);
    let bounded = [
        ("tolerance", j.tolerance, (0.0, MAX_COORD), "m"),
        ("mu", j.mu, (0.0, MAX_MU), "(friction coefficient)"),
        ("phi", j.phi, (0.0, MAX_PHI_DEG), "deg"),
        ("cohesion", j.cohesion, (0.0, MAX_STRENGTH), "Pa"),
        ("tensile_strength", j.tensile_strength, (0.0, MAX_STRENGTH), "Pa"),
        ("softening_slip", j.softening_slip, (0.0, MAX_COORD), "m"),
        ("penalty_stiffness", j.penalty_stiffness, (0.0, MAX_PENALTY), "Pa/m"),
        ("edge_tolerance", j.edge_tolerance, (0.0, 0.5), "(fraction of the face size)"),
    ];
    for (field, v, range, unit) in bounded {
        if let Some(x) = v {
            check_range(&f(field), x, range, unit)?;
        }
    }
    if let Some(t) = j.tolerance {
        if t <= 0.0 {
            return Err(format!("{} = {t} must be positive [m]", f("tolerance")));
        }
    }
    validate_asperity_angle(j)
}

/// A joint's `asperity_angle` (the bilinear envelope, `JointSceneSpec::asperity_angle`): i in
/// (0, 90° − φ) so that tan(φ + i) is finite and above tan φ, on a joint with cohesion (else the
/// knee is at σ = 0 and the envelope is the Coulomb line), without tensile strength (the
/// envelope carries no shear without compression, which a bond in tension contradicts), not
/// tied (a tie has no shear limit).
fn validate_asperity_angle(j: &JointSceneSpec) -> Result<(), String> {
    let Some(i) = j.asperity_angle else { return Ok(()) };
    let field = format!("joint \"{}\": asperity_angle", j.name);
    let phi = j.friction().phi_deg();
    if !(i.is_finite() && i > 0.0 && i < 90.0 - phi) {
        return Err(format!("{field} = {i} deg must be in (0, 90 - phi) = (0, {:.3}) deg for this joint's phi = {phi:.3} deg (tan(phi + i) must be finite and above tan phi): give the joint's measured first-order asperity angle (typically 5-20 deg), or remove it for the Mohr-Coulomb cone", 90.0 - phi));
    }
    if j.cohesion.unwrap_or(0.0) <= 0.0 {
        return Err(format!("{field} needs `cohesion` > 0 (with c = 0 the envelope's knee is at 0 and it is the Coulomb line): give the joint's cohesion [Pa], or remove asperity_angle"));
    }
    if j.tensile_strength.unwrap_or(0.0) > 0.0 {
        return Err(format!("{field} and `tensile_strength` exclude each other (the envelope carries no shear without compression; a bond in tension contradicts it): remove one of them"));
    }
    if j.tied == Some(true) {
        return Err(format!("{field} on a tied joint has no effect (a tie has no shear limit): remove one of them"));
    }
    Ok(())
}

fn validate_damping(d: &Damping) -> Result<(), String> {
    d.coefficients()?;
    for (field, v, max, unit) in [("alpha", d.alpha, MAX_ALPHA, "1/s"), ("beta", d.beta, MAX_BETA, "s"), ("f1", d.f1, MAX_FREQUENCY, "Hz"), ("f2", d.f2, MAX_FREQUENCY, "Hz")] {
        if let Some(x) = v {
            check_range(&format!("damping.{field}"), x, (0.0, max), unit)?;
        }
    }
    if let Some(g) = &d.mass_groups {
        check_no_repeat("damping.mass_groups", g, "a repeat is not a larger damping")?;
    }
    Ok(())
}

fn validate_reservoir(r: &ReservoirScene) -> Result<(), String> {
    if r.faces.is_empty() {
        return Err("reservoir.faces: name at least one wet face group".into());
    }
    if !(r.rho_w > 0.0 && r.rho_w.is_finite()) {
        return Err(format!("reservoir.rho_w = {} must be positive [kg/m³]", r.rho_w));
    }
    if !r.level.is_finite() {
        return Err("reservoir.level must be a finite height [m]".into());
    }
    if let Some(b) = r.bottom {
        if !(b < r.level) {
            return Err(format!("reservoir.bottom = {b} m must be below the pool level {} m", r.level));
        }
        check_range("reservoir.bottom", b, (-MAX_ELEVATION, MAX_ELEVATION), "m")?;
    }
    check_range("reservoir.level", r.level, (-MAX_ELEVATION, MAX_ELEVATION), "m")?;
    check_range("reservoir.rho_w", r.rho_w, RHO_W_RANGE, "kg/m³")?;
    check_no_repeat("reservoir.faces", &r.faces, "its water pressure and added mass would be applied twice")?;
    super::reservoir::validate(r.model, r.fluid.as_ref(), r.added_mass_depth)?;
    Ok(())
}

/// `value` finite and within `range` (inclusive), else an error naming `field`, the value, the
/// range and the unit: the one form of every bound below.
fn check_range(field: &str, value: f64, range: (f64, f64), unit: &str) -> Result<(), String> {
    if !(value >= range.0 && value <= range.1) {
        return Err(format!("{field} = {value:e} is outside the accepted range [{:e}, {:e}] {unit} (docs/scenes.md)", range.0, range.1));
    }
    Ok(())
}

/// Every component of `v` finite and at most `max` in size.
fn check_finite_vector(field: &str, v: &[f64; 3], max: f64) -> Result<(), String> {
    if v.iter().any(|c| !(c.abs() <= max)) {
        return Err(format!("{field} = {v:?} must be finite with components of at most {max:e}"));
    }
    Ok(())
}

/// A list of groups where a repeat would change the physics (or the outputs): refused, naming
/// the group and `why`.
fn check_no_repeat(field: &str, list: &[String], why: &str) -> Result<(), String> {
    let mut seen = std::collections::BTreeSet::new();
    for g in list {
        if !seen.insert(g.as_str()) {
            return Err(format!("{field}: \"{g}\" is listed twice ({why}); list each group once"));
        }
    }
    Ok(())
}

/// Standard gravity `g` and `loads.gravity.g` accepted [m/s²]: 0.1 to 100, from a small moon to
/// ten times the Earth's, the range of the record commands' `--g` (one definition there).
/// Outside, the unit is wrong (1e300 ran to inf peaks, issue 33).
pub const G_RANGE: (f64, f64) = crate::motion::commands::G_RANGE;
/// Largest peak ground acceleration (`pga`, `synth.pga`) [g]: 10, more than twice the largest
/// ever recorded (about 4 g); beyond it the unit is wrong (1e300 ran to inf peaks).
pub const MAX_PGA: f64 = 10.0;
/// Largest `scale` of a record [-]: 100 (a record in cm/s² read as g would need 1/981; a
/// scale above 100 is a unit mistake, and 1e300 ran to inf peaks).
pub const MAX_SCALE: f64 = 100.0;
/// Largest coordinate or length a scene may give [m] (points, directions, tolerances,
/// softening slip): 10⁷, the size of the Earth; keeps every distance far inside f64.
pub const MAX_COORD: f64 = 1e7;
/// Largest |elevation| of a pool level or reservoir bottom [m]: 10⁵, beyond any site on Earth
/// (a level of 1e308 reached an assertion in the mass assembly, issue 33).
pub const MAX_ELEVATION: f64 = 1e5;
/// Water density accepted [kg/m³]: 500 to 3000, from light oil to a heavy mud (fresh water
/// 1000, sea water 1025).
pub const RHO_W_RANGE: (f64, f64) = (500.0, 3000.0);
/// Largest time step and `mass_scaling.target_dt` [s]: 1 (a step of a second resolves no
/// earthquake frequency).
pub const MAX_DT: f64 = 1.0;
/// Largest output interval (`frame_interval`, `history_interval`) [s]: 10⁶ (11.6 days).
pub const MAX_DURATION: f64 = 1e6;
/// Largest `time.energy_tolerance` [-]: 10 (an error ten times the energy scale; above it the
/// check is off in all but name).
pub const MAX_ENERGY_TOLERANCE: f64 = 10.0;
/// Largest `time.max_steps`: 10¹² (weeks of a 10⁴-element model on one core).
pub const MAX_MAX_STEPS: u64 = 1_000_000_000_000;
/// Largest `equilibrium.max_steps`: 10⁹.
pub const MAX_RELAX_STEPS: usize = 1_000_000_000;
/// Largest Rayleigh α [1/s]: 10⁴ (critical damping of a 800 Hz mode; the joint-test rig uses
/// 3142); β [s]: 1 (critical damping at 0.3 Hz, far below any structure's modes); `f1`, `f2`
/// [Hz]: 10⁴. Beyond these the stable step overflowed and the run said "no element has mass".
pub const MAX_ALPHA: f64 = 1e4;
pub const MAX_BETA: f64 = 1.0;
pub const MAX_FREQUENCY: f64 = 1e4;
/// Largest joint friction coefficient μ [-]: 10 (φ = 84°), and angle φ [deg]: 89.
pub const MAX_MU: f64 = 10.0;
pub const MAX_PHI_DEG: f64 = 89.0;
/// Largest joint cohesion and tensile strength [Pa]: 10¹⁰ (ten times the strongest rock).
pub const MAX_STRENGTH: f64 = 1e10;
/// Largest penalty stiffness [Pa/m]: 10¹⁶ (10⁵ E/h for E = 100 GPa, h = 1 m).
pub const MAX_PENALTY: f64 = 1e16;

/// Young's modulus accepted [Pa]: 1 kPa (a very soft soil) to 10 TPa (ten times diamond). Outside
/// this the input is in the wrong unit, and the stable step becomes absurd (E 1e307 Pa would
/// take ~10¹⁵⁰ steps a second; E 1e-300 Pa no step at all).
pub const E_RANGE: (f64, f64) = (1e3, 1e13);
/// Density accepted when positive [kg/m³]: 1 (air) to 10⁵ (five times osmium). 0 is allowed
/// (a block without mass). Below, the stable step is NaN or absurd (rho 1e-300 gave dt = NaN).
pub const RHO_RANGE: (f64, f64) = (1.0, 1e5);
/// Largest traction component accepted [Pa] (10⁴ GPa) and nodal force [N]: beyond these the
/// run overflows to inf (a 1e300 N force gave inf peaks and `null` in summary.json).
pub const MAX_TRACTION: f64 = 1e13;
pub const MAX_FORCE: f64 = 1e15;

/// A load's vector within `max` and its ramp a finite time ≥ 0 [s].
fn check_load(what: &str, field: &str, v: &[f64; 3], max: f64, unit: &str, ramp: f64) -> Result<(), String> {
    if v.iter().any(|c| !(c.abs() <= max)) {
        return Err(format!("{what}: {field} = {v:?} must be finite with components of at most {max:e} {unit}"));
    }
    if !(ramp >= 0.0 && ramp.is_finite()) {
        return Err(format!("{what}: ramp = {ramp} must be a finite time ≥ 0 [s] (0 = step load)"));
    }
    Ok(())
}

/// A name that becomes a file name (scene → `<name>.pvd`, monitor → `histories/<name>.csv`):
/// letters, digits, `_`, `-`, `.`, `:`, `+`, not starting with `.`, 1–100 characters, so that
/// no name writes outside the output directory or makes a hidden file.
pub fn check_file_name(field: &str, name: &str) -> Result<(), String> {
    if name.is_empty() || !crate::files::is_file_stem(name) {
        return Err(format!(
            "{field} \"{name}\" becomes a file name: use 1–100 letters, digits, `_`, `-`, `.` or `+`, not starting with `.` (no `/`, spaces or `..`)"
        ));
    }
    Ok(())
}

