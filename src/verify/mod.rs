//! The verification toolkit that every study kind shares: errors of a discrete solution
//! ([`field`]: plain P1 displacements and P0 stresses, whoever computed them) against
//! another mesh's ([`norms`] over [`intersect`]ions, [`contact_error`] on Gamma_C) and
//! against exact solutions ([`exact_error`]), the [`quantity`] names, [`rates`] and their verdicts, the
//! study file ([`study_file`]), the independent solves of a study ([`jobs`]), and what a
//! study kind is ([`kind`]). Nothing here knows any particular kind.

pub mod contact_error;
pub mod distance;
pub mod exact_error;
pub mod field;
pub mod geometry;
pub mod intersect;
pub mod jobs;
pub mod judge;
pub mod kind;
pub mod norms;
pub mod pressure_l2;
pub mod quantity;
pub mod rates;
pub mod study_file;
pub mod table;
pub mod truth;

use crate::case::Case;
use crate::error::Result;
use crate::solve::{self, Settings, Solution, SolverKind};
use field::P1History;
use norms::Comparison;
use std::time::Instant;

/// Solve `case` with `kind` on `steps` uniform steps, keeping the history; with the wall
/// time of the call (s).
pub fn solve_case(case: &Case, kind: SolverKind, steps: usize) -> Result<(Solution, f64)> {
    let t = Instant::now();
    let sol = solve::solve(
        &case.problem,
        &Settings {
            kind,
            ..Settings::default()
        },
        steps,
        true,
    )?;
    Ok((sol, t.elapsed().as_secs_f64()))
}

/// Theorem-quantity distance of two solutions with the same time grid, relative to `b`.
pub fn theorem_distance(ca: &Case, sa: &Solution, cb: &Case, sb: &Solution) -> f64 {
    let (a, b) = (
        P1History::of_solution(ca, sa),
        P1History::of_solution(cb, sb),
    );
    let cmp = Comparison::new(a.model, b.model);
    let d = a
        .steps
        .iter()
        .zip(&b.steps)
        .map(|(x, y)| cmp.difference(a.model, x, b.model, y).theorem())
        .fold(0.0f64, f64::max);
    let n = b
        .steps
        .iter()
        .map(|y| norms::norms(b.model, y).theorem())
        .fold(0.0f64, f64::max);
    d / n
}

/// The git commit of the working tree, or "unknown".
pub fn commit() -> String {
    std::process::Command::new("git")
        .args(["rev-parse", "--short=12", "HEAD"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_else(|| "unknown".into())
}
