//! The seconds of row assembly (`contact::constraint_rows`) against one solve, per method,
//! on contact-mms levels 5-7 (the baseline issue 75 holds its contact operator to: at most
//! 2x this and under 1% of the solve):
//! `cargo run --release --example contact_rows_timing -- [LEVELS] [REPEATS]` (default
//! 5-7 and 5). Prints per level and method the median of REPEATS assemblies, the rows'
//! count, and one newton solve of the scene's steps with those rows, and their ratio.
use contact_rates::case::Case;
use contact_rates::contact::{Method, constraint_rows};
use contact_rates::scene::Scene;
use contact_rates::solve::SolverKind;
use std::time::Instant;

fn main() {
    contact_rates::init();
    let args: Vec<String> = std::env::args().collect();
    let (first, last) = match args.get(1) {
        Some(r) => {
            let (a, b) = r.split_once('-').unwrap_or((r, r));
            (
                a.parse().expect("LEVELS: 5-7"),
                b.parse().expect("LEVELS: 5-7"),
            )
        }
        None => (5usize, 7usize),
    };
    let repeats: usize = args
        .get(2)
        .map_or(5, |r| r.parse().expect("REPEATS: a count"));
    let scene = Scene::load("contact-mms").expect("the built-in scene");
    for level in first..=last {
        for method in Method::ALL {
            let case = Case::build(&scene, level, method, &[]).expect("the case builds");
            let p = &case.problem;
            let mut seconds: Vec<f64> = (0..repeats)
                .map(|_| {
                    let t = Instant::now();
                    let rows = constraint_rows(&p.model, &p.interface, method);
                    let s = t.elapsed().as_secs_f64();
                    assert_eq!(rows.len(), p.rows.len());
                    s
                })
                .collect();
            seconds.sort_by(f64::total_cmp);
            let median = seconds[repeats / 2];
            let (_, solve_s) =
                contact_rates::verify::solve_case(&case, SolverKind::Newton, scene.steps)
                    .expect("the solve converges");
            println!(
                "level {level} {method:6} dofs {:8} rows {:4}: assembly {median:.6} s (median of {repeats}), solve {solve_s:.3} s, ratio {:.2e}",
                p.model.n_free,
                p.rows.len(),
                median / solve_s
            );
        }
    }
}
