//! Reference: issue 49 (Theorem 3.1's r in its own norm: the distance between the cones);
//! the triangle inequality.
//! Goal:
//! - on the patch scene (paper Test 2), where mortar reproduces the exact stress and
//!   pressure, the distance D between the cones in l2_stress, band_stress and l2_pressure
//!   equals nts's error in the same quantity to 1e-9 (relative to the same truth);
//! - on contact-mms, D - e_mortar <= e_nts <= D + e_mortar in Theorem 3.1's norm;
//! - on matching meshes (`rates` with matching = 1) the cones coincide: D <= 1e-9 (the
//!   solves stop at 1e-10).
//! Geometry: the scenes' own; levels 0-2.

mod common;

use contact_rates::contact::Method;
use contact_rates::scene::Scene;
use contact_rates::solve::SolverKind;
use contact_rates::verify::distance::cone_distance;
use contact_rates::verify::field::P1History;
use contact_rates::verify::quantity::Quantity;
use contact_rates::verify::solve_case;
use contact_rates::verify::truth::Truth;
use std::collections::BTreeMap;

/// Both cones on `scene` at `level` (its own sizes, 4 steps) against its exact solution:
/// mortar's and nts's errors and the distance between them.
fn both_cones(scene: &str, level: usize) -> [BTreeMap<Quantity, f64>; 3] {
    let loaded = Scene::load(scene).unwrap();
    let truth = Truth::Exact(loaded.exact.as_deref().unwrap(), 4);
    let cases = [Method::Mortar, Method::Nts].map(|m| common::case(scene, level, m, &[]));
    let sols = cases
        .each_ref()
        .map(|c| solve_case(c, SolverKind::Newton, 4).unwrap().0);
    let (mortar, _) = truth.measure_solved(&cases[0], &sols[0]);
    let (nts, scale) = truth.measure_solved(&cases[1], &sols[1]);
    let d = cone_distance(
        &P1History::of_solution(&cases[0], &sols[0]),
        &P1History::of_solution(&cases[1], &sols[1]),
        &scale,
    );
    [mortar, nts, d]
}

#[test]
fn patch_distance_equals_nts_error_where_mortar_is_exact() {
    for level in 0..=2 {
        let [mortar, nts, d] = both_cones("patch", level);
        for (distance, error) in [
            (Quantity::ConeDistanceL2Stress, Quantity::L2Stress),
            (Quantity::ConeDistanceBandStress, Quantity::BandStress),
            (Quantity::ConeDistanceL2Pressure, Quantity::L2Pressure),
        ] {
            let (dv, ev) = (d[&distance], nts[&error]);
            println!(
                "level {level}: {distance} {dv:.12e}, nts {error} {ev:.12e}, mortar {:.2e}",
                mortar[&error]
            );
            assert!(
                mortar[&error] <= 1e-9,
                "mortar is exact: {}",
                mortar[&error]
            );
            assert!((dv - ev).abs() <= 1e-9 * ev, "{distance}: {dv} vs {ev}");
        }
    }
}

#[test]
fn the_distance_bounds_nts_error_from_both_sides() {
    for level in 0..=2 {
        let [mortar, nts, d] = both_cones("contact-mms", level);
        let d = d[&Quantity::ConeDistance];
        let (em, en) = (mortar[&Quantity::Theorem], nts[&Quantity::Theorem]);
        println!("level {level}: D {d:.4e}, e_mortar {em:.4e}, e_nts {en:.4e}");
        // Max over the steps of a norm: the bounds hold step by step, hence for the maxima
        // (the three maxima may sit at different steps, which only loosens them).
        assert!(d > 0.0);
        assert!(en <= d + em * (1.0 + 1e-12), "{en} > {d} + {em}");
        assert!(en >= d - em - 1e-12, "{en} < {d} - {em}");
    }
}

#[test]
fn on_matching_meshes_the_cones_coincide() {
    let p = [("matching", 1.0)];
    let scene = Scene::load("rates").unwrap();
    for level in 0..=1 {
        let cases = [Method::Mortar, Method::Nts].map(|m| common::case("rates", level, m, &p));
        let sols = cases
            .each_ref()
            .map(|c| solve_case(c, SolverKind::Newton, scene.steps).unwrap().0);
        let (a, b) = (
            P1History::of_solution(&cases[0], &sols[0]),
            P1History::of_solution(&cases[1], &sols[1]),
        );
        // Relative to mortar's own norms: the scene has no exact solution.
        let norm = a
            .steps
            .iter()
            .map(|s| contact_rates::verify::norms::norms(a.model, s).theorem())
            .fold(0.0f64, f64::max);
        let scale = contact_rates::verify::quantity::Scale {
            theorem: norm,
            h1: norm,
            stress: norm,
            pressure: Some(1.0),
            jump: 1.0,
        };
        let d = cone_distance(&a, &b, &scale)[&Quantity::ConeDistance];
        println!("level {level}: D = {d:.3e}");
        assert!(d <= 1e-9, "{d}");
    }
}
