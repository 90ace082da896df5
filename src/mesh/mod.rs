//! Meshes: gmsh runs and caching ([`gmsh`]), gmsh's MSH format read and written ([`msh`]),
//! and the per-body triangulation used by everything downstream ([`BodyMesh`]).

pub mod gmsh;
pub mod msh;

use crate::error::Result;
pub use msh::{MeshSource, RawMesh};

/// Marker for a raw node that is not part of a body.
const ABSENT: usize = usize::MAX;

/// The triangulation of one body, with its own node numbering (0..nodes.len()).
#[derive(Debug, Clone)]
pub struct BodyMesh {
    /// Physical-surface name of the body.
    pub name: String,
    /// Node coordinates (x, y), length units of the scene.
    pub nodes: Vec<[f64; 2]>,
    /// Triangles as counter-clockwise node triples.
    pub triangles: Vec<[usize; 3]>,
    /// For each raw mesh node, its index in this body, or `usize::MAX`.
    local_of_raw: Vec<usize>,
}

/// The edges of `triangles` that belong to one triangle only (the boundary), each as its
/// two nodes [smaller, larger], in the order they are first met.
pub fn boundary_edges(triangles: impl IntoIterator<Item = [usize; 3]>) -> Vec<[usize; 2]> {
    let mut count: std::collections::HashMap<[usize; 2], (usize, usize)> =
        std::collections::HashMap::new();
    for (order, (tri, k)) in triangles
        .into_iter()
        .flat_map(|tri| (0..3).map(move |k| (tri, k)))
        .enumerate()
    {
        let (p, q) = (tri[k], tri[(k + 1) % 3]);
        count.entry([p.min(q), p.max(q)]).or_insert((0, order)).0 += 1;
    }
    let mut edges: Vec<([usize; 2], usize)> = count
        .into_iter()
        .filter(|(_, (n, _))| *n == 1)
        .map(|(e, (_, first))| (e, first))
        .collect();
    edges.sort_by_key(|(_, first)| *first);
    edges.into_iter().map(|(e, _)| e).collect()
}

/// Signed area of a triangle (positive when counter-clockwise).
pub fn signed_area(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]))
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}

impl BodyMesh {
    /// Extract the body meshed as physical surface `surface` from `raw`; errors name the
    /// scene file of `source` and its field `field` that names the surface.
    pub fn from_raw(
        raw: &RawMesh,
        surface: &str,
        source: &MeshSource,
        field: &str,
    ) -> Result<Self> {
        let tag = raw.physical_tag(2, surface).ok_or_else(|| {
            source.error(
                field,
                format!(
                    "the mesh of {} has no physical surface named '{surface}'; its surfaces are {}; fix: name one of them in {field}, or add `Physical Surface(\"{surface}\")` to the .geo",
                    source.geo.display(),
                    raw.names_of_dim(2).join(", ")
                ),
            )
        })?;
        let mut local_of_raw = vec![ABSENT; raw.nodes.len()];
        let mut nodes = Vec::new();
        let mut triangles = Vec::new();
        for (tri, p) in &raw.triangles {
            if *p != tag {
                continue;
            }
            let mut t = [0usize; 3];
            for (k, &r) in tri.iter().enumerate() {
                if local_of_raw[r] == ABSENT {
                    local_of_raw[r] = nodes.len();
                    nodes.push(raw.nodes[r]);
                }
                t[k] = local_of_raw[r];
            }
            let area = signed_area(nodes[t[0]], nodes[t[1]], nodes[t[2]]);
            if area.abs()
                <= 1e-14
                    * dist(nodes[t[0]], nodes[t[1]])
                        .powi(2)
                        .max(f64::MIN_POSITIVE)
            {
                return Err(source.error(
                    "geo",
                    format!(
                        "the mesh of {} has a degenerate triangle in body '{surface}' with nodes at {:?}; fix the mesh sizes in the .geo or the scene's [parameters]",
                        source.geo.display(),
                        t.map(|i| nodes[i])
                    ),
                ));
            }
            if area < 0.0 {
                t.swap(1, 2);
            }
            triangles.push(t);
        }
        Ok(BodyMesh {
            name: surface.to_string(),
            nodes,
            triangles,
            local_of_raw,
        })
    }

    /// This body's node index of the raw mesh's node `raw`, where the node is this body's.
    pub fn local(&self, raw: usize) -> Option<usize> {
        self.local_of_raw.get(raw).copied().filter(|&l| l != ABSENT)
    }

    /// Edges (pairs of body node indices) of the physical curve `curve` that lie on this
    /// body; empty when the curve belongs to the other body.
    pub fn curve_edges(&self, raw: &RawMesh, curve: &str) -> Vec<[usize; 2]> {
        let Some(tag) = raw.physical_tag(1, curve) else {
            return Vec::new();
        };
        raw.lines
            .iter()
            .filter(|(_, p)| *p == tag)
            .filter_map(|(l, _)| {
                let a = self.local_of_raw[l[0]];
                let b = self.local_of_raw[l[1]];
                (a != ABSENT && b != ABSENT).then_some([a, b])
            })
            .collect()
    }

    /// This body's number of raw mesh node `raw`, if the node is on the body.
    pub fn local_of_raw(&self, raw: usize) -> Option<usize> {
        self.local_of_raw.get(raw).copied().filter(|&l| l != ABSENT)
    }

    /// Area of triangle `t`.
    pub fn area(&self, t: usize) -> f64 {
        let [a, b, c] = self.triangles[t];
        signed_area(self.nodes[a], self.nodes[b], self.nodes[c])
    }

    /// Largest triangle diameter (longest edge), length units.
    pub fn h(&self) -> f64 {
        self.triangles
            .iter()
            .map(|&[a, b, c]| {
                let (pa, pb, pc) = (self.nodes[a], self.nodes[b], self.nodes[c]);
                dist(pa, pb).max(dist(pb, pc)).max(dist(pc, pa))
            })
            .fold(0.0, f64::max)
    }
}
