//! The paper study's part of docs/results.md.

use crate::error::Result;
use crate::report::markdown::{DOCS_REPORTS, Doc};
use std::path::Path;

/// The paper study's section of docs/results.md (no rates: one mesh per test).
pub fn section(_reports: &Path) -> Result<String> {
    let mut doc = Doc::new();
    doc.heading(
        2,
        format!("[`paper`]({DOCS_REPORTS}/paper/README.md): the paper's three tests regenerated"),
    )
    .bullet("Every figure of its section 5 and the numbers behind its words (no rates: one mesh per test).")
    .blank();
    Ok(doc.finish())
}
