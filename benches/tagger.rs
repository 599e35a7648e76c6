//! Tagger benchmark: 10⁶ slave nodes (a 999 × 999 quad slave surface) against a 10⁶-face master
//! surface (1000 × 1000 quads), one thread: wall time of `tag_joint` and peak memory.
//! `tag_joint` runs `JQ_BENCH_REPEATS` times (default 3; the machine is shared): best and median
//! time; the peak memory is the process's VmHWM after the runs (each run's result is dropped
//! before the next).
//! Run: `cargo bench --bench tagger` (`JQ_TAG_N` sets the master side, default 1000).
use jointquake::interface::{flat_joint_mesh, tag_joint, JointSpec};
use std::time::Instant;

fn vm_hwm_mb() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| s.lines().find(|l| l.starts_with("VmHWM:")).and_then(|l| l.split_whitespace().nth(1)).and_then(|v| v.parse::<f64>().ok()))
        .map(|kb| kb / 1024.0)
        .unwrap_or(f64::NAN)
}

fn main() {
    let n: usize = std::env::var("JQ_TAG_N").ok().and_then(|v| v.parse().ok()).unwrap_or(1000);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    pool.install(|| {
        let t = Instant::now();
        let mesh = flat_joint_mesh(n, n - 1);
        let t_mesh = t.elapsed().as_secs_f64();
        let mem_mesh = vm_hwm_mb();
        let spec = JointSpec { name: "J".into(), master: "joint:master".into(), slave: "joint:slave".into(), auto: false };
        let repeats: usize = std::env::var("JQ_BENCH_REPEATS").ok().and_then(|v| v.parse().ok()).unwrap_or(3usize).max(1);
        let mut times = Vec::new();
        let (mut n_slave, mut n_faces) = (0, 0);
        for _ in 0..repeats {
            let t = Instant::now();
            let j = tag_joint(&mesh, &spec, 1e-9).expect("tagging");
            times.push(t.elapsed().as_secs_f64());
            (n_slave, n_faces) = (j.n_slave(), j.master.faces.len());
        }
        let mem = vm_hwm_mb();
        let mut sorted = times.clone();
        sorted.sort_by(f64::total_cmp);
        let (best, median) = (sorted[0], sorted[sorted.len() / 2]);
        let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default().trim().to_string();
        println!("tagger benchmark (1 thread, load average {load}): {n_slave} slave nodes vs {n_faces} master faces");
        println!("  mesh generation  {t_mesh:.2} s (peak memory {mem_mesh:.0} MB)");
        println!(
            "  tag_joint        best {best:.2} s, median {median:.2} s of {repeats} (target < 10 s), peak memory {mem:.0} MB ({:.0} bytes per slave node above the mesh)",
            (mem - mem_mesh) * 1048576.0 / n_slave as f64
        );
        let json = serde_json::json!({"slave_nodes": n_slave, "master_faces": n_faces, "tag_seconds": times, "tag_best_seconds": best,
            "tag_median_seconds": median, "mesh_seconds": t_mesh, "peak_mb": mem, "peak_mb_after_mesh": mem_mesh, "load": load});
        let _ = std::fs::create_dir_all("target/bench");
        let _ = std::fs::write("target/bench/tagger.json", serde_json::to_string_pretty(&json).unwrap());
    });
}
