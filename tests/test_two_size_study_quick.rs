//! Reference: Lemma 3.1 of the paper (consistency error h1^(3/4) + h2 for K_h^pi,
//! (h1^(1/2) ||e||)^(1/2) + h1^(3/4) + h2^(3/4) for K_h^I, body 1 the slave) and Theorem
//! 3.1's rates.
//! Goal: the quick tier of the two-size studies (contact-mms against its exact solution,
//! each body over levels 0-2, the other held at level 4, slave 'upper') (1) identifies the
//! slave's exponent a1 of the theorem norm in the grid fit E = C1 h1^a1 + C2 h2^a2 and it
//! reaches the study file's threshold (the Lemma's slave exponent minus the tolerance:
//! 0.70 mortar, 0.45 nts, the approximation error h1 only raising it; 0.95 lac, the rate 1
//! read from Drouet and Hild); (2) its equal-level pairs, the diagonal
//! study's meshes, reproduce the committed `rates-exact` errors to the solver tolerance
//! (1e-9 relative; one step here against four there: the problem is elastic and
//! proportional, so the solution at T does not depend on the steps); (3) refining the
//! slave reduces the theorem error from the (2, 2) point for both cones.
//! Geometry and data: the `contact-mms` scene, 1 time step, newton.

use contact_rates::contact::Method;
use contact_rates::studies::two_size;
use contact_rates::verify::quantity::Quantity;

#[test]
fn quick_two_size_study_meets_the_lemma_and_reproduces_the_diagonal() {
    contact_rates::init();
    let res = two_size::run("two-size-quick").unwrap();
    assert!(res.failures().is_empty(), "{:?}", res.failures());
    for f in res.fits.iter().filter(|f| f.quantity == Quantity::Theorem) {
        let x = f.fit.expect("a grid fit");
        println!(
            "{} {}: a1 = {:.3} +- {:.3}, a2 = {:.3} +- {:.3}, rms {:.3}",
            f.slave, f.method, x.a[0], x.se[0], x.a[1], x.se[1], x.rms_log_residual
        );
        assert!(
            x.se[0] <= 0.5 && x.rms_log_residual <= 0.25,
            "a1 identified"
        );
        // The study file's threshold: Theorem 3.1's rate minus 0.05 for the cones (the
        // Lemma's slave exponents), Drouet and Hild's claimed 1 minus 0.05 for lac.
        let need = res
            .threshold(f.method)
            .expect("every method has a threshold here");
        assert!(x.a[0] >= need, "{}: a1 {} < {need}", f.method, x.a[0]);
    }
    // The diagonal against the committed diagonal study.
    let committed = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("reports/rates-exact/errors.csv"),
    )
    .unwrap();
    let mut checked = 0;
    for line in committed.lines().skip(1) {
        let c: Vec<&str> = line.split(',').collect();
        let (method, level, quantity, error): (&str, usize, &str, f64) =
            (c[0], c[1].parse().unwrap(), c[5], c[6].parse().unwrap());
        let m = Method::parse(method).expect("a method");
        let Some(q) = res.quantities.iter().find(|q| q.name() == quantity) else {
            continue;
        };
        if let Some(e) = res.error("upper", m, *q, [level, level]) {
            let d = (e - error).abs() / error.abs();
            assert!(
                d < 1e-9,
                "{method} level {level} {quantity}: {e} against {error} ({d:e})"
            );
            checked += 1;
        }
    }
    println!("{checked} diagonal errors equal to the committed rates-exact ones");
    // The three methods at levels 0, 1, 2 and the fixed level 4, every quantity.
    assert_eq!(checked, 3 * 4 * res.quantities.len());
    // Refining the slave from (2, 2) to (4, 2) reduces the theorem error.
    for m in Method::ALL {
        let base = res.error("upper", m, Quantity::Theorem, [2, 2]).unwrap();
        let finer = res.error("upper", m, Quantity::Theorem, [4, 2]).unwrap();
        println!("{m}: theorem error {base:.3e} at (2, 2), {finer:.3e} at (4, 2)");
        assert!(finer < 0.5 * base);
    }
}
