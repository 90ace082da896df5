//! The rows of the CSV files that studies write and other code reads back, one serde type
//! per file, serialized and deserialized by the same struct: errors.csv ([`ErrorRecord`])
//! and rates.csv ([`RateRecord`]). A row's method is a [`MethodLabel`]: one of this
//! project's cones or the label of a graded code; a quantity that compares two methods
//! (a distance between their solutions) is listed under the second one. Columns a study
//! may not have are `Option`s skipped when empty, so a file has them in every row or in
//! none, and a reader of an older file finds them empty.

use crate::contact::Method;
use crate::error::{Error, Result};
use crate::verify::quantity::Quantity;
use crate::verify::rates::{Assessment, Outcome, Verdict};
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::path::Path;

/// What produced a solution: one of this project's cones, or a label from outside (a
/// graded contact code). Written as the cone's name or the label.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum MethodLabel {
    /// K_h^pi (`mortar`) or K_h^I (`nts`), solved here.
    Cone(Method),
    /// A graded code's label (never `mortar` or `nts`).
    External(String),
}

impl MethodLabel {
    /// The label read from a file: a cone's name is that cone.
    pub fn parse(s: &str) -> Self {
        Method::parse(s).map_or_else(|| MethodLabel::External(s.to_string()), MethodLabel::Cone)
    }
    /// The name written to files.
    pub fn name(&self) -> &str {
        match self {
            MethodLabel::Cone(m) => m.name(),
            MethodLabel::External(s) => s,
        }
    }
    /// The cone, for a row of this project's own solves.
    pub fn cone(&self) -> Option<Method> {
        match self {
            MethodLabel::Cone(m) => Some(*m),
            MethodLabel::External(_) => None,
        }
    }
}

impl From<Method> for MethodLabel {
    fn from(m: Method) -> Self {
        MethodLabel::Cone(m)
    }
}

impl PartialEq<Method> for MethodLabel {
    fn eq(&self, other: &Method) -> bool {
        self.cone() == Some(*other)
    }
}

impl std::fmt::Display for MethodLabel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.name())
    }
}

impl Serialize for MethodLabel {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for MethodLabel {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        Ok(MethodLabel::parse(&String::deserialize(d)?))
    }
}

impl Serialize for Outcome {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for Outcome {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        Outcome::from_name(&name)
            .ok_or_else(|| serde::de::Error::custom(format!("unknown threshold outcome '{name}'")))
    }
}

impl Serialize for Verdict {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for Verdict {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        Verdict::from_name(&name)
            .ok_or_else(|| serde::de::Error::custom(format!("unknown verdict '{name}'")))
    }
}

/// The distinct methods of `labels`, in the order they first appear (a report's order).
pub fn methods_in_order<'a>(labels: impl IntoIterator<Item = &'a MethodLabel>) -> Vec<MethodLabel> {
    let mut out: Vec<MethodLabel> = Vec::new();
    for m in labels {
        if !out.contains(m) {
            out.push(m.clone());
        }
    }
    out
}

/// One row of errors.csv: one method's error in one quantity on one level.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ErrorRecord {
    /// The method.
    pub method: MethodLabel,
    /// Mesh level.
    pub level: usize,
    /// Max element diameter (length).
    pub h: f64,
    /// Free dofs.
    pub dofs: usize,
    /// Time steps.
    pub steps: usize,
    /// Quantity.
    pub quantity: Quantity,
    /// Relative error (max over time steps).
    pub error: f64,
    /// Wall time of the solve (s); empty for a graded code's solution (not timed here).
    pub wall_s: Option<f64>,
    /// The scene family's parameter, for a study over a family of scenes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub parameter: Option<f64>,
}

/// One row of rates.csv: what one method's errors in one quantity support. The quantity
/// is one of this project's ([`Quantity`]) or, for `judge` on anyone's table, its name.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RateRecord<Q = Quantity> {
    /// The method.
    pub method: MethodLabel,
    /// Quantity.
    pub quantity: Q,
    /// The rate in h over `levels_used` (empty without one).
    pub rate: Option<f64>,
    /// Its standard error.
    pub stderr: Option<f64>,
    /// Levels in the fit, space separated.
    pub levels_used: String,
    /// The required rate or the error bound.
    pub threshold: Option<f64>,
    /// What the threshold makes of the errors: pass, fail or unverified.
    pub pass: Option<Outcome>,
    /// The rate in dofs (error ~ dofs^-rate) over the same levels.
    pub rate_dofs: Option<f64>,
    /// Successive rates, space separated ("-" next to a level at round-off).
    pub successive: String,
    /// What the errors support ([`Verdict::name`]).
    pub verdict: Verdict,
    /// The fit over every usable level: reported, not judged.
    pub rate_all_levels: Option<f64>,
    /// The last judged rate (between the finest usable level and the finest one at least
    /// 1.9 times its h: its neighbour in a halving table).
    pub last_rate: Option<f64>,
    /// Celik et al. 2008 on the last three usable levels: observed order,
    pub observed_order: Option<f64>,
    /// whether the convergence oscillates (eps32 / eps21 < 0),
    pub oscillatory: Option<bool>,
    /// the GCI of the finest level (units of the error),
    pub gci_fine: Option<f64>,
    /// and GCI_coarse / (r^p GCI_fine) at the reported rate (1 in the asymptotic range).
    pub asymptotic_ratio: Option<f64>,
    /// The scene family's parameter, for a study over a family of scenes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub parameter: Option<f64>,
}

/// A number where it is finite (no NaN or infinity reaches a report).
fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

/// Levels (or step counts) as written in a CSV cell: space separated.
pub fn join(levels: &[usize]) -> String {
    levels
        .iter()
        .map(|l| l.to_string())
        .collect::<Vec<_>>()
        .join(" ")
}

impl<Q> RateRecord<Q> {
    /// The row of `method`'s `quantity` judged as `a`, with its threshold's value and
    /// outcome.
    pub fn from_parts(
        method: MethodLabel,
        quantity: Q,
        parameter: Option<f64>,
        a: &Assessment,
        threshold: Option<f64>,
        outcome: Option<Outcome>,
    ) -> Self {
        RateRecord {
            method,
            quantity,
            rate: a.fit.and_then(|f| finite(f.rate)),
            stderr: a.fit.and_then(|f| finite(f.stderr)),
            levels_used: join(&a.used),
            threshold,
            pass: outcome,
            rate_dofs: a.fit_dofs.map(|f| -f.rate),
            successive: a.successive_text(),
            verdict: a.verdict,
            rate_all_levels: a.fit_all.and_then(|f| finite(f.rate)),
            last_rate: a.last_rate().and_then(finite),
            observed_order: a.celik.and_then(|c| finite(c.order)),
            oscillatory: a.celik.map(|c| c.oscillatory),
            gci_fine: a.celik.and_then(|c| finite(c.gci_fine)),
            asymptotic_ratio: a.asymptotic_ratio.and_then(finite),
            parameter,
        }
    }

    /// The last two successive rates, as written.
    pub fn last_successive(&self) -> String {
        let all: Vec<&str> = self.successive.split_whitespace().collect();
        all[all.len().saturating_sub(2)..].join(" ")
    }
}

/// Read every row of the CSV file `path` as `T` (an error names the file and says to
/// regenerate the report).
pub fn read<T: for<'de> Deserialize<'de>>(path: &Path) -> Result<Vec<T>> {
    let mut reader = csv::Reader::from_path(path).map_err(|e| {
        Error::input(
            path,
            "file",
            format!("cannot read ({e}); regenerate the report"),
        )
    })?;
    reader
        .deserialize()
        .collect::<std::result::Result<Vec<T>, _>>()
        .map_err(|e| Error::input(path, "rows", format!("{e}; regenerate the report")))
}
