//! Reference: SPEC section 5 (manufactured contact solutions); the plane-stress law
//! sigma = a tr(eps) I + b eps, a = E nu / (1 - nu^2), b = E / (1 + nu).
//! Goal: body forces and tractions derived by exact symbolic differentiation equal the
//! hand-derived ones for a polynomial field (to round-off), derivatives through abs are the
//! branch derivatives, and a field that is not a contact solution on Gamma_C (pressure x gap
//! != 0, or a tangential traction) is refused before solving, with the condition and the
//! point, and a non-zero exit.
//! Geometry and data: the `contact-mms` scene (E1 = 100, E2 = 150, nu = 0.3).

use contact_rates::analytical::{Exact, traction};
use contact_rates::expr::Expr;
use contact_rates::material::{Elasticity, Material};
use std::path::{Path, PathBuf};
use std::process::Command;

fn expr(s: &str) -> Expr {
    Expr::parse(s, Path::new("test"), "test").unwrap()
}

fn elastic(young: f64, poisson: f64) -> Material {
    Material {
        elastic: Elasticity::plane_stress(young, poisson),
        viscoplastic: None,
    }
}

#[test]
fn derived_body_force_and_traction_of_a_polynomial_field_equal_the_hand_derived_ones() {
    // u = (x^2 y, x y^3) in both bodies: eps11 = 2 x y, eps22 = 3 x y^2,
    // eps12 = (x^2 + y^3) / 2; sigma11 = 2 (a + b) x y + 3 a x y^2,
    // sigma22 = 2 a x y + 3 (a + b) x y^2, sigma12 = b (x^2 + y^3) / 2;
    // f = -div sigma = (-(2 (a + b) y + 3 a y^2 + 3 b y^2 / 2), -(b x + 2 a x + 6 (a + b) x y)).
    let m = elastic(100.0, 0.3);
    let (a, b) = (m.elastic.a(), m.elastic.b());
    let u = || [expr("x^2*y"), expr("x*y^3")];
    let ex = Exact::new(Some([u(), u()]), None, None, true, [&m, &m]);
    let f = ex.body_force.as_ref().unwrap();
    for &(x, y) in &[(0.3, 0.7), (1.1, -0.4), (-2.0, 3.0)] {
        let s_hand = [
            2.0 * (a + b) * x * y + 3.0 * a * x * y * y,
            2.0 * a * x * y + 3.0 * (a + b) * x * y * y,
            0.5 * b * (x * x + y * y * y),
        ];
        let f_hand = [
            -(2.0 * (a + b) * y + 3.0 * a * y * y + 1.5 * b * y * y),
            -(b * x + 2.0 * a * x + 6.0 * (a + b) * x * y),
        ];
        let s = ex.stress_at(0, x, y, 1.0).unwrap();
        for k in 0..3 {
            assert!(
                (s[k] - s_hand[k]).abs() <= 1e-13 * s_hand[k].abs().max(1.0),
                "sigma[{k}] at ({x}, {y}): {} vs {}",
                s[k],
                s_hand[k]
            );
        }
        for c in 0..2 {
            let v = f[0][c].eval(x, y, 1.0);
            assert!(
                (v - f_hand[c]).abs() <= 1e-13 * f_hand[c].abs().max(1.0),
                "f[{c}] at ({x}, {y}): {v} vs {}",
                f_hand[c]
            );
        }
        // The traction on a boundary with outward normal n is sigma n.
        let n = [0.6, -0.8];
        let g = traction(s, n);
        let g_hand = [
            s_hand[0] * n[0] + s_hand[2] * n[1],
            s_hand[2] * n[0] + s_hand[1] * n[1],
        ];
        for c in 0..2 {
            assert!((g[c] - g_hand[c]).abs() <= 1e-13 * g_hand[c].abs().max(1.0));
        }
    }
}

#[test]
fn derivatives_through_abs_are_the_branch_derivatives() {
    // max(x - a, 0)^4 = ((x - a + abs(x - a)) / 2)^4: derivative 4 max(x - a, 0)^3, second
    // derivative 12 max(x - a, 0)^2, on both sides of a.
    let e = expr("((x-0.5871+abs(x-0.5871))/2)^4");
    let (d1, d2) = (e.partial(0), e.partial(0).partial(0));
    for x in [0.1, 0.5, 0.5871, 0.6, 0.9] {
        let p = (x - 0.5871f64).max(0.0);
        assert!((d1.eval(x, 0.0, 0.0) - 4.0 * p.powi(3)).abs() < 1e-15);
        assert!((d2.eval(x, 0.0, 0.0) - 12.0 * p.powi(2)).abs() < 1e-14);
    }
    // A min through abs: d/dx cos(pi min(x, a) / a) = -pi / a sin(pi x / a) for x < a, 0 beyond.
    let c = expr("cos(pi*((x+0.5871-abs(x-0.5871))/2)/0.5871)").partial(0);
    let k = std::f64::consts::PI / 0.5871;
    assert!((c.eval(0.2, 0.0, 0.0) + k * (k * 0.2).sin()).abs() < 1e-13);
    assert_eq!(c.eval(0.8, 0.0, 0.0), 0.0);
}

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The contact-mms scene with `edit` applied, written into `dir`.
fn mms_scene(dir: &Path, edit: impl Fn(String) -> String) -> PathBuf {
    let text = std::fs::read_to_string(repo().join("scenes/contact-mms.toml")).unwrap();
    let geo = repo().join("meshes/two_blocks.geo");
    let text = text.replace(
        "\"../meshes/two_blocks.geo\"",
        &format!("{:?}", geo.display().to_string()),
    );
    let f = dir.join("mms.toml");
    std::fs::write(&f, edit(text)).unwrap();
    f
}

fn solve(scene: &Path, out: &Path) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_contact-rates"))
        .args([
            "solve",
            "--scene",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap()
}

#[test]
fn a_field_that_is_not_a_contact_solution_is_refused_before_solving() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    // The unperturbed field passes the check and solves.
    let ok = solve(&mms_scene(dir.path(), |t| t), &out);
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    std::fs::remove_dir_all(&out).unwrap();
    let cases: [(Box<dyn Fn(String) -> String>, &[&str]); 2] = [
        (
            // The gap opens at 0.4 while the pressure acts up to 0.5871.
            Box::new(|t: String| {
                t.replace(
                    "0.3*t*((x-0.5871+abs(x-0.5871))/2)^2",
                    "0.3*t*((x-0.4+abs(x-0.4))/2)^2",
                )
                .replace(
                    "0.1*t*((x-0.5871+abs(x-0.5871))/2)^3",
                    "0.1*t*((x-0.4+abs(x-0.4))/2)^3",
                )
            }),
            &[
                "not a solution of the contact problem",
                "pressure x gap",
                "!= 0",
                "(x, y) = (0.",
                "t = 0.25",
            ],
        ),
        (
            // A shear u_x = 0.01 t (y - 1) x: sigma_12 = b 0.01 t x / 2 on y = 1.
            Box::new(|t: String| {
                t.replacen(
                    "+ 0.02*t*(y-1)^2*sin(pi*x)",
                    "+ 0.02*t*(y-1)^2*sin(pi*x) + 0.01*t*(y-1)*x",
                    1,
                )
            }),
            &[
                "not a solution of the contact problem",
                "tangential traction on the slave side",
                "(x, y) = (",
            ],
        ),
    ];
    let original = std::fs::read_to_string(repo().join("scenes/contact-mms.toml")).unwrap();
    for (edit, needles) in cases {
        assert_ne!(edit(original.clone()), original, "the perturbation applies");
        let o = solve(&mms_scene(dir.path(), edit), &out);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{err}");
        assert!(!err.contains("panicked"), "{err}");
        assert_eq!(err.lines().count(), 1, "one line: {err}");
        for n in needles {
            assert!(err.contains(n), "'{n}' not in: {err}");
        }
        assert!(!out.join("solution.vtu").exists(), "nothing written");
    }
}
