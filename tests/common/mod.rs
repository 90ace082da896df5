//! Shared helpers for the integration tests.
#![allow(dead_code)]

pub mod vtu;

use contact_rates::case::Case;
use contact_rates::contact::Method;
use contact_rates::scene::Scene;
use std::process::{Command, Output};

/// A fixed sequence in [-1, 1] (linear congruential; the tests need no randomness).
pub fn sequence(len: usize) -> Vec<f64> {
    let mut state: u64 = 12345;
    (0..len)
        .map(|_| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        })
        .collect()
}

/// Run the `contact-rates` binary with `args` and extra environment `envs`.
pub fn run(args: &[&str], envs: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_contact-rates"));
    c.args(args);
    for (k, v) in envs {
        c.env(k, v);
    }
    c.output().unwrap()
}

/// Build a built-in scene at `level` with `method` and gmsh parameter overrides.
pub fn case(scene: &str, level: usize, method: Method, params: &[(&str, f64)]) -> Case {
    contact_rates::init();
    let scene = Scene::load(scene).expect("built-in scene loads");
    let params: Vec<(String, f64)> = params.iter().map(|(k, v)| (k.to_string(), *v)).collect();
    Case::build(&scene, level, method, &params).expect("case builds")
}

/// Largest absolute entry.
pub fn amax(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |a, x| a.max(x.abs()))
}

/// max |a - b| / max |a|.
pub fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        / amax(a)
}

/// Print a fitted rate and assert that it was fitted over exactly `levels` and passed its
/// threshold; a lac row the study file gives no threshold (`lac = { none = ... }`) has no
/// outcome. The cones always have one.
pub fn assert_rate_passes(r: &contact_rates::studies::convergence::RateRow, levels: &[usize]) {
    println!(
        "{}: rate {:.3} +- {:.3} over {:?}",
        r.method,
        r.rate(),
        r.stderr(),
        r.assessment.used
    );
    assert_eq!(r.assessment.used, levels);
    let lac = r.method.cone() == Some(contact_rates::contact::Method::Lac);
    if r.threshold.is_none() {
        assert!(lac, "{}: the cones always have a threshold", r.method);
        assert_eq!(r.outcome, None, "no threshold, no outcome");
        return;
    }
    assert_eq!(
        r.outcome,
        Some(contact_rates::verify::rates::Outcome::Pass),
        "{} rate {} below {:?}",
        r.method,
        r.rate(),
        r.threshold
    );
}

/// Largest difference between a scene's exact displacement and stress and the stacked
/// blocks' closed form `closed`, on an 11 x 11 grid of each block at t = 1, relative to the
/// fields' sizes (0.05 for u, 10 for sigma).
pub fn closed_form_difference(
    closed: &contact_rates::analytical::stacked::StackedBlocks,
    scene: &Scene,
) -> f64 {
    let ex = scene
        .exact
        .as_deref()
        .expect("the scene has an exact solution");
    let mut worst = 0.0f64;
    for b in 0..2 {
        for i in 0..=10 {
            for j in 0..=10 {
                let (x, y) = (i as f64 / 10.0, 1.0 - b as f64 + j as f64 / 10.0);
                let (u, s) = (
                    closed.displacement(b, x, y, 1.0),
                    closed.stress(b, x, y, 1.0),
                );
                let (ue, se) = (
                    ex.displacement_at(b, x, y, 1.0).unwrap(),
                    ex.stress_at(b, x, y, 1.0).unwrap(),
                );
                for c in 0..2 {
                    worst = worst.max((u[c] - ue[c]).abs() / 0.05);
                }
                for k in 0..3 {
                    worst = worst.max((s[k] - se[k]).abs() / 10.0);
                }
            }
        }
    }
    worst
}

/// The nodal interpolant of the exact displacement of `ex` at time `t` on the model's nodes
/// (two components per node, in the model's node order).
pub fn nodal_interpolant(
    m: &contact_rates::fe::Model,
    ex: &contact_rates::analytical::Exact,
    t: f64,
) -> Vec<f64> {
    let mut u = vec![0.0; 2 * m.n_nodes];
    for b in 0..2 {
        for (i, x) in m.meshes[b].nodes.iter().enumerate() {
            let d = ex.displacement_at(b, x[0], x[1], t).unwrap();
            let n = m.node_offset[b] + i;
            u[2 * n] = d[0];
            u[2 * n + 1] = d[1];
        }
    }
    u
}
