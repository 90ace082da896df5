//! Constitutive laws of SPEC section 1: elasticity `E` (plane stress, or plane strain where a
//! scene asks), and the Perzyna
//! viscoplastic function `G(sigma) = -(1/(2 lambda)) E (sigma - P_B sigma)`, with `P_B` the
//! projection onto the von Mises set `B` in the `(tau, E tau)` inner product.
//!
//! Stresses and strains are stored as tensor components `[11, 22, 12]` (not Voigt's
//! engineering shear). All three quadratic forms involved (von Mises, the E-norm and E
//! itself) are diagonal in the coordinates `p = (s11 + s22)/2`, `d = (s11 - s22)/2`,
//! `t = s12`, with equal weights on `d` and `t`; the backward-Euler update therefore reduces
//! to one scalar equation, solved to machine precision.

use nalgebra::{Matrix3, Vector3};

/// Stress tensor components `[s11, s22, s12]` (force per length in 2D, scene units).
pub type Stress = Vector3<f64>;
/// Strain tensor components `[e11, e22, e12]` (dimensionless).
pub type Strain = Vector3<f64>;

/// Isotropic elasticity of the in-plane components: `E tau = a tr(tau) I + b tau`,
/// `b = E / (1 + nu)` = 2 mu, and `a = E nu / (1 - nu^2)` in plane stress (sigma_33 = 0),
/// `a = E nu / ((1 + nu) (1 - 2 nu))` = Lame's lambda in plane strain (eps_33 = 0,
/// sigma_33 = nu (sigma_11 + sigma_22)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Elasticity {
    /// Young's modulus E (stress units).
    pub young: f64,
    /// Poisson's ratio nu (dimensionless, in (-1, 0.5)).
    pub poisson: f64,
    /// Which out-of-plane component vanishes.
    pub plane: Plane,
}

/// The 2D reduction of the 3D law: which out-of-plane component is zero.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Plane {
    /// sigma_33 = 0 (a thin plate; the paper's setting).
    #[default]
    Stress,
    /// eps_33 = 0 (a long body: Hertz's cylinder, Lame's tube).
    Strain,
}

impl Plane {
    /// "plane stress" or "plane strain", for reports and exported problems.
    pub fn label(self) -> &'static str {
        match self {
            Plane::Stress => "plane stress",
            Plane::Strain => "plane strain",
        }
    }
}

/// Perzyna viscoplasticity parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Viscoplasticity {
    /// Viscosity lambda (stress x time units).
    pub lambda: f64,
    /// Uniaxial yield stress sigma_Y (stress units).
    pub yield_stress: f64,
}

/// A body's material: elastic, and viscoplastic when a yield stress is given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// The elasticity tensor E.
    pub elastic: Elasticity,
    /// Perzyna parameters; `None` for a purely elastic body (no plasticity cost at all).
    pub viscoplastic: Option<Viscoplasticity>,
}

/// Von Mises norm `sqrt(t11^2 + t22^2 - t11 t22 + 3 t12^2)`.
pub fn von_mises(s: &Stress) -> f64 {
    (s[0] * s[0] + s[1] * s[1] - s[0] * s[1] + 3.0 * s[2] * s[2])
        .max(0.0)
        .sqrt()
}

/// `(p, d, t)` coordinates of a tensor `[11, 22, 12]`.
fn to_pdt(s: &Stress) -> Vector3<f64> {
    Vector3::new(0.5 * (s[0] + s[1]), 0.5 * (s[0] - s[1]), s[2])
}

fn from_pdt(v: &Vector3<f64>) -> Stress {
    Vector3::new(v[0] + v[1], v[0] - v[1], v[2])
}

/// Newton iterations allowed for a root (the monotone iterates converge long before).
const ROOT_ITERATIONS: usize = 200;

/// Triangles whose return maps [`Material::update_lanes`] runs side by side.
pub const LANES: usize = 8;

/// A trial stress of [`Material::trial`].
enum Trial {
    /// In the elastic set, or an elastic body: the trial stress and the elastic tangent.
    Settled(Stress, Matrix3<f64>),
    /// Outside: the flow whose multiplier is the root of [`Flow::h`].
    Flowing(Flow),
}

/// The return map of a trial stress outside the elastic set, up to its multiplier mu.
#[derive(Clone, Copy)]
struct Flow {
    /// The trial stress in (p, d, t) coordinates, p, and |(d, t)|^2.
    v: Vector3<f64>,
    p: f64,
    r2: f64,
    /// sigma_Y^2.
    y2: f64,
    /// A = 1 + mu da, Bq = 1 + mu db.
    da: f64,
    db: f64,
    /// The norm weights of the elastic tensor and k / (2 lambda).
    alpha: f64,
    beta: f64,
    c: f64,
    /// The elastic tensor.
    e: Matrix3<f64>,
    /// A start below the root.
    start: f64,
}

impl Flow {
    /// The flow of a lane of [`Material::update_lanes`] with no triangle flowing in it:
    /// plain numbers (h = 0 at every mu), never finished. Why a lane holds one: the
    /// compiled loop of `update_lanes` computes with every lane's fields, and an
    /// `Option`'s empty slot left them as whatever the stack held, often subnormal
    /// numbers, whose arithmetic takes a microcode assist on x86. Measured
    /// ([`Model::update_stresses`] of `rates-elastic`, 34,304 triangles, one thread,
    /// fastest of 200): 3.2-3.3 ms per update with empty slots, 0.28 ms with the same code
    /// and denormals-are-zero set (MXCSR DAZ with FTZ; DAZ alone 0.31 ms, FTZ alone 3.2 ms:
    /// the cost was subnormal inputs), 0.27 ms with these lanes and the loop skipped where
    /// no lane flows.
    ///
    /// [`Model::update_stresses`]: crate::fe::Model::update_stresses
    const IDLE: Flow = Flow {
        v: Vector3::new(0.0, 0.0, 0.0),
        p: 0.0,
        r2: 0.0,
        y2: 0.0,
        da: 0.0,
        db: 0.0,
        alpha: 1.0,
        beta: 1.0,
        c: 0.0,
        e: Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        start: 0.0,
    };

    /// h(mu) and h'(mu): convex and decreasing, zero at the multiplier.
    fn h(&self, mu: f64) -> (f64, f64) {
        let (p, r2, da, db) = (self.p, self.r2, self.da, self.db);
        let a = 1.0 + mu * da;
        let bq = 1.0 + mu * db;
        let val = p * p / (a * a) + 3.0 * r2 / (bq * bq) - self.y2;
        let der = -2.0 * p * p * da / (a * a * a) - 6.0 * r2 * db / (bq * bq * bq);
        (val, der)
    }

    /// The stress and the consistent tangent at the multiplier `mu`.
    fn finish(&self, mu: f64) -> (Stress, Matrix3<f64>) {
        let (v, da, db, c) = (self.v, self.da, self.db, self.c);
        let a = 1.0 + mu * da;
        let bq = 1.0 + mu * db;
        // sigma_p = P_p (1 + mu/alpha), sigma_q = P_q (1 + 3 mu / beta).
        let phi = (1.0 + mu / self.alpha) / a;
        let psi = (1.0 + 3.0 * mu / self.beta) / bq;
        let sigma = from_pdt(&Vector3::new(v[0] * phi, v[1] * psi, v[2] * psi));
        // Tangent in (p, d, t): diag(phi, psi, psi) + (p phi', q psi') (grad mu)^T.
        let dphi = -0.5 * c / (a * a);
        let dpsi = -1.5 * c / (bq * bq);
        let (_, h_mu) = self.h(mu);
        let grad_h = Vector3::new(
            2.0 * v[0] / (a * a),
            6.0 * v[1] / (bq * bq),
            6.0 * v[2] / (bq * bq),
        );
        let grad_mu = -grad_h / h_mu;
        let col = Vector3::new(v[0] * dphi, v[1] * dpsi, v[2] * dpsi);
        let j_pdt =
            Matrix3::from_diagonal(&Vector3::new(phi, psi, psi)) + col * grad_mu.transpose();
        // Chain rule: tensor -> (p, d, t) -> tensor.
        let to = Matrix3::new(0.5, 0.5, 0.0, 0.5, -0.5, 0.0, 0.0, 0.0, 1.0);
        let from = Matrix3::new(1.0, 1.0, 0.0, 1.0, -1.0, 0.0, 0.0, 0.0, 1.0);
        (sigma, from * j_pdt * to * self.e)
    }
}

/// Root of a convex, strictly decreasing function, by Newton from `start`, a point with
/// `f(start) >= 0` (below the root): the iterates increase monotonically to the root, so
/// no safeguard is needed.
fn convex_decreasing_root(start: f64, f: impl Fn(f64) -> (f64, f64)) -> f64 {
    let mut mu = start;
    for _ in 0..ROOT_ITERATIONS {
        let (next, going) = root_step(mu, f(mu));
        mu = next;
        if !going {
            break;
        }
    }
    mu
}

/// One iteration of [`convex_decreasing_root`] from `mu`, where the function and its
/// derivative are `(v, dv)`: the next iterate, and whether to go on (not at or past the
/// root, and the step above round-off of mu; a NaN step goes on, as it did).
#[allow(clippy::neg_cmp_op_on_partial_ord)]
fn root_step(mu: f64, (v, dv): (f64, f64)) -> (f64, bool) {
    if v <= 0.0 || dv >= 0.0 {
        return (mu, false);
    }
    let step = -v / dv;
    let next = mu + step;
    (next, !(step <= 4.0 * f64::EPSILON * next))
}

impl Elasticity {
    /// The plane-stress elasticity of `young` and `poisson`.
    pub fn plane_stress(young: f64, poisson: f64) -> Self {
        Elasticity {
            young,
            poisson,
            plane: Plane::Stress,
        }
    }
    /// `a = E nu / (1 - nu^2)` (plane stress) or `E nu / ((1 + nu) (1 - 2 nu))` (plane
    /// strain).
    pub fn a(&self) -> f64 {
        let nu = self.poisson;
        match self.plane {
            Plane::Stress => self.young * nu / (1.0 - nu * nu),
            Plane::Strain => self.young * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
        }
    }
    /// The out-of-plane stress sigma_33 of the in-plane stress `s`: 0 in plane stress,
    /// nu (s11 + s22) in plane strain.
    pub fn sigma_33(&self, s: &Stress) -> f64 {
        match self.plane {
            Plane::Stress => 0.0,
            Plane::Strain => self.poisson * (s[0] + s[1]),
        }
    }
    /// `b = E / (1 + nu)`.
    pub fn b(&self) -> f64 {
        self.young / (1.0 + self.poisson)
    }
    /// Matrix of E acting on tensor components `[11, 22, 12]`.
    pub fn matrix(&self) -> Matrix3<f64> {
        let (a, b) = (self.a(), self.b());
        Matrix3::new(a + b, a, 0.0, a, a + b, 0.0, 0.0, 0.0, b)
    }
    /// `E tau`.
    pub fn apply(&self, tau: &Vector3<f64>) -> Vector3<f64> {
        self.matrix() * tau
    }
    /// `E^{-1} sigma` (the strain of a stress).
    pub fn compliance(&self, s: &Stress) -> Strain {
        let (a, b) = (self.a(), self.b());
        // E = a tr I + b I  =>  E^{-1} s = (s - a tr(s)/(2a + b) I) / b.
        let tr = s[0] + s[1];
        let m = a * tr / (2.0 * a + b);
        Vector3::new((s[0] - m) / b, (s[1] - m) / b, s[2] / b)
    }
    /// Weights of the E-norm squared in `(p, d, t)`: `alpha p^2 + beta (d^2 + t^2)`.
    fn norm_weights(&self) -> (f64, f64) {
        (4.0 * self.a() + 2.0 * self.b(), 2.0 * self.b())
    }
}

impl Material {
    /// Projection `P_B sigma` onto `{|tau|_VM <= sigma_Y}` in the E-inner product.
    /// Identity for an elastic body.
    pub fn project(&self, s: &Stress) -> Stress {
        let Some(vp) = self.viscoplastic else {
            return *s;
        };
        let y2 = vp.yield_stress * vp.yield_stress;
        if von_mises(s) * von_mises(s) <= y2 {
            return *s;
        }
        let (alpha, beta) = self.elastic.norm_weights();
        let v = to_pdt(s);
        let (p, r2) = (v[0], v[1] * v[1] + v[2] * v[2]);
        // Stationarity: P_p = alpha p / (alpha + mu), P_q = beta q / (beta + 3 mu).
        let mu = convex_decreasing_root(0.0, |mu| {
            let fa = alpha / (alpha + mu);
            let fb = beta / (beta + 3.0 * mu);
            let val = p * p * fa * fa + 3.0 * r2 * fb * fb - y2;
            let der =
                -2.0 * p * p * fa * fa / (alpha + mu) - 18.0 * r2 * fb * fb / (beta + 3.0 * mu);
            (val, der)
        });
        let fa = alpha / (alpha + mu);
        let fb = beta / (beta + 3.0 * mu);
        from_pdt(&Vector3::new(v[0] * fa, v[1] * fb, v[2] * fb))
    }

    /// Perzyna function `G(sigma) = -(1/(2 lambda)) E (sigma - P_B sigma)` (stress per time).
    pub fn g(&self, s: &Stress) -> Stress {
        match self.viscoplastic {
            None => Stress::zeros(),
            Some(vp) => -(0.5 / vp.lambda) * self.elastic.apply(&(s - self.project(s))),
        }
    }

    /// Whether `s` lies outside the elastic set B (viscoplastic flow active).
    pub fn is_plastic(&self, s: &Stress) -> bool {
        self.viscoplastic
            .is_some_and(|vp| von_mises(s) > vp.yield_stress * (1.0 + 1e-12))
    }

    /// Backward-Euler update of one triangle:
    /// solve `sigma = sigma_trial + k G(sigma)` with `sigma_trial = sigma_prev + E d_eps`.
    /// Returns sigma and the consistent tangent `d sigma / d eps` (tensor components).
    pub fn update(&self, sigma_trial: &Stress, k: f64) -> (Stress, Matrix3<f64>) {
        match self.trial(sigma_trial, k) {
            Trial::Settled(sigma, tangent) => (sigma, tangent),
            Trial::Flowing(flow) => {
                flow.finish(convex_decreasing_root(flow.start, |mu| flow.h(mu)))
            }
        }
    }

    /// The return map of `sigma_trial` up to its root: settled where the trial stress
    /// lies in the elastic set (or the body is elastic), else the flow to solve for.
    fn trial(&self, sigma_trial: &Stress, k: f64) -> Trial {
        let e = self.elastic.matrix();
        let Some(vp) = self.viscoplastic else {
            return Trial::Settled(*sigma_trial, e);
        };
        let y2 = vp.yield_stress * vp.yield_stress;
        let vm = von_mises(sigma_trial);
        if vm * vm <= y2 {
            return Trial::Settled(*sigma_trial, e);
        }
        let (alpha, beta) = self.elastic.norm_weights();
        let c = 0.5 * k / vp.lambda;
        let v = to_pdt(sigma_trial);
        let (p, r2) = (v[0], v[1] * v[1] + v[2] * v[2]);
        // With mu the multiplier of the projection of sigma (not of the trial):
        // P_p = p_tr / A(mu), P_q = q_tr / Bq(mu), A = 1 + mu (1/alpha + c/2),
        // Bq = 1 + 3 mu (1/beta + c/2), and h(mu) = P_p^2 + 3 |P_q|^2 - sigma_Y^2 = 0.
        let da = 1.0 / alpha + 0.5 * c;
        let db = 3.0 * (1.0 / beta + 0.5 * c);
        // A start below the root: with d = max(da, db), h(mu) >= vm^2 / (1 + mu d)^2 -
        // sigma_Y^2, which vanishes at (vm / sigma_Y - 1) / d. Measured (`rates`, 34,432
        // dofs, 4 steps, 93,352 plastic updates): 5.31 Newton steps per update against
        // 7.22 from 0, the constitutive updates 16.5 -> 15.8 ms (fastest of 25 runs).
        let start = (vm / vp.yield_stress - 1.0) / da.max(db);
        Trial::Flowing(Flow {
            v,
            p,
            r2,
            y2,
            da,
            db,
            alpha,
            beta,
            c,
            e,
            start,
        })
    }

    /// [`Material::update`] of several triangles (`trials[i]` of `materials[i]`, at most
    /// [`LANES`]), handed to `out(i, stress, tangent)` exactly once per triangle (the
    /// in-place fill of [`Model::update_stresses`] relies on it), to the same bits (NaN
    /// results aside, whose sign bit may differ): the Newton iterations of their return maps'
    /// roots run interleaved. One root is a chain of dependent divisions (two per
    /// iteration, 5.3 iterations on average in `rates`), which the processor cannot
    /// overlap with the next triangle's work past the loop's exit; side by side, the
    /// chains of several triangles overlap. Measured ([`Model::update_stresses`] at the
    /// last state of `rates`, 34,304 triangles, fastest of 100, 2 threads): 1.06 ms one at
    /// a time, 0.81 / 0.60 / 0.55 / 0.52 ms with 2 / 4 / 8 / 16 lanes.
    ///
    /// [`Model::update_stresses`]: crate::fe::Model::update_stresses
    pub fn update_lanes(
        materials: &[&Material],
        trials: &[Stress],
        k: f64,
        mut out: impl FnMut(usize, Stress, Matrix3<f64>),
    ) {
        let n = trials.len();
        assert!(
            n <= LANES && materials.len() == n,
            "at most LANES triangles"
        );
        // Lanes with no flowing triangle hold Flow::IDLE (see there) and are never run.
        let mut flows = [Flow::IDLE; LANES];
        let mut flowing = [false; LANES];
        let mut mu = [0.0; LANES];
        for i in 0..n {
            match materials[i].trial(&trials[i], k) {
                Trial::Settled(sigma, tangent) => out(i, sigma, tangent),
                Trial::Flowing(flow) => {
                    mu[i] = flow.start;
                    flowing[i] = true;
                    flows[i] = flow;
                }
            }
        }
        if !flowing.contains(&true) {
            return;
        }
        // Each lane runs convex_decreasing_root's loop, pass by pass.
        let mut running = flowing;
        for _ in 0..ROOT_ITERATIONS {
            let mut any = false;
            for i in 0..LANES {
                if running[i] {
                    (mu[i], running[i]) = root_step(mu[i], flows[i].h(mu[i]));
                    any |= running[i];
                }
            }
            if !any {
                break;
            }
        }
        for i in 0..LANES {
            if flowing[i] {
                let (sigma, tangent) = flows[i].finish(mu[i]);
                out(i, sigma, tangent);
            }
        }
    }

    /// Lipschitz-type scale `|E| / (2 lambda)` of G (1/time); zero for elastic bodies.
    pub fn g_rate_scale(&self) -> f64 {
        self.viscoplastic
            .map_or(0.0, |vp| self.elastic.matrix().norm() / (2.0 * vp.lambda))
    }
}
