//! Measures the smallest distance between the two trace meshes' nodes (relative to h)
//! over seven levels of uniform splitting, for several gradings of the upper contact line:
//! `cargo run --release --example interface_separation -- H_UPPER H_LOWER`.
//! Measured (0.3, 0.2): grading 1 gives 1e-11 h (near-coincident nodes), 1.3 gives 1.5e-3 h.
use contact_rates::{case::Case, contact::Method, scene::Scene};
fn main() {
    let scene = Scene::load("patch").unwrap();
    let args: Vec<String> = std::env::args().collect();
    let hu: f64 = args[1].parse().unwrap();
    let hl: f64 = args[2].parse().unwrap();
    for g in [1.0, 1.1, 1.2, 1.25, 1.3, 1.35, 1.4, 1.5] {
        let mut worst = f64::INFINITY;
        let mut s = String::new();
        for level in 0..7 {
            let c = Case::build(
                &scene,
                level,
                Method::Nts,
                &[
                    ("h_upper".into(), hu),
                    ("h_lower".into(), hl),
                    ("grading".into(), g),
                ],
            )
            .unwrap();
            let sep = c.problem.interface.min_relative_separation();
            worst = worst.min(sep);
            s += &format!(" {sep:.2e}");
        }
        println!("grading {g}: min {worst:.3e}:{s}");
    }
}
