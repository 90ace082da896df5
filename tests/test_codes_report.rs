//! Reference: issue 61 (what real contact codes converge at: reports/codes).
//! Goal: the committed report says what its CSVs hold: every table row's rate and finest
//! error are rates.csv's and errors.csv's; no graded level is flagged; on `crossover`, where
//! the cones differ, the node-on-segment brick sides with nts and the mortar codes with
//! mortar (finest theorem errors), and the distance to mortar of the node-on-segment code is
//! read at h^(1/2).
//! Geometry and data: the committed reports/codes (GetFEM 5.4, Kratos 10.4; the libraries are
//! not needed: the report is read, not rebuilt).

use contact_rates::external::codes::{CodeAsymptote, CodeCheck, CodeError, CodeRate};
use contact_rates::verify::quantity::Quantity;
use contact_rates::verify::rates::Verdict;
use contact_rates::verify::table::read;
use std::path::PathBuf;

fn dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("reports/codes")
}

/// The README's table rows of one problem's section: cells per row.
fn rows(readme: &str, study: &str) -> Vec<Vec<String>> {
    let start = readme
        .find(&format!("## {study} (levels"))
        .unwrap_or_else(|| panic!("no section {study}"));
    readme[start..]
        .lines()
        .skip(1)
        .take_while(|l| !l.starts_with("## "))
        .filter(|l| l.starts_with("| `"))
        .map(|l| {
            l.trim_matches('|')
                .split(" | ")
                .map(|c| c.trim().to_string())
                .collect()
        })
        .collect()
}

#[test]
fn the_committed_codes_report_says_what_its_csvs_hold() {
    let readme = std::fs::read_to_string(dir().join("README.md")).unwrap();
    let errors: Vec<CodeError> = read(&dir().join("errors.csv")).unwrap();
    let rates: Vec<CodeRate> = read(&dir().join("rates.csv")).unwrap();
    let checks: Vec<CodeCheck> = read(&dir().join("checks.csv")).unwrap();
    let asymptotes: Vec<CodeAsymptote> = read(&dir().join("asymptotes.csv")).unwrap();
    assert!(!checks.is_empty());
    for c in &checks {
        assert_eq!(c.verdict, "converged", "{c:?}");
    }
    let mut studies: Vec<&str> = errors.iter().map(|r| r.study.as_str()).collect();
    studies.dedup();
    for study in &studies {
        assert!(dir().join(format!("error_vs_h_{study}.png")).exists());
        let key = match errors
            .iter()
            .any(|r| &r.study == study && r.quantity == Quantity::Theorem)
        {
            true => Quantity::Theorem,
            false => Quantity::L2Stress,
        };
        for row in rows(&readme, study) {
            let method = row[0].trim_matches('`');
            let finest = errors
                .iter()
                .filter(|r| &r.study == study && r.method.name() == method && r.quantity == key)
                .max_by_key(|r| r.level)
                .unwrap();
            assert_eq!(row[3], format!("{:.4e}", finest.error), "{study} {method}");
            let rate = rates
                .iter()
                .find(|r| &r.study == study && r.method.name() == method && r.quantity == key)
                .unwrap();
            match (rate.verdict, rate.rate, rate.stderr) {
                (Verdict::Fitted, Some(v), Some(s)) => {
                    assert_eq!(
                        row[2],
                        format!("{v:.3} ± {s:.3} (fitted)"),
                        "{study} {method}"
                    )
                }
                _ => assert!(
                    row[2].starts_with(&rate.reads),
                    "{study} {method}: {}",
                    row[2]
                ),
            }
        }
    }
    // Where the cones differ (nts's finest theorem error 1.2 times mortar's or more:
    // crossover and the regularity family below beta = 2), each code sides with its kind,
    // the nearer cone in log.
    let finest = |study: &str, method: &str| {
        errors
            .iter()
            .filter(|r| {
                r.study == study && r.method.name() == method && r.quantity == Quantity::Theorem
            })
            .max_by_key(|r| r.level)
            .map(|r| r.error)
    };
    let mut apart = Vec::new();
    for study in &studies {
        let (Some(mortar), Some(nts)) = (finest(study, "mortar"), finest(study, "nts")) else {
            continue;
        };
        if nts < 1.2 * mortar {
            continue;
        }
        apart.push(*study);
        let near = |x: f64| {
            if (x / mortar).ln().abs() < (x / nts).ln().abs() {
                "mortar"
            } else {
                "nts"
            }
        };
        println!("{study} finest: mortar {mortar:.4e}, nts {nts:.4e}");
        for (code, side) in [
            ("getfem-integral", "mortar"),
            ("kratos-alm", "mortar"),
            ("getfem-nodal", "nts"),
        ] {
            let x = finest(study, code).unwrap();
            println!(
                "  {code}: {x:.4e} ({:.3} x mortar, {:.3} x nts)",
                x / mortar,
                x / nts
            );
            assert_eq!(near(x), side, "{study} {code}");
        }
    }
    assert!(apart.contains(&"crossover"), "{apart:?}");
    // The node-on-segment brick's distance to mortar: fitted at h^(1/2) within 0.1.
    let d = asymptotes
        .iter()
        .find(|a| {
            a.study == "crossover"
                && a.method.name() == "getfem-nodal"
                && a.quantity == Quantity::Theorem
        })
        .unwrap();
    let r = rates
        .iter()
        .find(|r| {
            r.study == "crossover"
                && r.method.name() == "getfem-nodal"
                && r.quantity == Quantity::ConeDistance
        })
        .unwrap();
    println!(
        "getfem-nodal on crossover: D {:?} {:?}, asymptote {:?}",
        r.verdict, r.rate, d.asymptotic_rate
    );
    assert_eq!(r.verdict, Verdict::Fitted);
    assert!((r.rate.unwrap() - 0.5).abs() <= 0.1, "{:?}", r.rate);
}
