//! Sparse Cholesky factorisation A = L Lᵀ with faer: the symbolic analysis (a fill-reducing
//! ordering, [`FillOrdering`]: AMD or METIS nested dissection; supernodal or simplicial
//! structure) once, the numeric factorisation once (or again, for a
//! matrix of the same pattern: [`SparseCholesky::refactor`]), then solves that reuse one
//! scratch buffer (no allocation per solve).

use super::ordering::{nested_dissection, FillOrdering};
use super::tree_solve::TreeSplit;
use super::{Csc, LinalgError};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltError as NumericLltError;
use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, LltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering};
use faer::{Conj, MatMut, Par, Side};

/// The threads of the triangular solves: one (`Par::Seq`). Why: a solve with one right-hand
/// side reads each entry of the factor once (memory-bound) and faer parallelises it only
/// within each supernode's dense blocks; measured on the fine dam's preconditioner (754 MB
/// factor, load 6, docs/performance.md §7b) a solve took 0.125 s of CPU on two threads against
/// 0.116 s on one, and no less wall time.
pub const SOLVE_PAR: Par = Par::Seq;

/// The scalar a factor's values are computed and stored in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum FactorPrecision {
    /// f64 (8 B an entry): a direct solve to the matrix's round-off.
    Double,
    /// f32 (4 B an entry): half the memory and the bandwidth of the solves; a solve is exact
    /// only to f32's round-off times the condition number, so only for a preconditioner (the
    /// right-hand side is rounded to f32 and the solution widened back to f64).
    Single,
}

/// A factor's values in their precision; for f32 also the matrix's values and a right-hand
/// side rounded to f32.
enum Values {
    Double(Vec<f64>),
    Single { l: Vec<f32>, a: Vec<f32>, x: Vec<f32> },
}

/// A factorised symmetric positive definite matrix.
pub struct SparseCholesky {
    symbolic: SymbolicCholesky<usize>,
    values: Values,
    /// Scratch of one solve with `scratch_cols` right-hand sides.
    scratch: MemBuffer,
    scratch_cols: usize,
    /// Threads of the numeric factorisation.
    par: Par,
    /// Entries of the matrix the symbolic analysis was made for (a refactorisation must have
    /// the same pattern).
    pattern_nnz: usize,
    /// The ordering the analysis used (never `Auto`).
    ordering: FillOrdering,
    /// Seconds of the symbolic analysis (the ordering included).
    analysis_seconds: f64,
    /// The elimination tree's split for solves in two parts at once ([`Self::split_solves`]),
    /// and the permuted right-hand side's buffer.
    split: Option<TreeSplit>,
    permuted: Vec<f64>,
}

impl std::fmt::Debug for SparseCholesky {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "SparseCholesky {{ n: {}, factor entries: {}, {:?} }}", self.n(), self.factor_entries(), self.precision())
    }
}

impl SparseCholesky {
    /// Factorise `a` (its lower triangle is read). `what` names the matrix in errors.
    /// `par`: faer's parallelism for the numeric factorisations (`Par::Seq` for small systems or
    /// when the caller already runs in parallel; a run's: [`super::run_par`]). The solves run on
    /// one thread whatever `par` ([`SOLVE_PAR`]).
    /// The ordering is faer's AMD ([`SparseCholesky::factor_ordered`] chooses another).
    pub fn factor(a: &Csc, what: &str, par: Par) -> Result<SparseCholesky, LinalgError> {
        SparseCholesky::factor_ordered(a, what, par, FillOrdering::Amd)
    }

    /// [`SparseCholesky::factor`] with the fill-reducing ordering `ordering`.
    pub fn factor_ordered(a: &Csc, what: &str, par: Par, ordering: FillOrdering) -> Result<SparseCholesky, LinalgError> {
        SparseCholesky::factor_in(a, what, par, ordering, FactorPrecision::Double)
    }

    /// [`SparseCholesky::factor_ordered`] with the factor's values in `precision`. In f32 a
    /// matrix whose condition number is near 1/f32's round-off (1e7) may lose a pivot: the
    /// error is then [`LinalgError::NotPositiveDefinite`], as for a singular matrix (a caller
    /// that has an f64 fallback uses it).
    pub fn factor_in(a: &Csc, what: &str, par: Par, ordering: FillOrdering, precision: FactorPrecision) -> Result<SparseCholesky, LinalgError> {
        let n = a.n_rows;
        if a.n_cols != n {
            return Err(LinalgError::Invalid(format!("{what}: a {n}×{} matrix is not square", a.n_cols)));
        }
        let start = std::time::Instant::now();
        let ordering = ordering.resolve(n);
        let symbolic = symbolic_analysis(a, what, ordering)?;
        let analysis_seconds = start.elapsed().as_secs_f64();
        let mut chol = SparseCholesky { symbolic, values: Values::Double(Vec::new()), scratch: MemBuffer::new(faer::dyn_stack::StackReq::EMPTY), scratch_cols: 0, par, pattern_nnz: a.nnz(), ordering, analysis_seconds, split: None, permuted: Vec::new() };
        chol.refactor_in(a, what, precision)?;
        Ok(chol)
    }

    /// [`SparseCholesky::refactor`] with the factor's values in `precision` from now on (the
    /// analysis is kept; e.g. f64 after an f32 factorisation lost a pivot).
    pub fn refactor_in(&mut self, a: &Csc, what: &str, precision: FactorPrecision) -> Result<(), LinalgError> {
        let (n, len) = (self.n(), self.symbolic.len_val());
        let oom = || LinalgError::OutOfMemory { what: what.to_string(), n };
        // scratch_cols 0: made by `factor_in`, nothing allocated yet (an empty factor, len 0,
        // already has the right number of values but still needs the solve's scratch)
        if self.precision() != precision || self.factor_entries() != len || self.scratch_cols == 0 {
            // the old values go first: the two factors need not fit at once
            self.values = Values::Double(Vec::new());
            self.values = match precision {
                FactorPrecision::Double => Values::Double(zeros(len).ok_or_else(oom)?),
                FactorPrecision::Single => Values::Single { l: zeros(len).ok_or_else(oom)?, a: zeros(self.pattern_nnz).ok_or_else(oom)?, x: zeros(n).ok_or_else(oom)? },
            };
            self.scratch = MemBuffer::try_new(self.solve_scratch(1, SOLVE_PAR)).map_err(|_| oom())?;
            self.scratch_cols = 1;
        }
        self.refactor(a, what)
    }

    /// Factorise `a` again, a matrix with the pattern of the one this was made for (the
    /// symbolic analysis, its ordering and the factor's memory are reused: only the numeric
    /// factorisation is done). A different pattern is an error.
    pub fn refactor(&mut self, a: &Csc, what: &str) -> Result<(), LinalgError> {
        let n = self.n();
        if a.n_rows != n || a.n_cols != n || a.nnz() != self.pattern_nnz {
            return Err(LinalgError::Invalid(format!("{what}: refactorising a {}×{} matrix with {} entries on the analysis of a {n}×{n} one with {}", a.n_rows, a.n_cols, a.nnz(), self.pattern_nnz)));
        }
        let oom = || LinalgError::OutOfMemory { what: what.to_string(), n };
        let res = match &mut self.values {
            Values::Double(l) => {
                let mut stack = MemBuffer::try_new(self.symbolic.factorize_numeric_llt_scratch::<f64>(self.par, Default::default())).map_err(|_| oom())?;
                self.symbolic.factorize_numeric_llt::<f64>(l, a.as_faer(), Side::Lower, Default::default(), self.par, MemStack::new(&mut stack), Default::default()).map(|_| ())
            }
            Values::Single { l, a: a32, .. } => {
                a32.iter_mut().zip(&a.val).for_each(|(s, &v)| *s = v as f32);
                let m = faer::sparse::SparseColMatRef::new(a.as_faer().symbolic(), &a32[..]);
                let mut stack = MemBuffer::try_new(self.symbolic.factorize_numeric_llt_scratch::<f32>(self.par, Default::default())).map_err(|_| oom())?;
                self.symbolic.factorize_numeric_llt::<f32>(l, m, Side::Lower, Default::default(), self.par, MemStack::new(&mut stack), Default::default()).map(|_| ())
            }
        };
        match res {
            Ok(()) => Ok(()),
            Err(NumericLltError::NonPositivePivot { index }) => Err(LinalgError::NotPositiveDefinite { what: what.to_string(), pivot: index, n }),
        }
    }

    /// Order of the matrix.
    pub fn n(&self) -> usize {
        self.symbolic.nrows()
    }

    /// Entries of the factor L (8 B each in f64, 4 B in f32: [`Self::factor_bytes`]).
    pub fn factor_entries(&self) -> usize {
        match &self.values {
            Values::Double(l) => l.len(),
            Values::Single { l, .. } => l.len(),
        }
    }

    /// Bytes of the factor's values.
    pub fn factor_bytes(&self) -> usize {
        match &self.values {
            Values::Double(l) => 8 * l.len(),
            Values::Single { l, .. } => 4 * l.len(),
        }
    }

    /// The precision of the factor's values.
    pub fn precision(&self) -> FactorPrecision {
        match &self.values {
            Values::Double(_) => FactorPrecision::Double,
            Values::Single { .. } => FactorPrecision::Single,
        }
    }

    /// The fill-reducing ordering of the analysis (AMD or nested dissection).
    pub fn ordering(&self) -> FillOrdering {
        self.ordering
    }

    /// Seconds of the symbolic analysis, the ordering included.
    pub fn analysis_seconds(&self) -> f64 {
        self.analysis_seconds
    }

    /// Floating-point operations of one numeric factorisation, Σ_j d_j² over the columns j of L
    /// with d_j entries each (the multiply-adds of the column updates, counted twice: the
    /// usual leading term of a Cholesky flop count). One solve costs 4 × [`Self::factor_entries`].
    pub fn factor_flops(&self) -> f64 {
        factor_flops_of(&self.symbolic)
    }

    /// From now on solve one right-hand side ([`Self::solve_in_place`]) in two halves of the
    /// elimination tree at once (`linalg::tree_solve`: bit-identical on any number of threads,
    /// equal to the sequential solve to round-off); nothing for a simplicial factor. Returns the
    /// factor entries of the two halves and of the part above them, solved alone.
    pub fn split_solves(&mut self) -> Option<[usize; 3]> {
        if let SymbolicCholeskyRaw::Supernodal(sn) = self.symbolic.raw() {
            let split = TreeSplit::new(sn);
            let weights = split.weights;
            self.split = Some(split);
            self.permuted = vec![0.0; self.n()];
            return Some(weights);
        }
        None
    }

    /// x ← A⁻¹ x.
    pub fn solve_in_place(&mut self, x: &mut [f64]) {
        let n = self.n();
        assert_eq!(x.len(), n, "right-hand side length");
        if let (Some(split), SymbolicCholeskyRaw::Supernodal(sn)) = (&self.split, self.symbolic.raw()) {
            let xp = &mut self.permuted;
            match self.symbolic.perm() {
                Some(perm) => perm.arrays().0.iter().zip(xp.iter_mut()).for_each(|(&old, v)| *v = x[old]),
                None => xp.copy_from_slice(x),
            }
            match &mut self.values {
                Values::Double(l) => split.solve_permuted(sn, l, xp),
                Values::Single { l, x: x32, .. } => {
                    x32.iter_mut().zip(xp.iter()).for_each(|(s, &v)| *s = v as f32);
                    split.solve_permuted(sn, l, x32);
                    xp.iter_mut().zip(x32.iter()).for_each(|(v, &s)| *v = s as f64);
                }
            }
            match self.symbolic.perm() {
                Some(perm) => perm.arrays().0.iter().zip(xp.iter()).for_each(|(&old, v)| x[old] = *v),
                None => x.copy_from_slice(xp),
            }
            return;
        }
        let rhs = MatMut::from_column_major_slice_mut(x, n, 1);
        self.solve_mat_in_place(rhs);
    }

    /// The scratch faer's solve needs for `cols` right-hand sides, in the factor's precision.
    fn solve_scratch(&self, cols: usize, par: Par) -> faer::dyn_stack::StackReq {
        match self.values {
            Values::Double(_) => self.symbolic.solve_in_place_scratch::<f64>(cols, par),
            Values::Single { .. } => self.symbolic.solve_in_place_scratch::<f32>(cols, par),
        }
    }

    /// X ← A⁻¹ X for a column-major block of right-hand sides.
    pub fn solve_mat_in_place(&mut self, rhs: MatMut<'_, f64>) {
        if rhs.ncols() > self.scratch_cols {
            self.scratch = MemBuffer::new(self.solve_scratch(rhs.ncols(), SOLVE_PAR));
            self.scratch_cols = rhs.ncols();
        }
        solve_with(&self.symbolic, &self.values, rhs, SOLVE_PAR, MemStack::new(&mut self.scratch));
    }

    /// X ← A⁻¹ X with a scratch of its own (one thread): for blocks of right-hand sides solved
    /// in parallel on a shared factorisation.
    pub fn solve_block_in_place(&self, rhs: MatMut<'_, f64>) -> Result<(), LinalgError> {
        let n = self.n();
        let mut scratch = MemBuffer::try_new(self.solve_scratch(rhs.ncols(), Par::Seq)).map_err(|_| LinalgError::OutOfMemory { what: "solve scratch".into(), n })?;
        solve_with(&self.symbolic, &self.values, rhs, Par::Seq, MemStack::new(&mut scratch));
        Ok(())
    }
}

/// A vector of `len` zeros, or `None` if the memory cannot be had.
fn zeros<T: Clone + Default>(len: usize) -> Option<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(len).ok()?;
    v.resize(len, T::default());
    Some(v)
}

/// X ← A⁻¹ X with faer's solve on the factor `values` of `symbolic` (an f32 factor on a copy of X
/// rounded to f32, widened back).
fn solve_with(symbolic: &SymbolicCholesky<usize>, values: &Values, mut rhs: MatMut<'_, f64>, par: Par, stack: &mut MemStack) {
    match values {
        Values::Double(l) => LltRef::new(symbolic, l).solve_in_place_with_conj(Conj::No, rhs, par, stack),
        Values::Single { l, .. } => {
            let mut x32 = faer::Mat::<f32>::from_fn(rhs.nrows(), rhs.ncols(), |i, j| rhs[(i, j)] as f32);
            LltRef::new(symbolic, l).solve_in_place_with_conj(Conj::No, x32.as_mut(), par, stack);
            for j in 0..rhs.ncols() {
                for i in 0..rhs.nrows() {
                    rhs[(i, j)] = x32[(i, j)] as f64;
                }
            }
        }
    }
}

/// The symbolic analysis of `a` (its lower triangle) with the ordering `ordering` (not `Auto`).
fn symbolic_analysis(a: &Csc, what: &str, ordering: FillOrdering) -> Result<SymbolicCholesky<usize>, LinalgError> {
    let n = a.n_rows;
    let oom = || LinalgError::OutOfMemory { what: what.to_string(), n };
    let m = a.as_faer();
    match ordering {
        FillOrdering::NestedDissection => {
            let (fwd, inv) = nested_dissection(a, what)?;
            let perm = faer::perm::PermRef::new_checked(&fwd, &inv, n);
            factorize_symbolic_cholesky(m.symbolic(), Side::Lower, SymmetricOrdering::Custom(perm), Default::default())
        }
        _ => factorize_symbolic_cholesky(m.symbolic(), Side::Lower, SymmetricOrdering::Amd, Default::default()),
    }
    .map_err(|_| oom())
}

/// Σ_j d_j² over the columns of the factor of `symbolic` ([`SparseCholesky::factor_flops`]).
fn factor_flops_of(symbolic: &SymbolicCholesky<usize>) -> f64 {
    match symbolic.raw() {
        SymbolicCholeskyRaw::Supernodal(sn) => {
            let (begin, end, below) = (sn.supernode_begin(), sn.supernode_end(), sn.nnz_per_super());
            (0..sn.n_supernodes())
                .map(|s| {
                    // column k of a supernode of c columns with r rows below it: c − k + r entries
                    let (c, r) = (end[s] - begin[s], below[s] as f64);
                    (1..=c).map(|m| (m as f64 + r).powi(2)).sum::<f64>()
                })
                .sum()
        }
        SymbolicCholeskyRaw::Simplicial(sp) => sp.col_ptr().windows(2).map(|w| ((w[1] - w[0]) as f64).powi(2)).sum(),
    }
}

/// What a symbolic analysis predicts, without the numeric factorisation (for measuring the
/// fill of an ordering on a matrix whose factor may not fit in memory).
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct CholeskyAnalysis {
    pub n: usize,
    /// Entries of the factor L (8 B each).
    pub factor_entries: usize,
    pub factor_flops: f64,
    pub seconds: f64,
    pub nested_dissection: bool,
}

/// The symbolic analysis of the square matrix `a` with `ordering`: the factor's size and flops.
pub fn analyse(a: &Csc, what: &str, ordering: FillOrdering) -> Result<CholeskyAnalysis, LinalgError> {
    let n = a.n_rows;
    if a.n_cols != n {
        return Err(LinalgError::Invalid(format!("{what}: a {n}×{} matrix is not square", a.n_cols)));
    }
    let start = std::time::Instant::now();
    let ordering = ordering.resolve(n);
    let symbolic = symbolic_analysis(a, what, ordering)?;
    Ok(CholeskyAnalysis { n, factor_entries: symbolic.len_val(), factor_flops: factor_flops_of(&symbolic), seconds: start.elapsed().as_secs_f64(), nested_dissection: ordering == FillOrdering::NestedDissection })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::assemble::{dof_map, restrict, stiffness};

    /// K_ff of the box (`assemble::tests::box_model`, tetrahedra, `dims` divisions) clamped
    /// on its x0 face: the stiffness on its free dofs.
    fn clamped_box_kff(dims: [usize; 3]) -> Csc {
        let m = crate::linalg::assemble::tests::box_model(true, dims);
        let k = stiffness(&m, &[true]);
        let (map, nf) = dof_map(3 * m.n_nodes(), |d| m.is_free(d / 3, d % 3));
        restrict(&k, &map, nf, &map, nf)
    }

    /// The largest |a − b| relative to the largest |a|.
    fn rel_diff<T: Into<f64> + Copy>(a: &[T], b: &[T]) -> f64 {
        let scale = a.iter().fold(0.0f64, |m, &v| m.max(v.into().abs()));
        a.iter().zip(b).map(|(&x, &y)| (x.into() - y.into()).abs()).fold(0.0, f64::max) / scale
    }

    /// Regression: with the f32 option, `factor_in` allocated the values and the solve's scratch
    /// only when the factor's entry count changed, so a factor with no entries (a model whose
    /// condensed block is empty: the tied-interface joint test) kept an empty scratch and faer's
    /// solve panicked ("buffer is not large enough to accomodate the requested alignment").
    #[test]
    fn regression_an_empty_factor_solved_with_an_empty_scratch() {
        let empty = Csc { n_rows: 0, n_cols: 0, col_ptr: vec![0], row: Vec::new(), val: Vec::new() };
        for precision in [FactorPrecision::Double, FactorPrecision::Single] {
            let mut ch = SparseCholesky::factor_in(&empty, "empty", Par::Seq, FillOrdering::Amd, precision).unwrap();
            let mut x: Vec<f64> = Vec::new();
            ch.solve_in_place(&mut x);
            ch.refactor(&empty, "empty").unwrap();
            ch.solve_in_place(&mut x);
        }
    }

    #[test]
    fn cholesky_solves_the_supported_box() {
        // K_ff x = b on the free dofs of a clamped box; residual ‖K x − b‖ ≤ 1e-10 ‖b‖
        // (a direct solve: only round-off, the condition number here is about 1e4)
        let kff = clamped_box_kff([4, 2, 2]);
        let nf = kff.n_rows;
        let mut ch = SparseCholesky::factor(&kff, "test", Par::Seq).unwrap();
        let b: Vec<f64> = (0..nf).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut x = b.clone();
        ch.solve_in_place(&mut x);
        let mut r = vec![0.0; nf];
        kff.mul_into(&x, &mut r);
        let err = r.iter().zip(&b).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt();
        let nb = b.iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!(err < 1e-10 * nb, "residual {err} vs {nb}");
    }

    #[test]
    fn refactorisation_reuses_the_analysis_and_checks_the_pattern() {
        // K x = b, then 2 K refactorised on the same analysis: x/2 to round-off (1e-12
        // relative); a matrix of another pattern (another box) is refused, not factorised wrongly
        let mut kff = clamped_box_kff([3, 2, 2]);
        let nf = kff.n_rows;
        let mut ch = SparseCholesky::factor(&kff, "test", Par::Seq).unwrap();
        let b: Vec<f64> = (0..nf).map(|i| (i as f64 * 0.11).cos()).collect();
        let mut x1 = b.clone();
        ch.solve_in_place(&mut x1);
        kff.val.iter_mut().for_each(|v| *v *= 2.0);
        ch.refactor(&kff, "test").unwrap();
        let mut x2 = b.clone();
        ch.solve_in_place(&mut x2);
        let scale = x1.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        assert!(x1.iter().zip(&x2).all(|(a, b)| (a - 2.0 * b).abs() < 1e-12 * scale));
        let other = clamped_box_kff([3, 2, 3]);
        assert!(matches!(ch.refactor(&other, "other"), Err(LinalgError::Invalid(_))));
    }

    #[test]
    fn nested_dissection_factor_solves_as_amd_does() {
        // the clamped 8×6×6 box's K_ff x = b with both orderings: the same x to 1e-10 relative
        // (direct solves, only round-off differs), residual ≤ 1e-10 ‖b‖; the factor's flop
        // count is positive and its solve scratch works for a block of right-hand sides too
        let kff = clamped_box_kff([8, 6, 6]);
        let nf = kff.n_rows;
        let mut amd = SparseCholesky::factor_ordered(&kff, "box", Par::Seq, FillOrdering::Amd).unwrap();
        let mut nd = SparseCholesky::factor_ordered(&kff, "box", Par::Seq, FillOrdering::NestedDissection).unwrap();
        assert_eq!(nd.ordering(), FillOrdering::NestedDissection);
        assert_eq!(amd.ordering(), FillOrdering::Amd);
        println!("factor entries AMD {} ND {}, flops AMD {:.3e} ND {:.3e}", amd.factor_entries(), nd.factor_entries(), amd.factor_flops(), nd.factor_flops());
        assert!(nd.factor_flops() > 0.0 && amd.factor_flops() > 0.0);
        let b: Vec<f64> = (0..nf).map(|i| (i as f64 * 0.29).sin()).collect();
        let (mut xa, mut xn) = (b.clone(), b.clone());
        amd.solve_in_place(&mut xa);
        nd.solve_in_place(&mut xn);
        let scale = xa.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        assert!(xa.iter().zip(&xn).all(|(a, b)| (a - b).abs() < 1e-10 * scale));
        let mut r = vec![0.0; nf];
        kff.mul_into(&xn, &mut r);
        let err = r.iter().zip(&b).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt();
        let nb = b.iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!(err < 1e-10 * nb, "residual {err} vs {nb}");
    }

    #[test]
    fn split_solve_equals_the_sequential_solve_on_any_threads() {
        // the clamped 10×8×8 box's K_ff under nested dissection (many supernodes): the solve
        // split over the elimination tree (linalg::tree_solve) against faer's sequential one,
        // equal to round-off (1e-12 of the largest entry: the same operations, the top's
        // updates summed in another order), and bit-identical in pools of 1 and 2 threads
        let kff = clamped_box_kff([10, 8, 8]);
        let nf = kff.n_rows;
        let mut ch = SparseCholesky::factor_ordered(&kff, "box", Par::Seq, FillOrdering::NestedDissection).unwrap();
        let b: Vec<f64> = (0..nf).map(|i| (i as f64 * 0.31).sin()).collect();
        let mut reference = b.clone();
        ch.solve_in_place(&mut reference);
        let weights = ch.split_solves().expect("a supernodal factor");
        println!("split of {} factor entries: bins {} and {}, top {}", ch.factor_entries(), weights[0], weights[1], weights[2]);
        assert_eq!(weights.iter().sum::<usize>(), ch.factor_entries());
        assert!(weights[0] > 0 && weights[1] > 0, "{weights:?}");
        let mut solve = |threads: usize| {
            let mut x = b.clone();
            rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(|| ch.solve_in_place(&mut x));
            x
        };
        let (x1, x2) = (solve(1), solve(2));
        assert!(x1.iter().zip(&x2).all(|(a, b)| a.to_bits() == b.to_bits()));
        let scale = reference.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let d = reference.iter().zip(&x1).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(d < 1e-12 * scale, "{d} vs {scale}");
    }

    #[test]
    fn single_precision_factor_solves_to_f32_round_off_and_switches_back() {
        // the clamped 10×8×8 box's K_ff (condition number about 1e4) factorised in f32 under
        // nested dissection: 4 bytes an entry, half the f64 factor's; its solution equals the f64
        // one to 1e-3 of the largest entry (f32's round-off 6e-8 × the condition number; measured 9e-6; a
        // preconditioner needs no more); the split solve equals faer's f32 solve to 1e-5 (f32
        // round-off, sums in another order); refactorised in f64 on the same analysis it is
        // the f64 factor again (to 1e-12)
        let kff = clamped_box_kff([10, 8, 8]);
        let b: Vec<f64> = (0..kff.n_rows).map(|i| (i as f64 * 0.23).cos()).collect();
        let solve = |ch: &mut SparseCholesky| {
            let mut x = b.clone();
            ch.solve_in_place(&mut x);
            x
        };
        let mut double = SparseCholesky::factor_ordered(&kff, "box", Par::Seq, FillOrdering::NestedDissection).unwrap();
        let mut single = SparseCholesky::factor_in(&kff, "box", Par::Seq, FillOrdering::NestedDissection, FactorPrecision::Single).unwrap();
        assert_eq!(single.precision(), FactorPrecision::Single);
        assert_eq!(single.factor_bytes(), 4 * single.factor_entries());
        let (x64, x32) = (solve(&mut double), solve(&mut single));
        let d = rel_diff(&x64, &x32);
        println!("f32 factor vs f64: {d:.2e}");
        assert!(d < 1e-3 && d > 0.0, "{d:.2e}");
        single.split_solves().expect("a supernodal factor");
        let d_split = rel_diff(&x32, &solve(&mut single));
        println!("f32 split solve vs faer's f32 solve: {d_split:.2e}");
        assert!(d_split < 1e-5, "{d_split:.2e}");
        let bytes32 = single.factor_bytes();
        single.refactor_in(&kff, "box", FactorPrecision::Double).unwrap();
        assert_eq!(single.precision(), FactorPrecision::Double);
        assert_eq!(single.factor_bytes(), 2 * bytes32);
        let d64 = rel_diff(&x64, &solve(&mut single));
        assert!(d64 < 1e-12, "{d64:.2e}");
    }

    #[test]
    fn nested_dissection_of_a_floating_body_is_reported_not_factorised() {
        // the ordering does not hide a singular matrix: NotPositiveDefinite, not a panic
        let m = crate::linalg::assemble::tests::box_model(false, [2, 1, 1]);
        let k = stiffness(&m, &[true]);
        let n = 3 * m.n_nodes();
        let (map, nf) = dof_map(n, |_| true);
        let kff = restrict(&k, &map, nf, &map, nf);
        assert!(matches!(SparseCholesky::factor_ordered(&kff, "floating box", Par::Seq, FillOrdering::NestedDissection), Err(LinalgError::NotPositiveDefinite { .. })));
    }

    #[test]
    fn floating_body_is_reported_not_factorised() {
        // no support: K is singular (six rigid modes) -> NotPositiveDefinite, not a panic
        let m = crate::linalg::assemble::tests::box_model(false, [2, 1, 1]);
        let k = stiffness(&m, &[true]);
        let n = 3 * m.n_nodes();
        let (map, nf) = dof_map(n, |_| true);
        let kff = restrict(&k, &map, nf, &map, nf);
        match SparseCholesky::factor(&kff, "floating box", Par::Seq) {
            Err(LinalgError::NotPositiveDefinite { .. }) => {}
            other => panic!("expected NotPositiveDefinite, got {other:?}"),
        }
    }
}

/// x ← A⁻¹ x for a square sparse matrix that need not be symmetric (faer's sparse LU with
/// partial pivoting; symbolic and numeric factorisation on every call). `what` names the
/// matrix in errors.
pub fn lu_solve_in_place(a: &Csc, x: &mut [f64], what: &str) -> Result<(), LinalgError> {
    use faer::linalg::solvers::Solve;
    let n = a.n_rows;
    if a.n_cols != n || x.len() != n {
        return Err(LinalgError::Invalid(format!("{what}: a {n}×{} matrix with a right-hand side of {}", a.n_cols, x.len())));
    }
    let lu = a.as_faer().sp_lu().map_err(|e| LinalgError::Invalid(format!("{what}: sparse LU failed ({e:?}): the model can move without deforming, or the matrix is singular")))?;
    lu.solve_in_place(MatMut::from_column_major_slice_mut(x, n, 1));
    Ok(())
}
