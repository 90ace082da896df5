//! L2(Gamma_C) integrals of a pressure on one straight piece: the difference of a discrete
//! profile to it, and its best approximation (L2 projection) in a profile's space, for any
//! pressure that gives a rule on each segment ([`SegmentPressure`]: the exact solution's,
//! with Gauss-Jacobi rules from a singular point; or a closed form in a test).

use super::exact_error::Split;
use super::field::PressureSpace;

/// A pressure along a straight piece of Gamma_C, as the L2 integrals read it.
pub trait SegmentPressure {
    /// The quadrature of one segment a -> b: `visit(q, w, p, p_s, part)` at each point
    /// a + q (b - a), w its weight times the length, p the pressure and p_s its singular
    /// part there, `part` which part of a product the rule takes ([`Split`]; `Whole` away
    /// from a singular point).
    fn segment_points(
        &self,
        xa: [f64; 2],
        xb: [f64; 2],
        visit: &mut dyn FnMut(f64, f64, f64, f64, Split),
    );
    /// The point where the pressure is singular, if any: a segment with it inside is
    /// integrated in two parts either side of it.
    fn singular_point(&self) -> Option<[f64; 2]>;
}

/// (||p_h - p||^2, ||p||^2) over one piece added to `sums` (one running sum over Gamma_C),
/// p_h linear between the profile's points (a jump where two points share a position).
pub fn piece_difference(
    p: &dyn SegmentPressure,
    profile: &[([f64; 2], f64)],
    (mut diff, mut norm): (f64, f64),
) -> (f64, f64) {
    for w in profile.windows(2) {
        let ((xa, pa), (xb, pb)) = (w[0], w[1]);
        if xa == xb {
            continue; // a jump of a piecewise-constant pressure: no length
        }
        // A segment with the singular point inside is split there (p_h linear).
        for ((a, ya), (b, yb)) in split_at(p.singular_point(), xa, xb) {
            let value = |q: f64| match q {
                0.0 => pa,
                1.0 => pb,
                _ => pa + q * (pb - pa),
            };
            let (pa_, pb_) = (value(a), value(b));
            p.segment_points(ya, yb, &mut |q, w, exact, ps, part| {
                let ph = pa_ + q * (pb_ - pa_);
                diff += w * part.square(ph - exact, -ps);
                norm += part.weighted_square(w, exact, ps);
            });
        }
    }
    (diff, norm)
}

/// The values at `points` (in order along the piece) of the L2 projection of `p` onto
/// `space`: for `Linear`, the continuous piecewise-linear functions on the points (the mass
/// matrix of the hat functions against the moments int p phi_i); for `ConstantOnPairs`, the
/// mean of p over each consecutive pair's interval (both points of a pair get it).
pub fn piece_projection(
    p: &dyn SegmentPressure,
    points: &[[f64; 2]],
    space: PressureSpace,
) -> Vec<f64> {
    match space {
        PressureSpace::Linear => project_on_hats(points, |a, b| moments(p, a, b)),
        PressureSpace::ConstantOnPairs => points
            .chunks(2)
            .flat_map(|pair| {
                let (a, b) = (pair[0], pair[pair.len() - 1]);
                let len = (b[0] - a[0]).hypot(b[1] - a[1]);
                let m = moments(p, a, b);
                let mean = if len > 0.0 { (m[0] + m[1]) / len } else { 0.0 };
                vec![mean; pair.len()]
            })
            .collect(),
    }
}

/// (int p (1 - q), int p q) over the segment a -> b, q the fraction along it.
fn moments(p: &dyn SegmentPressure, a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    let mut m = [0.0; 2];
    for ((q0, ya), (q1, yb)) in split_at(p.singular_point(), a, b) {
        p.segment_points(ya, yb, &mut |q, w, value, ps, part| {
            let g = q0 + q * (q1 - q0);
            m[0] += w * part.product((value, ps), (1.0 - g, 0.0));
            m[1] += w * part.product((value, ps), (g, 0.0));
        });
    }
    m
}

/// The point a + q (b - a).
pub fn along(a: [f64; 2], b: [f64; 2], q: f64) -> [f64; 2] {
    [a[0] + q * (b[0] - a[0]), a[1] + q * (b[1] - a[1])]
}

/// The segment a -> b as (fraction, point) pairs of its parts' ends: itself, or its two
/// parts either side of `singular` where that lies inside it.
#[allow(clippy::type_complexity)]
fn split_at(
    singular: Option<[f64; 2]>,
    xa: [f64; 2],
    xb: [f64; 2],
) -> Vec<((f64, [f64; 2]), (f64, [f64; 2]))> {
    match singular.and_then(|c| interior_fraction(xa, xb, c).map(|q| (q, c))) {
        Some((q, c)) => vec![((0.0, xa), (q, c)), ((q, c), (1.0, xb))],
        None => vec![((0.0, xa), (1.0, xb))],
    }
}

/// Where `c` lies strictly inside the segment a -> b (within 1e-12 of its length of the
/// segment, more than that from both ends): its fraction along the segment.
fn interior_fraction(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> Option<f64> {
    let ab = [b[0] - a[0], b[1] - a[1]];
    let len2 = ab[0] * ab[0] + ab[1] * ab[1];
    let q = ((c[0] - a[0]) * ab[0] + (c[1] - a[1]) * ab[1]) / len2;
    let off = (a[0] + q * ab[0] - c[0]).hypot(a[1] + q * ab[1] - c[1]);
    let tol = 1e-12;
    (off <= tol * len2.sqrt() && q > tol && q < 1.0 - tol).then_some(q)
}

/// The coefficients of the L2 projection onto the continuous piecewise-linear functions on
/// the points `x` (in order along a straight piece), given each segment's moments
/// `moments(a, b)` = (int p (1 - q), int p q): the mass matrix is tridiagonal (L/3 on the
/// diagonal, L/6 beside it, per segment of length L), solved by the Thomas algorithm by
/// hand (a few lines; the matrix is SPD and diagonally dominant, so no pivoting is needed).
fn project_on_hats(x: &[[f64; 2]], moments: impl Fn([f64; 2], [f64; 2]) -> [f64; 2]) -> Vec<f64> {
    let n = x.len();
    let segments = n.saturating_sub(1);
    let (mut diag, mut off, mut rhs) = (vec![0.0; n], vec![0.0; segments], vec![0.0; n]);
    for k in 0..segments {
        let len = (x[k + 1][0] - x[k][0]).hypot(x[k + 1][1] - x[k][1]);
        diag[k] += len / 3.0;
        diag[k + 1] += len / 3.0;
        off[k] = len / 6.0;
        let m = moments(x[k], x[k + 1]);
        rhs[k] += m[0];
        rhs[k + 1] += m[1];
    }
    for k in 1..n {
        let f = off[k - 1] / diag[k - 1];
        diag[k] -= f * off[k - 1];
        rhs[k] -= f * rhs[k - 1];
    }
    let mut c = vec![0.0; n];
    for k in (0..n).rev() {
        let next = if k + 1 < n { off[k] * c[k + 1] } else { 0.0 };
        c[k] = (rhs[k] - next) / diag[k];
    }
    c
}
