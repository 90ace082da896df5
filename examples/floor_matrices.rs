//! Writes the floor's matrices of one `study speed` mesh for an outside factorization, and
//! times this project's floor factorization on them: the elastic stiffness of the `rates`
//! family at LEVEL (h_upper = 0.28, h_lower = 0.28 / 1.4142), shifted as the floor shifts it,
//! one file per body's diagonal block (`block_B.bin`: n, nnz as u64, then the lower
//! triangle in compressed columns: column pointers and row indices as u64, values as f64).
//! bench/cholmod_floor.c factorizes the same files with CHOLMOD.
//!
//! `cargo run --release --example floor_matrices -- LEVEL DIR`
//!
//! Prints per block: n, nnz of the lower triangle, factor entries, and the best of 3 of
//! ordering + symbolic analysis, numeric factorization and one solve (s), on one thread.

use contact_rates::case::Case;
use contact_rates::contact::Method;
use contact_rates::scene::Scene;
use contact_rates::solve::floor::shifted_stiffness;
use contact_rates::solve::linear::OrderedCholesky;
use contact_rates::solve::ordering;
use std::io::Write;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let (Some(level), Some(dir)) = (
        args.get(1).and_then(|s| s.parse::<usize>().ok()),
        args.get(2),
    ) else {
        eprintln!("usage: floor_matrices LEVEL DIR");
        std::process::exit(2);
    };
    contact_rates::init();
    let scene = Scene::load("rates-elastic")?;
    let params = vec![
        ("h_upper".to_string(), 0.28),
        ("h_lower".to_string(), 0.28 / 1.4142),
    ];
    let case = Case::build(&scene, level, Method::Mortar, &params)?;
    let model = &case.problem.model;
    let n = model.n_free;
    let (pattern, values, _) = shifted_stiffness(model);
    std::fs::create_dir_all(dir)?;
    println!("level {level}: {n} dofs");
    for (b, range) in pattern.diagonal_blocks().into_iter().enumerate() {
        let (block, entries) = pattern.block(&range);
        let vals = &values[entries];
        // The lower triangle in compressed columns.
        let (mut ptr, mut rows, mut lower) = (vec![0u64], Vec::new(), Vec::new());
        for c in 0..block.n {
            for k in block.col_ptr[c]..block.col_ptr[c + 1] {
                if block.row_idx[k] >= c {
                    rows.push(block.row_idx[k] as u64);
                    lower.push(vals[k]);
                }
            }
            ptr.push(rows.len() as u64);
        }
        let mut f = std::io::BufWriter::new(std::fs::File::create(
            std::path::Path::new(dir).join(format!("block_{b}.bin")),
        )?);
        f.write_all(&(block.n as u64).to_le_bytes())?;
        f.write_all(&(rows.len() as u64).to_le_bytes())?;
        for v in &ptr {
            f.write_all(&v.to_le_bytes())?;
        }
        for v in &rows {
            f.write_all(&v.to_le_bytes())?;
        }
        for v in &lower {
            f.write_all(&v.to_le_bytes())?;
        }
        f.flush()?;
        let mut best = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
        let mut fill = 0;
        for _ in 0..3 {
            let t = Instant::now();
            let order = ordering::order(&block, &vec![false; block.n], None, range.start)?;
            let mut system = OrderedCholesky::new(&block, &order)?;
            let analyse = t.elapsed().as_secs_f64();
            let t = Instant::now();
            system.factor(vals)?;
            let factor = t.elapsed().as_secs_f64();
            let mut rhs = vec![1.0; block.n];
            let t = Instant::now();
            system.solve(&mut rhs);
            let solve = t.elapsed().as_secs_f64();
            fill = system.factor_entries();
            if analyse + factor + solve < best.0 + best.1 + best.2 {
                best = (analyse, factor, solve);
            }
        }
        println!(
            "block {b}: n {} nnz(lower) {} factor entries {fill}; faer: analyse {:.4} s, factor {:.4} s, solve {:.4} s, total {:.4} s",
            block.n,
            rows.len(),
            best.0,
            best.1,
            best.2,
            best.0 + best.1 + best.2
        );
    }
    Ok(())
}
