//! The quantities a convergence study measures, each a relative error of one time history
//! against the reference's (max over the time steps).

use super::contact_error::{ContactStep, PressureStep};
use super::norms::SquaredNorms;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// One measured quantity. Written in files by its [`Quantity::name`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(try_from = "String")]
pub enum Quantity {
    /// max_n (||u - u_ref||_H1 + ||sigma - sigma_ref||_L2), Theorem 3.1's norm.
    #[serde(rename = "theorem")]
    Theorem,
    /// max_n ||u - u_ref||_H1.
    #[serde(rename = "h1_u")]
    H1U,
    /// max_n ||u - u_ref||_L2.
    #[serde(rename = "l2_u")]
    L2U,
    /// max_n ||sigma - sigma_ref||_L2.
    #[serde(rename = "l2_stress")]
    L2Stress,
    /// max_n ||p - p_ref||_L2(Gamma_C).
    #[serde(rename = "l2_pressure")]
    L2Pressure,
    /// The error of the best approximation of the exact pressure in the method's own
    /// pressure space on the level (its L2(Gamma_C) projection: piecewise linear on the
    /// body-1 trace for the nodal rows, constant on each macro-element for lac), relative as
    /// l2_pressure: what no solution in that space can beat.
    #[serde(rename = "best_l2_pressure")]
    BestL2Pressure,
    /// Largest interpenetration over the history, relative to max |u_ref|.
    #[serde(rename = "max_penetration")]
    MaxPenetration,
    /// max_n ||sigma - sigma_ref||_L2 over the triangles touching Gamma_C, relative to the
    /// reference's stress norm over both bodies: a consistency error of fixed size in the
    /// one-element layer then shows as h^(1/2) (relative to the band's own norm, which
    /// shrinks like h^(1/2) too, it would not converge at all).
    #[serde(rename = "band_stress")]
    BandStress,
    /// Largest distance of a contact edge of the truth to the nearest discrete one, relative
    /// to the length of Gamma_C.
    #[serde(rename = "contact_edge")]
    ContactEdge,
    /// max_n |int p - int p_ref| / max_n int |p_ref|: the resultant contact force.
    #[serde(rename = "pressure_resultant")]
    PressureResultant,
    /// max_n ||h^(1/2) (p - p_ref)||_L2(Gamma_C) / (|Gamma_C|^(1/2) max_n ||p_ref||): the
    /// discrete stand-in for H^(-1/2) (one half order above the L2 rate).
    #[serde(rename = "pressure_weighted")]
    PressureWeighted,
    /// max_n |TV(p) - TV(p_ref)| / max_n max(TV(p_ref), max |p_ref|): oscillation of the
    /// pressure (the second scale keeps it defined for a constant truth).
    #[serde(rename = "pressure_oscillation")]
    PressureOscillation,
    /// max_n ||[u.nu]^+||_L2(Gamma_C), relative to |Gamma_C|^(1/2) max |u_ref|.
    #[serde(rename = "l2_penetration")]
    L2Penetration,
    /// Proposition 3.1's consistency term max_n |int_Gamma_C sigma_nu [u_h.nu]|^(1/2), with
    /// the exact sigma_nu, relative to the exact solution's energy norm (int sigma : eps(u))^(1/2)
    /// (both are square roots of energies): the part of the error the
    /// discrete contact condition adds (it vanishes for a cone inside the continuous one).
    #[serde(rename = "consistency")]
    Consistency,
    /// The distance between the two cones' solutions on the same meshes, D = max_n
    /// (||u^I - u^pi||_H1 + ||sigma^I - sigma^pi||_L2), relative to the truth's theorem norm:
    /// D - e_mortar <= e_nts <= D + e_mortar, so D falling like h^(1/2) while e_mortar
    /// falls like h shows an h^(1/2) part in nts's error. Listed under nts.
    #[serde(rename = "cone_distance")]
    ConeDistance,
    /// D in ||.||_H1 of the displacement, relative as h1_u.
    #[serde(rename = "cone_distance_h1_u")]
    ConeDistanceH1U,
    /// D in ||.||_L2 of the stress, relative as l2_stress.
    #[serde(rename = "cone_distance_l2_stress")]
    ConeDistanceL2Stress,
    /// D in the stress over the triangles touching Gamma_C, relative as band_stress.
    #[serde(rename = "cone_distance_band_stress")]
    ConeDistanceBandStress,
    /// D in the pressure, L2(Gamma_C), relative as l2_pressure.
    #[serde(rename = "cone_distance_l2_pressure")]
    ConeDistanceL2Pressure,
    /// D in the normal jump [u.nu], L2(Gamma_C), relative as l2_penetration.
    #[serde(rename = "cone_distance_normal_jump")]
    ConeDistanceNormalJump,
    /// ||g_h - g||_L2(Gamma_C) / ||g||_L2(Gamma_C): the method's discrete initial gap (its
    /// rows' right-hand sides in its pressure space) against the initial gap g between the
    /// traces, measured where a scene has one (`verify::contact_error::discrete_gap_error`).
    #[serde(rename = "discrete_gap")]
    DiscreteGap,
}

impl Quantity {
    /// Every quantity, in the order reports list them.
    pub const ALL: [Quantity; 21] = [
        Quantity::Theorem,
        Quantity::H1U,
        Quantity::L2U,
        Quantity::L2Stress,
        Quantity::L2Pressure,
        Quantity::BestL2Pressure,
        Quantity::MaxPenetration,
        Quantity::BandStress,
        Quantity::ContactEdge,
        Quantity::PressureResultant,
        Quantity::PressureWeighted,
        Quantity::PressureOscillation,
        Quantity::L2Penetration,
        Quantity::Consistency,
        Quantity::ConeDistance,
        Quantity::ConeDistanceH1U,
        Quantity::ConeDistanceL2Stress,
        Quantity::ConeDistanceBandStress,
        Quantity::ConeDistanceL2Pressure,
        Quantity::ConeDistanceNormalJump,
        Quantity::DiscreteGap,
    ];

    /// The distances between the two cones (measured between two solutions, not against
    /// the truth).
    pub const DISTANCES: [Quantity; 6] = [
        Quantity::ConeDistance,
        Quantity::ConeDistanceH1U,
        Quantity::ConeDistanceL2Stress,
        Quantity::ConeDistanceBandStress,
        Quantity::ConeDistanceL2Pressure,
        Quantity::ConeDistanceNormalJump,
    ];

    /// The quantities of one solution that need its discrete pressure (measured only where
    /// the solution gives one).
    pub const PRESSURE: [Quantity; 6] = [
        Quantity::L2Pressure,
        Quantity::BestL2Pressure,
        Quantity::PressureWeighted,
        Quantity::PressureResultant,
        Quantity::PressureOscillation,
        Quantity::ContactEdge,
    ];

    /// Whether it needs the solution's discrete pressure.
    pub fn needs_pressure(self) -> bool {
        Self::PRESSURE.contains(&self)
    }

    /// Whether it measures the method's space rather than its solution (the best
    /// approximation of the exact pressure): no comparison of methods reads it as an error.
    pub fn is_best_approximation(self) -> bool {
        self == Quantity::BestL2Pressure
    }

    /// Whether it reads the method's constraint rows (the discrete gap on their right-hand
    /// sides), which a field on a mesh does not carry: measured by the studies, never from
    /// a solution alone (`Truth::errors`, grade).
    pub fn reads_rows(self) -> bool {
        self == Quantity::DiscreteGap
    }

    /// Whether it is a distance between the two cones.
    pub fn is_distance(self) -> bool {
        Self::DISTANCES.contains(&self)
    }

    /// The quantities measured on Gamma_C and next to it, where the cones differ.
    pub const CONTACT: [Quantity; 9] = [
        Quantity::DiscreteGap,
        Quantity::BandStress,
        Quantity::ContactEdge,
        Quantity::L2Pressure,
        Quantity::PressureWeighted,
        Quantity::PressureResultant,
        Quantity::PressureOscillation,
        Quantity::MaxPenetration,
        Quantity::L2Penetration,
    ];

    /// Whether it is measured on Gamma_C or next to it.
    pub fn is_contact(self) -> bool {
        Self::CONTACT.contains(&self)
    }

    /// What it measures, in one sentence for a reader who has not read the code: the
    /// glossary of docs/studies.md and of every grade report ([`glossary`]). Every quantity
    /// is a relative error, the max over the time steps.
    pub fn meaning(self) -> &'static str {
        match self {
            Quantity::Theorem => {
                "Theorem 3.1's norm: ||u - u_ref||_H1 + ||sigma - sigma_ref||_L2 over both bodies, relative to the truth's."
            }
            Quantity::H1U => {
                "the displacement's error in the H1 norm over both bodies, relative to the truth's H1 norm."
            }
            Quantity::L2U => {
                "the displacement's error in the L2 norm over both bodies, relative to the truth's L2 norm."
            }
            Quantity::L2Stress => {
                "the stress's error in the L2 norm over both bodies, relative to the truth's."
            }
            Quantity::L2Pressure => {
                "the contact pressure's error in L2(Gamma_C), relative to the truth's pressure norm."
            }
            Quantity::BestL2Pressure => {
                "the error of the best approximation of the exact pressure in the method's own pressure space (piecewise linear on the body-1 trace for mortar and nts, constant per macro-element for lac): what no solution in that space can beat (exact studies only)."
            }
            Quantity::MaxPenetration => {
                "the largest interpenetration ([u.nu] - g0)^+ on Gamma_C (g0 the initial gap, 0 where the bodies touch), relative to max |u_ref|."
            }
            Quantity::BandStress => {
                "the stress's error on the one layer of triangles that touch Gamma_C, relative to the stress norm over both bodies: where a contact condition's consistency error sits (a fixed error in that layer shows as h^(1/2))."
            }
            Quantity::ContactEdge => {
                "the largest distance from an edge of the truth's contact zone to the nearest discrete one, relative to |Gamma_C| (1 where the discrete solution has no edge and the truth has one)."
            }
            Quantity::PressureResultant => {
                "the error of the resultant contact force (int p over Gamma_C), relative to the truth's."
            }
            Quantity::PressureWeighted => {
                "||h^(1/2) (p - p_ref)||_L2(Gamma_C) relative to |Gamma_C|^(1/2) ||p_ref||: a discrete stand-in for the pressure's H^(-1/2) error, the norm the theory bounds."
            }
            Quantity::PressureOscillation => {
                "|TV(p) - TV(p_ref)|, the error of the pressure's total variation along Gamma_C, relative to max(TV(p_ref), max |p_ref|) (the second keeps it defined for a constant truth): oscillations an L2 error may hide."
            }
            Quantity::L2Penetration => {
                "the L2(Gamma_C) norm of the interpenetration ([u.nu] - g0)^+, relative to |Gamma_C|^(1/2) max |u_ref|."
            }
            Quantity::Consistency => {
                "Proposition 3.1's consistency term |int_Gamma_C sigma_nu [u_h.nu]|^(1/2) with the exact sigma_nu, relative to the exact energy norm: the part of the error a discrete contact condition adds (0 for a cone inside the continuous one)."
            }
            Quantity::ConeDistance => {
                "D, the distance between a method's solution and mortar's on the same meshes, in the theorem norm, relative to the truth's: D - e_mortar <= e <= D + e_mortar."
            }
            Quantity::ConeDistanceH1U => "D in the displacement's H1 norm, relative as h1_u.",
            Quantity::ConeDistanceL2Stress => "D in the stress's L2 norm, relative as l2_stress.",
            Quantity::ConeDistanceBandStress => {
                "D in the stress on the triangles touching Gamma_C, relative as band_stress."
            }
            Quantity::ConeDistanceL2Pressure => {
                "D in the pressure on Gamma_C, relative as l2_pressure."
            }
            Quantity::ConeDistanceNormalJump => {
                "D in the normal jump [u.nu] on Gamma_C, relative as l2_penetration."
            }
            Quantity::DiscreteGap => {
                "the method's discrete initial gap (its rows' right-hand sides: linear between the body-1 nodes for mortar and nts, constant per macro-element for lac) against the initial gap between the traces, in L2(Gamma_C), relative to the gap's norm (scenes with a gap only)."
            }
        }
    }

    /// Name in study files and reports.
    pub fn name(self) -> &'static str {
        match self {
            Quantity::Theorem => "theorem",
            Quantity::H1U => "h1_u",
            Quantity::L2U => "l2_u",
            Quantity::L2Stress => "l2_stress",
            Quantity::L2Pressure => "l2_pressure",
            Quantity::BestL2Pressure => "best_l2_pressure",
            Quantity::MaxPenetration => "max_penetration",
            Quantity::BandStress => "band_stress",
            Quantity::ContactEdge => "contact_edge",
            Quantity::PressureResultant => "pressure_resultant",
            Quantity::PressureWeighted => "pressure_weighted",
            Quantity::PressureOscillation => "pressure_oscillation",
            Quantity::L2Penetration => "l2_penetration",
            Quantity::Consistency => "consistency",
            Quantity::ConeDistance => "cone_distance",
            Quantity::ConeDistanceH1U => "cone_distance_h1_u",
            Quantity::ConeDistanceL2Stress => "cone_distance_l2_stress",
            Quantity::ConeDistanceBandStress => "cone_distance_band_stress",
            Quantity::ConeDistanceL2Pressure => "cone_distance_l2_pressure",
            Quantity::ConeDistanceNormalJump => "cone_distance_normal_jump",
            Quantity::DiscreteGap => "discrete_gap",
        }
    }
}

impl TryFrom<String> for Quantity {
    type Error = String;
    fn try_from(s: String) -> Result<Self, String> {
        Quantity::ALL
            .into_iter()
            .find(|q| q.name() == s)
            .ok_or_else(|| {
                let names: Vec<&str> = Quantity::ALL.iter().map(|q| q.name()).collect();
                format!("unknown quantity '{s}'; use any of {}", names.join(", "))
            })
    }
}

impl std::fmt::Display for Quantity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.name())
    }
}

/// The truth's sizes that relative errors divide by, each the max over the steps t_1..t_N:
/// what a distance between two solutions is made relative to, as their errors are.
#[derive(Debug, Clone, Copy)]
pub struct Scale {
    /// ||u||_H1 + ||sigma||_L2.
    pub theorem: f64,
    /// ||u||_H1.
    pub h1: f64,
    /// ||sigma||_L2.
    pub stress: f64,
    /// ||p||_L2(Gamma_C), where the solution gives a pressure.
    pub pressure: Option<f64>,
    /// |Gamma_C|^(1/2) max |u| (the normal jump's scale).
    pub jump: f64,
}

/// The differences of one solution to the reference, per time step t_1..t_N.
pub struct Differences<'a> {
    /// Squared norms of (solution - reference) per step.
    pub fields: &'a [SquaredNorms],
    /// Squared norms of the reference per step.
    pub reference: &'a [SquaredNorms],
    /// (||p - p_ref||^2, ||p_ref||^2) on Gamma_C per step; `None` when the solution gives
    /// no pressure (the pressure quantities are then not measured).
    pub pressure: Option<&'a [(f64, f64)]>,
    /// Largest interpenetration over the history (length).
    pub penetration: f64,
    /// Largest |u_ref| over the history (length).
    pub reference_displacement: f64,
    /// Gamma_C's quantities per step.
    pub contact: &'a [ContactStep],
    /// (||sigma - sigma_ref||^2, ||sigma_ref||^2) on the band per step.
    pub band_stress: &'a [f64],
    /// The length of Gamma_C.
    pub contact_length: f64,
}

impl Differences<'_> {
    /// The truth's sizes the relative errors divide by.
    pub fn scale(&self) -> Scale {
        let max_over =
            |f: &dyn Fn(&SquaredNorms) -> f64| self.reference.iter().map(f).fold(0.0f64, f64::max);
        Scale {
            theorem: max_over(&|n| n.theorem()),
            h1: max_over(&|n| n.h1()),
            stress: max_over(&|n| n.stress.sqrt()),
            pressure: self
                .pressure
                .map(|p| p.iter().map(|p| p.1.sqrt()).fold(0.0f64, f64::max)),
            jump: self.contact_length.sqrt() * self.reference_displacement,
        }
    }

    /// Every quantity's relative error (max over the steps, relative to the reference's
    /// max over the steps); the pressure quantities only when the solution gives a pressure;
    /// none relative to a size the truth lacks ([`crate::verify::rates::relative_to`]).
    pub fn relative(&self) -> BTreeMap<Quantity, f64> {
        let max_over = |f: &dyn Fn(&SquaredNorms) -> f64, v: &[SquaredNorms]| {
            v.iter().map(f).fold(0.0f64, f64::max)
        };
        let theorem = max_over(&|n| n.theorem(), self.reference);
        let relative =
            |value: f64, size: f64| crate::verify::rates::relative_to(value, size, theorem);
        let rel = |f: &dyn Fn(&SquaredNorms) -> f64| {
            relative(max_over(f, self.fields), max_over(f, self.reference))
        };
        let max =
            |f: &dyn Fn(&ContactStep) -> f64| self.contact.iter().map(f).fold(0.0f64, f64::max);
        let band = self
            .band_stress
            .iter()
            .map(|b| b.sqrt())
            .fold(0.0f64, f64::max);
        let jump_size = self.contact_length.sqrt() * self.reference_displacement;
        let mut out: Vec<(Quantity, Option<f64>)> = vec![
            (
                Quantity::BandStress,
                relative(band, max_over(&|n| n.stress.sqrt(), self.reference)),
            ),
            (
                Quantity::L2Penetration,
                relative(max(&|c| c.penetration_l2.sqrt()), jump_size),
            ),
            (Quantity::Theorem, rel(&|n| n.theorem())),
            (Quantity::H1U, rel(&|n| n.h1())),
            (Quantity::L2U, rel(&|n| n.l2_u.sqrt())),
            (Quantity::L2Stress, rel(&|n| n.stress.sqrt())),
            (
                Quantity::MaxPenetration,
                relative(self.penetration, self.reference_displacement),
            ),
        ];
        if let Some(pressure) = self.pressure {
            out.extend(self.pressure_quantities(pressure, &relative));
        }
        out.into_iter().filter_map(|(q, v)| Some((q, v?))).collect()
    }

    /// The quantities of the pressure on Gamma_C.
    fn pressure_quantities(
        &self,
        pressure: &[(f64, f64)],
        relative: &dyn Fn(f64, f64) -> Option<f64>,
    ) -> [(Quantity, Option<f64>); 5] {
        let pressure_diff = pressure.iter().map(|p| p.0.sqrt()).fold(0.0f64, f64::max);
        let pressure_ref = pressure.iter().map(|p| p.1.sqrt()).fold(0.0f64, f64::max);
        let max = |f: &dyn Fn(&PressureStep) -> f64| {
            self.contact
                .iter()
                .filter_map(|c| c.pressure.as_ref().map(f))
                .fold(0.0f64, f64::max)
        };
        let p_norm = pressure_ref * self.contact_length.sqrt();
        [
            (
                Quantity::ContactEdge,
                Some(max(&|c| c.edge) / self.contact_length),
            ),
            (
                Quantity::PressureResultant,
                relative(max(&|c| c.resultant.0.abs()), max(&|c| c.resultant.1)),
            ),
            (
                Quantity::PressureWeighted,
                relative(max(&|c| c.pressure_weighted.sqrt()), p_norm),
            ),
            (
                Quantity::PressureOscillation,
                relative(
                    max(&|c| (c.variation.0 - c.variation.1).abs()),
                    max(&|c| c.variation.1.max(c.pressure_max)),
                ),
            ),
            (Quantity::L2Pressure, relative(pressure_diff, pressure_ref)),
        ]
    }
}

/// The words reports use beside the quantities, each with its meaning.
pub const TERMS: [(&str, &str); 3] = [
    (
        "pythagorean",
        "error / sqrt(e_mortar^2 + D^2) - 1 for a method at distance D from mortar's solution: 0 where its error and D meet at right angles, descriptive only.",
    ),
    (
        "residual bound delta",
        "the energy distance sqrt(r^T K^-1 r) / ||u_h||_E of a graded solution to the field in equilibrium with the exported loads: its error is changed by at most that much (in squares).",
    ),
    (
        "verdicts",
        "`fitted` (a rate over a trailing window of levels whose successive rates agree: the only verdict that gives a rate), `falling` and `rising` (in transition: the last successive rate is given), `pre-asymptotic`, `too few levels`, `not converging`, `exact` (round-off), `fixed at a node`, `fixed by equilibrium` (docs/studies.md#rates).",
    ),
];

/// The glossary of `quantities` (in [`Quantity::ALL`]'s order) and of [`TERMS`], as
/// Markdown bullets: one definition for docs/studies.md and every grade report.
pub fn glossary(quantities: &[Quantity]) -> String {
    let mut out = String::from(
        "Every quantity is relative and the max over the time steps (at T alone for a solution given at T only).\n\n",
    );
    for q in Quantity::ALL.iter().filter(|q| quantities.contains(q)) {
        out.push_str(&format!("- `{}`: {}\n", q.name(), q.meaning()));
    }
    for (term, meaning) in TERMS {
        out.push_str(&format!("- {term}: {meaning}\n"));
    }
    out
}
