//! Scalar measures of a state: interpenetration, contact fraction, plastic fraction.

use crate::contact;
use crate::solve::{Problem, State};

/// Largest interpenetration [u.nu]^+ over all trace nodes of both bodies (length units).
pub fn max_penetration(p: &Problem, s: &State) -> f64 {
    contact::normal_jumps(&p.interface, &s.u)
        .iter()
        .map(|j| j.2)
        .fold(0.0, f64::max)
}

/// Fraction of Gamma_C's length in contact: the lumped weights of the constraint rows that
/// carry a positive multiplier, over the total length.
pub fn contact_fraction(p: &Problem, s: &State) -> f64 {
    let total: f64 = p.rows.iter().map(|r| r.weight).sum();
    let scale = crate::solve::inf_norm(&s.lambda);
    let on: f64 = p
        .rows
        .iter()
        .zip(&s.lambda)
        .filter(|(_, l)| **l > 1e-8 * scale && **l > 0.0)
        .map(|(r, _)| r.weight)
        .sum();
    if total > 0.0 { on / total } else { 0.0 }
}

/// Area fraction of both bodies where the stress lies outside the elastic set B.
pub fn plastic_fraction(p: &Problem, s: &State) -> f64 {
    let m = &p.model;
    let total: f64 = m.elements.iter().map(|e| e.area).sum();
    let plastic: f64 = m
        .elements
        .iter()
        .zip(&s.sigma)
        .filter(|(e, sg)| m.materials[e.body].is_plastic(sg))
        .map(|(e, _)| e.area)
        .sum();
    // + 0.0: an empty float sum is -0.0.
    (plastic + 0.0) / total
}

/// Largest aspect ratio over all triangles: longest edge over the altitude onto it,
/// `2 |T| max_a |grad phi_a|^2` (1.15 for an equilateral triangle; dimensionless).
pub fn max_aspect_ratio(p: &Problem) -> f64 {
    p.model
        .elements
        .iter()
        .map(|e| {
            let g2 = e
                .grads
                .iter()
                .map(|g| g[0] * g[0] + g[1] * g[1])
                .fold(0.0f64, f64::max);
            2.0 * e.area * g2
        })
        .fold(0.0, f64::max)
}
