//! Every figure in a committed report is its own method's.
//!
//! Reference: issue "Every figure in a report is its own method's" (an independent review
//! re-derived every cell of the committed READMEs from their CSVs).
//! Goal: (1) no README table mixes methods' rows without a method column; every rate,
//! verdict and ratio cell of a table with a method column is the CSV row of the method
//! named in its row, re-derived here from rates.csv and asymptotes.csv by a formatter of
//! this test's own; (2) no committed CSV holds a non-finite number or a relative error
//! above 1e3 (an error relative to a size the truth lacks).
//! Data: reports/ as committed.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One Markdown table: the heading above it, its header and its rows.
struct MdTable {
    heading: String,
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

fn cells(line: &str) -> Vec<String> {
    let inner = line.trim().trim_start_matches('|').trim_end_matches('|');
    inner.split('|').map(|c| c.trim().to_string()).collect()
}

fn tables(md: &str) -> Vec<MdTable> {
    let lines: Vec<&str> = md.lines().collect();
    let mut out = Vec::new();
    let mut heading = String::new();
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i];
        if line.starts_with('#') {
            heading = line.trim_start_matches('#').trim().to_string();
        }
        let is_separator = |l: &str| l.starts_with("|---") || l.starts_with("| ---");
        if line.starts_with('|') && i + 1 < lines.len() && is_separator(lines[i + 1]) {
            let header = cells(line);
            let mut rows = Vec::new();
            i += 2;
            while i < lines.len() && lines[i].starts_with('|') {
                rows.push(cells(lines[i]));
                i += 1;
            }
            out.push(MdTable {
                heading: heading.clone(),
                header,
                rows,
            });
            continue;
        }
        i += 1;
    }
    out
}

/// Every file below `dir` that `keep` takes, recursively.
fn files(dir: &Path, keep: &dyn Fn(&Path) -> bool, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("reports/ is readable") {
        let path = entry.expect("an entry").path();
        if path.is_dir() {
            files(&path, keep, out);
        } else if keep(&path) {
            out.push(path);
        }
    }
}

fn readmes(dir: &Path, out: &mut Vec<PathBuf>) {
    files(
        dir,
        &|p| p.file_name().is_some_and(|n| n == "README.md"),
        out,
    );
}

fn csv_files(dir: &Path, out: &mut Vec<PathBuf>) {
    files(dir, &|p| p.extension().is_some_and(|e| e == "csv"), out);
}

fn reports() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("reports")
}

/// A CSV file as rows of (column -> value).
fn read_csv(path: &Path) -> Vec<BTreeMap<String, String>> {
    let mut reader =
        csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let header: Vec<String> = reader
        .headers()
        .expect("a header")
        .iter()
        .map(String::from)
        .collect();
    reader
        .records()
        .map(|r| {
            let r = r.expect("a record");
            header
                .iter()
                .cloned()
                .zip(r.iter().map(String::from))
                .collect()
        })
        .collect()
}

/// The column that names a row's method, if the table has one.
fn method_column(header: &[String]) -> Option<usize> {
    header.iter().position(|h| h == "method" || h == "cone")
}

const METHODS: [&str; 3] = ["mortar", "nts", "lac"];

/// Column headers that name what a row is about (a row's key is its leading cells of these).
const KEYS: [&str; 10] = [
    "quantity",
    "level",
    "beta",
    "family",
    "scene",
    "case",
    "parameter",
    "study",
    "solver",
    "levels",
];

/// Tables without a method column that print one key twice: rows from more than one
/// method (or the same row twice), which a reader cannot tell apart.
fn mixed_tables(readme: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(readme).expect("a README");
    let mut bad = Vec::new();
    for t in tables(&text) {
        if method_column(&t.header).is_some() || t.rows.len() < 2 {
            continue;
        }
        // A row's key: its leading cells that name what the row is about.
        let keys = t
            .header
            .iter()
            .take_while(|h| KEYS.contains(&h.as_str()))
            .count()
            .max(1);
        let mut seen = BTreeMap::new();
        for row in &t.rows {
            let key = row[..keys.min(row.len())].join(" / ");
            if let Some(previous) = seen.insert(key.clone(), ()) {
                let _ = previous;
                bad.push(format!(
                    "{} (\"{}\", header {:?}): row key {key} twice and no method column",
                    readme.display(),
                    t.heading,
                    t.header
                ));
                break;
            }
        }
    }
    bad
}

/// What a rates.csv row reads as in a report cell, re-derived from its fields.
fn expected_rate_cell(row: &BTreeMap<String, String>) -> String {
    let num = |k: &str| row.get(k).and_then(|v| v.parse::<f64>().ok());
    let last = num("last_rate").map_or("NaN".into(), |v| format!("{v:.3}"));
    match row["verdict"].as_str() {
        "fitted" => format!(
            "{:.3} ± {:.3}",
            num("rate").unwrap(),
            num("stderr").unwrap()
        ),
        "falling" => format!("falling (last successive rate {last})"),
        "rising" => format!("rising (last successive rate {last})"),
        "pre-asymptotic" => "(pre-asymptotic)".into(),
        "round-off" => "exact (round-off".into(),
        "not converging" => "does not converge".into(),
        "too few levels" => "no fit".into(),
        "fixed by equilibrium" => "fixed by equilibrium".into(),
        "fixed at a node" => "fixed at a node".into(),
        v => panic!("unknown verdict {v}"),
    }
}

/// Whether `cell` says what `row` says: equal for a fitted or a transition verdict, the
/// verdict's words for the others.
fn cell_matches(cell: &str, row: &BTreeMap<String, String>) -> bool {
    let expected = expected_rate_cell(row);
    match row["verdict"].as_str() {
        "fitted" | "falling" | "rising" => cell.replace("**", "") == expected,
        _ => cell.contains(&expected),
    }
}

/// The distance quantity of a decomposed quantity.
fn distance_of(q: &str) -> Option<&'static str> {
    match q {
        "theorem" => Some("cone_distance"),
        "h1_u" => Some("cone_distance_h1_u"),
        "l2_stress" => Some("cone_distance_l2_stress"),
        _ => None,
    }
}

/// Every cell of a method-bearing table in a convergence README checked against the CSV
/// row of the method in its row; the mismatches.
fn foreign_cells(readme: &Path) -> (usize, Vec<String>) {
    let dir = readme.parent().expect("a folder");
    let (rates_path, asymptotes_path) = (dir.join("rates.csv"), dir.join("asymptotes.csv"));
    if !rates_path.exists() {
        return (0, Vec::new());
    }
    let rates = read_csv(&rates_path);
    if !rates.first().is_some_and(|r| {
        r.contains_key("method") && r.contains_key("verdict") && r.contains_key("stderr")
    }) {
        return (0, Vec::new());
    }
    let asymptotes = if asymptotes_path.exists() {
        read_csv(&asymptotes_path)
    } else {
        Vec::new()
    };
    let rate = |m: &str, q: &str| {
        rates
            .iter()
            .find(|r| r["method"] == m && r["quantity"] == q)
    };
    let text = std::fs::read_to_string(readme).expect("a README");
    let (mut checked, mut bad) = (0, Vec::new());
    let mut read_against_distance: Vec<(String, String)> = Vec::new();
    for t in tables(&text) {
        let (Some(mc), Some(qc)) = (
            method_column(&t.header),
            t.header.iter().position(|h| h == "quantity"),
        ) else {
            continue;
        };
        let col = |name: &str| t.header.iter().position(|h| h == name);
        for row in &t.rows {
            let m = row[mc].trim_matches('`');
            let q = row[qc].trim_matches('`');
            if !METHODS.contains(&m) {
                continue;
            }
            let mut check = |what: &str, cell: &str, ok: bool| {
                checked += 1;
                if !ok {
                    bad.push(format!(
                        "{}: table \"{}\", {m} {q}, {what}: \"{cell}\"",
                        readme.display(),
                        t.heading
                    ));
                }
            };
            match col("verdict") {
                // A table with a verdict column of its own (grade's): the verdict there, the
                // fit's rate and standard error beside it, "-" where there is no fit.
                Some(v) => {
                    if let (Some(c), Some(r)) = (col("rate in h"), rate(m, q)) {
                        check("verdict", &row[v], row[v] == r["verdict"]);
                        let expected = match (r["rate"].parse::<f64>(), r["stderr"].parse::<f64>())
                        {
                            (Ok(x), Ok(se)) => format!("{x:.3} ± {se:.3}"),
                            _ => "-".into(),
                        };
                        check("rate in h", &row[c], row[c] == expected);
                    }
                }
                None => {
                    for name in ["rate in h", "observed"] {
                        if let (Some(c), Some(r)) = (col(name), rate(m, q)) {
                            check(name, &row[c], cell_matches(&row[c], r));
                        }
                    }
                }
            }
            if let (Some(c), Some(r)) = (col("mortar"), rate("mortar", q)) {
                check("mortar", &row[c], cell_matches(&row[c], r));
            }
            if let (Some(c), Some(dq)) = (col("D (distance to mortar)"), distance_of(q)) {
                let ok = rate(m, dq).is_some_and(|r| cell_matches(&row[c], r));
                check("D", &row[c], ok);
            }
            let asymptote = asymptotes
                .iter()
                .find(|a| a["method"] == m && a["quantity"] == q);
            if let (Some(c), Some(a)) = (col("D / e_mortar, finest level"), asymptote) {
                let ok = row[c].starts_with("mortar exact")
                    || a["finest_ratio"]
                        .parse::<f64>()
                        .is_ok_and(|v| row[c] == format!("{v:.2}"));
                check("D / e_mortar", &row[c], ok);
            }
            if col("asymptotic rate").is_some() {
                read_against_distance.push((m.to_string(), q.to_string()));
            }
            if let (Some(c), Some(a)) = (col("asymptotic rate"), asymptote) {
                let ok = match a["asymptotic_rate"].parse::<f64>() {
                    Ok(v) => row[c].contains(&format!("{v:.3}")),
                    Err(_) => row[c].starts_with("no asymptotic rate"),
                };
                check("asymptotic rate", &row[c], ok);
            }
        }
    }
    // Every row of asymptotes.csv is a row of the README's distance table, under its method
    // (reports/codes, whose asymptotes.csv spans problems, prints its key quantity's only).
    let one_problem = asymptotes.first().is_none_or(|a| !a.contains_key("study"));
    for a in asymptotes
        .iter()
        .filter(|a| one_problem && METHODS.contains(&a["method"].as_str()))
    {
        if !read_against_distance
            .iter()
            .any(|(m, q)| *m == a["method"] && *q == a["quantity"])
        {
            bad.push(format!(
                "{}: asymptotes.csv's {} {} is no row of a table with a method column",
                readme.display(),
                a["method"],
                a["quantity"]
            ));
        }
    }
    (checked, bad)
}

#[test]
fn no_committed_table_mixes_methods_without_a_method_column() {
    let mut files = Vec::new();
    readmes(&reports(), &mut files);
    assert!(
        files.len() > 20,
        "the committed READMEs are found ({})",
        files.len()
    );
    let bad: Vec<String> = files.iter().flat_map(|f| mixed_tables(f)).collect();
    assert!(
        bad.is_empty(),
        "{} tables mix methods' rows:\n{}",
        bad.len(),
        bad.join("\n")
    );
}

#[test]
fn every_rate_verdict_and_ratio_cell_is_its_rows_method() {
    let mut files = Vec::new();
    readmes(&reports(), &mut files);
    let (mut checked, mut bad) = (0, Vec::new());
    for f in &files {
        let (n, b) = foreign_cells(f);
        checked += n;
        bad.extend(b);
    }
    assert!(
        bad.is_empty(),
        "{} of {checked} cells are not their row's method's:\n{}",
        bad.len(),
        bad.join("\n")
    );
    // 19 convergence READMEs with a rates table, 18 with a distance table.
    assert!(checked > 700, "cells checked: {checked}");
}

/// Columns of a committed CSV that hold a relative error or distance.
const RELATIVE: [&str; 3] = ["error", "mortar_error", "distance"];

#[test]
fn committed_csvs_are_finite_and_no_relative_error_exceeds_1e3() {
    let mut files = Vec::new();
    csv_files(&reports(), &mut files);
    assert!(
        files.len() > 50,
        "the committed CSVs are found ({})",
        files.len()
    );
    let mut bad = Vec::new();
    for f in &files {
        for (i, row) in read_csv(f).iter().enumerate() {
            for (column, value) in row {
                let Ok(v) = value.parse::<f64>() else {
                    continue;
                };
                if !v.is_finite() || (RELATIVE.contains(&column.as_str()) && v > 1e3) {
                    bad.push(format!("{} row {} {column} = {value}", f.display(), i + 2));
                }
            }
        }
    }
    assert!(
        bad.is_empty(),
        "{} values:\n{}",
        bad.len(),
        bad[..bad.len().min(40)].join("\n")
    );
}
