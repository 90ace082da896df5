//! What a study kind is: a name, a description, where its studies come from, and a run whose
//! [`Outcome`] writes the report. The kinds are listed in one table,
//! `crate::studies::KINDS`; a new kind is its folder under `src/studies/` and one line there.

use crate::error::Result;
use crate::verify::jobs::Mode;
use crate::verify::study_file::StudyFile;
use std::path::Path;

/// Where a kind's studies come from.
pub enum Found {
    /// One built-in study, named after the kind (`study paper`).
    BuiltIn,
    /// Study files (studies/NAME.toml or a path) for which `claims` holds; the claims of the
    /// kinds found in files exclude each other.
    Files {
        /// Whether a study file is of this kind.
        claims: fn(&StudyFile) -> bool,
    },
}

/// One study kind: a line of the table `crate::studies::KINDS`.
pub struct Kind {
    /// The kind's name: the study's name for a built-in kind.
    pub name: &'static str,
    /// One line for `study list`.
    pub description: &'static str,
    /// Where its studies come from.
    pub found: Found,
    /// Whether its studies run as shards (`--shard i/n`, `--merge`).
    pub shards: bool,
    /// Run one study: `file` is the study file for a kind found in files. A shard gives no
    /// outcome (its records are the result).
    pub run: fn(file: Option<&Path>, mode: Mode) -> Result<Option<Box<dyn Outcome>>>,
    /// Judge a written report `dir` again from its CSVs, without solving (`study NAME
    /// --rejudge`); None for a kind whose report holds no judged rates.
    pub rejudge: Option<fn(file: Option<&Path>, dir: &Path) -> Result<Box<dyn Outcome>>>,
    /// The kind's part of docs/results.md (Markdown), read from the committed reports under
    /// `reports`; None for a kind with no part there.
    pub results: Option<fn(reports: &Path) -> Result<String>>,
}

/// What a study measured: it writes its report folder and says what the console shows.
pub trait Outcome {
    /// Write the report into `dir` (normally reports/NAME), all or nothing.
    fn write(&self, dir: &Path) -> Result<()>;
    /// What the console shows after the report was written into `dir`: whole lines, each
    /// ending in a newline, the last naming the report (the CLI prints it as it is).
    fn console(&self, dir: &Path) -> String;
    /// Warnings about the scene, for the user.
    fn warnings(&self) -> &[String] {
        &[]
    }
    /// The thresholds missed (`fail`), one sentence each (empty: none failed). Only these
    /// make `study` exit non-zero.
    fn failures(&self) -> Vec<String> {
        Vec::new()
    }
    /// The thresholds neither met nor missed (`unverified`: the errors support no rate and
    /// the last successive rate is not below it), one sentence each.
    fn unverified(&self) -> Vec<String> {
        Vec::new()
    }
}
