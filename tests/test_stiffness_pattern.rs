//! Reference: the sparsity of a P1 stiffness: entry (r, c) is stored where the unknowns r
//! and c belong to nodes of one triangle (both free), rows increasing in each column.
//! Goal: the pattern built from the nodes' neighbours (the fast path every solver and the
//! floor use) is the one built from the list of every element entry, to the index, and so
//! are the 36 value slots of every triangle.
//! Geometry: six built-in scenes with different constrained unknowns (`rates`: rollers
//! with x fixed and y free, and a clamped block; `paper-1`: symmetry with y fixed and x
//! free; `patch`: both kinds; `paper-3`: a contact line with corners; `stacked-exact`;
//! `contact-mms-vp`), at levels 0-2.
//! Data: the scenes' own meshes.

mod common;
use contact_rates::contact::Method;
use contact_rates::fe::FIXED;

#[test]
fn nodes_pattern_equals_the_entries_pattern_on_every_scene() {
    let (mut x_fixed, mut y_fixed) = (0, 0);
    for scene in [
        "rates",
        "paper-1",
        "patch",
        "paper-3",
        "stacked-exact",
        "contact-mms-vp",
    ] {
        for level in 0..=2 {
            let case = common::case(scene, level, Method::Mortar, &[]);
            let model = &case.problem.model;
            let n = model.n_free;
            let (fast, fast_slots) = model.stiffness_pattern(&[], n);
            let (entries, entries_slots) = model.stiffness_pattern_by_entries(&[], n);
            assert_eq!(fast.n, entries.n, "{scene} level {level}: size");
            assert_eq!(
                fast.col_ptr, entries.col_ptr,
                "{scene} level {level}: columns"
            );
            assert_eq!(fast.row_idx, entries.row_idx, "{scene} level {level}: rows");
            assert!(
                fast_slots == entries_slots,
                "{scene} level {level}: the triangles' value slots differ"
            );
            // Some unknowns are constrained, so the test covers the fixed ones.
            assert!(n < 2 * model.n_nodes, "{scene}: no constrained unknown");
            let fixed = |d: usize| model.equation[d] == FIXED;
            for j in 0..model.n_nodes {
                x_fixed += (fixed(2 * j) && !fixed(2 * j + 1)) as usize;
                y_fixed += (!fixed(2 * j) && fixed(2 * j + 1)) as usize;
            }
        }
    }
    // Nodes with one of their two unknowns fixed, of both kinds (the slots' offsets differ).
    assert!(
        x_fixed > 0 && y_fixed > 0,
        "x fixed {x_fixed}, y fixed {y_fixed}"
    );
}
