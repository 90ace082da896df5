//! Reference: Drouet and Hild, "An accurate local average contact (LAC) method for
//! nonmatching meshes in 2D and 3D", Numer. Math. 136 (2017) 467-502, section 2.
//! Goal: LAC's rows are the macro-element averages (1/|M|) int_M [u.nu] ds, integrated
//! exactly; the macro-elements are pairs of body-1 segments (a triple at an odd end), each
//! with a body-1 node inside; on split levels they are the parent level's segments.
//! Geometry: a straight piece of length 1 with hand-placed traces; the rates scene's
//! meshes at levels 1-3.
//! Data: body-1 nodes at 0, 1/4, 1/2, 4/5, 1; body-2 nodes at 0, 2/5, 1.

mod common;
use contact_rates::contact::{Method, Piece, constraint_rows, macro_averages, macro_elements};

#[test]
fn macro_element_averages_match_the_hand_computed_integrals() {
    let p = Piece {
        a: [0.0, 0.0],
        tangent: [1.0, 0.0],
        length: 1.0,
        normal: [0.0, -1.0],
        slave_nodes: (0..5).collect(),
        slave_s: vec![0.0, 0.25, 0.5, 0.8, 1.0],
        master_nodes: (0..3).collect(),
        master_s: vec![0.0, 0.4, 1.0],
        breaks: Vec::new(),
        ..Default::default()
    };
    let rows = macro_averages(&p);
    assert_eq!(rows.len(), 2);
    // M1 = [0, 1/2]: body-1 hats (h/2 at the ends, (h_l + h_r)/2 inside) over |M1| = 1/2;
    // body-2 hats: int_0^(2/5) (1 - 5x/2) = 1/5; int_0^(2/5) 5x/2 + int_(2/5)^(1/2)
    // (1 - 5(x - 2/5)/3) = 1/5 + 11/120; int_(2/5)^(1/2) 5(x - 2/5)/3 = 1/120.
    // M2 = [1/2, 1]: int_(1/2)^1 (1 - 5(x - 2/5)/3) = 5/24, int_(1/2)^1 5(x - 2/5)/3 = 7/24.
    let expected = [
        (
            [0, 2],
            0.5,
            vec![0.25, 0.5, 0.25],
            vec![(0, 2.0 / 5.0), (1, 7.0 / 12.0), (2, 1.0 / 60.0)],
        ),
        (
            [2, 4],
            0.5,
            vec![0.3, 0.5, 0.2],
            vec![(1, 5.0 / 12.0), (2, 7.0 / 12.0)],
        ),
    ];
    for (row, (span, size, slave, master)) in rows.iter().zip(expected) {
        assert_eq!(row.span, span);
        assert!((row.size - size).abs() < 1e-15);
        for ((j, v), w) in row.slave.iter().zip(&slave) {
            assert!(
                (v - w).abs() < 1e-15,
                "M {span:?}: body-1 node {j}: {v} vs {w}"
            );
        }
        assert_eq!(row.slave.len(), slave.len());
        let mut got = row.master.clone();
        got.retain(|e| e.1 != 0.0);
        got.sort_by_key(|e| e.0);
        assert_eq!(got.len(), master.len(), "M {span:?}: {got:?}");
        for ((q, v), (qq, w)) in got.iter().zip(&master) {
            assert_eq!(q, qq);
            assert!(
                (v - w).abs() < 1e-15,
                "M {span:?}: body-2 node {q}: {v} vs {w}"
            );
        }
    }
}

#[test]
fn macro_elements_are_pairs_with_a_triple_at_an_odd_end() {
    assert_eq!(macro_elements(1), vec![[0, 1]]);
    assert_eq!(macro_elements(2), vec![[0, 2]]);
    assert_eq!(macro_elements(3), vec![[0, 3]]);
    assert_eq!(macro_elements(5), vec![[0, 2], [2, 5]]);
    assert_eq!(macro_elements(8), vec![[0, 2], [2, 4], [4, 6], [6, 8]]);
    for n in 2..40 {
        let m = macro_elements(n);
        // They tile the piece, and each holds 2 or 3 segments: a body-1 node inside.
        assert_eq!(m[0][0], 0);
        assert_eq!(m.last().unwrap()[1], n);
        assert!(m.windows(2).all(|w| w[0][1] == w[1][0]));
        assert!(m.iter().all(|s| (2..=3).contains(&(s[1] - s[0]))));
    }
}

/// On levels made by splitting, level L+1's macro-elements are level L's body-1 segments;
/// every LAC row owns a body-1 dof no other row has (the rows are independent, so the
/// multipliers are unique), and its body-1 and body-2 averages each sum to 1.
#[test]
fn lac_rows_on_split_levels_are_the_parent_segments() {
    for level in 1..3 {
        let coarse = common::case("rates", level, Method::Lac, &[]);
        let fine = common::case("rates", level + 1, Method::Lac, &[]);
        for (pc, pf) in coarse
            .problem
            .interface
            .pieces
            .iter()
            .zip(&fine.problem.interface.pieces)
        {
            let ends: Vec<f64> = macro_averages(pf)
                .iter()
                .map(|m| pf.slave_s[m.span[0]])
                .chain([pf.length])
                .collect();
            assert_eq!(ends.len(), pc.slave_s.len());
            for (a, b) in ends.iter().zip(&pc.slave_s) {
                assert!(
                    (a - b).abs() <= 1e-12 * pc.length,
                    "level {level}: {a} vs {b}"
                );
            }
        }
        let p = &fine.problem;
        let rows = constraint_rows(&p.model, &p.interface, Method::Lac);
        assert_eq!(rows, p.rows.clone());
        let owners = |d: usize| {
            rows.iter()
                .filter(|r| r.entries.iter().any(|e| e.0 == d))
                .count()
        };
        for r in &rows {
            let piece = &p.interface.pieces[r.piece];
            assert!(
                r.entries.iter().any(|e| owners(e.0) == 1),
                "row {:?} shares every dof",
                r.span
            );
            assert!(r.span[1] - r.span[0] >= 2, "a body-1 node is inside M");
            let interior = piece.slave_nodes[r.span[0] + 1];
            assert!(r.entries.iter().any(|e| e.0 / 2 == interior));
            let m = macro_averages(&piece);
            let avg = m.iter().find(|a| a.span == r.span).unwrap();
            let s1: f64 = avg.slave.iter().map(|e| e.1).sum();
            let s2: f64 = avg.master.iter().map(|e| e.1).sum();
            assert!(
                (s1 - 1.0).abs() < 1e-14 && (s2 - 1.0).abs() < 1e-14,
                "{s1} {s2}"
            );
            assert!(
                (avg.size - (piece.slave_s[r.span[1]] - piece.slave_s[r.span[0]])).abs() < 1e-15
            );
        }
    }
}

/// The macro-elements do not depend on which way a piece runs (its direction follows gmsh's
/// node numbers): a piece and its mirror image give the same intervals of Gamma_C, the
/// triple of an odd count at the end last in (x, y) order.
#[test]
fn macro_elements_do_not_depend_on_the_direction_of_a_piece() {
    let s = vec![0.0, 0.15, 0.35, 0.5, 0.7, 1.0];
    let m = vec![0.0, 0.3, 0.55, 1.0];
    let forward = piece_along_y1(&s, &m, Vec::new());
    let backward = mirrored(&forward, Vec::new());
    let intervals = |p: &Piece| {
        let mut v: Vec<(f64, f64, f64)> = macro_averages(p)
            .iter()
            .map(|a| {
                let (x0, x1) = (
                    p.point(p.slave_s[a.span[0]])[0],
                    p.point(p.slave_s[a.span[1]])[0],
                );
                (x0.min(x1), x0.max(x1), a.size)
            })
            .collect();
        v.sort_by(|a, b| a.0.total_cmp(&b.0));
        v
    };
    let (f, b) = (intervals(&forward), intervals(&backward));
    assert_eq!(f.len(), 2);
    assert!(
        (f[1].0 - 0.35).abs() < 1e-15 && (f[1].1 - 1.0).abs() < 1e-15,
        "triple at x = 1: {f:?}"
    );
    for (x, y) in f.iter().zip(&b) {
        assert!(
            (x.0 - y.0).abs() < 1e-14 && (x.1 - y.1).abs() < 1e-14 && (x.2 - y.2).abs() < 1e-14,
            "{f:?} vs {b:?}"
        );
    }
    // Each macro-element's averages are the same numbers, node for node.
    for (ma, mb) in macro_averages(&forward)
        .iter()
        .zip(macro_averages(&backward).iter().rev())
    {
        let mut sa: Vec<f64> = ma.slave.iter().map(|e| e.1).collect();
        let mut sb: Vec<f64> = mb.slave.iter().map(|e| e.1).rev().collect();
        sa.iter_mut()
            .zip(sb.iter_mut())
            .for_each(|(x, y)| assert!((*x - *y).abs() < 1e-14));
    }
}

/// Macro-elements end at every geometry point inside a piece (the transition point c of
/// meshes/two_blocks_graded.geo is one): each run between the piece's ends and its breaks
/// is paired on its own, in both directions of the piece alike.
#[test]
fn macro_elements_end_at_the_geometry_points_of_a_piece() {
    use contact_rates::contact::macro_elements_between;
    assert_eq!(macro_elements_between(8, &[]), macro_elements(8));
    // A break at node 3 of 8 segments: runs of 3 and 5.
    assert_eq!(
        macro_elements_between(8, &[3]),
        vec![[0, 3], [3, 5], [5, 8]]
    );
    assert_eq!(
        macro_elements_between(9, &[2, 5]),
        vec![[0, 2], [2, 5], [5, 7], [7, 9]]
    );
    for n in 2..30 {
        for b in 2..n - 1 {
            let m = macro_elements_between(n, &[b]);
            assert!(
                m.iter().any(|s| s[1] == b),
                "n = {n}: a macro-element ends at the break {b}"
            );
            assert!(m.windows(2).all(|w| w[0][1] == w[1][0]));
            assert!(m.iter().all(|s| (2..=3).contains(&(s[1] - s[0]))));
        }
    }
    // The same piece and break, run forward and backward, gives the same macro-elements.
    let s = vec![0.0, 0.1, 0.25, 0.4, 0.5, 0.7, 0.85, 1.0];
    let m = vec![0.0, 0.3, 0.55, 1.0];
    let forward = piece_along_y1(&s, &m, vec![3]);
    let backward = mirrored(&forward, vec![4]);
    let ends = |p: &Piece| {
        let mut v: Vec<(i64, i64)> = macro_averages(p)
            .iter()
            .map(|a| {
                let (x0, x1) = (
                    p.point(p.slave_s[a.span[0]])[0],
                    p.point(p.slave_s[a.span[1]])[0],
                );
                (
                    (x0.min(x1) * 1e9).round() as i64,
                    (x0.max(x1) * 1e9).round() as i64,
                )
            })
            .collect();
        v.sort();
        v
    };
    assert_eq!(ends(&forward), ends(&backward));
    assert!(
        ends(&forward).iter().any(|e| e.1 == 400_000_000),
        "a macro-element ends at x = 0.4"
    );
}

/// A piece of Gamma_C along y = 1 from x = 0 to 1, body-1 abscissae `s`, body-2 `m`.
fn piece_along_y1(s: &[f64], m: &[f64], breaks: Vec<usize>) -> Piece {
    Piece {
        a: [0.0, 1.0],
        tangent: [1.0, 0.0],
        length: 1.0,
        normal: [0.0, 1.0],
        slave_nodes: (0..s.len()).collect(),
        slave_s: s.to_vec(),
        master_nodes: (0..m.len()).collect(),
        master_s: m.to_vec(),
        breaks,
        ..Default::default()
    }
}

/// The same piece run from x = 1 to 0 (its abscissae mirrored), with `breaks` in the
/// mirrored node numbering.
fn mirrored(p: &Piece, breaks: Vec<usize>) -> Piece {
    let mirror = |v: &Vec<f64>| v.iter().rev().map(|x| 1.0 - x).collect::<Vec<f64>>();
    Piece {
        a: [1.0, 1.0],
        tangent: [-1.0, 0.0],
        slave_s: mirror(&p.slave_s),
        master_s: mirror(&p.master_s),
        breaks,
        ..p.clone()
    }
}
