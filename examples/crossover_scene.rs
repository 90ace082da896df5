//! Writes the `crossover` scene for a given epsilon: stacked-exact's uniform compression plus
//! epsilon times its Airy mode (top load -10 t (0.3 + epsilon cos(pi x))), in closed form
//! (`analytical::stacked`). The uniform part is exact in P1, so the bulk error scales with
//! epsilon, while nts's consistency error scales with the pressure, mostly the uniform
//! part's: epsilon places the level where nts's h^(1/2) overtakes.
//!
//! `cargo run --release --example crossover_scene -- EPSILON > scenes/crossover.toml`

use contact_rates::analytical::stacked::StackedBlocks;

fn main() {
    let Some(epsilon) = std::env::args().nth(1).and_then(|s| s.parse::<f64>().ok()) else {
        eprintln!("error: EPSILON: give the Airy mode's factor, e.g. 0.01");
        std::process::exit(2);
    };
    let closed = StackedBlocks::new(100.0, 0.3, 3.0, 10.0 * epsilon);
    let u = closed.expressions();
    print!(
        r#"description = "Stacked blocks in uniform compression plus epsilon = {epsilon} times one Airy mode (stacked-exact's, scaled): the interface stays closed, the bulk P1 error scales with epsilon and nts's consistency error with the pressure, so nts's h^(1/2) overtakes within reach; exact solution in closed form (examples/crossover_scene.rs writes this file)"
geo = "../meshes/two_blocks.geo"
final_time = 1.0
steps = 4

[parameters]
h_upper = 0.3
h_lower = 0.2
grading = 1.3

[[bodies]]
surface = "upper"
young = 100.0
poisson = 0.3

[[bodies]]
surface = "lower"
young = 100.0
poisson = 0.3

[[clamp]]
curve = "bottom"

[[roller]]
curve = "left_upper"
component = "x"

[[roller]]
curve = "right_upper"
component = "x"

[[roller]]
curve = "left_lower"
component = "x"

[[roller]]
curve = "right_lower"
component = "x"

[[traction]]
curve = "top"
g = ["0", "-10*t*(0.3 + {epsilon}*cos(pi*x))"]

[contact]
slave_body = "upper"
slave_curve = "contact_upper"
master_curve = "contact_lower"

# stacked-exact's closed form with the Airy mode scaled by epsilon = {epsilon}
# (src/analytical/stacked.rs; tests/test_exact_references.rs checks it).
[exact]
displacement = [
  ["{}",
   "{}"],
  ["{}",
   "{}"],
]
"#,
        u[0][0], u[0][1], u[1][0], u[1][1]
    );
}
