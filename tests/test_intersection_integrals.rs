//! Reference: SPEC section 5 (errors between meshes are integrated exactly over the
//! intersection of the two triangulations).
//! Goal: the intersection conserves area to 1e-13; it integrates quadratic polynomials
//! exactly (closed form); on nested meshes the error computed through the intersection
//! equals the error computed directly on the fine mesh after exact prolongation.
//! Geometry: the two-block domain [0,1]x[0,2] of the `rates` scene, non-matching study
//! meshes against matching (nested) reference meshes.

mod common;
use contact_rates::contact::Method;
use contact_rates::material::Stress;
use contact_rates::solve::{self, Settings, State};
use contact_rates::verify::field::P1Field;
use contact_rates::verify::intersect::{Tri, barycentric, clip};
use contact_rates::verify::norms::{Comparison, norms};

fn area(m: &contact_rates::fe::Model) -> f64 {
    m.elements.iter().map(|e| e.area).sum()
}

#[test]
fn clipping_two_triangles_gives_the_closed_form_overlap() {
    // Unit right triangle against its mirror: the overlap is the triangle (0,0),(0.5,0.5),(1,0)...
    let a: Tri = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
    let b: Tri = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]];
    let p = clip(&a, &b);
    let ar: f64 = (1..p.len() - 1)
        .map(|k| {
            0.5 * ((p[k][0] - p[0][0]) * (p[k + 1][1] - p[0][1])
                - (p[k + 1][0] - p[0][0]) * (p[k][1] - p[0][1]))
        })
        .sum();
    assert!((ar - 0.25).abs() < 1e-15, "overlap area {ar}");
    // Disjoint triangles.
    let c: Tri = [[2.0, 2.0], [3.0, 2.0], [2.0, 3.0]];
    assert!(clip(&a, &c).len() < 3);
    let l = barycentric(&a, [0.25, 0.5]);
    assert!(
        (l[0] - 0.25).abs() < 1e-15 && (l[1] - 0.25).abs() < 1e-15 && (l[2] - 0.5).abs() < 1e-15
    );
}

#[test]
fn intersection_conserves_area_and_integrates_quadratics_exactly() {
    let reference = common::case("rates", 3, Method::Mortar, &[("matching", 1.0)]);
    for level in 0..3 {
        let study = common::case("rates", level, Method::Mortar, &[]);
        let cmp = Comparison::new(&study.problem.model, &reference.problem.model);
        let a_ref = area(&reference.problem.model);
        let a_study = area(&study.problem.model);
        println!(
            "level {level}: intersection area {:.16}, study mesh {a_study:.16}, reference mesh {a_ref:.16}",
            cmp.area()
        );
        assert!(
            (cmp.area() - a_ref).abs() <= 1e-13 * a_ref,
            "area not conserved: {} vs {a_ref}",
            cmp.area()
        );
        // int over [0,1]x[0,2] of x^2 + 3xy - y^2 + 2 = 2/3 + 3 - 8/3 + 4 = 5.
        let v = cmp.integrate(&study.problem.model, |x| {
            x[0] * x[0] + 3.0 * x[0] * x[1] - x[1] * x[1] + 2.0
        });
        assert!((v - 5.0).abs() < 1e-12, "quadratic integral {v}");
    }
}

/// Prolong a coarse state to a nested fine mesh: P1 values at the fine nodes (exact, the
/// coarse field is linear on each coarse triangle) and the P0 stress of the coarse parent.
fn prolong(coarse: &contact_rates::fe::Model, s: &State, fine: &contact_rates::fe::Model) -> State {
    let locate = |x: [f64; 2], body: usize| -> (usize, [f64; 3]) {
        let mut best = (usize::MAX, [0.0; 3], f64::NEG_INFINITY);
        for (i, e) in coarse
            .elements
            .iter()
            .enumerate()
            .filter(|(_, e)| e.body == body)
        {
            let t = e.nodes.map(|n| coarse.position(n));
            let l = barycentric(&t, x);
            let m = l[0].min(l[1]).min(l[2]);
            if m > best.2 {
                best = (i, l, m);
            }
        }
        (best.0, best.1)
    };
    let mut u = vec![0.0; 2 * fine.n_nodes];
    for b in 0..2 {
        for ln in 0..fine.meshes[b].nodes.len() {
            let g = ln + fine.node_offset[b];
            let (e, l) = locate(fine.position(g), b);
            for c in 0..2 {
                u[2 * g + c] = (0..3)
                    .map(|k| l[k] * s.u[2 * coarse.elements[e].nodes[k] + c])
                    .sum();
            }
        }
    }
    let sigma: Vec<Stress> = fine
        .elements
        .iter()
        .map(|e| {
            let p = e.nodes.map(|n| fine.position(n));
            let c = [
                (p[0][0] + p[1][0] + p[2][0]) / 3.0,
                (p[0][1] + p[1][1] + p[2][1]) / 3.0,
            ];
            s.sigma[locate(c, e.body).0]
        })
        .collect();
    State {
        time: s.time,
        u,
        sigma,
        lambda: Vec::new(),
    }
}

#[test]
fn nested_meshes_give_the_direct_sum() {
    let p = [("matching", 1.0)];
    let coarse = common::case("rates", 1, Method::Mortar, &p);
    let fine = common::case("rates", 2, Method::Mortar, &p);
    let sc = solve::solve(&coarse.problem, &Settings::default(), 2, false).unwrap();
    let sf = solve::solve(&fine.problem, &Settings::default(), 2, false).unwrap();
    let (mc, mf) = (&coarse.problem.model, &fine.problem.model);
    let cmp = Comparison::new(mc, mf);
    let via = cmp.difference(
        mc,
        &P1Field::of_state(&coarse.problem, sc.last()),
        mf,
        &P1Field::of_state(&fine.problem, sf.last()),
    );
    let pro = prolong(mc, sc.last(), mf);
    let d = P1Field {
        time: 1.0,
        u: pro.u.iter().zip(&sf.last().u).map(|(a, b)| a - b).collect(),
        stress: pro
            .sigma
            .iter()
            .zip(&sf.last().sigma)
            .map(|(a, b)| a - b)
            .collect(),
        pressure: None,
        pressure_space: contact_rates::verify::field::PressureSpace::Linear,
    };
    let direct = norms(mf, &d);
    println!("via intersection: {via:?}\ndirect on the fine mesh: {direct:?}");
    for (a, b) in [
        (via.l2_u, direct.l2_u),
        (via.semi_u, direct.semi_u),
        (via.stress, direct.stress),
    ] {
        assert!((a - b).abs() <= 1e-10 * b, "{a} vs {b}");
    }
}
