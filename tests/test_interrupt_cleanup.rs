//! Reference: issue 47 (a new user's runs), part 7: interrupted runs clean up.
//! Goal: a `solve` or `study` ended by SIGINT, SIGTERM or SIGHUP removes its staging
//! folder (and the folders it created above its output), leaves the previous output byte
//! for byte, and exits with 128 + the signal's number (130, 143, 129); a signal the run was
//! started ignoring (`nohup` and SIGHUP) stays ignored. SIGKILL is
//! tests/test_solve_output_folder.rs's case: its debris is removed by the next run.
//! Geometry: the `rates` scene's mesh; the `patch` study's meshes.

use contact_rates::report::{remove_live, write_folder};
use std::collections::BTreeMap;
use std::os::raw::c_int;
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_contact-rates");

/// Start the binary with `args` in `cwd`, with SIGINT, SIGTERM and SIGHUP at their default
/// action (as from a terminal, whatever the test runner inherited) but `ignored`, ignored
/// (as `nohup` does for SIGHUP).
fn start(args: &[&str], cwd: &Path, ignored: Option<c_int>) -> Child {
    let mut c = Command::new(BIN);
    c.args(args)
        .current_dir(cwd)
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    // SAFETY: signal() is async-signal-safe, as a pre_exec hook must be.
    unsafe {
        c.pre_exec(move || {
            for s in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP] {
                let action = if Some(s) == ignored {
                    libc::SIG_IGN
                } else {
                    libc::SIG_DFL
                };
                libc::signal(s, action);
            }
            Ok(())
        });
    }
    c.spawn().unwrap()
}

fn run_ok(args: &[&str], cwd: &Path) {
    let o = Command::new(BIN)
        .args(args)
        .current_dir(cwd)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// Every file under `dir` (relative name -> bytes).
fn snapshot(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let p = e.unwrap().path();
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            (name, std::fs::read(&p).unwrap())
        })
        .collect()
}

/// The entries of `parent` whose names start with `.NAME.` (staging, old, probe folders).
fn debris(parent: &Path, name: &str) -> Vec<PathBuf> {
    let prefix = format!(".{name}.");
    std::fs::read_dir(parent)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with(&prefix)
        })
        .collect()
}

/// Wait (at most 60 s) until `ready()`; the child must still run meanwhile.
fn wait_until(child: &mut Child, what: &str, ready: impl Fn() -> bool) {
    let t = Instant::now();
    while !ready() {
        assert!(
            t.elapsed() < Duration::from_secs(60),
            "no {what} after 60 s"
        );
        assert!(
            child.try_wait().unwrap().is_none(),
            "the run ended before {what}"
        );
        std::thread::sleep(Duration::from_millis(2));
    }
}

fn kill(child: &Child, signo: c_int) {
    // SAFETY: kill() with the id of a child this test started and has not waited for.
    assert_eq!(unsafe { libc::kill(child.id() as libc::pid_t, signo) }, 0);
}

/// Wait for `child` and assert it exited with 128 + `signo`; its stderr.
fn assert_exit(child: Child, signo: c_int) -> String {
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert_eq!(
        (o.status.code(), o.status.signal()),
        (Some(128 + signo), None),
        "exit status after signal {signo}: {:?}; {err}",
        o.status
    );
    err
}

/// `solve --level 5 --steps 40` into a folder that holds a previous output, interrupted once
/// its staging folder has step files (the writer thread may be writing the next one).
fn interrupted_solve(signo: c_int) {
    let dir = tempfile::tempdir().unwrap();
    let cwd = dir.path();
    run_ok(
        &[
            "solve", "--scene", "rates", "--level", "0", "--steps", "2", "--out", "o",
        ],
        cwd,
    );
    let before = snapshot(&cwd.join("o"));
    assert_eq!(
        before.len(),
        2 + 1 + 3,
        "2 steps, solution.vtu, pvd, 2 CSVs"
    );

    let mut child = start(
        &[
            "solve", "--scene", "rates", "--level", "5", "--steps", "40", "--out", "o",
        ],
        cwd,
        None,
    );
    let staging = cwd.join(format!(".o.staging-{}", child.id()));
    wait_until(&mut child, "step file in the staging folder", || {
        std::fs::read_dir(&staging).is_ok_and(|mut d| d.next().is_some())
    });
    kill(&child, signo);
    let err = assert_exit(child, signo);

    assert!(
        err.contains("interrupted by SIG")
            && err.contains("removed its unfinished output ./.o.staging-"),
        "one line says so and names the folder removed: {err}"
    );
    assert_eq!(
        debris(cwd, "o"),
        Vec::<PathBuf>::new(),
        "no staging folder left"
    );
    assert_eq!(
        snapshot(&cwd.join("o")),
        before,
        "the previous output, byte for byte"
    );
}

#[test]
fn sigint_removes_the_staging_folder_and_exits_130() {
    interrupted_solve(libc::SIGINT);
}

#[test]
fn sigterm_removes_the_staging_folder_and_exits_143() {
    interrupted_solve(libc::SIGTERM);
}

#[test]
fn sighup_removes_the_staging_folder_and_exits_129() {
    interrupted_solve(libc::SIGHUP);
}

/// A run started with SIGHUP ignored (`nohup`) goes on after a SIGHUP; SIGTERM still ends
/// it cleanly.
#[test]
fn sighup_ignored_at_the_start_stays_ignored() {
    let dir = tempfile::tempdir().unwrap();
    let cwd = dir.path();
    let mut child = start(
        &[
            "solve", "--scene", "rates", "--level", "5", "--steps", "40", "--out", "o",
        ],
        cwd,
        Some(libc::SIGHUP),
    );
    let staging = cwd.join(format!(".o.staging-{}", child.id()));
    wait_until(&mut child, "step file in the staging folder", || {
        std::fs::read_dir(&staging).is_ok_and(|mut d| d.next().is_some())
    });
    kill(&child, libc::SIGHUP);
    std::thread::sleep(Duration::from_millis(300));
    assert!(
        child.try_wait().unwrap().is_none(),
        "still running after SIGHUP"
    );
    assert!(staging.exists(), "its staging folder too");
    kill(&child, libc::SIGTERM);
    assert_exit(child, libc::SIGTERM);
    assert_eq!(std::fs::read_dir(cwd).unwrap().count(), 0, "nothing left");
}

/// `study patch` interrupted while it computes: into new folders, which it created before
/// computing and removes; into a previous report, which stays byte for byte.
#[test]
fn an_interrupted_study_leaves_nothing_and_the_previous_report() {
    let dir = tempfile::tempdir().unwrap();
    let cwd = dir.path();
    let mut child = start(&["study", "patch", "--out", "new/deeper/rep"], cwd, None);
    wait_until(&mut child, "new/deeper", || cwd.join("new/deeper").exists());
    kill(&child, libc::SIGINT);
    assert_exit(child, libc::SIGINT);
    assert_eq!(
        std::fs::read_dir(cwd).unwrap().count(),
        0,
        "the folders created above the report removed"
    );

    let rep = cwd.join("rep");
    std::fs::create_dir(&rep).unwrap();
    std::fs::write(rep.join("README.md"), "# the previous report\n").unwrap();
    std::fs::write(rep.join("rates.csv"), "level,h\n0,0.5\n").unwrap();
    let before = snapshot(&rep);
    let child = start(&["study", "patch", "--out", "rep"], cwd, None);
    // The study computes for over a second before its report folder is staged.
    std::thread::sleep(Duration::from_millis(400));
    kill(&child, libc::SIGTERM);
    let err = assert_exit(child, libc::SIGTERM);
    assert!(
        err.contains("interrupted by SIGTERM while patch: ")
            && err.contains("no output was written or changed"),
        "one line says what the run was doing and that nothing was written: {err}"
    );
    assert_eq!(debris(cwd, "rep"), Vec::<PathBuf>::new());
    assert_eq!(snapshot(&rep), before, "the previous report, byte for byte");
}

/// A study's report folder is staged only at its end, by write_folder: registered there, so
/// that an interrupt while the report is written removes it too.
#[test]
fn a_report_being_written_is_removed_on_interrupt() {
    let dir = tempfile::tempdir().unwrap();
    let rep = dir.path().join("rep");
    std::fs::create_dir(&rep).unwrap();
    std::fs::write(rep.join("README.md"), "# the previous report\n").unwrap();
    let before = snapshot(&rep);
    let mut seen = None;
    let written = write_folder(&rep, |staging| {
        std::fs::write(staging.join("rates.csv"), "level,h\n").unwrap();
        let interrupted = remove_live();
        assert_eq!(interrupted.removed, [staging.to_path_buf()]);
        seen = Some(staging.to_path_buf());
        // The process would exit here; the test goes on, so the report must not be swapped.
        drop(interrupted);
        Err(contact_rates::Error::io(
            staging,
            std::io::Error::other("interrupted"),
        ))
    });
    assert!(written.is_err());
    assert!(!seen.unwrap().exists(), "the staging folder removed");
    assert_eq!(debris(dir.path(), "rep"), Vec::<PathBuf>::new());
    assert_eq!(snapshot(&rep), before);
}

/// A run interrupted while gmsh refines its meshes ends gmsh and leaves no temporary mesh
/// in the cache (issue 74: a `.tmp.msh` was left there), and a later run still finds
/// the cached levels it completed.
#[test]
fn an_interrupted_refinement_leaves_no_temporary_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let cache = dir.path().join("cache");
    let mut c = Command::new(BIN);
    c.args([
        "solve", "--scene", "rates", "--level", "6", "--steps", "1", "--out", "o",
    ])
    .current_dir(dir.path())
    .env("CONTACT_RATES_CACHE", &cache)
    .stdout(Stdio::null())
    .stderr(Stdio::piped());
    // SAFETY: signal() is async-signal-safe, as a pre_exec hook must be.
    unsafe {
        c.pre_exec(|| {
            libc::signal(libc::SIGINT, libc::SIG_DFL);
            Ok(())
        });
    }
    let mut child = c.spawn().unwrap();
    let cached = |level: usize| {
        std::fs::read_dir(&cache)
            .into_iter()
            .flatten()
            .flatten()
            .any(|e| {
                e.file_name()
                    .to_string_lossy()
                    .ends_with(&format!("-L{level}.msh"))
            })
    };
    // Level 4 cached: gmsh is refining level 5 (a few seconds on 2 cores).
    wait_until(&mut child, "level 4 in the mesh cache", || cached(4));
    kill(&child, libc::SIGINT);
    let err = assert_exit(child, libc::SIGINT);
    assert!(err.contains("interrupted by SIGINT"), "{err}");
    let temporary = || -> Vec<String> {
        std::fs::read_dir(&cache)
            .unwrap()
            .flatten()
            .map(|e| e.file_name().to_string_lossy().to_string())
            .filter(|n| n.ends_with(".tmp.msh"))
            .collect()
    };
    assert_eq!(temporary(), Vec::<String>::new(), "{err}");
    // gmsh was ended, not orphaned: nothing appears later either.
    std::thread::sleep(Duration::from_millis(1500));
    assert_eq!(
        temporary(),
        Vec::<String>::new(),
        "a temporary mesh written after the exit"
    );
    assert!(cached(4), "the completed levels stay cached");
}
