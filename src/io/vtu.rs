//! VTK XML unstructured grids (.vtu) in VTK's binary form: every array zlib-compressed in
//! blocks and appended raw after the XML header (`<AppendedData encoding="raw">`), the
//! layout ParaView's own writer uses by default; ParaView, VTK and meshio read it.
//!
//! Written by hand on flate2 because the Rust VTK crate does not fit: vtkio's last release
//! (0.6.3, 2021; 0.7 is a release candidate) writes compressed XML arrays only inline in
//! base64, a third larger than raw, and copies every array into its own model first. The
//! format is short: per array a header of UInt64 words [blocks, block size, size of the last
//! block, compressed size of each block], then the zlib streams of the blocks.

use crate::fe::Model;
use crate::metrics::ContactNode;
use crate::solve::State;
use flate2::{Compression, write::ZlibEncoder};
use std::fmt::Write as _;
use std::io::Write as _;

/// Uncompressed bytes per block (VTK's default block size).
pub const BLOCK_BYTES: usize = 1 << 15;

/// zlib level of the arrays written at every step. Measured on `solve --scene rates --level
/// 6` (zlib-rs): level 2 writes the 10 steps in about half the time of level 6 with files
/// 0.5% larger; level 1 (zlib-rs's quick strategy, static Huffman codes) makes the
/// floating-point arrays 6% larger than raw.
const STEP_LEVEL: u32 = 2;

/// zlib level of the mesh arrays, compressed once per series: the best. Measured on level 6
/// of `rates` (zlib-rs): the offsets compress to 0.35 of raw at level 9 against 0.65 at
/// level 6, the whole file 18.4 MB against 18.9 MB.
const MESH_LEVEL: u32 = 9;

/// A number type VTK knows, written little-endian.
pub trait Scalar: Copy + Send + Sync {
    /// VTK's name of the type.
    const VTK: &'static str;
    /// Append the little-endian bytes of `self`.
    fn put(self, out: &mut Vec<u8>);
}

macro_rules! scalar {
    ($t:ty, $name:literal) => {
        impl Scalar for $t {
            const VTK: &'static str = $name;
            fn put(self, out: &mut Vec<u8>) {
                out.extend_from_slice(&self.to_le_bytes());
            }
        }
    };
}
scalar!(f64, "Float64");
scalar!(i32, "Int32");
scalar!(i64, "Int64");
scalar!(u8, "UInt8");

/// One data array, compressed: its XML attributes and its appended bytes.
pub struct DataArray {
    name: String,
    vtk_type: &'static str,
    components: usize,
    component_names: Vec<String>,
    /// Header words and zlib blocks.
    bytes: Vec<u8>,
}

impl DataArray {
    /// The array `name` of `values`, `components` per tuple, compressed at zlib `level`
    /// block by block on the calling thread (`solve` writes on a thread of its own while the
    /// solver runs on the other core).
    pub fn new<T: Scalar>(name: &str, components: usize, values: &[T], level: u32) -> Self {
        let per_block = BLOCK_BYTES / std::mem::size_of::<T>();
        let blocks: Vec<Vec<u8>> = values
            .chunks(per_block)
            .map(|chunk| {
                let mut raw = Vec::with_capacity(BLOCK_BYTES);
                chunk.iter().for_each(|v| v.put(&mut raw));
                let mut z =
                    ZlibEncoder::new(Vec::with_capacity(raw.len() + 64), Compression::new(level));
                z.write_all(&raw).expect("writing to memory");
                z.finish().expect("writing to memory")
            })
            .collect();
        let total = std::mem::size_of_val(values);
        let last = match total % BLOCK_BYTES {
            0 if total > 0 => BLOCK_BYTES,
            r => r,
        };
        let mut bytes =
            Vec::with_capacity(8 * (3 + blocks.len()) + blocks.iter().map(Vec::len).sum::<usize>());
        for word in [blocks.len(), BLOCK_BYTES, last]
            .into_iter()
            .chain(blocks.iter().map(Vec::len))
        {
            bytes.extend_from_slice(&(word as u64).to_le_bytes());
        }
        blocks.iter().for_each(|b| bytes.extend_from_slice(b));
        DataArray {
            name: name.to_string(),
            vtk_type: T::VTK,
            components,
            component_names: Vec::new(),
            bytes,
        }
    }

    /// The same array with named components (e.g. s11 s22 s12).
    pub fn with_component_names(mut self, names: &[&str]) -> Self {
        self.component_names = names.iter().map(|s| s.to_string()).collect();
        self
    }
}

/// The mesh part of a .vtu file of a triangle mesh, compressed once: points and cells, and
/// cell arrays that do not change between steps.
pub struct Mesh {
    points: usize,
    cells: usize,
    coordinates: DataArray,
    topology: [DataArray; 3],
    cell_data: Vec<DataArray>,
}

impl Mesh {
    /// Points (x, y; z = 0) and triangles (three point indices each), with the cell arrays
    /// `cell_data` that every file of the mesh repeats.
    pub fn new(points: &[[f64; 2]], triangles: &[[usize; 3]], cell_data: Vec<DataArray>) -> Self {
        let coordinates: Vec<f64> = points.iter().flat_map(|p| [p[0], p[1], 0.0]).collect();
        let connectivity = triangles.iter().flatten().copied();
        let offsets = (1..=triangles.len()).map(|i| 3 * i);
        // Int32 indices unless the mesh needs more (zlib reads half the bytes).
        let [connectivity, offsets] = if 3 * triangles.len() <= i32::MAX as usize {
            let c: Vec<i32> = connectivity.map(|n| n as i32).collect();
            let o: Vec<i32> = offsets.map(|n| n as i32).collect();
            [
                DataArray::new("connectivity", 1, &c, MESH_LEVEL),
                DataArray::new("offsets", 1, &o, MESH_LEVEL),
            ]
        } else {
            let c: Vec<i64> = connectivity.map(|n| n as i64).collect();
            let o: Vec<i64> = offsets.map(|n| n as i64).collect();
            [
                DataArray::new("connectivity", 1, &c, MESH_LEVEL),
                DataArray::new("offsets", 1, &o, MESH_LEVEL),
            ]
        };
        let types = DataArray::new("types", 1, &vec![5u8; triangles.len()], MESH_LEVEL); // VTK_TRIANGLE
        Mesh {
            points: points.len(),
            cells: triangles.len(),
            coordinates: DataArray::new("Points", 3, &coordinates, MESH_LEVEL),
            topology: [connectivity, offsets, types],
            cell_data,
        }
    }

    /// The .vtu file of the mesh with point arrays `point_data` and cell arrays `cell_data`
    /// (after the mesh's own). The first three-component point array without component
    /// names is marked as the vectors.
    pub fn file(&self, point_data: &[DataArray], cell_data: &[DataArray]) -> Vec<u8> {
        let mut xml = String::from(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\">\n<UnstructuredGrid>\n",
        );
        let _ = writeln!(
            xml,
            "<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
            self.points, self.cells
        );
        let vectors = point_data
            .iter()
            .find(|a| a.components == 3 && a.component_names.is_empty())
            .map(|a| format!(" Vectors=\"{}\"", a.name))
            .unwrap_or_default();
        let sections: [(String, Vec<&DataArray>); 4] = [
            (format!("PointData{vectors}"), point_data.iter().collect()),
            (
                "CellData".into(),
                self.cell_data.iter().chain(cell_data).collect(),
            ),
            ("Points".into(), vec![&self.coordinates]),
            ("Cells".into(), self.topology.iter().collect()),
        ];
        let mut offset = 0;
        for (tag, arrays) in &sections {
            let _ = writeln!(xml, "<{tag}>");
            for a in arrays {
                let _ = write!(
                    xml,
                    "<DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\"",
                    a.vtk_type, a.name, a.components
                );
                for (i, c) in a.component_names.iter().enumerate() {
                    let _ = write!(xml, " ComponentName{i}=\"{c}\"");
                }
                let _ = writeln!(xml, " format=\"appended\" offset=\"{offset}\"/>");
                offset += a.bytes.len();
            }
            let _ = writeln!(xml, "</{}>", tag.split(' ').next().unwrap_or(tag));
        }
        xml.push_str("</Piece>\n</UnstructuredGrid>\n<AppendedData encoding=\"raw\">\n_");
        let tail = b"\n</AppendedData>\n</VTKFile>\n";
        let mut file = Vec::with_capacity(xml.len() + offset + tail.len());
        file.extend_from_slice(xml.as_bytes());
        for (_, arrays) in &sections {
            arrays.iter().for_each(|a| file.extend_from_slice(&a.bytes));
        }
        file.extend_from_slice(tail);
        file
    }
}

/// The .vtu files of a model's states: the mesh and the cell array `body` (1 or 2)
/// compressed once, the solution arrays at every step.
pub struct StateFile {
    mesh: Mesh,
}

impl StateFile {
    /// The writer of `model`'s states.
    pub fn new(model: &Model) -> Self {
        let points: Vec<[f64; 2]> = (0..model.n_nodes).map(|g| model.position(g)).collect();
        let triangles: Vec<[usize; 3]> = model.elements.iter().map(|e| e.nodes).collect();
        let body: Vec<i32> = model.elements.iter().map(|e| e.body as i32 + 1).collect();
        let body = DataArray::new("body", 1, &body, MESH_LEVEL);
        StateFile {
            mesh: Mesh::new(&points, &triangles, vec![body]),
        }
    }

    /// Both bodies at `state`: point data `displacement` (x, y, 0), `pressure` and
    /// `normal_jump` (at the slave nodes of Gamma_C from `contact`, zero elsewhere); cell
    /// data `body` and `stress` (s11 s22 s12, the solver's P0 stress). Units are the
    /// scene's. The von Mises stress is not written: it is a function of `stress`
    /// (docs/solve.md gives ParaView's Calculator expression), and it would be 15% of a file
    /// that does not compress.
    pub fn file(&self, state: &State, contact: &[ContactNode]) -> Vec<u8> {
        let np = self.mesh.points;
        let displacement: Vec<f64> = (0..np)
            .flat_map(|g| [state.u[2 * g], state.u[2 * g + 1], 0.0])
            .collect();
        let (mut pressure, mut jump) = (vec![0.0; np], vec![0.0; np]);
        for c in contact {
            pressure[c.node] = c.pressure;
            jump[c.node] = c.normal_jump;
        }
        let stress: Vec<f64> = state
            .sigma
            .iter()
            .flat_map(|s| [s[0], s[1], s[2]])
            .collect();
        self.mesh.file(
            &[
                DataArray::new("displacement", 3, &displacement, STEP_LEVEL),
                DataArray::new("pressure", 1, &pressure, STEP_LEVEL),
                DataArray::new("normal_jump", 1, &jump, STEP_LEVEL),
            ],
            &[DataArray::new("stress", 3, &stress, STEP_LEVEL)
                .with_component_names(&["s11", "s22", "s12"])],
        )
    }
}
