//! Ground motions in scenes: `loads.base[]` entries that name a generated (synthetic) record,
//! the explicit `baseline` option, and the drift of each base input reported in the run's notes.

use crate::common::{fixture, scratch};
use jointquake::dynamics::loads::base_motions;
use jointquake::motion::{Baseline, drift};
use jointquake::pipeline::{RunOptions, run};
use jointquake::scene::Scene;
use serde_json::{Value, json};
use std::path::{Path, PathBuf};

fn write_scene(dir: &Path, scene: &Value) -> PathBuf {
    let p = dir.join("scene.json");
    std::fs::write(&p, serde_json::to_string_pretty(scene).unwrap()).unwrap();
    p
}

/// The column fixture (10 hex8, clamped base) under the given base entries, 0.05 s.
fn column(base: Value) -> Value {
    json!({
        "geometry": {"msh": fixture("column_hex.msh")},
        "materials": [{"group": "block:column", "E": 30e9, "nu": 0.2, "rho": 2400}],
        "boundary": [{"group": "bc:base"}],
        "loads": {"base": base},
        "time": {"duration": 0.05}
    })
}

fn synth(seed: u64, component: &str) -> Value {
    json!({"spectrum": {"kind": "code", "structure": "arch", "site_class": "I"}, "seed": seed, "component": component, "duration": 20, "dt": 0.01})
}

fn elcentro() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("pipelines/records/elcentro1940_NS_chopra.txt")
}

/// Reference: the entry's `pga` is the applied peak, max |scale · a(t_i)| = pga · g, to 1e-12
/// relative (one multiplication); the run's summary.json carries the drift note of the entry.
#[test]
fn synth_base_entry_runs_at_the_requested_pga_and_reports_its_drift() {
    let dir = scratch("motion_scene/synth_run");
    let p = write_scene(&dir, &column(json!([{"synth": synth(1, "h1"), "direction": [1, 0, 0], "pga": 0.3}])));
    let sc = Scene::load(&p).unwrap();
    let (m, notes) = base_motions(&sc).unwrap();
    let applied = m[0].record.peak() * m[0].scale;
    assert!((applied - 0.3 * 9.81).abs() < 1e-12 * 0.3 * 9.81, "applied PGA {applied} m/s²");
    assert_eq!(m[0].record.accel.len(), 2001);
    assert!(notes[0].contains("synth h1") && notes[0].contains("drift as applied"), "{notes:?}");
    let out = dir.join("out");
    run(&p, &RunOptions { out_dir: Some(out.clone()), ..Default::default() }).unwrap();
    let v: Value = serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let notes: Vec<&str> = v["notes"].as_array().unwrap().iter().filter_map(|n| n.as_str()).collect();
    assert!(notes.iter().any(|n| n.starts_with("base[0] synth h1") && n.contains("end velocity") && n.contains("end displacement")), "{notes:?}");
}

/// Same seed → the same samples (bit for bit); another seed → another record. The vertical at
/// the entry's pga is generated for the set's horizontal PGA pga / (2/3) and applied at pga.
#[test]
fn synth_base_entry_is_deterministic_per_seed() {
    let base = json!([
        {"synth": synth(1, "v"), "direction": [0, 0, 1], "pga": 0.2},
        {"synth": synth(1, "v"), "direction": [0, 0, 1], "pga": 0.2},
        {"synth": synth(2, "v"), "direction": [0, 0, 1], "pga": 0.2}
    ]);
    let sc: Scene = serde_json::from_value(column(base)).unwrap();
    sc.validate().unwrap();
    let (m, _) = base_motions(&sc).unwrap();
    assert_eq!(m[0].record.accel, m[1].record.accel);
    assert_ne!(m[0].record.accel, m[2].record.accel);
    // generated at 2/3 × 0.3 g = 0.2 g: the scale is 1 to round-off of the written peak
    assert!((m[0].scale - 1.0).abs() < 1e-9, "scale {}", m[0].scale);
}

#[test]
fn base_entry_with_record_and_synth_is_an_error_naming_the_entry() {
    let dir = scratch("motion_scene/both");
    let p = write_scene(&dir, &column(json!([
        {"record": elcentro(), "direction": [1, 0, 0]},
        {"record": elcentro(), "synth": synth(1, "h1"), "direction": [0, 1, 0], "pga": 0.2}
    ])));
    let e = Scene::load(&p).unwrap_err().to_string();
    assert!(e.contains("loads.base[1]") && e.contains("not both"), "{e}");
    let p = write_scene(&dir, &column(json!([{"direction": [1, 0, 0]}])));
    let e = Scene::load(&p).unwrap_err().to_string();
    assert!(e.contains("loads.base[0]") && e.contains("`synth`"), "{e}");
    let p = write_scene(&dir, &column(json!([{"record": elcentro(), "direction": [1, 0, 0], "baseline": "linear"}])));
    let e = Scene::load(&p).unwrap_err().to_string();
    assert!(e.contains("loads.base[0]") && e.contains("\"linear\""), "{e}");
}

/// Reference: the polynomial correction constrains the end velocity and displacement to zero
/// (docs/motion.md), so the drift as applied is round-off (< 1e-9 m/s, m); El Centro NS as given
/// ends at −5.3 mm (docs/motion.md), scaled here × 2. The baseline is applied before the `pga`
/// scaling, so the applied PGA is the requested one either way; `{"highpass": 0.1}` is the
/// zero-phase Butterworth at 0.1 Hz, order 4, cut to the record's window (its drift grows).
#[test]
fn base_entry_baseline_option_changes_the_reported_drift() {
    let base = json!([
        {"record": elcentro(), "direction": [1, 0, 0], "scale": 2.0},
        {"record": elcentro(), "direction": [1, 0, 0], "scale": 2.0, "baseline": "polynomial"},
        {"record": elcentro(), "direction": [0, 1, 0], "pga": 0.5, "baseline": {"highpass": 0.1}}
    ]);
    let sc: Scene = serde_json::from_value(column(base)).unwrap();
    sc.validate().unwrap();
    let (m, notes) = base_motions(&sc).unwrap();
    let raw = drift(&m[0].record.accel, m[0].record.dt);
    assert!((m[0].drift.d_end - 2.0 * raw.d_end).abs() < 1e-15 && m[0].drift.d_end.abs() > 5e-3, "{:?}", m[0].drift);
    assert!(m[0].baseline.is_none() && notes[0].contains("baseline none"), "{}", notes[0]);
    assert_eq!(m[1].baseline, Some(Baseline::Polynomial { degree: 5 }));
    assert!(m[1].drift.v_end.abs() < 1e-9 && m[1].drift.d_end.abs() < 1e-9, "{:?}", m[1].drift);
    assert!(notes[1].contains("before the correction"), "{}", notes[1]);
    assert_eq!(m[2].baseline, Some(Baseline::HighPass { corner: 0.1, order: 4 }));
    assert!((m[2].record.peak() * m[2].scale - 0.5 * 9.81).abs() < 1e-12 * 0.5 * 9.81);
    // the run's record starts at its first sample, so the acausal filter's response before it is
    // cut (docs/motion.md: El Centro at 0.1 Hz then ends near −0.58 m at its own PGA): the note
    // must show a large drift, not hide it
    assert!(m[2].drift.d_end.abs() > 0.1 && notes[2].contains("high-pass"), "{:?} {}", m[2].drift, notes[2]);
}
