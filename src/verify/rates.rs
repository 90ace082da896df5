//! Convergence rates: least-squares slopes with standard errors, and successive rates.

/// A fitted rate: error ~ C h^rate.
#[derive(Debug, Clone, Copy)]
pub struct Fit {
    /// Slope of log(error) against log(h).
    pub rate: f64,
    /// Standard error of the slope (0 with two points).
    pub stderr: f64,
    /// log C.
    pub intercept: f64,
}

/// Least-squares fit of log(y) = intercept + rate log(x); None with fewer than 2 points.
/// Values of y at or below 1e-12 are left out: relative errors at round-off carry no rate.
pub fn fit(x: &[f64], y: &[f64]) -> Option<Fit> {
    let pts: Vec<(f64, f64)> = x
        .iter()
        .zip(y)
        .filter(|(a, b)| **a > 0.0 && **b > 1e-12 && a.is_finite() && b.is_finite())
        .map(|(a, b)| (a.ln(), b.ln()))
        .collect();
    let n = pts.len();
    if n < 2 {
        return None;
    }
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n as f64;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n as f64;
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let rate = sxy / sxx;
    let intercept = my - rate * mx;
    let stderr = if n > 2 {
        let ssr: f64 = pts
            .iter()
            .map(|p| (p.1 - intercept - rate * p.0).powi(2))
            .sum();
        (ssr / (n - 2) as f64 / sxx).sqrt()
    } else {
        0.0
    };
    Some(Fit {
        rate,
        stderr,
        intercept,
    })
}

/// Rates between neighbouring points: log(y_i/y_{i+1}) / log(x_i/x_{i+1}).
pub fn successive(x: &[f64], y: &[f64]) -> Vec<f64> {
    x.windows(2)
        .zip(y.windows(2))
        .map(|(a, b)| (b[0] / b[1]).ln() / (a[0] / a[1]).ln())
        .collect()
}

/// Errors at or below this (relative) are round-off: the solvers' relative tolerance. They
/// are marked and never fitted.
pub const ROUNDOFF: f64 = 1e-10;
/// A relative error or distance is measured only where the truth's size it divides by is at
/// least this fraction of the truth's theorem norm: a smaller size is one the truth lacks
/// (patch's exact displacement is 0, so its H1 size is 0) and the ratio measures nothing, so
/// no row is written. The same fraction as [`ROUNDOFF`]: a size below it is round-off of the
/// norm it is part of.
pub const MIN_REFERENCE_SIZE: f64 = ROUNDOFF;

/// `value / size` where `size` is at least [`MIN_REFERENCE_SIZE`] of the truth's theorem
/// norm `theorem` (and positive); None where the truth lacks that size: the one rule for
/// every relative error and distance, the cones' and a graded code's alike.
pub fn relative_to(value: f64, size: f64, theorem: f64) -> Option<f64> {
    (size > 0.0 && size >= MIN_REFERENCE_SIZE * theorem).then(|| value / size)
}

/// Errors of the last [`MIN_FIT_LEVELS`] usable levels within this relative spread of each
/// other are one value: `fixed` (a position the levels share, not a discretization error
/// that stalls). 1e-9: the solvers' tolerance 1e-10 with a margin; a stalling error moves
/// by far more (nts's l2_pressure by 1e-3 and beyond between levels).
pub const FIXED_SPREAD: f64 = 1e-9;

/// A fitted rate within this many standard errors of 0 is no rate: the errors are `not
/// converging` (unaligned beta = 1.5, nts `l2_pressure`: 0.021 ± 0.013 over levels 5-7).
/// A steady small rate measured to more than two standard errors stays fitted.
pub const ZERO_RATE_STDERRS: f64 = 2.0;

/// Fewest levels a fitted rate rests on; with fewer, only successive rates are given.
pub const MIN_FIT_LEVELS: usize = 3;
/// The fitted window: the longest trailing run of levels (at least [`MIN_FIT_LEVELS`])
/// whose judged rates lie within this spread (max - min) of each other. Why 0.1: a fixed
/// number small beside the 1/4 between the 3/4 and 1/2 that Theorem 3.1 distinguishes, and
/// large enough for a 1 % level-to-level noise in the errors (each successive rate moves
/// by 0.029, a spread of 0.058 between two neighbours).
pub const WINDOW_SPREAD: f64 = 0.1;
/// The trend rule: where the last three judged rates are strictly monotone and differ end to
/// end by more than this, the rate is `falling` or `rising`, whatever the window.
pub const TREND: f64 = 0.1;
/// A quantity whose last two judged rates average at most this (the rate across the last
/// three levels of a halving table), or whose last one is negative, has stopped converging.
/// A steady small rate above it is judged like any other.
pub const STALLED: f64 = 0.02;
/// Two levels' rate is judged only where their h differ by at least this factor: halving
/// tables (2, or within 5 % of it on unstructured meshes) use neighbours, a sqrt(2) table
/// every second level, a 1.3 table every third, so that a 1 % noise in the errors moves a
/// judged rate as little as in a halving table (0.029 at most).
pub const MIN_RATE_SPAN: f64 = 1.9;
/// Levels whose error is within this factor of the truth's own estimated error are left out.
pub const TRUTH_MARGIN: f64 = 5.0;
/// The safety factor of the grid convergence index with three levels (Celik et al. 2008).
pub const GCI_SAFETY: f64 = 1.25;

/// What a quantity's errors over the levels support.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// A least-squares rate over a trailing window of at least [`MIN_FIT_LEVELS`] levels
    /// whose judged rates agree within [`WINDOW_SPREAD`], with no trend ([`TREND`]) in the
    /// last three: the only verdict that supports a rate.
    Fitted,
    /// The last three judged rates fall strictly, by more than [`TREND`] end to end: the
    /// errors are in transition to a lower rate; the last judged rate is reported.
    Falling,
    /// The last three judged rates rise strictly, by more than [`TREND`]: in transition to
    /// a higher rate.
    Rising,
    /// No trailing window of agreeing rates and no trend: the fit over every usable level
    /// is shown, flagged.
    PreAsymptotic,
    /// Fewer than [`MIN_FIT_LEVELS`] levels usable: successive rates only.
    TooFewLevels,
    /// The error stops falling while the mesh is refined: the last two judged rates average
    /// at most [`STALLED`], or the last one is negative, or the window's fitted rate lies
    /// within [`ZERO_RATE_STDERRS`] standard errors of 0.
    NotConverging,
    /// Every level's error is at round-off ([`ROUNDOFF`]): the discretization is exact.
    RoundOff,
    /// The error is the same to [`FIXED_SPREAD`] on the last [`MIN_FIT_LEVELS`] usable
    /// levels while h falls: a discrete position that every level keeps (lac's contact edge
    /// at the macro-element end nearest the exact edge, a node of every level), bounded by
    /// the resolution of the rows, not a rate and not a stall of the discretization.
    Fixed,
    /// The quantity is fixed by equilibrium (the contact resultant of a body held normal to
    /// Gamma_C only by the contact, computed by this project's cones): it measures the
    /// load's quadrature, not the cones, and is never fitted. Set by the study, never by
    /// [`assess`].
    FixedByEquilibrium,
}

impl Verdict {
    /// Every verdict, in the order of the rules.
    pub const ALL: [Verdict; 9] = [
        Verdict::Fitted,
        Verdict::Falling,
        Verdict::Rising,
        Verdict::PreAsymptotic,
        Verdict::TooFewLevels,
        Verdict::NotConverging,
        Verdict::RoundOff,
        Verdict::Fixed,
        Verdict::FixedByEquilibrium,
    ];

    /// Name in rates.csv.
    pub fn name(self) -> &'static str {
        match self {
            Verdict::Fitted => "fitted",
            Verdict::Falling => "falling",
            Verdict::Rising => "rising",
            Verdict::PreAsymptotic => "pre-asymptotic",
            Verdict::TooFewLevels => "too few levels",
            Verdict::NotConverging => "not converging",
            Verdict::RoundOff => "round-off",
            Verdict::Fixed => "fixed at a node",
            Verdict::FixedByEquilibrium => "fixed by equilibrium",
        }
    }

    /// The verdict named `name` in rates.csv ([`Verdict::name`]).
    pub fn from_name(name: &str) -> Option<Verdict> {
        Verdict::ALL.into_iter().find(|v| v.name() == name)
    }

    /// Whether the verdict supports a rate: fitted only. A pre-asymptotic fit is shown
    /// flagged; a falling or rising rate is in transition.
    pub fn supports_rate(self) -> bool {
        self == Verdict::Fitted
    }

    /// Whether the verdict says what the errors do plainly enough to compare the cones'
    /// finest errors on it: a fitted rate, a rate in transition, exact, or not converging.
    /// Pre-asymptotic rates, tables too short to fit and quantities fixed by equilibrium are
    /// not compared.
    pub fn compares_cones(self) -> bool {
        matches!(
            self,
            Verdict::Fitted
                | Verdict::Falling
                | Verdict::Rising
                | Verdict::RoundOff
                | Verdict::NotConverging
        )
    }
}

/// What a required rate R makes of a judged rate ([`threshold_outcome`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// The verdict supports a rate and min(fitted rate, last judged rate) >= R.
    Pass,
    /// The last judged rate is below R, whatever the verdict (for a falling rate, also its
    /// extrapolation to the finest level).
    Fail,
    /// Anything else: no supported rate, none below R either.
    Unverified,
}

impl Outcome {
    /// Name in the pass column of rates.csv.
    pub fn name(self) -> &'static str {
        match self {
            Outcome::Pass => "pass",
            Outcome::Fail => "fail",
            Outcome::Unverified => "unverified",
        }
    }
    /// As consoles and tables print it: a failure in capitals.
    pub fn shouted(self) -> &'static str {
        match self {
            Outcome::Fail => "FAIL",
            o => o.name(),
        }
    }
    /// The outcome named `name` ([`Outcome::name`]).
    pub fn from_name(name: &str) -> Option<Outcome> {
        [Outcome::Pass, Outcome::Fail, Outcome::Unverified]
            .into_iter()
            .find(|o| o.name() == name)
    }
}

/// The one threshold rule for study files, `grade` and `judge`: a rate R is met (`Pass`)
/// where the verdict supports a rate and both the fit and the last judged rate reach R;
/// missed (`Fail`) where the last judged rate is below R, whatever the verdict, or, for a
/// falling rate, where its extrapolation to the finest level is (the last judged rate
/// describes the middle of the last pair of levels, half a level behind the finest one
/// for halving h); `Unverified` otherwise.
pub fn threshold_outcome(a: &Assessment, required: f64) -> Outcome {
    let Some(last) = a.last_rate() else {
        return Outcome::Unverified;
    };
    if last < required || a.finest_slope.is_some_and(|s| s < required) {
        return Outcome::Fail;
    }
    match (a.verdict, a.fit) {
        (Verdict::Fitted, Some(f)) if f.rate.min(last) >= required => Outcome::Pass,
        _ => Outcome::Unverified,
    }
}

/// Why [`threshold_outcome`] gave `outcome` for `a` at `required`, as the end of a sentence
/// ("unverified, because ..."): the numbers the rule compared.
pub fn outcome_reason(a: &Assessment, required: f64, outcome: Outcome) -> String {
    let f3 = crate::io::fmt3;
    let Some(last) = a.last_rate() else {
        return "there is no successive rate (no two levels at least 1.9 apart in h)".into();
    };
    match (outcome, a.verdict, a.fit) {
        (Outcome::Pass, _, Some(f)) => format!(
            "the fit {} and the last successive rate {} both reach it",
            f3(f.rate),
            f3(last)
        ),
        (Outcome::Fail, _, _) if last < required => {
            format!("the last successive rate {} is below it", f3(last))
        }
        (Outcome::Fail, _, _) => format!(
            "the rate is falling and its extrapolation to the finest level, {}, is below it",
            f3(a.finest_slope.unwrap_or(f64::NAN))
        ),
        (_, Verdict::Fitted, Some(f)) => format!(
            "the fit {} is below it while the last successive rate {} reaches it",
            f3(f.rate),
            f3(last)
        ),
        _ => format!(
            "the verdict, {}, supports no rate, while the last successive rate {} reaches it",
            a.verdict.name(),
            f3(last)
        ),
    }
}

/// The one rule behind every word of a report that claims a rate reaches a target
/// ("follows its best", "tends to mortar's rate", "D falls no slower"): the threshold
/// rule at `target - slack`, so a supported rate whose fit and last judged rate both reach
/// it ([`threshold_outcome`] passes). Never the fit alone: a fit that reaches the target
/// while the successive rates fall below it is still in transition.
pub fn reaches(a: &Assessment, target: f64, slack: f64) -> bool {
    threshold_outcome(a, target - slack) == Outcome::Pass
}

/// One level's error of one quantity.
#[derive(Debug, Clone, Copy)]
pub struct LevelError {
    /// Mesh level.
    pub level: usize,
    /// Max element diameter (length).
    pub h: f64,
    /// Free dofs.
    pub dofs: f64,
    /// Relative error.
    pub error: f64,
}

/// The verification conventions of ASME V&V 20 / Celik et al. 2008 (J. Fluids Eng. 130,
/// 078001) on the last three usable levels, fine (1), medium (2), coarse (3), applied to
/// the quantity's error phi (whose limit is 0): the observed order p of
/// p = |ln|eps32 / eps21| + q(p)| / ln r21, q(p) = ln((r21^p - s) / (r32^p - s)), eps32 =
/// phi3 - phi2, eps21 = phi2 - phi1, s = sign(eps32 / eps21), r = h_coarser / h_finer, by
/// fixed-point iteration from q = 0. The GCIs are in the units of phi (the relative form
/// divides by phi1, which tends to 0 for an error).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Celik {
    /// Observed order p.
    pub order: f64,
    /// Oscillatory convergence: eps32 / eps21 < 0 (s = -1).
    pub oscillatory: bool,
    /// GCI of the finest level: 1.25 |eps21| / (r21^p - 1).
    pub gci_fine: f64,
    /// GCI of the medium level: 1.25 |eps32| / (r32^p - 1).
    pub gci_coarse: f64,
    /// Refinement ratios r21, r32.
    pub ratios: (f64, f64),
    /// Differences eps21, eps32.
    pub differences: (f64, f64),
}

impl Celik {
    /// Roache's asymptotic-range check GCI_coarse / (r21^p GCI_fine) with both GCIs taken
    /// at the order `p`: 1 where an error ~ C h^p describes the three levels. With the
    /// observed order of the same three levels it is 1 by construction (monotone case), so
    /// the reports take `p` = the rate they print.
    pub fn asymptotic_ratio(&self, p: f64) -> f64 {
        let ((r21, r32), (e21, e32)) = (self.ratios, self.differences);
        let fine = GCI_SAFETY * e21.abs() / (r21.powf(p) - 1.0);
        let coarse = GCI_SAFETY * e32.abs() / (r32.powf(p) - 1.0);
        coarse / (r21.powf(p) * fine)
    }
}

/// Celik's procedure on three (h, phi) pairs ordered fine, medium, coarse (h increasing);
/// None where it has no answer: two equal values (eps = 0), or an iteration that does not
/// settle to a finite positive order within 200 steps.
pub fn celik(h: [f64; 3], phi: [f64; 3]) -> Option<Celik> {
    let (r21, r32) = (h[1] / h[0], h[2] / h[1]);
    let (e21, e32) = (phi[1] - phi[0], phi[2] - phi[1]);
    if e21 == 0.0 || e32 == 0.0 || r21 <= 1.0 || r32 <= 1.0 {
        return None;
    }
    let s = (e32 / e21).signum();
    let ln_ratio = (e32 / e21).abs().ln();
    let q = |p: f64| ((r21.powf(p) - s) / (r32.powf(p) - s)).ln();
    let mut p = ln_ratio.abs() / r21.ln();
    let mut settled = false;
    for _ in 0..200 {
        let next = (ln_ratio + q(p)).abs() / r21.ln();
        if !next.is_finite() {
            return None;
        }
        let done = (next - p).abs() <= 1e-12 * next.abs().max(1.0);
        p = next;
        if done {
            settled = true;
            break;
        }
    }
    if !settled || p <= 0.0 {
        return None;
    }
    Some(Celik {
        order: p,
        oscillatory: s < 0.0,
        gci_fine: GCI_SAFETY * e21.abs() / (r21.powf(p) - 1.0),
        gci_coarse: GCI_SAFETY * e32.abs() / (r32.powf(p) - 1.0),
        ratios: (r21, r32),
        differences: (e21, e32),
    })
}

/// A rate between two usable levels at least [`MIN_RATE_SPAN`] apart in h: what the judge's
/// rules read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JudgedRate {
    /// The coarser level and the finer one.
    pub levels: (usize, usize),
    /// log(e_coarse / e_fine) / log(h_coarse / h_fine).
    pub rate: f64,
    /// The mean of the two levels' log h: where the rate describes the errors.
    pub log_h: f64,
}

/// What [`assess`] concluded.
#[derive(Debug, Clone)]
pub struct Assessment {
    /// The verdict.
    pub verdict: Verdict,
    /// The fit in h over exactly `used`: the window (Fitted), every usable level
    /// (PreAsymptotic, flagged); none otherwise.
    pub fit: Option<Fit>,
    /// The fit in dofs over the same levels.
    pub fit_dofs: Option<Fit>,
    /// The fitted levels.
    pub used: Vec<usize>,
    /// The fit over every usable level (at least [`MIN_FIT_LEVELS`]): reported, not judged.
    pub fit_all: Option<Fit>,
    /// Levels at round-off.
    pub roundoff: Vec<usize>,
    /// Levels within [`TRUTH_MARGIN`] of the truth's own error.
    pub near_truth: Vec<usize>,
    /// Successive rates between neighbouring levels; None where either is at round-off.
    pub successive: Vec<Option<f64>>,
    /// The rates the rules read: between usable levels at least [`MIN_RATE_SPAN`] apart in h
    /// (the neighbours of a halving table), finest last.
    pub judged: Vec<JudgedRate>,
    /// For a falling rate, the last judged rate extrapolated to the finest level's log h
    /// along the line through it and the judged rate two before (same parity: a period-2
    /// wobble cancels).
    pub finest_slope: Option<f64>,
    /// Celik's procedure on the last three usable levels.
    pub celik: Option<Celik>,
    /// Its asymptotic-range ratio at the reported rate ([`Celik::asymptotic_ratio`]).
    pub asymptotic_ratio: Option<f64>,
}

/// Two levels of a quantity's table with the same h: a successive rate would divide by
/// log(1) = 0. A study file refuses it when read (levels must increase).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EqualH {
    /// The two levels.
    pub levels: (usize, usize),
}

impl std::fmt::Display for EqualH {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "levels {} and {} have the same h: no rate between them; give distinct, increasing levels",
            self.levels.0, self.levels.1
        )
    }
}

/// Rate between two levels: log(e_a / e_b) / log(h_a / h_b).
fn rate_between(a: &LevelError, b: &LevelError) -> f64 {
    successive(&[a.h, b.h], &[a.error, b.error])[0]
}

/// Judge a quantity's errors over the levels (coarsest first) against a truth whose own
/// estimated error is `truth_error` (0 for an exact solution). The rules, in order
/// (docs/studies.md#rates): every level at round-off is `round-off`; levels at round-off or
/// within [`TRUTH_MARGIN`] of the truth are left out; errors that stop falling ([`STALLED`])
/// are `not converging`; fewer than [`MIN_FIT_LEVELS`] usable levels are `too few levels`; the last
/// three judged rates strictly monotone by more than [`TREND`] are `falling` or `rising`;
/// a trailing window of at least three levels whose judged rates spread by at most
/// [`WINDOW_SPREAD`] is `fitted`, unless its fitted rate is within [`ZERO_RATE_STDERRS`]
/// standard errors of 0 (`not converging`); else `pre-asymptotic`. Errs on two levels with
/// the same h.
pub fn assess(levels: &[LevelError], truth_error: f64) -> Result<Assessment, EqualH> {
    check_distinct_h(levels)?;
    let (mut out, usable) = classify(levels, truth_error);
    if usable.is_empty() && !out.roundoff.is_empty() {
        out.verdict = Verdict::RoundOff;
        return Ok(out);
    }
    out.judged = judged_rates(&usable);
    if fixed(&usable) {
        out.verdict = Verdict::Fixed;
        return Ok(out);
    }
    let rates: Vec<f64> = out.judged.iter().map(|r| r.rate).collect();
    let last_two = &rates[rates.len().saturating_sub(2)..];
    // The last two judged rates together (their mean: the rate across the last three
    // levels of a halving table) at most STALLED, or the last one negative.
    let stalled = match last_two {
        [] => false,
        [.., last] if *last < 0.0 => true,
        [a, b] => 0.5 * (a + b) <= STALLED,
        _ => false,
    };
    if stalled {
        out.verdict = Verdict::NotConverging;
        return Ok(out);
    }
    if usable.len() < MIN_FIT_LEVELS {
        return Ok(out);
    }
    let n = usable.len();
    out.celik = celik(
        [usable[n - 1].h, usable[n - 2].h, usable[n - 3].h],
        [
            usable[n - 1].error,
            usable[n - 2].error,
            usable[n - 3].error,
        ],
    );
    out.fit_all = fit_over(&usable).0;
    if let Some(trend) = trend(&out.judged) {
        out.verdict = trend;
        if trend == Verdict::Falling {
            out.finest_slope = Some(extrapolate_to_finest(&out.judged, usable[n - 1].h));
        }
        return Ok(out);
    }
    let window: &[&LevelError] = match trailing_window(&usable, &out.judged) {
        Some(first) => {
            out.verdict = Verdict::Fitted;
            &usable[first..]
        }
        None => {
            out.verdict = Verdict::PreAsymptotic;
            &usable
        }
    };
    (out.fit, out.fit_dofs) = fit_over(window);
    out.used = window.iter().map(|e| e.level).collect();
    if out.verdict == Verdict::Fitted
        && out
            .fit
            .is_some_and(|f| f.rate <= ZERO_RATE_STDERRS * f.stderr)
    {
        // A rate the data cannot tell from 0 supports no rate.
        out.verdict = Verdict::NotConverging;
        (out.fit, out.fit_dofs) = (None, None);
        out.used.clear();
        return Ok(out);
    }
    out.asymptotic_ratio = match (out.celik, out.fit) {
        (Some(c), Some(f)) if f.rate > 0.0 => Some(c.asymptotic_ratio(f.rate)),
        _ => None,
    };
    Ok(out)
}

/// Whether the last [`MIN_FIT_LEVELS`] usable levels' errors agree to [`FIXED_SPREAD`].
fn fixed(usable: &[&LevelError]) -> bool {
    let Some(last) = usable
        .len()
        .checked_sub(MIN_FIT_LEVELS)
        .map(|i| &usable[i..])
    else {
        return false;
    };
    let (lo, hi) = last.iter().fold((f64::INFINITY, 0.0f64), |(a, b), e| {
        (a.min(e.error), b.max(e.error))
    });
    hi <= lo * (1.0 + FIXED_SPREAD)
}

/// Refuse two levels with the same h (relative 1e-12): no rate between them.
pub fn check_distinct_h(levels: &[LevelError]) -> Result<(), EqualH> {
    for (i, a) in levels.iter().enumerate() {
        for b in &levels[i + 1..] {
            if (a.h - b.h).abs() <= 1e-12 * a.h.abs().max(b.h.abs()) {
                return Err(EqualH {
                    levels: (a.level, b.level),
                });
            }
        }
    }
    Ok(())
}

/// The levels sorted out: at round-off, near the truth (within [`TRUTH_MARGIN`] of its
/// error `truth_error`), and the usable rest; with the successive rates between
/// neighbouring levels. The assessment so far (too few levels, nothing fitted) and the
/// usable levels.
fn classify(levels: &[LevelError], truth_error: f64) -> (Assessment, Vec<&LevelError>) {
    let at_roundoff = |e: &LevelError| e.error <= ROUNDOFF;
    let roundoff: Vec<usize> = levels
        .iter()
        .filter(|e| at_roundoff(e))
        .map(|e| e.level)
        .collect();
    let near_truth: Vec<usize> = levels
        .iter()
        .filter(|e| !at_roundoff(e) && e.error < TRUTH_MARGIN * truth_error)
        .map(|e| e.level)
        .collect();
    let successive_rates: Vec<Option<f64>> = levels
        .windows(2)
        .map(|w| (!at_roundoff(&w[0]) && !at_roundoff(&w[1])).then(|| rate_between(&w[0], &w[1])))
        .collect();
    let usable: Vec<&LevelError> = levels
        .iter()
        .filter(|e| !at_roundoff(e) && !near_truth.contains(&e.level))
        .collect();
    let out = Assessment {
        verdict: Verdict::TooFewLevels,
        fit: None,
        fit_dofs: None,
        used: Vec::new(),
        fit_all: None,
        roundoff,
        near_truth,
        successive: successive_rates,
        judged: Vec::new(),
        finest_slope: None,
        celik: None,
        asymptotic_ratio: None,
    };
    (out, usable)
}

/// For each usable level, the rate from the finest coarser level at least
/// [`MIN_RATE_SPAN`] times its h (none for the coarsest levels that have no such partner).
fn judged_rates(usable: &[&LevelError]) -> Vec<JudgedRate> {
    (0..usable.len())
        .filter_map(|i| {
            let fine = usable[i];
            let coarse = usable[..i]
                .iter()
                .rev()
                .find(|c| c.h >= MIN_RATE_SPAN * fine.h * (1.0 - 1e-9))?;
            Some(JudgedRate {
                levels: (coarse.level, fine.level),
                rate: rate_between(coarse, fine),
                log_h: 0.5 * (coarse.h.ln() + fine.h.ln()),
            })
        })
        .collect()
}

/// `Falling` or `Rising` where the last three judged rates are strictly monotone and differ
/// end to end by more than [`TREND`].
fn trend(judged: &[JudgedRate]) -> Option<Verdict> {
    let [a, b, c] = judged.get(judged.len().checked_sub(3)?..)? else {
        return None;
    };
    let (a, b, c) = (a.rate, b.rate, c.rate);
    if a > b && b > c && a - c > TREND {
        Some(Verdict::Falling)
    } else if a < b && b < c && c - a > TREND {
        Some(Verdict::Rising)
    } else {
        None
    }
}

/// The last judged rate carried to `finest_h` along the line through it and the judged rate
/// two before it (at least three judged rates).
fn extrapolate_to_finest(judged: &[JudgedRate], finest_h: f64) -> f64 {
    let (last, before) = (judged[judged.len() - 1], judged[judged.len() - 3]);
    let slope = (last.rate - before.rate) / (last.log_h - before.log_h);
    last.rate + slope * (finest_h.ln() - last.log_h)
}

/// The fits in h and in dofs over `window`.
fn fit_over(window: &[&LevelError]) -> (Option<Fit>, Option<Fit>) {
    let h: Vec<f64> = window.iter().map(|e| e.h).collect();
    let d: Vec<f64> = window.iter().map(|e| e.dofs).collect();
    let e: Vec<f64> = window.iter().map(|e| e.error).collect();
    (fit(&h, &e), fit(&d, &e))
}

/// The first index into `usable` of the longest trailing window of at least
/// [`MIN_FIT_LEVELS`] levels holding at least two judged rates (both levels in the window)
/// that spread by at most [`WINDOW_SPREAD`], every level of it an end of one of those
/// rates (a level no judged rate inside the window reads would enter the fit unchecked:
/// on remeshed levels a step under [`MIN_RATE_SPAN`] pairs a level with the one before
/// its neighbour); None where no such window exists.
fn trailing_window(usable: &[&LevelError], judged: &[JudgedRate]) -> Option<usize> {
    let mut start = None;
    for first in (0..=usable.len() - MIN_FIT_LEVELS).rev() {
        let window = &usable[first..];
        let inside: Vec<&JudgedRate> = judged
            .iter()
            .filter(|r| window.iter().any(|e| e.level == r.levels.0))
            .collect();
        if inside.len() < 2 {
            continue;
        }
        let spread = inside
            .iter()
            .map(|r| r.rate)
            .fold(f64::NEG_INFINITY, f64::max)
            - inside.iter().map(|r| r.rate).fold(f64::INFINITY, f64::min);
        if spread > WINDOW_SPREAD {
            break;
        }
        let covered = window.iter().all(|e| {
            inside
                .iter()
                .any(|r| r.levels.0 == e.level || r.levels.1 == e.level)
        });
        if covered {
            start = Some(first);
        }
    }
    start
}

/// Largest condition number of J^T J scaled to unit diagonal (the parameters'
/// correlation matrix) over the directions [`exponent_standard_errors`] reads variances
/// from: an inverse's relative error is about the condition times f64's epsilon, so
/// 4.5e12 keeps three digits. Measured on the committed two-size grids: identified fits
/// 1e2-3.5e3 over all four directions; the degenerate ones have one direction at
/// 1e15-1e17 and beyond (a term alive at one level of its size only, or 1e-23 of the
/// error everywhere: any steeper exponent with a larger constant fits as well).
const MAX_CORRELATION_CONDITION: f64 = 1e-3 / f64::EPSILON;

/// Share of an exponent's unit vector in the undetermined directions above which the data
/// do not determine it. Measured on the committed two-size grids: an undetermined exponent
/// 0.5 (its term's constant and exponent move together), a determined one 3e-16 at most.
const MAX_UNDETERMINED_SHARE: f64 = 1e-6;

/// Standard errors of a1 and a2 from s^2 (J^T J)^+ (`s2`: the residual variance): the
/// inverse over the directions the data determine ([`MAX_CORRELATION_CONDITION`]), and
/// infinite for an exponent with a share in the others ([`MAX_UNDETERMINED_SHARE`]).
/// Why not the plain inverse: where one term's exponent is undetermined, J^T J is
/// singular to round-off and every entry of its inverse is noise, positive or not (the
/// other exponent's standard error read 0.017 on a grid where the projection gives 0.072,
/// and moved by 28 % between two runs whose errors differed by 9e-10); a determined
/// exponent keeps its own.
fn exponent_standard_errors(jtj: &nalgebra::Matrix4<f64>, s2: f64) -> [f64; 2] {
    // A column of J that is zero (a term vanishing to underflow) scales to zero: its
    // parameter then spans a zero eigenvalue's direction.
    let scale = jtj
        .diagonal()
        .map(|v| if v > 0.0 { 1.0 / v.sqrt() } else { 0.0 });
    let correlation = jtj.component_mul(&(scale * scale.transpose()));
    let eigen = correlation.symmetric_eigen();
    let largest = eigen.eigenvalues.max();
    let determined = |i: usize| eigen.eigenvalues[i] * MAX_CORRELATION_CONDITION > largest;
    [1, 3].map(|p| {
        let (mut variance, mut undetermined) = (0.0, 0.0);
        for i in 0..4 {
            let v = eigen.eigenvectors[(p, i)];
            match determined(i) {
                true => variance += v * v / eigen.eigenvalues[i],
                false => undetermined += v * v,
            }
        }
        match undetermined <= MAX_UNDETERMINED_SHARE {
            true => (s2 * variance).sqrt() * scale[p],
            false => f64::INFINITY,
        }
    })
}

/// The fit of errors over two mesh sizes to E(h1, h2) = C1 h1^a1 + C2 h2^a2 (Lemma 3.1's
/// form: one term per body), in log space (relative residuals: the errors span decades).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PowerSumFit {
    /// C1, C2 (units of the error over length^a).
    pub c: [f64; 2],
    /// Exponents a1 (in h1) and a2 (in h2).
    pub a: [f64; 2],
    /// Standard errors of a1 and a2 (from s^2 (J^T J)^+ at the optimum, over the
    /// directions the data determine); infinite for an exponent they do not determine
    /// (see `exponent_standard_errors`).
    pub se: [f64; 2],
    /// Root mean square of the log residuals ln E - ln E_fit.
    pub rms_log_residual: f64,
    /// Number of points fitted.
    pub points: usize,
}

impl PowerSumFit {
    /// The fitted error at (h1, h2), and its two terms.
    pub fn terms(&self, h: [f64; 2]) -> [f64; 2] {
        [0, 1].map(|b| self.c[b] * h[b].powf(self.a[b]))
    }
}

/// The exponents each of [`fit_power_sum`]'s starts takes for a1 and for a2 (25 pairs).
/// Why a decreasing term and a steep one: starting only from {0.5, 1, 2}, six of the
/// committed two-size fits stopped in a local minimum (rms of the log residuals 1.69 ->
/// 1.50, 1.81 -> 1.66, 0.704 -> 0.618, 2.03 -> 1.92, 2.08 -> 2.00, 1.02541 -> 1.02525 with
/// these starts, the minima an independent 49-start search found); every fit with rms <=
/// 0.25 kept its exponents and standard errors to 3e-8.
const START_EXPONENTS: [f64; 5] = [-1.0, 0.5, 1.0, 2.0, 4.0];

/// Least-squares fit of `points` (h1, h2, E), every E > 0, to E = C1 h1^a1 + C2 h2^a2:
/// Levenberg-Marquardt on (ln C1, a1, ln C2, a2) minimizing the squared log residuals,
/// started from every pair of [`START_EXPONENTS`] (the best kept: the objective is not
/// convex). Written by hand: four parameters and a 4 x 4 solve; the maintained LM crates
/// are generic over nalgebra's dimension machinery for no gain here. None with fewer than
/// five points (no degree of freedom left for the standard errors) or no finite optimum.
pub fn fit_power_sum(points: &[(f64, f64, f64)]) -> Option<PowerSumFit> {
    use nalgebra::{Matrix4, Vector4};
    let n = points.len();
    if n < 5
        || points
            .iter()
            .any(|p| !(p.0 > 0.0 && p.1 > 0.0 && p.2 > 0.0))
    {
        return None;
    }
    // Residuals and Jacobian of the model ln(C1 h1^a1 + C2 h2^a2) at theta.
    let evaluate = |th: &Vector4<f64>| -> (Vec<f64>, Vec<[f64; 4]>) {
        let mut r = Vec::with_capacity(n);
        let mut j = Vec::with_capacity(n);
        for &(h1, h2, e) in points {
            let t1 = (th[0] + th[1] * h1.ln()).exp();
            let t2 = (th[2] + th[3] * h2.ln()).exp();
            let s = t1 + t2;
            r.push(e.ln() - s.ln());
            j.push([t1 / s, t1 * h1.ln() / s, t2 / s, t2 * h2.ln() / s]);
        }
        (r, j)
    };
    let ssr = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>();
    let mean_ln_e = points.iter().map(|p| p.2.ln()).sum::<f64>() / n as f64;
    let mean_ln_h = [0, 1].map(|b| {
        points
            .iter()
            .map(|p| if b == 0 { p.0 } else { p.1 }.ln())
            .sum::<f64>()
            / n as f64
    });
    let mut best: Option<(f64, Vector4<f64>)> = None;
    for a1 in START_EXPONENTS {
        for a2 in START_EXPONENTS {
            // Each term half the mean error at the mean sizes.
            let c = |a: f64, lh: f64| mean_ln_e - std::f64::consts::LN_2 - a * lh;
            let mut th = Vector4::new(c(a1, mean_ln_h[0]), a1, c(a2, mean_ln_h[1]), a2);
            let (mut r, mut j) = evaluate(&th);
            let mut f = ssr(&r);
            let mut mu = 1e-3;
            for _ in 0..500 {
                let mut jtj = Matrix4::zeros();
                let mut jtr = Vector4::zeros();
                for (ri, ji) in r.iter().zip(&j) {
                    let v = Vector4::from(*ji);
                    jtj += v * v.transpose();
                    jtr += v * *ri;
                }
                let mut damped = jtj;
                for k in 0..4 {
                    damped[(k, k)] += mu * jtj[(k, k)].max(1e-12);
                }
                let Some(step) = damped.lu().solve(&jtr) else {
                    break;
                };
                let trial = th + step;
                let (rt, jt) = evaluate(&trial);
                let ft = ssr(&rt);
                if ft.is_finite() && ft < f {
                    let converged = f - ft <= 1e-15 * f.max(1e-300) || step.amax() < 1e-13;
                    (th, r, j, f) = (trial, rt, jt, ft);
                    mu = (mu * 0.3).max(1e-12);
                    if converged {
                        break;
                    }
                } else {
                    mu *= 10.0;
                    if mu > 1e12 {
                        break;
                    }
                }
            }
            if f.is_finite() && best.as_ref().is_none_or(|b| f < b.0) {
                best = Some((f, th));
            }
        }
    }
    let (f, th) = best?;
    let (_, j) = evaluate(&th);
    let mut jtj = Matrix4::zeros();
    for ji in &j {
        let v = Vector4::from(*ji);
        jtj += v * v.transpose();
    }
    let fit = PowerSumFit {
        c: [th[0].exp(), th[2].exp()],
        a: [th[1], th[3]],
        se: exponent_standard_errors(&jtj, f / (n - 4) as f64),
        rms_log_residual: (f / n as f64).sqrt(),
        points: n,
    };
    (fit.a.iter().chain(&fit.c).all(|v| v.is_finite())).then_some(fit)
}

impl Assessment {
    /// The successive rates, space separated, 3 decimals ("-" next to a level at
    /// round-off), as rates.csv and the reports write them.
    pub fn successive_text(&self) -> String {
        self.successive
            .iter()
            .map(|s| s.map_or("-".into(), |s| format!("{s:.3}")))
            .collect::<Vec<_>>()
            .join(" ")
    }

    /// The last judged rate ([`Assessment::judged`]), where there is one.
    pub fn last_rate(&self) -> Option<f64> {
        self.judged.last().map(|r| r.rate)
    }

    /// The verdict as one plain line, as `judge`, `grade` and `study` print it: the rate or
    /// why there is none, the fitted levels, the successive rates, and, given a threshold
    /// and its outcome, the outcome with the numbers that decided it ([`outcome_reason`]).
    pub fn verdict_line(&self, threshold: Option<(f64, Outcome)>) -> String {
        let successive = match self.successive.iter().any(Option::is_some) {
            true => format!(
                " (successive rates {})",
                self.successive_text().replace(' ', ", ")
            ),
            false => String::new(),
        };
        let mut line = match (self.verdict, self.fit) {
            (Verdict::Fitted, Some(f)) => format!(
                "rate {:.3} ± {:.3}, fitted over levels {}{successive}",
                f.rate,
                f.stderr,
                crate::verify::table::join(&self.used)
            ),
            (Verdict::PreAsymptotic, Some(f)) => format!(
                "no rate: pre-asymptotic (the fit over every level, {:.3} ± {:.3}, is not supported){successive}",
                f.rate, f.stderr
            ),
            _ => format!("no rate: {}{successive}", self.describe().replace("**", "")),
        };
        if let Some((t, o)) = threshold {
            line.push_str(&format!(
                "; threshold {t:?}: {}, because {}",
                o.shouted(),
                outcome_reason(self, t, o)
            ));
        }
        line
    }

    /// The judged rate with its standard error, or the verdict that replaces it, as reports
    /// write it.
    pub fn describe(&self) -> String {
        let last = crate::io::fmt3(self.last_rate().unwrap_or(f64::NAN));
        match (self.verdict, self.fit) {
            (Verdict::Fitted, Some(f)) => format!("{:.3} ± {:.3}", f.rate, f.stderr),
            (Verdict::Falling, _) => format!("falling (last successive rate {last})"),
            (Verdict::Rising, _) => format!("rising (last successive rate {last})"),
            (Verdict::PreAsymptotic, Some(f)) => {
                format!("{:.3} ± {:.3} (pre-asymptotic)", f.rate, f.stderr)
            }
            (Verdict::RoundOff, _) => format!("exact (round-off, <= {ROUNDOFF:.0e})"),
            (Verdict::NotConverging, _) => "**does not converge**".into(),
            (Verdict::Fixed, _) => format!(
                "fixed at a node (the same error to {FIXED_SPREAD:.0e} on the last {MIN_FIT_LEVELS} levels: a position every level keeps, not a rate)"
            ),
            (Verdict::TooFewLevels, _) => format!("no fit (< {MIN_FIT_LEVELS} levels)"),
            (Verdict::FixedByEquilibrium, _) => {
                "fixed by equilibrium: measures the load quadrature".into()
            }
            _ => "n/a".into(),
        }
    }
}

/// A judged rate, or what replaces it, in a few characters (plot legends, table cells):
/// "1.85" where fitted, "falling to 0.557" or "rising to 1.117" with the last judged rate
/// (no brackets or commas: table cells list several), "exact" at round-off, else the verdict's name (a pre-asymptotic fit is never
/// printed as a rate). `rate` is the fit's, `last` the last judged rate.
pub fn short_text(verdict: Verdict, rate: Option<f64>, last: Option<f64>) -> String {
    let last = crate::io::fmt3(last.unwrap_or(f64::NAN));
    match (verdict, rate) {
        (Verdict::Fitted, Some(v)) => format!("{v:.2}"),
        (Verdict::Falling | Verdict::Rising, _) => format!("{} to {last}", verdict.name()),
        (Verdict::RoundOff, _) => "exact".into(),
        (v, _) => v.name().into(),
    }
}

/// [`assess`] of one quantity; where it is a contact resultant that equilibrium fixes
/// (`fixed_by_equilibrium`, decided by the caller), its error measures the load
/// quadrature, not the discretization: it is named so and never fitted.
pub fn judge(
    levels: &[LevelError],
    truth_error: f64,
    fixed_by_equilibrium: bool,
) -> Result<Assessment, EqualH> {
    let mut a = assess(levels, truth_error)?;
    if fixed_by_equilibrium {
        a.verdict = Verdict::FixedByEquilibrium;
        (a.fit, a.fit_dofs, a.fit_all, a.celik, a.asymptotic_ratio) =
            (None, None, None, None, None);
        a.used.clear();
        a.judged.clear();
        a.finest_slope = None;
    }
    Ok(a)
}

/// Largest standard error of an exponent of a [`PowerSumFit`] that counts as measured.
pub const FIT_MAX_SE: f64 = 0.5;
/// Largest rms log residual of a [`PowerSumFit`] that describes its errors (within ~28 %).
pub const FIT_MAX_RMS: f64 = 0.25;

/// Whether a power-sum fit identifies an exponent with standard error `se` given its rms
/// log residual `rms` (NaN never does).
pub fn fit_identifies(se: f64, rms: f64) -> bool {
    se <= FIT_MAX_SE && rms <= FIT_MAX_RMS
}
