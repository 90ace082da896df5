//! A case: one scene on one mesh level with one cone, built from files through gmsh.

use crate::contact::{Interface, Method};
use crate::error::Result;
use crate::fe::Model;
use crate::mesh::{gmsh, msh};
use crate::scene::Scene;
use crate::solve::{Problem, Solution, SolverKind, Timings};
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

/// What one solve of a case gave and cost: the run summary that `solve` writes as
/// summary.csv and `study speed` extends with its own columns.
#[derive(Debug, Clone)]
pub struct RunSummary {
    /// Scene name.
    pub scene: String,
    /// Cone.
    pub method: Method,
    /// Solver.
    pub solver: SolverKind,
    /// Mesh level.
    pub level: usize,
    /// Max element diameter over both bodies (length).
    pub h: f64,
    /// Free dofs.
    pub dofs: usize,
    /// Time steps.
    pub steps: usize,
    /// Iterations in total (Newton iterations; inner solves for the fixed-point solvers).
    pub iterations: usize,
    /// Largest iteration count of one step.
    pub max_step_iterations: usize,
    /// Active-set changes summed over the steps.
    pub active_set_changes: usize,
    /// Largest interpenetration at T (length).
    pub max_penetration: f64,
    /// Contact fraction at T.
    pub contact_fraction: f64,
    /// Plastic fraction at T.
    pub plastic_fraction: f64,
    /// Seconds generating (or fetching) and reading the mesh.
    pub mesh_s: f64,
    /// Seconds building the model, interface and constraint rows.
    pub model_s: f64,
    /// Wall time of the time loop (s), without the solver's one-off set-up.
    pub time_loop_s: f64,
    /// Where the solver's time went.
    pub timings: Timings,
    /// The floor measured on the same problem (s), when measured.
    pub floor_s: Option<f64>,
    /// The process's peak resident memory when the summary was taken (GiB), where known.
    pub peak_rss_gib: Option<f64>,
}

impl RunSummary {
    /// Summarize `sol`, the solution of `case` by `solver`.
    pub fn new(case: &Case, solver: SolverKind, sol: &Solution, floor_s: Option<f64>) -> Self {
        let p = &case.problem;
        let last = sol.last();
        RunSummary {
            scene: p.model.scene.name.clone(),
            method: p.method,
            solver,
            level: case.level,
            h: case.h,
            dofs: p.model.n_free,
            steps: sol.reports.len(),
            iterations: sol.iterations(),
            max_step_iterations: sol.max_step_iterations(),
            active_set_changes: sol.active_set_changes(),
            max_penetration: crate::metrics::max_penetration(p, last),
            contact_fraction: crate::metrics::contact_fraction(p, last),
            plastic_fraction: crate::metrics::plastic_fraction(p, last),
            mesh_s: case.mesh_s,
            model_s: case.setup_s,
            time_loop_s: sol.wall_s,
            timings: sol.timings,
            floor_s,
            peak_rss_gib: peak_rss_gib(),
        }
    }

    /// Time loop over floor.
    pub fn ratio_to_floor(&self) -> Option<f64> {
        self.floor_s.map(|f| self.time_loop_s / f)
    }
}

/// The process's peak resident set size (GiB), from /proc/self/status.
pub fn peak_rss_gib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / (1024.0 * 1024.0))
}
