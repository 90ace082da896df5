//! The report of a convergence study: CSV tables, PNG plots and a README.md, and the lines
//! printed on the console.

use crate::contact::Method;
use crate::error::Result;
use crate::io::{csv_bytes, fmt3};
use crate::report::folder::{write, write_folder};
use crate::report::plot::{self, Panel, Series};
use crate::studies::convergence::{RateRow, Source, StudyResult, TimeStudy, join};
use crate::verify::quantity::Quantity;
use crate::verify::rates::{self, Verdict};
use crate::verify::study_file::Threshold;
use crate::verify::table::{MethodLabel, RateRecord};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;

/// One row of variants.csv: a variant family's error.
#[derive(Serialize)]
struct VariantCsv {
    /// Size of body 1 at level 0 of the family.
    coarsest: f64,
    method: MethodLabel,
    level: usize,
    h: f64,
    dofs: usize,
    quantity: Quantity,
    error: f64,
}

/// The row of rates.csv of `r`.
fn rate_record(r: &RateRow) -> RateRecord {
    RateRecord::new(
        r.method.into(),
        r.quantity,
        &r.assessment,
        r.threshold.map(Threshold::value),
        r.pass,
    )
}

fn successive(r: &RateRow) -> String {
    r.assessment
        .successive
        .iter()
        .map(|s| s.map_or("-".into(), |s| format!("{s:.3}")))
        .collect::<Vec<_>>()
        .join(" ")
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
    match (a.verdict, a.fit) {
        (Verdict::Fitted, Some(f)) => format!("{:.3} ± {:.3}", f.rate, f.stderr),
        (Verdict::Drifting, Some(f)) => format!(
            "{:.3} ± {:.3} (drifting: {} over every level)",
            f.rate,
            f.stderr,
            fmt3(a.fit_all.map_or(f64::NAN, |f| f.rate))
        ),
        (Verdict::PreAsymptotic, Some(f)) => {
            format!("{:.3} ± {:.3} (pre-asymptotic)", f.rate, f.stderr)
        }
        (Verdict::RoundOff, _) => format!("exact (round-off, <= {:.0e})", rates::ROUNDOFF),
        (Verdict::NotConverging, _) => "**does not converge**".into(),
        (Verdict::TooFewLevels, _) => format!("no fit (< {} levels)", rates::MIN_FIT_LEVELS),
        (Verdict::FixedByEquilibrium, _) => {
            "fixed by equilibrium: measures the load quadrature".into()
        }
        _ => "n/a".into(),
    }
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
        let rates: Vec<RateRecord> = res.rates.iter().map(rate_record).collect();
        write(d, "rates.csv", &csv_bytes(&rates)?)?;
        write(d, "levels.csv", &csv_bytes(&res.levels)?)?;
        write(d, "pressure.csv", &csv_bytes(&res.pressure)?)?;
        write(d, "gap.csv", &csv_bytes(&res.gap)?)?;
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
        series.push(Series {
            label: format!("{m} ({})", quantity_label(key)),
            points: rows.iter().map(|r| (r.h, r.error)).collect(),
            markers: true,
            line: false,
            color: i,
            thin: false,
        });
        // The study's fitted line over the levels used.
        let used: Vec<f64> = rows
            .iter()
            .filter(|r| rate.assessment.used.contains(&r.level))
            .map(|r| r.h)
            .collect();
        if let Some(fit) = rate.assessment.fit.filter(|_| used.len() >= 2) {
            let hs = [
                used.iter().copied().fold(f64::INFINITY, f64::min),
                used.iter().copied().fold(0.0, f64::max),
            ];
            series.push(Series {
                label: format!("{m} fit: slope {:.2} ± {:.2}", fit.rate, fit.stderr),
                points: hs
                    .iter()
                    .map(|&h| (h, (fit.intercept + fit.rate * h.ln()).exp()))
                    .collect(),
                markers: false,
                line: true,
                color: i,
                thin: false,
            });
        }
    }
    for (i, &m) in res.file.methods.iter().enumerate() {
        let pts: Vec<(f64, f64)> = res
            .errors
            .iter()
            .filter(|r| r.method == m && r.quantity == Quantity::L2Pressure)
            .map(|r| (r.h, r.error))
            .collect();
        if !pts.is_empty() {
            series.push(Series {
                label: format!("{m} (contact pressure, L2(Gamma_C))"),
                points: pts,
                markers: true,
                line: true,
                color: i,
                thin: true,
            });
        }
    }
    plot::loglog(
        &d.join("error_vs_h.png"),
        &format!("{}: error against h", res.name),
        "h (max element diameter)",
        &format!("relative error ({})", quantity_label(key)),
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
    }];
    let a = &ts.assessment;
    let used: Vec<f64> = a.used.iter().map(|&i| ts.runs[i].k).collect();
    if let Some(fit) = a.fit.filter(|_| used.len() >= 2) {
        let ks = [
            used.iter().copied().fold(f64::INFINITY, f64::min),
            used.iter().copied().fold(0.0, f64::max),
        ];
        series.push(Series {
            label: format!(
                "fit: slope {:.2} ± {:.2} ({})",
                fit.rate,
                fit.stderr,
                a.verdict.name()
            ),
            points: ks
                .iter()
                .map(|&k| (k, (fit.intercept + fit.rate * k.ln()).exp()))
                .collect(),
            markers: false,
            line: true,
            color: 0,
            thin: false,
        });
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
                .map(|r| (r.wall_s.max(1e-4), r.error))
                .collect(),
            markers: true,
            line: true,
            color: i,
            thin: false,
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
        ("gap", &res.gap, "normal gap -[u.nu] (length)"),
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
                pts.dedup_by(|a, b| a.0 == b.0);
                let reference =
                    source != Source::Cone(Method::Mortar) && source != Source::Cone(Method::Nts);
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
                    color: if reference { 2 } else { i },
                    thin: reference,
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

fn readme(res: &StudyResult) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Study `{}`\n\n{}\n", res.name, res.description);
    let _ = writeln!(s, "Scene `{}`: {}\n", res.scene.name, res.scene.description);
    let _ = writeln!(
        s,
        "Regenerate with `cargo run --release -- study {}` ({:.0} s on this machine, {} cores). Solver `{}`, {} uniform time steps over [0, {}].\n",
        res.name,
        res.wall_s,
        res.provenance.get("cores").cloned().unwrap_or_default(),
        res.file.solver,
        res.file.steps,
        res.scene.final_time
    );
    cones_compared(&mut s, res);
    let _ = writeln!(s, "![error against h](error_vs_h.png)\n");
    let _ = writeln!(
        s,
        "## Rates\n\nLeast-squares slope of log(error) against log(h) over the levels used (± standard error), rate against dofs, and successive rates between neighbouring levels. A rate never overstates: errors at round-off (<= 1e-10, the solvers' tolerance) are marked and never fitted (their successive rates are `-`), levels within 5x of the truth's own error in that quantity are left out, a rate needs at least 3 levels, and a quantity whose last two successive rates average below 0.15 is called non-converging and given no slope. The levels used are the longest trailing window (at least 3 levels) whose successive rates lie within 0.25 of each other; where even the last two differ by more, the fit over every level is shown, flagged pre-asymptotic. A window's rate that differs from the fit over every level, or from the mean of the last two successive rates, by more than max(0.15, 2 standard errors) is called drifting (the rate is still changing; the all-level fit is given beside it). A contact resultant fixed by equilibrium is named so and never fitted. Beside the fit, the conventions of ASME V&V 20 (Celik et al. 2008, J. Fluids Eng. 130, 078001) on the last three levels: the observed order p (non-uniform ratio, fixed-point iteration), oscillatory convergence named, the GCI of the finest level (safety factor 1.25 at the observed order, in the units of the error) and the asymptotic ratio GCI_coarse / (r^p GCI_fine) at the rate in h printed (1 where that rate describes the last three levels; at the observed order it would be 1 by construction). The `theorem` quantity is max_n (||u - u_ref||_H1 + ||sigma - sigma_ref||_L2) over both bodies, relative to the reference's; Theorem 3.1 predicts h^(3/4) for mortar (K_h^pi) and h^(1/2) for nts (K_h^I).\n"
    );
    let _ = writeln!(
        s,
        "| method | quantity | rate in h | levels used | rate in dofs | successive | observed order (last 3) | GCI fine | GCI ratio | threshold | pass |\n|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for r in &res.rates {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            r.method,
            r.quantity,
            fmt_rate(r),
            join(&r.assessment.used),
            fmt3(r.rate_dofs().unwrap_or(f64::NAN)),
            successive(r),
            fmt_order(r),
            r.assessment
                .celik
                .map_or("-".into(), |c| format!("{:.2e}", c.gci_fine)),
            r.assessment
                .asymptotic_ratio
                .map_or("-".into(), |v| format!("{v:.3}")),
            r.threshold
                .map(|t| threshold_text(t, 2))
                .unwrap_or_default(),
            r.pass
                .map(|p| if p { "yes" } else { "**no**" })
                .unwrap_or("")
        );
    }
    let _ = writeln!(
        s,
        "\n## Errors\n\n| method | level | h | dofs | Gamma_C nodes (body 1 / body 2) | theorem | l2_pressure | max_penetration | iterations (max per step) | contact fraction | plastic fraction | solve (s) | fitted |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for l in &res.levels {
        let e = |q: Quantity| {
            res.errors
                .iter()
                .find(|r| r.method == l.method && r.level == l.level && r.quantity == q)
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
            .find(|r| r.method == l.method && r.level == l.level)
            .map(|r| r.wall_s)
            .unwrap_or(0.0);
        let _ = writeln!(
            s,
            "| {} | {} | {:.4} | {} | {} / {} | {} | {} | {} | {} ({}) | {:.3} | {:.3} | {:.2} | {} |",
            l.method,
            l.level,
            l.h,
            l.dofs,
            l.slave_nodes,
            l.master_nodes,
            e(Quantity::Theorem),
            e(Quantity::L2Pressure),
            e(Quantity::MaxPenetration),
            l.iterations,
            l.max_step_iterations,
            l.contact_fraction,
            l.plastic_fraction,
            wall,
            if l.flagged {
                "no (within 5x of the reference error)"
            } else {
                "yes"
            }
        );
    }
    match (res.reference, res.exact_quadrature) {
        (Some(r), _) => {
            let _ = writeln!(
                s,
                "\n## Reference\n\nMatching meshes on Gamma_C (where K_h^pi = K_h^I is conforming), level {} (h = {:.4}, {} dofs, solved in {:.1} s). Its own error in the theorem norm, estimated from the two coarser reference levels with the nested-space model d(L, R)^2 = e_L^2 - e_R^2, e_L = C h^p (fitted p = {:.2}): **{:.3e}** relative. Levels whose error is within a factor 5 of it are left out of the fits.\n",
                r.level, r.h, r.dofs, r.wall_s, r.error_rate, r.error
            );
        }
        (None, Some(points)) => {
            let _ = writeln!(
                s,
                "\n## Reference: the exact solution\n\nEvery error is measured against the exact solution of scene `{}` (its `[exact]` table), with no reference solve: integrated on each study mesh by a collapsed Gauss rule of {points} x {points} points per triangle (exact to degree {}) and {} Gauss points per segment of Gamma_C, each triangle or segment that a kink of a piecewise exact field crosses split along the kink and the rule applied on each piece (the loads are integrated the same way, with Dunavant's degree-8 rule). Doubling the rule changes no printed digit (tested).\n",
                res.scene.name,
                2 * points - 2,
                2 * points
            );
            if res
                .scene
                .exact
                .as_deref()
                .is_some_and(|e| e.source_rate.is_some())
            {
                let _ = writeln!(
                    s,
                    "The scene is a manufactured viscoplastic solution: its constitutive law carries the source s = d sigma/dt - E eps(du/dt) - G(sigma), each triangle's mean (2 x 2 collapsed Gauss rule, split along the kinks) added as k s(t_n) to the backward-Euler update. Where its fields are affine in t (contact-mms-vp), the time-discrete law holds exactly and every error in h is spatial; a t^2 part (contact-mms-vp-time) is what the time study measures.\n"
                );
            }
        }
        (None, None) => {}
    }
    alignment(&mut s, res);
    if let Some(ts) = &res.time_study {
        time_section(&mut s, ts);
    }
    let _ = writeln!(
        s,
        "## Contact and plasticity at T\n\n![pressure](pressure.png)\n\n![gap](gap.png)\n\n![von Mises](von_mises.png)\n"
    );
    let _ = writeln!(s, "## Cost\n\n![error against time](error_vs_time.png)\n");
    let _ = writeln!(s, "## Provenance\n");
    for (k, v) in &res.provenance {
        let _ = writeln!(s, "- {k}: {v}");
    }
    let _ = writeln!(
        s,
        "- mesh family: {} = {} at level 0, h1/h2 = {}, levels {:?}; reference parameters {:?}",
        res.file.mesh.size_parameter_1,
        res.file.mesh.coarsest,
        res.file.mesh.ratio,
        res.file.mesh.levels,
        res.file.reference.parameters
    );
    let _ = writeln!(
        s,
        "\nData: `errors.csv`, `rates.csv`, `levels.csv`, `pressure.csv`, `gap.csv`."
    );
    s
}

/// The rate in time: the runs, the truth they are measured against, and the judged rate.
fn time_section(s: &mut String, ts: &TimeStudy) {
    let truth = match ts.reference_steps {
        Some(r) => {
            format!("a reference with {r} steps on the same mesh, at the common time points")
        }
        None => format!(
            "the exact solution of scene `{}` at every step (no reference in time)",
            ts.scene
        ),
    };
    let _ = writeln!(
        s,
        "## Rate in time

Scene `{}`, {}, fixed mesh (level {}, h = {:.4}, {} dofs), k halved from run to run, each run against {truth}. Errors are max_n ||e||, relative to the truth's theorem norm max_n (||u||_H1 + ||sigma||_L2) = {:.4e} (this scene's: not the normalization of a spatial study on another scene). Theorem 3.1 bounds the error by C (h^r + k): backward Euler's k term has rate 1, and as k -> 0 the error tends to this mesh's spatial error. The rate in k is judged as a rate in h is (the same windows and verdicts); data in `time.csv`.\n\n![error against k](error_vs_k.png)\n\n| steps | k | theorem error | successive rate | plastic fraction at T | solve (s) |\n|---|---|---|---|---|---|",
        ts.scene,
        ts.method,
        ts.level,
        ts.h,
        ts.dofs,
        ts.runs.last().map_or(f64::NAN, |r| r.norm)
    );
    for (i, r) in ts.runs.iter().enumerate() {
        let rate = i.checked_sub(1).and_then(|j| ts.assessment.successive[j]);
        let _ = writeln!(
            s,
            "| {} | {:.5} | {:.3e} | {} | {:.3} | {:.2} |",
            r.steps,
            r.k,
            r.error,
            rate.map_or("-".into(), |v| format!("{v:.3}")),
            r.plastic_fraction,
            r.wall_s
        );
    }
    let a = &ts.assessment;
    let steps: Vec<String> = a
        .used
        .iter()
        .map(|&i| ts.runs[i].steps.to_string())
        .collect();
    let _ = writeln!(
        s,
        "\nRate in k: **{}**, verdict `{}`, fitted on the step counts {} (backward Euler: 1).\n",
        fmt_assessment(a),
        a.verdict.name(),
        if steps.is_empty() {
            "-".into()
        } else {
            steps.join(", ")
        }
    );
}

/// What `study NAME` prints: the rates with their thresholds, the theorem error per level,
/// the reference, and where the report went.
pub fn console(res: &StudyResult, dir: &Path) -> String {
    let mut s = String::new();
    for r in &res.rates {
        let _ = writeln!(
            s,
            "{:7} {:16} rate {:>6} +- {} (levels {}) {}{}",
            r.method.name(),
            r.quantity.name(),
            fmt3(r.rate()),
            fmt3(r.stderr()),
            join(&r.assessment.used),
            r.assessment.verdict.name(),
            r.threshold
                .map(|t| format!(
                    " threshold {}: {}",
                    threshold_text(t, 3),
                    if r.pass == Some(true) { "pass" } else { "FAIL" }
                ))
                .unwrap_or_default()
        );
    }
    for e in res
        .errors
        .iter()
        .filter(|e| e.quantity == res.file.thresholds.quantity)
    {
        let _ = writeln!(
            s,
            "{} level {} h {:.4} dofs {} error {:.4e} ({:.2} s)",
            e.method, e.level, e.h, e.dofs, e.error, e.wall_s
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
        let _ = writeln!(
            s,
            "time study rate in k {:>6} +- {} (steps {}) {}",
            fmt3(a.fit.map_or(f64::NAN, |f| f.rate)),
            fmt3(a.fit.map_or(f64::NAN, |f| f.stderr)),
            a.used
                .iter()
                .map(|&i| ts.runs[i].steps.to_string())
                .collect::<Vec<_>>()
                .join(" "),
            a.verdict.name()
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
                    .map_or("n/a".into(), verdict_text);
                series.push(Series {
                    label: format!("{m} {q}: {rate}"),
                    points,
                    markers: true,
                    line: true,
                    color: c,
                    thin: m == Method::Nts,
                });
            }
        }
    }
    if series.is_empty() {
        return Ok(());
    }
    plot::loglog(
        &d.join("contact_vs_h.png"),
        &format!(
            "{}: contact quantities against h (thick: mortar, thin: nts)",
            res.name
        ),
        "h (max element diameter)",
        "relative error",
        &series,
        &[(0.5, "1/2"), (1.0, "1")],
    )
}

/// A rate or the verdict that replaces it, short.
fn verdict_text(r: &RateRow) -> String {
    match (r.assessment.verdict, r.assessment.fit) {
        (Verdict::Fitted, Some(f)) => format!("{:.2}", f.rate),
        (Verdict::Drifting, Some(f)) => format!("{:.2} (drifting)", f.rate),
        (Verdict::PreAsymptotic, Some(f)) => format!("{:.2} (pre-asymptotic)", f.rate),
        (Verdict::RoundOff, _) => "exact".into(),
        (Verdict::NotConverging, _) => "does not converge".into(),
        (Verdict::FixedByEquilibrium, _) => "fixed by equilibrium".into(),
        _ => "no fit".into(),
    }
}

/// The report's lead: what separates the cones, quantity by quantity, contact quantities
/// first: the error at the finest level and the rate (or why there is none) of each cone,
/// and a sentence per quantity; only quantities whose verdicts compare the cones in every
/// cone ([`Verdict::compares_cones`]), the others named below the table with the reason.
fn cones_compared(s: &mut String, res: &StudyResult) {
    let finest = *res.file.mesh.levels.last().expect("levels");
    let against = if res.reference.is_some() {
        "the reference"
    } else {
        "the exact solution"
    };
    let rate_of =
        |m: Method, q: Quantity| res.rates.iter().find(|r| r.method == m && r.quantity == q);
    let compared = |q: Quantity| {
        res.file
            .methods
            .iter()
            .all(|&m| rate_of(m, q).is_some_and(|r| r.assessment.verdict.compares_cones()))
    };
    let ordered: Vec<Quantity> = res
        .file
        .quantities
        .iter()
        .copied()
        .filter(|q| q.is_contact())
        .chain(
            res.file
                .quantities
                .iter()
                .copied()
                .filter(|q| !q.is_contact()),
        )
        .collect();
    let quantities: Vec<Quantity> = ordered.iter().copied().filter(|&q| compared(q)).collect();
    let left_out: Vec<String> = ordered
        .iter()
        .copied()
        .filter(|&q| !compared(q))
        .map(|q| {
            let why: Vec<String> = res
                .file
                .methods
                .iter()
                .filter_map(|&m| rate_of(m, q).map(|r| format!("{m}: {}", fmt_rate(r))))
                .collect();
            format!("{q} ({})", why.join("; "))
        })
        .collect();
    let _ = writeln!(
        s,
        "## What separates the cones\n\nEvery quantity against {against}, the contact quantities (on Gamma_C and in the band of triangles touching it) first: the error at level {finest} and the rate in h of each cone.\n\n![contact quantities against h](contact_vs_h.png)\n\n| quantity | where | {} |\n|---|---|{}",
        res.file
            .methods
            .iter()
            .map(|m| format!("{m}: error at level {finest} | {m}: rate"))
            .collect::<Vec<_>>()
            .join(" | "),
        "---|".repeat(2 * res.file.methods.len())
    );
    let error_of = |m: Method, q: Quantity| {
        res.errors
            .iter()
            .find(|e| e.method == m && e.quantity == q && e.level == finest)
            .map(|e| e.error)
    };
    for &q in &quantities {
        let cells: Vec<String> = res
            .file
            .methods
            .iter()
            .map(|&m| {
                let e = error_of(m, q).map_or(String::new(), |e| format!("{e:.3e}"));
                let r = res
                    .rates
                    .iter()
                    .find(|r| r.method == m && r.quantity == q)
                    .map_or("n/a".into(), fmt_rate);
                format!("{e} | {r}")
            })
            .collect();
        let place = if q.is_contact() { "contact" } else { "bulk" };
        let _ = writeln!(s, "| {q} | {place} | {} |", cells.join(" | "));
    }
    if !left_out.is_empty() {
        let _ = writeln!(
            s,
            "\nNot compared (no rate the numbers support in some cone, or a quantity that does not measure the cones): {}.",
            left_out.join(", ")
        );
    }
    if res.file.methods.len() == 2 {
        let _ = writeln!(s);
        let verdict = |m: Method, q: Quantity| {
            res.rates
                .iter()
                .find(|r| r.method == m && r.quantity == q)
                .map(|r| r.assessment.verdict)
        };
        for &q in &quantities {
            let (Some(a), Some(b)) = (error_of(Method::Mortar, q), error_of(Method::Nts, q)) else {
                continue;
            };
            let floor = rates::ROUNDOFF;
            let sentence = match (verdict(Method::Mortar, q), verdict(Method::Nts, q)) {
                (Some(Verdict::RoundOff), Some(Verdict::RoundOff)) => {
                    "both cones are exact (round-off)".to_string()
                }
                (Some(Verdict::RoundOff), _) => {
                    format!("mortar is exact (round-off); nts's error is {b:.3e}")
                }
                (_, Some(Verdict::RoundOff)) => {
                    format!("nts is exact (round-off); mortar's error is {a:.3e}")
                }
                (Some(Verdict::NotConverging), Some(Verdict::NotConverging)) => {
                    "neither cone converges".to_string()
                }
                (_, Some(Verdict::NotConverging)) => format!(
                    "**nts does not converge** (stalls at {b:.3e}); mortar reaches {a:.3e}, {:.1}x smaller",
                    b / a.max(floor)
                ),
                (Some(Verdict::NotConverging), _) => {
                    format!("**mortar does not converge** (stalls at {a:.3e}); nts reaches {b:.3e}")
                }
                _ if b > 1.5 * a => format!("nts's error is {:.2}x mortar's", b / a.max(floor)),
                _ if a > 1.5 * b => format!("mortar's error is {:.2}x nts's", a / b.max(floor)),
                _ => format!(
                    "the cones agree within a factor 1.5 (nts / mortar = {:.3})",
                    b / a.max(floor)
                ),
            };
            let _ = writeln!(s, "- {q}: {sentence} at level {finest}.");
        }
    }
    let _ = writeln!(s);
}

/// The variant families: the rates of the contact quantities per family and their spread,
/// and whether the main family's last successive rates stall.
fn alignment(s: &mut String, res: &StudyResult) {
    if res.variants.is_empty() {
        return;
    }
    let shown = [
        Quantity::L2Pressure,
        Quantity::PressureWeighted,
        Quantity::ContactEdge,
    ];
    let families: Vec<(f64, &Vec<RateRow>)> = std::iter::once((res.file.mesh.coarsest, &res.rates))
        .chain(res.variants.iter().map(|v| (v.coarsest, &v.rates)))
        .collect();
    let _ = writeln!(
        s,
        "## Alignment of the contact edge\n\nNested refinement keeps a contact edge at the same place relative to the nodes every other level, which makes pressure and edge rates stall and jump. The same study on {} further families (body 1's size at level 0: {}; the same ratio and levels; data in `variants.csv`) puts the edge elsewhere. Rates (or verdicts) and successive rates per family:\n\n| quantity | method | {} | spread of the fitted rates |\n|---|---|{}---|",
        res.variants.len(),
        res.variants
            .iter()
            .map(|v| v.coarsest.to_string())
            .collect::<Vec<_>>()
            .join(", "),
        families
            .iter()
            .map(|(c, _)| format!("h1 = {c}"))
            .collect::<Vec<_>>()
            .join(" | "),
        "---|".repeat(families.len())
    );
    for q in shown.iter().filter(|q| res.file.quantities.contains(q)) {
        for &m in &res.file.methods {
            let rows: Vec<Option<&RateRow>> = families
                .iter()
                .map(|(_, rates)| rates.iter().find(|r| r.method == m && r.quantity == *q))
                .collect();
            let cells: Vec<String> = rows
                .iter()
                .map(|r| {
                    r.map_or("-".into(), |r| {
                        format!("{} ({})", verdict_text(r), successive(r))
                    })
                })
                .collect();
            let fitted: Vec<f64> = rows
                .iter()
                .flatten()
                .filter_map(|r| r.assessment.fit.map(|f| f.rate))
                .collect();
            let spread = if fitted.len() >= 2 {
                let (lo, hi) = fitted
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                        (a.min(v), b.max(v))
                    });
                format!("{lo:.2} to {hi:.2}")
            } else {
                "n/a".into()
            };
            let _ = writeln!(s, "| {q} | {m} | {} | {spread} |", cells.join(" | "));
        }
    }
    // The main family's last successive rate against the variants'.
    let last = |rates: &Vec<RateRow>, m: Method| {
        rates
            .iter()
            .find(|r| r.method == m && r.quantity == Quantity::L2Pressure)
            .and_then(|r| r.assessment.successive.last().copied().flatten())
    };
    let _ = writeln!(s);
    for &m in &res.file.methods {
        let main = last(&res.rates, m);
        let others: Vec<f64> = res
            .variants
            .iter()
            .filter_map(|v| last(&v.rates, m))
            .collect();
        if let Some(main) = main {
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
            let _ = writeln!(
                s,
                "- {m} l2_pressure, last successive rate (below 0.3: stalled): {main:.3} in the main family, {} in the variants: {verdict}.",
                others
                    .iter()
                    .map(|o| format!("{o:.3}"))
                    .collect::<Vec<_>>()
                    .join(", "),
            );
        }
    }
    let _ = writeln!(s);
}
