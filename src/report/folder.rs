//! Output folders written all or nothing, for study reports and `solve` alike: the files go
//! into a staging sibling `.NAME.staging-PID`, which replaces NAME only once the run has
//! succeeded. A failed run removes its staging folder; a killed one leaves it, and the next
//! run into the same folder removes it with a one-line note. The previous folder is never
//! touched before the swap, so it survives any failure byte for byte. A running run holds an
//! advisory lock (flock) on its staging folder, which the system releases when the process
//! ends however it ends: a staging folder is stale exactly when its lock is free, whatever
//! the process ids say (another PID namespace, another system).

use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// The folder of all reports: `reports/` in the crate.
pub fn reports_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("reports")
}

/// What kind of output a folder holds, known by a file every such output has: an existing
/// non-empty folder without it is someone else's and is not replaced.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Output {
    /// A study report (README.md).
    Report,
    /// The output of `solve` (summary.csv).
    Solve,
}

impl Output {
    /// The file every output of this kind holds.
    pub fn signature(self) -> &'static str {
        match self {
            Output::Report => "README.md",
            Output::Solve => "summary.csv",
        }
    }

    fn what(self) -> &'static str {
        match self {
            Output::Report => "reports folder",
            Output::Solve => "--out",
        }
    }
}

const FIX: &str = "pass --out with a writable folder, or make this one writable";

/// Check, before any computing, that `dir` can receive an output of kind `kind`: its parent
/// can be created and written, and `dir` is missing, empty, or an earlier output of the same
/// kind. Creates the parent, never `dir`. Also removes staging debris of killed runs (see
/// [`Staging`]), returning one note per folder removed.
pub fn check_writable(dir: &Path, kind: Output) -> Result<Vec<String>> {
    if dir.file_name().is_none() {
        return Err(Error::input(
            dir,
            kind.what(),
            "names no folder of its own (it is replaced whole); pass --out with a new folder's name, e.g. out",
        ));
    }
    let parent = parent(dir);
    std::fs::create_dir_all(&parent).map_err(|e| {
        Error::input(
            &parent,
            kind.what(),
            format!("cannot create it ({e}); {FIX}"),
        )
    })?;
    if dir.exists() {
        if !dir.is_dir() {
            return Err(Error::input(
                dir,
                kind.what(),
                format!("exists and is not a folder; {FIX}"),
            ));
        }
        let empty = std::fs::read_dir(dir)
            .map_err(|e| Error::io(dir, e))?
            .next()
            .is_none();
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt;
            let (here, above) = (std::fs::metadata(dir), std::fs::metadata(&parent));
            if let (Ok(here), Ok(above)) = (here, above)
                && here.dev() != above.dev()
            {
                return Err(Error::input(
                    dir,
                    kind.what(),
                    "is a mount point, which cannot be replaced; pass --out with a folder inside it",
                ));
            }
        }
        if !empty && !dir.join(kind.signature()).exists() {
            return Err(Error::input(
                dir,
                kind.what(),
                format!(
                    "holds files but no {}, so it is not an earlier output and would be replaced whole; pass --out with a new or empty folder",
                    kind.signature()
                ),
            ));
        }
    }
    let probe = sibling(dir, "probe", std::process::id());
    std::fs::create_dir(&probe).map_err(|e| {
        Error::input(
            &parent,
            kind.what(),
            format!("cannot write here ({e}); {FIX}"),
        )
    })?;
    let _ = std::fs::remove_dir(&probe);
    Ok(remove_stale(dir))
}

/// A folder being written: files go into [`Staging::path`]; [`Staging::commit`] swaps it
/// in for the target, and dropping it uncommitted removes it (a failed run).
pub struct Staging {
    target: PathBuf,
    path: PathBuf,
    committed: bool,
    /// The open staging folder, locked while this run lives (see the module).
    _lock: Option<std::fs::File>,
    /// The first folder above the target this run created, removed again (when empty)
    /// if the run fails.
    created: Option<PathBuf>,
}

impl Staging {
    /// Check `dir` as [`check_writable`] does and create its staging folder; the notes say
    /// which stale staging folders were removed.
    pub fn begin(dir: &Path, kind: Output) -> Result<(Staging, Vec<String>)> {
        let created = parent(dir)
            .ancestors()
            .take_while(|a| !a.as_os_str().is_empty() && !a.exists())
            .last()
            .map(Path::to_path_buf);
        let notes = check_writable(dir, kind)?;
        let path = sibling(dir, "staging", std::process::id());
        let _ = std::fs::remove_dir_all(&path);
        std::fs::create_dir(&path).map_err(|e| {
            Error::input(
                parent(dir),
                kind.what(),
                format!("cannot write here ({e}); {FIX}"),
            )
        })?;
        let lock = std::fs::File::open(&path).ok().filter(try_lock);
        let staging = Staging {
            target: dir.to_path_buf(),
            path,
            committed: false,
            _lock: lock,
            created,
        };
        Ok((staging, notes))
    }

    /// The folder to write into.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Replace the target by the staging folder: one atomic exchange where the file system
    /// has it (Linux renameat2), two renames otherwise; then remove the previous output.
    pub fn commit(mut self) -> Result<()> {
        let old = sibling(&self.target, "old", std::process::id());
        if self.target.exists() {
            let exchanged =
                exchange(&self.path, &self.target).map_err(|e| Error::io(&self.target, e))?;
            if !exchanged {
                std::fs::rename(&self.target, &old).map_err(|e| Error::io(&self.target, e))?;
                if let Err(e) = std::fs::rename(&self.path, &self.target) {
                    // Put the previous output back: the target is never left missing.
                    let _ = std::fs::rename(&old, &self.target);
                    return Err(Error::io(&self.target, e));
                }
                self.committed = true;
                let _ = std::fs::remove_dir_all(&old);
                return Ok(());
            }
            // The staging path now holds the previous output.
            let _ = std::fs::remove_dir_all(&self.path);
        } else {
            std::fs::rename(&self.path, &self.target).map_err(|e| Error::io(&self.target, e))?;
        }
        self.committed = true;
        Ok(())
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_dir_all(&self.path);
            // The folders this run created above the target, if they are still empty.
            if let Some(top) = &self.created {
                for folder in parent(&self.target).ancestors() {
                    if std::fs::remove_dir(folder).is_err() || folder == top {
                        break;
                    }
                }
            }
        }
    }
}

/// Write a report folder all or nothing (see [`Staging`]).
pub fn write_folder(dir: &Path, fill: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let (staging, notes) = Staging::begin(dir, Output::Report)?;
    for n in notes {
        eprintln!("note: {n}");
    }
    fill(staging.path())?;
    staging.commit()
}

/// Write `bytes` as the file `name` in `dir`.
pub fn write(dir: &Path, name: &str, bytes: &[u8]) -> Result<()> {
    let p = dir.join(name);
    std::fs::write(&p, bytes).map_err(|e| Error::io(p, e))
}

fn parent(dir: &Path) -> PathBuf {
    match dir.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// `.NAME.ROLE-PID` beside `dir`.
fn sibling(dir: &Path, role: &str, pid: u32) -> PathBuf {
    let name = dir.file_name().unwrap_or_default().to_string_lossy();
    parent(dir).join(format!(".{name}.{role}-{pid}"))
}

/// Remove the staging and old folders of `dir` left by runs whose process is gone; when a
/// killed run got between its two renames (no atomic exchange), put the previous output
/// back first. One note per folder.
fn remove_stale(dir: &Path) -> Vec<String> {
    let name = dir
        .file_name()
        .unwrap_or_default()
        .to_string_lossy()
        .to_string();
    let Ok(entries) = std::fs::read_dir(parent(dir)) else {
        return Vec::new();
    };
    let mut notes = Vec::new();
    let mut found: Vec<(String, u32, PathBuf)> = entries
        .filter_map(|e| e.ok())
        .filter_map(|e| {
            let file = e.file_name().to_string_lossy().to_string();
            let rest = file.strip_prefix(&format!(".{name}."))?;
            let (role, pid) = rest.rsplit_once('-')?;
            let pid: u32 = pid.parse().ok()?;
            let stale = match role {
                "staging" => !held(&e.path()),
                "old" => !alive(pid),
                _ => false,
            };
            stale.then(|| (role.to_string(), pid, e.path()))
        })
        .collect();
    found.sort();
    for (role, pid, path) in found {
        if role == "old" && !dir.exists() && std::fs::rename(&path, dir).is_ok() {
            notes.push(format!(
                "restored {} from {} (run {pid} was killed while swapping it)",
                dir.display(),
                path.display()
            ));
            continue;
        }
        if std::fs::remove_dir_all(&path).is_ok() {
            notes.push(format!(
                "removed {}, left by run {pid}, which was killed before it finished",
                path.display()
            ));
        }
    }
    notes
}

/// Whether process `pid` runs (Linux: /proc; elsewhere every other process counts as gone).
/// Only for the previous output a run set aside while swapping without an atomic exchange.
fn alive(pid: u32) -> bool {
    pid == std::process::id() || Path::new(&format!("/proc/{pid}")).exists()
}

/// Whether a live run holds the lock of the staging folder `path` (a folder that cannot be
/// opened counts as held: it is left alone).
fn held(path: &Path) -> bool {
    match std::fs::File::open(path) {
        Ok(file) => !try_lock(&file),
        Err(_) => true,
    }
}

/// Take an exclusive advisory lock on `file` without waiting (released when the file is
/// closed, or the process ends).
#[cfg(unix)]
fn try_lock(file: &std::fs::File) -> bool {
    use std::os::unix::io::AsRawFd;
    // SAFETY: flock on a file descriptor this File owns.
    unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) == 0 }
}

#[cfg(not(unix))]
fn try_lock(_: &std::fs::File) -> bool {
    true
}

/// Exchange two paths atomically (Linux renameat2 RENAME_EXCHANGE): Ok(false) where the
/// system or the file system has no such call, the error of any other failure.
#[cfg(target_os = "linux")]
fn exchange(a: &Path, b: &Path) -> std::io::Result<bool> {
    use std::os::unix::ffi::OsStrExt;
    let (Ok(a), Ok(b)) = (
        std::ffi::CString::new(a.as_os_str().as_bytes()),
        std::ffi::CString::new(b.as_os_str().as_bytes()),
    ) else {
        return Ok(false);
    };
    // SAFETY: both are valid NUL-terminated paths; renameat2 only reads them.
    let rc = unsafe {
        libc::renameat2(
            libc::AT_FDCWD,
            a.as_ptr(),
            libc::AT_FDCWD,
            b.as_ptr(),
            libc::RENAME_EXCHANGE,
        )
    };
    if rc == 0 {
        return Ok(true);
    }
    let e = std::io::Error::last_os_error();
    match e.raw_os_error() {
        Some(libc::EINVAL) | Some(libc::ENOSYS) | Some(libc::EOPNOTSUPP) => Ok(false),
        _ => Err(e),
    }
}

#[cfg(not(target_os = "linux"))]
fn exchange(_: &Path, _: &Path) -> std::io::Result<bool> {
    Ok(false)
}
