//! The reader of a ParaView collection (.pvd): the (time, dataset file) pairs of a time
//! series, each file resolved against the .pvd's folder.

use super::xml::{attributes, shown, xml_error};
use crate::error::{Error, Result, line_of};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

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
    let mut reader = quick_xml::Reader::from_str(text);
    let mut stack: Vec<String> = Vec::new();
    let mut collection = Collection {
        path,
        folder: path.parent().unwrap_or(Path::new("")),
        steps: Vec::new(),
        of_time: HashMap::new(),
    };
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
                check_root(&e, path)?;
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
            (Some("Collection"), "DataSet") => collection.dataset(&e)?,
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
    if collection.steps.is_empty() {
        return Err(Error::input(
            path,
            "Collection",
            "the collection lists no <DataSet>: give the .pvd of the time series, one DataSet per step",
        ));
    }
    Ok(collection.steps)
}

/// Refuse a root `<VTKFile>` of a type other than `Collection`.
fn check_root(e: &quick_xml::events::BytesStart, path: &Path) -> Result<()> {
    let a = attributes(e, path, "VTKFile")?;
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
    Ok(())
}

/// The steps of a collection read so far.
struct Collection<'a> {
    path: &'a Path,
    /// The folder the datasets' files are relative to.
    folder: &'a Path,
    steps: Vec<(f64, PathBuf)>,
    /// The dataset of each time read (0 and -0 alike).
    of_time: HashMap<u64, usize>,
}

impl Collection<'_> {
    /// A `<DataSet>`: its time, finite and not read before, and its file.
    fn dataset(&mut self, e: &quick_xml::events::BytesStart) -> Result<()> {
        let (path, i) = (self.path, self.steps.len());
        let field = |key: &str| format!("Collection/DataSet[{i}]/{key}");
        let a = attributes(e, path, &field("timestep"))?;
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
            Some(f) if !f.is_empty() => self.folder.join(f),
            _ => {
                return Err(Error::input(
                    path,
                    field("file"),
                    "the dataset names no file: give each DataSet file=\"name.vtu\" (relative to the .pvd's folder)",
                ));
            }
        };
        if let Some(&j) = self.of_time.get(&(time + 0.0).to_bits()) {
            return Err(Error::input(
                path,
                field("timestep"),
                format!(
                    "datasets {j} and {i} both have timestep {time}: one file per time is read; if they are parts of one state (part=...), merge them (ParaView's Merge Blocks, then Save Data)"
                ),
            ));
        }
        self.of_time.insert((time + 0.0).to_bits(), i);
        self.steps.push((time, file));
        Ok(())
    }
}
