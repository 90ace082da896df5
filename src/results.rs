//! What the committed convergence reports found, read back from their CSVs (rates.csv,
//! errors.csv, ...) through the same row types that wrote them, so that the documentation
//! says what the harness measured and a test can tell when it no longer matches them:
//! [`section`] is the full page docs/results.md (`contact-rates results`), [`headline`] the
//! compact table of README.md (`contact-rates results --headline`).

use crate::contact::Method;
use crate::error::{Error, Result};
use crate::report::markdown::{Doc, Table};
use crate::solve::SolverKind;
use crate::studies::convergence::{LevelInfo, TimeRun};
use crate::studies::regularity::report::RateCsv as RegularityRate;
use crate::studies::speed::report::SpeedRecord;
use crate::studies::stability::StabilityRow;
use crate::studies::two_size::SizePoint;
use crate::studies::two_size::report::FitRecord;
use crate::verify::quantity::Quantity;
use crate::verify::rates::{self, Verdict};
use crate::verify::judge::AsymptoteRow;
use crate::verify::table::{ErrorRecord, RateRecord, read};
use std::path::Path;

/// The convergence studies whose reports the section summarises, with a line on what each
/// measures against.
pub const STUDIES: [(&str, &str); 5] = [
    (
        "rates",
        "the viscoplastic `rates` scene against a matching-mesh reference",
    ),
    (
        "rates-exact",
        "the manufactured `contact-mms` scene against its exact solution",
    ),
    (
        "rates-exact-vp",
        "the manufactured viscoplastic `contact-mms-vp` scene (both bodies flowing) against its exact solution, in h and in k",
    ),
    (
        "patch",
        "paper Test 2 against its exact stress diag(0, -10 t) and pressure 10 t",
    ),
    (
        "crossover",
        "stacked blocks, uniform compression plus 0.2 times an Airy mode, against the exact solution: where nts's h^(1/2) overtakes",
    ),
];

/// The studies of the README's headline table, the exact ones first, with what each is
/// measured against.
pub const HEADLINE: [(&str, &str); 5] = [
    ("rates-exact", "`contact-mms` (elastic), exact solution"),
    (
        "rates-exact-vp",
        "`contact-mms-vp` (both bodies flowing), exact solution",
    ),
    ("patch", "paper Test 2, exact stress and pressure"),
    (
        "crossover",
        "`crossover` (stacked blocks, a small Airy mode), exact solution",
    ),
    ("rates", "`rates` (viscoplastic), matching-mesh reference"),
];

/// The two-size studies whose reports the section summarises.
pub const TWO_SIZE: [(&str, &str); 2] = [
    (
        "two-size-exact",
        "the slave's and the master's mesh refined independently, `contact-mms` against its exact solution",
    ),
    (
        "two-size-rates",
        "the same on the viscoplastic `rates` scene against a matching-mesh reference",
    ),
];

/// Where docs/results.md links to the reports and to the rate rules (relative to docs/).
const DOCS_REPORTS: &str = "../reports";
/// Where README.md links to the reports (relative to the repository's root).
const README_REPORTS: &str = "reports";

/// The cones, in the order the pages name them.
const CONES: [Method; 2] = [Method::Mortar, Method::Nts];
/// A ratio of the cones' errors at the finest level beyond this (either way) separates them.
const SEPARATES: f64 = 1.5;
/// An nts rate within this of 1/2 attains K_h^I's h^(1/2).
const NEAR_HALF: f64 = 0.15;

/// "0.981 ± 0.005 (fitted, levels 0 1 2 3 4 5)" where the verdict supports a rate, else
/// the verdict with the last successive rate ("falling, last successive rate 0.557").
fn rate_text(r: &RateRecord) -> String {
    match (r.verdict.supports_rate(), r.rate, r.stderr) {
        (true, Some(rate), Some(se)) => {
            format!(
                "{rate:.3} ± {se:.3} ({}, levels {})",
                r.verdict.name(),
                r.levels_used
            )
        }
        _ => match r.last_rate {
            Some(last) if r.verdict != Verdict::RoundOff => {
                format!("{}, last successive rate {last:.3}", r.verdict.name())
            }
            _ => r.verdict.name().to_string(),
        },
    }
}

/// The rate in a table cell ([`rates::short_text`]).
fn rate_short(r: &RateRecord) -> String {
    rates::short_text(r.verdict, r.rate, r.last_rate)
}

/// The items joined by `sep`, or `none` where there are none.
fn listed(items: &[String], sep: &str, none: &str) -> String {
    if items.is_empty() {
        none.to_string()
    } else {
        items.join(sep)
    }
}

/// One convergence report read back: its rates and its errors at the finest level.
struct Report {
    rates: Vec<RateRecord>,
    errors: Vec<ErrorRecord>,
    /// What each method's distance to mortar supports (asymptotes.csv; empty where the
    /// study measures no distance).
    asymptotes: Vec<AsymptoteRow>,
    /// The finest level measured.
    finest: usize,
}

impl Report {
    fn read(dir: &Path) -> Result<Report> {
        let rates: Vec<RateRecord> = read(&dir.join("rates.csv"))?;
        let errors: Vec<ErrorRecord> = read(&dir.join("errors.csv"))?;
        let finest = errors.iter().map(|e| e.level).max().unwrap_or(0);
        let path = dir.join("asymptotes.csv");
        let asymptotes = if path.exists() { read(&path)? } else { Vec::new() };
        Ok(Report {
            rates,
            errors,
            asymptotes,
            finest,
        })
    }

    fn rate(&self, method: Method, quantity: Quantity) -> Option<&RateRecord> {
        self.rates
            .iter()
            .find(|r| r.method == method && r.quantity == quantity)
    }

    /// The error of a method in a quantity at the finest level.
    fn error(&self, r: &RateRecord) -> Option<f64> {
        self.errors
            .iter()
            .find(|e| e.method == r.method && e.quantity == r.quantity && e.level == self.finest)
            .map(|e| e.error)
    }

    /// The contact quantities compared between the cones at the finest level.
    fn compare_cones(&self) -> Comparison<'_> {
        let mut c = Comparison::default();
        for mortar in self
            .rates
            .iter()
            .filter(|r| r.method == Method::Mortar && r.quantity.is_contact())
        {
            let q = mortar.quantity;
            let Some(nts) = self.rate(Method::Nts, q) else {
                continue;
            };
            if !mortar.verdict.compares_cones() || !nts.verdict.compares_cones() {
                c.not_compared.push(q.to_string());
                continue;
            }
            let (Some(a), Some(b)) = (self.error(mortar), self.error(nts)) else {
                continue;
            };
            let ratio = error_ratio(mortar.verdict, nts.verdict, a, b);
            if !(1.0 / SEPARATES..=SEPARATES).contains(&ratio) {
                c.separate.push(Separation {
                    quantity: q,
                    ratio,
                    mortar_error: a,
                    nts_error: b,
                    mortar,
                    nts,
                });
            } else if mortar.verdict == Verdict::RoundOff && nts.verdict == Verdict::RoundOff {
                // error_ratio's 1.0 here is no measured ratio: say why they agree.
                c.agree.push(format!("{q} (both cones exact)"));
            } else {
                c.agree.push(q.to_string());
            }
        }
        c
    }

    /// The rows whose errors stop decreasing.
    /// The errors that stop decreasing (a distance between the cones is no error: it is
    /// reported with the distance).
    fn stalled(&self) -> impl Iterator<Item = &RateRecord> {
        self.rates
            .iter()
            .filter(|r| r.verdict == Verdict::NotConverging && !r.quantity.is_distance())
    }

    /// What nts's distance to mortar supports of nts's rate in `q`, where measured.
    fn asymptote(&self, q: Quantity) -> Option<&AsymptoteRow> {
        self.asymptotes
            .iter()
            .find(|a| a.method == Method::Nts && a.quantity == q)
    }

    /// The distance between the cones and the consistency terms, as a sentence; None where
    /// the study does not measure it.
    fn distance_text(&self) -> Option<String> {
        let d = self.rate(Method::Nts, Quantity::ConeDistance)?;
        let mut out = format!(
            "the distance D between the cones' solutions (Theorem 3.1's norm) falls at {}",
            rate_text(d)
        );
        if let Some(a) = self.asymptote(Quantity::Theorem) {
            out.push_str(&format!(
                " (D / e_mortar {:.2} at level {}, largest abs(pythagorean) {:.1e}): nts's theorem norm {}",
                a.finest_ratio.unwrap_or(f64::NAN),
                a.finest_level,
                a.largest_pythagorean.unwrap_or(f64::NAN),
                a.describe()
            ));
        }
        let consistency: Vec<String> = CONES
            .iter()
            .filter_map(|&m| {
                self.rate(m, Quantity::Consistency)
                    .map(|r| format!("{m} {}", rate_text(r)))
            })
            .collect();
        if !consistency.is_empty() {
            out.push_str(&format!(
                "; Proposition 3.1's consistency term: {}",
                consistency.join("; ")
            ));
        }
        Some(out)
    }
}

/// nts's error over mortar's; a cone at round-off is exact: infinite where mortar is, 0
/// where nts is, 1 where both are (rather than a ratio of round-off).
fn error_ratio(mortar: Verdict, nts: Verdict, mortar_error: f64, nts_error: f64) -> f64 {
    let exact = |v: Verdict| v == Verdict::RoundOff;
    match (exact(mortar), exact(nts)) {
        (true, true) => 1.0,
        (true, false) => f64::INFINITY,
        (false, true) => 0.0,
        (false, false) => nts_error / mortar_error,
    }
}

/// A contact quantity whose errors differ between the cones by more than [`SEPARATES`].
struct Separation<'a> {
    quantity: Quantity,
    /// nts's error over mortar's at the finest level ([`error_ratio`]).
    ratio: f64,
    mortar_error: f64,
    nts_error: f64,
    mortar: &'a RateRecord,
    nts: &'a RateRecord,
}

impl Separation<'_> {
    /// "nts/mortar = 63", "nts/mortar = 2.99", "mortar exact" or "nts exact".
    fn ratio_text(&self) -> String {
        if self.ratio.is_infinite() {
            "mortar exact".to_string()
        } else if self.ratio == 0.0 {
            "nts exact".to_string()
        } else if self.ratio >= 10.0 {
            format!("nts/mortar = {:.0}", self.ratio)
        } else {
            format!("nts/mortar = {:.2}", self.ratio)
        }
    }

    /// The gap between the cones either way (infinite where one is exact).
    fn gap(&self) -> f64 {
        self.ratio.max(1.0 / self.ratio)
    }

    /// The headline's cell: "`l2_pressure` 63x (mortar 1.85, nts not converging)".
    fn headline_text(&self) -> String {
        let q = self.quantity;
        let (mortar, nts) = (rate_short(self.mortar), rate_short(self.nts));
        if self.ratio.is_infinite() {
            format!("`{q}` mortar exact (nts {nts})")
        } else if self.ratio == 0.0 {
            format!("`{q}` nts exact (mortar {mortar})")
        } else if self.ratio >= 10.0 {
            format!("`{q}` {:.0}x (mortar {mortar}, nts {nts})", self.ratio)
        } else {
            format!("`{q}` {:.1}x (mortar {mortar}, nts {nts})", self.ratio)
        }
    }
}

/// The contact quantities of a report, by what the cones' errors say.
#[derive(Default)]
struct Comparison<'a> {
    /// Error ratio beyond [`SEPARATES`], in rates.csv's order.
    separate: Vec<Separation<'a>>,
    /// Within [`SEPARATES`].
    agree: Vec<String>,
    /// No rate the numbers support in some cone, or fixed by equilibrium.
    not_compared: Vec<String>,
}

/// The page docs/results.md: what each committed report measured, for the reports under
/// `reports`.
pub fn section(reports: &Path) -> Result<String> {
    let mut doc = Doc::new();
    doc.heading(1, "Results").paragraph(
        "What the committed reports measured (`cargo run --release -- results` prints this page from their CSVs; a test fails when it no longer matches them). Rates are least-squares slopes in h over the levels named, with the verdict of [the rate rules](studies.md#rates) (fitted; falling or rising: in transition; pre-asymptotic, not converging, round-off, fixed by equilibrium). Only a fitted verdict supports a rate.",
    );
    for (name, what) in STUDIES {
        study_section(&mut doc, &reports.join(name), name, what)?;
    }
    for (name, what) in TWO_SIZE {
        two_size_section(&mut doc, &reports.join(name), name, what)?;
    }
    regularity_section(&mut doc, reports)?;
    doc.heading(
        2,
        format!("[`paper`]({DOCS_REPORTS}/paper/README.md): the paper's three tests regenerated"),
    )
    .bullet("Every figure of its section 5 and the numbers behind its words (no rates: one mesh per test).")
    .blank();
    speed_section(&mut doc, reports)?;
    stability_section(&mut doc, reports)?;
    Ok(doc.finish())
}

/// One convergence report's section: the theorem norm, plasticity and time, where nts
/// reaches h^(1/2), what separates the cones, what does not converge, what has no rate.
fn study_section(doc: &mut Doc, dir: &Path, name: &str, what: &str) -> Result<()> {
    let report = Report::read(dir)?;
    doc.heading(
        2,
        format!("[`{name}`]({DOCS_REPORTS}/{name}/README.md): {what}"),
    );
    let theorem: Vec<String> = CONES
        .iter()
        .filter_map(|&m| {
            report
                .rate(m, Quantity::Theorem)
                .map(|r| format!("{m} {}, Theorem 3.1: {}", rate_text(r), m.theorem_rate()))
        })
        .collect();
    if !theorem.is_empty() {
        doc.bullet(format!("Theorem 3.1 norm: {}.", theorem.join("; ")));
    }
    plasticity_and_time(doc, dir)?;
    doc.bullet(format!(
        "nts at h^(1/2) (a rate within {NEAR_HALF} of 0.5): {}.",
        listed(&near_half(&report), "; ", "no quantity")
    ));
    separation_bullets(doc, &report);
    if let Some(text) = report.distance_text() {
        doc.bullet(format!("Between the cones: {text}."));
    }
    doc.bullet(format!(
        "Does not converge: {}.",
        listed(&stalled_texts(&report), "; ", "nothing")
    ));
    let unfitted: Vec<String> = report
        .rates
        .iter()
        .filter(|r| {
            matches!(
                r.verdict,
                Verdict::PreAsymptotic
                    | Verdict::FixedByEquilibrium
                    | Verdict::TooFewLevels
                    | Verdict::Falling
                    | Verdict::Rising
            )
        })
        .map(|r| format!("{} {} ({})", r.method, r.quantity, rate_short(r)))
        .collect();
    if !unfitted.is_empty() {
        doc.bullet(format!("No rate claimed: {}.", unfitted.join(", ")));
    }
    doc.blank();
    Ok(())
}

/// The quantities other than the theorem norm where nts's fitted rate is
/// within [`NEAR_HALF`] of 1/2.
fn near_half(report: &Report) -> Vec<String> {
    report
        .rates
        .iter()
        .filter(|r| r.method == Method::Nts && r.quantity != Quantity::Theorem)
        .filter(|r| r.verdict.supports_rate())
        .filter(|r| r.rate.is_some_and(|v| (v - 0.5).abs() <= NEAR_HALF))
        .map(|r| {
            format!(
                "{} {}, last successive rates {}",
                r.quantity,
                rate_text(r),
                r.last_successive()
            )
        })
        .collect()
}

/// The contact quantities that separate the cones at the finest level, those within
/// [`SEPARATES`], and those not compared.
fn separation_bullets(doc: &mut Doc, report: &Report) {
    let comparison = report.compare_cones();
    let separate: Vec<String> = comparison
        .separate
        .iter()
        .map(|c| {
            format!(
                "{} {} (mortar {:.2e}, {}; nts {:.2e}, {})",
                c.quantity,
                c.ratio_text(),
                c.mortar_error,
                rate_text(c.mortar),
                c.nts_error,
                rate_text(c.nts)
            )
        })
        .collect();
    let agree = if comparison.agree.is_empty() {
        String::new()
    } else {
        format!(" Within {SEPARATES}x: {}.", comparison.agree.join(", "))
    };
    doc.bullet(format!(
        "Contact quantities that separate the cones at level {} (error ratio beyond {SEPARATES}): {}.{agree}",
        report.finest,
        listed(&separate, "; ", "none"),
    ));
    if !comparison.not_compared.is_empty() {
        doc.bullet(format!(
            "Not compared (no rate the numbers support in some cone, or fixed by equilibrium): {}.",
            comparison.not_compared.join(", ")
        ));
    }
}

/// Each quantity that does not converge, with its error at the finest level and its
/// successive rates.
fn stalled_texts(report: &Report) -> Vec<String> {
    report
        .stalled()
        .map(|r| {
            let e = report.error(r).map_or(String::new(), |e| {
                format!(
                    " (at {e:.2e} at level {}; successive {})",
                    report.finest, r.successive
                )
            });
            format!("{} {}{e}", r.method, r.quantity)
        })
        .collect()
}

/// The plastic fraction at T of the finest level (where the bodies flow), and the rate in
/// k of the time study (where there is one), judged again from time.csv by the rule that
/// judged it ([`rates::assess`]).
fn plasticity_and_time(doc: &mut Doc, dir: &Path) -> Result<()> {
    let levels: Vec<LevelInfo> = read(&dir.join("levels.csv"))?;
    let finest = levels.iter().map(|l| l.level).max().unwrap_or(0);
    let plastic: Vec<String> = levels
        .iter()
        .filter(|l| l.level == finest && l.plastic_fraction > 0.0)
        .map(|l| format!("{} {:.3}", l.method, l.plastic_fraction))
        .collect();
    if !plastic.is_empty() {
        doc.bullet(format!(
            "Plastic fraction at T, level {finest}: {}.",
            plastic.join(", ")
        ));
    }
    let path = dir.join("time.csv");
    if !path.exists() {
        return Ok(());
    }
    let runs: Vec<TimeRun> = read(&path)?;
    let judged: Vec<(usize, f64, f64)> = runs.iter().map(|r| (r.steps, r.k, r.error)).collect();
    let a = crate::verify::judge::assess_in_k(&judged)
        .map_err(|e| Error::input(&path, "k", format!("{e}; regenerate the report")))?;
    let steps: Vec<String> = a.used.iter().map(|&i| runs[i].steps.to_string()).collect();
    let rate = match a.fit {
        Some(f) => format!(
            "{:.3} ± {:.3} ({}, steps {})",
            f.rate,
            f.stderr,
            a.verdict.name(),
            steps.join(" ")
        ),
        None => a.verdict.name().to_string(),
    };
    doc.bullet(format!(
        "Rate in k (time study, backward Euler's k term: 1): {rate}."
    ));
    Ok(())
}

/// The README's headline, for the reports under `reports`: three lines on what separates
/// the cones, how they meet Theorem 3.1 and what does not converge, then a table per study
/// of [`HEADLINE`]: the contact quantities whose errors separate the cones at the finest
/// level (largest ratio first), what does not converge, and the rate of the quantity the
/// study judges (Theorem 3.1's norm; the stress for `patch`) in each cone. A rate is
/// printed only where its verdict supports one (see [`rate_short`]).
pub fn headline(reports: &Path) -> Result<String> {
    let mut studies = Vec::new();
    for (name, what) in HEADLINE {
        studies.push((name, what, Report::read(&reports.join(name))?));
    }
    let mut doc = Doc::new();
    doc.bullet(format!(
        "**Where the cones differ:** {}.",
        cones_differ(&studies)
    ));
    let theorem: Vec<String> = CONES.iter().map(|&m| theorem_rates(&studies, m)).collect();
    doc.bullet(format!(
        "**Theorem 3.1's norm**, observed rates in h with their verdicts: {}.",
        theorem.join("; ")
    ));
    let distances: Vec<String> = studies
        .iter()
        .filter_map(|(name, _, report)| {
            let d = report.rate(Method::Nts, Quantity::ConeDistance)?;
            let a = report.asymptote(Quantity::Theorem)?;
            Some(format!(
                "in `{name}` D is {} and nts's error {}",
                match d.verdict {
                    Verdict::Fitted => format!("fitted at {}", rate_text(d)),
                    _ => rate_text(d),
                },
                a.describe()
            ))
        })
        .collect();
    if !distances.is_empty() {
        doc.bullet(format!(
            "**nts read against its distance D to mortar** (D - e_mortar <= e_nts <= D + e_mortar, on the same meshes): {}.",
            distances.join("; ")
        ));
    }
    doc.bullet(regularity_headline(&read(
        &reports.join("regularity").join("rates.csv"),
    )?));
    doc.bullet(format!(
        "**Does not converge:** {}.",
        listed(&stalled_anywhere(&studies), "; ", "nothing")
    ))
    .blank();
    let mut table = Table::new([
        "study: scene, measured against".to_string(),
        "where the cones differ: contact quantities at the finest level, nts's error / mortar's (rates)".to_string(),
        "does not converge".to_string(),
        format!("rate, mortar (Theorem 3.1: {})", Method::Mortar.theorem_rate()),
        format!("rate, nts (Theorem 3.1: {})", Method::Nts.theorem_rate()),
    ]);
    for (name, what, report) in &studies {
        table.row(headline_row(name, what, report));
    }
    Ok(doc.as_str().to_string() + &table.render())
}

/// The headline's first line: how many contact-quantity errors separate the cones over the
/// studies, which cone's is the larger, by how much, and where mortar is exact.
fn cones_differ(studies: &[(&str, &str, Report)]) -> String {
    let (mut nts_larger, mut total, mut widest) = (0, 0, 1.0f64);
    let mut mortar_exact = Vec::new();
    for (name, _, report) in studies {
        for c in report.compare_cones().separate {
            total += 1;
            if c.ratio > 1.0 {
                nts_larger += 1;
            }
            if c.ratio.is_infinite() {
                if !mortar_exact.contains(name) {
                    mortar_exact.push(*name);
                }
            } else if c.ratio > 1.0 {
                // The sentence says by how much nts's error is the larger.
                widest = widest.max(c.ratio);
            }
        }
    }
    let exact = if mortar_exact.is_empty() {
        String::new()
    } else {
        let names: Vec<String> = mortar_exact.iter().map(|n| format!("`{n}`")).collect();
        format!("; mortar is exact to round-off in {}", names.join(", "))
    };
    if total == 0 {
        format!(
            "no contact quantity's error separates them (ratio beyond {SEPARATES}x at the finest level) in any of the {} studies",
            studies.len()
        )
    } else {
        format!(
            "over the {} studies, {total} contact-quantity errors separate them (ratio beyond {SEPARATES}x at the finest level, among the quantities where both cones' verdicts support a comparison; the others are listed in docs/results.md), nts's the larger in {nts_larger}, by up to {widest:.0}x{exact}",
            studies.len()
        )
    }
}

/// Theorem 3.1's norm in one cone over the studies: the range of the fitted rates, and
/// each study whose errors support no rate, with its verdict.
fn theorem_rates(studies: &[(&str, &str, Report)], m: Method) -> String {
    let rows: Vec<(&str, &RateRecord)> = studies
        .iter()
        .filter_map(|(name, _, r)| Some((*name, r.rate(m, Quantity::Theorem)?)))
        .collect();
    let fitted: Vec<f64> = rows
        .iter()
        .filter(|(_, r)| r.verdict.supports_rate())
        .filter_map(|(_, r)| r.rate)
        .collect();
    let (lo, hi) = fitted
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let range = if fitted.is_empty() {
        "no fitted rate".to_string()
    } else if format!("{lo:.2}") == format!("{hi:.2}") {
        format!("{lo:.2} fitted in {} studies", fitted.len())
    } else {
        format!("{lo:.2}-{hi:.2} fitted in {} studies", fitted.len())
    };
    let others: Vec<String> = rows
        .iter()
        .filter(|(_, r)| !r.verdict.supports_rate())
        .map(|(name, r)| format!("{} in `{name}`", rate_short(r)))
        .collect();
    let more = if others.is_empty() {
        String::new()
    } else {
        format!(", {}", others.join(", "))
    };
    format!("{m} {range}{more} (Theorem 3.1: {})", m.theorem_rate())
}

/// Each (method, quantity) that does not converge, with the studies where it stalls.
fn stalled_anywhere(studies: &[(&str, &str, Report)]) -> Vec<String> {
    let mut stalled: Vec<(String, Vec<&str>)> = Vec::new();
    for (name, _, report) in studies {
        for r in report.stalled() {
            let key = format!("{} `{}`", r.method, r.quantity);
            match stalled.iter_mut().find(|(k, _)| *k == key) {
                Some((_, names)) => names.push(name),
                None => stalled.push((key, vec![name])),
            }
        }
    }
    stalled
        .iter()
        .map(|(k, names)| format!("{k} (in {})", names.join(", ")))
        .collect()
}

/// One study's row of the headline table.
fn headline_row(name: &str, what: &str, report: &Report) -> [String; 5] {
    let mut comparison = report.compare_cones();
    // The widest gap first; an exact cone (an infinite or zero ratio) leads.
    comparison
        .separate
        .sort_by(|a, b| b.gap().total_cmp(&a.gap()));
    let separate: Vec<String> = comparison
        .separate
        .iter()
        .map(Separation::headline_text)
        .collect();
    let separate = if separate.is_empty() {
        format!("none beyond {SEPARATES}x (level {})", report.finest)
    } else {
        format!("level {}: {}", report.finest, separate.join(", "))
    };
    let stalled: Vec<String> = report
        .stalled()
        .map(|r| format!("{} `{}`", r.method, r.quantity))
        .collect();
    [
        format!("[`{name}`]({README_REPORTS}/{name}/README.md): {what}"),
        separate,
        listed(&stalled, ", ", "nothing"),
        judged_rate(report, Method::Mortar),
        judged_rate(report, Method::Nts),
    ]
}

/// The rate of the quantity the study judges (the one with a threshold) in cone `m`, as
/// far as its verdict supports one.
fn judged_rate(report: &Report, m: Method) -> String {
    report
        .rates
        .iter()
        .find(|r| r.method == m && r.threshold.is_some())
        .map_or("not measured".to_string(), |r| {
            let rate = match (r.verdict, r.rate, r.stderr) {
                (Verdict::Fitted, Some(v), Some(se)) => {
                    format!("{v:.3} ± {se:.3} {}", r.verdict.name())
                }
                (Verdict::RoundOff, _, _) => "exact (round-off)".to_string(),
                _ => rate_short(r),
            };
            // What the distance to mortar supports beside what was observed.
            let asymptote = report
                .asymptotes
                .iter()
                .find(|a| a.method == m && a.quantity == r.quantity)
                .map_or(String::new(), |a| format!("; {}", a.describe()));
            if r.quantity == Quantity::Theorem {
                format!("{rate}{asymptote}")
            } else {
                format!("`{}` {rate}{asymptote}", r.quantity)
            }
        })
}

/// A two-size report's section: the theorem norm's exponents per slave choice and cone,
/// and what refining each body alone from the finest grid diagonal point does to the
/// theorem error and the penetration.
fn two_size_section(doc: &mut Doc, dir: &Path, name: &str, what: &str) -> Result<()> {
    let fits: Vec<FitRecord> = read(&dir.join("fits.csv"))?;
    let grid: Vec<SizePoint> = read(&dir.join("grid.csv"))?;
    doc.heading(
        2,
        format!("[`{name}`]({DOCS_REPORTS}/{name}/README.md): {what}"),
    );
    let exponent = |v: f64, se: f64, rms: f64| match rates::fit_identifies(se, rms) {
        true => format!("{v:.2} ± {se:.2}"),
        false => "not identified".into(),
    };
    let mut slaves: Vec<&str> = fits.iter().map(|f| f.slave.as_str()).collect();
    slaves.dedup();
    let lemma: Vec<String> = CONES
        .iter()
        .map(|m| {
            let [a1, a2] = m.lemma_exponents();
            format!("{m} ({a1}, {a2})")
        })
        .collect();
    for slave in &slaves {
        let parts: Vec<String> = fits
            .iter()
            .filter(|f| f.slave == *slave && f.quantity == Quantity::Theorem)
            .map(|f| {
                format!(
                    "{} a1 {}, a2 {}",
                    f.method,
                    exponent(f.a1, f.se_a1, f.rms_log_residual),
                    exponent(f.a2, f.se_a2, f.rms_log_residual)
                )
            })
            .collect();
        doc.bullet(format!(
            "Theorem norm, E = C1 h1^a1 + C2 h2^a2 with slave '{slave}' (Lemma 3.1: {}): {}.",
            lemma.join(", "),
            parts.join("; ")
        ));
    }
    if let Some(slave) = slaves.first() {
        doc.bullet(one_body_refined(&grid, slave));
    }
    doc.blank();
    Ok(())
}

/// From the finest diagonal point of the grid, each body refined alone to the fixed level:
/// the theorem error and the penetration of both cones, with slave `slave`.
fn one_body_refined(grid: &[SizePoint], slave: &str) -> String {
    let top = grid
        .iter()
        .map(|p| p.slave_level.max(p.master_level))
        .max()
        .unwrap_or(0);
    let finest = grid
        .iter()
        .filter(|p| p.slave_level == p.master_level && p.slave_level < top)
        .map(|p| p.slave_level)
        .max()
        .unwrap_or(0);
    let error = |m: Method, q: Quantity, l: [usize; 2]| {
        grid.iter()
            .find(|p| {
                p.slave == slave
                    && p.method == m
                    && p.quantity == q
                    && [p.slave_level, p.master_level] == l
            })
            .map(|p| p.error)
    };
    let mut parts = Vec::new();
    for m in CONES {
        for q in [Quantity::Theorem, Quantity::MaxPenetration] {
            let (Some(base), Some(s1), Some(s2)) = (
                error(m, q, [finest, finest]),
                error(m, q, [top, finest]),
                error(m, q, [finest, top]),
            ) else {
                continue;
            };
            parts.push(format!(
                "{m} {q} {base:.2e} -> slave refined {s1:.2e} (x{:.2}), master refined {s2:.2e} (x{:.2})",
                s1 / base,
                s2 / base
            ));
        }
    }
    format!(
        "From ({finest}, {finest}), slave '{slave}', one body refined to level {top}: {}.",
        parts.join("; ")
    )
}

/// The cost of the default solver against the floor, per family, from 1e4 dofs.
fn speed_section(doc: &mut Doc, reports: &Path) -> Result<()> {
    let speed: Vec<SpeedRecord> = read(&reports.join("speed").join("speed.csv"))?;
    let newton: Vec<&SpeedRecord> = speed
        .iter()
        .filter(|r| r.solver == SolverKind::Newton && r.dofs >= 10_000)
        .collect();
    let mut families: Vec<&str> = newton.iter().map(|r| r.family.as_str()).collect();
    families.dedup();
    let ranges: Vec<String> = families
        .iter()
        .map(|f| {
            let ratios = newton
                .iter()
                .filter(|r| r.family == *f)
                .map(|r| r.ratio_to_floor);
            let (lo, hi) = ratios.fold((f64::INFINITY, 0.0f64), |(a, b), v| (a.min(v), b.max(v)));
            format!("{f} {lo:.2}-{hi:.2}")
        })
        .collect();
    let top = speed.iter().map(|r| r.dofs).max().unwrap_or(0);
    let threads = speed.first().map_or(String::new(), |r| {
        format!(" ({} threads, the solver and the floor alike)", r.threads)
    });
    doc.heading(
        2,
        format!("[`speed`]({DOCS_REPORTS}/speed/README.md): cost against the floor (the faster of an f64 Cholesky and an f32 Cholesky with conjugate gradients)"),
    )
    .bullet(format!(
        "newton's (set-up + time loop) / floor from 1e4 to {top} dofs{threads}: {}.",
        ranges.join(", ")
    ))
    .blank();
    Ok(())
}

/// The theorem-norm rows of the regularity study's rates.csv of cone `m`, in beta order.
fn regularity_theorem(rows: &[RegularityRate], m: Method) -> Vec<&RegularityRate> {
    rows.iter()
        .filter(|r| r.method == m && r.quantity == Quantity::Theorem)
        .collect()
}

/// The betas of `rows` that follow (or not) their best rate, as text.
fn betas_where(rows: &[&RegularityRate], follows: bool) -> Vec<String> {
    rows.iter()
        .filter(|r| r.follows_best == Some(follows))
        .map(|r| format!("{}", r.beta))
        .collect()
}

/// The headline's line on the regularity study: where each cone's theorem-norm rate follows
/// min(1, beta), where it falls below (the largest shortfall), and where its errors support
/// no rate (in transition, with the last successive rate).
fn regularity_headline(rows: &[RegularityRate]) -> String {
    let cone = |m: Method| {
        let theorem = regularity_theorem(rows, m);
        let mut parts = Vec::new();
        let follows = betas_where(&theorem, true);
        if !follows.is_empty() {
            parts.push(format!("follows it at beta = {}", follows.join(", ")));
        }
        let worst = theorem
            .iter()
            .filter(|r| r.follows_best == Some(false))
            .filter_map(|r| Some((r.beta, r.best_rate? - r.rate?, r.rate?)))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((beta, short, rate)) = worst {
            parts.push(format!(
                "falls below it at beta = {} (by up to {short:.2}: {rate:.3} at beta = {beta})",
                betas_where(&theorem, false).join(", ")
            ));
        }
        let unsupported: Vec<String> = theorem
            .iter()
            .filter(|r| r.follows_best.is_none())
            .map(|r| {
                format!(
                    "{} at beta = {}",
                    rates::short_text(r.verdict, r.rate, r.last_rate),
                    r.beta
                )
            })
            .collect();
        if !unsupported.is_empty() {
            parts.push(format!("supports no rate: {}", unsupported.join(", ")));
        }
        format!("{m}'s rate {}", parts.join("; "))
    };
    format!(
        "**Rates against the regularity of the contact transition** ([`regularity`](reports/regularity/README.md), u ~ r^beta where contact ends, Theorem 3.1's norm against the best uniform-mesh rate min(1, beta)): {}; {}.",
        cone(Method::Mortar),
        cone(Method::Nts)
    )
}

/// The regularity study: its rate table, beta x cone x quantity, with verdicts.
fn regularity_section(doc: &mut Doc, reports: &Path) -> Result<()> {
    let rows: Vec<RegularityRate> = read(&reports.join("regularity").join("rates.csv"))?;
    doc.heading(
        2,
        format!("[`regularity`]({DOCS_REPORTS}/regularity/README.md): rates against the regularity beta of the contact transition (u ~ r^beta there)"),
    )
    .bullet(regularity_headline(&rows).replace("(reports/", &format!("({DOCS_REPORTS}/")))
    .bullet("Theorem 3.1 applies only for beta > 1 (u in H^2, f in L2); † marks the betas where it does not. A rate is shown where its verdict supports one, with \"follows\" where it reaches the best rate within 0.05 (or two standard errors).")
    .blank();
    let mut table = Table::new(["beta", "quantity", "best rate", "mortar", "nts"]);
    let mut keys: Vec<(f64, Quantity)> = Vec::new();
    for r in &rows {
        if !keys.contains(&(r.beta, r.quantity)) {
            keys.push((r.beta, r.quantity));
        }
    }
    for (beta, q) in keys {
        let of = |m: Method| {
            rows.iter()
                .find(|r| r.beta == beta && r.quantity == q && r.method == m)
        };
        let text = |r: Option<&RegularityRate>| match r {
            Some(r) => match (r.rate, r.stderr) {
                (Some(rate), Some(se)) => format!(
                    "{rate:.3} ± {se:.3} {}{}",
                    r.verdict.name(),
                    match r.follows_best {
                        Some(true) => ", follows",
                        Some(false) => ", below",
                        None => "",
                    }
                ),
                _ => format!("{} (successive rates {})", r.verdict.name(), r.successive),
            },
            None => "-".into(),
        };
        // From any row of this beta: cone_distance has an nts row only.
        let applies = rows.iter().any(|r| r.beta == beta && r.theorem_applies);
        table.row([
            format!("{beta}{}", if applies { "" } else { " †" }),
            format!("`{q}`"),
            of(Method::Mortar)
                .and_then(|r| r.best_rate)
                .map_or("-".into(), |b| format!("{b:.2}")),
            text(of(Method::Mortar)),
            text(of(Method::Nts)),
        ]);
    }
    doc.table(&table);
    Ok(())
}

/// The hard cases: how many runs of each solver did not converge, and newton's most
/// iterations in one step.
fn stability_section(doc: &mut Doc, reports: &Path) -> Result<()> {
    let stability: Vec<StabilityRow> = read(&reports.join("stability").join("stability.csv"))?;
    let count = |solver: SolverKind| {
        let runs = stability.iter().filter(|r| r.solver == solver);
        let failed = runs.clone().filter(|r| !r.converged).count();
        format!("{solver} {failed} of {}", runs.count())
    };
    let worst = stability
        .iter()
        .filter(|r| r.solver == SolverKind::Newton && r.converged)
        .max_by_key(|r| r.max_step_iterations);
    let counts: Vec<String> = [SolverKind::Newton, SolverKind::Paper, SolverKind::Qp]
        .into_iter()
        .map(count)
        .collect();
    doc.heading(
        2,
        format!("[`stability`]({DOCS_REPORTS}/stability/README.md): hard cases, every solver"),
    )
    .bullet(format!(
        "Not converged: {}.{}",
        counts.join(", "),
        worst.map_or(String::new(), |w| format!(
            " newton's most iterations in one step: {} ({}, {}, {}).",
            w.max_step_iterations,
            w.case.name(),
            w.parameter,
            w.method
        ))
    ))
    .blank();
    Ok(())
}
