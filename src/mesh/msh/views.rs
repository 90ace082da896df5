//! gmsh's views, `$NodeData` and `$ElementData`: one field at one time, as values by node
//! or element tag (how gmsh and meshio store a solution in MSH 4.1 and 2.2 alike).

use super::cursor::Cursor;
use crate::error::{Error, Result};
use std::collections::HashMap;
use std::path::Path;

/// A view whose name is one of the fields read.
pub struct View {
    /// Per element (`$ElementData`) rather than per node.
    pub per_element: bool,
    /// Its name (the first string tag).
    pub name: String,
    /// Its time (the first real tag).
    pub time: f64,
    /// Values per node or element.
    pub components: usize,
    /// Values by node or element tag: the start of the tag's components in `data`.
    start: HashMap<u64, usize>,
    data: Vec<f64>,
}

/// A view as its header gives it, read or skipped: for the errors that list the views a
/// file has. `components` is `None` for a skipped view whose header does not read (a view
/// not asked for is skipped unchecked).
#[derive(Clone, Debug, PartialEq)]
pub struct ViewHeader {
    /// `$ElementData` rather than `$NodeData`.
    pub per_element: bool,
    /// Its name.
    pub name: String,
    /// Values per node or element.
    pub components: Option<usize>,
}

impl View {
    /// The error field of the view: `$NodeData "displacement" (time 0.5)`.
    pub fn field(&self) -> String {
        format!(
            "{} \"{}\" (time {})",
            if self.per_element {
                "$ElementData"
            } else {
                "$NodeData"
            },
            self.name,
            self.time
        )
    }

    /// The values of the tags `tags` in order, or an error naming the first tag missing.
    pub fn gather(
        &self,
        tags: impl Iterator<Item = u64>,
        what: &str,
        path: &Path,
    ) -> Result<Vec<f64>> {
        let mut out = Vec::new();
        for tag in tags {
            let s = self.start.get(&tag).ok_or_else(|| {
                Error::input(
                    path,
                    self.field(),
                    format!(
                        "no value at {what} {tag} (the view has values at {} {what}s): write the field at every {what} of the bodies' triangles",
                        self.start.len()
                    ),
                )
            })?;
            out.extend_from_slice(&self.data[*s..*s + self.components]);
        }
        Ok(out)
    }
}

/// Read a `$NodeData` or `$ElementData` view (its marker read): its header, and the view if
/// its name is one of `wanted` (else it is skipped).
pub fn read_view(
    c: &mut Cursor,
    per_element: bool,
    wanted: &[&str],
) -> Result<(ViewHeader, Option<View>)> {
    let section = if per_element {
        "$ElementData"
    } else {
        "$NodeData"
    };
    let n = c.count("the number of string tags")?;
    let mut strings = Vec::new();
    for _ in 0..n {
        strings.push(c.string("a string tag")?);
    }
    let name = strings.first().cloned().unwrap_or_default();
    if !wanted.contains(&name.as_str()) {
        let header = ViewHeader {
            per_element,
            name,
            components: peek_components(c),
        };
        c.skip(section)?;
        return Ok((header, None));
    }
    c.section = format!("{section} \"{name}\"");
    let (time, components, count) = read_tags(c)?;
    let mut view = View {
        per_element,
        name,
        time,
        components,
        start: HashMap::new(),
        data: Vec::new(),
    };
    let what = if per_element { "element" } else { "node" };
    for _ in 0..count {
        let tag: u64 = c.parsed(
            &format!("a{} {what} tag", if per_element { "n" } else { "" }),
            "a tag",
        )?;
        if view.start.insert(tag, view.data.len()).is_some() {
            return Err(c.err(format!(
                "{what} {tag} has two values in the view: write the file again"
            )));
        }
        for _ in 0..components {
            let v = c.float("a value")?;
            view.data.push(v);
        }
    }
    c.end(&format!("$End{}", &section[1..]))?;
    let header = ViewHeader {
        per_element,
        name: view.name.clone(),
        components: Some(components),
    };
    Ok((header, Some(view)))
}

/// A view's real and integer tags: its time (the first real tag), its components and its
/// number of values (the second and third integer tags).
fn read_tags(c: &mut Cursor) -> Result<(f64, usize, usize)> {
    let n = c.count("the number of real tags")?;
    let mut reals = Vec::new();
    for _ in 0..n {
        reals.push(c.float("a real tag")?);
    }
    let Some(&time) = reals.first() else {
        return Err(c.err(
            "the view has no real tag, so no time: write the time of the state as its first real tag",
        ));
    };
    let n = c.count("the number of integer tags")?;
    let mut ints: Vec<i64> = Vec::new();
    for _ in 0..n {
        ints.push(c.int("an integer tag")?);
    }
    let [_, components, count, ..] = ints[..] else {
        return Err(c.err(format!(
            "{} integer tags; a view has at least 3 (time step, components, number of values): write the file again",
            ints.len()
        )));
    };
    if components < 1 {
        return Err(c.err(format!(
            "{components} components: a view has at least one; write the file again"
        )));
    }
    Ok((time, components as usize, count.max(0) as usize))
}

/// The components a skipped view's header announces, read ahead without moving `c` or
/// refusing anything; `None` where the header does not read so. A header of more than a
/// few real tags is not read ahead (gmsh writes one, the time), so that a corrupt count
/// cannot make every skipped view scan the rest of the file.
fn peek_components(c: &Cursor) -> Option<usize> {
    let mut c = c.clone();
    let reals: usize = c.token()?.parse().ok()?;
    if reals > 8 {
        return None;
    }
    for _ in 0..reals {
        c.token()?;
    }
    let ints: usize = c.token()?.parse().ok()?;
    if ints < 3 {
        return None;
    }
    c.token()?;
    let components: usize = c.token()?.parse().ok()?;
    (components >= 1).then_some(components)
}
