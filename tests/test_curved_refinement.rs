//! Reference: issue 77 (curved traces that converge to their curves); the polygonal
//! approximation of a domain bounded by circle arcs (Strang and Fix, An Analysis of the
//! Finite Element Method, section 4.4: the area between an arc and its chords is
//! O(h^2) of the arc's length).
//! Goal: with `Split::OnCurves` every level's boundary nodes lie on the .geo's arcs (to
//! round-off), so the bodies' polygonal areas converge to the annuli's at rate 2 (ratio 4
//! per level); with `Split::Chords` (gmsh -refine of the saved mesh) the new nodes stay on
//! level 0's chords and the area error stays level 0's: the test fails if the levels
//! are split without the .geo.
//! Geometry: meshes/press_fit.geo: body 1 the quarter annulus 0.5 <= r <= 1, body 2 the
//! quarter annulus 1.02 <= r <= 1.5, meshed independently; levels 0-3.

use contact_rates::mesh::RawMesh;
use contact_rates::mesh::gmsh::{self, Split};
use contact_rates::mesh::msh::read_msh;
use std::f64::consts::FRAC_PI_4;

const GEO: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/meshes/press_fit.geo");

fn mesh(dir: &std::path::Path, level: usize, split: Split) -> RawMesh {
    let generated =
        gmsh::generate_in(dir, GEO.as_ref(), &[], level, split).expect("gmsh meshes it");
    read_msh(&generated.path).expect("the mesh reads")
}

/// The largest |r - radius| over the nodes of the physical curve `name`.
fn off_the_arc(m: &RawMesh, name: &str, radius: f64) -> f64 {
    let tag = m.physical_tag(1, name).expect("the curve is named");
    m.lines
        .iter()
        .filter(|l| l.1 == tag)
        .flat_map(|l| l.0)
        .map(|n| (m.nodes[n][0].hypot(m.nodes[n][1]) - radius).abs())
        .fold(0.0, f64::max)
}

/// The area of the physical surface `name`'s triangles.
fn area(m: &RawMesh, name: &str) -> f64 {
    let tag = m.physical_tag(2, name).expect("the surface is named");
    m.triangles
        .iter()
        .filter(|t| t.1 == tag)
        .map(|t| {
            let [p, q, r] = t.0.map(|n| m.nodes[n]);
            0.5 * ((q[0] - p[0]) * (r[1] - p[1]) - (r[0] - p[0]) * (q[1] - p[1])).abs()
        })
        .sum()
}

#[test]
fn levels_split_on_the_curves_converge_to_the_arcs_and_split_chords_do_not() {
    let dir = tempfile::tempdir().unwrap();
    let exact = [
        ("inner", FRAC_PI_4 * (1.0 - 0.25)),
        ("outer", FRAC_PI_4 * (1.5f64.powi(2) - 1.02f64.powi(2))),
    ];
    let errors = |split: Split| -> Vec<[f64; 2]> {
        (0..4)
            .map(|level| {
                let m = mesh(dir.path(), level, split);
                if split == Split::OnCurves {
                    for (curve, radius) in [
                        ("contact_inner", 1.0),
                        ("contact_outer", 1.02),
                        ("bore", 0.5),
                        ("outside", 1.5),
                    ] {
                        let off = off_the_arc(&m, curve, radius);
                        assert!(off < 1e-12, "level {level}: {curve} {off:e} off its arc");
                    }
                }
                exact.map(|(name, want)| (want - area(&m, name)) / want)
            })
            .collect()
    };
    let (curved, chords) = (errors(Split::OnCurves), errors(Split::Chords));
    for level in 0..4 {
        println!(
            "level {level}: relative area error on curves {:.3e} {:.3e}, on chords {:.3e} {:.3e}",
            curved[level][0], curved[level][1], chords[level][0], chords[level][1]
        );
    }
    assert_eq!(
        curved[0], chords[0],
        "level 0 is gmsh's own mesh either way"
    );
    for body in 0..2 {
        for level in 1..4 {
            // The area between n chords of angle d and their arc of radius rho is
            // n rho^2 (d - sin d) / 2 = rho^2 theta d^2 (1 - d^2 / 20 + ...) / 12: rate 2 with
            // a correction that quarters per level (measured 0.057, 0.015, 0.004 on body
            // 2, whose two arcs' errors partly cancel), so within 0.02 of 2 from level 2.
            let rate = (curved[level - 1][body] / curved[level][body]).log2();
            let tolerance = if level >= 2 { 0.02 } else { 0.1 };
            assert!(
                curved[level][body] > 0.0 && (rate - 2.0).abs() < tolerance,
                "body {body} level {level}: rate {rate}"
            );
            // The chords never move: level 0's area at every level (to the round-off of
            // summing the triangles, relative to the area).
            let kept = (chords[level][body] - chords[0][body]).abs();
            assert!(kept < 1e-13, "body {body} level {level}: {kept:e}");
        }
    }
}

/// The .geo's parameters reach the session that splits on the curves (`-setnumber` into a
/// DefineConstant of the included .geo): g0 = 0.05 puts body 2's trace on r = 1.05 at
/// level 2, and the mesh is not the default's.
#[test]
fn a_parameter_reaches_the_split_on_the_curves() {
    let dir = tempfile::tempdir().unwrap();
    let params = [("g0".to_string(), 0.05)];
    let generated = gmsh::generate_in(dir.path(), GEO.as_ref(), &params, 2, Split::OnCurves)
        .expect("gmsh meshes it");
    let m = read_msh(&generated.path).expect("the mesh reads");
    let off = off_the_arc(&m, "contact_outer", 1.05);
    assert!(off < 1e-12, "{off:e} off r = 1.05");
    assert!(off_the_arc(&m, "contact_inner", 1.0) < 1e-12);
}
