//! Reference: Theorem 3.1 of the paper (H1 rates h^(3/4) for K_h^pi, h^(1/2) for K_h^I).
//! Goal: the quick tier of `study rates` (levels 0-2, reference on matching meshes at
//! level 5) meets the theorem's thresholds minus the study's tolerance, with every level
//! in the fit and the reference's own error at least 5x below the finest level's error.
//! Geometry and data: the `rates` scene, 4 time steps, newton solver.

mod common;

use contact_rates::contact::Method;
use contact_rates::studies::{Study, convergence};
use contact_rates::verify::{
    jobs::Mode,
    quantity::Quantity,
    rates,
    study_file::{self, StudyFile},
};

#[test]
fn quick_rates_study_meets_the_theorem_thresholds() {
    contact_rates::init();
    let res = convergence::run("rates-quick").unwrap();
    let reference = res.reference.expect("a reference solve");
    let (ref_err, p) = (reference.error, reference.error_rate);
    println!("reference error estimate {ref_err:.3e} (fitted p = {p:.2})");
    for r in res.rates.iter().filter(|r| r.quantity == Quantity::Theorem) {
        // All quick levels are asymptotic and unflagged.
        common::assert_rate_passes(r, &[0, 1, 2]);
        let finest = res
            .errors
            .iter()
            .filter(|e| e.method == r.method && e.quantity == Quantity::Theorem)
            .map(|e| e.error)
            .fold(f64::INFINITY, f64::min);
        assert!(
            finest >= 5.0 * ref_err,
            "reference error {ref_err} not 5x below {finest}"
        );
    }
    assert!(
        res.errors
            .iter()
            .all(|e| e.error.is_finite() && e.wall_s.is_some_and(f64::is_finite))
    );
    // The two cones differ where the contact condition acts: the contact pressure.
    let pe = |m: Method| {
        res.errors
            .iter()
            .filter(|e| e.method == m && e.quantity == Quantity::L2Pressure)
            .map(|e| e.error)
            .fold(f64::INFINITY, f64::min)
    };
    assert!(pe(Method::Mortar) != pe(Method::Nts));

    // The same study spread over two shards and merged from their records gives the same
    // errors and rates to the last bit (the jobs are independent and deterministic).
    assert!(
        convergence::run_mode("rates-quick", Mode::Shard(1, 2))
            .unwrap()
            .is_none()
    );
    assert!(
        convergence::run_mode("rates-quick", Mode::Shard(2, 2))
            .unwrap()
            .is_none()
    );
    let merged = convergence::run_mode("rates-quick", Mode::Merge)
        .unwrap()
        .unwrap();
    assert_eq!(res.errors.len(), merged.errors.len());
    for (a, b) in res.errors.iter().zip(&merged.errors) {
        assert_eq!(
            (&a.method, a.level, a.quantity, a.error.to_bits()),
            (&b.method, b.level, b.quantity, b.error.to_bits())
        );
    }
    for (a, b) in res.rates.iter().zip(&merged.rates) {
        assert_eq!(
            (
                a.rate().to_bits(),
                a.stderr().to_bits(),
                &a.assessment.used,
                a.outcome
            ),
            (
                b.rate().to_bits(),
                b.stderr().to_bits(),
                &b.assessment.used,
                b.outcome
            )
        );
    }

    // `study rates-quick --rejudge`: the written report judged again from its CSVs and
    // run.toml rewrites every file byte for byte (rates.csv, plots, README.md), without
    // solving; von_mises.png is kept.
    let dir = tempfile::tempdir().unwrap();
    let (full, again) = (dir.path().join("full"), dir.path().join("again"));
    convergence::report::write_study(&res, &full).unwrap();
    convergence::report::write_study(&res, &again).unwrap();
    let rejudged = convergence::rejudge("rates-quick", &again).unwrap();
    convergence::report::write_study(&rejudged, &again).unwrap();
    let mut names: Vec<_> = std::fs::read_dir(&full)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    names.sort();
    assert!(names.iter().any(|n| n == "rates.csv") && names.iter().any(|n| n == "README.md"));
    for name in &names {
        let (a, b) = (
            std::fs::read(full.join(name)).unwrap(),
            std::fs::read(again.join(name)).unwrap(),
        );
        assert!(a == b, "{name:?} differs after --rejudge");
    }
}

#[test]
fn least_squares_rate_recovers_a_known_power_law() {
    let h = [0.4, 0.2, 0.1, 0.05];
    let e: Vec<f64> = h.iter().map(|x: &f64| 3.0 * x.powf(0.75)).collect();
    let f = rates::fit(&h, &e).unwrap();
    assert!((f.rate - 0.75).abs() < 1e-12 && f.stderr < 1e-12);
    let s = rates::successive(&h, &e);
    assert!(s.iter().all(|r| (r - 0.75).abs() < 1e-12));
    // Noise gives a positive standard error.
    let noisy = [e[0] * 1.05, e[1], e[2] * 0.97, e[3]];
    assert!(rates::fit(&h, &noisy).unwrap().stderr > 0.0);
}

#[test]
fn study_file_errors_name_the_file_and_key() {
    let dir = tempfile::tempdir().unwrap();
    let base = std::fs::read_to_string(study_file::builtin_dir().join("rates.toml")).unwrap();
    let cases = [
        (
            base.replace("steps = 4", "steps = 4\nspeed = 2"),
            "unknown field `speed`",
        ),
        (base.replace("steps = 4\n", ""), "missing field `steps`"),
        (base.replace("ratio = 1.4142", "ratio = 1.5"), "mesh.ratio"),
        (
            base.replace("levels_above = 3", "levels_above = 1"),
            "reference.levels_above",
        ),
        (
            base.replace("tolerance = 0.05", "tolerance = 0.2"),
            "thresholds.tolerance",
        ),
        (
            base.replace(
                "methods = [\"mortar\", \"nts\", \"lac\"]",
                "methods = [\"penalty\"]",
            ),
            "unknown method 'penalty'",
        ),
        (
            base.replace("levels = [0, 1, 2, 3]", "levels = [0, 1]"),
            "mesh.levels",
        ),
        (base.replace("steps = 4", "steps = 0"), "steps"),
        // Checked when the file is read, not after the solves.
        (
            base.replace("reference_steps = 512", "reference_steps = 500"),
            "time.reference_steps",
        ),
        (
            base.replace(
                "quantities = [\"theorem\"",
                "quantities = [\"theorem\", \"energy\"",
            ),
            "unknown quantity 'energy'",
        ),
        (
            base.replace("solver = \"newton\"", "solver = \"cg\""),
            "unknown solver 'cg'",
        ),
    ];
    for (text, needle) in cases {
        let f = dir.path().join("bad.toml");
        std::fs::write(&f, text).unwrap();
        let e = StudyFile::load(&f).unwrap_err().to_string();
        assert!(
            e.contains("bad.toml") && e.contains(needle),
            "'{needle}' not in: {e}"
        );
    }
}

#[test]
fn shard_argument_is_checked() {
    assert_eq!(Mode::shard("2/4").unwrap(), Mode::Shard(2, 4));
    for bad in ["0/2", "3/2", "1", "a/b", "1/0"] {
        let e = Mode::shard(bad).unwrap_err().to_string();
        assert!(e.contains("--shard") && e.contains(bad), "{e}");
    }
}

#[test]
fn study_list_names_every_kind() {
    let names: Vec<String> = Study::list().into_iter().map(|(n, _)| n).collect();
    for kind in [
        "paper",
        "patch",
        "rates",
        "rates-quick",
        "speed",
        "stability",
    ] {
        assert!(
            names.iter().any(|n| n == kind),
            "{kind} missing from {names:?}"
        );
    }
    let speed = Study::resolve("speed").unwrap();
    assert_eq!((speed.kind.name, speed.file), ("speed", None));
    let rates = Study::resolve("rates").unwrap();
    assert_eq!(rates.kind.name, "convergence");
    assert!(rates.file.unwrap().ends_with("studies/rates.toml"));
    assert_eq!(
        Study::resolve("two-size-quick").unwrap().kind.name,
        "two-size"
    );
}
