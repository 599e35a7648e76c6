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

// ---- issues 33 and 34: numbers to the extremes, hostile names, wildcards, repeats, targets ----

/// Run `check` on `cases()` values of `strategy` with a fixed seed (`seed` byte).
fn fuzz_values<S: Strategy>(name: &str, seed: u8, cases: u32, strategy: S, check: impl Fn(S::Value) -> Result<(), TestCaseError>) {
    let mut r = TestRunner::new_with_rng(Config { cases, failure_persistence: None, ..Config::default() }, TestRng::from_seed(RngAlgorithm::ChaCha, &[seed; 32]));
    if let Err(e) = r.run(&strategy, check) {
        panic!("{name}: {e}");
    }
}

/// A scene with a value at every numeric field the checks bound (loads, damping, time,
/// equilibrium, output, joints, reservoir).
fn full_numeric_scene() -> serde_json::Value {
    serde_json::json!({
        "geometry": {"msh": fixture("boxes_hex_4x3.msh")},
        "materials": [{"group": "block:lower", "E": 30e9, "nu": 0.2, "rho": 2400}, {"group": "block:upper", "E": 30e9, "nu": 0.2, "rho": 2400}],
        "boundary": [{"group": "bc:base"}],
        "loads": {"gravity": {"g": 9.81, "direction": [0, 0, -1]},
                  "traction": [{"group": "joint:J:upper", "traction": [0, 0, -1e5], "ramp": 0.001}],
                  "nodal": [{"point": [0, 0, 0.5], "force": [1e3, 0, 0], "ramp": 0.0}]},
        "damping": {"alpha": 1.0, "beta": 1e-5},
        "time": {"duration": 0.001, "courant": 0.9, "energy_tolerance": 0.05, "max_steps": 100000},
        "equilibrium": {"tolerance": 1e-6, "max_residual": 1e-3, "max_steps": 2000},
        "output": {"frames": false, "history_interval": 1e-4, "monitor": [{"name": "m", "point": [0, 0, 0.5]}]},
        "joints": [{"name": "J", "master": "joint:J:lower", "slave": "joint:J:upper", "mu": 0.6, "cohesion": 0.0, "tensile_strength": 0.0, "edge_tolerance": 1e-3}],
        "reservoir": {"faces": ["joint:J:upper"], "level": 1.5, "rho_w": 1000.0},
        "g": 9.81
    })
}

/// JSON paths of every number in `v` (arrays by index).
fn number_paths(v: &serde_json::Value, at: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
    match v {
        serde_json::Value::Number(_) => out.push(at.clone()),
        serde_json::Value::Object(m) => {
            for (k, x) in m {
                at.push(k.clone());
                number_paths(x, at, out);
                at.pop();
            }
        }
        serde_json::Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                at.push(i.to_string());
                number_paths(x, at, out);
                at.pop();
            }
        }
        _ => {}
    }
}

fn at_path<'a>(v: &'a mut serde_json::Value, path: &[String]) -> &'a mut serde_json::Value {
    path.iter().fold(v, |v, k| match v {
        serde_json::Value::Array(a) => &mut a[k.parse::<usize>().unwrap()],
        other => &mut other[k.as_str()],
    })
}

/// Issue 33 §6: every numeric scene field set to ±1e308, 0, a denormal, a huge integer or (as
/// a JSON text) NaN/inf: the scene loads or is refused with an error, never a panic; an accepted
/// one runs (one case in 50: each run takes a mesh and a few steps) to a finite peak or an
/// error. NaN cannot be written as a JSON number: its texts ("NaN", 1e999) are parse errors.
#[test]
fn fuzz_every_numeric_scene_field_to_the_extremes() {
    use jointquake::pipeline::{run, RunOptions};
    let base = full_numeric_scene();
    let mut paths = Vec::new();
    number_paths(&base, &mut Vec::new(), &mut paths);
    let dir = scratch("fuzz/numeric_fields");
    let p = dir.join("scene.json");
    let opts = RunOptions { out_dir: Some(dir.join("out")), ..Default::default() };
    let extremes = ["1e308", "-1e308", "0", "-0", "5e-324", "-1", "18446744073709551615", "1e999", "NaN"];
    fuzz_values("numeric fields", 11, cases(), (0..paths.len(), 0..extremes.len(), 0u32..50), |(k, e, r)| {
        let mut s = base.clone();
        *at_path(&mut s, &paths[k]) = serde_json::Value::String("@@".into());
        let text = serde_json::to_string(&s).unwrap().replace("\"@@\"", extremes[e]);
        std::fs::write(&p, text).unwrap();
        if jointquake::scene::Scene::load(&p).is_ok() && r == 0 {
            if let Ok(sum) = run(&p, &opts) {
                prop_assert!(sum.peak_displacement.value.is_finite(), "non-finite peak with {} = {}", paths[k].join("."), extremes[e]);
            }
        }
        Ok(())
    });
}

/// Issue 33 §2: any name (slashes, dots, NUL, unicode, 300 characters) becomes a stem that is
/// its own stem, at most 100 bytes, and stays under the output directory when joined.
#[test]
fn fuzz_hostile_names_become_stems_under_out() {
    let chars = proptest::sample::select(vec!['a', 'Z', '0', '.', '/', '\\', '\0', ' ', ':', '-', '_', '+', 'é', '~', '*', '\n']);
    fuzz_values("names", 12, cases(), proptest::collection::vec(chars, 0..300), |v| {
        let name: String = v.into_iter().collect();
        let stem = jointquake::files::file_stem(&name);
        prop_assert!(jointquake::files::is_file_stem(&stem) && stem.len() <= jointquake::files::MAX_STEM_LEN && !stem.starts_with('.'));
        let p = jointquake::files::path_under(std::path::Path::new("out"), &format!("joint_{stem}_forces.csv")).unwrap();
        prop_assert!(p.parent() == Some(std::path::Path::new("out")), "{p:?}");
        Ok(())
    });
}

/// The readings (up to 2) of `name` by a pattern, by plain backtracking: the reference the
/// linear matcher must agree with (exponential, so only on short inputs).
fn naive_readings(p: &str, name: &str) -> usize {
    fn go(p: &[char], s: &[char]) -> usize {
        match p.first() {
            None => usize::from(s.is_empty()),
            Some('*') => (0..=s.iter().position(|&c| c == ':').unwrap_or(s.len())).map(|e| go(&p[1..], &s[e..])).sum::<usize>().min(2),
            Some('#') => (1..=s.iter().position(|&c| c == ':').unwrap_or(s.len())).map(|e| go(&p[1..], &s[e..])).sum::<usize>().min(2),
            Some(c) => if s.first() == Some(c) { go(&p[1..], &s[1..]) } else { 0 },
        }
    }
    let pc: Vec<char> = p.chars().collect();
    let sc: Vec<char> = name.chars().collect();
    go(&pc, &sc)
}

/// Issue 33 §3: patterns with many wildcards answer at once and as plain backtracking does
/// (no match, one reading, or ambiguous) on short names; long ones (60 parts, 2000
/// characters) within 0.2 s each.
#[test]
fn fuzz_patterns_with_many_wildcards_match_fast_and_right() {
    use jointquake::mesh::pattern::{GroupPattern, PatternError};
    let tok = proptest::sample::select(vec!["*", "#", "a", "b", ":", "ab"]);
    let letter = proptest::sample::select(vec!['a', 'b', ':']);
    fuzz_values("patterns", 13, cases(), (proptest::collection::vec(tok, 1..10), proptest::collection::vec(letter, 0..14)), |(toks, name)| {
        // '#' is a placeholder {Pn}; two wildcards may not touch (the parser refuses it)
        let mut text = String::new();
        let mut naive = String::new();
        for (i, t) in toks.iter().enumerate() {
            if *t == "#" {
                text.push_str(&format!("{{P{i}}}"));
            } else {
                text.push_str(t);
            }
            naive.push_str(t);
        }
        let name: String = name.into_iter().collect();
        let Ok(p) = GroupPattern::parse(&text) else { return Ok(()) };
        let want = naive_readings(&naive, &name);
        match p.match_name(&name) {
            Ok(None) => prop_assert_eq!(want, 0, "{} on {}", text, name),
            Ok(Some(_)) => prop_assert_eq!(want, 1, "{} on {}", text, name),
            Err(PatternError::Ambiguous { .. }) => prop_assert_eq!(want, 2, "{} on {}", text, name),
            Err(e) => prop_assert!(false, "{e}"),
        }
        Ok(())
    });
    fuzz_values("long patterns", 14, (cases() / 20).max(10), (1usize..30, 100usize..2000), |(stars, len)| {
        let p = GroupPattern::parse(&format!("g:{}b", "*a".repeat(stars))).unwrap();
        let t = std::time::Instant::now();
        let _ = p.match_name(&format!("g:{}", "a".repeat(len)));
        prop_assert!(t.elapsed().as_secs_f64() < 0.2, "{stars} stars on {len} characters: {:?}", t.elapsed());
        Ok(())
    });
}

/// Issue 34: group lists with repeats (reservoir faces, gravity groups, mass groups, envelope
/// faces) are refused exactly when a group repeats; and writes to non-regular targets
/// (device, symlink, directory, fifo) are refused and leave them as they were.
#[test]
fn fuzz_repeated_groups_and_non_regular_targets() {
    let dir = scratch("fuzz/repeats");
    let p = dir.join("scene.json");
    let group = proptest::sample::select(vec!["joint:J:upper", "joint:J:lower", "bc:base"]);
    let field = 0usize..4;
    fuzz_values("repeats", 15, (cases() / 4).max(10), (field, proptest::collection::vec(group, 1..5)), |(f, groups)| {
        let mut s = full_numeric_scene();
        let list = serde_json::json!(groups);
        match f {
            0 => s["reservoir"]["faces"] = list,
            1 => s["loads"]["gravity"]["groups"] = list,
            2 => s["damping"]["mass_groups"] = list,
            _ => s["output"]["envelope"] = serde_json::json!({"faces": list}),
        }
        std::fs::write(&p, serde_json::to_string(&s).unwrap()).unwrap();
        let repeats = groups.iter().enumerate().any(|(i, g)| groups[..i].contains(g));
        match jointquake::scene::Scene::load(&p) {
            Ok(_) => prop_assert!(!repeats, "accepted {groups:?} in field {f}"),
            Err(e) => prop_assert!(!repeats || e.to_string().contains("listed twice"), "{e}"),
        }
        Ok(())
    });
    let target = dir.join("real.txt");
    std::fs::write(&target, "keep").unwrap();
    let link = dir.join("link.txt");
    let _ = std::fs::remove_file(&link);
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let fifo = dir.join("fifo");
    if !fifo.exists() {
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        unsafe { libc::mkfifo(c.as_ptr(), 0o600) };
    }
    let targets = [PathBuf::from("/dev/null"), link.clone(), dir.join("sub"), fifo.clone()];
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    fuzz_values("targets", 16, (cases() / 20).max(10), (0..targets.len(), proptest::collection::vec(any::<u8>(), 0..64)), |(k, bytes)| {
        let t = &targets[k];
        let before = std::fs::symlink_metadata(t).unwrap().file_type();
        prop_assert!(jointquake::files::write_whole(t, &bytes).is_err());
        prop_assert_eq!(std::fs::symlink_metadata(t).unwrap().file_type(), before);
        Ok(())
    });
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "keep");
}

/// Issue 34: output file names that collide (a monitor `joint_J` and a joint `J` both wrote
/// `histories/joint_J.csv`) are refused before the run, and only then. Random joint and
/// monitor names from a pool built to collide after the stem rule (`joint_J`, `J_forces`,
/// `a/b` and `a_b`, …), with and without the joint-force histories: the run (0 s, the boxes)
/// fails naming "unique" exactly when two of the files the reference below lists coincide
/// (or the scene refuses a name for itself); otherwise each of those files exists and holds
/// the header of its one writer.
#[test]
fn fuzz_colliding_output_names_are_refused_before_the_run() {
    use jointquake::files::file_stem;
    use jointquake::pipeline::{run, RunOptions};
    let dir = scratch("fuzz/collisions");
    let p = dir.join("scene.json");
    let pool = vec!["J", "joint_J", "joint_J_forces", "J_forces", "a/b", "a_b", "a b", "x", "joint_x", "summary"];
    let name = proptest::sample::select(pool);
    fuzz_values("collisions", 17, (cases() / 20).max(10), (name.clone(), proptest::collection::vec(name, 0..4), any::<bool>()), |(joint, monitors, forces)| {
        let mut s = full_numeric_scene();
        s["reservoir"] = serde_json::Value::Null;
        s["loads"] = serde_json::json!({});
        s["time"] = serde_json::json!({"duration": 0.0});
        s["joints"][0]["name"] = serde_json::json!(joint);
        s["output"] = serde_json::json!({"frames": false, "joint_forces": forces, "monitor": monitors.iter().map(|m| serde_json::json!({"name": m, "point": [0, 0, 0.5]})).collect::<Vec<_>>()});
        std::fs::write(&p, serde_json::to_string(&s).unwrap()).unwrap();
        // the reference: every history file and its writer's header line
        let mut files: Vec<(String, &str)> = monitors.iter().map(|m| (format!("{}.csv", file_stem(m)), jointquake::output::history::MONITOR_HEADER)).collect();
        files.push((format!("joint_{}.csv", file_stem(joint)), jointquake::output::joints::JOINT_HEADER));
        if forces {
            files.push((format!("joint_{}_forces.csv", file_stem(joint)), jointquake::output::joints::JOINT_FORCES_HEADER));
        }
        let collide = files.iter().enumerate().any(|(i, f)| files[..i].iter().any(|g| g.0 == f.0));
        let out = dir.join("out");
        let _ = std::fs::remove_dir_all(&out);
        match run(&p, &RunOptions { out_dir: Some(out.clone()), ..Default::default() }) {
            Err(e) => {
                let (m, by_scene) = (e.to_string(), jointquake::scene::Scene::load(&p).is_err());
                prop_assert!(by_scene || (collide && (m.contains("unique") || m.contains("two monitors are named"))), "collide {collide}: {m}");
            }
            Ok(_) => {
                prop_assert!(!collide, "accepted colliding names: joint {joint:?}, monitors {monitors:?}");
                for (f, header) in &files {
                    let text = std::fs::read_to_string(out.join("histories").join(f)).unwrap_or_default();
                    prop_assert_eq!(text.lines().next(), Some(*header), "{}", f);
                }
            }
        }
        Ok(())
    });
}
