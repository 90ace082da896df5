//! The report of `study stability`: stability.csv, the sweep plots, one section per hard
//! case with its note and table, and the lines printed on the console.

use crate::contact::Method;
use crate::error::Result;
use crate::io::csv_bytes;
use crate::report::folder::{write, write_folder};
use crate::report::markdown::{Doc, Table};
use crate::report::plot::{self, Series};
use crate::solve::SolverKind;
use crate::studies::stability::{HardCase, StabilityResult, StabilityRow};
use std::fmt::Write as _;
use std::path::Path;
use crate::verify::kind::Outcome;

/// Write the report of `study stability`.
pub fn write_stability(res: &StabilityResult, dir: &Path) -> Result<()> {
    write_folder(dir, |d| {
        write(d, "stability.csv", &csv_bytes(&res.rows)?)?;
        sweep_plots(res, d)?;
        write(d, "README.md", readme(res, d).as_bytes())
    })
}

/// Iterations and difference to newton against each swept parameter (the reference method).
fn sweep_plots(res: &StabilityResult, d: &Path) -> Result<()> {
    for case in HardCase::SWEEPS {
        let sweep = case.sweep().expect("a swept case");
        let (name, file) = (case.name(), sweep.file);
        let rows: Vec<_> = res
            .rows
            .iter()
            .filter(|r| r.case == case && r.method.is_reference())
            .collect();
        let mut its = Vec::new();
        let mut errs = Vec::new();
        for (i, so) in [SolverKind::Newton, SolverKind::Paper, SolverKind::Qp]
            .iter()
            .enumerate()
        {
            let pts: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.solver == *so && r.converged)
                .map(|r| (r.value, r.mean_step_iterations.max(1e-3)))
                .collect();
            if !pts.is_empty() {
                its.push(Series {
                    label: format!("{so} (converged runs)"),
                    points: pts,
                    markers: true,
                    line: true,
                    color: i,
                    thin: false,
                    shape: None,
                });
            }
            let pe: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.solver == *so && r.converged && r.error > 0.0)
                .map(|r| (r.value, r.error))
                .collect();
            if !pe.is_empty() {
                errs.push(Series {
                    label: format!("{so}: difference to newton"),
                    points: pe,
                    markers: true,
                    line: true,
                    color: i,
                    thin: false,
                    shape: None,
                });
            }
        }
        let xlabel = sweep.axis;
        plot::loglog(
            &d.join(format!("{file}_iterations.png")),
            &format!("{name}: mean iterations per step (mortar)"),
            xlabel,
            "iterations per step",
            &its,
            &[],
        )?;
        if !errs.is_empty() {
            plot::loglog(
                &d.join(format!("{file}_error.png")),
                &format!("{name}: difference to newton (mortar)"),
                xlabel,
                "relative nodal difference",
                &errs,
                &[],
            )?;
        }
    }
    Ok(())
}

/// The README: one section per case with its note, plots and table.
fn readme(res: &StabilityResult, d: &Path) -> String {
    let mut doc = Doc::new();
    doc.heading(1, "Study `stability`").paragraph(format!(
        "Hard cases, each run with every solver and every method: mortar, nts and lac (level 1 of the `rates` scene with 4 steps unless stated). A failure is a result: `converged = no` with the solver's reason. `error` is the largest nodal difference to newton's solution of the same discrete problem, relative to the largest displacement. Regenerate with `cargo run --release -- study stability` ({:.0} s).",
        res.wall_s
    ));
    newton_by_method(&mut doc, res);
    let mut cases: Vec<HardCase> = Vec::new();
    for r in &res.rows {
        if !cases.contains(&r.case) {
            cases.push(r.case);
        }
    }
    for case in cases {
        hard_case(&mut doc, res, case, d);
    }
    doc.finish()
}

/// The lead: newton on every hard case, method by method: runs, failures (named) and the
/// most iterations in a step.
fn newton_by_method(doc: &mut Doc, res: &StabilityResult) {
    let mut table = Table::new([
        "method",
        "newton runs",
        "converged",
        "most iterations in a step",
        "in",
        "mean iterations per step (largest over the runs)",
        "did not converge",
    ]);
    for m in Method::ALL {
        let runs: Vec<_> = res
            .rows
            .iter()
            .filter(|r| r.method == m && r.solver == SolverKind::Newton)
            .collect();
        if runs.is_empty() {
            continue;
        }
        let ok: Vec<_> = runs.iter().filter(|r| r.converged).collect();
        let failed: Vec<String> = runs
            .iter()
            .filter(|r| !r.converged)
            .map(|r| format!("{} ({})", r.case.name(), r.parameter))
            .collect();
        table.row([
            m.to_string(),
            runs.len().to_string(),
            ok.len().to_string(),
            ok.iter().map(|r| r.max_step_iterations).max().unwrap_or(0).to_string(),
            ok.iter()
                .max_by_key(|r| r.max_step_iterations)
                .map_or(String::new(), |r| format!("{} ({})", r.case.name(), r.parameter)),
            format!("{:.1}", ok.iter().map(|r| r.mean_step_iterations).fold(0.0, f64::max)),
            if failed.is_empty() { "none".into() } else { failed.join(", ") },
        ]);
    }
    doc.heading(2, "Newton on every hard case, by method").table(&table);
    limit_load(doc, res);
}

/// ## One hard case: its note, its sweep's plots (those written into `d`) and its runs.
fn hard_case(doc: &mut Doc, res: &StabilityResult, case: HardCase, d: &Path) {
    doc.heading(2, case.name());
    if !case.note().is_empty() {
        doc.paragraph(case.note());
    }
    if let Some(sweep) = case.sweep() {
        let file = sweep.file;
        doc.image("iterations", &format!("{file}_iterations.png"));
        if d.join(format!("{file}_error.png")).exists() {
            doc.image("error", &format!("{file}_error.png"));
        }
    }
    overloaded(doc, res, case);
    let mut table = Table::new([
        "parameter",
        "method",
        "solver",
        "converged",
        "max / mean iterations per step",
        "error",
        "max penetration (over max |u|)",
        "wall (s)",
        "reason",
    ]);
    let finite = |v: f64| {
        if v.is_finite() {
            format!("{v:.2e}")
        } else {
            String::new()
        }
    };
    for r in res.rows.iter().filter(|r| r.case == case) {
        table.row([
            r.parameter.clone(),
            r.method.to_string(),
            r.solver.to_string(),
            if r.converged { "yes" } else { "**no**" }.to_string(),
            format!("{} / {:.1}", r.max_step_iterations, r.mean_step_iterations),
            finite(r.error),
            match (r.max_penetration.is_finite(), r.max_displacement > 0.0) {
                (true, true) => format!("{} ({:.2e})", finite(r.max_penetration), r.max_penetration / r.max_displacement),
                _ => finite(r.max_penetration),
            },
            format!("{:.3}", r.wall_s),
            r.reason.replace('|', "/"),
        ]);
    }
    doc.table(&table);
}

/// The limit-load check over the cases, once: the cases whose load is past the limit load
/// (the check's ratio above 1), where Perzyna's flow never relaxes and the runs measure a
/// flow bounded only by the final time and the viscosity, not an equilibrium.
fn limit_load(doc: &mut Doc, res: &StabilityResult) {
    let mut over: Vec<(HardCase, f64)> = Vec::new();
    for r in res.rows.iter().filter(|r| r.limit_load_ratio > 1.0) {
        match over.iter_mut().find(|(c, _)| *c == r.case) {
            Some((_, w)) => *w = w.max(r.limit_load_ratio),
            None => over.push((r.case, r.limit_load_ratio)),
        }
    }
    if over.is_empty() {
        return;
    }
    let cases: Vec<String> = over.iter().map(|(c, w)| format!("{} ({w:.2})", c.name())).collect();
    let total = HardCase::ALL.iter().filter(|c| res.rows.iter().any(|r| r.case == **c)).count();
    doc.paragraph(format!(
        "**Loaded past the limit load** in {} of {total} cases: {}. The limit-load check (in brackets): the least plane-stress von Mises stress of any stress state that carries the given traction at a point of its edge, sqrt(3/4 t_n^2 + 3 t_t^2), over the yield stress, at the final time; above 1 no stress field inside the yield surface carries the load, the rate-independent problem has no solution, and Perzyna's flow never relaxes (the plastic strain grows like t / lambda). The rates scene's traction, 10 t (0.1 + cos(pi x)) at x = 0, does this from t = 0.33 on. Such a run measures a flow bounded only by the final time and the viscosity: where a case's sweep speeds the flow up, its displacements and penetrations grow with it (its section says by how much).",
        over.len(),
        cases.join(", ")
    ));
}

/// A case loaded past its limit load whose sweep shows the flow: newton's largest
/// displacement by parameter, where it spreads by more than 10x over the case's runs.
fn overloaded(doc: &mut Doc, res: &StabilityResult, case: HardCase) {
    let rows: Vec<&StabilityRow> = res.rows.iter().filter(|r| r.case == case).collect();
    if !rows.iter().any(|r| r.limit_load_ratio > 1.0) {
        return;
    }
    let newton = |m: Method| -> Vec<&&StabilityRow> {
        rows.iter()
            .filter(|r| r.method == m && r.solver == SolverKind::Newton && r.max_displacement.is_finite())
            .collect()
    };
    let spread = Method::ALL
        .iter()
        .flat_map(|&m| newton(m))
        .map(|r| r.max_displacement)
        .fold((f64::INFINITY, 0.0f64), |(a, b), u| (a.min(u), b.max(u)));
    if spread.1 <= 10.0 * spread.0 {
        return;
    }
    let growth: Vec<String> = Method::ALL
        .iter()
        .map(|&m| {
            let u: Vec<String> = newton(m)
                .iter()
                .map(|r| format!("{:.2e} ({:.1e} penetration)", r.max_displacement, r.max_penetration))
                .collect();
            format!("{m} {}", u.join(", "))
        })
        .collect();
    doc.paragraph(format!(
        "Past the limit load (see the top of this report), the flow shows here: newton's largest displacement max |u_i|, and its largest penetration, by parameter in the table's order: {}.",
        growth.join("; ")
    ));
}

/// What `study stability` prints: one line per run, and where the report went.
pub fn console(res: &StabilityResult, dir: &Path) -> String {
    let mut s = String::new();
    for r in &res.rows {
        let _ = writeln!(
            s,
            "{:26} {:36} {:7} {:7} converged {:5} iterations max {:3} mean {:6.1} error {:9} {:.2} s{}",
            r.case.name(),
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
    let _ = writeln!(s, "wrote {} ({:.1} s)", dir.display(), res.wall_s);
    s
}

/// The kind's outcome writes this report.
impl Outcome for StabilityResult {
    fn write(&self, dir: &Path) -> Result<()> {
        write_stability(self, dir)
    }
    fn console(&self, dir: &Path) -> String {
        console(self, dir)
    }
}
