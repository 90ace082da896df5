//! Reference: issue 77 (export and grade of the press fit).
//! Goal: this project's mortar solves of `press-fit` levels 0-2, handed to `grade` as VTU
//! series an outside code would write, give grade's own mortar errors in every quantity
//! grade measures for an outside code (to 1e-9 relative: the files' Float64 values are the
//! solver's): the curved traces across the radial gap, the exact contact geometry and
//! mesh_in's area check (each body's triangles against the scene's polygon at that level)
//! hold for an outside code's files.
//! Geometry: scenes/press-fit.toml on the quick tier's meshes (meshes/press_fit.geo).
//! Data: E = 100 and 150, nu = 0.3, plane strain, bore pressure 6.6; one step.

mod common;
#[path = "common/graded_series.rs"]
mod graded_series;

use contact_rates::case::Case;
use contact_rates::contact::Method;
use contact_rates::external::export::Source;
use contact_rates::external::grade::{GradeRequest, grade};
use contact_rates::io::solution::FieldNames;
use contact_rates::solve::SolverKind;
use contact_rates::verify::solve_case;
use contact_rates::verify::study_file::LoadedStudy;

#[test]
fn own_mortar_solves_of_the_press_fit_graded_as_an_outside_code_give_grades_own_errors() {
    contact_rates::init();
    let study = LoadedStudy::load("press-fit-quick").unwrap();
    let params = study.file.family_parameters();
    let dir = tempfile::tempdir().unwrap();
    for level in 0..=2 {
        let case = Case::build(&study.scene, level, Method::Mortar, &params).unwrap();
        let (sol, _) = solve_case(&case, SolverKind::Newton, study.file.steps).unwrap();
        graded_series::write_states(dir.path(), level, &case, &sol.states, |_| ());
    }
    let g = grade(&GradeRequest {
        source: Source::Study("press-fit-quick".into()),
        solutions: dir.path().to_path_buf(),
        levels: None,
        name: "outside".into(),
        threshold: None,
        names: FieldNames::default(),
        compare: true,
    })
    .unwrap();
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
