//! What the committed convergence reports found, read back from their CSVs (rates.csv,
//! errors.csv, ...), so that the documentation says what the harness measured and a test
//! can tell when it no longer matches them: [`section`] is the full page docs/results.md
//! (`contact-rates results`), [`headline`] the compact table of README.md
//! (`contact-rates results --headline`).

use crate::error::{Error, Result};
use crate::verify::quantity::Quantity;
use crate::verify::rates::{self, Verdict};
use serde::Deserialize;
use std::fmt::Write as _;
use std::path::Path;

/// The convergence studies whose reports the section summarises, with a line on what each
/// measures against.
pub const STUDIES: [(&str, &str); 4] = [
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
];

/// The studies of the README's headline table, the exact ones first, with what each is
/// measured against.
pub const HEADLINE: [(&str, &str); 4] = [
    ("rates-exact", "`contact-mms` (elastic), exact solution"),
    (
        "rates-exact-vp",
        "`contact-mms-vp` (both bodies flowing), exact solution",
    ),
    ("patch", "paper Test 2, exact stress and pressure"),
    ("rates", "`rates` (viscoplastic), matching-mesh reference"),
];

/// Where docs/results.md links to the reports and to the rate rules (relative to docs/).
const DOCS_REPORTS: &str = "../reports";
/// Where README.md links to the reports (relative to the repository's root).
const README_REPORTS: &str = "reports";

/// Theorem 3.1's rates of the `theorem` norm: K_h^pi (mortar), K_h^I (nts).
const THEOREM: [(&str, f64); 2] = [("mortar", 0.75), ("nts", 0.5)];
/// A ratio of the cones' errors at the finest level beyond this (either way) separates them.
const SEPARATES: f64 = 1.5;
/// An nts rate within this of 1/2 attains K_h^I's h^(1/2).
const NEAR_HALF: f64 = 0.15;

/// One row of a report's rates.csv (the columns read here).
#[derive(Debug, Deserialize)]
pub struct RateLine {
    /// Cone.
    pub method: String,
    /// Quantity.
    pub quantity: String,
    /// Fitted rate (empty without one).
    pub rate: Option<f64>,
    /// Its standard error.
    pub stderr: Option<f64>,
    /// Fitted levels, space separated.
    pub levels_used: String,
    /// The rate the study requires of this cone, on the quantity it judges (empty on the
    /// other quantities).
    pub threshold: Option<f64>,
    /// Successive rates, space separated.
    pub successive: String,
    /// Verdict.
    #[serde(deserialize_with = "verdict_by_name")]
    pub verdict: Verdict,
}

/// A verdict read back from its name in rates.csv.
fn verdict_by_name<'de, D: serde::Deserializer<'de>>(
    d: D,
) -> std::result::Result<Verdict, D::Error> {
    let name = String::deserialize(d)?;
    Verdict::from_name(&name)
        .ok_or_else(|| serde::de::Error::custom(format!("unknown verdict '{name}'")))
}

/// One row of a report's errors.csv (the columns read here).
#[derive(Debug, Deserialize)]
pub struct ErrorLine {
    /// Cone.
    pub method: String,
    /// Level.
    pub level: usize,
    /// Quantity.
    pub quantity: String,
    /// Relative error (max over time steps).
    pub error: f64,
}

fn read<T: for<'de> Deserialize<'de>>(path: &Path) -> Result<Vec<T>> {
    let mut reader = csv::Reader::from_path(path).map_err(|e| {
        Error::input(
            path,
            "file",
            format!("cannot read ({e}); regenerate the report"),
        )
    })?;
    reader
        .deserialize()
        .collect::<std::result::Result<Vec<T>, _>>()
        .map_err(|e| Error::input(path, "rows", format!("{e}; regenerate the report")))
}

/// Whether the quantity named `q` is a contact quantity (where the cones differ).
fn is_contact(q: &str) -> bool {
    Quantity::CONTACT.iter().any(|c| c.name() == q)
}

/// "0.981 ± 0.005 (fitted, levels 0 1 2 3 4 5)", or the verdict where there is no rate.
fn rate_text(r: &RateLine) -> String {
    match (r.rate, r.stderr) {
        (Some(rate), Some(se)) => {
            format!(
                "{rate:.3} ± {se:.3} ({}, levels {})",
                r.verdict.name(),
                r.levels_used
            )
        }
        _ => r.verdict.name().to_string(),
    }
}

/// The rate in a table cell: "1.85" where fitted, "0.88 drifting" where the rate is still
/// changing, "exact" at round-off, the verdict's name where the numbers support no rate
/// (a pre-asymptotic fit is never printed as a rate).
fn rate_short(r: &RateLine) -> String {
    match (r.verdict, r.rate) {
        (Verdict::Fitted, Some(v)) => format!("{v:.2}"),
        (Verdict::Drifting, Some(v)) => format!("{v:.2} drifting"),
        (Verdict::RoundOff, _) => "exact".to_string(),
        (v, _) => v.name().to_string(),
    }
}

/// The items joined by "; ", or `none` where there are none.
fn listed(items: &[String], none: &str) -> String {
    if items.is_empty() {
        none.to_string()
    } else {
        items.join("; ")
    }
}

/// The last two successive rates of a row, as printed in rates.csv.
fn last_successive(r: &RateLine) -> String {
    let all: Vec<&str> = r.successive.split_whitespace().collect();
    all[all.len().saturating_sub(2)..].join(" ")
}

/// One convergence report read back: its rates and its errors at the finest level.
struct Report {
    rates: Vec<RateLine>,
    errors: Vec<ErrorLine>,
    /// The finest level measured.
    finest: usize,
}

impl Report {
    fn read(dir: &Path) -> Result<Report> {
        let rates: Vec<RateLine> = read(&dir.join("rates.csv"))?;
        let errors: Vec<ErrorLine> = read(&dir.join("errors.csv"))?;
        let finest = errors.iter().map(|e| e.level).max().unwrap_or(0);
        Ok(Report {
            rates,
            errors,
            finest,
        })
    }

    fn rate(&self, method: &str, quantity: &str) -> Option<&RateLine> {
        self.rates
            .iter()
            .find(|r| r.method == method && r.quantity == quantity)
    }

    /// The error of a cone in a quantity at the finest level.
    fn error(&self, method: &str, quantity: &str) -> Option<f64> {
        self.errors
            .iter()
            .find(|e| e.method == method && e.quantity == quantity && e.level == self.finest)
            .map(|e| e.error)
    }

    /// The contact quantities compared between the cones at the finest level.
    fn compare_cones(&self) -> Comparison<'_> {
        let mut c = Comparison::default();
        for r in self
            .rates
            .iter()
            .filter(|r| r.method == "mortar" && is_contact(&r.quantity))
        {
            let q = r.quantity.as_str();
            let Some(nts) = self.rate("nts", q) else {
                continue;
            };
            if !r.verdict.compares_cones() || !nts.verdict.compares_cones() {
                c.not_compared.push(q.to_string());
                continue;
            }
            let (Some(a), Some(b)) = (self.error("mortar", q), self.error("nts", q)) else {
                continue;
            };
            // A cone at round-off is exact: say so rather than divide by round-off.
            let exact = |v: Verdict| v == Verdict::RoundOff;
            let ratio = match (exact(r.verdict), exact(nts.verdict)) {
                (true, true) => 1.0,
                (true, false) => f64::INFINITY,
                (false, true) => 0.0,
                (false, false) => b / a,
            };
            if !(1.0 / SEPARATES..=SEPARATES).contains(&ratio) {
                c.separate.push(Separation {
                    quantity: q,
                    ratio,
                    mortar_error: a,
                    nts_error: b,
                    mortar: r,
                    nts,
                });
            } else {
                c.agree.push(q.to_string());
            }
        }
        c
    }

    /// The rows whose errors stop decreasing.
    fn stalled(&self) -> impl Iterator<Item = &RateLine> {
        self.rates
            .iter()
            .filter(|r| r.verdict == Verdict::NotConverging)
    }
}

/// A contact quantity whose errors differ between the cones by more than [`SEPARATES`].
struct Separation<'a> {
    quantity: &'a str,
    /// nts's error over mortar's at the finest level (infinite where mortar is exact, 0
    /// where nts is).
    ratio: f64,
    mortar_error: f64,
    nts_error: f64,
    mortar: &'a RateLine,
    nts: &'a RateLine,
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
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Results\n\nWhat the committed reports measured (`cargo run --release -- results` prints this page from their CSVs; a test fails when it no longer matches them). Rates are least-squares slopes in h over the levels named, with the verdict of [the rate rules](studies.md#rates) (fitted, drifting, pre-asymptotic, not converging, round-off, fixed by equilibrium).\n"
    );
    for (name, what) in STUDIES {
        let dir = reports.join(name);
        let report = Report::read(&dir)?;
        let finest = report.finest;
        let _ = writeln!(
            s,
            "## [`{name}`]({DOCS_REPORTS}/{name}/README.md): {what}\n"
        );
        // The theorem norm against Theorem 3.1 (where the study measures it).
        let theorem: Vec<String> = THEOREM
            .iter()
            .filter_map(|&(m, p)| {
                report
                    .rate(m, "theorem")
                    .map(|r| format!("{m} {}, Theorem 3.1: {p}", rate_text(r)))
            })
            .collect();
        if !theorem.is_empty() {
            let _ = writeln!(s, "- Theorem 3.1 norm: {}.", theorem.join("; "));
        }
        plasticity_and_time(&dir, &mut s)?;
        // Where nts attains h^(1/2).
        let half: Vec<String> = report
            .rates
            .iter()
            .filter(|r| r.method == "nts" && r.quantity != "theorem")
            .filter(|r| matches!(r.verdict, Verdict::Fitted | Verdict::Drifting))
            .filter(|r| r.rate.is_some_and(|v| (v - 0.5).abs() <= NEAR_HALF))
            .map(|r| {
                format!(
                    "{} {}, last successive rates {}",
                    r.quantity,
                    rate_text(r),
                    last_successive(r)
                )
            })
            .collect();
        let _ = writeln!(
            s,
            "- nts at h^(1/2) (a rate within {NEAR_HALF} of 0.5): {}.",
            listed(&half, "no quantity")
        );
        // Contact quantities that separate the cones at the finest level.
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
        let _ = writeln!(
            s,
            "- Contact quantities that separate the cones at level {finest} (error ratio beyond {SEPARATES}): {}.{}",
            listed(&separate, "none"),
            if comparison.agree.is_empty() {
                String::new()
            } else {
                format!(" Within {SEPARATES}x: {}.", comparison.agree.join(", "))
            },
        );
        if !comparison.not_compared.is_empty() {
            let _ = writeln!(
                s,
                "- Not compared (no rate the numbers support in some cone, or fixed by equilibrium): {}.",
                comparison.not_compared.join(", ")
            );
        }
        // What does not converge, and what carries no rate the numbers support.
        let stalled: Vec<String> = report
            .stalled()
            .map(|r| {
                let e = report
                    .error(&r.method, &r.quantity)
                    .map_or(String::new(), |e| {
                        format!(
                            " (at {e:.2e} at level {finest}; successive {})",
                            r.successive
                        )
                    });
                format!("{} {}{e}", r.method, r.quantity)
            })
            .collect();
        let _ = writeln!(s, "- Does not converge: {}.", listed(&stalled, "nothing"));
        let unfitted: Vec<String> = report
            .rates
            .iter()
            .filter(|r| {
                matches!(
                    r.verdict,
                    Verdict::PreAsymptotic | Verdict::FixedByEquilibrium | Verdict::TooFewLevels
                )
            })
            .map(|r| format!("{} {} ({})", r.method, r.quantity, r.verdict.name()))
            .collect();
        if !unfitted.is_empty() {
            let _ = writeln!(s, "- No rate claimed: {}.", unfitted.join(", "));
        }
        let _ = writeln!(s);
    }
    for (name, what) in TWO_SIZE {
        two_size_headline(reports, name, what, &mut s)?;
    }
    speed_and_stability(reports, &mut s)?;
    Ok(s)
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
    let mut s = String::new();
    // What separates the cones: which cone's error is the larger, and by how much.
    let (mut nts_larger, mut total, mut widest) = (0, 0, 1.0f64);
    let mut mortar_exact = Vec::new();
    for (name, _, report) in &studies {
        for c in report.compare_cones().separate {
            total += 1;
            if c.ratio > 1.0 {
                nts_larger += 1;
            }
            if c.ratio.is_infinite() {
                if !mortar_exact.contains(name) {
                    mortar_exact.push(*name);
                }
            } else if c.ratio > 0.0 {
                widest = widest.max(c.ratio.max(1.0 / c.ratio));
            }
        }
    }
    let exact = if mortar_exact.is_empty() {
        String::new()
    } else {
        format!(
            "; mortar is exact to round-off in {}",
            mortar_exact
                .iter()
                .map(|n| format!("`{n}`"))
                .collect::<Vec<_>>()
                .join(", ")
        )
    };
    let differ = if total == 0 {
        format!(
            "no contact quantity's error separates them (ratio beyond {SEPARATES}x at the finest level) in any of the {} studies",
            studies.len()
        )
    } else {
        format!(
            "over the {} studies, {total} contact-quantity errors separate them (ratio beyond {SEPARATES}x at the finest level), nts's the larger in {nts_larger}, by up to {widest:.0}x{exact}",
            studies.len()
        )
    };
    let _ = writeln!(s, "- **Where the cones differ:** {differ}.");
    // Theorem 3.1's norm: the fitted rates per cone over the studies that measure it.
    let theorem: Vec<String> = THEOREM
        .iter()
        .map(|&(m, p)| {
            let rows: Vec<&RateLine> = studies
                .iter()
                .filter_map(|(_, _, r)| r.rate(m, "theorem"))
                .collect();
            let fitted: Vec<f64> = rows
                .iter()
                .filter(|r| r.verdict == Verdict::Fitted)
                .filter_map(|r| r.rate)
                .collect();
            let (lo, hi) = fitted
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                    (a.min(v), b.max(v))
                });
            let unfitted = rows.len() - fitted.len();
            let range = if fitted.is_empty() {
                "no fitted rate".to_string()
            } else if format!("{lo:.2}") == format!("{hi:.2}") {
                format!("{lo:.2}")
            } else {
                format!("{lo:.2}-{hi:.2}")
            };
            let more = if unfitted > 0 {
                format!(", {unfitted} not fitted")
            } else {
                String::new()
            };
            format!(
                "{m} {range} (Theorem 3.1: {p}; {} studies{more})",
                rows.len()
            )
        })
        .collect();
    let _ = writeln!(
        s,
        "- **Theorem 3.1's norm**, fitted rates in h: {}.",
        theorem.join("; ")
    );
    // What does not converge, each (cone, quantity) with the studies where it stalls.
    let mut stalled: Vec<(String, Vec<&str>)> = Vec::new();
    for (name, _, report) in &studies {
        for r in report.stalled() {
            let key = format!("{} `{}`", r.method, r.quantity);
            match stalled.iter_mut().find(|(k, _)| *k == key) {
                Some((_, names)) => names.push(name),
                None => stalled.push((key, vec![name])),
            }
        }
    }
    let stalled: Vec<String> = stalled
        .iter()
        .map(|(k, names)| format!("{k} (in {})", names.join(", ")))
        .collect();
    let _ = writeln!(
        s,
        "- **Does not converge:** {}.\n",
        listed(&stalled, "nothing")
    );
    let _ = writeln!(
        s,
        "| study: scene, measured against | where the cones differ: contact quantities at the finest level, nts's error / mortar's (rates) | does not converge | rate, mortar (Theorem 3.1: {}) | rate, nts (Theorem 3.1: {}) |\n|---|---|---|---|---|",
        THEOREM[0].1, THEOREM[1].1
    );
    for (name, what, report) in &studies {
        let mut comparison = report.compare_cones();
        // The widest gap first; an exact cone (an infinite or zero ratio) leads.
        comparison.separate.sort_by(|a, b| {
            let gap = |c: &Separation| c.ratio.max(1.0 / c.ratio);
            gap(b).total_cmp(&gap(a))
        });
        let separate: Vec<String> = comparison
            .separate
            .iter()
            .map(|c| {
                let q = c.quantity;
                let (mortar, nts) = (rate_short(c.mortar), rate_short(c.nts));
                if c.ratio.is_infinite() {
                    format!("`{q}` mortar exact (nts {nts})")
                } else if c.ratio == 0.0 {
                    format!("`{q}` nts exact (mortar {mortar})")
                } else if c.ratio >= 10.0 {
                    format!("`{q}` {:.0}x (mortar {mortar}, nts {nts})", c.ratio)
                } else {
                    format!("`{q}` {:.1}x (mortar {mortar}, nts {nts})", c.ratio)
                }
            })
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
        let stalled = if stalled.is_empty() {
            "nothing".to_string()
        } else {
            stalled.join(", ")
        };
        let judged = |m: &str| {
            report
                .rates
                .iter()
                .find(|r| r.method == m && r.threshold.is_some())
                .map_or("not measured".to_string(), |r| {
                    let rate = match (r.verdict, r.rate, r.stderr) {
                        (Verdict::Fitted | Verdict::Drifting, Some(v), Some(se)) => {
                            format!("{v:.3} ± {se:.3} {}", r.verdict.name())
                        }
                        (Verdict::RoundOff, _, _) => "exact (round-off)".to_string(),
                        _ => rate_short(r),
                    };
                    if r.quantity == "theorem" {
                        rate
                    } else {
                        format!("`{}` {rate}", r.quantity)
                    }
                })
        };
        let _ = writeln!(
            s,
            "| [`{name}`]({README_REPORTS}/{name}/README.md): {what} | {separate} | {stalled} | {} | {} |",
            judged("mortar"),
            judged("nts")
        );
    }
    Ok(s)
}

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

/// One row of a two-size report's fits.csv (the columns read here).
#[derive(Debug, Deserialize)]
struct SizeFitLine {
    slave: String,
    method: String,
    quantity: String,
    a1: Option<f64>,
    se_a1: Option<f64>,
    a2: Option<f64>,
    se_a2: Option<f64>,
    rms_log_residual: Option<f64>,
}

/// One row of a two-size report's grid.csv (the columns read here).
#[derive(Debug, Deserialize)]
struct SizePointLine {
    slave: String,
    method: String,
    slave_level: usize,
    master_level: usize,
    quantity: String,
    error: f64,
}

/// The theorem norm's exponents per slave choice and cone, and what refining each body
/// alone from the finest grid diagonal point does to the theorem error and the penetration.
fn two_size_headline(reports: &Path, name: &str, what: &str, s: &mut String) -> Result<()> {
    let dir = reports.join(name);
    let fits: Vec<SizeFitLine> = read(&dir.join("fits.csv"))?;
    let grid: Vec<SizePointLine> = read(&dir.join("grid.csv"))?;
    let _ = writeln!(
        s,
        "## [`{name}`]({DOCS_REPORTS}/{name}/README.md): {what}
"
    );
    let exponent = |v: Option<f64>, se: Option<f64>, rms: Option<f64>| match (v, se, rms) {
        (Some(v), Some(se), Some(rms)) if rates::fit_identifies(se, rms) => {
            format!("{v:.2} ± {se:.2}")
        }
        _ => "not identified".into(),
    };
    let mut slaves: Vec<&str> = fits.iter().map(|f| f.slave.as_str()).collect();
    slaves.dedup();
    for slave in &slaves {
        let parts: Vec<String> = fits
            .iter()
            .filter(|f| f.slave == *slave && f.quantity == "theorem")
            .map(|f| {
                format!(
                    "{} a1 {}, a2 {}",
                    f.method,
                    exponent(f.a1, f.se_a1, f.rms_log_residual),
                    exponent(f.a2, f.se_a2, f.rms_log_residual)
                )
            })
            .collect();
        let _ = writeln!(
            s,
            "- Theorem norm, E = C1 h1^a1 + C2 h2^a2 with slave '{slave}' (Lemma 3.1: mortar (0.75, 1), nts (0.5, 0.75)): {}.",
            parts.join("; ")
        );
    }
    // From the finest diagonal point, each body refined alone to the fixed level.
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
    let error = |slave: &str, m: &str, q: &str, l: [usize; 2]| {
        grid.iter()
            .find(|p| {
                p.slave == slave
                    && p.method == m
                    && p.quantity == q
                    && [p.slave_level, p.master_level] == l
            })
            .map(|p| p.error)
    };
    if let Some(slave) = slaves.first() {
        let mut parts = Vec::new();
        for m in ["mortar", "nts"] {
            for q in ["theorem", "max_penetration"] {
                let (Some(base), Some(s1), Some(s2)) = (
                    error(slave, m, q, [finest, finest]),
                    error(slave, m, q, [top, finest]),
                    error(slave, m, q, [finest, top]),
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
        let _ = writeln!(
            s,
            "- From ({finest}, {finest}), slave '{slave}', one body refined to level {top}: {}.",
            parts.join("; ")
        );
    }
    let _ = writeln!(s);
    Ok(())
}

/// One row of a report's levels.csv (the columns read here).
#[derive(Debug, Deserialize)]
struct LevelLine {
    method: String,
    level: usize,
    plastic_fraction: f64,
}

/// One row of a report's time.csv.
#[derive(Debug, Deserialize)]
struct TimeLine {
    steps: usize,
    k: f64,
    error: f64,
}

/// The plastic fraction at T of the finest level (where the bodies flow), and the rate in
/// k of the time study (where there is one), judged again from time.csv by the rule that
/// judged it ([`rates::assess`]).
fn plasticity_and_time(dir: &Path, s: &mut String) -> Result<()> {
    let levels: Vec<LevelLine> = read(&dir.join("levels.csv"))?;
    let finest = levels.iter().map(|l| l.level).max().unwrap_or(0);
    let plastic: Vec<String> = levels
        .iter()
        .filter(|l| l.level == finest && l.plastic_fraction > 0.0)
        .map(|l| format!("{} {:.3}", l.method, l.plastic_fraction))
        .collect();
    if !plastic.is_empty() {
        let _ = writeln!(
            s,
            "- Plastic fraction at T, level {finest}: {}.",
            plastic.join(", ")
        );
    }
    let path = dir.join("time.csv");
    if !path.exists() {
        return Ok(());
    }
    let runs: Vec<TimeLine> = read(&path)?;
    let judged: Vec<(usize, f64, f64)> = runs.iter().map(|r| (r.steps, r.k, r.error)).collect();
    let a = rates::assess_in_k(&judged)
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
    let _ = writeln!(
        s,
        "- Rate in k (time study, backward Euler's k term: 1): {rate}."
    );
    Ok(())
}

/// One row of reports/speed/speed.csv (the columns read here).
#[derive(Debug, Deserialize)]
struct SpeedLine {
    solver: String,
    dofs: usize,
    ratio_to_floor: f64,
    family: String,
    /// Threads of the solver and the floor (absent in reports before threads were used).
    #[serde(default)]
    threads: Option<usize>,
}

/// One row of reports/stability/stability.csv (the columns read here).
#[derive(Debug, Deserialize)]
struct StabilityLine {
    case: String,
    parameter: String,
    method: String,
    solver: String,
    converged: bool,
    max_step_iterations: usize,
}

/// The paper's tests (a link), the cost of the default solver against the floor, and the
/// hard cases.
fn speed_and_stability(reports: &Path, s: &mut String) -> Result<()> {
    let speed: Vec<SpeedLine> = read(&reports.join("speed").join("speed.csv"))?;
    let newton: Vec<&SpeedLine> = speed
        .iter()
        .filter(|r| r.solver == "newton" && r.dofs >= 10_000)
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
    let threads = match speed.first().and_then(|r| r.threads) {
        Some(t) => format!(" ({t} threads, the solver and the floor alike)"),
        None => String::new(),
    };
    let _ = writeln!(
        s,
        "## [`paper`]({DOCS_REPORTS}/paper/README.md): the paper's three tests regenerated\n\n- Every figure of its section 5 and the numbers behind its words (no rates: one mesh per test).\n"
    );
    let _ = writeln!(
        s,
        "## [`speed`]({DOCS_REPORTS}/speed/README.md): cost against the floor (one Cholesky of the stiffness)

- newton's (set-up + time loop) / floor from 1e4 to {top} dofs{threads}: {}.
",
        ranges.join(", ")
    );
    let stability: Vec<StabilityLine> = read(&reports.join("stability").join("stability.csv"))?;
    let failed = |solver: &str| {
        stability
            .iter()
            .filter(|r| r.solver == solver && !r.converged)
            .count()
    };
    let total = |solver: &str| stability.iter().filter(|r| r.solver == solver).count();
    let worst = stability
        .iter()
        .filter(|r| r.solver == "newton" && r.converged)
        .max_by_key(|r| r.max_step_iterations);
    let _ = writeln!(
        s,
        "## [`stability`]({DOCS_REPORTS}/stability/README.md): hard cases, every solver

- Not converged: newton {} of {}, paper {} of {}, qp {} of {}.{}
",
        failed("newton"),
        total("newton"),
        failed("paper"),
        total("paper"),
        failed("qp"),
        total("qp"),
        worst.map_or(String::new(), |w| format!(
            " newton's most iterations in one step: {} ({}, {}, {}).",
            w.max_step_iterations, w.case, w.parameter, w.method
        ))
    );
    Ok(())
}
