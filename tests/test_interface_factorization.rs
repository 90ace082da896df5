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

/// The elastic stiffness of `case` (matrix and pattern), its mean diagonal c
/// (force/length) and the contact rows over the free unknowns.
fn elastic_system(
    case: &contact_rates::case::Case,
) -> (
    SparseSystem,
    f64,
    Vec<Vec<(usize, f64)>>,
    contact_rates::fe::Pattern,
) {
    let model = &case.problem.model;
    let n = model.n_free;
    let (pattern, slots) = model.stiffness_pattern(&[], n);
    let mut stiffness = SparseSystem::new(&pattern);
    model.add_tangent(&model.elastic_tangents(), &slots, stiffness.values_mut());
    let values = stiffness.values();
    let c = (0..n).map(|i| values[pattern.slot(i, i)]).sum::<f64>() / n as f64;
    (stiffness, c, case.problem.free_rows(), pattern)
}

/// Level 1 factorizes each body whole; level 4 (34,432 dofs) splits the larger body's
/// elimination tree into subtrees substituted side by side ([`contact_rates::solve::substitution`]).
#[test]
fn interface_solve_is_exact_for_any_active_set() {
    for (level, method) in [(1, Method::Mortar), (1, Method::Nts), (4, Method::Mortar)] {
        let case = common::case("rates", level, method, &[]);
        let n = case.problem.model.n_free;
        let (stiffness, c, rows, pattern) = elastic_system(&case);
        let m = rows.len();
        let b = common::sequence(n + m);
        // Single precision's error grows with the condition of the stiffness (h^-2): its
        // bound is the level-1 one; the split's exactness is checked in double precision.
        let precisions = match level {
            1 => vec![(Precision::Double, 1e-12), (Precision::Single, 1e-4)],
            _ => vec![(Precision::Double, 1e-12)],
        };
        for (precision, tolerance) in precisions {
            let mut factorization = InterfaceFactorization::new(&pattern, &rows).unwrap();
            factorization
                .factor(stiffness.values(), c, precision)
                .unwrap();
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
                    "level {level} {method:?} {precision:?} active {} of {m}: residual {residual:.2e}",
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

/// The substitutions' subtrees run as tasks on whatever threads there are, and each
/// subtree's updates are added in a fixed order: one thread and two give the same bits.
#[test]
fn a_solve_gives_the_same_bits_on_one_thread_and_on_two() {
    let case = common::case("rates", 4, Method::Mortar, &[]);
    let n = case.problem.model.n_free;
    let (stiffness, c, rows, pattern) = elastic_system(&case);
    // The values alone cross into the pools (the matrix counts its solves in a Cell).
    let values = stiffness.values();
    let b = common::sequence(n + rows.len());
    let solve_on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut factorization = InterfaceFactorization::new(&pattern, &rows).unwrap();
            factorization.factor(values, c, Precision::Single).unwrap();
            let set = factorization
                .active_set(&vec![true; rows.len()], c)
                .unwrap();
            let mut x = b.clone();
            factorization.solve(&set, c, &mut x);
            x
        })
    };
    let (one, two) = (solve_on(1), solve_on(2));
    let differing = one
        .iter()
        .zip(&two)
        .filter(|(a, b)| a.to_bits() != b.to_bits())
        .count();
    assert_eq!(differing, 0, "{differing} of {} values differ", one.len());
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

/// Newton's products K_t x read the elastic stiffness and add the viscoplastic triangles'
/// share per triangle (`TangentChange`) instead of an assembled K_t: the two agree to
/// round-off (1e-12 of the largest entry) at a state where part of the mesh flows, on one
/// thread (level 1) and with the bodies on two (level 4, from PARALLEL_ELEMENTS triangles).
#[test]
fn the_per_triangle_tangent_change_is_the_assembled_one() {
    for level in [1, 4] {
        let case = common::case("rates", level, Method::Mortar, &[]);
        let model = &case.problem.model;
        let (elastic, _, _, pattern) = elastic_system(&case);
        // A displacement of pseudo-random nodal values, strains of order 0.1 (stresses
        // about 3 sigma_Y in the triangles with large gradients, elastic elsewhere).
        let h = model.h();
        let u: Vec<f64> = common::sequence(2 * model.n_nodes)
            .iter()
            .map(|v| 0.05 * h * v)
            .collect();
        let zero_strain = model.strains(&vec![0.0; u.len()]);
        let zero_sigma = vec![contact_rates::material::Stress::zeros(); model.elements.len()];
        let (_, tangents) = model.update_stresses(&u, &zero_strain, &zero_sigma, 0.01, None, true);
        let change = model.tangent_change(&tangents);
        let flowing = (tangents.iter().zip(&model.elements))
            .filter(|(d, e)| **d != model.materials[e.body].elastic.matrix())
            .count();
        assert!(
            flowing > 0 && flowing < model.elements.len(),
            "level {level}: {flowing} of {} triangles flow: the test needs both kinds",
            model.elements.len()
        );
        let n = model.n_free;
        let (_, slots) = model.stiffness_pattern(&[], n);
        let mut assembled = SparseSystem::new(&pattern);
        model.add_tangent(&tangents, &slots, assembled.values_mut());
        let x = common::sequence(n + 7)[7..].to_vec();
        let mut expected = vec![0.0; n];
        assembled.matvec(&x, &mut expected);
        let mut product = vec![0.0; n];
        elastic.matvec(&x, &mut product);
        change.add_product(&x, &mut product);
        let difference = common::rel_diff(&product, &expected);
        assert!(
            difference < 1e-12,
            "level {level}: per-triangle product differs from the assembled K_t by {difference:.2e}"
        );
    }
}
