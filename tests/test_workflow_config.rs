//! Reference: issue 78 (reports/codes on a workflow engine: workflow/Snakefile).
//! Goal: the workflow's settings name what exists: every problem of config/config.yaml is a
//! study that loads, with levels among the study's own, and every code's driver is a file
//! (CI has no Snakemake: this is the part of the workflow a test can read); and `export`
//! rewrites a file's time stamp only where its bytes change, which is what keeps a rebuilt
//! binary's re-export from re-solving (an export into its own earlier output keeps every
//! time; a file whose bytes differ gets a new one).
//! Data: config/config.yaml; studies/patch.toml levels 0-1.

mod common;
use contact_rates::verify::study_file::LoadedStudy;

/// `key: {a: b, c: "d"}` lines under the top-level `section:` of config/config.yaml.
fn entries(text: &str, section: &str) -> Vec<(String, Vec<(String, String)>)> {
    let mut out = Vec::new();
    let mut inside = false;
    for line in text.lines() {
        if !line.starts_with(' ') && !line.starts_with('#') {
            inside = line.trim_end() == format!("{section}:");
            continue;
        }
        let Some((name, rest)) = line.trim().split_once(": {") else {
            continue;
        };
        if !inside {
            continue;
        }
        let fields = rest
            .trim_end_matches('}')
            .split(", ")
            .filter_map(|f| f.split_once(": "))
            .map(|(k, v)| (k.to_string(), v.trim_matches('"').to_string()))
            .collect();
        out.push((name.to_string(), fields));
    }
    out
}

fn field<'a>(fields: &'a [(String, String)], key: &str) -> &'a str {
    &fields
        .iter()
        .find(|f| f.0 == key)
        .expect("the field is given")
        .1
}

#[test]
fn the_workflows_problems_are_studies_and_its_drivers_files() {
    contact_rates::init();
    let root = env!("CARGO_MANIFEST_DIR");
    let text = std::fs::read_to_string(format!("{root}/config/config.yaml")).unwrap();
    let problems = entries(&text, "problems");
    assert_eq!(problems.len(), 9, "{problems:?}");
    for (name, fields) in &problems {
        let study = LoadedStudy::load(field(fields, "study")).unwrap();
        let (a, b) = field(fields, "levels").split_once('-').unwrap();
        let (a, b): (usize, usize) = (a.parse().unwrap(), b.parse().unwrap());
        for level in a..=b {
            assert!(
                study.file.mesh.levels.contains(&level),
                "{name}: level {level}"
            );
        }
    }
    let codes = entries(&text, "codes");
    assert_eq!(codes.len(), 3, "{codes:?}");
    for (name, fields) in &codes {
        let driver = format!("{root}/{}", field(fields, "driver"));
        assert!(std::path::Path::new(&driver).is_file(), "{name}: {driver}");
    }
}

#[test]
fn export_keeps_the_time_of_a_file_whose_bytes_did_not_change() {
    contact_rates::init();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("patch");
    let export = |levels: &str| {
        let o = out.to_str().unwrap();
        let run = common::run(
            &["export", "--study", "patch", "--levels", levels, "--out", o],
            &[],
        );
        assert!(run.status.success(), "{run:?}");
    };
    let time = |name: &str| {
        std::fs::metadata(out.join(name))
            .unwrap()
            .modified()
            .unwrap()
    };
    export("0-1");
    let before = (time("mesh_0.msh"), time("problem.toml"));
    std::thread::sleep(std::time::Duration::from_millis(50));
    export("0-1");
    assert_eq!((time("mesh_0.msh"), time("problem.toml")), before);
    // Another level range changes problem.toml (its levels), not level 0's mesh.
    std::thread::sleep(std::time::Duration::from_millis(50));
    export("0-2");
    assert_eq!(time("mesh_0.msh"), before.0);
    assert!(time("problem.toml") > before.1);
}
