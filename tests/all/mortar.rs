//! Dual mortar contact (issue 31; src/contact/mortar, docs/contact.md "Dual mortar"): the flat
//! patch test on the joint-test matrix's mesh pairs, momentum, and the kinds of
//! `jointquake testcase` with `method: "mortar"`.
//! References: the patch kind's uniform state (σzz = −p, σxz = τ, contact pressure p at every
//! slave node; ν = 0; src/testcase/mod.rs). Mortar integrates the constraint exactly over the
//! overlaps (degree-5 rule, exact for the parallelogram faces of these meshes), so the patch
//! test passes to the round-off of the static solve (it stops at ‖M a‖/‖F‖ < 1e-10).
use crate::common::{patch_errors, testcase as case};
use jointquake::testcase::run::Errors;
use serde_json::json;

/// The flat patch test, pressure only, on the matrix's non-conforming pairs, either side slave.
/// Bound: 1e-6 relative on σ next to the joint and on the contact pressure (issue 31).
#[test]
fn mortar_patch_pressure_passes_on_every_mesh_pair() {
    let mut worst: f64 = 0.0;
    for (lower, upper, slave) in HEX_TET_PAIRS.into_iter().chain(MIXED_PAIRS) {
        let r = case(json!({"kind": "patch", "lower": lower, "upper": upper, "slave": slave, "method": "mortar"}));
        let (s, p, _) = patch_errors(&r);
        worst = worst.max(s).max(p);
        assert!(s < 1e-6 && p < 1e-6, "{lower}/{upper} slave {slave}: σ {s:.2e}, pressure {p:.2e}");
    }
    println!("worst {worst:.2e}");
}

/// Two free, non-conforming blocks (tet 4 × 4 below, hex 3 × 3 above, shifted so that the
/// mortar weights couple each slave node to up to 16 master nodes), no support, no damping, no
/// gravity, pushed together by a traction on the top face only: the total momentum
/// Σ m (u[n+1] − u[n]) / dt grows by exactly dt F per step (the elastic forces sum to zero), so
/// after n steps it is n dt F whatever the contact does, if and only if the contact forces on
/// slave and master sides are equal and opposite (mortar weights Σ_k M_jk / D_jj = 1).
/// Reference: Newton's third law; tolerance 1e-9 of n dt |F| (round-off of the sums over
/// 10³ nodes and 400 steps).
#[test]
fn mortar_contact_conserves_momentum() {
    use jointquake::mesh::structured::{add_box, BoxSpec};
    use jointquake::mesh::Mesh;
    use jointquake::problem::Problem;
    use jointquake::simulation::Simulation;
    let mut mesh = Mesh { source: "<momentum>".into(), nodes: vec![], node_tags: vec![], cells: vec![], groups: vec![] };
    add_box(&mut mesh, &BoxSpec::new("lower", [1.0, 1.0, 0.5], [4, 4, 2]).tets(true).at([0.0, 0.0, -0.5]));
    add_box(&mut mesh, &BoxSpec::new("upper", [0.8, 0.8, 0.5], [3, 3, 2]).at([0.13, 0.07, 0.0]));
    let sc: jointquake::scene::Scene = serde_json::from_value(json!({
        "geometry": {"msh": "unused.msh"},
        "materials": [{"group": "block:lower", "E": 1e9, "nu": 0.25, "rho": 2000.0},
                      {"group": "block:upper", "E": 1e9, "nu": 0.25, "rho": 2000.0}],
        "boundary": [],
        "joints": [{"name": "J", "master": "lower:z1", "slave": "upper:z0", "mu": 0.3, "method": "mortar"}],
        "loads": {"traction": [{"group": "upper:z1", "traction": [2e5, -1e5, -1e6]}]},
        "time": {"duration": 1.0, "energy_tolerance": 1.0}
    }))
    .unwrap();
    let problem = Problem::build(sc, mesh).unwrap();
    let mut sim = Simulation::new(&problem).unwrap();
    let dt = sim.dt();
    let steps = 400;
    for _ in 0..steps {
        sim.step().unwrap();
    }
    let st = &sim.state;
    let pairs = st.contact.joints[0].pairs.iter().filter(|p| p.r_n > 0.0).count();
    assert!(pairs > 0, "no pair in contact");
    let mass = &problem.model.mass.inertial;
    let mut p = [0.0; 3];
    for (n, m) in mass.iter().enumerate() {
        for c in 0..3 {
            p[c] += m * (st.u[3 * n + c] - st.u_prev[3 * n + c]) / dt;
        }
    }
    let f = [2e5 * 0.64, -1e5 * 0.64, -1e6 * 0.64];
    let scale = steps as f64 * dt * 1e6 * 0.64;
    for c in 0..3 {
        let want = steps as f64 * dt * f[c];
        println!("momentum {c}: {:.12e} vs {want:.12e} ({pairs} pairs in contact)", p[c]);
        assert!((p[c] - want).abs() < 1e-9 * scale, "momentum component {c}: {} vs n dt F = {want}", p[c]);
    }
}

/// The mesh pairs of the joint-test matrix with a mixed side (lower, upper, slave side).
const MIXED_PAIRS: [(&str, &str, &str); 4] = [("mixed:4", "hex8:3", "lower"), ("mixed:4", "hex8:3", "upper"), ("hex8:4", "mixed:3", "lower"), ("mixed:4", "mixed:3", "lower")];

/// The mesh pairs of the joint-test matrix (lower, upper, slave side) without a mixed side.
const HEX_TET_PAIRS: [(&str, &str, &str); 9] = [
    ("hex8:3", "hex8:3", "upper"),
    ("hex8:4", "hex8:3", "lower"),
    ("hex8:4", "hex8:3", "upper"),
    ("hex8:7", "hex8:5", "lower"),
    ("hex8:7", "hex8:5", "upper"),
    ("tet4:4", "hex8:3", "lower"),
    ("tet4:4", "hex8:3", "upper"),
    ("tet4:4", "tet4:3", "lower"),
    ("tet4:3", "hex8:3", "lower"),
];

/// Pressure and shear (p = 1 MPa, τ = 0.3 MPa) through a tied mortar joint on every hex and tet
/// pair of the matrix, either side slave: the tie holds the material points that the mortar
/// integrals of the first step pair (the integrals are kept while nothing slides), so the
/// uniform state passes. Bound 1e-6 of max(p, |τ|) on σ next to the joint (issue 31; measured
/// ≤ 7.8e-7, hex 4/3 slave lower) and 2e-6 on the force of each slave node (measured ≤ 1.4e-6,
/// tet 4/3). Mixed sides are left out: a conforming mixed 3/3 block pair tied node to node
/// misses uniform shear by 2 % too (the mesh's hex–tet columns, not the joint), checked below
/// to be the same with mortar. The frictional joint (μ = 0.6) on the proportional load path
/// measures 1.5e-4 on hex 4/3 (bound 2.5e-4): p and τ ramped together from zero, the pairs carry
/// shear at nearly zero pressure in the first steps and slip (μ = 10 gives 5.2e-5, conforming
/// NTS with μ = 0.6 6.6e-5): the loading path, not the mortar integrals; on the pressure-first
/// path it passes (`mortar_frictional_shear_patch_passes_pressure_first`).
#[test]
fn mortar_patch_shear_passes_on_every_hex_and_tet_pair() {
    let mut worst: (f64, f64) = (0.0, 0.0);
    for (lower, upper, slave) in HEX_TET_PAIRS {
        let v = json!({"kind": "patch", "lower": lower, "upper": upper, "slave": slave, "shear": 3e5, "tied": true, "method": "mortar"});
        let r = case(v.clone());
        let (s, p, t) = patch_errors(&r);
        println!("MEASURED {v}: σ {s:.3e}, pressure {p:.3e}, shear {t:.3e}");
        worst = (worst.0.max(s), worst.1.max(p).max(t));
        assert!(s < 1e-6 && p < 2e-6 && t < 2e-6, "{v}: σ {s:.2e}, pressure {p:.2e}, shear {t:.2e}");
    }
    println!("worst σ {:.2e}, node force {:.2e}", worst.0, worst.1);
    let friction = case(json!({"kind": "patch", "lower": "hex8:4", "upper": "hex8:3", "slave": "lower", "shear": 3e5, "method": "mortar"}));
    assert!(friction.error < 2.5e-4, "frictional shear σ {:.3e}", friction.error);
    let mixed = |method: &str| case(json!({"kind": "patch", "lower": "mixed:3", "upper": "mixed:3", "slave": "upper", "shear": 3e5, "tied": true, "method": method})).error;
    let (ntn, mortar) = (mixed("ntn"), mixed("mortar"));
    assert!((mortar - ntn).abs() < 1e-6 * ntn, "conforming mixed shear: mortar {mortar:.6e} vs node-to-node {ntn:.6e}");
}

/// Frictional shear (μ = 0.6, p = 1 MPa, τ = 0.3 MPa < μ p) on the pressure-first load path
/// (`pressure_first`: p relaxed to equilibrium, then τ ramped in at full p), on every hex and
/// tet pair of the matrix. Reference: the patch's uniform state; on this path a joint with
/// |τ| < μ p sticks throughout, so the frictional joint must pass as the tied one does. Bound
/// 1e-6 of max(p, |τ|) on σ next to the joint (issue 31; measured 3.6e-10 to 2.7e-7), except
/// tet 4/3 slave lower: 2.571e-6, which a tied joint on the same path gives to the digit (and
/// to 5.7e-7 on the proportional path): the static solve's path with a tie on that pair, not
/// friction; that pair is held to 1.25 × its measurement and to the tied run within 1e-6 of it.
/// The proportional path on hex 4/3 is checked to stay above 1e-5 (measured 1.49e-4), so the
/// option is what makes the difference.
#[test]
fn mortar_frictional_shear_patch_passes_pressure_first() {
    let mut worst: f64 = 0.0;
    for (lower, upper, slave) in HEX_TET_PAIRS {
        let v = json!({"kind": "patch", "lower": lower, "upper": upper, "slave": slave, "shear": 3e5, "mu": 0.6, "pressure_first": true, "method": "mortar"});
        let r = case(v.clone());
        let (s, _, _) = patch_errors(&r);
        println!("MEASURED {v}: σ {s:.3e}");
        if (lower, upper, slave) == ("tet4:4", "tet4:3", "lower") {
            let mut tied = v.clone();
            tied["tied"] = json!(true);
            let t = patch_errors(&case(tied)).0;
            assert!(s < 1.25 * 2.571e-6 && (s - t).abs() < 1e-6 * t, "{v}: σ {s:.3e}, tied on the same path {t:.3e}");
            continue;
        }
        worst = worst.max(s);
        assert!(s < 1e-6, "{v}: σ {s:.2e}");
    }
    println!("worst σ {worst:.2e}");
    let proportional = case(json!({"kind": "patch", "lower": "hex8:4", "upper": "hex8:3", "slave": "lower", "shear": 3e5, "method": "mortar"}));
    assert!(proportional.error > 1e-5, "the proportional path passes too ({:.3e}): the pressure-first option no longer matters", proportional.error);
    // the option needs shear (without it the two paths are one) and the patch kind
    for bad in [json!({"kind": "patch", "pressure_first": true}), json!({"kind": "slide", "pressure_first": true})] {
        let spec: jointquake::testcase::CaseSpec = serde_json::from_value(bad.clone()).unwrap();
        assert!(spec.resolved().is_err(), "{bad} accepted");
    }
}

/// The dynamic kinds with mortar against the NTS figures of docs/validation.md §8 (bounds 1.25 ×
/// those): the block sliding down a 30° incline, s(t) = ½ g (sin β − μ cos β) t² (NTS 0.096 %
/// hex, 0.091 % tet, 0.083 % shifted), the rigid Newmark block under El Centro at 0.5 g (NTS
/// 2.06 %), and the two-bar impact, plateau force ρ c A v0 / 2 (NTS 0.0153 % on hex 2 × 2 against
/// 3 × 3), whose contact must create no energy (contact work ≤ 1e-9 of the bar's kinetic energy).
#[test]
fn mortar_slide_newmark_and_impact_within_the_nts_errors() {
    for (v, bound) in [
        (json!({"kind": "slide", "method": "mortar"}), 1.25 * 0.096e-2),
        (json!({"kind": "slide", "upper": "tet4:4:2", "method": "mortar"}), 1.25 * 0.0914e-2),
        (json!({"kind": "slide", "offset": 0.3, "method": "mortar"}), 1.25 * 0.0833e-2),
        (json!({"kind": "newmark", "method": "mortar"}), 1.25 * 2.06e-2),
        (json!({"kind": "impact", "lower": "hex8:2:100", "upper": "hex8:3:100", "method": "mortar"}), 1.25 * 0.0153e-2),
    ] {
        let r = case(v.clone());
        assert!(r.error < bound, "{v}: error {:.3e} above the NTS bound {bound:.3e}", r.error);
        if let Errors::Impact { contact_work, .. } = r.errors {
            assert!(contact_work < 1e-9, "{v}: the contact created energy: work {contact_work:.3e} of the initial kinetic energy");
        }
    }
}

/// The cylindrical joint's three levels: hex 4/3 with 2 element layers per block, 8/6 with 4,
/// 16/12 with 8 (every size halved: self-similar meshes), the finer lower side slave.
const CYL_LEVELS: [(&str, &str); 3] = [("hex8:4:2", "hex8:3:2"), ("hex8:8:4", "hex8:6:4"), ("hex8:16:8", "hex8:12:8")];
/// Measured on those levels (4 Dec 2026; [σ next to the joint, u L2] per level), mortar and NTS,
/// slave nodes on the master's facets and both sides' nodes on the cylinder.
const CYL_MORTAR_FACETS: [[f64; 2]; 3] = [[2.904e-3, 5.440e-3], [1.959e-3, 1.342e-3], [1.158e-3, 3.285e-4]];
const CYL_MORTAR_ON: [[f64; 2]; 3] = [[4.741e-3, 4.745e-3], [2.387e-3, 1.174e-3], [1.380e-3, 2.874e-4]];
const CYL_NTS_FACETS: [[f64; 2]; 3] = [[8.275e-2, 3.519e-2], [9.389e-2, 1.072e-2], [9.747e-2, 3.575e-3]];
const CYL_NTS_ON: [[f64; 2]; 3] = [[8.459e-2, 3.860e-2], [9.652e-2, 1.152e-2], [9.879e-2, 3.787e-3]];
/// Bound of the conforming cylinder's σ error (measured 1.3e-10, the static solve's residual).
const CONFORMING_CYL: f64 = 1e-8;

/// [σ next to the joint, u L2] of the cylindrical patch (R = 1 m) on the three levels.
fn cylinder_levels(method: &str, slave_on_cylinder: bool) -> Vec<[f64; 2]> {
    CYL_LEVELS
        .iter()
        .map(|(lower, upper)| {
            let r = case(json!({"kind": "patch", "lower": lower, "upper": upper, "slave": "lower", "curvature": 1.0, "method": method, "slave_on_cylinder": slave_on_cylinder}));
            match r.errors {
                Errors::Patch { stress_joint, displacement_l2, .. } => [stress_joint, displacement_l2],
                e => panic!("not a patch: {e:?}"),
            }
        })
        .collect()
}

/// The cylindrical joint (R = 1 m, axis along y) under refinement, issue 31's check "error
/// converging as O(h²)". Reference: the patch kind's uniform state σzz = −p, exact on the
/// cylinder too, with its linear displacement u = −(p/E)(z + H) e_z, which is exact on the
/// meshed (faceted) geometry as well, so any error is the joint's (src/testcase/mod.rs). Two
/// geometries: the slave's joint nodes on the master's facets (the testcase's default), and both
/// sides' nodes on the exact cylinder (`slave_on_cylinder`, as a mesher puts them; the two
/// faceted surfaces then differ by the chords' sags at every level). Either way the two sides
/// are different faceted surfaces O(h²/R) apart, grouted on the initial configuration.
///
/// What converges at second order is the **displacement** (the lumped-mass L2 norm of u −
/// u_exact over the nodes / max |u_exact|), the quantity of the mortar theory for linear
/// elements (Wohlmuth 2000: L2 displacement O(h²), energy norm O(h)) and the one a joint's
/// opening and slip, the dam's outputs, are made of. Measured 5.44e-3, 1.34e-3, 3.29e-4 (facets)
/// and 4.75e-3, 1.17e-3, 2.87e-4 (on the cylinder): observed orders 2.02, 2.03 and 2.01, 2.03.
/// The tie of the linear exact field leaves n · ∇u (x̄_j − x_j) at each node (x̄_j the mortar
/// image of the slave node, O(h²/R) off it): a displacement jump O(p h²/(E R)), hence a strain
/// error O(h/R) in the elements at the joint: the σ error next to the joint converges at first
/// order at best (facets 2.90e-3, 1.96e-3, 1.16e-3: orders 0.57, 0.76; on the cylinder
/// 4.74e-3, 2.39e-3, 1.38e-3: 0.99, 0.79), the order of linear elements' stresses in general.
/// NTS beside it, same levels: σ 8.3, 9.4, 9.7 % and 8.5, 9.7, 9.9 % (not converging), u L2
/// 3.5e-2, 1.1e-2, 3.6e-3 (orders 1.71, 1.58) and 3.9e-2, 1.2e-2, 3.8e-3 (1.74, 1.60).
/// Bounds: each error 1.25 × measured; mortar's L2 displacement orders within [1.8, 2.2] (the
/// theory's 2; not tuned: both geometries gave 2.01–2.03), its σ orders within [0.4, 1.3]
/// (first order, the geometric error above). The conforming cylinder is exact (the coincident
/// faces give M_jk = D_jj δ_jk: a node-to-node tie).
#[test]
fn mortar_cylindrical_joint_displacements_converge_at_second_order() {
    let order = |a: f64, b: f64| (a / b).log2();
    let runs = [("mortar", false, CYL_MORTAR_FACETS), ("mortar", true, CYL_MORTAR_ON), ("nts", false, CYL_NTS_FACETS), ("nts", true, CYL_NTS_ON)];
    for (method, on, measured) in runs {
        let e = cylinder_levels(method, on);
        let (s, u): (Vec<f64>, Vec<f64>) = e.iter().map(|x| (x[0], x[1])).unzip();
        let sci = |v: &[f64]| v.iter().map(|x| format!("{x:.4e}")).collect::<Vec<_>>().join(", ");
        println!("MEASURED cylinder {method} slave on cylinder {on}: σ {} (orders {:.2}, {:.2}), u L2 {} (orders {:.2}, {:.2})", sci(&s), order(s[0], s[1]), order(s[1], s[2]), sci(&u), order(u[0], u[1]), order(u[1], u[2]));
        for (got, m) in e.iter().zip(measured) {
            assert!(got[0] < 1.25 * m[0] && got[1] < 1.25 * m[1], "{method} on {on}: [σ, u L2] {e:?} above 1.25 × {measured:?}");
        }
        if method == "mortar" {
            for k in 0..2 {
                let (os, ou) = (order(s[k], s[k + 1]), order(u[k], u[k + 1]));
                assert!((1.8..=2.2).contains(&ou), "mortar on {on}: u L2 order {ou:.2} outside [1.8, 2.2] ({u:?})");
                assert!((0.4..=1.3).contains(&os), "mortar on {on}: σ order {os:.2} outside [0.4, 1.3] ({s:?})");
            }
        }
    }
    // the conforming cylinder: coincident faces give M = D (biorthogonality), a node-to-node tie
    let r = case(json!({"kind": "patch", "lower": "hex8:3", "upper": "hex8:3", "curvature": 1.0, "method": "mortar"}));
    assert!(r.error < CONFORMING_CYL, "conforming cylinder mortar σ {:.3e}", r.error);
}

/// Static stages on mortar joints (issue 31): the coarse dam (pipelines/dam_coarse.json, the
/// construction sequence) with its contraction joints `method: "mortar"`. Stage c pairs each
/// slave node with its mortar master point and area D_jj (`statics::contact`), grouting closes
/// the mortar weighted gap (`statics::sequence::grout_pairs`), so the dynamic stage starts from
/// the static state of its own pairs. Released at rest with the full reservoir and no record for
/// 0.2 s, the crown must stay (drift below 1 mm) and the energy balance hold to 1e-9, as for
/// NTS and NTN (tests/all/dam.rs, `dam_released_at_rest`).
#[test]
fn mortar_dam_static_state_stays_at_rest() {
    super::dam::dam_released_at_rest("mortar", 0.2);
}

/// The coarse dam (pipelines/dam_coarse.json) with the joints whose name `mortar` takes in
/// `method: "mortar"` (the scene's joints as loaded: J01 … J28 and the tied "base").
fn dam_mortar_problem(mortar: impl Fn(&str) -> bool) -> jointquake::problem::Problem {
    let (mut s, mesh) = crate::common::dam_coarse_scene();
    for j in s.joints.iter_mut().filter(|j| mortar(&j.name)) {
        j.method = Some(jointquake::scene::ContactMethod::Mortar);
    }
    jointquake::problem::Problem::build(s, mesh).unwrap()
}

/// The construction sequence's stages a (self-weight, joints open, base tied), b (grouting) and
/// c (the reservoir with the joints active) on `pb`: the total displacement after c and c's
/// report.
fn dam_static_stages(pb: &jointquake::problem::Problem) -> (Vec<f64>, jointquake::statics::contact::StaticContactInfo) {
    let (u, _) = jointquake::statics::sequence::self_weight_open_joints(pb).unwrap();
    let mut f = vec![0.0; u.len()];
    for &(n, fv) in &pb.loads.static_forces {
        for c in 0..3 {
            f[3 * n + c] += fv[c];
        }
    }
    let mut contact = jointquake::contact::ContactState::new(&pb.joints);
    jointquake::statics::sequence::grout(pb, &mut contact, &u).unwrap();
    let (du, info) = jointquake::statics::contact::solve_static_increment(pb, &f, &mut contact, jointquake::statics::contact::PENALTY_FACTOR).unwrap();
    (u.iter().zip(&du).map(|(a, b)| a + b).collect(), info)
}

/// The largest displacement of the crest's nodes [m] and the crown's radial (y) one.
fn crest_numbers(pb: &jointquake::problem::Problem, u: &[f64]) -> (f64, f64) {
    let crest = pb.model.mesh.group_nodes("face:crest").unwrap();
    let largest = crest.iter().map(|&n| (0..3).map(|c| u[3 * n + c] * u[3 * n + c]).sum::<f64>().sqrt()).fold(0.0, f64::max);
    let crown = crest.iter().copied().min_by(|&a, &b| pb.model.mesh.x(a)[0].abs().total_cmp(&pb.model.mesh.x(b)[0].abs()).then(pb.model.mesh.x(b)[2].total_cmp(&pb.model.mesh.x(a)[2]))).unwrap();
    (largest, u[3 * crown + 1])
}

/// Review item of issue 31: the static stage c builds one contact solver per static solve for
/// the mortar master points of all its mortar joints (scratch only), not one per joint. On the
/// coarse dam with its contraction joints in mortar: (1) one solver asked for every joint in turn
/// gives each joint's master points and areas bit for bit as a fresh solver per joint does (the
/// scratch carries nothing from one joint to the next); (2) stage c's static table with joint
/// J01 in mortar is the one measured before the change (code of main at bb78b6e): 14 Newton
/// iterations, pairs stick 1004 / slip 103 / open 15, crest's largest displacement
/// 5.016140172894090e-2 m, crown uy 5.016000594835923e-2 m; tolerance 1e-9 relative and the
/// same pair states (measured at bb78b6e with the same arithmetic to 1e-12; since then stage c
/// refactorises its preconditioner by a cost rule, branch `static`, which changes the Newton
/// path, 11 iterations instead of 14, and the table by 6.5e-13: the static tables of that
/// change agree within 4e-10, so 1e-9 keeps the check on the mortar points' reuse without
/// pinning the linear solver's path). On 5 December the static law's stick spring became
/// k_t = 0.1 k tangentially (`statics::contact::STICK_TANGENTIAL`, it was k): the same pair
/// states, the crest's largest displacement 5.016140172894090e-2 → 5.017304471606503e-2 m and
/// the crown's uy 5.016000594835923e-2 → 5.017164326258328e-2 m (+2.3e-4, the softer stick's
/// compliance); the values below are those. The table with all 28 contraction joints in mortar
/// is printed (docs/contact.md).
#[test]
fn mortar_static_stage_reuses_one_contact_solver() {
    use jointquake::contact::force::ContactSolver;
    let pb = dam_mortar_problem(|n| n != "base");
    let model = &pb.model;
    let contact = jointquake::contact::ContactState::new(&pb.joints);
    let zero = vec![0.0; 3 * model.n_nodes()];
    let mut shared = ContactSolver::new(model, &pb.joints);
    let mut joints = 0;
    for ji in (0..pb.joints.len()).filter(|&ji| pb.joints[ji].method == jointquake::contact::joint::Method::Mortar) {
        let a = shared.mortar_master_points(model, ji, &contact.joints[ji], &zero).unwrap();
        let b = ContactSolver::new(model, &pb.joints).mortar_master_points(model, ji, &contact.joints[ji], &zero).unwrap();
        assert_eq!(a, b, "joint {ji}: a shared solver's master points differ from a fresh one's");
        joints += 1;
    }
    assert_eq!(joints, 28);
    let t = std::time::Instant::now();
    let (u, info) = dam_static_stages(&pb);
    let (largest, crown) = crest_numbers(&pb, &u);
    println!("MEASURED all 28 joints mortar: {} ; crest largest {largest:.6e} crown uy {crown:.6e}; stages a–c {:.2} s wall", info.line(), t.elapsed().as_secs_f64());
    let pb = dam_mortar_problem(|n| n == "J01");
    let (u, info) = dam_static_stages(&pb);
    let (largest, crown) = crest_numbers(&pb, &u);
    println!("MEASURED J01 mortar: {} ; crest largest {largest:.15e} crown uy {crown:.15e}", info.line());
    assert!(info.converged, "{}", info.line());
    assert_eq!((info.stick, info.slip, info.open), (1004, 103, 15), "{}", info.line());
    assert!((largest / 5.017304471606503e-2 - 1.0).abs() < 1e-9, "crest {largest:.15e}");
    assert!((crown / 5.017164326258328e-2 - 1.0).abs() < 1e-9, "crown {crown:.15e}");
}

/// Tied mortar in the construction sequence (issue 31): the coarse dam with its contraction
/// joints in mortar and its tied base in mortar too (the dam–rock interface bonded by the dual
/// mortar tie in stages a and c, `statics::bonding`) against the same dam with the base tied node
/// to segment. Reference: the node-to-segment tie's static table (crest's largest displacement,
/// crown uy). Tolerance: 1 % of the crest displacement; both ties transmit the base's forces, and
/// differ in how each slave node's force reaches the rock, an error the patch tests put at 5–8 %
/// of the local stress next to the base for NTS, whose effect on the crest is far smaller.
#[test]
fn mortar_tied_base_static_table_is_near_the_node_to_segment_ties() {
    let nts = dam_mortar_problem(|n| n != "base");
    let mortar = dam_mortar_problem(|_| true);
    let model = &mortar.model;
    let base: Vec<&jointquake::contact::joint::ContactJoint> = mortar.joints.iter().filter(|j| j.law.tied).collect();
    let ties = jointquake::statics::bonding::Bonding::build(model, &base, |d| model.is_free(d / 3, d % 3)).unwrap().info;
    println!("MEASURED the base's mortar tie: {ties:?}");
    assert!(base.len() == 1 && ties.mortar > 0, "{ties:?}");
    let (u0, i0) = dam_static_stages(&nts);
    let (u1, i1) = dam_static_stages(&mortar);
    let (l0, c0) = crest_numbers(&nts, &u0);
    let (l1, c1) = crest_numbers(&mortar, &u1);
    println!("MEASURED base tied nts: {} ; crest largest {l0:.6e} crown uy {c0:.6e}", i0.line());
    println!("MEASURED base tied mortar: {} ; crest largest {l1:.6e} crown uy {c1:.6e}; differences {:.3e} {:.3e}", i1.line(), l1 / l0 - 1.0, c1 / c0 - 1.0);
    assert!(i1.converged, "{}", i1.line());
    assert!((l1 / l0 - 1.0).abs() < 1e-2 && (c1 / c0 - 1.0).abs() < 1e-2, "crest {l1:.6e} vs {l0:.6e}, crown {c1:.6e} vs {c0:.6e}");
}

/// The static σ error of a tied patch case `v` (pressure and shear) solved directly with its joint
/// bonded (`statics::sequence::linear_static`: the tie eliminated, one Cholesky): the largest
/// |σ_ij − σ_ij exact| / max(p, |τ|) over every element, and the bonding's report.
fn bonded_patch_error(v: serde_json::Value) -> (f64, jointquake::statics::bonding::TieInfo) {
    let spec: jointquake::testcase::CaseSpec = serde_json::from_value(v).unwrap();
    let case = jointquake::testcase::build(&spec).unwrap();
    let scene: jointquake::scene::Scene = serde_json::from_value(case.scene.clone()).unwrap();
    let pb = jointquake::problem::Problem::build(scene, case.mesh.clone()).unwrap();
    let mut f = vec![0.0; 3 * pb.model.n_nodes()];
    for p in &pb.loads.patterns {
        for &(n, fv) in &p.forces {
            for c in 0..3 {
                f[3 * n + c] += fv[c];
            }
        }
    }
    let (u, residual, t) = jointquake::statics::sequence::linear_static(&pb, &[&pb.joints[0]], &f).unwrap();
    assert!(residual < 1e-10, "residual {residual:.2e}");
    let mut stress = Vec::new();
    pb.model.element_stress_into(&u, &mut stress);
    let exact = jointquake::testcase::patch_stress(&case.spec);
    let s_ref = case.spec.pressure.max(case.spec.shear.abs());
    let err = stress.iter().map(|s| (0..6).map(|i| (s[i] - exact[i]).abs()).fold(0.0, f64::max)).fold(0.0, f64::max) / s_ref;
    (err, t.info)
}

/// Tied mortar joints in the static bonding (issue 31): a tied flat patch with non-matching
/// meshes under pressure and shear (p = 1 MPa, τ = 0.3 MPa), solved directly with the tie
/// eliminated, transmits the uniform state exactly. Reference: the patch kind's uniform σ
/// (src/testcase/mod.rs); the dual mortar tie u_s = Σ c_k u_k reproduces a linear field exactly
/// on a flat joint (Σ_k M_jk x_k = D_jj x_j by biorthogonality). Bound 1e-6 of max(p, τ) on σ
/// over every element (issue 31). Control: the same cases tied node to segment (the bonding's
/// rule for the other methods) miss by percents (hex 4/3: 8.40 % σzz in the dynamic matrix), so
/// the bound tells the two ties apart. The mixed slave is loaded by pressure only: in shear a
/// mixed block's hex–tet columns miss by 2 % whatever the joint (docs/validation.md §8; measured
/// here 1.48e-2 with the mortar tie).
#[test]
fn tied_mortar_patch_passes_in_the_static_bonding() {
    for (lower, upper, slave, shear) in [("hex8:4", "hex8:3", "lower", 3e5), ("hex8:3", "hex8:4", "upper", 3e5), ("hex8:7", "hex8:5", "lower", 3e5), ("tet4:4", "hex8:3", "lower", 3e5), ("hex8:3", "tet4:4", "upper", 3e5), ("mixed:4", "hex8:3", "lower", 0.0)] {
        let v = |method: &str| json!({"kind": "patch", "lower": lower, "upper": upper, "slave": slave, "shear": shear, "tied": true, "method": method});
        let (err, info) = bonded_patch_error(v("mortar"));
        let (err_nts, _) = bonded_patch_error(v("nts"));
        println!("MEASURED bonded tied patch {lower}/{upper} slave {slave}: mortar σ {err:.3e} ({} of {} slave nodes by mortar), nts {err_nts:.3e}", info.mortar, info.tied);
        assert!(info.mortar == info.tied && info.mortar > 0, "{info:?}");
        assert!(err < 1e-6, "{lower}/{upper}: mortar tie σ error {err:.3e}");
        assert!(err_nts > 1e-3, "{lower}/{upper}: the node-to-segment tie is not the control it should be: {err_nts:.3e}");
    }
}
