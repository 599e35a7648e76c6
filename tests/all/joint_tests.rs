//! Generated joint tests (`jointquake testcase`, src/testcase): a coarse subset of the matrix
//! of `make joint-tests` (pipelines/joint_tests_study.json, docs/validation.md §8) with the
//! measured errors as bounds. Each bound is about 1.25 × the measurement it names (so that a
//! regression of a quarter fails); every run also checks that the static solve converged.
//! References: the patch kind's uniform state (σzz = −p, σxz = τ, contact pressure p at every
//! slave node; ν = 0), s(t) = ½ g (sin β − μ cos β) t² for the slide, ρ c A v0 / 2 for 2L/c
//! for the impact (src/testcase/mod.rs).
use crate::common::{patch_errors, testcase};
use jointquake::testcase::run::{run_case, CaseResult, Errors};
use jointquake::testcase::{build, CaseSpec};
use serde_json::json;

/// [`testcase`], and for a patch on a flat joint global equilibrium: Σ r_n = p A (or ≈ 0 in
/// pure shear, relative to τ A); on a curved joint Σ r_n also depends on how the force splits
/// into normal and shear.
fn case(v: serde_json::Value) -> CaseResult {
    let r = testcase(v.clone());
    if let Errors::Patch { total, .. } = &r.errors {
        if v.get("curvature").is_none() {
            assert!(total.abs() < 1e-6, "{v}: Σ r_n off by {total:.2e}");
        }
    }
    r
}

/// Conforming joints pass exactly: hex 3×3 on 3×3 and tet 3×3 on 3×3, NTS and NTN.
/// Measured: σ 1.2e-10 (hex, both methods), 5.0e-10 (tet). Bound 1e-8 (the relaxation stops at
/// a residual of 1e-10).
#[test]
fn conforming_patch_is_exact() {
    for v in [
        json!({"kind": "patch", "lower": "hex8:3", "upper": "hex8:3"}),
        json!({"kind": "patch", "lower": "hex8:3", "upper": "hex8:3", "method": "ntn"}),
        json!({"kind": "patch", "lower": "tet4:3", "upper": "tet4:3"}),
    ] {
        let r = case(v);
        let (s, p, _) = patch_errors(&r);
        assert!(s < 1e-8 && p < 1e-8, "conforming patch: σ {s:.2e}, pressure {p:.2e}");
    }
}

/// Hex 4×4 on 3×3, pressure only (the CalculiX comparison case, 34 % for its node-to-face).
/// Measured σzz next to the joint: NTS finer slave 8.40 %, coarser slave 15.0 %, NTN 62.2 %
/// (docs/validation.md §2 gives the same three from the dynamic recipe: 8.4 %, 15.0 %, 12.4/62.3 %).
/// Bounds: NTS finer 0.105; the order finer < coarser < NTN.
#[test]
fn patch_4x4_over_3x3_orders_the_methods() {
    let base = json!({"kind": "patch", "lower": "hex8:4", "upper": "hex8:3"});
    let with = |k: &str, v: serde_json::Value| {
        let mut b = base.clone();
        b[k] = v;
        b
    };
    let finer = case(with("slave", json!("lower")));
    let coarser = case(with("slave", json!("upper")));
    let mut ntn = with("slave", json!("lower"));
    ntn["method"] = json!("ntn");
    let ntn = case(ntn);
    assert!(finer.error < 0.105, "NTS finer slave σzz {:.4}", finer.error);
    assert!(finer.error < coarser.error && coarser.error < ntn.error, "order: finer {:.4}, coarser {:.4}, NTN {:.4}", finer.error, coarser.error, ntn.error);
}

/// Tet over hex, 4×4 tets on 3×3 hexes, NTS with the finer (tet) side as slave.
/// Measured σzz 22.3 %; bound 0.28. Same grid, different face types (tet 3×3 on hex 3×3, nodes
/// coincide): 18.1 % whichever side is slave (no node-based method can pass it); bound 0.23.
#[test]
fn tet_over_hex_patch_within_measured_bounds() {
    let r = case(json!({"kind": "patch", "lower": "tet4:4", "upper": "hex8:3", "slave": "lower"}));
    assert!(r.error < 0.28, "tet4 4×4 on hex 3×3: σzz {:.4}", r.error);
    let r = case(json!({"kind": "patch", "lower": "tet4:3", "upper": "hex8:3", "slave": "lower"}));
    assert!(r.error < 0.23 && r.error > 0.05, "tet4 3×3 on hex 3×3: σzz {:.4}", r.error);
}

/// Mixed blocks (hex8 in the first ⌈N/2⌉ columns, Kuhn tets in the rest, one block; the joint
/// face half quads, half triangles). Reference: the uniform state, exact on conforming joints.
/// Measured: mixed 3×3 on mixed 3×3 (conforming, so the hex–tet faces inside each block are
/// exercised alone) σ 6.2e-10, bound 1e-8; mixed 4×4 slave on hex 3×3, NTS σzz 18.5 % (bound
/// 0.23), between hex/hex (8.40 %) and tet/hex (22.3 %) on the same grids.
#[test]
fn mixed_hex_tet_block_patch_within_measured_bounds() {
    let r = case(json!({"kind": "patch", "lower": "mixed:3", "upper": "mixed:3"}));
    let (s, p, _) = patch_errors(&r);
    assert!(s < 1e-8 && p < 1e-8, "conforming mixed patch: σ {s:.2e}, pressure {p:.2e}");
    let r = case(json!({"kind": "patch", "lower": "mixed:4", "upper": "hex8:3", "slave": "lower"}));
    assert!(r.error < 0.23 && r.error > 0.05, "mixed 4×4 on hex 3×3: σzz {:.4}", r.error);
}

/// Node alignment broken on equal meshes: the upper 3×3 hex side shifted by 0.3 of an element
/// (interior grid lines) or turned by 15° about the joint normal (inner half rigid), slave upper.
/// Reference: the uniform state (outline unchanged, so it is still exact). Measured: shift, NTS
/// σzz 19.6 % (bound 0.245), NTN 58.2 % (larger than NTS); turn, NTS 10.6 % (bound 0.13).
#[test]
fn offset_and_turned_meshes_within_measured_bounds() {
    let nts = case(json!({"kind": "patch", "lower": "hex8:3", "upper": "hex8:3", "offset": 0.3}));
    let ntn = case(json!({"kind": "patch", "lower": "hex8:3", "upper": "hex8:3", "offset": 0.3, "method": "ntn"}));
    assert!(nts.error < 0.245 && nts.error > 0.05, "offset 0.3 NTS σzz {:.4}", nts.error);
    assert!(ntn.error > nts.error, "offset 0.3: NTN {:.4} vs NTS {:.4}", ntn.error, nts.error);
    let r = case(json!({"kind": "patch", "lower": "hex8:3", "upper": "hex8:3", "rotate": 15.0}));
    assert!(r.error < 0.13 && r.error > 0.02, "turned 15° NTS σzz {:.4}", r.error);
}

/// Cylindrical joints (radius R = 1 m, axis along y: the lower block bulges 0.134 m into the
/// upper; slave nodes placed on the master's facets). Reference: the uniform σzz = −p, exactly
/// linear, so exact on conforming meshes whatever the shape; on the cylinder it is a normal
/// and a shear traction (σ n = −p n_z e_z), held by friction. Measured on the conforming hex
/// 3×3 joint: NTN 1.3e-10 (bound 1e-8), NTS 0.521 % (bound 0.0065; it falls as about 1/R²:
/// 0.146 % at R = 2 m, 0.031 % at 5 m, so it is the facet kink, 19° here, not the mesh
/// ratio); hex 4×4 slave on 3×3: NTS σ 8.28 % (bound 0.105), NTN 74.5 % (larger).
#[test]
fn cylindrical_joint_patch_within_measured_bounds() {
    let conf = json!({"kind": "patch", "lower": "hex8:3", "upper": "hex8:3", "curvature": 1.0});
    let mut ntn = conf.clone();
    ntn["method"] = json!("ntn");
    let r = case(ntn);
    assert!(r.error < 1e-8, "conforming cylinder NTN σ {:.3e}", r.error);
    let r = case(conf);
    assert!(r.error < 0.0065, "conforming cylinder NTS σ {:.4e}", r.error);
    let fine = json!({"kind": "patch", "lower": "hex8:4", "upper": "hex8:3", "slave": "lower", "curvature": 1.0});
    let nts = case(fine.clone());
    let mut n = fine;
    n["method"] = json!("ntn");
    let ntn = case(n);
    assert!(nts.error < 0.105 && ntn.error > nts.error, "cylinder 4×4 on 3×3: NTS {:.4}, NTN {:.4}", nts.error, ntn.error);
}

/// Issue 13 §3: a tied NTS interface between non-conforming meshes (hex 4×4 slave on 3×3)
/// passes a uniform stress with the error of NTS (measured σzz 8.40 %, bound 0.105) and a
/// uniform shear (pure shear τ = 1 MPa, p = 0, edge_tolerance 0.05: σ 5.89 %, shear traction
/// 18.0 %; bounds 0.074 and 0.225); the same next to a massless lower block (8.41 %; 5.83 %);
/// conforming pure shear with edge_tolerance 0.05: 0.173 % (bound 0.0022).
#[test]
fn tied_interface_passes_uniform_stress_and_shear() {
    let tied = json!({"kind": "patch", "lower": "hex8:4", "upper": "hex8:3", "slave": "lower", "tied": true});
    let r = case(tied.clone());
    assert!(r.error < 0.105, "tied pressure σzz {:.4}", r.error);
    let mut m = tied.clone();
    m["massless_lower"] = json!(true);
    let r = case(m);
    assert!(r.error < 0.105, "tied pressure on a massless block σzz {:.4}", r.error);
    let mut shear = tied.clone();
    shear["pressure"] = json!(0.0);
    shear["shear"] = json!(1e6);
    shear["edge_tolerance"] = json!(0.05);
    let r = case(shear.clone());
    let (s, _, t) = patch_errors(&r);
    assert!(s < 0.074 && t < 0.225, "tied pure shear: σ {s:.4}, shear traction {t:.4}");
    assert_eq!(r.lost, 0);
    let mut sm = shear.clone();
    sm["massless_lower"] = json!(true);
    let r = case(sm);
    let (s, _, t) = patch_errors(&r);
    assert!(s < 0.074 && t < 0.225, "tied pure shear on a massless block: σ {s:.4}, shear traction {t:.4}");
    let mut c = shear;
    c["lower"] = json!("hex8:3");
    c["slave"] = json!("upper");
    let r = case(c);
    assert!(r.error < 0.0022, "conforming tied pure shear σ {:.4e}", r.error);
}

/// Regression (found by the joint-test matrix, docs/validation.md §8): at the default
/// edge_tolerance (1e-3 of the master face size) the perimeter slave nodes of a tied joint in
/// pure shear were searched at their contact-free prediction, which leaves the master by
/// dt² F/m (about 8e-4 m here, against 5e-4 m of tolerance): they were lost and carried no
/// force (σ error 83 % on the conforming 3×3 joint). A tied pair now keeps the face it was tied
/// to. Reference: the uniform shear state, exact on a conforming joint; bound 0.0022 as for the
/// same joint with edge_tolerance 0.05 above (its measured 0.07–0.17 % is not yet explained).
#[test]
fn tied_pure_shear_keeps_perimeter_nodes_at_the_default_edge_tolerance() {
    let r = case(json!({"kind": "patch", "lower": "hex8:3", "upper": "hex8:3", "tied": true, "pressure": 0.0, "shear": 1e6}));
    assert_eq!(r.lost, 0, "lost node-steps on a tied joint");
    assert!(r.error < 0.0022, "conforming tied pure shear at the default edge tolerance: σ {:.4e}", r.error);
}

/// Slide: hex 4/m slider on a hex 2/m base at β = 30°, μ = 0.3, 1 s: measured +0.096 %
/// (docs/validation.md §4 gives +0.085 % on its fixture); bound 0.0012. Impact of two bars with
/// non-matching cross-sections (2×2 on 3×3): plateau mean −(1.5e-4), min/max within 0.9 %;
/// bounds 2e-4 and 2 % (the validation's tolerance).
#[test]
fn slide_and_impact_match_their_references() {
    let r = case(json!({"kind": "slide"}));
    assert!(r.error < 0.0012, "slide slip error {:.4e}", r.error);
    let r = case(json!({"kind": "impact", "lower": "hex8:2:100", "upper": "hex8:3:100"}));
    assert!(r.error < 2e-4, "impact plateau mean {:.3e}", r.error);
    if let Errors::Impact { force_min, force_max, duration, .. } = r.errors {
        assert!(force_min.abs() < 0.02 && force_max.abs() < 0.02 && duration.abs() < 0.02, "impact plateau [{force_min}, {force_max}], duration {duration}");
    }
}

/// The slide case with extra supports (scene `boundary` entries) added to its base support.
fn slide_with_supports(extra: serde_json::Value) -> CaseResult {
    let spec: CaseSpec = serde_json::from_value(json!({"kind": "slide"})).expect("case spec");
    let mut c = build(&spec).expect("case builds");
    let bc = c.scene["boundary"].as_array_mut().expect("the slide has a base support");
    bc.extend(extra.as_array().expect("a list of supports").iter().cloned());
    let r = run_case(&c).expect("case runs");
    println!("supports {extra}: error {:.4e} ({}), {:?}, lost {}", r.error, r.error_of, r.errors, r.lost);
    r
}

/// Issue 19: a block whose slave nodes were fixed in y (a symmetry plane) did not slide — any
/// fixed component made a node immovable for the contact force, the pairs took no force, the
/// block sank into its base and the run stopped at step 10 with "energy balance lost". The
/// free components now take the contact force. Reference: the rigid block on the incline,
/// s(t) = ½ g (sin β − μ cos β) t² (β = 30°, μ = 0.3, 1 s: 1.1781 m); tolerance 0.0012, the
/// bound of the unconstrained slide above (its measured +0.096 %): fixing y on the sliding
/// face or on the block's y = 0.25 m side leaves the rigid-body slide unchanged, only the
/// block's elastic response differs. Measured: slave face fixed in y +0.081 %, the block's
/// side face fixed in y +0.098 %.
#[test]
fn partly_fixed_slave_nodes_slide_on_an_incline_with_a_symmetry_plane() {
    for extra in [json!([{"group": "upper:z0", "fix": ["y"]}]), json!([{"group": "upper:y0", "fix": ["y"]}])] {
        let r = slide_with_supports(extra.clone());
        assert_eq!(r.lost, 0, "{extra}: lost node-steps");
        assert!(r.error < 0.0012, "{extra}: slide slip error {:.4e}", r.error);
    }
}

/// The master side: the base's master face fixed in y (its nodes partly fixed), alone and with
/// the slave face fixed in y too. Same reference and tolerance as above. (Before the fix such
/// master nodes counted as fully fixed: on this stiff base that still slid, so this test guards
/// the master path rather than reproducing the failure.) Measured: +0.096 %, +0.074 %.
#[test]
fn partly_fixed_master_nodes_carry_a_sliding_block() {
    for extra in [json!([{"group": "lower:z1", "fix": ["y"]}]), json!([{"group": "lower:z1", "fix": ["y"]}, {"group": "upper:z0", "fix": ["y"]}])] {
        let r = slide_with_supports(extra.clone());
        assert_eq!(r.lost, 0, "{extra}: lost node-steps");
        assert!(r.error < 0.0012, "{extra}: slide slip error {:.4e}", r.error);
    }
}

/// A slope across the free components: the slide case with its slave face fixed in x (the
/// slope rises along x, so the slave nodes can move in y and z only and the block cannot slide:
/// it is held). The pairs' normal and slip direction are at 30° to the free components, where
/// one pair update leaves part of its own residual; with the repeated updates of such pairs
/// (`PARTIAL_PAIR_UPDATES`) every step converges (measured: at most 163 sweeps; with one update
/// per sweep 359 of the 2295 steps stopped at the 200-sweep cap). Checked over 0.2 s: no lost
/// node, no unconverged step, no penetration beyond round-off (measured 2.1e-22 m; bound
/// 1e-12 m), and the block stays put (peak |u| measured 2.9e-6 m, the elastic settling of a
/// 1e10 Pa block; bound 1e-4 m, against 0.047 m of free sliding at 0.2 s).
#[test]
fn partly_fixed_slave_nodes_across_the_slope_hold_the_block_with_converged_sweeps() {
    use jointquake::problem::Problem;
    use jointquake::simulation::Simulation;
    let spec: CaseSpec = serde_json::from_value(json!({"kind": "slide", "duration": 0.2})).expect("case spec");
    let mut c = build(&spec).expect("case builds");
    c.scene["boundary"].as_array_mut().unwrap().push(json!({"group": "upper:z0", "fix": ["x"]}));
    let scene: jointquake::scene::Scene = serde_json::from_value(c.scene.clone()).unwrap();
    let pb = Problem::build(scene, c.mesh.clone()).unwrap();
    let mut sim = Simulation::new(&pb).unwrap();
    let (mut peak, mut penetration) = (0.0f64, 0.0f64);
    for _ in 0..sim.n_steps() {
        sim.step().expect("the step runs");
        peak = sim.state.u.iter().fold(peak, |m, v| m.max(v.abs()));
        penetration = sim.state.contact.joints[0].pairs.iter().filter(|p| p.gap.is_finite()).fold(penetration, |m, p| m.max(-p.gap));
    }
    let j = &sim.state.contact.joints[0];
    println!("peak |u| {peak:.3e} m, penetration {penetration:.2e} m, max sweeps {}, unconverged {}", j.max_sweeps, j.unconverged_steps);
    assert_eq!(j.events.lost, 0);
    assert_eq!(j.unconverged_steps, 0, "max sweeps {}, residual up to {:.2e} m", j.max_sweeps, j.max_gs_residual);
    assert!(penetration < 1e-12, "penetration {penetration:.3e} m");
    assert!(peak < 1e-4, "the block moved {peak:.3e} m");
}

/// Bad options name the option and the fix.
#[test]
fn bad_testcase_options_are_named() {
    let e = serde_json::from_value::<CaseSpec>(json!({"kind": "patch", "lower": "hex9:4"})).unwrap_err().to_string();
    assert!(e.contains("ELEMENT:N"), "{e}");
    let spec: CaseSpec = serde_json::from_value(json!({"kind": "patch", "shear": 7e5})).unwrap();
    let e = build(&spec).err().expect("τ ≥ μ p is refused").to_string();
    assert!(e.contains("`shear`") && e.contains("tied"), "{e}");
    let spec: CaseSpec = serde_json::from_value(json!({"kind": "patch", "curvature": 0.6, "mu": 0.3})).unwrap();
    let e = build(&spec).err().expect("μ below the cylinder's slope is refused").to_string();
    assert!(e.contains("`curvature`") && e.contains("slope"), "{e}");
    let spec: CaseSpec = serde_json::from_value(json!({"kind": "patch", "upper": "hex8:10", "rotate": 45.0})).unwrap();
    let e = build(&spec).err().expect("an inverted element is refused").to_string();
    assert!(e.contains("`rotate`") && e.contains("inside out"), "{e}");
    let spec: CaseSpec = serde_json::from_value(json!({"kind": "slide", "slave": "lower"})).unwrap();
    assert!(build(&spec).err().unwrap().to_string().contains("`slave`"));
    let spec: CaseSpec = serde_json::from_value(json!({"kind": "patch", "lower": "hex8:200:200", "upper": "hex8:200:200"})).unwrap();
    assert!(build(&spec).err().unwrap().to_string().contains("million"));
}

/// `write_case` writes a mesh the reader takes back with the joint's groups, and a scene that
/// `Scene::load` accepts.
#[test]
fn written_case_reads_back() {
    let spec: CaseSpec = serde_json::from_value(json!({"kind": "patch", "lower": "tet4:4", "upper": "hex8:3", "inclination": 20.0})).unwrap();
    let c = build(&spec).unwrap();
    let dir = crate::common::scratch("testcase_written");
    let f = jointquake::testcase::write_case(&c, &dir).unwrap();
    let m = jointquake::mesh::Mesh::from_msh(&f.msh).unwrap();
    assert_eq!(m.nodes.len(), c.mesh.nodes.len());
    assert_eq!(m.group("lower:z1").unwrap().cells.len(), 32);
    assert_eq!(m.group("upper:z0").unwrap().cells.len(), 9);
    jointquake::scene::Scene::load(&f.scene).expect("the written scene loads");
}
