//! The study file (`pipelines/*_study.json`): a base scene, axes of variation and the runs.
//!
//! Format and every field with its default: `docs/studies.md`. Paths are relative to the study
//! file. Unknown keys are errors (`deny_unknown_fields`), and every error names the study file
//! and the field (`axes[2].values[1].scene./output/frams`, `runs[3].axes.mesh`, …).

use crate::error::StudyError;
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One change to the base scene. Used for an axis value, for `all` (every run) and for a run
/// selection's `with` (per-run overrides). Applied in that order: `all`, then the values of the
/// run's axes in axis order, then the overrides; inside one variation: `set`, `joints`,
/// `joint`, `scene` (JSON patches of the scene), then `pga`, then `scale` (on the records).
#[derive(Clone, Debug, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Variation {
    /// Label of an axis value: its part of the run id (letters, digits, `.`, `_`, `+`; may be
    /// empty, then the value adds nothing to the id). Required for an axis value given as an
    /// object; not allowed in `all` or `with`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub label: Option<String>,
    /// Relative cost of an axis value [-] (default 1): a run's cost is the product of its
    /// values' costs, and the plan starts the most expensive runs first, so that parallel
    /// jobs end together. Axis values only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cost: Option<f64>,
    /// The runs with this axis value need the machine to themselves [-] (default false): too
    /// large in memory to run beside another (the dam's h 2.5 m mesh: 12.8 GB each, two of them
    /// above a 24 GB machine). `runs.mk` runs them first, one at a time, each on
    /// `$(ALONE_THREADS)` threads (`make study` passes its JOBS), and the other runs after them.
    /// Axis values only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub alone: Option<bool>,
    /// The study PGA [g]: the target PGA of the first base record; every record of the scene is
    /// scaled by the same factor, so the others keep their ratio to it (unlike a scene entry's
    /// own `pga`, the record PGA, which scales that record alone: `dynamics::loads::scale_for_pga`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pga: Option<f64>,
    /// Factor on every base record's amplitude [-] (after `pga`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<f64>,
    /// Mesh parameters merged into `geometry.set` (`-setnumber` of the `.geo`).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub set: BTreeMap<String, f64>,
    /// Fields set on every joint (the fields of a scene joint: `method`, `layer`, `phi`, `mu`,
    /// `cohesion`, …).
    #[serde(default, skip_serializing_if = "Map::is_empty")]
    pub joints: Map<String, Value>,
    /// Fields set on the joints named (joint name → fields).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub joint: BTreeMap<String, Map<String, Value>>,
    /// Any scene field by path (`/output/frames`, `/materials/0/E`, `/boundary`): the value
    /// replaces what is there (objects on the way are created; array indices must exist).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub scene: BTreeMap<String, Value>,
}

impl Variation {
    pub fn is_empty(&self) -> bool {
        self.pga.is_none() && self.scale.is_none() && self.set.is_empty() && self.joints.is_empty() && self.joint.is_empty() && self.scene.is_empty()
    }
}

/// An axis: a name and its values. A value is a [`Variation`] object with a `label`, or, when
/// the axis has a `field`, a bare number or string for that field.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct AxisFile {
    pub name: String,
    /// What a bare value sets: `pga` [g], `scale`, `set.<name>` (a mesh parameter),
    /// `joints.<field>` (that field of every joint) or a scene path `/…`. Default none (every
    /// value is an object).
    #[serde(default)]
    pub field: Option<String>,
    /// Decimals of a bare number in its label (`pga` 0.5 with 2 → `pga0.50`). Default: the
    /// shortest form (`pga0.5`).
    #[serde(default)]
    pub decimals: Option<usize>,
    pub values: Vec<Value>,
}

/// A selection of runs: a label, a list of labels or `"*"` (every value) per axis; an axis not
/// named takes its first value. The runs are the product of the selected values.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SelectionFile {
    pub axes: BTreeMap<String, Value>,
    /// Overrides for these runs (e.g. frames for the one run to look at in ParaView).
    #[serde(default)]
    pub with: Variation,
}

/// The study file as written.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct StudyFile {
    /// Name; output under `out/<name>` unless `out` is given. Default: the file stem.
    #[serde(default)]
    pub name: Option<String>,
    /// The base scene.
    pub scene: PathBuf,
    /// Output directory. Default `out/<name>`.
    #[serde(default)]
    pub out: Option<PathBuf>,
    /// The study's own report: `{"kind": "<kind>", …its parameters}` (docs/studies.md lists
    /// the kinds). Default `{"kind": "runs"}`: the run table only.
    #[serde(default)]
    pub report: Option<Map<String, Value>>,
    /// Applied to every run before its axis values.
    #[serde(default)]
    pub all: Variation,
    pub axes: Vec<AxisFile>,
    /// Axes whose labels make the run id, in order. Default: every axis, in axis order.
    #[serde(default)]
    pub id: Option<Vec<String>>,
    /// The runs: a list of selections (their union, in order, without duplicates). Default:
    /// the product of all axes.
    #[serde(default)]
    pub runs: Option<Vec<SelectionFile>>,
}

/// An axis value after loading.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct AxisValue {
    pub label: String,
    pub cost: f64,
    /// [`Variation::alone`].
    #[serde(default)]
    pub alone: bool,
    pub variation: Variation,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Axis {
    pub name: String,
    pub values: Vec<AxisValue>,
}

impl Axis {
    pub fn value(&self, label: &str) -> Option<&AxisValue> {
        self.values.iter().find(|v| v.label == label)
    }
}

/// One selection after loading: per axis the labels chosen, and the overrides.
#[derive(Clone, Debug)]
pub struct Selection {
    pub labels: Vec<Vec<String>>,
    pub with: Variation,
}

/// A loaded, checked study.
#[derive(Clone, Debug)]
pub struct Study {
    /// The study file (as given).
    pub path: PathBuf,
    pub name: String,
    /// The base scene (resolved against the study file's directory).
    pub scene: PathBuf,
    pub out: PathBuf,
    /// The report kind and its parameters (without `kind`).
    pub kind: String,
    pub params: Map<String, Value>,
    pub all: Variation,
    pub axes: Vec<Axis>,
    /// Indices into `axes` of the labels that make the id.
    pub id_axes: Vec<usize>,
    pub selections: Vec<Selection>,
}

fn label_ok(s: &str) -> bool {
    s.chars().all(|c| c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '+'))
}

fn number_label(x: f64, decimals: Option<usize>) -> String {
    match decimals {
        Some(d) => format!("{x:.d$}"),
        None => format!("{x}"),
    }
}

impl Study {
    /// Read and check a study file.
    pub fn load(path: &Path) -> Result<Study, StudyError> {
        let invalid = |message: String| StudyError::Invalid { path: path.to_path_buf(), message };
        let text = crate::files::read_text_bounded(path, crate::files::MAX_TEXT_INPUT).map_err(|e| StudyError::Io { path: path.to_path_buf(), message: e.to_string() })?;
        let f: StudyFile = serde_json::from_str(&text).map_err(|e| invalid(format!("{e} (the fields are in docs/studies.md)")))?;
        let dir = path.parent().unwrap_or(Path::new("."));
        let name = f.name.clone().unwrap_or_else(|| path.file_stem().and_then(|s| s.to_str()).unwrap_or("study").to_string());
        if name.is_empty() || !label_ok(&name) {
            return Err(invalid(format!("`name` = \"{name}\": use letters, digits, `.`, `_`, `+` (it names the output directory)")));
        }
        let scene = if f.scene.is_relative() { dir.join(&f.scene) } else { f.scene.clone() };
        let out = match &f.out {
            Some(o) if o.is_relative() => dir.join(o),
            Some(o) => o.clone(),
            None => PathBuf::from("out").join(&name),
        };
        let mut report = f.report.clone().unwrap_or_default();
        let kind = match report.remove("kind") {
            Some(Value::String(k)) => k,
            None if report.is_empty() => "runs".to_string(),
            None => return Err(invalid("`report` needs a `kind` (e.g. \"wedge\", \"incline\", \"runs\")".into())),
            Some(v) => return Err(invalid(format!("`report.kind` = {v}: must be a string"))),
        };
        only_for_values(path, &f.all, "all")?;
        if f.axes.is_empty() {
            return Err(invalid("`axes`: give at least one axis (a name and its values)".into()));
        }
        let mut axes = Vec::new();
        for (i, a) in f.axes.iter().enumerate() {
            let at = format!("axes[{i}] (\"{}\")", a.name);
            if a.name.is_empty() || !label_ok(&a.name) {
                return Err(invalid(format!("{at}: `name`: use letters, digits, `.`, `_`, `+`")));
            }
            if f.axes[..i].iter().any(|b| b.name == a.name) {
                return Err(invalid(format!("{at}: axis \"{}\" is given twice", a.name)));
            }
            if a.values.is_empty() {
                return Err(invalid(format!("{at}: `values` is empty")));
            }
            axes.push(read_axis(path, a, &at)?);
        }
        let axis_index = |n: &str, at: &str| -> Result<usize, StudyError> {
            axes.iter().position(|a| a.name == n).ok_or_else(|| {
                invalid(format!("{at}: no axis \"{n}\" (axes: {})", axes.iter().map(|a| a.name.as_str()).collect::<Vec<_>>().join(", ")))
            })
        };
        let id_axes = match &f.id {
            Some(ids) => {
                let mut v = Vec::new();
                for n in ids {
                    v.push(axis_index(n, "`id`")?);
                }
                for (i, a) in axes.iter().enumerate() {
                    if !v.contains(&i) && a.values.len() > 1 {
                        return Err(invalid(format!("`id`: axis \"{}\" has several values but is not in the id, so runs would share ids", a.name)));
                    }
                }
                v
            }
            None => (0..axes.len()).collect(),
        };
        let selections = read_selections(path, f.runs.as_deref(), &axes)?;
        Ok(Study { path: path.to_path_buf(), name, scene, out, kind, params: report, all: f.all.clone(), axes, id_axes, selections })
    }

    pub fn axis(&self, name: &str) -> Option<&Axis> {
        self.axes.iter().find(|a| a.name == name)
    }
}

/// A variation that is not an axis value (`all`, a selection's `with`): no `label`, no `cost`,
/// and the checks of every variation.
fn only_for_values(path: &Path, v: &Variation, field: &str) -> Result<(), StudyError> {
    let invalid = |message: String| StudyError::Invalid { path: path.to_path_buf(), message };
    if v.label.is_some() || v.cost.is_some() || v.alone.is_some() {
        return Err(invalid(format!("`{field}`: `label`, `cost` and `alone` belong to axis values only")));
    }
    check_variation(v, field).map_err(invalid)
}

/// One axis of the study file (`at` names it in errors): its values, labelled, costed and
/// checked (labels file-safe and distinct, costs positive).
fn read_axis(path: &Path, a: &AxisFile, at: &str) -> Result<Axis, StudyError> {
    let invalid = |message: String| StudyError::Invalid { path: path.to_path_buf(), message };
    let mut values: Vec<AxisValue> = Vec::new();
    for (k, v) in a.values.iter().enumerate() {
        let vat = format!("{at}.values[{k}]");
        let value = match v {
            Value::Object(_) => {
                let var: Variation = serde_json::from_value(v.clone()).map_err(|e| invalid(format!("{vat}: {e}")))?;
                let label = var.label.clone().ok_or_else(|| invalid(format!("{vat}: an object value needs a `label` (its part of the run id; \"\" for none)")))?;
                let cost = var.cost.unwrap_or(1.0);
                let alone = var.alone.unwrap_or(false);
                AxisValue { label, cost, alone, variation: Variation { label: None, cost: None, alone: None, ..var } }
            }
            Value::Number(_) | Value::String(_) => {
                let field = a.field.as_deref().ok_or_else(|| invalid(format!("{vat}: a bare value {v} needs the axis' `field` (pga, scale, set.<name>, joints.<field> or a scene path /…); or give an object with a `label`")))?;
                let label = match v {
                    Value::Number(n) => format!("{}{}", a.name, number_label(n.as_f64().unwrap_or(f64::NAN), a.decimals)),
                    Value::String(s) => s.clone(),
                    _ => unreachable!(),
                };
                let variation = field_variation(field, v).map_err(|m| invalid(format!("{at}: `field` = \"{field}\": {m}")))?;
                AxisValue { label, cost: 1.0, alone: false, variation }
            }
            other => return Err(invalid(format!("{vat}: {other} is neither a number, a string nor an object"))),
        };
        if !label_ok(&value.label) {
            return Err(invalid(format!("{vat}: label \"{}\": use letters, digits, `.`, `_`, `+` (it goes into file names)", value.label)));
        }
        if values.iter().any(|o| o.label == value.label) {
            return Err(invalid(format!("{vat}: label \"{}\" is given twice on this axis", value.label)));
        }
        if !(value.cost.is_finite() && value.cost > 0.0) {
            return Err(invalid(format!("{vat}: `cost` = {} must be a positive number", value.cost)));
        }
        check_variation(&value.variation, &vat).map_err(invalid)?;
        values.push(value);
    }
    Ok(Axis { name: a.name.clone(), values })
}

/// The run selections of the study file (`None`: the product of all axes), each label checked
/// against its axis.
fn read_selections(path: &Path, runs: Option<&[SelectionFile]>, axes: &[Axis]) -> Result<Vec<Selection>, StudyError> {
    let invalid = |message: String| StudyError::Invalid { path: path.to_path_buf(), message };
    let axis_index = |n: &str, at: &str| -> Result<usize, StudyError> {
        axes.iter().position(|a| a.name == n).ok_or_else(|| {
            invalid(format!("{at}: no axis \"{n}\" (axes: {})", axes.iter().map(|a| a.name.as_str()).collect::<Vec<_>>().join(", ")))
        })
    };
    let mut selections = Vec::new();
    match runs {
        None => selections.push(Selection { labels: axes.iter().map(|a| a.values.iter().map(|v| v.label.clone()).collect()).collect(), with: Variation::default() }),
        Some(list) => {
            if list.is_empty() {
                return Err(invalid("`runs` is empty: leave it out for the product of all axes".into()));
            }
            for (i, s) in list.iter().enumerate() {
                let at = format!("runs[{i}]");
                let mut labels: Vec<Vec<String>> = axes.iter().map(|a| vec![a.values[0].label.clone()]).collect();
                for (name, v) in &s.axes {
                    let k = axis_index(name, &format!("{at}.axes"))?;
                    let known = || axes[k].values.iter().map(|x| format!("\"{}\"", x.label)).collect::<Vec<_>>().join(", ");
                    let list: Vec<String> = match v {
                        Value::String(s) if s == "*" => axes[k].values.iter().map(|x| x.label.clone()).collect(),
                        Value::String(s) => vec![s.clone()],
                        Value::Array(a) => a.iter().map(|x| x.as_str().map(str::to_string).ok_or_else(|| invalid(format!("{at}.axes.{name}: {x} is not a label (a string)")))).collect::<Result<_, _>>()?,
                        other => return Err(invalid(format!("{at}.axes.{name}: {other}: give a label, a list of labels or \"*\""))),
                    };
                    for l in &list {
                        if axes[k].value(l).is_none() {
                            return Err(invalid(format!("{at}.axes.{name}: no value labelled \"{l}\" (labels: {})", known())));
                        }
                    }
                    if list.is_empty() {
                        return Err(invalid(format!("{at}.axes.{name}: an empty list selects no run")));
                    }
                    labels[k] = list;
                }
                only_for_values(path, &s.with, &format!("{at}.with"))?;
                selections.push(Selection { labels, with: s.with.clone() });
            }
        }
    }
    Ok(selections)
}

/// The variation a bare axis value stands for.
fn field_variation(field: &str, v: &Value) -> Result<Variation, String> {
    let num = || v.as_f64().ok_or_else(|| format!("value {v} must be a number"));
    let mut var = Variation::default();
    if field == "pga" {
        var.pga = Some(num()?);
    } else if field == "scale" {
        var.scale = Some(num()?);
    } else if let Some(p) = field.strip_prefix("set.") {
        var.set.insert(p.to_string(), num()?);
    } else if let Some(p) = field.strip_prefix("joints.") {
        var.joints.insert(p.to_string(), v.clone());
    } else if field.starts_with('/') {
        var.scene.insert(field.to_string(), v.clone());
    } else {
        return Err("expected pga, scale, set.<name>, joints.<field> or a scene path starting with /".into());
    }
    Ok(var)
}

fn check_variation(v: &Variation, at: &str) -> Result<(), String> {
    if let Some(p) = v.pga
        && !(p.is_finite() && p > 0.0)
    {
        return Err(format!("{at}: `pga` = {p} must be a positive acceleration [g]"));
    }
    if let Some(s) = v.scale
        && !(s.is_finite() && s > 0.0)
    {
        return Err(format!("{at}: `scale` = {s} must be a positive factor"));
    }
    for (k, x) in &v.set {
        if !x.is_finite() {
            return Err(format!("{at}: `set.{k}` = {x} must be a finite number"));
        }
    }
    for p in v.scene.keys() {
        if !p.starts_with('/') || p.len() < 2 {
            return Err(format!("{at}: scene path \"{p}\" must start with / (e.g. \"/output/frames\")"));
        }
    }
    Ok(())
}
