//! The discrete non-penetration conditions of the paper on each straight piece of
//! Gamma_C: K_h^I (node-on-segment interpolation) and K_h^pi (the mortar projection pi_h^1
//! with modified end functions, M^{-1} D from exact integration over merged breakpoints).
//!
//! Both give one constraint row per body-1 node of each piece: a corner node carries one
//! row per piece. A row reads `u^1(y_i).nu^1 + sum_q P_iq u^2(x_q).nu^2 <= 0`.
//!
//! A third condition, LAC (Drouet and Hild, Numer. Math. 136 (2017) 467-502), gives one row
//! per macro-element M of body 1's trace: `(1/|M|) int_M [u_h.nu] ds <= 0`, with a
//! multiplier constant on M. Here the macro-elements are pairs of consecutive body-1
//! segments of a piece (a triple at the piece's end where its count is odd), so that each
//! holds a body-1 node in its interior (see [`macro_elements`]).

use crate::error::{Error, Result};
use crate::fe::{FIXED, Model};
use crate::mesh::{MeshSource, RawMesh};

/// Which discrete cone. Written as its [`Method::name`] in files; read from it with an
/// error that lists the names.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase", try_from = "String")]
pub enum Method {
    /// K_h^pi, the global mortar-type condition.
    Mortar,
    /// K_h^I, the local node-on-segment condition.
    Nts,
    /// LAC, the local average contact condition of Drouet and Hild (2017): non-penetration
    /// on average over each macro-element of body 1's trace.
    Lac,
}

impl Method {
    /// Name used on the command line and in files.
    pub fn name(self) -> &'static str {
        match self {
            Method::Mortar => "mortar",
            Method::Nts => "nts",
            Method::Lac => "lac",
        }
    }
    /// Every method, in the order the reports list them.
    pub const ALL: [Method; 3] = [Method::Mortar, Method::Nts, Method::Lac];

    /// Whether the pressure is constant on each row's support (LAC's macro-elements)
    /// rather than linear between body-1 nodes.
    pub fn piecewise_constant_pressure(self) -> bool {
        self == Method::Lac
    }
    /// Parse "mortar", "nts" or "lac".
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "mortar" => Some(Method::Mortar),
            "nts" => Some(Method::Nts),
            "lac" => Some(Method::Lac),
            _ => None,
        }
    }
}

impl TryFrom<String> for Method {
    type Error = String;
    fn try_from(s: String) -> std::result::Result<Self, String> {
        Method::parse(&s)
            .ok_or_else(|| format!("unknown method '{s}'; use \"mortar\", \"nts\" or \"lac\""))
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.name())
    }
}

/// One straight piece of Gamma_C with both trace meshes on it.
#[derive(Debug, Clone)]
pub struct Piece {
    /// Start point c_a.
    pub a: [f64; 2],
    /// Unit tangent from a to b.
    pub tangent: [f64; 2],
    /// Length of the piece.
    pub length: f64,
    /// Outward unit normal of body 1 (nu^1; nu^2 = -nu^1).
    pub normal: [f64; 2],
    /// Body-1 (global) nodes ordered along the piece, and their abscissae.
    pub slave_nodes: Vec<usize>,
    /// Abscissae of the body-1 nodes, from 0 to `length`.
    pub slave_s: Vec<f64>,
    /// Body-2 (global) nodes ordered along the piece.
    pub master_nodes: Vec<usize>,
    /// Abscissae of the body-2 nodes, from 0 to `length`.
    pub master_s: Vec<f64>,
    /// Indices into `slave_nodes` of the interior body-1 nodes that are geometry points of
    /// the mesh (gmsh's points on the contact curve, nodes of every level): LAC's
    /// macro-elements end there, so that they follow a rule about the mesh alone. Mortar's
    /// and nts's rows do not see them.
    pub breaks: Vec<usize>,
}

/// Gamma_C as straight pieces.
#[derive(Debug, Clone)]
pub struct Interface {
    /// The pieces.
    pub pieces: Vec<Piece>,
}

/// One constraint row: on `piece`, at body-1 node index `i` of that piece; sparse entries
/// over global dofs.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// Piece index.
    pub piece: usize,
    /// Index of the body-1 node within the piece: the row's node (mortar, nts), or the
    /// first body-1 node inside the row's macro-element (lac).
    pub i: usize,
    /// The body-1 node indices within the piece at the two ends of the part of Gamma_C the
    /// row's pressure covers: `[i, i]` for a nodal row (mortar, nts), the macro-element's
    /// end nodes for lac.
    pub span: [usize; 2],
    /// (global dof, coefficient).
    pub entries: Vec<(usize, f64)>,
    /// Lumped trace weight of the node on the piece, or the macro-element's length |M|
    /// (length units).
    pub weight: f64,
}

impl Row {
    /// Whether the row's pressure is constant on a macro-element (lac) rather than nodal.
    pub fn is_macro(&self) -> bool {
        self.span[0] != self.span[1]
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
    let k = abscissae
        .windows(2)
        .position(|w| s <= w[1])
        .unwrap_or(abscissae.len().saturating_sub(2));
    let (a, b) = (abscissae[k], abscissae[k + 1]);
    ((s - a).min(b - s) / (b - a)).max(0.0)
}

impl Interface {
    /// Where the point `c` sits among the trace nodes (None: `c` is on no piece).
    pub fn node_offset(&self, c: [f64; 2]) -> Option<NodeOffset> {
        self.pieces.iter().find_map(|p| {
            let d = [c[0] - p.a[0], c[1] - p.a[1]];
            let s = d[0] * p.tangent[0] + d[1] * p.tangent[1];
            let off = (d[0] * p.tangent[1] - d[1] * p.tangent[0]).abs();
            let tol = 1e-9 * p.length;
            (off <= tol && s >= -tol && s <= p.length + tol).then(|| NodeOffset {
                slave: relative_offset(&p.slave_s, s),
                master: relative_offset(&p.master_s, s),
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
        let straight = self
            .pieces
            .iter()
            .all(|p| (p.normal[0] - n[0]).abs() + (p.normal[1] - n[1]).abs() <= 1e-12);
        let free_along_normal = |b: usize| {
            let nodes = model.node_offset[b]..model.node_offset[b] + model.meshes[b].nodes.len();
            nodes
                .into_iter()
                .all(|g| (0..2).all(|c| model.equation[2 * g + c] != FIXED || n[c].abs() <= 1e-12))
        };
        (0..2).find(|&b| straight && free_along_normal(b))
    }

    /// Build Gamma_C from the scene's slave and master curves.
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
            // Split at corners.
            let mut start = 0;
            for k in 1..chain.len() {
                let last = k == chain.len() - 1;
                let corner = !last && {
                    let (p0, p1, p2) = (pos(chain[k - 1]), pos(chain[k]), pos(chain[k + 1]));
                    let d1 = [p1[0] - p0[0], p1[1] - p0[1]];
                    let d2 = [p2[0] - p1[0], p2[1] - p1[1]];
                    let cross = d1[0] * d2[1] - d1[1] * d2[0];
                    cross.abs() > 1e-8 * d1[0].hypot(d1[1]) * d2[0].hypot(d2[1])
                };
                if corner || last {
                    let mut piece = Self::piece(model, &chain[start..=k], &master_edges)?;
                    let interior = 1..piece.slave_nodes.len().saturating_sub(1);
                    piece.breaks = interior
                        .filter(|&j| points.contains(&piece.slave_nodes[j]))
                        .collect();
                    pieces.push(piece);
                    start = k;
                }
            }
        }
        Ok(Interface { pieces })
    }

    fn piece(model: &Model, slave: &[usize], master_edges: &[[usize; 2]]) -> Result<Piece> {
        let file = &model.scene.file;
        let a = model.position(slave[0]);
        let b = model.position(*slave.last().unwrap());
        let length = (b[0] - a[0]).hypot(b[1] - a[1]);
        let tangent = [(b[0] - a[0]) / length, (b[1] - a[1]) / length];
        let mut normal = [tangent[1], -tangent[0]];
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
        let pt = model.position(third);
        if (pt[0] - a[0]) * normal[0] + (pt[1] - a[1]) * normal[1] > 0.0 {
            normal = [-normal[0], -normal[1]];
        }
        let tol = 1e-9 * length;
        let abscissa = |p: [f64; 2]| (p[0] - a[0]) * tangent[0] + (p[1] - a[1]) * tangent[1];
        let offset = |p: [f64; 2]| ((p[0] - a[0]) * normal[0] + (p[1] - a[1]) * normal[1]).abs();
        let slave_s: Vec<f64> = slave.iter().map(|&n| abscissa(model.position(n))).collect();
        if slave_s.windows(2).any(|w| w[1] <= w[0]) {
            return Err(Error::input(
                file,
                "contact.slave_curve",
                "slave nodes are not ordered along the piece",
            ));
        }
        // Master nodes on this piece (both ends of an edge on the segment).
        let on =
            |p: [f64; 2]| offset(p) <= tol && abscissa(p) >= -tol && abscissa(p) <= length + tol;
        let mut mnodes: Vec<usize> = Vec::new();
        let mut medges = 0;
        for e in master_edges {
            if on(model.position(e[0])) && on(model.position(e[1])) {
                mnodes.extend_from_slice(e);
                medges += 1;
            }
        }
        mnodes.sort_unstable();
        mnodes.dedup();
        mnodes
            .sort_by(|&p, &q| abscissa(model.position(p)).total_cmp(&abscissa(model.position(q))));
        let master_s: Vec<f64> = mnodes
            .iter()
            .map(|&n| abscissa(model.position(n)))
            .collect();
        if mnodes.len() < 2
            || medges != mnodes.len() - 1
            || master_s[0].abs() > tol
            || (master_s.last().unwrap() - length).abs() > tol
        {
            return Err(Error::input(
                file,
                "contact.master_curve",
                format!(
                    "the master curve does not cover the piece from {a:?} to {b:?} with nodes at both ends; the end points and corners of Gamma_C must be geometry points of both bodies"
                ),
            ));
        }
        let mut master_s = master_s;
        master_s[0] = 0.0;
        *master_s.last_mut().unwrap() = length;
        let mut slave_s = slave_s;
        slave_s[0] = 0.0;
        *slave_s.last_mut().unwrap() = length;
        Ok(Piece {
            a,
            tangent,
            length,
            normal,
            slave_nodes: slave.to_vec(),
            slave_s,
            master_nodes: mnodes,
            master_s,
            breaks: Vec::new(),
        })
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

impl Piece {
    /// The point at arc length `s` from the start (length).
    pub fn point(&self, s: f64) -> [f64; 2] {
        [
            self.a[0] + s * self.tangent[0],
            self.a[1] + s * self.tangent[1],
        ]
    }

    /// The matrix P (rows: body-1 nodes, columns: body-2 nodes) mapping body-2 trace
    /// values to the body-1 trace values of I_h^1 (nts) or pi_h^1 (mortar), dense. LAC has
    /// no such matrix (its rows are averages over macro-elements): see
    /// [`Piece::macro_averages`].
    pub fn transfer(&self, method: Method) -> Vec<Vec<f64>> {
        match method {
            Method::Nts => self.interpolation(),
            Method::Mortar => self.mortar(),
            Method::Lac => panic!("lac has no nodal transfer; use Piece::macro_averages"),
        }
    }

    /// LAC's rows on this piece: for each macro-element M (body-1 node indices
    /// `[first, last]`, from [`macro_elements`]), the averages (1/|M|) int_M lambda_j ds of
    /// the body-1 hats and (1/|M|) int_M mu_q ds of the body-2 hats, integrated exactly over
    /// the merged breakpoints of both traces (each integrand is linear between them, so
    /// the midpoint rule is exact), with |M|.
    pub fn macro_averages(&self) -> Vec<MacroAverage> {
        let (ss, ms) = (&self.slave_s, &self.master_s);
        // Pairs start at the piece's end first in (x, y) order, whichever way the piece runs
        // (its direction follows the mesh's node numbers): the macro-elements, a triple's
        // place among them, do not depend on how gmsh numbered the nodes.
        let n = ss.len() - 1;
        let end = self.point(self.length);
        let reversed = (end[0], end[1]) < (self.a[0], self.a[1]);
        let spans: Vec<[usize; 2]> = match reversed {
            false => macro_elements_between(n, &self.breaks),
            true => {
                let breaks: Vec<usize> = self.breaks.iter().rev().map(|b| n - b).collect();
                macro_elements_between(n, &breaks)
                    .iter()
                    .rev()
                    .map(|s| [n - s[1], n - s[0]])
                    .collect()
            }
        };
        spans
            .into_iter()
            .map(|span| {
                let (a, b) = (ss[span[0]], ss[span[1]]);
                let size = b - a;
                // Body-1 hats: exact, M is a union of whole body-1 segments.
                let mut slave = Vec::new();
                for j in span[0]..=span[1] {
                    let left = if j > span[0] { ss[j] - ss[j - 1] } else { 0.0 };
                    let right = if j < span[1] { ss[j + 1] - ss[j] } else { 0.0 };
                    slave.push((j, 0.5 * (left + right) / size));
                }
                // Body-2 hats over the body-2 nodes inside M and M's ends.
                let mut br: Vec<f64> = vec![a, b];
                br.extend(ms.iter().copied().filter(|&x| x > a && x < b));
                br.sort_by(f64::total_cmp);
                br.dedup_by(|x, y| (*x - *y).abs() <= 1e-14 * self.length);
                let nm = ms.len();
                let mut master: Vec<(usize, f64)> = Vec::new();
                for w in br.windows(2) {
                    let (x0, x1) = (w[0], w[1]);
                    if x1 <= x0 {
                        continue;
                    }
                    let xm = 0.5 * (x0 + x1);
                    let f = (ms.partition_point(|&s| s <= xm).max(1) - 1).min(nm - 2);
                    let t = (xm - ms[f]) / (ms[f + 1] - ms[f]);
                    for (q, v) in [(f, 1.0 - t), (f + 1, t)] {
                        let v = v * (x1 - x0) / size;
                        match master.iter_mut().find(|e| e.0 == q) {
                            Some(e) => e.1 += v,
                            None => master.push((q, v)),
                        }
                    }
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

    fn interpolation(&self) -> Vec<Vec<f64>> {
        let nm = self.master_s.len();
        self.slave_s
            .iter()
            .map(|&s| {
                let mut row = vec![0.0; nm];
                let q = (self.master_s.partition_point(|&m| m <= s).max(1) - 1).min(nm - 2);
                let theta = ((s - self.master_s[q]) / (self.master_s[q + 1] - self.master_s[q]))
                    .clamp(0.0, 1.0);
                row[q] += 1.0 - theta;
                row[q + 1] += theta;
                row
            })
            .collect()
    }

    /// pi_h^1 as the matrix M^{-1} D: the interior rows solve the tridiagonal system of
    /// the test functions psi_j against the body-1 hats; the end rows keep the end values.
    fn mortar(&self) -> Vec<Vec<f64>> {
        let m = self.slave_s.len() - 1; // body-1 elements
        let nm = self.master_s.len();
        let mut p = vec![vec![0.0; nm]; m + 1];
        p[0][0] = 1.0;
        p[m][nm - 1] = 1.0;
        if m < 2 {
            return p;
        }
        let integrals = self.trace_integrals();
        let system = MortarSystem::new(&integrals, m, nm);
        for (r, row) in system.solve().into_iter().enumerate() {
            p[r + 1] = row;
        }
        p
    }

    /// The products of the trace hats, integrated exactly over the merged breakpoints of
    /// both trace meshes: on each sub-interval the integrands are products of two linear
    /// functions, which Simpson's rule integrates exactly.
    fn trace_integrals(&self) -> TraceIntegrals {
        let (ss, ms) = (&self.slave_s, &self.master_s);
        let m = ss.len() - 1;
        let nm = ms.len();
        let mut br: Vec<f64> = ss.iter().chain(ms.iter()).copied().collect();
        br.sort_by(f64::total_cmp);
        br.dedup_by(|x, y| (*x - *y).abs() <= 1e-14 * self.length);
        let mut slave_slave = vec![[0.0f64; 3]; m + 1];
        let mut slave_master: Vec<Vec<(usize, f64)>> = vec![Vec::new(); m + 1];
        let hat = |nodes: &Vec<f64>, e: usize, x: f64| -> [f64; 2] {
            let t = (x - nodes[e]) / (nodes[e + 1] - nodes[e]);
            [1.0 - t, t]
        };
        for w in br.windows(2) {
            let (x0, x1) = (w[0], w[1]);
            let len = x1 - x0;
            if len <= 0.0 {
                continue;
            }
            let xm = 0.5 * (x0 + x1);
            let e = (ss.partition_point(|&s| s <= xm).max(1) - 1).min(m - 1);
            let f = (ms.partition_point(|&s| s <= xm).max(1) - 1).min(nm - 2);
            let pts = [x0, xm, x1];
            let wts = [len / 6.0, 4.0 * len / 6.0, len / 6.0];
            for (x, wt) in pts.iter().zip(wts) {
                let l = hat(ss, e, *x);
                let mu = hat(ms, f, *x);
                for a in 0..2 {
                    for b in 0..2 {
                        // slave j = e + a, k = e + b => offset k - j + 1
                        slave_slave[e + a][1 + b - a] += wt * l[a] * l[b];
                        let entry = &mut slave_master[e + a];
                        let q = f + b;
                        match entry.iter_mut().find(|(qq, _)| *qq == q) {
                            Some(v) => v.1 += wt * l[a] * mu[b],
                            None => entry.push((q, wt * l[a] * mu[b])),
                        }
                    }
                }
            }
        }
        TraceIntegrals {
            slave_slave,
            slave_master,
        }
    }
}

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

/// Integrals of products of trace hats on one piece.
struct TraceIntegrals {
    /// int lambda_j lambda_k for k = j-1, j, j+1 (body-1 hats; tridiagonal).
    slave_slave: Vec<[f64; 3]>,
    /// int lambda_j mu_q, sparse over the body-2 hats q.
    slave_master: Vec<Vec<(usize, f64)>>,
}

/// The tridiagonal system M X = R of the mortar projection's interior rows: test functions
/// psi_j (j = 1..m-1) are lambda_j, plus lambda_0 for j = 1 and lambda_m for j = m-1 (the
/// end elements' functions made constant); M[j][k] = int psi_j lambda_k for k = 1..m-1,
/// R[j][q] = int psi_j mu_q minus the end-value contributions
/// int psi_j (lambda_0 phi(c_a) + lambda_m phi(c_b)).
struct MortarSystem {
    lower: Vec<f64>,
    diag: Vec<f64>,
    upper: Vec<f64>,
    rhs: Vec<Vec<f64>>,
}

impl MortarSystem {
    fn new(integrals: &TraceIntegrals, m: usize, nm: usize) -> Self {
        let n = m - 1;
        let get = |j: usize, k: usize| -> f64 {
            if k + 1 < j || k > j + 1 {
                0.0
            } else {
                integrals.slave_slave[j][k + 1 - j]
            }
        };
        let psi_lambda = |j: usize, k: usize| -> f64 {
            let mut v = get(j, k);
            if j == 1 {
                v += get(0, k);
            }
            if j == m - 1 {
                v += get(m, k);
            }
            v
        };
        let mut lower = vec![0.0; n];
        let mut diag = vec![0.0; n];
        let mut upper = vec![0.0; n];
        let mut rhs = vec![vec![0.0; nm]; n];
        for r in 0..n {
            let j = r + 1;
            diag[r] = psi_lambda(j, j);
            if r > 0 {
                lower[r] = psi_lambda(j, j - 1);
            }
            if r + 1 < n {
                upper[r] = psi_lambda(j, j + 1);
            }
            let mut add_row = |jj: usize| {
                for &(q, v) in &integrals.slave_master[jj] {
                    rhs[r][q] += v;
                }
            };
            add_row(j);
            if j == 1 {
                add_row(0);
            }
            if j == m - 1 {
                add_row(m);
            }
            rhs[r][0] -= psi_lambda(j, 0);
            rhs[r][nm - 1] -= psi_lambda(j, m);
        }
        MortarSystem {
            lower,
            diag,
            upper,
            rhs,
        }
    }

    /// X = M^{-1} R by the Thomas algorithm: M is diagonally dominant (a mass matrix with
    /// lumped ends), so no pivoting is needed.
    fn solve(mut self) -> Vec<Vec<f64>> {
        let n = self.diag.len();
        let (diag, rhs) = (&mut self.diag, &mut self.rhs);
        for r in 1..n {
            let factor = self.lower[r] / diag[r - 1];
            diag[r] -= factor * self.upper[r - 1];
            let (prev, cur) = rhs.split_at_mut(r);
            for (c, pv) in cur[0].iter_mut().zip(&prev[r - 1]) {
                *c -= factor * pv;
            }
        }
        for r in (0..n).rev() {
            if r + 1 < n {
                let (cur, next) = rhs.split_at_mut(r + 1);
                for (c, nv) in cur[r].iter_mut().zip(&next[0]) {
                    *c -= self.upper[r] * nv;
                }
            }
            let d = diag[r];
            for c in rhs[r].iter_mut() {
                *c /= d;
            }
        }
        self.rhs
    }
}

/// Constraint rows of the chosen cone over global dofs; constrained dofs are dropped.
/// Entries of P below 1e-15 of the row's largest are dropped: the mortar rows decay
/// geometrically away from the node, and such entries are below round-off.
pub fn constraint_rows(model: &Model, interface: &Interface, method: Method) -> Vec<Row> {
    let mut rows = Vec::new();
    for (pi, p) in interface.pieces.iter().enumerate() {
        // (global node, coefficient along nu^1) -> entries over the free dofs.
        let entries_of = |terms: &mut dyn Iterator<Item = (usize, f64)>| {
            let mut entries = Vec::new();
            for (node, coef) in terms {
                for c in 0..2 {
                    let d = 2 * node + c;
                    let v = coef * p.normal[c];
                    if model.equation[d] != FIXED && v != 0.0 {
                        entries.push((d, v));
                    }
                }
            }
            entries
        };
        if method == Method::Lac {
            for m in p.macro_averages() {
                let slave = m.slave.iter().map(|&(j, v)| (p.slave_nodes[j], v));
                let master = m.master.iter().map(|&(q, v)| (p.master_nodes[q], -v));
                rows.push(Row {
                    piece: pi,
                    i: m.span[0] + 1,
                    span: m.span,
                    entries: entries_of(&mut slave.chain(master)),
                    weight: m.size,
                });
            }
            continue;
        }
        let tr = p.transfer(method);
        for (i, &node) in p.slave_nodes.iter().enumerate() {
            let big = tr[i].iter().fold(0.0f64, |a, v| a.max(v.abs()));
            let master = tr[i]
                .iter()
                .enumerate()
                .filter(|(_, v)| v.abs() > 1e-15 * big)
                .map(|(q, &v)| (p.master_nodes[q], -v));
            let entries = entries_of(&mut std::iter::once((node, 1.0)).chain(master));
            let left = if i > 0 {
                p.slave_s[i] - p.slave_s[i - 1]
            } else {
                0.0
            };
            let right = if i + 1 < p.slave_s.len() {
                p.slave_s[i + 1] - p.slave_s[i]
            } else {
                0.0
            };
            rows.push(Row {
                piece: pi,
                i,
                span: [i, i],
                entries,
                weight: 0.5 * (left + right),
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

/// Add `C^T lambda` to a global-dof vector.
pub fn add_transpose(rows: &[Row], lambda: &[f64], out: &mut [f64]) {
    for (r, l) in rows.iter().zip(lambda) {
        for &(d, v) in &r.entries {
            out[d] += v * l;
        }
    }
}

/// Normal jump [u.nu] = u^1.nu^1 + u^2.nu^2 at every trace node of both bodies (both
/// traces interpolated), positive where the bodies interpenetrate. Length units.
pub fn normal_jumps(interface: &Interface, u: &[f64]) -> Vec<(usize, f64, f64)> {
    let mut out = Vec::new();
    let un = |n: usize, nu: [f64; 2]| u[2 * n] * nu[0] + u[2 * n + 1] * nu[1];
    let interp = |nodes: &[usize], s_nodes: &[f64], s: f64, nu: [f64; 2]| -> f64 {
        let q = (s_nodes.partition_point(|&m| m <= s).max(1) - 1).min(s_nodes.len() - 2);
        let t = ((s - s_nodes[q]) / (s_nodes[q + 1] - s_nodes[q])).clamp(0.0, 1.0);
        (1.0 - t) * un(nodes[q], nu) + t * un(nodes[q + 1], nu)
    };
    for (pi, p) in interface.pieces.iter().enumerate() {
        let nu1 = p.normal;
        let nu2 = [-nu1[0], -nu1[1]];
        for (i, &n) in p.slave_nodes.iter().enumerate() {
            let s = p.slave_s[i];
            out.push((
                pi,
                s,
                un(n, nu1) + interp(&p.master_nodes, &p.master_s, s, nu2),
            ));
        }
        for (q, &n) in p.master_nodes.iter().enumerate() {
            let s = p.master_s[q];
            out.push((
                pi,
                s,
                interp(&p.slave_nodes, &p.slave_s, s, nu1) + un(n, nu2),
            ));
        }
    }
    out
}
