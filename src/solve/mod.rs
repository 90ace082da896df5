//! Solving the fully discrete problem (2.1) step by step with one of three solvers that
//! solve the same equations: [`newton`] (default), the paper's fixed point with the
//! penalty-duality iteration, and a Clarabel QP cross-check (both in [`fixed_point`]).

pub mod elimination;
pub mod fixed_point;
pub mod floor;
pub mod interface;
pub mod linear;
pub mod newton;
pub mod ordering;
pub mod pieces;
pub mod substitution;

pub use floor::{Floor, floor, floor_time};

use crate::contact::{self, Interface, Method, Row};
use crate::error::{Error, Result};
use crate::fe::Model;
use crate::material::Stress;
use std::time::Instant;

/// Which solver. Written as its [`SolverKind::name`] in files; read from it with an error
/// that lists the names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase", try_from = "String")]
pub enum SolverKind {
    /// Implicit return map + consistent tangent + semismooth Newton on the contact rows.
    Newton,
    /// The paper's fixed point (4.2)-(4.3) with penalty-duality (4.4)-(4.5).
    Paper,
    /// The paper's fixed point with each contact subproblem solved by Clarabel.
    Qp,
}

impl SolverKind {
    /// Name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            SolverKind::Newton => "newton",
            SolverKind::Paper => "paper",
            SolverKind::Qp => "qp",
        }
    }
    /// Parse a name.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "newton" => Some(SolverKind::Newton),
            "paper" => Some(SolverKind::Paper),
            "qp" => Some(SolverKind::Qp),
            _ => None,
        }
    }
}

impl TryFrom<String> for SolverKind {
    type Error = String;
    fn try_from(s: String) -> std::result::Result<Self, String> {
        SolverKind::parse(&s)
            .ok_or_else(|| format!("unknown solver '{s}'; use newton, paper or qp"))
    }
}

impl std::fmt::Display for SolverKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.name())
    }
}

/// Largest absolute entry of `v` (0 for an empty slice).
pub fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |a, x| a.max(x.abs()))
}

/// Solver settings.
#[derive(Debug, Clone, Copy)]
pub struct Settings {
    /// Which solver.
    pub kind: SolverKind,
    /// Relative tolerance on the equilibrium residual and complementarity.
    pub tol: f64,
    /// Iteration limit per step (Newton iterations, or outer fixed-point iterations).
    pub max_iterations: usize,
    /// Penalty parameter omega of the paper's solver (force / length^2); None: automatic.
    pub omega: Option<f64>,
    /// Relaxation rho in (0, 1] of the paper's solver.
    pub rho: f64,
    /// Newton only: end each step after this many iterations and keep the iterate,
    /// converged or not (what a code with a fixed iteration count writes: `grade`'s tests
    /// of unconverged files). `None`: iterate to the tolerance.
    pub stop_after: Option<usize>,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            kind: SolverKind::Newton,
            tol: 1e-10,
            max_iterations: 60,
            omega: None,
            rho: 0.5,
            stop_after: None,
        }
    }
}

/// The discrete problem on one mesh with one cone.
#[derive(Debug, Clone)]
pub struct Problem {
    /// Elements, dofs and loads.
    pub model: Model,
    /// Gamma_C.
    pub interface: Interface,
    /// The cone.
    pub method: Method,
    /// Constraint rows of the cone.
    pub rows: Vec<Row>,
}

impl Problem {
    /// Assemble the constraint rows of `method` for `model` and `interface`.
    pub fn new(model: Model, interface: Interface, method: Method) -> Self {
        let rows = contact::constraint_rows(&model, &interface, method);
        Problem {
            model,
            interface,
            method,
            rows,
        }
    }

    /// The constraint rows over the free unknowns: per row, (equation, coefficient) for
    /// each entry on a free dof (the rows of the Newton system).
    pub fn free_rows(&self) -> Vec<Vec<(usize, f64)>> {
        let equation = &self.model.equation;
        (self.rows.iter())
            .map(|r| {
                (r.entries.iter())
                    .map(|&(d, v)| (equation[d], v))
                    .filter(|&(eq, _)| eq != crate::fe::FIXED)
                    .collect()
            })
            .collect()
    }
}

/// The discrete state at one time t_n.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct State {
    /// Time t_n.
    pub time: f64,
    /// Nodal displacements over global dofs (x, y per node), length units.
    pub u: Vec<f64>,
    /// Stress per element (tensor components), stress units.
    pub sigma: Vec<Stress>,
    /// Contact multipliers per constraint row (nodal forces, force units, >= 0).
    pub lambda: Vec<f64>,
}

/// What one time step cost and why it stopped.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct StepReport {
    /// Iterations (Newton iterations; for the fixed-point solvers, inner solves).
    pub iterations: usize,
    /// Outer iterations (fixed point); equals `iterations` for Newton.
    pub outer_iterations: usize,
    /// Final relative equilibrium residual.
    pub residual: f64,
    /// Active-set changes during the step.
    pub active_set_changes: usize,
    /// Why the iteration stopped.
    pub reason: String,
}

/// Where the time of a solve went (s), and the factorization count.
#[derive(Debug, Clone, Copy, Default, serde::Serialize, serde::Deserialize)]
pub struct Timings {
    /// Assembling internal forces and tangent stiffnesses.
    pub assembly_s: f64,
    /// Numeric factorizations (for `qp`, also Clarabel's solves).
    pub factor_s: f64,
    /// Triangular solves.
    pub solve_s: f64,
    /// Constitutive updates (return map per triangle).
    pub constitutive_s: f64,
    /// Contact rows: gaps and C^T lambda.
    pub contact_s: f64,
    /// Number of numeric factorizations.
    pub factorizations: usize,
    /// Number of right-hand sides solved with a factorization.
    pub solves: usize,
    /// One-off set-up per mesh: the matrix pattern with its entry-to-slot map and the
    /// symbolic analysis (ordering). Not part of the time loop (`Solution::wall_s`).
    pub setup_s: f64,
    /// The fill of the stiffness's factor, entries of L ([`ordering::factor_entries`]);
    /// 0 for a solver without one.
    #[serde(default)]
    pub factor_entries: usize,
    /// Flops of one numeric factorization of the stiffness (a multiply-add counts 2)
    /// ([`ordering::flops`]); 0 for a solver without one.
    #[serde(default)]
    pub factor_flops: f64,
}

/// Run `f`, adding its wall time to `cell`.
pub fn timed<T>(cell: &std::cell::Cell<f64>, f: impl FnOnce() -> T) -> T {
    let t = Instant::now();
    let r = f();
    cell.set(cell.get() + t.elapsed().as_secs_f64());
    r
}

/// A solved history.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Solution {
    /// States t_0 .. t_N (all of them when `keep_history`, else t_0 and t_N).
    pub states: Vec<State>,
    /// One report per step.
    pub reports: Vec<StepReport>,
    /// Wall time of the time loop (s): everything the steps do, without the one-off
    /// set-up (`timings.setup_s`).
    pub wall_s: f64,
    /// Where the time went (factorizations, solves, ...).
    pub timings: Timings,
}

impl Solution {
    /// The final state.
    pub fn last(&self) -> &State {
        self.states.last().expect("at least the initial state")
    }
    /// Sum of iterations over the steps.
    pub fn iterations(&self) -> usize {
        self.reports.iter().map(|r| r.iterations).sum()
    }
    /// Largest iteration count of one step.
    pub fn max_step_iterations(&self) -> usize {
        self.reports.iter().map(|r| r.iterations).max().unwrap_or(0)
    }
    /// Active-set changes summed over the steps.
    pub fn active_set_changes(&self) -> usize {
        self.reports.iter().map(|r| r.active_set_changes).sum()
    }
}

/// One solver's per-step interface.
pub trait StepSolver {
    /// Advance from `prev` to time `t` with step `k`, starting from `guess`.
    fn step(&mut self, prev: &State, guess: &State, t: f64, k: f64) -> Result<(State, StepReport)>;
    /// Where the time went so far.
    fn timings(&self) -> Timings;
}

/// How far `state` is from solving (2.1) at the load `f_ext`, relative to the force scale
/// max(|F|, |f_int|) over the free dofs: the equilibrium residual |f_int - F + C^T lambda|
/// and the complementarity max_i |min(lambda_i, -c g_i)| (g = C u - gap turned into forces
/// by `c`, the mean diagonal of the stiffness). Every solver stops when both are below its
/// tolerance.
pub fn distance_to_solution(p: &Problem, state: &State, f_ext: &[f64], c: f64) -> (f64, f64) {
    let mut r = p.model.internal_force(&state.sigma);
    let scale = inf_norm(&p.model.restrict(&r))
        .max(inf_norm(&p.model.restrict(f_ext)))
        .max(f64::MIN_POSITIVE);
    for (ri, f) in r.iter_mut().zip(f_ext) {
        *ri -= f;
    }
    contact::add_transpose(&p.rows, &state.lambda, &mut r);
    let residual = inf_norm(&p.model.restrict(&r)) / scale;
    let gaps = contact::constraint_values(&p.rows, &state.u);
    (residual, complementarity(&state.lambda, &gaps, c) / scale)
}

/// The complementarity max_i |min(lambda_i, -c g_i)| of multipliers and constraint values
/// (force): zero exactly when lambda >= 0, g <= 0 and lambda g = 0.
pub fn complementarity(lambda: &[f64], gaps: &[f64], c: f64) -> f64 {
    lambda
        .iter()
        .zip(gaps)
        .map(|(l, g)| l.min(-c * g).abs())
        .fold(0.0f64, f64::max)
}

/// Solve the history on `steps` uniform steps over [0, T]; zero initial state.
pub fn solve(
    p: &Problem,
    settings: &Settings,
    steps: usize,
    keep_history: bool,
) -> Result<Solution> {
    solve_times(p, settings, &uniform_times(p, steps)?, keep_history)
}

/// `steps` uniform time steps over [0, T]: t_1, ..., t_N = T.
fn uniform_times(p: &Problem, steps: usize) -> Result<Vec<f64>> {
    if steps == 0 {
        return Err(Error::input(
            &p.model.scene.file,
            "steps",
            "the number of time steps must be at least 1",
        ));
    }
    let k = p.model.scene.final_time / steps as f64;
    Ok((1..=steps).map(|n| n as f64 * k).collect())
}

/// Called after every solved step with the step's number n (from 1), the number of steps,
/// the state and its report; its time is left out of the solution's `wall_s`. An error
/// stops the run.
pub type StepObserver<'o> = dyn FnMut(usize, usize, &State, &StepReport) -> Result<()> + 'o;

/// [`solve`] with `observer` called after every step (progress, a time series); only the
/// initial and the final state are kept.
pub fn solve_observed(
    p: &Problem,
    settings: &Settings,
    steps: usize,
    observer: &mut StepObserver,
) -> Result<Solution> {
    run_steps(p, settings, &uniform_times(p, steps)?, false, observer)
}

/// States before the last one used by the predictor (HISTORY + 1 points: polynomial
/// extrapolation of degree HISTORY).
const HISTORY: usize = 2;

/// Solve the history on the time grid `times` (t_1 < ... < t_N, t_0 = 0).
pub fn solve_times(
    p: &Problem,
    settings: &Settings,
    times: &[f64],
    keep_history: bool,
) -> Result<Solution> {
    run_steps(p, settings, times, keep_history, &mut |_, _, _, _| Ok(()))
}

/// The time loop of [`solve_times`] with an observer of every step.
fn run_steps(
    p: &Problem,
    settings: &Settings,
    times: &[f64],
    keep_history: bool,
    observer: &mut StepObserver,
) -> Result<Solution> {
    check_times(p, times)?;
    let steps = times.len();
    let start = Instant::now();
    let initial = initial_state(p);
    let mut solver = step_solver(p, settings)?;
    // t_0 for a run that keeps only t_0 and t_N (a run keeping every state moves them).
    let first = (!keep_history).then(|| initial.clone());
    let mut states = Vec::new();
    let mut reports = Vec::new();
    // The last HISTORY + 1 states, oldest first: `prev` and the predictor's points. A state
    // leaving it moves into `states` when every state is kept (no copy of its fields).
    let mut window: Vec<State> = vec![initial];
    let mut observer_s = 0.0;
    for n in 1..=steps {
        let t = times[n - 1];
        let prev = window.last().expect("the window holds prev");
        let k = t - prev.time;
        let guess = predictor(&window, t);
        let (state, report) = solver.step(prev, &guess, t, k).map_err(|e| match e {
            Error::NotConverged(m) => Error::NotConverged(format!(
                "{} solver, {} cone, step {n} of {steps} (t = {t}): {m}",
                settings.kind.name(),
                p.method.name()
            )),
            other => other,
        })?;
        let observed = Instant::now();
        observer(n, steps, &state, &report)?;
        observer_s += observed.elapsed().as_secs_f64();
        reports.push(report);
        window.push(state);
        if window.len() > HISTORY + 1 {
            let oldest = window.remove(0);
            if keep_history {
                states.push(oldest);
            }
        }
    }
    match first {
        Some(first) => {
            states.push(first);
            states.push(window.pop().expect("the window holds t_N"));
        }
        None => states.extend(window),
    }
    let timings = solver.timings();
    Ok(Solution {
        states,
        reports,
        wall_s: start.elapsed().as_secs_f64() - timings.setup_s - observer_s,
        timings,
    })
}

/// Errs unless `times` are positive and increasing (t_0 = 0 before them).
fn check_times(p: &Problem, times: &[f64]) -> Result<()> {
    if times.is_empty() || times[0] <= 0.0 || times.windows(2).any(|w| w[1] <= w[0]) {
        return Err(Error::input(
            &p.model.scene.file,
            "time steps",
            "time steps k must be positive: t_1 > 0 and the times increasing",
        ));
    }
    Ok(())
}

/// The zero state at t_0 = 0.
fn initial_state(p: &Problem) -> State {
    State {
        time: 0.0,
        u: vec![0.0; 2 * p.model.n_nodes],
        sigma: vec![Stress::zeros(); p.model.elements.len()],
        lambda: vec![0.0; p.rows.len()],
    }
}

/// The solver of `settings.kind` for `p`, set up (pattern, factorization).
fn step_solver<'p>(p: &'p Problem, settings: &Settings) -> Result<Box<dyn StepSolver + 'p>> {
    Ok(match settings.kind {
        SolverKind::Newton => Box::new(newton::Newton::new(p, settings)?),
        SolverKind::Paper => Box::new(fixed_point::FixedPoint::new(
            p,
            settings,
            fixed_point::Inner::PenaltyDuality,
        )?),
        SolverKind::Qp => Box::new(fixed_point::FixedPoint::new(
            p,
            settings,
            fixed_point::Inner::Clarabel,
        )?),
    })
}

/// The warm start of the step to `t`: the Lagrange extrapolation through the states of
/// `window` (the last three; two at the second step; at the first, the initial state
/// itself): the steps' Newton iterations start closer to the solution. It has the
/// displacements and multipliers only, the multipliers clipped at 0.
fn predictor(window: &[State], t: f64) -> State {
    let points: Vec<&State> = window.iter().rev().collect();
    let weights: Vec<f64> = (0..points.len())
        .map(|i| {
            (0..points.len())
                .filter(|&j| j != i)
                .map(|j| (t - points[j].time) / (points[i].time - points[j].time))
                .product()
        })
        .collect();
    // sum_i w_i field(point i), the terms of each entry in the order of the points.
    let mix = |field: &dyn Fn(&State) -> &[f64]| -> Vec<f64> {
        let mut sum: Vec<f64> = field(points[0]).iter().map(|v| weights[0] * v).collect();
        for (s, w) in points.iter().zip(&weights).skip(1) {
            for (total, v) in sum.iter_mut().zip(field(s)) {
                *total += w * v;
            }
        }
        sum
    };
    State {
        time: t,
        u: mix(&|s: &State| s.u.as_slice()),
        // The solvers read the guess's displacements and multipliers only.
        sigma: Vec::new(),
        lambda: mix(&|s: &State| s.lambda.as_slice())
            .into_iter()
            .map(|l| l.max(0.0))
            .collect(),
    }
}
