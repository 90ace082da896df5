//! Reference: issue 20 (the front page says what the harness found; no reported rate
//! disagrees with its last successive rates unless its verdict says so); SPEC section 5.
//! Goal: the README's Results section is exactly what the committed reports' CSVs say
//! (`contact-rates results` regenerates it), and every rate a committed rates.csv calls
//! "fitted" lies within max(0.15, 2 stderr) of the mean of its last two successive rates.
//! Data: README.md and reports/*/rates.csv, errors.csv as committed.

use contact_rates::results::{RateLine, STUDIES, section};
use contact_rates::verify::rates::Verdict;
use std::path::Path;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn readme_results_section_matches_the_committed_reports() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let start = readme
        .find("## Results\n")
        .expect("README has a Results section");
    let end = readme[start + 3..]
        .find("\n## ")
        .map_or(readme.len(), |i| start + 3 + i + 1);
    let written = &readme[start..end];
    let expected = section(&root().join("reports")).unwrap();
    assert!(
        written == expected,
        "README.md's Results section no longer matches the reports' CSVs; replace it with the output of `cargo run --release -- results`:\n{expected}"
    );
    // It comes right after the two set-up commands' paragraph, before the description.
    assert!(start < readme.find("## What it is").unwrap());
}

#[test]
fn every_fitted_rate_agrees_with_its_last_successive_rates() {
    let mut checked = 0;
    for (name, _) in STUDIES {
        let path = root().join("reports").join(name).join("rates.csv");
        let mut reader = csv::Reader::from_path(&path).unwrap();
        for row in reader.deserialize::<RateLine>() {
            let r = row.unwrap();
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
