//! The seconds of newton's preconditioner solve (forward substitution, dense interface
//! solve, back substitution; both bodies side by side) on one mesh of `study speed` (the
//! `rates` family), the fastest of `REPEATS` solves of a fixed right-hand side, and the
//! largest difference from the first solve's result (the kernels are deterministic):
//! `cargo run --release --example substitutions -- LEVEL [mortar|nts] [REPEATS]`.
use contact_rates::case::Case;
use contact_rates::contact::Method;
use contact_rates::scene::Scene;
use contact_rates::solve::interface::{InterfaceFactorization, Precision};
use std::time::Instant;

fn main() -> contact_rates::error::Result<()> {
    contact_rates::init();
    contact_rates::on_pool(body)
}

fn body() -> contact_rates::error::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let level: usize = args.get(1).map_or(5, |s| s.parse().expect("level"));
    let method = match args.get(2).map(String::as_str) {
        Some("nts") => Method::Nts,
        Some("lac") => Method::Lac,
        _ => Method::Mortar,
    };
    let repeats: usize = args.get(3).map_or(30, |s| s.parse().expect("repeats"));
    let sizes = [
        ("h_upper".to_string(), 0.28),
        ("h_lower".to_string(), 0.28 / 1.4142),
    ];
    let case = Case::build(&Scene::load("rates")?, level, method, &sizes)?;
    let model = &case.problem.model;
    let n = model.n_free;
    let (pattern, slots) = model.stiffness_pattern(&[], n);
    let mut values = vec![0.0; pattern.nnz()];
    model.add_tangent(&model.elastic_tangents(), &slots, &mut values);
    let c = (0..n).map(|i| values[pattern.slot(i, i)]).sum::<f64>() / n as f64;
    let rows = case.problem.free_rows();
    let m = rows.len();
    let mut factorization = InterfaceFactorization::new(&pattern, &rows)?;
    factorization.factor(&values, c, Precision::Single)?;
    let set = factorization.active_set(&vec![true; m], c)?;
    // A fixed, dense right-hand side.
    let b: Vec<f64> = (0..n + m)
        .map(|i| ((i * 7919) % 1000) as f64 / 500.0 - 1.0)
        .collect();
    let (mut best, mut first, mut spread) = (f64::INFINITY, None::<Vec<f64>>, 0.0f64);
    let (mut forward, mut back) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..repeats {
        let mut x = b.clone();
        let t = Instant::now();
        factorization.solve(&set, c, &mut x);
        best = best.min(t.elapsed().as_secs_f64());
        // The two substitutions apart.
        let t = Instant::now();
        let condensed = factorization.condense(&b[..n]);
        forward = forward.min(t.elapsed().as_secs_f64());
        let (x_interface, _) = factorization.interface_solve(&set, c, &condensed.load, &b[n..]);
        let t = Instant::now();
        let _ = factorization.expand(condensed, &x_interface);
        back = back.min(t.elapsed().as_secs_f64());
        match &first {
            None => first = Some(x),
            Some(f) => {
                spread = f
                    .iter()
                    .zip(&x)
                    .fold(spread, |s, (a, b)| s.max((a - b).abs()))
            }
        }
    }
    let x = first.expect("one solve");
    println!(
        "level {level} {method:?} dofs {n} threads {} fill {}: solve {:.3} ms (fastest of {repeats}; forward {:.3}, back {:.3}), |x| {:.6e}, spread {spread:.1e}, bits {:016x}",
        rayon::current_num_threads(),
        factorization.factor_entries(),
        best * 1e3,
        forward * 1e3,
        back * 1e3,
        x.iter().map(|v| v * v).sum::<f64>().sqrt(),
        // A checksum of every bit of x: two versions of the kernels agree to the bit
        // where it does.
        x.iter()
            .fold(0u64, |h, v| (h ^ v.to_bits()).wrapping_mul(0x100000001b3))
    );
    Ok(())
}
