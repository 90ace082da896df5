//! Convergence studies: a family of non-matching meshes solved with each cone, errors
//! against a fine method-neutral reference (matching meshes), fitted rates and thresholds.
//!
//! A study reads top to bottom like the paper's description of a test:
//! 1. solve the reference on matching meshes at three levels (the two coarser ones estimate
//!    the reference's own error);
//! 2. solve every study level with every cone and measure its error against the reference,
//!    integrated exactly over the intersection of the triangulations;
//! 3. leave out levels whose error is within a factor 5 of the reference's, fit rates,
//!    compare with Theorem 3.1.

pub mod error;
pub mod file;
pub mod intersect;
pub mod jobs;
pub mod paper;
pub mod rates;
pub mod speed;
pub mod stability;

use crate::case::Case;
use crate::contact::Method;
use crate::error::{Error, Result};
use crate::metrics;
use crate::scene::Scene;
use crate::solve::{self, Settings, Solution, SolverKind};
use error::{Comparison, SquaredNorms};
use file::StudyFile;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

/// One row of errors.csv.
#[derive(Debug, Clone, Serialize)]
pub struct ErrorRow {
    /// Cone.
    pub method: String,
    /// Mesh level.
    pub level: usize,
    /// Max element diameter.
    pub h: f64,
    /// Free dofs.
    pub dofs: usize,
    /// Time steps.
    pub steps: usize,
    /// Quantity name.
    pub quantity: String,
    /// Relative error (max over time steps).
    pub error: f64,
    /// Wall time of the solve (s).
    pub wall_s: f64,
}

/// One row of rates.csv.
#[derive(Debug, Clone, Serialize)]
pub struct RateRow {
    /// Cone.
    pub method: String,
    /// Quantity.
    pub quantity: String,
    /// Fitted rate in h.
    #[serde(serialize_with = "crate::io::finite_or_empty")]
    pub rate: f64,
    /// Standard error of the rate.
    #[serde(serialize_with = "crate::io::finite_or_empty")]
    pub stderr: f64,
    /// Levels used in the fit, e.g. "0 1 2 3".
    pub levels_used: String,
    /// Required rate minus tolerance (theorem only), empty otherwise.
    pub threshold: Option<f64>,
    /// Whether the rate meets the threshold (theorem only).
    pub pass: Option<bool>,
    /// Rate against dofs (error ~ dofs^-rate_dofs).
    #[serde(serialize_with = "crate::io::finite_or_empty")]
    pub rate_dofs: f64,
    /// Successive rates between neighbouring levels, space separated.
    pub successive: String,
}

/// Per-level facts of the mesh family.
#[derive(Debug, Clone, Serialize)]
pub struct LevelInfo {
    /// Cone.
    pub method: String,
    /// Level.
    pub level: usize,
    /// Max element diameter over both bodies.
    pub h: f64,
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
}

/// A profile along Gamma_C at T: (solution label, x, y, value).
#[derive(Debug, Clone, Serialize)]
pub struct ProfilePoint {
    /// "mortar", "nts" or "reference".
    pub label: String,
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
    /// Cone label.
    pub label: String,
    /// Triangles as deformed vertex coordinates.
    pub triangles: Vec<[[f64; 2]; 3]>,
    /// Von Mises stress per triangle.
    pub von_mises: Vec<f64>,
    /// Body (1 or 2) per triangle.
    pub body: Vec<u8>,
    /// Displacement magnification used.
    pub magnification: f64,
}

/// Everything a study measured.
#[derive(Debug, Clone)]
pub struct StudyResult {
    /// Study name.
    pub name: String,
    /// Study description.
    pub description: String,
    /// The parsed study file.
    pub file: StudyFile,
    /// The scene.
    pub scene: Scene,
    /// Errors per method, level and quantity.
    pub errors: Vec<ErrorRow>,
    /// Rates per method and quantity.
    pub rates: Vec<RateRow>,
    /// Per-level facts.
    pub levels: Vec<LevelInfo>,
    /// Reference: level, h, dofs, wall time.
    pub reference: (usize, f64, usize, f64),
    /// Estimated relative error of the reference (theorem quantity) and the rate used.
    pub reference_error: (f64, f64),
    /// Pressure profiles at T on the profile level.
    pub pressure: Vec<ProfilePoint>,
    /// Gap profiles at T on the profile level.
    pub gap: Vec<ProfilePoint>,
    /// Level of the profiles.
    pub profile_level: usize,
    /// Deformed meshes on the profile level.
    pub deformed: Vec<DeformedMesh>,
    /// Time study: (steps, k, error) per run, and its fitted rate.
    pub time_study: Option<(Vec<(usize, f64, f64)>, Option<rates::Fit>)>,
    /// gmsh version and .geo hash.
    pub provenance: BTreeMap<String, String>,
    /// Total wall time (s).
    pub wall_s: f64,
    /// Scene warnings (from the reference case).
    pub warnings: Vec<String>,
}

/// Progress reporting: one tick per solve; silent when stderr is not a terminal.
pub struct Progress(indicatif::ProgressBar);

impl Progress {
    fn new(n: u64, name: &str) -> Self {
        use std::io::IsTerminal;
        let pb = if std::io::stderr().is_terminal() {
            indicatif::ProgressBar::new(n)
        } else {
            indicatif::ProgressBar::hidden()
        };
        pb.set_style(
            indicatif::ProgressStyle::with_template(
                "{prefix} [{bar:30}] {pos}/{len} {msg} ({elapsed})",
            )
            .unwrap()
            .progress_chars("=> "),
        );
        pb.set_prefix(name.to_string());
        Progress(pb)
    }
    fn tick(&self, msg: String) {
        self.0.set_message(msg);
        self.0.inc(1);
    }
}

fn relative_quantities(
    diff: &[SquaredNorms],
    refn: &[SquaredNorms],
    pdiff: &[(f64, f64)],
    pen: f64,
    uref: f64,
) -> BTreeMap<&'static str, f64> {
    let maxn = |f: &dyn Fn(&SquaredNorms) -> f64, v: &[SquaredNorms]| {
        v.iter().map(f).fold(0.0f64, f64::max)
    };
    let rel =
        |f: &dyn Fn(&SquaredNorms) -> f64| maxn(f, diff) / maxn(f, refn).max(f64::MIN_POSITIVE);
    let mut q = BTreeMap::new();
    q.insert("theorem", rel(&|n| n.theorem()));
    q.insert("h1_u", rel(&|n| n.h1()));
    q.insert("l2_u", rel(&|n| n.l2_u.sqrt()));
    q.insert("l2_stress", rel(&|n| n.stress.sqrt()));
    let pd = pdiff.iter().map(|p| p.0.sqrt()).fold(0.0f64, f64::max);
    let pn = pdiff.iter().map(|p| p.1.sqrt()).fold(0.0f64, f64::max);
    q.insert("l2_pressure", pd / pn.max(f64::MIN_POSITIVE));
    q.insert("max_penetration", pen / uref.max(f64::MIN_POSITIVE));
    q
}

pub(crate) fn solve_case(case: &Case, kind: SolverKind, steps: usize) -> Result<(Solution, f64)> {
    let t = Instant::now();
    let sol = solve::solve(
        &case.problem,
        &Settings {
            kind,
            ..Settings::default()
        },
        steps,
        true,
    )?;
    Ok((sol, t.elapsed().as_secs_f64()))
}

/// Theorem-quantity distance of two solutions with the same time grid, relative to `b`.
pub(crate) fn theorem_distance(ca: &Case, sa: &Solution, cb: &Case, sb: &Solution) -> f64 {
    let cmp = Comparison::new(&ca.problem.model, &cb.problem.model);
    let d = sa
        .states
        .iter()
        .zip(&sb.states)
        .skip(1)
        .map(|(x, y)| {
            cmp.difference(&ca.problem.model, x, &cb.problem.model, y)
                .theorem()
        })
        .fold(0.0f64, f64::max);
    let n = sb
        .states
        .iter()
        .skip(1)
        .map(|y| error::norms(&cb.problem.model, y).theorem())
        .fold(0.0f64, f64::max);
    d / n
}

fn deformed(case: &Case, sol: &Solution, label: &str, magnification: f64) -> DeformedMesh {
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
        label: label.to_string(),
        triangles: m.elements.iter().map(|e| e.nodes.map(pos)).collect(),
        von_mises: s.sigma.iter().map(crate::material::von_mises).collect(),
        body: m.elements.iter().map(|e| e.body as u8 + 1).collect(),
        magnification,
    }
}

fn profiles(
    case: &Case,
    sol: &Solution,
    label: &str,
    pressure: &mut Vec<ProfilePoint>,
    gap: &mut Vec<ProfilePoint>,
) {
    let p = &case.problem;
    let s = sol.last();
    for prof in error::pressure_profile(p, s) {
        for (x, v) in prof {
            pressure.push(ProfilePoint {
                label: label.into(),
                x: x[0],
                y: x[1],
                value: v,
            });
        }
    }
    for (pi, sv, j) in crate::contact::normal_jumps(&p.interface, &s.u) {
        let pc = &p.interface.pieces[pi];
        // Gap = -[u.nu]: positive where the bodies separate.
        gap.push(ProfilePoint {
            label: label.into(),
            x: pc.a[0] + sv * pc.tangent[0],
            y: pc.a[1] + sv * pc.tangent[1],
            value: -j,
        });
    }
}

/// Run the study `name` (built-in name or path).
pub fn run(name: &str) -> Result<StudyResult> {
    run_mode(name, jobs::Mode::All).map(|r| r.expect("a full run gives a result"))
}

/// Run the study `name` in `mode`: all jobs here, one shard of them (records only, no
/// result), or a merge of the records of all shards.
pub fn run_mode(name: &str, mode: jobs::Mode) -> Result<Option<StudyResult>> {
    let t0 = Instant::now();
    let path = file::resolve(name)?;
    let sf = StudyFile::load(&path)?;
    let study_name = path.file_stem().unwrap().to_string_lossy().to_string();
    let scene_path = {
        let p = path.parent().unwrap_or(Path::new(".")).join(&sf.scene);
        if p.exists() {
            p.display().to_string()
        } else {
            sf.scene.clone()
        }
    };
    let scene = Scene::load(&scene_path)?;
    let kind = SolverKind::parse(&sf.solver).unwrap();
    let methods: Vec<Method> = sf
        .methods
        .iter()
        .map(|m| Method::parse(m).unwrap())
        .collect();
    let finest = *sf.mesh.levels.last().unwrap();
    let rlevel = finest + sf.reference.levels_above;
    let fam = sf.family_parameters();
    let refp = sf.reference_parameters();
    let n_jobs = 3
        + methods.len() * sf.mesh.levels.len()
        + sf.time.as_ref().map_or(0, |t| t.steps.len() + 1);
    let progress = Progress::new(n_jobs as u64, &study_name);

    // The independent solves, planned in order: the reference levels, every cone on every
    // level, then the time study.
    let mut plan = Vec::new();
    let mut add =
        |label: String, method: Method, level: usize, params: &Vec<(String, f64)>, steps: usize| {
            let id = plan.len();
            plan.push(jobs::Job {
                id,
                label,
                method,
                level,
                params: params.clone(),
                steps,
            });
        };
    for l in [rlevel - 2, rlevel - 1, rlevel] {
        add(
            format!("reference level {l}"),
            Method::Mortar,
            l,
            &refp,
            sf.steps,
        );
    }
    for &method in &methods {
        for &level in &sf.mesh.levels {
            add(
                format!("{} level {level}", method.name()),
                method,
                level,
                &fam,
                sf.steps,
            );
        }
    }
    if let Some(ts) = &sf.time {
        add(
            format!("time reference ({} steps)", ts.reference_steps),
            methods[0],
            ts.level,
            &fam,
            ts.reference_steps,
        );
        for &n in &ts.steps {
            if ts.reference_steps % n != 0 {
                return Err(Error::input(
                    &path,
                    "time.reference_steps",
                    "reference_steps must be a multiple of every step count",
                ));
            }
            add(
                format!("time study ({n} steps)"),
                methods[0],
                ts.level,
                &fam,
                n,
            );
        }
    }
    let study_text = std::fs::read_to_string(&path).map_err(|e| Error::io(&path, e))?;
    let outputs = jobs::execute(&plan, &scene, kind, &study_text, mode, &|l: &str| {
        progress.tick(l.to_string())
    })?;
    if let jobs::Mode::Shard(i, n) = mode {
        progress.0.finish_and_clear();
        eprintln!(
            "shard {i}/{n}: {} of {} jobs solved, records in {}",
            outputs.iter().filter(|o| o.is_some()).count(),
            plan.len(),
            jobs::records_dir().display()
        );
        return Ok(None);
    }
    let mut outputs: std::collections::VecDeque<(Case, Solution)> = outputs
        .into_iter()
        .map(|o| o.expect("all jobs ran"))
        .collect();
    let mut refs = Vec::new();
    for _ in 0..3 {
        let (case, sol) = outputs.pop_front().unwrap();
        if case.problem.interface.min_relative_separation() > 1e-9 {
            return Err(Error::input(
                &path,
                "reference.parameters",
                "the reference meshes do not match on Gamma_C; set the .geo parameter that makes them match (e.g. matching = 1)",
            ));
        }
        let wall = sol.wall_s;
        refs.push((case, sol, wall));
    }
    let (rcase, rsol, rwall) = refs.pop().unwrap();
    let warnings = rcase.warnings.clone();
    let d1 = theorem_distance(&refs[1].0, &refs[1].1, &rcase, &rsol);
    let d2 = theorem_distance(&refs[0].0, &refs[0].1, &rcase, &rsol);
    // The reference levels are nested conforming spaces, so their errors are close to
    // orthogonal: d(L, R)^2 = e_L^2 - e_R^2 with e_L = C h_L^p (measured on this scene:
    // d(R-2,R)/d(R-1,R) = 2.24 = sqrt(5), i.e. p = 1). Hence
    // (d(R-2,R)/d(R-1,R))^2 = 4^p + 1 and e_R = d(R-1,R) / sqrt(4^p - 1).
    let p_ref = ((d2 / d1).powi(2) - 1.0)
        .max(1.0 + 1e-12)
        .log(4.0)
        .clamp(0.25, 3.0);
    let ref_err = d1 / (4f64.powf(p_ref) - 1.0).sqrt();
    drop(refs);
    let ref_norms: Vec<SquaredNorms> = rsol
        .states
        .iter()
        .skip(1)
        .map(|s| error::norms(&rcase.problem.model, s))
        .collect();
    let uref = rsol
        .states
        .iter()
        .map(|s| s.u.iter().fold(0.0f64, |a, v| a.max(v.abs())))
        .fold(0.0f64, f64::max);

    // 2. Every level with every cone against the reference.
    let mut errors = Vec::new();
    let mut levels = Vec::new();
    let mut pressure = Vec::new();
    let mut gap = Vec::new();
    let mut deformed_meshes = Vec::new();
    let profile_level = sf.mesh.levels[sf.mesh.levels.len() / 2];
    profiles(&rcase, &rsol, "reference", &mut pressure, &mut gap);
    let umax_ref = rsol.last().u.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let magnification = 0.1 / umax_ref.max(f64::MIN_POSITIVE);
    for &method in &methods {
        for &level in &sf.mesh.levels {
            let (case, sol) = outputs.pop_front().unwrap();
            let wall = sol.wall_s;
            let cmp = Comparison::new(&case.problem.model, &rcase.problem.model);
            let diff: Vec<SquaredNorms> = sol
                .states
                .iter()
                .zip(&rsol.states)
                .skip(1)
                .map(|(s, r)| cmp.difference(&case.problem.model, s, &rcase.problem.model, r))
                .collect();
            let pdiff: Vec<(f64, f64)> = sol
                .states
                .iter()
                .zip(&rsol.states)
                .skip(1)
                .map(|(s, r)| error::pressure_difference(&case.problem, s, &rcase.problem, r))
                .collect();
            let pen = sol
                .states
                .iter()
                .map(|s| metrics::max_penetration(&case.problem, s))
                .fold(0.0f64, f64::max);
            let q = relative_quantities(&diff, &ref_norms, &pdiff, pen, uref);
            for name in &sf.quantities {
                let e = q[name.as_str()];
                if !e.is_finite() {
                    return Err(Error::NotConverged(format!(
                        "{} level {level}: the {name} error is not finite",
                        method.name()
                    )));
                }
                errors.push(ErrorRow {
                    method: method.name().into(),
                    level,
                    h: case.h,
                    dofs: case.problem.model.n_free,
                    steps: sf.steps,
                    quantity: name.clone(),
                    error: e,
                    wall_s: wall,
                });
            }
            let last = sol.last();
            levels.push(LevelInfo {
                method: method.name().into(),
                level,
                h: case.h,
                dofs: case.problem.model.n_free,
                slave_nodes: case
                    .problem
                    .interface
                    .pieces
                    .iter()
                    .map(|p| p.slave_nodes.len())
                    .sum(),
                master_nodes: case
                    .problem
                    .interface
                    .pieces
                    .iter()
                    .map(|p| p.master_nodes.len())
                    .sum(),
                iterations: sol.iterations(),
                max_step_iterations: sol.max_step_iterations(),
                contact_fraction: metrics::contact_fraction(&case.problem, last),
                plastic_fraction: metrics::plastic_fraction(&case.problem, last),
                flagged: q["theorem"] < 5.0 * ref_err,
            });
            if level == profile_level {
                profiles(&case, &sol, method.name(), &mut pressure, &mut gap);
                deformed_meshes.push(deformed(&case, &sol, method.name(), magnification));
            }
        }
    }

    // 3. Rates over the levels not flagged.
    let mut rates_out = Vec::new();
    for &method in &methods {
        for qn in &sf.quantities {
            let rows: Vec<&ErrorRow> = errors
                .iter()
                .filter(|r| r.method == method.name() && &r.quantity == qn)
                .collect();
            let exact_method = sf.thresholds.exact.iter().any(|m| m == method.name());
            let used: Vec<&&ErrorRow> = rows
                .iter()
                .filter(|r| {
                    exact_method
                        || !levels
                            .iter()
                            .any(|l| l.method == r.method && l.level == r.level && l.flagged)
                })
                .collect();
            let h: Vec<f64> = used.iter().map(|r| r.h).collect();
            let e: Vec<f64> = used.iter().map(|r| r.error).collect();
            let dofs: Vec<f64> = used.iter().map(|r| r.dofs as f64).collect();
            let fit = rates::fit(&h, &e);
            let fit_d = rates::fit(&dofs, &e);
            let exact = sf.thresholds.exact.iter().any(|m| m == method.name());
            let threshold = (qn == "theorem").then(|| {
                if exact {
                    sf.thresholds.exact_tolerance
                } else {
                    let required = match method {
                        Method::Mortar => sf.thresholds.mortar,
                        Method::Nts => sf.thresholds.nts,
                    };
                    required - sf.thresholds.tolerance
                }
            });
            let (rate, stderr) = fit.map_or((f64::NAN, f64::NAN), |f| (f.rate, f.stderr));
            let enough = used.len() >= 3;
            let max_err = rows.iter().map(|r| r.error).fold(0.0f64, f64::max);
            let pass = threshold.map(|t| {
                if exact {
                    max_err <= t
                } else {
                    enough && rate >= t
                }
            });
            rates_out.push(RateRow {
                method: method.name().into(),
                quantity: qn.clone(),
                rate,
                stderr,
                levels_used: used
                    .iter()
                    .map(|r| r.level.to_string())
                    .collect::<Vec<_>>()
                    .join(" "),
                threshold,
                pass,
                rate_dofs: fit_d.map_or(f64::NAN, |f| -f.rate),
                successive: rates::successive(
                    &rows.iter().map(|r| r.h).collect::<Vec<_>>(),
                    &rows.iter().map(|r| r.error).collect::<Vec<_>>(),
                )
                .iter()
                .map(|r| format!("{r:.3}"))
                .collect::<Vec<_>>()
                .join(" "),
            });
        }
    }

    // 4. Rate in time on a fixed mesh.
    let time_study = match &sf.time {
        None => None,
        Some(ts) => {
            let (case, rs) = outputs.pop_front().unwrap();
            let m = &case.problem.model;
            let mut runs = Vec::new();
            for &n in &ts.steps {
                let (_, s) = outputs.pop_front().unwrap();
                let stride = ts.reference_steps / n;
                let mut err = 0.0f64;
                let mut norm = 0.0f64;
                for (i, st) in s.states.iter().enumerate().skip(1) {
                    let r = &rs.states[i * stride];
                    let d = State2::diff(m, st, r);
                    err = err.max(d.theorem());
                    norm = norm.max(error::norms(m, r).theorem());
                }
                runs.push((
                    n,
                    case.problem.model.scene.final_time / n as f64,
                    err / norm,
                ));
            }
            let ks: Vec<f64> = runs.iter().map(|r| r.1).collect();
            let es: Vec<f64> = runs.iter().map(|r| r.2).collect();
            Some((runs, rates::fit(&ks, &es)))
        }
    };
    progress.0.finish_and_clear();
    let mut provenance = BTreeMap::new();
    provenance.insert("gmsh".into(), rcase.mesh.gmsh_version.clone());
    provenance.insert(
        "geo".into(),
        format!(
            "{} (sha256 {})",
            scene.geo.file_name().unwrap().to_string_lossy(),
            rcase.mesh.geo_hash
        ),
    );
    provenance.insert(
        "solver".into(),
        format!(
            "{} (tolerance {:.0e})",
            kind.name(),
            Settings::default().tol
        ),
    );
    provenance.insert(
        "cores".into(),
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
            .to_string(),
    );
    provenance.insert("commit".into(), commit());
    Ok(Some(StudyResult {
        name: study_name,
        description: sf.description.clone(),
        scene,
        errors,
        rates: rates_out,
        levels,
        reference: (rlevel, rcase.h, rcase.problem.model.n_free, rwall),
        reference_error: (ref_err, p_ref),
        pressure,
        gap,
        profile_level,
        deformed: deformed_meshes,
        time_study,
        provenance,
        wall_s: t0.elapsed().as_secs_f64(),
        warnings,
        file: sf,
    }))
}

/// Differences of two states on the same mesh.
struct State2;
impl State2 {
    fn diff(m: &crate::fe::Model, a: &solve::State, b: &solve::State) -> SquaredNorms {
        let d = solve::State {
            time: a.time,
            u: a.u.iter().zip(&b.u).map(|(x, y)| x - y).collect(),
            sigma: a.sigma.iter().zip(&b.sigma).map(|(x, y)| x - y).collect(),
            lambda: Vec::new(),
        };
        error::norms(m, &d)
    }
}

/// The git commit of the working tree, or "unknown".
pub fn commit() -> String {
    std::process::Command::new("git")
        .args(["rev-parse", "--short=12", "HEAD"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_else(|| "unknown".into())
}
