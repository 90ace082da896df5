//! A study set beside another on the same meshes (the study file's `beside`): what this
//! study's scene adds to the other's, level by level and method by method, from the other's
//! committed errors.csv (the `gap` study beside regularity-unaligned's beta = 1.5: the
//! same contact zone and pressure, across an initial gap).

use super::StudyResult;
use crate::contact::Method;
use crate::report::markdown::{Doc, Table};
use crate::verify::quantity::Quantity;
use crate::verify::rates::{LevelError, assess};
use crate::verify::table::ErrorRecord;

/// The quantities set beside the other study's, where both measure them.
const BESIDE: [Quantity; 5] = [
    Quantity::Theorem,
    Quantity::L2Pressure,
    Quantity::ContactEdge,
    Quantity::MaxPenetration,
    Quantity::DiscreteGap,
];

/// The other study's committed errors, or why there are none.
fn other_errors(other: &str) -> std::result::Result<Vec<ErrorRecord>, String> {
    let path = crate::report::folder::reports_dir().join(other).join("errors.csv");
    crate::verify::table::read(&path).map_err(|e| e.to_string())
}

/// One method's errors in `q` at the levels both studies measure, here and there, or why
/// they cannot be set side by side (a level whose dofs differ: not the same meshes).
fn paired(
    res: &StudyResult,
    theirs: &[ErrorRecord],
    m: Method,
    q: Quantity,
) -> std::result::Result<Vec<(LevelError, LevelError)>, String> {
    let of = |rows: &[ErrorRecord], level: usize| {
        rows.iter()
            .find(|e| e.method == m && e.quantity == q && e.level == level)
            .map(|e| LevelError { level, h: e.h, dofs: e.dofs as f64, error: e.error })
    };
    let mut out = Vec::new();
    for &level in &res.file.mesh.levels {
        if let (Some(a), Some(b)) = (of(&res.errors, level), of(theirs, level)) {
            if a.dofs != b.dofs {
                return Err(format!(
                    "level {level} has {} dofs here and {} there: not the same meshes",
                    a.dofs, b.dofs
                ));
            }
            out.push((a, b));
        }
    }
    Ok(out)
}

/// The verdict of `levels` judged alone, in a few words.
fn judged(levels: &[LevelError]) -> String {
    match assess(levels, 0.0) {
        Ok(a) => a.describe().replace("**", ""),
        Err(e) => e.to_string(),
    }
}

/// The lead of a study with `beside`: per method the theorem-norm verdict here and there
/// and the ratio of the errors at the finest common level.
pub fn lead(doc: &mut Doc, res: &StudyResult) {
    let Some(other) = &res.file.beside else {
        return;
    };
    let theirs = match other_errors(other) {
        Ok(t) => t,
        Err(e) => {
            doc.heading(2, "What the study learned").paragraph(format!(
                "Not set beside {other}: {e} (`cargo run --release -- study {other}` writes it)."
            ));
            return;
        }
    };
    let mut lines = Vec::new();
    for &m in &res.file.methods {
        match paired(res, &theirs, m, Quantity::Theorem) {
            Ok(pairs) if !pairs.is_empty() => lines.push(theorem_line(res, &theirs, other, m, &pairs)),
            Ok(_) => {}
            Err(e) => lines.push(format!("{m}: not set beside {other}: {e}.")),
        }
    }
    doc.heading(2, &format!("What the study adds to {other}")).list(lines);
}

/// One method's theorem norm here and there: both verdicts, the spread of the ratio of
/// the errors over the common levels (each relative to its own exact norm), and the
/// pressure's ratio at the finest common level.
fn theorem_line(
    res: &StudyResult,
    theirs: &[ErrorRecord],
    other: &str,
    m: Method,
    pairs: &[(LevelError, LevelError)],
) -> String {
    let (here, there): (Vec<LevelError>, Vec<LevelError>) = pairs.iter().cloned().unzip();
    // A zero error there has no ratio: such levels are left out of the spread.
    let ratios: Vec<f64> = pairs
        .iter()
        .filter(|(_, b)| b.error > 0.0)
        .map(|(a, b)| a.error / b.error)
        .collect();
    let spread = match ratios.iter().copied().reduce(f64::min).zip(ratios.iter().copied().reduce(f64::max)) {
        Some((lo, hi)) => format!("the error here over the error there {lo:.3} to {hi:.3}"),
        None => "no ratio (zero errors there)".into(),
    };
    let pressure = paired(res, theirs, m, Quantity::L2Pressure)
        .ok()
        .and_then(|p| p.last().cloned())
        .filter(|(_, b)| b.error > 0.0)
        .map_or(String::new(), |(a, b)| {
            format!("; l2_pressure here over there at level {}: {:.3}", a.level, a.error / b.error)
        });
    format!(
        "{m}, theorem norm: here {}; in {other} {}; over levels {}-{} {spread}{pressure}.",
        judged(&here),
        judged(&there),
        here[0].level,
        here[here.len() - 1].level,
    )
}

/// The section: per method and quantity of [`BESIDE`], the errors here and there at every
/// common level and their ratio.
pub fn section(doc: &mut Doc, res: &StudyResult) {
    let Some(other) = &res.file.beside else {
        return;
    };
    let Ok(theirs) = other_errors(other) else {
        return;
    };
    doc.heading(2, &format!("Beside {other}, level by level"))
        .paragraph(format!(
            "Each method's errors here and in reports/{other} (its committed errors.csv) on the same meshes (the dofs of every level checked equal), each relative to its own problem's exact solution, and their ratio. A ratio constant over the levels is the same rate, and an error that differs only by the ratio of the two problems' norms where this study's scene changes the solution's size; `-` where the other study does not measure the quantity."
        ));
    let quantities: Vec<Quantity> = BESIDE
        .into_iter()
        .filter(|q| res.file.quantities.contains(q))
        .collect();
    // A quantity the other study does not measure is shown here alone ("-" there).
    let alone = |q: Quantity| !theirs.iter().any(|e| e.quantity == q);
    let mut header = vec!["method".to_string(), "level".into(), "h".into()];
    for q in &quantities {
        header.extend([format!("{q} here"), format!("{q} there"), "here / there".into()]);
    }
    let mut table = Table::new(header);
    for &m in &res.file.methods {
        let columns: Vec<Vec<(LevelError, LevelError)>> = quantities
            .iter()
            .map(|&q| match alone(q) {
                true => here_only(res, m, q),
                false => paired(res, &theirs, m, q).unwrap_or_default(),
            })
            .collect();
        for &level in &res.file.mesh.levels {
            let cells: Vec<Option<&(LevelError, LevelError)>> = columns
                .iter()
                .map(|c| c.iter().find(|(a, _)| a.level == level))
                .collect();
            let Some(h) = cells.iter().flatten().next().map(|(a, _)| a.h) else {
                continue;
            };
            let mut row = vec![m.to_string(), level.to_string(), format!("{h:.5}")];
            for cell in cells {
                match cell {
                    Some((a, b)) if b.error.is_nan() => {
                        row.extend([format!("{:.4e}", a.error), "-".into(), "-".into()])
                    }
                    Some((a, b)) => row.extend([
                        format!("{:.4e}", a.error),
                        format!("{:.4e}", b.error),
                        // A zero error there has no ratio (never inf in a report).
                        if b.error > 0.0 { format!("{:.3}", a.error / b.error) } else { "-".into() },
                    ]),
                    None => row.extend(["-".into(), "-".into(), "-".into()]),
                }
            }
            table.row(row);
        }
    }
    doc.table(&table);
}

/// One method's errors in `q` here, paired with a NaN stand-in there (the other study does
/// not measure `q`: printed "-", never as a number).
fn here_only(res: &StudyResult, m: Method, q: Quantity) -> Vec<(LevelError, LevelError)> {
    res.errors
        .iter()
        .filter(|e| e.method == m && e.quantity == q)
        .map(|e| {
            let a = LevelError { level: e.level, h: e.h, dofs: e.dofs as f64, error: e.error };
            (a.clone(), LevelError { error: f64::NAN, ..a })
        })
        .collect()
}
