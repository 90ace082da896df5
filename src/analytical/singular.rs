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

/// The unaligned family's transition abscissa, 8/15: 2/3 of the way along the lower trace's
/// level-0 segment [0.4, 0.6] (meshes/two_blocks.geo with h_lower in (0.2, 0.25]: five
/// uniform segments) and 1/3 along the upper trace's third segment once that line is graded
/// by [`unaligned_grading`]. Halving a segment moves a point at 1/3 of it to 2/3 of a half
/// and back, so c is 1/3 of its segment from the nearest node of both traces at every level.
pub const UNALIGNED_TRANSITION: f64 = 8.0 / 15.0;

/// The nodes of meshes/two_blocks.geo's upper contact line with `nodes` nodes and total
/// grading `grading` (gmsh's `Using Progression`: segment lengths in geometric ratio
/// grading^(1 / (nodes - 2))).
pub fn graded_line(nodes: usize, grading: f64) -> Vec<f64> {
    let ratio = grading.powf(1.0 / (nodes as f64 - 2.0));
    let lengths: Vec<f64> = (0..nodes - 1).map(|k| ratio.powi(k as i32)).collect();
    let total: f64 = lengths.iter().sum();
    let mut x = vec![0.0];
    for l in lengths {
        x.push(x.last().unwrap() + l / total);
    }
    x
}

/// The upper line's grading (five nodes: h_upper in [0.25, 1/3)) that puts
/// [`UNALIGNED_TRANSITION`] at 1/3 of its third segment, by bisection (1.3844).
pub fn unaligned_grading() -> f64 {
    let miss = |g: f64| {
        let x = graded_line(5, g);
        x[2] + (x[3] - x[2]) / 3.0 - UNALIGNED_TRANSITION
    };
    // miss falls as the grading rises: 0.05 at 1, negative at 2.
    let (mut lo, mut hi) = (1.0, 2.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if miss(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// How a member's meshes meet its transition point c.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Placement {
    /// c = ([`TRANSITION`], 1) is a geometry point of both contact lines
    /// (meshes/two_blocks_point.geo): a node of both traces at every level.
    Aligned,
    /// c = ([`UNALIGNED_TRANSITION`], 1), a node of neither trace at any level
    /// (meshes/two_blocks.geo, the upper line graded by [`unaligned_grading`]).
    Unaligned,
    /// c = ([`TRANSITION`], 1) a node of both, every level meshed by gmsh with sizes graded
    /// toward c with exponent `mu` (meshes/two_blocks_graded.geo).
    Graded {
        /// The grading exponent mu (< beta): element size h (r / R)^(1 - mu) near c.
        mu: f64,
    },
}

/// The radius R of the graded meshes' grading zone: element size h (r / R)^(1 - mu) within
/// R of c, h beyond.
pub const GRADED_RADIUS: f64 = 0.5;

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
    /// Where c sits among the mesh nodes (and so c itself).
    pub placement: Placement,
    /// The aligned placement's upper-line grading (meshes/two_blocks_point.geo's `grading`:
    /// the ratio of the last to the first segment on each side of c).
    pub grading: f64,
}

/// The chosen values of Phi (upper, lower body) on the separated side (theta = 0) and the
/// contact side (theta = +-pi), and the upper body's Phi_y'(pi), which sets the pressure;
/// the contact conditions give the other derivatives.
#[derive(Debug, Clone, Copy)]
pub struct Ends {
    /// Phi_x(0) of each body.
    pub x0: [f64; 2],
    /// Phi_y(0) of each body (the gap: upper minus lower, > 0).
    pub y0: [f64; 2],
    /// Phi_x(pi) of each body.
    pub xpi: [f64; 2],
    /// Phi_y(pi) of each body (equal: no normal jump).
    pub ypi: [f64; 2],
    /// The upper body's Phi_y'(pi).
    pub dy1pi: f64,
}

impl Ends {
    /// The crossover-transition family's: every value 0 but the gap's (0.1) and the
    /// pressure's derivative (5), so that the singular part carries as much pressure as it
    /// can for its curvature (measured at beta = 1.25, levels 0-4: D / e_mortar 0.40, 0.34,
    /// 0.72, 0.91, 1.25 against the regularity family's 0.32, 0.26, 0.55, 0.70, 0.96).
    pub const CROSSOVER_TRANSITION: Ends = Ends {
        x0: [0.0, 0.0],
        y0: [0.1, 0.0],
        xpi: [0.0, 0.0],
        ypi: [0.0, 0.0],
        dy1pi: 5.0,
    };

    /// The regularity family's.
    pub const REGULARITY: Ends = Ends {
        x0: [0.2, -0.1],
        y0: [1.0, 0.0],
        xpi: [-0.3, 0.2],
        ypi: [-0.5, -0.5],
        dy1pi: 1.2,
    };
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
        // Chosen: the upper body lifts off on the separated side (Phi1_y(0) - Phi2_y(0) = 1)
        // and both bodies move down together on the contact side.
        Self::with_ends(beta, &Ends::REGULARITY)
    }

    /// The member for `beta` whose Phi takes the values `ends` (E = 100 and 150, nu = 0.3,
    /// A = 0.05).
    pub fn with_ends(beta: f64, ends: &Ends) -> Self {
        assert!(beta > 0.5, "beta > 1/2");
        let (young, nu) = ([100.0, 150.0], 0.3);
        let k = young.map(|e| e / (1.0 - nu * nu));
        let Ends {
            x0,
            y0,
            xpi,
            ypi,
            dy1pi,
        } = *ends;
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
            placement: Placement::Aligned,
            grading: 1.3,
        }
    }

    /// The member for `beta` with c placed by `placement` (the same Phi and amplitudes).
    pub fn placed(beta: f64, placement: Placement) -> Self {
        SingularContact {
            placement,
            ..Self::new(beta)
        }
    }

    /// The transition point's abscissa a: c = (a, 1).
    pub fn transition(&self) -> f64 {
        match self.placement {
            Placement::Aligned | Placement::Graded { .. } => TRANSITION,
            Placement::Unaligned => UNALIGNED_TRANSITION,
        }
    }

    /// The geometry file (relative to scenes/) and its gmsh parameters at level 0, as the
    /// scene's `geo` and `[parameters]` lines.
    fn mesh_lines(&self) -> (&'static str, String) {
        let a = self.transition();
        match self.placement {
            Placement::Aligned => (
                "../meshes/two_blocks_point.geo",
                format!(
                    "h_upper = 0.3\nh_lower = 0.2\ngrading = {:?}\npoint = {a}",
                    self.grading
                ),
            ),
            Placement::Unaligned => (
                "../meshes/two_blocks.geo",
                format!(
                    "h_upper = 0.3\nh_lower = 0.2\ngrading = {:?}",
                    unaligned_grading()
                ),
            ),
            Placement::Graded { mu } => (
                "../meshes/two_blocks_graded.geo",
                format!(
                    "h_upper = 0.3\nh_lower = 0.2\npoint = {a}\nmu = {mu}\nradius = {GRADED_RADIUS}"
                ),
            ),
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
        let a = self.transition();
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
        let where_c = match self.placement {
            Placement::Aligned => String::new(),
            Placement::Unaligned => {
                "; c at 1/3 of a trace segment of both meshes at every level, a node of neither"
                    .into()
            }
            Placement::Graded { mu } => format!(
                "; every level meshed by gmsh with sizes graded toward c, h (r/R)^(1-mu), mu = {mu}"
            ),
        };
        let description = format!(
            "Manufactured contact solution with a singular part r^beta Phi_l(theta) at the transition point c = ({}, 1), beta = {}: pressure ~ dist^(beta-1), gap ~ dist^beta (src/analytical/singular.rs){where_c}",
            self.transition(),
            self.beta
        );
        self.scene_toml_as(steps, "regularity_scenes", &description)
    }

    /// The scene file of this member, written by `examples/WRITER.rs`, with `description`.
    pub fn scene_toml_as(&self, steps: usize, writer: &str, description: &str) -> String {
        self.scene_toml_with(steps, writer, description, None)
    }

    /// The scene of this member across the initial gap g0 = x^2 / (2 R) of [`ClosingGap`]
    /// (the `gap` study's, written by `examples/regularity_scenes.rs`).
    pub fn gap_scene_toml(&self, gap: &ClosingGap) -> String {
        let description = format!(
            "The singular manufactured solution with beta = {} and its transition at c = ({}, 1) (regularity-unaligned-{:.2}), posed across the initial gap g0 = x^2 / (2 R), R = {}, which body 1's added displacement {} closes on all of Gamma_C (src/analytical/singular.rs, ClosingGap): contact on [0, c), the gap opening like dist^beta beyond, as without g0",
            self.beta,
            self.transition(),
            self.beta,
            gap.radius,
            gap.description()
        );
        self.scene_toml_with(1, "regularity_scenes", &description, Some(gap))
    }

    fn scene_toml_with(
        &self,
        steps: usize,
        writer: &str,
        description: &str,
        gap: Option<&ClosingGap>,
    ) -> String {
        let [u1, u2] = [0, 1].map(|l| self.singular_text(l));
        let [m1, m2] = [0, 1].map(|l| self.smooth_text(l));
        let (m1, gap_line, gap_comment) = match gap {
            Some(g) => g.scene_lines(m1),
            None => (m1, String::new(), String::new()),
        };
        let (geo, parameters) = self.mesh_lines();
        let refinement = match self.placement {
            Placement::Graded { .. } => "\nrefinement = \"remesh\"",
            _ => "",
        };
        format!(
            r#"# Written by `cargo run --release --example {writer}`: do not edit by hand.
description = "{description}"
geo = "{geo}"{refinement}
final_time = 1.0
steps = {steps}

[parameters]
{parameters}

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
master_curve = "contact_lower"{gap_line}

# Contact on [0, {a}), separation on ({a}, 1]: pressure {p:.6} t r^({bm1}), gap {g:.6} t r^{beta}.{gap_comment}
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
            a = self.transition(),
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

/// The initial gap g0(x) = x^2 / (2 R) on Gamma_C (y = 1; a cylinder of radius R over a
/// plane, to second order) and the displacement of body 1 that closes it: u_g = w(y)
/// ((y - 1) g0'(x), -g0(x)), w = y (2 - y). On y = 1, w = 1 and w' = 0: u_g = (0, -g0),
/// so [u_g.nu] = g0 (nu = (0, -1)), and grad u_g = [[0, g0'], [-g0', 0]] is a rotation, so
/// sigma(u_g) = 0 there: the approach equals g0 on all of Gamma_C and neither the pressure
/// nor the opening beyond c changes. On the clamp y = 2, w = 0. g0 is a polynomial, so
/// the body force -div sigma(u_g) is smooth. g0 therefore sets neither the contact zone
/// nor the pressure: what it changes is the rows' right-hand side and the displacement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosingGap {
    /// R (length).
    pub radius: f64,
}

impl ClosingGap {
    /// The `gap` study's: R = 10, g0 from 0 to 0.05 on [0, 1], of the order of the
    /// singular part's displacement.
    pub const STUDY: ClosingGap = ClosingGap { radius: 10.0 };

    /// g0(x) (length).
    pub fn gap(&self, x: f64) -> f64 {
        x * x / (2.0 * self.radius)
    }

    /// g0 as a scene expression.
    pub fn gap_text(&self) -> String {
        format!("x^2/{:?}", 2.0 * self.radius)
    }

    /// u_g as scene expressions.
    pub fn displacement_text(&self) -> [String; 2] {
        let r = self.radius;
        [
            format!("y*(2-y)*(y-1)*x/{r:?}"),
            format!("-y*(2-y)*x^2/{:?}", 2.0 * r),
        ]
    }

    /// What the gap adds to a scene file: body 1's displacement `upper` (scene
    /// expressions) with u_g added, the `[contact] gap` line and the comment saying why.
    fn scene_lines(&self, upper: [String; 2]) -> ([String; 2], String, String) {
        let [cx, cy] = self.displacement_text();
        // cy reads "-y*...": written as a difference.
        let displacement = [
            format!("{} + {cx}", upper[0]),
            format!("{} - {}", upper[1], cy.trim_start_matches('-')),
        ];
        let line = format!("\ngap = \"{}\"", self.gap_text());
        let comment = format!(
            "\n# Body 1 (upper) carries the closing part {} (no factor t: it closes g0 at every t,\n# traction-free on y = 1), so that g0 - [u.nu] is the gap without g0.",
            self.description()
        );
        (displacement, line, comment)
    }

    /// u_g in words, for descriptions.
    pub fn description(&self) -> String {
        let [x, y] = self.displacement_text();
        format!("u_g = ({x}, {y})")
    }

    /// u_g at (x, y) (length).
    pub fn displacement(&self, x: f64, y: f64) -> [f64; 2] {
        let w = y * (2.0 - y);
        [w * (y - 1.0) * x / self.radius, -w * self.gap(x)]
    }
}
