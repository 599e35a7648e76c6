//! Reading MSH 4.1 with `mshio`, plus the `$PhysicalNames` section it skips.
//!
//! Node tags: mshio keeps per-block tag maps only when the file's tags are sparse
//! (max - min + 1 > count). When they are dense it drops them, yet dense tags need not
//! appear in file order (another writer may list 3 1 2), so in that case the tags are
//! read here directly from the `$Nodes` section ([`node_tags_in_file_order`]).

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
    let file_tags = if nodes_sec.node_blocks.iter().any(|b| b.node_tags.is_none()) {
        let tags = node_tags_in_file_order(bytes, &msh.header).map_err(malformed)?;
        let n: usize = nodes_sec.node_blocks.iter().map(|b| b.nodes.len()).sum();
        if tags.len() != n {
            return Err(malformed(format!("$Nodes lists {} node tags for {n} nodes", tags.len())));
        }
        tags
    } else {
        Vec::new()
    };
    let mut next = 0usize; // position in file_tags
    for block in &nodes_sec.node_blocks {
        let mut tags = vec![0u64; block.nodes.len()];
        match &block.node_tags {
            Some(map) => {
                for (&t, &i) in map {
                    tags[i] = t;
                }
            }
            None => {
                tags.copy_from_slice(&file_tags[next..next + block.nodes.len()]);
            }
        }
        next += block.nodes.len();
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

/// Node tags of the `$Nodes` section in file order (ASCII or binary MSH 4.1; mshio has
/// already validated the section's structure, this only walks it again for the tags).
fn node_tags_in_file_order(bytes: &[u8], header: &mshio::MshHeader) -> Result<Vec<u64>, String> {
    const ERR: &str = "$Nodes section ends early";
    let start = find(bytes, b"$Nodes").ok_or("no $Nodes section")? + b"$Nodes".len();
    let body = &bytes[start..];
    let mut tags = Vec::new();
    if header.file_type == 0 {
        let end = find(body, b"$EndNodes").ok_or("$Nodes has no $EndNodes")?;
        let text = std::str::from_utf8(&body[..end]).map_err(|_| "$Nodes is not text in an ASCII file")?;
        let mut tok = text.split_ascii_whitespace();
        fn num<'a>(tok: &mut impl Iterator<Item = &'a str>) -> Result<u64, String> {
            let t = tok.next().ok_or(ERR)?;
            t.parse::<u64>().map_err(|e| format!("$Nodes: `{t}`: {e}"))
        }
        let blocks = num(&mut tok)?;
        for _ in 0..3 {
            num(&mut tok)?; // numNodes minNodeTag maxNodeTag
        }
        for _ in 0..blocks {
            let (_dim, _entity, _parametric, n) = (num(&mut tok)?, num(&mut tok)?, num(&mut tok)?, num(&mut tok)?);
            for _ in 0..n {
                tags.push(num(&mut tok)?);
            }
            for _ in 0..3 * n {
                tok.next().ok_or(ERR)?; // x y z (parametric nodes are rejected by mshio)
            }
        }
    } else {
        // binary: "4.1 1 8\n" then a binary int 1 that tells the byte order
        let fmt = find(bytes, b"$MeshFormat").ok_or("no $MeshFormat")?;
        let nl = fmt + bytes[fmt..].iter().position(|&b| b == b'\n').ok_or(ERR)? + 1;
        let nl = nl + bytes[nl..].iter().position(|&b| b == b'\n').ok_or(ERR)? + 1;
        let one = bytes.get(nl..nl + header.int_size).ok_or(ERR)?;
        let little = one.first() == Some(&1);
        let (st, is, fs) = (header.size_t_size, header.int_size, header.float_size);
        let mut pos = 1usize; // skip the newline after "$Nodes"
        let mut read = |size: usize| -> Result<u64, String> {
            let b = body.get(pos..pos + size).ok_or(ERR)?;
            pos += size;
            let mut v = 0u64;
            for k in 0..size.min(8) {
                let byte = if little { b[k] } else { b[size - 1 - k] };
                v |= (byte as u64) << (8 * k);
            }
            Ok(v)
        };
        let blocks = read(st)?;
        for _ in 0..3 {
            read(st)?;
        }
        for _ in 0..blocks {
            let (_dim, _entity, _parametric, n) = (read(is)?, read(is)?, read(is)?, read(st)?);
            for _ in 0..n {
                tags.push(read(st)?);
            }
            for _ in 0..3 * n {
                read(fs)?;
            }
        }
    }
    Ok(tags)
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
