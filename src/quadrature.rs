//! Quadrature of any order on segments and triangles, for integrals of non-polynomial
//! (exact) fields: Gauss-Legendre on a segment, and on a triangle the collapsed
//! (Duffy) product of two Gauss-Legendre rules.
//!
//! Written by hand: the rules are twenty lines, and the crates that offer them fix the
//! order at compile time or pull in a linear-algebra stack for the Golub-Welsch solve.

/// Gauss-Legendre points and weights on [0, 1] with `n` points (exact for polynomials of
/// degree 2n - 1). Newton's method on P_n from Tricomi's initial guesses converges to
/// round-off in a few steps for every n used here (n <= 64).
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    assert!((1..=64).contains(&n), "1 to 64 Gauss points");
    let mut rule = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            // P_n(x) and P_n'(x) by the three-term recurrence.
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let k = k as f64;
                (p0, p1) = (p1, ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k);
            }
            let pn = if n == 1 { x } else { p1 };
            let pm = if n == 1 { 1.0 } else { p0 };
            dp = n as f64 * (x * pn - pm) / (x * x - 1.0);
            let dx = pn / dp;
            x -= dx;
            if dx.abs() <= 1e-16 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        rule.push((0.5 * (1.0 - x), 0.5 * w));
    }
    rule.sort_by(|a, b| a.0.total_cmp(&b.0));
    rule
}

/// A rule on the reference triangle {(l1, l2): l1, l2 >= 0, l1 + l2 <= 1}: points as
/// barycentric pairs (l1, l2) (the third is 1 - l1 - l2) and weights summing to 1 (a mean,
/// to be multiplied by the triangle's area). With n points per direction it integrates
/// polynomials of degree 2n - 2 exactly.
pub fn triangle(n: usize) -> Vec<(f64, f64, f64)> {
    let g = gauss_legendre(n);
    let mut rule = Vec::with_capacity(n * n);
    for &(u, wu) in &g {
        for &(v, wv) in &g {
            // (u, v) in the unit square -> (u, v (1 - u)); Jacobian 1 - u; area 1/2.
            rule.push((u, v * (1.0 - u), 2.0 * wu * wv * (1.0 - u)));
        }
    }
    rule
}

/// The rule of [`triangle`] on each of the m^2 congruent sub-triangles of the reference
/// triangle (weights summing to 1): for integrands that are smooth only piecewise, such as
/// exact fields with a kink inside the triangle.
pub fn triangle_composite(n: usize, m: usize) -> Vec<(f64, f64, f64)> {
    let base = triangle(n);
    let h = 1.0 / m as f64;
    let mut rule = Vec::with_capacity(base.len() * m * m);
    for i in 0..m {
        for j in 0..m - i {
            // Upward sub-triangle (i, j), (i+1, j), (i, j+1), and the downward one beside it.
            let mut corners = vec![[[i, j], [i + 1, j], [i, j + 1]]];
            if i + j + 1 < m {
                corners.push([[i + 1, j], [i + 1, j + 1], [i, j + 1]]);
            }
            for c in corners {
                let p = c.map(|[a, b]| [a as f64 * h, b as f64 * h]);
                for &(l1, l2, w) in &base {
                    let l0 = 1.0 - l1 - l2;
                    rule.push((
                        l0 * p[0][0] + l1 * p[1][0] + l2 * p[2][0],
                        l0 * p[0][1] + l1 * p[1][1] + l2 * p[2][1],
                        w / (m * m) as f64,
                    ));
                }
            }
        }
    }
    rule
}
