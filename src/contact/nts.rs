//! K_h^I, node-on-segment: one row per body-1 node y_j of a piece, the jump there with
//! body 2's trace interpolated where y_j's normal meets it,
//! `u^1(y_j).nu_j - (I_h u^2)(y_j).nu_j <= g(y_j)`, g the gap along that normal. Its
//! pressure is nodal (the multiplier over the node's lumped weight).

use super::{Piece, PieceRow};

/// The rows on one piece (pointwise: no mortar segment is needed).
pub fn rows(piece: &Piece) -> Vec<PieceRow> {
    (0..piece.slave_s.len())
        .map(|j| {
            let (meet, gap) = piece.meet_master(piece.slave_s[j]);
            let [a, b] = meet.shape();
            let master = [(meet.segment, a), (meet.segment + 1, b)];
            PieceRow::nodal(piece, j, master.into_iter(), gap)
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
