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

/// The element loop on more than one thread runs the chunks on their dependency graph
/// (`model::ChunkGraph`): a chunk waits only for the earlier chunks that share one of its nodes,
/// not for a whole colour. Checked on a mixed box (hexes and Kuhn tets sharing nodes, so the
/// graph joins the two kinds' chunks): (1) every two chunks in a row, in the one-thread order,
/// to touch a node are joined by an edge, so no two chunks that share a node ever run at once;
/// (2) K u on two threads, 20 times, is bit-identical to K u on one thread (reference: one
/// thread; tolerance: none, bits).
#[test]
fn element_loop_on_the_chunk_graph_is_bit_identical_to_one_thread() {
    let mesh = box_mesh(&BoxSpec::new("b", [4.0, 1.0, 1.0], [24, 8, 8]).mixed(true));
    let sc = scene(json!({
        "geometry": {"msh": "unused.msh"},
        "materials": [{"group": "block:b", "E": 1e9, "nu": 0.25, "rho": 2000.0}],
        "boundary": [{"group": "b:x0"}],
        "time": {"duration": 1.0}
    }));
    let pb = problem(mesh, &sc, 0.9);
    let m = &pb.model;
    let (t, h) = (&m.tets.schedule, &m.hexes.schedule);
    assert!(t.chunks.len() > 2 && h.chunks.len() > 2 && m.chunk_graph.len() == t.chunks.len() + h.chunks.len(), "both kinds cut into chunks");
    // (1) consecutive chunks touching a node are joined by an edge
    let mut last = vec![usize::MAX; m.n_nodes()];
    let mut k = 0;
    for s in [t, h] {
        for c in 0..s.chunks.len() {
            for &v in &s.chunk_nodes[s.chunk_node_start[c]..s.chunk_node_start[c + 1]] {
                let prev = std::mem::replace(&mut last[v as usize], k);
                assert!(prev == usize::MAX || m.chunk_graph.successors(prev).contains(&(k as u32)), "node {v}: chunk {k} does not wait for chunk {prev}");
            }
            k += 1;
        }
    }
    // (2) K u on 1 and 2 threads
    let u: Vec<f64> = (0..3 * m.n_nodes()).map(|i| 1e-3 * ((i as f64 * 0.618).sin() + 0.1 * (i as f64 * 1.7).cos())).collect();
    let ku = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        let mut f = vec![0.0; u.len()];
        pool.install(|| m.internal_forces_into(&u, &mut f));
        f
    };
    let one = ku(1);
    assert!(one.iter().any(|&v| v != 0.0));
    for _ in 0..20 {
        let two = ku(2);
        assert!(one.iter().zip(&two).all(|(a, b)| a.to_bits() == b.to_bits()), "2 threads differ from 1");
    }
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

/// The prism of [`wave_in_prism_matches_dalembert`] with the section at x = 5 m moved 0.1 m
/// towards the load's far end: element 24 is 0.1 m long (half the others, half their step),
/// element 25 0.3 m.
fn prism_with_a_short_element() -> jointquake::mesh::Mesh {
    let mut mesh = box_mesh(&BoxSpec::new("prism", [10.0, 1.0, 1.0], [50, 1, 1]));
    for x in mesh.nodes.iter_mut() {
        if (x[0] - 5.0).abs() < 1e-9 {
            x[0] = 4.9;
        }
    }
    mesh
}

/// Issue 19, mass scaling's error measured (docs/elements.md "Mass scaling"). The d'Alembert
/// wave of [`wave_in_prism_matches_dalembert`] (σ0 step at x = L, fixed at 0, ν = 0: the end
/// displacement is a triangle of peak 2σ0L/E over 0 … 4L/c) on the prism with one short
/// element, run (1) unscaled, at 0.9 of its step (set by the short element), and (2) with
/// `time.mass_scaling` to 0.7 × the regular elements' step: only the short element is scaled,
/// by s ≈ 2, and the step grows by about 1.4. Reference for the tolerance: a heavier segment of
/// length l acts on a wave like a lumped mass (s − 1) ρ A l: it reflects a pulse of displacement
/// v0 τ, τ = (s − 1) l / (2c) (doubled at the loaded end, a free end for the reflection: v0 (s − 1)
/// l / c = ½ f of the peak 2 v0 L / c, with f = (s − 1) l / L the added mass fraction), and
/// delays the transmitted wave by (l/c)(√s − 1) ≤ τ (another ≤ ½ f once back at the end). So the
/// end's displacement changes by at most about f of the peak. Tolerance: the scaled run's worst
/// deviation from d'Alembert may exceed the unscaled one's by at most f × peak. Measured: the
/// short element scaled by 1.96 (0.96 % added mass), the step 1.40× larger, the worst deviation
/// 1.056 % of the peak unscaled and 1.284 % scaled: +0.23 % against the tolerance 0.96 %
/// (docs/elements.md "Mass scaling").
#[test]
fn mass_scaling_error_on_the_wave_is_within_the_added_mass_fraction() {
    let (l, e, rho, s0): (f64, f64, f64, f64) = (10.0, 1e9, 2000.0, 1e6);
    let c = (e / rho).sqrt();
    let v0 = s0 / (rho * c);
    let peak = 2.0 * s0 * l / e;
    let base = json!({
        "geometry": {"msh": "unused.msh"},
        "materials": [{"group": "block:prism", "E": e, "nu": 0.0, "rho": rho}],
        "boundary": [{"group": "prism:x0"}],
        "loads": {"traction": [{"group": "prism:x1", "traction": [s0, 0.0, 0.0]}]},
        "time": {"duration": 1.0}
    });
    // the regular elements' step: that of the uniform prism
    let t_reg = problem(box_mesh(&BoxSpec::new("prism", [l, 1.0, 1.0], [50, 1, 1])), &scene(base.clone()), 0.9).model.stable_dt();
    let worst_of = |sc: serde_json::Value| -> (f64, f64, Option<jointquake::model::mass_scaling::MassScaling>) {
        let mesh = prism_with_a_short_element();
        let end = mesh.group_nodes("prism:x1").unwrap();
        let pb = problem(mesh, &scene(sc), 0.9);
        let dt = 0.9 * pb.model.stable_dt();
        let steps = (4.0 * l / c / dt) as usize;
        let mut worst: f64 = 0.0;
        simulate(&pb, steps, |t, u| {
            let exact = if t < 2.0 * l / c { v0 * t } else { v0 * (4.0 * l / c - t) };
            worst = worst.max((mean_u(u, &end, 0) - exact).abs());
        });
        (worst, dt, pb.model.mass_scaling.clone())
    };
    let (w0, dt0, none) = worst_of(base.clone());
    assert!(none.is_none());
    let mut scaled = base.clone();
    scaled["time"]["mass_scaling"] = json!({"target_dt": 0.9 * 0.7 * t_reg});
    let (w1, dt1, ms) = worst_of(scaled);
    let ms = ms.expect("scaled");
    let f = ms.added_fraction();
    eprintln!(
        "wave with a short element: unscaled dt {dt0:.4e} s, worst {:.3} % of the peak; scaled (1 element × {:.3}, added {:.3} % of the mass) dt {dt1:.4e} s ({:.2} ×), worst {:.3} % of the peak; change {:+.3} % (tolerance {:.3} %)",
        100.0 * w0 / peak, ms.max_factor, 100.0 * f, dt1 / dt0, 100.0 * w1 / peak, 100.0 * (w1 - w0) / peak, 100.0 * f
    );
    assert_eq!(ms.scaled_elements, 1, "only the short element");
    assert!((dt1 - 0.9 * 0.7 * t_reg).abs() < 1e-9 * dt1, "the step reaches the target");
    assert!(dt1 > 1.3 * dt0, "the step grows: {dt1} vs {dt0}");
    assert!(w1 - w0 <= f * peak, "error change {:.3} % of the peak above the added fraction {:.3} %", 100.0 * (w1 - w0) / peak, 100.0 * f);
}

/// Issue 19, mass scaling keeps the weight: gravity acts on the unscaled (gravitational) mass.
/// (1) sliver_tet.msh under gravity with `time.mass_scaling` to the unaltered mesh's step: the
/// external force of every node equals the unscaled model's, and their sum is ρ g V (V summed
/// from the element volumes), to 1e-12 relative. (2) A gravity column (as
/// [`gravity_column_stress_after_equilibrium`]) with one thin element layer (0.3 m of 0.5 m), its
/// step raised 1.2× (measured: its 4 elements scaled, 1.32 % added mass), relaxed to 1e-8: the
/// base reaction Σ (K u − F)_z equals ρ g V (the weight) to 1e-6 relative (the relaxation's
/// tolerance with margin), and the displacement field the unscaled one's (static: the mass does
/// not enter) to 1e-6 of its peak.
#[test]
fn mass_scaling_leaves_the_weight_and_the_static_state_unchanged() {
    use jointquake::dynamics::loads::Loads;
    use jointquake::model::Model;
    let fixture = crate::common::fixture("sliver_tet.msh");
    let base = json!({
        "geometry": {"msh": fixture},
        "materials": [
            {"group": "block:lower", "E": 30e9, "nu": 0.2, "rho": 2400},
            {"group": "block:upper", "E": 30e9, "nu": 0.2, "rho": 2400}
        ],
        "boundary": [{"group": "bc:base"}],
        "loads": {"gravity": {"g": 9.81}},
        "time": {"duration": 0.0}
    });
    let model0 = Model::build(jointquake::mesh::Mesh::from_msh(&fixture).unwrap(), &scene(base.clone())).unwrap();
    // target: the unaltered boxes_tet.msh's step (measured: only the sliver is below it, factor 98)
    let mut unaltered = base.clone();
    unaltered["geometry"]["msh"] = json!(crate::common::fixture("boxes_tet.msh"));
    let regular = Model::build(jointquake::mesh::Mesh::from_msh(crate::common::fixture("boxes_tet.msh")).unwrap(), &scene(unaltered)).unwrap().stable_dt();
    let mut sc = base.clone();
    sc["time"]["mass_scaling"] = json!({"target_dt": 0.9 * regular});
    let model1 = Model::build(jointquake::mesh::Mesh::from_msh(&fixture).unwrap(), &scene(sc.clone())).unwrap();
    let ms = model1.mass_scaling.clone().unwrap();
    assert!(ms.scaled_elements >= 1 && ms.added_fraction() > 0.0, "{ms:?}");
    eprintln!("sliver_tet.msh scaled to the regular step: {} elements, added {:.3} %", ms.scaled_elements, 100.0 * ms.added_fraction());
    let force = |m: &Model, s: &serde_json::Value| {
        let (loads, _) = Loads::build(m, &scene(s.clone())).unwrap();
        let mut f = vec![0.0; 3 * m.n_nodes()];
        loads.external_force_into(m, 0.0, true, false, &mut f);
        f
    };
    let (f0, f1) = (force(&model0, &base), force(&model1, &sc));
    let fmax = f0.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    let diff = f0.iter().zip(&f1).fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
    assert!(diff <= 1e-12 * fmax, "nodal gravity forces differ by {diff:e} (max {fmax:e})");
    let volume: f64 = model1.tets.geom.iter().map(|g| g.vol).sum();
    let weight = 2400.0 * 9.81 * volume;
    let fz: f64 = f1.iter().skip(2).step_by(3).sum();
    assert!((fz + weight).abs() <= 1e-12 * weight, "Σ f_z {fz} vs −ρgV {}", -weight);
    let inertia = model1.mass.total_along(&nalgebra::Vector3::z());
    assert!((inertia - (1.0 + ms.added_fraction()) * weight / 9.81).abs() < 1e-12 * inertia, "the inertia is scaled: {inertia}");

    // (2) a relaxed column with a thin layer
    let (rho, g, h): (f64, f64, f64) = (2500.0, 9.81, 10.0);
    let column = || {
        let mut mesh = box_mesh(&BoxSpec::new("col", [1.0, 1.0, h], [2, 2, 20]));
        for x in mesh.nodes.iter_mut() {
            if (x[2] - 5.0).abs() < 1e-9 {
                x[2] = 4.8;
            }
        }
        mesh
    };
    let col = json!({
        "geometry": {"msh": "unused.msh"},
        "materials": [{"group": "block:col", "E": 1e9, "nu": 0.25, "rho": rho}],
        "boundary": [{"group": "col:z0", "fix": ["z"]}, {"group": "col:x0", "fix": ["x"]}, {"group": "col:y0", "fix": ["y"]}],
        "loads": {"gravity": {"g": g}},
        "time": {"duration": 0.0}
    });
    let relaxed = |sc: serde_json::Value| {
        let pb = problem(column(), &scene(sc), 0.9);
        let mut sim = jointquake::simulation::Simulation::new(&pb).unwrap();
        let eq = sim.relax(1e-8, 400_000).unwrap();
        assert!(eq.converged, "{eq:?}");
        let mut fi = vec![0.0; sim.state.u.len()];
        pb.model.internal_forces_into(&sim.state.u, &mut fi);
        let mut fe = vec![0.0; sim.state.u.len()];
        pb.loads.external_force_into(&pb.model, 0.0, true, false, &mut fe);
        let base_nodes = pb.model.mesh.group_nodes("col:z0").unwrap();
        let reaction: f64 = base_nodes.iter().map(|&n| fi[3 * n + 2] - fe[3 * n + 2]).sum();
        (sim.state.u.clone(), reaction, pb.model.stable_dt(), pb.model.mass_scaling.clone())
    };
    let (u0, r0, dt0, _) = relaxed(col.clone());
    let mut cs = col.clone();
    cs["time"]["mass_scaling"] = json!({"target_dt": 0.9 * 1.2 * dt0});
    let (u1, r1, dt1, ms) = relaxed(cs);
    let ms = ms.unwrap();
    assert!(ms.scaled_elements > 0 && (dt1 - 1.2 * dt0).abs() < 1e-9 * dt1, "{ms:?}, {dt1} vs {dt0}");
    let w = rho * g * h;
    eprintln!("column: reaction {r0:.6e} N unscaled, {r1:.6e} N scaled, weight {w:.6e} N; {} elements scaled, added {:.3} %", ms.scaled_elements, 100.0 * ms.added_fraction());
    assert!((r0 - w).abs() < 1e-6 * w && (r1 - w).abs() < 1e-6 * w, "reactions {r0} {r1} vs {w}");
    let umax = u0.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    let du = u0.iter().zip(&u1).fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
    assert!(du < 1e-6 * umax, "static states differ by {du:e} (peak {umax:e})");
}
