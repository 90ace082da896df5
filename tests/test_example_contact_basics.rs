//! Reference: the committed report reports/rates-exact (errors.csv), the manufactured
//! `contact-mms` scene against its exact solution.
//! Goal: the teaching example examples/contact_basics.rs runs, and what it prints is what
//! the study measured: it drives the library on its own (scene, case, solve, exact error),
//! so its theorem-norm error at level 1 must equal the report's for every cone to the
//! seven digits it prints (the same meshes, steps and quadrature).
//! Geometry and data: scenes/contact-mms.toml, level 1 (465 dofs), 4 steps.

#[path = "../examples/contact_basics.rs"]
#[allow(dead_code)]
mod example;

use contact_rates::verify::quantity::Quantity;
use contact_rates::verify::table::{ErrorRecord, MethodLabel, read};

#[test]
fn the_teaching_example_prints_the_reports_errors() {
    let mut out = Vec::new();
    example::run(1, &mut out).unwrap();
    let text = String::from_utf8(out).unwrap();
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("reports/rates-exact/errors.csv");
    let report: Vec<ErrorRecord> = read(&path).unwrap();
    for method in ["mortar", "nts", "lac"] {
        let line = text
            .lines()
            .find(|l| l.starts_with(&format!("{method}: level 1,")))
            .unwrap_or_else(|| panic!("no line for {method} in\n{text}"));
        let printed: f64 = line
            .split("theorem-norm error ")
            .nth(1)
            .and_then(|s| s.split(',').next())
            .and_then(|s| s.parse().ok())
            .unwrap_or_else(|| panic!("no error in '{line}'"));
        let expected = report
            .iter()
            .find(|r| {
                r.method == MethodLabel::parse(method)
                    && r.level == 1
                    && r.quantity == Quantity::Theorem
            })
            .unwrap()
            .error;
        assert!(
            (printed - expected).abs() <= 5e-7 * expected,
            "{method}: printed {printed:e}, report {expected:e}"
        );
    }
    // Six pressures per cone, finite and non-negative (a multiplier of the cone).
    let pressures: Vec<f64> = text
        .lines()
        .filter(|l| l.starts_with("  ") && !l.trim_start().starts_with('x'))
        .map(|l| l.split_whitespace().nth(1).unwrap().parse().unwrap())
        .collect();
    assert!(pressures.len() >= 8, "{text}");
    assert!(
        pressures.iter().all(|p| p.is_finite() && *p >= 0.0),
        "{text}"
    );
}
