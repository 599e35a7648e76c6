//! Issue 17 §2: why the FEM wedge with cohesion kept slides several times as far as the rigid
//! block, and further as the wedge stiffens (docs/wedge_mechanism.md).
//!
//! The mechanism pinned here: while the elastic wedge slides, it rattles on its bed (pairs
//! open and close hundreds of times a second); the friction part of the joint resistance,
//! μ Σ r_n, is held by the wedge's equilibrium whatever the number of pairs that carry it, but
//! the cohesive part is c A only on the pairs closed at that instant. The rigid block carries c
//! on the whole area. Driven by the cohesion the FEM pairs actually carried (the opt-in force
//! diagnostic `output.joint_forces`), the rigid block slides as far as the FEM wedge.
use crate::common::{fixture, scratch};
use jointquake::dynamics::loads::{base_motions, ground_acceleration_of};
use jointquake::output::joints::{read_joint_forces, JointForcesRow};
use jointquake::rigid::wedge::{analyse_wedge, build_wedge, wedge_seismic_coeffs, WedgeInput};
use jointquake::scene::Scene;
use jointquake::studies::wedge::report::PointHistory;
use serde_json::json;
use std::path::{Path, PathBuf};

/// A constant horizontal ground acceleration of `a` g towards north (+y), ramped up over 0.1 s
/// from t = 0.1 s, sampled at 0.01 s to 2 s.
fn step_record(path: &Path, a: f64) {
    let mut s = String::from("# ramp to a constant acceleration, tests/all/wedge_mechanism.rs\n");
    for i in 0..=200 {
        let t = i as f64 * 0.01;
        let v = if t < 0.1 { 0.0 } else { a * ((t - 0.1) / 0.1).min(1.0) };
        s.push_str(&format!("{t:.2} {v}\n"));
    }
    std::fs::write(path, s).unwrap();
}

/// The seed wedge on the coarse fixture, cohesion kept on both joints (seed table 1, no
/// softening), rigid rock, the wedge's modulus `e_wedge`, under `record` for `duration` s, with
/// the force diagnostic on. Returns the scene file and the output directory.
fn run_wedge(dir: &Path, name: &str, record: &Path, e_wedge: f64, duration: f64) -> (PathBuf, PathBuf) {
    let v = json!({
        "name": name,
        "geometry": {"msh": fixture("wedge_coarse.msh")},
        "materials": [
            {"group": "block:wedge", "E": e_wedge, "nu": 0.25, "rho": 2563},
            {"group": "block:rock", "E": 1e10, "nu": 0.25, "rho": 2563}
        ],
        "boundary": [{"group": "bc:fixed"}, {"group": "block:rock"}],
        "loads": {"gravity": {"groups": ["block:wedge"]}, "base": [{"record": record, "direction": [0, 1, 0], "scale": 1.0}]},
        "joints": [
            {"name": "A", "master": "joint:A:rock", "slave": "joint:A:wedge", "phi": 20, "cohesion": 24000, "keep_cohesion": true},
            {"name": "B", "master": "joint:B:rock", "slave": "joint:B:wedge", "phi": 30, "cohesion": 48000, "keep_cohesion": true}
        ],
        "time": {"duration": duration},
        "output": {"frames": false, "joint_forces": true, "monitor": [
            {"name": "P2w", "point": [-12.398, 30.278, 19.812], "group": "block:wedge"},
            {"name": "P2r", "point": [-12.398, 30.278, 19.812], "group": "block:rock"}
        ]}
    });
    let sp = dir.join(format!("{name}.json"));
    std::fs::write(&sp, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    let out = dir.join(name);
    let opts = jointquake::pipeline::RunOptions { out_dir: Some(out.clone()), ..Default::default() };
    jointquake::pipeline::run(&sp, &opts).unwrap();
    (sp, out)
}

/// Residual slip at P2 down the line of intersection [m] (as the wedge study defines it).
fn p2_slip(out: &Path) -> f64 {
    let h = |n: &str| PointHistory::read(&out.join(format!("histories/{n}.csv"))).unwrap();
    let (w, r) = (h("P2w"), h("P2r"));
    let e = build_wedge(&WedgeInput::default()).unwrap().e;
    let s = |i: usize| (0..3).map(|k| (w.u[i][k] - r.u[i][k]) * e[k]).sum::<f64>();
    s(w.t.len() - 1) - s(0)
}

/// The rigid block (one-way Newmark along the line of intersection, horizontal ground
/// acceleration along +y only) with the cohesive force `cohesion(t)` [N] in place of the
/// limit-equilibrium c_A A_A + c_B A_B. Explicit integration at 1e-4 s of
/// s'' = r0 + rh kh(t) + (C_full − C(t)) / m while sliding or while that is > 0, v ≥ 0 (checked
/// against the closed form with C = C_full below).
fn rigid_slip_with_cohesion(scene: &Scene, duration: f64, cohesion: &dyn Fn(f64) -> f64) -> f64 {
    let w = WedgeInput::default();
    let c = wedge_seismic_coeffs(&w, 0.0, true).unwrap();
    let g = analyse_wedge(&w).unwrap().geometry;
    let c_full = w.joint_a.cohesion * g.area_a + w.joint_b.cohesion * g.area_b;
    let (motions, _) = base_motions(scene).unwrap();
    let h = 1e-4;
    let (mut v, mut d) = (0.0f64, 0.0f64);
    for k in 0..(duration / h).round() as usize {
        let t = k as f64 * h;
        let kh = ground_acceleration_of(&motions, t)[1] / scene.g;
        let r = c.r0() + c.rh() * kh + (c_full - cohesion(t)) / c.mass;
        if v > 0.0 || r > 0.0 {
            let v2 = (v + r * h).max(0.0);
            d += 0.5 * (v + v2) * h;
            v = v2;
        }
    }
    d
}

/// The cohesive force carried by both joints' pairs at time t [N], linear between rows.
fn carried_cohesion(a: &[JointForcesRow], b: &[JointForcesRow]) -> impl Fn(f64) -> f64 {
    let ts: Vec<f64> = a.iter().map(|r| r.t).collect();
    let c: Vec<f64> = a.iter().zip(b).map(|(x, y)| x.cohesion + y.cohesion).collect();
    move |t| {
        let i = ts.partition_point(|&x| x <= t);
        if i == 0 {
            c[0]
        } else if i >= ts.len() {
            c[c.len() - 1]
        } else {
            let f = (t - ts[i - 1]) / (ts[i] - ts[i - 1]);
            c[i - 1] * (1.0 - f) + c[i] * f
        }
    }
}

#[test]
fn cohesive_wedge_slides_as_the_rigid_block_with_the_cohesion_its_pairs_carry() {
    // Load: 0.5 g towards north, constant after a 0.1 s ramp (no vertical), 1.5 s: above the
    // rigid block's critical 0.354 g, so both slide from about 0.17 s, and the input itself has
    // no frequency content that could rattle the wedge. Reference: the rigid block
    // (limit-equilibrium coefficients of `rigid::wedge`, closed form for this load) with full
    // cohesion, and the same block with the cohesion the FEM pairs carried at each instant.
    // Measured (coarse fixture, on the commit of this test): rigid block 1.536 m; FEM
    // E = 10 GPa 3.720 m, rigid block with the FEM's carried cohesion 3.713 m (−0.2 %);
    // E = 100 GPa 4.126 m and 4.123 m (−0.1 %). After 0.3 s the pairs closed are 29 % / 10 %
    // of joints A / B at E and 22 % / 7 % at 10 E, the mean cohesion carried 19 % and 14 % of
    // c A, with 65 and 196 open/close transitions per pair and second. (Medium mesh: FEM
    // 3.995 m, rigid block with its carried cohesion 3.985 m; docs/wedge_mechanism.md.)
    // Tolerances: the FEM slides more than twice the full-cohesion rigid block (the issue's
    // discrepancy, here 2.4–2.7×); driven by the carried cohesion the rigid block is within 3 %
    // of the FEM at both stiffnesses (the mechanism accounts for the whole difference); the
    // carried cohesion while sliding is below half of c A and falls as the wedge stiffens (the
    // rattling grows with the wedge's frequencies, so a stiffer wedge moves away from the rigid
    // block).
    let dir = scratch("wedge_mechanism/step");
    let rec = dir.join("step05.txt");
    step_record(&rec, 0.5);
    let duration = 1.5;
    let w = WedgeInput::default();
    let g = analyse_wedge(&w).unwrap().geometry;
    let c_full = w.joint_a.cohesion * g.area_a + w.joint_b.cohesion * g.area_b;
    let mut carried_while_sliding = Vec::new();
    let mut fem = Vec::new();
    for (name, e) in [("e1", 1e10), ("e10", 1e11)] {
        let (sp, out) = run_wedge(&dir, name, &rec, e, duration);
        let scene = Scene::load(&sp).unwrap();
        let slip = p2_slip(&out);
        let a = read_joint_forces(&out.join("histories/joint_A_forces.csv")).unwrap();
        let b = read_joint_forces(&out.join("histories/joint_B_forces.csv")).unwrap();
        assert_eq!(a.len(), b.len());
        let coh = carried_cohesion(&a, &b);
        // the integrator against the closed form of the full-cohesion rigid block at t = 1.5 s
        // (0.5 %): kh = 5 (t − 0.1) on the ramp, so sliding starts at t0 = 0.1 + kc / 5 with
        // s'' = 5 rh (t − t0) until 0.2 s, then s'' = r0 + 0.5 rh
        let c = wedge_seismic_coeffs(&w, 0.0, true).unwrap();
        let t0 = 0.1 + c.critical_horizontal_acceleration().unwrap() / 5.0;
        let tau = 0.2 - t0;
        let (v1, d1, r1, rest) = (2.5 * c.rh() * tau * tau, 5.0 / 6.0 * c.rh() * tau.powi(3), c.r0() + 0.5 * c.rh(), duration - 0.2);
        let exact = d1 + v1 * rest + 0.5 * r1 * rest * rest;
        let full = rigid_slip_with_cohesion(&scene, duration, &|_| c_full);
        assert!((full - exact).abs() < 5e-3 * exact, "integrator {full} vs closed form {exact}");
        let with_fem = rigid_slip_with_cohesion(&scene, duration, &coh);
        // while sliding (the rigid block slides from 0.17 s on; FEM rows from 0.3 s)
        let sliding: Vec<(&JointForcesRow, &JointForcesRow)> = a.iter().zip(&b).filter(|(x, _)| x.t > 0.3).collect();
        let mean_coh = sliding.iter().map(|(x, y)| x.cohesion + y.cohesion).sum::<f64>() / sliding.len() as f64 / c_full;
        let (na, nb) = (34.0, 33.0); // slave nodes of joints A and B on the coarse fixture
        let closed_a = sliding.iter().map(|(x, _)| x.closed as f64).sum::<f64>() / sliding.len() as f64 / na;
        let closed_b = sliding.iter().map(|(_, y)| y.closed as f64).sum::<f64>() / sliding.len() as f64 / nb;
        let dt_rows = a[1].t - a[0].t;
        let transitions = sliding.iter().map(|(x, y)| (x.transitions + y.transitions) as f64).sum::<f64>() / (sliding.len() as f64 * dt_rows) / (na + nb);
        eprintln!(
            "E = {e:.0e} Pa: FEM slip {slip:.4} m; rigid block {exact:.4} m (full cohesion), {with_fem:.4} m with the FEM's carried cohesion ({:+.1} %); while sliding: closed A {:.0} %, B {:.0} %, cohesion carried {:.0} % of c A, {transitions:.0} open/close transitions per pair and second",
            100.0 * (with_fem / slip - 1.0),
            100.0 * closed_a,
            100.0 * closed_b,
            100.0 * mean_coh
        );
        assert!(slip > 2.0 * exact, "E {e}: FEM {slip} m against the rigid block's {exact} m: the discrepancy of issue 17 is gone (update docs/wedge_mechanism.md)");
        assert!((with_fem - slip).abs() < 0.03 * slip, "E {e}: rigid block with the carried cohesion {with_fem} m vs FEM {slip} m");
        assert!(mean_coh < 0.5, "E {e}: cohesion carried while sliding {mean_coh} of c A");
        assert!(transitions > 10.0, "E {e}: {transitions} transitions per pair and second: no rattling");
        carried_while_sliding.push(mean_coh);
        fem.push(slip);
    }
    assert!(carried_while_sliding[1] < carried_while_sliding[0], "a stiffer wedge carries less cohesion while sliding: {carried_while_sliding:?}");
    assert!(fem[1] > fem[0], "a stiffer wedge slides further: {fem:?}");
}
