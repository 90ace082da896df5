// Reference: issue 63 ("each new family can be exported and graded"); issue 48 (grade).
// Goal: the transition studies' families go through export and grade like the others:
//   `export` writes every level's meshes and loads for regularity-unaligned (c inside a
//   trace segment), regularity-graded (each level meshed anew) and crossover-transition;
//   this project's own mortar solves of levels 0-2, handed to `grade` as the VTU series an
//   outside code would write, are graded to the same errors as grade's own mortar
//   (distance between them at round-off, every error within 1e-10 relative).
// Geometry: the stacked unit blocks; c = (8/15, 1) off the nodes, or (0.5871, 1) a node.
// Data: one beta of each family, levels 0-2 (0-1 for the export).

mod common;
#[path = "common/graded_series.rs"]
mod graded_series;

use contact_rates::contact::Method;

const STUDIES: [&str; 3] = [
    "regularity-unaligned/beta-1.50",
    "regularity-graded/beta-0.75",
    "crossover-transition",
];

#[test]
fn the_transition_families_export_every_level() {
    for study in STUDIES {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("problem");
        let run = common::run(
            &[
                "export",
                "--study",
                study,
                "--levels",
                "0-1",
                "--out",
                out.to_str().unwrap(),
            ],
            &[],
        );
        assert!(
            run.status.success(),
            "{study}: {}",
            String::from_utf8_lossy(&run.stderr)
        );
        for f in ["problem.toml", "problem.py", "README.md"] {
            assert!(out.join(f).exists(), "{study}: {f}");
        }
        let files: Vec<String> = std::fs::read_dir(&out)
            .unwrap()
            .chain(std::fs::read_dir(out.join("meshes")).into_iter().flatten())
            .flatten()
            .map(|e| e.file_name().to_string_lossy().to_string())
            .collect();
        println!("{study}: {files:?}");
        for level in [0, 1] {
            assert!(
                files.iter().any(|f| f.contains(&format!("loads_{level}"))),
                "{study}: the loads of level {level} in {files:?}"
            );
        }
    }
}

#[test]
fn this_projects_mortar_is_graded_as_grades_own() {
    for study in STUDIES {
        common::case("contact-mms", 0, Method::Mortar, &[]);
        let g = graded_series::grade_own_solves(study, Method::Mortar, 2);
        let mut worst = 0.0f64;
        let mut distance = 0.0f64;
        let mut compared = 0;
        for r in g.errors.iter().filter(|r| r.method.name() == "outside") {
            if r.quantity.is_distance() {
                distance = distance.max(r.error);
                continue;
            }
            let own = g
                .errors
                .iter()
                .find(|o| {
                    o.method.name() == "mortar" && o.level == r.level && o.quantity == r.quantity
                })
                .expect("grade's own mortar has the row");
            worst = worst.max((r.error - own.error).abs() / own.error.abs().max(1e-300));
            compared += 1;
        }
        println!(
            "{study}: {compared} errors, largest relative difference to grade's mortar {worst:.1e}, distance {distance:.1e}"
        );
        assert!(compared >= 9, "{study}: {compared}");
        assert!(worst <= 1e-10, "{study}: {worst}");
        assert!(distance <= 1e-10, "{study}: {distance}");
    }
}
