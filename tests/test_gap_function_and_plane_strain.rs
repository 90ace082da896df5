//! Reference: issue 76 (a gap function as scene data; plane strain), after the patch test
//! of Fernandez-Garcia, Hild and Viano, section 5.2 (Test 2), and Lame's hydrostatic block
//! (a uniform pressure on a rectangle: sigma = -p I, a linear displacement, which P1
//! elements reproduce exactly).
//! Goal: (1) an initial gap given as `[contact] gap` reaches each method's rows as its own
//! discretization of g0 (nts: g0 at the body-1 nodes; mortar: the projection pi_h^1 g0,
//! exact for a g0 linear along Gamma_C; lac: the mean of g0 over each macro-element, in
//! closed form for a quadratic g0), and with g0 constant on touching non-matching meshes
//! mortar and lac close it exactly: the stress and pressure at solver tolerance and the
//! closed gap equal to g0 at every body-1 node to 1e-10 (dropped, the gap would be 0);
//! (2) `plane = "strain"` gives the plane-strain nodal displacements at solver tolerance,
//! which differ from plane stress's by 26 % (eps = -(1 + nu)(1 - 2 nu) p / E against
//! -(1 - nu) p / E).
//! Geometry: meshes/two_blocks.geo, upper block [0,1]x[1,2] (body 1) on the lower
//! [0,1]x[0,1], non-matching (h 0.3 and 0.2, the upper contact line graded 1.3).
//! Data: (1) E = 3e5, nu = 0.3, g = (0, -10) on top, symmetry on the right sides and the
//! bottom (tests/data/gap-function-patch.toml); (2) E = 100 and 150, nu = 0.3, pressure 1
//! on the top and right sides, rollers on the left sides and the bottom
//! (tests/data/pressed-blocks-strain.toml).

mod common;
use contact_rates::case::Case;
use contact_rates::contact::{self, Method};
use contact_rates::scene::Scene;
use contact_rates::solve::{self, Settings};
use nalgebra::Vector3;

const G0: f64 = 0.01;

fn scene(name: &str, edit: impl Fn(String) -> String) -> (tempfile::TempDir, Scene) {
    contact_rates::init();
    let data = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/");
    let text = std::fs::read_to_string(format!("{data}{name}")).unwrap();
    let text = text.replace("\"../../meshes/", &format!("\"{data}../../meshes/"));
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join(name);
    std::fs::write(&file, edit(text)).unwrap();
    let scene = Scene::load(file.to_str().unwrap()).expect("the scene loads");
    (dir, scene)
}

/// Every method's row gaps are its discretization of g0 = 0.01 + 0.02 x + 0.03 x^2 (nts,
/// lac) or of its linear part (mortar, whose projection reproduces P1 functions).
#[test]
fn each_method_takes_its_discrete_gap_from_the_gap_function() {
    let g0 = |x: f64, c2: f64| 0.01 + 0.02 * x + c2 * x * x;
    for (method, c2) in [
        (Method::Nts, 0.03),
        (Method::Lac, 0.03),
        (Method::Mortar, 0.0),
    ] {
        let text = format!("gap = \"0.01 + 0.02*x + {c2}*x^2\"");
        let (_dir, sc) = scene("gap-function-patch.toml", |t| {
            t.replace("gap = \"0.01\"", &text)
        });
        for level in 0..3 {
            let case = Case::build(&sc, level, method, &[]).expect("the case builds");
            let p = &case.problem;
            let piece = &p.interface.pieces[0];
            let x = |j: usize| piece.point(piece.slave_s[j])[0];
            let mut worst = 0.0f64;
            for r in &p.rows {
                let want = match r.node() {
                    Some(j) => g0(x(j), c2),
                    None => {
                        let (a, b) = (x(r.span[0]), x(r.span[1]));
                        0.01 + 0.02 * (a + b) / 2.0 + c2 * (a * a + a * b + b * b) / 3.0
                    }
                };
                worst = worst.max((r.gap - want).abs());
            }
            println!(
                "{method} level {level}: {} rows, largest |g_i - want| {worst:.2e}",
                p.rows.len()
            );
            assert!(
                worst < 1e-14,
                "{method} level {level}: row gap off by {worst:e}"
            );
        }
    }
}

#[test]
fn mortar_and_lac_close_a_gap_given_as_data_exactly() {
    let (_dir, sc) = scene("gap-function-patch.toml", |t| t);
    for level in 0..2 {
        for method in [Method::Mortar, Method::Lac] {
            let case = Case::build(&sc, level, method, &[]).expect("the case builds");
            let p = &case.problem;
            assert!(p.interface.min_relative_separation() > 1e-3, "non-matching");
            let sol = solve::solve(p, &Settings::default(), 1, false).expect("converges");
            let last = sol.last();
            let exact = Vector3::new(0.0, -10.0, 0.0);
            let stress = last
                .sigma
                .iter()
                .map(|s| (s - exact).amax())
                .fold(0.0, f64::max);
            let pressure = p
                .rows
                .iter()
                .zip(&last.lambda)
                .map(|(r, l)| (r.pressure(*l) - 10.0).abs())
                .fold(0.0, f64::max);
            let slave_nodes = p.interface.pieces[0].slave_s.len();
            let jumps = contact::normal_jumps(&p.interface, &last.u);
            let closed = jumps[..slave_nodes]
                .iter()
                .map(|j| (j.2 - G0).abs())
                .fold(0.0, f64::max)
                / G0;
            // The penetration, measured against g0, vanishes where the gap closed.
            let penetration = contact::penetrations(&p.interface, &last.u)[..slave_nodes]
                .iter()
                .map(|j| j.2.abs())
                .fold(0.0, f64::max)
                / G0;
            println!(
                "level {level} {method}: stress {stress:.2e}, pressure {pressure:.2e}, |closed gap - g0| / g0 {closed:.2e}, |penetration| / g0 {penetration:.2e}"
            );
            assert!(
                stress / 10.0 < 1e-9 && pressure / 10.0 < 1e-9,
                "{method} {level}"
            );
            assert!(closed < 1e-10 && penetration < 1e-10, "{method} {level}");
        }
    }
}

/// The nodal displacements of Lame's block, plane strain, against the closed form.
#[test]
fn plane_strain_pressed_blocks_match_the_closed_form_at_the_nodes() {
    let nu: f64 = 0.3;
    for (plane, strain_of) in [
        ("strain", (1.0 + nu) * (1.0 - 2.0 * nu)),
        ("stress", 1.0 - nu),
    ] {
        let (_dir, sc) = scene("pressed-blocks-strain.toml", |t| {
            // Plane stress's closed form for the same blocks: the exact fields follow it.
            let t = t.replace("plane = \"strain\"", &format!("plane = \"{plane}\""));
            t.replace("\n[exact]", "\n[unused]")
                .split("\n[unused]")
                .next()
                .unwrap()
                .to_string()
        });
        let e = [100.0, 150.0].map(|young: f64| -strain_of / young);
        for method in [Method::Mortar, Method::Lac] {
            let case = Case::build(&sc, 1, method, &[]).expect("the case builds");
            let p = &case.problem;
            let sol = solve::solve(p, &Settings::default(), 1, false).expect("converges");
            let u = &sol.last().u;
            let mut worst = 0.0f64;
            let mut largest = 0.0f64;
            for b in 0..2 {
                let m = &p.model;
                for (k, x) in m.meshes[b].nodes.iter().enumerate() {
                    let want = match b {
                        0 => [e[0] * x[0], e[1] + e[0] * (x[1] - 1.0)],
                        _ => [e[1] * x[0], e[1] * x[1]],
                    };
                    let g = m.node_offset[b] + k;
                    for c in 0..2 {
                        worst = worst.max((u[2 * g + c] - want[c]).abs());
                        largest = largest.max(want[c].abs());
                    }
                }
            }
            println!("plane {plane}, {method}: largest |u_h - u| {worst:.2e} of |u| {largest:.2e}");
            assert!(worst < 1e-9 * largest, "plane {plane} {method}: {worst:e}");
        }
    }
}
