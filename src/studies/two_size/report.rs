//! The report of a two-size study: grid.csv and fits.csv (computing and plotting joined by
//! them), the error maps over (slave level, master level) with the iso-dofs lines, the
//! one-sided sweeps with their fitted slopes, and a README that answers, per cone and
//! quantity, which mesh limits the error and which body should carry the constraint.

use crate::contact::Method;
use crate::error::Result;
use crate::io::{csv_bytes, fmt3};
use crate::report::folder::{write, write_folder};
use crate::report::markdown::{Doc, Table};
use crate::report::plot::{self, GridPanel, Series};
use crate::studies::two_size::{SizeFit, TwoSizeResult};
use crate::verify::quantity::Quantity;
use crate::verify::rates::{Assessment, ROUNDOFF, Verdict};
use crate::verify::table::{ErrorRecord, join};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;
use crate::verify::kind::Outcome;

/// The quantities drawn as maps.
const MAPPED: [Quantity; 4] = [
    Quantity::Theorem,
    Quantity::L2Pressure,
    Quantity::BandStress,
    Quantity::MaxPenetration,
];

/// One row of fits.csv: one slave choice, cone and quantity, the grid fitted to
/// E = C1 h1^a1 + C2 h2^a2 and the one-sided sweeps.
#[derive(Debug, Serialize, serde::Deserialize)]
pub struct FitRecord {
    /// The body carrying the constraint.
    pub slave: String,
    /// Cone.
    pub method: Method,
    /// Quantity.
    pub quantity: Quantity,
    /// Exponent of h1 (the slave) in E = C1 h1^a1 + C2 h2^a2 (empty without a fit).
    #[serde(with = "crate::io::finite")]
    pub a1: f64,
    /// Its standard error.
    #[serde(with = "crate::io::finite")]
    pub se_a1: f64,
    /// Exponent of h2 (the master).
    #[serde(with = "crate::io::finite")]
    pub a2: f64,
    /// Its standard error.
    #[serde(with = "crate::io::finite")]
    pub se_a2: f64,
    /// C1.
    #[serde(with = "crate::io::finite")]
    pub c1: f64,
    /// C2.
    #[serde(with = "crate::io::finite")]
    pub c2: f64,
    /// Root mean square of the fit's residuals in log(error).
    #[serde(with = "crate::io::finite")]
    pub rms_log_residual: f64,
    /// The study file's consistency exponent of h1 (`two_size.exponents`; empty where no
    /// lemma covers the method).
    pub expected_a1: Option<f64>,
    /// The same of h2.
    pub expected_a2: Option<f64>,
    /// Rate in h1 with the master fixed (empty without a fit).
    #[serde(with = "crate::io::finite")]
    pub rate_h1: f64,
    /// Its standard error.
    #[serde(with = "crate::io::finite")]
    pub stderr_h1: f64,
    /// Slave levels in that fit, space separated.
    pub levels_h1: String,
    /// Its verdict.
    pub verdict_h1: Verdict,
    /// Rate in h2 with the slave fixed (empty without a fit).
    #[serde(with = "crate::io::finite")]
    pub rate_h2: f64,
    /// Its standard error.
    #[serde(with = "crate::io::finite")]
    pub stderr_h2: f64,
    /// Master levels in that fit, space separated.
    pub levels_h2: String,
    /// Its verdict.
    pub verdict_h2: Verdict,
    /// The error with both bodies at the fixed level.
    #[serde(with = "crate::io::finite")]
    pub floor: f64,
    /// C1 h1^a1 at the finest diagonal point.
    #[serde(with = "crate::io::finite")]
    pub term1: f64,
    /// C2 h2^a2 there.
    #[serde(with = "crate::io::finite")]
    pub term2: f64,
    /// Error removed per added dof, refining the slave from the finest diagonal point.
    #[serde(with = "crate::io::finite")]
    pub gain1_per_dof: f64,
    /// The same, refining the master.
    #[serde(with = "crate::io::finite")]
    pub gain2_per_dof: f64,
}

impl FitRecord {
    fn new(f: &SizeFit, expected: Option<[f64; 2]>) -> Self {
        let nan = f64::NAN;
        let fit = f.fit;
        let rate = |a: &Assessment| a.fit.map_or((nan, nan), |x| (x.rate, x.stderr));
        let (r1, s1) = rate(&f.sweeps[0]);
        let (r2, s2) = rate(&f.sweeps[1]);
        FitRecord {
            slave: f.slave.clone(),
            method: f.method,
            quantity: f.quantity,
            a1: fit.map_or(nan, |x| x.a[0]),
            se_a1: fit.map_or(nan, |x| x.se[0]),
            a2: fit.map_or(nan, |x| x.a[1]),
            se_a2: fit.map_or(nan, |x| x.se[1]),
            c1: fit.map_or(nan, |x| x.c[0]),
            c2: fit.map_or(nan, |x| x.c[1]),
            rms_log_residual: fit.map_or(nan, |x| x.rms_log_residual),
            expected_a1: expected.map(|e| e[0]),
            expected_a2: expected.map(|e| e[1]),
            rate_h1: r1,
            stderr_h1: s1,
            levels_h1: join(&f.sweeps[0].used),
            verdict_h1: f.sweeps[0].verdict,
            rate_h2: r2,
            stderr_h2: s2,
            levels_h2: join(&f.sweeps[1].used),
            verdict_h2: f.sweeps[1].verdict,
            floor: f.floor,
            term1: f.terms[0],
            term2: f.terms[1],
            gain1_per_dof: f.gain_per_dof[0],
            gain2_per_dof: f.gain_per_dof[1],
        }
    }
}

/// Write the report of a two-size study into `dir`.
pub fn write_two_size(res: &TwoSizeResult, dir: &Path) -> Result<()> {
    write_folder(dir, |d| {
        write(d, "grid.csv", &csv_bytes(&res.points)?)?;
        let fits: Vec<FitRecord> = res
            .fits
            .iter()
            .map(|f| FitRecord::new(f, res.exponents(f.method)))
            .collect();
        write(d, "fits.csv", &csv_bytes(&fits)?)?;
        for slave in &res.slaves {
            for &method in &res.methods {
                maps(res, slave, method, d)?;
            }
            sweeps(res, slave, d)?;
        }
        write(d, "README.md", readme(res).as_bytes())
    })
}

fn map_file(slave: &str, method: Method) -> String {
    format!("map_{slave}_{method}.png")
}

fn sweep_file(slave: &str) -> String {
    format!("sweeps_{slave}.png")
}

/// Least-squares line ln N = alpha + beta l through the (level, dofs) pairs.
fn dofs_line(pairs: &[(usize, usize)]) -> (f64, f64) {
    let n = pairs.len() as f64;
    let (sx, sy) = pairs.iter().fold((0.0, 0.0), |(a, b), &(l, d)| {
        (a + l as f64, b + (d as f64).ln())
    });
    let (mx, my) = (sx / n, sy / n);
    let (sxx, sxy) = pairs.iter().fold((0.0, 0.0), |(a, b), &(l, d)| {
        let x = l as f64 - mx;
        (a + x * x, b + x * ((d as f64).ln() - my))
    });
    let beta = sxy / sxx.max(f64::MIN_POSITIVE);
    (my - beta * mx, beta)
}

/// The error maps of one slave choice and cone, with the iso-dofs line through every grid
/// diagonal point (N1(l1) + N2(l2) constant, each N_b ~ exp(alpha_b + beta_b l) fitted).
fn maps(res: &TwoSizeResult, slave: &str, method: Method, d: &Path) -> Result<()> {
    let grid = |p: &&crate::studies::two_size::SizePoint| {
        res.levels.contains(&p.slave_level) && res.levels.contains(&p.master_level)
    };
    let theorem: Vec<_> = res
        .of(slave, method, Quantity::Theorem)
        .filter(grid)
        .collect();
    let d1: Vec<(usize, usize)> = theorem.iter().map(|p| (p.slave_level, p.dofs1)).collect();
    let d2: Vec<(usize, usize)> = theorem.iter().map(|p| (p.master_level, p.dofs2)).collect();
    let (a1, b1) = dofs_line(&d1);
    let (a2, b2) = dofs_line(&d2);
    let (lo, hi) = (
        *res.levels.first().expect("levels") as f64,
        *res.levels.last().expect("levels") as f64,
    );
    let lines: Vec<(String, Vec<(f64, f64)>)> = res
        .levels
        .iter()
        .map(|&l| {
            let total = (a1 + b1 * l as f64).exp() + (a2 + b2 * l as f64).exp();
            let pts = (0..=60)
                .filter_map(|i| {
                    let x = lo - 0.5 + (hi - lo + 1.0) * i as f64 / 60.0;
                    let rest = total - (a1 + b1 * x).exp();
                    let y = (rest.ln() - a2) / b2;
                    (rest > 0.0 && y >= lo - 0.5 && y <= hi + 0.5).then_some((x, y))
                })
                .collect();
            (format!("{:.0} dofs", total), pts)
        })
        .collect();
    let panels: Vec<GridPanel> = MAPPED
        .iter()
        .filter(|q| res.quantities.contains(q))
        .map(|&q| GridPanel {
            title: q.name().to_string(),
            cells: res
                .of(slave, method, q)
                .filter(grid)
                .map(|p| (p.slave_level as f64, p.master_level as f64, p.error))
                .collect(),
            lines: lines.clone(),
            roundoff: crate::verify::rates::ROUNDOFF,
        })
        .collect();
    plot::grid_panels(
        &d.join(map_file(slave, method)),
        &format!(
            "{}: relative error over the two mesh levels ({method}, slave '{slave}'); red: iso-dofs",
            res.name
        ),
        "slave level (body 1)",
        "master level (body 2)",
        &panels,
    )
}

/// The one-sided sweeps of one slave choice: the theorem error against the swept body's h,
/// both cones, fitted slopes in the legend.
fn sweeps(res: &TwoSizeResult, slave: &str, d: &Path) -> Result<()> {
    let mut series = Vec::new();
    for (i, &method) in res.methods.iter().enumerate() {
        let f = res
            .fits
            .iter()
            .find(|f| f.slave == slave && f.method == method && f.quantity == Quantity::Theorem)
            .expect("the theorem fit");
        for b in 0..2 {
            let pts: Vec<(f64, f64)> = res
                .of(slave, method, Quantity::Theorem)
                .filter(|p| {
                    if b == 0 {
                        p.master_level == res.fixed && res.levels.contains(&p.slave_level)
                    } else {
                        p.slave_level == res.fixed && res.levels.contains(&p.master_level)
                    }
                })
                .map(|p| (if b == 0 { p.h1 } else { p.h2 }, p.error))
                .collect();
            let a = &f.sweeps[b];
            let slope = a.fit.map_or(a.verdict.name().to_string(), |x| {
                format!(
                    "slope {:.2} ± {:.2} ({})",
                    x.rate,
                    x.stderr,
                    a.verdict.name()
                )
            });
            series.push(Series {
                label: format!(
                    "{method}: {} swept, {} at level {}: {slope}",
                    ["slave", "master"][b],
                    ["master", "slave"][b],
                    res.fixed
                ),
                points: pts,
                markers: true,
                line: true,
                color: 2 * i + b,
                thin: b == 1,
                shape: None,
            });
        }
    }
    plot::loglog(
        &d.join(sweep_file(slave)),
        &format!(
            "{}: one-sided sweeps (slave '{slave}', theorem norm)",
            res.name
        ),
        "h of the swept body",
        "relative error (theorem norm)",
        &series,
        &[(0.5, "1/2"), (0.75, "3/4"), (1.0, "1")],
    )
}

use crate::verify::rates::{FIT_MAX_RMS as FIT_RMS, FIT_MAX_SE as FIT_SE};

/// Exponent `b` of the grid fit, or why the numbers do not support one: a poor fit overall,
/// or a term too small on the grid to identify its exponent.
fn fmt_fit(f: &SizeFit, b: usize) -> String {
    match f.fit {
        None => "no fit".into(),
        Some(x) if x.rms_log_residual > FIT_RMS => {
            format!("poor fit (rms {:.2})", x.rms_log_residual)
        }
        Some(x) if x.se[b].is_nan() || x.se[b] > FIT_SE || !(0.0..6.0).contains(&x.a[b]) => {
            match x.se[b].is_finite() {
                true => format!("not identified ({:.2} ± {:.2})", x.a[b], x.se[b]),
                false => format!("not identified ({:.2}, standard error unbounded)", x.a[b]),
            }
        }
        Some(x) => format!("{:.3} ± {:.3}", x.a[b], x.se[b]),
    }
}

fn fmt_sweep(a: &Assessment) -> String {
    match a.fit {
        Some(x) if a.verdict != Verdict::NotConverging => format!(
            "{:.3} ± {:.3} ({}, levels {})",
            x.rate,
            x.stderr,
            a.verdict.name(),
            join(&a.used)
        ),
        _ => a.verdict.name().to_string(),
    }
}

/// One-sided refinements from the finest grid diagonal point (L, L): the slave refined to
/// the fixed level (fixed, L) and the master refined to it (L, fixed), each gain in error
/// divided by the dofs it adds.
struct Refinements {
    /// The error at (L, L).
    base: f64,
    /// The errors with the slave, then the master, refined.
    refined: [f64; 2],
    /// Error gained per added dof: slave, master.
    gain: [f64; 2],
}

/// The one-sided refinements of one slave choice, cone and quantity (None where a point
/// was not measured).
fn refinements(res: &TwoSizeResult, f: &SizeFit) -> Option<Refinements> {
    let finest = *res.levels.last().expect("levels");
    let at = |l: [usize; 2]| {
        res.of(&f.slave, f.method, f.quantity)
            .find(|p| [p.slave_level, p.master_level] == l)
    };
    let base = at([finest, finest])?;
    let s1 = at([res.fixed, finest])?;
    let s2 = at([finest, res.fixed])?;
    Some(Refinements {
        base: base.error,
        refined: [s1.error, s2.error],
        gain: [
            (base.error - s1.error) / (s1.dofs1 as f64 - base.dofs1 as f64),
            (base.error - s2.error) / (s2.dofs2 as f64 - base.dofs2 as f64),
        ],
    })
}

/// The plain answer for one slave choice, cone and quantity, from the measured errors
/// alone ([`Refinements`]): which body's refinement gains more per added dof.
fn answer(res: &TwoSizeResult, f: &SizeFit) -> String {
    let master = res
        .scene
        .bodies
        .iter()
        .map(|b| b.surface.as_str())
        .find(|s| *s != f.slave)
        .unwrap_or("?");
    let finest = *res.levels.last().expect("levels");
    let Some(Refinements {
        base,
        refined,
        gain,
    }) = refinements(res, f)
    else {
        return "not measured".into();
    };
    let names = [
        format!("the slave '{}'", f.slave),
        format!("the master '{master}'"),
    ];
    let better = usize::from(gain[1] > gain[0]);
    if gain[0] <= 0.0 && gain[1] <= 0.0 {
        return format!(
            "from {base:.3e} at ({finest}, {finest}), refining the slave to level {} gives {:.3e}, the master {:.3e}: neither refinement alone reduces it (the error depends on both meshes together)",
            res.fixed, refined[0], refined[1]
        );
    }
    let words = |g: f64, e: f64| {
        if g > 0.0 {
            format!("to {e:.3e}")
        } else {
            format!("not at all ({e:.3e})")
        }
    };
    let factor = if gain[0].min(gain[1]) > 0.0 {
        format!(" ({:.1}x more per dof)", gain[better] / gain[1 - better])
    } else {
        String::new()
    };
    format!(
        "from {base:.3e} at ({finest}, {finest}), refining the slave to level {} brings it {}, the master {}; per added dof {:.2e} against {:.2e}: {} limits the error{factor}",
        res.fixed,
        words(gain[0], refined[0]),
        words(gain[1], refined[1]),
        gain[0],
        gain[1],
        names[better],
    )
}

/// One quantity's agreement of the grid diagonal with the diagonal study.
struct DiagonalAgreement {
    quantity: Quantity,
    /// Diagonal pairs compared (both cones, every level).
    pairs: usize,
    /// Largest relative difference over them.
    largest: f64,
    /// Whether both sides are at round-off in every pair (then they agree to round-off,
    /// not relatively).
    roundoff: bool,
}

/// The diagonal pairs against the diagonal study's errors, per quantity.
fn diagonal_agreement(res: &TwoSizeResult, rows: &[ErrorRecord]) -> Vec<DiagonalAgreement> {
    let slave = &res.scene.bodies[0].surface;
    let mut out = Vec::new();
    for &q in &res.quantities {
        let mut agreement = DiagonalAgreement {
            quantity: q,
            pairs: 0,
            largest: 0.0,
            roundoff: true,
        };
        for &m in &res.methods {
            for &l in &res.levels {
                let (Some(a), Some(b)) = (
                    res.error(slave, m, q, [l, l]),
                    rows.iter()
                        .find(|r| r.method == m && r.level == l && r.quantity == q)
                        .map(|r| r.error),
                ) else {
                    continue;
                };
                if a > ROUNDOFF || b > ROUNDOFF {
                    agreement.roundoff = false;
                    let difference = (a - b).abs() / b.abs().max(f64::MIN_POSITIVE);
                    agreement.largest = agreement.largest.max(difference);
                }
                agreement.pairs += 1;
            }
        }
        if agreement.pairs > 0 {
            out.push(agreement);
        }
    }
    out
}

/// ## The diagonal against the diagonal study: its committed errors on the same meshes.
fn diagonal(doc: &mut Doc, res: &TwoSizeResult) {
    let Some(name) = &res.diagonal else { return };
    let path = crate::report::reports_dir().join(name).join("errors.csv");
    // Without the diagonal study's report there is nothing to compare with.
    let Ok(rows) = crate::verify::table::read::<ErrorRecord>(&path) else {
        return;
    };
    let mut table = Table::new(["quantity", "pairs", "largest relative difference"]);
    for a in diagonal_agreement(res, &rows) {
        let difference = if a.roundoff {
            format!("both at round-off (<= {ROUNDOFF:.0e})")
        } else {
            format!("{:.2e}", a.largest)
        };
        table.row([a.quantity.to_string(), a.pairs.to_string(), difference]);
    }
    doc.heading(2, format!("The diagonal against `{name}`"))
        .paragraph(format!(
            "Where both bodies have the same level the mesh is the diagonal study's (each body split from the same gmsh level-0 mesh; slave '{}'), so its errors must agree with [`reports/{name}`](../{name}/README.md) to the solver tolerance (this study's {} against its own; a quantity taken as the max over the steps may differ where they do). Largest relative difference per quantity over both cones and levels {}:",
            res.scene.bodies[0].surface,
            crate::io::count(res.steps, "time step"),
            join(&res.levels)
        ))
        .table(&table);
}

/// The README: which exponents the grid fits, which mesh limits the error, which body
/// should be the slave, the diagonal against its study, the plots, the truth.
fn readme(res: &TwoSizeResult) -> String {
    let mut doc = Doc::new();
    title(&mut doc, res);
    exponents(&mut doc, res);
    which_mesh_limits(&mut doc, res);
    if res.slaves.len() > 1 {
        which_body_slave(&mut doc, res);
    }
    diagonal(&mut doc, res);
    doc.heading(2, "Maps and sweeps");
    for slave in &res.slaves {
        for &m in &res.methods {
            doc.image(&format!("{m}, slave {slave}"), &map_file(slave, m));
        }
        doc.image(&format!("sweeps, slave {slave}"), &sweep_file(slave));
    }
    truth(&mut doc, res);
    doc.heading(2, "Provenance")
        .list(res.provenance.iter().map(|(k, v)| format!("{k}: {v}")))
        .line("Data: `grid.csv` (every pair and quantity), `fits.csv` (every fit).");
    doc.finish()
}

/// The title, the study's and the scene's descriptions, the grid and how to regenerate it.
fn title(doc: &mut Doc, res: &TwoSizeResult) {
    crate::report::study_heading(doc, &res.name, &res.description, &res.scene);
    doc.paragraph(format!(
            "Regenerate with `cargo run --release -- study {}` ({:.0} s on this machine, {} cores). Grid: every pair of levels {} of the slave (body 1) and the master (body 2); one-sided sweeps: each body over those levels with the other at level {fixed}; and (level {fixed}, level {fixed}) as their floor. Slave choices: {}. {}.",
            res.name,
            res.wall_s,
            res.provenance.get("cores").cloned().unwrap_or_default(),
            join(&res.levels),
            res.slaves.join(", "),
            crate::io::count(res.steps, "time step"),
            fixed = res.fixed
        ));
}

/// ## What differs between the cones: the lead, the exponents per cone and slave against
/// the study file's expected ones, and the one-sided rates.
fn exponents(doc: &mut Doc, res: &TwoSizeResult) {
    let fixed = res.fixed;
    let mut table = Table::new([
        "slave".to_string(),
        "method".into(),
        "quantity".into(),
        "a1 (h1)".into(),
        "a2 (h2)".into(),
        "expected (a1, a2)".into(),
        "rms log residual".into(),
        "rate in h1, master fixed".into(),
        "rate in h2, slave fixed".into(),
        format!("floor ({fixed}, {fixed})"),
    ]);
    let mut rows: Vec<&SizeFit> = res
        .fits
        .iter()
        .filter(|f| MAPPED.contains(&f.quantity))
        .collect();
    rows.sort_by_key(|f| {
        (
            res.slaves.iter().position(|x| *x == f.slave),
            MAPPED.iter().position(|q| *q == f.quantity),
            f.method.name(),
        )
    });
    for f in rows {
        let expected = res
            .exponents(f.method)
            .map_or("none stated".into(), |e| format!("({}, {})", e[0], e[1]));
        table.row([
            f.slave.clone(),
            f.method.to_string(),
            f.quantity.to_string(),
            fmt_fit(f, 0),
            fmt_fit(f, 1),
            expected,
            fmt3(f.fit.map_or(f64::NAN, |x| x.rms_log_residual)),
            fmt_sweep(&f.sweeps[0]),
            fmt_sweep(&f.sweeps[1]),
            format!("{:.3e}", f.floor),
        ]);
    }
    doc.heading(2, "What differs between the cones: exponents in h1 (slave) and h2 (master)")
        .paragraph(format!(
            "Rows of the cones side by side (the quantities mapped below; every quantity in `fits.csv`). The grid fitted to E = C1 h1^a1 + C2 h2^a2 (nonlinear least squares in log space, ± standard errors, rms of the log residuals), beside the consistency exponents the study file gives with their source ({}); the finite elements' own approximation adds h1 + h2 in the theorem norm. The one-sided rates: the slave swept with the master at level {fixed}, the master swept with the slave at level {fixed} (a sweep level within 5x of the error at ({fixed}, {fixed}), which bounds the fixed body's own error, is left out: that is how the fixed level is checked to be fine enough; `too few levels` there means the swept body's error is swamped by that floor from the second level on: its mesh does not limit the error). Thresholds: the fitted a1 of the threshold quantity must reach the study file's rate minus its tolerance where the fit identifies it; per method: {}.",
            exponent_sources(res),
            threshold_claims(res),
        ))
        .table(&table)
        .paragraph(format!(
            "`poor fit`: the grid fit misses the errors by more than 28 % rms (rms log residual > {FIT_RMS}): the additive model does not describe them. Where an error grows when one body alone is refined (below: K_h^I's contact quantities when the master is refined past the slave, whose nodes alone carry the constraint), no sum of two positive terms C1 h1^a1 + C2 h2^a2 can fit it: the error depends on the ratio h1/h2, not on each size separately. `not identified`: a term too small on the grid for its exponent to be measured (standard error > {FIT_SE}), or one alive at a single level of its size (or negligible at every level), which any steeper exponent with a larger constant fits as well (no standard error: J^T J is singular to round-off along that term's constant and exponent; the other exponent's standard error is taken over the directions the data determine)."
        ));
}

/// Each listed method's expected exponents and their source, or that none is stated.
fn exponent_sources(res: &TwoSizeResult) -> String {
    let parts: Vec<String> = res
        .methods
        .iter()
        .map(|&m| match &res.exponents[super::index(m)] {
            Some(e) => format!("{m}: h1^{} + h2^{}, {}", e.slave, e.master, e.source),
            None => format!("{m}: none stated (no lemma covers it)"),
        })
        .collect();
    parts.join("; ")
}

/// Each listed method's threshold as the study file states it.
fn threshold_claims(res: &TwoSizeResult) -> String {
    let parts: Vec<String> = res
        .methods
        .iter()
        .map(|&m| format!("{m} {}", res.threshold_claims[super::index(m)]))
        .collect();
    parts.join("; ")
}

/// ## Which mesh limits the error: the plain answer per slave choice, cone and quantity.
fn which_mesh_limits(doc: &mut Doc, res: &TwoSizeResult) {
    let finest = *res.levels.last().expect("levels");
    doc.heading(2, "Which mesh limits the error")
        .paragraph(format!(
            "Measured, no model: from the finest grid diagonal point (level {finest} for both bodies), the error with the slave refined to level {} and with the master refined to it, each gain divided by the dofs the refinement adds (every quantity in `fits.csv`: the fitted terms C_b h_b^a_b at that point and a_b C_b h_b^a_b / (2 N_b), the model's gain per dof).",
            res.fixed
        ))
        .list(
            res.fits
                .iter()
                .filter(|f| MAPPED.contains(&f.quantity))
                .map(|f| {
                    format!(
                        "{} / {} / {}: {}.",
                        f.slave,
                        f.method,
                        f.quantity,
                        answer(res, f)
                    )
                }),
        );
}

/// ## Which body should be the slave: the same meshes with each body carrying the
/// constraint in turn.
fn which_body_slave(doc: &mut Doc, res: &TwoSizeResult) {
    let finest = *res.levels.last().expect("levels");
    let mut header = vec!["method".to_string(), "quantity".to_string()];
    header.extend(res.slaves.iter().map(|x| format!("slave '{x}'")));
    header.push("smaller error with slave".into());
    let mut table = Table::new(header);
    for &m in &res.methods {
        for &q in &res.quantities {
            let e: Vec<Option<f64>> = res
                .slaves
                .iter()
                .map(|x| res.error(x, m, q, [finest, finest]))
                .collect();
            let shown: Vec<String> = e
                .iter()
                .map(|v| v.map_or("-".into(), |v| format!("{v:.3e}")))
                .collect();
            let best = if e.iter().all(|v| v.is_some_and(|v| v <= ROUNDOFF)) {
                "both at round-off".to_string()
            } else if shown.windows(2).all(|w| w[0] == w[1]) {
                "the same to the digits shown".to_string()
            } else {
                e.iter()
                    .enumerate()
                    .filter_map(|(i, v)| v.map(|v| (i, v)))
                    .min_by(|a, b| a.1.total_cmp(&b.1))
                    .map(|(i, _)| res.slaves[i].clone())
                    .unwrap_or_default()
            };
            let mut cells = vec![m.to_string(), q.to_string()];
            cells.extend(shown);
            cells.push(best);
            table.row(cells);
        }
    }
    doc.heading(2, "Which body should be the slave")
        .paragraph(format!(
            "The same meshes (level {finest} for both bodies) with each body carrying the constraint in turn:"
        ))
        .table(&table);
}

/// ## Truth: the exact solution, or the matching-mesh reference per slave choice.
fn truth(doc: &mut Doc, res: &TwoSizeResult) {
    match (&res.exact_quadrature, res.references.is_empty()) {
        (Some(points), _) => {
            doc.heading(2, "Truth").paragraph(format!(
                "The exact solution of scene `{}`, integrated with {points} x {points} Gauss points per triangle split along its kinks (as in the diagonal exact studies).",
                res.scene.name
            ));
        }
        (None, false) => {
            doc.heading(2, "Truth")
                .paragraph("A reference on matching meshes per slave choice (the bodies are numbered by it):")
                .list(res.references.iter().map(|(slave, r)| {
                    format!(
                        "slave '{slave}': level {} (h = {:.4}, {} dofs, {:.1} s), estimated error {:.3e} in the theorem norm (rate {:.2}).",
                        r.level, r.h, r.dofs, r.wall_s, r.error, r.error_rate
                    )
                }));
        }
        _ => {}
    }
}

/// What `study NAME` prints for a two-size study.
pub fn console(res: &TwoSizeResult, dir: &Path) -> String {
    let mut s = String::new();
    for f in res.fits.iter().filter(|f| f.quantity == Quantity::Theorem) {
        let _ = writeln!(
            s,
            "slave {:6} {:6} theorem: a1 {} a2 {} (expected {}); rate in h1 {}; rate in h2 {}",
            f.slave,
            f.method.name(),
            fmt_fit(f, 0),
            fmt_fit(f, 1),
            res.exponents(f.method)
                .map_or("none stated".into(), |e| format!("({}, {})", e[0], e[1])),
            fmt_sweep(&f.sweeps[0]),
            fmt_sweep(&f.sweeps[1])
        );
    }
    let _ = writeln!(s, "study {:.1} s\nwrote {}", res.wall_s, dir.display());
    s
}

/// The kind's outcome writes this report.
impl Outcome for TwoSizeResult {
    fn write(&self, dir: &Path) -> Result<()> {
        write_two_size(self, dir)
    }
    fn console(&self, dir: &Path) -> String {
        console(self, dir)
    }
    fn warnings(&self) -> &[String] {
        &self.warnings
    }
    fn failures(&self) -> Vec<String> {
        TwoSizeResult::failures(self)
    }
}
