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

use jointquake::dynamics::{loads::Loads, ExplicitSolver, Stage, State};
use jointquake::model::Model;
use jointquake::scene::Scene;

/// A scene from inline JSON (fields as in pipelines/*.json).
pub fn scene(v: serde_json::Value) -> Scene {
    serde_json::from_value(v).expect("test scene parses")
}

/// Mean of component `c` of u over `nodes`.
pub fn mean_u(u: &[f64], nodes: &[usize], c: usize) -> f64 {
    nodes.iter().map(|&n| u[3 * n + c]).sum::<f64>() / nodes.len() as f64
}

/// Run the dynamic stage from rest for `steps` steps at `courant` × the stable step, calling
/// `observe(t, u)` after every step with u = u[n+1] at t[n+1].
pub fn simulate(model: &Model, scene: &Scene, courant: f64, steps: usize, mut observe: impl FnMut(f64, &[f64])) -> (f64, State) {
    let (loads, _) = Loads::build(model, scene).expect("loads");
    let dt = courant * model.stable_dt();
    let mut solver = ExplicitSolver::new(model, dt, scene.time.energy_tolerance);
    let mut state = State::at_rest(model);
    solver.start_energy(model, &mut state);
    for _ in 0..steps {
        solver.step(model, &loads, &mut state, Stage::Dynamic, None).expect("step");
        observe(state.t, &state.u);
    }
    (dt, state)
}

/// As [`simulate`], with the model's joints in contact (dynamic contact force) and optional
/// gravity relaxation first. Returns (dt, final state).
pub fn simulate_contact(model: &Model, scene: &Scene, courant: f64, steps: usize, relax: bool, mut observe: impl FnMut(f64, &State)) -> (f64, State) {
    use jointquake::contact::force::ContactSolver;
    use jointquake::dynamics::{relax_gravity, Correction};
    let (loads, _) = Loads::build(model, scene).expect("loads");
    let dt = courant * model.stable_dt();
    let mut solver = ExplicitSolver::new(model, dt, scene.time.energy_tolerance);
    let mut contact = ContactSolver::new(model, &model.joints);
    let mut state = State::at_rest(model);
    if relax {
        let eq = relax_gravity(model, &loads, &mut solver, &mut state, Some(&mut contact as &mut dyn Correction), 1e-6, 200_000).expect("relaxation");
        assert!(eq.converged, "gravity relaxation: {eq:?}");
        state.step = 0;
        state.t = 0.0;
    }
    solver.start_energy(model, &mut state);
    for _ in 0..steps {
        solver.step(model, &loads, &mut state, Stage::Dynamic, Some(&mut contact as &mut dyn Correction)).expect("step");
        observe(state.t, &state);
    }
    (dt, state)
}
