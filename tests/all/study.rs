//! The study engine (src/study/): study files, the plan (run ids, variant scenes, runs.mk),
//! typed results and the report scaffold, with the incline study (src/studies/incline.rs) as
//! the end-to-end case: planned, run through its own runs.mk with `make`, reported against
//! the rigid Newmark block.
use crate::common::{fixture, scratch};
use jointquake::study::{plan_runs, write_plan, write_report, Study};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

fn manifest(p: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(p)
}

/// The incline scene of pipelines/incline.json with `record` and `duration`.
fn incline_scene(record: &Path, duration: f64) -> Value {
    let mut s: Value = serde_json::from_str(&std::fs::read_to_string(manifest("pipelines/incline.json")).unwrap()).unwrap();
    s["geometry"]["msh"] = json!(fixture("incline_hex.msh"));
    s["loads"]["base"][0]["record"] = json!(record);
    s["time"]["duration"] = json!(duration);
    s
}

/// Write `study` (with `scene` next to it) into `dir` and return the study file's path.
fn write_study(dir: &Path, scene: &Value, mut study: Value) -> PathBuf {
    if study.get("out").is_none() {
        study["out"] = json!("out"); // next to the study file, not under the current directory
    }
    std::fs::write(dir.join("scene.json"), serde_json::to_string_pretty(scene).unwrap()).unwrap();
    let p = dir.join("study.json");
    std::fs::write(&p, serde_json::to_string_pretty(&study).unwrap()).unwrap();
    p
}

fn load_err(dir: &Path, study: Value) -> String {
    let rec = manifest("pipelines/records/elcentro1940_NS_chopra.txt");
    let p = write_study(dir, &incline_scene(&rec, 1.0), study);
    match jointquake::studies::load(&p) {
        Ok(_) => panic!("the study loads"),
        Err(e) => e.to_string(),
    }
}

/// A study that loads but cannot be planned: the plan's error.
fn plan_err(dir: &Path, study: Value) -> String {
    let rec = manifest("pipelines/records/elcentro1940_NS_chopra.txt");
    let p = write_study(dir, &incline_scene(&rec, 1.0), study);
    let s = Study::load(&p).unwrap_or_else(|e| panic!("loads: {e}"));
    match write_plan(&s, &[], &dir.join("cache"), "jointquake") {
        Ok(_) => panic!("the plan succeeds"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn study_runs_are_the_product_of_the_axes_or_the_selections_with_stable_ids() {
    let dir = scratch("study/product");
    let rec = manifest("pipelines/records/elcentro1940_NS_chopra.txt");
    let p = write_study(
        &dir,
        &incline_scene(&rec, 1.0),
        json!({"scene": "scene.json", "axes": [
            {"name": "phi", "field": "joints.phi", "values": [35, 40.5]},
            {"name": "pga", "field": "pga", "decimals": 2, "values": [0.25, 0.5, 0.75]},
            {"name": "m", "values": [{"label": "", "cost": 2}, {"label": "ntn", "joints": {"method": "ntn"}}]}
        ]}),
    );
    let s = Study::load(&p).unwrap();
    assert_eq!(s.name, "study");
    assert_eq!(s.kind, "runs");
    let runs = plan_runs(&s).unwrap();
    let ids: Vec<&str> = runs.iter().map(|r| r.id.as_str()).collect();
    // 2 × 3 × 2, the costly (label "") runs first, in product order (the first axis outermost)
    assert_eq!(runs.len(), 12);
    assert_eq!(&ids[..3], ["phi35-pga0.25", "phi35-pga0.50", "phi35-pga0.75"], "{ids:?}");
    assert_eq!(ids[6], "phi35-pga0.25-ntn");
    assert!(ids.contains(&"phi40.5-pga0.75-ntn"), "{ids:?}");
    assert_eq!(runs[1].pga, Some(0.5));
    // a listed subset: the union of selections, an axis not named at its first value
    let p = write_study(
        &dir,
        &incline_scene(&rec, 1.0),
        json!({"scene": "scene.json", "axes": [
            {"name": "phi", "field": "joints.phi", "values": [35, 40]},
            {"name": "pga", "field": "pga", "values": [0.25, 0.5]}
        ], "runs": [
            {"axes": {"pga": "*"}},
            {"axes": {"phi": ["phi40"], "pga": "pga0.5"}, "with": {"scene": {"/time/duration": 2.0}}},
            {"axes": {"phi": "phi35", "pga": "pga0.5"}, "with": {"scale": 2.0}}
        ]}),
    );
    let s = Study::load(&p).unwrap();
    let runs = plan_runs(&s).unwrap();
    assert_eq!(runs.iter().map(|r| r.id.as_str()).collect::<Vec<_>>(), ["phi35-pga0.25", "phi35-pga0.5", "phi40-pga0.5"]);
    assert_eq!(runs[1].overrides.len(), 1, "the override joins the run already selected");
    // the plan writes each run's scene: the base scene with its variations, valid, absolute paths
    let files = write_plan(&s, &[], &dir.join("cache"), "jointquake").unwrap();
    assert_eq!(files.scenes.len(), 3);
    assert_eq!(files.changed, 3);
    let sc = jointquake::scene::Scene::load(&dir.join("out/scenes/phi40-pga0.5.json")).unwrap();
    assert_eq!(sc.joints[0].phi, Some(40.0));
    assert_eq!(sc.time.duration, 2.0);
    assert!(sc.geometry.msh.as_ref().unwrap().is_absolute());
    // PGA: the first record scaled to 0.5 g (the record's own PGA is 0.319 g); scale on top
    let peak = jointquake::dynamics::record::Record::read(&rec, 9.81).unwrap().peak();
    let scale = |id: &str| jointquake::scene::Scene::load(&dir.join(format!("out/scenes/{id}.json"))).unwrap().loads.base[0].scale.unwrap();
    assert!((scale("phi40-pga0.5") * peak - 0.5 * 9.81).abs() < 1e-12);
    assert!((scale("phi35-pga0.5") / scale("phi40-pga0.5") - 2.0).abs() < 1e-12);
    // planning again changes no scene (make reruns nothing)
    let again = write_plan(&s, &[], &dir.join("cache"), "jointquake").unwrap();
    assert_eq!(again.changed, 0);
}

#[test]
fn study_file_errors_name_the_file_and_the_field() {
    let dir = scratch("study/errors");
    let axes = json!([{"name": "phi", "field": "joints.phi", "values": [35, 40]}]);
    // unknown key in the study file
    let e = load_err(&dir, json!({"scene": "scene.json", "axes": axes, "run": []}));
    assert!(e.contains("study.json") && e.contains("unknown field `run`"), "{e}");
    // a scene path the scene does not have: deserialised as a Scene, the path named (at plan time)
    let e = plan_err(&dir, json!({"scene": "scene.json", "axes": [{"name": "f", "values": [{"label": "x", "scene": {"/output/framez": true}}]}]}));
    assert!(e.contains("study.json") && e.contains("/output/framez") && e.contains("framez") && e.contains("run x"), "{e}");
    // an index beyond a list
    let e = plan_err(&dir, json!({"scene": "scene.json", "axes": [{"name": "f", "values": [{"label": "x", "scene": {"/materials/5/E": 1e9}}]}]}));
    assert!(e.contains("/materials/5/E") && e.contains("2 entries"), "{e}");
    // mesh parameters on a scene with a ready .msh
    let e = plan_err(&dir, json!({"scene": "scene.json", "axes": [{"name": "h", "field": "set.h", "values": [1]}]}));
    assert!(e.contains("`set`") && e.contains("msh"), "{e}");
    // a joint field the scene's joints do not have
    let e = plan_err(&dir, json!({"scene": "scene.json", "axes": [{"name": "f", "field": "joints.fi", "values": [30]}]}));
    assert!(e.contains("run f30") && e.contains("fi"), "{e}");
    // two runs with one id
    let e = plan_err(&dir, json!({"scene": "scene.json", "axes": [
        {"name": "a", "values": [{"label": "x"}, {"label": ""}]}, {"name": "b", "values": [{"label": ""}, {"label": "x"}]}],
        "runs": [{"axes": {"a": "x", "b": ""}}, {"axes": {"a": "", "b": "x"}}]}));
    assert!(e.contains("same id \"x\""), "{e}");
    // a selection naming an unknown axis or label
    let e = load_err(&dir, json!({"scene": "scene.json", "axes": axes, "runs": [{"axes": {"psi": "*"}}]}));
    assert!(e.contains("runs[0].axes") && e.contains("\"psi\"") && e.contains("phi"), "{e}");
    let e = load_err(&dir, json!({"scene": "scene.json", "axes": axes, "runs": [{"axes": {"phi": "phi36"}}]}));
    assert!(e.contains("\"phi36\"") && e.contains("\"phi35\", \"phi40\""), "{e}");
    // duplicate labels on one axis are refused at load
    let e = load_err(&dir, json!({"scene": "scene.json", "axes": [axes[0], {"name": "m", "values": [{"label": ""}, {"label": ""}]}]}));
    assert!(e.contains("axes[1]") && e.contains("given twice"), "{e}");
    // an object value without a label, a bare value without a field
    let e = load_err(&dir, json!({"scene": "scene.json", "axes": [{"name": "m", "values": [{"pga": 0.2}]}]}));
    assert!(e.contains("axes[0] (\"m\").values[0]") && e.contains("label"), "{e}");
    let e = load_err(&dir, json!({"scene": "scene.json", "axes": [{"name": "m", "values": [0.2]}]}));
    assert!(e.contains("field"), "{e}");
    // an unknown kind, a kind's unknown parameter
    let e = load_err(&dir, json!({"scene": "scene.json", "axes": axes, "report": {"kind": "dams"}}));
    assert!(e.contains("\"dams\"") && e.contains("wedge, incline, dam, runs"), "{e}");
    let e = load_err(&dir, json!({"scene": "scene.json", "axes": axes, "report": {"kind": "incline", "beta": 30, "monitor": "slider", "joint": "J", "betta": 1}}));
    assert!(e.contains("kind \"incline\"") && e.contains("betta"), "{e}");
    let e = load_err(&dir, json!({"scene": "scene.json", "axes": axes, "report": {"kind": "incline", "beta": 30, "monitor": "slidr", "joint": "J"}}));
    assert!(e.contains("\"slidr\""), "{e}");
}

/// The first `t_cut` s of the committed El Centro NS record (its peak, at 2.04 s, kept).
fn cut_record(dir: &Path, t_cut: f64) -> PathBuf {
    let text = std::fs::read_to_string(manifest("pipelines/records/elcentro1940_NS_chopra.txt")).unwrap();
    let mut cut = format!("# first {t_cut} s of pipelines/records/elcentro1940_NS_chopra.txt\n");
    for l in text.lines() {
        let t = l.split_whitespace().next().and_then(|t| t.parse::<f64>().ok());
        if l.starts_with('#') || t.is_some_and(|t| t <= t_cut + 1e-9) {
            cut.push_str(l);
            cut.push('\n');
        }
    }
    let p = dir.join("elcentro_cut.txt");
    std::fs::write(&p, cut).unwrap();
    p
}

#[test]
fn incline_study_plans_runs_with_make_and_reports_against_rigid_newmark() {
    // A small incline study: φ 35° and 40° at PGA 0.5 g on the first 4 s of El Centro NS plus
    // 1 s of free run-out (the full study, pipelines/incline_study.json, runs the whole record),
    // and one run made to fail (dt above the stable step) to show that a failed run stops
    // nothing and is named in the report. Reference: the rigid Newmark block (rigid::newmark,
    // one-way) under the same records; tolerance 5 % (docs/validation.md §6: +0.07 % for φ 35°
    // on the first 6 s).
    let dir = scratch("study/incline");
    let rec = cut_record(&dir, 4.0);
    let p = write_study(
        &dir,
        &incline_scene(&rec, 5.0),
        json!({
            "name": "incline_small",
            "scene": "scene.json",
            "report": {"kind": "incline", "beta": 30, "monitor": "slider", "joint": "J"},
            "axes": [
                {"name": "phi", "field": "joints.phi", "values": [35, 40]},
                {"name": "pga", "field": "pga", "decimals": 2, "values": [0.5]},
                {"name": "dt", "values": [{"label": ""}, {"label": "baddt", "scene": {"/time/dt": 0.01, "/time/courant": null}}]}
            ],
            "runs": [{"axes": {"phi": "*"}}, {"axes": {"phi": "phi35", "dt": "baddt"}}]
        }),
    );
    let (study, kind) = jointquake::studies::load(&p).unwrap();
    let files = write_plan(&study, &kind.steps(), &dir.join("cache"), env!("CARGO_BIN_EXE_jointquake")).unwrap();
    assert_eq!(files.scenes.len(), 3);
    // before any run: the report names every run as missing, and says so
    let r = write_report(&study, kind.as_ref()).unwrap();
    assert_eq!(r.problems.len(), 3, "{:?}", r.problems);
    assert!(r.problems.iter().all(|(_, why)| why.contains("not run")), "{:?}", r.problems);
    // the runs, through the generated Makefile
    let o = std::process::Command::new("make").args(["-s", "-j2", "-f"]).arg(&files.makefile).arg("all").output().expect("make runs");
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "make: {stdout}\n{}", String::from_utf8_lossy(&o.stderr));
    assert!(stdout.contains("run phi35-pga0.50-baddt FAILED") && stdout.contains("stability limit"), "{stdout}");
    let r = write_report(&study, kind.as_ref()).unwrap();
    assert!(r.problems.is_empty(), "{:?}", r.problems);
    let md = std::fs::read_to_string(&r.report).unwrap();
    assert!(md.contains("`phi35-pga0.50-baddt`: ") && md.contains("stability limit"), "{md}");
    let doc: Value = serde_json::from_str(&std::fs::read_to_string(&r.json).unwrap()).unwrap();
    let rows = doc["report"]["runs"].as_array().unwrap();
    let ok: Vec<&Value> = rows.iter().collect();
    assert_eq!(ok.len(), 2, "{rows:?}");
    assert_eq!(doc["report"]["stopped"][0][0], "phi35-pga0.50-baddt");
    for x in &ok {
        let (fem, nm) = (x["fem_slip"].as_f64().unwrap(), x["newmark_slip"].as_f64().unwrap());
        eprintln!("{}: FEM {fem:.4} m, Newmark {nm:.4} m ({:+.2} %)", x["id"], 100.0 * (fem / nm - 1.0));
        assert!(nm > 0.05, "the case slides: {x}");
        assert!((fem / nm - 1.0).abs() < 0.05, "{x}");
    }
    assert!(ok[0]["newmark_slip"].as_f64().unwrap() > ok[1]["newmark_slip"].as_f64().unwrap(), "more friction, less slip");
    assert!(r.charts.iter().all(|c| c.exists()) && !r.charts.is_empty());
    // make again: nothing is rerun (no scene changed, the failed run is not retried)
    write_plan(&study, &kind.steps(), &dir.join("cache"), env!("CARGO_BIN_EXE_jointquake")).unwrap();
    let o = std::process::Command::new("make").args(["-s", "-j2", "-f"]).arg(&files.makefile).arg("all").output().unwrap();
    assert!(String::from_utf8_lossy(&o.stdout).trim().is_empty(), "{}", String::from_utf8_lossy(&o.stdout));
    // a corrupt summary is reported as such, by run, and the command fails naming it
    let s = dir.join("out/runs/phi40-pga0.50/summary.json");
    std::fs::write(&s, "{\"nodes\": 3}").unwrap();
    let r = write_report(&study, kind.as_ref()).unwrap();
    assert_eq!(r.problems.len(), 1, "{:?}", r.problems);
    assert!(r.problems[0].0 == "phi40-pga0.50" && r.problems[0].1.contains("not a run summary"), "{:?}", r.problems);
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_jointquake")).args(["study", "report"]).arg(&p).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("phi40-pga0.50") && err.contains("no results"), "{err}");
    assert!(std::fs::read_to_string(dir.join("out/report.md")).unwrap().contains("## Runs without results"));
}

#[test]
fn history_table_reads_columns_by_name_and_names_what_is_wrong() {
    // The typed history reader (src/output/history.rs): columns by name, `NaN` is a value; a
    // missing column, a truncated row or a non-numeric cell is an error naming the file, the
    // line and the column (never a 0 or a NaN filled in).
    use jointquake::output::history::HistoryTable;
    let dir = scratch("study/history");
    let p = dir.join("h.csv");
    std::fs::write(&p, "# monitor P1\nt,ux,open\n0,1e-3,4\n0.5,NaN,2\n").unwrap();
    let h = HistoryTable::read(&p).unwrap();
    assert_eq!(h.len(), 2);
    assert_eq!(h.column("t").unwrap(), [0.0, 0.5]);
    assert!(h.column("ux").unwrap()[1].is_nan());
    let e = h.column("uy").unwrap_err().to_string();
    assert!(e.contains("h.csv") && e.contains("`uy`") && e.contains("t, ux, open"), "{e}");
    std::fs::write(&p, "t,ux,open\n0,1e-3,4\n0.5,2e-3\n").unwrap();
    let e = HistoryTable::read(&p).unwrap_err().to_string();
    assert!(e.contains("line 3") && e.contains("2 values for 3 columns"), "{e}");
    std::fs::write(&p, "t,ux,open\n0,abc,4\n").unwrap();
    let e = HistoryTable::read(&p).unwrap_err().to_string();
    assert!(e.contains("line 2, column `ux`") && e.contains("abc"), "{e}");
    std::fs::write(&p, "# nothing\n").unwrap();
    assert!(HistoryTable::read(&p).unwrap_err().to_string().contains("no header"));
}

/// Regression (make dam, 4 December 2026: the six pulse runs failed): a record path that an
/// axis patches in (`records/pulse_sin4_T0.6.txt` in pipelines/dam_study.json) was left
/// relative in the run's scene, which the run then resolved against `out/<study>/scenes/`.
/// Paths a study patches in resolve against the study file, like its base scene's.
#[test]
fn study_patch_record_path_resolves_against_the_study_file() {
    let dir = scratch("study/patch_record_path");
    let rec = manifest("pipelines/records/elcentro1940_NS_chopra.txt");
    std::fs::create_dir_all(dir.join("records")).unwrap();
    std::fs::copy(&rec, dir.join("records/patched.txt")).unwrap();
    let p = write_study(
        &dir,
        &incline_scene(&rec, 1.0),
        json!({"scene": "scene.json", "axes": [
            {"name": "level", "values": [
                {"label": "base"},
                {"label": "patched", "scene": {"/loads/base": [{"record": "records/patched.txt", "direction": [1, 0, 0]}]}}
            ]}
        ]}),
    );
    let s = Study::load(&p).unwrap();
    write_plan(&s, &[], &dir.join("cache"), "jointquake").unwrap();
    let sc = jointquake::scene::Scene::load(&dir.join("out/scenes/patched.json")).unwrap();
    let r = sc.loads.base[0].record.as_ref().unwrap();
    assert!(r.is_absolute(), "{}", r.display());
    assert_eq!(std::fs::canonicalize(r).unwrap(), std::fs::canonicalize(dir.join("records/patched.txt")).unwrap());
    // the base scene's own record stays where it was
    let b = jointquake::scene::Scene::load(&dir.join("out/scenes/base.json")).unwrap();
    assert_eq!(std::fs::canonicalize(b.loads.base[0].record.as_ref().unwrap()).unwrap(), std::fs::canonicalize(&rec).unwrap());
}

/// `alone` axis values (src/study/file.rs, `Variation::alone`): runs.mk runs those runs first,
/// one at a time, on ALONE_THREADS threads, and every other run after them. Checked by running
/// the plan's own runs.mk with `make -j3` and a stand-in binary that logs when each run starts
/// and ends (an alone run must never overlap another run, whatever make's job count).
#[test]
fn alone_runs_run_first_one_at_a_time_on_alone_threads_and_never_beside_another_run() {
    use std::os::unix::fs::PermissionsExt;
    let dir = scratch("study/alone");
    let rec = manifest("pipelines/records/elcentro1940_NS_chopra.txt");
    let p = write_study(
        &dir,
        &incline_scene(&rec, 1.0),
        json!({"scene": "scene.json", "axes": [
            {"name": "mesh", "values": [{"label": "small"}, {"label": "big", "cost": 40, "alone": true}]},
            {"name": "pga", "field": "pga", "values": [0.25, 0.5, 0.75]}
        ]}),
    );
    let s = Study::load(&p).unwrap();
    let runs = plan_runs(&s).unwrap();
    assert!(runs[..3].iter().all(|r| r.alone) && runs[3..].iter().all(|r| !r.alone), "alone runs first: {:?}", runs.iter().map(|r| (&r.id, r.alone)).collect::<Vec<_>>());
    let files = write_plan(&s, &[], &dir.join("cache"), "jointquake").unwrap();
    // the stand-in: `BIN run SCENE --out DIR --cache C --threads N --quiet`
    let bin = dir.join("fake-bin");
    let events = dir.join("events.txt");
    std::fs::write(&bin, format!("#!/bin/sh\nid=$(basename \"$2\" .json)\necho \"start $id $8\" >> {e}\nsleep 0.3\necho \"end $id\" >> {e}\n", e = events.display())).unwrap();
    std::fs::set_permissions(&bin, std::fs::Permissions::from_mode(0o755)).unwrap();
    let o = std::process::Command::new("make").args(["-s", "-j3", "-f"]).arg(&files.makefile).arg("runs").arg(format!("BIN={}", bin.display())).arg("ALONE_THREADS=3").output().unwrap();
    assert!(o.status.success(), "make: {}", String::from_utf8_lossy(&o.stderr));
    let log = std::fs::read_to_string(&events).unwrap();
    let lines: Vec<Vec<&str>> = log.lines().map(|l| l.split(' ').collect()).collect();
    assert_eq!(lines.len(), 12, "{log}");
    let mut running: Vec<&str> = Vec::new();
    let (mut started, mut most) = (0, 0);
    for l in &lines {
        match l[0] {
            "start" => {
                let big = l[1].starts_with("big");
                // the three big runs start first, each on ALONE_THREADS threads, the others on 1
                assert_eq!(big, started < 3, "{log}");
                assert_eq!(l[2], if big { "3" } else { "1" }, "{log}");
                running.push(l[1]);
                assert!(running.len() == 1 || running.iter().all(|r| !r.starts_with("big")), "an alone run beside another: {log}");
                most = most.max(running.len());
                started += 1;
            }
            _ => running.retain(|r| *r != l[1]),
        }
    }
    // make -j3 did run the small runs side by side (the check above could not fail otherwise)
    assert!(most >= 2, "the small runs never overlapped: {log}");
}
