//! The speed study's manufactured scenes: the cost of a solve whose loads come from an
//! exact solution (a body force -div sigma(u) integrated across kinks and singular points),
//! from the cached mesh to the last step, against the same floor as every other row. A
//! plain scene's load is a few boundary integrals; a manufactured one evaluates its
//! expressions at every quadrature point of the mesh, which is what this table keeps in
//! view.

use super::{STEPS, repeats};
use crate::case::{Case, release_free_heap};
use crate::contact::Method;
use crate::error::Result;
use crate::scene::Scene;
use crate::solve::{self, SolverKind};
use crate::verify::solve_case;
use serde::{Deserialize, Serialize};

/// The manufactured scenes timed, with their gmsh sizes: `contact-mms` on the meshes of
/// `study rates-exact`, `regularity-1.50` (five fractional powers of one distance in its
/// body force, Gauss-Jacobi rules at its singular point) on its own.
pub const SCENES: [(&str, &[(&str, f64)]); 2] = [
    (
        "contact-mms",
        &[("h_upper", 0.3), ("h_lower", 0.21213406873143828)],
    ),
    ("regularity-1.50", &[]),
];

/// Levels timed (level 5: about 1.1e5 dofs).
pub const LEVELS: [usize; 2] = [4, 5];

/// One row of manufactured.csv: a manufactured scene's solve against its floor.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ManufacturedRecord {
    pub scene: String,
    pub level: usize,
    pub dofs: usize,
    pub steps: usize,
    /// The model built from the read mesh, its checks and the load at the final time,
    /// from scratch (no load cached): what a fresh `solve` pays before its solver (s).
    pub model_s: f64,
    /// The load's integral alone, from scratch (s).
    pub load_s: f64,
    /// Quadrature points of that integral (tractions' and body forces').
    pub load_points: usize,
    /// load_s per point (microseconds).
    pub load_per_point_us: f64,
    /// The solver's set-up and time loop (newton, mortar; s).
    pub solve_s: f64,
    /// The floor on the same mesh (s).
    pub floor_s: f64,
    /// (model_s + solve_s) / floor_s.
    pub ratio_to_floor: f64,
    pub repeats: usize,
}

/// Time every scene of [`SCENES`] at every level of [`LEVELS`]: each measurement the
/// fastest of [`repeats`] (model built anew, its load not cached, then solved; the floor
/// beside it).
pub fn run() -> Result<Vec<ManufacturedRecord>> {
    let mut rows = Vec::new();
    for (name, sizes) in SCENES {
        let scene = Scene::load(name)?;
        let sizes: Vec<(String, f64)> = sizes.iter().map(|(k, v)| (k.to_string(), *v)).collect();
        for level in LEVELS {
            rows.push(timed(&scene, name, level, &sizes)?);
        }
    }
    Ok(rows)
}

fn timed(scene: &Scene, name: &str, level: usize, sizes: &[(String, f64)]) -> Result<ManufacturedRecord> {
    // The mesh once into gmsh's cache, so that no measurement meshes.
    Case::mesh(scene, level, sizes)?;
    let mut best: Option<ManufacturedRecord> = None;
    let mut n = 1;
    let mut k = 0;
    while k < n {
        release_free_heap();
        crate::fe::forget_loads();
        let case = Case::build(scene, level, Method::reference(), sizes)?;
        let model = &case.problem.model;
        n = repeats(model.n_free);
        let (sol, _) = solve_case(&case, SolverKind::Newton, STEPS)?;
        let floor = solve::floor(&case.problem, STEPS)?;
        let t = std::time::Instant::now();
        let points = model.integrate_load_from_scratch(scene.final_time)?;
        let load_s = t.elapsed().as_secs_f64();
        let row = ManufacturedRecord {
            scene: name.to_string(),
            level,
            dofs: model.n_free,
            steps: STEPS,
            model_s: case.setup_s,
            load_s,
            load_points: points,
            load_per_point_us: 1e6 * load_s / points.max(1) as f64,
            solve_s: sol.wall_s + sol.timings.setup_s,
            floor_s: floor.seconds,
            ratio_to_floor: 0.0,
            repeats: n,
        };
        best = Some(match best {
            None => row,
            Some(b) => ManufacturedRecord {
                model_s: b.model_s.min(row.model_s),
                load_s: b.load_s.min(row.load_s),
                load_per_point_us: b.load_per_point_us.min(row.load_per_point_us),
                solve_s: b.solve_s.min(row.solve_s),
                floor_s: b.floor_s.min(row.floor_s),
                ..b
            },
        });
        k += 1;
    }
    let mut b = best.expect("at least one run");
    b.ratio_to_floor = (b.model_s + b.solve_s) / b.floor_s;
    Ok(b)
}
