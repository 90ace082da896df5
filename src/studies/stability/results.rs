//! The stability study's part of docs/results.md, read back from its report's CSV.

use crate::solve::SolverKind;
use crate::studies::stability::StabilityRow;
use crate::error::Result;
use crate::report::markdown::{DOCS_REPORTS, Doc};
use crate::verify::table::read;
use std::path::Path;

/// The stability study's section of docs/results.md.
pub fn section(reports: &Path) -> Result<String> {
    let mut doc = Doc::new();
    stability_section(&mut doc, reports)?;
    Ok(doc.finish())
}

/// The hard cases: how many runs of each solver did not converge, and newton's most
/// iterations in one step.
fn stability_section(doc: &mut Doc, reports: &Path) -> Result<()> {
    let stability: Vec<StabilityRow> = read(&reports.join("stability").join("stability.csv"))?;
    let count = |solver: SolverKind| {
        let runs = stability.iter().filter(|r| r.solver == solver);
        let failed = runs.clone().filter(|r| !r.converged).count();
        format!("{solver} {failed} of {}", runs.count())
    };
    let worst = stability
        .iter()
        .filter(|r| r.solver == SolverKind::Newton && r.converged)
        .max_by_key(|r| r.max_step_iterations);
    let counts: Vec<String> = [SolverKind::Newton, SolverKind::Paper, SolverKind::Qp]
        .into_iter()
        .map(count)
        .collect();
    doc.heading(
        2,
        format!("[`stability`]({DOCS_REPORTS}/stability/README.md): hard cases, every solver"),
    )
    .bullet(format!(
        "Not converged: {}.{}",
        counts.join(", "),
        worst.map_or(String::new(), |w| format!(
            " newton's most iterations in one step: {} ({}, {}, {}).",
            w.max_step_iterations,
            w.case.name(),
            w.parameter,
            w.method
        ))
    ))
    .blank();
    Ok(())
}

