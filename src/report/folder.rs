//! Output folders written all or nothing, for study reports and `solve` alike: the files go
//! into a staging sibling `.NAME.staging-PID`, which replaces NAME only once the run has
//! succeeded. A failed run removes its staging folder, and so does one interrupted by a
//! signal the binary catches (SIGINT, SIGTERM, SIGHUP: see [`remove_live`]); a killed one
//! (SIGKILL) leaves it, and the next run into the same folder removes it with a one-line
//! note. The previous folder is never touched before the swap, so it survives any failure
//! byte for byte. A running run holds an advisory lock (flock) on its staging folder, which
//! the system releases when the process ends however it ends: a staging folder is stale
//! exactly when its lock is free, whatever the process ids say (another PID namespace,
//! another system).

use crate::error::{Error, Result};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};

/// The folder of all reports: `reports/` in the crate.
pub fn reports_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("reports")
}

/// Where a study writes its report by default: target/reports under the checkout, outside
/// version control, so that running a study leaves a clean checkout clean (its timings and
/// provenance differ from run to run). `study NAME --publish` writes the committed report
/// under [`reports_dir`] instead.
pub fn scratch_reports_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("target")
        .join("reports")
}

/// What kind of output a folder holds, known by a file every such output has: an existing
/// non-empty folder without it is someone else's and is not replaced.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Output {
    /// A study report (README.md).
    Report,
    /// The output of `solve` (summary.csv).
    Solve,
    /// An exported problem (problem.toml).
    Export,
}

impl Output {
    /// The file every output of this kind holds.
    pub fn signature(self) -> &'static str {
        match self {
            Output::Report => "README.md",
            Output::Solve => "summary.csv",
            Output::Export => "problem.toml",
        }
    }

    fn what(self) -> &'static str {
        match self {
            Output::Report => "reports folder",
            Output::Solve | Output::Export => "--out",
        }
    }
}

const FIX: &str = "pass --out with a writable folder, or make this one writable";

/// Check, before any computing, that `dir` can receive an output of kind `kind`: its parent
/// can be created and written, and `dir` is missing, empty, or an earlier output of the same
/// kind. Creates the parent, never `dir`. Also removes staging debris of killed runs (see
/// [`Staging`]), returning one note per folder removed.
pub fn check_writable(dir: &Path, kind: Output) -> Result<Vec<String>> {
    // Under the registry's lock: an interrupting signal finds the folders created above
    // `dir` registered, or none created yet.
    let mut live = live();
    let created = first_missing(dir);
    let notes = check(dir, kind)?;
    live.add(None, created.map(|top| (parent(dir), top)));
    Ok(notes)
}

/// [`check_writable`] without the registry.
fn check(dir: &Path, kind: Output) -> Result<Vec<String>> {
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
    /// Its entry in the registry of live folders (see [`remove_live`]).
    id: u64,
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
        // Under the registry's lock from the check to the registration: an interrupting
        // signal finds this staging folder registered, or none created yet.
        let mut live = live();
        let created = first_missing(dir);
        let notes = check(dir, kind)?;
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
        let id = live.add(
            Some(path.clone()),
            created.clone().map(|top| (parent(dir), top)),
        );
        let staging = Staging {
            target: dir.to_path_buf(),
            path,
            committed: false,
            id,
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
        keep_unchanged_times(&self.path, &self.target);
        // The swap holds the registry's lock, so an interrupting signal waits for it to end
        // (see [`remove_live`]): the target is the previous output or the new one, never
        // half swapped. What is left to remove afterwards, the previous output, is
        // registered in place of the staging folder.
        let mut live = live();
        if self.target.exists() {
            let exchanged =
                exchange(&self.path, &self.target).map_err(|e| Error::io(&self.target, e))?;
            let previous = if exchanged {
                // The staging path now holds the previous output.
                self.path.clone()
            } else {
                std::fs::rename(&self.target, &old).map_err(|e| Error::io(&self.target, e))?;
                if let Err(e) = std::fs::rename(&self.path, &self.target) {
                    // Put the previous output back: the target is never left missing.
                    let _ = std::fs::rename(&old, &self.target);
                    return Err(Error::io(&self.target, e));
                }
                old
            };
            self.committed = true;
            live.set(self.id, Some(previous.clone()));
            drop(live);
            let _ = std::fs::remove_dir_all(&previous);
        } else {
            std::fs::rename(&self.path, &self.target).map_err(|e| Error::io(&self.target, e))?;
            self.committed = true;
            live.set(self.id, None);
        }
        Ok(())
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        let mut live = live();
        if !self.committed {
            let _ = std::fs::remove_dir_all(&self.path);
            if let Some(top) = &self.created {
                remove_created(&parent(&self.target), top);
            }
        }
        live.remove(self.id);
    }
}

/// The folders of this process that an interrupted run removes: staging folders (or, once
/// swapped in, the previous output they replaced) and the first folder above an output that
/// a run created.
struct Live {
    entries: Vec<Entry>,
    next_id: u64,
}

struct Entry {
    id: u64,
    /// A folder to remove whole.
    folder: Option<PathBuf>,
    /// (an output's parent, the first folder above the output the run created): the empty
    /// folders from the first up to the second are removed.
    created: Option<(PathBuf, PathBuf)>,
}

impl Live {
    /// Register `folder` and `created` (see [`Entry`]); the entry's id.
    fn add(&mut self, folder: Option<PathBuf>, created: Option<(PathBuf, PathBuf)>) -> u64 {
        let id = self.next_id;
        self.next_id += 1;
        self.entries.push(Entry {
            id,
            folder,
            created,
        });
        id
    }

    /// Entry `id` now has `folder` to remove and nothing created (its output is in place).
    fn set(&mut self, id: u64, folder: Option<PathBuf>) {
        if let Some(e) = self.entries.iter_mut().find(|e| e.id == id) {
            e.folder = folder;
            e.created = None;
        }
    }

    fn remove(&mut self, id: u64) {
        self.entries.retain(|e| e.id != id);
    }
}

static LIVE: Mutex<Live> = Mutex::new(Live {
    entries: Vec::new(),
    next_id: 0,
});

/// The registry of live folders, locked (a panic elsewhere while it was held leaves it
/// usable: every change to it is one push, one field set or one removal).
fn live() -> MutexGuard<'static, Live> {
    LIVE.lock().unwrap_or_else(PoisonError::into_inner)
}

/// The registry of live folders held after [`remove_live`]: while it is held no staging
/// folder of this process is created, swapped in or removed.
#[must_use = "hold it until the process exits: dropped, a run may go on writing"]
pub struct Interrupted {
    _live: MutexGuard<'static, Live>,
    /// The folders removed, staging folders first in the order they were created.
    pub removed: Vec<PathBuf>,
}

/// Remove what this process's runs have under way, for a run interrupted by a signal that
/// is about to exit: every staging folder being written (or previous output being deleted
/// after a swap) and, when they are empty again, the folders the runs created above their
/// outputs. Waits for a swap under way to end (the target is then the new output). The
/// returned value holds the registry locked: runs that go on meanwhile wait at their next
/// staging step (a creation, a swap, a removal) instead of writing a new folder.
pub fn remove_live() -> Interrupted {
    let live = live();
    let mut removed = Vec::new();
    for e in &live.entries {
        if let Some(folder) = &e.folder
            && remove_busy(folder)
        {
            removed.push(folder.clone());
        }
    }
    for e in &live.entries {
        if let Some((below, top)) = &e.created {
            remove_created(below, top);
        }
    }
    Interrupted {
        _live: live,
        removed,
    }
}

/// Remove the folder `path` whole while another thread may still be writing into it (the
/// step-file writer of `solve`): a file created between the listing and the removal makes
/// the removal fail, so retry, a bounded number of times. Whether `path` was there and is
/// gone now.
fn remove_busy(path: &Path) -> bool {
    if std::fs::symlink_metadata(path).is_err() {
        return false;
    }
    for _ in 0..200 {
        let _ = std::fs::remove_dir_all(path);
        if std::fs::symlink_metadata(path).is_err() {
            return true;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    false
}

/// Remove the empty folders from `below` up to `top` (the first folder above an output
/// that its run created), stopping at the first that is not empty.
fn remove_created(below: &Path, top: &Path) {
    for folder in below.ancestors() {
        if std::fs::remove_dir(folder).is_err() || folder == top {
            break;
        }
    }
}

/// The first folder above `dir` that does not exist yet (a run creates it and those below).
fn first_missing(dir: &Path) -> Option<PathBuf> {
    parent(dir)
        .ancestors()
        .take_while(|a| !a.as_os_str().is_empty() && !a.exists())
        .last()
        .map(Path::to_path_buf)
}

/// Give every staged file whose bytes equal the previous output's file of that name the
/// previous file's modification time: the swap then changes the time of a file only where its
/// bytes change, so that a make-like tool (workflow/Snakefile) rebuilds only what depends on a
/// changed file. Best effort: a file whose time cannot be read or set keeps the new one.
fn keep_unchanged_times(staged: &Path, previous: &Path) {
    let Ok(entries) = std::fs::read_dir(staged) else {
        return;
    };
    for entry in entries.flatten() {
        let (new, old) = (entry.path(), previous.join(entry.file_name()));
        let same = match (std::fs::read(&new), std::fs::read(&old)) {
            (Ok(a), Ok(b)) => a == b,
            _ => false,
        };
        let time = std::fs::metadata(&old).and_then(|m| m.modified());
        if let (true, Ok(time)) = (same, time) {
            if let Ok(file) = std::fs::File::options().write(true).open(&new) {
                let _ = file.set_modified(time);
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
