//! Bad input through the library (`pipeline::run`, `pipeline::tag`): every error must NAME the
//! culprit (key, group, file, element, line, value) and say what to fix. Scenes are written into
//! scratch directories and point at the committed fixtures by absolute path.
use crate::common::{assert_mentions, column_scene, fixture, run_error_at, scratch, write_scene_in};
use jointquake::mesh::Mesh;
use jointquake::model::Model;
use jointquake::pipeline::{run, tag, RunOptions};
use jointquake::scene::Scene;
use serde_json::{json, Value};
use std::path::PathBuf;

/// Write `scene` as `<scratch(bad_input/test)>/scene.json`; returns (scene path, scratch dir).
fn write_scene(test: &str, scene: &Value) -> (PathBuf, PathBuf) {
    write_scene_in(&format!("bad_input/{test}"), scene)
}

/// The error message of `run` on `scene` (which must fail).
fn run_error(test: &str, scene: &Value) -> String {
    let (p, dir) = write_scene(test, scene);
    run_error_at(test, &p, &dir)
}

#[test]
fn control_the_base_scene_runs() {
    // Guards the tests below: each breaks exactly one thing in a scene that runs.
    let (p, dir) = write_scene("control", &column_scene());
    let opts = RunOptions { out_dir: Some(dir.join("out")), ..Default::default() };
    let s = run(&p, &opts).expect("the unbroken scene runs");
    assert!(s.steps > 0);
}

#[test]
fn unknown_scene_key_is_named() {
    let mut s = column_scene();
    s["dampng"] = json!({"ratio": 0.05});
    let msg = run_error("unknown_key", &s);
    assert_mentions(&msg, &["unknown field `dampng`", "`damping`", "docs/scenes.md", "scene.json"]);
}

#[test]
fn unknown_key_in_a_nested_section_is_named() {
    let mut s = column_scene();
    s["time"]["durration"] = json!(1.0);
    let msg = run_error("unknown_nested_key", &s);
    assert_mentions(&msg, &["unknown field `durration`", "`duration`"]);
}

#[test]
fn unknown_material_group_is_named_with_the_available_ones() {
    let mut s = column_scene();
    s["materials"][0]["group"] = json!("block:colum");
    let msg = run_error("unknown_material_group", &s);
    assert_mentions(&msg, &["\"block:colum\"", "Groups in the mesh", "\"block:column\" (dim 3)", "\"bc:base\""]);
}

#[test]
fn unknown_boundary_group_is_named() {
    let mut s = column_scene();
    s["boundary"][0]["group"] = json!("bc:bottom");
    let msg = run_error("unknown_boundary_group", &s);
    assert_mentions(&msg, &["\"bc:bottom\"", "Groups in the mesh", "\"bc:base\""]);
}

#[test]
fn missing_record_names_the_path() {
    let mut s = column_scene();
    s["loads"] = json!({"base": [{"record": "records/no_such_record.txt", "direction": [1, 0, 0]}]});
    let (p, dir) = write_scene("missing_record", &s);
    let msg = run(&p, &RunOptions { out_dir: Some(dir.join("out")), ..Default::default() }).unwrap_err().to_string();
    // relative record paths are resolved against the scene's directory, and the message shows the result
    let want = dir.join("records/no_such_record.txt");
    assert_mentions(&msg, &[&want.display().to_string(), "Check the `record` path"]);
}

/// Tag of the one tet4 of `block:upper` whose nodes differ between boxes_tet.msh and
/// inverted_tet.msh (found by comparison, so the test does not depend on the number).
fn altered_element() -> u64 {
    let a = Mesh::from_msh(fixture("boxes_tet.msh")).unwrap();
    let b = Mesh::from_msh(fixture("inverted_tet.msh")).unwrap();
    let g = b.group("block:upper").unwrap();
    let changed: Vec<u64> = g.cells.iter().filter(|&&c| a.cells[c].nodes() != b.cells[c].nodes()).map(|&c| b.cells[c].tag).collect();
    assert_eq!(changed.len(), 1, "exactly one element is altered: {changed:?}");
    changed[0]
}

#[test]
fn inverted_element_is_named_with_its_group() {
    let s = json!({
        "geometry": {"msh": fixture("inverted_tet.msh")},
        "materials": [
            {"group": "block:lower", "E": 30e9, "nu": 0.2, "rho": 2400},
            {"group": "block:upper", "E": 30e9, "nu": 0.2, "rho": 2400}
        ],
        "boundary": [{"group": "bc:base"}],
        "time": {"duration": 0.001}
    });
    let msg = run_error("inverted", &s);
    let tag = altered_element();
    assert_eq!(tag, 405, "tests/fixtures/README.md documents element 405");
    assert_mentions(&msg, &["inverted_tet.msh", &format!("element {tag} is inverted"), "\"block:upper\"", "ReverseMesh"]);
}

#[test]
fn time_step_above_the_limit_quotes_the_limit_and_the_critical_element() {
    let mut s = column_scene();
    s["time"]["dt"] = json!(1.0);
    // a duration of at least dt / 2, so that the step is refused for its stability and not for
    // taking no step (`a_time_step_above_twice_the_duration_is_refused`)
    s["time"]["duration"] = json!(1.0);
    let msg = run_error("dt_unstable", &s);
    // the reference: the model's own stable step and critical element
    let scene: Scene = serde_json::from_value(column_scene()).unwrap();
    let model = Model::build(Mesh::from_msh(fixture("column_hex.msh")).unwrap(), &scene).unwrap();
    let limit = format!("{:.4e} s", model.stable_dt());
    assert_mentions(
        &msg,
        &["dt = 1.0000e0 s", &format!("stability limit {limit}"), &format!("critical element {}", model.critical.tag), "\"block:column\"", "\"courant\""],
    );
}

#[test]
fn malformed_msh_names_the_file() {
    let mut s = column_scene();
    s["geometry"]["msh"] = json!(fixture("malformed.msh"));
    let msg = run_error("malformed_msh", &s);
    assert_mentions(&msg, &[&fixture("malformed.msh").display().to_string(), "not a valid MSH 4.1 file", "-format msh41"]);
}

#[test]
fn missing_msh_names_the_file() {
    let mut s = column_scene();
    s["geometry"]["msh"] = json!("meshes/not_there.msh");
    let (p, dir) = write_scene("missing_msh", &s);
    let msg = run(&p, &RunOptions { out_dir: Some(dir.join("out")), ..Default::default() }).unwrap_err().to_string();
    assert_mentions(&msg, &["cannot read mesh file", &dir.join("meshes/not_there.msh").display().to_string(), "`geometry.msh`"]);
}

/// A scene on the column with a base record written into the scratch dir.
fn record_error(test: &str, record: &str) -> (String, PathBuf) {
    let dir = scratch(&format!("bad_input/{test}"));
    let rec = dir.join("record.txt");
    std::fs::write(&rec, record).unwrap();
    let mut s = column_scene();
    s["loads"] = json!({"base": [{"record": rec, "direction": [1, 0, 0]}]});
    let p = dir.join("scene.json");
    std::fs::write(&p, s.to_string()).unwrap();
    let msg = run(&p, &RunOptions { out_dir: Some(dir.join("out")), ..Default::default() }).unwrap_err().to_string();
    (msg, rec)
}

#[test]
fn record_with_uneven_steps_names_the_line() {
    // line 1 is a comment; the third sample (line 4) comes 0.015 s after the second
    let (msg, rec) = record_error("uneven_record", "# t [s]  a [g]\n0 0\n0.01 0.1\n0.025 0.2\n0.03 0\n");
    assert_mentions(&msg, &[&rec.display().to_string(), "line 4", "uneven time step", "Resample"]);
}

#[test]
fn record_with_a_non_finite_value_names_the_line_and_value() {
    let (msg, rec) = record_error("nan_record", "0 0\n0.01 0.1\n0.02 NaN\n0.03 0\n");
    assert_mentions(&msg, &[&rec.display().to_string(), "line 3", "NaN", "Replace it with a number"]);
}

#[test]
fn courant_above_one_is_refused() {
    let mut s = column_scene();
    s["time"]["courant"] = json!(1.5);
    let msg = run_error("courant", &s);
    assert_mentions(&msg, &["time.courant = 1.5", "must be in (0, 1]"]);
}

/// `time.mass_scaling.target_dt` must be a positive finite step [s]: 0 and a negative value are
/// refused naming the field (NaN cannot be written in JSON; the check `> 0 && finite` covers it
/// for scenes built in code), as is a missing `target_dt` and an unknown key in the section; a
/// target the mass-proportional damping alone forbids (target/courant ≥ 2/α) is refused at the
/// build, naming the field and 2/α.
#[test]
fn mass_scaling_target_dt_must_be_positive() {
    for (k, v) in [json!(0.0), json!(-1e-5)].into_iter().enumerate() {
        let mut s = column_scene();
        s["time"]["mass_scaling"] = json!({"target_dt": v});
        let msg = run_error(&format!("mass_scaling_{k}"), &s);
        assert_mentions(&msg, &["time.mass_scaling.target_dt", "must be positive and finite [s]"]);
    }
    let mut s = column_scene();
    s["time"]["mass_scaling"] = json!({});
    assert_mentions(&run_error("mass_scaling_missing", &s), &["missing field `target_dt`"]);
    s["time"]["mass_scaling"] = json!({"target_dt": 1e-5, "factor": 2});
    assert_mentions(&run_error("mass_scaling_unknown", &s), &["unknown field `factor`", "`target_dt`"]);
    let mut s = column_scene();
    s["damping"] = json!({"alpha": 1000.0});
    s["time"]["mass_scaling"] = json!({"target_dt": 0.9 * 0.002});
    assert_mentions(&run_error("mass_scaling_alpha", &s), &["time.mass_scaling.target_dt", "2/α = 2.0000e-3 s"]);
    // NaN, in a scene built in code: refused by the scene's check and by the model build
    let mut sc: Scene = serde_json::from_value(column_scene()).unwrap();
    sc.time.mass_scaling = Some(jointquake::scene::MassScalingSpec { target_dt: f64::NAN });
    assert_mentions(&sc.validate().unwrap_err(), &["time.mass_scaling.target_dt = NaN", "must be positive and finite"]);
    let e = Model::build(Mesh::from_msh(fixture("column_hex.msh")).unwrap(), &sc).err().expect("refused").to_string();
    assert_mentions(&e, &["time.mass_scaling.target_dt", "positive and finite"]);
}

#[test]
fn boundary_component_other_than_xyz_is_named() {
    let mut s = column_scene();
    s["boundary"][0]["fix"] = json!(["x", "w"]);
    let msg = run_error("component", &s);
    assert_mentions(&msg, &["boundary \"bc:base\"", "component \"w\"", "\"x\", \"y\" or \"z\""]);
}

/// Scene on the 4x3 boxes with one joint, for `tag`.
fn boxes_scene(master: &str, slave: &str) -> Value {
    json!({
        "geometry": {"msh": fixture("boxes_hex_4x3.msh")},
        "materials": [
            {"group": "block:lower", "E": 30e9, "nu": 0.2, "rho": 2400},
            {"group": "block:upper", "E": 30e9, "nu": 0.2, "rho": 2400}
        ],
        "time": {"duration": 0.0},
        "joints": [{"name": "J", "master": master, "slave": slave}]
    })
}

fn tag_error(test: &str, scene: &Value) -> String {
    let (p, dir) = write_scene(test, scene);
    match tag(&p, &RunOptions { out_dir: Some(dir.join("out")), ..Default::default() }) {
        Ok(_) => panic!("{test}: tagging should fail"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn unknown_joint_group_is_named_with_the_available_ones() {
    let msg = tag_error("tag_unknown_group", &boxes_scene("joint:J:lowr", "joint:J:upper"));
    assert_mentions(&msg, &["joint \"J\"", "\"joint:J:lowr\"", "Groups in the mesh", "\"joint:J:lower\" (dim 2)"]);
}

#[test]
fn tag_without_joints_says_what_to_add() {
    let mut s = boxes_scene("a", "b");
    s["joints"] = json!([]);
    let msg = tag_error("tag_no_joints", &s);
    assert_mentions(&msg, &["no joints to tag", "`joints`", "docs/scenes.md"]);
}

#[test]
fn tag_with_a_tolerance_too_small_names_the_far_node() {
    // A master group that does not face the slave: bc:base is the bottom of the lower box
    // (z = -0.5 m), the slave joint:J:upper lies on z = 0, so every slave node is 0.5 m away.
    let mut s = boxes_scene("bc:base", "joint:J:upper");
    s["joints"][0]["tolerance"] = json!(1e-3);
    let msg = tag_error("tag_far", &s);
    assert_mentions(&msg, &["joint \"J\"", "\"joint:J:upper\"", "\"bc:base\"", "tolerance 1.000e-3 m", "5.000000e-1 m from the master surface", "raise the tolerance"]);
}

/// Issue 19: a joint whose master and slave are faces of the same block (here the lower box's
/// top face and its base, with a tolerance that lets every slave node reach the master) passed
/// `tag`, and `run` then blamed "penalty contact" for an nts joint. Both now refuse it up
/// front, naming the joint, the two groups and the fix.
#[test]
fn joint_with_master_and_slave_on_the_same_block_is_named() {
    let mut s = boxes_scene("joint:J:lower", "bc:base");
    s["joints"][0]["tolerance"] = json!(1.0);
    let parts = ["joint \"J\"", "\"joint:J:lower\"", "\"bc:base\"", "same block", "a face group of each block"];
    assert_mentions(&tag_error("tag_same_block", &s), &parts);
    s["boundary"] = json!([{"group": "bc:base"}]);
    s["time"] = json!({"duration": 0.001});
    s["output"] = json!({"frames": false});
    let msg = run_error("run_same_block", &s);
    assert_mentions(&msg, &parts);
    assert!(!msg.contains("penalty"), "{msg}");
}

#[test]
fn duplicate_joint_file_names_are_refused() {
    let mut s = boxes_scene("joint:J:lower", "joint:J:upper");
    s["joints"] = json!([
        {"name": "J/1", "master": "joint:J:lower", "slave": "joint:J:upper"},
        {"name": "J_1", "master": "joint:J:lower", "slave": "joint:J:upper"}
    ]);
    let msg = tag_error("tag_duplicate_names", &s);
    assert_mentions(&msg, &["joint \"J_1\"", "J_1.vtu", "\"J/1\"", "distinct names"]);
}

#[test]
fn material_on_a_face_group_says_a_volume_group_is_needed() {
    let mut s = column_scene();
    s["materials"][0]["group"] = json!("bc:base");
    let msg = run_error("material_on_faces", &s);
    assert_mentions(&msg, &["\"bc:base\" has dimension 2", "a volume group (tet4/hex8 elements) of dimension 3 is needed", "\"block:column\" (dim 3)"]);
}

#[test]
fn record_with_non_monotonic_time_names_the_line() {
    // the fourth sample (line 4) goes back in time
    let (msg, rec) = record_error("backwards_record", "0 0\n0.01 0.1\n0.02 0.2\n0.015 0\n");
    assert_mentions(&msg, &[&rec.display().to_string(), "line 4", "time 0.015 does not increase", "previous 0.02"]);
}

#[test]
fn record_with_a_text_value_names_the_line_and_value() {
    let (msg, rec) = record_error("text_record", "0 0\n0.01 O.1\n");
    assert_mentions(&msg, &[&rec.display().to_string(), "line 2", "acceleration `O.1` is not a number"]);
}

/// A PEER AT2 record through a whole scene: read (NGA header), scaled, and quoted in the notes.
/// Reference: the file's own 5 values and DT; `pga` 0.5 over the file's peak 0.4 g.
#[test]
fn peer_at2_record_runs_through_a_scene() {
    let dir = scratch("bad_input/at2_ok");
    let rec = dir.join("RSN1_TEST.AT2");
    std::fs::write(&rec, "PEER NGA STRONG MOTION DATABASE RECORD\nTEST 1/1/2000, STATION, 000\nACCELERATION TIME SERIES IN UNITS OF G\nNPTS=    5, DT=   .0100 SEC\n  .1000000E+00 -.4000000E+00  .2000000E+00\n  .0000000E+00  .1000000E+00\n").unwrap();
    let mut s = column_scene();
    s["loads"] = json!({"base": [{"record": rec, "direction": [0, 1, 0], "pga": 0.5}]});
    let p = dir.join("scene.json");
    std::fs::write(&p, s.to_string()).unwrap();
    let summary = run(&p, &RunOptions { out_dir: Some(dir.join("out")), ..Default::default() }).expect("the AT2 scene runs");
    assert!(summary.notes.iter().any(|n| n.contains("RSN1_TEST.AT2: 5 samples, dt 0.01 s, PGA 0.4000 g × 1.2500")), "{:?}", summary.notes);
}

/// A bad AT2 file: a value that is not a number or not finite names the line (header lines
/// count: data start on line 5), and a sample count that differs from NPTS gives both counts.
#[test]
fn peer_at2_record_errors_name_the_line_or_the_counts() {
    let head = "PEER NGA STRONG MOTION DATABASE RECORD\nx\nACCELERATION TIME SERIES IN UNITS OF G\nNPTS=    4, DT=   .0100 SEC\n";
    for (test, body, parts) in [
        ("at2_nan", "  .1 .2\n  NaN .3\n", vec!["line 6", "non-finite value `NaN`"]),
        ("at2_text", "  .1 .2\n  .3 x.4\n", vec!["line 6", "`x.4` is not a number"]),
        ("at2_count", "  .1 .2 .3\n", vec!["NPTS = 4 but 3 values"]),
    ] {
        let dir = scratch(&format!("bad_input/{test}"));
        let rec = dir.join("r.at2");
        std::fs::write(&rec, format!("{head}{body}")).unwrap();
        let mut s = column_scene();
        s["loads"] = json!({"base": [{"record": rec, "direction": [1, 0, 0]}]});
        let p = dir.join("scene.json");
        std::fs::write(&p, s.to_string()).unwrap();
        let msg = run(&p, &RunOptions { out_dir: Some(dir.join("out")), ..Default::default() }).unwrap_err().to_string();
        let mut all = vec![rec.display().to_string()];
        all.extend(parts.iter().map(|x| x.to_string()));
        assert_mentions(&msg, &all.iter().map(String::as_str).collect::<Vec<_>>());
    }
}

#[test]
fn unsupported_element_type_is_named() {
    // one 6-node prism (Gmsh type 6) in a volume group: jointquake reads tet4/hex8 only
    let text = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n\
        $PhysicalNames\n1\n3 1 \"block:p\"\n$EndPhysicalNames\n\
        $Entities\n0 0 0 1\n1 0 0 0 1 1 1 1 1 0\n$EndEntities\n\
        $Nodes\n1 6 1 6\n3 1 0 6\n1\n2\n3\n4\n5\n6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 0 1\n0 1 1\n$EndNodes\n\
        $Elements\n1 1 1 1\n3 1 6 1\n7 1 2 3 4 5 6\n$EndElements\n";
    let dir = scratch("bad_input/prism");
    let msh = dir.join("prism.msh");
    std::fs::write(&msh, text).unwrap();
    let mut s = column_scene();
    s["geometry"]["msh"] = json!(msh);
    s["materials"][0]["group"] = json!("block:p");
    let msg = run_error("prism_run", &s);
    assert_mentions(&msg, &["prism.msh", "element 7", "unsupported type", "tet4 and hex8"]);
}

// ---- issue 19 §3: crashers and misleading messages from record and mesh files.
// Each test is named after the bug it guards against.

/// Read a record file directly (no scene); the error text, or the record.
fn read_record(test: &str, file: &str, text: &[u8]) -> Result<jointquake::dynamics::record::Record, String> {
    let dir = scratch(&format!("bad_input/{test}"));
    let p = dir.join(file);
    std::fs::write(&p, text).unwrap();
    jointquake::dynamics::record::Record::read(&p, 9.81).map_err(|e| e.to_string())
}

#[test]
fn record_with_dt_1e_300_is_refused_instead_of_panicking_at_index() {
    // Before: dt 1e-300 read, then `Record::at` indexed out of bounds (the saturated cast).
    let (msg, rec) = record_error("tiny_dt_record", "0 0\n1e-300 0.1\n2e-300 0\n");
    assert_mentions(&msg, &[&rec.display().to_string(), "sample interval", "seconds"]);
}

#[test]
fn record_at_far_beyond_its_end_is_zero_not_a_panic() {
    // The interpolation guards its own index: a time 1e300 record-steps past the end reads 0.
    let r = read_record("record_at_far", "r.txt", b"0 1\n0.01 1\n0.02 1\n").unwrap();
    assert_eq!(r.at(1e300), 0.0);
    assert_eq!(r.at(f64::NAN), 0.0);
    assert_eq!(r.at(-1.0), 0.0);
    assert!((r.at(0.015) - 9.81).abs() < 1e-12);
}

#[test]
fn at2_with_npts_1e15_is_an_error_not_an_allocation_abort() {
    let msg = read_record("at2_npts_huge", "r.AT2", b"h1\nh2\nh3\nNPTS= 1000000000000000, DT= 0.01 SEC\n0.1 0.2\n").unwrap_err();
    assert_mentions(&msg, &["line 4", "NPTS", "more values than a file of"]);
}

#[test]
fn at2_with_npts_2_pow_64_is_an_error_not_a_capacity_overflow() {
    let msg = read_record("at2_npts_u64", "r.AT2", b"h1\nh2\nh3\nNPTS= 18446744073709551615, DT= 0.01 SEC\n0.1 0.2\n").unwrap_err();
    assert_mentions(&msg, &["line 4", "NPTS"]);
}

#[test]
fn at2_with_npts_0_says_npts_not_header_lines() {
    // Before: "an AT2 file has 4 header lines" for a file that has them.
    let msg = read_record("at2_npts_0", "r.AT2", b"h1\nh2\nh3\nNPTS= 0, DT= 0.01 SEC\n").unwrap_err();
    assert_mentions(&msg, &["line 4", "NPTS = 0", "positive whole number"]);
}

#[test]
fn record_with_a_utf8_bom_reads() {
    // Before: the invisible BOM made line 1 "not a number".
    let r = read_record("record_bom", "r.txt", b"\xEF\xBB\xBF0 0\n0.01 0.5\n0.02 0\n").unwrap();
    assert_eq!(r.accel.len(), 3);
}

#[test]
fn record_with_three_columns_is_refused_not_cut_to_two() {
    // Before: the third column was dropped silently.
    let (msg, rec) = record_error("three_column_record", "0 0 0\n0.01 0.1 0.2\n0.02 0 0\n");
    assert_mentions(&msg, &[&rec.display().to_string(), "line 1", "third", "one component"]);
}

/// The column fixture with one line replaced (1-based), written to scratch.
fn column_msh_with(test: &str, line: usize, new: &str) -> PathBuf {
    let text = std::fs::read_to_string(fixture("column_hex.msh")).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    lines[line - 1] = new;
    let p = scratch(&format!("bad_input/{test}")).join("m.msh");
    std::fs::write(&p, lines.join("\n") + "\n").unwrap();
    p
}

#[test]
fn msh_nodes_header_claiming_1e12_nodes_is_an_error_not_an_allocation() {
    // Line 42 is the $Nodes header `blocks nodes min max` (44 nodes in 19 blocks).
    let p = column_msh_with("msh_nodes_1e12", 42, "19 1000000000000 1 44");
    let msg = Mesh::from_msh(p.clone()).unwrap_err().to_string();
    assert_mentions(&msg, &[&p.display().to_string(), "claims 1000000000000 nodes", "hold 44"]);
}

#[test]
fn msh_elements_header_claiming_more_elements_is_an_error() {
    let p = column_msh_with("msh_elements_claim", 152, "7 52000000000 1 52");
    let msg = Mesh::from_msh(p.clone()).unwrap_err().to_string();
    assert_mentions(&msg, &["claims 52000000000 elements", "hold 52"]);
}

#[test]
fn msh_2_2_says_re_export_as_4_1_instead_of_a_parser_dump() {
    let p = column_msh_with("msh22", 2, "2.2 0 8");
    let msg = Mesh::from_msh(p.clone()).unwrap_err().to_string();
    assert_mentions(&msg, &[&p.display().to_string(), "this is MSH 2.2", "-format msh41"]);
    assert!(!msg.contains("0x"), "no hex dump: {msg}");
}

#[test]
fn msh_4_0_says_re_export_as_4_1() {
    let p = column_msh_with("msh40", 2, "4 0 8");
    let msg = Mesh::from_msh(p).unwrap_err().to_string();
    assert_mentions(&msg, &["this is MSH 4", "msh41"]);
}

// ---- issue 19 §2: inputs that ran with exit 0 and a silently wrong (or no) answer.

#[test]
fn rho_1e_300_is_refused_instead_of_dt_nan_and_zero_steps() {
    let mut s = column_scene();
    s["materials"][0]["rho"] = json!(1e-300);
    assert_mentions(&run_error("rho_tiny", &s), &["block:column", "rho = 1e-300", "kg/m³"]);
}

#[test]
fn e_1e_300_is_refused_instead_of_zero_steps() {
    let mut s = column_scene();
    s["materials"][0]["E"] = json!(1e-300);
    assert_mentions(&run_error("e_tiny", &s), &["block:column", "E = 1e-300", "in Pa"]);
}

#[test]
fn e_1e307_is_refused_instead_of_running_for_ever() {
    let mut s = column_scene();
    s["materials"][0]["E"] = json!(1e307);
    assert_mentions(&run_error("e_huge", &s), &["E = 1e307"]);
}

#[test]
fn force_1e300_is_refused_instead_of_inf_peaks() {
    let mut s = column_scene();
    s["loads"] = json!({"nodal": [{"point": [0, 0, 10], "force": [1e300, 0, 0]}]});
    assert_mentions(&run_error("force_huge", &s), &["loads.nodal[0]", "force"]);
}

#[test]
fn negative_ramp_is_refused() {
    let mut s = column_scene();
    s["loads"] = json!({"traction": [{"group": "load:top", "traction": [0, 0, -1e5], "ramp": -1.0}]});
    assert_mentions(&run_error("negative_ramp", &s), &["loads.traction[0]", "load:top", "ramp = -1"]);
}

#[test]
fn pga_0_and_negative_scale_are_refused() {
    for (k, v, want) in [("pga", 0.0, "pga = 0"), ("scale", -1.0, "scale = -1"), ("pga", -0.5, "pga = -0.5")] {
        let mut s = column_scene();
        s["loads"] = json!({"base": [{"record": "r.txt", "direction": [1, 0, 0], k: v}]});
        assert_mentions(&run_error(&format!("base_{k}_{v}"), &s), &[want, "reverse its `direction`"]);
    }
}

#[test]
fn negative_energy_and_equilibrium_tolerances_are_refused() {
    let mut s = column_scene();
    s["time"]["energy_tolerance"] = json!(-0.1);
    assert_mentions(&run_error("neg_energy_tol", &s), &["time.energy_tolerance = -0.1"]);
    let mut s = column_scene();
    s["equilibrium"] = json!({"tolerance": -1e-6});
    assert_mentions(&run_error("neg_eq_tol", &s), &["equilibrium.tolerance = -0.000001"]);
}

#[test]
fn gravity_direction_zero_is_named_not_time_step_too_large() {
    let mut s = column_scene();
    s["loads"] = json!({"gravity": {"direction": [0, 0, 0]}});
    assert_mentions(&run_error("gravity_zero_dir", &s), &["loads.gravity.direction", "non-zero"]);
    let mut s = column_scene();
    s["loads"] = json!({"gravity": {"g": -9.81}});
    assert_mentions(&run_error("gravity_negative_g", &s), &["loads.gravity.g = -9.81"]);
}

#[test]
fn geometry_set_with_msh_is_refused() {
    let mut s = column_scene();
    s["geometry"]["set"] = json!({"h": 0.5});
    assert_mentions(&run_error("set_with_msh", &s), &["geometry.set", "`msh`"]);
}

#[test]
fn scene_names_that_escape_the_output_directory_are_refused() {
    // Before: name "/" wrote /.pvd at the filesystem root; "../../x" wrote outside --out; "" a hidden file.
    for (k, name) in ["/", "../../x", "", ".hidden", "a b"].iter().enumerate() {
        let mut s = column_scene();
        s["name"] = json!(name);
        assert_mentions(&run_error(&format!("bad_name_{k}"), &s), &["name", "becomes a file name"]);
    }
}

#[test]
fn monitor_names_that_escape_or_collide_are_refused() {
    let mut s = column_scene();
    s["output"]["monitor"] = json!([{"name": "../../evil", "point": [0, 0, 0]}]);
    assert_mentions(&run_error("monitor_escape", &s), &["output.monitor name", "../../evil"]);
    let mut s = column_scene();
    s["output"]["monitor"] = json!([{"name": "top", "point": [0, 0, 0]}, {"name": "top", "point": [0, 0, 10]}]);
    assert_mentions(&run_error("monitor_twice", &s), &["two monitors are named \"top\""]);
}

#[test]
fn two_joints_on_the_same_pair_of_groups_are_refused() {
    let mut s = column_scene();
    s["joints"] = json!([
        {"name": "J1", "master": "bc:base", "slave": "load:top"},
        {"name": "J2", "master": "load:top", "slave": "bc:base"}
    ]);
    assert_mentions(&run_error("joint_twice", &s), &["\"J1\" and \"J2\"", "applied twice"]);
}

#[test]
fn a_scene_file_name_with_spaces_gives_a_clean_default_name() {
    let dir = scratch("bad_input/spaced_name");
    let p = dir.join("my scene.json");
    std::fs::write(&p, column_scene().to_string()).unwrap();
    assert_eq!(Scene::load(&p).unwrap().name(), "my_scene");
}

#[test]
fn a_run_of_more_steps_than_max_steps_is_refused_up_front() {
    // Before: dt 1e-300 or a duration of 1e300 s ran for ever with no output.
    let mut s = column_scene();
    s["time"] = json!({"duration": 1e300});
    assert_mentions(&run_error("duration_huge", &s), &["time.duration", "steps, above time.max_steps = 100000000", "raise time.max_steps"]);
    let mut s = column_scene();
    s["time"] = json!({"duration": 1.0, "dt": 1e-300});
    assert_mentions(&run_error("dt_tiny", &s), &["steps, above time.max_steps"]);
    // The limit is a knob: a small one refuses the ordinary run, naming it.
    let mut s = column_scene();
    s["time"]["max_steps"] = json!(1);
    assert_mentions(&run_error("max_steps_1", &s), &["above time.max_steps = 1 "]);
}

/// Issue 19 §2: a record entirely outside the run time (its first time after the run's end) was
/// accepted with exit 0 and the base never moved; now an error naming loads.base[0], the record's
/// span, the run's span and the fix.
#[test]
fn record_entirely_outside_the_run_time_is_refused() {
    let (msg, rec) = record_error("record_outside_run", "10.0 0.0\n10.01 0.1\n10.02 0.0\n");
    assert_mentions(&msg, &["loads.base[0]", rec.to_str().unwrap(), "10 … 10.02 s", "entirely outside the run (0 … 0.001 s)", "time.duration"]);
}
