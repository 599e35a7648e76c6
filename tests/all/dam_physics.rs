//! Dam physics: massless foundation (static condensation), reservoir (hydrostatic, added mass),
//! natural frequencies (docs/dam_physics.md). Each test states its reference and tolerance.

use crate::common::{problem, scene, scratch, stiff_block_base_shear};
use jointquake::linalg::{dof_map, lowest_modes, mass_matrix, restrict, stiffness, ModesOptions, NONE};
use jointquake::mesh::structured::{box_mesh, BoxSpec};
use jointquake::mesh::{Group, Mesh};
use jointquake::problem::foundation::CondensationMethod;
use jointquake::simulation::{FnObserver, Simulation};

/// Both condensation methods (docs/dam_physics.md): every massless-foundation test runs on each.
const METHODS: [CondensationMethod; 2] = [CondensationMethod::Solve, CondensationMethod::Schur];

/// A structured box whose cells are split into two volume groups: `block:<lower>` for cells
/// with centroid z below `z_cut`, `block:<upper>` above (conforming: shared nodes).
fn split_box(size: [f64; 3], div: [usize; 3], z_cut: f64, lower: &str, upper: &str) -> Mesh {
    let mut m = box_mesh(&BoxSpec::new("b", size, div));
    let cells = m.group("block:b").unwrap().cells.clone();
    let (mut lo, mut hi) = (Vec::new(), Vec::new());
    for c in cells {
        let z: f64 = m.cells[c].nodes().iter().map(|&v| m.nodes[v as usize][2]).sum::<f64>() / 8.0;
        if z < z_cut { lo.push(c) } else { hi.push(c) }
    }
    m.groups.retain(|g| g.name != "block:b");
    m.groups.push(Group { name: format!("block:{lower}"), dim: 3, tag: 101, cells: lo });
    m.groups.push(Group { name: format!("block:{upper}"), dim: 3, tag: 102, cells: hi });
    m
}

/// The dense condensed problem on the dofs with mass: S = K_bb − K_bf K_ff⁻¹ K_fb and the
/// lowest eigenvalue of M_b⁻¹ S (nalgebra, dense).
fn dense_condensed_first_omega2(model: &jointquake::model::Model) -> f64 {
    let k = stiffness(model, &vec![true; model.materials.len()]);
    let n = 3 * model.n_nodes();
    let free = |d: usize| model.is_free(d / 3, d % 3) && k.col_ptr[d + 1] > k.col_ptr[d];
    let (bmap, nb) = dof_map(n, |d| free(d) && model.mass.inertial[d / 3] > 0.0);
    let (fmap, nf) = dof_map(n, |d| free(d) && model.mass.inertial[d / 3] == 0.0);
    let kd = |rm: &[usize], nr, cm: &[usize], nc| restrict(&k, rm, nr, cm, nc).to_dense();
    let kbb = kd(&bmap, nb, &bmap, nb);
    let kbf = kd(&bmap, nb, &fmap, nf);
    let kff = kd(&fmap, nf, &fmap, nf);
    let s = &kbb - &kbf * kff.cholesky().unwrap().solve(&kbf.transpose());
    let mb = mass_matrix(&model.mass.inertial, &[], &bmap, nb).to_dense();
    let li = mb.cholesky().unwrap().l().try_inverse().unwrap();
    let a = &li * s * li.transpose();
    let a = (&a + a.transpose()) * 0.5;
    nalgebra::SymmetricEigen::new(a).eigenvalues.iter().copied().fold(f64::INFINITY, f64::min)
}

fn column_scene(extra: serde_json::Value) -> jointquake::scene::Scene {
    // a 1 × 1 × 10 m massless column (E = 1 GPa, ν = 0) under a 1 m stiff heavy cap
    // (E = 10⁴ GPa, ρ = 10⁵ kg/m³: m = 10⁵ kg), base fixed
    let mut v = serde_json::json!({
        "geometry": {"msh": "none.msh"},
        "materials": [
            {"group": "block:col", "E": 1e9, "nu": 0.0, "rho": 2000.0, "massless": true},
            {"group": "block:cap", "E": 1e13, "nu": 0.0, "rho": 1e5}
        ],
        "boundary": [{"group": "b:z0"}],
        "time": {"duration": 1.0}
    });
    for (k, x) in extra.as_object().unwrap() {
        v[k] = x.clone();
    }
    scene(v)
}

#[test]
fn mass_on_a_massless_column_vibrates_at_the_static_stiffness() {
    // Reference: 1 DOF, ω² = k/m with k = EA/L = 1e9 · 1 / 10 = 1e8 N/m, m = 10⁵ kg (the cap):
    // ω = 31.623 rad/s, T = 0.19869 s (the cap's own flexibility shifts it by ~1e-4). A step
    // traction on the cap's top gives u(t) = (F/k)(1 − cos ωt); the measured period (mean of
    // three, from the crossings of the static value) within 1 %. Also: the condensed
    // foundation carries no mass, so the cap's static deflection is F/k (1e-3).
    for method in METHODS {
        step_load_on_the_massless_column(method);
    }
}

fn step_load_on_the_massless_column(method: CondensationMethod) {
    let mesh = split_box([1.0, 1.0, 11.0], [1, 1, 11], 10.0, "col", "cap");
    let sc = column_scene(serde_json::json!({"loads": {"traction": [{"group": "b:z1", "traction": [0.0, 0.0, -1e6]}]}}));
    let pb = problem(mesh, &sc, 0.9);
    let mut sim = Simulation::with_condensation(&pb, Some(method)).unwrap();
    assert_eq!(sim.foundation.as_ref().map(|f| f.method()), Some(method), "the massless column is condensed");
    let top: Vec<usize> = pb.model.mesh.group_nodes("b:z1").unwrap();
    let (k, m, f) = (1e8, 1e5, 1e6);
    let static_u = -f / k;
    let w = (k / m as f64).sqrt();
    let dt = sim.dt();
    let steps = (3.2 * 2.0 * std::f64::consts::PI / w / dt) as usize;
    let mut prev = 0.0;
    let mut crossings = Vec::new();
    let mut peak = 0.0f64;
    for _ in 0..steps {
        sim.step().unwrap();
        let u = top.iter().map(|&n| sim.state.u[3 * n + 2]).sum::<f64>() / top.len() as f64;
        peak = peak.min(u);
        let (a, b) = (prev - static_u, u - static_u);
        if a > 0.0 && b <= 0.0 || a < 0.0 && b >= 0.0 {
            let t = sim.state.t - dt * b / (b - a);
            crossings.push(t);
        }
        prev = u;
    }
    assert!(crossings.len() >= 6, "crossings {crossings:?}");
    // crossings every half period: T = 2 (t_{i+2} − t_i)/2
    let periods: Vec<f64> = (0..crossings.len() - 2).step_by(2).map(|i| crossings[i + 2] - crossings[i]).collect();
    let t_mean = periods.iter().sum::<f64>() / periods.len() as f64;
    let t_exact = 2.0 * std::f64::consts::PI / w;
    println!("massless column ({method:?}): T = {t_mean:.6} s, exact {t_exact:.6} s ({:+.3} %), peak {peak:.4e} m (2 F/k = {:.4e})", 100.0 * (t_mean / t_exact - 1.0), 2.0 * static_u);
    assert!((t_mean / t_exact - 1.0).abs() < 0.01, "period {t_mean} vs {t_exact}");
    assert!((peak / (2.0 * static_u) - 1.0).abs() < 0.01, "peak {peak} vs 2F/k {}", 2.0 * static_u);
}

#[test]
fn modes_of_the_massless_column_are_the_condensed_one_dof() {
    // Reference: the dense condensed problem (S = K_bb − K_bf K_ff⁻¹ K_fb, M_b) solved with
    // nalgebra: the sparse shift-invert Lanczos on the full K with the singular M gives the same
    // ω² to 1e-7 (both direct; the cap is 10⁴ times stiffer than the column, so the dense
    // Schur complement loses about 8 digits: measured 1e-8); and ω² = (EA/L)/m within 1e-3 (the cap's flexibility, 1e-4, and its
    // rotational inertia in the bending modes do not enter the axial mode)
    let mesh = split_box([1.0, 1.0, 11.0], [1, 1, 11], 10.0, "col", "cap");
    let pb = problem(mesh, &column_scene(serde_json::json!({})), 0.9);
    let model = &pb.model;
    let k = stiffness(model, &vec![true; model.materials.len()]);
    let n = 3 * model.n_nodes();
    let (map, nf) = dof_map(n, |d| model.is_free(d / 3, d % 3));
    let modes = lowest_modes(&restrict(&k, &map, nf, &map, nf), &mass_matrix(&model.mass.inertial, &[], &map, nf), &ModesOptions { count: 6, ..Default::default() }).unwrap();
    let dense = dense_condensed_first_omega2(model);
    assert!((modes.omega2[0] - dense).abs() < 1e-7 * dense, "first ω² {} vs dense condensed {dense}", modes.omega2[0]);
    // the axial mode: the one whose shape is along z at the cap
    let top = model.mesh.group_nodes("b:z1").unwrap()[0];
    let axial = (0..modes.omega2.len())
        .max_by(|&a, &b| {
            let z = |i: usize| modes.shapes[i][map[3 * top + 2]].abs() / (modes.shapes[i][map[3 * top]].abs() + 1e-30);
            z(a).total_cmp(&z(b))
        })
        .unwrap();
    let exact = 1e8 / 1e5;
    println!("massless column: axial mode {axial}, ω² = {:.6} (EA/(L m) = {exact})", modes.omega2[axial]);
    assert!((modes.omega2[axial] / exact - 1.0).abs() < 1e-3);
    assert!(map.iter().filter(|&&d| d != NONE).count() == nf);
}

#[test]
fn block_on_a_massless_foundation_first_frequency_equals_the_dense_condensation() {
    // Reference: the dense condensed stiffness S on the block's dofs (nalgebra), lowest
    // eigenvalue of M⁻¹ S; the sparse Lanczos (full K, singular M) to 1e-6 relative. A 4 × 4 × 2
    // m massless foundation (E = 20 GPa, ν = 0.25, base fixed) under a 4 × 4 × 1 m block
    // (E = 25 GPa, ρ = 2400), hex8 4 × 4 × 3.
    let mesh = split_box([4.0, 4.0, 3.0], [4, 4, 3], 2.0, "rock", "dam");
    let sc = scene(serde_json::json!({
        "geometry": {"msh": "none.msh"},
        "materials": [
            {"group": "block:rock", "E": 2e10, "nu": 0.25, "rho": 2700.0, "massless": true},
            {"group": "block:dam", "E": 2.5e10, "nu": 0.2, "rho": 2400.0}
        ],
        "boundary": [{"group": "b:z0"}],
        "time": {"duration": 0.0}
    }));
    let pb = problem(mesh, &sc, 0.9);
    let model = &pb.model;
    let k = stiffness(model, &vec![true; model.materials.len()]);
    let n = 3 * model.n_nodes();
    let (map, nf) = dof_map(n, |d| model.is_free(d / 3, d % 3));
    let modes = lowest_modes(&restrict(&k, &map, nf, &map, nf), &mass_matrix(&model.mass.inertial, &[], &map, nf), &ModesOptions { count: 3, ..Default::default() }).unwrap();
    let dense = dense_condensed_first_omega2(model);
    println!("block on massless rock: f1 = {:.6} Hz (dense condensed {:.6} Hz)", modes.frequency(0), dense.sqrt() / (2.0 * std::f64::consts::PI));
    assert!((modes.omega2[0] - dense).abs() < 1e-6 * dense);
    // the massless elements set no stable step: the critical element is in the dam
    assert_eq!(model.critical.group, "block:dam");
}

#[test]
fn base_shear_of_a_stiff_block_with_a_wet_face_includes_the_westergaard_mass() {
    // Reference: quasi-static rigid response to a uniform base acceleration a along x (the wet
    // face's normal): base shear V = (M + (7/12) ρw H² b) a (Westergaard 1933), with M the
    // block's mass, H = 10 m, b = 3 m. The base shear is the reaction at the fixed base, from
    // the stiffness (Σ over the fixed x dofs of (K u)) plus the inertia of the base nodes, which
    // move with the ground. Block 2 × 3 × 10 m, E = 10⁵ GPa (stiff: f1 ≈ 400 Hz), the record
    // ramps to 0.2 g over 0.2 s and holds; V read at 0.3 s. Tolerance 1 % (the nodal added mass
    // sum is −0.3 % low at 20 nodes over H; hydrostatic off, so V has no static part).
    let mesh = box_mesh(&BoxSpec::new("b", [2.0, 3.0, 10.0], [2, 3, 20]));
    let reservoir = serde_json::json!({"faces": ["b:x0"], "level": 10.0, "hydrostatic": false});
    let (v, m_total, a, _) = stiff_block_base_shear("dam_base_shear", mesh, reservoir, false);
    let expect = (m_total + 7.0 / 12.0 * 1000.0 * 100.0 * 3.0) * a;
    let dry = m_total * a;
    println!("wet base shear {v:.5e} N, expected {expect:.5e} N ({:+.3} %), dry {dry:.5e} N", 100.0 * (v / expect - 1.0));
    assert!((v / expect - 1.0).abs() < 0.01, "base shear {v} vs (M + 7/12 ρ H² b) a = {expect}");
}

#[test]
fn modes_command_on_the_cantilever_fixture() {
    // Reference: Euler–Bernoulli cantilever L = 10, b = h = 1 m (E = 1 GPa, ν = 0, ρ = 2000):
    // ω1 = 1.875104² √(E I / (ρ A L⁴)) = 7.177 rad/s in both bending planes (square section),
    // first-mode effective mass 0.6131 of the total (Chopra, Dynamics of Structures, cantilever
    // mode 1). hex8 20 × 1 × 2 (tests/fixtures/cantilever_hex.msh): f within 3 %, the effective
    // mass fraction within 3 % (of the mass the ground moves: the clamped nodes excluded).
    let dir = scratch("dam_modes_cli");
    let sc = scene(serde_json::json!({
        "geometry": {"msh": crate::common::fixture("cantilever_hex.msh")},
        "materials": [{"group": "block:beam", "E": 1e9, "nu": 0.0, "rho": 2000.0}],
        "boundary": [{"group": "bc:fixed"}],
        "time": {"duration": 0.0}
    }));
    let mesh = Mesh::from_msh(crate::common::fixture("cantilever_hex.msh")).unwrap();
    let pb = problem(mesh, &sc, 0.9);
    let r = jointquake::statics::modes::modes(&pb, 4, &dir).unwrap();
    let text = r.to_text();
    println!("{text}");
    let w1 = 1.875104f64.powi(2) * (1e9f64 / 12.0 / (2000.0 * 1e4)).sqrt();
    let f1 = w1 / (2.0 * std::f64::consts::PI);
    for m in &r.modes[..2] {
        assert!((m.frequency_hz / f1 - 1.0).abs() < 0.03, "f = {} Hz vs Euler–Bernoulli {f1} Hz", m.frequency_hz);
        assert!(m.residual < 1e-8);
    }
    // the two bending modes together carry 61.3 % of the mass along y and along z
    for c in [1, 2] {
        let frac: f64 = r.modes[..2].iter().map(|m| m.effective_fraction[c]).sum();
        assert!((frac / 0.6131 - 1.0).abs() < 0.03, "direction {c}: effective fraction {frac}");
    }
    assert!(r.pvd.exists() && dir.join("modes/mode_004.vtu").exists() && dir.join("modes/modes.json").exists());
    let pvd = std::fs::read_to_string(&r.pvd).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 4);
}

fn dam_on_rock_with_a_tied_joint(rho_rock: f64) -> (Mesh, jointquake::scene::Scene) {
    // a 2 × 2 × 1 m dam block (hex 3 × 3 × 2) on a 4 × 4 × 3 m massless rock (hex 4 × 4 × 3):
    // non-conforming, bonded by a tied NTS joint (master the rock's top, slave the dam's base)
    let mut mesh = box_mesh(&BoxSpec::new("rock", [4.0, 4.0, 3.0], [4, 4, 3]));
    jointquake::mesh::structured::add_box(&mut mesh, &BoxSpec::new("dam", [2.0, 2.0, 1.0], [3, 3, 2]).at([1.0, 1.0, 3.0]));
    let sc = scene(serde_json::json!({
        "geometry": {"msh": "none.msh"},
        "materials": [
            {"group": "block:rock", "E": 2e10, "nu": 0.25, "rho": rho_rock, "massless": true},
            {"group": "block:dam", "E": 2.5e10, "nu": 0.2, "rho": 2400.0}
        ],
        "boundary": [{"group": "rock:z0"}],
        "loads": {"gravity": {}},
        "joints": [{"name": "base", "master": "rock:z1", "slave": "dam:z0", "tied": true}],
        "time": {"duration": 0.0}
    }));
    (mesh, sc)
}

#[test]
fn tied_joint_on_a_massless_block_gets_a_weightless_massive_layer() {
    // The decision of docs/dam_physics.md: the rock elements touching the joint keep their
    // density (so the dynamic contact force has nodal masses on the master side) but no weight;
    // the rest of the rock is condensed. Check: the layer nodes have mass and no weight, the
    // condensed unknowns exist, and after gravity relaxation (residual 1e-6) the vertical
    // reaction at the fixed rock base equals the dam's weight alone (ρ g V = 2400 · 9.81 · 4 N)
    // to 1e-4: no weight from the rock or its layer, the load carried through the tied joint
    // and the condensed rock.
    let (mesh, sc) = dam_on_rock_with_a_tied_joint(2700.0);
    let pb = problem(mesh, &sc, 0.9);
    let model = &pb.model;
    let top = model.mesh.group_nodes("rock:z1").unwrap();
    assert!(top.iter().all(|&n| model.mass.inertial[n] > 0.0 && model.mass.weight_mass(n) == 0.0), "layer: mass, no weight");
    assert!(model.condensed.iter().any(|&c| c != 0));
    for method in METHODS {
        let mut sim = Simulation::with_condensation(&pb, Some(method)).unwrap();
        tied_dam_on_massless_rock_carries_its_weight(&pb, &mut sim, method);
    }
}

fn tied_dam_on_massless_rock_carries_its_weight(pb: &jointquake::problem::Problem, sim: &mut Simulation<'_>, method: CondensationMethod) {
    let model = &pb.model;
    assert_eq!(sim.foundation.as_ref().map(|f| f.method()), Some(method));
    let eq = sim.relax(1e-6, 200_000).unwrap();
    assert!(eq.converged, "{eq:?}");
    let mut ku = vec![0.0; 3 * model.n_nodes()];
    model.internal_forces_into(&sim.state.u, &mut ku);
    let base = model.mesh.group_nodes("rock:z0").unwrap();
    let rz: f64 = base.iter().map(|&n| ku[3 * n + 2]).sum();
    let weight = 2400.0 * 9.81 * 4.0;
    println!("dam on massless rock, tied ({method:?}): base reaction {rz:.6e} N, dam weight {weight:.6e} N");
    assert!((rz.abs() / weight - 1.0).abs() < 1e-4, "reaction {rz} vs weight {weight}");
}

#[test]
fn joint_on_a_massless_block_without_density_is_a_clear_error() {
    // rho = 0 leaves the joint's layer without mass: refused, naming the group and the fix
    let (mesh, sc) = dam_on_rock_with_a_tied_joint(0.0);
    let err = jointquake::problem::Problem::build(sc, mesh).unwrap_err().to_string();
    assert!(err.contains("block:rock") && err.contains("joint") && err.contains("rho"), "{err}");
}

/// A record file: a sin² pulse a(t) = a_g sin²(π t / period) [g] for t ≤ period, 0 after,
/// sampled every period / 2000 up to `end`.
fn pulse_record(dir: &std::path::Path, a_g: f64, period: f64, end: f64) -> std::path::PathBuf {
    let p = dir.join("pulse.txt");
    let mut s = String::from("# t [s], a [g]\n");
    let dt = period / 2000.0;
    let n = (end / dt).ceil() as usize;
    for i in 0..=n {
        let t = i as f64 * dt;
        let a = if t <= period { a_g * (std::f64::consts::PI * t / period).sin().powi(2) } else { 0.0 };
        s.push_str(&format!("{t} {a}\n"));
    }
    std::fs::write(&p, s).unwrap();
    p
}

#[test]
fn schur_and_solve_condensations_give_the_same_trajectory() {
    // The two methods of docs/dam_physics.md (a solve for u_f per step; the dense Schur
    // complement S in the step with u_f reconstructed for the observer) are the same linear
    // map in exact arithmetic: u[n+1] from K_massive u + S u_b. Reference: the solve method.
    // The 4 × 4 × 1 m block on the 4 × 4 × 2 m massless foundation, a 0.3 g sin² base pulse
    // along x (0.05 s) and Rayleigh damping (α = 2 1/s, β = 1e-5 s: the β path applies S to
    // u + β v_b), 400 steps; every u[n] of every node (foundation included, reconstructed each
    // step for the observer) within 1e-9 of the largest |u| of the run.
    let dir = scratch("dam_schur_vs_solve");
    let rec = pulse_record(&dir, 0.3, 0.05, 0.2);
    let mesh = split_box([4.0, 4.0, 3.0], [4, 4, 3], 2.0, "rock", "dam");
    let sc = scene(serde_json::json!({
        "geometry": {"msh": "none.msh"},
        "materials": [
            {"group": "block:rock", "E": 2e10, "nu": 0.25, "rho": 2700.0, "massless": true},
            {"group": "block:dam", "E": 2.5e10, "nu": 0.2, "rho": 2400.0}
        ],
        "boundary": [{"group": "b:z0"}],
        "loads": {"base": [{"record": rec, "direction": [1.0, 0.0, 0.0]}]},
        "damping": {"alpha": 2.0, "beta": 1e-5},
        "time": {"duration": 0.2}
    }));
    let pb = problem(mesh, &sc, 0.9);
    let run = |method| {
        let mut sim = Simulation::with_condensation(&pb, Some(method)).unwrap();
        assert_eq!(sim.foundation.as_ref().unwrap().method(), method);
        let mut us: Vec<Vec<f64>> = Vec::new();
        sim.run_steps(400, &mut FnObserver(|s: &Simulation<'_>| us.push(s.state.u.clone()))).unwrap();
        (us, sim.state.energy.clone())
    };
    let (a, ea) = run(CondensationMethod::Solve);
    let (b, eb) = run(CondensationMethod::Schur);
    let scale = a.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    let diff = a.iter().flatten().zip(b.iter().flatten()).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    // the foundation's nodes move (they are reconstructed, not left 0)
    let f0 = pb.model.condensed.iter().position(|&c| c != 0).unwrap();
    let moved = b.iter().map(|u| u[3 * f0].abs()).fold(0.0, f64::max);
    println!("schur vs solve: max |Δu| {diff:.3e} of max |u| {scale:.3e} ({:.2e}); foundation node moves {moved:.3e} m; energy error {:.2e} / {:.2e}", diff / scale, ea.max_error, eb.max_error);
    assert!(scale > 0.0 && moved > 1e-3 * scale);
    assert!(diff <= 1e-9 * scale, "trajectories differ by {diff} (scale {scale})");
    assert!((ea.external_work - eb.external_work).abs() <= 1e-9 * ea.external_work.abs());
    // an observer that reads the foundation every 7th step only (as the recorder does at its
    // frames): there u[n−1], u[n], u[n+1] equal the solve method's, elsewhere the foundation's
    // entries are 0 in all three (never a stale mixture)
    struct Sparse<'a> {
        reference: &'a [Vec<f64>],
        condensed: Vec<usize>,
        checked: usize,
        worst: f64,
    }
    impl jointquake::simulation::Observer for Sparse<'_> {
        fn full_state_due(&self, _sim: &Simulation<'_>, k: usize, _n: usize) -> bool {
            k % 7 == 0
        }
        fn observe(&mut self, sim: &Simulation<'_>, k: usize, _n: usize) -> Result<(), jointquake::Error> {
            let kin = sim.kinematics();
            if k % 7 == 0 {
                // reference[j] is u after step j: u[n+1] here, u[n] one step back, u[n−1] two
                for (back, v) in [kin.u_next, kin.u, kin.u_prev].into_iter().enumerate().filter(|&(back, _)| back <= k) {
                    let r = &self.reference[k - back];
                    let d = v.iter().zip(r.iter()).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
                    self.worst = self.worst.max(d);
                }
                self.checked += 1;
            } else {
                assert!(self.condensed.iter().all(|&d| kin.u_prev[d] == 0.0 && kin.u[d] == 0.0 && kin.u_next[d] == 0.0), "step {k}: stale foundation entries");
            }
            Ok(())
        }
    }
    let condensed: Vec<usize> = (0..3 * pb.model.n_nodes()).filter(|&d| pb.model.condensed[d / 3] & (1 << (d % 3)) != 0).collect();
    let mut obs = Sparse { reference: &a, condensed, checked: 0, worst: 0.0 };
    let mut sim = Simulation::with_condensation(&pb, Some(CondensationMethod::Schur)).unwrap();
    sim.run_steps(400, &mut obs).unwrap();
    println!("schur, foundation read every 7th step: {} checks, max |Δu| {:.3e}", obs.checked, obs.worst);
    assert!(obs.checked == 58 && obs.worst <= 1e-9 * scale);
}

#[test]
fn rigid_block_on_a_massless_foundation_moves_with_the_ground_under_a_slow_pulse() {
    // Reference: a rigid mass m on a massless spring k under a base acceleration a_g(t) much
    // slower than its period moves with the ground; in the relative form its relative
    // displacement is the quasi-static deflection u(t) = −m a_g(t) / k (the base force −m a_g
    // on the spring). Here k = EA/L = 1e8 N/m (the 1 × 1 × 10 m massless column, E = 1 GPa,
    // ν = 0: uniform strain, exact for hex8), m = 10⁵ kg (the cap, 10⁴ times stiffer),
    // T = 2π √(m/k) = 0.199 s; a_g = 0.1 g sin²(π t / 4 s) along z (the column's axis), a pulse
    // 20 T long. The dynamic part is of order (T / T_pulse)² / 2 = 0.13 % of the peak; the cap's
    // own flexibility 1e-4. Tolerance: max_t |u − u_qs| ≤ 1 % of max |u_qs|
    // and the peak itself within 1 %, on both condensation methods (measured 0.25 %, peak +0.24 %).
    let dir = scratch("dam_quasistatic_pulse");
    let (tp, ag) = (4.0, 0.1);
    let rec = pulse_record(&dir, ag, tp, tp);
    let (k, m) = (1e8, 1e5);
    for method in METHODS {
        let mesh = split_box([1.0, 1.0, 11.0], [1, 1, 11], 10.0, "col", "cap");
        let sc = column_scene(serde_json::json!({
            "loads": {"base": [{"record": rec, "direction": [0.0, 0.0, 1.0]}]},
            "time": {"duration": tp}
        }));
        let pb = problem(mesh, &sc, 0.9);
        let top: Vec<usize> = pb.model.mesh.group_nodes("b:z1").unwrap();
        let m_total: f64 = pb.model.mass.inertial.iter().sum();
        assert!((m_total / m - 1.0).abs() < 1e-12, "the column carries no mass: {m_total}");
        let mut sim = Simulation::with_condensation(&pb, Some(method)).unwrap();
        let (mut err, mut peak, mut peak_qs) = (0.0f64, 0.0f64, 0.0f64);
        let n = sim.n_steps();
        for _ in 0..n {
            sim.step().unwrap();
            let t = sim.state.t;
            let a = if t <= tp { ag * 9.81 * (std::f64::consts::PI * t / tp).sin().powi(2) } else { 0.0 };
            let u_qs = -m * a / k;
            let u = top.iter().map(|&nd| sim.state.u[3 * nd + 2]).sum::<f64>() / top.len() as f64;
            err = err.max((u - u_qs).abs());
            peak = peak.max(u.abs());
            peak_qs = peak_qs.max(u_qs.abs());
        }
        println!("rigid block on massless column, slow pulse ({method:?}): max |u − u_qs| = {:.3} % of the peak {peak_qs:.4e} m; peak {peak:.4e} m", 100.0 * err / peak_qs);
        assert!(err <= 0.01 * peak_qs, "{method:?}: max |u − u_qs| = {err} vs peak {peak_qs}");
        assert!((peak / peak_qs - 1.0).abs() < 0.01);
    }
}

/// Euler–Bernoulli cantilever mode n (clamped at ζ = 0, ζ = z / L): φ and φ'' (per unit ζ²),
/// normalised so that ∫₀¹ φ² dζ = 1.
fn cantilever_mode(n: usize, zeta: f64) -> (f64, f64) {
    const BL: [f64; 6] = [1.875104068711961, 4.694091132974175, 7.854757438237613, 10.995540734875467, 14.137168391046471, 17.278759532088237];
    let b = BL[n];
    let s = (b.sinh() - b.sin()) / (b.cosh() + b.cos());
    let x = b * zeta;
    let phi = x.cosh() - x.cos() - s * (x.sinh() - x.sin());
    let d2 = b * b * (x.cosh() + x.cos() - s * (x.sinh() + x.sin()));
    (phi, d2)
}

/// ∫₀¹ f by composite 4-point Gauss–Legendre on 400 intervals.
fn integrate(f: impl Fn(f64) -> f64) -> f64 {
    const X: [f64; 4] = [-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526];
    const W: [f64; 4] = [0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538];
    let n = 400;
    let h = 1.0 / n as f64;
    let mut s = 0.0;
    for i in 0..n {
        for q in 0..4 {
            s += 0.5 * h * W[q] * f((i as f64 + 0.5 + 0.5 * X[q]) * h);
        }
    }
    s
}

#[test]
fn wall_monolith_frequency_drop_with_a_full_reservoir_matches_westergaard() {
    // Reference (closed form, Westergaard 1933 added mass on a flexible monolith, the approach
    // of Chopra's simplified analysis, Fenves & Chopra 1984/1986 UCB/EERC-85/10, and of Miquel
    // & Bouaanani 2010): a rigid-base wall monolith H = 20 m high, t = 1 m thick along x (the
    // upstream face x = 0 wet to the crest), b = 2 m wide, concrete E = 25 GPa, ν = 0, ρ = 2400,
    // water ρw = 1000, incompressible. The dam is an Euler–Bernoulli cantilever (EI = E b t³/12,
    // m = ρ b t per metre) with Westergaard's added mass (7/8) ρw √(H (H − z)) b per metre along
    // x; the wet fundamental frequency from the Rayleigh–Ritz quotient on the first six dry
    // cantilever modes (closed-form shapes, integrals by Gauss quadrature; with one mode it is
    // Rayleigh's estimate, 0.13 % above the six-mode value). Checked: the ratio of the first
    // frequencies full / empty of the hex8 model (2 × 2 × 40, the added mass lumped at the wet
    // nodes along the face normal, `modes` machinery: linalg::lowest_modes) within 1 % of the
    // reference ratio (mesh effects cancel in the ratio; the nodal added-mass sum is −0.1 % at
    // 41 nodes over H). Measured: f 1.3010 → 0.6585 Hz, ratio 0.50613 vs 0.50432 (+0.36 %).
    let (h, t, b, e, rho, rho_w) = (20.0, 1.0, 2.0, 25e9, 2400.0, 1000.0);
    let first_omega2 = |wet: bool| {
        let mesh = box_mesh(&BoxSpec::new("b", [t, b, h], [2, 2, 40]));
        let mut v = serde_json::json!({
            "geometry": {"msh": "none.msh"},
            "materials": [{"group": "block:b", "E": e, "nu": 0.0, "rho": rho}],
            "boundary": [{"group": "b:z0"}],
            "time": {"duration": 0.0}
        });
        if wet {
            v["reservoir"] = serde_json::json!({"faces": ["b:x0"], "level": h, "rho_w": rho_w, "hydrostatic": false});
        }
        let pb = problem(mesh, &scene(v), 0.9);
        let model = &pb.model;
        let k = stiffness(model, &vec![true; model.materials.len()]);
        let n = 3 * model.n_nodes();
        let (map, nf) = dof_map(n, |d| model.is_free(d / 3, d % 3));
        let blocks: Vec<(usize, [[f64; 3]; 3])> = model.mass.blocks.iter().map(|bl| (bl.node as usize, bl.added.into())).collect();
        assert_eq!(blocks.is_empty(), !wet);
        let modes = lowest_modes(&restrict(&k, &map, nf, &map, nf), &mass_matrix(&model.mass.inertial, &blocks, &map, nf), &ModesOptions { count: 3, ..Default::default() }).unwrap();
        // the first mode bends along x (the thin direction, towards the water)
        let crest = model.mesh.group_nodes("b:z1").unwrap()[0];
        let sh = &modes.shapes[0];
        assert!(sh[map[3 * crest]].abs() > 10.0 * sh[map[3 * crest + 1]].abs(), "first mode along x");
        modes.omega2[0]
    };
    let (dry, wet) = (first_omega2(false), first_omega2(true));
    // Rayleigh–Ritz on six cantilever modes
    let nm = 6;
    let ei = e * b * t.powi(3) / 12.0;
    let mass = |wet: bool| {
        nalgebra::DMatrix::from_fn(nm, nm, |i, j| {
            integrate(|z| {
                let (pi, pj) = (cantilever_mode(i, z).0, cantilever_mode(j, z).0);
                let mw = if wet { 0.875 * rho_w * (h * h * (1.0 - z)).max(0.0).sqrt() * b } else { 0.0 };
                (rho * b * t + mw) * pi * pj * h
            })
        })
    };
    let kr = nalgebra::DMatrix::from_fn(nm, nm, |i, j| integrate(|z| ei * cantilever_mode(i, z).1 * cantilever_mode(j, z).1 / h.powi(3)));
    let lowest = |m: nalgebra::DMatrix<f64>| {
        let li = m.cholesky().unwrap().l().try_inverse().unwrap();
        let a = &li * &kr * li.transpose();
        nalgebra::SymmetricEigen::new((&a + a.transpose()) * 0.5).eigenvalues.iter().copied().fold(f64::INFINITY, f64::min)
    };
    let (dry_ref, wet_ref) = (lowest(mass(false)), lowest(mass(true)));
    let eb = 1.875104068711961f64.powi(4) * ei / (rho * b * t * h.powi(4));
    assert!((dry_ref / eb - 1.0).abs() < 1e-6, "Ritz dry {dry_ref} vs Euler–Bernoulli {eb}");
    let rayleigh = {
        let (m0, m1) = (mass(false), mass(true));
        dry_ref * m0[(0, 0)] / m1[(0, 0)]
    };
    let ratio = (wet / dry).sqrt();
    let ratio_ref = (wet_ref / dry_ref).sqrt();
    let tau = 2.0 * std::f64::consts::PI;
    println!(
        "wall monolith H = 20 m: f_empty = {:.4} Hz (E–B {:.4} Hz), f_full = {:.4} Hz; ratio full/empty {ratio:.5}, Westergaard–Ritz {ratio_ref:.5} ({:+.3} %), Rayleigh (dry shape) {:.5}",
        dry.sqrt() / tau,
        eb.sqrt() / tau,
        wet.sqrt() / tau,
        100.0 * (ratio / ratio_ref - 1.0),
        (rayleigh / dry_ref).sqrt()
    );
    assert!((ratio / ratio_ref - 1.0).abs() < 0.01, "frequency ratio {ratio} vs {ratio_ref}");
}
