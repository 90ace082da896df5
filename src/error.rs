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
    /// A bad command-line value: the option as given, what is wrong and how to fix it.
    #[error("{option}: {message}")]
    Argument {
        /// The option and its value, as on the command line.
        option: String,
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

/// The 1-based line of byte `at` in `text`, for a field such as `XML (line 12)`.
pub fn line_of(text: &str, at: usize) -> usize {
    1 + text.as_bytes()[..at.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
}

/// Deserialize TOML `text` read from `file`; a syntax error, unknown key or missing field
/// becomes one error naming the file, the line, the key (as a path: `bodies[0].young`) and
/// the fix (`what` names the kind of file).
pub fn parse_toml<T: serde::de::DeserializeOwned>(
    text: &str,
    file: &std::path::Path,
    what: &str,
) -> Result<T> {
    let document = toml::Deserializer::parse(text).map_err(|e| {
        let key = syntax_error_key(text, e.span());
        toml_error(text, file, what, &e, key)
    })?;
    // serde_path_to_error tracks where the deserializer stood: the key of a bad value, or
    // the table of a missing or unknown field (whose name the message gives).
    serde_path_to_error::deserialize(document).map_err(|e| {
        let table = e.path().to_string();
        let table = if table == "." { String::new() } else { table };
        let named = ["missing field `", "unknown field `"]
            .iter()
            .find_map(|p| e.inner().message().strip_prefix(p))
            .and_then(|rest| rest.split_once('`'))
            .map(|(name, _)| name.to_string());
        // An unknown field's path ends with it already; a missing one's is its table.
        let key = match named {
            Some(name) if table.is_empty() => Some(name),
            Some(name) if table != name && !table.ends_with(&format!(".{name}")) => {
                Some(format!("{table}.{name}"))
            }
            _ => (!table.is_empty()).then_some(table),
        };
        toml_error(text, file, what, e.inner(), key)
    })
}

/// The key a TOML syntax error sits on, with its table: `key = ...` on the error's line
/// and the last `[table]` header above it.
fn syntax_error_key(text: &str, span: Option<std::ops::Range<usize>>) -> Option<String> {
    let s = span?.start.min(text.len());
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
        Some(t) => format!("{t}.{k}"),
        None => k.to_string(),
    })
}

/// The error of a TOML file: field `toml (line N) key KEY`, the parser's message and the fix.
fn toml_error(
    text: &str,
    file: &std::path::Path,
    what: &str,
    e: &toml::de::Error,
    key: Option<String>,
) -> Error {
    let line = e
        .span()
        .map(|s| {
            format!(
                " (line {})",
                1 + text[..s.start.min(text.len())].matches('\n').count()
            )
        })
        .unwrap_or_default();
    let key = key.map(|k| format!(" key {k}")).unwrap_or_default();
    Error::input(
        file,
        format!("toml{line}{key}"),
        format!("{}; fix the {what}", e.message()),
    )
}
