//! The `regularity` family: manufactured elastic contact solutions of the two stacked unit
//! blocks whose displacement has a singular part r^beta Phi_l(theta) at the transition point
//! c = (a, 1) between contact (x < a) and separation (x > a) on Gamma_C (y = 1), one
//! parameter beta > 1/2.
//!
//! Body l (1 upper, theta in [0, pi]; 2 lower, theta in [-pi, 0]) has
//! u_s = A t w(y) r^beta Phi_l(theta), w = y (2 - y), with Phi_l = (Phi_x, Phi_y) and each
//! component a trigonometric polynomial c0 + c1 cos(theta) + s1 sin(theta) + s2 sin(2 theta)
//! (so r^beta Phi needs no angle: r^beta cos(theta) = r^(beta-1) (x - a), ...). The factor w
//! vanishes on the clamps y = 0 and y = 2 and has w = 1, w' = 0 on Gamma_C, so it changes
//! neither the displacement nor the stress there: no cutoff is needed, and the singular
//! part alone satisfies every contact condition on the whole of Gamma_C.
//!
//! With grad u = r^(beta-1) (beta cos(theta) Phi - sin(theta) Phi', beta sin(theta) Phi +
//! cos(theta) Phi'), the conditions on y = 1 are linear in Phi and Phi' at theta = 0
//! (separated side) and theta = +-pi (contact side), for every beta (no eigenfunction is
//! sought: the body force absorbs the equilibrium):
//! - separated side, each body: no shear, Phi_x'(0) + beta Phi_y(0) = 0, and no normal
//!   traction, Phi_y'(0) + nu beta Phi_x(0) = 0;
//! - contact side, each body: no shear, Phi_x'(pi) + beta Phi_y(pi) = 0;
//! - equal normal tractions, k_1 (Phi1_y' + nu beta Phi1_x) = k_2 (Phi2_y' + nu beta Phi2_x)
//!   at pi and -pi, k_l = E_l / (1 - nu^2); no normal jump, Phi1_y(pi) = Phi2_y(-pi);
//! - signs: the pressure A t k_1 r^(beta-1) (Phi1_y'(pi) + nu beta Phi1_x(pi)) > 0 and the
//!   gap A t r^beta (Phi1_y(0) - Phi2_y(0)) > 0.
//!
//! The values of Phi at 0 and pi and Phi1_y'(pi) are chosen (below); the eight conditions
//! give the derivatives. A trigonometric polynomial takes the same values and derivatives
//! at pi and -pi, so the lower body's conditions at -pi read the same. A smooth bulk part
//! t c_l (y - 1)^2 (sin(pi x), cos(pi x)) (times (2 - y) or y) vanishes with its gradient
//! on Gamma_C and on the clamps.

/// The transition point's abscissa (the same as contact-mms's).
pub const TRANSITION: f64 = 0.5871;

/// Coefficients (c0, c1, s1, s2) of c0 + c1 cos(theta) + s1 sin(theta) + s2 sin(2 theta).
pub type Trig = [f64; 4];

/// One member of the family.
#[derive(Debug, Clone)]
pub struct SingularContact {
    /// beta (> 1/2: the pressure ~ dist^(beta-1) must lie in L2(Gamma_C)).
    pub beta: f64,
    /// Young's moduli of the upper (slave) and lower body.
    pub young: [f64; 2],
    /// Poisson's ratio of both.
    pub poisson: f64,
    /// The amplitude A of the singular part (length per unit t, at r = 1).
    pub amplitude: f64,
    /// Phi of each body (upper, lower), per component (x, y).
    pub phi: [[Trig; 2]; 2],
}

/// Phi's values and derivatives at 0 and pi: (value 0, value pi, derivative 0, derivative pi).
fn trig_from_ends(v0: f64, vpi: f64, d0: f64, dpi: f64) -> Trig {
    // Phi(0) = c0 + c1, Phi(pi) = c0 - c1, Phi'(0) = s1 + 2 s2, Phi'(pi) = -s1 + 2 s2.
    [
        0.5 * (v0 + vpi),
        0.5 * (v0 - vpi),
        0.5 * (d0 - dpi),
        0.25 * (d0 + dpi),
    ]
}

impl SingularContact {
    /// The family's member for `beta`: E = 100 (upper) and 150 (lower), nu = 0.3, A = 0.05.
    pub fn new(beta: f64) -> Self {
        assert!(beta > 0.5, "beta > 1/2");
        let (young, nu) = ([100.0, 150.0], 0.3);
        let k = young.map(|e| e / (1.0 - nu * nu));
        // Chosen: the upper body lifts off on the separated side (Phi1_y(0) - Phi2_y(0) = 1)
        // and both bodies move down together on the contact side.
        let (x0, y0) = ([0.2, -0.1], [1.0, 0.0]);
        let (xpi, ypi) = ([-0.3, 0.2], [-0.5, -0.5]);
        let dy1pi = 1.2;
        let pressure = dy1pi + nu * beta * xpi[0];
        let dypi = [dy1pi, k[0] * pressure / k[1] - nu * beta * xpi[1]];
        let phi = [0, 1].map(|l| {
            [
                // x: Phi_x'(0) = -beta Phi_y(0), Phi_x'(pi) = -beta Phi_y(pi).
                trig_from_ends(x0[l], xpi[l], -beta * y0[l], -beta * ypi[l]),
                // y: Phi_y'(0) = -nu beta Phi_x(0).
                trig_from_ends(y0[l], ypi[l], -nu * beta * x0[l], dypi[l]),
            ]
        });
        SingularContact {
            beta,
            young,
            poisson: nu,
            amplitude: 0.05,
            phi,
        }
    }

    /// Phi_l(theta) and Phi_l'(theta) of body `l` (0 upper, 1 lower).
    pub fn angular(&self, l: usize, theta: f64) -> ([f64; 2], [f64; 2]) {
        let f = |c: Trig| {
            (
                c[0] + c[1] * theta.cos() + c[2] * theta.sin() + c[3] * (2.0 * theta).sin(),
                -c[1] * theta.sin() + c[2] * theta.cos() + 2.0 * c[3] * (2.0 * theta).cos(),
            )
        };
        let (x, y) = (f(self.phi[l][0]), f(self.phi[l][1]));
        ([x.0, y.0], [x.1, y.1])
    }

    /// The pressure amplitude: p = A t k_1 P r^(beta-1) on the contact side.
    pub fn pressure_factor(&self) -> f64 {
        let (v, d) = self.angular(0, std::f64::consts::PI);
        let k1 = self.young[0] / (1.0 - self.poisson.powi(2));
        self.amplitude * k1 * (d[1] + self.poisson * self.beta * v[0])
    }

    /// The gap amplitude: g = A t G r^beta on the separated side.
    pub fn gap_factor(&self) -> f64 {
        self.amplitude * (self.angular(0, 0.0).0[1] - self.angular(1, 0.0).0[1])
    }

    /// The singular part of body `l`'s displacement as scene expressions (x, y, t).
    pub fn singular_text(&self, l: usize) -> [String; 2] {
        let a = TRANSITION;
        let r2 = format!("((x-{a})^2+(y-1)^2)");
        let b = self.beta;
        let pow = |p: f64| format!("{r2}^({})", p / 2.0);
        [0, 1].map(|c| {
            let [c0, c1, s1, s2] = self.phi[l][c];
            format!(
                "{amp}*t*y*(2-y)*(({c0:?})*{rb} + (({c1:?})*(x-{a}) + ({s1:?})*(y-1))*{rb1} + ({s2x2:?})*(x-{a})*(y-1)*{rb2})",
                amp = self.amplitude,
                rb = pow(b),
                rb1 = pow(b - 1.0),
                rb2 = pow(b - 2.0),
                s2x2 = 2.0 * s2,
            )
        })
    }

    /// The smooth bulk part of body `l`'s displacement as scene expressions: zero with its
    /// gradient on Gamma_C (the factor (y - 1)^2), zero on the body's clamp.
    pub fn smooth_text(&self, l: usize) -> [String; 2] {
        let (coef, clamp) = [(0.02, "(2-y)"), (0.03, "y")][l];
        [
            format!("{coef}*t*(y-1)^2*{clamp}*sin(pi*x)"),
            format!("{coef}*t*(y-1)^2*{clamp}*cos(pi*x)"),
        ]
    }

    /// The scene file of this member (the `regularity` scenes are written by
    /// `examples/regularity_scenes.rs`).
    pub fn scene_toml(&self, steps: usize) -> String {
        let [u1, u2] = [0, 1].map(|l| self.singular_text(l));
        let [m1, m2] = [0, 1].map(|l| self.smooth_text(l));
        format!(
            r#"# Written by `cargo run --release --example regularity_scenes`: do not edit by hand.
description = "Manufactured contact solution with a singular part r^beta Phi_l(theta) at the transition point c = ({a}, 1), beta = {beta}: pressure ~ dist^(beta-1), gap ~ dist^beta (src/analytical/singular.rs)"
geo = "../meshes/two_blocks_point.geo"
final_time = 1.0
steps = {steps}

[parameters]
h_upper = 0.3
h_lower = 0.2
grading = 1.3
point = {a}

[[bodies]]
surface = "upper"
young = {e1:?}
poisson = {nu:?}

[[bodies]]
surface = "lower"
young = {e2:?}
poisson = {nu:?}

[[clamp]]
curve = "bottom"

[[clamp]]
curve = "top"

# Neumann parts: sigma(u) n derived from the manufactured displacement.
[[traction]]
curve = "left_upper"

[[traction]]
curve = "right_upper"

[[traction]]
curve = "left_lower"

[[traction]]
curve = "right_lower"

[contact]
slave_body = "upper"
slave_curve = "contact_upper"
master_curve = "contact_lower"

# Contact on [0, {a}), separation on ({a}, 1]: pressure {p:.6} t r^({bm1}), gap {g:.6} t r^{beta}.
# The displacement is the smooth part below plus the singular part of [exact.singular].
[exact]
manufactured = true
displacement = [
  ["{m1x}", "{m1y}"],
  ["{m2x}", "{m2y}"],
]

[exact.singular]
point = [{a}, 1.0]
exponent = {beta}
displacement = [
  ["{u1x}",
   "{u1y}"],
  ["{u2x}",
   "{u2y}"],
]
"#,
            a = TRANSITION,
            beta = self.beta,
            bm1 = self.beta - 1.0,
            e1 = self.young[0],
            e2 = self.young[1],
            nu = self.poisson,
            p = self.pressure_factor(),
            g = self.gap_factor(),
            m1x = m1[0],
            m1y = m1[1],
            m2x = m2[0],
            m2y = m2[1],
            u1x = u1[0],
            u1y = u1[1],
            u2x = u2[0],
            u2y = u2[1],
        )
    }
}
