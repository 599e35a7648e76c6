//! Fuzz-style property tests (issue 19 §4): mutated copies of the committed fixtures' `.msh`
//! files, of a record and of a scene are fed to the readers, which must either accept the input
//! or return an error — never panic, abort or hang. Fixed seed (proptest's deterministic RNG),
//! a bounded number of cases so that this runs in seconds; `make fuzz` runs many more
//! (`JQ_FUZZ_CASES`).
use crate::common::{fixture, scratch};
use jointquake::dynamics::record::Record;
use jointquake::mesh::msh::parse_msh;
use jointquake::scene::Scene;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use std::path::PathBuf;

/// Cases per property: `JQ_FUZZ_CASES` or 200.
fn cases() -> u32 {
    std::env::var("JQ_FUZZ_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(200)
}

fn runner() -> TestRunner {
    let config = Config { cases: cases(), failure_persistence: None, ..Config::default() };
    TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &[7; 32]))
}

/// Numbers that break readers: zero, negative, huge, tiny, non-finite, past u64 and i32.
const EXTREMES: &[&str] = &["0", "-1", "1e300", "1e-300", "NaN", "inf", "18446744073709551615", "2147483648", "1000000000000", "-0", "3.5", ""];

#[derive(Clone, Debug)]
enum Mutation {
    /// Replace the k-th whitespace-separated token with an extreme value.
    Token(usize, usize),
    /// Delete the k-th line.
    DeleteLine(usize),
    /// Duplicate the k-th line.
    DuplicateLine(usize),
    /// Cut the text at a fraction (per mille) of its length.
    Truncate(u16),
    /// Overwrite the byte at a position with a value.
    Byte(usize, u8),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), 0..EXTREMES.len()).prop_map(|(k, e)| Mutation::Token(k, e)),
        any::<usize>().prop_map(Mutation::DeleteLine),
        any::<usize>().prop_map(Mutation::DuplicateLine),
        (0u16..1000).prop_map(Mutation::Truncate),
        (any::<usize>(), any::<u8>()).prop_map(|(k, b)| Mutation::Byte(k, b)),
    ]
}

/// Apply mutations to a text file's bytes.
fn mutate(original: &[u8], ms: &[Mutation]) -> Vec<u8> {
    let mut b = original.to_vec();
    for m in ms {
        let text = String::from_utf8_lossy(&b).into_owned();
        b = match *m {
            Mutation::Token(k, e) => {
                let spans: Vec<(usize, usize)> = token_spans(&text);
                if spans.is_empty() {
                    continue;
                }
                let (s, t) = spans[k % spans.len()];
                format!("{}{}{}", &text[..s], EXTREMES[e], &text[t..]).into_bytes()
            }
            Mutation::DeleteLine(k) | Mutation::DuplicateLine(k) => {
                let mut lines: Vec<&str> = text.split('\n').collect();
                let i = k % lines.len();
                if matches!(m, Mutation::DeleteLine(_)) {
                    lines.remove(i);
                } else {
                    lines.insert(i, lines[i]);
                }
                lines.join("\n").into_bytes()
            }
            Mutation::Truncate(f) => b[..b.len() * f as usize / 1000].to_vec(),
            Mutation::Byte(k, v) => {
                if !b.is_empty() {
                    let i = k % b.len();
                    b[i] = v;
                }
                b
            }
        };
    }
    b
}

/// Byte spans of the whitespace-separated tokens of `s`.
fn token_spans(s: &str) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = None;
    for (i, c) in s.char_indices() {
        match (c.is_whitespace(), start) {
            (true, Some(a)) => {
                out.push((a, i));
                start = None;
            }
            (false, None) => start = Some(i),
            _ => {}
        }
    }
    if let Some(a) = start {
        out.push((a, s.len()));
    }
    out
}

/// Run a property over mutated copies of `original`; `check` must return (Ok or Err), never panic.
fn fuzz(name: &str, original: &[u8], check: impl Fn(&[u8])) {
    let mut r = runner();
    let result = r.run(&proptest::collection::vec(mutation(), 1..4), |ms| {
        let bytes = mutate(original, &ms);
        check(&bytes);
        Ok(())
    });
    if let Err(e) = result {
        panic!("{name}: {e}");
    }
}

#[test]
fn fuzz_mutated_meshes_parse_or_fail_cleanly() {
    for f in ["column_hex.msh", "boxes_hex_4x3.msh", "boxes_tet.msh"] {
        let original = std::fs::read(fixture(f)).unwrap();
        fuzz(f, &original, |bytes| {
            if let Ok(mesh) = parse_msh(bytes, PathBuf::from(f)) {
                // An accepted mesh answers group queries without panicking.
                for g in &mesh.groups {
                    let _ = mesh.group_nodes(&g.name);
                }
            }
        });
    }
}

#[test]
fn fuzz_mutated_binary_mesh_parses_or_fails_cleanly() {
    let original = std::fs::read(fixture("boxes_hex_4x3_binary.msh")).unwrap();
    fuzz("boxes_hex_4x3_binary.msh", &original, |bytes| {
        let _ = parse_msh(bytes, PathBuf::from("binary.msh"));
    });
}

#[test]
fn fuzz_mutated_records_read_or_fail_cleanly() {
    let dir = scratch("fuzz/records");
    let two_col = std::fs::read(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("pipelines/records/elcentro1940_NS_chopra.txt")).unwrap();
    let two_col = &two_col[..two_col.len().min(4000)];
    let at2 = b"PEER STRONG MOTION DATABASE RECORD\nTEST\nACCELERATION TIME SERIES IN UNITS OF G\nNPTS=    8, DT=   .0100 SEC\n 0.1 0.2 -0.3 0.4\n 0.0 0.01 -0.02 0.0\n".to_vec();
    for (name, original) in [("r.txt", two_col.to_vec()), ("r.AT2", at2)] {
        let p = dir.join(name);
        fuzz(name, &original, |bytes| {
            std::fs::write(&p, bytes).unwrap();
            if let Ok(r) = Record::read(&p, 9.81) {
                // An accepted record interpolates anywhere without panicking.
                for t in [-1.0, 0.0, r.t_end(), 1e300, f64::NAN] {
                    let _ = r.at(t);
                }
                assert!(r.dt > 0.0 && r.accel.iter().all(|a| a.is_finite()));
            }
        });
    }
}

#[test]
fn fuzz_mutated_scenes_load_or_fail_cleanly() {
    let dir = scratch("fuzz/scenes");
    let original = std::fs::read(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("pipelines/wedge.json")).unwrap();
    let p = dir.join("scene.json");
    fuzz("wedge.json", &original, |bytes| {
        std::fs::write(&p, bytes).unwrap();
        if let Ok(s) = Scene::load(&p) {
            let _ = s.validate();
        }
    });
}

#[test]
fn fuzz_mutated_scenes_run_or_fail_cleanly() {
    // The column scene (hex8 fixture) with its numbers, keys and lines mutated, run for at most
    // 0.01 s: each case either runs or returns an error (no panic, no inf/NaN in the summary).
    use jointquake::pipeline::{run, RunOptions};
    let dir = scratch("fuzz/runs");
    let scene = serde_json::json!({
        "geometry": {"msh": fixture("column_hex.msh")},
        "materials": [{"group": "block:column", "E": 30e9, "nu": 0.2, "rho": 2400}],
        "boundary": [{"group": "bc:base"}],
        "loads": {"gravity": {}, "traction": [{"group": "load:top", "traction": [1e5, 0, -1e5], "ramp": 0.001}]},
        "damping": {"alpha": 1.0},
        "time": {"duration": 0.01, "courant": 0.9},
        "output": {"frames": false, "monitor": [{"name": "top", "point": [0.5, 0.5, 10]}]}
    });
    let original = serde_json::to_string_pretty(&scene).unwrap().into_bytes();
    let p = dir.join("scene.json");
    let opts = RunOptions { out_dir: Some(dir.join("out")), duration: Some(0.01), ..Default::default() };
    let mut r = TestRunner::new_with_rng(Config { cases: (cases() / 4).max(10), failure_persistence: None, ..Config::default() }, TestRng::from_seed(RngAlgorithm::ChaCha, &[9; 32]));
    let result = r.run(&proptest::collection::vec(mutation(), 1..3), |ms| {
        std::fs::write(&p, mutate(&original, &ms)).unwrap();
        if let Ok(s) = run(&p, &opts) {
            prop_assert!(s.peak_displacement.value.is_finite(), "non-finite peak from an accepted scene");
        }
        Ok(())
    });
    if let Err(e) = result {
        panic!("column scene: {e}");
    }
}
