//! Sparse linear algebra on a fixed pattern: the values are refilled in place, the symbolic
//! analysis is done once, and numeric factorizations are timed. Two symmetric
//! factorizations, both faer's supernodal Cholesky with its fill-reducing (AMD) ordering:
//! LL^T of a positive definite matrix and LDL^T of a quasi-definite one (the contact KKT
//! matrix), with dynamic regularization of the pivots that vanish.

use crate::error::{Error, Result};
use crate::fe::Pattern;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::perm::PermRef;
use faer::sparse::linalg::amd;
use faer::sparse::linalg::cholesky::{
    LdltRef, SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::linalg::solvers::{Llt, Lu, SymbolicLlt, SymbolicLu};
use faer::sparse::{SparseColMat, SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};
use faer::{Conj, Par, Side};
use std::time::Instant;

/// An LDL^T factorization (values and the one symbolic analysis they belong to).
struct Ldlt {
    values: Vec<f64>,
    /// The symmetric scaling W of the factored matrix W A W (see [`equilibrate`]).
    scaling: Vec<f64>,
}

/// The symmetric (Jacobi) scaling w of the matrix whose lower triangle is `values`: w_j =
/// 1/sqrt|a_jj|, and for a zero diagonal (an active multiplier row) 1 / the largest
/// |a_ij| w_i of its row, so that W A W has unit diagonal or a largest entry of 1 in
/// every row. Pivots can then be judged against one threshold whatever the units and the
/// bodies' moduli.
fn equilibrate(symbolic: SymbolicSparseColMatRef<'_, usize>, values: &[f64]) -> Vec<f64> {
    let n = symbolic.ncols();
    let mut diagonal = vec![0.0f64; n];
    for j in 0..n {
        for (s, i) in symbolic.row_idx_of_col(j).enumerate() {
            if i == j {
                diagonal[j] = values[symbolic.col_ptr()[j] + s].abs();
            }
        }
    }
    let mut w: Vec<f64> = diagonal
        .iter()
        .map(|&d| if d > 0.0 { 1.0 / d.sqrt() } else { 0.0 })
        .collect();
    let mut largest = vec![0.0f64; n];
    for j in 0..n {
        for (s, i) in symbolic.row_idx_of_col(j).enumerate() {
            if i > j {
                let a = values[symbolic.col_ptr()[j] + s].abs();
                if diagonal[i] == 0.0 {
                    largest[i] = largest[i].max(a * w[j]);
                }
                if diagonal[j] == 0.0 {
                    largest[j] = largest[j].max(a * w[i]);
                }
            }
        }
    }
    for j in 0..n {
        if diagonal[j] == 0.0 {
            w[j] = if largest[j] > 0.0 {
                1.0 / largest[j]
            } else {
                1.0
            };
        }
    }
    w
}

/// A square sparse matrix with a fixed pattern and a reusable symbolic factorization.
pub struct SparseSystem {
    /// The matrix (values refilled by the caller through [`SparseSystem::values_mut`]).
    mat: SparseColMat<usize, f64>,
    symbolic_ldlt: Option<SymbolicCholesky<usize>>,
    symbolic_llt: Option<SymbolicLlt<usize>>,
    symbolic_lu: Option<SymbolicLu<usize>>,
    ldlt: Option<Ldlt>,
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
}

impl SparseSystem {
    /// A zero matrix with `pattern`.
    pub fn new(pattern: &Pattern) -> Self {
        let sym = SymbolicSparseColMat::new_checked(
            pattern.n,
            pattern.n,
            pattern.col_ptr.clone(),
            None,
            pattern.row_idx.clone(),
        );
        let mat = SparseColMat::new(sym, vec![0.0; pattern.nnz()]);
        SparseSystem {
            mat,
            symbolic_ldlt: None,
            symbolic_llt: None,
            symbolic_lu: None,
            ldlt: None,
            llt: None,
            lu: None,
            factor_s: 0.0,
            symbolic_s: 0.0,
            factorizations: 0,
            solves: std::cell::Cell::new(0),
        }
    }

    /// Values in pattern order (CSC slots).
    pub fn values_mut(&mut self) -> &mut [f64] {
        self.mat.val_mut()
    }

    /// The symbolic analysis of the LDL^T factorization (once per pattern; timed apart from
    /// the numeric factorizations). The ordering is faer's AMD of the whole pattern, except
    /// that every row k >= `n_primal` (a multiplier) is moved to just after the last of its
    /// neighbours < `n_primal`: its pivot is then a Schur complement -C S^{-1} C^T, non-zero,
    /// where AMD would eliminate it first on a zero diagonal. It adds about one column of
    /// fill per multiplier.
    pub fn analyze_ldlt(&mut self, n_primal: usize) -> Result<()> {
        if self.symbolic_ldlt.is_some() {
            return Ok(());
        }
        let t = Instant::now();
        let n = self.mat.nrows();
        let symbolic = self.mat.symbolic();
        let (mut fwd, mut inv) = (vec![0usize; n], vec![0usize; n]);
        let nnz = symbolic.row_idx().len();
        let mut buffer = MemBuffer::try_new(amd::order_scratch::<usize>(n, nnz))
            .map_err(|_| Error::NotConverged("out of memory in the ordering".into()))?;
        amd::order(
            &mut fwd,
            &mut inv,
            symbolic,
            Default::default(),
            MemStack::new(&mut buffer),
        )
        .map_err(|e| Error::NotConverged(format!("ordering failed: {e:?}")))?;
        // Multipliers after their last primal neighbour (rows of column k hold the
        // neighbours: the pattern is symmetric).
        let mut after: Vec<Vec<usize>> = vec![Vec::new(); n];
        let mut unattached = Vec::new();
        for k in n_primal..n {
            let last = symbolic
                .row_idx_of_col(k)
                .filter(|&r| r < n_primal)
                .max_by_key(|&r| inv[r]);
            match last {
                Some(r) => after[r].push(k),
                None => unattached.push(k),
            }
        }
        let mut order = Vec::with_capacity(n);
        for &r in fwd.iter().filter(|&&r| r < n_primal) {
            order.push(r);
            order.extend_from_slice(&after[r]);
        }
        order.extend(unattached);
        let mut order_inv = vec![0usize; n];
        for (position, &k) in order.iter().enumerate() {
            order_inv[k] = position;
        }
        let perm = PermRef::new_checked(&order, &order_inv, n);
        self.symbolic_ldlt = Some(
            factorize_symbolic_cholesky(
                symbolic,
                Side::Lower,
                SymmetricOrdering::Custom(perm),
                Default::default(),
            )
            .map_err(|e| Error::NotConverged(format!("symbolic LDLT failed: {e:?}")))?,
        );
        self.symbolic_s += t.elapsed().as_secs_f64();
        Ok(())
    }

    /// LDL^T factorization of the symmetric matrix A whose lower triangle is `values` (in
    /// pattern order; the upper triangle is not read), scaled symmetrically first (W A W,
    /// [`equilibrate`]). `signs` are the expected pivot signs (+1 displacement rows, -1
    /// multiplier rows); a pivot of the scaled matrix of the wrong sign or below `eps` in
    /// magnitude is replaced by `delta` with its expected sign (faer's dynamic
    /// regularization): the factorization is then that of a nearby matrix (a low-rank
    /// change), which callers refine.
    pub fn factor_ldlt(
        &mut self,
        values: &mut [f64],
        signs: &[i8],
        eps: f64,
        delta: f64,
    ) -> Result<()> {
        let symbolic = self
            .symbolic_ldlt
            .as_ref()
            .expect("analyze_ldlt before factor_ldlt");
        let t = Instant::now();
        let pattern = self.mat.symbolic();
        let scaling = equilibrate(pattern, values);
        for j in 0..pattern.ncols() {
            let start = pattern.col_ptr()[j];
            for (s, i) in pattern.row_idx_of_col(j).enumerate() {
                values[start + s] *= scaling[i] * scaling[j];
            }
        }
        let mut l_values = self.ldlt.take().map(|f| f.values).unwrap_or_default();
        l_values.resize(symbolic.len_val(), 0.0);
        let par = Par::Seq;
        let mut buffer = MemBuffer::try_new(
            symbolic.factorize_numeric_ldlt_scratch::<f64>(par, Default::default()),
        )
        .map_err(|_| Error::NotConverged("out of memory in the LDLT".into()))?;
        let mat = SparseColMatRef::new(self.mat.symbolic(), values);
        let regularization = LdltRegularization {
            dynamic_regularization_signs: Some(signs),
            dynamic_regularization_delta: delta,
            dynamic_regularization_epsilon: eps,
        };
        symbolic
            .factorize_numeric_ldlt(
                &mut l_values,
                mat,
                Side::Lower,
                regularization,
                par,
                MemStack::new(&mut buffer),
                Default::default(),
            )
            .map_err(|e| Error::NotConverged(format!("LDLT failed: {e:?}")))?;
        self.factor_s += t.elapsed().as_secs_f64();
        self.factorizations += 1;
        self.ldlt = Some(Ldlt {
            values: l_values,
            scaling,
        });
        self.llt = None;
        self.lu = None;
        Ok(())
    }

    /// LU factorization with partial pivoting of the matrix itself (any invertible matrix;
    /// its symbolic analysis is done on first use). 3-7x the cost of the LDL^T: the fallback
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
        self.ldlt = None;
        self.llt = None;
        Ok(())
    }

    /// Whether the last factorization is the LU of the matrix itself.
    pub fn is_lu(&self) -> bool {
        self.lu.is_some()
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
        self.ldlt = None;
        self.lu = None;
        Ok(())
    }

    /// Solve with the last factorization, in place.
    pub fn solve(&self, rhs: &mut [f64]) {
        self.solve_many(rhs, 1);
    }
}

impl SparseSystem {
    /// Solve with the last factorization for `k` right-hand sides stored column after
    /// column in `rhs`, in place (one blocked solve: several times cheaper per column than
    /// `k` single solves).
    pub fn solve_many(&self, rhs: &mut [f64], k: usize) {
        use faer::linalg::solvers::Solve;
        let n = rhs.len() / k;
        self.solves.set(self.solves.get() + k);
        if let Some(ldlt) = &self.ldlt {
            // A^{-1} = W (W A W)^{-1} W.
            let scale = |rhs: &mut [f64]| {
                for col in rhs.chunks_mut(n) {
                    col.iter_mut().zip(&ldlt.scaling).for_each(|(v, w)| *v *= w);
                }
            };
            scale(rhs);
            let symbolic = self.symbolic_ldlt.as_ref().expect("factored");
            let mut buffer = MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(k, Par::Seq));
            let m = faer::MatMut::from_column_major_slice_mut(rhs, n, k);
            LdltRef::new(symbolic, &ldlt.values).solve_in_place_with_conj(
                Conj::No,
                m,
                Par::Seq,
                MemStack::new(&mut buffer),
            );
            scale(rhs);
        } else if let Some(lu) = &self.lu {
            lu.solve_in_place(faer::MatMut::from_column_major_slice_mut(rhs, n, k));
        } else if let Some(llt) = &self.llt {
            llt.solve_in_place(faer::MatMut::from_column_major_slice_mut(rhs, n, k));
        } else {
            panic!("solve before factor");
        }
    }

    /// `y = A x` with the current values.
    pub fn matvec(&self, x: &[f64], y: &mut [f64]) {
        let (sym, val) = self.mat.parts();
        let cp = sym.col_ptr();
        let ri = sym.row_idx();
        y.iter_mut().for_each(|v| *v = 0.0);
        for c in 0..x.len() {
            let xc = x[c];
            if xc != 0.0 {
                for s in cp[c]..cp[c + 1] {
                    y[ri[s]] += val[s] * xc;
                }
            }
        }
    }

    /// Whether a factorization is available.
    pub fn is_factored(&self) -> bool {
        self.ldlt.is_some() || self.llt.is_some() || self.lu.is_some()
    }

    /// Solve `A x = b` with the current values of A by GMRES, right-preconditioned with
    /// `precondition` (in place: v -> M^{-1} v; typically the last factorization, of a
    /// possibly older matrix). Returns the iterations used, or None when the relative
    /// residual `rtol` is not reached in `max_iter` iterations. `b` is replaced by x.
    ///
    /// Written by hand: a few dozen lines, and the preconditioner is faer's factorization.
    pub fn gmres(
        &self,
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
            self.matvec(&z, &mut w);
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
}
