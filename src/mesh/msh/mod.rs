//! gmsh's MSH format, read and written in one place:
//!
//! - [`cursor`]: the tokenizer both readers share (tokens with their line, numbers, quoted
//!   strings, end markers, skipped sections), wording refusals in the reader's voice;
//! - [`read`]: the reader of the project's own meshes, MSH 4.1 as gmsh writes it for a
//!   scene, into a [`RawMesh`] (nodes, 2-node lines, 3-node triangles, physical groups by
//!   name);
//! - [`file`] and [`views`]: the reader of any ASCII MSH 4.1 or 2.2 file with its
//!   `$NodeData`/`$ElementData` views, for the solution another code wrote
//!   (`io::solution` makes the solution of it);
//! - [`write`]: the writer of a two-body mesh with its physical groups, MSH 4.1 and 2.2,
//!   for the codes `export` writes a problem for.
//!
//! The two readers keep their own section readers (but for `$Entities`, read alike here):
//! the cache's is strict (4.1, first order, no parametric nodes) and its fix is to
//! regenerate the mesh; an outside file may be 4.1 or 2.2, of any element type, and its
//! fix is to write it again, with the line named.
//!
//! Written by hand: the maintained crate (mshio 0.4.2) reads MSH 4.1 only, not 2.2, and
//! neither `$PhysicalNames` (how scenes refer to bodies and boundary parts) nor the views
//! that carry a solution; and it does not write MSH.

pub mod cursor;
pub mod file;
pub mod read;
pub mod views;
pub mod write;

use crate::error::{Error, Result};
use cursor::Cursor;
use std::collections::HashMap;
use std::hash::Hash;
use std::path::Path;
use std::str::FromStr;

pub use read::{parse_msh, read_msh};
pub use write::{ExportMesh, PhysicalGroup};

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
    /// The nodes of the geometry's points (gmsh's node blocks of dimension 0): the ends and
    /// the named points of the curves, nodes of every level (LAC's macro-elements end there).
    pub points: Vec<usize>,
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
            out.points.extend(
                raw.points
                    .iter()
                    .filter(|&&n| on_body[n])
                    .map(|n| n + offset),
            );
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

/// Physical tags of each (dimension, entity tag), from `$Entities`.
pub type EntityPhysicals<T> = HashMap<(usize, T), Vec<T>>;

/// `$Entities` (MSH 4.1, its marker read): the physical tags of each (dimension, entity),
/// tags of type `T`. `plausible(cursor, n, what)` checks a count of physical tags or of
/// bounding entities before they are read (the cache's reader bounds them; an outside
/// file's are bounded by its text).
pub fn read_entities<T: FromStr + Eq + Hash>(
    c: &mut Cursor,
    plausible: impl Fn(&Cursor, usize, &str) -> Result<()>,
) -> Result<EntityPhysicals<T>> {
    let mut out = HashMap::new();
    let counts = [
        c.count("the number of points")?,
        c.count("the number of curves")?,
        c.count("the number of surfaces")?,
        c.count("the number of volumes")?,
    ];
    for (dim, n) in counts.into_iter().enumerate() {
        for _ in 0..n {
            let tag: T = c.int("an entity tag")?;
            for _ in 0..if dim == 0 { 3 } else { 6 } {
                c.float("an entity's coordinates")?;
            }
            let np = c.count("the number of physical tags")?;
            plausible(c, np, "physical tag")?;
            let mut physicals = Vec::new();
            for _ in 0..np {
                physicals.push(c.int("a physical tag")?);
            }
            out.insert((dim, tag), physicals);
            if dim > 0 {
                let nb = c.count("the number of bounding entities")?;
                plausible(c, nb, "bounding entity")?;
                for _ in 0..nb {
                    c.int::<T>("a bounding entity")?;
                }
            }
        }
    }
    c.end("$EndEntities")?;
    Ok(out)
}
