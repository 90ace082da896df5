//! `study speed`: what each accuracy costs. Every run's wall time is split into its parts
//! and compared with the floor measured in the same run on the same matrix (assembly once,
//! one numeric factorization, two triangular solves per time step).

use super::{error, solve_case};
use crate::case::Case;
use crate::contact::Method;
use crate::error::Result;
use crate::scene::Scene;
use crate::solve::{self, Solution, SolverKind};
use serde::Serialize;

/// One row of speed.csv.
#[derive(Debug, Clone, Serialize)]
pub struct SpeedRow {
    /// Scene.
    pub scene: String,
    /// Cone.
    pub method: String,
    /// Solver.
    pub solver: String,
    /// Mesh level.
    pub level: usize,
    /// Free dofs.
    pub dofs: usize,
    /// Time steps.
    pub steps: usize,
    /// Iterations in total (Newton iterations; inner solves for `paper`).
    pub iterations: usize,
    /// Numeric factorizations.
    pub factorizations: usize,
    /// Wall time of the time loop (s).
    pub wall_s: f64,
    /// Floor measured in the same run (s).
    pub floor_s: f64,
    /// wall_s / floor_s.
    pub ratio_to_floor: f64,
    /// Seconds in factorizations.
    pub factor_s: f64,
    /// Seconds in triangular solves (including GMRES).
    pub solve_s: f64,
    /// Seconds assembling.
    pub assembly_s: f64,
    /// Seconds in constitutive updates.
    pub constitutive_s: f64,
    /// Relative theorem-norm error against the reference (empty when the level is too close
    /// to the reference to measure).
    pub error: Option<f64>,
}

/// What `study speed` measured.
#[derive(Debug, Clone)]
pub struct SpeedResult {
    /// All runs.
    pub rows: Vec<SpeedRow>,
    /// Reference level and dofs.
    pub reference: (usize, usize),
    /// Total wall time (s).
    pub wall_s: f64,
}

/// Newton levels, paper levels, reference level and steps of the speed study.
pub const NEWTON_LEVELS: [usize; 6] = [0, 1, 2, 3, 4, 5];
/// Levels at which the paper's solver is timed.
pub const PAPER_LEVELS: [usize; 4] = [0, 1, 2, 3];
/// Reference level (matching meshes).
pub const REFERENCE_LEVEL: usize = 6;
/// Time steps.
pub const STEPS: usize = 4;

fn row(
    scene: &Scene,
    case: &Case,
    kind: SolverKind,
    sol: &Solution,
    floor_s: f64,
    error: Option<f64>,
) -> SpeedRow {
    let t = &sol.timings;
    SpeedRow {
        scene: scene.name.clone(),
        method: case.problem.method.name().into(),
        solver: kind.name().into(),
        level: case.level,
        dofs: case.problem.model.n_free,
        steps: sol.reports.len(),
        iterations: sol.iterations(),
        factorizations: t.factorizations,
        wall_s: sol.wall_s,
        floor_s,
        ratio_to_floor: sol.wall_s / floor_s,
        factor_s: t.factor_s,
        solve_s: t.solve_s,
        assembly_s: t.assembly_s,
        constitutive_s: t.constitutive_s,
        error,
    }
}

/// Run the speed study on the `rates` scene (h1/h2 = 1.4142 as in `study rates`).
pub fn run() -> Result<SpeedResult> {
    let t0 = std::time::Instant::now();
    let scene = Scene::load("rates")?;
    let fam = vec![
        ("h_upper".to_string(), 0.3),
        ("h_lower".to_string(), 0.3 / 1.4142),
    ];
    let mut refp = fam.clone();
    refp.push(("matching".to_string(), 1.0));
    let rcase = Case::build(&scene, REFERENCE_LEVEL, Method::Mortar, &refp)?;
    let (rsol, _) = solve_case(&rcase, SolverKind::Newton, STEPS)?;
    let mut rows = Vec::new();
    for method in [Method::Mortar, Method::Nts] {
        for &level in &NEWTON_LEVELS {
            let case = Case::build(&scene, level, method, &fam)?;
            for kind in [SolverKind::Newton, SolverKind::Paper] {
                if kind == SolverKind::Paper && !PAPER_LEVELS.contains(&level) {
                    continue;
                }
                let (sol, _) = solve_case(&case, kind, STEPS)?;
                let floor_s = solve::floor_time(&case.problem, STEPS)?;
                // Errors only where the reference is at least 3 levels finer.
                let err = (level + 3 <= REFERENCE_LEVEL)
                    .then(|| super::theorem_distance(&case, &sol, &rcase, &rsol));
                rows.push(row(&scene, &case, kind, &sol, floor_s, err));
            }
        }
    }
    let _ = error::norms;
    Ok(SpeedResult {
        rows,
        reference: (REFERENCE_LEVEL, rcase.problem.model.n_free),
        wall_s: t0.elapsed().as_secs_f64(),
    })
}
