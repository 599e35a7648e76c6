//! Writing VTU (VTK XML unstructured grid) files.
//!
//! One generic writer serves the volume frames, the joint surfaces and the tagger's
//! inspection files. Files are written to `<name>.tmp` and renamed, so a reader (or a
//! crash) never sees a half-written file.
//!
//! Encoding: binary (base64 in the XML) and zlib-compressed at level [`ZLIB_LEVEL`]
//! (`compressor="vtkZLibDataCompressor"`, `header_type="UInt64"`), in VTK's layout: per array a
//! header [blocks = 1, block size, last block size, compressed size] base64-encoded on its own,
//! then the zlib stream. vtkio's model writer puts only one size before the stream (ParaView and
//! meshio cannot read that) and feeds zlib one byte per call (10x slower), so the XML is
//! written here, with `flate2` (vtkio's own zlib). Sizes and write times against the former uncompressed
//! files: docs/performance.md §7.
//! Labels of categorical arrays go into the grid's `FieldData` as one-value Int32 arrays
//! ([`write_vtu_labelled`]).

use crate::error::OutputError;
use crate::mesh::CellKind;
use std::path::Path;
use std::fmt::Write as _;

/// A named array of `ncomp` components per point or per cell.
pub struct Field<'a> {
    pub name: &'a str,
    pub ncomp: usize,
    pub data: FieldData<'a>,
}

/// Field values, row-major (`ncomp` values per entry).
pub enum FieldData<'a> {
    F64(&'a [f64]),
    I32(&'a [i32]),
}

impl<'a> Field<'a> {
    pub fn f64(name: &'a str, ncomp: usize, data: &'a [f64]) -> Self {
        Field { name, ncomp, data: FieldData::F64(data) }
    }
    pub fn i32(name: &'a str, ncomp: usize, data: &'a [i32]) -> Self {
        Field { name, ncomp, data: FieldData::I32(data) }
    }
    fn len(&self) -> usize {
        match self.data {
            FieldData::F64(d) => d.len(),
            FieldData::I32(d) => d.len(),
        }
    }
}

/// An unstructured grid to write: points and cells given by kind and node list.
pub struct Grid<'a> {
    pub points: &'a [[f64; 3]],
    /// (kind, node indices into `points`)
    pub cells: Vec<(CellKind, &'a [u32])>,
}

/// zlib level of the frames: 1, the fastest. Measured on the demo's volume frame
/// (docs/performance.md §7): most of the size gain of level 6 for a fraction of its time.
pub const ZLIB_LEVEL: u32 = 1;

/// Standard base64 (RFC 4648, with padding) of `bytes`, appended to `out` (the `base64` crate).
fn base64_into(bytes: &[u8], out: &mut String) {
    use base64::Engine as _;
    base64::engine::general_purpose::STANDARD.encode_string(bytes, out);
}

/// One `<DataArray>` of the little-endian bytes `raw`, zlib-compressed in VTK's block layout
/// (one block).
fn data_array_into(out: &mut String, vtk_type: &str, name: Option<&str>, ncomp: usize, raw: &[u8]) {
    use std::io::Write as _;
    let _ = write!(out, "<DataArray type=\"{vtk_type}\"");
    if let Some(n) = name {
        let _ = write!(out, " Name=\"{n}\"");
    }
    let _ = write!(out, " NumberOfComponents=\"{ncomp}\" format=\"binary\">");
    let n = raw.len() as u64;
    if n == 0 {
        base64_into(&[0u8; 24], out);
    } else {
        let mut z = flate2::write::ZlibEncoder::new(Vec::with_capacity(raw.len() / 4), flate2::Compression::new(ZLIB_LEVEL));
        z.write_all(raw).expect("writing to memory");
        let stream = z.finish().expect("writing to memory");
        let header: Vec<u8> = [1u64, n, n, stream.len() as u64].iter().flat_map(|v| v.to_le_bytes()).collect();
        base64_into(&header, out);
        base64_into(&stream, out);
    }
    out.push_str("</DataArray>\n");
}

/// Little-endian bytes of `v`.
fn le_bytes<T: Copy, const N: usize>(v: &[T], to: impl Fn(T) -> [u8; N]) -> Vec<u8> {
    let mut b = Vec::with_capacity(v.len() * N);
    for &x in v {
        b.extend_from_slice(&to(x));
    }
    b
}

fn field_into(out: &mut String, f: &Field) {
    match f.data {
        FieldData::F64(d) => data_array_into(out, "Float64", Some(f.name), f.ncomp, &le_bytes(d, f64::to_le_bytes)),
        FieldData::I32(d) => data_array_into(out, "Int32", Some(f.name), f.ncomp, &le_bytes(d, i32::to_le_bytes)),
    }
}

/// Write `grid` with point and cell fields to `path` (`.vtu`), atomically.
pub fn write_vtu(path: &Path, grid: &Grid, point_fields: &[Field], cell_fields: &[Field]) -> Result<(), OutputError> {
    write_vtu_labelled(path, grid, point_fields, cell_fields, &[])
}

/// [`write_vtu`] with `labels`: (name, value) pairs written as the grid's `FieldData`, one
/// Int32 array of one value each (e.g. `state_label_open` = 0), so a file names the codes of
/// its categorical arrays.
pub fn write_vtu_labelled(path: &Path, grid: &Grid, point_fields: &[Field], cell_fields: &[Field], labels: &[(&str, i32)]) -> Result<(), OutputError> {
    let np = grid.points.len();
    let nc = grid.cells.len();
    for f in point_fields {
        if f.len() != np * f.ncomp {
            return Err(OutputError::write(path, format!("point field {} has {} values, expected {}", f.name, f.len(), np * f.ncomp)));
        }
    }
    for f in cell_fields {
        if f.len() != nc * f.ncomp {
            return Err(OutputError::write(path, format!("cell field {} has {} values, expected {}", f.name, f.len(), nc * f.ncomp)));
        }
    }
    let mut connectivity: Vec<i64> = Vec::with_capacity(nc * 8);
    let mut offsets: Vec<i64> = Vec::with_capacity(nc);
    let mut types: Vec<u8> = Vec::with_capacity(nc);
    for (kind, nodes) in &grid.cells {
        connectivity.extend(nodes.iter().map(|&n| n as i64));
        offsets.push(connectivity.len() as i64);
        // VTK cell type codes
        types.push(match kind {
            CellKind::Tet4 => 10,
            CellKind::Hex8 => 12,
            CellKind::Tri3 => 5,
            CellKind::Quad4 => 9,
        });
    }
    let mut x = String::with_capacity(64 * 1024);
    x.push_str("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\">\n<UnstructuredGrid>\n");
    if !labels.is_empty() {
        x.push_str("<FieldData>\n");
        for (name, v) in labels {
            let _ = writeln!(x, "<DataArray type=\"Int32\" Name=\"{name}\" NumberOfTuples=\"1\" format=\"ascii\">{v}</DataArray>");
        }
        x.push_str("</FieldData>\n");
    }
    let _ = writeln!(x, "<Piece NumberOfPoints=\"{np}\" NumberOfCells=\"{nc}\">");
    x.push_str("<PointData>\n");
    for f in point_fields {
        field_into(&mut x, f);
    }
    x.push_str("</PointData>\n<CellData>\n");
    for f in cell_fields {
        field_into(&mut x, f);
    }
    x.push_str("</CellData>\n<Points>\n");
    let points: Vec<f64> = grid.points.iter().flatten().copied().collect();
    data_array_into(&mut x, "Float64", None, 3, &le_bytes(&points, f64::to_le_bytes));
    x.push_str("</Points>\n<Cells>\n");
    data_array_into(&mut x, "Int64", Some("connectivity"), 1, &le_bytes(&connectivity, i64::to_le_bytes));
    data_array_into(&mut x, "Int64", Some("offsets"), 1, &le_bytes(&offsets, i64::to_le_bytes));
    data_array_into(&mut x, "UInt8", Some("types"), 1, &types);
    x.push_str("</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    // whole, the temporary file removed on a full disk (issue 34), never over a non-regular file
    crate::files::write_whole(path, x.as_bytes()).map_err(|(p, m)| OutputError::write(p, m))
}

/// Read back the Float64 `<DataArray>` named `name` (point or cell data) of a VTU written by
/// [`write_vtu`] (binary, one zlib block, UInt64 header): its values, row-major. The reader next
/// to the writer, for the project's own checks (ParaView and meshio read the files as they are).
pub fn read_vtu_f64_array(path: &Path, name: &str) -> Result<Vec<f64>, OutputError> {
    use base64::Engine as _;
    use std::io::Read as _;
    let bad = |m: String| OutputError::read(path, m);
    let text = std::fs::read_to_string(path).map_err(|e| OutputError::read(path, e))?;
    let key = format!("type=\"Float64\" Name=\"{name}\"");
    let start = text.find(&key).ok_or_else(|| bad(format!("no Float64 array \"{name}\"")))?;
    let body = &text[start..];
    let open = body.find('>').ok_or_else(|| bad(format!("array \"{name}\" has no content")))? + 1;
    let close = body.find("</DataArray>").ok_or_else(|| bad(format!("array \"{name}\" is not closed")))?;
    let data = body.get(open..close).ok_or_else(|| bad(format!("array \"{name}\" is malformed")))?.trim();
    let b64 = base64::engine::general_purpose::STANDARD;
    // an empty array is a header of 3 zero UInt64 (no block): 32 characters
    if data.len() == 32 {
        let h = b64.decode(data).map_err(|e| bad(format!("array \"{name}\": header: {e}")))?;
        return if h.iter().all(|&b| b == 0) { Ok(Vec::new()) } else { Err(bad(format!("array \"{name}\": a header without data"))) };
    }
    // the header [blocks, block size, last block size, compressed size] is 4 UInt64 (32 bytes):
    // 44 base64 characters on their own, then the zlib stream
    let (h, z) = (data.get(..44).ok_or_else(|| bad(format!("array \"{name}\": header cut")))?, &data[44..]);
    let header = b64.decode(h).map_err(|e| bad(format!("array \"{name}\": header: {e}")))?;
    let raw_len = u64::from_le_bytes(header.get(8..16).and_then(|b| b.try_into().ok()).ok_or_else(|| bad(format!("array \"{name}\": header of {} bytes", header.len())))?);
    if raw_len == 0 {
        return Ok(Vec::new());
    }
    let stream = b64.decode(z).map_err(|e| bad(format!("array \"{name}\": data: {e}")))?;
    // never allocate from the file's count: the decompressed size is bounded by the stream read
    let mut raw = Vec::new();
    flate2::read::ZlibDecoder::new(stream.as_slice()).read_to_end(&mut raw).map_err(|e| bad(format!("array \"{name}\": zlib: {e}")))?;
    if raw.len() as u64 != raw_len || raw.len() % 8 != 0 {
        return Err(bad(format!("array \"{name}\": {} bytes, header says {raw_len}", raw.len())));
    }
    Ok(raw.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes"))).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A written array reads back bit for bit (point and cell data), and a missing one is named.
    #[test]
    fn written_arrays_read_back() {
        let dir = std::env::temp_dir().join(format!("jq_vtu_rt_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("t.vtu");
        let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let tet = [0u32, 1, 2, 3];
        let grid = Grid { points: &points, cells: vec![(CellKind::Tet4, &tet[..])] };
        let u: Vec<f64> = (0..12).map(|i| i as f64 * 0.1 - 0.35).collect();
        let s = [1.5e6, -2.0e-300, f64::MAX, 0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
        write_vtu(&path, &grid, &[Field::f64("u", 3, &u)], &[Field::f64("stress", 9, &s), Field::f64("empty_name_check", 1, &[7.0])]).unwrap();
        assert_eq!(read_vtu_f64_array(&path, "u").unwrap(), u);
        assert_eq!(read_vtu_f64_array(&path, "stress").unwrap(), s.to_vec());
        let e = read_vtu_f64_array(&path, "strain").unwrap_err().to_string();
        assert!(e.contains("\"strain\"") && e.contains("t.vtu"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
