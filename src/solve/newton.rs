//! The default solver: exact implicit return map per triangle, consistent tangent, and a
//! semismooth Newton (primal-dual active set) treatment of the contact rows. Every Newton
//! system `[K_t c C^T; c C_A 0]` is solved by GMRES preconditioned with the exact solve of
//! `[K_s c C^T; c C_A 0]` for the current active set (see [`super::interface`]): K_s is the
//! stiffness or the symmetric part of an earlier consistent tangent, factorized once with
//! the contact interface's unknowns last, so that a change of the active set costs a dense
//! solve on the interface and never a sparse refactorization. The sparse matrix is
//! refactorized only when GMRES needs many iterations (the tangent moved far from the
//! factored one). The factorization is in single precision (see
//! [`InterfaceFactorization::factor`]): for elastic bodies K_s = K_t, a step is solved to
//! the tolerance in one iteration (`Newton::exact_forcing`), a step whose predictor
//! already meets the tolerance takes none, and the whole run factorizes the stiffness
//! once, like the floor.

use super::elimination::{Elimination, Increment};
use super::interface::{ActiveSet, InterfaceFactorization, Precision};
use super::linear::{SparseSystem, SymmetricProduct, gmres};
use super::pieces;
use super::{Problem, Settings, State, StepReport, StepSolver, inf_norm};
use super::{Timings, timed};
use crate::contact;
use crate::error::{Error, Result};
use crate::fe::{FIXED, Pattern, TangentChange};
use crate::material::{Strain, Stress};
use nalgebra::Matrix3;
use rayon::prelude::*;
use std::cell::Cell;

/// Newton solver state (pattern, slots, factorization) for one problem.
pub struct Newton<'a> {
    p: &'a Problem,
    settings: Settings,
    n: usize,
    /// Slots of each triangle's 6 x 6 entries in the stiffness pattern.
    slots: Vec<[usize; 36]>,
    /// The elastic stiffness K_el, assembled once. GMRES's products read it by rows (its
    /// transpose product: its element matrices B^T (E S) B |T| differ from their
    /// transposes in the last bit, so the products are K_el x to 2.5e-16 relative, not
    /// to the bit).
    stiffness: SymmetricProduct,
    /// The viscoplastic triangles' share K_t - K_el of the current tangent, applied per
    /// triangle in the products (empty while every tangent is elastic).
    change: TangentChange,
    /// The contact rows over the free unknowns: (equation, coefficient).
    rows: Vec<Vec<(usize, f64)>>,
    factorization: InterfaceFactorization,
    /// The dense interface system of the last active set.
    active_set: Option<ActiveSet>,
    /// Which factorization preconditions GMRES.
    preconditioner: Preconditioner,
    /// The KKT matrix for its LU, built on first need.
    kkt: Option<KktMatrix>,
    /// The factorization is too old to precondition well: refactor at the next iteration.
    stale: bool,
    /// Scale turning gaps into forces in the complementarity function (force/length).
    c_scale: f64,
    clock: std::rc::Rc<Clock>,
    /// Seconds building the pattern, slot maps and symbolic analysis (once per mesh).
    setup_s: f64,
    /// Print one line per iteration to stderr (environment CONTACT_RATES_TRACE set): the
    /// distances, the active set and its flips, the plastic triangles and how many switched,
    /// the line search's step length.
    trace: bool,
    /// Whether a body is held along Gamma_C's normal only by the contact
    /// ([`crate::contact::Interface::held_only_by_contact`]).
    floating: bool,
    /// Whether a body is viscoplastic; if not, every tangent is elastic: the constitutive
    /// update stores none ([`Evaluation::tangents`] is empty) and `change` stays empty.
    viscoplastic: bool,
    /// The first value slot of body 1 in the stiffness ([`Model::body_slot_split`]),
    /// computed at the first factorization of a viscoplastic tangent.
    body_split: std::cell::OnceCell<Option<usize>>,
    /// Lower triangle of the symmetric stiffness handed to the LDL^T (pattern order).
    symmetric_values: Vec<f64>,
    /// GMRES iterations of the first solve after the last factorization.
    fresh_iterations: usize,
    /// Contact rows the active-set prediction changed (summed over rounds and iterations).
    predicted_changes: usize,
    /// Local re-equilibration of the triangles where a step leaves the linear model.
    elimination: Elimination,
}

/// The share of the tolerance the last linear solve of a nonlinear step may leave in the
/// residual ([`Newton::forcing_term`]); the rest is margin for the Newton model's own
/// error, far smaller there (quadratic in a residual of 1e-8 or less). Measured with
/// `speed_pieces` (4 steps, one run per case): 0.5 instead of 0.3 saves a GMRES iteration
/// in the last iteration of a plastic step (`rates` preconditioner applications: 26 -> 24
/// at 34,432 dofs, 25 -> 24 at 8,640, 29 -> 28 at 137,472, 28 -> 27 at 549,376, both
/// cones), and no run of `rates` or `rates-elastic` at levels 3-6 takes another iteration.
const TOLERANCE_MARGIN: f64 = 0.5;

/// The same share for a step solved at once ([`Newton::exact_forcing`]: every tangent
/// elastic). There 0.5 saved nothing (`rates-elastic` levels 3-6: 3 or 4 applications
/// either way) and left the elastic studies' equilibrium-fixed quantity at the solver
/// tolerance instead of round-off: the pressure resultant of `contact-mms` at level 3
/// went from 5.0e-12 to 1.07e-10, past the reports' round-off line (1e-10), and
/// `two-size-exact` then named a better slave for it.
const EXACT_MARGIN: f64 = 0.3;

/// A line-search trial whose merit is at most this share of the iterate's skips the
/// nonlinear elimination ([`Newton::eliminate`]) and its pass over the triangles: a step
/// that cut the merit 1000x left the return map's linear model nowhere it mattered (a
/// heuristic, measured). Measured with `speed_pieces` (`rates`, 34,432 dofs, 4 steps):
/// the search for failed triangles cost 2.5 ms of a 0.15 s run (10 trials at 0.25 ms),
/// and no trial of `rates` there had a failed triangle; over `study stability` and 144
/// stiff-viscosity runs (k E / lambda 1e-2 to 1e4, levels 1-3, 1-10 steps, both cones:
/// 3,993 eliminations) every trial the elimination moved had a merit of at least 1.46e-2
/// of the iterate's, so the skip changes none of them. At 1e-2 the margin was 1.46x; at
/// 1e-3 it is 14.6x and the last iteration of a plastic step (merit ratios up to 7e-3
/// there) still pays the search.
const ELIMINATION_SKIP: f64 = 1e-3;

/// The factorization GMRES is preconditioned with.
#[derive(PartialEq)]
enum Preconditioner {
    /// None yet.
    None,
    /// The stiffness's LDL^T with the interface last, any active set.
    Interface,
    /// The LU of the KKT matrix with this active set.
    KktLu(Vec<bool>),
}

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

/// Rounds of the active-set prediction per Newton iteration (see [`Newton::newton_step`]):
/// the primal-dual active set method can cycle on a matrix that is not an M-matrix.
const MAX_PREDICTIONS: usize = 20;

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

/// The Newton matrix itself, `[K_t c C^T; c C_A 0]` with `c` on the diagonal of inactive
/// rows, assembled for its sparse LU: the fallback when the tangent is too far from
/// symmetric for GMRES (stiff viscosity, k E / lambda near 1e4). Built on first need.
struct KktMatrix {
    system: SparseSystem,
    slots: Vec<[usize; 36]>,
    /// Per row: (slot in row n+i, slot in column n+i, coefficient) for each free entry.
    row_slots: Vec<Vec<(usize, usize, f64)>>,
    diag_slots: Vec<usize>,
}

impl KktMatrix {
    fn new(p: &Problem, rows: &[Vec<(usize, f64)>]) -> Self {
        let n = p.model.n_free;
        let m = rows.len();
        let mut extra = Vec::new();
        for (i, r) in rows.iter().enumerate() {
            for &(eq, _) in r {
                extra.push((n + i, eq));
                extra.push((eq, n + i));
            }
            extra.push((n + i, n + i));
        }
        let (pattern, slots): (Pattern, _) = p.model.stiffness_pattern(&extra, n + m);
        let row_slots = rows
            .iter()
            .enumerate()
            .map(|(i, r)| {
                r.iter()
                    .map(|&(eq, v)| (pattern.slot(n + i, eq), pattern.slot(eq, n + i), v))
                    .collect()
            })
            .collect();
        let diag_slots = (0..m).map(|i| pattern.slot(n + i, n + i)).collect();
        KktMatrix {
            system: SparseSystem::new(&pattern),
            slots,
            row_slots,
            diag_slots,
        }
    }

    /// Assemble the Newton matrix of `tangents` and `active` (contact rows scaled by `c`:
    /// every entry has the size of the stiffness) and factorize it.
    fn factor(
        &mut self,
        p: &Problem,
        tangents: &[Matrix3<f64>],
        active: &[bool],
        c: f64,
    ) -> Result<()> {
        let vals = self.system.values_mut();
        vals.iter_mut().for_each(|v| *v = 0.0);
        p.model.add_tangent(tangents, &self.slots, vals);
        for (i, row) in self.row_slots.iter().enumerate() {
            for &(rs, cs, v) in row {
                vals[cs] = c * v;
                vals[rs] = if active[i] { c * v } else { 0.0 };
            }
            vals[self.diag_slots[i]] = if active[i] { 0.0 } else { c };
        }
        self.system.factor_lu()
    }
}

impl<'a> Newton<'a> {
    /// Set up the stiffness pattern and the symbolic analysis for `p`.
    pub fn new(p: &'a Problem, settings: &Settings) -> Result<Self> {
        let t_setup = std::time::Instant::now();
        let n = p.model.n_free;
        let (pattern, slots) =
            pieces::time("setup.pattern", 0, || p.model.stiffness_pattern(&[], n));
        let rows = p.free_rows();
        let viscoplastic = p.model.materials.iter().any(|m| m.viscoplastic.is_some());
        let values = pieces::time("setup.values", 0, || {
            let mut values = vec![0.0; pattern.nnz()];
            p.model
                .add_tangent(&p.model.elastic_tangents(), &slots, &mut values);
            values
        });
        // Stiffness scale: the mean diagonal of the elastic stiffness.
        let c_scale = (0..n).map(|i| values[pattern.slot(i, i)]).sum::<f64>() / n.max(1) as f64;
        let factorization = pieces::time("setup.interface_analysis", 0, || {
            InterfaceFactorization::new(&pattern, &rows)
        })?;
        let stiffness = SymmetricProduct::new(pattern, values);
        let setup_s = t_setup.elapsed().as_secs_f64();
        pieces::record("setup.total", 0, setup_s);
        Ok(Newton {
            p,
            settings: *settings,
            n,
            slots,
            stiffness,
            change: TangentChange::default(),
            rows,
            factorization,
            active_set: None,
            preconditioner: Preconditioner::None,
            kkt: None,
            stale: false,
            c_scale,
            clock: Default::default(),
            setup_s,
            viscoplastic,
            body_split: std::cell::OnceCell::new(),
            symmetric_values: Vec::new(),
            fresh_iterations: 0,
            predicted_changes: 0,
            elimination: Elimination::new(&p.model),
            trace: std::env::var_os("CONTACT_RATES_TRACE").is_some(),
            floating: p.interface.held_only_by_contact(&p.model).is_some(),
        })
    }

    /// `y = A x` for the Newton matrix A of the current tangent and `active`.
    fn kkt_product(&self, active: &[bool], x: &[f64], y: &mut [f64]) {
        let (n, c) = (self.n, self.c_scale);
        let (xu, xl) = x.split_at(n);
        let (yu, yl) = y.split_at_mut(n);
        // K_t x = K_el x (by rows, to round-off: see the field) + (K_t - K_el) x.
        self.stiffness.product(xu, yu);
        self.change.add_product(xu, yu);
        for (i, row) in self.rows.iter().enumerate() {
            let xi = c * xl[i];
            if xi != 0.0 {
                for &(eq, v) in row {
                    yu[eq] += v * xi;
                }
            }
            yl[i] = if active[i] {
                c * row.iter().map(|&(eq, v)| v * xu[eq]).sum::<f64>()
            } else {
                c * xl[i]
            };
        }
    }

    /// Factorize the symmetric counterpart K_s of the tangent stiffness (see the module).
    /// Where the model is exact ([`Newton::model_is_exact`], `change` set from the same
    /// tangents just before), K_s is the stiffness itself, factorized as it is.
    fn factor(&mut self, tangents: &[Matrix3<f64>]) -> Result<()> {
        if self.model_is_exact() {
            self.factorization
                .factor(self.stiffness.values(), self.c_scale, Precision::Single)?;
        } else {
            let clock = std::rc::Rc::clone(&self.clock);
            let mut vals = std::mem::take(&mut self.symmetric_values);
            timed(&clock.assembly, || {
                vals.clear();
                vals.extend_from_slice(self.stiffness.values());
                let model = &self.p.model;
                let symmetric: Vec<Matrix3<f64>> = (model
                    .elements
                    .par_iter()
                    .zip(tangents.par_iter()))
                .with_min_len(4096)
                .map(|(e, d)| symmetric_tangent(d, &model.materials[e.body].elastic.matrix()))
                .collect();
                let split = *self
                    .body_split
                    .get_or_init(|| model.body_slot_split(&self.slots));
                model.add_tangent_change(&symmetric, &self.slots, split, &mut vals);
            });
            let result = self
                .factorization
                .factor(&vals, self.c_scale, Precision::Single);
            self.symmetric_values = vals;
            result?;
        }
        self.active_set = None;
        self.stale = false;
        self.preconditioner = Preconditioner::Interface;
        Ok(())
    }

    /// The dense interface system of `active` (kept while the active set stays).
    fn prepare_active_set(&mut self, active: &[bool]) -> Result<()> {
        if self
            .active_set
            .as_ref()
            .is_none_or(|s| s.active() != active)
        {
            self.active_set = Some(self.factorization.active_set(active, self.c_scale)?);
        }
        Ok(())
    }

    /// Apply the current preconditioner to `v` in place.
    fn precondition(&self, v: &mut [f64]) {
        match &self.preconditioner {
            Preconditioner::Interface => {
                let set = self.active_set.as_ref().expect("prepared");
                self.factorization.solve(set, self.c_scale, v);
            }
            Preconditioner::KktLu(_) => {
                self.kkt.as_ref().expect("factored").system.solve(v);
            }
            Preconditioner::None => unreachable!("a factorization precedes GMRES"),
        }
    }

    /// GMRES on the Newton system of `active` from the initial guess `x0` (`rhs` in, step
    /// out), preconditioned by the current factorization; None (and `rhs` untouched) when
    /// it misses `forcing` in `budget` iterations.
    fn krylov(
        &self,
        rhs: &mut [f64],
        x0: Option<&[f64]>,
        active: &[bool],
        forcing: f64,
        budget: usize,
    ) -> Option<usize> {
        timed(&self.clock.solve, || {
            let product = |x: &[f64], y: &mut [f64]| self.kkt_product(active, x, y);
            let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
            // Solve for the correction of x0 (zero when there is none): A e = b - A x0, to
            // the same |b|-relative tolerance.
            let zero;
            let (x0, mut residual) = match x0 {
                Some(x0) => {
                    let mut residual = vec![0.0; rhs.len()];
                    product(x0, &mut residual);
                    residual
                        .iter_mut()
                        .zip(&*rhs)
                        .for_each(|(r, b)| *r = b - *r);
                    (x0, residual)
                }
                None => {
                    zero = vec![0.0; rhs.len()];
                    (&zero[..], rhs.to_vec())
                }
            };
            let (b_norm, r_norm) = (norm(rhs), norm(&residual));
            if r_norm <= forcing * b_norm {
                rhs.copy_from_slice(x0);
                return Some(0);
            }
            let its = gmres(
                &product,
                &mut residual,
                forcing * b_norm / r_norm,
                budget,
                &|v| self.precondition(v),
            )?;
            for ((x, e), x0) in rhs.iter_mut().zip(&residual).zip(x0) {
                *x = x0 + e;
            }
            Some(its)
        })
    }
}

/// The residual of (2.1) with the return map at one iterate (u, lambda).
struct Evaluation {
    /// Stresses from the return map.
    sigma: Vec<Stress>,
    /// Consistent tangents per triangle; empty when no body is viscoplastic (all elastic).
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
    /// The strains of `prev.u` per triangle.
    strain_prev: Vec<Strain>,
    k: f64,
    /// The constitutive source per element at t_n (a manufactured solution's), if any.
    source: Option<Vec<Stress>>,
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
    /// Solves with a factorization so far: the interface factorization's (a prediction's
    /// forward and back substitutions, or one preconditioner application) and the Newton
    /// matrix's LU (the fallback).
    fn solves(&self) -> usize {
        self.factorization.solves.get() + self.kkt.as_ref().map_or(0, |k| k.system.solves.get())
    }

    /// Return map, internal forces and constraint values at (u, lambda).
    fn evaluate(&self, data: &StepData, u: &[f64], lambda: &[f64]) -> Evaluation {
        let (model, clock) = (&self.p.model, &self.clock);
        let (sigma, tangents) = timed(&clock.constitutive, || {
            model.update_stresses(
                u,
                &data.strain_prev,
                &data.prev.sigma,
                data.k,
                data.source.as_deref(),
                self.viscoplastic,
            )
        });
        let f_int = timed(&clock.assembly, || model.internal_force(&sigma));
        // f_int - F over the free dofs and the largest free |f_int|, in one pass, then
        // C^T lambda row by row: the same sums as over every dof, restricted after.
        let mut residual = vec![0.0; self.n];
        let mut internal = 0.0f64;
        for ((&eq, f), f_ext) in model.equation.iter().zip(&f_int).zip(&data.f_ext) {
            if eq != FIXED {
                residual[eq] = f - f_ext;
                internal = internal.max(f.abs());
            }
        }
        let gaps = timed(&clock.contact, || {
            for (row, l) in self.rows.iter().zip(lambda) {
                for &(eq, v) in row {
                    residual[eq] += v * l;
                }
            }
            contact::constraint_values(&self.p.rows, u)
        });
        let scale = inf_norm(&data.f_free).max(internal).max(f64::MIN_POSITIVE);
        Evaluation {
            sigma,
            tangents,
            residual,
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

    /// Set the current tangent for GMRES's products: the viscoplastic triangles' changes
    /// against the elastic stiffness ([`Model::tangent_change`]), kept per triangle. Before,
    /// the products read an assembled K_t: a copy of the elastic values and a scatter of
    /// the changed triangles' 6 x 6 matrices per iteration.
    fn assemble_tangent(&mut self, tangents: &[Matrix3<f64>]) {
        if !self.viscoplastic {
            // Every tangent is elastic: the stiffness is the tangent.
            return;
        }
        let clock = std::rc::Rc::clone(&self.clock);
        self.change = timed(&clock.assembly, || self.p.model.tangent_change(tangents));
    }

    /// The Newton step at the iterate of `ev` and `lambda`, and the active set it was
    /// computed with. Every iteration is a full semismooth Newton step with the current
    /// consistent tangent. Its active set is the one the factorized linear model predicts:
    /// starting from `active` (the semismooth rule at the iterate), the model's step is
    /// solved on the interface, the rule applied to the resulting multipliers and gaps,
    /// and so on until the set repeats ([`MAX_PREDICTIONS`] at most): each round is a
    /// dense solve on the interface, where each outer iteration costs a sparse solve and a
    /// return map over the mesh. For elastic bodies the model is exact and a step ends in
    /// one iteration. The linear system is then solved by GMRES from the model's step,
    /// preconditioned with the last factorization (of an older tangent: it changes little
    /// between iterations and steps); the stiffness is refactorized only when GMRES needs
    /// many iterations. Returns (step, active set, whether it factorized).
    fn newton_step(
        &mut self,
        ev: &Evaluation,
        lambda: &[f64],
        active: Vec<bool>,
        distance: &Distance,
    ) -> Result<(Vec<f64>, Vec<bool>, bool)> {
        // GMRES is worth it while its solves cost less than a fresh factorization (about
        // 10 solves here): cap it at 10 iterations and refactor next time when it used more
        // than 5 and more than the fresh factorization needed. The rule counts iterations,
        // not seconds, so the results do not depend on the machine's load.
        let budget = 10;
        self.assemble_tangent(&ev.tangents);
        let forcing = match self.model_is_exact() {
            true => self.exact_forcing(distance),
            false => self.forcing_term(distance),
        };
        let reusable = match &self.preconditioner {
            Preconditioner::Interface => true,
            Preconditioner::KktLu(a) => *a == active,
            Preconditioner::None => false,
        };
        if reusable && !self.stale {
            let (set, x0, flips) = self.predicted_step(ev, lambda, active.clone())?;
            self.predicted_changes += flips;
            let mut rhs = self.right_hand_side(ev, lambda, &set);
            if let Some(its) = self.krylov(&mut rhs, x0.as_deref(), &set, forcing, budget) {
                let its = its + x0.is_some() as usize;
                self.stale = 2 * its > budget && its > self.fresh_iterations + 1;
                return Ok((rhs, set, false));
            }
        }
        self.factor(&ev.tangents)?;
        let (set, x0, flips) = self.predicted_step(ev, lambda, active)?;
        self.predicted_changes += flips;
        let mut rhs = self.right_hand_side(ev, lambda, &set);
        let its = match self.krylov(&mut rhs, x0.as_deref(), &set, forcing, FRESH_BUDGET) {
            Some(its) => its + x0.is_some() as usize,
            None => {
                // A tangent too far from symmetric (stiff viscosity, k E / lambda near 1e4):
                // the LU of the Newton matrix itself, exact.
                let (p, c) = (self.p, self.c_scale);
                let rows = &self.rows;
                let kkt = self.kkt.get_or_insert_with(|| KktMatrix::new(p, rows));
                let elastic;
                let tangents = match self.viscoplastic {
                    true => &ev.tangents,
                    false => {
                        elastic = p.model.elastic_tangents();
                        &elastic
                    }
                };
                kkt.factor(p, tangents, &set, c)?;
                timed(&self.clock.solve, || kkt.system.solve(&mut rhs));
                self.preconditioner = Preconditioner::KktLu(set.clone());
                0
            }
        };
        self.fresh_iterations = its;
        Ok((rhs, set, true))
    }

    /// The Newton right-hand side of the active set `set`: minus the residual, and per
    /// contact row -c g_i (active) or -lambda_i (inactive).
    fn right_hand_side(&self, ev: &Evaluation, lambda: &[f64], set: &[bool]) -> Vec<f64> {
        let mut rhs: Vec<f64> = ev.residual.iter().map(|v| -v).collect();
        rhs.extend(self.right_hand_side_rows(ev, lambda, set));
        rhs
    }

    /// The active set the factorized model predicts from `active`, the model's step for
    /// it (None when the preconditioner is not the interface factorization: the set is
    /// then `active`), and how many rows changed on the way. See [`Newton::newton_step`].
    fn predicted_step(
        &mut self,
        ev: &Evaluation,
        lambda: &[f64],
        mut active: Vec<bool>,
    ) -> Result<(Vec<bool>, Option<Vec<f64>>, usize)> {
        if self.preconditioner != Preconditioner::Interface {
            return Ok((active, None, 0));
        }
        let (c, m) = (self.c_scale, lambda.len());
        // A body that only the contact holds along Gamma_C's normal floats on an empty
        // set: its system is singular, and in single precision its rigid mode's pivot is
        // rounding of either sign, so the regularized model may even pull the bodies apart
        // (measured: an initial gap of 0.01, 60 iterations at residual 1). Every row
        // active holds it, and the model's rounds drop the rows that pull.
        if self.floating && !active.iter().any(|&a| a) {
            active = vec![true; m];
        }
        let minus_residual: Vec<f64> = ev.residual.iter().map(|v| -v).collect();
        let condensed = timed(&self.clock.solve, || {
            self.factorization.condense(&minus_residual)
        });
        let (mut round, mut flips) = (0, 0);
        let (x_interface, y) = loop {
            self.prepare_active_set(&active)?;
            let set = self.active_set.as_ref().expect("prepared");
            let factorization = &self.factorization;
            let g = self.right_hand_side_rows(ev, lambda, &active);
            let (x_interface, y) = factorization.interface_solve(set, c, &condensed.load, &g);
            let next: Vec<bool> = (0..m)
                .map(|i| {
                    let gap = ev.gaps[i] + factorization.row_product(i, &x_interface);
                    lambda[i] + c * y[i] + c * gap >= 0.0
                })
                .collect();
            round += 1;
            if next == active || round == MAX_PREDICTIONS {
                break (x_interface, y);
            }
            flips += next.iter().zip(&active).filter(|(a, b)| a != b).count();
            active = next;
        };
        let mut step = timed(&self.clock.solve, || {
            self.factorization.expand(condensed, &x_interface)
        });
        step.extend(y);
        Ok((active, Some(step), flips))
    }

    /// The contact rows' part of [`Newton::right_hand_side`].
    fn right_hand_side_rows(&self, ev: &Evaluation, lambda: &[f64], set: &[bool]) -> Vec<f64> {
        let c = self.c_scale;
        (0..set.len())
            .map(|i| if set[i] { -c * ev.gaps[i] } else { -lambda[i] })
            .collect()
    }

    /// Inexact Newton: the linear solve needs only to beat the equilibrium residual
    /// (forcing term min(1e-2, residual): quadratic convergence), and never more than the
    /// tolerance asks for ([`Newton::tolerance_forcing`], for the last iteration of a
    /// step). While only the active set is searched (residual at
    /// round-off), the semismooth steps terminate finitely and want the solve to tolerance:
    /// a 1e-2 solve there left 4e-9 behind and cost one more iteration in other units.
    /// Where the Newton model is exact, [`Newton::exact_forcing`] applies instead.
    fn forcing_term(&self, distance: &Distance) -> f64 {
        let res = distance.residual;
        let tol_term = self.tolerance_forcing(distance, TOLERANCE_MARGIN);
        if tol_term > 1e-2 {
            // Within TOLERANCE_MARGIN / 1e-2 = 50x of the tolerance: a loose solve ends it (the
            // quadratic term is far below the tolerance there).
            tol_term.min(0.5)
        } else {
            res.max(tol_term).min(1e-2)
        }
        .max(1e-12)
    }

    /// Whether every triangle's tangent at the iterate last assembled
    /// ([`Newton::assemble_tangent`]) is its body's elastic one (`change` empty): the
    /// Newton model is then the step's linear problem itself, up to the active set, which
    /// the interface model predicts. Where that prediction is the solution's set (every
    /// `rates-elastic` run so far), its solution to the tolerance ends the step in one
    /// iteration; where it is not, the next iteration corrects the set as before.
    fn model_is_exact(&self) -> bool {
        !self.viscoplastic || self.change.is_empty()
    }

    /// The forcing that leaves the next residual within `margin` of the tolerance
    /// (`margin` tol / the larger of residual and complementarity): [`Newton::forcing_term`]'s
    /// bound ([`TOLERANCE_MARGIN`]) and [`Newton::exact_forcing`]'s target ([`EXACT_MARGIN`]).
    fn tolerance_forcing(&self, distance: &Distance, margin: f64) -> f64 {
        margin * self.settings.tol / distance.residual.max(distance.complementarity)
    }

    /// The forcing term where the Newton model is exact ([`Newton::model_is_exact`]): the
    /// solve that leaves the next residual below the tolerance, so that the step ends at
    /// the next evaluation. Measured (`speed_pieces`, 34,432 dofs, 4 steps, six rounds of
    /// five runs alternating with the 1e-2 forcing): `rates-elastic` 2 iterations and 3
    /// preconditioner applications become 1 and 3 (loop 0.0355 -> 0.0328 s, fastest);
    /// `rates`, whose first step is elastic, 11 and 26 become 10 and 26 (0.110 -> 0.107
    /// s). Before steps whose predictor meets the tolerance took no iteration, the same
    /// rule for every all-elastic step cost more than it saved (137,472 dofs: 4
    /// iterations and 7 applications against 5 and 6): a step that the extrapolation
    /// nearly solves ended in one iteration on the loose solve.
    fn exact_forcing(&self, distance: &Distance) -> f64 {
        self.tolerance_forcing(distance, EXACT_MARGIN)
            .clamp(1e-12, 0.5)
    }

    /// Nonlinear elimination of a line-search trial `(ut, lt)` (evaluated in `ev`) from
    /// the iterate `u` (evaluated in `current`): the nodes of the triangles where the step
    /// left the return map's linear model ([`Elimination::failed_triangles`]), and of two
    /// rings of triangles around them ([`Elimination::region`]), are
    /// re-equilibrated with the rest of the mesh held, the gaps of the active contact rows
    /// through them kept, until their residual is a tenth of the iterate's largest. Returns
    /// the evaluation of the trial so moved (None when no triangle failed: the trial is as it was).
    fn eliminate(
        &self,
        data: &StepData,
        u: &[f64],
        current: &Evaluation,
        ut: &mut [f64],
        lt: &mut [f64],
        ev: &Evaluation,
    ) -> Option<Evaluation> {
        let model = &self.p.model;
        let failed = timed(&self.clock.constitutive, || {
            Elimination::failed_triangles(
                model,
                u,
                (&current.sigma, &current.tangents),
                ut,
                (&ev.sigma, &ev.tangents),
            )
        });
        if failed.is_empty() {
            return None;
        }
        let region = self.elimination.region(model, &failed);
        let c = self.c_scale;
        let active: Vec<bool> = (0..lt.len())
            .map(|i| lt[i] + c * ev.gaps[i] >= 0.0)
            .collect();
        // The contact forces of the trial's multipliers are held, as a load.
        let mut load = vec![0.0; data.f_ext.len()];
        contact::add_transpose(&self.p.rows, lt, &mut load);
        for (l, f) in load.iter_mut().zip(&data.f_ext) {
            *l = f - *l;
        }
        let increment = Increment {
            strain_prev: &data.strain_prev,
            sigma_prev: &data.prev.sigma,
            k: data.k,
            source: data.source.as_deref(),
            f_ext: &load,
            rows: &self.p.rows,
            active: &active,
        };
        let tol = 0.1 * inf_norm(&current.residual);
        let relaxed = timed(&self.clock.constitutive, || {
            self.elimination
                .relax(model, &increment, &region, ut, lt, tol)
        });
        if self.trace {
            eprintln!(
                "    eliminated {} triangles ({} failed), {} unknowns, {} local iterations",
                region.len(),
                failed.len(),
                relaxed.unknowns,
                relaxed.iterations
            );
        }
        Some(self.evaluate(data, ut, lt))
    }

    /// Backtracking along `step` on the merit |r|^2 + |min(lambda, -c g)|^2 (Armijo against
    /// `reference`, the current iterate's merit): full steps near the solution, shorter
    /// ones when a large step flips many triangles between elastic and viscoplastic (stiff
    /// k E / lambda). Monotone: the contact search that raised the merit on its way (the
    /// reason for a non-monotone search before) now happens on the interface, inside
    /// [`Newton::predicted_step`]; with stiff viscosity (k E / lambda = 1e3, `rates` level
    /// 1) a non-monotone search (memory 3) let the merit oscillate for 43 iterations of
    /// one step where the monotone one takes 12, and `rates` and `rates-elastic` take the
    /// same iterations either way (levels 1, 3, 5, measured). Each trial whose merit is above
    /// [`ELIMINATION_SKIP`] of `reference` is first moved by [`Newton::eliminate`] where the
    /// step left the return map's linear model (kept only where that lowers the merit).
    /// Returns the best trial with its evaluation (the next iteration's residual), its step
    /// length, and whether its merit is below `reference`.
    fn line_search(
        &self,
        data: &StepData,
        u: &[f64],
        lambda: &[f64],
        current: &Evaluation,
        step: &[f64],
        reference: f64,
    ) -> (Vec<f64>, Vec<f64>, Evaluation, f64, bool) {
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
        let mut best: Option<(f64, (Vec<f64>, Vec<f64>), Evaluation, f64)> = None;
        for _ in 0..12 {
            let (mut ut, mut lt) = trial(alpha);
            let ev = self.evaluate(data, &ut, &lt);
            // The trial moved by the elimination, unless that raised the merit (a safeguard:
            // the local solves hold the rest of the mesh and can land on a worse point; the
            // line search then never judges a trial worse than the plain one). A trial that
            // already cuts the merit to ELIMINATION_SKIP of the iterate's is judged as it is
            // (see the constant), and only a trial the elimination may move is copied.
            let raw_merit = self.merit(&ev, &lt);
            let moved = if raw_merit > ELIMINATION_SKIP * reference {
                let (mut moved_u, mut moved_l) = (ut.clone(), lt.clone());
                self.eliminate(data, u, current, &mut moved_u, &mut moved_l, &ev)
                    .map(|moved| (self.merit(&moved, &moved_l), moved, moved_u, moved_l))
            } else {
                None
            };
            let (ev, merit) = match moved {
                Some((merit, moved, moved_u, moved_l)) if merit <= raw_merit => {
                    (ut, lt) = (moved_u, moved_l);
                    (moved, merit)
                }
                _ => (ev, raw_merit),
            };
            let done = merit <= (1.0 - 1e-4 * alpha) * reference;
            if self.trace {
                let res = (ev.residual.iter().map(|v| v * v).sum::<f64>()).sqrt();
                eprintln!(
                    "    trial alpha={alpha} merit/ref={:.4e} |r|={res:.4e}",
                    merit / reference
                );
            }
            if best.as_ref().is_none_or(|b| merit < b.0) {
                best = Some((merit, (ut, lt), ev, alpha));
            }
            if done {
                break;
            }
            alpha *= 0.5;
        }
        let (merit, (u, lambda), ev, alpha) = best.expect("at least one trial");
        (u, lambda, ev, alpha, merit < reference)
    }
}

/// What one time step's iterations counted so far.
struct Counts {
    iterations: usize,
    factorizations: usize,
    /// Active-set changes between iterations (the predictions' are counted apart, in
    /// [`Newton::predicted_changes`]).
    changes: usize,
    /// [`Newton::predicted_changes`] when the step began.
    predicted_before: usize,
}

impl Newton<'_> {
    /// What the iterations of the step to time `t` (from `prev`, step `k`) share: the
    /// load, the constitutive source and the strains at t_{n-1}.
    fn step_data<'s>(&self, prev: &'s State, t: f64, k: f64) -> Result<StepData<'s>> {
        let model = &self.p.model;
        let f_ext = model.load(t)?;
        let source = timed(&self.clock.constitutive, || model.constitutive_source(t))?;
        let strain_prev = timed(&self.clock.constitutive, || model.strains(&prev.u));
        Ok(StepData {
            prev,
            strain_prev,
            k,
            source,
            f_free: model.restrict(&f_ext),
            f_ext,
        })
    }

    /// The distance of the iterate evaluated in `ev`, with multipliers `lambda`.
    fn distance(&self, ev: &Evaluation, lambda: &[f64]) -> Distance {
        Distance {
            residual: inf_norm(&ev.residual) / ev.scale,
            complementarity: super::complementarity(lambda, &ev.gaps, self.c_scale) / ev.scale,
        }
    }

    /// The converged step to `t` from its last iterate (u, sigma, lambda) with the active
    /// set `active`: the state and its report.
    fn converged(
        &self,
        t: f64,
        (u, sigma, mut lambda): (Vec<f64>, Vec<Stress>, Vec<f64>),
        active: &[bool],
        distance: &Distance,
        counts: &Counts,
    ) -> (State, StepReport) {
        // Inactive rows carry no force; GMRES leaves round-off there.
        for i in 0..lambda.len() {
            if !active[i] {
                lambda[i] = 0.0;
            }
        }
        let (res, compl) = (distance.residual, distance.complementarity);
        let (iterations, factorizations) = (counts.iterations, counts.factorizations);
        let stopped = self.settings.stop_after == Some(iterations);
        let reason = match iterations {
            _ if stopped => format!(
                "stopped after {iterations} iterations (stop_after) at residual {res:.2e}, complementarity {compl:.2e}: not necessarily converged"
            ),
            0 => format!(
                "the predictor's residual {res:.2e} and complementarity {compl:.2e} below {:.0e}: no iteration needed",
                self.settings.tol
            ),
            _ => format!(
                "residual {res:.2e} and complementarity {compl:.2e} below {:.0e}, active set settled ({factorizations} factorizations)",
                self.settings.tol
            ),
        };
        let report = StepReport {
            iterations,
            outer_iterations: iterations,
            residual: res,
            active_set_changes: counts.changes + self.predicted_changes - counts.predicted_before,
            reason,
        };
        let state = State {
            time: t,
            u,
            sigma,
            lambda,
        };
        (state, report)
    }

    /// Errs where the iterate is not finite or the iterations ran out.
    fn check_progress(&self, distance: &Distance, iterations: usize) -> Result<()> {
        let (res, compl) = (distance.residual, distance.complementarity);
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
        Ok(())
    }

    /// The trace line of the linear solve: the relative residual of `step` in the Newton
    /// system of the active set `set`, the solves it took since `solves_before`, and its
    /// size against the iterate `u`.
    fn trace_linear_solve(
        &self,
        ev: &Evaluation,
        (u, lambda): (&[f64], &[f64]),
        set: &[bool],
        step: &[f64],
        solves_before: usize,
    ) {
        let n = self.n;
        let rhs = self.right_hand_side(ev, lambda, set);
        let mut y = vec![0.0; step.len()];
        self.kkt_product(set, step, &mut y);
        let lin = y
            .iter()
            .zip(&rhs)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            .sqrt()
            / rhs.iter().map(|b| b * b).sum::<f64>().sqrt();
        eprintln!(
            "    linear residual {lin:.2e} ({} solves with a factorization), |du|/|u| = {:.3e}",
            self.solves() - solves_before,
            inf_norm(&step[..n]) / inf_norm(u).max(1e-300)
        );
    }

    /// The trace line of iteration `iterations` of the step to `t`: the distance, the
    /// active set `set` and its flips against `last_active`, the plastic triangles and how
    /// many switched from the tangents `before` to `after`, the step length `alpha` and
    /// whether the iteration factorized.
    fn trace_iteration(
        &self,
        (t, iterations): (f64, usize),
        distance: &Distance,
        (set, last_active): (&[bool], Option<&[bool]>),
        (before, after): (&[Matrix3<f64>], &[Matrix3<f64>]),
        (alpha, factorized): (f64, bool),
    ) {
        let model = &self.p.model;
        let (res, compl) = (distance.residual, distance.complementarity);
        // A triangle is plastic where its tangent is not the elastic one.
        let plastic = |tangents: &[Matrix3<f64>]| -> Vec<bool> {
            tangents
                .iter()
                .zip(&model.elements)
                .map(|(d, e)| *d != model.materials[e.body].elastic.matrix())
                .collect()
        };
        let (before, after) = (plastic(before), plastic(after));
        let switched = before.iter().zip(&after).filter(|(a, b)| a != b).count();
        let flips = set
            .iter()
            .zip(last_active.unwrap_or(set))
            .filter(|(a, b)| a != b)
            .count();
        eprintln!(
            "trace t={t:.4} it={iterations} res={res:.3e} compl={compl:.3e} active={} flips={flips} plastic={} switched={switched} alpha={alpha} factorized={factorized}",
            set.iter().filter(|&&a| a).count(),
            after.iter().filter(|&&a| a).count(),
        );
    }
}

impl StepSolver for Newton<'_> {
    fn step(&mut self, prev: &State, guess: &State, t: f64, k: f64) -> Result<(State, StepReport)> {
        let (n, m, c) = (self.n, self.p.rows.len(), self.c_scale);
        let data = self.step_data(prev, t, k)?;
        let mut u = guess.u.clone();
        let mut lambda = guess.lambda.clone();
        let mut last_active: Option<Vec<bool>> = None;
        let mut counts = Counts {
            iterations: 0,
            factorizations: 0,
            changes: 0,
            predicted_before: self.predicted_changes,
        };
        let mut evaluation = self.evaluate(&data, &u, &lambda);
        loop {
            let ev = &evaluation;
            let active: Vec<bool> = (0..m).map(|i| lambda[i] + c * ev.gaps[i] >= 0.0).collect();
            let distance = self.distance(ev, &lambda);
            let (res, compl) = (distance.residual, distance.complementarity);
            let same_set = last_active.as_ref().is_some_and(|a| *a == active);
            if let Some(a) = &last_active {
                counts.changes += a.iter().zip(&active).filter(|(x, y)| x != y).count();
            }
            // Converged: residual and complementarity within the tolerance, and the active
            // set the one the last step was computed with. A predictor (the extrapolation of
            // the last steps) that already meets the tolerance is the step's solution: no
            // iteration can improve on the tolerance the run asks for. Measured: an elastic
            // run whose load is linear in time (`rates-elastic`, 34,432 dofs, 4 steps)
            // starts steps 2-4 at residuals 9e-14 to 1.1e-13, where a Newton iteration
            // cost a preconditioner solve, a product and a return map each (5 iterations
            // to 2).
            let settled = same_set || counts.iterations == 0;
            let stopped = self
                .settings
                .stop_after
                .is_some_and(|k| counts.iterations >= k);
            if stopped || (res <= self.settings.tol && compl <= self.settings.tol && settled) {
                let iterate = (u, evaluation.sigma, lambda);
                return Ok(self.converged(t, iterate, &active, &distance, &counts));
            }
            self.check_progress(&distance, counts.iterations)?;
            let reference = self.merit(ev, &lambda);
            let tangents_before = self.trace.then(|| ev.tangents.clone());
            let solves_before = self.solves();
            let (step, set, factorized) = self.newton_step(ev, &lambda, active, &distance)?;
            debug_assert_eq!(step.len(), n + m);
            if self.trace {
                self.trace_linear_solve(ev, (&u, &lambda), &set, &step, solves_before);
            }
            counts.factorizations += factorized as usize;
            let (alpha, decreased);
            (u, lambda, evaluation, alpha, decreased) =
                self.line_search(&data, &u, &lambda, &evaluation, &step, reference);
            // No trial lowered the merit: the step (from an older factorization, through the
            // interface model's active set) is no descent direction here; the next one is
            // computed from a fresh factorization of the current tangent. Measured: a
            // viscoplastic body on an elastic one (lambda = 0.0025, level 1, 4 steps) sat at
            // merit ratio 1.0000 for 58 iterations without this, and took 10 with it.
            if !decreased {
                self.stale = true;
            }
            if let Some(before) = &tangents_before {
                self.trace_iteration(
                    (t, counts.iterations),
                    &distance,
                    (&set, last_active.as_deref()),
                    (before, &evaluation.tangents),
                    (alpha, factorized),
                );
            }
            last_active = Some(set);
            counts.iterations += 1;
        }
    }

    fn timings(&self) -> Timings {
        let (kkt_factor_s, kkt_factorizations) = self
            .kkt
            .as_ref()
            .map_or((0.0, 0), |k| (k.system.factor_s, k.system.factorizations));
        Timings {
            assembly_s: self.clock.assembly.get(),
            factor_s: self.factorization.factor_s.get() + kkt_factor_s,
            solve_s: self.clock.solve.get(),
            constitutive_s: self.clock.constitutive.get(),
            contact_s: self.clock.contact.get(),
            factorizations: self.factorization.factorizations + kkt_factorizations,
            solves: self.solves(),
            setup_s: self.setup_s,
            factor_entries: self.factorization.factor_entries(),
            factor_flops: self.factorization.factor_flops(),
        }
    }
}
