//! The plan of a study: its runs (the product of the axes or the union of the selections),
//! each run's scene (the base scene with the run's variations), `plan.json` and `runs.mk`.
//!
//! A run is named by the labels of its axis values; its id joins the non-empty labels of the
//! id axes with `-` (`nts1-medium-pga1.00-rigidrock`). Its scene is written to
//! `<out>/scenes/<id>.json` (absolute paths) and its results go to `<out>/runs/<id>/`.
//! A scene is rewritten only when its content changes, so that `make` reruns exactly the runs
//! whose scene changed.

use super::file::{Study, Variation};
use super::StepSpec;
use crate::dynamics::loads::base_motions;
use crate::error::{Error, ModelError, OutputError, StudyError};
use crate::scene::Scene;
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};
use std::path::{Path, PathBuf};

/// One run of the plan.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct RunSpec {
    /// File-safe identifier, e.g. `nts1-medium-pga1.00-rigidrock`.
    pub id: String,
    /// (axis, label) of every axis, in axis order.
    pub labels: Vec<(String, String)>,
    /// Per-run overrides of the selections that chose this run, in order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub overrides: Vec<Variation>,
    /// Relative cost: the product of its values' costs.
    pub cost: f64,
    /// One of its values is `alone` ([`super::file::Variation::alone`]): the run needs the
    /// machine to itself.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub alone: bool,
    /// Target PGA [g] of the run's first record, when a variation sets one (the last wins).
    pub pga: Option<f64>,
}

impl RunSpec {
    /// The label of axis `axis`, if the study has that axis.
    pub fn label(&self, axis: &str) -> Option<&str> {
        self.labels.iter().find(|(a, _)| a == axis).map(|(_, l)| l.as_str())
    }
}

/// Most runs a study may plan: 10 000 (the wedge study plans 60; a dam campaign a few hundred).
/// Checked on the product of the selected axis values before any run is enumerated: a study
/// whose axes multiplied to 10¹² planned for ever (issue 33).
pub const MAX_STUDY_RUNS: usize = 10_000;

/// Every run of the study, without duplicates, the most expensive first (stable: in selection
/// order within a cost), so that `make -j` starts the long runs early.
pub fn plan_runs(study: &Study) -> Result<Vec<RunSpec>, StudyError> {
    let mut runs: Vec<RunSpec> = Vec::new();
    let combinations: f64 = study.selections.iter().map(|sel| sel.labels.iter().map(|l| l.len() as f64).product::<f64>()).sum();
    if combinations > MAX_STUDY_RUNS as f64 {
        return Err(StudyError::Invalid {
            path: study.path.clone(),
            message: format!("the selections' axes multiply to {combinations:.3e} runs, above the limit of {MAX_STUDY_RUNS}: select fewer values (a study of that size is a cluster campaign: split it into several studies)"),
        });
    }
    for sel in &study.selections {
        // the product of the selected labels, the first axis outermost
        let mut idx = vec![0usize; study.axes.len()];
        'product: loop {
            let labels: Vec<(String, String)> = study.axes.iter().zip(&idx).enumerate().map(|(k, (a, &i))| (a.name.clone(), sel.labels[k][i].clone())).collect();
            match runs.iter_mut().find(|r| r.labels == labels) {
                Some(r) => {
                    if !sel.with.is_empty() {
                        r.overrides.push(sel.with.clone());
                        r.pga = sel.with.pga.or(r.pga);
                    }
                }
                None => {
                    let values: Vec<&super::file::AxisValue> = study.axes.iter().zip(&labels).map(|(a, (_, l))| a.value(l).expect("checked label")).collect();
                    let id = study.id_axes.iter().map(|&k| labels[k].1.as_str()).filter(|l| !l.is_empty()).collect::<Vec<_>>().join("-");
                    let cost = values.iter().map(|v| v.cost).product();
                    let alone = values.iter().any(|v| v.alone);
                    let mut pga = study.all.pga;
                    for v in values.iter().map(|v| &v.variation).chain(std::iter::once(&sel.with)) {
                        pga = v.pga.or(pga);
                    }
                    let overrides = if sel.with.is_empty() { vec![] } else { vec![sel.with.clone()] };
                    runs.push(RunSpec { id, labels, overrides, cost, alone, pga });
                }
            }
            // next index of the product (last axis fastest)
            for k in (0..idx.len()).rev() {
                idx[k] += 1;
                if idx[k] < sel.labels[k].len() {
                    continue 'product;
                }
                idx[k] = 0;
            }
            break;
        }
    }
    for (i, r) in runs.iter().enumerate() {
        let invalid = |message: String| StudyError::Invalid { path: study.path.clone(), message };
        if r.id.is_empty() {
            return Err(invalid(format!("a run has only empty labels ({:?}): give one of its values a label", r.labels)));
        }
        if !crate::files::is_file_stem(&r.id) {
            return Err(invalid(format!("run id \"{}\" ({:?}) is not a file name: at most {} characters of letters, digits, `.`, `_`, `+`, `-` (shorten the labels or leave axes out of `id`)", r.id, r.labels, crate::files::MAX_STEM_LEN)));
        }
        if let Some(o) = runs[..i].iter().find(|o| o.id == r.id) {
            return Err(invalid(format!("runs {:?} and {:?} get the same id \"{}\": give their values distinct labels (or add the axis to `id`)", o.labels, r.labels, r.id)));
        }
    }
    // the runs that need the machine alone first (runs.mk chains them), then by cost
    runs.sort_by(|a, b| b.alone.cmp(&a.alone).then(b.cost.total_cmp(&a.cost)));
    Ok(runs)
}

/// Canonical absolute form of a path that exists (else the path joined to the current directory).
pub fn absolute(p: &Path) -> PathBuf {
    std::fs::canonicalize(p).unwrap_or_else(|_| std::env::current_dir().map(|d| d.join(p)).unwrap_or_else(|_| p.to_path_buf()))
}

/// The base scene of a study with absolute paths (geometry, records).
pub fn load_base(study: &Study) -> Result<Scene, Error> {
    let mut s = Scene::load(&study.scene)?;
    if let Some(g) = s.geometry.geo.as_mut() {
        *g = absolute(g);
    }
    if let Some(m) = s.geometry.msh.as_mut() {
        *m = absolute(m);
    }
    for b in &mut s.loads.base {
        b.map_paths(|p| *p = absolute(p));
    }
    Ok(s)
}

/// Set `value` at a JSON-pointer path (`/a/0/b`; `~1` is `/`, `~0` is `~`) of `root`.
/// Objects on the way are created where missing or null; array indices must exist.
fn set_path(root: &mut Value, path: &str, value: Value) -> Result<(), String> {
    let tokens: Vec<String> = path[1..].split('/').map(|t| t.replace("~1", "/").replace("~0", "~")).collect();
    let mut cur = root;
    let mut at = String::new();
    for (i, t) in tokens.iter().enumerate() {
        let last = i + 1 == tokens.len();
        if cur.is_null() {
            *cur = Value::Object(Map::new());
        }
        cur = match cur {
            Value::Object(m) => {
                if last {
                    m.insert(t.clone(), value);
                    return Ok(());
                }
                m.entry(t.clone()).or_insert(Value::Null)
            }
            Value::Array(a) => {
                let k: usize = t.parse().map_err(|_| format!("{at} is a list: `{t}` must be an index 0..{}", a.len()))?;
                let n = a.len();
                let slot = a.get_mut(k).ok_or_else(|| format!("{at} has {n} entries: index {k} is out of range"))?;
                if last {
                    *slot = value;
                    return Ok(());
                }
                slot
            }
            other => return Err(format!("{} is {}, not an object or a list", if at.is_empty() { "the scene" } else { &at }, other)),
        };
        at.push('/');
        at.push_str(t);
    }
    unreachable!("a path has at least one token")
}

/// Apply the JSON parts of `v` (`set`, `joints`, `joint`, `scene`) to a scene's JSON.
fn apply_json(root: &mut Value, v: &Variation) -> Result<(), String> {
    if !v.set.is_empty() {
        if root["geometry"]["geo"].is_null() {
            return Err(format!("`set` {:?} changes gmsh parameters, but the scene has a `geometry.msh`, not a `geo`", v.set));
        }
        for (k, x) in &v.set {
            set_path(root, &format!("/geometry/set/{}", k.replace('~', "~0").replace('/', "~1")), Value::from(*x))?;
        }
    }
    let joints = root["joints"].as_array_mut();
    match joints {
        Some(js) => {
            for j in js.iter_mut() {
                for (k, x) in &v.joints {
                    j[k.as_str()] = x.clone();
                }
            }
            for (name, fields) in &v.joint {
                let names: Vec<String> = js.iter().filter_map(|j| j["name"].as_str().map(str::to_string)).collect();
                let j = js.iter_mut().find(|j| j["name"] == name.as_str()).ok_or_else(|| format!("`joint`: no joint \"{name}\" in the scene (joints: {})", names.join(", ")))?;
                for (k, x) in fields {
                    j[k.as_str()] = x.clone();
                }
            }
        }
        None if !v.joints.is_empty() || !v.joint.is_empty() => return Err("`joints`/`joint`: the scene has no joints".into()),
        None => {}
    }
    for (p, x) in &v.scene {
        set_path(root, p, x.clone()).map_err(|e| format!("scene path \"{p}\": {e}"))?;
    }
    Ok(())
}

/// The study PGA's factor (`dynamics::loads::scale_for_pga`, the study meaning): the one that
/// brings the first base record of `scene`, as the scene scales it, to `pga` [g] (all records
/// get it).
fn pga_factor(scene: &Scene, pga: f64) -> Result<f64, Error> {
    let (base, _) = base_motions(scene)?;
    let first = base.first().ok_or_else(|| ModelError::Invalid("`pga`: the scene has no `loads.base` record to scale".into()))?;
    let peak = first.record.peak() * first.scale; // m/s²
    crate::dynamics::loads::scale_for_pga(peak, pga, scene.g).ok_or_else(|| ModelError::Invalid(format!("record {} is all zeros: cannot scale it to {pga} g", first.record.path.display())).into())
}

/// The study PGA: scale every record so that the first peaks at `pga` [g]; the records' own
/// `pga`/`scale` become one `scale` each.
fn apply_pga(s: &mut Scene, pga: f64) -> Result<(), Error> {
    let f = pga_factor(s, pga)?;
    let (motions, _) = base_motions(s)?;
    for (b, m) in s.loads.base.iter_mut().zip(&motions) {
        // a synth entry keeps the design PGA its spectrum was drawn for
        if let Some(sy) = b.synth.as_mut()
            && sy.pga.is_none()
        {
            let ratio = crate::motion::SynthRequest::new(sy.spectrum.clone(), 1.0, sy.seed).vertical_ratio;
            sy.pga = b.pga.map(|p| if sy.component == crate::scene::SynthComponent::V { p / ratio } else { p });
        }
        b.scale = Some(m.scale * f);
        b.pga = None;
    }
    Ok(())
}

/// The scene of a run: the base scene (`base`, absolute paths, as JSON) with the study's
/// `all`, the run's axis values, its overrides and `extra`, named `name`, with no output
/// directory of its own (the plan gives it one).
pub fn variant_scene(study: &Study, base: &Value, labels: &[(String, String)], overrides: &[Variation], name: &str) -> Result<Scene, Error> {
    let invalid = |message: String| -> Error { StudyError::Invalid { path: study.path.clone(), message }.into() };
    let mut vars: Vec<(String, &Variation)> = vec![("`all`".into(), &study.all)];
    for (axis, label) in labels {
        let a = study.axis(axis).ok_or_else(|| invalid(format!("run {name}: no axis \"{axis}\"")))?;
        let v = a.value(label).ok_or_else(|| invalid(format!("run {name}: axis \"{axis}\" has no value \"{label}\"")))?;
        vars.push((format!("axis \"{axis}\" value \"{label}\""), &v.variation));
    }
    for o in overrides {
        vars.push(("the run's `with`".into(), o));
    }
    let mut v = base.clone();
    for (what, var) in &vars {
        apply_json(&mut v, var).map_err(|e| invalid(format!("run {name}, {what}: {e}")))?;
    }
    let mut s: Scene = match serde_json::from_value(v) {
        Ok(s) => s,
        Err(e) => {
            // name the variation that breaks the scene: try each alone on the base
            for (what, var) in &vars {
                let mut one = base.clone();
                if apply_json(&mut one, var).is_ok()
                    && let Err(e1) = serde_json::from_value::<Scene>(one)
                {
                    let paths: Vec<&str> = var.scene.keys().map(String::as_str).collect();
                    return Err(invalid(format!("run {name}, {what}{}: the scene does not accept it: {e1}", if paths.is_empty() { String::new() } else { format!(" (paths {})", paths.join(", ")) })));
                }
            }
            return Err(invalid(format!("run {name}: the variations together give an invalid scene: {e}")));
        }
    };
    let mut pga = None;
    let mut scale = 1.0;
    for (_, var) in &vars {
        pga = var.pga.or(pga);
        scale *= var.scale.unwrap_or(1.0);
    }
    if let Some(p) = pga {
        apply_pga(&mut s, p)?;
    }
    if scale != 1.0 {
        for b in &mut s.loads.base {
            match b.pga.as_mut() {
                Some(p) => *p *= scale,
                None => b.scale = Some(b.scale.unwrap_or(1.0) * scale),
            }
        }
    }
    // Paths a study patches in (an axis's record, a mesh) are written relative to the study
    // file, like its base scene; the base's own are absolute already.
    let study_dir = absolute(study.path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new(".")));
    s.resolve_paths_against(&study_dir);
    s.name = Some(name.to_string());
    s.output.dir = None;
    s.validate().map_err(|e| invalid(format!("run {name}: {e}")))?;
    Ok(s)
}

/// The scene of any combination of labels (axes not given take their first value) plus
/// extra variations, named `name`: what a study's own steps (strength reduction, a reference
/// level) use to get a scene of the study without being one of its runs.
pub fn scene_for(study: &Study, base: &Scene, labels: &[(&str, &str)], extra: &[Variation], name: &str) -> Result<Scene, Error> {
    let mut full: Vec<(String, String)> = study.axes.iter().map(|a| (a.name.clone(), a.values[0].label.clone())).collect();
    for (a, l) in labels {
        let slot = full.iter_mut().find(|(n, _)| n == a).ok_or_else(|| Error::from(StudyError::Invalid { path: study.path.clone(), message: format!("no axis \"{a}\" (axes: {})", study.axes.iter().map(|x| x.name.as_str()).collect::<Vec<_>>().join(", ")) }))?;
        slot.1 = l.to_string();
    }
    let v = serde_json::to_value(base).expect("a scene serialises");
    variant_scene(study, &v, &full, extra, name)
}

/// A run as written to `plan.json`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PlannedRun {
    #[serde(flatten)]
    pub spec: RunSpec,
    /// Its scene file and its results directory (absolute).
    pub scene: PathBuf,
    pub dir: PathBuf,
}

/// A study's own step as written to `plan.json`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PlannedStep {
    pub name: String,
    /// Its result file and its log (absolute).
    pub output: PathBuf,
    pub log: PathBuf,
}

/// `<out>/plan.json`: what `study plan` wrote; read back by `study report`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Plan {
    pub study: PathBuf,
    pub name: String,
    pub kind: String,
    pub out: PathBuf,
    pub runs: Vec<PlannedRun>,
    pub steps: Vec<PlannedStep>,
}

impl Plan {
    /// Read `<out>/plan.json` (typed).
    pub fn read(out: &Path) -> Result<Plan, OutputError> {
        let p = out.join("plan.json");
        let text = std::fs::read_to_string(&p).map_err(|e| OutputError::read(&p, format!("{e} (run `jointquake study plan` first)")))?;
        let plan: Plan = serde_json::from_str(&text).map_err(|e| OutputError::read(&p, format!("not a study plan: {e} (re-run `jointquake study plan`)")))?;
        Ok(plan.moved_to(&absolute(out)))
    }

    /// The plan with its output directory at `out`: the paths under the directory it was
    /// planned in are moved along, so that a result directory copied elsewhere (from a
    /// cluster to a laptop) reads as it was written.
    fn moved_to(mut self, out: &Path) -> Plan {
        if self.out == out {
            return self;
        }
        let from = std::mem::replace(&mut self.out, out.to_path_buf());
        let move_path = |p: &mut PathBuf| {
            if let Ok(rel) = p.strip_prefix(&from) {
                *p = out.join(rel);
            }
        };
        for r in &mut self.runs {
            move_path(&mut r.scene);
            move_path(&mut r.dir);
        }
        for s in &mut self.steps {
            move_path(&mut s.output);
            move_path(&mut s.log);
        }
        self
    }
}

/// Files written by [`write_plan`].
#[derive(Clone, Debug, Serialize)]
pub struct PlanFiles {
    pub plan: PathBuf,
    pub makefile: PathBuf,
    pub scenes: Vec<PathBuf>,
    /// Scenes whose content changed (their runs are stale).
    pub changed: usize,
    pub meshes: Vec<PathBuf>,
}

/// Write `path` only when its content differs (keeps the mtime `make` compares).
fn write_if_changed(path: &Path, text: &str) -> Result<bool, OutputError> {
    if std::fs::read_to_string(path).is_ok_and(|t| t == text) {
        return Ok(false);
    }
    crate::report::file::write_atomic(path, text.as_bytes()).map_err(|e| OutputError::write(path, e))?;
    Ok(true)
}

/// Make-safe form of a path (spaces would split a target).
pub(crate) fn mk_path(p: &Path) -> Result<String, Error> {
    let s = p.display().to_string();
    if s.contains(' ') || s.contains('$') || s.contains(':') {
        return Err(ModelError::Invalid(format!("{s}: the generated Makefile cannot name a path with spaces, `$` or `:`; move the study or its output")).into());
    }
    Ok(s)
}

/// Write `<out>/scenes/<id>.json` for every run, `<out>/plan.json` and `<out>/runs.mk` (a
/// Makefile with one target per run and per step of the study, for `make -j`), and mesh every
/// distinct geometry once now, so that parallel runs never mesh the same `.geo` at once.
pub fn write_plan(study: &Study, steps: &[StepSpec], mesh_cache: &Path, bin: &str) -> Result<PlanFiles, Error> {
    let base = load_base(study)?;
    let base_v = serde_json::to_value(&base).expect("a scene serialises");
    std::fs::create_dir_all(&study.out).map_err(|e| OutputError::write(&study.out, e))?;
    let out = absolute(&study.out);
    let scenes_dir = out.join("scenes");
    std::fs::create_dir_all(&scenes_dir).map_err(|e| OutputError::write(&scenes_dir, e))?;
    let runs = plan_runs(study)?;
    let mut planned = Vec::new();
    let mut scenes = Vec::new();
    let mut meshes: Vec<PathBuf> = Vec::new();
    let mut changed = 0;
    for r in &runs {
        crate::interrupt::check("the planning of the study (its scenes and meshes)")?;
        let s = variant_scene(study, &base_v, &r.labels, &r.overrides, &r.id)?;
        if let Some(geo) = &s.geometry.geo {
            let m = crate::gmsh::mesh_geo(geo, &s.geometry.set, mesh_cache)?;
            if !meshes.contains(&m) {
                meshes.push(m);
            }
        }
        let p = scenes_dir.join(format!("{}.json", r.id));
        if write_if_changed(&p, &serde_json::to_string_pretty(&s).expect("a scene serialises"))? {
            changed += 1;
        }
        planned.push(PlannedRun { spec: r.clone(), scene: p.clone(), dir: out.join("runs").join(&r.id) });
        scenes.push(p);
    }
    let study_abs = absolute(&study.path);
    let planned_steps: Vec<PlannedStep> = steps.iter().map(|s| PlannedStep { name: s.name.clone(), output: out.join(&s.output), log: out.join(format!("{}.log", s.name)) }).collect();
    let plan = Plan { study: study_abs.clone(), name: study.name.clone(), kind: study.kind.clone(), out: out.clone(), runs: planned, steps: planned_steps };
    let plan_path = out.join("plan.json");
    write_if_changed(&plan_path, &serde_json::to_string_pretty(&plan).expect("a plan serialises"))?;

    let mk = out.join("runs.mk");
    let mut t = String::new();
    t.push_str(&format!("# Generated by `jointquake study plan` for {}: one target per run and per step.\n", study_abs.display()));
    t.push_str("# `make -f runs.mk -j2 all`. A run is redone when its scene changed since it ran (or it never ran);\n");
    t.push_str("# a run that fails leaves failed.txt (the error) and does not stop the others: the report names it.\n");
    t.push_str(&format!("BIN ?= {bin}\nOUT := {}\nSTUDY := {}\nCACHE := {}\n", mk_path(&out)?, mk_path(&study_abs)?, mk_path(&absolute(mesh_cache))?));
    t.push_str("RUNS :=");
    for r in &runs {
        t.push_str(&format!(" \\\n  {}", r.id));
    }
    t.push_str("\n\n.PHONY: all runs steps\nall: runs steps\nruns: $(RUNS:%=$(OUT)/runs/%/.done)\nsteps:");
    for s in &plan.steps {
        t.push_str(&format!(" $(OUT)/.{}.done", s.name));
    }
    t.push_str("\n\n$(OUT)/runs/%/.done: $(OUT)/scenes/%.json\n");
    push_recipe_into(&RecipeVars { bin: "$(BIN)", out: "$(OUT)", id: "$*", cache: "$(CACHE)", threads: "1", dollar: "$$" }, &mut t);
    write_alone_rules_into(&runs, &mut t);
    for (s, spec) in plan.steps.iter().zip(steps) {
        let output = mk_path(&s.output)?;
        t.push_str(&format!("\n$(OUT)/.{n}.done: $(STUDY) {scene}\n", n = s.name, scene = mk_path(&absolute(&study.scene))?));
        t.push_str(&format!("\t@rm -f {output} {output}.failed.txt\n\t@echo \"{about}\"\n", about = spec.about.replace('"', "'")));
        t.push_str(&format!(
            "\t@$(BIN) study step $(STUDY) {n} --cache $(CACHE) --threads 1 > {log} 2>&1 || {{ grep '^error' {log} > {output}.failed.txt || tail -n 5 {log} > {output}.failed.txt; echo \"step {n} FAILED: $$(cat {output}.failed.txt)\"; }}\n\t@touch $@\n",
            n = s.name,
            log = mk_path(&s.log)?
        ));
    }
    write_if_changed(&mk, &t)?;
    Ok(PlanFiles { plan: plan_path, makefile: mk, scenes, changed, meshes })
}

/// [`run_recipe`]'s commands as the recipe lines of a `runs.mk` rule (silent, tab-indented).
fn push_recipe_into(vars: &RecipeVars, t: &mut String) {
    for line in run_recipe(vars) {
        t.push_str(&format!("\t@{line}\n"));
    }
}

/// The rules of `runs.mk` for the runs that need the machine alone ([`RunSpec::alone`]): each
/// its own target on `$(ALONE_THREADS)` threads, after the previous one (order-only: a failed
/// run does not stop the next), and every other run after the last of them; nothing when there
/// are none.
fn write_alone_rules_into(runs: &[RunSpec], t: &mut String) {
    let alone: Vec<&str> = runs.iter().filter(|r| r.alone).map(|r| r.id.as_str()).collect();
    let Some(last) = alone.last() else { return };
    t.push_str("\n# Runs that need the machine alone (`alone` in the study): one at a time, first, each on\n");
    t.push_str("# ALONE_THREADS threads; the other runs wait for the last of them.\nALONE_THREADS ?= 2\n");
    for (k, id) in alone.iter().enumerate() {
        let after = if k > 0 { format!(" | $(OUT)/runs/{}/.done", alone[k - 1]) } else { String::new() };
        t.push_str(&format!("\n$(OUT)/runs/{id}/.done: $(OUT)/scenes/{id}.json{after}\n"));
        push_recipe_into(&RecipeVars { bin: "$(BIN)", out: "$(OUT)", id, cache: "$(CACHE)", threads: "$(ALONE_THREADS)", dollar: "$$" }, t);
    }
    for r in runs.iter().filter(|r| !r.alone) {
        t.push_str(&format!("$(OUT)/runs/{}/.done: | $(OUT)/runs/{last}/.done\n", r.id));
    }
}

/// Where the commands of [`run_recipe`] find their parts: shell words (a path checked by the
/// caller, or a variable of the Makefile or script that runs them).
pub struct RecipeVars<'a> {
    /// The jointquake binary.
    pub bin: &'a str,
    /// The study's output directory.
    pub out: &'a str,
    /// The run id.
    pub id: &'a str,
    /// The mesh cache.
    pub cache: &'a str,
    /// `--threads` of the run.
    pub threads: &'a str,
    /// What the shell's `$` is written as: `$$` in a Makefile, `$` in a script.
    pub dollar: &'a str,
}

/// The shell commands that run one planned run and record its outcome, one per line: the
/// recipe of a run in `runs.mk` and the body of a Slurm array task (`study submit`), written
/// once. The run's terminal output goes to `<out>/runs/<id>.log`; a run that stops with an
/// error leaves `failed.txt` (the error line, else the log's tail) and does not fail the
/// recipe; `.done` is touched last, so a run killed before it ends (Ctrl-C, `scancel`) is redone.
pub fn run_recipe(v: &RecipeVars) -> Vec<String> {
    let RecipeVars { bin, out, id, cache, threads, dollar } = v;
    let dir = format!("{out}/runs/{id}");
    let log = format!("{out}/runs/{id}.log");
    vec![
        format!("mkdir -p {dir}"),
        format!("rm -f {dir}/failed.txt {dir}/summary.json {dir}/.done"),
        format!("echo \"run {id}\""),
        format!(
            "{bin} run {out}/scenes/{id}.json --out {dir} --cache {cache} --threads {threads} --quiet > {log} 2>&1 || {{ grep '^error' {log} > {dir}/failed.txt || tail -n 5 {log} > {dir}/failed.txt; echo \"run {id} FAILED: {dollar}(cat {dir}/failed.txt)\"; }}"
        ),
        format!("touch {dir}/.done"),
    ]
}

/// Whether a planned run is done, by the rule `runs.mk` gives `make` for the target
/// `runs/<id>/.done` made from `scenes/<id>.json`: not done while `.done` is missing, stale
/// when the scene is newer than it. Written once for what does not go through `make`: the
/// report (`results`) and `study submit` (which tasks a re-submit runs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RunFreshness {
    /// `.done` is there and not older than the scene: the run ended (finished or failed).
    Done,
    /// No `.done`: never run, still running, or killed before it ended.
    NotDone,
    /// `.done` is older than the scene: the scene changed after the run.
    Stale,
}

impl PlannedRun {
    /// The run's `.done` marker (touched when its recipe ends).
    pub fn done_marker(&self) -> PathBuf {
        self.dir.join(".done")
    }

    /// The run's terminal output (`<out>/runs/<id>.log`).
    pub fn log(&self) -> PathBuf {
        self.dir.with_file_name(format!("{}.log", self.spec.id))
    }

    /// [`RunFreshness`] of the run now.
    pub fn freshness(&self) -> RunFreshness {
        let mtime = |f: &Path| std::fs::metadata(f).and_then(|m| m.modified()).ok();
        match (mtime(&self.done_marker()), mtime(&self.scene)) {
            (None, _) => RunFreshness::NotDone,
            (Some(d), Some(s)) if d < s => RunFreshness::Stale,
            _ => RunFreshness::Done,
        }
    }
}
