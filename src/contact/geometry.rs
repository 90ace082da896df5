//! Gamma_C's geometry, computed once for every method: the pieces (split at corners), the
//! two trace meshes on each, body 1's averaged nodal normals, where each slave point meets
//! the master trace along that normal, and the mortar segments with their Gauss points
//! (Yang, Laursen and Meng 2005; Popp, Gee and Wall 2009, in two dimensions).
//!
//! A piece is parametrised by body 1's arc length s. On a straight piece (every turn of
//! the slave polyline below 1e-8 rad) the normal is the piece's, s is the abscissa along
//! its chord and a master node's s its abscissa too (the projection along a constant normal
//! is the orthogonal one); on a curved piece the normal is averaged at the slave nodes and
//! interpolated linearly between them, and a master node's s is where the normal through
//! it leaves the slave polyline (a quadratic in 2D, solved in closed form).

use crate::error::{Error, Result};
use crate::fe::Model;
use crate::mesh::{MeshSource, RawMesh};

/// The turn between two consecutive slave segments above which Gamma_C is split into two
/// pieces (degrees): above the 11.25 degrees of a quarter circle in 8 chords (the coarsest
/// curved level the curved benchmarks mesh) and below 45 degrees. Turns below it are
/// averaged over by the nodal normals.
pub const CORNER_ANGLE_DEGREES: f64 = 30.0;

/// Turns below this (radians, as |sin|) are rounding: such a piece is straight.
const STRAIGHT_TURN: f64 = 1e-8;

/// One piece of Gamma_C with both trace meshes on it.
#[derive(Debug, Clone, Default)]
pub struct Piece {
    /// Start point c_a (body 1's first node).
    pub a: [f64; 2],
    /// Unit tangent of the chord from a to the last slave node.
    pub tangent: [f64; 2],
    /// Arc length of body 1's trace on the piece (the chord's length on a straight piece).
    pub length: f64,
    /// Outward unit normal of body 1 on a straight piece (nu^1; nu^2 = -nu^1); on a curved
    /// one the chord's, the nodal normals being in `curve`.
    pub normal: [f64; 2],
    /// Body-1 (global) nodes ordered along the piece.
    pub slave_nodes: Vec<usize>,
    /// Arc lengths of the body-1 nodes, from 0 to `length`.
    pub slave_s: Vec<f64>,
    /// Body-2 (global) nodes ordered along the piece.
    pub master_nodes: Vec<usize>,
    /// Where the normal through each body-2 node meets body 1's trace, as an arc length
    /// from 0 to `length`.
    pub master_s: Vec<f64>,
    /// Indices into `slave_nodes` of the interior body-1 nodes that are geometry points of
    /// the mesh (gmsh's points on the contact curve, nodes of every level): LAC's
    /// macro-elements end there, so that they follow a rule about the mesh alone. Mortar's
    /// and nts's rows do not see them.
    pub breaks: Vec<usize>,
    /// Each body-2 node's signed distance from body 1's trace along the normal through it
    /// (length; positive: the bodies are apart). Empty where the two traces coincide
    /// (every distance below 1e-9 of the piece: rounding, not a gap).
    pub master_gap: Vec<f64>,
    /// A curved piece's nodes and normals (None: straight).
    pub curve: Option<CurvedTrace>,
    /// The scene's initial gap g0(x, y) (`[contact] gap`), added to the gap between the
    /// traces at every point of body 1's trace (None: no initial gap).
    pub initial_gap: Option<crate::expr::Expr>,
}

/// The nodes of a curved piece, where the normal is not constant.
#[derive(Debug, Clone)]
pub struct CurvedTrace {
    /// Body-1 node positions, in piece order.
    pub slave_points: Vec<[f64; 2]>,
    /// Averaged outward unit normals at the body-1 nodes: the mean of the two segments'
    /// normals inside the piece, the end segment's at its ends.
    pub slave_normals: Vec<[f64; 2]>,
    /// Body-2 node positions, in piece order.
    pub master_points: Vec<[f64; 2]>,
}

/// Gamma_C as pieces.
#[derive(Debug, Clone)]
pub struct Interface {
    /// The pieces.
    pub pieces: Vec<Piece>,
}

/// A point on one trace: the segment that holds it and the local coordinate in [0, 1].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Location {
    /// Segment index (nodes `segment` and `segment + 1`).
    pub segment: usize,
    /// Local coordinate from the segment's first node.
    pub t: f64,
}

impl Location {
    /// The two P1 shape values at the point.
    pub fn shape(&self) -> [f64; 2] {
        [1.0 - self.t, self.t]
    }
}

/// The segment of the increasing `abscissae` that holds `s` (the later one at a node, the
/// last one at the end) and the local coordinate there, clamped to [0, 1]: the one place
/// a point is located on a trace.
pub fn locate(abscissae: &[f64], s: f64) -> Location {
    let n = abscissae.len();
    let segment = (abscissae.partition_point(|&m| m <= s).max(1) - 1).min(n - 2);
    let (a, b) = (abscissae[segment], abscissae[segment + 1]);
    Location {
        segment,
        t: ((s - a) / (b - a)).clamp(0.0, 1.0),
    }
}

/// One mortar segment: an interval of the piece between consecutive breakpoints of both
/// traces, inside one slave and one master segment.
#[derive(Debug, Clone, PartialEq)]
pub struct MortarSegment {
    /// Slave segment index (body-1 nodes `slave` and `slave + 1` of the piece).
    pub slave: usize,
    /// Master segment index (body-2 nodes `master` and `master + 1` of the piece).
    pub master: usize,
    /// The interval in body 1's arc length.
    pub s: [f64; 2],
    /// Its Gauss points.
    pub points: [GaussPoint; GAUSS.len()],
}

/// A Gauss point of a mortar segment, with both sides' shape values there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaussPoint {
    /// Quadrature weight (length: body 1's arc element).
    pub weight: f64,
    /// Arc length on body 1's trace.
    pub s: f64,
    /// Body-1 shape values of the mortar segment's slave segment.
    pub slave: [f64; 2],
    /// Body-2 shape values of its master segment, where the normal meets it.
    pub master: [f64; 2],
    /// The outward unit normal of body 1 there.
    pub normal: [f64; 2],
    /// The gap between the two discrete traces along that normal (length; positive:
    /// apart, negative: the polygons cross).
    pub gap: f64,
}

/// Gauss-Legendre points on [0, 1] and weights: exact for degree 5, so for the products of
/// two linear shape functions on a straight piece, which is all the rows integrate there.
pub(crate) const GAUSS: [(f64, f64); 3] = [
    (0.112_701_665_379_258_31, 5.0 / 18.0),
    (0.5, 8.0 / 18.0),
    (0.887_298_334_620_741_7, 5.0 / 18.0),
];

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}
fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}
fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}
fn lerp(a: [f64; 2], b: [f64; 2], t: f64) -> [f64; 2] {
    [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
}
fn unit(a: [f64; 2]) -> [f64; 2] {
    let n = a[0].hypot(a[1]);
    [a[0] / n, a[1] / n]
}

/// Where the ray x + t n meets the segment [p, q]: (local coordinate on the segment, t),
/// in closed form (None: parallel).
fn ray_meets_segment(x: [f64; 2], n: [f64; 2], p: [f64; 2], q: [f64; 2]) -> Option<(f64, f64)> {
    let d = sub(q, p);
    let det = cross(d, n);
    if det.abs() <= 1e-14 * d[0].hypot(d[1]) {
        return None;
    }
    let w = sub(x, p);
    Some((cross(w, n) / det, cross(w, d) / det))
}

/// Where the normal field of a slave segment (ends p0, p1, nodal normals n0, n1 linear
/// between them) passes through x: (local coordinate xi in [0, 1], or beyond an end the
/// caller opens, down to -1 or up to 2; signed distance along the normal).
/// (x - p(xi)) x n(xi) = 0 is a quadratic in xi, solved in closed form.
fn normal_through(
    x: [f64; 2],
    p0: [f64; 2],
    p1: [f64; 2],
    n0: [f64; 2],
    n1: [f64; 2],
    (open_start, open_end): (bool, bool),
) -> Option<(f64, f64)> {
    let (d, t, dn) = (sub(x, p0), sub(p1, p0), sub(n1, n0));
    // c0 + c1 xi + c2 xi^2 = 0.
    let (c0, c1, c2) = (cross(d, n0), cross(d, dn) - cross(t, n0), -cross(t, dn));
    let scale = c0.abs().max(c1.abs()).max(c2.abs()).max(f64::MIN_POSITIVE);
    let roots: Vec<f64> = if c2.abs() <= 1e-14 * scale {
        vec![-c0 / c1]
    } else {
        let disc = c1 * c1 - 4.0 * c2 * c0;
        if disc < 0.0 {
            return None;
        }
        // The stable pair of roots.
        let q = -0.5 * (c1 + c1.signum() * disc.sqrt());
        vec![q / c2, c0 / q]
    };
    let tol = 1e-9;
    // An open end accepts a point beyond it (on the segment's line, the normal
    // extrapolated): where a trace's end node across a gap meets the other.
    let (lo, hi) = (
        if open_start { -1.0 } else { -tol },
        if open_end { 2.0 } else { 1.0 + tol },
    );
    roots
        .into_iter()
        .filter(|xi| xi.is_finite() && *xi >= lo && *xi <= hi)
        .map(|xi| {
            // Onto the segment, but past an open end.
            let xi = xi.clamp(
                if open_start { lo } else { 0.0 },
                if open_end { hi } else { 1.0 },
            );
            let n = unit(lerp(n0, n1, xi));
            (xi, dot(sub(x, lerp(p0, p1, xi)), n))
        })
        .min_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
}

impl Piece {
    /// The point of body 1's trace at arc length `s`.
    pub fn point(&self, s: f64) -> [f64; 2] {
        match &self.curve {
            None => [
                self.a[0] + s * self.tangent[0],
                self.a[1] + s * self.tangent[1],
            ],
            Some(c) => {
                let at = locate(&self.slave_s, s);
                lerp(
                    c.slave_points[at.segment],
                    c.slave_points[at.segment + 1],
                    at.t,
                )
            }
        }
    }

    /// The arc length of the point of body 1's trace nearest `x` and x's distance from it:
    /// on a straight piece the abscissa along the chord and the distance off its line
    /// (unclamped), on a curved one the nearest of the slave segments'.
    pub fn abscissa_of(&self, x: [f64; 2]) -> (f64, f64) {
        let Some(c) = &self.curve else {
            let d = sub(x, self.a);
            return (dot(d, self.tangent), dot(d, self.normal).abs());
        };
        let mut best = (0.0, f64::INFINITY);
        for (j, w) in c.slave_points.windows(2).enumerate() {
            let e = sub(w[1], w[0]);
            let len2 = dot(e, e);
            let t = (dot(sub(x, w[0]), e) / len2).clamp(0.0, 1.0);
            let off = sub(x, lerp(w[0], w[1], t));
            let distance = dot(off, off).sqrt();
            if distance < best.1 {
                let s = self.slave_s[j] + t * (self.slave_s[j + 1] - self.slave_s[j]);
                best = (s, distance);
            }
        }
        best
    }

    /// Body 1's outward unit normal at slave node `j`: the piece's on a straight piece, the
    /// averaged nodal normal on a curved one.
    pub fn slave_normal(&self, j: usize) -> [f64; 2] {
        match &self.curve {
            None => self.normal,
            Some(c) => c.slave_normals[j],
        }
    }

    /// Body 1's outward unit normal at arc length `s` (linear between the nodal normals,
    /// normalised).
    pub fn normal_at(&self, s: f64) -> [f64; 2] {
        match &self.curve {
            None => self.normal,
            Some(c) => {
                let at = locate(&self.slave_s, s);
                unit(lerp(
                    c.slave_normals[at.segment],
                    c.slave_normals[at.segment + 1],
                    at.t,
                ))
            }
        }
    }

    /// Where the normal at arc length `s` meets the master trace: its master segment and
    /// local coordinate there, and the gap along the normal (length; positive: apart).
    pub fn meet_master(&self, s: f64) -> (Location, f64) {
        let (at, gap) = self.meet_master_trace(s);
        (at, gap + self.initial_gap_at(s))
    }

    /// The scene's initial gap g0 at arc length `s` of body 1's trace (length; 0 without one).
    pub fn initial_gap_at(&self, s: f64) -> f64 {
        match &self.initial_gap {
            None => 0.0,
            Some(g) => {
                let x = self.point(s);
                g.eval(x[0], x[1], 0.0)
            }
        }
    }

    /// [`Piece::meet_master`] with the gap between the two meshed traces alone.
    fn meet_master_trace(&self, s: f64) -> (Location, f64) {
        let at = locate(&self.master_s, s);
        match &self.curve {
            None => {
                let gap = match self.master_gap.is_empty() {
                    true => 0.0,
                    false => {
                        let g = &self.master_gap;
                        (1.0 - at.t) * g[at.segment] + at.t * g[at.segment + 1]
                    }
                };
                (at, gap)
            }
            Some(c) => {
                let (x, n) = (self.point(s), self.normal_at(s));
                let f = at.segment;
                let (p, q) = (c.master_points[f], c.master_points[f + 1]);
                match ray_meets_segment(x, n, p, q) {
                    Some((t, gap)) => (
                        Location {
                            segment: f,
                            t: t.clamp(0.0, 1.0),
                        },
                        gap,
                    ),
                    None => (at, dot(sub(lerp(p, q, at.t), x), n)),
                }
            }
        }
    }

    /// The gap at body-2 node `q`: its distance from body 1's trace along the normal that
    /// passes through it (length).
    pub fn master_node_gap(&self, q: usize) -> f64 {
        self.master_gap.get(q).copied().unwrap_or(0.0) + self.initial_gap_at(self.master_s[q])
    }

    /// The gap at slave node `j` along its normal (length).
    pub fn slave_gap(&self, j: usize) -> f64 {
        self.meet_master(self.slave_s[j]).1
    }

    /// The lumped trace weight of slave node `j`: half its two segments' lengths inside
    /// the piece (length).
    pub fn lumped_weight(&self, j: usize) -> f64 {
        let s = &self.slave_s;
        let left = if j > 0 { s[j] - s[j - 1] } else { 0.0 };
        let right = if j + 1 < s.len() {
            s[j + 1] - s[j]
        } else {
            0.0
        };
        0.5 * (left + right)
    }

    /// The mortar segments of the piece, in order of s: the intervals between the merged
    /// breakpoints of both traces (breakpoints closer than 1e-14 of the piece merged), each
    /// with three Gauss points.
    pub fn mortar_segments(&self) -> Vec<MortarSegment> {
        let (ss, ms) = (&self.slave_s, &self.master_s);
        // Both traces' abscissae are sorted: merge them (no sort) and walk both traces'
        // segments along (no search per segment); the row assembly is timed against the
        // solve.
        let mut br: Vec<f64> = Vec::with_capacity(ss.len() + ms.len());
        let (mut i, mut j) = (0, 0);
        while i < ss.len() || j < ms.len() {
            let take_slave = j == ms.len() || (i < ss.len() && ss[i] <= ms[j]);
            let x = if take_slave { ss[i] } else { ms[j] };
            if take_slave {
                i += 1;
            } else {
                j += 1;
            }
            match br.last() {
                Some(&last) if (x - last).abs() <= 1e-14 * self.length => {}
                _ => br.push(x),
            }
        }
        let mut out = Vec::with_capacity(br.len());
        let (mut slave, mut master) = (0, 0);
        for w in br.windows(2).filter(|w| w[1] > w[0]) {
            let (x0, x1) = (w[0], w[1]);
            let middle = 0.5 * (x0 + x1);
            // The segments holding the middle, as `locate` finds them, moving forward only.
            while slave + 2 < ss.len() && ss[slave + 1] <= middle {
                slave += 1;
            }
            while master + 2 < ms.len() && ms[master + 1] <= middle {
                master += 1;
            }
            let points = GAUSS.map(|(xi, w)| {
                let s = x0 + xi * (x1 - x0);
                let t = (s - ss[slave]) / (ss[slave + 1] - ss[slave]);
                let (meet, gap) = self.meet_master(s);
                // The middle of the interval decides the master segment: at its ends
                // rounding may place a point on the next one.
                let on = match meet.segment == master {
                    true => meet.t,
                    false => (s - ms[master]) / (ms[master + 1] - ms[master]),
                };
                GaussPoint {
                    weight: w * (x1 - x0),
                    s,
                    slave: [1.0 - t, t],
                    master: [1.0 - on, on],
                    normal: self.normal_at(s),
                    gap,
                }
            });
            out.push(MortarSegment {
                slave,
                master,
                s: [x0, x1],
                points,
            });
        }
        out
    }
}

/// Chain edges (pairs of global nodes) into polylines; error if branched.
fn chains(edges: &[[usize; 2]], what: &str, file: &std::path::Path) -> Result<Vec<Vec<usize>>> {
    use std::collections::HashMap;
    let mut adj: HashMap<usize, Vec<usize>> = HashMap::new();
    for e in edges {
        adj.entry(e[0]).or_default().push(e[1]);
        adj.entry(e[1]).or_default().push(e[0]);
    }
    if adj.values().any(|v| v.len() > 2) {
        return Err(Error::input(
            file,
            what,
            "the contact curve branches; Gamma_C must be a simple polyline",
        ));
    }
    let mut seen = std::collections::HashSet::new();
    let mut ends: Vec<usize> = adj
        .iter()
        .filter(|(_, v)| v.len() == 1)
        .map(|(k, _)| *k)
        .collect();
    ends.sort();
    let mut out = Vec::new();
    for s in ends {
        if seen.contains(&s) {
            continue;
        }
        let mut chain = vec![s];
        seen.insert(s);
        let mut cur = s;
        loop {
            let next = adj[&cur].iter().copied().find(|n| !seen.contains(n));
            match next {
                Some(n) => {
                    seen.insert(n);
                    chain.push(n);
                    cur = n;
                }
                None => break,
            }
        }
        out.push(chain);
    }
    if seen.len() != adj.len() {
        return Err(Error::input(
            file,
            what,
            "the contact curve is closed; Gamma_C must have two end points",
        ));
    }
    Ok(out)
}

/// Where a point of Gamma_C sits among the trace nodes: on each trace, its distance to
/// the nearest node of that trace over the length of the trace segment that holds it (0 at
/// a node, at most 1/2 at a midpoint).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NodeOffset {
    /// On body 1's trace.
    pub slave: f64,
    /// On body 2's trace.
    pub master: f64,
}

impl NodeOffset {
    /// The smaller of the two.
    pub fn min(&self) -> f64 {
        self.slave.min(self.master)
    }
}

/// Distance from abscissa `s` to the nearest of the increasing `abscissae`, over the length
/// of the segment between them that holds `s`.
fn relative_offset(abscissae: &[f64], s: f64) -> f64 {
    let t = locate(abscissae, s).t;
    t.min(1.0 - t).max(0.0)
}

/// The sine of the turn from segment p0-p1 to p1-p2 (signed).
fn turn(p0: [f64; 2], p1: [f64; 2], p2: [f64; 2]) -> f64 {
    let (d1, d2) = (sub(p1, p0), sub(p2, p1));
    cross(d1, d2) / (d1[0].hypot(d1[1]) * d2[0].hypot(d2[1]))
}

/// Whether the turn at p1 is a corner: above [`CORNER_ANGLE_DEGREES`] (a turn backwards,
/// above 90 degrees, always is).
pub fn is_corner(p0: [f64; 2], p1: [f64; 2], p2: [f64; 2]) -> bool {
    let (d1, d2) = (sub(p1, p0), sub(p2, p1));
    let angle = cross(d1, d2).atan2(dot(d1, d2)).abs();
    angle > CORNER_ANGLE_DEGREES.to_radians()
}

impl Interface {
    /// Where the point `c` sits among the trace nodes (None: `c` is on no piece).
    pub fn node_offset(&self, c: [f64; 2]) -> Option<NodeOffset> {
        self.pieces.iter().find_map(|p| {
            let d = sub(c, p.a);
            let s = dot(d, p.tangent);
            let off = cross(d, p.tangent).abs();
            let tol = 1e-9 * p.length;
            (p.curve.is_none() && off <= tol && s >= -tol && s <= p.length + tol).then(|| {
                NodeOffset {
                    slave: relative_offset(&p.slave_s, s),
                    master: relative_offset(&p.master_s, s),
                }
            })
        })
    }

    /// Whether equilibrium fixes the total contact force normal to Gamma_C: Gamma_C is
    /// straight (every piece has the same normal) and one body's rigid translation along
    /// that normal is held by no clamp or roller, so only the contact holds it there and
    /// the contact resultant equals that body's load resultant along the normal, in the
    /// discrete problem as in the exact one, in both cones. Its error then measures the
    /// load's quadrature, not the contact discretization.
    pub fn resultant_fixed_by_equilibrium(&self, model: &Model) -> bool {
        self.held_only_by_contact(model).is_some()
    }

    /// The body (0: body 1, 1: body 2) whose rigid translation along Gamma_C's normal no
    /// clamp or roller holds, where Gamma_C is straight: only the contact holds it there
    /// (the first such body, or `None`).
    pub fn held_only_by_contact(&self, model: &Model) -> Option<usize> {
        let n = self.pieces.first()?.normal;
        let straight = self.pieces.iter().all(|p| {
            p.curve.is_none() && (p.normal[0] - n[0]).abs() + (p.normal[1] - n[1]).abs() <= 1e-12
        });
        let free_along_normal = |b: usize| {
            let nodes = model.node_offset[b]..model.node_offset[b] + model.meshes[b].nodes.len();
            nodes.into_iter().all(|g| {
                (0..2).all(|c| model.equation[2 * g + c] != crate::fe::FIXED || n[c].abs() <= 1e-12)
            })
        };
        (0..2).find(|&b| straight && free_along_normal(b))
    }

    /// Build Gamma_C from the scene's slave and master curves: body 1's contact edges
    /// chained and split at corners into pieces, each body-2 contact edge given to the
    /// piece it faces (both its nodes' normals meet the piece; the nearest such piece).
    pub fn new(model: &Model, raw: &RawMesh) -> Result<Self> {
        let sc = &model.scene;
        let source = MeshSource {
            scene: &sc.file,
            geo: &sc.geo,
        };
        raw.require_curve(&sc.slave_curve, &source, "contact.slave_curve")?;
        raw.require_curve(&sc.master_curve, &source, "contact.master_curve")?;
        // Body b's edges on its contact curve, in global node numbers.
        let edges_on =
            |b: usize, curve: &str, field: &str, role: &str| -> Result<Vec<[usize; 2]>> {
                let off = model.node_offset[b];
                let edges: Vec<[usize; 2]> = model.meshes[b]
                    .curve_edges(raw, curve)
                    .iter()
                    .map(|e| [e[0] + off, e[1] + off])
                    .collect();
                if edges.is_empty() {
                    return Err(Error::input(
                        &sc.file,
                        field,
                        format!(
                            "curve '{curve}' has no edge on the {role} body '{}'",
                            sc.bodies[b].surface
                        ),
                    ));
                }
                Ok(edges)
            };
        let slave_edges = edges_on(0, &sc.slave_curve, "contact.slave_curve", "slave")?;
        let master_edges = edges_on(1, &sc.master_curve, "contact.master_curve", "master")?;
        let pos = |g: usize| model.position(g);
        // Body 1's nodes at the geometry's points, in global numbers.
        let off = model.node_offset[0];
        let points: std::collections::BTreeSet<usize> = raw
            .points
            .iter()
            .filter_map(|&r| model.meshes[0].local(r))
            .map(|l| l + off)
            .collect();
        let mut pieces = Vec::new();
        for chain in chains(&slave_edges, "contact.slave_curve", &sc.file)? {
            let mut start = 0;
            for k in 1..chain.len() {
                let last = k == chain.len() - 1;
                let corner =
                    !last && is_corner(pos(chain[k - 1]), pos(chain[k]), pos(chain[k + 1]));
                if corner || last {
                    let mut piece = slave_piece(model, &chain[start..=k])?;
                    let interior = 1..piece.slave_nodes.len().saturating_sub(1);
                    piece.breaks = interior
                        .filter(|&j| points.contains(&piece.slave_nodes[j]))
                        .collect();
                    pieces.push(piece);
                    start = k;
                }
            }
        }
        // Each master edge to the nearest piece whose normals meet both its nodes.
        let mut faced: Vec<Vec<[usize; 2]>> = vec![Vec::new(); pieces.len()];
        for e in &master_edges {
            let best = pieces
                .iter()
                .enumerate()
                .filter_map(|(k, p)| {
                    let tol = 1e-9 * p.length;
                    let (s0, d0) = p.through(pos(e[0]))?;
                    let (s1, d1) = p.through(pos(e[1]))?;
                    let inside = |s: f64, d: f64| {
                        let beyond = tol + p.end_allowance(d);
                        s >= -beyond && s <= p.length + beyond
                    };
                    (inside(s0, d0) && inside(s1, d1)).then_some((k, d0.abs().max(d1.abs())))
                })
                .min_by(|a, b| a.1.total_cmp(&b.1));
            if let Some((k, _)) = best {
                faced[k].push(*e);
            }
        }
        for (piece, edges) in pieces.iter_mut().zip(&faced) {
            piece.add_master(model, edges)?;
            piece.initial_gap = sc.initial_gap.clone();
            piece.check_initial_gap(&sc.file)?;
        }
        Ok(Interface { pieces })
    }

    /// Smallest distance between an interior body-1 node and any body-2 node on Gamma_C,
    /// relative to the largest trace element length (0 when nodes coincide).
    pub fn min_relative_separation(&self) -> f64 {
        let mut best = f64::INFINITY;
        for p in &self.pieces {
            let hmax = p
                .slave_s
                .windows(2)
                .chain(p.master_s.windows(2))
                .map(|w| w[1] - w[0])
                .fold(0.0, f64::max);
            for &s in &p.slave_s[1..p.slave_s.len() - 1] {
                let k = p.master_s.partition_point(|&m| m < s);
                for j in [k.saturating_sub(1), k.min(p.master_s.len() - 1)] {
                    best = best.min((p.master_s[j] - s).abs() / hmax);
                }
            }
        }
        best
    }

    /// Total length of Gamma_C.
    pub fn length(&self) -> f64 {
        self.pieces.iter().map(|p| p.length).sum()
    }
}

/// A piece's body-1 side: its nodes `slave` (global, in chain order), their arc lengths,
/// the outward normal (from a slave triangle on the first edge) and, on a curved piece,
/// the averaged nodal normals.
fn slave_piece(model: &Model, slave: &[usize]) -> Result<Piece> {
    let file = &model.scene.file;
    let points: Vec<[f64; 2]> = slave.iter().map(|&n| model.position(n)).collect();
    let (a, b) = (points[0], *points.last().unwrap());
    let chord = (b[0] - a[0]).hypot(b[1] - a[1]);
    let tangent = [(b[0] - a[0]) / chord, (b[1] - a[1]) / chord];
    // Outward for body 1: away from the third vertex of a triangle on the first edge.
    let (n0, n1) = (slave[0], slave[1]);
    let tri = model.elements.iter().find(|e| e.body == 0 && e.nodes.contains(&n0) && e.nodes.contains(&n1)).ok_or_else(|| {
        Error::input(file, "contact.slave_curve", "a contact edge does not belong to a slave triangle; the curve must lie on the slave body's boundary")
    })?;
    let third = tri
        .nodes
        .iter()
        .copied()
        .find(|&n| n != n0 && n != n1)
        .unwrap();
    // The sign turning a segment's tangent into body 1's outward normal: (t1, -t0) times it.
    let first = sub(points[1], points[0]);
    let inward = dot(sub(model.position(third), points[0]), [first[1], -first[0]]) > 0.0;
    let sign = if inward { -1.0 } else { 1.0 };
    let straight = points
        .windows(3)
        .all(|w| turn(w[0], w[1], w[2]).abs() <= STRAIGHT_TURN);
    let normal = [sign * tangent[1], -sign * tangent[0]];
    let (slave_s, length, curve) = if straight {
        let s: Vec<f64> = points.iter().map(|&p| dot(sub(p, a), tangent)).collect();
        if s.windows(2).any(|w| w[1] <= w[0]) {
            return Err(Error::input(
                file,
                "contact.slave_curve",
                "slave nodes are not ordered along the piece",
            ));
        }
        let mut s = s;
        s[0] = 0.0;
        *s.last_mut().unwrap() = chord;
        (s, chord, None)
    } else {
        let mut s = vec![0.0];
        for w in points.windows(2) {
            let d = sub(w[1], w[0]);
            s.push(s.last().unwrap() + d[0].hypot(d[1]));
        }
        let segment_normals: Vec<[f64; 2]> = points
            .windows(2)
            .map(|w| {
                let t = unit(sub(w[1], w[0]));
                [sign * t[1], -sign * t[0]]
            })
            .collect();
        let m = segment_normals.len();
        let slave_normals = (0..=m)
            .map(|j| match j {
                0 => segment_normals[0],
                j if j == m => segment_normals[m - 1],
                j => unit([
                    segment_normals[j - 1][0] + segment_normals[j][0],
                    segment_normals[j - 1][1] + segment_normals[j][1],
                ]),
            })
            .collect();
        let length = *s.last().unwrap();
        let curve = CurvedTrace {
            slave_points: points,
            slave_normals,
            master_points: Vec::new(),
        };
        (s, length, Some(curve))
    };
    Ok(Piece {
        a,
        tangent,
        length,
        normal,
        slave_nodes: slave.to_vec(),
        slave_s,
        master_nodes: Vec::new(),
        master_s: Vec::new(),
        breaks: Vec::new(),
        master_gap: Vec::new(),
        curve,
        initial_gap: None,
    })
}

impl Piece {
    /// The initial gap at every trace node of both bodies is finite and not negative.
    fn check_initial_gap(&self, file: &std::path::Path) -> Result<()> {
        let Some(g) = &self.initial_gap else {
            return Ok(());
        };
        for &s in self.slave_s.iter().chain(&self.master_s) {
            let x = self.point(s);
            let v = g.eval(x[0], x[1], 0.0);
            if !v.is_finite() {
                return Err(g.not_finite(file, "contact.gap", x[0], x[1], 0.0));
            }
            if v < 0.0 {
                return Err(Error::input(
                    file,
                    "contact.gap",
                    format!(
                        "the initial gap '{}' is {v:e} < 0 at ({}, {}) on Gamma_C; an initial gap is a distance between the bodies: make it >= 0 there (bodies that overlap are meshed so)",
                        g.text, x[0], x[1]
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Where the normal field of body 1's trace passes through the point x: (arc length
    /// s, signed distance along the normal), or None where no normal of the piece does.
    fn through(&self, x: [f64; 2]) -> Option<(f64, f64)> {
        match &self.curve {
            None => {
                let d = sub(x, self.a);
                Some((dot(d, self.tangent), dot(d, self.normal)))
            }
            Some(c) => (0..self.slave_s.len() - 1)
                .filter_map(|e| {
                    let (p0, p1) = (c.slave_points[e], c.slave_points[e + 1]);
                    let (n0, n1) = (c.slave_normals[e], c.slave_normals[e + 1]);
                    let last = self.slave_s.len() - 2;
                    normal_through(x, p0, p1, n0, n1, (e == 0, e == last)).map(|(xi, d)| {
                        let (s0, s1) = (self.slave_s[e], self.slave_s[e + 1]);
                        (s0 + xi * (s1 - s0), d)
                    })
                })
                .min_by(|a, b| a.1.abs().total_cmp(&b.1.abs())),
        }
    }

    /// How far beyond an end of the piece a body-2 node at gap `d` may meet it (length):
    /// across a gap, an end node meets a curved trace along the end segment's normal, which
    /// the chord tilts from the line joining the two ends, so up to |d| beyond; a straight
    /// piece's ends are exact (0).
    fn end_allowance(&self, d: f64) -> f64 {
        match self.curve {
            Some(_) => d.abs(),
            None => 0.0,
        }
    }

    /// Body 2's side of the piece from the master edges facing it: its nodes ordered by
    /// where their normals meet body 1's trace, which must cover the piece with nodes at
    /// both ends (within 1e-9 of its length).
    fn add_master(&mut self, model: &Model, edges: &[[usize; 2]]) -> Result<()> {
        let file = &model.scene.file;
        let tol = 1e-9 * self.length;
        let mut nodes: Vec<usize> = edges.iter().flatten().copied().collect();
        nodes.sort_unstable();
        nodes.dedup();
        let mut placed: Vec<(usize, f64, f64)> = nodes
            .iter()
            .map(|&n| {
                let (s, d) = self.through(model.position(n)).unwrap_or((f64::NAN, 0.0));
                (n, s, d)
            })
            .collect();
        placed.sort_by(|x, y| x.1.total_cmp(&y.1));
        // An end node may land beyond the end ([`Piece::end_allowance`]) and is then placed
        // at it; every other node lies strictly inside.
        let end_tol = |p: &(usize, f64, f64)| tol + self.end_allowance(p.2);
        let n = placed.len();
        let covered = n >= 2
            && edges.len() == n - 1
            && placed[0].1.abs() <= end_tol(&placed[0])
            && (placed[n - 1].1 - self.length).abs() <= end_tol(&placed[n - 1])
            && placed.windows(2).all(|w| w[1].1 > w[0].1)
            && (n == 2 || (placed[1].1 > 0.0 && placed[n - 2].1 < self.length));
        if !covered {
            let b = self.point(self.length);
            return Err(Error::input(
                file,
                "contact.master_curve",
                format!(
                    "the master curve does not cover the piece from {:?} to {b:?} with nodes at both ends; the end points and corners of Gamma_C must be geometry points of both bodies",
                    self.a
                ),
            ));
        }
        self.master_nodes = placed.iter().map(|x| x.0).collect();
        self.master_s = placed.iter().map(|x| x.1).collect();
        self.master_s[0] = 0.0;
        *self.master_s.last_mut().unwrap() = self.length;
        let apart = placed.iter().any(|x| x.2.abs() > tol);
        self.master_gap = match apart {
            true => placed.iter().map(|x| x.2).collect(),
            false => Vec::new(),
        };
        if let Some(c) = &mut self.curve {
            c.master_points = self
                .master_nodes
                .iter()
                .map(|&n| model.position(n))
                .collect();
        }
        Ok(())
    }
}
