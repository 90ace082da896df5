//! Reference: the sparsity of a P1 stiffness: entry (r, c) is stored where the unknowns r
//! and c belong to nodes of one triangle (both free), rows increasing in each column.
//! Goal: the pattern built from the nodes' neighbours (the fast path every solver and the
//! floor use) is the one built from the list of every element entry, to the index, and so
//! are the 36 value slots of every triangle.
//! Geometry: every built-in scene with a different set of constrained unknowns (`rates`:
//! rollers and a clamped block, one of a node's two unknowns fixed on the rollers;
//! `patch`: symmetry sides; `paper-3`: a contact line with corners; `stacked-exact`;
//! `contact-mms-vp`), at levels 0-2.
//! Data: the scenes' own meshes.

mod common;
use contact_rates::contact::Method;
use contact_rates::fe::FIXED;

#[test]
fn nodes_pattern_equals_the_entries_pattern_on_every_scene() {
    for scene in [
        "rates",
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
            // Some unknowns are constrained, so the test covers the fixed ones; on `rates`
            // some node has one of its two fixed (rollers).
            assert!(n < 2 * model.n_nodes, "{scene}: no constrained unknown");
            let half_fixed = (0..model.n_nodes)
                .filter(|&j| {
                    (model.equation[2 * j] == FIXED) != (model.equation[2 * j + 1] == FIXED)
                })
                .count();
            assert!(scene != "rates" || half_fixed > 0, "rates: no roller node");
        }
    }
}
