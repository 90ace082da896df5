//! Sparse linear algebra on a fixed pattern: the values are refilled in place, the symbolic
//! analysis is done once, and numeric factorizations are timed: faer's sparse Cholesky
//! (AMD ordering, or a given one: [`OrderedCholesky`], the floor's) and sparse LU (the Newton matrix itself, the fallback of
//! stiff tangents), products, and GMRES. The default solver's factorization is in
//! [`super::interface`].

use crate::error::{Error, Result};
use crate::fe::{Pattern, split_ranges_mut};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::perm::PermRef;
use faer::sparse::SparseColMatRef;
use faer::sparse::linalg::cholesky::{
    LltRef, SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::linalg::solvers::{Llt, Lu, SymbolicLlt, SymbolicLu};
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use faer::{Conj, Par, Side};
use rayon::prelude::*;
use std::time::Instant;

/// A square sparse matrix with a fixed pattern and a reusable symbolic factorization.
pub struct SparseSystem {
    /// The matrix (values refilled by the caller through [`SparseSystem::values_mut`]).
    mat: SparseColMat<usize, f64>,
    symbolic_llt: Option<SymbolicLlt<usize>>,
    symbolic_lu: Option<SymbolicLu<usize>>,
    llt: Option<Llt<usize, f64>>,
    lu: Option<Lu<usize, f64>>,
    /// Seconds spent in numeric factorizations.
    pub factor_s: f64,
    /// Seconds spent in the one-off symbolic analysis (ordering, elimination tree).
    pub symbolic_s: f64,
    /// Number of numeric factorizations.
    pub factorizations: usize,
    /// Number of right-hand sides solved with a factorization (forward and back
    /// substitution each).
    pub solves: std::cell::Cell<usize>,
    /// The matrix's diagonal blocks (see [`Pattern::diagonal_blocks`]), for the products.
    blocks: Vec<std::ops::Range<usize>>,
}

/// Equations from which the products run on rayon's threads (by column chunks, or by
/// diagonal blocks in [`SparseSystem::matvec`]). Measured at
/// level 4 of `study speed` (34,432 dofs, `rates`, fastest of 10 runs): newton's solves
/// (GMRES with its products) 0.050 s on 2 threads against 0.056 s on one.
pub const PARALLEL_EQUATIONS: usize = 20_000;

/// Columns per task of [`SymmetricProduct::product`] on rayon's threads.
const PRODUCT_CHUNK: usize = 4096;

impl SparseSystem {
    /// A zero matrix with `pattern`.
    pub fn new(pattern: &Pattern) -> Self {
        Self::with_values(pattern.clone(), vec![0.0; pattern.nnz()])
    }

    /// The matrix with `pattern` and `values` (pattern order), taking both.
    pub fn with_values(pattern: Pattern, values: Vec<f64>) -> Self {
        assert_eq!(values.len(), pattern.nnz(), "one value per slot");
        let blocks = pattern.diagonal_blocks();
        let Pattern {
            n,
            col_ptr,
            row_idx,
        } = pattern;
        let sym = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        let mat = SparseColMat::new(sym, values);
        SparseSystem {
            mat,
            blocks,
            symbolic_llt: None,
            symbolic_lu: None,
            llt: None,
            lu: None,
            factor_s: 0.0,
            symbolic_s: 0.0,
            factorizations: 0,
            solves: std::cell::Cell::new(0),
        }
    }

    /// Values in pattern order (CSC slots).
    pub fn values(&self) -> &[f64] {
        self.mat.val()
    }

    /// Values in pattern order (CSC slots), to write.
    pub fn values_mut(&mut self) -> &mut [f64] {
        self.mat.val_mut()
    }

    /// LU factorization with partial pivoting of the matrix itself (any invertible matrix;
    /// its symbolic analysis is done on first use). 3-7x the cost of a Cholesky: the fallback
    /// for a tangent too far from symmetric for GMRES.
    pub fn factor_lu(&mut self) -> Result<()> {
        if self.symbolic_lu.is_none() {
            let t = Instant::now();
            self.symbolic_lu = Some(
                SymbolicLu::try_new(self.mat.symbolic())
                    .map_err(|e| Error::NotConverged(format!("symbolic LU failed: {e:?}")))?,
            );
            self.symbolic_s += t.elapsed().as_secs_f64();
        }
        let t = Instant::now();
        let lu = Lu::try_new_with_symbolic(
            self.symbolic_lu.clone().expect("analyzed above"),
            self.mat.as_ref(),
        )
        .map_err(|e| {
            Error::NotConverged(format!(
                "the linearized system is singular ({e:?}): is a body free to move?"
            ))
        })?;
        self.factor_s += t.elapsed().as_secs_f64();
        self.factorizations += 1;
        self.lu = Some(lu);
        self.llt = None;
        Ok(())
    }

    /// Cholesky factorization (symmetric positive definite matrices; lower triangle read).
    pub fn factor_llt(&mut self) -> Result<()> {
        if self.symbolic_llt.is_none() {
            let t = Instant::now();
            self.symbolic_llt = Some(
                SymbolicLlt::try_new(self.mat.symbolic(), Side::Lower)
                    .map_err(|e| Error::NotConverged(format!("symbolic Cholesky failed: {e:?}")))?,
            );
            self.symbolic_s += t.elapsed().as_secs_f64();
        }
        let t = Instant::now();
        let llt = Llt::try_new_with_symbolic(
            self.symbolic_llt.clone().unwrap(),
            self.mat.as_ref(),
            Side::Lower,
        )
        .map_err(|e| {
            Error::NotConverged(format!(
                "the matrix is not positive definite ({e:?}): is a body free to move?"
            ))
        })?;
        self.factor_s += t.elapsed().as_secs_f64();
        self.factorizations += 1;
        self.llt = Some(llt);
        self.lu = None;
        Ok(())
    }

    /// Solve with the last factorization, in place.
    pub fn solve(&self, rhs: &mut [f64]) {
        use faer::linalg::solvers::Solve;
        self.solves.set(self.solves.get() + 1);
        let rhs = faer::MatMut::from_column_major_slice_mut(rhs, rhs.len(), 1);
        if let Some(lu) = &self.lu {
            lu.solve_in_place(rhs);
        } else if let Some(llt) = &self.llt {
            llt.solve_in_place(rhs);
        } else {
            panic!("solve before factor");
        }
    }

    /// `y = A x` with the current values.
    pub fn matvec(&self, x: &[f64], y: &mut [f64]) {
        let (sym, val) = self.mat.parts();
        let cp = sym.col_ptr();
        let ri = sym.row_idx();
        // Columns `columns` write rows `columns` only (a diagonal block): into y_block,
        // the rows from `columns.start` on.
        let product = |columns: std::ops::Range<usize>, y_block: &mut [f64]| {
            y_block.iter_mut().for_each(|v| *v = 0.0);
            for c in columns.clone() {
                let xc = x[c];
                if xc != 0.0 {
                    for s in cp[c]..cp[c + 1] {
                        y_block[ri[s] - columns.start] += val[s] * xc;
                    }
                }
            }
        };
        if self.blocks.len() > 1 && x.len() >= PARALLEL_EQUATIONS {
            // The blocks on rayon's threads: the same sums in the same order as one thread.
            let parts = split_ranges_mut(y, self.blocks.iter().cloned());
            self.blocks
                .par_iter()
                .zip(parts)
                .for_each(|(columns, y_block)| product(columns.clone(), y_block));
        } else {
            product(0..x.len(), y);
        }
    }
}

/// A symmetric matrix kept for products only (newton's elastic stiffness): its pattern's
/// column pointers, its row indices in 32 bits and its values. A product reads every
/// index and value once; 4-byte indices make it 12 bytes per entry instead of 16, and
/// the product is bound by memory (newton's GMRES runs one per iteration).
pub struct SymmetricProduct {
    col_ptr: Vec<usize>,
    rows: Vec<u32>,
    values: Vec<f64>,
}

impl SymmetricProduct {
    /// The matrix with `pattern` (both triangles) and `values` (pattern order), taking
    /// both. Panics from 2^32 equations on (a level refused long before for its memory).
    pub fn new(pattern: Pattern, values: Vec<f64>) -> Self {
        assert_eq!(values.len(), pattern.nnz(), "one value per slot");
        assert!(u32::try_from(pattern.n).is_ok(), "rows indexed in 32 bits");
        let Pattern {
            n,
            col_ptr,
            row_idx,
        } = pattern;
        debug_assert!(row_idx.iter().all(|&r| r < n), "rows below n");
        let rows = row_idx.into_iter().map(|r| r as u32).collect();
        SymmetricProduct {
            col_ptr,
            rows,
            values,
        }
    }

    /// Values in pattern order (CSC slots).
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// `y = A^T x`: per column of A, its dot product with x, in increasing row order (the
    /// same sums on any number of threads; the columns split evenly between them). For a
    /// symmetric A this is `A x` read row by row: the sums stay in registers.
    pub fn product(&self, x: &[f64], y: &mut [f64]) {
        let (cp, ri, val) = (&self.col_ptr, &self.rows, &self.values);
        let columns = |first: usize, y_chunk: &mut [f64]| {
            for (c, yc) in (first..).zip(y_chunk.iter_mut()) {
                let mut sum = 0.0;
                for s in cp[c]..cp[c + 1] {
                    sum += val[s] * x[ri[s] as usize];
                }
                *yc = sum;
            }
        };
        if x.len() >= PARALLEL_EQUATIONS {
            y.par_chunks_mut(PRODUCT_CHUNK)
                .enumerate()
                .for_each(|(k, y_chunk)| columns(k * PRODUCT_CHUNK, y_chunk));
        } else {
            columns(0, y);
        }
    }
}

/// A sparse Cholesky factorization L L^T of a symmetric positive definite matrix in a given
/// elimination order (the floor's: see [`super::floor`]): faer's symbolic analysis,
/// numeric factorization and substitutions, timed apart.
pub struct OrderedCholesky {
    pattern: SymbolicSparseColMat<usize>,
    symbolic: SymbolicCholesky<usize>,
    values: Vec<f64>,
    /// The single-precision factor ([`OrderedCholesky::factor_single`]), if any.
    values_single: Vec<f32>,
    /// Seconds in the numeric factorizations.
    pub factor_s: f64,
    /// Seconds in the symbolic analysis (the ordering given).
    pub symbolic_s: f64,
}

impl OrderedCholesky {
    /// The fill of the factor ([`super::ordering::factor_entries`]).
    pub fn factor_entries(&self) -> usize {
        super::ordering::factor_entries(&self.symbolic)
    }

    /// The flops of one numeric factorization ([`super::ordering::factor_flops`]).
    pub fn factor_flops(&self) -> f64 {
        super::ordering::factor_flops(&self.symbolic)
    }

    /// The symbolic analysis of `pattern` (both triangles; the lower one is read) in the
    /// elimination order `order` (the equation eliminated first, second, ...).
    pub fn new(pattern: &Pattern, order: &[usize]) -> Result<Self> {
        let t = Instant::now();
        let n = pattern.n;
        let pattern = SymbolicSparseColMat::new_checked(
            n,
            n,
            pattern.col_ptr.clone(),
            None,
            pattern.row_idx.clone(),
        );
        let mut position = vec![0usize; n];
        for (p, &e) in order.iter().enumerate() {
            position[e] = p;
        }
        let symbolic = factorize_symbolic_cholesky(
            pattern.as_ref(),
            Side::Lower,
            SymmetricOrdering::Custom(PermRef::new_checked(order, &position, n)),
            Default::default(),
        )
        .map_err(|e| Error::NotConverged(format!("symbolic Cholesky failed: {e:?}")))?;
        Ok(OrderedCholesky {
            pattern,
            symbolic,
            values: Vec::new(),
            values_single: Vec::new(),
            factor_s: 0.0,
            symbolic_s: t.elapsed().as_secs_f64(),
        })
    }

    /// Factorize the matrix whose values (pattern order) are `values`.
    pub fn factor(&mut self, values: &[f64]) -> Result<()> {
        let t = Instant::now();
        let mut factor = std::mem::take(&mut self.values);
        numeric_llt(&self.symbolic, &self.pattern, values, &mut factor, None)?;
        self.values = factor;
        self.factor_s += t.elapsed().as_secs_f64();
        Ok(())
    }

    /// Factorize in single precision the matrix whose values, rounded to f32, are
    /// `values`: half the bytes and twice the SIMD lanes of [`OrderedCholesky::factor`],
    /// for a preconditioner ([`OrderedCholesky::solve_single`]). A pivot below
    /// `pivot_epsilon` (absolute, as faer compares it) is replaced by
    /// `pivot_replacement`: f32's rounding (6e-8 relative) exceeds the 1e-8 shift that
    /// makes a body held only by contact definite, and leaves its rigid mode's pivot at
    /// the rounding's noise, of either sign.
    pub fn factor_single(
        &mut self,
        values: &[f32],
        pivot_epsilon: f32,
        pivot_replacement: f32,
    ) -> Result<()> {
        let t = Instant::now();
        let mut factor = std::mem::take(&mut self.values_single);
        let regularization = Some((pivot_epsilon, pivot_replacement));
        numeric_llt(
            &self.symbolic,
            &self.pattern,
            values,
            &mut factor,
            regularization,
        )?;
        self.values_single = factor;
        self.factor_s += t.elapsed().as_secs_f64();
        Ok(())
    }

    /// Solve with the single-precision factorization, in place.
    pub fn solve_single(&self, rhs: &mut [f32]) {
        substitute(&self.symbolic, &self.values_single, rhs);
    }

    /// Drop the double-precision factor (its memory handed back).
    pub fn drop_double(&mut self) {
        self.values = Vec::new();
    }

    /// Solve with the factorization, in place.
    pub fn solve(&self, rhs: &mut [f64]) {
        substitute(&self.symbolic, &self.values, rhs);
    }
}

/// faer's forward and back substitutions with the L L^T factor `values` of `symbolic`, in
/// place, in the precision of `T`.
fn substitute<T: super::substitution::Value>(
    symbolic: &SymbolicCholesky<usize>,
    values: &[T],
    rhs: &mut [T],
) {
    let n = rhs.len();
    let mut buffer = MemBuffer::new(symbolic.solve_in_place_scratch::<T>(1, Par::Seq));
    LltRef::new(symbolic, values).solve_in_place_with_conj(
        Conj::No,
        faer::MatMut::from_column_major_slice_mut(rhs, n, 1),
        Par::Seq,
        MemStack::new(&mut buffer),
    );
}

/// faer's numeric L L^T of `values` (pattern order, lower triangle read) into `factor`
/// (resized), in the precision of `T`, with dynamic regularization (pivot epsilon,
/// replacement) if given.
fn numeric_llt<T: super::substitution::Value>(
    symbolic: &SymbolicCholesky<usize>,
    pattern: &SymbolicSparseColMat<usize>,
    values: &[T],
    factor: &mut Vec<T>,
    regularization: Option<(T, T)>,
) -> Result<()> {
    factor.clear();
    factor.resize(symbolic.len_val(), T::from_f64(0.0));
    let mut buffer = MemBuffer::try_new(
        symbolic.factorize_numeric_llt_scratch::<T>(Par::Seq, Default::default()),
    )
    .map_err(|_| Error::NotConverged("out of memory in the Cholesky".into()))?;
    let regularization = match regularization {
        Some((epsilon, delta)) => LltRegularization {
            dynamic_regularization_delta: delta,
            dynamic_regularization_epsilon: epsilon,
        },
        None => Default::default(),
    };
    symbolic
        .factorize_numeric_llt(
            factor,
            SparseColMatRef::new(pattern.as_ref(), values),
            Side::Lower,
            regularization,
            Par::Seq,
            MemStack::new(&mut buffer),
            Default::default(),
        )
        .map_err(|e| {
            Error::NotConverged(format!(
                "the matrix is not positive definite ({e:?}): is a body free to move?"
            ))
        })?;
    Ok(())
}

/// Solve `A x = b` by GMRES (`matvec`: y = A x), right-preconditioned with
/// `precondition` (in place: v -> M^{-1} v; typically the last factorization, of a
/// possibly older matrix). Returns the iterations used, or None when the relative
/// residual `rtol` is not reached in `max_iter` iterations. `b` is replaced by x.
///
/// Written by hand: a few dozen lines, and the preconditioner is faer's factorization.
pub fn gmres(
    matvec: &dyn Fn(&[f64], &mut [f64]),
    b: &mut [f64],
    rtol: f64,
    max_iter: usize,
    precondition: &dyn Fn(&mut [f64]),
) -> Option<usize> {
    let n = b.len();
    let dot = |a: &[f64], c: &[f64]| a.iter().zip(c).map(|(x, y)| x * y).sum::<f64>();
    let bnorm = dot(b, b).sqrt();
    if bnorm == 0.0 {
        return Some(0);
    }
    let mut v: Vec<Vec<f64>> = vec![b.iter().map(|x| x / bnorm).collect()];
    let mut h = vec![vec![0.0; max_iter]; max_iter + 1];
    let (mut cs, mut sn) = (vec![0.0; max_iter], vec![0.0; max_iter]);
    let mut g = vec![0.0; max_iter + 1];
    g[0] = bnorm;
    // Z = M^{-1} V is kept (flexible GMRES): x = Z y needs no further solve.
    let mut zs: Vec<Vec<f64>> = Vec::with_capacity(max_iter);
    let mut w = vec![0.0; n];
    let mut k_done = 0;
    let mut converged = false;
    for k in 0..max_iter {
        let mut z = v[k].clone();
        precondition(&mut z);
        matvec(&z, &mut w);
        zs.push(z);
        for i in 0..=k {
            h[i][k] = dot(&w, &v[i]);
            for (wj, vj) in w.iter_mut().zip(&v[i]) {
                *wj -= h[i][k] * vj;
            }
        }
        h[k + 1][k] = dot(&w, &w).sqrt();
        for i in 0..k {
            let tmp = cs[i] * h[i][k] + sn[i] * h[i + 1][k];
            h[i + 1][k] = -sn[i] * h[i][k] + cs[i] * h[i + 1][k];
            h[i][k] = tmp;
        }
        let r = h[k][k].hypot(h[k + 1][k]);
        cs[k] = h[k][k] / r;
        sn[k] = h[k + 1][k] / r;
        h[k][k] = r;
        h[k + 1][k] = 0.0;
        g[k + 1] = -sn[k] * g[k];
        g[k] *= cs[k];
        k_done = k + 1;
        if g[k + 1].abs() <= rtol * bnorm {
            converged = true;
            break;
        }
        let nw = dot(&w, &w).sqrt();
        if nw == 0.0 {
            converged = true;
            break;
        }
        v.push(w.iter().map(|x| x / nw).collect());
    }
    if !converged {
        return None;
    }
    // y = H^{-1} g, x = M^{-1} V y = Z y.
    let mut y = vec![0.0; k_done];
    for i in (0..k_done).rev() {
        let s: f64 = (i + 1..k_done).map(|j| h[i][j] * y[j]).sum();
        y[i] = (g[i] - s) / h[i][i];
    }
    let mut x = vec![0.0; n];
    for (j, yj) in y.iter().enumerate() {
        for (xi, zi) in x.iter_mut().zip(&zs[j]) {
            *xi += yj * zi;
        }
    }
    b.copy_from_slice(&x);
    Some(k_done)
}
