//! Reference: issue 23 (`solve` output a user can trust and afford), SPEC section 8.
//! Goal: `solve` writes its output folder all or nothing: a killed run leaves the previous
//! folder byte for byte and debris the next run removes with a note; a second run into the
//! same folder leaves only its own files; a failed run leaves nothing; a folder that is not
//! an earlier output is refused. The binary VTU decodes, with the test's own reader
//! (tests/common/vtu.rs: string search and flate2's decoder), to the solver's arrays bit for
//! bit. `scene list` lists the built-in scenes.
//! Geometry: meshes/two_blocks.geo (scene `patch`) and the `rates` scene's mesh.

mod common;
use contact_rates::contact::Method;
use contact_rates::io::vtu::StateFile;
use contact_rates::metrics::{ContactNode, contact_nodes};
use contact_rates::solve::{self, Settings, State};
use std::collections::BTreeMap;
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

const BIN: &str = env!("CARGO_BIN_EXE_contact-rates");

/// `contact-rates solve --scene SCENE ARGS... --out OUT`.
fn solve(scene: &str, args: &[&str], out: &Path) -> Output {
    solve_with_env(scene, args, out, &[])
}

fn solve_with_env(scene: &str, args: &[&str], out: &Path, envs: &[(&str, &str)]) -> Output {
    let mut all = vec!["solve", "--scene", scene];
    all.extend_from_slice(args);
    all.extend(["--out", out.to_str().unwrap()]);
    common::run(&all, envs)
}

fn ok(o: &Output) {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// Every file under `dir` (relative name -> bytes).
fn snapshot(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut files = BTreeMap::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        assert!(
            p.is_file(),
            "only files in an output folder: {}",
            p.display()
        );
        let name = p.file_name().unwrap().to_string_lossy().to_string();
        files.insert(name, std::fs::read(&p).unwrap());
    }
    files
}

/// The entries beside `dir` whose names start with `.NAME.` (staging, old, probe folders).
fn debris(dir: &Path) -> Vec<PathBuf> {
    let prefix = format!(".{}.", dir.file_name().unwrap().to_string_lossy());
    std::fs::read_dir(dir.parent().unwrap())
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

/// Start `solve --scene rates --level 4 --steps STEPS --out OUT` and wait until its first
/// step file exists in its staging folder; the child and the staging folder.
fn start_and_wait_for_a_step(out: &Path, steps: &str) -> (std::process::Child, PathBuf) {
    let mut child = Command::new(BIN)
        .args([
            "solve", "--scene", "rates", "--level", "4", "--steps", steps,
        ])
        .args(["--out", out.to_str().unwrap()])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let name = out.file_name().unwrap().to_string_lossy();
    let staging = out
        .parent()
        .unwrap()
        .join(format!(".{name}.staging-{}", child.id()));
    let t = std::time::Instant::now();
    while !staging.join("solution_0001.vtu").exists() {
        assert!(t.elapsed().as_secs() < 300, "no step file after 300 s");
        assert!(child.try_wait().unwrap().is_none(), "the run ended first");
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    (child, staging)
}

/// A `solve` killed with SIGKILL right after its first step file appears leaves the previous
/// output byte for byte; the next run removes the killed run's staging folder with a note.
#[test]
fn a_killed_solve_leaves_the_previous_folder_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    ok(&solve("patch", &["--level", "1", "--steps", "3"], &out));
    let before = snapshot(&out);
    assert_eq!(
        before.len(),
        3 + 1 + 3,
        "3 steps, solution.vtu, pvd, 2 CSVs"
    );

    let (mut child, staging) = start_and_wait_for_a_step(&out, "40");
    child.kill().unwrap();
    let status = child.wait().unwrap();
    assert_eq!(status.signal(), Some(9), "killed mid-run: {status:?}");

    assert_eq!(snapshot(&out), before, "the previous folder, byte for byte");
    assert_eq!(
        debris(&out),
        [staging.clone()],
        "the killed run's staging folder"
    );

    let o = solve("patch", &["--level", "1", "--steps", "2"], &out);
    ok(&o);
    let err = String::from_utf8_lossy(&o.stderr);
    let note = format!("note: removed {}", staging.display());
    assert!(err.contains(&note), "a one-line note: {err}");
    assert!(debris(&out).is_empty(), "{:?}", debris(&out));
    assert_eq!(snapshot(&out).len(), 2 + 1 + 3, "the new run's files");
}

/// 10 steps, then 4 steps into the same folder: only the second run's files remain.
#[test]
fn ten_steps_then_four_leave_only_the_second_runs_files() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    ok(&solve("patch", &["--steps", "10"], &out));
    assert!(out.join("solution_0010.vtu").exists());
    ok(&solve("patch", &["--steps", "4"], &out));
    let names: Vec<String> = snapshot(&out).into_keys().collect();
    assert_eq!(
        names,
        [
            "contact.csv",
            "solution.pvd",
            "solution.vtu",
            "solution_0001.vtu",
            "solution_0002.vtu",
            "solution_0003.vtu",
            "solution_0004.vtu",
            "summary.csv"
        ]
    );
    let mut summary = csv::Reader::from_path(out.join("summary.csv")).unwrap();
    let steps = summary.headers().unwrap().iter().position(|h| h == "steps");
    let row = summary.records().next().unwrap().unwrap();
    assert_eq!(&row[steps.unwrap()], "4");
    assert!(debris(&out).is_empty());
}

/// One thread (`RAYON_NUM_THREADS=1`: the steps are written on the solve's thread) and
/// two (a writer thread beside the solve, the bodies' factorizations side by side) write
/// the same folder byte for byte but summary.csv's timings; the console says where the
/// files were written.
#[test]
fn one_thread_and_two_write_the_same_files() {
    let dir = tempfile::tempdir().unwrap();
    let mut folders = Vec::new();
    for threads in ["1", "2"] {
        let out = dir.path().join(format!("out{threads}"));
        let args = ["--level", "2", "--steps", "3"];
        let o = solve_with_env("rates", &args, &out, &[("RAYON_NUM_THREADS", threads)]);
        ok(&o);
        let console =
            String::from_utf8_lossy(&o.stdout).to_string() + &String::from_utf8_lossy(&o.stderr);
        let place = if threads == "1" {
            "on the solve's thread (RAYON_NUM_THREADS=1)"
        } else {
            "on a second thread"
        };
        assert!(console.contains(place), "{console}");
        let mut files = snapshot(&out);
        files.remove("summary.csv");
        folders.push(files);
    }
    assert_eq!(folders[0].len(), 6);
    assert!(folders[0] == folders[1], "the two folders differ");
}

/// A run refused after its staging folder exists (a size that is not positive is found
/// while the case is built) leaves no folder where there was none, and the previous folder
/// unchanged where there was one; no debris either way.
#[test]
fn a_failed_solve_leaves_nothing_behind() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let o = solve("rates", &["--set", "h_upper=0"], &out);
    assert_eq!(o.status.code(), Some(1));
    assert!(!out.exists(), "no folder from a refused run");
    assert!(debris(&out).is_empty());

    ok(&solve("patch", &["--steps", "2"], &out));
    let before = snapshot(&out);
    let o = solve("rates", &["--set", "h_upper=0"], &out);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(snapshot(&out), before);
    assert!(debris(&out).is_empty());
}

/// A non-empty folder that is not an earlier output (no summary.csv) is refused before
/// anything is computed, and left as it was.
#[test]
fn a_folder_that_is_not_an_earlier_output_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("mine");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("notes.txt"), "keep me").unwrap();
    let o = solve("patch", &["--steps", "1"], &out);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    for needle in ["mine", "--out", "summary.csv", "new or empty folder"] {
        assert!(err.contains(needle), "message lacks '{needle}': {err}");
    }
    assert_eq!(
        std::fs::read_to_string(out.join("notes.txt")).unwrap(),
        "keep me"
    );
    assert_eq!(snapshot(&out).len(), 1);
}

/// Compare `vtu` with the model and `state` bit for bit.
fn assert_bitwise(
    vtu: &common::vtu::Vtu,
    case: &contact_rates::case::Case,
    state: &State,
    nodes: &[ContactNode],
) {
    let model = &case.problem.model;
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<u64>>();
    assert_eq!(vtu.points, model.n_nodes);
    assert_eq!(vtu.cells, model.elements.len());
    let (points, c) = vtu.f64("Points", "Points");
    assert_eq!(c, 3);
    let expected: Vec<f64> = (0..model.n_nodes)
        .flat_map(|g| [model.position(g)[0], model.position(g)[1], 0.0])
        .collect();
    assert_eq!(bits(&points), bits(&expected), "points");
    let connectivity: Vec<i32> = model
        .elements
        .iter()
        .flat_map(|e| e.nodes.map(|n| n as i32))
        .collect();
    assert_eq!(vtu.i32("Cells", "connectivity"), connectivity);
    let offsets: Vec<i32> = (1..=model.elements.len() as i32).map(|i| 3 * i).collect();
    assert_eq!(vtu.i32("Cells", "offsets"), offsets);
    assert!(
        vtu.u8("Cells", "types").iter().all(|&t| t == 5),
        "triangles"
    );
    let body: Vec<i32> = model.elements.iter().map(|e| e.body as i32 + 1).collect();
    assert_eq!(vtu.i32("CellData", "body"), body);
    let (u, c) = vtu.f64("PointData", "displacement");
    assert_eq!(c, 3);
    let expected: Vec<f64> = (0..model.n_nodes)
        .flat_map(|g| [state.u[2 * g], state.u[2 * g + 1], 0.0])
        .collect();
    assert_eq!(bits(&u), bits(&expected), "displacement");
    let (stress, c) = vtu.f64("CellData", "stress");
    assert_eq!(c, 3);
    let expected: Vec<f64> = state
        .sigma
        .iter()
        .flat_map(|s| [s[0], s[1], s[2]])
        .collect();
    assert_eq!(bits(&stress), bits(&expected), "stress");
    let (mut pressure, mut jump) = (vec![0.0; model.n_nodes], vec![0.0; model.n_nodes]);
    for c in nodes {
        pressure[c.node] = c.pressure;
        jump[c.node] = c.normal_jump;
    }
    assert!(pressure.iter().any(|&p| p > 0.0), "some contact pressure");
    assert_eq!(bits(&vtu.f64("PointData", "pressure").0), bits(&pressure));
    assert_eq!(bits(&vtu.f64("PointData", "normal_jump").0), bits(&jump));
}

/// Reference: VTK's XML file formats (appended raw data, vtkZLibDataCompressor, UInt64
/// headers). Data: scene `rates`, level 2 (1,760 triangles: several 32 KiB blocks per
/// array), mortar, newton, 3 steps. Every state the solver produces, written by the
/// library and decoded by the test's reader, equals the solver's arrays bit for bit; and the
/// file the binary writes for the last step equals the in-process state bit for bit (the
/// solve is deterministic).
#[test]
fn vtu_decodes_to_the_solvers_arrays_bit_for_bit() {
    let case = common::case("rates", 2, Method::Mortar, &[]);
    let dir = tempfile::tempdir().unwrap();
    let writer = StateFile::new(&case.problem.model);
    let mut kept: Vec<(PathBuf, State, Vec<ContactNode>)> = Vec::new();
    solve::solve_observed(
        &case.problem,
        &Settings::default(),
        3,
        &mut |n, _, state, _| {
            let nodes = contact_nodes(&case.problem, state);
            let file = dir.path().join(format!("step_{n}.vtu"));
            std::fs::write(&file, writer.file(state, &nodes)).unwrap();
            kept.push((file, state.clone(), nodes));
            Ok(())
        },
    )
    .unwrap();
    assert_eq!(kept.len(), 3);
    for (file, state, nodes) in &kept {
        assert_bitwise(&common::vtu::read(file), &case, state, nodes);
    }
    let out = dir.path().join("out");
    ok(&solve("rates", &["--level", "2", "--steps", "3"], &out));
    let (_, state, nodes) = &kept[2];
    assert_bitwise(
        &common::vtu::read(&out.join("solution_0003.vtu")),
        &case,
        state,
        nodes,
    );
}

/// `scene list` prints every built-in scene with its description; an unknown scene's error
/// names them and the command.
#[test]
fn scene_list_names_every_built_in_scene() {
    let o = common::run(&["scene", "list"], &[]);
    ok(&o);
    let text = String::from_utf8_lossy(&o.stdout);
    let names = contact_rates::scene::builtin_names();
    assert!(names.len() >= 10, "{names:?}");
    for n in &names {
        let scene = contact_rates::scene::Scene::load(n).unwrap();
        let line = text
            .lines()
            .find(|l| l.split_whitespace().next() == Some(n.as_str()))
            .unwrap_or_else(|| panic!("{n} not listed: {text}"));
        assert!(line.ends_with(&scene.description), "{line}");
    }
    assert_eq!(text.lines().count(), names.len());
    let dir = tempfile::tempdir().unwrap();
    let o = solve("no-such-scene", &[], &dir.path().join("o"));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        err.contains("scene list") && err.contains("contact-mms-vp"),
        "{err}"
    );
}

/// A live run's staging folder is locked: another run into the same folder (here one that
/// fails on its input) leaves it alone and prints no note, whatever the process ids say.
#[test]
fn a_live_runs_staging_folder_is_left_alone() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let (mut child, staging) = start_and_wait_for_a_step(&out, "400");
    let o = solve("rates", &["--set", "h_upper=0"], &out);
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    let alive = child.try_wait().unwrap().is_none();
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(alive, "the long run was still running during the check");
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(!err.contains("note: removed"), "{err}");
    assert!(
        staging.exists(),
        "the live run's staging folder is still there"
    );
}

/// `--out .` names no folder of its own and is refused before anything is computed; a
/// failed run removes the folders it created above `--out`.
#[test]
fn out_must_name_a_folder_and_failed_runs_leave_no_parents() {
    let dir = tempfile::tempdir().unwrap();
    let o = Command::new(BIN)
        .args(["solve", "--scene", "patch", "--out", "."])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("names no folder of its own"), "{err}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    let deep = dir.path().join("missing").join("deeper").join("out");
    let o = solve("rates", &["--set", "h_upper=0"], &deep);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        !dir.path().join("missing").exists(),
        "created parents removed"
    );
}
