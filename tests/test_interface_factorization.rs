//! Reference: block elimination of a saddle-point system onto the unknowns its constraints
//! touch (the Schur complement of the stiffness onto the contact interface), SPEC
//! section 7.
//! Goal: the default solver's factorization solves the Newton system
//! `[K c C^T; c C_A 0]` (c on the diagonal of inactive rows) exactly for any active set,
//! from one sparse factorization of the stiffness: residual at round-off (1e-12 of the
//! right-hand side) in double precision, within 1e-4 in single precision (newton's: f32
//! rounding times the condition of the stiffness); and an elastic run factorizes once and
//! ends every time step in at most two Newton iterations.
//! Geometry: the `rates` scene (its upper block is held vertically only by contact: a
//! singular stiffness) at level 1, both cones; `rates-elastic` at level 2.
//! Data: E = 100, nu = 0.3; right-hand sides from a fixed pseudo-random sequence.

mod common;
use contact_rates::contact::Method;
use contact_rates::solve::interface::{InterfaceFactorization, Precision};
use contact_rates::solve::linear::SparseSystem;
use contact_rates::solve::{self, Settings};

/// A fixed sequence in [-1, 1] (linear congruential; the test needs no randomness).
fn sequence(len: usize) -> Vec<f64> {
    let mut state: u64 = 12345;
    (0..len)
        .map(|_| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        })
        .collect()
}

/// Largest residual entry of the Newton system of `active`, relative to the largest
/// right-hand side entry.
fn relative_residual(
    stiffness: &SparseSystem,
    rows: &[Vec<(usize, f64)>],
    active: &[bool],
    c: f64,
    x: &[f64],
    b: &[f64],
) -> f64 {
    let n = b.len() - rows.len();
    let mut r = vec![0.0; n];
    stiffness.matvec(&x[..n], &mut r);
    for (i, row) in rows.iter().enumerate() {
        for &(eq, v) in row {
            r[eq] += c * v * x[n + i];
        }
    }
    let mut worst = (0..n).map(|k| (r[k] - b[k]).abs()).fold(0.0, f64::max);
    for (i, row) in rows.iter().enumerate() {
        let lhs = match active[i] {
            true => c * row.iter().map(|&(eq, v)| v * x[eq]).sum::<f64>(),
            false => c * x[n + i],
        };
        worst = worst.max((lhs - b[n + i]).abs());
    }
    worst / b.iter().fold(0.0f64, |a, v| a.max(v.abs()))
}

#[test]
fn interface_solve_is_exact_for_any_active_set() {
    for method in [Method::Mortar, Method::Nts] {
        let case = common::case("rates", 1, method, &[]);
        let model = &case.problem.model;
        let n = model.n_free;
        let (pattern, slots) = model.stiffness_pattern(&[], n);
        let mut stiffness = SparseSystem::new(&pattern);
        model.add_tangent(&model.elastic_tangents(), &slots, stiffness.values_mut());
        let values = stiffness.values_mut().to_vec();
        let c = (0..n).map(|i| values[pattern.slot(i, i)]).sum::<f64>() / n as f64;
        let rows = case.problem.free_rows();
        let m = rows.len();
        let b = sequence(n + m);
        for (precision, tolerance) in [(Precision::Double, 1e-12), (Precision::Single, 1e-4)] {
            let mut factorization = InterfaceFactorization::new(&pattern, &rows).unwrap();
            factorization.factor(&values, c, precision).unwrap();
            let sets: [Vec<bool>; 3] = [
                vec![true; m],
                (0..m).map(|i| i % 2 == 0).collect(),
                (0..m).map(|i| i < m / 2).collect(),
            ];
            for active in &sets {
                let set = factorization.active_set(active, c).unwrap();
                let mut x = b.clone();
                factorization.solve(&set, c, &mut x);
                let residual = relative_residual(&stiffness, &rows, active, c, &x, &b);
                println!(
                    "{method:?} {precision:?} active {} of {m}: residual {residual:.2e}",
                    active.iter().filter(|&&a| a).count()
                );
                assert!(
                    residual <= tolerance,
                    "{method:?}: residual {residual:.2e} above {tolerance:.0e}"
                );
            }
        }
    }
}

/// An elastic step is linear but for the active set, which the interface model settles:
/// its first Newton iteration leaves the single-precision solve's error (8.5e-6 of the
/// right-hand side at level 1 in the test above), its second the square of that, below
/// the tolerance 1e-10. The stiffness never changes: one factorization for the whole run.
#[test]
fn an_elastic_run_factorizes_once_and_takes_at_most_two_iterations_per_step() {
    for method in [Method::Mortar, Method::Nts] {
        let case = common::case("rates-elastic", 2, method, &[]);
        let sol = solve::solve(&case.problem, &Settings::default(), 4, false).unwrap();
        println!(
            "{method:?}: {} factorizations, iterations per step {:?}",
            sol.timings.factorizations,
            sol.reports.iter().map(|r| r.iterations).collect::<Vec<_>>()
        );
        assert_eq!(sol.timings.factorizations, 1);
        assert!(sol.reports.iter().all(|r| r.iterations <= 2));
    }
}
