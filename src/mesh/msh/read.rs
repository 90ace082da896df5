//! The reader of the project's own meshes: gmsh's MSH 4.1 ASCII output for a scene's .geo
//! (nodes, 2-node lines, 3-node triangles and physical groups by name), into a [`RawMesh`].
//! Strict: a file it refuses is a corrupt cache entry, to delete and regenerate.

use super::cursor::{Cursor, Voice};
use super::{EntityPhysicals, RawMesh, read_entities};
use crate::error::{Error, Result};
use std::collections::HashMap;
use std::path::Path;

/// Guard against absurd counts in corrupted files before allocating.
fn check_count(c: &Cursor, n: usize, what: &str) -> Result<()> {
    if n > 200_000_000 {
        return Err(c.err(format!("{what} count {n} is not plausible")));
    }
    Ok(())
}

/// Read a MSH 4.1 ASCII file.
pub fn read_msh(path: &Path) -> Result<RawMesh> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    parse_msh(&text, path)
}

/// Parse the text of a MSH 4.1 ASCII file; `path` is used in error messages only.
pub fn parse_msh(text: &str, path: &Path) -> Result<RawMesh> {
    let mut mesh = RawMesh::default();
    let rest = take_physical_names(text, path, &mut mesh.physical_names)?;
    let mut entity_physicals = EntityPhysicals::new();
    let mut node_index: HashMap<usize, usize> = HashMap::new();
    let (mut have_format, mut have_nodes, mut have_elements) = (false, false, false);
    // The errors name the section last entered (a stray token, the one before it).
    let mut c = Cursor::new(&rest, path, "$MeshFormat", Voice::Cache);
    while let Some(tok) = c.token() {
        match tok {
            "$MeshFormat" => {
                read_format(&mut c)?;
                have_format = true;
            }
            "$Entities" => {
                c.section = "$Entities".into();
                entity_physicals.extend(read_entities(&mut c, check_count)?);
            }
            "$Nodes" => {
                read_nodes(&mut c, &mut mesh, &mut node_index)?;
                have_nodes = true;
            }
            "$Elements" => {
                read_elements(&mut c, &mut mesh, &entity_physicals, &node_index)?;
                have_elements = true;
            }
            s if s.starts_with('$') && !s.starts_with("$End") => c.skip(s)?,
            other => return Err(c.err(format!("unexpected token '{other}'"))),
        }
    }
    if !have_format || !have_nodes || !have_elements {
        return Err(Error::input(
            path,
            "file",
            "missing $MeshFormat, $Nodes or $Elements (an empty or truncated mesh); delete it and regenerate it",
        ));
    }
    if mesh.triangles.is_empty() {
        return Err(Error::input(
            path,
            "$Elements",
            "the mesh has no triangle in a physical surface (gmsh wrote an empty mesh); check the .geo's Physical Surface lines",
        ));
    }
    Ok(mesh)
}

/// `$PhysicalNames` has quoted names that may contain spaces: read it by lines into
/// `names`, and return the text without it for the token reader.
fn take_physical_names(
    text: &str,
    path: &Path,
    names: &mut HashMap<(usize, i32), String>,
) -> Result<String> {
    let bad = |msg: String| Error::input(path, "$PhysicalNames", msg);
    let mut rest = text;
    let mut out = String::new();
    while let Some(start) = rest.find("$PhysicalNames") {
        out.push_str(&rest[..start]);
        let after = &rest[start + "$PhysicalNames".len()..];
        let end = after.find("$EndPhysicalNames").ok_or_else(|| {
            bad(
                "section is not closed by $EndPhysicalNames; delete the file and regenerate it"
                    .into(),
            )
        })?;
        let mut lines = after[..end]
            .lines()
            .map(str::trim)
            .filter(|l| !l.is_empty());
        let n: usize = lines
            .next()
            .and_then(|l| l.parse().ok())
            .ok_or_else(|| bad("missing count; delete the file and regenerate it".into()))?;
        for _ in 0..n {
            let l = lines.next().ok_or_else(|| {
                bad("fewer names than announced; delete the file and regenerate it".into())
            })?;
            let mut parts = l.splitn(3, char::is_whitespace);
            let dim: Option<usize> = parts.next().and_then(|s| s.parse().ok());
            let tag: Option<i32> = parts.next().and_then(|s| s.parse().ok());
            let name = parts.next().map(|s| s.trim().trim_matches('"').to_string());
            match (dim, tag, name) {
                (Some(d), Some(t), Some(nm)) if d <= 3 => {
                    names.insert((d, t), nm);
                }
                _ => {
                    return Err(bad(format!(
                        "malformed line '{l}'; delete the file and regenerate it"
                    )));
                }
            }
        }
        rest = &after[end + "$EndPhysicalNames".len()..];
    }
    out.push_str(rest);
    Ok(out)
}

fn read_format(c: &mut Cursor) -> Result<()> {
    c.section = "$MeshFormat".into();
    let version = c.next("the version")?;
    if version != "4.1" {
        return Err(c.err(format!(
            "version {version} is not supported (need 4.1: run gmsh with -format msh41)"
        )));
    }
    let file_type = c.count("the file type")?;
    if file_type != 0 {
        return Err(c.err("binary MSH is not supported (need ASCII: run gmsh with -bin 0)"));
    }
    let _data_size = c.count("the data size")?;
    c.end("$EndMeshFormat")
}

fn read_nodes(
    c: &mut Cursor,
    mesh: &mut RawMesh,
    node_index: &mut HashMap<usize, usize>,
) -> Result<()> {
    c.section = "$Nodes".into();
    let nblocks = c.count("the number of node blocks")?;
    let nnodes = c.count("the number of nodes")?;
    check_count(c, nnodes, "node")?;
    let _min = c.count("the smallest node tag")?;
    let _max = c.count("the largest node tag")?;
    mesh.nodes.reserve(nnodes);
    for _ in 0..nblocks {
        let dim = c.count("a node block's dimension")?;
        let _etag = c.int::<i32>("a node block's entity")?;
        let parametric = c.count("a node block's parametric flag")?;
        let n = c.count("a node block's size")?;
        check_count(c, n, "node")?;
        let tags: Vec<usize> = (0..n)
            .map(|_| c.count("a node tag"))
            .collect::<Result<_>>()?;
        for tag in tags {
            let x = c.float("a node's x")?;
            let y = c.float("a node's y")?;
            let _z = c.float("a node's z")?;
            if parametric != 0 {
                return Err(c.err(
                    "parametric node coordinates are not supported (Mesh.SaveParametric = 0)",
                ));
            }
            if node_index.insert(tag, mesh.nodes.len()).is_some() {
                return Err(c.err(format!("node tag {tag} appears twice")));
            }
            if dim == 0 {
                mesh.points.push(mesh.nodes.len());
            }
            mesh.nodes.push([x, y]);
        }
    }
    if mesh.nodes.len() != nnodes {
        return Err(c.err(format!(
            "header announces {nnodes} nodes, blocks hold {}",
            mesh.nodes.len()
        )));
    }
    c.end("$EndNodes")
}

fn read_elements(
    c: &mut Cursor,
    mesh: &mut RawMesh,
    physicals: &EntityPhysicals<i32>,
    node_index: &HashMap<usize, usize>,
) -> Result<()> {
    c.section = "$Elements".into();
    let nblocks = c.count("the number of element blocks")?;
    let _nel = c.count("the number of elements")?;
    let _min = c.count("the smallest element tag")?;
    let _max = c.count("the largest element tag")?;
    for _ in 0..nblocks {
        let dim = c.count("an element block's dimension")?;
        let etag = c.int::<i32>("an element block's entity")?;
        let etype = c.count("an element block's type")?;
        let n = c.count("an element block's size")?;
        check_count(c, n, "element")?;
        let nper = match etype {
            15 => 1,
            1 => 2,
            2 => 3,
            other => {
                return Err(c.err(format!(
                    "element type {other} is not supported (only points, 2-node lines and 3-node triangles: use first-order meshes)"
                )));
            }
        };
        let phys = physicals.get(&(dim, etag)).cloned().unwrap_or_default();
        for _ in 0..n {
            let _tag = c.count("an element tag")?;
            let mut ids = [0usize; 3];
            for id in ids.iter_mut().take(nper) {
                let tag = c.count("an element's node tag")?;
                *id = *node_index
                    .get(&tag)
                    .ok_or_else(|| c.err(format!("element refers to unknown node {tag}")))?;
            }
            for &p in &phys {
                match etype {
                    1 => mesh.lines.push(([ids[0], ids[1]], p)),
                    2 => mesh.triangles.push(([ids[0], ids[1], ids[2]], p)),
                    _ => {}
                }
            }
        }
    }
    c.end("$EndElements")
}
