//! Reference: issue 72 (best-approximation errors, measured); the L2 projection onto a
//! finite-dimensional space is the least-squares fit in the L2 inner product; the best
//! L2 approximation of d^gamma by constants on cells [a, b] has the closed-form error^2
//! sum (int f^2 - (int f)^2 / (b - a)), int d^g = d^(g+1) / (g + 1).
//! Goal: (1) on one level of the crossover scene (a polynomial pressure along Gamma_C, so
//! a Gauss rule integrates every product exactly) the projection that the studies measure
//! (`ExactComparison::best_pressure`: the hat functions' mass matrix against the moments,
//! or the mean per macro-element) equals a direct least-squares fit (QR of the weighted
//! sample matrix at Gauss points) to 1e-12, for mortar's space (piecewise linear on the
//! body-1 trace nodes) and lac's (constant on each macro-element); (2) the error of the
//! best piecewise-constant approximation of d^(1/4) and d^(1/2) on halving cells of [0, 1],
//! computed by the same projection and difference code, matches the closed form to 1e-9
//! relative and its successive rates to 1e-3.
//! Geometry and data: scene `crossover` (stacked blocks, level 1, newton, 1 step); the
//! segment [0, 1] x {0} with d the distance to (0, 0), cells 1/2^L, L = 0..8.

mod common;

use contact_rates::contact::Method;
use contact_rates::quadrature::{gauss_legendre, singular::segment_from};
use contact_rates::scene::Scene;
use contact_rates::solve::SolverKind;
use contact_rates::verify::exact_error::{ExactComparison, Split};
use contact_rates::verify::field::{P1Field, PressureSpace, pressure_profile};
use contact_rates::verify::pressure_l2::{SegmentPressure, piece_difference, piece_projection};
use contact_rates::verify::solve_case;
use nalgebra::{DMatrix, DVector};

/// The least-squares fit of `p` on `points` in `space`, from the weighted sample matrix at
/// `rule`'s points on every segment (pairs for constants), by QR.
fn least_squares(
    points: &[[f64; 2]],
    space: PressureSpace,
    p: &dyn Fn([f64; 2]) -> f64,
) -> Vec<f64> {
    let rule = gauss_legendre(12);
    let n = points.len();
    let (mut rows, mut rhs) = (Vec::new(), Vec::new());
    let mut sample = |a: [f64; 2], b: [f64; 2], basis: &dyn Fn(f64) -> Vec<(usize, f64)>| {
        let len = (b[0] - a[0]).hypot(b[1] - a[1]);
        for &(q, w) in &rule {
            let x = [a[0] + q * (b[0] - a[0]), a[1] + q * (b[1] - a[1])];
            let mut row = vec![0.0; n];
            for (i, v) in basis(q) {
                row[i] = (w * len).sqrt() * v;
            }
            rows.push(row);
            rhs.push((w * len).sqrt() * p(x));
        }
    };
    match space {
        PressureSpace::Linear => {
            for k in 0..n - 1 {
                sample(points[k], points[k + 1], &|q| {
                    vec![(k, 1.0 - q), (k + 1, q)]
                });
            }
        }
        PressureSpace::ConstantOnPairs => {
            for k in (0..n).step_by(2) {
                // Both points of a pair carry the one value: the column of the first.
                sample(points[k], points[k + 1], &|_| vec![(k, 1.0)]);
            }
        }
    }
    let keep: Vec<usize> = match space {
        PressureSpace::Linear => (0..n).collect(),
        PressureSpace::ConstantOnPairs => (0..n).step_by(2).collect(),
    };
    let a = DMatrix::from_fn(rows.len(), keep.len(), |r, c| rows[r][keep[c]]);
    let b = DVector::from_vec(rhs);
    let qr = a.qr();
    let x = qr
        .r()
        .solve_upper_triangular(&(qr.q().transpose() * b))
        .unwrap();
    let mut out = vec![0.0; n];
    for (c, &i) in keep.iter().enumerate() {
        out[i] = x[c];
        if space == PressureSpace::ConstantOnPairs {
            out[i + 1] = x[c];
        }
    }
    out
}

#[test]
fn the_projection_is_the_least_squares_fit_on_a_polynomial_pressure() {
    let scene = Scene::load("crossover").unwrap();
    let exact = scene.exact.as_deref().unwrap();
    let cmp = ExactComparison::new(exact, 4);
    for method in [Method::Mortar, Method::Lac] {
        let case = common::case("crossover", 1, method, &[]);
        let (sol, _) = solve_case(&case, SolverKind::Newton, 1).unwrap();
        let state = sol.last();
        let field = P1Field::of_state(&case.problem, state);
        let profile = pressure_profile(&case.problem, state);
        let interface = &case.problem.interface;
        let best = cmp.best_pressure(interface, &profile, field.pressure_space, state.time);
        for (piece, (points, projected)) in interface.pieces.iter().zip(profile.iter().zip(&best)) {
            let x: Vec<[f64; 2]> = points.iter().map(|p| p.0).collect();
            let p = |y: [f64; 2]| {
                exact
                    .pressure_at(piece.normal, y[0], y[1], state.time)
                    .unwrap()
            };
            let fit = least_squares(&x, field.pressure_space, &p);
            let scale = fit.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let worst = projected
                .iter()
                .zip(&fit)
                .map(|(a, b)| (a.1 - b).abs() / scale)
                .fold(0.0f64, f64::max);
            println!(
                "{method}: {} values, largest difference to least squares {worst:.2e} of {scale:.3e}",
                x.len()
            );
            assert!(worst < 1e-12, "{method}: {worst:e}");
        }
    }
}

/// p = d^gamma, d the distance to the origin, on the x axis: Gauss-Jacobi from the
/// origin (the whole pressure is the singular part), Gauss-Legendre elsewhere.
struct Power(f64);

impl SegmentPressure for Power {
    fn segment_points(
        &self,
        xa: [f64; 2],
        xb: [f64; 2],
        visit: &mut dyn FnMut(f64, f64, f64, f64, Split),
    ) {
        let len = (xb[0] - xa[0]).hypot(xb[1] - xa[1]);
        let at = |q: f64| xa[0] + q * (xb[0] - xa[0]);
        let g = self.0;
        if xa[0] == 0.0 {
            for (alpha, part) in [
                (0.0, Split::Smooth),
                (g, Split::Cross),
                (2.0 * g, Split::Singular),
            ] {
                for (q, w) in segment_from(alpha, 20) {
                    let p = at(q).powf(g);
                    visit(q, w * len, p, p, part);
                }
            }
        } else {
            for (q, w) in gauss_legendre(30) {
                visit(q, w * len, at(q).powf(g), 0.0, Split::Whole);
            }
        }
    }
    fn singular_point(&self) -> Option<[f64; 2]> {
        Some([0.0, 0.0])
    }
}

/// The closed-form error of the best constants for d^g on 2^level cells of [0, 1].
fn closed_form(g: f64, level: i32) -> f64 {
    let (n, h) = (1usize << level, 0.5f64.powi(level));
    let int = |p: f64, a: f64, b: f64| (b.powf(p + 1.0) - a.powf(p + 1.0)) / (p + 1.0);
    (0..n)
        .map(|k| {
            let (a, b) = (k as f64 * h, (k + 1) as f64 * h);
            int(2.0 * g, a, b) - int(g, a, b).powi(2) / h
        })
        .sum::<f64>()
        .sqrt()
}

#[test]
fn best_constants_of_a_power_on_halving_cells_follow_the_closed_form() {
    for g in [0.25, 0.5] {
        let (mut ours, mut exact) = (Vec::new(), Vec::new());
        for level in 0..=8 {
            let n = 1usize << level;
            let points: Vec<[f64; 2]> = (0..n)
                .flat_map(|k| [[k as f64 / n as f64, 0.0], [(k + 1) as f64 / n as f64, 0.0]])
                .collect();
            let values = piece_projection(&Power(g), &points, PressureSpace::ConstantOnPairs);
            let profile: Vec<([f64; 2], f64)> = points.into_iter().zip(values).collect();
            let e = piece_difference(&Power(g), &profile, (0.0, 0.0)).0.sqrt();
            let c = closed_form(g, level);
            assert!(
                (e - c).abs() <= 1e-9 * c,
                "g {g} level {level}: {e} against {c}"
            );
            ours.push(e);
            exact.push(c);
        }
        let rates =
            |e: &[f64]| -> Vec<f64> { e.windows(2).map(|w| (w[0] / w[1]).log2()).collect() };
        let (r, rc) = (rates(&ours), rates(&exact));
        println!("d^{g}: successive rates {:.4?} (closed form {:.4?})", r, rc);
        for (a, b) in r.iter().zip(&rc) {
            assert!((a - b).abs() < 1e-3, "{a} against {b}");
        }
    }
}
