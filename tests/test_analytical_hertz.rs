//! Reference: Johnson, Contact Mechanics (1985), section 4.3, eqs. (4.43)-(4.45): Hertz's
//! line contact, a = sqrt(4 P R / (pi E*)), p0 = 2 P / (pi a), p = p0 sqrt(1 - x^2/a^2).
//! Goal: `analytical::hertz::LineContact` against a hand computation (steel on steel), its
//! profile's resultant equal to P (integrated by Gauss-Chebyshev of the second kind, exact
//! for sqrt(1 - s^2) times a constant), and a growing like sqrt(P) and sqrt(R).
//! Geometry: a cylinder of radius R = 10 on a half-space (the relative radius).
//! Data: E = 210e3, nu = 0.3 both, P = 100 per unit length; E* by hand 210e3 / (2 (1 - 0.09))
//! = 115384.615..., a = 0.105046383664732, p0 = 606.036828834992.

use contact_rates::analytical::hertz::LineContact;
use contact_rates::material::{Elasticity, Plane};

fn steel() -> Elasticity {
    Elasticity {
        young: 210e3,
        poisson: 0.3,
        plane: Plane::Strain,
    }
}

fn contact(radius: f64, load: f64) -> LineContact {
    LineContact {
        radius,
        load,
        elastic: [steel(), steel()],
    }
}

#[test]
fn johnson_line_contact_matches_the_hand_computation_and_carries_its_load() {
    let c = contact(10.0, 100.0);
    let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
    assert!(rel(c.contact_modulus(), 115384.61538461539) < 1e-14);
    assert!(rel(c.half_width(), 0.10504638366473201) < 1e-14);
    assert!(rel(c.peak_pressure(), 606.0368288349923) < 1e-14);
    // The resultant: int_{-a}^{a} p dx = a p0 int_{-1}^{1} sqrt(1 - s^2) ds; Gauss-Chebyshev
    // of the second kind with n points is exact for that weight times a polynomial.
    let (a, n) = (c.half_width(), 16);
    let resultant: f64 = (1..=n)
        .map(|k| {
            let theta = k as f64 * std::f64::consts::PI / (n + 1) as f64;
            let w = std::f64::consts::PI / (n + 1) as f64 * theta.sin().powi(2);
            // p(x) / sqrt(1 - s^2) = p0 at every interior point.
            let s = theta.cos();
            w * c.pressure(a * s) / (1.0 - s * s).sqrt()
        })
        .sum::<f64>()
        * a;
    assert!(rel(resultant, 100.0) < 1e-13, "{resultant}");
    assert_eq!(c.pressure(1.0001 * a), 0.0);
    // a ~ sqrt(P R): four times the load or the radius doubles it.
    assert!(rel(contact(10.0, 400.0).half_width(), 2.0 * a) < 1e-14);
    assert!(rel(contact(40.0, 100.0).half_width(), 2.0 * a) < 1e-14);
}
