//! Scalar measures of a state: interpenetration, contact fraction, plastic fraction.

use crate::contact;
use crate::solve::{Problem, State};

/// Largest interpenetration ([u.nu] - g)^+ over all trace nodes of both bodies, g the
/// initial gap between the traces (length units).
pub fn max_penetration(p: &Problem, s: &State) -> f64 {
    contact::penetrations(&p.interface, &s.u)
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

/// The contact result at one body-1 (slave) node of Gamma_C: what a contact user looks at.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactNode {
    /// Piece of Gamma_C.
    pub piece: usize,
    /// Global node.
    pub node: usize,
    /// Arc length from the piece's start (length).
    pub arc_length: f64,
    /// Reference position (length).
    pub position: [f64; 2],
    /// Contact pressure: the node's multiplier over its lumped trace weight (force/length).
    pub pressure: f64,
    /// Normal jump [u.nu] with the other body's trace interpolated (length): positive where
    /// the bodies interpenetrate, negative where they are apart.
    pub normal_jump: f64,
    /// Whether the node's constraint row holds as an equality (C u)_i = 0, to 1e-8 of the
    /// row's size times max |u|: in contact in the discrete cone's sense.
    pub active: bool,
}

/// The contact result at every slave node of Gamma_C, in row order (piece by piece, along
/// each piece). LAC's rows are macro-elements: each body-1 node of a macro-element M gets
/// M's pressure and activity, a node shared by two macro-elements the mean of their
/// pressures and the activity of either.
pub fn contact_nodes(p: &Problem, s: &State) -> Vec<ContactNode> {
    // normal_jumps lists each piece's slave nodes, then its master nodes.
    let jumps = contact::normal_jumps(&p.interface, &s.u);
    let mut first_of_piece = Vec::with_capacity(p.interface.pieces.len());
    let mut k = 0;
    for piece in &p.interface.pieces {
        first_of_piece.push(k);
        k += piece.slave_nodes.len() + piece.master_nodes.len();
    }
    let rows_u = contact::constraint_values(&p.rows, &s.u);
    let u_max = crate::solve::inf_norm(&s.u).max(f64::MIN_POSITIVE);
    let mut out: Vec<ContactNode> = Vec::new();
    for ((row, &lambda), &cu) in p.rows.iter().zip(&s.lambda).zip(&rows_u) {
        let piece = &p.interface.pieces[row.piece];
        let size: f64 = row.entries.iter().map(|(_, v)| v.abs()).sum();
        let active = cu.abs() <= 1e-8 * size * u_max;
        let node_at = |i: usize| {
            let arc = piece.slave_s[i];
            ContactNode {
                piece: row.piece,
                node: piece.slave_nodes[i],
                arc_length: arc,
                position: piece.point(arc),
                pressure: row.pressure(lambda),
                normal_jump: jumps[first_of_piece[row.piece] + i].2,
                active,
            }
        };
        for i in row.span[0]..=row.span[1] {
            let node = node_at(i);
            match out.last_mut() {
                // The end a macro-element shares with the one before it.
                Some(last)
                    if row.is_macro() && last.piece == node.piece && last.node == node.node =>
                {
                    last.pressure = 0.5 * (last.pressure + node.pressure);
                    last.active |= node.active;
                }
                _ => out.push(node),
            }
        }
    }
    out
}

/// The least plane-stress von Mises stress of any stress state that carries the traction
/// (t_n, t_t) (normal and tangential to the boundary; stress units) at a boundary point:
/// with sigma_nn = t_n, sigma_nt = t_t and sigma_tt free, sigma_nn^2 - sigma_nn sigma_tt +
/// sigma_tt^2 + 3 sigma_nt^2 is least at sigma_tt = t_n / 2, where it is 3/4 t_n^2 + 3 t_t^2.
pub fn least_von_mises_for_traction(normal: f64, tangential: f64) -> f64 {
    (0.75 * normal * normal + 3.0 * tangential * tangential).sqrt()
}

/// The limit-load check of a viscoplastic scene at time `t`: the largest ratio, over the
/// given tractions' edges (their ends and midpoints) on viscoplastic bodies, of
/// [`least_von_mises_for_traction`] to the body's yield stress. Above 1 no stress field
/// inside the yield surface carries the load there (the lower-bound theorem's admissible
/// set is empty): the load is past the limit load, the rate-independent problem has no
/// solution, and Perzyna's flow never relaxes (the plastic strain grows like t / lambda).
/// None where no given traction acts on a viscoplastic body.
pub fn limit_load_ratio(model: &crate::fe::Model, t: f64) -> Option<f64> {
    let mut worst: Option<f64> = None;
    for &(i, [a, b]) in &model.traction_edges {
        let body = usize::from(a >= model.node_offset[1]);
        let (Some(g), Some(vp)) = (
            &model.scene.tractions[i].g,
            model.materials[body].viscoplastic,
        ) else {
            continue;
        };
        let (pa, pb) = (model.position(a), model.position(b));
        // A unit normal of the edge: its sign does not matter (t_n enters squared).
        let length = (pb[0] - pa[0]).hypot(pb[1] - pa[1]);
        let n = [(pb[1] - pa[1]) / length, -(pb[0] - pa[0]) / length];
        let mid = [0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1])];
        for p in [pa, mid, pb] {
            let gx = g.0[0].eval(p[0], p[1], t);
            let gy = g.0[1].eval(p[0], p[1], t);
            let normal = gx * n[0] + gy * n[1];
            let tangential = -gx * n[1] + gy * n[0];
            let ratio = least_von_mises_for_traction(normal, tangential) / vp.yield_stress;
            worst = Some(worst.map_or(ratio, |w| w.max(ratio)));
        }
    }
    worst
}
