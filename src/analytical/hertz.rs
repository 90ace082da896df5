//! Hertz's line contact (issue 79): two long elastic cylinders, or a cylinder on a
//! half-space, pressed together in plane strain by a load P per unit length (Johnson,
//! Contact Mechanics, 1985, section 4.3). The half-width a = sqrt(4 P R / (pi E*)), the peak
//! p0 = 2 P / (pi a) and the profile p(x) = p0 sqrt(1 - x^2 / a^2) on |x| <= a, with
//! 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2 and R the relative radius of curvature (the
//! cylinder's on a flat block). It is the half-space solution of a parabolic gap
//! x^2 / (2 R): a finite body differs from it by a model error that refining the mesh does
//! not remove (the study `hertz` measures the two apart).

use crate::material::Elasticity;

/// A line contact: the relative radius R (length), the load P per unit length (force per
/// length) and both bodies' elasticity (plane strain: their E and nu).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineContact {
    /// R (length).
    pub radius: f64,
    /// P, the whole load per unit length (a symmetric half carries P / 2).
    pub load: f64,
    /// The two bodies' elasticity.
    pub elastic: [Elasticity; 2],
}

impl LineContact {
    /// E*, the contact modulus (stress): 1/E* = sum (1 - nu_i^2) / E_i.
    pub fn contact_modulus(&self) -> f64 {
        let compliance: f64 = self
            .elastic
            .iter()
            .map(|e| (1.0 - e.poisson * e.poisson) / e.young)
            .sum();
        1.0 / compliance
    }

    /// The half-width a (length).
    pub fn half_width(&self) -> f64 {
        (4.0 * self.load * self.radius / (std::f64::consts::PI * self.contact_modulus())).sqrt()
    }

    /// The peak pressure p0 = 2 P / (pi a) (stress).
    pub fn peak_pressure(&self) -> f64 {
        2.0 * self.load / (std::f64::consts::PI * self.half_width())
    }

    /// The contact pressure at distance `x` from the centre of contact (stress; 0 outside).
    pub fn pressure(&self, x: f64) -> f64 {
        let a = self.half_width();
        match x.abs() < a {
            true => self.peak_pressure() * (1.0 - (x / a).powi(2)).sqrt(),
            false => 0.0,
        }
    }
}
