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
/// Fewest levels a fitted rate rests on; with fewer, only successive rates are given.
pub const MIN_FIT_LEVELS: usize = 3;
/// A fitted rate whose last two successive rates (its last three levels) differ by more
/// than this is flagged pre-asymptotic.
pub const PRE_ASYMPTOTIC_SPREAD: f64 = 0.25;
/// A quantity whose last two successive rates average below this does not converge: it is
/// called that, and given no slope.
pub const STALLED: f64 = 0.15;
/// Levels whose error is within this factor of the truth's own estimated error are left out.
pub const TRUTH_MARGIN: f64 = 5.0;

/// What a quantity's errors over the levels support.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// A least-squares rate over at least [`MIN_FIT_LEVELS`] levels.
    Fitted,
    /// Fitted, but its last successive rates spread more than [`PRE_ASYMPTOTIC_SPREAD`].
    PreAsymptotic,
    /// Fewer than [`MIN_FIT_LEVELS`] levels usable: successive rates only.
    TooFewLevels,
    /// The error stops decreasing while the mesh is refined (last successive rates below
    /// [`STALLED`]).
    NotConverging,
    /// Every level's error is at round-off ([`ROUNDOFF`]): the discretization is exact.
    RoundOff,
}

impl Verdict {
    /// Name in rates.csv.
    pub fn name(self) -> &'static str {
        match self {
            Verdict::Fitted => "fitted",
            Verdict::PreAsymptotic => "pre-asymptotic",
            Verdict::TooFewLevels => "too few levels",
            Verdict::NotConverging => "not converging",
            Verdict::RoundOff => "round-off",
        }
    }
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

/// What [`assess`] concluded.
#[derive(Debug, Clone)]
pub struct Assessment {
    /// The verdict.
    pub verdict: Verdict,
    /// The fit in h over exactly `used` (Fitted and PreAsymptotic only).
    pub fit: Option<Fit>,
    /// The fit in dofs over the same levels.
    pub fit_dofs: Option<Fit>,
    /// The fitted levels.
    pub used: Vec<usize>,
    /// Levels at round-off.
    pub roundoff: Vec<usize>,
    /// Levels within [`TRUTH_MARGIN`] of the truth's own error.
    pub near_truth: Vec<usize>,
    /// Successive rates between neighbouring levels; None where either is at round-off.
    pub successive: Vec<Option<f64>>,
}

/// Judge a quantity's errors over the levels (finest last) against a truth whose own
/// estimated error is `truth_error` (0 for an exact solution): never a rate on round-off,
/// on levels too close to the truth, on fewer than three levels, or of a stalled quantity.
pub fn assess(levels: &[LevelError], truth_error: f64) -> Assessment {
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
        .map(|w| {
            (!at_roundoff(&w[0]) && !at_roundoff(&w[1]))
                .then(|| successive(&[w[0].h, w[1].h], &[w[0].error, w[1].error])[0])
        })
        .collect();
    let usable: Vec<&LevelError> = levels
        .iter()
        .filter(|e| !at_roundoff(e) && !near_truth.contains(&e.level))
        .collect();
    let mut out = Assessment {
        verdict: Verdict::TooFewLevels,
        fit: None,
        fit_dofs: None,
        used: Vec::new(),
        roundoff,
        near_truth,
        successive: successive_rates,
    };
    if usable.is_empty() && !out.roundoff.is_empty() {
        out.verdict = Verdict::RoundOff;
        return out;
    }
    // The successive rates of the last three usable levels.
    let tail: Vec<f64> = usable[usable.len().saturating_sub(3)..]
        .windows(2)
        .map(|w| successive(&[w[0].h, w[1].h], &[w[0].error, w[1].error])[0])
        .collect();
    if !tail.is_empty() && tail.iter().sum::<f64>() / (tail.len() as f64) < STALLED {
        out.verdict = Verdict::NotConverging;
        return out;
    }
    if usable.len() < MIN_FIT_LEVELS {
        return out;
    }
    let column = |f: fn(&LevelError) -> f64| -> Vec<f64> { usable.iter().map(|e| f(e)).collect() };
    out.fit = fit(&column(|e| e.h), &column(|e| e.error));
    out.fit_dofs = fit(&column(|e| e.dofs), &column(|e| e.error));
    out.used = usable.iter().map(|e| e.level).collect();
    out.verdict = if tail.len() == 2 && (tail[0] - tail[1]).abs() > PRE_ASYMPTOTIC_SPREAD {
        Verdict::PreAsymptotic
    } else {
        Verdict::Fitted
    };
    out
}
