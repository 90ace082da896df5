//! Reference: issue 77 (export and grade of the press fit).
//! Goal: this project's mortar solves of `press-fit` levels 0-2, handed to `grade` as VTU
//! series an outside code would write, give grade's own mortar errors in every quantity
//! grade measures for an outside code (to 1e-9 relative: the files' Float64 values are the
//! solver's): the curved traces across the radial gap, the exact contact geometry and
//! mesh_in's area check (each body's triangles against the scene's polygon at that level)
//! hold for an outside code's files.
//! Geometry: scenes/press-fit.toml on the quick tier's meshes (meshes/press_fit.geo).
//! Data: E = 100 and 150, nu = 0.3, plane strain, bore pressure 6.6; one step.

#[path = "common/graded_series.rs"]
mod graded_series;

use contact_rates::contact::Method;

#[test]
fn own_mortar_solves_of_the_press_fit_graded_as_an_outside_code_give_grades_own_errors() {
    contact_rates::init();
    let g = graded_series::grade_own_solves("press-fit-quick", Method::Mortar, 2);
    let of = |m: &str| {
        g.errors
            .iter()
            .filter(|r| r.method.name() == m && !r.quantity.is_distance())
            .collect::<Vec<_>>()
    };
    let (outside, mortar) = (of("outside"), of("mortar"));
    // Every level passes grade's checks, so all three give rows.
    let levels: std::collections::BTreeSet<usize> = outside.iter().map(|r| r.level).collect();
    assert_eq!(levels.into_iter().collect::<Vec<_>>(), vec![0, 1, 2]);
    let mut worst = 0.0f64;
    for r in &outside {
        let m = mortar
            .iter()
            .find(|m| m.level == r.level && m.quantity == r.quantity)
            .expect("grade's mortar has the row");
        let d = (r.error - m.error).abs() / m.error.abs();
        worst = worst.max(d);
        assert!(d <= 1e-9, "{r:?} vs {m:?}");
    }
    println!(
        "{} errors, largest relative difference to grade's mortar {worst:.2e}",
        outside.len()
    );
}
