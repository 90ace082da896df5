//! The default solver: exact implicit return map per triangle, consistent tangent, and a
//! semismooth Newton (primal-dual active set) treatment of the contact rows, on the KKT
//! system `[K C^T; C_A 0]` whose pattern (all rows present) and symbolic LU are fixed per
//! mesh. One factorization serves many iterations and steps: each Newton system is solved
//! by GMRES preconditioned with the last factorization, corrected exactly (Woodbury) for
//! the contact rows whose active set changed since; it is refactorized only when GMRES
//! needs many iterations (the tangent moved far from the factored one).

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
    /// Whether the factored matrix has the elastic stiffness.
    factored_elastic: bool,
    /// The elastic stiffness in pattern order (contact entries zero).
    elastic_values: Vec<f64>,
    /// Columns A0^{-1} e_{n+i} of the factored matrix, computed when row i changes.
    w_columns: Vec<Option<Vec<f64>>>,
}

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

/// See [`super::floor_time`].
pub fn floor_time(p: &Problem, steps: usize) -> Result<f64> {
    let mut nw = Newton::new(p, &super::Settings::default())?;
    let t0 = std::time::Instant::now();
    let tangents = p.model.elastic_tangents();
    let m = p.rows.len();
    let c = nw.c_scale;
    let vals = nw.system.values_mut();
    vals.iter_mut().for_each(|v| *v = 0.0);
    p.model.add_tangent(&tangents, &nw.slots, vals);
    fill_contact_rows(vals, &nw.row_slots, &nw.diag_slots, c, &vec![true; m]);
    nw.system.factor_lu()?;
    let mut rhs = vec![1.0; nw.n + m];
    for _ in 0..steps {
        nw.system.solve(&mut rhs);
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
        system.analyze_lu()?;
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
            factored_elastic: false,
            elastic_values: vals,
            w_columns: vec![None; m],
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

/// Largest number of stored entries of W (columns A0^{-1} e_{n+i}) before a refactorization
/// is preferred: 3e8 doubles = 2.4 GB (at 1.1e6 dofs, the 240 rows that change in the first
/// step; the LU there takes about 12 GB).
const MAX_CORRECTION_ENTRIES: usize = 300_000_000;

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
    /// those missing) and factor the capacitance matrix. None when W would be too large.
    fn row_update(&mut self, active: &[bool], all_columns: bool) -> Option<RowUpdate> {
        let big_n = self.n + self.p.rows.len();
        let rows: Vec<usize> = (0..active.len())
            .filter(|&i| active[i] != self.factored_active[i])
            .collect();
        let wanted: Vec<usize> = if all_columns {
            (0..active.len()).collect()
        } else {
            rows.clone()
        };
        if wanted.len() * big_n > MAX_CORRECTION_ENTRIES {
            return None;
        }
        let missing: Vec<usize> = wanted
            .iter()
            .copied()
            .filter(|&i| self.w_columns[i].is_none())
            .collect();
        if !missing.is_empty() {
            let mut block = vec![0.0; big_n * missing.len()];
            for (j, &i) in missing.iter().enumerate() {
                block[j * big_n + self.n + i] = 1.0;
            }
            timed(&self.clock.solve, || {
                self.system.solve_many(&mut block, missing.len())
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
        self.system.solve(v);
        self.correct(update, v);
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
        active: &[bool],
        elastic_now: bool,
        distance: &Distance,
    ) -> Result<bool> {
        let clock = std::rc::Rc::clone(&self.clock);
        let (n, m) = (self.n, self.p.rows.len());
        let reusable = self.system.is_factored() && !self.stale;
        // While only the active set is searched on an unchanged (elastic) stiffness, the
        // residual is at round-off and the right-hand side lives on the contact rows:
        // A0^{-1} b = W b_c with all columns W = A0^{-1} e_{n+i} (one blocked solve), and
        // the Woodbury correction makes it exact: no sparse solve per iteration.
        let exact =
            self.factored_elastic && elastic_now && distance.residual <= 1e-2 * self.settings.tol;
        if reusable && exact {
            if let Some(update) = self.row_update(active, true) {
                timed(&clock.solve, || {
                    let mut x = vec![0.0; n + m];
                    for i in 0..m {
                        let w = self.w_columns[i].as_ref().expect("all columns computed");
                        for (xj, wj) in x.iter_mut().zip(w) {
                            *xj += rhs[n + i] * wj;
                        }
                    }
                    self.correct(&update, &mut x);
                    *rhs = x;
                });
                return Ok(false);
            }
        }
        if reusable {
            if let Some(update) = self.row_update(active, false) {
                // GMRES is worth it while its solves cost less than a fresh factorization
                // (about 10-25 solves here, measured from 7e3 to 1e5 dofs): cap it at 10
                // iterations and refactor next time when it used more than 5. The rule
                // counts iterations, not seconds, so the results do not depend on the
                // machine's load.
                let budget = 10;
                let forcing = self.forcing_term(distance);
                let rhs0 = rhs.clone();
                let result = timed(&clock.solve, || {
                    self.system
                        .gmres(rhs, forcing, budget, &|v| self.precondition(&update, v))
                });
                if let Some(its) = result {
                    self.stale = 2 * its > budget;
                    return Ok(false);
                }
                rhs.copy_from_slice(&rhs0);
            }
        }
        self.system.factor_lu()?;
        self.stale = false;
        self.factored_elastic = elastic_now;
        self.factored_active = active.to_vec();
        self.w_columns.iter_mut().for_each(|w| *w = None);
        timed(&clock.solve, || self.system.solve(rhs));
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
    /// and viscoplastic (stiff k E / lambda) or many contact rows. Returns the best trial
    /// with its evaluation (the next iteration's residual).
    fn line_search(
        &self,
        data: &StepData,
        u: &[f64],
        lambda: &[f64],
        step: &[f64],
        merit0: f64,
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
            let done = merit <= (1.0 - 1e-4 * alpha) * merit0;
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
        loop {
            let ev = &evaluation;
            let active: Vec<bool> = (0..m).map(|i| lambda[i] + c * ev.gaps[i] >= 0.0).collect();
            let elastic_now = model
                .elements
                .iter()
                .zip(&ev.tangents)
                .all(|(e, d)| *d == model.materials[e.body].elastic.matrix());
            let distance = Distance {
                residual: inf_norm(&ev.residual) / ev.scale,
                complementarity: (0..m)
                    .map(|i| lambda[i].min(-c * ev.gaps[i]).abs())
                    .fold(0.0f64, f64::max)
                    / ev.scale,
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
            let merit0 = self.merit(ev, &lambda);
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
            if self.solve_newton_system(&mut step, &active, elastic_now, &distance)? {
                factorizations += 1;
            }
            (u, lambda, evaluation) = self.line_search(&data, &u, &lambda, &step, merit0);
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
