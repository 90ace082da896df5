//! Reference: SPEC section 4 (the convergence scene).
//! Goal: at T the scene has both contact and separation on Gamma_C with the transition
//! point inside Gamma_C, and viscoplastic flow in part (not all) of the domain.
//! Geometry: upper block [0,1]x[1,2] (body 1) on a clamped block [0,1]x[0,1], rollers on all
//! vertical sides, traction (0, -10 t (0.1 + cos(pi x))) on top.
//! Data: E = 100, nu = 0.3, lambda = 100, sigma_Y = sqrt(10), T = 1, 10 steps.

mod common;
use contact_rates::contact::Method;
use contact_rates::metrics;
use contact_rates::solve::{self, Settings};

#[test]
fn rates_scene_has_contact_separation_and_partial_flow() {
    for method in [Method::Mortar, Method::Nts] {
        let case = common::case("rates", 2, method, &[]);
        let p = &case.problem;
        let sol = solve::solve(p, &Settings::default(), 10, false).unwrap();
        let last = sol.last();
        let cf = metrics::contact_fraction(p, last);
        let pf = metrics::plastic_fraction(p, last);
        println!(
            "{}: contact fraction {cf:.3}, plastic fraction {pf:.3}",
            method.name()
        );
        assert!(cf > 0.2 && cf < 0.8, "contact fraction {cf}");
        assert!(pf > 0.05 && pf < 0.95, "plastic fraction {pf}");
        // The active rows, ordered by x, form one block starting at x = 0: one transition
        // point, inside Gamma_C.
        let piece = &p.interface.pieces[0];
        let mut by_x: Vec<(f64, bool)> = last
            .lambda
            .iter()
            .zip(&piece.slave_s)
            .map(|(&l, &s)| (piece.a[0] + s * piece.tangent[0], l > 0.0))
            .collect();
        by_x.sort_by(|a, b| a.0.total_cmp(&b.0));
        let active: Vec<bool> = by_x.iter().map(|a| a.1).collect();
        let switches = active.windows(2).filter(|w| w[0] != w[1]).count();
        assert_eq!(switches, 1, "one contact/separation transition");
        assert!(active[0] && !active[active.len() - 1]);
        let x_t = by_x[active.iter().position(|a| !a).unwrap()].0;
        println!(
            "{}: transition between x = {:.3} and {x_t:.3}",
            method.name(),
            by_x[active.iter().position(|a| !a).unwrap() - 1].0
        );
        assert!(x_t > 0.1 && x_t < 0.9, "transition at x = {x_t}");
        // Separation is real: the gap opens to a visible fraction of the displacement.
        let gap = contact::normal_jumps_min(p, last);
        assert!(gap < -1e-3 * common::amax(&last.u), "max opening {gap}");
    }
}

mod contact {
    use contact_rates::solve::{Problem, State};
    /// Most negative normal jump (the widest opening), length units.
    pub fn normal_jumps_min(p: &Problem, s: &State) -> f64 {
        contact_rates::contact::normal_jumps(&p.interface, &s.u)
            .iter()
            .map(|j| j.2)
            .fold(0.0, f64::min)
    }
}
