//! The stiffness factorized with the contact interface's unknowns last, and every active
//! set solved on the interface alone.
//!
//! The contact rows C touch only the b unknowns on Gamma_C (b ~ sqrt(n)). Ordered last, a
//! sparse LDL^T of the stiffness ends in a dense b x b block whose L D L^T is the Schur
//! complement S of the stiffness onto the interface. The Newton system of any active set A,
//!
//! ```text
//! [ K       c C^T ] [x]   [f]        (inactive rows: c y_i = g_i)
//! [ c C_A   0     ] [y] = [g_A]
//! ```
//!
//! is then one forward substitution, a dense saddle-point solve on the interface
//! `[S c C_A^T; c C_A 0]` (b + |A| unknowns, one dense LU per active set) and one back
//! substitution: the sparse matrix is factorized once per tangent and never per active set.
//! (The KKT matrix's LDL^T it replaces was refactorized two or three times per run, at
//! every large change of the active set; measured in issue 14.)
//!
//! A body held only by contact has a singular stiffness, but its rigid mode lives on the
//! interface: the factorized matrix is K + sigma P_I^T P_I (sigma the stiffness scale on
//! the interface diagonal), positive definite, and S = (its trailing block) - sigma I is
//! exact; the saddle-point system is regular as soon as the active rows hold the body.
//!
//! Written by hand on top of faer's supernodal LDL^T (its public supernode values): faer
//! solves with the whole factor only, and this needs the forward and back substitutions
//! apart, with the interface solve in between.

use super::substitution::{self, Lift, Split, Structure, Value};
use super::{ordering, pieces};
use crate::error::{Error, Result};
use crate::fe::Pattern;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::linalg::solvers::{PartialPivLu, SolveCore};
use faer::perm::PermRef;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::supernodal::{SupernodalLdltRef, SymbolicSupernodalCholesky};
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
    factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Accum, Conj, Mat, Par, Side};
use rayon::prelude::*;
use std::cell::Cell;
use std::time::Instant;

/// A contact row restricted to the free unknowns: (interface index, equation, coefficient).
type InterfaceRow = Vec<(usize, usize, f64)>;

/// The factorization of one symmetric stiffness with the interface last (see the module).
/// The stiffness is block diagonal (the bodies share no node): each diagonal block (a body)
/// is factorized on its own, with its own interface unknowns last, the blocks on rayon's
/// threads side by side; the interface's Schur complement is the blocks' trailing blocks
/// side by side.
pub struct InterfaceFactorization {
    n: usize,
    /// Free equations on Gamma_C, in the order of the dense interface system: block after
    /// block, each block's in equation order.
    interface: Vec<usize>,
    /// Contact rows over the interface.
    rows: Vec<InterfaceRow>,
    /// 1 / |C_i| (Euclidean norm of row i; 1 for an empty row): scales the multiplier rows
    /// of the dense saddle-point matrix to the size of the stiffness.
    row_scale: Vec<f64>,
    /// The diagonal blocks, in equation order.
    blocks: Vec<Block>,
    /// Each block's elimination tree split into subtrees for the substitutions.
    splits: Vec<Split>,
    /// S: the Schur complement of the stiffness onto the interface (b x b, force/length),
    /// block diagonal.
    schur: Option<Mat<f64>>,
    /// Seconds in numeric work: sparse LDL^T, interface block, dense LUs.
    pub factor_s: Cell<f64>,
    /// Seconds in the symbolic analysis (ordering, elimination tree), once per mesh.
    pub symbolic_s: f64,
    /// Sparse numeric factorizations.
    pub factorizations: usize,
    /// Right-hand sides solved.
    pub solves: Cell<usize>,
}

/// One diagonal block of the stiffness: equations `first..first + n`, no entry outside.
struct Block {
    first: usize,
    n: usize,
    /// The block's entries in the values of the whole stiffness (its columns are contiguous).
    entries: std::ops::Range<usize>,
    /// The block's equations on Gamma_C (local numbers, increasing), last in its order.
    interface: Vec<usize>,
    /// Position of each local equation in the block's elimination order.
    position: Vec<usize>,
    symbolic: SymbolicCholesky<usize>,
    /// First column of each supernode of the factor, and n at the end.
    begin: Vec<usize>,
    /// Pattern of the block (lower triangle read) and the slots of its diagonal entries,
    /// in local equation order.
    pattern: SymbolicSparseColMat<usize>,
    diagonal: Vec<usize>,
    numeric: Option<Numeric>,
}

/// The numeric part of a block: values of the factor and the interface's dense blocks.
struct Numeric {
    /// Values of the supernodal L (unit diagonal) with D on its diagonal.
    values: FactorValues,
    /// 1 / D, in elimination order.
    inverse_diagonal: Vec<f64>,
    /// Symmetric scaling W (local equation order): W (K + sigma P^T P) W was factorized.
    scaling: Vec<f64>,
    /// The trailing block of L (unit lower triangular) and of D.
    l_interface: Mat<f64>,
    d_interface: Vec<f64>,
}

/// The precision of a factorization's values (see [`InterfaceFactorization::factor`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Precision {
    /// f64: every solve exact to round-off.
    Double,
    /// f32: half the bytes and twice the SIMD lanes; a preconditioner.
    Single,
}

/// The factor values of every block, in their one precision.
enum Values<'a> {
    Double(Vec<&'a [f64]>),
    Single(Vec<&'a [f32]>),
}

/// The values of a block's factor.
enum FactorValues {
    Double(Vec<f64>),
    Single(Vec<f32>),
}

impl FactorValues {
    /// The f64 values, if these are.
    fn double(self) -> Option<Vec<f64>> {
        match self {
            FactorValues::Double(l) => Some(l),
            FactorValues::Single(_) => None,
        }
    }

    /// The f32 values, if these are.
    fn single(self) -> Option<Vec<f32>> {
        match self {
            FactorValues::Single(l) => Some(l),
            FactorValues::Double(_) => None,
        }
    }

    /// The f64 values, if these are, borrowed.
    fn as_double(&self) -> Option<&[f64]> {
        match self {
            FactorValues::Double(l) => Some(l),
            FactorValues::Single(_) => None,
        }
    }

    /// The f32 values, if these are, borrowed.
    fn as_single(&self) -> Option<&[f32]> {
        match self {
            FactorValues::Single(l) => Some(l),
            FactorValues::Double(_) => None,
        }
    }
}

/// Whether an LU's pivots are all above 1e-12 of the largest (an empty matrix is regular).
fn is_regular(lu: &PartialPivLu<f64>) -> bool {
    let u = lu.U();
    let diagonal = (0..u.nrows()).map(|i| u[(i, i)].abs());
    let (small, large) = diagonal.fold((f64::INFINITY, 0.0f64), |(s, l), v| (s.min(v), l.max(v)));
    u.nrows() == 0 || small > 1e-12 * large
}

/// A load after the forward substitution (see [`InterfaceFactorization::condense`]).
pub struct Condensed {
    /// The forward-substituted, scaled and permuted load, block by block.
    y: Vec<Vec<f64>>,
    /// What the interface sees of the load: `f_I - K_Ir K_rr^{-1} f_r` (force, b values).
    pub load: Vec<f64>,
}

/// The dense interface system of one active set, factorized.
pub struct ActiveSet {
    active: Vec<bool>,
    /// Active rows, in order.
    rows: Vec<usize>,
    lu: PartialPivLu<f64>,
}

impl ActiveSet {
    /// The active set this system was built for.
    pub fn active(&self) -> &[bool] {
        &self.active
    }
}

/// Pivots of the scaled stiffness (unit diagonal) below this are replaced by
/// [`PIVOT_REPLACEMENT`]: only a body with a rigid mode contact does not control can
/// produce one (its problem is singular); GMRES then sees the difference.
const PIVOT_EPSILON: f64 = 1e-12;
const PIVOT_REPLACEMENT: f64 = 1e-6;

impl Block {
    /// The block of equations `range` of `pattern`, with its equations on the interface
    /// (`on_interface`, global) last: the interior in the order of [`ordering::order`]
    /// (METIS's nested dissection of the nodes, or AMD for a small block), then the
    /// interface.
    fn new(
        pattern: &Pattern,
        range: std::ops::Range<usize>,
        on_interface: &[bool],
    ) -> Result<Self> {
        let (first, n) = (range.start, range.len());
        let (block, entries) = pieces::time("setup.block", first, || pattern.block(&range));
        let local_interface = &on_interface[range.clone()];
        let order = pieces::time("setup.order", first, || {
            ordering::order(&block, local_interface, None, first)
        })?;
        let interface: Vec<usize> = (0..n).filter(|&e| local_interface[e]).collect();
        let Pattern {
            col_ptr, row_idx, ..
        } = block;
        let mut position = vec![0usize; n];
        for (p, &e) in order.iter().enumerate() {
            position[e] = p;
        }
        let diagonal: Vec<usize> = (0..n)
            .map(|e| {
                let rows = &row_idx[col_ptr[e]..col_ptr[e + 1]];
                col_ptr[e] + rows.binary_search(&e).expect("diagonal entry in pattern")
            })
            .collect();
        let block_pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        let perm = PermRef::new_checked(&order, &position, n);
        let symbolic = pieces::time("setup.symbolic", first, || {
            factorize_symbolic_cholesky(
                block_pattern.as_ref(),
                Side::Lower,
                SymmetricOrdering::Custom(perm),
                CholeskySymbolicParams {
                    supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                    ..Default::default()
                },
            )
        })
        .map_err(|e| Error::NotConverged(format!("symbolic LDLT failed: {e:?}")))?;
        let begin = match symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(s) => {
                let mut begin = s.supernode_begin().to_vec();
                begin.push(n);
                begin
            }
            SymbolicCholeskyRaw::Simplicial(_) => unreachable!("supernodal forced above"),
        };
        Ok(Block {
            first,
            n,
            entries,
            interface,
            position,
            symbolic,
            begin,
            pattern: block_pattern,
            diagonal,
            numeric: None,
        })
    }

    fn supernodal(&self) -> &SymbolicSupernodalCholesky<usize> {
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(s) => s,
            SymbolicCholeskyRaw::Simplicial(_) => unreachable!("supernodal forced in new"),
        }
    }

    /// Factorize the block whose lower-triangle values are `values` (read only: the
    /// shifted and scaled values are a copy in `precision`) and return its Schur
    /// complement onto its interface (see [`InterfaceFactorization::factor`]).
    fn factor(&mut self, values: &[f64], shift: f64, precision: Precision) -> Result<Mat<f64>> {
        let t = Instant::now();
        let mut diagonal: Vec<f64> = self.diagonal.iter().map(|&s| values[s]).collect();
        for &e in &self.interface {
            diagonal[e] += shift;
        }
        let scaling: Vec<f64> = (diagonal.iter())
            .map(|&d| if d > 0.0 { 1.0 / d.sqrt() } else { 1.0 })
            .collect();
        // The factor's storage of the last factorization is reused (same pattern).
        let previous = self.numeric.take().map(|f| f.values);
        let (l, (l_interface, d_interface, inverse_diagonal)) = match precision {
            Precision::Double => {
                let l = previous.and_then(FactorValues::double).unwrap_or_default();
                let (l, parts) = self.numeric_from(l, values, &diagonal, &scaling, t)?;
                (FactorValues::Double(l), parts)
            }
            Precision::Single => {
                let l = previous.and_then(FactorValues::single).unwrap_or_default();
                let (l, parts) = self.numeric_from(l, values, &diagonal, &scaling, t)?;
                (FactorValues::Single(l), parts)
            }
        };
        let t = Instant::now();
        // S = W_I^{-1} L D L^T W_I^{-1} - sigma I.
        let b = self.interface.len();
        let w: Vec<f64> = self.interface.iter().map(|&e| scaling[e]).collect();
        let ld = Mat::from_fn(b, b, |i, j| l_interface[(i, j)] * d_interface[j]);
        let mut ldl = Mat::zeros(b, b);
        faer::linalg::matmul::matmul(
            ldl.as_mut(),
            Accum::Replace,
            ld.as_ref(),
            l_interface.transpose(),
            1.0,
            Par::Seq,
        );
        let schur = Mat::from_fn(b, b, |i, j| {
            let s = 0.5 * (ldl[(i, j)] + ldl[(j, i)]) / (w[i] * w[j]);
            if i == j { s - shift } else { s }
        });
        pieces::record("factor.schur", self.first, t.elapsed().as_secs_f64());
        self.numeric = Some(Numeric {
            inverse_diagonal,
            values: l,
            scaling,
            l_interface,
            d_interface,
        });
        Ok(schur)
    }

    /// The scaled values in the precision of `T` ([`Block::scaled`]) and their LDL^T
    /// into `l` ([`Block::numeric_ldlt`]); `t` started the scaling's clock.
    #[allow(clippy::type_complexity)]
    fn numeric_from<T: Value>(
        &self,
        mut l: Vec<T>,
        values: &[f64],
        diagonal: &[f64],
        scaling: &[f64],
        t: Instant,
    ) -> Result<(Vec<T>, (Mat<f64>, Vec<f64>, Vec<f64>))> {
        let scaled = self.scaled(values, diagonal, scaling);
        pieces::record("factor.scale", self.first, t.elapsed().as_secs_f64());
        let parts = self.numeric_ldlt(&mut l, &scaled)?;
        Ok((l, parts))
    }

    /// W (K + sigma P^T P) W in the precision of `T` (pattern order): the block's values
    /// `values` with the shifted `diagonal`, scaled by `scaling` (W).
    fn scaled<T: Value>(&self, values: &[f64], diagonal: &[f64], scaling: &[f64]) -> Vec<T> {
        let pattern = self.pattern.as_ref();
        let mut scaled = Vec::with_capacity(values.len());
        for j in 0..self.n {
            let start = pattern.col_ptr()[j];
            let diagonal_slot = self.diagonal[j];
            scaled.extend(pattern.row_idx_of_col(j).enumerate().map(|(s, i)| {
                let v = match start + s == diagonal_slot {
                    true => diagonal[j],
                    false => values[start + s],
                };
                T::from_f64(v * (scaling[i] * scaling[j]))
            }));
        }
        scaled
    }

    /// The numeric LDL^T of the block's scaled values `values` (pattern order) into `l`
    /// (resized to the factor), in the precision of `T`: the trailing interface blocks of
    /// L and D and 1 / D (elimination order), in f64.
    fn numeric_ldlt<T: Value>(
        &self,
        l: &mut Vec<T>,
        values: &[T],
    ) -> Result<(Mat<f64>, Vec<f64>, Vec<f64>)> {
        let t = Instant::now();
        l.resize(self.symbolic.len_val(), T::from_f64(0.0));
        let mut buffer = MemBuffer::try_new(
            self.symbolic
                .factorize_numeric_ldlt_scratch::<T>(Par::Seq, Default::default()),
        )
        .map_err(|_| Error::NotConverged("out of memory in the LDLT".into()))?;
        let signs = vec![1i8; self.n];
        pieces::record("factor.allocate", self.first, t.elapsed().as_secs_f64());
        let t = Instant::now();
        self.symbolic
            .factorize_numeric_ldlt(
                l,
                SparseColMatRef::new(self.pattern.as_ref(), values),
                Side::Lower,
                LdltRegularization {
                    dynamic_regularization_signs: Some(&signs),
                    dynamic_regularization_delta: T::from_f64(PIVOT_REPLACEMENT),
                    dynamic_regularization_epsilon: T::from_f64(PIVOT_EPSILON),
                },
                Par::Seq,
                MemStack::new(&mut buffer),
                Default::default(),
            )
            .map_err(|e| Error::NotConverged(format!("LDLT failed: {e:?}")))?;
        pieces::record("factor.numeric", self.first, t.elapsed().as_secs_f64());
        let (l_interface, d_interface) = self.trailing_block(l);
        let t = Instant::now();
        let mut inverse_diagonal = vec![0.0; self.n];
        let structure = self.structure();
        for s in 0..structure.n_supernodes() {
            let (start, width, pattern, values) = structure.supernode(l, s);
            let rows = width + pattern.len();
            for j in 0..width {
                inverse_diagonal[start + j] = 1.0 / values[j * rows + j].get();
            }
        }
        pieces::record(
            "factor.inverse_diagonal",
            self.first,
            t.elapsed().as_secs_f64(),
        );
        Ok((l_interface, d_interface, inverse_diagonal))
    }

    /// The trailing b x b blocks of L (unit lower triangular) and D, read from the
    /// supernodes that hold the last b columns.
    fn trailing_block<T: Value>(&self, l_values: &[T]) -> (Mat<f64>, Vec<f64>) {
        let b = self.interface.len();
        let first = self.n - b;
        let mut l = Mat::zeros(b, b);
        let mut d = vec![0.0; b];
        let sym = self.supernodal();
        let factor = SupernodalLdltRef::new(sym, l_values);
        for s in 0..sym.n_supernodes() {
            let node = factor.supernode(s);
            let (start, values) = (node.start(), node.val());
            let size = values.ncols();
            if start + size <= first {
                continue;
            }
            for jj in 0..size {
                let j = start + jj;
                if j < first {
                    continue;
                }
                let col = j - first;
                d[col] = values[(jj, jj)].get();
                l[(col, col)] = 1.0;
                for ii in jj + 1..size {
                    l[(start + ii - first, col)] = values[(ii, jj)].get();
                }
                for (k, &i) in node.pattern().iter().enumerate() {
                    l[(i - first, col)] = values[(size + k, jj)].get();
                }
            }
        }
        (l, d)
    }

    /// The block's load `f` (local equations) scaled by W and in elimination order: the
    /// vector the forward substitution starts from.
    fn permuted(&self, f: &[f64]) -> Vec<f64> {
        let numeric = self.numeric.as_ref().expect("factor before solve");
        let mut y = vec![0.0; self.n];
        for (e, &p) in self.position.iter().enumerate() {
            y[p] = numeric.scaling[e] * f[e];
        }
        y
    }

    /// What the block's interface sees of the load, from its forward substitution `y`: the
    /// condensed load W_I^{-1} L_II y_I.
    fn interface_load(&self, y: &[f64]) -> Vec<f64> {
        let numeric = self.numeric.as_ref().expect("factor before solve");
        let (n, b) = (self.n, self.interface.len());
        let first = n - b;
        let mut load = vec![0.0; b];
        for j in 0..b {
            let yj = y[first + j];
            if yj != 0.0 {
                for i in j..b {
                    load[i] += numeric.l_interface[(i, j)] * yj;
                }
            }
        }
        for (i, &e) in self.interface.iter().enumerate() {
            load[i] /= numeric.scaling[e];
        }
        load
    }

    /// The vector the back substitution starts from: the forward substitution `y` with the
    /// trailing values that lead to the interface values `x_interface` (D L_II^T W_I^{-1}
    /// x_I), all times D^{-1}.
    fn before_back(&self, mut y: Vec<f64>, x_interface: &[f64]) -> Vec<f64> {
        let numeric = self.numeric.as_ref().expect("factor before solve");
        let (n, b) = (self.n, self.interface.len());
        let first = n - b;
        let scaled: Vec<f64> = (0..b)
            .map(|i| x_interface[i] / numeric.scaling[self.interface[i]])
            .collect();
        for j in 0..b {
            let s: f64 = (j..b)
                .map(|i| numeric.l_interface[(i, j)] * scaled[i])
                .sum();
            y[first + j] = numeric.d_interface[j] * s;
        }
        for (yi, d) in y.iter_mut().zip(&numeric.inverse_diagonal) {
            *yi *= d;
        }
        y
    }

    /// The block's displacement (local equations) from its back substitution `y`.
    fn unpermuted(&self, y: &[f64]) -> Vec<f64> {
        let numeric = self.numeric.as_ref().expect("factor before solve");
        let mut x = vec![0.0; self.n];
        for (e, &p) in self.position.iter().enumerate() {
            x[e] = numeric.scaling[e] * y[p];
        }
        x
    }

    /// The factor's supernodal structure.
    fn structure(&self) -> Structure<'_> {
        let sym = self.supernodal();
        Structure {
            begin: &self.begin,
            row_ptr: sym.col_ptr_for_row_idx(),
            rows: sym.row_idx(),
            val_ptr: sym.col_ptr_for_val(),
        }
    }
}

impl InterfaceFactorization {
    /// The fill of the blocks' factors (interface rows included), summed over the blocks
    /// ([`ordering::supernodal_entries`]).
    pub fn factor_entries(&self) -> usize {
        self.blocks
            .iter()
            .map(|b| ordering::supernodal_entries(b.supernodal()))
            .sum()
    }

    /// The flops of one numeric factorization of the blocks (a multiply-add counts 2), summed
    /// ([`ordering::flops`]).
    pub fn factor_flops(&self) -> f64 {
        self.blocks
            .iter()
            .map(|b| ordering::flops(b.supernodal()))
            .sum()
    }

    /// Order the stiffness with pattern `pattern` (n x n, both triangles) with the interface
    /// of `rows` (contact rows as (equation, coefficient)) last in each of its diagonal
    /// blocks, and analyze the blocks (on rayon's threads).
    pub fn new(pattern: &Pattern, rows: &[Vec<(usize, f64)>]) -> Result<Self> {
        let t = Instant::now();
        let n = pattern.n;
        let mut on_interface = vec![false; n];
        for row in rows {
            for &(eq, _) in row {
                on_interface[eq] = true;
            }
        }
        let blocks: Vec<Block> = ordering::largest_first(pattern.diagonal_blocks(), |range| {
            Block::new(pattern, range, &on_interface)
        })?;
        let interface: Vec<usize> = blocks
            .iter()
            .flat_map(|b| b.interface.iter().map(move |&e| b.first + e))
            .collect();
        let structures: Vec<Structure> = blocks.iter().map(Block::structure).collect();
        let splits = pieces::time("setup.split", 0, || substitution::split(&structures));
        let mut local = vec![usize::MAX; n];
        for (l, &e) in interface.iter().enumerate() {
            local[e] = l;
        }
        let interface_rows: Vec<InterfaceRow> = rows
            .iter()
            .map(|r| r.iter().map(|&(eq, v)| (local[eq], eq, v)).collect())
            .collect();
        let row_scale = rows
            .iter()
            .map(|r| {
                let norm = r.iter().map(|&(_, v)| v * v).sum::<f64>().sqrt();
                if norm > 0.0 { 1.0 / norm } else { 1.0 }
            })
            .collect();
        Ok(InterfaceFactorization {
            n,
            interface,
            rows: interface_rows,
            row_scale,
            blocks,
            splits,
            schur: None,
            factor_s: Cell::new(0.0),
            symbolic_s: t.elapsed().as_secs_f64(),
            factorizations: 0,
            solves: Cell::new(0),
        })
    }

    /// Factorize the symmetric positive (semi)definite stiffness whose lower triangle is
    /// `values` (pattern order; read only). `shift` is sigma, the stiffness scale
    /// (force/length) added on the interface diagonal. The blocks are factorized on
    /// rayon's threads.
    ///
    /// In [`Precision::Single`] (newton's): the scaled stiffness is rounded to f32 and
    /// faer's LDL^T runs in f32; the interface's dense blocks stay in f64, and the
    /// substitutions run in f32 below the tops of the elimination trees and in f64 in the
    /// tops ([`substitution`]'s arithmetic). The factorization moves half the bytes and
    /// runs twice the SIMD lanes, a substitution reads half the bytes (measured on
    /// `rates-elastic` at 549,376 dofs: the factorization 0.88 s against 1.37 s in f64,
    /// the run 2.64 s against 3.06 s). A solve is then exact for a matrix within about 1e-7 cond(K) of K
    /// (8.5e-6 of the right-hand side at level 1 of `rates`), and newton's GMRES and Newton
    /// iterations take the system to its tolerance: on `rates-elastic` at 137,472 dofs, 4
    /// steps, 6 preconditioner applications and 5 iterations against 4 and 4 in f64; on
    /// `rates`, 29 and 11 against 28 and 11.
    pub fn factor(&mut self, values: &[f64], shift: f64, precision: Precision) -> Result<()> {
        let t = Instant::now();
        let schurs: Vec<Mat<f64>> = self
            .blocks
            .par_iter_mut()
            .map(|block| block.factor(&values[block.entries.clone()], shift, precision))
            .collect::<Result<_>>()?;
        let b = self.interface.len();
        let mut schur = Mat::zeros(b, b);
        let mut offset = 0;
        for s in &schurs {
            for j in 0..s.ncols() {
                for i in 0..s.nrows() {
                    schur[(offset + i, offset + j)] = s[(i, j)];
                }
            }
            offset += s.nrows();
        }
        self.schur = Some(schur);
        pieces::record("factor.total", 0, t.elapsed().as_secs_f64());
        self.factorizations += 1;
        self.factor_s
            .set(self.factor_s.get() + t.elapsed().as_secs_f64());
        Ok(())
    }

    /// Factorize the dense interface system of the active set `active` (c: the scale of
    /// the contact rows, force/length).
    pub fn active_set(&mut self, active: &[bool], c: f64) -> Result<ActiveSet> {
        let t = Instant::now();
        let rows: Vec<usize> = (0..active.len()).filter(|&i| active[i]).collect();
        let mut lu = self.saddle_point_lu(&rows, c, 0.0);
        if !is_regular(&lu) {
            // The active rows do not hold a body held only by contact (an intermediate
            // active set of the semismooth search): its rigid mode gets a small stiffness,
            // 1e-8 of the stiffness scale, for this active set (GMRES corrects the
            // difference, the line search the size of the step).
            lu = self.saddle_point_lu(&rows, c, 1e-8 * c);
        }
        self.factor_s
            .set(self.factor_s.get() + t.elapsed().as_secs_f64());
        pieces::record("active_set.lu", 0, t.elapsed().as_secs_f64());
        Ok(ActiveSet {
            active: active.to_vec(),
            rows,
            lu,
        })
    }

    /// LU of the saddle-point matrix `[S + r I, c C_A^T s; s c C_A, 0]` of the rows `rows`
    /// (s: the rows' scales, r: the regularization).
    fn saddle_point_lu(&self, rows: &[usize], c: f64, regularization: f64) -> PartialPivLu<f64> {
        let schur = self.schur.as_ref().expect("factor before active_set");
        let b = self.interface.len();
        let size = b + rows.len();
        let mut a = Mat::<f64>::zeros(size, size);
        for j in 0..b {
            for i in 0..b {
                a[(i, j)] = schur[(i, j)];
            }
            a[(j, j)] += regularization;
        }
        for (k, &r) in rows.iter().enumerate() {
            let scale = c * self.row_scale[r];
            for &(l, _, v) in &self.rows[r] {
                a[(b + k, l)] += scale * v;
                a[(l, b + k)] += scale * v;
            }
        }
        a.partial_piv_lu()
    }

    /// Solve the Newton system of `set` in place: `v` = [f (n); g (m)] in, [x; y] out (see
    /// the module; y is the multiplier step divided by c).
    pub fn solve(&self, set: &ActiveSet, c: f64, v: &mut [f64]) {
        let n = self.n;
        let (f, g) = v.split_at_mut(n);
        let condensed = pieces::time("solve.forward", 0, || self.condense(f));
        let (x_interface, y) = pieces::time("solve.interface", 0, || {
            self.interface_solve(set, c, &condensed.load, g)
        });
        g.copy_from_slice(&y);
        let x = pieces::time("solve.back", 0, || self.expand(condensed, &x_interface));
        f.copy_from_slice(&x);
    }

    /// Forward substitution of the load `f` (n): what the interface sees of it (the
    /// subtrees, then the blocks' tops, on rayon's threads: see [`substitution`]).
    pub fn condense(&self, f: &[f64]) -> Condensed {
        self.solves.set(self.solves.get() + 1);
        let mut y: Vec<Vec<f64>> = self
            .blocks
            .par_iter()
            .map(|b| b.permuted(&f[b.first..b.first + b.n]))
            .collect();
        match self.values() {
            Values::Single(v) => self.forward(&v, &mut y),
            Values::Double(v) => self.forward(&v, &mut y),
        }
        let load = (self.blocks.iter().zip(&y))
            .flat_map(|(b, yb)| b.interface_load(yb))
            .collect();
        Condensed { y, load }
    }

    /// The blocks' factor values, all in one precision.
    fn values(&self) -> Values<'_> {
        let numeric = || {
            self.blocks
                .iter()
                .map(|b| &b.numeric.as_ref().expect("factored").values)
        };
        match numeric().map(FactorValues::as_single).collect() {
            Some(single) => Values::Single(single),
            None => Values::Double(
                numeric()
                    .map(|v| v.as_double().expect("one precision per factorization"))
                    .collect(),
            ),
        }
    }

    /// y <- L^{-1} y, block by block (`y`: the blocks' vectors in elimination order), the
    /// subtrees in the factor's own precision ([`substitution::forward_blocks`]).
    fn forward<T: Lift<T>>(&self, values: &[&[T]], y: &mut [Vec<f64>]) {
        let structures: Vec<Structure> = self.blocks.iter().map(Block::structure).collect();
        substitution::forward_blocks(&self.splits, &structures, values, y);
    }

    /// y <- L^{-T} y, block by block, as [`InterfaceFactorization::forward`].
    fn back<T: Lift<T>>(&self, values: &[&[T]], y: &mut [Vec<f64>]) {
        let structures: Vec<Structure> = self.blocks.iter().map(Block::structure).collect();
        substitution::back_blocks(&self.splits, &structures, values, y);
    }

    /// The interface part of the Newton system of `set` (see the module): the interface
    /// unknowns x_I (b) and every row's y (m), from the condensed load `load` (b, see
    /// [`Condensed`]) and the rows' right-hand sides `g` (m). An inactive row's y is
    /// g_i / c and its column moves to the right-hand side, on the interface only (where
    /// the condensed load equals the load); the rest is the saddle-point system
    /// `[S c C_A^T; c C_A 0] [x_I; y_A] = [load; g_A]`.
    pub fn interface_solve(
        &self,
        set: &ActiveSet,
        c: f64,
        load: &[f64],
        g: &[f64],
    ) -> (Vec<f64>, Vec<f64>) {
        let b = self.interface.len();
        let mut rhs = Mat::<f64>::zeros(b + set.rows.len(), 1);
        for (i, &l) in load.iter().enumerate() {
            rhs[(i, 0)] = l;
        }
        let mut y: Vec<f64> = g.iter().map(|gi| gi / c).collect();
        for (i, row) in self.rows.iter().enumerate() {
            if !set.active[i] {
                for &(l, _, coef) in row {
                    rhs[(l, 0)] -= coef * g[i];
                }
            }
        }
        for (k, &r) in set.rows.iter().enumerate() {
            rhs[(b + k, 0)] = self.row_scale[r] * g[r];
        }
        set.lu.solve_in_place_with_conj(Conj::No, rhs.as_mut());
        for (k, &r) in set.rows.iter().enumerate() {
            y[r] = self.row_scale[r] * rhs[(b + k, 0)];
        }
        ((0..b).map(|i| rhs[(i, 0)]).collect(), y)
    }

    /// The displacement (n) whose interface values are `x_interface`, from the forward
    /// substitution `condensed`: per block, the trailing values that lead to x_I, D L_II^T
    /// W_I^{-1} x_I, then the back substitution (on rayon's threads, as the forward one).
    pub fn expand(&self, condensed: Condensed, x_interface: &[f64]) -> Vec<f64> {
        let mut offsets = Vec::with_capacity(self.blocks.len());
        let mut offset = 0;
        for b in &self.blocks {
            offsets.push(offset);
            offset += b.interface.len();
        }
        let mut y: Vec<Vec<f64>> = (self.blocks.par_iter().zip(condensed.y).zip(offsets))
            .map(|((b, y), o)| b.before_back(y, &x_interface[o..o + b.interface.len()]))
            .collect();
        match self.values() {
            Values::Single(v) => self.back(&v, &mut y),
            Values::Double(v) => self.back(&v, &mut y),
        }
        let parts: Vec<Vec<f64>> = (self.blocks.par_iter().zip(&y))
            .map(|(b, yb)| b.unpermuted(yb))
            .collect();
        parts.concat()
    }

    /// C_i x restricted to the interface (`x_interface`: b values).
    pub fn row_product(&self, i: usize, x_interface: &[f64]) -> f64 {
        self.rows[i]
            .iter()
            .map(|&(l, _, v)| v * x_interface[l])
            .sum()
    }
}
