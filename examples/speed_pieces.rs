//! The seconds of each piece of newton's set-up and factorization and of the floor, on one
//! mesh of `study speed` (the `rates` family: h_upper = 0.28, h_lower = 0.28 / 1.4142 at
//! level 0), solver and floor alternately as in the study:
//! `CONTACT_RATES_PIECES=1 cargo run --release --example speed_pieces -- LEVEL [mortar|nts]
//! [rates|rates-elastic] [REPEATS]`.
//!
//! Prints one line per run: the run's totals, then `piece@block=seconds` (block: the
//! first equation of the diagonal block, 0 for a piece of the whole matrix; a piece run
//! several times, such as the solves, is summed and its count given in parentheses).
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

fn main() -> contact_rates::error::Result<()> {
    contact_rates::init();
    assert!(pieces::enabled(), "set CONTACT_RATES_PIECES=1");
    let args: Vec<String> = std::env::args().collect();
    let level: usize = args.get(1).map_or(5, |s| s.parse().expect("level"));
    let method = match args.get(2).map(String::as_str) {
        Some("nts") => Method::Nts,
        _ => Method::Mortar,
    };
    let scene = args.get(3).map_or("rates", String::as_str);
    let repeats: usize = args.get(4).map_or(3, |s| s.parse().expect("repeats"));
    let sizes = [
        ("h_upper".to_string(), 0.28),
        ("h_lower".to_string(), 0.28 / 1.4142),
    ];
    let case = Case::build(&Scene::load(scene)?, level, method, &sizes)?;
    println!(
        "level {level} {method:?} {scene} dofs {} threads {}",
        case.problem.model.n_free,
        rayon::current_num_threads()
    );
    pieces::take();
    for r in 0..repeats {
        release_free_heap();
        let sol = solve::solve(&case.problem, &Settings::default(), 4, true)?;
        let t = &sol.timings;
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
        let floor = solve::floor_time(&case.problem, 4)?;
        println!("run {r} floor total={floor:.4} {}", pieces_line());
    }
    Ok(())
}
