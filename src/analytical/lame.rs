//! The Lame press fit (issue 77): two concentric annuli across a radial gap, closed by a
//! pressure on the inner bore, in closed form.
//!
//! Body 1 (the slave) is the annulus a <= r <= R, body 2 (the master) the ring
//! R + g0 <= r <= b. An internal pressure p_i on r = a expands body 1 across the gap g0;
//! body 2 is free on r = b. Each body's displacement is Lame's radial field
//! u = u_r(r) e_r, u_r = A r + B / r, whose stress is sigma_rr = k A - beta B / r^2,
//! sigma_tt = k A + beta B / r^2 with k = 2 a_E + b_E and beta = b_E (sigma = a_E tr(eps) I
//! + b_E eps, [`crate::material::Elasticity::a`] and `b`: plane strain or stress alike).
//! The six unknowns A1, B1, A2, B2 and the contact pressures p1 (on r = R, body 1's side)
//! and p2 (on r = R + g0, body 2's) solve six linear equations:
//! sigma_rr^1(a) = -p_i, sigma_rr^1(R) = -p1, sigma_rr^2(R + g0) = -p2, sigma_rr^2(b) = 0,
//! the closure u_r^1(R) - u_r^2(R + g0) = g0, and action equal to reaction per unit angle
//! along the radial map (the slave-normal map) p1 R = p2 (R + g0). The radial field is
//! axisymmetric, so rollers on the symmetry lines x = 0 and y = 0 hold it on a quarter.

use crate::material::Elasticity;
use nalgebra::{SMatrix, SVector};

/// The press fit's data: radii (length), the gap (length), the bore pressure (stress),
/// and each body's elasticity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PressFit {
    /// Body 1's bore radius a.
    pub bore: f64,
    /// Body 1's outer radius R, Gamma_C on its side.
    pub radius: f64,
    /// The radial gap g0 >= 0: body 2's inner radius is R + g0.
    pub gap: f64,
    /// Body 2's outer radius b.
    pub outer: f64,
    /// The pressure p_i on the bore r = a.
    pub bore_pressure: f64,
    /// Elasticity of body 1 and body 2.
    pub elastic: [Elasticity; 2],
}

/// Lame's coefficients of both bodies and the two contact pressures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PressFitSolution {
    /// (A, B) of body 1 and body 2: u_r = A r + B / r (A dimensionless, B length^2).
    pub coefficients: [[f64; 2]; 2],
    /// p1, the contact pressure on body 1's side r = R (stress).
    pub pressure_inner: f64,
    /// p2, the contact pressure on body 2's side r = R + g0 (stress).
    pub pressure_outer: f64,
}

/// Lame's k = 2 a + b and beta = b of an elasticity (stress): sigma_rr = k A - beta B / r^2.
fn moduli(e: &Elasticity) -> (f64, f64) {
    (2.0 * e.a() + e.b(), e.b())
}

impl PressFit {
    /// The press fit of meshes/press_fit.geo and scenes/press-fit.toml: a = 0.5, R = 1,
    /// g0 = 0.02, b = 1.5, bore pressure 6.6, E = 100 and 150, nu = 0.3, plane strain.
    pub fn benchmark() -> Self {
        let strain = |young| Elasticity {
            young,
            poisson: 0.3,
            plane: crate::material::Plane::Strain,
        };
        PressFit {
            bore: 0.5,
            radius: 1.0,
            gap: 0.02,
            outer: 1.5,
            bore_pressure: 6.6,
            elastic: [strain(100.0), strain(150.0)],
        }
    }

    /// The closed form with the contact closed: the six equations above, solved by LU.
    /// The pressures are those of a closed contact; [`PressFit::closes`] says whether they
    /// are compressive.
    pub fn solve(&self) -> PressFitSolution {
        let (k1, b1) = moduli(&self.elastic[0]);
        let (k2, b2) = moduli(&self.elastic[1]);
        let (a, r, rho, b) = (self.bore, self.radius, self.radius + self.gap, self.outer);
        // Unknowns (A1, B1, A2, B2, p1, p2).
        #[rustfmt::skip]
        let m = SMatrix::<f64, 6, 6>::from_row_slice(&[
            k1, -b1 / (a * a), 0.0, 0.0, 0.0, 0.0,
            k1, -b1 / (r * r), 0.0, 0.0, 1.0, 0.0,
            0.0, 0.0, k2, -b2 / (rho * rho), 0.0, 1.0,
            0.0, 0.0, k2, -b2 / (b * b), 0.0, 0.0,
            r, 1.0 / r, -rho, -1.0 / rho, 0.0, 0.0,
            0.0, 0.0, 0.0, 0.0, r, -rho,
        ]);
        let rhs =
            SVector::<f64, 6>::from_row_slice(&[-self.bore_pressure, 0.0, 0.0, 0.0, self.gap, 0.0]);
        let x = m
            .lu()
            .solve(&rhs)
            .expect("the press fit's six equations are regular");
        PressFitSolution {
            coefficients: [[x[0], x[1]], [x[2], x[3]]],
            pressure_inner: x[4],
            pressure_outer: x[5],
        }
    }

    /// The bore pressure that just closes the gap: body 1 alone, free on r = R, expands
    /// by g0 there (u_r^1(R) = g0 with sigma_rr^1(R) = 0; stress).
    pub fn closing_pressure(&self) -> f64 {
        let (k1, b1) = moduli(&self.elastic[0]);
        let (a, r) = (self.bore, self.radius);
        // sigma_rr(a) = -p, sigma_rr(R) = 0: A = B b1 / (k1 R^2), B b1 (1/R^2 - 1/a^2) = -p;
        // u_r(R) = A R + B / R, linear in p: the p that gives g0.
        let b_per_p = -1.0 / (b1 * (1.0 / (r * r) - 1.0 / (a * a)));
        let a_per_p = b_per_p * b1 / (k1 * r * r);
        self.gap / (a_per_p * r + b_per_p / r)
    }

    /// Whether the bore pressure closes the gap with a compressive contact pressure.
    pub fn closes(&self) -> bool {
        self.solve().pressure_inner > 0.0
    }
}

impl PressFitSolution {
    /// u_r of body `i` at radius `r` (length).
    pub fn radial_displacement(&self, i: usize, r: f64) -> f64 {
        let [a, b] = self.coefficients[i];
        a * r + b / r
    }

    /// (sigma_rr, sigma_tt) of body `i` at radius `r` for the body's elasticity `e`
    /// (stress).
    pub fn radial_stress(&self, i: usize, r: f64, e: &Elasticity) -> (f64, f64) {
        let [a, b] = self.coefficients[i];
        let (k, beta) = moduli(e);
        (k * a - beta * b / (r * r), k * a + beta * b / (r * r))
    }

    /// Body `i`'s displacement as scene expressions in x and y: u_r e_r = A (x, y) +
    /// B (x, y) / (x^2 + y^2).
    pub fn displacement_text(&self, i: usize) -> [String; 2] {
        let [a, b] = self.coefficients[i];
        ["x", "y"].map(|c| format!("{a:?}*{c} + {b:?}*{c}/(x^2+y^2)"))
    }
}
