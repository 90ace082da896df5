//! Two blocks pressed together, meshed independently, solved with each discrete contact
//! condition (mortar, nts and lac) and measured against the exact solution.
//!
//! `cargo run --release --example contact_basics -- [LEVEL]` (default 2)
//!
//! The scene `contact-mms` (scenes/contact-mms.toml): two elastic blocks touching along
//! y = 1, in contact for x < a, apart beyond; its loads come from a manufactured solution,
//! so each cone's error is measured against the truth in Theorem 3.1's norm.

use contact_rates::case::Case;
use contact_rates::contact::Method;
use contact_rates::metrics::contact_nodes;
use contact_rates::scene::Scene;
use contact_rates::solve::SolverKind;
use contact_rates::verify::{exact_error::ExactComparison, field::P1History, solve_case};
use std::io::Write;

/// Solve `contact-mms` at `level` with every cone and write what each measured to `out`.
pub fn run(level: usize, out: &mut impl Write) -> contact_rates::Result<()> {
    let scene = Scene::load("contact-mms")?;
    let exact = scene
        .exact
        .as_deref()
        .expect("contact-mms has an exact solution");
    let rule = ExactComparison::new(exact, 4);
    for method in Method::ALL {
        // The meshes of both bodies (gmsh, split `level` times) and the discrete problem.
        let case = Case::build(&scene, level, method, &[])?;
        // Newton's method on the scene's time steps, keeping every step.
        let (solution, seconds) = solve_case(&case, SolverKind::Newton, scene.steps)?;
        // The error at every step against the exact solution at that time: the integrals
        // take plain P1 displacements and P0 stresses, whoever computed them.
        let (mut error, mut norm) = (0.0f64, 0.0f64);
        let history = P1History::of_solution(&case, &solution);
        for field in &history.steps {
            let d = rule.difference(history.model, history.interface, field);
            error = error.max(d.difference.theorem());
            norm = norm.max(d.exact.theorem());
        }
        let _ = writeln!(
            out,
            "{method}: level {level}, {} dofs, h = {:.4}, theorem-norm error {:.6e}, solved in {seconds:.2} s",
            case.problem.model.n_free,
            case.h,
            error / norm
        );
        // The contact pressure at T along Gamma_C beside the exact one, at a few nodes.
        let last = solution
            .states
            .last()
            .expect("the history has the final state");
        let nodes = contact_nodes(&case.problem, last);
        let _ = writeln!(out, "  x         pressure  exact     normal jump");
        for node in nodes.iter().step_by(nodes.len().div_ceil(6)) {
            let normal = case.problem.interface.pieces[node.piece].normal;
            let [x, y] = node.position;
            let truth = exact
                .pressure_at(normal, x, y, last.time)
                .expect("contact-mms gives the pressure");
            let _ = writeln!(
                out,
                "  {x:<9.4} {:<9.4} {truth:<9.4} {:.2e}",
                node.pressure, node.normal_jump
            );
        }
    }
    Ok(())
}

fn main() {
    contact_rates::init();
    let Ok(level) = std::env::args().nth(1).map_or(Ok(2), |s| s.parse()) else {
        eprintln!("error: LEVEL: expected a mesh level (0, 1, 2, ...)");
        std::process::exit(2);
    };
    if let Err(e) = run(level, &mut std::io::stdout()) {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}
