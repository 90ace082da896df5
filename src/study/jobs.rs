//! The independent solves of a study as jobs: planned from the study file, run in
//! parallel across the machine's cores (each solve is sequential and deterministic, so the
//! results equal a serial run), or sliced over a cluster's job array with `--shard i/n`,
//! each job's solution stored as a record keyed by a hash of its inputs, and gathered by
//! `--merge`.

use crate::case::Case;
use crate::contact::Method;
use crate::error::{Error, Result};
use crate::material::Stress;
use crate::mesh::gmsh;
use crate::scene::Scene;
use crate::solve::{self, Settings, Solution, SolverKind, State, StepReport, Timings};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// One solve of a study.
#[derive(Debug, Clone)]
pub struct Job {
    /// Position in the plan.
    pub id: usize,
    /// Human-readable label.
    pub label: String,
    /// Cone.
    pub method: Method,
    /// Mesh level.
    pub level: usize,
    /// gmsh parameters.
    pub params: Vec<(String, f64)>,
    /// Time steps.
    pub steps: usize,
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
        "record-v1|{}|{}|{}|{}|{:?}|{}|",
        super::commit(),
        kind.name(),
        job.method.name(),
        job.level,
        job.params,
        job.steps
    );
    k.push_str(&gmsh::sha256_hex(&scene_text));
    k.push_str(&gmsh::sha256_hex(&geo));
    k.push_str(&gmsh::sha256_hex(study_text.as_bytes()));
    Ok(gmsh::sha256_hex(k.as_bytes())[..24].to_string())
}

fn put_f64s(out: &mut Vec<u8>, v: impl IntoIterator<Item = f64>) {
    for x in v {
        out.extend_from_slice(&x.to_le_bytes());
    }
}

/// Serialize a solution (states, step reports, timings) to bytes.
pub fn encode(sol: &Solution) -> Vec<u8> {
    let mut o = b"CRREC2\n".to_vec();
    let t = &sol.timings;
    put_f64s(
        &mut o,
        [
            sol.wall_s,
            t.assembly_s,
            t.factor_s,
            t.solve_s,
            t.constitutive_s,
            t.contact_s,
            t.factorizations as f64,
            t.setup_s,
            t.solves as f64,
        ],
    );
    put_f64s(&mut o, [sol.reports.len() as f64]);
    for r in &sol.reports {
        put_f64s(
            &mut o,
            [
                r.iterations as f64,
                r.outer_iterations as f64,
                r.residual,
                r.active_set_changes as f64,
            ],
        );
    }
    put_f64s(&mut o, [sol.states.len() as f64]);
    for s in &sol.states {
        put_f64s(
            &mut o,
            [
                s.time,
                s.u.len() as f64,
                s.sigma.len() as f64,
                s.lambda.len() as f64,
            ],
        );
        put_f64s(&mut o, s.u.iter().copied());
        put_f64s(&mut o, s.sigma.iter().flat_map(|v| [v[0], v[1], v[2]]));
        put_f64s(&mut o, s.lambda.iter().copied());
    }
    o
}

/// Read back what [`encode`] wrote.
pub fn decode(bytes: &[u8], path: &Path) -> Result<Solution> {
    let bad = || {
        Error::input(
            path,
            "record",
            "the record is truncated or not a record; delete it and run the shard again",
        )
    };
    if !bytes.starts_with(b"CRREC2\n") {
        return Err(bad());
    }
    let mut pos = 7;
    let mut next = || -> Result<f64> {
        let b = bytes.get(pos..pos + 8).ok_or_else(bad)?;
        pos += 8;
        Ok(f64::from_le_bytes(b.try_into().unwrap()))
    };
    let h: Vec<f64> = (0..9).map(|_| next()).collect::<Result<_>>()?;
    let timings = Timings {
        assembly_s: h[1],
        factor_s: h[2],
        solve_s: h[3],
        constitutive_s: h[4],
        contact_s: h[5],
        factorizations: h[6] as usize,
        setup_s: h[7],
        solves: h[8] as usize,
    };
    let nr = next()? as usize;
    let mut reports = Vec::with_capacity(nr.min(1 << 20));
    for _ in 0..nr {
        let r: Vec<f64> = (0..4).map(|_| next()).collect::<Result<_>>()?;
        reports.push(StepReport {
            iterations: r[0] as usize,
            outer_iterations: r[1] as usize,
            residual: r[2],
            active_set_changes: r[3] as usize,
            reason: "from record".into(),
        });
    }
    let ns = next()? as usize;
    let mut states = Vec::with_capacity(ns.min(1 << 20));
    for _ in 0..ns {
        let head: Vec<f64> = (0..4).map(|_| next()).collect::<Result<_>>()?;
        let (nu, nsg, nl) = (head[1] as usize, head[2] as usize, head[3] as usize);
        let u: Vec<f64> = (0..nu).map(|_| next()).collect::<Result<_>>()?;
        let sigma: Vec<Stress> = (0..nsg)
            .map(|_| Ok(Stress::new(next()?, next()?, next()?)))
            .collect::<Result<_>>()?;
        let lambda: Vec<f64> = (0..nl).map(|_| next()).collect::<Result<_>>()?;
        states.push(State {
            time: head[0],
            u,
            sigma,
            lambda,
        });
    }
    Ok(Solution {
        states,
        reports,
        wall_s: h[0],
        timings,
    })
}

/// Build every job's case and obtain its solution according to `mode`. Returns, in plan
/// order, `Some((case, solution))` for the jobs that were run or loaded (all of them except
/// in `Shard` mode).
pub fn execute(
    jobs: &[Job],
    scene: &Scene,
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
        let case = Case::build(scene, job.level, job.method, &job.params)?;
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
