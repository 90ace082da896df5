//! The paper's algorithm (section 4): the fixed point (4.2)-(4.3) on
//! `eta = G(sigma_eta)`, each contact subproblem (4.2) being an elastic variational
//! inequality with the load shifted by `-k eta`. The subproblem is solved either by the
//! penalty-duality iteration (4.4)-(4.5) on the matrix `A + omega C^T W C` (factorized once
//! per mesh) or, as an independent cross-check, by Clarabel as a convex QP.
//!
//! Discretization choice: the L2(Gamma_C) products of (4.4)-(4.5) use the lumped trace mass
//! W of body 1, so that the nodal clipping P_U is the exact projection and the limit solves
//! exactly the same discrete problem as the other solvers (multipliers `lambda = W p`).

use super::linear::SparseSystem;
use super::{Problem, Settings, State, StepReport, StepSolver, inf_norm};
use crate::contact;
use crate::error::{Error, Result};
use crate::fe::Pattern;
use crate::material::Stress;

/// The tightest stopping tolerance of the penalty-duality iteration (relative change).
const INNER_TOL_FLOOR: f64 = 1e-15;

/// How each contact subproblem is solved.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Inner {
    /// Penalty-duality (4.4)-(4.5), the paper's method.
    PenaltyDuality,
    /// Clarabel interior point on the QP.
    Clarabel,
}

/// Fixed-point solver state for one problem.
pub struct FixedPoint<'a> {
    p: &'a Problem,
    settings: Settings,
    /// Mean diagonal of the stiffness (force/length): turns gaps into forces in the
    /// complementarity test.
    c_scale: f64,
    /// Relative change of the penalty-duality iterates at which it stops (1e-3 of the
    /// tolerance, tightened when the equations are not solved to the tolerance).
    inner_tol: f64,
    inner: Inner,
    /// A + omega C^T W C (penalty-duality) or A (Clarabel), over free dofs.
    system: SparseSystem,
    pattern: Pattern,
    omega: f64,
    /// Multiplier iterate q of (4.5), kept as a warm start between steps.
    q: Vec<f64>,
    /// Stored eta of the last step (warm start).
    eta: Option<Vec<Stress>>,
    clarabel_s: f64,
    /// Seconds building the pattern and slot map (once per mesh).
    pattern_s: f64,
}

impl<'a> FixedPoint<'a> {
    /// Assemble and factorize the constant matrix.
    pub fn new(p: &'a Problem, settings: &Settings, inner: Inner) -> Result<Self> {
        let t_setup = std::time::Instant::now();
        let model = &p.model;
        let n = model.n_free;
        let mut extra = Vec::new();
        if inner == Inner::PenaltyDuality {
            for r in &p.rows {
                for &(d1, _) in &r.entries {
                    for &(d2, _) in &r.entries {
                        extra.push((model.equation[d1], model.equation[d2]));
                    }
                }
            }
        }
        let (pattern, slots) = model.stiffness_pattern(&extra, n);
        let mut system = SparseSystem::new(&pattern);
        let pattern_s = t_setup.elapsed().as_secs_f64();
        let tangents = model.elastic_tangents();
        let vals = system.values_mut();
        model.add_tangent(&tangents, &slots, vals);
        let mean_diag = (0..n).map(|i| vals[pattern.slot(i, i)]).sum::<f64>() / n.max(1) as f64;
        let mean_w = p.rows.iter().map(|r| r.weight).sum::<f64>() / p.rows.len().max(1) as f64;
        // Default omega: the penalty term has the size of the stiffness diagonal.
        let omega = settings
            .omega
            .unwrap_or(mean_diag / mean_w.max(f64::MIN_POSITIVE));
        if !(omega > 0.0 && omega.is_finite()) {
            return Err(Error::input(
                &p.model.scene.file,
                "omega",
                format!("omega must be positive and finite, got {omega}"),
            ));
        }
        if !(settings.rho > 0.0 && settings.rho <= 1.0) {
            return Err(Error::input(
                &p.model.scene.file,
                "rho",
                format!("rho must lie in (0, 1], got {}", settings.rho),
            ));
        }
        if inner == Inner::PenaltyDuality {
            for r in &p.rows {
                for &(d1, v1) in &r.entries {
                    for &(d2, v2) in &r.entries {
                        vals[pattern.slot(model.equation[d1], model.equation[d2])] +=
                            omega * r.weight * v1 * v2;
                    }
                }
            }
            system.factor_llt()?;
        }
        Ok(FixedPoint {
            p,
            settings: *settings,
            inner,
            system,
            pattern,
            omega,
            q: vec![0.0; p.rows.len()],
            eta: None,
            c_scale: mean_diag,
            inner_tol: 1e-3 * settings.tol,
            clarabel_s: 0.0,
            pattern_s,
        })
    }

    /// Solve the contact subproblem `A u = b - C^T lambda`, `C u <= g`, complementarity.
    /// Returns (u over global dofs, lambda, inner iterations).
    fn contact_subproblem(&mut self, b: &[f64], u0: &[f64]) -> Result<(Vec<f64>, Vec<f64>, usize)> {
        match self.inner {
            Inner::PenaltyDuality => self.penalty_duality(b, u0),
            Inner::Clarabel => self.clarabel(b),
        }
    }

    fn penalty_duality(&mut self, b: &[f64], u0: &[f64]) -> Result<(Vec<f64>, Vec<f64>, usize)> {
        let p = self.p;
        let model = &p.model;
        let (omega, rho) = (self.omega, self.settings.rho);
        let w: Vec<f64> = p.rows.iter().map(|r| r.weight).collect();
        let mut u_old = u0.to_vec();
        let tol = self.inner_tol;
        for it in 1..=100_000 {
            // (4.4): (A + omega C^T W C) u = b - C^T W (q - omega g), the constraint
            // C u <= g (g: the rows' gaps) shifted to C u - g <= 0.
            let wq: Vec<f64> = (self.q.iter().zip(&w).zip(&p.rows))
                .map(|((q, w), r)| (q - omega * r.gap) * w)
                .collect();
            let mut rhs_g = vec![0.0; 2 * model.n_nodes];
            contact::add_transpose(&p.rows, &wq, &mut rhs_g);
            let mut rhs = model.restrict(&rhs_g);
            for (r, bi) in rhs.iter_mut().zip(b) {
                *r = bi - *r;
            }
            self.system.solve(&mut rhs);
            let u = model.expand(&rhs);
            let g = contact::constraint_values(&p.rows, &u);
            // (4.5): q~ = 2 g + q/omega; q_half = omega (q~ - 2 P_U q~); relaxation rho.
            let mut dq = 0.0f64;
            for i in 0..self.q.len() {
                let qt = 2.0 * g[i] + self.q[i] / omega;
                let qh = omega * (qt - 2.0 * qt.min(0.0));
                let qn = rho * qh + (1.0 - rho) * self.q[i];
                dq = dq.max((qn - self.q[i]).abs());
                self.q[i] = qn;
            }
            let du = u
                .iter()
                .zip(&u_old)
                .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
            let un = inf_norm(&u).max(f64::MIN_POSITIVE);
            let qn = inf_norm(&self.q).max(omega * un);
            u_old = u;
            if !du.is_finite() {
                return Err(Error::NotConverged(
                    "penalty-duality iterate became non-finite".into(),
                ));
            }
            if du <= tol * un && dq <= tol * qn {
                // Physical multiplier p = q + omega g, nodal force lambda = W p.
                let g = contact::constraint_values(&p.rows, &u_old);
                let lambda = (0..g.len())
                    .map(|i| w[i] * (self.q[i] + omega * g[i]).max(0.0))
                    .collect();
                return Ok((u_old, lambda, it));
            }
        }
        Err(Error::NotConverged(format!(
            "penalty-duality (4.4)-(4.5) did not converge in 100000 iterations (omega = {omega:.3e}, rho = {rho})"
        )))
    }

    fn clarabel(&mut self, b: &[f64]) -> Result<(Vec<f64>, Vec<f64>, usize)> {
        use clarabel::algebra::CscMatrix;
        use clarabel::solver::{
            DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
        };
        let p = self.p;
        let model = &p.model;
        let n = model.n_free;
        let t0 = std::time::Instant::now();
        // Scaling: u = alpha x with alpha the size of b / diag(A), so that x is O(1) and the
        // interior point's absolute complementarity floor is small against u; the
        // objective is divided by alpha^2 mean diag(A). The QP's solution is unchanged.
        let vals = self.system.values_mut().to_vec();
        let diag_mean =
            (0..n).map(|i| vals[self.pattern.slot(i, i)]).sum::<f64>() / n.max(1) as f64;
        let alpha = (inf_norm(b) / diag_mean).max(f64::MIN_POSITIVE);
        let scale = diag_mean;
        let (mut cp, mut ri, mut nz) = (vec![0usize], Vec::new(), Vec::new());
        for c in 0..n {
            for s in self.pattern.col_ptr[c]..self.pattern.col_ptr[c + 1] {
                let r = self.pattern.row_idx[s];
                if r <= c {
                    ri.push(r);
                    nz.push(vals[s] / scale);
                }
            }
            cp.push(ri.len());
        }
        let pm = CscMatrix::new(n, n, cp, ri, nz);
        // A: the constraint rows (m x n) in CSC.
        let m = p.rows.len();
        let mut cols: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
        for (i, r) in p.rows.iter().enumerate() {
            for &(d, v) in &r.entries {
                cols[model.equation[d]].push((i, v));
            }
        }
        let (mut cp, mut ri, mut nz) = (vec![0usize], Vec::new(), Vec::new());
        for col in &mut cols {
            col.sort_by_key(|e| e.0);
            for &(i, v) in col.iter() {
                ri.push(i);
                nz.push(v);
            }
            cp.push(ri.len());
        }
        let am = CscMatrix::new(m, n, cp, ri, nz);
        let q: Vec<f64> = b.iter().map(|v| -v / (scale * alpha)).collect();
        let cones = [SupportedConeT::NonnegativeConeT(m)];
        let settings = DefaultSettingsBuilder::default()
            .verbose(false)
            .tol_gap_abs(1e-15)
            .tol_gap_rel(1e-15)
            .tol_feas(1e-14)
            .tol_ktratio(1e-12)
            .max_iter(200)
            .build()
            .expect("valid Clarabel settings");
        // C u <= g with u = alpha x: C x + s = g / alpha, s >= 0.
        let gaps: Vec<f64> = p.rows.iter().map(|r| r.gap / alpha).collect();
        let mut solver = DefaultSolver::new(&pm, &q, &am, &gaps, &cones, settings)
            .map_err(|e| Error::NotConverged(format!("Clarabel setup failed: {e}")))?;
        solver.solve();
        self.clarabel_s += t0.elapsed().as_secs_f64();
        let sol = &solver.solution;
        match sol.status {
            SolverStatus::Solved | SolverStatus::AlmostSolved => {}
            s => {
                return Err(Error::NotConverged(format!(
                    "Clarabel stopped with status {s:?} after {} iterations",
                    sol.iterations
                )));
            }
        }
        let x: Vec<f64> = sol.x.iter().map(|x| x * alpha).collect();
        Ok((
            model.expand(&x),
            sol.z.iter().map(|z| z * scale * alpha).collect(),
            sol.iterations as usize,
        ))
    }
}

/// What the outer iterations of one time step of the fixed point share: the step from
/// `prev` to `t`, its load and a manufactured solution's constitutive source.
struct StepData<'s> {
    prev: &'s State,
    t: f64,
    k: f64,
    f_ext: Vec<f64>,
    /// The constitutive source per element at t_n, if any.
    source: Option<Vec<Stress>>,
}

impl StepData<'_> {
    /// k s of a manufactured solution's constitutive source on element `i`: added to sigma
    /// with k eta (zero, and nothing stored, for a scene without one).
    fn k_source(&self, i: usize) -> Stress {
        self.source
            .as_ref()
            .map_or(Stress::zeros(), |s| self.k * s[i])
    }
}

/// Where one outer iteration of the fixed point stands.
struct Outer {
    /// Its number, from 1.
    outer: usize,
    /// Inner iterations so far.
    inner_total: usize,
    /// The change of k eta, max over the elements (stress).
    change: f64,
    /// `change` relative to the largest stress.
    rel: f64,
}

/// What a settled fixed point (the change of k eta at the tolerance) leads to.
enum Settled {
    /// The step is solved.
    Solved(State, StepReport),
    /// Not solved yet: iterate again from these displacements, the distance to the
    /// solution now this.
    Again(Vec<f64>, f64),
}

impl FixedPoint<'_> {
    /// The shift of (4.2) per element: E eps(u^{n-1}) - sigma^{n-1} - k s.
    fn shift(&self, data: &StepData) -> Vec<Stress> {
        let model = &self.p.model;
        let prev = data.prev;
        model
            .elements
            .iter()
            .enumerate()
            .map(|(i, e)| {
                model.materials[e.body].elastic.apply(&e.strain(&prev.u))
                    - prev.sigma[i]
                    - data.k_source(i)
            })
            .collect()
    }

    /// The first eta of the step: the last step's, or G(sigma^{n-1}) at the first step.
    fn initial_eta(&self, prev: &State) -> Vec<Stress> {
        let model = &self.p.model;
        match &self.eta {
            Some(e) => e.clone(),
            None => model
                .elements
                .iter()
                .zip(&prev.sigma)
                .map(|(e, s)| model.materials[e.body].g(s))
                .collect(),
        }
    }

    /// The load of the contact subproblem (4.2) over the free dofs:
    /// b = F + sum |T| B^T (E eps(u^{n-1}) - sigma^{n-1} - k eta).
    fn subproblem_load(&self, data: &StepData, shift: &[Stress], eta: &[Stress]) -> Vec<f64> {
        let model = &self.p.model;
        let k = data.k;
        let loads: Vec<Stress> = shift.iter().zip(eta).map(|(s, e)| s - k * e).collect();
        let fb = model.internal_force(&loads);
        model.restrict(
            &data
                .f_ext
                .iter()
                .zip(&fb)
                .map(|(f, l)| f + l)
                .collect::<Vec<_>>(),
        )
    }

    /// (4.3): sigma_eta = sigma^{n-1} + E eps(u) - E eps(u^{n-1}) + k eta (+ k s), and the
    /// next eta' = G(sigma_eta).
    fn stress_and_eta(
        &self,
        data: &StepData,
        u: &[f64],
        eta: &[Stress],
    ) -> (Vec<Stress>, Vec<Stress>) {
        let model = &self.p.model;
        let (prev, k) = (data.prev, data.k);
        let sigma: Vec<Stress> = model
            .elements
            .iter()
            .enumerate()
            .map(|(i, e)| {
                prev.sigma[i]
                    + model.materials[e.body]
                        .elastic
                        .apply(&(e.strain(u) - e.strain(&prev.u)))
                    + k * eta[i]
                    + data.k_source(i)
            })
            .collect();
        let eta_new: Vec<Stress> = model
            .elements
            .iter()
            .zip(&sigma)
            .map(|(e, s)| model.materials[e.body].g(s))
            .collect();
        (sigma, eta_new)
    }

    /// The fixed point settled at `state` (eta now `eta`): solved, or to iterate again while
    /// the distance to the solution shrinks against `settled_distance` (the last settled
    /// iterate's).
    fn settled(
        &mut self,
        data: &StepData,
        state: State,
        eta: &[Stress],
        it: &Outer,
        settled_distance: Option<f64>,
    ) -> Result<Settled> {
        let (outer, change, rel) = (it.outer, it.change, it.rel);
        // The change of k eta is the paper's criterion; the step is solved when the
        // equations are: equilibrium and complementarity below the tolerance, the
        // same test as newton's.
        let (residual, complementarity) =
            super::distance_to_solution(self.p, &state, &data.f_ext, self.c_scale);
        let tol = self.settings.tol;
        if residual <= tol && complementarity <= tol {
            self.eta = Some(eta.to_vec());
            let report = StepReport {
                iterations: it.inner_total,
                outer_iterations: outer,
                residual,
                active_set_changes: 0,
                reason: format!(
                    "fixed point converged: relative change of k*eta {rel:.2e}, residual {residual:.2e} and complementarity {complementarity:.2e} below {tol:.0e}"
                ),
            };
            return Ok(Settled::Solved(state, report));
        }
        // Settled but not solved: go on while the distance shrinks (the next
        // iterations sharpen eta); an exact fixed point, or one that stopped
        // improving, has inaccurate contact subproblems.
        let distance = residual.max(complementarity);
        if self.inner == Inner::PenaltyDuality && self.inner_tol > INNER_TOL_FLOOR {
            // The penalty-duality iteration stops on the change of its iterates:
            // ask it for more digits and solve the subproblem again.
            self.inner_tol = (self.inner_tol * 1e-2).max(INNER_TOL_FLOOR);
        } else if change == 0.0 || settled_distance.is_some_and(|d| distance > 0.5 * d) {
            return Err(Error::NotConverged(format!(
                "the fixed point settled after {outer} iterations (relative change of k*eta {rel:.2e}) but the equilibrium residual {residual:.3e} and complementarity {complementarity:.3e} of (2.1) are not both below the tolerance {tol:.0e}: the contact subproblems were solved inaccurately"
            )));
        }
        Ok(Settled::Again(state.u, distance))
    }
}

/// The change of k eta from `eta` to `eta_new` (max over the elements), and that change
/// relative to the largest stress of `sigma`.
fn eta_change(eta_new: &[Stress], eta: &[Stress], sigma: &[Stress], k: f64) -> (f64, f64) {
    let change = eta_new
        .iter()
        .zip(eta)
        .map(|(a, b)| (a - b).amax())
        .fold(0.0f64, f64::max)
        * k;
    let size = sigma
        .iter()
        .map(|s| s.amax())
        .fold(0.0f64, f64::max)
        .max(f64::MIN_POSITIVE);
    (change, change / size)
}

/// Errs where the fixed point diverges: a relative change `rel` not finite, or after 5
/// iterations above both the last one's and the first one's.
fn check_divergence(outer: usize, rel: f64, last_change: f64, first_change: f64) -> Result<()> {
    if !rel.is_finite() || (outer > 5 && rel > last_change && rel > first_change) {
        let factor = if last_change.is_finite() {
            rel / last_change
        } else {
            f64::INFINITY
        };
        return Err(Error::NotConverged(format!(
            "the fixed point (4.2)-(4.3) diverges after {outer} iterations (change ratio {factor:.3} > 1): k L is too large; take a smaller time step or use the newton solver"
        )));
    }
    Ok(())
}

impl StepSolver for FixedPoint<'_> {
    fn step(&mut self, prev: &State, guess: &State, t: f64, k: f64) -> Result<(State, StepReport)> {
        let model = &self.p.model;
        let data = StepData {
            prev,
            t,
            k,
            f_ext: model.load(t)?,
            source: model.constitutive_source(t)?,
        };
        let shift = self.shift(&data);
        let mut eta = self.initial_eta(prev);
        let mut u = guess.u.clone();
        let mut inner_total = 0;
        let mut first_change = None;
        let mut last_change = f64::INFINITY;
        let mut settled_distance: Option<f64> = None;
        for outer in 1..=self.settings.max_iterations.max(200) {
            let b = self.subproblem_load(&data, &shift, &eta);
            let (un, lambda, inner) = self.contact_subproblem(&b, &u)?;
            inner_total += inner;
            u = un;
            let (sigma, eta_new) = self.stress_and_eta(&data, &u, &eta);
            let (change, rel) = eta_change(&eta_new, &eta, &sigma, k);
            first_change.get_or_insert(rel);
            eta = eta_new;
            if rel <= self.settings.tol || change == 0.0 {
                let state = State {
                    time: data.t,
                    u,
                    sigma,
                    lambda,
                };
                let it = Outer {
                    outer,
                    inner_total,
                    change,
                    rel,
                };
                match self.settled(&data, state, &eta, &it, settled_distance)? {
                    Settled::Solved(state, report) => return Ok((state, report)),
                    Settled::Again(back, distance) => {
                        settled_distance = Some(distance);
                        u = back;
                        continue;
                    }
                }
            }
            check_divergence(outer, rel, last_change, first_change.unwrap())?;
            last_change = rel;
        }
        Err(Error::NotConverged(format!(
            "the fixed point (4.2)-(4.3) did not converge in {} iterations (last relative change {last_change:.3e})",
            self.settings.max_iterations.max(200)
        )))
    }

    fn timings(&self) -> super::Timings {
        super::Timings {
            factor_s: self.system.factor_s + self.clarabel_s,
            factorizations: self.system.factorizations,
            solves: self.system.solves.get(),
            setup_s: self.pattern_s + self.system.symbolic_s,
            ..Default::default()
        }
    }
}
