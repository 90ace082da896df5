//! Reference: issue 76 (export and grade with a gap).
//! Goal: this project's mortar solves of `gap` levels 0-2, handed to `grade` as VTU series
//! an outside code would write, give grade's own mortar errors in every quantity grade
//! measures for an outside code, penetration against g0 among them (to 1e-9 relative:
//! the files' Float64 values are the solver's), and the export's problem.toml carries the
//! gap and its rule.
//! Geometry: scenes/gap.toml on the study's meshes (meshes/two_blocks.geo).
//! Data: g0 = x^2 / 20; one step.

mod common;
#[path = "common/graded_series.rs"]
mod graded_series;

use contact_rates::case::Case;
use contact_rates::contact::Method;
use contact_rates::external::export::Source;
use contact_rates::external::grade::{GradeRequest, grade};
use contact_rates::io::solution::FieldNames;
use contact_rates::solve::SolverKind;
use contact_rates::verify::quantity::Quantity;
use contact_rates::verify::solve_case;
use contact_rates::verify::study_file::LoadedStudy;

#[test]
fn own_mortar_solves_across_the_gap_graded_as_an_outside_code_give_grades_own_errors() {
    contact_rates::init();
    let study = LoadedStudy::load("gap").unwrap();
    let params = study.file.family_parameters();
    let dir = tempfile::tempdir().unwrap();
    for level in 0..=2 {
        let case = Case::build(&study.scene, level, Method::Mortar, &params).unwrap();
        let (sol, _) = solve_case(&case, SolverKind::Newton, study.file.steps).unwrap();
        graded_series::write_states(dir.path(), level, &case, &sol.states, |_| ());
    }
    let g = grade(&GradeRequest {
        source: Source::Study("gap".into()),
        solutions: dir.path().to_path_buf(),
        levels: None,
        name: "outside".into(),
        threshold: None,
        names: FieldNames::default(),
        compare: true,
    })
    .unwrap();
    let (outside, _) = graded_series::outside_equals_mortar(&g);
    assert!(
        outside
            .iter()
            .any(|r| r.quantity == Quantity::MaxPenetration)
    );
    assert!(outside.iter().any(|r| r.quantity == Quantity::ContactEdge));
    // The export carries the gap and how to pose it.
    let out = tempfile::tempdir().unwrap();
    let status = common::run(
        &[
            "export",
            "--study",
            "gap",
            "--levels",
            "0-0",
            "--out",
            out.path().to_str().unwrap(),
        ],
        &[],
    );
    assert!(status.status.success(), "{status:?}");
    let problem = std::fs::read_to_string(out.path().join("problem.toml")).unwrap();
    assert!(problem.contains("gap = \"x^2/20.0\""), "{problem}");
    assert!(problem.contains("gap_rule = "));
}
