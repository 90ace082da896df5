//! The tokenizer of ASCII MSH both readers share: whitespace-separated tokens with their
//! line, numbers, gmsh's quoted strings, section end markers and skipped sections, each
//! refusal worded in the reader's [`Voice`].

use crate::error::{Error, Result, line_of};
use std::path::Path;

/// How a reader words a malformed file. The two readers' files call for different fixes:
/// a mesh of the project's cache is regenerated, a file of another code is written again.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Voice {
    /// A mesh gmsh wrote for a scene ([`super::read`]): the field is the section, the fix to
    /// delete the file and let the program regenerate it.
    Cache,
    /// A file another code wrote ([`super::file`]): the field is the section and its line,
    /// the fix to write the file again.
    Outside,
}

/// A cursor over the tokens of an ASCII MSH text.
#[derive(Clone)]
pub struct Cursor<'a> {
    text: &'a str,
    at: usize,
    path: &'a Path,
    /// The section read, for errors.
    pub section: String,
    voice: Voice,
}

impl<'a> Cursor<'a> {
    /// A cursor at the start of `text` (read from `path`), in section `section`.
    pub fn new(text: &'a str, path: &'a Path, section: &str, voice: Voice) -> Self {
        Cursor {
            text,
            at: 0,
            path,
            section: section.to_string(),
            voice,
        }
    }

    /// The file read, for errors.
    pub fn path(&self) -> &'a Path {
        self.path
    }

    /// The field of an error here: the section, and for an outside file its line.
    pub fn field(&self) -> String {
        match self.voice {
            Voice::Cache => self.section.clone(),
            Voice::Outside => format!("{} (line {})", self.section, line_of(self.text, self.at)),
        }
    }

    /// The file refused here with `message`, in the reader's voice.
    pub fn err(&self, message: impl Into<String>) -> Error {
        let message = message.into();
        match self.voice {
            Voice::Cache => Error::input(
                self.path,
                self.field(),
                format!(
                    "{message}; the file is not a valid gmsh MSH 4.1 ASCII mesh: delete it and let the program regenerate it"
                ),
            ),
            Voice::Outside => Error::input(self.path, self.field(), message),
        }
    }

    fn skip_space(&mut self) {
        let rest = &self.text[self.at..];
        self.at += rest.len() - rest.trim_start().len();
    }

    /// The next token, or `None` at the end of the text.
    pub fn token(&mut self) -> Option<&'a str> {
        self.skip_space();
        let rest = &self.text[self.at..];
        if rest.is_empty() {
            return None;
        }
        let end = rest.find(char::is_whitespace).unwrap_or(rest.len());
        self.at += end;
        Some(&rest[..end])
    }

    /// The next token, `what` the file should hold there.
    pub fn next(&mut self, what: &str) -> Result<&'a str> {
        self.token().ok_or_else(|| {
            self.err(match self.voice {
                Voice::Cache => "unexpected end of file".to_string(),
                Voice::Outside => format!(
                    "the file ends where {what} is expected (a truncated file?): write it again"
                ),
            })
        })
    }

    /// The refusal of token `s` where `what`, `kind` (a number, an integer, ...), is expected.
    fn not_a(&self, what: &str, kind: &str, s: &str) -> Error {
        self.err(match self.voice {
            Voice::Cache => format!("expected {kind}, found '{s}'"),
            Voice::Outside => format!(
                "{what}: '{s}' is not {kind}; the file is not valid MSH: write it again with gmsh or meshio"
            ),
        })
    }

    /// The next token parsed as `T`; `what` it is and the `kind` of text it must be.
    pub fn parsed<T: std::str::FromStr>(&mut self, what: &str, kind: &str) -> Result<T> {
        let s = self.next(what)?;
        s.parse().map_err(|_| self.not_a(what, kind, s))
    }

    /// A count (a non-negative integer).
    pub fn count(&mut self, what: &str) -> Result<usize> {
        self.parsed(what, "a non-negative integer")
    }

    /// An integer of type `T` (a tag).
    pub fn int<T: std::str::FromStr>(&mut self, what: &str) -> Result<T> {
        self.parsed(what, "an integer")
    }

    /// A finite number.
    pub fn float(&mut self, what: &str) -> Result<f64> {
        let s = self.next(what)?;
        let v: f64 = s.parse().map_err(|_| self.not_a(what, "a number", s))?;
        if !v.is_finite() {
            return Err(self.err(match self.voice {
                Voice::Cache => format!("non-finite coordinate '{s}'"),
                Voice::Outside => format!(
                    "{what} is {v}: the grading needs finite numbers; fix the solution (a diverged solve?) or the export"
                ),
            }));
        }
        Ok(v)
    }

    /// A quoted string (gmsh's names and string tags; they may hold spaces), or a bare token.
    pub fn string(&mut self, what: &str) -> Result<String> {
        self.skip_space();
        let rest = &self.text[self.at..];
        if let Some(quoted) = rest.strip_prefix('"') {
            let line = quoted.split('\n').next().unwrap_or("");
            let end = line.find('"').ok_or_else(|| {
                self.err(format!(
                    "{what}: the quoted string is not closed on its line: write the file again"
                ))
            })?;
            self.at += end + 2;
            return Ok(quoted[..end].to_string());
        }
        Ok(self.next(what)?.to_string())
    }

    /// The section's end marker.
    pub fn end(&mut self, marker: &str) -> Result<()> {
        let s = self.next(marker)?;
        if s != marker {
            return Err(self.err(match self.voice {
                Voice::Cache => format!("expected '{marker}', found '{s}'"),
                Voice::Outside => format!(
                    "expected {marker}, found '{s}': the counts of the section do not match its lines; write the file again"
                ),
            }));
        }
        Ok(())
    }

    /// Skip to the end marker of the section `name` (`$Name` read).
    pub fn skip(&mut self, name: &str) -> Result<()> {
        let marker = format!("$End{}", &name[1..]);
        while let Some(t) = self.token() {
            if t == marker {
                return Ok(());
            }
        }
        Err(self.err(match self.voice {
            Voice::Cache => format!("section {name} is not closed"),
            Voice::Outside => format!(
                "{name} is not closed by {marker} (a truncated file?): write the file again"
            ),
        }))
    }
}
