//! The convergence studies' part of docs/results.md, read back from their reports' CSVs
//! (rates.csv, errors.csv, asymptotes.csv, levels.csv, time.csv), and what the README's
//! headline reads of them.

use crate::contact::Method;
use crate::studies::convergence::{LevelInfo, TimeRun};
use crate::verify::judge::AsymptoteRow;
use crate::verify::quantity::Quantity;
use crate::verify::rates::{self, Verdict};
use crate::verify::table::{ErrorRecord, RateRecord};
use crate::error::{Error, Result};
use crate::report::markdown::{DOCS_REPORTS, Doc, listed};
use crate::verify::table::read;
use std::path::Path;

/// The convergence studies' sections of docs/results.md, for the reports under `reports`.
pub fn section(reports: &Path) -> Result<String> {
    let mut doc = Doc::new();
    for (name, what) in STUDIES {
        study_section(&mut doc, &reports.join(name), name, what)?;
    }
    Ok(doc.finish())
}

/// The convergence studies whose reports the section summarises, with a line on what each
/// measures against.
pub const STUDIES: [(&str, &str); 8] = [
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
    (
        "crossover-transition",
        "the interface separating at c = (0.5871, 1), u ~ r^1.25 there, the singular part carrying the pressure: nts's h^(1/2) distance to mortar past mortar's error",
    ),
    (
        "gap",
        "regularity-unaligned-1.50 across the initial gap g0 = x^2 / 20, closed on [0, c) by body 1's traction-free u_g, against the exact solution: the gap's own discretization error per method",
    ),
    (
        "press-fit",
        "the Lame press fit, two quarter annuli across the radial gap g0 = 0.02 on curved traces split on their arcs, against the closed form on the discrete domains",
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

/// The cones, in the order the pages name them.
pub(crate) const CONES: [Method; 3] = Method::ALL;

pub(crate) use crate::verify::judge::SEPARATES;

/// An nts rate within this of 1/2 attains K_h^I's h^(1/2).
pub(crate) const NEAR_HALF: f64 = 0.15;

/// What the study file held a rates.csv row to and the outcome: "threshold 0.70: pass",
/// "exact to 1e-9: pass", or "no threshold" (none on this quantity, or none the theorems
/// give the method on this study).
pub(crate) fn held_to(r: &RateRecord) -> String {
    match (r.threshold, r.pass) {
        // An exactness bound is a relative error, far below any rate threshold.
        (Some(t), Some(p)) if t > 0.0 && t < 1e-3 => format!("exact to {t:.0e}: {}", p.name()),
        (Some(t), Some(p)) => format!("threshold {t:.2}: {}", p.name()),
        _ => "no threshold".into(),
    }
}

/// "0.981 ± 0.005 (fitted, levels 0 1 2 3 4 5)" where the verdict supports a rate, else
/// the verdict with the last successive rate ("falling, last successive rate 0.557").
pub(crate) fn rate_text(r: &RateRecord) -> String {
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
pub(crate) fn rate_short(r: &RateRecord) -> String {
    rates::short_text(r.verdict, r.rate, r.last_rate)
}

/// One convergence report read back: its rates and its errors at the finest level.
pub(crate) struct Report {
    pub(crate) rates: Vec<RateRecord>,
    pub(crate) errors: Vec<ErrorRecord>,
    /// What each method's distance to mortar supports (asymptotes.csv; empty where the
    /// study measures no distance).
    pub(crate) asymptotes: Vec<AsymptoteRow>,
    /// The finest level measured.
    pub(crate) finest: usize,
}

impl Report {
    pub(crate) fn read(dir: &Path) -> Result<Report> {
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

    pub(crate) fn rate(&self, method: Method, quantity: Quantity) -> Option<&RateRecord> {
        self.rates
            .iter()
            .find(|r| r.method == method && r.quantity == quantity)
    }

    /// The error of a method in a quantity at the finest level.
    pub(crate) fn error(&self, r: &RateRecord) -> Option<f64> {
        self.errors
            .iter()
            .find(|e| e.method == r.method && e.quantity == r.quantity && e.level == self.finest)
            .map(|e| e.error)
    }

    /// The contact quantities compared at the finest level between the reference (mortar)
    /// and each other method of the registry, one method after the other.
    pub(crate) fn compare_cones(&self) -> Comparison<'_> {
        let mut c = Comparison::default();
        let reference = Method::reference();
        // The rule of the study's own README (report.rs's quantities_compared): a contact
        // quantity is compared only where every method's verdict compares the cones.
        let (compared, left_out): (Vec<&RateRecord>, Vec<&RateRecord>) = self
            .rates
            .iter()
            .filter(|r| r.method == reference && r.quantity.is_contact())
            .partition(|base| {
                self.rates
                    .iter()
                    .filter(|r| r.quantity == base.quantity && r.method.cone().is_some())
                    .all(|r| r.verdict.compares_cones())
            });
        c.not_compared = left_out.iter().map(|r| r.quantity.to_string()).collect();
        for method in Method::compared(&CONES) {
            for &base in &compared {
                let q = base.quantity;
                let Some(other) = self.rate(method, q) else {
                    continue;
                };
                let (Some(a), Some(b)) = (self.error(base), self.error(other)) else {
                    continue;
                };
                let ratio = error_ratio(base.verdict, other.verdict, a, b);
                if !(1.0 / SEPARATES..=SEPARATES).contains(&ratio) {
                    c.separate.push(Separation {
                        quantity: q,
                        method,
                        ratio,
                        reference_error: a,
                        other_error: b,
                        reference: base,
                        other,
                    });
                } else if base.verdict == Verdict::RoundOff && other.verdict == Verdict::RoundOff {
                    // error_ratio's 1.0 here is no measured ratio: say why they agree.
                    c.agree.push((method, format!("{q} (both exact)")));
                } else {
                    c.agree.push((method, q.to_string()));
                }
            }
        }
        c
    }

    /// The rows whose errors stop decreasing.
    /// The errors that stop decreasing (a distance between the cones is no error: it is
    /// reported with the distance).
    pub(crate) fn stalled(&self) -> impl Iterator<Item = &RateRecord> {
        self.rates
            .iter()
            .filter(|r| r.verdict == Verdict::NotConverging && !r.quantity.is_distance())
    }

    /// What `method`'s distance to mortar supports of its rate in `q`, where measured.
    pub(crate) fn asymptote(&self, method: Method, q: Quantity) -> Option<&AsymptoteRow> {
        self.asymptotes
            .iter()
            .find(|a| a.method == method && a.quantity == q)
    }

    /// The distance of each method to mortar and the consistency terms, as a sentence;
    /// None where the study does not measure it.
    pub(crate) fn distance_text(&self) -> Option<String> {
        let reference = Method::reference();
        let parts: Vec<String> = Method::compared(&CONES)
            .filter_map(|m| {
                let d = self.rate(m, Quantity::ConeDistance)?;
                // "falls at" only a rate the verdict supports; else what the verdict says.
                let how = match d.verdict.supports_rate() && d.rate.is_some() {
                    true => format!("falls at {}", rate_text(d)),
                    false => format!("supports no rate ({})", rate_text(d)),
                };
                let mut out = format!("{m}'s distance D to {reference} {how}");
                if let Some(a) = self.asymptote(m, Quantity::Theorem) {
                    // No ratio is written where the study measured none (never a NaN).
                    let ratio = a.finest_ratio.map_or("-".into(), |v| format!("{v:.2}"));
                    let pythagorean = a.largest_pythagorean.map_or("-".into(), |v| format!("{v:.1e}"));
                    out.push_str(&format!(
                        " (D / e_{reference} {ratio} at level {}, largest abs(pythagorean) {pythagorean}); {m}'s theorem norm: {}",
                        a.finest_level,
                        a.describe()
                    ));
                }
                Some(out)
            })
            .collect();
        if parts.is_empty() {
            return None;
        }
        let mut out = format!("in Theorem 3.1's norm, {}", parts.join("; "));
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

/// The other method's error over the reference's; a method at round-off is exact:
/// infinite where the reference is, 0 where the other is, 1 where both are (rather than a
/// ratio of round-off). Two errors exactly equal (both 0 included) give 1, never NaN.
pub(crate) fn error_ratio(reference: Verdict, other: Verdict, reference_error: f64, other_error: f64) -> f64 {
    let exact = |v: Verdict| v == Verdict::RoundOff;
    match (exact(reference), exact(other)) {
        (true, true) => 1.0,
        (true, false) => f64::INFINITY,
        (false, true) => 0.0,
        (false, false) if other_error == reference_error => 1.0,
        (false, false) => other_error / reference_error,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_zero_errors_are_equal_not_nan() {
        let v = Verdict::Fitted;
        assert_eq!(error_ratio(v, v, 0.0, 0.0), 1.0);
        assert_eq!(error_ratio(v, v, 0.0, 1e-3), f64::INFINITY);
        assert_eq!(error_ratio(v, v, 2e-3, 1e-3), 0.5);
    }
}

/// A contact quantity whose errors differ between a method and the reference by more than
/// [`SEPARATES`].
pub(crate) struct Separation<'a> {
    pub(crate) quantity: Quantity,
    /// The method compared with the reference.
    pub(crate) method: Method,
    /// The other method's error over the reference's at the finest level ([`error_ratio`]).
    pub(crate) ratio: f64,
    pub(crate) reference_error: f64,
    pub(crate) other_error: f64,
    pub(crate) reference: &'a RateRecord,
    pub(crate) other: &'a RateRecord,
}

impl Separation<'_> {
    /// "nts/mortar = 63", "nts/mortar = 2.99", "mortar exact" or "nts exact".
    pub(crate) fn ratio_text(&self) -> String {
        let (r, o) = (Method::reference(), self.method);
        if self.ratio.is_infinite() {
            format!("{r} exact")
        } else if self.ratio == 0.0 {
            format!("{o} exact")
        } else if self.ratio >= 10.0 {
            format!("{o}/{r} = {:.0}", self.ratio)
        } else {
            format!("{o}/{r} = {:.2}", self.ratio)
        }
    }

    /// The gap between the two methods either way (infinite where one is exact).
    pub(crate) fn gap(&self) -> f64 {
        self.ratio.max(1.0 / self.ratio)
    }

    /// The headline's cell: "`l2_pressure` nts/mortar 63x (mortar 1.85, nts not converging)"
    /// (the method named first, since one study lists several methods against the reference).
    pub(crate) fn headline_text(&self) -> String {
        let q = self.quantity;
        let (r, o) = (Method::reference(), self.method);
        let (a, b) = (rate_short(self.reference), rate_short(self.other));
        if self.ratio.is_infinite() {
            format!("`{q}` {r} exact ({o} {b})")
        } else if self.ratio == 0.0 {
            format!("`{q}` {o} exact ({r} {a})")
        } else if self.ratio >= 10.0 {
            format!("`{q}` {o}/{r} {:.0}x ({r} {a}, {o} {b})", self.ratio)
        } else if self.ratio >= 1.0 {
            format!("`{q}` {o}/{r} {:.1}x ({r} {a}, {o} {b})", self.ratio)
        } else {
            format!("`{q}` {o}/{r} {:.2}x ({r} {a}, {o} {b})", self.ratio)
        }
    }
}

/// The contact quantities of a report, by what the methods' errors say against the
/// reference's.
#[derive(Default)]
pub(crate) struct Comparison<'a> {
    /// Error ratio beyond [`SEPARATES`], method by method, in rates.csv's order.
    pub(crate) separate: Vec<Separation<'a>>,
    /// Within [`SEPARATES`]: the method and the quantity.
    pub(crate) agree: Vec<(Method, String)>,
    /// No rate the numbers support in some cone, or fixed by equilibrium.
    pub(crate) not_compared: Vec<String>,
}

/// One convergence report's section: the theorem norm, plasticity and time, where nts
/// reaches h^(1/2), what separates the cones, what does not converge, what has no rate.
pub(crate) fn study_section(doc: &mut Doc, dir: &Path, name: &str, what: &str) -> Result<()> {
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
                .map(|r| format!("{m} {} ({})", rate_text(r), held_to(r)))
        })
        .collect();
    if !theorem.is_empty() {
        doc.bullet(format!("Theorem 3.1's norm: {}.", theorem.join("; ")));
    }
    plasticity_and_time(doc, dir)?;
    for m in Method::compared(&CONES) {
        doc.bullet(format!(
            "{m} at h^(1/2) (the fit and the last judged rate within {NEAR_HALF} of 0.5): {}.",
            listed(&near_half(&report, m), "; ", "no quantity")
        ));
    }
    separation_bullets(doc, &report);
    if let Some(text) = report.distance_text() {
        doc.bullet(format!("Between the methods: {text}."));
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

/// The quantities other than the theorem norm where `method`'s fitted rate and its last
/// judged rate are both within [`NEAR_HALF`] of 1/2 (a rate claim: never the fit alone).
pub(crate) fn near_half(report: &Report, method: Method) -> Vec<String> {
    let near = |v: f64| (v - 0.5).abs() <= NEAR_HALF;
    report
        .rates
        .iter()
        .filter(|r| r.method == method && r.quantity != Quantity::Theorem)
        .filter(|r| r.verdict.supports_rate())
        .filter(|r| r.rate.is_some_and(near) && r.last_rate.is_some_and(near))
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

/// The contact quantities that separate each method from the reference at the finest
/// level, those within [`SEPARATES`], and those not compared.
pub(crate) fn separation_bullets(doc: &mut Doc, report: &Report) {
    let comparison = report.compare_cones();
    let reference = Method::reference();
    for m in Method::compared(&CONES) {
        // A method the study does not solve gets no bullet.
        let measured = report.rate(m, Quantity::Theorem).is_some()
            || comparison.agree.iter().any(|a| a.0 == m)
            || comparison.separate.iter().any(|c| c.method == m);
        if !measured {
            continue;
        }
        let separate: Vec<String> = comparison
            .separate
            .iter()
            .filter(|c| c.method == m)
            .map(|c| {
                format!(
                    "{} {} ({reference} {:.2e}, {}; {m} {:.2e}, {})",
                    c.quantity,
                    c.ratio_text(),
                    c.reference_error,
                    rate_text(c.reference),
                    c.other_error,
                    rate_text(c.other)
                )
            })
            .collect();
        let agree: Vec<&str> = comparison.agree.iter().filter(|a| a.0 == m).map(|a| a.1.as_str()).collect();
        let agree = if agree.is_empty() {
            String::new()
        } else {
            format!(" Within {SEPARATES}x: {}.", agree.join(", "))
        };
        doc.bullet(format!(
            "Contact quantities that separate {m} from {reference} at level {} (error ratio beyond {SEPARATES}): {}.{agree}",
            report.finest,
            listed(&separate, "; ", "none"),
        ));
    }
    if !comparison.not_compared.is_empty() {
        doc.bullet(format!(
            "Not compared (no rate the numbers support in some cone, or fixed by equilibrium): {}.",
            comparison.not_compared.join(", ")
        ));
    }
}

/// Each quantity that does not converge, with its error at the finest level and its
/// successive rates.
pub(crate) fn stalled_texts(report: &Report) -> Vec<String> {
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
pub(crate) fn plasticity_and_time(doc: &mut Doc, dir: &Path) -> Result<()> {
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

