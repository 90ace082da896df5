//! The reporting toolkit every study kind writes with: report folders checked before
//! computing and swapped in whole ([`folder`]), Markdown documents and tables
//! ([`markdown`]), the PNG charts ([`plot`]), and the output of
//! `solve`, one case ([`solve_output`]). Each kind's own report is in its folder under
//! `crate::studies`.

pub mod folder;
pub mod markdown;
pub mod plot;
pub mod solve_output;

pub use folder::{Output, Staging, check_writable, remove_live, reports_dir, write_folder};
