//! Reference: issue 73 (grade tells an unconverged solve from a code's own load
//! integration).
//! Goal:
//! - a converged solve whose loads are integrated with a rule one degree too low (the
//!   centroid rule: degree 1, where a linear load times a P1 function needs 2), not split at
//!   the loads' kinks, is graded on every level: its equilibrium residual against the
//!   exported integrals is one of the common load rules' (so at most lambda_q, to
//!   round-off), printed with the change of the key error it makes (the centroid rule's
//!   errors on this load, which jumps at x = a inside triangles, do not settle to a rate);
//! - a solve stopped after one Newton iteration per step (viscoplastic, so the interior is
//!   nonlinear) is refused as unconverged wherever its residual exceeds 1/20 of the error:
//!   its residual does not scale with the load from step to step, as a load rule's does.
//!
//! Geometry: contact-mms (two elastic blocks) and contact-mms-vp (the same blocks,
//! viscoplastic, with the exact solution's extra stress diag(q, 0)), levels 0-3.
//! Data: the scenes'; 4 steps.

mod common;
#[path = "common/graded_series.rs"]
mod graded_series;

use contact_rates::contact::Method;
use contact_rates::external::checks::LevelCheck;
use contact_rates::external::export::Source;
use contact_rates::external::grade::{GradeRequest, Graded, grade};
use contact_rates::fe::LoadRule;
use contact_rates::io::solution::FieldNames;
use contact_rates::solve::{Settings, SolverKind, solve};
use contact_rates::verify::quantity::Quantity;
use graded_series::write_states;

const STEPS: usize = 4;
const LEVELS: usize = 4;

/// `scene`'s levels 0-3 solved by mortar's Newton with `settings`, the loads by `rule`
/// where given, written as an outside code writes them and graded.
fn graded(scene: &str, rule: Option<&LoadRule>, settings: &Settings) -> Graded {
    let dir = tempfile::tempdir().unwrap();
    for level in 0..LEVELS {
        let mut case = common::case(scene, level, Method::Mortar, &[]);
        case.problem.model.load_rule = rule.cloned();
        let sol = solve(&case.problem, settings, STEPS, true).unwrap();
        write_states(dir.path(), level, &case, &sol.states, |_| ());
    }
    grade(&GradeRequest {
        source: Source::Scene(scene.into()),
        solutions: dir.path().to_path_buf(),
        levels: None,
        name: "outside".into(),
        threshold: None,
        names: FieldNames::default(),
        compare: false,
    })
    .unwrap()
}

fn print_checks(what: &str, g: &Graded) {
    for c in &g.checks {
        println!(
            "{what}: level {} error {:.4e} delta {:.3e} delta_w {:.3e} lambda_q {:.3e} ({}) shift {:?} verdict {}",
            c.level,
            c.error,
            c.residual,
            c.residual_off_load.unwrap(),
            c.load_rule_residual.unwrap(),
            c.residual_cause.as_deref().unwrap(),
            c.error_shift,
            c.verdict
        );
    }
    for f in &g.flagged {
        println!("{what}: {f}");
    }
}

#[test]
fn loads_integrated_one_degree_too_low_are_graded_with_their_bound() {
    let centroid = LoadRule::common().remove(0);
    assert!(centroid.name.starts_with("centroid"));
    let g = graded("contact-mms", Some(&centroid), &Settings::default());
    print_checks("centroid loads", &g);
    assert!(g.flagged.is_empty(), "{:?}", g.flagged);
    for c in &g.checks {
        // The file's residual is the centroid rule's load difference, one of the common
        // rules lambda_q is the largest of.
        let lambda_q = c.load_rule_residual.unwrap();
        assert!(c.residual <= lambda_q * (1.0 + 1e-9), "{c:?}");
        // A load rule's residual scales with the load, t^1 here, to round-off.
        assert!(c.residual_off_load.unwrap() <= 1e-12, "{c:?}");
        assert!(c.residual > LevelCheck::residual_limit(c.error), "{c:?}");
        assert_eq!(c.residual_cause.as_deref(), Some("load rule"), "{c:?}");
        assert!(c.error_shift.is_some(), "{c:?}");
    }
    // Every level gives its errors (none is set apart), and the report says what the
    // residual does to the key rate.
    for level in 0..LEVELS {
        assert!(g.errors.iter().any(|r| r.method.name() == "outside"
            && r.level == level
            && r.quantity == Quantity::Theorem));
    }
    let note = g
        .notes
        .iter()
        .find(|n| n.contains("without the residual"))
        .unwrap();
    println!("{note}");
}

#[test]
fn a_solve_stopped_after_one_newton_iteration_is_refused() {
    let once = Settings {
        kind: SolverKind::Newton,
        stop_after: Some(1),
        ..Settings::default()
    };
    let g = graded("contact-mms-vp", None, &once);
    print_checks("one Newton iteration", &g);
    let converged = graded("contact-mms-vp", None, &Settings::default());
    print_checks("converged", &converged);
    assert!(converged.flagged.is_empty(), "{:?}", converged.flagged);
    // One Newton iteration from the predictor leaves a residual that does not scale with
    // the load from step to step (nearly all of it where it counts: delta_w / delta > 0.9), and it grows as
    // the mesh is refined while lambda_q falls. Each level where it exceeds 1/20 of the
    // error is refused as unconverged; the others are graded (their residual moves their
    // error by less than 0.13%).
    let residuals: Vec<f64> = g.checks.iter().map(|c| c.residual).collect();
    assert!(residuals.windows(2).all(|w| w[1] > w[0]), "{residuals:?}");
    let mut refused = 0;
    for c in &g.checks {
        if c.residual > LevelCheck::residual_limit(c.error) {
            assert!(c.residual_off_load.unwrap() > 0.9 * c.residual, "{c:?}");
            refused += 1;
            assert_eq!(c.residual_cause.as_deref(), Some("unconverged"), "{c:?}");
            assert_eq!(c.verdict, "flagged", "{c:?}");
        }
    }
    assert!(refused >= 1);
    assert_eq!(g.flagged.len(), refused);
    assert!(
        g.flagged
            .iter()
            .all(|f| f.contains("does not scale with the load"))
    );
}
