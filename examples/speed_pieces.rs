//! The seconds of each piece of newton's set-up and factorization and of the floor, on one
//! mesh of `study speed` (the `rates` family: h_upper = 0.28, h_lower = 0.28 / 1.4142 at
//! level 0), solver and floor alternately as in the study:
//! `CONTACT_RATES_PIECES=1 cargo run --release --example speed_pieces -- LEVEL [mortar|nts]
//! [rates|rates-elastic] [REPEATS]`.
//!
//! Prints two lines per run and side: `faults solver|floor N cpu S`, the minor page faults
//! of that run (a first touch of a fresh 4 KB page cost 2.0-2.2 us on the 2-core machine of
//! issue 24, so 15,000 faults are about 30 ms of CPU time) and the user + system CPU
//! seconds of all the process's threads over it (rayon's spinning within the run
//! included); then the run's totals and `piece@block=seconds` (block: the first equation
//! of the diagonal block, 0 for a piece of the whole matrix; a piece run several times,
//! such as the solves, is summed and its count given in parentheses).
//!
//! Environment, for experiments: `SKIP_FLOOR` (set, whatever its value) times the solver
//! only (for `perf record` of newton alone); `HISTORY_LEVEL=L` first
//! solves `rates` at level L with the same cone and measures its floor once, then drops
//! it, so that the timed runs follow a large run in the same process, as most blocks of
//! `study speed` after the first do (there the large run is the previous block's level 7,
//! of the other cone or family). Measured once each: after level 7, `rates-elastic` level
//! 4 mortar read 0.0713 s against a floor of 0.0715 s (ratio 1.00), a fresh process right
//! after 0.0650 and 0.0629 s (1.03): both sides slower by 10-14% in that sample, the ratio
//! alike.
use contact_rates::case::{Case, release_free_heap};
use contact_rates::contact::Method;
use contact_rates::scene::Scene;
use contact_rates::solve::{self, Settings, pieces};
use std::collections::BTreeMap;

/// The pieces recorded since the last call, summed per (piece, block), as one string.
fn pieces_line() -> String {
    let mut sums: BTreeMap<(&str, usize), (f64, usize)> = BTreeMap::new();
    for (name, block, seconds) in pieces::take() {
        let entry = sums.entry((name, block)).or_default();
        entry.0 += seconds;
        entry.1 += 1;
    }
    sums.iter()
        .map(|(&(name, block), &(seconds, count))| match count {
            1 => format!("{name}@{block}={seconds:.4}"),
            _ => format!("{name}@{block}={seconds:.4}({count})"),
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// The process's (minor page faults, user + system CPU seconds) so far.
fn usage() -> (i64, f64) {
    // SAFETY: getrusage only writes the struct it is given.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) };
    let seconds = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    (u.ru_minflt, seconds(u.ru_utime) + seconds(u.ru_stime))
}

/// `faults WHO N cpu S` since `before` (a [`usage`]).
fn usage_line(who: &str, before: (i64, f64)) -> String {
    let now = usage();
    format!(
        "faults {who} {} cpu {:.4}",
        now.0 - before.0,
        now.1 - before.1
    )
}

fn main() -> contact_rates::error::Result<()> {
    contact_rates::init();
    contact_rates::on_pool(body)
}

fn body() -> contact_rates::error::Result<()> {
    assert!(pieces::enabled(), "set CONTACT_RATES_PIECES=1");
    let args: Vec<String> = std::env::args().collect();
    let level: usize = args.get(1).map_or(5, |s| s.parse().expect("level"));
    let method = match args.get(2).map(String::as_str) {
        Some("nts") => Method::Nts,
        Some("lac") => Method::Lac,
        _ => Method::Mortar,
    };
    let scene = args.get(3).map_or("rates", String::as_str);
    let repeats: usize = args.get(4).map_or(3, |s| s.parse().expect("repeats"));
    let sizes = [
        ("h_upper".to_string(), 0.28),
        ("h_lower".to_string(), 0.28 / 1.4142),
    ];
    if let Some(history) = std::env::var("HISTORY_LEVEL").ok() {
        let history: usize = history.parse().expect("HISTORY_LEVEL: a level");
        let large = Case::build(&Scene::load("rates")?, history, method, &sizes)?;
        drop(solve::solve(&large.problem, &Settings::default(), 4, true)?);
        release_free_heap();
        solve::floor_time(&large.problem, 4)?;
        drop(large);
        release_free_heap();
        println!("history: level {history} solved and its floor measured");
    }
    let case = Case::build(&Scene::load(scene)?, level, method, &sizes)?;
    println!(
        "level {level} {method:?} {scene} dofs {} threads {}",
        case.problem.model.n_free,
        rayon::current_num_threads()
    );
    pieces::take();
    for r in 0..repeats {
        release_free_heap();
        let before = usage();
        let sol = solve::solve(&case.problem, &Settings::default(), 4, true)?;
        let t = &sol.timings;
        println!("{}", usage_line("solver", before));
        println!(
            "run {r} solver total={:.4} setup={:.4} loop={:.4} factor={:.4} solve={:.4} assembly={:.4} constitutive={:.4} contact={:.4} iterations={} factorizations={} solves={} {}",
            sol.wall_s + t.setup_s,
            t.setup_s,
            sol.wall_s,
            t.factor_s,
            t.solve_s,
            t.assembly_s,
            t.constitutive_s,
            t.contact_s,
            sol.iterations(),
            t.factorizations,
            t.solves,
            pieces_line()
        );
        drop(sol);
        release_free_heap();
        if std::env::var_os("SKIP_FLOOR").is_some() {
            continue;
        }
        let before = usage();
        let floor = solve::floor(&case.problem, 4)?;
        println!("{}", usage_line("floor", before));
        println!(
            "run {r} floor total={:.4} ({:?}) double={:.4} single={} systems={} applications={} {}",
            floor.seconds,
            floor.precision,
            floor.double_s,
            floor
                .single_s
                .map_or("missed".into(), |s| format!("{s:.4}")),
            floor.systems,
            floor.single_applications,
            pieces_line()
        );
    }
    Ok(())
}
