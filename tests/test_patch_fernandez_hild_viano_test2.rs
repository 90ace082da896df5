//! Reference: Fernandez-Garcia, Hild, Viano, "Numerical approximation of the
//! elastic-viscoplastic contact problem with non-matching meshes", section 5.2 (Test 2).
//! Goal: K_h^pi reproduces the homogeneous solution exactly on non-matching meshes;
//! K_h^I does not (interpenetration and spurious stresses). LAC (Drouet and Hild 2017)
//! reproduces it too: the exact P1 solution meets each macro-element's average with
//! equality and its constant pressure is piecewise constant.
//! Geometry: two stacked unit blocks, upper [0,1]x[1,2] (body 1), lower [0,1]x[0,1];
//! symmetry on the right sides and the bottom; meshes non-matching on y = 1.
//! Data: E = 3e5, nu = 0.3, lambda = 100, sigma_Y = sqrt(10), g = (0, -10 t) on top, T = 1,
//! 10 steps. Exact: sigma = diag(0, -10 t) in both bodies; the strain follows the
//! backward-Euler integration of the Perzyna law, computed here independently.

mod common;
use contact_rates::contact::{self, Method};
use contact_rates::material::{Elasticity, Stress};
use contact_rates::metrics;
use contact_rates::solve::{self, Settings};
use nalgebra::Vector3;

/// Projection onto the von Mises ellipse in the E-norm by direct minimization over the
/// boundary's angle (a dense scan, then bisection on the derivative): independent of the
/// library's scalar-multiplier solve.
fn project_independent(el: &Elasticity, s: &Stress, y: f64) -> Stress {
    let vm = (s[0] * s[0] + s[1] * s[1] - s[0] * s[1] + 3.0 * s[2] * s[2]).sqrt();
    if vm <= y {
        return *s;
    }
    // Boundary points for a stress with s12 = 0: tau11 = y (cos th + sin th/sqrt3), etc.
    let point = |th: f64| -> Stress {
        let p = y * th.cos();
        let d = y * th.sin() / 3f64.sqrt();
        Vector3::new(p + d, p - d, 0.0)
    };
    let dist = |th: f64| {
        let r = s - point(th);
        r.dot(&el.apply(&r))
    };
    let n = 20000;
    let mut best = 0;
    for i in 0..n {
        if dist(i as f64 * std::f64::consts::TAU / n as f64)
            < dist(best as f64 * std::f64::consts::TAU / n as f64)
        {
            best = i;
        }
    }
    let h = std::f64::consts::TAU / n as f64;
    // d/dth of the distance: -2 (s - point)^T E point'(th); it changes sign at the minimum.
    let slope = |th: f64| {
        let dp = Vector3::new(
            -y * th.sin() + y * th.cos() / 3f64.sqrt(),
            -y * th.sin() - y * th.cos() / 3f64.sqrt(),
            0.0,
        );
        -(s - point(th)).dot(&el.apply(&dp))
    };
    let (mut a, mut b) = ((best as f64 - 1.0) * h, (best as f64 + 1.0) * h);
    assert!(slope(a) < 0.0 && slope(b) > 0.0, "bracket");
    for _ in 0..200 {
        let c = 0.5 * (a + b);
        if slope(c) < 0.0 { a = c } else { b = c }
    }
    point(0.5 * (a + b))
}

#[test]
fn mortar_reproduces_the_homogeneous_solution_and_nts_does_not() {
    let steps = 10;
    let el = Elasticity::plane_stress(3e5, 0.3);
    let (lambda, y) = (100.0, 10f64.sqrt());
    // Independent backward Euler: eps^n = eps^{n-1} + E^{-1}(sigma^n - sigma^{n-1} - k G(sigma^n)).
    let k = 1.0 / steps as f64;
    let mut eps = vec![Vector3::zeros()];
    for n in 1..=steps {
        let s = Vector3::new(0.0, -10.0 * n as f64 * k, 0.0);
        let sp = Vector3::new(0.0, -10.0 * (n - 1) as f64 * k, 0.0);
        let g = -(0.5 / lambda) * el.apply(&(s - project_independent(&el, &s, y)));
        eps.push(eps[n - 1] + el.compliance(&(s - sp - k * g)));
    }
    assert!(
        eps[steps][1].abs() > 10.0 * 10.0 / 3e5,
        "the test must exercise viscoplastic flow"
    );

    for level in 0..3 {
        let case = common::case("patch", level, Method::Mortar, &[]);
        let p = &case.problem;
        assert!(
            p.interface.min_relative_separation() > 1e-3,
            "meshes must be non-matching"
        );
        let sol = solve::solve(p, &Settings::default(), steps, true).unwrap();
        for (n, st) in sol.states.iter().enumerate().skip(1) {
            let exact = Vector3::new(0.0, -10.0 * st.time, 0.0);
            let err = st
                .sigma
                .iter()
                .map(|s| (s - exact).amax())
                .fold(0.0, f64::max)
                / exact.amax();
            assert!(
                err < 1e-9,
                "level {level} step {n}: mortar stress error {err:e}"
            );
            let pen = metrics::max_penetration(p, st) / common::amax(&st.u);
            assert!(
                pen < 1e-12,
                "level {level} step {n}: mortar interpenetration {pen:e}"
            );
        }
        let last = sol.last();
        for (e, _) in p.model.elements.iter().zip(&last.sigma) {
            let strain = e.strain(&last.u);
            let err = (strain - eps[steps]).amax() / eps[steps].amax();
            assert!(
                err < 1e-9,
                "level {level}: strain {strain:?} vs backward Euler {:?}",
                eps[steps]
            );
        }

        let case = common::case("patch", level, Method::Nts, &[]);
        let p = &case.problem;
        let sol = solve::solve(p, &Settings::default(), steps, false).unwrap();
        let last = sol.last();
        let exact = Vector3::new(0.0, -10.0, 0.0);
        let err = last
            .sigma
            .iter()
            .map(|s| (s - exact).amax())
            .fold(0.0, f64::max)
            / 10.0;
        let pen = metrics::max_penetration(p, last) / common::amax(&last.u);
        println!(
            "level {level}: nts max stress error {err:.3e} (relative), max interpenetration {pen:.3e} (relative to max |u|)"
        );
        assert!(err > 1e-3, "nts must show spurious stresses, got {err:e}");
        assert!(pen > 1e-3, "nts must show interpenetration, got {pen:e}");
    }
    let _ = contact::Method::Mortar;
}

#[test]
fn lac_reproduces_the_homogeneous_solution_stress_and_pressure() {
    let steps = 10;
    for level in 0..3 {
        let case = common::case("patch", level, Method::Lac, &[]);
        let p = &case.problem;
        let sol = solve::solve(p, &Settings::default(), steps, false).unwrap();
        let (mut stress, mut pressure) = (0.0f64, 0.0f64);
        for st in sol.states.iter().skip(1) {
            let exact = Vector3::new(0.0, -10.0 * st.time, 0.0);
            for s in &st.sigma {
                stress = stress.max((s - exact).amax() / exact.amax());
            }
            for (row, l) in p.rows.iter().zip(&st.lambda) {
                pressure =
                    pressure.max((row.pressure(*l) - 10.0 * st.time).abs() / (10.0 * st.time));
            }
        }
        println!("level {level}: lac stress {stress:.2e}, pressure {pressure:.2e} (relative)");
        // Round-off of a solve at the default tolerance (1e-10 relative).
        assert!(
            stress <= 1e-10,
            "level {level}: lac stress error {stress:e}"
        );
        assert!(
            pressure <= 1e-10,
            "level {level}: lac pressure error {pressure:e}"
        );
    }
}
