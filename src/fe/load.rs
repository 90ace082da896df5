//! The external load: tractions on their edges, body forces on the triangles. The scene's
//! expressions are compiled ([`crate::expr::Program`]: the components of a field share
//! their subexpressions), the triangles are integrated on every core, and a load that is
//! t^k times a field of (x, y) (read from the expressions, [`Program::time_degree`]) is
//! integrated once per mesh and scaled at each step: the manufactured scenes' loads are
//! written that way, and a solve's steps, its supports' check, both cones of a level and
//! `grade`'s checks then share one integral.

use super::{Element, Model};
use crate::error::{Error, Result};
use crate::expr::{Expr, Program, compile, distinct_kinks, kink_functions};
use crate::quadrature;
use rayon::prelude::*;
use std::hash::{Hash, Hasher};
use std::sync::{Arc, Mutex};

/// Loads integrated at t = 1, by fingerprint ([`LoadPrograms::fingerprint`]): the last few
/// meshes' (a study alternates the cones of one level; a level's vector is 16 bytes a node).
static FIELDS: Mutex<Vec<(u64, Arc<Vec<f64>>)>> = Mutex::new(Vec::new());
const FIELDS_KEPT: usize = 4;

/// The load's expressions of a model, compiled (once per model: [`Model::load`] keeps them).
#[derive(Debug)]
pub(crate) struct LoadPrograms {
    /// Per traction curve with a given g: its two components.
    given: Vec<Option<Program>>,
    /// Per body, for the tractions derived from the exact stress: s11, s22, s12.
    stress: [Option<Program>; 2],
    /// Per body with a body force: its program and what the singular rules need.
    body: [Option<BodyForce>; 2],
    /// [`LoadPrograms::fingerprint`] of the model they were compiled for.
    fingerprint: u64,
}

#[derive(Debug)]
struct BodyForce {
    /// The two components.
    whole: Program,
    /// The two components, then the singular part's two (a manufactured scene with a
    /// singular point).
    with_singular: Option<Program>,
    /// Its expressions (for the kinks and messages).
    exprs: Vec<Expr>,
    /// Derived from the exact fields (the error then says so).
    derived: bool,
}

impl LoadPrograms {
    fn new(model: &Model) -> Self {
        let scene = &model.scene;
        let exact = scene.exact.as_deref();
        let compiled = |exprs: &[&Expr]| {
            compile(exprs).expect("every scene expression compiles (test_compiled_expressions)")
        };
        let given = scene
            .tractions
            .iter()
            .map(|tr| tr.g.as_ref().map(|g| compiled(&[&g.0[0], &g.0[1]])))
            .collect();
        let stress = [0, 1].map(|b| {
            exact
                .and_then(|e| e.stress.as_ref())
                .filter(|_| scene.tractions.iter().any(|t| t.g.is_none()))
                .map(|s| compiled(&[&s[b][0], &s[b][1], &s[b][2]]))
        });
        let derived = exact.is_some_and(|e| e.body_force.is_some());
        let body = [0, 1].map(|b| {
            let bf = scene.bodies[b].body_force.as_ref()?;
            let exprs: Vec<Expr> = bf.0.to_vec();
            let with_singular = exact
                .and_then(|e| e.singular.as_ref())
                .filter(|_| derived)
                .map(|s| {
                    let fs = &s.body_force[b];
                    compiled(&[&bf.0[0], &bf.0[1], &fs[0], &fs[1]])
                });
            Some(BodyForce {
                whole: compiled(&[&bf.0[0], &bf.0[1]]),
                with_singular,
                exprs,
                derived,
            })
        });
        let mut programs = LoadPrograms {
            given,
            stress,
            body,
            fingerprint: 0,
        };
        programs.fingerprint = programs.fingerprint(model);
        programs
    }

    /// The k with the whole load t^k times a field of (x, y) for t > 0, if there is one.
    fn time_degree(&self) -> Option<f64> {
        let programs = self
            .given
            .iter()
            .flatten()
            .chain(self.stress.iter().flatten())
            .chain(
                self.body
                    .iter()
                    .flatten()
                    .flat_map(|b| std::iter::once(&b.whole).chain(&b.with_singular)),
            );
        let mut common: Option<f64> = None;
        for p in programs {
            match p.time_degree()? {
                None => {}
                Some(k) if common.is_none_or(|c| c == k) => common = Some(k),
                Some(_) => return None,
            }
        }
        Some(common.unwrap_or(0.0))
    }

    /// What the load's integral depends on: the mesh (positions, triangles, traction edges
    /// and normals), the compiled expressions and the singular point.
    fn fingerprint(&self, model: &Model) -> u64 {
        let mut h = std::collections::hash_map::DefaultHasher::new();
        for b in 0..2 {
            for p in &model.meshes[b].nodes {
                p.map(f64::to_bits).hash(&mut h);
            }
        }
        for e in &model.elements {
            (e.body, e.nodes).hash(&mut h);
        }
        model.traction_edges.hash(&mut h);
        for (b, n) in &model.traction_normals {
            (b, n.map(f64::to_bits)).hash(&mut h);
        }
        self.given.hash(&mut h);
        self.stress.hash(&mut h);
        for bf in self.body.iter().flatten() {
            (&bf.whole, &bf.with_singular, bf.derived).hash(&mut h);
        }
        if let Some(s) = model.scene.exact.as_ref().and_then(|e| e.singular.as_ref()) {
            (s.point.map(f64::to_bits), s.exponent.to_bits()).hash(&mut h);
            // The rules at the point: a load integrated more finely is another load.
            crate::quadrature::singular::accuracy().hash(&mut h);
        }
        h.finish()
    }
}

/// A plain quadrature of the load, as another code may integrate it: one rule on every
/// triangle and one on every traction edge, neither split at the load's kinks nor graded
/// toward a singular point ([`Model::load_by_rule`]).
#[derive(Debug, Clone, PartialEq)]
pub struct LoadRule {
    /// Its name in messages ("centroid", ...).
    pub name: &'static str,
    /// The triangles' rule as [`quadrature::triangle`]'s (l1, l2, weight), weights summing to 1.
    pub triangle: Vec<(f64, f64, f64)>,
    /// The edges' rule on [0, 1] as (s, weight), weights summing to 1.
    pub segment: Vec<(f64, f64)>,
}

impl LoadRule {
    /// The plain rules of P1 codes, lowest first: the centroid (degree 1, one point; an
    /// edge's midpoint), three interior points (degree 2, Strang and Fix; 2 Gauss points),
    /// the collapsed 3 x 3 Gauss rule (degree 4; 3 Gauss points) and Dunavant's degree-8 rule
    /// (8 Gauss points: the load's own rule without its split at the kinks). All points are
    /// interior, so a load singular at a vertex is finite at each.
    pub fn common() -> Vec<LoadRule> {
        let third = 1.0 / 3.0;
        let (a, b) = (1.0 / 6.0, 2.0 / 3.0);
        vec![
            LoadRule {
                name: "centroid (degree 1)",
                triangle: vec![(third, third, 1.0)],
                segment: quadrature::gauss_legendre(1),
            },
            LoadRule {
                name: "3 interior points (degree 2)",
                triangle: vec![(a, a, third), (b, a, third), (a, b, third)],
                segment: quadrature::gauss_legendre(2),
            },
            LoadRule {
                name: "3 x 3 collapsed Gauss (degree 4)",
                triangle: quadrature::triangle(3),
                segment: quadrature::gauss_legendre(3),
            },
            LoadRule {
                name: "Dunavant 16 points (degree 8)",
                triangle: quadrature::dunavant8(),
                segment: quadrature::gauss_legendre(8),
            },
        ]
    }
}

/// Forget every load integrated so far (the speed study times a fresh process's work).
pub fn forget_loads() {
    FIELDS
        .lock()
        .expect("no thread panics holding the loads")
        .clear();
}

impl Model {
    /// External load vector at time `t` over global dofs (force): tractions on their edges
    /// (8 Gauss-Legendre points, exact to degree 15) and body forces on the triangles
    /// ([`quadrature::dunavant8`], degree 8). Where a load expression changes branch (an
    /// `abs`) inside an element, the element is split along the branch's zero line and the
    /// rule applied on each piece ([`quadrature::triangle_rule`],
    /// [`quadrature::segment_rule`]): the load of a manufactured field is then as exact on a
    /// kinked element as on a smooth one (for an affine branch argument; see
    /// [`quadrature::split_triangle`] otherwise). A load t^k g(x, y) is integrated once, at
    /// t = 1, and scaled by t^k (for t > 0).
    pub fn load(&self, t: f64) -> Result<Vec<f64>> {
        if let Some(rule) = &self.load_rule {
            return self.load_by_rule(t, rule);
        }
        let programs = self
            .load_programs
            .get_or_init(|| Arc::new(LoadPrograms::new(self)));
        let Some(k) = programs.time_degree().filter(|_| t > 0.0) else {
            return Ok(self.integrate_load(programs, t, None)?.0);
        };
        let key = programs.fingerprint;
        let cached = FIELDS
            .lock()
            .expect("no thread panics holding the loads")
            .iter()
            .find(|(fingerprint, _)| *fingerprint == key)
            .map(|(_, field)| field.clone());
        let field = match cached {
            Some(field) => field,
            None => {
                let field = Arc::new(self.integrate_load(programs, 1.0, None)?.0);
                let mut fields = FIELDS.lock().expect("no thread panics holding the loads");
                if fields.len() >= FIELDS_KEPT {
                    fields.remove(0);
                }
                fields.push((key, field.clone()));
                field
            }
        };
        let scale = t.powf(k);
        Ok(field.iter().map(|v| scale * v).collect())
    }

    /// The load at `t` integrated from scratch, its expressions compiled anew, nothing
    /// cached: the number of quadrature points it took (what `study speed` divides the
    /// time by).
    pub fn integrate_load_from_scratch(&self, t: f64) -> Result<usize> {
        Ok(self.integrate_load(&LoadPrograms::new(self), t, None)?.1)
    }

    /// The k with the whole load t^k times a field of (x, y) for t > 0, if there is one (then
    /// any rule's integral of it, and so any difference of two rules', scales as t^k).
    pub fn load_time_degree(&self) -> Option<f64> {
        self.load_programs
            .get_or_init(|| Arc::new(LoadPrograms::new(self)))
            .time_degree()
    }

    /// The load at `t` (force, over global dofs) integrated by the plain rule `rule`: as
    /// another code may integrate it, one rule per triangle and per traction edge, not split
    /// at the load's kinks. Not cached.
    pub fn load_by_rule(&self, t: f64, rule: &LoadRule) -> Result<Vec<f64>> {
        let programs = self
            .load_programs
            .get_or_init(|| Arc::new(LoadPrograms::new(self)));
        Ok(self.integrate_load(programs, t, Some(rule))?.0)
    }

    /// The load at `t`, integrated (by `plain`, or with the load's own rules where `None`),
    /// and the number of quadrature points.
    fn integrate_load(
        &self,
        programs: &LoadPrograms,
        t: f64,
        plain: Option<&LoadRule>,
    ) -> Result<(Vec<f64>, usize)> {
        let mut f = vec![0.0; 2 * self.n_nodes];
        let mut points = self.add_tractions(programs, t, plain, &mut f)?;
        for body in 0..2 {
            if let Some(bf) = &programs.body[body] {
                points += self.add_body_force(bf, body, t, plain, &mut f)?;
            }
        }
        Ok((f, points))
    }

    /// The tractions' share of the load (by `plain` where given); returns the number of
    /// quadrature points.
    fn add_tractions(
        &self,
        programs: &LoadPrograms,
        t: f64,
        plain: Option<&LoadRule>,
        f: &mut [f64],
    ) -> Result<usize> {
        let segment = match plain {
            Some(rule) => rule.segment.clone(),
            None => quadrature::gauss_legendre(8),
        };
        let exact = self.scene.exact.as_deref();
        fn kinks_of<'e>(
            exprs: &'e [Expr],
            t: f64,
            plain: bool,
        ) -> Vec<crate::expr::KinkFunction<'e>> {
            match plain {
                true => Vec::new(),
                false => kink_functions(&distinct_kinks(exprs), t),
            }
        }
        // The kinks at t of each traction's expressions (a derived traction: of the body's
        // stress), built once per call rather than per edge.
        let traction_kinks: Vec<_> = self
            .scene
            .tractions
            .iter()
            .map(|tr| match &tr.g {
                Some(g) => kinks_of(&g.0, t, plain.is_some()),
                None => Vec::new(),
            })
            .collect();
        let stress_kinks = [0, 1].map(|b| match exact.and_then(|e| e.stress.as_ref()) {
            Some(st) => kinks_of(&st[b], t, plain.is_some()),
            None => Vec::new(),
        });
        let mut registers = Vec::new();
        let mut points = 0;
        for (e, &(i, [a, b])) in self.traction_edges.iter().enumerate() {
            let (pa, pb) = (self.position(a), self.position(b));
            let len = (pb[0] - pa[0]).hypot(pb[1] - pa[1]);
            let kinks = match &self.scene.tractions[i].g {
                Some(_) => &traction_kinks[i],
                None => &stress_kinks[self.traction_normals[e].0],
            };
            for &(s, w) in quadrature::segment_rule(pa, pb, kinks, &segment).iter() {
                points += 1;
                let x = pa[0] + s * (pb[0] - pa[0]);
                let y = pa[1] + s * (pb[1] - pa[1]);
                let g = match &programs.given[i] {
                    Some(p) => {
                        let mut g = [0.0; 2];
                        p.eval_point(x, y, t, &mut registers, &mut g);
                        if let Some(c) = g.iter().position(|v| !v.is_finite()) {
                            let expr = &self.scene.tractions[i].g.as_ref().expect("given").0[c];
                            return Err(expr.not_finite(
                                &self.scene.file,
                                &format!("traction[{i}].g[{c}]"),
                                x,
                                y,
                                t,
                            ));
                        }
                        g
                    }
                    None => {
                        let (body, n) = self.traction_normals[e];
                        let program = programs.stress[body].as_ref().expect(
                            "a scene without g on a traction is manufactured, with a stress",
                        );
                        let mut s = [0.0; 3];
                        program.eval_point(x, y, t, &mut registers, &mut s);
                        let g = crate::analytical::traction(s, n);
                        if g.iter().any(|v| !v.is_finite()) {
                            return Err(Error::input(
                                &self.scene.file,
                                "exact",
                                format!(
                                    "the traction on traction[{i}] (curve '{}') derived from the exact fields is not finite at x = {x}, y = {y}, t = {t}; fix the displacement (or the stress)",
                                    self.scene.tractions[i].curve
                                ),
                            ));
                        }
                        g
                    }
                };
                let w = w * len;
                for c in 0..2 {
                    f[2 * a + c] += w * (1.0 - s) * g[c];
                    f[2 * b + c] += w * s * g[c];
                }
            }
        }
        Ok(points)
    }

    /// Body `body`'s body force share of the load: each triangle's three nodal forces on a
    /// core of its own, added in element order (the same sums for any number of threads).
    /// Returns the number of quadrature points.
    fn add_body_force(
        &self,
        bf: &BodyForce,
        body: usize,
        t: f64,
        plain: Option<&LoadRule>,
        f: &mut [f64],
    ) -> Result<usize> {
        let kinks = match plain {
            Some(_) => Vec::new(),
            None => kink_functions(&distinct_kinks(&bf.exprs), t),
        };
        let triangle = match plain {
            Some(rule) => rule.triangle.clone(),
            None => quadrature::dunavant8(),
        };
        // A singular part's load r^(beta-2) (times P1, smooth along the rays) and the rest
        // of the load, each with its own rule on the triangles at the point.
        let singular = self
            .scene
            .exact
            .as_deref()
            .and_then(|e| e.singular.as_ref())
            .filter(|_| plain.is_none());
        let powers = singular.map_or([0.0; 2], |s| [0.0, s.exponent - 2.0]);
        let point = singular.map(|s| s.point);
        let elements: Vec<&Element> = self.elements.iter().filter(|e| e.body == body).collect();
        // Chunks of triangles, their rules' points evaluated together: one operation of the
        // program then runs over a few hundred points, not over one rule's 16.
        let chunks: Vec<Result<Vec<([f64; 6], usize)>>> = elements
            .par_chunks(TRIANGLES_PER_CHUNK)
            .map_init(
                || [Lanes::default(), Lanes::default()],
                |[whole, split], chunk| {
                    whole.clear();
                    split.clear();
                    // (triangle of the chunk, part, rule, its first point in its lanes)
                    let mut pieces = Vec::new();
                    for (k, e) in chunk.iter().enumerate() {
                        let p = e.nodes.map(|n| self.position(n));
                        for (part, rule) in
                            quadrature::singular::rules(p, &kinks, &triangle, point, &powers)
                        {
                            let lanes = if part.is_none() {
                                &mut *whole
                            } else {
                                &mut *split
                            };
                            let start = lanes.push(p, &rule);
                            pieces.push((k, part, rule, start));
                        }
                    }
                    whole.evaluate(&bf.whole, t);
                    if let Some(program) =
                        bf.with_singular.as_ref().filter(|_| !split.xs.is_empty())
                    {
                        split.evaluate(program, t);
                    }
                    let mut out = vec![([0.0; 6], 0); chunk.len()];
                    for (k, part, rule, start) in pieces {
                        let lanes = if part.is_none() { &*whole } else { &*split };
                        let n = lanes.xs.len();
                        let area = chunk[k].area;
                        out[k].1 += rule.len();
                        for (q, &(l1, l2, w)) in rule.iter().enumerate() {
                            let value = |o: usize| lanes.values[o * n + start + q];
                            let v = match part {
                                None => [value(0), value(1)],
                                // The rest: smooth at the point.
                                Some(0) => [value(0) - value(2), value(1) - value(3)],
                                Some(_) => [value(2), value(3)],
                            };
                            if let Some(c) = v.iter().position(|c| !c.is_finite()) {
                                let (x, y) = (lanes.xs[start + q], lanes.ys[start + q]);
                                return Err(self.body_force_not_finite(bf, body, c, x, y, t));
                            }
                            let lam = [1.0 - l1 - l2, l1, l2];
                            for a in 0..3 {
                                for c in 0..2 {
                                    out[k].0[2 * a + c] += w * area * lam[a] * v[c];
                                }
                            }
                        }
                    }
                    Ok(out)
                },
            )
            .collect();
        add_in_element_order(&elements, chunks, f)
    }

    fn body_force_not_finite(
        &self,
        bf: &BodyForce,
        body: usize,
        c: usize,
        x: f64,
        y: f64,
        t: f64,
    ) -> Error {
        if bf.derived {
            return Error::input(
                &self.scene.file,
                "exact",
                format!(
                    "the body force -div sigma of body '{}' derived from the exact fields is not finite at x = {x}, y = {y}, t = {t}; fix the displacement (or the stress)",
                    self.scene.bodies[body].surface
                ),
            );
        }
        let field = format!(
            "bodies[{}].body_force[{c}]",
            self.scene.bodies[body].file_index
        );
        bf.exprs[c].not_finite(&self.scene.file, &field, x, y, t)
    }
}

/// The chunks' nodal forces (per triangle: its six nodal components and its quadrature
/// points) added into `f` in element order, so the sums are the same for any number of
/// threads; returns the number of quadrature points, or the first chunk's error.
fn add_in_element_order(
    elements: &[&Element],
    chunks: Vec<Result<Vec<([f64; 6], usize)>>>,
    f: &mut [f64],
) -> Result<usize> {
    let mut points = 0;
    let nodal = chunks.into_iter().collect::<Result<Vec<_>>>()?;
    for (e, (forces, n)) in elements.iter().zip(nodal.into_iter().flatten()) {
        points += n;
        for a in 0..3 {
            for c in 0..2 {
                f[2 * e.nodes[a] + c] += forces[2 * a + c];
            }
        }
    }
    Ok(points)
}

/// Triangles whose quadrature points are evaluated in one call of a program (about 500
/// points with Dunavant's 16 per triangle).
const TRIANGLES_PER_CHUNK: usize = 32;

/// One thread's scratch space for the points of several rules and their values.
#[derive(Default)]
struct Lanes {
    xs: Vec<f64>,
    ys: Vec<f64>,
    registers: Vec<f64>,
    values: Vec<f64>,
}

impl Lanes {
    fn clear(&mut self) {
        self.xs.clear();
        self.ys.clear();
    }

    /// Add the points of `rule` (barycentric l1, l2) on the triangle `p`; returns the index
    /// of its first point.
    fn push(&mut self, p: [[f64; 2]; 3], rule: &[(f64, f64, f64)]) -> usize {
        let start = self.xs.len();
        for &(l1, l2, _) in rule {
            let l0 = 1.0 - l1 - l2;
            self.xs.push(l0 * p[0][0] + l1 * p[1][0] + l2 * p[2][0]);
            self.ys.push(l0 * p[0][1] + l1 * p[1][1] + l2 * p[2][1]);
        }
        start
    }

    /// `program` at every point added: output o at point i is `values[o * n + i]`.
    fn evaluate(&mut self, program: &Program, t: f64) {
        self.values.resize(program.n_outputs() * self.xs.len(), 0.0);
        program.eval_lanes(&self.xs, &self.ys, t, &mut self.registers, &mut self.values);
    }
}
