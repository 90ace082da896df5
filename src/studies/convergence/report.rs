//! The report of a convergence study: CSV tables, PNG plots and a README.md, and the lines
//! printed on the console.

use crate::contact::Method;
use crate::error::Result;
use crate::io::{csv_bytes, fmt3};
use crate::report::folder::{write, write_folder};
use crate::report::markdown::{Doc, Table};
use crate::report::plot::{self, Panel, Series};
use crate::studies::convergence::{RateRow, Source, StudyResult, TimeStudy, join};
use crate::verify::quantity::Quantity;
use crate::verify::rates::{self, Verdict};
use crate::verify::study_file::Threshold;
use crate::verify::table::{ErrorRecord, MethodLabel, RateRecord};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;
use crate::verify::kind::Outcome;

/// One row of variants.csv: a variant family's error.
#[derive(Serialize, serde::Deserialize)]
pub(super) struct VariantCsv {
    /// Size of body 1 at level 0 of the family.
    pub coarsest: f64,
    pub method: MethodLabel,
    pub level: usize,
    pub h: f64,
    pub dofs: usize,
    pub quantity: Quantity,
    pub error: f64,
}

impl VariantCsv {
    /// The errors.csv row it was written from (`steps`: the study's; no wall time).
    pub fn record(&self, steps: usize) -> ErrorRecord {
        ErrorRecord {
            method: self.method.clone(),
            level: self.level,
            h: self.h,
            dofs: self.dofs,
            steps,
            quantity: self.quantity,
            error: self.error,
            wall_s: None,
            parameter: None,
        }
    }
}

/// run.toml: what a report holds beyond its CSVs, so that `study NAME --rejudge` can judge
/// its errors again and rewrite it without solving.
#[derive(Serialize, serde::Deserialize)]
pub(super) struct RunFacts {
    /// Total wall time of the run (s).
    pub wall_s: f64,
    /// Level of the profiles and of von_mises.png.
    pub profile_level: usize,
    /// Whether equilibrium fixes the cones' contact resultant.
    pub resultant_fixed: bool,
    /// Gauss points per direction of the exact-error rule (none: a reference solve).
    pub exact_quadrature: Option<usize>,
    /// The reference solve's facts (none: the exact solution).
    pub reference: Option<crate::verify::truth::Reference>,
    /// The truth's own estimated error per quantity name.
    pub truth_errors: std::collections::BTreeMap<String, f64>,
    /// Scene warnings.
    pub warnings: Vec<String>,
    /// The time study's fixed facts (its runs are time.csv).
    pub time: Option<TimeFacts>,
    /// gmsh version, .geo hash, solver, cores, commit.
    pub provenance: std::collections::BTreeMap<String, String>,
}

/// The time study's facts beside time.csv.
#[derive(Serialize, serde::Deserialize)]
pub(super) struct TimeFacts {
    pub scene: String,
    pub method: Method,
    pub level: usize,
    pub h: f64,
    pub dofs: usize,
    pub reference_steps: Option<usize>,
}

impl RunFacts {
    fn of(res: &StudyResult) -> Self {
        RunFacts {
            wall_s: res.wall_s,
            profile_level: res.profile_level,
            resultant_fixed: res.resultant_fixed,
            exact_quadrature: res.exact_quadrature,
            reference: res.reference,
            truth_errors: res
                .truth_errors
                .iter()
                .map(|(q, e)| (q.name().to_string(), *e))
                .collect(),
            warnings: res.warnings.clone(),
            time: res.time_study.as_ref().map(|t| TimeFacts {
                scene: t.scene.clone(),
                method: t.method,
                level: t.level,
                h: t.h,
                dofs: t.dofs,
                reference_steps: t.reference_steps,
            }),
            provenance: res.provenance.clone(),
        }
    }
}

/// "rate >= 0.70" or "error <= 1e-9", with `digits` decimals for a rate.
fn threshold_text(t: Threshold, digits: usize) -> String {
    match t {
        Threshold::Rate(v) => format!("rate >= {v:.digits$}"),
        Threshold::Exact(v) => format!("error <= {v:.0e}"),
    }
}

fn fmt_rate(r: &RateRow) -> String {
    fmt_assessment(&r.assessment)
}

/// A judged rate with its standard error, or the verdict that replaces it.
fn fmt_assessment(a: &rates::Assessment) -> String {
    a.describe()
}

/// Celik's observed order of the last three levels, "(oscillatory)" where it oscillates.
fn fmt_order(r: &RateRow) -> String {
    r.assessment.celik.map_or("-".into(), |c| {
        format!(
            "{:.3}{}",
            c.order,
            if c.oscillatory { " (oscillatory)" } else { "" }
        )
    })
}

/// Write the report of a study into `dir` (normally reports/NAME).
pub fn write_study(res: &StudyResult, dir: &Path) -> Result<()> {
    write_folder(dir, |d| {
        write(d, "errors.csv", &csv_bytes(&res.errors)?)?;
        let rates: Vec<RateRecord> = res.rates.iter().map(RateRow::record).collect();
        write(d, "rates.csv", &csv_bytes(&rates)?)?;
        write(d, "levels.csv", &csv_bytes(&res.levels)?)?;
        write(d, "pressure.csv", &csv_bytes(&res.pressure)?)?;
        write(d, "gap.csv", &csv_bytes(&res.gap)?)?;
        if !res.geometry.is_empty() {
            write(d, "geometry.csv", &csv_bytes(&res.geometry)?)?;
        }
        let facts = toml::to_string(&RunFacts::of(res))
            .map_err(|e| crate::error::Error::input(d.join("run.toml"), "facts", e.to_string()))?;
        write(d, "run.toml", facts.as_bytes())?;
        let decomposition = crate::verify::judge::decomposition(&res.errors);
        if !decomposition.is_empty() {
            write(d, "decomposition.csv", &csv_bytes(&decomposition)?)?;
            let asymptotes = crate::verify::judge::asymptotes(&res.rates, &res.errors);
            write(d, "asymptotes.csv", &csv_bytes(&asymptotes)?)?;
        }
        if !res.variants.is_empty() {
            let rows: Vec<VariantCsv> = res
                .variants
                .iter()
                .flat_map(|v| {
                    v.errors.iter().map(move |e| VariantCsv {
                        coarsest: v.coarsest,
                        method: e.method.clone(),
                        level: e.level,
                        h: e.h,
                        dofs: e.dofs,
                        quantity: e.quantity,
                        error: e.error,
                    })
                })
                .collect();
            write(d, "variants.csv", &csv_bytes(&rows)?)?;
        }
        if let Some(ts) = &res.time_study {
            write(d, "time.csv", &csv_bytes(&ts.runs)?)?;
        }
        plots(res, d)?;
        write(d, "README.md", readme(res).as_bytes())
    })
}

fn plots(res: &StudyResult, d: &Path) -> Result<()> {
    error_vs_h(res, d)?;
    super::distance_report::plot(res, d)?;
    contact_vs_h(res, d)?;
    error_vs_time(res, d)?;
    if let Some(ts) = &res.time_study {
        error_vs_k(res, ts, d)?;
    }
    profiles(res, d)?;
    von_mises(res, d)
}

/// How plots name a quantity.
fn quantity_label(q: Quantity) -> String {
    match q {
        Quantity::Theorem => "theorem norm".into(),
        other => other.name().into(),
    }
}

/// Error against h for the threshold quantity with the fitted lines, and the pressure error.
fn error_vs_h(res: &StudyResult, d: &Path) -> Result<()> {
    let key = res.file.thresholds.quantity;
    let mut series = Vec::new();
    for (i, &m) in res.file.methods.iter().enumerate() {
        let rows: Vec<_> = res
            .errors
            .iter()
            .filter(|r| r.method == m && r.quantity == key)
            .collect();
        let rate = res
            .rates
            .iter()
            .find(|r| r.method == m && r.quantity == key)
            .unwrap();
        // Without a supported rate, the legend says what the errors do instead.
        let verdict = match rate.supported_fit() {
            Some(_) => String::new(),
            None => format!(": {}", rate.short_text()),
        };
        series.push(Series {
            label: format!("{m} ({}){verdict}", quantity_label(key)),
            points: rows.iter().map(|r| (r.h, r.error)).collect(),
            markers: true,
            line: false,
            color: i,
            thin: false,
            shape: None,
        });
        // The study's fitted line over the levels used, from the fit itself.
        if let Some((legend, rate, intercept, hs)) = rate.line(&rows) {
            series.extend(plot::fit_line(format!("{m} {legend}"), rate, intercept, &hs, i));
        }
    }
    let mut pressure_drawn = false;
    for (i, &m) in res.file.methods.iter().enumerate() {
        let pts: Vec<(f64, f64)> = res
            .errors
            .iter()
            .filter(|r| r.method == m && r.quantity == Quantity::L2Pressure)
            .map(|r| (r.h, r.error))
            .collect();
        if !pts.is_empty() {
            pressure_drawn = true;
            series.push(Series {
                label: format!("{m} (contact pressure, L2(Gamma_C))"),
                points: pts,
                markers: true,
                line: true,
                color: i,
                thin: true,
                shape: None,
            });
        }
    }
    plot::loglog(
        &d.join("error_vs_h.png"),
        &format!("{}: error against h", res.name),
        res.scene.refinement.h_axis(),
        // With the pressure's error drawn too, the legend says which is which.
        match pressure_drawn {
            true => "relative error (legend: which quantity)".to_string(),
            false => format!("relative error ({})", quantity_label(key)),
        }
        .as_str(),
        &series,
        &[(0.5, "1/2"), (0.75, "3/4"), (1.0, "1")],
    )
}

/// The time study's error against k, with the fitted slope in the legend.
fn error_vs_k(res: &StudyResult, ts: &TimeStudy, d: &Path) -> Result<()> {
    let mut series = vec![Series {
        label: format!("{} (theorem norm)", ts.method),
        points: ts.runs.iter().map(|r| (r.k, r.error)).collect(),
        markers: true,
        line: false,
        color: 0,
        thin: false,
        shape: None,
    }];
    let a = &ts.assessment;
    let used: Vec<f64> = a.used.iter().map(|&i| ts.runs[i].k).collect();
    if let Some(fit) = a.fit {
        let label = format!(
            "fit: slope {:.2} ± {:.2} ({})",
            fit.rate,
            fit.stderr,
            a.verdict.name()
        );
        series.extend(plot::fit_line(label, fit.rate, fit.intercept, &used, 0));
    }
    plot::loglog(
        &d.join("error_vs_k.png"),
        &format!(
            "{}: error against the time step ({}, level {})",
            res.name, ts.scene, ts.level
        ),
        "k (time step)",
        "relative error (theorem norm)",
        &series,
        &[(1.0, "1")],
    )
}

/// Error against the wall time of each solve (threshold quantity).
fn error_vs_time(res: &StudyResult, d: &Path) -> Result<()> {
    let key = res.file.thresholds.quantity;
    let series: Vec<Series> = res
        .file
        .methods
        .iter()
        .enumerate()
        .map(|(i, &m)| Series {
            label: format!("{m}"),
            points: res
                .errors
                .iter()
                .filter(|r| r.method == m && r.quantity == key)
                .filter_map(|r| Some((r.wall_s?.max(1e-4), r.error)))
                .collect(),
            markers: true,
            line: true,
            color: i,
            thin: false,
            shape: None,
        })
        .collect();
    plot::loglog(
        &d.join("error_vs_time.png"),
        &format!(
            "{}: error against solve time ({} solver)",
            res.name, res.file.solver
        ),
        "wall time of the solve (s)",
        &format!("relative error ({})", quantity_label(key)),
        &series,
        &[],
    )
}

/// Pressure and gap along Gamma_C at T, both cones and the reference.
fn profiles(res: &StudyResult, d: &Path) -> Result<()> {
    for (name, data, ylabel) in [
        ("pressure", &res.pressure, "contact pressure (force/length)"),
        ("gap", &res.gap, "gap g0 - [u.nu] (length; g0 the initial gap, 0 without one)"),
    ] {
        let mut sources: Vec<Source> = res.file.methods.iter().map(|&m| Source::Cone(m)).collect();
        sources.push(if res.reference.is_some() {
            Source::Reference
        } else {
            Source::Exact
        });
        let series: Vec<Series> = sources
            .iter()
            .enumerate()
            .map(|(i, &source)| {
                let mut pts: Vec<(f64, f64)> = data
                    .iter()
                    .filter(|p| p.label == source)
                    .map(|p| (p.x, p.value))
                    .collect();
                pts.sort_by(|a, b| a.0.total_cmp(&b.0));
                // A pressure constant on macro-elements (lac) keeps its jumps: two points at
                // one position, in order.
                let steps = name == "pressure"
                    && matches!(source, Source::Cone(m) if m.piecewise_constant_pressure());
                pts.dedup_by(|a, b| a.0 == b.0 && !(steps && a.1 != b.1));
                let reference = matches!(source, Source::Reference | Source::Exact);
                Series {
                    label: match (source, res.reference) {
                        (Source::Reference, Some(r)) => {
                            format!("reference (level {}, matching)", r.level)
                        }
                        (Source::Exact, _) => "exact solution".into(),
                        _ => format!("{} (level {})", source.name(), res.profile_level),
                    },
                    points: pts,
                    markers: !reference,
                    line: true,
                    // The reference's colour follows the methods' (2 beside two of them).
                    color: if reference { res.file.methods.len().max(2) } else { i },
                    thin: reference,
                    shape: None,
                }
            })
            .collect();
        plot::lines(
            &d.join(format!("{name}.png")),
            &format!(
                "{}: {name} along Gamma_C at T = {}",
                res.name, res.scene.final_time
            ),
            "x along Gamma_C",
            ylabel,
            &series,
        )?;
    }
    Ok(())
}

/// Deformed meshes coloured by von Mises stress.
fn von_mises(res: &StudyResult, d: &Path) -> Result<()> {
    // Rejudged from the CSVs: no solution to draw, the plot is kept as it was.
    if let Some(from) = &res.kept_from {
        let old = from.join("von_mises.png");
        if old.exists() {
            let new = d.join("von_mises.png");
            std::fs::copy(&old, &new).map_err(|e| crate::error::Error::io(new, e))?;
        }
        return Ok(());
    }
    let panels: Vec<Panel> = res
        .deformed
        .iter()
        .map(|m| Panel {
            title: format!("{} (level {})", m.method, res.profile_level),
            triangles: m.triangles.clone(),
            values: m.von_mises.clone(),
            body: m.body.clone(),
            highlight: Vec::new(),
        })
        .collect();
    if !panels.is_empty() {
        let mag = res.deformed[0].magnification;
        plot::field_panels(
            &d.join("von_mises.png"),
            &format!(
                "{}: von Mises stress at T = {}, displacements magnified x{mag:.1}",
                res.name, res.scene.final_time
            ),
            "von Mises stress",
            &panels,
        )?;
    }
    Ok(())
}

/// The README: the study and its scene, what separates the cones, the rates, the errors
/// per level, the truth they are measured against, and the plots.
fn readme(res: &StudyResult) -> String {
    let mut doc = Doc::new();
    title(&mut doc, res);
    super::distance_report::lead(&mut doc, res);
    super::beside_report::lead(&mut doc, res);
    super::lac_report::section(&mut doc, res);
    super::best_report::section(&mut doc, res);
    cones_compared(&mut doc, res);
    super::distance_report::section(&mut doc, res);
    super::beside_report::section(&mut doc, res);
    doc.image("error against h", "error_vs_h.png");
    rates_table(&mut doc, res);
    errors_table(&mut doc, res);
    reference(&mut doc, res);
    alignment(&mut doc, res);
    super::geometry_report::section(&mut doc, res);
    if let Some(ts) = &res.time_study {
        rate_in_time(&mut doc, ts);
    }
    doc.heading(2, "Contact and plasticity at T")
        .image("pressure", "pressure.png")
        .image("gap", "gap.png")
        .image("von Mises", "von_mises.png");
    doc.heading(2, "Cost")
        .image("error against time", "error_vs_time.png");
    provenance(&mut doc, res);
    doc.finish()
}

/// The title, the study's and the scene's descriptions, and how to regenerate the report.
fn title(doc: &mut Doc, res: &StudyResult) {
    crate::report::study_heading(doc, &res.name, &res.description, &res.scene);
    doc.paragraph(format!(
            "Regenerate with `cargo run --release -- study {}` ({:.0} s on this machine, {} cores). Solver `{}`, {} over [0, {}].",
            res.name,
            res.wall_s,
            res.provenance.get("cores").cloned().unwrap_or_default(),
            res.file.solver,
            crate::io::count(res.file.steps, "uniform time step"),
            res.scene.final_time
        ));
}

/// The report's lead: what separates the cones, quantity by quantity, contact quantities
/// first: the error at the finest level and the rate (or why there is none) of each cone,
/// and a sentence per quantity; only quantities whose verdicts compare the cones in every
/// cone ([`Verdict::compares_cones`]), the others named below the table with the reason.
fn cones_compared(doc: &mut Doc, res: &StudyResult) {
    let finest = finest_level(res);
    let against = if res.reference.is_some() {
        "the reference"
    } else {
        "the exact solution"
    };
    let (quantities, left_out) = quantities_compared(res);
    let mut header = vec!["quantity".to_string(), "where".to_string()];
    for m in &res.file.methods {
        header.push(format!("{m}: error at level {finest}"));
        header.push(format!("{m}: rate"));
    }
    let mut table = Table::new(header);
    for &q in &quantities {
        let place = if q.is_contact() { "contact" } else { "bulk" };
        let mut cells = vec![q.to_string(), place.to_string()];
        for &m in &res.file.methods {
            cells.push(finest_error(res, m, q).map_or(String::new(), |e| format!("{e:.3e}")));
            cells.push(rate_row(res, m, q).map_or("n/a".into(), fmt_rate));
        }
        table.row(cells);
    }
    doc.heading(2, "What separates the cones")
        .paragraph(format!(
            "Every quantity against {against}, the contact quantities (on Gamma_C and in the band of triangles touching it) first: the error at level {finest} and the rate in h of each cone."
        ))
        .image("contact quantities against h", "contact_vs_h.png")
        .table(&table);
    if !left_out.is_empty() {
        doc.paragraph(format!(
            "Not compared (no rate the numbers support in some cone, or a quantity that does not measure the cones): {}.",
            left_out.join(", ")
        ));
    }
    fixed_at_a_node(doc, res);
    let reference = Method::reference();
    if res.file.methods.contains(&reference) {
        doc.list(quantities.iter().filter_map(|&q| {
            let sentences: Vec<String> = Method::compared(&res.file.methods)
                .filter_map(|m| cones_sentence(res, q, reference, m))
                .collect();
            (!sentences.is_empty())
                .then(|| format!("{q}: {} at level {finest}.", sentences.join("; ")))
        }));
    }
}

/// The quantities whose error is fixed at a node (the same on the last levels), each with
/// its value and the bound the rows' resolution gives it at the finest level (levels.csv
/// `resolution`: the largest macro-element for lac, the largest body-1 segment for the
/// nodal rows, over |Gamma_C|), and whether the error lies within it.
fn fixed_at_a_node(doc: &mut Doc, res: &StudyResult) {
    let finest = finest_level(res);
    let lines: Vec<String> = res
        .rates
        .iter()
        .filter(|r| r.assessment.verdict == crate::verify::rates::Verdict::Fixed)
        .filter_map(|r| {
            let m = r.method.cone()?;
            let e = res.error(m, finest, r.quantity)?;
            let bound = res
                .levels
                .iter()
                .find(|l| l.method == m && l.level == finest)
                .and_then(|l| l.resolution);
            let levels = crate::verify::table::join(
                &res.errors
                    .iter()
                    .filter(|x| x.method == m && x.quantity == r.quantity && (x.error - e).abs() <= crate::verify::rates::FIXED_SPREAD * e)
                    .map(|x| x.level)
                    .collect::<Vec<_>>(),
            );
            Some(match bound {
                Some(b) => format!(
                    "{m} `{}`: {e:.4e} on levels {levels}, {} the rows' resolution at level {finest} ({b:.4e} of |Gamma_C|: {}): a position every level keeps, which falls only once the rows resolve finer than it",
                    r.quantity,
                    if e <= b { "within" } else { "**beyond**" },
                    if m.piecewise_constant_pressure() { "the largest macro-element" } else { "the largest body-1 segment" }
                ),
                None => format!("{m} `{}`: {e:.4e} on levels {levels}", r.quantity),
            })
        })
        .collect();
    if !lines.is_empty() {
        doc.paragraph(format!(
            "Fixed at a node (the same error to {:.0e} on the last levels: not a rate, and not a discretization error that stalls):",
            crate::verify::rates::FIXED_SPREAD
        ))
        .list(lines);
    }
}

/// The finest level of the study.
fn finest_level(res: &StudyResult) -> usize {
    *res.file.mesh.levels.last().expect("levels")
}

/// The rate row of a cone and quantity.
fn rate_row(res: &StudyResult, m: Method, q: Quantity) -> Option<&RateRow> {
    res.rate(m, q)
}

/// The error of a cone and quantity at the finest level.
fn finest_error(res: &StudyResult, m: Method, q: Quantity) -> Option<f64> {
    res.error(m, finest_level(res), q)
}

/// The quantities that compare the cones, contact quantities first, and the others, each
/// named with every cone's verdict ("l2_u (mortar: ...; nts: ...)").
fn quantities_compared(res: &StudyResult) -> (Vec<Quantity>, Vec<String>) {
    let compared = |q: Quantity| {
        res.file
            .methods
            .iter()
            .all(|&m| rate_row(res, m, q).is_some_and(|r| r.assessment.verdict.compares_cones()))
    };
    // The distances between the cones have a section of their own.
    // The best approximation measures the space, not the solution: its own section.
    let quantities: Vec<Quantity> = res
        .file
        .solution_quantities()
        .filter(|q| !q.is_best_approximation())
        .collect();
    let ordered = quantities
        .iter()
        .filter(|q| q.is_contact())
        .chain(quantities.iter().filter(|q| !q.is_contact()))
        .copied();
    let (shown, left_out): (Vec<Quantity>, Vec<Quantity>) = ordered.partition(|&q| compared(q));
    let left_out = left_out
        .into_iter()
        .map(|q| {
            let why: Vec<String> = res
                .file
                .methods
                .iter()
                .filter_map(|&m| rate_row(res, m, q).map(|r| format!("{m}: {}", fmt_rate(r))))
                .collect();
            format!("{q} ({})", why.join("; "))
        })
        .collect();
    (shown, left_out)
}

/// How `other` compares with `reference` in one quantity at the finest level, from their
/// errors and verdicts (None where a cone has no error there).
fn cones_sentence(res: &StudyResult, q: Quantity, reference: Method, other: Method) -> Option<String> {
    let a = finest_error(res, reference, q)?;
    let b = finest_error(res, other, q)?;
    let verdict = |m: Method| rate_row(res, m, q).map(|r| r.assessment.verdict);
    let floor = rates::ROUNDOFF;
    let (r, o) = (reference, other);
    Some(match (verdict(reference), verdict(other)) {
        (Some(Verdict::RoundOff), Some(Verdict::RoundOff)) => {
            format!("{r} and {o} are exact (round-off)")
        }
        (Some(Verdict::RoundOff), _) => {
            format!("{r} is exact (round-off); {o}'s error is {b:.3e}")
        }
        (_, Some(Verdict::RoundOff)) => {
            format!("{o} is exact (round-off); {r}'s error is {a:.3e}")
        }
        (Some(Verdict::NotConverging), Some(Verdict::NotConverging)) => {
            format!("neither {r} nor {o} converges")
        }
        (_, Some(Verdict::NotConverging)) if b >= a => format!(
            "**{o} does not converge** (stalls at {b:.3e}); {r} reaches {a:.3e}, {:.1}x smaller",
            b / a.max(floor)
        ),
        // The one that does not converge may still be below the other at this level.
        (_, Some(Verdict::NotConverging)) => format!(
            "**{o} does not converge** (at {b:.3e} here); {r}'s error {a:.3e} is {:.1}x larger at this level",
            a / b.max(floor)
        ),
        (Some(Verdict::NotConverging), _) => {
            format!("**{r} does not converge** (stalls at {a:.3e}); {o} reaches {b:.3e}")
        }
        _ if b > 1.5 * a => format!("{o}'s error is {:.2}x {r}'s", b / a.max(floor)),
        _ if a > 1.5 * b => format!("{r}'s error is {:.2}x {o}'s", a / b.max(floor)),
        _ => format!(
            "{o} and {r} agree within a factor 1.5 ({o} / {r} = {:.3})",
            b / a.max(floor)
        ),
    })
}

/// How the rates are judged, above the table of rates: the rules' constants read from
/// verify::rates, so that the text cannot drift from the judge.
fn rates_text() -> String {
    use crate::verify::rates::{
        GCI_SAFETY, MIN_FIT_LEVELS, MIN_RATE_SPAN, ROUNDOFF, STALLED, TREND, TRUTH_MARGIN,
        WINDOW_SPREAD, ZERO_RATE_STDERRS,
    };
    format!(
        "Least-squares slope of log(error) against log(h) over the levels used (± standard error), rate against dofs, and successive rates between neighbouring levels, judged by the rules of docs/studies.md#rates on the judged rates (between levels at least {MIN_RATE_SPAN}x apart in h: neighbours of a halving table). A rate never overstates: errors at round-off (<= {ROUNDOFF:.0e}, the solvers' tolerance) are marked and never fitted (their successive rates are `-`), levels within {TRUTH_MARGIN}x of the truth's own error in that quantity are left out, and a rate needs at least {MIN_FIT_LEVELS} levels. A quantity whose last two judged rates average at most {STALLED}, or whose last is negative, does not converge, and so does one whose fitted rate lies within {ZERO_RATE_STDERRS} standard errors of 0. Where the last three judged rates are strictly monotone and differ by more than {TREND} end to end, the rate is `falling` or `rising` (in transition): no rate is claimed, the last judged rate is given. Otherwise the levels used are the longest trailing window (at least {MIN_FIT_LEVELS} levels) whose judged rates lie within {WINDOW_SPREAD} of each other (`fitted`); without one the fit over every level is shown, flagged `pre-asymptotic`. Only `fitted` supports a rate. A threshold passes where the rate is fitted and both the fit and the last judged rate reach it, fails where the last judged rate is below it (for a falling rate, also its extrapolation to the finest level), and is `unverified` otherwise; only a failure makes the study exit non-zero. A contact resultant fixed by equilibrium is named so and never fitted. Beside the fit, the conventions of ASME V&V 20 (Celik et al. 2008, J. Fluids Eng. 130, 078001) on the last three levels: the observed order p (non-uniform ratio, fixed-point iteration), oscillatory convergence named, the GCI of the finest level (safety factor {GCI_SAFETY} at the observed order, in the units of the error) and the asymptotic ratio GCI_coarse / (r^p GCI_fine) at the rate in h printed (1 where that rate describes the last three levels; at the observed order it would be 1 by construction). The `theorem` quantity is max_n (||u - u_ref||_H1 + ||sigma - sigma_ref||_L2) over both bodies, relative to the reference's; Theorem 3.1 predicts h^(3/4) for mortar (K_h^pi) and h^(1/2) for nts (K_h^I) where u is in H^2; it does not cover lac (LAC). Each method's threshold, with the theorem it comes from and its hypotheses, is the study file's (below)."
    )
}

/// ## Rates: every cone and quantity's rate, with how it is judged.
fn rates_table(doc: &mut Doc, res: &StudyResult) {
    let mut table = Table::new([
        "method",
        "quantity",
        "rate in h",
        "levels used",
        "rate in dofs",
        "successive",
        "observed order (last 3)",
        "GCI fine",
        "GCI ratio",
        "threshold",
        "outcome",
    ]);
    for r in &res.rates {
        let a = &r.assessment;
        table.row([
            r.method.to_string(),
            r.quantity.to_string(),
            fmt_rate(r),
            join(&a.used),
            fmt3(r.rate_dofs().unwrap_or(f64::NAN)),
            r.assessment.successive_text(),
            fmt_order(r),
            a.celik
                .map_or("-".into(), |c| format!("{:.2e}", c.gci_fine)),
            a.asymptotic_ratio.map_or("-".into(), |v| format!("{v:.3}")),
            r.threshold
                .map(|t| threshold_text(t, 2))
                .unwrap_or_default(),
            r.outcome.map_or(String::new(), |o| match o {
                rates::Outcome::Fail => "**fail**".into(),
                o => o.name().into(),
            }),
        ]);
    }
    doc.heading(2, "Rates").paragraph(rates_text());
    let held: Vec<String> = res
        .file
        .methods
        .iter()
        .map(|&m| format!("{m}: {}", res.file.thresholds.describe(m)))
        .collect();
    doc.paragraph(format!(
        "Thresholds on `{}` (tolerance {}), from the study file: {}.",
        res.file.thresholds.quantity,
        res.file.thresholds.tolerance,
        held.join("; ")
    ))
    .table(&table);
}

/// ## Errors: per cone and level, the mesh, the errors that matter most and the solve.
fn errors_table(doc: &mut Doc, res: &StudyResult) {
    let mut table = Table::new([
        "method",
        "level",
        "h",
        "dofs",
        "Gamma_C nodes (body 1 / body 2)",
        "theorem",
        "l2_pressure",
        "max_penetration",
        "iterations (max per step)",
        "contact fraction",
        "plastic fraction",
        "solve (s)",
        "fitted",
    ]);
    for l in &res.levels {
        let at_level = |r: &&ErrorRecord| r.method == l.method && r.level == l.level;
        let error = |q: Quantity| {
            res.errors
                .iter()
                .filter(at_level)
                .find(|r| r.quantity == q)
                .map(|r| {
                    if r.error <= rates::ROUNDOFF {
                        format!("{:.3e} (round-off)", r.error)
                    } else {
                        format!("{:.3e}", r.error)
                    }
                })
                .unwrap_or_default()
        };
        let wall = res
            .errors
            .iter()
            .find(at_level)
            .and_then(|r| r.wall_s)
            .unwrap_or(0.0);
        table.row([
            l.method.to_string(),
            l.level.to_string(),
            format!("{:.4}", l.h),
            l.dofs.to_string(),
            format!("{} / {}", l.slave_nodes, l.master_nodes),
            error(Quantity::Theorem),
            error(Quantity::L2Pressure),
            error(Quantity::MaxPenetration),
            format!("{} ({})", l.iterations, l.max_step_iterations),
            format!("{:.3}", l.contact_fraction),
            format!("{:.3}", l.plastic_fraction),
            format!("{wall:.2}"),
            if l.flagged {
                "no (within 5x of the reference error)"
            } else {
                "yes"
            }
            .to_string(),
        ]);
    }
    doc.heading(2, "Errors").table(&table);
}

/// ## Reference (a matching-mesh solve and its own error) or ## Reference: the exact
/// solution (how it is integrated).
fn reference(doc: &mut Doc, res: &StudyResult) {
    match (res.reference, res.exact_quadrature) {
        (Some(r), _) => {
            doc.heading(2, "Reference").paragraph(format!(
                "Matching meshes on Gamma_C (where K_h^pi = K_h^I is conforming), level {} (h = {:.4}, {} dofs, solved in {:.1} s). Its own error in the theorem norm, estimated from the two coarser reference levels with the nested-space model d(L, R)^2 = e_L^2 - e_R^2, e_L = C h^p (fitted p = {:.2}): **{:.3e}** relative. Levels whose error is within a factor 5 of it are left out of the fits.",
                r.level, r.h, r.dofs, r.wall_s, r.error_rate, r.error
            ));
        }
        (None, Some(points)) => {
            doc.heading(2, "Reference: the exact solution").paragraph(format!(
                "Every error is measured against the exact solution of scene `{}` (its `[exact]` table), with no reference solve: integrated on each study mesh by a collapsed Gauss rule of {points} x {points} points per triangle (exact to degree {}) and {} Gauss points per segment of Gamma_C, each triangle or segment that a kink of a piecewise exact field crosses split along the kink and the rule applied on each piece (the loads are integrated the same way, with Dunavant's degree-8 rule). Doubling the rule changes no printed digit (tested).",
                res.scene.name,
                2 * points - 2,
                2 * points
            ));
            let manufactured_viscoplastic = res
                .scene
                .exact
                .as_deref()
                .is_some_and(|e| e.source_rate.is_some());
            if manufactured_viscoplastic {
                doc.paragraph("The scene is a manufactured viscoplastic solution: its constitutive law carries the source s = d sigma/dt - E eps(du/dt) - G(sigma), each triangle's mean (2 x 2 collapsed Gauss rule, split along the kinks) added as k s(t_n) to the backward-Euler update. Where its fields are affine in t (contact-mms-vp), the time-discrete law holds exactly and every error in h is spatial; a t^2 part (contact-mms-vp-time) is what the time study measures.");
            }
        }
        (None, None) => {}
    }
}

/// ## Alignment of the contact edge: the variant families' rates of the contact quantities
/// and their spread, and whether the main family's last successive rates stall.
fn alignment(doc: &mut Doc, res: &StudyResult) {
    if res.variants.is_empty() {
        return;
    }
    let coarsest: Vec<String> = res
        .variants
        .iter()
        .map(|v| v.coarsest.to_string())
        .collect();
    doc.heading(2, "Alignment of the contact edge")
        .paragraph(format!(
            "Nested refinement keeps a contact edge at the same place relative to the nodes every other level, which makes pressure and edge rates stall and jump. The same study on {} further families (body 1's size at level 0: {}; the same ratio and levels; data in `variants.csv`) puts the edge elsewhere. Rates (or verdicts) and successive rates per family:",
            res.variants.len(),
            coarsest.join(", ")
        ))
        .table(&families_table(res));
    doc.list(
        res.file
            .methods
            .iter()
            .filter_map(|&m| stall_verdict(res, m)),
    );
}

/// The main family and the variants: body 1's size at level 0 and the rates.
fn families(res: &StudyResult) -> Vec<(f64, &Vec<RateRow>)> {
    std::iter::once((res.file.mesh.coarsest, &res.rates))
        .chain(res.variants.iter().map(|v| (v.coarsest, &v.rates)))
        .collect()
}

/// Per contact quantity and cone, each family's rate (or verdict) with its successive
/// rates, and the spread of the fitted rates.
fn families_table(res: &StudyResult) -> Table {
    let families = families(res);
    let mut header = vec!["quantity".to_string(), "method".to_string()];
    header.extend(families.iter().map(|(c, _)| format!("h1 = {c}")));
    header.push("spread of the fitted rates".into());
    let mut table = Table::new(header);
    let shown = [
        Quantity::L2Pressure,
        Quantity::PressureWeighted,
        Quantity::ContactEdge,
    ];
    for q in shown.iter().filter(|q| res.file.quantities.contains(q)) {
        for &m in &res.file.methods {
            let rows: Vec<Option<&RateRow>> = families
                .iter()
                .map(|(_, rates)| rates.iter().find(|r| r.method == m && r.quantity == *q))
                .collect();
            let mut cells = vec![q.to_string(), m.to_string()];
            cells.extend(rows.iter().map(|r| {
                r.map_or("-".into(), |r| {
                    format!("{} ({})", r.short_text(), r.assessment.successive_text())
                })
            }));
            // Only rates the verdicts support: a pre-asymptotic fit is no rate to compare.
            let fitted: Vec<f64> = rows
                .iter()
                .flatten()
                .filter(|r| r.assessment.verdict.supports_rate())
                .filter_map(|r| r.assessment.fit.map(|f| f.rate))
                .collect();
            cells.push(spread(&fitted, rows.len()));
            table.row(cells);
        }
    }
    table
}

/// "lo to hi" of at least two rates, else "n/a" with how many of the `families` have one.
fn spread(fitted: &[f64], families: usize) -> String {
    if fitted.len() < 2 {
        return format!("n/a ({} of {families} families fitted)", fitted.len());
    }
    let (lo, hi) = fitted
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    format!("{lo:.2} to {hi:.2}")
}

/// Whether the main family's last successive rate of l2_pressure stalls, against the
/// variants': a stall in some families only is an alignment effect (None without a rate
/// in the main family).
fn stall_verdict(res: &StudyResult, m: Method) -> Option<String> {
    let last = |rates: &Vec<RateRow>| {
        rates
            .iter()
            .find(|r| r.method == m && r.quantity == Quantity::L2Pressure)
            .and_then(|r| r.assessment.successive.last().copied().flatten())
    };
    let main = last(&res.rates)?;
    let others: Vec<f64> = res.variants.iter().filter_map(|v| last(&v.rates)).collect();
    let stalled = |r: f64| r < 0.3;
    let stalling = others.iter().filter(|&&o| stalled(o)).count();
    let verdict = match (stalled(main), stalling) {
        (false, 0) => "no family stalls".to_string(),
        (true, n) if n == others.len() => {
            "every family stalls: not an alignment effect".to_string()
        }
        (_, n) => format!(
            "the stall depends on the family ({} of {} families stall): an alignment effect of the contact edge with the nodes",
            n + stalled(main) as usize,
            others.len() + 1
        ),
    };
    let others: Vec<String> = others.iter().map(|o| format!("{o:.3}")).collect();
    Some(format!(
        "{m} l2_pressure, last successive rate (below 0.3: stalled): {main:.3} in the main family, {} in the variants: {verdict}.",
        others.join(", "),
    ))
}

/// ## Rate in time: the runs, the truth they are measured against, and the judged rate.
fn rate_in_time(doc: &mut Doc, ts: &TimeStudy) {
    let truth = match ts.reference_steps {
        Some(r) => {
            format!("a reference with {r} steps on the same mesh, at the common time points")
        }
        None => format!(
            "the exact solution of scene `{}` at every step (no reference in time)",
            ts.scene
        ),
    };
    let mut table = Table::new([
        "steps",
        "k",
        "theorem error",
        "successive rate",
        "plastic fraction at T",
        "solve (s)",
    ]);
    for (i, r) in ts.runs.iter().enumerate() {
        let rate = i.checked_sub(1).and_then(|j| ts.assessment.successive[j]);
        table.row([
            r.steps.to_string(),
            format!("{:.5}", r.k),
            format!("{:.3e}", r.error),
            rate.map_or("-".into(), |v| format!("{v:.3}")),
            format!("{:.3}", r.plastic_fraction),
            format!("{:.2}", r.wall_s),
        ]);
    }
    let a = &ts.assessment;
    let steps: Vec<String> = a
        .used
        .iter()
        .map(|&i| ts.runs[i].steps.to_string())
        .collect();
    doc.heading(2, "Rate in time")
        .paragraph(format!(
            "Scene `{}`, {}, fixed mesh (level {}, h = {:.4}, {} dofs), k halved from run to run, each run against {truth}. Errors are max_n ||e||, relative to the truth's theorem norm max_n (||u||_H1 + ||sigma||_L2) = {:.4e} (this scene's: not the normalization of a spatial study on another scene). Theorem 3.1 bounds the error by C (h^r + k): backward Euler's k term has rate 1, and as k -> 0 the error tends to this mesh's spatial error. The rate in k is judged as a rate in h is (the same windows and verdicts); data in `time.csv`.",
            ts.scene,
            ts.method,
            ts.level,
            ts.h,
            ts.dofs,
            ts.runs.last().map_or(f64::NAN, |r| r.norm)
        ))
        .image("error against k", "error_vs_k.png")
        .table(&table)
        .paragraph(format!(
            "Rate in k: **{}**, verdict `{}`, fitted on the step counts {} (backward Euler: 1).",
            fmt_assessment(a),
            a.verdict.name(),
            if steps.is_empty() {
                "-".into()
            } else {
                steps.join(", ")
            }
        ));
}

/// ## Provenance: where and how the study ran, the mesh family, and the data files.
fn provenance(doc: &mut Doc, res: &StudyResult) {
    let mesh = &res.file.mesh;
    doc.heading(2, "Provenance")
        .list(
            res.provenance
                .iter()
                .map(|(k, v)| format!("{k}: {v}"))
                .chain(std::iter::once(format!(
                    "mesh family: {} = {} at level 0, h1/h2 = {}, levels {:?}; reference parameters {:?}",
                    mesh.size_parameter_1,
                    mesh.coarsest,
                    mesh.ratio,
                    mesh.levels,
                    res.file.reference.parameters
                ))),
        )
        .line("Data: `errors.csv`, `rates.csv`, `levels.csv`, `pressure.csv`, `gap.csv`.");
}

/// What `study NAME` prints: the rates with their thresholds, the theorem error per level,
/// the reference, and where the report went.
pub fn console(res: &StudyResult, dir: &Path) -> String {
    let mut s = String::new();
    for r in &res.rates {
        let _ = writeln!(s, "{}", r.verdict_line());
    }
    for e in res
        .errors
        .iter()
        .filter(|e| e.quantity == res.file.thresholds.quantity)
    {
        let _ = writeln!(
            s,
            "{} level {} h {:.4} dofs {} error {:.4e} ({:.2} s)",
            e.method,
            e.level,
            e.h,
            e.dofs,
            e.error,
            e.wall_s.unwrap_or(0.0)
        );
    }
    if let Some(ts) = &res.time_study {
        for r in &ts.runs {
            let _ = writeln!(
                s,
                "time study {} level {} steps {} k {:.5} error {:.4e} ({:.2} s)",
                ts.scene, ts.level, r.steps, r.k, r.error, r.wall_s
            );
        }
        let a = &ts.assessment;
        let steps: Vec<usize> = a.used.iter().map(|&i| ts.runs[i].steps).collect();
        let verdict = match (a.verdict, a.fit) {
            (Verdict::Fitted, Some(f)) => format!(
                "rate in k {:.3} ± {:.3}, fitted over {} steps",
                f.rate,
                f.stderr,
                steps.iter().map(|n| n.to_string()).collect::<Vec<_>>().join(", ")
            ),
            _ => format!("no rate in k: {}", a.describe().replace("**", "")),
        };
        let _ = writeln!(
            s,
            "time study: {verdict} (successive rates {})",
            a.successive_text().replace(' ', ", ")
        );
    }
    match res.reference {
        Some(r) => {
            let _ = writeln!(
                s,
                "reference level {} ({} dofs, {:.1} s), estimated error {:.3e} (rate {:.2}); study {:.1} s",
                r.level, r.dofs, r.wall_s, r.error, r.error_rate, res.wall_s
            );
        }
        None => {
            let _ = writeln!(
                s,
                "measured against the exact solution of scene {} (no reference solve); study {:.1} s",
                res.scene.name, res.wall_s
            );
        }
    }
    let _ = writeln!(s, "wrote {}", dir.display());
    s
}

/// The contact quantities against h, both cones (the cones differ only there).
fn contact_vs_h(res: &StudyResult, d: &Path) -> Result<()> {
    // Four quantities: the plot's four colours (penetration is in the table).
    let shown = [
        Quantity::L2Pressure,
        Quantity::PressureWeighted,
        Quantity::ContactEdge,
        Quantity::BandStress,
    ];
    let mut series = Vec::new();
    for (c, &q) in shown.iter().enumerate() {
        for &m in &res.file.methods {
            let points: Vec<(f64, f64)> = res
                .errors
                .iter()
                .filter(|e| e.method == m && e.quantity == q && e.error > rates::ROUNDOFF)
                .map(|e| (e.h, e.error))
                .collect();
            if points.len() >= 2 {
                let rate = res
                    .rates
                    .iter()
                    .find(|r| r.method == m && r.quantity == q)
                    .map_or("n/a".into(), RateRow::short_text);
                series.push(Series::of_quantity(
                    format!("{m} {q}: {rate}"),
                    points,
                    c,
                    plot::method_style(m),
                    plot::method_dashed(m),
                ));
            }
        }
    }
    if series.is_empty() {
        return Ok(());
    }
    plot::loglog(
        &d.join("contact_vs_h.png"),
        &format!(
            "{}: contact quantities against h (colour: quantity, marker: method)",
            res.name
        ),
        res.scene.refinement.h_axis(),
        "relative error",
        &series,
        &[(0.5, "1/2"), (1.0, "1")],
    )
}


/// The kind's outcome writes this report.
impl Outcome for StudyResult {
    fn write(&self, dir: &Path) -> Result<()> {
        write_study(self, dir)
    }
    fn console(&self, dir: &Path) -> String {
        console(self, dir)
    }
    fn warnings(&self) -> &[String] {
        &self.warnings
    }
    fn failures(&self) -> Vec<String> {
        StudyResult::failures(self)
    }
    fn unverified(&self) -> Vec<String> {
        StudyResult::unverified(self)
    }
}
