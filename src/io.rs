//! Writing results: ParaView VTU of a state, and one-row summary CSVs. Files are written
//! to a temporary name and renamed, so a failed run never leaves half a file.

use crate::error::{Error, Result};
use crate::fe::Model;
use crate::material::von_mises;
use crate::metrics::ContactNode;
use crate::solve::State;
use std::fmt::Write as _;
use std::path::Path;

/// Write `contents` to `path` atomically (temp file in the same folder, then rename).
pub fn write_atomic(path: &Path, contents: &[u8]) -> Result<()> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let tmp = dir.join(format!(
        ".{}.{}.tmp",
        path.file_name().unwrap().to_string_lossy(),
        std::process::id()
    ));
    std::fs::write(&tmp, contents).map_err(|e| Error::io(&tmp, e))?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        Error::io(path, e)
    })
}

/// ParaView-readable unstructured grid of both bodies at `state`: point data
/// `displacement`, `pressure` and `normal_jump` (at the slave nodes of Gamma_C from
/// `contact`, zero elsewhere), cell data `stress` (s11 s22 s12), `von_mises` and `body`
/// (1 or 2).
pub fn vtu(model: &Model, state: &State, contact: &[ContactNode]) -> String {
    let np = model.n_nodes;
    let nc = model.elements.len();
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n<UnstructuredGrid>"
    );
    let _ = writeln!(s, "<Piece NumberOfPoints=\"{np}\" NumberOfCells=\"{nc}\">");
    s.push_str(
        "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n",
    );
    for g in 0..np {
        let p = model.position(g);
        let _ = writeln!(s, "{:e} {:e} 0", p[0], p[1]);
    }
    s.push_str("</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    for e in &model.elements {
        let _ = writeln!(s, "{} {} {}", e.nodes[0], e.nodes[1], e.nodes[2]);
    }
    s.push_str("</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    for i in 0..nc {
        let _ = writeln!(s, "{}", 3 * (i + 1));
    }
    s.push_str("</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    for _ in 0..nc {
        s.push_str("5\n");
    }
    s.push_str("</DataArray>\n</Cells>\n<PointData Vectors=\"displacement\">\n<DataArray type=\"Float64\" Name=\"displacement\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for g in 0..np {
        let _ = writeln!(s, "{:e} {:e} 0", state.u[2 * g], state.u[2 * g + 1]);
    }
    let (mut pressure, mut jump) = (vec![0.0; np], vec![0.0; np]);
    for c in contact {
        pressure[c.node] = c.pressure;
        jump[c.node] = c.normal_jump;
    }
    for (name, values) in [("pressure", &pressure), ("normal_jump", &jump)] {
        let _ = writeln!(
            s,
            "</DataArray>\n<DataArray type=\"Float64\" Name=\"{name}\" format=\"ascii\">"
        );
        for v in values {
            let _ = writeln!(s, "{v:e}");
        }
    }
    s.push_str("</DataArray>\n</PointData>\n<CellData Scalars=\"von_mises\">\n<DataArray type=\"Float64\" Name=\"stress\" NumberOfComponents=\"3\" ComponentName0=\"s11\" ComponentName1=\"s22\" ComponentName2=\"s12\" format=\"ascii\">\n");
    for sg in &state.sigma {
        let _ = writeln!(s, "{:e} {:e} {:e}", sg[0], sg[1], sg[2]);
    }
    s.push_str("</DataArray>\n<DataArray type=\"Float64\" Name=\"von_mises\" format=\"ascii\">\n");
    for sg in &state.sigma {
        let _ = writeln!(s, "{:e}", von_mises(sg));
    }
    s.push_str("</DataArray>\n<DataArray type=\"Int32\" Name=\"body\" format=\"ascii\">\n");
    for e in &model.elements {
        let _ = writeln!(s, "{}", e.body + 1);
    }
    s.push_str("</DataArray>\n</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    s
}

/// A ParaView collection (.pvd) of the time series: one (time, file name) per step, the
/// files relative to the .pvd's folder.
pub fn pvd(steps: &[(f64, String)]) -> String {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n<Collection>\n",
    );
    for (time, file) in steps {
        let _ = writeln!(
            s,
            "<DataSet timestep=\"{time:e}\" group=\"\" part=\"0\" file=\"{file}\"/>"
        );
    }
    s.push_str("</Collection>\n</VTKFile>\n");
    s
}

/// Serialize records with a header into CSV bytes.
pub fn csv_bytes<T: serde::Serialize>(records: &[T]) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for r in records {
        w.serialize(r)
            .map_err(|e| Error::io("csv", std::io::Error::other(e.to_string())))?;
    }
    w.into_inner()
        .map_err(|e| Error::io("csv", std::io::Error::other(e.to_string())))
}

/// Serialize a number as itself when finite and as an empty field otherwise, so no NaN or
/// infinity reaches a CSV report (a rate that cannot be fitted is blank).
pub fn finite_or_empty<S: serde::Serializer>(
    v: &f64,
    s: S,
) -> std::result::Result<S::Ok, S::Error> {
    if v.is_finite() {
        s.serialize_f64(*v)
    } else {
        s.serialize_str("")
    }
}

/// `{:.3}` of a finite number, "n/a" otherwise.
pub fn fmt3(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.3}")
    } else {
        "n/a".into()
    }
}
