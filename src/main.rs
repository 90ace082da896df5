//! Command-line interface: a thin layer over the library.

use anyhow::Context;
use clap::{Parser, Subcommand};
use contact_rates::case::{Case, PeakMemory, RunSummary};
use contact_rates::contact::Method;
use contact_rates::external::export::{self, Source};
use contact_rates::external::{grade, judge_file};
use contact_rates::io::solution::FieldNames;
use contact_rates::progress::Progress;
use contact_rates::report::{self, Output, Staging};
use contact_rates::scene::Scene;
use contact_rates::solve::{self, Settings, SolverKind};
use contact_rates::studies::Study;
use contact_rates::verify::jobs::Mode;
use signal_hook::iterator::Signals;
use signal_hook::low_level::signal_name;
use std::io::Write as _;
use std::path::PathBuf;

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
    /// Run a study (`study list` lists them) and write its report to target/reports/NAME/
    /// (outside version control), or with --publish to the committed reports/NAME/.
    Study {
        /// Study name (studies/NAME.toml), a path to a study file, or `list`.
        name: String,
        /// Report folder (default: target/reports/NAME; reports/NAME with --publish).
        #[arg(long, conflicts_with = "publish")]
        out: Option<PathBuf>,
        /// Write the committed report reports/NAME (what the repository's reports are
        /// refreshed with; its timings and provenance change the tracked files).
        #[arg(long)]
        publish: bool,
        /// Run only the i-th of n slices of the study's solves and store their records
        /// (for a cluster's job array); no report.
        #[arg(long, value_name = "i/n", conflicts_with = "merge")]
        shard: Option<String>,
        /// Build the report from the records of all shards.
        #[arg(long)]
        merge: bool,
        /// Judge the written report (the report folder as above) again from its CSVs and rewrite
        /// rates.csv, the plots and README.md, without solving (von_mises.png is kept).
        #[arg(long, conflicts_with_all = ["shard", "merge"])]
        rejudge: bool,
    },
    /// Print the Results page docs/results.md, read from the committed reports' CSVs
    /// (reports/rates, rates-exact, rates-exact-vp, patch, crossover, two-size-exact, two-size-rates,
    /// speed, stability).
    Results {
        /// Print instead README.md's headline table (between its `headline` markers).
        #[arg(long, conflicts_with = "glossary")]
        headline: bool,
        /// Print instead the glossary of every quantity (docs/studies.md, between its
        /// `glossary` markers; every grade report prints the part it names).
        #[arg(long)]
        glossary: bool,
    },
    /// The built-in scenes (`scene list`).
    Scene {
        #[command(subcommand)]
        action: SceneAction,
    },
    /// Solve one scene on one mesh level and write its time series (binary VTU), contact.csv
    /// and summary.csv into --out, all or nothing.
    Solve(SolveArgs),
    /// Grade another code's solutions of an exported problem against the exact solution:
    /// errors, rates and verdicts beside this project's mortar, nts and lac (reports/grade-NAME).
    Grade(GradeArgs),
    /// Assemble the report of what real contact codes converge at (reports/codes) from grade
    /// reports GRADES/PROBLEM/CODE/ (the workflow in workflow/Snakefile writes them).
    Codes {
        /// The folder of PROBLEM/CODE grade reports.
        #[arg(long)]
        grades: PathBuf,
        /// Report folder.
        #[arg(long, default_value = "reports/codes")]
        out: PathBuf,
    },
    /// Judge anyone's table of errors with the studies' rules: a CSV with columns h,error and
    /// optionally level, dofs, method, quantity (one verdict per method and quantity) and
    /// truth_error. Exits non-zero only where a threshold fails.
    Judge {
        /// The CSV file.
        file: PathBuf,
        /// A required rate R: `pass` where the verdict supports a rate and both the fit and
        /// the last successive rate reach R, `fail` where the last successive rate is below
        /// R, `unverified` otherwise.
        #[arg(long, value_name = "R")]
        threshold: Option<f64>,
        /// Apply the threshold to this method only (default: every group).
        #[arg(long, value_name = "M")]
        method: Option<String>,
        /// Apply the threshold to this quantity only (default: every group).
        #[arg(long, value_name = "Q")]
        quantity: Option<String>,
        /// Write rates.csv and error_vs_h.png into this folder.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Export a manufactured contact problem for another code: meshes (MSH 4.1 and 2.2),
    /// problem.toml, problem.py, nodal loads per level and step, README.md; all or nothing.
    Export {
        #[command(flatten)]
        source: SourceArgs,
        /// Mesh levels, A-B (e.g. 0-3).
        #[arg(long, value_name = "A-B")]
        levels: String,
        /// Output folder.
        #[arg(long)]
        out: PathBuf,
    },
}

/// The arguments of `grade`.
#[derive(clap::Args)]
struct GradeArgs {
    #[command(flatten)]
    source: SourceArgs,
    /// The folder of the solutions: level_L.vtu (the state at T), level_L.pvd (a series)
    /// or level_L.msh, one per level.
    #[arg(long)]
    solutions: PathBuf,
    /// Levels to grade, A-B (default: every level with a file).
    #[arg(long, value_name = "A-B")]
    levels: Option<String>,
    /// The graded code's label in the report (not mortar, nts or lac).
    #[arg(long, default_value = "graded")]
    name: String,
    /// A required rate R for the graded code's theorem norm (l2_stress where the exact
    /// solution gives no displacement): `pass` where its verdict supports a rate and both
    /// the fit and the last successive rate reach R; `fail` (non-zero exit) where the last
    /// successive rate is below R; `unverified` (printed, zero exit) otherwise.
    #[arg(long, value_name = "R")]
    threshold: Option<f64>,
    /// Report folder (default: reports/grade-NAME).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Do not solve this project's mortar, nts and lac beside it.
    #[arg(long)]
    no_compare: bool,
    /// The name of the displacement point data.
    #[arg(long, default_value = "displacement")]
    displacement: String,
    /// The name of the stress cell data.
    #[arg(long, default_value = "stress")]
    stress: String,
    /// The name of the pressure point data.
    #[arg(long, default_value = "pressure")]
    pressure: String,
}

/// Where an exported or graded problem comes from: a study or a scene.
#[derive(clap::Args)]
#[group(required = true, multiple = false)]
struct SourceArgs {
    /// A study (studies/NAME.toml or a path): its scene, mesh family and steps.
    #[arg(long)]
    study: Option<String>,
    /// A scene (built-in name or a path), with its own mesh sizes and steps.
    #[arg(long)]
    scene: Option<String>,
}

impl SourceArgs {
    fn source(&self) -> Source {
        match (&self.study, &self.scene) {
            (Some(study), _) => Source::Study(study.clone()),
            (None, Some(scene)) => Source::Scene(scene.clone()),
            (None, None) => unreachable!("clap requires --study or --scene"),
        }
    }
}

/// The arguments of `solve`.
#[derive(clap::Args)]
struct SolveArgs {
    /// Built-in scene name (`scene list` lists them) or path to a scene .toml.
    #[arg(long)]
    scene: String,
    /// Contact condition: mortar (K_h^pi), nts (K_h^I) or lac (local average contact)
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
    /// Also measure the floor (one sparse Cholesky of the stiffness and a solve per
    /// step, from scratch) and report the solver's cost as a multiple of it.
    #[arg(long)]
    floor: bool,
    /// Write every K-th time step (and the last) to the time series.
    #[arg(long, value_name = "K", default_value_t = 1)]
    every: usize,
}

#[derive(Subcommand)]
enum SceneAction {
    /// List the built-in scenes with their descriptions.
    List,
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

/// The command line, or clap's message and exit 2. clap's tip for an unknown option after a
/// positional argument ("to pass '--levle' as a value, use '-- --levle'") would send a user
/// of `study NAME --levle 3` the wrong way: a study takes no options for its levels, its
/// study file sets them, and the tip says so instead.
fn parse_cli() -> Cli {
    let e = match Cli::try_parse() {
        Ok(cli) => return cli,
        Err(e) => e,
    };
    let text = e.render().to_string();
    let in_study = std::env::args().nth(1).as_deref() == Some("study");
    if e.kind() == clap::error::ErrorKind::UnknownArgument && in_study && text.contains("-- ") {
        let tip = "  tip: `study NAME` takes --out, --publish, --shard, --merge and --rejudge; its levels, methods, solver and steps are set in the study file (studies/NAME.toml: [mesh] levels, methods, solver, steps; docs/studies.md)";
        let fixed: Vec<String> = text
            .lines()
            .map(|l| match l.trim_start().starts_with("tip: to pass") {
                true => tip.to_string(),
                false => l.to_string(),
            })
            .collect();
        eprintln!("{}", fixed.join("\n"));
        std::process::exit(2);
    }
    e.exit()
}

fn run() -> anyhow::Result<()> {
    contact_rates::init();
    match parse_cli().command {
        Command::Study {
            name,
            out,
            publish,
            shard,
            merge,
            rejudge,
        } => study(&name, out, publish, shard.as_deref(), merge, rejudge),
        Command::Results { headline, glossary } => {
            let reports = report::reports_dir();
            if glossary {
                print!(
                    "{}",
                    contact_rates::verify::quantity::glossary(
                        &contact_rates::verify::quantity::Quantity::ALL
                    )
                );
            } else if headline {
                print!("{}", contact_rates::results::headline(&reports)?);
            } else {
                print!("{}", contact_rates::results::section(&reports)?);
            }
            Ok(())
        }
        Command::Scene {
            action: SceneAction::List,
        } => {
            for (name, description) in contact_rates::scene::builtin_list()? {
                println!("{name:20} {description}");
            }
            Ok(())
        }
        Command::Solve(args) => solve_one(&args.request()?),
        Command::Grade(args) => grade(args),
        Command::Codes { grades, out } => {
            contact_rates::external::codes::codes_report(&grades, &out)?;
            println!("wrote {}", out.display());
            Ok(())
        }
        Command::Judge {
            file,
            threshold,
            method,
            quantity,
            out,
        } => judge(
            judge_file::JudgeRequest {
                file,
                threshold,
                method,
                quantity,
            },
            out,
        ),
        Command::Export {
            source,
            levels,
            out,
        } => {
            let levels = export::parse_levels(&levels).map_err(anyhow::Error::msg)?;
            let done = export::export(&source.source(), &levels, &out)?;
            for (level, h, nodes, triangles) in &done.levels {
                println!("level {level}: h = {h:.6}, {nodes} nodes, {triangles} triangles");
            }
            println!("wrote {} files to {}", done.files, out.display());
            Ok(())
        }
    }
}

/// `study NAME`: check the report folder, run, write the report, print its summary; an
/// error when a threshold is missed.
fn study(
    name: &str,
    out: Option<PathBuf>,
    publish: bool,
    shard: Option<&str>,
    merge: bool,
    rejudge: bool,
) -> anyhow::Result<()> {
    if name == "list" {
        // The run time of the committed report, where it records one (run.toml).
        let times = contact_rates::results::wall_times(&report::reports_dir()).unwrap_or_default();
        let studies = Study::list();
        let width = studies.iter().map(|s| s.0.len()).max().unwrap_or(5);
        println!("{:width$} {:>9}  what it measures", "study", "run time");
        for (n, d) in studies {
            let time = times
                .iter()
                .find(|t| t.0 == n)
                .map_or("-".to_string(), |t| format!("{:.0} s", t.1));
            println!("{n:width$} {time:>9}  {d}");
        }
        println!(
            "(run time: the committed report's, on 2 cores, after the build; - where its report records none)"
        );
        return Ok(());
    }
    let kind = Study::resolve(name)?;
    let mode = match (shard, merge) {
        (Some(sh), _) => Mode::shard(sh)?,
        (None, true) => Mode::Merge,
        (None, false) => Mode::All,
    };
    let dir = match (publish, out) {
        (true, _) => report::reports_dir().join(kind.name()),
        (false, Some(dir)) => dir,
        (false, None) => report::scratch_reports_dir().join(kind.name()),
    };
    // The report folder is checked before any computing (a shard writes no report).
    if shard.is_none() {
        for n in report::check_writable(&dir, Output::Report)? {
            eprintln!("note: {n}");
        }
    }
    let outcome = match rejudge {
        true => kind.rejudge(&dir)?,
        false => match kind.run(mode)? {
            Some(outcome) => outcome,
            None => return Ok(()),
        },
    };
    for w in outcome.warnings() {
        eprintln!("warning: {w}");
    }
    let phase = contact_rates::progress::Progress::phase(
        &kind.name(),
        &format!("writing the report (tables, plots) to {}", dir.display()),
    );
    outcome.write(&dir)?;
    drop(phase);
    print!("{}", outcome.console(&dir));
    for u in outcome.unverified() {
        println!("unverified: {u}");
    }
    let failures = outcome.failures();
    if !failures.is_empty() {
        anyhow::bail!("rate below threshold: {}", failures.join("; "));
    }
    Ok(())
}

/// `judge FILE.csv`: every group judged, printed, written where asked; an error only where
/// a threshold fails (an unverified one is printed).
fn judge(req: judge_file::JudgeRequest, out: Option<PathBuf>) -> anyhow::Result<()> {
    if let Some(dir) = &out {
        for n in report::check_writable(dir, Output::Report)? {
            eprintln!("note: {n}");
        }
    }
    let groups = judge_file::judge_file(&req)?;
    print!("{}", judge_file::console(&groups));
    if let Some(dir) = &out {
        judge_file::write_report(&groups, &req.file, dir)?;
        println!("wrote {}", dir.display());
    }
    let failed: Vec<String> = groups
        .iter()
        .filter(|g| g.outcome == Some(contact_rates::verify::rates::Outcome::Fail))
        .map(judge_file::group_name)
        .collect();
    if !failed.is_empty() {
        anyhow::bail!(
            "threshold missed ({}): the line above says by how much",
            failed.join(", ")
        );
    }
    Ok(())
}

/// `grade`: check the report folder, measure, write the report; an error when the
/// threshold is missed.
fn grade(args: GradeArgs) -> anyhow::Result<()> {
    let levels = match &args.levels {
        Some(l) => Some(export::parse_levels(l).map_err(anyhow::Error::msg)?),
        None => None,
    };
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| report::reports_dir().join(format!("grade-{}", args.name)));
    for n in report::check_writable(&dir, Output::Report)? {
        eprintln!("note: {n}");
    }
    let graded = grade::grade(&grade::GradeRequest {
        source: args.source.source(),
        solutions: args.solutions,
        levels,
        name: args.name,
        threshold: args.threshold,
        names: FieldNames {
            displacement: args.displacement,
            stress: args.stress,
            pressure: args.pressure,
        },
        compare: !args.no_compare,
    })?;
    graded.write(&dir)?;
    print!("{}", graded.console(&dir));
    for u in &graded.unverified {
        println!("unverified: {u}");
    }
    if !graded.failures.is_empty() {
        anyhow::bail!("{}", graded.failures.join("; "));
    }
    Ok(())
}

impl SolveArgs {
    /// The checked request: the cone, the solver and its settings parsed.
    fn request(self) -> anyhow::Result<SolveRequest> {
        let method = Method::parse(&self.method).with_context(|| {
            format!(
                "--method: unknown cone '{}'; use mortar (K_h^pi), nts (K_h^I) or lac (local average contact)",
                self.method
            )
        })?;
        let kind = SolverKind::parse(&self.solver).with_context(|| {
            format!(
                "--solver: unknown solver '{}'; use newton, paper or qp",
                self.solver
            )
        })?;
        if !(self.tol > 0.0) {
            anyhow::bail!("--tol: the tolerance must be positive, got {}", self.tol);
        }
        let settings = Settings {
            kind,
            tol: self.tol,
            omega: self.omega,
            rho: self.rho,
            ..Settings::default()
        };
        Ok(SolveRequest {
            scene: self.scene,
            method,
            settings,
            level: self.level,
            steps: self.steps,
            out: self.out,
            params: parse_sets(&self.set)?,
            floor: self.floor,
            every: self.every,
        })
    }
}

/// What `solve` was asked to do.
struct SolveRequest {
    scene: String,
    method: Method,
    settings: Settings,
    level: usize,
    steps: Option<usize>,
    out: PathBuf,
    params: Vec<(String, f64)>,
    /// Measure the floor too.
    floor: bool,
    /// Write every `every`-th step to the time series.
    every: usize,
}

/// `solve`: one scene on one level with one cone and solver: the time series, contact.csv,
/// solution.vtu and summary.csv.
fn solve_one(req: &SolveRequest) -> anyhow::Result<()> {
    let scene = Scene::load(&req.scene)?;
    let steps = req.steps.unwrap_or(scene.steps);
    if steps == 0 {
        anyhow::bail!("--steps: the number of time steps must be at least 1");
    }
    if req.every == 0 {
        anyhow::bail!("--every: write every K-th step with K >= 1, got 0");
    }
    // The output folder is checked before any computing; the run writes into a staging
    // folder that replaces it only at the end (dropped on any error).
    let (staging, notes) = Staging::begin(&req.out, Output::Solve)?;
    for n in notes {
        eprintln!("note: {n}");
    }
    let t0 = std::time::Instant::now();
    let case = Case::build(&scene, req.level, req.method, &req.params)?;
    for w in &case.warnings {
        eprintln!("warning: {w}");
    }
    let mut series = report::solve_output::Series::new(staging.path(), &case.problem, req.every);
    let progress = Progress::new(steps as u64, "solve", "time step");
    let memory = PeakMemory::start();
    let solved = series.write_during(|on_step| {
        solve::solve_observed(
            &case.problem,
            &req.settings,
            steps,
            &mut |n, total, state, step| {
                progress.tick(&format!(
                    "step {n} of {total}: {} iterations",
                    step.iterations
                ));
                on_step(n, total, state)
            },
        )
    });
    progress.finish();
    let peak = memory.peak_gib();
    let sol = solved?;
    let floor_s = match req.floor {
        true => {
            // Cold, as the solve was (see PeakMemory::start).
            contact_rates::case::release_free_heap();
            Some(solve::floor_time(&case.problem, steps)?)
        }
        false => None,
    };
    let run = RunSummary::new(&case, req.settings.kind, &sol, floor_s, peak);
    let wall_s = t0.elapsed().as_secs_f64();
    let written = series.finish(&run, wall_s)?;
    staging.commit()?;
    print!(
        "{}",
        report::solve_output::console(&run, wall_s, &written, &req.out)
    );
    Ok(())
}

/// On SIGINT, SIGTERM or SIGHUP (those not ignored at the start): remove the run's staging
/// folders and exit with 128 + the signal's number, the status a shell gives a process that
/// signal ended (130, 143, 129).
fn exit_cleanly_on_signals() -> std::io::Result<()> {
    let mut signals = Signals::new(contact_rates::interrupt::catchable())?;
    std::thread::spawn(move || {
        if let Some(signo) = signals.forever().next() {
            let interrupted = report::remove_live();
            let meshes = contact_rates::interrupt::remove_temporary_files();
            let name = signal_name(signo).unwrap_or("a signal");
            contact_rates::progress::clear_line();
            let during = contact_rates::progress::current_phase()
                .map_or(String::new(), |p| format!(" while {p}"));
            let gmsh = match meshes {
                0 => String::new(),
                n => format!(
                    "gmsh ended and {} removed from the mesh cache; ",
                    match n {
                        1 => "its unfinished mesh".to_string(),
                        n => format!("{n} unfinished meshes"),
                    }
                ),
            };
            let removed = match interrupted.removed.is_empty() {
                true => format!("{gmsh}no output was written or changed"),
                false => {
                    let folders: Vec<String> = interrupted
                        .removed
                        .iter()
                        .map(|f| f.display().to_string())
                        .collect();
                    format!(
                        "{gmsh}removed its unfinished output {}; what was there before is unchanged",
                        folders.join(", ")
                    )
                }
            };
            // Not eprintln: after SIGHUP the terminal may be gone, and a panic here would
            // leave the run going.
            let _ = writeln!(
                std::io::stderr(),
                "interrupted by {name}{during}: {removed}"
            );
            std::process::exit(128 + signo);
        }
    });
    Ok(())
}

fn main() {
    if let Err(e) = exit_cleanly_on_signals() {
        eprintln!(
            "warning: cannot catch SIGINT, SIGTERM and SIGHUP ({e}); an interrupted run leaves its staging folder, which the next run removes"
        );
    }
    if let Err(e) = contact_rates::on_pool(run) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
