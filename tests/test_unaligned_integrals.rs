// Reference: issue 63; src/quadrature/singular.rs (the rules at a singular point c: one
//   Gauss-Jacobi rule per power of r on triangles with a vertex at c, triangles holding c
//   on an edge split there first, triangles near c split recursively).
// Goal: on the unaligned family, where c lies on an edge of two boundary triangles and
//   inside a trace segment of both meshes at every level, the load and the error integrals
//   do not move (1e-8 relative) when the Gauss-Jacobi order (12 -> 20 points per
//   direction), the near split's depth (8 -> 11) and the distance it splits to (6 -> 16
//   diameters) are all raised.
// Geometry: the stacked unit blocks, c = (8/15, 1) at 2/3 of a lower and 1/3 of an upper
//   trace segment (levels 1 and 2: c at 1/3 and 2/3 of its segments in turn).
// Data: beta = 0.75 (body force ~ r^-1.25, pressure ~ r^-0.25: the strongest of the
//   family) and 1.5; t = 1; the error of the nodal interpolant of the exact solution.
// The accuracy is process-wide: this binary holds this one test.

mod common;

use contact_rates::contact::Method;
use contact_rates::quadrature::singular::{Accuracy, set_accuracy};
use contact_rates::studies::regularity::UNALIGNED;
use contact_rates::verify::exact_error::ExactComparison;
use contact_rates::verify::field::P1Field;

/// The load vector at t = 1 and the error integrals of the nodal interpolant (squared
/// differences and squared norms of u, grad u and the stress, the band's stress, the
/// pressure's), with the accuracy set now.
fn integrals(scene: &str, level: usize) -> (Vec<f64>, Vec<f64>) {
    let case = common::case(scene, level, Method::Mortar, &[]);
    let (m, interface) = (&case.problem.model, &case.problem.interface);
    let ex = m.scene.exact.as_deref().unwrap();
    let u = common::nodal_interpolant(m, ex, 1.0);
    // The exact pressure at the slave nodes (0 elsewhere), linear between them.
    let mut p = vec![0.0; m.n_nodes];
    for piece in &interface.pieces {
        for (&n, &s) in piece.slave_nodes.iter().zip(&piece.slave_s) {
            let x = piece.point(s);
            p[n] = ex.pressure_at(piece.normal, x[0], x[1], 1.0).unwrap();
        }
    }
    let field = P1Field::from_nodal(m, interface, 1.0, u, None, Some(p)).unwrap();
    let d = ExactComparison::new(ex, 4).difference(m, interface, &field);
    let errors = vec![
        d.difference.l2_u,
        d.difference.semi_u,
        d.difference.stress,
        d.exact.l2_u,
        d.exact.semi_u,
        d.exact.stress,
        d.band_stress,
        d.energy,
        d.pressure.unwrap().0,
        d.pressure.unwrap().1,
    ];
    (m.load(1.0).unwrap(), errors)
}

#[test]
fn load_and_error_integrals_do_not_move_when_the_rules_are_refined() {
    let raised = Accuracy {
        points: 20,
        near_depth: 11,
        near_ratio: 16,
    };
    for beta in [0.75, 1.5] {
        let scene = UNALIGNED.scene_name(beta);
        for level in [1, 2] {
            set_accuracy(Accuracy::DEFAULT);
            let (load, errors) = integrals(&scene, level);
            set_accuracy(raised);
            let (load_raised, errors_raised) = integrals(&scene, level);
            set_accuracy(Accuracy::DEFAULT);
            let scale = load.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let load_moved = load
                .iter()
                .zip(&load_raised)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
                / scale;
            let error_moved = errors
                .iter()
                .zip(&errors_raised)
                .map(|(a, b)| (a - b).abs() / a.abs().max(f64::MIN_POSITIVE))
                .fold(0.0f64, f64::max);
            println!(
                "beta {beta}, level {level}: load moved {load_moved:.1e} of its largest entry, error integrals {error_moved:.1e} relative"
            );
            assert!(
                load_moved <= 1e-8,
                "beta {beta} level {level}: load {load_moved:e}"
            );
            assert!(
                error_moved <= 1e-8,
                "beta {beta} level {level}: errors {error_moved:e} ({errors:?} vs {errors_raised:?})"
            );
        }
    }
}
