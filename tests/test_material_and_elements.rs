//! Reference: SPEC section 1 (plane-stress E, Perzyna G with P_B in the E-inner product)
//! and the P1 triangle.
//! Goal: shape gradients form a partition of unity's derivative (sum to zero) and
//! reproduce linear fields; the backward-Euler update solves its equation to round-off
//! for every k (including k E / lambda = 1e4); P_B is the E-orthogonal projection; the
//! consistent tangent matches central finite differences; the return maps run side by
//! side (`Material::update_lanes`) give the bits of one at a time.
//! Data: E = 100, nu = 0.3, lambda = 100, sigma_Y = sqrt(10) unless stated.

use contact_rates::fe::p1_gradients;
use contact_rates::material::{Elasticity, LANES, Material, Stress, Viscoplasticity, von_mises};
use nalgebra::{Matrix3, Vector3};

fn material(young: f64, lambda: f64) -> Material {
    Material {
        elastic: Elasticity::plane_stress(young, 0.3),
        viscoplastic: Some(Viscoplasticity {
            lambda,
            yield_stress: 10f64.sqrt(),
        }),
    }
}

#[test]
fn p1_gradients_sum_to_zero_and_reproduce_linear_fields() {
    let tris = [
        [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
        [[0.3, -0.2], [2.0, 0.4], [-0.5, 1.7]],
        [[1e3, 1e3], [1e3 + 1e-3, 1e3], [1e3, 1e3 + 1e-6]],
    ];
    for p in tris {
        let (area, g) = p1_gradients(p);
        assert!(area > 0.0);
        let scale = g
            .iter()
            .map(|v| v[0].abs().max(v[1].abs()))
            .fold(0.0, f64::max);
        for c in 0..2 {
            let s: f64 = g.iter().map(|v| v[c]).sum();
            assert!(s.abs() <= 1e-12 * scale, "sum of d/dx{c} = {s}");
        }
        // grad of x and y: sum_a x_a grad(lambda_a) = (1, 0), (0, 1).
        for c in 0..2 {
            let gx: f64 = (0..3).map(|a| p[a][c] * g[a][0]).sum();
            let gy: f64 = (0..3).map(|a| p[a][c] * g[a][1]).sum();
            let expect = if c == 0 { (1.0, 0.0) } else { (0.0, 1.0) };
            assert!((gx - expect.0).abs() < 1e-9 && (gy - expect.1).abs() < 1e-9);
        }
    }
}

fn stresses() -> Vec<Stress> {
    vec![
        Vector3::new(0.0, -10.0, 0.0),
        Vector3::new(5.0, 1.0, 2.0),
        Vector3::new(-3.0, 4.0, -6.0),
        Vector3::new(20.0, 20.0, 0.0),
        Vector3::new(1e3, -2e3, 5e2),
        Vector3::new(1.0, 0.5, 0.1), // inside B
    ]
}

#[test]
fn plane_stress_elasticity_and_compliance_are_inverse() {
    let el = Elasticity::plane_stress(100.0, 0.3);
    // a = E nu / (1 - nu^2), b = E / (1 + nu)
    assert!((el.a() - 100.0 * 0.3 / 0.91).abs() < 1e-12);
    assert!((el.b() - 100.0 / 1.3).abs() < 1e-12);
    for s in stresses() {
        let back = el.apply(&el.compliance(&s));
        assert!((back - s).amax() < 1e-12 * s.amax());
    }
}

/// Tensor inner product a : b of [11, 22, 12] components.
fn ddot(a: &Stress, b: &Stress) -> f64 {
    a[0] * b[0] + a[1] * b[1] + 2.0 * a[2] * b[2]
}

#[test]
fn projection_is_the_e_orthogonal_projection_onto_the_von_mises_set() {
    let m = material(100.0, 100.0);
    let el = m.elastic;
    for s in stresses() {
        let p = m.project(&s);
        let y = 10f64.sqrt();
        if von_mises(&s) <= y {
            assert_eq!(p, s);
            continue;
        }
        assert!((von_mises(&p) - y).abs() < 1e-12 * y, "on the boundary");
        // Variational inequality: (s - P s, E (tau - P s)) <= 0 for tau in B (sampled).
        for k in 0..400 {
            let th = k as f64 * 0.0157;
            let ph = k as f64 * 0.731;
            let dir = Vector3::new(th.cos() * ph.cos(), th.sin() * ph.cos(), ph.sin());
            let tau = dir * (y / von_mises(&dir)) * 0.999;
            let v = ddot(&(s - p), &el.apply(&(tau - p)));
            assert!(v <= 1e-9 * s.amax() * s.amax(), "VI violated: {v}");
        }
    }
}

#[test]
fn backward_euler_update_solves_its_equation_for_every_k() {
    for (young, lambda) in [(100.0, 100.0), (3e5, 100.0), (100.0, 1000.0)] {
        let m = material(young, lambda);
        for k in [1e-6, 1e-3, 0.1, 1.0, 100.0 * lambda / young * 100.0] {
            for s in stresses() {
                let (sig, _) = m.update(&s, k);
                let res = sig - s - k * m.g(&sig);
                assert!(
                    res.amax() <= 1e-12 * s.amax(),
                    "E = {young}, k = {k}: residual {res:?}"
                );
            }
        }
    }
}

#[test]
fn consistent_tangent_matches_central_differences() {
    let m = material(100.0, 100.0);
    let el = m.elastic;
    for k in [0.01, 0.1, 1.0, 1e4] {
        for s0 in stresses() {
            // sigma(eps) = update(s0 + E eps, k); derivative at eps = 0.
            let (_, d) = m.update(&s0, k);
            let h = 1e-6 * s0.amax() / 100.0;
            let mut fd = Matrix3::zeros();
            for j in 0..3 {
                let mut e = Vector3::zeros();
                e[j] = h;
                let (sp, _) = m.update(&(s0 + el.apply(&e)), k);
                let (sm, _) = m.update(&(s0 - el.apply(&e)), k);
                fd.set_column(j, &((sp - sm) / (2.0 * h)));
            }
            let err = (fd - d).amax() / d.amax();
            assert!(
                err < 1e-6,
                "k = {k}, sigma = {s0:?}: tangent error {err:e}\n{d}\n{fd}"
            );
        }
    }
}

#[test]
fn elastic_body_pays_nothing() {
    let m = Material {
        elastic: Elasticity::plane_stress(100.0, 0.3),
        viscoplastic: None,
    };
    let s = Vector3::new(1e3, -2e3, 5e2);
    let (sig, d) = m.update(&s, 1.0);
    assert_eq!(sig, s);
    assert_eq!(d, m.elastic.matrix());
    assert_eq!(m.g(&s), Vector3::zeros());
}

#[test]
fn update_lanes_gives_the_bits_of_update() {
    // Three materials side by side (stiff, viscous, elastic), every group size up to LANES,
    // trial stresses inside and far outside the elastic set.
    let elastic = Material {
        elastic: Elasticity::plane_stress(100.0, 0.3),
        viscoplastic: None,
    };
    let materials = [material(100.0, 100.0), material(3e5, 100.0), elastic];
    let mut trials = Vec::new();
    for (i, s) in stresses().iter().enumerate() {
        for j in 0..7 {
            trials.push(s * (0.3 + 0.7 * j as f64) + Vector3::new(0.1 * i as f64, 0.0, 0.2));
        }
    }
    for k in [1e-3, 0.25, 1e4] {
        for size in 1..=LANES {
            for (g, group) in trials.chunks(size).enumerate() {
                let ms: Vec<&Material> = (0..group.len())
                    .map(|i| &materials[(g + i) % materials.len()])
                    .collect();
                let mut got = vec![None; group.len()];
                Material::update_lanes(&ms, group, k, |i, s, d| {
                    assert!(got[i].is_none(), "lane {i} written twice");
                    got[i] = Some((s, d));
                });
                for (i, s) in group.iter().enumerate() {
                    assert_eq!(
                        got[i],
                        Some(ms[i].update(s, k)),
                        "k = {k}, lane {i} of {size}"
                    );
                }
            }
        }
    }
}
