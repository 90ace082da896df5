//! The reader of a solution in gmsh's ASCII MSH format (4.1 or 2.2): the MSH module reads
//! the file ([`crate::mesh::msh::file`]); here the bodies' triangles are picked by physical
//! surface, the nodes they use kept, and the views grouped into one step per time.

use super::checks::{
    DISPLACEMENT, ElementKind, Named, PRESSURE, STRESS, check_both_bodies, conversion_route,
    displacement_2d, planar_points, quoted_list, stress_2d,
};
use super::{FieldNames, Precision, SolutionMesh, SolutionStep};
use crate::error::{Error, Result};
use crate::mesh::msh::file::{MshFile, MshVersion, parse_msh_file};
use crate::mesh::msh::views::View;
use std::path::Path;

/// A triangle of the bodies: its element tag, its nodes (indices into the file's nodes)
/// and its body (1 or 2).
type BodyTriangle = (u64, [usize; 3], u8);

/// The views of one time: displacement, stress, pressure.
type StepViews<'a> = [Option<&'a View>; 3];

/// Read a solution in gmsh's ASCII MSH format (4.1 or 2.2): the triangles of the physical
/// surfaces named `bodies[0]` (body 1) and `bodies[1]` (body 2) (in a file without
/// `$PhysicalNames`, physical tags 1 and 2, as in the exported mesh), the nodes they use, and
/// per time step the views named by `names`: `$NodeData` displacement (2 or 3
/// components), optional `$ElementData` stress (3, 4 or 9 components, as for a .vtu),
/// optional `$NodeData` pressure (1 component). A step's time is its views' first real
/// tag. The steps are returned in time order; decimal text is read as [`Precision::F64`].
pub fn read_msh_solution(
    path: &Path,
    names: &FieldNames,
    bodies: [&str; 2],
) -> Result<Vec<(f64, SolutionStep)>> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    parse_msh_solution(&bytes, path, names, bodies)
}

/// Read the bytes of an MSH solution; `path` names the file in errors only.
pub fn parse_msh_solution(
    bytes: &[u8],
    path: &Path,
    names: &FieldNames,
    bodies: [&str; 2],
) -> Result<Vec<(f64, SolutionStep)>> {
    let wanted = [
        names.displacement.as_str(),
        names.stress.as_str(),
        names.pressure.as_str(),
    ];
    let file = parse_msh_file(bytes, path, &wanted)?;
    let body_tags = body_tags(&file, path, bodies)?;
    let triangles = body_triangles(&file, path, bodies, body_tags)?;
    let (mesh, kept) = solution_mesh(&file, path, &triangles)?;
    let times = views_by_time(&file, path, names)?;
    let kept_of = Kept {
        file: &file,
        path,
        kept: &kept,
        triangles: &triangles,
    };
    let mut steps = Vec::with_capacity(times.len());
    for (time, views) in times {
        let step = kept_of.step(time, views, names, mesh.clone())?;
        steps.push((time, step));
    }
    Ok(steps)
}

/// The physical tags of the bodies' surfaces, by name; in a file that names no surface,
/// 1 and 2 (the tags of the exported mesh).
fn body_tags(file: &MshFile, path: &Path, bodies: [&str; 2]) -> Result<[i64; 2]> {
    let surfaces: Vec<&str> = file
        .physical_names
        .iter()
        .filter(|(d, _, _)| *d == 2)
        .map(|(_, _, n)| n.as_str())
        .collect();
    let mut body_tags = [0i64; 2];
    for (k, name) in bodies.iter().enumerate() {
        let tags: Vec<i64> = file
            .physical_names
            .iter()
            .filter(|(d, _, n)| *d == 2 && n == name)
            .map(|(_, t, _)| *t)
            .collect();
        body_tags[k] = match tags[..] {
            [t] => t,
            // Without names, the physical tags of the exported mesh: 1 and 2.
            [] if surfaces.is_empty() => k as i64 + 1,
            [] => {
                return Err(Error::input(
                    path,
                    "$PhysicalNames",
                    format!(
                        "no physical surface named '{name}' (body {}); the file's physical surfaces are {}: name the bodies' surfaces as the file does, or write the mesh with `Physical Surface(\"{name}\")`",
                        k + 1,
                        if surfaces.is_empty() {
                            "none".to_string()
                        } else {
                            surfaces.join(", ")
                        }
                    ),
                ));
            }
            _ => {
                return Err(Error::input(
                    path,
                    "$PhysicalNames",
                    format!(
                        "{} physical surfaces are named '{name}': give each body's surface a name of its own",
                        tags.len()
                    ),
                ));
            }
        };
    }
    Ok(body_tags)
}

/// The triangles of the bodies' surfaces (tags `body_tags`), in the file's order: 3-node
/// triangles of one body each, no point repeated; another element type in a body is
/// refused with the way to convert.
fn body_triangles(
    file: &MshFile,
    path: &Path,
    bodies: [&str; 2],
    body_tags: [i64; 2],
) -> Result<Vec<BodyTriangle>> {
    let mut triangles: Vec<BodyTriangle> = Vec::new();
    for e in &file.surface_elements {
        let of = |t: i64| e.physicals.iter().any(|p| p.abs() == t);
        let body = match (of(body_tags[0]), of(body_tags[1])) {
            (false, false) => continue,
            (true, false) => 1u8,
            (false, true) => 2,
            (true, true) => {
                return Err(Error::input(
                    path,
                    "$Elements",
                    format!(
                        "element {} belongs to both '{}' and '{}': each triangle belongs to one body",
                        e.tag, bodies[0], bodies[1]
                    ),
                ));
            }
        };
        if e.etype != 2 {
            let (what, kind) = match e.etype {
                3 | 10 | 16 => ("quadrilateral", ElementKind::Quadrilateral),
                9 => ("quadratic triangle", ElementKind::QuadraticTriangle),
                _ => ("higher-order element", ElementKind::Other),
            };
            return Err(Error::input(
                path,
                "$Elements",
                format!(
                    "element {} of '{}' is a {what} (gmsh type {}); {}",
                    e.tag,
                    bodies[body as usize - 1],
                    e.etype,
                    conversion_route(kind)
                ),
            ));
        }
        let t = [e.nodes[0], e.nodes[1], e.nodes[2]];
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            return Err(Error::input(
                path,
                "$Elements",
                format!(
                    "triangle {} repeats a node: a degenerate triangle; fix the mesh",
                    e.tag
                ),
            ));
        }
        triangles.push((e.tag, t, body));
    }
    if triangles.is_empty() {
        let entities = if file.version == MshVersion::V41 && file.entities.is_none() {
            " (the file has no $Entities section, through which MSH 4.1 gives the elements' physical groups)"
        } else {
            ""
        };
        return Err(Error::input(
            path,
            "$Elements",
            format!(
                "no triangle lies in the physical surfaces '{}' and '{}'{entities}: write the mesh with the bodies' physical surfaces",
                bodies[0], bodies[1]
            ),
        ));
    }
    Ok(triangles)
}

/// The mesh of the bodies' triangles, both bodies present, on the nodes they use (in the
/// file's order, in the z = 0 plane); with those nodes' indices into the file's.
fn solution_mesh(
    file: &MshFile,
    path: &Path,
    triangles: &[BodyTriangle],
) -> Result<(SolutionMesh, Vec<usize>)> {
    let body: Vec<u8> = triangles.iter().map(|t| t.2).collect();
    check_both_bodies(&body, path, "$Elements")?;
    let mut point_of = vec![usize::MAX; file.nodes.len()];
    for (_, t, _) in triangles {
        for &n in t {
            point_of[n] = 0;
        }
    }
    let mut kept: Vec<usize> = Vec::new();
    for (n, p) in point_of.iter_mut().enumerate() {
        if *p == 0 {
            *p = kept.len();
            kept.push(n);
        }
    }
    let xyz: Vec<f64> = kept.iter().flat_map(|&n| file.nodes[n]).collect();
    let points = planar_points(&xyz, Precision::F64, path, "$Nodes")?;
    let mesh = SolutionMesh {
        points,
        triangles: triangles
            .iter()
            .map(|(_, t, _)| t.map(|n| point_of[n]))
            .collect(),
        body,
        precision: Precision::F64,
    };
    Ok((mesh, kept))
}

/// The views of each time, in time order: a view of the kind its field is (the stress per
/// element, the others per node), one per field and time; a displacement in the file, and
/// a stress or pressure named other than by default.
fn views_by_time<'a>(
    file: &'a MshFile,
    path: &Path,
    names: &FieldNames,
) -> Result<Vec<(f64, StepViews<'a>)>> {
    let mut times: Vec<(f64, StepViews<'a>)> = Vec::new();
    for v in &file.views {
        let k = if v.name == names.displacement {
            0
        } else if v.name == names.stress {
            1
        } else {
            2
        };
        if v.per_element != (k == 1) {
            return Err(Error::input(
                path,
                v.field(),
                if k == 1 {
                    "the stress is a $NodeData view: the grading reads a P0 stress per triangle; write it as $ElementData, or leave it out".to_string()
                } else {
                    format!(
                        "'{}' is an $ElementData view: it is read per node; write it as $NodeData",
                        v.name
                    )
                },
            ));
        }
        let i = match times.iter().position(|(t, _)| *t == v.time) {
            Some(i) => i,
            None => {
                times.push((v.time, [None; 3]));
                times.len() - 1
            }
        };
        if times[i].1[k].replace(v).is_some() {
            return Err(Error::input(
                path,
                v.field(),
                "two views of this name have this time: write one view per field and time",
            ));
        }
    }
    let given = |k: usize| times.iter().any(|(_, views)| views[k].is_some());
    if !given(0) {
        return Err(missing_view(
            file,
            path,
            &names.displacement,
            &DISPLACEMENT,
            false,
            "write the displacement as a $NodeData view of that name per time step",
        ));
    }
    if names.stress_named() && !given(1) {
        return Err(missing_view(
            file,
            path,
            &names.stress,
            &STRESS,
            true,
            "write the P0 stress as an $ElementData view of that name per time step",
        ));
    }
    if names.pressure_named() && !given(2) {
        return Err(missing_view(
            file,
            path,
            &names.pressure,
            &PRESSURE,
            false,
            "write the nodal pressure as a $NodeData view of that name per time step",
        ));
    }
    times.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(times)
}

/// The refusal of a file without a view named `name` of the field `named` (`per_element`:
/// an `$ElementData` view): the views of its kind the file has, and the fix (`write` says
/// how to write it under that name).
fn missing_view(
    file: &MshFile,
    path: &Path,
    name: &str,
    named: &Named,
    per_element: bool,
    write: &str,
) -> Error {
    let section = if per_element {
        "$ElementData"
    } else {
        "$NodeData"
    };
    let found: Vec<(&str, Option<usize>)> = file
        .headers
        .iter()
        .filter(|h| h.per_element == per_element)
        .map(|h| (h.name.as_str(), h.components))
        .collect();
    Error::input(
        path,
        format!("{section} \"{name}\""),
        format!(
            "no {section} view named '{name}' (the file's {section} views are {}): {}",
            quoted_list(found.iter().map(|f| f.0)),
            named.fix(&found, write)
        ),
    )
}

/// The nodes and triangles kept of a file, for the values of its views.
struct Kept<'a> {
    file: &'a MshFile,
    path: &'a Path,
    /// The file's index of each point of the mesh.
    kept: &'a [usize],
    triangles: &'a [BodyTriangle],
}

impl Kept<'_> {
    /// The state at `time` from its views (displacement, stress, pressure), on `mesh`.
    fn step(
        &self,
        time: f64,
        [u, s, p]: StepViews,
        names: &FieldNames,
        mesh: SolutionMesh,
    ) -> Result<SolutionStep> {
        let (file, path) = (self.file, self.path);
        let node_tags = || self.kept.iter().map(|&n| file.node_tags[n]);
        let Some(u) = u else {
            let other = s.or(p).expect("a view of the time");
            return Err(Error::input(
                path,
                format!("$NodeData \"{}\" (time {time})", names.displacement),
                format!(
                    "no $NodeData view '{}' at time {time}, where '{}' is given: write the displacement at every time step",
                    names.displacement, other.name
                ),
            ));
        };
        let values = u.gather(node_tags(), "node", path)?;
        let label = |i: usize| format!("node {}", file.node_tags[self.kept[i]]);
        let displacement = displacement_2d(
            &values,
            u.components,
            Precision::F64,
            path,
            &u.field(),
            &label,
        )?;
        let stress = match s {
            None => None,
            Some(s) => {
                let tags = self.triangles.iter().map(|t| t.0);
                let values = s.gather(tags, "element", path)?;
                let label = |i: usize| format!("element {}", self.triangles[i].0);
                Some(stress_2d(
                    &values,
                    s.components,
                    Precision::F64,
                    path,
                    &s.field(),
                    &label,
                )?)
            }
        };
        let pressure = match p {
            None => None,
            Some(p) if p.components != 1 => {
                return Err(Error::input(
                    path,
                    p.field(),
                    format!(
                        "{} components per node; the pressure has one: write it so",
                        p.components
                    ),
                ));
            }
            Some(p) => Some(p.gather(node_tags(), "node", path)?),
        };
        Ok(SolutionStep {
            mesh,
            displacement,
            stress,
            pressure,
        })
    }
}
