//! Closed-form and manufactured solutions as first-class code: a scene's exact solution
//! (displacement and stress of each body, the contact pressure on Gamma_C), with what
//! follows from it by exact symbolic differentiation: the gradient, the stress of an
//! elastic body, and for a manufactured solution the body force f = -div sigma and, where
//! the stress is given with the displacement (a viscoplastic body), the constitutive source
//! s = d sigma/dt - E eps(du/dt) - G(sigma) (SPEC section 5, Roache's method of
//! manufactured solutions with a source in every equation the fields do not satisfy).
//!
//! [`stacked`] derives the closed form of the `stacked-exact` scene; [`singular`] the
//! `regularity` family, whose displacement has a part singular at a point ([`Singular`]);
//! [`lame`] the press fit of two annuli across a radial gap; [`hertz`] the line contact of a
//! cylinder on a half-space.

pub mod hertz;
pub mod lame;
pub mod singular;
pub mod stacked;

use crate::expr::Expr;
use crate::material::Material;

/// Displacement of one body: (u_x, u_y).
pub type Displacement = [Expr; 2];
/// Stress of one body: (s11, s22, s12).
pub type StressField = [Expr; 3];

/// The exact solution of a scene, per body (index 0 the slave, as in the scene).
#[derive(Debug, Clone)]
pub struct Exact {
    /// Displacement of each body (length), if given.
    pub displacement: Option<[Displacement; 2]>,
    /// d u_c / d x_d of each body: `gradient[b][c][d]`, derived from the displacement.
    pub gradient: Option<[[[Expr; 2]; 2]; 2]>,
    /// Stress of each body (stress units), given or derived from the displacement of an
    /// elastic body.
    pub stress: Option<[StressField; 2]>,
    /// Contact pressure on Gamma_C (force/length), if given; otherwise -sigma_nn of the
    /// slave's stress where the stress is known.
    pub pressure: Option<Expr>,
    /// Body force f = -div sigma of each body, for a manufactured solution.
    pub body_force: Option<[[Expr; 2]; 2]>,
    /// The part of the constitutive source that is linear in the fields,
    /// d sigma/dt - E eps(du/dt) of each body (stress per time), for a manufactured solution
    /// whose stress is given with its displacement; the source is this minus G(sigma)
    /// ([`Exact::source_at`]). None: the law needs no source (an elastic manufactured
    /// solution, whose stress is E eps(u)).
    pub source_rate: Option<[StressField; 2]>,
    /// s12 - s21 of a body whose stress was given as a full tensor with different
    /// off-diagonal texts: checked to vanish on the mesh before anything is solved.
    pub asymmetry: [Option<Expr>; 2],
    /// The part of the fields singular at a point, already included in the fields above;
    /// the integrals split each integrand by power of r there ([`Singular`]).
    pub singular: Option<Singular>,
    /// The scene's initial gap g0(x, y) on Gamma_C (`[contact] gap`), part of the exact
    /// gap ([`Exact::gap_at`]).
    pub initial_gap: Option<Expr>,
    /// Gamma_C's exact geometry (`[exact.contact]`): None, flat and touching.
    pub contact: Option<ContactMap>,
}

/// The exact contact geometry of a curved Gamma_C or of bodies apart: body 1's outward
/// normal nu(x) and the point m(x) of body 2's curve that x faces along it, as expressions
/// on body 1's curve (the press fit: nu = x / |x|, m = x (R + g0) / R).
#[derive(Debug, Clone)]
pub struct ContactMap {
    /// nu(x, y), normalised where it is read.
    pub normal: [Expr; 2],
    /// m(x, y) (length).
    pub master: [Expr; 2],
    /// d m_c / d x_d: `jacobian[c][d]`.
    pub jacobian: [[Expr; 2]; 2],
}

impl ContactMap {
    /// The map with its derivatives.
    pub fn new(normal: [Expr; 2], master: [Expr; 2]) -> Self {
        let jacobian = gradient(&master);
        ContactMap {
            normal,
            master,
            jacobian,
        }
    }

    /// nu at (x, y), a unit vector.
    pub fn normal_at(&self, x: f64, y: f64) -> [f64; 2] {
        let n = [
            self.normal[0].eval(x, y, 0.0),
            self.normal[1].eval(x, y, 0.0),
        ];
        let len = n[0].hypot(n[1]);
        [n[0] / len, n[1] / len]
    }

    /// m at (x, y).
    pub fn master_at(&self, x: f64, y: f64) -> [f64; 2] {
        [
            self.master[0].eval(x, y, 0.0),
            self.master[1].eval(x, y, 0.0),
        ]
    }

    /// |dm/ds| at (x, y): the length of body 2's curve per unit length of body 1's along
    /// the map (the tangent taken normal to nu), by which a master traction is multiplied
    /// to balance the slave's (p1 = p2 |dm/ds|; (R + g0) / R for the radial map).
    pub fn stretch_at(&self, x: f64, y: f64) -> f64 {
        let n = self.normal_at(x, y);
        let tau = [-n[1], n[0]];
        let j = self
            .jacobian
            .each_ref()
            .map(|r| r.each_ref().map(|e| e.eval(x, y, 0.0)));
        let d = [
            j[0][0] * tau[0] + j[0][1] * tau[1],
            j[1][0] * tau[0] + j[1][1] * tau[1],
        ];
        d[0].hypot(d[1])
    }
}

/// The part of an elastic manufactured solution singular at a point c: a displacement
/// O(r^beta) (r = |x - c|), its gradient and stress O(r^(beta-1)) and body force
/// O(r^(beta-2)), each r^power times a factor smooth along the rays from c. The exact
/// fields include it; what remains of them is smooth at c. Integrals on the triangles at c
/// integrate the remainder, the cross terms and the singular part's square each with
/// its own Gauss-Jacobi weight (`quadrature::singular`).
#[derive(Debug, Clone)]
pub struct Singular {
    /// The point c (length).
    pub point: [f64; 2],
    /// beta.
    pub exponent: f64,
    /// The singular part of each body's displacement.
    pub displacement: [Displacement; 2],
    /// The rest of it (smooth at c).
    pub smooth: [Displacement; 2],
    /// Its gradient `[b][c][d]`.
    pub gradient: [[[Expr; 2]; 2]; 2],
    /// Its stress (elastic).
    pub stress: [StressField; 2],
    /// Its body force -div sigma.
    pub body_force: [[Expr; 2]; 2],
}

impl Singular {
    /// The singular part `displacement` at `point` with exponent beta (`smooth` the rest of
    /// the displacement), its other fields derived for the elastic `materials`.
    pub fn new(
        point: [f64; 2],
        exponent: f64,
        displacement: [Displacement; 2],
        smooth: [Displacement; 2],
        materials: [&Material; 2],
    ) -> Self {
        let derived = per_body(|b| {
            let g = gradient(&displacement[b]);
            let s = elastic_stress(materials[b], &g);
            let f = body_force(&s);
            (g, s, f)
        });
        let [(g0, s0, f0), (g1, s1, f1)] = derived;
        let (gradient, stress, body_force) = ([g0, g1], [s0, s1], [f0, f1]);
        Singular {
            point,
            exponent,
            displacement,
            smooth,
            gradient,
            stress,
            body_force,
        }
    }

    /// Distance from c.
    pub fn distance(&self, x: f64, y: f64) -> f64 {
        (x - self.point[0]).hypot(y - self.point[1])
    }
}

/// `f` of body 0 and of body 1, side by side: exmex's symbolic derivatives of a
/// manufactured scene take tenths of a second per body (regularity family).
pub fn per_body<T: Send>(f: impl Fn(usize) -> T + Sync) -> [T; 2] {
    let (a, b) = rayon::join(|| f(0), || f(1));
    [a, b]
}

/// Two displacements added component by component.
pub fn add_displacements(a: &[Displacement; 2], b: &[Displacement; 2]) -> [Displacement; 2] {
    [0, 1].map(|l| [0, 1].map(|c| Expr::combine(&[(1.0, &a[l][c]), (1.0, &b[l][c])])))
}

/// What an exact solution gives, for messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Field {
    /// The displacement of both bodies.
    Displacement,
    /// The stress of both bodies.
    Stress,
    /// The contact pressure.
    Pressure,
}

impl Field {
    /// The key a scene's `[exact]` table gives it by.
    pub fn key(self) -> &'static str {
        match self {
            Field::Displacement => "exact.displacement",
            Field::Stress => "exact.stress",
            Field::Pressure => "exact.pressure",
        }
    }
}

/// The gradient of a displacement: `[c][d]` = d u_c / d x_d.
pub fn gradient(u: &Displacement) -> [[Expr; 2]; 2] {
    [0, 1].map(|c| [0, 1].map(|d| u[c].partial(d)))
}

/// The stress of an elastic body with displacement gradient `g`: sigma = a tr(eps) I + b eps
/// (b = E / (1 + nu); a = E nu / (1 - nu^2) in plane stress, Lame's lambda in plane strain:
/// [`crate::material::Elasticity::a`]).
pub fn elastic_stress(material: &Material, g: &[[Expr; 2]; 2]) -> StressField {
    let (a, b) = (material.elastic.a(), material.elastic.b());
    [
        Expr::combine(&[(a + b, &g[0][0]), (a, &g[1][1])]),
        Expr::combine(&[(a, &g[0][0]), (a + b, &g[1][1])]),
        Expr::combine(&[(0.5 * b, &g[0][1]), (0.5 * b, &g[1][0])]),
    ]
}

/// d sigma/dt - E eps(du/dt) of one body: the linear part of the constitutive source of a
/// manufactured solution with displacement gradient `g` and stress `s`.
pub fn source_rate(material: &Material, g: &[[Expr; 2]; 2], s: &StressField) -> StressField {
    let dg = g.each_ref().map(|row| row.each_ref().map(|e| e.partial(2)));
    let elastic_rate = elastic_stress(material, &dg);
    [0, 1, 2].map(|c| Expr::combine(&[(1.0, &s[c].partial(2)), (-1.0, &elastic_rate[c])]))
}

/// The body force that balances a stress field: f = -div sigma.
pub fn body_force(s: &StressField) -> [Expr; 2] {
    [
        Expr::combine(&[(-1.0, &s[0].partial(0)), (-1.0, &s[2].partial(1))]),
        Expr::combine(&[(-1.0, &s[2].partial(0)), (-1.0, &s[1].partial(1))]),
    ]
}

impl Exact {
    /// Complete what is given: the gradient of a given displacement, the stress of an
    /// elastic body from it (when not given), and for a manufactured solution the body
    /// forces and, where the stress is given with the displacement, the constitutive
    /// source. `materials` are the bodies' in scene order.
    pub fn new(
        displacement: Option<[Displacement; 2]>,
        stress: Option<[StressField; 2]>,
        pressure: Option<Expr>,
        manufactured: bool,
        materials: [&Material; 2],
    ) -> Self {
        let gradient = displacement.as_ref().map(|u| per_body(|b| gradient(&u[b])));
        let elastic = materials.iter().all(|m| m.viscoplastic.is_none());
        let stress_given = stress.is_some();
        let stress = stress.or_else(|| {
            let g = gradient.as_ref().filter(|_| elastic)?;
            Some([0, 1].map(|b| elastic_stress(materials[b], &g[b])))
        });
        let body_force = stress
            .as_ref()
            .filter(|_| manufactured)
            .map(|s| per_body(|b| body_force(&s[b])));
        let source_rate = match (&gradient, &stress) {
            (Some(g), Some(s)) if manufactured && stress_given => {
                Some([0, 1].map(|b| source_rate(materials[b], &g[b], &s[b])))
            }
            _ => None,
        };
        Exact {
            displacement,
            gradient,
            stress,
            pressure,
            body_force,
            source_rate,
            asymmetry: [None, None],
            singular: None,
            initial_gap: None,
            contact: None,
        }
    }

    /// The exact solution whose fields are `smooth`'s (derived from the smooth part of the
    /// displacement) plus `singular`'s, field by field; `displacement` is their sum, given.
    pub fn with_singular(
        displacement: Option<[Displacement; 2]>,
        pressure: Option<Expr>,
        smooth: Exact,
        singular: Singular,
    ) -> Self {
        let add = |a: &Expr, b: &Expr| Expr::combine(&[(1.0, a), (1.0, b)]);
        let gradient = smooth.gradient.as_ref().map(|g| {
            [0, 1].map(|b| {
                [0, 1].map(|c| [0, 1].map(|d| add(&g[b][c][d], &singular.gradient[b][c][d])))
            })
        });
        let stress = smooth
            .stress
            .as_ref()
            .map(|s| [0, 1].map(|b| [0, 1, 2].map(|k| add(&s[b][k], &singular.stress[b][k]))));
        let body_force = smooth
            .body_force
            .as_ref()
            .map(|f| [0, 1].map(|b| [0, 1].map(|c| add(&f[b][c], &singular.body_force[b][c]))));
        Exact {
            displacement,
            gradient,
            stress,
            pressure,
            body_force,
            source_rate: smooth.source_rate,
            asymmetry: [None, None],
            singular: Some(singular),
            initial_gap: smooth.initial_gap,
            contact: smooth.contact,
        }
    }

    /// The constitutive source s = d sigma/dt - E eps(du/dt) - G(sigma) of body `b` (with
    /// its `material`) at (x, y, t), stress per time; None when the law needs none. Added
    /// as `k s(t_n)` to the backward-Euler update, it makes fields affine in t satisfy the
    /// time-discrete law exactly.
    pub fn source_at(
        &self,
        b: usize,
        material: &Material,
        x: f64,
        y: f64,
        t: f64,
    ) -> Option<[f64; 3]> {
        let rate = &self.source_rate.as_ref()?[b];
        let sigma = nalgebra::Vector3::from(self.stress_at(b, x, y, t)?);
        let g = material.g(&sigma);
        Some([0, 1, 2].map(|c| rate[c].eval(x, y, t) - g[c]))
    }

    /// Whether the exact solution gives `field` (the pressure also follows from the stress).
    pub fn gives(&self, field: Field) -> bool {
        match field {
            Field::Displacement => self.displacement.is_some(),
            Field::Stress => self.stress.is_some(),
            Field::Pressure => self.pressure.is_some() || self.stress.is_some(),
        }
    }

    /// The distinct kinks ([`Expr::kinks`]) of body `b`'s exact fields: where one changes
    /// sign inside a triangle, the integrands of the errors are smooth only piecewise.
    pub fn kinks(&self, b: usize) -> Vec<&Expr> {
        let mut fields: Vec<&Expr> = Vec::new();
        if let Some(u) = &self.displacement {
            fields.extend(u[b].iter());
        }
        if let Some(g) = &self.gradient {
            fields.extend(g[b].iter().flatten());
        }
        if let Some(s) = &self.stress {
            fields.extend(s[b].iter());
        }
        if let Some(r) = &self.source_rate {
            fields.extend(r[b].iter());
        }
        crate::expr::distinct_kinks(fields)
    }

    /// The distinct kinks of the exact pressure on Gamma_C (the given pressure, or the
    /// slave's stress it follows from), and of the gap (both displacements).
    pub fn contact_kinks(&self) -> Vec<&Expr> {
        let mut fields: Vec<&Expr> = Vec::new();
        match (&self.pressure, &self.stress) {
            (Some(p), _) => fields.push(p),
            (None, Some(s)) => fields.extend(s[0].iter()),
            (None, None) => {}
        }
        if let Some(u) = &self.displacement {
            fields.extend(u.iter().flatten());
        }
        crate::expr::distinct_kinks(fields)
    }

    /// Stress of body `b` at (x, y, t) as [s11, s22, s12].
    pub fn stress_at(&self, b: usize, x: f64, y: f64, t: f64) -> Option<[f64; 3]> {
        let s = &self.stress.as_ref()?[b];
        Some([s[0].eval(x, y, t), s[1].eval(x, y, t), s[2].eval(x, y, t)])
    }

    /// Displacement of body `b` at (x, y, t). At a singular point the singular part's
    /// expressions read 0 * inf; its limit there, 0, is taken.
    pub fn displacement_at(&self, b: usize, x: f64, y: f64, t: f64) -> Option<[f64; 2]> {
        let u = &self.displacement.as_ref()?[b];
        if let Some(s) = self.singular.as_ref().filter(|s| s.distance(x, y) == 0.0) {
            let u = &s.smooth[b];
            return Some([u[0].eval(x, y, t), u[1].eval(x, y, t)]);
        }
        Some([u[0].eval(x, y, t), u[1].eval(x, y, t)])
    }

    /// Body 1's outward unit normal at (x, y) on Gamma_C: the exact geometry's where the
    /// scene gives it, else `n` (the discrete trace's).
    pub fn normal_at(&self, n: [f64; 2], x: f64, y: f64) -> [f64; 2] {
        self.contact.as_ref().map_or(n, |c| c.normal_at(x, y))
    }

    /// The point of body 2 that (x, y) of body 1's Gamma_C faces: the exact geometry's
    /// m(x, y), else (x, y) itself (touching).
    pub fn facing(&self, x: f64, y: f64) -> [f64; 2] {
        self.contact.as_ref().map_or([x, y], |c| c.master_at(x, y))
    }

    /// The gap g0 + (m - x).nu - (u^1(x) - u^2(m)).nu at x = (x, y) and t on Gamma_C, g0 the
    /// scene's initial gap (zero where it gives none), m and nu the exact geometry's where
    /// the scene gives it, else x and the slave's outward normal `n`.
    pub fn gap_at(&self, n: [f64; 2], x: f64, y: f64, t: f64) -> Option<f64> {
        let (n, m) = (self.normal_at(n, x, y), self.facing(x, y));
        let (u1, u2) = (
            self.displacement_at(0, x, y, t)?,
            self.displacement_at(1, m[0], m[1], t)?,
        );
        let g0 = self.initial_gap.as_ref().map_or(0.0, |g| g.eval(x, y, 0.0))
            + (m[0] - x) * n[0]
            + (m[1] - y) * n[1];
        Some(g0 - ((u1[0] - u2[0]) * n[0] + (u1[1] - u2[1]) * n[1]))
    }

    /// Contact pressure at (x, y, t) on Gamma_C (body 1's side) with the slave's outward
    /// normal `n` (the exact geometry's where the scene gives it): the given pressure, or
    /// -nu.sigma^1 nu.
    pub fn pressure_at(&self, n: [f64; 2], x: f64, y: f64, t: f64) -> Option<f64> {
        if let Some(p) = &self.pressure {
            return Some(p.eval(x, y, t));
        }
        let n = self.normal_at(n, x, y);
        let s = self.stress_at(0, x, y, t)?;
        Some(-(n[0] * n[0] * s[0] + n[1] * n[1] * s[1] + 2.0 * n[0] * n[1] * s[2]))
    }
}

/// The traction sigma n of a stress [s11, s22, s12] on a normal n.
pub fn traction(s: [f64; 3], n: [f64; 2]) -> [f64; 2] {
    [s[0] * n[0] + s[2] * n[1], s[2] * n[0] + s[1] * n[1]]
}
