//! Sparse linear algebra on a fixed pattern: the values are refilled in place, the symbolic
//! analysis is done once, and numeric factorizations are timed.

use crate::error::{Error, Result};
use crate::fe::Pattern;
use faer::sparse::linalg::solvers::{Llt, Lu, SymbolicLlt, SymbolicLu};
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use faer::{Mat, Side};
use std::time::Instant;

/// A square sparse matrix with a fixed pattern and a reusable symbolic factorization.
pub struct SparseSystem {
    /// The matrix (values refilled by the caller through [`SparseSystem::values_mut`]).
    mat: SparseColMat<usize, f64>,
    symbolic_lu: Option<SymbolicLu<usize>>,
    symbolic_llt: Option<SymbolicLlt<usize>>,
    lu: Option<Lu<usize, f64>>,
    llt: Option<Llt<usize, f64>>,
    /// Seconds spent in numeric factorizations.
    pub factor_s: f64,
    /// Number of numeric factorizations.
    pub factorizations: usize,
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
            symbolic_lu: None,
            symbolic_llt: None,
            lu: None,
            llt: None,
            factor_s: 0.0,
            factorizations: 0,
        }
    }

    /// Values in pattern order (CSC slots).
    pub fn values_mut(&mut self) -> &mut [f64] {
        self.mat.val_mut()
    }

    /// LU factorization with partial pivoting (any invertible matrix).
    pub fn factor_lu(&mut self) -> Result<()> {
        if self.symbolic_lu.is_none() {
            self.symbolic_lu = Some(
                SymbolicLu::try_new(self.mat.symbolic())
                    .map_err(|e| Error::NotConverged(format!("symbolic LU failed: {e:?}")))?,
            );
        }
        let t = Instant::now();
        let lu = Lu::try_new_with_symbolic(self.symbolic_lu.clone().unwrap(), self.mat.as_ref())
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
            self.symbolic_llt = Some(
                SymbolicLlt::try_new(self.mat.symbolic(), Side::Lower)
                    .map_err(|e| Error::NotConverged(format!("symbolic Cholesky failed: {e:?}")))?,
            );
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
        let mut m = Mat::<f64>::from_fn(rhs.len(), 1, |i, _| rhs[i]);
        if let Some(lu) = &self.lu {
            lu.solve_in_place(m.as_mut());
        } else if let Some(llt) = &self.llt {
            llt.solve_in_place(m.as_mut());
        } else {
            panic!("solve before factor");
        }
        for (i, r) in rhs.iter_mut().enumerate() {
            *r = m[(i, 0)];
        }
    }
}
