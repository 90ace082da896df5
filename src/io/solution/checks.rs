//! Checks shared by the VTU and MSH readers: finite values, in-plane points and fields,
//! symmetric plane stresses, both bodies present, the route for a refused element type, and
//! the wording of a field missing.

use super::Precision;
use crate::error::{Error, Result};
use std::path::Path;

/// Refuse a NaN or infinity in `values` (`components` per tuple), naming the first one.
pub(super) fn check_finite(
    values: &[f64],
    components: usize,
    file: &Path,
    field: &str,
    tuple: &str,
) -> Result<()> {
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        let c = components.max(1);
        return Err(Error::input(
            file,
            field,
            format!(
                "{tuple} {} (component {}) is {}: the grading needs finite numbers; fix the solution (a diverged solve?) or the export and write the file again",
                i / c,
                i % c,
                values[i]
            ),
        ));
    }
    Ok(())
}

/// Largest |value| over the components `which` of each tuple.
pub(super) fn largest(values: &[f64], components: usize, which: &[usize]) -> f64 {
    values
        .chunks_exact(components)
        .flat_map(|t| which.iter().map(move |&c| t[c].abs()))
        .fold(0.0, f64::max)
}

/// Nodal displacements from 2 or 3 components per tuple; a third must vanish; `label(i)`
/// names row i in errors.
pub(super) fn displacement_2d(
    values: &[f64],
    components: usize,
    precision: Precision,
    file: &Path,
    field: &str,
    label: &dyn Fn(usize) -> String,
) -> Result<Vec<[f64; 2]>> {
    match components {
        2 => Ok(values.chunks_exact(2).map(|t| [t[0], t[1]]).collect()),
        3 => in_plane(values, precision).map_err(|(i, z, scale)| {
            Error::input(
                file,
                field,
                format!(
                    "the third component at {} is {z:e}, not zero (largest in-plane |u| {scale:e}); the grading is 2D in the x-y plane: write the x and y components only, or a zero z component",
                    label(i)
                ),
            )
        }),
        n => Err(Error::input(
            file,
            field,
            format!(
                "{n} components per point; a 2D displacement has 2 (u_x, u_y) or 3 (u_x, u_y, 0): write it so"
            ),
        )),
    }
}

/// P0 stresses [s11, s22, s12] from 3 components, a 2x2 tensor (4, row-major) or a 3x3
/// tensor (9, row-major) whose z row and column vanish (plane stress); `label(i)` names
/// row i in errors.
pub(super) fn stress_2d(
    values: &[f64],
    components: usize,
    precision: Precision,
    file: &Path,
    field: &str,
    label: &dyn Fn(usize) -> String,
) -> Result<Vec<[f64; 3]>> {
    // Positions of s11, s12, s21, s22 in a row-major tensor, and of its z row and column.
    let (s11, s12, s21, s22, z): (usize, usize, usize, usize, &[usize]) = match components {
        3 => return Ok(values.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect()),
        4 => (0, 1, 2, 3, &[]),
        9 => (0, 1, 3, 4, &[2, 5, 6, 7, 8]),
        n => {
            return Err(Error::input(
                file,
                field,
                format!(
                    "{n} components per cell; the stress is read as 3 components [s11, s22, s12], a 2x2 tensor (4, row-major [s11, s12, s21, s22]) or a 3x3 tensor (9, row-major, plane stress): write one of these"
                ),
            ));
        }
    };
    let scale = largest(values, components, &[s11, s12, s21, s22]);
    let tolerance = precision.tolerance(scale);
    for (i, t) in values.chunks_exact(components).enumerate() {
        if (t[s12] - t[s21]).abs() > tolerance {
            return Err(Error::input(
                file,
                field,
                format!(
                    "{}: s12 = {:e} and s21 = {:e} differ by more than round-off (largest |stress| {scale:e}); a Cauchy stress is symmetric: check the export (a displacement gradient written instead of the stress?)",
                    label(i),
                    t[s12],
                    t[s21]
                ),
            ));
        }
        if let Some(&c) = z.iter().find(|&&c| t[c].abs() > tolerance) {
            return Err(Error::input(
                file,
                field,
                format!(
                    "{}: the z component {} of the 3x3 stress is {:e}, not zero (largest in-plane |stress| {scale:e}); the grading compares plane stresses: write the in-plane components only (3 components [s11, s22, s12] or the 2x2 tensor); a plane-strain code's s33 = nu (s11 + s22) belongs out of it",
                    label(i),
                    ["xx", "xy", "xz", "yx", "yy", "yz", "zx", "zy", "zz"][c],
                    t[c]
                ),
            ));
        }
    }
    Ok(values
        .chunks_exact(components)
        .map(|t| [t[s11], t[s22], 0.5 * (t[s12] + t[s21])])
        .collect())
}

/// Points (x, y) from (x, y, z) triples whose z vanishes relative to the mesh's size.
pub(super) fn planar_points(
    xyz: &[f64],
    precision: Precision,
    file: &Path,
    field: &str,
) -> Result<Vec<[f64; 2]>> {
    in_plane(xyz, precision).map_err(|(i, z, size)| {
        Error::input(
            file,
            field,
            format!(
                "point {i} has z = {z:e}, not zero (largest |x|, |y| {size:e}); the grading is 2D: write the mesh in the z = 0 plane"
            ),
        )
    })
}

/// The (x, y) of 3-component tuples whose third component vanishes to the precision,
/// relative to the largest |x|, |y|; else the first offending tuple, its third component and
/// that scale.
pub(super) fn in_plane(
    xyz: &[f64],
    precision: Precision,
) -> std::result::Result<Vec<[f64; 2]>, (usize, f64, f64)> {
    let scale = largest(xyz, 3, &[0, 1]);
    let tolerance = precision.tolerance(scale);
    match xyz.chunks_exact(3).position(|t| t[2].abs() > tolerance) {
        Some(i) => Err((i, xyz[3 * i + 2], scale)),
        None => Ok(xyz.chunks_exact(3).map(|t| [t[0], t[1]]).collect()),
    }
}

/// Refuse a mesh without a triangle of each body.
pub(super) fn check_both_bodies(body: &[u8], file: &Path, field: &str) -> Result<()> {
    for b in [1u8, 2] {
        if !body.contains(&b) {
            return Err(Error::input(
                file,
                field,
                format!(
                    "no triangle belongs to body {b}; a two-body contact solution has triangles of both bodies: mark the first body's triangles 1 and the second's 2"
                ),
            ));
        }
    }
    Ok(())
}

/// Why a cell or element type other than the P1 triangle is refused, and the way to convert.
pub(super) fn conversion_route(kind: ElementKind) -> &'static str {
    match kind {
        ElementKind::Quadrilateral => {
            "split each quadrilateral into two triangles (meshio, or gmsh's Mesh.SubdivisionAlgorithm / `Mesh.RecombineAll = 0`)"
        }
        ElementKind::QuadraticTriangle => {
            "P2 is not graded yet: write the P1 solution (the vertices of each triangle) or interpolate to P1"
        }
        ElementKind::Other => {
            "only P1 triangles are graded: write the solution on a P1 triangle mesh"
        }
    }
}

/// The refused element families.
#[derive(Clone, Copy)]
pub(super) enum ElementKind {
    Quadrilateral,
    QuadraticTriangle,
    Other,
}

/// A field read by name, for the error of one missing: the grade flag that names it, the
/// components a field of its kind has, and what grading without it means (`None`: the
/// field is required).
pub(super) struct Named {
    flag: &'static str,
    shapes: &'static [usize],
    without: Option<&'static str>,
}

/// The nodal displacement: required, 2 or 3 components.
pub(super) const DISPLACEMENT: Named = Named {
    flag: "--displacement",
    shapes: &[2, 3],
    without: None,
};

/// The P0 stress: 3, 4 or 9 components; without it, E eps(u_h) is graded.
pub(super) const STRESS: Named = Named {
    flag: "--stress",
    shapes: &[3, 4, 9],
    without: Some("to grade E eps(u_h) in its place"),
};

/// The nodal pressure: 1 component; without it, the pressure quantities are not measured.
pub(super) const PRESSURE: Named = Named {
    flag: "--pressure",
    shapes: &[1],
    without: Some("(the pressure quantities are then not measured)"),
};

impl Named {
    /// The fix of the field missing from a file whose fields of its kind (point arrays,
    /// `$NodeData` views, ...) are `found`, as (name, components if known); `write` says
    /// how to write it under the name looked for. Where a field found has the right number
    /// of components, the fix is to pass its name with the flag (`pass --displacement u`).
    pub(super) fn fix(&self, found: &[(&str, Option<usize>)], write: &str) -> String {
        let mut passes: Vec<String> = Vec::new();
        for &(name, components) in found {
            let Some(k) = components.filter(|k| self.shapes.contains(k)) else {
                continue;
            };
            let pass = format!(
                "{} {} ({k} component{})",
                self.flag,
                shell_word(name),
                if k == 1 { "" } else { "s" }
            );
            if !passes.contains(&pass) {
                passes.push(pass);
            }
        }
        let flag = self.flag;
        match (passes.is_empty(), self.without) {
            (false, None) => format!("pass {}, or {write}", passes.join(" or ")),
            (false, Some(w)) => format!("pass {}, or leave {flag} out {w}", passes.join(" or ")),
            (true, None) => {
                format!("{write}, or pass {flag} with the name of the one that holds it")
            }
            (true, Some(w)) => format!("{write}, or leave {flag} out {w}"),
        }
    }
}

/// Names as a list, `'a', 'b'` (each once), or `none`.
pub(super) fn quoted_list<'a>(names: impl Iterator<Item = &'a str>) -> String {
    let mut v: Vec<String> = Vec::new();
    for n in names {
        let q = format!("'{n}'");
        if !v.contains(&q) {
            v.push(q);
        }
    }
    if v.is_empty() {
        "none".to_string()
    } else {
        v.join(", ")
    }
}

/// `name` as one shell word: quoted where it holds anything but letters, digits and `_-./:`.
fn shell_word(name: &str) -> String {
    let plain = |c: char| c.is_ascii_alphanumeric() || "_-./:".contains(c);
    if !name.is_empty() && name.chars().all(plain) {
        name.to_string()
    } else {
        format!("'{}'", name.replace('\'', "'\\''"))
    }
}
