//! The regularity study's part of docs/results.md, and its headline line, read back from
//! its report's rates.csv.

use crate::contact::Method;
use crate::studies::regularity::report::RateCsv as RegularityRate;
use crate::verify::quantity::Quantity;
use crate::verify::rates;
use crate::error::Result;
use crate::report::markdown::{DOCS_REPORTS, Doc, Table};
use crate::verify::table::read;
use std::path::Path;

/// The regularity study's section of docs/results.md.
pub fn section(reports: &Path) -> Result<String> {
    family_section(reports, "regularity", "rates against the regularity beta of the contact transition (u ~ r^beta there)")
}

/// regularity-unaligned's section of docs/results.md.
pub fn unaligned_section(reports: &Path) -> Result<String> {
    family_section(reports, "regularity-unaligned", "the regularity family with the transition point off the nodes of both meshes, levels 0-7")
}

/// regularity-graded's section of docs/results.md.
pub fn graded_section(reports: &Path) -> Result<String> {
    family_section(reports, "regularity-graded", "the regularity family for beta < 1 on meshes graded toward the transition point (remeshed levels)")
}

/// One regularity family's section, from its report reports/`name`.
fn family_section(reports: &Path, name: &str, what: &str) -> Result<String> {
    let mut doc = Doc::new();
    regularity_section(&mut doc, reports, name, what)?;
    Ok(doc.finish())
}

/// The README headline's line on the regularity study.
pub fn headline(reports: &Path) -> Result<String> {
    Ok(regularity_headline(&read(&reports.join("regularity").join("rates.csv"))?))
}

/// The theorem-norm rows of the regularity study's rates.csv of cone `m`, in beta order.
fn regularity_theorem(rows: &[RegularityRate], m: Method) -> Vec<&RegularityRate> {
    rows.iter()
        .filter(|r| r.method == m && r.quantity == Quantity::Theorem)
        .collect()
}

/// The betas of `rows` that follow (or not) their best rate, as text.
fn betas_where(rows: &[&RegularityRate], follows: bool) -> Vec<String> {
    rows.iter()
        .filter(|r| r.follows_best == Some(follows))
        .map(|r| format!("{}", r.beta))
        .collect()
}

/// The headline's line on the regularity study: where each cone's theorem-norm rate follows
/// min(1, beta), where it falls below (the largest shortfall), and where its errors support
/// no rate (in transition, with the last successive rate).
fn regularity_headline(rows: &[RegularityRate]) -> String {
    let cone = |m: Method| {
        let theorem = regularity_theorem(rows, m);
        let mut parts = Vec::new();
        let follows = betas_where(&theorem, true);
        if !follows.is_empty() {
            parts.push(format!("follows it at beta = {}", follows.join(", ")));
        }
        let worst = theorem
            .iter()
            .filter(|r| r.follows_best == Some(false))
            // The judged rate is min(fit, last judged rate): the one rule's.
            .filter_map(|r| {
                let judged = r.rate?.min(r.last_rate.unwrap_or(f64::INFINITY));
                Some((r.beta, r.best_rate? - judged, judged))
            })
            .max_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((beta, short, rate)) = worst {
            parts.push(format!(
                "falls below it at beta = {} (by up to {short:.2}: min(fit, last judged rate) {rate:.3} at beta = {beta})",
                betas_where(&theorem, false).join(", ")
            ));
        }
        let unsupported: Vec<String> = theorem
            .iter()
            .filter(|r| r.follows_best.is_none())
            .map(|r| {
                format!(
                    "{} at beta = {}",
                    rates::short_text(r.verdict, r.rate, r.last_rate),
                    r.beta
                )
            })
            .collect();
        if !unsupported.is_empty() {
            parts.push(format!("supports no rate: {}", unsupported.join(", ")));
        }
        format!("{m}'s rate {}", parts.join("; "))
    };
    format!(
        "**Rates against the regularity of the contact transition** ([`regularity`](reports/regularity/README.md), u ~ r^beta where contact ends, Theorem 3.1's norm against the best uniform-mesh rate min(1, beta)): {}.",
        Method::ALL.map(cone).join("; ")
    )
}

/// A regularity family: its rate table, beta x quantity x method, with verdicts.
fn regularity_section(doc: &mut Doc, reports: &Path, name: &str, what: &str) -> Result<()> {
    let rows: Vec<RegularityRate> = read(&reports.join(name).join("rates.csv"))?;
    doc.heading(2, format!("[`{name}`]({DOCS_REPORTS}/{name}/README.md): {what}"));
    if name == "regularity" {
        doc.bullet(regularity_headline(&rows).replace("(reports/", &format!("({DOCS_REPORTS}/")));
    }
    doc.bullet(format!(
        "Theorem 3.1 applies only for beta > 1 (u in H^2, f in L2); † marks the betas where it does not. A rate is shown where its verdict supports one, with \"follows\" where the fit and the last judged rate both reach the best rate within {} (or two standard errors of the fit): the threshold rule's min(fit, last judged rate).",
        super::report::FOLLOW_TOLERANCE
    ))
    .blank();
    let methods = crate::verify::table::methods_in_order(rows.iter().map(|r| &r.method));
    let mut header = vec!["beta".to_string(), "quantity".into(), "best rate".into()];
    header.extend(methods.iter().map(|m| m.to_string()));
    let mut table = Table::new(header);
    let mut keys: Vec<(f64, Quantity)> = Vec::new();
    for r in &rows {
        if !keys.contains(&(r.beta, r.quantity)) {
            keys.push((r.beta, r.quantity));
        }
    }
    for (beta, q) in keys {
        let of = |m: &crate::verify::table::MethodLabel| {
            rows.iter()
                .find(|r| r.beta == beta && r.quantity == q && &r.method == m)
        };
        let text = |r: Option<&RegularityRate>| match r {
            Some(r) => match (r.rate, r.stderr) {
                (Some(rate), Some(se)) => format!(
                    "{rate:.3} ± {se:.3} {}{}",
                    r.verdict.name(),
                    match r.follows_best {
                        Some(true) => ", follows",
                        Some(false) => ", below",
                        None => "",
                    }
                ),
                _ => format!("{} (successive rates {})", r.verdict.name(), r.successive),
            },
            None => "-".into(),
        };
        // From any row of this beta: cone_distance has an nts row only.
        let applies = rows.iter().any(|r| r.beta == beta && r.theorem_applies);
        let best = rows
            .iter()
            .find(|r| r.beta == beta && r.quantity == q)
            .and_then(|r| r.best_rate)
            .map_or("-".into(), |b| format!("{b:.2}"));
        let mut cells = vec![format!("{beta}{}", if applies { "" } else { " †" }), format!("`{q}`"), best];
        cells.extend(methods.iter().map(|m| text(of(m))));
        table.row(cells);
    }
    doc.table(&table);
    Ok(())
}

