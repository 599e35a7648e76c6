//! Tagger benchmark: 10⁶ slave nodes (a 999 × 999 quad slave surface) against a 10⁶-face master
//! surface (1000 × 1000 quads), one thread: wall time of `tag_joint` and peak memory.
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
        let t = Instant::now();
        let j = tag_joint(&mesh, &spec, 1e-9).expect("tagging");
        let secs = t.elapsed().as_secs_f64();
        let mem = vm_hwm_mb();
        println!("tagger benchmark (1 thread): {} slave nodes vs {} master faces", j.n_slave(), j.master.faces.len());
        println!("  mesh generation  {t_mesh:.2} s (peak memory {mem_mesh:.0} MB)");
        println!("  tag_joint        {secs:.2} s (target < 10 s), peak memory {mem:.0} MB ({:.0} bytes per slave node above the mesh)", (mem - mem_mesh) * 1048576.0 / j.n_slave() as f64);
        let json = serde_json::json!({"slave_nodes": j.n_slave(), "master_faces": j.master.faces.len(), "tag_seconds": secs,
            "mesh_seconds": t_mesh, "peak_mb": mem, "peak_mb_after_mesh": mem_mesh});
        let _ = std::fs::create_dir_all("target/bench");
        let _ = std::fs::write("target/bench/tagger.json", serde_json::to_string_pretty(&json).unwrap());
    });
}
