//! A discrete solution as the error integrals see it: P1 displacements at the nodes and P0
//! stresses on the triangles of a mesh of both bodies, optionally a contact pressure along
//! Gamma_C, over the time steps. Any contact code can provide this much (no multipliers, no
//! active set, no solver state), so the same integrals grade this project's cones and a code
//! it did not write.

use crate::case::Case;
use crate::contact::Interface;
use crate::fe::Model;
use crate::material::Stress;
use crate::solve::{Problem, Solution, State};
use std::borrow::Cow;

/// A contact pressure along Gamma_C: per piece of the interface, (position, pressure) at the
/// body-1 trace nodes in order along the piece (force per length), linear in between. Two
/// consecutive points at one position make a jump there (LAC's pressure, constant on each
/// macro-element, is its two ends' values per macro-element).
pub type PressureProfile = Vec<Vec<([f64; 2], f64)>>;

/// One time step of a discrete solution.
#[derive(Debug, Clone)]
pub struct P1Field<'a> {
    /// Time t_n.
    pub time: f64,
    /// Nodal displacements, x and y per node of the model (length).
    pub u: Cow<'a, [f64]>,
    /// Stress per triangle of the model, `[s11, s22, s12]` (stress units).
    pub stress: Cow<'a, [Stress]>,
    /// The contact pressure; `None` when the solution gives none (its pressure quantities
    /// are then not measured).
    pub pressure: Option<PressureProfile>,
    /// The space the pressure lies in, between the profile's points.
    pub pressure_space: PressureSpace,
}

pub use crate::contact::PressureSpace;

/// Why a displacement field cannot be measured.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FieldError {
    #[error("the displacement has {got} values; the mesh has {nodes} nodes, so it needs {}", 2 * nodes)]
    DisplacementLength { got: usize, nodes: usize },
    #[error("the stress has {got} values; the mesh has {triangles} triangles, one stress each")]
    StressLength { got: usize, triangles: usize },
    #[error("the pressure has {got} values; the mesh has {nodes} nodes, one value each")]
    PressureLength { got: usize, nodes: usize },
    #[error(
        "body {body} {why}, so its stress does not follow from the displacement: give the stress per triangle"
    )]
    StressNeeded { body: usize, why: &'static str },
    #[error(
        "{field} is not finite at {what} {index}: write finite values (a diverged solve is not graded)"
    )]
    NotFinite {
        field: &'static str,
        what: &'static str,
        index: usize,
    },
}

impl<'a> P1Field<'a> {
    /// A state of this project's solver, borrowed; its pressure is the nodal multiplier over
    /// its lumped weight at the body-1 trace nodes.
    pub fn of_state(p: &Problem, s: &'a State) -> Self {
        P1Field {
            time: s.time,
            u: Cow::Borrowed(&s.u),
            stress: Cow::Borrowed(&s.sigma),
            pressure: Some(pressure_profile(p, s)),
            pressure_space: p.method.pressure_space(),
        }
    }

    /// A solution computed elsewhere on `model`'s mesh: the displacement at the nodes (x, y
    /// per node), the stress per triangle where the solution gives it, and the pressure per
    /// node where it gives one (only the body-1 trace nodes of `interface` are read). Without
    /// stresses, an elastic body's stress is its elastic stress C eps(u_h) per triangle; a
    /// viscoplastic body's cannot be derived and is an error.
    pub fn from_nodal(
        model: &Model,
        interface: &Interface,
        time: f64,
        u: Vec<f64>,
        stress: Option<Vec<Stress>>,
        pressure: Option<Vec<f64>>,
    ) -> Result<P1Field<'static>, FieldError> {
        let (nodes, triangles) = (model.n_nodes, model.elements.len());
        if u.len() != 2 * nodes {
            return Err(FieldError::DisplacementLength {
                got: u.len(),
                nodes,
            });
        }
        finite("the displacement", "node", u.iter().map(|v| *v), 2)?;
        let stress = match stress {
            Some(s) if s.len() != triangles => {
                return Err(FieldError::StressLength {
                    got: s.len(),
                    triangles,
                });
            }
            Some(s) => s,
            None => elastic_stress(model, &u)?,
        };
        finite(
            "the stress",
            "triangle",
            stress.iter().flat_map(|s| s.iter().copied()),
            3,
        )?;
        let pressure = match pressure {
            Some(p) if p.len() != nodes => {
                return Err(FieldError::PressureLength {
                    got: p.len(),
                    nodes,
                });
            }
            Some(p) => {
                finite("the pressure", "node", p.iter().copied(), 1)?;
                Some(nodal_pressure_profile(model, interface, &p))
            }
            None => None,
        };
        Ok(P1Field {
            time,
            u: Cow::Owned(u),
            stress: Cow::Owned(stress),
            pressure,
            pressure_space: PressureSpace::Linear,
        })
    }
}

/// The first value that is not finite, as the entity (`per` values each) it belongs to.
fn finite(
    field: &'static str,
    what: &'static str,
    values: impl Iterator<Item = f64>,
    per: usize,
) -> Result<(), FieldError> {
    match values.enumerate().find(|(_, v)| !v.is_finite()) {
        Some((i, _)) => Err(FieldError::NotFinite {
            field,
            what,
            index: i / per,
        }),
        None => Ok(()),
    }
}

/// C eps(u) per triangle, for a displacement of elastic bodies whose law has no
/// constitutive source (with one, sigma_n = sigma_(n-1) + E (eps_n - eps_(n-1)) + k s_n is
/// not E eps(u_n)).
fn elastic_stress(model: &Model, u: &[f64]) -> Result<Vec<Stress>, FieldError> {
    if let Some(body) = (0..2).find(|&b| model.materials[b].viscoplastic.is_some()) {
        return Err(FieldError::StressNeeded {
            body: body + 1,
            why: "is viscoplastic",
        });
    }
    if model
        .scene
        .exact
        .as_deref()
        .is_some_and(|e| e.source_rate.is_some())
    {
        return Err(FieldError::StressNeeded {
            body: 1,
            why: "has a constitutive source (the scene gives its exact stress)",
        });
    }
    Ok(model.elastic_stresses(u))
}

/// The pressure of a discrete solution of this project's solver: the nodal multiplier over
/// its lumped weight at the body-1 trace nodes (force per length), per piece; for LAC the
/// multiplier over |M|, constant on each macro-element M (written at M's two ends).
pub fn pressure_profile(p: &Problem, s: &State) -> PressureProfile {
    let mut out: PressureProfile = vec![Vec::new(); p.interface.pieces.len()];
    for (row, l) in p.rows.iter().zip(&s.lambda) {
        let piece = &p.interface.pieces[row.piece];
        let value = row.pressure(*l);
        for at in row.pressure_at(piece) {
            out[row.piece].push((piece.point(at), value));
        }
    }
    out
}

/// A nodal pressure (one value per node of `model`) at the body-1 trace nodes, per piece.
fn nodal_pressure_profile(model: &Model, interface: &Interface, p: &[f64]) -> PressureProfile {
    interface
        .pieces
        .iter()
        .map(|piece| {
            piece
                .slave_nodes
                .iter()
                .map(|&n| (model.position(n), p[n]))
                .collect()
        })
        .collect()
}

/// A discrete solution's history t_1..t_N on one mesh: what is measured against a truth.
pub struct P1History<'a> {
    /// The mesh of both bodies, with their materials.
    pub model: &'a Model,
    /// Gamma_C on that mesh.
    pub interface: &'a Interface,
    /// The steps t_1..t_N (t_0 is the initial state, not measured).
    pub steps: Vec<P1Field<'a>>,
}

impl<'a> P1History<'a> {
    /// A solve of this project's solver, borrowed.
    pub fn of_solution(case: &'a Case, sol: &'a Solution) -> Self {
        let p = &case.problem;
        P1History {
            model: &p.model,
            interface: &p.interface,
            steps: sol
                .states
                .iter()
                .skip(1)
                .map(|s| P1Field::of_state(p, s))
                .collect(),
        }
    }
}
