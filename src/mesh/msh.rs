//! Reader for gmsh's MSH 4.1 ASCII format: nodes, 2-node lines, 3-node triangles and
//! physical groups by name.
//!
//! Written by hand because the maintained reader (mshio 0.4) ignores `$PhysicalNames`,
//! which is how scenes refer to bodies and boundary parts; the subset used here is small.

use crate::error::{Error, Result};
use std::collections::HashMap;
use std::path::Path;

/// Where a mesh's physical groups are named, for errors: the scene file whose fields name
/// them, and the .geo that defines them.
#[derive(Debug, Clone, Copy)]
pub struct MeshSource<'a> {
    /// The scene file.
    pub scene: &'a Path,
    /// The .geo meshed.
    pub geo: &'a Path,
}

impl MeshSource<'_> {
    /// Bad input at the scene file's `field`.
    pub fn error(&self, field: &str, message: String) -> Error {
        Error::input(self.scene, field, message)
    }
}

/// A mesh as gmsh wrote it: all nodes, and the elements that belong to physical groups.
#[derive(Debug, Clone, Default)]
pub struct RawMesh {
    /// Node coordinates (x, y), indexed by position (gmsh tags mapped to 0..n).
    pub nodes: Vec<[f64; 2]>,
    /// Triangles (node indices, counter-clockwise not guaranteed) with their physical tag.
    pub triangles: Vec<([usize; 3], i32)>,
    /// 2-node boundary lines with their physical tag.
    pub lines: Vec<([usize; 2], i32)>,
    /// Physical names by (dimension, tag).
    pub physical_names: HashMap<(usize, i32), String>,
}

impl RawMesh {
    /// The tag of the physical group of dimension `dim` named `name`, if any.
    pub fn physical_tag(&self, dim: usize, name: &str) -> Option<i32> {
        self.physical_names
            .iter()
            .find(|((d, _), n)| *d == dim && n.as_str() == name)
            .map(|((_, t), _)| *t)
    }

    /// The tag of the physical curve `name`, or an error naming the scene file and its
    /// field `field` that names the curve, the .geo, the curves the mesh has, and the fix.
    pub fn require_curve(&self, name: &str, source: &MeshSource, field: &str) -> Result<i32> {
        self.physical_tag(1, name).ok_or_else(|| {
            source.error(
                field,
                format!(
                    "the mesh of {} has no physical curve named '{name}'; its curves are {}; fix: name one of them in {field}, or add `Physical Curve(\"{name}\")` to the .geo",
                    source.geo.display(),
                    self.names_of_dim(1).join(", ")
                ),
            )
        })
    }

    /// A mesh made of body `surfaces[0]` as meshed in `a` and body `surfaces[1]` as meshed in
    /// `b` (two levels of one family, the bodies refined independently): their triangles
    /// and the boundary lines on their nodes, `b`'s nodes numbered after `a`'s. The bodies
    /// of a non-matching family share no node, so each line belongs to one body and the
    /// result is the mesh gmsh would give with those two sizes, without a new gmsh run.
    pub fn combine_bodies(a: &RawMesh, b: &RawMesh, surfaces: [&str; 2]) -> RawMesh {
        let mut out = RawMesh {
            physical_names: a.physical_names.clone(),
            ..Default::default()
        };
        for (raw, surface) in [(a, surfaces[0]), (b, surfaces[1])] {
            let offset = out.nodes.len();
            out.nodes.extend_from_slice(&raw.nodes);
            let tag = raw.physical_tag(2, surface);
            let mut on_body = vec![false; raw.nodes.len()];
            for (t, p) in &raw.triangles {
                if Some(*p) == tag {
                    out.triangles.push((t.map(|n| n + offset), *p));
                    for &n in t {
                        on_body[n] = true;
                    }
                }
            }
            for (l, p) in &raw.lines {
                if l.iter().all(|&n| on_body[n]) {
                    out.lines.push((l.map(|n| n + offset), *p));
                }
            }
        }
        out
    }

    /// Sorted names of the physical groups of dimension `dim`.
    pub fn names_of_dim(&self, dim: usize) -> Vec<String> {
        let mut v: Vec<String> = self
            .physical_names
            .iter()
            .filter(|((d, _), _)| *d == dim)
            .map(|(_, n)| n.clone())
            .collect();
        v.sort();
        v
    }
}

struct Tokens<'a> {
    it: std::iter::Peekable<std::str::SplitWhitespace<'a>>,
    path: &'a Path,
    section: &'static str,
}

impl<'a> Tokens<'a> {
    fn err(&self, msg: impl Into<String>) -> Error {
        Error::input(
            self.path,
            self.section,
            format!(
                "{}; the file is not a valid gmsh MSH 4.1 ASCII mesh: delete it and let the program regenerate it",
                msg.into()
            ),
        )
    }
    fn next_str(&mut self) -> Result<&'a str> {
        self.it
            .next()
            .ok_or_else(|| self.err("unexpected end of file"))
    }
    fn usize(&mut self) -> Result<usize> {
        let s = self.next_str()?;
        s.parse()
            .map_err(|_| self.err(format!("expected a non-negative integer, found '{s}'")))
    }
    fn i32(&mut self) -> Result<i32> {
        let s = self.next_str()?;
        s.parse()
            .map_err(|_| self.err(format!("expected an integer, found '{s}'")))
    }
    fn f64(&mut self) -> Result<f64> {
        let s = self.next_str()?;
        let v: f64 = s
            .parse()
            .map_err(|_| self.err(format!("expected a number, found '{s}'")))?;
        if !v.is_finite() {
            return Err(self.err(format!("non-finite coordinate '{s}'")));
        }
        Ok(v)
    }
    fn expect(&mut self, what: &str) -> Result<()> {
        let s = self.next_str()?;
        if s != what {
            return Err(self.err(format!("expected '{what}', found '{s}'")));
        }
        Ok(())
    }
}

/// Guard against absurd counts in corrupted files before allocating.
fn check_count(t: &Tokens, n: usize, what: &str) -> Result<()> {
    if n > 200_000_000 {
        return Err(t.err(format!("{what} count {n} is not plausible")));
    }
    Ok(())
}

/// Read a MSH 4.1 ASCII file.
pub fn read_msh(path: &Path) -> Result<RawMesh> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    parse_msh(&text, path)
}

/// Physical tags of each (dimension, entity tag), from `$Entities`.
type EntityPhysicals = HashMap<(usize, i32), Vec<i32>>;

/// Parse the text of a MSH 4.1 ASCII file; `path` is used in error messages only.
pub fn parse_msh(text: &str, path: &Path) -> Result<RawMesh> {
    let mut mesh = RawMesh::default();
    let rest = take_physical_names(text, path, &mut mesh.physical_names)?;
    let mut entity_physicals = EntityPhysicals::new();
    let mut node_index: HashMap<usize, usize> = HashMap::new();
    let (mut have_format, mut have_nodes, mut have_elements) = (false, false, false);
    let mut t = Tokens {
        it: rest.split_whitespace().peekable(),
        path,
        section: "$MeshFormat",
    };
    while let Some(tok) = t.it.next() {
        match tok {
            "$MeshFormat" => {
                read_format(&mut t)?;
                have_format = true;
            }
            "$Entities" => read_entities(&mut t, &mut entity_physicals)?,
            "$Nodes" => {
                read_nodes(&mut t, &mut mesh, &mut node_index)?;
                have_nodes = true;
            }
            "$Elements" => {
                read_elements(&mut t, &mut mesh, &entity_physicals, &node_index)?;
                have_elements = true;
            }
            s if s.starts_with("$") && !s.starts_with("$End") => skip_section(&mut t, s)?,
            other => return Err(t.err(format!("unexpected token '{other}'"))),
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

fn read_format(t: &mut Tokens) -> Result<()> {
    t.section = "$MeshFormat";
    let version = t.next_str()?;
    if version != "4.1" {
        return Err(t.err(format!(
            "version {version} is not supported (need 4.1: run gmsh with -format msh41)"
        )));
    }
    let file_type = t.usize()?;
    if file_type != 0 {
        return Err(t.err("binary MSH is not supported (need ASCII: run gmsh with -bin 0)"));
    }
    let _data_size = t.usize()?;
    t.expect("$EndMeshFormat")
}

/// A count of physical tags followed by the tags.
fn read_physical_tags(t: &mut Tokens) -> Result<Vec<i32>> {
    let n = t.usize()?;
    check_count(t, n, "physical tag")?;
    (0..n).map(|_| t.i32()).collect()
}

fn read_entities(t: &mut Tokens, physicals: &mut EntityPhysicals) -> Result<()> {
    t.section = "$Entities";
    let np = t.usize()?;
    let nc = t.usize()?;
    let ns = t.usize()?;
    let nv = t.usize()?;
    for _ in 0..np {
        let tag = t.i32()?;
        for _ in 0..3 {
            t.f64()?;
        }
        physicals.insert((0, tag), read_physical_tags(t)?);
    }
    for (dim, n) in [(1usize, nc), (2, ns), (3, nv)] {
        for _ in 0..n {
            let tag = t.i32()?;
            for _ in 0..6 {
                t.f64()?;
            }
            physicals.insert((dim, tag), read_physical_tags(t)?);
            let nb = t.usize()?;
            check_count(t, nb, "bounding entity")?;
            for _ in 0..nb {
                t.i32()?;
            }
        }
    }
    t.expect("$EndEntities")
}

fn read_nodes(
    t: &mut Tokens,
    mesh: &mut RawMesh,
    node_index: &mut HashMap<usize, usize>,
) -> Result<()> {
    t.section = "$Nodes";
    let nblocks = t.usize()?;
    let nnodes = t.usize()?;
    check_count(t, nnodes, "node")?;
    let _min = t.usize()?;
    let _max = t.usize()?;
    mesh.nodes.reserve(nnodes);
    for _ in 0..nblocks {
        let _dim = t.usize()?;
        let _etag = t.i32()?;
        let parametric = t.usize()?;
        let n = t.usize()?;
        check_count(t, n, "node")?;
        let tags: Vec<usize> = (0..n).map(|_| t.usize()).collect::<Result<_>>()?;
        for tag in tags {
            let x = t.f64()?;
            let y = t.f64()?;
            let _z = t.f64()?;
            if parametric != 0 {
                return Err(t.err(
                    "parametric node coordinates are not supported (Mesh.SaveParametric = 0)",
                ));
            }
            if node_index.insert(tag, mesh.nodes.len()).is_some() {
                return Err(t.err(format!("node tag {tag} appears twice")));
            }
            mesh.nodes.push([x, y]);
        }
    }
    if mesh.nodes.len() != nnodes {
        return Err(t.err(format!(
            "header announces {nnodes} nodes, blocks hold {}",
            mesh.nodes.len()
        )));
    }
    t.expect("$EndNodes")
}

fn read_elements(
    t: &mut Tokens,
    mesh: &mut RawMesh,
    physicals: &EntityPhysicals,
    node_index: &HashMap<usize, usize>,
) -> Result<()> {
    t.section = "$Elements";
    let nblocks = t.usize()?;
    let _nel = t.usize()?;
    let _min = t.usize()?;
    let _max = t.usize()?;
    for _ in 0..nblocks {
        let dim = t.usize()?;
        let etag = t.i32()?;
        let etype = t.usize()?;
        let n = t.usize()?;
        check_count(t, n, "element")?;
        let nper = match etype {
            15 => 1,
            1 => 2,
            2 => 3,
            other => {
                return Err(t.err(format!(
                    "element type {other} is not supported (only points, 2-node lines and 3-node triangles: use first-order meshes)"
                )));
            }
        };
        let phys = physicals.get(&(dim, etag)).cloned().unwrap_or_default();
        for _ in 0..n {
            let _tag = t.usize()?;
            let mut ids = [0usize; 3];
            for id in ids.iter_mut().take(nper) {
                let tag = t.usize()?;
                *id = *node_index
                    .get(&tag)
                    .ok_or_else(|| t.err(format!("element refers to unknown node {tag}")))?;
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
    t.expect("$EndElements")
}

/// Skip an unknown section ($Periodic, $NodeData, ...) up to its end marker.
fn skip_section(t: &mut Tokens, start: &str) -> Result<()> {
    let end = format!("$End{}", &start[1..]);
    loop {
        match t.it.next() {
            Some(x) if x == end => return Ok(()),
            Some(_) => {}
            None => return Err(t.err(format!("section {start} is not closed"))),
        }
    }
}
