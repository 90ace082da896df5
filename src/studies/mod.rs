//! The study kinds, one folder each (what it measures in `mod.rs`, how it reports in
//! `report.rs`), and the one table that dispatches to them, [`KINDS`]. A new kind is its
//! folder and one line in that table.
//!
//! - [`convergence`]: a study file (studies/NAME.toml): rates of both cones on a mesh
//!   family against a fine reference or the exact solution, with Theorem 3.1's thresholds;
//! - [`two_size`]: a study file with a `[two_size]` table: each body's mesh refined alone;
//! - [`paper`]: the paper's three numerical tests regenerated;
//! - [`speed`]: what each accuracy costs, against the floor;
//! - [`stability`]: hard cases with every solver.

use crate::error::{Error, Result};
use crate::verify::jobs::Mode;
use crate::verify::kind::{Found, Kind, Outcome};
use crate::verify::study_file::{self, StudyFile};
use std::path::PathBuf;

/// Declares each kind's folder as a module and lists its `KIND` in [`KINDS`], so that a
/// kind is named once.
macro_rules! kinds {
    ($($kind:ident $([$($more:ident),*])?),* $(,)?) => {
        $(pub mod $kind;)*
        /// Every study kind, in the order `study NAME` tries them.
        pub const KINDS: &[&Kind] = &[$(&$kind::KIND, $($(&$kind::$more,)*)?)*];
    };
}

// The table of study kinds: one folder under src/studies/ each (a folder may hold more
// than one kind: the regularity studies' mesh families).
kinds![
    convergence,
    two_size,
    regularity[UNALIGNED_KIND, GRADED_KIND],
    paper,
    speed,
    stability,
];

/// A study to run: its kind and, for a kind found in files, the study file.
pub struct Study {
    /// The study's kind.
    pub kind: &'static Kind,
    /// The study file, for a kind found in files.
    pub file: Option<PathBuf>,
}

impl Study {
    /// The study called `name`: a built-in kind, a built-in study file or a path.
    pub fn resolve(name: &str) -> Result<Study> {
        if let Some(kind) = KINDS
            .iter()
            .find(|k| matches!(k.found, Found::BuiltIn) && k.name == name)
        {
            return Ok(Study { kind, file: None });
        }
        let path = study_file::resolve(name).ok_or_else(|| unknown_study(name))?;
        let file = StudyFile::load(&path)?;
        let kind = KINDS
            .iter()
            .find(|k| matches!(k.found, Found::Files { claims } if claims(&file)))
            .expect("every study file is claimed by a kind");
        Ok(Study {
            kind,
            file: Some(path),
        })
    }

    /// Every built-in study, name and description, sorted by name.
    pub fn list() -> Vec<(String, String)> {
        let mut all = study_file::list();
        all.extend(
            KINDS
                .iter()
                .filter(|k| matches!(k.found, Found::BuiltIn))
                .map(|k| (k.name.to_string(), k.description.to_string())),
        );
        all.sort();
        all
    }

    /// The study's name: its report folder under reports/.
    pub fn name(&self) -> String {
        match &self.file {
            Some(path) => path.file_stem().map_or_else(
                || path.display().to_string(),
                |s| s.to_string_lossy().to_string(),
            ),
            None => self.kind.name.to_string(),
        }
    }

    /// Run the study in `mode` (a shard gives no outcome; kinds that do not shard run whole).
    pub fn run(&self, mode: Mode) -> Result<Option<Box<dyn Outcome>>> {
        if mode != Mode::All && !self.kind.shards {
            return Err(Error::input(
                self.name(),
                "--shard/--merge",
                "only convergence studies (study files) run as shards; run this study without --shard or --merge",
            ));
        }
        (self.kind.run)(self.file.as_deref(), mode)
    }
}

impl Study {
    /// Judge the written report `dir` again from its CSVs and rewrite it, without solving.
    pub fn rejudge(&self, dir: &std::path::Path) -> Result<Box<dyn Outcome>> {
        let Some(rejudge) = self.kind.rejudge else {
            return Err(Error::input(
                self.name(),
                "--rejudge",
                format!(
                    "a {} study's report holds no judged rates to rejudge; run the study without --rejudge",
                    self.kind.name
                ),
            ));
        };
        rejudge(self.file.as_deref(), dir)
    }
}

/// The error for a study name that is neither built in nor a file, with the nearest built-in
/// names where a typo is likely (at most 2 edits away).
pub fn unknown_study(name: &str) -> Error {
    let names: Vec<String> = Study::list().into_iter().map(|(n, _)| n).collect();
    let distances: Vec<usize> = names.iter().map(|n| strsim::levenshtein(name, n)).collect();
    let best = distances.iter().copied().min().unwrap_or(usize::MAX);
    let near: Vec<&str> = names
        .iter()
        .zip(&distances)
        .filter(|(_, d)| **d == best && best <= 2)
        .map(|(n, _)| n.as_str())
        .collect();
    let hint = match near.as_slice() {
        [] => String::new(),
        [one] => format!("did you mean '{one}'? "),
        many => format!("did you mean one of {}? ", many.join(", ")),
    };
    Error::input(
        name,
        "study",
        format!(
            "no built-in study named '{name}' and no such file; {hint}built-in studies: {}",
            names.join(", ")
        ),
    )
}
