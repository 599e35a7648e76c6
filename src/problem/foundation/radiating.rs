//! The radiating foundation's far boundary: Lysmer dashpots (optionally springs) and the free
//! field's effective forces on the far faces (issue 29; docs/dam_physics.md "Foundation models").
//!
//! Per far node i, from its faces a (outward unit normal n_a, nodal area w_a = ∫ N_i dA):
//! - dashpot C_i = Σ w_a (ρ c_p n nᵀ + ρ c_s (I − n nᵀ)) (Lysmer & Kuhlemeyer 1969: exact for
//!   plane waves at normal incidence);
//! - spring K_i = Σ w_a G/R_a (4/3 n nᵀ + 2/3 (I − n nᵀ)) with `foundation.springs` (the
//!   viscous-spring boundary of Liu, Du et al. 2006, R_a the distance to the scattering source);
//! - effective force F_i(t) = σ_ff(z_i, t) N_i + C_i v_ff(z_i, t) + K_i u_ff(z_i, t),
//!   N_i = Σ w_a n_a: the free field's traction plus the boundary's force on the free field's
//!   motion, so that the boundary absorbs only what the structure scatters. On the bottom of a
//!   vertically incident wave this is the Lysmer/Joyner–Chen input 2 ρ c v_in w.
//! Equation at a far node: m ü + (K u)_i = f_i + H_i + F_i(t) − C_i u̇ − K_i (u − u⁰), with H_i the
//! static reaction of the far boundary at the start of the dynamic stage (the far groups'
//! `boundary` entries hold them through gravity; the reactions then stand for the rock below,
//! whose in-situ state predates the dam) and u⁰ the static displacement there.
//!
//! Time integration: the dashpot with the central velocity (u[n+1] − u[n−1]) / 2dt, solved per
//! node after the prediction (a 3 × 3 system: (m/dt² I + C/2dt) u[n+1] = m ũ/dt² + C u[n−1]/2dt),
//! so it is unconditionally stable and sets no step; its work, Δu_c · (−C v_c) ≤ 0, goes to the
//! correction's work. F, H and the springs enter the external force at t[n] (external work).
//! The springs add k/m to ω²_max ([`FarBoundary::omega2_bound`]).
//!
//! Displacements are total (not relative to a moving base): the scene's base records are not
//! applied as −M a_g; they are the free field's surface motion (`free_field`).

use super::free_field::FreeField;
use crate::constraint::{Constraint, ConstraintInfo, StepContext};
use crate::dynamics::loads::Loads;
use crate::interface::{face_nodal_weights_into, FaceWeights};
use crate::error::{ModelError, StepError};
use crate::mesh::CellKind;
use crate::model::Model;
use crate::motion::column::DepthWeight;
use nalgebra::{Matrix3, Vector3};

/// Spring coefficients of the viscous-spring boundary (Liu et al. 2006): k_n = 4/3 G/R and
/// k_t = 2/3 G/R per unit area (their α_N = 1.33, α_T = 0.67, recommended for 3-D).
pub const SPRING_NORMAL: f64 = 4.0 / 3.0;
pub const SPRING_TANGENT: f64 = 2.0 / 3.0;

/// The far boundary of a radiating foundation: built once (immutable).
#[derive(Clone, Debug)]
pub struct FarBoundary {
    /// Far nodes (mesh indices), ascending.
    pub nodes: Vec<usize>,
    pub dashpot: Vec<Matrix3<f64>>,
    /// Springs (empty without `foundation.springs`).
    pub spring: Vec<Matrix3<f64>>,
    /// N_i = Σ w_a n_a [m²].
    pub normal_area: Vec<Vector3<f64>>,
    pub depth: Vec<DepthWeight>,
    pub free_field: FreeField,
    /// The held components of the dynamic stage: the model's, with the far groups' released.
    pub dynamic_held: Vec<u8>,
    /// Faces of the far groups and their total area [m²] (for the notes).
    pub faces: usize,
    pub area: f64,
}

/// The geometry of the far faces: per node its dashpot, spring and N (module doc).
pub struct FarFaces<'a> {
    pub model: &'a Model,
    /// Far face groups (plain names, patterns expanded).
    pub groups: &'a [String],
    /// ρ [kg/m³], c_p, c_s [m/s], G [Pa] of the rock.
    pub rho: f64,
    pub cp: f64,
    pub cs: f64,
    pub shear_modulus: f64,
    /// `Some(R)`: springs with R [m] (`None` for R: each face's distance to `source`).
    pub springs: Option<Option<f64>>,
    /// The scattering source's position for the default R [m].
    pub source: [f64; 3],
    /// Inside the rock (the outward normal points away from it) [m].
    pub inside: [f64; 3],
}

/// (nodes, dashpots, springs, N, faces, area) of the far faces.
type FaceSums = (Vec<usize>, Vec<Matrix3<f64>>, Vec<Matrix3<f64>>, Vec<Vector3<f64>>, usize, f64);

impl FarFaces<'_> {
    fn sums(&self) -> Result<FaceSums, ModelError> {
        let mesh = &self.model.mesh;
        let mut index = vec![usize::MAX; mesh.nodes.len()];
        let (mut nodes, mut c, mut k, mut na) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let (mut faces, mut area) = (0usize, 0.0);
        let inside = Vector3::from(self.inside);
        for g in self.groups {
            let grp = mesh.group_of_dim(g, 2).map_err(|e| ModelError::Invalid(format!("foundation.far: {e}")))?;
            for &ci in &grp.cells {
                let cell = &mesh.cells[ci];
                if !matches!(cell.kind, CellKind::Tri3 | CellKind::Quad4) {
                    return Err(ModelError::Invalid(format!("foundation.far: element {} of \"{g}\" is not a tri3 or quad4 face", cell.tag)));
                }
                let x: Vec<Vector3<f64>> = cell.nodes().iter().map(|&n| mesh.x(n as usize)).collect();
                let nv = if cell.kind == CellKind::Tri3 { (x[1] - x[0]).cross(&(x[2] - x[0])) } else { (x[2] - x[0]).cross(&(x[3] - x[1])) };
                let centre = x.iter().sum::<Vector3<f64>>() / x.len() as f64;
                let Some(mut n) = nv.try_normalize(0.0) else {
                    return Err(ModelError::Invalid(format!("foundation.far: face element {} of \"{g}\" has zero area", cell.tag)));
                };
                if n.dot(&(centre - inside)) < 0.0 {
                    n = -n;
                }
                let nn = n * n.transpose();
                let tt = Matrix3::identity() - nn;
                let cf = nn * (self.rho * self.cp) + tt * (self.rho * self.cs);
                let kf = self.springs.map(|r| {
                    let r = r.unwrap_or_else(|| (centre - Vector3::from(self.source)).norm());
                    (nn * SPRING_NORMAL + tt * SPRING_TANGENT) * (self.shear_modulus / r.max(1e-9))
                });
                let mut xa = [[0.0; 3]; 4];
                for (xi, p) in xa.iter_mut().zip(&x) {
                    *xi = [p.x, p.y, p.z];
                }
                let mut fw = FaceWeights::default();
                face_nodal_weights_into(cell.kind, &xa[..x.len()], &mut fw);
                let w = fw.area;
                for (a, &nd) in cell.nodes().iter().enumerate() {
                    let nd = nd as usize;
                    if index[nd] == usize::MAX {
                        index[nd] = nodes.len();
                        nodes.push(nd);
                        c.push(Matrix3::zeros());
                        k.push(Matrix3::zeros());
                        na.push(Vector3::zeros());
                    }
                    let i = index[nd];
                    c[i] += cf * w[a];
                    if let Some(kf) = kf {
                        k[i] += kf * w[a];
                    }
                    na[i] += n * w[a];
                    area += w[a];
                }
                faces += 1;
            }
        }
        if self.springs.is_none() {
            k.clear();
        }
        // ascending node order
        let mut order: Vec<usize> = (0..nodes.len()).collect();
        order.sort_by_key(|&i| nodes[i]);
        let pick = |v: &Vec<Matrix3<f64>>| if v.is_empty() { Vec::new() } else { order.iter().map(|&i| v[i]).collect() };
        Ok((order.iter().map(|&i| nodes[i]).collect(), pick(&c), pick(&k), order.iter().map(|&i| na[i]).collect(), faces, area))
    }
}

impl FarBoundary {
    /// The far boundary of `faces` with free field `free_field`; `released[node]`: the
    /// components the far groups' `boundary` entries hold through gravity and the dynamic
    /// stage frees.
    pub fn build(faces: &FarFaces<'_>, free_field: FreeField, released: &[u8]) -> Result<FarBoundary, ModelError> {
        let model = faces.model;
        let (nodes, dashpot, spring, normal_area, nf, area) = faces.sums()?;
        for &n in &nodes {
            if model.mass.inertial[n] <= 0.0 {
                return Err(ModelError::Invalid(format!("foundation.far: node {} of the far faces has no mass: the far faces must bound the massed rock", model.mesh.node_tags[n])));
            }
            if model.mass.blocks.iter().any(|b| b.node as usize == n) {
                return Err(ModelError::Invalid(format!("foundation.far: node {} of the far faces carries an added inertia (a wet face?): the far boundary must be bare rock", model.mesh.node_tags[n])));
            }
        }
        let depth = nodes.iter().map(|&n| free_field.depth_weight(model.mesh.nodes[n][2])).collect();
        let dynamic_held = model.held.iter().zip(released).map(|(&h, &r)| h & !r).collect();
        Ok(FarBoundary { nodes, dashpot, spring, normal_area, depth, free_field, dynamic_held, faces: nf, area })
    }

    /// ω² the springs add to the stable-step bound: max_i λ_max(K_i) / m_i [1/s²] (0 without).
    pub fn omega2_bound(&self, model: &Model) -> f64 {
        self.spring.iter().zip(&self.nodes).map(|(k, &n)| k.symmetric_eigenvalues().max() / model.mass.inertial[n]).fold(0.0, f64::max)
    }

    /// The effective force F_i(t) of far node `i` (index into `nodes`) [N].
    pub fn effective_force(&self, i: usize, t: f64) -> Vector3<f64> {
        let ff = self.free_field.at(self.depth[i], t);
        let s = ff.stress;
        let sigma = Matrix3::new(s[0], s[3], s[5], s[3], s[1], s[4], s[5], s[4], s[2]);
        let mut f = sigma * self.normal_area[i] + self.dashpot[i] * Vector3::from(ff.vel);
        if let Some(k) = self.spring.get(i) {
            f += k * Vector3::from(ff.disp);
        }
        f
    }
}

/// The far boundary in a run: the static reactions H and displacements u⁰ taken when the
/// dynamic stage starts ([`Radiating::start`]).
pub struct Radiating<'p> {
    pub far: &'p FarBoundary,
    hold: Vec<Vector3<f64>>,
    u0: Vec<Vector3<f64>>,
    /// Whether the step being taken is dynamic (set by the force hook, read by the correction).
    dynamic: bool,
    scratch: Vec<f64>,
}

impl<'p> Radiating<'p> {
    pub fn new(far: &'p FarBoundary) -> Radiating<'p> {
        let n = far.nodes.len();
        Radiating { far, hold: vec![Vector3::zeros(); n], u0: vec![Vector3::zeros(); n], dynamic: false, scratch: Vec::new() }
    }

    /// Take the state `u` (the static equilibrium, at rest) as the start of the dynamic stage:
    /// H_i = (K u − F_static)_i on the far nodes, u⁰ = u there.
    pub fn start(&mut self, model: &Model, loads: &Loads, u: &[f64]) {
        let n = u.len();
        self.scratch.resize(2 * n, 0.0);
        let (ku, fs) = self.scratch.split_at_mut(n);
        model.internal_forces_into(u, ku);
        loads.external_force_into(model, 0.0, true, false, fs);
        for (i, &node) in self.far.nodes.iter().enumerate() {
            let r = |c: usize| ku[3 * node + c] - fs[3 * node + c];
            self.hold[i] = Vector3::new(r(0), r(1), r(2));
            self.u0[i] = Vector3::new(u[3 * node], u[3 * node + 1], u[3 * node + 2]);
        }
        self.scratch = Vec::new();
    }
}

impl<H: ?Sized> Constraint<H> for Radiating<'_> {
    /// H + F(t[n]) − K (u[n] − u⁰) on the far nodes in the dynamic stage (nothing while relaxing).
    fn add_external_force_into(&mut self, _model: &Model, step: &StepContext<'_>, dynamic: bool, f: &mut [f64]) {
        self.dynamic = dynamic;
        if !dynamic {
            return;
        }
        let t = step.t_next - step.dt;
        for (i, &node) in self.far.nodes.iter().enumerate() {
            let mut fi = self.hold[i] + self.far.effective_force(i, t);
            if let Some(k) = self.far.spring.get(i) {
                let u = Vector3::new(step.u[3 * node], step.u[3 * node + 1], step.u[3 * node + 2]);
                fi -= k * (u - self.u0[i]);
            }
            for c in 0..3 {
                f[3 * node + c] += fi[c];
            }
        }
    }

    /// The dashpots with the central velocity (module doc), on the released components.
    fn correct(&mut self, model: &Model, _history: &mut H, step: &StepContext<'_>, u_next: &mut [f64]) -> Result<ConstraintInfo, StepError> {
        if !self.dynamic {
            return Ok(ConstraintInfo::default());
        }
        let dt = step.dt;
        let mut work = 0.0;
        for (i, &node) in self.far.nodes.iter().enumerate() {
            let held = self.far.dynamic_held[node];
            let m = model.mass.inertial[node] / (dt * dt);
            let c = self.far.dashpot[i] / (2.0 * dt);
            let i0 = 3 * node;
            let ut = Vector3::new(u_next[i0], u_next[i0 + 1], u_next[i0 + 2]);
            let um = Vector3::new(step.u_prev[i0], step.u_prev[i0 + 1], step.u_prev[i0 + 2]);
            let mut a = Matrix3::identity() * m + c;
            let mut b = ut * m + c * um;
            for k in 0..3 {
                if held & (1 << k) != 0 {
                    // a held component keeps its predicted value (0)
                    for j in 0..3 {
                        a[(k, j)] = if j == k { 1.0 } else { 0.0 };
                    }
                    b[k] = ut[k];
                }
            }
            let Some(x) = a.lu().solve(&b) else {
                return Err(StepError::Foundation(format!("radiating boundary: singular dashpot system at node {}", model.mesh.node_tags[node])));
            };
            let du = (x - um) * 0.5;
            let mut r = -(self.far.dashpot[i] * du) / dt;
            for k in 0..3 {
                if held & (1 << k) != 0 {
                    r[k] = 0.0;
                }
                u_next[i0 + k] = x[k];
            }
            work += du.dot(&r);
        }
        Ok(ConstraintInfo { work, iterations: 0 })
    }
}
