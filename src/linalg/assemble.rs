//! Global matrices from the model's element kernels: K (both triangles, CSC), M (diagonal plus
//! optional 3×3 node blocks), their restriction to dof subsets, and products with vectors.

use crate::model::{hex8, tet4, Model};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};

/// Not in the sub-problem (an entry of a dof map).
pub const NONE: usize = usize::MAX;

/// A column-compressed sparse matrix (sorted row indices per column).
#[derive(Clone, Debug, Default)]
pub struct Csc {
    pub n_rows: usize,
    pub n_cols: usize,
    pub col_ptr: Vec<usize>,
    pub row: Vec<usize>,
    pub val: Vec<f64>,
}

impl Csc {
    /// Stored entries.
    pub fn nnz(&self) -> usize {
        self.row.len()
    }

    /// The faer view of this matrix (no copy).
    pub fn as_faer(&self) -> SparseColMatRef<'_, usize, f64> {
        // SAFETY: every constructor of `Csc` in this module builds increasing column pointers
        // that end at nnz and strictly increasing, in-range row indices per column (the
        // invariants faer's unchecked constructor asks for); checked by the unit tests.
        let sym = unsafe { SymbolicSparseColMatRef::new_unchecked(self.n_rows, self.n_cols, &self.col_ptr, None, &self.row) };
        SparseColMatRef::new(sym, &self.val)
    }

    /// y += A x.
    pub fn mul_add_into(&self, x: &[f64], y: &mut [f64]) {
        for j in 0..self.n_cols {
            let xj = x[j];
            if xj == 0.0 {
                continue;
            }
            for p in self.col_ptr[j]..self.col_ptr[j + 1] {
                y[self.row[p]] += self.val[p] * xj;
            }
        }
    }

    /// y = A x (y overwritten).
    pub fn mul_into(&self, x: &[f64], y: &mut [f64]) {
        y.fill(0.0);
        self.mul_add_into(x, y);
    }

    /// Entry (i, j) (0 when not stored).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let r = &self.row[self.col_ptr[j]..self.col_ptr[j + 1]];
        r.binary_search(&i).map(|p| self.val[self.col_ptr[j] + p]).unwrap_or(0.0)
    }

    /// Dense copy (small matrices: tests and checks).
    pub fn to_dense(&self) -> nalgebra::DMatrix<f64> {
        let mut d = nalgebra::DMatrix::zeros(self.n_rows, self.n_cols);
        for j in 0..self.n_cols {
            for p in self.col_ptr[j]..self.col_ptr[j + 1] {
                d[(self.row[p], j)] += self.val[p];
            }
        }
        d
    }
}

/// The dof map of a selection: `keep(dof)` → consecutive indices in dof order (others [`NONE`]),
/// and the number kept.
pub fn dof_map(n_dofs: usize, keep: impl Fn(usize) -> bool) -> (Vec<usize>, usize) {
    let mut map = vec![NONE; n_dofs];
    let mut k = 0;
    for (d, m) in map.iter_mut().enumerate() {
        if keep(d) {
            *m = k;
            k += 1;
        }
    }
    (map, k)
}

/// Element stiffness of one hex shape (24×24, column-major: entry (3b+j, 3a+i) at
/// `k[24 (3a+i) + 3b+j]`) from the hex8 internal-force kernel.
fn hex_stiffness(s: &hex8::HexShape, lame: &crate::model::material::Lame) -> Vec<f64> {
    let mut k = vec![0.0; 576];
    for a in 0..8 {
        for i in 0..3 {
            let mut u = [[0.0; 3]; 8];
            u[a][i] = 1.0;
            let f = hex8::internal_forces(s, &u, lame);
            for b in 0..8 {
                for j in 0..3 {
                    k[24 * (3 * a + i) + 3 * b + j] = f[b][j];
                }
            }
        }
    }
    k
}

/// The global stiffness K over every model dof, of the elements whose material index `mat`
/// has `include[mat]` (both triangles stored; dofs of nodes outside those elements have empty
/// columns). Symmetrised: the element kernels are symmetric to round-off.
pub fn stiffness(model: &Model, include: &[bool]) -> Csc {
    stiffness_of(model, |_, mat| include[mat])
}

/// The global stiffness K of the elements for which `keep(mesh cell, material)` holds.
pub fn stiffness_of(model: &Model, keep: impl Fn(usize, usize) -> bool) -> Csc {
    let n_nodes = model.n_nodes();
    let tets: Vec<usize> = (0..model.tets.nodes.len()).filter(|&e| keep(model.tets.cell[e] as usize, model.tets.mat[e] as usize)).collect();
    let hexes: Vec<usize> = (0..model.hexes.nodes.len()).filter(|&e| keep(model.hexes.cell[e] as usize, model.hexes.mat[e] as usize)).collect();
    // node graph: neighbours (self included) of every node, sorted
    let mut adj: Vec<Vec<u32>> = vec![Vec::new(); n_nodes];
    let mut link = |nd: &[u32]| {
        for &a in nd {
            adj[a as usize].extend_from_slice(nd);
        }
    };
    for &e in &tets {
        link(&model.tets.nodes[e]);
    }
    for &e in &hexes {
        link(&model.hexes.nodes[e]);
    }
    for a in adj.iter_mut() {
        a.sort_unstable();
        a.dedup();
    }
    let n = 3 * n_nodes;
    let mut col_ptr = Vec::with_capacity(n + 1);
    col_ptr.push(0);
    for a in &adj {
        for _ in 0..3 {
            col_ptr.push(col_ptr.last().unwrap() + 3 * a.len());
        }
    }
    let nnz = *col_ptr.last().unwrap();
    let mut row = Vec::with_capacity(nnz);
    for a in &adj {
        for _ in 0..3 {
            for &b in a {
                row.extend_from_slice(&[3 * b as usize, 3 * b as usize + 1, 3 * b as usize + 2]);
            }
        }
    }
    let mut val = vec![0.0; nnz];
    // entry (row 3 r + i, column 3 c + j)
    let mut add = |r: u32, c: u32, i: usize, j: usize, v: f64| {
        let p = adj[c as usize].binary_search(&r).expect("node graph holds every element pair");
        val[col_ptr[3 * c as usize + j] + 3 * p + i] += v;
    };
    for &e in &tets {
        let nd = model.tets.nodes[e];
        let g = &model.tets.geom[e];
        let lame = &model.materials[model.tets.mat[e] as usize].lame;
        for a in 0..4 {
            for i in 0..3 {
                let mut u = [[0.0; 3]; 4];
                u[a][i] = 1.0;
                let f = tet4::internal_forces(&g.grad, g.vol, &u, lame);
                for b in 0..4 {
                    for j in 0..3 {
                        // K[(b,j),(a,i)] = f_b,j of a unit displacement at (a,i)
                        add(nd[b], nd[a], j, i, f[b][j]);
                    }
                }
            }
        }
    }
    let mut shape_k: Vec<Option<Vec<f64>>> = vec![None; model.hexes.shapes.len()];
    for &e in &hexes {
        let si = model.hexes.shape[e] as usize;
        if shape_k[si].is_none() {
            shape_k[si] = Some(hex_stiffness(&model.hexes.shapes[si], &model.materials[model.hexes.mat[e] as usize].lame));
        }
        let k = shape_k[si].as_ref().unwrap();
        let nd = model.hexes.nodes[e];
        for a in 0..8 {
            for i in 0..3 {
                for b in 0..8 {
                    for j in 0..3 {
                        add(nd[b], nd[a], j, i, k[24 * (3 * a + i) + 3 * b + j]);
                    }
                }
            }
        }
    }
    let mut k = Csc { n_rows: n, n_cols: n, col_ptr, row, val };
    symmetrise(&mut k);
    k
}

/// A ← (A + Aᵀ)/2 for a matrix with a symmetric pattern.
fn symmetrise(a: &mut Csc) {
    for j in 0..a.n_cols {
        for p in a.col_ptr[j]..a.col_ptr[j + 1] {
            let i = a.row[p];
            if i > j {
                let q = a.col_ptr[i] + a.row[a.col_ptr[i]..a.col_ptr[i + 1]].binary_search(&j).expect("symmetric pattern");
                let m = 0.5 * (a.val[p] + a.val[q]);
                a.val[p] = m;
                a.val[q] = m;
            }
        }
    }
}

/// The block A[rows, cols] of `a` with the dof maps `rows` and `cols` (increasing maps from
/// [`dof_map`]): `n_rows` × `n_cols`.
pub fn restrict(a: &Csc, rows: &[usize], n_rows: usize, cols: &[usize], n_cols: usize) -> Csc {
    let mut col_ptr = vec![0usize; n_cols + 1];
    let mut row = Vec::new();
    let mut val = Vec::new();
    let mut order: Vec<(usize, usize)> = (0..a.n_cols).filter(|&j| cols[j] != NONE).map(|j| (cols[j], j)).collect();
    order.sort_unstable();
    for (new_j, j) in order {
        for p in a.col_ptr[j]..a.col_ptr[j + 1] {
            let r = rows[a.row[p]];
            if r != NONE {
                row.push(r);
                val.push(a.val[p]);
            }
        }
        col_ptr[new_j + 1] = row.len();
    }
    for j in 0..n_cols {
        if col_ptr[j + 1] < col_ptr[j] {
            col_ptr[j + 1] = col_ptr[j];
        }
    }
    Csc { n_rows, n_cols, col_ptr, row, val }
}

/// The mass matrix on the dofs of `map` (`n` kept): `diag[node]` on the three dofs of every
/// node, plus the 3×3 `blocks` (node, symmetric block [kg]) added on their nodes (reservoir
/// added mass m_a n nᵀ). Entries of dropped dofs are dropped.
pub fn mass_matrix(diag: &[f64], blocks: &[(usize, [[f64; 3]; 3])], map: &[usize], n: usize) -> Csc {
    let mut cols: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
    for (node, &m) in diag.iter().enumerate() {
        for c in 0..3 {
            let d = map[3 * node + c];
            if d != NONE && m != 0.0 {
                cols[d].push((d, m));
            }
        }
    }
    for &(node, b) in blocks {
        for j in 0..3 {
            let dj = map[3 * node + j];
            if dj == NONE {
                continue;
            }
            for i in 0..3 {
                let di = map[3 * node + i];
                if di != NONE && b[i][j] != 0.0 {
                    cols[dj].push((di, b[i][j]));
                }
            }
        }
    }
    from_columns(n, cols)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::mesh::structured::{box_mesh, BoxSpec};

    pub(crate) fn box_model(tets: bool, div: [usize; 3]) -> Model {
        box_model_of([2.0, 1.0, 1.0], tets, div, 0.25)
    }

    /// A box of `size` clamped on its x0 face, E = 1 GPa, ρ = 2000 kg/m³.
    pub(crate) fn box_model_of(size: [f64; 3], tets: bool, div: [usize; 3], nu: f64) -> Model {
        let mesh = box_mesh(&BoxSpec::new("b", size, div).tets(tets));
        let scene: crate::scene::Scene = serde_json::from_value(serde_json::json!({
            "geometry": {"msh": "none.msh"},
            "materials": [{"group": "block:b", "E": 1e9, "nu": nu, "rho": 2000.0}],
            "boundary": [{"group": "b:x0"}],
            "time": {"duration": 0.0}
        }))
        .unwrap();
        Model::build(mesh, &scene).unwrap()
    }

    #[test]
    fn assembled_stiffness_applies_the_element_kernels() {
        // K u from the sparse matrix equals the explicit step's internal force to round-off,
        // for tet4 and hex8 (reference: Model::internal_forces_into; tolerance 1e-12 relative)
        for tets in [true, false] {
            let m = box_model(tets, [3, 2, 2]);
            let k = stiffness(&m, &[true]);
            let n = 3 * m.n_nodes();
            let u: Vec<f64> = (0..n).map(|i| ((i * 7919) % 113) as f64 * 1e-5 - 5e-4).collect();
            let mut f1 = vec![0.0; n];
            let mut f2 = vec![0.0; n];
            m.internal_forces_into(&u, &mut f1);
            k.mul_into(&u, &mut f2);
            let scale = f1.iter().fold(0.0f64, |a, b| a.max(b.abs()));
            for i in 0..n {
                assert!((f1[i] - f2[i]).abs() < 1e-12 * scale, "tets {tets} dof {i}: {} vs {}", f1[i], f2[i]);
            }
            // pattern invariants relied on by `as_faer`
            for j in 0..k.n_cols {
                let r = &k.row[k.col_ptr[j]..k.col_ptr[j + 1]];
                assert!(r.windows(2).all(|w| w[0] < w[1]) && r.iter().all(|&i| i < k.n_rows));
                for (p, &i) in r.iter().enumerate() {
                    assert_eq!(k.val[k.col_ptr[j] + p], k.get(j, i), "symmetric");
                }
            }
        }
    }

    #[test]
    fn restriction_and_mass_blocks() {
        let m = box_model(false, [2, 1, 1]);
        let k = stiffness(&m, &[true]);
        let n = 3 * m.n_nodes();
        let (rows, nr) = dof_map(n, |d| d % 2 == 0);
        let (cols, nc) = dof_map(n, |d| d % 3 != 1);
        let s = restrict(&k, &rows, nr, &cols, nc);
        let kd = k.to_dense();
        let sd = s.to_dense();
        for i in 0..n {
            for j in 0..n {
                if rows[i] != NONE && cols[j] != NONE {
                    assert_eq!(sd[(rows[i], cols[j])], kd[(i, j)]);
                }
            }
        }
        let (all, na) = dof_map(n, |_| true);
        let b = [[1.0, 2.0, 0.0], [2.0, 5.0, 0.0], [0.0, 0.0, 0.0]];
        let mm = mass_matrix(&m.mass.inertial, &[(3, b)], &all, na).to_dense();
        assert_eq!(mm[(10, 9)], 2.0);
        assert_eq!(mm[(10, 10)], m.mass.inertial[3] + 5.0);
        assert_eq!(mm[(11, 11)], m.mass.inertial[3]);
    }
}

/// A + E for a square matrix `a` and extra entries `extra` (row, column, value), duplicates
/// summed; the pattern grows where E has entries outside A's.
pub fn add_entries(a: &Csc, extra: &[(usize, usize, f64)]) -> Csc {
    let mut cols: Vec<Vec<(usize, f64)>> = (0..a.n_cols).map(|j| (a.col_ptr[j]..a.col_ptr[j + 1]).map(|p| (a.row[p], a.val[p])).collect()).collect();
    for &(i, j, v) in extra {
        cols[j].push((i, v));
    }
    from_columns(a.n_rows, cols)
}

/// The matrix whose column j holds the entries `cols[j]` (row, value) in any order, duplicates
/// summed in the order given (a stable sort: the sums do not depend on the sort's internals).
pub fn from_columns(n_rows: usize, mut cols: Vec<Vec<(usize, f64)>>) -> Csc {
    let nnz = cols.iter().map(|c| c.len()).sum();
    let mut col_ptr = Vec::with_capacity(cols.len() + 1);
    col_ptr.push(0);
    let (mut row, mut val) = (Vec::with_capacity(nnz), Vec::with_capacity(nnz));
    for c in cols.iter_mut() {
        c.sort_by_key(|e| e.0);
        let mut last = usize::MAX;
        for &(r, v) in c.iter() {
            if r == last {
                *val.last_mut().unwrap() += v;
            } else {
                row.push(r);
                val.push(v);
                last = r;
            }
        }
        col_ptr.push(row.len());
    }
    Csc { n_rows, n_cols: cols.len(), col_ptr, row, val }
}
