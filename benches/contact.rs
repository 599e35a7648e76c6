//! Contact benchmark: cost per active pair per step (NTS on quads, Gauss–Seidel included) and the
//! whole-step overhead when about 10 % of the nodes are slave nodes in contact.
//!
//! Model: two stacked non-conforming hex8 boxes (lower n × n × 4, upper (n−1) × (n−1) × 4, so the
//! slave side is the upper box's bottom face), pressed together by a traction on the top. The
//! same model without the joint gives the contact-free step. One thread. Each repeat times
//! `steps` steps of both models in turn (after 200 warm-up steps each), so that both see the
//! same load from other users of the machine; best and median of the repeats are reported.
//! The state after the warm-up and all the repeats is hashed (displacements and every pair's
//! force, gap, slip), so that two builds can be compared for identical results. The contact
//! correction's own timers (`ContactSolver::timings`) split its time into search and set-up,
//! warm start and colouring, sweeps and record.
//! Run: `cargo bench --bench contact`. Knobs (environment):
//! - `JQ_BENCH_N`: n, default 40 → about 10 % of the nodes are slave nodes;
//! - `JQ_BENCH_REPEATS`: timed repeats, default 5 (at least 3);
//! - `JQ_BENCH_STEPS`: steps per repeat, default 400;
//! - `JQ_BENCH_GS_TOL`: Gauss–Seidel tolerance as a fraction of the joint size, default the
//!   solver's (1e-12).
//!
//! Tied case (issue 13 §3: what a large bonded interface costs), after the main case and
//! without touching it (its state hash stays the same): the same model with the joint `tied`
//! at `JQ_BENCH_TIED_N` (default 100: 99 × 99 upper cells, 10⁴ slave nodes, 8 × 10⁴ hex8),
//! `JQ_BENCH_TIED_STEPS` steps per repeat (default 50) and 3 repeats, against its contact-free
//! model; reported as the step ratio and the cost per pair per step, as for the main case.
//! `JQ_BENCH_TIED_N=0` skips it.
//!
//! Mortar case (issue 31), after the tied case: the main case's frictional joint at
//! `JQ_BENCH_MORTAR_N` (default 100: 10⁴ slave nodes), once with NTS and once with
//! `method: "mortar"` (integrals kept between steps and re-evaluated per slave face when it slides
//! or its candidates change, `contact::force::MORTAR_REEVALUATE`; the share re-evaluated per
//! step is printed), `JQ_BENCH_MORTAR_STEPS` steps per
//! repeat (default 50), 3 repeats, each against the contact-free model; reported as the cost per
//! pair per step of each method and their ratio (goal ≤ 3). `JQ_BENCH_MORTAR_N=0` skips it.
use jointquake::mesh::structured::{add_box, BoxSpec};
use jointquake::mesh::Mesh;
use jointquake::problem::Problem;
use jointquake::simulation::Simulation;
use std::time::Instant;

fn build(n: usize, with_joint: bool) -> Problem {
    build_with(n, with_joint, false)
}

/// The main case's model with its joint's contact method `method` (frictional, μ = 0.5).
fn build_method(n: usize, method: &str) -> Problem {
    build_joints(n, serde_json::json!([{"name": "J", "master": "lower:z1", "slave": "upper:z0", "mu": 0.5, "method": method}]))
}

fn build_with(n: usize, with_joint: bool, tied: bool) -> Problem {
    let joints = if with_joint && tied {
        serde_json::json!([{"name": "J", "master": "lower:z1", "slave": "upper:z0", "mu": 0.5, "tied": true}])
    } else if with_joint {
        serde_json::json!([{"name": "J", "master": "lower:z1", "slave": "upper:z0", "mu": 0.5}])
    } else {
        serde_json::json!([])
    };
    build_joints(n, joints)
}

fn build_joints(n: usize, joints: serde_json::Value) -> Problem {
    let mut mesh = Mesh { source: "<bench>".into(), nodes: vec![], node_tags: vec![], cells: vec![], groups: vec![] };
    add_box(&mut mesh, &BoxSpec::new("lower", [1.0, 1.0, 0.2], [n, n, 4]).at([0.0, 0.0, -0.2]));
    add_box(&mut mesh, &BoxSpec::new("upper", [1.0, 1.0, 0.2], [n - 1, n - 1, 4]));
    let sc: jointquake::scene::Scene = serde_json::from_value(serde_json::json!({
        "geometry": {"msh": "unused.msh"},
        "materials": [{"group": "block:lower", "E": 1e9, "nu": 0.25, "rho": 2000.0},
                      {"group": "block:upper", "E": 1e9, "nu": 0.25, "rho": 2000.0}],
        "boundary": [{"group": "lower:z0"}],
        "joints": joints,
        "loads": {"traction": [{"group": "upper:z1", "traction": [1e4, 0.0, -1e6]}]},
        "time": {"duration": 1.0, "energy_tolerance": 1.0}
    }))
    .unwrap();
    Problem::build(sc, mesh).unwrap()
}

/// A problem stepped repeatedly (the run object at the scene's default step, 0.9 of the stable
/// step), with the Gauss–Seidel sweeps counted.
struct Run<'p> {
    sim: Simulation<'p>,
    sweeps: usize,
}

impl<'p> Run<'p> {
    fn new(problem: &'p Problem) -> Run<'p> {
        let mut sim = Simulation::new(problem).unwrap();
        if let (Some(cs), Some(r)) = (sim.contact.as_mut(), std::env::var("JQ_BENCH_GS_TOL").ok().and_then(|v| v.parse::<f64>().ok())) {
            cs.gs_tolerance = r * problem.joints[0].tag.size;
        }
        Run { sim, sweeps: 0 }
    }

    /// Seconds for `n` steps.
    fn steps(&mut self, n: usize) -> f64 {
        let t = Instant::now();
        for _ in 0..n {
            let info = self.sim.step().unwrap();
            self.sweeps += info.correction.iterations;
        }
        t.elapsed().as_secs_f64()
    }

    fn active_pairs(&self) -> usize {
        self.sim.state.contact.joints.first().map(|j| j.pairs.iter().filter(|p| p.r_n > 0.0).count()).unwrap_or(0)
    }

    /// FNV-1a over the bits of u and of every pair's forces, gap, slip and face.
    fn state_hash(&self) -> u64 {
        let mut h = 0xcbf29ce484222325u64;
        let mut eat = |v: u64| h = (h ^ v).wrapping_mul(0x100000001b3);
        self.sim.state.u.iter().for_each(|v| eat(v.to_bits()));
        for j in &self.sim.state.contact.joints {
            for p in &j.pairs {
                [p.r_n, p.r_t[0], p.r_t[1], p.gap, p.slip, p.d_t[0], p.d_t[1], p.hist.slip].iter().for_each(|v| eat(v.to_bits()));
                eat(p.face as u64);
            }
        }
        h
    }
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    if n % 2 == 1 { s[n / 2] } else { 0.5 * (s[n / 2 - 1] + s[n / 2]) }
}

fn main() {
    let n: usize = std::env::var("JQ_BENCH_N").ok().and_then(|v| v.parse().ok()).unwrap_or(40);
    let repeats: usize = std::env::var("JQ_BENCH_REPEATS").ok().and_then(|v| v.parse().ok()).unwrap_or(5usize).max(3);
    let steps: usize = std::env::var("JQ_BENCH_STEPS").ok().and_then(|v| v.parse().ok()).unwrap_or(400);
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default().trim().to_string();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    pool.install(|| {
        let free = build(n, false);
        let with = build(n, true);
        let slaves = with.joints[0].tag.n_slave();
        let mut a = Run::new(&free);
        let mut b = Run::new(&with);
        // one mesh, one material: the same stable step with and without the joint
        assert_eq!(a.sim.dt(), b.sim.dt());
        a.steps(200);
        b.steps(200);
        b.sweeps = 0;
        // time the parts of the contact correction over the repeats
        b.sim.contact.as_mut().unwrap().timings = Some(Default::default());
        let (mut t_free, mut t_with, mut per_pair, mut ratio) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut active = Vec::new();
        for _ in 0..repeats {
            let tf = a.steps(steps);
            let tw = b.steps(steps);
            let act = b.active_pairs();
            t_free.push(1e6 * tf / steps as f64);
            t_with.push(1e6 * tw / steps as f64);
            per_pair.push(1e6 * (tw - tf) / (act.max(1) * steps) as f64);
            ratio.push(tw / tf);
            active.push(act);
        }
        let best = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
        let frac = slaves as f64 / with.model.n_nodes() as f64;
        let sweeps = b.sweeps as f64 / (repeats * steps) as f64;
        println!("contact benchmark (1 thread, load average {load}): n = {n}, {} nodes, {} hex8, {} slave nodes ({:.1} % of the nodes), {} active pairs", with.model.n_nodes(), with.model.n_elements(), slaves, 100.0 * frac, active[repeats - 1]);
        println!("  {repeats} repeats of {steps} steps; best / median");
        println!("  contact-free step   {:9.1} / {:9.1} µs", best(&t_free), median(&t_free));
        println!("  step with contact   {:9.1} / {:9.1} µs", best(&t_with), median(&t_with));
        println!("  ratio               {:9.2} / {:9.2}  (target ≤ 1.5)", best(&ratio), median(&ratio));
        println!("  per active pair     {:9.3} / {:9.3} µs per step (target ≤ 1 µs), Gauss–Seidel sweeps {sweeps:.1} per step", best(&per_pair), median(&per_pair));
        let parts = b.sim.contact.as_ref().unwrap().timings.clone().unwrap();
        let per_step = |d: std::time::Duration| 1e6 * d.as_secs_f64() / parts.steps.max(1) as f64;
        let (t_search, t_prepare, t_sweeps, t_record) = (per_step(parts.search), per_step(parts.prepare), per_step(parts.sweeps), per_step(parts.record));
        println!("  contact part, mean over the repeats: search and set-up {t_search:.1} µs, warm start and colouring {t_prepare:.1} µs, sweeps {t_sweeps:.1} µs, record {t_record:.1} µs per step");
        println!("  state hash after {} steps: {:016x}", 200 + repeats * steps, b.state_hash());
        let json = serde_json::json!({
            "load_before": load, "n": n, "nodes": with.model.n_nodes(), "elements": with.model.n_elements(), "slave_nodes": slaves,
            "slave_fraction": frac, "active_pairs": active, "steps_per_repeat": steps, "repeats": repeats,
            "step_contact_free_us": t_free, "step_with_contact_us": t_with, "overhead_ratio": ratio, "per_pair_us": per_pair,
            "best": {"step_contact_free_us": best(&t_free), "step_with_contact_us": best(&t_with), "overhead_ratio": best(&ratio), "per_pair_us": best(&per_pair)},
            "median": {"step_contact_free_us": median(&t_free), "step_with_contact_us": median(&t_with), "overhead_ratio": median(&ratio), "per_pair_us": median(&per_pair)},
            "sweeps_per_step": sweeps, "state_hash": format!("{:016x}", b.state_hash()),
            "contact_parts_us_per_step": {"search": t_search, "prepare": t_prepare, "sweeps": t_sweeps, "record": t_record},
        });
        let _ = std::fs::create_dir_all("target/bench");
        let _ = std::fs::write("target/bench/contact.json", serde_json::to_string_pretty(&json).unwrap());
        tied_case();
        mortar_case();
    });
}

/// The tied interface of 10⁴ pairs (module docs): contact-free and tied steps in turn.
fn tied_case() {
    let n: usize = std::env::var("JQ_BENCH_TIED_N").ok().and_then(|v| v.parse().ok()).unwrap_or(100);
    if n < 2 {
        return;
    }
    let steps: usize = std::env::var("JQ_BENCH_TIED_STEPS").ok().and_then(|v| v.parse().ok()).unwrap_or(50);
    let repeats = 3;
    let free = build_with(n, false, false);
    let tied = build_with(n, true, true);
    let pairs = tied.joints[0].tag.n_slave();
    let mut a = Run::new(&free);
    let mut b = Run::new(&tied);
    a.steps(steps);
    b.steps(steps);
    b.sweeps = 0;
    let (mut t_free, mut t_tied, mut per_pair, mut ratio) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for _ in 0..repeats {
        let tf = a.steps(steps);
        let tw = b.steps(steps);
        t_free.push(1e6 * tf / steps as f64);
        t_tied.push(1e6 * tw / steps as f64);
        per_pair.push(1e6 * (tw - tf) / (pairs * steps) as f64);
        ratio.push(tw / tf);
    }
    let best = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
    let sweeps = b.sweeps as f64 / (repeats * steps) as f64;
    println!("tied interface (1 thread): n = {n}, {} nodes, {} hex8, {pairs} tied pairs", tied.model.n_nodes(), tied.model.n_elements());
    println!("  {repeats} repeats of {steps} steps; best / median");
    println!("  contact-free step   {:9.1} / {:9.1} µs", best(&t_free), median(&t_free));
    println!("  step with the joint {:9.1} / {:9.1} µs", best(&t_tied), median(&t_tied));
    println!("  ratio               {:9.2} / {:9.2}", best(&ratio), median(&ratio));
    println!("  per tied pair       {:9.3} / {:9.3} µs per step, Gauss–Seidel sweeps {sweeps:.1} per step", best(&per_pair), median(&per_pair));
    let json = serde_json::json!({
        "n": n, "nodes": tied.model.n_nodes(), "elements": tied.model.n_elements(), "pairs": pairs, "steps_per_repeat": steps, "repeats": repeats,
        "step_contact_free_us": t_free, "step_tied_us": t_tied, "ratio": ratio, "per_pair_us": per_pair, "sweeps_per_step": sweeps,
    });
    let _ = std::fs::write("target/bench/contact_tied.json", serde_json::to_string_pretty(&json).unwrap());
}

/// Mortar against NTS on the same frictional interface (module docs): per pair per step.
fn mortar_case() {
    let n: usize = std::env::var("JQ_BENCH_MORTAR_N").ok().and_then(|v| v.parse().ok()).unwrap_or(100);
    if n < 2 {
        return;
    }
    let steps: usize = std::env::var("JQ_BENCH_MORTAR_STEPS").ok().and_then(|v| v.parse().ok()).unwrap_or(50);
    let repeats = 3;
    let free = build_with(n, false, false);
    let nts = build_method(n, "nts");
    let mortar = build_method(n, "mortar");
    let mut a = Run::new(&free);
    let mut b = Run::new(&nts);
    let mut c = Run::new(&mortar);
    a.steps(steps);
    b.steps(steps);
    c.steps(steps);
    b.sweeps = 0;
    c.sweeps = 0;
    c.sim.contact.as_mut().unwrap().timings = Some(Default::default());
    let evaluated_before = c.sim.contact.as_ref().unwrap().mortar_face_evaluations();
    let (mut per_nts, mut per_mortar, mut ratio) = (Vec::new(), Vec::new(), Vec::new());
    let (mut pairs_nts, mut pairs_mortar) = (0, 0);
    for _ in 0..repeats {
        let tf = a.steps(steps);
        let tn = b.steps(steps);
        let tm = c.steps(steps);
        pairs_nts = b.active_pairs();
        pairs_mortar = c.active_pairs();
        let pn = 1e6 * (tn - tf) / (pairs_nts.max(1) * steps) as f64;
        let pm = 1e6 * (tm - tf) / (pairs_mortar.max(1) * steps) as f64;
        per_nts.push(pn);
        per_mortar.push(pm);
        ratio.push(pm / pn);
    }
    let best = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
    let sweeps = |r: &Run| r.sweeps as f64 / (repeats * steps) as f64;
    let parts = c.sim.contact.as_ref().unwrap().timings.clone().unwrap();
    let per_step = |d: std::time::Duration| 1e6 * d.as_secs_f64() / parts.steps.max(1) as f64;
    println!("mortar against NTS (1 thread): n = {n}, {} nodes, {} hex8, {} slave nodes; pairs in contact NTS {pairs_nts}, mortar {pairs_mortar}", mortar.model.n_nodes(), mortar.model.n_elements(), mortar.joints[0].tag.n_slave());
    println!("  {repeats} repeats of {steps} steps; best / median");
    println!("  per pair, NTS       {:9.3} / {:9.3} µs per step, Gauss–Seidel sweeps {:.1} per step", best(&per_nts), median(&per_nts), sweeps(&b));
    println!("  per pair, mortar    {:9.3} / {:9.3} µs per step, Gauss–Seidel sweeps {:.1} per step", best(&per_mortar), median(&per_mortar), sweeps(&c));
    println!("  mortar / NTS        {:9.2} / {:9.2}  (goal ≤ 3)", best(&ratio), median(&ratio));
    let evaluated = c.sim.contact.as_ref().unwrap().mortar_face_evaluations() - evaluated_before;
    let faces = mortar.joints[0].tag.slave.faces.len();
    println!("  mortar integrals re-evaluated: {:.4} of the {faces} slave faces per step (warm-up: all at the first step)", evaluated as f64 / (faces * repeats * steps) as f64);
    println!("  mortar contact part: integrals, search and set-up {:.1} µs, warm start {:.1} µs, sweeps {:.1} µs, record {:.1} µs per step", per_step(parts.search), per_step(parts.prepare), per_step(parts.sweeps), per_step(parts.record));
    let json = serde_json::json!({
        "n": n, "nodes": mortar.model.n_nodes(), "elements": mortar.model.n_elements(), "steps_per_repeat": steps, "repeats": repeats,
        "pairs_nts": pairs_nts, "pairs_mortar": pairs_mortar, "per_pair_nts_us": per_nts, "per_pair_mortar_us": per_mortar, "ratio": ratio,
        "sweeps_nts": sweeps(&b), "sweeps_mortar": sweeps(&c), "faces_reevaluated_per_step": evaluated as f64 / (repeats * steps) as f64,
    });
    let _ = std::fs::write("target/bench/contact_mortar.json", serde_json::to_string_pretty(&json).unwrap());
}
