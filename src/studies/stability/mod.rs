//! `study stability`: hard cases where naive solvers fail, each run with every solver and
//! both cones. A case where a solver fails is a result (converged = false, with its reason),
//! not an error. The error of a run is its largest nodal difference to the `newton` solution
//! of the same discrete problem, relative to the largest displacement.

pub mod report;
pub mod results;

use crate::verify::kind::{Found, Kind};

/// The kind: one built-in study, `study stability`.
pub const KIND: Kind = Kind {
    name: "stability",
    description: DESCRIPTION,
    found: Found::BuiltIn,
    shards: false,
    run: |_, _| Ok(Some(Box::new(run()?))),
    rejudge: None,
    results: Some(results::section),
};


use crate::case::Case;
use crate::contact::Method;
use crate::error::{Error, Result};
use crate::metrics;
use crate::scene::Scene;
use crate::solve::{self, Settings, Solution, SolverKind};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// One line for `study list`.
pub const DESCRIPTION: &str = "Hard cases (stiff viscosity, modulus contrast, mesh-size ratio, slivers, units, ...) with every solver and both cones";

/// The hard cases, each with what its report says about it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HardCase {
    /// k E / lambda swept from 1e-2 to 1e4.
    StiffViscosity,
    /// Young's modulus contrast between the bodies.
    ModulusContrast,
    /// h1/h2 from 1/16 to 16.
    MeshSizeRatio,
    /// The lower block carries the constraint.
    SwappedSlave,
    /// The patch scene's upper block, held vertically only by contact.
    HeldOnlyByContact,
    /// Interface nodes 1e-11 h apart.
    NearCoincidentNodes,
    /// Matching interface meshes.
    CoincidentNodes,
    /// Flat triangles along Gamma_C.
    Slivers,
    /// Lengths x 1e3, moduli x 1e6.
    UnitsRescaled,
    /// Newton's iterations per step at levels 0-5.
    NewtonAcrossLevels,
    /// One time step over [0, T].
    SingleStep,
    /// The paper's omega over 8 decades.
    OmegaSweep,
}

/// A case swept over a numeric parameter, plotted against it.
#[derive(Debug, Clone, Copy)]
pub struct Sweep {
    /// File stem of its plots.
    pub file: &'static str,
    /// Label of the swept parameter's axis.
    pub axis: &'static str,
}

impl HardCase {
    /// Name in stability.csv and the report.
    pub fn name(self) -> &'static str {
        match self {
            HardCase::StiffViscosity => "stiff viscosity",
            HardCase::ModulusContrast => "modulus contrast",
            HardCase::MeshSizeRatio => "mesh-size ratio",
            HardCase::SwappedSlave => "slave and master swapped",
            HardCase::HeldOnlyByContact => "held only by contact",
            HardCase::NearCoincidentNodes => "near-coincident nodes",
            HardCase::CoincidentNodes => "coincident nodes",
            HardCase::Slivers => "slivers",
            HardCase::UnitsRescaled => "units rescaled",
            HardCase::NewtonAcrossLevels => "newton iterations across levels",
            HardCase::SingleStep => "single time step",
            HardCase::OmegaSweep => "omega sweep",
        }
    }

    /// What the report says about the case (empty: its table speaks for itself).
    pub fn note(self) -> &'static str {
        match self {
            HardCase::StiffViscosity => {
                "k = 0.25, E = 100; lambda set so that k E / lambda sweeps 1e-2..1e4. The paper's fixed point (4.2)-(4.3) is a contraction only while k L < 1."
            }
            HardCase::ModulusContrast => "E of the lower block = 100 x E2/E1, upper block E = 100.",
            HardCase::MeshSizeRatio => {
                "Level 0 with h_upper = 0.2 sqrt(r), h_lower = 0.2 / sqrt(r)."
            }
            HardCase::Slivers => {
                "The upper block's first layer along Gamma_C is a structured strip (the `strip` parameter of meshes/two_blocks.geo), one triangle pair per contact edge: the thinner the strip, the flatter the triangles that carry the constraint. The largest aspect ratio (longest edge over the altitude onto it) is measured on the mesh."
            }
            HardCase::UnitsRescaled => {
                "scenes/rates-units.toml: the rates scene with lengths x 1e3 (gmsh writes the .msh scaled, `unit = 1000`), moduli, yield stress, viscosity and tractions x 1e6. `error` here is the largest nodal difference of u / 1e3 to the same solver's solution in the original units, relative to its largest displacement; the reason says whether the iterations per step are identical."
            }
            HardCase::NewtonAcrossLevels => {
                "The study rates family (h_upper = 0.3, h_lower = 0.3 / 1.4142), levels 0-5 (118 to 112,896 dofs): newton's iterations per step do not grow with h."
            }
            _ => "",
        }
    }

    /// The sweep plotted for this case, if any.
    pub fn sweep(self) -> Option<Sweep> {
        let sweep = |file, axis| Some(Sweep { file, axis });
        match self {
            HardCase::StiffViscosity => sweep("stiff_viscosity", "k E / lambda"),
            HardCase::OmegaSweep => sweep("omega_sweep", "omega / automatic omega"),
            HardCase::ModulusContrast => sweep("modulus_contrast", "E2 / E1"),
            HardCase::Slivers => sweep("slivers", "largest aspect ratio of a triangle"),
            _ => None,
        }
    }

    /// Every case.
    pub const ALL: [HardCase; 12] = [
        HardCase::StiffViscosity,
        HardCase::ModulusContrast,
        HardCase::MeshSizeRatio,
        HardCase::SwappedSlave,
        HardCase::HeldOnlyByContact,
        HardCase::NearCoincidentNodes,
        HardCase::CoincidentNodes,
        HardCase::Slivers,
        HardCase::UnitsRescaled,
        HardCase::NewtonAcrossLevels,
        HardCase::SingleStep,
        HardCase::OmegaSweep,
    ];

    /// The swept cases in the order their plots are drawn.
    pub const SWEEPS: [HardCase; 4] = [
        HardCase::StiffViscosity,
        HardCase::OmegaSweep,
        HardCase::ModulusContrast,
        HardCase::Slivers,
    ];
}

impl Serialize for HardCase {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for HardCase {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        HardCase::ALL
            .into_iter()
            .find(|c| c.name() == name)
            .ok_or_else(|| serde::de::Error::custom(format!("unknown hard case '{name}'")))
    }
}

/// One row of stability.csv.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct StabilityRow {
    /// The case.
    pub case: HardCase,
    /// Swept parameter and its value, e.g. "k E / lambda = 1e2".
    pub parameter: String,
    /// Numeric value of the parameter (for plots).
    pub value: f64,
    /// Cone.
    pub method: Method,
    /// Solver.
    pub solver: SolverKind,
    /// Whether the solver converged on every step.
    pub converged: bool,
    /// Why it stopped (for a failure, the solver's message).
    pub reason: String,
    /// Largest iteration count of one step.
    pub max_step_iterations: usize,
    /// Mean iterations per step.
    pub mean_step_iterations: f64,
    /// Relative nodal difference to newton's solution of the same problem (blank if none).
    #[serde(
        serialize_with = "crate::io::finite_or_empty",
        deserialize_with = "crate::io::empty_as_nan"
    )]
    pub error: f64,
    /// Largest interpenetration over the history (length units; blank if not converged).
    #[serde(
        serialize_with = "crate::io::finite_or_empty",
        deserialize_with = "crate::io::empty_as_nan"
    )]
    pub max_penetration: f64,
    /// Largest displacement component max_i |u_i| over the history (length units; blank if
    /// not converged): the penetration's scale.
    #[serde(
        serialize_with = "crate::io::finite_or_empty",
        deserialize_with = "crate::io::empty_as_nan",
        default = "nan"
    )]
    pub max_displacement: f64,
    /// The limit-load check at the final time ([`crate::metrics::limit_load_ratio`]): above
    /// 1 the load is past the limit load (blank for an elastic scene).
    #[serde(
        serialize_with = "crate::io::finite_or_empty",
        deserialize_with = "crate::io::empty_as_nan",
        default = "nan"
    )]
    pub limit_load_ratio: f64,
    /// Wall time (s).
    pub wall_s: f64,
}

fn nan() -> f64 {
    f64::NAN
}

/// What `study stability` measured.
#[derive(Debug, Clone)]
pub struct StabilityResult {
    /// All runs.
    pub rows: Vec<StabilityRow>,
    /// Total wall time (s).
    pub wall_s: f64,
}

struct Variant {
    case: HardCase,
    parameter: String,
    value: f64,
    scene: Scene,
    level: usize,
    params: Vec<(String, f64)>,
    steps: usize,
    solvers: Vec<(SolverKind, Settings)>,
    /// For the units case: the same problem in the original units and the length factor;
    /// the error is then the difference to the original solution with the same solver.
    baseline: Option<(Scene, f64)>,
}

impl Variant {
    /// A variant of `case` at level 1 with 4 steps, the scene's own mesh parameters and
    /// every solver.
    fn new(case: HardCase, parameter: impl Into<String>, value: f64, scene: Scene) -> Self {
        Variant {
            case,
            parameter: parameter.into(),
            value,
            scene,
            level: 1,
            params: Vec::new(),
            steps: 4,
            solvers: default_solvers(),
            baseline: None,
        }
    }
}

fn default_solvers() -> Vec<(SolverKind, Settings)> {
    [SolverKind::Newton, SolverKind::Paper, SolverKind::Qp]
        .into_iter()
        .map(|k| {
            (
                k,
                Settings {
                    kind: k,
                    max_iterations: 100,
                    ..Settings::default()
                },
            )
        })
        .collect()
}

/// Every hard case's variants, in the report's order.
fn plan() -> Result<Vec<Variant>> {
    let rates = Scene::load("rates")?;
    Ok([
        stiff_viscosity(&rates),
        modulus_contrast(&rates),
        mesh_size_ratio(&rates),
        vec![swapped_slave(&rates)],
        vec![held_only_by_contact()?],
        coincident_nodes(&rates),
        slivers(&rates),
        vec![units_rescaled(&rates)?],
        newton_across_levels(&rates),
        vec![single_step(&rates)],
        omega_sweep(&rates)?,
    ]
    .into_iter()
    .flatten()
    .collect())
}

/// Stiff viscosity: k E / lambda from 1e-2 to 1e4 at k = 0.25, E = 100, with 2 and 5 to
/// narrow down where the paper's fixed point stops converging.
fn stiff_viscosity(rates: &Scene) -> Vec<Variant> {
    let ratios = [
        (1e-2, "1e-2"),
        (1e-1, "1e-1"),
        (1.0, "1"),
        (2.0, "2"),
        (5.0, "5"),
        (1e1, "1e1"),
        (1e2, "1e2"),
        (1e3, "1e3"),
        (1e4, "1e4"),
    ];
    ratios
        .into_iter()
        .map(|(ratio, label)| {
            let mut s = rates.clone();
            for body in &mut s.bodies {
                if let Some(vp) = body.material.viscoplastic.as_mut() {
                    vp.lambda = 0.25 * 100.0 / ratio;
                }
            }
            let parameter = format!("k E / lambda = {label}");
            Variant::new(HardCase::StiffViscosity, parameter, ratio, s)
        })
        .collect()
}

/// Young's modulus contrast between the bodies: E2 / E1 from 1 to 1e6.
fn modulus_contrast(rates: &Scene) -> Vec<Variant> {
    [0, 2, 4, 6]
        .into_iter()
        .map(|exp| {
            let mut s = rates.clone();
            s.bodies[1].material.elastic.young = 100.0 * 10f64.powi(exp);
            let parameter = format!("E2 / E1 = 1e{exp}");
            Variant::new(HardCase::ModulusContrast, parameter, 10f64.powi(exp), s)
        })
        .collect()
}

/// Mesh-size ratio h1/h2 from 1/16 to 16 (graded meshes at level 0).
fn mesh_size_ratio(rates: &Scene) -> Vec<Variant> {
    [1.0 / 16.0, 0.25, 1.0, 4.0, 16.0]
        .into_iter()
        .map(|r| {
            let parameter = format!("h1 / h2 = {r}");
            let mut var = Variant::new(HardCase::MeshSizeRatio, parameter, r, rates.clone());
            var.params = vec![
                ("h_upper".into(), 0.2 * f64::sqrt(r)),
                ("h_lower".into(), 0.2 / f64::sqrt(r)),
                ("grading".into(), 1.3),
            ];
            var.level = 0;
            var
        })
        .collect()
}

/// Slave and master swapped: the lower block carries the constraint.
fn swapped_slave(rates: &Scene) -> Variant {
    let mut s = rates.clone();
    s.bodies.swap(0, 1);
    std::mem::swap(&mut s.slave_curve, &mut s.master_curve);
    Variant::new(HardCase::SwappedSlave, "slave = lower block", 1.0, s)
}

/// A body held only by contact (the patch scene's upper block), E = 3e5: the paper's fixed
/// point needs k L < 1, so it is run with 4 steps like the others.
fn held_only_by_contact() -> Result<Variant> {
    Ok(Variant::new(
        HardCase::HeldOnlyByContact,
        "patch, upper block",
        1.0,
        Scene::load("patch")?,
    ))
}

/// Near-coincident nodes (uniform sizing: 1e-11 h apart after splitting) and coincident
/// ones (matching meshes).
fn coincident_nodes(rates: &Scene) -> Vec<Variant> {
    let mut near = Variant::new(
        HardCase::NearCoincidentNodes,
        "grading = 1 (nodes 1e-11 h apart)",
        1.0,
        rates.clone(),
    );
    near.params = vec![("grading".into(), 1.0)];
    near.level = 2;
    let mut matching = Variant::new(
        HardCase::CoincidentNodes,
        "matching = 1",
        1.0,
        rates.clone(),
    );
    matching.params = vec![("matching".into(), 1.0)];
    vec![near, matching]
}

/// Slivers: a structured strip of the upper block along Gamma_C, one triangle pair per
/// contact edge, thinner and thinner (the measured aspect ratio is in the parameter).
fn slivers(rates: &Scene) -> Vec<Variant> {
    [2.9e-2, 2.9e-3, 2.9e-4]
        .into_iter()
        .map(|strip| {
            let parameter = format!("strip {strip:e}");
            let mut var = Variant::new(HardCase::Slivers, parameter, 0.0, rates.clone());
            var.params = vec![("strip".into(), strip)];
            var
        })
        .collect()
}

/// Units rescaled: lengths x 1e3 (gmsh writes the mesh scaled), moduli, stresses,
/// viscosity and tractions x 1e6; compared with the rates scene, solver by solver.
fn units_rescaled(rates: &Scene) -> Result<Variant> {
    let mut var = Variant::new(
        HardCase::UnitsRescaled,
        "lengths x 1e3, moduli x 1e6",
        1.0,
        Scene::load("rates-units")?,
    );
    var.baseline = Some((rates.clone(), 1e3));
    Ok(var)
}

/// Newton's iterations per step on the rates scene (study rates' family) at every level.
// 1.4142 is that family's size ratio as studies/rates.toml writes it (the same meshes), not
// sqrt(2).
#[allow(clippy::approx_constant)]
fn newton_across_levels(rates: &Scene) -> Vec<Variant> {
    (0..=5)
        .map(|level| {
            let parameter = format!("level {level}");
            let mut var = Variant::new(
                HardCase::NewtonAcrossLevels,
                parameter,
                level as f64,
                rates.clone(),
            );
            var.level = level;
            var.params = vec![("h_upper".into(), 0.3), ("h_lower".into(), 0.3 / 1.4142)];
            var.solvers.truncate(1);
            var
        })
        .collect()
}

/// One single time step over [0, T].
fn single_step(rates: &Scene) -> Variant {
    let mut var = Variant::new(HardCase::SingleStep, "steps = 1", 1.0, rates.clone());
    var.steps = 1;
    var
}

/// The paper's penalty parameter omega over 8 decades around the automatic value (newton
/// beside it as the reference).
fn omega_sweep(rates: &Scene) -> Result<Vec<Variant>> {
    let auto = omega_auto(rates)?;
    Ok([-4, -2, 0, 2, 4]
        .into_iter()
        .map(|exp| {
            let parameter = format!("omega = 1e{exp} x automatic");
            let mut var = Variant::new(
                HardCase::OmegaSweep,
                parameter,
                10f64.powi(exp),
                rates.clone(),
            );
            let paper = Settings {
                kind: SolverKind::Paper,
                max_iterations: 100,
                omega: Some(auto * 10f64.powi(exp)),
                ..Settings::default()
            };
            var.solvers = vec![
                (SolverKind::Newton, Settings::default()),
                (SolverKind::Paper, paper),
            ];
            var
        })
        .collect())
}

/// The automatic omega of the paper solver on the rates scene at level 1 (mean stiffness
/// diagonal over mean trace weight), so the sweep is stated relative to it.
fn omega_auto(scene: &Scene) -> Result<f64> {
    let case = Case::build(scene, 1, Method::reference(), &[])?;
    let p = &case.problem;
    let (pattern, slots) = p.model.stiffness_pattern(&[], p.model.n_free);
    let mut vals = vec![0.0; pattern.nnz()];
    p.model
        .add_tangent(&p.model.elastic_tangents(), &slots, &mut vals);
    let d = (0..p.model.n_free)
        .map(|i| vals[pattern.slot(i, i)])
        .sum::<f64>()
        / p.model.n_free as f64;
    let w = p.rows.iter().map(|r| r.weight).sum::<f64>() / p.rows.len() as f64;
    Ok(d / w)
}

/// The units case: `sol` against the same solver's solution of `base` (the problem in the
/// original units, lengths 1 / unit of `sol`'s): the relative nodal difference of u / unit,
/// and a note comparing the iterations per step (NaN and no note when `base` fails).
fn against_baseline(
    sol: &Solution,
    base: &Case,
    settings: &Settings,
    steps: usize,
    unit: f64,
) -> (f64, String) {
    let Ok(b) = solve::solve(&base.problem, settings, steps, true) else {
        return (f64::NAN, String::new());
    };
    let per_step =
        |s: &Solution| -> Vec<usize> { s.reports.iter().map(|r| r.iterations).collect() };
    let (a, bb) = (per_step(sol), per_step(&b));
    let note = if a == bb {
        format!("; iterations per step {a:?}, identical to the original units")
    } else {
        format!("; iterations per step {a:?} against {bb:?} in the original units")
    };
    (rel_diff_scaled(sol, &b, 1.0 / unit), note)
}

fn rel_diff(a: &Solution, b: &Solution) -> f64 {
    rel_diff_scaled(a, b, 1.0)
}

/// Largest nodal difference of `factor * a` to `b` over the final states, relative to the
/// largest displacement of `b`.
fn rel_diff_scaled(a: &Solution, b: &Solution, factor: f64) -> f64 {
    let (ua, ub) = (&a.last().u, &b.last().u);
    let m = ub
        .iter()
        .fold(0.0f64, |x, v| x.max(v.abs()))
        .max(f64::MIN_POSITIVE);
    ua.iter()
        .zip(ub)
        .fold(0.0f64, |x, (p, q)| x.max((factor * p - q).abs()))
        / m
}

/// Run every case with every solver and every method (mortar, nts, lac).
pub fn run() -> Result<StabilityResult> {
    let t0 = std::time::Instant::now();
    let mut rows = Vec::new();
    for var in plan()? {
        for method in Method::ALL {
            rows.extend(run_variant(&var, method)?);
        }
    }
    Ok(StabilityResult {
        rows,
        wall_s: t0.elapsed().as_secs_f64(),
    })
}

/// One variant with one cone, solver by solver (newton first: the others' errors are their
/// differences to its solution); a solver that does not converge gives a row that says why.
fn run_variant(var: &Variant, method: Method) -> Result<Vec<StabilityRow>> {
    let case = Case::build(&var.scene, var.level, method, &var.params)?;
    let (mut parameter, mut value) = (var.parameter.clone(), var.value);
    if var.case == HardCase::Slivers {
        value = metrics::max_aspect_ratio(&case.problem);
        parameter = format!("{parameter}: max aspect ratio {value:.0}");
    }
    let baseline = match &var.baseline {
        Some((scene, unit)) => Some((Case::build(scene, var.level, method, &var.params)?, *unit)),
        None => None,
    };
    // The scene's load against its yield stress: one figure per variant, on every row.
    let limit_load_ratio = crate::metrics::limit_load_ratio(&case.problem.model, var.scene.final_time)
        .unwrap_or(f64::NAN);
    // A run's row before its outcome is known: the failure's blanks.
    let row = |solver: SolverKind, wall_s: f64| StabilityRow {
        case: var.case,
        parameter: parameter.clone(),
        value,
        method,
        solver,
        converged: false,
        reason: String::new(),
        max_step_iterations: 0,
        mean_step_iterations: 0.0,
        error: f64::NAN,
        max_penetration: f64::NAN,
        max_displacement: f64::NAN,
        limit_load_ratio,
        wall_s,
    };
    let mut newton: Option<Solution> = None;
    let mut rows = Vec::new();
    for (kind, settings) in &var.solvers {
        let t = std::time::Instant::now();
        let out = solve::solve(&case.problem, settings, var.steps, true);
        let wall_s = t.elapsed().as_secs_f64();
        match out {
            Ok(sol) => {
                let (error, note) = match (&baseline, &newton) {
                    (Some((base_case, unit)), _) => {
                        against_baseline(&sol, base_case, settings, var.steps, *unit)
                    }
                    (None, Some(n)) => (rel_diff(&sol, n), String::new()),
                    (None, None) if *kind == SolverKind::Newton => (0.0, String::new()),
                    (None, None) => (f64::NAN, String::new()),
                };
                rows.push(StabilityRow {
                    converged: true,
                    reason: sol
                        .reports
                        .last()
                        .map(|r| r.reason.clone() + &note)
                        .unwrap_or_default(),
                    max_step_iterations: sol.max_step_iterations(),
                    mean_step_iterations: sol.iterations() as f64 / sol.reports.len().max(1) as f64,
                    error,
                    max_penetration: max_penetration(&case, &sol),
                    max_displacement: sol
                        .states
                        .iter()
                        .map(|s| crate::solve::inf_norm(&s.u))
                        .fold(0.0, f64::max),
                    ..row(*kind, wall_s)
                });
                if *kind == SolverKind::Newton {
                    newton = Some(sol);
                }
            }
            Err(Error::NotConverged(msg)) => rows.push(StabilityRow {
                reason: msg,
                ..row(*kind, wall_s)
            }),
            Err(e) => return Err(e),
        }
    }
    Ok(rows)
}

/// The largest interpenetration over the history (length).
fn max_penetration(case: &Case, sol: &Solution) -> f64 {
    sol.states
        .iter()
        .map(|s| metrics::max_penetration(&case.problem, s))
        .fold(0.0, f64::max)
}
