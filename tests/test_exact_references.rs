//! Reference: SPEC section 5 (exact references); Theorem 3.1 (rates h^(3/4) for K_h^pi and
//! h^(1/2) for K_h^I in the theorem norm).
//! Goal: a study measures against a scene's exact solution with no reference solve; the
//! quick tier of rates-exact meets the theorem's thresholds; doubling the quadrature
//! changes no printed digit of its errors; a quantity the exact solution does not cover is
//! refused when the study is read; the stacked-exact closed form equals the scene's
//! expressions and agrees with a fine matching-mesh reference to that reference's own
//! estimated error.
//! Geometry and data: contact-mms (manufactured, partial contact), stacked-exact (two unit
//! blocks, E = 100, nu = 0.3, load -10 t (0.3 + cos(pi x))), patch (exact stress only).

mod common;

use contact_rates::analytical::stacked::StackedBlocks;
use contact_rates::contact::Method;
use contact_rates::scene::Scene;
use contact_rates::solve::SolverKind;
use contact_rates::studies::convergence;
use contact_rates::verify::exact_error::ExactComparison;
use contact_rates::verify::field::P1History;
use contact_rates::verify::quantity::Quantity;
use contact_rates::verify::{solve_case, study_file, theorem_distance};

fn quick_study(dir: &std::path::Path, edit: impl Fn(String) -> String) -> String {
    let text =
        std::fs::read_to_string(study_file::builtin_dir().join("rates-exact-quick.toml")).unwrap();
    let f = dir.join("study.toml");
    std::fs::write(&f, edit(text)).unwrap();
    f.display().to_string()
}

#[test]
fn quick_exact_study_meets_the_thresholds_and_its_quadrature_is_converged() {
    contact_rates::init();
    let res = convergence::run("rates-exact-quick").unwrap();
    assert!(res.reference.is_none(), "no reference solve");
    for r in res.rates.iter().filter(|r| r.quantity == Quantity::Theorem) {
        common::assert_rate_passes(r, &[0, 1, 2]);
    }
    // The same study with twice the Gauss points per direction (64 instead of 16 points per
    // triangle): every error equal to the digits the report prints.
    let dir = tempfile::tempdir().unwrap();
    let doubled = quick_study(dir.path(), |t| {
        t.replace("exact = true", "exact = true\nquadrature = 8")
    });
    let res8 = convergence::run(&doubled).unwrap();
    assert_eq!(res.errors.len(), res8.errors.len());
    for (a, b) in res.errors.iter().zip(&res8.errors) {
        assert_eq!(
            (&a.method, a.level, a.quantity),
            (&b.method, b.level, b.quantity)
        );
        assert_eq!(
            format!("{:.3e}", a.error),
            format!("{:.3e}", b.error),
            "{} level {} {}",
            &a.method,
            a.level,
            a.quantity
        );
        // A tenth of the last printed digit (4 significant digits), so no rounding boundary
        // hides a change.
        assert!(
            (a.error - b.error).abs() <= 5e-5 * a.error,
            "{} {}: {} vs {}",
            &a.method,
            a.quantity,
            a.error,
            b.error
        );
    }
}

#[test]
fn a_quantity_the_exact_solution_does_not_cover_is_refused_when_the_study_is_read() {
    let dir = tempfile::tempdir().unwrap();
    // The patch scene's exact solution gives stress and pressure only.
    let f = quick_study(dir.path(), |t| {
        t.replace("scene = \"contact-mms\"", "scene = \"patch\"")
    });
    let e = convergence::run(&f).unwrap_err().to_string();
    assert!(
        e.contains("study.toml")
            && e.contains("quantity 'theorem'")
            && e.contains("exact.displacement")
            && e.contains("patch"),
        "{e}"
    );
    // And a scene with no exact solution at all.
    let f = quick_study(dir.path(), |t| {
        t.replace("scene = \"contact-mms\"", "scene = \"rates\"")
    });
    let e = convergence::run(&f).unwrap_err().to_string();
    assert!(
        e.contains("reference.exact") && e.contains("no exact solution"),
        "{e}"
    );
}

#[test]
fn stacked_exact_scene_is_the_closed_form() {
    let closed = StackedBlocks::scene();
    let scene = Scene::load("stacked-exact").unwrap();
    let ex = scene.exact.as_deref().unwrap();
    let worst = common::closed_form_difference(&closed, &scene);
    println!("largest difference scene / closed form: {worst:.2e} of the field's size");
    assert!(worst < 1e-12, "{worst}");
    // Its equilibrium: the body force of the closed form's stress vanishes.
    let zero = contact_rates::analytical::body_force(&ex.stress.as_ref().unwrap()[0]);
    assert!(zero[1].eval(0.3, 1.6, 1.0).abs() < 1e-10 * 10.0);
}

#[test]
fn stacked_exact_agrees_with_a_fine_matching_reference_to_its_estimated_error() {
    // The study's reference machinery on matching meshes, levels 2, 3, 4 (R = 4).
    let solved: Vec<_> = [2, 3, 4]
        .iter()
        .map(|&l| {
            let case = common::case("stacked-exact", l, Method::Mortar, &[("matching", 1.0)]);
            let (sol, _) = solve_case(&case, SolverKind::Newton, 4).unwrap();
            (case, sol)
        })
        .collect();
    let (rc, rs) = &solved[2];
    let d1 = theorem_distance(&solved[1].0, &solved[1].1, rc, rs);
    let d2 = theorem_distance(&solved[0].0, &solved[0].1, rc, rs);
    let (estimated, p) = convergence::estimated_reference_error(d1, d2);
    // The reference's true error, against the closed form.
    let scene = Scene::load("stacked-exact").unwrap();
    let cmp = ExactComparison::new(scene.exact.as_deref().unwrap(), 6);
    let (mut diff, mut norm) = (0.0f64, 0.0f64);
    let history = P1History::of_solution(rc, rs);
    for s in &history.steps {
        let d = cmp.difference(history.model, history.interface, s);
        diff = diff.max(d.difference.theorem());
        norm = norm.max(d.exact.theorem());
    }
    let actual = diff / norm;
    println!(
        "reference level 4 ({} dofs): error against the closed form {actual:.4e}, estimated {estimated:.4e} (p = {p:.2})",
        rc.problem.model.n_free
    );
    assert!(
        actual <= 1.5 * estimated && actual >= estimated / 1.5,
        "actual {actual}, estimated {estimated}"
    );
}

#[test]
fn contact_mms_edge_is_no_mesh_node() {
    // The contact edge a = 0.5871 of contact-mms at every level of rates-exact: its distance
    // to the nearest node of either body on Gamma_C, relative to the local trace element.
    let a = 0.5871;
    for level in 0..=5 {
        let case = common::case(
            "contact-mms",
            level,
            Method::Mortar,
            &[("h_upper", 0.3), ("h_lower", 0.3 / 1.4142)],
        );
        let piece = &case.problem.interface.pieces[0];
        let nearest = |s: &[f64]| -> (f64, f64) {
            let k = s.partition_point(|&v| v < a).clamp(1, s.len() - 1);
            let d = (s[k - 1] - a).abs().min((s[k] - a).abs());
            (d, s[k] - s[k - 1])
        };
        let (ds, hs) = nearest(&piece.slave_s);
        let (dm, hm) = nearest(&piece.master_s);
        println!(
            "level {level}: distance of a to the nearest node: body 1 {ds:.3e} ({:.2} h), body 2 {dm:.3e} ({:.2} h)",
            ds / hs,
            dm / hm
        );
        assert!(ds > 0.01 * hs && dm > 0.01 * hm);
    }
}
