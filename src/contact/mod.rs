//! The discrete non-penetration conditions on Gamma_C, built as one operator: the geometry
//! once ([`geometry`]: pieces split at corners, averaged nodal normals, mortar segments with
//! their Gauss points and the gap between the two discrete traces), then each method's
//! rows from it, a file each, listed in the registry ([`method`]):
//!
//! - [`mortar`]: K_h^pi of the paper, the mortar projection pi_h^1 with modified end
//!   functions;
//! - [`nts`]: K_h^I, node-on-segment interpolation;
//! - [`lac`]: LAC (Drouet and Hild, Numer. Math. 136 (2017) 467-502), the average of the
//!   jump over each macro-element of body 1's trace.
//!
//! Every row reads `sum_j c_j . u^1_j + sum_q c_q . u^2_q <= g`: the rows are the contract
//! with the solvers, which never ask which method made them.

pub mod geometry;
pub mod lac;
pub mod method;
pub mod mortar;
pub mod nts;

pub use geometry::{
    CORNER_ANGLE_DEGREES, CurvedTrace, GaussPoint, Interface, Location, MortarSegment, NodeOffset,
    Piece, is_corner, locate,
};
pub use lac::{MacroAverage, macro_averages, macro_elements, macro_elements_between};
pub use method::{Method, MethodInfo, PressureSpace, REGISTRY};

use crate::fe::{FIXED, Model};

/// One constraint row over global dofs: `entries . u <= gap`.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// Piece index.
    pub piece: usize,
    /// The body-1 node indices within the piece at the two ends of the part of Gamma_C the
    /// row's pressure covers: `[i, i]` for a nodal row (mortar, nts: the row's node), a
    /// macro-element's end nodes for a piecewise-constant one (lac).
    pub span: [usize; 2],
    /// (global dof, coefficient).
    pub entries: Vec<(usize, f64)>,
    /// Lumped trace weight of the node on the piece, or the macro-element's length |M|
    /// (length units).
    pub weight: f64,
    /// The right-hand side: the method's discrete initial gap (length; zero where the two
    /// traces coincide; negative where the two polygons cross).
    pub gap: f64,
}

impl Row {
    /// The row's node, for a nodal row (None: the row covers a macro-element).
    pub fn node(&self) -> Option<usize> {
        (self.span[0] == self.span[1]).then_some(self.span[0])
    }

    /// Whether the row's pressure is constant on a macro-element (lac) rather than nodal.
    pub fn is_macro(&self) -> bool {
        self.node().is_none()
    }

    /// The arc lengths on its piece where the row's pressure is drawn: its node, or a
    /// macro-element's two ends (the pressure is constant between them).
    pub fn pressure_at(&self, piece: &Piece) -> Vec<f64> {
        match self.node() {
            Some(i) => vec![piece.slave_s[i]],
            None => self.span.iter().map(|&j| piece.slave_s[j]).collect(),
        }
    }

    /// Contact pressure of the multiplier `lambda` of this row: the nodal force over the
    /// lumped trace weight, or over |M| for a macro-element (force/length; 0 where the
    /// weight vanishes).
    pub fn pressure(&self, lambda: f64) -> f64 {
        if self.weight > 0.0 {
            lambda / self.weight
        } else {
            0.0
        }
    }
}

/// One row of a method on a piece, over the piece's trace nodes.
#[derive(Debug, Clone, PartialEq)]
pub struct PieceRow {
    /// As [`Row::span`].
    pub span: [usize; 2],
    /// (body-1 node index within the piece, coefficient vector multiplying u^1 there).
    pub slave: Vec<(usize, [f64; 2])>,
    /// (body-2 node index within the piece, coefficient vector multiplying u^2 there).
    pub master: Vec<(usize, [f64; 2])>,
    /// As [`Row::weight`].
    pub weight: f64,
    /// As [`Row::gap`].
    pub gap: f64,
}

impl PieceRow {
    /// The nodal row at body-1 node `j` (mortar, nts): `u^1_j.nu_j - sum_q c_q u^2_q.nu_j
    /// <= gap` over the body-2 nodes' coefficients `master` (q, c_q), nu_j the node's
    /// normal. Coefficients below 1e-15 of the largest are dropped: the mortar rows decay
    /// geometrically away from the node, and such entries are below round-off.
    pub fn nodal(
        piece: &Piece,
        j: usize,
        master: impl Iterator<Item = (usize, f64)> + Clone,
        gap: f64,
    ) -> PieceRow {
        let nu = piece.slave_normal(j);
        let big = master.clone().fold(0.0f64, |a, e| a.max(e.1.abs()));
        PieceRow {
            span: [j, j],
            slave: vec![(j, nu)],
            master: master
                .filter(|e| e.1.abs() > 1e-15 * big)
                .map(|(q, v)| (q, [-v * nu[0], -v * nu[1]]))
                .collect(),
            weight: piece.lumped_weight(j),
            gap,
        }
    }
}

/// Constraint rows of the chosen cone over global dofs; constrained dofs are dropped.
pub fn constraint_rows(model: &Model, interface: &Interface, method: Method) -> Vec<Row> {
    let rows_of = method.info().rows;
    let mut rows = Vec::new();
    for (pi, p) in interface.pieces.iter().enumerate() {
        for row in rows_of(p) {
            let mut entries = Vec::with_capacity(2 * (row.slave.len() + row.master.len()));
            let slave = row.slave.iter().map(|&(j, c)| (p.slave_nodes[j], c));
            let master = row.master.iter().map(|&(q, c)| (p.master_nodes[q], c));
            for (node, coefficient) in slave.chain(master) {
                for (c, &v) in coefficient.iter().enumerate() {
                    let d = 2 * node + c;
                    if model.equation[d] != FIXED && v != 0.0 {
                        entries.push((d, v));
                    }
                }
            }
            rows.push(Row {
                piece: pi,
                span: row.span,
                entries,
                weight: row.weight,
                gap: row.gap,
            });
        }
    }
    rows
}

/// Apply rows to a global displacement vector: `(C u)_i`.
pub fn apply_rows(rows: &[Row], u: &[f64]) -> Vec<f64> {
    rows.iter()
        .map(|r| r.entries.iter().map(|&(d, v)| v * u[d]).sum())
        .collect()
}

/// The constraint values `(C u)_i - g_i` (length): at most zero where the condition holds,
/// zero where it is active. What the solvers hold.
pub fn constraint_values(rows: &[Row], u: &[f64]) -> Vec<f64> {
    rows.iter()
        .map(|r| r.entries.iter().map(|&(d, v)| v * u[d]).sum::<f64>() - r.gap)
        .collect()
}

/// Add `C^T lambda` to a global-dof vector.
pub fn add_transpose(rows: &[Row], lambda: &[f64], out: &mut [f64]) {
    for (r, l) in rows.iter().zip(lambda) {
        for &(d, v) in &r.entries {
            out[d] += v * l;
        }
    }
}

/// Normal jump [u.nu] = u^1.nu^1 + u^2.nu^2 at every trace node of both bodies (both
/// traces interpolated, body 1's normal there), positive where the displacement closes
/// the bodies onto each other: (piece, arc length, jump). Length units.
pub fn normal_jumps(interface: &Interface, u: &[f64]) -> Vec<(usize, f64, f64)> {
    let mut out = Vec::new();
    let un = |n: usize, nu: [f64; 2]| u[2 * n] * nu[0] + u[2 * n + 1] * nu[1];
    let interp = |nodes: &[usize], at: Location, nu: [f64; 2]| -> f64 {
        let [a, b] = at.shape();
        a * un(nodes[at.segment], nu) + b * un(nodes[at.segment + 1], nu)
    };
    for (pi, p) in interface.pieces.iter().enumerate() {
        for (i, &n) in p.slave_nodes.iter().enumerate() {
            let s = p.slave_s[i];
            let nu = p.slave_normal(i);
            let (meet, _) = p.meet_master(s);
            let minus = [-nu[0], -nu[1]];
            out.push((pi, s, un(n, nu) + interp(&p.master_nodes, meet, minus)));
        }
        for (q, &n) in p.master_nodes.iter().enumerate() {
            let s = p.master_s[q];
            let nu = p.normal_at(s);
            let minus = [-nu[0], -nu[1]];
            let on_slave = locate(&p.slave_s, s);
            out.push((pi, s, interp(&p.slave_nodes, on_slave, nu) + un(n, minus)));
        }
    }
    out
}

/// The penetration at every trace node of both bodies: the normal jump
/// ([`normal_jumps`]) less the initial gap between the two discrete traces there along
/// body 1's normal; positive where the deformed bodies overlap: (piece, arc length,
/// penetration). Length units. Equal to the jump where the traces touch.
pub fn penetrations(interface: &Interface, u: &[f64]) -> Vec<(usize, f64, f64)> {
    let gaps = interface.pieces.iter().flat_map(|p| {
        let slave = (0..p.slave_s.len()).map(|j| p.slave_gap(j));
        let master = (0..p.master_s.len()).map(|q| p.master_node_gap(q));
        slave.chain(master).collect::<Vec<f64>>()
    });
    normal_jumps(interface, u)
        .into_iter()
        .zip(gaps)
        .map(|((piece, s, jump), gap)| (piece, s, jump - gap))
        .collect()
}
