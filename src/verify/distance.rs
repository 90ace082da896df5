//! The distance between the two cones' discrete solutions on the same meshes, in the norms
//! of the errors and relative to the same truth's sizes: computed exactly on the one mesh,
//! without intersecting meshes. By the triangle inequality D - e_mortar <= e_nts <= D +
//! e_mortar (the theorem norm is not an inner-product norm, so no sum of squares): D falling
//! like h^(1/2) while e_mortar falls like h shows that nts's error has an h^(1/2) part,
//! the rate Theorem 3.1 allows K_h^I.

use super::contact_error::{band, piece_jumps};
use super::field::P1History;
use super::norms::{norms_of_difference, pressure_difference};
use super::quantity::{Quantity, Scale};
use std::collections::BTreeMap;

/// ||[w.nu]||^2 in L2(Gamma_C) of the normal jumps `jumps` (piece, abscissa, jump),
/// linear between the merged trace nodes: exact.
fn jump_l2(pieces: usize, jumps: &[(usize, f64, f64)]) -> f64 {
    let mut total = 0.0;
    for pi in 0..pieces {
        let f = piece_jumps(jumps, pi);
        for w in f.windows(2) {
            let ((s0, f0), (s1, f1)) = (w[0], w[1]);
            total += (s1 - s0).max(0.0) * (f0 * f0 + f0 * f1 + f1 * f1) / 3.0;
        }
    }
    total
}

/// Every distance quantity between `a` and `b` (the same mesh and steps), max over the
/// steps, relative to the truth's `scale`; the pressure distance where both give a pressure.
/// Listed in reports under the second cone.
pub fn cone_distance(a: &P1History, b: &P1History, scale: &Scale) -> BTreeMap<Quantity, f64> {
    let (model, interface) = (a.model, a.interface);
    let in_band = band(model, interface);
    let mut max = BTreeMap::<Quantity, f64>::new();
    let mut raise = |q: Quantity, v: f64| {
        let e = max.entry(q).or_insert(0.0);
        *e = e.max(v);
    };
    for (x, y) in a.steps.iter().zip(&b.steps) {
        let n = norms_of_difference(model, x, y);
        raise(Quantity::ConeDistance, n.theorem());
        raise(Quantity::ConeDistanceH1U, n.h1());
        raise(Quantity::ConeDistanceL2Stress, n.stress.sqrt());
        let band_stress: f64 = model
            .elements
            .iter()
            .enumerate()
            .filter(|(i, _)| in_band[*i])
            .map(|(i, e)| {
                let d = x.stress[i] - y.stress[i];
                e.area * (d[0] * d[0] + d[1] * d[1] + 2.0 * d[2] * d[2])
            })
            .sum();
        raise(Quantity::ConeDistanceBandStress, band_stress.sqrt());
        let w: Vec<f64> = x.u.iter().zip(y.u.iter()).map(|(p, q)| p - q).collect();
        let jumps = crate::contact::normal_jumps(interface, &w);
        raise(
            Quantity::ConeDistanceNormalJump,
            jump_l2(interface.pieces.len(), &jumps).sqrt(),
        );
        if let (Some(p), Some(q)) = (&x.pressure, &y.pressure) {
            raise(
                Quantity::ConeDistanceL2Pressure,
                pressure_difference(interface, p, q).0.sqrt(),
            );
        }
    }
    // A distance relative to a size the truth lacks is not measured (verify::rates).
    max.into_iter()
        .filter_map(|(q, v)| {
            let s = match q {
                Quantity::ConeDistance => scale.theorem,
                Quantity::ConeDistanceH1U => scale.h1,
                Quantity::ConeDistanceL2Stress | Quantity::ConeDistanceBandStress => scale.stress,
                Quantity::ConeDistanceL2Pressure => scale.pressure?,
                _ => scale.jump,
            };
            Some((q, crate::verify::rates::relative_to(v, s, scale.theorem)?))
        })
        .collect()
}
