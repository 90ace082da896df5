//! `grade`: the solutions of a contact code this project did not write, one per mesh level,
//! measured against the scene's exact solution with the studies' error integrals, judged by
//! the studies' rate verdicts, beside this project's mortar, nts and lac on the family's meshes.

use super::checks::{self, CheckRecord, LevelCheck};
use super::family::{Family, Source};
use super::mesh_in::OutsideModel;
use crate::case::Case;
use crate::contact::Method;
use crate::error::{Error, Result};
use crate::io::solution::{FieldNames, SolutionStep, read_msh_solution, read_pvd, read_vtu};
use crate::solve::Solution;
use crate::solve::SolverKind;
use crate::verify::field::{P1Field, P1History};
use crate::verify::jobs::{self, Job};
use crate::verify::judge::{RateRow, Rules, Threshold, judge_errors};
use crate::verify::norms::Comparison;
use crate::verify::quantity::Quantity;
use crate::verify::quantity::Scale;
use crate::verify::rates;
use crate::verify::study_file::{LoadedStudy, needs};
use crate::verify::table::{ErrorRecord, MethodLabel};
use crate::verify::truth::Truth;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// What `grade` was asked.
pub struct GradeRequest {
    /// The study or scene whose problem was solved.
    pub source: Source,
    /// The folder of level_L.{vtu,pvd,msh}.
    pub solutions: PathBuf,
    /// The levels to grade (default: every level with a file).
    pub levels: Option<Vec<usize>>,
    /// The graded code's label in the report.
    pub name: String,
    /// The rate the graded code's key quantity must reach.
    pub threshold: Option<f64>,
    /// The field names.
    pub names: FieldNames,
    /// Solve mortar, nts and lac on the family's meshes beside it.
    pub compare: bool,
}

/// How a level's solution is stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Storage {
    /// One .vtu: the state at T.
    Vtu,
    /// A .pvd series.
    Pvd,
    /// An MSH file with views.
    Msh,
}

impl Storage {
    const ALL: [(Storage, &'static str); 3] = [
        (Storage::Vtu, "vtu"),
        (Storage::Pvd, "pvd"),
        (Storage::Msh, "msh"),
    ];
}

/// One level's measured solution.
pub struct GradedLevel {
    pub level: usize,
    pub file: PathBuf,
    pub storage: Storage,
    /// The times graded (t_1..t_N, or T alone).
    pub times: Vec<f64>,
    /// Whether the file gave stresses (otherwise E eps(u_h) of the elastic bodies).
    pub stress_given: bool,
    pub pressure_given: bool,
    pub h: f64,
    pub dofs: usize,
    pub triangles: usize,
    /// What was checked of the file: equilibrium, Gamma_C's forces, the pressure's scale.
    pub check: LevelCheck,
}

impl GradedLevel {
    /// Why this level is not a converged solution of the problem, given its error in the key
    /// quantity (empty: it is one).
    pub fn problems(&self, error: f64) -> Vec<String> {
        self.check.problems(error)
    }
}

/// What `grade` measured.
pub struct Graded {
    /// The scene's name, and the study's if the family is one.
    pub scene: String,
    pub study: Option<String>,
    pub label: String,
    pub levels: Vec<GradedLevel>,
    pub errors: Vec<ErrorRecord>,
    pub rates: Vec<RateRow>,
    /// The quantity the threshold applies to.
    pub key: Quantity,
    /// The time steps of the problem.
    pub steps: usize,
    /// The solves of this project's cones were compared.
    pub compared: bool,
    /// Sentences for the user: what was graded how.
    pub notes: Vec<String>,
    /// Why the threshold failed (empty: passed, unverified or none given).
    pub failures: Vec<String>,
    /// Why the threshold is neither met nor missed (empty: passed, failed or none given).
    pub unverified: Vec<String>,
    /// The command that reproduces the grade (the report folder aside).
    pub command: String,
    /// Each level's checks (checks.csv).
    pub checks: Vec<CheckRecord>,
    /// Why a level is set apart as no converged solution, one sentence per level.
    pub flagged: Vec<String>,
}

/// The solution files of `dir`, per level: exactly one each.
fn level_files(
    dir: &Path,
    wanted: Option<&[usize]>,
) -> Result<BTreeMap<usize, (Storage, PathBuf)>> {
    let entries = std::fs::read_dir(dir).map_err(|e| {
        Error::input(dir, "--solutions", format!("cannot read the folder ({e}); pass the folder that holds level_L.vtu, level_L.pvd or level_L.msh"))
    })?;
    let mut found: BTreeMap<usize, Vec<(Storage, PathBuf)>> = BTreeMap::new();
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().to_string();
        if entry.path().is_dir() {
            if let Some((level, file)) = level_folder(&name, &entry.path())? {
                found.entry(level).or_default().push(file);
            }
            continue;
        }
        let Some(rest) = name.strip_prefix("level_") else {
            continue;
        };
        let Some((level, ext)) = rest.split_once('.') else {
            continue;
        };
        let (Ok(level), Some(storage)) = (
            level.parse::<usize>(),
            Storage::ALL.iter().find(|(_, e)| *e == ext).map(|s| s.0),
        ) else {
            continue;
        };
        found
            .entry(level)
            .or_default()
            .push((storage, entry.path()));
    }
    if let Some((level, files)) = found.iter().find(|(_, f)| f.len() > 1) {
        let names: Vec<String> = files.iter().map(|f| f.1.display().to_string()).collect();
        return Err(Error::input(
            dir,
            format!("level_{level}"),
            format!(
                "level {level} has {} solutions ({}); keep one of them",
                files.len(),
                names.join(", ")
            ),
        ));
    }
    let mut out: BTreeMap<usize, (Storage, PathBuf)> = found
        .into_iter()
        .map(|(l, mut f)| (l, f.remove(0)))
        .collect();
    if let Some(legacy) = legacy_vtk(dir, &out, wanted) {
        return Err(legacy);
    }
    if let Some(wanted) = wanted {
        if let Some(missing) = wanted.iter().find(|l| !out.contains_key(l)) {
            return Err(Error::input(
                dir,
                format!("level_{missing}"),
                format!(
                    "--levels asks for level {missing}, but the folder has no level_{missing}.vtu, .pvd or .msh; write it, or leave the level out of --levels"
                ),
            ));
        }
        out.retain(|l, _| wanted.contains(l));
    }
    let at_t: Vec<usize> = out
        .iter()
        .filter(|(_, f)| f.0 == Storage::Vtu)
        .map(|(l, _)| *l)
        .collect();
    if !at_t.is_empty() && at_t.len() < out.len() {
        return Err(Error::input(
            dir,
            format!("level_{}", at_t[0]),
            format!(
                "levels {at_t:?} give the state at T alone (.vtu), the others a series: their errors would be different norms (at T, or the maximum over the steps); give every level the same way"
            ),
        ));
    }
    if out.is_empty() {
        return Err(Error::input(
            dir,
            "--solutions",
            "holds no level_L.vtu, level_L.pvd or level_L.msh; write one per mesh level (README.md of the export says how)",
        ));
    }
    Ok(out)
}

/// A folder `level_L` (as `solve --out DIR/level_L` writes one): its one .pvd series, or its
/// one .vtu or .msh file.
fn level_folder(name: &str, path: &Path) -> Result<Option<(usize, (Storage, PathBuf))>> {
    let Some(level) = name
        .strip_prefix("level_")
        .and_then(|l| l.parse::<usize>().ok())
    else {
        return Ok(None);
    };
    let mut files: Vec<(Storage, PathBuf)> = std::fs::read_dir(path)
        .map_err(|e| Error::input(path, "--solutions", format!("cannot read the folder ({e})")))?
        .flatten()
        .filter_map(|entry| {
            let p = entry.path();
            let ext = p.extension()?.to_str()?.to_string();
            Storage::ALL
                .iter()
                .find(|(_, e)| *e == ext)
                .map(|(storage, _)| (*storage, p))
        })
        .collect();
    files.sort_by(|a, b| a.1.cmp(&b.1));
    // A series' steps are .vtu files beside its .pvd: the .pvd is the level.
    if files.iter().any(|f| f.0 == Storage::Pvd) {
        files.retain(|f| f.0 == Storage::Pvd);
    }
    match files.len() {
        0 => Ok(None),
        1 => Ok(Some((level, files.remove(0)))),
        n => Err(Error::input(
            path,
            format!("level_{level}"),
            format!(
                "the folder of level {level} holds {n} solutions ({}); keep one .pvd, or one .vtu or .msh",
                files
                    .iter()
                    .map(|f| f.1.display().to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        )),
    }
}

/// A level given only as a legacy VTK file (`level_L.vtk`, which grade does not read),
/// where it is missing or no level is found: refused with meshio's conversion.
fn legacy_vtk(
    dir: &Path,
    found: &BTreeMap<usize, (Storage, PathBuf)>,
    wanted: Option<&[usize]>,
) -> Option<Error> {
    let level = std::fs::read_dir(dir).ok()?.flatten().find_map(|entry| {
        let name = entry.file_name().to_string_lossy().to_string();
        let level: usize = name
            .strip_prefix("level_")?
            .strip_suffix(".vtk")?
            .parse()
            .ok()?;
        let needed = match wanted {
            Some(w) => w.contains(&level),
            None => found.is_empty(),
        };
        (needed && !found.contains_key(&level)).then_some(level)
    })?;
    Some(Error::input(
        dir.join(format!("level_{level}.vtk")),
        "format",
        format!(
            "a legacy VTK file, which grade does not read; convert it to VTK XML with meshio (`pip install meshio`): python3 -c \"import meshio; meshio.write('level_{level}.vtu', meshio.read('level_{level}.vtk'))\" (keep the cell data `body`, or set it as the export's README.md shows), then grade again"
        ),
    ))
}

/// The states of one level's file, with their times.
fn read_level(
    storage: Storage,
    path: &Path,
    names: &FieldNames,
    family: &Family,
) -> Result<Vec<(f64, SolutionStep)>> {
    let times = family.times();
    let final_time = family.scene.final_time;
    let steps = match storage {
        Storage::Vtu => return Ok(vec![(final_time, read_vtu(path, names)?)]),
        Storage::Pvd => read_pvd(path)?
            .into_iter()
            .map(|(t, file)| Ok((t, read_vtu(&file, names)?)))
            .collect::<Result<Vec<_>>>()?,
        Storage::Msh => read_msh_solution(
            path,
            names,
            [
                &family.scene.bodies[0].surface,
                &family.scene.bodies[1].surface,
            ],
        )?,
    };
    // t_0 = 0 is the unloaded state, not graded.
    let steps: Vec<(f64, SolutionStep)> = steps
        .into_iter()
        .filter(|(t, _)| t.abs() > 1e-9 * final_time)
        .collect();
    let matches = steps.len() == times.len()
        && steps
            .iter()
            .zip(&times)
            .all(|((t, _), tn)| (t - tn).abs() <= 1e-9 * final_time);
    if !matches {
        let given: Vec<String> = steps.iter().map(|(t, _)| format!("{t}")).collect();
        let want: Vec<String> = times.iter().map(|t| format!("{t}")).collect();
        return Err(Error::input(
            path,
            "time",
            format!(
                "the steps' times are [{}]; the problem's are t_n = [{}] (problem.toml's time.times): write one state per t_n, or the final state alone as level_L.vtu",
                given.join(", "),
                want.join(", ")
            ),
        ));
    }
    if let Some((_, first)) = steps.first()
        && steps.iter().any(|(_, s)| s.mesh != first.mesh)
    {
        return Err(Error::input(
            path,
            "Cells",
            "the steps are on different meshes; write every step on the same mesh",
        ));
    }
    Ok(steps)
}

/// The quantities measured: the study's, or for a scene every one its exact solution
/// gives; the pressure ones only where the solutions give a pressure.
fn quantities(family: &Family, study: Option<&LoadedStudy>, pressure: bool) -> Vec<Quantity> {
    let exact = family
        .scene
        .exact
        .as_deref()
        .expect("a graded family has an exact solution");
    let all: Vec<Quantity> = match study {
        Some(s) => s.file.quantities.clone(),
        None => Quantity::ALL
            .into_iter()
            .filter(|q| needs(*q).iter().all(|f| exact.gives(*f)))
            .collect(),
    };
    // A distance between the cones is not a property of one solution, nor the discrete
    // gap of the method's rows, which a solution's files do not carry.
    all.into_iter()
        .filter(|q| !q.is_distance() && !q.reads_rows() && (pressure || !q.needs_pressure()))
        .collect()
}

/// The rows of errors.csv of one level's errors.
fn rows(
    label: &MethodLabel,
    level: usize,
    h: f64,
    dofs: usize,
    steps: usize,
    wall_s: Option<f64>,
    quantities: &[Quantity],
    errors: &BTreeMap<Quantity, f64>,
    file: &Path,
) -> Result<Vec<ErrorRecord>> {
    quantities
        .iter()
        // A quantity relative to a size the truth lacks has no row (verify::rates::relative_to).
        .filter_map(|&quantity| Some((quantity, *errors.get(&quantity)?)))
        .map(|(quantity, error)| {
            if !error.is_finite() {
                return Err(Error::input(
                    file,
                    quantity.name(),
                    format!("the {quantity} error is not finite; check the solution's values"),
                ));
            }
            Ok(ErrorRecord {
                method: label.clone(),
                level,
                h,
                dofs,
                steps,
                quantity,
                error,
                wall_s,
                parameter: None,
            })
        })
        .collect()
}

/// This project's cones on the family's levels, each solved once and kept as a record.
type Cones = Vec<(Method, usize, Case, Solution)>;

/// Grade the solutions of `req`: the cones solved first (mortar's solution is what each
/// graded level's distance to mortar is measured against), each level read, checked and
/// measured, the levels that are no converged solution set apart, the rest judged.
pub fn grade(req: &GradeRequest) -> Result<Graded> {
    let label = check_label(&req.name)?;
    let family = Family::resolve(&req.source)?;
    let study = match &req.source {
        Source::Study(name) => Some(LoadedStudy::load(name)?),
        Source::Scene(_) => None,
    };
    let exact = family
        .scene
        .exact
        .as_deref()
        .expect("resolve refuses a scene without one");
    let points = study
        .as_ref()
        .map_or(crate::verify::exact_error::DEFAULT_POINTS, |s| {
            s.file.reference.quadrature
        });
    let truth = Truth::Exact(exact, points);
    let key = key_quantity(exact);
    let files = level_files(&req.solutions, req.levels.as_deref())?;
    let cones = solve_cones(&family, &files, req.compare)?;
    let (levels, measured, resultant_fixed) =
        measure_levels(req, &family, &truth, key, &files, &cones)?;
    check_distinct_h(&levels, &req.solutions)?;
    let ratios: Vec<(usize, &Path, f64)> = levels
        .iter()
        .filter_map(|l| {
            l.check
                .pressure_ratio
                .map(|r| (l.level, l.file.as_path(), r))
        })
        .collect();
    checks::check_pressure_scale(&ratios)?;
    let pressure = levels.iter().all(|l| l.pressure_given);
    let quantities = quantities(&family, study.as_ref(), pressure);
    let mut errors = graded_rows(&label, &levels, &measured, &quantities, key)?;
    errors.extend(cone_rows(&family, study.as_ref(), &truth, &cones)?);
    let threshold = |m: &MethodLabel, q: Quantity| {
        req.threshold
            .filter(|_| m == &label && q == key)
            .map(Threshold::Rate)
    };
    let rules = Rules {
        truth_error: &|_| 0.0,
        resultant_fixed,
        threshold: &threshold,
    };
    let rates = judge_errors(&errors, &rules)
        .map_err(|e| Error::input(&req.solutions, "levels", e.to_string()))?;
    let residual_note = residual_note(&label, &levels, &measured, key, &rules);
    let failures = rates.iter().filter_map(RateRow::failure).collect();
    let unverified = rates.iter().filter_map(RateRow::unverified).collect();
    let mut notes = notes(&levels, &family, pressure);
    notes.extend(residual_note);
    let command = command_line(req, &files);
    let (checks, flagged) = level_checks(&levels, &measured, key);
    Ok(Graded {
        checks,
        flagged,
        scene: family.scene.name.clone(),
        study: family.study.clone(),
        label: label.name().to_string(),
        levels,
        errors,
        rates,
        key,
        steps: family.steps,
        compared: req.compare,
        notes,
        failures,
        unverified,
        command,
    })
}

/// Where a graded level's residual exceeds 1/20 of its error: the key rate of the errors
/// with the residual taken off (u~_h, [`LevelCheck::shift`]; the other levels' as graded)
/// beside the file's, judged by the same rules: what the code's own load integration (or
/// its solver) does to its rate.
fn residual_note(
    label: &MethodLabel,
    levels: &[GradedLevel],
    measured: &[BTreeMap<Quantity, f64>],
    key: Quantity,
    rules: &Rules,
) -> Option<String> {
    let graded: Vec<(&GradedLevel, f64)> = levels
        .iter()
        .zip(measured)
        .map(|(l, e)| (l, e[&key]))
        .filter(|(l, e)| l.problems(*e).is_empty())
        .collect();
    if graded.iter().all(|(l, _)| l.check.shift.is_none()) {
        return None;
    }
    let record = |l: &GradedLevel, error: f64| ErrorRecord {
        method: label.clone(),
        level: l.level,
        h: l.h,
        dofs: l.dofs,
        steps: l.times.len(),
        quantity: key,
        error,
        wall_s: None,
        parameter: None,
    };
    let fitted = |records: Vec<ErrorRecord>| {
        let rows = judge_errors(&records, rules).ok()?;
        rows.into_iter()
            .find(|r| r.quantity == key)
            .and_then(|r| r.supported_fit().map(|f| f.rate))
    };
    let file = fitted(graded.iter().map(|(l, e)| record(l, *e)).collect());
    let corrected = fitted(
        graded
            .iter()
            .map(|(l, e)| record(l, e * (1.0 + l.check.shift.unwrap_or(0.0))))
            .collect(),
    );
    let shifts: Vec<String> = graded
        .iter()
        .filter_map(|(l, _)| {
            Some(format!(
                "level {}: {:+.2}%",
                l.level,
                100.0 * l.check.shift?
            ))
        })
        .collect();
    let rates = match (file, corrected) {
        (Some(a), Some(b)) => format!(
            "its {key} rate is {a:.3} as graded and {b:.3} without the residual, a difference of {:+.3}",
            b - a
        ),
        _ => format!("no {key} rate is supported with or without the residual"),
    };
    Some(format!(
        "Equilibrium residuals above 1/20 of the error, each of a load rule's size (the code's own load integration, checks.csv `residual_cause`): the key error of the field in equilibrium with the exported loads (Gamma_C held) differs from the file's by {}; {rates}.",
        shifts.join(", ")
    ))
}

/// checks.csv's rows, and for each level that is no converged solution, why (its errors
/// give no rate).
fn level_checks(
    levels: &[GradedLevel],
    measured: &[BTreeMap<Quantity, f64>],
    key: Quantity,
) -> (Vec<CheckRecord>, Vec<String>) {
    let mut flagged = Vec::new();
    let records = levels
        .iter()
        .zip(measured)
        .map(|(l, e)| {
            let problems = l.problems(e[&key]);
            if !problems.is_empty() {
                flagged.push(format!(
                    "level {} ({}) is not a converged solution of this problem, and gives no rate: {}",
                    l.level,
                    l.file.display(),
                    problems.join("; ")
                ));
            }
            CheckRecord::new(l.level, l.h, e[&key], &l.check)
        })
        .collect();
    (records, flagged)
}

/// Mortar, nts and lac on every graded level (none without `compare`), in parallel.
fn solve_cones(
    family: &Family,
    files: &BTreeMap<usize, (Storage, PathBuf)>,
    compare: bool,
) -> Result<Cones> {
    let jobs: Vec<(Method, usize)> = match compare {
        true => Method::ALL
            .into_iter()
            .flat_map(|m| files.keys().map(move |&l| (m, l)))
            .collect(),
        false => Vec::new(),
    };
    jobs.par_iter()
        .map(|&(method, level)| {
            let (case, solution) = cone_solve(family, method, level)?;
            Ok((method, level, case, solution))
        })
        .collect()
}

/// Mortar's solve of `level` among `cones`.
fn mortar_at(cones: &Cones, level: usize) -> Option<(&Case, &Solution)> {
    cones
        .iter()
        .find(|c| c.0.is_reference() && c.1 == level)
        .map(|c| (&c.2, &c.3))
}

/// Every level's file read, checked and measured (in parallel, in level order); with
/// whether equilibrium fixes the contact resultant on them.
#[allow(clippy::type_complexity)]
fn measure_levels(
    req: &GradeRequest,
    family: &Family,
    truth: &Truth,
    key: Quantity,
    files: &BTreeMap<usize, (Storage, PathBuf)>,
    cones: &Cones,
) -> Result<(Vec<GradedLevel>, Vec<BTreeMap<Quantity, f64>>, bool)> {
    let graded: Vec<(GradedLevel, BTreeMap<Quantity, f64>, bool)> = files
        .par_iter()
        .map(|(&level, (storage, path))| {
            grade_level(
                level,
                *storage,
                path,
                &req.names,
                family,
                truth,
                key,
                mortar_at(cones, level),
            )
        })
        .collect::<Result<Vec<_>>>()?;
    let resultant_fixed = graded.first().is_some_and(|g| g.2);
    let (levels, measured) = graded.into_iter().map(|(l, m, _)| (l, m)).unzip();
    Ok((levels, measured, resultant_fixed))
}

/// The graded code's rows of errors.csv: its converged levels only (a flagged level's
/// errors are an iteration's, and give no rate; checks.csv keeps its key error).
fn graded_rows(
    label: &MethodLabel,
    levels: &[GradedLevel],
    measured: &[BTreeMap<Quantity, f64>],
    quantities: &[Quantity],
    key: Quantity,
) -> Result<Vec<ErrorRecord>> {
    let mut errors = Vec::new();
    for (l, e) in levels.iter().zip(measured) {
        if !l.problems(e[&key]).is_empty() {
            continue;
        }
        let mut quantities = quantities.to_vec();
        quantities.extend(DECOMPOSED_DISTANCES.iter().filter(|q| e.contains_key(q)));
        let steps = l.times.len();
        errors.extend(rows(
            label,
            l.level,
            l.h,
            l.dofs,
            steps,
            None,
            &quantities,
            e,
            &l.file,
        )?);
    }
    Ok(errors)
}

/// The cones' rows of errors.csv: their errors against the truth and, for nts, its
/// distance to mortar on the same level.
fn cone_rows(
    family: &Family,
    study: Option<&LoadedStudy>,
    truth: &Truth,
    cones: &Cones,
) -> Result<Vec<ErrorRecord>> {
    let cone_quantities: Vec<Quantity> = match study {
        Some(s) => s.file.quantities.clone(),
        None => self::quantities(family, None, true),
    }
    .into_iter()
    .filter(|q| !q.is_distance())
    .collect();
    let mut errors = Vec::new();
    for (method, level, case, solution) in cones {
        let (mut errors_here, scale) = truth.measure_solved(case, solution);
        if !method.is_reference()
            && let Some((mc, ms)) = mortar_at(cones, *level)
        {
            let (a, b) = (
                P1History::of_solution(case, solution),
                P1History::of_solution(mc, ms),
            );
            errors_here.extend(
                crate::verify::distance::cone_distance(&a, &b, &scale)
                    .into_iter()
                    .filter(|(q, _)| DECOMPOSED_DISTANCES.contains(q)),
            );
        }
        let mut quantities = cone_quantities.clone();
        quantities.extend(
            DECOMPOSED_DISTANCES
                .iter()
                .filter(|q| errors_here.contains_key(q)),
        );
        errors.extend(rows(
            &(*method).into(),
            *level,
            case.h,
            case.problem.model.n_free,
            family.steps,
            Some(solution.wall_s),
            &quantities,
            &errors_here,
            &family.scene.file,
        )?);
    }
    Ok(errors)
}

/// `contact-rates grade ...` with the request's options.
fn command_line(req: &GradeRequest, files: &BTreeMap<usize, (Storage, PathBuf)>) -> String {
    let source = match &req.source {
        Source::Study(s) => format!("--study {s}"),
        Source::Scene(s) => format!("--scene {s}"),
    };
    let (first, last) = (
        files.keys().next().copied().unwrap_or(0),
        files.keys().last().copied().unwrap_or(0),
    );
    let mut out = format!(
        "contact-rates grade {source} --solutions {} --levels {first}-{last} --name {}",
        req.solutions.display(),
        req.name
    );
    if let Some(t) = req.threshold {
        out.push_str(&format!(" --threshold {t}"));
    }
    if !req.compare {
        out.push_str(" --no-compare");
    }
    let defaults = FieldNames::default();
    for (flag, name, default) in [
        (
            "--displacement",
            &req.names.displacement,
            &defaults.displacement,
        ),
        ("--stress", &req.names.stress, &defaults.stress),
        ("--pressure", &req.names.pressure, &defaults.pressure),
    ] {
        if name != default {
            out.push_str(&format!(" {flag} {name}"));
        }
    }
    out
}

/// One level's file read, put on a model of the scene and measured against `truth`; with
/// whether equilibrium fixes the contact resultant on it.
fn grade_level(
    level: usize,
    storage: Storage,
    path: &Path,
    names: &FieldNames,
    family: &Family,
    truth: &Truth,
    key: Quantity,
    mortar: Option<(&Case, &Solution)>,
) -> Result<(GradedLevel, BTreeMap<Quantity, f64>, bool)> {
    let steps = read_level(storage, path, names, family)?;
    let (reference, raw) = family.model(level)?;
    let mesh = &steps[0].1.mesh;
    let outside = OutsideModel::new(&family.scene, mesh, &reference, &raw, path)?;
    let history = P1History {
        model: &outside.model,
        interface: &outside.interface,
        steps: steps
            .iter()
            .map(|(t, s)| outside.field(*t, s, path))
            .collect::<Result<Vec<_>>>()?,
    };
    let resultant_fixed = outside
        .interface
        .resultant_fixed_by_equilibrium(&outside.model);
    let (mut errors, scale) = truth.measure(&history);
    if let Some(mortar) = mortar {
        errors.extend(distance_to_mortar(&history, mortar, &scale));
    }
    let checked = checks::check_level(&outside.model, &outside.interface, &history.steps)?;
    let mut check = checked.check;
    let error = errors[&key];
    if check.residual > LevelCheck::residual_limit(error) {
        check.shift =
            Some(corrected_error(&history, &checked.corrections, truth, key) / error - 1.0);
    }
    let graded = GradedLevel {
        check,
        level,
        file: path.to_path_buf(),
        storage,
        times: steps.iter().map(|s| s.0).collect(),
        stress_given: steps[0].1.stress.is_some(),
        pressure_given: steps.iter().all(|s| s.1.pressure.is_some()),
        h: outside.model.judge_h(),
        dofs: outside.model.n_free,
        triangles: outside.model.elements.len(),
    };
    Ok((graded, errors, resultant_fixed))
}

/// The key error of `history` with each step's `corrections` taken off (u - c, sigma -
/// C eps(c)): the field in equilibrium with the exported loads, Gamma_C's trace held. Its
/// pressure is left out (the key quantity is not the pressure's).
fn corrected_error(
    history: &P1History,
    corrections: &[Vec<f64>],
    truth: &Truth,
    key: Quantity,
) -> f64 {
    let model = history.model;
    let steps = history
        .steps
        .iter()
        .zip(corrections)
        .map(|(step, c)| {
            if c.is_empty() {
                return P1Field {
                    pressure: None,
                    ..step.clone()
                };
            }
            let u: Vec<f64> = step.u.iter().zip(c).map(|(u, c)| u - c).collect();
            let change = model.elastic_stresses(c);
            let stress = step
                .stress
                .iter()
                .zip(&change)
                .map(|(s, d)| s - d)
                .collect::<Vec<_>>();
            P1Field {
                time: step.time,
                u: u.into(),
                stress: stress.into(),
                pressure: None,
                pressure_space: step.pressure_space,
            }
        })
        .collect();
    let corrected = P1History {
        model,
        interface: history.interface,
        steps,
    };
    truth.measure(&corrected).0[&key]
}

/// The graded code's label: any name but a cone's.
fn check_label(name: &str) -> Result<MethodLabel> {
    let ok = !name.trim().is_empty()
        && name
            .chars()
            .all(|c| c.is_alphanumeric() || "-_.+".contains(c));
    if !ok {
        return Err(Error::input(
            "--name",
            "name",
            format!(
                "'{name}' is not a label; use letters, digits and - _ . + (e.g. getfem-nitsche)"
            ),
        ));
    }
    match MethodLabel::parse(name) {
        MethodLabel::Cone(m) => Err(Error::input(
            "--name",
            "name",
            format!(
                "'{m}' names this project's own cone, which grade puts beside yours; choose another label"
            ),
        )),
        label => Ok(label),
    }
}

/// Two levels with the same h cannot give a rate ([`rates::check_distinct_h`]): refused,
/// naming both files, before anything is solved beside them.
fn check_distinct_h(levels: &[GradedLevel], dir: &Path) -> Result<()> {
    let as_levels =
        crate::verify::judge::levels_of(levels.iter().map(|l| (l.level, l.h, l.dofs as f64, 0.0)));
    rates::check_distinct_h(&as_levels).map_err(|e| {
        let of = |level: usize| levels.iter().find(|l| l.level == level);
        let file = |level: usize| of(level).map_or(String::new(), |l| l.file.display().to_string());
        let (a, b) = e.levels;
        Error::input(
            dir,
            format!("level_{b}"),
            format!(
                "levels {a} and {b} have the same h = {} ({} and {}): each level must be a finer mesh than the one before; write level L on the family's level-L mesh",
                of(a).map_or(f64::NAN, |l| l.h),
                file(a),
                file(b)
            ),
        )
    })
}

/// The quantity a threshold applies to: the theorem norm, or l2_stress where the exact
/// solution gives no displacement (`patch`).
pub fn key_quantity(exact: &crate::analytical::Exact) -> Quantity {
    if exact.displacement.is_some() {
        Quantity::Theorem
    } else {
        Quantity::L2Stress
    }
}

/// The distances to mortar that each graded code and nts are read against
/// (decomposition.csv).
const DECOMPOSED_DISTANCES: [Quantity; 3] = [
    Quantity::ConeDistance,
    Quantity::ConeDistanceH1U,
    Quantity::ConeDistanceL2Stress,
];

/// This project's `method` on the family's level `level`, solved once and kept as a
/// record (the studies' job records, keyed by everything the solve depends on).
fn cone_solve(family: &Family, method: Method, level: usize) -> Result<(Case, Solution)> {
    let job = Job {
        id: 0,
        label: format!("{method} level {level}"),
        method,
        level,
        body_levels: [level, level],
        params: family.params.clone(),
        steps: family.steps,
        scene: 0,
    };
    jobs::solve_cached(&job, &family.scene, SolverKind::Newton, "grade")
}

/// The distance between a graded level's solution and mortar's on the same level
/// (through the intersection of the two meshes), max over the steps, each matched with
/// mortar's step at the same time, relative to the truth's sizes `scale`. Empty unless the
/// graded steps are all of mortar's: D is read against errors that are maxima over every
/// step, and a distance at T alone would mix two norms in time.
fn distance_to_mortar(
    graded: &P1History,
    mortar: (&Case, &Solution),
    scale: &Scale,
) -> BTreeMap<Quantity, f64> {
    let m = P1History::of_solution(mortar.0, mortar.1);
    let tolerance = 1e-9 * m.steps.last().map_or(1.0, |s| s.time.abs().max(1.0));
    let pairs: Option<Vec<(&P1Field, &P1Field)>> = graded
        .steps
        .iter()
        .map(|g| {
            m.steps
                .iter()
                .find(|s| (s.time - g.time).abs() <= tolerance)
                .map(|s| (g, s))
        })
        .collect();
    let Some(pairs) = pairs.filter(|p| p.len() == m.steps.len()) else {
        return BTreeMap::new();
    };
    let cmp = Comparison::new(graded.model, m.model);
    let (mut theorem, mut h1, mut stress) = (0.0f64, 0.0f64, 0.0f64);
    for (g, s) in pairs {
        let d = cmp.difference(graded.model, g, m.model, s);
        theorem = theorem.max(d.theorem());
        h1 = h1.max(d.h1());
        stress = stress.max(d.stress.sqrt());
    }
    // A distance relative to a size the truth does not have (patch's exact solution gives
    // no displacement: its H1 size is 0) is not measured: the one rule of verify::rates.
    [
        (Quantity::ConeDistance, theorem, scale.theorem),
        (Quantity::ConeDistanceH1U, h1, scale.h1),
        (Quantity::ConeDistanceL2Stress, stress, scale.stress),
    ]
    .into_iter()
    .filter_map(|(q, v, s)| Some((q, crate::verify::rates::relative_to(v, s, scale.theorem)?)))
    .collect()
}

/// What the report says about how the solutions were graded.
fn notes(levels: &[GradedLevel], family: &Family, pressure: bool) -> Vec<String> {
    let mut out = Vec::new();
    if levels.iter().any(|l| l.storage == Storage::Vtu) {
        out.push(format!(
            "Levels given as one .vtu are graded at t = T only: their theorem norm is the error at T, not the maximum over the {}, and their distance to mortar (a maximum over the steps like mortar's error) is not measured.",
            crate::io::count(family.steps, "step")
        ));
    }
    if levels.iter().any(|l| !l.stress_given) {
        out.push("Where a file gives no stress, the stress graded is E eps(u_h) per triangle (elastic bodies).".into());
    }
    if !pressure {
        let names: Vec<&str> = Quantity::PRESSURE.iter().map(|q| q.name()).collect();
        out.push(format!(
            "Not every level gives a pressure: the pressure quantities ({}) are not measured.",
            names.join(", ")
        ));
    }
    out
}
