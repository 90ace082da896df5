//! What `grade` checks of each level before it claims a rate from it: that the file is a
//! converged solution of this problem, and that its pressure is a pressure.
//!
//! - **Equilibrium.** The residual r = B^T sigma_h - f of the P1 problem on the file's own
//!   mesh (sigma_h the file's stress, or C eps(u_h) of an elastic body; f the scene's load
//!   integrals, equal to the bit to an export's loads_L.csv on its meshes), with the
//!   supports' and Gamma_C's dofs held, measured in energy:
//!   delta = sqrt(r^T K^-1 r) / ||u_h||_E (K the elastic stiffness with those dofs held).
//!   A solve stopped early leaves delta at the size of the error it adds; a level where
//!   delta exceeds 1/20 of its own error is an iteration's state, not a discretization's.
//! - **Gamma_C.** The reactions r at Gamma_C's nodes are the contact forces: the two sides'
//!   normal forces balance (action and reaction), a frictionless contact has no tangential
//!   force, and a unilateral one does not pull on the slave side.
//! - **The pressure.** Its resultant at T against the exact pressure's (or, where only the
//!   contact holds a body along Gamma_C's normal, that body's normal load): a negative ratio
//!   is a sign error, a ratio off 1 by more than 5% and the same to 1% at every level a scale
//!   factor (a multiplier's units, a missing length weight).

use crate::contact::Interface;
use crate::error::{Error, Result};
use crate::fe::{FIXED, Model};
use crate::quadrature::gauss_legendre;
use crate::solve::linear::SparseSystem;
use crate::verify::field::P1Field;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// A level is not a converged solution where delta exceeds this share of its own error.
pub const RESIDUAL_SHARE: f64 = 1.0 / 20.0;
/// delta at or below this is round-off of the assembled sums (the patch test's errors sit at
/// 1e-13, where 1/20 of the error is no limit a double-precision solve can meet).
pub const RESIDUAL_FLOOR: f64 = 1e-10;
/// Largest imbalance of the two sides' normal forces, tangential force and pulling force,
/// relative to the contact resultant.
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

impl LevelCheck {
    /// Why the level is not a converged solution of the problem, given its error `error`
    /// in the key quantity (empty: it is one).
    pub fn problems(&self, error: f64) -> Vec<String> {
        let mut out = Vec::new();
        let limit = (RESIDUAL_SHARE * error).max(RESIDUAL_FLOOR);
        if self.residual > limit {
            out.push(format!(
                "its equilibrium residual in energy is {:.3e} of ||u_h||_E, above 1/20 of its error {:.3e}: the solve stopped before it converged (tighten the solver's tolerance, or raise its iteration limit)",
                self.residual, error
            ));
        }
        let share = |v: Option<f64>| v.filter(|v| *v > FORCE_SHARE);
        if let Some(v) = share(self.imbalance) {
            out.push(format!(
                "the normal contact forces of the two sides differ by {v:.3e} of the resultant: action and reaction do not balance on Gamma_C (an unconverged contact iteration, or a force on one side only)"
            ));
        }
        if let Some(v) = share(self.tangential) {
            out.push(format!(
                "the contact forces on Gamma_C have a tangential part of {v:.3e} of the resultant: the problem is frictionless (is friction or a tied contact on?)"
            ));
        }
        if let Some(v) = share(self.pulling) {
            out.push(format!(
                "the contact pulls on the slave side, with {v:.3e} of the resultant: unilateral contact only pushes (an active-set or augmented-Lagrangian loop stopped before its last active set)"
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
    /// delta, the equilibrium residual in energy relative to ||u_h||_E.
    pub residual: f64,
    /// The limit delta is held to: max(error / 20, 1e-10).
    pub residual_limit: f64,
    pub normal_imbalance: Option<f64>,
    pub tangential: Option<f64>,
    pub pulling: Option<f64>,
    pub pressure_ratio: Option<f64>,
    /// `converged`, or `flagged` (the level gives no rate).
    pub verdict: String,
}

impl CheckRecord {
    /// The row of `check` at `level` (h, its `error`).
    pub fn new(level: usize, h: f64, error: f64, check: &LevelCheck) -> Self {
        let flagged = !check.problems(error).is_empty();
        CheckRecord {
            level,
            h,
            error,
            residual: check.residual,
            residual_limit: (RESIDUAL_SHARE * error).max(RESIDUAL_FLOOR),
            normal_imbalance: check.imbalance,
            tangential: check.tangential,
            pulling: check.pulling,
            pressure_ratio: check.pressure_ratio,
            verdict: if flagged { "flagged" } else { "converged" }.into(),
        }
    }
}

/// Gamma_C's nodes: for each, its side (0: body 1, slave) and its side's outward unit normal
/// (the mean of its pieces'), and whether it is a corner of Gamma_C (pieces of two normals
/// meet there: the force's direction is any in their cone, so no tangential part is read).
struct ContactNodes(BTreeMap<usize, (usize, [f64; 2], bool)>);

impl ContactNodes {
    fn new(interface: &Interface) -> Self {
        let mut nodes: BTreeMap<usize, (usize, [f64; 2], Vec<[f64; 2]>)> = BTreeMap::new();
        for piece in &interface.pieces {
            let n = piece.normal;
            for (side, list, normal) in [
                (0, &piece.slave_nodes, n),
                (1, &piece.master_nodes, [-n[0], -n[1]]),
            ] {
                for &g in list {
                    let e = nodes.entry(g).or_insert((side, [0.0; 2], Vec::new()));
                    e.2.push(normal);
                }
            }
        }
        ContactNodes(
            nodes
                .into_iter()
                .map(|(g, (side, _, normals))| {
                    let sum = normals
                        .iter()
                        .fold([0.0; 2], |s, n| [s[0] + n[0], s[1] + n[1]]);
                    let len = sum[0].hypot(sum[1]).max(f64::MIN_POSITIVE);
                    let corner = normals.iter().any(|n| {
                        (n[0] - normals[0][0]).abs() + (n[1] - normals[0][1]).abs() > 1e-9
                    });
                    (g, (side, [sum[0] / len, sum[1] / len], corner))
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

/// The contact forces' balance at one step from the reactions `reaction` (global dofs):
/// (imbalance, tangential, pulling) over the resultant, or `None` where nothing touches
/// (resultant below 1e-12 of the load's size `load`).
fn contact_balance(
    nodes: &ContactNodes,
    model: &Model,
    reaction: &[f64],
    load: f64,
) -> Option<(f64, f64, f64)> {
    let (mut push, mut tangential, mut pulling) = ([0.0f64; 2], 0.0f64, 0.0f64);
    for (&g, &(side, n, corner)) in &nodes.0 {
        // A component a support holds carries the support's reaction, not the contact's.
        let r = [0, 1].map(|c| match model.equation[2 * g + c] {
            FIXED => 0.0,
            _ => reaction[2 * g + c],
        });
        let normal = r[0] * n[0] + r[1] * n[1];
        push[side] -= normal;
        if !corner {
            tangential += (r[1] * n[0] - r[0] * n[1]).abs();
        }
        if side == 0 {
            pulling += normal.max(0.0);
        }
    }
    let resultant = push[0].abs().max(push[1].abs());
    (resultant > 1e-12 * load).then(|| {
        (
            (push[0] - push[1]).abs() / resultant,
            tangential / resultant,
            pulling / resultant,
        )
    })
}

/// The checks of one level's steps on `model`: equilibrium and Gamma_C's forces (maxima
/// over the steps), and the pressure's resultant at the last step, T.
pub fn check_level(model: &Model, interface: &Interface, steps: &[P1Field]) -> Result<LevelCheck> {
    let nodes = ContactNodes::new(interface);
    let held = nodes.held(model);
    let system = match held.n_free {
        0 => None,
        _ => Some(factored_stiffness(&held)?),
    };
    let mut out = LevelCheck::default();
    let mut load = Vec::new();
    for step in steps {
        load = model.load(step.time)?;
        let internal = model.internal_force(&step.stress);
        let reaction: Vec<f64> = internal.iter().zip(&load).map(|(a, b)| a - b).collect();
        let energy: f64 = dot(
            &model.internal_force(&model.elastic_stresses(&step.u)),
            &step.u,
        );
        if let Some(system) = &system {
            let r = held.restrict(&reaction);
            let mut z = r.clone();
            system.solve(&mut z);
            let delta = (dot(&r, &z).max(0.0) / energy.max(f64::MIN_POSITIVE)).sqrt();
            out.residual = out.residual.max(delta);
        }
        let size = load.iter().map(|v| v.abs()).sum::<f64>();
        if let Some((i, t, p)) = contact_balance(&nodes, model, &reaction, size) {
            let max = |a: Option<f64>, b: f64| Some(a.map_or(b, |a| a.max(b)));
            out.imbalance = max(out.imbalance, i);
            out.tangential = max(out.tangential, t);
            out.pulling = max(out.pulling, p);
        }
    }
    if let Some(last) = steps.last() {
        out.pressure_ratio = pressure_ratio(model, interface, last, &load);
    }
    Ok(out)
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
