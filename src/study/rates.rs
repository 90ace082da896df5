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
