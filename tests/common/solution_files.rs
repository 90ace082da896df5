//! Writers of the solution files other codes write, for the tests of
//! `contact_rates::io::solution` (tests/test_solution_readers.rs) and its fuzzing
//! (tests/common/fuzz.rs): a VTU writer with every layout VTK has (ascii, inline base64,
//! appended raw or base64; zlib blocks or none; UInt32 or UInt64 headers; either byte
//! order), gmsh's MSH 4.1 and 2.2 with `$NodeData`/`$ElementData` views, and a small
//! two-body solution to write. Independent of the reader: it follows VTK's and gmsh's
//! documented layouts.
#![allow(dead_code)]

use base64::Engine as _;
use base64::engine::general_purpose::STANDARD;
use flate2::{Compression, write::ZlibEncoder};
use std::fmt::Write as _;
use std::io::Write as _;

/// Where a VTU's arrays are written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Encoding {
    /// `format="ascii"`.
    Ascii,
    /// `format="binary"`: inline base64.
    Binary,
    /// `format="appended"` with `<AppendedData encoding="raw">`.
    AppendedRaw,
    /// `format="appended"` with `<AppendedData encoding="base64">`.
    AppendedBase64,
}

impl Encoding {
    /// All encodings.
    pub const ALL: [Encoding; 4] = [
        Encoding::Ascii,
        Encoding::Binary,
        Encoding::AppendedRaw,
        Encoding::AppendedBase64,
    ];
}

/// How a VTU is written.
#[derive(Debug, Clone, Copy)]
pub struct Options {
    pub encoding: Encoding,
    /// zlib blocks (`compressor="vtkZLibDataCompressor"`).
    pub compressed: bool,
    /// UInt64 block headers (else UInt32).
    pub header64: bool,
    /// `byte_order="BigEndian"`.
    pub big_endian: bool,
    /// Uncompressed bytes per zlib block (small, so arrays take several blocks).
    pub block_bytes: usize,
    /// Base64 of an uncompressed array: the header as a stream of its own (else header and
    /// data in one stream, as VTK and meshio write).
    pub separate_header: bool,
}

impl Options {
    /// `encoding`, otherwise VTK's defaults (uncompressed, UInt32 headers, little-endian).
    pub fn new(encoding: Encoding) -> Self {
        Options {
            encoding,
            compressed: false,
            header64: false,
            big_endian: false,
            block_bytes: 40,
            separate_header: false,
        }
    }

    /// A short name of the options, for messages and file names.
    pub fn label(&self) -> String {
        format!(
            "{:?}{}{}{}{}",
            self.encoding,
            if self.compressed { "-zlib" } else { "" },
            if self.header64 { "-u64" } else { "-u32" },
            if self.big_endian { "-be" } else { "" },
            if self.separate_header { "-sep" } else { "" }
        )
    }
}

/// One DataArray: values as f64, written as `vtk_type`.
#[derive(Debug, Clone)]
pub struct Array {
    /// PointData, CellData, Points or Cells.
    pub section: &'static str,
    pub name: String,
    pub vtk_type: &'static str,
    pub components: usize,
    pub values: Vec<f64>,
}

impl Array {
    pub fn new(
        section: &'static str,
        name: &str,
        vtk_type: &'static str,
        components: usize,
        values: Vec<f64>,
    ) -> Self {
        Array {
            section,
            name: name.to_string(),
            vtk_type,
            components,
            values,
        }
    }

    /// The values as bytes of the array's type.
    fn bytes(&self, big_endian: bool) -> Vec<u8> {
        let mut out = Vec::new();
        for &v in &self.values {
            let mut b: Vec<u8> = match self.vtk_type {
                "Float64" => v.to_le_bytes().to_vec(),
                "Float32" => (v as f32).to_le_bytes().to_vec(),
                "Int8" => (v as i8).to_le_bytes().to_vec(),
                "UInt8" => (v as u8).to_le_bytes().to_vec(),
                "Int16" => (v as i16).to_le_bytes().to_vec(),
                "UInt16" => (v as u16).to_le_bytes().to_vec(),
                "Int32" => (v as i32).to_le_bytes().to_vec(),
                "UInt32" => (v as u32).to_le_bytes().to_vec(),
                "Int64" => (v as i64).to_le_bytes().to_vec(),
                "UInt64" => (v as u64).to_le_bytes().to_vec(),
                other => panic!("no VTK type {other}"),
            };
            if big_endian {
                b.reverse();
            }
            out.extend(b);
        }
        out
    }

    /// The values as text.
    fn ascii(&self) -> String {
        let words: Vec<String> = self
            .values
            .iter()
            .map(|&v| match self.vtk_type {
                "Float64" => format!("{v:e}"),
                "Float32" => format!("{:e}", v as f32),
                _ => format!("{}", v as i64),
            })
            .collect();
        words.join(" ")
    }
}

/// A VTU's piece: counts and arrays.
#[derive(Debug, Clone)]
pub struct Vtu {
    pub points: usize,
    pub cells: usize,
    pub arrays: Vec<Array>,
}

/// Header words, in the options' width and byte order.
fn words(w: &[usize], o: &Options) -> Vec<u8> {
    let mut out = Vec::new();
    for &x in w {
        let mut b = if o.header64 {
            (x as u64).to_le_bytes().to_vec()
        } else {
            (x as u32).to_le_bytes().to_vec()
        };
        if o.big_endian {
            b.reverse();
        }
        out.extend(b);
    }
    out
}

/// An array's binary form: (header, data), uncompressed or in zlib blocks.
fn binary(data: &[u8], o: &Options) -> (Vec<u8>, Vec<u8>) {
    if !o.compressed {
        return (words(&[data.len()], o), data.to_vec());
    }
    let blocks: Vec<Vec<u8>> = data
        .chunks(o.block_bytes)
        .map(|c| {
            let mut z = ZlibEncoder::new(Vec::new(), Compression::new(6));
            z.write_all(c).unwrap();
            z.finish().unwrap()
        })
        .collect();
    // VTK writes 0 as the size of a full last block.
    let last = data.len() % o.block_bytes;
    let mut w = vec![blocks.len(), o.block_bytes, last];
    w.extend(blocks.iter().map(Vec::len));
    (words(&w, o), blocks.concat())
}

/// An array's base64: VTK encodes a compressed array's header and blocks as two streams.
fn base64_of(header: &[u8], data: &[u8], o: &Options) -> String {
    if o.compressed || o.separate_header {
        format!("{}{}", STANDARD.encode(header), STANDARD.encode(data))
    } else {
        STANDARD.encode([header, data].concat())
    }
}

impl Vtu {
    /// The array `name` of `section`.
    pub fn array_mut(&mut self, section: &str, name: &str) -> &mut Array {
        self.arrays
            .iter_mut()
            .find(|a| a.section == section && a.name == name)
            .unwrap_or_else(|| panic!("no array {section}/{name}"))
    }

    /// Drop the array `name` of `section`.
    pub fn remove(&mut self, section: &str, name: &str) {
        self.arrays
            .retain(|a| !(a.section == section && a.name == name));
    }

    /// The file's bytes.
    pub fn write(&self, o: &Options) -> Vec<u8> {
        let mut xml = String::from("<?xml version=\"1.0\"?>\n");
        let _ = write!(
            xml,
            "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"{}\" header_type=\"{}\"{}>\n  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n",
            if o.big_endian {
                "BigEndian"
            } else {
                "LittleEndian"
            },
            if o.header64 { "UInt64" } else { "UInt32" },
            if o.compressed {
                " compressor=\"vtkZLibDataCompressor\""
            } else {
                ""
            },
            self.points,
            self.cells
        );
        let mut appended: Vec<u8> = Vec::new();
        for section in ["PointData", "CellData", "Points", "Cells"] {
            let _ = writeln!(xml, "      <{section}>");
            for a in self.arrays.iter().filter(|a| a.section == section) {
                let format = match o.encoding {
                    Encoding::Ascii => "ascii",
                    Encoding::Binary => "binary",
                    _ => "appended",
                };
                let _ = write!(
                    xml,
                    "        <DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"{format}\"",
                    a.vtk_type, a.name, a.components
                );
                let (header, data) = binary(&a.bytes(o.big_endian), o);
                match o.encoding {
                    Encoding::Ascii => {
                        let _ = writeln!(xml, ">\n          {}\n        </DataArray>", a.ascii());
                    }
                    Encoding::Binary => {
                        let _ = writeln!(
                            xml,
                            ">\n          {}\n        </DataArray>",
                            base64_of(&header, &data, o)
                        );
                    }
                    Encoding::AppendedRaw => {
                        let _ = writeln!(xml, " offset=\"{}\"/>", appended.len());
                        appended.extend(header);
                        appended.extend(data);
                    }
                    Encoding::AppendedBase64 => {
                        let _ = writeln!(xml, " offset=\"{}\"/>", appended.len());
                        appended.extend(base64_of(&header, &data, o).into_bytes());
                    }
                }
            }
            let _ = writeln!(xml, "      </{section}>");
        }
        xml.push_str("    </Piece>\n  </UnstructuredGrid>\n");
        let mut file = xml.into_bytes();
        match o.encoding {
            Encoding::AppendedRaw | Encoding::AppendedBase64 => {
                let encoding = if o.encoding == Encoding::AppendedRaw {
                    "raw"
                } else {
                    "base64"
                };
                file.extend(format!("  <AppendedData encoding=\"{encoding}\">\n   _").bytes());
                file.extend(appended);
                file.extend(b"\n  </AppendedData>\n");
            }
            _ => {}
        }
        file.extend(b"</VTKFile>\n");
        file
    }
}

/// A two-body P1 solution: a lower unit square of 4 triangles (body 1) and an upper one of
/// 3 triangles (body 2) on it, non-matching along y = 1; smooth fields of `time`.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
    pub points: Vec<[f64; 2]>,
    pub triangles: Vec<[usize; 3]>,
    pub body: Vec<u8>,
    pub displacement: Vec<[f64; 2]>,
    pub stress: Vec<[f64; 3]>,
    pub pressure: Vec<f64>,
}

/// The solution at `time`.
pub fn two_bodies(time: f64) -> Solution {
    let points: Vec<[f64; 2]> = vec![
        [0.0, 0.0],
        [1.0, 0.0],
        [1.0, 1.0],
        [0.0, 1.0],
        [0.5, 0.5],
        [0.0, 1.0],
        [0.5, 1.0],
        [1.0, 1.0],
        [1.0, 2.0],
        [0.0, 2.0],
    ];
    let triangles = vec![
        [0, 1, 4],
        [1, 2, 4],
        [2, 3, 4],
        [3, 0, 4],
        [5, 6, 9],
        [6, 7, 8],
        [6, 8, 9],
    ];
    let body = vec![1, 1, 1, 1, 2, 2, 2];
    let displacement = points
        .iter()
        .map(|p| {
            [
                0.1 * time * (1.0 + p[0] + 2.0 * p[1]).sin(),
                -0.05 * time * (0.3 + p[0] * p[1]).cos() - 1e-7,
            ]
        })
        .collect();
    let stress = (0..triangles.len())
        .map(|i| {
            let x = i as f64 + time;
            [-(x / 3.0).exp(), 1.0 / (x + 7.0), (x * 0.7).sin() * 1e-3]
        })
        .collect();
    let pressure = points
        .iter()
        .map(|p| {
            if p[1] == 1.0 {
                time * (0.1 + p[0]).sqrt() / 3.0
            } else {
                0.0
            }
        })
        .collect();
    Solution {
        points,
        triangles,
        body,
        displacement,
        stress,
        pressure,
    }
}

impl Solution {
    /// The VTU of the solution with its floats written as `float` (Float64 or Float32):
    /// displacement with a zero z component, stress as 3 components; its cells start with a
    /// line and end with a vertex and a poly-line (boundary cells an exporter writes, body 0
    /// and stress 1e30 there: the reader skips them).
    pub fn vtu(&self, float: &'static str) -> Vtu {
        let np = self.points.len();
        let mut connectivity: Vec<f64> = vec![0.0, 1.0];
        let mut offsets = vec![2.0];
        let mut types = vec![3.0];
        let mut body = vec![0.0];
        let mut stress = vec![1e30, 1e30, 1e30];
        for (t, (b, s)) in self
            .triangles
            .iter()
            .zip(self.body.iter().zip(&self.stress))
        {
            connectivity.extend(t.iter().map(|&n| n as f64));
            offsets.push(connectivity.len() as f64);
            types.push(5.0);
            body.push(*b as f64);
            stress.extend(s);
        }
        for (cell, kind) in [(vec![3.0], 1.0), (vec![5.0, 6.0, 7.0], 4.0)] {
            connectivity.extend(cell);
            offsets.push(connectivity.len() as f64);
            types.push(kind);
            body.push(0.0);
            stress.extend([1e30, 1e30, 1e30]);
        }
        let cells = types.len();
        Vtu {
            points: np,
            cells,
            arrays: vec![
                Array::new(
                    "PointData",
                    "displacement",
                    float,
                    3,
                    self.displacement
                        .iter()
                        .flat_map(|u| [u[0], u[1], 0.0])
                        .collect(),
                ),
                Array::new("PointData", "pressure", float, 1, self.pressure.clone()),
                Array::new("PointData", "normal_jump", float, 1, vec![0.25; np]),
                Array::new("CellData", "body", "Int32", 1, body),
                Array::new("CellData", "stress", float, 3, stress),
                Array::new(
                    "Points",
                    "Points",
                    float,
                    3,
                    self.points.iter().flat_map(|p| [p[0], p[1], 0.0]).collect(),
                ),
                Array::new("Cells", "connectivity", "Int64", 1, connectivity),
                Array::new("Cells", "offsets", "Int64", 1, offsets),
                Array::new("Cells", "types", "UInt8", 1, types),
            ],
        }
    }

    /// The solution as it reads from a file of precision `eps` (f32: every value rounded).
    pub fn rounded_to_f32(&self) -> Solution {
        let r = |v: f64| v as f32 as f64;
        Solution {
            points: self.points.iter().map(|p| p.map(r)).collect(),
            displacement: self.displacement.iter().map(|p| p.map(r)).collect(),
            stress: self.stress.iter().map(|p| p.map(r)).collect(),
            pressure: self.pressure.iter().map(|&p| r(p)).collect(),
            ..self.clone()
        }
    }
}

/// The names of the two bodies' physical surfaces in the MSH files (one with a space).
pub const BODIES: [&str; 2] = ["lower block", "upper"];

/// Node tags of the MSH files: not 1..n, to test the mapping.
pub fn node_tag(i: usize) -> usize {
    101 + 2 * i
}

/// Element tags of the triangles.
pub fn triangle_tag(i: usize) -> usize {
    1001 + i
}

/// One view's text (the same in MSH 4.1 and 2.2).
fn view(
    out: &mut String,
    section: &str,
    name: &str,
    time: f64,
    step: usize,
    components: usize,
    rows: &[(usize, Vec<f64>)],
) {
    let _ = writeln!(
        out,
        "${section}\n1\n\"{name}\"\n1\n{time:e}\n3\n{step}\n{components}\n{}",
        rows.len()
    );
    for (tag, values) in rows {
        let v: Vec<String> = values.iter().map(|x| format!("{x:e}")).collect();
        let _ = writeln!(out, "{tag} {}", v.join(" "));
    }
    let _ = writeln!(out, "$End{section}");
}

/// The views of the steps, last step first (the reader sorts by time): displacement with
/// `u_components` (2 or 3, z = 0), stress as a 3x3 tensor (9) or 3 components, pressure,
/// and a view the reader skips.
fn views(out: &mut String, steps: &[(f64, &Solution)], u_components: usize, tensor: bool) {
    for (k, (time, s)) in steps.iter().enumerate().rev() {
        let u: Vec<(usize, Vec<f64>)> = s
            .displacement
            .iter()
            .enumerate()
            .map(|(i, u)| (node_tag(i), [u[0], u[1], 0.0][..u_components].to_vec()))
            .collect();
        view(out, "NodeData", "displacement", *time, k, u_components, &u);
        let skipped: Vec<(usize, Vec<f64>)> = (0..s.points.len())
            .map(|i| (node_tag(i), vec![1.0]))
            .collect();
        view(out, "NodeData", "von Mises", *time, k, 1, &skipped);
        let sigma: Vec<(usize, Vec<f64>)> = s
            .stress
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let v = if tensor {
                    vec![t[0], t[2], 0.0, t[2], t[1], 0.0, 0.0, 0.0, 0.0]
                } else {
                    t.to_vec()
                };
                (triangle_tag(i), v)
            })
            .collect();
        view(
            out,
            "ElementData",
            "stress",
            *time,
            k,
            if tensor { 9 } else { 3 },
            &sigma,
        );
        let p: Vec<(usize, Vec<f64>)> = s
            .pressure
            .iter()
            .enumerate()
            .map(|(i, &p)| (node_tag(i), vec![p]))
            .collect();
        view(out, "NodeData", "pressure", *time, k, 1, &p);
    }
}

/// The physical names: a curve, and the bodies' surfaces (tags 7 and 8).
fn physical_names(out: &mut String) {
    let _ = writeln!(
        out,
        "$PhysicalNames\n3\n1 3 \"contact\"\n2 7 \"{}\"\n2 8 \"{}\"\n$EndPhysicalNames",
        BODIES[0], BODIES[1]
    );
}

/// gmsh's MSH 4.1 of the steps (same mesh): entities 1 and 2 the bodies' surfaces, curve 5
/// the contact edge, an extra node no element uses, a point element, and per step the views.
pub fn msh41(steps: &[(f64, &Solution)]) -> String {
    let s = steps[0].1;
    let mut out = String::from("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n");
    physical_names(&mut out);
    out.push_str("$Entities\n1 1 2 0\n9 0 0 0 0\n5 0 1 0 1 1 0 1 3 0\n");
    out.push_str("1 0 0 0 1 1 0 1 7 0\n2 0 1 0 1 2 0 1 8 0\n$EndEntities\n");
    let n = s.points.len();
    let _ = writeln!(
        out,
        "$Nodes\n2 {} {} {}\n2 1 0 {n}",
        n + 1,
        node_tag(0),
        node_tag(n)
    );
    for i in 0..n {
        let _ = writeln!(out, "{}", node_tag(i));
    }
    for p in &s.points {
        let _ = writeln!(out, "{:e} {:e} 0", p[0], p[1]);
    }
    let _ = writeln!(out, "0 9 0 1\n{}\n3 3 0\n$EndNodes", node_tag(n));
    let lower: Vec<usize> = (0..s.triangles.len()).filter(|&t| s.body[t] == 1).collect();
    let upper: Vec<usize> = (0..s.triangles.len()).filter(|&t| s.body[t] == 2).collect();
    let _ = writeln!(
        out,
        "$Elements\n4 {} 1 {}\n0 9 15 1\n1 {}\n1 5 1 1\n2 {} {}",
        s.triangles.len() + 2,
        triangle_tag(s.triangles.len() - 1),
        node_tag(n),
        node_tag(3),
        node_tag(2)
    );
    for (entity, list) in [(1, &lower), (2, &upper)] {
        let _ = writeln!(out, "2 {entity} 2 {}", list.len());
        for &t in list {
            let v = s.triangles[t].map(node_tag);
            let _ = writeln!(out, "{} {} {} {}", triangle_tag(t), v[0], v[1], v[2]);
        }
    }
    out.push_str("$EndElements\n");
    views(&mut out, steps, 3, true);
    out
}

/// gmsh's MSH 2.2 of the steps: physical tag first of each element's tags, displacement with
/// 2 components, stress with 3.
pub fn msh22(steps: &[(f64, &Solution)]) -> String {
    let s = steps[0].1;
    let mut out = String::from("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n");
    physical_names(&mut out);
    let n = s.points.len();
    let _ = writeln!(out, "$Nodes\n{}", n + 1);
    for (i, p) in s.points.iter().enumerate() {
        let _ = writeln!(out, "{} {:e} {:e} 0", node_tag(i), p[0], p[1]);
    }
    let _ = writeln!(out, "{} 3 3 0\n$EndNodes", node_tag(n));
    let _ = writeln!(
        out,
        "$Elements\n{}\n1 15 2 0 9 {}\n2 1 2 3 5 {} {}",
        s.triangles.len() + 2,
        node_tag(n),
        node_tag(3),
        node_tag(2)
    );
    for (t, tri) in s.triangles.iter().enumerate() {
        let v = tri.map(node_tag);
        let physical = if s.body[t] == 1 { 7 } else { 8 };
        let _ = writeln!(
            out,
            "{} 2 2 {physical} {} {} {} {}",
            triangle_tag(t),
            s.body[t],
            v[0],
            v[1],
            v[2]
        );
    }
    out.push_str("$EndElements\n");
    views(&mut out, steps, 2, false);
    out
}
