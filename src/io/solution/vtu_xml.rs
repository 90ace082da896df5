//! What the XML of a .vtu says: the `<AppendedData>` split off first (its raw layout holds
//! bytes that are not XML), then `<VTKFile>` (byte order, header type, compressor), the one
//! `<Piece>` (its counts) and the `<DataArray>`s of its sections, read event by event.

use super::payload::{Appended, ArrayInfo, BinaryFormat, ByteOrder, Layout, Section};
use super::xml::{attributes, shown, xml_error};
use crate::error::{Error, Result, line_of};
use std::collections::HashMap;
use std::path::Path;

/// What the XML of a .vtu says.
pub(super) struct VtuDocument {
    /// How its binary arrays are stored.
    pub(super) format: BinaryFormat,
    /// `NumberOfPoints` of the piece.
    pub(super) points: usize,
    /// `NumberOfCells` of the piece.
    pub(super) cells: usize,
    /// The DataArrays of the piece's sections, in the file's order.
    pub(super) arrays: Vec<ArrayInfo>,
}

/// The `<AppendedData>` of a .vtu, if any, and the XML without it (the raw layout holds
/// bytes that are not XML).
pub(super) fn split_appended<'a>(
    bytes: &'a [u8],
    path: &Path,
) -> Result<(String, Option<Appended<'a>>)> {
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
pub(super) fn parse_vtu_xml(xml: &str, path: &Path) -> Result<VtuDocument> {
    use quick_xml::events::Event;
    let mut reader = quick_xml::Reader::from_str(xml);
    let mut read = XmlRead {
        xml,
        path,
        stack: Vec::new(),
        doc: VtuDocument {
            format: BinaryFormat {
                order: ByteOrder::Little,
                header64: false,
                compressed: false,
            },
            points: 0,
            cells: 0,
            arrays: Vec::new(),
        },
        root_seen: false,
        pieces: 0,
        open: None,
    };
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
                read.close();
                continue;
            }
            Event::Text(t) => {
                if let Some(a) = read.open.as_mut() {
                    a.text.push_str(&t);
                }
                continue;
            }
            _ => continue,
        };
        read.element(&e, empty, at)?;
    }
    read.finish()
}

/// The reading of a .vtu's XML, event by event.
struct XmlRead<'a> {
    xml: &'a str,
    path: &'a Path,
    /// The names of the elements open, outermost first.
    stack: Vec<String>,
    doc: VtuDocument,
    root_seen: bool,
    pieces: usize,
    /// The DataArray being read (its text arrives in events of its own).
    open: Option<ArrayInfo>,
}

impl XmlRead<'_> {
    /// An element closes: a DataArray read is complete.
    fn close(&mut self) {
        if self.stack.pop().as_deref() == Some("DataArray")
            && let Some(a) = self.open.take()
        {
            self.doc.arrays.push(a);
        }
    }

    /// An element opens (at byte `at`; `empty`: `<... />`): the root, the piece and the
    /// DataArrays of its sections are read, the rest passed over.
    fn element(&mut self, e: &quick_xml::events::BytesStart, empty: bool, at: u64) -> Result<()> {
        let path = self.path;
        let name = e.name().as_ref().to_string();
        let parent = self.stack.last().map(String::as_str);
        match (parent, name.as_str()) {
            (None, "VTKFile") => {
                self.root_seen = true;
                let a = attributes(e, path, "VTKFile")?;
                read_root(&a, &mut self.doc, path)?;
            }
            (None, other) => {
                return Err(Error::input(
                    path,
                    format!("XML (line {})", line_of(self.xml, at as usize)),
                    format!(
                        "the root element is <{other}>, not <VTKFile>: give a VTK XML unstructured grid (.vtu)"
                    ),
                ));
            }
            (Some("UnstructuredGrid"), "Piece") => {
                self.pieces += 1;
                if self.pieces > 1 {
                    return Err(Error::input(
                        path,
                        "Piece",
                        "the grid has more than one <Piece>: one piece is read; merge the pieces into one (ParaView's Merge Blocks, then Save Data), or write the solution from one process",
                    ));
                }
                let a = attributes(e, path, "Piece")?;
                self.doc.points = count_attribute(&a, "NumberOfPoints", None, path, "Piece")?;
                self.doc.cells = count_attribute(&a, "NumberOfCells", None, path, "Piece")?;
            }
            (Some(section), "DataArray") => {
                let section = match section {
                    "PointData" => Some(Section::PointData),
                    "CellData" => Some(Section::CellData),
                    "Points" => Some(Section::Points),
                    "Cells" => Some(Section::Cells),
                    _ => None,
                };
                let stack = &self.stack;
                let in_piece = stack.len() >= 2 && stack[stack.len() - 2] == "Piece";
                if let (Some(section), true) = (section, in_piece) {
                    let a = attributes(e, path, section.name())?;
                    let info = array_info(&a, section, path)?;
                    if empty {
                        self.doc.arrays.push(info);
                    } else {
                        self.open = Some(info);
                    }
                }
            }
            _ => {}
        }
        if !empty {
            self.stack.push(name);
        }
        Ok(())
    }

    /// The document, once the XML is read whole: closed, with a root and a piece.
    fn finish(self) -> Result<VtuDocument> {
        let path = self.path;
        if let Some(unclosed) = self.stack.last() {
            return Err(Error::input(
                path,
                "XML",
                format!(
                    "<{unclosed}> is not closed (a truncated file?): write the file again with the code that made it"
                ),
            ));
        }
        if !self.root_seen {
            return Err(Error::input(
                path,
                "VTKFile",
                "no <VTKFile> element (an empty or truncated file?): give a VTK XML unstructured grid (.vtu)",
            ));
        }
        if self.pieces == 0 {
            return Err(Error::input(
                path,
                "Piece",
                "the grid has no <Piece> inside <UnstructuredGrid>: write the mesh and the solution into the file",
            ));
        }
        Ok(self.doc)
    }
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
    doc.format.order = match a.get("byte_order").map(String::as_str) {
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
    doc.format.header64 = match a.get("header_type").map(String::as_str) {
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
    doc.format.compressed = match a.get("compressor").map(String::as_str) {
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
