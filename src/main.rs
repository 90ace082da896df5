//! Command-line interface: a thin layer over the library.

use anyhow::Context;
use clap::{Parser, Subcommand};
use contact_rates::case::Case;
use contact_rates::contact::Method;
use contact_rates::solve::{self, Settings, SolverKind};
use contact_rates::{io, metrics, scene::Scene};
use serde::Serialize;
use std::path::{Path, PathBuf};

#[derive(Parser)]
#[command(
    name = "contact-rates",
    version,
    about = "Convergence rates of mortar and node-on-segment contact on non-matching meshes"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a convergence study (`study list` lists them) and write reports/NAME/.
    Study {
        /// Study name (studies/NAME.toml), a path to a study file, or `list`.
        name: String,
        /// Report folder (default: reports/NAME).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Run only the i-th of n slices of the study's solves and store their records
        /// (for a cluster's job array); no report.
        #[arg(long, value_name = "i/n", conflicts_with = "merge")]
        shard: Option<String>,
        /// Build the report from the records of all shards.
        #[arg(long)]
        merge: bool,
    },
    /// Solve one scene on one mesh level and write solution.vtu and summary.csv.
    Solve {
        /// Built-in scene name or path to a scene .toml.
        #[arg(long)]
        scene: String,
        /// Contact condition: mortar (K_h^pi) or nts (K_h^I).
        #[arg(long, default_value = "mortar")]
        method: String,
        /// Solver: newton, paper or qp.
        #[arg(long, default_value = "newton")]
        solver: String,
        /// Mesh refinement level (0 = the .geo's own mesh; each level splits every triangle in 4).
        #[arg(long, default_value_t = 0)]
        level: usize,
        /// Number of time steps (default: the scene's).
        #[arg(long)]
        steps: Option<usize>,
        /// Output folder.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Penalty parameter omega of the paper solver (default: automatic).
        #[arg(long)]
        omega: Option<f64>,
        /// Relaxation rho of the paper solver, in (0, 1] (0.5: rho = 1 can cycle forever on a body held only by contact).
        #[arg(long, default_value_t = 0.5)]
        rho: f64,
        /// Relative tolerance of the solvers.
        #[arg(long, default_value_t = 1e-10)]
        tol: f64,
        /// gmsh parameter overrides, NAME=VALUE (repeatable).
        #[arg(long = "set", value_name = "NAME=VALUE")]
        set: Vec<String>,
    },
}

/// One row of summary.csv.
#[derive(Serialize)]
struct Summary {
    scene: String,
    method: String,
    solver: String,
    level: usize,
    h: f64,
    dofs: usize,
    steps: usize,
    iterations: usize,
    max_step_iterations: usize,
    wall_s: f64,
    max_penetration: f64,
    contact_fraction: f64,
    plastic_fraction: f64,
    converged: bool,
    mesh_s: f64,
    assembly_s: f64,
    factor_s: f64,
    solve_s: f64,
    constitutive_s: f64,
    contact_s: f64,
    factorizations: usize,
    active_set_changes: usize,
    time_loop_s: f64,
    solver_setup_s: f64,
    floor_s: f64,
    ratio_to_floor: f64,
}

fn parse_sets(set: &[String]) -> anyhow::Result<Vec<(String, f64)>> {
    set.iter()
        .map(|s| {
            let (k, v) = s
                .split_once('=')
                .with_context(|| format!("--set {s}: expected NAME=VALUE"))?;
            let v: f64 = v
                .parse()
                .with_context(|| format!("--set {s}: '{v}' is not a number"))?;
            Ok((k.to_string(), v))
        })
        .collect()
}

fn run() -> anyhow::Result<()> {
    contact_rates::init();
    let cli = Cli::parse();
    match cli.command {
        Command::Study {
            name,
            out,
            shard,
            merge,
        } => {
            if name == "list" {
                println!(
                    "{:12} {}",
                    "paper",
                    "The paper's three numerical tests (section 5): figures and the numbers behind its words"
                );
                for (n, d) in contact_rates::study::file::list() {
                    println!("{n:12} {d}");
                }
                return Ok(());
            }
            // The report folder is checked before any computing.
            if shard.is_none() {
                let stem = Path::new(&name)
                    .file_stem()
                    .map(|s| s.to_string_lossy().to_string())
                    .unwrap_or_else(|| name.clone());
                let dir = out
                    .clone()
                    .unwrap_or_else(|| contact_rates::report::reports_dir().join(stem));
                contact_rates::report::check_writable(&dir)?;
            }
            if name == "stability" {
                let res = contact_rates::study::stability::run()?;
                let dir =
                    out.unwrap_or_else(|| contact_rates::report::reports_dir().join("stability"));
                contact_rates::report::write_stability(&res, &dir)?;
                for r in &res.rows {
                    println!(
                        "{:26} {:36} {:7} {:7} converged {:5} iterations max {:3} mean {:6.1} error {:9} {:.2} s{}",
                        r.case,
                        r.parameter,
                        r.method,
                        r.solver,
                        r.converged,
                        r.max_step_iterations,
                        r.mean_step_iterations,
                        if r.error.is_finite() {
                            format!("{:.2e}", r.error)
                        } else {
                            "-".into()
                        },
                        r.wall_s,
                        if r.converged {
                            String::new()
                        } else {
                            format!(": {}", r.reason)
                        }
                    );
                }
                println!("wrote {} ({:.1} s)", dir.display(), res.wall_s);
                return Ok(());
            }
            if name == "speed" {
                let res = contact_rates::study::speed::run()?;
                let dir = out.unwrap_or_else(|| contact_rates::report::reports_dir().join("speed"));
                contact_rates::report::write_speed(&res, &dir)?;
                for r in &res.rows {
                    println!(
                        "{:11} {:7} {:7} level {} {:7} dofs: {:3} iterations, {:2} factorizations, {:8.3} s = {:5.2} x floor ({:.3} s), set-up {:.3} s, peak {} GiB, error {}",
                        r.family,
                        r.method,
                        r.solver,
                        r.level,
                        r.dofs,
                        r.iterations,
                        r.factorizations,
                        r.wall_s,
                        r.ratio_to_floor,
                        r.floor_s,
                        r.setup_s,
                        r.peak_rss_gib
                            .map(|g| format!("{g:.1}"))
                            .unwrap_or_default(),
                        r.error.map(|e| format!("{e:.3e}")).unwrap_or_default()
                    );
                }
                println!("wrote {} ({:.1} s)", dir.display(), res.wall_s);
                return Ok(());
            }
            if name == "paper" {
                let res = contact_rates::study::paper::run()?;
                let dir = out.unwrap_or_else(|| contact_rates::report::reports_dir().join("paper"));
                contact_rates::report::paper::write_paper(&res, &dir)?;
                let t = &res.test2_numbers;
                println!(
                    "Test 2: mortar stress error {:.2e}, nts interpenetration {:.3e} ({:.2e} of max |u|), nts spurious stress {:.3}",
                    t.mortar_stress_error,
                    t.nts_penetration.0,
                    t.nts_penetration.1,
                    t.nts_stress_error.0
                );
                for (l, h, d) in &res.test3_agreement {
                    println!("Test 3: level {l} h {h:.4}: non-matching vs matching {d:.3e}");
                }
                println!("wrote {} ({:.1} s)", dir.display(), res.wall_s);
                return Ok(());
            }
            let mode = match (&shard, merge) {
                (Some(sh), _) => contact_rates::study::jobs::Mode::shard(sh)?,
                (None, true) => contact_rates::study::jobs::Mode::Merge,
                (None, false) => contact_rates::study::jobs::Mode::All,
            };
            let Some(result) = contact_rates::study::run_mode(&name, mode)? else {
                return Ok(());
            };
            for w in &result.warnings {
                eprintln!("warning: {w}");
            }
            let dir =
                out.unwrap_or_else(|| contact_rates::report::reports_dir().join(&result.name));
            contact_rates::report::write_study(&result, &dir)?;
            for r in &result.rates {
                println!(
                    "{:7} {:16} rate {:>6} +- {} (levels {}){}",
                    r.method,
                    r.quantity,
                    contact_rates::io::fmt3(r.rate),
                    contact_rates::io::fmt3(r.stderr),
                    r.levels_used,
                    r.threshold
                        .map(|t| format!(
                            " threshold {}: {}",
                            if t < 0.01 {
                                format!("error <= {t:.0e}")
                            } else {
                                format!("rate >= {t:.3}")
                            },
                            if r.pass == Some(true) { "pass" } else { "FAIL" }
                        ))
                        .unwrap_or_default()
                );
            }
            for e in &result.errors {
                if e.quantity == "theorem" {
                    println!(
                        "{} level {} h {:.4} dofs {} error {:.4e} ({:.2} s)",
                        e.method, e.level, e.h, e.dofs, e.error, e.wall_s
                    );
                }
            }
            println!(
                "reference level {} ({} dofs, {:.1} s), estimated error {:.3e} (rate {:.2}); study {:.1} s",
                result.reference.0,
                result.reference.2,
                result.reference.3,
                result.reference_error.0,
                result.reference_error.1,
                result.wall_s
            );
            println!("wrote {}", dir.display());
            let failed: Vec<String> = result
                .rates
                .iter()
                .filter(|r| r.pass == Some(false))
                .map(|r| {
                    if result.file.thresholds.exact.contains(&r.method) {
                        format!(
                            "{} {} error above the exactness tolerance {:.1e}",
                            r.method,
                            r.quantity,
                            r.threshold.unwrap()
                        )
                    } else {
                        format!(
                            "{} {} rate {:.3} < {:.3} (levels {})",
                            r.method,
                            r.quantity,
                            r.rate,
                            r.threshold.unwrap(),
                            r.levels_used
                        )
                    }
                })
                .collect();
            if !failed.is_empty() {
                anyhow::bail!("rate below threshold: {}", failed.join("; "));
            }
        }
        Command::Solve {
            scene,
            method,
            solver,
            level,
            steps,
            out,
            omega,
            rho,
            tol,
            set,
        } => {
            let method = Method::parse(&method).with_context(|| {
                format!("--method: unknown cone '{method}'; use mortar (K_h^pi) or nts (K_h^I)")
            })?;
            let kind = SolverKind::parse(&solver).with_context(|| {
                format!("--solver: unknown solver '{solver}'; use newton, paper or qp")
            })?;
            if !(tol > 0.0) {
                anyhow::bail!("--tol: the tolerance must be positive, got {tol}");
            }
            let scene = Scene::load(&scene)?;
            let steps = steps.unwrap_or(scene.steps);
            if steps == 0 {
                anyhow::bail!("--steps: the number of time steps must be at least 1");
            }
            // The output folder is checked (and created) before any computing.
            contact_rates::report::check_writable(&out.join("solution"))?;
            let t0 = std::time::Instant::now();
            let case = Case::build(&scene, level, method, &parse_sets(&set)?)?;
            for w in &case.warnings {
                eprintln!("warning: {w}");
            }
            let settings = Settings {
                kind,
                tol,
                omega,
                rho,
                ..Settings::default()
            };
            let sol = solve::solve(&case.problem, &settings, steps, false)?;
            let floor_s = solve::floor_time(&case.problem, steps)?;
            let last = sol.last();
            let p = &case.problem;
            let summary = Summary {
                scene: scene.name.clone(),
                method: method.name().into(),
                solver: kind.name().into(),
                level,
                h: case.h,
                dofs: p.model.n_free,
                steps,
                iterations: sol.iterations(),
                max_step_iterations: sol.max_step_iterations(),
                wall_s: t0.elapsed().as_secs_f64(),
                max_penetration: metrics::max_penetration(p, last),
                contact_fraction: metrics::contact_fraction(p, last),
                plastic_fraction: metrics::plastic_fraction(p, last),
                converged: true,
                mesh_s: case.mesh_s,
                assembly_s: sol.timings.assembly_s,
                factor_s: sol.timings.factor_s,
                solve_s: sol.timings.solve_s,
                constitutive_s: sol.timings.constitutive_s,
                contact_s: sol.timings.contact_s,
                factorizations: sol.timings.factorizations,
                active_set_changes: sol.active_set_changes(),
                time_loop_s: sol.wall_s,
                solver_setup_s: sol.timings.setup_s,
                floor_s,
                ratio_to_floor: sol.wall_s / floor_s,
            };
            io::write_atomic(
                &out.join("solution.vtu"),
                io::vtu(&p.model, last).as_bytes(),
            )?;
            io::write_atomic(&out.join("summary.csv"), &io::csv_bytes(&[&summary])?)?;
            println!(
                "{} {} {} level {level}: h = {:.4}, {} dofs, {steps} steps, {} iterations (max {} per step), {:.3} s; max penetration {:.3e}, contact fraction {:.3}, plastic fraction {:.3}",
                summary.scene,
                summary.method,
                summary.solver,
                summary.h,
                summary.dofs,
                summary.iterations,
                summary.max_step_iterations,
                summary.wall_s,
                summary.max_penetration,
                summary.contact_fraction,
                summary.plastic_fraction
            );
            let t = &sol.timings;
            println!(
                "  mesh {:.3} s, model {:.3} s, solver set-up (pattern, symbolic) {:.3} s; time loop {:.3} s = {:.2} x the floor ({:.3} s): {} factorizations {:.3} s, solves {:.3} s, assembly {:.3} s, constitutive {:.3} s, contact {:.3} s; {} active-set changes; peak RSS {} GiB",
                case.mesh_s,
                case.setup_s,
                t.setup_s,
                sol.wall_s,
                sol.wall_s / floor_s,
                floor_s,
                t.factorizations,
                t.factor_s,
                t.solve_s,
                t.assembly_s,
                t.constitutive_s,
                t.contact_s,
                sol.active_set_changes(),
                contact_rates::study::speed::peak_rss_gib()
                    .map(|g| format!("{g:.1}"))
                    .unwrap_or_default()
            );
            println!(
                "wrote {} and {}",
                out.join("solution.vtu").display(),
                out.join("summary.csv").display()
            );
        }
    }
    Ok(())
}

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
