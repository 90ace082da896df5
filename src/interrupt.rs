//! The signals that interrupt a run from outside: SIGINT (Ctrl-C), SIGTERM (`kill`,
//! `timeout`) and SIGHUP (the terminal closed). The binary catches them to remove its
//! staging folders ([`crate::report::folder::remove_live`]) before it exits.

use std::os::raw::c_int;

/// SIGINT, SIGTERM, SIGHUP.
pub const SIGNALS: [c_int; 3] = [libc::SIGINT, libc::SIGTERM, libc::SIGHUP];

/// Those of [`SIGNALS`] that this process did not start with ignored. A signal ignored at
/// the start stays ignored, as the caller asked: `nohup` ignores SIGHUP so that a run
/// outlives its terminal, a shell without job control ignores SIGINT in a background job.
pub fn catchable() -> Vec<c_int> {
    SIGNALS.into_iter().filter(|&s| !ignored(s)).collect()
}

/// Whether signal `signo` is ignored now (SIG_IGN).
fn ignored(signo: c_int) -> bool {
    // SAFETY: sigaction with a null new action only reads the current one into `old`, a
    // zeroed sigaction (a valid value of this plain C struct).
    unsafe {
        let mut old: libc::sigaction = std::mem::zeroed();
        libc::sigaction(signo, std::ptr::null(), &mut old) == 0 && old.sa_sigaction == libc::SIG_IGN
    }
}

/// Files being written outside a report folder (gmsh's temporary meshes in the cache) that
/// an interrupted run removes ([`remove_temporary_files`]) before it exits.
static TEMPORARY: std::sync::Mutex<Vec<std::path::PathBuf>> = std::sync::Mutex::new(Vec::new());

fn temporary() -> std::sync::MutexGuard<'static, Vec<std::path::PathBuf>> {
    TEMPORARY
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// A temporary file registered for removal on interruption while this value lives; dropped,
/// it is unregistered (the file itself is left to its writer: renamed into place or
/// removed on failure).
pub struct TemporaryFile(std::path::PathBuf);

impl TemporaryFile {
    /// Register `path`.
    pub fn new(path: &std::path::Path) -> Self {
        temporary().push(path.to_path_buf());
        TemporaryFile(path.to_path_buf())
    }
}

impl Drop for TemporaryFile {
    fn drop(&mut self) {
        temporary().retain(|p| p != &self.0);
    }
}

/// Child processes (gmsh) writing registered temporary files: an interrupted run ends them
/// first, so that none writes its file after it was removed.
static CHILDREN: std::sync::Mutex<Vec<u32>> = std::sync::Mutex::new(Vec::new());

fn children() -> std::sync::MutexGuard<'static, Vec<u32>> {
    CHILDREN
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// A child process registered to be ended on interruption while this value lives.
pub struct RunningChild(u32);

impl RunningChild {
    /// Register the child `pid`.
    pub fn new(pid: u32) -> Self {
        children().push(pid);
        RunningChild(pid)
    }
}

impl Drop for RunningChild {
    fn drop(&mut self) {
        children().retain(|&p| p != self.0);
    }
}

/// End every registered child process (SIGKILL, then reaped), then remove every registered
/// temporary file that exists; how many files were removed.
pub fn remove_temporary_files() -> usize {
    for &pid in children().iter() {
        // SAFETY: kill and waitpid on a child of this process that is still registered
        // (not yet reaped by its owner, which unregisters it after its wait).
        unsafe {
            libc::kill(pid as libc::pid_t, libc::SIGKILL);
            libc::waitpid(pid as libc::pid_t, std::ptr::null_mut(), 0);
        }
    }
    temporary()
        .iter()
        .filter(|p| std::fs::remove_file(p).is_ok())
        .count()
}
