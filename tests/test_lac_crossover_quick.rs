//! Reference: issue 64; Drouet and Hild, Numer. Math. 136 (2017): LAC is local like
//! node-on-segment and has the mortar method's order; Theorem 3.1 (K_h^I: h^(1/2)).
//! Goal: LAC is not a cone in disguise. On the quick tier of the `crossover` study
//! (crossover-quick, levels 0-2, where nts's h^(1/2) consistency error dominates), lac's
//! theorem-norm rate is fitted at 0.85 or more, as mortar's; lac's solution is not
//! mortar's (its distance to mortar is well above the solves' 1e-10 tolerance) and that
//! distance falls at rate 0.9 or more. A lac that is nts in disguise fails the rate, one that
//! is mortar in disguise fails the distance.
//! Geometry: two unit blocks stacked (two_blocks.geo), non-matching on y = 1.
//! Data: E = 100, nu = 0.3, top load -10 t (0.3 + 0.01 cos(pi x)), one step.

mod common;

use contact_rates::contact::Method;
use contact_rates::scene::Scene;
use contact_rates::solve::SolverKind;
use contact_rates::verify::distance::cone_distance;
use contact_rates::verify::field::P1History;
use contact_rates::verify::judge::levels_of;
use contact_rates::verify::quantity::Quantity;
use contact_rates::verify::rates::{Verdict, assess};
use contact_rates::verify::solve_case;
use contact_rates::verify::truth::Truth;

#[test]
fn lac_on_crossover_quick_is_as_accurate_as_mortar_and_is_not_mortar() {
    let scene = Scene::load("crossover-quick").unwrap();
    let truth = Truth::Exact(scene.exact.as_deref().unwrap(), 4);
    let (mut errors, mut distances) = (Vec::new(), Vec::new());
    for level in 0..=2 {
        let [mortar, lac] = [Method::Mortar, Method::Lac].map(|m| {
            let case = common::case("crossover-quick", level, m, &[]);
            let (sol, _) = solve_case(&case, SolverKind::Newton, 1).unwrap();
            (case, sol)
        });
        let (measured, sizes) = truth.measure_solved(&lac.0, &lac.1);
        let e = measured[&Quantity::Theorem];
        let d = cone_distance(
            &P1History::of_solution(&mortar.0, &mortar.1),
            &P1History::of_solution(&lac.0, &lac.1),
            &sizes,
        )[&Quantity::ConeDistance];
        let (h, dofs) = (lac.0.h, lac.0.problem.model.n_free as f64);
        errors.push((level, h, dofs, e));
        distances.push((level, h, dofs, d));
    }
    let judge =
        |rows: &[(usize, f64, f64, f64)]| assess(&levels_of(rows.iter().copied()), 0.0).unwrap();
    let (a, b) = (judge(&errors), judge(&distances));
    let (rate, d_rate) = (a.fit.unwrap().rate, b.fit.unwrap().rate);
    println!(
        "lac theorem norm {:?}: rate {rate:.3} ({}); distance to mortar {:?}: rate {d_rate:.3} ({})",
        errors.iter().map(|r| r.3).collect::<Vec<_>>(),
        a.verdict.name(),
        distances.iter().map(|r| r.3).collect::<Vec<_>>(),
        b.verdict.name()
    );
    assert_eq!(a.verdict, Verdict::Fitted, "lac's theorem-norm verdict");
    assert!(rate >= 0.85, "lac's theorem-norm rate {rate}");
    // The solves stop at 1e-10 relative: a distance 1e4 times that is a different solution.
    assert!(
        distances.iter().all(|r| r.3 > 1e-6),
        "lac is mortar: {distances:?}"
    );
    assert!(d_rate >= 0.9, "lac's distance to mortar falls at {d_rate}");
}

/// Where the two cones coincide (nested traces: the slave one level finer, every master
/// node on Gamma_C a slave node), lac does not: its rows average over macro-elements, so its
/// distance to mortar stays well above the solves' tolerance.
#[test]
fn on_matching_traces_lac_is_not_mortar() {
    use contact_rates::case::Case;
    let scene = Scene::load("stacked-exact").unwrap();
    let truth = Truth::Exact(scene.exact.as_deref().unwrap(), 4);
    common::case("stacked-exact", 0, Method::Mortar, &[]);
    let params = vec![("matching".to_string(), 1.0)];
    for master in 0..=1 {
        let [mortar, nts, lac] = Method::ALL.map(|m| {
            let case = Case::build_sizes(&scene, [master + 1, master], m, &params).unwrap();
            let (sol, _) = solve_case(&case, SolverKind::Newton, 1).unwrap();
            (case, sol)
        });
        let d = |x: &(Case, contact_rates::solve::Solution)| {
            let (_, sizes) = truth.measure_solved(&x.0, &x.1);
            cone_distance(
                &P1History::of_solution(&mortar.0, &mortar.1),
                &P1History::of_solution(&x.0, &x.1),
                &sizes,
            )[&Quantity::ConeDistance]
        };
        let (dn, dl) = (d(&nts), d(&lac));
        println!(
            "slave level {}, master level {master}: D(nts, mortar) = {dn:.2e}, D(lac, mortar) = {dl:.2e}",
            master + 1
        );
        assert!(dn <= 1e-9, "{dn}");
        assert!(dl > 1e-6, "{dl}");
    }
}
