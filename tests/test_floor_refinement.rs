//! Reference: mixed-precision iterative refinement: a factorization in low precision used
//! as the preconditioner of a Krylov method in high precision reaches the high precision's
//! accuracy when u_low * cond(A) < 1 (Carson and Higham, SIAM J. Sci. Comput. 40 (2018)
//! A817; conjugate gradients for a symmetric positive definite A).
//! Goal: the floor's single way (an f32 Cholesky preconditioning conjugate gradients in
//! f64) solves the stiffness's systems to the solver's tolerance 1e-10, checked with an
//! independent product, and agrees with the double way (the f64 Cholesky); the floor
//! counts one system per distinct right-hand side.
//! Geometry: the speed study's families, `rates` (viscoplastic) and `rates-elastic`, whose
//! upper body is held only by contact: its shifted stiffness keeps a rigid mode whose
//! solution is about 1e8 times the rest, the hard case for f32.
//! Data: the scenes' loads at the end of each of 4 steps; levels 1-3 (552-8640 dofs).

mod common;
use contact_rates::contact::Method;
use contact_rates::solve::floor::{
    self, REFINEMENT_BUDGET, SINGLE_PIVOT_EPSILON, SINGLE_PIVOT_REPLACEMENT,
};
use contact_rates::solve::interface::Precision;
use contact_rates::solve::linear::{OrderedCholesky, SymmetricProduct};
use contact_rates::solve::{Settings, ordering};

/// Goal: an elastic run under a proportional load needs one system; a viscoplastic run
/// one per step.
#[test]
fn the_floor_solves_one_system_per_distinct_right_hand_side() {
    let elastic = common::case("rates-elastic", 1, Method::Mortar, &[]);
    let viscoplastic = common::case("rates", 1, Method::Mortar, &[]);
    assert_eq!(
        floor::right_hand_sides(&elastic.problem, 4).unwrap().len(),
        1
    );
    assert_eq!(
        floor::right_hand_sides(&viscoplastic.problem, 4)
            .unwrap()
            .len(),
        4
    );
}

/// Goal: per body's block, the single way's answer has a true residual (an independent
/// product) within the tolerance or the round-off of the product itself, in at most 8
/// applications (f32's 6e-8 against a condition number below 1e6 on these meshes: each
/// application gains at least two digits), and it agrees with the f64 Cholesky's answer to
/// the tolerance times the condition number that separates them.
#[test]
fn single_precision_cholesky_with_conjugate_gradients_meets_the_tolerance() {
    let tol = Settings::default().tol;
    for level in 1..=3 {
        let case = common::case("rates-elastic", level, Method::Mortar, &[]);
        let model = &case.problem.model;
        let load = &floor::right_hand_sides(&case.problem, 4).unwrap()[0];
        let (pattern, values, mean) = floor::shifted_stiffness(model);
        for range in pattern.diagonal_blocks() {
            let (block, entries) = pattern.block(&range);
            let block_values = &values[entries];
            let b: Vec<f64> = match load[range.clone()].iter().all(|&v| v == 0.0) {
                true => vec![1.0; range.len()],
                false => load[range.clone()].to_vec(),
            };
            let order = ordering::order(&block, &vec![false; block.n], None, 0).unwrap();
            let mut system = OrderedCholesky::new(&block, &order).unwrap();
            system.factor(block_values).unwrap();
            let mut double = b.clone();
            system.solve(&mut double);
            let single: Vec<f32> = block_values.iter().map(|&v| v as f32).collect();
            system
                .factor_single(
                    &single,
                    (SINGLE_PIVOT_EPSILON * mean) as f32,
                    (SINGLE_PIVOT_REPLACEMENT * mean) as f32,
                )
                .unwrap();
            let product = SymmetricProduct::new(block.clone(), block_values.to_vec());
            let absolute: Vec<f64> = block_values.iter().map(|v| v.abs()).collect();
            let absolute = SymmetricProduct::new(block.clone(), absolute);
            let attainable = |x: &[f64]| {
                let x: Vec<f64> = x.iter().map(|v| v.abs()).collect();
                let mut y = vec![0.0; x.len()];
                absolute.product(&x, &mut y);
                10.0 * f64::EPSILON * common::amax(&y)
            };
            let precondition = |r: &[f64], z: &mut [f64]| {
                let mut v: Vec<f32> = r.iter().map(|&x| x as f32).collect();
                system.solve_single(&mut v);
                z.iter_mut().zip(&v).for_each(|(z, &v)| *z = v as f64);
            };
            let solved = floor::conjugate_gradients(
                &|x, y| product.product(x, y),
                &attainable,
                &precondition,
                &b,
                tol,
            )
            .expect("the single way converges");
            let residual = |x: &[f64]| {
                let mut ax = vec![0.0; x.len()];
                product.product(x, &mut ax);
                let r: Vec<f64> = b.iter().zip(&ax).map(|(b, a)| b - a).collect();
                common::amax(&r)
            };
            let (r_single, r_double) = (residual(&solved.x), residual(&double));
            let bound = (tol * common::amax(&b)).max(attainable(&solved.x));
            println!(
                "level {level} block {range:?}: {} applications, residual single {:.2e} double {:.2e} (|b| {:.2e}, bound {bound:.2e}), x differ by {:.2e} relative",
                solved.applications,
                r_single,
                r_double,
                common::amax(&b),
                common::rel_diff(&double, &solved.x)
            );
            assert!(
                r_single <= bound,
                "level {level}: residual {r_single:.3e} > {bound:.3e}"
            );
            assert!(
                solved.applications <= 8,
                "{} applications",
                solved.applications
            );
            // The two answers meet the same residual bound: they differ by at most
            // cond(A) times it; cond(A) < 1e6 on these meshes, < 1e9 with the shift's
            // rigid mode, whose component both answers carry alike.
            assert!(common::rel_diff(&double, &solved.x) <= 1e-6);
        }
    }
}

/// Goal: the floor reports both ways, the faster as the floor, one system for the elastic
/// family and four for the viscoplastic one, and the single way within its budget.
#[test]
fn the_floor_times_both_ways_and_keeps_the_faster() {
    for (scene, systems) in [("rates-elastic", 1), ("rates", 4)] {
        let case = common::case(scene, 2, Method::Mortar, &[]);
        let f = floor::floor(&case.problem, 4).unwrap();
        let single = f.single_s.expect("the single way converges");
        assert_eq!(f.systems, systems, "{scene}");
        assert!(
            f.single_applications >= systems
                && f.single_applications <= REFINEMENT_BUDGET * systems
        );
        assert_eq!(f.seconds, f.double_s.min(single), "{scene}");
        assert_eq!(
            f.precision,
            match single < f.double_s {
                true => Precision::Single,
                false => Precision::Double,
            }
        );
        assert!(f.factor_flops > 0.0 && f.double_bytes > 0.0 && f.single_bytes > 0.0);
    }
}
