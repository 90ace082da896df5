//! The long run of the readers' fuzzing (the quick tier is tests/test_fuzz_readers.rs):
//!
//! ```sh
//! cargo run --release --example fuzz_readers -- [INPUTS_PER_READER] [SEED] [READER...]
//! ```
//!
//! tries INPUTS_PER_READER inputs (default 100,000; half random text, half a few edits of a
//! valid file) on each reader, or on the READERs named: gmsh's MSH 4.1 output (msh), study
//! files (study), scene files (scene), and the readers of other codes' solutions: .vtu with
//! ascii, inline base64, appended raw and appended base64 arrays (vtu-ascii, vtu-binary,
//! vtu-appended-raw, vtu-appended-base64), .pvd (pvd) and .msh with views (msh-solution).
//! A scene that reads is also checked against its level-0 mesh and its problem set up
//! (everything `solve` does before the time loop); gmsh runs once per distinct .geo and
//! parameters, into a temporary mesh cache. Prints per reader the inputs tried, accepted,
//! rejected, the panics and the errors that do not name the file and a field; saves those
//! inputs under target/fuzz-readers/; exits 1 if there is any. Deterministic for a seed, on
//! 2 threads.

#[path = "../tests/common/fuzz.rs"]
mod fuzz;

use fuzz::{Meshes, Reader};
use std::process::ExitCode;
use std::time::Instant;

/// Inputs per reader without an argument.
const DEFAULT_INPUTS: u64 = 100_000;
/// The seed without an argument (the quick test's).
const DEFAULT_SEED: u64 = 20261122;
/// Bad inputs saved and printed per reader.
const SHOWN: usize = 5;
/// How to run the example.
const USAGE: &str =
    "cargo run --release --example fuzz_readers -- [INPUTS_PER_READER] [SEED] [READER...]";

fn argument(args: &[String], i: usize, name: &str, default: u64) -> Result<u64, String> {
    match args.get(i) {
        None => Ok(default),
        Some(a) => a
            .replace('_', "")
            .parse()
            .map_err(|_| format!("{name}: '{a}' is not a non-negative integer; usage: {USAGE}")),
    }
}

/// 1234567 as "1,234,567".
fn thousands(n: u64) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(c);
    }
    out
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (count, seed) = match (
        argument(&args, 0, "INPUTS_PER_READER", DEFAULT_INPUTS),
        argument(&args, 1, "SEED", DEFAULT_SEED),
    ) {
        (Ok(c), Ok(s)) => (c, s),
        (Err(e), _) | (_, Err(e)) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let mut readers = Vec::new();
    for name in args.iter().skip(2) {
        match Reader::named(name) {
            Some(r) => readers.push(r),
            None => {
                let known: Vec<&str> = Reader::ALL.iter().map(|r| r.name()).collect();
                eprintln!(
                    "error: READER: '{name}' is not a reader; the readers are {}; usage: {USAGE}",
                    known.join(", ")
                );
                return ExitCode::from(2);
            }
        }
    }
    if readers.is_empty() {
        readers = Reader::ALL.to_vec();
    }
    // A cache of its own: the odd parameters of mutated scenes stay out of the project's.
    let cache = tempfile::tempdir().expect("a temporary folder");
    // SAFETY: no other thread exists yet (rayon's pool is built below).
    unsafe { std::env::set_var("CONTACT_RATES_CACHE", cache.path()) };
    rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build_global()
        .expect("rayon's pool");
    let saved_dir = fuzz::repo().join("target").join("fuzz-readers");
    let _ = std::fs::remove_dir_all(&saved_dir);
    std::fs::create_dir_all(&saved_dir).expect("target/fuzz-readers");
    println!(
        "{} inputs per reader, seed {seed}, 2 threads",
        thousands(count)
    );
    let mut failed = false;
    for reader in readers {
        let bases = fuzz::bases(reader, &[]);
        let meshes = Meshes::default();
        // The panics are counted and reported below, not printed as they happen.
        let hook = std::panic::take_hook();
        std::panic::set_hook(Box::new(|_| {}));
        let start = Instant::now();
        let tally = fuzz::run(reader, &bases, &meshes, seed, count);
        let seconds = start.elapsed().as_secs_f64();
        std::panic::set_hook(hook);
        let stages: Vec<String> = tally
            .rejected
            .iter()
            .map(|(stage, n)| format!("{stage} {}", thousands(*n)))
            .collect();
        println!(
            "{}: {} inputs ({} bases) in {seconds:.1} s: {} accepted ({} of {} mutated), {} rejected ({}), {} panics, {} errors not naming the file and a field{}",
            reader.name(),
            thousands(tally.tried),
            bases.len(),
            thousands(tally.accepted),
            thousands(tally.mutated_accepted),
            thousands(tally.mutated),
            thousands(tally.rejected_total()),
            stages.join(", "),
            tally.panics.len(),
            tally.unnamed.len(),
            if reader == Reader::Scene {
                format!("; {} distinct level-0 meshes", meshes.len())
            } else {
                String::new()
            }
        );
        let mut panics = tally.panics.clone();
        panics.sort_by_key(|p| p.0);
        for (index, path, message) in panics.iter().take(SHOWN) {
            println!(
                "  panic on input {index} (read as {}): {message}",
                path.display()
            );
        }
        let mut unnamed = tally.unnamed.clone();
        unnamed.sort_by_key(|u| u.0);
        for (index, error) in unnamed.iter().take(SHOWN) {
            println!("  input {index}: an error naming no file and field: {error}");
        }
        if !panics.is_empty() || !unnamed.is_empty() {
            // Regenerated from their indices: a run is deterministic.
            let mut first: Vec<u64> = panics.iter().map(|p| p.0).take(SHOWN).collect();
            first.extend(unnamed.iter().map(|u| u.0).take(SHOWN));
            for index in first {
                let (path, bytes) = fuzz::input(reader, &bases, seed, index);
                let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("txt");
                let f = saved_dir.join(format!("{}-{index}.{ext}", reader.name()));
                std::fs::write(&f, bytes).expect("write a saved input");
                println!("  input {index} saved as {}", f.display());
            }
            failed = true;
        }
    }
    if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}
