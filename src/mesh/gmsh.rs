//! Running gmsh on a `.geo` with parameters, uniform refinement by splitting, and a
//! content-addressed cache of the generated meshes outside git.

use crate::error::{Error, Result};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

/// The folder where generated meshes are cached: `$CONTACT_RATES_CACHE` if set,
/// otherwise `target/mesh-cache` under the crate.
pub fn cache_dir() -> PathBuf {
    match std::env::var_os("CONTACT_RATES_CACHE") {
        Some(p) if !p.is_empty() => PathBuf::from(p),
        _ => Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("target")
            .join("mesh-cache"),
    }
}

/// The gmsh executable, found on PATH.
fn gmsh_command() -> String {
    "gmsh".to_string()
}

fn missing_gmsh(cmd: &str) -> Error {
    Error::Gmsh(format!(
        "the command `{cmd}` was not found on PATH; install it (Debian: `apt-get update && apt-get install -y gmsh`) and run again"
    ))
}

/// The gmsh version string (e.g. "4.8.4"), asked once per process.
pub fn gmsh_version() -> Result<String> {
    static VERSION: OnceLock<std::result::Result<String, String>> = OnceLock::new();
    let cmd = gmsh_command();
    let v = VERSION.get_or_init(|| match Command::new(&cmd).arg("--version").output() {
        Ok(out) if out.status.success() => {
            let s = String::from_utf8_lossy(&out.stdout).to_string()
                + &String::from_utf8_lossy(&out.stderr);
            Ok(s.trim().to_string())
        }
        Ok(out) => Err(format!("`{cmd} --version` failed with {}", out.status)),
        Err(_) => Err(missing_gmsh(&cmd).to_string()),
    });
    v.clone()
        .map_err(|e| Error::Gmsh(e.trim_start_matches("gmsh: ").to_string()))
}

/// Hex SHA-256 of a byte string.
pub fn sha256_hex(bytes: &[u8]) -> String {
    let mut h = Sha256::new();
    h.update(bytes);
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// Run gmsh with `args`; on failure return its error lines. `out` must exist afterwards.
fn run_gmsh(args: &[String], out: &Path, what: &Path) -> Result<()> {
    let cmd = gmsh_command();
    let start_error = |e: std::io::Error| {
        if e.kind() == std::io::ErrorKind::NotFound {
            missing_gmsh(&cmd)
        } else {
            Error::Gmsh(format!("could not start `{cmd}`: {e}"))
        }
    };
    let child = Command::new(&cmd)
        .args(args)
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .map_err(start_error)?;
    // An interrupted run ends gmsh before it removes the file gmsh writes.
    let registered = crate::interrupt::RunningChild::new(child.id());
    let output = child.wait_with_output().map_err(start_error)?;
    drop(registered);
    let text = String::from_utf8_lossy(&output.stdout).to_string()
        + &String::from_utf8_lossy(&output.stderr);
    let has_errors = text.lines().any(|l| l.starts_with("Error"));
    if !output.status.success() || has_errors {
        let _ = std::fs::remove_file(out);
        let detail = if has_errors {
            summarize_errors(&text)
        } else {
            text.lines().last().unwrap_or("").to_string()
        };
        return Err(Error::Input {
            file: what.to_path_buf(),
            field: "gmsh".into(),
            message: format!(
                "gmsh failed ({}): {detail}; fix the geometry or its parameters",
                output.status
            ),
        });
    }
    if !out.exists() {
        return Err(Error::input(
            what,
            "gmsh",
            "gmsh exited 0 but wrote no mesh; check the .geo defines Physical Surface groups",
        ));
    }
    Ok(())
}

/// Most distinct gmsh error messages quoted in an error.
const MAX_DISTINCT_ERRORS: usize = 3;

/// gmsh's error lines as their distinct messages with counts, in order of first
/// appearance, at most [`MAX_DISTINCT_ERRORS`] of them (gmsh repeats one error per element
/// or edge: "Wrong mesh element size" 1040 times for a negative size).
pub fn summarize_errors(text: &str) -> String {
    let mut distinct: Vec<(String, usize)> = Vec::new();
    for line in text.lines().filter(|l| l.starts_with("Error")) {
        let message = line
            .trim_start_matches("Error")
            .trim_start()
            .trim_start_matches(':')
            .trim()
            .to_string();
        match distinct.iter_mut().find(|(m, _)| *m == message) {
            Some(entry) => entry.1 += 1,
            None => distinct.push((message, 1)),
        }
    }
    let mut parts: Vec<String> = distinct
        .iter()
        .take(MAX_DISTINCT_ERRORS)
        .map(|(m, n)| {
            if *n > 1 {
                format!("'{m}' (x{n})")
            } else {
                format!("'{m}'")
            }
        })
        .collect();
    if distinct.len() > MAX_DISTINCT_ERRORS {
        parts.push(format!(
            "and {} other messages",
            distinct.len() - MAX_DISTINCT_ERRORS
        ));
    }
    parts.join("; ")
}

/// Run gmsh with `args` writing the temporary file `tmp`, check that what it wrote parses
/// (a failed run can leave a broken file), and only then publish it as `path`. `what` is
/// shown on a terminal while gmsh runs; errors name `geo`, `bad` and `fix` say what went
/// wrong and how to fix it.
fn produce(
    args: &[String],
    tmp: &Path,
    path: &Path,
    geo: &Path,
    (what, bad, fix): (&str, &str, &str),
) -> Result<()> {
    let spinner = crate::progress::Progress::spinner(&format!("gmsh: {what}"));
    // An interrupted run removes the partial mesh instead of leaving it in the cache.
    let _registered = crate::interrupt::TemporaryFile::new(tmp);
    let ran = run_gmsh(args, tmp, geo);
    spinner.finish();
    ran?;
    super::msh::read_msh(tmp).map_err(|e| {
        let _ = std::fs::remove_file(tmp);
        Error::input(geo, "gmsh", format!("{bad} ({e}){fix}"))
    })?;
    std::fs::rename(tmp, path).map_err(|e| Error::io(path, e))
}

/// A generated mesh file with its provenance.
#[derive(Debug, Clone)]
pub struct GeneratedMesh {
    /// The cached MSH 4.1 file.
    pub path: PathBuf,
    /// SHA-256 of the .geo file's bytes.
    pub geo_hash: String,
    /// gmsh version used.
    pub gmsh_version: String,
}

/// How a level above 0 splits every triangle in four.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Split {
    /// `gmsh -refine` of the cached level L - 1: new boundary nodes at edge midpoints, on
    /// level 0's chords (exactly nested levels; right for polygonal bodies).
    Chords,
    /// gmsh's `RefineMesh` L times in the session that meshed the .geo: each new boundary
    /// node is placed on its .geo curve, so a circle arc's trace converges to the arc (the
    /// levels are nested but for those nodes).
    OnCurves,
}

/// Generate (or fetch from the cache) the mesh of `geo` with `params` refined `level` times
/// by uniform splitting. Level 0 is gmsh's own 2D mesh; level L splits level L-1 (nested).
pub fn generate(geo: &Path, params: &[(String, f64)], level: usize) -> Result<GeneratedMesh> {
    generate_in(&cache_dir(), geo, params, level, Split::Chords)
}

/// The cache key of `geo` with `params`: the stem of its files' names and the hash of the
/// .geo's bytes, the parameters and the gmsh version; with the .geo's own hash and the
/// version.
fn cache_key(geo: &Path, params: &[(String, f64)]) -> Result<(String, String, String)> {
    let bytes = std::fs::read(geo).map_err(|e| Error::io(geo, e))?;
    let version = gmsh_version()?;
    let geo_hash = sha256_hex(&bytes);
    let mut key = bytes;
    for (k, v) in params {
        key.extend_from_slice(format!("\n{k}={v:e}").as_bytes());
    }
    key.extend_from_slice(version.as_bytes());
    let stem = geo.file_stem().and_then(|s| s.to_str()).unwrap_or("mesh");
    let name = format!("{stem}-{}", &sha256_hex(&key)[..20]);
    Ok((name, geo_hash, version))
}

/// Where [`generate_in`] keeps (or would keep) the mesh of `geo` with `params` at `level`
/// in the cache folder `dir`, whether or not it is there.
pub fn cache_path(
    dir: &Path,
    geo: &Path,
    params: &[(String, f64)],
    level: usize,
    split: Split,
) -> Result<PathBuf> {
    let (name, _, _) = cache_key(geo, params)?;
    Ok(dir.join(file_name(&name, level, split)))
}

/// The cached file of `level`: level 0 is the same mesh whichever the split.
fn file_name(name: &str, level: usize, split: Split) -> String {
    match (split, level) {
        (Split::OnCurves, 1..) => format!("{name}-curves-L{level}.msh"),
        _ => format!("{name}-L{level}.msh"),
    }
}

/// [`generate`] with the cache in the folder `dir`.
pub fn generate_in(
    dir: &Path,
    geo: &Path,
    params: &[(String, f64)],
    level: usize,
    split: Split,
) -> Result<GeneratedMesh> {
    let (name, geo_hash, version) = cache_key(geo, params)?;
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    if split == Split::OnCurves && level > 0 {
        let path = dir.join(file_name(&name, level, split));
        if !path.exists() {
            split_on_curves(dir, geo, params, level, &path)?;
        }
        return Ok(GeneratedMesh {
            path,
            geo_hash,
            gmsh_version: version,
        });
    }
    let stem = geo.file_stem().and_then(|s| s.to_str()).unwrap_or("mesh");
    let path_of = |l: usize| dir.join(file_name(&name, l, Split::Chords));
    // Find the finest cached level at or below `level`.
    let mut have = None;
    for l in (0..=level).rev() {
        if path_of(l).exists() {
            have = Some(l);
            break;
        }
    }
    let tmp = |l: usize| temporary(dir, &format!("{name}-L{l}"), "msh");
    let start = match have {
        Some(l) => l + 1,
        None => {
            let mut args: Vec<String> = vec![geo.display().to_string(), "-2".into()];
            args.extend(set_numbers(params));
            args.extend(["-format".into(), "msh41".into(), "-o".into()]);
            let t = tmp(0);
            args.push(t.display().to_string());
            produce(
                &args,
                &t,
                &path_of(0),
                geo,
                (
                    &format!("meshing {stem} (level 0)"),
                    "gmsh wrote an unusable mesh",
                    "; fix the .geo",
                ),
            )?;
            1
        }
    };
    for l in start..=level {
        let t = tmp(l);
        let args: Vec<String> = vec![
            path_of(l - 1).display().to_string(),
            "-refine".into(),
            "-format".into(),
            "msh41".into(),
            "-o".into(),
            t.display().to_string(),
        ];
        produce(
            &args,
            &t,
            &path_of(l),
            geo,
            (
                &format!("refining {stem} to level {l} of {level}"),
                "gmsh -refine wrote an unusable mesh",
                "",
            ),
        )?;
    }
    Ok(GeneratedMesh {
        path: path_of(level),
        geo_hash,
        gmsh_version: version,
    })
}

/// Level `level` of `geo` made in one gmsh session ([`Split::OnCurves`]): a script that
/// includes the .geo, meshes it and splits it `level` times with `RefineMesh`, which
/// places each new boundary node on its curve while the .geo's geometry is loaded (a
/// `-refine` of a saved .msh sees only its segments). Written to `path` through a
/// temporary file; the script is removed afterwards.
fn split_on_curves(
    dir: &Path,
    geo: &Path,
    params: &[(String, f64)],
    level: usize,
    path: &Path,
) -> Result<()> {
    // Absolute, not canonical: a .geo behind a link includes what sits beside the link,
    // as `gmsh geo -2` (level 0) does.
    let absolute = std::path::absolute(geo).map_err(|e| Error::io(geo, e))?;
    let shown = absolute.display().to_string();
    if shown.contains('"') {
        return Err(Error::input(
            geo,
            "geo",
            "the .geo's path holds a '\"', which a gmsh script cannot include; rename its folder",
        ));
    }
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("mesh");
    let (script, tmp) = (temporary(dir, stem, "geo"), temporary(dir, stem, "msh"));
    let text = format!(
        "Include \"{shown}\";\nMesh 2;\n{}",
        "RefineMesh;\n".repeat(level)
    );
    std::fs::write(&script, text).map_err(|e| Error::io(&script, e))?;
    let _script = crate::interrupt::TemporaryFile::new(&script);
    let mut args: Vec<String> = vec![script.display().to_string()];
    args.extend(set_numbers(params));
    args.extend(["-save", "-format", "msh41", "-o"].map(String::from));
    args.push(tmp.display().to_string());
    let made = produce(
        &args,
        &tmp,
        path,
        geo,
        (
            &format!("meshing and splitting {stem} on its curves"),
            "gmsh RefineMesh wrote an unusable mesh",
            "; fix the .geo",
        ),
    );
    let _ = std::fs::remove_file(&script);
    made
}

/// A temporary file name in `dir` unique to this process and call: several threads or
/// processes may generate the same mesh.
fn temporary(dir: &Path, stem: &str, extension: &str) -> PathBuf {
    static COUNTER: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    dir.join(format!("{stem}.{}-{n}.tmp.{extension}", std::process::id()))
}

/// gmsh's `-setnumber NAME VALUE` for each parameter.
fn set_numbers(params: &[(String, f64)]) -> Vec<String> {
    params
        .iter()
        .flat_map(|(k, v)| ["-setnumber".into(), k.clone(), format!("{v:e}")])
        .collect()
}
