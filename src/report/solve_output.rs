//! The output of `solve`: the time series (solution_NNNN.vtu and solution.pvd), contact.csv,
//! solution.vtu (the last step), summary.csv, and the lines printed on the console. The
//! files go into a staging folder (see [`super::folder::Staging`]) that replaces the output
//! folder once the run has succeeded.

use super::folder::write;
use crate::case::RunSummary;
use crate::contact::Method;
use crate::error::Result;
use crate::io::{self, csv_bytes};
use crate::metrics::{ContactNode, contact_nodes};
use crate::solve::{Problem, SolverKind, State};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;

/// The one row of summary.csv.
#[derive(Serialize)]
struct SummaryCsv<'a> {
    scene: &'a str,
    method: Method,
    solver: SolverKind,
    level: usize,
    h: f64,
    dofs: usize,
    steps: usize,
    iterations: usize,
    max_step_iterations: usize,
    /// Everything `solve` did, from reading the scene's mesh to the floor (s).
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
    floor_s: Option<f64>,
    ratio_to_floor: Option<f64>,
    /// Building, compressing and writing the step files, on a second thread unless the
    /// run has one (s).
    output_s: f64,
    /// Of that, the time the solve waited for it (s), part of `wall_s`.
    output_wait_s: f64,
    /// Size of the step files (MB = 1e6 bytes; solution.vtu is the last one's second name).
    output_mb: f64,
}

/// One row of contact.csv: a slave node of Gamma_C at a written time step.
#[derive(Serialize)]
struct ContactCsv {
    /// Time.
    time: f64,
    /// Piece of Gamma_C (from 0).
    piece: usize,
    /// Arc length along the piece from its end of smaller x (of smaller y where x is the
    /// same) (length): a plot against it reads left to right whichever way body 1's
    /// boundary runs.
    arc_length: f64,
    x: f64,
    y: f64,
    /// Contact pressure (force/length).
    pressure: f64,
    /// Normal jump [u.nu] (length; > 0 interpenetration, < 0 apart).
    normal_jump: f64,
    /// Whether the node's constraint holds as an equality.
    active: bool,
}

/// One piece's nodes from its end of smaller x (smaller y where x is the same), each with
/// its distance along the piece from that end (a piece is straight, so the distance is the
/// arc length).
fn reading_order(piece: &[ContactNode]) -> Vec<(f64, &ContactNode)> {
    let key = |c: &ContactNode| (c.position[0], c.position[1]);
    let Some(start) = piece
        .iter()
        .min_by(|a, b| key(a).partial_cmp(&key(b)).unwrap())
    else {
        return Vec::new();
    };
    let distance = |c: &ContactNode| {
        (c.position[0] - start.position[0]).hypot(c.position[1] - start.position[1])
    };
    let mut out: Vec<(f64, &ContactNode)> = piece.iter().map(|c| (distance(c), c)).collect();
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    out
}

/// The time series of a `solve` run: every `every`-th step and the last as
/// `solution_NNNN.vtu` (the last also as solution.vtu) with its rows of contact.csv.
/// [`Series::write_during`] runs the solve and writes the step files on a second thread, so
/// compressing one step overlaps solving the next; [`Series::finish`] then writes the
/// collection `solution.pvd`, contact.csv and summary.csv.
pub struct Series<'a> {
    dir: &'a Path,
    problem: &'a Problem,
    every: usize,
    written: Vec<(f64, String)>,
    contact: Vec<ContactCsv>,
    output: Written,
}

/// What a series wrote: step files, their bytes and the time it took.
#[derive(Debug, Clone, Copy, Default)]
pub struct Written {
    /// Step files (solution_NNNN.vtu).
    pub files: usize,
    /// Their size (bytes).
    pub bytes: u64,
    /// Building, compressing and writing them (s).
    pub seconds: f64,
    /// Of that, the time the solve waited for the writer (s): the part of the run's wall
    /// time the output costs.
    pub waited_s: f64,
    /// Written on the solve's own thread (a run of one thread) rather than a writer thread.
    pub on_solve_thread: bool,
}

/// A step for the writer thread: the file name, whether it is the last step, the state and
/// its contact nodes.
type StepFile = (String, bool, State, Vec<ContactNode>);

impl<'a> Series<'a> {
    /// A series of `problem`'s steps into `dir`, every `every`-th step (>= 1).
    pub fn new(dir: &'a Path, problem: &'a Problem, every: usize) -> Self {
        Series {
            dir,
            problem,
            every: every.max(1),
            written: Vec::new(),
            contact: Vec::new(),
            output: Written::default(),
        }
    }

    /// Run `solve`, giving it the observer that hands each due step to a writer thread (at
    /// most one step waits; the solve blocks when the writer falls behind). The writer
    /// compresses on one core, the solve goes on on the other. With one thread
    /// (`RAYON_NUM_THREADS=1`, rayon's convention for the thread count, which the whole run
    /// honours) the steps are written in turn on the solve's own thread. An error of either
    /// stops both and is returned (the writer's first).
    pub fn write_during<T>(
        &mut self,
        solve: impl FnOnce(&mut dyn FnMut(usize, usize, &State) -> Result<()>) -> Result<T>,
    ) -> Result<T> {
        let (dir, model) = (self.dir, &self.problem.model);
        // Build, compress and write one step file (and solution.vtu for the last); its bytes.
        let write_step = |vtu: &mut Option<io::vtu::StateFile>, step: StepFile| -> Result<u64> {
            let (name, last, state, nodes) = step;
            let file = vtu
                .get_or_insert_with(|| io::vtu::StateFile::new(model))
                .file(&state, &nodes);
            write(dir, &name, &file)?;
            if last {
                // The last step again, as a second name of the same file (a copy where the
                // file system has no hard links).
                let (step, last) = (dir.join(&name), dir.join("solution.vtu"));
                if std::fs::hard_link(&step, &last).is_err() {
                    write(dir, "solution.vtu", &file)?;
                }
            }
            Ok(file.len() as u64)
        };
        if rayon::current_num_threads() == 1 {
            let (mut vtu, mut bytes, mut seconds) = (None, 0u64, 0.0);
            let solved = solve(&mut |n, steps, state| {
                if let Some(step) = self.due(n, steps, state) {
                    let t0 = std::time::Instant::now();
                    bytes += write_step(&mut vtu, step)?;
                    seconds += t0.elapsed().as_secs_f64();
                }
                Ok(())
            })?;
            self.output = Written {
                files: self.written.len(),
                bytes,
                seconds,
                waited_s: seconds,
                on_solve_thread: true,
            };
            return Ok(solved);
        }
        std::thread::scope(|scope| {
            let (send, receive) = std::sync::mpsc::sync_channel::<StepFile>(1);
            let writer = scope.spawn(move || -> Result<(u64, f64)> {
                let (mut bytes, mut seconds) = (0u64, 0.0);
                let mut vtu: Option<io::vtu::StateFile> = None;
                for step in receive {
                    let t0 = std::time::Instant::now();
                    bytes += write_step(&mut vtu, step)?;
                    seconds += t0.elapsed().as_secs_f64();
                }
                Ok((bytes, seconds))
            });
            let mut waited_s = 0.0;
            let solved = solve(&mut |n, steps, state| {
                let Some(step) = self.due(n, steps, state) else {
                    return Ok(());
                };
                let t0 = std::time::Instant::now();
                let sent = send.send(step);
                waited_s += t0.elapsed().as_secs_f64();
                // A closed channel means the writer failed: its error is returned below.
                sent.map_err(|_| {
                    crate::Error::io(dir, std::io::Error::other("the VTU writer stopped"))
                })
            });
            drop(send);
            let t0 = std::time::Instant::now();
            let wrote = writer.join().expect("the VTU writer thread panicked");
            waited_s += t0.elapsed().as_secs_f64();
            let (bytes, seconds) = wrote?;
            self.output = Written {
                files: self.written.len(),
                bytes,
                seconds,
                waited_s,
                on_solve_thread: false,
            };
            solved
        })
    }

    /// Step `n` of `steps` as a file to write, recorded, when it is due (every `every`-th
    /// and the last).
    fn due(&mut self, n: usize, steps: usize, state: &State) -> Option<StepFile> {
        if !n.is_multiple_of(self.every) && n != steps {
            return None;
        }
        let nodes = contact_nodes(self.problem, state);
        let name = format!("solution_{n:04}.vtu");
        self.record(state.time, &nodes, name.clone());
        Some((name, n == steps, state.clone(), nodes))
    }

    /// Record a written step: its time and file, and its contact rows, each piece's in
    /// reading order ([`reading_order`]).
    fn record(&mut self, time: f64, nodes: &[ContactNode], file: String) {
        self.written.push((time, file));
        for piece in nodes.chunk_by(|a, b| a.piece == b.piece) {
            self.contact
                .extend(
                    reading_order(piece)
                        .into_iter()
                        .map(|(arc_length, c)| ContactCsv {
                            time,
                            piece: c.piece,
                            arc_length,
                            x: c.position[0],
                            y: c.position[1],
                            pressure: c.pressure,
                            normal_jump: c.normal_jump,
                            active: c.active,
                        }),
                );
        }
    }

    /// Write solution.pvd, contact.csv and summary.csv; `wall_s` is the whole run's wall
    /// time.
    pub fn finish(self, run: &RunSummary, wall_s: f64) -> Result<Written> {
        write(self.dir, "solution.pvd", io::pvd(&self.written).as_bytes())?;
        write(self.dir, "contact.csv", &csv_bytes(&self.contact)?)?;
        write_summary(self.dir, run, wall_s, &self.output)?;
        Ok(self.output)
    }
}

/// Write `dir/summary.csv`; `wall_s` is the whole run's wall time.
fn write_summary(dir: &Path, run: &RunSummary, wall_s: f64, output: &Written) -> Result<()> {
    let t = &run.timings;
    let row = SummaryCsv {
        scene: &run.scene,
        method: run.method,
        solver: run.solver,
        level: run.level,
        h: run.h,
        dofs: run.dofs,
        steps: run.steps,
        iterations: run.iterations,
        max_step_iterations: run.max_step_iterations,
        wall_s,
        max_penetration: run.max_penetration,
        contact_fraction: run.contact_fraction,
        plastic_fraction: run.plastic_fraction,
        converged: true,
        mesh_s: run.mesh_s,
        assembly_s: t.assembly_s,
        factor_s: t.factor_s,
        solve_s: t.solve_s,
        constitutive_s: t.constitutive_s,
        contact_s: t.contact_s,
        factorizations: t.factorizations,
        active_set_changes: run.active_set_changes,
        time_loop_s: run.time_loop_s,
        solver_setup_s: t.setup_s,
        floor_s: run.floor_s,
        ratio_to_floor: run.ratio_to_floor(),
        output_s: output.seconds,
        output_wait_s: output.waited_s,
        output_mb: output.bytes as f64 / 1e6,
    };
    write(dir, "summary.csv", &csv_bytes(&[row])?)
}

/// What `solve` prints: the run, its cost split, and where the files went.
pub fn console(run: &RunSummary, wall_s: f64, written: &Written, dir: &Path) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{} {} {} level {}: h = {:.4}, {} dofs, {}, {} iterations (max {} per step), {:.3} s; max penetration {:.3e}, contact fraction {:.3}, plastic fraction {:.3}",
        run.scene,
        run.method,
        run.solver,
        run.level,
        run.h,
        run.dofs,
        crate::io::count(run.steps, "step"),
        run.iterations,
        run.max_step_iterations,
        wall_s,
        run.max_penetration,
        run.contact_fraction,
        run.plastic_fraction
    );
    let t = &run.timings;
    let floor = match (run.floor_s, run.ratio_to_floor()) {
        (Some(f), Some(r)) => format!(" (set-up + time loop = {r:.2} x the floor, {f:.3} s)"),
        _ => String::new(),
    };
    let _ = writeln!(
        s,
        "  mesh {:.3} s, model {:.3} s, solver set-up (pattern, symbolic) {:.3} s; time loop {:.3} s{floor}: {} {:.3} s, solves {:.3} s, assembly {:.3} s, constitutive {:.3} s, contact {:.3} s; {}; peak RSS {}",
        run.mesh_s,
        run.model_s,
        t.setup_s,
        run.time_loop_s,
        crate::io::count(t.factorizations, "factorization"),
        t.factor_s,
        t.solve_s,
        t.assembly_s,
        t.constitutive_s,
        t.contact_s,
        crate::io::count(run.active_set_changes, "active-set change"),
        run.peak_rss_gib
            .map_or("not measured".into(), crate::io::memory_text)
    );
    let _ = writeln!(
        s,
        "wrote {} ({:.1} MB, binary zlib VTU) in {:.3} s {}, {:.3} s of it waited for; {} and {}",
        crate::io::count(written.files, "step file"),
        written.bytes as f64 / 1e6,
        written.seconds,
        if written.on_solve_thread {
            "on the solve's thread (RAYON_NUM_THREADS=1)"
        } else {
            "on a second thread"
        },
        written.waited_s,
        dir.join("solution.pvd").display(),
        dir.join("summary.csv").display()
    );
    s
}
