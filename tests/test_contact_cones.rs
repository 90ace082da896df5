//! Reference: paper section 2.1 (K_h^pi and K_h^I) and SPEC section 2.
//! Goal: the mortar projection pi_h^1 keeps end values and reproduces every function of
//! W_h^1 (in particular linear functions) exactly; on matching meshes K_h^pi = K_h^I.
//! Geometry: synthetic straight pieces with random non-matching trace meshes, and the
//! patch .geo meshed with matching contact lines (equal sizes, no grading).

mod common;
use contact_rates::contact::{self, Method, Piece, constraint_rows};

/// A deterministic pseudo-random sequence (xorshift) so the test is reproducible.
fn rng(seed: &mut u64) -> f64 {
    *seed ^= *seed << 13;
    *seed ^= *seed >> 7;
    *seed ^= *seed << 17;
    (*seed >> 11) as f64 / (1u64 << 53) as f64
}

fn random_trace(n: usize, len: f64, seed: &mut u64) -> Vec<f64> {
    let mut s: Vec<f64> = (0..n).map(|_| 0.2 + rng(seed)).collect();
    let mut acc = 0.0;
    let mut out = vec![0.0];
    let total: f64 = s.iter().sum();
    for v in s.iter_mut() {
        acc += *v / total * len;
        out.push(acc);
    }
    *out.last_mut().unwrap() = len;
    out
}

fn piece(slave_s: Vec<f64>, master_s: Vec<f64>, len: f64) -> Piece {
    Piece {
        a: [0.0, 0.0],
        tangent: [1.0, 0.0],
        length: len,
        normal: [0.0, -1.0],
        slave_nodes: (0..slave_s.len()).collect(),
        slave_s,
        master_nodes: (0..master_s.len()).collect(),
        master_s,
        breaks: Vec::new(),
        ..Default::default()
    }
}

#[test]
fn mortar_projection_reproduces_linear_functions_and_keeps_end_values() {
    let mut seed = 0x2545F4914F6CDD1D;
    for (ns, nm) in [(2, 3), (3, 2), (5, 7), (8, 5), (13, 29), (40, 17)] {
        let len = 1.7;
        let p = piece(
            random_trace(ns, len, &mut seed),
            random_trace(nm, len, &mut seed),
            len,
        );
        let tr = contact::mortar::transfer(&p);
        for (a, b) in [(1.0, 0.0), (0.0, 1.0), (-2.5, 0.75)] {
            let phi: Vec<f64> = p.master_s.iter().map(|s| a + b * s).collect();
            for (i, s) in p.slave_s.iter().enumerate() {
                let v: f64 = tr[i].iter().zip(&phi).map(|(c, f)| c * f).sum();
                assert!(
                    (v - (a + b * s)).abs() < 1e-12,
                    "{ns}x{nm}: pi(linear) at s = {s}: {v} vs {}",
                    a + b * s
                );
            }
        }
        // End values are kept for any function.
        let phi: Vec<f64> = p.master_s.iter().map(|s| (3.0 * s).sin()).collect();
        let first: f64 = tr[0].iter().zip(&phi).map(|(c, f)| c * f).sum();
        let last: f64 = tr[ns].iter().zip(&phi).map(|(c, f)| c * f).sum();
        assert!((first - phi[0]).abs() < 1e-14 && (last - phi[nm]).abs() < 1e-14);
        // Orthogonality to M_h: the projected function has the same integral as phi against
        // the constant 1 (which lies in M_h when there are at least two elements).
        let int = |s: &[f64], v: &[f64]| {
            s.windows(2)
                .zip(v.windows(2))
                .map(|(x, y)| 0.5 * (x[1] - x[0]) * (y[0] + y[1]))
                .sum::<f64>()
        };
        let pv: Vec<f64> = tr
            .iter()
            .map(|r| r.iter().zip(&phi).map(|(c, f)| c * f).sum())
            .collect();
        if ns >= 2 {
            assert!(
                (int(&p.slave_s, &pv) - int(&p.master_s, &phi)).abs() < 1e-13,
                "{ns}x{nm}: mean not preserved"
            );
        }
    }
}

#[test]
fn interpolation_reproduces_linear_functions() {
    let mut seed = 42;
    let p = piece(
        random_trace(9, 1.0, &mut seed),
        random_trace(6, 1.0, &mut seed),
        1.0,
    );
    let tr = contact::nts::transfer(&p);
    for (i, s) in p.slave_s.iter().enumerate() {
        let v: f64 = tr[i]
            .iter()
            .zip(&p.master_s)
            .map(|(c, x)| c * (1.0 - 2.0 * x))
            .sum();
        assert!((v - (1.0 - 2.0 * s)).abs() < 1e-14);
    }
}

#[test]
fn cones_coincide_on_matching_meshes() {
    let params = [("h_lower", 0.2), ("matching", 1.0)];
    for level in 0..3 {
        let mortar = common::case("patch", level, Method::Mortar, &params);
        let nts = common::case("patch", level, Method::Nts, &params);
        assert!(
            mortar.problem.interface.min_relative_separation() < 1e-12,
            "matching trace nodes"
        );
        let (a, b) = (&mortar.problem.rows, &nts.problem.rows);
        assert_eq!(a.len(), b.len());
        let mut worst = 0.0f64;
        for (ra, rb) in a.iter().zip(b) {
            let mut da = ra.entries.clone();
            let mut db = rb.entries.clone();
            da.retain(|e| e.1.abs() > 1e-12);
            db.retain(|e| e.1.abs() > 1e-12);
            assert_eq!(
                da.iter().map(|e| e.0).collect::<Vec<_>>(),
                db.iter().map(|e| e.0).collect::<Vec<_>>()
            );
            for (x, y) in da.iter().zip(&db) {
                worst = worst.max((x.1 - y.1).abs());
            }
            // Entries dropped above are below 1e-12 in the mortar row.
            for e in ra.entries.iter().filter(|e| e.1.abs() <= 1e-12) {
                worst = worst.max(e.1.abs());
            }
        }
        println!("level {level}: max |K_pi row - K_I row| = {worst:.2e}");
        assert!(worst < 1e-12);
    }
}

#[test]
fn nonmatching_meshes_stay_apart_under_refinement() {
    // Uniform splitting of a graded line never brings the two traces' nodes together.
    for scene in ["patch", "rates"] {
        for level in 0..7 {
            let c = common::case(scene, level, Method::Nts, &[]);
            let sep = c.problem.interface.min_relative_separation();
            println!("{scene} level {level}: min node separation {sep:.3} h");
            assert!(
                sep > 1e-3,
                "{scene} level {level}: interface nodes {sep} h apart"
            );
        }
    }
    let _ = constraint_rows;
}
