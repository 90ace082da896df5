//! Two-size convergence studies: the two bodies refined independently, to separate what
//! each mesh contributes. Lemma 3.1 bounds the consistency error by one term per body,
//! h1^(3/4) + h2 for K_h^pi and (h1^(1/2) ||e||)^(1/2) + h1^(3/4) + h2^(3/4) for K_h^I (body
//! 1 the slave); the diagonal studies refine both at a fixed ratio and see only their sum.
//!
//! [`run`] reads like the description of the study:
//! 1. plan, for every slave choice and cone, the grid of (slave level, master level) pairs,
//!    the two one-sided sweeps (each body swept with the other held at `fixed`, finer than
//!    every grid level) and the pair (fixed, fixed), the floor of both sweeps;
//! 2. solve them (meshes: each body split from the same gmsh family to its own level, so a
//!    pair of equal levels is the diagonal study's mesh), and the reference where the study
//!    has no exact solution (one per slave choice: the bodies are numbered by it);
//! 3. measure every pair against the truth ([`Truth`], shared with the diagonal studies);
//! 4. fit: the rate in h1 along the sweep at fixed h2 and the rate in h2 along the other
//!    ([`rates::assess`], with the (fixed, fixed) error as the floor: a sweep level within
//!    5x of it is left out), and the whole grid to E = C1 h1^a1 + C2 h2^a2
//!    ([`rates::fit_power_sum`]).

pub mod report;
pub mod results;

use crate::verify::kind::{Found, Kind};

/// The kind: study files with a `[two_size]` table.
pub const KIND: Kind = Kind {
    name: "two-size",
    description: "A study file with a [two_size] table: the slave's and the master's meshes refined independently",
    found: Found::Files {
        claims: |file| file.two_size.is_some(),
    },
    shards: false,
    run: |file, _| {
        let path = file
            .expect("a two-size study is a file")
            .display()
            .to_string();
        Ok(Some(Box::new(run(&path)?)))
    },
    rejudge: None,
    results: Some(results::section),
};


use crate::case::Case;
use crate::contact::Method;
use crate::error::{Error, Result};
use crate::progress::Progress;
use crate::scene::Scene;
use crate::solve::Solution;
use crate::verify::study_file::{LoadedStudy, provenance};
use crate::verify::truth::{Reference, Truth, reference};
use crate::verify::jobs::{self, Job, JobId, Mode};
use crate::verify::quantity::Quantity;
use crate::verify::judge;
use crate::verify::rates::{self, Assessment, PowerSumFit};
use crate::verify::study_file::TwoSizeSpec;
use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;
use std::time::Instant;

/// One measured pair of sizes.
#[derive(Debug, Clone, Serialize, serde::Deserialize)]
pub struct SizePoint {
    /// The body carrying the constraint.
    pub slave: String,
    /// Cone.
    pub method: Method,
    /// Level of the slave's mesh.
    pub slave_level: usize,
    /// Level of the master's mesh.
    pub master_level: usize,
    /// Max element diameter of the slave (length).
    pub h1: f64,
    /// Max element diameter of the master (length).
    pub h2: f64,
    /// Free dofs on the slave's nodes.
    pub dofs1: usize,
    /// Free dofs on the master's nodes.
    pub dofs2: usize,
    /// Quantity.
    pub quantity: Quantity,
    /// Relative error (max over time steps).
    pub error: f64,
    /// Wall time of the solve (s).
    pub wall_s: f64,
}

/// What one slave choice, cone and quantity measured and fitted.
#[derive(Debug, Clone)]
pub struct SizeFit {
    /// The body carrying the constraint.
    pub slave: String,
    /// Cone.
    pub method: Method,
    /// Quantity.
    pub quantity: Quantity,
    /// The grid fit E = C1 h1^a1 + C2 h2^a2 (None: no finite fit).
    pub fit: Option<PowerSumFit>,
    /// The rate in h1 at fixed h2 and the rate in h2 at fixed h1 (levels are the swept
    /// body's).
    pub sweeps: [Assessment; 2],
    /// The error at (fixed, fixed): the floor of both sweeps.
    pub floor: f64,
    /// At the finest grid diagonal point: each body's fitted term C_b h_b^a_b.
    pub terms: [f64; 2],
    /// At the same point: the error removed per added dof by refining each body,
    /// a_b C_b h_b^a_b / (2 N_b) (N_b the body's dofs, ~ h_b^-2).
    pub gain_per_dof: [f64; 2],
}

/// Everything a two-size study measured.
#[derive(Debug, Clone)]
pub struct TwoSizeResult {
    /// LoadedStudy name.
    pub name: String,
    /// LoadedStudy description.
    pub description: String,
    /// The scene (as its file names the slave).
    pub scene: Scene,
    /// The grid levels of each body.
    pub levels: Vec<usize>,
    /// The level a body is held at while the other is swept.
    pub fixed: usize,
    /// The slave choices, in order.
    pub slaves: Vec<String>,
    /// The diagonal study on the same family, if named.
    pub diagonal: Option<String>,
    /// The cones.
    pub methods: Vec<Method>,
    /// The quantities.
    pub quantities: Vec<Quantity>,
    /// Time steps per solve.
    pub steps: usize,
    /// The quantity the thresholds apply to.
    pub threshold_quantity: Quantity,
    /// The required a1 of mortar, nts and lac, in [`Method::ALL`]'s order (the study
    /// file's rate minus its tolerance; None: reported without a threshold).
    pub thresholds: [Option<f64>; 3],
    /// What the study file holds each method to, in [`Method::ALL`]'s order
    /// ([`crate::verify::study_file::ThresholdSpec::describe`]).
    pub threshold_claims: [String; 3],
    /// Each method's consistency exponents (h1, h2) from the study file, in
    /// [`Method::ALL`]'s order, with their source (None: no lemma covers it).
    pub exponents: [Option<crate::verify::study_file::Exponents>; 3],
    /// Every measured pair.
    pub points: Vec<SizePoint>,
    /// Every fit.
    pub fits: Vec<SizeFit>,
    /// The reference of each slave choice (empty: against the exact solution).
    pub references: Vec<(String, Reference)>,
    /// Gauss points per direction of the exact-error rule (None: a reference solve).
    pub exact_quadrature: Option<usize>,
    /// gmsh version, .geo hash, solver, cores, commit.
    pub provenance: BTreeMap<String, String>,
    /// Total wall time (s).
    pub wall_s: f64,
    /// Scene warnings.
    pub warnings: Vec<String>,
}

impl TwoSizeResult {
    /// Theorem 3.1's thresholds carried to the grid fit (Lemma 3.1: the slave's term is
    /// h1^(3/4) for K_h^pi and h1^(1/2) for K_h^I, the approximation error h1): the fitted
    /// exponent a1 of the threshold quantity must reach the study's rate threshold minus its
    /// tolerance wherever the fit identifies it ([`rates::fit_identifies`]). One sentence
    /// per miss.
    pub fn failures(&self) -> Vec<String> {
        self.fits
            .iter()
            .filter(|f| f.quantity == self.threshold_quantity)
            .filter_map(|f| {
                let x = f
                    .fit
                    .filter(|x| rates::fit_identifies(x.se[0], x.rms_log_residual))?;
                let need = self.threshold(f.method)?;
                (x.a[0] < need).then(|| {
                    format!(
                        "slave {} {} {}: a1 = {:.3} < {need:.3}",
                        f.slave, f.method, f.quantity, x.a[0]
                    )
                })
            })
            .collect()
    }

    /// The required a1 of `method` (None: no threshold).
    pub fn threshold(&self, method: Method) -> Option<f64> {
        self.thresholds[index(method)]
    }

    /// The consistency exponents (h1, h2) of `method` the study file gives.
    pub fn exponents(&self, method: Method) -> Option<[f64; 2]> {
        self.exponents[index(method)]
            .as_ref()
            .map(|e| [e.slave, e.master])
    }

    /// The points of one slave choice, cone and quantity.
    pub fn of(&self, slave: &str, method: Method, q: Quantity) -> impl Iterator<Item = &SizePoint> {
        self.points
            .iter()
            .filter(move |p| p.slave == slave && p.method == method && p.quantity == q)
    }

    /// The error at (slave level, master level), if measured.
    pub fn error(
        &self,
        slave: &str,
        method: Method,
        q: Quantity,
        levels: [usize; 2],
    ) -> Option<f64> {
        self.of(slave, method, q)
            .find(|p| [p.slave_level, p.master_level] == levels)
            .map(|p| p.error)
    }
}

/// The (slave, master) level pairs of one slave choice and cone: the grid, the two sweeps
/// and (fixed, fixed).
fn pairs(levels: &[usize], fixed: usize) -> Vec<[usize; 2]> {
    let mut out: Vec<[usize; 2]> = Vec::new();
    for &a in levels {
        for &b in levels {
            out.push([a, b]);
        }
    }
    for &l in levels {
        out.push([l, fixed]);
        out.push([fixed, l]);
    }
    out.push([fixed, fixed]);
    out
}

/// The planned solves.
struct Plan {
    jobs: Vec<Job>,
    /// Per slave choice, its reference levels (none against the exact solution).
    references: Vec<Option<[JobId; 3]>>,
    /// (slave choice, cone, levels, job).
    pairs: Vec<(usize, Method, [usize; 2], JobId)>,
}

impl Plan {
    fn new(study: &LoadedStudy, slaves: usize, fixed: usize) -> Self {
        let sf = &study.file;
        let family = sf.family_parameters();
        let reference_parameters = sf.reference_parameters();
        let mut jobs: Vec<Job> = Vec::new();
        let mut add = |label: String,
                       method: Method,
                       levels: [usize; 2],
                       params: &[(String, f64)],
                       scene: usize| {
            jobs.push(Job {
                id: jobs.len(),
                label,
                method,
                level: levels[0].max(levels[1]),
                body_levels: levels,
                params: params.to_vec(),
                steps: sf.steps,
                scene,
            });
            jobs.len() - 1
        };
        let r = study.reference_level();
        let mut references = Vec::new();
        let mut planned = Vec::new();
        for s in 0..slaves {
            references.push((!sf.reference.exact).then(|| {
                [r - 2, r - 1, r].map(|l| {
                    add(
                        format!("reference {s} level {l}"),
                        Method::reference(),
                        [l, l],
                        &reference_parameters,
                        s,
                    )
                })
            }));
            for &method in &sf.methods {
                for levels in pairs(&sf.mesh.levels, fixed) {
                    let label = format!("slave {s} {method} levels {levels:?}");
                    planned.push((s, method, levels, add(label, method, levels, &family, s)));
                }
            }
        }
        Plan {
            jobs,
            references,
            pairs: planned,
        }
    }

    /// The planned pairs' solves, taken from `solved`.
    fn pair_runs(&self, solved: &mut jobs::Solved) -> Vec<PairRun> {
        self.pairs
            .iter()
            .map(|&(slave, method, levels, id)| {
                let (case, solution) = solved.take(id);
                PairRun {
                    slave,
                    method,
                    levels,
                    case,
                    solution,
                }
            })
            .collect()
    }
}

/// Free dofs on the nodes of each body.
fn body_dofs(case: &Case) -> [usize; 2] {
    let m = &case.problem.model;
    [0, 1].map(|b| {
        let range = m.node_offset[b]..m.node_offset[b] + m.meshes[b].nodes.len();
        range
            .flat_map(|n| [2 * n, 2 * n + 1])
            .filter(|&d| m.equation[d] != crate::fe::FIXED)
            .count()
    })
}

/// One planned pair solved: its slave choice, cone and (slave, master) levels.
struct PairRun {
    /// Index into the slave choices.
    slave: usize,
    method: Method,
    levels: [usize; 2],
    case: Case,
    solution: Solution,
}

/// Run the two-size study `name` (built-in name or path).
pub fn run(name: &str) -> Result<TwoSizeResult> {
    let t0 = Instant::now();
    let study = LoadedStudy::load(name)?;
    let _planning = crate::progress::during(&format!("{}: meshing and planning", study.name));
    study.check_memory()?;
    let spec = study.file.two_size.as_ref().ok_or_else(|| {
        Error::input(
            &study.path,
            "two_size",
            "not a two-size study: add a [two_size] table",
        )
    })?;
    // Step 1: the plan, a scene per slave choice.
    let slaves = slave_choices(&study, spec);
    let scenes: Vec<Scene> = slaves
        .iter()
        .map(|s| study.scene.with_slave(s))
        .collect::<Result<_>>()?;
    let plan = Plan::new(&study, slaves.len(), spec.fixed);
    // Step 2: every solve, and each slave choice's truth.
    let mut solved = solve_all(&study, &plan, &scenes)?;
    let truths = truths(&study, &plan, &scenes, &mut solved);
    // Step 3: every pair against its truth.
    let runs = plan.pair_runs(&mut solved);
    let phase = crate::progress::Progress::phase(
        &study.name,
        &format!(
            "measuring {} against {}",
            crate::io::count(runs.len(), "pair"),
            match truths.first() {
                Some(Truth::Solved(_)) => "the references (the error integrals over the meshes' intersection)",
                _ => "the exact solution",
            }
        ),
    );
    let points = measure(&study, &slaves, &runs, &truths)?;
    drop(phase);
    // Step 4: the fits.
    let fits = fit_all(&study, spec, &slaves, &points, &truths)?;
    let references = truths
        .iter()
        .zip(&slaves)
        .filter_map(|(t, s)| match t {
            Truth::Solved(r) => Some((s.clone(), r.facts)),
            Truth::Exact(..) => None,
        })
        .collect();
    let first = &runs[0].case;
    let sf = &study.file;
    Ok(TwoSizeResult {
        name: study.name.clone(),
        description: sf.description.clone(),
        levels: sf.mesh.levels.clone(),
        fixed: spec.fixed,
        methods: sf.methods.clone(),
        quantities: sf.quantities.clone(),
        steps: sf.steps,
        threshold_quantity: sf.thresholds.quantity,
        thresholds: Method::ALL.map(|m| sf.thresholds.of(m).map(|t| t.value())),
        threshold_claims: Method::ALL.map(|m| sf.thresholds.describe(m)),
        exponents: Method::ALL.map(|m| spec.exponents.of(m).cloned()),
        diagonal: spec.diagonal.clone(),
        slaves,
        points,
        fits,
        references,
        exact_quadrature: sf.reference.exact.then_some(sf.reference.quadrature),
        provenance: provenance(&study, &first.mesh),
        wall_s: t0.elapsed().as_secs_f64(),
        warnings: first.warnings.clone(),
        scene: study.scene,
    })
}

/// The slave choices: the study's, or the scene's own slave surface.
fn slave_choices(study: &LoadedStudy, spec: &TwoSizeSpec) -> Vec<String> {
    if spec.slaves.is_empty() {
        vec![study.scene.bodies[0].surface.clone()]
    } else {
        spec.slaves.clone()
    }
}

/// Every planned solve, with progress on the console.
fn solve_all(study: &LoadedStudy, plan: &Plan, scenes: &[Scene]) -> Result<jobs::Solved> {
    let progress = Progress::new(plan.jobs.len() as u64, &study.name, "job");
    let scene_refs: Vec<&Scene> = scenes.iter().collect();
    let outputs = jobs::execute(
        &plan.jobs,
        &scene_refs,
        study.file.solver,
        &study.text,
        Mode::All,
        &|l| progress.tick(l),
    )?;
    progress.finish();
    Ok(jobs::Solved::complete(outputs).expect("every job ran"))
}

/// Each slave choice's truth: its reference solve, or its scene's exact solution.
fn truths<'s>(
    study: &LoadedStudy,
    plan: &Plan,
    scenes: &'s [Scene],
    solved: &mut jobs::Solved,
) -> Vec<Truth<'s>> {
    plan.references
        .iter()
        .zip(scenes)
        .map(|(ids, scene)| match ids {
            Some(ids) => Truth::Solved(reference(*ids, solved, study.reference_level())),
            None => Truth::Exact(
                scene
                    .exact
                    .as_deref()
                    .expect("checked when the study was read"),
                study.file.reference.quadrature,
            ),
        })
        .collect()
}

/// Every pair's errors against its slave choice's truth, one point per quantity (an error
/// that is not finite stops the study).
fn measure(
    study: &LoadedStudy,
    slaves: &[String],
    runs: &[PairRun],
    truths: &[Truth],
) -> Result<Vec<SizePoint>> {
    let measured: Vec<BTreeMap<Quantity, f64>> = runs
        .par_iter()
        .map(|r| truths[r.slave].relative_errors(&r.case, &r.solution))
        .collect();
    let mut points = Vec::new();
    for (r, errors) in runs.iter().zip(&measured) {
        let m = &r.case.problem.model;
        let dofs = body_dofs(&r.case);
        for &quantity in &study.file.quantities {
            // A quantity relative to a size the truth lacks has no row.
            let Some(&error) = errors.get(&quantity) else {
                continue;
            };
            if !error.is_finite() {
                return Err(Error::NotConverged(format!(
                    "slave {} {} levels {:?}: the {quantity} error is not finite",
                    slaves[r.slave], r.method, r.levels
                )));
            }
            points.push(SizePoint {
                slave: slaves[r.slave].clone(),
                method: r.method,
                slave_level: r.levels[0],
                master_level: r.levels[1],
                h1: m.meshes[0].h(),
                h2: m.meshes[1].h(),
                dofs1: dofs[0],
                dofs2: dofs[1],
                quantity,
                error,
                wall_s: r.solution.wall_s,
            });
        }
    }
    Ok(points)
}

/// The fits of every slave choice, cone and quantity.
fn fit_all(
    study: &LoadedStudy,
    spec: &TwoSizeSpec,
    slaves: &[String],
    points: &[SizePoint],
    truths: &[Truth],
) -> Result<Vec<SizeFit>> {
    let sf = &study.file;
    let mut fits = Vec::new();
    for (s, slave) in slaves.iter().enumerate() {
        for &method in &sf.methods {
            for &quantity in &sf.quantities {
                fits.push(fit(
                    points,
                    slave,
                    method,
                    quantity,
                    &sf.mesh.levels,
                    spec.fixed,
                    truths[s].quantity_error(quantity),
                    &study.path,
                )?);
            }
        }
    }
    Ok(fits)
}

/// Step 4 for one slave choice, cone and quantity.
#[allow(clippy::too_many_arguments)]
fn fit(
    points: &[SizePoint],
    slave: &str,
    method: Method,
    quantity: Quantity,
    levels: &[usize],
    fixed: usize,
    truth_error: f64,
    path: &std::path::Path,
) -> Result<SizeFit> {
    let mine: Vec<&SizePoint> = points
        .iter()
        .filter(|p| p.slave == slave && p.method == method && p.quantity == quantity)
        .collect();
    let at = |l: [usize; 2]| {
        mine.iter()
            .find(|p| [p.slave_level, p.master_level] == l)
            .copied()
    };
    let floor = at([fixed, fixed]).map_or(0.0, |p| p.error);
    // The sweeps: a level is left out where its error is within 5x of the floor (the
    // fixed body's own error) or of the truth's.
    let sweep = |b: usize| -> Result<Assessment> {
        let rows = judge::levels_of(levels.iter().filter_map(|&l| {
            let p = at(if b == 0 { [l, fixed] } else { [fixed, l] })?;
            Some(match b {
                0 => (l, p.h1, p.dofs1 as f64, p.error),
                _ => (l, p.h2, p.dofs2 as f64, p.error),
            })
        }));
        rates::assess(&rows, floor.max(truth_error)).map_err(|e| {
            Error::input(
                path,
                "mesh.levels",
                format!("{slave} {method} {quantity}: {e}"),
            )
        })
    };
    let sweeps = [sweep(0)?, sweep(1)?];
    let grid: Vec<(f64, f64, f64)> = mine
        .iter()
        .filter(|p| levels.contains(&p.slave_level) && levels.contains(&p.master_level))
        .filter(|p| p.error > rates::ROUNDOFF)
        .map(|p| (p.h1, p.h2, p.error))
        .collect();
    let fit = rates::fit_power_sum(&grid);
    let finest = *levels.last().expect("levels");
    let (terms, gain_per_dof) = match (fit, at([finest, finest])) {
        (Some(f), Some(p)) => {
            let t = f.terms([p.h1, p.h2]);
            let n = [p.dofs1 as f64, p.dofs2 as f64];
            (t, [0, 1].map(|b| f.a[b] * t[b] / (2.0 * n[b])))
        }
        _ => ([f64::NAN; 2], [f64::NAN; 2]),
    };
    Ok(SizeFit {
        slave: slave.to_string(),
        method,
        quantity,
        fit,
        sweeps,
        floor,
        terms,
        gain_per_dof,
    })
}

/// The position of `method` in [`Method::ALL`].
fn index(method: Method) -> usize {
    Method::ALL
        .iter()
        .position(|&m| m == method)
        .expect("every method is in Method::ALL")
}
