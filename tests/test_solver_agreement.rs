//! Reference: SPEC section 3 (every solver solves the same discrete problem (2.1)).
//! Goal: `newton`, `paper` (fixed point + penalty-duality) and `qp` (fixed point + Clarabel)
//! give the same nodal displacements to 1e-7 relative, for both cones.
//! Geometry: the `patch` scene (E = 3e5, so the paper's fixed point needs k L < 1: one
//! elastic step to t = 0.25, then 350 steps of 2e-4 to t = 0.32, through the onset of
//! viscoplastic flow at t = 0.275 (K_h^I's spurious stresses) and 0.316 (exact solution))
//! and the `rates` scene (E = 100, 10 uniform steps of 0.1), both at level 1; and the
//! manufactured viscoplastic `contact-mms-vp` (4 steps of 0.25, both bodies flowing, the
//! constitutive source in every solver) at level 1, where at their default tolerance
//! (1e-10 relative residual and complementarity) they must agree to 1e-10.

mod common;
use contact_rates::contact::Method;
use contact_rates::metrics;
use contact_rates::solve::{self, Settings, SolverKind};

fn agree(scene: &str, times: &[f64]) {
    agree_to(scene, times, Settings::default().tol, 1e-7);
}

/// The three solvers, run to the relative tolerance `tol`, give nodal displacements within
/// `bound` of newton's (relative to its largest).
fn agree_to(scene: &str, times: &[f64], tol: f64, bound: f64) {
    for method in [Method::Mortar, Method::Nts] {
        let case = common::case(scene, 1, method, &[]);
        let p = &case.problem;
        let run = |kind| {
            solve::solve_times(
                p,
                &Settings {
                    kind,
                    tol,
                    ..Settings::default()
                },
                times,
                false,
            )
            .unwrap()
        };
        let newton = run(SolverKind::Newton);
        let last = newton.last();
        let plastic = metrics::plastic_fraction(p, last);
        assert!(
            plastic > 0.0,
            "{scene}: the comparison must include viscoplastic flow"
        );
        for kind in [SolverKind::Paper, SolverKind::Qp] {
            let other = run(kind);
            let d = common::rel_diff(&last.u, &other.last().u);
            println!(
                "{scene} {} {}: max nodal difference to newton {d:.3e} (relative), plastic fraction {plastic:.3}",
                method.name(),
                kind.name()
            );
            assert!(
                d < bound,
                "{scene} {} {}: {d:e}",
                method.name(),
                kind.name()
            );
        }
    }
}

#[test]
fn solvers_agree_on_the_patch_scene() {
    let mut times = vec![0.25];
    for j in 1..=350 {
        times.push(0.25 + 2e-4 * j as f64);
    }
    agree("patch", &times);
}

#[test]
fn solvers_agree_on_the_rates_scene() {
    let times: Vec<f64> = (1..=10).map(|n| 0.1 * n as f64).collect();
    agree("rates", &times);
}

#[test]
fn solvers_agree_on_the_manufactured_viscoplastic_scene() {
    agree_to("contact-mms-vp", &[0.25, 0.5, 0.75, 1.0], 1e-10, 1e-10);
}
