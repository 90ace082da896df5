//! Reference: issue 48 (grade a contact code this project did not write); the parallelogram
//! law of the H1 inner product.
//! Goal:
//! - round trip: this project's own solves of `rates-exact` levels 0-2, handed to `grade`
//!   as VTU series an outside code would write, give the study's errors to 1e-10 relative
//!   and the same verdicts as grade's own mortar beside them;
//! - a known perturbation: u_h + delta b and u_h - delta b (b a P1 hat function of one
//!   interior node) graded at T satisfy E(+)^2 + E(-)^2 = 2 E^2 + 2 delta^2 |b|^2_H1 (H1
//!   parts, absolute), |b| computed here by hand, to 1e-8;
//! - bad solution folders and labels are refused with a message naming the file and the
//!   field, and no report is left behind;
//! - the threshold: met and missed.
//!
//! Geometry: contact-mms (two elastic blocks, Gamma_C: y = 1) on the rates-exact family.
//! Data: the scene's; 4 steps (1 for the perturbation).

mod common;
#[path = "common/graded_series.rs"]
mod graded_series;

use contact_rates::case::Case;
use contact_rates::contact::Method;
use contact_rates::external::export::Source;
use contact_rates::external::grade::{GradeRequest, Graded, grade};
use contact_rates::io::solution::FieldNames;
use contact_rates::scene::Scene;
use contact_rates::solve::{Solution as Solved, SolverKind};
use contact_rates::verify::exact_error::ExactComparison;
use contact_rates::verify::field::P1Field;
use contact_rates::verify::judge::RateRow;
use contact_rates::verify::quantity::Quantity;
use contact_rates::verify::rates::Verdict;
use contact_rates::verify::solve_case;
use contact_rates::verify::study_file::LoadedStudy;
use contact_rates::verify::table::{ErrorRecord, read};
use graded_series::{outside, write_states, write_vtu};
use std::path::Path;

/// A solve's steps t_1..t_N as `dir/level_L.pvd` with one .vtu per step.
fn write_series(dir: &Path, level: usize, case: &Case, sol: &Solved) {
    write_states(dir, level, case, &sol.states, |_| ())
}

fn request(source: Source, dir: &Path, compare: bool) -> GradeRequest {
    GradeRequest {
        source,
        solutions: dir.to_path_buf(),
        levels: None,
        name: "outside".into(),
        threshold: None,
        names: FieldNames::default(),
        compare,
    }
}

fn errors_of<'a>(g: &'a Graded, method: &str) -> Vec<&'a ErrorRecord> {
    g.errors
        .iter()
        .filter(|r| r.method.name() == method)
        .collect()
}

#[test]
fn round_trip_of_this_projects_solves_gives_the_study_errors() {
    common::case("contact-mms", 0, Method::Mortar, &[]);
    let study = LoadedStudy::load("rates-exact").unwrap();
    let params = study.file.family_parameters();
    let dir = tempfile::tempdir().unwrap();
    for level in 0..=2 {
        let case = Case::build(&study.scene, level, Method::Mortar, &params).unwrap();
        let (sol, _) = solve_case(&case, SolverKind::Newton, study.file.steps).unwrap();
        write_series(dir.path(), level, &case, &sol);
    }
    let g = grade(&request(
        Source::Study("rates-exact".into()),
        dir.path(),
        true,
    ))
    .unwrap();
    // Against the committed study (reports/rates-exact, levels 0-5).
    let committed: Vec<ErrorRecord> = read(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("reports/rates-exact/errors.csv")
            .as_path(),
    )
    .unwrap();
    let (distances, mine): (Vec<&ErrorRecord>, Vec<&ErrorRecord>) = errors_of(&g, "outside")
        .into_iter()
        .partition(|r| r.quantity.is_distance());
    let graded: Vec<Quantity> = study.file.solution_quantities().collect();
    assert_eq!(mine.len(), 3 * graded.len());
    // Its distance to grade's own mortar, measured through the intersection of the two
    // meshes (here the same mesh): the graded solution is mortar's, so D is round-off, in
    // the theorem norm, h1_u and l2_stress at each of the 3 levels.
    assert_eq!(distances.len(), 9);
    let largest = distances.iter().map(|r| r.error).fold(0.0f64, f64::max);
    println!("distance of the written mortar solution to grade's mortar: {largest:.2e}");
    assert!(largest <= 1e-10, "{largest}");
    let mut worst = 0.0f64;
    for r in &mine {
        let s = committed
            .iter()
            .find(|c| c.method.name() == "mortar" && c.level == r.level && c.quantity == r.quantity)
            .expect("the study has the row");
        // The committed study ran on the baseline's rows, which the rebuilt operator
        // equals to 1e-13 (issue 75), not bit for bit: errors agree to 1e-8 relative, and
        // an error that is itself round-off (the resultant fixed by equilibrium, 2e-12)
        // to 1e-11 absolute.
        let allowed = 1e-8 * s.error.abs() + 1e-11;
        assert!((r.error - s.error).abs() <= allowed, "{r:?} vs {s:?}");
        worst = worst.max((r.error - s.error).abs() / s.error.abs());
        assert!(
            (r.h - s.h).abs() <= 1e-15 * s.h && r.dofs == s.dofs,
            "{r:?} vs {s:?}"
        );
    }
    println!(
        "round trip: {} errors, largest relative difference to the study {worst:.2e}",
        mine.len()
    );
    // Rates and verdicts against grade's own mortar on the same levels.
    let rate = |m: &str, q: Quantity| -> &RateRow {
        g.rates
            .iter()
            .find(|r| r.method.name() == m && r.quantity == q)
            .unwrap()
    };
    for &q in &graded {
        let (a, b) = (rate("outside", q), rate("mortar", q));
        if q == Quantity::PressureResultant {
            // Fixed by equilibrium in this project's cones; measured for a graded code,
            // whose resultant equilibrium does not guarantee: here at round-off.
            assert_eq!(b.assessment.verdict, Verdict::FixedByEquilibrium);
            assert_eq!(a.assessment.verdict, Verdict::RoundOff);
            continue;
        }
        assert_eq!(a.assessment.verdict, b.assessment.verdict, "{q}");
        assert_eq!(a.assessment.used, b.assessment.used, "{q}");
        match (
            a.assessment.fit.map(|f| f.rate),
            b.assessment.fit.map(|f| f.rate),
        ) {
            (Some(x), Some(y)) => assert!((x - y).abs() <= 1e-9 * y.abs(), "{q}: {x} vs {y}"),
            (x, y) => assert_eq!(x, y, "{q}"),
        }
    }
    // The console's verdict lines and the summary of what differs (issue 74): the graded
    // solution is mortar's, so it sides with mortar, every compared ratio 1.000.
    let console = g.console(dir.path());
    println!("{console}");
    let first = console.lines().next().unwrap();
    assert!(first.starts_with("outside theorem: rate "), "{first}");
    assert!(
        console.contains("it agrees with mortar within 1.5x in all")
            && console.contains("(furthest: a ratio of 1.000)")
            && console.contains("It sides with mortar"),
        "{console}"
    );
}

#[test]
fn a_known_perturbation_obeys_the_parallelogram_law() {
    let scene = Scene::load("contact-mms").unwrap();
    let exact = scene.exact.as_deref().unwrap();
    let case = common::case("contact-mms", 1, Method::Mortar, &[]);
    let (sol, _) = solve_case(&case, SolverKind::Newton, 1).unwrap();
    let last = sol.states.last().unwrap();
    let m = &case.problem.model;
    // An interior node of body 1 (no boundary curve touches it: every triangle around it
    // closes a fan).
    let on_boundary = {
        let mut count = std::collections::HashMap::new();
        for e in &m.elements {
            for k in 0..3 {
                let (a, b) = (e.nodes[k], e.nodes[(k + 1) % 3]);
                *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        let mut on = vec![false; m.n_nodes];
        for ((a, b), n) in count {
            if n == 1 {
                on[a] = true;
                on[b] = true;
            }
        }
        on
    };
    let node = (0..m.node_offset[1]).find(|&g| !on_boundary[g]).unwrap();
    // |b|^2_H1 of the hat function by hand: int phi^2 = |T| / 6, |grad phi|^2 constant.
    let (mut l2, mut semi) = (0.0, 0.0);
    for e in m.elements.iter().filter(|e| e.nodes.contains(&node)) {
        let a = e.nodes.iter().position(|&n| n == node).unwrap();
        l2 += e.area / 6.0;
        semi += e.area * (e.grads[a][0].powi(2) + e.grads[a][1].powi(2));
    }
    let b2 = l2 + semi;
    let delta = 1e-3 * last.u.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let norm_exact = {
        let cmp = ExactComparison::new(exact, contact_rates::verify::exact_error::DEFAULT_POINTS);
        let d = cmp.difference(
            m,
            &case.problem.interface,
            &P1Field::of_state(&case.problem, last),
        );
        (d.exact.l2_u + d.exact.semi_u).sqrt()
    };
    let graded = |shift: f64| -> f64 {
        let dir = tempfile::tempdir().unwrap();
        let mut u = last.u.clone();
        u[2 * node] += shift;
        write_vtu(&dir.path().join("level_1.vtu"), &outside(&case, last, &u));
        let g = grade(&request(
            Source::Scene("contact-mms".into()),
            dir.path(),
            false,
        ))
        .unwrap();
        let e = errors_of(&g, "outside")
            .into_iter()
            .find(|r| r.quantity == Quantity::H1U)
            .unwrap()
            .error;
        e * norm_exact
    };
    let (e0, plus, minus) = (graded(0.0), graded(delta), graded(-delta));
    let lhs = plus * plus + minus * minus - 2.0 * e0 * e0;
    let rhs = 2.0 * delta * delta * b2;
    println!(
        "node {node}: E = {e0:.6e}, E+ = {plus:.6e}, E- = {minus:.6e}; E+^2 + E-^2 - 2E^2 = {lhs:.10e}, 2 delta^2 |b|^2 = {rhs:.10e}"
    );
    assert!((lhs - rhs).abs() <= 1e-8 * rhs, "{lhs} vs {rhs}");
}

/// Grade `dir` and return the error's message, checking that no report appeared.
fn refused(req: GradeRequest) -> String {
    match grade(&req) {
        Ok(_) => panic!("graded {}", req.solutions.display()),
        Err(e) => e.to_string(),
    }
}

#[test]
fn bad_solution_folders_are_refused_with_the_file_and_the_field() {
    let case = common::case("contact-mms", 0, Method::Mortar, &[]);
    let (sol, _) = solve_case(&case, SolverKind::Newton, 4).unwrap();
    let last = sol.states.last().unwrap();
    let good = outside(&case, last, &last.u);
    let scene = || Source::Scene("contact-mms".into());
    // Two solutions of one level.
    let dir = tempfile::tempdir().unwrap();
    write_vtu(&dir.path().join("level_0.vtu"), &good);
    write_series(dir.path(), 0, &case, &sol);
    let msg = refused(request(scene(), dir.path(), false));
    assert!(
        msg.contains("level_0") && msg.contains("has 2 solutions"),
        "{msg}"
    );
    // A level asked for that is missing.
    let dir = tempfile::tempdir().unwrap();
    write_vtu(&dir.path().join("level_0.vtu"), &good);
    let mut req = request(scene(), dir.path(), false);
    req.levels = Some(vec![0, 1]);
    let msg = refused(req);
    assert!(msg.contains("level_1") && msg.contains("--levels"), "{msg}");
    // Two levels with the same h.
    write_vtu(&dir.path().join("level_1.vtu"), &good);
    let msg = refused(request(scene(), dir.path(), false));
    assert!(msg.contains("same h"), "{msg}");
    // A mesh that leaves a triangle of body 1 out.
    let dir = tempfile::tempdir().unwrap();
    let mut holed = good.clone();
    let t = holed.body.iter().position(|&b| b == 1).unwrap();
    holed.triangles.remove(t);
    holed.body.remove(t);
    holed.stress.remove(t);
    let file = dir.path().join("level_0.vtu");
    write_vtu(&file, &holed);
    let msg = refused(request(scene(), dir.path(), false));
    assert!(
        msg.contains(&file.display().to_string()) && msg.contains("does not cover"),
        "{msg}"
    );
    // The bodies glued at the ends of Gamma_C: body 2's corner points replaced by body 1's.
    let dir = tempfile::tempdir().unwrap();
    let mut glued = good.clone();
    for t in 0..glued.triangles.len() {
        if glued.body[t] == 2 {
            for k in 0..3 {
                let p = glued.triangles[t][k];
                if let Some(q) = (0..glued.points.len()).find(|&q| {
                    q != p
                        && glued.points[q] == glued.points[p]
                        && glued
                            .triangles
                            .iter()
                            .zip(&glued.body)
                            .any(|(tri, b)| *b == 1 && tri.contains(&q))
                }) {
                    glued.triangles[t][k] = q;
                }
            }
        }
    }
    assert_ne!(glued.triangles, good.triangles);
    write_vtu(&dir.path().join("level_0.vtu"), &glued);
    let msg = refused(request(scene(), dir.path(), false));
    assert!(msg.contains("belongs to triangles of both bodies"), "{msg}");
    // A triangle without area.
    let dir = tempfile::tempdir().unwrap();
    let mut flat = good.clone();
    let [a, b, c] = flat.triangles[3];
    let (pa, pb) = (flat.points[a], flat.points[b]);
    flat.points[c] = [(pa[0] + pb[0]) / 2.0, (pa[1] + pb[1]) / 2.0];
    write_vtu(&dir.path().join("level_0.vtu"), &flat);
    let msg = refused(request(scene(), dir.path(), false));
    assert!(msg.contains("has no area"), "{msg}");
    // The state at T for one level, a series for another.
    let dir = tempfile::tempdir().unwrap();
    write_vtu(&dir.path().join("level_0.vtu"), &good);
    let case1 = common::case("contact-mms", 1, Method::Mortar, &[]);
    let (sol1, _) = solve_case(&case1, SolverKind::Newton, 4).unwrap();
    write_series(dir.path(), 1, &case1, &sol1);
    let msg = refused(request(scene(), dir.path(), false));
    assert!(msg.contains("the same way"), "{msg}");
    // Times that are not the problem's steps.
    let dir = tempfile::tempdir().unwrap();
    write_series(dir.path(), 0, &case, &sol);
    let pvd = dir.path().join("level_0.pvd");
    let text = std::fs::read_to_string(&pvd)
        .unwrap()
        .replace("timestep=\"5e-1\"", "timestep=\"0.6\"");
    std::fs::write(&pvd, text).unwrap();
    let msg = refused(request(scene(), dir.path(), false));
    assert!(msg.contains("level_0.pvd") && msg.contains("time"), "{msg}");
    // A cone's name as the label, and a scene without an exact solution.
    let dir = tempfile::tempdir().unwrap();
    write_vtu(&dir.path().join("level_0.vtu"), &good);
    let mut req = request(scene(), dir.path(), false);
    req.name = "nts".into();
    assert!(refused(req).contains("--name"));
    let msg = refused(request(Source::Scene("rates".into()), dir.path(), false));
    assert!(
        msg.contains("no exact solution") && msg.contains("contact-mms"),
        "{msg}"
    );
}

#[test]
fn the_threshold_is_met_and_missed() {
    let (dir, skewed) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    for level in 0..=2 {
        let case = common::case("contact-mms", level, Method::Mortar, &[]);
        let (sol, _) = solve_case(&case, SolverKind::Newton, 4).unwrap();
        write_series(dir.path(), level, &case, &sol);
        // The finest level a converged solve with another upper mesh (its size 1.3 times
        // smaller than level 1's, not 2): the successive rates disagree, no window of
        // agreeing rates (pre-asymptotic), so no rate to meet a threshold with: a threshold
        // above the last successive rate fails, one below it is unverified. (A level whose
        // stress is scaled is no converged solution any more: grade sets it apart.)
        if level < 2 {
            write_series(skewed.path(), level, &case, &sol);
        } else {
            let coarse = common::case(
                "contact-mms",
                2,
                Method::Mortar,
                &[("h_upper", 0.3 * 4.0 / 2.0 / 1.3)],
            );
            let (sol, _) = solve_case(&coarse, SolverKind::Newton, 4).unwrap();
            write_series(skewed.path(), level, &coarse, &sol);
        }
    }
    let mut req = request(Source::Scene("contact-mms".into()), dir.path(), false);
    req.threshold = Some(0.7);
    let g = grade(&req).unwrap();
    assert!(g.failures.is_empty(), "{:?}", g.failures);
    req.threshold = Some(1.5);
    let g = grade(&req).unwrap();
    assert_eq!(g.failures.len(), 1, "{:?}", g.failures);
    assert!(g.failures[0].contains("< 1.500"), "{:?}", g.failures);
    // Successive rates 0.934 and 1.572.
    let mut req = request(Source::Scene("contact-mms".into()), skewed.path(), false);
    req.threshold = Some(1.6);
    let g = grade(&req).unwrap();
    let theorem = g
        .rates
        .iter()
        .find(|r| r.method.name() == "outside" && r.quantity == Quantity::Theorem)
        .unwrap();
    println!(
        "skewed: {}, successive {}",
        theorem.assessment.describe(),
        theorem.assessment.successive_text()
    );
    assert_eq!(theorem.assessment.verdict, Verdict::PreAsymptotic);
    assert_eq!(g.failures.len(), 1, "{:?}", g.failures);
    assert!(
        g.failures[0].contains("last successive rate"),
        "{:?}",
        g.failures
    );
    // Below the last successive rate, a pre-asymptotic fit neither passes nor fails.
    req.threshold = Some(1.0);
    let g = grade(&req).unwrap();
    assert!(g.failures.is_empty(), "{:?}", g.failures);
    assert_eq!(g.unverified.len(), 1, "{:?}", g.unverified);
}
