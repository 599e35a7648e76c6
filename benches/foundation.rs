//! Massless-foundation condensation benchmark (issue 13): the cost per explicit step of the
//! static condensation u_f = −K_ff⁻¹ K_fb u_b at about 10⁴ and 10⁵ condensed unknowns, against
//! the alternative of a dense Schur complement S on the interface (its product per step and
//! its formation by n_b solves), and against the model's own element loop.
//!
//! Model: a massless hex8 foundation box n × n × n (E = 20 GPa, ν = 0.25, base fixed) carrying
//! a massive one-element layer (the dam's footprint) on its whole top face: the interface is
//! the (n+1)² top nodes. Reported per case: condensed and interface unknowns, factor entries,
//! symbolic + numeric factorisation time, solve per step (best and median of the repeats,
//! one thread), the dense S product per step (an n_b × n_b matrix-vector product: the same
//! flops as with S formed), the estimated time to form S (n_b solves, from blocks of 64
//! right-hand sides), the memory of S, and the element loop (K u on the whole model) per step.
//! Results to stdout and `target/bench/foundation.json`.
//!
//! Run: `cargo bench --bench foundation` (part of `make bench`). `JQ_BENCH_SIZES`: comma list of
//! `1e4`, `1e5` (default both).
use jointquake::foundation::Condensation;
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
    println!("massless foundation: condensation per step (one thread; times in ms)");
    println!("{:>6} {:>9} {:>8} {:>11} {:>9} {:>13} {:>13} {:>10} {:>9} {:>11}", "case", "condensed", "interf.", "L entries", "factor", "solve/step", "S·u/step", "form S", "S [MB]", "K u/step");
    for s in sizes.split(',') {
        let n = match s.trim() {
            "1e4" => 14, // 15³ nodes → 3·14·15² ≈ 9.4e3 condensed unknowns
            "1e5" => 31, // 32³ nodes → 3·31·32² ≈ 9.5e4
            other => panic!("JQ_BENCH_SIZES: unknown size {other} (1e4, 1e5)"),
        };
        let m = model(n);
        let t0 = Instant::now();
        let mut c = Condensation::build(&m, faer::Par::Seq).unwrap().unwrap();
        let factor = t0.elapsed().as_secs_f64();
        let nf = c.f_dofs.len();
        let nb = c.b_dofs.len();
        let mut u = vec![0.0; 3 * m.n_nodes()];
        for (k, &d) in c.b_dofs.iter().enumerate() {
            u[d] = 1e-4 * ((k as f64) * 0.37).sin();
        }
        let reps = if n > 20 { 15 } else { 60 };
        let mut t_solve = Vec::new();
        for _ in 0..reps {
            let t = Instant::now();
            c.condense_into(&mut u);
            t_solve.push(t.elapsed().as_secs_f64());
        }
        // the Schur alternative: a dense n_b × n_b product per step (S not formed here: the
        // same flops and memory traffic)
        let smat: Vec<f64> = (0..nb * nb).map(|i| ((i % 97) as f64) * 1e-3).collect();
        let x: Vec<f64> = (0..nb).map(|i| i as f64).collect();
        let mut y = vec![0.0; nb];
        let mut t_schur = Vec::new();
        for _ in 0..reps {
            let t = Instant::now();
            for (i, yi) in y.iter_mut().enumerate() {
                let row = &smat[i * nb..(i + 1) * nb];
                *yi = row.iter().zip(&x).map(|(a, b)| a * b).sum();
            }
            std::hint::black_box(&y);
            t_schur.push(t.elapsed().as_secs_f64());
        }
        drop(smat);
        // forming S: n_b solves; timed on one block of 64 right-hand sides
        let t = Instant::now();
        let mut block = faer::Mat::<f64>::zeros(nf, 64);
        for j in 0..64 {
            block[(j * 7 % nf, j)] = 1.0;
        }
        let solve_block = {
            let mut ch = jointquake::linalg::SparseCholesky::factor(
                &jointquake::linalg::restrict(
                    &jointquake::linalg::stiffness_of(&m, |cell, _| m.massless_cells[cell]),
                    &jointquake::linalg::dof_map(3 * m.n_nodes(), |d| m.condensed[d / 3] & (1 << (d % 3)) != 0).0,
                    nf,
                    &jointquake::linalg::dof_map(3 * m.n_nodes(), |d| m.condensed[d / 3] & (1 << (d % 3)) != 0).0,
                    nf,
                ),
                "bench",
                faer::Par::Seq,
            )
            .unwrap();
            let t1 = Instant::now();
            ch.solve_mat_in_place(block.as_mut());
            t1.elapsed().as_secs_f64()
        };
        let _ = t;
        let form_s = solve_block / 64.0 * nb as f64;
        let mut f = vec![0.0; 3 * m.n_nodes()];
        let mut t_ku = Vec::new();
        for _ in 0..reps {
            let t = Instant::now();
            m.internal_forces_into(&u, &mut f);
            t_ku.push(t.elapsed().as_secs_f64());
        }
        let (sb, sm) = stats(t_solve);
        let (xb, xm) = stats(t_schur);
        let (kb, km) = stats(t_ku);
        let info = c.info(factor);
        println!(
            "{:>6} {:>9} {:>8} {:>11} {:>8.2}s {:>6.2}/{:>6.2} {:>6.2}/{:>6.2} {:>9.1}s {:>9.1} {:>5.2}/{:>5.2}",
            s, nf, nb, info.factor_entries, factor, 1e3 * sb, 1e3 * sm, 1e3 * xb, 1e3 * xm, form_s, (nb * nb * 8) as f64 / 1e6, 1e3 * kb, 1e3 * km
        );
        out.push(serde_json::json!({
            "case": s, "condensed_unknowns": nf, "interface_unknowns": nb, "factor_entries": info.factor_entries,
            "factor_s": factor, "solve_ms_best": 1e3 * sb, "solve_ms_median": 1e3 * sm,
            "schur_product_ms_best": 1e3 * xb, "schur_product_ms_median": 1e3 * xm, "schur_form_s_estimate": form_s,
            "schur_mb": (nb * nb * 8) as f64 / 1e6, "element_loop_ms_best": 1e3 * kb, "element_loop_ms_median": 1e3 * km,
        }));
    }
    std::fs::create_dir_all("target/bench").ok();
    std::fs::write("target/bench/foundation.json", serde_json::to_string_pretty(&out).unwrap()).ok();
    println!("(solve, S·u, K u: best/median; form S: n_b solves estimated from a 64-column block solve)");
}
