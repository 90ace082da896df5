//! Quadrature of any order on segments and triangles, for integrals of non-polynomial
//! (exact) fields: Gauss-Legendre on a segment, and on a triangle the collapsed
//! (Duffy) product of two Gauss-Legendre rules.
//!
//! Written by hand: the rules are twenty lines, and the crates that offer them fix the
//! order at compile time or pull in a linear-algebra stack for the Golub-Welsch solve.

pub mod singular;

use std::borrow::Cow;

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

/// Gauss points per direction of the rules that measure errors against an exact solution
/// (16 points per triangle, exact to degree 6; 8 points per segment, exact to degree 15).
pub const DEFAULT_POINTS: usize = 4;

/// Dunavant's symmetric 16-point rule of degree 8 on the reference triangle (IJNME 21,
/// 1985, 1129-1148), as [`triangle`]'s (l1, l2, weight) with weights summing to 1: the
/// loads' rule. The 16 points of the collapsed rule reach only degree 6; measured on the
/// load of `contact-mms` at level 1 against a degree-22 integration, their 6e-12 relative
/// error (the sine terms) drops to round-off with degree 8. Tested on every monomial of
/// degree <= 8 against its closed form.
pub fn dunavant8() -> Vec<(f64, f64, f64)> {
    // (weight, barycentric orbit generator): one centroid, three (a, b, b) orbits, one
    // (a, b, c) orbit of six.
    let mut rule = vec![(1.0 / 3.0, 1.0 / 3.0, 0.144_315_607_677_787)];
    for (w, a, b) in [
        (
            0.095_091_634_267_285,
            0.081_414_823_414_554,
            0.459_292_588_292_723,
        ),
        (
            0.103_217_370_534_718,
            0.658_861_384_496_480,
            0.170_569_307_751_760,
        ),
        (
            0.032_458_497_623_198,
            0.898_905_543_365_938,
            0.050_547_228_317_031,
        ),
    ] {
        rule.extend([(a, b, w), (b, a, w), (b, b, w)]);
    }
    let (w, a, b, c) = (
        0.027_230_314_174_435,
        0.008_394_777_409_958,
        0.263_112_829_634_638,
        0.728_492_392_955_404,
    );
    rule.extend([
        (a, b, w),
        (b, a, w),
        (a, c, w),
        (c, a, w),
        (b, c, w),
        (c, b, w),
    ]);
    rule
}

/// A kink of a piecewise field: a function whose sign tells the branch, so the field is
/// smooth where it keeps its sign (the argument z of an `abs(z)`). The rules below take any
/// `Fn([f64; 2]) -> f64`; this is the object form.
pub type Kink<'a> = dyn Fn([f64; 2]) -> f64 + 'a;

/// Relative size below which a kink function counts as zero at a vertex (the vertex lies on
/// the kink line: it cuts nothing there).
const ON_KINK: f64 = 1e-12;

fn sign(z: f64, scale: f64) -> i8 {
    if z.abs() <= ON_KINK * scale {
        0
    } else if z > 0.0 {
        1
    } else {
        -1
    }
}

/// The point of the segment a -> b where `z` vanishes, given z(a) > 0 > z(b) or the reverse.
/// Exact (one evaluation to confirm) where z is affine along the segment; otherwise the
/// Illinois variant of regula falsi to round-off.
fn zero_on_segment(a: [f64; 2], b: [f64; 2], za: f64, zb: f64, z: impl Fn([f64; 2]) -> f64) -> f64 {
    let at = |s: f64| z([a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])]);
    let scale = za.abs().max(zb.abs());
    let (mut s0, mut s1, mut z0, mut z1) = (0.0, 1.0, za, zb);
    let mut side = 0i8;
    for _ in 0..200 {
        let s = (s0 * z1 - s1 * z0) / (z1 - z0);
        let zs = at(s);
        if zs.abs() <= 1e-15 * scale || (s1 - s0).abs() <= 1e-15 {
            return s;
        }
        if (zs > 0.0) == (z0 > 0.0) {
            (s0, z0) = (s, zs);
            if side == -1 {
                z1 *= 0.5;
            }
            side = -1;
        } else {
            (s1, z1) = (s, zs);
            if side == 1 {
                z0 *= 0.5;
            }
            side = 1;
        }
    }
    0.5 * (s0 + s1)
}

/// Twice the signed area of a triangle.
fn twice_area(p: &[[f64; 2]; 3]) -> f64 {
    (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1])
}

/// The triangle `t` cut along the zero line of every kink, as sub-triangles on each of which
/// every kink keeps one sign. A kink cuts a (sub-)triangle where its vertices' signs differ;
/// the cut runs between the zeros on the edges, found exactly where the kink is affine
/// (every built-in scene: x - a) and to round-off otherwise. Where a kink is not affine its
/// zero line is curved and the straight cut between the edge zeros leaves a sliver of
/// width O(h^2 |curvature|) on the wrong side; a kink that enters and leaves through the
/// same edge (signs equal at the vertices) is not seen. Both vanish as the mesh is refined.
pub fn split_triangle<K: Fn([f64; 2]) -> f64>(t: [[f64; 2]; 3], kinks: &[K]) -> Vec<[[f64; 2]; 3]> {
    let full = twice_area(&t).abs();
    let mut pieces = vec![t];
    for z in kinks {
        let mut next = Vec::with_capacity(pieces.len() + 2);
        for p in pieces {
            let v = p.map(|x| z(x));
            let scale = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let s = v.map(|x| sign(x, scale));
            if !(s.contains(&1) && s.contains(&-1)) {
                next.push(p);
                continue;
            }
            // Walk the edges: each side's polygon gets its vertices and the edge zeros.
            let (mut plus, mut minus) = (Vec::with_capacity(4), Vec::with_capacity(4));
            for i in 0..3 {
                let j = (i + 1) % 3;
                if s[i] >= 0 {
                    plus.push(p[i]);
                }
                if s[i] <= 0 {
                    minus.push(p[i]);
                }
                if s[i] * s[j] == -1 {
                    let r = zero_on_segment(p[i], p[j], v[i], v[j], z);
                    let c = [
                        p[i][0] + r * (p[j][0] - p[i][0]),
                        p[i][1] + r * (p[j][1] - p[i][1]),
                    ];
                    plus.push(c);
                    minus.push(c);
                }
            }
            // Each side is convex (a triangle or a quadrilateral): a fan triangulates it.
            for poly in [plus, minus] {
                for k in 1..poly.len().saturating_sub(1) {
                    let tri = [poly[0], poly[k], poly[k + 1]];
                    if twice_area(&tri).abs() > 1e-14 * full {
                        next.push(tri);
                    }
                }
            }
        }
        pieces = next;
    }
    pieces
}

/// A rule for the triangle with vertices `t`, as barycentric pairs (l1, l2) of `t` and
/// weights summing to 1 (to be multiplied by the area): `base` (a rule of the reference
/// triangle, as [`triangle`]) where no kink crosses `t`, and `base` on every piece of
/// [`split_triangle`] otherwise. On each piece the integrand is as smooth as the field's
/// branches, so the rule keeps `base`'s degree of exactness: with [`triangle`]`(n)`,
/// polynomials of degree 2n - 2 on each side of an affine kink, whatever jumps across it.
pub fn triangle_rule<'b, K: Fn([f64; 2]) -> f64>(
    t: [[f64; 2]; 3],
    kinks: &[K],
    base: &'b [(f64, f64, f64)],
) -> Cow<'b, [(f64, f64, f64)]> {
    let pieces = split_triangle(t, kinks);
    if pieces.len() == 1 {
        return Cow::Borrowed(base);
    }
    let full = twice_area(&t);
    // Barycentric (l1, l2) of a point of t: the areas of the sub-triangles opposite.
    let bary = |x: [f64; 2]| {
        (
            twice_area(&[t[0], x, t[2]]) / full,
            twice_area(&[t[0], t[1], x]) / full,
        )
    };
    let mut rule = Vec::with_capacity(pieces.len() * base.len());
    for q in &pieces {
        let fraction = (twice_area(q) / full).abs();
        for &(l1, l2, w) in base {
            let l0 = 1.0 - l1 - l2;
            let x = [0, 1].map(|c| l0 * q[0][c] + l1 * q[1][c] + l2 * q[2][c]);
            let (b1, b2) = bary(x);
            rule.push((b1, b2, w * fraction));
        }
    }
    Cow::Owned(rule)
}

/// The parameters in (0, 1) where a kink crosses the segment a -> b (sorted): the segment's
/// smooth pieces lie between them. Exact for affine kinks; a kink whose sign is the same at
/// both ends is not seen (as in [`split_triangle`]).
pub fn segment_breaks<K: Fn([f64; 2]) -> f64>(a: [f64; 2], b: [f64; 2], kinks: &[K]) -> Vec<f64> {
    let mut out = Vec::new();
    for z in kinks {
        let (za, zb) = (z(a), z(b));
        let scale = za.abs().max(zb.abs());
        if sign(za, scale) * sign(zb, scale) == -1 {
            out.push(zero_on_segment(a, b, za, zb, z));
        }
    }
    out.sort_by(f64::total_cmp);
    out
}

/// A rule for the segment a -> b as (s, w), s in [0, 1] and weights summing to 1: `base` (a
/// rule of [0, 1], as [`gauss_legendre`]) on each piece between the kinks' crossings
/// ([`segment_breaks`]), so it keeps `base`'s degree on each smooth piece.
pub fn segment_rule<'b, K: Fn([f64; 2]) -> f64>(
    a: [f64; 2],
    b: [f64; 2],
    kinks: &[K],
    base: &'b [(f64, f64)],
) -> Cow<'b, [(f64, f64)]> {
    let breaks = segment_breaks(a, b, kinks);
    if breaks.is_empty() {
        return Cow::Borrowed(base);
    }
    let ends: Vec<f64> = std::iter::once(0.0)
        .chain(breaks)
        .chain(std::iter::once(1.0))
        .collect();
    let mut rule = Vec::with_capacity((ends.len() - 1) * base.len());
    for w in ends.windows(2) {
        let len = w[1] - w[0];
        if len <= 1e-15 {
            continue;
        }
        rule.extend(base.iter().map(|&(s, ws)| (w[0] + s * len, ws * len)));
    }
    Cow::Owned(rule)
}
