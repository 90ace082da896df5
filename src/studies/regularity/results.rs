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
    let mut doc = Doc::new();
    regularity_section(&mut doc, reports)?;
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
        "**Rates against the regularity of the contact transition** ([`regularity`](reports/regularity/README.md), u ~ r^beta where contact ends, Theorem 3.1's norm against the best uniform-mesh rate min(1, beta)): {}; {}.",
        cone(Method::Mortar),
        cone(Method::Nts)
    )
}

/// The regularity study: its rate table, beta x cone x quantity, with verdicts.
fn regularity_section(doc: &mut Doc, reports: &Path) -> Result<()> {
    let rows: Vec<RegularityRate> = read(&reports.join("regularity").join("rates.csv"))?;
    doc.heading(
        2,
        format!("[`regularity`]({DOCS_REPORTS}/regularity/README.md): rates against the regularity beta of the contact transition (u ~ r^beta there)"),
    )
    .bullet(regularity_headline(&rows).replace("(reports/", &format!("({DOCS_REPORTS}/")))
    .bullet("Theorem 3.1 applies only for beta > 1 (u in H^2, f in L2); † marks the betas where it does not. A rate is shown where its verdict supports one, with \"follows\" where it reaches the best rate within 0.05 (or two standard errors).")
    .blank();
    let mut table = Table::new(["beta", "quantity", "best rate", "mortar", "nts"]);
    let mut keys: Vec<(f64, Quantity)> = Vec::new();
    for r in &rows {
        if !keys.contains(&(r.beta, r.quantity)) {
            keys.push((r.beta, r.quantity));
        }
    }
    for (beta, q) in keys {
        let of = |m: Method| {
            rows.iter()
                .find(|r| r.beta == beta && r.quantity == q && r.method == m)
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
        table.row([
            format!("{beta}{}", if applies { "" } else { " †" }),
            format!("`{q}`"),
            of(Method::Mortar)
                .and_then(|r| r.best_rate)
                .map_or("-".into(), |b| format!("{b:.2}")),
            text(of(Method::Mortar)),
            text(of(Method::Nts)),
        ]);
    }
    doc.table(&table);
    Ok(())
}

