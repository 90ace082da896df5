//! Errors between a study solution and a reference solution on different meshes of the
//! same bodies, integrated exactly over the intersection of the two triangulations.

use super::field::{P1Field, PressureProfile};
use super::intersect::{Overlap, Tri, intersect};
use crate::contact::Interface;
use crate::fe::Model;
use nalgebra::Matrix2;

/// The overlaps of a study model with a reference model, per body, with global element
/// indices.
pub struct Comparison {
    overlaps: Vec<Overlap>,
}

fn body_tris(m: &Model, b: usize) -> (Vec<Tri>, Vec<usize>) {
    let mut tris = Vec::new();
    let mut ids = Vec::new();
    for (i, e) in m.elements.iter().enumerate() {
        if e.body == b {
            tris.push(e.nodes.map(|n| m.position(n)));
            ids.push(i);
        }
    }
    (tris, ids)
}

/// Squared norms at one time step, summed over both bodies.
#[derive(Debug, Clone, Copy, Default)]
pub struct SquaredNorms {
    /// ||u||_L2^2 (length^2 area).
    pub l2_u: f64,
    /// |u|_H1^2.
    pub semi_u: f64,
    /// ||sigma||_L2^2 (tensor norm).
    pub stress: f64,
}

impl SquaredNorms {
    /// ||u||_H1 + ||sigma||_L2, the quantity of Theorem 3.1.
    pub fn theorem(&self) -> f64 {
        (self.l2_u + self.semi_u).sqrt() + self.stress.sqrt()
    }
    /// ||u||_H1.
    pub fn h1(&self) -> f64 {
        (self.l2_u + self.semi_u).sqrt()
    }
}

fn tensor_norm2(s: &nalgebra::Vector3<f64>) -> f64 {
    s[0] * s[0] + s[1] * s[1] + 2.0 * s[2] * s[2]
}

fn grad(m: &Model, e: usize, u: &[f64]) -> Matrix2<f64> {
    let el = &m.elements[e];
    let mut g = Matrix2::zeros();
    for a in 0..3 {
        for c in 0..2 {
            for d in 0..2 {
                g[(c, d)] += u[2 * el.nodes[a] + c] * el.grads[a][d];
            }
        }
    }
    g
}

/// Norms of a field on its own mesh (exact P1 mass integrals).
pub fn norms(m: &Model, s: &P1Field) -> SquaredNorms {
    let mut n = SquaredNorms::default();
    for (i, e) in m.elements.iter().enumerate() {
        for c in 0..2 {
            let v = e.nodes.map(|k| s.u[2 * k + c]);
            let sum: f64 = v.iter().sum();
            let sq: f64 = v.iter().map(|x| x * x).sum();
            n.l2_u += e.area / 12.0 * (sq + sum * sum);
        }
        n.semi_u += e.area * grad(m, i, &s.u).norm_squared();
        n.stress += e.area * tensor_norm2(&s.stress[i]);
    }
    n
}

impl Comparison {
    /// Intersect the triangulations of `study` and `reference`, body by body.
    pub fn new(study: &Model, reference: &Model) -> Self {
        let mut overlaps = Vec::new();
        for b in 0..2 {
            let (ta, ia) = body_tris(study, b);
            let (tb, ib) = body_tris(reference, b);
            for mut o in intersect(&ta, &tb) {
                o.a = ia[o.a];
                o.b = ib[o.b];
                overlaps.push(o);
            }
        }
        Comparison { overlaps }
    }

    /// Total area of the overlaps (equals the bodies' area when the meshes cover the same
    /// region).
    pub fn area(&self) -> f64 {
        self.overlaps.iter().map(|o| o.area).sum()
    }

    /// Squared norms of the difference (study - reference) at one time step.
    pub fn difference(
        &self,
        study: &Model,
        s: &P1Field,
        reference: &Model,
        r: &P1Field,
    ) -> SquaredNorms {
        let gs: Vec<Matrix2<f64>> = (0..study.elements.len())
            .map(|e| grad(study, e, &s.u))
            .collect();
        let gr: Vec<Matrix2<f64>> = (0..reference.elements.len())
            .map(|e| grad(reference, e, &r.u))
            .collect();
        let mut n = SquaredNorms::default();
        for o in &self.overlaps {
            let (ea, eb) = (&study.elements[o.a], &reference.elements[o.b]);
            let mut l2 = 0.0;
            for m in 0..3 {
                for c in 0..2 {
                    let ua: f64 = (0..3)
                        .map(|k| o.bary_a[m][k] * s.u[2 * ea.nodes[k] + c])
                        .sum();
                    let ub: f64 = (0..3)
                        .map(|k| o.bary_b[m][k] * r.u[2 * eb.nodes[k] + c])
                        .sum();
                    l2 += (ua - ub).powi(2);
                }
            }
            n.l2_u += o.area / 3.0 * l2;
            n.semi_u += o.area * (gs[o.a] - gr[o.b]).norm_squared();
            n.stress += o.area * tensor_norm2(&(s.stress[o.a] - r.stress[o.b]));
        }
        n
    }

    /// ||sigma - sigma_ref||^2 over the overlaps of the study triangles marked in `band`.
    pub fn band_stress(&self, s: &P1Field, r: &P1Field, band: &[bool]) -> f64 {
        self.overlaps
            .iter()
            .filter(|o| band[o.a])
            .map(|o| o.area * tensor_norm2(&(s.stress[o.a] - r.stress[o.b])))
            .sum()
    }

    /// Integral over the overlaps of a function of position evaluated exactly for
    /// polynomials of degree <= 2 (used by the tests).
    pub fn integrate(&self, study: &Model, f: impl Fn([f64; 2]) -> f64) -> f64 {
        self.overlaps
            .iter()
            .map(|o| {
                let el = &study.elements[o.a];
                let p = el.nodes.map(|n| study.position(n));
                let sum: f64 = (0..3)
                    .map(|m| {
                        let x =
                            [0, 1].map(|c| (0..3).map(|k| o.bary_a[m][k] * p[k][c]).sum::<f64>());
                        f(x)
                    })
                    .sum();
                o.area / 3.0 * sum
            })
            .sum()
    }
}

fn profile_on(interface: &Interface, piece: usize, profile: &[([f64; 2], f64)]) -> Vec<(f64, f64)> {
    let pc = &interface.pieces[piece];
    let mut v: Vec<(f64, f64)> = profile
        .iter()
        .map(|(x, p)| (pc.abscissa_of(*x).0, *p))
        .collect();
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    v
}

/// The piecewise-linear function through sorted points `f` at `x` (constant beyond the
/// ends).
pub fn eval_pl(f: &[(f64, f64)], x: f64) -> f64 {
    if f.len() == 1 {
        return f[0].1;
    }
    let k = f.partition_point(|p| p.0 <= x).clamp(1, f.len() - 1);
    let (a, b) = (f[k - 1], f[k]);
    let t = if b.0 > a.0 {
        ((x - a.0) / (b.0 - a.0)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    a.1 + t * (b.1 - a.1)
}

/// The piecewise-linear function through sorted points `f` at `x`, on the segment of `f`
/// that holds `inside` (a point strictly inside a sub-interval that has `x` at an end): the
/// one-sided value at a jump of `f` (two points at one abscissa). Without a jump it is
/// [`eval_pl`]'s value to the last bit: eval_pl's own where it picks the same segment, else
/// x is a node of `f` and eval_pl gives that node's value (t = 0 on the next segment).
pub fn eval_pl_within(f: &[(f64, f64)], x: f64, inside: f64) -> f64 {
    if f.len() == 1 {
        return f[0].1;
    }
    let k = f.partition_point(|p| p.0 <= inside).clamp(1, f.len() - 1);
    // The segment eval_pl picks for x itself: the same one, eval_pl's value.
    if f.partition_point(|p| p.0 <= x).clamp(1, f.len() - 1) == k {
        return eval_pl(f, x);
    }
    let (a, b) = (f[k - 1], f[k]);
    if x == a.0 {
        return a.1;
    }
    if x == b.0 {
        return b.1;
    }
    eval_pl(&f[k - 1..=k], x)
}

/// Points (position, value) projected on each study piece, sorted and deduplicated.
pub fn project(study: &Interface, points: &[([f64; 2], f64)]) -> Vec<Vec<(f64, f64)>> {
    study
        .pieces
        .iter()
        .map(|piece| {
            let tol = 1e-9 * piece.length;
            let mut f: Vec<(f64, f64)> = points
                .iter()
                .filter_map(|&(x, p)| {
                    let (s, off) = piece.abscissa_of(x);
                    (off <= tol && s >= -tol && s <= piece.length + tol)
                        .then_some((s.clamp(0.0, piece.length), p))
                })
                .collect();
            f.sort_by(|a, b| a.0.total_cmp(&b.0));
            // Points at one abscissa are one point, but for a jump inside the piece (two
            // values at one position: a piecewise-constant pressure).
            let interior = |s: f64| s > tol && s < piece.length - tol;
            f.dedup_by(|a, b| {
                (a.0 - b.0).abs() <= 1e-12 * piece.length && !(interior(b.0) && a.1 != b.1)
            });
            f
        })
        .collect()
}

/// (||p - p_ref||^2, ||p_ref||^2) in L2(Gamma_C), exact for the piecewise-linear profiles
/// `study` on the pieces of `interface` and `reference` (anywhere on Gamma_C: its points are
/// matched to the study's pieces by their geometry).
pub fn pressure_difference(
    interface: &Interface,
    study: &PressureProfile,
    reference: &PressureProfile,
) -> (f64, f64) {
    // The reference's points that lie on each study piece.
    let references = project(interface, &reference.concat());
    let (mut diff, mut norm) = (0.0, 0.0);
    for (i, piece) in interface.pieces.iter().enumerate() {
        let fs = profile_on(interface, i, &study[i]);
        let fr = &references[i];
        if fs.len() < 2 || fr.len() < 2 {
            continue;
        }
        let mut br: Vec<f64> = fs.iter().chain(fr.iter()).map(|p| p.0).collect();
        br.sort_by(f64::total_cmp);
        br.dedup_by(|a, b| (*a - *b).abs() <= 1e-14 * piece.length);
        for w in br.windows(2) {
            let (a, b) = (w[0], w[1]);
            let m = 0.5 * (a + b);
            // Each profile's piece that holds the sub-interval (one-sided at a jump).
            let d = |x: f64| eval_pl_within(&fs, x, m) - eval_pl_within(&fr, x, m);
            diff += (b - a) / 6.0 * (d(a).powi(2) + 4.0 * d(m).powi(2) + d(b).powi(2));
            let q = |x: f64| eval_pl_within(&fr, x, m);
            norm += (b - a) / 6.0 * (q(a).powi(2) + 4.0 * q(m).powi(2) + q(b).powi(2));
        }
    }
    (diff, norm)
}

/// Norms of the difference `a - b` of two fields on the same mesh (a time study's error).
pub fn norms_of_difference(m: &Model, a: &P1Field, b: &P1Field) -> SquaredNorms {
    let d = P1Field {
        time: a.time,
        u: a.u.iter().zip(b.u.iter()).map(|(x, y)| x - y).collect(),
        stress: a
            .stress
            .iter()
            .zip(b.stress.iter())
            .map(|(x, y)| x - y)
            .collect(),
        pressure: None,
        pressure_space: super::field::PressureSpace::Linear,
    };
    norms(m, &d)
}
