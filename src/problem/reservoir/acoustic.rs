//! Compressible acoustic water (`reservoir.model: "acoustic"`): the reservoir's dynamic pressure
//! on the meshed water volume, advanced explicitly with the dam and coupled both ways through the
//! wet face.
//!
//! Unknown: the **dynamic** pressure p [Pa] at the water's nodes off the free surface. The
//! hydrostatic part ρw g (z_w − z) stays the `hydrostatic` load of the dam (module doc of
//! `reservoir`): the acoustic water carries only what the motion adds (the split is exact for
//! linear water; with cavitation the floor is on the total). Equations (Zienkiewicz & Bettess
//! 1978; Fenves & Chopra 1984), with H the Laplacian and G the wet-face coupling of the
//! incompressible model (modules `fluid_mesh`, `transfer`):
//!
//! ```text
//!   Q p̈ + C ṗ + H p = ρw G a_t        (water; a_t the dam's total acceleration at the wet face)
//!   M ü + … = F − Gᵀ p                (dam; the water pushes along −n)
//! ```
//!
//! - Q_i = ∫ N_i dV / c² [s² m]: row-sum lumped (tet4 V/4, hex8 2×2×2 Gauss), so the update is
//!   explicit (c: `reservoir.fluid.sound_speed`, default 1440 m/s).
//! - Free surface: p = 0 (no surface waves: their frequencies, √(g k), are far below the
//!   dam's for the wavelengths that matter; stated).
//! - Far end (`far_end`): Sommerfeld's plane-wave radiation ∂p/∂t = −c ∂p/∂n, a dashpot C_i =
//!   ∫ N_i dA / c. Exact for a plane wave at normal incidence; a propagating mode of the
//!   channel (vertical wavenumber λ, horizontal k = √(ω²/c² − λ²)) is reflected by
//!   (ω/c − k)/(ω/c + k), and an evanescent one (below the channel's cut-off) partly: put the far
//!   end a few depths away (Lw = 3H).
//! - Bottom and banks (`bottom`): Fenves & Chopra's absorbing boundary, ∂p/∂n = −q ṗ with
//!   q = (1 − α)/((1 + α) c), i.e. a dashpot of impedance ρw c (1 + α)/(1 − α) per unit area;
//!   α = 1 (default) is rigid. Every face not named is rigid (∂p/∂n = 0).
//! - Wet face: ∂p/∂n_water = ρw a_t·n, n the dam's outward normal; a_t = ü + a_g(t) in the
//!   relative formulation of a massless or massed_fixed foundation (the base moves the dam;
//!   the valley's own motion does not drive the water: the same assumption as the added-mass
//!   models), ü alone with a radiating foundation (total displacements).
//! - Cavitation (`vapour_pressure`, default off): the total pressure p + ρw g (z_w − z) is
//!   floored at p_v after each update (the cut-off model: the water cannot take tension
//!   beyond p_v; it does not conserve energy when it acts).
//!
//! Time integration: central differences, the damping with the central rate (p⁺ − p⁻)/2h, so
//! (Q/h² + C/2h) p⁺ = Q (2p − p⁻)/h² + C p⁻/2h − H p + ρw G a_t (diagonal: explicit, and the
//! dashpots set no step). The water's own stable step 2/ω_max (ω²_max ≤ max_i Σ_j |H_ij| / Q_i,
//! Gershgorin) is stated beside the solid's; when it is shorter the water takes `substeps`
//! steps of dt/substeps per solid step with the dam's acceleration held. Coupling in the solid
//! step (one hook, [`AcousticRun`], a `Constraint` like the radiating foundation's): the water's
//! force −Gᵀp[n] enters the dam's external force at t[n]; after the dam's u[n+1] is final, its
//! acceleration at t[n] drives the water from p[n] to p[n+1] (central differences of the coupled
//! system). The dam's energy account books the water's force as external work.
//!
//! The water's changing state (p[n], p[n−1]) is held by the run's hook, as the radiating
//! boundary's is; the operator here is built once with the problem and immutable.

use super::fluid_mesh::{element_lumped_volumes, fluid_mesh_held, FluidMesh};
use super::transfer::{wet_coupling, WetCoupling};
use super::{ReservoirSpec, WetFace};
use crate::constraint::{Constraint, ConstraintInfo, StepContext};
use crate::dynamics::loads::Loads;
use crate::error::{Error, ModelError, StepError};
use crate::interface::{face_nodal_weights_into, FaceWeights};
use crate::linalg::NONE;
use crate::mesh::Mesh;
use crate::model::Model;
use crate::scene::reservoir::FluidScene;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Safety factor on the water's stable step when choosing its substeps: 0.9 (the Gershgorin
/// bound is already an upper bound of ω_max; the margin covers the coupling with the dam).
const WATER_STEP_SAFETY: f64 = 0.9;

/// The acoustic water: its operators and its coupling with the dam (built once).
#[derive(Clone, Debug)]
pub struct AcousticWater {
    pub fluid: FluidMesh,
    pub coupling: WetCoupling,
    /// ρw [kg/m³], c [m/s], α of the bottom [-].
    pub rho_w: f64,
    pub sound_speed: f64,
    pub reflection: f64,
    /// Q_i = ∫ N_i dV / c² [s² m] per unknown.
    pub capacity: Vec<f64>,
    /// C_i [s m] per unknown: far end ∫ N_i dA / c, bottom ∫ N_i dA (1 − α)/((1 + α) c).
    pub damping: Vec<f64>,
    /// Per water node of the coupling (`coupling.water_nodes`): its unknown, or `NONE` (p = 0).
    pub wet_unknown: Vec<usize>,
    /// With cavitation: the floor of the dynamic pressure per unknown, p_v − ρw g (z_w − z) [Pa].
    pub floor: Option<Vec<f64>>,
    /// ω²_max bound of the water alone [1/s²] (Gershgorin on Q⁻¹H).
    pub omega2_bound: f64,
    /// Areas of the radiating far end and of the absorbing bottom [m²].
    pub far_area: f64,
    pub bottom_area: f64,
}

impl AcousticWater {
    /// Build the water of `fluid` on `mesh` against the dam's wet faces `dam` below the pool.
    /// Errors name the group and element and say what to fix.
    pub fn build(mesh: &Mesh, dam: &[WetFace], spec: &ReservoirSpec, fluid: &FluidScene) -> Result<AcousticWater, Error> {
        let held: Vec<&String> = fluid.free_surface.iter().collect();
        let water = fluid_mesh_held(mesh, fluid, &held)?;
        let coupling = wet_coupling(mesh, dam, &water.wet, spec.level)?;
        if coupling.dam_nodes.is_empty() {
            return Err(ModelError::Invalid(format!("reservoir.fluid: no wet face of the dam lies below the pool level {} m", spec.level)).into());
        }
        let c = fluid.sound_speed();
        let alpha = fluid.reflection();
        let n = water.nodes.len();
        let mut capacity = vec![0.0; n];
        for &cell in &mesh.group_of_dim(&fluid.volume, 3)?.cells {
            let cl = &mesh.cells[cell];
            let x: Vec<Vector3<f64>> = cl.nodes().iter().map(|&v| mesh.x(v as usize)).collect();
            let v = element_lumped_volumes(cl.kind, &x).ok_or_else(|| ModelError::Invalid(format!("reservoir.fluid.volume \"{}\": element {} is degenerate (zero or negative volume)", fluid.volume, cl.tag)))?;
            for (a, &node) in cl.nodes().iter().enumerate() {
                let k = water.unknown[node as usize];
                if k != NONE {
                    capacity[k] += v[a] / (c * c);
                }
            }
        }
        let mut damping = vec![0.0; n];
        let far_area = add_boundary_damping(mesh, &water, &fluid.far_end, 1.0 / c, &mut damping)?;
        let bottom_area = add_boundary_damping(mesh, &water, &fluid.bottom, (1.0 - alpha) / ((1.0 + alpha) * c), &mut damping)?;
        let wet_unknown = coupling.water_nodes.iter().map(|&v| water.unknown[v]).collect();
        let floor = fluid.vapour_pressure.map(|pv| water.nodes.iter().map(|&v| pv - spec.pressure(mesh.nodes[v][2])).collect());
        let h = &water.laplacian;
        let mut omega2_bound = 0.0f64;
        for j in 0..n {
            // H is symmetric: the column sums of |H| are its row sums
            let row: f64 = h.val[h.col_ptr[j]..h.col_ptr[j + 1]].iter().map(|v| v.abs()).sum();
            omega2_bound = omega2_bound.max(row / capacity[j]);
        }
        Ok(AcousticWater { fluid: water, coupling, rho_w: spec.rho_w, sound_speed: c, reflection: alpha, capacity, damping, wet_unknown, floor, omega2_bound, far_area, bottom_area })
    }

    /// The water's stable step 2/ω_max [s] (from the Gershgorin bound).
    pub fn stable_step(&self) -> f64 {
        2.0 / self.omega2_bound.sqrt()
    }

    /// Water steps per solid step of `dt`: the fewest of length ≤ 0.9 × the water's stable step.
    pub fn substeps(&self, dt: f64) -> usize {
        ((dt / (WATER_STEP_SAFETY * self.stable_step())).ceil() as usize).max(1)
    }

    /// q = ρw G a (overwritten) on the unknowns [Pa m], for the dam's total accelerations `a`
    /// [m/s²] at the coupling's dam nodes.
    pub fn flux_into(&self, a: &[[f64; 3]], q: &mut [f64]) {
        q.fill(0.0);
        for &(i, b, g) in &self.coupling.entries {
            let k = self.wet_unknown[i];
            if k != NONE {
                q[k] += self.rho_w * (g[0] * a[b][0] + g[1] * a[b][1] + g[2] * a[b][2]);
            }
        }
    }

    /// f −= Gᵀ p on the dam's wet nodes (model dofs, 3 per node) [N].
    pub fn add_forces_into(&self, p: &[f64], f: &mut [f64]) {
        for &(i, b, g) in &self.coupling.entries {
            let k = self.wet_unknown[i];
            if k != NONE {
                let node = self.coupling.dam_nodes[b];
                for c in 0..3 {
                    f[3 * node + c] -= g[c] * p[k];
                }
            }
        }
    }

    /// One water step of `h` from (p⁻, p) to p⁺ with the flux `q` (module doc); `hp` scratch.
    /// Returns how many unknowns the cavitation floor holds after the step (at or below it; 0
    /// without cavitation).
    pub fn advance_into(&self, p_prev: &[f64], p: &[f64], q: &[f64], h: f64, hp: &mut [f64], p_next: &mut [f64]) -> usize {
        self.fluid.laplacian.mul_into(p, hp);
        let h2 = h * h;
        let mut floored = 0;
        for k in 0..p.len() {
            let (m, c) = (self.capacity[k] / h2, self.damping[k] / (2.0 * h));
            let mut v = (m * (2.0 * p[k] - p_prev[k]) + c * p_prev[k] - hp[k] + q[k]) / (m + c);
            // at or below the floor: held there (a cavitated region stays at the floor exactly
            // when its neighbours do, the Laplacian of the floor's linear profile being zero)
            if let Some(fl) = &self.floor
                && v <= fl[k]
            {
                v = fl[k];
                floored += 1;
            }
            p_next[k] = v;
        }
        floored
    }

    /// The discrete energy of the water's pressure field, ½ v·Q v + ½ p·H p⁻ with v = (p − p⁻)/h
    /// [Pa² m]: the quadratic form of the pressure equation, conserved by closed undamped water
    /// (the acoustic energy of ṗ up to a constant); for reflection checks, as a ratio.
    pub fn field_energy(&self, p_prev: &[f64], p: &[f64], h: f64, hp: &mut [f64]) -> f64 {
        self.fluid.laplacian.mul_into(p_prev, hp);
        let kin: f64 = (0..p.len()).map(|k| self.capacity[k] * ((p[k] - p_prev[k]) / h).powi(2)).sum();
        let pot: f64 = (0..p.len()).map(|k| p[k] * hp[k]).sum();
        0.5 * (kin + pot)
    }

    /// The run summary's line: sizes, boundaries and the water's stable step beside the solid's.
    pub fn note(&self, dt: f64) -> String {
        format!(
            "acoustic water: {} elements, {} pressure unknowns ({} held at p = 0), c {} m/s, far end {:.4e} m² radiating, bottom {:.4e} m² with α = {}, cavitation {}; wet area {:.4e} m² (largest gap between the meshes {:.3e} m); the water's stable step {:.4e} s beside the solid's {:.4e} s: {} water step(s) per solid step",
            self.fluid.cells,
            self.fluid.nodes.len(),
            self.fluid.zero_pressure_nodes,
            self.sound_speed,
            self.far_area,
            self.bottom_area,
            self.reflection,
            if self.floor.is_some() { "on" } else { "off" },
            self.coupling.area,
            self.coupling.max_gap,
            self.stable_step(),
            dt,
            self.substeps(dt)
        )
    }
}

/// damping_i += coef ∫ N_i dA over the faces of `groups`; their total area [m²]. A group with no
/// node among the water's unknowns is an error.
fn add_boundary_damping(mesh: &Mesh, water: &FluidMesh, groups: &[String], coef: f64, damping: &mut [f64]) -> Result<f64, Error> {
    let mut area = 0.0;
    let mut w = FaceWeights::default();
    for name in groups {
        let g = mesh.group_of_dim(name, 2)?;
        let mut touched = false;
        for &c in &g.cells {
            let cl = &mesh.cells[c];
            let x: Vec<[f64; 3]> = cl.nodes().iter().map(|&v| mesh.nodes[v as usize]).collect();
            face_nodal_weights_into(cl.kind, &x, &mut w);
            for (a, &v) in cl.nodes().iter().enumerate() {
                area += w.area[a];
                let k = water.unknown[v as usize];
                if k != NONE {
                    damping[k] += coef * w.area[a];
                    touched = true;
                }
            }
        }
        if !touched {
            return Err(ModelError::Invalid(format!("reservoir.fluid: face group \"{name}\" has no node in the water volume off the free surface: the far end and bottom must be faces of the water")).into());
        }
    }
    Ok(area)
}

/// The acoustic water of a run in `summary.json` (`water`): the water's step beside the solid's,
/// the largest dynamic pressure and, with cavitation, how much of the water the floor held.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct WaterSummary {
    /// Pressure unknowns (nodes off the free surface).
    pub unknowns: usize,
    /// The water's stable step 2/ω_max (Gershgorin) [s], beside the run's `dt_stable`.
    pub dt_stable: f64,
    /// Water steps per solid step, and their length dt / substeps [s].
    pub substeps: usize,
    pub dt: f64,
    /// The largest |dynamic pressure| of any unknown over the dynamic stage [Pa], where and when
    /// (the water node's index in the mesh, the time [s]).
    pub peak_pressure: f64,
    pub peak_node: usize,
    pub peak_t: f64,
    /// With cavitation (`fluid.vapour_pressure`): whether it was on, the unknown-steps held at
    /// the floor (summed over the water's substeps), the solid steps with any, the largest number
    /// of unknowns held in one water step and the first time [s] (null: never).
    pub cavitation: bool,
    pub cavitated_node_steps: u64,
    pub cavitated_steps: u64,
    pub max_cavitated_nodes: usize,
    pub first_cavitation_t: Option<f64>,
}

impl WaterSummary {
    /// One line for the run's summary text.
    pub fn line(&self) -> String {
        let cav = match (self.cavitation, self.first_cavitation_t) {
            (false, _) => "cavitation off".to_string(),
            (true, None) => "cavitation on, never reached".to_string(),
            (true, Some(t)) => format!(
                "cavitation: {} unknown-steps held at the vapour pressure in {} solid steps (at most {} unknowns at once), first at t = {t:.4} s",
                self.cavitated_node_steps, self.cavitated_steps, self.max_cavitated_nodes
            ),
        };
        format!(
            "acoustic, {} unknowns: step {:.4e} s ({} per solid step; the water's stable {:.4e} s); peak dynamic pressure {:.4e} Pa (t = {:.4} s, node {}); {cav}",
            self.unknowns, self.dt, self.substeps, self.dt_stable, self.peak_pressure, self.peak_t, self.peak_node
        )
    }
}

/// The acoustic water in a run: its state (p[n], p[n−1]), scratch, and the hook into the solid
/// step (module doc).
pub struct AcousticRun<'p> {
    pub water: &'p AcousticWater,
    loads: &'p Loads,
    /// The dam's displacements are relative to the moving base (add a_g to ü); false with a
    /// radiating foundation (total displacements).
    relative: bool,
    /// Water steps per solid step.
    pub substeps: usize,
    /// p[n] and p[n−1] [Pa] on the unknowns.
    pub p: Vec<f64>,
    pub p_prev: Vec<f64>,
    q: Vec<f64>,
    hp: Vec<f64>,
    next: Vec<f64>,
    accel: Vec<[f64; 3]>,
    dynamic: bool,
    /// The water's clock [s]: the time of p[n] (0 at rest, at the start of the dynamic stage).
    pub t: f64,
    /// What the run's summary reports (`WaterSummary`: peaks and cavitation counts).
    pub stats: WaterSummary,
}

impl<'p> AcousticRun<'p> {
    /// At rest, for solid steps of `dt`.
    pub fn new(water: &'p AcousticWater, loads: &'p Loads, relative: bool, dt: f64) -> AcousticRun<'p> {
        let n = water.fluid.nodes.len();
        AcousticRun {
            water,
            loads,
            relative,
            substeps: water.substeps(dt),
            p: vec![0.0; n],
            p_prev: vec![0.0; n],
            q: vec![0.0; n],
            hp: vec![0.0; n],
            next: vec![0.0; n],
            accel: vec![[0.0; 3]; water.coupling.dam_nodes.len()],
            dynamic: false,
            t: 0.0,
            stats: Self::fresh_stats(water, dt),
        }
    }

    fn fresh_stats(water: &AcousticWater, dt: f64) -> WaterSummary {
        let substeps = water.substeps(dt);
        WaterSummary { unknowns: water.fluid.nodes.len(), dt_stable: water.stable_step(), substeps, dt: dt / substeps as f64, cavitation: water.floor.is_some(), ..WaterSummary::default() }
    }

    /// The water at rest (p = 0: the hydrostatic state), as at the start of the dynamic stage;
    /// its peaks and cavitation counts restart too.
    pub fn restart(&mut self) {
        self.p.fill(0.0);
        self.p_prev.fill(0.0);
        self.t = 0.0;
        self.stats = Self::fresh_stats(self.water, self.stats.dt * self.substeps as f64);
    }

    /// Advance the water over one solid step `dt` with the dam's total accelerations `a` [m/s²]
    /// at the coupling's dam nodes, held over the substeps; the water's clock, its peak pressure
    /// and the cavitation counts follow.
    pub fn advance_with_acceleration(&mut self, a: &[[f64; 3]], dt: f64) {
        let t = self.t;
        self.t += dt;
        self.water.flux_into(a, &mut self.q);
        let h = dt / self.substeps as f64;
        let mut any = false;
        for s in 0..self.substeps {
            let held = self.water.advance_into(&self.p_prev, &self.p, &self.q, h, &mut self.hp, &mut self.next);
            std::mem::swap(&mut self.p_prev, &mut self.p);
            std::mem::swap(&mut self.p, &mut self.next);
            let st = &mut self.stats;
            if held > 0 {
                any = true;
                st.cavitated_node_steps += held as u64;
                st.max_cavitated_nodes = st.max_cavitated_nodes.max(held);
                st.first_cavitation_t.get_or_insert(t + (s + 1) as f64 * h);
            }
            for (k, &v) in self.p.iter().enumerate() {
                if v.abs() > st.peak_pressure {
                    (st.peak_pressure, st.peak_node, st.peak_t) = (v.abs(), self.water.fluid.nodes[k], t + (s + 1) as f64 * h);
                }
            }
        }
        self.stats.cavitated_steps += any as u64;
    }

    /// The water's field energy now (see [`AcousticWater::field_energy`]) for solid steps `dt`.
    pub fn field_energy(&mut self, dt: f64) -> f64 {
        self.water.field_energy(&self.p_prev, &self.p, dt / self.substeps as f64, &mut self.hp)
    }
}

impl<H: ?Sized> Constraint<H> for AcousticRun<'_> {
    /// −Gᵀ p[n] on the dam's wet nodes in the dynamic stage (nothing while relaxing: the water
    /// is at rest and the hydrostatic load is the dam's own).
    fn add_external_force_into(&mut self, _model: &Model, _step: &StepContext<'_>, dynamic: bool, f: &mut [f64]) {
        self.dynamic = dynamic;
        if dynamic {
            self.water.add_forces_into(&self.p, f);
        }
    }

    /// Leaves u[n+1] as it is; advances the water with the dam's acceleration at t[n].
    fn correct(&mut self, _model: &Model, _history: &mut H, step: &StepContext<'_>, u_next: &mut [f64]) -> Result<ConstraintInfo, StepError> {
        if !self.dynamic {
            return Ok(ConstraintInfo::default());
        }
        let dt = step.dt;
        let ag = if self.relative { self.loads.ground_acceleration(step.t_next - dt) } else { [0.0; 3] };
        let mut accel = std::mem::take(&mut self.accel);
        for (a, &node) in accel.iter_mut().zip(&self.water.coupling.dam_nodes) {
            for c in 0..3 {
                let i = 3 * node + c;
                a[c] = (u_next[i] - 2.0 * step.u[i] + step.u_prev[i]) / (dt * dt) + ag[c];
            }
        }
        self.advance_with_acceleration(&accel, dt);
        self.accel = accel;
        Ok(ConstraintInfo::default())
    }
}
