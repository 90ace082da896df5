//! What `export` and `grade` share: a scene's problem on a mesh family, from a study (its
//! mesh family, sizes and steps) or from the scene itself.

use crate::case::Case;
use crate::contact::Method;
use crate::error::{Error, Result};
use crate::scene::Scene;
use crate::verify::study_file::LoadedStudy;

/// Where the problem comes from.
#[derive(Debug, Clone)]
pub enum Source {
    /// A study: its scene, mesh family and steps, so the meshes are those of its report.
    Study(String),
    /// A scene with its own mesh sizes and steps.
    Scene(String),
}

/// A scene's problem on a mesh family: what export and grade share.
pub struct Family {
    /// The scene.
    pub scene: Scene,
    /// The study, if the family is a study's.
    pub study: Option<String>,
    /// gmsh parameters of level 0 (the scene's own where empty).
    pub params: Vec<(String, f64)>,
    /// Time steps.
    pub steps: usize,
    /// The command-line option that named the source, for errors.
    pub option: &'static str,
}

impl Family {
    /// The study's or the scene's family; a scene without an exact solution is refused.
    pub fn resolve(source: &Source) -> Result<Self> {
        let family = match source {
            Source::Study(name) => {
                let study = LoadedStudy::load(name)?;
                Family {
                    params: study.file.family_parameters(),
                    steps: study.file.steps,
                    study: Some(study.name),
                    scene: study.scene,
                    option: "--study",
                }
            }
            Source::Scene(name) => {
                let scene = Scene::load(name)?;
                Family {
                    params: Vec::new(),
                    steps: scene.steps,
                    study: None,
                    scene,
                    option: "--scene",
                }
            }
        };
        if family.scene.exact.is_none() {
            let with: Vec<String> = crate::scene::builtin_names()
                .into_iter()
                .filter(|n| Scene::load(n).is_ok_and(|s| s.exact.is_some()))
                .collect();
            return Err(Error::input(
                &family.scene.file,
                "exact",
                format!(
                    "scene '{}' has no exact solution, so a solution of it cannot be graded; use a scene with one ({}), or a study on one",
                    family.scene.name,
                    with.join(", ")
                ),
            ));
        }
        Ok(family)
    }

    /// The case of `level` (mortar's constraint rows; only the mesh, model and interface
    /// are used), with the mesh as gmsh wrote it.
    pub fn case(&self, level: usize) -> Result<(Case, crate::mesh::RawMesh)> {
        let (generated, raw) = Case::mesh(&self.scene, level, &self.params)?;
        let case = Case::on_mesh(
            &self.scene,
            level,
            Method::reference(),
            generated,
            raw.clone(),
        )?;
        Ok((case, raw))
    }

    /// The model of `level`'s mesh alone (no contact rows, no checks of the exact solution:
    /// what grade needs of the scene's own mesh), with the mesh as gmsh wrote it.
    pub fn model(&self, level: usize) -> Result<(crate::fe::Model, crate::mesh::RawMesh)> {
        let (generated, raw) = Case::mesh(&self.scene, level, &self.params)?;
        let model = crate::fe::Model::new(&self.scene, &raw, &generated.path)?;
        Ok((model, raw))
    }

    /// t_1 .. t_N.
    pub fn times(&self) -> Vec<f64> {
        (1..=self.steps)
            .map(|n| self.scene.final_time * n as f64 / self.steps as f64)
            .collect()
    }

    /// `contact-rates solve` of `level` on this family's mesh and steps.
    pub fn solve_command(&self, level: usize) -> String {
        let sets: String = self
            .params
            .iter()
            .map(|(k, v)| format!(" --set {k}={v}"))
            .collect();
        format!(
            "contact-rates solve --scene {} --level {level} --steps {}{sets}",
            self.scene.name, self.steps
        )
    }
}
