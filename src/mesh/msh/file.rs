//! The reader of an ASCII MSH file another code wrote (gmsh, meshio, ...), 4.1 or 2.2: its
//! physical names, entities, nodes, 2D elements of any type, and the views asked for by
//! name ([`super::views`]). What to make of them is the caller's (`io::solution` grades a
//! solution); errors name the section and its line, and say to write the file again.

use super::cursor::{Cursor, Voice};
use super::read_entities;
use super::views::{View, ViewHeader, read_view};
use crate::error::{Error, Result};
use std::collections::HashMap;
use std::path::Path;

/// The MSH versions read.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum MshVersion {
    /// MSH 2.2.
    V22,
    /// MSH 4.1.
    V41,
}

/// A 2D element of the file.
pub struct SurfaceElement {
    /// Its tag.
    pub tag: u64,
    /// gmsh's element type (2 for the 3-node triangle).
    pub etype: usize,
    /// Its nodes (indices into [`MshFile::nodes`]).
    pub nodes: Vec<usize>,
    /// Its physical tags.
    pub physicals: Vec<i64>,
}

/// What an ASCII MSH file holds, the views limited to those asked for.
pub struct MshFile {
    /// The version read.
    pub version: MshVersion,
    /// (dimension, tag, name) of each physical group named.
    pub physical_names: Vec<(usize, i64, String)>,
    /// Physical tags by (dimension, entity tag), from `$Entities` (4.1).
    pub entities: Option<HashMap<(usize, i64), Vec<i64>>>,
    /// Node coordinates (x, y, z), in the file's order.
    pub nodes: Vec<[f64; 3]>,
    /// The tag of each node.
    pub node_tags: Vec<u64>,
    /// The 2D elements.
    pub surface_elements: Vec<SurfaceElement>,
    /// The views asked for, in the file's order.
    pub views: Vec<View>,
    /// Every view's header, asked for or not, in the file's order.
    pub headers: Vec<ViewHeader>,
}

/// The refusal of a binary MSH, with the conversions to ASCII.
fn binary_msh(path: &Path) -> Error {
    Error::input(
        path,
        "$MeshFormat",
        "the file is a binary MSH; ASCII MSH (4.1 or 2.2) is read: convert it with `gmsh file.msh -save -format msh41` with `Mesh.Binary = 0` (`-setnumber Mesh.Binary 0`), or write it with meshio's `file_format=\"gmsh\"` and `binary=False`",
    )
}

/// Whether the text starting a file announces a binary MSH (`$MeshFormat`, a version, 1).
fn announces_binary(prefix: &str) -> bool {
    prefix.find("$MeshFormat").is_some_and(|i| {
        let mut t = prefix[i + "$MeshFormat".len()..].split_whitespace();
        t.next().is_some() && t.next() == Some("1")
    })
}

/// Read the bytes of an ASCII MSH file: the mesh, and the views named in `wanted`; `path`
/// names the file in errors only.
pub fn parse_msh_file(bytes: &[u8], path: &Path, wanted: &[&str]) -> Result<MshFile> {
    let text = match std::str::from_utf8(bytes) {
        Ok(t) => t,
        Err(e) => {
            let prefix = std::str::from_utf8(&bytes[..e.valid_up_to()]).unwrap_or("");
            if announces_binary(prefix) {
                return Err(binary_msh(path));
            }
            return Err(Error::input(
                path,
                "file",
                format!(
                    "not text (byte {} is not UTF-8): give gmsh's ASCII MSH file (4.1 or 2.2)",
                    e.valid_up_to()
                ),
            ));
        }
    };
    parse_text(text, path, wanted)
}

/// Read the text of an ASCII MSH file, section by section.
fn parse_text(text: &str, path: &Path, wanted: &[&str]) -> Result<MshFile> {
    let mut c = Cursor::new(text, path, "file", Voice::Outside);
    let mut file = MshFile {
        version: MshVersion::V41,
        physical_names: Vec::new(),
        entities: None,
        nodes: Vec::new(),
        node_tags: Vec::new(),
        surface_elements: Vec::new(),
        views: Vec::new(),
        headers: Vec::new(),
    };
    let mut node_index: HashMap<u64, usize> = HashMap::new();
    let (mut format_seen, mut nodes_seen, mut elements_seen) = (false, false, false);
    while let Some(tok) = c.token() {
        // A section's errors name it; a stray token names the file and its line.
        c.section = if tok.starts_with('$') { tok } else { "file" }.to_string();
        if !format_seen && tok != "$MeshFormat" {
            return Err(c.err(format!(
                "the file starts with '{tok}', not $MeshFormat: give gmsh's MSH file (ASCII 4.1 or 2.2)"
            )));
        }
        match tok {
            "$MeshFormat" => {
                file.version = read_format(&mut c)?;
                format_seen = true;
            }
            "$PhysicalNames" => read_physical_names(&mut c, &mut file)?,
            "$Entities" if file.version == MshVersion::V41 => {
                file.entities = Some(read_entities(&mut c, |_, _, _| Ok(()))?);
            }
            "$Nodes" => {
                read_nodes(&mut c, &mut file, &mut node_index)?;
                nodes_seen = true;
            }
            "$Elements" => {
                read_elements(&mut c, &mut file, &node_index)?;
                elements_seen = true;
            }
            "$NodeData" | "$ElementData" => {
                let (header, view) = read_view(&mut c, tok == "$ElementData", wanted)?;
                file.headers.push(header);
                file.views.extend(view);
            }
            s if s.starts_with('$') && !s.starts_with("$End") => c.skip(s)?,
            other => {
                return Err(c.err(format!(
                    "'{other}' between sections: the counts of the section before do not match its lines; write the file again"
                )));
            }
        }
    }
    if !format_seen || !nodes_seen || !elements_seen {
        return Err(Error::input(
            path,
            "file",
            "$MeshFormat, $Nodes or $Elements is missing (an empty or truncated file?): give the MSH file with the mesh and the solution's views",
        ));
    }
    Ok(file)
}

/// `$MeshFormat` (its marker read): the version, which must be ASCII 4.1 or 2.2.
fn read_format(c: &mut Cursor) -> Result<MshVersion> {
    let version = match c.next("the version")? {
        "4.1" => MshVersion::V41,
        "2.2" => MshVersion::V22,
        other => {
            return Err(c.err(format!(
                "MSH version {other}; versions 4.1 and 2.2 are read: write the file with `gmsh file.msh -save -format msh41` (or msh22), or meshio's file_format=\"gmsh\" (4.1) or \"gmsh22\""
            )));
        }
    };
    let binary = c.next("the file type")?;
    if binary != "0" {
        return Err(binary_msh(c.path()));
    }
    c.count("the data size")?;
    c.end("$EndMeshFormat")?;
    Ok(version)
}

/// `$PhysicalNames` (its marker read): (dimension, tag, name) of each group.
fn read_physical_names(c: &mut Cursor, file: &mut MshFile) -> Result<()> {
    let n = c.count("the number of physical names")?;
    for _ in 0..n {
        let dim = c.count("a physical group's dimension")?;
        let tag = c.int("a physical tag")?;
        let name = c.string("a physical name")?;
        file.physical_names.push((dim, tag, name));
    }
    c.end("$EndPhysicalNames")
}

/// Nodes and dimension of gmsh's element types 1 to 31.
fn element_shape(etype: usize) -> Option<(usize, usize)> {
    const SHAPES: [(usize, usize); 31] = [
        (2, 1),
        (3, 2),
        (4, 2),
        (4, 3),
        (8, 3),
        (6, 3),
        (5, 3),
        (3, 1),
        (6, 2),
        (9, 2),
        (10, 3),
        (27, 3),
        (18, 3),
        (14, 3),
        (1, 0),
        (8, 2),
        (20, 3),
        (15, 3),
        (13, 3),
        (9, 2),
        (10, 2),
        (12, 2),
        (15, 2),
        (15, 2),
        (21, 2),
        (4, 1),
        (5, 1),
        (6, 1),
        (20, 3),
        (35, 3),
        (56, 3),
    ];
    etype.checked_sub(1).and_then(|i| SHAPES.get(i).copied())
}

/// `$Nodes` (its marker read), in the file's version.
fn read_nodes(c: &mut Cursor, file: &mut MshFile, index: &mut HashMap<u64, usize>) -> Result<()> {
    let mut add = |c: &Cursor, file: &mut MshFile, tag: u64, xyz: [f64; 3]| -> Result<()> {
        if index.insert(tag, file.nodes.len()).is_some() {
            return Err(c.err(format!(
                "node tag {tag} appears twice: write the file again"
            )));
        }
        file.nodes.push(xyz);
        file.node_tags.push(tag);
        Ok(())
    };
    let xyz = |c: &mut Cursor| -> Result<[f64; 3]> {
        Ok([
            c.float("a node's x")?,
            c.float("a node's y")?,
            c.float("a node's z")?,
        ])
    };
    match file.version {
        MshVersion::V22 => {
            let n = c.count("the number of nodes")?;
            for _ in 0..n {
                let tag: u64 = c.parsed("a node tag", "a node tag")?;
                let p = xyz(c)?;
                add(c, file, tag, p)?;
            }
        }
        MshVersion::V41 => {
            let blocks = c.count("the number of node blocks")?;
            let total = c.count("the number of nodes")?;
            c.count("the smallest node tag")?;
            c.count("the largest node tag")?;
            let before = file.nodes.len();
            for _ in 0..blocks {
                let dim = c.count("a node block's dimension")?;
                c.int::<i64>("a node block's entity")?;
                let parametric = c.count("a node block's parametric flag")?;
                let n = c.count("a node block's size")?;
                // Tags first, then coordinates: read the tags as they come, bounded by the
                // text (not by the count).
                let mut tags = Vec::new();
                for _ in 0..n {
                    tags.push(c.parsed::<u64>("a node tag", "a node tag")?);
                }
                for tag in tags {
                    let p = xyz(c)?;
                    if parametric != 0 {
                        for _ in 0..dim.min(2) {
                            c.float("a parametric coordinate")?;
                        }
                    }
                    add(c, file, tag, p)?;
                }
            }
            if file.nodes.len() - before != total {
                return Err(c.err(format!(
                    "the header announces {total} nodes, the blocks hold {}: write the file again",
                    file.nodes.len() - before
                )));
            }
        }
    }
    c.end("$EndNodes")
}

/// `$Elements` (its marker read), in the file's version: the 2D elements are kept.
fn read_elements(c: &mut Cursor, file: &mut MshFile, index: &HashMap<u64, usize>) -> Result<()> {
    let shape = |c: &Cursor, etype: usize| {
        element_shape(etype).ok_or_else(|| {
            c.err(format!(
                "element type {etype} is not one of gmsh's types 1 to 31: write the file again"
            ))
        })
    };
    // Read an element's node tags; keep the element if it is 2D.
    let element = |c: &mut Cursor,
                   file: &mut MshFile,
                   tag: u64,
                   etype: usize,
                   dim: usize,
                   physicals: Vec<i64>|
     -> Result<()> {
        let (n, _) = shape(c, etype)?;
        let mut nodes = Vec::new();
        for _ in 0..n {
            let t: u64 = c.parsed("an element's node tag", "a node tag")?;
            if dim == 2 {
                nodes.push(*index.get(&t).ok_or_else(|| {
                    c.err(format!(
                        "element {tag} refers to node {t}, which $Nodes does not list: write the file again"
                    ))
                })?);
            }
        }
        if dim == 2 {
            file.surface_elements.push(SurfaceElement {
                tag,
                etype,
                nodes,
                physicals,
            });
        }
        Ok(())
    };
    match file.version {
        MshVersion::V22 => {
            let n = c.count("the number of elements")?;
            for _ in 0..n {
                let tag: u64 = c.parsed("an element tag", "an element tag")?;
                let etype = c.count("an element type")?;
                let ntags = c.count("the number of element tags")?;
                let mut tags = Vec::new();
                for _ in 0..ntags {
                    tags.push(c.int::<i64>("an element tag")?);
                }
                // The first tag is the physical group, the second the elementary entity.
                let physicals = tags.first().map(|&p| vec![p]).unwrap_or_default();
                let (_, dim) = shape(c, etype)?;
                element(c, file, tag, etype, dim, physicals)?;
            }
        }
        MshVersion::V41 => {
            let blocks = c.count("the number of element blocks")?;
            c.count("the number of elements")?;
            c.count("the smallest element tag")?;
            c.count("the largest element tag")?;
            for _ in 0..blocks {
                let dim = c.count("an element block's dimension")?;
                let entity = c.int::<i64>("an element block's entity")?;
                let etype = c.count("an element block's type")?;
                let n = c.count("an element block's size")?;
                shape(c, etype)?;
                let physicals = file
                    .entities
                    .as_ref()
                    .and_then(|e| e.get(&(dim, entity)).cloned())
                    .unwrap_or_default();
                for _ in 0..n {
                    let tag: u64 = c.parsed("an element tag", "an element tag")?;
                    element(c, file, tag, etype, dim, physicals.clone())?;
                }
            }
        }
    }
    c.end("$EndElements")
}
