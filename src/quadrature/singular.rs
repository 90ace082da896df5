//! Rules that stay exact at a point singularity c: integrands r^alpha g with r = |x - c|,
//! alpha > -2 (on a triangle) or > -1 (on a segment), and g smooth along each ray from c
//! (a polynomial in r there for the manufactured fields of `analytical::singular`).
//!
//! On a triangle with a vertex at c the rule is Gauss-Jacobi in r and Gauss-Legendre across
//! the rays: x = c + rho ((1 - tau) (P1 - c) + tau (P2 - c)), so r = rho L(tau) and
//! dA = 2|T| rho drho dtau; the weight rho^(alpha + 1) is integrated exactly by Gauss-Jacobi,
//! and L(tau)^alpha g is smooth in tau (tau parametrizes the angle: "Gauss in theta"). A
//! Duffy transform with Gauss-Legendre in rho would leave rho^(alpha + 1), still singular
//! for alpha < -1. An integrand that mixes powers of r is split by the caller, one rule per
//! power ([`vertex_rule`]'s weights carry r^-alpha so that the rule applies to the integrand
//! itself).
//!
//! Triangles near c but not touching it are split into four recursively until each piece is
//! at least six of its diameters from c ([`near_rule`]): the integrand is smooth there but
//! steep, r^alpha at a distance comparable to the triangle's size.
//!
//! Gauss-Jacobi is written by hand (Golub-Welsch on nalgebra, already a dependency, then
//! Newton on the orthonormal recurrence): thirty lines, no new crate.

use nalgebra::{DMatrix, SymmetricEigen};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Gauss-Jacobi points and weights on [0, 1] for the weight s^b (b > -1) with `n` points:
/// sum w_i g(s_i) = int_0^1 s^b g(s) ds for polynomials g of degree <= 2n - 1.
pub fn gauss_jacobi(n: usize, b: f64) -> Vec<(f64, f64)> {
    assert!(
        b > -1.0 && (1..=40).contains(&n),
        "weight s^b with b > -1, 1 to 40 points"
    );
    // Monic recurrence of the Jacobi polynomials P^(0, b) on [-1, 1]: diagonal d_k,
    // off-diagonal e_k = sqrt(beta_k) (k >= 1), mu0 = int (1 + x)^b dx = 2^(b+1) / (b + 1).
    let d = |k: usize| {
        let k = k as f64;
        if k == 0.0 {
            b / (b + 2.0)
        } else {
            b * b / ((2.0 * k + b) * (2.0 * k + b + 2.0))
        }
    };
    let e = |k: usize| {
        let k = k as f64;
        let s = 2.0 * k + b;
        (4.0 * k * k * (k + b) * (k + b) / (s * s * (s + 1.0) * (s - 1.0))).sqrt()
    };
    let mu0 = 2f64.powf(b + 1.0) / (b + 1.0);
    let mut jacobi = DMatrix::<f64>::zeros(n, n);
    for k in 0..n {
        jacobi[(k, k)] = d(k);
        if k + 1 < n {
            jacobi[(k, k + 1)] = e(k + 1);
            jacobi[(k + 1, k)] = e(k + 1);
        }
    }
    let eig = SymmetricEigen::new(jacobi);
    // p_0 .. p_n orthonormal at x, p_{k+1} e_{k+1} = (x - d_k) p_k - e_k p_{k-1}, and
    // their derivatives (the recurrence differentiated).
    let orthonormal = |x: f64| {
        let (mut p, mut dp) = (vec![1.0 / mu0.sqrt()], vec![0.0]);
        for k in 0..n {
            let (pp, dpp) = if k == 0 {
                (0.0, 0.0)
            } else {
                (e(k) * p[k - 1], e(k) * dp[k - 1])
            };
            p.push(((x - d(k)) * p[k] - pp) / e(k + 1));
            dp.push((p[k] + (x - d(k)) * dp[k] - dpp) / e(k + 1));
        }
        (p, dp)
    };
    let mut rule: Vec<(f64, f64)> = eig
        .eigenvalues
        .iter()
        .map(|&x0| {
            // Newton on p_n.
            let mut x = x0;
            for _ in 0..3 {
                let (p, dp) = orthonormal(x);
                if dp[n] != 0.0 {
                    x -= p[n] / dp[n];
                }
            }
            // Christoffel: w = 1 / sum_{k < n} p_k(x)^2 for the weight (1 + x)^b on [-1, 1];
            // on [0, 1] with s^b the weights scale by 2^-(b+1).
            let (p, _) = orthonormal(x);
            let w = 1.0 / p[..n].iter().map(|v| v * v).sum::<f64>();
            (0.5 * (1.0 + x), w * 2f64.powf(-(b + 1.0)))
        })
        .collect();
    rule.sort_by(|a, b| a.0.total_cmp(&b.0));
    rule
}

/// Points per direction of the singular rules (Gauss-Jacobi in r, Gauss-Legendre across):
/// measured, r^gamma cos(k theta) on the test triangles to <= 1e-14 relative with 12.
pub const SINGULAR_POINTS: usize = 12;

/// How finely the rules at a singular point resolve it: Gauss-Jacobi points per direction,
/// and how [`near_rule`] splits the triangles near the point: at most `near_depth` times,
/// until each piece is `near_ratio` of its diameters from the point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Accuracy {
    /// Points per direction of [`vertex_rule`] and [`segment_from`].
    pub points: usize,
    /// Times [`near_rule`] may split a triangle near the point.
    pub near_depth: usize,
    /// Diameters from the point beyond which a piece is no longer split.
    pub near_ratio: usize,
}

impl Accuracy {
    /// What every study uses: [`SINGULAR_POINTS`], [`NEAR_DEPTH`] and [`NEAR_RATIO`].
    pub const DEFAULT: Accuracy = Accuracy {
        points: SINGULAR_POINTS,
        near_depth: NEAR_DEPTH,
        near_ratio: NEAR_RATIO,
    };
}

/// [`near_rule`]'s default distance: pieces are split until six of their diameters from
/// the point. Measured on regularity-unaligned-0.75 at level 1 against a split to 16
/// diameters: at 2 the load moved by 2.4e-8 of its largest entry and the error integrals
/// by 1.1e-7 (an independent integration of that load agreed on the 2.4e-8); at 6, 6.9e-13
/// and 5.6e-9 (tests/test_unaligned_integrals.rs).
pub const NEAR_RATIO: usize = 6;

static POINTS: AtomicUsize = AtomicUsize::new(SINGULAR_POINTS);
static DEPTH: AtomicUsize = AtomicUsize::new(NEAR_DEPTH);
static RATIO: AtomicUsize = AtomicUsize::new(NEAR_RATIO);

/// The accuracy the load and error integrals use now ([`Accuracy::DEFAULT`] unless
/// [`set_accuracy`] changed it).
pub fn accuracy() -> Accuracy {
    Accuracy {
        points: POINTS.load(Ordering::Relaxed),
        near_depth: DEPTH.load(Ordering::Relaxed),
        near_ratio: RATIO.load(Ordering::Relaxed),
    }
}

/// Change the accuracy of every singular rule in this process: for checking that the
/// integrals do not move when it is raised (the load cache keys on it). Process-wide, so
/// a test that sets it runs alone in its binary.
pub fn set_accuracy(a: Accuracy) {
    assert!((1..=40).contains(&a.points), "1 to 40 points");
    POINTS.store(a.points, Ordering::Relaxed);
    DEPTH.store(a.near_depth, Ordering::Relaxed);
    RATIO.store(a.near_ratio, Ordering::Relaxed);
}

/// A rule for the triangle `t` whose vertex `v` (0, 1 or 2) is the singular point, for
/// integrands r^alpha g (g smooth along rays, alpha > -2): barycentric pairs (l1, l2) of `t`
/// and weights to be multiplied by the area, with r^-alpha folded in, so that
/// `area * sum w F(x)` integrates F = r^alpha g itself. Exact in r for g a polynomial of
/// degree <= 2n - 1 along each ray; across the rays, n Gauss points on each of the
/// sub-wedges of at most pi/6 (L(tau)^alpha is analytic but varies faster the wider the
/// angle: measured, one 12-point rule over an angle of 2.2 rad was off by 5e-7).
pub fn vertex_rule(t: &[[f64; 2]; 3], v: usize, alpha: f64, n: usize) -> Vec<(f64, f64, f64)> {
    assert!(
        alpha > -2.0,
        "r^alpha is integrable on a triangle only for alpha > -2"
    );
    let radial = gauss_jacobi(n, alpha + 1.0);
    let across = super::gauss_legendre(n);
    let (i1, i2) = ((v + 1) % 3, (v + 2) % 3);
    let (a, b) = (
        [t[i1][0] - t[v][0], t[i1][1] - t[v][1]],
        [t[i2][0] - t[v][0], t[i2][1] - t[v][1]],
    );
    let angle = (a[0] * b[1] - a[1] * b[0])
        .abs()
        .atan2(a[0] * b[0] + a[1] * b[1]);
    let wedges = (angle / (std::f64::consts::PI / 6.0)).ceil().max(1.0) as usize;
    let mut rule = Vec::with_capacity(n * n * wedges);
    for k in 0..wedges {
        let (t0, dt) = (k as f64 / wedges as f64, 1.0 / wedges as f64);
        for &(rho, wr) in &radial {
            for &(s, wt) in &across {
                let tau = t0 + s * dt;
                // Barycentric coordinates: (1 - rho) at v, rho (1 - tau) at i1, rho tau at i2.
                let mut lam = [0.0; 3];
                lam[v] = 1.0 - rho;
                lam[i1] = rho * (1.0 - tau);
                lam[i2] = rho * tau;
                // 2|T| rho^(alpha+1) drho dtau / |T|; F / (rho^alpha L^alpha) = g, and
                // L^alpha g is the smooth factor across: r^-alpha leaves rho^-alpha.
                rule.push((lam[1], lam[2], 2.0 * wr * wt * dt * rho.powf(-alpha)));
            }
        }
    }
    rule
}

/// The index of the vertex of `t` at `c` (within 1e-12 of the triangle's size), if any.
pub fn vertex_at(t: &[[f64; 2]; 3], c: [f64; 2]) -> Option<usize> {
    let size = diameter(t);
    (0..3).find(|&i| (t[i][0] - c[0]).hypot(t[i][1] - c[1]) <= 1e-12 * size)
}

fn diameter(t: &[[f64; 2]; 3]) -> f64 {
    (0..3)
        .map(|i| {
            let j = (i + 1) % 3;
            (t[i][0] - t[j][0]).hypot(t[i][1] - t[j][1])
        })
        .fold(0.0, f64::max)
}

/// Distance from `c` to the triangle `t` (0 inside).
fn distance(t: &[[f64; 2]; 3], c: [f64; 2]) -> f64 {
    let full = super::twice_area(t);
    let inside = (0..3).all(|i| super::twice_area(&[t[i], t[(i + 1) % 3], c]) * full >= 0.0);
    if inside {
        return 0.0;
    }
    (0..3)
        .map(|i| {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            let ab = [b[0] - a[0], b[1] - a[1]];
            let s = (((c[0] - a[0]) * ab[0] + (c[1] - a[1]) * ab[1])
                / (ab[0] * ab[0] + ab[1] * ab[1]))
                .clamp(0.0, 1.0);
            (a[0] + s * ab[0] - c[0]).hypot(a[1] + s * ab[1] - c[1])
        })
        .fold(f64::INFINITY, f64::min)
}

/// Whether the triangle `t` is closer to `c` than `ratio` of its diameters: near enough for
/// [`near_rule`] to split it.
fn is_within(t: &[[f64; 2]; 3], c: [f64; 2], ratio: usize) -> bool {
    distance(t, c) < ratio as f64 * diameter(t)
}

/// `base` (a rule of the reference triangle, weights summing to 1) on the pieces of `t`
/// split into four recursively until each piece is at least [`NEAR_RATIO`] of its diameters from `c`
/// (at most `depth` times), as barycentric pairs of `t` and weights summing to 1.
pub fn near_rule(
    t: [[f64; 2]; 3],
    c: [f64; 2],
    base: &[(f64, f64, f64)],
    depth: usize,
) -> Vec<(f64, f64, f64)> {
    near_rule_within(t, c, base, depth, NEAR_RATIO)
}

/// [`near_rule`] splitting until each piece is `ratio` of its diameters from `c`.
pub fn near_rule_within(
    t: [[f64; 2]; 3],
    c: [f64; 2],
    base: &[(f64, f64, f64)],
    depth: usize,
    ratio: usize,
) -> Vec<(f64, f64, f64)> {
    // Pieces in barycentric coordinates (l1, l2) of t, with their area fraction.
    let mut out = Vec::new();
    let to_x = |l: [f64; 2]| {
        let l0 = 1.0 - l[0] - l[1];
        [0, 1].map(|k| l0 * t[0][k] + l[0] * t[1][k] + l[1] * t[2][k])
    };
    let mut stack = vec![([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], 1.0, 0usize)];
    while let Some((p, fraction, level)) = stack.pop() {
        let x = p.map(to_x);
        if level < depth && is_within(&x, c, ratio) {
            let mid = |a: [f64; 2], b: [f64; 2]| [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
            let (m01, m12, m20) = (mid(p[0], p[1]), mid(p[1], p[2]), mid(p[2], p[0]));
            for child in [
                [p[0], m01, m20],
                [m01, p[1], m12],
                [m20, m12, p[2]],
                [m12, m20, m01],
            ] {
                stack.push((child, 0.25 * fraction, level + 1));
            }
            continue;
        }
        for &(l1, l2, w) in base {
            let l0 = 1.0 - l1 - l2;
            let l = [0, 1].map(|k| l0 * p[0][k] + l1 * p[1][k] + l2 * p[2][k]);
            out.push((l[0], l[1], w * fraction));
        }
    }
    out
}

/// A rule on the segment c -> b (c the singular point) for integrands r^alpha g, alpha > -1:
/// (s, w) with s in [0, 1] the position from c and weights with r^-alpha folded in, to be
/// multiplied by the length: `len * sum w F(c + s (b - c))` integrates F = r^alpha g (exact
/// for g a polynomial of degree <= 2n - 1).
pub fn segment_from(alpha: f64, n: usize) -> Vec<(f64, f64)> {
    gauss_jacobi(n, alpha)
        .into_iter()
        .map(|(s, w)| (s, w * s.powf(-alpha)))
        .collect()
}

/// Depth of [`near_rule`]'s split in [`rules`] (a triangle next to c ends in pieces 1/256
/// of its size: measured, r^-1.4 on them to 1e-9 relative).
pub const NEAR_DEPTH: usize = 8;

/// The pieces of `t` that have a vertex at `c` when `c` lies in `t` (on an edge or inside)
/// but is none of its vertices: the triangles (c, t_i, t_i+1) of non-zero area, as the
/// barycentric coordinates in `t` of their three vertices (c first) and their area
/// fractions. None where `c` lies outside `t`.
pub fn split_at(t: &[[f64; 2]; 3], c: [f64; 2]) -> Option<Vec<([[f64; 3]; 3], f64)>> {
    let full = super::twice_area(t);
    // Barycentric coordinates of c: the sub-areas opposite each vertex.
    let lam: [f64; 3] =
        [0, 1, 2].map(|i| super::twice_area(&[c, t[(i + 1) % 3], t[(i + 2) % 3]]) / full);
    const TOL: f64 = 1e-12;
    if lam.iter().any(|&l| l < -TOL) {
        return None;
    }
    let unit = |i: usize| {
        let mut e = [0.0; 3];
        e[i] = 1.0;
        e
    };
    Some(
        (0..3)
            .filter(|&i| lam[(i + 2) % 3] > TOL)
            .map(|i| ([lam, unit(i), unit((i + 1) % 3)], lam[(i + 2) % 3]))
            .collect(),
    )
}

/// [`vertex_rule`] on each piece of [`split_at`], as one rule of `t` (barycentric pairs of
/// `t`, weights to be multiplied by `t`'s area).
fn split_rule(
    t: &[[f64; 2]; 3],
    pieces: &[([[f64; 3]; 3], f64)],
    alpha: f64,
    n: usize,
) -> Vec<(f64, f64, f64)> {
    let mut out = Vec::new();
    for (vertices, fraction) in pieces {
        // The piece itself, so that vertex_rule's sub-wedges follow its angle at c.
        let piece =
            vertices.map(|lam| [0, 1].map(|k| (0..3).map(|a| lam[a] * t[a][k]).sum::<f64>()));
        for (l1, l2, w) in vertex_rule(&piece, 0, alpha, n) {
            let l0 = 1.0 - l1 - l2;
            let lam =
                [0, 1, 2].map(|k| l0 * vertices[0][k] + l1 * vertices[1][k] + l2 * vertices[2][k]);
            out.push((lam[1], lam[2], w * fraction));
        }
    }
    out
}

/// The rules of the triangle `t` when the integrand is singular at `point` (None: not
/// singular), each with the index into `powers` of the part it integrates:
/// - `t` has a vertex at the point: one [`vertex_rule`] per entry of `powers` (each part
///   of the split integrand r^power g, the caller's to evaluate);
/// - the point lies on an edge of `t` (or inside): `t` split there into triangles with a
///   vertex at the point ([`split_at`]), one rule per power over the pieces;
/// - `t` is near it (closer than the accuracy's `near_ratio` of its diameters): `base` on
///   [`near_rule`]'s pieces, for the whole integrand
///   (None);
/// - otherwise `base` split along the `kinks` ([`super::triangle_rule`]), None.
///
/// The points per direction and the near split's depth and distance are [`accuracy`]'s.
pub fn rules<'b, K: Fn([f64; 2]) -> f64>(
    t: [[f64; 2]; 3],
    kinks: &[K],
    base: &'b [(f64, f64, f64)],
    point: Option<[f64; 2]>,
    powers: &[f64],
) -> Vec<(Option<usize>, std::borrow::Cow<'b, [(f64, f64, f64)]>)> {
    use std::borrow::Cow;
    let Some(c) = point else {
        return vec![(None, super::triangle_rule(t, kinks, base))];
    };
    let accuracy = accuracy();
    if let Some(v) = vertex_at(&t, c) {
        return powers
            .iter()
            .enumerate()
            .map(|(i, &a)| (Some(i), Cow::Owned(vertex_rule(&t, v, a, accuracy.points))))
            .collect();
    }
    if let Some(pieces) = split_at(&t, c) {
        return powers
            .iter()
            .enumerate()
            .map(|(i, &a)| {
                (
                    Some(i),
                    Cow::Owned(split_rule(&t, &pieces, a, accuracy.points)),
                )
            })
            .collect();
    }
    if is_within(&t, c, accuracy.near_ratio) {
        let rule = near_rule_within(t, c, base, accuracy.near_depth, accuracy.near_ratio);
        return vec![(None, Cow::Owned(rule))];
    }
    vec![(None, super::triangle_rule(t, kinks, base))]
}
