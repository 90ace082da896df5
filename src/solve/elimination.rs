//! Nonlinear elimination inside Newton's line search (Lanzkron, Rose and Wilkes, SIAM J.
//! Sci. Comput. 17, 1996; Cai and Keyes, SIAM J. Sci. Comput. 24, 2002).
//!
//! Why: with stiff viscosity (k E / lambda >= 1e3) a few triangles of a forming hinge carry
//! trial stresses of tens of sigma_Y, and there the return map is far from its linear
//! model: a Newton step turns their trial stress (its pressure changes sign) and the stress
//! on the yield surface turns with it, where the consistent tangent predicts a change
//! proportional to the strain. Measured on `rates` level 1 at k E / lambda = 1e4: the
//! model's error was 1.4-2.4 sigma_Y in 3 of 440 triangles and at most 0.031 sigma_Y in the
//! others, and the full step raised the merit 150x, so the line search cut every step to
//! 1/8 for 20 iterations. Here the nodes of those few triangles are re-equilibrated after
//! the step, with every other unknown held, by a small dense Newton: the global merit then
//! judges the step on the rest of the mesh, where the linear model holds.
//!
//! The region re-equilibrated is those triangles and two rings of viscoplastic triangles
//! around them ([`RINGS`]): where a stiff body sits on its yield surface under a
//! concentrated load (modulus contrast E2/E1 = 1e6, node-on-segment contact, `study
//! stability`), the failing triangles' neighbours are on the yield surface too, and with
//! them held the stress field around the load cannot turn: there the step stalled at 1/16
//! to 1/32 for 20 iterations of one step (26 in all), with the model errors of the
//! neighbours only 0.01-0.05 sigma_Y but the residual already 1e-2 of the force scale.

use super::linear::SparseSystem;
use crate::contact::Row;
use crate::fe::{FIXED, Model, Pattern};
use crate::material::{Strain, Stress, von_mises};
use nalgebra::{DMatrix, DVector, Matrix3};
use rayon::prelude::*;

/// Error of a triangle's linear model, in units of its yield stress, above which it and
/// its [`RINGS`] rings of neighbours are re-equilibrated. Measured on the stiff cases of
/// `study stability` (k E / lambda = 1e4, 1e3, E2/E1 = 1e6; level 1, 4 steps, both cones),
/// newton's most iterations in one step with two rings: 7-9 for any value from 0.07 to
/// 0.3, but 44 in one case at 0.5; 0.2 is inside the band with room on both sides.
pub const MODEL_ERROR: f64 = 0.2;

/// Rings of neighbouring viscoplastic triangles (sharing a node) added to the failed ones.
/// Measured at [`MODEL_ERROR`] 0.1-0.2 (most iterations in one step over the three stiff
/// cases): no ring 15-26, one ring 8-9, two rings 6-8, three rings 5-8.
pub const RINGS: usize = 2;

/// Most Newton iterations of one local solve.
const LOCAL_ITERATIONS: usize = 50;

/// Local systems up to this size are solved dense (at most 261 unknowns in the stiff cases
/// of `study stability`), larger ones by a sparse LU: where a whole body yields in one
/// step (`study patch`, nts), hundreds of triangles fail at once and with their rings the
/// region reached 992 unknowns at level 3 and about 4,000 at level 4, where dense LU made
/// the study's level-4 run take 278 s instead of 0.4 s.
const DENSE_UNKNOWNS: usize = 400;

/// The local KKT matrix `[J C^T; C 0]`, dense or sparse by its size.
enum LocalMatrix {
    Dense(DMatrix<f64>),
    Sparse(Box<(SparseSystem, Pattern)>),
}

impl LocalMatrix {
    /// A zero matrix of size `n` whose entries can be the pairs in `entries`.
    fn new(n: usize, entries: impl Fn() -> Vec<(usize, usize)>) -> Self {
        if n <= DENSE_UNKNOWNS {
            LocalMatrix::Dense(DMatrix::zeros(n, n))
        } else {
            let pattern = Pattern::from_entries(n, entries());
            LocalMatrix::Sparse(Box::new((SparseSystem::new(&pattern), pattern)))
        }
    }
    fn add(&mut self, row: usize, col: usize, v: f64) {
        match self {
            LocalMatrix::Dense(m) => m[(row, col)] += v,
            LocalMatrix::Sparse(b) => {
                let slot = b.1.slot(row, col);
                b.0.values_mut()[slot] += v;
            }
        }
    }
    fn clear(&mut self) {
        match self {
            LocalMatrix::Dense(m) => m.fill(0.0),
            LocalMatrix::Sparse(b) => b.0.values_mut().fill(0.0),
        }
    }
    /// The solution of `A x = rhs`, None when A is singular.
    fn solve(&mut self, rhs: DVector<f64>) -> Option<DVector<f64>> {
        match self {
            LocalMatrix::Dense(m) => m.clone().lu().solve(&rhs),
            LocalMatrix::Sparse(b) => {
                b.0.factor_lu().ok()?;
                let mut x = rhs;
                b.0.solve(x.as_mut_slice());
                x.iter().all(|v| v.is_finite()).then_some(x)
            }
        }
    }
}

/// What the local solves of one time step share with the global residual.
pub struct Increment<'a> {
    /// Strains at t_{n-1} per triangle ([`Model::strains`]).
    pub strain_prev: &'a [Strain],
    /// Stresses at t_{n-1} per triangle.
    pub sigma_prev: &'a [Stress],
    /// Time step.
    pub k: f64,
    /// Constitutive source per triangle, if any.
    pub source: Option<&'a [Stress]>,
    /// External load minus the contact forces `C^T lambda` of the iterate, over all dofs
    /// (force).
    pub f_ext: &'a [f64],
    /// The contact rows.
    pub rows: &'a [Row],
    /// Which rows are active at the iterate: their gaps are held by the local solves.
    pub active: &'a [bool],
}

/// The mesh's adjacency for the local solves, built once per problem (the constrained
/// dofs, which they never move, are read from [`Model::equation`]).
pub struct Elimination {
    /// Triangles around each node, built at the first elimination (most solves never
    /// eliminate: at 2.2e6 dofs the lists cost a million allocations).
    node_elements: std::cell::OnceCell<Vec<Vec<usize>>>,
    /// Nodes of the mesh.
    n_nodes: usize,
}

/// What one [`Elimination::relax`] did.
#[derive(Debug, Default, Clone, Copy)]
pub struct Relaxed {
    /// Unknowns re-equilibrated.
    pub unknowns: usize,
    /// Local Newton iterations.
    pub iterations: usize,
}

impl Elimination {
    /// Adjacency of `model`.
    pub fn new(model: &Model) -> Self {
        Elimination {
            node_elements: std::cell::OnceCell::new(),
            n_nodes: model.n_nodes,
        }
    }

    /// Triangles around each node of `model` (the model of [`Elimination::new`]).
    fn node_elements(&self, model: &Model) -> &[Vec<usize>] {
        self.node_elements.get_or_init(|| {
            let mut node_elements = vec![Vec::new(); self.n_nodes];
            for (i, e) in model.elements.iter().enumerate() {
                for &a in &e.nodes {
                    node_elements[a].push(i);
                }
            }
            node_elements
        })
    }

    /// The viscoplastic triangles whose linear model fails on the step from `u` (stresses
    /// `sigma`, tangents `tangents`) to `trial` (stresses `sigma_trial`, tangents
    /// `tangents_trial`): `|sigma_trial - sigma - D (eps(trial) - eps(u))|_VM > MODEL_ERROR
    /// sigma_Y`. A triangle elastic at both ends is skipped: both stresses are then the
    /// same affine map of the strain, D is its slope, and the miss is round-off, below
    /// 1e-15 of stresses inside the yield surface.
    pub fn failed_triangles(
        model: &Model,
        u: &[f64],
        (sigma, tangents): (&[Stress], &[Matrix3<f64>]),
        trial: &[f64],
        (sigma_trial, tangents_trial): (&[Stress], &[Matrix3<f64>]),
    ) -> Vec<usize> {
        // Elastic bodies pay nothing: their linear model is exact.
        if model.materials.iter().all(|m| m.viscoplastic.is_none()) {
            return Vec::new();
        }
        let elastic: Vec<Matrix3<f64>> =
            model.materials.iter().map(|m| m.elastic.matrix()).collect();
        // Every triangle alone: the same list on any number of threads.
        model
            .elements
            .par_iter()
            .enumerate()
            .with_min_len(4096)
            .filter(|(i, e)| {
                let Some(vp) = model.materials[e.body].viscoplastic else {
                    return false;
                };
                let elastic = elastic[e.body];
                if tangents[*i] == elastic && tangents_trial[*i] == elastic {
                    return false;
                }
                let de = e.strain(trial) - e.strain(u);
                let miss = sigma_trial[*i] - sigma[*i] - tangents[*i] * de;
                von_mises(&miss) > MODEL_ERROR * vp.yield_stress
            })
            .map(|(i, _)| i)
            .collect()
    }

    /// `triangles` and [`RINGS`] rings of viscoplastic triangles around them, sorted.
    pub fn region(&self, model: &Model, triangles: &[usize]) -> Vec<usize> {
        let node_elements = self.node_elements(model);
        let mut region = triangles.to_vec();
        for _ in 0..RINGS {
            region = region
                .iter()
                .flat_map(|&i| model.elements[i].nodes)
                .flat_map(|a| node_elements[a].iter().copied())
                .chain(region.iter().copied())
                .filter(|&i| {
                    model.materials[model.elements[i].body]
                        .viscoplastic
                        .is_some()
                })
                .collect();
            region.sort_unstable();
            region.dedup();
        }
        region
    }

    /// Re-equilibrate the free dofs of `triangles`' nodes (all other dofs held) by a dense
    /// Newton with backtracking on the local residual `f_int - f_ext` at those dofs, until
    /// its largest entry is at most `tol` (force) or [`LOCAL_ITERATIONS`] have run. Moves
    /// `u` in place; the local residual never grows.
    pub fn relax(
        &self,
        model: &Model,
        step: &Increment,
        triangles: &[usize],
        u: &mut [f64],
        lambda: &mut [f64],
        tol: f64,
    ) -> Relaxed {
        let Some(local) = LocalProblem::new(self, model, step, triangles) else {
            return Relaxed::default();
        };
        let (nl, nc) = (local.dofs.len(), local.constrained.len());
        let mut multipliers = vec![0.0; nc];
        let mut iterations = 0;
        let mut kkt = local.kkt_matrix();
        let mut r = local.with_contact(local.residual(u, Some(&mut kkt)), &multipliers);
        while r.amax() > tol && iterations < LOCAL_ITERATIONS {
            local.add_rows(&mut kkt);
            let mut rhs = DVector::zeros(nl + nc);
            rhs.rows_mut(0, nl).copy_from(&(-&r));
            let Some(dx) = kkt.solve(rhs) else {
                break;
            };
            let accepted = local.line_search(u, &mut multipliers, &dx, r.norm_squared());
            iterations += 1;
            if !accepted {
                break;
            }
            kkt.clear();
            r = local.with_contact(local.residual(u, Some(&mut kkt)), &multipliers);
        }
        for ((i, _), m) in local.constrained.iter().zip(&multipliers) {
            lambda[*i] += m;
        }
        Relaxed {
            unknowns: nl,
            iterations,
        }
    }
}

/// The local problem of one [`Elimination::relax`]: its unknowns, the triangles whose
/// forces reach them, and the active contact rows through them.
struct LocalProblem<'a> {
    model: &'a Model,
    step: &'a Increment<'a>,
    /// The unknowns: global dofs, increasing.
    dofs: Vec<usize>,
    /// Every triangle touching the unknowns: the terms of their residual.
    patch: Vec<usize>,
    /// Active rows through the unknowns: (row, its entries (local unknown, coefficient)).
    constrained: Vec<(usize, Vec<(usize, f64)>)>,
}

impl<'a> LocalProblem<'a> {
    /// The local problem of `triangles`' nodes; None when they have no free dof.
    fn new(
        elimination: &Elimination,
        model: &'a Model,
        step: &'a Increment<'a>,
        triangles: &[usize],
    ) -> Option<Self> {
        let dofs = unknowns(model, step, triangles);
        if dofs.is_empty() {
            return None;
        }
        // Every triangle touching them contributes to their residual.
        let mut patch: Vec<usize> = dofs
            .iter()
            .flat_map(|&d| elimination.node_elements(model)[d / 2].iter().copied())
            .collect();
        patch.sort_unstable();
        patch.dedup();
        let mut local = LocalProblem {
            model,
            step,
            dofs,
            patch,
            constrained: Vec::new(),
        };
        // Active rows through the unknowns keep their gaps: the local KKT system
        // [J C^T; C 0] with C their entries at the unknowns (C dx = 0 keeps each gap).
        local.constrained = (0..step.rows.len())
            .filter(|&i| step.active[i])
            .filter_map(|i| {
                let c: Vec<(usize, f64)> = step.rows[i]
                    .entries
                    .iter()
                    .filter_map(|&(d, v)| local.local(d).map(|l| (l, v)))
                    .collect();
                (!c.is_empty()).then_some((i, c))
            })
            .collect();
        Some(local)
    }

    /// The local index of global dof `d`, if it is an unknown.
    fn local(&self, d: usize) -> Option<usize> {
        self.dofs.binary_search(&d).ok()
    }

    /// The residual `f_int - f_ext` at the unknowns for the displacements `u`, with the
    /// Jacobian's block added into `jacobian` when given.
    fn residual(&self, u: &[f64], mut jacobian: Option<&mut LocalMatrix>) -> DVector<f64> {
        let (model, step) = (self.model, self.step);
        let mut r =
            DVector::from_iterator(self.dofs.len(), self.dofs.iter().map(|&d| -step.f_ext[d]));
        for &i in &self.patch {
            let e = &model.elements[i];
            let (m, trial) =
                model.trial_stress(i, u, step.strain_prev, step.sigma_prev, step.k, step.source);
            let (s, d) = m.update(&trial, step.k);
            let fe = e.internal_force(&s);
            let ke = jacobian.as_ref().map(|_| e.stiffness(&d));
            let ed = e.dofs();
            for (a, &da) in ed.iter().enumerate() {
                let Some(la) = self.local(da) else { continue };
                r[la] += fe[a];
                if let (Some(j), Some(ke)) = (jacobian.as_deref_mut(), ke.as_ref()) {
                    for (b, &db) in ed.iter().enumerate() {
                        if let Some(lb) = self.local(db) {
                            j.add(la, lb, ke[(a, b)]);
                        }
                    }
                }
            }
        }
        r
    }

    /// `r` plus the contact forces `C^T multipliers` of the constrained rows.
    fn with_contact(&self, mut r: DVector<f64>, multipliers: &[f64]) -> DVector<f64> {
        for ((_, c), m) in self.constrained.iter().zip(multipliers) {
            for &(l, v) in c {
                r[l] += v * m;
            }
        }
        r
    }

    /// The zero KKT matrix `[J C^T; C 0]`, with the entries the Jacobian's block
    /// (accumulated by [`LocalProblem::residual`]) and the rows' can take.
    fn kkt_matrix(&self) -> LocalMatrix {
        let (nl, nc) = (self.dofs.len(), self.constrained.len());
        LocalMatrix::new(nl + nc, || {
            let mut entries: Vec<(usize, usize)> = (0..nl + nc).map(|i| (i, i)).collect();
            for &i in &self.patch {
                let ed: Vec<usize> = self.model.elements[i]
                    .dofs()
                    .iter()
                    .filter_map(|&d| self.local(d))
                    .collect();
                entries.extend(ed.iter().flat_map(|&a| ed.iter().map(move |&b| (a, b))));
            }
            for (j, (_, c)) in self.constrained.iter().enumerate() {
                entries.extend(c.iter().flat_map(|&(l, _)| [(l, nl + j), (nl + j, l)]));
            }
            entries
        })
    }

    /// Add the constrained rows' blocks C^T and C to `kkt`.
    fn add_rows(&self, kkt: &mut LocalMatrix) {
        let nl = self.dofs.len();
        for (j, (_, c)) in self.constrained.iter().enumerate() {
            for &(l, v) in c {
                kkt.add(l, nl + j, v);
                kkt.add(nl + j, l, v);
            }
        }
    }

    /// Backtracking along the step `dx` of the unknowns and multipliers (Armijo on the
    /// squared residual against `reference`, at most 30 halvings). Moves `u` and
    /// `multipliers` to the accepted trial and returns true, or leaves them as they were
    /// and returns false.
    fn line_search(
        &self,
        u: &mut [f64],
        multipliers: &mut Vec<f64>,
        dx: &DVector<f64>,
        reference: f64,
    ) -> bool {
        let nl = self.dofs.len();
        let start: Vec<f64> = self.dofs.iter().map(|&d| u[d]).collect();
        let start_multipliers = multipliers.clone();
        let mut alpha = 1.0;
        for _ in 0..30 {
            for (l, &d) in self.dofs.iter().enumerate() {
                u[d] = start[l] + alpha * dx[l];
            }
            for (j, m) in multipliers.iter_mut().enumerate() {
                *m = start_multipliers[j] + alpha * dx[nl + j];
            }
            let trial = self.with_contact(self.residual(u, None), multipliers);
            if trial.norm_squared() <= (1.0 - 1e-4 * alpha) * reference {
                return true;
            }
            alpha *= 0.5;
        }
        for (l, &d) in self.dofs.iter().enumerate() {
            u[d] = start[l];
        }
        *multipliers = start_multipliers;
        false
    }
}

/// The unknowns of the local solve of `triangles`, in increasing order: the free dofs of
/// their nodes, and those of every active row through them (a row moves with its multiplier
/// all its dofs).
fn unknowns(model: &Model, step: &Increment, triangles: &[usize]) -> Vec<usize> {
    let mut dofs: Vec<usize> = triangles
        .iter()
        .flat_map(|&i| model.elements[i].dofs())
        .filter(|&d| model.equation[d] != FIXED)
        .collect();
    dofs.sort_unstable();
    dofs.dedup();
    // An active row through them moves with its multiplier all its dofs: they join.
    let mut joined: Vec<usize> = (0..step.rows.len())
        .filter(|&i| step.active[i])
        .filter(|&i| {
            step.rows[i]
                .entries
                .iter()
                .any(|(d, _)| dofs.binary_search(d).is_ok())
        })
        .flat_map(|i| step.rows[i].entries.iter().map(|&(d, _)| d))
        .filter(|&d| model.equation[d] != FIXED)
        .collect();
    dofs.append(&mut joined);
    dofs.sort_unstable();
    dofs.dedup();
    dofs
}
