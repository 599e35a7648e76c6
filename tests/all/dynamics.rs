//! Explicit elastodynamics against exact references (no contact).
use crate::common::{mean_u, problem, scene, simulate};
use jointquake::mesh::structured::{box_mesh, BoxSpec};
use serde_json::json;

/// 1-D wave in a prism fixed at x = 0 with a step traction σ0 at x = L (ν = 0, so the
/// problem is exactly one-dimensional). Reference (d'Alembert): the loaded end moves at
/// v0 = σ0/(ρc) until the wave reflected from the fixed end returns at 2L/c, then at −v0 until
/// 4L/c: u(L,t) is a triangle wave of peak 2σ0L/E. Tolerance: 2 % of the peak over two round
/// trips (0 … 4L/c), 50 hex8 elements, Courant 0.9 of the element bound.
#[test]
fn wave_in_prism_matches_dalembert() {
    let (l, e, rho, s0): (f64, f64, f64, f64) = (10.0, 1e9, 2000.0, 1e6);
    let mesh = box_mesh(&BoxSpec::new("prism", [l, 1.0, 1.0], [50, 1, 1]));
    let sc = scene(json!({
        "geometry": {"msh": "unused.msh"},
        "materials": [{"group": "block:prism", "E": e, "nu": 0.0, "rho": rho}],
        "boundary": [{"group": "prism:x0"}],
        "loads": {"traction": [{"group": "prism:x1", "traction": [s0, 0.0, 0.0]}]},
        "time": {"duration": 1.0}
    }));
    let end = mesh.group_nodes("prism:x1").unwrap();
    let pb = problem(mesh, &sc, 0.9);
    let model = &pb.model;
    let c = (e / rho).sqrt();
    let v0 = s0 / (rho * c);
    let t_end = 4.0 * l / c;
    let dt = 0.9 * model.stable_dt();
    let steps = (t_end / dt) as usize;
    let peak = 2.0 * s0 * l / e;
    let mut worst: f64 = 0.0;
    simulate(&pb, steps, |t, u| {
        let exact = if t < 2.0 * l / c { v0 * t } else { v0 * (4.0 * l / c - t) };
        worst = worst.max((mean_u(u, &end, 0) - exact).abs());
    });
    assert!(worst < 0.02 * peak, "largest deviation {:.3} % of the peak", 100.0 * worst / peak);
}

/// First natural frequency of a period from the upward crossings of the mid level.
fn dominant_frequency(t: &[f64], u: &[f64]) -> f64 {
    let (lo, hi) = u.iter().fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)));
    let mid = 0.5 * (lo + hi);
    let mut crossings = Vec::new();
    for i in 1..u.len() {
        if u[i - 1] < mid && u[i] >= mid {
            let f = (mid - u[i - 1]) / (u[i] - u[i - 1]);
            crossings.push(t[i - 1] + f * (t[i] - t[i - 1]));
        }
    }
    assert!(crossings.len() >= 3, "need at least two periods");
    (crossings.len() - 1) as f64 / (crossings[crossings.len() - 1] - crossings[0])
}

/// Cantilever L = 10 m, h = b = 1 m, fixed at x = 0, step load at the tip: it vibrates about the
/// static deflection at its first frequency. Reference: Euler–Bernoulli
/// f1 = 1.875104² / (2π) · sqrt(EI / (ρ A L⁴)).
fn cantilever_frequency(nx: usize, nz: usize, tets: bool) -> f64 {
    let (e, rho) = (30e9, 2500.0);
    let mesh = box_mesh(&BoxSpec::new("beam", [10.0, 1.0, 1.0], [nx, nz, nz]).tets(tets));
    let sc = scene(json!({
        "geometry": {"msh": "unused.msh"},
        "materials": [{"group": "block:beam", "E": e, "nu": 0.2, "rho": rho}],
        "boundary": [{"group": "beam:x0"}],
        "loads": {"traction": [{"group": "beam:x1", "traction": [0.0, 0.0, -1e5]}]},
        "time": {"duration": 1.0}
    }));
    let tip = mesh.group_nodes("beam:x1").unwrap();
    let pb = problem(mesh, &sc, 0.9);
    let model = &pb.model;
    let dt = 0.9 * model.stable_dt();
    let steps = (0.6 / dt) as usize; // about 3 periods of the first mode
    let (mut ts, mut us) = (Vec::new(), Vec::new());
    simulate(&pb, steps, |t, u| {
        ts.push(t);
        us.push(mean_u(u, &tip, 2));
    });
    dominant_frequency(&ts, &us)
}

fn euler_bernoulli_f1() -> f64 {
    let (e, rho, l, i, a): (f64, f64, f64, f64, f64) = (30e9, 2500.0, 10.0, 1.0 / 12.0, 1.0);
    1.875104f64.powi(2) / (2.0 * std::f64::consts::PI) * (e * i / (rho * a * l.powi(4))).sqrt()
}

/// hex8 with 2 elements through the depth: within 5 % of Euler–Bernoulli (L/h = 10, where
/// shear deformation lowers the exact frequency by about 1 %).
#[test]
fn cantilever_hex8_two_elements_deep_within_5_percent() {
    let f = cantilever_frequency(20, 2, false);
    let fe = euler_bernoulli_f1();
    let err = (f - fe) / fe;
    eprintln!("hex8 20x2x2: f1 = {f:.4} Hz, Euler-Bernoulli {fe:.4} Hz, error {:.2} %", 100.0 * err);
    assert!(err.abs() < 0.05, "error {:.2} %", 100.0 * err);
}

/// tet4 (Kuhn-split structured meshes) locks in bending, so its frequency is too high on coarse
/// meshes; the error must fall monotonically under refinement (measured: 74 %, 18.5 %, 10.2 % for
/// h = 1, 0.5, 0.25 m) and the finest mesh be within 15 % of Euler–Bernoulli.
#[test]
fn cantilever_tet4_converges_under_refinement() {
    let fe = euler_bernoulli_f1();
    let errs: Vec<f64> = [(10, 1), (20, 2), (40, 4)].iter().map(|&(nx, nz)| (cantilever_frequency(nx, nz, true) - fe) / fe).collect();
    eprintln!("tet4 errors (10x1, 20x2, 40x4): {:?}", errs.iter().map(|e| format!("{:.2} %", 100.0 * e)).collect::<Vec<_>>());
    assert!(errs[0] > errs[1] && errs[1] > errs[2] && errs[2] > -0.05, "errors must decrease: {errs:?}");
    assert!(errs[2] < 0.15, "finest error {:.2} %", 100.0 * errs[2]);
}

/// Gravity column H = 10 m on rollers (base fixed in z, symmetry planes x0 and y0 fixed in
/// x and y), ν = 0.25: after dynamic relaxation σzz = −ρ g (H − z) at each element centroid,
/// within 1 % of ρ g H.
#[test]
fn gravity_column_stress_after_equilibrium() {
    let (rho, g, h): (f64, f64, f64) = (2500.0, 9.81, 10.0);
    let mesh = box_mesh(&BoxSpec::new("col", [1.0, 1.0, h], [2, 2, 20]));
    let sc = scene(json!({
        "geometry": {"msh": "unused.msh"},
        "materials": [{"group": "block:col", "E": 1e9, "nu": 0.25, "rho": rho}],
        "boundary": [{"group": "col:z0", "fix": ["z"]}, {"group": "col:x0", "fix": ["x"]}, {"group": "col:y0", "fix": ["y"]}],
        "loads": {"gravity": {"g": g}},
        "time": {"duration": 0.0}
    }));
    let pb = problem(mesh, &sc, 0.9);
    let model = &pb.model;
    let mut sim = jointquake::simulation::Simulation::new(&pb).unwrap();
    let eq = sim.relax(1e-7, 200_000).unwrap();
    let state = &sim.state;
    assert!(eq.converged, "relaxation: {eq:?}");
    let mut stress = Vec::new();
    model.element_stress_into(&state.u, &mut stress);
    let mut worst: f64 = 0.0;
    for (e, s) in stress.iter().enumerate() {
        let nodes = model.hexes.nodes[e];
        let zc = nodes.iter().map(|&n| model.mesh.nodes[n as usize][2]).sum::<f64>() / 8.0;
        let exact = -rho * g * (h - zc);
        worst = worst.max((s[2] - exact).abs());
    }
    eprintln!("gravity column: {} relaxation steps, residual {:.1e}, worst σzz error {:.3} % of ρgH", eq.steps, eq.residual, 100.0 * worst / (rho * g * h));
    assert!(worst < 0.01 * rho * g * h);
}

/// The same scene gives bit-identical displacements on 1 and 2 threads (colour-ordered assembly).
#[test]
fn results_identical_on_one_and_two_threads() {
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let mesh = box_mesh(&BoxSpec::new("b", [4.0, 1.0, 1.0], [24, 6, 6]).tets(true));
            let sc = scene(json!({
                "geometry": {"msh": "unused.msh"},
                "materials": [{"group": "block:b", "E": 1e9, "nu": 0.25, "rho": 2000.0}],
                "boundary": [{"group": "b:x0"}],
                "loads": {"traction": [{"group": "b:x1", "traction": [1e5, 2e5, -3e5]}]},
                "time": {"duration": 1.0}
            }));
            simulate(&problem(mesh, &sc, 0.9), 200, |_, _| {}).1.u
        })
    };
    let a = run(1);
    let b = run(2);
    assert!(a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()));
}

/// Inertia apart from weight (design §4 "Mass"): a free box (no supports) falls under gravity
/// with an added inertia A = m_a n nᵀ (n = (1, 2, 2)/3, oblique, so it couples the directions) on
/// its top nodes. Reference: the discrete momentum balance of central differences on a free
/// body (Σ K u = 0 for a rigid translation): Σ M v[N−½] = N dt W after N steps from rest, with
/// M the full inertia (blocks included) and W = Σ m_g g the weight (no weight from A). Tolerance
/// 1e-9 of |N dt W| per component; the energy balance error stays below 1e-9 (KE includes ½vᵀAv).
#[test]
fn added_inertia_moves_with_the_full_block_but_adds_no_weight() {
    use jointquake::simulation::Simulation;
    use nalgebra::Vector3;
    let mesh = box_mesh(&BoxSpec::new("b", [1.0, 1.0, 1.0], [3, 3, 3]));
    let sc = scene(json!({
        "geometry": {"msh": "unused.msh"},
        "materials": [{"group": "block:b", "E": 1e9, "nu": 0.25, "rho": 2000.0}],
        "loads": {"gravity": {"g": 9.81}},
        "equilibrium": {"method": "none"},
        "time": {"duration": 1.0}
    }));
    let mut pb = problem(mesh, &sc, 0.9);
    let top = pb.model.mesh.group_nodes("b:z1").unwrap();
    let n = Vector3::new(1.0, 2.0, 2.0) / 3.0;
    let m_a = 500.0;
    for &node in &top {
        pb.model.add_inertia(node, n * n.transpose() * m_a);
    }
    assert_eq!(pb.model.mass.blocks.len(), top.len());
    let weight: f64 = pb.model.mass.total_weight_mass() * 9.81;
    let mut sim = Simulation::new(&pb).unwrap();
    let steps = 300;
    for _ in 0..steps {
        sim.step().unwrap();
    }
    let dt = sim.dt();
    let st = &sim.state;
    let mut p = Vector3::zeros();
    for node in 0..pb.model.n_nodes() {
        let v = Vector3::from_fn(|c, _| (st.u[3 * node + c] - st.u_prev[3 * node + c]) / dt);
        p += pb.model.mass.apply(node, &v);
    }
    let expect = Vector3::new(0.0, 0.0, -(steps as f64) * dt * weight);
    eprintln!("momentum {p:?}, expected {expect:?}, energy error {:e}", st.energy.max_error);
    assert!((p - expect).norm() < 1e-9 * expect.norm(), "momentum {p:?} vs {expect:?}");
    assert!(st.energy.max_error.abs() < 1e-9, "energy balance {}", st.energy.max_error);
    // the blocks matter: the top nodes fall slower than the bottom ones (a diagonal mass
    // would have given the same uniform free fall everywhere)
    let bottom = pb.model.mesh.group_nodes("b:z0").unwrap();
    let uz = |ns: &[usize]| ns.iter().map(|&k| st.u[3 * k + 2]).sum::<f64>() / ns.len() as f64;
    assert!(uz(&top) > uz(&bottom), "top {} vs bottom {}", uz(&top), uz(&bottom));
}

/// Nodes without inertia (a massless block, ρ = 0, as the massless foundation will be before
/// its static condensation) are held by the prediction (u = 0, no division by a zero mass) and
/// set no stable step: a massive box beside a massless one steps exactly as alone. Reference:
/// the massive box alone, same steps; tolerance 1e-12 of its largest displacement (the element
/// storage order differs, so the sums may round differently).
#[test]
fn massless_nodes_are_held_and_set_no_stable_step() {
    use jointquake::mesh::structured::add_box;
    use jointquake::mesh::Mesh;
    let build = |with_massless: bool| {
        let mut mesh = Mesh { source: "<boxes>".into(), nodes: vec![], node_tags: vec![], cells: vec![], groups: vec![] };
        add_box(&mut mesh, &BoxSpec::new("m", [1.0, 1.0, 1.0], [3, 3, 3]));
        let mut materials = vec![json!({"group": "block:m", "E": 1e9, "nu": 0.25, "rho": 2000.0})];
        if with_massless {
            add_box(&mut mesh, &BoxSpec::new("f", [1.0, 1.0, 1.0], [2, 2, 2]).at([3.0, 0.0, 0.0]));
            materials.push(json!({"group": "block:f", "E": 1e10, "nu": 0.25, "rho": 0.0}));
        }
        let sc = scene(json!({
            "geometry": {"msh": "unused.msh"}, "materials": materials,
            "boundary": [{"group": "m:z0"}],
            "loads": {"gravity": {"g": 9.81}}, "equilibrium": {"method": "none"}, "time": {"duration": 1.0}
        }));
        let model = jointquake::model::Model::build(mesh, &sc).unwrap();
        jointquake::problem::Problem::from_model(sc, model).unwrap()
    };
    let (alone, both) = (build(false), build(true));
    assert_eq!(alone.model.stable_dt(), both.model.stable_dt(), "the massless box must not set the step");
    let massless: Vec<usize> = both.model.mesh.group_nodes("block:f").unwrap();
    assert!(massless.iter().all(|&n| both.model.mass.inertial[n] == 0.0 && both.model.held[n] == 7 && both.model.fixed[n] == 0));
    let (_, a) = simulate(&alone, 200, |_, _| {});
    let (_, b) = simulate(&both, 200, |_, u| assert!(u.iter().all(|x| x.is_finite())));
    assert!(massless.iter().all(|&n| (0..3).all(|c| b.u[3 * n + c] == 0.0)));
    let scale = a.u.iter().map(|x| x.abs()).fold(0.0, f64::max);
    let diff = (0..alone.model.n_nodes() * 3).map(|i| (a.u[i] - b.u[i]).abs()).fold(0.0, f64::max);
    assert!(scale > 0.0 && diff < 1e-12 * scale, "massive box differs by {diff:e} of {scale:e}");
}
