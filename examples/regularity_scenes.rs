//! Writes the regularity families (aligned, unaligned, graded): one scene per family and
//! beta (scenes/FAMILY-BETA.toml, the manufactured solution of `analytical::singular` with
//! its transition point placed as the family places it) and one study file per beta
//! (studies/FAMILY/beta-BETA.toml, both cones against the exact solution), which the
//! built-in study FAMILY (`regularity`, `regularity-unaligned`, `regularity-graded`) runs
//! together.
//!
//! It also writes the `gap` study: the unaligned beta = 1.5 member posed across the
//! initial gap of [`ClosingGap::STUDY`] (scenes/gap.toml, studies/gap.toml), set beside
//! regularity-unaligned's beta = 1.5 on the same meshes.
//!
//! `cargo run --release --example regularity_scenes`

use contact_rates::analytical::singular::{ClosingGap, Placement, SingularContact};
use contact_rates::studies::regularity::{ALIGNED, Family, GRADED, UNALIGNED};

fn main() -> std::io::Result<()> {
    for family in [&ALIGNED, &UNALIGNED, &GRADED] {
        write_family(family)?;
    }
    write_gap()
}

/// The `gap` study: regularity-unaligned-1.50 across g0 = x^2 / (2 R), closed on all of
/// Gamma_C by body 1's added displacement, so that the contact zone, the pressure and the
/// opening beyond c are the member's: what the gap adds is measured beside it.
fn write_gap() -> std::io::Result<()> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let member = SingularContact::placed(1.5, Placement::Unaligned);
    let scene = root.join("scenes").join("gap.toml");
    std::fs::write(&scene, member.gap_scene_toml(&ClosingGap::STUDY))?;
    let levels: Vec<String> = UNALIGNED.levels.iter().map(|l| l.to_string()).collect();
    let study = root.join("studies").join("gap.toml");
    std::fs::write(
        &study,
        format!(
            r#"# Written by `cargo run --release --example regularity_scenes`: do not edit by hand.
description = "The three methods across an initial gap g0 = x^2 / (2 R), R = {radius}, closed on [0, c) and opening like dist^1.5 beyond (scene gap: regularity-unaligned-1.50 with body 1 displaced by the closing part), over {n} levels of uniform refinement against the exact solution, beside regularity-unaligned-1.50 on the same meshes"
scene = "gap"
methods = ["mortar", "nts", "lac"]
solver = "newton"
steps = 1
quantities = ["theorem", "h1_u", "l2_stress", "band_stress", "l2_pressure", "contact_edge", "max_penetration", "l2_penetration", "discrete_gap", "cone_distance"]
beside = "regularity-unaligned/beta-1.50"

[mesh]
size_parameter_1 = "h_upper"
size_parameter_2 = "h_lower"
coarsest = 0.3
ratio = 1.4142
levels = [{levels}]

[reference]
exact = true

# Theorem 3.1 is stated for bodies touching (no gap); its rates are taken as the expectation
# for a smooth g0, whose discretization (O(h^2) at the nodes) lies below them: a claim under test.
[thresholds]
mortar = {{ rate = 0.75, source = "Theorem 3.1 of Fernandez, Hild and Viano (K_h^pi, h^(3/4), u in H^2; stated without a gap: a smooth g0 taken to leave it unchanged, a claim under test)" }}
nts = {{ rate = 0.5, source = "Theorem 3.1 of Fernandez, Hild and Viano (K_h^I, h^(1/2); stated without a gap, as for mortar)" }}
lac = {{ rate = 1.0, source = "Drouet and Hild, Numer. Math. 136 (2017): h^1 for elastic bodies with P1 and u in H^2, read from its abstract (no gap; a claim under test)" }}
tolerance = 0.05
"#,
            radius = ClosingGap::STUDY.radius,
            n = UNALIGNED.levels.len(),
            levels = levels.join(", "),
        ),
    )?;
    println!("wrote {} and {}", scene.display(), study.display());
    Ok(())
}

/// What a family's study files say of its meshes (nothing for the aligned family's).
fn meshes(family: &Family) -> &'static str {
    match family.placement {
        Placement::Aligned => "",
        Placement::Unaligned => {
            " of uniform refinement with the transition point a node of neither trace (1/3 of a segment of both at every level)"
        }
        Placement::Graded { .. } => {
            " of meshes graded toward the transition point, each level meshed by gmsh (not nested)"
        }
    }
}

fn write_family(family: &Family) -> std::io::Result<()> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    for &beta in family.betas {
        let member = SingularContact::placed(beta, family.placement);
        let scene = root
            .join("scenes")
            .join(format!("{}.toml", family.scene_name(beta)));
        std::fs::write(&scene, member.scene_toml(1))?;
        let study = family.study_path(beta);
        std::fs::create_dir_all(study.parent().expect("a folder"))?;
        // Theorem 3.1 needs u in H^2 and f in L2: beta > 1. Below, it claims no rate, and
        // the study asks only that the error converge (rate >= 0).
        let (mortar, nts, tolerance) = if beta > 1.0 {
            (0.75, 0.5, 0.05)
        } else {
            (0.0, 0.0, 0.0)
        };
        let graded = matches!(family.placement, Placement::Graded { .. });
        let (mortar_source, nts_source) = if beta > 1.0 {
            (
                "Theorem 3.1 of Fernandez, Hild and Viano: K_h^pi, h^(3/4) for u in W^(1,inf)(0,T; H^2), Gamma_C straight, sigma_nu in H^(1/2)(Gamma_C) (Lemma 3.1)",
                "Theorem 3.1 of Fernandez, Hild and Viano: K_h^I, h^(1/2), the same hypotheses",
            )
        } else {
            (
                "Theorem 3.1 does not apply (u not in H^2; f not in L2 for beta <= 1): only convergence is asked",
                "Theorem 3.1 does not apply (u not in H^2; f not in L2 for beta <= 1): only convergence is asked",
            )
        };
        // LAC: Drouet and Hild's estimate (elastic bodies, read from its abstract as h^1 for
        // u in H^2; its mesh hypotheses unread) where beta > 1 on uniform meshes; none else.
        let lac = match (beta > 1.0, graded) {
            (true, false) => "lac = { rate = 1.0, source = \"Drouet and Hild, Numer. Math. 136 (2017): optimal for elastic bodies with P1, read as h^1 for u in H^2 (abstract only: the theorem and its mesh hypotheses are a claim under test)\" }".to_string(),
            (true, true) => "lac = { none = \"graded meshes: Drouet and Hild's estimate is taken for quasi-uniform meshes\" }".to_string(),
            (false, false) => "lac = { none = \"beta <= 1: u is not in H^2, below the regularity of Drouet and Hild's optimal rate\" }".to_string(),
            (false, true) => "lac = { none = \"beta <= 1: u is not in H^2, below the regularity of Drouet and Hild's optimal rate; and the meshes are graded, not quasi-uniform\" }".to_string(),
        };
        let levels: Vec<String> = family.levels.iter().map(|l| l.to_string()).collect();
        std::fs::write(
            &study,
            format!(
                r#"# Written by `cargo run --release --example regularity_scenes`: do not edit by hand.
description = "The three methods on the singular manufactured solution with beta = {beta} (u ~ r^beta at the transition point) over {n} levels{meshes} against the exact solution; part of the study `{study}`"
scene = "{scene}"
methods = ["mortar", "nts", "lac"]
solver = "newton"
steps = 1
quantities = ["theorem", "h1_u", "l2_stress", "band_stress", "l2_pressure", "best_l2_pressure", "cone_distance"]

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
mortar = {{ rate = {mortar:?}, source = "{mortar_source}" }}
nts = {{ rate = {nts:?}, source = "{nts_source}" }}
{lac}
tolerance = {tolerance}
"#,
                n = family.levels.len(),
                meshes = meshes(family),
                study = family.name,
                scene = family.scene_name(beta),
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
