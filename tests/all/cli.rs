//! The command-line binary: `tag` and `wedge-fs` outputs, and bad input at the CLI level (exit
//! status 1, `error: ...` on stderr naming the culprit, never a panic).
use crate::common::{fixture, scratch};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn jointquake(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_jointquake")).args(args).current_dir(cwd).output().expect("the jointquake binary starts")
}

fn repo(p: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(p)
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The command must fail cleanly: status 1, one `error: ` message mentioning every part, no panic.
fn assert_clean_failure(o: &Output, parts: &[&str]) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(1), "exit status; stderr:\n{err}");
    assert!(!err.contains("panicked"), "panic:\n{err}");
    assert!(err.starts_with("error: "), "stderr must start with `error: `:\n{err}");
    for p in parts {
        assert!(err.contains(p), "stderr does not mention {p:?}:\n{err}");
    }
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn tag_boxes_scene_summary_and_files() {
    // pipelines/tag_boxes.json: boxes_hex_4x3.msh, joint J named master joint:J:lower, slave
    // joint:J:upper, auto. References (exact, from the structured grids on the unit square z = 0):
    // lower side 4×4 quads (25 nodes, finer), upper side 3×3 quads (16 nodes), so auto makes the
    // lower side the slave (swapped). Per axis the slave coordinates k/4 meet master coordinates
    // k/3 only at 0 and 1, so 2×2 = 4 slave nodes are NTN-conforming, and the largest distance to O
    // is at (1/2, 1/2): √2/6 m. Layers are separable per axis: O's master index along an axis is
    // (0, 1, 1, 2, 3) for slave (0, 1/4, 1/2, 3/4, 1) (the tie at 1/2 goes to the lower index);
    // faces around a master index: 1 at an end, 2 inside → Σ = 8 per axis, Layer1 mean 64/25;
    // Layer2 along an axis: 2 at an end, 3 inside → Σ = 13, Layer2 mean 169/25. Tolerance on the distance 1e-9 relative (node coordinates
    // as written by Gmsh; measured 3e-12), counts and means exact to 1e-12.
    let dir = scratch("cli/tag_boxes");
    let out = dir.join("out");
    let o = jointquake(&["tag", repo("pipelines/tag_boxes.json").to_str().unwrap(), "--out", out.to_str().unwrap(), "--json"], &dir);
    assert!(o.status.success(), "tag failed:\n{}", stderr(&o));
    let s: Value = serde_json::from_str(&stdout(&o)).expect("--json prints the summary");
    let j = &s["joints"][0];
    assert_eq!(j["name"], "J");
    assert_eq!(j["slave_group"], "joint:J:lower");
    assert_eq!(j["master_group"], "joint:J:upper");
    assert_eq!(j["auto"], true);
    assert_eq!(j["swapped"], true);
    assert_eq!(j["slave_nodes"], 25);
    assert_eq!(j["master_nodes"], 16);
    assert_eq!(j["ntn_conforming"], 4);
    assert!(rel(j["ntn_max_distance"].as_f64().unwrap(), 2f64.sqrt() / 6.0) < 1e-9, "{}", j["ntn_max_distance"]);
    assert!(rel(j["layer1_mean"].as_f64().unwrap(), 64.0 / 25.0) < 1e-12, "{}", j["layer1_mean"]);
    assert!(rel(j["layer2_mean"].as_f64().unwrap(), 169.0 / 25.0) < 1e-12, "{}", j["layer2_mean"]);
    // default tolerance: 1e-6 × the mesh bounding-box diagonal (unit square × 1 m height: √3 m)
    assert_eq!(j["tolerance_source"], "default");
    assert!(rel(j["tolerance"].as_f64().unwrap(), 1e-6 * 3f64.sqrt()) < 1e-12);
    // files
    let tagging = out.join("tagging");
    let joints: Value = serde_json::from_str(&std::fs::read_to_string(tagging.join("joints.json")).unwrap()).unwrap();
    assert_eq!(joints["format"], "jointquake-joints");
    assert_eq!(joints["joints"][0]["slave_group"], "joint:J:lower");
    assert_eq!(joints["joints"][0]["ntn_conforming_count"], 4);
    let vtu = std::fs::read_to_string(tagging.join("J.vtu")).unwrap();
    assert!(vtu.contains("<VTKFile") && vtu.contains("NumberOfPoints=\"41\""), "VTU with 16 + 25 points");
    assert!(tagging.join("summary.json").exists());

    // the text table shows the same numbers
    let o = jointquake(&["tag", repo("pipelines/tag_boxes.json").to_str().unwrap(), "--out", out.to_str().unwrap()], &dir);
    assert!(o.status.success());
    let text = stdout(&o);
    for p in ["joint J", "\"joint:J:lower\": 25 nodes", "auto: swapped", "Layer1 2.56, Layer2 6.76", "2.3570e-1 m", "4 of 25 slave nodes conforming"] {
        assert!(text.contains(p), "tag output lacks {p:?}:\n{text}");
    }
}

#[test]
fn tag_uses_the_joint_tolerance_when_given() {
    let dir = scratch("cli/tag_tolerance");
    let scene = json!({
        "geometry": {"msh": fixture("boxes_hex_3x3.msh")},
        "materials": [{"group": "block:lower", "E": 1e9, "nu": 0.2, "rho": 2000}],
        "time": {"duration": 0.0},
        "joints": [{"name": "conforming", "master": "joint:J:lower", "slave": "joint:J:upper", "tolerance": 1e-4}]
    });
    std::fs::write(dir.join("s.json"), scene.to_string()).unwrap();
    let o = jointquake(&["tag", "s.json", "--out", "out", "--json"], &dir);
    assert!(o.status.success(), "{}", stderr(&o));
    let s: Value = serde_json::from_str(&stdout(&o)).unwrap();
    let j = &s["joints"][0];
    // boxes_hex_3x3 is conforming (README): all 16 slave nodes coincide with their O
    assert_eq!(j["tolerance"], 1e-4);
    assert_eq!(j["tolerance_source"], "scene");
    assert_eq!(j["ntn_conforming"], 16);
    assert_eq!(j["swapped"], false);
    assert!(dir.join("out/tagging/conforming.vtu").exists());
}

#[test]
fn wedge_fs_prints_the_seed_table() {
    // References: shared refs hoek_bray_wedge.py analyse(39.624, "intersection") FS 1.8479394005,
    // friction only 1.1066196831; analyse(39.624, "H1") FS 1.6768740968 (as in tests/all/rigid.rs).
    let dir = scratch("cli/wedge_fs");
    let o = jointquake(&["wedge-fs"], &dir);
    assert!(o.status.success(), "{}", stderr(&o));
    let t = stdout(&o);
    assert!(t.contains("FS                                 1.8479"), "{t}");
    assert!(t.contains("FS friction only (c = 0)           1.1066"), "{t}");
    let o = jointquake(&["wedge-fs", "--height-def", "crest-on-a"], &dir);
    assert!(stdout(&o).contains("FS                                 1.6769"), "{}", stdout(&o));

    let o = jointquake(&["wedge-fs", "--json"], &dir);
    let v: Value = serde_json::from_str(&stdout(&o)).expect("--json is JSON");
    assert!(rel(v["fs"].as_f64().unwrap(), 1.8479394005119585) < 1e-9);
    assert!(rel(v["fs_friction_only"].as_f64().unwrap(), 1.1066196830064965) < 1e-9);
    // rigid wedge: the strength-reduction factor equals the limit-equilibrium FS (to the bisection's 1e-12)
    assert!(rel(v["strength_reduction_factor"].as_f64().unwrap(), 1.8479394005119585) < 1e-9);
    assert_eq!(v["input"]["height"], 39.624);

    // --input with a partial file (missing fields = seed) and --H overriding it
    std::fs::write(dir.join("w.json"), r#"{"height_def": "crest_on_a", "height": 10.0}"#).unwrap();
    let o = jointquake(&["wedge-fs", "--input", "w.json", "--H", "39.624", "--json"], &dir);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(v["input"]["height"], 39.624);
    assert_eq!(v["input"]["height_def"], "crest_on_a");
    assert!(rel(v["fs"].as_f64().unwrap(), 1.676874096799082) < 1e-9, "{}", v["fs"]);
}

#[test]
fn wedge_fs_bad_input_names_the_quantity() {
    let dir = scratch("cli/wedge_fs_bad");
    let o = jointquake(&["wedge-fs", "--H", "-3"], &dir);
    assert_clean_failure(&o, &["wedge height H [m] = -3", "must be a finite number > 0"]);
    std::fs::write(dir.join("w.json"), r#"{"plane_a": {"dip": 45.0}}"#).unwrap();
    let o = jointquake(&["wedge-fs", "--input", "w.json"], &dir);
    assert_clean_failure(&o, &["w.json", "missing field `dip_direction`"]);
    std::fs::write(dir.join("p.json"), r#"{"plane_b": {"dip": 45.0, "dip_direction": 105.0}}"#).unwrap();
    let o = jointquake(&["wedge-fs", "--input", "p.json"], &dir);
    assert_clean_failure(&o, &["p.json", "parallel", "two joint planes with different orientations"]);
    let o = jointquake(&["wedge-fs", "--input", "nope.json"], &dir);
    assert_clean_failure(&o, &["nope.json"]);
}

#[test]
fn wedge_fs_tension_crack_flags_and_file() {
    // Reference: shared refs hoek_bray_wedge.py clipped_wedge_fs() (crack 70/165, L = 12.192 m,
    // H1 = 30.48 m, dry): V 5003.621380283401 m3, FS 1.7369230728038687 (as in tests/all/rigid.rs).
    let dir = scratch("cli/wedge_fs_crack");
    let base = ["wedge-fs", "--height-def", "crest-on-a", "--H", "30.48"];
    let o = jointquake(&[&base[..], &["--crack", "70/165", "--crack-distance", "12.192"]].concat(), &dir);
    assert!(o.status.success(), "{}", stderr(&o));
    let t = stdout(&o);
    for needle in [
        "tension crack 70/165 at L = 12.192 m behind the crest along the trace of A (|QA P| = 44.918 m)",
        "volume (truncated by the crack)    5003.62 m3",
        "tetrahedron volume (no crack)      6510.76 m3",
        "FS                                 1.7369",
    ] {
        assert!(t.contains(needle), "lacks {needle:?}:\n{t}");
    }
    // The same crack from the --input file, JSON output.
    std::fs::write(
        dir.join("w.json"),
        r#"{"height_def": "crest_on_a", "height": 30.48, "tension_crack": {"orientation": {"dip": 70, "dip_direction": 165}, "distance": 12.192}}"#,
    )
    .unwrap();
    let o = jointquake(&["wedge-fs", "--input", "w.json", "--json"], &dir);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert!(rel(v["fs"].as_f64().unwrap(), 1.7369230728038687) < 1e-6, "{}", v["fs"]);
    assert!(rel(v["geometry"]["volume"].as_f64().unwrap(), 5003.621380283401) < 1e-6);
    assert_eq!(v["geometry"]["crack"]["removed"], json!(["P"]));
    assert_eq!(v["input"]["tension_crack"]["distance"], 12.192);
    assert!(rel(v["strength_reduction_factor"].as_f64().unwrap(), 1.7369230728038687) < 1e-6);
    // A flag overrides one part of the file's crack: L = 0 (crack through the crest point
    // QA), HB clipped_wedge_fs(L=0.0) FS 1.7475504149831675.
    let o = jointquake(&["wedge-fs", "--input", "w.json", "--crack-distance", "0", "--json"], &dir);
    let v: Value = serde_json::from_str(&stdout(&o)).unwrap_or_else(|_| panic!("{}", stderr(&o)));
    assert!(rel(v["fs"].as_f64().unwrap(), 1.7475504149831675) < 1e-6, "{}", v["fs"]);
    assert_eq!(v["input"]["tension_crack"]["orientation"]["dip"], 70.0);
}

#[test]
fn wedge_fs_tension_crack_bad_input() {
    let dir = scratch("cli/wedge_fs_crack_bad");
    let o = jointquake(&["wedge-fs", "--crack", "70/165"], &dir);
    assert_clean_failure(&o, &["--crack needs --crack-distance"]);
    let o = jointquake(&["wedge-fs", "--crack-distance", "5"], &dir);
    assert_clean_failure(&o, &["--crack-distance needs --crack"]);
    let o = jointquake(&["wedge-fs", "--crack", "70-165", "--crack-distance", "5"], &dir);
    assert_eq!(o.status.code(), Some(2), "malformed command line: {}", stderr(&o));
    assert!(stderr(&o).contains("expected DIP/DIPDIR in degrees, e.g. 70/165"), "{}", stderr(&o));
    // Beyond P (|QA P| = 44.918 m for the appendix wedge).
    let o = jointquake(&["wedge-fs", "--height-def", "crest-on-a", "--H", "30.48", "--crack", "70/165", "--crack-distance", "50"], &dir);
    assert_clean_failure(&o, &["tension crack 70/165 at L = 50 m does not cut the wedge", "0 <= L < 44.918 m"]);
    let o = jointquake(&["wedge-fs", "--crack", "20/185", "--crack-distance", "12"], &dir);
    assert_clean_failure(&o, &["tension crack 20/185", "cuts off the toe"]);
    std::fs::write(dir.join("wet.json"), r#"{"water": "hoek_bray_short"}"#).unwrap();
    let o = jointquake(&["wedge-fs", "--input", "wet.json", "--crack", "70/165", "--crack-distance", "12"], &dir);
    assert_clean_failure(&o, &["wet.json", "dry wedge only"]);
}

/// Write a scene and run `jointquake <cmd> scene.json --out out`.
fn cli_on_scene(test: &str, cmd: &str, scene: &Value) -> Output {
    let dir = scratch(&format!("cli/{test}"));
    std::fs::write(dir.join("scene.json"), serde_json::to_string_pretty(scene).unwrap()).unwrap();
    jointquake(&[cmd, "scene.json", "--out", "out"], &dir)
}

fn column(extra: Value) -> Value {
    let mut s = json!({
        "geometry": {"msh": fixture("column_hex.msh")},
        "materials": [{"group": "block:column", "E": 30e9, "nu": 0.2, "rho": 2400}],
        "boundary": [{"group": "bc:base"}],
        "time": {"duration": 0.001},
        "output": {"frames": false}
    });
    for (k, v) in extra.as_object().unwrap() {
        s[k] = v.clone();
    }
    s
}

#[test]
fn run_bad_scenes_fail_cleanly_naming_the_culprit() {
    let o = cli_on_scene("unknown_key", "run", &column(json!({"dampng": {}})));
    assert_clean_failure(&o, &["scene.json", "unknown field `dampng`"]);

    let mut s = column(json!({}));
    s["materials"][0]["group"] = json!("block:colum");
    assert_clean_failure(&cli_on_scene("unknown_group", "run", &s), &["\"block:colum\"", "\"block:column\" (dim 3)"]);

    let s = column(json!({"loads": {"base": [{"record": "no_record.txt", "direction": [0, 1, 0]}]}}));
    let o = cli_on_scene("missing_record", "run", &s);
    assert_clean_failure(&o, &["no_record.txt", "Check the `record` path"]);
    // the I/O cause is printed once, not repeated by the context chain
    assert_eq!(stderr(&o).matches("No such file or directory").count(), 1, "{}", stderr(&o));

    let mut s = column(json!({}));
    s["geometry"]["msh"] = json!(fixture("inverted_tet.msh"));
    s["materials"][0]["group"] = json!("block:upper");
    assert_clean_failure(&cli_on_scene("inverted", "run", &s), &["element 405 is inverted", "\"block:upper\""]);

    let mut s = column(json!({}));
    s["time"]["dt"] = json!(0.5);
    s["time"]["duration"] = json!(1.0); // dt ≤ 2 × duration: refused for its stability, not for taking no step
    assert_clean_failure(&cli_on_scene("dt", "run", &s), &["above the stability limit", "critical element", "\"block:column\""]);

    let mut s = column(json!({}));
    s["geometry"]["msh"] = json!(fixture("malformed.msh"));
    assert_clean_failure(&cli_on_scene("malformed", "run", &s), &["malformed.msh", "not a valid MSH 4.1 file"]);

    let mut s = column(json!({}));
    s["geometry"]["msh"] = json!("gone.msh");
    assert_clean_failure(&cli_on_scene("missing_msh", "run", &s), &["gone.msh", "cannot read mesh file"]);

    let mut s = column(json!({}));
    s["time"]["courant"] = json!(2.0);
    assert_clean_failure(&cli_on_scene("courant", "run", &s), &["time.courant = 2"]);

    let mut s = column(json!({}));
    s["boundary"][0]["fix"] = json!(["xy"]);
    assert_clean_failure(&cli_on_scene("component", "run", &s), &["component \"xy\""]);

    // a scene that does not exist, and a scene that is not JSON
    let dir = scratch("cli/no_scene");
    assert_clean_failure(&jointquake(&["run", "nothing.json"], &dir), &["nothing.json"]);
    std::fs::write(dir.join("text.json"), "geometry = 1").unwrap();
    assert_clean_failure(&jointquake(&["run", "text.json"], &dir), &["text.json", "line 1"]);
}

#[test]
fn tag_bad_scenes_fail_cleanly_naming_the_culprit() {
    let scene = |master: &str| {
        json!({
            "geometry": {"msh": fixture("boxes_hex_4x3.msh")},
            "materials": [{"group": "block:lower", "E": 1e9, "nu": 0.2, "rho": 2000}],
            "time": {"duration": 0.0},
            "joints": [{"name": "J", "master": master, "slave": "joint:J:upper"}]
        })
    };
    let o = cli_on_scene("tag_unknown_group", "tag", &scene("joint:J:lowr"));
    assert_clean_failure(&o, &["joint \"J\"", "\"joint:J:lowr\"", "\"joint:J:lower\" (dim 2)"]);
    let o = cli_on_scene("tag_same_group", "tag", &scene("joint:J:upper"));
    assert_clean_failure(&o, &["joint \"J\"", "same group \"joint:J:upper\""]);
    let o = cli_on_scene("tag_volume_group", "tag", &scene("block:lower"));
    assert_clean_failure(&o, &["joint \"J\"", "\"block:lower\""]);
}
