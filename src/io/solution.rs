//! Readers of a 2D two-body contact solution computed by another code (GetFEM, FEniCSx,
//! MOOSE, scikit-fem, ...), for grading: P1 triangles of both bodies with a `body` mark,
//! nodal displacements, optional P0 stresses per triangle and an optional nodal pressure.
//!
//! - [`read_vtu`]: a VTK XML unstructured grid (.vtu) with one piece, arrays in every
//!   layout VTK and its exporters write: `ascii`, inline `binary` (base64) and `appended`
//!   (`raw` bytes or `base64`), uncompressed or zlib-compressed in blocks
//!   (`vtkZLibDataCompressor`), UInt32 or UInt64 block headers, either byte order, every
//!   VTK number type. The project's own writer ([`super::vtu`]) is read bit for bit.
//! - [`read_pvd`]: the (time, file) list of a ParaView collection (.pvd).
//! - [`read_msh_solution`]: gmsh's ASCII MSH 4.1 or 2.2 with the solution as
//!   `$NodeData`/`$ElementData` views, one per field and time.
//!
//! Every refusal is an [`Error::input`] naming the file, the field (`PointData/displacement`,
//! `CellData/body`, `Cells`, `$NodeData "displacement" (line 40)`, ...) and the fix.
//! Counts in a file are checked against the bytes present before anything is allocated
//! from them, so a corrupt header cannot ask for absurd memory. What must vanish (z, a third
//! displacement component, the z row of a stress) or agree (s12 and s21) is judged to
//! [`ROUNDING`] epsilons of the precision stored, relative to its array's size.
//!
//! Written by hand on quick-xml (the XML), base64 and flate2 (zlib) because no maintained
//! Rust crate reads these files whole. Checked: vtkio's last release is 0.6.3 (2021); its
//! 0.7.0-rc2 (a release candidate) reads appended raw data but slices the appended bytes
//! by the header's counts unchecked (a truncated file panics) and pins quick-xml 0.22;
//! mshio 0.4.2 reads MSH 4.1 only, not 2.2, and neither `$PhysicalNames` nor the
//! `$NodeData`/`$ElementData` views that carry a solution. The appended raw layout is not
//! well-formed XML (binary bytes after `_`), so the file is split there before the XML is
//! parsed, as VTK's own reader does. The project's mesh reader (`mesh::msh`) reads the
//! project's own 4.1 meshes and is left as it is; this module depends on `crate::error`
//! only.

use crate::error::{Error, Result};
use base64::Engine as _;
use std::collections::HashMap;
use std::io::Read as _;
use std::path::{Path, PathBuf};

/// The names of the solution fields to read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FieldNames {
    /// Nodal displacement (point data, `$NodeData`); required.
    pub displacement: String,
    /// P0 stress per triangle (cell data, `$ElementData`); optional.
    pub stress: String,
    /// Nodal contact pressure (point data, `$NodeData`); optional.
    pub pressure: String,
}

impl Default for FieldNames {
    fn default() -> Self {
        FieldNames {
            displacement: "displacement".into(),
            stress: "stress".into(),
            pressure: "pressure".into(),
        }
    }
}

/// The cell array that says which body each triangle belongs to (1 or 2).
pub const BODY_ARRAY: &str = "body";

/// The precision a file stored its coordinates and field values in.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Precision {
    /// Single precision (Float32).
    F32,
    /// Double precision (Float64, integers, MSH's decimal text).
    F64,
}

impl Precision {
    /// The machine epsilon of the precision (`f32::EPSILON` widened, or `f64::EPSILON`).
    pub fn epsilon(self) -> f64 {
        match self {
            Precision::F32 => f32::EPSILON as f64,
            Precision::F64 => f64::EPSILON,
        }
    }

    /// The coarser of two precisions.
    pub fn coarser(self, other: Precision) -> Precision {
        if self == Precision::F32 || other == Precision::F32 {
            Precision::F32
        } else {
            Precision::F64
        }
    }

    /// Largest |value| of a quantity that must be zero, or |a - b| of two that must agree,
    /// for a quantity of size `scale` stored in this precision: [`ROUNDING`] epsilons of it.
    pub fn tolerance(self, scale: f64) -> f64 {
        ROUNDING * self.epsilon() * scale
    }
}

/// How many epsilons of the stored precision a value that must vanish (a z coordinate, a
/// third displacement component, the z row of a plane stress) or two that must agree (s12
/// and s21) may be off, relative to the size of their array: the round-off of a few
/// operations in the code that wrote them, far below any modelling difference.
pub const ROUNDING: f64 = 64.0;

/// A P1 triangle mesh of both bodies as a solution file gives it.
#[derive(Debug, Clone, PartialEq)]
pub struct SolutionMesh {
    /// Point coordinates (x, y), length units of the file.
    pub points: Vec<[f64; 2]>,
    /// Triangles: indices into `points`.
    pub triangles: Vec<[usize; 3]>,
    /// Per triangle: 1 (the scene's first body) or 2.
    pub body: Vec<u8>,
    /// The coarser of the coordinates' and the fields' precision.
    pub precision: Precision,
}

/// One state read from a file.
#[derive(Debug, Clone, PartialEq)]
pub struct SolutionStep {
    /// The mesh of both bodies.
    pub mesh: SolutionMesh,
    /// Displacement (u_x, u_y) per point, length units.
    pub displacement: Vec<[f64; 2]>,
    /// P0 stress [s11, s22, s12] per triangle, stress units; `None` when the file has none.
    pub stress: Option<Vec<[f64; 3]>>,
    /// Contact pressure per point, stress units; `None` when the file has none.
    pub pressure: Option<Vec<f64>>,
}

// ---------------------------------------------------------------------------------------
// Checks shared by the VTU and MSH readers.

/// Refuse a NaN or infinity in `values` (`components` per tuple), naming the first one.
fn check_finite(
    values: &[f64],
    components: usize,
    file: &Path,
    field: &str,
    tuple: &str,
) -> Result<()> {
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        let c = components.max(1);
        return Err(Error::input(
            file,
            field,
            format!(
                "{tuple} {} (component {}) is {}: the grading needs finite numbers; fix the solution (a diverged solve?) or the export and write the file again",
                i / c,
                i % c,
                values[i]
            ),
        ));
    }
    Ok(())
}

/// Largest |value| over the components `which` of each tuple.
fn largest(values: &[f64], components: usize, which: &[usize]) -> f64 {
    values
        .chunks_exact(components)
        .flat_map(|t| which.iter().map(move |&c| t[c].abs()))
        .fold(0.0, f64::max)
}

/// Nodal displacements from 2 or 3 components per tuple; a third must vanish; `label(i)`
/// names row i in errors.
fn displacement_2d(
    values: &[f64],
    components: usize,
    precision: Precision,
    file: &Path,
    field: &str,
    label: &dyn Fn(usize) -> String,
) -> Result<Vec<[f64; 2]>> {
    match components {
        2 => Ok(values.chunks_exact(2).map(|t| [t[0], t[1]]).collect()),
        3 => in_plane(values, precision).map_err(|(i, z, scale)| {
            Error::input(
                file,
                field,
                format!(
                    "the third component at {} is {z:e}, not zero (largest in-plane |u| {scale:e}); the grading is 2D in the x-y plane: write the x and y components only, or a zero z component",
                    label(i)
                ),
            )
        }),
        n => Err(Error::input(
            file,
            field,
            format!(
                "{n} components per point; a 2D displacement has 2 (u_x, u_y) or 3 (u_x, u_y, 0): write it so"
            ),
        )),
    }
}

/// P0 stresses [s11, s22, s12] from 3 components, a 2x2 tensor (4, row-major) or a 3x3
/// tensor (9, row-major) whose z row and column vanish (plane stress); `label(i)` names
/// row i in errors.
fn stress_2d(
    values: &[f64],
    components: usize,
    precision: Precision,
    file: &Path,
    field: &str,
    label: &dyn Fn(usize) -> String,
) -> Result<Vec<[f64; 3]>> {
    // Positions of s11, s12, s21, s22 in a row-major tensor, and of its z row and column.
    let (s11, s12, s21, s22, z): (usize, usize, usize, usize, &[usize]) = match components {
        3 => return Ok(values.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect()),
        4 => (0, 1, 2, 3, &[]),
        9 => (0, 1, 3, 4, &[2, 5, 6, 7, 8]),
        n => {
            return Err(Error::input(
                file,
                field,
                format!(
                    "{n} components per cell; the stress is read as 3 components [s11, s22, s12], a 2x2 tensor (4, row-major [s11, s12, s21, s22]) or a 3x3 tensor (9, row-major, plane stress): write one of these"
                ),
            ));
        }
    };
    let scale = largest(values, components, &[s11, s12, s21, s22]);
    let tolerance = precision.tolerance(scale);
    for (i, t) in values.chunks_exact(components).enumerate() {
        if (t[s12] - t[s21]).abs() > tolerance {
            return Err(Error::input(
                file,
                field,
                format!(
                    "{}: s12 = {:e} and s21 = {:e} differ by more than round-off (largest |stress| {scale:e}); a Cauchy stress is symmetric: check the export (a displacement gradient written instead of the stress?)",
                    label(i),
                    t[s12],
                    t[s21]
                ),
            ));
        }
        if let Some(&c) = z.iter().find(|&&c| t[c].abs() > tolerance) {
            return Err(Error::input(
                file,
                field,
                format!(
                    "{}: the z component {} of the 3x3 stress is {:e}, not zero (largest in-plane |stress| {scale:e}); the grading compares plane stresses: write the in-plane components only (3 components [s11, s22, s12] or the 2x2 tensor); a plane-strain code's s33 = nu (s11 + s22) belongs out of it",
                    label(i),
                    ["xx", "xy", "xz", "yx", "yy", "yz", "zx", "zy", "zz"][c],
                    t[c]
                ),
            ));
        }
    }
    Ok(values
        .chunks_exact(components)
        .map(|t| [t[s11], t[s22], 0.5 * (t[s12] + t[s21])])
        .collect())
}

/// Points (x, y) from (x, y, z) triples whose z vanishes relative to the mesh's size.
fn planar_points(
    xyz: &[f64],
    precision: Precision,
    file: &Path,
    field: &str,
) -> Result<Vec<[f64; 2]>> {
    in_plane(xyz, precision).map_err(|(i, z, size)| {
        Error::input(
            file,
            field,
            format!(
                "point {i} has z = {z:e}, not zero (largest |x|, |y| {size:e}); the grading is 2D: write the mesh in the z = 0 plane"
            ),
        )
    })
}

/// The (x, y) of 3-component tuples whose third component vanishes to the precision,
/// relative to the largest |x|, |y|; else the first offending tuple, its third component and
/// that scale.
fn in_plane(
    xyz: &[f64],
    precision: Precision,
) -> std::result::Result<Vec<[f64; 2]>, (usize, f64, f64)> {
    let scale = largest(xyz, 3, &[0, 1]);
    let tolerance = precision.tolerance(scale);
    match xyz.chunks_exact(3).position(|t| t[2].abs() > tolerance) {
        Some(i) => Err((i, xyz[3 * i + 2], scale)),
        None => Ok(xyz.chunks_exact(3).map(|t| [t[0], t[1]]).collect()),
    }
}

/// Refuse a mesh without a triangle of each body.
fn check_both_bodies(body: &[u8], file: &Path, field: &str) -> Result<()> {
    for b in [1u8, 2] {
        if !body.contains(&b) {
            return Err(Error::input(
                file,
                field,
                format!(
                    "no triangle belongs to body {b}; a two-body contact solution has triangles of both bodies: mark the first body's triangles 1 and the second's 2"
                ),
            ));
        }
    }
    Ok(())
}

/// Why a cell or element type other than the P1 triangle is refused, and the way to convert.
fn conversion_route(kind: ElementKind) -> &'static str {
    match kind {
        ElementKind::Quadrilateral => {
            "split each quadrilateral into two triangles (meshio, or gmsh's Mesh.SubdivisionAlgorithm / `Mesh.RecombineAll = 0`)"
        }
        ElementKind::QuadraticTriangle => {
            "P2 is not graded yet: write the P1 solution (the vertices of each triangle) or interpolate to P1"
        }
        ElementKind::Other => {
            "only P1 triangles are graded: write the solution on a P1 triangle mesh"
        }
    }
}

/// The refused element families.
#[derive(Clone, Copy)]
enum ElementKind {
    Quadrilateral,
    QuadraticTriangle,
    Other,
}

// ---------------------------------------------------------------------------------------
// XML helpers.

/// The 1-based line of byte `at` in `text`.
fn line_of(text: &str, at: usize) -> usize {
    1 + text.as_bytes()[..at.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
}

/// A well-formedness error of quick-xml at byte `at` of `xml`.
fn xml_error(path: &Path, xml: &str, at: u64, e: impl std::fmt::Display, what: &str) -> Error {
    Error::input(
        path,
        format!("XML (line {})", line_of(xml, at as usize)),
        format!(
            "{e}; the file is not well-formed XML (truncated or edited?): write the {what} again with the code that made it"
        ),
    )
}

/// An attribute as the file gives it: `key="value"`, or that it is missing.
fn shown(key: &str, value: Option<&str>) -> String {
    match value {
        Some(v) => format!("{key}=\"{v}\""),
        None => format!("the attribute {key} is missing"),
    }
}

/// The attributes of an element by name.
fn attributes(
    e: &quick_xml::events::BytesStart,
    path: &Path,
    field: &str,
) -> Result<HashMap<String, String>> {
    let mut out = HashMap::new();
    for a in e.attributes() {
        let a = a.map_err(|err| {
            Error::input(
                path,
                field,
                format!("{err}: a malformed attribute; write the file again"),
            )
        })?;
        let value = a
            .normalized_value(quick_xml::XmlVersion::Implicit1_0)
            .map_err(|err| {
                Error::input(
                    path,
                    field,
                    format!("{err}: a malformed attribute value; write the file again"),
                )
            })?;
        out.insert(a.key.as_ref().to_string(), value.into_owned());
    }
    Ok(out)
}

// ---------------------------------------------------------------------------------------
// VTU.

/// VTK's number types.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "Int8" => Scalar::I8,
            "UInt8" => Scalar::U8,
            "Int16" => Scalar::I16,
            "UInt16" => Scalar::U16,
            "Int32" => Scalar::I32,
            "UInt32" => Scalar::U32,
            "Int64" => Scalar::I64,
            "UInt64" => Scalar::U64,
            "Float32" => Scalar::F32,
            "Float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::I64 | Scalar::U64 | Scalar::F64 => 8,
        }
    }

    fn is_float(self) -> bool {
        matches!(self, Scalar::F32 | Scalar::F64)
    }

    fn precision(self) -> Precision {
        if self == Scalar::F32 {
            Precision::F32
        } else {
            Precision::F64
        }
    }
}

/// The numbers of an array: integers exactly, floats widened to f64.
enum Numbers {
    Int(Vec<i64>),
    Float(Vec<f64>),
}

impl Numbers {
    fn into_f64(self) -> Vec<f64> {
        match self {
            Numbers::Int(v) => v.into_iter().map(|x| x as f64).collect(),
            Numbers::Float(v) => v,
        }
    }
}

/// The byte order of binary data.
#[derive(Clone, Copy, PartialEq, Eq)]
enum ByteOrder {
    Little,
    Big,
}

/// Bytes of one number in the file's byte order, as a little-endian array of `N`.
fn ordered<const N: usize>(b: &[u8], order: ByteOrder) -> [u8; N] {
    let mut a: [u8; N] = b.try_into().expect("a chunk of the type's size");
    if order == ByteOrder::Big {
        a.reverse();
    }
    a
}

/// Decode packed binary numbers of type `t` in byte order `order`.
fn from_bytes(bytes: &[u8], t: Scalar, order: ByteOrder) -> std::result::Result<Numbers, String> {
    let n = t.size();
    let chunks = bytes.chunks_exact(n);
    Ok(match t {
        Scalar::F32 => Numbers::Float(
            chunks
                .map(|c| f32::from_le_bytes(ordered(c, order)) as f64)
                .collect(),
        ),
        Scalar::F64 => Numbers::Float(
            chunks
                .map(|c| f64::from_le_bytes(ordered(c, order)))
                .collect(),
        ),
        Scalar::I8 => Numbers::Int(chunks.map(|c| c[0] as i8 as i64).collect()),
        Scalar::U8 => Numbers::Int(chunks.map(|c| c[0] as i64).collect()),
        Scalar::I16 => Numbers::Int(
            chunks
                .map(|c| i16::from_le_bytes(ordered(c, order)) as i64)
                .collect(),
        ),
        Scalar::U16 => Numbers::Int(
            chunks
                .map(|c| u16::from_le_bytes(ordered(c, order)) as i64)
                .collect(),
        ),
        Scalar::I32 => Numbers::Int(
            chunks
                .map(|c| i32::from_le_bytes(ordered(c, order)) as i64)
                .collect(),
        ),
        Scalar::U32 => Numbers::Int(
            chunks
                .map(|c| u32::from_le_bytes(ordered(c, order)) as i64)
                .collect(),
        ),
        Scalar::I64 => Numbers::Int(
            chunks
                .map(|c| i64::from_le_bytes(ordered(c, order)))
                .collect(),
        ),
        Scalar::U64 => Numbers::Int(
            chunks
                .map(|c| {
                    let v = u64::from_le_bytes(ordered(c, order));
                    i64::try_from(v).map_err(|_| format!("the value {v} is out of range"))
                })
                .collect::<std::result::Result<_, _>>()?,
        ),
    })
}

/// The sections of a piece that hold arrays.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
enum Section {
    PointData,
    CellData,
    Points,
    Cells,
}

impl Section {
    fn name(self) -> &'static str {
        match self {
            Section::PointData => "PointData",
            Section::CellData => "CellData",
            Section::Points => "Points",
            Section::Cells => "Cells",
        }
    }
}

/// Where an array's numbers are.
#[derive(Clone, Debug)]
enum Layout {
    /// Whitespace-separated text.
    Ascii,
    /// Inline base64 of a header and the (compressed) bytes.
    Binary,
    /// At this offset of the appended data.
    Appended(usize),
}

/// A `<DataArray>` as the XML gives it.
#[derive(Clone, Debug)]
struct ArrayInfo {
    section: Section,
    name: String,
    vtk_type: String,
    components: usize,
    layout: Layout,
    /// The element's text (ascii numbers or inline base64).
    text: String,
}

impl ArrayInfo {
    /// The error field of the array: `PointData/displacement`, `Points`, `Cells/types`.
    fn field(&self) -> String {
        if self.section == Section::Points {
            "Points".into()
        } else {
            format!("{}/{}", self.section.name(), self.name)
        }
    }
}

/// The data after `<AppendedData encoding=...>_`.
struct Appended<'a> {
    base64: bool,
    data: &'a [u8],
}

/// What the XML of a .vtu says.
struct VtuDocument {
    order: ByteOrder,
    header64: bool,
    compressed: bool,
    points: usize,
    cells: usize,
    arrays: Vec<ArrayInfo>,
}

/// The `<AppendedData>` of a .vtu, if any, and the XML without it (the raw layout holds
/// bytes that are not XML).
fn split_appended<'a>(bytes: &'a [u8], path: &Path) -> Result<(String, Option<Appended<'a>>)> {
    let not_utf8 = |e: std::str::Utf8Error| {
        Error::input(
            path,
            "XML",
            format!(
                "the XML is not UTF-8 text (byte {}): a .vtu is XML, with binary bytes only inside <AppendedData encoding=\"raw\">; write the file again",
                e.valid_up_to()
            ),
        )
    };
    let open = b"<AppendedData";
    let Some(start) = find(bytes, open) else {
        let xml = std::str::from_utf8(bytes).map_err(not_utf8)?;
        return Ok((xml.to_string(), None));
    };
    let field = "AppendedData";
    let truncated = |what: &str| {
        Error::input(
            path,
            field,
            format!("{what} (a truncated file?): write the file again"),
        )
    };
    let tag_end = start
        + bytes[start..]
            .iter()
            .position(|&b| b == b'>')
            .ok_or_else(|| truncated("the <AppendedData> tag is not closed"))?;
    let tag = std::str::from_utf8(&bytes[start..=tag_end]).map_err(not_utf8)?;
    let mut reader = quick_xml::Reader::from_str(tag);
    let attrs = match reader.read_event() {
        Ok(quick_xml::events::Event::Start(e)) | Ok(quick_xml::events::Event::Empty(e)) => {
            attributes(&e, path, field)?
        }
        _ => {
            return Err(truncated("the <AppendedData> tag is malformed"));
        }
    };
    let base64 = match attrs.get("encoding").map(String::as_str) {
        Some("raw") => false,
        Some("base64") => true,
        other => {
            return Err(Error::input(
                path,
                field,
                format!(
                    "{}: the appended data is read with encoding=\"raw\" or encoding=\"base64\": write it so",
                    shown("encoding", other)
                ),
            ));
        }
    };
    let after = tag_end + 1;
    let underscore = after
        + bytes[after..]
            .iter()
            .position(|&b| !b.is_ascii_whitespace())
            .ok_or_else(|| truncated("the appended data is missing"))?;
    if bytes[underscore] != b'_' {
        return Err(Error::input(
            path,
            field,
            "the appended data does not start with '_' (VTK's marker of its first byte): write the file again with VTK's XML writer",
        ));
    }
    let close = b"</AppendedData>";
    let end = rfind(bytes, close)
        .filter(|&e| e > underscore)
        .ok_or_else(|| truncated("</AppendedData> is missing"))?;
    let mut xml = std::str::from_utf8(&bytes[..start])
        .map_err(not_utf8)?
        .to_string();
    xml.push_str(std::str::from_utf8(&bytes[end + close.len()..]).map_err(not_utf8)?);
    Ok((
        xml,
        Some(Appended {
            base64,
            data: &bytes[underscore + 1..end],
        }),
    ))
}

fn find(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    haystack.windows(needle.len()).position(|w| w == needle)
}

fn rfind(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    haystack.windows(needle.len()).rposition(|w| w == needle)
}

/// A count attribute (`NumberOfPoints`, `NumberOfComponents`, `offset`).
fn count_attribute(
    attrs: &HashMap<String, String>,
    key: &str,
    default: Option<usize>,
    path: &Path,
    field: &str,
) -> Result<usize> {
    match (attrs.get(key), default) {
        (None, Some(d)) => Ok(d),
        (None, None) => Err(Error::input(
            path,
            field,
            format!("the attribute {key} is missing: write the file with {key}=\"N\""),
        )),
        (Some(v), _) => v.trim().parse().map_err(|_| {
            Error::input(
                path,
                field,
                format!("{key}=\"{v}\" is not a non-negative integer: write the file again"),
            )
        }),
    }
}

/// Parse the XML of a .vtu (without its appended data).
fn parse_vtu_xml(xml: &str, path: &Path) -> Result<VtuDocument> {
    use quick_xml::events::Event;
    let mut reader = quick_xml::Reader::from_str(xml);
    let mut stack: Vec<String> = Vec::new();
    let mut doc = VtuDocument {
        order: ByteOrder::Little,
        header64: false,
        compressed: false,
        points: 0,
        cells: 0,
        arrays: Vec::new(),
    };
    let (mut root_seen, mut pieces) = (false, 0usize);
    // The DataArray being read (its text arrives in events of its own).
    let mut open: Option<ArrayInfo> = None;
    loop {
        let at = reader.buffer_position();
        let event = reader
            .read_event()
            .map_err(|e| xml_error(path, xml, reader.error_position(), e, ".vtu"))?;
        let (e, empty) = match event {
            Event::Eof => break,
            Event::Start(e) => (e, false),
            Event::Empty(e) => (e, true),
            Event::End(_) => {
                if stack.pop().as_deref() == Some("DataArray")
                    && let Some(a) = open.take()
                {
                    doc.arrays.push(a);
                }
                continue;
            }
            Event::Text(t) => {
                if let Some(a) = open.as_mut() {
                    a.text.push_str(&t);
                }
                continue;
            }
            _ => continue,
        };
        let name = e.name().as_ref().to_string();
        let parent = stack.last().map(String::as_str);
        let line = line_of(xml, at as usize);
        match (parent, name.as_str()) {
            (None, "VTKFile") => {
                root_seen = true;
                let a = attributes(&e, path, "VTKFile")?;
                read_root(&a, &mut doc, path)?;
            }
            (None, other) => {
                return Err(Error::input(
                    path,
                    format!("XML (line {line})"),
                    format!(
                        "the root element is <{other}>, not <VTKFile>: give a VTK XML unstructured grid (.vtu)"
                    ),
                ));
            }
            (Some("UnstructuredGrid"), "Piece") => {
                pieces += 1;
                if pieces > 1 {
                    return Err(Error::input(
                        path,
                        "Piece",
                        "the grid has more than one <Piece>: one piece is read; merge the pieces into one (ParaView's Merge Blocks, then Save Data), or write the solution from one process",
                    ));
                }
                let a = attributes(&e, path, "Piece")?;
                doc.points = count_attribute(&a, "NumberOfPoints", None, path, "Piece")?;
                doc.cells = count_attribute(&a, "NumberOfCells", None, path, "Piece")?;
            }
            (Some(section), "DataArray") => {
                let section = match section {
                    "PointData" => Some(Section::PointData),
                    "CellData" => Some(Section::CellData),
                    "Points" => Some(Section::Points),
                    "Cells" => Some(Section::Cells),
                    _ => None,
                };
                let in_piece = stack.len() >= 2 && stack[stack.len() - 2] == "Piece";
                if let (Some(section), true) = (section, in_piece) {
                    let a = attributes(&e, path, section.name())?;
                    let info = array_info(&a, section, path)?;
                    if empty {
                        doc.arrays.push(info);
                    } else {
                        open = Some(info);
                    }
                }
            }
            _ => {}
        }
        if !empty {
            stack.push(name);
        }
    }
    if let Some(unclosed) = stack.last() {
        return Err(Error::input(
            path,
            "XML",
            format!(
                "<{unclosed}> is not closed (a truncated file?): write the file again with the code that made it"
            ),
        ));
    }
    if !root_seen {
        return Err(Error::input(
            path,
            "VTKFile",
            "no <VTKFile> element (an empty or truncated file?): give a VTK XML unstructured grid (.vtu)",
        ));
    }
    if pieces == 0 {
        return Err(Error::input(
            path,
            "Piece",
            "the grid has no <Piece> inside <UnstructuredGrid>: write the mesh and the solution into the file",
        ));
    }
    Ok(doc)
}

/// The attributes of `<VTKFile>`: the type, byte order, header type and compressor.
fn read_root(a: &HashMap<String, String>, doc: &mut VtuDocument, path: &Path) -> Result<()> {
    let field = "VTKFile";
    match a.get("type").map(String::as_str) {
        Some("UnstructuredGrid") => {}
        Some("PUnstructuredGrid") => {
            return Err(Error::input(
                path,
                field,
                "type=\"PUnstructuredGrid\": a parallel grid (.pvtu) only lists its pieces; read the .vtu of a run on one process, or merge the pieces into one .vtu (ParaView's Merge Blocks, then Save Data)",
            ));
        }
        other => {
            return Err(Error::input(
                path,
                field,
                format!(
                    "{}: an unstructured grid (type=\"UnstructuredGrid\", a .vtu) is read; convert the dataset to one (meshio, or ParaView's Save Data as .vtu)",
                    shown("type", other)
                ),
            ));
        }
    }
    doc.order = match a.get("byte_order").map(String::as_str) {
        None | Some("LittleEndian") => ByteOrder::Little,
        Some("BigEndian") => ByteOrder::Big,
        Some(other) => {
            return Err(Error::input(
                path,
                field,
                format!("byte_order=\"{other}\": write LittleEndian or BigEndian"),
            ));
        }
    };
    doc.header64 = match a.get("header_type").map(String::as_str) {
        None | Some("UInt32") => false,
        Some("UInt64") => true,
        Some(other) => {
            return Err(Error::input(
                path,
                field,
                format!(
                    "header_type=\"{other}\": VTK's block headers are UInt32 or UInt64; write one of these"
                ),
            ));
        }
    };
    doc.compressed = match a.get("compressor").map(String::as_str) {
        None | Some("") => false,
        Some("vtkZLibDataCompressor") => true,
        Some(other) => {
            return Err(Error::input(
                path,
                field,
                format!(
                    "compressor=\"{other}\": zlib (vtkZLibDataCompressor) or no compression is read; write the file with one of these (ParaView's Save Data: Compressor Type ZLib or None)"
                ),
            ));
        }
    };
    Ok(())
}

/// A `<DataArray>`'s attributes.
fn array_info(a: &HashMap<String, String>, section: Section, path: &Path) -> Result<ArrayInfo> {
    let name = a.get("Name").cloned().unwrap_or_default();
    let mut info = ArrayInfo {
        section,
        name,
        vtk_type: a.get("type").cloned().unwrap_or_default(),
        components: 1,
        layout: Layout::Ascii,
        text: String::new(),
    };
    let field = info.field();
    info.components = count_attribute(a, "NumberOfComponents", Some(1), path, &field)?;
    info.layout = match a.get("format").map(String::as_str) {
        Some("ascii") => Layout::Ascii,
        Some("binary") => Layout::Binary,
        Some("appended") => Layout::Appended(count_attribute(a, "offset", None, path, &field)?),
        other => {
            return Err(Error::input(
                path,
                field,
                format!(
                    "{}: a DataArray's format is \"ascii\", \"binary\" or \"appended\"; write the file again",
                    shown("format", other)
                ),
            ));
        }
    };
    Ok(info)
}

/// A lenient base64 engine: padding optional, trailing bits allowed (VTK pads each stream).
const BASE64: base64::engine::GeneralPurpose = base64::engine::GeneralPurpose::new(
    &base64::alphabet::STANDARD,
    base64::engine::GeneralPurposeConfig::new()
        .with_decode_allow_trailing_bits(true)
        .with_decode_padding_mode(base64::engine::DecodePaddingMode::Indifferent),
);

/// Characters of the base64 of `bytes` bytes.
fn base64_chars(bytes: usize) -> Option<usize> {
    bytes.div_ceil(3).checked_mul(4)
}

/// Where the bytes of a binary array come from.
enum Source<'a> {
    /// Raw bytes (appended raw).
    Raw(&'a [u8]),
    /// base64 characters (inline binary, appended base64), whitespace removed.
    Base64(&'a [u8]),
}

impl Source<'_> {
    /// `n` bytes from byte `start` of the header stream (raw: of the data).
    fn header_bytes(&self, start: usize, n: usize) -> std::result::Result<Vec<u8>, String> {
        let end = start.checked_add(n).ok_or("a header past any file")?;
        match self {
            Source::Raw(d) => d.get(start..end).map(<[u8]>::to_vec).ok_or_else(|| {
                format!(
                    "the file ends inside the array's header ({} bytes from its offset, {end} needed)",
                    d.len()
                )
            }),
            Source::Base64(t) => {
                let chars = base64_chars(end).ok_or("a header past any file")?;
                let text = t.get(..chars).ok_or_else(|| {
                    format!(
                        "the base64 text ends inside the array's header ({} characters, {chars} needed)",
                        t.len()
                    )
                })?;
                let bytes = BASE64
                    .decode(text)
                    .map_err(|e| format!("the header is not valid base64 ({e})"))?;
                bytes
                    .get(start..end)
                    .map(<[u8]>::to_vec)
                    .ok_or_else(|| "the header is shorter than announced".into())
            }
        }
    }

    /// The `n` payload bytes after a header of `header` bytes.
    fn payload(&self, header: usize, n: usize) -> std::result::Result<Vec<u8>, String> {
        let end = header.checked_add(n).ok_or("a payload past any file")?;
        match self {
            Source::Raw(d) => d.get(header..end).map(<[u8]>::to_vec).ok_or_else(|| {
                format!(
                    "the file holds {} bytes from the array's offset, the header announces {end}",
                    d.len()
                )
            }),
            Source::Base64(t) => {
                let header_chars = base64_chars(header).ok_or("a header past any file")?;
                // VTK encodes a compressed array's header and its blocks as two base64
                // streams, the header padded; meshio and VTK encode an uncompressed one as
                // one stream. A header of a multiple of 3 bytes reads the same either way.
                let separate = header.is_multiple_of(3)
                    || t.get(..header_chars).is_some_and(|h| h.ends_with(b"="));
                let (from, chars, skip) = if separate {
                    (header_chars, base64_chars(n), 0)
                } else {
                    (0, base64_chars(end), header)
                };
                let to = chars
                    .and_then(|c| c.checked_add(from))
                    .ok_or("a payload past any file")?;
                let text = t.get(from..to).ok_or_else(|| {
                    format!(
                        "the base64 text holds {} characters, the header announces {n} bytes ({to} characters)",
                        t.len()
                    )
                })?;
                let bytes = BASE64
                    .decode(text)
                    .map_err(|e| format!("the data is not valid base64 ({e})"))?;
                bytes
                    .get(skip..skip.saturating_add(n))
                    .map(<[u8]>::to_vec)
                    .ok_or_else(|| "the data is shorter than announced".into())
            }
        }
    }
}

impl VtuDocument {
    /// The header words `start..start + n` of a binary array.
    fn words(
        &self,
        source: &Source,
        start: usize,
        n: usize,
    ) -> std::result::Result<Vec<u64>, String> {
        let word = self.word();
        let b = source.header_bytes(start * word, n * word)?;
        Ok(b.chunks_exact(word)
            .map(|c| {
                if word == 8 {
                    u64::from_le_bytes(ordered(c, self.order))
                } else {
                    u32::from_le_bytes(ordered(c, self.order)) as u64
                }
            })
            .collect())
    }

    /// Bytes of a header word.
    fn word(&self) -> usize {
        if self.header64 { 8 } else { 4 }
    }

    /// The bytes of a binary array, decompressed: `expected` bytes if given (the header is
    /// checked against it), else as many as its header announces.
    fn binary(
        &self,
        source: Source,
        expected: Option<usize>,
    ) -> std::result::Result<Vec<u8>, String> {
        let word = self.word();
        let need = |n: u64| match expected {
            Some(e) if n != e as u64 => Err(format!(
                "the header announces {n} bytes, the array's tuples and components need {e}"
            )),
            _ => usize::try_from(n).map_err(|_| format!("the header announces {n} bytes")),
        };
        if !self.compressed {
            let n = need(self.words(&source, 0, 1)?[0])?;
            // Checked against the data present before anything is allocated.
            return source.payload(word, n);
        }
        let blocks = self.words(&source, 0, 1)?[0];
        // The header is 3 + blocks words: refuse a count the data cannot hold before
        // reading (or allocating) it.
        let available = match &source {
            Source::Raw(d) => d.len() as u64,
            Source::Base64(t) => t.len() as u64 / 4 * 3,
        };
        if blocks.saturating_add(3).saturating_mul(word as u64) > available {
            return Err(format!(
                "the header announces {blocks} compressed blocks, more than the {available} bytes of data can hold"
            ));
        }
        let blocks = blocks as usize;
        let h = self.words(&source, 0, 3 + blocks)?;
        let (block_size, last_size) = (h[1], h[2]);
        // VTK writes 0 as the last block's size when it is full.
        let total = match blocks {
            0 => 0,
            b if last_size == 0 => (b as u64).saturating_mul(block_size),
            b => ((b - 1) as u64)
                .saturating_mul(block_size)
                .saturating_add(last_size),
        };
        if blocks > 0 && last_size > block_size {
            return Err(format!(
                "the header announces blocks of {block_size} bytes, the last of {last_size}"
            ));
        }
        let total = need(total).map_err(|m| {
            format!("{m} ({blocks} blocks of {block_size} bytes, the last {last_size})")
        })?;
        let compressed: u64 = h[3..].iter().fold(0u64, |s, &c| s.saturating_add(c));
        if compressed > available {
            return Err(format!(
                "the header announces {compressed} compressed bytes, the file holds {available}"
            ));
        }
        let data = source.payload(word * (3 + blocks), compressed as usize)?;
        // zlib expands at most about 1000 times: the capacity follows the bytes present.
        let mut out = Vec::with_capacity(total.min(4 * data.len() + 64));
        let mut at = 0usize;
        for (b, &size) in h[3..].iter().enumerate() {
            let size = size as usize;
            let want = if b + 1 == blocks && last_size != 0 {
                last_size
            } else {
                block_size
            };
            let before = out.len();
            flate2::read::ZlibDecoder::new(&data[at..at + size])
                .take(want.saturating_add(1))
                .read_to_end(&mut out)
                .map_err(|e| format!("block {b} is not a valid zlib stream ({e})"))?;
            if (out.len() - before) as u64 != want {
                return Err(format!(
                    "block {b} decompresses to {} bytes, the header announces {want}",
                    out.len() - before
                ));
            }
            at += size;
        }
        Ok(out)
    }

    /// Decode `a` as `tuples` tuples of its components, or as many as it holds (`None`).
    fn numbers(
        &self,
        a: &ArrayInfo,
        appended: Option<&Appended>,
        tuples: Option<usize>,
        path: &Path,
    ) -> Result<(Numbers, Precision)> {
        let field = a.field();
        let bad = |m: String| Error::input(path, &field, m);
        let t = Scalar::parse(&a.vtk_type).ok_or_else(|| {
            bad(format!(
                "type \"{}\" is not a VTK number type (Int8 ... UInt64, Float32, Float64): write the array as numbers",
                a.vtk_type
            ))
        })?;
        if a.components == 0 {
            return Err(bad(
                "NumberOfComponents=\"0\": an array has at least one component per tuple; write the file again".into(),
            ));
        }
        let count = match tuples {
            None => None,
            Some(n) => Some(n.checked_mul(a.components).ok_or_else(|| {
                bad(format!(
                    "{n} tuples of {} components overflow: the counts are corrupt; write the file again",
                    a.components
                ))
            })?),
        };
        let (tuple, count_name) = match a.section {
            Section::PointData | Section::Points => ("point", "NumberOfPoints"),
            _ => ("cell", "NumberOfCells"),
        };
        let wrong_count = |found: usize| {
            bad(match (tuples, count) {
                (Some(n), Some(c)) => format!(
                    "{found} values, but {count_name} = {n} tuples of {} components need {c}: write one tuple per {tuple} (a field of another mesh, or of the boundary?)",
                    a.components
                ),
                _ => format!(
                    "{found} values are not a whole number of tuples of {} components: write the file again",
                    a.components
                ),
            })
        };
        let numbers = match &a.layout {
            Layout::Ascii => {
                let found = a.text.split_ascii_whitespace().count();
                if count.is_some_and(|c| c != found) || !found.is_multiple_of(a.components) {
                    return Err(wrong_count(found));
                }
                ascii_numbers(&a.text, t).map_err(|(i, s)| {
                    bad(format!(
                        "value {i} '{s}' is not a{} {}: write the array again",
                        if t.is_float() {
                            ""
                        } else {
                            "n integer of type"
                        },
                        a.vtk_type
                    ))
                })?
            }
            layout => {
                let expected = match count {
                    None => None,
                    Some(c) => Some(c.checked_mul(t.size()).ok_or_else(|| wrong_count(0))?),
                };
                let text: Vec<u8>;
                let source = match layout {
                    Layout::Binary => {
                        text = a
                            .text
                            .bytes()
                            .filter(|b| !b.is_ascii_whitespace())
                            .collect();
                        Source::Base64(&text)
                    }
                    Layout::Appended(offset) => {
                        let ap = appended.ok_or_else(|| {
                            bad("format=\"appended\", but the file has no <AppendedData>: write the file again".into())
                        })?;
                        let data = ap.data.get(*offset..).ok_or_else(|| {
                            bad(format!(
                                "offset {offset} is past the end of the appended data ({} bytes): write the file again",
                                ap.data.len()
                            ))
                        })?;
                        if ap.base64 {
                            Source::Base64(data)
                        } else {
                            Source::Raw(data)
                        }
                    }
                    Layout::Ascii => unreachable!("handled above"),
                };
                let bytes = self.binary(source, expected).map_err(|m| {
                    let counts = match tuples {
                        Some(n) => format!(
                            " ({count_name} = {n} tuples of {} components of {})",
                            a.components, a.vtk_type
                        ),
                        None => String::new(),
                    };
                    bad(format!(
                        "{m}{counts}; the binary data does not match the array (a truncated or edited file, or a wrong header_type): write the file again"
                    ))
                })?;
                let tuple_bytes = t.size().saturating_mul(a.components);
                if !bytes.len().is_multiple_of(tuple_bytes) {
                    return Err(wrong_count(bytes.len() / t.size()));
                }
                from_bytes(&bytes, t, self.order)
                    .map_err(|m| bad(format!("{m}: write the array again")))?
            }
        };
        if let Numbers::Float(v) = &numbers {
            check_finite(v, a.components, path, &field, tuple)?;
        }
        Ok((numbers, t.precision()))
    }
}

/// Parse whitespace-separated numbers of type `t`; a bad one as (index, text).
fn ascii_numbers(text: &str, t: Scalar) -> std::result::Result<Numbers, (usize, String)> {
    let tokens = text.split_ascii_whitespace().enumerate();
    let bad = |i: usize, s: &str| (i, s.to_string());
    Ok(match t {
        Scalar::F32 => Numbers::Float(
            tokens
                .map(|(i, s)| s.parse::<f32>().map(f64::from).map_err(|_| bad(i, s)))
                .collect::<std::result::Result<_, _>>()?,
        ),
        Scalar::F64 => Numbers::Float(
            tokens
                .map(|(i, s)| s.parse::<f64>().map_err(|_| bad(i, s)))
                .collect::<std::result::Result<_, _>>()?,
        ),
        _ => Numbers::Int(
            tokens
                .map(|(i, s)| s.parse::<i64>().map_err(|_| bad(i, s)))
                .collect::<std::result::Result<_, _>>()?,
        ),
    })
}

/// Read a .vtu file of one state (see the module's documentation for the layouts read).
pub fn read_vtu(path: &Path, names: &FieldNames) -> Result<SolutionStep> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    parse_vtu(&bytes, path, names)
}

/// Read the bytes of a .vtu file; `path` names the file in errors only.
pub fn parse_vtu(bytes: &[u8], path: &Path, names: &FieldNames) -> Result<SolutionStep> {
    let (xml, appended) = split_appended(bytes, path)?;
    let doc = parse_vtu_xml(&xml, path)?;
    let appended = appended.as_ref();
    let (np, nc) = (doc.points, doc.cells);
    // Duplicate names: the grading would not know which array to read.
    let mut seen = std::collections::HashSet::new();
    for a in &doc.arrays {
        if a.section != Section::Points && !seen.insert((a.section, a.name.as_str())) {
            return Err(Error::input(
                path,
                a.field(),
                format!(
                    "two arrays of {} are named '{}': rename or drop one, so the array read is the one meant",
                    a.section.name(),
                    a.name
                ),
            ));
        }
    }
    let get = |section: Section, name: &str| {
        doc.arrays
            .iter()
            .find(|a| a.section == section && a.name == name)
    };
    let names_in = |section: Section| {
        let v: Vec<String> = doc
            .arrays
            .iter()
            .filter(|a| a.section == section)
            .map(|a| format!("'{}'", a.name))
            .collect();
        if v.is_empty() {
            "none".to_string()
        } else {
            v.join(", ")
        }
    };

    // Points.
    let coordinates: Vec<&ArrayInfo> = doc
        .arrays
        .iter()
        .filter(|a| a.section == Section::Points)
        .collect();
    let [coordinates] = coordinates[..] else {
        return Err(Error::input(
            path,
            "Points",
            format!(
                "<Points> holds {} arrays; it holds one, the coordinates: write the file again",
                coordinates.len()
            ),
        ));
    };
    if coordinates.components != 3 {
        return Err(Error::input(
            path,
            "Points",
            format!(
                "the coordinates have {} components; VTK stores 3 (x, y, z = 0): write them so",
                coordinates.components
            ),
        ));
    }
    let (xyz, coordinate_precision) = doc.numbers(coordinates, appended, Some(np), path)?;
    let points = planar_points(&xyz.into_f64(), coordinate_precision, path, "Points")?;

    // Cells.
    let topology = |name: &str| -> Result<Vec<i64>> {
        let a = get(Section::Cells, name).ok_or_else(|| {
            Error::input(
                path,
                format!("Cells/{name}"),
                format!(
                    "<Cells> has no array '{name}' (it needs connectivity, offsets and types): write the file again"
                ),
            )
        })?;
        // The connectivity holds as many entries as it holds: the offsets say where each
        // cell ends.
        let tuples = (name != "connectivity").then_some(nc);
        match doc.numbers(a, appended, tuples, path)?.0 {
            Numbers::Int(v) => Ok(v),
            Numbers::Float(_) => Err(Error::input(
                path,
                a.field(),
                format!(
                    "type {}: cell topology is integer (Int32 or Int64): write it so",
                    a.vtk_type
                ),
            )),
        }
    };
    let connectivity = topology("connectivity")?;
    let offsets = topology("offsets")?;
    let types = topology("types")?;
    let mut triangle_cells: Vec<usize> = Vec::new();
    let mut triangles: Vec<[usize; 3]> = Vec::new();
    let mut start = 0i64;
    for (cell, (&end, &kind)) in offsets.iter().zip(&types).enumerate() {
        if end < start || end as u64 > connectivity.len() as u64 {
            return Err(Error::input(
                path,
                "Cells/offsets",
                format!(
                    "cell {cell} ends at offset {end}, after {start} and within {} connectivity entries expected: write the file again",
                    connectivity.len()
                ),
            ));
        }
        let nodes = &connectivity[start as usize..end as usize];
        start = end;
        match kind {
            5 => {}
            // Vertices, poly-vertices, lines and poly-lines: exporters write the boundary
            // edges and nodes too; they are not part of the mesh graded.
            1..=4 => continue,
            other => {
                let count = types.iter().filter(|&&t| t == other).count();
                let (what, kind) = match other {
                    9 => ("quadrilateral", ElementKind::Quadrilateral),
                    22 => ("quadratic triangle", ElementKind::QuadraticTriangle),
                    // What FEniCSx writes for a triangle of degree 2 or more.
                    69 => ("Lagrange triangle", ElementKind::QuadraticTriangle),
                    _ => ("cell", ElementKind::Other),
                };
                return Err(Error::input(
                    path,
                    "Cells",
                    format!(
                        "cell {cell} is a {what} (VTK type {other}; {count} such cells); {}",
                        conversion_route(kind)
                    ),
                ));
            }
        }
        let [a, b, c] = nodes[..] else {
            return Err(Error::input(
                path,
                "Cells",
                format!(
                    "cell {cell} is a triangle (VTK type 5) with {} points; a triangle has 3: write the file again",
                    nodes.len()
                ),
            ));
        };
        let mut t = [0usize; 3];
        for (k, n) in [a, b, c].into_iter().enumerate() {
            if n < 0 || n as u64 >= np as u64 {
                return Err(Error::input(
                    path,
                    "Cells/connectivity",
                    format!(
                        "triangle (cell {cell}) refers to point {n}, but the file has {np} points (NumberOfPoints): write the file again"
                    ),
                ));
            }
            t[k] = n as usize;
        }
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            return Err(Error::input(
                path,
                "Cells/connectivity",
                format!(
                    "triangle (cell {cell}) repeats a point ({t:?}): a degenerate triangle; fix the mesh"
                ),
            ));
        }
        triangle_cells.push(cell);
        triangles.push(t);
    }
    if offsets
        .last()
        .is_some_and(|&e| e as u64 != connectivity.len() as u64)
    {
        return Err(Error::input(
            path,
            "Cells/offsets",
            format!(
                "the last cell ends at offset {}, but connectivity holds {} entries: write the file again",
                offsets[offsets.len() - 1],
                connectivity.len()
            ),
        ));
    }
    if triangles.is_empty() {
        return Err(Error::input(
            path,
            "Cells",
            "the file has no triangle (VTK type 5): give the P1 triangle mesh of both bodies",
        ));
    }

    // Which body each triangle belongs to.
    let body_array = get(Section::CellData, BODY_ARRAY).ok_or_else(|| {
        Error::input(
            path,
            format!("CellData/{BODY_ARRAY}"),
            format!(
                "no cell array '{BODY_ARRAY}' (the cell arrays are {}): add one, 1 on the triangles of the scene's first body and 2 on the second's (e.g. from the physical surface tags)",
                names_in(Section::CellData)
            ),
        )
    })?;
    if body_array.components != 1 {
        return Err(Error::input(
            path,
            format!("CellData/{BODY_ARRAY}"),
            format!(
                "{} components per cell; '{BODY_ARRAY}' has one (1 or 2): write it so",
                body_array.components
            ),
        ));
    }
    let marks = doc
        .numbers(body_array, appended, Some(nc), path)?
        .0
        .into_f64();
    let mut body = Vec::with_capacity(triangles.len());
    for &cell in &triangle_cells {
        match marks[cell] {
            1.0 => body.push(1u8),
            2.0 => body.push(2u8),
            v => {
                return Err(Error::input(
                    path,
                    format!("CellData/{BODY_ARRAY}"),
                    format!(
                        "triangle (cell {cell}) has body {v}; each triangle is marked 1 (the scene's first body) or 2: fix the marks"
                    ),
                ));
            }
        }
    }
    check_both_bodies(&body, path, &format!("CellData/{BODY_ARRAY}"))?;

    // The fields.
    let misplaced = |name: &str, wanted: Section, other: Section| {
        get(other, name).map(|_| {
            format!(
                " ('{name}' is in {}: the grading reads it from {}, {})",
                other.name(),
                wanted.name(),
                if wanted == Section::PointData {
                    "one value per point"
                } else {
                    "one P0 value per cell"
                }
            )
        })
    };
    let d = &names.displacement;
    let displacement_array = get(Section::PointData, d).ok_or_else(|| {
        Error::input(
            path,
            format!("PointData/{d}"),
            format!(
                "no point array '{d}'{} (the point arrays are {}): write the nodal displacement as point data named '{d}', or name the array the file has",
                misplaced(d, Section::PointData, Section::CellData).unwrap_or_default(),
                names_in(Section::PointData)
            ),
        )
    })?;
    let field = displacement_array.field();
    let (values, mut precision) = doc.numbers(displacement_array, appended, Some(np), path)?;
    let displacement = displacement_2d(
        &values.into_f64(),
        displacement_array.components,
        precision,
        path,
        &field,
        &|i| format!("point {i}"),
    )?;
    precision = precision.coarser(coordinate_precision);

    let s = &names.stress;
    if get(Section::CellData, s).is_none()
        && let Some(m) = misplaced(s, Section::CellData, Section::PointData)
    {
        return Err(Error::input(
            path,
            format!("PointData/{s}"),
            format!("the stress is point data{m}: write the stress per cell (P0), or leave it out"),
        ));
    }
    let stress = match get(Section::CellData, s) {
        None => None,
        Some(a) => {
            let (values, p) = doc.numbers(a, appended, Some(nc), path)?;
            precision = precision.coarser(p);
            // The triangles' rows only: the values of skipped cells (often placeholders)
            // neither set the scale of the checks nor are checked.
            let (values, k) = (values.into_f64(), a.components);
            let rows: Vec<f64> = triangle_cells
                .iter()
                .flat_map(|&c| values[c * k..(c + 1) * k].iter().copied())
                .collect();
            let label = |i: usize| format!("cell {}", triangle_cells[i]);
            Some(stress_2d(&rows, k, p, path, &a.field(), &label)?)
        }
    };
    let q = &names.pressure;
    let pressure = match get(Section::PointData, q) {
        None => None,
        Some(a) => {
            if a.components != 1 {
                return Err(Error::input(
                    path,
                    a.field(),
                    format!(
                        "{} components per point; the pressure has one: write it so",
                        a.components
                    ),
                ));
            }
            let (values, p) = doc.numbers(a, appended, Some(np), path)?;
            precision = precision.coarser(p);
            Some(values.into_f64())
        }
    };
    Ok(SolutionStep {
        mesh: SolutionMesh {
            points,
            triangles,
            body,
            precision,
        },
        displacement,
        stress,
        pressure,
    })
}

// ---------------------------------------------------------------------------------------
// PVD.

/// Read a ParaView collection (.pvd): its (time, dataset file) pairs in file order, the
/// files resolved against the .pvd's folder.
pub fn read_pvd(path: &Path) -> Result<Vec<(f64, PathBuf)>> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    parse_pvd(&bytes, path)
}

/// Read the bytes of a .pvd; `path` names the file in errors and resolves the datasets.
pub fn parse_pvd(bytes: &[u8], path: &Path) -> Result<Vec<(f64, PathBuf)>> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        Error::input(
            path,
            "XML",
            format!(
                "not UTF-8 text (byte {}): a .pvd is XML; give the collection file, not a dataset",
                e.valid_up_to()
            ),
        )
    })?;
    use quick_xml::events::Event;
    let folder = path.parent().unwrap_or(Path::new(""));
    let mut reader = quick_xml::Reader::from_str(text);
    let mut stack: Vec<String> = Vec::new();
    let mut out: Vec<(f64, PathBuf)> = Vec::new();
    // The dataset of each time read (0 and -0 alike).
    let mut of_time: HashMap<u64, usize> = HashMap::new();
    let mut root_seen = false;
    loop {
        let at = reader.buffer_position();
        let event = reader
            .read_event()
            .map_err(|e| xml_error(path, text, reader.error_position(), e, ".pvd"))?;
        let (e, empty) = match event {
            Event::Eof => break,
            Event::Start(e) => (e, false),
            Event::Empty(e) => (e, true),
            Event::End(_) => {
                stack.pop();
                continue;
            }
            _ => continue,
        };
        let name = e.name().as_ref().to_string();
        match (stack.last().map(String::as_str), name.as_str()) {
            (None, "VTKFile") => {
                root_seen = true;
                let a = attributes(&e, path, "VTKFile")?;
                if a.get("type").map(String::as_str) != Some("Collection") {
                    return Err(Error::input(
                        path,
                        "VTKFile",
                        format!(
                            "{}: a ParaView collection has type=\"Collection\"; give the .pvd that lists the time steps (or read a single .vtu as one state)",
                            shown("type", a.get("type").map(String::as_str))
                        ),
                    ));
                }
            }
            (None, other) => {
                return Err(Error::input(
                    path,
                    format!("XML (line {})", line_of(text, at as usize)),
                    format!(
                        "the root element is <{other}>, not <VTKFile type=\"Collection\">: give a ParaView collection (.pvd)"
                    ),
                ));
            }
            (Some("Collection"), "DataSet") => {
                let i = out.len();
                let field = |key: &str| format!("Collection/DataSet[{i}]/{key}");
                let a = attributes(&e, path, &field("timestep"))?;
                let time = match a.get("timestep") {
                    None => {
                        return Err(Error::input(
                            path,
                            field("timestep"),
                            "the dataset has no timestep: give each DataSet timestep=\"t\" (the time of its state)",
                        ));
                    }
                    Some(t) => match t.trim().parse::<f64>() {
                        Ok(v) if v.is_finite() => v,
                        _ => {
                            return Err(Error::input(
                                path,
                                field("timestep"),
                                format!(
                                    "timestep=\"{t}\" is not a finite number: write the time of the state"
                                ),
                            ));
                        }
                    },
                };
                let file = match a.get("file").map(|f| f.trim()) {
                    Some(f) if !f.is_empty() => folder.join(f),
                    _ => {
                        return Err(Error::input(
                            path,
                            field("file"),
                            "the dataset names no file: give each DataSet file=\"name.vtu\" (relative to the .pvd's folder)",
                        ));
                    }
                };
                if let Some(&j) = of_time.get(&(time + 0.0).to_bits()) {
                    return Err(Error::input(
                        path,
                        field("timestep"),
                        format!(
                            "datasets {j} and {i} both have timestep {time}: one file per time is read; if they are parts of one state (part=...), merge them (ParaView's Merge Blocks, then Save Data)"
                        ),
                    ));
                }
                of_time.insert((time + 0.0).to_bits(), i);
                out.push((time, file));
            }
            _ => {}
        }
        if !empty {
            stack.push(name);
        }
    }
    if !root_seen {
        return Err(Error::input(
            path,
            "VTKFile",
            "no <VTKFile type=\"Collection\"> element (an empty or truncated file?): give a ParaView collection (.pvd)",
        ));
    }
    if let Some(unclosed) = stack.last() {
        return Err(Error::input(
            path,
            "XML",
            format!("<{unclosed}> is not closed (a truncated file?): write the collection again"),
        ));
    }
    if out.is_empty() {
        return Err(Error::input(
            path,
            "Collection",
            "the collection lists no <DataSet>: give the .pvd of the time series, one DataSet per step",
        ));
    }
    Ok(out)
}

// ---------------------------------------------------------------------------------------
// MSH.

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

/// A cursor over the tokens of an ASCII MSH file.
struct Cursor<'a> {
    text: &'a str,
    at: usize,
    path: &'a Path,
    /// The section read, for errors.
    section: String,
}

impl<'a> Cursor<'a> {
    fn field(&self) -> String {
        format!("{} (line {})", self.section, line_of(self.text, self.at))
    }

    fn err(&self, message: impl Into<String>) -> Error {
        Error::input(self.path, self.field(), message.into())
    }

    fn skip_space(&mut self) {
        let rest = &self.text[self.at..];
        self.at += rest.len() - rest.trim_start().len();
    }

    fn token(&mut self) -> Option<&'a str> {
        self.skip_space();
        let rest = &self.text[self.at..];
        if rest.is_empty() {
            return None;
        }
        let end = rest.find(char::is_whitespace).unwrap_or(rest.len());
        self.at += end;
        Some(&rest[..end])
    }

    fn next(&mut self, what: &str) -> Result<&'a str> {
        self.token().ok_or_else(|| {
            self.err(format!(
                "the file ends where {what} is expected (a truncated file?): write it again"
            ))
        })
    }

    fn parsed<T: std::str::FromStr>(&mut self, what: &str, kind: &str) -> Result<T> {
        let s = self.next(what)?;
        s.parse().map_err(|_| {
            self.err(format!(
                "{what}: '{s}' is not {kind}; the file is not valid MSH: write it again with gmsh or meshio"
            ))
        })
    }

    fn count(&mut self, what: &str) -> Result<usize> {
        self.parsed(what, "a non-negative integer")
    }

    fn int(&mut self, what: &str) -> Result<i64> {
        self.parsed(what, "an integer")
    }

    fn float(&mut self, what: &str) -> Result<f64> {
        let v: f64 = self.parsed(what, "a number")?;
        if !v.is_finite() {
            return Err(self.err(format!(
                "{what} is {v}: the grading needs finite numbers; fix the solution (a diverged solve?) or the export"
            )));
        }
        Ok(v)
    }

    /// A quoted string (gmsh's names and string tags; they may hold spaces), or a bare token.
    fn string(&mut self, what: &str) -> Result<String> {
        self.skip_space();
        let rest = &self.text[self.at..];
        if let Some(quoted) = rest.strip_prefix('"') {
            let line = quoted.split('\n').next().unwrap_or("");
            let end = line.find('"').ok_or_else(|| {
                self.err(format!(
                    "{what}: the quoted string is not closed on its line: write the file again"
                ))
            })?;
            self.at += end + 2;
            return Ok(quoted[..end].to_string());
        }
        Ok(self.next(what)?.to_string())
    }

    /// The section's end marker.
    fn end(&mut self, marker: &str) -> Result<()> {
        let s = self.next(marker)?;
        if s != marker {
            return Err(self.err(format!(
                "expected {marker}, found '{s}': the counts of the section do not match its lines; write the file again"
            )));
        }
        Ok(())
    }

    /// Skip to the end marker of the section `name` (`$Name` read).
    fn skip(&mut self, name: &str) -> Result<()> {
        let marker = format!("$End{}", &name[1..]);
        while let Some(t) = self.token() {
            if t == marker {
                return Ok(());
            }
        }
        Err(self.err(format!(
            "{name} is not closed by {marker} (a truncated file?): write the file again"
        )))
    }
}

/// The MSH versions read.
#[derive(Clone, Copy, PartialEq, Eq)]
enum MshVersion {
    V22,
    V41,
}

/// A view (`$NodeData`, `$ElementData`) whose name is one of the fields read.
struct View {
    /// Per element (`$ElementData`) rather than per node.
    per_element: bool,
    name: String,
    time: f64,
    components: usize,
    /// Values by node or element tag: the start of the tag's components in `data`.
    start: HashMap<u64, usize>,
    data: Vec<f64>,
}

impl View {
    fn field(&self) -> String {
        format!(
            "{} \"{}\" (time {})",
            if self.per_element {
                "$ElementData"
            } else {
                "$NodeData"
            },
            self.name,
            self.time
        )
    }

    /// The values of the tags `tags` in order, or an error naming the first tag missing.
    fn gather(&self, tags: impl Iterator<Item = u64>, what: &str, path: &Path) -> Result<Vec<f64>> {
        let mut out = Vec::new();
        for tag in tags {
            let s = self.start.get(&tag).ok_or_else(|| {
                Error::input(
                    path,
                    self.field(),
                    format!(
                        "no value at {what} {tag} (the view has values at {} {what}s): write the field at every {what} of the bodies' triangles",
                        self.start.len()
                    ),
                )
            })?;
            out.extend_from_slice(&self.data[*s..*s + self.components]);
        }
        Ok(out)
    }
}

/// A 2D element of the file.
struct SurfaceElement {
    tag: u64,
    etype: usize,
    nodes: Vec<usize>,
    physicals: Vec<i64>,
}

/// What an ASCII MSH file holds, the views limited to the fields read.
struct MshFile {
    version: MshVersion,
    physical_names: Vec<(usize, i64, String)>,
    /// Physical tags by (dimension, entity tag), from `$Entities` (4.1).
    entities: Option<HashMap<(usize, i64), Vec<i64>>>,
    nodes: Vec<[f64; 3]>,
    node_tags: Vec<u64>,
    surface_elements: Vec<SurfaceElement>,
    views: Vec<View>,
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

/// Read gmsh's ASCII MSH file: the mesh, and the views named by `names`.
fn parse_msh_file(text: &str, path: &Path, names: &FieldNames) -> Result<MshFile> {
    let mut c = Cursor {
        text,
        at: 0,
        path,
        section: "file".into(),
    };
    let mut file = MshFile {
        version: MshVersion::V41,
        physical_names: Vec::new(),
        entities: None,
        nodes: Vec::new(),
        node_tags: Vec::new(),
        surface_elements: Vec::new(),
        views: Vec::new(),
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
                let version = c.next("the version")?;
                file.version = match version {
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
                    return Err(binary_msh(path));
                }
                c.count("the data size")?;
                c.end("$EndMeshFormat")?;
                format_seen = true;
            }
            "$PhysicalNames" => {
                let n = c.count("the number of physical names")?;
                for _ in 0..n {
                    let dim = c.count("a physical group's dimension")?;
                    let tag = c.int("a physical tag")?;
                    let name = c.string("a physical name")?;
                    file.physical_names.push((dim, tag, name));
                }
                c.end("$EndPhysicalNames")?;
            }
            "$Entities" if file.version == MshVersion::V41 => {
                file.entities = Some(read_entities(&mut c)?);
            }
            "$Nodes" => {
                read_msh_nodes(&mut c, &mut file, &mut node_index)?;
                nodes_seen = true;
            }
            "$Elements" => {
                read_msh_elements(&mut c, &mut file, &node_index)?;
                elements_seen = true;
            }
            "$NodeData" | "$ElementData" => {
                if let Some(view) = read_view(&mut c, tok == "$ElementData", names)? {
                    file.views.push(view);
                }
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

/// `$Entities` (4.1): the physical tags of each (dimension, entity).
fn read_entities(c: &mut Cursor) -> Result<HashMap<(usize, i64), Vec<i64>>> {
    let mut out = HashMap::new();
    let counts = [
        c.count("the number of points")?,
        c.count("the number of curves")?,
        c.count("the number of surfaces")?,
        c.count("the number of volumes")?,
    ];
    for (dim, n) in counts.into_iter().enumerate() {
        for _ in 0..n {
            let tag = c.int("an entity tag")?;
            for _ in 0..if dim == 0 { 3 } else { 6 } {
                c.float("an entity's coordinates")?;
            }
            let np = c.count("the number of physical tags")?;
            let mut physicals = Vec::new();
            for _ in 0..np {
                physicals.push(c.int("a physical tag")?);
            }
            out.insert((dim, tag), physicals);
            if dim > 0 {
                let nb = c.count("the number of bounding entities")?;
                for _ in 0..nb {
                    c.int("a bounding entity")?;
                }
            }
        }
    }
    c.end("$EndEntities")?;
    Ok(out)
}

fn read_msh_nodes(
    c: &mut Cursor,
    file: &mut MshFile,
    index: &mut HashMap<u64, usize>,
) -> Result<()> {
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
                c.int("a node block's entity")?;
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

fn read_msh_elements(
    c: &mut Cursor,
    file: &mut MshFile,
    index: &HashMap<u64, usize>,
) -> Result<()> {
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
                    tags.push(c.int("an element tag")?);
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
                let entity = c.int("an element block's entity")?;
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

/// Read a `$NodeData` or `$ElementData` view; `None` for a view of another name.
fn read_view(c: &mut Cursor, per_element: bool, names: &FieldNames) -> Result<Option<View>> {
    let section = if per_element {
        "$ElementData"
    } else {
        "$NodeData"
    };
    let n = c.count("the number of string tags")?;
    let mut strings = Vec::new();
    for _ in 0..n {
        strings.push(c.string("a string tag")?);
    }
    let name = strings.first().cloned().unwrap_or_default();
    if ![&names.displacement, &names.stress, &names.pressure].contains(&&name) {
        c.skip(section)?;
        return Ok(None);
    }
    c.section = format!("{section} \"{name}\"");
    let n = c.count("the number of real tags")?;
    let mut reals = Vec::new();
    for _ in 0..n {
        reals.push(c.float("a real tag")?);
    }
    let Some(&time) = reals.first() else {
        return Err(c.err(
            "the view has no real tag, so no time: write the time of the state as its first real tag",
        ));
    };
    let n = c.count("the number of integer tags")?;
    let mut ints = Vec::new();
    for _ in 0..n {
        ints.push(c.int("an integer tag")?);
    }
    let [_, components, count, ..] = ints[..] else {
        return Err(c.err(format!(
            "{} integer tags; a view has at least 3 (time step, components, number of values): write the file again",
            ints.len()
        )));
    };
    if components < 1 {
        return Err(c.err(format!(
            "{components} components: a view has at least one; write the file again"
        )));
    }
    let (components, count) = (components as usize, count.max(0) as usize);
    let mut view = View {
        per_element,
        name,
        time,
        components,
        start: HashMap::new(),
        data: Vec::new(),
    };
    let what = if per_element { "element" } else { "node" };
    for _ in 0..count {
        let tag: u64 = c.parsed(
            &format!("a{} {what} tag", if per_element { "n" } else { "" }),
            "a tag",
        )?;
        if view.start.insert(tag, view.data.len()).is_some() {
            return Err(c.err(format!(
                "{what} {tag} has two values in the view: write the file again"
            )));
        }
        for _ in 0..components {
            let v = c.float("a value")?;
            view.data.push(v);
        }
    }
    c.end(&format!("$End{}", &section[1..]))?;
    Ok(Some(view))
}

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
    let file = parse_msh_file(text, path, names)?;

    // The bodies' physical surfaces.
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
    let mut triangles: Vec<(u64, [usize; 3], u8)> = Vec::new();
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
    let body: Vec<u8> = triangles.iter().map(|t| t.2).collect();
    check_both_bodies(&body, path, "$Elements")?;

    // The nodes of the triangles, in the file's order.
    let mut point_of = vec![usize::MAX; file.nodes.len()];
    for (_, t, _) in &triangles {
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
    let node_tags = || kept.iter().map(|&n| file.node_tags[n]);
    let element_tags = || triangles.iter().map(|t| t.0);

    // The views, by time.
    let mut times: Vec<(f64, [Option<&View>; 3])> = Vec::new();
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
    if times.is_empty() {
        return Err(Error::input(
            path,
            format!("$NodeData \"{}\"", names.displacement),
            format!(
                "no $NodeData view named '{}': write the displacement as a $NodeData view of that name per time step, or name the view the file has",
                names.displacement
            ),
        ));
    }
    times.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut steps = Vec::with_capacity(times.len());
    for (time, [u, s, p]) in times {
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
        let label = |i: usize| format!("node {}", file.node_tags[kept[i]]);
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
                let values = s.gather(element_tags(), "element", path)?;
                let label = |i: usize| format!("element {}", triangles[i].0);
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
        steps.push((
            time,
            SolutionStep {
                mesh: mesh.clone(),
                displacement,
                stress,
                pressure,
            },
        ));
    }
    Ok(steps)
}
