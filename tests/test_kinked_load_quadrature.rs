//! Reference: SPEC section 5 ("the discrete load is as exact as the error measurement");
//! issue 20. Closed forms: the integral of a polynomial over a polygon (antiderivatives in
//! x, or area times the value at the centroid for a linear field).
//! Goal: a field that jumps across a straight line through a triangle (or an edge) is
//! integrated by the split rule (`quadrature::triangle_rule`, `segment_rule`) to round-off,
//! and the load vector of the manufactured `contact-mms` scene, whose derived body force
//! jumps at x = a = 0.5871 inside some triangles, equals one computed here independently:
//! every kinked triangle cut at x = a by hand, a degree-22 rule on each piece.
//! Geometry and data: the triangles and lines named in each test; `contact-mms` at level 1
//! (scene sizes h_upper = 0.3, h_lower = 0.2), t = 1.

mod common;

use contact_rates::contact::Method;
use contact_rates::quadrature::{Kink, gauss_legendre, segment_rule, triangle, triangle_rule};

/// Integrate `f` over the triangle `t` with the split rule of 4 x 4 points per piece.
fn split_integral(t: [[f64; 2]; 3], kinks: &[&Kink], f: impl Fn([f64; 2]) -> f64) -> f64 {
    let area = 0.5
        * ((t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[2][0] - t[0][0]) * (t[1][1] - t[0][1]))
            .abs();
    let base = triangle(4);
    triangle_rule(t, kinks, &base)
        .iter()
        .map(|&(l1, l2, w)| {
            let l0 = 1.0 - l1 - l2;
            let x = [0, 1].map(|c| l0 * t[0][c] + l1 * t[1][c] + l2 * t[2][c]);
            w * area * f(x)
        })
        .sum()
}

#[test]
fn a_polynomial_that_jumps_across_a_vertical_line_is_integrated_exactly() {
    // T = (0,0), (2,0), (0,1): y from 0 to 1 - x/2. Cut at x = a = 0.7.
    // f = x^2 y on x < a: int_0^a x^2 (1 - x/2)^2 / 2 dx
    //   = [x^3/6 - x^4/8 + x^5/40]_0^a;
    // f = 5 + y on x > a: int_a^2 5 (1 - x/2) + (1 - x/2)^2 / 2 dx
    //   = [5 x - 5 x^2/4 - (1 - x/2)^3 / 3]_a^2.
    let a: f64 = 0.7;
    let left = a.powi(3) / 6.0 - a.powi(4) / 8.0 + a.powi(5) / 40.0;
    let right_at = |x: f64| 5.0 * x - 1.25 * x * x - (1.0 - x / 2.0).powi(3) / 3.0;
    let exact = left + right_at(2.0) - right_at(a);
    let z = |x: [f64; 2]| x[0] - a;
    let f = |x: [f64; 2]| {
        if x[0] < a {
            x[0] * x[0] * x[1]
        } else {
            5.0 + x[1]
        }
    };
    let q = split_integral([[0.0, 0.0], [2.0, 0.0], [0.0, 1.0]], &[&z], f);
    let unsplit = split_integral([[0.0, 0.0], [2.0, 0.0], [0.0, 1.0]], &[], f);
    println!(
        "vertical cut: split {:.2e}, unsplit {:.2e} relative",
        (q - exact).abs() / exact,
        (unsplit - exact).abs() / exact
    );
    assert!((q - exact).abs() <= 1e-13 * exact, "{q} vs {exact}");
    assert!((unsplit - exact).abs() > 1e-4 * exact, "the jump matters");
}

#[test]
fn a_linear_field_that_jumps_across_a_slanted_line_is_integrated_exactly() {
    // The reference triangle (0,0), (1,0), (0,1) cut by x + 2 y = 0.9: the line meets the
    // edge y = 0 at (0.9, 0) and the edge x = 0 at (0, 0.45). The side x + 2 y < 0.9 is the
    // triangle (0,0), (0.9,0), (0,0.45): area 0.2025, centroid (0.3, 0.15). The other side is
    // the rest: area 0.5 - 0.2025 = 0.2975, centroid from the whole triangle's (1/3, 1/3):
    // (0.5/3 - 0.2025 * 0.3, 0.5/3 - 0.2025 * 0.15) / 0.2975.
    // f = 2 + x - y below the line, -1 + 3 y above: a linear field integrates to area times
    // its value at the centroid.
    let (a_low, c_low) = (0.2025, [0.3, 0.15]);
    let a_high = 0.5 - a_low;
    let c_high = [
        (0.5 / 3.0 - a_low * c_low[0]) / a_high,
        (0.5 / 3.0 - a_low * c_low[1]) / a_high,
    ];
    let exact = a_low * (2.0 + c_low[0] - c_low[1]) + a_high * (-1.0 + 3.0 * c_high[1]);
    let z = |x: [f64; 2]| x[0] + 2.0 * x[1] - 0.9;
    let q = split_integral([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], &[&z], |x| {
        if z(x) < 0.0 {
            2.0 + x[0] - x[1]
        } else {
            -1.0 + 3.0 * x[1]
        }
    });
    assert!((q - exact).abs() <= 1e-13 * exact.abs(), "{q} vs {exact}");
    // The same line given twice (as a derived field's kinks are) cuts once.
    let twice = split_integral([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], &[&z, &z], |x| {
        if z(x) < 0.0 {
            2.0 + x[0] - x[1]
        } else {
            -1.0 + 3.0 * x[1]
        }
    });
    assert!(
        (twice - exact).abs() <= 1e-13 * exact.abs(),
        "{twice} vs {exact}"
    );
}

#[test]
fn a_polynomial_that_jumps_inside_an_edge_is_integrated_exactly() {
    // The edge (0,0) -> (2,1), length sqrt(5), parameter s in [0, 1], x = 2 s; kink x = 1.3
    // at s = 0.65. f = s^7 before, 4 - s^3 after: int = 0.65^8 / 8 + 4 (1 - 0.65)
    // - (1 - 0.65^4) / 4 (times the length).
    let (a, b) = ([0.0, 0.0], [2.0, 1.0]);
    let s0: f64 = 0.65;
    let exact = s0.powi(8) / 8.0 + 4.0 * (1.0 - s0) - (1.0 - s0.powi(4)) / 4.0;
    let z = |x: [f64; 2]| x[0] - 1.3;
    let base = gauss_legendre(8);
    let q: f64 = segment_rule(a, b, &[&z], &base)
        .iter()
        .map(|&(s, w)| w * if s < s0 { s.powi(7) } else { 4.0 - s.powi(3) })
        .sum();
    assert!((q - exact).abs() <= 1e-13 * exact, "{q} vs {exact}");
}

#[test]
fn contact_mms_load_at_level_1_equals_a_hand_cut_high_degree_integration() {
    let case = common::case("contact-mms", 1, Method::Mortar, &[]);
    let model = &case.problem.model;
    let t = 1.0;
    let a = 0.5871;
    let produced = model.load(t).unwrap();

    // Independently: degree-22 rules (12 x 12 collapsed Gauss on triangles, 20 Gauss points
    // on edges), every triangle that x = a crosses cut by hand into its two sides.
    let tri = triangle(12);
    let gauss = gauss_legendre(20);
    let mut f = vec![0.0; produced.len()];
    let mut kinked = 0;
    for e in &model.elements {
        let Some(bf) = &model.scene.bodies[e.body].body_force else {
            continue;
        };
        let p = e.nodes.map(|n| model.position(n));
        let left: Vec<usize> = (0..3).filter(|&k| p[k][0] < a).collect();
        let pieces: Vec<[[f64; 2]; 3]> = if left.is_empty() || left.len() == 3 {
            vec![p]
        } else {
            kinked += 1;
            // The lone vertex on one side, the other two on the other; the line meets the
            // two edges from the lone vertex at x = a.
            let lone = if left.len() == 1 {
                left[0]
            } else {
                (0..3).find(|k| !left.contains(k)).unwrap()
            };
            let (j, k) = ((lone + 1) % 3, (lone + 2) % 3);
            let cut = |q: [f64; 2]| {
                let r = (a - p[lone][0]) / (q[0] - p[lone][0]);
                [a, p[lone][1] + r * (q[1] - p[lone][1])]
            };
            let (cj, ck) = (cut(p[j]), cut(p[k]));
            vec![[p[lone], cj, ck], [cj, p[j], p[k]], [cj, p[k], ck]]
        };
        for q in pieces {
            let area = 0.5
                * ((q[1][0] - q[0][0]) * (q[2][1] - q[0][1])
                    - (q[2][0] - q[0][0]) * (q[1][1] - q[0][1]))
                    .abs();
            for &(l1, l2, w) in &tri {
                let l0 = 1.0 - l1 - l2;
                let x = [0, 1].map(|c| l0 * q[0][c] + l1 * q[1][c] + l2 * q[2][c]);
                let v = [bf.0[0].eval(x[0], x[1], t), bf.0[1].eval(x[0], x[1], t)];
                // The hat functions of the element at x.
                let hat = (0..3).map(|m| {
                    let (i, j) = ((m + 1) % 3, (m + 2) % 3);
                    let num =
                        (p[i][0] - x[0]) * (p[j][1] - x[1]) - (p[j][0] - x[0]) * (p[i][1] - x[1]);
                    num / (2.0 * e.area)
                });
                for (m, lam) in hat.enumerate() {
                    for c in 0..2 {
                        f[2 * e.nodes[m] + c] += w * area * lam * v[c];
                    }
                }
            }
        }
    }
    // Tractions sigma n on `top` (y = 2, crossed by x = a) and `right_upper` (x = 1).
    let exact = model.scene.exact.as_deref().unwrap();
    for (edge, &(_, [na, nb])) in model.traction_edges.iter().enumerate() {
        let (body, n) = model.traction_normals[edge];
        let (pa, pb) = (model.position(na), model.position(nb));
        let len = (pb[0] - pa[0]).hypot(pb[1] - pa[1]);
        let mut parts = vec![(0.0, 1.0)];
        if (pa[0] - a) * (pb[0] - a) < 0.0 {
            let r = (a - pa[0]) / (pb[0] - pa[0]);
            parts = vec![(0.0, r), (r, 1.0)];
        }
        for (s0, s1) in parts {
            for &(q, w) in &gauss {
                let s = s0 + q * (s1 - s0);
                let x = [pa[0] + s * (pb[0] - pa[0]), pa[1] + s * (pb[1] - pa[1])];
                let g = contact_rates::analytical::traction(
                    exact.stress_at(body, x[0], x[1], t).unwrap(),
                    n,
                );
                for c in 0..2 {
                    f[2 * na + c] += w * (s1 - s0) * len * (1.0 - s) * g[c];
                    f[2 * nb + c] += w * (s1 - s0) * len * s * g[c];
                }
            }
        }
    }
    let d = common::rel_diff(&f, &produced);
    println!("{kinked} kinked triangles; load max |difference| / max |load| = {d:.2e}");
    assert!(kinked > 0, "x = a crosses triangles at level 1");
    assert!(d <= 1e-12, "{d:.3e}");
}
