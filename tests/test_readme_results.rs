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
use contact_rates::verify::judge::AsymptoteRow;
use contact_rates::verify::rates::{self, Verdict};
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

/// The headline table's row of study `name`.
fn headline_row<'a>(text: &'a str, name: &str) -> &'a str {
    text.lines()
        .find(|l| l.starts_with(&format!("| [`{name}`]")))
        .unwrap_or_else(|| panic!("no headline row for {name}"))
}

/// Every number with a decimal point in the headline table's rows is a rate (to 2 or 3
/// decimals) of a fitted row of that study, or its standard error, the last successive
/// rate of a row in transition (falling or rising), or what asymptotes.csv derives from
/// fitted rows (the asymptotic rate, its standard error, a predicted level): no rate a
/// verdict does not support is printed.
#[test]
fn headline_prints_only_rates_the_verdicts_support() {
    let text = headline(&root().join("reports")).unwrap();
    let mut checked = 0;
    for (name, _) in HEADLINE {
        let row = headline_row(&text, name);
        let path = root().join("reports").join(name).join("rates.csv");
        let rows: Vec<RateRecord> = read(&path).unwrap();
        let mut allowed = Vec::new();
        for r in rows.iter().filter(|r| r.verdict == Verdict::Fitted) {
            let (rate, se) = (r.rate.unwrap(), r.stderr.unwrap());
            allowed.extend([
                format!("{rate:.2}"),
                format!("{rate:.3}"),
                format!("{se:.3}"),
            ]);
        }
        // The study file's thresholds, as rates.csv holds them.
        allowed.extend(
            rows.iter()
                .filter_map(|r| r.threshold)
                .map(|t| format!("{t:.2}")),
        );
        for r in rows
            .iter()
            .filter(|r| matches!(r.verdict, Verdict::Falling | Verdict::Rising))
        {
            allowed.push(format!("{:.3}", r.last_rate.unwrap()));
        }
        let asymptotes = root().join("reports").join(name).join("asymptotes.csv");
        if asymptotes.exists() {
            let rows: Vec<AsymptoteRow> = read(&asymptotes).unwrap();
            for a in rows {
                allowed.extend(a.asymptotic_rate.map(|v| format!("{v:.3}")));
                allowed.extend(a.asymptotic_stderr.map(|v| format!("{v:.3}")));
                allowed.extend(a.predicted_from.map(|v| format!("{v:.1}")));
                allowed.extend(a.predicted_to.map(|v| format!("{v:.1}")));
            }
        }
        // A ratio ends in 'x' ("63x", "3.0x") and so is not a number here.
        for token in row.split(|c: char| !(c.is_ascii_digit() || c == '.' || c == 'x')) {
            let token = token.trim_end_matches('.');
            if token.contains('.') && token.parse::<f64>().is_ok() {
                assert!(
                    allowed.iter().any(|a| a == token),
                    "{name}: the headline prints {token}, not the rate or standard error of a fitted row:\n{row}"
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

/// The cells of a headline row (6: study, separations, stalls, mortar, nts, lac).
fn cells(row: &str) -> Vec<&str> {
    let cells: Vec<&str> = row
        .trim()
        .trim_matches('|')
        .split('|')
        .map(str::trim)
        .collect();
    assert_eq!(cells.len(), 6, "a headline row has 6 cells: {row}");
    cells
}

/// Each method's rate cell of a headline row: (method, quantity, the cell after its
/// quantity), the quantity `theorem` where the cell names none.
fn method_cells(row: &str) -> Vec<(&'static str, &str, &str)> {
    let cells = cells(row);
    [("mortar", cells[3]), ("nts", cells[4]), ("lac", cells[5])]
        .into_iter()
        .map(|(method, cell)| {
            let (quantity, text) = match cell.strip_prefix('`') {
                Some(rest) => rest.split_once("` ").unwrap(),
                None => ("theorem", cell),
            };
            (method, quantity, text)
        })
        .collect()
}

/// What a headline row states, one (method, quantity, text) per cell part: the contact
/// quantities that separate the cones ("`l2_pressure` 63x (mortar 1.85, nts not
/// converging)", "`band_stress` mortar exact (nts 0.60)") and the judged rate of each cone
/// ("0.981 ± 0.005 fitted" of the theorem norm, "`l2_stress` 0.601 ± 0.032 fitted"), lac's
/// beside them.
fn row_claims(row: &str) -> Vec<(String, String, String)> {
    let cells = cells(row);
    let mut claims = Vec::new();
    if let Some((_, items)) = cells[1].split_once(": ") {
        for item in items.split("), ") {
            let item = item.trim_end_matches(')');
            let mut parts = item.splitn(3, '`');
            let (_, quantity, after) = (parts.next(), parts.next().unwrap(), parts.next().unwrap());
            let (head, inner) = after.trim().split_once(" (").unwrap();
            for method in ["mortar", "nts"] {
                if head == format!("{method} exact") {
                    claims.push((method.into(), quantity.into(), "exact".into()));
                }
            }
            for part in inner.split(", ") {
                let (method, text) = part.split_once(' ').unwrap();
                claims.push((method.into(), quantity.into(), text.into()));
            }
        }
    }
    for (method, quantity, text) in method_cells(row) {
        // "observed; what the distance to mortar supports" (asymptotes.csv, checked apart).
        let observed = text.split_once("; ").map_or(text, |(o, _)| o);
        // "... (threshold 0.70: pass)": the study file's threshold, checked apart.
        let observed = held_apart(observed).0;
        if observed != "not measured" {
            claims.push((method.into(), quantity.into(), observed.into()));
        }
    }
    claims
}

/// A cell's observed text and its threshold's part in brackets ("threshold 0.70: pass",
/// "exact to 1e-9: pass", "no threshold"), if it ends with one.
fn held_apart(text: &str) -> (&str, Option<&str>) {
    match text.rsplit_once(" (") {
        Some((observed, held))
            if ["threshold ", "exact to ", "no threshold"]
                .iter()
                .any(|p| held.starts_with(p)) =>
        {
            (observed, Some(held.trim_end_matches(')')))
        }
        _ => (text, None),
    }
}

/// What a headline cell must say of rates.csv row `r`'s threshold, written here apart from
/// the library: the bound and outcome of rates.csv's `threshold` and `pass` columns.
fn expected_held(r: &RateRecord) -> String {
    match (r.threshold, r.pass) {
        (Some(t), Some(p)) if t > 0.0 && t < 1e-3 => format!("exact to {t:.0e}: {}", p.name()),
        (Some(t), Some(p)) => format!("threshold {t:.2}: {}", p.name()),
        _ => "no threshold".into(),
    }
}

/// Whether `text` says what the row `r` of rates.csv supports: its rate (and standard
/// error) where the verdict is fitted, "exact" at round-off, else what
/// [`rates::short_text`] says (the verdict, with the last successive rate in transition).
fn states(r: &RateRecord, text: &str) -> bool {
    let words: Vec<&str> = text.split_whitespace().collect();
    let rounded = |v: f64, token: &str| {
        let decimals = token.split_once('.').map_or(0, |(_, d)| d.len());
        decimals >= 2 && token == format!("{v:.decimals$}")
    };
    match (r.verdict, r.rate, r.stderr) {
        (Verdict::Fitted, Some(rate), Some(se)) => match words.as_slice() {
            [v] => rounded(rate, v),
            [v, "±", s, verdict] => {
                rounded(rate, v) && rounded(se, s) && *verdict == r.verdict.name()
            }
            _ => false,
        },
        (Verdict::RoundOff, _, _) => text == "exact" || text == "exact (round-off)",
        (v, rate, _) => text == rates::short_text(v, rate, r.last_rate),
    }
}

/// The claims of `row` that rates.csv's row of the same method and quantity does not
/// support.
fn unsupported(row: &str, rates: &[RateRecord]) -> Vec<String> {
    row_claims(row)
        .into_iter()
        .filter(|(m, q, text)| {
            !rates
                .iter()
                .find(|r| r.method.name() == m && r.quantity.name() == q)
                .is_some_and(|r| states(r, text))
        })
        .map(|(m, q, text)| format!("{m} {q}: '{text}'"))
        .collect()
}

/// Each rate, standard error and verdict in the headline table is the one of its own
/// method and quantity in that study's rates.csv (not just some row's), and a cell
/// with the cones swapped is refused.
#[test]
fn headline_cells_state_their_own_rows_rates() {
    let text = headline(&root().join("reports")).unwrap();
    let mut checked = 0;
    for (name, _) in HEADLINE {
        let row = headline_row(&text, name);
        let rates: Vec<RateRecord> =
            read(&root().join("reports").join(name).join("rates.csv")).unwrap();
        let wrong = unsupported(row, &rates);
        assert!(
            wrong.is_empty(),
            "{name}: not what rates.csv says: {wrong:?}\n{row}"
        );
        // Each method cell's threshold is its own row's, from rates.csv.
        for (method, quantity, text) in method_cells(row) {
            let observed = text.split_once("; ").map_or(text, |(o, _)| o);
            let r = rates
                .iter()
                .find(|r| r.method.name() == method && r.quantity.name() == quantity)
                .expect("the cell's row");
            assert_eq!(
                held_apart(observed).1,
                Some(expected_held(r).as_str()),
                "{name} {method}: {text}"
            );
            checked += 1;
        }
        checked += row_claims(row).len();
        // The asymptote after a rate cell's "; " is asymptotes.csv's own sentence.
        let path = root().join("reports").join(name).join("asymptotes.csv");
        let asymptotes: Vec<AsymptoteRow> = if path.exists() {
            read(&path).unwrap()
        } else {
            Vec::new()
        };
        for (method, q, text) in method_cells(row) {
            if let Some((_, said)) = text.split_once("; ") {
                let a = asymptotes
                    .iter()
                    .find(|a| a.method.name() == method && a.quantity.name() == q)
                    .unwrap_or_else(|| panic!("{name}: no asymptote row for {method} {q}"));
                assert_eq!(said, a.describe(), "{name} {method} {q}");
                checked += 1;
            }
        }
        if name == "rates-exact" {
            let swapped = row
                .replace("mortar", "\u{0}")
                .replace("nts", "mortar")
                .replace('\u{0}', "nts");
            assert!(!unsupported(&swapped, &rates).is_empty(), "{swapped}");
        }
    }
    println!("{checked} headline cells checked");
    assert!(checked >= 20);
}

/// docs/results.md's regularity table marks with † exactly the betas where the committed
/// rates.csv says Theorem 3.1 does not apply, on every quantity's row (cone_distance has
/// an nts row only).
#[test]
fn regularity_table_marks_the_theorem_rows_by_beta() {
    let text = section(&root().join("reports")).unwrap();
    let csv = std::fs::read_to_string(root().join("reports/regularity/rates.csv")).unwrap();
    // Betas as numbers: rates.csv writes 2.0 where the table writes 2.
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let column = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (beta_at, applies_at) = (column("beta"), column("theorem_applies"));
    let applies: Vec<(f64, bool)> = csv
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[beta_at].parse::<f64>().unwrap(), f[applies_at] == "true")
        })
        .collect();
    let rows: Vec<&str> = text
        .lines()
        .filter(|l| l.starts_with("| ") && l.contains(" | `"))
        .filter(|l| {
            let beta = l[2..].split(' ').next().unwrap().parse::<f64>();
            beta.is_ok_and(|beta| applies.iter().any(|(b, _)| *b == beta))
        })
        .collect();
    assert!(
        rows.len() >= 30,
        "the regularity table has its rows, got {}",
        rows.len()
    );
    for row in rows {
        let beta: f64 = row[2..].split(' ').next().unwrap().parse().unwrap();
        let theorem = applies.iter().find(|(b, _)| *b == beta).unwrap().1;
        let dagger = row.split(" | ").next().unwrap().ends_with('†');
        assert_eq!(dagger, !theorem, "row {row}: † must mark beta <= 1 only");
    }
}

/// Reference: issue 74 (a glossary shared by docs/studies.md and the grade reports).
/// Goal: docs/studies.md's glossary, between its `glossary` markers, is the one
/// `contact-rates results --glossary` prints, and names every quantity.
#[test]
fn docs_studies_glossary_is_the_one_the_reports_print() {
    use contact_rates::verify::quantity::{Quantity, glossary};
    let studies = std::fs::read_to_string(root().join("docs/studies.md")).unwrap();
    let (start, end) = ("<!-- glossary:start -->\n", "<!-- glossary:end -->");
    let from = studies
        .find(start)
        .expect("docs/studies.md has glossary markers")
        + start.len();
    let to = from + studies[from..].find(end).expect("a glossary end marker");
    let expected = glossary(&Quantity::ALL);
    assert!(
        studies[from..to] == expected,
        "docs/studies.md's glossary differs; replace the text between its glossary markers with the output of `cargo run --release -- results --glossary`:\n{expected}"
    );
    for q in Quantity::ALL {
        assert!(
            expected.contains(&format!("`{}`", q.name())),
            "{q} has no entry"
        );
    }
}
