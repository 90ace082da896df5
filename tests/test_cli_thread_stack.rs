//! Reference: `contact_rates::on_pool` (the CLI's whole work runs on a thread of rayon's
//! pool) and the helper's review of it, which found `scene list` and the manufactured
//! scenes overflowing a pool thread's default stack (exmex differentiates their
//! expressions recursively: 1.5-1.6 MiB in a release build, more in a debug one).
//! Goal: the CLI does not depend on the default stack of a spawned thread: `on_pool` gives
//! the pool's threads the main thread's 8 MiB, whatever `RUST_MIN_STACK` says.
//! Data: `scene list` (loads every built-in scene, the manufactured ones included) and
//! `solve --scene contact-mms` with the default stack of spawned threads set to 256 KiB.

use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_contact-rates");

/// Run the CLI with `args`, spawned threads' default stack 256 KiB, on 1 and 2 threads.
fn runs_with_small_default_stacks(args: &[&str]) {
    for threads in ["1", "2"] {
        let out = Command::new(BIN)
            .args(args)
            .env("RUST_MIN_STACK", "262144")
            .env("RAYON_NUM_THREADS", threads)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{args:?} on {threads} threads: {:?}\n{}",
            out.status,
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

#[test]
fn scene_list_runs_with_small_default_stacks() {
    runs_with_small_default_stacks(&["scene", "list"]);
}

#[test]
fn manufactured_scene_solves_with_small_default_stacks() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    runs_with_small_default_stacks(&[
        "solve",
        "--scene",
        "contact-mms",
        "--steps",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
}
