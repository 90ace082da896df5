//! Reference: issue 48 (export the manufactured contact problems for other codes).
//! Goal: `export --study rates-exact` writes meshes that this project's reader and gmsh
//! itself read back to the model's nodes, triangles and physical curves (MSH 4.1 and 2.2),
//! nodal loads equal to the solver's at every step, a problem.toml whose numbers are the
//! scene's (plane-stress lambda* and mu), and a problem.py whose derived fields agree with
//! sympy's own derivatives of the given ones; a scene without an exact solution is refused.
//! Geometry: contact-mms on the rates-exact family, levels 0-1.

mod common;

use contact_rates::case::Case;
use contact_rates::contact::Method;
use contact_rates::external::export::{LoadRow, Source, export};
use contact_rates::mesh::msh::read_msh;
use contact_rates::verify::study_file::LoadedStudy;
use std::path::Path;
use std::process::Command;

#[test]
fn the_export_reads_back_as_the_solvers_problem() {
    common::case("contact-mms", 0, Method::Mortar, &[]);
    let out = tempfile::tempdir().unwrap();
    let dir = out.path().join("exported");
    let done = export(&Source::Study("rates-exact".into()), &[0, 1], &dir).unwrap();
    assert_eq!(done.levels.len(), 2);
    let study = LoadedStudy::load("rates-exact").unwrap();
    let params = study.file.family_parameters();
    for level in [0, 1] {
        let case = Case::build(&study.scene, level, Method::Mortar, &params).unwrap();
        let m = &case.problem.model;
        // This project's reader and gmsh (which rewrites the 2.2 file as 4.1) read the same
        // mesh: every node and triangle, every physical curve of the scene.
        let converted = out.path().join(format!("gmsh_{level}.msh"));
        let status = Command::new("gmsh")
            .arg(dir.join(format!("mesh_{level}.msh22.msh")))
            .args(["-save", "-format", "msh41", "-o"])
            .arg(&converted)
            .output()
            .expect("gmsh runs");
        assert!(
            status.status.success(),
            "{}",
            String::from_utf8_lossy(&status.stderr)
        );
        // The 4.1 file keeps the model's numbering (loads_L.csv refers to it).
        let own = read_msh(&dir.join(format!("mesh_{level}.msh"))).unwrap();
        for (g, p) in own.nodes.iter().enumerate() {
            assert_eq!(*p, m.position(g), "mesh_{level}.msh node {}", g + 1);
        }
        for file in [dir.join(format!("mesh_{level}.msh")), converted] {
            let raw = read_msh(&file).unwrap();
            assert_eq!(raw.nodes.len(), m.n_nodes, "{}", file.display());
            assert_eq!(raw.triangles.len(), m.elements.len(), "{}", file.display());
            // gmsh renumbers the nodes it rewrites: the same points, in some order.
            let sorted = |mut v: Vec<[f64; 2]>| {
                v.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
                v
            };
            let model_nodes: Vec<[f64; 2]> = (0..m.n_nodes).map(|g| m.position(g)).collect();
            assert_eq!(
                sorted(raw.nodes.clone()),
                sorted(model_nodes),
                "{}",
                file.display()
            );
            let curves = raw.names_of_dim(1);
            for name in [
                "bottom",
                "top",
                "contact_upper",
                "contact_lower",
                "left_upper",
                "right_lower",
            ] {
                assert!(
                    curves.iter().any(|c| c == name),
                    "{}: {curves:?}",
                    file.display()
                );
            }
            let surfaces = raw.names_of_dim(2);
            assert_eq!(surfaces, vec!["lower".to_string(), "upper".to_string()]);
        }
        // The loads: what the solver assembles, at every step, to the bit.
        let rows: Vec<LoadRow> = csv::Reader::from_path(dir.join(format!("loads_{level}.csv")))
            .unwrap()
            .deserialize()
            .map(|r| r.unwrap())
            .collect();
        assert_eq!(rows.len(), study.file.steps * m.n_nodes);
        for step in 1..=study.file.steps {
            let t = step as f64 / study.file.steps as f64;
            let f = m.load(t).unwrap();
            for r in rows.iter().filter(|r| r.step == step) {
                assert_eq!(r.t, t);
                assert_eq!([r.fx, r.fy], [f[2 * (r.node - 1)], f[2 * (r.node - 1) + 1]]);
            }
        }
    }
    // problem.toml: the scene's numbers.
    let text = std::fs::read_to_string(dir.join("problem.toml")).unwrap();
    let problem: toml::Value = toml::from_str(&text).unwrap();
    let body = &problem["bodies"][0];
    let (e, nu) = (
        body["young"].as_float().unwrap(),
        body["poisson"].as_float().unwrap(),
    );
    assert_eq!(
        body["lambda_star"].as_float().unwrap(),
        e * nu / (1.0 - nu * nu)
    );
    assert!((body["mu"].as_float().unwrap() - e / (2.0 * (1.0 + nu))).abs() <= 1e-14 * e);
    assert_eq!(problem["time"]["steps"].as_integer(), Some(4));
    let normal = problem["contact"]["pieces"][0]["slave_normal"]
        .as_array()
        .unwrap();
    assert_eq!(normal[1].as_float(), Some(-1.0));
    check_problem_py(&dir);
}

/// `python3 problem.py` compares every derived field with sympy's derivatives. Needs sympy:
/// the CI installs it and sets CONTACT_RATES_REQUIRE_SYMPY; elsewhere its absence is said.
fn check_problem_py(dir: &Path) {
    let has_sympy = Command::new("python3")
        .args(["-c", "import sympy"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !has_sympy {
        assert!(
            std::env::var_os("CONTACT_RATES_REQUIRE_SYMPY").is_none(),
            "python3 with sympy is required (pip install sympy)"
        );
        eprintln!(
            "note: python3 with sympy not found: problem.py's check not run (pip install sympy)"
        );
        return;
    }
    let run = Command::new("python3")
        .arg("problem.py")
        .current_dir(dir)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&run.stderr)
    );
    println!("{stdout}");
    let count: usize = stdout
        .split_whitespace()
        .nth(1)
        .and_then(|w| w.parse().ok())
        .expect("problem.py prints its count");
    // 2 bodies x (3 stress + 2 body force) x 12 points x 4 steps, 2 x 22 points of
    // Gamma_C x 4 steps, 2 tractions x 2 components x 12 x 4.
    assert!(count >= 500, "{count} comparisons");
}

#[test]
fn a_scene_without_an_exact_solution_is_refused_and_nothing_written() {
    let out = tempfile::tempdir().unwrap();
    let dir = out.path().join("exported");
    let e = export(&Source::Scene("rates".into()), &[0], &dir)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("no exact solution") && e.contains("contact-mms"),
        "{e}"
    );
    assert!(!dir.exists());
}
