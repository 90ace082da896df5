//! Reference: closed-form integrals (monomials on the reference triangle,
//! int x^i y^j = i! j! / (i + j + 2)!; int_0^1 int_0^1 sin(pi x) e^y = 2 (e - 1) / pi).
//! Goal: the collapsed Gauss rule with n points per direction integrates polynomials of
//! degree 2n - 2 to round-off, and converges on a smooth non-polynomial integrand, so that
//! the errors against exact solutions carry no quadrature error at the digits printed.
//! Geometry: the reference triangle, and the unit square as two triangles.

use contact_rates::quadrature::{gauss_legendre, triangle};

fn factorial(n: u32) -> f64 {
    (1..=n).map(f64::from).product()
}

#[test]
fn gauss_legendre_integrates_degree_2n_minus_1_exactly() {
    for n in 1..=12 {
        let rule = gauss_legendre(n);
        assert!((rule.iter().map(|p| p.1).sum::<f64>() - 1.0).abs() < 1e-14);
        for d in 0..(2 * n as i32) {
            let q: f64 = rule.iter().map(|&(x, w)| w * x.powi(d)).sum();
            let exact = 1.0 / (d + 1) as f64;
            assert!(
                (q - exact).abs() < 1e-14,
                "n {n} degree {d}: {q} vs {exact}"
            );
        }
    }
}

#[test]
fn collapsed_rule_integrates_degree_2n_minus_2_exactly_on_the_triangle() {
    for n in 1..=8 {
        let rule = triangle(n);
        for i in 0..(2 * n as u32 - 1) {
            for j in 0..(2 * n as u32 - 1 - i) {
                // The rule's weights are a mean: times the area 1/2.
                let q: f64 = rule
                    .iter()
                    .map(|&(l1, l2, w)| 0.5 * w * l1.powi(i as i32) * l2.powi(j as i32))
                    .sum();
                let exact = factorial(i) * factorial(j) / factorial(i + j + 2);
                assert!(
                    (q - exact).abs() <= 1e-14 * exact,
                    "n {n}, x^{i} y^{j}: {q} vs {exact}"
                );
            }
        }
    }
}

#[test]
fn collapsed_rule_converges_on_a_smooth_integrand() {
    // The unit square as the triangles (0,0),(1,0),(1,1) and (0,0),(1,1),(0,1).
    let tris = [
        [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]],
        [[0.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
    ];
    let f = |x: f64, y: f64| (std::f64::consts::PI * x).sin() * y.exp();
    let exact = 2.0 * (1f64.exp() - 1.0) / std::f64::consts::PI;
    let integral = |n: usize| -> f64 {
        let mut s = 0.0;
        for t in &tris {
            for &(l1, l2, w) in &triangle(n) {
                let l0 = 1.0 - l1 - l2;
                let x = l0 * t[0][0] + l1 * t[1][0] + l2 * t[2][0];
                let y = l0 * t[0][1] + l1 * t[1][1] + l2 * t[2][1];
                s += 0.5 * w * f(x, y);
            }
        }
        s
    };
    let errors: Vec<f64> = [2, 4, 8]
        .iter()
        .map(|&n| (integral(n) - exact).abs())
        .collect();
    println!("errors with 2, 4, 8 points per direction: {errors:?}");
    // Spectral convergence on the whole square (h = 1): the rule of a study, on triangles
    // of h <= 0.3, is far more accurate still.
    assert!(
        errors[0] > errors[1] && errors[1] < 1e-4 * exact && errors[2] < 1e-14 * exact,
        "{errors:?}"
    );
}

#[test]
fn dunavant_degree_8_rule_is_exact_on_every_monomial_of_degree_8() {
    // int over the reference triangle of x^i y^j = i! j! / (i + j + 2)!.
    use contact_rates::quadrature::dunavant8;
    let rule = dunavant8();
    assert_eq!(rule.len(), 16);
    let fact = |n: u32| (1..=n).map(f64::from).product::<f64>();
    for i in 0..=8u32 {
        for j in 0..=(8 - i) {
            let exact = fact(i) * fact(j) / fact(i + j + 2);
            let q: f64 = rule
                .iter()
                .map(|&(x, y, w)| 0.5 * w * x.powi(i as i32) * y.powi(j as i32))
                .sum();
            assert!(
                (q - exact).abs() <= 1e-14 * exact.max(1e-3),
                "x^{i} y^{j}: {q} vs {exact}"
            );
        }
    }
}
