//! Shared helpers for the integration tests.
#![allow(dead_code)]

pub mod vtu;

use contact_rates::case::Case;
use contact_rates::contact::Method;
use contact_rates::scene::Scene;
use std::process::{Command, Output};

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
/// threshold.
pub fn assert_rate_passes(r: &contact_rates::studies::convergence::RateRow, levels: &[usize]) {
    println!(
        "{}: rate {:.3} +- {:.3} over {:?}",
        r.method,
        r.rate(),
        r.stderr(),
        r.assessment.used
    );
    assert_eq!(r.assessment.used, levels);
    assert_eq!(
        r.pass,
        Some(true),
        "{} rate {} below {:?}",
        r.method,
        r.rate(),
        r.threshold
    );
}
