//! Reference: issue "Scenes are data" and docs/scenes.md, "Adding a scene".
//! Goal: a user adds a scene (a .geo and a TOML file) outside the repo and runs `solve` and
//! a small `study` on it with both cones, without writing Rust; a body that nothing holds
//! gets a warning that says so.
//! Geometry: examples/adding-a-scene (a narrow viscoplastic block on an elastic base,
//! non-uniform traction on top), copied into a temporary folder.

use std::path::{Path, PathBuf};
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_contact-rates");

fn copy_example(dir: &Path) -> PathBuf {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/adding-a-scene");
    for f in ["blocks.geo", "blocks.toml", "blocks-study.toml"] {
        std::fs::copy(src.join(f), dir.join(f)).unwrap();
    }
    dir.to_path_buf()
}

#[test]
fn user_scene_solves_and_studies_with_both_cones() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = copy_example(tmp.path());
    let cache = dir.join("cache");
    for method in ["mortar", "nts"] {
        let out = dir.join(format!("out-{method}"));
        let o = Command::new(BIN)
            .args([
                "solve",
                "--scene",
                dir.join("blocks.toml").to_str().unwrap(),
                "--method",
                method,
                "--level",
                "1",
                "--out",
                out.to_str().unwrap(),
            ])
            .env("CONTACT_RATES_CACHE", &cache)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let summary = std::fs::read_to_string(out.join("summary.csv")).unwrap();
        let values: Vec<&str> = summary.lines().nth(1).unwrap().split(',').collect();
        for v in &values[4..13] {
            let x: f64 = v.parse().unwrap();
            assert!(x.is_finite(), "{summary}");
        }
        assert!(std::fs::metadata(out.join("solution.vtu")).unwrap().len() > 1000);
    }
    let report = dir.join("report");
    let o = Command::new(BIN)
        .args([
            "study",
            dir.join("blocks-study.toml").to_str().unwrap(),
            "--out",
            report.to_str().unwrap(),
        ])
        .env("CONTACT_RATES_CACHE", &cache)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    println!("{stdout}");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in [
        "README.md",
        "errors.csv",
        "rates.csv",
        "error_vs_h.png",
        "pressure.png",
        "von_mises.png",
    ] {
        assert!(report.join(f).exists(), "{f} missing");
    }
    for f in [
        "rates.csv",
        "levels.csv",
        "pressure.csv",
        "gap.csv",
        "README.md",
    ] {
        let text = std::fs::read_to_string(report.join(f))
            .unwrap()
            .to_lowercase();
        let bad = text
            .split(|c: char| !c.is_alphanumeric())
            .any(|w| w == "nan" || w == "inf" || w == "infinity");
        assert!(!bad, "{f}: {text}");
    }
    let errors = std::fs::read_to_string(report.join("errors.csv")).unwrap();
    assert!(
        !errors.contains("NaN") && !errors.contains("inf"),
        "{errors}"
    );
}

#[test]
fn a_body_nothing_holds_gets_a_warning() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = copy_example(tmp.path());
    let text = std::fs::read_to_string(dir.join("blocks.toml")).unwrap();
    let cases = [
        (text.replace("[[roller]]                  # u_x = 0 on the top block's left side\ncurve = \"top_left\"\ncomponent = \"x\"\n", ""), "body 'top' has no clamp or roller holding u_x"),
        (text.replace("-8*t*(1 + 0.5*sin(pi*x))", "8*t"), "body 'top' has no clamp or roller holding u_y"),
    ];
    for (scene, needle) in cases {
        assert_ne!(scene, text, "the edit applies");
        let f = dir.join("free.toml");
        std::fs::write(&f, scene).unwrap();
        let o = Command::new(BIN)
            .args([
                "solve",
                "--scene",
                f.to_str().unwrap(),
                "--out",
                dir.join("o").to_str().unwrap(),
            ])
            .env("CONTACT_RATES_CACHE", dir.join("cache"))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            err.contains("warning:") && err.contains(needle) && err.contains("free to move"),
            "{err}"
        );
        assert!(!err.contains("panicked"), "{err}");
    }
}
