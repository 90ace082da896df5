//! K_h^I, node-on-segment: one row per body-1 node y_j of a piece, the jump there with
//! body 2's trace interpolated where y_j's normal meets it,
//! `u^1(y_j).nu_j - (I_h u^2)(y_j).nu_j <= g(y_j)`, g the gap along that normal. Its
//! pressure is nodal (the multiplier over the node's lumped weight).

use super::{MortarSegment, Piece, PieceRow};

/// The rows on one piece (the mortar segments are not needed: the rows are pointwise).
pub fn rows(piece: &Piece, _segments: &[MortarSegment]) -> Vec<PieceRow> {
    (0..piece.slave_s.len())
        .map(|j| {
            let nu = piece.slave_normal(j);
            let (meet, gap) = piece.meet_master(piece.slave_s[j]);
            let shape = meet.shape();
            let big = shape[0].abs().max(shape[1].abs());
            let master = (0..2)
                .filter(|&b| shape[b].abs() > 1e-15 * big)
                .map(|b| (meet.segment + b, [-shape[b] * nu[0], -shape[b] * nu[1]]))
                .collect();
            PieceRow {
                span: [j, j],
                slave: vec![(j, nu)],
                master,
                weight: piece.lumped_weight(j),
                gap,
            }
        })
        .collect()
}

/// I_h^1 as a dense matrix (rows: body-1 nodes, columns: body-2 nodes): the body-2 trace
/// values to the body-1 trace values of the interpolant.
pub fn transfer(piece: &Piece) -> Vec<Vec<f64>> {
    let nm = piece.master_s.len();
    piece
        .slave_s
        .iter()
        .map(|&s| {
            let mut row = vec![0.0; nm];
            let (meet, _) = piece.meet_master(s);
            let [a, b] = meet.shape();
            row[meet.segment] += a;
            row[meet.segment + 1] += b;
            row
        })
        .collect()
}
