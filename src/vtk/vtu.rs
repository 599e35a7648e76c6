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

/// Standard base64 (RFC 4648, with padding) of `bytes`, appended to `out`.
fn base64_into(bytes: &[u8], out: &mut String) {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    out.reserve(bytes.len().div_ceil(3) * 4);
    for c in bytes.chunks(3) {
        let b = [c[0], *c.get(1).unwrap_or(&0), *c.get(2).unwrap_or(&0)];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        out.push(A[(n >> 18) as usize & 63] as char);
        out.push(A[(n >> 12) as usize & 63] as char);
        out.push(if c.len() > 1 { A[(n >> 6) as usize & 63] as char } else { '=' });
        out.push(if c.len() > 2 { A[n as usize & 63] as char } else { '=' });
    }
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
    let tmp = path.with_extension("vtu.tmp");
    std::fs::write(&tmp, x).map_err(|e| OutputError::write(&tmp, e))?;
    std::fs::rename(&tmp, path).map_err(|e| OutputError::write(path, e))?;
    Ok(())
}
