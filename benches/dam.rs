//! Arch dam benchmark (issue 15): time per explicit step with node-to-segment contact on the
//! 28 contraction joints (plus the tied dam–rock interface), per element and per contact pair,
//! the stable step, and the wall time one second of earthquake would take (target: under 20 s
//! on the default mesh, one core).
//!
//! Model: geo/arch_dam.geo, coarse (the committed fixture tests/fixtures/arch_dam_coarse.msh) and
//! default (meshed by gmsh into target/bench-mesh; skipped with a message if gmsh is missing).
//! Concrete E = 24 GPa, ν = 0.17, ρ = 2400 kg/m³; rock E = 24.5 GPa, ν = 0.25, ρ = 2000 kg/m³,
//! in one of the rock variants of `JQ_DAM_ROCK`: `massive` (the rock's nodes are stepped and its
//! elements enter the stable step), `massless` (the dam study's model: `"massless": true`, the
//! rock condensed statically, docs/dam_physics.md, by the method the rule picks; its layer
//! along the tied base keeps its mass), or `solve` / `schur` (massless with that method forced).
//! The massless variants also report the condensation's size and setup time. `radiating`
//! (issue 29): the massed rock with Lysmer dashpots and the free field of the study's three
//! DL 5073 records on `bc:far` (`foundation.model = "radiating"`, docs/dam_physics.md §4):
//! its step against the massless one, with its step size. Joints: NTS, μ = 0.8, c = 0 (seed section 5), one entry `joint:{J}:left` /
//! `joint:{J}:right`; the base `tied`. Loads: gravity plus a uniform 1 MPa downstream traction
//! on the upstream face (a stand-in for the reservoir that puts the joints in compression, so
//! that the pairs are active as during shaking). dt = 0.9 × the stable step. One thread unless
//! `JQ_BENCH_THREADS` says more.
//! 100 warm-up steps, then `repeats` × `steps` timed steps; best and median reported.
//! Joints use `edge_tolerance` 0.02: their curved edges are cut into chords at different nodes
//! on the two sides, so an edge node lies up to the chord sagitta (0.12 m on the coarse mesh)
//! outside the other side; with the default 1e-3 those nodes are lost every step (measured: 154
//! per step on the coarse mesh, none at 0.02).
//! Knobs: `JQ_DAM_SIZES` (comma list of coarse, default, fine; default "coarse,default"),
//! `JQ_DAM_ROCK` (comma list of massive, massless, solve, schur, radiating; default
//! "massive,massless,radiating"),
//! `JQ_BENCH_REPEATS` (default 3), `JQ_BENCH_STEPS` (default 100), `JQ_BENCH_GS_TOL` (Gauss–Seidel
//! tolerance as a fraction of joint J01's size; default the solver's, 1e-12 of the model size),
//! `JQ_DAM_PER_JOINT` (set: print lost nodes, searches and sweeps per joint), `JQ_DAM_METHOD`
//! (the contraction joints' method: "nts", the default, or "mortar", issue 31; the base stays
//! tied node to segment), `JQ_BENCH_THREADS`
//! (comma list of thread counts, default "1": the first builds the model and times the steps as
//! above; each further count times as many steps more, in its own rayon pool, with its speed-up
//! over the first, the bound Amdahl's law puts on it with the contact's set-up and record serial
//! (its search and sweeps run on all threads), and the contact's parts on that count; a
//! loaded machine shares its cores, so time the threads on an idle one). Every run also prints
//! the process's CPU time per step (all threads; /proc/self/task/*/schedstat), which a load on
//! the machine inflates far less than the wall time, and the parallel regions (rayon
//! fork-joins, `jointquake::par`) a step opens on each thread count; and per mesh the element
//! chunks and colours, and the speed-up the element loop's schedule allows on two threads
//! (`element_schedule_bounds`: colour by colour, and on the chunk graph), which no load changes.
//! Then the step with each reservoir model against Westergaard's (`reservoir_models`, knob
//! `JQ_DAM_RESERVOIR`, default "coarse"). Then the static state (`static_state`, knob
//! `JQ_DAM_STATIC`; `JQ_DAM_STATIC_METHOD`, the contraction joints' method there: "nts", the
//! scene's, or "ntn", whose Newton needs about twice NTS's iterations) and the static stages'
//! fill with AMD and nested dissection (`static_fill`, knob `JQ_DAM_FILL`), both off by default.
//! Run: `cargo bench --bench dam`; results also in target/bench/dam.json.

use jointquake::problem::foundation::CondensationMethod;
use jointquake::mesh::Mesh;
use jointquake::problem::Problem;
use jointquake::scene::Scene;
use jointquake::simulation::Simulation;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

/// A hex8's work in the element loop over a tet4's (`element_schedule_bounds`): 5, the ratio of
/// their one-thread rates on the structured boxes of docs/performance.md §1 (95 ns and 18 ns an
/// element).
const HEX_WEIGHT: f64 = 5.0;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The mesh of a size variant (parameters as in docs/dam.md).
fn mesh_of(size: &str) -> Result<Mesh, String> {
    let set: BTreeMap<String, f64> = match size {
        "coarse" => return Mesh::from_msh(root().join("tests/fixtures/arch_dam_coarse.msh")).map_err(|e| e.to_string()),
        "default" => BTreeMap::new(),
        "fine" => [("h", 5.0), ("ht", 1.25), ("hr", 12.5), ("hrf", 80.0)].into_iter().map(|(k, v)| (k.to_string(), v)).collect(),
        other => return Err(format!("unknown size \"{other}\" in JQ_DAM_SIZES (coarse, default, fine)")),
    };
    let msh = jointquake::gmsh::mesh_geo(&root().join("geo/arch_dam.geo"), &set, &root().join("target/bench-mesh")).map_err(|e| e.to_string())?;
    Mesh::from_msh(msh).map_err(|e| e.to_string())
}

fn scene(massless: bool, radiating: bool) -> Scene {
    let mut v: serde_json::Value = serde_json::json!({
        "geometry": {"msh": "unused.msh"},
        "materials": [{"group": "block:monolith:*", "E": 24e9, "nu": 0.17, "rho": 2400.0},
                      {"group": "block:rock", "E": 24.5e9, "nu": 0.25, "rho": 2000.0, "massless": massless}],
        "boundary": [{"group": "bc:far"}],
        "joints": [
            {"name": "J{J}", "master": "joint:{J}:left", "slave": "joint:{J}:right", "auto": true, "tolerance": 0.5, "method": "nts", "mu": 0.8, "cohesion": 0.0, "edge_tolerance": 0.02},
            {"name": "base", "master": "interface:rock:base", "slave": "interface:dam:base", "tolerance": 0.5, "method": "nts", "tied": true}
        ],
        "loads": {"gravity": {}, "traction": [{"group": "face:upstream", "traction": [0.0, 1e6, 0.0]}]},
        "time": {"duration": 1.0, "energy_tolerance": 1.0}
    });
    // the contraction joints' method (issue 31: the dam step with mortar joints)
    let method = std::env::var("JQ_DAM_METHOD").unwrap_or_else(|_| "nts".into());
    v["joints"][0]["method"] = serde_json::json!(method);
    if radiating {
        let rec = |c: &str| root().join(format!("pipelines/records/dam_dl5073_arch_I_s1_{c}.txt")).to_string_lossy().to_string();
        v["loads"]["base"] = serde_json::json!([
            {"record": rec("h1"), "direction": [1, 0, 0]},
            {"record": rec("h2"), "direction": [0, 1, 0]},
            {"record": rec("v"), "direction": [0, 0, 1]}
        ]);
        v["foundation"] = serde_json::json!({"model": "radiating"});
    }
    serde_json::from_value(v).expect("bench scene")
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    if n % 2 == 1 { s[n / 2] } else { 0.5 * (s[n / 2 - 1] + s[n / 2]) }
}

/// CPU time of this process [s], all its threads (the first field of each thread's
/// /proc/self/task/*/schedstat: ns on a CPU), so that a step can be timed apart from the
/// machine's load; NaN where /proc is missing.
fn cpu_s() -> f64 {
    let Ok(dir) = std::fs::read_dir("/proc/self/task") else { return f64::NAN };
    dir.flatten().filter_map(|t| std::fs::read_to_string(t.path().join("schedstat")).ok()).filter_map(|s| s.split_whitespace().next()?.parse::<f64>().ok()).sum::<f64>() * 1e-9
}

fn best(v: &[f64]) -> f64 {
    v.iter().copied().fold(f64::INFINITY, f64::min)
}

fn main() {
    let sizes = std::env::var("JQ_DAM_SIZES").unwrap_or_else(|_| "coarse,default".into());
    let repeats: usize = std::env::var("JQ_BENCH_REPEATS").ok().and_then(|v| v.parse().ok()).unwrap_or(3usize).max(1);
    let steps: usize = std::env::var("JQ_BENCH_STEPS").ok().and_then(|v| v.parse().ok()).unwrap_or(100usize).max(1);
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default().trim().to_string();
    let rocks = std::env::var("JQ_DAM_ROCK").unwrap_or_else(|_| "massive,massless,radiating".into());
    let threads: Vec<usize> = std::env::var("JQ_BENCH_THREADS").unwrap_or_else(|_| "1".into()).split(',').filter_map(|t| t.trim().parse().ok()).filter(|&t| t > 0).collect();
    let threads = if threads.is_empty() { vec![1] } else { threads };
    let pools: Vec<(usize, rayon::ThreadPool)> = threads.iter().map(|&t| (t, rayon::ThreadPoolBuilder::new().num_threads(t).build().unwrap())).collect();
    let pool = &pools[0].1;
    println!("arch dam benchmark (threads {threads:?}, load average {load}); rock variants {rocks}");
    let mut rows = Vec::new();
    pool.install(|| {
        for size in sizes.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let t0 = Instant::now();
            let mesh = match mesh_of(size) {
                Ok(m) => m,
                Err(e) => {
                    println!("  {size}: skipped ({e})");
                    continue;
                }
            };
            let t_mesh = t0.elapsed().as_secs_f64();
            for rock in rocks.split(',').map(str::trim).filter(|s| !s.is_empty()) {
                let method = match rock {
                    "massive" | "massless" | "radiating" => None,
                    "solve" => Some(CondensationMethod::Solve),
                    "schur" => Some(CondensationMethod::Schur),
                    other => panic!("JQ_DAM_ROCK: unknown rock variant \"{other}\" (massive, massless, solve, schur, radiating)"),
                };
                let mesh = mesh.clone();
                let mut sc = scene(rock != "massive", rock == "radiating");
                jointquake::pipeline::expand_patterns(&mut sc, &mesh, std::path::Path::new("benches/dam.rs")).expect("patterns expand on the dam mesh");
                let t1 = Instant::now();
                let problem = Problem::build(sc, mesh).expect("dam model");
                let t_build = t1.elapsed().as_secs_f64();
                let model = &problem.model;
                let t2 = Instant::now();
                let mut sim = Simulation::with_condensation(&problem, method).expect("dam simulation");
                let t_sim = t2.elapsed().as_secs_f64();
                let found = sim.foundation.as_ref().map(|f| f.info(t_sim));
                if let Some(far) = &problem.far_boundary {
                    println!("  {size}, rock {rock}: {} far nodes with dashpots and free-field forces, {} far faces ({:.3e} m²), free-field delay {:.3} s", far.nodes.len(), far.faces, far.area, far.free_field.delay);
                }
                let (dt_stable, dt) = (sim.time.dt_stable, sim.dt());
                if let Some(r) = std::env::var("JQ_BENCH_GS_TOL").ok().and_then(|v| v.parse::<f64>().ok()) {
                    sim.contact.as_mut().expect("joints").gs_tolerance = r * problem.joints[0].tag.size;
                }
                let slaves: usize = problem.joints.iter().map(|j| j.tag.n_slave()).sum();
                let joint_slaves: usize = problem.joints.iter().take(28).map(|j| j.tag.n_slave()).sum();
                let mut sweeps = 0usize;
                let step = |n: usize, sim: &mut Simulation, sweeps: &mut usize| {
                    let t = Instant::now();
                    // as `pipeline::run` steps: the pool's other workers kept awake
                    jointquake::par::with_awake_workers(|| {
                        for _ in 0..n {
                            let info = sim.step().expect("step");
                            *sweeps += info.correction.iterations;
                        }
                    });
                    t.elapsed().as_secs_f64()
                };
                step(100, &mut sim, &mut sweeps);
                sweeps = 0;
                let events0: Vec<(u64, u64, u64, u64)> = sim.state.contact.joints.iter().map(|j| (j.events.fresh_searches, j.events.recentred, j.events.lost, j.events.projection_failures)).collect();
                sim.contact.as_mut().expect("joints").timings = Some(Default::default());
                let mut per_step = Vec::new();
                let (cpu0, fj0) = (cpu_s(), jointquake::par::fork_joins());
                for _ in 0..repeats {
                    per_step.push(step(steps, &mut sim, &mut sweeps) / steps as f64);
                }
                let timed = (repeats * steps) as f64;
                let cpu_step = (cpu_s() - cpu0) / timed;
                let forks_step = (jointquake::par::fork_joins() - fj0) as f64 / timed;
                let parts = sim.contact.as_ref().expect("joints").timings.clone().unwrap();
                // the same steps on each further thread count (after the one-thread steps: the
                // state moves on, the contact's pairs and sweeps stay about the same)
                let mut threads_rows = Vec::new();
                for (nt, p) in pools.iter().skip(1) {
                    let (mut sw, c0, fj) = (0usize, cpu_s(), jointquake::par::fork_joins());
                    sim.contact.as_mut().expect("joints").timings = Some(Default::default());
                    let par_calls = |sim: &Simulation| sim.contact.as_ref().expect("joints").sweep_threads.as_ref().map_or(0, |c| c.parallel_calls());
                    let pc0 = par_calls(&sim);
                    let t: Vec<f64> = p.install(|| (0..repeats).map(|_| step(steps, &mut sim, &mut sw) / steps as f64).collect());
                    // the share of the timed steps whose sweeps ran on all threads (chosen by timing)
                    let par_share = (par_calls(&sim) - pc0) as f64 / timed;
                    let pt = sim.contact.as_ref().expect("joints").timings.clone().unwrap();
                    let forks = (jointquake::par::fork_joins() - fj) as f64 / timed;
                    threads_rows.push((*nt, t, (cpu_s() - c0) / timed, sw as f64 / timed, pt, forks, par_share));
                }
                let sweeps_per_step = sweeps as f64 / timed;
                let unconverged: u64 = sim.state.contact.joints.iter().map(|j| j.unconverged_steps).sum();
                let (mut fresh, mut recentred, mut lost, mut failures) = (0u64, 0u64, 0u64, 0u64);
                for (j, e0) in sim.state.contact.joints.iter().zip(&events0) {
                    fresh += j.events.fresh_searches - e0.0;
                    recentred += j.events.recentred - e0.1;
                    lost += j.events.lost - e0.2;
                    failures += j.events.projection_failures - e0.3;
                }
                let active: usize = sim.state.contact.joints.iter().map(|j| j.pairs.iter().filter(|p| p.r_n > 0.0).count()).sum();
                let contact = (parts.search + parts.prepare + parts.sweeps + parts.record).as_secs_f64() / parts.steps.max(1) as f64;
                let (b, m) = (best(&per_step), median(&per_step));
                let ne = model.n_elements();
                let hexes = model.hexes.nodes.len();
                let per_second = m / dt;
                // the condensation's own cost per step, apart from the step (whose time the contact
                // dominates): a solve for u_f, and S u_b when S is formed; best of 20 calls each
                let mut cond_ms = (f64::NAN, f64::NAN);
                if let (Some(i), Some(f)) = (&found, sim.foundation.as_mut()) {
                    let mut u = sim.state.u.clone();
                    let mut fi = vec![0.0; u.len()];
                    let best_of = |g: &mut dyn FnMut()| (0..20).map(|_| { let t = Instant::now(); g(); t.elapsed().as_secs_f64() }).fold(f64::INFINITY, f64::min);
                    cond_ms.0 = 1e3 * best_of(&mut || f.condense_into(&mut u));
                    if i.method == CondensationMethod::Schur {
                        cond_ms.1 = 1e3 * best_of(&mut || f.add_schur_force_into(&u, &mut fi));
                    }
                    println!("  {size}, rock {rock}: condensation {:?}, {} condensed on {} interface unknowns, factor {} entries, S {:.1} MB, setup {:.2} s; per step: solve {:.3} ms, S·u_b {:.3} ms", i.method, i.condensed_unknowns, i.interface_unknowns, i.factor_entries, i.schur_bytes as f64 / 1e6, i.setup_time, cond_ms.0, cond_ms.1);
                }
                let sched = |s: &jointquake::model::Schedule| (s.chunks.len(), s.colors.len());
                let (tsched, hsched) = (sched(&model.tets.schedule), sched(&model.hexes.schedule));
                println!(
                    "  {size}, rock {rock}: {} nodes, {ne} elements ({hexes} hex8 with {} shapes, {} tet4), {} slave nodes ({joint_slaves} on the 28 joints), {active} pairs in compression; element chunks / colours: tet4 {} / {}, hex8 {} / {}",
                    model.n_nodes(),
                    model.hexes.shapes.len(),
                    ne - hexes,
                    slaves,
                    tsched.0,
                    tsched.1,
                    hsched.0,
                    hsched.1
                );
                // the element loop's speed-up bound from its schedule (the Schur path skips the
                // massless rock's elements)
                let skip = found.as_ref().is_some_and(|i| i.method == CondensationMethod::Schur);
                let nt_max = threads.iter().copied().max().unwrap_or(1).max(2);
                let (bound_colours, bound_graph) = element_schedule_bounds(model, skip, HEX_WEIGHT, nt_max);
                println!("    element loop on {nt_max} threads, the speed-up its schedule allows (work per chunk: its elements assembled, a hex8 = {HEX_WEIGHT} tet4): colour by colour {bound_colours:.2}×, chunk graph {bound_graph:.2}×");
                println!("    mesh {t_mesh:.2} s, model build and tagging {t_build:.2} s; stable dt {dt_stable:.4e} s (critical element {} in {}), dt {dt:.4e} s", model.critical.tag, model.critical.group);
                println!("    step {:.3} / {:.3} ms (best / median of {repeats} × {steps}); {:.3} µs per element; contact {:.3} ms per step = {:.3} µs per slave node", 1e3 * b, 1e3 * m, 1e6 * m / ne as f64, 1e3 * contact, 1e6 * contact / slaves.max(1) as f64);
                let part = |d: std::time::Duration| d.as_secs_f64() / parts.steps.max(1) as f64 / m;
                let shares = [part(parts.search), part(parts.prepare), part(parts.sweeps), part(parts.record)];
                // the search and the sweeps run on all threads; the set-up and record on one
                let serial = shares[1] + shares[3];
                println!("    CPU time {:.3} ms per step ({} thread{}, all threads), {forks_step:.1} fork-joins per step; the contact {:.0} % of the step: search {:.0} %, prepare {:.0} %, sweeps {:.0} %, record {:.0} % (serial: prepare and record)", 1e3 * cpu_step, pools[0].0, if pools[0].0 == 1 { "" } else { "s" }, 1e2 * contact / m, 1e2 * shares[0], 1e2 * shares[1], 1e2 * shares[2], 1e2 * shares[3]);
                let mut threads_json = Vec::new();
                for (nt, t, cpu, sw, pt, forks, par_share) in &threads_rows {
                    let amdahl = 1.0 / (serial + (1.0 - serial) * pools[0].0 as f64 / *nt as f64);
                    let ms = |d: std::time::Duration| 1e3 * d.as_secs_f64() / pt.steps.max(1) as f64;
                    let parts_ms = [ms(pt.search), ms(pt.prepare), ms(pt.sweeps), ms(pt.record)];
                    println!("    {nt} threads: step {:.3} / {:.3} ms, {:.2}× the {}-thread median (Amdahl bound with the contact's set-up and record serial: {amdahl:.2}×); CPU time {:.3} ms per step; {forks:.1} fork-joins per step; {sw:.1} sweeps per step, on all threads in {:.0} % of the steps (chosen by timing); contact {:.3} ms (search {:.3}, prepare {:.3}, sweeps {:.3}, record {:.3})", 1e3 * best(t), 1e3 * median(t), m / median(t), pools[0].0, 1e3 * cpu, 1e2 * par_share, parts_ms.iter().sum::<f64>(), parts_ms[0], parts_ms[1], parts_ms[2], parts_ms[3]);
                    threads_json.push(serde_json::json!({"threads": nt, "step_s": t, "best_step_s": best(t), "median_step_s": median(t), "speedup_median": m / median(t), "amdahl_bound": amdahl, "cpu_s_per_step": cpu, "fork_joins_per_step": forks, "gs_sweeps_per_step": sw, "sweeps_parallel_share": par_share, "contact_ms_search_prepare_sweeps_record": parts_ms}));
                }
                println!(
                    "    Gauss–Seidel {sweeps_per_step:.1} sweeps per step ({unconverged} unconverged steps since the start); per timed step: {:.2} fresh searches, {:.2} recentred, {:.2} lost, {:.2} projection failures",
                    fresh as f64 / timed,
                    recentred as f64 / timed,
                    lost as f64 / timed,
                    failures as f64 / timed
                );
                if std::env::var("JQ_DAM_PER_JOINT").is_ok() {
                    for (j, (cj, e0)) in sim.state.contact.joints.iter().zip(problem.joints.iter().zip(&events0)) {
                        println!("      {:5} lost {:8} fresh {:8} unconverged {:6} max sweeps {:5}", cj.tag.name, j.events.lost - e0.2, j.events.fresh_searches - e0.0, j.unconverged_steps, j.max_sweeps);
                    }
                }
                println!("    one second of earthquake: {:.0} steps, {per_second:.1} s of wall time (target < 20 s on the default mesh)", 1.0 / dt);
                rows.push(serde_json::json!({
                    "size": size, "rock": rock, "condensation": found, "condensation_solve_ms": cond_ms.0, "condensation_schur_product_ms": cond_ms.1, "nodes": model.n_nodes(), "elements": ne, "hex8": hexes, "tet4": ne - hexes,
                    "slave_nodes": slaves, "joint_slave_nodes": joint_slaves, "pairs_in_compression": active,
                    "dt_stable": dt_stable, "dt": dt, "critical_element": model.critical.tag, "critical_group": model.critical.group,
                    "step_s": per_step, "best_step_s": b, "median_step_s": m, "us_per_element": 1e6 * m / ne as f64,
                    "contact_s_per_step": contact, "contact_us_per_slave_node": 1e6 * contact / slaves.max(1) as f64,
                    "wall_s_per_earthquake_second": per_second, "gs_sweeps_per_step": sweeps_per_step, "unconverged_steps": unconverged,
                    "fresh_searches_per_step": fresh as f64 / timed, "recentred_per_step": recentred as f64 / timed, "lost_per_step": lost as f64 / timed, "mesh_s": t_mesh, "build_s": t_build,
                    "threads": pools[0].0, "cpu_s_per_step": cpu_step, "fork_joins_per_step": forks_step, "element_schedule_bound_colours": bound_colours, "element_schedule_bound_graph": bound_graph, "hex8_shapes": model.hexes.shapes.len(), "chunks_colours_tet4_hex8": [tsched, hsched], "contact_share": contact / m, "serial_share": serial, "contact_shares_search_prepare_sweeps_record": shares, "other_threads": threads_json,
                }));
            }
        }
    });
    let reservoir = pool.install(|| reservoir_models(repeats, steps));
    let static_rows = static_state();
    let fill_rows = static_fill();
    let factor_rows = static_factor();
    let _ = std::fs::create_dir_all(root().join("target/bench"));
    let _ = std::fs::write(root().join("target/bench/dam.json"), serde_json::to_string_pretty(&serde_json::json!({"load_before": load, "runs": rows, "reservoir": reservoir, "static_state": static_rows, "static_fill": fill_rows, "static_factor": factor_rows})).unwrap());
}

/// The bench scene of the static state on mesh `size` (coarse, default, fine, h2.5): written
/// into target/bench-static/dam_<size>.json; returns its path and JSON.
fn static_scene(size: &str) -> (std::path::PathBuf, serde_json::Value) {
    let set: serde_json::Value = match size {
        "coarse" => serde_json::json!({"h": 20, "ht": 3.4, "hr": 40, "hrf": 200}),
        "default" => serde_json::json!({}),
        "fine" => serde_json::json!({"h": 5, "ht": 1.25, "hr": 12.5, "hrf": 80}),
        "h2.5" => serde_json::json!({"h": 2.5, "ht": 0.625, "hr": 6.25, "hrf": 40}),
        other => panic!("JQ_DAM_STATIC / JQ_DAM_FILL: unknown mesh \"{other}\" (coarse, default, fine, h2.5)"),
    };
    let text = std::fs::read_to_string(root().join("pipelines/dam.json")).expect("pipelines/dam.json");
    let mut scene: serde_json::Value = serde_json::from_str(&text).expect("pipelines/dam.json is JSON");
    scene["geometry"] = serde_json::json!({"geo": root().join("geo/arch_dam.geo"), "set": set});
    // the contraction joints' method (the first joint entry, J{J}); the base stays tied
    if let Ok(method) = std::env::var("JQ_DAM_STATIC_METHOD") {
        scene["joints"][0]["method"] = serde_json::json!(method);
    }
    for rec in scene["loads"]["base"].as_array_mut().into_iter().flatten() {
        let r = root().join("pipelines").join(rec["record"].as_str().unwrap_or_default());
        rec["record"] = serde_json::json!(r);
    }
    let dir = root().join("target/bench-static");
    let _ = std::fs::create_dir_all(&dir);
    let path = dir.join(format!("dam_{size}.json"));
    std::fs::write(&path, serde_json::to_string_pretty(&scene).unwrap()).expect("writing the bench scene");
    (path, scene)
}

/// The fill of the static stages' Cholesky factors with AMD and with METIS nested dissection,
/// symbolic analyses only (no numeric factorisation, so a mesh whose factor would not fit can
/// be measured), per mesh of `JQ_DAM_FILL` (comma list as `JQ_DAM_STATIC`; unset skips it):
/// stage a's K̂ and stage c's preconditioner P (`statics::contact::static_matrices`), each
/// with its unknowns, factor entries (MB at 8 B each, and at 4 B: the f32 factor stage c uses
/// from `statics::contact::SINGLE_FROM` unknowns), flops of one factorisation and the
/// analysis's seconds, and the process's peak RSS after the mesh.
fn static_fill() -> Vec<serde_json::Value> {
    use jointquake::linalg::{analyse, FillOrdering};
    let mut rows = Vec::new();
    for (size, _, _, problem) in static_problems("JQ_DAM_FILL") {
        let (k0, p) = match problem.and_then(|pb| jointquake::statics::contact::static_matrices(&pb).map_err(|e| e.to_string())) {
            Ok(m) => m,
            Err(e) => {
                println!("fill, {size}: skipped ({e})");
                continue;
            }
        };
        for (stage, m) in [("a: K̂", &k0), ("c: P", &p)] {
            for ordering in [FillOrdering::Amd, FillOrdering::NestedDissection] {
                match analyse(m, stage, ordering) {
                    Ok(a) => {
                        let (_, peak_mb) = cpu_and_peak();
                        println!("fill, {size}, stage {stage}: {ordering:?}: {} unknowns, {} entries, factor {:.0} MB (in f32 {:.0} MB), {:.3e} flops, analysis {:.1} s (peak RSS so far {peak_mb:.0} MB)", a.n, m.nnz(), a.factor_entries as f64 * 8e-6, a.factor_entries as f64 * 4e-6, a.factor_flops, a.seconds);
                        rows.push(serde_json::json!({"mesh": size, "stage": stage, "ordering": format!("{ordering:?}"), "n": a.n, "entries": m.nnz(), "factor_mb": a.factor_entries as f64 * 8e-6, "factor_mb_f32": a.factor_entries as f64 * 4e-6, "factor_flops": a.factor_flops, "analysis_s": a.seconds}));
                    }
                    Err(e) => println!("fill, {size}, stage {stage}: {ordering:?}: {e}"),
                }
            }
        }
    }
    rows
}

/// The numeric factorisation and the solves of stage c's preconditioner P on one thread and on
/// all of rayon's (issue 30 §1), per mesh of `JQ_DAM_FACTOR` (comma list as `JQ_DAM_STATIC`;
/// unset skips it): P's pattern with K̂'s values (`statics::contact::static_matrices`: the pair
/// blocks are zeros, so P = K̂, positive definite, with the fill and flops of the Newton
/// preconditioner), nested dissection. Per `Par` (one thread, then all of rayon's global pool:
/// `RAYON_NUM_THREADS`): the numeric factorisation (best of `JQ_FACTOR_REPEATS`, default 2,
/// wall and process CPU), its flop rate, and one solve (best of 10); the solution's largest
/// difference from the one-thread factor's, relative to its largest entry.
fn static_factor() -> Vec<serde_json::Value> {
    use jointquake::linalg::{FillOrdering, SparseCholesky};
    let repeats: usize = std::env::var("JQ_FACTOR_REPEATS").ok().and_then(|v| v.parse().ok()).unwrap_or(2usize).max(1);
    let mut rows = Vec::new();
    for (size, _, _, problem) in static_problems("JQ_DAM_FACTOR") {
        let p = match problem.and_then(|pb| jointquake::statics::contact::static_matrices(&pb).map_err(|e| e.to_string())) {
            Ok((_, p)) => p,
            Err(e) => {
                println!("factor, {size}: skipped ({e})");
                continue;
            }
        };
        let b: Vec<f64> = (0..p.n_rows).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut reference: Option<Vec<f64>> = None;
        for par in [faer::Par::Seq, faer::Par::rayon(0)] {
            let threads = par.degree();
            let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default().trim().to_string();
            let mut ch = match SparseCholesky::factor_ordered(&p, "P", par, FillOrdering::NestedDissection) {
                Ok(ch) => ch,
                Err(e) => {
                    println!("factor, {size}: {e}");
                    break;
                }
            };
            let (mut wall, mut cpu) = (f64::INFINITY, f64::INFINITY);
            for _ in 0..repeats {
                let (c0, t0) = (cpu_and_peak().0, Instant::now());
                ch.refactor(&p, "P").expect("P refactorised");
                wall = wall.min(t0.elapsed().as_secs_f64());
                cpu = cpu.min(cpu_and_peak().0 - c0);
            }
            let mut x = b.clone();
            let (mut sw, mut sc) = (f64::INFINITY, f64::INFINITY);
            for _ in 0..10 {
                x.copy_from_slice(&b);
                let (c0, t0) = (cpu_and_peak().0, Instant::now());
                ch.solve_in_place(&mut x);
                sw = sw.min(t0.elapsed().as_secs_f64());
                sc = sc.min(cpu_and_peak().0 - c0);
            }
            let diff = reference.as_ref().map_or(0.0, |r| {
                let scale = r.iter().fold(0.0f64, |a, v| a.max(v.abs()));
                r.iter().zip(&x).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / scale
            });
            if reference.is_none() {
                reference = Some(x.clone());
            }
            // the solve split over the elimination tree (`SparseCholesky::split_solves`), on as
            // many threads as the factorisation
            let weights = ch.split_solves().unwrap_or_default();
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("a thread pool");
            let (mut tw, mut tc) = (f64::INFINITY, f64::INFINITY);
            for _ in 0..10 {
                x.copy_from_slice(&b);
                let (c0, t0) = (cpu_and_peak().0, Instant::now());
                pool.install(|| ch.solve_in_place(&mut x));
                tw = tw.min(t0.elapsed().as_secs_f64());
                tc = tc.min(cpu_and_peak().0 - c0);
            }
            let split_diff = reference.as_ref().map_or(0.0, |r| {
                let scale = r.iter().fold(0.0f64, |a, v| a.max(v.abs()));
                r.iter().zip(&x).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / scale
            });
            println!("factor, {size}, {threads} thread(s): solve split over the tree (halves {} / {} MB, top {} MB) {tw:.3} s wall / {tc:.3} s CPU; vs the one-thread factor's faer solve {split_diff:.1e}", weights[0] / 125_000, weights[1] / 125_000, weights[2] / 125_000);
            let flops = ch.factor_flops();
            println!(
                "factor, {size}, {threads} thread(s) (load {load}): {} unknowns, factor {:.0} MB, {flops:.3e} flops; numeric factorisation {wall:.2} s wall, {cpu:.2} s CPU ({:.2e} flops/s wall, {:.2e} per CPU s); solve (one thread, `linalg::cholesky::SOLVE_PAR`) {:.3} s wall / {:.3} s CPU; solution vs 1 thread {diff:.1e}",
                p.n_rows, ch.factor_entries() as f64 * 8e-6, flops / wall, flops / cpu, sw, sc
            );
            rows.push(serde_json::json!({"mesh": size, "threads": threads, "load_before": load, "n": p.n_rows, "factor_mb": ch.factor_entries() as f64 * 8e-6, "factor_flops": flops, "factor_wall_s": wall, "factor_cpu_s": cpu, "solve_wall_s": sw, "solve_cpu_s": sc, "split_solve_wall_s": tw, "split_solve_cpu_s": tc, "split_entries": weights, "split_vs_one_thread": split_diff, "solution_vs_one_thread": diff}));
        }
    }
    rows
}

/// The step with each reservoir model against the Westergaard step (issue 28; goals:
/// `fe_incompressible` ≤ 1.5×, `acoustic` ≤ 2×). The dam with its meshed water: coarse (the
/// committed tests/fixtures/arch_dam_coarse_water.msh) and/or default (`arch_dam.geo -setnumber
/// water 1`, meshed into target/bench-mesh), `JQ_DAM_RESERVOIR` (comma list, default "coarse";
/// "none" skips). The bench scene with the massless rock, and instead of the traction the
/// reservoir at 205 m (hydrostatic on) with `westergaard`, `fe_incompressible` (its lumping in
/// the step) and `acoustic` (c = 1440 m/s, Sommerfeld far end, rigid bed). Per model: the
/// build (the condensation of `fe_incompressible` is paid there), the step (best / median of
/// `repeats` × `steps` after 20 warm-up steps), and for `acoustic` the water's own share (its
/// hook alone, best of 20 calls) and its stable step beside the solid's, and what a dense solve
/// on the wet dofs would cost per step (the full incompressible operator in the explicit step;
/// `JQ_DAM_DENSE=0` skips it: its factor takes minutes on the default mesh).
fn reservoir_models(repeats: usize, steps: usize) -> Vec<serde_json::Value> {
    let sizes = std::env::var("JQ_DAM_RESERVOIR").unwrap_or_else(|_| "coarse".into());
    let mut rows = Vec::new();
    for size in sizes.split(',').map(str::trim).filter(|s| !s.is_empty() && *s != "none") {
        let mesh = match size {
            "coarse" => Mesh::from_msh(root().join("tests/fixtures/arch_dam_coarse_water.msh")).map_err(|e| e.to_string()),
            "default" => {
                let set: BTreeMap<String, f64> = [("water".to_string(), 1.0)].into_iter().collect();
                jointquake::gmsh::mesh_geo(&root().join("geo/arch_dam.geo"), &set, &root().join("target/bench-mesh")).map_err(|e| e.to_string()).and_then(|m| Mesh::from_msh(m).map_err(|e| e.to_string()))
            }
            other => Err(format!("unknown size \"{other}\" in JQ_DAM_RESERVOIR (coarse, default, none)")),
        };
        let mesh = match mesh {
            Ok(m) => m,
            Err(e) => {
                println!("  reservoir models, {size}: skipped ({e})");
                continue;
            }
        };
        let mut base_step = f64::NAN;
        for model in ["westergaard", "fe_incompressible", "acoustic"] {
            let mut v = serde_json::to_value(scene(true, false)).expect("bench scene");
            v["loads"] = serde_json::json!({"gravity": {}});
            v["reservoir"] = serde_json::json!({"faces": ["face:upstream"], "level": 205.0, "model": model});
            if model != "westergaard" {
                v["reservoir"]["fluid"] = serde_json::json!({"volume": "block:water", "wet": ["water:dam"], "free_surface": ["water:surface"], "far_end": ["water:far"]});
            }
            let mut sc: Scene = serde_json::from_value(v).expect("reservoir bench scene");
            jointquake::pipeline::expand_patterns(&mut sc, &mesh, std::path::Path::new("benches/dam.rs")).expect("patterns expand on the dam mesh");
            let t1 = Instant::now();
            let problem = Problem::build(sc, mesh.clone()).expect("dam model with its reservoir");
            let mut sim = Simulation::new(&problem).expect("dam simulation");
            let t_build = t1.elapsed().as_secs_f64();
            for _ in 0..20 {
                sim.step().expect("step");
            }
            let mut per_step = Vec::new();
            let mut sweeps = 0usize;
            for _ in 0..repeats {
                let t = Instant::now();
                for _ in 0..steps {
                    sweeps += sim.step().expect("step").correction.iterations;
                }
                per_step.push(t.elapsed().as_secs_f64() / steps as f64);
            }
            let sweeps = sweeps as f64 / (repeats * steps) as f64;
            let (b, m) = (best(&per_step), median(&per_step));
            if model == "westergaard" {
                base_step = m;
            }
            let dt = sim.dt();
            let mut water_ms = f64::NAN;
            let mut water_note = String::new();
            let mut dense_ms = (0usize, f64::NAN, f64::NAN);
            if let Some(w) = sim.water.as_mut() {
                let a = vec![[0.1, 0.2, 0.0]; w.water.coupling.dam_nodes.len()];
                water_ms = 1e3 * (0..20).map(|_| { let t = Instant::now(); w.advance_with_acceleration(&a, dt); t.elapsed().as_secs_f64() }).fold(f64::INFINITY, f64::min);
                water_note = w.water.note(dt);
                if std::env::var("JQ_DAM_DENSE").map_or(true, |v| v != "0") {
                    dense_ms = dense_wet_solve_ms(3 * w.water.coupling.dam_nodes.len());
                }
            }
            println!(
                "  reservoir {model} ({size} mesh with water): build {t_build:.2} s; step {:.3} / {:.3} ms (best / median), {:.2}× the westergaard step, {sweeps:.1} Gauss–Seidel sweeps per step{}",
                1e3 * b,
                1e3 * m,
                m / base_step,
                if water_ms.is_nan() { String::new() } else { format!("; the water's hook alone {water_ms:.3} ms per step ({water_note})") }
            );
            if dense_ms.0 > 0 {
                println!("    the full incompressible operator in the step would need a dense solve on the {} wet dofs: factor {:.2} s once, {:.3} ms per step (two triangular solves, best of 5)", dense_ms.0, dense_ms.1, dense_ms.2);
            }
            rows.push(serde_json::json!({"size": size, "model": model, "build_s": t_build, "best_step_s": b, "median_step_s": m, "ratio_to_westergaard": m / base_step, "gs_sweeps_per_step": sweeps, "dt": dt, "water_hook_ms": water_ms, "water": water_note, "dense_wet_dofs": dense_ms.0, "dense_factor_s": dense_ms.1, "dense_solve_ms": dense_ms.2}));
        }
    }
    rows
}

/// The cost of the full incompressible operator in the explicit step (docs/dam_physics.md, "What
/// is left"): a dense SPD matrix of the wet dofs' size n (diagonal 2, off-diagonal 1/n: the
/// structure of M + M_a, whose values do not change the cost), its Cholesky factor (s) and one
/// solve with it (ms, best of 5).
fn dense_wet_solve_ms(n: usize) -> (usize, f64, f64) {
    let a = nalgebra::DMatrix::<f64>::from_fn(n, n, |i, j| if i == j { 2.0 } else { 1.0 / n as f64 });
    let t = Instant::now();
    let Some(ch) = a.cholesky() else { return (n, f64::NAN, f64::NAN) };
    let factor = t.elapsed().as_secs_f64();
    let b = nalgebra::DVector::<f64>::from_element(n, 1.0);
    let solve = (0..5).map(|_| { let t = Instant::now(); let x = ch.solve(&b); std::hint::black_box(x); t.elapsed().as_secs_f64() }).fold(f64::INFINITY, f64::min);
    (n, factor, 1e3 * solve)
}

/// CPU seconds (user + system) of this process and its peak resident set [MB] (getrusage).
fn cpu_and_peak() -> (f64, f64) {
    // SAFETY: getrusage writes the struct it is given; a zeroed rusage is a valid value
    let mut r: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut r) };
    let s = |t: libc::timeval| t.tv_sec as f64 + 1e-6 * t.tv_usec as f64;
    (s(r.ru_utime) + s(r.ru_stime), r.ru_maxrss as f64 / 1024.0)
}

/// The dam's construction-sequence static state (issue 30 §1; `jointquake dam-static`, stages a
/// to c) per mesh of `JQ_DAM_STATIC` (comma list of coarse, default, fine, h2.5; unset or empty
/// skips it): the scene pipelines/dam.json with the mesh's `geometry.set` (coarse: h 20, ht 3.4,
/// hr 40, hrf 200; fine: h 5, ht 1.25, hr 12.5, hrf 80; h2.5: h 2.5, ht 0.625, hr 6.25, hrf 40),
/// meshed into target/bench-mesh, solved by `pipeline::run_inspect` with duration 0 (outputs in
/// target/bench-static). Prints per mesh the wall and CPU time of the run (meshing excluded:
/// the mesh is made, and a model built and dropped, first: `static_problems`), the stages' notes (stage a: unknowns, assembly and Cholesky time,
/// factor size; stage c: Newton iterations, factorisations, GMRES products, their times), and
/// the process's peak RSS so far (sizes in the order given, so list them smallest first: the
/// peak is then the last mesh's). Goals: fine ≤ 120 s and ≤ 3 GB, h2.5 ≤ 15 min and ≤ 16 GB.
/// `JQ_DAM_STATIC_METHOD=ntn` solves it with node-to-node contraction joints.
fn static_state() -> Vec<serde_json::Value> {
    let mut rows = Vec::new();
    let mut t_mesh = Instant::now();
    for (size, path, scene, problem) in static_problems("JQ_DAM_STATIC") {
        // the mesh is made (and the model built, then dropped) before the timed run
        if let Err(e) = problem {
            println!("static state, {size}: skipped ({e})");
            t_mesh = Instant::now();
            continue;
        }
        drop(problem);
        let mesh_s = t_mesh.elapsed().as_secs_f64();
        let cache = root().join("target/bench-mesh");
        let opts = jointquake::pipeline::RunOptions { out_dir: Some(root().join("target/bench-static").join(&size)), mesh_cache: Some(cache), progress: false, duration: Some(0.0), threads: None };
        let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default().trim().to_string();
        let (cpu0, _) = cpu_and_peak();
        let t0 = Instant::now();
        let summary = jointquake::pipeline::run_inspect(&path, &opts, &mut |_, _| Ok(()));
        let wall = t0.elapsed().as_secs_f64();
        let (cpu1, peak_mb) = cpu_and_peak();
        match summary {
            Ok(s) => {
                let stages: Vec<&String> = s.notes.iter().filter(|n| n.starts_with("static sequence")).collect();
                let method = scene["joints"][0]["method"].as_str().unwrap_or("nts");
                println!("static state, {size}, {method} joints (load average {load}): {wall:.1} s wall, {:.1} s CPU, peak RSS {peak_mb:.0} MB (mesh and model {mesh_s:.1} s before)", cpu1 - cpu0);
                for n in &stages {
                    println!("    {n}");
                }
                rows.push(serde_json::json!({"mesh": size, "method": method, "set": scene["geometry"]["set"], "load_before": load, "wall_s": wall, "cpu_s": cpu1 - cpu0, "peak_rss_mb": peak_mb, "mesh_s": mesh_s, "stages": stages}));
            }
            Err(e) => println!("static state, {size}: failed after {wall:.1} s ({e})"),
        }
        t_mesh = Instant::now();
    }
    rows
}

/// The element loop's speed-up on `threads` threads that its schedule allows, from the work of
/// each chunk alone (no memory or hand-off costs): the work of a chunk is its elements that the
/// step assembles (the massless rock's are skipped with `skip_massless`), a hex8 weighing
/// `w_hex` tet4. Returns (colour by colour, each colour's chunks shared out in order to the
/// first free thread and all threads waiting for the colour's last chunk: the loop before
/// `model::ChunkGraph`; the chunk graph, a free thread taking the lowest-numbered ready chunk).
fn element_schedule_bounds(model: &jointquake::model::Model, skip_massless: bool, w_hex: f64, threads: usize) -> (f64, f64) {
    let mut work = Vec::new();
    let mut colours = Vec::new();
    for (s, cells, w) in [(&model.tets.schedule, &model.tets.cell, 1.0), (&model.hexes.schedule, &model.hexes.cell, w_hex)] {
        let first = work.len();
        work.extend(s.chunks.iter().map(|r| w * r.clone().filter(|&e| !(skip_massless && model.massless_cells[cells[e] as usize])).count() as f64));
        colours.extend(s.colors.iter().map(|c| first + c.start..first + c.end));
    }
    let total: f64 = work.iter().sum();
    let barrier: f64 = colours
        .iter()
        .map(|c| {
            let mut free = vec![0.0f64; threads];
            for k in c.clone() {
                let t = (0..threads).min_by(|&a, &b| free[a].total_cmp(&free[b])).unwrap();
                free[t] += work[k];
            }
            free.iter().copied().fold(0.0, f64::max)
        })
        .sum();
    // the graph: event by event, a free thread takes the lowest ready chunk
    let g = &model.chunk_graph;
    let mut pending: Vec<u32> = (0..g.len()).map(|k| g.predecessors(k)).collect();
    let mut ready: std::collections::BTreeSet<usize> = (0..g.len()).filter(|&k| pending[k] == 0).collect();
    let mut running: Vec<(f64, usize)> = Vec::new(); // (finish time, chunk)
    let (mut now, mut idle) = (0.0f64, threads);
    while !ready.is_empty() || !running.is_empty() {
        while idle > 0 && !ready.is_empty() {
            let k = ready.pop_first().unwrap();
            running.push((now + work[k], k));
            idle -= 1;
        }
        let i = (0..running.len()).min_by(|&a, &b| running[a].0.total_cmp(&running[b].0)).unwrap();
        let (t, k) = running.swap_remove(i);
        now = t;
        idle += 1;
        for &j in g.successors(k) {
            pending[j as usize] -= 1;
            if pending[j as usize] == 0 {
                ready.insert(j as usize);
            }
        }
    }
    (total / barrier, total / now)
}

/// The meshes of the env list `var` (comma list of coarse, default, fine, h2.5; unset or empty:
/// none), one after the other: each mesh's name, its bench scene (`static_scene`: file and JSON) and the
/// model on the mesh loaded from target/bench-mesh (meshed there first if missing), or why
/// not. Lazy, so that one model is in memory at a time.
fn static_problems(var: &str) -> impl Iterator<Item = (String, PathBuf, serde_json::Value, Result<Problem, String>)> {
    let sizes: Vec<String> = std::env::var(var).unwrap_or_default().split(',').map(str::trim).filter(|s| !s.is_empty()).map(String::from).collect();
    sizes.into_iter().map(|size| {
        let (path, scene) = static_scene(&size);
        let cache = root().join("target/bench-mesh");
        let problem = jointquake::scene::Scene::load(&path).map_err(|e| e.to_string()).and_then(|mut s| {
            let mesh = jointquake::pipeline::load_scene_mesh(&mut s, &path, Some(&cache)).map_err(|e| e.to_string())?;
            Problem::build(s, mesh).map_err(|e| e.to_string())
        });
        (size, path, scene, problem)
    })
}
