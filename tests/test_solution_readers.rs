//! Reference: the `grade` issue (readers of a contact solution computed by another code).
//! Goal: `io::solution` reads a two-body P1 solution from a .vtu in every layout VTK writes
//! (ascii, inline base64, appended raw or base64; zlib or not; UInt32 or UInt64 headers;
//! either byte order; Float32 or Float64) to the same values, the project's own writer bit
//! for bit, a .pvd's time series, and gmsh's MSH 4.1 and 2.2 with solution views; and
//! refuses each kind of bad file with one error naming the file, the field and the fix.
//! Data: a 10-point, 7-triangle two-body solution written in the test
//! (tests/common/solution_files.rs); contact-mms at level 0 solved for the round trip.

mod common;
#[path = "common/solution_files.rs"]
mod solution_files;

use contact_rates::error::{Error, Result};
use contact_rates::io::solution::{
    FieldNames, Precision, SolutionStep, parse_msh_solution, parse_pvd, parse_vtu,
    read_msh_solution, read_pvd, read_vtu,
};
use solution_files::{BODIES, Encoding, Options, Solution, Vtu, two_bodies};
use std::path::{Path, PathBuf};

/// The path errors name (the parse functions read bytes; the path is for messages).
fn path(name: &str) -> PathBuf {
    PathBuf::from(format!("/data/{name}"))
}

/// `step` holds `s` exactly, at `precision`.
fn assert_reads_as(step: &SolutionStep, s: &Solution, precision: Precision, what: &str) {
    let expected = match precision {
        Precision::F64 => s.clone(),
        Precision::F32 => s.rounded_to_f32(),
    };
    let m = &step.mesh;
    assert_eq!(m.precision, precision, "{what}");
    assert_eq!(m.points, expected.points, "{what}");
    assert_eq!(m.triangles, expected.triangles, "{what}");
    assert_eq!(m.body, expected.body, "{what}");
    assert_eq!(step.displacement, expected.displacement, "{what}");
    assert_eq!(step.stress.as_ref(), Some(&expected.stress), "{what}");
    assert_eq!(step.pressure.as_ref(), Some(&expected.pressure), "{what}");
}

/// `r` is refused with an input error naming `file` and `field` whose message holds
/// every one of `needles`.
fn assert_refused<T: std::fmt::Debug>(r: Result<T>, file: &Path, field: &str, needles: &[&str]) {
    let e = r.expect_err("refused");
    let text = e.to_string();
    println!("{text}");
    match &e {
        Error::Input {
            file: f, field: g, ..
        } => {
            assert_eq!(f, file, "{text}");
            assert_eq!(g, field, "{text}");
        }
        other => panic!("not an input error: {other}"),
    }
    assert!(text.starts_with(&format!("{}: {field}: ", file.display())));
    for n in needles {
        assert!(text.contains(n), "'{text}' lacks '{n}'");
    }
}

/// Every layout of the test writer, Float64 and Float32.
fn all_options() -> Vec<Options> {
    let mut out = Vec::new();
    for encoding in Encoding::ALL {
        for compressed in [false, true] {
            for header64 in [false, true] {
                for big_endian in [false, true] {
                    if encoding == Encoding::Ascii && (compressed || header64 || big_endian) {
                        continue;
                    }
                    out.push(Options {
                        compressed,
                        header64,
                        big_endian,
                        ..Options::new(encoding)
                    });
                }
            }
        }
    }
    // A base64 header encoded as a stream of its own, uncompressed.
    for encoding in [Encoding::Binary, Encoding::AppendedBase64] {
        for header64 in [false, true] {
            out.push(Options {
                header64,
                separate_header: true,
                ..Options::new(encoding)
            });
        }
    }
    out
}

#[test]
fn every_vtu_layout_reads_to_the_same_values() {
    let s = two_bodies(0.7);
    let dir = tempfile::tempdir().unwrap();
    let mut read = 0;
    for o in all_options() {
        for (float, precision) in [("Float64", Precision::F64), ("Float32", Precision::F32)] {
            let file = dir.path().join(format!("{}-{float}.vtu", o.label()));
            std::fs::write(&file, s.vtu(float).write(&o)).unwrap();
            let step = read_vtu(&file, &FieldNames::default()).unwrap();
            assert_reads_as(&step, &s, precision, &file.display().to_string());
            read += 1;
        }
    }
    println!("{read} files read to the solution's values");
    assert_eq!(read, 2 * (1 + 3 * 8 + 4));
}

/// Float32 values read as the f32 nearest the f64 ones: within f32 precision of them.
#[test]
fn float32_files_read_within_f32_precision() {
    let s = two_bodies(0.7);
    let step = parse_vtu(
        &s.vtu("Float32").write(&Options::new(Encoding::AppendedRaw)),
        &path("f32.vtu"),
        &FieldNames::default(),
    )
    .unwrap();
    assert_eq!(step.mesh.precision, Precision::F32);
    assert_eq!(Precision::F32.epsilon(), f32::EPSILON as f64);
    let scale = s
        .displacement
        .iter()
        .flatten()
        .fold(0.0f64, |a, x| a.max(x.abs()));
    let worst = step
        .displacement
        .iter()
        .flatten()
        .zip(s.displacement.iter().flatten())
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    println!("largest difference {worst:e} of max |u| {scale:e}");
    assert!(worst > 0.0 && worst <= f32::EPSILON as f64 * scale);
}

/// The project's writer (appended raw, zlib, UInt64 headers, full last blocks written as
/// their size) reads back bit for bit.
#[test]
fn the_project_vtu_writer_reads_back_bit_for_bit() {
    use contact_rates::io::vtu::{DataArray, Mesh};
    let s = two_bodies(0.3);
    let body: Vec<i32> = s.body.iter().map(|&b| b as i32).collect();
    let mesh = Mesh::new(
        &s.points,
        &s.triangles,
        vec![DataArray::new("body", 1, &body, 9)],
    );
    let u: Vec<f64> = s
        .displacement
        .iter()
        .flat_map(|u| [u[0], u[1], 0.0])
        .collect();
    let sigma: Vec<f64> = s.stress.iter().flatten().copied().collect();
    let bytes = mesh.file(
        &[
            DataArray::new("displacement", 3, &u, 2),
            DataArray::new("pressure", 1, &s.pressure, 2),
        ],
        &[DataArray::new("stress", 3, &sigma, 2).with_component_names(&["s11", "s22", "s12"])],
    );
    let step = parse_vtu(&bytes, &path("own.vtu"), &FieldNames::default()).unwrap();
    assert_reads_as(&step, &s, Precision::F64, "the project's writer");
}

/// What `solve` writes for a solved state (io::vtu::StateFile) reads back bit for bit:
/// points, triangles, bodies, displacements, stresses and contact pressures.
#[test]
fn a_state_written_by_solve_reads_back_bit_for_bit() {
    use contact_rates::contact::Method;
    use contact_rates::io::vtu::StateFile;
    use contact_rates::metrics::contact_nodes;
    use contact_rates::solve::SolverKind;
    use contact_rates::verify::solve_case;
    let case = common::case("contact-mms", 0, Method::Mortar, &[]);
    let (sol, _) = solve_case(&case, SolverKind::Newton, 2).unwrap();
    let p = &case.problem;
    let state = sol.states.last().unwrap();
    let nodes = contact_nodes(p, state);
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("solution_0002.vtu");
    std::fs::write(&file, StateFile::new(&p.model).file(state, &nodes)).unwrap();
    let step = read_vtu(&file, &FieldNames::default()).unwrap();
    let m = &p.model;
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(step.mesh.precision, Precision::F64);
    let points: Vec<f64> = (0..m.n_nodes).flat_map(|g| m.position(g)).collect();
    assert_eq!(bits(&points), bits(&step.mesh.points.concat()));
    let triangles: Vec<[usize; 3]> = m.elements.iter().map(|e| e.nodes).collect();
    assert_eq!(step.mesh.triangles, triangles);
    let body: Vec<u8> = m.elements.iter().map(|e| e.body as u8 + 1).collect();
    assert_eq!(step.mesh.body, body);
    assert_eq!(bits(&state.u), bits(&step.displacement.concat()));
    let sigma: Vec<f64> = state
        .sigma
        .iter()
        .flat_map(|s| [s[0], s[1], s[2]])
        .collect();
    assert_eq!(bits(&sigma), bits(&step.stress.unwrap().concat()));
    let mut pressure = vec![0.0; m.n_nodes];
    for c in &nodes {
        pressure[c.node] = c.pressure;
    }
    let read = step.pressure.unwrap();
    assert_eq!(bits(&pressure), bits(&read));
    let in_contact = read.iter().filter(|&&x| x != 0.0).count();
    println!(
        "{} points, {} triangles, {in_contact} nonzero pressures read bit for bit",
        step.mesh.points.len(),
        triangles.len()
    );
    assert!(in_contact > 0);
}

#[test]
fn a_pvd_lists_its_steps_in_file_order_resolved_against_its_folder() {
    let dir = tempfile::tempdir().unwrap();
    let pvd = dir.path().join("solution.pvd");
    let steps = vec![
        (0.5, "solution_0001.vtu".to_string()),
        (1.0, "steps/solution_0002.vtu".to_string()),
        (0.25, "solution_0000.vtu".to_string()),
    ];
    std::fs::write(&pvd, contact_rates::io::pvd(&steps)).unwrap();
    let read = read_pvd(&pvd).unwrap();
    let expected: Vec<(f64, PathBuf)> = steps
        .iter()
        .map(|(t, f)| (*t, dir.path().join(f)))
        .collect();
    assert_eq!(read, expected);
    // Each file reads: a series of .vtu written by another code.
    for (k, (time, file)) in read.iter().enumerate() {
        std::fs::create_dir_all(file.parent().unwrap()).unwrap();
        let o = Options::new(Encoding::ALL[k % 4]);
        std::fs::write(file, two_bodies(*time).vtu("Float64").write(&o)).unwrap();
        let step = read_vtu(file, &FieldNames::default()).unwrap();
        assert_reads_as(&step, &two_bodies(*time), Precision::F64, "a pvd step");
    }
    // A collection written by hand: other attributes, no declaration, a comment.
    let text = "<VTKFile type=\"Collection\" version=\"0.1\">\n<!-- two steps -->\n<Collection>\n  <DataSet part=\"0\" timestep=\"2e-1\" file=\"a.vtu\"></DataSet>\n  <DataSet timestep=\" 4 \" file=\"/abs/b.vtu\"/>\n</Collection>\n</VTKFile>\n";
    let read = parse_pvd(text.as_bytes(), Path::new("run/s.pvd")).unwrap();
    assert_eq!(
        read,
        vec![
            (0.2, PathBuf::from("run/a.vtu")),
            (4.0, PathBuf::from("/abs/b.vtu"))
        ]
    );
}

/// The two steps of an MSH solution, in time order, each the solution of its time.
fn assert_msh_steps(steps: &[(f64, SolutionStep)], times: [f64; 2]) {
    assert_eq!(steps.len(), 2);
    for ((time, step), expected) in steps.iter().zip(times) {
        assert_eq!(*time, expected);
        assert_reads_as(step, &two_bodies(expected), Precision::F64, "msh");
    }
}

#[test]
fn an_msh41_solution_reads_its_two_steps_in_time_order() {
    let (a, b) = (two_bodies(0.5), two_bodies(1.0));
    let text = solution_files::msh41(&[(0.5, &a), (1.0, &b)]);
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("solution.msh");
    std::fs::write(&file, &text).unwrap();
    let steps = read_msh_solution(&file, &FieldNames::default(), BODIES).unwrap();
    assert_msh_steps(&steps, [0.5, 1.0]);
    // The bodies the other way round: body 1 is the upper block.
    let swapped = parse_msh_solution(
        text.as_bytes(),
        &file,
        &FieldNames::default(),
        [BODIES[1], BODIES[0]],
    )
    .unwrap();
    let flipped: Vec<u8> = steps[0].1.mesh.body.iter().map(|b| 3 - b).collect();
    assert_eq!(swapped[0].1.mesh.body, flipped);
}

#[test]
fn an_msh22_solution_reads_its_two_steps_in_time_order() {
    let (a, b) = (two_bodies(0.5), two_bodies(1.0));
    let text = solution_files::msh22(&[(0.5, &a), (1.0, &b)]);
    let steps = parse_msh_solution(
        text.as_bytes(),
        &path("s.msh"),
        &FieldNames::default(),
        BODIES,
    )
    .unwrap();
    assert_msh_steps(&steps, [0.5, 1.0]);
}

/// Other field names: the views and arrays are found by the names given.
#[test]
fn fields_are_found_by_the_names_given() {
    let s = two_bodies(0.7);
    let names = FieldNames {
        displacement: "u".into(),
        stress: "sigma".into(),
        pressure: "p_n".into(),
    };
    let mut vtu = s.vtu("Float64");
    vtu.array_mut("PointData", "displacement").name = "u".into();
    vtu.array_mut("CellData", "stress").name = "sigma".into();
    vtu.array_mut("PointData", "pressure").name = "p_n".into();
    let bytes = vtu.write(&Options::new(Encoding::Binary));
    let step = parse_vtu(&bytes, &path("named.vtu"), &names).unwrap();
    assert_reads_as(&step, &s, Precision::F64, "named");
    // With the default names the stress and pressure are absent, the displacement missing.
    assert_refused(
        parse_vtu(&bytes, &path("named.vtu"), &FieldNames::default()),
        &path("named.vtu"),
        "PointData/displacement",
        &[
            "no point array 'displacement'",
            "'u'",
            "pass --displacement u (3 components)",
        ],
    );
    let text = solution_files::msh22(&[(0.5, &s)])
        .replace("\"displacement\"", "\"u\"")
        .replace("\"stress\"", "\"sigma\"")
        .replace("\"pressure\"", "\"p_n\"");
    let steps = parse_msh_solution(text.as_bytes(), &path("n.msh"), &names, BODIES).unwrap();
    assert_reads_as(&steps[0].1, &s, Precision::F64, "named msh");
}

/// Optional fields: without stress and pressure the step has none.
#[test]
fn stress_and_pressure_are_optional() {
    let s = two_bodies(0.7);
    let mut vtu = s.vtu("Float64");
    vtu.remove("CellData", "stress");
    vtu.remove("PointData", "pressure");
    let step = parse_vtu(
        &vtu.write(&Options::new(Encoding::Ascii)),
        &path("u.vtu"),
        &FieldNames::default(),
    )
    .unwrap();
    assert_eq!((step.stress, step.pressure), (None, None));
    assert_eq!(step.displacement, s.displacement);
}

// ---------------------------------------------------------------------------------------
// The component layouts accepted.

/// A displacement of 2 components, a stress as a 2x2 tensor and as a 3x3 plane-stress
/// tensor read as the 3-component ones.
#[test]
fn displacement_and_stress_component_layouts_read_alike() {
    let s = two_bodies(0.7);
    let read = |edit: &dyn Fn(&mut Vtu)| {
        let mut vtu = s.vtu("Float64");
        edit(&mut vtu);
        parse_vtu(
            &vtu.write(&Options::new(Encoding::AppendedBase64)),
            &path("c.vtu"),
            &FieldNames::default(),
        )
        .unwrap()
    };
    let two = read(&|v| {
        let a = v.array_mut("PointData", "displacement");
        a.values = a.values.chunks(3).flat_map(|t| [t[0], t[1]]).collect();
        a.components = 2;
    });
    assert_eq!(two.displacement, s.displacement);
    let tensor = |nine: bool| {
        read(&|v| {
            let a = v.array_mut("CellData", "stress");
            a.values = a
                .values
                .chunks(3)
                .flat_map(|t| {
                    if nine {
                        vec![t[0], t[2], 0.0, t[2], t[1], 0.0, 0.0, 0.0, 0.0]
                    } else {
                        vec![t[0], t[2], t[2], t[1]]
                    }
                })
                .collect();
            a.components = if nine { 9 } else { 4 };
        })
    };
    assert_eq!(tensor(false).stress, Some(s.stress.clone()));
    assert_eq!(tensor(true).stress, Some(s.stress.clone()));
}

// ---------------------------------------------------------------------------------------
// One test per error rule: the file, the field and the fix.

/// The bytes of the solution's VTU after `edit`, in `encoding`.
fn vtu_with(encoding: Encoding, edit: impl Fn(&mut Vtu)) -> Vec<u8> {
    let mut vtu = two_bodies(0.7).vtu("Float64");
    edit(&mut vtu);
    vtu.write(&Options::new(encoding))
}

/// The ascii VTU with `from` replaced by `to` in its text.
fn vtu_text_with(from: &str, to: &str) -> Vec<u8> {
    let text = String::from_utf8(vtu_with(Encoding::Ascii, |_| {})).unwrap();
    assert!(text.contains(from), "{from}");
    text.replacen(from, to, 1).into_bytes()
}

fn refused_vtu(bytes: &[u8], field: &str, needles: &[&str]) {
    let file = path("bad.vtu");
    assert_refused(
        parse_vtu(bytes, &file, &FieldNames::default()),
        &file,
        field,
        needles,
    );
}

#[test]
fn a_grid_of_another_type_is_refused() {
    refused_vtu(
        &vtu_text_with("type=\"UnstructuredGrid\"", "type=\"PolyData\""),
        "VTKFile",
        &["\"PolyData\"", "Save Data as .vtu"],
    );
}

#[test]
fn a_parallel_grid_is_refused_with_the_piece_route() {
    refused_vtu(
        &vtu_text_with("type=\"UnstructuredGrid\"", "type=\"PUnstructuredGrid\""),
        "VTKFile",
        &["parallel grid (.pvtu)", "run on one process"],
    );
}

#[test]
fn two_pieces_are_refused() {
    let text = String::from_utf8(vtu_with(Encoding::Ascii, |_| {})).unwrap();
    let (a, b) = (
        text.find("    <Piece").unwrap(),
        text.find("  </UnstructuredGrid>").unwrap(),
    );
    let piece = &text[a..b];
    let twice = format!("{}{piece}{}", &text[..b], &text[b..]);
    refused_vtu(
        twice.as_bytes(),
        "Piece",
        &["more than one <Piece>", "Merge Blocks"],
    );
}

#[test]
fn an_unknown_compressor_or_header_type_is_refused() {
    let text = String::from_utf8(vtu_with(Encoding::Ascii, |_| {})).unwrap();
    let lz4 = text.replacen(
        "header_type=\"UInt32\"",
        "header_type=\"UInt32\" compressor=\"vtkLZ4DataCompressor\"",
        1,
    );
    refused_vtu(lz4.as_bytes(), "VTKFile", &["vtkLZ4DataCompressor", "ZLib"]);
    refused_vtu(
        &vtu_text_with("header_type=\"UInt32\"", "header_type=\"Int16\""),
        "VTKFile",
        &["UInt32 or UInt64"],
    );
}

#[test]
fn big_endian_files_are_read() {
    let s = two_bodies(0.7);
    let o = Options {
        big_endian: true,
        compressed: true,
        header64: true,
        ..Options::new(Encoding::AppendedRaw)
    };
    let step = parse_vtu(
        &s.vtu("Float64").write(&o),
        &path("be.vtu"),
        &FieldNames::default(),
    )
    .unwrap();
    assert_reads_as(&step, &s, Precision::F64, "big-endian");
}

#[test]
fn points_off_the_z0_plane_are_refused() {
    // Round-off in z is accepted, relative to the mesh's size.
    let small = vtu_with(Encoding::Ascii, |v| {
        v.array_mut("Points", "Points").values[2] = 1e-15;
    });
    parse_vtu(&small, &path("z.vtu"), &FieldNames::default()).unwrap();
    let off = vtu_with(Encoding::Ascii, |v| {
        v.array_mut("Points", "Points").values[3 * 4 + 2] = 1e-6;
    });
    refused_vtu(&off, "Points", &["point 4 has z = 1e-6", "z = 0 plane"]);
}

/// Replace the third triangle (cell 3) by a cell of `kind` with `nodes` points.
fn with_cell(kind: f64, nodes: usize) -> Vec<u8> {
    vtu_with(Encoding::Binary, |v| {
        let offsets = v.array_mut("Cells", "offsets").values.clone();
        let (start, end) = (offsets[2] as usize, offsets[3] as usize);
        let c = &mut v.array_mut("Cells", "connectivity").values;
        let extra: Vec<f64> = (0..nodes).map(|i| (i % 10) as f64).collect();
        c.splice(start..end, extra);
        let shift = nodes as f64 - 3.0;
        for o in &mut v.array_mut("Cells", "offsets").values[3..] {
            *o += shift;
        }
        v.array_mut("Cells", "types").values[3] = kind;
    })
}

#[test]
fn quadrilaterals_are_refused_with_the_split_route() {
    refused_vtu(
        &with_cell(9.0, 4),
        "Cells",
        &[
            "cell 3 is a quadrilateral (VTK type 9; 1 such cells)",
            "split each quadrilateral into two triangles",
            "Mesh.RecombineAll = 0",
        ],
    );
}

#[test]
fn quadratic_triangles_are_refused_with_the_p1_route() {
    refused_vtu(
        &with_cell(22.0, 6),
        "Cells",
        &[
            "quadratic triangle (VTK type 22",
            "P2 is not graded yet",
            "interpolate to P1",
        ],
    );
}

#[test]
fn lagrange_triangles_are_refused_with_the_p1_route() {
    refused_vtu(
        &with_cell(69.0, 6),
        "Cells",
        &["Lagrange triangle (VTK type 69", "P2 is not graded yet"],
    );
}

#[test]
fn other_cells_are_refused() {
    refused_vtu(
        &with_cell(10.0, 4),
        "Cells",
        &["VTK type 10", "only P1 triangles are graded"],
    );
}

#[test]
fn vertex_line_and_polyline_cells_are_skipped_with_their_cell_data() {
    // The writer's cells start with a line and end with a vertex and a poly-line, marked
    // body 0 with a stress of 1e30: read as the triangles alone.
    let s = two_bodies(0.7);
    let vtu = s.vtu("Float64");
    assert_eq!(vtu.cells, s.triangles.len() + 3);
    let step = parse_vtu(
        &vtu.write(&Options::new(Encoding::Binary)),
        &path("l.vtu"),
        &FieldNames::default(),
    )
    .unwrap();
    assert_reads_as(&step, &s, Precision::F64, "skipped cells");
    // A poly-vertex (type 2) is skipped too.
    let pv = with_cell(2.0, 3);
    let step = parse_vtu(&pv, &path("pv.vtu"), &FieldNames::default()).unwrap();
    assert_eq!(step.mesh.triangles.len(), s.triangles.len() - 1);
}

#[test]
fn a_missing_body_array_is_refused() {
    refused_vtu(
        &vtu_with(Encoding::AppendedRaw, |v| v.remove("CellData", "body")),
        "CellData/body",
        &[
            "no cell array 'body'",
            "'stress'",
            "1 on the triangles of the scene's first body",
        ],
    );
}

#[test]
fn a_body_mark_other_than_1_or_2_is_refused() {
    refused_vtu(
        &vtu_with(Encoding::Ascii, |v| {
            v.array_mut("CellData", "body").values[2] = 3.0
        }),
        "CellData/body",
        &["cell 2", "has body 3", "marked 1"],
    );
    // Any number type: Float32 marks 1.0 and 2.0 read.
    let floats = vtu_with(Encoding::Binary, |v| {
        v.array_mut("CellData", "body").vtk_type = "Float32"
    });
    parse_vtu(&floats, &path("f.vtu"), &FieldNames::default()).unwrap();
    // A mesh of one body is no two-body solution.
    refused_vtu(
        &vtu_with(Encoding::Ascii, |v| {
            for b in &mut v.array_mut("CellData", "body").values {
                if *b == 2.0 {
                    *b = 1.0;
                }
            }
        }),
        "CellData/body",
        &["no triangle belongs to body 2"],
    );
}

#[test]
fn a_missing_displacement_is_refused() {
    refused_vtu(
        &vtu_with(Encoding::Ascii, |v| v.remove("PointData", "displacement")),
        "PointData/displacement",
        &[
            "no point array 'displacement'",
            "'pressure', 'normal_jump'",
            "or pass --displacement with the name of the one that holds it",
        ],
    );
    // Found as cell data: the message says so.
    refused_vtu(
        &vtu_with(Encoding::Ascii, |v| {
            v.remove("PointData", "displacement");
            let mut a = v.array_mut("CellData", "stress").clone();
            a.name = "displacement".into();
            v.arrays.push(a);
        }),
        "PointData/displacement",
        &["'displacement' is in CellData"],
    );
}

/// The displacement under another name: the error lists the point arrays and names the
/// grade flag that reads an array of 2 or 3 components.
#[test]
fn a_missing_displacement_names_the_flag_for_an_array_of_its_shape() {
    for (components, encoding) in [(3, Encoding::Ascii), (2, Encoding::AppendedRaw)] {
        let bytes = vtu_with(encoding, |v| {
            let a = v.array_mut("PointData", "displacement");
            a.name = "u".into();
            if components == 2 {
                a.components = 2;
                a.values = a.values.chunks(3).flat_map(|t| [t[0], t[1]]).collect();
            }
        });
        refused_vtu(
            &bytes,
            "PointData/displacement",
            &[
                "no point array 'displacement' (the point arrays are 'u', 'pressure', 'normal_jump')",
                &format!(
                    "pass --displacement u ({components} components), or write the nodal displacement as point data named 'displacement'"
                ),
            ],
        );
        // The flag read: the file reads.
        let names = FieldNames {
            displacement: "u".into(),
            ..FieldNames::default()
        };
        assert!(parse_vtu(&bytes, &path("bad.vtu"), &names).is_ok());
    }
}

/// A stress or pressure named with its flag and missing is refused (by default both are
/// optional), with the flag for an array of its shape.
#[test]
fn a_named_stress_or_pressure_missing_is_refused_with_the_flag() {
    let bytes = vtu_with(Encoding::Binary, |_| {});
    let file = path("named.vtu");
    let named = |stress: &str, pressure: &str| FieldNames {
        stress: stress.into(),
        pressure: pressure.into(),
        ..FieldNames::default()
    };
    assert_refused(
        parse_vtu(&bytes, &file, &named("sigma", "pressure")),
        &file,
        "CellData/sigma",
        &[
            "no cell array 'sigma' (the cell arrays are 'body', 'stress')",
            "pass --stress stress (3 components), or leave --stress out to grade E eps(u_h) in its place",
        ],
    );
    assert_refused(
        parse_vtu(&bytes, &file, &named("stress", "p_n")),
        &file,
        "PointData/p_n",
        &[
            "no point array 'p_n'",
            "pass --pressure pressure (1 component) or --pressure normal_jump (1 component), or leave --pressure out",
        ],
    );
    // Under their default names they stay optional.
    let bare = vtu_with(Encoding::Binary, |v| {
        v.remove("CellData", "stress");
        v.remove("PointData", "pressure");
    });
    let step = parse_vtu(&bare, &file, &FieldNames::default()).unwrap();
    assert_eq!((step.stress, step.pressure), (None, None));
    // In an MSH: the views of the kind the file has.
    let text = msh(true);
    assert_refused(
        parse_msh_solution(text.as_bytes(), &file, &named("sigma", "pressure"), BODIES),
        &file,
        "$ElementData \"sigma\"",
        &[
            "no $ElementData view named 'sigma' (the file's $ElementData views are 'stress')",
            "pass --stress stress (9 components)",
        ],
    );
    // A name with a space is quoted for the shell.
    assert_refused(
        parse_msh_solution(text.as_bytes(), &file, &named("stress", "p_n"), BODIES),
        &file,
        "$NodeData \"p_n\"",
        &[
            "no $NodeData view named 'p_n' (the file's $NodeData views are 'displacement', 'von Mises', 'pressure')",
            "pass --pressure 'von Mises' (1 component) or --pressure pressure (1 component)",
        ],
    );
}

#[test]
fn a_nonzero_third_displacement_component_is_refused() {
    // Round-off relative to max |u| passes; more does not.
    let ok = vtu_with(Encoding::Ascii, |v| {
        v.array_mut("PointData", "displacement").values[5] = 1e-18;
    });
    parse_vtu(&ok, &path("u.vtu"), &FieldNames::default()).unwrap();
    refused_vtu(
        &vtu_with(Encoding::Ascii, |v| {
            v.array_mut("PointData", "displacement").values[5] = 1e-9;
        }),
        "PointData/displacement",
        &[
            "third component at point 1 is 1e-9",
            "x and y components only",
        ],
    );
    // f32 files are judged at f32 precision.
    let f32_ok = {
        let mut vtu = two_bodies(0.7).vtu("Float32");
        vtu.array_mut("PointData", "displacement").values[5] = 1e-9;
        vtu.write(&Options::new(Encoding::Binary))
    };
    parse_vtu(&f32_ok, &path("u32.vtu"), &FieldNames::default()).unwrap();
}

#[test]
fn a_displacement_of_other_component_counts_is_refused() {
    refused_vtu(
        &vtu_with(Encoding::Ascii, |v| {
            let a = v.array_mut("PointData", "displacement");
            a.values.truncate(a.values.len() / 3);
            a.components = 1;
        }),
        "PointData/displacement",
        &["1 components per point", "2 (u_x, u_y) or 3"],
    );
}

/// Stress of `components` per cell from `of(s11, s22, s12, cell)`.
fn with_stress(components: usize, of: impl Fn(f64, f64, f64, usize) -> Vec<f64>) -> Vec<u8> {
    vtu_with(Encoding::AppendedBase64, |v| {
        let a = v.array_mut("CellData", "stress");
        a.values = a
            .values
            .chunks(3)
            .enumerate()
            .flat_map(|(i, t)| of(t[0], t[1], t[2], i))
            .collect();
        a.components = components;
    })
}

#[test]
fn an_asymmetric_2x2_stress_is_refused() {
    refused_vtu(
        &with_stress(4, |a, b, c, i| {
            vec![a, c, if i == 4 { c + 1e-6 } else { c }, b]
        }),
        "CellData/stress",
        &["cell 4: s12", "differ by more than round-off", "symmetric"],
    );
}

#[test]
fn a_3x3_stress_out_of_plane_is_refused() {
    refused_vtu(
        &with_stress(9, |a, b, c, i| {
            let zz = if i == 2 { 0.3 * (a + b) } else { 0.0 };
            vec![a, c, 0.0, c, b, 0.0, 0.0, 0.0, zz]
        }),
        "CellData/stress",
        &[
            "cell 2: the z component zz",
            "plane stress",
            "s33 = nu (s11 + s22)",
        ],
    );
}

#[test]
fn a_stress_of_other_component_counts_is_refused() {
    refused_vtu(
        &with_stress(2, |a, b, _, _| vec![a, b]),
        "CellData/stress",
        &[
            "2 components per cell",
            "3 components [s11, s22, s12]",
            "(4, row-major",
            "(9, row-major",
        ],
    );
    // As point data: read per cell only.
    refused_vtu(
        &vtu_with(Encoding::Ascii, |v| {
            let mut a = v.array_mut("PointData", "displacement").clone();
            a.name = "stress".into();
            v.arrays.push(a);
            v.remove("CellData", "stress");
        }),
        "PointData/stress",
        &["'stress' is in PointData", "per cell (P0)"],
    );
}

#[test]
fn a_pressure_of_two_components_is_refused() {
    refused_vtu(
        &vtu_with(Encoding::Ascii, |v| {
            let a = v.array_mut("PointData", "pressure");
            a.values = a.values.iter().flat_map(|&p| [p, p]).collect();
            a.components = 2;
        }),
        "PointData/pressure",
        &["2 components per point", "the pressure has one"],
    );
}

#[test]
fn a_wrong_number_of_tuples_is_refused_in_every_layout() {
    for encoding in Encoding::ALL {
        refused_vtu(
            &vtu_with(encoding, |v| {
                v.array_mut("PointData", "displacement").values.truncate(27);
            }),
            "PointData/displacement",
            &["NumberOfPoints = 10 tuples of 3 components"],
        );
        refused_vtu(
            &vtu_with(encoding, |v| {
                v.array_mut("CellData", "body").values.push(1.0);
            }),
            "CellData/body",
            &["NumberOfCells = 10 tuples of 1 components"],
        );
    }
}

#[test]
fn nan_or_infinity_is_refused_naming_the_array_and_index() {
    for encoding in Encoding::ALL {
        refused_vtu(
            &vtu_with(encoding, |v| {
                v.array_mut("PointData", "displacement").values[3 * 6 + 1] = f64::NAN;
            }),
            "PointData/displacement",
            &["point 6 (component 1) is NaN"],
        );
        refused_vtu(
            &vtu_with(encoding, |v| {
                v.array_mut("Points", "Points").values[3 * 2] = f64::INFINITY;
            }),
            "Points",
            &["point 2 (component 0) is inf"],
        );
        refused_vtu(
            &vtu_with(encoding, |v| {
                v.array_mut("CellData", "stress").values[3 * 5 + 2] = f64::NEG_INFINITY;
            }),
            "CellData/stress",
            &["cell 5 (component 2) is -inf"],
        );
    }
}

#[test]
fn a_triangle_referencing_a_missing_point_is_refused() {
    refused_vtu(
        &vtu_with(Encoding::AppendedRaw, |v| {
            v.array_mut("Cells", "connectivity").values[4] = 10.0;
        }),
        "Cells/connectivity",
        &["cell 1) refers to point 10", "the file has 10 points"],
    );
}

#[test]
fn missing_or_duplicate_arrays_are_refused() {
    refused_vtu(
        &vtu_with(Encoding::Ascii, |v| {
            let a = v.array_mut("PointData", "displacement").clone();
            v.arrays.insert(0, a);
        }),
        "PointData/displacement",
        &["two arrays of PointData are named 'displacement'"],
    );
    refused_vtu(
        &vtu_with(Encoding::Binary, |v| v.remove("Cells", "types")),
        "Cells/types",
        &["no array 'types'"],
    );
}

#[test]
fn corrupt_binary_data_is_refused() {
    // Truncated appended data, and a zlib block with a flipped byte.
    let o = Options {
        compressed: true,
        ..Options::new(Encoding::AppendedRaw)
    };
    let bytes = two_bodies(0.7).vtu("Float64").write(&o);
    let cut = bytes.len() - 60;
    let truncated = [&bytes[..cut], b"\n</AppendedData>\n</VTKFile>\n"].concat();
    let file = path("t.vtu");
    let e = parse_vtu(&truncated, &file, &FieldNames::default()).unwrap_err();
    println!("{e}");
    assert!(e.to_string().starts_with("/data/t.vtu: Cells/"), "{e}");
    let mut flipped = bytes.clone();
    let at = bytes.len() - 40;
    flipped[at] ^= 0x55;
    let e = parse_vtu(&flipped, &file, &FieldNames::default()).unwrap_err();
    println!("{e}");
    assert!(
        e.to_string().contains("zlib") || e.to_string().contains("decompresses"),
        "{e}"
    );
    // An absurd block count: refused before any allocation.
    let text = String::from_utf8_lossy(&bytes).to_string();
    let underscore = text.find("   _").unwrap() + 4;
    let mut huge = bytes.clone();
    huge[underscore..underscore + 4].copy_from_slice(&u32::MAX.to_le_bytes());
    assert_refused(
        parse_vtu(&huge, &file, &FieldNames::default()),
        &file,
        "PointData/displacement",
        &["4294967295 compressed blocks"],
    );
}

#[test]
fn an_unknown_number_type_is_refused() {
    refused_vtu(
        &vtu_text_with(
            "type=\"Int32\" Name=\"body\"",
            "type=\"String\" Name=\"body\"",
        ),
        "CellData/body",
        &["\"String\" is not a VTK number type"],
    );
}

#[test]
fn malformed_xml_is_refused_with_its_line() {
    let file = path("x.vtu");
    let text = String::from_utf8(vtu_with(Encoding::Ascii, |_| {})).unwrap();
    let broken = text.replacen("</PointData>", "</PointDat>", 1);
    let e = parse_vtu(broken.as_bytes(), &file, &FieldNames::default()).unwrap_err();
    println!("{e}");
    assert!(e.to_string().starts_with("/data/x.vtu: XML (line "), "{e}");
}

// PVD.

fn refused_pvd(text: &str, field: &str, needles: &[&str]) {
    let file = path("s.pvd");
    assert_refused(parse_pvd(text.as_bytes(), &file), &file, field, needles);
}

#[test]
fn a_pvd_time_that_is_not_a_finite_number_is_refused() {
    let pvd = |t: &str| {
        format!(
            "<VTKFile type=\"Collection\"><Collection><DataSet timestep=\"0\" file=\"a.vtu\"/><DataSet timestep=\"{t}\" file=\"b.vtu\"/></Collection></VTKFile>"
        )
    };
    for t in ["abc", "nan", "inf", ""] {
        refused_pvd(
            &pvd(t),
            "Collection/DataSet[1]/timestep",
            &["not a finite number"],
        );
    }
    refused_pvd(
        &pvd("0"),
        "Collection/DataSet[1]/timestep",
        &["both have timestep 0"],
    );
}

#[test]
fn a_pvd_dataset_without_a_file_is_refused() {
    refused_pvd(
        "<VTKFile type=\"Collection\"><Collection><DataSet timestep=\"1\"/></Collection></VTKFile>",
        "Collection/DataSet[0]/file",
        &["names no file"],
    );
    refused_pvd(
        "<VTKFile type=\"Collection\"><Collection><DataSet timestep=\"1\" file=\"  \"/></Collection></VTKFile>",
        "Collection/DataSet[0]/file",
        &["names no file"],
    );
    refused_pvd(
        "<VTKFile type=\"Collection\"><Collection><DataSet file=\"a.vtu\"/></Collection></VTKFile>",
        "Collection/DataSet[0]/timestep",
        &["no timestep"],
    );
    refused_pvd(
        "<VTKFile type=\"UnstructuredGrid\"><Collection/></VTKFile>",
        "VTKFile",
        &["type=\"Collection\""],
    );
    refused_pvd(
        "<VTKFile type=\"Collection\"><Collection></Collection></VTKFile>",
        "Collection",
        &["lists no <DataSet>"],
    );
}

// MSH.

fn refused_msh(text: &[u8], field: &str, needles: &[&str]) {
    let file = path("s.msh");
    assert_refused(
        parse_msh_solution(text, &file, &FieldNames::default(), BODIES),
        &file,
        field,
        needles,
    );
}

fn msh(v41: bool) -> String {
    let (a, b) = (two_bodies(0.5), two_bodies(1.0));
    if v41 {
        solution_files::msh41(&[(0.5, &a), (1.0, &b)])
    } else {
        solution_files::msh22(&[(0.5, &a), (1.0, &b)])
    }
}

#[test]
fn a_binary_msh_is_refused_with_the_conversions() {
    let needles = [
        "binary MSH",
        "gmsh file.msh -save -format msh41",
        "Mesh.Binary = 0",
        "binary=False",
    ];
    let binary = msh(true).replacen("4.1 0 8", "4.1 1 8", 1);
    refused_msh(binary.as_bytes(), "$MeshFormat", &needles);
    // With binary bytes after the header, as gmsh writes it.
    let mut bytes = b"$MeshFormat\n4.1 1 8\n".to_vec();
    bytes.extend([1, 0, 0, 0, 0xff, 0xfe, 0x80]);
    refused_msh(&bytes, "$MeshFormat", &needles);
}

#[test]
fn an_msh_of_another_version_is_refused() {
    refused_msh(
        msh(false).replacen("2.2 0 8", "3.0 0 8", 1).as_bytes(),
        "$MeshFormat (line 2)",
        &["MSH version 3.0", "-format msh41"],
    );
}

#[test]
fn a_missing_body_surface_is_refused() {
    for v41 in [true, false] {
        refused_msh(
            msh(v41).replace("\"upper\"", "\"top\"").as_bytes(),
            "$PhysicalNames",
            &[
                "no physical surface named 'upper' (body 2)",
                "lower block, top",
            ],
        );
    }
}

#[test]
fn quadrilaterals_in_a_body_are_refused() {
    // Element 1003 of the 2.2 file becomes a 4-node quadrilateral (type 3).
    let text = msh(false);
    let line = text.lines().find(|l| l.starts_with("1003 2 2 ")).unwrap();
    let quad = line.replacen("1003 2 2 ", "1003 3 2 ", 1) + " 101";
    refused_msh(
        text.replacen(line, &quad, 1).as_bytes(),
        "$Elements",
        &[
            "element 1003 of 'lower block' is a quadrilateral (gmsh type 3)",
            "split each quadrilateral",
        ],
    );
}

#[test]
fn a_missing_displacement_view_is_refused() {
    for (v41, components) in [(true, 3), (false, 2)] {
        // Under another name: the $NodeData views are listed, with the flag that reads one
        // of the displacement's shape.
        refused_msh(
            msh(v41).replace("\"displacement\"", "\"u\"").as_bytes(),
            "$NodeData \"displacement\"",
            &[
                "no $NodeData view named 'displacement' (the file's $NodeData views are 'u', ",
                &format!(
                    "pass --displacement u ({components} components), or write the displacement as a $NodeData view of that name per time step"
                ),
            ],
        );
        // Missing at one time (time 1, written first) only.
        refused_msh(
            msh(v41).replacen("\"displacement\"", "\"u\"", 1).as_bytes(),
            "$NodeData \"displacement\" (time 1)",
            &["no $NodeData view 'displacement' at time 1"],
        );
    }
    let text = msh(true);
    let cut = text.find("$NodeData").unwrap();
    refused_msh(
        text[..cut].as_bytes(),
        "$NodeData \"displacement\"",
        &["no $NodeData view named 'displacement'"],
    );
}

#[test]
fn a_view_missing_a_node_is_refused() {
    let text = msh(true);
    // Drop node 105's displacement at time 1 (written first).
    let start = text.find("\"displacement\"").unwrap();
    let row = text[start..].find("\n105 ").unwrap() + start + 1;
    let end = row + text[row..].find('\n').unwrap() + 1;
    let header = "\"displacement\"\n1\n1e0\n3\n1\n3\n10\n";
    assert!(text[start..].starts_with(header));
    let fewer = format!("{}{}", &text[..row], &text[end..]).replacen(
        header,
        &header.replace("\n10\n", "\n9\n"),
        1,
    );
    refused_msh(
        fewer.as_bytes(),
        "$NodeData \"displacement\" (time 1)",
        &["no value at node 105"],
    );
}

#[test]
fn an_msh_stress_of_other_component_counts_is_refused() {
    let mut edited = msh(false);
    for (time, step) in [("1e0", 1), ("5e-1", 0)] {
        let header = format!("\"stress\"\n1\n{time}\n3\n{step}\n3\n7\n");
        assert!(edited.contains(&header));
        edited = edited.replacen(&header, &header.replace("\n3\n7\n", "\n2\n7\n"), 1);
    }
    // Two values per element now: drop each row's third.
    let rows: Vec<String> = edited
        .lines()
        .map(|l| {
            let w: Vec<&str> = l.split(' ').collect();
            if w.len() == 4 && w[0].starts_with("100") && w[0].len() == 4 {
                w[..3].join(" ")
            } else {
                l.to_string()
            }
        })
        .collect();
    edited = rows.join("\n");
    refused_msh(
        edited.as_bytes(),
        "$ElementData \"stress\" (time 0.5)",
        &["2 components per cell"],
    );
}

#[test]
fn a_non_finite_msh_value_is_refused_with_its_line() {
    let text = msh(false).replacen("101 ", "101 nan ", 1);
    let file = path("s.msh");
    let e = parse_msh_solution(text.as_bytes(), &file, &FieldNames::default(), BODIES).unwrap_err();
    println!("{e}");
    assert!(
        e.to_string().starts_with("/data/s.msh: $Nodes (line "),
        "{e}"
    );
    assert!(e.to_string().contains("finite"), "{e}");
}
