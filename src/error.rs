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
        let line = e
            .span()
            .map(|s| {
                format!(
                    " (line {})",
                    text[..s.start.min(text.len())].lines().count().max(1)
                )
            })
            .unwrap_or_default();
        Error::input(
            file,
            format!("toml{line}"),
            format!("{}; fix the {what}", e.message()),
        )
    })
}
