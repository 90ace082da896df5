//! What `grade` checks of each level before it claims a rate from it: that the file is a
//! converged solution of a P1 discretization of this problem, and that its pressure is a
//! pressure.
//!
//! - **Equilibrium.** The residual r = B^T sigma_h - f of the P1 problem on the file's own
//!   mesh (sigma_h the file's stress, or C eps(u_h) of an elastic body; f the scene's load
//!   integrals, equal to the bit to an export's loads_L.csv on its meshes), with the
//!   supports' and Gamma_C's dofs held, measured in energy:
//!   delta = sqrt(r^T K^-1 r) / ||u_h||_E (K the elastic stiffness with those dofs held).
//!   delta is the energy distance from u_h to u~_h = u_h - K^-1 r, the field with the same
//!   Gamma_C trace in equilibrium with the exported loads: the bound on what the residual can
//!   change in the graded error. Two causes leave one:
//!   - **the code's own load integration**: a code that integrates f and g with its own rule
//!     is in equilibrium with its loads, not with the exported integrals; its residual is
//!     their difference, which falls with h as a quadrature error does. grade integrates
//!     the scene's loads on the file's mesh with the common plain rules of P1 codes
//!     ([`LoadRule::common`]: no split at the loads' kinks) and takes the largest of their
//!     residuals, lambda_q, as the size a load rule leaves on that mesh;
//!   - **a solve stopped before it converged**: its residual is the iteration's, tied to
//!     neither the mesh nor the load. Where the load is t^k times a field of (x, y) (every
//!     manufactured scene), any rule's integral of it scales as t^k, and so does a load
//!     rule's residual, to the solver's round-off; an iteration's does not. The residuals of
//!     the steps are fitted by t_n^k times one vector (least squares in K^-1's norm): the
//!     part left over, delta_w, is the residual that is no load rule's.
//!
//!   A level is refused as unconverged where delta exceeds 1/20 of its error (below that, a
//!   perturbation orthogonal to the error in energy moves it by at most 0.13%) and either
//!   delta_w exceeds 1/20 of its error or delta exceeds LOAD_MARGIN lambda_q; and whatever the
//!   cause where delta exceeds BOUND_SHARE of its error. Otherwise it is graded with delta
//!   printed beside its error, and where delta exceeds 1/20 of the error, with the key
//!   error of u~_h beside the file's (`shift`): `grade` judges the key rate of those errors
//!   too, the rate without the residual.
//! - **Gamma_C.** The reactions r at Gamma_C's nodes are the contact forces (plus, for a code
//!   with its own load rule, its loads' difference there): the two sides' normal forces
//!   balance (action and reaction), a frictionless contact has no tangential force, and a
//!   unilateral one does not pull on the slave side, each to FORCE_SHARE of the resultant or
//!   LOAD_MARGIN times the common rules' load difference on Gamma_C's nodes, the larger.
//! - **The pressure.** Its resultant at T against the exact pressure's (or, where only the
//!   contact holds a body along Gamma_C's normal, that body's normal load): a negative ratio
//!   is a sign error, a ratio off 1 by more than 5% and the same to 1% at every level a scale
//!   factor (a multiplier's units, a missing length weight).

use crate::contact::Interface;
use crate::error::{Error, Result};
use crate::fe::{FIXED, LoadRule, Model};
use crate::quadrature::gauss_legendre;
use crate::solve::linear::SparseSystem;
use crate::verify::field::P1Field;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// Below this share of its own error, delta is no cause for concern: a perturbation d that
/// is orthogonal in energy to the error adds to it as sqrt(e^2 + d^2), so 1/20 moves it by
/// 0.13% at most.
pub const RESIDUAL_SHARE: f64 = 1.0 / 20.0;
/// delta at or below this is round-off of the assembled sums (the patch test's errors sit at
/// 1e-13, where 1/20 of the error is no limit a double-precision solve can meet).
pub const RESIDUAL_FLOOR: f64 = 1e-10;
/// A residual up to this many times lambda_q, the largest the common plain load rules leave
/// on the level's mesh, is of a load rule's size: the lumped load (f at the vertices, what a
/// code that interpolates f at the nodes assembles) has 3 times the centroid rule's error on
/// a quadratic load (x^2 on the unit triangle: 1/12 against 1/36, of opposite sign).
pub const LOAD_MARGIN: f64 = 3.0;
/// The largest delta, relative to the level's error, that is graded whatever its cause.
/// The correction K^-1 r is orthogonal in energy to the error of u~_h (Galerkin orthogonality
/// on the interior dofs, where both fields' loads are the exported integrals), so in the
/// energy norm the squares add: ||u - u_h||_E^2 = ||u - u~_h||_E^2 + ||K^-1 r||_E^2. Up to
/// delta = e/2 the residual carries at most a quarter of the error's energy, and the error
/// is the discretization's (with its load rule) more than the residual's; beyond it, not.
/// The key error is the theorem norm (H1 plus L2 stress), not the energy, and delta is
/// relative to ||u_h||_E, not to the exact solution: the comparison is one of sizes, and
/// the key error's own change (`shift`) is measured, not derived (GetFEM's IM_TRIANGLE(2)
/// loads, rates-exact level 0: -1.20% measured, -1.82% by the energy identity).
pub const BOUND_SHARE: f64 = 0.5;
/// Largest imbalance of the two sides' normal forces, tangential force and pulling force,
/// relative to the contact resultant (where the common load rules put less on Gamma_C).
pub const FORCE_SHARE: f64 = 1e-3;
/// A pressure resultant off the reference by more than this share at every level...
pub const SCALE_OFF: f64 = 0.05;
/// ...and the same ratio to this share at every level is a scale factor.
pub const SCALE_SAME: f64 = 0.01;

/// What one level's file gave, checked (maxima over its steps).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LevelCheck {
    /// delta: the equilibrium residual in energy relative to ||u_h||_E.
    pub residual: f64,
    /// lambda_q: the largest delta the common plain load rules leave on this mesh (their
    /// loads against the exported integrals, in the same norm).
    pub load_rule_residual: f64,
    /// What the common load rules' differences alone put into the three force checks on
    /// Gamma_C (imbalance, tangential, |normal| on the slave side), each over P, the
    /// largest over the rules and steps; `None` where nothing touches.
    pub load_rule_forces: Option<[f64; 3]>,
    /// (e(u~_h) - e(u_h)) / e(u_h) in the key quantity, where delta exceeds 1/20 of the
    /// error (measured by `grade`); `None` where it does not.
    pub shift: Option<f64>,
    /// delta_w: the part of the residual (relative as delta, maximum over the steps) that
    /// does not scale with the load as t^k; `None` with one step, or a load that is not t^k
    /// times a field of (x, y).
    pub off_load: Option<f64>,
    /// |P_1 - P_2| / P, the two sides' normal forces; `None` where nothing touches.
    pub imbalance: Option<f64>,
    /// The tangential forces on Gamma_C over P.
    pub tangential: Option<f64>,
    /// The slave side's pulling normal forces over P.
    pub pulling: Option<f64>,
    /// The pressure's resultant at T over the reference resultant; `None` without a
    /// pressure or a reference.
    pub pressure_ratio: Option<f64>,
}

/// What the equilibrium residual of a level points to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ResidualCause {
    /// delta at most 1/20 of the error (or round-off): nothing to tell.
    None,
    /// delta of the size the common load rules leave on the mesh: the code's own load
    /// integration.
    LoadRule,
    /// delta above LOAD_MARGIN lambda_q: an iteration's, not a load rule's.
    Unconverged,
}

impl ResidualCause {
    /// Its name in checks.csv.
    pub fn name(self) -> &'static str {
        match self {
            ResidualCause::None => "none",
            ResidualCause::LoadRule => "load rule",
            ResidualCause::Unconverged => "unconverged",
        }
    }
}

impl LevelCheck {
    /// The limit delta is held to where its cause is not a load rule: max(error / 20, 1e-10).
    pub fn residual_limit(error: f64) -> f64 {
        (RESIDUAL_SHARE * error).max(RESIDUAL_FLOOR)
    }

    /// delta / lambda_q: the residual against the largest the common load rules leave on
    /// this mesh (0 where they leave none).
    pub fn load_ratio(&self) -> f64 {
        match self.load_rule_residual > 0.0 {
            true => self.residual / self.load_rule_residual,
            false => f64::INFINITY * self.residual.signum().max(0.0),
        }
    }

    /// What the residual points to, given the level's key error `error`: a load rule's where
    /// delta is at most LOAD_MARGIN lambda_q and its part that does not scale with the load
    /// (delta_w) is at most 1/20 of the error.
    pub fn cause(&self, error: f64) -> ResidualCause {
        let limit = Self::residual_limit(error);
        let off_load = self.off_load.is_some_and(|w| w > limit);
        if self.residual <= limit {
            ResidualCause::None
        } else if self.load_ratio() <= LOAD_MARGIN && !off_load {
            ResidualCause::LoadRule
        } else {
            ResidualCause::Unconverged
        }
    }

    /// The limits of the Gamma_C force checks (imbalance, tangential, pulling):
    /// FORCE_SHARE, or, where the residual is not an iteration's, LOAD_MARGIN times what the
    /// code's load integration can put into each where larger: the common rules' share of
    /// it, scaled by delta / lambda_q (the code's rule against theirs in the interior). A
    /// converged solve with the exported loads (delta at round-off) is held to FORCE_SHARE.
    pub fn force_limits(&self, error: f64) -> [f64; 3] {
        let scale = match self.cause(error) {
            ResidualCause::Unconverged => 0.0,
            _ => LOAD_MARGIN * self.load_ratio(),
        };
        let forces = self.load_rule_forces.unwrap_or([0.0; 3]);
        forces.map(|f| FORCE_SHARE.max(scale * f))
    }

    /// Why the level is not a converged solution of the problem, given its error `error`
    /// in the key quantity (empty: it is one).
    pub fn problems(&self, error: f64) -> Vec<String> {
        let mut out = Vec::new();
        let cause = self.cause(error);
        if cause == ResidualCause::Unconverged {
            let limit = Self::residual_limit(error);
            let against = match self.off_load {
                Some(w) if w > limit => format!(
                    "{w:.3e} of it does not scale with the load from step to step, as a load rule's residual does"
                ),
                _ => format!(
                    "it is {:.3} times the {:.3e} the common load rules leave on this mesh, more than a load rule leaves ({LOAD_MARGIN} times)",
                    self.load_ratio(),
                    self.load_rule_residual
                ),
            };
            out.push(format!(
                "its equilibrium residual in energy is {:.3e} of ||u_h||_E, above 1/20 of its error {error:.3e}, and {against}: the solve stopped before it converged (tighten the solver's tolerance, or raise its iteration limit)",
                self.residual
            ));
        }
        // An unconverged residual is told above; a load rule's that large is told here.
        if cause == ResidualCause::LoadRule && self.residual > BOUND_SHARE * error {
            out.push(format!(
                "its equilibrium residual in energy is {:.3e} of ||u_h||_E, of the size the common load rules leave on this mesh ({:.3e}) but above 1/2 of its error {error:.3e}: its own load integration, not the contact discretization, makes that error (integrate the loads more finely, split at their kinks, or read them from loads_L.csv)",
                self.residual, self.load_rule_residual
            ));
        }
        let limits = self.force_limits(error);
        let beyond = |k: usize| match limits[k] > FORCE_SHARE {
            true => format!(
                " (above {:.3e}, what its load integration can put there)",
                limits[k]
            ),
            false => String::new(),
        };
        let share = |v: Option<f64>, k: usize| v.filter(|v| *v > limits[k]);
        if let Some(v) = share(self.imbalance, 0) {
            out.push(format!(
                "the normal contact forces of the two sides differ by {v:.3e} of the resultant{}: action and reaction do not balance on Gamma_C (an unconverged contact iteration, or a force on one side only)",
                beyond(0)
            ));
        }
        if let Some(v) = share(self.tangential, 1) {
            out.push(format!(
                "the contact forces on Gamma_C have a tangential part of {v:.3e} of the resultant{}: the problem is frictionless (is friction or a tied contact on?)",
                beyond(1)
            ));
        }
        if let Some(v) = share(self.pulling, 2) {
            out.push(format!(
                "the contact pulls on the slave side, with {v:.3e} of the resultant{}: unilateral contact only pushes (an active-set or augmented-Lagrangian loop stopped before its last active set)",
                beyond(2)
            ));
        }
        out
    }
}

/// One row of checks.csv: a graded level's checks and what they concluded.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct CheckRecord {
    pub level: usize,
    pub h: f64,
    /// The level's error in the key quantity (relative).
    pub error: f64,
    /// delta, the equilibrium residual in energy relative to ||u_h||_E: the energy distance
    /// to the field in equilibrium with the exported loads (Gamma_C held).
    pub residual: f64,
    /// The limit delta is held to where it is no load rule's: max(error / 20, 1e-10).
    pub residual_limit: f64,
    /// lambda_q: the largest delta of the common plain load rules on this mesh.
    #[serde(default)]
    pub load_rule_residual: Option<f64>,
    /// delta_w: the residual's part that does not scale with the load from step to step.
    #[serde(default)]
    pub residual_off_load: Option<f64>,
    /// What the residual points to: none, load rule, unconverged.
    #[serde(default)]
    pub residual_cause: Option<String>,
    /// The relative change of the key error the residual makes (where delta > error / 20).
    #[serde(default)]
    pub error_shift: Option<f64>,
    pub normal_imbalance: Option<f64>,
    pub tangential: Option<f64>,
    pub pulling: Option<f64>,
    /// The limits of the three force checks (FORCE_SHARE, or what the code's load
    /// integration can put there).
    #[serde(default)]
    pub imbalance_limit: Option<f64>,
    #[serde(default)]
    pub tangential_limit: Option<f64>,
    #[serde(default)]
    pub pulling_limit: Option<f64>,
    pub pressure_ratio: Option<f64>,
    /// `converged`, or `flagged` (the level gives no rate).
    pub verdict: String,
}

impl CheckRecord {
    /// The row of `check` at `level` (h, its `error`).
    pub fn new(level: usize, h: f64, error: f64, check: &LevelCheck) -> Self {
        let flagged = !check.problems(error).is_empty();
        let limits = check.force_limits(error);
        CheckRecord {
            level,
            h,
            error,
            residual: check.residual,
            residual_limit: LevelCheck::residual_limit(error),
            load_rule_residual: Some(check.load_rule_residual),
            residual_off_load: check.off_load,
            residual_cause: Some(check.cause(error).name().into()),
            error_shift: check.shift,
            normal_imbalance: check.imbalance,
            tangential: check.tangential,
            pulling: check.pulling,
            imbalance_limit: Some(limits[0]),
            tangential_limit: Some(limits[1]),
            pulling_limit: Some(limits[2]),
            pressure_ratio: check.pressure_ratio,
            verdict: if flagged { "flagged" } else { "converged" }.into(),
        }
    }
}

/// Gamma_C's nodes: for each, its side (0: body 1, slave) and its side's outward unit normal
/// (the mean of its pieces'), whether it is a corner of Gamma_C (pieces of two normals
/// meet there: the force's direction is any in their cone, so no tangential part is read),
/// and on a curved piece the sine of the largest angle between its normal and its
/// neighbours' (0 on a straight piece): its force, an integral over its support of
/// normals within that cone, may lean that far off its own normal without friction (and
/// where a support holds one of its dofs, the support takes part of it: no tangential part
/// is read there).
struct ContactNodes(BTreeMap<usize, ContactNode>);

/// (side, normal, corner, spread): one entry of [`ContactNodes`].
type ContactNode = (usize, [f64; 2], bool, f64);

/// |sin| of the angle between two unit vectors.
fn sine(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] * b[1] - a[1] * b[0]).abs()
}

/// The spread of each of `normals` (in trace order): the largest sine to a neighbour's.
fn spreads(normals: &[[f64; 2]]) -> Vec<f64> {
    (0..normals.len())
        .map(|k| {
            let before = k
                .checked_sub(1)
                .map_or(0.0, |p| sine(normals[p], normals[k]));
            let after = normals.get(k + 1).map_or(0.0, |&n| sine(n, normals[k]));
            before.max(after)
        })
        .collect()
}

impl ContactNodes {
    fn new(interface: &Interface) -> Self {
        let mut nodes: BTreeMap<usize, (usize, Vec<[f64; 2]>, f64)> = BTreeMap::new();
        for piece in &interface.pieces {
            // Body 1's averaged nodal normal (the piece's on a straight piece), and at a
            // body-2 node the opposite of body 1's normal where the normal through it meets.
            let slave: Vec<[f64; 2]> = (0..piece.slave_nodes.len())
                .map(|j| piece.slave_normal(j))
                .collect();
            let master: Vec<[f64; 2]> = piece
                .master_s
                .iter()
                .map(|&s| piece.normal_at(s).map(|v| -v))
                .collect();
            for (side, list, normals) in [
                (0, &piece.slave_nodes, slave),
                (1, &piece.master_nodes, master),
            ] {
                for ((&g, normal), spread) in list.iter().zip(&normals).zip(spreads(&normals)) {
                    let e = nodes.entry(g).or_insert((side, Vec::new(), 0.0));
                    e.1.push(*normal);
                    e.2 = e.2.max(spread);
                }
            }
        }
        ContactNodes(
            nodes
                .into_iter()
                .map(|(g, (side, normals, spread))| {
                    let sum = normals
                        .iter()
                        .fold([0.0; 2], |s, n| [s[0] + n[0], s[1] + n[1]]);
                    let len = sum[0].hypot(sum[1]).max(f64::MIN_POSITIVE);
                    let corner = normals.iter().any(|n| {
                        (n[0] - normals[0][0]).abs() + (n[1] - normals[0][1]).abs() > 1e-9
                    });
                    (g, (side, [sum[0] / len, sum[1] / len], corner, spread))
                })
                .collect(),
        )
    }

    /// The model with Gamma_C's dofs held beside the supports'.
    fn held(&self, model: &Model) -> Model {
        let mut held = model.clone();
        let mut next = 0;
        for (d, eq) in held.equation.iter_mut().enumerate() {
            if model.equation[d] == FIXED || self.0.contains_key(&(d / 2)) {
                *eq = FIXED;
            } else {
                *eq = next;
                next += 1;
            }
        }
        held.n_free = next;
        held
    }
}

/// The elastic stiffness of `held` over its free dofs, factored.
fn factored_stiffness(held: &Model) -> Result<SparseSystem> {
    let (pattern, slots) = held.stiffness_pattern(&[], held.n_free);
    let mut values = vec![0.0; pattern.nnz()];
    held.add_tangent(&held.elastic_tangents(), &slots, &mut values);
    let mut system = SparseSystem::with_values(pattern, values);
    system.factor_llt()?;
    Ok(system)
}

/// The sums the force checks read of a force over Gamma_C's nodes (global dofs; a component a
/// support holds is left out: it carries the support's reaction): |P_1 - P_2|, the
/// tangential parts' lengths (off the corners), and the slave side's pulling normal parts
/// (or, with `either_sign`, all its normal parts' sizes: a load difference of unknown sign);
/// and the resultant max(|P_1|, |P_2|).
fn force_sums(
    nodes: &ContactNodes,
    model: &Model,
    force: &[f64],
    either_sign: bool,
) -> ([f64; 3], f64) {
    let (mut push, mut tangential, mut pulling) = ([0.0f64; 2], 0.0f64, 0.0f64);
    for (&g, &(side, n, corner, spread)) in &nodes.0 {
        let r = [0, 1].map(|c| match model.equation[2 * g + c] {
            FIXED => 0.0,
            _ => force[2 * g + c],
        });
        let normal = r[0] * n[0] + r[1] * n[1];
        push[side] -= normal;
        if !corner {
            let lean = (r[1] * n[0] - r[0] * n[1]).abs();
            // On a straight piece spread = 0: the whole tangential part. On a curved one a
            // support that holds a dof of the node takes part of its contact force, so
            // what is left is no contact force's direction: nothing is read there.
            let held = (0..2).any(|c| model.equation[2 * g + c] == FIXED);
            tangential += match (spread > 0.0, held) {
                (true, true) => 0.0,
                (true, false) => (lean - spread * r[0].hypot(r[1])).max(0.0),
                (false, _) => lean,
            };
        }
        if side == 0 {
            pulling += match either_sign {
                true => normal.abs(),
                false => normal.max(0.0),
            };
        }
    }
    (
        [(push[0] - push[1]).abs(), tangential, pulling],
        push[0].abs().max(push[1].abs()),
    )
}

/// The contact forces' balance at one step from the reactions `reaction` (global dofs):
/// (imbalance, tangential, pulling) over the resultant, and the resultant; `None` where
/// nothing touches (resultant below 1e-12 of the load's size `load`).
fn contact_balance(
    nodes: &ContactNodes,
    model: &Model,
    reaction: &[f64],
    load: f64,
) -> Option<([f64; 3], f64)> {
    let (sums, resultant) = force_sums(nodes, model, reaction, false);
    (resultant > 1e-12 * load).then(|| (sums.map(|v| v / resultant), resultant))
}

/// One level's checks ([`check_level`]) and, where delta is above round-off, the correction
/// per step: K^-1 r over the global dofs (zero on the held ones), so that
/// u~_h = u_h - correction is in equilibrium with the exported loads.
pub struct Checked {
    pub check: LevelCheck,
    /// Per step of `steps`, K^-1 r (global dofs; empty where delta is at round-off).
    pub corrections: Vec<Vec<f64>>,
}

/// The checks of one level's steps on `model`: equilibrium against the exported loads and
/// against the common plain load rules, and Gamma_C's forces (maxima over the steps), and
/// the pressure's resultant at the last step, T.
pub fn check_level(model: &Model, interface: &Interface, steps: &[P1Field]) -> Result<Checked> {
    let nodes = ContactNodes::new(interface);
    let held = nodes.held(model);
    let system = match held.n_free {
        0 => None,
        _ => Some(factored_stiffness(&held)?),
    };
    let rules = LoadRule::common();
    let mut out = LevelCheck::default();
    let mut corrections = Vec::with_capacity(steps.len());
    let mut load = Vec::new();
    let max = |a: Option<f64>, b: f64| Some(a.map_or(b, |a| a.max(b)));
    // Per step: the residual over the free dofs, K^-1 of it and ||u_h||_E^2.
    let mut fitted: Vec<(Vec<f64>, Vec<f64>, f64)> = Vec::with_capacity(steps.len());
    // Each common rule's load minus the exported one at t (global dofs); integrated once, at
    // t = 1, where the load is t^k times a field of (x, y) and every step is at t > 0.
    let difference = |rule: &LoadRule, t: f64| -> Result<Vec<f64>> {
        let exported = model.load(t)?;
        let by_rule = model.load_by_rule(t, rule)?;
        Ok(by_rule.iter().zip(&exported).map(|(a, b)| a - b).collect())
    };
    let degree = model.load_time_degree();
    let at_unit_time = match (degree, steps.iter().all(|s| s.time > 0.0)) {
        (Some(_), true) => Some(
            rules
                .iter()
                .map(|rule| difference(rule, 1.0))
                .collect::<Result<Vec<_>>>()?,
        ),
        _ => None,
    };
    for step in steps {
        load = model.load(step.time)?;
        let internal = model.internal_force(&step.stress);
        let reaction: Vec<f64> = internal.iter().zip(&load).map(|(a, b)| a - b).collect();
        let energy: f64 = dot(
            &model.internal_force(&model.elastic_stresses(&step.u)),
            &step.u,
        )
        .max(f64::MIN_POSITIVE);
        // delta of a force over the global dofs, with the force over the free ones and K^-1
        // of it (both empty without free dofs).
        let in_energy = |force: &[f64]| -> (f64, Vec<f64>, Vec<f64>) {
            let Some(system) = &system else {
                return (0.0, Vec::new(), Vec::new());
            };
            let r = held.restrict(force);
            let mut z = r.clone();
            system.solve(&mut z);
            ((dot(&r, &z).max(0.0) / energy).sqrt(), r, z)
        };
        let (delta, r, z) = in_energy(&reaction);
        out.residual = out.residual.max(delta);
        let correction = match delta > RESIDUAL_FLOOR {
            true => held.expand(&z),
            false => Vec::new(),
        };
        if !z.is_empty() {
            fitted.push((r, z, energy));
        }
        corrections.push(correction);
        let size = load.iter().map(|v| v.abs()).sum::<f64>();
        let balance = contact_balance(&nodes, model, &reaction, size);
        if let Some(([i, t, p], _)) = balance {
            out.imbalance = max(out.imbalance, i);
            out.tangential = max(out.tangential, t);
            out.pulling = max(out.pulling, p);
        }
        for (i, rule) in rules.iter().enumerate() {
            // A load t^k g(x, y): every rule's difference is t^k times its difference at 1.
            let difference: Vec<f64> = match (degree, &at_unit_time) {
                (Some(k), Some(at_one)) => {
                    let scale = step.time.powf(k);
                    at_one[i].iter().map(|d| scale * d).collect()
                }
                _ => difference(rule, step.time)?,
            };
            out.load_rule_residual = out.load_rule_residual.max(in_energy(&difference).0);
            if let Some((_, resultant)) = balance {
                let sums = force_sums(&nodes, model, &difference, true).0;
                let shares = sums.map(|v| v / resultant);
                out.load_rule_forces = Some(match out.load_rule_forces {
                    Some(m) => [0, 1, 2].map(|k| m[k].max(shares[k])),
                    None => shares,
                });
            }
        }
    }
    if let (Some(k), true) = (degree, fitted.len() >= 2) {
        let scales: Vec<f64> = steps.iter().map(|s| s.time.powf(k)).collect();
        out.off_load = Some(off_load(&fitted, &scales));
    }
    if let Some(last) = steps.last() {
        out.pressure_ratio = pressure_ratio(model, interface, last, &load);
    }
    Ok(Checked {
        check: out,
        corrections,
    })
}

/// delta_w: the steps' residuals r_n (with z_n = K^-1 r_n and ||u_h||_E^2 at each) fitted
/// by s_n rho, s_n = t_n^k (least squares: rho = sum s_n r_n / sum s_n^2, the same in any
/// norm), and the largest remainder sqrt((r_n - s_n rho)^T K^-1 (r_n - s_n rho)) / ||u_h||_E.
fn off_load(fitted: &[(Vec<f64>, Vec<f64>, f64)], scales: &[f64]) -> f64 {
    let norm: f64 = scales.iter().map(|s| s * s).sum();
    let n = fitted[0].0.len();
    let (mut rho, mut zeta) = (vec![0.0; n], vec![0.0; n]);
    for ((r, z, _), s) in fitted.iter().zip(scales) {
        for i in 0..n {
            rho[i] += s * r[i] / norm;
            zeta[i] += s * z[i] / norm;
        }
    }
    fitted
        .iter()
        .zip(scales)
        .map(|((r, z, energy), s)| {
            let w: f64 = (0..n)
                .map(|i| (r[i] - s * rho[i]) * (z[i] - s * zeta[i]))
                .sum();
            (w.max(0.0) / energy).sqrt()
        })
        .fold(0.0, f64::max)
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The resultant of the file's pressure at T over the reference's: the exact pressure's
/// integral over Gamma_C, or where only the contact holds a body along Gamma_C's normal,
/// that body's normal load (from `load`, the nodal loads at T). `None` without a pressure
/// or a reference.
fn pressure_ratio(
    model: &Model,
    interface: &Interface,
    last: &P1Field,
    load: &[f64],
) -> Option<f64> {
    let profile = last.pressure.as_ref()?;
    let given: f64 = profile
        .iter()
        .flat_map(|piece| piece.windows(2))
        .map(|w| {
            let (a, b) = (w[0].0, w[1].0);
            (b[0] - a[0]).hypot(b[1] - a[1]) * 0.5 * (w[0].1 + w[1].1)
        })
        .sum();
    let reference = exact_resultant(model, interface, last.time)
        .or_else(|| normal_load(model, interface, load))?;
    (reference.abs() > 0.0).then(|| given / reference)
}

/// The exact pressure's integral over Gamma_C at `t`, by 8 Gauss points on each segment of
/// the slave trace (far below the 1% the scale check reads).
fn exact_resultant(model: &Model, interface: &Interface, t: f64) -> Option<f64> {
    let exact = model.scene.exact.as_deref()?;
    let gauss = gauss_legendre(8);
    let mut total = 0.0;
    for piece in &interface.pieces {
        for w in piece.slave_s.windows(2) {
            let len = w[1] - w[0];
            for &(q, wq) in &gauss {
                let x = piece.point(w[0] + q * len);
                total += wq * len * exact.pressure_at(piece.normal, x[0], x[1], t)?;
            }
        }
    }
    Some(total)
}

/// Where only the contact holds a body along Gamma_C's (straight) normal, its load along
/// that normal toward the other body: the contact resultant equilibrium gives.
fn normal_load(model: &Model, interface: &Interface, load: &[f64]) -> Option<f64> {
    let body = interface.held_only_by_contact(model)?;
    let n = interface.pieces[0].normal;
    let nodes = model.node_offset[body]..model.node_offset[body] + model.meshes[body].nodes.len();
    let along: f64 = nodes
        .map(|g| load[2 * g] * n[0] + load[2 * g + 1] * n[1])
        .sum();
    // Body 1 pushes along nu^1 onto body 2; body 2 along -nu^1.
    Some(if body == 0 { along } else { -along })
}

/// Refuses pressures whose resultants `ratios` (per level, with its file) are of the wrong
/// sign, or a constant scale factor away from the reference.
pub fn check_pressure_scale(ratios: &[(usize, &Path, f64)]) -> Result<()> {
    if let Some((level, file, r)) = ratios.iter().find(|(_, _, r)| *r < 0.0) {
        return Err(Error::input(
            file,
            "pressure",
            format!(
                "at level {level} the pressure's resultant over Gamma_C is {r:.4} times the exact one: its sign is flipped; write the pressure positive in compression (multiply your multiplier or nodal force by -1 where it is negative in compression)"
            ),
        ));
    }
    let (Some(lo), Some(hi)) = (
        ratios.iter().map(|r| r.2).min_by(f64::total_cmp),
        ratios.iter().map(|r| r.2).max_by(f64::total_cmp),
    ) else {
        return Ok(());
    };
    let list: Vec<String> = ratios
        .iter()
        .map(|(l, _, r)| format!("level {l}: {r:.4}"))
        .collect();
    let off = ratios.iter().all(|(_, _, r)| (r - 1.0).abs() > SCALE_OFF);
    if ratios.len() >= 2 && off && hi <= lo * (1.0 + SCALE_SAME) {
        return Err(Error::input(
            ratios[0].1,
            "pressure",
            format!(
                "the pressure's resultant over Gamma_C is the same factor of the exact one at every level ({}): a scale factor, not a discretization error; divide the pressure by {:.4} after finding where it comes from (a multiplier in other units, or a nodal force not divided by its length weight: the export's README.md, 'A pressure from contact forces or multipliers')",
                list.join(", "),
                0.5 * (lo + hi)
            ),
        ));
    }
    // A pressure in other units: off by more than a factor 2 at every level, however the
    // factor varies (a multiplier scaled per level). Chosen beyond the 5%/1% rule above,
    // which needs the same factor at every level.
    if ratios.iter().all(|(_, _, r)| !(0.5..=2.0).contains(r)) {
        return Err(Error::input(
            ratios[0].1,
            "pressure",
            format!(
                "the pressure's resultant over Gamma_C is far from the exact one at every level ({}): it is not a pressure in the scene's units (force per length); convert the multiplier or nodal forces by the export's README.md, 'A pressure from contact forces or multipliers'",
                list.join(", ")
            ),
        ));
    }
    Ok(())
}
