//! LAC (Drouet and Hild, Numer. Math. 136 (2017) 467-502): one row per macro-element M of
//! body 1's trace, `(1/|M|) int_M [u.nu] ds <= (1/|M|) int_M g ds`, with a multiplier
//! constant on M (its pressure: the multiplier over |M|). The macro-elements are pairs of
//! consecutive body-1 segments of a piece (a triple at the piece's end where its count is
//! odd), so that each holds a body-1 node in its interior (see [`macro_elements`]); the
//! integrals are sums over the mortar segments inside M, exact on a straight piece (the
//! integrands are linear on each).

use super::{MortarSegment, Piece, PieceRow};

/// The macro-elements of LAC on a piece of `segments` body-1 segments, as body-1 node
/// indices `[first, last]` counted from the piece's end where pairing starts (the end first
/// in (x, y) order, see [`Piece::macro_averages`]): pairs of consecutive segments from it, the last three segments one macro-element where the count is odd, and the single
/// segment where the piece has only one (then no body-1 node lies inside it). Every
/// macro-element of two or three segments holds a body-1 node in its interior, the
/// condition Drouet and Hild's inf-sup argument asks of macro-elements. The pieces end at
/// Gamma_C's ends and corners, which are nodes of every level, so a macro-element never
/// spans a corner; on levels made by splitting every segment in two, each piece has an even
/// count and the pairs are exactly the parent level's segments.
pub fn macro_elements(segments: usize) -> Vec<[usize; 2]> {
    if segments <= 1 {
        return vec![[0, segments]];
    }
    let mut out = Vec::new();
    let mut k = 0;
    while k < segments {
        let size = if segments - k == 3 { 3 } else { 2 };
        out.push([k, k + size]);
        k += size;
    }
    out
}

/// [`macro_elements`] on each run of segments between the piece's ends and its interior
/// `breaks` (body-1 node indices, increasing, counted from the end where pairing starts):
/// no macro-element spans a break, each run paired from its own first node.
pub fn macro_elements_between(segments: usize, breaks: &[usize]) -> Vec<[usize; 2]> {
    let mut out = Vec::new();
    let mut start = 0;
    for &end in breaks
        .iter()
        .filter(|&&b| b > 0 && b < segments)
        .chain(std::iter::once(&segments))
    {
        out.extend(
            macro_elements(end - start)
                .iter()
                .map(|m| [m[0] + start, m[1] + start]),
        );
        start = end;
    }
    out
}

/// One LAC row on a piece, before it is written over global dofs.
#[derive(Debug, Clone, PartialEq)]
pub struct MacroAverage {
    /// Body-1 node indices of M's ends within the piece.
    pub span: [usize; 2],
    /// |M| (length).
    pub size: f64,
    /// (body-1 node index within the piece, (1/|M|) int_M lambda_j ds).
    pub slave: Vec<(usize, f64)>,
    /// (body-2 node index within the piece, (1/|M|) int_M mu_q ds).
    pub master: Vec<(usize, f64)>,
}

/// The macro-elements of a piece as body-1 node spans: pairs start at the piece's end
/// first in (x, y) order, whichever way the piece runs (its direction follows the mesh's
/// node numbers), so that the macro-elements, a triple's place among them, do not depend
/// on how gmsh numbered the nodes.
pub fn spans(piece: &Piece) -> Vec<[usize; 2]> {
    let n = piece.slave_s.len() - 1;
    let end = piece.point(piece.length);
    let reversed = (end[0], end[1]) < (piece.a[0], piece.a[1]);
    match reversed {
        false => macro_elements_between(n, &piece.breaks),
        true => {
            let breaks: Vec<usize> = piece.breaks.iter().rev().map(|b| n - b).collect();
            macro_elements_between(n, &breaks)
                .iter()
                .rev()
                .map(|s| [n - s[1], n - s[0]])
                .collect()
        }
    }
}

/// LAC's averages on a piece, scalar (along the normal): for each macro-element M, the
/// averages (1/|M|) int_M lambda_j ds of the body-1 hats and (1/|M|) int_M mu_q ds of the
/// body-2 hats, with |M|.
pub fn macro_averages(piece: &Piece) -> Vec<MacroAverage> {
    let segments = piece.mortar_segments();
    spans(piece)
        .into_iter()
        .map(|span| {
            let size = piece.slave_s[span[1]] - piece.slave_s[span[0]];
            let (mut slave, mut master) = (Vec::new(), Vec::new());
            for g in points_in(&segments, span) {
                add(&mut slave, g.0.slave, g.1.slave, g.1.weight / size);
                add(&mut master, g.0.master, g.1.master, g.1.weight / size);
            }
            MacroAverage {
                span,
                size,
                slave,
                master,
            }
        })
        .collect()
}

/// The rows on one piece.
pub fn rows(piece: &Piece) -> Vec<PieceRow> {
    let segments = &piece.mortar_segments();
    spans(piece)
        .into_iter()
        .map(|span| {
            let size = piece.slave_s[span[1]] - piece.slave_s[span[0]];
            let (mut slave, mut master) = (Vec::new(), Vec::new());
            let mut gap = 0.0;
            for (segment, g) in points_in(segments, span) {
                let w = g.weight / size;
                let n = g.normal;
                for b in 0..2 {
                    let (l, m) = (g.slave[b] * w, -g.master[b] * w);
                    add_vector(&mut slave, segment.slave + b, [l * n[0], l * n[1]]);
                    add_vector(&mut master, segment.master + b, [m * n[0], m * n[1]]);
                }
                gap += w * g.gap;
            }
            PieceRow {
                span,
                slave,
                master,
                weight: size,
                gap,
            }
        })
        .collect()
}

/// The Gauss points of the mortar segments inside the macro-element `span` (a union of
/// whole body-1 segments), with their segment.
fn points_in(
    segments: &[MortarSegment],
    span: [usize; 2],
) -> impl Iterator<Item = (&MortarSegment, &super::GaussPoint)> {
    let first = segments.partition_point(|m| m.slave < span[0]);
    let last = segments.partition_point(|m| m.slave < span[1]);
    segments[first..last]
        .iter()
        .flat_map(|m| m.points.iter().map(move |g| (m, g)))
}

/// Add `w shape[b]` to the entries of nodes `first + b`, in order of first appearance.
fn add(entries: &mut Vec<(usize, f64)>, first: usize, shape: [f64; 2], w: f64) {
    for (b, v) in shape.iter().enumerate() {
        let v = v * w;
        match entries.iter_mut().find(|e| e.0 == first + b) {
            Some(e) => e.1 += v,
            None => entries.push((first + b, v)),
        }
    }
}

fn add_vector(entries: &mut Vec<(usize, [f64; 2])>, node: usize, v: [f64; 2]) {
    match entries.iter_mut().find(|e| e.0 == node) {
        Some(e) => {
            e.1[0] += v[0];
            e.1[1] += v[1];
        }
        None => entries.push((node, v)),
    }
}
