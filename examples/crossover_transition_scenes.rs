//! Writes the `crossover-transition` scenes: the regularity family's singular solution at
//! beta = 1.25 with the values of Phi chosen to carry pressure (`Ends::CROSSOVER_TRANSITION`),
//! c = (0.5871, 1) a node of both meshes, so that the interface separates on (c, 1] while
//! mortar converges at rate 1 and nts's h^(1/2) distance to mortar overtakes mortar's error
//! within the computed levels:
//! - scenes/crossover-transition.toml: the upper contact line graded 1.3 on each side of c,
//!   as the crossover study's meshes are (studies/crossover-transition.toml, levels 0-7);
//! - scenes/crossover-transition-quick.toml: the upper line graded 5 on each side of c; with
//!   the slave sqrt(10) coarser than the master (studies/crossover-transition-quick.toml)
//!   nts's distance to mortar is twice mortar's error from level 0.
//!
//! `cargo run --release --example crossover_transition_scenes`

use contact_rates::analytical::singular::{Ends, SingularContact};

fn main() -> std::io::Result<()> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    for (name, grading, what) in [
        (
            "crossover-transition",
            1.3,
            "the upper contact line graded 1.3 on each side of c, as crossover's",
        ),
        (
            "crossover-transition-quick",
            5.0,
            "the upper contact line graded 5 on each side of c, so that nts's distance to mortar overtakes mortar's error from level 0",
        ),
    ] {
        let member = SingularContact {
            grading,
            ..SingularContact::with_ends(1.25, &Ends::CROSSOVER_TRANSITION)
        };
        let description = format!(
            "Contact on [0, 0.5871), separation on (0.5871, 1]: the regularity family's singular solution at beta = 1.25 (mortar at rate 1) with Phi's values 0 but the gap's and the pressure's derivative, so that the singular part carries pressure 27.47 t r^0.25 for its curvature (src/analytical/singular.rs, Ends::CROSSOVER_TRANSITION); {what}"
        );
        assert!((member.pressure_factor() - 27.472527472527474).abs() < 1e-9);
        let text = member.scene_toml_as(1, "crossover_transition_scenes", &description);
        let path = root.join("scenes").join(format!("{name}.toml"));
        std::fs::write(&path, text)?;
        println!("wrote {}", path.display());
    }
    Ok(())
}
