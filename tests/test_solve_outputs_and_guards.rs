//! Reference: issue 15, SPEC section 8 (bad input).
//! Goal: `solve` writes the contact result (contact.csv, pressure and normal jump as VTU
//! point data) and a ParaView time series; runs that cannot succeed are refused before
//! meshing with one short message and a non-zero exit; gmsh's errors are summarised; a
//! cache entry that does not parse heals itself.
//! Geometry: meshes/two_blocks.geo; the `patch` scene (paper Test 2: the upper block is held
//! vertically only by contact, pressure 10 t on top, viscoplastic) and the `rates` scene.

mod common;
use std::path::{Path, PathBuf};
use std::process::Output;

/// `contact-rates solve --scene SCENE ARGS... --out OUT` with extra environment `envs`.
fn solve(scene: &str, args: &[&str], out: &Path, envs: &[(&str, &str)]) -> Output {
    let mut all = vec!["solve", "--scene", scene];
    all.extend_from_slice(args);
    all.extend(["--out", out.to_str().unwrap()]);
    common::run(&all, envs)
}

/// A clean failure: exit 1, no panic, at most 3 lines, one of them the error, containing
/// every one of `needles`.
fn fails_short(out: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "exit code; stderr: {err}");
    assert!(!err.contains("panicked"), "panic: {err}");
    assert!(err.lines().count() <= 3, "at most a few lines: {err}");
    assert!(
        err.len() <= 600,
        "a short message ({} bytes): {err}",
        err.len()
    );
    for n in needles {
        assert!(err.contains(n), "message lacks '{n}': {err}");
    }
}

/// Reference: issue 15, acceptance 1. Data: scenes/patch.toml, level 1, 4 steps, newton,
/// both cones. The pressure is >= 0, the rows where it is positive are active, its
/// resultant (trapezoid over the arc length) equals the load 10 t on the unit-wide top to
/// the solver's tolerance (the upper block is held vertically only by contact), and the
/// .pvd lists 4 readable VTU files at increasing times carrying the same pressure.
#[test]
fn solve_writes_contact_csv_and_a_paraview_time_series() {
    for method in ["mortar", "nts"] {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        let o = solve(
            "patch",
            &["--method", method, "--level", "1", "--steps", "4"],
            &out,
            &[],
        );
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        // contact.csv
        let mut rdr = csv::Reader::from_path(out.join("contact.csv")).unwrap();
        let header: Vec<String> = rdr.headers().unwrap().iter().map(String::from).collect();
        assert_eq!(
            header,
            [
                "time",
                "piece",
                "arc_length",
                "x",
                "y",
                "pressure",
                "normal_jump",
                "active"
            ]
        );
        let rows: Vec<csv::StringRecord> = rdr.records().map(|r| r.unwrap()).collect();
        let f = |r: &csv::StringRecord, i: usize| r[i].parse::<f64>().unwrap();
        let mut times: Vec<f64> = rows.iter().map(|r| f(r, 0)).collect();
        times.dedup();
        assert_eq!(times, [0.25, 0.5, 0.75, 1.0], "{method}: the 4 steps");
        for &t in &times {
            let at: Vec<&csv::StringRecord> = rows.iter().filter(|r| f(r, 0) == t).collect();
            let p_max = at.iter().map(|r| f(r, 5)).fold(0.0, f64::max);
            for r in &at {
                assert!(
                    f(r, 5) >= -1e-9 * p_max,
                    "{method} t = {t}: pressure {}",
                    f(r, 5)
                );
                if f(r, 5) > 1e-8 * p_max {
                    assert_eq!(&r[7], "true", "{method} t = {t}: pressure > 0 but inactive");
                }
            }
            // Trapezoid over each piece's arc length (rows are in order along a piece).
            let mut resultant = 0.0;
            for w in at.windows(2) {
                if w[0][1] == w[1][1] {
                    resultant += 0.5 * (f(w[0], 5) + f(w[1], 5)) * (f(w[1], 2) - f(w[0], 2));
                }
            }
            let load = 10.0 * t;
            assert!(
                (resultant - load).abs() <= 1e-8 * load,
                "{method} t = {t}: resultant {resultant} against the load {load}"
            );
        }
        // Each piece's rows in reading order: arc length from 0 at the end of smaller x (of
        // smaller y on a vertical piece), increasing, and the distance from that end.
        let first = rows.iter().filter(|r| f(r, 0) == 1.0);
        let mut by_piece: std::collections::BTreeMap<String, Vec<&csv::StringRecord>> =
            Default::default();
        for r in first {
            by_piece.entry(r[1].to_string()).or_default().push(r);
        }
        for (piece, at) in by_piece {
            assert_eq!(f(at[0], 2), 0.0, "{method} piece {piece} starts at 0");
            for w in at.windows(2) {
                let (a, b) = (w[0], w[1]);
                assert!(
                    f(b, 2) > f(a, 2),
                    "{method} piece {piece}: arc length increases"
                );
                assert!(
                    (f(b, 3), f(b, 4)) > (f(a, 3), f(a, 4)),
                    "{method} piece {piece}: reading order"
                );
                let d = (f(b, 3) - f(at[0], 3)).hypot(f(b, 4) - f(at[0], 4));
                assert!(
                    (d - f(b, 2)).abs() <= 1e-12,
                    "{method} piece {piece}: arc length"
                );
            }
        }
        // The .pvd and its VTU files.
        let pvd = std::fs::read_to_string(out.join("solution.pvd")).unwrap();
        let sets: Vec<(f64, PathBuf)> = pvd
            .lines()
            .filter(|l| l.contains("<DataSet"))
            .map(|l| {
                let attr = |a: &str| {
                    let k = l.find(&format!("{a}=\"")).unwrap() + a.len() + 2;
                    l[k..k + l[k..].find('"').unwrap()].to_string()
                };
                (attr("timestep").parse().unwrap(), out.join(attr("file")))
            })
            .collect();
        assert_eq!(sets.len(), 4, "{method}: 4 steps in the .pvd");
        assert!(sets.windows(2).all(|w| w[1].0 > w[0].0), "times increase");
        for (t, file) in &sets {
            let vtu = common::vtu::read(file);
            let n = vtu.points;
            let (pressure, _) = vtu.f64("PointData", "pressure");
            assert_eq!(
                pressure.len(),
                n,
                "{}: one pressure per point",
                file.display()
            );
            assert_eq!(vtu.f64("PointData", "normal_jump").0.len(), n);
            let csv_max = rows
                .iter()
                .filter(|r| f(r, 0) == *t)
                .map(|r| f(r, 5))
                .fold(0.0, f64::max);
            let vtu_max = pressure.iter().copied().fold(0.0, f64::max);
            assert!(
                (vtu_max - csv_max).abs() <= 1e-12 * csv_max,
                "{vtu_max} {csv_max}"
            );
        }
        // solution.vtu is the last step.
        let last = std::fs::read(out.join("solution.vtu")).unwrap();
        let last_step = std::fs::read(&sets[3].1).unwrap();
        assert_eq!(last, last_step);
    }
}

/// `--every 2` writes steps 2 and 4 (and the last is always written).
#[test]
fn every_kth_step_and_the_last() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let o = solve("patch", &["--steps", "5", "--every", "2"], &out, &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let pvd = std::fs::read_to_string(out.join("solution.pvd")).unwrap();
    let files: Vec<&str> = pvd
        .lines()
        .filter_map(|l| l.split("file=\"").nth(1))
        .map(|s| s.trim_end_matches("\"/>"))
        .collect();
    assert_eq!(
        files,
        [
            "solution_0002.vtu",
            "solution_0004.vtu",
            "solution_0005.vtu"
        ]
    );
}

/// Sizes that are not finite or not positive are refused before gmsh runs (a fake gmsh
/// that would fail is on PATH, so a message about gmsh would mean it ran).
#[test]
fn sizes_that_are_not_finite_or_not_positive_are_refused_before_meshing() {
    for (value, needle) in [
        ("nan", "not a finite number"),
        ("inf", "not a finite number"),
        ("-inf", "not a finite number"),
        ("0", "must be positive"),
        ("-1", "must be positive"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let set = format!("h_upper={value}");
        let o = solve("rates", &["--set", &set], &dir.path().join("o"), &[]);
        fails_short(&o, &["rates.toml", "parameters.h_upper", needle]);
    }
}

/// A level whose estimated memory exceeds the machine's is refused before refining, with
/// the estimate and the largest level that fits (level 12 of `rates` is about 1.9e9 dofs).
#[test]
fn a_level_beyond_the_machines_memory_is_refused_with_the_largest_that_fits() {
    let dir = tempfile::tempdir().unwrap();
    let t = std::time::Instant::now();
    let o = solve("rates", &["--level", "12"], &dir.path().join("o"), &[]);
    fails_short(
        &o,
        &[
            "rates.toml: level: level 12 needs about",
            "GiB",
            "the largest level that fits is",
        ],
    );
    assert!(t.elapsed().as_secs_f64() < 30.0, "refused before refining");
}

/// gmsh's repeated errors are summarised as distinct messages with counts.
#[test]
fn gmsh_errors_are_summarised() {
    let mut text = String::from("Info    : Meshing 1D...\n");
    for _ in 0..1040 {
        text.push_str("Error   : Wrong mesh element size lc = -1 (lcmin = 1e-22, lcmax = 1e22)\n");
    }
    text.push_str("Error   : Unable to recover the edge 12 (3/4) on curve 4 (on surface 1)\n");
    for k in 0..5 {
        text.push_str(&format!("Error   : other message {k}\n"));
    }
    let s = contact_rates::mesh::gmsh::summarize_errors(&text);
    assert!(s.contains("(x1040)"), "{s}");
    assert!(s.contains("Unable to recover the edge"), "{s}");
    assert!(s.contains("and 4 other messages"), "{s}");
    assert!(s.len() < 300 && !s.contains('\n'), "{s}");
    // Through the binary: a fake gmsh printing 1040 errors.
    let dir = tempfile::tempdir().unwrap();
    let bin = dir.path().join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    let script = "#!/bin/sh\nif [ \"$1\" = --version ]; then echo 4.8.4; exit 0; fi\ni=0\nwhile [ $i -lt 1040 ]; do echo 'Error   : Wrong mesh element size lc = -1'; i=$((i+1)); done\nexit 1\n";
    let gmsh = bin.join("gmsh");
    std::fs::write(&gmsh, script).unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&gmsh, std::fs::Permissions::from_mode(0o755)).unwrap();
    let path = format!("{}:/usr/bin:/bin", bin.display());
    let cache = dir.path().join("cache");
    let o = solve(
        "rates",
        &[],
        &dir.path().join("o"),
        &[
            ("PATH", &path),
            ("CONTACT_RATES_CACHE", cache.to_str().unwrap()),
        ],
    );
    fails_short(
        &o,
        &[
            "two_blocks.geo",
            "gmsh failed",
            "'Wrong mesh element size lc = -1' (x1040)",
        ],
    );
}

/// A cached mesh that does not parse is regenerated with a one-line warning.
#[test]
fn a_broken_cache_entry_heals_itself() {
    let dir = tempfile::tempdir().unwrap();
    let cache = dir.path().join("cache");
    let env = [("CONTACT_RATES_CACHE", cache.to_str().unwrap())];
    let solve_one_step = |out: &Path| solve("rates", &["--steps", "1"], out, &env);
    let first = solve_one_step(&dir.path().join("a"));
    assert!(
        first.status.success(),
        "{}",
        String::from_utf8_lossy(&first.stderr)
    );
    let cached: Vec<PathBuf> = std::fs::read_dir(&cache)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "msh"))
        .collect();
    assert_eq!(cached.len(), 1, "{cached:?}");
    let text = std::fs::read_to_string(&cached[0]).unwrap();
    std::fs::write(&cached[0], &text[..text.len() / 2]).unwrap();
    let second = solve_one_step(&dir.path().join("b"));
    let err = String::from_utf8_lossy(&second.stderr);
    assert!(second.status.success(), "{err}");
    let warnings: Vec<&str> = err.lines().filter(|l| l.starts_with("warning")).collect();
    assert_eq!(warnings.len(), 1, "{err}");
    assert!(
        warnings[0].contains("did not parse; regenerating it"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_to_string(&cached[0]).unwrap(),
        text,
        "regenerated identically"
    );
    let summary =
        |d: &str| std::fs::read_to_string(dir.path().join(d).join("contact.csv")).unwrap();
    assert_eq!(summary("a"), summary("b"));
}
