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
    /// Warnings about the scene (e.g. a body free to move), for the user.
    pub warnings: Vec<String>,
}

/// Warnings for bodies that neither a support nor the contact holds: for each displacement
/// component a body's clamps and rollers leave free, the net load at T must press the body
/// against Gamma_C (contact pushes body b along -nu^b) or the body can move freely.
pub fn support_warnings(
    model: &Model,
    interface: &Interface,
    raw: &crate::mesh::RawMesh,
) -> Result<Vec<String>> {
    let sc = &model.scene;
    let f = model.load(sc.final_time)?;
    let mut out = Vec::new();
    for b in 0..2 {
        let mesh = &model.meshes[b];
        let mut held = [false; 2];
        for c in &sc.clamps {
            if !mesh.curve_edges(raw, c).is_empty() {
                held = [true, true];
            }
        }
        for r in &sc.rollers {
            if !mesh.curve_edges(raw, &r.curve).is_empty() {
                held[r.component] = true;
            }
        }
        let range = model.node_offset[b]..model.node_offset[b] + mesh.nodes.len();
        let load = [0, 1].map(|c| range.clone().map(|n| f[2 * n + c]).sum::<f64>());
        let scale = load[0].abs().max(load[1].abs()).max(f64::MIN_POSITIVE);
        for c in 0..2 {
            if held[c] {
                continue;
            }
            let pressed = interface.pieces.iter().any(|p| {
                let nu = if b == 0 { p.normal[c] } else { -p.normal[c] };
                nu * load[c] > 1e-9 * scale
            });
            if !pressed {
                out.push(format!(
                    "{}: body '{}' has no clamp or roller holding u_{} and its net load at T ({:.3e}) does not press it against Gamma_C in that direction: it is free to move; add a roller or a clamp",
                    sc.file.display(),
                    sc.bodies[b].surface,
                    ["x", "y"][c],
                    load[c]
                ));
            }
        }
    }
    Ok(out)
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
        let warnings = support_warnings(&model, &interface, &raw)?;
        let problem = Problem::new(model, interface, method);
        Ok(Case {
            problem,
            level,
            h,
            mesh: generated,
            mesh_s,
            setup_s: t1.elapsed().as_secs_f64(),
            warnings,
        })
    }
}
