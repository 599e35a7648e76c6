//! Triangular solves x ← (L Lᵀ)⁻¹ x with a supernodal Cholesky factor of faer, split over its
//! elimination tree into two bins of independent subtrees solved at once (`rayon::join`) and
//! the supernodes above them (the "top", solved alone).
//!
//! Why: a solve with one right-hand side reads each entry of the factor once and is bound by
//! memory bandwidth; faer parallelises it only inside each supernode's dense blocks, which on
//! the dam's preconditioner gained nothing (linalg::cholesky::SOLVE_PAR). Two subtrees of the
//! nested-dissection tree touch disjoint rows, except their common ancestors', so each bin
//! works on its own copy of x: forward, a bin's updates of the top's rows are accumulated from
//! zero and added to x afterwards (bin 0's, then bin 1's); backward, the top is solved first and
//! each bin reads it from its copy. The split depends only on the factor's structure and the
//! bins' sums are added in a fixed order, so the result is bit-identical on any number of
//! threads (a pool of one runs the two bins one after the other); it differs from faer's
//! sequential solve by round-off only (the top rows' updates are summed in another order).
//!
//! Conventions: rows are those of the permuted matrix P A Pᵀ (faer's supernodes number them);
//! supernode s owns the columns `begin[s]..end[s]` and its below-diagonal rows (its pattern)
//! are rows of its ancestors; a child's index is below its parent's (faer's postorder).

use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve::{solve_lower_triangular_in_place, solve_upper_triangular_in_place};
use faer::prelude::{Reborrow, ReborrowMut};
use faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky;
use faer::{Accum, MatMut, MatRef, Par};

/// The scalars a factor may be stored in (f64, or f32 for a preconditioner:
/// `linalg::cholesky::FactorPrecision`).
pub trait Real: faer::traits::RealField + Copy + Send + Sync + std::ops::AddAssign + std::ops::SubAssign + From<f32> {}
impl Real for f64 {}
impl Real for f32 {}

/// Expansions of the top tried when splitting the tree: 200. Why: each moves the heaviest
/// subtree's root into the top and its children into the candidates; the best split (least
/// top + larger bin) of the fine dam's factor is found within a few tens, and each trial costs a
/// sort of the candidates (microseconds).
const SPLIT_EXPANSIONS: usize = 200;

/// The split of a factor's supernodes (see the module header).
#[derive(Clone, Debug)]
pub struct TreeSplit {
    /// Supernodes of each bin and of the top, ascending.
    bins: [Vec<usize>; 2],
    top: Vec<usize>,
    /// Rows of the top's supernodes.
    top_rows: Vec<usize>,
    /// Factor entries of each bin and of the top (the work of a solve is in proportion).
    pub weights: [usize; 3],
}

impl TreeSplit {
    /// The split of `sn`'s elimination tree that least delays the solve when the two bins run
    /// at once: the top's entries plus the larger bin's, least over [`SPLIT_EXPANSIONS`]
    /// expansions of the top from the roots (each bin filled largest subtree first).
    pub fn new(sn: &SymbolicSupernodalCholesky<usize>) -> TreeSplit {
        let ns = sn.n_supernodes();
        let (begin, end, val_ptr) = (sn.supernode_begin(), sn.supernode_end(), sn.col_ptr_for_val());
        let mut col_super = vec![0usize; sn.nrows()];
        for s in 0..ns {
            col_super[begin[s]..end[s]].iter_mut().for_each(|c| *c = s);
        }
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); ns];
        let mut roots = Vec::new();
        let mut weight: Vec<usize> = (0..ns).map(|s| val_ptr[s + 1] - val_ptr[s]).collect();
        for s in 0..ns {
            match sn.supernode(s).pattern().first() {
                Some(&r) => {
                    let p = col_super[r];
                    children[p].push(s);
                    weight[p] += weight[s];
                }
                None => roots.push(s),
            }
        }
        // weight[s] is now the subtree's (children come before their parent)
        let total = val_ptr[ns];
        let pack = |cands: &[usize]| {
            let mut sorted = cands.to_vec();
            sorted.sort_by(|&a, &b| weight[b].cmp(&weight[a]).then(a.cmp(&b)));
            let mut bins: [(usize, Vec<usize>); 2] = Default::default();
            for s in sorted {
                let b = if bins[0].0 <= bins[1].0 { 0 } else { 1 };
                bins[b].0 += weight[s];
                bins[b].1.push(s);
            }
            bins
        };
        let (mut cands, mut top, mut top_weight) = (roots, Vec::new(), 0usize);
        let mut best = (usize::MAX, Vec::new(), Default::default());
        for _ in 0..SPLIT_EXPANSIONS {
            let bins = pack(&cands);
            let span = top_weight + bins[0].0.max(bins[1].0);
            if span < best.0 {
                best = (span, top.clone(), bins);
            }
            let Some((i, &h)) = cands.iter().enumerate().max_by(|a, b| weight[*a.1].cmp(&weight[*b.1]).then(b.1.cmp(a.1))) else { break };
            if children[h].is_empty() || 2 * top_weight > total {
                break;
            }
            cands.swap_remove(i);
            top.push(h);
            top_weight += val_ptr[h + 1] - val_ptr[h];
            cands.extend_from_slice(&children[h]);
        }
        let (_, mut top, packed) = best;
        let subtree = |roots: &[usize]| {
            let (mut out, mut stack) = (Vec::new(), roots.to_vec());
            while let Some(s) = stack.pop() {
                out.push(s);
                stack.extend_from_slice(&children[s]);
            }
            out.sort_unstable();
            out
        };
        let bins = [subtree(&packed[0].1), subtree(&packed[1].1)];
        top.sort_unstable();
        let top_rows = top.iter().flat_map(|&s| begin[s]..end[s]).collect();
        let w = |v: &[usize]| v.iter().map(|&s| val_ptr[s + 1] - val_ptr[s]).sum();
        let weights = [w(&bins[0]), w(&bins[1]), w(&top)];
        TreeSplit { bins, top, top_rows, weights }
    }

    /// x ← (L Lᵀ)⁻¹ x for the permuted right-hand side `x` (length n), with the factor's
    /// `values` (faer's supernodal layout of `sn`).
    pub fn solve_permuted<T: Real>(&self, sn: &SymbolicSupernodalCholesky<usize>, values: &[T], x: &mut [T]) {
        // forward, L y = x: the bins (their top rows accumulated from 0), then the top
        let forward_bin = |b: usize| {
            let mut xb = x.to_vec();
            self.top_rows.iter().for_each(|&r| xb[r] = T::from(0.0));
            let mut tmp = Vec::new();
            for &s in &self.bins[b] {
                forward(sn, values, s, &mut xb, &mut tmp);
            }
            xb
        };
        let (x0, x1) = rayon::join(|| forward_bin(0), || forward_bin(1));
        self.merge(sn, x, &x0, &x1, true);
        let mut tmp = Vec::new();
        for &s in &self.top {
            forward(sn, values, s, x, &mut tmp);
        }
        // backward, Lᵀ z = y: the top, then the bins (each from a copy with the top's rows)
        for &s in self.top.iter().rev() {
            backward(sn, values, s, x, &mut tmp);
        }
        let backward_bin = |b: usize| {
            let mut xb = x.to_vec();
            let mut tmp = Vec::new();
            for &s in self.bins[b].iter().rev() {
                backward(sn, values, s, &mut xb, &mut tmp);
            }
            xb
        };
        let (x0, x1) = rayon::join(|| backward_bin(0), || backward_bin(1));
        self.merge(sn, x, &x0, &x1, false);
    }

    /// The bins' rows from their copies `x0`, `x1` into `x`; after a forward sweep also their
    /// updates of the top's rows (`x[r] += x0[r]`, then `+= x1[r]`).
    fn merge<T: Real>(&self, sn: &SymbolicSupernodalCholesky<usize>, x: &mut [T], x0: &[T], x1: &[T], forward: bool) {
        let (begin, end) = (sn.supernode_begin(), sn.supernode_end());
        for (bin, xb) in self.bins.iter().zip([x0, x1]) {
            for &s in bin {
                x[begin[s]..end[s]].copy_from_slice(&xb[begin[s]..end[s]]);
            }
        }
        if forward {
            for &r in &self.top_rows {
                x[r] += x0[r];
                x[r] += x1[r];
            }
        }
    }
}

/// Supernode `s`'s columns of L (rows: its own columns, then its pattern).
fn block<'a, T: Real>(sn: &SymbolicSupernodalCholesky<usize>, values: &'a [T], s: usize) -> MatRef<'a, T> {
    let (begin, end, val_ptr) = (sn.supernode_begin(), sn.supernode_end(), sn.col_ptr_for_val());
    let ncols = end[s] - begin[s];
    let nrows = ncols + sn.supernode(s).pattern().len();
    MatRef::from_column_major_slice(&values[val_ptr[s]..val_ptr[s + 1]], nrows, ncols)
}

/// Forward step of supernode `s`: x_s ← L_ss⁻¹ x_s, x_pattern −= L_ps x_s.
fn forward<T: Real>(sn: &SymbolicSupernodalCholesky<usize>, values: &[T], s: usize, x: &mut [T], tmp: &mut Vec<T>) {
    let (start, stop) = (sn.supernode_begin()[s], sn.supernode_end()[s]);
    let pattern = sn.supernode(s).pattern();
    let (l_top, l_bot) = block(sn, values, s).split_at_row(stop - start);
    let (head, _) = x.split_at_mut(stop);
    let mut x_top = MatMut::from_column_major_slice_mut(&mut head[start..], stop - start, 1);
    solve_lower_triangular_in_place(l_top, x_top.rb_mut(), Par::Seq);
    tmp.clear();
    tmp.resize(pattern.len(), T::from(0.0));
    matmul(MatMut::from_column_major_slice_mut(tmp, pattern.len(), 1), Accum::Replace, l_bot, x_top.rb(), T::from(1.0), Par::Seq);
    for (&r, t) in pattern.iter().zip(tmp.iter()) {
        x[r] -= *t;
    }
}

/// Backward step of supernode `s`: x_s ← L_ssᵀ⁻¹ (x_s − L_psᵀ x_pattern).
fn backward<T: Real>(sn: &SymbolicSupernodalCholesky<usize>, values: &[T], s: usize, x: &mut [T], tmp: &mut Vec<T>) {
    let (start, stop) = (sn.supernode_begin()[s], sn.supernode_end()[s]);
    let pattern = sn.supernode(s).pattern();
    let (l_top, l_bot) = block(sn, values, s).split_at_row(stop - start);
    tmp.clear();
    tmp.extend(pattern.iter().map(|&r| x[r]));
    let mut x_top = MatMut::from_column_major_slice_mut(&mut x[start..stop], stop - start, 1);
    matmul(x_top.rb_mut(), Accum::Add, l_bot.transpose(), MatRef::from_column_major_slice(tmp, pattern.len(), 1), T::from(-1.0), Par::Seq);
    solve_upper_triangular_in_place(l_top.transpose(), x_top, Par::Seq);
}
