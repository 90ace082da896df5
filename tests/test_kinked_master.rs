//! Reference: issue 77 (a kinked master), after the patch test of Fernandez-Garcia, Hild and
//! Viano, section 5.2 (Test 2), and Popp, Gee and Wall (2009), section 5.1 (mortar segments
//! with averaged nodal normals).
//! Goal: on a Gamma_C with one kink K and zero gap, a hydrostatic state (sigma = -I, u
//! linear, which P1 reproduces) is reproduced at solver tolerance by mortar and lac where
//! the kink turns by more than the corner angle (30 degrees: Gamma_C is two straight pieces
//! split at K); where it turns by less, Gamma_C is one piece whose averaged normal at K is
//! the mean of the two segments' normals, and the error that normal makes is measured and
//! printed, not claimed zero (it is asserted above solver tolerance, so that the test fails
//! if the one-piece case became exact by splitting at K after all, and falling with h).
//! Geometry: meshes/kinked_blocks.geo: Gamma_C from (0, 1) to K = (0.5, 1), then up at
//! theta to (1, 1 + 0.5 tan theta); body 1 above, 3 segments on each part at level 0, body
//! 2 below with 6 (the slave polyline plus extra nodes); levels split.
//! Data: E = 100 in both (one material, so that u is continuous in every direction), nu =
//! 0.3, plane stress; pressure 1 on the top and right sides, rollers on the left sides and
//! the bottom (tests/data/kinked-master.toml). Exact: u = -0.007 (x, y), pressure 1.

mod common;
use contact_rates::case::Case;
use contact_rates::contact::Method;
use contact_rates::scene::Scene;
use contact_rates::solve::{self, Settings};

/// Newton's tolerance is 1e-10 on the residual; nodal values within 1e-9 of |u|.
const SOLVER: f64 = 1e-9;

/// (largest |u_h - u| over every node / largest |u|, largest |p_h - 1| over the rows) of
/// one solve at `theta` degrees and `level`, and the number of pieces of Gamma_C.
fn errors(theta: f64, level: usize, method: Method) -> (f64, f64, usize) {
    contact_rates::init();
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/kinked-master.toml");
    let scene = Scene::load(path).expect("the kinked-master scene loads");
    let case =
        Case::build(&scene, level, method, &[("theta".into(), theta)]).expect("the case builds");
    let p = &case.problem;
    let sol = solve::solve(p, &Settings::default(), 1, false).expect("the solve converges");
    let last = sol.last();
    let (mut worst, mut largest) = (0.0f64, 0.0f64);
    for b in 0..2 {
        for (k, x) in p.model.meshes[b].nodes.iter().enumerate() {
            let g = p.model.node_offset[b] + k;
            for c in 0..2 {
                let want = -0.007 * x[c];
                worst = worst.max((last.u[2 * g + c] - want).abs());
                largest = largest.max(want.abs());
            }
        }
    }
    let pressure = p
        .rows
        .iter()
        .zip(&last.lambda)
        .map(|(r, l)| (r.pressure(*l) - 1.0).abs())
        .fold(0.0, f64::max);
    (worst / largest, pressure, p.interface.pieces.len())
}

#[test]
fn a_kink_above_the_corner_angle_splits_gamma_c_and_mortar_and_lac_are_exact() {
    for level in 0..3 {
        for method in Method::ALL {
            let (u, p, pieces) = errors(40.0, level, method);
            println!(
                "theta 40, level {level}, {method}: |u_h - u| / |u| {u:.2e}, |p_h - 1| {p:.2e}, {pieces} pieces"
            );
            assert_eq!(pieces, 2, "a 40-degree kink is a corner");
            if method != Method::Nts {
                assert!(
                    u < SOLVER && p < SOLVER,
                    "{method} level {level}: {u:e} {p:e}"
                );
            }
        }
    }
}

#[test]
fn a_kink_below_the_corner_angle_is_one_piece_and_its_error_is_measured() {
    for method in [Method::Mortar, Method::Lac] {
        let mut previous = f64::INFINITY;
        for level in 0..3 {
            let (u, p, pieces) = errors(20.0, level, method);
            println!(
                "theta 20, level {level}, {method}: |u_h - u| / |u| {u:.2e}, |p_h - 1| {p:.2e}, {pieces} piece"
            );
            assert_eq!(pieces, 1, "a 20-degree turn is not a corner");
            assert!(
                u > 100.0 * SOLVER,
                "{method} level {level}: the averaged normal at K is not exact ({u:e})"
            );
            assert!(
                u < previous,
                "{method} level {level}: {u:e} after {previous:e}"
            );
            previous = u;
        }
    }
}
