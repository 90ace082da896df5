//! The reporting toolkit every study kind writes with: report folders checked before
//! computing and swapped in whole ([`folder`]), Markdown documents and tables
//! ([`markdown`]), the PNG charts ([`plot`]), and the output of
//! `solve`, one case ([`solve_output`]). Each kind's own report is in its folder under
//! `crate::studies`.

pub mod folder;
pub mod markdown;
pub mod plot;
pub mod solve_output;

pub use folder::{
    Output, Staging, check_writable, remove_live, reports_dir, scratch_reports_dir, write_folder,
};

/// A study report's opening: the title `Study `name``, the study's description and its
/// scene's name and description, each a paragraph.
pub fn study_heading(
    doc: &mut markdown::Doc,
    name: &str,
    description: &str,
    scene: &crate::scene::Scene,
) {
    doc.heading(1, format!("Study `{name}`"))
        .paragraph(description)
        .paragraph(format!("Scene `{}`: {}", scene.name, scene.description));
}
