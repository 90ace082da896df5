//! The report of `study regularity`: errors.csv and rates.csv (each with a `beta` column),
//! one rate-against-beta plot per quantity with its best uniform-mesh rate, README.md
//! leading with where the cones differ, and each beta's convergence report in `beta-BETA/`.

use super::{Regularity, theorem_applies};
use crate::analytical::singular::Placement;
use crate::contact::Method;
use crate::error::Result;
use crate::io::csv_bytes;
use crate::report::folder::{write, write_folder};
use crate::report::markdown::{Doc, Table};
use crate::report::plot::{self, Series};
use crate::studies::convergence::{RateRow, StudyResult};
use crate::verify::kind::Outcome as KindOutcome;
use crate::verify::rates::Outcome;
use crate::verify::table::MethodLabel;
use crate::verify::quantity::Quantity;
use crate::verify::rates::Verdict;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The quantities the report tabulates and plots, in order.
const QUANTITIES: [Quantity; 5] = [
    Quantity::Theorem,
    Quantity::H1U,
    Quantity::BandStress,
    Quantity::L2Pressure,
    Quantity::ConeDistance,
];

/// How far below its best rate a fitted rate may lie and still follow it: the tolerance of
/// the studies' thresholds, or two standard errors where larger.
pub(crate) const FOLLOW_TOLERANCE: f64 = 0.05;

/// One row of errors.csv.
#[derive(Debug, Serialize)]
struct ErrorRow {
    beta: f64,
    method: String,
    level: usize,
    h: f64,
    dofs: usize,
    quantity: Quantity,
    error: f64,
    wall_s: Option<f64>,
}

/// One row of the regularity study's decomposition.csv: each beta's
/// [`crate::verify::judge::DecompositionRow`].
#[derive(Debug, Serialize)]
struct DecompositionCsv {
    beta: f64,
    method: String,
    quantity: Quantity,
    level: usize,
    h: f64,
    error: f64,
    mortar_error: f64,
    distance: f64,
    pythagorean: f64,
}

/// `method`'s distance to mortar over mortar's error, D / e_mortar, in the theorem norm at
/// a study's finest level.
pub(super) fn finest_ratio(res: &StudyResult, method: Method) -> Option<f64> {
    let finest = res.errors.iter().map(|e| e.level).max()?;
    let d = res.error(method, finest, Quantity::ConeDistance)?;
    Some(d / res.error(Method::reference(), finest, Quantity::Theorem)?)
}

/// One row of the regularity study's rates.csv.
#[derive(Debug, Serialize, Deserialize)]
pub struct RateCsv {
    /// beta: u ~ r^beta at the transition point.
    pub beta: f64,
    /// The cone.
    pub method: MethodLabel,
    /// The quantity.
    pub quantity: Quantity,
    /// The rate in h where the verdict supports one (fitted).
    pub rate: Option<f64>,
    /// Its standard error.
    pub stderr: Option<f64>,
    /// What the errors support.
    pub verdict: Verdict,
    /// The levels of the fit, space separated.
    pub levels_used: String,
    /// Successive rates between neighbouring levels, space separated.
    pub successive: String,
    /// The last judged rate.
    pub last_rate: Option<f64>,
    /// The best rate a uniform P1 mesh can give for this quantity at this beta.
    pub best_rate: Option<f64>,
    /// Whether the rate reaches the best rate (within the tolerance), where both exist.
    pub follows_best: Option<bool>,
    /// Whether Theorem 3.1's hypotheses hold (beta > 1).
    pub theorem_applies: bool,
    /// The study's threshold on the theorem norm.
    pub threshold: Option<f64>,
    /// What it makes of the errors: pass, fail or unverified.
    pub pass: Option<Outcome>,
}

/// The rate a row's verdict supports (fitted), with its standard error.
fn supported(r: &RateRow) -> Option<(f64, f64)> {
    r.supported_fit().map(|f| (f.rate, f.stderr))
}

/// Whether a judged rate follows `best`: by the one rule ([`crate::verify::rates::reaches`]),
/// its fit and its last judged rate both within [`FOLLOW_TOLERANCE`] (or 2 standard errors
/// of the fit, where larger) of it.
fn follows(a: &crate::verify::rates::Assessment, best: f64) -> bool {
    let slack = FOLLOW_TOLERANCE.max(2.0 * a.fit.map_or(0.0, |f| f.stderr));
    crate::verify::rates::reaches(a, best, slack)
}

fn rate_rows(family: &super::Family, beta: f64, res: &StudyResult) -> Vec<RateCsv> {
    res.rates
        .iter()
        .map(|r| {
            let rate = supported(r);
            // The pressure's best rate is measured where the study measures the best
            // approximation on each level (`best_l2_pressure`, in the method's own space):
            // its fitted rate, or none where its own errors support none.
            let best = match (r.quantity, r.method.cone().and_then(|m| res.rate(m, Quantity::BestL2Pressure))) {
                (Quantity::L2Pressure, Some(b)) => supported(b).map(|x| x.0),
                _ => family.best_rate(r.quantity, beta),
            };
            RateCsv {
                beta,
                method: r.method.clone(),
                quantity: r.quantity,
                rate: rate.map(|x| x.0),
                stderr: rate.map(|x| x.1),
                verdict: r.assessment.verdict,
                levels_used: crate::verify::table::join(&r.assessment.used),
                successive: r.assessment.successive_text(),
                last_rate: r.assessment.last_rate(),
                best_rate: best,
                follows_best: rate.zip(best).map(|(_, b)| follows(&r.assessment, b)),
                theorem_applies: theorem_applies(beta),
                threshold: r.threshold.map(|t| t.value()),
                pass: r.outcome,
            }
        })
        .collect()
}

/// A rate cell: the rate and its standard error where supported, else the verdict.
fn cell(r: Option<&RateRow>) -> String {
    super::families::cell(r.map(|r| &r.assessment))
}

impl Regularity {
    /// Whether the family's meshes are graded toward c.
    fn graded(&self) -> bool {
        matches!(self.family.placement, Placement::Graded { .. })
    }

    /// The methods the family's studies solve, in the registry's order.
    pub(super) fn methods(&self) -> Vec<Method> {
        Method::ALL
            .into_iter()
            .filter(|m| self.members.iter().any(|(_, res)| res.file.methods.contains(m)))
            .collect()
    }

    fn row(&self, beta: f64, m: Method, q: Quantity) -> Option<&RateRow> {
        self.members
            .iter()
            .find(|(b, _)| *b == beta)
            .and_then(|(_, res)| res.rate(m, q))
    }

    /// One sentence per beta on the theorem norm: each cone's rate (or its verdict) beside
    /// the best, and nts's distance to mortar against mortar's error at the finest level.
    fn differences(&self) -> Vec<String> {
        self.members
            .iter()
            .map(|(beta, res)| {
                let best = self.family.best_rate(Quantity::Theorem, *beta).expect("a best rate");
                let say = |m: Method| match self.row(*beta, m, Quantity::Theorem) {
                    Some(r) => match supported(r) {
                        Some(x) if follows(&r.assessment, best) => format!("{m} {:.2} (follows)", x.0),
                        Some(x) => {
                            let last = r.assessment.last_rate().unwrap_or(x.0);
                            match last < x.0 {
                                true => format!(
                                    "{m} {:.2}, last judged rate {last:.3} (**{:.2} below**)",
                                    x.0,
                                    best - last
                                ),
                                false => format!("{m} {:.2} (**{:.2} below**)", x.0, best - x.0),
                            }
                        }
                        None => format!(
                            "{m} {}",
                            r.short_text()
                        ),
                    },
                    None => format!("{m} not measured"),
                };
                let dagger = if theorem_applies(*beta) { "" } else { " †" };
                let ratios: Vec<String> = Method::compared(&res.file.methods)
                    .filter_map(|m| finest_ratio(res, m).map(|r| format!("{m} {r:.2}")))
                    .collect();
                let ratio = match ratios.is_empty() {
                    true => String::new(),
                    false => format!("; D / e_{} at the finest level {}", Method::reference(), ratios.join(", ")),
                };
                let which = if self.graded() { "best on graded meshes" } else { "best min(1, beta)" };
                let says: Vec<String> = self.methods().into_iter().map(say).collect();
                format!("beta = {beta}{dagger}: {which} = {best:.2}; {}{ratio}", says.join(", "))
            })
            .collect()
    }

    /// Whether nts's shortfall in the theorem norm follows beta or where its distance to
    /// mortar overtakes mortar's error: the betas where nts's rate is supported and follows
    /// its best, against those where it is not, ordered by D / e_mortar at the finest level.
    fn deficit(&self) -> String {
        let mut rows: Vec<(f64, f64, bool)> = self
            .members
            .iter()
            .filter_map(|(beta, res)| {
                let best = self.family.best_rate(Quantity::Theorem, *beta)?;
                let follows_best = self
                    .row(*beta, Method::Nts, Quantity::Theorem)
                    .is_some_and(|r| follows(&r.assessment, best));
                Some((*beta, finest_ratio(res, Method::Nts)?, follows_best))
            })
            .collect();
        rows.sort_by(|a, b| a.1.total_cmp(&b.1));
        let list = |f: bool| -> String {
            let v: Vec<String> = rows
                .iter()
                .filter(|r| r.2 == f)
                .map(|r| format!("{} ({:.2})", r.0, r.1))
                .collect();
            if v.is_empty() { "none".into() } else { v.join(", ") }
        };
        // Separated by the ratio: every follower below every non-follower.
        let separated = rows
            .iter()
            .filter(|r| r.2)
            .all(|f| rows.iter().filter(|r| !r.2).all(|n| f.1 < n.1));
        let by_beta = {
            let mut b = rows.clone();
            b.sort_by(|x, y| x.0.total_cmp(&y.0));
            let flips = b.windows(2).filter(|w| w[0].2 != w[1].2).count();
            flips <= 1
        };
        let verdict = match (separated, by_beta) {
            (true, false) => "The shortfall follows where its distance to mortar overtakes mortar's error, not beta: every beta where nts's rate follows its best has a smaller D / e_mortar than every beta where it does not",
            (true, true) => "The ratio D / e_mortar separates the betas where nts's rate follows its best from those where it does not, and so does beta itself: these levels cannot tell the two explanations apart",
            (false, true) => "Beta separates the betas where nts's rate follows its best from those where it does not; D / e_mortar does not",
            (false, false) => "Neither beta nor D / e_mortar separates the betas where nts's rate follows its best from those where it does not",
        };
        format!(
            "nts's theorem norm, by D / e_mortar at the finest level (in brackets): follows its best at beta = {}; falls short of it, or is still in transition, at beta = {}. {verdict}.",
            list(true),
            list(false)
        )
    }

    /// The title and the lead paragraph of the family's report.
    fn lead(&self) -> (String, String) {
        let family = self.family;
        let common = "Both cones on a manufactured contact solution whose displacement has a singular part r^beta Phi_l(theta) at the point c where contact ends (src/analytical/singular.rs; the pressure ~ dist^(beta-1), the gap ~ dist^beta), for each beta, measured against the exact solution. The load and the error integrals on the triangles at c split each integrand by power of r, one Gauss-Jacobi rule per power (src/quadrature/singular.rs)";
        let n = family.levels.len();
        match family.placement {
            Placement::Aligned => (
                "regularity: rates against the regularity of the contact transition".into(),
                format!("{common}; c = (0.5871, 1), on {n} levels of uniform refinement with c a node of both meshes."),
            ),
            Placement::Unaligned => (
                "regularity-unaligned: the transition off the mesh nodes".into(),
                format!("{common}; c = (8/15, 1) is a node of neither mesh: at 2/3 of a lower and 1/3 of an upper level-0 trace segment (meshes/two_blocks.geo, the upper line graded by 1.3844 to put it there), so that under halving it sits at 1/3 or 2/3 of its segment on both traces at every level. The triangles with c on an edge and the trace segments holding c are split at c for the load and the error integrals. {n} levels of uniform refinement."),
            ),
            Placement::Graded { mu } => (
                "regularity-graded: meshes graded toward the transition".into(),
                format!("{common}; c = (0.5871, 1), a node of both meshes. Each level is meshed by gmsh with element sizes h_L min(1, (r/R)^(1-mu)) within R = {} of c (floored at h_L^(1/mu) R^(1-1/mu), the size of the elements at c), mu = {mu}: any mu < beta gives the best approximation of r^beta at rate 1 in H1, and 1/2 is below every beta here (meshes/two_blocks_graded.geo; h_L halves from level to level). {n} levels.", crate::analytical::singular::GRADED_RADIUS),
            ),
        }
    }

    /// The table of rates in h, one per method, beside the family's best rates.
    fn rates_table(&self, doc: &mut Doc) {
        let methods = self.methods();
        let names: Vec<&str> = methods.iter().map(|m| m.name()).collect();
        doc.heading(2, &format!("Rates in h, {}, beside the best {} rate", names.join(" / "), if self.graded() { "graded-mesh" } else { "uniform-mesh" }));
        let mut t = Table::new(
            ["beta"]
                .into_iter()
                .map(String::from)
                .chain(QUANTITIES.iter().map(|q| format!("`{q}`"))),
        );
        for (beta, _) in &self.members {
            let dagger = if theorem_applies(*beta) { "" } else { " †" };
            t.row(std::iter::once(format!("{beta}{dagger}")).chain(QUANTITIES.iter().map(|&q| {
                // The nodal methods' best pressure: the reference's space (linear on the trace).
                let best = match (q, self.row(*beta, Method::reference(), Quantity::BestL2Pressure)) {
                    (Quantity::L2Pressure, Some(b)) => format!(" (best measured {})", cell(Some(b))),
                    _ => self.family.best_rate(q, *beta).map_or(String::new(), |b| format!(" (best {b:.2})")),
                };
                let cells: Vec<String> = methods.iter().map(|&m| cell(self.row(*beta, m, q))).collect();
                format!("{}{best}", cells.join(" / "))
            })));
        }
        doc.table(&t);
        if self.graded() {
            doc.paragraph("Best rates on meshes graded with mu < beta: 1 for the H1 and theorem norms and the stress in L2 (the best approximation of r^beta on such meshes); none claimed for the others.");
        }
        doc.paragraph("Best rates on uniform meshes: min(1, beta) for the H1 and theorem norms; min(beta, 3/2) for the stress in the band of triangles along Gamma_C (pointwise h on a band of area O(h), h^(beta-1) on the triangles at c); for the pressure in L2(Gamma_C), the rate of its best approximation measured on each level in the cones' own space (the L2 projection of the exact pressure onto the piecewise-linear functions on the body-1 trace: `best_l2_pressure`; min(beta - 1/2, 2) is only its limit, p ~ dist^(beta-1), which a fit over these levels need not reach). `cone_distance` is the distance between the two cones' solutions on the same meshes (docs/studies.md). A rate is printed only where the verdict supports one (fitted); otherwise the verdict (falling or rising: in transition, with the last successive rate).");
    }

    /// The third method beside the cones, per beta: lac's theorem-norm rate beside
    /// mortar's and nts's, lac's error over mortar's at the finest level, lac's distance to
    /// mortar (rate, and over mortar's error), and lac's pressure rate beside the best a
    /// piecewise-constant profile can reach.
    fn lac_table(&self, doc: &mut Doc) {
        if !self.members.iter().any(|(_, res)| res.file.methods.contains(&Method::Lac)) {
            return;
        }
        let mut t = Table::new([
            "beta",
            "`theorem`: lac / mortar / nts",
            "lac / mortar error, finest level",
            "lac's distance to mortar: rate",
            "over e_mortar, finest level",
            "`l2_pressure`: lac (its best approximation, constant on macro-elements, measured) / mortar",
        ]);
        // On remeshed (graded) levels a fitted rate is shown with the last judged one.
        let cell = |r: Option<&RateRow>| match self.graded() {
            true => super::families::with_last(r.map(|r| &r.assessment)),
            false => cell(r),
        };
        for (beta, res) in &self.members {
            let finest = res.errors.iter().map(|e| e.level).max().unwrap_or(0);
            let theorem = |m: Method| res.error(m, finest, Quantity::Theorem);
            let ratio = |a: Option<f64>, b: Option<f64>| match (a, b) {
                (Some(a), Some(b)) if b > 0.0 => format!("{:.3}", a / b),
                _ => "-".into(),
            };
            // lac's best: the projection onto constants on its macro-elements, measured.
            let best_p0 = match self.row(*beta, Method::Lac, Quantity::BestL2Pressure) {
                Some(b) => format!(
                    "{}; error / best {}",
                    cell(Some(b)),
                    ratio(res.error(Method::Lac, finest, Quantity::L2Pressure), res.error(Method::Lac, finest, Quantity::BestL2Pressure))
                ),
                None => "not measured".into(),
            };
            t.row([
                beta.to_string(),
                format!(
                    "{} / {} / {}",
                    cell(self.row(*beta, Method::Lac, Quantity::Theorem)),
                    cell(self.row(*beta, Method::Mortar, Quantity::Theorem)),
                    cell(self.row(*beta, Method::Nts, Quantity::Theorem))
                ),
                ratio(theorem(Method::Lac), theorem(Method::Mortar)),
                cell(self.row(*beta, Method::Lac, Quantity::ConeDistance)),
                ratio(res.error(Method::Lac, finest, Quantity::ConeDistance), theorem(Method::Mortar)),
                format!(
                    "{} (best {best_p0}) / {}",
                    cell(self.row(*beta, Method::Lac, Quantity::L2Pressure)),
                    cell(self.row(*beta, Method::Mortar, Quantity::L2Pressure))
                ),
            ]);
        }
        doc.heading(2, "The third method: lac beside the cones")
            .paragraph("LAC (Drouet and Hild 2017; docs/methods.md): non-penetration on average over macro-elements of two body-1 segments (three at the end of a piece with an odd count), the pressure constant on each. Its rates in the theorem norm beside mortar's and nts's, its error over mortar's and its distance to mortar's solution on the same meshes, and its pressure rate beside the error and rate of the best approximation of the exact pressure in its own space (constant on each macro-element), measured on every level (`best_l2_pressure`; on uniform meshes its rate tends to min(1, beta - 1/2) from below, p ~ dist^(beta-1), so a fit over these levels is compared with the level's own best, not with that limit).")
            .table(&t);
    }

    fn readme(&self) -> Result<String> {
        let mut doc = Doc::new();
        let (title, lead) = self.lead();
        doc.heading(1, &title);
        doc.paragraph(lead);
        let reports = crate::report::folder::reports_dir();
        let findings = match self.family.placement {
            Placement::Aligned => Vec::new(),
            Placement::Unaligned => {
                super::families::unaligned_findings(self, &reports, &QUANTITIES)?
            }
            Placement::Graded { .. } => super::families::graded_findings(self, &reports)?,
        };
        if !findings.is_empty() {
            doc.heading(2, "What the study learned");
            doc.list(findings);
        }
        doc.heading(2, "What differs between the cones (Theorem 3.1's norm)");
        doc.list(self.differences());
        doc.paragraph(self.deficit());
        match self.family.placement {
            Placement::Aligned => {}
            Placement::Unaligned => {
                super::families::against_aligned(&mut doc, self, &reports, &[Quantity::Theorem, Quantity::L2Pressure, Quantity::ConeDistance])?;
                super::families::parity_section(&mut doc, self, &QUANTITIES);
            }
            Placement::Graded { .. } => {
                super::families::against_uniform(&mut doc, self, &reports, &[Quantity::Theorem, Quantity::H1U, Quantity::ConeDistance])?;
            }
        }
        if self.family.placement != Placement::Aligned {
            super::families::placement_section(&mut doc, self);
        }
        doc.paragraph("D is the distance between the two cones' solutions on the same meshes (`cone_distance`); D - e_mortar <= e_nts <= D + e_mortar, so nts's error tends to D's rate once D overtakes e_mortar. Each beta's report reads each method against its own D (its decomposition.csv and \"Each method read against its distance to mortar\"); `decomposition.csv` here holds every beta's.");
        doc.paragraph("† Theorem 3.1 does not apply: for beta <= 1 the solution is not in H^2 and the body force ~ r^(beta-2) is not in L2 (it lies in V' only). Its rates 3/4 and 1/2 are claimed only for beta > 1; below, the study requires only convergence (rate >= 0).");
        self.rates_table(&mut doc);
        self.lac_table(&mut doc);
        let stalled: Vec<String> = self
            .members
            .iter()
            .flat_map(|(beta, res)| {
                res.rates
                    .iter()
                    .filter(|r| r.assessment.verdict == Verdict::NotConverging)
                    .map(move |r| format!("beta = {beta}: {} `{}`", r.method, r.quantity))
            })
            .collect();
        doc.heading(2, "Did not converge");
        if stalled.is_empty() {
            doc.paragraph("Every quantity converges.");
        } else {
            doc.list(stalled);
        }
        // Where the best rate itself is below the rules' stall threshold, the verdict
        // cannot tell slow convergence from none: the successive rates say which.
        let slow: Vec<String> = self
            .members
            .iter()
            .flat_map(|(beta, res)| {
                QUANTITIES.iter().filter_map(move |&q| {
                    let best = self.family.best_rate(q, *beta).filter(|b| *b < crate::verify::rates::STALLED)?;
                    let successive: Vec<String> = res
                        .file
                        .methods
                        .iter()
                        .map(|&m| format!("{m} {}", res.rate(m, q).map_or("-".into(), |r| r.assessment.successive_text())))
                        .collect();
                    Some(format!(
                        "`{q}` at beta = {beta} (best {best:.2}): successive rates {}",
                        successive.join(", ")
                    ))
                })
            })
            .collect();
        if !slow.is_empty() {
            doc.paragraph(format!(
                "Where the best rate itself lies below the rate rules' stall threshold {}, their verdict \"not converging\" cannot be told from convergence at that rate; the successive rates say which:",
                crate::verify::rates::STALLED
            ));
            doc.list(slow);
        }
        doc.heading(2, "Rate against beta");
        for q in QUANTITIES {
            doc.image(&format!("{q} rate against beta"), &format!("rate_vs_beta_{q}.png"));
        }
        doc.heading(2, "Per beta");
        doc.list(self.members.iter().map(|(beta, res)| {
            format!(
                "beta = {beta}: [beta-{beta:.2}/README.md](beta-{beta:.2}/README.md) ({:.0} s)",
                res.wall_s
            )
        }));
        doc.paragraph(format!("Reproduce: `cargo run --release -- study {}` (the scenes and the per-beta study files are written by `cargo run --release --example regularity_scenes`).", self.family.name));
        Ok(doc.finish())
    }

    fn plots(&self, d: &Path) -> Result<()> {
        for q in QUANTITIES {
            let mut series = Vec::new();
            for m in self.methods() {
                let i = plot::method_style(m);
                let points: Vec<(f64, f64)> = self
                    .members
                    .iter()
                    .filter_map(|(beta, _)| {
                        self.row(*beta, m, q).and_then(supported).map(|r| (*beta, r.0))
                    })
                    .collect();
                if !points.is_empty() {
                    series.push(Series {
                        label: m.to_string(),
                        points,
                        markers: true,
                        line: true,
                        color: i,
                        thin: false,
                        shape: None,
                    });
                }
            }
            // The aligned family's supported rates beside this family's (thin lines).
            if self.family.placement != Placement::Aligned {
                let path = crate::report::folder::reports_dir()
                    .join(super::ALIGNED.name)
                    .join("rates.csv");
                if let Ok(rows) = crate::verify::table::read::<RateCsv>(&path) {
                    for m in self.methods() {
                        let i = plot::method_style(m);
                        let points: Vec<(f64, f64)> = rows
                            .iter()
                            .filter(|r| r.method == m && r.quantity == q)
                            .filter_map(|r| Some((r.beta, r.rate?)))
                            .collect();
                        if !points.is_empty() {
                            series.push(Series {
                                label: format!("{m}, uniform meshes, c a node (regularity)"),
                                points,
                                markers: true,
                                // Markers only: betas without a supported rate are missing.
                                line: false,
                                color: i,
                                thin: true,
                                shape: None,
                            });
                        }
                    }
                }
            }
            if self.family.best_rate(q, 1.0).is_some() {
                let points = (0..=30)
                    .map(|k| 0.5 + 1.5 * k as f64 / 30.0)
                    .filter_map(|b| self.family.best_rate(q, b).map(|r| (b, r)))
                    .collect();
                series.push(Series {
                    label: if self.graded() { "best graded-mesh rate".into() } else { "best uniform-mesh rate".into() },
                    points,
                    markers: false,
                    line: true,
                    // The colour after the methods'.
                    color: Method::ALL.len(),
                    thin: true,
                    shape: None,
                });
            }
            plot::lines(
                &d.join(format!("rate_vs_beta_{q}.png")),
                &format!("{q}: rate in h against beta"),
                "beta",
                "rate",
                &series,
            )?;
        }
        Ok(())
    }
}

impl KindOutcome for Regularity {
    fn write(&self, dir: &Path) -> Result<()> {
        write_folder(dir, |d| {
            let errors: Vec<ErrorRow> = self
                .members
                .iter()
                .flat_map(|(beta, res)| {
                    res.errors.iter().map(move |e| ErrorRow {
                        beta: *beta,
                        method: e.method.to_string(),
                        level: e.level,
                        h: e.h,
                        dofs: e.dofs,
                        quantity: e.quantity,
                        error: e.error,
                        wall_s: e.wall_s,
                    })
                })
                .collect();
            write(d, "errors.csv", &csv_bytes(&errors)?)?;
            let rates: Vec<RateCsv> = self
                .members
                .iter()
                .flat_map(|(beta, res)| rate_rows(self.family, *beta, res))
                .collect();
            write(d, "rates.csv", &csv_bytes(&rates)?)?;
            let decomposition: Vec<DecompositionCsv> = self
                .members
                .iter()
                .flat_map(|(beta, res)| {
                    crate::verify::judge::decomposition(&res.errors)
                        .into_iter()
                        .map(move |r| DecompositionCsv {
                            beta: *beta,
                            method: r.method.to_string(),
                            quantity: r.quantity,
                            level: r.level,
                            h: r.h,
                            error: r.error,
                            mortar_error: r.mortar_error,
                            distance: r.distance,
                            pythagorean: r.pythagorean,
                        })
                })
                .collect();
            write(d, "decomposition.csv", &csv_bytes(&decomposition)?)?;
            write(d, "placement.csv", &csv_bytes(&self.placement)?)?;
            self.plots(d)?;
            for (beta, res) in &self.members {
                crate::studies::convergence::report::write_study(res, &d.join(format!("beta-{beta:.2}")))?;
            }
            if self.family.parity {
                let rows = super::families::parity_rows(self, &QUANTITIES);
                write(d, "parity.csv", &csv_bytes(&rows)?)?;
            }
            write(d, "README.md", self.readme()?.as_bytes())
        })
    }

    fn console(&self, dir: &Path) -> String {
        let mut out = String::new();
        for line in self.differences() {
            out.push_str(&line.replace("**", ""));
            out.push('\n');
        }
        out.push_str(&format!("wrote {}\n", dir.display()));
        out
    }

    fn failures(&self) -> Vec<String> {
        let mut out: Vec<String> = self
            .members
            .iter()
            .flat_map(|(beta, res)| res.failures().into_iter().map(move |f| format!("beta = {beta}: {f}")))
            .collect();
        if self.family.parity {
            out.extend(
                super::families::parity_rows(self, &QUANTITIES)
                    .iter()
                    .filter_map(|r| Some(format!("beta = {}: {}", r.beta, r.failure()?))),
            );
        }
        out
    }

    fn unverified(&self) -> Vec<String> {
        self.members
            .iter()
            .flat_map(|(beta, res)| res.unverified().into_iter().map(move |f| format!("beta = {beta}: {f}")))
            .collect()
    }
}
