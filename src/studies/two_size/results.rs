//! The two-size studies' part of docs/results.md, read back from their reports' CSVs.

use crate::contact::Method;
use crate::studies::two_size::SizePoint;
use crate::studies::two_size::report::FitRecord;
use crate::verify::quantity::Quantity;
use crate::verify::rates;
use crate::error::Result;
use crate::report::markdown::{DOCS_REPORTS, Doc};

/// The cones, in the order the page names them.
const CONES: [Method; 3] = Method::ALL;
use crate::verify::table::read;
use std::path::Path;

/// The two-size studies' sections of docs/results.md.
pub fn section(reports: &Path) -> Result<String> {
    let mut doc = Doc::new();
    for (name, what) in TWO_SIZE {
        two_size_section(&mut doc, &reports.join(name), name, what)?;
    }
    Ok(doc.finish())
}

/// The two-size studies whose reports the section summarises.
pub const TWO_SIZE: [(&str, &str); 2] = [
    (
        "two-size-exact",
        "the slave's and the master's mesh refined independently, `contact-mms` against its exact solution",
    ),
    (
        "two-size-rates",
        "the same on the viscoplastic `rates` scene against a matching-mesh reference",
    ),
];

/// A two-size report's section: the theorem norm's exponents per slave choice and cone,
/// and what refining each body alone from the finest grid diagonal point does to the
/// theorem error and the penetration.
fn two_size_section(doc: &mut Doc, dir: &Path, name: &str, what: &str) -> Result<()> {
    let fits: Vec<FitRecord> = read(&dir.join("fits.csv"))?;
    let grid: Vec<SizePoint> = read(&dir.join("grid.csv"))?;
    doc.heading(
        2,
        format!("[`{name}`]({DOCS_REPORTS}/{name}/README.md): {what}"),
    );
    let exponent = |v: f64, se: f64, rms: f64| match rates::fit_identifies(se, rms) {
        true => format!("{v:.2} ± {se:.2}"),
        false => "not identified".into(),
    };
    let mut slaves: Vec<&str> = fits.iter().map(|f| f.slave.as_str()).collect();
    slaves.dedup();
    // The expected exponents as the study file gave them (fits.csv's columns).
    let lemma: Vec<String> = CONES
        .iter()
        .filter_map(|&m| {
            let f = fits.iter().find(|f| f.method == m)?;
            Some(match (f.expected_a1, f.expected_a2) {
                (Some(a1), Some(a2)) => format!("{m} ({a1}, {a2})"),
                _ => format!("{m} none stated"),
            })
        })
        .collect();
    for slave in &slaves {
        let parts: Vec<String> = fits
            .iter()
            .filter(|f| f.slave == *slave && f.quantity == Quantity::Theorem)
            .map(|f| {
                format!(
                    "{} a1 {}, a2 {}",
                    f.method,
                    exponent(f.a1, f.se_a1, f.rms_log_residual),
                    exponent(f.a2, f.se_a2, f.rms_log_residual)
                )
            })
            .collect();
        doc.bullet(format!(
            "Theorem norm, E = C1 h1^a1 + C2 h2^a2 with slave '{slave}' (expected, from the study file: {}): {}.",
            lemma.join(", "),
            parts.join("; ")
        ));
    }
    if let Some(slave) = slaves.first() {
        doc.bullet(one_body_refined(&grid, slave));
    }
    doc.blank();
    Ok(())
}

/// From the finest diagonal point of the grid, each body refined alone to the fixed level:
/// the theorem error and the penetration of both cones, with slave `slave`.
fn one_body_refined(grid: &[SizePoint], slave: &str) -> String {
    let top = grid
        .iter()
        .map(|p| p.slave_level.max(p.master_level))
        .max()
        .unwrap_or(0);
    let finest = grid
        .iter()
        .filter(|p| p.slave_level == p.master_level && p.slave_level < top)
        .map(|p| p.slave_level)
        .max()
        .unwrap_or(0);
    let error = |m: Method, q: Quantity, l: [usize; 2]| {
        grid.iter()
            .find(|p| {
                p.slave == slave
                    && p.method == m
                    && p.quantity == q
                    && [p.slave_level, p.master_level] == l
            })
            .map(|p| p.error)
    };
    let mut parts = Vec::new();
    for m in CONES {
        for q in [Quantity::Theorem, Quantity::MaxPenetration] {
            let (Some(base), Some(s1), Some(s2)) = (
                error(m, q, [finest, finest]),
                error(m, q, [top, finest]),
                error(m, q, [finest, top]),
            ) else {
                continue;
            };
            parts.push(format!(
                "{m} {q} {base:.2e} -> slave refined {s1:.2e} (x{:.2}), master refined {s2:.2e} (x{:.2})",
                s1 / base,
                s2 / base
            ));
        }
    }
    format!(
        "From ({finest}, {finest}), slave '{slave}', one body refined to level {top}: {}.",
        parts.join("; ")
    )
}

