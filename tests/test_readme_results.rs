//! Reference: issue 20 (the front page says what the harness found; no reported rate
//! disagrees with its last successive rates unless its verdict says so); issue 47 (the
//! front page's headline table, the full Results in docs/results.md); SPEC section 5.
//! Goal: docs/results.md and README.md's headline (between its `headline` markers) are
//! exactly what the committed reports' CSVs say (`contact-rates results` and
//! `contact-rates results --headline` regenerate them); the headline prints no rate that
//! a verdict does not support; and every rate a committed rates.csv calls "fitted" lies
//! within max(0.15, 2 stderr) of the mean of its last two successive rates.
//! Data: README.md, docs/results.md and reports/*/rates.csv, errors.csv as committed.

use contact_rates::results::{HEADLINE, STUDIES, headline, section};
use contact_rates::verify::rates::Verdict;
use contact_rates::verify::table::{RateRecord, read};
use std::path::Path;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

const START: &str = "<!-- headline:start -->\n";
const END: &str = "<!-- headline:end -->";

/// README.md's text between the headline markers, and where it starts.
fn readme_headline(readme: &str) -> (usize, &str) {
    let start = readme
        .find(START)
        .expect("README.md has a `<!-- headline:start -->` line")
        + START.len();
    let end = start
        + readme[start..]
            .find(END)
            .expect("README.md has a `<!-- headline:end -->` line after the start marker");
    (start, &readme[start..end])
}

#[test]
fn docs_results_page_matches_the_committed_reports() {
    let written = std::fs::read_to_string(root().join("docs/results.md")).unwrap();
    let expected = section(&root().join("reports")).unwrap();
    assert!(
        written == expected,
        "docs/results.md no longer matches the reports' CSVs; regenerate it with `cargo run --release -- results > docs/results.md`:\n{expected}"
    );
}

#[test]
fn readme_headline_matches_the_committed_reports() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let (start, written) = readme_headline(&readme);
    let expected = headline(&root().join("reports")).unwrap();
    assert!(
        written == expected,
        "README.md's headline no longer matches the reports' CSVs; replace the text between its headline markers with the output of `cargo run --release -- results --headline`:\n{expected}"
    );
    // The front page: the set-up commands, what it is, then what it found.
    let what_it_is = readme
        .find("## What it is")
        .expect("a 'What it is' section");
    assert!(readme.find("```sh").unwrap() < what_it_is && what_it_is < start);
}

/// Every number with a decimal point in the headline table's rows is a rate (to 2 or 3
/// decimals) of a fitted or drifting row of that study, or its standard error: no rate a
/// verdict does not support is printed.
#[test]
fn headline_prints_only_rates_the_verdicts_support() {
    let text = headline(&root().join("reports")).unwrap();
    let mut checked = 0;
    for (name, _) in HEADLINE {
        let row = text
            .lines()
            .find(|l| l.starts_with(&format!("| [`{name}`]")))
            .unwrap_or_else(|| panic!("no headline row for {name}"));
        let path = root().join("reports").join(name).join("rates.csv");
        let rows: Vec<RateRecord> = read(&path).unwrap();
        let mut allowed = Vec::new();
        for r in rows
            .iter()
            .filter(|r| matches!(r.verdict, Verdict::Fitted | Verdict::Drifting))
        {
            let (rate, se) = (r.rate.unwrap(), r.stderr.unwrap());
            allowed.extend([
                format!("{rate:.2}"),
                format!("{rate:.3}"),
                format!("{se:.3}"),
            ]);
        }
        // A ratio ends in 'x' ("63x", "3.0x") and so is not a number here.
        for token in row.split(|c: char| !(c.is_ascii_digit() || c == '.' || c == 'x')) {
            let token = token.trim_end_matches('.');
            if token.contains('.') && token.parse::<f64>().is_ok() {
                assert!(
                    allowed.iter().any(|a| a == token),
                    "{name}: the headline prints {token}, not the rate or standard error of a fitted or drifting row:\n{row}"
                );
                checked += 1;
            }
        }
    }
    println!("{checked} headline numbers checked");
    assert!(checked >= 8);
}

#[test]
fn every_fitted_rate_agrees_with_its_last_successive_rates() {
    let mut checked = 0;
    for (name, _) in STUDIES {
        let path = root().join("reports").join(name).join("rates.csv");
        for r in read::<RateRecord>(&path).unwrap() {
            if r.verdict != Verdict::Fitted {
                continue;
            }
            let (rate, se) = (r.rate.unwrap(), r.stderr.unwrap());
            let last: Vec<f64> = r
                .successive
                .split_whitespace()
                .filter_map(|v| v.parse().ok())
                .collect();
            let tail = &last[last.len().saturating_sub(2)..];
            let mean = tail.iter().sum::<f64>() / tail.len() as f64;
            let tolerance = 0.15f64.max(2.0 * se);
            assert!(
                (rate - mean).abs() <= tolerance,
                "{name} {} {}: fitted {rate:.3} but last successive rates {tail:?}",
                r.method,
                r.quantity
            );
            checked += 1;
        }
    }
    println!("{checked} fitted rates checked");
    assert!(checked > 20);
}
