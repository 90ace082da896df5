//! The unaligned and graded families' parts of the regularity report: each parity of levels
//! judged on its own, where the transition point sits among the trace nodes, and the rates
//! beside the aligned uniform family's (read from its committed report, reports/regularity).

use super::report::finest_ratio;
use super::{ALIGNED, PlacementRow, Regularity};
use crate::contact::Method;
use crate::error::Result;
use crate::report::markdown::{Doc, Table};
use crate::studies::convergence::StudyResult;
use crate::verify::quantity::Quantity;
use crate::verify::judge::{Threshold, levels_of, levels_of_errors};
use crate::verify::rates::{Assessment, LevelError, Outcome, Verdict, assess, short_text};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The least distance from c to a trace node, over the segment that holds it, that the
/// unaligned family must keep at every level.
pub const LEAST_OFFSET: f64 = 0.125;

/// One (beta, cone, quantity) errors of a study, as the judge reads them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Levels {
    /// Every level.
    All,
    /// Even levels (c at the same fraction of its segment on each).
    Even,
    /// Odd levels.
    Odd,
}

impl Levels {
    fn holds(self, level: usize) -> bool {
        match self {
            Levels::All => true,
            Levels::Even => level % 2 == 0,
            Levels::Odd => level % 2 == 1,
        }
    }
}

/// One row of parity.csv: one cone's quantity judged on a parity of levels.
#[derive(Debug, Serialize, Deserialize)]
pub struct ParityRow {
    /// beta.
    pub beta: f64,
    /// The cone.
    pub method: Method,
    /// The quantity.
    pub quantity: Quantity,
    /// Which levels.
    pub levels: Levels,
    /// The judge's verdict on them.
    pub verdict: Verdict,
    /// The rate in h where the verdict supports one (fitted).
    pub rate: Option<f64>,
    /// Its standard error.
    pub stderr: Option<f64>,
    /// The last successive rate.
    pub last_rate: Option<f64>,
    /// The member's threshold on this quantity for this cone (rate threshold), applied to
    /// this parity's levels as to the whole: c's position alternates with the level, so a
    /// rate must hold on each parity alone. Empty without one.
    #[serde(default)]
    pub threshold: Option<f64>,
    /// What the threshold makes of this parity's errors.
    #[serde(default)]
    pub pass: Option<Outcome>,
}

impl ParityRow {
    /// The sentence of a threshold this parity failed (None: it did not fail or has none).
    pub fn failure(&self) -> Option<String> {
        (self.pass == Some(Outcome::Fail)).then(|| {
            let levels = match self.levels {
                Levels::All => "all",
                Levels::Even => "even",
                Levels::Odd => "odd",
            };
            format!(
                "{} {} on the {levels} levels: threshold {:.3} failed ({}, last judged rate {})",
                self.method,
                self.quantity,
                self.threshold.unwrap_or(f64::NAN),
                self.verdict.name(),
                crate::io::fmt3(self.last_rate.unwrap_or(f64::NAN))
            )
        })
    }
}

/// `res`'s errors of cone `m` in `q` on the levels `keep` admits, judged against the exact
/// solution (truth error 0) by the studies' rules.
pub fn judge_levels(
    res: &StudyResult,
    m: Method,
    q: Quantity,
    keep: impl Fn(usize) -> bool,
) -> Option<Assessment> {
    let rows: Vec<&crate::verify::table::ErrorRecord> = res
        .errors
        .iter()
        .filter(|e| e.method == m && e.quantity == q && keep(e.level))
        .collect();
    judge_sorted(levels_of_errors(&rows))
}

/// `levels` in level order judged against the exact solution (truth error 0); None for
/// none.
fn judge_sorted(mut levels: Vec<LevelError>) -> Option<Assessment> {
    levels.sort_by_key(|e| e.level);
    (!levels.is_empty()).then(|| assess(&levels, 0.0).ok()).flatten()
}

/// An assessment as a table cell: "rate ± se" where fitted, else the verdict.
pub(super) fn cell(a: Option<&Assessment>) -> String {
    match a {
        Some(a) if a.verdict.supports_rate() => match a.fit {
            Some(f) => format!("{:.3} ± {:.3}", f.rate, f.stderr),
            None => a.verdict.name().into(),
        },
        Some(a) => short_text(a.verdict, a.fit.map(|f| f.rate), a.last_rate()),
        None => "-".into(),
    }
}

/// [`cell`], with the last judged rate beside a fitted one: on meshes remeshed at every
/// level the window's rates scatter, and the fit may lie above the last of them.
pub(super) fn with_last(a: Option<&Assessment>) -> String {
    match (a, a.and_then(Assessment::last_rate)) {
        (Some(x), Some(last)) if x.verdict.supports_rate() => {
            format!("{} (last {last:.3})", cell(a))
        }
        _ => cell(a),
    }
}

/// Every (beta, cone, quantity) of `reg` judged on all levels, the even and the odd ones.
pub fn parity_rows(reg: &Regularity, quantities: &[Quantity]) -> Vec<ParityRow> {
    let mut rows = Vec::new();
    for (beta, res) in &reg.members {
        for &m in &res.file.methods {
            for &q in quantities {
                for levels in [Levels::All, Levels::Even, Levels::Odd] {
                    let Some(a) = judge_levels(res, m, q, |l| levels.holds(l)) else {
                        continue;
                    };
                    let fit = a.fit.filter(|_| a.verdict == Verdict::Fitted);
                    let threshold = res
                        .rates
                        .iter()
                        .find(|r| r.method.cone() == Some(m) && r.quantity == q)
                        .and_then(|r| r.threshold);
                    let pass = match (threshold, levels) {
                        // The whole's outcome is rates.csv's; a parity's is judged here.
                        (Some(t @ Threshold::Rate(_)), Levels::Even | Levels::Odd) => {
                            Some(t.outcome(&a, f64::NAN))
                        }
                        _ => None,
                    };
                    rows.push(ParityRow {
                        beta: *beta,
                        method: m,
                        quantity: q,
                        levels,
                        verdict: a.verdict,
                        rate: fit.map(|f| f.rate),
                        stderr: fit.map(|f| f.stderr),
                        last_rate: a.last_rate(),
                        threshold: pass.and(threshold).map(Threshold::value),
                        pass,
                    });
                }
            }
        }
    }
    rows
}

/// The parity section: a table of verdicts on all, even and odd levels, and where they
/// disagree.
pub fn parity_section(doc: &mut Doc, reg: &Regularity, quantities: &[Quantity]) {
    doc.heading(2, "Each parity of levels judged on its own");
    doc.paragraph("c sits at 1/3 of its segment on even levels of one trace and at 2/3 on odd ones (and the reverse on the other trace), so the errors may alternate with period 2. Each parity (levels 0, 2, 4, 6 and 1, 3, 5, 7: h falls by 4 between neighbours) is judged by the same rules as the whole; a rate the whole supports and a parity does not, or parities that disagree beyond their spread, is the alternation showing.");
    let mut t = Table::new(
        ["beta", "quantity", "cone", "all levels", "even levels", "odd levels"]
            .map(String::from),
    );
    let mut disagree = Vec::new();
    for (beta, res) in &reg.members {
        for &q in quantities {
            for &m in &res.file.methods {
                let [all, even, odd] = [Levels::All, Levels::Even, Levels::Odd]
                    .map(|l| judge_levels(res, m, q, |k| l.holds(k)));
                if all.is_none() {
                    continue;
                }
                let fitted = |a: &Option<Assessment>| {
                    a.as_ref()
                        .filter(|a| a.verdict == Verdict::Fitted)
                        .and_then(|a| a.fit)
                };
                let (fa, fe, fo) = (fitted(&all), fitted(&even), fitted(&odd));
                let gap = match (fe, fo) {
                    (Some(e), Some(o)) => {
                        (e.rate - o.rate).abs() > 0.1f64.max(2.0 * (e.stderr + o.stderr))
                    }
                    _ => false,
                };
                if fa.is_some() != (fe.is_some() && fo.is_some()) || gap {
                    disagree.push(format!(
                        "beta = {beta}, {m} `{q}`: all {}, even {}, odd {}",
                        cell(all.as_ref()),
                        cell(even.as_ref()),
                        cell(odd.as_ref())
                    ));
                }
                t.row([
                    format!("{beta}"),
                    format!("`{q}`"),
                    m.to_string(),
                    cell(all.as_ref()),
                    cell(even.as_ref()),
                    cell(odd.as_ref()),
                ]);
            }
        }
    }
    if disagree.is_empty() {
        doc.paragraph("Both parities and the whole agree everywhere: each supports a rate where the others do, within 0.1 (or two standard errors) of each other.");
    } else {
        doc.paragraph("Where the whole and the parities disagree (a rate supported by one and not the others, or parities apart by more than 0.1 and two standard errors):");
        doc.list(disagree);
    }
    doc.table(&t);
}

/// The placement section: c's distance to the nearest node of each trace over the segment
/// that holds it, per level, beside contact-mms's transition on rates-exact's meshes.
pub fn placement_section(doc: &mut Doc, reg: &Regularity) {
    doc.heading(2, "Where the transition point sits among the trace nodes");
    let first = reg.members.first().map(|(b, _)| reg.family.scene_name(*b));
    let family: Vec<&PlacementRow> = reg
        .placement
        .iter()
        .filter(|r| Some(&r.scene) == first.as_ref())
        .collect();
    let mms: Vec<&PlacementRow> = reg
        .placement
        .iter()
        .filter(|r| r.scene == "contact-mms")
        .collect();
    let members: Vec<&PlacementRow> = reg
        .placement
        .iter()
        .filter(|r| r.scene.starts_with(reg.family.name))
        .collect();
    let least = members
        .iter()
        .map(|r| r.slave_offset.min(r.master_offset))
        .fold(f64::INFINITY, f64::min);
    doc.paragraph(format!(
        "The distance from c to the nearest node of each trace, over the length of the trace segment that holds c (0 at a node, 1/2 at a midpoint), at every level of every beta of this study ({} levels x {} betas; the betas share their meshes): least {least:.4}{}. For comparison, contact-mms's transition a = {} on rates-exact's meshes (described there as no mesh node).",
        reg.family.levels.len(),
        reg.members.len(),
        match reg.family.placement {
            crate::analytical::singular::Placement::Unaligned if least >= LEAST_OFFSET => {
                format!(" (at least {LEAST_OFFSET}: on each trace, c's distance to the nearest node never falls below 1/8 of the segment that holds it, the trace's local h)")
            }
            crate::analytical::singular::Placement::Unaligned => {
                format!(" (**below {LEAST_OFFSET}**)")
            }
            _ => " (c is a node of both meshes)".into(),
        },
        super::CONTACT_MMS_TRANSITION,
    ));
    let mut t = Table::new(
        [
            "level",
            "c: slave offset",
            "c: master offset",
            "contact-mms: slave offset",
            "contact-mms: master offset",
        ]
        .map(String::from),
    );
    let levels: Vec<usize> = family.iter().map(|r| r.level).collect();
    for level in levels {
        let at = |rows: &[&PlacementRow], f: fn(&PlacementRow) -> f64| {
            rows.iter()
                .find(|r| r.level == level)
                .map_or("-".into(), |r| format!("{:.4}", f(r)))
        };
        t.row([
            level.to_string(),
            at(&family, |r| r.slave_offset),
            at(&family, |r| r.master_offset),
            at(&mms, |r| r.slave_offset),
            at(&mms, |r| r.master_offset),
        ]);
    }
    doc.table(&t);
}

/// One row of the aligned study's errors.csv (reports/regularity/errors.csv).
#[derive(Debug, Deserialize)]
struct AlignedError {
    beta: f64,
    method: Method,
    level: usize,
    h: f64,
    dofs: usize,
    quantity: Quantity,
    error: f64,
}

/// The aligned family's errors of cone `m` in `q` at `beta`, judged on the levels `keep`
/// admits.
fn judge_aligned(
    rows: &[AlignedError],
    beta: f64,
    m: Method,
    q: Quantity,
) -> Option<(Assessment, Vec<(usize, f64)>)> {
    let levels = levels_of(
        rows.iter()
            .filter(|e| e.beta == beta && e.method == m && e.quantity == q)
            .map(|e| (e.level, e.h, e.dofs as f64, e.error)),
    );
    let mut errors: Vec<(usize, f64)> = levels.iter().map(|e| (e.level, e.error)).collect();
    errors.sort_by_key(|e| e.0);
    Some((judge_sorted(levels)?, errors))
}

/// The aligned report's errors, if it is there.
fn aligned_errors(reports: &Path) -> Result<Option<Vec<AlignedError>>> {
    let path = reports.join(ALIGNED.name).join("errors.csv");
    if !path.exists() {
        return Ok(None);
    }
    crate::verify::table::read(&path).map(Some)
}

/// The unaligned family beside the aligned one: each cone's verdict on the aligned study's
/// levels (0-5) for both placements, on all of this study's levels, and the ratio of the
/// errors at the aligned study's finest level.
pub fn against_aligned(doc: &mut Doc, reg: &Regularity, reports: &Path, quantities: &[Quantity]) -> Result<()> {
    doc.heading(2, "Against the aligned family (c a node of both meshes)");
    let Some(aligned) = aligned_errors(reports)? else {
        doc.paragraph("reports/regularity/errors.csv is missing: run `cargo run --release -- study regularity` first.");
        return Ok(());
    };
    let finest = super::LEVELS.last().copied().unwrap_or(0);
    doc.paragraph(format!("The aligned study (reports/regularity) measures levels 0-{finest}. Both placements judged on those levels by the same rules, this study also on all of its levels, and the error with c unaligned over the error with c aligned at level {finest} (the meshes differ: the upper trace's grading is 1.3844 here, 1.3 there; c = 8/15 here, 0.5871 there)."));
    let mut t = Table::new(
        [
            "beta",
            "quantity",
            "cone",
            "aligned, levels 0-5",
            "unaligned, levels 0-5",
            "unaligned, all levels",
            "error ratio at level 5",
        ]
        .map(String::from),
    );
    for (beta, res) in &reg.members {
        for &q in quantities {
            for &m in &res.file.methods {
                let Some((a, errors)) = judge_aligned(&aligned, *beta, m, q) else {
                    continue;
                };
                let here = judge_levels(res, m, q, |l| l <= finest);
                let all = judge_levels(res, m, q, |_| true);
                let ratio = res
                    .error(m, finest, q)
                    .zip(errors.iter().find(|e| e.0 == finest).map(|e| e.1))
                    .map_or("-".into(), |(u, a)| format!("{:.3}", u / a));
                t.row([
                    format!("{beta}"),
                    format!("`{q}`"),
                    m.to_string(),
                    cell(Some(&a)),
                    cell(here.as_ref()),
                    cell(all.as_ref()),
                    ratio,
                ]);
            }
        }
    }
    doc.table(&t);
    Ok(())
}

/// The graded family beside the uniform one: rates in h and in dofs of both cones.
pub fn against_uniform(doc: &mut Doc, reg: &Regularity, reports: &Path, quantities: &[Quantity]) -> Result<()> {
    doc.heading(2, "Graded against uniform meshes: rates in h and in dofs");
    let Some(uniform) = aligned_errors(reports)? else {
        doc.paragraph("reports/regularity/errors.csv is missing: run `cargo run --release -- study regularity` first.");
        return Ok(());
    };
    doc.paragraph("A rate in dofs N is the slope of -log(error) against log(N) over the levels of the fit; on uniform meshes it is half the rate in h. On graded meshes the levels are meshed anew by gmsh, not split, and their largest element (far from c) shrinks by uneven steps; the judge's h there is the effective size h_eff = (|Omega| / number of triangles)^(1/2) (levels.csv `h`, beside `h_max`), the size of a uniform mesh with as many triangles, so that a rate in h is twice the rate in triangles. The judge needs no nesting (it reads h and N of each level).");
    let mut t = Table::new(
        [
            "beta",
            "quantity",
            "cone",
            "graded: rate in h",
            "graded: rate in dofs",
            "uniform: rate in h",
            "uniform: rate in dofs",
            "dofs at the finest level, graded / uniform",
        ]
        .map(String::from),
    );
    let dofs_rate = |a: &Assessment| {
        a.fit_dofs
            .filter(|_| a.verdict == Verdict::Fitted)
            .map_or("-".into(), |f| format!("{:.3}", -f.rate))
    };
    for (beta, res) in &reg.members {
        for &q in quantities {
            for &m in &res.file.methods {
                let Some(graded) = judge_levels(res, m, q, |_| true) else {
                    continue;
                };
                let Some((flat, _)) = judge_aligned(&uniform, *beta, m, q) else {
                    continue;
                };
                let finest = reg.family.levels.last().copied().unwrap_or(0);
                let dofs = |rows: Option<usize>, other: Option<usize>| {
                    rows.zip(other)
                        .map_or("-".into(), |(g, u)| format!("{:.2}", g as f64 / u as f64))
                };
                t.row([
                    format!("{beta}"),
                    format!("`{q}`"),
                    m.to_string(),
                    with_last(Some(&graded)),
                    dofs_rate(&graded),
                    with_last(Some(&flat)),
                    dofs_rate(&flat),
                    dofs(
                        res.errors
                            .iter()
                            .find(|e| e.method == m && e.level == finest)
                            .map(|e| e.dofs),
                        uniform
                            .iter()
                            .find(|e| e.beta == *beta && e.method == m && e.level == finest)
                            .map(|e| e.dofs),
                    ),
                ]);
            }
        }
    }
    doc.table(&t);
    Ok(())
}

/// The theorem-norm cell of cone `m` at `beta` in the aligned family's errors, on its levels.
fn aligned_theorem(rows: &[AlignedError], beta: f64, m: Method) -> String {
    judge_aligned(rows, beta, m, Quantity::Theorem).map_or("-".into(), |(a, _)| cell(Some(&a)))
}

/// Per compared method, D / e_mortar at each member's finest level, as a sentence (none
/// where no member measures D).
fn distance_ratios(reg: &Regularity) -> Vec<String> {
    Method::compared(&reg.methods())
        .filter_map(|m| {
            let ratio: Vec<String> = reg
                .members
                .iter()
                .filter_map(|(beta, res)| Some(format!("{:.2} (beta = {beta})", finest_ratio(res, m)?)))
                .collect();
            (!ratio.is_empty()).then(|| {
                format!(
                    "{m}'s distance to {} over its error at the finest level: {}; D's own verdicts are in the table below.",
                    Method::reference(),
                    ratio.join(", ")
                )
            })
        })
        .collect()
}

/// What the unaligned study learned, in a few sentences of numbers: the cones' theorem-norm
/// verdicts beside the aligned family's, mortar's error against the aligned one at its
/// finest level, D / e_mortar, where the parities disagree with the whole, and where c sat.
pub fn unaligned_findings(
    reg: &Regularity,
    reports: &Path,
    quantities: &[Quantity],
) -> Result<Vec<String>> {
    let aligned = aligned_errors(reports)?.unwrap_or_default();
    let finest = super::LEVELS.last().copied().unwrap_or(0);
    let mut out = Vec::new();
    let per_beta: Vec<String> = reg
        .members
        .iter()
        .map(|(beta, res)| {
            let here = |m: Method| cell(judge_levels(res, m, Quantity::Theorem, |_| true).as_ref());
            let each: Vec<String> = res
                .file
                .methods
                .iter()
                .map(|&m| format!("{m} {} (aligned {})", here(m), aligned_theorem(&aligned, *beta, m)))
                .collect();
            format!("beta = {beta}: {}", each.join(", "))
        })
        .collect();
    out.push(format!(
        "Theorem norm, this study's levels 0-{} against the aligned study's 0-{finest}: {}.",
        reg.family.levels.last().copied().unwrap_or(0),
        per_beta.join("; ")
    ));
    let ratios: Vec<String> = reg
        .members
        .iter()
        .filter_map(|(beta, res)| {
            let (_, errors) = judge_aligned(&aligned, *beta, Method::reference(), Quantity::Theorem)?;
            let a = errors.iter().find(|e| e.0 == finest)?.1;
            Some(format!("{:.3} (beta = {beta})", res.error(Method::reference(), finest, Quantity::Theorem)? / a))
        })
        .collect();
    if !ratios.is_empty() {
        out.push(format!(
            "Whether the unresolved transition adds an error of its own: mortar's theorem-norm error at level {finest} over the aligned family's is {} (the meshes differ in the upper trace's grading and c moves from 0.5871 to 8/15, so a ratio near 1 is the same error).",
            ratios.join(", ")
        ));
    }
    out.extend(distance_ratios(reg));
    let rows = parity_rows(reg, quantities);
    let alternating: Vec<String> = reg
        .members
        .iter()
        .flat_map(|(beta, res)| {
            let rows = &rows;
            res.file.methods.iter().copied().flat_map(move |m| {
                quantities.iter().filter_map(move |&q| {
                    let find = |l: Levels| {
                        rows.iter()
                            .find(|r| r.beta == *beta && r.method == m && r.quantity == q && r.levels == l)
                    };
                    let (all, even, odd) = (find(Levels::All)?, find(Levels::Even)?, find(Levels::Odd)?);
                    let fitted = |r: &ParityRow| r.verdict == Verdict::Fitted;
                    (!fitted(all) && fitted(even) && fitted(odd)).then(|| {
                        format!(
                            "beta = {beta} {m} `{q}` ({:.3} even, {:.3} odd)",
                            even.rate.unwrap_or(f64::NAN),
                            odd.rate.unwrap_or(f64::NAN)
                        )
                    })
                })
            })
        })
        .collect();
    out.push(if alternating.is_empty() {
        "No rate that the whole leaves unsupported is supported by each parity alone.".into()
    } else {
        format!(
            "c's position alternating with the level shows where the whole supports no rate but each parity does (levels 4x apart): {}.",
            alternating.join(", ")
        )
    });
    let least = reg
        .placement
        .iter()
        .filter(|r| r.scene.starts_with(reg.family.name))
        .map(|r| r.slave_offset.min(r.master_offset))
        .fold(f64::INFINITY, f64::min);
    out.push(format!(
        "c stayed {least:.4} of its segment from the nearest node of either trace at every level (at least {LEAST_OFFSET} required)."
    ));
    Ok(out)
}

/// What the graded study learned: each cone's theorem-norm rate in h and in dofs against the
/// uniform family's, and nts's distance to mortar.
pub fn graded_findings(reg: &Regularity, reports: &Path) -> Result<Vec<String>> {
    let uniform = aligned_errors(reports)?.unwrap_or_default();
    let dofs_rate = |a: &Assessment| {
        a.fit_dofs
            .filter(|_| a.verdict == Verdict::Fitted)
            .map_or(String::new(), |f| format!(", {:.3} in dofs", -f.rate))
    };
    let mut out = Vec::new();
    for m in reg.methods() {
        let per_beta: Vec<String> = reg
            .members
            .iter()
            .map(|(beta, res)| {
                let graded = judge_levels(res, m, Quantity::Theorem, |_| true);
                let flat = judge_aligned(&uniform, *beta, m, Quantity::Theorem).map(|x| x.0);
                format!(
                    "beta = {beta}: {}{} (uniform {}{})",
                    with_last(graded.as_ref()),
                    graded.as_ref().map_or(String::new(), dofs_rate),
                    with_last(flat.as_ref()),
                    flat.as_ref().map_or(String::new(), dofs_rate)
                )
            })
            .collect();
        out.push(format!("{m}, theorem norm on graded meshes: {}.", per_beta.join("; ")));
    }
    for m in Method::compared(&reg.methods()) {
        let distance: Vec<String> = reg
            .members
            .iter()
            .map(|(beta, res)| {
                let l = res.errors.iter().map(|e| e.level).max().unwrap_or(0);
                let ratio = finest_ratio(res, m).map_or("-".into(), |r| format!("{r:.2}"));
                format!(
                    "beta = {beta}: D {}, D / e_{} {ratio} at level {l}",
                    cell(judge_levels(res, m, Quantity::ConeDistance, |_| true).as_ref()),
                    Method::reference()
                )
            })
            .collect();
        out.push(format!("{m}'s distance to {} on graded meshes: {}.", Method::reference(), distance.join("; ")));
    }
    out.push("Grading removes the singular part's limit on mortar's rate, not nts's consistency error (nts's distance above).".into());
    Ok(out)
}
