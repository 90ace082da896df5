//! XML helpers shared by the VTU and PVD readers (quick-xml).

use crate::error::{Error, Result, line_of};
use std::collections::HashMap;
use std::path::Path;
/// A well-formedness error of quick-xml at byte `at` of `xml`.
pub(super) fn xml_error(
    path: &Path,
    xml: &str,
    at: u64,
    e: impl std::fmt::Display,
    what: &str,
) -> Error {
    Error::input(
        path,
        format!("XML (line {})", line_of(xml, at as usize)),
        format!(
            "{e}; the file is not well-formed XML (truncated or edited?): write the {what} again with the code that made it"
        ),
    )
}

/// An attribute as the file gives it: `key="value"`, or that it is missing.
pub(super) fn shown(key: &str, value: Option<&str>) -> String {
    match value {
        Some(v) => format!("{key}=\"{v}\""),
        None => format!("the attribute {key} is missing"),
    }
}

/// The attributes of an element by name.
pub(super) fn attributes(
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
