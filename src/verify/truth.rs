//! What a study's levels are measured against, the truth: a fine reference solve on
//! matching meshes with the estimate of its own error, or a scene's exact solution; and
//! every quantity's relative error of one solved level against it (max over the steps).

use crate::analytical::Exact;
use crate::case::Case;
use crate::contact::Interface;
use crate::solve::{Solution, inf_norm};
use crate::verify::contact_error::{
    self, ContactStep, TruthPressure, contact_step, piece_jumps, reference_profile,
};
use crate::verify::exact_error::{ExactComparison, ExactDifference};
use crate::verify::field::{P1Field, P1History};
use crate::verify::jobs::{JobId, Solved};
use crate::verify::norms::{self, Comparison, SquaredNorms};
use crate::verify::quantity::{Differences, Quantity, Scale};
use rayon::prelude::*;
use std::collections::BTreeMap;

/// The reference solution's facts.
#[derive(Debug, Clone, Copy, serde::Serialize, serde::Deserialize)]
pub struct Reference {
    /// Mesh level.
    pub level: usize,
    /// Max element diameter (length).
    pub h: f64,
    /// Free dofs.
    pub dofs: usize,
    /// Wall time of its solve (s).
    pub wall_s: f64,
    /// Its estimated relative error in the theorem norm.
    pub error: f64,
    /// The rate p of the nested-space model used for that estimate.
    pub error_rate: f64,
}

/// The reference solution with what every level is measured against.
pub struct ReferenceSolution {
    pub case: Case,
    pub solution: Solution,
    /// Squared norms per step t_1..t_N.
    pub norms: Vec<SquaredNorms>,
    /// Largest |u| over the history (length).
    pub max_displacement: f64,
    pub facts: Reference,
    /// Each quantity's estimated own error (the same nested-space model per quantity).
    pub quantity_errors: BTreeMap<Quantity, f64>,
}

/// The estimated relative error of a reference R and the rate p of the model, from its
/// distances d1 = d(R-1, R) and d2 = d(R-2, R) to its two coarser nested levels: with
/// e_L = C h_L^p and d(L, R)^2 = e_L^2 - e_R^2, (d2 / d1)^2 = 4^p + 1 and
/// e_R = d1 / sqrt(4^p - 1). p is kept in [0.25, 3].
pub fn estimated_reference_error(d1: f64, d2: f64) -> (f64, f64) {
    let p = ((d2 / d1).powi(2) - 1.0)
        .max(1.0 + 1e-12)
        .log(4.0)
        .clamp(0.25, 3.0);
    (d1 / (4f64.powf(p) - 1.0).sqrt(), p)
}

/// The reference and the estimate of its own error. The reference levels are nested
/// conforming spaces, so their errors are close to orthogonal: d(L, R)^2 = e_L^2 - e_R^2 with
/// e_L = C h_L^p (measured on the rates scene: d(R-2,R)/d(R-1,R) = 2.24 = sqrt(5), i.e.
/// p = 1). Hence (d(R-2,R)/d(R-1,R))^2 = 4^p + 1 and e_R = d(R-1,R) / sqrt(4^p - 1).
pub fn reference(ids: [JobId; 3], solved: &mut Solved, level: usize) -> ReferenceSolution {
    let [coarser2, coarser1, finest] = ids.map(|id| solved.take(id));
    let (case, solution) = finest;
    let norms = P1History::of_solution(&case, &solution)
        .steps
        .iter()
        .map(|s| norms::norms(&case.problem.model, s))
        .collect();
    let max_displacement = solution
        .states
        .iter()
        .map(|s| inf_norm(&s.u))
        .fold(0.0f64, f64::max);
    let facts = Reference {
        level,
        h: case.h,
        dofs: case.problem.model.n_free,
        wall_s: solution.wall_s,
        error: 0.0,
        error_rate: 0.0,
    };
    let mut reference = ReferenceSolution {
        case,
        solution,
        norms,
        max_displacement,
        facts,
        quantity_errors: BTreeMap::new(),
    };
    // Every quantity's distances of the two coarser levels to the reference.
    let d1 = relative_errors(
        &P1History::of_solution(&coarser1.0, &coarser1.1),
        &reference,
    )
    .0;
    let d2 = relative_errors(
        &P1History::of_solution(&coarser2.0, &coarser2.1),
        &reference,
    )
    .0;
    for q in d1.keys().copied().collect::<Vec<_>>() {
        let (error, rate) = estimated_reference_error(d1[&q], d2[&q]);
        if q == Quantity::Theorem {
            (reference.facts.error, reference.facts.error_rate) = (error, rate);
        }
        reference
            .quantity_errors
            .insert(q, if d1[&q] > 0.0 { error } else { 0.0 });
    }
    reference
}

/// What the levels are measured against.
pub enum Truth<'s> {
    /// A fine reference solve on matching meshes.
    Solved(ReferenceSolution),
    /// The scene's exact solution, with the Gauss points per direction of the rule.
    Exact(&'s Exact, usize),
}

impl Truth<'_> {
    /// Every quantity's relative error of one solved level.
    pub fn relative_errors(&self, case: &Case, sol: &Solution) -> BTreeMap<Quantity, f64> {
        self.errors(&P1History::of_solution(case, sol))
    }

    /// Every quantity's relative error of a discrete solution, whoever computed it (the
    /// pressure quantities only when it gives a pressure).
    pub fn errors(&self, history: &P1History) -> BTreeMap<Quantity, f64> {
        self.measure(history).0
    }

    /// [`Truth::errors`] with the truth's sizes they are relative to.
    pub fn measure(&self, history: &P1History) -> (BTreeMap<Quantity, f64>, Scale) {
        match self {
            Truth::Solved(reference) => relative_errors(history, reference),
            Truth::Exact(exact, points) => exact_errors(history, exact, *points),
        }
    }

    /// [`Truth::measure`] of one solved level.
    pub fn measure_solved(&self, case: &Case, sol: &Solution) -> (BTreeMap<Quantity, f64>, Scale) {
        self.measure(&P1History::of_solution(case, sol))
    }

    /// The estimated error of the truth in the theorem norm (0 for the exact solution).
    pub fn error(&self) -> f64 {
        self.quantity_error(Quantity::Theorem)
    }

    /// The estimated error of the truth in quantity `q` (0 for the exact solution, and for a
    /// distance between the cones: two discrete solutions, which the truth's error does not
    /// limit).
    pub fn quantity_error(&self, q: Quantity) -> f64 {
        match self {
            Truth::Solved(_) if q.is_distance() => 0.0,
            Truth::Solved(r) => r.quantity_errors.get(&q).copied().unwrap_or(0.0),
            Truth::Exact(..) => 0.0,
        }
    }
}

/// Every quantity's relative error of a discrete solution against the exact solution.
pub fn exact_errors(
    history: &P1History,
    exact: &Exact,
    points: usize,
) -> (BTreeMap<Quantity, f64>, Scale) {
    let (model, interface) = (history.model, history.interface);
    let cmp = ExactComparison::new(exact, points);
    // Steps are independent: measured in parallel, in step order (the same bits).
    let diffs: Vec<ExactDifference> = history
        .steps
        .par_iter()
        .map(|s| cmp.difference(model, interface, s))
        .collect();
    let fields: Vec<SquaredNorms> = diffs.iter().map(|d| d.difference).collect();
    let reference: Vec<SquaredNorms> = diffs.iter().map(|d| d.exact).collect();
    let pressure: Option<Vec<(f64, f64)>> = diffs.iter().map(|d| d.pressure).collect();
    let band_stress: Vec<f64> = diffs.iter().map(|d| d.band_stress).collect();
    let contact: Vec<ContactStep> = history
        .steps
        .par_iter()
        .map(|s| contact_step(interface, s, &TruthPressure::Exact(exact, s.time)))
        .collect();
    let differences = Differences {
        fields: &fields,
        reference: &reference,
        pressure: pressure.as_deref(),
        penetration: history_penetration(history),
        reference_displacement: match exact.displacement {
            Some(_) => diffs.iter().map(|d| d.max_displacement).fold(0.0, f64::max),
            None => history
                .steps
                .iter()
                .map(|s| inf_norm(&s.u))
                .fold(0.0, f64::max),
        },
        contact: &contact,
        band_stress: &band_stress,
        contact_length: interface.length(),
    };
    let (mut errors, scale) = (differences.relative(), differences.scale());
    // The best approximation of the exact pressure in the solution's own pressure space,
    // relative as l2_pressure (max over the steps).
    let best: Option<Vec<f64>> = history
        .steps
        .par_iter()
        .map(|s| {
            let profile = s.pressure.as_ref()?;
            Some(cmp.best_pressure_error(interface, profile, s.pressure_space, s.time))
        })
        .collect();
    if let (Some(best), Some(size)) = (best, scale.pressure) {
        let value = best.iter().map(|b| b.sqrt()).fold(0.0f64, f64::max);
        if let Some(v) = crate::verify::rates::relative_to(value, size, scale.theorem) {
            errors.insert(Quantity::BestL2Pressure, v);
        }
    }
    if exact.stress.is_some() {
        let term = history
            .steps
            .par_iter()
            .map(|s| consistency_term(interface, s, exact))
            .collect::<Vec<f64>>()
            .into_iter()
            .fold(0.0f64, f64::max);
        // |int sigma_nu [u_h.nu]| is an energy (Proposition 3.1 bounds the squared energy
        // norm of the error by it): its square root is relative to the exact solution's
        // energy norm sqrt(int sigma : eps(u)), max over the steps.
        let energy = diffs
            .iter()
            .map(|d| d.energy.abs())
            .fold(0.0f64, f64::max)
            .sqrt();
        // A size the truth lacks measures nothing (verify::rates::relative_to): no row.
        if let Some(v) = crate::verify::rates::relative_to(term, energy, scale.theorem) {
            errors.insert(Quantity::Consistency, v);
        }
    }
    (errors, scale)
}

/// The largest interpenetration [u.nu] - g0 over a solution's history (length; g0 the
/// initial gap between the discrete traces at each trace node).
pub fn history_penetration(history: &P1History) -> f64 {
    history
        .steps
        .iter()
        .flat_map(|s| crate::contact::penetrations(history.interface, &s.u))
        .map(|j| j.2)
        .fold(0.0f64, f64::max)
}

/// Every quantity's relative error of a discrete solution against the reference, with the
/// reference's sizes.
pub fn relative_errors(
    history: &P1History,
    reference: &ReferenceSolution,
) -> (BTreeMap<Quantity, f64>, Scale) {
    let (model, interface) = (history.model, history.interface);
    let rproblem = &reference.case.problem;
    let (rmodel, rinterface) = (&rproblem.model, &rproblem.interface);
    let references = P1History::of_solution(&reference.case, &reference.solution);
    let cmp = Comparison::new(model, rmodel);
    let steps = || history.steps.iter().zip(&references.steps);
    let fields: Vec<SquaredNorms> = steps()
        .map(|(s, r)| cmp.difference(model, s, rmodel, r))
        .collect();
    let pressure: Option<Vec<(f64, f64)>> = steps()
        .map(|(s, r)| {
            Some(norms::pressure_difference(
                interface,
                s.pressure.as_ref()?,
                reference_pressure(r),
            ))
        })
        .collect();
    let band = contact_error::band(model, interface);
    let band_stress: Vec<f64> = steps().map(|(s, r)| cmp.band_stress(s, r, &band)).collect();
    let contact: Vec<ContactStep> = steps()
        .map(|(s, r)| {
            let truth = reference_profile(interface, rinterface, &r.u, reference_pressure(r));
            contact_step(interface, s, &truth)
        })
        .collect();
    let differences = Differences {
        fields: &fields,
        reference: &reference.norms,
        pressure: pressure.as_deref(),
        penetration: history_penetration(history),
        reference_displacement: reference.max_displacement,
        contact: &contact,
        band_stress: &band_stress,
        contact_length: interface.length(),
    };
    (differences.relative(), differences.scale())
}

/// |int_Gamma_C sigma_nu ([u_h.nu] - g0)|^(1/2) at one step, sigma_nu = nu^1 . sigma nu^1 of
/// the exact slave stress (zero where the bodies separate), g0 the initial gap between the
/// discrete traces (zero where they touch) and [u_h.nu] - g0 linear between the merged
/// trace nodes of both bodies: 8 Gauss points per stretch between breakpoints (the traces'
/// nodes and the exact fields' kinks).
pub fn consistency_term(interface: &Interface, s: &P1Field, exact: &Exact) -> f64 {
    let gauss = crate::quadrature::gauss_legendre(8);
    let jumps = crate::contact::penetrations(interface, &s.u);
    let kinks = crate::expr::kink_functions(&exact.contact_kinks(), s.time);
    let mut total = 0.0;
    for (pi, piece) in interface.pieces.iter().enumerate() {
        let mut f = piece_jumps(&jumps, pi);
        f.dedup_by(|a, b| (a.0 - b.0).abs() <= 1e-14 * piece.length);
        let mut breaks: Vec<f64> = f.iter().map(|p| p.0).collect();
        let (a, b) = (piece.point(0.0), piece.point(piece.length));
        breaks.extend(
            crate::quadrature::segment_breaks(a, b, &kinks)
                .into_iter()
                .map(|r| r * piece.length),
        );
        breaks.sort_by(f64::total_cmp);
        breaks.dedup_by(|a, b| (*a - *b).abs() <= 1e-14 * piece.length);
        let n = piece.normal;
        for w in breaks.windows(2) {
            let len = w[1] - w[0];
            if len <= 0.0 {
                continue;
            }
            for &(q, wq) in &gauss {
                let sq = w[0] + q * len;
                let x = piece.point(sq);
                let Some(st) = exact.stress_at(0, x[0], x[1], s.time) else {
                    continue;
                };
                let snn = n[0] * n[0] * st[0] + 2.0 * n[0] * n[1] * st[2] + n[1] * n[1] * st[1];
                total += wq * len * snn * super::norms::eval_pl(&f, sq);
            }
        }
    }
    total.abs().sqrt()
}

/// A reference solve's pressure (this project's solver always gives one).
fn reference_pressure<'a>(r: &'a P1Field) -> &'a crate::verify::field::PressureProfile {
    r.pressure
        .as_ref()
        .expect("a reference solve gives a pressure")
}
