//! Hardening, third round (issues 33 and 34): one regression test per class of hostile input,
//! named after it. Each either checks the clear error (naming the field, the value and the
//! limit) or that what is written stays where it belongs.
use crate::common::{assert_mentions, column_scene, fixture, run_error_at, scratch, write_scene_in};
use jointquake::pipeline::{run, RunOptions};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// The two 4x3 boxes with one joint `J` (runs in a few steps).
fn boxes_scene() -> Value {
    json!({
        "geometry": {"msh": fixture("boxes_hex_4x3.msh")},
        "materials": [
            {"group": "block:lower", "E": 30e9, "nu": 0.2, "rho": 2400},
            {"group": "block:upper", "E": 30e9, "nu": 0.2, "rho": 2400}
        ],
        "boundary": [{"group": "bc:base"}],
        "time": {"duration": 0.0005},
        "joints": [{"name": "J", "master": "joint:J:lower", "slave": "joint:J:upper"}],
        "output": {"frames": true, "frame_stride": 1}
    })
}

/// Write `scene` as `<scratch(hardening/test)>/scene.json`; returns (scene path, scratch dir).
fn write_scene(test: &str, scene: &Value) -> (PathBuf, PathBuf) {
    write_scene_in(&format!("hardening/{test}"), scene)
}

/// The error message of `run` on `scene` (which must fail).
fn run_error(test: &str, scene: &Value) -> String {
    let (p, dir) = write_scene(test, scene);
    run_error_at(test, &p, &dir)
}

/// Every file under `dir` (recursively).
fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).into_iter().flatten().flatten() {
        let p = e.path();
        if p.is_dir() {
            out.extend(files_under(&p));
        } else {
            out.push(p);
        }
    }
    out
}

// ---- issue 33 -----------------------------------------------------------------------------

#[test]
fn reservoir_level_1e308_and_bottom_minus_1e308_are_refused_not_an_assertion() {
    // Before: an assertion in model/mass.rs (exit 101). Limit: MAX_ELEVATION = 1e5 m.
    let mut s = column_scene();
    s["reservoir"] = json!({"faces": ["load:top"], "level": 1e308});
    assert_mentions(&run_error("level_1e308", &s), &["reservoir.level", "1e308", "1e5"]);
    s["reservoir"] = json!({"faces": ["load:top"], "level": 10.0, "bottom": -1e308});
    assert_mentions(&run_error("bottom_1e308", &s), &["reservoir.bottom", "-1e308"]);
}

#[test]
fn synth_sample_count_above_the_limit_is_refused_before_allocating() {
    // Before: `memory allocation of N bytes failed` (dt 1e-9), or a run with no output for
    // dt 1e-5. Limits: motion::synth::MIN_SYNTH_DT (5 ms), MAX_SYNTH_SAMPLES (120 001).
    let mut s = column_scene();
    s["loads"] = json!({"base": [{"synth": {"spectrum": {"kind": "table", "points": [[0.1, 1.0], [1.0, 1.0]]}, "seed": 1, "dt": 1e-9}, "direction": [1, 0, 0], "pga": 0.2}]});
    assert_mentions(&run_error("synth_dt_1e-9", &s), &["loads.base[0]", "synth.dt", "must be in [0.005, 0.05]"]);
    s["loads"]["base"][0]["synth"]["dt"] = json!(0.005);
    s["loads"]["base"][0]["synth"]["duration"] = json!(1e6);
    assert_mentions(&run_error("synth_1e6_s", &s), &["synth.dt", "2.000e8 samples", "120001"]);
    // the same rule for `record synth`
    let mut req = jointquake::motion::synth::SynthRequest::new(jointquake::motion::TargetSpec::Table { points: Some(vec![[0.1, 1.0], [1.0, 1.0]]), file: None }, 0.2, 1);
    req.dt = 1e-6;
    req.duration = 600.0;
    let e = req.check("").unwrap_err().to_string();
    assert_mentions(&e, &["dt", "must be in [0.005, 0.05]"]);
}

#[test]
fn study_whose_axes_multiply_to_1e12_is_refused_before_planning() {
    // Before: `study plan` ran for ever. Limit: study::plan::MAX_STUDY_RUNS (10 000).
    let dir = scratch("hardening/study_1e12");
    let scene = column_scene();
    std::fs::write(dir.join("scene.json"), scene.to_string()).unwrap();
    let axis = |name: &str| json!({"name": name, "field": "set.x", "values": (0..1000).map(|k| json!({"label": format!("{name}{k}")})).collect::<Vec<_>>()});
    let study = json!({"scene": "scene.json", "out": "out", "axes": [axis("a"), axis("b"), axis("c"), axis("d")]});
    let p = dir.join("study.json");
    std::fs::write(&p, study.to_string()).unwrap();
    let t = std::time::Instant::now();
    let e = match jointquake::study::Study::load(&p) {
        Ok(s) => jointquake::study::plan_runs(&s).unwrap_err().to_string(),
        Err(e) => e.to_string(),
    };
    assert_mentions(&e, &["1.000e12 runs", "10000"]);
    assert!(t.elapsed().as_secs_f64() < 30.0, "refused only after {:?}", t.elapsed());
}

#[test]
fn joint_name_with_slashes_and_dotdot_writes_inside_out() {
    // Before: histories/joint_<name>.csv, joint_<name>_forces.csv and joints/<name>.pvd took the
    // name raw, so "../../x" wrote outside --out. Reference: files::file_stem.
    let mut s = boxes_scene();
    s["joints"][0]["name"] = json!("../../../escaped");
    s["output"]["joint_forces"] = json!(true);
    let (p, dir) = write_scene("joint_dotdot", &s);
    let out = dir.join("deep/out");
    run(&p, &RunOptions { out_dir: Some(out.clone()), ..Default::default() }).expect("runs");
    let outside: Vec<PathBuf> = files_under(&dir).into_iter().filter(|f| !f.starts_with(&out) && f.file_name().is_some_and(|n| n.to_string_lossy().contains("escaped"))).collect();
    assert!(outside.is_empty(), "written outside --out: {outside:?}");
    assert!(out.join("histories/joint__._.._.._escaped.csv").exists(), "{:?}", files_under(&out));
}

#[test]
fn record_synth_absolute_name_is_refused() {
    let req = jointquake::motion::synth::SynthRequest::new(jointquake::motion::TargetSpec::Table { points: Some(vec![[0.1, 1.0], [1.0, 1.0]]), file: None }, 0.2, 1);
    let out = scratch("hardening/synth_abs");
    for name in ["/tmp/jq-abs-name", "../up", ""] {
        let e = jointquake::motion::commands::synth_files(&req, &out, name).unwrap_err().to_string();
        assert_mentions(&e, &["--name", "not a file name"]);
    }
}

#[test]
fn pga_scale_and_gravity_1e300_are_refused_not_inf_peaks() {
    // Before: exit 0 with inf/NaN peaks in the summary.
    let rec = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("pipelines/records/elcentro1940_NS_chopra.txt");
    let mut s = column_scene();
    s["loads"] = json!({"base": [{"record": rec, "direction": [1, 0, 0], "pga": 1e300}]});
    assert_mentions(&run_error("pga_1e300", &s), &["pga", "1e300", "[0e0, 1e1] g"]);
    s["loads"] = json!({"base": [{"record": rec, "direction": [1, 0, 0], "scale": 1e300}]});
    assert_mentions(&run_error("scale_1e300", &s), &["scale", "1e300"]);
    s["loads"] = json!({"gravity": {"g": 1e300}});
    assert_mentions(&run_error("gravity_1e300", &s), &["loads.gravity.g", "1e300", "m/s²"]);
    let mut s = column_scene();
    s["g"] = json!(1e300);
    assert_mentions(&run_error("g_1e300", &s), &["g = 1e300"]);
}

#[test]
fn huge_damping_is_refused_naming_the_field_not_no_element_has_mass() {
    // Before: α, β, f1/f2 or target_dt near 1e300 said "no element has mass".
    for (d, field) in [(json!({"alpha": 1e300}), "damping.alpha"), (json!({"beta": 1e300}), "damping.beta"), (json!({"ratio": 0.05, "f1": 1.0, "f2": 1e300}), "damping.f2")] {
        let mut s = column_scene();
        s["damping"] = d;
        let m = run_error("damping_huge", &s);
        assert_mentions(&m, &[field]);
        assert!(!m.contains("no element has mass"), "{m}");
    }
    let mut s = column_scene();
    s["time"]["mass_scaling"] = json!({"target_dt": 1e300});
    assert_mentions(&run_error("target_dt_huge", &s), &["time.mass_scaling.target_dt", "1e300"]);
}

// ---- issue 34 -----------------------------------------------------------------------------

#[test]
fn reservoir_faces_listed_twice_are_refused() {
    // Before: the water pressure and added mass were silently doubled.
    let mut s = column_scene();
    s["reservoir"] = json!({"faces": ["load:top", "load:top"], "level": 10.0});
    assert_mentions(&run_error("faces_twice", &s), &["reservoir.faces", "\"load:top\" is listed twice", "applied twice"]);
    let mut s = column_scene();
    s["loads"] = json!({"gravity": {"groups": ["block:column", "block:column"]}});
    assert_mentions(&run_error("gravity_groups_twice", &s), &["loads.gravity.groups", "listed twice"]);
}

#[test]
fn monitor_named_joint_j_and_joint_j_collide_before_the_run() {
    // Before: both wrote histories/joint_J.csv, which ended up corrupt.
    let mut s = boxes_scene();
    s["output"]["monitor"] = json!([{"name": "joint_J", "point": [0, 0, 0.5]}]);
    let (p, dir) = write_scene("monitor_joint_collision", &s);
    let out = dir.join("out");
    let e = run(&p, &RunOptions { out_dir: Some(out.clone()), ..Default::default() }).unwrap_err().to_string();
    assert_mentions(&e, &["histories/joint_J.csv", "monitor \"joint_J\"", "joint \"J\"", "unique"]);
    assert!(files_under(&out).is_empty(), "written before the check: {:?}", files_under(&out));
}

#[test]
fn record_correct_out_to_a_device_or_symlink_is_refused() {
    // Before: the temp file + rename replaced the target (as root, /dev/null itself).
    let dir = scratch("hardening/correct_dev");
    let a: Vec<f64> = (0..200).map(|i| (i as f64 * 0.3).sin()).collect();
    let e = jointquake::motion::commands::correct_file(Path::new("in.txt"), 0.0, 0.01, &a, 9.81, &jointquake::motion::Baseline::Mean, Path::new("/dev/null")).unwrap_err().to_string();
    assert_mentions(&e, &["/dev/null", "not a regular file"]);
    let target = dir.join("keep.txt");
    std::fs::write(&target, "keep").unwrap();
    let link = dir.join("link.txt");
    let _ = std::fs::remove_file(&link);
    std::os::unix::fs::symlink(&target, &link).unwrap();
    assert!(jointquake::motion::commands::correct_file(Path::new("in.txt"), 0.0, 0.01, &a, 9.81, &jointquake::motion::Baseline::Mean, &link).is_err());
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "keep");
}

#[test]
fn a_time_step_above_twice_the_duration_is_refused() {
    // Before: 0 dynamic steps and exit 0.
    let mut s = column_scene();
    s["time"] = json!({"duration": 0.001, "dt": 0.5});
    assert_mentions(&run_error("dt_twice_duration", &s), &["time.dt = 0.5 s", "more than twice time.duration", "no dynamic step"]);
}

#[test]
fn record_info_with_a_negative_g_is_refused() {
    let out = scratch("hardening/info_g");
    let a = vec![0.0, 1.0, -1.0, 0.5];
    for g in [-9.81, f64::NAN, 0.0] {
        let e = jointquake::motion::commands::info("r", 0.0, 0.01, &a, g, &out).unwrap_err().to_string();
        assert_mentions(&e, &["--g"]);
    }
}

#[test]
fn testcase_nan_or_inf_options_are_refused_not_the_defaults() {
    let e = jointquake::testcase::check_finite_options(&[("mu", Some(0.3)), ("pressure", Some(f64::NAN))]).unwrap_err().to_string();
    assert_mentions(&e, &["pressure", "NaN", "finite"]);
    assert!(jointquake::testcase::check_finite_options(&[("rotate", Some(f64::INFINITY))]).is_err());
    assert!(jointquake::testcase::check_finite_options(&[("mu", Some(0.3)), ("shear", None)]).is_ok());
}

#[test]
fn envelope_group_is_checked_before_any_output_is_written() {
    // Before: the error came after the frames and histories were written.
    let mut s = column_scene();
    s["output"]["envelope"] = json!({"faces": ["block:column"]});
    let (p, dir) = write_scene("envelope_first", &s);
    let out = dir.join("out");
    let e = run(&p, &RunOptions { out_dir: Some(out.clone()), ..Default::default() }).unwrap_err().to_string();
    assert_mentions(&e, &["block:column"]);
    assert!(files_under(&out).is_empty(), "written before the check: {:?}", files_under(&out));
}

#[test]
fn dev_zero_as_scene_record_or_mesh_is_refused_at_its_size_bound() {
    // Before: read until memory ran out. Bounds: files::MAX_TEXT_INPUT (16 MiB),
    // MAX_RECORD_INPUT (256 MiB), MAX_MESH_INPUT (2 GiB): the mesh is not tried here (2 GiB of
    // reading), its reader calls the same function.
    let e = jointquake::scene::Scene::load(Path::new("/dev/zero")).unwrap_err().to_string();
    assert_mentions(&e, &["/dev/zero", "longer than 16777216 bytes"]);
    let e = jointquake::dynamics::record::Record::read(Path::new("/dev/zero"), 9.81).unwrap_err().to_string();
    assert_mentions(&e, &["/dev/zero", "longer than"]);
}

/// Processes whose command line mentions `needle`.
fn processes_mentioning(needle: &str) -> Vec<String> {
    let mut out = Vec::new();
    for e in std::fs::read_dir("/proc").into_iter().flatten().flatten() {
        if let Ok(c) = std::fs::read(e.path().join("cmdline")) {
            let c = String::from_utf8_lossy(&c).replace('\0', " ");
            if c.contains(needle) {
                out.push(c);
            }
        }
    }
    out
}

#[test]
#[ignore = "runs gmsh (make test runs it): cargo test --test all -- --ignored gmsh"]
fn sigterm_during_meshing_ends_the_run_and_its_gmsh_child_gmsh() {
    // Before: the first SIGTERM was ignored until the time loop, and the gmsh child outlived
    // its parent. The arch dam's default mesh takes gmsh several seconds: SIGTERM after 1.5 s
    // must end jointquake within 5 s (poll 50 ms, then the phase check), with "interrupted"
    // and the phase, and leave no gmsh child (its command line names the mesh cache below).
    let dir = scratch("hardening/sigterm_gmsh");
    let cache = dir.join("mesh-cache");
    let _ = std::fs::remove_dir_all(&cache);
    let scene = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("pipelines/dam.json");
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_jointquake"))
        .args(["run", scene.to_str().unwrap(), "--quiet", "--out", dir.join("out").to_str().unwrap(), "--cache", cache.to_str().unwrap()])
        .stderr(std::process::Stdio::piped())
        .stdout(std::process::Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    assert!(!processes_mentioning(cache.to_str().unwrap()).is_empty(), "gmsh should be meshing");
    unsafe {
        libc::kill(child.id() as i32, libc::SIGTERM);
    }
    let t = std::time::Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        assert!(t.elapsed().as_secs_f64() < 5.0, "still running 5 s after SIGTERM");
        std::thread::sleep(std::time::Duration::from_millis(50));
    };
    let mut err = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
    assert!(!status.success());
    assert_mentions(&err, &["interrupted"]);
    std::thread::sleep(std::time::Duration::from_millis(200));
    let left: Vec<String> = processes_mentioning(cache.to_str().unwrap()).into_iter().filter(|c| !c.contains("cargo")).collect();
    assert!(left.is_empty(), "gmsh left running: {left:?}");
}
