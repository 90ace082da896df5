//! The one judge: a table of errors (method, quantity, level, h, dofs, error) turned into
//! judged rates ([`RateRow`]) by [`judge_errors`], the one threshold rule ([`Threshold`],
//! [`crate::verify::rates::threshold_outcome`]), and each method read against its distance
//! to mortar ([`decomposition`]). Every study kind, `grade`, `judge` and `results` judge
//! through here; rates.csv is a view of [`RateRow`] ([`RateRecord`]).

use crate::verify::quantity::Quantity;
use crate::verify::rates::{self, Assessment, EqualH, LevelError, Outcome, Verdict};
use crate::verify::table::{ErrorRecord, MethodLabel, RateRecord};
use serde::Serialize;

/// What a method's error in the threshold quantity must satisfy.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Threshold {
    /// A rate in h of at least this (Theorem 3.1's rate minus the tolerance), judged by
    /// [`rates::threshold_outcome`].
    Rate(f64),
    /// Every level's relative error at most this (a method exact on the scene).
    Exact(f64),
}

impl Threshold {
    /// The number: the required rate or the error bound.
    pub fn value(self) -> f64 {
        match self {
            Threshold::Rate(v) | Threshold::Exact(v) => v,
        }
    }

    /// The outcome for errors judged as `a`, the largest `max_error`: the rule of
    /// [`rates::threshold_outcome`] for a rate; pass or fail on the bound for exactness.
    pub fn outcome(self, a: &Assessment, max_error: f64) -> Outcome {
        match self {
            Threshold::Exact(bound) if max_error <= bound => Outcome::Pass,
            Threshold::Exact(_) => Outcome::Fail,
            Threshold::Rate(rate) => rates::threshold_outcome(a, rate),
        }
    }
}

/// A ratio of two methods' errors at the finest level beyond this (either way) separates
/// them: one rule for every study's lead and every grade report's.
pub const SEPARATES: f64 = 1.5;

/// The judge's level records of any table: (level, h, dofs, error) rows, coarsest first.
/// The one place a table becomes what [`rates::assess`] reads.
pub fn levels_of(rows: impl IntoIterator<Item = (usize, f64, f64, f64)>) -> Vec<LevelError> {
    rows.into_iter()
        .map(|(level, h, dofs, error)| LevelError {
            level,
            h,
            dofs,
            error,
        })
        .collect()
}

/// The level records of one group of errors.csv rows.
pub fn levels_of_errors(rows: &[&ErrorRecord]) -> Vec<LevelError> {
    levels_of(rows.iter().map(|r| (r.level, r.h, r.dofs as f64, r.error)))
}

/// Judge a rate in the time step k as a rate in h is judged ([`rates::assess`] with k in
/// place of h, the runs in order of halving k, the truth exact in time): one rule for the
/// time studies and for the README's reading of their `time.csv`. `runs` are (steps, k,
/// error).
pub fn assess_in_k(runs: &[(usize, f64, f64)]) -> Result<Assessment, EqualH> {
    let levels = levels_of(
        runs.iter()
            .enumerate()
            .map(|(i, &(steps, k, error))| (i, k, steps as f64, error)),
    );
    rates::assess(&levels, 0.0)
}

/// One method's errors in one quantity, judged: the type every study kind, `grade`,
/// `judge`, the plots and rates.csv ([`RateRow::record`]) use.
#[derive(Debug, Clone)]
pub struct RateRow {
    /// The method (a cone, or a graded code's label).
    pub method: MethodLabel,
    /// Quantity.
    pub quantity: Quantity,
    /// The scene family's parameter, for a study over a family of scenes.
    pub parameter: Option<f64>,
    /// What the errors support: verdict, fit, window, judged and successive rates, Celik.
    pub assessment: Assessment,
    /// What the error must satisfy (the threshold quantity only).
    pub threshold: Option<Threshold>,
    /// What it makes of the errors.
    pub outcome: Option<Outcome>,
}

impl RateRow {
    /// The fitted rate in h, NaN when there is none.
    pub fn rate(&self) -> f64 {
        self.assessment.fit.map_or(f64::NAN, |f| f.rate)
    }
    /// Its standard error, NaN when there is none.
    pub fn stderr(&self) -> f64 {
        self.assessment.fit.map_or(f64::NAN, |f| f.stderr)
    }
    /// Rate against dofs (error ~ dofs^-rate_dofs), over the same levels.
    pub fn rate_dofs(&self) -> Option<f64> {
        self.assessment.fit_dofs.map(|f| -f.rate)
    }
    /// The fit where the verdict supports a rate.
    pub fn supported_fit(&self) -> Option<rates::Fit> {
        self.assessment
            .fit
            .filter(|_| self.assessment.verdict.supports_rate())
    }
    /// The fitted line to draw through `rows` (this row's errors): its legend after the
    /// method's name, its rate and intercept (the fit's own), and the h of the levels it
    /// was fitted on. None without a fit; a pre-asymptotic fit says so in its legend.
    pub fn line(&self, rows: &[&ErrorRecord]) -> Option<(String, f64, f64, Vec<f64>)> {
        let fit = self.assessment.fit?;
        let hs: Vec<f64> = rows
            .iter()
            .filter(|r| self.assessment.used.contains(&r.level))
            .map(|r| r.h)
            .collect();
        let flag = match self.assessment.verdict {
            Verdict::Fitted => "",
            v => v.name(),
        };
        let legend = match flag {
            "" => format!("fit: slope {:.2} ± {:.2}", fit.rate, fit.stderr),
            _ => format!("fit ({flag}): slope {:.2} ± {:.2}", fit.rate, fit.stderr),
        };
        Some((legend, fit.rate, fit.intercept, hs))
    }
    /// "0.968 ± 0.009 (fitted)" where the verdict supports a rate, else "no rate: " and
    /// what the verdict says ([`Assessment::describe`]).
    pub fn describe_with_verdict(&self) -> String {
        match self.supported_fit() {
            Some(f) => format!("{:.3} ± {:.3} (fitted)", f.rate, f.stderr),
            None => format!("no rate: {}", self.assessment.describe().replace("**", "")),
        }
    }
    /// The rate or what replaces it, in a few characters ([`rates::short_text`]).
    pub fn short_text(&self) -> String {
        let a = &self.assessment;
        rates::short_text(a.verdict, a.fit.map(|f| f.rate), a.last_rate())
    }
    /// "method quantity: " and the verdict as one plain line ([`Assessment::verdict_line`]),
    /// with the threshold's outcome and why (an exactness bound: whether every level's error
    /// is within it).
    pub fn verdict_line(&self) -> String {
        let a = &self.assessment;
        let line = match (self.threshold, self.outcome) {
            (Some(Threshold::Rate(t)), Some(o)) => a.verdict_line(Some((t, o))),
            (Some(Threshold::Exact(t)), Some(o)) => format!(
                "{}; exactness bound {t:.0e}: {}",
                a.verdict_line(None),
                match o {
                    Outcome::Pass => "pass, every level's error is at most it",
                    _ => "FAIL, a level's error is above it",
                }
            ),
            _ => a.verdict_line(None),
        };
        format!("{} {}: {line}", self.method, self.quantity)
    }
    /// The row of rates.csv.
    pub fn record(&self) -> RateRecord {
        RateRecord::from_parts(
            self.method.clone(),
            self.quantity,
            self.parameter,
            &self.assessment,
            self.threshold.map(Threshold::value),
            self.outcome,
        )
    }
    /// The sentence of a threshold this row failed (None: it did not fail).
    pub fn failure(&self) -> Option<String> {
        if self.outcome != Some(Outcome::Fail) {
            return None;
        }
        let (method, quantity) = (&self.method, self.quantity);
        Some(match self.threshold? {
            Threshold::Exact(t) => {
                format!("{method} {quantity} error above the exactness tolerance {t:.1e}")
            }
            Threshold::Rate(t) => format!(
                "{method} {quantity} last successive rate {} < {t:.3} ({})",
                crate::io::fmt3(self.assessment.last_rate().unwrap_or(f64::NAN)),
                self.assessment.verdict.name()
            ),
        })
    }
    /// The sentence of a threshold this row neither met nor missed (None otherwise).
    pub fn unverified(&self) -> Option<String> {
        if self.outcome != Some(Outcome::Unverified) {
            return None;
        }
        Some(format!(
            "{} {}: threshold {} unverified: {}",
            self.method,
            self.quantity,
            crate::io::fmt3(self.threshold?.value()),
            self.assessment.describe().replace("**", "")
        ))
    }
}

/// Two levels of one group with the same h: which group, and the levels.
#[derive(Debug, Clone)]
pub struct GroupEqualH {
    /// "method quantity" of the group.
    pub group: String,
    /// The two levels.
    pub equal: EqualH,
}

impl std::fmt::Display for GroupEqualH {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.group, self.equal)
    }
}

/// How [`judge_errors`] judges a table.
pub struct Rules<'a> {
    /// The truth's own estimated error in a quantity (0 for an exact solution).
    pub truth_error: &'a dyn Fn(Quantity) -> f64,
    /// Whether equilibrium fixes the contact resultant of this project's cones (a body
    /// held normal to Gamma_C only by the contact): their `pressure_resultant` is then
    /// named so and never fitted. A graded code's resultant is judged like any quantity.
    pub resultant_fixed: bool,
    /// The threshold of a method's quantity, if any.
    pub threshold: &'a dyn Fn(&MethodLabel, Quantity) -> Option<Threshold>,
}

/// The groups of `errors` in order of first appearance: parameter, then method, then
/// quantity; each group's rows in table order (coarsest first).
pub fn groups(errors: &[ErrorRecord]) -> Vec<Vec<&ErrorRecord>> {
    let mut keys: Vec<(Option<u64>, &MethodLabel, Quantity)> = Vec::new();
    let (mut params, mut methods, mut quantities) = (Vec::new(), Vec::new(), Vec::new());
    for r in errors {
        let p = r.parameter.map(f64::to_bits);
        if !params.contains(&p) {
            params.push(p);
        }
        if !methods.contains(&&r.method) {
            methods.push(&r.method);
        }
        if !quantities.contains(&r.quantity) {
            quantities.push(r.quantity);
        }
    }
    for p in &params {
        for m in &methods {
            for q in &quantities {
                keys.push((*p, m, *q));
            }
        }
    }
    keys.into_iter()
        .map(|(p, m, q)| {
            errors
                .iter()
                .filter(|r| r.parameter.map(f64::to_bits) == p && &r.method == m && r.quantity == q)
                .collect::<Vec<_>>()
        })
        .filter(|g| !g.is_empty())
        .collect()
}

/// One group's levels judged ([`rates::assess`], truth `truth_error`), and its threshold's
/// outcome; `resultant_fixed`: the group is a cone's contact resultant fixed by
/// equilibrium ([`rates::judge`]). The per-group step of [`judge_errors`] and of `judge`
/// on anyone's table.
pub fn judge_levels(
    levels: &[LevelError],
    truth_error: f64,
    resultant_fixed: bool,
    threshold: Option<Threshold>,
) -> Result<(Assessment, Option<Outcome>), EqualH> {
    let assessment = rates::judge(levels, truth_error, resultant_fixed)?;
    let max_error = levels.iter().map(|l| l.error).fold(0.0f64, f64::max);
    let outcome = threshold.map(|t| t.outcome(&assessment, max_error));
    Ok((assessment, outcome))
}

/// Every group of `errors` (parameter, method, quantity) judged by the rules of
/// [`rates::assess`], with its threshold's outcome: the one judging loop.
pub fn judge_errors(errors: &[ErrorRecord], rules: &Rules) -> Result<Vec<RateRow>, GroupEqualH> {
    groups(errors)
        .into_iter()
        .map(|rows| {
            let (method, quantity) = (rows[0].method.clone(), rows[0].quantity);
            let fixed = rules.resultant_fixed
                && method.cone().is_some()
                && quantity == Quantity::PressureResultant;
            let threshold = (rules.threshold)(&method, quantity);
            let (assessment, outcome) = judge_levels(
                &levels_of_errors(&rows),
                (rules.truth_error)(quantity),
                fixed,
                threshold,
            )
            .map_err(|equal| GroupEqualH {
                group: format!("{method} {quantity}"),
                equal,
            })?;
            Ok(RateRow {
                method,
                quantity,
                parameter: rows[0].parameter,
                assessment,
                threshold,
                outcome,
            })
        })
        .collect()
}

/// The quantities of a method's error that are read against its distance to mortar, and
/// the distance quantity of each.
pub const DECOMPOSED: [(Quantity, Quantity); 3] = [
    (Quantity::Theorem, Quantity::ConeDistance),
    (Quantity::H1U, Quantity::ConeDistanceH1U),
    (Quantity::L2Stress, Quantity::ConeDistanceL2Stress),
];

/// One row of decomposition.csv: a method X's error beside mortar's and the distance D
/// between the two solutions on the same meshes, which bound it from both sides
/// (D - e_mortar <= e_X <= D + e_mortar).
#[derive(Debug, Clone, Serialize)]
pub struct DecompositionRow {
    /// The scene family's parameter, for a study over a family of scenes.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub parameter: Option<f64>,
    /// X.
    pub method: MethodLabel,
    /// The error's quantity.
    pub quantity: Quantity,
    /// Mesh level.
    pub level: usize,
    /// Max element diameter (length).
    pub h: f64,
    /// X's relative error.
    pub error: f64,
    /// Mortar's relative error on the same level.
    pub mortar_error: f64,
    /// The distance between X's and mortar's solutions, relative as the errors are.
    pub distance: f64,
    /// error / sqrt(mortar_error^2 + distance^2) - 1: descriptive (0 where the two parts
    /// are orthogonal).
    pub pythagorean: f64,
}

/// The rows of decomposition.csv: for every method other than mortar that has a distance
/// to mortar in `errors`, each level's error, mortar's and the distance, for the theorem
/// norm, h1_u and l2_stress.
pub fn decomposition(errors: &[ErrorRecord]) -> Vec<DecompositionRow> {
    let find = |p: Option<f64>, m: &MethodLabel, q: Quantity, level: usize| {
        errors
            .iter()
            .find(|r| r.parameter == p && &r.method == m && r.quantity == q && r.level == level)
    };
    let mortar = MethodLabel::Cone(crate::contact::Method::reference());
    let mut out = Vec::new();
    for group in groups(errors) {
        let first = group[0];
        let Some(&(quantity, _)) = DECOMPOSED.iter().find(|(_, d)| *d == first.quantity) else {
            continue;
        };
        if first.method == mortar {
            continue;
        }
        for d in group {
            let (Some(x), Some(m)) = (
                find(d.parameter, &d.method, quantity, d.level),
                find(d.parameter, &mortar, quantity, d.level),
            ) else {
                continue;
            };
            out.push(DecompositionRow {
                parameter: d.parameter,
                method: d.method.clone(),
                quantity,
                level: d.level,
                h: d.h,
                error: x.error,
                mortar_error: m.error,
                distance: d.error,
                pythagorean: x.error / m.error.hypot(d.error) - 1.0,
            });
        }
    }
    out
}

/// What a method's distance to mortar predicts of its error: the asymptotic rate
/// min(r_D, r_mortar) and where D overtakes mortar's error, or why nothing is predicted.
#[derive(Debug, Clone, PartialEq)]
enum Asymptote {
    /// D's verdict supports no rate (or mortar's none): nothing is predicted.
    Unsupported {
        /// D's verdict.
        distance: Verdict,
        /// Mortar's verdict.
        mortar: Verdict,
    },
    /// D's rate is at or above mortar's: the distance never dominates.
    MortarRate {
        /// Mortar's fitted rate.
        rate: f64,
    },
    /// D's rate is below mortar's: X tends to D's rate.
    DistanceRate {
        /// The asymptotic rate min(r_D, r_mortar) = r_D (D's fit).
        rate: f64,
        /// Its standard error.
        stderr: f64,
        /// Where D overtakes e_mortar already in the data (the first level where
        /// D >= e_mortar and stays so), if it does.
        observed: Option<usize>,
        /// Otherwise the levels where D's line crosses mortar's, with D's rate taken over
        /// its range (the window's fit, the last successive rate, the fit over every level)
        /// and D's line anchored at D's finest level, mortar's at its fit (fractional
        /// levels, lowest and highest; no highest where a rate in D's range is at or above
        /// mortar's: the lines may never cross).
        predicted: Option<(f64, Option<f64>)>,
    },
}

/// [`Asymptote`] of method X from the judged rows of D (`distance`) and of mortar's error
/// in the same quantity, with their errors (`d_errors`, `m_errors`: (level, h, error),
/// coarsest first).
fn asymptote(
    distance: &RateRow,
    mortar: &RateRow,
    d_errors: &[(usize, f64, f64)],
    m_errors: &[(usize, f64, f64)],
) -> Asymptote {
    let (Some(fd), Some(fm)) = (distance.supported_fit(), mortar.supported_fit()) else {
        return Asymptote::Unsupported {
            distance: distance.assessment.verdict,
            mortar: mortar.assessment.verdict,
        };
    };
    // "D falls no slower than mortar's error" is a rate claim: the one rule's, D's fit and
    // its last judged rate both at mortar's rate.
    if crate::verify::rates::reaches(&distance.assessment, fm.rate, 0.0) {
        return Asymptote::MortarRate { rate: fm.rate };
    }
    if fd.rate >= fm.rate {
        // D's fit reaches mortar's rate and its last judged rate does not: undecided.
        return Asymptote::Unsupported {
            distance: distance.assessment.verdict,
            mortar: mortar.assessment.verdict,
        };
    }
    let observed = (0..d_errors.len())
        .find(|&i| {
            d_errors[i..].iter().all(|&(level, _, d)| {
                m_errors
                    .iter()
                    .find(|m| m.0 == level)
                    .is_some_and(|m| d >= m.2)
            })
        })
        .map(|i| d_errors[i].0);
    let predicted = match (observed, d_errors.last()) {
        (None, Some(&(level, h, d))) => {
            let halving = h.ln() - d_errors[d_errors.len() - 2].1.ln();
            let per_level = halving / (level as f64 - d_errors[d_errors.len() - 2].0 as f64);
            let candidates = [
                Some(fd.rate),
                distance.assessment.last_rate(),
                distance.assessment.fit_all.map(|f| f.rate),
            ];
            let rates: Vec<f64> = candidates.into_iter().flatten().collect();
            // A rate in D's range at or above mortar's never crosses: no upper end.
            let never = rates.iter().any(|r| *r >= fm.rate);
            let crossings: Vec<f64> = rates
                .into_iter()
                .filter(|r| *r < fm.rate)
                .map(|rd| {
                    // ln D(h) = ln d + rd (ln h - ln h_f); ln e_m(h) = c_m + rm ln h.
                    let log_h = (fm.intercept - d.ln() + rd * h.ln()) / (rd - fm.rate);
                    level as f64 + (log_h - h.ln()) / per_level
                })
                .collect();
            (!crossings.is_empty()).then(|| {
                (
                    crossings.iter().copied().fold(f64::INFINITY, f64::min),
                    (!never).then(|| crossings.iter().copied().fold(f64::NEG_INFINITY, f64::max)),
                )
            })
        }
        _ => None,
    };
    Asymptote::DistanceRate {
        rate: fd.rate,
        stderr: fd.stderr,
        observed,
        predicted,
    }
}

/// One row of asymptotes.csv: what a method X's distance to mortar says of X's error in
/// one quantity ([`Asymptote`]), with the decomposition's largest |pythagorean| and
/// D / e_mortar at the finest level.
#[derive(Debug, Clone, Serialize, serde::Deserialize)]
pub struct AsymptoteRow {
    /// X.
    pub method: MethodLabel,
    /// X's error's quantity.
    pub quantity: Quantity,
    /// X's own verdict in that quantity.
    pub verdict: Verdict,
    /// X's last judged rate.
    pub last_rate: Option<f64>,
    /// D's verdict.
    pub distance_verdict: Verdict,
    /// Mortar's verdict.
    pub mortar_verdict: Verdict,
    /// The asymptotic rate min(r_D, r_mortar), where D's and mortar's verdicts support
    /// rates.
    pub asymptotic_rate: Option<f64>,
    /// Its standard error.
    pub asymptotic_stderr: Option<f64>,
    /// Whether that rate is D's (D falls slower than mortar's error).
    pub distance_sets_rate: Option<bool>,
    /// The first level from which D >= e_mortar in the data.
    pub overtakes_from: Option<usize>,
    /// Otherwise the predicted crossing level, lowest and highest over D's rate range.
    pub predicted_from: Option<f64>,
    /// The highest; empty beside a lowest where a rate in D's range reaches mortar's (the
    /// lines may never cross).
    pub predicted_to: Option<f64>,
    /// Largest |pythagorean| over the levels.
    pub largest_pythagorean: Option<f64>,
    /// D / e_mortar at the finest level.
    pub finest_ratio: Option<f64>,
    /// The finest level.
    pub finest_level: usize,
}

/// The rows of asymptotes.csv for every method other than mortar with a distance to
/// mortar in `errors`, judged as `rates`.
pub fn asymptotes(rates: &[RateRow], errors: &[ErrorRecord]) -> Vec<AsymptoteRow> {
    let mortar = MethodLabel::Cone(crate::contact::Method::reference());
    let decomposition = decomposition(errors);
    let find =
        |m: &MethodLabel, q: Quantity| rates.iter().find(|r| &r.method == m && r.quantity == q);
    let series = |m: &MethodLabel, q: Quantity| -> Vec<(usize, f64, f64)> {
        errors
            .iter()
            .filter(|e| &e.method == m && e.quantity == q)
            .map(|e| (e.level, e.h, e.error))
            .collect()
    };
    let mut out = Vec::new();
    for d in rates.iter().filter(|r| r.method != mortar) {
        let Some(&(q, dq)) = DECOMPOSED.iter().find(|(_, dq)| *dq == d.quantity) else {
            continue;
        };
        let (Some(x), Some(m)) = (find(&d.method, q), find(&mortar, q)) else {
            continue;
        };
        let rows: Vec<&DecompositionRow> = decomposition
            .iter()
            .filter(|r| r.method == d.method && r.quantity == q)
            .collect();
        let Some(last) = rows.last() else {
            continue;
        };
        let largest = rows
            .iter()
            .map(|r| r.pythagorean.abs())
            .fold(None, |a: Option<f64>, v| Some(a.map_or(v, |a| a.max(v))));
        let mut row = AsymptoteRow {
            method: d.method.clone(),
            quantity: q,
            verdict: x.assessment.verdict,
            last_rate: x.assessment.last_rate(),
            distance_verdict: d.assessment.verdict,
            mortar_verdict: m.assessment.verdict,
            asymptotic_rate: None,
            asymptotic_stderr: None,
            distance_sets_rate: None,
            overtakes_from: None,
            predicted_from: None,
            predicted_to: None,
            largest_pythagorean: largest,
            finest_ratio: Some(last.distance / last.mortar_error),
            finest_level: last.level,
        };
        match asymptote(d, m, &series(&d.method, dq), &series(&mortar, q)) {
            Asymptote::Unsupported { .. } => {}
            Asymptote::MortarRate { rate } => {
                row.asymptotic_rate = Some(rate);
                row.asymptotic_stderr = m.supported_fit().map(|f| f.stderr);
                row.distance_sets_rate = Some(false);
            }
            Asymptote::DistanceRate {
                rate,
                stderr,
                observed,
                predicted,
            } => {
                row.asymptotic_rate = Some(rate);
                row.asymptotic_stderr = Some(stderr);
                row.distance_sets_rate = Some(true);
                row.overtakes_from = observed;
                row.predicted_from = predicted.map(|p| p.0);
                row.predicted_to = predicted.and_then(|p| p.1);
            }
        }
        out.push(row);
    }
    out
}

impl AsymptoteRow {
    /// What D supports of X's asymptotic rate, in a few words: "tends to D's 0.504 ± 0.005
    /// (D >= e_mortar from level 3)", "tends to D's 0.57 ± 0.03 past level 11.9-16.0",
    /// "tends to mortar's 0.98", or "no asymptotic rate predicted (D falling)".
    pub fn describe(&self) -> String {
        match (self.asymptotic_rate, self.distance_sets_rate) {
            (Some(r), Some(true)) => {
                let se = self.asymptotic_stderr.unwrap_or(f64::NAN);
                match (self.overtakes_from, self.predicted_from, self.predicted_to) {
                    (Some(l), _, _) => {
                        format!(
                            "tends to D's rate {r:.3} ± {se:.3} (D >= e_mortar from level {l} on)"
                        )
                    }
                    (None, Some(a), Some(b)) => {
                        format!("tends to D's rate {r:.3} ± {se:.3} past level {a:.1}-{b:.1}")
                    }
                    (None, Some(a), None) => format!(
                        "tends to D's rate {r:.3} ± {se:.3} past level {a:.1}, or never (D's rate over its range reaches mortar's)"
                    ),
                    _ => format!("tends to D's rate {r:.3} ± {se:.3}"),
                }
            }
            (Some(r), _) => format!("tends to mortar's rate {r:.3} (D falls no slower)"),
            _ if self.distance_verdict.supports_rate() && self.mortar_verdict.supports_rate() => {
                "no asymptotic rate predicted (D's fit reaches mortar's rate, its last judged rate does not)".into()
            }
            _ => format!(
                "no asymptotic rate predicted (D {}, mortar {})",
                self.distance_verdict.name(),
                self.mortar_verdict.name()
            ),
        }
    }
}
