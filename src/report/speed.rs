//! The report of `study speed`: speed.csv, the work-precision and time-against-dofs plots,
//! the README table, and the lines printed on the console.

use super::folder::{write, write_folder};
use super::plot::{self, Series};
use crate::contact::Method;
use crate::error::Result;
use crate::io::csv_bytes;
use crate::solve::SolverKind;
use crate::study::speed::{SpeedResult, SpeedRun};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;

/// One row of speed.csv.
#[derive(Serialize)]
struct SpeedCsv {
    scene: String,
    method: Method,
    solver: SolverKind,
    level: usize,
    dofs: usize,
    steps: usize,
    /// Iterations in total (Newton iterations; inner solves for `paper`).
    iterations: usize,
    factorizations: usize,
    /// Wall time of the time loop (s): the fastest of `repeats` runs.
    wall_s: f64,
    /// One-off set-up per mesh, not in wall_s: pattern, slot map, symbolic analysis (s).
    setup_s: f64,
    repeats: usize,
    floor_s: f64,
    ratio_to_floor: f64,
    factor_s: f64,
    solve_s: f64,
    assembly_s: f64,
    constitutive_s: f64,
    error: Option<f64>,
    /// The process's peak resident memory so far (GiB).
    peak_rss_gib: Option<f64>,
    family: &'static str,
}

impl SpeedCsv {
    fn new(r: &SpeedRun) -> Self {
        let run = &r.run;
        let t = &run.timings;
        SpeedCsv {
            scene: run.scene.clone(),
            method: run.method,
            solver: run.solver,
            level: run.level,
            dofs: run.dofs,
            steps: run.steps,
            iterations: run.iterations,
            factorizations: t.factorizations,
            wall_s: run.time_loop_s,
            setup_s: t.setup_s,
            repeats: r.repeats,
            floor_s: floor_of(r),
            ratio_to_floor: run.ratio_to_floor().unwrap_or(f64::NAN),
            factor_s: t.factor_s,
            solve_s: t.solve_s,
            assembly_s: t.assembly_s,
            constitutive_s: t.constitutive_s,
            error: r.error,
            peak_rss_gib: run.peak_rss_gib,
            family: r.family,
        }
    }
}

/// The floor of a speed run (always measured by the study).
fn floor_of(r: &SpeedRun) -> f64 {
    r.run
        .floor_s
        .expect("study speed measures the floor of every run")
}

fn runs_of(res: &SpeedResult, m: Method, so: SolverKind) -> impl Iterator<Item = &SpeedRun> {
    res.rows
        .iter()
        .filter(move |r| r.run.method == m && r.run.solver == so)
}

/// The solver and cone pairs plotted, with their colours.
const COMBOS: [(Method, SolverKind, usize); 4] = [
    (Method::Mortar, SolverKind::Newton, 0),
    (Method::Nts, SolverKind::Newton, 1),
    (Method::Mortar, SolverKind::Paper, 3),
    (Method::Nts, SolverKind::Paper, 2),
];

/// Write the report of `study speed`.
pub fn write_speed(res: &SpeedResult, dir: &Path) -> Result<()> {
    write_folder(dir, |d| {
        let rows: Vec<SpeedCsv> = res.rows.iter().map(SpeedCsv::new).collect();
        write(d, "speed.csv", &csv_bytes(&rows)?)?;
        work_precision(res, d)?;
        time_vs_dofs(res, d)?;
        write(d, "README.md", readme(res).as_bytes())
    })
}

/// Error against the time loop's wall time, one line per cone and solver.
fn work_precision(res: &SpeedResult, d: &Path) -> Result<()> {
    let series: Vec<Series> = COMBOS
        .iter()
        .map(|(m, so, c)| Series {
            label: format!("{m}, {so}"),
            points: runs_of(res, *m, *so)
                .filter_map(|r| r.error.map(|e| (r.run.time_loop_s.max(1e-4), e)))
                .collect(),
            markers: true,
            line: true,
            color: *c,
            thin: *so == SolverKind::Paper,
        })
        .filter(|s| !s.points.is_empty())
        .collect();
    plot::loglog(
        &d.join("work_precision.png"),
        "speed: error against wall time (rates scene, 4 steps)",
        "wall time of the time loop (s)",
        "relative error (theorem norm)",
        &series,
        &[],
    )
}

/// Wall time against dofs with the fitted exponents, and the floor.
fn time_vs_dofs(res: &SpeedResult, d: &Path) -> Result<()> {
    let mut series = Vec::new();
    for (m, so, c) in COMBOS {
        let rows: Vec<_> = runs_of(res, m, so).collect();
        if rows.is_empty() {
            continue;
        }
        let x: Vec<f64> = rows.iter().map(|r| r.run.dofs as f64).collect();
        let y: Vec<f64> = rows.iter().map(|r| r.run.time_loop_s).collect();
        // Exponent over the levels with at least 1e4 dofs (below, fixed costs dominate).
        let big: Vec<usize> = (0..x.len()).filter(|&i| x[i] >= 1e4).collect();
        let fit = crate::study::rates::fit(
            &big.iter().map(|&i| x[i]).collect::<Vec<_>>(),
            &big.iter().map(|&i| y[i]).collect::<Vec<_>>(),
        );
        let label = match fit {
            Some(f) => format!("{m}, {so}: time ~ dofs^{:.2}", f.rate),
            None => format!("{m}, {so}"),
        };
        series.push(Series {
            label,
            points: x.iter().copied().zip(y.iter().copied()).collect(),
            markers: true,
            line: true,
            color: c,
            thin: so == SolverKind::Paper,
        });
    }
    let floor: Vec<(f64, f64)> = runs_of(res, Method::Mortar, SolverKind::Newton)
        .map(|r| (r.run.dofs as f64, floor_of(r)))
        .collect();
    series.push(Series {
        label: "floor (mortar): assembly + 1 factorization + 2 solves per step".into(),
        points: floor,
        markers: false,
        line: true,
        color: 2,
        thin: true,
    });
    plot::loglog(
        &d.join("time_vs_dofs.png"),
        "speed: wall time against dofs",
        "free dofs",
        "wall time (s)",
        &series,
        &[],
    )
}

/// The README: what the study measures, the plots, the table, newton against paper.
fn readme(res: &SpeedResult) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Study `speed`\n\nWhat each accuracy costs on the `rates` scene (h1/h2 = 1.4142, {} time steps). Every run's time loop is compared with the floor measured in the same run on the same KKT matrix: assembling it once, one numeric factorization, and two triangular solves per time step. The one-off set-up per mesh (pattern, entry-to-slot map, symbolic analysis) is in neither and is shown apart. Runs below {} dofs are timed {} times, solver and floor alternately, and the fastest of each is kept (single timings of 0.01-0.1 s scatter by a factor 2 on this shared 2-core machine). Errors are in the theorem norm against a matching-mesh reference at level {} ({} dofs), shown where the reference is at least 3 levels finer. `peak RSS` is the process's peak so far. Regenerate with `cargo run --release -- study speed` ({:.0} s).\n",
        crate::study::speed::STEPS,
        crate::study::speed::REPEATS.0,
        crate::study::speed::REPEATS.1,
        crate::study::speed::REFERENCE_LEVEL,
        res.reference_dofs,
        res.wall_s
    );
    let _ = writeln!(
        s,
        "![work precision](work_precision.png)\n\n![time against dofs](time_vs_dofs.png)\n"
    );
    s.push_str(&table(res));
    for m in [Method::Mortar, Method::Nts] {
        let finest = crate::study::speed::PAPER_LEVELS.iter().max().unwrap();
        let at_finest = |so| runs_of(res, m, so).find(|r| r.run.level == *finest);
        if let (Some(a), Some(b)) = (at_finest(SolverKind::Newton), at_finest(SolverKind::Paper)) {
            let _ = writeln!(
                s,
                "\n{m}, level {finest}: newton {:.3} s ({:.2} x the floor), paper {:.3} s at the same final tolerance: newton is {:.1} x faster.",
                a.run.time_loop_s,
                a.run.time_loop_s / floor_of(a),
                b.run.time_loop_s,
                b.run.time_loop_s / a.run.time_loop_s
            );
        }
    }
    s
}

fn gib(v: Option<f64>) -> String {
    v.map(|g| format!("{g:.1}")).unwrap_or_default()
}

/// The table of every run: cost split, floor, memory and error.
fn table(res: &SpeedResult) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "| family | method | solver | level | dofs | iterations | factorizations | time loop (s) | floor (s) | ratio to floor | set-up (s) | factorizations (s) | solves (s) | assembly (s) | constitutive (s) | peak RSS (GiB) | error |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for r in &res.rows {
        let (run, t) = (&r.run, &r.run.timings);
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {:.3} | {:.3} | {:.2} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {} | {} |",
            r.family,
            run.method,
            run.solver,
            run.level,
            run.dofs,
            run.iterations,
            t.factorizations,
            run.time_loop_s,
            floor_of(r),
            run.time_loop_s / floor_of(r),
            t.setup_s,
            t.factor_s,
            t.solve_s,
            t.assembly_s,
            t.constitutive_s,
            gib(run.peak_rss_gib),
            r.error.map(|e| format!("{e:.3e}")).unwrap_or_default()
        );
    }
    s
}

/// What `study speed` prints: the table of the runs, and where the report went.
pub fn console(res: &SpeedResult, dir: &Path) -> String {
    format!(
        "{}wrote {} ({:.1} s)\n",
        table(res),
        dir.display(),
        res.wall_s
    )
}
