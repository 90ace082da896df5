//! Convergence studies: a family of non-matching meshes solved with each cone, errors
//! against a fine method-neutral reference (matching meshes), fitted rates and thresholds.
//!
//! [`run_mode`] reads like the description of a study:
//! 1. plan the solves (every input check before the first one);
//! 2. the reference: matching meshes at three levels, the two coarser ones estimating the
//!    reference's own error;
//! 3. measure every level of every cone against it, integrated exactly over the
//!    intersection of the triangulations;
//! 4. fit rates over the levels whose error is not within 5x of the reference's, and check
//!    Theorem 3.1's thresholds;
//! 5. the rate in time on a fixed mesh;
//! 6. the provenance.

mod beside_report;
mod best_report;
mod distance_report;
mod geometry_report;
mod lac_report;
pub use lac_report::best_pressure_rate;
pub mod report;
pub mod results;

use crate::verify::kind::{Found, Kind, Outcome};

/// The kind: study files without a `[two_size]` table.
pub const KIND: Kind = Kind {
    name: "convergence",
    description: "A study file: rates of both cones on a mesh family against a reference or the exact solution",
    found: Found::Files {
        claims: |file| file.two_size.is_none(),
    },
    shards: true,
    run: |file, mode| {
        let path = file
            .expect("a convergence study is a file")
            .display()
            .to_string();
        Ok(run_mode(&path, mode)?.map(|r| Box::new(r) as Box<dyn Outcome>))
    },
    rejudge: Some(|file, dir| {
        let path = file.expect("a convergence study is a file").display().to_string();
        Ok(Box::new(rejudge(&path, dir)?) as Box<dyn Outcome>)
    }),
    results: Some(results::section),
};


use crate::analytical::Exact;
use crate::case::Case;
use crate::contact::Method;
use crate::error::{Error, Result};
use crate::metrics;
use crate::progress::Progress;
use crate::scene::Scene;
use crate::solve::{Solution, inf_norm};
use crate::verify::exact_error::{
    ExactComparison, exact_profiles, max_exact_displacement,
};
use crate::verify::jobs::{self, Job, JobId, Mode, Solved};
use crate::verify::field::{P1Field, pressure_profile};
use crate::verify::distance::cone_distance;
use crate::verify::field::P1History;
use crate::verify::norms;
use crate::verify::quantity::Scale;
use crate::verify::quantity::Quantity;
use crate::verify::judge::{Rules, judge_errors};
use crate::verify::rates::Assessment;
use crate::verify::table::MethodLabel;
use crate::verify::study_file::{LoadedStudy, StudyFile, provenance};
pub use crate::verify::truth::{Reference, estimated_reference_error};
use crate::verify::truth::{Truth, reference};
pub use crate::verify::table::{ErrorRecord, join};
use rayon::prelude::*;
use serde::{Deserialize, Serialize, Serializer};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

pub use crate::verify::judge::RateRow;

/// Per-level facts of the mesh family.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct LevelInfo {
    /// Cone.
    pub method: Method,
    /// Level.
    pub level: usize,
    /// The judge's h (length): `h_max` on nested (split) levels, `h_eff` on levels meshed
    /// anew (`refinement = "remesh"`; see [`crate::fe::Model::judge_h`]).
    pub h: f64,
    /// Largest element diameter over both bodies (length). Empty in reports written
    /// before it was printed.
    #[serde(default)]
    pub h_max: Option<f64>,
    /// Effective size (|Omega| / number of triangles)^(1/2) (length). Empty in reports
    /// written before it was printed.
    #[serde(default)]
    pub h_eff: Option<f64>,
    /// Free dofs.
    pub dofs: usize,
    /// Body-1 nodes on Gamma_C.
    pub slave_nodes: usize,
    /// Body-2 nodes on Gamma_C.
    pub master_nodes: usize,
    /// Newton (or fixed-point) iterations in total.
    pub iterations: usize,
    /// Largest iteration count of one step.
    pub max_step_iterations: usize,
    /// Contact fraction at T.
    pub contact_fraction: f64,
    /// Plastic fraction at T.
    pub plastic_fraction: f64,
    /// Whether the level was left out of the fits (error within 5x of the reference's).
    pub flagged: bool,
    /// The largest part of Gamma_C one row resolves, relative to |Gamma_C|: a macro-element
    /// for lac, a body-1 segment for the nodal rows (the bound of a contact edge fixed at a
    /// row's end). Empty in reports written before it was measured.
    #[serde(default)]
    pub resolution: Option<f64>,
}

/// Which solution a profile point belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// A study level solved with this cone.
    Cone(Method),
    /// The reference.
    Reference,
    /// The scene's exact solution.
    Exact,
}

impl Source {
    /// "mortar", "nts" or "reference".
    pub fn name(self) -> &'static str {
        match self {
            Source::Cone(m) => m.name(),
            Source::Reference => "reference",
            Source::Exact => "exact",
        }
    }
}

impl Serialize for Source {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for Source {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        match name.as_str() {
            "reference" => Ok(Source::Reference),
            "exact" => Ok(Source::Exact),
            _ => Method::parse(&name)
                .map(Source::Cone)
                .ok_or_else(|| serde::de::Error::custom(format!("unknown profile source '{name}'"))),
        }
    }
}

/// A point of a profile along Gamma_C at T.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ProfilePoint {
    /// Whose profile.
    pub label: Source,
    /// Position x.
    pub x: f64,
    /// Position y.
    pub y: f64,
    /// Contact pressure (force/length) or normal gap (length).
    pub value: f64,
}

/// Deformed mesh data for the von Mises plot.
#[derive(Debug, Clone)]
pub struct DeformedMesh {
    /// Cone.
    pub method: Method,
    /// Triangles as deformed vertex coordinates.
    pub triangles: Vec<[[f64; 2]; 3]>,
    /// Von Mises stress per triangle.
    pub von_mises: Vec<f64>,
    /// Body (1 or 2) per triangle.
    pub body: Vec<u8>,
    /// Displacement magnification used.
    pub magnification: f64,
}


/// One run of the time study.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
pub struct TimeRun {
    /// Time steps.
    pub steps: usize,
    /// Step length k (time).
    pub k: f64,
    /// Relative theorem-norm error (max over the steps) against the truth in time.
    pub error: f64,
    /// What the error is relative to: the truth's theorem norm, max over the steps.
    pub norm: f64,
    /// Plastic fraction at T.
    pub plastic_fraction: f64,
    /// Wall time of the solve (s).
    pub wall_s: f64,
}

/// The rate in time on a fixed mesh.
#[derive(Debug, Clone)]
pub struct TimeStudy {
    /// Scene of the runs.
    pub scene: String,
    /// Cone of the runs.
    pub method: Method,
    /// Mesh level.
    pub level: usize,
    /// Max element diameter of that mesh (length).
    pub h: f64,
    /// Free dofs of that mesh.
    pub dofs: usize,
    /// Steps of the reference in time; None: measured against the exact solution.
    pub reference_steps: Option<usize>,
    /// The runs, k halved from one to the next.
    pub runs: Vec<TimeRun>,
    /// The rate in k judged like a rate in h ([`rates::assess`], k in place of h).
    pub assessment: Assessment,
}

/// Everything a study measured.
#[derive(Debug, Clone)]
pub struct StudyResult {
    /// LoadedStudy name.
    pub name: String,
    /// LoadedStudy description.
    pub description: String,
    /// The parsed study file.
    pub file: StudyFile,
    /// The scene.
    pub scene: Scene,
    /// Errors per method, level and quantity.
    pub errors: Vec<ErrorRecord>,
    /// Rates per method and quantity.
    pub rates: Vec<RateRow>,
    /// Per-level facts.
    pub levels: Vec<LevelInfo>,
    /// The reference solve (None: measured against the scene's exact solution).
    pub reference: Option<Reference>,
    /// Gauss points per direction of the rule integrating errors against the exact
    /// solution (None: measured against a reference solve).
    pub exact_quadrature: Option<usize>,
    /// Pressure profiles at T on the profile level (and the reference's).
    pub pressure: Vec<ProfilePoint>,
    /// Gap profiles at T on the profile level (and the reference's).
    pub gap: Vec<ProfilePoint>,
    /// The polygonal boundaries' geometric error per level, for a scene whose levels are
    /// split on its curves (empty otherwise).
    pub geometry: Vec<crate::verify::geometry::GeometryRow>,
    /// Level of the profiles.
    pub profile_level: usize,
    /// Deformed meshes on the profile level.
    pub deformed: Vec<DeformedMesh>,
    /// The time study, if the study file asks for one.
    pub time_study: Option<TimeStudy>,
    /// The variant families (alignment of the contact edge), if any.
    pub variants: Vec<Variant>,
    /// gmsh version, .geo hash, solver, cores, commit.
    pub provenance: BTreeMap<String, String>,
    /// Total wall time (s).
    pub wall_s: f64,
    /// Scene warnings (from the reference case).
    pub warnings: Vec<String>,
    /// The truth's own estimated error per quantity (0 against an exact solution): levels
    /// within 5x of it are left out of the rates.
    pub truth_errors: BTreeMap<Quantity, f64>,
    /// Whether equilibrium fixes the cones' contact resultant.
    pub resultant_fixed: bool,
    /// For a report rejudged from its CSVs (`--rejudge`): the folder whose plots that need
    /// a solution (von_mises.png) are kept.
    pub kept_from: Option<PathBuf>,
}

impl StudyResult {
    /// The rate row of a cone and quantity.
    pub fn rate(&self, m: Method, q: Quantity) -> Option<&RateRow> {
        self.rates.iter().find(|r| r.method == m && r.quantity == q)
    }

    /// The error of a cone and quantity at `level`.
    pub fn error(&self, m: Method, level: usize, q: Quantity) -> Option<f64> {
        self.errors
            .iter()
            .find(|e| e.method == m && e.quantity == q && e.level == level)
            .map(|e| e.error)
    }

    /// The thresholds the study missed, one sentence each (empty: it passed).
    pub fn failures(&self) -> Vec<String> {
        self.rates.iter().filter_map(RateRow::failure).collect()
    }

    /// The thresholds neither met nor missed, one sentence each.
    pub fn unverified(&self) -> Vec<String> {
        self.rates.iter().filter_map(RateRow::unverified).collect()
    }
}

/// The study's solves, with a named handle for each.
struct Plan {
    jobs: Vec<Job>,
    /// The reference levels, coarsest first (the finest is the reference); none when the
    /// study measures against the exact solution.
    reference: Option<[JobId; 3]>,
    /// Every cone on every study level, cone by cone.
    levels: FamilyJobs,
    /// The variant families: their coarsest size and their levels like `levels`.
    variants: Vec<(f64, FamilyJobs)>,
    /// The time study.
    time: Option<TimeJobs>,
}

/// The solves of a mesh family: (cone, level, job), cone by cone.
type FamilyJobs = Vec<(Method, usize, JobId)>;

/// The time study's solves.
struct TimeJobs {
    /// Its reference in time (none against the exact solution).
    reference: Option<JobId>,
    /// One run per step count: (steps, job).
    runs: Vec<(usize, JobId)>,
}

/// The study's solves as they are planned: each job added gets the next id.
#[derive(Default)]
struct JobList(Vec<Job>);

impl JobList {
    /// Add a job on `scene` (0: the study's, 1: the time study's) with both bodies at
    /// `level`, and return its id.
    fn add(
        &mut self,
        label: String,
        method: Method,
        level: usize,
        params: &[(String, f64)],
        steps: usize,
        scene: usize,
    ) -> JobId {
        let id = self.0.len();
        self.0.push(Job {
            id,
            label,
            method,
            level,
            body_levels: [level, level],
            params: params.to_vec(),
            steps,
            scene,
        });
        id
    }
}

impl Plan {
    /// Plan every solve and check what can be checked before the first one: the reference
    /// meshes must match on Gamma_C.
    fn new(study: &LoadedStudy) -> Result<Self> {
        let sf = &study.file;
        let mut jobs = JobList::default();
        let reference = Plan::reference(study, &mut jobs);
        let levels = Plan::family(study, &mut jobs, &sf.family_parameters(), "");
        let variants = sf
            .mesh
            .variants
            .iter()
            .map(|&coarsest| {
                let params = sf.variant_parameters(coarsest);
                let suffix = format!(" (family {coarsest})");
                (coarsest, Plan::family(study, &mut jobs, &params, &suffix))
            })
            .collect();
        let time = Plan::time_study(study, &mut jobs);
        if let Some(reference) = reference {
            check_reference_matches(study, &jobs.0[reference[0]])?;
        }
        Ok(Plan {
            jobs: jobs.0,
            reference,
            levels,
            variants,
            time,
        })
    }

    /// The reference's three levels, coarsest first (none against the exact solution).
    fn reference(study: &LoadedStudy, jobs: &mut JobList) -> Option<[JobId; 3]> {
        let sf = &study.file;
        let parameters = sf.reference_parameters();
        let r = study.reference_level();
        (!sf.reference.exact).then(|| {
            [r - 2, r - 1, r].map(|l| {
                let label = format!("reference level {l}");
                jobs.add(label, Method::reference(), l, &parameters, sf.steps, 0)
            })
        })
    }

    /// Every cone on every study level of a mesh family, cone by cone; `suffix` ends each
    /// label.
    fn family(
        study: &LoadedStudy,
        jobs: &mut JobList,
        params: &[(String, f64)],
        suffix: &str,
    ) -> FamilyJobs {
        let sf = &study.file;
        let mut runs = Vec::new();
        for &method in &sf.methods {
            for &level in &sf.mesh.levels {
                let label = format!("{method} level {level}{suffix}");
                runs.push((
                    method,
                    level,
                    jobs.add(label, method, level, params, sf.steps, 0),
                ));
            }
        }
        runs
    }

    /// The time study on its scene: its reference in time (none against the exact
    /// solution), then one run per step count.
    fn time_study(study: &LoadedStudy, jobs: &mut JobList) -> Option<TimeJobs> {
        let sf = &study.file;
        let family = sf.family_parameters();
        let scene = usize::from(study.time_scene.is_some());
        sf.time.as_ref().map(|ts| {
            let method = sf.methods[0];
            let reference = ts.reference_steps.map(|r| {
                let label = format!("time reference ({r} steps)");
                jobs.add(label, method, ts.level, &family, r, scene)
            });
            let runs = ts
                .steps
                .iter()
                .map(|&n| {
                    let label = format!("time study ({n} steps)");
                    (n, jobs.add(label, method, ts.level, &family, n, scene))
                })
                .collect();
            TimeJobs { reference, runs }
        })
    }
}

/// The reference meshes must match on Gamma_C. Uniform splitting keeps matching traces
/// matching, so the coarsest reference level (a cheap mesh) decides for all three.
fn check_reference_matches(study: &LoadedStudy, coarsest: &Job) -> Result<()> {
    let case = Case::build(
        &study.scene,
        coarsest.level,
        coarsest.method,
        &coarsest.params,
    )?;
    if case.problem.interface.min_relative_separation() > 1e-9 {
        return Err(Error::input(
            &study.path,
            "reference.parameters",
            "the reference meshes do not match on Gamma_C; set the .geo parameter that makes them match (e.g. matching = 1)",
        ));
    }
    Ok(())
}






/// What step 3 measured.
#[derive(Default)]
struct Measured {
    errors: Vec<ErrorRecord>,
    levels: Vec<LevelInfo>,
    pressure: Vec<ProfilePoint>,
    gap: Vec<ProfilePoint>,
    geometry: Vec<crate::verify::geometry::GeometryRow>,
    deformed: Vec<DeformedMesh>,
    /// The mesh provenance and scene warnings of the first level.
    mesh: Option<crate::mesh::gmsh::GeneratedMesh>,
    warnings: Vec<String>,
    /// Whether equilibrium fixes the contact resultant (first level's interface and
    /// constraints; the same on every level of a family).
    resultant_fixed: bool,
}

/// Step 3: every level of every cone against the truth (levels in parallel: each is
/// measured on its own, so the numbers equal a serial run's); profiles and deformed meshes
/// on `profile_level`.
fn measure_levels(
    sf: &StudyFile,
    plan: &Plan,
    solved: &mut Solved,
    truth: &Truth,
    profile_level: usize,
) -> Result<Measured> {
    let runs: Vec<(Method, usize, Case, Solution)> = plan
        .levels
        .iter()
        .map(|&(method, level, id)| {
            let (case, sol) = solved.take(id);
            (method, level, case, sol)
        })
        .collect();
    let measured: Vec<(BTreeMap<Quantity, f64>, Scale)> = runs
        .par_iter()
        .map(|(_, _, case, sol)| {
            let (mut errors, scale) = truth.measure_solved(case, sol);
            if sf.quantities.contains(&Quantity::DiscreteGap) {
                let p = &case.problem;
                let (error, size) = crate::verify::contact_error::discrete_gap_error(&p.interface, &p.rows);
                if size > 0.0 {
                    errors.insert(Quantity::DiscreteGap, error / size);
                }
            }
            (errors, scale)
        })
        .collect();
    let all_errors: Vec<&BTreeMap<Quantity, f64>> = measured.iter().map(|m| &m.0).collect();
    let mut out = Measured::default();
    if let Some((_, _, case, _)) = runs.first() {
        out.mesh = Some(case.mesh.clone());
        out.warnings = case.warnings.clone();
        out.resultant_fixed = case
            .problem
            .interface
            .resultant_fixed_by_equilibrium(&case.problem.model);
    }
    let magnification = match truth {
        Truth::Solved(reference) => {
            profiles(
                &reference.case,
                &reference.solution,
                Source::Reference,
                &mut out,
            );
            0.1 / inf_norm(&reference.solution.last().u).max(f64::MIN_POSITIVE)
        }
        Truth::Exact(exact, _) => {
            let (_, _, case, sol) = runs
                .iter()
                .find(|r| r.1 == profile_level)
                .expect("the profile level is a study level");
            exact_profile_points(case, exact, sol.last().time, &mut out);
            let umax = match exact.displacement {
                Some(_) => max_exact_displacement(&case.problem.model, exact, sol.last().time),
                None => inf_norm(&sol.last().u),
            };
            0.1 / umax.max(f64::MIN_POSITIVE)
        }
    };
    for ((method, level, case, sol), errors) in runs.iter().zip(all_errors) {
        let (method, level) = (*method, *level);
        out.errors
            .extend(error_rows(sf, method, case, sol, errors)?);
        if !method.is_reference() {
            out.errors
                .extend(distance_rows(sf, &runs, method, level, &measured)?);
        }
        let flagged = errors[&Quantity::Theorem] < 5.0 * truth.error();
        out.levels.push(level_info(case, sol, method, flagged));
        let curved = case.problem.model.scene.refinement == crate::scene::Refinement::Curved;
        if curved && out.geometry.iter().all(|g| g.level != level) {
            let exact = match truth {
                Truth::Exact(exact, _) => Some(*exact),
                Truth::Solved(_) => None,
            };
            let model = &case.problem.model;
            out.geometry.push(crate::verify::geometry::boundary_geometry(
                model,
                level,
                model.judge_h(),
                exact,
                sol.last().time,
            ));
        }
        if level == profile_level {
            profiles(case, sol, Source::Cone(method), &mut out);
            out.deformed
                .push(deformed(case, sol, method, magnification));
        }
    }
    Ok(out)
}

/// The rows of errors.csv of the distance of `method`'s solution to mortar's on `level`
/// (listed under `method`: nts or lac), where the study measures it: both solutions on
/// that level's mesh, relative to the truth's sizes there.
fn distance_rows(
    sf: &StudyFile,
    runs: &[(Method, usize, Case, Solution)],
    method: Method,
    level: usize,
    measured: &[(BTreeMap<Quantity, f64>, Scale)],
) -> Result<Vec<ErrorRecord>> {
    let wanted: Vec<Quantity> = sf.quantities.iter().copied().filter(|q| q.is_distance()).collect();
    let find = |m: Method| runs.iter().position(|r| r.0 == m && r.1 == level);
    let (Some(a), Some(b)) = (find(Method::reference()), find(method)) else {
        return Ok(Vec::new());
    };
    if wanted.is_empty() {
        return Ok(Vec::new());
    }
    let (ca, sa) = (&runs[a].2, &runs[a].3);
    let (cb, sb) = (&runs[b].2, &runs[b].3);
    let d = cone_distance(
        &P1History::of_solution(ca, sa),
        &P1History::of_solution(cb, sb),
        &measured[b].1,
    );
    wanted
        .into_iter()
        .filter(|q| d.contains_key(q))
        .map(|quantity| {
            let error = d[&quantity];
            if !error.is_finite() {
                return Err(Error::NotConverged(format!(
                    "level {level}: the {quantity} is not finite"
                )));
            }
            Ok(ErrorRecord {
                method: method.into(),
                level,
                h: cb.h,
                dofs: cb.problem.model.n_free,
                steps: sf.steps,
                quantity,
                error,
                wall_s: None,
                parameter: None,
            })
        })
        .collect()
}

/// The rows of errors.csv of one solved level: the study's quantities, each finite.
fn error_rows(
    sf: &StudyFile,
    method: Method,
    case: &Case,
    sol: &Solution,
    errors: &BTreeMap<Quantity, f64>,
) -> Result<Vec<ErrorRecord>> {
    sf.solution_quantities()
        // A quantity relative to a size the truth lacks has no row (verify::rates::relative_to).
        .filter_map(|quantity| Some((quantity, *errors.get(&quantity)?)))
        .map(|(quantity, error)| {
            if !error.is_finite() {
                return Err(Error::NotConverged(format!(
                    "{method} level {}: the {quantity} error is not finite",
                    case.level
                )));
            }
            Ok(ErrorRecord {
                method: method.into(),
                level: case.level,
                h: case.h,
                dofs: case.problem.model.n_free,
                steps: sf.steps,
                quantity,
                error,
                wall_s: Some(sol.wall_s),
                parameter: None,
            })
        })
        .collect()
}

/// A variant family: its coarsest size, its errors and its judged rates.
#[derive(Debug, Clone)]
pub struct Variant {
    /// Size of body 1 at level 0 (length).
    pub coarsest: f64,
    /// Errors per method, level and quantity.
    pub errors: Vec<ErrorRecord>,
    /// Rates per method and quantity.
    pub rates: Vec<RateRow>,
}

/// Step 3b: the variant families, measured against the same truth.
fn measure_variants(
    sf: &StudyFile,
    path: &Path,
    plan: &Plan,
    solved: &mut Solved,
    truth: &Truth,
    resultant_fixed: bool,
) -> Result<Vec<Variant>> {
    let mut out = Vec::new();
    for (coarsest, runs) in &plan.variants {
        let taken: Vec<(Method, Case, Solution)> = runs
            .iter()
            .map(|&(method, _, id)| {
                let (case, sol) = solved.take(id);
                (method, case, sol)
            })
            .collect();
        let all_errors: Vec<BTreeMap<Quantity, f64>> = taken
            .par_iter()
            .map(|(_, case, sol)| truth.relative_errors(case, sol))
            .collect();
        let mut errors = Vec::new();
        for ((method, case, sol), e) in taken.iter().zip(&all_errors) {
            errors.extend(error_rows(sf, *method, case, sol, e)?);
        }
        let rates = fit_rates(sf, path, &errors, &|q| truth.quantity_error(q), resultant_fixed)?;
        out.push(Variant {
            coarsest: *coarsest,
            errors,
            rates,
        });
    }
    Ok(out)
}



/// The exact pressure and gap along Gamma_C at time `t`, where the solution gives them.
fn exact_profile_points(case: &Case, exact: &Exact, t: f64, out: &mut Measured) {
    for (x, pressure, gap) in exact_profiles(&case.problem.interface, exact, t) {
        if pressure.is_finite() {
            out.pressure.push(ProfilePoint {
                label: Source::Exact,
                x: x[0],
                y: x[1],
                value: pressure,
            });
        }
        if gap.is_finite() {
            out.gap.push(ProfilePoint {
                label: Source::Exact,
                x: x[0],
                y: x[1],
                value: gap,
            });
        }
    }
}


fn level_info(case: &Case, sol: &Solution, method: Method, flagged: bool) -> LevelInfo {
    let pieces = &case.problem.interface.pieces;
    let last = sol.last();
    LevelInfo {
        method,
        level: case.level,
        h: case.h,
        h_max: Some(case.problem.model.h()),
        h_eff: Some(case.problem.model.effective_h()),
        dofs: case.problem.model.n_free,
        slave_nodes: pieces.iter().map(|p| p.slave_nodes.len()).sum(),
        master_nodes: pieces.iter().map(|p| p.master_nodes.len()).sum(),
        iterations: sol.iterations(),
        max_step_iterations: sol.max_step_iterations(),
        contact_fraction: metrics::contact_fraction(&case.problem, last),
        plastic_fraction: metrics::plastic_fraction(&case.problem, last),
        flagged,
        resolution: Some(resolution(&case.problem)),
    }
}

/// [`LevelInfo::resolution`]: the largest body-1 interval between the ends of one row's
/// span (a macro-element) or between neighbouring nodes, over |Gamma_C|.
fn resolution(p: &crate::solve::Problem) -> f64 {
    let pieces = &p.interface.pieces;
    let total: f64 = pieces.iter().map(|x| x.length).sum();
    let segment = pieces
        .iter()
        .flat_map(|x| x.slave_s.windows(2).map(|w| w[1] - w[0]))
        .fold(0.0f64, f64::max);
    let span = p
        .rows
        .iter()
        .map(|r| {
            let s = &pieces[r.piece].slave_s;
            (s[r.span[1]] - s[r.span[0]]).abs()
        })
        .fold(0.0f64, f64::max);
    segment.max(span) / total
}

/// Pressure at the body-1 trace nodes and gap -[u.nu] at both bodies' trace nodes, at T.
fn profiles(case: &Case, sol: &Solution, label: Source, out: &mut Measured) {
    let p = &case.problem;
    let s = sol.last();
    for profile in pressure_profile(p, s) {
        for (x, value) in profile {
            out.pressure.push(ProfilePoint {
                label,
                x: x[0],
                y: x[1],
                value,
            });
        }
    }
    for (pi, sv, jump) in crate::contact::penetrations(&p.interface, &s.u) {
        let at = p.interface.pieces[pi].point(sv);
        // Gap = g0 - [u.nu]: positive where the bodies separate.
        out.gap.push(ProfilePoint {
            label,
            x: at[0],
            y: at[1],
            value: -jump,
        });
    }
}

fn deformed(case: &Case, sol: &Solution, method: Method, magnification: f64) -> DeformedMesh {
    let m = &case.problem.model;
    let s = sol.last();
    let pos = |n: usize| {
        let p = m.position(n);
        [
            p[0] + magnification * s.u[2 * n],
            p[1] + magnification * s.u[2 * n + 1],
        ]
    };
    DeformedMesh {
        method,
        triangles: m.elements.iter().map(|e| e.nodes.map(pos)).collect(),
        von_mises: s.sigma.iter().map(crate::material::von_mises).collect(),
        body: m.elements.iter().map(|e| e.body as u8 + 1).collect(),
        magnification,
    }
}

/// Step 4: every quantity of every cone judged over its levels ([`rates::assess`]: no rate
/// on round-off, on levels within 5x of the truth's own error in that quantity, on fewer
/// than three levels, or for a quantity that stops converging; a rate over the trailing
/// window of agreeing successive rates; falling or rising where the last three move), and
/// the thresholds. Where equilibrium fixes the contact resultant (`resultant_fixed`), its
/// error measures the load quadrature: it is named so and never fitted.
fn fit_rates(
    sf: &StudyFile,
    path: &Path,
    errors: &[ErrorRecord],
    truth_error: &dyn Fn(Quantity) -> f64,
    resultant_fixed: bool,
) -> Result<Vec<RateRow>> {
    let threshold = |m: &MethodLabel, q: Quantity| {
        m.cone()
            .filter(|_| q == sf.thresholds.quantity)
            .and_then(|c| sf.thresholds.of(c))
    };
    let rules = Rules {
        truth_error,
        resultant_fixed,
        threshold: &threshold,
    };
    judge_errors(errors, &rules).map_err(|e| Error::input(path, "mesh.levels", e.to_string()))
}

/// Step 5: the rate in time on a fixed mesh: each run against the reference in time at the
/// common time points, or against the exact solution of the time study's scene at every
/// step (`points`: the Gauss points per direction of the error rule). The rate in k is
/// judged as a rate in h is ([`rates::assess`]: the same windows and verdicts).
fn time_study(
    study: &LoadedStudy,
    plan: &Plan,
    solved: &mut Solved,
    points: usize,
) -> Result<Option<TimeStudy>> {
    let sf = &study.file;
    let (Some(ts), Some(jobs)) = (sf.time.as_ref(), plan.time.as_ref()) else {
        return Ok(None);
    };
    let reference = jobs.reference.map(|id| solved.take(id));
    let runs: Vec<(usize, Case, Solution)> = jobs
        .runs
        .iter()
        .map(|&(steps, id)| {
            let (case, sol) = solved.take(id);
            (steps, case, sol)
        })
        .collect();
    let scene = study.time_scene.as_ref().unwrap_or(&study.scene);
    let errors: Vec<(f64, f64)> = match &reference {
        Some((_, reference)) => runs
            .par_iter()
            .map(|(steps, case, sol)| time_reference_error(case, sol, reference, *steps))
            .collect(),
        None => {
            let exact = scene
                .exact
                .as_deref()
                .expect("checked when the study was read");
            time_exact_errors(&runs, exact, points)
        }
    };
    let case = &runs[0].1;
    let model = &case.problem.model;
    let runs: Vec<TimeRun> = runs
        .iter()
        .zip(&errors)
        .map(|((steps, case, sol), &(error, norm))| TimeRun {
            steps: *steps,
            k: model.scene.final_time / *steps as f64,
            error,
            norm,
            plastic_fraction: metrics::plastic_fraction(&case.problem, sol.last()),
            wall_s: sol.wall_s,
        })
        .collect();
    if let Some(r) = runs.iter().find(|r| !r.error.is_finite()) {
        return Err(Error::NotConverged(format!(
            "time study ({} steps): the theorem error is not finite",
            r.steps
        )));
    }
    let judged: Vec<(usize, f64, f64)> = runs.iter().map(|r| (r.steps, r.k, r.error)).collect();
    let assessment = crate::verify::judge::assess_in_k(&judged)
        .map_err(|e| Error::input(&study.path, "time.steps", format!("time study: {e}")))?;
    Ok(Some(TimeStudy {
        scene: scene.name.clone(),
        method: case.problem.method,
        level: ts.level,
        h: case.h,
        dofs: model.n_free,
        reference_steps: ts.reference_steps,
        runs,
        assessment,
    }))
}

/// The relative theorem-norm error of each run against the exact solution, max over the
/// steps of ||e|| relative to the max of the exact solution's norm (as
/// [`Differences::relative`] has it), with that norm. Every state of every run is measured in parallel: the
/// longest run alone would otherwise set the wall time.
fn time_exact_errors(
    runs: &[(usize, Case, Solution)],
    exact: &Exact,
    points: usize,
) -> Vec<(f64, f64)> {
    let cmp = ExactComparison::new(exact, points);
    let states: Vec<(usize, &crate::solve::State)> = runs
        .iter()
        .enumerate()
        .flat_map(|(r, (_, _, sol))| sol.states.iter().skip(1).map(move |s| (r, s)))
        .collect();
    let norms: Vec<(usize, f64, f64)> = states
        .par_iter()
        .map(|&(r, s)| {
            let p = &runs[r].1.problem;
            let d = cmp.difference(&p.model, &p.interface, &P1Field::of_state(p, s));
            (r, d.difference.theorem(), d.exact.theorem())
        })
        .collect();
    (0..runs.len())
        .map(|r| {
            let (mut error, mut norm) = (0.0f64, 0.0f64);
            for &(_, e, n) in norms.iter().filter(|x| x.0 == r) {
                (error, norm) = (error.max(e), norm.max(n));
            }
            (error / norm.max(f64::MIN_POSITIVE), norm)
        })
        .collect()
}

/// The relative theorem-norm error (max over the steps) of a run with `steps` steps against
/// a reference in time on the same mesh, at the common time points, with the reference's
/// norm it is relative to.
fn time_reference_error(
    case: &Case,
    sol: &Solution,
    reference: &Solution,
    steps: usize,
) -> (f64, f64) {
    let (p, model) = (&case.problem, &case.problem.model);
    let stride = (reference.states.len() - 1) / steps;
    let (mut error, mut norm) = (0.0f64, 0.0f64);
    for (i, state) in sol.states.iter().enumerate().skip(1) {
        let (s, r) = (
            P1Field::of_state(p, state),
            P1Field::of_state(p, &reference.states[i * stride]),
        );
        error = error.max(norms::norms_of_difference(model, &s, &r).theorem());
        norm = norm.max(norms::norms(model, &r).theorem());
    }
    (error / norm, norm)
}


/// Run the convergence study `name` (built-in name or path).
pub fn run(name: &str) -> Result<StudyResult> {
    run_mode(name, Mode::All).map(|r| r.expect("a full run gives a result"))
}

/// The report `dir` of the convergence study `name` judged again from its CSVs (errors,
/// levels, gap, pressure, time, variants) and run.toml, without solving: the result a full
/// run on the same errors gives, but for the solution it no longer has (von_mises.png is
/// kept from `dir`).
pub fn rejudge(name: &str, dir: &Path) -> Result<StudyResult> {
    let study = LoadedStudy::load(name)?;
    let sf = &study.file;
    let facts_path = dir.join("run.toml");
    let text = std::fs::read_to_string(&facts_path).map_err(|_| {
        Error::input(
            &facts_path,
            "file",
            "no run.toml: the report predates --rejudge (or is not this study's); run the study once without --rejudge",
        )
    })?;
    let facts: report::RunFacts = crate::error::parse_toml(&text, &facts_path, "run facts")?;
    let errors: Vec<ErrorRecord> = crate::verify::table::read(&dir.join("errors.csv"))?;
    let truth_errors: BTreeMap<Quantity, f64> = facts
        .truth_errors
        .iter()
        .map(|(name, e)| {
            Quantity::try_from(name.clone())
                .map(|q| (q, *e))
                .map_err(|m| Error::input(&facts_path, "truth_errors", format!("{m}; regenerate the report")))
        })
        .collect::<Result<_>>()?;
    let truth_error = |q: Quantity| truth_errors.get(&q).copied().unwrap_or(0.0);
    let rates = fit_rates(sf, &study.path, &errors, &truth_error, facts.resultant_fixed)?;
    let variants = match dir.join("variants.csv") {
        p if p.exists() => {
            let rows: Vec<report::VariantCsv> = crate::verify::table::read(&p)?;
            let mut coarsest: Vec<f64> = Vec::new();
            for r in &rows {
                if !coarsest.contains(&r.coarsest) {
                    coarsest.push(r.coarsest);
                }
            }
            coarsest
                .into_iter()
                .map(|c| {
                    let errors: Vec<ErrorRecord> = rows
                        .iter()
                        .filter(|r| r.coarsest == c)
                        .map(|r| r.record(sf.steps))
                        .collect();
                    let rates = fit_rates(sf, &study.path, &errors, &truth_error, facts.resultant_fixed)?;
                    Ok(Variant {
                        coarsest: c,
                        errors,
                        rates,
                    })
                })
                .collect::<Result<_>>()?
        }
        _ => Vec::new(),
    };
    let time_study = match facts.time {
        Some(t) => {
            let runs: Vec<TimeRun> = crate::verify::table::read(&dir.join("time.csv"))?;
            let judged: Vec<(usize, f64, f64)> = runs.iter().map(|r| (r.steps, r.k, r.error)).collect();
            let assessment = crate::verify::judge::assess_in_k(&judged)
                .map_err(|e| Error::input(&study.path, "time.steps", format!("time study: {e}")))?;
            Some(TimeStudy {
                scene: t.scene,
                method: t.method,
                level: t.level,
                h: t.h,
                dofs: t.dofs,
                reference_steps: t.reference_steps,
                runs,
                assessment,
            })
        }
        None => None,
    };
    Ok(StudyResult {
        name: study.name,
        description: sf.description.clone(),
        scene: study.scene,
        errors,
        rates,
        levels: crate::verify::table::read(&dir.join("levels.csv"))?,
        reference: facts.reference,
        exact_quadrature: facts.exact_quadrature,
        pressure: crate::verify::table::read(&dir.join("pressure.csv"))?,
        gap: crate::verify::table::read(&dir.join("gap.csv"))?,
        geometry: match dir.join("geometry.csv") {
            p if p.exists() => crate::verify::table::read(&p)?,
            _ => Vec::new(),
        },
        profile_level: facts.profile_level,
        deformed: Vec::new(),
        time_study,
        variants,
        provenance: facts.provenance,
        wall_s: facts.wall_s,
        warnings: facts.warnings,
        truth_errors,
        resultant_fixed: facts.resultant_fixed,
        kept_from: Some(dir.to_path_buf()),
        file: study.file,
    })
}

/// Run the convergence study `name` in `mode`: all jobs here, one shard of them (records
/// only, no result), or a merge of the records of all shards.
pub fn run_mode(name: &str, mode: Mode) -> Result<Option<StudyResult>> {
    let t0 = Instant::now();
    // 1. Plan the solves and run them (a shard stores its records and stops there).
    let study = LoadedStudy::load(name)?;
    let planning = crate::progress::during(&format!("{}: meshing and planning", study.name));
    study.check_memory()?;
    let sf = &study.file;
    let plan = Plan::new(&study)?;
    drop(planning);
    let Some(mut solved) = solve_all(&study, &plan, mode)? else {
        return Ok(None);
    };
    // 2. The reference, or the exact solution.
    let truth = truth(&study, &plan, &mut solved);
    // 3. Every level of every cone against it.
    let profile_level = sf.mesh.levels[sf.mesh.levels.len() / 2];
    let phase = Progress::phase(&study.name, &measuring(plan.levels.len(), &truth));
    let measured = measure_levels(sf, &plan, &mut solved, &truth, profile_level)?;
    drop(phase);
    // 4. The rates and their thresholds, and the variant families'.
    let fixed = measured.resultant_fixed;
    let rates = fit_rates(sf, &study.path, &measured.errors, &|q| truth.quantity_error(q), fixed)?;
    let phase = (!plan.variants.is_empty()).then(|| {
        let n = plan.variants.iter().map(|v| v.1.len()).sum();
        Progress::phase(&study.name, &format!("{} of the variant families", measuring(n, &truth)))
    });
    let variants = measure_variants(sf, &study.path, &plan, &mut solved, &truth, fixed)?;
    drop(phase);
    // 5. The rate in time on a fixed mesh.
    let phase = plan
        .time
        .is_some()
        .then(|| Progress::phase(&study.name, "measuring the time study's errors"));
    let time_study = time_study(&study, &plan, &mut solved, sf.reference.quadrature)?;
    drop(phase);
    // 6. The provenance, with the mesh the truth was measured on.
    let (reference, exact_quadrature, mesh, warnings) = match &truth {
        Truth::Solved(r) => (
            Some(r.facts),
            None,
            r.case.mesh.clone(),
            r.case.warnings.clone(),
        ),
        Truth::Exact(_, points) => (
            None,
            Some(*points),
            measured.mesh.clone().expect("at least one level"),
            measured.warnings.clone(),
        ),
    };
    let provenance = provenance(&study, &mesh);
    let truth_errors = measured
        .errors
        .iter()
        .map(|e| (e.quantity, truth.quantity_error(e.quantity)))
        .collect();
    Ok(Some(StudyResult {
        name: study.name,
        description: sf.description.clone(),
        scene: study.scene,
        errors: measured.errors,
        rates,
        levels: measured.levels,
        reference,
        exact_quadrature,
        pressure: measured.pressure,
        gap: measured.gap,
        geometry: measured.geometry,
        profile_level,
        deformed: measured.deformed,
        time_study,
        variants,
        provenance,
        wall_s: t0.elapsed().as_secs_f64(),
        warnings,
        truth_errors,
        resultant_fixed: fixed,
        kept_from: None,
        file: study.file,
    }))
}

/// "measuring 24 solutions against the reference (level 7)": the phase of step 3.
fn measuring(solutions: usize, truth: &Truth) -> String {
    let against = match truth {
        Truth::Solved(r) => format!("the reference (level {}, the error integrals over the meshes' intersection)", r.facts.level),
        Truth::Exact(..) => "the exact solution".to_string(),
    };
    format!("measuring {} against {against}", crate::io::count(solutions, "solution"))
}

/// Every job of the plan in `mode`: all of them, one shard's (records only: None), or the
/// records of all shards.
fn solve_all(study: &LoadedStudy, plan: &Plan, mode: Mode) -> Result<Option<Solved>> {
    let progress = Progress::new(plan.jobs.len() as u64, &study.name, "job");
    let scenes: Vec<&Scene> = std::iter::once(&study.scene)
        .chain(study.time_scene.as_ref())
        .collect();
    let outputs = jobs::execute(
        &plan.jobs,
        &scenes,
        study.file.solver,
        &study.text,
        mode,
        &|label| progress.tick(label),
    )?;
    progress.finish();
    if let Mode::Shard(i, n) = mode {
        eprintln!(
            "shard {i}/{n}: {} of {} jobs solved, records in {}",
            outputs.iter().filter(|o| o.is_some()).count(),
            plan.jobs.len(),
            jobs::records_dir().display()
        );
        return Ok(None);
    }
    Ok(Some(
        Solved::complete(outputs).expect("every job ran or was loaded"),
    ))
}

/// What every level is measured against: the reference solve (with its own error), or the
/// scene's exact solution.
fn truth<'s>(study: &'s LoadedStudy, plan: &Plan, solved: &mut Solved) -> Truth<'s> {
    match plan.reference {
        Some(ids) => Truth::Solved(reference(ids, solved, study.reference_level())),
        None => Truth::Exact(
            study
                .scene
                .exact
                .as_deref()
                .expect("checked when the study was read"),
            study.file.reference.quadrature,
        ),
    }
}
