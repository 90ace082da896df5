//! The output of `solve`: the time series (solution_NNNN.vtu and solution.pvd), contact.csv,
//! solution.vtu (the last step), summary.csv, and the lines printed on the console.

use crate::case::RunSummary;
use crate::contact::Method;
use crate::error::Result;
use crate::io::{self, csv_bytes, write_atomic};
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
}

/// One row of contact.csv: a slave node of Gamma_C at a written time step.
#[derive(Serialize)]
struct ContactCsv {
    /// Time.
    time: f64,
    /// Piece of Gamma_C (from 0).
    piece: usize,
    /// Arc length along the piece from its start (length).
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

/// The time series of a `solve` run, written as the steps come: every `every`-th step and
/// the last as `solution_NNNN.vtu` (the last also as solution.vtu) with its rows of
/// contact.csv. [`Series::finish`] writes the collection `solution.pvd`, contact.csv and
/// summary.csv; [`Series::abandon`] removes the step files of a run that failed.
pub struct Series<'a> {
    dir: &'a Path,
    problem: &'a Problem,
    every: usize,
    written: Vec<(f64, String)>,
    contact: Vec<ContactCsv>,
    last_contact: Vec<ContactNode>,
}

impl<'a> Series<'a> {
    /// A series of `problem`'s steps into `dir`, every `every`-th step (>= 1).
    pub fn new(dir: &'a Path, problem: &'a Problem, every: usize) -> Self {
        Series {
            dir,
            problem,
            every: every.max(1),
            written: Vec::new(),
            contact: Vec::new(),
            last_contact: Vec::new(),
        }
    }

    /// Write step `n` of `steps` when it is due (the last one also as solution.vtu).
    pub fn step(&mut self, n: usize, steps: usize, state: &State) -> Result<()> {
        if n % self.every != 0 && n != steps {
            return Ok(());
        }
        let nodes = contact_nodes(self.problem, state);
        let name = format!("solution_{n:04}.vtu");
        let vtu = io::vtu(&self.problem.model, state, &nodes);
        write_atomic(&self.dir.join(&name), vtu.as_bytes())?;
        if n == steps {
            write_atomic(&self.dir.join("solution.vtu"), vtu.as_bytes())?;
        }
        self.written.push((state.time, name));
        self.contact.extend(nodes.iter().map(|c| ContactCsv {
            time: state.time,
            piece: c.piece,
            arc_length: c.arc_length,
            x: c.position[0],
            y: c.position[1],
            pressure: c.pressure,
            normal_jump: c.normal_jump,
            active: c.active,
        }));
        self.last_contact = nodes;
        Ok(())
    }

    /// Write solution.pvd, contact.csv and summary.csv; `wall_s` is the whole run's wall
    /// time.
    pub fn finish(self, run: &RunSummary, wall_s: f64) -> Result<()> {
        write_atomic(
            &self.dir.join("solution.pvd"),
            io::pvd(&self.written).as_bytes(),
        )?;
        write_atomic(&self.dir.join("contact.csv"), &csv_bytes(&self.contact)?)?;
        write_summary(self.dir, run, wall_s)
    }

    /// Remove the step files written so far (the run failed).
    pub fn abandon(self) {
        for (_, name) in &self.written {
            let _ = std::fs::remove_file(self.dir.join(name));
        }
    }
}

/// Write `dir/summary.csv`; `wall_s` is the whole run's wall time.
fn write_summary(dir: &Path, run: &RunSummary, wall_s: f64) -> Result<()> {
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
    };
    write_atomic(&dir.join("summary.csv"), &csv_bytes(&[row])?)
}

/// What `solve` prints: the run, its cost split, and where the files went.
pub fn console(run: &RunSummary, wall_s: f64, dir: &Path) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{} {} {} level {}: h = {:.4}, {} dofs, {} steps, {} iterations (max {} per step), {:.3} s; max penetration {:.3e}, contact fraction {:.3}, plastic fraction {:.3}",
        run.scene,
        run.method,
        run.solver,
        run.level,
        run.h,
        run.dofs,
        run.steps,
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
        "  mesh {:.3} s, model {:.3} s, solver set-up (pattern, symbolic) {:.3} s; time loop {:.3} s{floor}: {} factorizations {:.3} s, solves {:.3} s, assembly {:.3} s, constitutive {:.3} s, contact {:.3} s; {} active-set changes; peak RSS {} GiB",
        run.mesh_s,
        run.model_s,
        t.setup_s,
        run.time_loop_s,
        t.factorizations,
        t.factor_s,
        t.solve_s,
        t.assembly_s,
        t.constitutive_s,
        t.contact_s,
        run.active_set_changes,
        run.peak_rss_gib
            .map(|g| format!("{g:.1}"))
            .unwrap_or_default()
    );
    let _ = writeln!(
        s,
        "wrote {} and {}",
        dir.join("solution.vtu").display(),
        dir.join("summary.csv").display()
    );
    s
}
