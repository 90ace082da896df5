//! A solution's own P1 mesh of the two bodies as a model of the scene, so that the error
//! integrals run on it: its boundary edges are assigned to the scene's physical curves by
//! geometry (the curves of the scene's own mesh at the same level), its bodies' areas are
//! checked against the scene's, and its fields are mapped onto the model's numbering.
//!
//! Any P1 mesh of the same bodies is accepted, not only the exported one: the errors against
//! the exact solution need no matching meshes.

use crate::contact::Interface;
use crate::error::{Error, Result};
use crate::fe::Model;
use crate::io::solution::{SolutionMesh, SolutionStep};
use crate::material::Stress;
use crate::mesh::RawMesh;
use crate::scene::Scene;
use crate::verify::field::P1Field;
use std::collections::HashMap;
use std::path::Path;

/// A solution's mesh as a model of the scene.
pub struct OutsideModel {
    /// The model on the solution's mesh (the scene's materials and supports).
    pub model: Model,
    /// Gamma_C on the solution's mesh.
    pub interface: Interface,
    /// The model node of each file point, per body (a point of both bodies is a node of
    /// each).
    node_of: [Vec<Option<usize>>; 2],
    /// The file triangle of each model element.
    triangle_of: Vec<usize>,
}

/// A straight segment of a physical curve of the scene's mesh.
type Segment = ([f64; 2], [f64; 2]);

fn distance_to_segment(p: [f64; 2], (a, b): Segment) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let len2 = d[0] * d[0] + d[1] * d[1];
    let s = if len2 > 0.0 {
        (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p[0] - a[0] - s * d[0]).hypot(p[1] - a[1] - s * d[1])
}

/// The physical curves of the scene's mesh of one body: name and segments.
fn curves_of_body(reference: &Model, raw: &RawMesh, b: usize) -> Vec<(String, Vec<Segment>)> {
    let offset = reference.node_offset[b];
    raw.names_of_dim(1)
        .into_iter()
        .filter_map(|name| {
            let segments: Vec<Segment> = reference.meshes[b]
                .curve_edges(raw, &name)
                .iter()
                .map(|e| {
                    (
                        reference.position(e[0] + offset),
                        reference.position(e[1] + offset),
                    )
                })
                .collect();
            (!segments.is_empty()).then_some((name, segments))
        })
        .collect()
}

/// The edges of body `b`'s triangles (1-based `body` marks) that belong to one triangle
/// only, in the order they are first met.
fn boundary_edges(mesh: &SolutionMesh, b: usize) -> Vec<[usize; 2]> {
    let of_body = (0..mesh.triangles.len()).filter(|&t| mesh.body[t] as usize == b + 1);
    crate::mesh::boundary_edges(of_body.map(|t| mesh.triangles[t]))
}

impl OutsideModel {
    /// The model of `scene` on the mesh of `step` read from `file`, its curves taken from
    /// the scene's own mesh `reference` (built on `raw`) at the same level.
    pub fn new(
        scene: &Scene,
        mesh: &SolutionMesh,
        reference: &Model,
        raw: &RawMesh,
        file: &Path,
    ) -> Result<Self> {
        let size = diameter(&mesh.points);
        check_bodies_apart(mesh, file)?;
        check_triangles(mesh, file)?;
        // Straight boundaries match to round-off; a coarse tolerance would let an edge of a
        // wrong boundary through.
        let tolerance = mesh.precision.tolerance(size).max(1e-10 * size);
        if marks_swapped(mesh, reference, raw, tolerance) {
            return Err(swapped_marks_error(scene, file));
        }
        check_areas(scene, mesh, reference, file)?;
        let mut out = RawMesh {
            nodes: mesh.points.clone(),
            triangles: mesh
                .triangles
                .iter()
                .zip(&mesh.body)
                .map(|(t, &b)| (*t, b as i32))
                .collect(),
            ..Default::default()
        };
        for b in 0..2 {
            out.physical_names
                .insert((2, b as i32 + 1), scene.bodies[b].surface.clone());
        }
        assign_curves(scene, mesh, reference, raw, tolerance, file, &mut out)?;
        // Their errors name the scene file; here the mesh at fault is the solution's.
        let model = Model::new(scene, &out, file).map_err(|e| on_file(e, file))?;
        let interface = Interface::new(&model, &out).map_err(|e| on_file(e, file))?;
        let node_of = [0, 1].map(|b| {
            (0..mesh.points.len())
                .map(|p| {
                    model.meshes[b]
                        .local_of_raw(p)
                        .map(|l| l + model.node_offset[b])
                })
                .collect()
        });
        // Model::new takes body 1's triangles in file order, then body 2's.
        let triangle_of = (1..=2u8)
            .flat_map(|b| {
                mesh.body
                    .iter()
                    .enumerate()
                    .filter(move |(_, m)| **m == b)
                    .map(|(t, _)| t)
            })
            .collect();
        Ok(OutsideModel {
            model,
            interface,
            node_of,
            triangle_of,
        })
    }

    /// The field of `step` at time `time` on this model.
    pub fn field(&self, time: f64, step: &SolutionStep, file: &Path) -> Result<P1Field<'static>> {
        let model = &self.model;
        let mut u = vec![0.0; 2 * model.n_nodes];
        let mut pressure = step.pressure.as_ref().map(|_| vec![0.0; model.n_nodes]);
        for b in 0..2 {
            for (p, g) in self.node_of[b].iter().enumerate() {
                let Some(g) = *g else { continue };
                u[2 * g] = step.displacement[p][0];
                u[2 * g + 1] = step.displacement[p][1];
                if let (Some(out), Some(given)) = (pressure.as_mut(), step.pressure.as_ref()) {
                    out[g] = given[p];
                }
            }
        }
        let stress = step.stress.as_ref().map(|s| {
            self.triangle_of
                .iter()
                .map(|&t| Stress::new(s[t][0], s[t][1], s[t][2]))
                .collect()
        });
        P1Field::from_nodal(model, &self.interface, time, u, stress, pressure)
            .map_err(|e| Error::input(file, "stress", e.to_string()))
    }
}

/// Each boundary edge of the solution's mesh assigned to the scene's physical curve it lies
/// on (within `tolerance`), as a line of `out`; an edge on no curve is refused.
fn assign_curves(
    scene: &Scene,
    mesh: &SolutionMesh,
    reference: &Model,
    raw: &RawMesh,
    tolerance: f64,
    file: &Path,
    out: &mut RawMesh,
) -> Result<()> {
    let mut tags: HashMap<String, i32> = HashMap::new();
    for b in 0..2 {
        let curves = curves_of_body(reference, raw, b);
        for e in boundary_edges(mesh, b) {
            let (p, q) = (mesh.points[e[0]], mesh.points[e[1]]);
            let mid = [(p[0] + q[0]) / 2.0, (p[1] + q[1]) / 2.0];
            let off = |segments: &[Segment]| {
                [p, q, mid]
                    .iter()
                    .map(|&x| {
                        segments
                            .iter()
                            .map(|&s| distance_to_segment(x, s))
                            .fold(f64::INFINITY, f64::min)
                    })
                    .fold(0.0f64, f64::max)
            };
            // The curve the edge lies on (the nearest; a corner's neighbours are farther).
            let nearest = curves
                .iter()
                .map(|(name, segments)| (name, off(segments)))
                .min_by(|a, b| a.1.total_cmp(&b.1));
            match nearest {
                Some((name, d)) if d <= tolerance => {
                    let next = tags.len() as i32 + 10;
                    let tag = *tags.entry(name.clone()).or_insert(next);
                    out.physical_names.insert((1, tag), name.clone());
                    out.lines.push((e, tag));
                }
                // A boundary edge of no curve: an inner hole, or a crack between
                // triangles that do not share their nodes.
                _ => {
                    return Err(Error::input(
                        file,
                        "Cells",
                        format!(
                            "the boundary edge from ({}, {}) to ({}, {}) of body {} lies on no boundary curve of scene '{}' (nearest {:.3e} away): the mesh has a gap or a hole there, or its triangles do not share their nodes along it; write a conforming mesh of the bodies",
                            p[0],
                            p[1],
                            q[0],
                            q[1],
                            b + 1,
                            scene.name,
                            nearest.map_or(f64::INFINITY, |n| n.1)
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// Whether every boundary edge of each mark's triangles lies on a curve of the other body:
/// the marks 1 and 2 are swapped.
fn marks_swapped(mesh: &SolutionMesh, reference: &Model, raw: &RawMesh, tolerance: f64) -> bool {
    (0..2).all(|b| {
        let other = curves_of_body(reference, raw, 1 - b);
        let edges = boundary_edges(mesh, b);
        !edges.is_empty()
            && edges.iter().all(|e| {
                [mesh.points[e[0]], mesh.points[e[1]]].iter().all(|&x| {
                    other.iter().any(|(_, segments)| {
                        segments
                            .iter()
                            .any(|&s| distance_to_segment(x, s) <= tolerance)
                    })
                })
            })
    })
}

fn swapped_marks_error(scene: &Scene, file: &Path) -> Error {
    let (one, two) = (&scene.bodies[0].surface, &scene.bodies[1].surface);
    Error::input(
        file,
        "body",
        format!(
            "the triangles marked body 1 lie where the scene's body 2 ('{two}') is, and those marked 2 where body 1 ('{one}') is: the body marks are swapped; write `body` = 1 on '{one}' (the slave) and 2 on '{two}' (the master), as the physical surfaces of mesh_L.msh number them"
        ),
    )
}

/// The two bodies share no point: a point of both (a writer that merged coincident points)
/// glues them there and changes every error.
fn check_bodies_apart(mesh: &SolutionMesh, file: &Path) -> Result<()> {
    let mut body_of = vec![0u8; mesh.points.len()];
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for &p in tri {
            let b = mesh.body[t];
            if body_of[p] != 0 && body_of[p] != b {
                let x = mesh.points[p];
                return Err(Error::input(
                    file,
                    "Cells",
                    format!(
                        "point {p} at ({}, {}) belongs to triangles of both bodies, which glues them there; write each body with points of its own (do not merge coincident points where the bodies touch)",
                        x[0], x[1]
                    ),
                ));
            }
            body_of[p] = b;
        }
    }
    Ok(())
}

/// No triangle is degenerate (area at round-off of its longest edge squared), the
/// criterion of the scene's own meshes.
fn check_triangles(mesh: &SolutionMesh, file: &Path) -> Result<()> {
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let [p, q, r] = tri.map(|i| mesh.points[i]);
        let edge2 = [(p, q), (q, r), (r, p)]
            .iter()
            .map(|(a, b)| (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2))
            .fold(0.0f64, f64::max);
        let area = crate::mesh::signed_area(p, q, r).abs();
        if area <= mesh.precision.tolerance(1.0).max(1e-14) * edge2.max(f64::MIN_POSITIVE) {
            return Err(Error::input(
                file,
                "Cells",
                format!(
                    "triangle {t} with corners ({}, {}), ({}, {}), ({}, {}) has no area: remove it, or fix its points",
                    p[0], p[1], q[0], q[1], r[0], r[1]
                ),
            ));
        }
    }
    Ok(())
}

/// An error about the scene's mesh, restated as one about the solution file's.
fn on_file(e: Error, file: &Path) -> Error {
    match e {
        Error::Input { message, .. } => Error::input(file, "Cells", message),
        other => other,
    }
}

/// The largest extent of the points (length).
fn diameter(points: &[[f64; 2]]) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in points {
        for c in 0..2 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
    }
    (hi[0] - lo[0]).hypot(hi[1] - lo[1])
}

/// Each body's area against the scene's: a mesh that leaves part of a body out (or covers
/// more) is refused. The tolerance follows the file's precision and the triangle count
/// (round-off of the sum).
fn check_areas(scene: &Scene, mesh: &SolutionMesh, reference: &Model, file: &Path) -> Result<()> {
    for b in 0..2 {
        let want: f64 = reference.elements[reference.body_elements(b)]
            .iter()
            .map(|e| e.area)
            .sum();
        let (mut got, mut n) = (0.0, 0usize);
        for (t, tri) in mesh.triangles.iter().enumerate() {
            if mesh.body[t] as usize == b + 1 {
                let [p, q, r] = tri.map(|i| mesh.points[i]);
                got += crate::mesh::signed_area(p, q, r).abs();
                n += 1;
            }
        }
        let tolerance = mesh
            .precision
            .tolerance((n.max(1) as f64).sqrt())
            .max(1e-10);
        if (got - want).abs() > tolerance * want {
            return Err(Error::input(
                file,
                "Cells",
                format!(
                    "the triangles of body {} ('{}') cover an area of {got:.12e}, the body's is {want:.12e} (off by {:.2e} relative, beyond the file's precision): the mesh does not cover the body; write the whole body, with `body` = {} on its triangles",
                    b + 1,
                    scene.bodies[b].surface,
                    (got - want).abs() / want,
                    b + 1
                ),
            ));
        }
    }
    Ok(())
}
