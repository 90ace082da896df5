//! Exact intersection of two triangulations of the same body: every pair of overlapping
//! triangles is clipped (Sutherland-Hodgman, convex against convex) and the intersection
//! polygon is split into a fan of sub-triangles. On each sub-triangle a P1 field of either
//! mesh is linear and a P0 field constant, so error integrals there are exact with a rule
//! exact for quadratics (edge midpoints).
//!
//! Written by hand: no maintained crate does mesh-mesh intersection of 2D triangulations.

/// Triangle vertices.
pub type Tri = [[f64; 2]; 3];

/// One sub-triangle of the intersection of triangle `a` (first mesh) and `b` (second),
/// with the barycentric coordinates of its three edge midpoints in both.
#[derive(Debug, Clone)]
pub struct Overlap {
    /// Element of the first mesh.
    pub a: usize,
    /// Element of the second mesh.
    pub b: usize,
    /// Area of the sub-triangle.
    pub area: f64,
    /// Barycentric coordinates of the edge midpoints in element `a`.
    pub bary_a: [[f64; 3]; 3],
    /// Barycentric coordinates of the edge midpoints in element `b`.
    pub bary_b: [[f64; 3]; 3],
}

fn cross(o: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// Intersection polygon of two counter-clockwise triangles (possibly empty).
pub fn clip(subject: &Tri, clipper: &Tri) -> Vec<[f64; 2]> {
    let mut poly: Vec<[f64; 2]> = subject.to_vec();
    for e in 0..3 {
        let (p, q) = (clipper[e], clipper[(e + 1) % 3]);
        let len2 = (q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2);
        // Points within round-off of the edge count as inside, so shared edges of nested
        // meshes do not produce slivers.
        let tol = 1e-13 * len2;
        let inside = |x: [f64; 2]| cross(p, q, x) >= -tol;
        let input = std::mem::take(&mut poly);
        if input.is_empty() {
            break;
        }
        for i in 0..input.len() {
            let cur = input[i];
            let prev = input[(i + input.len() - 1) % input.len()];
            let (ci, pi) = (inside(cur), inside(prev));
            if ci != pi {
                let (dp, dc) = (cross(p, q, prev), cross(p, q, cur));
                let t = dp / (dp - dc);
                poly.push([
                    prev[0] + t * (cur[0] - prev[0]),
                    prev[1] + t * (cur[1] - prev[1]),
                ]);
            }
            if ci {
                poly.push(cur);
            }
        }
    }
    poly
}

/// Barycentric coordinates of `x` in triangle `t`.
pub fn barycentric(t: &Tri, x: [f64; 2]) -> [f64; 3] {
    let d = cross(t[0], t[1], t[2]);
    let l1 = cross(t[0], x, t[2]) / d;
    let l2 = cross(t[0], t[1], x) / d;
    [1.0 - l1 - l2, l1, l2]
}

/// A uniform bucket grid over triangles' bounding boxes for overlap candidates.
struct Grid {
    x0: [f64; 2],
    cell: f64,
    n: [usize; 2],
    buckets: Vec<Vec<usize>>,
}

fn bbox(t: &Tri) -> ([f64; 2], [f64; 2]) {
    let mut lo = t[0];
    let mut hi = t[0];
    for p in &t[1..] {
        for c in 0..2 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
    }
    (lo, hi)
}

impl Grid {
    fn new(tris: &[Tri]) -> Self {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for t in tris {
            let (a, b) = bbox(t);
            for c in 0..2 {
                lo[c] = lo[c].min(a[c]);
                hi[c] = hi[c].max(b[c]);
            }
        }
        let area = ((hi[0] - lo[0]) * (hi[1] - lo[1])).max(f64::MIN_POSITIVE);
        let cell = (area / tris.len().max(1) as f64).sqrt() * 1.5;
        let n = [
            ((hi[0] - lo[0]) / cell).ceil().max(1.0) as usize,
            ((hi[1] - lo[1]) / cell).ceil().max(1.0) as usize,
        ];
        let mut g = Grid {
            x0: lo,
            cell,
            n,
            buckets: vec![Vec::new(); n[0] * n[1]],
        };
        for (i, t) in tris.iter().enumerate() {
            let (a, b) = bbox(t);
            let (i0, j0) = g.index(a);
            let (i1, j1) = g.index(b);
            for ii in i0..=i1 {
                for jj in j0..=j1 {
                    g.buckets[jj * g.n[0] + ii].push(i);
                }
            }
        }
        g
    }
    fn index(&self, p: [f64; 2]) -> (usize, usize) {
        let i = ((p[0] - self.x0[0]) / self.cell)
            .floor()
            .clamp(0.0, (self.n[0] - 1) as f64) as usize;
        let j = ((p[1] - self.x0[1]) / self.cell)
            .floor()
            .clamp(0.0, (self.n[1] - 1) as f64) as usize;
        (i, j)
    }
}

/// All overlaps between triangulations `ta` and `tb` of the same region.
pub fn intersect(ta: &[Tri], tb: &[Tri]) -> Vec<Overlap> {
    let grid = Grid::new(tb);
    let mut out = Vec::new();
    let mut seen = vec![usize::MAX; tb.len()];
    for (ia, a) in ta.iter().enumerate() {
        let (lo, hi) = bbox(a);
        let (i0, j0) = grid.index(lo);
        let (i1, j1) = grid.index(hi);
        let area_a = 0.5 * cross(a[0], a[1], a[2]);
        for ii in i0..=i1 {
            for jj in j0..=j1 {
                for &ib in &grid.buckets[jj * grid.n[0] + ii] {
                    if seen[ib] == ia {
                        continue;
                    }
                    seen[ib] = ia;
                    let b = &tb[ib];
                    let (blo, bhi) = bbox(b);
                    if blo[0] > hi[0] || bhi[0] < lo[0] || blo[1] > hi[1] || bhi[1] < lo[1] {
                        continue;
                    }
                    let poly = clip(a, b);
                    if poly.len() < 3 {
                        continue;
                    }
                    for k in 1..poly.len() - 1 {
                        let s = [poly[0], poly[k], poly[k + 1]];
                        let area = 0.5 * cross(s[0], s[1], s[2]);
                        if area <= 1e-15 * area_a {
                            continue;
                        }
                        let mids = [
                            [0.5 * (s[0][0] + s[1][0]), 0.5 * (s[0][1] + s[1][1])],
                            [0.5 * (s[1][0] + s[2][0]), 0.5 * (s[1][1] + s[2][1])],
                            [0.5 * (s[2][0] + s[0][0]), 0.5 * (s[2][1] + s[0][1])],
                        ];
                        out.push(Overlap {
                            a: ia,
                            b: ib,
                            area,
                            bary_a: mids.map(|m| barycentric(a, m)),
                            bary_b: mids.map(|m| barycentric(b, m)),
                        });
                    }
                }
            }
        }
    }
    out
}
