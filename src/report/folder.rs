//! Report folders: checked before any computing, written whole into a temporary sibling
//! and swapped in, so a failed run leaves the previous report intact.

use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// The folder of all reports: `reports/` in the crate.
pub fn reports_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("reports")
}

/// Check, before any computing, that the report folder `dir` can be written (its parent is
/// created when missing): a study that runs for minutes must not fail at the end.
pub fn check_writable(dir: &Path) -> Result<()> {
    let parent = dir.parent().unwrap_or(Path::new("."));
    let fix = "pass --out with a writable folder, or make this one writable";
    std::fs::create_dir_all(parent).map_err(|e| {
        Error::input(
            parent,
            "reports folder",
            format!("cannot create it ({e}); {fix}"),
        )
    })?;
    if dir.exists() && !dir.is_dir() {
        return Err(Error::input(
            dir,
            "reports folder",
            format!("exists and is not a folder; {fix}"),
        ));
    }
    let name = dir.file_name().unwrap_or_default().to_string_lossy();
    let probe = parent.join(format!(".{name}.probe-{}", std::process::id()));
    std::fs::create_dir(&probe).map_err(|e| {
        Error::input(
            parent,
            "reports folder",
            format!("cannot write here ({e}); {fix}"),
        )
    })?;
    let _ = std::fs::remove_dir(&probe);
    Ok(())
}

/// Write a report folder atomically: fill a temporary sibling, then swap it in, so a failed
/// run leaves the previous report intact.
pub fn write_folder(dir: &Path, fill: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let parent = dir.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(parent).map_err(|e| Error::io(parent, e))?;
    let name = dir.file_name().unwrap().to_string_lossy().to_string();
    let tmp = parent.join(format!(".{name}.tmp-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    std::fs::create_dir_all(&tmp).map_err(|e| {
        Error::input(
            parent,
            "reports folder",
            format!(
                "cannot write here ({e}); make the folder writable or run from a writable checkout"
            ),
        )
    })?;
    if let Err(e) = fill(&tmp) {
        let _ = std::fs::remove_dir_all(&tmp);
        return Err(e);
    }
    let old = parent.join(format!(".{name}.old-{}", std::process::id()));
    if dir.exists() {
        std::fs::rename(dir, &old).map_err(|e| Error::io(dir, e))?;
    }
    std::fs::rename(&tmp, dir).map_err(|e| Error::io(dir, e))?;
    let _ = std::fs::remove_dir_all(&old);
    Ok(())
}

/// Write `bytes` as the file `name` in `dir`.
pub fn write(dir: &Path, name: &str, bytes: &[u8]) -> Result<()> {
    let p = dir.join(name);
    std::fs::write(&p, bytes).map_err(|e| Error::io(p, e))
}
