//! Expanding group patterns of a scene against a mesh's physical groups (docs/dam.md,
//! "Group patterns"; the syntax is in [`crate::mesh::pattern`]).
//!
//! Done once, right after the mesh is read and before anything looks a group up, so the rest
//! of the pipeline only ever sees plain group names. What expands:
//! - `materials[].group` (volume groups): one material entry per matched group;
//! - `boundary[].group` (any dimension): one entry per matched group;
//! - `loads.gravity.groups[]`, `damping.mass_groups[]` (volume groups): the matched names;
//! - `joints[]`: `master` is matched against the face groups; `slave` must use the same
//!   placeholders and is filled in from each match (`joint:{J}:left` / `joint:{J}:right`), so
//!   the two sides of one joint always carry the same joint number. `name` is filled in too
//!   (`"J{J}"` gives `J01`…); a pattern that expands to several joints needs a placeholder in
//!   the name. Every other field of the entry (law, method, tolerance…) is copied.
//!
//! A pattern that matches nothing is an error naming the field, the pattern and the groups
//! that exist; so is a master match whose slave partner is missing. Entries without pattern
//! syntax are left as they are (their group is checked where it is used, as before).

use crate::mesh::pattern::{binding_text, fill_text, is_pattern, GroupPattern, PatternError};
use crate::mesh::Mesh;
use crate::scene::{JointSceneSpec, Scene};
use serde::Serialize;

/// One pattern that was expanded: where it was, what it said, how many entries it became.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct PatternUse {
    /// E.g. `joints[0].master`, `materials[1].group`.
    pub field: String,
    pub pattern: String,
    /// Names it produced (groups, or joint names for a joint entry), in order.
    pub expanded: Vec<String>,
}

/// (name, dimension) of every physical group of a mesh, the input of
/// [`Scene::expand_group_patterns`].
pub fn mesh_group_names(mesh: &Mesh) -> Vec<(String, usize)> {
    mesh.groups.iter().map(|g| (g.name.clone(), g.dim)).collect()
}

fn names_of_dim(groups: &[(String, usize)], dim: Option<usize>) -> Vec<&str> {
    groups.iter().filter(|(_, d)| dim.is_none_or(|want| *d == want)).map(|(n, _)| n.as_str()).collect()
}

fn what(dim: Option<usize>) -> String {
    match dim {
        Some(3) => "volume group (dimension 3)".into(),
        Some(2) => "face group (dimension 2)".into(),
        Some(d) => format!("group of dimension {d}"),
        None => "group".into(),
    }
}

/// The groups of dimension `dim` that `pattern` matches (at least one, else an error).
fn expand_one(field: &str, pattern: &str, groups: &[(String, usize)], dim: Option<usize>) -> Result<Vec<String>, PatternError> {
    let p = GroupPattern::parse(pattern)?;
    let names = names_of_dim(groups, dim);
    let m = p.matches(names.iter().copied())?;
    if m.is_empty() {
        return Err(PatternError::NoMatch {
            field: field.to_string(),
            pattern: pattern.to_string(),
            what: what(dim),
            available: names.iter().map(|s| s.to_string()).collect(),
        });
    }
    Ok(m.into_iter().map(|(n, _)| n).collect())
}

/// Expand a list of group names where some may be patterns.
fn expand_list(field: &str, list: &mut Vec<String>, groups: &[(String, usize)], dim: Option<usize>, uses: &mut Vec<PatternUse>) -> Result<(), PatternError> {
    if !list.iter().any(|g| is_pattern(g)) {
        return Ok(());
    }
    let mut out = Vec::with_capacity(list.len());
    for (i, g) in list.iter().enumerate() {
        if is_pattern(g) {
            let f = format!("{field}[{i}]");
            let e = expand_one(&f, g, groups, dim)?;
            uses.push(PatternUse { field: f, pattern: g.clone(), expanded: e.clone() });
            out.extend(e);
        } else {
            out.push(g.clone());
        }
    }
    *list = out;
    Ok(())
}

impl Scene {
    /// Replace every group pattern of the scene by the groups of `groups` ((name, dimension),
    /// e.g. from [`mesh_group_names`]) it names; see the module documentation. Returns what
    /// was expanded (empty for a scene without patterns, which is left unchanged).
    pub fn expand_group_patterns(&mut self, groups: &[(String, usize)]) -> Result<Vec<PatternUse>, PatternError> {
        let mut uses = Vec::new();
        // materials: one entry per matched volume group
        expand_entries("materials", &mut self.materials, |m| &mut m.group, groups, Some(3), &mut uses)?;
        // boundary: one entry per matched group of any dimension
        expand_entries("boundary", &mut self.boundary, |b| &mut b.group, groups, None, &mut uses)?;
        if let Some(g) = self.loads.gravity.as_mut() {
            if let Some(list) = g.groups.as_mut() {
                expand_list("loads.gravity.groups", list, groups, Some(3), &mut uses)?;
            }
        }
        if let Some(list) = self.damping.mass_groups.as_mut() {
            expand_list("damping.mass_groups", list, groups, Some(3), &mut uses)?;
        }
        // joints: master matched, slave (and name) filled in from the captures
        if self.joints.iter().any(|j| is_pattern(&j.master) || is_pattern(&j.slave)) {
            let faces = names_of_dim(groups, Some(2));
            let mut out = Vec::new();
            for (i, j) in self.joints.iter().enumerate() {
                if !is_pattern(&j.master) && !is_pattern(&j.slave) {
                    out.push(j.clone());
                    continue;
                }
                let field = format!("joints[{i}]");
                let names = expand_joint_into(&field, j, &faces, &mut out)?;
                uses.push(PatternUse { field: format!("{field}.master"), pattern: j.master.clone(), expanded: names });
            }
            self.joints = out;
        }
        Ok(uses)
    }
}

/// Expand the entries of section `section` (`materials`, `boundary`) whose group (`group` of
/// an entry) is a pattern into one entry per matched group of dimension `dim`, the entry
/// copied; entries without pattern stay as they are.
fn expand_entries<T: Clone>(
    section: &str,
    entries: &mut Vec<T>,
    group: fn(&mut T) -> &mut String,
    groups: &[(String, usize)],
    dim: Option<usize>,
    uses: &mut Vec<PatternUse>,
) -> Result<(), PatternError> {
    if !entries.iter_mut().any(|e| is_pattern(group(e))) {
        return Ok(());
    }
    let mut out = Vec::new();
    for (i, m) in entries.iter_mut().enumerate() {
        let pattern = group(m).clone();
        if is_pattern(&pattern) {
            let field = format!("{section}[{i}].group");
            let e = expand_one(&field, &pattern, groups, dim)?;
            for g in &e {
                let mut c = m.clone();
                *group(&mut c) = g.clone();
                out.push(c);
            }
            uses.push(PatternUse { field, pattern, expanded: e });
        } else {
            out.push(m.clone());
        }
    }
    *entries = out;
    Ok(())
}

/// The joints of the pattern entry `j` (at `field`, e.g. `joints[0]`) appended to `out`: its
/// master matched against the face groups `faces`, its slave and name filled in from each
/// match. Returns the joints' names.
fn expand_joint_into(field: &str, j: &JointSceneSpec, faces: &[&str], out: &mut Vec<JointSceneSpec>) -> Result<Vec<String>, PatternError> {
    let mp = GroupPattern::parse(&j.master)?;
    let sp = GroupPattern::parse(&j.slave)?;
    let (mut a, mut b) = (mp.placeholders(), sp.placeholders());
    a.sort();
    b.sort();
    if a != b || a.is_empty() {
        return Err(PatternError::PlaceholderMismatch {
            field: format!("{field} (master/slave)"),
            pattern: j.master.clone(),
            other: j.slave.clone(),
            found: a,
            other_found: b,
        });
    }
    let m = mp.matches(faces.iter().copied())?;
    if m.is_empty() {
        return Err(PatternError::NoMatch {
            field: format!("{field}.master"),
            pattern: j.master.clone(),
            what: what(Some(2)),
            available: faces.iter().map(|s| s.to_string()).collect(),
        });
    }
    if m.len() > 1 && !j.name.contains('{') {
        let example = format!("{}{}", j.name, mp.placeholders().iter().map(|p| format!("{{{p}}}")).collect::<String>());
        return Err(PatternError::NameCollision { field: format!("{field}.name"), pattern: j.master.clone(), count: m.len(), name: j.name.clone(), example });
    }
    let mut names = Vec::with_capacity(m.len());
    for (master, bind) in &m {
        let slave = sp.instantiate(bind)?;
        if !faces.contains(&slave.as_str()) {
            return Err(PatternError::MissingPartner {
                field: format!("{field}.slave"),
                pattern: j.master.clone(),
                matched: master.clone(),
                binding: binding_text(bind),
                partner_pattern: j.slave.clone(),
                partner: slave,
                what: what(Some(2)),
            });
        }
        let name = fill_text(&j.name, bind).map_err(|missing| PatternError::UnknownPlaceholder {
            field: format!("{field}.name"),
            text: j.name.clone(),
            name: missing,
            pattern: j.master.clone(),
        })?;
        let mut c = j.clone();
        c.master = master.clone();
        c.slave = slave;
        c.name = name.clone();
        names.push(name);
        out.push(c);
    }
    Ok(names)
}
