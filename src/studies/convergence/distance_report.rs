//! The distance between the cones in a convergence report: each method X compared with
//! the reference (mortar, [`Method::reference`]): e_mortar, e_X and X's distance D to
//! mortar against h, the triangle-inequality bounds D - e_mortar <= e_X <= D + e_mortar,
//! the consistency term of each cone, and X read against its distance to mortar.

use super::{RateRow, StudyResult};
use crate::contact::Method;
use crate::error::Result;
use crate::report::markdown::{Doc, Table};
use crate::report::plot::{self, Series};
use crate::verify::quantity::Quantity;
use crate::verify::judge;
use crate::verify::rates::{Fit, LevelError, Verdict, assess};
use std::path::Path;

/// The fit of a row whose verdict supports a rate.
fn supported_fit(row: Option<&RateRow>) -> Option<Fit> {
    row?.supported_fit()
}

/// The methods whose distance to the reference the study measures in the theorem norm.
fn with_distance(res: &StudyResult) -> Vec<Method> {
    Method::compared(&res.file.methods)
        .filter(|&m| res.rate(m, Quantity::ConeDistance).is_some())
        .collect()
}

/// The section, where the study measures the cone distance in the theorem norm.
pub fn section(doc: &mut Doc, res: &StudyResult) {
    let key = Quantity::ConeDistance;
    let others = with_distance(res);
    let reference = Method::reference();
    if others.is_empty() {
        // No distance in the theorem norm (patch's truth has no displacement): the methods
        // are still read against the distances the study measures.
        if !judge::asymptotes(&res.rates, &res.errors).is_empty() {
            doc.heading(2, "The distance between the cones");
            decomposition(doc, res);
        }
        return;
    }
    let theorem = Quantity::Theorem;
    doc.heading(2, "The distance between the cones")
        .paragraph(
            "Every method is solved on the same meshes as mortar, so the distance D between a method X's solution and mortar's is computed exactly on one mesh: D = max over the steps of ||u^X - u^pi||_H1 + ||sigma^X - sigma^pi||_L2, relative to the truth's norm as the errors are. By the triangle inequality D - e_mortar <= e_X <= D + e_mortar. nts's D falling like h^(1/2) while e_mortar falls like h shows that nts's error holds an h^(1/2) part: the rate Theorem 3.1 allows K_h^I is then attained, not only respected.",
        )
        .image("the cones' errors and their distance against h", "cone_distance.png");
    let consistency = res.file.quantities.contains(&Quantity::Consistency);
    let mut header: Vec<String> = vec!["level".into(), "h".into(), format!("e_{reference}")];
    for m in &others {
        header.extend([format!("e_{m}"), format!("D_{m}"), format!("D_{m} - e_{reference}"), format!("D_{m} + e_{reference}")]);
    }
    if consistency {
        header.extend(res.file.methods.iter().map(|m| format!("consistency, {m}")));
    }
    let mut table = Table::new(header);
    for level in &res.file.mesh.levels {
        let Some(em) = res.error(reference, *level, theorem) else {
            continue;
        };
        let pairs: Option<Vec<(f64, f64)>> = others
            .iter()
            .map(|&m| Some((res.error(m, *level, theorem)?, res.error(m, *level, key)?)))
            .collect();
        let Some(pairs) = pairs else {
            continue;
        };
        let h = res
            .errors
            .iter()
            .find(|e| e.level == *level)
            .map_or(f64::NAN, |e| e.h);
        let mut row = vec![level.to_string(), format!("{h:.5}"), format!("{em:.4e}")];
        for (en, d) in pairs {
            row.extend([format!("{en:.4e}"), format!("{d:.4e}"), format!("{:.4e}", d - em), format!("{:.4e}", d + em)]);
        }
        if consistency {
            for &m in &res.file.methods {
                row.push(
                    res.error(m, *level, Quantity::Consistency)
                        .map_or("-".into(), |v| format!("{v:.4e}")),
                );
            }
        }
        table.row(row);
    }
    doc.table(&table);
    let mut rates = Table::new(["quantity", "rate of the distance in h (the method's rows of rates.csv)"]);
    for &m in &others {
        for q in Quantity::DISTANCES {
            if let Some(r) = res.rate(m, q) {
                rates.row([format!("`{q}`, {m}"), r.assessment.describe()]);
            }
        }
    }
    if consistency {
        for &m in &res.file.methods {
            if let Some(r) = res.rate(m, Quantity::Consistency) {
                rates.row([format!("`consistency`, {m}"), r.assessment.describe()]);
            }
        }
    }
    doc.table(&rates);
    decomposition(doc, res);
    compared(doc, res);
}

/// `method`'s distance to mortar in the theorem norm of `errors`, by level.
fn distances(errors: &[crate::verify::table::ErrorRecord], method: Method) -> Vec<LevelError> {
    let rows: Vec<&crate::verify::table::ErrorRecord> = errors
        .iter()
        .filter(|e| e.method == method && e.quantity == Quantity::ConeDistance)
        .collect();
    let mut out = judge::levels_of_errors(&rows);
    out.sort_by_key(|e| e.level);
    out
}

/// `method`'s distance to mortar here and in the committed report reports/`other`, on
/// the levels both measure, in level order: (here, there).
fn beside(res: &StudyResult, other: &str, method: Method) -> Result<(Vec<LevelError>, Vec<LevelError>)> {
    let path = crate::report::folder::reports_dir().join(other).join("errors.csv");
    let (ours, theirs) = (distances(&res.errors, method), distances(&crate::verify::table::read(&path)?, method));
    let common = |a: &[LevelError], b: &[LevelError]| -> Vec<LevelError> {
        a.iter().filter(|x| b.iter().any(|y| y.level == x.level)).cloned().collect()
    };
    Ok((common(&ours, &theirs), common(&theirs, &ours)))
}

/// D judged on `levels`, with its constant: "rate ± se (fitted), D ~ C h^rate with C = ..."
/// where fitted, else the verdict.
fn judged_with_constant(levels: &[LevelError]) -> String {
    match assess(levels, 0.0) {
        Ok(a) => match a.fit.filter(|_| a.verdict == Verdict::Fitted) {
            Some(f) => format!(
                "{:.3} ± {:.3} over levels {}, D ~ C h^rate with C = {:.3e}",
                f.rate,
                f.stderr,
                crate::verify::table::join(&a.used),
                f.intercept.exp()
            ),
            None => a.describe(),
        },
        Err(e) => e.to_string(),
    }
}

/// The lead of a study with `compare`: what it learned, in a few sentences of numbers:
/// D's verdict, D / e_mortar on the two finest levels, each cone's theorem-norm verdict, the
/// contact fraction, and D's rate and D / h^(1/2) beside the other study's.
pub fn lead(doc: &mut Doc, res: &StudyResult) {
    let Some(other) = &res.file.compare else {
        return;
    };
    let levels = &res.file.mesh.levels;
    let reference = Method::reference();
    let ratio = |m: Method, l: usize| {
        Some(res.error(m, l, Quantity::ConeDistance)? / res.error(reference, l, Quantity::Theorem)?)
    };
    let finest = |m: Method| -> Vec<String> {
        levels
            .iter()
            .rev()
            .take(2)
            .rev()
            .map(|&l| ratio(m, l).map_or(format!("- (level {l})"), |r| format!("{r:.2} (level {l})")))
            .collect()
    };
    let describe = |m: Method, q: Quantity| res.rate(m, q).map_or("-".into(), |r| r.assessment.describe());
    let fraction = |m: Method| {
        res.levels
            .iter()
            .filter(|l| l.method == m)
            .max_by_key(|l| l.level)
            .map_or("-".into(), |l| format!("{:.4}", l.contact_fraction))
    };
    let others = with_distance(res);
    let mut lines: Vec<String> = others
        .iter()
        .map(|&m| {
            format!(
                "{m}'s distance to {reference} D (theorem norm): {}; D / e_{reference} on the two finest levels {}: where D is the larger, {m}'s error is D's.",
                describe(m, Quantity::ConeDistance),
                finest(m).join(", ")
            )
        })
        .collect();
    lines.extend([
        format!(
            "Theorem norm: {}.",
            res.file
                .methods
                .iter()
                .map(|&m| format!("{m} {}", describe(m, Quantity::Theorem)))
                .collect::<Vec<_>>()
                .join("; ")
        ),
        format!(
            "The interface separates: contact on a fraction {} of Gamma_C at the finest level (levels.csv).",
            res.file
                .methods
                .iter()
                .map(|&m| format!("{} ({m})", fraction(m)))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    ]);
    for &m in &others {
        let Ok((mine, yours)) = beside(res, other, m) else {
            continue;
        };
        if let (Some(first), Some(a), Some(b)) = (mine.first(), mine.last(), yours.last()) {
            lines.push(format!(
                "Against {other} at its levels {}-{} (each D relative to its own problem's norm): {m}'s D's rate here {}, there {}; D / h^(1/2) at level {} {:.4} here, {:.4} there ({:.2}x).",
                first.level,
                a.level,
                judged_with_constant(&mine),
                judged_with_constant(&yours),
                a.level,
                a.error / a.h.sqrt(),
                b.error / b.h.sqrt(),
                (a.error / a.h.sqrt()) / (b.error / b.h.sqrt())
            ));
        }
    }
    doc.heading(2, "What the study learned").list(lines);
}

/// The study file's `compare`: each method's distance to mortar beside the other study's
/// (its committed report) at the levels both measure, judged on those levels alone.
fn compared(doc: &mut Doc, res: &StudyResult) {
    let Some(other) = &res.file.compare else {
        return;
    };
    doc.heading(3, &format!("The distance beside {other}'s"));
    for m in with_distance(res) {
        match beside(res, other, m) {
            Ok((mine, yours)) => compared_table(doc, other, m, &mine, &yours),
            Err(e) => {
                doc.paragraph(format!("Not compared: {e} (`cargo run --release -- study {other}` writes it)."));
                return;
            }
        }
    }
}

/// One method's distance to mortar here (`mine`) and in `other` (`yours`), level by level.
fn compared_table(doc: &mut Doc, other: &str, m: Method, mine: &[LevelError], yours: &[LevelError]) {
    let mut table = Table::new(
        ["level", "h here", "D here", "h there", &format!("D in {other}"), "here / there", "D / h^(1/2) here", "D / h^(1/2) there"]
            .map(String::from),
    );
    for (a, b) in mine.iter().zip(yours) {
        table.row([
            a.level.to_string(),
            format!("{:.5}", a.h),
            format!("{:.4e}", a.error),
            format!("{:.5}", b.h),
            format!("{:.4e}", b.error),
            format!("{:.3}", a.error / b.error),
            format!("{:.4}", a.error / a.h.sqrt()),
            format!("{:.4}", b.error / b.h.sqrt()),
        ]);
    }
    doc.paragraph(format!(
        "{m}'s distance to {} in the theorem norm here and in reports/{other} (its committed errors.csv), relative to each problem's own exact solution, at the levels both measure, each judged by the same rules on those levels only: here {}; in {other} {}.",
        Method::reference(),
        judged_with_constant(mine),
        judged_with_constant(yours)
    ))
    .table(&table);
}

/// Each method read against its distance to mortar: for the theorem norm, h1_u and
/// l2_stress, the method's observed verdict beside mortar's and its own D's, the largest
/// |pythagorean| of decomposition.csv, D / e_mortar at the finest level, and what D's
/// verdict supports of the method's asymptotic rate (asymptotes.csv). One row per method
/// and quantity, every cell read from the method named in its row.
fn decomposition(doc: &mut Doc, res: &StudyResult) {
    let mut table = Table::new([
        "method",
        "quantity",
        "observed",
        "mortar",
        "D (distance to mortar)",
        "largest abs(pythagorean)",
        "D / e_mortar, finest level",
        "asymptotic rate",
    ]);
    for a in judge::asymptotes(&res.rates, &res.errors) {
        let Some(method) = a.method.cone() else {
            continue;
        };
        let (q, dq) = judge::DECOMPOSED
            .into_iter()
            .find(|(q, _)| *q == a.quantity)
            .expect("a decomposed quantity");
        let describe = |m: Method, q: Quantity| res.rate(m, q).map_or("-".into(), |r| r.assessment.describe());
        table.row([
            method.to_string(),
            format!("`{q}`"),
            describe(method, q),
            describe(Method::reference(), q),
            describe(method, dq),
            a.largest_pythagorean.map_or("-".into(), |v| format!("{v:.1e}")),
            match a.mortar_verdict {
                // A ratio to round-off measures nothing.
                crate::verify::rates::Verdict::RoundOff => "mortar exact (round-off)".into(),
                _ => a.finest_ratio.map_or("-".into(), |v| format!("{v:.2}")),
            },
            a.describe(),
        ]);
    }
    if table.is_empty() {
        return;
    }
    doc.heading(3, "Each method read against its distance to mortar")
        .paragraph("Since D - e_mortar <= e_X <= D + e_mortar for a method X with distance D to mortar on the same meshes, X's error tends to the rate min(r_D, r_mortar) once D's rate is supported, and its observed rate turns where D overtakes e_mortar. `pythagorean` = e_X / sqrt(e_mortar^2 + D^2) - 1 (decomposition.csv) is descriptive: near 0 where the two parts are orthogonal. Where D's verdict supports no rate, nothing is predicted. Where D has not yet overtaken e_mortar, the predicted level range takes D's rate over its own range (its fitted rate, its last successive rate, its fit over every level), D's line anchored at its finest level and mortar's at its fit (asymptotes.csv). Each row's cells are its method's own (asymptotes.csv's `method`).")
        .table(&table);
}

/// cone_distance.png: e_mortar, and each other method's e_X and distance D to mortar, in
/// the theorem norm against h, with D's and mortar's fitted lines.
pub fn plot(res: &StudyResult, d: &Path) -> Result<()> {
    let others = with_distance(res);
    if others.is_empty() {
        return Ok(());
    }
    let reference = Method::reference();
    let points = |m: Method, q: Quantity| -> Vec<(f64, f64)> {
        res.errors
            .iter()
            .filter(|e| e.method == m && e.quantity == q)
            .map(|e| (e.h, e.error))
            .collect()
    };
    let mut series = Vec::new();
    let mut curves = vec![(format!("e_{reference}"), reference, Quantity::Theorem, res.rate(reference, Quantity::Theorem), 0)];
    for (k, &m) in others.iter().enumerate() {
        curves.push((format!("e_{m}"), m, Quantity::Theorem, None, 1 + 2 * k));
        curves.push((format!("D ({m} - {reference})"), m, Quantity::ConeDistance, res.rate(m, Quantity::ConeDistance), 2 + 2 * k));
    }
    for (label, m, q, row, color) in curves {
        series.push(Series {
            label: label.clone(),
            points: points(m, q),
            markers: true,
            line: row.is_none(),
            color,
            thin: row.is_none(),
            shape: None,
        });
        if let (Some(fit), Some(row)) = (supported_fit(row), row) {
            let used: Vec<f64> = res
                .errors
                .iter()
                .filter(|e| e.method == m && e.quantity == q && row.assessment.used.contains(&e.level))
                .map(|e| e.h)
                .collect();
            let line = format!("{label} fit: slope {:.2} ± {:.2}", fit.rate, fit.stderr);
            series.extend(plot::fit_line(line, fit.rate, fit.intercept, &used, color));
        }
    }
    plot::loglog(
        &d.join("cone_distance.png"),
        &format!("{}: the cones' errors and their distance", res.name),
        res.scene.refinement.h_axis(),
        "relative, Theorem 3.1's norm",
        &series,
        &[(0.5, "1/2"), (0.75, "3/4"), (1.0, "1")],
    )
}
