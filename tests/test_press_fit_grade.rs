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
    let (outside, _) = graded_series::outside_equals_mortar(&g);
    // Every level passes grade's checks, so all three give rows.
    let levels: std::collections::BTreeSet<usize> = outside.iter().map(|r| r.level).collect();
    assert_eq!(levels.into_iter().collect::<Vec<_>>(), vec![0, 1, 2]);
}
