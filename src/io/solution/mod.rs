//! Readers of a 2D two-body contact solution computed by another code (GetFEM, FEniCSx,
//! MOOSE, scikit-fem, ...), for grading: P1 triangles of both bodies with a `body` mark,
//! nodal displacements, optional P0 stresses per triangle and an optional nodal pressure.
//!
//! - [`read_vtu`] (`vtu.rs`; its XML read by `vtu_xml.rs`, its arrays decoded by
//!   `payload.rs`): a VTK XML unstructured grid (.vtu) with one piece, arrays in every
//!   layout VTK and its exporters write: `ascii`, inline `binary` (base64) and `appended`
//!   (`raw` bytes or `base64`), uncompressed or zlib-compressed in blocks
//!   (`vtkZLibDataCompressor`), UInt32 or UInt64 block headers, either byte order, every
//!   VTK number type. The project's own writer ([`super::vtu`]) is read bit for bit.
//! - [`read_pvd`] (`pvd.rs`): the (time, file) list of a ParaView collection (.pvd).
//! - [`read_msh_solution`] (`msh.rs`): gmsh's ASCII MSH 4.1 or 2.2 with the solution as
//!   `$NodeData`/`$ElementData` views, one per field and time, read by the MSH module
//!   ([`crate::mesh::msh::file`]).
//!
//! Every refusal is an [`Error::input`](crate::error::Error::input) naming the file, the
//! field (`PointData/displacement`, `CellData/body`, `Cells`, `$NodeData "displacement"
//! (line 40)`, ...) and the fix. A field missing lists the fields of its kind the file has
//! and, for one of the right number of components, the grade flag that reads it (`pass
//! --displacement u`); a stress or pressure named other than by default is required. Counts
//! in a file are checked against the bytes present before anything is allocated from them,
//! so a corrupt header cannot ask for absurd memory. What must vanish (z, a third
//! displacement component, the z row of a stress) or agree (s12 and s21) is judged to
//! [`ROUNDING`] epsilons of the precision stored, relative to its array's size
//! (`checks.rs`).
//!
//! Written by hand on quick-xml (the XML), base64 and flate2 (zlib) because no maintained
//! Rust crate reads these files whole. Checked: vtkio's last release is 0.6.3 (2021); its
//! 0.7.0-rc2 (a release candidate) reads appended raw data but slices the appended bytes
//! by the header's counts unchecked (a truncated file panics) and pins quick-xml 0.22 (for
//! MSH, see [`crate::mesh::msh`]). The appended raw layout is not well-formed XML (binary
//! bytes after `_`), so the file is split there before the XML is parsed, as VTK's own
//! reader does.

mod checks;
mod msh;
mod payload;
mod pvd;
mod vtu;
mod vtu_xml;
mod xml;

pub use msh::{parse_msh_solution, read_msh_solution};
pub use pvd::{parse_pvd, read_pvd};
pub use vtu::{parse_vtu, read_vtu};

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

impl FieldNames {
    /// Whether the stress is named other than by default (`--stress`): a file without it
    /// is then refused, where by default the stress is optional.
    pub fn stress_named(&self) -> bool {
        self.stress != FieldNames::default().stress
    }

    /// Whether the pressure is named other than by default (`--pressure`): a file without
    /// it is then refused, where by default the pressure is optional.
    pub fn pressure_named(&self) -> bool {
        self.pressure != FieldNames::default().pressure
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
