//! What the third method, LAC, changes in a convergence report: at the finest level, lac's
//! error beside mortar's and nts's in each quantity and the method it is nearer, lac's and
//! nts's distances to mortar, and lac's pressure rate beside the best rate a
//! piecewise-constant profile can reach.

use super::StudyResult;
use crate::contact::Method;
use crate::report::markdown::{Doc, Table};
use crate::verify::quantity::Quantity;
use crate::verify::rates::{ROUNDOFF, Verdict};

/// The best rate in h of the L2(Gamma_C) pressure error a profile of the given kind can
/// reach on uniform meshes: piecewise constant min(1, beta - 1/2), piecewise linear
/// min(2, beta - 1/2) where the pressure is ~ r^(beta - 1) at a point (`beta`: best
/// approximation of r^a in L2 on the O(1) segments at the point is h^(a + 1/2)); 1 and 2
/// for a smooth one (`beta` None).
pub fn best_pressure_rate(beta: Option<f64>, piecewise_constant: bool) -> f64 {
    let order = if piecewise_constant { 1.0 } else { 2.0 };
    beta.map_or(order, |b| (b - 0.5).min(order))
}

/// The exponent beta of the study's singular part, if its exact solution has one.
fn singular_exponent(res: &StudyResult) -> Option<f64> {
    let exact = res.scene.exact.as_ref()?;
    exact.singular.as_ref().map(|s| s.exponent)
}

/// Which of mortar and nts lac's error `lac` is nearer to (in the ratio of errors).
fn nearer(lac: f64, mortar: f64, nts: f64) -> &'static str {
    let off = |x: f64| x <= ROUNDOFF;
    match (off(lac), off(mortar), off(nts)) {
        (true, true, false) => return "mortar (both at round-off)",
        (true, false, true) => return "nts (both at round-off)",
        (true, true, true) => return "all at round-off",
        _ => {}
    }
    let (a, b) = ((lac / mortar).ln().abs(), (lac / nts).ln().abs());
    if a.min(b) > 2f64.ln() {
        "neither (more than 2x from both)"
    } else if (mortar / nts).ln().abs() < 0.05 {
        "both (mortar and nts within 5%)"
    } else if a < b {
        "mortar"
    } else {
        "nts"
    }
}

/// The section, where the study solves lac beside mortar and nts.
pub fn section(doc: &mut Doc, res: &StudyResult) {
    let methods = &res.file.methods;
    if !(methods.contains(&Method::Lac) && methods.contains(&Method::Mortar) && methods.contains(&Method::Nts)) {
        return;
    }
    let finest = *res.file.mesh.levels.last().expect("levels");
    let rate = |m: Method, q: Quantity| res.rate(m, q).map_or("n/a".into(), |r| r.assessment.describe());
    let mut table = Table::new([
        "quantity".to_string(),
        format!("lac: error at level {finest}"),
        "lac / mortar".into(),
        "lac / nts".into(),
        "nearer".into(),
        "lac: rate".into(),
        "mortar: rate".into(),
        "nts: rate".into(),
    ]);
    // The best approximation measures the space, not the solution: its own section.
    let quantities: Vec<Quantity> = res
        .file
        .solution_quantities()
        .filter(|q| !q.is_best_approximation())
        .collect();
    let ordered = quantities
        .iter()
        .filter(|q| **q == Quantity::Theorem)
        .chain(quantities.iter().filter(|q| q.is_contact()))
        .chain(quantities.iter().filter(|q| !q.is_contact() && **q != Quantity::Theorem));
    for &q in ordered {
        let error = |m: Method| res.error(m, finest, q);
        let (Some(l), Some(m), Some(n)) = (error(Method::Lac), error(Method::Mortar), error(Method::Nts)) else {
            continue;
        };
        let ratio = |x: f64| match l / x {
            _ if x <= ROUNDOFF => "-".into(),
            r if r < 1e-2 => format!("{r:.1e}"),
            r => format!("{r:.3}"),
        };
        table.row([
            format!("`{q}`"),
            format!("{l:.3e}"),
            ratio(m),
            ratio(n),
            nearer(l, m, n).to_string(),
            rate(Method::Lac, q),
            rate(Method::Mortar, q),
            rate(Method::Nts, q),
        ]);
    }
    doc.heading(2, "What the third method changes")
        .paragraph(format!(
            "LAC (Drouet and Hild, Numer. Math. 136 (2017) 467-502) asks non-penetration on average over macro-elements of two body-1 segments (three at the end of a piece with an odd count; docs/methods.md), with a pressure constant on each: local like nts; its authors announce an optimal estimate for elastic bodies (read here as h^1 for u in H^2, a claim under test: the study file's thresholds say where it is held to it). At level {finest}: lac's error over mortar's and over nts's in each quantity, the method whose error it is nearer (by the ratio; `neither` where it is more than 2x from both), and the three rates. A ratio is `-` where the other's error is at round-off (<= 1e-10)."
        ))
        .table(&table);
    let mut lines = Vec::new();
    for m in [Method::Lac, Method::Nts] {
        let (Some(d), Some(e)) = (
            res.error(m, finest, Quantity::ConeDistance),
            res.error(Method::Mortar, finest, Quantity::Theorem),
        ) else {
            continue;
        };
        let ratio = if e > ROUNDOFF { format!("{:.3}", d / e) } else { "-".into() };
        lines.push(format!(
            "{m}'s distance to mortar in the theorem norm at level {finest}: {d:.3e}, {ratio} of mortar's error; its rate {}.",
            rate(m, Quantity::ConeDistance)
        ));
    }
    lines.extend(pressure_line(res, finest));
    let edge = res.rate(Method::Lac, Quantity::ContactEdge);
    if let (Some(r), Some(e)) = (edge, res.error(Method::Lac, finest, Quantity::ContactEdge))
        && r.assessment.verdict == Verdict::NotConverging
    {
        lines.push(format!(
            "`contact_edge` of lac does not converge: a pressure constant on macro-elements places the edge of contact at a macro-element end, so the error stays at about the distance from the exact edge to the nearest such end ({e:.3e} at level {finest}) until a finer level puts one nearer (docs/methods.md)."
        ));
    }
    doc.list(lines);
}

/// lac's pressure beside what its space allows: the measured best approximations where the
/// study measures them (`best_l2_pressure`), else the asymptotic best rates.
fn pressure_line(res: &StudyResult, finest: usize) -> Option<String> {
    let rate = |m: Method, q: Quantity| res.rate(m, q).map_or("n/a".into(), |r| r.assessment.describe());
    let listed = |q: Quantity| res.file.quantities.contains(&q);
    let best = |m: Method| res.error(m, finest, Quantity::BestL2Pressure);
    if let (Some(bl), Some(bm), Some(el), Some(em)) = (
        best(Method::Lac),
        best(Method::Mortar),
        res.error(Method::Lac, finest, Quantity::L2Pressure),
        res.error(Method::Mortar, finest, Quantity::L2Pressure),
    ) && bl > ROUNDOFF
        && bm > ROUNDOFF
    {
        Some(format!(
            "`l2_pressure` beside the best approximation of the exact pressure in each method's own space at level {finest} (measured, `best_l2_pressure`; below): lac's space (constant on each macro-element) {bl:.3e}, its best's rate {}; the cones' (piecewise linear) {bm:.3e}, rate {}; lac's error is {:.2} times its best, mortar's {:.2} times its.",
            rate(Method::Lac, Quantity::BestL2Pressure),
            rate(Method::Mortar, Quantity::BestL2Pressure),
            el / bl,
            em / bm
        ))
    } else if listed(Quantity::BestL2Pressure) {
        Some(format!(
            "`l2_pressure`: the exact pressure lies in lac's space or the cones' (its best approximation's error at level {finest}: lac {}, the cones {}): no best rate to read lac's against.",
            best(Method::Lac).map_or("-".into(), |b| format!("{b:.1e}")),
            best(Method::Mortar).map_or("-".into(), |b| format!("{b:.1e}"))
        ))
    } else if listed(Quantity::L2Pressure) {
        Some(format!(
            "`l2_pressure`: lac's pressure is constant on each macro-element, so the best rate in h a profile like it can reach here is {:.3} (mortar's and nts's piecewise-linear profiles: {:.3}); lac's rate {}, mortar's {}.",
            best_pressure_rate(singular_exponent(res), true),
            best_pressure_rate(singular_exponent(res), false),
            rate(Method::Lac, Quantity::L2Pressure),
            rate(Method::Mortar, Quantity::L2Pressure)
        ))
    } else {
        None
    }
}
