//! Writing VTU (VTK XML unstructured grid) files with `vtkio`.
//!
//! One generic writer serves the volume frames, the joint surfaces and the tagger's
//! inspection files. Files are written to `<name>.tmp` and renamed, so a reader (or a
//! crash) never sees a half-written file.

use crate::error::OutputError;
use crate::mesh::CellKind;
use std::path::Path;
use vtkio::model::{
    Attribute, Attributes, ByteOrder, CellType, Cells, DataArray, DataSet, ElementType, IOBuffer,
    UnstructuredGridPiece, Version, VertexNumbers, Vtk,
};

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

fn to_attr(f: &Field) -> Attribute {
    let elem = match f.ncomp {
        1 => ElementType::Scalars { num_comp: 1, lookup_table: None },
        3 => ElementType::Vectors,
        9 => ElementType::Tensors,
        n => ElementType::Generic(n as u32),
    };
    let data = match f.data {
        FieldData::F64(d) => IOBuffer::F64(d.to_vec()),
        FieldData::I32(d) => IOBuffer::I32(d.to_vec()),
    };
    Attribute::DataArray(DataArray { name: f.name.to_string(), elem, data })
}

/// Write `grid` with point and cell fields to `path` (`.vtu`), atomically.
pub fn write_vtu(path: &Path, grid: &Grid, point_fields: &[Field], cell_fields: &[Field]) -> Result<(), OutputError> {
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
    let mut connectivity = Vec::with_capacity(nc * 8);
    let mut offsets = Vec::with_capacity(nc);
    let mut types = Vec::with_capacity(nc);
    for (kind, nodes) in &grid.cells {
        connectivity.extend(nodes.iter().map(|&n| n as u64));
        offsets.push(connectivity.len() as u64);
        types.push(match kind {
            CellKind::Tet4 => CellType::Tetra,
            CellKind::Hex8 => CellType::Hexahedron,
            CellKind::Tri3 => CellType::Triangle,
            CellKind::Quad4 => CellType::Quad,
        });
    }
    let piece = UnstructuredGridPiece {
        points: IOBuffer::F64(grid.points.iter().flatten().copied().collect()),
        cells: Cells { cell_verts: VertexNumbers::XML { connectivity, offsets }, types },
        data: Attributes {
            point: point_fields.iter().map(to_attr).collect(),
            cell: cell_fields.iter().map(to_attr).collect(),
        },
    };
    let vtk = Vtk {
        version: Version::new((1, 0)),
        title: String::new(),
        byte_order: ByteOrder::LittleEndian,
        data: DataSet::inline(piece),
        file_path: None,
    };
    let tmp = path.with_extension("vtu.tmp");
    // vtkio picks the format from the extension, so export to a .vtu name and rename into place.
    let tmp_vtu = tmp.with_extension("tmp.vtu");
    vtk.export(&tmp_vtu).map_err(|e| OutputError::write(path, format!("{e:?}")))?;
    std::fs::rename(&tmp_vtu, path).map_err(|e| OutputError::write(path, e))?;
    Ok(())
}
