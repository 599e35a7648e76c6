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
