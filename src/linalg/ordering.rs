//! Fill-reducing orderings for [`SparseCholesky`](super::SparseCholesky): faer's approximate
//! minimum degree (AMD, the default of small systems) or METIS's multilevel nested dissection
//! (`METIS_NodeND`), which on the 3-D stiffness matrices of a dam gives a factor with fewer
//! entries and fewer flops than AMD from some ten thousand nodes on (docs/performance.md §7b:
//! the measured fill of both on the coarse, default, fine and h 2.5 m meshes).
//!
//! Conventions: a permutation is returned as `(forward, inverse)` with `forward[new] = old` and
//! `inverse[old] = new`, faer's `PermRef` convention (row `new` of P A Pᵀ is row `forward[new]`
//! of A).

use super::{Csc, LinalgError};

/// Which fill-reducing ordering a symbolic Cholesky analysis uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum FillOrdering {
    /// faer's approximate minimum degree (cheap to compute; the fill grows fast with the size
    /// of a 3-D mesh).
    #[default]
    Amd,
    /// METIS multilevel nested dissection on the pattern's graph (METIS's default options:
    /// vertices of identical adjacency, here the three unknowns of a node, are compressed
    /// into one before the dissection).
    NestedDissection,
    /// [`FillOrdering::NestedDissection`] for matrices of at least `NESTED_DISSECTION_FROM`
    /// unknowns, AMD below.
    Auto,
}

/// Unknowns from which [`FillOrdering::Auto`] takes nested dissection: 20 000. Why (measured
/// factors of the dam's static stages, docs/performance.md §7b): on the coarse dam (10 623
/// unknowns) AMD's factor of the stiffness is smaller (5 against 7 MB) and the preconditioner's
/// about the same (18 against 16 MB); on the default dam (30 741) METIS's preconditioner factor
/// needs 0.54× AMD's flops (76 against 101 MB) while the stiffness's is 13 % larger; on the
/// fine dam (144 438) METIS's are smaller for both (298 against 339 MB, 754 against 1 217 MB,
/// 0.40× the flops of the preconditioner's).
pub const NESTED_DISSECTION_FROM: usize = 20_000;

impl FillOrdering {
    /// The ordering this choice takes for a matrix of `n` unknowns (never `Auto`).
    pub fn resolve(self, n: usize) -> FillOrdering {
        match self {
            FillOrdering::Auto if n >= NESTED_DISSECTION_FROM => FillOrdering::NestedDissection,
            FillOrdering::Auto => FillOrdering::Amd,
            other => other,
        }
    }
}

/// The nested-dissection permutation `(forward, inverse)` of the square matrix `a`'s pattern
/// (the pattern is symmetrised: an entry (i, j) or (j, i) is an edge; the diagonal and the
/// values are ignored). `what` names the matrix in errors.
pub fn nested_dissection(a: &Csc, what: &str) -> Result<(Vec<usize>, Vec<usize>), LinalgError> {
    let n = a.n_rows;
    if a.n_cols != n || a.col_ptr.len() != n + 1 || a.col_ptr.last() != Some(&a.row.len()) {
        return Err(LinalgError::Invalid(format!("{what}: a {n}×{} matrix with {} column pointers is not a square compressed-column matrix", a.n_cols, a.col_ptr.len())));
    }
    if a.col_ptr.windows(2).any(|w| w[0] > w[1]) {
        return Err(LinalgError::Invalid(format!("{what}: decreasing column pointers")));
    }
    if let Some(&bad) = a.row.iter().find(|&&i| i >= n) {
        return Err(LinalgError::Invalid(format!("{what}: row index {bad} of a {n}×{n} matrix")));
    }
    if n == 0 {
        return Ok((Vec::new(), Vec::new()));
    }
    let (xadj, adjncy) = symmetric_graph(a, what)?;
    let mut nvtxs = n as metis_sys::idx_t;
    let mut xadj = xadj;
    let mut adjncy = adjncy;
    let mut options = [0 as metis_sys::idx_t; metis_sys::METIS_NOPTIONS as usize];
    let mut perm = vec![0 as metis_sys::idx_t; n];
    let mut iperm = vec![0 as metis_sys::idx_t; n];
    // SAFETY: every pointer is to a live, exclusively borrowed buffer of the length METIS reads
    // (options: METIS_NOPTIONS; xadj: n + 1; adjncy: xadj[n]; perm, iperm: n), the graph is
    // valid input for METIS (0-based, symmetric, no self loops, indices < n: built by
    // `symmetric_graph`), and a null vwgt means unit vertex weights.
    let status = unsafe {
        metis_sys::METIS_SetDefaultOptions(options.as_mut_ptr());
        metis_sys::METIS_NodeND(&mut nvtxs, xadj.as_mut_ptr(), adjncy.as_mut_ptr(), std::ptr::null_mut(), options.as_mut_ptr(), perm.as_mut_ptr(), iperm.as_mut_ptr())
    };
    match status {
        metis_sys::rstatus_et_METIS_OK => {}
        metis_sys::rstatus_et_METIS_ERROR_MEMORY => return Err(LinalgError::OutOfMemory { what: format!("{what}: nested dissection (METIS)"), n }),
        other => return Err(LinalgError::Invalid(format!("{what}: METIS nested dissection failed (status {other})"))),
    }
    let forward: Vec<usize> = perm.iter().map(|&v| v as usize).collect();
    let inverse: Vec<usize> = iperm.iter().map(|&v| v as usize).collect();
    check_permutation(&forward, &inverse).map_err(|e| LinalgError::Invalid(format!("{what}: METIS returned {e}")))?;
    Ok((forward, inverse))
}

/// The adjacency (METIS's CSR `xadj`, `adjncy`) of the symmetrised pattern of `a` without its
/// diagonal. Errors when the graph does not fit METIS's 32-bit indices.
fn symmetric_graph(a: &Csc, what: &str) -> Result<(Vec<metis_sys::idx_t>, Vec<metis_sys::idx_t>), LinalgError> {
    let n = a.n_rows;
    let too_big = || LinalgError::Invalid(format!("{what}: {n} unknowns with {} entries exceed METIS's 32-bit indices", a.nnz()));
    if 2 * a.nnz() > metis_sys::idx_t::MAX as usize {
        return Err(too_big());
    }
    // each off-diagonal entry (i, j) gives i → j and j → i; duplicates are removed per vertex
    let mut degree = vec![0usize; n];
    for j in 0..n {
        for &i in &a.row[a.col_ptr[j]..a.col_ptr[j + 1]] {
            if i != j {
                degree[i] += 1;
                degree[j] += 1;
            }
        }
    }
    let mut start = vec![0usize; n + 1];
    for v in 0..n {
        start[v + 1] = start[v] + degree[v];
    }
    let mut adj = vec![0 as metis_sys::idx_t; start[n]];
    let mut fill = start[..n].to_vec();
    for j in 0..n {
        for &i in &a.row[a.col_ptr[j]..a.col_ptr[j + 1]] {
            if i != j {
                adj[fill[i]] = j as metis_sys::idx_t;
                fill[i] += 1;
                adj[fill[j]] = i as metis_sys::idx_t;
                fill[j] += 1;
            }
        }
    }
    let mut xadj = Vec::with_capacity(n + 1);
    xadj.push(0 as metis_sys::idx_t);
    let mut len = 0usize;
    for v in 0..n {
        let (s, e) = (start[v], start[v + 1]);
        adj[s..e].sort_unstable();
        let mut last = None;
        for q in s..e {
            if last != Some(adj[q]) {
                last = Some(adj[q]);
                adj[len] = adj[q];
                len += 1;
            }
        }
        xadj.push(len as metis_sys::idx_t);
    }
    adj.truncate(len);
    adj.shrink_to_fit();
    Ok((xadj, adj))
}

/// Ok when `forward` and `inverse` are permutations of 0..n inverse to each other; else what
/// is wrong.
pub fn check_permutation(forward: &[usize], inverse: &[usize]) -> Result<(), String> {
    let n = forward.len();
    if inverse.len() != n {
        return Err(format!("a permutation of {n} with an inverse of {}", inverse.len()));
    }
    let mut seen = vec![false; n];
    for (new, &old) in forward.iter().enumerate() {
        if old >= n || seen[old] {
            return Err(format!("a forward permutation that is not one of 0..{n} (entry {new} = {old})"));
        }
        seen[old] = true;
        if inverse[old] != new {
            return Err(format!("an inverse permutation that does not invert the forward one at {old}"));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::assemble::{dof_map, restrict, stiffness};

    #[test]
    fn nested_dissection_is_a_valid_permutation_of_a_box_stiffness() {
        // the clamped 6×4×4 box's K_ff: METIS's output is a permutation of 0..n and its inverse
        let m = crate::linalg::assemble::tests::box_model(true, [6, 4, 4]);
        let k = stiffness(&m, &[true]);
        let n = 3 * m.n_nodes();
        let (map, nf) = dof_map(n, |d| m.is_free(d / 3, d % 3));
        let kff = restrict(&k, &map, nf, &map, nf);
        let (fwd, inv) = nested_dissection(&kff, "box").unwrap();
        assert_eq!(fwd.len(), nf);
        check_permutation(&fwd, &inv).unwrap();
    }

    #[test]
    fn check_permutation_rejects_repeats_and_wrong_inverses() {
        assert!(check_permutation(&[2, 0, 1], &[1, 2, 0]).is_ok());
        assert!(check_permutation(&[0, 0, 1], &[0, 2, 1]).is_err());
        assert!(check_permutation(&[2, 0, 1], &[2, 0, 1]).is_err());
        assert!(check_permutation(&[0, 3, 1], &[0, 2, 1]).is_err());
    }

    #[test]
    fn nested_dissection_of_a_malformed_matrix_is_a_typed_error() {
        // a non-square matrix and an out-of-range row index: LinalgError::Invalid, no call into
        // METIS (which would read out of bounds)
        let rect = Csc { n_rows: 2, n_cols: 3, col_ptr: vec![0, 1, 2, 3], row: vec![0, 1, 1], val: vec![1.0; 3] };
        assert!(matches!(nested_dissection(&rect, "rect"), Err(LinalgError::Invalid(_))));
        let bad = Csc { n_rows: 2, n_cols: 2, col_ptr: vec![0, 1, 2], row: vec![0, 5], val: vec![1.0; 2] };
        assert!(matches!(nested_dissection(&bad, "bad"), Err(LinalgError::Invalid(_))));
        let empty = Csc { n_rows: 0, n_cols: 0, col_ptr: vec![0], row: vec![], val: vec![] };
        assert_eq!(nested_dissection(&empty, "empty").unwrap(), (vec![], vec![]));
    }
}
