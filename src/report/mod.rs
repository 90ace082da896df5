//! Reports: one module per study kind, each writing its folder (CSV tables, PNG plots, a
//! README.md) atomically through [`folder`] and formatting what the console shows.
//!
//! - [`folder`]: report folders checked before computing and swapped in whole;
//! - [`study`]: a convergence study; [`paper`], [`speed`], [`stability`]: the other kinds;
//! - [`run`]: the output of `solve` (one case);
//! - [`plot`]: the PNG charts all of them draw;
//! - [`results`]: the README's Results section, read back from the reports' CSVs.

pub mod folder;
pub mod paper;
pub mod plot;
pub mod results;
pub mod run;
pub mod speed;
pub mod stability;
pub mod study;
pub mod two_size;

pub use folder::{Output, Staging, check_writable, remove_live, reports_dir, write_folder};

use crate::error::Result;
use crate::study::Outcome;
use std::path::Path;

/// Write the report of `outcome` into `dir` (normally reports/NAME).
pub fn write(outcome: &Outcome, dir: &Path) -> Result<()> {
    match outcome {
        Outcome::Convergence(r) => study::write_study(r, dir),
        Outcome::TwoSize(r) => two_size::write_two_size(r, dir),
        Outcome::Paper(r) => paper::write_paper(r, dir),
        Outcome::Speed(r) => speed::write_speed(r, dir),
        Outcome::Stability(r) => stability::write_stability(r, dir),
    }
}

/// What the console shows after `outcome`'s report was written into `dir`.
pub fn console(outcome: &Outcome, dir: &Path) -> String {
    match outcome {
        Outcome::Convergence(r) => study::console(r, dir),
        Outcome::TwoSize(r) => two_size::console(r, dir),
        Outcome::Paper(r) => paper::console(r, dir),
        Outcome::Speed(r) => speed::console(r, dir),
        Outcome::Stability(r) => stability::console(r, dir),
    }
}
