//! `export`: a scene's manufactured contact problem on a family of meshes, as files another
//! code can solve: the meshes (MSH 4.1 and 2.2), the physics (problem.toml, problem.py), the
//! nodal loads and constitutive sources per level and step (CSV), and a README that says
//! what to solve and what to write back for `grade`.

use super::family::Family;
pub use super::family::Source;
use super::problem::{Origin, ProblemFile, problem_file, problem_py};
use crate::error::{Error, Result};
use crate::fe::Model;
use crate::io::csv_bytes;
use crate::mesh::RawMesh;
use crate::mesh::msh::{ExportMesh, PhysicalGroup};
use crate::report::folder::write;
use crate::report::{Output, Staging};
use crate::scene::Scene;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// One row of loads_L.csv: the P1-consistent nodal load (force) at one node and step.
#[derive(Debug, Serialize, Deserialize)]
pub struct LoadRow {
    /// Step n (1..N).
    pub step: usize,
    /// t_n.
    pub t: f64,
    /// Node tag of mesh_L.msh (the model's node number + 1).
    pub node: usize,
    /// The load's components (force).
    pub fx: f64,
    pub fy: f64,
}

/// One row of source_L.csv: the constitutive source's mean over one triangle at t_n
/// (stress per time).
#[derive(Serialize)]
struct SourceRow {
    step: usize,
    t: f64,
    element: usize,
    s11: f64,
    s22: f64,
    s12: f64,
}

/// What an export wrote.
#[derive(Debug)]
pub struct Exported {
    /// Per level: (level, h, nodes, triangles).
    pub levels: Vec<(usize, f64, usize, usize)>,
    /// Files written.
    pub files: usize,
}

/// The mesh of `model` with its physical groups, the curves read from the mesh `raw` it
/// was built on: the two bodies (surfaces 1 and 2, in the scene's order), then every
/// physical curve that has edges on the model (tags from 3, by name).
pub fn export_mesh(model: &Model, raw: &RawMesh) -> ExportMesh {
    let nodes = (0..model.n_nodes).map(|g| model.position(g)).collect();
    let mut groups: Vec<PhysicalGroup> = (0..2)
        .map(|b| PhysicalGroup {
            dim: 2,
            tag: b + 1,
            name: model.meshes[b].name.clone(),
            elements: model.elements[model.body_elements(b)]
                .iter()
                .map(|e| e.nodes.to_vec())
                .collect(),
        })
        .collect();
    for name in raw.names_of_dim(1) {
        let elements: Vec<Vec<usize>> = (0..2)
            .flat_map(|b| {
                let offset = model.node_offset[b];
                model.meshes[b]
                    .curve_edges(raw, &name)
                    .into_iter()
                    .map(move |e| vec![e[0] + offset, e[1] + offset])
            })
            .collect();
        if !elements.is_empty() {
            let tag = groups.len() + 1;
            groups.push(PhysicalGroup {
                dim: 1,
                tag,
                name,
                elements,
            });
        }
    }
    ExportMesh {
        nodes,
        body_nodes: [0..model.node_offset[1], model.node_offset[1]..model.n_nodes],
        groups,
    }
}

/// Export `source` at `levels` into `out`, all or nothing.
pub fn export(source: &Source, levels: &[usize], out: &Path) -> Result<Exported> {
    let family = Family::resolve(source)?;
    // Before anything is meshed or written: the finest level must fit in memory (gmsh alone
    // took 15 GB refining level 10 of rates-exact).
    if let Some(&finest) = levels.iter().max() {
        if let Some(message) =
            crate::case::memory_refusal_of(&family.scene, &family.params, finest)?
        {
            return Err(Error::Argument {
                option: format!("--levels {}-{finest}", levels.iter().min().unwrap_or(&0)),
                message: format!("{message}; export at most that level"),
            });
        }
    }
    let (staging, notes) = Staging::begin(out, Output::Export)?;
    for n in notes {
        eprintln!("note: {n}");
    }
    let dir = staging.path().to_path_buf();
    let mut exported = Exported {
        levels: Vec::new(),
        files: 0,
    };
    let mut first: Option<(ProblemFile, String)> = None;
    let mut loading = Loading {
        proportional: true,
        held_by_contact: None,
    };
    for &level in levels {
        let (case, raw) = family.case(level)?;
        let model = &case.problem.model;
        let mesh = export_mesh(model, &raw);
        write(&dir, &format!("mesh_{level}.msh"), mesh.msh41().as_bytes())?;
        write(
            &dir,
            &format!("mesh_{level}.msh22.msh"),
            mesh.msh22().as_bytes(),
        )?;
        let (files, proportional) = write_loads(&family, model, level, &dir)?;
        exported.files += 2 + files;
        loading.proportional &= proportional;
        if first.is_none() {
            loading.held_by_contact = case.problem.interface.held_only_by_contact(model);
            let origin = Origin {
                scene: &family.scene,
                study: family.study.as_deref(),
                levels,
                steps: family.steps,
            };
            let problem = problem_file(&origin, model, &case.problem.interface, &mesh);
            let derived = derived_stress(&family.scene);
            let python = problem_py(&problem, &samples(model), derived);
            first = Some((problem, python));
        }
        exported
            .levels
            .push((level, case.h, model.n_nodes, model.elements.len()));
    }
    let (problem, python) = first.ok_or_else(|| {
        Error::input(
            out,
            "--levels",
            "no level to export; give --levels A-B with A <= B",
        )
    })?;
    let toml = toml::to_string_pretty(&problem).map_err(|e| {
        Error::input(
            out,
            "problem.toml",
            format!("cannot write it ({e}); this is a bug"),
        )
    })?;
    let toml = format!("{}{toml}", header_comment(&family));
    write(&dir, "problem.toml", toml.as_bytes())?;
    write(&dir, "problem.py", python.as_bytes())?;
    write(
        &dir,
        "README.md",
        super::readme::export_readme(&family, &exported.levels, &loading).as_bytes(),
    )?;
    exported.files += 3;
    staging.commit()?;
    Ok(exported)
}

fn header_comment(family: &Family) -> String {
    let what = match &family.study {
        Some(s) => format!("study {s} (scene {})", family.scene.name),
        None => format!("scene {}", family.scene.name),
    };
    format!(
        "# The physics of {what}, exported by contact-rates: numbers, and expressions in the\n# syntax of `syntax`. README.md says what to solve and what to write back.\n\n"
    )
}

/// What the README says of the loading: whether the loads are proportional to t, and which
/// body only the contact holds along Gamma_C's normal.
pub struct Loading {
    /// Every step's nodal loads are t_n / T times those at T (to 1e-12 of their largest).
    pub proportional: bool,
    /// The body (0: body 1) no support holds along Gamma_C's normal.
    pub held_by_contact: Option<usize>,
}

/// loads_L.csv at every step and, where the law needs one, source_L.csv; the files written,
/// and whether the loads are proportional to t.
fn write_loads(
    family: &Family,
    model: &crate::fe::Model,
    level: usize,
    dir: &Path,
) -> Result<(usize, bool)> {
    let mut loads = Vec::new();
    let mut sources = Vec::new();
    let times = family.times();
    let per_step = times
        .iter()
        .map(|&t| model.load(t))
        .collect::<Result<Vec<_>>>()?;
    let (final_time, at_t) = (times[times.len() - 1], &per_step[per_step.len() - 1]);
    let largest = at_t.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let proportional = times.iter().zip(&per_step).all(|(t, f)| {
        f.iter()
            .zip(at_t)
            .all(|(a, b)| (a - t / final_time * b).abs() <= 1e-12 * largest)
    });
    for (n, (&t, f)) in times.iter().zip(&per_step).enumerate() {
        for node in 0..model.n_nodes {
            loads.push(LoadRow {
                step: n + 1,
                t,
                node: node + 1,
                fx: f[2 * node],
                fy: f[2 * node + 1],
            });
        }
        if let Some(s) = model.constitutive_source(t)? {
            for (e, v) in s.iter().enumerate() {
                sources.push(SourceRow {
                    step: n + 1,
                    t,
                    element: e + 1,
                    s11: v[0],
                    s22: v[1],
                    s12: v[2],
                });
            }
        }
    }
    write(dir, &format!("loads_{level}.csv"), &csv_bytes(&loads)?)?;
    if sources.is_empty() {
        return Ok((1, proportional));
    }
    write(dir, &format!("source_{level}.csv"), &csv_bytes(&sources)?)?;
    Ok((2, proportional))
}

/// Whether each body's exact stress is E eps(u), derived from the displacement (an elastic
/// body of a scene that gives no stress of its own).
fn derived_stress(scene: &Scene) -> [bool; 2] {
    let exact = scene.exact.as_deref();
    [0, 1].map(|b| {
        exact
            .and_then(|e| e.stress.as_ref())
            .is_some_and(|s| s[b].iter().any(|c| c.text.contains("d/d")))
    })
}

/// Up to 12 triangle centroids per body, spread over its elements: where problem.py's
/// check compares.
fn samples(model: &crate::fe::Model) -> [Vec<[f64; 2]>; 2] {
    [0, 1].map(|b| {
        let range = model.body_elements(b);
        let step = range.len().div_ceil(12).max(1);
        model.elements[range]
            .iter()
            .step_by(step)
            .map(|e| {
                let p = e.nodes.map(|n| model.position(n));
                [0, 1].map(|c| (p[0][c] + p[1][c] + p[2][c]) / 3.0)
            })
            .collect()
    })
}

/// The levels A-B of a `--levels` argument.
pub fn parse_levels(text: &str) -> std::result::Result<Vec<usize>, String> {
    let (a, b) = text.split_once('-').unwrap_or((text, text));
    let parse = |s: &str| {
        s.trim()
            .parse::<usize>()
            .map_err(|_| format!("--levels {text}: '{s}' is not a level; write A-B, e.g. 0-3"))
    };
    let (a, b) = (parse(a)?, parse(b)?);
    if a > b {
        return Err(format!(
            "--levels {text}: {a} > {b}; write A-B with A <= B, e.g. 0-3"
        ));
    }
    Ok((a..=b).collect())
}
