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
