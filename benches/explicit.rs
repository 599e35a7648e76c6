//! Explicit-dynamics benchmark (issue 2): contact-free central-difference steps
//! (`Simulation::step`: `ExplicitSolver::step`, `Stage::Dynamic`, gravity on a box fixed at its base, no damping,
//! no contact) on structured tet4 and hex8 boxes of about 10⁴, 10⁵ and 10⁶ elements, on one and
//! two threads, plus the Akantu/CalculiX comparison case (1 × 1 × 10 m hex8 prism of
//! 10 × 10 × 100 elements, 1000 steps).
//!
//! Per case it reports element-steps per second (best and median of the repeats), the estimated
//! bytes moved per step (see [`Traffic`]: what is counted), the achieved bandwidth as a fraction
//! of the triad bandwidth measured in the same run (a[i] = b[i] + s c[i] on arrays far larger
//! than the caches, counted as 24 bytes per index), the peak resident memory per element
//! (VmHWM, reset after the mesh is generated, in a fresh process per case: the bench re-executes
//! itself with `--child`), the two-thread speed-up, and whether 1 and 2 threads gave
//! bit-identical displacements. Results go to stdout and `target/bench/explicit.json`.
//!
//! Run: `cargo bench --bench explicit` (or `make bench`). Knobs (environment):
//! - `JQ_BENCH_SIZES`: comma list of `1e4`, `1e5`, `1e6`, `prism` (the comparison case).
//!   Default all; `JQ_BENCH_SIZES=1e4,prism` is a quick run.
//! - `JQ_BENCH_KINDS`: comma list of `tet4`, `hex8`. Default both (the prism is hex8 only).
//! - `JQ_BENCH_REPEATS`: timed repeats per case and thread count. Default 5 (at least 3: the
//!   machine is shared, best and median are reported).
//! - `JQ_BENCH_SECONDS`: target wall time of one repeat [s]. Default 1.0: long enough to
//!   average over a few hundred steps on small meshes, short enough for the 10⁶ cases.
//! - `JQ_TRIAD_MB`: size of each of the three triad arrays [MB]. Default 512: far above the
//!   L2 (2 MB per core) and any last-level cache, so the triad measures main memory (on the
//!   development VM the triad runs at memory speed from 3 × 64 MB on).
//! - `JQ_BENCH_DUMP_U=1`: also write the displacement after the determinism check
//!   (`target/bench/u_<case>.f64`, little-endian f64) to compare two builds.
use jointquake::problem::Problem;
use jointquake::simulation::Simulation;
use jointquake::mesh::structured::{box_mesh, BoxSpec};
use jointquake::model::Model;
use rayon::prelude::*;
use std::time::Instant;

/// Steps of the 1-thread / 2-thread determinism check (from rest, fresh state each time).
const CHECK_STEPS: usize = 10;

#[derive(Clone, Debug)]
struct Case {
    label: String,
    tets: bool,
    divisions: [usize; 3],
    size: [f64; 3],
    /// Fixed number of steps per repeat (the comparison case); None: calibrated to JQ_BENCH_SECONDS.
    steps: Option<usize>,
    threads: Vec<usize>,
}

fn env_list(name: &str, default: &str) -> Vec<String> {
    std::env::var(name).unwrap_or_else(|_| default.into()).split(',').map(|s| s.trim().to_string()).filter(|s| !s.is_empty()).collect()
}

fn env_num<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name).ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

fn cases() -> Vec<Case> {
    let sizes = env_list("JQ_BENCH_SIZES", "1e4,1e5,1e6,prism");
    let kinds = env_list("JQ_BENCH_KINDS", "tet4,hex8");
    let mut v = Vec::new();
    for kind in &kinds {
        let tets = kind == "tet4";
        for s in &sizes {
            // cubes of n³ cells of 0.1 m; tet4 splits each cell in 6
            let n = match (s.as_str(), tets) {
                ("1e4", false) => 22,
                ("1e5", false) => 46,
                ("1e6", false) => 100,
                ("1e4", true) => 12,
                ("1e5", true) => 26,
                ("1e6", true) => 55,
                _ => continue,
            };
            v.push(Case { label: format!("{kind} {s}"), tets, divisions: [n; 3], size: [0.1 * n as f64; 3], steps: None, threads: vec![1, 2] });
        }
    }
    if sizes.iter().any(|s| s == "prism") && kinds.iter().any(|k| k == "hex8") {
        v.push(Case {
            label: "hex8 prism 10x10x100 (Akantu/CalculiX case)".into(),
            tets: false,
            divisions: [10, 10, 100],
            size: [1.0, 1.0, 10.0],
            steps: Some(1000),
            threads: vec![1, 2],
        });
    }
    v
}

fn proc_status_kb(key: &str) -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| s.lines().find(|l| l.starts_with(key)).and_then(|l| l.split_whitespace().nth(1)).and_then(|v| v.parse::<f64>().ok()))
        .unwrap_or(f64::NAN)
}

/// Reset VmHWM to the current RSS (Linux ≥ 4.0: `echo 5 > /proc/self/clear_refs`).
fn reset_peak_rss() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    if n % 2 == 1 { s[n / 2] } else { 0.5 * (s[n / 2 - 1] + s[n / 2]) }
}

fn best(v: &[f64]) -> f64 {
    v.iter().copied().fold(f64::NAN, f64::max)
}

/// Triad bandwidth [GB/s] on `threads` threads, `reps` timed passes after one warm-up pass.
fn triad_gbs(n: usize, threads: usize, reps: usize) -> Vec<f64> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| {
        const CHUNK: usize = 1 << 15;
        let mut a = vec![0.0f64; n];
        let b = vec![1.0f64; n];
        let c = vec![2.0f64; n];
        let s = std::hint::black_box(3.0);
        let mut out = Vec::new();
        for r in 0..=reps {
            let t = Instant::now();
            a.par_chunks_mut(CHUNK).zip(b.par_chunks(CHUNK)).zip(c.par_chunks(CHUNK)).for_each(|((a, b), c)| {
                for i in 0..a.len() {
                    a[i] = b[i] + s * c[i];
                }
            });
            let secs = t.elapsed().as_secs_f64();
            std::hint::black_box(&mut a);
            if r > 0 {
                out.push(24.0 * n as f64 / secs / 1e9);
            }
        }
        out
    })
}

/// Estimated bytes moved per step by `ExplicitSolver::step` (Stage::Dynamic, α = β = 0, no
/// contact), counting each array once per loop that streams it: a loop reuses what it touches,
/// nothing survives from one loop to the next (so at 10⁴ elements, where everything fits in the
/// L2 cache, the real memory traffic is lower and the "fraction of the bandwidth" can exceed 1).
/// - element data, once: node ids (16 B tet4, 32 B hex8), geometry (tet4: 9 gradients and
///   the volume, 80 B) or shape id (hex8, 4 B; the shared shapes once), material id (2 B);
/// - element chunks (`jointquake::model::Schedule`): each chunk reads its node list (4 B per
///   node) and, at each of its distinct nodes, reads u and reads and writes f_int (72 B); the
///   chunk's nodes stay in cache while its elements are assembled;
/// - nodal loops, per node: zeroing f_int (24 B), the external force (mass in, f_ext out:
///   32 B), the update with the energy increments and the non-finite check fused in (mass,
///   fixed, u, u_prev, f_ext, f_int in, u_next out: 129 B), and the energy check every
///   `energy_stride` = 10 steps (u, u_prev, mass, f_int: 80 B / 10).
#[derive(Clone, Debug, serde::Serialize)]
struct Traffic {
    element: f64,
    element_chunks: usize,
    chunk_node_touches: usize,
    chunk_nodal: f64,
    nodal_loops: f64,
    total: f64,
}

fn traffic(model: &Model) -> Traffic {
    let n = model.n_nodes() as f64;
    let t = &model.tets;
    let h = &model.hexes;
    let element = t.nodes.len() as f64 * (std::mem::size_of::<[u32; 4]>() + std::mem::size_of::<jointquake::model::tet4::TetGeom>() + 2) as f64
        + h.nodes.len() as f64 * (std::mem::size_of::<[u32; 8]>() + 4 + 2) as f64
        + (h.shapes.len() * std::mem::size_of::<jointquake::model::hex8::HexShape>()) as f64;
    let touches = t.schedule.chunk_nodes.len() + h.schedule.chunk_nodes.len();
    let chunk_nodal = (4.0 + 72.0) * touches as f64;
    let per_node = 24.0 + 32.0 + 129.0 + 80.0 / 10.0;
    let nodal_loops = per_node * n;
    Traffic {
        element,
        element_chunks: t.schedule.chunks.len() + h.schedule.chunks.len(),
        chunk_node_touches: touches,
        chunk_nodal,
        nodal_loops,
        total: element + chunk_nodal + nodal_loops,
    }
}

fn scene() -> jointquake::scene::Scene {
    serde_json::from_value(serde_json::json!({
        "geometry": {"msh": "unused.msh"},
        "materials": [{"group": "block:b", "E": 3e10, "nu": 0.2, "rho": 2400.0}],
        "boundary": [{"group": "b:z0"}],
        "loads": {"gravity": {"g": 9.81}},
        "equilibrium": {"method": "none"},
        "time": {"duration": 1.0, "energy_tolerance": 1.0}
    }))
    .unwrap()
}

fn hash_bits(u: &[f64]) -> u64 {
    // FNV-1a over the bit patterns
    u.iter().fold(0xcbf29ce484222325u64, |h, v| (h ^ v.to_bits()).wrapping_mul(0x100000001b3))
}

/// One case in this process: build, check determinism, time on each thread count.
fn child(case: &Case) -> serde_json::Value {
    let repeats: usize = env_num("JQ_BENCH_REPEATS", 5usize).max(3);
    let seconds: f64 = env_num("JQ_BENCH_SECONDS", 1.0);
    let t0 = Instant::now();
    let mesh = box_mesh(&BoxSpec::new("b", case.size, case.divisions).tets(case.tets));
    let t_mesh = t0.elapsed().as_secs_f64();
    let rss_mesh = proc_status_kb("VmRSS:") * 1024.0;
    let reset = reset_peak_rss();
    let sc = scene();
    let t0 = Instant::now();
    // the model, its (no) joints and loads; the run object at the scene's default step (0.9 of
    // the stable step)
    let problem = Problem::build(sc, mesh).unwrap();
    let t_model = t0.elapsed().as_secs_f64();
    let model: &Model = &problem.model;
    let ne = model.n_elements();
    let fresh = || Simulation::new(&problem).unwrap();
    let dt = fresh().dt();
    let run = |sim: &mut Simulation, steps: usize| {
        for _ in 0..steps {
            sim.step().unwrap();
        }
    };
    // determinism: the same steps from rest on 1 and 2 threads
    let mut hashes = Vec::new();
    let mut u_check = Vec::new();
    for &k in &[1usize, 2] {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(k).build().unwrap();
        let u = pool.install(|| {
            let mut sim = fresh();
            run(&mut sim, CHECK_STEPS);
            sim.state.u
        });
        hashes.push(hash_bits(&u));
        u_check = u;
    }
    if std::env::var("JQ_BENCH_DUMP_U").is_ok_and(|v| v == "1") {
        let name = case.label.split_whitespace().take(2).collect::<Vec<_>>().join("_");
        let bytes: Vec<u8> = u_check.iter().flat_map(|v| v.to_le_bytes()).collect();
        let _ = std::fs::create_dir_all("target/bench");
        let _ = std::fs::write(format!("target/bench/u_{name}.f64"), bytes);
    }
    // peak memory of one run (model, loads, one solver and state), before the timing below
    // keeps one solver and state per thread count
    let hwm = proc_status_kb("VmHWM:") * 1024.0;
    let rss = proc_status_kb("VmRSS:") * 1024.0;
    // timing: the thread counts take turns repeat by repeat, so that both see the same load
    // from the other users of the machine
    let pools: Vec<rayon::ThreadPool> = case.threads.iter().map(|&k| rayon::ThreadPoolBuilder::new().num_threads(k).build().unwrap()).collect();
    let mut runs: Vec<(Simulation, usize, Vec<f64>)> = pools
        .iter()
        .map(|pool| {
            pool.install(|| {
                let mut sim = fresh();
                let t = Instant::now();
                run(&mut sim, 2);
                let per_step = t.elapsed().as_secs_f64() / 2.0;
                let steps = case.steps.unwrap_or_else(|| ((seconds / per_step).round() as usize).clamp(3, 20000));
                (sim, steps, Vec::new())
            })
        })
        .collect();
    for _ in 0..repeats {
        for (pool, (sim, steps, rates)) in pools.iter().zip(runs.iter_mut()) {
            pool.install(|| {
                let t = Instant::now();
                run(sim, *steps);
                rates.push((ne * *steps) as f64 / t.elapsed().as_secs_f64());
            });
        }
    }
    let mut per_threads = Vec::new();
    for (&k, (_, steps, rates)) in case.threads.iter().zip(&runs) {
        eprintln!("  {:<44} {k} thread(s): {steps:5} steps × {repeats}: best {:.3e}, median {:.3e} element-steps/s", case.label, best(rates), median(rates));
        per_threads.push(serde_json::json!({"threads": k, "steps_per_repeat": steps, "rates": rates, "best": best(rates), "median": median(rates)}));
    }
    drop(runs);
    let tr = traffic(model);
    serde_json::json!({
        "label": case.label, "kind": if case.tets { "tet4" } else { "hex8" }, "divisions": case.divisions, "size_m": case.size,
        "elements": ne, "nodes": model.n_nodes(), "chunks": model.tets.schedule.chunks.len() + model.hexes.schedule.chunks.len(), "colours": model.tets.schedule.colors.len() + model.hexes.schedule.colors.len(), "hex_shapes": model.hexes.shapes.len(), "dt": dt,
        "mesh_seconds": t_mesh, "model_seconds": t_model,
        "traffic": tr, "bytes_per_step": tr.total, "bytes_per_element_step": tr.total / ne as f64,
        "rss_after_mesh_bytes": rss_mesh, "peak_rss_bytes": hwm, "rss_end_bytes": rss, "peak_reset": reset,
        "peak_rss_bytes_per_element": hwm / ne as f64,
        "check_steps": CHECK_STEPS, "hash_1_thread": format!("{:016x}", hashes[0]), "hash_2_threads": format!("{:016x}", hashes[1]),
        "identical_1_2_threads": hashes[0] == hashes[1],
        "runs": per_threads,
    })
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let Some(i) = args.iter().position(|a| a == "--child") {
        let idx: usize = args[i + 1].parse().unwrap();
        let case = &cases()[idx];
        let r = child(case);
        println!("JQ_RESULT {}", serde_json::to_string(&r).unwrap());
        return;
    }
    let repeats: usize = env_num("JQ_BENCH_REPEATS", 5usize).max(3);
    let triad_mb: usize = env_num("JQ_TRIAD_MB", 512usize);
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default().trim().to_string();
    println!("explicit benchmark: load average before {load}");
    let n = triad_mb * (1 << 20) / 8;
    let mut triad = Vec::new();
    for k in [1usize, 2] {
        let r = triad_gbs(n, k, repeats);
        println!("  triad {k} thread(s), 3 × {triad_mb} MB: best {:.2} GB/s, median {:.2} GB/s", best(&r), median(&r));
        triad.push(serde_json::json!({"threads": k, "gbs": r, "best": best(&r), "median": median(&r)}));
    }
    let triad_best = |k: usize| triad[k - 1]["best"].as_f64().unwrap();
    let exe = std::env::current_exe().unwrap();
    let mut results = Vec::new();
    println!(
        "\n  {:<44} {:>9} {:>3} {:>11} {:>11} {:>10} {:>8} {:>7} {:>8} {:>9}",
        "case", "elements", "thr", "best el/s", "median el/s", "B/el-step", "GB/s", "of bw", "speed-up", "peak B/el"
    );
    for (idx, case) in cases().iter().enumerate() {
        let out = std::process::Command::new(&exe).arg("--child").arg(idx.to_string()).stderr(std::process::Stdio::inherit()).output().expect("re-exec the bench");
        let text = String::from_utf8_lossy(&out.stdout);
        let Some(line) = text.lines().find_map(|l| l.strip_prefix("JQ_RESULT ")) else {
            println!("  {}: child failed ({})", case.label, out.status);
            continue;
        };
        let mut r: serde_json::Value = serde_json::from_str(line).unwrap();
        let bpe = r["bytes_per_element_step"].as_f64().unwrap();
        let ne = r["elements"].as_u64().unwrap();
        let one = r["runs"][0]["best"].as_f64().unwrap();
        let runs = r["runs"].as_array().unwrap().clone();
        let mut enriched = Vec::new();
        for run in runs {
            let k = run["threads"].as_u64().unwrap() as usize;
            let b = run["best"].as_f64().unwrap();
            let gbs = b * bpe / 1e9;
            let frac = gbs / triad_best(k);
            let speedup = b / one;
            println!(
                "  {:<44} {:>9} {:>3} {:>11.3e} {:>11.3e} {:>10.0} {:>8.2} {:>6.0}% {:>8.2} {:>9.0}",
                r["label"].as_str().unwrap(),
                ne,
                k,
                b,
                run["median"].as_f64().unwrap(),
                bpe,
                gbs,
                100.0 * frac,
                speedup,
                r["peak_rss_bytes_per_element"].as_f64().unwrap()
            );
            let mut run = run.clone();
            run["achieved_gbs"] = serde_json::json!(gbs);
            run["fraction_of_triad"] = serde_json::json!(frac);
            run["speedup_vs_1_thread"] = serde_json::json!(speedup);
            enriched.push(run);
        }
        if !r["identical_1_2_threads"].as_bool().unwrap() {
            println!("  WARNING {}: 1 and 2 threads differ after {CHECK_STEPS} steps", case.label);
        }
        r["runs"] = serde_json::Value::Array(enriched);
        results.push(r);
    }
    let load_after = std::fs::read_to_string("/proc/loadavg").unwrap_or_default().trim().to_string();
    println!("  load average after {load_after}");
    let json = serde_json::json!({"load_before": load, "load_after": load_after, "repeats": repeats, "triad_mb": triad_mb, "triad": triad, "cases": results});
    let _ = std::fs::create_dir_all("target/bench");
    let _ = std::fs::write("target/bench/explicit.json", serde_json::to_string_pretty(&json).unwrap());
}
