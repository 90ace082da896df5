//! Reference: issues 61 (grade checks what it grades) and 73 (which rule refuses each).
//! Goal:
//! - this project's converged solves pass every check of `grade` at round-off: the
//!   equilibrium residual in energy, action and reaction on Gamma_C, no tangential and no
//!   pulling force, the pressure's resultant against the exact one's;
//! - a pressure of the wrong sign, or scaled by 1.1 or by 475, is refused with one message;
//! - a level that is no converged solution is set apart and gives no rate: a solve stopped
//!   early (steepest descent on the interior dofs, stopped where the theorem error is about
//!   15% above the converged one), and an active-set loop cut after its first active set
//!   (every slave row active: the contact is tied; the theorem error moves by 1.2% only, as
//!   the gap of the separated part is small, but the contact pulls there).
//!
//! Geometry: contact-mms (two elastic blocks, Gamma_C: y = 1; contact on [0, a), separation
//! on (a, 1]) on its own mesh family, levels 0-2.
//! Data: the scene's; 4 steps.

mod common;
#[path = "common/graded_series.rs"]
mod graded_series;

use contact_rates::case::Case;
use contact_rates::contact::Method;
use contact_rates::external::export::Source;
use contact_rates::external::grade::{GradeRequest, Graded, grade};
use contact_rates::fe::{FIXED, Model};
use contact_rates::io::solution::FieldNames;
use contact_rates::solve::linear::SparseSystem;
use contact_rates::solve::{Solution as Solved, SolverKind, State};
use contact_rates::verify::quantity::Quantity;
use contact_rates::verify::solve_case;
use graded_series::write_states;
use std::path::Path;

const STEPS: usize = 4;

fn request(dir: &Path) -> GradeRequest {
    GradeRequest {
        source: Source::Scene("contact-mms".into()),
        solutions: dir.to_path_buf(),
        levels: None,
        name: "outside".into(),
        threshold: None,
        names: FieldNames::default(),
        compare: false,
    }
}

/// Mortar's converged solves of levels 0-2.
fn converged() -> Vec<(Case, Solved)> {
    (0..=2)
        .map(|level| {
            let case = common::case("contact-mms", level, Method::Mortar, &[]);
            let (sol, _) = solve_case(&case, SolverKind::Newton, STEPS).unwrap();
            (case, sol)
        })
        .collect()
}

/// The solves written to a new folder, level `changed` as `states` instead.
fn folder(solves: &[(Case, Solved)], changed: Option<(usize, &[State])>) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for (level, (case, sol)) in solves.iter().enumerate() {
        let states = match changed {
            Some((l, s)) if l == level => s,
            _ => &sol.states[..],
        };
        write_states(dir.path(), level, case, states, |_| ());
    }
    dir
}

fn key_error(g: &Graded, level: usize) -> f64 {
    g.checks.iter().find(|c| c.level == level).unwrap().error
}

#[test]
fn converged_solves_pass_every_check_and_wrong_pressures_are_refused() {
    let solves = converged();
    let dir = folder(&solves, None);
    let g = grade(&request(dir.path())).unwrap();
    assert!(g.flagged.is_empty(), "{:?}", g.flagged);
    for c in &g.checks {
        println!("{c:?}");
        // Newton's tolerance: 3.2e-12 at level 2; the checks' round-off floor is 1e-10.
        assert!(c.residual <= 1e-10, "{c:?}");
        for v in [c.normal_imbalance, c.tangential, c.pulling] {
            assert!(v.unwrap() <= 1e-10, "{c:?}");
        }
        // The exact pressure's resultant by 8 Gauss points per slave segment across the
        // C^1 kink at a: 1e-5 at level 0.
        assert!((c.pressure_ratio.unwrap() - 1.0).abs() <= 1e-4, "{c:?}");
    }
    for (factor, words) in [
        (-1.0, "sign is flipped"),
        (1.1, "same factor"),
        (475.0, "same factor"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        for (level, (case, sol)) in solves.iter().enumerate() {
            write_states(dir.path(), level, case, &sol.states, |w| {
                w.pressure.iter_mut().for_each(|p| *p *= factor)
            });
        }
        let msg = match grade(&request(dir.path())) {
            Ok(_) => panic!("a pressure times {factor} was graded"),
            Err(e) => e.to_string(),
        };
        println!("x {factor}: {msg}");
        assert!(msg.contains(words) && msg.contains("pressure"), "{msg}");
    }
}

/// K v over the global dofs: the internal force of the elastic stress of `v`.
fn stiffness_times(model: &Model, v: &[f64]) -> Vec<f64> {
    model.internal_force(&model.elastic_stresses(v))
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Steepest descent on the interior dofs (neither a support's nor Gamma_C's, held at the
/// converged values), from the previous step's state, stopped at the first iterate whose
/// energy distance to the converged state is at most `share` of its energy: a solve
/// stopped early. Stresses are C eps(u) (elastic bodies).
fn stopped_early(case: &Case, sol: &Solved, share: f64) -> Vec<State> {
    let model = &case.problem.model;
    let mut on_gamma = vec![false; model.n_nodes];
    for p in &case.problem.interface.pieces {
        for &g in p.slave_nodes.iter().chain(&p.master_nodes) {
            on_gamma[g] = true;
        }
    }
    let interior: Vec<bool> = (0..2 * model.n_nodes)
        .map(|d| model.equation[d] != FIXED && !on_gamma[d / 2])
        .collect();
    let mut states = vec![sol.states[0].clone()];
    for n in 1..sol.states.len() {
        let target = &sol.states[n];
        let mut u: Vec<f64> = (0..target.u.len())
            .map(|d| match interior[d] {
                true => states[n - 1].u[d],
                false => target.u[d],
            })
            .collect();
        let load = model.load(target.time).unwrap();
        let energy = dot(&stiffness_times(model, &target.u), &target.u);
        for _ in 0..100_000 {
            let e: Vec<f64> = u.iter().zip(&target.u).map(|(a, b)| a - b).collect();
            if dot(&stiffness_times(model, &e), &e) <= share * share * energy {
                break;
            }
            let ku = stiffness_times(model, &u);
            let r: Vec<f64> = (0..u.len())
                .map(|d| if interior[d] { load[d] - ku[d] } else { 0.0 })
                .collect();
            let alpha = dot(&r, &r) / dot(&stiffness_times(model, &r), &r);
            u.iter_mut().zip(&r).for_each(|(x, y)| *x += alpha * y);
        }
        let sigma = model.elastic_stresses(&u);
        states.push(State {
            time: target.time,
            u,
            sigma,
            lambda: target.lambda.clone(),
        });
    }
    states
}

/// The primal-dual active set's first iterate from "every slave row active": the
/// saddle-point system [K C^T; C 0] with every constraint row an equality (the contact
/// tied), solved by LU at each step.
fn tied(case: &Case, sol: &Solved) -> Vec<State> {
    let p = &case.problem;
    let model = &p.model;
    let (n, rows) = (model.n_free, p.free_rows());
    let m = rows.len();
    let mut extra = Vec::new();
    for (k, row) in rows.iter().enumerate() {
        for &(eq, _) in row {
            extra.extend([(eq, n + k), (n + k, eq)]);
        }
        extra.push((n + k, n + k));
    }
    let (pattern, slots) = model.stiffness_pattern(&extra, n + m);
    let mut values = vec![0.0; pattern.nnz()];
    model.add_tangent(&model.elastic_tangents(), &slots, &mut values);
    for (k, row) in rows.iter().enumerate() {
        for &(eq, v) in row {
            values[pattern.slot(eq, n + k)] += v;
            values[pattern.slot(n + k, eq)] += v;
        }
    }
    let mut system = SparseSystem::with_values(pattern, values);
    system.factor_lu().unwrap();
    let mut states = vec![sol.states[0].clone()];
    for target in &sol.states[1..] {
        let mut x = model.restrict(&model.load(target.time).unwrap());
        x.resize(n + m, 0.0);
        system.solve(&mut x);
        let u = model.expand(&x[..n]);
        let sigma = model.elastic_stresses(&u);
        states.push(State {
            time: target.time,
            u,
            sigma,
            lambda: x[n..].to_vec(),
        });
    }
    states
}

#[test]
fn a_solve_stopped_early_and_a_cut_active_set_give_no_rate() {
    let solves = converged();
    let g = grade(&request(folder(&solves, None).path())).unwrap();
    let level = 1;
    // A discrete perturbation d of u_h is about energy-orthogonal to u - u_h, so the error
    // becomes sqrt(e^2 + d^2): d = 0.57 e moves it by about 15%.
    let share = 0.57 * key_error(&g, level);
    let cases: [(&str, Vec<State>); 2] = [
        (
            "stopped early",
            stopped_early(&solves[level].0, &solves[level].1, share),
        ),
        ("tied", tied(&solves[level].0, &solves[level].1)),
    ];
    for (what, states) in cases {
        let dir = folder(&solves, Some((level, &states)));
        let cut = grade(&request(dir.path())).unwrap();
        let moved = key_error(&cut, level) / key_error(&g, level) - 1.0;
        println!(
            "{what}: theorem error {:+.1}%, checks {:?}, flagged {:?}",
            100.0 * moved,
            cut.checks[level],
            cut.flagged
        );
        assert_eq!(cut.flagged.len(), 1, "{what}: {:?}", cut.flagged);
        assert!(cut.flagged[0].starts_with(&format!("level {level} ")));
        assert_eq!(cut.checks[level].verdict, "flagged");
        // No rate from it: its rows are left out of errors.csv and of the judged levels.
        assert!(
            !cut.errors
                .iter()
                .any(|r| r.method.name() == "outside" && r.level == level)
        );
        let theorem = cut
            .rates
            .iter()
            .find(|r| r.method.name() == "outside" && r.quantity == Quantity::Theorem)
            .unwrap();
        assert!(
            theorem.supported_fit().is_none(),
            "{what}: {}",
            theorem.short_text()
        );
        let check = &cut.checks[level];
        if what == "stopped early" {
            assert!((0.10..=0.20).contains(&moved), "{what}: {moved}");
            // Refused by the residual (issue 73): part of it does not scale with the load
            // from step to step (delta_w above 1/20 of the error), and it exceeds 1/2 of the
            // error; the contact forces on Gamma_C do not balance either.
            assert_eq!(check.residual_cause.as_deref(), Some("unconverged"));
            assert!(check.residual_off_load.unwrap() > check.residual_limit);
            assert!(check.residual > 0.5 * check.error);
        } else {
            // Tied: in equilibrium (delta at round-off), refused by the pulling force.
            assert_eq!(check.residual_cause.as_deref(), Some("none"));
            assert!(check.pulling.unwrap() > check.pulling_limit.unwrap());
        }
    }
}

#[test]
fn swapped_body_marks_and_a_legacy_vtk_folder_get_their_message() {
    let case = common::case("contact-mms", 0, Method::Mortar, &[]);
    let (sol, _) = solve_case(&case, SolverKind::Newton, STEPS).unwrap();
    let dir = tempfile::tempdir().unwrap();
    write_states(dir.path(), 0, &case, &sol.states, |w| {
        w.body.iter_mut().for_each(|b| *b = 3 - *b)
    });
    let msg = grade(&request(dir.path())).err().unwrap().to_string();
    println!("{msg}");
    assert!(
        msg.contains("body marks are swapped") && msg.contains("body"),
        "{msg}"
    );
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("level_0.vtk"),
        "# vtk DataFile Version 5.1\n",
    )
    .unwrap();
    let msg = grade(&request(dir.path())).err().unwrap().to_string();
    println!("{msg}");
    assert!(
        msg.contains("level_0.vtk") && msg.contains("meshio.write('level_0.vtu'"),
        "{msg}"
    );
}
