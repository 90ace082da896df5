//! Reference: issue 72 (each threshold from the theorem that states it, read from the
//! study file); Theorem 3.1 of Fernández, Hild and Viaño (3/4 for K_h^pi, 1/2 for K_h^I);
//! Drouet and Hild, Numer. Math. 136 (2017) for LAC (rate 1 for u in H^2, a claim under
//! test).
//! Goal: the thresholds the judge applies are the study file's and nothing else: the
//! committed rates-exact errors judged with studies/rates-exact.toml pass every method; the
//! same file with lac's rate raised to 1.2 fails lac alone (its last judged rate is 0.998 <
//! 1.15), with mortar's raised to 1.2 fails mortar alone, and with lac `none` gives lac no
//! threshold; a listed method with no entry is refused with the field named.
//! Geometry and data: contact-mms, levels 0-5, the committed reports/rates-exact CSVs.

use contact_rates::contact::Method;
use contact_rates::studies::convergence;
use contact_rates::verify::quantity::Quantity;
use contact_rates::verify::rates::Outcome;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).to_path_buf()
}

/// studies/rates-exact.toml with `line` (the entry of `key` in [thresholds]) replaced, in a
/// temporary folder of its own.
fn variant(tag: &str, key: &str, line: Option<&str>) -> PathBuf {
    let text = std::fs::read_to_string(root().join("studies/rates-exact.toml")).unwrap();
    let out: Vec<String> = text
        .lines()
        .filter_map(|l| match l.starts_with(&format!("{key} = ")) {
            true => line.map(String::from),
            false => Some(l.to_string()),
        })
        .collect();
    let dir = std::env::temp_dir().join(format!(
        "contact-rates-thresholds-{tag}-{}",
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("rates-exact.toml");
    std::fs::write(&path, out.join("\n")).unwrap();
    path
}

/// The outcome of each method's theorem-norm threshold, the study file at `path` judging
/// the committed errors.
fn outcomes(path: &Path) -> Vec<(Method, Option<Outcome>, Option<f64>)> {
    let res =
        convergence::rejudge(path.to_str().unwrap(), &root().join("reports/rates-exact")).unwrap();
    Method::ALL
        .iter()
        .map(|&m| {
            let r = res
                .rates
                .iter()
                .find(|r| r.method.cone() == Some(m) && r.quantity == Quantity::Theorem)
                .expect("a theorem row");
            (m, r.outcome, r.threshold.map(|t| t.value()))
        })
        .collect()
}

#[test]
fn the_study_files_thresholds_decide_the_outcome() {
    let committed = outcomes(&root().join("studies/rates-exact.toml"));
    println!("committed: {committed:?}");
    assert!(committed.iter().all(|(_, o, _)| *o == Some(Outcome::Pass)));
    assert_eq!(
        committed[2].2,
        Some(0.95),
        "lac held to Drouet and Hild's 1 minus 0.05"
    );

    let lac = outcomes(&variant(
        "lac",
        "lac",
        Some("lac = { rate = 1.2, source = \"test\" }"),
    ));
    println!("lac 1.2: {lac:?}");
    assert_eq!(lac[2].1, Some(Outcome::Fail));
    assert_eq!(
        (lac[0].1, lac[1].1),
        (Some(Outcome::Pass), Some(Outcome::Pass))
    );

    let mortar = outcomes(&variant(
        "mortar",
        "mortar",
        Some("mortar = { rate = 1.2, source = \"test\" }"),
    ));
    println!("mortar 1.2: {mortar:?}");
    assert_eq!(mortar[0].1, Some(Outcome::Fail));
    assert_eq!(
        (mortar[1].1, mortar[2].1),
        (Some(Outcome::Pass), Some(Outcome::Pass))
    );

    let none = outcomes(&variant(
        "none",
        "lac",
        Some("lac = { none = \"test: no theorem\" }"),
    ));
    assert_eq!((none[2].1, none[2].2), (None, None));

    let missing = variant("missing", "lac", None);
    let err = convergence::rejudge(
        missing.to_str().unwrap(),
        &root().join("reports/rates-exact"),
    )
    .err()
    .expect("a listed method without a threshold entry is refused")
    .to_string();
    println!("{err}");
    assert!(err.contains("thresholds.lac"), "{err}");
}
