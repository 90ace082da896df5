// Reference: Golub and Welsch, "Calculation of Gauss quadrature rules", Math. Comp. 23
//   (1969); the polar integral int_T r^gamma cos(k theta) dA = int cos(k theta)
//   R(theta)^(gamma+2) / (gamma+2) dtheta (R: distance from c to the opposite edge along
//   theta) is the closed form in r.
// Goal: the singular rules of quadrature::singular integrate r^gamma cos(k theta) on a
//   triangle with a vertex at the singular point c to 1e-12 relative, for every gamma from
//   -1.4 (the load's r^(beta-2) at beta = 0.6) to 2; Gauss-Jacobi integrates its moments
//   exactly; the recursive split of a nearby triangle converges.
// Geometry: three triangles with a vertex at c = (0.5871, 1): a right one, an obtuse one
//   (angle 2.2 rad at c) and a thin one (aspect ratio 8), as meshes put them.
// Data: gamma in {-1.4, -0.9, -0.5, -0.2, 0, 0.2, 0.5, 1, 1.5, 2}, k in {0, 1, 3}.

use contact_rates::quadrature::singular::{gauss_jacobi, near_rule, segment_from, vertex_rule};
use contact_rates::quadrature::{dunavant8, gauss_legendre};

const C: [f64; 2] = [0.5871, 1.0];

fn triangles() -> Vec<[[f64; 2]; 3]> {
    vec![
        [C, [C[0] + 0.1, C[1]], [C[0], C[1] + 0.1]],
        [C, [C[0] + 0.08, C[1] + 0.01], [C[0] - 0.05, C[1] + 0.07]],
        [[C[0] + 0.04, C[1] - 0.005], C, [C[0] + 0.04, C[1] + 0.0]],
    ]
}

/// int_T r^gamma cos(k theta) dA with the radial integral in closed form and the angular
/// one by 400 panels of 20-point Gauss-Legendre (smooth in theta).
fn polar_reference(t: [[f64; 2]; 3], v: usize, gamma: f64, k: f64) -> f64 {
    let c = t[v];
    let (p1, p2) = (t[(v + 1) % 3], t[(v + 2) % 3]);
    let ang = |p: [f64; 2]| (p[1] - c[1]).atan2(p[0] - c[0]);
    let (mut a1, mut a2) = (ang(p1), ang(p2));
    if a2 < a1 {
        std::mem::swap(&mut a1, &mut a2);
    }
    if a2 - a1 > std::f64::consts::PI {
        // The wedge wraps around theta = pi.
        (a1, a2) = (a2, a1 + 2.0 * std::f64::consts::PI);
    }
    // The opposite edge's line: distance d and normal angle.
    let e = [p2[0] - p1[0], p2[1] - p1[1]];
    let len = e[0].hypot(e[1]);
    let mut normal = [e[1] / len, -e[0] / len];
    let mut d = (p1[0] - c[0]) * normal[0] + (p1[1] - c[1]) * normal[1];
    if d < 0.0 {
        normal = [-normal[0], -normal[1]];
        d = -d;
    }
    let an = normal[1].atan2(normal[0]);
    let g = gauss_legendre(20);
    let panels = 400;
    let mut sum = 0.0;
    for p in 0..panels {
        let (lo, hi) = (
            a1 + (a2 - a1) * p as f64 / panels as f64,
            a1 + (a2 - a1) * (p + 1) as f64 / panels as f64,
        );
        for &(s, w) in &g {
            let th = lo + s * (hi - lo);
            let r = d / (th - an).cos();
            sum += w * (hi - lo) * (k * th).cos() * r.powf(gamma + 2.0) / (gamma + 2.0);
        }
    }
    sum
}

fn area(t: &[[f64; 2]; 3]) -> f64 {
    0.5 * ((t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[2][0] - t[0][0]) * (t[1][1] - t[0][1]))
        .abs()
}

fn term(c: [f64; 2], gamma: f64, k: f64) -> impl Fn([f64; 2]) -> f64 {
    move |x| {
        let (dx, dy) = (x[0] - c[0], x[1] - c[1]);
        dx.hypot(dy).powf(gamma) * (k * dy.atan2(dx)).cos()
    }
}

#[test]
fn gauss_jacobi_integrates_its_moments() {
    for b in [-0.9, -0.4, 0.0, 0.2, 1.0, 3.0] {
        for n in [1, 4, 12] {
            let rule = gauss_jacobi(n, b);
            for k in 0..2 * n {
                let got: f64 = rule.iter().map(|&(s, w)| w * s.powi(k as i32)).sum();
                let want = 1.0 / (b + k as f64 + 1.0);
                assert!(
                    ((got - want) / want).abs() < 1e-13,
                    "b = {b}, n = {n}, k = {k}: {got} vs {want}"
                );
            }
        }
    }
    // b = 0 is Gauss-Legendre.
    for (a, b) in gauss_jacobi(7, 0.0).iter().zip(gauss_legendre(7)) {
        assert!((a.0 - b.0).abs() < 1e-15 && (a.1 - b.1).abs() < 1e-15);
    }
}

#[test]
fn single_terms_on_triangles_with_a_vertex_at_the_singular_point() {
    let mut worst: f64 = 0.0;
    for t in triangles() {
        let v = (0..3).find(|&i| t[i] == C).unwrap();
        let a = area(&t);
        for gamma in [-1.4, -0.9, -0.5, -0.2, 0.0, 0.2, 0.5, 1.0, 1.5, 2.0] {
            for k in [0.0, 1.0, 3.0] {
                let f = term(C, gamma, k);
                let rule = vertex_rule(&t, v, gamma, 12);
                let got: f64 = rule
                    .iter()
                    .map(|&(l1, l2, w)| {
                        let l0 = 1.0 - l1 - l2;
                        let x = [0, 1].map(|c| l0 * t[0][c] + l1 * t[1][c] + l2 * t[2][c]);
                        a * w * f(x)
                    })
                    .sum();
                let want = polar_reference(t, v, gamma, k);
                let scale = polar_reference(t, v, gamma, 0.0).abs();
                let rel = (got - want).abs() / scale;
                worst = worst.max(rel);
                assert!(
                    rel < 1e-12,
                    "gamma {gamma}, k {k}: {got:.15e} vs {want:.15e} ({rel:.1e})"
                );
            }
        }
    }
    println!("largest relative error of a single term: {worst:.2e}");
}

#[test]
fn single_terms_on_a_segment_from_the_singular_point() {
    // int_0^L s^gamma ds = L^(gamma+1) / (gamma + 1) along Gamma_C from c.
    let (b, len) = ([C[0] + 0.07, C[1]], 0.07);
    for gamma in [-0.9, -0.8, -0.4, 0.0, 0.5, 2.0] {
        let got: f64 = segment_from(gamma, 12)
            .iter()
            .map(|&(s, w)| {
                let x = [C[0] + s * (b[0] - C[0]), C[1] + s * (b[1] - C[1])];
                len * w * (x[0] - C[0]).hypot(x[1] - C[1]).powf(gamma) * (1.0 + (x[0] - C[0]))
            })
            .sum();
        let want = len.powf(gamma + 1.0) / (gamma + 1.0) + len.powf(gamma + 2.0) / (gamma + 2.0);
        // 1e-12: r is computed from absolute coordinates near c = (0.5871, 1), as the
        // fields are (round-off 1e-16 / r at the innermost Jacobi point).
        assert!(
            ((got - want) / want).abs() < 1e-12,
            "gamma {gamma}: {got} vs {want}"
        );
    }
}

#[test]
fn a_triangle_next_to_the_singular_point_split_until_far() {
    // A triangle sharing an edge with a vertex triangle (its nearest point at 0.05 from c):
    // the split rule against the polar reference of the union minus the vertex triangle.
    let outer = [C, [C[0] + 0.2, C[1]], [C[0], C[1] + 0.2]];
    let inner = [C, [C[0] + 0.1, C[1]], [C[0], C[1] + 0.1]];
    // outer minus inner = trapezoid = two triangles.
    let t1 = [[C[0] + 0.1, C[1]], [C[0] + 0.2, C[1]], [C[0], C[1] + 0.2]];
    let t2 = [[C[0] + 0.1, C[1]], [C[0], C[1] + 0.2], [C[0], C[1] + 0.1]];
    let base = dunavant8();
    for gamma in [-1.4, -0.9, 0.2] {
        let f = term(C, gamma, 1.0);
        let want = polar_reference(outer, 0, gamma, 1.0) - polar_reference(inner, 0, gamma, 1.0);
        let mut got = 0.0;
        for t in [t1, t2] {
            for &(l1, l2, w) in &near_rule(t, C, &base, 8) {
                let l0 = 1.0 - l1 - l2;
                let x = [0, 1].map(|c| l0 * t[0][c] + l1 * t[1][c] + l2 * t[2][c]);
                got += area(&t) * w * f(x);
            }
        }
        let rel = ((got - want) / want).abs();
        assert!(rel < 1e-9, "gamma {gamma}: {got} vs {want} ({rel:.1e})");
    }
}
