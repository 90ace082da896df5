//! What a study's levels are measured against, the truth: a fine reference solve on
//! matching meshes with the estimate of its own error, or a scene's exact solution; and
//! every quantity's relative error of one solved level against it (max over the steps).

use crate::analytical::Exact;
use crate::case::Case;
use crate::solve::{Solution, inf_norm};
use crate::verify::contact_error::{
    self, ContactStep, TruthPressure, contact_step, reference_profile,
};
use crate::verify::exact_error::{ExactComparison, ExactDifference};
use crate::verify::field::{P1Field, P1History};
use crate::verify::jobs::{JobId, Solved};
use crate::verify::norms::{self, Comparison, SquaredNorms};
use crate::verify::quantity::{Differences, Quantity};
use rayon::prelude::*;
use std::collections::BTreeMap;

/// The reference solution's facts.
#[derive(Debug, Clone, Copy)]
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
    );
    let d2 = relative_errors(
        &P1History::of_solution(&coarser2.0, &coarser2.1),
        &reference,
    );
    for q in Quantity::ALL {
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
        match self {
            Truth::Solved(reference) => relative_errors(history, reference),
            Truth::Exact(exact, points) => exact_errors(history, exact, *points),
        }
    }

    /// The estimated error of the truth in the theorem norm (0 for the exact solution).
    pub fn error(&self) -> f64 {
        self.quantity_error(Quantity::Theorem)
    }

    /// The estimated error of the truth in quantity `q` (0 for the exact solution).
    pub fn quantity_error(&self, q: Quantity) -> f64 {
        match self {
            Truth::Solved(r) => r.quantity_errors[&q],
            Truth::Exact(..) => 0.0,
        }
    }
}

/// Every quantity's relative error of a discrete solution against the exact solution.
pub fn exact_errors(history: &P1History, exact: &Exact, points: usize) -> BTreeMap<Quantity, f64> {
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
    Differences {
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
    }
    .relative()
}

/// The largest interpenetration over a solution's history (length).
pub fn history_penetration(history: &P1History) -> f64 {
    history
        .steps
        .iter()
        .flat_map(|s| crate::contact::normal_jumps(history.interface, &s.u))
        .map(|j| j.2)
        .fold(0.0f64, f64::max)
}

/// Every quantity's relative error of a discrete solution against the reference.
pub fn relative_errors(
    history: &P1History,
    reference: &ReferenceSolution,
) -> BTreeMap<Quantity, f64> {
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
    Differences {
        fields: &fields,
        reference: &reference.norms,
        pressure: pressure.as_deref(),
        penetration: history_penetration(history),
        reference_displacement: reference.max_displacement,
        contact: &contact,
        band_stress: &band_stress,
        contact_length: interface.length(),
    }
    .relative()
}

/// A reference solve's pressure (this project's solver always gives one).
fn reference_pressure<'a>(r: &'a P1Field) -> &'a crate::verify::field::PressureProfile {
    r.pressure
        .as_ref()
        .expect("a reference solve gives a pressure")
}
