//! Writes the `regularity` family: one scene per beta (scenes/regularity-BETA.toml, the
//! manufactured solution of `analytical::singular`) and one study file per beta
//! (studies/regularity/beta-BETA.toml, both cones against the exact solution), which the
//! built-in study `regularity` runs together.
//!
//! `cargo run --release --example regularity_scenes`

use contact_rates::analytical::singular::SingularContact;
use contact_rates::studies::regularity::{BETAS, LEVELS, scene_name, study_path};

fn main() -> std::io::Result<()> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    for &beta in BETAS {
        let member = SingularContact::new(beta);
        let scene = root
            .join("scenes")
            .join(format!("{}.toml", scene_name(beta)));
        std::fs::write(&scene, member.scene_toml(1))?;
        let study = study_path(beta);
        std::fs::create_dir_all(study.parent().expect("a folder"))?;
        // Theorem 3.1 needs u in H^2 and f in L2: beta > 1. Below, it claims no rate, and
        // the study asks only that the error converge (rate >= 0).
        let (mortar, nts, tolerance) = if beta > 1.0 {
            (0.75, 0.5, 0.05)
        } else {
            (0.0, 0.0, 0.0)
        };
        let levels: Vec<String> = LEVELS.iter().map(|l| l.to_string()).collect();
        std::fs::write(
            &study,
            format!(
                r#"# Written by `cargo run --release --example regularity_scenes`: do not edit by hand.
description = "Both cones on the singular manufactured solution with beta = {beta} (u ~ r^beta at the transition point) over {n} levels against the exact solution; part of the study `regularity`"
scene = "{scene}"
methods = ["mortar", "nts"]
solver = "newton"
steps = 1
quantities = ["theorem", "h1_u", "l2_stress", "band_stress", "l2_pressure", "cone_distance"]

[mesh]
size_parameter_1 = "h_upper"
size_parameter_2 = "h_lower"
coarsest = 0.3
ratio = 1.4142
levels = [{levels}]

[reference]
exact = true

# {why}
[thresholds]
mortar = {mortar}
nts = {nts}
tolerance = {tolerance}
"#,
                n = LEVELS.len(),
                scene = scene_name(beta),
                levels = levels.join(", "),
                why = if beta > 1.0 {
                    "Theorem 3.1 applies (u in H^2, f in L2): its rates."
                } else {
                    "Theorem 3.1 does not apply (u not in H^2; f not in L2 for beta <= 1): only convergence is asked."
                },
            ),
        )?;
        println!("wrote {} and {}", scene.display(), study.display());
    }
    Ok(())
}
