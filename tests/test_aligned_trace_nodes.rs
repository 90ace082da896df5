//! Reference: issue 75, acceptance: "coincident nodes on both traces, and a slave node
//! exactly at a master node: the rows equal hand-derived ones (aligned nodes are where
//! projection codes fail)"; paper section 2.1 for the rows.
//! Goal: where a body-1 node lies exactly on a body-2 node, the mortar segments, the
//! projection and the end rule give the rows derived by hand below, entry for entry, with
//! no spurious entry of a neighbouring node.
//! Geometry: a straight piece of length 1 along y = 0, body 1 above (normal (0, -1)).
//! Data: (a) both traces with nodes at 0, 0.3, 0.6, 1; (b) body-1 nodes at 0, 1/4, 1/2,
//! 1, body-2 nodes at 0, 1/2, 1.

use contact_rates::contact::{self, Piece, PieceRow};

const NU: [f64; 2] = [0.0, -1.0];

fn piece(slave_s: &[f64], master_s: &[f64]) -> Piece {
    Piece {
        a: [0.0, 0.0],
        tangent: [1.0, 0.0],
        length: 1.0,
        normal: NU,
        slave_nodes: (0..slave_s.len()).collect(),
        slave_s: slave_s.to_vec(),
        master_nodes: (0..master_s.len()).collect(),
        master_s: master_s.to_vec(),
        ..Default::default()
    }
}

/// The rows of a nodal method from the matrix P (body-1 node i: u^1_i.nu - sum_q P_iq
/// u^2_q.nu <= 0), with the lumped weights.
fn nodal_rows(p: &[Vec<f64>], weights: &[f64]) -> Vec<PieceRow> {
    p.iter()
        .enumerate()
        .map(|(i, row)| PieceRow {
            span: [i, i],
            slave: vec![(i, NU)],
            master: row
                .iter()
                .enumerate()
                .filter(|(_, v)| **v != 0.0)
                .map(|(q, v)| (q, [-v * NU[0], -v * NU[1]]))
                .collect(),
            weight: weights[i],
            gap: 0.0,
        })
        .collect()
}

fn assert_rows_equal(what: &str, got: &[PieceRow], want: &[PieceRow]) {
    assert_eq!(got.len(), want.len(), "{what}: row count");
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        assert_eq!(g.span, w.span, "{what} row {k}: span");
        assert_eq!(g.gap, 0.0, "{what} row {k}: gap");
        assert!(
            (g.weight - w.weight).abs() < 1e-15,
            "{what} row {k}: weight"
        );
        for (side, a, b) in [
            ("slave", &g.slave, &w.slave),
            ("master", &g.master, &w.master),
        ] {
            let nodes = |v: &Vec<(usize, [f64; 2])>| v.iter().map(|e| e.0).collect::<Vec<_>>();
            assert_eq!(nodes(a), nodes(b), "{what} row {k}: {side} nodes");
            for (x, y) in a.iter().zip(b) {
                let d = (x.1[0] - y.1[0]).abs().max((x.1[1] - y.1[1]).abs());
                assert!(
                    d < 1e-14,
                    "{what} row {k}: {side} node {}: {:?} vs {:?}",
                    x.0,
                    x.1,
                    y.1
                );
            }
        }
    }
}

#[test]
fn coincident_nodes_give_the_identity_in_both_nodal_methods() {
    // (a): every body-1 node on a body-2 node: pi_h and I_h are the identity (K_h^pi =
    // K_h^I on matching traces), one master entry per row.
    let s = [0.0, 0.3, 0.6, 1.0];
    let p = piece(&s, &s);
    let identity: Vec<Vec<f64>> = (0..4)
        .map(|i| (0..4).map(|q| (i == q) as u8 as f64).collect())
        .collect();
    let weights = [0.15, 0.3, 0.35, 0.2];
    let want = nodal_rows(&identity, &weights);
    let segments = p.mortar_segments();
    assert_eq!(segments.len(), 3, "one mortar segment per matching segment");
    assert_rows_equal("nts (a)", &contact::nts::rows(&p), &want);
    assert_rows_equal("mortar (a)", &contact::mortar::rows(&p), &want);
}

#[test]
fn a_slave_node_on_a_master_node_gives_the_hand_derived_rows() {
    // (b) by hand. I_h: y = 1/4 is the midpoint of body 2's first segment; y = 1/2 is its
    // node 1. pi_h: psi_1 = lambda_0 + lambda_1, psi_2 = lambda_2 + lambda_3 (h = 1/4,
    // 1/4, 1/2): M = [[5/24, 1/24], [1/24, 1/3]]; R = int psi_j mu_q minus the end terms
    // int psi_1 lambda_0 = 1/8 (q = 0) and int psi_2 lambda_3 = 1/4 (q = 2):
    // int psi_1 mu = (11/48, 7/48, 0), int psi_2 mu = (1/48, 17/48, 12/48), so
    // R = [[5/48, 7/48, 0], [1/48, 17/48, 0]] and M^-1 R = [[1/2, 1/2, 0], [0, 1, 0]]:
    // here pi_h equals I_h.
    let p = piece(&[0.0, 0.25, 0.5, 1.0], &[0.0, 0.5, 1.0]);
    let transfer = vec![
        vec![1.0, 0.0, 0.0],
        vec![0.5, 0.5, 0.0],
        vec![0.0, 1.0, 0.0],
        vec![0.0, 0.0, 1.0],
    ];
    let want = nodal_rows(&transfer, &[0.125, 0.25, 0.375, 0.25]);
    let segments = p.mortar_segments();
    assert_eq!(
        segments
            .iter()
            .map(|m| (m.slave, m.master, m.s))
            .collect::<Vec<_>>(),
        vec![(0, 0, [0.0, 0.25]), (1, 0, [0.25, 0.5]), (2, 1, [0.5, 1.0])],
        "the mortar segments: the node at 1/2 is one breakpoint, not two"
    );
    assert_rows_equal("nts (b)", &contact::nts::rows(&p), &want);
    assert_rows_equal("mortar (b)", &contact::mortar::rows(&p), &want);
    // LAC's one macro-element [0, 1] (three segments: a triple): the averages of the hats
    // over |M| = 1: body 1 (1/8, 1/4, 3/8, 1/4), body 2 (1/4, 1/2, 1/4).
    let lac = contact::lac::rows(&p);
    let want = PieceRow {
        span: [0, 3],
        slave: [0.125, 0.25, 0.375, 0.25]
            .iter()
            .enumerate()
            .map(|(j, v)| (j, [v * NU[0], v * NU[1]]))
            .collect(),
        master: [0.25, 0.5, 0.25]
            .iter()
            .enumerate()
            .map(|(q, v)| (q, [-v * NU[0], -v * NU[1]]))
            .collect(),
        weight: 1.0,
        gap: 0.0,
    };
    assert_rows_equal("lac (b)", &lac, &[want]);
}
