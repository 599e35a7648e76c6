//! Reading MSH 4.1 with `mshio`, plus the `$PhysicalNames` section it skips.
//!
//! Node tags: mshio keeps per-block tag maps only when the file's tags are sparse;
//! otherwise tags are the contiguous range min..=max in file order (as Gmsh writes them).

use super::{Cell, CellKind, Group, Mesh};
use crate::error::MeshError;
use mshio::mshfile::ElementType;
use std::collections::{BTreeMap, HashMap};
use std::path::PathBuf;

pub(super) fn read_msh(path: PathBuf) -> Result<Mesh, MeshError> {
    let bytes = std::fs::read(&path).map_err(|source| MeshError::Io { path: path.clone(), source })?;
    parse_msh(&bytes, path)
}

/// Parse a MSH 4.1 file held in memory; `path` is only used in messages.
pub fn parse_msh(bytes: &[u8], path: PathBuf) -> Result<Mesh, MeshError> {
    let malformed = |reason: String| MeshError::Malformed { path: path.clone(), reason };
    if !bytes.starts_with(b"$MeshFormat") {
        return Err(malformed("it does not start with $MeshFormat".into()));
    }
    let msh = mshio::parse_msh_bytes(bytes).map_err(|e| {
        let s = e.to_string();
        malformed(s.lines().take(6).collect::<Vec<_>>().join("; "))
    })?;
    if (msh.header.version - 4.1).abs() > 1e-9 {
        return Err(malformed(format!("version {} (need 4.1)", msh.header.version)));
    }
    let names = physical_names(bytes).map_err(malformed)?;

    // ---- nodes
    let nodes_sec = msh.data.nodes.as_ref().ok_or_else(|| malformed("no $Nodes section".into()))?;
    let mut nodes = Vec::with_capacity(nodes_sec.num_nodes as usize);
    let mut node_tags = Vec::with_capacity(nodes_sec.num_nodes as usize);
    let mut next_tag = nodes_sec.min_node_tag;
    for block in &nodes_sec.node_blocks {
        let mut tags = vec![0u64; block.nodes.len()];
        match &block.node_tags {
            Some(map) => {
                for (&t, &i) in map {
                    tags[i] = t;
                }
            }
            None => {
                for t in tags.iter_mut() {
                    *t = next_tag;
                    next_tag += 1;
                }
            }
        }
        for (n, t) in block.nodes.iter().zip(tags) {
            if !(n.x.is_finite() && n.y.is_finite() && n.z.is_finite()) {
                return Err(MeshError::NonFiniteNode { path: path.clone(), node: t });
            }
            nodes.push([n.x, n.y, n.z]);
            node_tags.push(t);
        }
    }
    let index_of: HashMap<u64, usize> = node_tags.iter().enumerate().map(|(i, &t)| (t, i)).collect();
    if index_of.len() != node_tags.len() {
        return Err(malformed("duplicate node tags".into()));
    }

    // ---- entities → physical tags
    let mut entity_phys: HashMap<(usize, i32), Vec<i32>> = HashMap::new();
    if let Some(ent) = &msh.data.entities {
        for p in &ent.points {
            entity_phys.insert((0, p.tag), p.physical_tags.clone());
        }
        for c in &ent.curves {
            entity_phys.insert((1, c.tag), c.physical_tags.clone());
        }
        for s in &ent.surfaces {
            entity_phys.insert((2, s.tag), s.physical_tags.clone());
        }
        for v in &ent.volumes {
            entity_phys.insert((3, v.tag), v.physical_tags.clone());
        }
    }

    // ---- elements
    let elems = msh.data.elements.as_ref().ok_or_else(|| malformed("no $Elements section".into()))?;
    let mut cells = Vec::new();
    let mut groups: BTreeMap<(usize, i32), Vec<usize>> = BTreeMap::new();
    let mut local = Vec::with_capacity(8);
    for block in &elems.element_blocks {
        let kind = match block.element_type {
            ElementType::Tet4 => CellKind::Tet4,
            ElementType::Hex8 => CellKind::Hex8,
            ElementType::Tri3 => CellKind::Tri3,
            ElementType::Qua4 => CellKind::Quad4,
            ElementType::Pnt | ElementType::Lin2 => continue, // points and lines are not used
            other => {
                let element = block.elements.first().map(|e| e.element_tag).unwrap_or(0);
                return Err(MeshError::UnsupportedElement {
                    path: path.clone(),
                    element,
                    kind: format!("{other:?}"),
                });
            }
        };
        let dim = block.entity_dim as usize;
        let phys = entity_phys.get(&(dim, block.entity_tag)).cloned().unwrap_or_default();
        for e in &block.elements {
            if e.nodes.len() != kind.n_nodes() {
                return Err(malformed(format!("element {} has {} nodes, {:?} needs {}", e.element_tag, e.nodes.len(), kind, kind.n_nodes())));
            }
            local.clear();
            for &t in &e.nodes {
                let i = *index_of.get(&t).ok_or(MeshError::MissingNode { path: path.clone(), element: e.element_tag, node: t })?;
                local.push(i);
            }
            let id = cells.len();
            cells.push(Cell::new(kind, e.element_tag, &local));
            for &p in &phys {
                groups.entry((dim, p.abs())).or_default().push(id);
            }
        }
    }
    let groups = groups
        .into_iter()
        .map(|((dim, tag), cells)| Group {
            name: names.get(&(dim, tag)).cloned().unwrap_or_else(|| format!("{dim}:{tag}")),
            dim,
            tag,
            cells,
        })
        .collect();
    Ok(Mesh { source: path, nodes, node_tags, cells, groups })
}

/// Parse the `$PhysicalNames` section (text even in binary files): `dim tag "name"` per line.
fn physical_names(bytes: &[u8]) -> Result<HashMap<(usize, i32), String>, String> {
    let mut out = HashMap::new();
    let Some(start) = find(bytes, b"$PhysicalNames") else { return Ok(out) };
    let rest = &bytes[start + b"$PhysicalNames".len()..];
    let end = find(rest, b"$EndPhysicalNames").ok_or("$PhysicalNames has no $EndPhysicalNames")?;
    let text = std::str::from_utf8(&rest[..end]).map_err(|_| "$PhysicalNames is not UTF-8 text")?;
    let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
    let n: usize = lines.next().and_then(|l| l.parse().ok()).ok_or("$PhysicalNames: missing count")?;
    for _ in 0..n {
        let l = lines.next().ok_or("$PhysicalNames: fewer names than its count")?;
        let mut it = l.splitn(3, char::is_whitespace);
        let dim: usize = it.next().and_then(|s| s.parse().ok()).ok_or_else(|| format!("$PhysicalNames: bad line `{l}`"))?;
        let tag: i32 = it.next().and_then(|s| s.trim().parse().ok()).ok_or_else(|| format!("$PhysicalNames: bad line `{l}`"))?;
        let name = it.next().unwrap_or("").trim().trim_matches('"').to_string();
        out.insert((dim, tag), name);
    }
    Ok(out)
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}
