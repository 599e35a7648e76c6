//! Massless-foundation condensation benchmark (issue 13): the cost per explicit step of the
//! condensation at about 10⁴ and 10⁵ condensed unknowns, by both methods of `foundation`:
//! the sparse solve u_f = −K_ff⁻¹ K_fb u_b per step, and the dense Schur complement S (formed
//! once, S u_b per step), against the model's element loop; and which one the rule
//! (`foundation::choose_method`) picks, i.e. the per-step cost of the path that runs.
//!
//! Model: a massless hex8 foundation box n × n × n (E = 20 GPa, ν = 0.25, base fixed) carrying
//! a massive one-element layer (the dam's footprint) on its whole top face: the interface is
//! the (n+1)² top nodes. Reported per case: condensed and interface unknowns, factor entries,
//! symbolic + numeric factorisation time, solve per step, S u_b per step
//! (`Condensation::add_schur_force_into`, the step's call), the time to form S (n_b solves in
//! blocks, measured), its memory, the element loop (K u on the whole model, and without the
//! massless elements as the Schur step runs it) per step, and the method chosen. Times per
//! step: best and median of the repeats, one thread. Results to stdout and
//! `target/bench/foundation.json`.
//!
//! Run: `cargo bench --bench foundation` (part of `make bench`). `JQ_BENCH_SIZES`: comma list of
//! `1e4`, `1e5` (default both).
use jointquake::problem::foundation::{choose_method, Condensation, CondensationMethod};
use jointquake::mesh::structured::{box_mesh, BoxSpec};
use jointquake::mesh::Group;
use jointquake::model::Model;
use std::time::Instant;

fn model(n: usize) -> Model {
    let h = 1.0;
    let mut m = box_mesh(&BoxSpec::new("b", [n as f64 * h, n as f64 * h, (n + 1) as f64 * h], [n, n, n + 1]));
    let cells = m.group("block:b").unwrap().cells.clone();
    let (mut lo, mut hi) = (Vec::new(), Vec::new());
    for c in cells {
        let z: f64 = m.cells[c].nodes().iter().map(|&v| m.nodes[v as usize][2]).sum::<f64>() / 8.0;
        if z < n as f64 * h { lo.push(c) } else { hi.push(c) }
    }
    m.groups.retain(|g| g.name != "block:b");
    m.groups.push(Group { name: "block:rock".into(), dim: 3, tag: 101, cells: lo });
    m.groups.push(Group { name: "block:dam".into(), dim: 3, tag: 102, cells: hi });
    let scene: jointquake::scene::Scene = serde_json::from_value(serde_json::json!({
        "geometry": {"msh": "none.msh"},
        "materials": [
            {"group": "block:rock", "E": 2e10, "nu": 0.25, "rho": 2700.0, "massless": true},
            {"group": "block:dam", "E": 2.5e10, "nu": 0.2, "rho": 2400.0}
        ],
        "boundary": [{"group": "b:z0"}],
        "time": {"duration": 0.0}
    }))
    .unwrap();
    Model::build(m, &scene).unwrap()
}

fn stats(mut v: Vec<f64>) -> (f64, f64) {
    v.sort_by(|a, b| a.total_cmp(b));
    (v[0], v[v.len() / 2])
}

fn main() {
    let sizes = std::env::var("JQ_BENCH_SIZES").unwrap_or_else(|_| "1e4,1e5".into());
    let mut out = Vec::new();
    println!("massless foundation: condensation per step (one thread; times in ms, best/median)");
    println!(
        "{:>5} {:>9} {:>7} {:>10} {:>8} {:>8} {:>15} {:>13} {:>9} {:>13} {:>13} {:>7}",
        "case", "condensed", "interf.", "L entries", "factor", "form S", "solve/step", "S·u_b/step", "S [MB]", "K u all", "K u massive", "chosen"
    );
    for s in sizes.split(',') {
        let n = match s.trim() {
            "1e4" => 14, // 15³ nodes → 3·14·15² ≈ 9.4e3 condensed unknowns
            "1e5" => 31, // 32³ nodes → 3·31·32² ≈ 9.5e4
            other => panic!("JQ_BENCH_SIZES: unknown size {other} (1e4, 1e5)"),
        };
        let m = model(n);
        // the solve method alone: assembly and factorisation
        let t0 = Instant::now();
        let c_solve = Condensation::build(&m, faer::Par::Seq, Some(CondensationMethod::Solve)).unwrap().unwrap();
        let factor = t0.elapsed().as_secs_f64();
        drop(c_solve);
        // the Schur method: the same, plus forming S (rayon over blocks of right-hand sides)
        let t0 = Instant::now();
        let mut c = Condensation::build(&m, faer::Par::Seq, Some(CondensationMethod::Schur)).unwrap().unwrap();
        let form_s = t0.elapsed().as_secs_f64() - factor;
        let info = c.info(0.0);
        let (nf, nb) = (info.condensed_unknowns, info.interface_unknowns);
        let chosen = choose_method(nb, info.factor_entries);
        let mut u = vec![0.0; 3 * m.n_nodes()];
        for (k, &d) in c.b_dofs.iter().enumerate() {
            u[d] = 1e-4 * ((k as f64) * 0.37).sin();
        }
        let reps = if n > 20 { 15 } else { 60 };
        let time = |f: &mut dyn FnMut()| {
            let v: Vec<f64> = (0..reps)
                .map(|_| {
                    let t = Instant::now();
                    f();
                    t.elapsed().as_secs_f64()
                })
                .collect();
            stats(v)
        };
        let mut f = vec![0.0; 3 * m.n_nodes()];
        let (sb, sm) = time(&mut || c.condense_into(&mut u));
        let (xb, xm) = time(&mut || c.add_schur_force_into(&u, &mut f));
        let (kb, km) = time(&mut || m.internal_forces_into(&u, &mut f));
        let (mb, mm) = time(&mut || m.internal_forces_of_massive_into(&u, &mut f));
        let schur_mb = info.schur_bytes as f64 / 1e6;
        println!(
            "{:>5} {:>9} {:>7} {:>10} {:>7.2}s {:>7.1}s {:>7.2}/{:>7.2} {:>6.3}/{:>6.3} {:>9.1} {:>6.2}/{:>6.2} {:>6.2}/{:>6.2} {:>7}",
            s, nf, nb, info.factor_entries, factor, form_s, 1e3 * sb, 1e3 * sm, 1e3 * xb, 1e3 * xm, schur_mb, 1e3 * kb, 1e3 * km, 1e3 * mb, 1e3 * mm,
            format!("{chosen:?}").to_lowercase()
        );
        let (run_b, run_m) = if chosen == CondensationMethod::Schur { (xb + mb, xm + mm) } else { (sb + kb, sm + km) };
        println!("{:>5} per step of the path that runs ({:?}): elements + condensation {:.3}/{:.3} ms", s, chosen, 1e3 * run_b, 1e3 * run_m);
        out.push(serde_json::json!({
            "case": s, "condensed_unknowns": nf, "interface_unknowns": nb, "factor_entries": info.factor_entries,
            "factor_s": factor, "schur_form_s": form_s, "schur_mb": schur_mb,
            "solve_ms_best": 1e3 * sb, "solve_ms_median": 1e3 * sm,
            "schur_product_ms_best": 1e3 * xb, "schur_product_ms_median": 1e3 * xm,
            "element_loop_ms_best": 1e3 * kb, "element_loop_ms_median": 1e3 * km,
            "element_loop_massive_ms_best": 1e3 * mb, "element_loop_massive_ms_median": 1e3 * mm,
            "chosen": chosen, "step_ms_best": 1e3 * run_b, "step_ms_median": 1e3 * run_m,
        }));
    }
    std::fs::create_dir_all("target/bench").ok();
    std::fs::write("target/bench/foundation.json", serde_json::to_string_pretty(&out).unwrap()).ok();
    println!("(solve: one sparse solve for u_f; S·u_b: the Schur step's product; K u all / massive: the element loop with / without the massless elements; the path that runs: Schur = K u massive + S·u_b, solve = K u all + solve)");
}
