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
        "output": {"frame_stride": 10, "monitor": [{"name": "top", "point": [0.3, 0.2, 10.0]}]}
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
    let head = lines.next().unwrap();
    assert!(head.starts_with("# monitor top at node ") && head.contains("snapped 3.606e-1 m from (0.3, 0.2, 10)"), "{head}");
    assert_eq!(lines.next().unwrap(), "t,ux,uy,uz,vx,vy,vz,ax,ay,az");
    let rows: Vec<Vec<f64>> = lines.map(|l| l.split(',').map(|x| x.parse().unwrap()).collect()).collect();
    assert_eq!(rows.len(), s.steps);
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
        "time": {"duration": 100.0},
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
    let rows: Vec<&str> = csv.lines().skip(2).collect();
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
        "output": {"frame_stride": 100}
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
        for name in ["displacement", "normal", "gap", "opening", "slip", "tangential_displacement", "normal_traction", "shear_traction", "state", "tributary_area"] {
            assert!(t.contains(&format!("Name=\"{name}\"")), "{} lacks {name}", f.display());
        }
    }
    let csv = std::fs::read_to_string(out.join("histories/joint_J.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next().unwrap(), "t,max_opening,max_slip,max_tangential_displacement,max_penetration,open,stick,slip,bonded,sweeps,normal_force,shear_force");
    let rows: Vec<Vec<f64>> = lines.map(|l| l.split(',').map(|x| x.parse().unwrap()).collect()).collect();
    assert_eq!(rows.len(), s.steps);
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
                let st = jointquake::study::wedge::WedgeStudy::load(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
                jointquake::scene::Scene::load(&st.scene).unwrap_or_else(|e| panic!("{}: {e}", st.scene.display()));
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
