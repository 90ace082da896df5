//! P1 finite elements on the two bodies: degrees of freedom with Dirichlet and roller
//! conditions, the sparse pattern with its entry-to-slot map (computed once per mesh),
//! loads from tractions and body forces, and assembly of internal force and tangent.

use crate::error::{Error, Result};
use crate::expr::kink_functions;
use crate::material::{LANES, Material, Strain, Stress};
use crate::mesh::{BodyMesh, MeshSource, RawMesh};
use crate::quadrature;
use crate::scene::Scene;
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};
use rayon::prelude::*;
use std::mem::MaybeUninit;

mod load;

pub use load::{LoadRule, forget_loads};
use std::path::Path;

/// Marker for a constrained degree of freedom.
pub const FIXED: usize = usize::MAX;

/// One P1 triangle of either body, with its geometry precomputed.
#[derive(Debug, Clone)]
pub struct Element {
    /// 0 for body 1 (slave), 1 for body 2 (master).
    pub body: usize,
    /// Global node indices.
    pub nodes: [usize; 3],
    /// Area.
    pub area: f64,
    /// Shape-function gradients (d/dx, d/dy) of the three hats.
    pub grads: [[f64; 2]; 3],
}

/// Strain-displacement matrix with engineering shear: rows e11, e22, 2 e12.
pub type BMatrix = SMatrix<f64, 3, 6>;

impl Element {
    /// The B matrix (engineering shear row), so that `sigma . (B v) = sigma : eps(v)`.
    pub fn b_matrix(&self) -> BMatrix {
        let mut b = BMatrix::zeros();
        for (a, g) in self.grads.iter().enumerate() {
            b[(0, 2 * a)] = g[0];
            b[(1, 2 * a + 1)] = g[1];
            b[(2, 2 * a)] = g[1];
            b[(2, 2 * a + 1)] = g[0];
        }
        b
    }
    /// Tensor strain of the element for the global displacement vector `u`.
    pub fn strain(&self, u: &[f64]) -> Strain {
        let mut e = Strain::zeros();
        for (a, g) in self.grads.iter().enumerate() {
            let (ux, uy) = (u[2 * self.nodes[a]], u[2 * self.nodes[a] + 1]);
            e[0] += g[0] * ux;
            e[1] += g[1] * uy;
            e[2] += 0.5 * (g[1] * ux + g[0] * uy);
        }
        e
    }
    /// Element internal force `|T| B^T sigma` over [`Element::dofs`] (force).
    pub fn internal_force(&self, sigma: &Stress) -> SVector<f64, 6> {
        self.b_matrix().transpose() * sigma * self.area
    }
    /// Element stiffness `|T| B^T D S B` of the tangent `d` (`d sigma / d eps` in tensor
    /// components; S halves B's engineering shear), over [`Element::dofs`] (force/length).
    pub fn stiffness(&self, d: &Matrix3<f64>) -> SMatrix<f64, 6, 6> {
        let s = Matrix3::from_diagonal(&SVector::<f64, 3>::new(1.0, 1.0, 0.5));
        let b = self.b_matrix();
        b.transpose() * (d * s) * b * self.area
    }
    /// Global dof indices of the element (x, y per node).
    pub fn dofs(&self) -> [usize; 6] {
        let n = self.nodes;
        [
            2 * n[0],
            2 * n[0] + 1,
            2 * n[1],
            2 * n[1] + 1,
            2 * n[2],
            2 * n[2] + 1,
        ]
    }
}

/// Area and hat-function gradients of a triangle.
pub fn p1_gradients(p: [[f64; 2]; 3]) -> (f64, [[f64; 2]; 3]) {
    let area = crate::mesh::signed_area(p[0], p[1], p[2]);
    let mut g = [[0.0; 2]; 3];
    for a in 0..3 {
        let (j, k) = ((a + 1) % 3, (a + 2) % 3);
        g[a] = [
            (p[j][1] - p[k][1]) / (2.0 * area),
            (p[k][0] - p[j][0]) / (2.0 * area),
        ];
    }
    (area, g)
}

/// A compressed-sparse-column pattern with sorted rows, and a lookup of entry slots.
#[derive(Debug, Clone)]
pub struct Pattern {
    /// Matrix dimension (square).
    pub n: usize,
    /// Column pointers.
    pub col_ptr: Vec<usize>,
    /// Row indices, sorted within each column.
    pub row_idx: Vec<usize>,
}

impl Pattern {
    /// Build from (row, col) pairs (duplicates allowed).
    pub fn from_entries(n: usize, entries: Vec<(usize, usize)>) -> Self {
        Self::from_pairs(n, || entries.iter().copied())
    }

    /// Build from the (row, col) pairs that `pairs` yields (duplicates allowed; called
    /// twice, so that no list of the pairs is kept). Bucket the rows by column (counting
    /// sort), then sort and deduplicate each short column: linear in the pairs, where one
    /// sort of all (36 per triangle) cost about 1 s at 4e5 dofs.
    pub fn from_pairs<I: Iterator<Item = (usize, usize)>>(n: usize, pairs: impl Fn() -> I) -> Self {
        let mut start = vec![0usize; n + 1];
        for (_, c) in pairs() {
            start[c + 1] += 1;
        }
        for c in 0..n {
            start[c + 1] += start[c];
        }
        let mut next = start.clone();
        let mut rows = vec![0usize; start[n]];
        for (r, c) in pairs() {
            rows[next[c]] = r;
            next[c] += 1;
        }
        let mut col_ptr = vec![0usize; n + 1];
        let mut row_idx = Vec::with_capacity(rows.len());
        for c in 0..n {
            let column = &mut rows[start[c]..start[c + 1]];
            column.sort_unstable();
            let first = row_idx.len();
            for &r in column.iter() {
                if row_idx.len() == first || row_idx.last() != Some(&r) {
                    row_idx.push(r);
                }
            }
            col_ptr[c + 1] = row_idx.len();
        }
        Pattern {
            n,
            col_ptr,
            row_idx,
        }
    }
    /// Slot of entry (row, col); panics if absent (a construction error).
    pub fn slot(&self, row: usize, col: usize) -> usize {
        let s = &self.row_idx[self.col_ptr[col]..self.col_ptr[col + 1]];
        self.col_ptr[col] + s.binary_search(&row).expect("entry in pattern")
    }
    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// The diagonal blocks of a symmetric pattern (both triangles stored): maximal runs of
    /// equations that no entry leaves (a stiffness has one per body: the bodies share no
    /// node). Blocks of fewer than 1% of the equations join a neighbour (each block costs a
    /// task on a thread).
    pub fn diagonal_blocks(&self) -> Vec<std::ops::Range<usize>> {
        let n = self.n;
        let mut blocks: Vec<std::ops::Range<usize>> = Vec::new();
        let (mut start, mut reach) = (0, 0);
        for j in 0..n {
            let column = &self.row_idx[self.col_ptr[j]..self.col_ptr[j + 1]];
            reach = reach.max(column.last().copied().unwrap_or(j)).max(j);
            if reach == j {
                match blocks.last_mut() {
                    Some(last) if (j + 1 - start) * 100 < n => last.end = j + 1,
                    _ => blocks.push(start..j + 1),
                }
                start = j + 1;
            }
        }
        if blocks.len() > 1 && blocks[0].len() * 100 < n {
            let first = blocks.remove(0);
            blocks[0].start = first.start;
        }
        blocks
    }

    /// The diagonal block of the equations `range` (no entry may leave it; see
    /// [`Pattern::diagonal_blocks`]) and the range of its entries in this pattern's values.
    pub fn block(&self, range: &std::ops::Range<usize>) -> (Pattern, std::ops::Range<usize>) {
        let base = self.col_ptr[range.start];
        let entries = base..self.col_ptr[range.end];
        let pattern = Pattern {
            n: range.len(),
            col_ptr: self.col_ptr[range.start..=range.end]
                .iter()
                .map(|&p| p - base)
                .collect(),
            row_idx: self.row_idx[entries.clone()]
                .iter()
                .map(|&r| r - range.start)
                .collect(),
        };
        (pattern, entries)
    }
}

/// The discrete model: both bodies' elements, dof numbering and boundary data.
#[derive(Debug, Clone)]
pub struct Model {
    /// The two body meshes (index 0 = body 1, the slave).
    pub meshes: [BodyMesh; 2],
    /// Materials per body.
    pub materials: [Material; 2],
    /// First global node index of each body.
    pub node_offset: [usize; 2],
    /// Total number of nodes.
    pub n_nodes: usize,
    /// All elements of both bodies.
    pub elements: Vec<Element>,
    /// For each global dof, its equation number, or [`FIXED`].
    pub equation: Vec<usize>,
    /// Number of free dofs (equations).
    pub n_free: usize,
    /// Traction edges: (curve index in scene.tractions, global node pair).
    pub traction_edges: Vec<(usize, [usize; 2])>,
    /// For each traction edge: its body and outward unit normal (what a derived traction
    /// sigma(u) n needs).
    pub traction_normals: Vec<(usize, [f64; 2])>,
    /// The scene it was built from.
    pub scene: Scene,
    /// The mesh file (for messages).
    pub mesh_file: std::path::PathBuf,
    /// The load's compiled expressions, built at the first [`Model::load`]; the model's
    /// mesh and scene must not change after it.
    load_programs: std::sync::OnceLock<std::sync::Arc<load::LoadPrograms>>,
    /// Where set, [`Model::load`] integrates the loads by this plain rule rather than its
    /// own (an outside code's load integration, solved here: `grade`'s tests).
    pub load_rule: Option<LoadRule>,
}

/// The body and outward unit normal of each boundary edge: away from the third vertex of
/// the edge's triangle.
fn outward_normals(
    elements: &[Element],
    edges: &[(usize, [usize; 2])],
    position: impl Fn(usize) -> [f64; 2],
) -> Vec<(usize, [f64; 2])> {
    let key = |a: usize, b: usize| (a.min(b), a.max(b));
    let mut third: std::collections::HashMap<(usize, usize), (usize, usize)> = edges
        .iter()
        .map(|&(_, [a, b])| (key(a, b), (usize::MAX, 0)))
        .collect();
    for el in elements {
        let n = el.nodes;
        for k in 0..3 {
            if let Some(v) = third.get_mut(&key(n[k], n[(k + 1) % 3])) {
                *v = (n[(k + 2) % 3], el.body);
            }
        }
    }
    edges
        .iter()
        .map(|&(_, [a, b])| {
            let (c, body) = third[&key(a, b)];
            let (pa, pb) = (position(a), position(b));
            let d = [pb[0] - pa[0], pb[1] - pa[1]];
            let len = d[0].hypot(d[1]);
            let mut n = [d[1] / len, -d[0] / len];
            if c != usize::MAX {
                let pc = position(c);
                if (pc[0] - pa[0]) * n[0] + (pc[1] - pa[1]) * n[1] > 0.0 {
                    n = [-n[0], -n[1]];
                }
            }
            (body, n)
        })
        .collect()
}

/// The physical curves of the two body meshes, in the model's global node numbering (body
/// b's nodes start at `offsets[b]`); errors name the scene file's field that names a curve.
struct Curves<'a> {
    raw: &'a RawMesh,
    meshes: &'a [BodyMesh; 2],
    offsets: [usize; 2],
    source: &'a MeshSource<'a>,
}

impl Curves<'_> {
    /// The edges of `curve` on either body as (body, global node pair); errs where the mesh
    /// has no such curve or it has no edge, naming the scene's field `field`.
    fn edges(&self, curve: &str, field: &str) -> Result<Vec<(usize, [usize; 2])>> {
        let (raw, meshes, offsets, source) = (self.raw, self.meshes, self.offsets, self.source);
        raw.require_curve(curve, source, field)?;
        let mut out = Vec::new();
        for b in 0..2 {
            for e in meshes[b].curve_edges(raw, curve) {
                out.push((b, [e[0] + offsets[b], e[1] + offsets[b]]));
            }
        }
        if out.is_empty() {
            return Err(source.error(
                field,
                format!(
                    "physical curve '{curve}' of the mesh of {} has no edge on either body ('{}', '{}'); fix: name a curve on a body's boundary in {field}, or check the .geo",
                    source.geo.display(),
                    meshes[0].name,
                    meshes[1].name
                ),
            ));
        }
        Ok(out)
    }

    /// The position of global node `g`.
    fn position(&self, g: usize) -> [f64; 2] {
        if g < self.offsets[1] {
            self.meshes[0].nodes[g]
        } else {
            self.meshes[1].nodes[g - self.offsets[1]]
        }
    }
}

/// The P1 elements of both bodies, body 1's first, with global node numbers.
fn body_elements(meshes: &[BodyMesh; 2], node_offset: [usize; 2]) -> Vec<Element> {
    let mut elements = Vec::new();
    for b in 0..2 {
        for t in &meshes[b].triangles {
            let p = t.map(|i| meshes[b].nodes[i]);
            let (area, grads) = p1_gradients(p);
            elements.push(Element {
                body: b,
                nodes: t.map(|i| i + node_offset[b]),
                area,
                grads,
            });
        }
    }
    elements
}

/// Which of the `2 n_nodes` dofs are held: both components on the clamped curves, the
/// roller's component on each roller curve (which must be straight along the other axis).
fn fixed_dofs(scene: &Scene, curves: &Curves, n_nodes: usize) -> Result<Vec<bool>> {
    let mut fixed = vec![false; 2 * n_nodes];
    for (i, c) in scene.clamps.iter().enumerate() {
        for (_, e) in curves.edges(c, &format!("clamp[{i}].curve"))? {
            for n in e {
                fixed[2 * n] = true;
                fixed[2 * n + 1] = true;
            }
        }
    }
    for (i, r) in scene.rollers.iter().enumerate() {
        let field = format!("roller[{i}].curve");
        for (_, e) in curves.edges(&r.curve, &field)? {
            let (a, b) = (curves.position(e[0]), curves.position(e[1]));
            let d = [b[0] - a[0], b[1] - a[1]];
            let len = d[0].hypot(d[1]);
            // A roller holding u_x lies on a vertical edge, one holding u_y on a horizontal one.
            if d[r.component].abs() > 1e-9 * len {
                return Err(Error::input(
                    &scene.file,
                    field,
                    format!(
                        "a roller holding u_{} needs a {} curve, but an edge of '{}' runs from {a:?} to {b:?}; use a clamp or fix the geometry",
                        ["x", "y"][r.component],
                        ["vertical", "horizontal"][r.component],
                        r.curve
                    ),
                ));
            }
            for n in e {
                fixed[2 * n + r.component] = true;
            }
        }
    }
    Ok(fixed)
}

/// The equation number of each dof ([`FIXED`] where `fixed`), in dof order, and the number
/// of equations.
fn number_equations(fixed: &[bool]) -> (Vec<usize>, usize) {
    let mut equation = vec![FIXED; fixed.len()];
    let mut n_free = 0;
    for (d, f) in fixed.iter().enumerate() {
        if !f {
            equation[d] = n_free;
            n_free += 1;
        }
    }
    (equation, n_free)
}

impl Model {
    /// Build the model of `scene` on the mesh `raw` read from `mesh_file`. Errors about the
    /// mesh's physical groups name the scene file and its field.
    pub fn new(scene: &Scene, raw: &RawMesh, mesh_file: &Path) -> Result<Self> {
        let source = MeshSource {
            scene: &scene.file,
            geo: &scene.geo,
        };
        let body_mesh = |b: usize| {
            let body = &scene.bodies[b];
            let field = format!("bodies[{}].surface", body.file_index);
            BodyMesh::from_raw(raw, &body.surface, &source, &field)
        };
        let meshes = [body_mesh(0)?, body_mesh(1)?];
        let node_offset = [0, meshes[0].nodes.len()];
        let n_nodes = node_offset[1] + meshes[1].nodes.len();
        let elements = body_elements(&meshes, node_offset);
        let curves = Curves {
            raw,
            meshes: &meshes,
            offsets: node_offset,
            source: &source,
        };
        let fixed = fixed_dofs(scene, &curves, n_nodes)?;
        let (equation, n_free) = number_equations(&fixed);
        let mut traction_edges = Vec::new();
        for (i, t) in scene.tractions.iter().enumerate() {
            for (_, e) in curves.edges(&t.curve, &format!("traction[{i}].curve"))? {
                traction_edges.push((i, e));
            }
        }
        // Only derived tractions need the normals.
        let traction_normals = if scene.tractions.iter().any(|t| t.g.is_none()) {
            outward_normals(&elements, &traction_edges, |g| curves.position(g))
        } else {
            Vec::new()
        };
        Ok(Model {
            materials: [scene.bodies[0].material, scene.bodies[1].material],
            meshes,
            node_offset,
            n_nodes,
            elements,
            equation,
            n_free,
            traction_normals,
            traction_edges,
            scene: scene.clone(),
            mesh_file: mesh_file.to_path_buf(),
            load_programs: Default::default(),
            load_rule: None,
        })
    }

    /// Coordinates of global node `g`.
    pub fn position(&self, g: usize) -> [f64; 2] {
        if g < self.node_offset[1] {
            self.meshes[0].nodes[g]
        } else {
            self.meshes[1].nodes[g - self.node_offset[1]]
        }
    }

    /// Largest element diameter over both bodies (length).
    pub fn h(&self) -> f64 {
        self.meshes[0].h().max(self.meshes[1].h())
    }

    /// The effective mesh size (|Omega| / number of triangles)^(1/2) over both bodies
    /// (length): the size of a uniform mesh with as many triangles. Under splitting it
    /// halves exactly, as the largest diameter does; on meshes graded toward a point it
    /// follows the triangle count where the largest diameter (far from the point) does not.
    pub fn effective_h(&self) -> f64 {
        let (area, triangles) = self.meshes.iter().fold((0.0, 0usize), |(a, n), m| {
            let body: f64 = (0..m.triangles.len()).map(|t| m.area(t).abs()).sum();
            (a + body, n + m.triangles.len())
        });
        (area / triangles as f64).sqrt()
    }

    /// The h the judge reads: the largest element diameter ([`Model::h`]) on nested
    /// (split) levels, the effective size ([`Model::effective_h`]) on levels meshed anew
    /// (`refinement = "remesh"`), whose largest element need not shrink with the rest, and
    /// on levels split on their curves (`"curved"`), nested but for their boundary nodes.
    pub fn judge_h(&self) -> f64 {
        match self.scene.refinement.judged_by_max_diameter() {
            true => self.h(),
            false => self.effective_h(),
        }
    }

    /// Pattern of the stiffness matrix over free dofs, and for every element its 36
    /// slots (row-major over the element dofs; `FIXED` where a dof is constrained).
    pub fn stiffness_pattern(
        &self,
        extra: &[(usize, usize)],
        n_total: usize,
    ) -> (Pattern, Vec<[usize; 36]>) {
        match extra.is_empty() && n_total == self.n_free {
            true => self.stiffness_pattern_by_nodes(),
            false => self.stiffness_pattern_by_entries(extra, n_total),
        }
    }

    /// [`Model::stiffness_pattern`] from the list of every entry (36 per triangle, and
    /// `extra`): the general builder, and the reference the nodes' builder is tested
    /// against.
    pub fn stiffness_pattern_by_entries(
        &self,
        extra: &[(usize, usize)],
        n_total: usize,
    ) -> (Pattern, Vec<[usize; 36]>) {
        let mut entries = Vec::with_capacity(self.elements.len() * 36 + extra.len());
        for e in &self.elements {
            let eq = e.dofs().map(|d| self.equation[d]);
            for &r in &eq {
                for &c in &eq {
                    if r != FIXED && c != FIXED {
                        entries.push((r, c));
                    }
                }
            }
        }
        entries.extend_from_slice(extra);
        let pattern = Pattern::from_entries(n_total, entries);
        let slots = self
            .elements
            .iter()
            .map(|e| {
                let eq = e.dofs().map(|d| self.equation[d]);
                let mut s = [FIXED; 36];
                for i in 0..6 {
                    for j in 0..6 {
                        if eq[i] != FIXED && eq[j] != FIXED {
                            s[6 * i + j] = pattern.slot(eq[i], eq[j]);
                        }
                    }
                }
                s
            })
            .collect();
        (pattern, slots)
    }

    /// [`Model::stiffness_pattern`] of the stiffness alone (no extra entries), built from
    /// the nodes' neighbours: the same pattern and slots. Why: the entry list of the
    /// general builder is 36 (row, column) pairs per triangle (20 MB at 34,432 dofs, 5,000
    /// fresh pages), where a node's neighbours are a few indices, and every column of a
    /// node's two equations holds the same rows: the free equations of its neighbours,
    /// increasing (equations are numbered in dof order).
    fn stiffness_pattern_by_nodes(&self) -> (Pattern, Vec<[usize; 36]>) {
        let n_nodes = self.n_nodes;
        // Each triangle's three nodes are neighbours of each of its nodes (itself
        // included): the nodes' graph as a pattern, node j's neighbours in column j.
        let graph = Pattern::from_pairs(n_nodes, || {
            self.elements.iter().flat_map(|e| {
                let nodes = e.nodes;
                (0..9).map(move |k| (nodes[k / 3], nodes[k % 3]))
            })
        });
        let (node_ptr, neighbours) = (graph.col_ptr, graph.row_idx);
        let free = |dof: usize| self.equation[dof] != FIXED;
        // The free equations must be numbered in dof order (Model::new does): the rows of a
        // column are then increasing and the columns follow the nodes.
        debug_assert!(
            (self.equation.iter().copied().filter(|&eq| eq != FIXED)).eq(0..self.n_free),
            "free equations numbered in dof order"
        );
        // Per node, its rows (the free equations of its neighbours) and, per neighbour, the
        // rows before it (`before[k]` for neighbours[k]).
        let mut before = vec![0usize; neighbours.len()];
        let mut col_ptr = vec![0usize; self.n_free + 1];
        let mut row_idx = Vec::new();
        for j in 0..n_nodes {
            let rows_start = row_idx.len();
            for k in node_ptr[j]..node_ptr[j + 1] {
                let i = neighbours[k];
                before[k] = row_idx.len() - rows_start;
                for d in [2 * i, 2 * i + 1] {
                    if free(d) {
                        row_idx.push(self.equation[d]);
                    }
                }
            }
            // One column per free dof of j, each with these rows (the second a copy).
            let rows = rows_start..row_idx.len();
            let columns = [2 * j, 2 * j + 1].map(|d| self.equation[d]);
            match columns.iter().filter(|&&c| c != FIXED).count() {
                0 => row_idx.truncate(rows_start),
                2 => row_idx.extend_from_within(rows.clone()),
                _ => {}
            }
            for c in columns.into_iter().filter(|&c| c != FIXED) {
                col_ptr[c + 1] = rows.len();
            }
        }
        for c in 0..self.n_free {
            col_ptr[c + 1] += col_ptr[c];
        }
        let pattern = Pattern {
            n: self.n_free,
            col_ptr,
            row_idx,
        };
        // Slot of (row dof d_row of node i, column equation c of node j): the column's
        // start, the rows of j's neighbours before i, and the x row of i if d_row is its y.
        let slots = self
            .elements
            .iter()
            .map(|e| {
                let eq = e.dofs().map(|d| self.equation[d]);
                let mut s = [FIXED; 36];
                for b in 0..3 {
                    let j = e.nodes[b];
                    let list = &neighbours[node_ptr[j]..node_ptr[j + 1]];
                    for a in 0..3 {
                        let i = e.nodes[a];
                        let k =
                            node_ptr[j] + list.iter().position(|&x| x == i).expect("a neighbour");
                        for q in 0..2 {
                            let c = eq[2 * b + q];
                            if c == FIXED {
                                continue;
                            }
                            let column = pattern.col_ptr[c] + before[k];
                            for p in 0..2 {
                                if eq[2 * a + p] != FIXED {
                                    let x_row = (p == 1 && free(2 * i)) as usize;
                                    s[6 * (2 * a + p) + 2 * b + q] = column + x_row;
                                }
                            }
                        }
                    }
                }
                s
            })
            .collect();
        (pattern, slots)
    }

    /// The constitutive source of a manufactured solution at time `t`, per element: the
    /// mean over the triangle of s = d sigma/dt - E eps(du/dt) - G(sigma) (stress per time;
    /// its L2 projection onto the P0 stresses), by the 2 x 2 collapsed Gauss rule split along
    /// the exact fields' kinks ([`quadrature::triangle_rule`]). None when the scene's law
    /// needs no source: such a scene pays nothing.
    pub fn constitutive_source(&self, t: f64) -> Result<Option<Vec<Stress>>> {
        let Some(exact) = self.scene.exact.as_deref() else {
            return Ok(None);
        };
        if exact.source_rate.is_none() {
            return Ok(None);
        }
        // Degree 2, not the loads' degree 8: measured on levels 0-4 of contact-mms-vp, every
        // theorem error moved by <= 1.4e-4 relative (1.2e-6 at level 4) and no slope by more
        // than 1e-4 against Dunavant-8, at a quarter of the cost; G(sigma)'s own kink (the
        // yield surface) is not split by either rule.
        let rule = quadrature::triangle(2);
        let kinks = [0, 1].map(|b| kink_functions(&exact.kinks(b), t));
        let mut out = Vec::with_capacity(self.elements.len());
        for e in &self.elements {
            let (b, p) = (e.body, e.nodes.map(|n| self.position(n)));
            let mut mean = Stress::zeros();
            for &(l1, l2, w) in quadrature::triangle_rule(p, &kinks[b], &rule).iter() {
                let lam = [1.0 - l1 - l2, l1, l2];
                let x = lam[0] * p[0][0] + lam[1] * p[1][0] + lam[2] * p[2][0];
                let y = lam[0] * p[0][1] + lam[1] * p[1][1] + lam[2] * p[2][1];
                let s = exact
                    .source_at(b, &self.materials[b], x, y, t)
                    .expect("a scene with a source rate has a stress");
                if s.iter().any(|v| !v.is_finite()) {
                    return Err(Error::input(
                        &self.scene.file,
                        "exact",
                        format!(
                            "the constitutive source derived from exact.stress and exact.displacement of body '{}' is not finite at x = {x}, y = {y}, t = {t}; fix the fields",
                            self.scene.bodies[b].surface
                        ),
                    ));
                }
                // The rule's weights sum to 1 over the triangle: a mean, not an integral.
                mean += w * Stress::from(s);
            }
            out.push(mean);
        }
        Ok(Some(out))
    }

    /// Restrict a global-dof vector to the free equations.
    pub fn restrict(&self, v: &[f64]) -> Vec<f64> {
        let mut r = vec![0.0; self.n_free];
        for (d, &eq) in self.equation.iter().enumerate() {
            if eq != FIXED {
                r[eq] = v[d];
            }
        }
        r
    }

    /// Expand free-equation values to global dofs (constrained dofs are zero).
    pub fn expand(&self, v: &[f64]) -> Vec<f64> {
        self.equation
            .iter()
            .map(|&eq| if eq == FIXED { 0.0 } else { v[eq] })
            .collect()
    }

    /// The strain of `u` (global dofs) in every element, tensor components: the
    /// `strain_prev` of [`Model::update_stresses`], computed once per time step.
    pub fn strains(&self, u: &[f64]) -> Vec<Strain> {
        match self.elements.len() >= PARALLEL_ELEMENTS {
            true => self
                .elements
                .par_iter()
                .with_min_len(4096)
                .map(|e| e.strain(u))
                .collect(),
            false => self.elements.iter().map(|e| e.strain(u)).collect(),
        }
    }

    /// Constitutive update of every element: `sigma = sigma_prev + E (eps(u) - eps(u_prev))
    /// + k G(sigma) + k s` with `s` the element's constitutive source at t_n, if any
    /// ([`Model::constitutive_source`]; it only shifts the trial stress), and
    /// `strain_prev` the elements' eps(u_prev) ([`Model::strains`]: the same per iteration
    /// of a step, so gathered once). Returns the stresses and, if `tangent`, the
    /// consistent tangents.
    pub fn update_stresses(
        &self,
        u: &[f64],
        strain_prev: &[Strain],
        sigma_prev: &[Stress],
        k: f64,
        source: Option<&[Stress]>,
        tangent: bool,
    ) -> (Vec<Stress>, Vec<Matrix3<f64>>) {
        let n = self.elements.len();
        let mut sigma: Vec<Stress> = Vec::with_capacity(n);
        // Without `tangent` no tangent is stored (at 2.2e6 triangles they are 150 MB of
        // fresh pages per update).
        let mut tangents: Vec<Matrix3<f64>> = Vec::with_capacity(if tangent { n } else { 0 });
        let blocks = n.div_ceil(UPDATE_BLOCK);
        let tangent_blocks: Vec<Option<&mut [MaybeUninit<Matrix3<f64>>]>> = match tangent {
            true => (tangents.spare_capacity_mut()[..n].chunks_mut(UPDATE_BLOCK))
                .map(Some)
                .collect(),
            false => (0..blocks).map(|_| None).collect(),
        };
        let jobs: Vec<_> = (sigma.spare_capacity_mut()[..n].chunks_mut(UPDATE_BLOCK))
            .zip(tangent_blocks)
            .enumerate()
            .collect();
        let update = |(b, (sigma, tangents))| {
            let first = b * UPDATE_BLOCK;
            self.update_block(
                first,
                sigma,
                tangents,
                u,
                strain_prev,
                sigma_prev,
                k,
                source,
            );
        };
        // On rayon's threads from PARALLEL_ELEMENTS triangles on (each triangle alone: the
        // same numbers on any number of threads); below, serial.
        match n >= PARALLEL_ELEMENTS {
            true => jobs.into_par_iter().for_each(update),
            false => jobs.into_iter().for_each(update),
        }
        // SAFETY: update_block wrote every slot of every block (and the blocks cover
        // 0..n), the tangents' only where `tangent`.
        unsafe {
            sigma.set_len(n);
            if tangent {
                tangents.set_len(n);
            }
        }
        (sigma, tangents)
    }

    /// [`Model::update_stresses`] of the triangles `first..first + sigma.len()` into
    /// `sigma` and, if given, `tangents` (every slot written), [`LANES`] at a time
    /// ([`Material::update_lanes`]). Written in place: the unzip of per-triangle pairs
    /// it replaces cost 0.30 ms per update of `rates-elastic` at 34,304 triangles, this
    /// 0.18 ms.
    #[allow(clippy::too_many_arguments)]
    fn update_block(
        &self,
        first: usize,
        sigma: &mut [MaybeUninit<Stress>],
        mut tangents: Option<&mut [MaybeUninit<Matrix3<f64>>]>,
        u: &[f64],
        strain_prev: &[Strain],
        sigma_prev: &[Stress],
        k: f64,
        source: Option<&[Stress]>,
    ) {
        for start in (0..sigma.len()).step_by(LANES) {
            let lanes = LANES.min(sigma.len() - start);
            let mut materials = [&self.materials[0]; LANES];
            let mut trials = [Stress::zeros(); LANES];
            for l in 0..lanes {
                let i = first + start + l;
                (materials[l], trials[l]) =
                    self.trial_stress(i, u, strain_prev, sigma_prev, k, source);
            }
            let mut written = 0;
            Material::update_lanes(&materials[..lanes], &trials[..lanes], k, |l, s, d| {
                sigma[start + l].write(s);
                if let Some(t) = tangents.as_deref_mut() {
                    t[start + l].write(d);
                }
                written += 1;
            });
            // The set_len of update_stresses needs every slot written.
            assert_eq!(written, lanes, "update_lanes wrote every triangle once");
        }
    }

    /// The material and the trial stress `sigma_prev + E (eps(u) - eps(u_prev)) + k s` of
    /// element `i` (see [`Model::update_stresses`]); its constitutive update alone is
    /// [`Material::update`] of them.
    pub fn trial_stress(
        &self,
        i: usize,
        u: &[f64],
        strain_prev: &[Strain],
        sigma_prev: &[Stress],
        k: f64,
        source: Option<&[Stress]>,
    ) -> (&Material, Stress) {
        let e = &self.elements[i];
        let m = &self.materials[e.body];
        let de = e.strain(u) - strain_prev[i];
        let mut trial = sigma_prev[i] + m.elastic.apply(&de);
        if let Some(source) = source {
            trial += k * source[i];
        }
        (m, trial)
    }

    /// Internal force `sum_T |T| B^T sigma_T` over global dofs. From
    /// [`PARALLEL_ELEMENTS`] triangles on, the two bodies (disjoint dofs) on two threads,
    /// each summing in element order: the same numbers as one thread.
    pub fn internal_force(&self, sigma: &[Stress]) -> Vec<f64> {
        let mut f = vec![0.0; 2 * self.n_nodes];
        let add = |body: usize, f: &mut [f64], dof_offset: usize| {
            let range = self.body_elements(body);
            for (e, s) in self.elements[range.clone()].iter().zip(&sigma[range]) {
                let fe = e.internal_force(s);
                for (k, d) in e.dofs().iter().enumerate() {
                    f[*d - dof_offset] += fe[k];
                }
            }
        };
        if self.elements.len() >= PARALLEL_ELEMENTS {
            let split = 2 * self.node_offset[1];
            let (f0, f1) = f.split_at_mut(split);
            rayon::join(|| add(0, f0, 0), || add(1, f1, split));
        } else {
            add(0, &mut f, 0);
            add(1, &mut f, 0);
        }
        f
    }

    /// Add the element tangents `|T| B^T D S B` (S halves the engineering shear) into
    /// `values` using the slot map.
    pub fn add_tangent(
        &self,
        tangents: &[Matrix3<f64>],
        slots: &[[usize; 36]],
        values: &mut [f64],
    ) {
        for ((e, d), sl) in self.elements.iter().zip(tangents).zip(slots) {
            scatter_tangent(e, d, sl, 0, values);
        }
    }

    /// Add `|T| B^T (D - E) S B` for the elements whose tangent D differs from the elastic
    /// E of their body (the viscoplastic ones): on top of the assembled elastic stiffness,
    /// this assembles the consistent tangent while elastic triangles cost nothing.
    /// `split`: [`Model::body_slot_split`] of `slots`, computed once by the caller.
    pub fn add_tangent_change(
        &self,
        tangents: &[Matrix3<f64>],
        slots: &[[usize; 36]],
        split: Option<usize>,
        values: &mut [f64],
    ) {
        // A body with no viscoplastic part is skipped whole. From PARALLEL_ELEMENTS
        // triangles on, the two bodies on two threads when their slots are apart (the
        // stiffness is block diagonal: body 1's values follow body 0's), each in element
        // order: every slot gets the same sums in the same order as on one thread.
        let flows = |body: usize| self.materials[body].viscoplastic.is_some();
        let add = |body: usize, values: &mut [f64], offset: usize| {
            if !flows(body) {
                return;
            }
            let elastic = self.materials[body].elastic.matrix();
            for ((e, d), sl) in self.elements.iter().zip(tangents).zip(slots) {
                if e.body == body && *d != elastic {
                    scatter_tangent(e, &(d - elastic), sl, offset, values);
                }
            }
        };
        let split =
            split.filter(|_| self.elements.len() >= PARALLEL_ELEMENTS && flows(0) && flows(1));
        match split {
            Some(split) => {
                let (first, second) = values.split_at_mut(split);
                rayon::join(|| add(0, first, 0), || add(1, second, split));
            }
            None => {
                add(0, values, 0);
                add(1, values, 0);
            }
        }
    }

    /// The viscoplastic triangles' share of the consistent tangent stiffness whose
    /// per-triangle tangents are `tangents` ([`TangentChange`]): the triangles whose
    /// tangent is not their body's elastic one, with `|T| (D - E)`. A body with no
    /// viscoplastic part is skipped whole; from [`PARALLEL_ELEMENTS`] triangles on, the
    /// bodies on two threads.
    pub fn tangent_change(&self, tangents: &[Matrix3<f64>]) -> TangentChange {
        let collect = |body: usize| -> Vec<ChangedTriangle> {
            if self.materials[body].viscoplastic.is_none() {
                return Vec::new();
            }
            let elastic = self.materials[body].elastic.matrix();
            let range = self.body_elements(body);
            self.elements[range.clone()]
                .iter()
                .zip(&tangents[range])
                .filter(|(_, d)| **d != elastic)
                .map(|(e, d)| ChangedTriangle {
                    equations: e.dofs().map(|dof| self.equation[dof]),
                    grads: e.grads,
                    change: (d - elastic) * e.area,
                })
                .collect()
        };
        let bodies = match self.elements.len() >= PARALLEL_ELEMENTS {
            true => {
                let (first, second) = rayon::join(|| collect(0), || collect(1));
                [first, second]
            }
            false => [collect(0), collect(1)],
        };
        // Equations are numbered in dof order, body 0 first: body 1's first free equation.
        let split = self.equation[2 * self.node_offset[1]..]
            .iter()
            .find(|&&eq| eq != FIXED)
            .copied()
            .unwrap_or(self.n_free);
        TangentChange { bodies, split }
    }

    /// The first value slot of body 1 when every slot of body 0's triangles is below it
    /// and every slot of body 1's at or above it (the stiffness's values split between
    /// the bodies), else None.
    pub fn body_slot_split(&self, slots: &[[usize; 36]]) -> Option<usize> {
        let (mut below, mut above) = (0usize, usize::MAX);
        for (e, sl) in self.elements.iter().zip(slots) {
            let used = sl.iter().filter(|&&s| s != FIXED);
            match e.body {
                0 => below = below.max(used.max().map_or(0, |&s| s + 1)),
                _ => above = above.min(used.min().copied().unwrap_or(usize::MAX)),
            }
        }
        (below <= above && above != usize::MAX).then_some(below)
    }

    /// The elements of `body` (0 or 1): body 0's come first ([`Model::new`]), so each
    /// body's loops read their own triangles only.
    pub fn body_elements(&self, body: usize) -> std::ops::Range<usize> {
        let first_of_1 = self.elements.partition_point(|e| e.body == 0);
        debug_assert!(self.elements[first_of_1..].iter().all(|e| e.body == 1));
        match body {
            0 => 0..first_of_1,
            _ => first_of_1..self.elements.len(),
        }
    }

    /// The elastic stress C eps(u) of every element (the displacement `u` over global dofs):
    /// an elastic body's stress, and the energy product's other factor for any body.
    pub fn elastic_stresses(&self, u: &[f64]) -> Vec<Stress> {
        self.elements
            .iter()
            .map(|e| self.materials[e.body].elastic.apply(&e.strain(u)))
            .collect()
    }

    /// Elastic tangents of all elements (E of each body).
    pub fn elastic_tangents(&self) -> Vec<Matrix3<f64>> {
        self.elements
            .iter()
            .map(|e| self.materials[e.body].elastic.matrix())
            .collect()
    }
}

/// `values` cut into the disjoint, increasing `ranges` (mutable slices, in order): the
/// diagonal blocks' parts of a vector or of a pattern's values, for one thread each.
pub fn split_ranges_mut<'a>(
    values: &'a mut [f64],
    ranges: impl IntoIterator<Item = std::ops::Range<usize>>,
) -> Vec<&'a mut [f64]> {
    let (mut rest, mut taken, mut parts) = (values, 0, Vec::new());
    for r in ranges {
        let (head, tail) = rest.split_at_mut(r.end - taken);
        parts.push(&mut head[r.start - taken..]);
        taken = r.end;
        rest = tail;
    }
    parts
}

/// The viscoplastic triangles' share `K_t - K_el` of a consistent tangent stiffness over
/// the free equations, kept per triangle and applied as a product: `|T| B^T (D - E) S B x`
/// summed over the triangles whose tangent D is not their body's elastic E (S halves B's
/// engineering shear). Newton's products `K_t x = K_el x + (K_t - K_el) x` then need no
/// assembled K_t: a product over the changed triangles costs less than a copy of the
/// stiffness's values and a scatter of their 6 x 6 matrices per iteration (see
/// [`Model::tangent_change`]).
#[derive(Debug, Clone, Default)]
pub struct TangentChange {
    /// Per body, its changed triangles in element order.
    bodies: [Vec<ChangedTriangle>; 2],
    /// The first equation of body 1 (every equation of body 0 lies below it).
    split: usize,
}

/// One triangle of a [`TangentChange`].
#[derive(Debug, Clone)]
struct ChangedTriangle {
    /// Equations of the triangle's 6 dofs ([`FIXED`] where constrained).
    equations: [usize; 6],
    /// Shape-function gradients (1/length).
    grads: [[f64; 2]; 3],
    /// `|T| (D - E)`: the tangent's change times the area (force).
    change: Matrix3<f64>,
}

impl TangentChange {
    /// Whether no triangle's tangent differs from the elastic one.
    pub fn is_empty(&self) -> bool {
        self.bodies.iter().all(Vec::is_empty)
    }

    /// `y += (K_t - K_el) x` over the free equations. From [`PARALLEL_ELEMENTS`] changed
    /// triangles on, the two bodies (disjoint equations) on two threads, each in element
    /// order: the same sums as on one thread.
    pub fn add_product(&self, x: &[f64], y: &mut [f64]) {
        let add = |triangles: &[ChangedTriangle], y: &mut [f64], offset: usize| {
            let at = |eq: usize| if eq == FIXED { 0.0 } else { x[eq] };
            for t in triangles {
                let (eq, g) = (&t.equations, &t.grads);
                // Tensor strain S B x, the stress change, and B^T of it (as Element::strain
                // and Element::internal_force).
                let mut strain = Vector3::zeros();
                for a in 0..3 {
                    let (ux, uy) = (at(eq[2 * a]), at(eq[2 * a + 1]));
                    strain[0] += g[a][0] * ux;
                    strain[1] += g[a][1] * uy;
                    strain[2] += 0.5 * (g[a][1] * ux + g[a][0] * uy);
                }
                let s = t.change * strain;
                for a in 0..3 {
                    if eq[2 * a] != FIXED {
                        y[eq[2 * a] - offset] += g[a][0] * s[0] + g[a][1] * s[2];
                    }
                    if eq[2 * a + 1] != FIXED {
                        y[eq[2 * a + 1] - offset] += g[a][1] * s[1] + g[a][0] * s[2];
                    }
                }
            }
        };
        let [first, second] = &self.bodies;
        if first.len() + second.len() >= PARALLEL_ELEMENTS {
            let (y0, y1) = y.split_at_mut(self.split);
            rayon::join(|| add(first, y0, 0), || add(second, y1, self.split));
        } else {
            add(first, y, 0);
            add(second, y, 0);
        }
    }
}

/// Triangles from which the constitutive update and the internal force run on rayon's
/// threads. Measured at level 4 of `study speed` (about 17,000 triangles, 34,432 dofs, 4
/// steps, fastest of 6 runs), serial against 2 threads: the constitutive updates of
/// `rates` 0.032 s against 0.021-0.024 s, of `rates-elastic` 0.0046 s against 0.0032-0.0036 s.
pub const PARALLEL_ELEMENTS: usize = 8_000;

/// Triangles per task of [`Model::update_stresses`] on rayon's threads. 4096 left the
/// 34,304 triangles of `study speed`'s level 4 (34,432 dofs) in 9 tasks for 2 threads, the
/// plastic ones (dearer) unevenly; 1024 makes 34. Measured (`speed_pieces 4 mortar rates
/// 20`, fastest of 20, three runs alternating with the old binary): the 14 constitutive
/// updates of a run 18.0 / 18.6 / 18.0 ms -> 17.1 / 17.7 / 16.8 ms. Same bits (each
/// triangle alone).
const UPDATE_BLOCK: usize = 1024;

/// Add `|T| B^T D S B` of one element into `values` through its slot map (S halves the
/// engineering shear).
fn scatter_tangent(
    e: &Element,
    d: &Matrix3<f64>,
    slots: &[usize; 36],
    offset: usize,
    values: &mut [f64],
) {
    let ke = e.stiffness(d);
    for i in 0..6 {
        for j in 0..6 {
            let slot = slots[6 * i + j];
            if slot != FIXED {
                values[slot - offset] += ke[(i, j)];
            }
        }
    }
}
