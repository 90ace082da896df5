//! The report of `study speed`: speed.csv, the work-precision and time-against-dofs plots,
//! the README table, and the lines printed on the console.

use crate::contact::Method;
use crate::error::Result;
use crate::io::csv_bytes;
use crate::report::folder::{write, write_folder};
use crate::report::markdown::{Doc, Table};
use crate::report::plot::{self, Series};
use crate::solve::{SolverKind, interface::Precision};
use crate::studies::speed::{FAMILIES, Family, Limits, SpeedResult, SpeedRun};
use serde::Serialize;
use std::path::Path;
use crate::verify::kind::Outcome;

/// One row of speed.csv: one run against its floor.
#[derive(Debug, Serialize, serde::Deserialize)]
pub struct SpeedRecord {
    pub scene: String,
    pub method: Method,
    pub solver: SolverKind,
    pub level: usize,
    pub dofs: usize,
    pub steps: usize,
    /// Iterations in total (Newton iterations; inner solves for `paper`).
    pub iterations: usize,
    pub factorizations: usize,
    /// Wall time of the time loop (s): the fastest of `repeats` runs.
    pub wall_s: f64,
    /// One-off set-up per mesh, not in wall_s: pattern, slot map, symbolic analysis (s).
    pub setup_s: f64,
    pub repeats: usize,
    /// Pattern, assembly, one sparse Cholesky (symbolic and numeric) of the stiffness and
    /// one solve per step (s).
    pub floor_s: f64,
    /// (setup_s + wall_s) / floor_s.
    pub ratio_to_floor: f64,
    pub factor_s: f64,
    pub solve_s: f64,
    pub assembly_s: f64,
    pub constitutive_s: f64,
    pub error: Option<f64>,
    /// Peak resident memory of the process during the solve (GiB).
    pub peak_rss_gib: Option<f64>,
    /// viscoplastic (`rates`) or elastic (`rates-elastic`).
    pub family: String,
    /// Threads of the solver and the floor.
    pub threads: usize,
    /// The same run's set-up + time loop on one thread (largest level; s).
    pub one_thread_s: Option<f64>,
    /// The floor on one thread (largest level; s).
    pub one_thread_floor_s: Option<f64>,
    /// Fill of the solver's factor of the stiffness: entries of L, both bodies, the
    /// interface rows included (0 for the paper's solver, which has no such factor).
    pub factor_entries: usize,
    /// Fill of the floor's Cholesky factor: entries of L, both bodies.
    pub floor_factor_entries: usize,
    /// The floor's faster way: `double` (f64 Cholesky, one substitution per system) or
    /// `single` (f32 Cholesky preconditioning conjugate gradients to the tolerance).
    pub floor_way: String,
    /// The floor's shared part: pattern, values, ordering, symbolic analysis (s).
    pub floor_shared_s: f64,
    /// The floor by the double way (s).
    pub floor_double_s: f64,
    /// The floor by the single way (s); empty where it missed the tolerance.
    pub floor_single_s: Option<f64>,
    /// Systems the floor solves (distinct right-hand sides).
    pub floor_systems: usize,
    /// The single way's applications of its f32 factor (the most of any body).
    pub floor_applications: usize,
    /// Applications of the solver's factorization (solves with it).
    pub solves: usize,
    /// Flops of one numeric factorization (a multiply-add counts 2): the solver's, the floor's.
    pub factor_flops: f64,
    pub floor_factor_flops: f64,
    /// The floor's bytes (its faster way's) over the measured bandwidth (s).
    pub floor_memory_bound_s: f64,
    /// The floor's factorization flops over the measured peak in its precision (s).
    pub floor_compute_bound_s: f64,
    /// The solver's bytes (factor twice per application, stiffness once) over the
    /// bandwidth (s); empty for the paper's solver.
    pub memory_bound_s: Option<f64>,
    /// The solver's factorization flops over the measured f32 peak (s).
    pub compute_bound_s: Option<f64>,
}

impl SpeedRecord {
    fn new(r: &SpeedRun, threads: usize, limits: &Limits) -> Self {
        let run = &r.run;
        let t = &run.timings;
        let b = bounds(r, limits);
        SpeedRecord {
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
            ratio_to_floor: ratio(r),
            factor_s: t.factor_s,
            solve_s: t.solve_s,
            assembly_s: t.assembly_s,
            constitutive_s: t.constitutive_s,
            error: r.error,
            peak_rss_gib: run.peak_rss_gib,
            family: r.family.label.to_string(),
            threads,
            one_thread_s: r.one_thread.map(|o| o.0),
            one_thread_floor_s: r.one_thread.map(|o| o.1),
            factor_entries: t.factor_entries,
            floor_factor_entries: r.floor.factor_entries,
            floor_way: way(r.floor.precision).to_string(),
            floor_shared_s: r.floor.shared_s,
            floor_double_s: r.floor.double_s,
            floor_single_s: r.floor.single_s,
            floor_systems: r.floor.systems,
            floor_applications: r.floor.single_applications,
            solves: t.solves,
            factor_flops: t.factor_flops,
            floor_factor_flops: r.floor.factor_flops,
            floor_memory_bound_s: b.floor_memory,
            floor_compute_bound_s: b.floor_compute,
            memory_bound_s: b.memory,
            compute_bound_s: b.compute,
        }
    }
}

/// The floor's way by name.
fn way(p: Precision) -> &'static str {
    match p {
        Precision::Double => "double",
        Precision::Single => "single",
    }
}

/// How far a run and its floor are from the machine's limits (s): bytes over the
/// streaming bandwidth, factorization flops over the dense peak in their precision.
struct Bounds {
    floor_memory: f64,
    floor_compute: f64,
    /// None for a solver without a factorization of the stiffness (the paper's).
    memory: Option<f64>,
    compute: Option<f64>,
}

/// The [`Bounds`] of `r` on a machine with `limits`. The solver's bytes: its f32 factor
/// read twice per application (4 bytes an entry) and the stiffness once per application
/// (GMRES pairs each with one product; 8 bytes an entry); the floor's: see
/// [`crate::solve::Floor::double_bytes`]. Index arrays are left out: lower bounds.
fn bounds(r: &SpeedRun, limits: &Limits) -> Bounds {
    let (f, t) = (&r.floor, &r.run.timings);
    let (floor_bytes, floor_peak) = match f.precision {
        Precision::Double => (f.double_bytes, limits.peak_f64),
        Precision::Single => (f.single_bytes, limits.peak_f32),
    };
    let has_factor = t.factor_entries > 0;
    let bytes = t.solves as f64 * (2.0 * 4.0 * t.factor_entries as f64 + 8.0 * f.stiffness_entries as f64);
    Bounds {
        floor_memory: floor_bytes / limits.bandwidth,
        // factor_flops counts flops (a multiply-add is 2), as the peak does.
        floor_compute: f.factor_flops / floor_peak,
        memory: has_factor.then(|| bytes / limits.bandwidth),
        compute: has_factor
            .then(|| t.factor_flops * t.factorizations as f64 / limits.peak_f32),
    }
}

/// Set-up plus time loop over the floor.
fn ratio(r: &SpeedRun) -> f64 {
    r.run
        .ratio_to_floor()
        .expect("study speed measures the floor of every run")
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

/// The runs of one family, cone and solver.
fn family_runs<'a>(
    res: &'a SpeedResult,
    family: &'a Family,
    m: Method,
    so: SolverKind,
) -> impl Iterator<Item = &'a SpeedRun> {
    runs_of(res, m, so).filter(move |r| std::ptr::eq(r.family, family))
}

/// Exponent p of time ~ dofs^p over the runs with at least 1e4 dofs (below, fixed costs
/// dominate), and its label.
fn exponent_label(name: &str, points: &[(f64, f64)]) -> String {
    let big: Vec<&(f64, f64)> = points.iter().filter(|p| p.0 >= 1e4).collect();
    let fit = crate::verify::rates::fit(
        &big.iter().map(|p| p.0).collect::<Vec<_>>(),
        &big.iter().map(|p| p.1).collect::<Vec<_>>(),
    );
    match fit {
        Some(f) => format!("{name}: time ~ dofs^{:.2}", f.rate),
        None => name.to_string(),
    }
}

/// The solver and cone pairs plotted, with their colours.
const COMBOS: [(Method, SolverKind, usize); 5] = [
    (Method::Mortar, SolverKind::Newton, 0),
    (Method::Nts, SolverKind::Newton, 1),
    (Method::Lac, SolverKind::Newton, 4),
    (Method::Mortar, SolverKind::Paper, 3),
    (Method::Nts, SolverKind::Paper, 2),
];

/// Write the report of `study speed`.
pub fn write_speed(res: &SpeedResult, dir: &Path) -> Result<()> {
    write_folder(dir, |d| {
        let rows: Vec<SpeedRecord> = res
            .rows
            .iter()
            .map(|r| SpeedRecord::new(r, res.threads, &res.limits))
            .collect();
        write(d, "speed.csv", &csv_bytes(&rows)?)?;
        write(d, "manufactured.csv", &csv_bytes(&res.manufactured)?)?;
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
            shape: None,
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

/// Newton's set-up plus time loop and the floor against dofs, per family and cone, with
/// the fitted exponents in the legend.
fn time_vs_dofs(res: &SpeedResult, d: &Path) -> Result<()> {
    let mut series = Vec::new();
    for (f, family) in FAMILIES.iter().enumerate() {
        for (k, m) in Method::ALL.into_iter().enumerate() {
            let points: Vec<(f64, f64)> = family_runs(res, family, m, SolverKind::Newton)
                .map(|r| (r.run.dofs as f64, r.run.time_loop_s + r.run.timings.setup_s))
                .collect();
            series.push(Series {
                label: exponent_label(&format!("{}, {m}, newton", family.label), &points),
                points,
                markers: true,
                line: true,
                color: 3 * f + k,
                thin: false,
                shape: None,
            });
        }
        let floor: Vec<(f64, f64)> = family_runs(res, family, Method::reference(), SolverKind::Newton)
            .map(|r| (r.run.dofs as f64, floor_of(r)))
            .collect();
        series.push(Series {
            label: exponent_label(&format!("{}, floor (Cholesky)", family.label), &floor),
            points: floor,
            markers: false,
            line: true,
            color: 3 * f,
            thin: true,
            shape: None,
        });
    }
    plot::loglog(
        &d.join("time_vs_dofs.png"),
        "speed: newton (set-up + time loop) and the floor against dofs, 4 steps",
        "free dofs",
        "wall time (s)",
        &series
            .into_iter()
            .filter(|s| !s.points.is_empty())
            .collect::<Vec<_>>(),
        &[],
    )
}

/// The README: what the study measures, the ratio to the floor per family and cone, the
/// floor's spread, the machine and threads, the plots, the table, newton against paper.
fn readme(res: &SpeedResult) -> String {
    let mut doc = Doc::new();
    doc.heading(1, "Study `speed`")
        .paragraph(what_is_measured(res))
        .table(&ratios_table(res))
        .paragraph(floor_spread(res));
    machine_and_threads(&mut doc, res);
    doc.table(&bounds_table(res));
    doc.image("work precision", "work_precision.png")
        .image("time against dofs", "time_vs_dofs.png")
        .table(&runs_table(res));
    for sentence in newton_against_paper(res) {
        doc.paragraph(sentence);
    }
    doc.heading(2, "Manufactured scenes").paragraph(MANUFACTURED_LEAD).table(&manufactured_table(res));
    doc.finish()
}

const MANUFACTURED_LEAD: &str = "A scene with an exact solution pays for its loads: the body force -div sigma(u) and the tractions sigma(u) n are evaluated at every quadrature point of the mesh (16 per triangle, more on the triangles a kink crosses and at a singular point), from expressions compiled once per scene (`expr::program`). Each row is newton with mortar from the cached mesh: the model built from scratch with its checks and the load at the final time (no load cached), then the solver's set-up and time loop; the load of every step is the one integral scaled by t (the loads are t times a field of x and y, read from the expressions). The load's integral is also timed alone, per quadrature point. Fastest of the same number of runs as the table above; manufactured.csv holds the rows.";

/// The manufactured scenes' cost against the floor.
fn manufactured_table(res: &SpeedResult) -> Table {
    let mut table = Table::new([
        "scene",
        "level",
        "dofs",
        "model with its load (s)",
        "load alone (s)",
        "quadrature points",
        "load per point (us)",
        "set-up + loop (s)",
        "floor (s)",
        "(model + set-up + loop) / floor",
    ]);
    for r in &res.manufactured {
        table.row([
            format!("`{}`", r.scene),
            r.level.to_string(),
            r.dofs.to_string(),
            seconds(r.model_s),
            seconds(r.load_s),
            r.load_points.to_string(),
            format!("{:.3}", r.load_per_point_us),
            seconds(r.solve_s),
            seconds(r.floor_s),
            format!("{:.2}", r.ratio_to_floor),
        ]);
    }
    table
}

/// The study's lead: the families, the floor, how the runs are timed, the errors.
fn what_is_measured(res: &SpeedResult) -> String {
    use crate::studies::speed::{REFERENCE_LEVEL, REPEATS, REPEATS_ABOVE, STEPS};
    let repeats: Vec<String> = REPEATS
        .iter()
        .map(|(below, times)| format!("{times} below {below} dofs"))
        .collect();
    format!(
        "What each accuracy costs, on two families of the same non-matching meshes (h1/h2 = 1.4142, h_upper = 0.28 at level 0, every level splits each triangle in 4), {STEPS} time steps: `rates` (viscoplastic, about half the domain flows) and `rates-elastic` (no yield stress). Each run's cost, the solver's set-up (pattern, symbolic analysis) plus its time loop, is compared with the floor measured on the same mesh: what the problem cannot avoid, from scratch (`solve::floor`). That is the elastic stiffness's pattern and values, its ordering and symbolic analysis (faer; shifted by 1e-8 of its mean diagonal so that a body held only by contact does not make it singular), and then the faster of two ways to solve the systems the problem needs to the solver's tolerance 1e-10: *double*, one f64 Cholesky and one forward-backward substitution per system; *single*, one f32 Cholesky preconditioning conjugate gradients in f64 per system (counted only where they reach the tolerance in 30 applications). The systems are one per distinct right-hand side: one for the elastic family (its proportional load's steps are scalings of one solution), one per step for the viscoplastic one (a body with no load of its own gets ones). Both ways are timed in every measurement and both times are in speed.csv and the table below. newton's runs are timed {} times, larger ones {REPEATS_ABOVE} times, solver and floor alternately (the paper's solver once), each on a heap handed back to the system as in a fresh process, and the fastest of each is kept (single timings of 0.01-1 s scatter by up to a factor 2 on this shared 2-core machine). Errors (viscoplastic family) are in the theorem norm against a matching-mesh reference at level {REFERENCE_LEVEL} ({} dofs), shown where the reference is at least 3 levels finer. `peak RSS` is the process's peak during the solve (reset before it). Regenerate with `cargo run --release -- study speed` ({:.0} s).",
        repeats.join(", "),
        res.reference_dofs,
        res.wall_s
    )
}

/// Per family and cone, newton's ratio to the floor from 1e4 dofs, and the largest run's
/// time and fill against the floor's.
fn ratios_table(res: &SpeedResult) -> Table {
    let mut table = Table::new([
        "family",
        "cone",
        "newton / floor from 1e4 dofs (smallest - largest)",
        "at the largest run",
        "fill at the largest run, entries of L: newton / floor",
    ]);
    for family in &FAMILIES {
        for m in Method::ALL {
            let runs: Vec<&SpeedRun> = family_runs(res, family, m, SolverKind::Newton)
                .filter(|r| r.run.dofs >= 10_000)
                .collect();
            let ratios: Vec<f64> = runs.iter().map(|r| ratio(r)).collect();
            let Some(last) = runs.last() else { continue };
            let (entries, floor_entries) = (
                last.run.timings.factor_entries as f64,
                last.floor.factor_entries as f64,
            );
            table.row([
                family.label.to_string(),
                m.to_string(),
                format!(
                    "{:.2} - {:.2}",
                    ratios.iter().copied().fold(f64::INFINITY, f64::min),
                    ratios.iter().copied().fold(0.0, f64::max)
                ),
                format!(
                    "{:.2} at {} dofs ({:.1} s, floor {:.1} s, {})",
                    ratio(last),
                    last.run.dofs,
                    last.run.time_loop_s + last.run.timings.setup_s,
                    floor_of(last),
                    way(last.floor.precision)
                ),
                format!(
                    "{entries:.3e} / {floor_entries:.3e} = {:.2}",
                    entries / floor_entries.max(1.0)
                ),
            ]);
        }
    }
    table
}

/// The spread the specification asks for: every row of a family's mesh times the same
/// floor (the same stiffness and systems, whatever the cone and solver); its fastest time
/// per row, smallest and largest, per family and mesh from 1e4 dofs.
fn floor_spread(res: &SpeedResult) -> String {
    let mut floors: std::collections::BTreeMap<(&str, usize), (f64, f64)> = Default::default();
    for r in res
        .rows
        .iter()
        .filter(|r| r.run.solver == SolverKind::Newton && r.run.dofs >= 10_000)
    {
        let f = floors
            .entry((r.family.label, r.run.dofs))
            .or_insert((f64::INFINITY, 0.0));
        *f = (f.0.min(floor_of(r)), f.1.max(floor_of(r)));
    }
    let spread: Vec<String> = floors
        .iter()
        .map(|((family, dofs), (lo, hi))| {
            format!(
                "{family} {dofs} dofs {} - {} s ({:.0}%)",
                seconds(*lo),
                seconds(*hi),
                100.0 * (hi / lo - 1.0)
            )
        })
        .collect();
    format!(
        "Spread: the floor is the same work in every row of a family's mesh (the same stiffness and systems, whatever the cone), timed anew beside each; its fastest time per row, smallest - largest: {}. A ratio moves with its floor by as much.",
        spread.join(", ")
    )
}

/// The machine the ratios depend on, the threads and how both sides use them, and the runs
/// timed on one thread as well.
fn machine_and_threads(doc: &mut Doc, res: &SpeedResult) {
    let l = &res.limits;
    doc.paragraph(format!(
        "Machine: {machine}; measured at the start of the study (`studies::speed::measure_limits`): streaming read bandwidth {bandwidth:.1} GB/s (a sum over 1 GiB), dense product peak {f64_peak:.1} GFLOP/s in f64 and {f32_peak:.1} GFLOP/s in f32 (faer's 2048 x 2048 product). The ratios depend on the machine: newton's viscoplastic runs apply their f32 factor {applications} times from 1e4 dofs (each reads the whole factor from memory) against the floor's one substitution per step, so a machine with less memory bandwidth per core reads higher ratios for the same code (`studies::speed::machine` gives a measured example). The bounds table divides each side's bytes by the bandwidth and its factorization's flops by the peak in its precision: how far each is from the machine's limits, not only from the other. The pattern, ordering and symbolic analysis have no such bound; the table lists them apart (newton's set-up is their counterpart).",
        machine = res.machine,
        applications = applications_range(res),
        bandwidth = l.bandwidth / 1e9,
        f64_peak = l.peak_f64 / 1e9,
        f32_peak = l.peak_f32 / 1e9
    ))
    .paragraph(format!(
        "Threads: {} (rayon's pool; `RAYON_NUM_THREADS` sets it), the same for the solver and the floor. The stiffness is block diagonal, one block per body (they meet only through the contact rows): both sides factorize the blocks apart and side by side, in the same ordering (`solve::ordering`: METIS's nested dissection of the nodes for a block of 500,000 equations or more, faer's AMD below), the floor of each whole block, newton of the block's interior with its contact-interface unknowns last; newton's substitutions run as tasks on the threads, one per subtree of the blocks' elimination trees (`solve::substitution`: split until no subtree holds more than a fifth of the work, so that the larger body does not set the time), the floor's as faer's solve of each block, side by side. Newton factorizes in single precision (faer's LDL^T in f32 of the stiffness scaled to unit diagonal; the substitutions' arithmetic in f32 below the tops of the elimination trees, in f64 in the tops, where the contact interface is) and reaches the tolerance 1e-10 through its Newton and GMRES iterations. The fill is the number of entries of the factor L on and below its diagonal (both bodies; newton's includes its interface rows).",
        res.threads
    ));
    let one = one_thread_table(res);
    if !one.is_empty() {
        doc.table(&one);
    }
}

/// The smallest and largest number of preconditioner applications of newton's
/// viscoplastic runs from 1e4 dofs, as text.
fn applications_range(res: &SpeedResult) -> String {
    let solves: Vec<usize> = Method::ALL
        .into_iter()
        .flat_map(|m| family_runs(res, &FAMILIES[0], m, SolverKind::Newton))
        .filter(|r| r.run.dofs >= 10_000)
        .map(|r| r.run.timings.solves)
        .collect();
    match (solves.iter().min(), solves.iter().max()) {
        (Some(lo), Some(hi)) if lo < hi => format!("{lo}-{hi}"),
        (Some(lo), _) => lo.to_string(),
        _ => "no".to_string(),
    }
}

/// Per family and level from 1e4 dofs (mortar's runs: the floor is the same for both
/// cones), the floor's two ways and newton, each measured and against its bounds.
fn bounds_table(res: &SpeedResult) -> Table {
    let mut table = Table::new([
        "family",
        "level",
        "dofs",
        "floor: double / single (s)",
        "floor used",
        "of which pattern, ordering, symbolic (s)",
        "floor's bound: memory + compute (s)",
        "newton (s)",
        "of which set-up (s)",
        "newton's bound: memory + compute (s)",
        "newton's factorization (s), its compute bound (s)",
        "applications: newton / floor's single way",
    ]);
    for family in &FAMILIES {
        for r in family_runs(res, family, Method::reference(), SolverKind::Newton)
            .filter(|r| r.run.dofs >= 10_000)
        {
            let (f, t) = (&r.floor, &r.run.timings);
            let b = bounds(r, &res.limits);
            let (memory, compute) = (b.memory.unwrap_or(0.0), b.compute.unwrap_or(0.0));
            table.row([
                family.label.to_string(),
                r.run.level.to_string(),
                r.run.dofs.to_string(),
                format!(
                    "{} / {}",
                    seconds(f.double_s),
                    f.single_s.map_or("missed the tolerance".into(), seconds)
                ),
                way(f.precision).to_string(),
                seconds(f.shared_s),
                format!(
                    "{} + {} = {}",
                    seconds(b.floor_memory),
                    seconds(b.floor_compute),
                    seconds(b.floor_memory + b.floor_compute)
                ),
                seconds(r.run.time_loop_s + t.setup_s),
                seconds(t.setup_s),
                format!(
                    "{} + {} = {}",
                    seconds(memory),
                    seconds(compute),
                    seconds(memory + compute)
                ),
                format!("{}, {}", seconds(t.factor_s), seconds(compute)),
                format!("{} / {}", t.solves, f.single_applications),
            ]);
        }
    }
    table
}

/// The runs timed on one thread as well: newton's and the floor's speed-up.
fn one_thread_table(res: &SpeedResult) -> Table {
    let n = res.threads;
    let mut table = Table::new([
        "family".to_string(),
        "cone".into(),
        "dofs".into(),
        "newton, 1 thread (s)".into(),
        format!("newton, {n} threads (s)"),
        "speed-up".into(),
        "floor, 1 thread (s)".into(),
        format!("floor, {n} threads (s)"),
        "speed-up".into(),
        "newton / floor, 1 thread".into(),
        format!("newton / floor, {n} threads"),
    ]);
    for r in &res.rows {
        let Some((one_s, one_floor)) = r.one_thread else {
            continue;
        };
        let all_s = r.run.time_loop_s + r.run.timings.setup_s;
        table.row([
            r.family.label.to_string(),
            r.run.method.to_string(),
            r.run.dofs.to_string(),
            format!("{one_s:.1}"),
            format!("{all_s:.1}"),
            format!("{:.2}", one_s / all_s),
            format!("{one_floor:.1}"),
            format!("{:.1}", floor_of(r)),
            format!("{:.2}", one_floor / floor_of(r)),
            format!("{:.2}", one_s / one_floor),
            format!("{:.2}", ratio(r)),
        ]);
    }
    table
}

/// Per cone, newton's time loop against the paper's solver at the paper's finest level.
fn newton_against_paper(res: &SpeedResult) -> Vec<String> {
    let finest = crate::studies::speed::PAPER_LEVELS.iter().max().unwrap();
    let mut out = Vec::new();
    for m in Method::ALL.into_iter().filter(|m| m.in_paper()) {
        let at_finest = |so| family_runs(res, &FAMILIES[0], m, so).find(|r| r.run.level == *finest);
        if let (Some(a), Some(b)) = (at_finest(SolverKind::Newton), at_finest(SolverKind::Paper)) {
            out.push(format!(
                "{m}, level {finest}: newton {:.3} s ({:.2} x the floor), paper {:.3} s at the same final tolerance: newton's time loop is {:.1} x faster.",
                a.run.time_loop_s,
                ratio(a),
                b.run.time_loop_s,
                b.run.time_loop_s / a.run.time_loop_s
            ));
        }
    }
    out
}

/// The two fills and their ratio (empty for a solver without a factor of the stiffness).
fn fill(newton: usize, floor: usize) -> String {
    match newton {
        0 => String::new(),
        _ => format!(
            "{:.3e} / {:.3e} = {:.3}",
            newton as f64,
            floor as f64,
            newton as f64 / floor.max(1) as f64
        ),
    }
}

fn gib(v: Option<f64>) -> String {
    v.map_or("-".into(), crate::io::memory_text)
}

/// The table of every run: cost split, floor, memory and error.
fn runs_table(res: &SpeedResult) -> Table {
    let mut table = Table::new([
        "family",
        "method",
        "solver",
        "level",
        "dofs",
        "iterations",
        "factorizations",
        "time loop (s)",
        "floor (s)",
        "(set-up + loop) / floor",
        "set-up (s)",
        "factorizations (s)",
        "solves (s)",
        "assembly (s)",
        "constitutive (s)",
        "fill, newton / floor (entries of L)",
        "peak RSS",
        "error",
    ]);
    for r in &res.rows {
        let (run, t) = (&r.run, &r.run.timings);
        table.row([
            r.family.label.to_string(),
            run.method.to_string(),
            run.solver.to_string(),
            run.level.to_string(),
            run.dofs.to_string(),
            run.iterations.to_string(),
            t.factorizations.to_string(),
            format!("{:.3}", run.time_loop_s),
            format!("{:.3}", floor_of(r)),
            format!("{:.2}", ratio(r)),
            format!("{:.3}", t.setup_s),
            format!("{:.3}", t.factor_s),
            format!("{:.3}", t.solve_s),
            format!("{:.3}", t.assembly_s),
            format!("{:.3}", t.constitutive_s),
            fill(t.factor_entries, r.floor.factor_entries),
            gib(run.peak_rss_gib),
            r.error.map(|e| format!("{e:.3e}")).unwrap_or_default(),
        ]);
    }
    table
}

/// What `study speed` prints: the table of the runs, and where the report went.
pub fn console(res: &SpeedResult, dir: &Path) -> String {
    format!(
        "{}{}wrote {} ({:.1} s)\n",
        runs_table(res).render(),
        manufactured_table(res).render(),
        dir.display(),
        res.wall_s
    )
}

/// Seconds with three significant digits (0.0744, 2.86, 16.3).
fn seconds(v: f64) -> String {
    format!(
        "{:.*}",
        (2 - v.abs().max(1e-300).log10().floor() as i32).max(0) as usize,
        v
    )
}

/// The kind's outcome writes this report.
impl Outcome for SpeedResult {
    fn write(&self, dir: &Path) -> Result<()> {
        write_speed(self, dir)
    }
    fn console(&self, dir: &Path) -> String {
        console(self, dir)
    }
}
