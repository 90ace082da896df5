//! The speed study's part of docs/results.md, read back from its report's CSVs.

use crate::studies::speed::report::SpeedRecord;
use crate::error::Result;
use crate::solve::SolverKind;
use crate::report::markdown::{DOCS_REPORTS, Doc};
use crate::verify::table::read;
use std::path::Path;

/// The speed study's section of docs/results.md.
pub fn section(reports: &Path) -> Result<String> {
    let mut doc = Doc::new();
    speed_section(&mut doc, reports)?;
    Ok(doc.finish())
}

/// The cost of the default solver against the floor, per family, from 1e4 dofs.
fn speed_section(doc: &mut Doc, reports: &Path) -> Result<()> {
    let speed: Vec<SpeedRecord> = read(&reports.join("speed").join("speed.csv"))?;
    let newton: Vec<&SpeedRecord> = speed
        .iter()
        .filter(|r| r.solver == SolverKind::Newton && r.dofs >= 10_000)
        .collect();
    let mut families: Vec<&str> = newton.iter().map(|r| r.family.as_str()).collect();
    families.dedup();
    let ranges: Vec<String> = families
        .iter()
        .map(|f| {
            let ratios = newton
                .iter()
                .filter(|r| r.family == *f)
                .map(|r| r.ratio_to_floor);
            let (lo, hi) = ratios.fold((f64::INFINITY, 0.0f64), |(a, b), v| (a.min(v), b.max(v)));
            format!("{f} {lo:.2}-{hi:.2}")
        })
        .collect();
    let top = speed.iter().map(|r| r.dofs).max().unwrap_or(0);
    let threads = speed.first().map_or(String::new(), |r| {
        format!(" ({} threads, the solver and the floor alike)", r.threads)
    });
    doc.heading(
        2,
        format!("[`speed`]({DOCS_REPORTS}/speed/README.md): cost against the floor (the faster of an f64 Cholesky and an f32 Cholesky with conjugate gradients)"),
    )
    .bullet(format!(
        "newton's (set-up + time loop) / floor from 1e4 to {top} dofs{threads}: {}.",
        ranges.join(", ")
    ))
    .blank();
    Ok(())
}

