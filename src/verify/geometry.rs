//! How far a level's polygonal boundary lies from the curves it approximates: the mesh's
//! boundary edges against the circle through each edge and its neighbour along the
//! boundary (exact for circle arcs, 0 for straight lines; turns above
//! [`crate::contact::CORNER_ANGLE_DEGREES`] are corners, not curvature), read from the mesh
//! alone. Used by studies whose levels are split on their curves (`refinement = "curved"`),
//! whose exact fields are expressions on the plane evaluated on the discrete domain
//! Omega_h: the slivers between the chords and the arcs are what Omega_h leaves out of (or
//! adds to) Omega.

use crate::analytical::Exact;
use crate::fe::Model;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The polygonal boundary's geometric error at one level (one row of geometry.csv).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GeometryRow {
    /// Level.
    pub level: usize,
    /// The judge's h (length).
    pub h: f64,
    /// The largest distance between a boundary chord and its arc (the sagitta, length).
    pub max_sagitta: f64,
    /// The slivers' total area, both bodies: the circular segments over the boundary
    /// chords (length^2).
    pub sliver_area: f64,
    /// `sliver_area` over the polygons' area.
    pub relative_area: f64,
    /// The exact solution's theorem norm (||u||_H1 + ||sigma||_L2) on the slivers over its
    /// theorem norm on Omega_h (each sliver's densities read at its chord's midpoint,
    /// Omega_h's at the triangles' centroids): what the slivers hold, in the units of the
    /// relative theorem-norm error. Empty without exact fields.
    pub sliver_energy: Option<f64>,
}

/// One boundary edge with the sagitta of its arc and the area between them (0 on a
/// straight part).
struct CurvedEdge {
    nodes: [usize; 2],
    sagitta: f64,
    area: f64,
}

/// The boundary edges of `model` (edges of one triangle, in node order) with their arcs'
/// sagittas.
fn curved_edges(model: &Model) -> Vec<CurvedEdge> {
    let mut boundary = crate::mesh::boundary_edges(model.elements.iter().map(|e| e.nodes));
    boundary.sort_unstable();
    let mut neighbours: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for e in &boundary {
        neighbours.entry(e[0]).or_default().push(e[1]);
        neighbours.entry(e[1]).or_default().push(e[0]);
    }
    boundary
        .iter()
        .map(|&[p, q]| {
            // The circle through the edge and its neighbour beyond each end, where the
            // boundary turns there by less than a corner; the mean of the two curvatures.
            let curvatures: Vec<f64> = [(p, q), (q, p)]
                .into_iter()
                .filter_map(|(end, other)| {
                    let next = neighbours[&end].iter().copied().find(|&n| n != other)?;
                    let (a, b, c) = (
                        model.position(other),
                        model.position(end),
                        model.position(next),
                    );
                    (!crate::contact::is_corner(a, b, c)).then(|| curvature(a, b, c))
                })
                .collect();
            let kappa = match curvatures.len() {
                0 => 0.0,
                n => curvatures.iter().sum::<f64>() / n as f64,
            };
            let (a, b) = (model.position(p), model.position(q));
            let half = 0.5 * (b[0] - a[0]).hypot(b[1] - a[1]);
            // The circular segment over the chord: sagitta r (1 - cos(theta/2)), area
            // r^2 (theta - sin theta) / 2, theta the chord's central angle.
            let (sagitta, area) = match kappa > 0.0 {
                true => {
                    let r = 1.0 / kappa;
                    let theta = 2.0 * (half / r).min(1.0).asin();
                    (
                        r - (r * r - half * half).max(0.0).sqrt(),
                        0.5 * r * r * (theta - theta.sin()),
                    )
                }
                false => (0.0, 0.0),
            };
            CurvedEdge {
                nodes: [p, q],
                sagitta,
                area,
            }
        })
        .collect()
}

/// 1 / the radius of the circle through a, b, c (0 for collinear points).
fn curvature(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    let d = |p: [f64; 2], q: [f64; 2]| (q[0] - p[0]).hypot(q[1] - p[1]);
    let cross = ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])).abs();
    // Turns below 1e-10 rad are rounding of a straight line.
    let (ab, bc, ca) = (d(a, b), d(b, c), d(c, a));
    match cross <= 1e-10 * ab * bc {
        true => 0.0,
        false => 2.0 * cross / (ab * bc * ca),
    }
}

/// The exact solution's squared densities at (x, y, t) in body `b`: (|u|^2 + |grad u|^2,
/// sigma : sigma), the two parts of the theorem norm ||u||_H1 + ||sigma||_L2.
fn densities(exact: &Exact, b: usize, x: [f64; 2], t: f64) -> Option<[f64; 2]> {
    let s = exact.stress_at(b, x[0], x[1], t)?;
    let u = exact.displacement_at(b, x[0], x[1], t)?;
    let g = &exact.gradient.as_ref()?[b];
    let grad: f64 = g
        .iter()
        .flatten()
        .map(|e| e.eval(x[0], x[1], t).powi(2))
        .sum();
    Some([
        u[0] * u[0] + u[1] * u[1] + grad,
        s[0] * s[0] + s[1] * s[1] + 2.0 * s[2] * s[2],
    ])
}

/// The theorem norm sqrt(a) + sqrt(b) of summed squared densities [a, b].
fn theorem_norm(d: [f64; 2]) -> f64 {
    d[0].sqrt() + d[1].sqrt()
}

/// The polygonal boundary's geometric error of `model` at `level` (judge's h `h`), with
/// the exact fields' share on the slivers at time `t` where `exact` gives them.
pub fn boundary_geometry(
    model: &Model,
    level: usize,
    h: f64,
    exact: Option<&Exact>,
    t: f64,
) -> GeometryRow {
    let edges = curved_edges(model);
    let body_of = |g: usize| usize::from(g >= model.node_offset[1]);
    let sliver_area: f64 = edges.iter().map(|e| e.area).sum();
    let area: f64 = model.elements.iter().map(|e| e.area).sum();
    let sliver_energy = exact.and_then(|ex| {
        // Each sliver's densities read at its chord's midpoint; Omega_h's at the centroids.
        let mut on_slivers = [0.0; 2];
        for e in edges.iter().filter(|e| e.area > 0.0) {
            let (a, b) = (model.position(e.nodes[0]), model.position(e.nodes[1]));
            let mid = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
            let d = densities(ex, body_of(e.nodes[0]), mid, t)?;
            (0..2).for_each(|k| on_slivers[k] += e.area * d[k]);
        }
        let mut total = [0.0; 2];
        for e in &model.elements {
            let p = e.nodes.map(|n| model.position(n));
            let c = [0, 1].map(|k| (p[0][k] + p[1][k] + p[2][k]) / 3.0);
            let d = densities(ex, e.body, c, t)?;
            (0..2).for_each(|k| total[k] += e.area * d[k]);
        }
        let whole = theorem_norm(total);
        (whole > 0.0).then(|| theorem_norm(on_slivers) / whole)
    });
    GeometryRow {
        level,
        h,
        max_sagitta: edges.iter().fold(0.0, |m, e| m.max(e.sagitta)),
        sliver_area,
        relative_area: sliver_area / area,
        sliver_energy,
    }
}
