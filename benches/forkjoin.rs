//! The cost of one rayon fork-join on this machine (issue 30 §2: how much of a dam step the
//! step's parallel regions cost; their count per step is printed by `benches/dam.rs`).
//!
//! In a pool of `JQ_BENCH_THREADS` threads (default 2; the calling thread is one of them, as in
//! the dam bench and `jointquake run`), regions shaped as the step's are timed, each after a
//! serial gap of G µs of busy work on the calling thread (G = 0: back to back; the step's
//! regions are separated by serial work, during which rayon's idle workers spin, yield and then
//! sleep, so the cost of a region depends on the gap before it):
//! - `join`: `rayon::join` of two empty closures;
//! - `colour k`: `(0..k).into_par_iter().with_max_len(1)` of empty tasks (k = 2, 12: an element
//!   colour of the fine dam mesh has about 12 chunks), the element loop's pattern;
//! - `work 2 × W`: two tasks of W µs of busy work each (the ideal wall time is W): the cost of
//!   handing one half of a region's work to the other thread.
//!
//! Per case: the wall time per region above the gap (and above W), best and median of
//! `JQ_BENCH_REPEATS` (default 5) repeats of `JQ_BENCH_REGIONS` regions (default 2000), and
//! the CPU time per region of all threads (/proc/self/task/*/schedstat) above the gap's and the
//! work's own CPU time: what the waiting and spinning of the other thread cost. Print the load
//! average beside it: on a loaded machine the other thread may not be running.
//!
//! Last, the **round trip of a cache line between two threads** (a ping-pong of one atomic,
//! 2 × 10⁶ round trips, best of 5; the operating system places the two threads, on a 2-core
//! machine one per core): it names the kind of core pair the machine has at that moment. On the
//! EPYC VM of docs/performance.md §7 ("Two kinds of core pair") it was 70–125 ns when the two
//! vCPUs shared a cache and 320–380 ns when not, and the host switched between the two every
//! few minutes: run it before and after a timing to know which one the timing saw.
//! Run: `cargo bench --bench forkjoin`; results also in target/bench/forkjoin.json.

use rayon::prelude::*;
use std::time::{Duration, Instant};

fn spin_for(d: Duration) {
    let t = Instant::now();
    while t.elapsed() < d {
        std::hint::spin_loop();
    }
}

/// CPU time of this process [s], all its threads (as in benches/dam.rs).
fn cpu_s() -> f64 {
    let Ok(dir) = std::fs::read_dir("/proc/self/task") else { return f64::NAN };
    dir.flatten().filter_map(|t| std::fs::read_to_string(t.path().join("schedstat")).ok()).filter_map(|s| s.split_whitespace().next()?.parse::<f64>().ok()).sum::<f64>() * 1e-9
}

/// The round trip [ns] of one cache line between two threads: `n` round trips of a counter
/// that each thread advances in turn.
fn ping_pong_ns(n: u64) -> f64 {
    use std::sync::atomic::{AtomicU64, Ordering::*};
    let flag = AtomicU64::new(0);
    std::thread::scope(|s| {
        s.spawn(|| {
            for i in 0..n {
                while flag.load(Acquire) != 2 * i + 1 {
                    std::hint::spin_loop();
                }
                flag.store(2 * i + 2, Release);
            }
        });
        let t = Instant::now();
        for i in 0..n {
            flag.store(2 * i + 1, Release);
            while flag.load(Acquire) != 2 * i + 2 {
                std::hint::spin_loop();
            }
        }
        t.elapsed().as_secs_f64() / n as f64 * 1e9
    })
}

fn stats(v: &[f64]) -> (f64, f64) {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    (s[0], s[s.len() / 2])
}

fn main() {
    let threads: usize = std::env::var("JQ_BENCH_THREADS").ok().and_then(|v| v.parse().ok()).unwrap_or(2usize).max(1);
    let repeats: usize = std::env::var("JQ_BENCH_REPEATS").ok().and_then(|v| v.parse().ok()).unwrap_or(5usize).max(1);
    let regions: usize = std::env::var("JQ_BENCH_REGIONS").ok().and_then(|v| v.parse().ok()).unwrap_or(2000usize).max(1);
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default().trim().to_string();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("a thread pool");
    println!("fork-join cost ({threads} threads, {repeats} × {regions} regions per case, load average {load})");
    type Case = (&'static str, u64, Box<dyn Fn() + Sync>);
    let cases: Vec<Case> = vec![
        ("join", 0, Box::new(|| rayon::join(|| (), || ()).0)),
        ("colour 2", 0, Box::new(|| (0..2).into_par_iter().with_max_len(1).for_each(|_| ()))),
        ("colour 12", 0, Box::new(|| (0..12).into_par_iter().with_max_len(1).for_each(|_| ()))),
        ("work 2 × 20 µs", 20, Box::new(|| (0..2).into_par_iter().with_max_len(1).for_each(|_| spin_for(Duration::from_micros(20))))),
        ("work 2 × 200 µs", 200, Box::new(|| (0..2).into_par_iter().with_max_len(1).for_each(|_| spin_for(Duration::from_micros(200))))),
    ];
    let mut rows = Vec::new();
    pool.install(|| {
        for (name, work_us, region) in &cases {
            for gap_us in [0u64, 5, 20, 100, 1000] {
                // fewer regions for the long gaps (the same order of total time per case)
                let n = if gap_us >= 100 || *work_us >= 200 { (regions / 10).max(1) } else { regions };
                let gap = Duration::from_micros(gap_us);
                let (mut wall, mut cpu) = (Vec::new(), Vec::new());
                for _ in 0..repeats {
                    let (c0, t0) = (cpu_s(), Instant::now());
                    for _ in 0..n {
                        spin_for(gap);
                        region();
                    }
                    let (w, c) = (t0.elapsed().as_secs_f64(), cpu_s() - c0);
                    let serial = 1e-6 * (gap_us as f64 + *work_us as f64);
                    // wall above the gap and the ideal work; CPU above the gap's and the work's
                    wall.push(1e6 * (w / n as f64 - serial));
                    cpu.push(1e6 * (c / n as f64 - 1e-6 * (gap_us as f64 + (threads.min(2) as f64) * *work_us as f64)));
                }
                let ((wb, wm), (cb, cm)) = (stats(&wall), stats(&cpu));
                println!("  {name:16} after a gap of {gap_us:4} µs: {wb:7.2} / {wm:7.2} µs wall per region (best / median), CPU above the serial work {cb:7.2} / {cm:7.2} µs");
                rows.push(serde_json::json!({"case": name, "gap_us": gap_us, "work_us": work_us, "regions": n, "wall_us_best": wb, "wall_us_median": wm, "cpu_us_best": cb, "cpu_us_median": cm}));
            }
        }
    });
    let load_after = std::fs::read_to_string("/proc/loadavg").unwrap_or_default().trim().to_string();
    println!("  load average after: {load_after}");
    // after the cases: its threads' CPU time would otherwise count in the first case's (the
    // process's CPU sum drops when the finished threads leave /proc/self/task)
    let round_trip = (0..5).map(|_| ping_pong_ns(2_000_000)).fold(f64::INFINITY, f64::min);
    println!("cache-line round trip between two threads: {round_trip:.0} ns (best of 5 × 2e6)");
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let _ = std::fs::create_dir_all(root.join("target/bench"));
    let _ = std::fs::write(root.join("target/bench/forkjoin.json"), serde_json::to_string_pretty(&serde_json::json!({"threads": threads, "round_trip_ns": round_trip, "load_before": load, "load_after": load_after, "cases": rows})).unwrap());
}
