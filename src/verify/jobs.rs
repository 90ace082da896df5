//! The independent solves of a study as jobs: planned from the study file, run in
//! parallel across the machine's cores (each solve is sequential and deterministic, so the
//! results equal a serial run), or sliced over a cluster's job array with `--shard i/n`,
//! each job's solution stored as a record keyed by a hash of its inputs, and gathered by
//! `--merge`.

use crate::case::Case;
use crate::contact::Method;
use crate::error::{Error, Result};
use crate::mesh::gmsh;
use crate::scene::Scene;
use crate::solve::{self, Settings, Solution, SolverKind};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// A job's position in its plan.
pub type JobId = usize;

/// One solve of a study.
#[derive(Debug, Clone)]
pub struct Job {
    /// Position in the plan.
    pub id: JobId,
    /// Human-readable label.
    pub label: String,
    /// Cone.
    pub method: Method,
    /// Mesh level (the finer body's, where the bodies differ).
    pub level: usize,
    /// Levels of body 1 (the slave) and body 2; both `level` except in a two-size study.
    pub body_levels: [usize; 2],
    /// gmsh parameters.
    pub params: Vec<(String, f64)>,
    /// Time steps.
    pub steps: usize,
    /// Which of the study's scenes (0: the study's own; 1: its time study's, if another).
    pub scene: usize,
}

/// How a study's jobs are executed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// All jobs here, in parallel.
    All,
    /// Only jobs with `id % n == i - 1`, saved as records (no report).
    Shard(usize, usize),
    /// No solving: load every job's record.
    Merge,
}

impl Mode {
    /// Parse "i/n" for `--shard`.
    pub fn shard(s: &str) -> Result<Self> {
        let bad = || {
            Error::input(
                "--shard",
                "shard",
                format!("'{s}' is not i/n with 1 <= i <= n (e.g. 2/4)"),
            )
        };
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let (i, n): (usize, usize) = (
            i.trim().parse().map_err(|_| bad())?,
            n.trim().parse().map_err(|_| bad())?,
        );
        if i == 0 || n == 0 || i > n {
            return Err(bad());
        }
        Ok(Mode::Shard(i, n))
    }
}

/// The folder of job records: `records/` under the mesh cache folder.
pub fn records_dir() -> PathBuf {
    gmsh::cache_dir().join("records")
}

fn key(job: &Job, scene: &Scene, kind: SolverKind, study_text: &str) -> Result<String> {
    let scene_text = std::fs::read(&scene.file).map_err(|e| Error::io(&scene.file, e))?;
    let geo = std::fs::read(&scene.geo).map_err(|e| Error::io(&scene.geo, e))?;
    let mut k = format!(
        "record-v3|{}|{}|{}|{:?}|{:?}|{}|",
        super::commit(),
        kind.name(),
        job.method.name(),
        job.body_levels,
        job.params,
        job.steps
    );
    k.push_str(&gmsh::sha256_hex(&scene_text));
    // The slave choice: a two-size study solves one scene file with either body as slave.
    k.push_str(&scene.bodies[0].surface);
    k.push_str(&gmsh::sha256_hex(&geo));
    k.push_str(&gmsh::sha256_hex(study_text.as_bytes()));
    Ok(gmsh::sha256_hex(k.as_bytes())[..24].to_string())
}

/// What a record holds: the solution with its step reports and timings.
const RECORD_MAGIC: &[u8] = b"CRREC3\n";

/// Serialize a solution (states, step reports, timings) to bytes (postcard: f64 as their
/// exact little-endian bits).
pub fn encode(sol: &Solution) -> Vec<u8> {
    let mut out = RECORD_MAGIC.to_vec();
    out.extend(postcard::to_stdvec(sol).expect("a solution serializes"));
    out
}

/// Read back what [`encode`] wrote.
pub fn decode(bytes: &[u8], path: &Path) -> Result<Solution> {
    bytes
        .strip_prefix(RECORD_MAGIC)
        .and_then(|body| postcard::from_bytes(body).ok())
        .ok_or_else(|| {
            Error::input(
                path,
                "record",
                "the record is truncated or not a record; delete it and run the shard again",
            )
        })
}

/// Build every job's case (on its scene of `scenes`) and obtain its solution according to
/// `mode`. Returns, in plan
/// order, `Some((case, solution))` for the jobs that were run or loaded (all of them except
/// in `Shard` mode).
pub fn execute(
    jobs: &[Job],
    scenes: &[&Scene],
    kind: SolverKind,
    study_text: &str,
    mode: Mode,
    tick: &(dyn Fn(&str) + Sync),
) -> Result<Vec<Option<(Case, Solution)>>> {
    let dir = records_dir();
    let run_one = |job: &Job| -> Result<Option<(Case, Solution)>> {
        let mine = match mode {
            Mode::All | Mode::Merge => true,
            Mode::Shard(i, n) => job.id % n == i - 1,
        };
        if !mine {
            return Ok(None);
        }
        let scene = scenes[job.scene];
        let case = Case::build_sizes(scene, job.body_levels, job.method, &job.params)?;
        let path = dir.join(format!("{}.rec", key(job, scene, kind, study_text)?));
        let sol = if mode == Mode::Merge {
            let bytes = std::fs::read(&path).map_err(|_| {
                Error::input(&path, "record", format!("no record for job {} ({}); run every shard (--shard i/n for i = 1..n) before --merge", job.id, job.label))
            })?;
            decode(&bytes, &path)?
        } else {
            let sol = solve::solve(
                &case.problem,
                &Settings {
                    kind,
                    ..Settings::default()
                },
                job.steps,
                true,
            )?;
            if let Mode::Shard(..) = mode {
                crate::io::write_atomic(&path, &encode(&sol))?;
            }
            sol
        };
        tick(&job.label);
        Ok(Some((case, sol)))
    };
    jobs.par_iter().map(run_one).collect()
}

/// The solved jobs of a plan, taken out by their handles.
pub struct Solved(Vec<Option<(Case, Solution)>>);

impl Solved {
    /// All jobs' outputs, or None when some were left to other shards.
    pub fn complete(outputs: Vec<Option<(Case, Solution)>>) -> Option<Self> {
        outputs
            .iter()
            .all(Option::is_some)
            .then_some(Solved(outputs))
    }

    /// Take job `id`'s case and solution (once).
    pub fn take(&mut self, id: JobId) -> (Case, Solution) {
        self.0[id].take().expect("each job is taken once")
    }
}

/// Build `job`'s case on `scene` and solve it with `kind`, or load the solution a previous
/// call stored: the record is keyed by everything the solve depends on (code commit, scene,
/// .geo, cone, levels, parameters, steps, and `context`), so a stale one is never found.
pub fn solve_cached(
    job: &Job,
    scene: &Scene,
    kind: SolverKind,
    context: &str,
) -> Result<(Case, Solution)> {
    let case = Case::build_sizes(scene, job.body_levels, job.method, &job.params)?;
    let path = records_dir().join(format!("{}.rec", key(job, scene, kind, context)?));
    if let Ok(bytes) = std::fs::read(&path)
        && let Ok(sol) = decode(&bytes, &path)
    {
        return Ok((case, sol));
    }
    let settings = Settings {
        kind,
        ..Settings::default()
    };
    let sol = solve::solve(&case.problem, &settings, job.steps, true)?;
    crate::io::write_atomic(&path, &encode(&sol))?;
    Ok((case, sol))
}
