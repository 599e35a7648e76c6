//! The massed foundation models (`massed_fixed`, `radiating`; scene `foundation`, module
//! `crate::scene::foundation`): what they change in a problem.
//!
//! - [`scene_for_model`]: the rock's materials keep their density (their `massless` flag is
//!   dropped), so the model integrates the rock explicitly and its elements set the stable step.
//! - [`prepare_loads`]: the rock carries no weight unless `rock_weight` (its in-situ state
//!   predates the dam, as with the massless rock: the static states agree); `radiating` takes
//!   the base records out of the loads (no −M a_g: displacements are total) and builds the far
//!   boundary ([`super::radiating`]) and its free field ([`super::free_field`]). Notes say what
//!   was done, with the stable step of the massed rock and its critical element.
//!
//! The massless model (absent `foundation`, the seed's) goes through none of this.

use super::free_field::FreeField;
use super::radiating::{FarBoundary, FarFaces};
use crate::dynamics::loads::Loads;
use crate::error::{Error, ModelError};
use crate::mesh::pattern::{is_pattern, GroupPattern};
use crate::mesh::Mesh;
use crate::model::Model;
use crate::scene::foundation::{FoundationModel, FoundationScene, RockDamping};
use crate::scene::Scene;

/// The scene as the model is built: with a massed foundation, the rock's materials massed (and
/// `foundation.rock` set to them), and with `foundation.damping` "as_dam" the rock's groups
/// added to `damping.mass_groups` (when it names groups: otherwise every node carries αM).
pub fn scene_for_model(mut scene: Scene) -> Scene {
    let Some(f) = scene.foundation.as_mut().filter(|f| f.model.massed()) else { return scene };
    let rock: Vec<String> = f.rock_materials(&scene.materials).iter().map(|m| m.group.clone()).collect();
    // the rock named explicitly: its materials are no longer marked massless
    f.rock = Some(rock.clone());
    let as_dam = matches!(f.damping, RockDamping::AsDam);
    for m in scene.materials.iter_mut().filter(|m| rock.contains(&m.group)) {
        m.massless = false;
    }
    if let (true, Some(groups)) = (as_dam, scene.damping.mass_groups.as_mut()) {
        for g in &rock {
            if !groups.contains(g) {
                groups.push(g.clone());
            }
        }
    }
    scene
}

/// The massed rock's own stable step: the largest ω²_max of its elements (element eigenvalue
/// bound, lumped mass, no mass scaling) and that element's tag; (0, 0) for a rock without elements.
fn rock_critical(model: &Model, rock_groups: &[String]) -> (f64, u64) {
    let is_rock: Vec<bool> = model.materials.iter().map(|m| rock_groups.contains(&m.group) && m.rho > 0.0).collect();
    let mut best = (0.0f64, 0u64);
    for (e, g) in model.tets.geom.iter().enumerate() {
        let mi = model.tets.mat[e] as usize;
        if is_rock[mi] {
            let m = &model.materials[mi];
            let w2 = crate::model::tet4::max_eigenvalue(&g.grad, g.vol, m.rho, &m.lame);
            if w2 > best.0 {
                best = (w2, model.mesh.cells[model.tets.cell[e] as usize].tag);
            }
        }
    }
    for (e, &si) in model.hexes.shape.iter().enumerate() {
        let mi = model.hexes.mat[e] as usize;
        if is_rock[mi] {
            let m = &model.materials[mi];
            let w2 = crate::model::hex8::max_eigenvalue(&model.hexes.shapes[si as usize], m.rho, &m.lame);
            if w2 > best.0 {
                best = (w2, model.mesh.cells[model.hexes.cell[e] as usize].tag);
            }
        }
    }
    best
}

/// The massed rock's Rayleigh pair (α [1/s], β [s]): its own ([`Model::rock_damping`]), the
/// scene's with "as_dam", the scene's β alone with "stiffness_only". What its elements step
/// with and what its free-field columns are damped by.
fn rock_pair(model: &Model, f: &FoundationScene) -> (f64, f64) {
    match (&model.rock_damping, &f.damping) {
        (Some(r), _) => (r.alpha, r.beta),
        (None, RockDamping::StiffnessOnly) => (0.0, model.beta),
        _ => (model.alpha, model.beta),
    }
}

/// The far face groups: `far`'s names and patterns matched against the mesh's face groups.
pub fn far_groups(mesh: &Mesh, far: &[String]) -> Result<Vec<String>, ModelError> {
    let faces: Vec<&str> = mesh.groups.iter().filter(|g| g.dim == 2).map(|g| g.name.as_str()).collect();
    let mut out = Vec::new();
    for p in far {
        let found: Vec<String> = if is_pattern(p) {
            let gp = GroupPattern::parse(p).map_err(|e| ModelError::Invalid(format!("foundation.far: {e}")))?;
            gp.matches(faces.iter().copied()).map_err(|e| ModelError::Invalid(format!("foundation.far: {e}")))?.into_iter().map(|(n, _)| n).collect()
        } else {
            faces.iter().filter(|n| **n == p).map(|n| n.to_string()).collect()
        };
        if found.is_empty() {
            return Err(ModelError::Invalid(format!("foundation.far: \"{p}\" matches no face group (dimension 2) of the mesh; face groups: {}", faces.join(", "))));
        }
        out.extend(found.into_iter().filter(|n| !out.contains(n)).collect::<Vec<_>>());
    }
    Ok(out)
}

/// The rock of a massed model: its nodes and its one material (a uniform rock).
struct Rock<'m> {
    nodes: Vec<usize>,
    material: &'m crate::model::material::Material,
}

fn rock_of<'m>(model: &'m Model, f: &FoundationScene, scene: &Scene) -> Result<Rock<'m>, ModelError> {
    let groups: Vec<String> = f.rock_materials(&scene.materials).iter().map(|m| m.group.clone()).collect();
    let mats: Vec<&crate::model::material::Material> = model.materials.iter().filter(|m| groups.contains(&m.group)).collect();
    let Some(&first) = mats.first() else {
        return Err(ModelError::Invalid(format!("foundation: no rock material among the model's ({}); name it in foundation.rock", groups.join(", "))));
    };
    if let Some(m) = mats.iter().find(|m| m.rho <= 0.0) {
        return Err(ModelError::Invalid(format!("foundation \"{}\": the rock \"{}\" was built massless; build the problem with Problem::build (it masses the rock)", f.model.as_str(), m.group)));
    }
    if f.model == FoundationModel::Radiating && mats.iter().any(|m| m.e != first.e || m.nu != first.nu || m.rho != first.rho) {
        return Err(ModelError::Invalid("foundation \"radiating\": the free field assumes a uniform rock, but the rock's materials differ (E, nu or rho): give them one material".into()));
    }
    let mut nodes = Vec::new();
    for g in &groups {
        nodes.extend(model.mesh.group_nodes(g).map_err(|e| ModelError::Invalid(format!("foundation.rock: {e}")))?);
    }
    nodes.sort_unstable();
    nodes.dedup();
    Ok(Rock { nodes, material: first })
}

/// Adjust the loads of a massed model and build the radiating far boundary (module doc);
/// `None` for the massless and massed_fixed models.
pub fn prepare_loads(scene: &Scene, model: &Model, loads: &mut Loads, notes: &mut Vec<String>) -> Result<Option<FarBoundary>, Error> {
    let Some(f) = scene.foundation.as_ref().filter(|f| f.model.massed()) else { return Ok(None) };
    let rock = rock_of(model, f, scene)?;
    if !f.rock_weight && loads.gravity.is_some() && scene.loads.gravity.as_ref().is_some_and(|g| g.groups.is_none()) {
        let mut mask = loads.gravity_nodes.take().unwrap_or_else(|| vec![true; model.n_nodes()]);
        for &n in &rock.nodes {
            mask[n] = false;
        }
        loads.gravity_nodes = Some(mask);
    }
    if matches!(f.damping, RockDamping::StiffnessOnly) && scene.damping.mass_groups.is_none() && model.alpha > 0.0 {
        return Err(ModelError::Invalid("foundation.damping \"stiffness_only\": damping.mass_groups names no groups, so every node (the rock's too) carries αM; name the dam's volume groups there".into()).into());
    }
    let c = &model.critical;
    let groups: Vec<String> = f.rock_materials(&scene.materials).iter().map(|m| m.group.clone()).collect();
    let (alpha, beta) = rock_pair(model, f);
    let (w2, tag) = rock_critical(model, &groups);
    notes.push(format!(
        "foundation {}: rock massed ({} nodes, ρ {} kg/m³, c_p {:.0} m/s, c_s {:.0} m/s){}; rock damping {} (α {alpha:.4} 1/s, β {beta:.3e} s: ξ {:.2} % at 1 Hz); the rock's own stable step {:.4e} s, set by its element {tag}; stable step of all elements {:.4e} s, set by element {} in \"{}\"",
        f.model.as_str(),
        rock.nodes.len(),
        rock.material.rho,
        rock.material.wave_speed(),
        (rock.material.lame.mu / rock.material.rho).sqrt(),
        if f.rock_weight { ", with its weight" } else { ", weightless (in-situ state predates the dam)" },
        f.damping.as_str(),
        100.0 * (alpha / (4.0 * std::f64::consts::PI) + beta * std::f64::consts::PI),
        crate::model::damped_step(w2, alpha, beta),
        model.stable_dt(),
        c.tag,
        c.group
    ));
    if f.model != FoundationModel::Radiating {
        return Ok(None);
    }
    far_boundary(scene, f, model, &rock, loads, notes).map(Some)
}

/// The radiating far boundary: free field from the base records (taken out of `loads`).
fn far_boundary(scene: &Scene, f: &FoundationScene, model: &Model, rock: &Rock<'_>, loads: &mut Loads, notes: &mut Vec<String>) -> Result<FarBoundary, Error> {
    let mesh = &model.mesh;
    let groups = far_groups(mesh, &f.far)?;
    let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
    for &n in &rock.nodes {
        for c in 0..3 {
            lo[c] = lo[c].min(mesh.nodes[n][c]);
            hi[c] = hi[c].max(mesh.nodes[n][c]);
        }
    }
    let surface = f.surface.unwrap_or(hi[2]);
    let height = surface - lo[2];
    if !(height > 0.0) {
        return Err(ModelError::Invalid(format!("foundation.surface = {surface} m is not above the rock's base (z = {} m)", lo[2])).into());
    }
    let (alpha, beta) = rock_pair(model, f);
    let base = std::mem::take(&mut loads.base);
    let f_max = f.max_frequency.unwrap_or(super::free_field::DEFAULT_MAX_FREQUENCY);
    let ff = FreeField::build(&base, rock.material, surface, height, alpha, beta, f_max);
    // components the far groups' boundary entries hold (and no other entry does)
    let mut far_bits = vec![0u8; model.n_nodes()];
    let mut other_bits = vec![0u8; model.n_nodes()];
    for b in &scene.boundary {
        let bits = b.fix.iter().fold(0u8, |acc, c| acc | match c.as_str() { "x" => 1, "y" => 2, _ => 4 });
        let target = if groups.contains(&b.group) { &mut far_bits } else { &mut other_bits };
        for n in mesh.group_nodes(&b.group)? {
            target[n] |= bits;
        }
    }
    let released: Vec<u8> = far_bits.iter().zip(&other_bits).map(|(&a, &b)| a & !b).collect();
    let m = rock.material;
    let centre = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])];
    let faces = FarFaces {
        model,
        groups: &groups,
        rho: m.rho,
        cp: m.wave_speed(),
        cs: (m.lame.mu / m.rho).sqrt(),
        shear_modulus: m.lame.mu,
        springs: f.springs.then_some(f.spring_distance),
        source: [centre[0], centre[1], surface],
        inside: centre,
    };
    let far = FarBoundary::build(&faces, ff, &released)?;
    notes.push(format!(
        "foundation radiating: {} far faces ({} m², groups {}), {} nodes with Lysmer dashpots{}; free field from {} base record(s) as the surface motion at z = {surface} m, low-passed at {f_max} Hz and deconvolved through a {height:.1} m uniform column (vertical S for x, y; P for z; Rayleigh α {alpha:.4} 1/s, β {beta:.3e} s as the rock); the surface record plays at t − {:.3} s",
        far.faces,
        far.area,
        groups.join(", "),
        far.nodes.len(),
        if f.springs { " and springs (4/3, 2/3 G/R)" } else { "" },
        base.len(),
        far.free_field.delay
    ));
    Ok(far)
}
