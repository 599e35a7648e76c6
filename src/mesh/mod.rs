//! The mesh: nodes, cells and named physical groups, read once from a Gmsh `.msh`.
//!
//! Owns: node coordinates (m), cells ([`Cell`], Gmsh node order, see [`cell`]),
//! and physical groups by name. Inputs: a MSH 4.1 file (ASCII or binary).
//! Invariants: every cell's nodes exist; volume cells referenced by a group have
//! been checked for inversion when the model is built ([`Mesh::check_orientation`]);
//! the mesh is never mutated after reading.
//!
//! Mesh parts are referred to only by Gmsh physical-group names (`block:wedge`,
//! `joint:A:master`, `bc:fixed`, ...). A physical group without a name in
//! `$PhysicalNames` is called `"<dim>:<tag>"`.

pub mod cell;
pub mod geometry;
pub mod msh;
pub mod pattern;
pub mod quality;
pub mod structured;
pub mod topology;

pub use cell::{Cell, CellKind};

use crate::error::MeshError;
use std::path::PathBuf;

/// A named physical group: its dimension, Gmsh tag and member cells.
#[derive(Clone, Debug)]
pub struct Group {
    pub name: String,
    pub dim: usize,
    pub tag: i32,
    /// Indices into [`Mesh::cells`], sorted.
    pub cells: Vec<usize>,
}

/// Nodes, cells and named groups of one Gmsh mesh.
#[derive(Clone, Debug)]
pub struct Mesh {
    /// Where the mesh came from (quoted in errors).
    pub source: PathBuf,
    /// Node coordinates [m].
    pub nodes: Vec<[f64; 3]>,
    /// Gmsh node tag of each node (for messages and cross-referencing).
    pub node_tags: Vec<u64>,
    pub cells: Vec<Cell>,
    pub groups: Vec<Group>,
}

impl Mesh {
    /// Read a `.msh` file (MSH 4.1, ASCII or binary).
    pub fn from_msh(path: impl Into<PathBuf>) -> Result<Mesh, MeshError> {
        msh::read_msh(path.into())
    }

    /// The group called `name` (any dimension).
    pub fn group(&self, name: &str) -> Result<&Group, MeshError> {
        self.groups.iter().find(|g| g.name == name).ok_or_else(|| MeshError::UnknownGroup {
            name: name.to_string(),
            dim: None,
            available: self.group_names(),
        })
    }

    /// The group called `name` with dimension `dim`.
    pub fn group_of_dim(&self, name: &str, dim: usize) -> Result<&Group, MeshError> {
        self.groups.iter().find(|g| g.name == name && g.dim == dim).ok_or_else(|| {
            MeshError::UnknownGroup { name: name.to_string(), dim: Some(dim), available: self.group_names() }
        })
    }

    /// "name (dim D)" for every group, for error messages.
    pub fn group_names(&self) -> Vec<String> {
        self.groups.iter().map(|g| format!("\"{}\" (dim {})", g.name, g.dim)).collect()
    }

    /// Sorted, unique node indices of a group's cells.
    pub fn group_nodes(&self, name: &str) -> Result<Vec<usize>, MeshError> {
        let g = self.group(name)?;
        Ok(self.cells_nodes(&g.cells))
    }

    /// Sorted, unique node indices of the given cells.
    pub fn cells_nodes(&self, cells: &[usize]) -> Vec<usize> {
        let mut v: Vec<usize> = cells.iter().flat_map(|&c| self.cells[c].nodes().iter().map(|&n| n as usize)).collect();
        v.sort_unstable();
        v.dedup();
        v
    }

    /// Coordinates of node `i`.
    pub fn x(&self, i: usize) -> nalgebra::Vector3<f64> {
        nalgebra::Vector3::from(self.nodes[i])
    }

    /// Diagonal of the bounding box of all nodes [m] (0 for an empty mesh): the model size that
    /// relative tolerances refer to.
    pub fn diagonal(&self) -> f64 {
        if self.nodes.is_empty() {
            return 0.0;
        }
        let (lo, hi) = self.nodes.iter().fold(([f64::MAX; 3], [f64::MIN; 3]), |(mut lo, mut hi), x| {
            for i in 0..3 {
                lo[i] = lo[i].min(x[i]);
                hi[i] = hi[i].max(x[i]);
            }
            (lo, hi)
        });
        ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt()
    }

    /// Index of the node nearest to `p` and its distance [m] (linear scan; use for a few points).
    pub fn nearest_node(&self, p: [f64; 3]) -> Option<(usize, f64)> {
        self.nodes
            .iter()
            .enumerate()
            .map(|(i, x)| (i, ((x[0] - p[0]).powi(2) + (x[1] - p[1]).powi(2) + (x[2] - p[2]).powi(2)).sqrt()))
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// Smallest corner Jacobian determinant of a volume cell (tet4: 6 × volume).
    pub fn min_corner_jacobian(&self, c: usize) -> f64 {
        let cell = &self.cells[c];
        let x = |i: usize| self.x(cell.node(i));
        match cell.kind {
            CellKind::Tet4 => (x(1) - x(0)).cross(&(x(2) - x(0))).dot(&(x(3) - x(0))),
            CellKind::Hex8 => {
                let mut jmin = f64::INFINITY;
                for i in 0..8 {
                    let s = cell::HEX8_REF[i];
                    // neighbour of corner i along each reference direction
                    let mut cols = [nalgebra::Vector3::zeros(); 3];
                    for (d, col) in cols.iter_mut().enumerate() {
                        let mut t = s;
                        t[d] = -t[d];
                        let j = cell::HEX8_REF.iter().position(|r| *r == t).unwrap();
                        *col = (x(j) - x(i)) * (-s[d]);
                    }
                    jmin = jmin.min(cols[0].cross(&cols[1]).dot(&cols[2]));
                }
                jmin
            }
            _ => f64::INFINITY,
        }
    }

    /// Check that no volume cell of `group` is inverted or degenerate.
    pub fn check_orientation(&self, group: &Group) -> Result<(), MeshError> {
        for &c in &group.cells {
            if self.cells[c].kind.dim() != 3 {
                continue;
            }
            let j = self.min_corner_jacobian(c);
            if !(j > 0.0) {
                return Err(MeshError::InvertedElement {
                    path: self.source.clone(),
                    group: group.name.clone(),
                    element: self.cells[c].tag,
                    jacobian: j,
                });
            }
        }
        Ok(())
    }
}
