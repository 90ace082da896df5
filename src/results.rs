//! What the committed reports found, read back from their CSVs (rates.csv, errors.csv,
//! ...) through the same row types that wrote them, so that the documentation says what
//! the harness measured and a test can tell when it no longer matches them: [`section`] is
//! the full page docs/results.md (`contact-rates results`), each study kind's part from the
//! kind itself (its `results` in the table `studies::KINDS`); [`headline`] the compact
//! table of README.md (`contact-rates results --headline`).

use crate::contact::Method;
use crate::error::Result;
use crate::report::markdown::{Doc, README_REPORTS, Table, listed};
use crate::studies::KINDS;
use crate::studies::convergence::results::{
    CONES, Report, SEPARATES, Separation, held_to, rate_short, rate_text,
};
pub use crate::studies::convergence::results::{HEADLINE, STUDIES};
use crate::verify::quantity::Quantity;
use crate::verify::rates::Verdict;
use crate::verify::table::RateRecord;
use std::path::Path;

/// The page docs/results.md: what each committed report measured, for the reports under
/// `reports`: every study kind's section, in the order of the kinds' table.
pub fn section(reports: &Path) -> Result<String> {
    let mut doc = Doc::new();
    doc.heading(1, "Results").paragraph(
        "What the committed reports measured (`cargo run --release -- results` prints this page from their CSVs; a test fails when it no longer matches them). Rates are least-squares slopes in h over the levels named, with the verdict of [the rate rules](studies.md#rates) (fitted; falling or rising: in transition; pre-asymptotic, not converging, round-off, fixed at a node, fixed by equilibrium). Only a fitted verdict supports a rate.",
    );
    let mut page = doc.finish();
    for kind in KINDS {
        if let Some(results) = kind.results {
            page.push_str(&results(reports)?);
        }
    }
    page.push_str(&crate::external::codes::results_section(reports)?);
    page.push_str(&run_times(reports)?);
    Ok(page)
}

/// The wall time of every report under `reports` that records one in its run.toml
/// (`wall_s` at its top level; a family's members summed): (study, seconds, how many
/// run.toml files were summed), by name. The one place the documentation and `study list`
/// take a study's run time from.
pub fn wall_times(reports: &Path) -> Result<Vec<(String, f64, usize)>> {
    let mut rows = Vec::new();
    let mut dirs: Vec<std::path::PathBuf> = std::fs::read_dir(reports)
        .map_err(|e| crate::error::Error::input(reports, "reports", e.to_string()))?
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.is_dir())
        .collect();
    dirs.sort();
    for dir in dirs {
        let mut files: Vec<std::path::PathBuf> = std::iter::once(dir.join("run.toml"))
            .chain(
                std::fs::read_dir(&dir)
                    .into_iter()
                    .flatten()
                    .flatten()
                    .map(|e| e.path().join("run.toml")),
            )
            .filter(|p| p.is_file())
            .collect();
        if files.is_empty() {
            continue;
        }
        files.sort();
        let mut total = 0.0;
        for f in &files {
            let text = std::fs::read_to_string(f)
                .map_err(|e| crate::error::Error::input(f, "run.toml", e.to_string()))?;
            let value: toml::Value = crate::error::parse_toml(&text, f, "run facts")?;
            total += value
                .get("wall_s")
                .and_then(toml::Value::as_float)
                .unwrap_or(0.0);
        }
        let name = dir
            .file_name()
            .map_or(String::new(), |n| n.to_string_lossy().to_string());
        rows.push((name, total, files.len()));
    }
    Ok(rows)
}

/// The wall times of [`wall_times`] as the page's last part.
fn run_times(reports: &Path) -> Result<String> {
    let rows: Vec<[String; 2]> = wall_times(reports)?
        .into_iter()
        .map(|(name, total, n)| {
            let parts = match n {
                1 => String::new(),
                n => format!(" ({n} members' run.toml summed)"),
            };
            [format!("`{name}`"), format!("{total:.0} s{parts}")]
        })
        .collect();
    let mut doc = Doc::new();
    doc.heading(2, "Run times").paragraph(
        "Wall time of each committed report's study on the machine that wrote it (2 cores), read from its run.toml (`wall_s`); the build comes first. Reports without a run.toml print their own time in their README.",
    );
    let mut table = Table::new(["study", "wall time"]);
    for r in rows {
        table.row(r);
    }
    doc.table(&table);
    Ok(doc.finish())
}

/// The README's headline, for the reports under `reports`: three lines on what separates
/// the cones, how they meet Theorem 3.1 and what does not converge, then a table per study
/// of [`HEADLINE`]: the contact quantities whose errors separate the cones at the finest
/// level (largest ratio first), what does not converge, and the rate of the quantity the
/// study judges (Theorem 3.1's norm; the stress for `patch`) in each cone. A rate is
/// printed only where its verdict supports one (see [`rate_short`]).
pub fn headline(reports: &Path) -> Result<String> {
    let mut studies = Vec::new();
    for (name, what) in HEADLINE {
        studies.push((name, what, Report::read(&reports.join(name))?));
    }
    let mut doc = Doc::new();
    doc.bullet(format!(
        "**Where the methods differ:** {}.",
        cones_differ(&studies)
    ));
    let theorem: Vec<String> = CONES.iter().map(|&m| theorem_rates(&studies, m)).collect();
    doc.bullet(format!(
        "**Theorem 3.1's norm**, observed rates in h with their verdicts: {}.",
        theorem.join("; ")
    ));
    let reference = Method::reference();
    for m in Method::compared(&CONES) {
        let distances: Vec<String> = studies
            .iter()
            .filter_map(|(name, _, report)| {
                let d = report.rate(m, Quantity::ConeDistance)?;
                let a = report.asymptote(m, Quantity::Theorem)?;
                Some(match (d.verdict, a.asymptotic_rate) {
                    (Verdict::Fitted, Some(_)) => format!(
                        "in `{name}` D falls at {}, and {m}'s error {}",
                        rate_text(d),
                        a.describe()
                    ),
                    _ => format!(
                        "in `{name}` D supports no rate ({}): no asymptotic rate is predicted",
                        rate_text(d)
                    ),
                })
            })
            .collect();
        if !distances.is_empty() {
            doc.bullet(format!(
                "**{m} read against its distance D to {reference}** (D - e_{reference} <= e_{m} <= D + e_{reference}, on the same meshes): {}.",
                distances.join("; ")
            ));
        }
    }
    doc.bullet(crate::studies::regularity::results::headline(reports)?);
    doc.bullet(format!(
        "**Does not converge:** {}.",
        listed(&stalled_anywhere(&studies), "; ", "nothing")
    ));
    let fixed = fixed_anywhere(&studies);
    if !fixed.is_empty() {
        doc.bullet(format!(
            "**Fixed at a node** (the same error on the last levels: a position every level keeps, bounded by the rows' resolution; each README prints the bound): {}.",
            fixed.join("; ")
        ));
    }
    doc.blank();
    let mut header = vec![
        "study: scene, measured against".to_string(),
        format!(
            "where the methods differ: contact quantities at the finest level, each method's error / {reference}'s (rates)"
        ),
        "does not converge".to_string(),
    ];
    header.extend(
        CONES
            .iter()
            .map(|m| format!("rate, {m} (threshold: the study file's)")),
    );
    let mut table = Table::new(header);
    for (name, what, report) in &studies {
        table.row(headline_row(name, what, report));
    }
    Ok(doc.as_str().to_string() + &table.render())
}

/// The headline's first line: how many contact-quantity errors separate each method from
/// the reference over the studies, whose is the larger, by how much, and where the
/// reference is exact.
fn cones_differ(studies: &[(&str, &str, Report)]) -> String {
    let reference = Method::reference();
    let mut parts = Vec::new();
    for m in Method::compared(&CONES) {
        let (mut larger, mut total, mut widest) = (0, 0, 1.0f64);
        let mut reference_exact = Vec::new();
        for (name, _, report) in studies {
            for c in report
                .compare_cones()
                .separate
                .iter()
                .filter(|c| c.method == m)
            {
                total += 1;
                if c.ratio > 1.0 {
                    larger += 1;
                }
                if c.ratio.is_infinite() {
                    if !reference_exact.contains(name) {
                        reference_exact.push(*name);
                    }
                } else if c.ratio > 1.0 {
                    // The sentence says by how much the method's error is the larger.
                    widest = widest.max(c.ratio);
                }
            }
        }
        let exact = if reference_exact.is_empty() {
            String::new()
        } else {
            let names: Vec<String> = reference_exact.iter().map(|n| format!("`{n}`")).collect();
            format!(
                "; {reference} is exact to round-off where {m} is not in {}",
                names.join(", ")
            )
        };
        let by = if larger > 0 && widest > 1.0 {
            format!(", by up to {widest:.0}x")
        } else {
            String::new()
        };
        parts.push(if total == 0 {
            format!("{m}: no contact quantity's error separates it from {reference}")
        } else {
            format!("{m}: {total} contact-quantity errors separate it from {reference}, {m}'s the larger in {larger}{by}{exact}")
        });
    }
    format!(
        "over the {} studies (ratio beyond {SEPARATES}x at the finest level, among the quantities where every method's verdict supports a comparison, the rule of each study's README; the others are listed in docs/results.md): {}",
        studies.len(),
        parts.join("; ")
    )
}

/// Theorem 3.1's norm in one cone over the studies: the range of the fitted rates, and
/// each study whose errors support no rate, with its verdict.
fn theorem_rates(studies: &[(&str, &str, Report)], m: Method) -> String {
    let rows: Vec<(&str, &RateRecord)> = studies
        .iter()
        .filter_map(|(name, _, r)| Some((*name, r.rate(m, Quantity::Theorem)?)))
        .collect();
    let fitted: Vec<f64> = rows
        .iter()
        .filter(|(_, r)| r.verdict.supports_rate())
        .filter_map(|(_, r)| r.rate)
        .collect();
    let (lo, hi) = fitted
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let range = if fitted.is_empty() {
        "no fitted rate".to_string()
    } else if format!("{lo:.2}") == format!("{hi:.2}") {
        format!("{lo:.2} fitted in {} studies", fitted.len())
    } else {
        format!("{lo:.2}-{hi:.2} fitted in {} studies", fitted.len())
    };
    let others: Vec<String> = rows
        .iter()
        .filter(|(_, r)| !r.verdict.supports_rate())
        .map(|(name, r)| format!("{} in `{name}`", rate_short(r)))
        .collect();
    let more = if others.is_empty() {
        String::new()
    } else {
        format!(", {}", others.join(", "))
    };
    let held: Vec<String> = rows
        .iter()
        .map(|(name, r)| format!("`{name}` {}", held_to(r)))
        .collect();
    format!(
        "{m} {range}{more} (each study file's threshold: {})",
        held.join(", ")
    )
}

/// Each (method, quantity) that does not converge, with the studies where it stalls.
fn stalled_anywhere(studies: &[(&str, &str, Report)]) -> Vec<String> {
    by_study(studies, |report| report.stalled().collect())
}

/// Each (method, quantity) fixed at a node, with the studies where it is.
fn fixed_anywhere(studies: &[(&str, &str, Report)]) -> Vec<String> {
    by_study(studies, |report| {
        report
            .rates
            .iter()
            .filter(|r| r.verdict == Verdict::Fixed)
            .collect()
    })
}

/// "method `quantity` (in study, study)" for each row `pick` takes from the studies.
fn by_study<'a>(
    studies: &'a [(&str, &str, Report)],
    pick: impl Fn(&'a Report) -> Vec<&'a RateRecord>,
) -> Vec<String> {
    let mut found: Vec<(String, Vec<&str>)> = Vec::new();
    for (name, _, report) in studies {
        for r in pick(report) {
            let key = format!("{} `{}`", r.method, r.quantity);
            match found.iter_mut().find(|(k, _)| *k == key) {
                Some((_, names)) => names.push(name),
                None => found.push((key, vec![name])),
            }
        }
    }
    found
        .iter()
        .map(|(k, names)| format!("{k} (in {})", names.join(", ")))
        .collect()
}

/// One study's row of the headline table.
fn headline_row(name: &str, what: &str, report: &Report) -> Vec<String> {
    let mut comparison = report.compare_cones();
    // The widest gap first; an exact cone (an infinite or zero ratio) leads.
    comparison
        .separate
        .sort_by(|a, b| b.gap().total_cmp(&a.gap()));
    let separate: Vec<String> = comparison
        .separate
        .iter()
        .map(Separation::headline_text)
        .collect();
    let separate = if separate.is_empty() {
        format!("none beyond {SEPARATES}x (level {})", report.finest)
    } else {
        format!("level {}: {}", report.finest, separate.join(", "))
    };
    let stalled: Vec<String> = report
        .stalled()
        .map(|r| format!("{} `{}`", r.method, r.quantity))
        .collect();
    let mut row = vec![
        format!("[`{name}`]({README_REPORTS}/{name}/README.md): {what}"),
        separate,
        listed(&stalled, ", ", "nothing"),
    ];
    row.extend(CONES.iter().map(|&m| judged_rate(report, m)));
    row
}

/// The rate of the quantity the study judges (the one with a threshold) in cone `m`, as
/// far as its verdict supports one.
fn judged_rate(report: &Report, m: Method) -> String {
    // The quantity some method's threshold is on: a method may have none there.
    let judged = report
        .rates
        .iter()
        .find(|r| r.threshold.is_some())
        .map(|r| r.quantity);
    report
        .rates
        .iter()
        .find(|r| r.method == m && Some(r.quantity) == judged)
        .map_or("not measured".to_string(), |r| {
            let rate = match (r.verdict, r.rate, r.stderr) {
                (Verdict::Fitted, Some(v), Some(se)) => {
                    format!("{v:.3} ± {se:.3} {}", r.verdict.name())
                }
                (Verdict::RoundOff, _, _) => "exact (round-off)".to_string(),
                _ => rate_short(r),
            };
            // What the distance to mortar supports beside what was observed.
            let asymptote = report
                .asymptotes
                .iter()
                .find(|a| a.method == m && a.quantity == r.quantity)
                .map_or(String::new(), |a| format!("; {}", a.describe()));
            let held = held_to(r);
            if r.quantity == Quantity::Theorem {
                format!("{rate} ({held}){asymptote}")
            } else {
                format!("`{}` {rate} ({held}){asymptote}", r.quantity)
            }
        })
}
