//! Repeats one Newton solve of the rates scene to profile it:
//! `cargo run --release --example profile_newton -- LEVEL REPEATS [mortar|nts]`.
use contact_rates::case::Case;
use contact_rates::contact::Method;
use contact_rates::scene::Scene;
use contact_rates::solve::{self, Settings};

fn main() -> contact_rates::error::Result<()> {
    contact_rates::init();
    contact_rates::on_pool(body)
}

fn body() -> contact_rates::error::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let level: usize = args.get(1).map_or(3, |s| s.parse().unwrap());
    let repeats: usize = args.get(2).map_or(10, |s| s.parse().unwrap());
    let scene = Scene::load("rates")?;
    let fam = vec![
        ("h_upper".to_string(), 0.3),
        ("h_lower".to_string(), 0.3 / 1.4142),
    ];
    let method = match args.get(3).map(String::as_str) {
        Some("nts") => Method::Nts,
        Some("lac") => Method::Lac,
        _ => Method::Mortar,
    };
    let case = Case::build(&scene, level, method, &fam)?;
    for _ in 0..repeats {
        let sol = solve::solve(&case.problem, &Settings::default(), 4, false)?;
        let floor = solve::floor_time(&case.problem, 4)?;
        let t = sol.timings;
        println!(
            "wall {:.4} floor {:.4} ratio {:.2} its {} fact {} ({:.4}) solves {} solve {:.4} asm {:.4} const {:.4} contact {:.4}",
            sol.wall_s,
            floor,
            sol.wall_s / floor,
            sol.iterations(),
            t.factorizations,
            t.factor_s,
            t.solves,
            t.solve_s,
            t.assembly_s,
            t.constitutive_s,
            t.contact_s
        );
    }
    Ok(())
}
