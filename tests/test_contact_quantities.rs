//! Reference: SPEC section 5 (contact quantities); closed forms of each quantity for known
//! fields.
//! Goal: the h^(1/2)-weighted pressure norm, the resultant and the total variation of a
//! known discrete pressure, the contact edge of known nodal pressure and gap, the band
//! stress error of a known stress, and the L2 norm of a known positive normal jump equal
//! their closed forms to round-off.
//! Geometry: the contact-mms scene at level 2 (Gamma_C: y = 1, 0 <= x <= 1, graded nodes).

mod common;

use contact_rates::contact::Method;
use contact_rates::material::Stress;
use contact_rates::verify::contact_error::{
    TruthPressure, band, contact_step, edges, penetration_l2,
};
use contact_rates::verify::exact_error::ExactComparison;
use contact_rates::verify::field::P1Field;

#[test]
fn weighted_norm_resultant_and_variation_of_a_linear_pressure() {
    let case = common::case("contact-mms", 2, Method::Mortar, &[]);
    let p = &case.problem;
    // A discrete pressure p_h(x) = 1 - x at the nodes, given as an outside code gives it
    // (nodal values, no multipliers), against a zero truth.
    let pressure = (0..p.model.n_nodes)
        .map(|n| 1.0 - p.model.position(n)[0])
        .collect();
    let s = P1Field::from_nodal(
        &p.model,
        &p.interface,
        1.0,
        vec![0.0; 2 * p.model.n_nodes],
        Some(vec![Stress::zeros(); p.model.elements.len()]),
        Some(pressure),
    )
    .unwrap();
    let piece = &p.interface.pieces[0];
    let zero = TruthPressure::Profile(vec![vec![(0.0, 0.0), (1.0, 0.0)]], vec![vec![]]);
    let c = contact_step(&p.interface, &s, &zero).pressure.unwrap();
    // sum_e h_e int_e (1 - x)^2 = sum_e h_e ((1 - a)^3 - (1 - b)^3) / 3.
    let xs: Vec<f64> = piece
        .slave_s
        .iter()
        .map(|s| piece.a[0] + s * piece.tangent[0])
        .collect();
    let mut sorted = xs.clone();
    sorted.sort_by(f64::total_cmp);
    let weighted: f64 = sorted
        .windows(2)
        .map(|w| (w[1] - w[0]) * ((1.0 - w[0]).powi(3) - (1.0 - w[1]).powi(3)) / 3.0)
        .sum();
    assert!(
        (c.pressure_weighted - weighted).abs() < 1e-14 * weighted,
        "{} vs {weighted}",
        c.pressure_weighted
    );
    assert!(
        (c.resultant.0 - 0.5).abs() < 1e-14,
        "resultant {}",
        c.resultant.0
    );
    assert!(
        (c.variation.0 - 1.0).abs() < 1e-14,
        "variation {}",
        c.variation.0
    );
}

#[test]
fn contact_edge_of_known_nodal_pressure_and_gap() {
    // p = max(0.55 - s, 0), g = max(s - 0.55, 0) at nodes 0, 0.1, ..., 1: phi = p / 0.55 -
    // g / 0.45 changes sign between 0.5 and 0.6, where linear interpolation puts it at
    // 0.5 + 0.1 (0.05/0.55) / (0.05/0.55 + 0.05/0.45).
    let nodes: Vec<f64> = (0..=10).map(|k| k as f64 / 10.0).collect();
    let p: Vec<(f64, f64)> = nodes.iter().map(|&s| (s, (0.55 - s).max(0.0))).collect();
    let g: Vec<(f64, f64)> = nodes.iter().map(|&s| (s, (s - 0.55).max(0.0))).collect();
    let e = edges(&p, &g);
    let (a, b) = (0.05 / 0.55, 0.05 / 0.45);
    assert_eq!(e.len(), 1);
    assert!((e[0] - (0.5 + 0.1 * a / (a + b))).abs() < 1e-14, "{e:?}");
    // Full contact: no edge.
    let full: Vec<(f64, f64)> = nodes.iter().map(|&s| (s, 1.0 + s)).collect();
    assert!(edges(&full, &[]).is_empty());
}

#[test]
fn band_stress_error_of_a_known_stress_is_the_band_area() {
    // Against the patch scene's exact stress diag(0, -10 t) at t = 1, a zero discrete stress
    // errs by |sigma|^2 = 100 on every triangle: the band error squared is 100 x the area of
    // the triangles with a vertex on y = 1 (found here by geometry, not by the interface).
    let case = common::case("patch", 1, Method::Mortar, &[]);
    let p = &case.problem;
    let scene = contact_rates::scene::Scene::load("patch").unwrap();
    let cmp = ExactComparison::new(scene.exact.as_deref().unwrap(), 2);
    let s = P1Field::from_nodal(
        &p.model,
        &p.interface,
        1.0,
        vec![0.0; 2 * p.model.n_nodes],
        Some(vec![Stress::zeros(); p.model.elements.len()]),
        None,
    )
    .unwrap();
    let d = cmp.difference(&p.model, &p.interface, &s);
    let area: f64 = p
        .model
        .elements
        .iter()
        .filter(|e| {
            e.nodes
                .iter()
                .any(|&n| (p.model.position(n)[1] - 1.0).abs() < 1e-12)
        })
        .map(|e| e.area)
        .sum();
    assert!(
        (d.band_stress - 100.0 * area).abs() < 1e-12 * 100.0 * area,
        "{} vs {}",
        d.band_stress,
        100.0 * area
    );
    assert_eq!(
        band(&p.model, &p.interface).iter().filter(|&&b| b).count(),
        p.model
            .elements
            .iter()
            .filter(|e| e
                .nodes
                .iter()
                .any(|&n| (p.model.position(n)[1] - 1.0).abs() < 1e-12))
            .count()
    );
}

#[test]
fn l2_penetration_of_a_known_jump() {
    // Body 1 moved down by (x - 0.5) where x > 0.5 (u_y = -(x - 0.5)^+ on its trace), body 2
    // at rest: [u.nu] = (x - 0.5)^+ (nu^1 = (0, -1)), whose L2 norm squared is
    // int_0.5^1 (x - 0.5)^2 = 1/24 -- exact when 0.5 is a node or the jump is linear between
    // the merged nodes; here the kink is between nodes, so compare with the same piecewise-
    // linear interpolant computed by hand.
    let case = common::case("contact-mms", 2, Method::Mortar, &[]);
    let p = &case.problem;
    let mut u = vec![0.0; 2 * p.model.n_nodes];
    let piece = &p.interface.pieces[0];
    for &n in &piece.slave_nodes {
        let x = p.model.position(n)[0];
        u[2 * n + 1] = -(x - 0.5).max(0.0);
    }
    // The jump is the slave's interpolant, evaluated at the merged nodes: linear between
    // consecutive slave nodes. Integrate its positive part squared per slave segment.
    let mut xs: Vec<f64> = piece
        .slave_nodes
        .iter()
        .map(|&n| p.model.position(n)[0])
        .collect();
    xs.sort_by(f64::total_cmp);
    let f = |x: f64| (x - 0.5).max(0.0);
    let exact: f64 = xs
        .windows(2)
        .map(|w| {
            let (a, b) = (f(w[0]), f(w[1]));
            let len = w[1] - w[0];
            if a > 0.0 || b == 0.0 {
                len * (a * a + a * b + b * b) / 3.0
            } else {
                // zero at w[0], linear up to b at w[1]
                len * b * b / 3.0
            }
        })
        .sum();
    let got = penetration_l2(&p.interface, &u);
    assert!((got - exact).abs() < 1e-14, "{got} vs {exact}");
    assert!((exact - 1.0 / 24.0).abs() < 0.01 / 24.0);
}
