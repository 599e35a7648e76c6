//! Reading MSH 4.1 with `mshio`, plus the `$PhysicalNames` section it skips.
//!
//! Node tags: mshio keeps per-block tag maps only when the file's tags are sparse
//! (max - min + 1 > count). When they are dense it drops them, yet dense tags need not
//! appear in file order (another writer may list 3 1 2), so in that case the tags are
//! read here directly from the `$Nodes` section ([`node_tags_in_file_order`]).

use super::{Cell, CellKind, Group, Mesh};
use crate::error::MeshError;
use mshio::mshfile::{ElementType, MshFile};
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

pub(super) fn read_msh(path: PathBuf) -> Result<Mesh, MeshError> {
    let bytes = crate::files::read_bounded(&path, crate::files::MAX_MESH_INPUT).map_err(|source| MeshError::Io { path: path.clone(), source })?;
    parse_msh(&bytes, path)
}

/// Parse a MSH 4.1 file held in memory; `path` is only used in messages.
pub fn parse_msh(bytes: &[u8], path: PathBuf) -> Result<Mesh, MeshError> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes); // a UTF-8 byte-order mark
    check_format_line(bytes, &path)?;
    let msh = mshio::parse_msh_bytes(bytes).map_err(|e| {
        let s = e.to_string();
        malformed(&path, s.lines().take(6).collect::<Vec<_>>().join("; "))
    })?;
    if (msh.header.version - 4.1).abs() > 1e-9 {
        return Err(malformed(&path, format!("version {} (need 4.1)", msh.header.version)));
    }
    let names = physical_names(bytes).map_err(|r| malformed(&path, r))?;
    let (nodes, node_tags) = read_nodes(bytes, &msh, &path)?;
    let index_of: HashMap<u64, usize> = node_tags.iter().enumerate().map(|(i, &t)| (t, i)).collect();
    if index_of.len() != node_tags.len() {
        return Err(malformed(&path, "duplicate node tags".into()));
    }
    let entity_phys = entity_physical_tags(&msh);
    let (cells, groups) = read_elements(&msh, &path, &index_of, &entity_phys)?;
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

/// The error for a malformed file at `path`.
fn malformed(path: &Path, reason: String) -> MeshError {
    MeshError::Malformed { path: path.to_path_buf(), reason }
}

/// The `$MeshFormat` line is `4.1 0 8` or `4.1 1 8`: checked before mshio sees the file, so
/// that MSH 2.2 or 4.0 gets a clear message instead of a parser dump.
fn check_format_line(bytes: &[u8], path: &Path) -> Result<(), MeshError> {
    if !bytes.starts_with(b"$MeshFormat") {
        return Err(malformed(path, "it does not start with $MeshFormat".into()));
    }
    let version_line = bytes[b"$MeshFormat".len()..].split(|&b| b == b'\n').map(|l| String::from_utf8_lossy(l).trim().to_string()).find(|l| !l.is_empty()).unwrap_or_default();
    let version = version_line.split_whitespace().next().unwrap_or("");
    if version != "4.1" {
        return Err(malformed(
            path,
            format!(
                "this is MSH {} (the $MeshFormat line reads `{version_line}`); jointquake reads MSH 4.1: re-export it with `gmsh FILE -save -format msh41` or Gmsh's File > Export, version 4.1",
                if version.is_empty() { "of an unknown version" } else { version }
            ),
        ));
    }
    let fields: Vec<&str> = version_line.split_whitespace().collect();
    if fields.len() != 3 || !matches!(fields[1], "0" | "1") || fields[2] != "8" {
        return Err(malformed(path, format!("the $MeshFormat line reads `{version_line}`; it must be `4.1 0 8` (ASCII) or `4.1 1 8` (binary)")));
    }
    Ok(())
}

/// The nodes' coordinates [m] and tags in file order, checked finite.
fn read_nodes(bytes: &[u8], msh: &MshFile<u64, i32, f64>, path: &Path) -> Result<(Vec<[f64; 3]>, Vec<u64>), MeshError> {
    let nodes_sec = msh.data.nodes.as_ref().ok_or_else(|| malformed(path, "no $Nodes section".into()))?;
    // Capacities from what was parsed, never from a count the file claims.
    let n_parsed: usize = nodes_sec.node_blocks.iter().map(|b| b.nodes.len()).sum();
    if nodes_sec.num_nodes as u128 != n_parsed as u128 {
        return Err(malformed(path, format!("the $Nodes header claims {} nodes but its blocks hold {n_parsed}", nodes_sec.num_nodes)));
    }
    let mut nodes = Vec::with_capacity(n_parsed);
    let mut node_tags = Vec::with_capacity(n_parsed);
    let file_tags = if nodes_sec.node_blocks.iter().any(|b| b.node_tags.is_none()) {
        let tags = node_tags_in_file_order(bytes, &msh.header).map_err(|r| malformed(path, r))?;
        let n: usize = nodes_sec.node_blocks.iter().map(|b| b.nodes.len()).sum();
        if tags.len() != n {
            return Err(malformed(path, format!("$Nodes lists {} node tags for {n} nodes", tags.len())));
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
                return Err(MeshError::NonFiniteNode { path: path.to_path_buf(), node: t });
            }
            nodes.push([n.x, n.y, n.z]);
            node_tags.push(t);
        }
    }
    Ok((nodes, node_tags))
}

/// Physical tags of each entity, keyed by (dimension, entity tag).
fn entity_physical_tags(msh: &MshFile<u64, i32, f64>) -> HashMap<(usize, i32), Vec<i32>> {
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
    entity_phys
}

/// The tet4/hex8/tri3/quad4 cells (points and lines skipped) with their nodes as indices
/// (`index_of` a node tag), and the cells of each physical group keyed by (dimension, tag).
fn read_elements(
    msh: &MshFile<u64, i32, f64>,
    path: &Path,
    index_of: &HashMap<u64, usize>,
    entity_phys: &HashMap<(usize, i32), Vec<i32>>,
) -> Result<(Vec<Cell>, BTreeMap<(usize, i32), Vec<usize>>), MeshError> {
    let elems = msh.data.elements.as_ref().ok_or_else(|| malformed(path, "no $Elements section".into()))?;
    let e_parsed: usize = elems.element_blocks.iter().map(|b| b.elements.len()).sum();
    if elems.num_elements as u128 != e_parsed as u128 {
        return Err(malformed(path, format!("the $Elements header claims {} elements but its blocks hold {e_parsed}", elems.num_elements)));
    }
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
                return Err(MeshError::UnsupportedElement { path: path.to_path_buf(), element, kind: format!("{other:?}") });
            }
        };
        let dim = block.entity_dim as usize;
        let phys = entity_phys.get(&(dim, block.entity_tag)).cloned().unwrap_or_default();
        for e in &block.elements {
            if e.nodes.len() != kind.n_nodes() {
                return Err(malformed(path, format!("element {} has {} nodes, {:?} needs {}", e.element_tag, e.nodes.len(), kind, kind.n_nodes())));
            }
            local.clear();
            for &t in &e.nodes {
                let i = *index_of.get(&t).ok_or(MeshError::MissingNode { path: path.to_path_buf(), element: e.element_tag, node: t })?;
                local.push(i);
            }
            let id = cells.len();
            cells.push(Cell::new(kind, e.element_tag, &local));
            for &p in &phys {
                groups.entry((dim, p.abs())).or_default().push(id);
            }
        }
    }
    Ok((cells, groups))
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

/// Write `mesh` as ASCII MSH 4.1 (one entity per physical group; a cell that belongs to
/// several groups is written once per group, under new element tags). Used by tests and
/// fixtures built in memory; gmsh and mshio read the result.
pub fn write_msh41(mesh: &Mesh, path: &std::path::Path) -> std::io::Result<()> {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(s, "$MeshFormat\n4.1 0 8\n$EndMeshFormat");
    let _ = writeln!(s, "$PhysicalNames\n{}", mesh.groups.len());
    for g in &mesh.groups {
        let _ = writeln!(s, "{} {} \"{}\"", g.dim, g.tag, g.name);
    }
    let _ = writeln!(s, "$EndPhysicalNames");
    // entities: group k → entity tag k+1 of its dimension
    let count = |d: usize| mesh.groups.iter().filter(|g| g.dim == d).count();
    let _ = writeln!(s, "$Entities\n0 {} {} {}", count(1), count(2), count(3));
    let (lo, hi) = mesh.nodes.iter().fold(([f64::MAX; 3], [f64::MIN; 3]), |(mut lo, mut hi), x| {
        for i in 0..3 {
            lo[i] = lo[i].min(x[i]);
            hi[i] = hi[i].max(x[i]);
        }
        (lo, hi)
    });
    for d in 1..=3 {
        for (k, g) in mesh.groups.iter().enumerate().filter(|(_, g)| g.dim == d) {
            let _ = writeln!(s, "{} {} {} {} {} {} {} 1 {} 0", k + 1, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], g.tag);
        }
    }
    let _ = writeln!(s, "$EndEntities");
    let n = mesh.nodes.len();
    let _ = writeln!(s, "$Nodes\n1 {n} 1 {n}\n3 0 0 {n}");
    for i in 0..n {
        let _ = writeln!(s, "{}", i + 1);
    }
    for x in &mesh.nodes {
        let _ = writeln!(s, "{:.17e} {:.17e} {:.17e}", x[0], x[1], x[2]);
    }
    let _ = writeln!(s, "$EndNodes");
    let total: usize = mesh.groups.iter().filter(|g| g.dim >= 1).map(|g| g.cells.len()).sum();
    // one element block per (group, cell kind): a group that mixes kinds (a block of hexes and
    // tets) is one entity with several blocks, as gmsh writes hybrid meshes
    const KINDS: [(CellKind, usize); 4] = [(CellKind::Tri3, 2), (CellKind::Quad4, 3), (CellKind::Tet4, 4), (CellKind::Hex8, 5)];
    let mut blocks: Vec<(usize, &Group, CellKind, usize, usize)> = Vec::new();
    for (k, g) in mesh.groups.iter().enumerate() {
        for (kind, ty) in KINDS {
            let n = g.cells.iter().filter(|&&c| mesh.cells[c].kind == kind).count();
            if n > 0 {
                blocks.push((k, g, kind, ty, n));
            }
        }
    }
    let _ = writeln!(s, "$Elements\n{} {} 1 {}", blocks.len(), total, total);
    let mut etag = 0;
    for (k, g, kind, ty, n) in blocks {
        let _ = writeln!(s, "{} {} {} {}", g.dim, k + 1, ty, n);
        for &c in g.cells.iter().filter(|&&c| mesh.cells[c].kind == kind) {
            etag += 1;
            let _ = write!(s, "{etag}");
            for &nd in mesh.cells[c].nodes() {
                let _ = write!(s, " {}", nd + 1);
            }
            let _ = writeln!(s);
        }
    }
    let _ = writeln!(s, "$EndElements");
    std::fs::write(path, s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::structured::{box_mesh, BoxSpec};

    /// A block of hexes and tets (one group, two cell kinds) is written as one entity with two
    /// element blocks and reads back with the same cells per group and kind.
    #[test]
    fn mixed_block_round_trips_through_msh41() {
        let m = box_mesh(&BoxSpec::new("b", [1.0, 1.0, 0.5], [3, 3, 2]).mixed(true));
        let dir = std::env::temp_dir().join(format!("jq-msh-mixed-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("mixed.msh");
        write_msh41(&m, &path).unwrap();
        let r = parse_msh(&std::fs::read(&path).unwrap(), path.clone()).unwrap();
        let count = |mesh: &Mesh, g: &str, k: CellKind| mesh.group(g).unwrap().cells.iter().filter(|&&c| mesh.cells[c].kind == k).count();
        for (g, k) in [("block:b", CellKind::Hex8), ("block:b", CellKind::Tet4), ("b:z1", CellKind::Quad4), ("b:z1", CellKind::Tri3)] {
            assert_eq!(count(&r, g, k), count(&m, g, k), "{g} {k:?}");
            assert!(count(&m, g, k) > 0);
        }
        assert_eq!(r.nodes.len(), m.nodes.len());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
