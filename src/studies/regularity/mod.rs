//! The `regularity` study: how each cone's rates follow the regularity of the solution at
//! the transition point between contact and separation.
//!
//! [`run`] reads like the description of the study:
//! 1. for each beta in [`BETAS`], the manufactured solution with a singular part
//!    r^beta Phi_l(theta) at the transition point (`analytical::singular`; the scenes and
//!    study files are written by `examples/regularity_scenes.rs`) is solved by both cones
//!    on [`LEVELS`] of uniform refinement and measured against itself (the convergence
//!    study of studies/regularity/beta-BETA.toml);
//! 2. each quantity's rate is set beside the best a uniform P1 mesh can give
//!    ([`best_rate`]): min(1, beta) for the H1 and theorem norms, min(beta, 3/2) for the
//!    stress along Gamma_C, min(beta - 1/2, 2) for the pressure in L2(Gamma_C);
//! 3. the report leads with where the cones differ, and marks where Theorem 3.1's
//!    hypotheses (u in H^2, f in L2: beta > 1) fail.

pub mod report;
pub mod results;

use crate::error::Result;
use crate::studies::convergence::{self, StudyResult};
use crate::verify::kind::{Found, Kind};
use crate::verify::quantity::Quantity;
use std::path::PathBuf;

/// The kind: built in (`study regularity`).
pub const KIND: Kind = Kind {
    name: "regularity",
    description: "Rates of both cones against the regularity beta of the contact transition (u ~ r^beta there), beta from 0.6 to 2",
    found: Found::BuiltIn,
    shards: false,
    run: |_, _| Ok(Some(Box::new(run(BETAS)?))),
    rejudge: Some(|_, dir| Ok(Box::new(rejudge(BETAS, dir)?))),
    results: Some(results::section),
};

/// The betas of the study.
pub const BETAS: &[f64] = &[0.6, 0.75, 0.9, 1.25, 1.5, 2.0];

/// The refinement levels of each beta's study (h = 0.3 / 1.4142^level).
pub const LEVELS: &[usize] = &[0, 1, 2, 3, 4, 5];

/// The scene of one beta.
pub fn scene_name(beta: f64) -> String {
    format!("regularity-{beta:.2}")
}

/// The study file of one beta.
pub fn study_path(beta: f64) -> PathBuf {
    crate::verify::study_file::builtin_dir()
        .join("regularity")
        .join(format!("beta-{beta:.2}.toml"))
}

/// The best rate in h a uniform P1 mesh can give for `quantity` when u ~ r^beta at one
/// point of Gamma_C: None where the study does not say.
/// - H1 and theorem norms, stress in L2: min(1, beta) (the gradient's best approximation on
///   the O(1) triangles at the point is h^beta, elsewhere h);
/// - stress in the band of triangles along Gamma_C: min(beta, 3/2) (pointwise h in a band of
///   area O(h), h^(beta-1) on the O(1) triangles of area h^2 at the point);
/// - pressure in L2(Gamma_C): min(beta - 1/2, 2) (p ~ dist^(beta-1)).
pub fn best_rate(quantity: Quantity, beta: f64) -> Option<f64> {
    match quantity {
        Quantity::Theorem | Quantity::H1U | Quantity::L2Stress => Some(beta.min(1.0)),
        Quantity::BandStress => Some(beta.min(1.5)),
        Quantity::L2Pressure => Some((beta - 0.5).min(2.0)),
        _ => None,
    }
}

/// Whether Theorem 3.1's hypotheses hold (u in H^2 and f in L2 need beta > 1).
pub fn theorem_applies(beta: f64) -> bool {
    beta > 1.0
}

/// What the study measured: one convergence study per beta.
pub struct Regularity {
    /// (beta, its convergence study), in the order of [`BETAS`].
    pub members: Vec<(f64, StudyResult)>,
}

/// The report `dir` judged again from each beta's CSVs (its `beta-BETA/` folders),
/// without solving.
pub fn rejudge(betas: &[f64], dir: &std::path::Path) -> Result<Regularity> {
    let mut members = Vec::new();
    for &beta in betas {
        let path = study_path(beta);
        let member = dir.join(format!("beta-{beta:.2}"));
        members.push((beta, convergence::rejudge(&path.display().to_string(), &member)?));
    }
    Ok(Regularity { members })
}

/// Run the study on `betas`.
pub fn run(betas: &[f64]) -> Result<Regularity> {
    let mut members = Vec::new();
    for &beta in betas {
        let path = study_path(beta);
        members.push((beta, convergence::run(&path.display().to_string())?));
    }
    Ok(Regularity { members })
}
