//! Reference: the method of manufactured solutions with a source in every equation the
//! chosen fields do not satisfy (Roache, "Code verification by the method of manufactured
//! solutions", J. Fluids Eng. 124 (2002); Salari and Knupp, SAND2000-1444), applied to the
//! backward-Euler Perzyna law of the paper, (2.1): with
//! s = d sigma/dt - E eps(du/dt) - G(sigma), the update
//! sigma^n = sigma^(n-1) + E (eps^n - eps^(n-1)) + k G(sigma^n) + k s(t_n)
//! holds exactly for fields affine in t.
//! Goal: (1) the exact fields of `contact-mms-vp` satisfy the time-discrete law with the
//! source at every quadrature point of a mesh to 1e-12 (relative to the stress scale), and
//! those of `contact-mms-vp-time` leave exactly the residual -k^2 c of their uniform stress
//! history c t (t - 1) in s11 (c = 200); (2) the derived body force and source equal
//! central finite differences of the fields; (3) the derived tractions sigma n balance the
//! stress: the assembled load equals the integral of sigma : eps(phi_i) at every free dof
//! off Gamma_C (the divergence theorem), to quadrature round-off; (4) the scene checks
//! refuse a viscoplastic manufactured body without a stress and a non-symmetric stress
//! tensor, with the field and the fix; (5) the quick tier of `rates-exact-vp` meets the
//! thresholds of Theorem 3.1 and its time study measures a rate in k near backward
//! Euler's 1.
//! Geometry and data: the `contact-mms-vp` scenes (two unit blocks, E1 = 100, E2 = 150,
//! nu = 0.3, lambda = 100, sigma_Y = 6 and 4), level 1.

mod common;
use contact_rates::analytical::Exact;
use contact_rates::contact::Method;
use contact_rates::expr::kink_functions;
use contact_rates::fe::FIXED;
use contact_rates::material::{Material, Stress};
use contact_rates::quadrature;
use contact_rates::scene::Scene;
use contact_rates::studies::convergence;
use contact_rates::verify::{quantity::Quantity, rates::Verdict};

/// Stress, strain (tensor components) and source of body `b` at (x, y, t).
fn fields(ex: &Exact, b: usize, m: &Material, x: f64, y: f64, t: f64) -> (Stress, Stress, Stress) {
    let g = &ex.gradient.as_ref().unwrap()[b];
    let eps = Stress::new(
        g[0][0].eval(x, y, t),
        g[1][1].eval(x, y, t),
        0.5 * (g[0][1].eval(x, y, t) + g[1][0].eval(x, y, t)),
    );
    let sigma = Stress::from(ex.stress_at(b, x, y, t).unwrap());
    let s = Stress::from(ex.source_at(b, m, x, y, t).unwrap());
    (sigma, eps, s)
}

/// Largest |residual| of the time-discrete law over every Dunavant point of every triangle
/// of the level-1 mesh and every step of `steps` uniform steps, per component, and the
/// largest stress component met (the scale).
fn law_residual(scene: &str, steps: usize) -> ([f64; 3], f64) {
    let case = common::case(scene, 1, Method::Mortar, &[]);
    let model = &case.problem.model;
    let ex = model.scene.exact.as_deref().unwrap();
    let k = model.scene.final_time / steps as f64;
    let rule = quadrature::dunavant8();
    let (mut worst, mut scale) = ([0.0f64; 3], 0.0f64);
    for e in &model.elements {
        let m = &model.materials[e.body];
        let p = e.nodes.map(|n| model.position(n));
        for &(l1, l2, _) in &rule {
            let (x, y) = (
                (1.0 - l1 - l2) * p[0][0] + l1 * p[1][0] + l2 * p[2][0],
                (1.0 - l1 - l2) * p[0][1] + l1 * p[1][1] + l2 * p[2][1],
            );
            for n in 1..=steps {
                let (t0, t1) = ((n - 1) as f64 * k, n as f64 * k);
                let (s0, e0, _) = fields(ex, e.body, m, x, y, t0);
                let (s1, e1, src) = fields(ex, e.body, m, x, y, t1);
                let r = s1 - (s0 + m.elastic.apply(&(e1 - e0)) + k * m.g(&s1) + k * src);
                for c in 0..3 {
                    worst[c] = worst[c].max(r[c].abs());
                }
                scale = scale.max(s1.amax());
            }
        }
    }
    (worst, scale)
}

#[test]
fn fields_affine_in_t_satisfy_the_time_discrete_law_at_every_quadrature_point() {
    for steps in [1, 4, 7] {
        let (r, scale) = law_residual("contact-mms-vp", steps);
        println!("contact-mms-vp, {steps} steps: residual {r:?}, stress scale {scale:.3}");
        assert!(
            r.iter().all(|&v| v <= 1e-12 * scale),
            "{r:?} against {scale}"
        );
    }
    // The variant's uniform history c t (t - 1) in s11 leaves -k^2 c per step there (its
    // local truncation error; c = 200) and nothing elsewhere.
    let steps = 4;
    let k = 1.0 / steps as f64;
    let (r, scale) = law_residual("contact-mms-vp-time", steps);
    println!(
        "contact-mms-vp-time, {steps} steps: residual {r:?}, expected [{}, 0, 0]",
        k * k * 200.0
    );
    assert!((r[0] - k * k * 200.0).abs() <= 1e-12 * scale);
    assert!(r[1] <= 1e-12 * scale && r[2] <= 1e-12 * scale);
}

#[test]
fn derived_body_force_and_source_match_central_differences() {
    contact_rates::init();
    let scene = Scene::load("contact-mms-vp").unwrap();
    let ex = scene.exact.as_deref().unwrap();
    let f = ex.body_force.as_ref().unwrap();
    let d = 1e-5;
    let mut worst = (0.0f64, 0.0f64);
    for b in 0..2 {
        let m = &scene.bodies[b].material;
        let y0 = if b == 0 { 1.0 } else { 0.0 };
        for i in 1..10 {
            for j in 1..10 {
                // Away from the kink x = 0.5871 by more than the difference step.
                let (x, y, t) = (
                    0.1 * i as f64 + 0.013,
                    y0 + 0.1 * j as f64,
                    0.37 + 0.05 * j as f64,
                );
                let s = |x: f64, y: f64, t: f64| Stress::from(ex.stress_at(b, x, y, t).unwrap());
                let u = |x: f64, y: f64, t: f64| ex.displacement_at(b, x, y, t).unwrap();
                // f = -div sigma by central differences in x and y.
                let dsx = (s(x + d, y, t) - s(x - d, y, t)) / (2.0 * d);
                let dsy = (s(x, y + d, t) - s(x, y - d, t)) / (2.0 * d);
                let f_fd = [-(dsx[0] + dsy[2]), -(dsx[2] + dsy[1])];
                for c in 0..2 {
                    let v = f[b][c].eval(x, y, t);
                    worst.0 = worst.0.max((v - f_fd[c]).abs() / v.abs().max(1.0));
                }
                // s = d sigma/dt - E eps(du/dt) - G(sigma), every derivative by differences.
                let dsdt = (s(x, y, t + d) - s(x, y, t - d)) / (2.0 * d);
                let v = |x: f64, y: f64| {
                    let (a, b) = (u(x, y, t + d), u(x, y, t - d));
                    [(a[0] - b[0]) / (2.0 * d), (a[1] - b[1]) / (2.0 * d)]
                };
                let e_rate = Stress::new(
                    (v(x + d, y)[0] - v(x - d, y)[0]) / (2.0 * d),
                    (v(x, y + d)[1] - v(x, y - d)[1]) / (2.0 * d),
                    0.5 * ((v(x, y + d)[0] - v(x, y - d)[0]) + (v(x + d, y)[1] - v(x - d, y)[1]))
                        / (2.0 * d),
                );
                let s_fd = dsdt - m.elastic.apply(&e_rate) - m.g(&s(x, y, t));
                let src = ex.source_at(b, m, x, y, t).unwrap();
                for c in 0..3 {
                    worst.1 = worst
                        .1
                        .max((src[c] - s_fd[c]).abs() / src[c].abs().max(1.0));
                }
            }
        }
    }
    println!(
        "largest difference to central differences: body force {:.2e}, source {:.2e}",
        worst.0, worst.1
    );
    // Central differences with step 1e-5: truncation ~1e-10, round-off ~1e-16/1e-5^2 for the
    // nested ones (the source's strain rate); 1e-5 leaves a wide margin over both.
    assert!(worst.0 < 1e-6 && worst.1 < 1e-5, "{worst:?}");
}

#[test]
fn derived_tractions_and_body_force_balance_the_stress_at_every_free_dof_off_gamma_c() {
    for scene in ["contact-mms-vp", "contact-mms-vp-time"] {
        let case = common::case(scene, 1, Method::Mortar, &[]);
        let model = &case.problem.model;
        let ex = model.scene.exact.as_deref().unwrap();
        let t = 0.7;
        let load = model.load(t).unwrap();
        // Internal force of the exact stress, integral of sigma : eps(phi_i), by the loads'
        // rule split along the kinks.
        let rule = quadrature::dunavant8();
        let mut internal = vec![0.0; load.len()];
        let kinks = [0, 1].map(|b| kink_functions(&ex.kinks(b), t));
        for e in &model.elements {
            let p = e.nodes.map(|n| model.position(n));
            for &(l1, l2, w) in quadrature::triangle_rule(p, &kinks[e.body], &rule).iter() {
                let (x, y) = (
                    (1.0 - l1 - l2) * p[0][0] + l1 * p[1][0] + l2 * p[2][0],
                    (1.0 - l1 - l2) * p[0][1] + l1 * p[1][1] + l2 * p[2][1],
                );
                let s = ex.stress_at(e.body, x, y, t).unwrap();
                for a in 0..3 {
                    let g = e.grads[a];
                    internal[2 * e.nodes[a]] += w * e.area * (s[0] * g[0] + s[2] * g[1]);
                    internal[2 * e.nodes[a] + 1] += w * e.area * (s[2] * g[0] + s[1] * g[1]);
                }
            }
        }
        let (mut worst, mut scale, mut checked) = (0.0f64, 0.0f64, 0);
        for n in 0..model.n_nodes {
            // Gamma_C (y = 1) carries the contact traction, which the load leaves out.
            if (model.position(n)[1] - 1.0).abs() < 1e-12 {
                continue;
            }
            for c in 0..2 {
                if model.equation[2 * n + c] == FIXED {
                    continue;
                }
                worst = worst.max((internal[2 * n + c] - load[2 * n + c]).abs());
                scale = scale.max(load[2 * n + c].abs());
                checked += 1;
            }
        }
        println!(
            "{scene}: {checked} free dofs off Gamma_C, largest |F - int sigma : eps(phi)| {worst:.2e} (load scale {scale:.3e})"
        );
        assert!(worst <= 1e-11 * scale, "{worst} against {scale}");
    }
}

fn scene_error(text: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("s.toml");
    let geo = contact_rates::scene::builtin_dir().join("../meshes/two_blocks.geo");
    std::fs::write(
        &file,
        text.replace("../meshes/two_blocks.geo", &geo.display().to_string()),
    )
    .unwrap();
    let out = common::run(
        &[
            "solve",
            "--scene",
            file.to_str().unwrap(),
            "--out",
            dir.path().join("out").to_str().unwrap(),
        ],
        &[],
    );
    assert!(!out.status.success(), "the scene must be refused");
    String::from_utf8_lossy(&out.stderr).to_string()
}

#[test]
fn a_viscoplastic_body_without_stress_and_a_non_symmetric_stress_are_refused() {
    let text =
        std::fs::read_to_string(contact_rates::scene::builtin_dir().join("contact-mms-vp.toml"))
            .unwrap();
    // No exact.stress: the source cannot be derived.
    let start = text.find("stress = [").unwrap();
    let end = start + text[start..].find("\n]\n").unwrap() + 3;
    let without = format!("{}{}", &text[..start], &text[end..]);
    let msg = scene_error(&without);
    println!("{msg}");
    assert!(
        msg.contains("exact.stress")
            && msg.contains("viscoplastic")
            && msg.contains("give exact.stress"),
        "{msg}"
    );
    // A full tensor whose s21 is not s12: refused before solving, naming the body and the fix.
    let tensor = format!(
        "{}stress = [\n  [[\"1\", \"x\"], [\"y\", \"2\"]],\n  [[\"1\", \"0\"], [\"0\", \"2\"]],\n]\n{}",
        &text[..start],
        &text[end..]
    );
    let msg = scene_error(&tensor);
    println!("{msg}");
    assert!(
        msg.contains("not symmetric") && msg.contains("exact.stress") && msg.contains("s21"),
        "{msg}"
    );
}

#[test]
fn quick_viscoplastic_exact_study_meets_the_thresholds_and_its_rate_in_k_is_backward_eulers() {
    contact_rates::init();
    let res = convergence::run("rates-exact-vp-quick").unwrap();
    for r in res.rates.iter().filter(|r| r.quantity == Quantity::Theorem) {
        common::assert_rate_passes(r, &[0, 1, 2]);
    }
    // Both bodies flow: the plastic fraction at T lies well inside (0.2, 0.8) on every level.
    for l in &res.levels {
        assert!(
            l.plastic_fraction > 0.2 && l.plastic_fraction < 0.8,
            "{l:?}"
        );
    }
    let ts = res
        .time_study
        .as_ref()
        .expect("the quick tier has a time study");
    for r in &ts.runs {
        println!("time study: {} steps, error {:.4e}", r.steps, r.error);
    }
    let a = &ts.assessment;
    let fit = a.fit.expect("a rate in k");
    println!(
        "rate in k {:.3} +- {:.3} ({})",
        fit.rate,
        fit.stderr,
        a.verdict.name()
    );
    // Theorem 3.1's k term: backward Euler is first order; a window rate within 0.1 of it.
    assert_eq!(a.verdict, Verdict::Fitted);
    assert!((fit.rate - 1.0).abs() < 0.1, "{}", fit.rate);
}
