// Reference: issue 63 (the unaligned transition); src/analytical/singular.rs
//   (UNALIGNED_TRANSITION, unaligned_grading).
// Goal: the quick tier of `study regularity-unaligned`: at every level of the study (0-7)
//   and every beta, the transition point c is a node of neither trace and at least h/8 from
//   the nearest node of each (h: the trace segment that holds c), on the study's own meshes
//   (so a .geo or grading that drifts puts c near a node and fails here); and c sits at 1/3
//   of its segment, as halving a segment with c at 1/3 of it keeps it at 1/3 or 2/3.
// Geometry: meshes/two_blocks.geo, the upper contact line graded so that c = (8/15, 1) is at
//   1/3 of its third level-0 segment; the lower line in five 0.2-long segments.
// Data: the study files studies/regularity-unaligned/beta-*.toml, levels 0-7.

use contact_rates::analytical::singular::{UNALIGNED_TRANSITION, graded_line, unaligned_grading};
use contact_rates::scene::Scene;
use contact_rates::studies::regularity::families::LEAST_OFFSET;
use contact_rates::studies::regularity::{UNALIGNED, placement};
use contact_rates::verify::study_file::StudyFile;

#[test]
fn the_grading_puts_c_at_a_third_of_an_upper_segment() {
    let x = graded_line(5, unaligned_grading());
    let fraction = (UNALIGNED_TRANSITION - x[2]) / (x[3] - x[2]);
    println!("upper nodes {x:?}, c at {fraction} of [x2, x3]");
    assert!((fraction - 1.0 / 3.0).abs() < 1e-14, "{fraction}");
    // The lower line's five segments: c at 2/3 of [0.4, 0.6].
    assert!(((UNALIGNED_TRANSITION - 0.4) / 0.2 - 2.0 / 3.0).abs() < 1e-14);
}

#[test]
fn c_stays_at_least_h_over_8_from_every_trace_node_at_every_level() {
    contact_rates::init();
    for &beta in UNALIGNED.betas {
        let file = StudyFile::load(&UNALIGNED.study_path(beta)).unwrap();
        assert_eq!(file.mesh.levels, UNALIGNED.levels, "the study's levels");
        let scene = Scene::load(&UNALIGNED.scene_name(beta)).unwrap();
        let c = scene
            .exact
            .as_ref()
            .unwrap()
            .singular
            .as_ref()
            .unwrap()
            .point;
        assert_eq!(c, [UNALIGNED_TRANSITION, 1.0]);
        let rows = placement(&scene, c, &file.family_parameters(), &file.mesh.levels).unwrap();
        for r in &rows {
            println!(
                "beta {beta} level {}: slave offset {:.6}, master offset {:.6}",
                r.level, r.slave_offset, r.master_offset
            );
            for offset in [r.slave_offset, r.master_offset] {
                assert!(
                    offset >= LEAST_OFFSET,
                    "beta {beta}, level {}: c at {offset} of its segment from a node",
                    r.level
                );
                // 1/3 up to where gmsh puts a progression's nodes (measured: 1.2e-9 of a
                // segment at level 0; each halving doubles the deviation relative to the
                // segment, 2^7 of it at level 7).
                assert!(
                    (offset - 1.0 / 3.0).abs() < 1e-6,
                    "level {}: {offset}",
                    r.level
                );
            }
        }
        assert_eq!(rows.len(), 8);
    }
}
