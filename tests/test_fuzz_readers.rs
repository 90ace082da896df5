//! Reference: SPEC section 8 (bad input), issue 6 item 4.
//! Goal: the readers of user files (gmsh's MSH 4.1 output, study files, scene files) turn
//! any input, random or a mutated valid file, into a value or an error, never a panic; and
//! what they accept is usable (node indices in range, finite coordinates, validated
//! study and scene data).
//! Data: a mesh gmsh writes for meshes/two_blocks.geo, the committed studies and scenes;
//! 300 random and 300 mutated inputs per reader, fixed seed (deterministic).

use contact_rates::mesh::msh::parse_msh;
use contact_rates::scene::Scene;
use contact_rates::verify::study_file::StudyFile;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed, TestRunner};
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn runner() -> TestRunner {
    TestRunner::new(Config {
        cases: 300,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(20261122),
        ..Config::default()
    })
}

/// Tokens that break numbers, counts and strings in interesting ways.
const TOKENS: [&str; 14] = [
    "-1",
    "0",
    "1e308",
    "NaN",
    "inf",
    "99999999999999999999",
    "abc",
    "",
    "\"",
    "[]",
    "$EndNodes",
    "4.1 0 8",
    "1.5",
    "\n",
];

/// One edit of a text: (kind, position as a fraction, token index, random text).
fn edit() -> impl Strategy<Value = (u8, f64, usize, String)> {
    (0u8..6, 0.0f64..1.0, 0usize..TOKENS.len(), "[ -~]{0,12}")
}

/// Apply edits to `base`: replace a whitespace-separated word by a token, delete a line,
/// duplicate a line, insert random text, truncate, or swap two lines.
fn mutate(base: &str, edits: &[(u8, f64, usize, String)]) -> String {
    let mut lines: Vec<String> = base.lines().map(String::from).collect();
    for (kind, at, tok, text) in edits {
        if lines.is_empty() {
            lines.push(text.clone());
            continue;
        }
        let i = ((*at * lines.len() as f64) as usize).min(lines.len() - 1);
        match kind {
            0 => {
                let mut words: Vec<String> = lines[i].split(' ').map(String::from).collect();
                let w = ((*at * 7919.0) as usize) % words.len();
                words[w] = TOKENS[*tok].to_string();
                lines[i] = words.join(" ");
            }
            1 => {
                lines.remove(i);
            }
            2 => {
                let l = lines[i].clone();
                lines.insert(i, l);
            }
            3 => lines.insert(i, text.clone()),
            4 => lines.truncate(i),
            _ => {
                let j = (i * 31 + 7) % lines.len();
                lines.swap(i, j);
            }
        }
    }
    lines.join("\n")
}

fn gmsh_mesh() -> String {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("m.msh");
    let status = std::process::Command::new("gmsh")
        .arg(repo().join("meshes/two_blocks.geo"))
        .args(["-2", "-v", "0", "-o"])
        .arg(&out)
        .status()
        .expect("gmsh on PATH");
    assert!(status.success());
    std::fs::read_to_string(out).unwrap()
}

/// Check what the reader accepts; true when it accepted the text.
fn check_mesh(text: &str) -> bool {
    let Ok(m) = parse_msh(text, Path::new("fuzz.msh")) else {
        return false;
    };
    {
        for n in &m.nodes {
            assert!(
                n[0].is_finite() && n[1].is_finite(),
                "accepted a non-finite node"
            );
        }
        for (t, _) in &m.triangles {
            for &v in t {
                assert!(
                    v < m.nodes.len(),
                    "accepted a triangle with node {v} of {}",
                    m.nodes.len()
                );
            }
        }
        for (l, _) in &m.lines {
            for &v in l {
                assert!(
                    v < m.nodes.len(),
                    "accepted a line with node {v} of {}",
                    m.nodes.len()
                );
            }
        }
    }
    true
}

#[test]
fn msh_reader_never_panics_on_random_or_mutated_files() {
    let base = gmsh_mesh();
    assert!(parse_msh(&base, Path::new("base.msh")).is_ok());
    runner()
        .run(
            &"(\\$MeshFormat\n4.1 0 8\n\\$EndMeshFormat\n)?[ -~\n]{0,400}",
            |text| {
                check_mesh(&text);
                Ok(())
            },
        )
        .unwrap();
    // Both outcomes must occur, or the mutations do not reach past the first section.
    let accepted = std::cell::Cell::new(0);
    let total = std::cell::Cell::new(0);
    runner()
        .run(&prop::collection::vec(edit(), 1..6), |edits| {
            total.set(total.get() + 1);
            if check_mesh(&mutate(&base, &edits)) {
                accepted.set(accepted.get() + 1);
            }
            Ok(())
        })
        .unwrap();
    println!(
        "mutated meshes accepted: {} of {}",
        accepted.get(),
        total.get()
    );
    assert!(accepted.get() > 0 && accepted.get() < total.get());
}

#[test]
fn study_and_scene_readers_never_panic_on_random_or_mutated_files() {
    let studies: Vec<(PathBuf, String)> = ["rates", "rates-quick", "patch"]
        .iter()
        .map(|n| {
            let p = repo().join(format!("studies/{n}.toml"));
            let t = std::fs::read_to_string(&p).unwrap();
            (p, t)
        })
        .collect();
    let scene_path = repo().join("scenes/rates.toml");
    let scene = std::fs::read_to_string(&scene_path).unwrap();
    for (p, t) in &studies {
        StudyFile::from_toml(t, p).unwrap();
    }
    Scene::from_toml(&scene, &scene_path).unwrap();
    runner()
        .run(&"[ -~\n]{0,300}", |text| {
            let _ = StudyFile::from_toml(&text, Path::new("fuzz.toml"));
            let _ = Scene::from_toml(&text, &scene_path);
            Ok(())
        })
        .unwrap();
    runner()
        .run(
            &(0usize..3, prop::collection::vec(edit(), 1..5)),
            |(which, edits)| {
                let (p, t) = &studies[which];
                if let Ok(s) = StudyFile::from_toml(&mutate(t, &edits), p) {
                    assert!(s.steps >= 1);
                    assert!(s.mesh.levels.len() >= 3);
                    assert!(s.mesh.levels.windows(2).all(|w| w[0] < w[1]));
                    assert!(s.mesh.coarsest > 0.0 && s.mesh.coarsest.is_finite());
                }
                if let Ok(sc) = Scene::from_toml(&mutate(&scene, &edits), &scene_path) {
                    assert!(sc.final_time > 0.0 && sc.final_time.is_finite());
                    for b in &sc.bodies {
                        let e = &b.material.elastic;
                        assert!(e.young > 0.0 && e.young.is_finite());
                    }
                }
                Ok(())
            },
        )
        .unwrap();
}
