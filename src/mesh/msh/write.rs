//! The mesh of both bodies as gmsh's MSH files, for codes this project did not write: MSH 4.1
//! (gmsh's current format) and MSH 2.2 (for readers that know only the older one, GetFEM 5.4
//! among them), with the scene's physical names (the bodies, every support, traction and
//! contact curve).
//!
//! Node tags are the model's global node numbers plus 1 (body 1's nodes first), triangle
//! tags the model's element numbers plus 1, so loads_L.csv and source_L.csv refer to them.
//! The two bodies share no node, also where they touch: an importer that merges coincident
//! points would glue them at the ends of Gamma_C.
//!
//! Written by hand: the two formats' ASCII forms are a few lines each, and the maintained
//! crate (mshio) reads MSH but does not write it.

use std::fmt::Write as _;

/// A physical group: gmsh's dimension (1 curve, 2 surface), its tag and name, and its
/// elements (node numbers of the model, from 0).
pub struct PhysicalGroup {
    pub dim: usize,
    pub tag: usize,
    pub name: String,
    pub elements: Vec<Vec<usize>>,
}

/// The mesh of two bodies with their physical groups: the two bodies (tags 1 and 2, in the
/// scene's order) and every physical curve of the mesh (tags from 3, by name); made from a
/// model by `external::export`.
pub struct ExportMesh {
    /// Node coordinates by global node number (length units of the scene).
    pub nodes: Vec<[f64; 2]>,
    /// The node numbers of each body: contiguous, body 1's first.
    pub body_nodes: [std::ops::Range<usize>; 2],
    /// Bodies first, then curves.
    pub groups: Vec<PhysicalGroup>,
}

impl ExportMesh {
    /// The body (0 or 1) whose nodes carry the physical curve `name`, if the mesh has it.
    pub fn body_of_curve(&self, name: &str) -> Option<usize> {
        let g = self.groups.iter().find(|g| g.dim == 1 && g.name == name)?;
        let n = *g.elements.first()?.first()?;
        Some(usize::from(n >= self.body_nodes[1].start))
    }

    fn physical_names(&self, out: &mut String) {
        let _ = writeln!(out, "$PhysicalNames\n{}", self.groups.len());
        for g in &self.groups {
            let _ = writeln!(out, "{} {} \"{}\"", g.dim, g.tag, g.name);
        }
        out.push_str("$EndPhysicalNames\n");
    }

    /// gmsh's element type of a group's elements: 1 (2-node line) or 2 (3-node triangle).
    fn element_type(g: &PhysicalGroup) -> usize {
        if g.dim == 1 { 1 } else { 2 }
    }

    /// The bounding box of a group's nodes: min x, min y, 0, max x, max y, 0.
    fn bounding_box(&self, g: &PhysicalGroup) -> String {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for &n in g.elements.iter().flatten() {
            for c in 0..2 {
                lo[c] = lo[c].min(self.nodes[n][c]);
                hi[c] = hi[c].max(self.nodes[n][c]);
            }
        }
        format!("{:e} {:e} 0 {:e} {:e} 0", lo[0], lo[1], hi[0], hi[1])
    }

    /// MSH 4.1, ASCII: one entity per physical group (surfaces 1, 2 the bodies; curves
    /// numbered from 1), the nodes in one block per body, the elements in one block per group
    /// (triangles first, so that their tags are the model's element numbers plus 1).
    pub fn msh41(&self) -> String {
        let mut out = String::from("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n");
        self.physical_names(&mut out);
        let (surfaces, curves): (Vec<&PhysicalGroup>, Vec<&PhysicalGroup>) =
            self.groups.iter().partition(|g| g.dim == 2);
        let _ = writeln!(out, "$Entities\n0 {} {} 0", curves.len(), surfaces.len());
        for (i, g) in curves.iter().enumerate() {
            let _ = writeln!(out, "{} {} 1 {} 0", i + 1, self.bounding_box(g), g.tag);
        }
        for g in &surfaces {
            let _ = writeln!(out, "{} {} 1 {} 0", g.tag, self.bounding_box(g), g.tag);
        }
        out.push_str("$EndEntities\n");
        // Nodes: a block per body (its nodes are contiguous in the model's numbering).
        let bodies = &self.body_nodes;
        let _ = writeln!(out, "$Nodes\n2 {} 1 {}", self.nodes.len(), self.nodes.len());
        for (b, range) in bodies.iter().enumerate() {
            let _ = writeln!(out, "2 {} 0 {}", b + 1, range.len());
            for n in range.clone() {
                let _ = writeln!(out, "{}", n + 1);
            }
            for n in range.clone() {
                let _ = writeln!(out, "{:e} {:e} 0", self.nodes[n][0], self.nodes[n][1]);
            }
        }
        out.push_str("$EndNodes\n");
        let total: usize = self.groups.iter().map(|g| g.elements.len()).sum();
        let _ = writeln!(out, "$Elements\n{} {total} 1 {total}", self.groups.len());
        let mut tag = 0;
        for g in surfaces.iter().chain(curves.iter()) {
            let entity = match g.dim {
                2 => g.tag,
                _ => 1 + curves.iter().position(|c| c.tag == g.tag).unwrap_or(0),
            };
            let _ = writeln!(
                out,
                "{} {entity} {} {}",
                g.dim,
                Self::element_type(g),
                g.elements.len()
            );
            for e in &g.elements {
                tag += 1;
                let _ = write!(out, "{tag}");
                for n in e {
                    let _ = write!(out, " {}", n + 1);
                }
                out.push('\n');
            }
        }
        out.push_str("$EndElements\n");
        out
    }

    /// MSH 2.2, ASCII: the same nodes and elements (same tags), each element with its
    /// physical and elementary tag.
    pub fn msh22(&self) -> String {
        let mut out = String::from("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n");
        self.physical_names(&mut out);
        let _ = writeln!(out, "$Nodes\n{}", self.nodes.len());
        for (n, p) in self.nodes.iter().enumerate() {
            let _ = writeln!(out, "{} {:e} {:e} 0", n + 1, p[0], p[1]);
        }
        out.push_str("$EndNodes\n");
        let total: usize = self.groups.iter().map(|g| g.elements.len()).sum();
        let _ = writeln!(out, "$Elements\n{total}");
        let mut tag = 0;
        let ordered = self
            .groups
            .iter()
            .filter(|g| g.dim == 2)
            .chain(self.groups.iter().filter(|g| g.dim == 1));
        for g in ordered {
            for e in &g.elements {
                tag += 1;
                let _ = write!(out, "{tag} {} 2 {} {}", Self::element_type(g), g.tag, g.tag);
                for n in e {
                    let _ = write!(out, " {}", n + 1);
                }
                out.push('\n');
            }
        }
        out.push_str("$EndElements\n");
        out
    }
}
