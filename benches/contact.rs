//! Contact benchmark: cost per active pair per step (NTS on quads, Gauss–Seidel included) and the
//! whole-step overhead when about 10 % of the nodes are slave nodes in contact.
//!
//! Model: two stacked non-conforming hex8 boxes (lower n × n × 4, upper (n−1) × (n−1) × 4, so the
//! slave side is the upper box's bottom face), pressed together by a traction on the top. The
//! same model without the joint gives the contact-free step. Run: `cargo bench --bench contact`
//! (`JQ_BENCH_N` sets n, default 40 → about 10 % of the nodes are slave nodes).
use jointquake::contact::force::ContactSolver;
use jointquake::dynamics::{loads::Loads, Correction, ExplicitSolver, Stage, State};
use jointquake::mesh::structured::{add_box, BoxSpec};
use jointquake::mesh::Mesh;
use jointquake::model::Model;
use std::time::Instant;

fn build(n: usize, with_joint: bool) -> (Model, jointquake::scene::Scene) {
    let mut mesh = Mesh { source: "<bench>".into(), nodes: vec![], node_tags: vec![], cells: vec![], groups: vec![] };
    add_box(&mut mesh, &BoxSpec::new("lower", [1.0, 1.0, 0.2], [n, n, 4]).at([0.0, 0.0, -0.2]));
    add_box(&mut mesh, &BoxSpec::new("upper", [1.0, 1.0, 0.2], [n - 1, n - 1, 4]));
    let joints = if with_joint {
        serde_json::json!([{"name": "J", "master": "lower:z1", "slave": "upper:z0", "mu": 0.5}])
    } else {
        serde_json::json!([])
    };
    let sc: jointquake::scene::Scene = serde_json::from_value(serde_json::json!({
        "geometry": {"msh": "unused.msh"},
        "materials": [{"group": "block:lower", "E": 1e9, "nu": 0.25, "rho": 2000.0},
                      {"group": "block:upper", "E": 1e9, "nu": 0.25, "rho": 2000.0}],
        "boundary": [{"group": "lower:z0"}],
        "joints": joints,
        "loads": {"traction": [{"group": "upper:z1", "traction": [1e4, 0.0, -1e6]}]},
        "time": {"duration": 1.0}
    }))
    .unwrap();
    (Model::build(mesh, &sc).unwrap(), sc)
}

fn time_steps(model: &Model, sc: &jointquake::scene::Scene, dt: f64, warm: usize, steps: usize, contact: bool) -> (f64, usize, usize) {
    let (loads, _) = Loads::build(model, sc).unwrap();
    let mut solver = ExplicitSolver::new(model, dt, 1.0);
    let mut state = State::at_rest(model);
    let mut cs = ContactSolver::new(model, &model.joints);
    solver.start_energy(model, &mut state);
    let mut run = |n: usize, state: &mut State| {
        let mut sweeps = 0;
        for _ in 0..n {
            let info = if contact {
                solver.step(model, &loads, state, Stage::Dynamic, Some(&mut cs as &mut dyn Correction)).unwrap()
            } else {
                solver.step(model, &loads, state, Stage::Dynamic, None).unwrap()
            };
            sweeps += info.correction.iterations;
        }
        sweeps
    };
    run(warm, &mut state);
    let t = Instant::now();
    let sweeps = run(steps, &mut state);
    let secs = t.elapsed().as_secs_f64();
    let active = state.contact.joints.first().map(|j| j.pairs.iter().filter(|p| p.r_n > 0.0).count()).unwrap_or(0);
    (secs, active, sweeps)
}

fn main() {
    let n: usize = std::env::var("JQ_BENCH_N").ok().and_then(|v| v.parse().ok()).unwrap_or(40);
    let steps = 400;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    pool.install(|| {
        let (free, sc_free) = build(n, false);
        let (with, sc_with) = build(n, true);
        let dt = 0.9 * with.stable_dt().min(free.stable_dt());
        let slaves = with.joints[0].tag.n_slave();
        let (t_free, _, _) = time_steps(&free, &sc_free, dt, 200, steps, false);
        let (t_with, active, sweeps) = time_steps(&with, &sc_with, dt, 200, steps, true);
        let per_pair = (t_with - t_free) / (active.max(1) * steps) as f64;
        let ratio = t_with / t_free;
        let frac = slaves as f64 / with.n_nodes() as f64;
        println!("contact benchmark (1 thread): n = {n}, {} nodes, {} hex8, {} slave nodes ({:.1} % of the nodes), {} active pairs", with.n_nodes(), with.n_elements(), slaves, 100.0 * frac, active);
        println!("  contact-free step   {:9.1} µs", 1e6 * t_free / steps as f64);
        println!("  step with contact   {:9.1} µs  ({:.2} × the contact-free step; target ≤ 1.5 ×)", 1e6 * t_with / steps as f64, ratio);
        println!("  per active pair     {:9.3} µs per step, Gauss–Seidel sweeps {:.1} per step (target ≤ 1 µs)", 1e6 * per_pair, sweeps as f64 / steps as f64);
        let json = serde_json::json!({
            "n": n, "nodes": with.n_nodes(), "elements": with.n_elements(), "slave_nodes": slaves,
            "slave_fraction": frac, "active_pairs": active, "steps": steps,
            "step_contact_free_us": 1e6 * t_free / steps as f64, "step_with_contact_us": 1e6 * t_with / steps as f64,
            "overhead_ratio": ratio, "per_pair_us": 1e6 * per_pair, "sweeps_per_step": sweeps as f64 / steps as f64
        });
        let _ = std::fs::create_dir_all("target/bench");
        let _ = std::fs::write("target/bench/contact.json", serde_json::to_string_pretty(&json).unwrap());
    });
}
