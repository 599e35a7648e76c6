//! Motion benchmark: synthesis of a three-component spectrum-compatible set, 20 s at 100 Hz
//! (2001 samples each), to the DL 5073-2000 arch-dam spectrum (β_max 2.50, site I, T_g 0.20 s)
//! at PGA 0.5575 g, seed 1 (the committed `pipelines/records/dam_dl5073_arch_I_s1_*`), one
//! thread. Target: under 2 s (docs/motion.md). `JQ_BENCH_REPEATS` runs (default 3): best and
//! median; the iteration counts say how much of the time is the iteration.
//! Run: `cargo bench --bench motion`.
use jointquake::motion::{SynthRequest, TargetSpec, synthesize_set};
use std::time::Instant;

fn main() {
    let spec = TargetSpec::Code { code: "DL 5073-2000".into(), structure: "arch".into(), site_class: "I".into(), basic_tg: None, tg: None, beta_max: None };
    let req = SynthRequest::new(spec, 0.5575, 1);
    let repeats: usize = std::env::var("JQ_BENCH_REPEATS").ok().and_then(|v| v.parse().ok()).unwrap_or(3usize).max(1);
    let mut times = Vec::new();
    let mut iters = Vec::new();
    for _ in 0..repeats {
        let t = Instant::now();
        let set = synthesize_set(&req).expect("synthesis");
        times.push(t.elapsed().as_secs_f64());
        iters = set.components.iter().map(|c| c.check.iterations).collect();
    }
    let mut sorted = times.clone();
    sorted.sort_by(f64::total_cmp);
    let (best, median) = (sorted[0], sorted[sorted.len() / 2]);
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default().trim().to_string();
    println!("motion synth: 3 components x 2001 samples (20 s, 100 Hz), iterations {iters:?}");
    println!("  best {best:.3} s, median {median:.3} s over {repeats} runs (target < 2 s) {}", if best < 2.0 { "ok" } else { "ABOVE TARGET" });
    println!("  load average: {load}");
}
