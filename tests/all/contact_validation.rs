//! Contact validation against analytic references (design.md §6); numbers in docs/validation.md.
//!
//! 1. Two-bar impact (refs/analytic.py section C): NTS, NTN and penalty.
//! 2. Contact patch test on non-conforming flat joints (fixtures `boxes_*`).
//! 3. Cohesion: onset of sliding of a block at c A + μ N.
//!
//! All runs drive the run object (`Simulation`) step by step, so that the tests can set what
//! scenes cannot (an initial velocity) and read the contact state per pair.
//! Every test prints its measured numbers (`cargo test ... -- --nocapture`).
use crate::common::{fixture, problem, scene};
use jointquake::contact::law::PairState;
use jointquake::dynamics::State;
use jointquake::simulation::Simulation;
use jointquake::mesh::structured::{add_box, box_mesh, BoxSpec};
use jointquake::mesh::Mesh;
use jointquake::model::Model;
use serde_json::{json, Value};

/// Discrete energy of central differences E = ½ v[n+½]ᵀ M v[n+½] + ½ u[n+1]ᵀ K u[n] (constant
/// for a conservative run), from state.u = u[n+1], state.u_prev = u[n].
fn discrete_energy(model: &Model, state: &State, dt: f64) -> f64 {
    let mut ku = vec![0.0; state.u.len()];
    model.internal_forces_into(&state.u_prev, &mut ku);
    let mut e = 0.0;
    for i in 0..state.u.len() {
        let v = (state.u[i] - state.u_prev[i]) / dt;
        e += 0.5 * model.mass.inertial[i / 3] * v * v + 0.5 * state.u[i] * ku[i];
    }
    e
}

/// Mass-weighted mean x-velocity v[n+½] of a set of nodes.
fn mean_velocity_x(model: &Model, state: &State, nodes: &[usize], dt: f64) -> f64 {
    let (mut p, mut m) = (0.0, 0.0);
    for &n in nodes {
        p += model.mass.inertial[n] * (state.u[3 * n] - state.u_prev[3 * n]) / dt;
        m += model.mass.inertial[n];
    }
    p / m
}

// =====================================================================================
// 1. Two-bar impact
// =====================================================================================

/// Bars: length L, square section a × a, E, ρ, ν = 0 (so the problem is exactly 1-D with free
/// lateral faces), N elements each, impact velocity v0.
const BAR_L: f64 = 1.0;
const BAR_A: f64 = 0.1;
const BAR_E: f64 = 2e9;
const BAR_RHO: f64 = 2000.0;
const BAR_N: usize = 100;
const BAR_V0: f64 = 1.0;

/// What one impact run measured.
#[derive(Debug)]
struct Impact {
    /// The step limit used [s] and the element-only limit [s].
    dt_limit: f64,
    dt_elements: f64,
    /// 1-D Courant number c dt / h (the one of refs/analytic.py).
    courant_1d: f64,
    /// Exact force ρ c A v0 / 2 [N].
    f_exact: f64,
    /// Contact force over the plateau 0.2 L/c < t < 1.8 L/c: mean, min, max [N].
    f_mean: f64,
    f_min: f64,
    f_max: f64,
    /// Time from the first to the last step with a contact force, + dt [s]; exact 2L/c.
    duration: f64,
    /// Mean velocities of the bars at the end (t = 3 L/c) [m/s]; exact 0 and v0.
    v1: f64,
    v2: f64,
    /// Discrete energy at the end over the initial kinetic energy; exact 1.
    energy_ratio: f64,
    /// Largest relative energy-balance error of the solver's own account.
    balance_error: f64,
}

/// Two bars end to end along x: bar1 on [−L, 0], bar2 on [0, L], touching at x = 0 (the joint
/// nodes coincide pairwise but are distinct nodes).
fn two_bars() -> Mesh {
    let mut m = box_mesh(&BoxSpec::new("bar1", [BAR_L, BAR_A, BAR_A], [BAR_N, 1, 1]).at([-BAR_L, -BAR_A / 2.0, -BAR_A / 2.0]));
    add_box(&mut m, &BoxSpec::new("bar2", [BAR_L, BAR_A, BAR_A], [BAR_N, 1, 1]).at([0.0, -BAR_A / 2.0, -BAR_A / 2.0]));
    m
}

/// Bar 1 moving at v0 hits bar 2 at rest at t = 0. `courant` is the fraction of the solver's
/// stable step (with the penalty springs' ω² bound for method "penalty", as the pipeline does);
/// `penalty` is the penalty stiffness in units of E/h per unit area (kn A = penalty × EA/h).
fn impact(method: &str, courant: f64, penalty: f64, energy_tolerance: f64) -> Impact {
    let h = BAR_L / BAR_N as f64;
    let mut joint = json!({"name": "J", "master": "bar2:x0", "slave": "bar1:x1", "method": method, "mu": 0.0});
    if method == "penalty" {
        joint["penalty_stiffness"] = json!(penalty * BAR_E / h);
    }
    let sc = scene(json!({
        "geometry": {"msh": "unused.msh"},
        "materials": [
            {"group": "block:bar1", "E": BAR_E, "nu": 0.0, "rho": BAR_RHO},
            {"group": "block:bar2", "E": BAR_E, "nu": 0.0, "rho": BAR_RHO}
        ],
        "joints": [joint],
        "time": {"duration": 1.0}
    }));
    let mesh = two_bars();
    let bar1 = mesh.group_nodes("block:bar1").unwrap();
    let bar2 = mesh.group_nodes("block:bar2").unwrap();
    let mut sc = sc;
    sc.time.energy_tolerance = energy_tolerance;
    let pb = problem(mesh, &sc, courant);
    let model = &pb.model;
    let mut sim = Simulation::new(&pb).unwrap();
    let dt_elements = model.stable_dt();
    let dt_limit = sim.time.dt_stable;
    let dt = sim.dt();
    let c = (BAR_E / BAR_RHO).sqrt();
    // Initial velocity (the library has no initial-velocity option): central differences carry
    // the velocity as v[n−½] = (u[n] − u[n−1]) / dt, so u[−1] = u[0] − v0 dt on bar 1 gives
    // v[−½] = v0 on bar 1 and 0 on bar 2, exactly the start of refs/analytic.py section C
    // (no force acts before the contact). The energy account starts from ½ M v0².
    for &n in &bar1 {
        sim.state.u_prev[3 * n] = -BAR_V0 * dt;
    }
    sim.solver.start_energy(model, &mut sim.state);
    let e0: f64 = bar1.iter().map(|&n| 0.5 * model.mass.inertial[n] * BAR_V0 * BAR_V0).sum();
    sim.state.energy.initial = e0;
    sim.state.energy.scale = e0;

    let t_end = 3.0 * BAR_L / c;
    let steps = (t_end / dt).round() as usize;
    let f_exact = BAR_RHO * c * BAR_A * BAR_A * BAR_V0 / 2.0;
    let (mut first, mut last) = (f64::NAN, f64::NAN);
    let (mut sum, mut count, mut f_min, mut f_max) = (0.0, 0usize, f64::INFINITY, f64::NEG_INFINITY);
    for _ in 0..steps {
        let t = sim.state.t; // the force of the step from t[n] to t[n+1] is that of t[n]
        sim.step().expect("step");
        let f: f64 = sim.state.contact.joints[0].pairs.iter().map(|p| p.r_n).sum();
        if f > 1e-6 * f_exact {
            if first.is_nan() {
                first = t;
            }
            last = t;
        }
        if t > 0.2 * BAR_L / c && t < 1.8 * BAR_L / c {
            sum += f;
            count += 1;
            f_min = f_min.min(f);
            f_max = f_max.max(f);
        }
    }
    Impact {
        dt_limit,
        dt_elements,
        courant_1d: c * dt / h,
        f_exact,
        f_mean: sum / count as f64,
        f_min,
        f_max,
        duration: last - first + dt,
        v1: mean_velocity_x(model, &sim.state, &bar1, dt),
        v2: mean_velocity_x(model, &sim.state, &bar2, dt),
        energy_ratio: discrete_energy(model, &sim.state, dt) / e0,
        balance_error: sim.state.energy.max_error,
    }
}

/// The dynamic contact force (NTS and NTN) against the exact impact of two equal bars.
///
/// Reference: 1-D wave theory (refs/analytic.py section C): contact force ρcA v0/2 for 2L/c,
/// then bar 1 at rest and bar 2 at v0, energy conserved. The 1-D FE reference of the same
/// script (forward-increment Lagrange multiplier, 100 elements per bar) gives at Courant 0.9 /
/// 0.5: plateau [0.4991, 0.5008] / [0.4987, 0.5012] × 2F, duration 2.007 / 2.015 L/c,
/// v1 0.0042 / 0.0062 v0, E/E0 0.9975 (the impact of the two end nodes is perfectly plastic:
/// it loses 1/(4N) of the energy).
/// Tolerances (brief): plateau mean, min and max within 2 % of the exact force, duration within
/// 2 % of 2L/c, final mean velocities within 0.02 v0 of 0 and v0, energy within 1 %; the
/// solver's energy account balances within 1e-3.
#[test]
fn two_bar_impact_matches_wave_theory() {
    let c = (BAR_E / BAR_RHO).sqrt();
    for method in ["nts", "ntn"] {
        for courant in [0.5, 0.9] {
            let r = impact(method, courant, 0.0, 0.05);
            println!("impact {method} Courant {courant} (c dt/h = {:.3}): {r:?}", r.courant_1d);
            let fe = r.f_exact;
            assert!((r.f_mean / fe - 1.0).abs() < 0.02, "{method} {courant}: plateau mean {} vs {fe}", r.f_mean);
            assert!((r.f_min / fe - 1.0).abs() < 0.02 && (r.f_max / fe - 1.0).abs() < 0.02, "{method} {courant}: plateau [{}, {}] vs {fe}", r.f_min, r.f_max);
            let dur = 2.0 * BAR_L / c;
            assert!((r.duration / dur - 1.0).abs() < 0.02, "{method} {courant}: duration {} vs {dur}", r.duration);
            assert!(r.v1.abs() < 0.02 * BAR_V0 && (r.v2 - BAR_V0).abs() < 0.02 * BAR_V0, "{method} {courant}: v1 {} v2 {}", r.v1, r.v2);
            assert!((r.energy_ratio - 1.0).abs() < 0.01, "{method} {courant}: E/E0 {}", r.energy_ratio);
            assert!(r.balance_error.abs() < 1e-3, "{method} {courant}: energy balance error {}", r.balance_error);
        }
    }
}

/// Penalty contact on the same impact: it oscillates and lowers the stable step.
///
/// Reference: refs/analytic.py section C, 1-D penalty FE with 100 elements per bar, run at the
/// same c dt/h as here (0.9 of the pipeline's penalty step limit):
/// - 1 × EA/h, c dt/h = 0.6364: plateau [0.1299, 0.8702] × 2F, duration 2.0237 L/c,
///   v1 0.0031, v2 0.9969, E/E0 1.0000;
/// - 10 × EA/h, c dt/h = 0.2714: plateau [0, 12.94] × 2F (the contact rattles), E/E0 2.53
///   (explicit penalty creates energy near its step limit).
/// The exact critical Courant numbers of the two bars with the spring are 0.7862 and 0.3084
/// (1 without penalty).
/// Checks:
/// - the penalty force oscillation (max − min over the plateau, / exact) is larger than NTS's at
///   the same fraction of the step limit (by 10× at least);
/// - the step limit used by the pipeline (`stable_dt_with(penalty_omega2_bound)`) is below the
///   element limit, below the exact ratio and within 15 % of it (Gershgorin gives 1/√(1 + k):
///   0.707 and 0.302);
/// - 1 × EA/h reproduces the 1-D reference: plateau min and max within 0.01 F, energy within 1 %,
///   momentum within 0.02 v0. The 10 × EA/h run is recorded (docs/validation.md), not asserted
///   beyond the first two points: it is chaotic (rattling), so its numbers are not reproducible
///   across implementations.
#[test]
fn two_bar_impact_penalty_oscillates_and_lowers_the_step() {
    let nts = impact("nts", 0.9, 0.0, 0.05);
    let osc_nts = (nts.f_max - nts.f_min) / nts.f_exact;
    for (k, exact_ratio) in [(1.0, 0.7862), (10.0, 0.3084)] {
        // generous energy tolerance: the penalty method's energy error is a measured result here
        let r = impact("penalty", 0.9, k, 10.0);
        let osc = (r.f_max - r.f_min) / r.f_exact;
        let ratio = r.dt_limit / r.dt_elements;
        println!(
            "impact penalty {k} × EA/h at 0.9 of its limit (c dt/h = {:.4}): oscillation {osc:.3} (NTS {osc_nts:.4}), step limit ratio {ratio:.4} (exact {exact_ratio}), {r:?}",
            r.courant_1d
        );
        assert!(osc > 10.0 * osc_nts, "penalty {k}: oscillation {osc} not larger than NTS {osc_nts}");
        assert!(r.dt_limit < r.dt_elements, "penalty {k}: step limit {} not below {}", r.dt_limit, r.dt_elements);
        assert!(ratio <= exact_ratio && ratio > 0.85 * exact_ratio, "penalty {k}: step ratio {ratio} vs exact {exact_ratio}");
        if k == 1.0 {
            // 1-D reference at c dt/h = 0.6364 (refs/analytic.py two_bar_fe): [0.1299, 0.8702] × 2F
            let (lo, hi) = (2.0 * 0.1299, 2.0 * 0.8702);
            assert!((r.f_min / r.f_exact - lo).abs() < 0.01 && (r.f_max / r.f_exact - hi).abs() < 0.01, "penalty 1: plateau [{}, {}] × F vs [{lo}, {hi}]", r.f_min / r.f_exact, r.f_max / r.f_exact);
            assert!((r.energy_ratio - 1.0).abs() < 0.01, "penalty 1: E/E0 {}", r.energy_ratio);
            assert!(r.v1.abs() < 0.02 * BAR_V0 && (r.v2 - BAR_V0).abs() < 0.02 * BAR_V0, "penalty 1: v1 {} v2 {}", r.v1, r.v2);
        }
    }
}

// =====================================================================================
// 2. Contact patch test
// =====================================================================================

/// What one patch run measured (relative deviations from the uniform solution p).
#[derive(Debug)]
struct Patch {
    /// max |r_n / (A_s p) − 1| over all slave nodes.
    pressure: f64,
    /// Slave node (mesh node tag) where it occurs, and its position.
    pressure_node: u64,
    pressure_at: [f64; 3],
    /// The same over the slave nodes off the joint's perimeter (x, y ∉ {0, 1}).
    pressure_interior: f64,
    /// max |σzz / (−p) − 1| over the elements of the layer next to the joint, lower and upper block.
    szz_lower: f64,
    szz_upper: f64,
    /// Σ r_n / (p A) − 1 (global equilibrium of the joint).
    total: f64,
    /// Relative velocity at the end, max |u[n+1] − u[n]| / max |u| (static when ≪ 1).
    residual: f64,
    steps: usize,
    /// Search events of the run (node-steps lost, fresh searches, Layer2 widenings).
    events: jointquake::contact::force::SearchEvents,
    /// Slave nodes without force at the end.
    unloaded: Vec<u64>,
}

const PATCH_E: f64 = 1e9;
const PATCH_RHO: f64 = 1000.0;
const PATCH_P: f64 = 1e6;

/// Uniform pressure p on `load:top` through the flat joint z = 0 of a `boxes_*` fixture
/// (1 × 1 m, lower box on z ∈ [−0.5, 0] fixed at its base `bc:base`, upper box on [0, 0.5]).
/// ν = 0, so the exact solution is uniaxial: σzz = −p everywhere, contact pressure p, whatever
/// the lateral faces do (left free). Static equilibrium is reached dynamically: the traction
/// is ramped over 4 periods of the lowest axial mode (ω1 = πc/(2H), H = 1 m) with
/// mass-proportional damping α = 2ω1 (critical for that mode) and the run continues until the
/// relative velocity is below 1e-10.
fn patch(msh: &str, master: &str, slave: &str, method: &str) -> Patch {
    let c = (PATCH_E / PATCH_RHO).sqrt();
    let w1 = std::f64::consts::PI * c / 2.0;
    let ramp = 4.0 * 2.0 * std::f64::consts::PI / w1;
    let sc = scene(json!({
        "geometry": {"msh": "unused.msh"},
        "materials": [
            {"group": "block:lower", "E": PATCH_E, "nu": 0.0, "rho": PATCH_RHO},
            {"group": "block:upper", "E": PATCH_E, "nu": 0.0, "rho": PATCH_RHO}
        ],
        "boundary": [{"group": "bc:base"}],
        "loads": {"traction": [{"group": "load:top", "traction": [0.0, 0.0, -PATCH_P], "ramp": ramp}]},
        "damping": {"alpha": 2.0 * w1},
        "joints": [{"name": "J", "master": master, "slave": slave, "method": method, "mu": 0.6}],
        "time": {"duration": 1.0}
    }));
    let mesh = Mesh::from_msh(fixture(msh)).unwrap();
    let mut sc = sc;
    sc.time.energy_tolerance = 0.05;
    let pb = problem(mesh, &sc, 0.9);
    let model = &pb.model;
    let mut sim = Simulation::new(&pb).unwrap();
    sim.solver.start_energy(model, &mut sim.state);
    let mut residual = f64::INFINITY;
    let mut steps = 0;
    while steps < 20_000 {
        sim.step().expect("step");
        steps += 1;
        if sim.state.t > ramp && steps % 50 == 0 {
            let du = sim.state.u.iter().zip(&sim.state.u_prev).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            let um = sim.state.u.iter().map(|a| a.abs()).fold(0.0, f64::max);
            residual = du / um;
            if residual < 1e-10 {
                break;
            }
        }
    }
    let j = &pb.joints[0];
    let mut out = Patch { pressure_interior: 0.0, pressure: 0.0, pressure_node: 0, pressure_at: [0.0; 3], szz_lower: 0.0, szz_upper: 0.0, total: 0.0, residual, steps, events: sim.state.contact.joints[0].events.clone(), unloaded: Vec::new() };
    let mut total = 0.0;
    for (i, p) in sim.state.contact.joints[0].pairs.iter().enumerate() {
        total += p.r_n;
        if p.r_n <= 0.0 {
            out.unloaded.push(model.mesh.node_tags[j.tag.slave_nodes()[i]]);
        }
        let dev = (p.r_n / (j.tag.areas[i] * PATCH_P) - 1.0).abs();
        let x = model.mesh.nodes[j.tag.slave_nodes()[i]];
        if [x[0], x[1]].iter().all(|&c| c > 1e-9 && c < 1.0 - 1e-9) {
            out.pressure_interior = out.pressure_interior.max(dev);
        }
        if dev > out.pressure || !dev.is_finite() {
            let s = j.tag.slave_nodes()[i];
            out.pressure = dev;
            out.pressure_node = model.mesh.node_tags[s];
            out.pressure_at = model.mesh.nodes[s];
        }
    }
    let area: f64 = j.tag.areas.iter().sum();
    out.total = total / (PATCH_P * area) - 1.0;
    // elements of the layer next to the joint: centroid within one element layer (0.25 m) of z = 0
    let mut stress = Vec::new();
    model.element_stress_into(&sim.state.u, &mut stress);
    let blocks = model.element_blocks();
    for (e, (_, nodes)) in model.element_cells().iter().enumerate() {
        let zc = nodes.iter().map(|&n| model.mesh.nodes[n as usize][2]).sum::<f64>() / nodes.len() as f64;
        if zc.abs() > 0.25 {
            continue;
        }
        let dev = (stress[e][2] / -PATCH_P - 1.0).abs();
        if blocks[e] == 0 {
            out.szz_lower = out.szz_lower.max(dev);
        } else {
            out.szz_upper = out.szz_upper.max(dev);
        }
    }
    out
}

/// Contact patch test, hex8 and tet4, three variants per mesh.
///
/// Reference: uniform pressure through a flat joint (design §6): contact pressure p and
/// σzz = −p everywhere (ν = 0). Single-pass node-to-segment is known to fail it on
/// non-conforming meshes by a mesh-dependent amount (for scale: CalculiX node-to-surface misses
/// σzz by 34 % on the 4×4/3×3 hex8 case). The deviations come from the load NTS hands to the
/// master nodes, Σ_s N_I(x_s) A_s p, which is not the consistent ∫ N_I p dA (see
/// docs/validation.md); the numbers are recorded there.
/// Checks:
/// - every run is static (relative velocity < 1e-10) and in global equilibrium (Σ r_n = p A
///   within 1e-6);
/// - the conforming joint (boxes_hex_3x3) passes exactly: deviations < 1e-6, all methods;
/// - ordering measured on the non-conforming joints: NTS with the finer side as slave has the
///   smallest σzz deviation, NTS with the coarser side as slave and NTN are worse;
/// - bounds on NTS with the finer side as slave, about 1.25 × the measured values (so that a
///   regression of a quarter fails): see the table `meshes` below.
#[test]
fn contact_patch_test() {
    // (fixture, finer side group, coarser side group, bounds for NTS with the finer side as
    // slave: largest σzz deviation next to the joint, largest interior contact-pressure deviation)
    let meshes = [
        ("boxes_hex_3x3.msh", "joint:J:lower", "joint:J:upper", 1e-6, 1e-6),
        ("boxes_hex_4x3.msh", "joint:J:lower", "joint:J:upper", 0.105, 0.14),
        ("boxes_hex_7x5.msh", "joint:J:lower", "joint:J:upper", 0.07, 0.095),
        ("boxes_tet.msh", "joint:J:lower", "joint:J:upper", 0.25, 0.12),
    ];
    for (msh, fine, coarse, bound_szz, bound_p) in meshes {
        let fine_slave = patch(msh, coarse, fine, "nts");
        let coarse_slave = patch(msh, fine, coarse, "nts");
        let ntn = patch(msh, coarse, fine, "ntn");
        for (name, r) in [("NTS finer slave", &fine_slave), ("NTS coarser slave", &coarse_slave), ("NTN finer slave", &ntn)] {
            println!(
                "patch {msh:18} {name:18}: pressure {:.4} (node {} at {:?}), interior {:.4}, szz lower {:.4}, upper {:.4}, total {:.1e}, residual {:.1e} after {} steps, {:?}, unloaded {:?}",
                r.pressure, r.pressure_node, r.pressure_at, r.pressure_interior, r.szz_lower, r.szz_upper, r.total, r.residual, r.steps, r.events, r.unloaded
            );
            assert!(r.residual < 1e-10, "{msh} {name}: not static ({})", r.residual);
            assert!(r.total.abs() < 1e-6, "{msh} {name}: Σ r_n off by {}", r.total);
        }
        if msh == "boxes_hex_3x3.msh" {
            for r in [&fine_slave, &coarse_slave, &ntn] {
                assert!(r.pressure < 1e-6 && r.szz_lower < 1e-6 && r.szz_upper < 1e-6, "conforming joint must pass exactly: {r:?}");
            }
            continue;
        }
        let worst = |r: &Patch| r.szz_lower.max(r.szz_upper);
        assert!(worst(&fine_slave) < bound_szz, "{msh}: finer slave σzz deviation {} above {bound_szz}", worst(&fine_slave));
        assert!(fine_slave.pressure_interior < bound_p, "{msh}: finer slave interior pressure deviation {} above {bound_p}", fine_slave.pressure_interior);
        assert!(worst(&fine_slave) < worst(&coarse_slave), "{msh}: finer slave {} not better than coarser slave {}", worst(&fine_slave), worst(&coarse_slave));
        assert!(worst(&fine_slave) < worst(&ntn), "{msh}: finer slave {} not better than NTN {}", worst(&fine_slave), worst(&ntn));
    }
}

// =====================================================================================
// 3. Cohesion
// =====================================================================================

/// Upper block 1 × 1 × 0.1 m (4 × 4 hex8) on a longer lower block 2 × 1 × 0.2 m (10 × 5 hex8,
/// x ∈ [−0.5, 1.5], fixed base), non-conforming; NTS with the sliding block's face as slave (so
/// its nodes stay on the master while it slides). A normal traction σn on the top is applied
/// first (ramp 10 ms), then a shear traction τ(t) along x ramped slowly (0 → 2 τ_lim over
/// 0.4 s). Returns (applied shear force when every pair first slips [N], largest interface shear
/// force Σ r_t [N], Σ r_n at that moment [N], analytic c A + μ N [N]).
fn cohesion_onset(keep_cohesion: bool) -> (f64, f64, f64, f64) {
    let (e, rho, sn, mu, coh) = (1e9, 2000.0, 1e6, 0.5, 2e5);
    let area = 1.0;
    let t_lim = coh * area + mu * sn * area;
    let t_ramp = 0.4;
    let mut mesh = box_mesh(&BoxSpec::new("lower", [2.0, 1.0, 0.2], [10, 5, 1]).at([-0.5, 0.0, -0.2]));
    add_box(&mut mesh, &BoxSpec::new("upper", [1.0, 1.0, 0.1], [4, 4, 1]));
    let joint: Value = json!({"name": "J", "master": "lower:z1", "slave": "upper:z0", "method": "nts",
        "mu": mu, "cohesion": coh, "keep_cohesion": keep_cohesion});
    let sc = scene(json!({
        "geometry": {"msh": "unused.msh"},
        "materials": [
            {"group": "block:lower", "E": e, "nu": 0.25, "rho": rho},
            {"group": "block:upper", "E": e, "nu": 0.25, "rho": rho}
        ],
        "boundary": [{"group": "lower:z0"}],
        "loads": {"traction": [
            {"group": "upper:z1", "traction": [0.0, 0.0, -sn], "ramp": 0.01},
            {"group": "upper:z1", "traction": [2.0 * t_lim / area, 0.0, 0.0], "ramp": t_ramp}
        ]},
        "damping": {"alpha": 100.0},
        "joints": [joint],
        "time": {"duration": 1.0}
    }));
    let mut sc = sc;
    sc.time.energy_tolerance = 0.05;
    let pb = problem(mesh, &sc, 0.9);
    let model = &pb.model;
    let mut sim = Simulation::new(&pb).unwrap();
    sim.solver.start_energy(model, &mut sim.state);
    let j = &pb.joints[0];
    let mut onset = f64::NAN;
    let mut normal = f64::NAN;
    let mut peak: f64 = 0.0;
    while sim.state.t < 0.75 * t_ramp {
        let t = sim.state.t;
        sim.step().expect("step");
        let pairs = &sim.state.contact.joints[0].pairs;
        // interface shear force on the master (lower) block = − force on the slave, x component
        let fx: f64 = -pairs.iter().enumerate().map(|(i, p)| p.r_t[0] * j.frames[i][1].x + p.r_t[1] * j.frames[i][2].x).sum::<f64>();
        peak = peak.max(fx.abs());
        if onset.is_nan() && pairs.iter().all(|p| p.state == PairState::Slip) {
            onset = 2.0 * t_lim * (t / t_ramp).min(1.0);
            normal = pairs.iter().map(|p| p.r_n).sum();
            break;
        }
    }
    (onset, peak, normal, t_lim)
}

/// A block held by cohesion starts sliding at c A + μ N.
///
/// Reference: Mohr-Coulomb limit of the joint, Σ (μ r_n + c A_s) = μ N + c A (Σ r_n = N and
/// Σ A_s = A whatever the distribution of r_n), here 0.2 MN + 0.5 × 1 MN = 0.7 MN. With
/// `keep_cohesion` the joint is ductile, so the block slides when the load reaches that limit
/// (lower-bound theorem); the ramp (0.4 s to twice the limit) is slow against the block's
/// periods (< 1 ms), so inertia adds < 0.1 %. Tolerance (brief): 1 %.
/// With the default brittle cohesion (lost at a pair's first slip) sliding may start earlier by
/// progressive failure; that number is recorded in docs/validation.md and must not exceed the
/// ductile limit.
#[test]
fn cohesion_onset_at_mohr_coulomb_limit() {
    let (onset, peak, normal, lim) = cohesion_onset(true);
    println!("cohesion (keep): onset at {onset:.1} N, peak interface shear {peak:.1} N, Σ r_n {normal:.1} N, analytic {lim:.1} N ({:+.3} %)", 100.0 * (onset / lim - 1.0));
    assert!((onset / lim - 1.0).abs() < 0.01, "onset {onset} vs analytic {lim}");
    assert!((peak / lim - 1.0).abs() < 0.01, "peak interface shear {peak} vs analytic {lim}");
    let (onset_b, peak_b, normal_b, _) = cohesion_onset(false);
    println!("cohesion (brittle): onset at {onset_b:.1} N, peak interface shear {peak_b:.1} N, Σ r_n {normal_b:.1} N ({:+.3} % of the ductile limit)", 100.0 * (onset_b / lim - 1.0));
    assert!(onset_b.is_finite() && onset_b <= 1.01 * lim, "brittle onset {onset_b} vs {lim}");
}


/// The scene pipelines/impact.json through the whole pipeline (scenes have no initial velocity,
/// so this is the companion problem of the impact): a step force σ0 A = 10 kN on the free end of
/// bar 1 (bars_hex.msh: 2 × 20 hex8, L = 1 m, c = 1000 m/s), bar 2 free.
///
/// Reference (1-D waves, equal impedances): the joint transmits the wave without reflection, so
/// the two bars act as one free–free bar of 2L: the joint force is 0 until L/c, σ0 A until 3L/c
/// (when the unloading wave reflected from bar 2's free end arrives), 0 until 5L/c (no tension is
/// ever needed, so the joint stays closed with zero force), then σ0 A again.
/// Tolerances: mean force over [1.5, 2.8] L/c within 3 % of σ0 A (20 elements: the front carries
/// a Gibbs overshoot of about ±10 % that averages out), |force| < 1 % of σ0 A over
/// [3.3, 4.7] L/c and before 0.9 L/c; the joint CSV history and summary are written.
#[test]
fn impact_scene_transmits_the_wave_through_the_joint() {
    use jointquake::pipeline::{run, RunOptions};
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let out = crate::common::scratch("impact_scene");
    let summary = run(&root.join("pipelines/impact.json"), &RunOptions { out_dir: Some(out.clone()), ..Default::default() }).expect("impact scene runs");
    let text = std::fs::read_to_string(out.join("histories/joint_J.csv")).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = head.iter().position(|&h| h == "normal_force [N]").expect("normal_force column");
    let (f0, lc) = (1e4, 1e-3);
    let (mut sum, mut n) = (0.0, 0);
    let mut worst_zero: f64 = 0.0;
    for l in lines {
        let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
        let (t, f) = (v[0], v[col]);
        if t > 1.5 * lc && t < 2.8 * lc {
            sum += f;
            n += 1;
        }
        if t < 0.9 * lc || (t > 3.3 * lc && t < 4.7 * lc) {
            worst_zero = worst_zero.max(f.abs());
        }
    }
    let mean = sum / n as f64;
    println!("impact scene: mean joint force {mean:.1} N over [1.5, 2.8] L/c (exact {f0}), largest |force| in the zero phases {worst_zero:.2e} N, max opening {:.2e} m", summary.joints[0].max_opening);
    assert!((mean / f0 - 1.0).abs() < 0.03, "mean force {mean} vs {f0}");
    assert!(worst_zero < 0.01 * f0, "force {worst_zero} where the exact one is 0");
}

/// Regression (found by the impact validation): penalty contact at 10 × EA/h and 0.9 of its
/// step limit creates energy (E/E0 = 2.63, as the 1-D reference's 2.53) while the balance still
/// closed, because the created energy was booked as contact work. The cumulative contact work
/// must never be positive, so the run now stops with an error naming the cause.
#[test]
fn regression_penalty_energy_creation_stops_the_run() {
    let r = std::panic::catch_unwind(|| impact("penalty", 0.9, 10.0, 0.05));
    let msg = match r {
        Ok(i) => panic!("the run should have stopped, E/E0 = {}", i.energy_ratio),
        Err(e) => e.downcast_ref::<String>().cloned().unwrap_or_default(),
    };
    assert!(msg.contains("positive work") && msg.contains("courant"), "{msg}");
}
