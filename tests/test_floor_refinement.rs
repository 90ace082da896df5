//! Reference: mixed-precision iterative refinement: a factorization in low precision used
//! as the preconditioner of a Krylov method in high precision reaches the high precision's
//! accuracy when u_low * cond(A) < 1 (Carson and Higham, SIAM J. Sci. Comput. 40 (2018)
//! A817; conjugate gradients for a symmetric positive definite A).
//! Goal: the floor's single way (an f32 Cholesky preconditioning conjugate gradients in
//! f64) solves the stiffness's systems to the solver's tolerance 1e-10, checked with an
//! independent product, and agrees with the double way (the f64 Cholesky); the floor
//! counts one system per distinct right-hand side.
//! Geometry: the speed study's families, `rates` (viscoplastic) and `rates-elastic`, whose
//! upper body is held only by contact: its shifted stiffness keeps an eigenvalue at the
//! shift (1e-8 of its mean diagonal), the hard case for f32.
//! Data: the scenes' loads at the end of each of 4 steps; levels 1-3 (552-8640 dofs).

mod common;
use contact_rates::contact::Method;
use contact_rates::fe::Pattern;
use contact_rates::solve::floor::{
    self, REFINEMENT_BUDGET, SINGLE_PIVOT_EPSILON, SINGLE_PIVOT_REPLACEMENT,
};
use contact_rates::solve::interface::Precision;
use contact_rates::solve::linear::{OrderedCholesky, SymmetricProduct};
use contact_rates::solve::{Settings, ordering};

/// One body's block factorized both ways (f64, and f32 as the floor does), with its
/// product and that of its absolute values: the pieces of the floor's single way.
struct BothWays {
    system: OrderedCholesky,
    product: SymmetricProduct,
    absolute: SymmetricProduct,
}

impl BothWays {
    fn new(block: &Pattern, values: &[f64], mean: f64) -> Self {
        let order = ordering::order(block, &vec![false; block.n], None, 0).unwrap();
        let mut system = OrderedCholesky::new(block, &order).unwrap();
        system.factor(values).unwrap();
        let single: Vec<f32> = values.iter().map(|&v| v as f32).collect();
        system
            .factor_single(
                &single,
                (SINGLE_PIVOT_EPSILON * mean) as f32,
                (SINGLE_PIVOT_REPLACEMENT * mean) as f32,
            )
            .unwrap();
        BothWays {
            system,
            product: SymmetricProduct::new(block.clone(), values.to_vec()),
            absolute: SymmetricProduct::new(
                block.clone(),
                values.iter().map(|v| v.abs()).collect(),
            ),
        }
    }

    /// 10 eps |A| |x|_inf: the round-off of computing A x.
    fn attainable(&self, x: &[f64]) -> f64 {
        let x: Vec<f64> = x.iter().map(|v| v.abs()).collect();
        let mut y = vec![0.0; x.len()];
        self.absolute.product(&x, &mut y);
        10.0 * f64::EPSILON * common::amax(&y)
    }

    /// The floor's single way for `b`: conjugate gradients to `tol` with these pieces.
    fn single_way(&self, b: &[f64], tol: f64) -> floor::Solved {
        let solved = floor::conjugate_gradients(
            &|x, y| self.product.product(x, y),
            &|x| self.attainable(x),
            &|r, z| self.precondition(r, z),
            b,
            tol,
        );
        assert!(solved.converged, "the single way converges");
        solved
    }

    /// z = the f32 factor's solve of r, in f64.
    fn precondition(&self, r: &[f64], z: &mut [f64]) {
        let mut v: Vec<f32> = r.iter().map(|&x| x as f32).collect();
        self.system.solve_single(&mut v);
        z.iter_mut().zip(&v).for_each(|(z, &v)| *z = v as f64);
    }
}

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
            let both = BothWays::new(&block, block_values, mean);
            let mut double = b.clone();
            both.system.solve(&mut double);
            let (product, attainable) = (&both.product, |x: &[f64]| both.attainable(x));
            let solved = both.single_way(&b, tol);
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

/// Goal: the flops the bounds divide by the measured peak (flop/s, a multiply-add is 2)
/// are flops too: a dense factor of order n costs n^3/3 flops, twice the multiply-adds of
/// its column Cholesky counted here (r multiplies by the pivot's inverse and the r (r + 1)
/// / 2 of the lower triangle of the rank-1 update, for a column with r rows below).
#[test]
fn factor_flops_count_a_multiply_add_as_two() {
    let n = 120;
    let pattern = contact_rates::fe::Pattern::from_entries(
        n,
        (0..n).flat_map(|i| (0..n).map(move |j| (i, j))).collect(),
    );
    let order: Vec<usize> = (0..n).collect();
    let system = OrderedCholesky::new(&pattern, &order).unwrap();
    let multiply_adds: f64 = (0..n)
        .map(|j| {
            let r = (n - 1 - j) as f64;
            r + r * (r + 1.0) / 2.0
        })
        .sum();
    let flops = system.factor_flops();
    println!("n {n}: factor_flops {flops:.4e}, multiply-adds {multiply_adds:.4e}");
    assert_eq!(system.factor_entries(), n * (n + 1) / 2);
    assert!(
        (flops / (2.0 * multiply_adds) - 1.0).abs() < 0.03,
        "{flops} flops against {multiply_adds} multiply-adds"
    );
}

/// Goal: where the tolerance is below the round-off of A x (ones on the body held only by
/// contact: its rigid mode's component is 1e5 times the load), conjugate gradients stop
/// as soon as the true residual is at that round-off, no later than a textbook version
/// that checks the true residual after every update (same preconditioner).
#[test]
fn conjugate_gradients_stop_at_the_round_off_of_the_product() {
    let tol = Settings::default().tol;
    for level in 1..=3 {
        let case = common::case("rates-elastic", level, Method::Mortar, &[]);
        let (pattern, values, mean) = floor::shifted_stiffness(&case.problem.model);
        // The body held only by contact: the one without a clamp, the first block.
        let range = pattern.diagonal_blocks()[0].clone();
        let (block, entries) = pattern.block(&range);
        let block_values = &values[entries];
        let both = BothWays::new(&block, block_values, mean);
        let (product, attainable) = (&both.product, |x: &[f64]| both.attainable(x));
        let precondition = |r: &[f64], z: &mut [f64]| both.precondition(r, z);
        let b = vec![1.0; block.n];
        let solved = both.single_way(&b, tol);
        // Textbook: one preconditioned CG, the true residual after each update.
        let dot = |a: &[f64], c: &[f64]| a.iter().zip(c).map(|(x, y)| x * y).sum::<f64>();
        let (mut x, mut r) = (vec![0.0; block.n], b.clone());
        let (mut z, mut q) = (vec![0.0; block.n], vec![0.0; block.n]);
        precondition(&r, &mut z);
        let (mut d, mut rz, mut textbook) = (z.clone(), dot(&r, &z), 1);
        loop {
            product.product(&d, &mut q);
            let alpha = rz / dot(&d, &q);
            x.iter_mut().zip(&d).for_each(|(x, d)| *x += alpha * d);
            r.iter_mut().zip(&q).for_each(|(r, q)| *r -= alpha * q);
            let mut ax = vec![0.0; block.n];
            product.product(&x, &mut ax);
            let true_residual = b
                .iter()
                .zip(&ax)
                .map(|(b, a)| (b - a).abs())
                .fold(0.0, f64::max);
            if true_residual <= (tol * common::amax(&b)).max(attainable(&x))
                || textbook == REFINEMENT_BUDGET
            {
                break;
            }
            precondition(&r, &mut z);
            textbook += 1;
            let rz_next = dot(&r, &z);
            d.iter_mut()
                .zip(&z)
                .for_each(|(d, z)| *d = z + rz_next / rz * *d);
            rz = rz_next;
        }
        println!(
            "level {level}: {} applications, textbook {textbook}",
            solved.applications
        );
        assert!(
            solved.applications <= textbook,
            "level {level}: {} applications, textbook {textbook}",
            solved.applications
        );
    }
}

/// Goal: where conjugate gradients cannot meet the tolerance (here a tolerance of 1e-300
/// |b|, far below the product's round-off, with the round-off stop switched off), they
/// give up after exactly [`REFINEMENT_BUDGET`] applications, say so, and count that work
/// (one product per application at least), which the floor adds to the single way's
/// applications and bytes. No committed run misses, so the floor's sum is not exercised
/// end to end here.
#[test]
fn conjugate_gradients_that_miss_the_tolerance_count_their_applications() {
    let case = common::case("rates-elastic", 1, Method::Mortar, &[]);
    let (pattern, values, mean) = floor::shifted_stiffness(&case.problem.model);
    let range = pattern.diagonal_blocks()[0].clone();
    let (block, entries) = pattern.block(&range);
    let both = BothWays::new(&block, &values[entries], mean);
    let b = vec![1.0; block.n];
    let solved = floor::conjugate_gradients(
        &|x, y| both.product.product(x, y),
        &|_| 0.0,
        &|r, z| both.precondition(r, z),
        &b,
        1e-300,
    );
    assert!(!solved.converged);
    assert_eq!(solved.applications, REFINEMENT_BUDGET);
    assert!(solved.products >= REFINEMENT_BUDGET, "{}", solved.products);
}

/// Goal: `Floor::fastest` of two measurements of one floor, where only the second's single
/// way met the tolerance, keeps that way's time and the work it did (not the missed
/// measurement's budget), and each way's fastest time.
#[test]
fn the_fastest_floor_takes_the_single_way_from_the_measurement_that_converged() {
    let missed = floor::Floor {
        seconds: 1.0,
        precision: Precision::Double,
        shared_s: 0.4,
        double_s: 1.0,
        single_s: None,
        systems: 4,
        single_applications: 4 * REFINEMENT_BUDGET,
        double_bytes: 8.0,
        single_bytes: 1000.0,
        factor_entries: 10,
        factor_flops: 100.0,
        stiffness_entries: 20,
    };
    let converged = floor::Floor {
        seconds: 0.9,
        precision: Precision::Single,
        shared_s: 0.5,
        double_s: 1.1,
        single_s: Some(0.9),
        single_applications: 20,
        single_bytes: 300.0,
        ..missed
    };
    for f in [missed.fastest(&converged), converged.fastest(&missed)] {
        assert_eq!((f.seconds, f.precision), (0.9, Precision::Single));
        assert_eq!((f.shared_s, f.double_s, f.single_s), (0.4, 1.0, Some(0.9)));
        assert_eq!((f.single_applications, f.single_bytes), (20, 300.0));
    }
}
