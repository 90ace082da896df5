//! A case: one scene on one mesh level with one cone, built from files through gmsh.

use crate::contact::{Interface, Method};
use crate::error::Result;
use crate::fe::Model;
use crate::mesh::{gmsh, msh};
use crate::scene::Scene;
use crate::solve::Problem;
use std::time::Instant;

/// A built case with its provenance and set-up costs.
#[derive(Debug, Clone)]
pub struct Case {
    /// The discrete problem.
    pub problem: Problem,
    /// Refinement level (0 = gmsh's own mesh).
    pub level: usize,
    /// Max element diameter over both bodies.
    pub h: f64,
    /// gmsh and .geo provenance.
    pub mesh: gmsh::GeneratedMesh,
    /// Seconds to generate (or fetch) and read the mesh.
    pub mesh_s: f64,
    /// Seconds to build the model, interface and constraint rows.
    pub setup_s: f64,
}

impl Case {
    /// Mesh `scene` at `level` (gmsh parameters from the scene, overridden by `params`),
    /// and build the problem for `method`.
    pub fn build(
        scene: &Scene,
        level: usize,
        method: Method,
        params: &[(String, f64)],
    ) -> Result<Self> {
        let t0 = Instant::now();
        let mut all: Vec<(String, f64)> = scene
            .parameters
            .iter()
            .map(|(k, v)| (k.clone(), *v))
            .collect();
        for (k, v) in params {
            match all.iter_mut().find(|(kk, _)| kk == k) {
                Some(e) => e.1 = *v,
                None => all.push((k.clone(), *v)),
            }
        }
        let generated = gmsh::generate(&scene.geo, &all, level)?;
        let raw = msh::read_msh(&generated.path)?;
        let mesh_s = t0.elapsed().as_secs_f64();
        let t1 = Instant::now();
        let model = Model::new(scene, &raw, &generated.path)?;
        let interface = Interface::new(&model, &raw)?;
        let h = model.h();
        let problem = Problem::new(model, interface, method);
        Ok(Case {
            problem,
            level,
            h,
            mesh: generated,
            mesh_s,
            setup_s: t1.elapsed().as_secs_f64(),
        })
    }
}
