//! Errors of a study solution against a scene's exact solution, integrated on the study's
//! own mesh by a collapsed Gauss rule per triangle (n x n points, exact to degree 2n - 2)
//! and Gauss-Legendre on Gamma_C's segments (2n points, degree 4n - 1): the exact fields are
//! not polynomials, so the rule is chosen with its own error far below the errors measured
//! (a test doubles it). A triangle or segment that a kink of the exact fields crosses (an
//! `abs` changing branch) is split along it and the rule applied on each piece, as the
//! loads are ([`crate::quadrature::triangle_rule`]): one implementation for both.

use super::field::{P1Field, PressureProfile, PressureSpace};
use super::norms::SquaredNorms;
use super::pressure_l2::{self, SegmentPressure, along};
use crate::analytical::Exact;
use crate::contact::Interface;
use crate::expr::{Expr, Program, compile, kink_functions};
use crate::fe::Model;
use crate::quadrature;

/// Gauss points per direction of the default rule (16 points per triangle, degree 6).
pub const DEFAULT_POINTS: usize = quadrature::DEFAULT_POINTS;

/// An exact solution with the quadrature that measures against it.
pub struct ExactComparison<'a> {
    exact: &'a Exact,
    triangle: Vec<(f64, f64, f64)>,
    segment: Vec<(f64, f64)>,
    /// Each body's exact fields compiled together.
    fields: [BodyFields; 2],
}

/// One body's exact displacement, gradient and stress compiled into one program (they
/// share their subexpressions), and its singular part's into another: outputs u_x, u_y,
/// du_x/dx, du_x/dy, du_y/dx, du_y/dy where the displacement is given, then s11, s22, s12
/// where the stress is.
struct BodyFields {
    whole: Program,
    singular: Option<Program>,
    displacement: bool,
    stress: bool,
}

impl BodyFields {
    fn new(ex: &Exact, b: usize) -> Self {
        let displacement = ex.displacement.is_some() && ex.gradient.is_some();
        let stress = ex.stress.is_some();
        let outputs = |u: Option<&[Expr; 2]>, g: Option<&[[Expr; 2]; 2]>, s: Option<&[Expr; 3]>| {
            let mut out: Vec<&Expr> = Vec::new();
            if let (Some(u), Some(g)) = (u, g) {
                out.extend(u.iter());
                out.extend(g.iter().flatten());
            }
            out.extend(s.into_iter().flatten());
            compile(&out).expect("every scene expression compiles (test_compiled_expressions)")
        };
        let whole = outputs(
            ex.displacement.as_ref().map(|u| &u[b]),
            ex.gradient.as_ref().map(|g| &g[b]),
            ex.stress.as_ref().map(|s| &s[b]),
        );
        let singular = ex.singular.as_ref().map(|sg| {
            outputs(
                Some(&sg.displacement[b]).filter(|_| displacement),
                Some(&sg.gradient[b]).filter(|_| displacement),
                Some(&sg.stress[b]).filter(|_| stress),
            )
        });
        BodyFields {
            whole,
            singular,
            displacement,
            stress,
        }
    }

    /// The fields at `x` into `values`, and their singular parts into `parts` where
    /// `split` (zeros otherwise).
    fn eval(
        &self,
        x: [f64; 2],
        t: f64,
        split: bool,
        registers: &mut Vec<f64>,
        values: &mut [f64],
        parts: &mut [f64],
    ) {
        self.whole.eval_point(x[0], x[1], t, registers, values);
        match self.singular.as_ref().filter(|_| split) {
            Some(program) => program.eval_point(x[0], x[1], t, registers, parts),
            None => parts.fill(0.0),
        }
    }

    /// Where the stress starts among the outputs.
    fn stress_at(&self) -> usize {
        if self.displacement { 6 } else { 0 }
    }
}

/// What one field measured against the exact solution at its time.
#[derive(Debug, Clone, Copy, Default)]
pub struct ExactDifference {
    /// Squared norms of (solution - exact).
    pub difference: SquaredNorms,
    /// Squared norms of the exact solution.
    pub exact: SquaredNorms,
    /// (||p_h - p||^2, ||p||^2) on Gamma_C; `None` when the field gives no pressure.
    pub pressure: Option<(f64, f64)>,
    /// Largest |u| component of the exact solution at the mesh's nodes.
    pub max_displacement: f64,
    /// ||sigma - sigma_ex||^2 on the band of triangles touching Gamma_C.
    pub band_stress: f64,
    /// int sigma : eps(u) of the exact solution over both bodies (its energy, stress x
    /// area); 0 where the exact solution gives no displacement and stress.
    pub energy: f64,
}

/// The part of a product a b that one rule takes, each factor given as (whole, singular
/// part) at a singular point: the smooth rest times the smooth rest (power 0), the cross
/// terms (power gamma), the singular parts' product (power 2 gamma).
#[derive(Debug, Clone, Copy)]
pub enum Split {
    /// The whole product (no singular point, or a triangle away from it).
    Whole,
    /// (a - a_s)(b - b_s).
    Smooth,
    /// (a - a_s) b_s + a_s (b - b_s).
    Cross,
    /// a_s b_s.
    Singular,
}

/// What the rule of each power in `ExactComparison::difference` takes, for the
/// displacement's integrands and for the gradient's and stress's: powers 0, beta - 1, beta,
/// 2 beta - 2, 2 beta of r.
const SPLIT_PARTS: [(Option<Split>, Option<Split>); 5] = [
    (Some(Split::Smooth), Some(Split::Smooth)),
    (None, Some(Split::Cross)),
    (Some(Split::Cross), None),
    (None, Some(Split::Singular)),
    (Some(Split::Singular), None),
];

impl Split {
    /// The part `self` of the product a b, each factor as (whole, singular part).
    pub fn product(self, (a, a_s): (f64, f64), (b, b_s): (f64, f64)) -> f64 {
        match self {
            Split::Whole => a * b,
            Split::Smooth => (a - a_s) * (b - b_s),
            Split::Cross => (a - a_s) * b_s + a_s * (b - b_s),
            Split::Singular => a_s * b_s,
        }
    }

    /// The part `self` of a^2 (a's singular part a_s).
    pub fn square(self, a: f64, a_s: f64) -> f64 {
        self.product((a, a_s), (a, a_s))
    }

    /// `w` times [`Split::square`]; the whole one as (w a) a, the order the exact norms have
    /// always been summed in, so that scenes without a singular part keep their digits.
    pub fn weighted_square(self, w: f64, a: f64, a_s: f64) -> f64 {
        match self {
            Split::Whole => w * a * a,
            _ => w * self.square(a, a_s),
        }
    }
}

/// The gradient d u_c / d x_d of the P1 displacement with nodal values `uh` on a triangle
/// whose shape functions have the gradients `grads`.
fn p1_gradient(uh: &[[f64; 2]; 3], grads: &[[f64; 2]; 3]) -> [[f64; 2]; 2] {
    let mut grad_h = [[0.0; 2]; 2];
    for a in 0..3 {
        for c in 0..2 {
            for d in 0..2 {
                grad_h[c][d] += uh[a][c] * grads[a][d];
            }
        }
    }
    grad_h
}

/// sigma : eps(u) = s11 e11 + s22 e22 + 2 s12 e12 of the exact stress (whole `se`,
/// singular part `ss`) and gradient `g` (each entry as (whole, singular part)), its part `p`.
fn energy_density(p: Split, se: [f64; 3], ss: [f64; 3], g: [[(f64, f64); 2]; 2]) -> f64 {
    let eps = [
        g[0][0],
        g[1][1],
        (g[0][1].0 + g[1][0].0, g[0][1].1 + g[1][0].1),
    ];
    (0..3)
        .map(|k| p.product((se[k], ss[k]), eps[k]))
        .sum::<f64>()
}

/// s11^2 + s22^2 + 2 s12^2, its part `p`, each component as (whole, singular part).
fn tensor_square(p: Split, s: [(f64, f64); 3]) -> f64 {
    p.product(s[0], s[0]) + p.product(s[1], s[1]) + 2.0 * p.product(s[2], s[2])
}

impl<'a> ExactComparison<'a> {
    /// Measure against `exact` with `points` Gauss points per direction on triangles (and
    /// 2 `points` on segments).
    pub fn new(exact: &'a Exact, points: usize) -> Self {
        ExactComparison {
            exact,
            triangle: quadrature::triangle(points),
            segment: quadrature::gauss_legendre(2 * points),
            fields: [0, 1].map(|b| BodyFields::new(exact, b)),
        }
    }

    /// Everything one field on `m` (with Gamma_C `interface`) measures against the exact
    /// solution at the field's time.
    pub fn difference(&self, m: &Model, interface: &Interface, s: &P1Field) -> ExactDifference {
        let (ex, t) = (self.exact, s.time);
        let mut out = ExactDifference {
            pressure: s
                .pressure
                .as_ref()
                .map(|p| self.pressure_difference(interface, p, t)),
            ..Default::default()
        };
        let band = super::contact_error::band(m, interface);
        let kinks = [0, 1].map(|b| kink_functions(&ex.kinks(b), t));
        let singular = ex.singular.as_ref();
        let beta = singular.map_or(1.0, |sg| sg.exponent);
        // The powers of r of SPLIT_PARTS's rules.
        let powers = [0.0, beta - 1.0, beta, 2.0 * beta - 2.0, 2.0 * beta];
        let point = singular.map(|sg| sg.point);
        let (mut registers, mut values, mut parts) = (Vec::new(), [0.0; 9], [0.0; 9]);
        for (i, el) in m.elements.iter().enumerate() {
            let b = el.body;
            let pos = el.nodes.map(|n| m.position(n));
            let uh = el.nodes.map(|n| [s.u[2 * n], s.u[2 * n + 1]]);
            let grad_h = p1_gradient(&uh, &el.grads);
            let sh = [s.stress[i][0], s.stress[i][1], s.stress[i][2]];
            for (part, rule) in
                quadrature::singular::rules(pos, &kinks[b], &self.triangle, point, &powers)
            {
                // Which part of each integrand this rule takes: the displacement's terms
                // (powers 0, beta, 2 beta) and the gradient's and stress's (0, beta - 1,
                // 2 beta - 2) split alike; None where the rule takes all of it.
                let (u_part, g_part) = match part {
                    None => (Some(Split::Whole), Some(Split::Whole)),
                    Some(k) => SPLIT_PARTS[k],
                };
                for &(l1, l2, w) in rule.iter() {
                    let lam = [1.0 - l1 - l2, l1, l2];
                    let x = [0, 1].map(|c| (0..3).map(|a| lam[a] * pos[a][c]).sum::<f64>());
                    let w = w * el.area;
                    let sing = singular.filter(|_| part.is_some());
                    // The exact fields at x (and their singular parts where this rule
                    // splits them), one program per body.
                    let fields = &self.fields[b];
                    fields.eval(
                        x,
                        t,
                        sing.is_some(),
                        &mut registers,
                        &mut values,
                        &mut parts,
                    );
                    let mut grad_e = None;
                    if fields.displacement {
                        let mut ge_all = [[(0.0, 0.0); 2]; 2];
                        for c in 0..2 {
                            let (ue, us) = (values[c], parts[c]);
                            let uhc: f64 = (0..3).map(|a| lam[a] * uh[a][c]).sum();
                            if let Some(p) = u_part {
                                out.difference.l2_u += w * p.square(uhc - ue, -us);
                                out.exact.l2_u += p.weighted_square(w, ue, us);
                            }
                            for d in 0..2 {
                                let (ge, gs) = (values[2 + 2 * c + d], parts[2 + 2 * c + d]);
                                if let Some(p) = g_part {
                                    out.difference.semi_u += w * p.square(grad_h[c][d] - ge, -gs);
                                    out.exact.semi_u += p.weighted_square(w, ge, gs);
                                }
                                ge_all[c][d] = (ge, gs);
                            }
                        }
                        grad_e = Some(ge_all);
                    }
                    let Some(p) = g_part else { continue };
                    if fields.stress {
                        let k0 = fields.stress_at();
                        let se = [0, 1, 2].map(|k| values[k0 + k]);
                        let ss = [0, 1, 2].map(|k| parts[k0 + k]);
                        if let Some(g) = grad_e {
                            out.energy += w * energy_density(p, se, ss, g);
                        }
                        let dk = [0, 1, 2].map(|k| (sh[k] - se[k], -ss[k]));
                        let (d, n) = (
                            tensor_square(p, dk),
                            tensor_square(p, [0, 1, 2].map(|k| (se[k], ss[k]))),
                        );
                        out.difference.stress += w * d;
                        out.exact.stress += w * n;
                        if band[i] {
                            out.band_stress += w * d;
                        }
                    }
                }
            }
        }
        out.max_displacement = max_exact_displacement(m, ex, t);
        out
    }

    /// (||p_h - p||^2, ||p||^2) in L2(Gamma_C), p_h linear between the profile's points (a
    /// jump where two points share a position).
    fn pressure_difference(
        &self,
        interface: &Interface,
        pressure: &PressureProfile,
        t: f64,
    ) -> (f64, f64) {
        let kinks = kink_functions(&self.exact.contact_kinks(), t);
        let (mut diff, mut norm) = (0.0, 0.0);
        for (piece, profile) in interface.pieces.iter().zip(pressure) {
            let on = ExactOnPiece {
                cmp: self,
                normal: piece.normal,
                kinks: &kinks,
                t,
            };
            (diff, norm) = pressure_l2::piece_difference(&on, profile, (diff, norm));
        }
        (diff, norm)
    }

    /// The exact pressure's quadrature on one segment a -> b of Gamma_C with outward normal
    /// `n` at time `t`: `visit(q, w, p, p_s, part)` at each point a + q (b - a), w its
    /// weight times the length, p the exact pressure and p_s its singular part, `part` which
    /// part of a product the rule takes ([`Split`]). Away from the singular point one rule
    /// takes the whole product (split at the pressure's kinks); a segment from the singular
    /// point splits p = p_rest + p_s (p_s ~ r^(beta-1)) and each part of a product has its
    /// own Gauss-Jacobi rule.
    fn segment_points(
        &self,
        n: [f64; 2],
        xa: [f64; 2],
        xb: [f64; 2],
        kinks: &[crate::expr::KinkFunction],
        t: f64,
        visit: &mut dyn FnMut(f64, f64, f64, f64, Split),
    ) {
        let len = (xb[0] - xa[0]).hypot(xb[1] - xa[1]);
        let exact_at = |x: [f64; 2]| self.exact.pressure_at(n, x[0], x[1], t).unwrap_or(f64::NAN);
        let from_point = self.exact.singular.as_ref().and_then(|sg| {
            let is_c = |x: [f64; 2]| sg.distance(x[0], x[1]) <= 1e-12 * len;
            (is_c(xa) || is_c(xb)).then_some((sg, is_c(xb)))
        });
        let Some((sg, reversed)) = from_point else {
            for &(q, wq) in quadrature::segment_rule(xa, xb, kinks, &self.segment).iter() {
                visit(q, wq * len, exact_at(along(xa, xb, q)), 0.0, Split::Whole);
            }
            return;
        };
        let singular_at = |x: [f64; 2]| {
            let st = sg.stress[0].each_ref().map(|e| e.eval(x[0], x[1], t));
            -(n[0] * n[0] * st[0] + n[1] * n[1] * st[1] + 2.0 * n[0] * n[1] * st[2])
        };
        let (beta, points) = (sg.exponent, quadrature::singular::accuracy().points);
        for (alpha, part) in [
            (0.0, Split::Smooth),
            (beta - 1.0, Split::Cross),
            (2.0 * beta - 2.0, Split::Singular),
        ] {
            for (r, wq) in quadrature::singular::segment_from(alpha, points) {
                let q = if reversed { 1.0 - r } else { r };
                let x = along(xa, xb, q);
                visit(q, wq * len, exact_at(x), singular_at(x), part);
            }
        }
    }

    /// The best approximation of the exact pressure at time `t` in the space of `profile`
    /// ([`PressureSpace`]): its L2(Gamma_C) projection, as a profile on the same points
    /// ([`pressure_l2::piece_projection`]).
    pub fn best_pressure(
        &self,
        interface: &Interface,
        profile: &PressureProfile,
        space: PressureSpace,
        t: f64,
    ) -> PressureProfile {
        let kinks = kink_functions(&self.exact.contact_kinks(), t);
        interface
            .pieces
            .iter()
            .zip(profile)
            .map(|(piece, points)| {
                let on = ExactOnPiece {
                    cmp: self,
                    normal: piece.normal,
                    kinks: &kinks,
                    t,
                };
                let x: Vec<[f64; 2]> = points.iter().map(|p| p.0).collect();
                let values = pressure_l2::piece_projection(&on, &x, space);
                x.into_iter().zip(values).collect()
            })
            .collect()
    }

    /// ||Pi p - p||^2 in L2(Gamma_C) at time `t`, Pi the projection onto the space of
    /// `profile` ([`ExactComparison::best_pressure`]).
    pub fn best_pressure_error(
        &self,
        interface: &Interface,
        profile: &PressureProfile,
        space: PressureSpace,
        t: f64,
    ) -> f64 {
        let best = self.best_pressure(interface, profile, space, t);
        self.pressure_difference(interface, &best, t).0
    }
}

/// The exact pressure on one straight piece of Gamma_C (outward normal `normal`) at time
/// `t`, as the L2 integrals of [`pressure_l2`] read it.
struct ExactOnPiece<'a> {
    cmp: &'a ExactComparison<'a>,
    normal: [f64; 2],
    kinks: &'a [crate::expr::KinkFunction<'a>],
    t: f64,
}

impl SegmentPressure for ExactOnPiece<'_> {
    fn segment_points(
        &self,
        xa: [f64; 2],
        xb: [f64; 2],
        visit: &mut dyn FnMut(f64, f64, f64, f64, Split),
    ) {
        self.cmp
            .segment_points(self.normal, xa, xb, self.kinks, self.t, visit);
    }
    fn singular_point(&self) -> Option<[f64; 2]> {
        self.cmp.exact.singular.as_ref().map(|sg| sg.point)
    }
}

/// The exact pressure and gap along Gamma_C at time `t`, at 401 points per piece:
/// (x, y, pressure, gap); a field the solution does not give is NaN.
pub fn exact_profiles(interface: &Interface, exact: &Exact, t: f64) -> Vec<([f64; 2], f64, f64)> {
    let mut out = Vec::new();
    for piece in &interface.pieces {
        let n = piece.normal;
        for k in 0..=400 {
            let s = piece.length * k as f64 / 400.0;
            let x = piece.point(s);
            let pressure = exact.pressure_at(n, x[0], x[1], t).unwrap_or(f64::NAN);
            let gap = exact.gap_at(n, x[0], x[1], t).unwrap_or(f64::NAN);
            out.push((x, pressure, gap));
        }
    }
    out
}

/// Largest |u| component of the exact solution at the nodes of `m` at time `t`.
pub fn max_exact_displacement(m: &Model, exact: &Exact, t: f64) -> f64 {
    let mut out = 0.0f64;
    for b in 0..2 {
        for x in &m.meshes[b].nodes {
            if let Some(u) = exact.displacement_at(b, x[0], x[1], t) {
                out = out.max(u[0].abs()).max(u[1].abs());
            }
        }
    }
    out
}
