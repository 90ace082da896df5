//! Writes the `press-fit` scene: the Lame press fit of meshes/press_fit.geo (body 1 the
//! quarter annulus 0.5 <= r <= 1, body 2 the ring 1.02 <= r <= 1.5, plane strain, E = 100
//! and 150, nu = 0.3) closed by the bore pressure 6.6, with its exact solution in closed
//! form (`analytical::lame::PressFit`) and the exact contact geometry: body 1's normal x/|x|
//! and the radial map m(x) = x (R + g0) / R onto body 2's arc.
//!
//! `cargo run --release --example press_fit_scene > scenes/press-fit.toml`

use contact_rates::analytical::lame::PressFit;

fn main() {
    let fit = PressFit::benchmark();
    let solution = fit.solve();
    assert!(fit.closes(), "the bore pressure closes the gap");
    let [u1, u2] = [0, 1].map(|i| solution.displacement_text(i));
    let (a, r, g0, b, p) = (fit.bore, fit.radius, fit.gap, fit.outer, fit.bore_pressure);
    let stretch = (r + g0) / r;
    print!(
        r#"# Written by `cargo run --release --example press_fit_scene`: do not edit by hand.
description = "The Lame press fit: body 1 (inner, {a} <= r <= {r}, E = 100) pressed by {p} on its bore across the radial gap {g0} against body 2 (outer, {rho} <= r <= {b}, E = 150, free outside), plane strain, nu = 0.3, rollers on the symmetry lines; levels split on the arcs; exact solution in closed form (contact pressures p1 = {p1:.6} on r = R, p2 = {p2:.6} on r = R + g0, p1 R = p2 (R + g0); the gap closes at the bore pressure {closing:.4})"
geo = "../meshes/press_fit.geo"
final_time = 1.0
steps = 1
refinement = "curved"
plane = "strain"

[parameters]
a = {a:?}
radius = {r:?}
g0 = {g0:?}
b = {b:?}
h_inner = 0.15
h_outer = 0.11

[[bodies]]
surface = "inner"
young = 100.0
poisson = 0.3

[[bodies]]
surface = "outer"
young = 150.0
poisson = 0.3

[[roller]]
curve = "left_inner"
component = "x"

[[roller]]
curve = "left_outer"
component = "x"

[[roller]]
curve = "bottom_inner"
component = "y"

[[roller]]
curve = "bottom_outer"
component = "y"

[[traction]]
curve = "bore"
g = ["{p:?}*x/{a:?}", "{p:?}*y/{a:?}"]

[contact]
slave_body = "inner"
slave_curve = "contact_inner"
master_curve = "contact_outer"

[exact]
displacement = [["{u1x}", "{u1y}"], ["{u2x}", "{u2y}"]]

# Gamma_C's exact geometry: body 1's outward normal on r = R and the radial map onto
# body 2's arc r = R + g0 (the slave-normal map; its stretch (R + g0) / R = {stretch:?}).
[exact.contact]
normal = ["x/sqrt(x^2+y^2)", "y/sqrt(x^2+y^2)"]
master = ["{stretch:?}*x", "{stretch:?}*y"]
"#,
        rho = r + g0,
        p1 = solution.pressure_inner,
        p2 = solution.pressure_outer,
        closing = fit.closing_pressure(),
        u1x = u1[0],
        u1y = u1[1],
        u2x = u2[0],
        u2y = u2[1],
    );
}
