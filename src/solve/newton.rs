//! The default solver: exact implicit return map per triangle, consistent tangent, and a
//! semismooth Newton (primal-dual active set) treatment of the contact rows, on the KKT
//! system `[K C^T; C_A 0]` whose pattern (all rows present) and symbolic analysis are fixed
//! per mesh. One factorization serves many iterations and steps: each Newton system is
//! solved by GMRES preconditioned with the last factorization, corrected exactly (Woodbury)
//! for the contact rows whose active set changed since; it is refactorized only when GMRES
//! needs many iterations (the tangent moved far from the factored one).
//!
//! The factorization is symmetric: an LDL^T of `[K_s c C_A^T; c C_A 0]` (K_s the stiffness,
//! or the symmetric part of the consistent tangent; inactive rows eliminated exactly, see
//! [`Newton::solve_factored`]), ordered by AMD with every multiplier moved after its
//! displacements, so that its pivot is a non-zero Schur complement. It costs about one
//! Cholesky of the stiffness (the KKT matrix's sparse LU cost 3-7x that) and is exact for
//! elastic bodies: GMRES then stops after one iteration. The non-symmetric part of a
//! viscoplastic tangent is left to GMRES (2-3 iterations per Newton step, measured).

use super::linear::SparseSystem;
use super::{Problem, Settings, State, StepReport, StepSolver, inf_norm};
use super::{Timings, timed};
use crate::contact;
use crate::error::{Error, Result};
use crate::fe::{FIXED, Pattern};
use crate::material::Stress;
use nalgebra::Matrix3;
use std::cell::Cell;

/// Newton solver state (pattern, slots, factorization) for one problem.
pub struct Newton<'a> {
    p: &'a Problem,
    settings: Settings,
    n: usize,
    slots: Vec<[usize; 36]>,
    /// Per row: (slot in row n+i, slot in column n+i) for each free entry, and the free eq.
    row_slots: Vec<Vec<(usize, usize, usize, f64)>>,
    diag_slots: Vec<usize>,
    system: SparseSystem,
    /// The factorization is too old to precondition well: refactor at the next iteration.
    stale: bool,

    /// Scale turning gaps into forces in the complementarity function (force/length).
    c_scale: f64,
    clock: std::rc::Rc<Clock>,
    /// Seconds building the pattern, slot maps and symbolic analysis (once per mesh).
    setup_s: f64,
    /// Active set of the factored matrix.
    factored_active: Vec<bool>,
    /// The elastic stiffness in pattern order (contact entries zero).
    elastic_values: Vec<f64>,
    /// Columns A0^{-1} e_{n+i} of the factored matrix, computed when row i changes.
    w_columns: Vec<Option<Vec<f64>>>,
    /// Lower triangle of the symmetric matrix handed to the LDL^T (pattern order).
    symmetric_values: Vec<f64>,
    /// Expected pivot signs: +1 on displacement rows, -1 on multiplier rows.
    signs: Vec<i8>,
    /// Scale s_i = 1/|C_i| of multiplier row i in the factored matrix (1/length for mortar
    /// rows, 1 for node-on-segment ones): every factored contact row has the norm c.
    row_scale: Vec<f64>,
    /// GMRES iterations of the first solve after the last factorization.
    fresh_iterations: usize,
}

/// Pivots of the scaled matrix (unit diagonal) expected positive but below 1e-8 are
/// replaced by 1e-6: a body held only by contact and eliminated before its contact rows
/// leaves a round-off pivot for its rigid mode, and the replacement is a low-rank change
/// GMRES removes. Measured on `rates` at 4.5e5 dofs (upper block held vertically only by
/// contact): a threshold of 1e-13 c on the unscaled matrix missed that pivot (GMRES 4-6
/// iterations per Newton step instead of 1-2, 16 s instead of 12 s), 1e-9 c caught it.
const PIVOT_THRESHOLD: (f64, f64) = (1e-8, 1e-6);

/// The tangent whose element stiffness is the symmetric part of that of `d`: the element
/// stiffness is |T| B^T D S B (S halves the engineering shear), so the symmetric part of
/// D S is taken and S undone. Where that is not positive definite (a strongly
/// non-symmetric tangent), the elastic tangent `elastic`: the factored stiffness stays
/// positive definite, and GMRES handles the difference.
fn symmetric_tangent(d: &Matrix3<f64>, elastic: &Matrix3<f64>) -> Matrix3<f64> {
    if d == elastic {
        return *d;
    }
    let s = Matrix3::from_diagonal(&nalgebra::Vector3::new(1.0, 1.0, 0.5));
    let ds = d * s;
    let sym = 0.5 * (ds + ds.transpose());
    let scale = (elastic * s).norm();
    if sym.symmetric_eigenvalues().min() > 1e-8 * scale {
        let s_inv = Matrix3::from_diagonal(&nalgebra::Vector3::new(1.0, 1.0, 2.0));
        sym * s_inv
    } else {
        *elastic
    }
}

/// Iterates whose merit the non-monotone line search remembers.
const MERIT_MEMORY: usize = 3;

/// GMRES iterations allowed right after a symmetric factorization (the non-symmetric part
/// of a viscoplastic tangent is all that is left for it); beyond, the LU of the Newton
/// matrix is used.
const FRESH_BUDGET: usize = 20;

/// Accumulated times of the solver's parts.
#[derive(Default)]
struct Clock {
    assembly: Cell<f64>,
    solve: Cell<f64>,
    constitutive: Cell<f64>,
    contact: Cell<f64>,
}

/// Write the contact rows and columns of the KKT values: column n+i holds c C_i^T; row n+i
/// holds c C_i and 0 on the diagonal when row i is active, 0 and c when it is inactive.
/// The multiplier unknowns are lambda / c and the contact rows are scaled by c, so every
/// entry has the size of the stiffness in any units: unscaled, an LU of [K C^T; C 0] in
/// lengths x 1e3, moduli x 1e6 solved to 1e-9 only.
fn fill_contact_rows(
    vals: &mut [f64],
    row_slots: &[Vec<(usize, usize, usize, f64)>],
    diag_slots: &[usize],
    c: f64,
    active: &[bool],
) {
    for (i, row) in row_slots.iter().enumerate() {
        for &(rs, cs, _, v) in row {
            vals[cs] = c * v;
            vals[rs] = if active[i] { c * v } else { 0.0 };
        }
        vals[diag_slots[i]] = if active[i] { 0.0 } else { c };
    }
}

/// Shift added to the stiffness diagonal for the floor's Cholesky, relative to its mean
/// diagonal: it makes the stiffness of a body held only by contact positive definite and
/// changes nothing the floor measures (its cost).
pub const FLOOR_SHIFT: f64 = 1e-8;

/// See [`super::floor_time`].
pub fn floor_time(p: &Problem, steps: usize) -> Result<f64> {
    let t0 = std::time::Instant::now();
    let model = &p.model;
    let n = model.n_free;
    let (pattern, slots) = model.stiffness_pattern(&[], n);
    let mut system = SparseSystem::new(&pattern);
    let vals = system.values_mut();
    model.add_tangent(&model.elastic_tangents(), &slots, vals);
    let diagonal: Vec<usize> = (0..n).map(|i| pattern.slot(i, i)).collect();
    let shift = FLOOR_SHIFT * diagonal.iter().map(|&s| vals[s]).sum::<f64>() / n.max(1) as f64;
    for &s in &diagonal {
        vals[s] += shift;
    }
    system.factor_llt()?;
    let mut rhs = vec![1.0; n];
    for _ in 0..steps {
        system.solve(&mut rhs);
    }
    Ok(t0.elapsed().as_secs_f64())
}

impl<'a> Newton<'a> {
    /// Set up the KKT pattern and the symbolic analysis for `p`.
    pub fn new(p: &'a Problem, settings: &Settings) -> Result<Self> {
        let t_setup = std::time::Instant::now();
        let n = p.model.n_free;
        let m = p.rows.len();
        let mut extra = Vec::new();
        for (i, r) in p.rows.iter().enumerate() {
            for &(d, _) in &r.entries {
                let eq = p.model.equation[d];
                extra.push((n + i, eq));
                extra.push((eq, n + i));
            }
            extra.push((n + i, n + i));
        }
        let (pattern, slots): (Pattern, _) = p.model.stiffness_pattern(&extra, n + m);
        let row_slots = p
            .rows
            .iter()
            .enumerate()
            .map(|(i, r)| {
                r.entries
                    .iter()
                    .map(|&(d, v)| {
                        let eq = p.model.equation[d];
                        (pattern.slot(n + i, eq), pattern.slot(eq, n + i), eq, v)
                    })
                    .collect()
            })
            .collect();
        let diag_slots = (0..m).map(|i| pattern.slot(n + i, n + i)).collect();
        // Stiffness scale: the mean diagonal of the elastic stiffness.
        let mut diag = vec![0.0; n];
        let tangents = p.model.elastic_tangents();
        let mut vals = vec![0.0; pattern.nnz()];
        p.model.add_tangent(&tangents, &slots, &mut vals);
        for (i, d) in diag.iter_mut().enumerate() {
            *d = vals[pattern.slot(i, i)];
        }
        let c_scale = diag.iter().sum::<f64>() / n.max(1) as f64;
        let mut system = SparseSystem::new(&pattern);
        system.analyze_ldlt(n)?;
        let signs = (0..n + m).map(|i| if i < n { 1 } else { -1 }).collect();
        let row_scale = p
            .rows
            .iter()
            .map(|r| {
                let norm: f64 = r.entries.iter().map(|&(_, v)| v * v).sum::<f64>().sqrt();
                if norm > 0.0 { 1.0 / norm } else { 1.0 }
            })
            .collect();
        Ok(Newton {
            p,
            settings: *settings,
            n,
            slots,
            row_slots,
            diag_slots,
            system,
            stale: false,
            c_scale,
            clock: Default::default(),
            setup_s: t_setup.elapsed().as_secs_f64(),
            factored_active: vec![true; m],
            elastic_values: vals,
            w_columns: vec![None; m],
            symmetric_values: Vec::new(),
            signs,
            row_scale,
            fresh_iterations: 0,
        })
    }
}

/// An exact correction of the last factorization for the contact rows whose active or
/// inactive form changed since it was computed (Sherman-Morrison-Woodbury on replaced rows):
/// with A0 the factored KKT matrix and A = A0 + E_R D_R^T (rows n+i, i in R, replaced),
/// A^{-1} = A0^{-1} - W (I + D_R^T W)^{-1} D_R^T A0^{-1}, W = A0^{-1} E_R. A change of the
/// active set then costs one blocked solve for the new columns of W and a small dense LU
/// instead of a sparse refactorization; GMRES is left with the tangent's changes only.
struct RowUpdate {
    /// Contact rows i in R.
    rows: Vec<usize>,
    /// Sign s_i: +1 when row i is active now and was inactive in A0, -1 the other way.
    signs: Vec<f64>,
    /// LU of the capacitance matrix I + D_R^T W (r x r).
    capacitance: Option<nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>>,
}

/// Largest number of new columns W_i = A0^{-1} e_{n+i} computed for one update before a
/// refactorization is preferred. Measured: at 1.1e5 dofs a blocked solve of 37 columns
/// took 0.23 s, one solve 0.03 s, one LDL^T 0.21-0.27 s; at 4.4e5 dofs 14 columns took
/// 0.52 s, one solve 0.14 s, one LDL^T 1.4-1.6 s. Counted in columns, not seconds, so that
/// the results do not depend on the machine's load.
const MAX_NEW_COLUMNS: usize = 32;

/// Largest number of stored entries of W before a refactorization is preferred: 2e8
/// doubles = 1.6 GB.
const MAX_CORRECTION_ENTRIES: usize = 200_000_000;

impl Newton<'_> {
    /// Difference row D_i = s_i c (C_i - e_{n+i}) applied to `y`.
    fn d_dot(&self, i: usize, sign: f64, y: &[f64]) -> f64 {
        let dot: f64 = self.row_slots[i]
            .iter()
            .map(|&(_, _, eq, v)| v * y[eq])
            .sum();
        sign * self.c_scale * (dot - y[self.n + i])
    }

    /// Make the columns W_i = A0^{-1} e_{n+i} of `rows` available (one blocked solve for
    /// those missing) and factor the capacitance matrix. None when a refactorization is
    /// cheaper ([`MAX_NEW_COLUMNS`]) or W would be too large.
    fn row_update(&mut self, active: &[bool]) -> Option<RowUpdate> {
        let big_n = self.n + self.p.rows.len();
        let rows: Vec<usize> = (0..active.len())
            .filter(|&i| active[i] != self.factored_active[i])
            .collect();
        let missing: Vec<usize> = rows
            .iter()
            .copied()
            .filter(|&i| self.w_columns[i].is_none())
            .collect();
        if missing.len() > MAX_NEW_COLUMNS || rows.len() * big_n > MAX_CORRECTION_ENTRIES {
            return None;
        }
        if !missing.is_empty() {
            let mut block = vec![0.0; big_n * missing.len()];
            for (j, &i) in missing.iter().enumerate() {
                block[j * big_n + self.n + i] = 1.0;
            }
            timed(&self.clock.solve, || {
                self.solve_factored(&mut block, missing.len())
            });
            for (j, &i) in missing.iter().enumerate() {
                self.w_columns[i] = Some(block[j * big_n..(j + 1) * big_n].to_vec());
            }
        }
        let signs: Vec<f64> = rows
            .iter()
            .map(|&i| if active[i] { 1.0 } else { -1.0 })
            .collect();
        let r = rows.len();
        let capacitance = (r > 0).then(|| {
            let cap = nalgebra::DMatrix::from_fn(r, r, |a, b| {
                let w = self.w_columns[rows[b]].as_ref().expect("computed above");
                (a == b) as u8 as f64 + self.d_dot(rows[a], signs[a], w)
            });
            cap.lu()
        });
        Some(RowUpdate {
            rows,
            signs,
            capacitance,
        })
    }

    /// Apply the corrected inverse of [`RowUpdate`] to `v` in place.
    fn precondition(&self, update: &RowUpdate, v: &mut [f64]) {
        self.solve_factored(v, 1);
        self.correct(update, v);
    }

    /// Factorize the symmetric counterpart of the Newton matrix with the symmetric part of
    /// `tangents` and the active set `active` (see the module's notes).
    fn factor(&mut self, tangents: &[Matrix3<f64>], active: &[bool]) -> Result<()> {
        let clock = std::rc::Rc::clone(&self.clock);
        let c = self.c_scale;
        let mut vals = std::mem::take(&mut self.symmetric_values);
        timed(&clock.assembly, || {
            vals.clear();
            vals.extend_from_slice(&self.elastic_values);
            let symmetric: Vec<Matrix3<f64>> = (self.p.model.elements.iter().zip(tangents))
                .map(|(e, d)| {
                    symmetric_tangent(d, &self.p.model.materials[e.body].elastic.matrix())
                })
                .collect();
            self.p
                .model
                .add_tangent_change(&symmetric, &self.slots, &mut vals);
            for (i, row) in self.row_slots.iter().enumerate() {
                let s = self.row_scale[i];
                for &(rs, _, _, v) in row {
                    vals[rs] = if active[i] { c * s * v } else { 0.0 };
                }
                vals[self.diag_slots[i]] = if active[i] { 0.0 } else { -c * s * s };
            }
        });
        let (eps, delta) = PIVOT_THRESHOLD;
        let result = self.system.factor_ldlt(&mut vals, &self.signs, eps, delta);
        self.symmetric_values = vals;
        result?;
        self.stale = false;
        self.factored_active = active.to_vec();
        self.w_columns.iter_mut().for_each(|w| *w = None);
        Ok(())
    }

    /// Solve with the factored Newton matrix A0 (`k` right-hand sides, column after column,
    /// in place). A0 has the columns c C_i^T of every row and, on an inactive row, c on the
    /// diagonal only: x_{n+i} = b_{n+i} / c is known, its columns move to the right-hand side,
    /// and the rest is the symmetric system the LDL^T factored (rows scaled by s_i).
    fn solve_factored(&self, v: &mut [f64], k: usize) {
        if self.system.is_lu() {
            // The LU is of A0 itself.
            self.system.solve_many(v, k);
            return;
        }
        let (n, m) = (self.n, self.p.rows.len());
        let big_n = n + m;
        for col in v.chunks_mut(big_n).take(k) {
            for i in 0..m {
                let b = col[n + i];
                if self.factored_active[i] {
                    col[n + i] = self.row_scale[i] * b;
                } else {
                    if b != 0.0 {
                        for &(_, _, eq, coef) in &self.row_slots[i] {
                            col[eq] -= coef * b;
                        }
                    }
                    col[n + i] = -self.row_scale[i] * b;
                }
            }
        }
        self.system.solve_many(v, k);
        for col in v.chunks_mut(big_n).take(k) {
            for i in 0..m {
                col[n + i] *= self.row_scale[i];
            }
        }
    }

    /// Turn `v = A0^{-1} b` into `A^{-1} b` (the Woodbury correction of [`RowUpdate`]).
    fn correct(&self, update: &RowUpdate, v: &mut [f64]) {
        if let Some(cap) = &update.capacitance {
            let z = nalgebra::DVector::from_iterator(
                update.rows.len(),
                update
                    .rows
                    .iter()
                    .zip(&update.signs)
                    .map(|(&i, &s)| self.d_dot(i, s, v)),
            );
            let t = cap
                .solve(&z)
                .unwrap_or_else(|| nalgebra::DVector::zeros(z.len()));
            for (b, &i) in update.rows.iter().enumerate() {
                let w = self.w_columns[i].as_ref().expect("computed in row_update");
                for (vj, wj) in v.iter_mut().zip(w) {
                    *vj -= t[b] * wj;
                }
            }
        }
    }
}

/// The residual of (2.1) with the return map at one iterate (u, lambda).
struct Evaluation {
    /// Stresses from the return map.
    sigma: Vec<Stress>,
    /// Consistent tangents per triangle.
    tangents: Vec<Matrix3<f64>>,
    /// Equilibrium residual f_int - F + C^T lambda over the free dofs (force).
    residual: Vec<f64>,
    /// Constraint values C u per row (length).
    gaps: Vec<f64>,
    /// Scale of the forces: the larger of |F| and |f_int| over the free dofs.
    scale: f64,
}

/// What one time step's iterations share.
struct StepData<'s> {
    prev: &'s State,
    k: f64,
    f_ext: Vec<f64>,
    f_free: Vec<f64>,
}

/// How far an iterate is from solving the step, relative to the force scale.
struct Distance {
    /// Equilibrium residual.
    residual: f64,
    /// Complementarity |min(lambda, -c g)|.
    complementarity: f64,
}

impl Newton<'_> {
    /// Return map, internal forces and constraint values at (u, lambda).
    fn evaluate(&self, data: &StepData, u: &[f64], lambda: &[f64]) -> Evaluation {
        let (model, clock) = (&self.p.model, &self.clock);
        let (sigma, tangents) = timed(&clock.constitutive, || {
            model.update_stresses(u, &data.prev.u, &data.prev.sigma, data.k, true)
        });
        let f_int = timed(&clock.assembly, || model.internal_force(&sigma));
        let mut r = f_int.clone();
        for (ri, f) in r.iter_mut().zip(&data.f_ext) {
            *ri -= f;
        }
        let gaps = timed(&clock.contact, || {
            contact::add_transpose(&self.p.rows, lambda, &mut r);
            contact::apply_rows(&self.p.rows, u)
        });
        let scale = inf_norm(&data.f_free)
            .max(inf_norm(&model.restrict(&f_int)))
            .max(f64::MIN_POSITIVE);
        Evaluation {
            sigma,
            tangents,
            residual: model.restrict(&r),
            gaps,
            scale,
        }
    }

    /// The line search's merit |r|^2 + |min(lambda, -c g)|^2.
    fn merit(&self, ev: &Evaluation, lambda: &[f64]) -> f64 {
        let c = self.c_scale;
        ev.residual.iter().map(|v| v * v).sum::<f64>()
            + (0..lambda.len())
                .map(|i| lambda[i].min(-c * ev.gaps[i]).powi(2))
                .sum::<f64>()
    }

    /// Write the KKT values of the current tangents and active set into the system: the
    /// elastic stiffness (assembled once) plus the viscoplastic triangles' changes, and
    /// the contact rows.
    fn assemble_kkt(&mut self, tangents: &[Matrix3<f64>], active: &[bool]) {
        let clock = std::rc::Rc::clone(&self.clock);
        timed(&clock.assembly, || {
            let vals = self.system.values_mut();
            vals.copy_from_slice(&self.elastic_values);
            self.p.model.add_tangent_change(tangents, &self.slots, vals);
            fill_contact_rows(
                vals,
                &self.row_slots,
                &self.diag_slots,
                self.c_scale,
                active,
            );
        });
    }

    /// Solve the Newton system in place (`rhs` in, step out). Every iteration is a full
    /// semismooth Newton step with the current consistent tangent and active set. Its
    /// linear system is solved by GMRES preconditioned with the last factorization (of an
    /// older matrix: the tangent changes little between iterations and steps), corrected
    /// exactly for the contact rows whose active set changed since; the matrix is
    /// refactorized only when GMRES needs many iterations. Returns whether it factorized.
    fn solve_newton_system(
        &mut self,
        rhs: &mut Vec<f64>,
        tangents: &[Matrix3<f64>],
        active: &[bool],
        distance: &Distance,
    ) -> Result<bool> {
        let clock = std::rc::Rc::clone(&self.clock);
        let reusable = self.system.is_factored() && !self.stale;
        // GMRES is worth it while its solves cost less than a fresh factorization (about
        // 10 solves here): cap it at 10 iterations and refactor next time when it used more
        // than 5 and more than the fresh factorization needed. The rule counts iterations,
        // not seconds, so the results do not depend on the machine's load.
        let budget = 10;
        if reusable {
            if let Some(update) = self.row_update(active) {
                let forcing = self.forcing_term(distance);
                let rhs0 = rhs.clone();
                let result = timed(&clock.solve, || {
                    self.system
                        .gmres(rhs, forcing, budget, &|v| self.precondition(&update, v))
                });
                if let Some(its) = result {
                    self.stale = 2 * its > budget && its > self.fresh_iterations + 1;
                    return Ok(false);
                }
                rhs.copy_from_slice(&rhs0);
            }
        }
        self.factor(tangents, active)?;
        let forcing = self.forcing_term(distance);
        let update = self
            .row_update(active)
            .expect("no row changed since the factorization");
        let rhs0 = rhs.clone();
        let fresh = timed(&clock.solve, || {
            self.system.gmres(rhs, forcing, FRESH_BUDGET, &|v| {
                self.precondition(&update, v)
            })
        });
        let its = match fresh {
            Some(its) => its,
            None => {
                // A tangent too far from symmetric (stiff viscosity, k E / lambda near 1e4):
                // the LU of the Newton matrix itself, exact, as before issue 14.
                rhs.copy_from_slice(&rhs0);
                self.system.factor_lu()?;
                timed(&clock.solve, || self.system.solve(rhs));
                0
            }
        };
        self.fresh_iterations = its;
        Ok(true)
    }

    /// Inexact Newton: the linear solve needs only to beat the equilibrium residual
    /// (forcing term min(1e-2, residual): quadratic convergence), and never more than the
    /// tolerance asks for (0.3 tol / the larger of residual and complementarity, for the
    /// last iteration of a step). While only the active set is searched (residual at
    /// round-off), the semismooth steps terminate finitely and want the solve to tolerance:
    /// a 1e-2 solve there left 4e-9 behind and cost one more iteration in other units.
    fn forcing_term(&self, distance: &Distance) -> f64 {
        let res = distance.residual;
        let tol_term = 0.3 * self.settings.tol / res.max(distance.complementarity);
        if tol_term > 1e-2 {
            // Within 30x of the tolerance: a loose solve ends it (the quadratic term is far
            // below the tolerance there).
            tol_term.min(0.5)
        } else {
            res.max(tol_term).min(1e-2)
        }
        .max(1e-12)
    }

    /// Backtracking along `step` on the merit |r|^2 + |min(lambda, -c g)|^2: full steps near
    /// the solution, shorter ones when a large step flips many triangles between elastic
    /// and viscoplastic (stiff k E / lambda) or many contact rows. Non-monotone (Grippo,
    /// Lampariello and Lucidi 1986): a trial is compared with `reference`, the largest merit
    /// of the step's last [`MERIT_MEMORY`] iterates, not the current one: the active-set
    /// steps raise the merit on their way (measured: monotone backtracking halved the first
    /// three steps of the first contact search, 10 iterations instead of 9 on a 4.4e5-dof
    /// elastic two-block case, 8 instead of 7 in the first step of `rates` level 5).
    /// Returns the best trial with its evaluation (the next iteration's residual).
    fn line_search(
        &self,
        data: &StepData,
        u: &[f64],
        lambda: &[f64],
        step: &[f64],
        reference: f64,
    ) -> (Vec<f64>, Vec<f64>, Evaluation) {
        let (n, c) = (self.n, self.c_scale);
        let trial = |alpha: f64| -> (Vec<f64>, Vec<f64>) {
            let mut ut = u.to_vec();
            for (d, &eq) in self.p.model.equation.iter().enumerate() {
                if eq != FIXED {
                    ut[d] += alpha * step[eq];
                }
            }
            let lt: Vec<f64> = (0..lambda.len())
                .map(|i| lambda[i] + alpha * c * step[n + i])
                .collect();
            (ut, lt)
        };
        let mut alpha = 1.0;
        let mut best: Option<(f64, (Vec<f64>, Vec<f64>), Evaluation)> = None;
        for _ in 0..12 {
            let (ut, lt) = trial(alpha);
            let ev = self.evaluate(data, &ut, &lt);
            let merit = self.merit(&ev, &lt);
            let done = merit <= (1.0 - 1e-4 * alpha) * reference;
            if best.as_ref().is_none_or(|b| merit < b.0) {
                best = Some((merit, (ut, lt), ev));
            }
            if done {
                break;
            }
            alpha *= 0.5;
        }
        let (_, (u, lambda), ev) = best.expect("at least one trial");
        (u, lambda, ev)
    }
}

impl StepSolver for Newton<'_> {
    fn step(&mut self, prev: &State, guess: &State, t: f64, k: f64) -> Result<(State, StepReport)> {
        let model = &self.p.model;
        let (n, m, c) = (self.n, self.p.rows.len(), self.c_scale);
        let f_ext = model.load(t)?;
        let data = StepData {
            prev,
            k,
            f_free: model.restrict(&f_ext),
            f_ext,
        };
        let mut u = guess.u.clone();
        let mut lambda = guess.lambda.clone();
        let mut last_active: Option<Vec<bool>> = None;
        let (mut changes, mut iterations, mut factorizations) = (0, 0, 0);
        let mut evaluation = self.evaluate(&data, &u, &lambda);
        let mut merits: Vec<f64> = Vec::new();
        loop {
            let ev = &evaluation;
            let active: Vec<bool> = (0..m).map(|i| lambda[i] + c * ev.gaps[i] >= 0.0).collect();
            let distance = Distance {
                residual: inf_norm(&ev.residual) / ev.scale,
                complementarity: super::complementarity(&lambda, &ev.gaps, c) / ev.scale,
            };
            let (res, compl) = (distance.residual, distance.complementarity);
            let same_set = last_active.as_ref().is_some_and(|a| *a == active);
            if let Some(a) = &last_active {
                changes += a.iter().zip(&active).filter(|(x, y)| x != y).count();
            }
            if iterations > 0 && res <= self.settings.tol && compl <= self.settings.tol && same_set
            {
                // Inactive rows carry no force; GMRES leaves round-off there.
                for i in 0..m {
                    if !active[i] {
                        lambda[i] = 0.0;
                    }
                }
                let reason = format!(
                    "residual {res:.2e} and complementarity {compl:.2e} below {:.0e}, active set settled ({factorizations} factorizations)",
                    self.settings.tol
                );
                let state = State {
                    time: t,
                    u,
                    sigma: evaluation.sigma,
                    lambda,
                };
                let report = StepReport {
                    iterations,
                    outer_iterations: iterations,
                    residual: res,
                    active_set_changes: changes,
                    reason,
                };
                return Ok((state, report));
            }
            if !res.is_finite() {
                return Err(Error::NotConverged(format!(
                    "Newton iterate became non-finite after {iterations} iterations"
                )));
            }
            if iterations >= self.settings.max_iterations {
                return Err(Error::NotConverged(format!(
                    "Newton reached {iterations} iterations with residual {res:.3e}, complementarity {compl:.3e} (tolerance {:.0e})",
                    self.settings.tol
                )));
            }
            merits.push(self.merit(ev, &lambda));
            let reference = merits
                .iter()
                .rev()
                .take(MERIT_MEMORY)
                .fold(0.0f64, |a, &b| a.max(b));
            let mut step: Vec<f64> = ev
                .residual
                .iter()
                .map(|v| -v)
                .chain((0..m).map(|i| {
                    if active[i] {
                        -c * ev.gaps[i]
                    } else {
                        -lambda[i]
                    }
                }))
                .collect();
            debug_assert_eq!(step.len(), n + m);
            self.assemble_kkt(&ev.tangents, &active);
            if self.solve_newton_system(&mut step, &ev.tangents, &active, &distance)? {
                factorizations += 1;
            }
            (u, lambda, evaluation) = self.line_search(&data, &u, &lambda, &step, reference);
            last_active = Some(active);
            iterations += 1;
        }
    }

    fn timings(&self) -> Timings {
        Timings {
            assembly_s: self.clock.assembly.get(),
            factor_s: self.system.factor_s,
            solve_s: self.clock.solve.get(),
            constitutive_s: self.clock.constitutive.get(),
            contact_s: self.clock.contact.get(),
            factorizations: self.system.factorizations,
            solves: self.system.solves.get(),
            setup_s: self.setup_s,
        }
    }
}
