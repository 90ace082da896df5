//! One error type for the library: every variant names the file, the field and the fix,
//! so the binary can print a single clear message and exit non-zero.

use std::path::PathBuf;

/// Errors raised by the library. Messages are complete sentences for the user.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Bad user input in a file (scene, study, .geo, .msh): file, field and fix.
    #[error("{file}: {field}: {message}")]
    Input {
        /// The offending file.
        file: PathBuf,
        /// The key, section or line that is wrong.
        field: String,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// gmsh is missing or failed.
    #[error("gmsh: {0}")]
    Gmsh(String),
    /// A solver did not converge; the message says which and why.
    #[error("solver did not converge: {0}")]
    NotConverged(String),
    /// I/O failure with the path involved.
    #[error("{path}: {source}")]
    Io {
        /// The path being read or written.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
}

/// Result alias for the library.
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    /// Bad input in `file` at `field`, with a message that says the fix.
    pub fn input(
        file: impl Into<PathBuf>,
        field: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        Error::Input {
            file: file.into(),
            field: field.into(),
            message: message.into(),
        }
    }
    /// I/O error on `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }
}

/// Deserialize TOML `text` read from `file`; a syntax error, unknown key or missing field
/// becomes one error naming the file, the line and the fix (`what` names the kind of file).
pub fn parse_toml<T: serde::de::DeserializeOwned>(
    text: &str,
    file: &std::path::Path,
    what: &str,
) -> Result<T> {
    toml::from_str(text).map_err(|e| {
        let start = e.span().map(|s| s.start.min(text.len()));
        let line = start
            .map(|s| format!(" (line {})", text[..s].lines().count().max(1)))
            .unwrap_or_default();
        // The key the error sits on, with its table: `key = ...` on the error's line and
        // the last `[table]` header above it.
        let key = start.and_then(|s| {
            let line_start = text[..s].rfind('\n').map_or(0, |i| i + 1);
            let (k, _) = text[line_start..].lines().next()?.split_once('=')?;
            let k = k.trim();
            let table = text[..line_start]
                .lines()
                .rev()
                .map(str::trim)
                .find(|l| l.starts_with('[') && l.ends_with(']'))
                .map(|l| l.trim_matches(|c| c == '[' || c == ']').to_string());
            (!k.is_empty()).then(|| match table {
                Some(t) => format!(" key {t}.{k}"),
                None => format!(" key {k}"),
            })
        });
        let line = format!("{line}{}", key.unwrap_or_default());
        Error::input(
            file,
            format!("toml{line}"),
            format!("{}; fix the {what}", e.message()),
        )
    })
}
