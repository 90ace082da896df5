//! The distance between the two cones in a convergence report: e_mortar, e_nts and D
//! against h, the triangle-inequality bounds D - e_mortar <= e_nts <= D + e_mortar, the
//! consistency term of each cone, and where D's fitted line would reach mortar's.

use super::{RateRow, StudyResult};
use crate::contact::Method;
use crate::error::Result;
use crate::report::markdown::{Doc, Table};
use crate::report::plot::{self, Series};
use crate::verify::quantity::Quantity;
use crate::verify::rates::{Fit, Verdict};
use std::path::Path;

/// The fit of a fitted rate (the rules' window of agreeing successive rates).
fn supported_fit(row: Option<&RateRow>) -> Option<Fit> {
    let a = &row?.assessment;
    // A drifting rate is still changing: no line to extrapolate.
    (a.verdict == Verdict::Fitted).then_some(a.fit).flatten()
}

/// The section, where the study measures the cone distance in the theorem norm.
pub fn section(doc: &mut Doc, res: &StudyResult) {
    let key = Quantity::ConeDistance;
    let Some(d_row) = res.rate(Method::Nts, key) else {
        return;
    };
    let theorem = Quantity::Theorem;
    doc.heading(2, "The distance between the cones")
        .paragraph(
            "Both cones are solved on the same meshes, so the distance D between their solutions is computed exactly on one mesh: D = max over the steps of ||u^I - u^pi||_H1 + ||sigma^I - sigma^pi||_L2, relative to the truth's norm as the errors are. By the triangle inequality D - e_mortar <= e_nts <= D + e_mortar. D falling like h^(1/2) while e_mortar falls like h shows that nts's error holds an h^(1/2) part: the rate Theorem 3.1 allows K_h^I is then attained, not only respected.",
        )
        .image("the cones' errors and their distance against h", "cone_distance.png");
    let consistency = res.file.quantities.contains(&Quantity::Consistency);
    let mut header: Vec<String> = ["level", "h", "e_mortar", "e_nts", "D", "D - e_mortar", "D + e_mortar"]
        .into_iter()
        .map(String::from)
        .collect();
    if consistency {
        header.push("consistency, mortar".into());
        header.push("consistency, nts".into());
    }
    let mut table = Table::new(header);
    for level in &res.file.mesh.levels {
        let (Some(em), Some(en), Some(d)) = (
            res.error(Method::Mortar, *level, theorem),
            res.error(Method::Nts, *level, theorem),
            res.error(Method::Nts, *level, key),
        ) else {
            continue;
        };
        let h = res
            .errors
            .iter()
            .find(|e| e.level == *level)
            .map_or(f64::NAN, |e| e.h);
        let mut row = vec![
            level.to_string(),
            format!("{h:.5}"),
            format!("{em:.4e}"),
            format!("{en:.4e}"),
            format!("{d:.4e}"),
            format!("{:.4e}", d - em),
            format!("{:.4e}", d + em),
        ];
        if consistency {
            for m in [Method::Mortar, Method::Nts] {
                row.push(
                    res.error(m, *level, Quantity::Consistency)
                        .map_or("-".into(), |v| format!("{v:.4e}")),
                );
            }
        }
        table.row(row);
    }
    doc.table(&table);
    let mut rates = Table::new(["quantity", "rate of the distance in h (nts's rows of rates.csv)"]);
    for q in Quantity::DISTANCES {
        if let Some(r) = res.rate(Method::Nts, q) {
            rates.row([format!("`{q}`"), r.assessment.describe()]);
        }
    }
    if consistency {
        for m in [Method::Mortar, Method::Nts] {
            if let Some(r) = res.rate(m, Quantity::Consistency) {
                rates.row([format!("`consistency`, {m}"), r.assessment.describe()]);
            }
        }
    }
    doc.table(&rates);
    doc.paragraph(crossover(res, d_row));
}

/// Where D's fitted line reaches mortar's, and the local rate of the upper bound
/// D + e_mortar of nts's error there and two levels later.
fn crossover(res: &StudyResult, d_row: &RateRow) -> String {
    let mortar = res.rate(Method::Mortar, Quantity::Theorem);
    let (Some(mortar), Some(fm), Some(fd)) = (mortar, supported_fit(mortar), supported_fit(Some(d_row))) else {
        return "No crossover is predicted: D's or mortar's theorem-norm errors support no rate (see the rates above).".into();
    };
    if fd.rate >= fm.rate {
        return format!(
            "D falls at {:.3}, no slower than mortar's error ({:.3}): no crossover is predicted from these levels.",
            fd.rate, fm.rate
        );
    }
    // e = exp(intercept) h^rate for both; equal at h*.
    let h_star = ((fm.intercept - fd.intercept) / (fd.rate - fm.rate)).exp();
    let finest = *res.file.mesh.levels.last().expect("levels");
    let (h_finest, dofs_finest) = res
        .errors
        .iter()
        .find(|e| e.level == finest && e.method == Method::Nts)
        .map_or((f64::NAN, 0), |e| (e.h, e.dofs));
    // Each level halves h and multiplies the dofs by about 4.
    let level = finest as f64 + (h_finest / h_star).log2();
    let dofs = dofs_finest as f64 * 4f64.powf(level - finest as f64);
    // The local rate of D + e_mortar where D / e_mortar = ratio.
    let upper = |ratio: f64| (fm.rate + fd.rate * ratio) / (1.0 + ratio);
    let later = 4f64.powf(fm.rate - fd.rate);
    let lines = [(mortar, fm), (d_row, fd)];
    let sd = crossover_level_sd(res, lines, h_star.ln()).map_or(String::new(), |sd| {
        format!(" ± {sd:.1} (one standard deviation from the two rates' standard errors)")
    });
    let place = if level <= finest as f64 {
        format!("at level {level:.1}{sd}, within the study's levels")
    } else {
        format!("near level {level:.1}{sd}, about {dofs:.1e} dofs")
    };
    format!(
        "From the fitted rates (D {:.3}, e_mortar {:.3}), D reaches e_mortar at h = {h_star:.3e}, {place}. There nts's error lies between 0 and 2 e_mortar, and the upper bound D + e_mortar falls at the local rate {:.2}; two levels later (D = {later:.1} e_mortar) at {:.2}, tending to D's {:.3}.",
        fd.rate,
        fm.rate,
        upper(1.0),
        upper(later),
        fd.rate
    )
}

/// One standard deviation of the level where two fitted lines log e = intercept + rate
/// log h (mortar's, then D's) cross at `log_h_star`, from their rates' standard errors:
/// the delta method on each line taken at its levels' mean log h, where its value and
/// slope are uncorrelated (value variance: the slope's times the levels' sum of squares
/// over their count), the two fits independent. None where a level's h is missing.
fn crossover_level_sd(res: &StudyResult, lines: [(&RateRow, Fit); 2], log_h_star: f64) -> Option<f64> {
    let mut variance = 0.0;
    for (row, fit) in lines {
        let log_h: Vec<f64> = (row.assessment.used.iter())
            .map(|&l| {
                let e = res.errors.iter().find(|e| e.level == l && e.method == row.method)?;
                Some(e.h.ln())
            })
            .collect::<Option<_>>()?;
        let n = log_h.len() as f64;
        let mean = log_h.iter().sum::<f64>() / n;
        let sxx: f64 = log_h.iter().map(|x| (x - mean).powi(2)).sum();
        let slope_variance = fit.stderr.powi(2);
        variance += slope_variance * sxx / n + (mean - log_h_star).powi(2) * slope_variance;
    }
    // d(log h*) / d(value) = 1 / (rate difference); a level is a factor 2 in h.
    let rate_difference = (lines[0].1.rate - lines[1].1.rate).abs();
    Some(variance.sqrt() / rate_difference / std::f64::consts::LN_2)
}

/// cone_distance.png: e_mortar, e_nts and D in the theorem norm against h, with D's and
/// mortar's fitted lines.
pub fn plot(res: &StudyResult, d: &Path) -> Result<()> {
    let Some(d_row) = res.rate(Method::Nts, Quantity::ConeDistance) else {
        return Ok(());
    };
    let points = |m: Method, q: Quantity| -> Vec<(f64, f64)> {
        res.errors
            .iter()
            .filter(|e| e.method == m && e.quantity == q)
            .map(|e| (e.h, e.error))
            .collect()
    };
    let mut series = Vec::new();
    let curves = [
        ("e_mortar", Method::Mortar, Quantity::Theorem, res.rate(Method::Mortar, Quantity::Theorem), 0),
        ("e_nts", Method::Nts, Quantity::Theorem, None, 1),
        ("D (nts - mortar)", Method::Nts, Quantity::ConeDistance, Some(d_row), 2),
    ];
    for (label, m, q, row, color) in curves {
        series.push(Series {
            label: label.to_string(),
            points: points(m, q),
            markers: true,
            line: row.is_none(),
            color,
            thin: row.is_none(),
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
        "h (max element diameter)",
        "relative, Theorem 3.1's norm",
        &series,
        &[(0.5, "1/2"), (0.75, "3/4"), (1.0, "1")],
    )
}
