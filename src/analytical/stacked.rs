//! The closed form of the `stacked-exact` scene: two elastic unit blocks (the same E and
//! nu), rollers on every vertical side, the lower block clamped at y = 0, the upper block's
//! top (y = 2) loaded by g = (0, -t (P0 + P1 cos(pi x))). The interface y = 1 stays closed.
//!
//! The solution is the uniform compression (u_x = 0, u_y = -P0 t y (1 - nu^2) / E) plus one
//! Airy mode per block, phi_i = t cos(pi x) f_i(y) with
//! f_i(y) = (A + B y) cosh(pi y) + (C + D y) sinh(pi y):
//! sigma_11 = phi_yy, sigma_22 = phi_xx, sigma_12 = -phi_xy, and from plane-stress
//! compliance u_x = t sin(pi x) (f'' + nu pi^2 f) / (pi E),
//! u_y = t cos(pi x) (-pi^2 F - nu f') / E with F = (2 pi^2 f' - f''') / pi^4 (the
//! antiderivative of f that compatibility fixes). Rollers hold since sin(pi x) = 0 at
//! x = 0, 1. The eight constants solve eight conditions: top traction (2), no shear on
//! either side of the frictionless interface (2), equal normal stress and normal
//! displacement across it (2), and the clamp (2).

use nalgebra::{SMatrix, SVector};
use std::f64::consts::PI;

/// g(y) = (c[0] + c[1] y) cosh(pi y) + (c[2] + c[3] y) sinh(pi y), as its four coefficients.
type Profile = [f64; 4];

fn derivative(c: Profile) -> Profile {
    // (B + pi (C + D y)) cosh + (D + pi (A + B y)) sinh
    [c[1] + PI * c[2], PI * c[3], c[3] + PI * c[0], PI * c[1]]
}

fn combine(terms: &[(f64, Profile)]) -> Profile {
    let mut out = [0.0; 4];
    for (w, c) in terms {
        for k in 0..4 {
            out[k] += w * c[k];
        }
    }
    out
}

/// F = (2 pi^2 f' - f''') / pi^4, the antiderivative of f that compatibility fixes.
fn antiderivative(c: Profile) -> Profile {
    let d1 = derivative(c);
    let d3 = derivative(derivative(d1));
    combine(&[(2.0 / PI.powi(2), d1), (-1.0 / PI.powi(4), d3)])
}

fn eval(c: Profile, y: f64) -> f64 {
    (c[0] + c[1] * y) * (PI * y).cosh() + (c[2] + c[3] * y) * (PI * y).sinh()
}

/// The closed form for Young's modulus `young`, Poisson's ratio `poisson`, and the top load
/// -t (uniform + cosine cos(pi x)).
#[derive(Debug, Clone, Copy)]
pub struct StackedBlocks {
    /// E (stress units).
    pub young: f64,
    /// nu.
    pub poisson: f64,
    /// The uniform part of the top pressure per unit t.
    pub uniform: f64,
    /// The cos(pi x) part of the top pressure per unit t.
    pub cosine: f64,
    /// Airy profiles f of the upper (0) and lower (1) block.
    pub airy: [Profile; 2],
}

impl StackedBlocks {
    /// Solve the eight conditions for the Airy constants.
    pub fn new(young: f64, poisson: f64, uniform: f64, cosine: f64) -> Self {
        let nu = poisson;
        fn f(c: Profile) -> Profile {
            c
        }
        fn d1(c: Profile) -> Profile {
            derivative(c)
        }
        fn d2(c: Profile) -> Profile {
            derivative(derivative(c))
        }
        fn big_f(c: Profile) -> Profile {
            antiderivative(c)
        }
        // Each condition: (body, linear functional of that body's profile, value) or a
        // difference of the two bodies' functionals.
        type Functional = Box<dyn Fn(Profile) -> f64>;
        let at = |op: fn(Profile) -> Profile, y: f64| -> Functional {
            Box::new(move |c| eval(op(c), y))
        };
        let conditions: Vec<(Option<Functional>, Option<Functional>, f64)> = vec![
            // Top: sigma_22 = -pi^2 f = -cosine, sigma_12 = pi f' = 0.
            (Some(at(f, 2.0)), None, cosine / PI.powi(2)),
            (Some(at(d1, 2.0)), None, 0.0),
            // Interface: no shear on either side; equal sigma_22 and u_y.
            (Some(at(d1, 1.0)), None, 0.0),
            (None, Some(at(d1, 1.0)), 0.0),
            (
                Some(at(f, 1.0)),
                Some(Box::new(move |c| -eval(c, 1.0))),
                0.0,
            ),
            (
                Some(Box::new(move |c| {
                    eval(big_f(c), 1.0) * PI.powi(2) + nu * eval(d1(c), 1.0)
                })),
                Some(Box::new(move |c| {
                    -(eval(big_f(c), 1.0) * PI.powi(2) + nu * eval(d1(c), 1.0))
                })),
                0.0,
            ),
            // Clamp at y = 0: u_x = 0 (f'' + nu pi^2 f = 0) and u_y = 0 (pi^2 F + nu f' = 0).
            (
                None,
                Some(Box::new(move |c| {
                    eval(d2(c), 0.0) + nu * PI.powi(2) * eval(c, 0.0)
                })),
                0.0,
            ),
            (
                None,
                Some(Box::new(move |c| {
                    PI.powi(2) * eval(big_f(c), 0.0) + nu * eval(d1(c), 0.0)
                })),
                0.0,
            ),
        ];
        let mut m = SMatrix::<f64, 8, 8>::zeros();
        let mut rhs = SVector::<f64, 8>::zeros();
        for (row, (upper, lower, value)) in conditions.iter().enumerate() {
            for k in 0..4 {
                let mut e = [0.0; 4];
                e[k] = 1.0;
                if let Some(l) = upper {
                    m[(row, k)] = l(e);
                }
                if let Some(l) = lower {
                    m[(row, 4 + k)] = l(e);
                }
            }
            rhs[row] = *value;
        }
        let x = m
            .lu()
            .solve(&rhs)
            .expect("the eight conditions are independent");
        StackedBlocks {
            young,
            poisson,
            uniform,
            cosine,
            airy: [[x[0], x[1], x[2], x[3]], [x[4], x[5], x[6], x[7]]],
        }
    }

    /// The scene's closed form: E = 100, nu = 0.3, top load -10 t (0.3 + cos(pi x)).
    pub fn scene() -> Self {
        Self::new(100.0, 0.3, 3.0, 10.0)
    }

    /// Profiles of u_x / (t sin(pi x)) and of the cosine part of u_y / (t cos(pi x)).
    fn displacement_profiles(&self, body: usize) -> (Profile, Profile) {
        let (e, nu, c) = (self.young, self.poisson, self.airy[body]);
        let d1 = derivative(c);
        let d2 = derivative(d1);
        let big_f = antiderivative(c);
        (
            combine(&[(1.0 / (PI * e), d2), (nu * PI / e, c)]),
            combine(&[(-PI.powi(2) / e, big_f), (-nu / e, d1)]),
        )
    }

    /// Displacement of `body` (0 upper, 1 lower) at (x, y, t).
    pub fn displacement(&self, body: usize, x: f64, y: f64, t: f64) -> [f64; 2] {
        let (ux, uy) = self.displacement_profiles(body);
        let squeeze = self.uniform * (1.0 - self.poisson.powi(2)) / self.young;
        [
            t * (PI * x).sin() * eval(ux, y),
            t * ((PI * x).cos() * eval(uy, y) - squeeze * y),
        ]
    }

    /// Stress [s11, s22, s12] of `body` at (x, y, t).
    pub fn stress(&self, body: usize, x: f64, y: f64, t: f64) -> [f64; 3] {
        let c = self.airy[body];
        let d1 = derivative(c);
        let d2 = derivative(d1);
        let (cx, sx) = ((PI * x).cos(), (PI * x).sin());
        [
            t * (cx * eval(d2, y) - self.poisson * self.uniform),
            t * (-PI.powi(2) * cx * eval(c, y) - self.uniform),
            t * PI * sx * eval(d1, y),
        ]
    }

    /// The displacement of both bodies as scene expressions in x, y, t, pi (full-precision
    /// constants), [[u_x, u_y] upper, [u_x, u_y] lower].
    pub fn expressions(&self) -> [[String; 2]; 2] {
        let profile = |c: Profile| {
            format!(
                "(({})+({})*y)*cosh(pi*y)+(({})+({})*y)*sinh(pi*y)",
                c[0], c[1], c[2], c[3]
            )
        };
        let squeeze = self.uniform * (1.0 - self.poisson.powi(2)) / self.young;
        [0, 1].map(|b| {
            let (ux, uy) = self.displacement_profiles(b);
            [
                format!("t*sin(pi*x)*({})", profile(ux)),
                format!("t*(cos(pi*x)*({})-({squeeze})*y)", profile(uy)),
            ]
        })
    }
}
