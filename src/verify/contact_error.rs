//! The quantities that tell the two cones apart: what happens on Gamma_C. For one state of
//! a study solution against the truth (a reference solve's profile, or the exact solution)
//! at the same time:
//! - the pressure (beside its L2(Gamma_C) error, in [`super::norms`]) in the h^(1/2)-weighted L2 norm (the discrete stand-in for
//!   H^(-1/2), where mortar theory bounds the multiplier), its resultant, and its total
//!   variation (oscillation);
//! - the contact edges: the transition points between contact and separation;
//! - the L2(Gamma_C) norm of the positive part of the normal jump (penetration).
//!
//! A discrete pressure is linear between the body-1 nodes (nodal multiplier over lumped
//! weight). Integrals run over the merged breakpoints of the study's and the truth's traces
//! with 8 Gauss points per piece: exact for the piecewise-linear truth of a reference, and
//! far below the errors measured for a smooth exact pressure.

use super::field::{P1Field, PressureProfile};
use super::norms::{eval_pl, project};
use crate::analytical::Exact;
use crate::contact::{Interface, Piece};
use crate::fe::Model;
use crate::quadrature::gauss_legendre;

/// The truth's pressure on the study's pieces of Gamma_C.
pub enum TruthPressure<'a> {
    /// A reference's nodal pressure (piecewise linear) on each study piece, (s, p) sorted,
    /// and its nodal gap -[u.nu] at its body-1 nodes, (s, gap) sorted.
    Profile(Vec<Vec<(f64, f64)>>, Vec<Vec<(f64, f64)>>),
    /// The exact solution at time `t`.
    Exact(&'a Exact, f64),
}

/// What one field measured on Gamma_C (squared norms where a norm is named).
#[derive(Debug, Clone, Copy, Default)]
pub struct ContactStep {
    /// What its pressure measured; `None` when the field gives no pressure.
    pub pressure: Option<PressureStep>,
    /// ||[u.nu]^+||^2 in L2(Gamma_C) (length^3).
    pub penetration_l2: f64,
}

/// What one field's pressure measured on Gamma_C (squared norms where a norm is named).
#[derive(Debug, Clone, Copy, Default)]
pub struct PressureStep {
    /// sum_e h_e ||p_h - p||^2_e over the study's body-1 segments e.
    pub pressure_weighted: f64,
    /// (int p_h - int p, int |p|).
    pub resultant: (f64, f64),
    /// (TV(p_h), TV(p)): total variations along Gamma_C.
    pub variation: (f64, f64),
    /// max |p| of the truth (the scale of the oscillation when the truth is constant).
    pub pressure_max: f64,
    /// Largest distance of a truth's contact edge to the nearest discrete one (length;
    /// the length of Gamma_C when the discrete solution has none, 0 when neither has).
    pub edge: f64,
}

/// A reference's nodal pressure and gap projected on each study piece (points within 1e-9
/// of the piece's length), sorted and deduplicated: the reference's displacement `u` and
/// pressure on its Gamma_C `reference`.
pub fn reference_profile(
    study: &Interface,
    reference: &Interface,
    u: &[f64],
    pressure: &PressureProfile,
) -> TruthPressure<'static> {
    let jumps = crate::contact::penetrations(reference, u);
    let pressure = project(study, &pressure.concat());
    let gap = project(study, &slave_gaps(reference, &jumps, u));
    TruthPressure::Profile(pressure, gap)
}

/// The gap g0 - [u.nu] at the body-1 nodes of every piece, as (position, gap), from the
/// normal jumps of the displacement `u`. Gaps below 1e-8 of the largest displacement are
/// round-off of a closed contact: 0.
fn slave_gaps(
    interface: &Interface,
    jumps: &[(usize, f64, f64)],
    u: &[f64],
) -> Vec<([f64; 2], f64)> {
    let floor = 1e-8 * crate::solve::inf_norm(u);
    let mut out = Vec::new();
    for (pi, piece) in interface.pieces.iter().enumerate() {
        // normal_jumps lists a piece's body-1 nodes first, in order.
        for j in jumps
            .iter()
            .filter(|j| j.0 == pi)
            .take(piece.slave_nodes.len())
        {
            out.push((piece.point(j.1), if -j.2 > floor { -j.2 } else { 0.0 }));
        }
    }
    out
}

/// The contact edges of nodal pressure `p` and gap `g` along a piece: the zeros of
/// phi = p / max p - g^+ / max g^+ (positive in contact, negative in separation, zero where
/// both vanish), linear between the nodes of `p` (the gap interpolated there).
pub fn edges(p: &[(f64, f64)], g: &[(f64, f64)]) -> Vec<f64> {
    let pmax = p
        .iter()
        .fold(0.0f64, |m, q| m.max(q.1))
        .max(f64::MIN_POSITIVE);
    let gmax = g
        .iter()
        .fold(0.0f64, |m, q| m.max(q.1))
        .max(f64::MIN_POSITIVE);
    let phi: Vec<(f64, f64)> = p
        .iter()
        .map(|&(s, v)| {
            let gap = if g.is_empty() {
                0.0
            } else {
                eval_pl(g, s).max(0.0)
            };
            // Pressures below 1e-8 of the largest are round-off of a separated node.
            let v = if v > 1e-8 * pmax { v } else { 0.0 };
            (s, v / pmax - gap / gmax)
        })
        .collect();
    phi.windows(2)
        .filter(|w| (w[0].1 > 0.0) != (w[1].1 > 0.0))
        .map(|w| {
            let ((s0, f0), (s1, f1)) = (w[0], w[1]);
            if f0 == f1 {
                0.5 * (s0 + s1)
            } else {
                s0 + (s1 - s0) * f0 / (f0 - f1)
            }
        })
        .collect()
}

impl TruthPressure<'_> {
    fn at(&self, piece_index: usize, piece: &Piece, s: f64) -> f64 {
        match self {
            TruthPressure::Profile(f, _) => eval_pl(&f[piece_index], s),
            TruthPressure::Exact(ex, t) => {
                let x = piece.point(s);
                ex.pressure_at(piece.normal, x[0], x[1], *t)
                    .unwrap_or(f64::NAN)
            }
        }
    }

    /// Breakpoints of the truth on a piece (arc length): a reference's nodes, or where a
    /// kink of the exact pressure or gap crosses the piece (none for a smooth one), so the
    /// integrals run on smooth pieces ([`crate::quadrature::segment_breaks`]).
    fn breakpoints(&self, piece_index: usize, piece: &Piece) -> Vec<f64> {
        match self {
            TruthPressure::Profile(f, _) => f[piece_index].iter().map(|p| p.0).collect(),
            TruthPressure::Exact(ex, t) => {
                let kinks = crate::expr::kink_functions(&ex.contact_kinks(), *t);
                let (a, b) = (piece.point(0.0), piece.point(piece.length));
                crate::quadrature::segment_breaks(a, b, &kinks)
                    .into_iter()
                    .map(|r| r * piece.length)
                    .collect()
            }
        }
    }

    /// The truth's total variation along a piece, its largest |p| and its contact edges.
    fn variation_and_edges(&self, piece_index: usize, piece: &Piece) -> (f64, f64, Vec<f64>) {
        match self {
            TruthPressure::Profile(f, g) => {
                let f = &f[piece_index];
                let scale = f.iter().fold(0.0f64, |m, p| m.max(p.1.abs()));
                let tv = f.windows(2).map(|w| (w[1].1 - w[0].1).abs()).sum();
                (tv, scale, edges(f, &g[piece_index]))
            }
            TruthPressure::Exact(ex, t) => {
                // 2001 samples; an edge is a sign change of p / max p - gap / max gap (both
                // vanish there: p on one side, the gap on the other), found by bisection.
                let n = 2000;
                let x_of = |s: f64| piece.point(s);
                let gap = |s: f64| {
                    let x = x_of(s);
                    ex.gap_at(piece.normal, x[0], x[1], *t).unwrap_or(0.0)
                };
                let ss: Vec<f64> = (0..=n)
                    .map(|k| piece.length * k as f64 / n as f64)
                    .collect();
                let ps: Vec<f64> = ss.iter().map(|&s| self.at(piece_index, piece, s)).collect();
                let gs: Vec<f64> = ss.iter().map(|&s| gap(s)).collect();
                let tv = ps.windows(2).map(|w| (w[1] - w[0]).abs()).sum();
                let (pmax, gmax) = (
                    ps.iter()
                        .fold(0.0f64, |m, v| m.max(v.abs()))
                        .max(f64::MIN_POSITIVE),
                    gs.iter()
                        .fold(0.0f64, |m, v| m.max(v.abs()))
                        .max(f64::MIN_POSITIVE),
                );
                let phi = |s: f64| {
                    let p = self.at(piece_index, piece, s);
                    let p = if p > 1e-12 * pmax { p } else { 0.0 };
                    p / pmax - gap(s) / gmax
                };
                let mut edges = Vec::new();
                for k in 0..n {
                    let (mut a, mut b) = (ss[k], ss[k + 1]);
                    let (fa, fb) = (phi(a), phi(b));
                    if fa > 0.0 && fb <= 0.0 || fa <= 0.0 && fb > 0.0 {
                        for _ in 0..60 {
                            let m = 0.5 * (a + b);
                            if (phi(m) > 0.0) == (fa > 0.0) {
                                a = m;
                            } else {
                                b = m;
                            }
                        }
                        edges.push(0.5 * (a + b));
                    }
                }
                (tv, pmax, edges)
            }
        }
    }
}

/// Everything one field of the study on Gamma_C `interface` measures there against the
/// truth.
pub fn contact_step(interface: &Interface, s: &P1Field, truth: &TruthPressure) -> ContactStep {
    let jumps = crate::contact::penetrations(interface, &s.u);
    ContactStep {
        pressure: s
            .pressure
            .as_ref()
            .map(|p| pressure_step(interface, p, &jumps, &s.u, truth)),
        penetration_l2: positive_jump_l2(interface.pieces.len(), &jumps),
    }
}

/// What the pressure `profile` of a field with displacement `u` (normal jumps `jumps`)
/// measures against the truth.
fn pressure_step(
    interface: &Interface,
    profile: &PressureProfile,
    jumps: &[(usize, f64, f64)],
    u: &[f64],
    truth: &TruthPressure,
) -> PressureStep {
    let gauss = gauss_legendre(8);
    let mut out = PressureStep::default();
    let total: f64 = interface.length();
    let mut worst_edge = 0.0f64;
    let gaps = project(interface, &slave_gaps(interface, jumps, u));
    for (i, (piece, profile)) in interface.pieces.iter().zip(profile).enumerate() {
        let ph: Vec<(f64, f64)> = profile
            .iter()
            .map(|&(x, v)| (piece.abscissa_of(x).0, v))
            .collect();
        let nodes: Vec<f64> = ph.iter().map(|q| q.0).collect();
        // The weights h_e are the body-1 segments': a profile's points are its nodes, but
        // for one with jumps (lac: constant on macro-elements) they are the macro-elements'
        // ends, so the piece's own body-1 abscissae give the segments.
        let has_jump = ph.windows(2).any(|w| w[0].0 == w[1].0);
        let segments: &[f64] = if has_jump { &piece.slave_s } else { &nodes };
        let mut br: Vec<f64> = nodes
            .iter()
            .copied()
            .chain(truth.breakpoints(i, piece))
            .collect();
        br.sort_by(f64::total_cmp);
        br.dedup_by(|a, b| (*a - *b).abs() <= 1e-14 * piece.length);
        for w in br.windows(2) {
            let len = w[1] - w[0];
            if len <= 0.0 {
                continue;
            }
            let mid = 0.5 * (w[0] + w[1]);
            let e = (segments.partition_point(|&v| v <= mid).max(1) - 1)
                .min(segments.len().saturating_sub(2));
            let h_e = segments.get(e + 1).map_or(len, |b| b - segments[e]);
            for &(q, wq) in &gauss {
                let sq = w[0] + q * len;
                let (a, b) = (eval_pl(&ph, sq), truth.at(i, piece, sq));
                let wl = wq * len;
                out.pressure_weighted += h_e * wl * (a - b).powi(2);
                out.resultant.0 += wl * (a - b);
                out.resultant.1 += wl * b.abs();
            }
        }
        out.variation.0 += ph.windows(2).map(|w| (w[1].1 - w[0].1).abs()).sum::<f64>();
        let (tv, pmax, truth_edges) = truth.variation_and_edges(i, piece);
        out.variation.1 += tv;
        out.pressure_max = out.pressure_max.max(pmax);
        let discrete_edges = edges(&ph, &gaps[i]);
        for a in &truth_edges {
            let d = discrete_edges
                .iter()
                .map(|b| (b - a).abs())
                .fold(f64::INFINITY, f64::min);
            worst_edge = worst_edge.max(if d.is_finite() { d } else { total });
        }
        if truth_edges.is_empty() && !discrete_edges.is_empty() {
            worst_edge = total;
        }
    }
    out.edge = worst_edge;
    out
}

/// ||([u.nu] - g0)^+||^2 in L2(Gamma_C): the penetration is linear between the merged trace
/// nodes of both bodies; its positive part squared is integrated exactly.
pub fn penetration_l2(interface: &Interface, u: &[f64]) -> f64 {
    positive_jump_l2(
        interface.pieces.len(),
        &crate::contact::penetrations(interface, u),
    )
}

/// The normal jumps (piece, abscissa, jump) on piece `pi` as (abscissa, jump), sorted
/// along the piece: the jump is linear between them.
pub fn piece_jumps(jumps: &[(usize, f64, f64)], pi: usize) -> Vec<(f64, f64)> {
    let mut f: Vec<(f64, f64)> = jumps
        .iter()
        .filter(|j| j.0 == pi)
        .map(|j| (j.1, j.2))
        .collect();
    f.sort_by(|a, b| a.0.total_cmp(&b.0));
    f
}

/// ||[u.nu]^+||^2 from the normal jumps (piece, abscissa, jump) of `pieces` pieces.
fn positive_jump_l2(pieces: usize, jumps: &[(usize, f64, f64)]) -> f64 {
    let mut total = 0.0;
    for pi in 0..pieces {
        let f = piece_jumps(jumps, pi);
        for w in f.windows(2) {
            let ((s0, f0), (s1, f1)) = (w[0], w[1]);
            let len = s1 - s0;
            if len <= 0.0 {
                continue;
            }
            total += if f0 >= 0.0 && f1 >= 0.0 {
                len * (f0 * f0 + f0 * f1 + f1 * f1) / 3.0
            } else if f0 > 0.0 {
                // Positive on [s0, s0 + theta len], theta = f0 / (f0 - f1).
                len * f0 / (f0 - f1) * f0 * f0 / 3.0
            } else if f1 > 0.0 {
                len * f1 / (f1 - f0) * f1 * f1 / 3.0
            } else {
                0.0
            };
        }
    }
    total
}

/// The triangles of both bodies with a node on Gamma_C: the band where node-on-segment's
/// consistency error lives.
pub fn band(model: &Model, interface: &Interface) -> Vec<bool> {
    let mut on = vec![false; model.n_nodes];
    for piece in &interface.pieces {
        for &n in piece.slave_nodes.iter().chain(&piece.master_nodes) {
            on[n] = true;
        }
    }
    model
        .elements
        .iter()
        .map(|e| e.nodes.iter().any(|&n| on[n]))
        .collect()
}

/// The discrete gap's own error: ||g_h - g||_L2(Gamma_C) and ||g||_L2(Gamma_C) over the
/// body-1 segments the rows cover (length^(3/2) each), where g is the initial gap between
/// the two discrete traces along body 1's normal (the scene's g0 where they touch) and g_h
/// the method's right-hand sides read in its pressure space: linear between the nodes of
/// nodal rows (mortar, nts), constant on each macro-element (lac). A segment whose two
/// nodes do not both carry a nodal row (a row dropped where a slave point misses the
/// master) is left out. 4 Gauss points per segment: exact for a quadratic g0.
pub fn discrete_gap_error(interface: &Interface, rows: &[crate::contact::Row]) -> (f64, f64) {
    let gauss = gauss_legendre(4);
    let (mut error, mut size) = (0.0, 0.0);
    let mut add = |piece: &Piece, a: f64, b: f64, gh: &dyn Fn(f64) -> f64| {
        for &(r, w) in &gauss {
            let s = a + r * (b - a);
            let g = piece.meet_master(s).1;
            error += w * (b - a) * (gh(s) - g).powi(2);
            size += w * (b - a) * g * g;
        }
    };
    for (pi, piece) in interface.pieces.iter().enumerate() {
        let on_piece: Vec<&crate::contact::Row> = rows.iter().filter(|r| r.piece == pi).collect();
        let mut nodal = vec![None; piece.slave_s.len()];
        for row in &on_piece {
            match row.node() {
                Some(i) => nodal[i] = Some(row.gap),
                None => {
                    let [i, j] = row.span;
                    let (a, b) = (
                        piece.slave_s[i].min(piece.slave_s[j]),
                        piece.slave_s[i].max(piece.slave_s[j]),
                    );
                    // The macro-element's segments one by one: g0's kinks sit at nodes.
                    for k in i.min(j)..i.max(j) {
                        let (sa, sb) = (piece.slave_s[k].max(a), piece.slave_s[k + 1].min(b));
                        add(piece, sa, sb, &|_| row.gap);
                    }
                }
            }
        }
        for k in 0..piece.slave_s.len().saturating_sub(1) {
            if let (Some(ga), Some(gb)) = (nodal[k], nodal[k + 1]) {
                let (a, b) = (piece.slave_s[k], piece.slave_s[k + 1]);
                add(piece, a, b, &|s| ga + (gb - ga) * (s - a) / (b - a));
            }
        }
    }
    (error.sqrt(), size.sqrt())
}
