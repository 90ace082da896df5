//! Studies: what the program measures, each a kind of its own.
//!
//! - [`convergence`]: a study file (studies/NAME.toml): rates of both cones on a mesh
//!   family against a fine reference, with Theorem 3.1's thresholds;
//! - [`paper`]: the paper's three numerical tests regenerated;
//! - [`speed`]: what each accuracy costs, against the floor;
//! - [`stability`]: hard cases with every solver.
//!
//! [`Kind`] names them; [`Kind::run`] runs one and gives its [`Outcome`], which
//! [`crate::report`] writes.

pub mod contact_error;
pub mod convergence;
pub mod error;
pub mod exact_error;
pub mod file;
pub mod intersect;
pub mod jobs;
pub mod paper;
pub mod quantity;
pub mod rates;
pub mod speed;
pub mod stability;
pub mod two_size;

pub use convergence::{ErrorRow, LevelInfo, RateRow, StudyResult, run, run_mode};

use crate::case::Case;
use crate::error::{Error, Result};
use crate::solve::{self, Settings, Solution, SolverKind};
use error::Comparison;
use std::path::PathBuf;
use std::time::Instant;

/// A study to run.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Kind {
    /// A convergence study file.
    Convergence(PathBuf),
    /// A two-size study file (one with a `[two_size]` table).
    TwoSize(PathBuf),
    /// The paper's tests.
    Paper,
    /// The speed study.
    Speed,
    /// The hard cases.
    Stability,
}

/// What a study measured.
#[derive(Debug)]
pub enum Outcome {
    /// A convergence study.
    Convergence(StudyResult),
    /// A two-size study.
    TwoSize(two_size::TwoSizeResult),
    /// The paper's tests.
    Paper(paper::PaperResult),
    /// The speed study.
    Speed(speed::SpeedResult),
    /// The hard cases.
    Stability(stability::StabilityResult),
}

impl Kind {
    /// The built-in kinds that are not study files, with their descriptions.
    const BUILT_IN: [(&'static str, Kind, &'static str); 3] = [
        ("paper", Kind::Paper, paper::DESCRIPTION),
        ("speed", Kind::Speed, speed::DESCRIPTION),
        ("stability", Kind::Stability, stability::DESCRIPTION),
    ];

    /// The study called `name`: a built-in kind, a built-in study file or a path.
    pub fn resolve(name: &str) -> Result<Kind> {
        match Self::BUILT_IN.iter().find(|(n, _, _)| *n == name) {
            Some((_, kind, _)) => Ok(kind.clone()),
            None => {
                let path = file::resolve(name).ok_or_else(|| unknown_study(name))?;
                let two_size = file::StudyFile::load(&path)?.two_size.is_some();
                Ok(if two_size {
                    Kind::TwoSize(path)
                } else {
                    Kind::Convergence(path)
                })
            }
        }
    }

    /// Every built-in study, name and description, sorted by name.
    pub fn list() -> Vec<(String, String)> {
        let mut all = file::list();
        all.extend(
            Self::BUILT_IN
                .iter()
                .map(|(n, _, d)| (n.to_string(), d.to_string())),
        );
        all.sort();
        all
    }

    /// The study's name: its report folder under reports/.
    pub fn name(&self) -> String {
        match self {
            Kind::Convergence(path) | Kind::TwoSize(path) => path.file_stem().map_or_else(
                || path.display().to_string(),
                |s| s.to_string_lossy().to_string(),
            ),
            other => Self::BUILT_IN
                .iter()
                .find(|(_, k, _)| k == other)
                .map(|(n, _, _)| n.to_string())
                .expect("every kind but a file is built in"),
        }
    }

    /// Run the study in `mode` (a shard of a convergence study gives no outcome; the other
    /// kinds run whole).
    pub fn run(&self, mode: jobs::Mode) -> Result<Option<Outcome>> {
        if mode != jobs::Mode::All && !matches!(self, Kind::Convergence(_)) {
            return Err(Error::input(
                self.name(),
                "--shard/--merge",
                "only convergence studies (study files) run as shards; run this study without --shard or --merge",
            ));
        }
        Ok(match self {
            Kind::Convergence(path) => {
                run_mode(&path.display().to_string(), mode)?.map(Outcome::Convergence)
            }
            Kind::TwoSize(path) => Some(Outcome::TwoSize(two_size::run(
                &path.display().to_string(),
            )?)),
            Kind::Paper => Some(Outcome::Paper(paper::run()?)),
            Kind::Speed => Some(Outcome::Speed(speed::run()?)),
            Kind::Stability => Some(Outcome::Stability(stability::run()?)),
        })
    }
}

/// The error for a study name that is neither built in nor a file.
pub fn unknown_study(name: &str) -> Error {
    let names: Vec<String> = Kind::list().into_iter().map(|(n, _)| n).collect();
    Error::input(
        name,
        "study",
        format!(
            "no built-in study named '{name}' and no such file; built-in studies: {}",
            names.join(", ")
        ),
    )
}

impl Outcome {
    /// Warnings about the scene, for the user.
    pub fn warnings(&self) -> &[String] {
        match self {
            Outcome::Convergence(r) => &r.warnings,
            Outcome::TwoSize(r) => &r.warnings,
            _ => &[],
        }
    }

    /// The thresholds missed, one sentence each (empty: the study passed).
    pub fn failures(&self) -> Vec<String> {
        match self {
            Outcome::Convergence(r) => r.failures(),
            Outcome::TwoSize(r) => r.failures(),
            _ => Vec::new(),
        }
    }
}

/// Solve `case` with `kind` on `steps` uniform steps, keeping the history; with the wall
/// time of the call (s).
pub fn solve_case(case: &Case, kind: SolverKind, steps: usize) -> Result<(Solution, f64)> {
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
pub fn theorem_distance(ca: &Case, sa: &Solution, cb: &Case, sb: &Solution) -> f64 {
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
