//! Reference: SPEC section 8 (bad input).
//! Goal: every bad input of the core solver's path (scene data, .geo, .msh, gmsh missing
//! or failing) stops the binary with one clear message naming the file, the field and the
//! fix, a non-zero exit, no panic, and no half-written output.

mod common;
use std::path::{Path, PathBuf};
use std::process::Output;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The built-in rates scene with `edit` applied, written into `dir`.
fn scene_file(dir: &Path, edit: impl Fn(String) -> String) -> PathBuf {
    let text = std::fs::read_to_string(repo().join("scenes/rates.toml")).unwrap();
    let geo = repo().join("meshes/two_blocks.geo");
    let text = text.replace(
        "\"../meshes/two_blocks.geo\"",
        &format!("{:?}", geo.display().to_string()),
    );
    let f = dir.join("scene.toml");
    std::fs::write(&f, edit(text)).unwrap();
    f
}

/// Assert a clean failure whose message contains every one of `needles`.
fn fails_with(out: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "exit code; stderr: {err}");
    assert!(!err.contains("panicked"), "panic: {err}");
    assert_eq!(
        err.lines().filter(|l| l.starts_with("error")).count(),
        1,
        "one error line: {err}"
    );
    for n in needles {
        assert!(err.contains(n), "message lacks '{n}': {err}");
    }
}

fn solve_scene(scene: &Path, out: &Path, envs: &[(&str, &str)]) -> Output {
    common::run(
        &[
            "solve",
            "--scene",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        envs,
    )
}

#[test]
fn scene_data_errors_name_file_field_and_fix() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let cases: Vec<(Box<dyn Fn(String) -> String>, Vec<&str>)> = vec![
        (
            Box::new(|t| t.replace("final_time = 1.0", "final_time = [")),
            vec!["scene.toml", "toml (line", "fix the scene file"],
        ),
        (
            Box::new(|t| t.replace("steps = 10", "steps = 10\ncolour = 3")),
            vec!["scene.toml", "unknown field `colour`"],
        ),
        (
            Box::new(|t| t.replace("final_time = 1.0\n", "")),
            vec!["scene.toml", "missing field `final_time`"],
        ),
        (
            Box::new(|t| t.replacen("young = 100.0", "young = -1.0", 1)),
            vec!["scene.toml", "bodies[0].young", "positive"],
        ),
        (
            Box::new(|t| t.replacen("poisson = 0.3", "poisson = 0.5", 1)),
            vec!["bodies[0].poisson", "(-1, 0.5)"],
        ),
        (
            Box::new(|t| t.replacen("lambda = 100.0", "lambda = 0.0", 1)),
            vec!["bodies[0].lambda", "positive"],
        ),
        (
            Box::new(|t| t.replacen("yield_stress = 3.1622776601683795", "yield_stress = -2", 1)),
            vec!["bodies[0].yield_stress", "positive"],
        ),
        (
            Box::new(|t| t.replace("final_time = 1.0", "final_time = 0.0")),
            vec!["final_time", "positive"],
        ),
        (
            Box::new(|t| t.replace("steps = 10", "steps = 0")),
            vec!["steps", "at least 1"],
        ),
        (
            Box::new(|t| t.replace("-10*t*(0.1 + cos(pi*x))", "-10*t*(")),
            vec!["traction[0].g[1]", "cannot parse expression"],
        ),
        (
            Box::new(|t| t.replace("-10*t*(0.1 + cos(pi*x))", "-10*z")),
            vec!["traction[0].g[1]", "unknown variable 'z'"],
        ),
        (
            Box::new(|t| t.replace("curve = \"left_upper\"", "curve = \"bottom\"")),
            vec!["roller[0].curve", "claimed twice"],
        ),
        (
            Box::new(|t| t.replace("component = \"x\"", "component = \"z\"")),
            vec!["roller[0].component", "\"x\" or \"y\""],
        ),
        (
            Box::new(|t| t.replace("slave_body = \"upper\"", "slave_body = \"top\"")),
            vec!["contact.slave_body", "upper"],
        ),
    ];
    for (edit, needles) in cases {
        let f = scene_file(dir.path(), edit);
        fails_with(&solve_scene(&f, &out, &[]), &needles);
        assert!(!out.exists(), "no output after a failure");
    }
}

#[test]
fn expression_that_is_not_finite_is_reported_with_its_place() {
    let dir = tempfile::tempdir().unwrap();
    let f = scene_file(dir.path(), |t| {
        t.replace("-10*t*(0.1 + cos(pi*x))", "1/(x-x)")
    });
    fails_with(
        &solve_scene(&f, &dir.path().join("o"), &[]),
        &["traction[0].g[1]", "1/(x-x)", "not finite"],
    );
}

#[test]
fn mesh_lacking_a_physical_group_lists_what_it_has() {
    let dir = tempfile::tempdir().unwrap();
    let f = scene_file(dir.path(), |t| {
        t.replace(
            "master_curve = \"contact_lower\"",
            "master_curve = \"interface\"",
        )
    });
    fails_with(
        &solve_scene(&f, &dir.path().join("o"), &[]),
        &[
            "scene.toml: contact.master_curve: the mesh of",
            "no physical curve named 'interface'",
            "contact_lower",
        ],
    );
    let f = scene_file(dir.path(), |t| {
        t.replace("surface = \"lower\"", "surface = \"base\"")
    });
    fails_with(
        &solve_scene(&f, &dir.path().join("o"), &[]),
        &[
            "scene.toml: bodies[1].surface: the mesh of",
            "no physical surface named 'base'",
            "lower, upper",
        ],
    );
}

#[test]
fn unknown_scene_method_solver_and_steps() {
    let dir = tempfile::tempdir().unwrap();
    let o = dir.path().join("o");
    let o = o.to_str().unwrap();
    fails_with(
        &common::run(&["solve", "--scene", "nosuch", "--out", o], &[]),
        &["no built-in scene named 'nosuch'", "patch", "rates"],
    );
    fails_with(
        &common::run(
            &[
                "solve", "--scene", "rates", "--method", "penalty", "--out", o,
            ],
            &[],
        ),
        &["--method", "mortar", "nts"],
    );
    fails_with(
        &common::run(
            &["solve", "--scene", "rates", "--solver", "cg", "--out", o],
            &[],
        ),
        &["--solver", "newton, paper or qp"],
    );
    fails_with(
        &common::run(
            &["solve", "--scene", "rates", "--steps", "0", "--out", o],
            &[],
        ),
        &["--steps", "at least 1"],
    );
}

#[test]
fn geo_with_a_syntax_error() {
    let dir = tempfile::tempdir().unwrap();
    let geo = dir.path().join("broken.geo");
    std::fs::write(&geo, "Point(1) = {0, 0, 0, 0.1;\nLine(1) = {1, 2};\n").unwrap();
    let f = scene_file(dir.path(), |t| {
        t.replace(
            &format!(
                "{:?}",
                repo().join("meshes/two_blocks.geo").display().to_string()
            ),
            "\"broken.geo\"",
        )
    });
    let cache = dir.path().join("cache");
    fails_with(
        &solve_scene(
            &f,
            &dir.path().join("o"),
            &[("CONTACT_RATES_CACHE", cache.to_str().unwrap())],
        ),
        &["broken.geo", "gmsh failed", "fix the geometry"],
    );
    let left: Vec<_> = std::fs::read_dir(&cache)
        .map(|r| r.flatten().collect())
        .unwrap_or_default();
    assert!(
        left.is_empty(),
        "nothing half-written in the cache: {left:?}"
    );
}

#[test]
fn gmsh_missing_from_path() {
    let dir = tempfile::tempdir().unwrap();
    let cache = dir.path().join("cache");
    let f = scene_file(dir.path(), |t| t);
    fails_with(
        &solve_scene(
            &f,
            &dir.path().join("o"),
            &[
                ("PATH", "/nonexistent"),
                ("CONTACT_RATES_CACHE", cache.to_str().unwrap()),
            ],
        ),
        &["gmsh", "not found on PATH", "apt-get install -y gmsh"],
    );
}

/// A fake gmsh on PATH: answers --version, writes `body` to the -o file, exits with `code`.
fn fake_gmsh(dir: &Path, body: &str, code: i32) -> String {
    let bin = dir.join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    let script = format!(
        "#!/bin/sh\nif [ \"$1\" = --version ]; then echo 4.8.4; exit 0; fi\nout=\nwhile [ $# -gt 0 ]; do if [ \"$1\" = -o ]; then out=$2; fi; shift; done\nprintf '%s' '{body}' > \"$out\"\nexit {code}\n"
    );
    let p = bin.join("gmsh");
    std::fs::write(&p, script).unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).unwrap();
    format!("{}:/usr/bin:/bin", bin.display())
}

#[test]
fn gmsh_failing_after_writing_a_broken_mesh() {
    for (code, needles) in [
        (1, vec!["gmsh failed", "exit status: 1"]),
        (0, vec!["unusable mesh", "$Nodes"]),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let path = fake_gmsh(
            dir.path(),
            "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 5 1 5\n",
            code,
        );
        let cache = dir.path().join("cache");
        let f = scene_file(dir.path(), |t| t);
        fails_with(
            &solve_scene(
                &f,
                &dir.path().join("o"),
                &[
                    ("PATH", &path),
                    ("CONTACT_RATES_CACHE", cache.to_str().unwrap()),
                ],
            ),
            &needles,
        );
        let left: Vec<_> = std::fs::read_dir(&cache)
            .map(|r| r.flatten().collect())
            .unwrap_or_default();
        assert!(
            left.is_empty(),
            "the broken mesh is not left in the cache: {left:?}"
        );
    }
}

/// The quick study file with `edit` applied, written into `dir`.
fn study_file(dir: &Path, edit: impl Fn(String) -> String) -> PathBuf {
    let text = std::fs::read_to_string(repo().join("studies/rates-quick.toml")).unwrap();
    let f = dir.join("study.toml");
    std::fs::write(&f, edit(text)).unwrap();
    f
}

#[test]
fn study_file_errors_through_the_binary() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("report");
    let cases: Vec<(Box<dyn Fn(String) -> String>, Vec<&str>)> = vec![
        (
            Box::new(|t| t.replace("steps = 4", "steps = 4 4")),
            vec!["study.toml", "line 5", "fix the study file"],
        ),
        (
            Box::new(|t| t.replace("steps = 4", "steps = 4\nspeed = 2")),
            vec!["study.toml", "unknown field `speed`"],
        ),
        (
            Box::new(|t| t.replace("scene = \"rates\"\n", "")),
            vec!["study.toml", "missing field `scene`"],
        ),
        (
            Box::new(|t| t.replace("levels = [0, 1, 2]", "levels = []")),
            vec!["study.toml", "mesh.levels", "at least 3 levels, got 0"],
        ),
        (
            // A level beyond the machine's memory, refused before meshing it (issue 74).
            Box::new(|t| t.replace("levels = [0, 1, 2]", "levels = [0, 1, 14]")),
            vec![
                "study.toml",
                "mesh.levels",
                "the largest level that fits is",
            ],
        ),
        (
            // Two levels with the same h: no rate between them (issue 20).
            Box::new(|t| t.replace("levels = [0, 1, 2]", "levels = [0, 1, 1, 2]")),
            vec!["study.toml", "mesh.levels", "same h"],
        ),
        (
            Box::new(|t| t.replace("levels = [0, 1, 2]", "levels = 0")),
            vec!["study.toml", "key mesh.levels", "sequence"],
        ),
        (
            // k = T / steps <= 0.
            Box::new(|t| t.replace("steps = 4", "steps = 0")),
            vec!["study.toml", "steps", "k must be positive"],
        ),
        (
            Box::new(|t| t.replace("scene = \"rates\"", "scene = \"nosuch\"")),
            vec!["no built-in scene named 'nosuch'"],
        ),
        (
            Box::new(|t| {
                t.replace(
                    "methods = [\"mortar\", \"nts\", \"lac\"]",
                    "methods = [\"penalty\"]",
                )
            }),
            vec!["study.toml", "methods", "unknown method 'penalty'"],
        ),
        (
            // lac listed, its threshold entry not given: Theorem 3.1 does not give one.
            Box::new(|t| {
                t.lines()
                    .filter(|l| !l.starts_with("lac = "))
                    .collect::<Vec<_>>()
                    .join("\n")
            }),
            vec!["study.toml", "thresholds.lac", "lac = { none ="],
        ),
        (
            // A threshold entry with a mistyped key.
            Box::new(|t| t.replace("lac = { none =", "lac = { nne =")),
            vec!["study.toml", "thresholds.lac", "unknown key `nne`"],
        ),
        (
            // Both a rate and a reason for none.
            Box::new(|t| t.replace("lac = { none =", "lac = { rate = 1.0, none =")),
            vec!["study.toml", "thresholds.lac", "not both"],
        ),
        (
            // Found while planning, before the first solve.
            Box::new(|t| t.replace("matching = 1", "matching = 0")),
            vec![
                "study.toml",
                "reference.parameters",
                "do not match on Gamma_C",
            ],
        ),
    ];
    for (edit, needles) in cases {
        let f = study_file(dir.path(), edit);
        let o = common::run(
            &["study", f.to_str().unwrap(), "--out", out.to_str().unwrap()],
            &[],
        );
        fails_with(&o, &needles);
        assert!(!out.exists(), "a failed study wrote a report");
    }
    fails_with(
        &common::run(&["study", "nosuch"], &[]),
        &["nosuch", "built-in studies", "rates-quick"],
    );
    // A typo gets the nearest name (issue 74).
    fails_with(
        &common::run(&["study", "rate"], &[]),
        &["'rate'", "did you mean 'rates'?"],
    );
}

#[test]
fn reports_folder_that_cannot_be_written_fails_before_computing() {
    let dir = tempfile::tempdir().unwrap();
    // A path whose parent is a regular file: no one can create it.
    let file = dir.path().join("plain-file");
    std::fs::write(&file, "x").unwrap();
    let bad = file.join("report");
    let t = std::time::Instant::now();
    let o = common::run(
        &["study", "rates-quick", "--out", bad.to_str().unwrap()],
        &[],
    );
    fails_with(&o, &["plain-file", "reports folder", "--out"]);
    // Checked up front: the study itself takes tens of seconds.
    assert!(t.elapsed().as_secs_f64() < 5.0);
    // An existing path that is a file.
    let o = common::run(
        &["study", "rates-quick", "--out", file.to_str().unwrap()],
        &[],
    );
    fails_with(&o, &["plain-file", "exists and is not a folder"]);
    // A read-only folder. Root ignores permission bits, so as root a read-only file system
    // (sysfs) stands in for it.
    let ro = dir.path().join("read-only");
    std::fs::create_dir(&ro).unwrap();
    let mut perm = std::fs::metadata(&ro).unwrap().permissions();
    std::os::unix::fs::PermissionsExt::set_mode(&mut perm, 0o555);
    std::fs::set_permissions(&ro, perm).unwrap();
    let target = if std::fs::create_dir(ro.join("probe")).is_ok() {
        PathBuf::from("/sys/contact-rates-read-only/report")
    } else {
        ro.join("report")
    };
    for (args, field) in [
        (
            vec!["study", "rates-quick", "--out", target.to_str().unwrap()],
            "reports folder",
        ),
        (
            vec![
                "solve",
                "--scene",
                "rates",
                "--out",
                target.to_str().unwrap(),
            ],
            "--out",
        ),
    ] {
        fails_with(&common::run(&args, &[]), &[field, "writable"]);
    }
}

#[test]
fn failed_study_leaves_the_previous_report_intact() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("report");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("rates.csv"), "previous report\n").unwrap();
    // An earlier report (README.md marks one; any other non-empty folder is refused).
    std::fs::write(out.join("README.md"), "# previous report\n").unwrap();
    // The scene's mesh lacks the physical group the scene asks for: found while computing.
    let scene = scene_file(dir.path(), |t| {
        t.replace("curve = \"top\"", "curve = \"roof\"")
    });
    let f = study_file(dir.path(), |t| {
        t.replace(
            "scene = \"rates\"",
            &format!("scene = {:?}", scene.display().to_string()),
        )
    });
    let o = common::run(
        &["study", f.to_str().unwrap(), "--out", out.to_str().unwrap()],
        &[],
    );
    fails_with(&o, &["roof"]);
    assert_eq!(
        std::fs::read_to_string(out.join("rates.csv")).unwrap(),
        "previous report\n"
    );
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(left.is_empty(), "temporary folders left behind: {left:?}");
}

#[test]
fn a_bad_singular_part_names_its_field_and_fix() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let text = std::fs::read_to_string(repo().join("scenes/regularity-0.60.toml")).unwrap();
    let geo = repo().join("meshes/two_blocks_point.geo");
    let text = text.replace(
        "\"../meshes/two_blocks_point.geo\"",
        &format!("{:?}", geo.display().to_string()),
    );
    let cases: Vec<(String, Vec<&str>)> = vec![
        (
            text.replace("exponent = 0.6", "exponent = 0.4"),
            vec!["scene.toml", "exact.singular.exponent", "> 0.5"],
        ),
        (
            text.replace(
                "young = 100.0",
                "young = 100.0\nlambda = 10.0\nyield_stress = 1.0",
            ),
            vec!["scene.toml", "exact.singular", "elastic bodies only"],
        ),
        (
            text.replace("point = [0.5871, 1.0]", "point = [0.5871]"),
            vec!["scene.toml", "exact.singular.point"],
        ),
        (
            text.replace("point = [0.5871, 1.0]", "point = [0.5871, 1.5]"),
            vec![
                "scene.toml",
                "exact.singular.point",
                "not on Gamma_C",
                "put the point on Gamma_C",
            ],
        ),
    ];
    for (text, needles) in cases {
        let f = dir.path().join("scene.toml");
        std::fs::write(&f, text).unwrap();
        fails_with(&solve_scene(&f, &out, &[]), &needles);
        assert!(!out.exists(), "no output after a failure");
    }
}

/// `export` refuses levels beyond the machine's memory before meshing or writing anything
/// (issue 74: `--levels 0-12` had gmsh at 15 GB refining level 10).
#[test]
fn export_of_levels_beyond_memory_is_refused_before_meshing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("export");
    let cache = dir.path().join("cache");
    let run = common::run(
        &[
            "export",
            "--study",
            "rates-exact",
            "--levels",
            "0-14",
            "--out",
            out.to_str().unwrap(),
        ],
        &[("CONTACT_RATES_CACHE", cache.to_str().unwrap())],
    );
    fails_with(&run, &["--levels 0-14", "the largest level that fits is"]);
    assert!(!out.exists(), "nothing is written");
    // The coarsest mesh, meshed to count its nodes, is not left behind either.
    let left: Vec<_> = std::fs::read_dir(&cache)
        .map(|d| d.flatten().map(|e| e.file_name()).collect())
        .unwrap_or_default();
    assert!(left.is_empty(), "the mesh cache as it was: {left:?}");
}

/// A study file beside a folder named like its scene (an export folder `contact-mms`) reads
/// the built-in scene, not the folder (issue 74: it failed with "Is a directory").
#[test]
fn a_folder_named_like_the_scene_is_not_read_as_it() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(repo().join("studies/rates-exact-quick.toml")).unwrap();
    let study = dir.path().join("study.toml");
    std::fs::write(&study, text).unwrap();
    std::fs::create_dir(dir.path().join("contact-mms")).unwrap();
    let out = dir.path().join("report");
    let run = common::run(
        &[
            "study",
            study.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        &[],
    );
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{err}");
    assert!(out.join("errors.csv").is_file());
}
