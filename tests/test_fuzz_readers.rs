//! Reference: SPEC section 8 (bad input), issue 6 item 4, issue 47 part 6, the `grade`
//! issue (readers of other codes' solutions).
//! Goal: the readers of user files (gmsh's MSH 4.1 output, study files, scene files; the
//! solutions of other codes in .vtu of each encoding, .pvd and .msh with views) turn any
//! input, random or a mutated valid file, into a value or an error naming the file and
//! the field, never a panic; what they accept is usable (node indices in range, finite
//! coordinates, validated study and scene data; a two-body P1 solution with one finite
//! value per point or triangle); a scene is read up to its level-0 mesh and its problem's
//! set-up, and an error found against the mesh names the scene file and its field, not the
//! cached mesh.
//! Data: meshes gmsh writes for meshes/two_blocks.geo, the committed studies and scenes,
//! the solution files of tests/common/solution_files.rs; the quick tier of
//! examples/fuzz_readers.rs (same inputs, same seed): 300 random and 300 mutated inputs per
//! reader.

#[path = "common/fuzz.rs"]
mod fuzz;

use contact_rates::contact::Method;
use fuzz::{Meshes, Outcome, Reader};

/// The long run's default seed.
const SEED: u64 = 20261122;
/// Inputs per reader: even indices random, odd ones mutated.
const INPUTS: u64 = 600;

/// Run the quick tier of `reader` on the bases named `names`: no panic, every error names
/// the file and a field, and the mutated inputs are both accepted and rejected (or the
/// mutations do not reach past the first section).
fn quick(reader: Reader, names: &[&str]) -> fuzz::Tally {
    let bases = fuzz::bases(reader, names);
    // The solution readers take all their bases.
    assert!(names.is_empty() || bases.len() == names.len());
    assert!(!bases.is_empty());
    let t = fuzz::run(reader, &bases, &Meshes::default(), SEED, INPUTS);
    println!(
        "{}: {} inputs, {} accepted ({} of {} mutated), rejected {:?}",
        reader.name(),
        t.tried,
        t.accepted,
        t.mutated_accepted,
        t.mutated,
        t.rejected
    );
    assert_eq!(t.tried, INPUTS);
    assert!(t.panics.is_empty(), "panics: {:?}", t.panics);
    assert!(
        t.unnamed.is_empty(),
        "errors naming no file and field: {:?}",
        t.unnamed
    );
    assert!(t.mutated_accepted > 0 && t.mutated_accepted < t.mutated);
    t
}

#[test]
fn msh_reader_never_panics_on_random_or_mutated_files() {
    quick(Reader::Msh, &["two_blocks"]);
}

#[test]
fn study_reader_never_panics_on_random_or_mutated_files() {
    quick(Reader::Study, &["patch", "rates", "rates-quick"]);
}

#[test]
fn vtu_ascii_reader_never_panics_on_random_or_mutated_files() {
    quick(Reader::VtuAscii, &[]);
}

#[test]
fn vtu_binary_reader_never_panics_on_random_or_mutated_files() {
    quick(Reader::VtuBinary, &[]);
}

#[test]
fn vtu_appended_raw_reader_never_panics_on_random_or_mutated_files() {
    quick(Reader::VtuAppendedRaw, &[]);
}

#[test]
fn vtu_appended_base64_reader_never_panics_on_random_or_mutated_files() {
    quick(Reader::VtuAppendedBase64, &[]);
}

#[test]
fn pvd_reader_never_panics_on_random_or_mutated_files() {
    quick(Reader::Pvd, &[]);
}

#[test]
fn msh_solution_reader_never_panics_on_random_or_mutated_files() {
    quick(Reader::MshSolution, &[]);
}

/// Every base of the solution readers reads, and a huge count written over each binary
/// header word of the appended raw bases is refused with the array named, without
/// allocating what the count claims.
#[test]
fn solution_bases_read_and_huge_header_counts_are_refused() {
    for reader in Reader::ALL.into_iter().filter(|r| r.reads_solutions()) {
        for base in fuzz::bases(reader, &[]) {
            let outcome = match reader {
                Reader::Pvd => fuzz::check_pvd(&base.bytes, &base.path),
                Reader::MshSolution => fuzz::check_msh_solution(&base.bytes, &base.path),
                _ => fuzz::check_vtu(&base.bytes, &base.path),
            };
            assert_eq!(outcome, Outcome::Accepted, "{}", base.path.display());
        }
    }
    let mut refused = 0;
    for base in fuzz::bases(Reader::VtuAppendedRaw, &[]) {
        for word in 0..4 {
            for width in [4usize, 8] {
                // kind 6: a huge word; byte 1 (odd: 8 wide) or 0 (4 wide) picks u64::MAX.
                let byte = if width == 8 { 3 } else { 0 };
                let edit = (6u8, 0.0, word, byte, String::new());
                let bytes = fuzz::mutate_bytes(&base.bytes, &[edit]);
                if bytes == base.bytes {
                    continue;
                }
                match fuzz::check_vtu(&bytes, &base.path) {
                    Outcome::Rejected { named, error, .. } => {
                        assert!(named, "{error}");
                        refused += 1;
                    }
                    Outcome::Accepted => {}
                }
            }
        }
    }
    println!("{refused} huge header words refused");
    assert!(refused >= 20);
}

#[test]
fn scene_reader_never_panics_on_random_or_mutated_files() {
    let t = quick(Reader::Scene, &["rates"]);
    // Some mutated scenes read and fail only against their mesh.
    assert!(t.rejected.get("mesh").is_some_and(|&n| n > 0));
}

/// Every error the rates scene gives against its mesh names the scene file and the field
/// to fix (a misspelled curve used to be reported against the cached .msh).
#[test]
fn scene_errors_found_against_the_mesh_name_the_scene_file_and_field() {
    let base = &fuzz::bases(Reader::Scene, &["rates"])[0];
    let meshes = Meshes::default();
    let curves = "its curves are bottom, contact_lower, contact_upper, left_lower, left_upper, right_lower, right_upper, top";
    let cases: [(&[(&str, &str)], &str, &str); 11] = [
        (
            &[("\"contact_upper\"", "\"contact_uper\"")],
            "contact.slave_curve",
            "no physical curve named 'contact_uper'",
        ),
        (
            &[("\"contact_lower\"", "\"contact_lowr\"")],
            "contact.master_curve",
            "no physical curve named 'contact_lowr'",
        ),
        (
            &[("\"bottom\"", "\"botom\"")],
            "clamp[0].curve",
            "no physical curve named 'botom'",
        ),
        (
            &[("\"right_lower\"", "\"right_lowr\"")],
            "roller[3].curve",
            "no physical curve named 'right_lowr'",
        ),
        (
            &[("\"top\"", "\"roof\"")],
            "traction[0].curve",
            "no physical curve named 'roof'",
        ),
        (
            &[("surface = \"lower\"", "surface = \"base\"")],
            "bodies[1].surface",
            "no physical surface named 'base'; its surfaces are lower, upper",
        ),
        (
            // The master first in the file: the field is still the file's.
            &[
                ("surface = \"upper\"", "surface = \"uper\""),
                ("slave_body = \"upper\"", "slave_body = \"lower\""),
                (
                    "slave_curve = \"contact_upper\"",
                    "slave_curve = \"contact_lower\"",
                ),
                (
                    "master_curve = \"contact_lower\"",
                    "master_curve = \"contact_upper\"",
                ),
            ],
            "bodies[0].surface",
            "no physical surface named 'uper'",
        ),
        (
            &[(
                "\"left_upper\"\ncomponent = \"x\"",
                "\"left_upper\"\ncomponent = \"y\"",
            )],
            "roller[0].curve",
            "a roller holding u_y needs a horizontal curve, but an edge of 'left_upper'",
        ),
        (
            &[("-10*t*(0.1 + cos(pi*x))", "1/(x-x)")],
            "traction[0].g[1]",
            "expression '1/(x-x)' is not finite",
        ),
        (
            &[("h_upper = 0.3", "h_upper = -1")],
            "parameters.h_upper",
            "must be positive",
        ),
        (
            // gmsh fails on a negative grading: the message keeps the .geo and gmsh's words.
            &[("grading = 1.3", "grading = -1")],
            "geo",
            "two_blocks.geo: gmsh: gmsh failed",
        ),
    ];
    for (edits, field, needle) in cases {
        let mut text = base.text().to_string();
        for (from, to) in edits {
            assert!(text.contains(from), "the rates scene has {from}");
            text = text.replacen(from, to, 1);
        }
        let outcome = fuzz::check_scene(&text, &base.path, &meshes, Method::Mortar);
        let Outcome::Rejected {
            stage,
            error,
            named,
        } = outcome
        else {
            panic!("{edits:?} accepted");
        };
        println!("{error}");
        assert_eq!(stage, "mesh", "{error}");
        assert!(named, "{error}");
        assert!(
            error.starts_with(&format!("{}: {field}: ", base.path.display())),
            "{error}"
        );
        assert!(error.contains(needle), "{error}");
        if needle.starts_with("no physical curve") {
            assert!(
                error.contains("two_blocks.geo") && error.contains(curves),
                "{error}"
            );
            assert!(error.contains(&format!("fix: name one of them in {field}")));
        }
    }
}

/// TOML errors name the key as a path, with the index of an array of tables, also for a
/// missing or unknown field.
#[test]
fn toml_errors_name_the_key_with_its_table_and_index() {
    let base = &fuzz::bases(Reader::Scene, &["rates"])[0];
    let meshes = Meshes::default();
    for (from, to, field) in [
        ("young = 100.0\n", "", "toml (line 11) key bodies[0].young"),
        (
            "curve = \"bottom\"\n",
            "",
            "toml (line 25) key clamp[0].curve",
        ),
        ("final_time = 1.0\n", "", "toml (line 1) key final_time"),
        (
            "steps = 10",
            "steps = 10\ncolour = 3",
            "toml (line 5) key colour",
        ),
        (
            "component = \"x\"",
            "component = 1",
            "toml (line 30) key roller[0].component",
        ),
        (
            "[contact]\n",
            "[contact]\nfriction = 0.2\n",
            "key contact.friction",
        ),
    ] {
        let text = base.text().replacen(from, to, 1);
        let Outcome::Rejected { error, named, .. } =
            fuzz::check_scene(&text, &base.path, &meshes, Method::Mortar)
        else {
            panic!("{to} accepted");
        };
        println!("{error}");
        assert!(named, "{error}");
        assert!(
            error.starts_with(&format!("{}: {field}", base.path.display()))
                || (field.starts_with("key") && error.contains(field)),
            "{error}"
        );
    }
}

/// Reproducer from the long run (seed 20261122, scene input 45751): a constant division by
/// zero in an exact field, which exmex folds to the constant `inf`, made combining the
/// fields panic ("no new variable: inf": the folded text read `inf` back as a variable).
/// The scene is now refused with the field to fix, and the combination evaluates to a
/// non-finite number, as the field itself does.
#[test]
fn a_constant_division_by_zero_in_an_exact_field_is_an_error_not_a_panic() {
    use contact_rates::scene::Expr;
    let base = &fuzz::bases(Reader::Scene, &["contact-mms-vp-time"])[0];
    let from = "(45/0.91)*(-(2*y-1)*(0.91/150)";
    assert!(base.text().contains(from));
    let text = base
        .text()
        .replacen(from, "(45/0.91)*(-(2*y-1)*(0.91/1/0)", 1);
    let outcome = fuzz::check_scene(&text, &base.path, &Meshes::default(), Method::Mortar);
    println!("{outcome:?}");
    assert!(
        matches!(&outcome, Outcome::Rejected { named: true, error, .. } if error.contains("exact")),
        "{outcome:?}"
    );
    let file = std::path::Path::new("s.toml");
    for text in ["x/0 + y", "0/0*x"] {
        let e = Expr::parse(text, file, "f").unwrap();
        let c = Expr::combine(&[(2.0, &e), (1.0, &e.partial(0))]);
        let v = c.eval(1.0, 1.0, 0.0);
        assert!(!v.is_finite(), "{text}: {v}");
    }
}
