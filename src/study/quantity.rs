//! The quantities a convergence study measures, each a relative error of one time history
//! against the reference's (max over the time steps).

use super::error::SquaredNorms;
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
    /// Largest interpenetration over the history, relative to max |u_ref|.
    #[serde(rename = "max_penetration")]
    MaxPenetration,
}

impl Quantity {
    /// Every quantity, in the order reports list them.
    pub const ALL: [Quantity; 6] = [
        Quantity::Theorem,
        Quantity::H1U,
        Quantity::L2U,
        Quantity::L2Stress,
        Quantity::L2Pressure,
        Quantity::MaxPenetration,
    ];

    /// Name in study files and reports.
    pub fn name(self) -> &'static str {
        match self {
            Quantity::Theorem => "theorem",
            Quantity::H1U => "h1_u",
            Quantity::L2U => "l2_u",
            Quantity::L2Stress => "l2_stress",
            Quantity::L2Pressure => "l2_pressure",
            Quantity::MaxPenetration => "max_penetration",
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

/// The differences of one solution to the reference, per time step t_1..t_N.
pub struct Differences<'a> {
    /// Squared norms of (solution - reference) per step.
    pub fields: &'a [SquaredNorms],
    /// Squared norms of the reference per step.
    pub reference: &'a [SquaredNorms],
    /// (||p - p_ref||^2, ||p_ref||^2) on Gamma_C per step.
    pub pressure: &'a [(f64, f64)],
    /// Largest interpenetration over the history (length).
    pub penetration: f64,
    /// Largest |u_ref| over the history (length).
    pub reference_displacement: f64,
}

impl Differences<'_> {
    /// Every quantity's relative error (max over the steps, relative to the reference's
    /// max over the steps).
    pub fn relative(&self) -> BTreeMap<Quantity, f64> {
        let max_over = |f: &dyn Fn(&SquaredNorms) -> f64, v: &[SquaredNorms]| {
            v.iter().map(f).fold(0.0f64, f64::max)
        };
        let rel = |f: &dyn Fn(&SquaredNorms) -> f64| {
            max_over(f, self.fields) / max_over(f, self.reference).max(f64::MIN_POSITIVE)
        };
        let pressure_diff = self
            .pressure
            .iter()
            .map(|p| p.0.sqrt())
            .fold(0.0f64, f64::max);
        let pressure_ref = self
            .pressure
            .iter()
            .map(|p| p.1.sqrt())
            .fold(0.0f64, f64::max);
        BTreeMap::from([
            (Quantity::Theorem, rel(&|n| n.theorem())),
            (Quantity::H1U, rel(&|n| n.h1())),
            (Quantity::L2U, rel(&|n| n.l2_u.sqrt())),
            (Quantity::L2Stress, rel(&|n| n.stress.sqrt())),
            (
                Quantity::L2Pressure,
                pressure_diff / pressure_ref.max(f64::MIN_POSITIVE),
            ),
            (
                Quantity::MaxPenetration,
                self.penetration / self.reference_displacement.max(f64::MIN_POSITIVE),
            ),
        ])
    }
}
