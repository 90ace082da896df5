//! The pressure beside its best approximation in a convergence report: each method's
//! `l2_pressure` error against the error of the L2 projection of the exact pressure onto
//! that method's own pressure space on the same level (`best_l2_pressure`), level by
//! level, with both judged rates. What no solution in that space can beat is measured, not
//! taken from an asymptotic formula.

use super::StudyResult;
use crate::report::markdown::{Doc, Table};
use crate::verify::quantity::Quantity;
use crate::verify::rates::ROUNDOFF;

/// The section, where the study measures `best_l2_pressure`.
pub fn section(doc: &mut Doc, res: &StudyResult) {
    if !res.file.quantities.contains(&Quantity::BestL2Pressure) {
        return;
    }
    let rate = |m, q| res.rate(m, q).map_or("-".into(), |r| r.assessment.describe());
    let mut table = Table::new([
        "method",
        "its pressure space",
        "`l2_pressure`: rate",
        "best approximation: rate",
        "best: successive rates",
        "error / best, per level",
    ]);
    for &m in &res.file.methods {
        let ratios: Vec<String> = res
            .file
            .mesh
            .levels
            .iter()
            .map(|&l| {
                match (res.error(m, l, Quantity::L2Pressure), res.error(m, l, Quantity::BestL2Pressure)) {
                    // A best at round-off (the space holds the exact pressure) has no
                    // ratio worth printing.
                    (Some(e), Some(b)) if b > ROUNDOFF => format!("{:.2}", e / b),
                    _ => "-".into(),
                }
            })
            .collect();
        let space = match m.piecewise_constant_pressure() {
            true => "constant on each macro-element",
            false => "piecewise linear on the body-1 trace nodes",
        };
        table.row([
            m.to_string(),
            space.to_string(),
            rate(m, Quantity::L2Pressure),
            rate(m, Quantity::BestL2Pressure),
            res.rate(m, Quantity::BestL2Pressure)
                .map_or("-".into(), |r| r.assessment.successive_text()),
            ratios.join(" "),
        ]);
    }
    doc.heading(2, "The pressure beside its best approximation")
        .paragraph("Each method's pressure error in L2(Gamma_C) beside the error of the best approximation of the exact pressure in that method's own pressure space on the same level (its L2 projection, `best_l2_pressure`, relative as `l2_pressure`): no pressure in that space does better, so error / best >= 1, and a ratio that stays bounded from level to level is an error of the best approximation's order (`-` where the best is at round-off: the space holds the exact pressure). The best approximation's own rate is judged by the same rules: a fit over rising successive rates is not its limit.")
        .table(&table);
}
