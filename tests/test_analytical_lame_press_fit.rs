//! Reference: Timoshenko and Goodier, Theory of Elasticity (1970), section 28 (Lame's thick
//! cylinder: sigma_rr = p_i a^2 / (b^2 - a^2) (1 - b^2 / r^2) under an internal pressure
//! p_i), and the compound cylinder of a shrink fit; issue 77 (the press fit).
//! Goal: `analytical::lame::PressFit` solves its six equations to round-off; with no gap
//! and one material the two bodies are one thick cylinder a <= r <= b and the contact
//! pressure is Lame's sigma_rr at R (an independent closed form, to 1e-13); at
//! `closing_pressure` the contact pressure vanishes; the radial field is in equilibrium
//! (d sigma_rr / dr + (sigma_rr - sigma_tt) / r = 0 by central differences) and its scene
//! expressions are u_r e_r.
//! Data: a = 0.5, R = 1, b = 1.5, g0 = 0.02, E = 100 and 150, nu = 0.3, plane strain.

use contact_rates::analytical::lame::PressFit;
use contact_rates::expr::Expr;
use contact_rates::material::{Elasticity, Plane};

fn strain(young: f64) -> Elasticity {
    Elasticity {
        young,
        poisson: 0.3,
        plane: Plane::Strain,
    }
}

fn fit(gap: f64, young: [f64; 2], bore_pressure: f64) -> PressFit {
    PressFit {
        bore: 0.5,
        radius: 1.0,
        gap,
        outer: 1.5,
        bore_pressure,
        elastic: young.map(strain),
    }
}

#[test]
fn without_a_gap_one_material_is_lames_thick_cylinder() {
    let f = fit(0.0, [100.0, 100.0], 3.0);
    let s = f.solve();
    let (a, r, b, p) = (0.5f64, 1.0f64, 1.5f64, 3.0);
    let lame = p * a * a * (b * b - r * r) / (r * r * (b * b - a * a));
    println!("p1 {:.16e}, Lame {lame:.16e}", s.pressure_inner);
    assert!((s.pressure_inner - lame).abs() <= 1e-13 * lame);
    assert!((s.pressure_outer - lame).abs() <= 1e-13 * lame);
    // One body: the same coefficients on both sides.
    for c in 0..2 {
        let (x, y) = (s.coefficients[0][c], s.coefficients[1][c]);
        assert!((x - y).abs() <= 1e-12 * x.abs(), "{x} {y}");
    }
}

#[test]
fn the_press_fit_closes_the_gap_and_balances_the_pressures() {
    let f = fit(0.02, [100.0, 150.0], 0.0);
    let closing = f.closing_pressure();
    // At the closing pressure the contact pressure vanishes (the equations' own answer).
    let at = PressFit {
        bore_pressure: closing,
        ..f
    }
    .solve();
    println!(
        "closing pressure {closing:.6}, p1 there {:.2e}",
        at.pressure_inner
    );
    assert!(closing > 0.0 && at.pressure_inner.abs() <= 1e-12 * closing);
    let f = PressFit {
        bore_pressure: 2.0 * closing,
        ..f
    };
    assert!(f.closes());
    let s = f.solve();
    let rho = 1.02;
    let closure = s.radial_displacement(0, 1.0) - s.radial_displacement(1, rho);
    assert!((closure - 0.02).abs() <= 1e-14, "closure {closure}");
    assert!((s.pressure_inner * 1.0 - s.pressure_outer * rho).abs() <= 1e-13 * s.pressure_inner);
    let e = f.elastic;
    let tractions = [
        (s.radial_stress(0, 0.5, &e[0]).0, -f.bore_pressure),
        (s.radial_stress(0, 1.0, &e[0]).0, -s.pressure_inner),
        (s.radial_stress(1, rho, &e[1]).0, -s.pressure_outer),
        (s.radial_stress(1, 1.5, &e[1]).0, 0.0),
    ];
    for (got, want) in tractions {
        assert!(
            (got - want).abs() <= 1e-12 * f.bore_pressure,
            "{got} {want}"
        );
    }
    // Equilibrium by central differences (error O(d^2) of the stress' third derivative).
    let d = 1e-4;
    for (i, r) in [(0, 0.75), (1, 1.25)] {
        let sr = |r: f64| s.radial_stress(i, r, &e[i]).0;
        let (srr, stt) = s.radial_stress(i, r, &e[i]);
        let residual = (sr(r + d) - sr(r - d)) / (2.0 * d) + (srr - stt) / r;
        assert!(
            residual.abs() <= 1e-7 * f.bore_pressure,
            "body {i}: {residual:e}"
        );
    }
    // The scene expressions are u_r e_r.
    for i in 0..2 {
        let [ux, uy] = s.displacement_text(i).map(|t| {
            Expr::parse(&t, std::path::Path::new("lame"), "displacement").expect("parses")
        });
        for (r, angle) in [(0.6, 0.3), (1.2, 1.1)] {
            let (x, y) = (r * f64::cos(angle), r * f64::sin(angle));
            let ur = s.radial_displacement(i, r);
            let got = [ux.eval(x, y, 0.0), uy.eval(x, y, 0.0)];
            let want = [ur * angle.cos(), ur * angle.sin()];
            for c in 0..2 {
                assert!((got[c] - want[c]).abs() <= 1e-14, "{got:?} {want:?}");
            }
        }
    }
}
