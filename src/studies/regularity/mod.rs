//! The `regularity` studies: how each cone's rates follow the regularity of the solution at
//! the transition point c between contact and separation, in three mesh families:
//! - `regularity` ([`ALIGNED`]): c a node of both meshes at every level;
//! - `regularity-unaligned` ([`UNALIGNED`]): c a node of neither trace, 1/3 of its segment
//!   from the nearest node on both at every level (its position alternates between 1/3 and
//!   2/3 under halving, so each parity of levels is judged as well as the whole);
//! - `regularity-graded` ([`GRADED`]): each level meshed by gmsh with sizes graded toward c
//!   (beta < 1), rates in h and in dofs beside the uniform family's.
//!
//! [`run`] reads like the description of the study:
//! 1. for each beta of the family, the manufactured solution with a singular part
//!    r^beta Phi_l(theta) at c (`analytical::singular`; the scenes and study files are
//!    written by `examples/regularity_scenes.rs`) is solved by both cones on the family's
//!    levels and measured against itself (the convergence study of
//!    studies/FAMILY/beta-BETA.toml);
//! 2. where c sits among the trace nodes is measured at every level ([`placement`]);
//! 3. each quantity's rate is set beside the best a uniform P1 mesh can give
//!    ([`best_rate`]): min(1, beta) for the H1 and theorem norms, min(beta, 3/2) for the
//!    stress along Gamma_C, min(beta - 1/2, 2) for the pressure in L2(Gamma_C);
//! 4. the report leads with where the cones differ, and marks where Theorem 3.1's
//!    hypotheses (u in H^2, f in L2: beta > 1) fail.

pub mod families;
pub mod report;
pub mod results;

use crate::analytical::singular::Placement;
use crate::contact::Interface;
use crate::error::Result;
use crate::scene::Scene;
use crate::studies::convergence::{self, StudyResult, best_pressure_rate};
use crate::verify::kind::{Found, Kind};
use crate::verify::quantity::Quantity;
use crate::verify::study_file::StudyFile;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// One mesh family of the regularity studies.
#[derive(Debug)]
pub struct Family {
    /// The study's name, its report folder and the prefix of its scenes.
    pub name: &'static str,
    /// The betas of the study.
    pub betas: &'static [f64],
    /// The levels of each beta's study.
    pub levels: &'static [usize],
    /// Where c sits among the nodes.
    pub placement: Placement,
    /// Whether each parity of levels is judged on its own (c's position alternates).
    pub parity: bool,
}

/// c a node of both meshes, levels 0-5 of uniform splitting.
pub const ALIGNED: Family = Family {
    name: "regularity",
    betas: BETAS,
    levels: LEVELS,
    placement: Placement::Aligned,
    parity: false,
};

/// c at 1/3 of a segment of both traces at every level, levels 0-7 of uniform splitting.
pub const UNALIGNED: Family = Family {
    name: "regularity-unaligned",
    betas: &[0.75, 1.25, 1.5, 2.0],
    levels: &[0, 1, 2, 3, 4, 5, 6, 7],
    placement: Placement::Unaligned,
    parity: true,
};

/// The grading exponent of [`GRADED`]: element size h (r / R)^(1 - mu) near c. Any
/// mu < beta gives the H1 error h on graded meshes for r^beta (Babuska's grading); 1/2 is
/// below every graded beta (0.6 and up), keeps the smallest elements at h^2 / R and the
/// element count O(h^-2).
pub const GRADED_MU: f64 = 0.5;

/// c a node of both meshes, each level meshed by gmsh graded toward c, levels 0-5.
pub const GRADED: Family = Family {
    name: "regularity-graded",
    betas: &[0.6, 0.75, 0.9],
    levels: LEVELS,
    placement: Placement::Graded { mu: GRADED_MU },
    parity: false,
};

/// The kind: built in (`study regularity`).
pub const KIND: Kind = Kind {
    name: "regularity",
    description: "Rates of both cones against the regularity beta of the contact transition (u ~ r^beta there), beta from 0.6 to 2",
    found: Found::BuiltIn,
    shards: false,
    run: |_, _| Ok(Some(Box::new(run(&ALIGNED)?))),
    rejudge: Some(|_, dir| Ok(Box::new(rejudge(&ALIGNED, dir)?))),
    results: Some(results::section),
};

/// The kind `study regularity-unaligned`.
pub const UNALIGNED_KIND: Kind = Kind {
    name: "regularity-unaligned",
    description: "The regularity study with the transition point off the nodes of both meshes (1/3 of a segment at every level), levels 0-7, each parity judged",
    found: Found::BuiltIn,
    shards: false,
    run: |_, _| Ok(Some(Box::new(run(&UNALIGNED)?))),
    rejudge: Some(|_, dir| Ok(Box::new(rejudge(&UNALIGNED, dir)?))),
    results: Some(results::unaligned_section),
};

/// The kind `study regularity-graded`.
pub const GRADED_KIND: Kind = Kind {
    name: "regularity-graded",
    description: "The regularity study for beta < 1 on meshes graded toward the transition point (each level meshed by gmsh), rates in h and in dofs beside the uniform family's",
    found: Found::BuiltIn,
    shards: false,
    run: |_, _| Ok(Some(Box::new(run(&GRADED)?))),
    rejudge: Some(|_, dir| Ok(Box::new(rejudge(&GRADED, dir)?))),
    results: Some(results::graded_section),
};

/// The betas of the aligned study.
pub const BETAS: &[f64] = &[0.6, 0.75, 0.9, 1.25, 1.5, 2.0];

/// The refinement levels of each beta's aligned study (h = 0.3 / 2^level).
pub const LEVELS: &[usize] = &[0, 1, 2, 3, 4, 5];

impl Family {
    /// The scene of one beta.
    pub fn scene_name(&self, beta: f64) -> String {
        format!("{}-{beta:.2}", self.name)
    }

    /// The study file of one beta.
    pub fn study_path(&self, beta: f64) -> PathBuf {
        crate::verify::study_file::builtin_dir()
            .join(self.name)
            .join(format!("beta-{beta:.2}.toml"))
    }
}

impl Family {
    /// The best rate in h the family's meshes can give for `quantity` at `beta`: on uniform
    /// meshes [`best_rate`]; on meshes graded toward c with mu < beta, 1 for the H1 and
    /// theorem norms and the stress in L2 (the graded best approximation of r^beta), None
    /// for the others (the study does not say).
    pub fn best_rate(&self, quantity: Quantity, beta: f64) -> Option<f64> {
        match self.placement {
            Placement::Graded { .. } => match quantity {
                Quantity::Theorem | Quantity::H1U | Quantity::L2Stress => Some(1.0),
                _ => None,
            },
            _ => best_rate(quantity, beta),
        }
    }
}

/// The aligned family's scene of one beta.
pub fn scene_name(beta: f64) -> String {
    ALIGNED.scene_name(beta)
}

/// The aligned family's study file of one beta.
pub fn study_path(beta: f64) -> PathBuf {
    ALIGNED.study_path(beta)
}

/// The best rate in h a uniform P1 mesh can give for `quantity` when u ~ r^beta at one
/// point of Gamma_C: None where the study does not say.
/// - H1 and theorem norms, stress in L2: min(1, beta) (the gradient's best approximation on
///   the O(1) triangles at the point is h^beta, elsewhere h);
/// - stress in the band of triangles along Gamma_C: min(beta, 3/2) (pointwise h in a band of
///   area O(h), h^(beta-1) on the O(1) triangles of area h^2 at the point);
/// - pressure in L2(Gamma_C): min(beta - 1/2, 2) (p ~ dist^(beta-1)).
pub fn best_rate(quantity: Quantity, beta: f64) -> Option<f64> {
    match quantity {
        Quantity::Theorem | Quantity::H1U | Quantity::L2Stress => Some(beta.min(1.0)),
        Quantity::BandStress => Some(beta.min(1.5)),
        Quantity::L2Pressure => Some(best_pressure_rate(Some(beta), false)),
        _ => None,
    }
}

/// Whether Theorem 3.1's hypotheses hold (u in H^2 and f in L2 need beta > 1).
pub fn theorem_applies(beta: f64) -> bool {
    beta > 1.0
}


/// Where a transition point sits at one level: one row of placement.csv.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PlacementRow {
    /// The scene.
    pub scene: String,
    /// The mesh level.
    pub level: usize,
    /// The transition point's abscissa.
    pub transition: f64,
    /// Its distance to the nearest node of the slave trace, over the length of the slave
    /// segment that holds it (0 at a node, 1/2 at a midpoint).
    pub slave_offset: f64,
    /// The same on the master trace.
    pub master_offset: f64,
}

/// Where the transition point `c` of `scene` sits among the trace nodes at each of
/// `levels`, on the meshes of the gmsh parameters `params` (from the cache).
pub fn placement(
    scene: &Scene,
    c: [f64; 2],
    params: &[(String, f64)],
    levels: &[usize],
) -> Result<Vec<PlacementRow>> {
    levels
        .iter()
        .map(|&level| {
            let (generated, raw) = crate::case::Case::mesh(scene, level, params)?;
            let model = crate::fe::Model::new(scene, &raw, &generated.path)?;
            let offset = Interface::new(&model, &raw)?.node_offset(c).ok_or_else(|| {
                crate::error::Error::input(
                    &scene.file,
                    "exact",
                    format!("the transition point ({}, {}) is not on Gamma_C", c[0], c[1]),
                )
            })?;
            Ok(PlacementRow {
                scene: scene.name.clone(),
                level,
                transition: c[0],
                slave_offset: offset.slave,
                master_offset: offset.master,
            })
        })
        .collect()
}

/// What the study measured: one convergence study per beta.
pub struct Regularity {
    /// The family.
    pub family: &'static Family,
    /// (beta, its convergence study), in the order of the family's betas.
    pub members: Vec<(f64, StudyResult)>,
    /// Where c sits at every level of every beta, and where contact-mms's transition sits.
    pub placement: Vec<PlacementRow>,
}

/// contact-mms's transition abscissa (scenes/contact-mms.toml: contact on [0, a)).
pub const CONTACT_MMS_TRANSITION: f64 = 0.5871;

/// Where c sits in each member of `family` (its study file's meshes), and, for comparison,
/// where contact-mms's transition sits on rates-exact's meshes.
fn family_placement(family: &Family) -> Result<Vec<PlacementRow>> {
    let mut rows = Vec::new();
    for &beta in family.betas {
        let file = StudyFile::load(&family.study_path(beta))?;
        let scene = Scene::load(&family.scene_name(beta))?;
        let c = scene
            .exact
            .as_ref()
            .and_then(|e| e.singular.as_ref())
            .map_or([CONTACT_MMS_TRANSITION, 1.0], |s| s.point);
        rows.extend(placement(&scene, c, &file.family_parameters(), family.levels)?);
    }
    let path = crate::verify::study_file::builtin_dir().join("rates-exact.toml");
    let file = StudyFile::load(&path)?;
    let scene = Scene::load(&file.scene)?;
    rows.extend(placement(
        &scene,
        [CONTACT_MMS_TRANSITION, 1.0],
        &file.family_parameters(),
        &file.mesh.levels,
    )?);
    Ok(rows)
}

/// The report `dir` judged again from each beta's CSVs (its `beta-BETA/` folders),
/// without solving.
pub fn rejudge(family: &'static Family, dir: &Path) -> Result<Regularity> {
    let mut members = Vec::new();
    for &beta in family.betas {
        let path = family.study_path(beta);
        let member = dir.join(format!("beta-{beta:.2}"));
        members.push((beta, convergence::rejudge(&path.display().to_string(), &member)?));
    }
    let placement = crate::verify::table::read(&dir.join("placement.csv"))?;
    Ok(Regularity {
        family,
        members,
        placement,
    })
}

/// Run the study of `family`.
pub fn run(family: &'static Family) -> Result<Regularity> {
    let mut members = Vec::new();
    for &beta in family.betas {
        let path = family.study_path(beta);
        members.push((beta, convergence::run(&path.display().to_string())?));
    }
    Ok(Regularity {
        family,
        members,
        placement: family_placement(family)?,
    })
}
