//! Writing results: ParaView VTU of a state ([`vtu`]), the .pvd collection of a time
//! series, and CSVs. Single files are written to a temporary name and renamed, so a failed
//! run never leaves half a file. Reading the solutions other codes write (.vtu, .pvd,
//! gmsh's .msh with views) for grading: [`solution`].

pub mod solution;
pub mod vtu;

use crate::error::{Error, Result};
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

/// Read back what [`finite_or_empty`] wrote: an empty field is NaN.
pub fn empty_as_nan<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<f64, D::Error> {
    let v: Option<f64> = serde::Deserialize::deserialize(d)?;
    Ok(v.unwrap_or(f64::NAN))
}

/// A number that may be NaN or infinite in a CSV cell: written by [`finite_or_empty`], read
/// back by [`empty_as_nan`] (`#[serde(with = "crate::io::finite")]`).
pub mod finite {
    pub use super::empty_as_nan as deserialize;
    pub use super::finite_or_empty as serialize;
}

/// "1 time step", "10 time steps": a count and its noun, plural where the count is not 1
/// (`noun` is the singular; its plural adds an s).
pub fn count(n: usize, noun: &str) -> String {
    match n {
        1 => format!("1 {noun}"),
        n => format!("{n} {noun}s"),
    }
}

/// A memory size given in GiB, in the unit that shows it: "0.3 MiB", "512 MiB", "5.3 GiB".
pub fn memory_text(gib: f64) -> String {
    match gib {
        g if g >= 1.0 => format!("{g:.1} GiB"),
        g if g * 1024.0 >= 10.0 => format!("{:.0} MiB", g * 1024.0),
        g => format!("{:.1} MiB", g * 1024.0),
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
