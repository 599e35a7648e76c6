//! Helpers shared by the integration tests.
#![allow(dead_code)]
use std::path::PathBuf;

/// Path of a committed fixture under tests/fixtures/.
pub fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(name)
}

/// A fresh scratch directory under target/ for one test.
pub fn scratch(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/test-scratch").join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

use jointquake::dynamics::State;
use jointquake::mesh::Mesh;
use jointquake::problem::Problem;
use jointquake::scene::Scene;
use jointquake::simulation::Simulation;

/// The scene of pipelines/dam_coarse.json (massless rock, tied base, 28 Mohr–Coulomb joints,
/// reservoir at crest − 5 m) with the committed coarse fixture's mesh, patterns expanded.
pub fn dam_coarse_scene() -> (Scene, Mesh) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("pipelines/dam_coarse.json");
    let mut s = Scene::load(&path).unwrap();
    // the scene reads the committed fixture (geometry.msh = tests/fixtures/arch_dam_coarse.msh)
    let mesh = jointquake::pipeline::load_scene_mesh(&mut s, &path, None).unwrap();
    (s, mesh)
}

/// A scene from inline JSON (fields as in pipelines/*.json).
pub fn scene(v: serde_json::Value) -> Scene {
    serde_json::from_value(v).expect("test scene parses")
}

/// Mean of component `c` of u over `nodes`.
pub fn mean_u(u: &[f64], nodes: &[usize], c: usize) -> f64 {
    nodes.iter().map(|&n| u[3 * n + c]).sum::<f64>() / nodes.len() as f64
}

/// The problem of `scene` on `mesh` with the time step `courant` × the stable step (the scene's
/// `time.dt` dropped).
pub fn problem(mesh: Mesh, scene: &Scene, courant: f64) -> Problem {
    let mut sc = scene.clone();
    sc.time.dt = None;
    sc.time.courant = Some(courant);
    Problem::build(sc, mesh).expect("problem builds")
}

/// Run the dynamic stage from rest for `steps` steps (the problem's time step), calling
/// `observe(t, u)` after every step with u = u[n+1] at t[n+1]. Returns (dt, final state).
pub fn simulate(problem: &Problem, steps: usize, mut observe: impl FnMut(f64, &[f64])) -> (f64, State) {
    simulate_contact(problem, steps, false, |t, st| observe(t, &st.u))
}

/// As [`simulate`], with the problem's joints in contact (dynamic contact force) and optional
/// gravity relaxation first (to a residual 1e-6, joints' own laws, no slip restart). Returns
/// (dt, final state).
pub fn simulate_contact(problem: &Problem, steps: usize, relax: bool, mut observe: impl FnMut(f64, &State)) -> (f64, State) {
    let mut sim = Simulation::new(problem).expect("simulation");
    if relax {
        let eq = sim.relax(1e-6, 200_000).expect("relaxation");
        assert!(eq.converged, "gravity relaxation: {eq:?}");
        sim.restart_clock();
    }
    for _ in 0..steps {
        sim.step().expect("step");
        observe(sim.state.t, &sim.state);
    }
    (sim.dt(), sim.state)
}

/// The error message of `jointquake::pipeline::run` on the scene file `scene` (which must
/// fail), its outputs and mesh cache under `dir`; `test` names the case in the panic.
pub fn run_error_at(test: &str, scene: &std::path::Path, dir: &std::path::Path) -> String {
    let opts = jointquake::pipeline::RunOptions { out_dir: Some(dir.join("out")), mesh_cache: Some(dir.join("mesh")), ..Default::default() };
    match jointquake::pipeline::run(scene, &opts) {
        Ok(_) => panic!("{test}: the run should fail"),
        Err(e) => e.to_string(),
    }
}

/// `msg` contains every one of `parts` (an error names its field, value and fix).
pub fn assert_mentions(msg: &str, parts: &[&str]) {
    for p in parts {
        assert!(msg.contains(p), "message does not mention {p:?}:\n{msg}");
    }
}

/// Build and run the generated joint test `v` (`jointquake testcase`, src/testcase), print its
/// errors, and for a patch assert that its static solve converged (residual below 1e-10).
pub fn testcase(v: serde_json::Value) -> jointquake::testcase::run::CaseResult {
    use jointquake::testcase::run::{run_case, Errors};
    let spec: jointquake::testcase::CaseSpec = serde_json::from_value(v.clone()).expect("case spec");
    let c = jointquake::testcase::build(&spec).expect("case builds");
    let r = run_case(&c).expect("case runs");
    println!("{v}: error {:.4e} ({}), {:?}, lost {}", r.error, r.error_of, r.errors, r.lost);
    if let Errors::Patch { converged, residual, .. } = &r.errors {
        assert!(*converged && *residual < 1e-10, "{v}: static solve not converged ({residual:.2e})");
    }
    r
}

/// A patch test's errors: σ next to the joint, the contact pressure inside, the shear.
pub fn patch_errors(r: &jointquake::testcase::run::CaseResult) -> (f64, f64, f64) {
    match &r.errors {
        jointquake::testcase::run::Errors::Patch { stress_joint, pressure_interior, shear, .. } => (*stress_joint, *pressure_interior, *shear),
        e => panic!("not a patch: {e:?}"),
    }
}

/// A record file `ramp.txt` in `dir`: the acceleration ramps linearly from 0 to `a_g` [g]
/// over `ramp` s, then holds, to `end` s (401 samples).
pub fn ramp_record(dir: &std::path::Path, a_g: f64, ramp: f64, end: f64) -> PathBuf {
    ramp_record_shaped(dir, a_g, ramp, end, false)
}

/// As [`ramp_record`], the rise a half cosine 0.5 (1 − cos(π t / `ramp`)) when `smooth`
/// (no kink at either end: little ringing of a stiff or acoustic system).
pub fn ramp_record_shaped(dir: &std::path::Path, a_g: f64, ramp: f64, end: f64, smooth: bool) -> PathBuf {
    let p = dir.join("ramp.txt");
    let mut s = String::from("# t [s], a [g]\n");
    let n = 400;
    for i in 0..=n {
        let t = end * i as f64 / n as f64;
        let r = if smooth && t < ramp { 0.5 * (1.0 - (std::f64::consts::PI * t / ramp).cos()) } else { (t / ramp).min(1.0) };
        s.push_str(&format!("{t} {}\n", a_g * r));
    }
    std::fs::write(&p, s).unwrap();
    p
}

/// The base-shear test's set-up (Westergaard's added mass, dam_physics.rs and reservoir.rs):
/// the stiff block `block:b` (2 × 3 × 10 m of `mesh`, E = 10⁵ GPa, fixed at `b:z0`) with the
/// reservoir section `reservoir`, shaken along x by a ramp to 0.2 g over 0.2 s (scratch
/// directory `test`), run to 0.3 s (0.9 × the stable step). Returns the base shear V [N] (the
/// reaction Σ (K u)_x over the fixed base nodes plus their inertia, which moves with the
/// ground), the model's total inertial mass [kg], the ground acceleration a [m/s²] and the
/// problem.
pub fn stiff_block_base_shear(test: &str, mesh: Mesh, reservoir: serde_json::Value, smooth: bool) -> (f64, f64, f64, Problem) {
    let dir = scratch(test);
    let rec = ramp_record_shaped(&dir, 0.2, 0.2, 0.5, smooth);
    let sc = scene(serde_json::json!({
        "geometry": {"msh": "none.msh"},
        "materials": [{"group": "block:b", "E": 1e14, "nu": 0.2, "rho": 2400.0}],
        "boundary": [{"group": "b:z0"}],
        "loads": {"base": [{"record": rec, "direction": [1.0, 0.0, 0.0]}]},
        "damping": {"alpha": 20.0},
        "reservoir": reservoir,
        "time": {"duration": 0.3}
    }));
    let pb = problem(mesh, &sc, 0.9);
    let model = &pb.model;
    let mut sim = Simulation::new(&pb).unwrap();
    let n_steps = sim.n_steps();
    for _ in 0..n_steps {
        sim.step().unwrap();
    }
    let mut ku = vec![0.0; 3 * model.n_nodes()];
    model.internal_forces_into(&sim.state.u, &mut ku);
    let a = 0.2 * 9.81;
    let base = model.mesh.group_nodes("b:z0").unwrap();
    // reaction on the structure at the base = −Σ (K u)_x there; plus the base nodes' inertia
    let mut v = 0.0;
    for &nd in &base {
        v += ku[3 * nd];
        v += model.mass.apply(nd, &nalgebra::Vector3::new(a, 0.0, 0.0))[0];
    }
    let m_total: f64 = model.mass.inertial.iter().sum();
    drop(sim);
    (v, m_total, a, pb)
}

/// A small valid scene on the 10-hex column fixture (it runs; the hardening and bad-input tests
/// break one thing in it).
pub fn column_scene() -> serde_json::Value {
    serde_json::json!({
        "geometry": {"msh": fixture("column_hex.msh")},
        "materials": [{"group": "block:column", "E": 30e9, "nu": 0.2, "rho": 2400}],
        "boundary": [{"group": "bc:base"}],
        "time": {"duration": 0.001},
        "output": {"frames": false}
    })
}

/// Write `scene` as `<scratch(dir)>/scene.json`; returns (scene path, scratch dir).
pub fn write_scene_in(dir: &str, scene: &serde_json::Value) -> (PathBuf, PathBuf) {
    let dir = scratch(dir);
    let p = dir.join("scene.json");
    std::fs::write(&p, serde_json::to_string_pretty(scene).unwrap()).unwrap();
    (p, dir)
}
