//! Reference: SPEC section 5 (errors against the exact solution); issue 47 (the error
//! integrals take a plain P1 field, which is what an outside contact code provides).
//! Goal: a solution handed over as an outside code would hand it over (nodal displacements,
//! a nodal pressure, no multipliers; for elastic bodies no stresses, which are then C eps(u_h))
//! measures the same errors as the solver's own state, to round-off; without a pressure the
//! pressure quantities are left out and the others unchanged; a field that cannot be
//! measured is refused with its reason.
//! Geometry: contact-mms (two elastic blocks, Gamma_C: y = 1) at level 2, both cones;
//! contact-mms-vp (the lower block viscoplastic) at level 0.
//! Data: the scenes' own, 4 steps.

mod common;

use contact_rates::contact::Method;
use contact_rates::scene::Scene;
use contact_rates::solve::SolverKind;
use contact_rates::verify::field::{FieldError, P1Field, P1History};
use contact_rates::verify::quantity::Quantity;
use contact_rates::verify::solve_case;
use contact_rates::verify::truth::Truth;

/// The pressure of a state per node, as an outside code writes it: the nodal multiplier over
/// its lumped weight at the body-1 trace nodes, 0 elsewhere.
fn nodal_pressure(p: &contact_rates::solve::Problem, lambda: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; p.model.n_nodes];
    for (row, l) in p.rows.iter().zip(lambda) {
        out[p.interface.pieces[row.piece].slave_nodes[row.node().expect("a nodal row")]] =
            row.pressure(*l);
    }
    out
}

#[test]
fn an_elastic_solution_given_as_nodal_values_measures_as_the_solver_state() {
    let scene = Scene::load("contact-mms").unwrap();
    let truth = Truth::Exact(scene.exact.as_deref().unwrap(), 4);
    for method in [Method::Mortar, Method::Nts] {
        let case = common::case("contact-mms", 2, method, &[]);
        let (sol, _) = solve_case(&case, SolverKind::Newton, 4).unwrap();
        let own = truth.relative_errors(&case, &sol);
        let p = &case.problem;
        let outside = |with_pressure: bool| P1History {
            model: &p.model,
            interface: &p.interface,
            steps: sol.states[1..]
                .iter()
                .map(|s| {
                    let pressure = with_pressure.then(|| nodal_pressure(p, &s.lambda));
                    P1Field::from_nodal(&p.model, &p.interface, s.time, s.u.clone(), None, pressure)
                        .unwrap()
                })
                .collect(),
        };
        let given = truth.errors(&outside(true));
        // Every quantity of one solution against the exact solution (a distance between the
        // cones is not one, nor the discrete gap, which reads the method's rows).
        assert_eq!(
            given.len(),
            Quantity::ALL
                .iter()
                .filter(|q| !q.is_distance() && !q.reads_rows())
                .count()
        );
        for (q, e) in &own {
            // The same integrals of the same P1 field; the stress C eps(u_h) recomputed from
            // u_h differs from the solver's by round-off.
            let got = given[q];
            println!("{method} {q}: solver state {e:.15e}, nodal values {got:.15e}");
            assert!(
                (got - e).abs() <= 1e-10 * e.abs(),
                "{method} {q}: {got} vs {e}"
            );
        }
        let without = truth.errors(&outside(false));
        for q in Quantity::ALL
            .into_iter()
            .filter(|q| !q.is_distance() && !q.reads_rows())
        {
            let pressure_quantity = q.needs_pressure();
            assert_eq!(
                without.get(&q).is_some(),
                !pressure_quantity,
                "{method} {q}"
            );
            if let Some(e) = without.get(&q) {
                assert_eq!(*e, given[&q], "{method} {q}");
            }
        }
    }
}

#[test]
fn a_field_that_cannot_be_measured_is_refused_with_its_reason() {
    let case = common::case("contact-mms-vp", 0, Method::Mortar, &[]);
    let (m, i) = (&case.problem.model, &case.problem.interface);
    let (nodes, triangles) = (m.n_nodes, m.elements.len());
    let zeros = || vec![0.0; 2 * nodes];
    // A viscoplastic body's stress does not follow from its displacement.
    let e = P1Field::from_nodal(m, i, 1.0, zeros(), None, None).unwrap_err();
    assert!(matches!(e, FieldError::StressNeeded { .. }), "{e}");
    let e = P1Field::from_nodal(m, i, 1.0, vec![0.0; 2 * nodes - 1], None, None).unwrap_err();
    assert_eq!(
        e,
        FieldError::DisplacementLength {
            got: 2 * nodes - 1,
            nodes
        }
    );
    let stress = vec![nalgebra::Vector3::zeros(); triangles + 1];
    let e = P1Field::from_nodal(m, i, 1.0, zeros(), Some(stress), None).unwrap_err();
    assert_eq!(
        e,
        FieldError::StressLength {
            got: triangles + 1,
            triangles
        }
    );
    let mut u = zeros();
    u[7] = f64::NAN;
    let stress = vec![nalgebra::Vector3::zeros(); triangles];
    let e = P1Field::from_nodal(m, i, 1.0, u, Some(stress.clone()), None).unwrap_err();
    assert_eq!(
        e.to_string(),
        "the displacement is not finite at node 3: write finite values (a diverged solve is not graded)"
    );
    let e = P1Field::from_nodal(m, i, 1.0, zeros(), Some(stress), Some(vec![0.0; 3])).unwrap_err();
    assert_eq!(e, FieldError::PressureLength { got: 3, nodes });
}
