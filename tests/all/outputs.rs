//! What a run writes and reports (issue 2 item 7, issue 4 item 4): `summary.json`, monitor
//! histories with their snap distance, the `.pvd` series (also after the run is killed), the
//! progress bar, joint-surface series and histories, and the errors that stop a run
//! (instability, non-finite values). Runs go through `pipeline::run` or the binary.
use crate::common::{fixture, scratch};
use jointquake::dynamics::loads::{ForcePattern, Loads};
use jointquake::dynamics::{ExplicitSolver, Stage, State};
use jointquake::error::StepError;
use jointquake::mesh::Mesh;
use jointquake::model::Model;
use jointquake::pipeline::{run, RunOptions};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

fn write_scene(dir: &Path, scene: &Value) -> PathBuf {
    let p = dir.join("scene.json");
    std::fs::write(&p, serde_json::to_string_pretty(scene).unwrap()).unwrap();
    p
}

/// (time, file) of every DataSet of a `.pvd`, checking the XML is complete.
fn pvd_entries(pvd: &Path) -> Vec<(f64, PathBuf)> {
    let text = std::fs::read_to_string(pvd).unwrap_or_else(|e| panic!("{}: {e}", pvd.display()));
    assert!(text.trim_end().ends_with("</VTKFile>"), "{}: truncated:\n{text}", pvd.display());
    let dir = pvd.parent().unwrap();
    text.lines()
        .filter(|l| l.contains("<DataSet"))
        .map(|l| {
            let attr = |k: &str| {
                let i = l.find(&format!("{k}=\"")).unwrap() + k.len() + 2;
                l[i..i + l[i..].find('"').unwrap()].to_string()
            };
            (attr("timestep").parse().unwrap(), dir.join(attr("file")))
        })
        .collect()
}

/// The repository's venv python (made by `make venv`, which `make test` runs first), if any.
/// Under `make test` (JQ_REQUIRE_VENV=1) its absence is a failure, not a skip.
pub fn venv_python() -> Option<PathBuf> {
    let py = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(".venv/bin/python");
    if py.exists() {
        return Some(py);
    }
    assert!(std::env::var_os("JQ_REQUIRE_VENV").is_none(), "{} is missing (make venv)", py.display());
    eprintln!("note: {} absent, meshio check skipped", py.display());
    None
}

/// A base record (two columns, t [s], a [g]): one sine cycle of 1 g at 25 Hz, dt = 1 ms (the
/// peak, at 10 ms, is a sample).
fn sine_record(dir: &Path) -> PathBuf {
    let p = dir.join("sine.txt");
    let mut s = String::from("# one 25 Hz sine cycle, 1 g\n");
    for i in 0..=40 {
        let t = i as f64 * 1e-3;
        s.push_str(&format!("{t:.4} {:.9e}\n", (2.0 * std::f64::consts::PI * 25.0 * t).sin()));
    }
    std::fs::write(&p, s).unwrap();
    p
}

/// summary.json of a small run (10-hex column fixture, 10 m high, 1 × 1 m, clamped base) under a
/// base record scaled to a target PGA, with damping given as a ratio at two frequencies and a
/// monitor off the nodes. References: steps = round(duration / dt), dt = 0.9 × dt_stable (default
/// Courant); the record scaled so that its peak is 0.2 g exactly (scale 0.2 / record peak);
/// α = 2ξ ω1ω2/(ω1+ω2), β = 2ξ/(ω1+ω2) (docs/scenes.md) to 1e-12; the monitor at (0.3, 0.2, 10)
/// snaps to the corner node (0, 0, 10) at √0.13 m (1e-12); one CSV row per step; the peak
/// displacement, velocity and acceleration (any node, sampled every 10 steps) not below the top
/// monitor's largest values less 1e-3 (the top is where the column moves most; sampling every
/// 10 of ~200 steps per period costs < 1e-3); frames = the `.pvd`'s DataSets, every 10 steps
/// plus the last; wall time ≥ the stage times; energy balance at round-off (< 1e-9).
#[test]
fn summary_json_reports_steps_dt_wall_time_energy_peaks_and_snap() {
    let dir = scratch("outputs/summary");
    let rec = sine_record(&dir);
    let scene = json!({
        "geometry": {"msh": fixture("column_hex.msh")},
        "materials": [{"group": "block:column", "E": 30e9, "nu": 0.2, "rho": 2400}],
        "boundary": [{"group": "bc:base"}],
        "loads": {"base": [{"record": rec, "direction": [1, 0, 0], "pga": 0.2}]},
        "damping": {"ratio": 0.05, "f1": 1.0, "f2": 10.0},
        "time": {"duration": 0.08},
        "output": {"frame_stride": 10, "history_stride": 1, "monitor": [{"name": "top", "point": [0.3, 0.2, 10.0]}]}
    });
    let p = write_scene(&dir, &scene);
    let out = dir.join("out");
    let s = run(&p, &RunOptions { out_dir: Some(out.clone()), ..Default::default() }).unwrap();
    let v: Value = serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    for k in ["steps", "dt", "dt_stable", "wall_time", "energy", "peak_displacement", "peak_velocity", "peak_acceleration", "monitors", "frames", "timings", "critical_element", "notes"] {
        assert!(v.get(k).is_some(), "summary.json lacks `{k}`");
    }
    let dt = v["dt"].as_f64().unwrap();
    assert!((dt - 0.9 * v["dt_stable"].as_f64().unwrap()).abs() < 1e-15 * dt);
    assert_eq!(v["steps"].as_u64().unwrap() as usize, (0.08 / dt).round() as usize);
    let stage_sum: f64 = s.timings.iter().map(|(_, t)| t).sum();
    assert!(v["wall_time"].as_f64().unwrap() >= stage_sum && stage_sum > 0.0);
    let err = v["energy"]["max_error"].as_f64().unwrap();
    assert!(err.is_finite() && err.abs() < 1e-9, "energy error {err}");
    assert!(v["energy"]["external_work"].as_f64().unwrap() != 0.0);

    // base motion: scale to the target PGA, and the damping coefficients from the ratio
    let sc = jointquake::scene::Scene::load(&p).unwrap();
    let model = Model::build(Mesh::from_msh(fixture("column_hex.msh")).unwrap(), &sc).unwrap();
    let (loads, notes) = Loads::build(&model, &sc).unwrap();
    let peak_ag = (0..=40).map(|i| loads.ground_acceleration(i as f64 * 1e-3)[0].abs()).fold(0.0, f64::max);
    assert!((peak_ag - 0.2 * 9.81).abs() < 1e-12 * 9.81, "peak ground acceleration {peak_ag}");
    assert!(notes.iter().any(|n| n.contains("sine.txt") && n.contains("41 samples") && n.contains("PGA 1.0000 g")), "{notes:?}");
    let (w1, w2) = (2.0 * std::f64::consts::PI, 20.0 * std::f64::consts::PI);
    assert!((model.alpha - 2.0 * 0.05 * w1 * w2 / (w1 + w2)).abs() < 1e-12 * model.alpha);
    assert!((model.beta - 2.0 * 0.05 / (w1 + w2)).abs() < 1e-12 * model.beta);

    // monitor snap, reported in the summary and in the CSV header
    let m = &v["monitors"][0];
    assert_eq!(m["position"], json!([0.0, 0.0, 10.0]));
    assert!((m["snap_distance"].as_f64().unwrap() - 0.13f64.sqrt()).abs() < 1e-12);
    let csv = std::fs::read_to_string(out.join("histories/top.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next().unwrap(), jointquake::output::history::MONITOR_HEADER);
    let mons = jointquake::output::history::read_monitors(&out.join("histories")).unwrap();
    assert_eq!((mons[0].name.as_str(), mons[0].requested), ("top", [0.3, 0.2, 10.0]));
    assert!((mons[0].snap_distance - 0.13f64.sqrt()).abs() < 1e-12);
    let rows: Vec<Vec<f64>> = lines.map(|l| l.split(',').map(|x| x.parse().unwrap()).collect()).collect();
    // rows at t[0] … t[N]
    assert_eq!(rows.len(), s.steps + 1);
    assert!(rows.iter().all(|r| r.len() == 10 && r.iter().all(|x| x.is_finite())));
    let max_of = |c: usize| rows.iter().map(|r| (r[c] * r[c] + r[c + 1] * r[c + 1] + r[c + 2] * r[c + 2]).sqrt()).fold(0.0, f64::max);
    for (name, c) in [("peak_displacement", 1), ("peak_velocity", 4), ("peak_acceleration", 7)] {
        let pk = v[name]["value"].as_f64().unwrap();
        let mon = max_of(c);
        eprintln!("{name}: {pk:.4e} (top monitor {mon:.4e})");
        assert!(mon > 0.0 && pk >= (1.0 - 1e-3) * mon, "{name} {pk} below the top monitor's {mon}");
    }

    // frames: every 10 steps and the last; the .pvd lists them in time order
    let entries = pvd_entries(&out.join("scene.pvd"));
    assert_eq!(entries.len(), v["frames"].as_u64().unwrap() as usize);
    assert_eq!(entries.len(), s.steps.div_ceil(10) + usize::from((s.steps - 1) % 10 != 0));
    assert!(entries.windows(2).all(|w| w[0].0 < w[1].0) && entries.iter().all(|(_, f)| f.exists()));
    // the one-screen summary names the same things
    let text = s.to_text();
    for part in ["time step       dt = ", "energy          max balance error", "peak |u|", "peak |v|, |a|", "monitor top", "3.606e-1 m from the requested point", "wall time"] {
        assert!(text.contains(part), "summary text lacks {part:?}:\n{text}");
    }
}

/// Killing a run: the `.pvd` is rewritten whole (temp file + rename) after every frame and every
/// VTU is written to a temp file and renamed, so a run killed (SIGKILL) at any point leaves a
/// complete `.pvd` whose every DataSet is a complete VTU, and monitor rows up to the last frame.
/// The binary runs a long scene (frames every step) and is killed once 5 frames are listed.
#[test]
fn killed_run_leaves_a_valid_pvd_series() {
    let dir = scratch("outputs/killed");
    let scene = json!({
        "geometry": {"msh": fixture("socket_tet.msh")},
        "materials": [{"group": "block:plug", "E": 1e9, "nu": 0.2, "rho": 2000},
                      {"group": "block:socket", "E": 1e9, "nu": 0.2, "rho": 2000}],
        "boundary": [{"group": "bc:bottom"}],
        "loads": {"gravity": {}},
        "equilibrium": {"method": "none"},
        // 4 s at dt 4.09e-5 s: 97 800 frames, under output::recorder::MAX_FRAMES (100 s asked
        // for 2.4 million and is refused before the run since issue 33)
        "time": {"duration": 4.0},
        "output": {"frame_stride": 1, "monitor": [{"name": "top", "point": [0, 0, 1]}]}
    });
    write_scene(&dir, &scene);
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_jointquake"))
        .args(["run", "scene.json", "--out", "out"])
        .current_dir(&dir)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let pvd = dir.join("out/scene.pvd");
    let t0 = std::time::Instant::now();
    loop {
        if let Ok(t) = std::fs::read_to_string(&pvd) {
            if t.matches("<DataSet").count() >= 5 {
                break;
            }
        }
        assert!(child.try_wait().unwrap().is_none(), "the run ended before it could be killed");
        assert!(t0.elapsed().as_secs() < 120, "no frames after 120 s");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let entries = pvd_entries(&pvd);
    assert!(entries.len() >= 5);
    assert!(!dir.join("out/summary.json").exists(), "the run was killed before its end");
    for (_, f) in &entries {
        let t = std::fs::read_to_string(f).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        assert!(t.contains("<VTKFile") && t.trim_end().ends_with("</VTKFile>"), "{} is incomplete", f.display());
    }
    let csv = std::fs::read_to_string(dir.join("out/histories/top.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert!(!rows.is_empty() && rows.iter().all(|r| r.split(',').count() == 10), "monitor rows up to the last frame");
    // an independent reader (meshio) reads the series left behind
    if let Some(py) = venv_python() {
        let o = std::process::Command::new(py).arg(concat!(env!("CARGO_MANIFEST_DIR"), "/scripts/check_vtu.py")).arg(dir.join("out")).output().unwrap();
        assert!(o.status.success(), "check_vtu.py on the killed run:\n{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    }
}

/// The progress bar is drawn only when stderr is a terminal: with stderr piped (as here, and in
/// `make`, CI or a log file) a run without `--quiet` writes nothing to stderr, and the one-screen
/// summary goes to stdout.
#[test]
fn no_progress_bar_when_stderr_is_not_a_terminal() {
    let dir = scratch("outputs/progress");
    let scene = json!({
        "geometry": {"msh": fixture("column_hex.msh")},
        "materials": [{"group": "block:column", "E": 30e9, "nu": 0.2, "rho": 2400}],
        "boundary": [{"group": "bc:base"}],
        "loads": {"gravity": {}},
        "time": {"duration": 0.5},
        "output": {"frames": false}
    });
    write_scene(&dir, &scene);
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_jointquake")).args(["run", "scene.json", "--out", "out"]).current_dir(&dir).output().unwrap();
    assert!(o.status.success());
    assert!(o.stderr.is_empty(), "stderr is not a terminal, yet the run wrote to it: {:?}", String::from_utf8_lossy(&o.stderr));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("scene scene: 44 nodes, 10 elements") && out.contains("summary         out/summary.json"), "{out}");
}

/// A time step above the stability limit (1.2 × dt_stable, which `run` refuses up front, so the
/// solver is driven directly) must stop the run with an error naming the step, the time, the
/// node and its position, and the likely cause. Reference: the central-difference scheme
/// amplifies the highest mode by |λ| > 1 per step beyond 2/ω_max, so the energy measure exceeds
/// 20 × the energy put in within a few hundred steps (the check runs every 10 steps).
#[test]
fn instability_stops_the_run_naming_step_place_and_cause() {
    let sc = crate::common::scene(json!({
        "geometry": {"msh": "unused.msh"},
        "materials": [{"group": "block:column", "E": 30e9, "nu": 0.2, "rho": 2400}],
        "boundary": [{"group": "bc:base"}],
        "loads": {"traction": [{"group": "load:top", "traction": [1e5, 0, 0]}]},
        "time": {"duration": 1.0}
    }));
    let model = Model::build(Mesh::from_msh(fixture("column_hex.msh")).unwrap(), &sc).unwrap();
    let (loads, _) = Loads::build(&model, &sc).unwrap();
    let mut solver = ExplicitSolver::new(&model, 1.2 * model.stable_dt(), 0.05);
    let mut state = State::at_rest(&model, Default::default());
    solver.start_energy(&model, &mut state);
    let err = (0..100_000).find_map(|_| solver.step(&model, &loads, &mut state, Stage::Dynamic, &mut []).err()).expect("the unstable run must stop");
    let msg = err.to_string();
    eprintln!("{msg}");
    match &err {
        StepError::EnergyGrowth { step, node, .. } | StepError::NonFinite { step, node, .. } => {
            assert!(*step > 0 && *step < 1000, "stopped at step {step}");
            assert!(model.mesh.node_tags.contains(&(*node as u64)), "node {node} is a Gmsh tag of the mesh");
            assert!(msg.contains(&format!("step {step} (t = ")) && msg.contains(&format!("node {node} at (")));
        }
        other => panic!("unexpected error {other:?}"),
    }
    assert!(msg.contains("Likely cause") && msg.contains("time step is above the limit"), "{msg}");
}

/// A non-finite value (here a NaN nodal force, which a scene cannot hold but a bug could make)
/// stops the run at the step where it appears, naming the node (Gmsh tag), its position and the
/// likely cause.
#[test]
fn non_finite_value_stops_the_run_naming_the_node() {
    let sc = crate::common::scene(json!({
        "geometry": {"msh": "unused.msh"},
        "materials": [{"group": "block:column", "E": 30e9, "nu": 0.2, "rho": 2400}],
        "boundary": [{"group": "bc:base"}],
        "time": {"duration": 1.0}
    }));
    let model = Model::build(Mesh::from_msh(fixture("column_hex.msh")).unwrap(), &sc).unwrap();
    let (node, _) = model.mesh.nearest_node([1.0, 1.0, 10.0]).unwrap();
    let loads = Loads { patterns: vec![ForcePattern { forces: vec![(node, [f64::NAN, 0.0, 0.0])], ramp: 0.0 }], ..Default::default() };
    let mut solver = ExplicitSolver::new(&model, 0.9 * model.stable_dt(), 0.05);
    let mut state = State::at_rest(&model, Default::default());
    solver.start_energy(&model, &mut state);
    for _ in 0..5 {
        solver.step(&model, &Loads::default(), &mut state, Stage::Dynamic, &mut []).unwrap();
    }
    let err = solver.step(&model, &loads, &mut state, Stage::Dynamic, &mut []).unwrap_err();
    let msg = err.to_string();
    eprintln!("{msg}");
    let tag = model.mesh.node_tags[node];
    assert!(matches!(err, StepError::NonFinite { step: 5, .. }), "{err:?}");
    assert!(msg.contains("non-finite displacement at step 5") && msg.contains(&format!("node {tag} at (1.000, 1.000, 10.000)")) && msg.contains("Likely cause"), "{msg}");
}

/// Joint outputs of a run (issue 4 item 4): the slider of the incline fixture released on
/// μ = 0.3 without relaxation (sliding from rest), NTS, 0.05 s with a frame every 100 steps.
/// Checked: `joints/J.pvd` lists exactly as many frames as the volume series, at increasing
/// times (regression: the end of the run wrote the last joint frame twice, at the same time);
/// every joint VTU has the documented point fields on the 12 slave nodes; the CSV has the
/// documented columns, one row per step, pairs per state summing to the slave nodes and at
/// least one Gauss–Seidel sweep once in contact; `summary.json` carries the joint maxima, the
/// sweeps and the search events, and its max slip equals the CSV's largest. Physics reference
/// (the first 0.05 s include the elastic start-up of a suddenly loaded block): the slip
/// ½ g (sin β − μ cos β) t² = 2.95e-3 m at t = 0.05 s within 3 % (measured +1.2 %).
#[test]
fn joint_outputs_series_history_and_summary() {
    let dir = scratch("outputs/joints");
    let scene = json!({
        "geometry": {"msh": fixture("incline_hex.msh")},
        "materials": [{"group": "block:base", "E": 1e10, "nu": 0.2, "rho": 2500.0},
                      {"group": "block:slider", "E": 1e10, "nu": 0.2, "rho": 2500.0}],
        "boundary": [{"group": "bc:base"}],
        "joints": [{"name": "J", "master": "joint:J:base", "slave": "joint:J:slider", "mu": 0.3}],
        "loads": {"gravity": {}},
        "equilibrium": {"method": "none"},
        "time": {"duration": 0.05},
        "output": {"frame_stride": 100, "history_stride": 1}
    });
    let p = write_scene(&dir, &scene);
    let out = dir.join("out");
    let s = run(&p, &RunOptions { out_dir: Some(out.clone()), ..Default::default() }).unwrap();
    assert_eq!(s.joint_series, vec![out.join("joints/J.pvd")]);
    let joint = pvd_entries(&out.join("joints/J.pvd"));
    let volume = pvd_entries(&out.join("scene.pvd"));
    assert_eq!(joint.len(), volume.len(), "one joint frame per volume frame");
    assert_eq!(joint.len(), s.frames);
    assert!(joint.windows(2).all(|w| w[0].0 < w[1].0), "joint frame times must increase: {:?}", joint.iter().map(|e| e.0).collect::<Vec<_>>());
    for (_, f) in &joint {
        let t = std::fs::read_to_string(f).unwrap();
        assert!(t.contains("NumberOfPoints=\"12\""), "{}: 12 slave nodes", f.display());
        for name in ["displacement", "normal", "gap", "opening", "slip", "tangential_displacement", "normal_traction", "shear_traction", "state", "lost", "lost_travel", "tributary_area", "state_label_slip"] {
            assert!(t.contains(&format!("Name=\"{name}\"")), "{} lacks {name}", f.display());
        }
    }
    let csv = std::fs::read_to_string(out.join("histories/joint_J.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next().unwrap(), jointquake::output::joints::JOINT_HEADER);
    let rows: Vec<Vec<f64>> = lines.map(|l| l.split(',').map(|x| x.parse().unwrap()).collect()).collect();
    assert_eq!(rows.len(), s.steps + 1);
    for r in &rows {
        assert_eq!(r[5] + r[6] + r[7] + r[8], 12.0, "pairs per state must sum to the slave nodes: {r:?}");
    }
    let last = rows.last().unwrap();
    assert!(last[7] > 0.0 && last[9] >= 1.0 && last[10] > 0.0, "sliding pairs, Gauss–Seidel sweeps and a normal force at the end: {last:?}");
    let v: Value = serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let j = &v["joints"][0];
    for k in ["name", "method", "max_opening", "max_opening_t", "max_slip", "max_tangential_displacement", "max_penetration", "max_sweeps", "gs_tolerance", "unconverged_steps", "events", "ntn_max_distance"] {
        assert!(j.get(k).is_some(), "summary.json joints[0] lacks `{k}`");
    }
    for k in ["recentred", "perimeter_kept", "widened_layer2", "fresh_searches", "lost", "projection_failures"] {
        assert!(j["events"].get(k).is_some(), "events lack `{k}`");
    }
    assert!(j["max_sweeps"].as_u64().unwrap() >= 1);
    // documented: 1e-12 × the joint size (diagonal of the bounding box of both surfaces)
    let joints = jointquake::contact::joint::build_joints(&Mesh::from_msh(fixture("incline_hex.msh")).unwrap(), &jointquake::scene::Scene::load(&p).unwrap()).unwrap();
    let tol = 1e-12 * joints[0].tag.size;
    assert!((j["gs_tolerance"].as_f64().unwrap() - tol).abs() < 1e-15 * tol, "{} vs {tol}", j["gs_tolerance"]);
    let csv_max_slip = rows.iter().map(|r| r[2]).fold(0.0, f64::max);
    assert!((j["max_slip"].as_f64().unwrap() - csv_max_slip).abs() <= 1e-9 * csv_max_slip, "{} vs {csv_max_slip}", j["max_slip"]);
    let b = 30f64.to_radians();
    let exact = 0.5 * 9.81 * (b.sin() - 0.3 * b.cos()) * 0.05f64.powi(2);
    let slip = j["max_tangential_displacement"].as_f64().unwrap();
    eprintln!("joint J after 0.05 s: max |d_t| {slip:.4e} m, exact sliding {exact:.4e} m, max slip {csv_max_slip:.4e} m");
    assert!((slip / exact - 1.0).abs() < 0.03, "slip {slip} vs {exact}");
    // meshio reads the joint series and checks its arrays (scripts/check_vtu.py)
    if let Some(py) = venv_python() {
        let o = std::process::Command::new(py).arg(concat!(env!("CARGO_MANIFEST_DIR"), "/scripts/check_vtu.py")).arg(&out).output().unwrap();
        assert!(o.status.success(), "check_vtu.py:\n{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    }
}

/// Every committed scene loads and validates (unknown keys, exclusive fields, ranges), so a
/// scene that drifts from the code fails here rather than at `make demo`.
#[test]
fn every_committed_scene_loads() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("pipelines");
    let mut n = 0;
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "json") {
            if p.file_stem().is_some_and(|s| s.to_string_lossy().ends_with("_study")) {
                // a study file (pipelines/wedge_study.json) names a scene; it must load and so must its scene
                let (st, _) = jointquake::studies::load(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
                jointquake::scene::Scene::load(&st.scene).unwrap_or_else(|e| panic!("{}: {e}", st.scene.display()));
            } else if p.file_stem().is_some_and(|s| s.to_string_lossy().ends_with("_reference")) {
                // an extrapolated reference (pipelines/dam_reference.json, `jointquake study
                // extrapolate`) is not a scene: it must read back through its typed reader
                jointquake::studies::dam::reference::DamReference::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            } else {
                jointquake::scene::Scene::load(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            }
            n += 1;
        }
    }
    assert!(n >= 4, "{n} scenes");
}

/// Regression: the end of a run wrote the last joint frame a second time (same time, one more
/// frame than the volume series: 35 against 34 on pipelines/impact.json), so ParaView showed a
/// duplicated time step and the joint and volume series disagreed on the frame count.
#[test]
fn regression_joint_series_repeated_its_last_frame() {
    let out = scratch("outputs/impact_frames");
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let s = run(&root.join("pipelines/impact.json"), &RunOptions { out_dir: Some(out.clone()), ..Default::default() }).unwrap();
    let joint = pvd_entries(&out.join("joints/J.pvd"));
    assert_eq!(joint.len(), s.frames, "joint frames vs volume frames");
    assert!(joint.windows(2).all(|w| w[0].0 < w[1].0), "repeated joint frame time");
}

/// `duration: 0` runs only the gravity equilibrium (docs/scenes.md): the run writes that state
/// as one frame (volume and joint series) and one history row, so the `.pvd` files the summary
/// lists exist. Scene:
/// pipelines/tag_boxes.json (two boxes on a non-conforming joint) with gravity added. Reference:
/// at equilibrium the joint carries the upper box's weight ρ g V = 2400 × 9.81 × 0.5 N; tolerance
/// 1e-3 (the relaxation stops at 1e-6 of the gravity load; measured 1e-6).
#[test]
fn zero_duration_writes_the_equilibrium_frame() {
    let dir = scratch("outputs/zero_duration");
    let mut scene: Value = serde_json::from_str(&std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/pipelines/tag_boxes.json")).unwrap()).unwrap();
    scene["geometry"]["msh"] = json!(fixture("boxes_hex_4x3.msh"));
    scene["loads"] = json!({"gravity": {}});
    let p = write_scene(&dir, &scene);
    let out = dir.join("out");
    let s = run(&p, &RunOptions { out_dir: Some(out.clone()), ..Default::default() }).unwrap();
    assert_eq!((s.steps, s.frames), (0, 1));
    assert!(s.pvd.as_ref().unwrap().exists() && s.joint_series.iter().all(|p| p.exists()));
    assert_eq!(pvd_entries(&out.join("tag_boxes.pvd")).len(), 1);
    assert_eq!(pvd_entries(&out.join("joints/J.pvd")).len(), 1);
    let vtu = std::fs::read_to_string(out.join("joints/J_00000.vtu")).unwrap();
    assert!(vtu.contains("Name=\"normal_traction\""));
    let csv = std::fs::read_to_string(out.join("histories/joint_J.csv")).unwrap();
    let row: Vec<f64> = csv.lines().nth(1).expect("one joint history row").split(',').map(|x| x.parse().unwrap()).collect();
    let weight = 2400.0 * 9.81 * 0.5;
    eprintln!("joint normal force at equilibrium {:.2} N, upper box weight {weight:.2} N", row[10]);
    assert!((row[10] / weight - 1.0).abs() < 1e-3, "joint normal force {} vs weight {weight}", row[10]);
    if let Some(py) = venv_python() {
        let o = std::process::Command::new(py).arg(concat!(env!("CARGO_MANIFEST_DIR"), "/scripts/check_vtu.py")).arg(&out).output().unwrap();
        assert!(o.status.success(), "check_vtu.py:\n{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    }
}

/// The other half: on a terminal (a pseudo-terminal from util-linux `script`) the run draws its
/// progress bar (`… steps, t = … s, eta …`), and `--quiet` suppresses it. Skipped with a note
/// where `script` is not installed.
#[test]
fn progress_bar_on_a_terminal_unless_quiet() {
    if !Path::new("/usr/bin/script").exists() {
        eprintln!("note: /usr/bin/script absent, terminal progress bar not checked");
        return;
    }
    let dir = scratch("outputs/progress_tty");
    let scene = json!({
        "geometry": {"msh": fixture("column_hex.msh")},
        "materials": [{"group": "block:column", "E": 30e9, "nu": 0.2, "rho": 2400}],
        "boundary": [{"group": "bc:base"}],
        "time": {"duration": 20.0},
        "output": {"frames": false}
    });
    write_scene(&dir, &scene);
    let tty = |extra: &str| {
        let cmd = format!("{} run scene.json --out out{extra}", env!("CARGO_BIN_EXE_jointquake"));
        let o = std::process::Command::new("/usr/bin/script").args(["-qec", &cmd, "/dev/null"]).current_dir(&dir).output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    let shown = tty("");
    assert!(shown.contains(" steps, t = ") && shown.contains("eta"), "no progress bar on a terminal:\n{shown}");
    let quiet = tty(" --quiet");
    assert!(!quiet.contains(" steps, t = ") && quiet.contains("summary "), "--quiet still drew a bar:\n{quiet}");
}

/// Issue 19 §1 (histories on the same clock): a history row stamped t carries the state at t,
/// and the last row is the state at t[N] = N dt. Reference: a free block under gravity g from rest
/// (no supports, `equilibrium: none`) under the scheme's start u[−1] = u[0] = 0 (rest at
/// t = −dt/2) has the exact discrete solution u[n] = −½ g t_n (t_n + dt), v[n] = −g (t_n + dt/2),
/// a[n] = −g (t_n = n dt), so every row must match it to round-off (1e-9 relative to the fall at
/// the end); a row one step off (u[n∓1] stamped t_n) misses by g t dt, above 1e-3 of the fall.
/// Before the fix the last row was at t[N − 1] and the joint rows one step ahead of the
/// monitors'.
#[test]
fn histories_on_the_same_clock_last_row_is_the_state_at_step_n() {
    let dir = scratch("outputs/same_clock");
    let scene = json!({
        "geometry": {"msh": fixture("column_hex.msh")},
        "materials": [{"group": "block:column", "E": 30e9, "nu": 0.2, "rho": 2400}],
        "loads": {"gravity": {}},
        "equilibrium": {"method": "none"},
        "time": {"duration": 0.01},
        "output": {"frame_stride": 7, "history_stride": 3, "monitor": [{"name": "top", "point": [0, 0, 10]}]}
    });
    let p = write_scene(&dir, &scene);
    let out = dir.join("out");
    let s = run(&p, &RunOptions { out_dir: Some(out.clone()), ..Default::default() }).unwrap();
    let h = jointquake::output::history::HistoryTable::read(&out.join("histories/top.csv")).unwrap();
    let (t, uz, vz, az) = (h.column("t").unwrap(), h.column("uz").unwrap(), h.column("vz [m/s]").unwrap(), h.column("az").unwrap());
    let n = s.steps;
    assert!(n > 20);
    // rows at 0, 3, 6, … and N
    assert!(close(*t.last().unwrap(), n as f64 * s.dt));
    assert_eq!(t.len(), n / 3 + 1 + usize::from(n % 3 != 0));
    let g = 9.81;
    let scale = 0.5 * g * (n as f64 * s.dt).powi(2);
    let dt = s.dt;
    for i in 0..t.len() {
        let exact = -0.5 * g * t[i] * (t[i] + dt);
        assert!((uz[i] - exact).abs() < 1e-9 * scale, "row {i} at t = {}: uz {} vs {exact}", t[i], uz[i]);
        if i == 0 {
            // t = 0: u[−1] = u[0] is the start, not a solution value (v, a there are g dt / 4, g / 2)
            continue;
        }
        assert!((vz[i] + g * (t[i] + 0.5 * dt)).abs() < 1e-9 * g * t[t.len() - 1] + 1e-12, "row {i}: vz {}", vz[i]);
        assert!((az[i] + g).abs() < 1e-6 * g, "row {i}: az {}", az[i]);
    }
    // the volume series ends at t[N] too
    let frames = pvd_entries(&out.join("scene.pvd"));
    assert!(close(frames.last().unwrap().0, n as f64 * s.dt));
    assert_eq!(frames.len(), s.frames);
}

/// Issue 19 §1 (joint and volume frames on one time axis): with a joint, the volume series, the
/// joint series, the monitor history and the joint history all carry the same times (before the
/// fix the joint frames were stamped t + dt: ParaView's slider had twice the positions). Scene:
/// the sliding block on the 30° incline fixture.
#[test]
fn joint_and_volume_frames_on_one_time_axis() {
    let dir = scratch("outputs/one_axis");
    let scene = json!({
        "geometry": {"msh": fixture("incline_hex.msh")},
        "materials": [{"group": "block:base", "E": 1e10, "nu": 0.2, "rho": 2500.0},
                      {"group": "block:slider", "E": 1e10, "nu": 0.2, "rho": 2500.0}],
        "boundary": [{"group": "bc:base"}],
        "joints": [{"name": "J", "master": "joint:J:base", "slave": "joint:J:slider", "mu": 0.3}],
        "loads": {"gravity": {}},
        "equilibrium": {"method": "none"},
        "time": {"duration": 0.01},
        "output": {"frame_stride": 9, "history_stride": 4, "monitor": [{"name": "m", "point": [0, 0, 0], "group": "block:slider"}]}
    });
    let p = write_scene(&dir, &scene);
    let out = dir.join("out");
    let s = run(&p, &RunOptions { out_dir: Some(out.clone()), ..Default::default() }).unwrap();
    let vt: Vec<f64> = pvd_entries(&out.join("scene.pvd")).iter().map(|e| e.0).collect();
    let jt: Vec<f64> = pvd_entries(&out.join("joints/J.pvd")).iter().map(|e| e.0).collect();
    assert_eq!(vt, jt, "joint frames must carry the volume frames' times");
    assert!(vt[0] == 0.0 && close(*vt.last().unwrap(), s.steps as f64 * s.dt));
    let read = |n: &str| jointquake::output::history::HistoryTable::read(&out.join("histories").join(n)).unwrap();
    assert_eq!(read("m.csv").column("t").unwrap(), read("joint_J.csv").column("t").unwrap(), "monitor and joint rows on one clock");
    assert!(close(*read("m.csv").column("t").unwrap().last().unwrap(), s.steps as f64 * s.dt));
    if let Some(py) = venv_python() {
        let o = std::process::Command::new(py).arg(concat!(env!("CARGO_MANIFEST_DIR"), "/scripts/check_vtu.py")).arg(&out).output().unwrap();
        assert!(o.status.success(), "check_vtu.py:\n{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    }
}

/// Issue 19 §1 (monitor CSVs): the first line is the column header with units (ParaView's CSV
/// reader and spreadsheets take the first line as the header); the snap metadata is in
/// `histories/monitors.json`; readers find columns with or without the unit.
#[test]
fn monitor_csv_first_line_is_the_header_with_units() {
    use jointquake::output::history::{HistoryTable, MONITOR_HEADER};
    let dir = scratch("outputs/csv_header");
    let scene = json!({
        "geometry": {"msh": fixture("column_hex.msh")},
        "materials": [{"group": "block:column", "E": 30e9, "nu": 0.2, "rho": 2400}],
        "boundary": [{"group": "bc:base"}],
        "loads": {"gravity": {}},
        "time": {"duration": 0.002},
        "output": {"frames": false, "monitor": [{"name": "top", "point": [0.3, 0.2, 10.0]}]}
    });
    let p = write_scene(&dir, &scene);
    let out = dir.join("out");
    run(&p, &RunOptions { out_dir: Some(out.clone()), ..Default::default() }).unwrap();
    let text = std::fs::read_to_string(out.join("histories/top.csv")).unwrap();
    assert_eq!(text.lines().next().unwrap(), MONITOR_HEADER);
    assert!(MONITOR_HEADER.starts_with("t [s],ux [m],") && MONITOR_HEADER.contains("vx [m/s]") && MONITOR_HEADER.contains("ax [m/s^2]"));
    assert!(!text.contains('#'), "no comment lines");
    let h = HistoryTable::read(&out.join("histories/top.csv")).unwrap();
    assert_eq!(h.column("ux").unwrap(), h.column("ux [m]").unwrap());
    let m = jointquake::output::history::read_monitors(&out.join("histories")).unwrap();
    assert_eq!(m.len(), 1);
    assert!((m[0].snap_distance - 0.13f64.sqrt()).abs() < 1e-12 && m[0].position == [0.0, 0.0, 10.0]);
}

/// Issue 19 §1 (crash-safe histories): the readers ignore an incomplete last line (a run killed
/// or a disk filled mid-row: ParaView read a cut `3.78` as `3`), and still refuse a short row
/// that is not the last.
#[test]
fn crash_safe_histories_readers_ignore_an_incomplete_last_line() {
    use jointquake::output::history::HistoryTable;
    use jointquake::output::joints::{read_joint_forces, JOINT_FORCES_HEADER};
    let dir = scratch("outputs/cut_row");
    let p = dir.join("h.csv");
    std::fs::write(&p, "t [s],ux [m]\n0,1\n0.5,3.78\n1.0,3").unwrap();
    let h = HistoryTable::read(&p).unwrap();
    assert_eq!(h.column("ux").unwrap(), [1.0, 3.78]);
    std::fs::write(&p, "t [s],ux [m]\n0,1\n0.5\n1.0,3\n").unwrap();
    assert!(HistoryTable::read(&p).unwrap_err().to_string().contains("line 3"));
    let f = dir.join("f.csv");
    let row = "0.1,1,0,0,0,1,0,0,1,0,0,0,0,0,0,0,1,0,1,1e-13,0,0,0";
    std::fs::write(&f, format!("{JOINT_FORCES_HEADER}\n{row}\n0.2,1,0,0")).unwrap();
    assert_eq!(read_joint_forces(&f).unwrap().len(), 1);
}

/// Issue 19 §1 (crash-safe histories, Ctrl-C / SIGTERM): a run sent SIGTERM prints one line,
/// finishes its current output (volume and joint frame at the same time, whole history rows)
/// and writes summary.json marked `interrupted`, exit status 130.
#[test]
fn sigterm_finishes_the_frame_and_marks_the_summary_interrupted() {
    let dir = scratch("outputs/sigterm");
    let scene = json!({
        "geometry": {"msh": fixture("incline_hex.msh")},
        "materials": [{"group": "block:base", "E": 1e10, "nu": 0.2, "rho": 2500.0},
                      {"group": "block:slider", "E": 1e10, "nu": 0.2, "rho": 2500.0}],
        "boundary": [{"group": "bc:base"}],
        "joints": [{"name": "J", "master": "joint:J:base", "slave": "joint:J:slider", "mu": 0.3}],
        "loads": {"gravity": {}},
        "equilibrium": {"method": "none"},
        "time": {"duration": 100.0},
        "output": {"frame_stride": 50, "monitor": [{"name": "m", "point": [0, 0, 0], "group": "block:slider"}]}
    });
    write_scene(&dir, &scene);
    let child = std::process::Command::new(env!("CARGO_BIN_EXE_jointquake"))
        .args(["run", "scene.json", "--out", "out", "--quiet"])
        .current_dir(&dir)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let pvd = dir.join("out/scene.pvd");
    let t0 = std::time::Instant::now();
    while std::fs::read_to_string(&pvd).map(|t| t.matches("<DataSet").count()).unwrap_or(0) < 3 {
        assert!(t0.elapsed().as_secs() < 120, "no frames after 120 s");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let st = std::process::Command::new("kill").args(["-TERM", &child.id().to_string()]).status().unwrap();
    assert!(st.success());
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(130), "stderr: {err}");
    assert_eq!(err.lines().filter(|l| l.starts_with("interrupted:")).count(), 1, "{err}");
    let s = jointquake::pipeline::RunSummary::read(&dir.join("out")).expect("summary.json written");
    let t_stop = s.interrupted.expect("marked interrupted");
    let vt: Vec<f64> = pvd_entries(&pvd).iter().map(|e| e.0).collect();
    let jt: Vec<f64> = pvd_entries(&dir.join("out/joints/J.pvd")).iter().map(|e| e.0).collect();
    assert_eq!(vt, jt);
    assert!(close(*vt.last().unwrap(), t_stop), "the last frame is the interrupted output");
    for n in ["m.csv", "joint_J.csv"] {
        let p = dir.join("out/histories").join(n);
        assert!(std::fs::read_to_string(&p).unwrap().ends_with('\n'), "{n}: whole rows");
        let h = jointquake::output::history::HistoryTable::read(&p).unwrap();
        assert!(close(*h.column("t").unwrap().last().unwrap(), t_stop), "{n}: last row at the stop");
    }
}

/// Issue 19 §1 (compressed binary VTU): frames are binary, zlib-compressed in VTK's layout (one
/// header per array), no ascii arrays; the file is several times smaller than the raw Float64
/// displacement alone would be as text. meshio reads them (check_vtu.py in the other tests).
#[test]
fn compressed_binary_vtu_frames() {
    let dir = scratch("outputs/zlib");
    let scene = json!({
        "geometry": {"msh": fixture("socket_tet.msh")},
        "materials": [{"group": "block:plug", "E": 1e9, "nu": 0.2, "rho": 2000},
                      {"group": "block:socket", "E": 1e9, "nu": 0.2, "rho": 2000}],
        "boundary": [{"group": "bc:bottom"}],
        "loads": {"gravity": {}},
        "equilibrium": {"method": "none"},
        "time": {"duration": 0.001},
    });
    let p = write_scene(&dir, &scene);
    let out = dir.join("out");
    let s = run(&p, &RunOptions { out_dir: Some(out.clone()), ..Default::default() }).unwrap();
    let last = pvd_entries(s.pvd.as_ref().unwrap()).pop().unwrap().1;
    let text = std::fs::read_to_string(&last).unwrap();
    assert!(text.contains("header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\""), "{}", &text[..200]);
    assert!(!text.contains("format=\"ascii\""));
    assert_eq!(text.matches("format=\"binary\"").count(), 3 + 4 + 1 + 3, "3 point, 4 cell arrays, points, 3 cell arrays");
    if let Some(py) = venv_python() {
        let o = std::process::Command::new(py).arg(concat!(env!("CARGO_MANIFEST_DIR"), "/scripts/check_vtu.py")).arg(&out).output().unwrap();
        assert!(o.status.success(), "check_vtu.py:\n{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    }
}

/// Issue 19 §1 (history default): without `history_stride` / `history_interval` a row every
/// 1 ms (DEFAULT_HISTORY_INTERVAL), finer for runs under 1 s (at least 1000 rows), never below a
/// step; `history_interval` sets the time between rows; both together are refused.
#[test]
fn history_default_is_a_time_interval() {
    use jointquake::output::recorder::history_stride;
    use jointquake::scene::OutputSpec;
    let d = OutputSpec::default();
    assert_eq!(history_stride(&d, 1e-5, 10.0), 100);
    assert_eq!(history_stride(&d, 1e-5, 0.1), 10);
    assert_eq!(history_stride(&d, 1e-3, 0.1), 1);
    let i = OutputSpec { history_interval: Some(0.01), ..OutputSpec::default() };
    assert_eq!(history_stride(&i, 1e-4, 10.0), 100);
    let dir = scratch("outputs/history_both");
    let scene = json!({
        "geometry": {"msh": fixture("column_hex.msh")},
        "materials": [{"group": "block:column", "E": 30e9, "nu": 0.2, "rho": 2400}],
        "boundary": [{"group": "bc:base"}],
        "time": {"duration": 0.01},
        "output": {"history_stride": 2, "history_interval": 0.01}
    });
    let e = run(&write_scene(&dir, &scene), &RunOptions::default()).unwrap_err().to_string();
    assert!(e.contains("history_stride") && e.contains("history_interval"), "{e}");
}

/// Times as written (10 significant digits in the `.pvd` and the CSVs) against computed ones.
fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * b.abs().max(1e-30)
}

/// The boxes fixture (1 × 1 m upper box on a 1 × 1 m lower box, fixed base) with gravity pulling
/// along x as much as down and no friction: the upper box slides off the lower one in about
/// √(2 m / (g/√2)) = 0.54 s.
fn sliding_off_scene(on_exit: &str, duration: f64) -> Value {
    json!({
        "geometry": {"msh": fixture("boxes_hex_4x3.msh")},
        "materials": [{"group": "block:lower", "E": 1e9, "nu": 0.2, "rho": 2400},
                      {"group": "block:upper", "E": 1e9, "nu": 0.2, "rho": 2400}],
        "boundary": [{"group": "bc:base"}],
        "joints": [{"name": "J", "master": "joint:J:lower", "slave": "joint:J:upper", "mu": 0.0, "on_exit": on_exit}],
        "loads": {"gravity": {"direction": [1, 0, -1]}},
        "equilibrium": {"method": "none"},
        "time": {"duration": duration},
        // the block sinks where "report" loses its nodes: the run is about the warnings, so it
        // accepts the penetration that would otherwise end it with an error (issue 34)
        "output": {"frame_interval": 0.1, "allow_penetration": true}
    })
}

/// Issue 19 §2 (`on_exit: "report"` without widening) and §1 (lost nodes): a block that slides
/// off its base loses its contact; lost node-steps above LOST_WARN_FRACTION (1 %) give a warning
/// in summary.json and on the terminal naming the joint and the fix, the joint history counts the
/// lost pairs, and the joint series' `lost_travel` (slip continued) is about the slide beyond the
/// edge, not frozen. Reference: free sliding at g/√2 along x (μ = 0) for 0.8 s: 2.2 m, so every
/// node is off the 1 m base; the largest lost travel must exceed 0.5 m.
#[test]
fn on_exit_report_lost_nodes_warn_and_lost_flag() {
    for on_exit in ["report", "widen"] {
        let dir = scratch(&format!("outputs/lost_{on_exit}"));
        let p = write_scene(&dir, &sliding_off_scene(on_exit, 0.8));
        let out = dir.join("out");
        let s = run(&p, &RunOptions { out_dir: Some(out.clone()), ..Default::default() }).unwrap();
        let w = s.warnings.iter().find(|w| w.contains("joint J") && w.contains("node-steps lost")).unwrap_or_else(|| panic!("{on_exit}: no lost-contact warning in {:?}", s.warnings));
        assert_eq!(w.contains("on_exit \"report\""), on_exit == "report", "{w}");
        assert!(s.to_text().contains("WARNING") && s.to_text().contains("node-steps lost"));
        assert!(s.joints[0].max_lost_travel > 0.5, "{on_exit}: lost travel {}", s.joints[0].max_lost_travel);
        let h = jointquake::output::history::HistoryTable::read(&out.join("histories/joint_J.csv")).unwrap();
        assert_eq!(*h.column("lost").unwrap().last().unwrap() as usize, s.joints[0].slave_nodes, "every node off the base at the end");
        assert!(*h.column("max_lost_travel").unwrap().last().unwrap() > 0.5);
        if let Some(py) = venv_python() {
            let o = std::process::Command::new(py).arg(concat!(env!("CARGO_MANIFEST_DIR"), "/scripts/check_vtu.py")).arg(&out).output().unwrap();
            assert!(o.status.success(), "check_vtu.py:\n{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
        }
    }
    // a block resting on its base (gravity straight down) keeps its contact: no warning
    let dir = scratch("outputs/lost_none");
    let mut sc = sliding_off_scene("report", 0.05);
    sc["loads"]["gravity"]["direction"] = json!([0, 0, -1]);
    let s = run(&write_scene(&dir, &sc), &RunOptions { out_dir: Some(dir.join("out")), ..Default::default() }).unwrap();
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
}

/// Issue 19 §2 (NTN on non-conforming meshes): the boxes fixture's joint is non-conforming (4 × 4
/// against 3 × 3 faces); with NTN the run warns with the largest slave-to-O distance and its
/// fraction of the face size (above NTN_WARN_FRACTION, 10 %), and the summary text says what
/// NTN's penetration is measured against.
#[test]
fn ntn_non_conforming_joint_warns_with_the_offset() {
    let dir = scratch("outputs/ntn_offset");
    let mut sc = sliding_off_scene("widen", 0.01);
    sc["joints"][0]["method"] = json!("ntn");
    let s = run(&write_scene(&dir, &sc), &RunOptions { out_dir: Some(dir.join("out")), ..Default::default() }).unwrap();
    let j = &s.joints[0];
    assert!(j.ntn_max_distance > 0.1 * j.face_size, "{} vs face {}", j.ntn_max_distance, j.face_size);
    assert!(s.warnings.iter().any(|w| w.contains("NTN on a non-conforming joint") && w.contains("face size")), "{:?}", s.warnings);
    assert!(s.to_text().contains("penetration is measured against O"));
}

/// Issue 19 §2 (Gauss–Seidel cap): a step that stops at the sweep cap leaves its residual in the
/// summary (`max_gs_residual`), and a residual above GS_WARN_FACTOR (10) × the tolerance warns.
/// The sliding incline block with the cap forced to 1 sweep.
#[test]
fn gauss_seidel_cap_reports_the_residual_and_warns() {
    use jointquake::output::recorder::Recorder;
    use jointquake::problem::Problem;
    use jointquake::simulation::Simulation;
    let dir = scratch("outputs/gs_cap");
    let scene = json!({
        "geometry": {"msh": fixture("incline_hex.msh")},
        "materials": [{"group": "block:base", "E": 1e10, "nu": 0.2, "rho": 2500.0},
                      {"group": "block:slider", "E": 1e10, "nu": 0.2, "rho": 2500.0}],
        "boundary": [{"group": "bc:base"}],
        "joints": [{"name": "J", "master": "joint:J:base", "slave": "joint:J:slider", "mu": 0.3}],
        "loads": {"gravity": {}},
        "equilibrium": {"method": "none"},
        "time": {"duration": 0.01},
        "output": {"frames": false}
    });
    let p = write_scene(&dir, &scene);
    let sc = jointquake::scene::Scene::load(&p).unwrap();
    let problem = Problem::build(sc, Mesh::from_msh(fixture("incline_hex.msh")).unwrap()).unwrap();
    let mut sim = Simulation::new(&problem).unwrap();
    sim.contact.as_mut().unwrap().gs_max_sweeps = 1;
    let mut rec = Recorder::create(&sim, &dir.join("out"), false).unwrap();
    sim.run(&mut rec).unwrap();
    let s = rec.summary(&sim, PathBuf::new(), vec![], 0.0);
    let j = &s.joints[0];
    assert!(j.unconverged_steps > 0 && j.max_gs_residual > 10.0 * j.gs_tolerance, "{} steps, residual {} vs tolerance {}", j.unconverged_steps, j.max_gs_residual, j.gs_tolerance);
    assert!(s.warnings.iter().any(|w| w.contains("Gauss–Seidel stopped") && w.contains("residual up to")), "{:?}", s.warnings);
    assert!(s.to_text().contains("residual up to"));
}

/// Regression: the joints' pairs are swept together, so when the sweeps stop at the cap every
/// joint reports the same steps and residual, and the coarse dam's summary repeated the same
/// Gauss–Seidel warning 28 times. Now one line names the joints that share it. The coarse dam
/// (pipelines/dam_coarse.json, 28 joints and the tied base) with the cap forced to 1 sweep,
/// released under gravity for 10 steps: exactly one Gauss–Seidel warning, naming J01 and J28.
#[test]
fn gauss_seidel_warning_is_one_line_for_joints_swept_together() {
    use jointquake::output::recorder::Recorder;
    use jointquake::problem::Problem;
    use jointquake::simulation::Simulation;
    let dir = scratch("outputs/gs_cap_dam");
    let (mut sc, mesh) = crate::common::dam_coarse_scene();
    sc.loads.base.clear();
    let problem = Problem::build(sc, mesh).unwrap();
    let mut sim = Simulation::new(&problem).unwrap();
    sim.contact.as_mut().unwrap().gs_max_sweeps = 1;
    let n = 10;
    let mut rec = Recorder::create(&sim, &dir.join("out"), false).unwrap();
    sim.run_steps(n, &mut rec).unwrap();
    let s = rec.summary(&sim, PathBuf::new(), vec![], 0.0);
    let gs: Vec<&String> = s.warnings.iter().filter(|w| w.contains("Gauss–Seidel stopped")).collect();
    assert_eq!(gs.len(), 1, "{gs:?}");
    assert!(gs[0].contains("J01") && gs[0].contains("J28") && gs[0].contains("swept together"), "{}", gs[0]);
}

/// A scene on a tet fixture (the boxes, no joint: the step is the elements' alone).
fn boxes_tet_scene(msh: &str) -> Value {
    json!({
        "geometry": {"msh": fixture(msh)},
        "materials": [
            {"group": "block:lower", "E": 30e9, "nu": 0.2, "rho": 2400},
            {"group": "block:upper", "E": 30e9, "nu": 0.2, "rho": 2400}
        ],
        "boundary": [{"group": "bc:base"}],
        "time": {"duration": 1e-4},
        "output": {"frames": false}
    })
}

/// Issue 19 (sliver tets): the stable step is printed with the element that sets it, its
/// scaled Jacobian (mesh::quality: 1 regular, about 0 flat) and its step over its block's mean;
/// a sliver below 0.2 (`SLIVER_SCALED_JACOBIAN`) is a warning in summary.json and on the
/// terminal. sliver_tet.msh is boxes_tet.msh with one top corner node moved down by 0.23 of its
/// 0.25 m layer (scripts/fixtures.sh): the flattened tet under it has a scaled Jacobian of 0.04
/// (computed independently with numpy on the fixture: 0.0397) and sets the step. The unaltered
/// boxes_tet.msh (structured, 6 tets per cell) sets it with a well-shaped tet (≥ 0.408, its
/// smallest) and no warning.
#[test]
fn sliver_setting_the_stable_step_is_named_with_its_quality() {
    use jointquake::mesh::quality::{cell_scaled_jacobian, SLIVER_SCALED_JACOBIAN};
    let run_on = |msh: &str| {
        let dir = scratch(&format!("outputs/quality_{msh}"));
        let p = write_scene(&dir, &boxes_tet_scene(msh));
        run(&p, &RunOptions { out_dir: Some(dir.join("out")), ..Default::default() }).expect("runs")
    };
    let good = run_on("boxes_tet.msh");
    let q = good.critical_scaled_jacobian.expect("written");
    assert!(q >= 0.40 && q <= 1.0, "structured tets: {q}");
    assert!(good.warnings.iter().all(|w| !w.contains("sliver")), "{:?}", good.warnings);
    let bad = run_on("sliver_tet.msh");
    let q = bad.critical_scaled_jacobian.expect("written");
    assert!((q - 0.0397).abs() < 1e-3 && q < SLIVER_SCALED_JACOBIAN, "sliver: {q}");
    // the element named is the flattened one, and the quality is that element's
    let m = Mesh::from_msh(fixture("sliver_tet.msh")).unwrap();
    let cell = m.cells.iter().position(|c| c.tag == bad.critical_element).expect("the critical element is a cell");
    assert_eq!(cell_scaled_jacobian(&m, cell), Some(q));
    assert!(bad.dt_stable < 0.5 * good.dt_stable, "the sliver lowers the step: {} vs {}", bad.dt_stable, good.dt_stable);
    let r = bad.critical_step_ratio.expect("written");
    assert!(r > 0.0 && r < 0.5, "step ratio {r}");
    let w = bad.warnings.iter().find(|w| w.contains("sliver")).unwrap_or_else(|| panic!("no sliver warning: {:?}", bad.warnings));
    for part in [format!("element {}", bad.critical_element), "\"block:upper\"".into(), format!("{q:.3}"), "below 0.2".into(), "Mesh quality".into()] {
        assert!(w.contains(&part), "{part:?} not in {w}");
    }
    let text = bad.to_text();
    assert!(text.contains(&format!("scaled Jacobian {q:.3}")) && text.contains("WARNING") && text.contains("sliver"), "{text}");
    // a run refused for its step count says so up front too
    let dir = scratch("outputs/quality_max_steps");
    let mut sc = boxes_tet_scene("sliver_tet.msh");
    sc["time"]["max_steps"] = json!(1);
    let p = write_scene(&dir, &sc);
    let e = run(&p, &RunOptions { out_dir: Some(dir.join("out")), ..Default::default() }).err().expect("refused").to_string();
    assert!(e.contains(&format!("element {}", bad.critical_element)) && e.contains(&format!("scaled Jacobian {q:.3}")) && e.contains("a sliver"), "{e}");
}

/// Issue 19 (mass scaling, docs/elements.md "Mass scaling"): `time.mass_scaling.target_dt`
/// raises the inertial density of every element whose own step 2/ω_e is below
/// T = target_dt / courant by s = (T / (2/ω_e))² (λ_max ∝ 1/ρ), so that the model's stable step
/// becomes T and the run's step target_dt. Reference: the element steps of the unscaled model
/// (`tet4::max_eigenvalue`, the bound `Model::stable_dt` uses), the count and the added mass
/// Σ (s − 1) ρ V summed here independently of the build. Tolerances: 1e-9 relative (round-off
/// of ω²/s; the formula is exact). Two targets on sliver_tet.msh: between the sliver's step and
/// the next element's (only the sliver is scaled, a small added mass, no warning), and just
/// above the median element step (half the elements scaled: added mass above 1 %, a warning). The sliver warning is not given once the sliver is scaled (its step is the
/// target's).
#[test]
fn mass_scaling_raises_the_sliver_step_to_the_target() {
    use jointquake::model::tet4;
    let sc0: jointquake::scene::Scene = serde_json::from_value(boxes_tet_scene("sliver_tet.msh")).unwrap();
    let model = Model::build(Mesh::from_msh(fixture("sliver_tet.msh")).unwrap(), &sc0).unwrap();
    // (element step 2/ω, volume, tag) of every tet, ascending by step
    let mut el: Vec<(f64, f64, u64)> = (0..model.tets.nodes.len())
        .map(|e| {
            let (g, m) = (&model.tets.geom[e], &model.materials[model.tets.mat[e] as usize]);
            (2.0 / tet4::max_eigenvalue(&g.grad, g.vol, m.rho, &m.lame).sqrt(), g.vol, model.mesh.cells[model.tets.cell[e] as usize].tag)
        })
        .collect();
    el.sort_by(|a, b| a.0.total_cmp(&b.0));
    let rho = 2400.0;
    let total: f64 = el.iter().map(|e| rho * e.1).sum();
    assert_eq!(el[0].2, model.critical.tag, "the sliver sets the unscaled step");
    let courant = 0.9;
    // targets between two distinct element steps (congruent elements share a step)
    let median = el[el.len() / 2].0;
    let above_median = el.iter().map(|e| e.0).find(|&t| t > median * (1.0 + 1e-9)).expect("a larger step");
    for (k, t_elem) in [(el[0].0 * el[1].0).sqrt(), (median * above_median).sqrt()].into_iter().enumerate() {
        let target = courant * t_elem;
        let below: Vec<&(f64, f64, u64)> = el.iter().filter(|e| e.0 < t_elem).collect();
        let added: f64 = below.iter().map(|e| ((t_elem / e.0).powi(2) - 1.0) * rho * e.1).sum();
        let dir = scratch(&format!("outputs/mass_scaling_{k}"));
        let mut sc = boxes_tet_scene("sliver_tet.msh");
        sc["time"]["mass_scaling"] = json!({"target_dt": target});
        let p = write_scene(&dir, &sc);
        let s = run(&p, &RunOptions { out_dir: Some(dir.join("out")), ..Default::default() }).expect("runs");
        let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
        assert!(rel(s.dt_stable, t_elem) < 1e-9, "stable step {} vs target/courant {t_elem}", s.dt_stable);
        assert!(rel(s.dt, target) < 1e-9, "step {} vs target {target}", s.dt);
        let ms = s.mass_scaling.as_ref().expect("reported");
        assert_eq!(ms.scaled_elements, below.len());
        assert!(rel(ms.added_mass, added) < 1e-9, "added {} vs {added}", ms.added_mass);
        assert!(rel(ms.total_mass, total) < 1e-12, "total {} vs {total}", ms.total_mass);
        assert_eq!(ms.max_factor_element, el[0].2, "the sliver has the largest factor");
        assert!(rel(ms.max_factor, (t_elem / el[0].0).powi(2)) < 1e-9, "factor {}", ms.max_factor);
        eprintln!("mass scaling case {k}: target {target:.4e} s, {} elements scaled, added {:.4e} kg = {:.4} % of {total:.4e} kg, largest factor {:.2}", ms.scaled_elements, ms.added_mass, 100.0 * ms.added_fraction(), ms.max_factor);
        assert!(s.notes.iter().any(|n| n.contains("mass scaling") && n.contains(&format!("{} element{} scaled", below.len(), if below.len() == 1 { "" } else { "s" }))), "{:?}", s.notes);
        assert!(s.warnings.iter().all(|w| !w.contains("sliver")), "{:?}", s.warnings);
        let warned = s.warnings.iter().any(|w| w.contains("mass scaling added") && w.contains("above 1 %"));
        assert_eq!(warned, added / total > 0.01, "warning iff the added mass exceeds 1 % ({:.3} %): {:?}", 100.0 * added / total, s.warnings);
        if k == 0 {
            assert_eq!(below.len(), 1, "only the sliver");
            assert!(!warned);
        } else {
            assert!(warned, "half the elements scaled: {:.3} %", 100.0 * added / total);
        }
        // summary.json carries it
        let back = jointquake::output::summary::RunSummary::read(&dir.join("out")).unwrap();
        assert_eq!(back.mass_scaling.as_ref(), Some(ms));
    }
}

/// The boxes fixture, frictionless, with `on_exit: "report"` (a node that leaves its initial
/// candidate set is lost, though still over the lower box) and a base acceleration along x of
/// +A sin(ωt) for one period T then −A sin(ω(t − T)) for the next, ω = 2π/T: the lower box moves
/// out by A T²/2π and back to where it started, the frictionless upper box stays, so its nodes
/// leave their candidate sets, fall while lost (gravity, no force) and find them again on the
/// way back: re-entries with a penetration.
fn reentry_scene(reentry: &str, record: &Path) -> Value {
    json!({
        "geometry": {"msh": fixture("boxes_hex_4x3.msh")},
        "materials": [{"group": "block:lower", "E": 1e9, "nu": 0.2, "rho": 2400},
                      {"group": "block:upper", "E": 1e9, "nu": 0.2, "rho": 2400}],
        "boundary": [{"group": "bc:base"}],
        "joints": [{"name": "J", "master": "joint:J:lower", "slave": "joint:J:upper", "mu": 0.0, "on_exit": "report", "reentry": reentry}],
        "loads": {"gravity": {}, "base": [{"record": record, "direction": [1, 0, 0]}]},
        "equilibrium": {"method": "none"},
        "time": {"duration": 1.0},
        "output": {"frames": false, "allow_penetration": true}
    })
}

/// Re-entry (the h 2.5 m dam run stopped by its energy check, docs/dam.md): a slave node that
/// finds a face again after lost steps, with a penetration δ it took while lost, is pushed out
/// in that one step (`reentry: "push"`, the default): relative velocity δ/dt, energy δ²/(2dt²w)
/// created, counted in the joint history's `reentry_work`. With `"hold"` the penetration is held
/// as closed and released as the node moves out: no positive work at re-entries, so less
/// energy created. Reference: the pair force closes g̃ exactly (design §5), so with hold
/// a re-entering pair starts at gap 0 and takes a force only as far as the sweeps' other pairs
/// push it back in: its re-entry work must be below 1e-3 of push's.
#[test]
fn reentry_push_creates_energy_and_hold_does_not() {
    let dir = scratch("outputs/reentry");
    let (t_half, a) = (0.5f64, 10.0f64);
    let w = 2.0 * std::f64::consts::PI / t_half;
    let rec: String = (0..=1000)
        .map(|k| {
            let t = k as f64 * 1e-3;
            let acc = if t <= t_half { a * (w * t).sin() } else { -a * (w * (t - t_half)).sin() };
            format!("{t:.4} {:.9}\n", acc / 9.81)
        })
        .collect();
    let rec_path = dir.join("out_and_back.txt");
    std::fs::write(&rec_path, rec).unwrap();
    let mut by = std::collections::BTreeMap::new();
    for reentry in ["push", "hold"] {
        let sub = dir.join(reentry);
        std::fs::create_dir_all(&sub).unwrap();
        let p = write_scene(&sub, &reentry_scene(reentry, &rec_path));
        let out = sub.join("out");
        let result = run(&p, &RunOptions { out_dir: Some(out.clone()), ..Default::default() });
        // the histories are readable whether the run finished or stopped
        let h = jointquake::output::history::HistoryTable::read(&out.join("histories/joint_J.csv")).unwrap();
        let last = |c: &str| *h.column(c).unwrap_or_else(|e| panic!("column {c}: {e}")).last().unwrap();
        by.insert(reentry, (last("reentries"), last("reentry_work [J]"), last("contact_work [J]"), result.map(|s| s.energy.max_error)));
    }
    let (push, hold) = (&by["push"], &by["hold"]);
    assert!(push.0 > 0.0 && hold.0 > 0.0, "no re-entries: push {push:?}, hold {hold:?}");
    assert!(push.1 > 0.0, "push: re-entries did no positive work {push:?}");
    assert!(hold.1 <= 1e-3 * push.1, "hold: re-entry work {} against push's {}", hold.1, push.1);
    // push: the energy check stops the run, naming energy created at the joints (as the h 2.5 m
    // dam run at t = 4.24 s); hold finishes with its balance closed
    match &push.3 {
        Err(e) => assert!(e.to_string().contains("contact forces did positive work"), "{e}"),
        Ok(err) => panic!("push finished (balance error {err:.2e}): the re-entries were expected to create energy past the check"),
    }
    let hold_err = hold.3.as_ref().unwrap_or_else(|e| panic!("hold did not finish: {e}"));
    assert!(hold_err.abs() < 1e-6, "hold: energy balance error {hold_err:.2e}");
    assert!(hold.2 < 0.0, "hold: the joint's contact work {} must dissipate", hold.2);
    // push with the energy check opened wide finishes, and warns, naming the joint and "hold"
    let sub = dir.join("push_unchecked");
    std::fs::create_dir_all(&sub).unwrap();
    let mut scene = reentry_scene("push", &rec_path);
    scene["time"]["energy_tolerance"] = json!(10.0);
    let p = write_scene(&sub, &scene);
    let s = run(&p, &RunOptions { out_dir: Some(sub.join("out")), ..Default::default() }).unwrap();
    let w = s.warnings.iter().find(|w| w.contains("re-entries")).unwrap_or_else(|| panic!("no re-entry warning in {:?}", s.warnings));
    assert!(w.starts_with("joint J:") && w.contains("\"hold\""), "{w}");
    assert!(s.joints[0].reentry_work > 0.01 * s.energy.scale, "{:?}", s.joints[0]);
    assert!(s.to_text().contains("re-entries after lost steps"));
}
