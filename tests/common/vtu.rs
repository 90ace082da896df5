//! A small VTU reader, independent of the writer in `contact_rates::io::vtu`: it parses the
//! XML header with string search, then decodes each appended raw array (UInt64 header
//! words: blocks, block size, last block size, compressed sizes; then zlib streams) with
//! flate2's decoder. Only what the program writes is supported, and everything else is an
//! assertion failure.

use std::collections::HashMap;
use std::io::Read;
use std::path::Path;

/// One decoded array.
pub struct Array {
    /// VTK type name (Float64, Int32, Int64, UInt8).
    pub vtk_type: String,
    /// Components per tuple.
    pub components: usize,
    /// Little-endian bytes.
    pub bytes: Vec<u8>,
}

/// A decoded .vtu file: counts, and arrays by section ("PointData", "CellData", "Points",
/// "Cells") and name.
pub struct Vtu {
    pub points: usize,
    pub cells: usize,
    pub arrays: HashMap<(String, String), Array>,
}

fn attribute(tag: &str, name: &str) -> Option<String> {
    let key = format!(" {name}=\"");
    let k = tag.find(&key)? + key.len();
    Some(tag[k..k + tag[k..].find('"').unwrap()].to_string())
}

/// Read and decode `path`.
pub fn read(path: &Path) -> Vtu {
    let raw = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let marker = b"<AppendedData encoding=\"raw\">";
    let at = raw
        .windows(marker.len())
        .position(|w| w == marker)
        .expect("an AppendedData section");
    let header = std::str::from_utf8(&raw[..at]).expect("an XML header");
    let underscore = at + raw[at..].iter().position(|&b| b == b'_').unwrap() + 1;
    let tail = b"\n</AppendedData>\n</VTKFile>\n";
    assert!(raw.ends_with(tail), "the file ends with the closing tags");
    let data = &raw[underscore..raw.len() - tail.len()];
    let root = &header[header.find("<VTKFile").unwrap()..];
    let root = &root[..root.find('>').unwrap()];
    assert_eq!(
        attribute(root, "byte_order").as_deref(),
        Some("LittleEndian")
    );
    assert_eq!(attribute(root, "header_type").as_deref(), Some("UInt64"));
    assert_eq!(
        attribute(root, "compressor").as_deref(),
        Some("vtkZLibDataCompressor")
    );
    let piece = &header[header.find("<Piece").unwrap()..];
    let points: usize = attribute(piece, "NumberOfPoints").unwrap().parse().unwrap();
    let cells: usize = attribute(piece, "NumberOfCells").unwrap().parse().unwrap();
    let mut arrays = HashMap::new();
    let mut section = String::new();
    for line in header.lines() {
        for s in ["PointData", "CellData", "Points", "Cells"] {
            if line.starts_with(&format!("<{s}>")) || line.starts_with(&format!("<{s} ")) {
                section = s.to_string();
            }
        }
        if !line.starts_with("<DataArray") {
            continue;
        }
        assert_eq!(attribute(line, "format").as_deref(), Some("appended"));
        let offset: usize = attribute(line, "offset").unwrap().parse().unwrap();
        let word = |i: usize| {
            u64::from_le_bytes(data[offset + 8 * i..offset + 8 * i + 8].try_into().unwrap())
                as usize
        };
        let (blocks, block_size, last_size) = (word(0), word(1), word(2));
        let mut bytes = Vec::new();
        let mut at = offset + 8 * (3 + blocks);
        for b in 0..blocks {
            let size = word(3 + b);
            let mut block = Vec::new();
            flate2::read::ZlibDecoder::new(&data[at..at + size])
                .read_to_end(&mut block)
                .unwrap();
            let expected = if b + 1 == blocks {
                last_size
            } else {
                block_size
            };
            assert_eq!(block.len(), expected, "block {b} of {line}");
            bytes.extend(block);
            at += size;
        }
        let name = attribute(line, "Name").unwrap();
        let array = Array {
            vtk_type: attribute(line, "type").unwrap(),
            components: attribute(line, "NumberOfComponents").map_or(1, |c| c.parse().unwrap()),
            bytes,
        };
        arrays.insert((section.clone(), name), array);
    }
    Vtu {
        points,
        cells,
        arrays,
    }
}

impl Vtu {
    fn array(&self, section: &str, name: &str, vtk_type: &str) -> &Array {
        let a = self
            .arrays
            .get(&(section.to_string(), name.to_string()))
            .unwrap_or_else(|| panic!("no array {section}/{name}"));
        assert_eq!(a.vtk_type, vtk_type, "{section}/{name}");
        a
    }

    /// A Float64 array's values and components.
    pub fn f64(&self, section: &str, name: &str) -> (Vec<f64>, usize) {
        let a = self.array(section, name, "Float64");
        let v = a
            .bytes
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect();
        (v, a.components)
    }

    /// An Int32 array's values.
    pub fn i32(&self, section: &str, name: &str) -> Vec<i32> {
        let a = self.array(section, name, "Int32");
        a.bytes
            .chunks_exact(4)
            .map(|c| i32::from_le_bytes(c.try_into().unwrap()))
            .collect()
    }

    /// A UInt8 array's values.
    pub fn u8(&self, section: &str, name: &str) -> Vec<u8> {
        self.array(section, name, "UInt8").bytes.clone()
    }
}
