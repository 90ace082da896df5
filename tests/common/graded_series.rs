//! Solutions of this project's solver written as an outside code writes them, for the
//! tests of `grade` (tests/test_grade_outside_code.rs, tests/test_grade_checks.rs): the mesh
//! of both bodies, the displacement, the P0 stress and the nodal pressure at the slave nodes
//! (0 elsewhere), one .vtu per step and a .pvd per level.
#![allow(dead_code)]

#[path = "solution_files.rs"]
mod solution_files;

use contact_rates::case::Case;
use contact_rates::solve::State;
pub use solution_files::{Encoding, Options, Solution};
use std::path::Path;

/// A solver state as an outside code writes it, with the displacement `u`.
pub fn outside(case: &Case, state: &State, u: &[f64]) -> Solution {
    let p = &case.problem;
    let m = &p.model;
    // Per slave node: its row's pressure, or (lac) its macro-element's, a node between two
    // macro-elements the mean of theirs, as `solve` writes them.
    let mut pressure = vec![0.0; m.n_nodes];
    for c in contact_rates::metrics::contact_nodes(p, state) {
        pressure[c.node] = c.pressure;
    }
    Solution {
        points: (0..m.n_nodes).map(|g| m.position(g)).collect(),
        triangles: m.elements.iter().map(|e| e.nodes).collect(),
        body: m.elements.iter().map(|e| e.body as u8 + 1).collect(),
        displacement: (0..m.n_nodes).map(|g| [u[2 * g], u[2 * g + 1]]).collect(),
        stress: state.sigma.iter().map(|s| [s[0], s[1], s[2]]).collect(),
        pressure,
    }
}

/// `s` as a compressed appended-raw VTU at `path`.
pub fn write_vtu(path: &Path, s: &Solution) {
    let mut o = Options::new(Encoding::AppendedRaw);
    o.compressed = true;
    o.block_bytes = 1 << 15;
    std::fs::write(path, s.vtu("Float64").write(&o)).unwrap();
}

/// The states t_1..t_N (`states[0]` is t_0, not written) as `dir/level_L.pvd` with one
/// .vtu per step, each solution changed by `edit` before it is written.
pub fn write_states(
    dir: &Path,
    level: usize,
    case: &Case,
    states: &[State],
    edit: impl Fn(&mut Solution),
) {
    let mut pvd = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n",
    );
    for (n, s) in states.iter().enumerate().skip(1) {
        let name = format!("level_{level}_step_{n}.vtu");
        let mut written = outside(case, s, &s.u);
        edit(&mut written);
        write_vtu(&dir.join(&name), &written);
        pvd.push_str(&format!(
            "<DataSet timestep=\"{:e}\" file=\"{name}\"/>\n",
            s.time
        ));
    }
    pvd.push_str("</Collection>\n</VTKFile>\n");
    std::fs::write(dir.join(format!("level_{level}.pvd")), pvd).unwrap();
}

/// This project's own `method` solves of `study`'s levels 0..=`finest`, written as an outside
/// code writes them and graded by `grade` as the code "outside" (grade solves its own
/// mortar, nts and lac beside).
pub fn grade_own_solves(
    study: &str,
    method: contact_rates::contact::Method,
    finest: usize,
) -> contact_rates::external::grade::Graded {
    use contact_rates::external::grade::{GradeRequest, grade};
    let loaded = contact_rates::verify::study_file::LoadedStudy::load(study).unwrap();
    let params = loaded.file.family_parameters();
    let dir = tempfile::tempdir().unwrap();
    for level in 0..=finest {
        let case = Case::build(&loaded.scene, level, method, &params).unwrap();
        let solver = contact_rates::solve::SolverKind::Newton;
        let (sol, _) = contact_rates::verify::solve_case(&case, solver, loaded.file.steps).unwrap();
        write_states(dir.path(), level, &case, &sol.states, |_| ());
    }
    grade(&GradeRequest {
        source: contact_rates::external::export::Source::Study(study.into()),
        solutions: dir.path().to_path_buf(),
        levels: None,
        name: "outside".into(),
        threshold: None,
        names: contact_rates::io::solution::FieldNames::default(),
        compare: true,
    })
    .unwrap()
}

/// The graded code "outside"'s rows of `g` (no distances), each asserted equal to grade's own
/// mortar row of its level and quantity to 1e-9 relative; with the largest difference.
pub fn outside_equals_mortar(
    g: &contact_rates::external::grade::Graded,
) -> (Vec<&contact_rates::verify::table::ErrorRecord>, f64) {
    let of = |m: &str| {
        g.errors
            .iter()
            .filter(|r| r.method.name() == m && !r.quantity.is_distance())
            .collect::<Vec<_>>()
    };
    let (outside, mortar) = (of("outside"), of("mortar"));
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
    (outside, worst)
}
