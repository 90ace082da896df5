//! `study speed`: what each accuracy costs. Every run's wall time is split into its parts
//! and compared with the floor measured in the same run on the same mesh (the stiffness
//! assembled and factorized once, in f64 or in f32 with conjugate gradients, whichever is
//! faster; see [`solve::floor`]), and both with the machine's measured limits.

pub mod manufactured;
pub mod report;
pub mod results;

use crate::verify::kind::{Found, Kind};

/// The kind: one built-in study, `study speed`.
pub const KIND: Kind = Kind {
    name: "speed",
    description: DESCRIPTION,
    found: Found::BuiltIn,
    shards: false,
    run: |_, _| Ok(Some(Box::new(run()?))),
    rejudge: None,
    results: Some(results::section),
};


use crate::case::{Case, PeakMemory, RunSummary, release_free_heap};
use crate::contact::Method;
use crate::error::Result;
use crate::scene::Scene;
use crate::solve::{self, Solution, SolverKind};
use crate::verify::solve_case;

/// One line for `study list`.
pub const DESCRIPTION: &str = "What each accuracy costs: time split, ratio to the floor (f64 or f32 Cholesky, the faster) and the machine's bounds, viscoplastic and elastic families up to 2.2e6 dofs, newton against the paper's solver";

/// One timed run of the speed study.
#[derive(Debug, Clone)]
pub struct SpeedRun {
    /// The run: its time loop is the fastest of `repeats`, with that run's timings.
    pub run: RunSummary,
    /// Runs timed (solver and floor alternately); times are the fastest of them.
    pub repeats: usize,
    /// Relative theorem-norm error against the reference (None when the level is too close
    /// to the reference to measure, or for the elastic family).
    pub error: Option<f64>,
    /// The mesh family: scene and gmsh sizes.
    pub family: &'static Family,
    /// At the largest level, with more than one thread: the same run and floor on one
    /// thread, (set-up + time loop, floor) in s.
    pub one_thread: Option<(f64, f64)>,
    /// The floor measured beside the run: each way at its fastest over the repeats, the
    /// faster of the two as `seconds` ([`solve::Floor`]); the solver's fill and flops are
    /// in `run`'s timings.
    pub floor: solve::Floor,
}

/// A family of meshes: a scene and its level-0 sizes, refined level by level.
#[derive(Debug)]
pub struct Family {
    /// Built-in scene.
    pub scene: &'static str,
    /// h_upper at level 0 (h_lower = h_upper / 1.4142, as in `study rates`).
    pub h_upper: f64,
    /// Name in the report.
    pub label: &'static str,
}

/// The viscoplastic family (the `rates` scene) and the elastic one (`rates-elastic`: no
/// yield stress, the same meshes). h_upper = 0.28 puts level 7 at 2,196,480 dofs.
pub static FAMILIES: [Family; 2] = [
    Family {
        scene: "rates",
        h_upper: 0.28,
        label: "viscoplastic",
    },
    Family {
        scene: "rates-elastic",
        h_upper: 0.28,
        label: "elastic",
    },
];

/// What `study speed` measured.
#[derive(Debug, Clone)]
pub struct SpeedResult {
    /// All runs.
    pub rows: Vec<SpeedRun>,
    /// Free dofs of the reference (matching meshes at [`REFERENCE_LEVEL`]).
    pub reference_dofs: usize,
    /// Total wall time (s).
    pub wall_s: f64,
    /// The machine the times were measured on ([`machine`]): the ratios depend on it.
    pub machine: String,
    /// Threads of rayon's pool (RAYON_NUM_THREADS, or the machine's cores), used alike by
    /// the solver and the floor.
    pub threads: usize,
    /// The machine's measured limits the bounds divide by.
    pub limits: Limits,
    /// The manufactured scenes' solves against their floors ([`manufactured`]).
    pub manufactured: Vec<manufactured::ManufacturedRecord>,
}

/// What the machine can do at most, measured on rayon's threads at the start of the
/// study: the bounds of the report divide each side's bytes and flops by these.
#[derive(Debug, Clone, Copy)]
pub struct Limits {
    /// Streaming read bandwidth (bytes/s): the fastest of 3 sums over [`STREAM_BYTES`] of
    /// f64, twice the largest last-level cache of the machines measured so far.
    pub bandwidth: f64,
    /// Dense f64 matrix product rate (flop/s; a multiply-add is 2): the fastest of 3 of
    /// faer's product of two [`PEAK_SIZE`]-square matrices.
    pub peak_f64: f64,
    /// The same in f32.
    pub peak_f32: f64,
}

/// Bytes read by the bandwidth measurement ([`Limits::bandwidth`]).
pub const STREAM_BYTES: usize = 1 << 30;
/// Order of the matrices of the peak measurement ([`Limits::peak_f64`]).
pub const PEAK_SIZE: usize = 2048;

/// Measure the machine's [`Limits`] (about 3 s).
pub fn measure_limits() -> Limits {
    use rayon::prelude::*;
    let data = vec![1.0f64; STREAM_BYTES / 8];
    let stream = fastest(&mut || {
        // Eight partial sums per chunk: the adds keep up with the loads.
        let total: f64 = data
            .par_chunks(1 << 16)
            .map(|c| {
                let mut s = [0.0; 8];
                for block in c.chunks_exact(8) {
                    for k in 0..8 {
                        s[k] += block[k];
                    }
                }
                s.iter().sum::<f64>()
            })
            .sum();
        // The sum is used, so the reads happen.
        std::hint::black_box(total);
    });
    drop(data);
    Limits {
        bandwidth: STREAM_BYTES as f64 / stream,
        peak_f64: product_rate::<f64>(),
        peak_f32: product_rate::<f32>(),
    }
}

/// The fastest of three runs of `f` (s).
fn fastest(f: &mut dyn FnMut()) -> f64 {
    (0..3)
        .map(|_| {
            let t = std::time::Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

/// faer's product of two [`PEAK_SIZE`]-square matrices in the precision of `T` on rayon's
/// threads, the fastest of three (flop/s; a multiply-add is 2).
fn product_rate<T: crate::solve::substitution::Value>() -> f64 {
    let n = PEAK_SIZE;
    let par = faer::Par::rayon(rayon::current_num_threads());
    let a = faer::Mat::<T>::from_fn(n, n, |i, j| T::from_f64(((i + 2 * j) % 7) as f64 - 3.0));
    let mut c = faer::Mat::<T>::zeros(n, n);
    let seconds = fastest(&mut || {
        faer::linalg::matmul::matmul(
            c.as_mut(),
            faer::Accum::Replace,
            a.as_ref(),
            a.as_ref(),
            T::from_f64(1.0),
            par,
        )
    });
    2.0 * (n as f64).powi(3) / seconds
}

/// Levels at which newton is timed (level 7: 2,196,480 dofs).
pub const NEWTON_LEVELS: [usize; 8] = [0, 1, 2, 3, 4, 5, 6, 7];
/// Levels at which the paper's solver is timed (viscoplastic family).
pub const PAPER_LEVELS: [usize; 4] = [0, 1, 2, 3];
/// Reference level (matching meshes) of the viscoplastic family's errors.
pub const REFERENCE_LEVEL: usize = 6;
/// Time steps.
pub const STEPS: usize = 4;
/// Runs below these many dofs are timed this often (solver and floor alternately) and the
/// fastest time is kept: on a shared 2-core machine single timings of 0.01-1 s scatter by
/// up to a factor 2. Two studies with three timings at 34,432 dofs, the second after a
/// change that made newton's solves faster, read ratios 1.13 then 1.20 (elastic, mortar)
/// and 1.93 then 1.63 (viscoplastic, nts): the fastest of three is still a draw there, so
/// the levels up to 137,472 dofs get nine. At 549,376 dofs three were a draw too: a study
/// read 1.84 (viscoplastic, mortar; set-up 1.33 s, loop 3.94 s, floor 2.86 s) where the
/// same two binaries timed in turn right after read 1.64-1.72 (set-up 1.27 s, loop
/// 3.19-3.46 s, floor 2.72-2.76 s); that level gets five. At 34,432 dofs nine were a
/// draw too: a study read 2.07 (viscoplastic, mortar; set-up 0.057 s, loop 0.124 s, floor
/// 0.088 s) where `speed_pieces` with the same solver, 54 runs alternating with the older
/// one the same hour, read 1.95 fastest to fastest (solver 0.150 s, floor 0.077 s), and
/// runs of nine with it that hour read 1.90 to 2.42 (mortar) and 1.66 to 2.10 (nts); a
/// pair there takes 0.25 s, so the levels below 50,000 dofs get twenty-five.
pub const REPEATS: [(usize, usize); 3] = [(50_000, 25), (200_000, 9), (600_000, 5)];

/// How often larger runs are timed: three times, because the first large solve after
/// the mesh is built is slow for reasons of the process, not of the solver (measured at
/// 2.2e6 dofs: the stiffness pattern took 7.6 s in the first run, 2.6 s in the second,
/// and the floor's, always run second, 2.5-3.1 s), and the fastest of the other two still
/// moved the ratio at 2,196,480 dofs from 1.68 to 1.80 between the same two studies
/// (viscoplastic, mortar; the second's solves faster); the fastest is kept, for both sides
/// alike.
pub const REPEATS_ABOVE: usize = 3;

/// How often a newton run with `dofs` unknowns is timed ([`REPEATS`], [`REPEATS_ABOVE`]).
pub fn repeats(dofs: usize) -> usize {
    REPEATS
        .iter()
        .find(|&&(below, _)| dofs < below)
        .map_or(REPEATS_ABOVE, |&(_, times)| times)
}

/// Solve `case` with `kind` and measure the floor, `repeats` times alternately: the
/// solution (deterministic) of the first run with the fastest run's timings, the floor
/// with each way at its fastest, and the largest peak memory of the solves.
fn timed_runs(
    case: &Case,
    kind: SolverKind,
    repeats: usize,
) -> Result<(Solution, solve::Floor, Option<f64>)> {
    // Every run, the solver's and the floor's, starts on a heap handed back to the system,
    // as in a fresh process: a run on the pages its predecessor freed skips their page
    // faults (measured at 3.4e4 dofs: the newton set-up took 0.08 s cold, 0.03 s warm).
    let memory = PeakMemory::start();
    let (mut best, _) = solve_case(case, kind, STEPS)?;
    let peak = memory.peak_gib();
    release_free_heap();
    let mut floor = solve::floor(&case.problem, STEPS)?;
    let cost = |s: &Solution| s.wall_s + s.timings.setup_s;
    for _ in 1..repeats {
        release_free_heap();
        let (sol, _) = solve_case(case, kind, STEPS)?;
        if cost(&sol) < cost(&best) {
            best.wall_s = sol.wall_s;
            best.timings = sol.timings;
        }
        release_free_heap();
        // Same ordering, same fill, same iterations: only the times change.
        floor = floor.fastest(&solve::floor(&case.problem, STEPS)?);
    }
    Ok((best, floor, peak))
}

/// The gmsh sizes of `family` (with matching meshes for the reference).
// 1.4142 is the rates scene's size ratio as studies/rates.toml writes it (the same meshes),
// not sqrt(2).
#[allow(clippy::approx_constant)]
fn sizes(family: &Family, matching: bool) -> Vec<(String, f64)> {
    let mut p = vec![
        ("h_upper".to_string(), family.h_upper),
        ("h_lower".to_string(), family.h_upper / 1.4142),
    ];
    if matching {
        p.push(("matching".to_string(), 1.0));
    }
    p
}

/// Run the speed study: every level of both families with newton, both cones; the paper's
/// solver on the coarse viscoplastic levels; errors of the viscoplastic levels against a
/// matching-mesh reference.
pub fn run() -> Result<SpeedResult> {
    let t0 = std::time::Instant::now();
    let threads = rayon::current_num_threads();
    let limits = measure_limits();
    // Timings first, on a quiet heap (the reference is solved afterwards); the solutions
    // of the levels that get an error are kept until the reference exists.
    let mut rows = Vec::new();
    let mut kept: Vec<(usize, Case, Solution)> = Vec::new();
    for family in &FAMILIES {
        let scene = Scene::load(family.scene)?;
        let viscoplastic = std::ptr::eq(family, &FAMILIES[0]);
        for method in Method::ALL {
            for &level in &NEWTON_LEVELS {
                let case = Case::build(&scene, level, method, &sizes(family, false))?;
                for kind in [SolverKind::Newton, SolverKind::Paper] {
                    // The paper's solver is timed against newton on the two cones of the
                    // paper; the other methods with newton, against the floor.
                    let paper_run = viscoplastic && PAPER_LEVELS.contains(&level) && method.in_paper();
                    if kind == SolverKind::Paper && !paper_run {
                        continue;
                    }
                    // The paper's solver takes seconds where newton takes milliseconds: one run.
                    let repeats = match kind {
                        SolverKind::Newton => repeats(case.problem.model.n_free),
                        _ => 1,
                    };
                    let (sol, floor, peak) = timed_runs(&case, kind, repeats)?;
                    let largest = level == *NEWTON_LEVELS.iter().max().unwrap();
                    let one_thread = match threads > 1 && largest && kind == SolverKind::Newton {
                        true => {
                            let pool = rayon::ThreadPoolBuilder::new()
                                .num_threads(1)
                                .build()
                                .map_err(|e| {
                                    crate::Error::NotConverged(format!("thread pool: {e}"))
                                })?;
                            release_free_heap();
                            let (one, floor_one, _) =
                                pool.install(|| timed_runs(&case, kind, 1))?;
                            Some((one.wall_s + one.timings.setup_s, floor_one.seconds))
                        }
                        false => None,
                    };
                    rows.push(SpeedRun {
                        run: RunSummary::new(&case, kind, &sol, Some(floor.seconds), peak),
                        repeats,
                        error: None,
                        family,
                        one_thread,
                        floor,
                    });
                    // Errors only where the reference is at least 3 levels finer.
                    if viscoplastic && level + 3 <= REFERENCE_LEVEL {
                        kept.push((rows.len() - 1, case.clone(), sol));
                    }
                }
            }
        }
    }
    let manufactured = manufactured::run()?;
    let family = &FAMILIES[0];
    let rcase = Case::build(
        &Scene::load(family.scene)?,
        REFERENCE_LEVEL,
        Method::reference(),
        &sizes(family, true),
    )?;
    let (rsol, _) = solve_case(&rcase, SolverKind::Newton, STEPS)?;
    for (i, case, sol) in &kept {
        rows[*i].error = Some(crate::verify::theorem_distance(case, sol, &rcase, &rsol));
    }
    Ok(SpeedResult {
        rows,
        reference_dofs: rcase.problem.model.n_free,
        wall_s: t0.elapsed().as_secs_f64(),
        machine: machine(),
        threads,
        limits,
        manufactured,
    })
}

/// The processor's model name, the cores available to the process and the last-level
/// cache (sysfs's size string, K = KiB), as Linux reports them (`/proc/cpuinfo`,
/// `/sys/devices/system/cpu/cpu0/cache`); "unknown" for what it does not. Why the report
/// names it: newton's preconditioner applications read the whole factor from memory each
/// time, about 24 of them per run against the floor's 4 solves, so the ratio moves with
/// the machine's memory bandwidth. Measured at 137,472 dofs (`speed_pieces 5 mortar
/// rates`): 1.64 on one 2-core machine, 2.2 on another with the same floor time (0.39 s),
/// where one application costs 7.4 ms with the factor cached and 11.7 ms after 400 MB of
/// other reads (`substitutions 5`).
pub fn machine() -> String {
    let cpuinfo = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
    let model = cpuinfo
        .lines()
        .find_map(|l| {
            l.strip_prefix("model name")?
                .split_once(':')
                .map(|(_, m)| m.trim())
        })
        .filter(|m| !m.is_empty())
        .unwrap_or("unknown processor")
        .to_string();
    // The cores this process may use (its affinity and cgroup limits applied).
    let cores = std::thread::available_parallelism().map_or_else(
        |_| "an unknown number of".to_string(),
        |n| n.get().to_string(),
    );
    // The highest cache level of cpu0 (index3 on most x86 machines).
    let cache = (0..8)
        .rev()
        .find_map(|i| {
            let dir = format!("/sys/devices/system/cpu/cpu0/cache/index{i}");
            let level = std::fs::read_to_string(format!("{dir}/level")).ok()?;
            let size = std::fs::read_to_string(format!("{dir}/size")).ok()?;
            Some(format!("L{} cache {}", level.trim(), size.trim()))
        })
        .unwrap_or_else(|| "cache size unknown".to_string());
    format!("{model}, {cores} cores available, {cache}")
}
