//! Reference: issue 75 (rows that carry a gap), after the patch test of Fernandez-Garcia,
//! Hild and Viano, section 5.2 (Test 2), and Popp, Gee and Wall (2009), section 5.1.
//! Goal: with the gap on each row's right-hand side, K_h^pi and LAC reproduce the
//! homogeneous solution exactly across an initial gap on non-matching meshes: the stress
//! and the pressure at solver tolerance, the closed gap equal to g0 at every body-1 node to
//! 1e-10 (so the test fails if the right-hand side is dropped: the gap would then stay
//! open by g0); K_h^I does not (its forces on body 2 are not the consistent ones). Each of
//! the three solvers (newton, the paper's fixed point, the QP) holds the right-hand side.
//! Geometry: two unit blocks, upper [0,1]x[1+g0,2+g0] (body 1), lower [0,1]x[0,1], g0 =
//! 0.01; symmetry on the right sides and the bottom; meshes non-matching (the upper
//! contact line graded).
//! Data: E = 3e5, nu = 0.3 (elastic), g = (0, -10) on top, one step. Exact: sigma =
//! diag(0, -10) in both bodies, pressure 10, body 1 moved down by g0 more than body 2.

mod common;
use contact_rates::case::Case;
use contact_rates::contact::{self, Method};
use contact_rates::scene::Scene;
use contact_rates::solve::{self, Settings, SolverKind};
use nalgebra::Vector3;

const G0: f64 = 0.01;

fn case(method: Method, level: usize) -> Case {
    contact_rates::init();
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/gap-patch.toml");
    let scene = Scene::load(path).expect("the gap patch scene loads");
    Case::build(&scene, level, method, &[]).expect("the case builds")
}

/// (largest stress error / 10, largest pressure error / 10, largest |closed gap - g0| /
/// g0 over the body-1 nodes) of one solve.
fn errors(case: &Case, solver: SolverKind) -> (f64, f64, f64) {
    let p = &case.problem;
    let settings = Settings {
        kind: solver,
        ..Settings::default()
    };
    let sol = solve::solve(p, &settings, 1, false).expect("the solve converges");
    let last = sol.last();
    let exact = Vector3::new(0.0, -10.0, 0.0);
    let stress = last
        .sigma
        .iter()
        .map(|s| (s - exact).amax())
        .fold(0.0, f64::max)
        / 10.0;
    let pressure = p
        .rows
        .iter()
        .zip(&last.lambda)
        .map(|(r, l)| (r.pressure(*l) - 10.0).abs())
        .fold(0.0, f64::max)
        / 10.0;
    // The jump at the body-1 nodes: u^1.nu + u^2.(-nu) at y_j, the distance the gap closed.
    let slave_nodes: usize = p.interface.pieces.iter().map(|x| x.slave_s.len()).sum();
    let jumps = contact::normal_jumps(&p.interface, &last.u);
    assert_eq!(p.interface.pieces.len(), 1);
    let gap = jumps[..slave_nodes]
        .iter()
        .map(|j| (j.2 - G0).abs())
        .fold(0.0, f64::max)
        / G0;
    (stress, pressure, gap)
}

#[test]
fn mortar_and_lac_close_the_gap_exactly_and_nts_does_not() {
    for level in 0..2 {
        for method in Method::ALL {
            let case = case(method, level);
            let p = &case.problem;
            assert!(p.interface.min_relative_separation() > 1e-3, "non-matching");
            // Every row's gap is g0: the traces are parallel at distance g0.
            for r in &p.rows {
                assert!((r.gap - G0).abs() < 1e-14, "{method} row gap {}", r.gap);
            }
            let (stress, pressure, gap) = errors(&case, SolverKind::Newton);
            println!(
                "level {level} {method}: stress {stress:.2e}, pressure {pressure:.2e}, closed gap - g0 {gap:.2e} (relative)"
            );
            if method == Method::Nts {
                assert!(
                    stress > 1e-3,
                    "nts must show spurious stresses, got {stress:e}"
                );
            } else {
                assert!(
                    stress < 1e-9,
                    "{method} level {level}: stress error {stress:e}"
                );
                assert!(
                    pressure < 1e-9,
                    "{method} level {level}: pressure error {pressure:e}"
                );
                assert!(
                    gap < 1e-10,
                    "{method} level {level}: closed gap error {gap:e}"
                );
            }
        }
    }
}

#[test]
fn every_solver_holds_the_gap() {
    for solver in [SolverKind::Paper, SolverKind::Qp] {
        for method in [Method::Mortar, Method::Lac] {
            let (stress, pressure, gap) = errors(&case(method, 0), solver);
            println!(
                "{solver:?} {method}: stress {stress:.2e}, pressure {pressure:.2e}, gap {gap:.2e}"
            );
            assert!(
                stress < 1e-7 && pressure < 1e-7 && gap < 1e-8,
                "{solver:?} {method}"
            );
        }
    }
}
