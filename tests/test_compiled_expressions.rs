//! Reference: exmex 0.20's evaluator (the interpreter the compiled programs replace).
//! Goal: every expression of every committed scene (displacements, gradients, stresses,
//! body forces, pressures, the singular parts, tractions) evaluates through its compiled
//! program to what exmex computes, to round-off: common subexpressions, integer powers as
//! products and quarter powers from one fourth root change the rounding, not the value.
//! Geometry: 400 points of [-0.2, 1.2] x [-0.2, 2.2] (both bodies and past them), t in
//! (0, 1].
//! Data: every scenes/*.toml.

use contact_rates::expr::Expr;
use contact_rates::scene::Scene;

fn fields(scene: &Scene) -> Vec<&Expr> {
    let mut out: Vec<&Expr> = Vec::new();
    for body in &scene.bodies {
        if let Some(f) = &body.body_force {
            out.extend(f.0.iter());
        }
    }
    for tr in &scene.tractions {
        if let Some(g) = &tr.g {
            out.extend(g.0.iter());
        }
    }
    if let Some(ex) = scene.exact.as_deref() {
        out.extend(ex.displacement.iter().flatten().flatten());
        out.extend(ex.gradient.iter().flatten().flatten().flatten());
        out.extend(ex.stress.iter().flatten().flatten());
        out.extend(ex.pressure.iter());
        out.extend(ex.body_force.iter().flatten().flatten());
        out.extend(ex.source_rate.iter().flatten().flatten());
        if let Some(s) = &ex.singular {
            out.extend(s.displacement.iter().flatten());
            out.extend(s.smooth.iter().flatten());
            out.extend(s.gradient.iter().flatten().flatten());
            out.extend(s.stress.iter().flatten());
            out.extend(s.body_force.iter().flatten());
        }
    }
    out
}

/// Deterministic points (a linear congruential sequence).
fn points(n: usize) -> Vec<[f64; 3]> {
    let mut state: u64 = 20261127;
    let mut next = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| {
            [
                -0.2 + 1.4 * next(),
                -0.2 + 2.4 * next(),
                1e-3 + (1.0 - 1e-3) * next(),
            ]
        })
        .collect()
}

#[test]
fn compiled_programs_agree_with_exmex_on_every_scene() {
    let pts = points(400);
    let mut checked = 0;
    let mut worst: f64 = 0.0;
    for entry in std::fs::read_dir("scenes").unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let scene = Scene::load(path.to_str().unwrap()).unwrap();
        let exprs = fields(&scene);
        let size_of = |e: &Expr| {
            pts.iter()
                .map(|p| e.eval_interpreted(p[0], p[1], p[2]))
                .filter(|v| v.is_finite())
                .fold(0.0f64, |m, v| m.max(v.abs()))
        };
        let scene_size = exprs.iter().map(|e| size_of(e)).fold(0.0f64, f64::max);
        for e in exprs {
            assert!(
                e.is_compiled(),
                "{}: '{}' was not compiled",
                path.display(),
                e.text
            );
            let interpreted: Vec<f64> = pts
                .iter()
                .map(|p| e.eval_interpreted(p[0], p[1], p[2]))
                .collect();
            let compiled: Vec<f64> = pts.iter().map(|p| e.eval(p[0], p[1], p[2])).collect();
            // Relative to the field's size over the points: a derived field's value near a
            // zero is a difference of large terms, rounded differently. A field that is
            // zero up to round-off (a time derivative of a term linear in t, minus its
            // elastic part) is measured against 1e-4 of the scene's largest field (its terms' size).
            let size = size_of(e).max(1e-4 * scene_size);
            for (i, (a, b)) in interpreted.iter().zip(&compiled).enumerate() {
                if !a.is_finite() {
                    assert!(
                        !b.is_finite() || a.is_nan() && b.is_nan(),
                        "{}: '{}' at {:?}: exmex {a}, compiled {b}",
                        path.display(),
                        e.text,
                        pts[i]
                    );
                    continue;
                }
                let off = (a - b).abs() / size.max(f64::MIN_POSITIVE);
                worst = worst.max(off);
                assert!(
                    off <= 1e-11,
                    "{}: '{}' at {:?}: exmex {a}, compiled {b} ({off:.1e} of its size {size:.3e})",
                    path.display(),
                    e.text,
                    pts[i]
                );
            }
            checked += 1;
        }
    }
    println!("{checked} expressions, largest difference {worst:.2e} of the field's size");
    assert!(checked > 100, "only {checked} expressions found");
}

/// Reference: the regularity family's exact solution (src/analytical/singular.rs): r^beta
/// Phi(theta) at c = (0.5871, 1), written with powers (r^2)^(k/4).
/// Goal: the body force of `regularity-1.50` (five fractional powers of r^2 after two
/// differentiations) compiled with its two components together takes the fourth root of
/// one base, r^2, once: two square roots for both components, every power a product of it.
/// Data: scenes/regularity-1.50.toml, body 1.
#[test]
fn regularity_body_force_takes_one_fourth_root() {
    let scene = Scene::load("regularity-1.50").unwrap();
    let f = &scene.exact.as_ref().unwrap().body_force.as_ref().unwrap()[0];
    let together = contact_rates::expr::compile(&[&f[0], &f[1]]).unwrap();
    let apart: usize = f
        .iter()
        .map(|e| contact_rates::expr::compile(&[e]).unwrap().operations())
        .sum();
    println!(
        "body force of body 1: {} operations together, {apart} compiled apart, {} square roots",
        together.operations(),
        together.square_roots()
    );
    assert_eq!(together.square_roots(), 2);
    assert!(
        together.operations() < apart,
        "the components share no work"
    );
}
