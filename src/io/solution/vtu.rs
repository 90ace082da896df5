//! The reader of a VTK XML unstructured grid (.vtu) of one piece: its XML read into a
//! document (`vtu_xml.rs`), then the grid read step by step: the points, the triangles
//! among the cells, the body of each triangle, the fields by name. The arrays' numbers are
//! decoded by `payload.rs`.

use super::checks::{
    DISPLACEMENT, ElementKind, PRESSURE, STRESS, check_both_bodies, conversion_route,
    displacement_2d, planar_points, quoted_list, stress_2d,
};
use super::payload::{Appended, ArrayInfo, Numbers, Section};
use super::vtu_xml::{VtuDocument, parse_vtu_xml, split_appended};
use super::{BODY_ARRAY, FieldNames, Precision, SolutionMesh, SolutionStep};
use crate::error::{Error, Result};
use std::path::Path;

/// Read a .vtu file of one state (see the module's documentation for the layouts read).
pub fn read_vtu(path: &Path, names: &FieldNames) -> Result<SolutionStep> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    parse_vtu(&bytes, path, names)
}

/// Read the bytes of a .vtu file; `path` names the file in errors only.
pub fn parse_vtu(bytes: &[u8], path: &Path, names: &FieldNames) -> Result<SolutionStep> {
    let (xml, appended) = split_appended(bytes, path)?;
    let grid = Grid {
        doc: parse_vtu_xml(&xml, path)?,
        appended,
        path,
    };
    grid.check_unique_names()?;
    let (points, coordinate_precision) = grid.points()?;
    let (triangle_cells, triangles) = grid.triangles()?;
    let body = grid.bodies(&triangle_cells)?;
    let (displacement, precision) = grid.displacement(&names.displacement)?;
    let mut precision = precision.coarser(coordinate_precision);
    let stress = grid.stress(names, &triangle_cells, &mut precision)?;
    let pressure = grid.pressure(names, &mut precision)?;
    Ok(SolutionStep {
        mesh: SolutionMesh {
            points,
            triangles,
            body,
            precision,
        },
        displacement,
        stress,
        pressure,
    })
}

/// A .vtu's document with its appended data: the grid read step by step.
struct Grid<'a> {
    doc: VtuDocument,
    appended: Option<Appended<'a>>,
    path: &'a Path,
}

impl Grid<'_> {
    /// The array of `section` named `name`.
    fn get(&self, section: Section, name: &str) -> Option<&ArrayInfo> {
        self.doc
            .arrays
            .iter()
            .find(|a| a.section == section && a.name == name)
    }

    /// The arrays of `section`.
    fn arrays_in(&self, section: Section) -> impl Iterator<Item = &ArrayInfo> {
        self.doc.arrays.iter().filter(move |a| a.section == section)
    }

    /// The names of the arrays of `section`, `'a', 'b'`, or `none`.
    fn names_in(&self, section: Section) -> String {
        quoted_list(self.arrays_in(section).map(|a| a.name.as_str()))
    }

    /// (name, components) of the arrays of `section`, for the fix of a field missing.
    fn found_in(&self, section: Section) -> Vec<(&str, Option<usize>)> {
        self.arrays_in(section)
            .map(|a| (a.name.as_str(), Some(a.components)))
            .collect()
    }

    /// Decode `a` as `tuples` tuples of its components, or as many as it holds (`None`).
    fn numbers(&self, a: &ArrayInfo, tuples: Option<usize>) -> Result<(Numbers, Precision)> {
        self.doc
            .format
            .numbers(a, self.appended.as_ref(), tuples, self.path)
    }

    /// Refuse two arrays of one name in a section: the grading would not know which to read.
    fn check_unique_names(&self) -> Result<()> {
        let mut seen = std::collections::HashSet::new();
        for a in &self.doc.arrays {
            if a.section != Section::Points && !seen.insert((a.section, a.name.as_str())) {
                return Err(Error::input(
                    self.path,
                    a.field(),
                    format!(
                        "two arrays of {} are named '{}': rename or drop one, so the array read is the one meant",
                        a.section.name(),
                        a.name
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The points (x, y), which must lie in the z = 0 plane, and their precision.
    fn points(&self) -> Result<(Vec<[f64; 2]>, Precision)> {
        let path = self.path;
        let coordinates: Vec<&ArrayInfo> = self.arrays_in(Section::Points).collect();
        let [coordinates] = coordinates[..] else {
            return Err(Error::input(
                path,
                "Points",
                format!(
                    "<Points> holds {} arrays; it holds one, the coordinates: write the file again",
                    coordinates.len()
                ),
            ));
        };
        if coordinates.components != 3 {
            return Err(Error::input(
                path,
                "Points",
                format!(
                    "the coordinates have {} components; VTK stores 3 (x, y, z = 0): write them so",
                    coordinates.components
                ),
            ));
        }
        let (xyz, precision) = self.numbers(coordinates, Some(self.doc.points))?;
        let points = planar_points(&xyz.into_f64(), precision, path, "Points")?;
        Ok((points, precision))
    }

    /// The integers of the `<Cells>` array `name` (connectivity, offsets or types).
    fn topology(&self, name: &str) -> Result<Vec<i64>> {
        let a = self.get(Section::Cells, name).ok_or_else(|| {
            Error::input(
                self.path,
                format!("Cells/{name}"),
                format!(
                    "<Cells> has no array '{name}' (it needs connectivity, offsets and types): write the file again"
                ),
            )
        })?;
        // The connectivity holds as many entries as it holds: the offsets say where each
        // cell ends.
        let tuples = (name != "connectivity").then_some(self.doc.cells);
        match self.numbers(a, tuples)?.0 {
            Numbers::Int(v) => Ok(v),
            Numbers::Float(_) => Err(Error::input(
                self.path,
                a.field(),
                format!(
                    "type {}: cell topology is integer (Int32 or Int64): write it so",
                    a.vtk_type
                ),
            )),
        }
    }

    /// The triangles (VTK type 5) and the cell each is: vertices and lines are skipped
    /// (exporters write the boundary's too), other cells refused with the way to convert.
    fn triangles(&self) -> Result<(Vec<usize>, Vec<[usize; 3]>)> {
        let path = self.path;
        let connectivity = self.topology("connectivity")?;
        let offsets = self.topology("offsets")?;
        let types = self.topology("types")?;
        let mut triangle_cells: Vec<usize> = Vec::new();
        let mut triangles: Vec<[usize; 3]> = Vec::new();
        let mut start = 0i64;
        for (cell, (&end, &kind)) in offsets.iter().zip(&types).enumerate() {
            if end < start || end as u64 > connectivity.len() as u64 {
                return Err(Error::input(
                    path,
                    "Cells/offsets",
                    format!(
                        "cell {cell} ends at offset {end}, after {start} and within {} connectivity entries expected: write the file again",
                        connectivity.len()
                    ),
                ));
            }
            let nodes = &connectivity[start as usize..end as usize];
            start = end;
            match kind {
                5 => {}
                // Vertices, poly-vertices, lines and poly-lines: exporters write the boundary
                // edges and nodes too; they are not part of the mesh graded.
                1..=4 => continue,
                other => return Err(self.refused_cell(cell, other, &types)),
            }
            triangles.push(self.triangle(cell, nodes)?);
            triangle_cells.push(cell);
        }
        if offsets
            .last()
            .is_some_and(|&e| e as u64 != connectivity.len() as u64)
        {
            return Err(Error::input(
                path,
                "Cells/offsets",
                format!(
                    "the last cell ends at offset {}, but connectivity holds {} entries: write the file again",
                    offsets[offsets.len() - 1],
                    connectivity.len()
                ),
            ));
        }
        if triangles.is_empty() {
            return Err(Error::input(
                path,
                "Cells",
                "the file has no triangle (VTK type 5): give the P1 triangle mesh of both bodies",
            ));
        }
        Ok((triangle_cells, triangles))
    }

    /// The refusal of `cell`, of VTK type `kind` (neither a triangle nor a vertex or line),
    /// with how many cells of `types` have it and the way to convert.
    fn refused_cell(&self, cell: usize, kind: i64, types: &[i64]) -> Error {
        let count = types.iter().filter(|&&t| t == kind).count();
        let (what, family) = match kind {
            9 => ("quadrilateral", ElementKind::Quadrilateral),
            22 => ("quadratic triangle", ElementKind::QuadraticTriangle),
            // What FEniCSx writes for a triangle of degree 2 or more.
            69 => ("Lagrange triangle", ElementKind::QuadraticTriangle),
            _ => ("cell", ElementKind::Other),
        };
        Error::input(
            self.path,
            "Cells",
            format!(
                "cell {cell} is a {what} (VTK type {kind}; {count} such cells); {}",
                conversion_route(family)
            ),
        )
    }

    /// The points of triangle `cell`: three distinct points of the grid.
    fn triangle(&self, cell: usize, nodes: &[i64]) -> Result<[usize; 3]> {
        let (path, np) = (self.path, self.doc.points);
        let [a, b, c] = nodes[..] else {
            return Err(Error::input(
                path,
                "Cells",
                format!(
                    "cell {cell} is a triangle (VTK type 5) with {} points; a triangle has 3: write the file again",
                    nodes.len()
                ),
            ));
        };
        let mut t = [0usize; 3];
        for (k, n) in [a, b, c].into_iter().enumerate() {
            if n < 0 || n as u64 >= np as u64 {
                return Err(Error::input(
                    path,
                    "Cells/connectivity",
                    format!(
                        "triangle (cell {cell}) refers to point {n}, but the file has {np} points (NumberOfPoints): write the file again"
                    ),
                ));
            }
            t[k] = n as usize;
        }
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            return Err(Error::input(
                path,
                "Cells/connectivity",
                format!(
                    "triangle (cell {cell}) repeats a point ({t:?}): a degenerate triangle; fix the mesh"
                ),
            ));
        }
        Ok(t)
    }

    /// The body (1 or 2) of each triangle, from the cell array [`BODY_ARRAY`]; both present.
    fn bodies(&self, triangle_cells: &[usize]) -> Result<Vec<u8>> {
        let path = self.path;
        let field = format!("CellData/{BODY_ARRAY}");
        let body_array = self.get(Section::CellData, BODY_ARRAY).ok_or_else(|| {
            Error::input(
                path,
                &field,
                format!(
                    "no cell array '{BODY_ARRAY}' (the cell arrays are {}): add one, 1 on the triangles of the scene's first body and 2 on the second's (e.g. from the physical surface tags)",
                    self.names_in(Section::CellData)
                ),
            )
        })?;
        if body_array.components != 1 {
            return Err(Error::input(
                path,
                &field,
                format!(
                    "{} components per cell; '{BODY_ARRAY}' has one (1 or 2): write it so",
                    body_array.components
                ),
            ));
        }
        let marks = self.numbers(body_array, Some(self.doc.cells))?.0.into_f64();
        let mut body = Vec::with_capacity(triangle_cells.len());
        for &cell in triangle_cells {
            match marks[cell] {
                1.0 => body.push(1u8),
                2.0 => body.push(2u8),
                v => {
                    return Err(Error::input(
                        path,
                        &field,
                        format!(
                            "triangle (cell {cell}) has body {v}; each triangle is marked 1 (the scene's first body) or 2: fix the marks"
                        ),
                    ));
                }
            }
        }
        check_both_bodies(&body, path, &field)?;
        Ok(body)
    }

    /// Where the array `name`, looked for in `wanted`, is found in `other` instead: the
    /// note for the error (the grading reads it from `wanted`).
    fn misplaced(&self, name: &str, wanted: Section, other: Section) -> Option<String> {
        self.get(other, name).map(|_| {
            format!(
                " ('{name}' is in {}: the grading reads it from {}, {})",
                other.name(),
                wanted.name(),
                if wanted == Section::PointData {
                    "one value per point"
                } else {
                    "one P0 value per cell"
                }
            )
        })
    }

    /// The nodal displacement (point array `d`) and its precision.
    fn displacement(&self, d: &str) -> Result<(Vec<[f64; 2]>, Precision)> {
        let path = self.path;
        let array = self.get(Section::PointData, d).ok_or_else(|| {
            Error::input(
                path,
                format!("PointData/{d}"),
                format!(
                    "no point array '{d}'{} (the point arrays are {}): {}",
                    self.misplaced(d, Section::PointData, Section::CellData)
                        .unwrap_or_default(),
                    self.names_in(Section::PointData),
                    DISPLACEMENT.fix(
                        &self.found_in(Section::PointData),
                        &format!("write the nodal displacement as point data named '{d}'")
                    )
                ),
            )
        })?;
        let field = array.field();
        let (values, precision) = self.numbers(array, Some(self.doc.points))?;
        let displacement = displacement_2d(
            &values.into_f64(),
            array.components,
            precision,
            path,
            &field,
            &|i| format!("point {i}"),
        )?;
        Ok((displacement, precision))
    }

    /// The P0 stress of each triangle (cell array `names.stress`), if the file has it;
    /// `precision` made the coarser of it and the stress's.
    fn stress(
        &self,
        names: &FieldNames,
        triangle_cells: &[usize],
        precision: &mut Precision,
    ) -> Result<Option<Vec<[f64; 3]>>> {
        let (path, s) = (self.path, &names.stress);
        let Some(a) = self.get(Section::CellData, s) else {
            if let Some(m) = self.misplaced(s, Section::CellData, Section::PointData) {
                return Err(Error::input(
                    path,
                    format!("PointData/{s}"),
                    format!(
                        "the stress is point data{m}: write the stress per cell (P0), or leave it out"
                    ),
                ));
            }
            if names.stress_named() {
                return Err(Error::input(
                    path,
                    format!("CellData/{s}"),
                    format!(
                        "no cell array '{s}' (the cell arrays are {}): {}",
                        self.names_in(Section::CellData),
                        STRESS.fix(
                            &self.found_in(Section::CellData),
                            &format!("write the P0 stress as cell data named '{s}'")
                        )
                    ),
                ));
            }
            return Ok(None);
        };
        let (values, p) = self.numbers(a, Some(self.doc.cells))?;
        *precision = precision.coarser(p);
        // The triangles' rows only: the values of skipped cells (often placeholders)
        // neither set the scale of the checks nor are checked.
        let (values, k) = (values.into_f64(), a.components);
        let rows: Vec<f64> = triangle_cells
            .iter()
            .flat_map(|&c| values[c * k..(c + 1) * k].iter().copied())
            .collect();
        let label = |i: usize| format!("cell {}", triangle_cells[i]);
        Ok(Some(stress_2d(&rows, k, p, path, &a.field(), &label)?))
    }

    /// The nodal pressure (point array `names.pressure`), if the file has it; `precision`
    /// made the coarser of it and the pressure's.
    fn pressure(&self, names: &FieldNames, precision: &mut Precision) -> Result<Option<Vec<f64>>> {
        let (path, q) = (self.path, &names.pressure);
        let Some(a) = self.get(Section::PointData, q) else {
            if names.pressure_named() {
                return Err(Error::input(
                    path,
                    format!("PointData/{q}"),
                    format!(
                        "no point array '{q}'{} (the point arrays are {}): {}",
                        self.misplaced(q, Section::PointData, Section::CellData)
                            .unwrap_or_default(),
                        self.names_in(Section::PointData),
                        PRESSURE.fix(
                            &self.found_in(Section::PointData),
                            &format!("write the nodal pressure as point data named '{q}'")
                        )
                    ),
                ));
            }
            return Ok(None);
        };
        if a.components != 1 {
            return Err(Error::input(
                path,
                a.field(),
                format!(
                    "{} components per point; the pressure has one: write it so",
                    a.components
                ),
            ));
        }
        let (values, p) = self.numbers(a, Some(self.doc.points))?;
        *precision = precision.coarser(p);
        Ok(Some(values.into_f64()))
    }
}
