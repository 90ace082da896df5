//! Reference: SPEC section 5 (rates never overstate what was measured); issue 20; Celik et
//! al. 2008, J. Fluids Eng. 130, 078001 (the observed order and GCI procedure, Table 1).
//! Goal: a synthetic error table with round-off levels, a two-point fit, a stalled quantity,
//! a pre-asymptotic one, levels too close to the truth, sequences in transition (two of the
//! committed `rates-exact` report before issue 20) and equal h is reported exactly as the
//! rules say: "levels used" are exactly the fitted levels (the trailing window of agreeing
//! successive rates), round-off is never fitted, no fitted rate rests on fewer than 3
//! levels, a stalled quantity gets no slope, a falling one is named, equal h is an error.
//! Data: errors e = C h^p on h = 0.4 / 2^l with the deviations named per case.

use contact_rates::verify::rates::{LevelError, Verdict, assess, celik};

fn assess_ok(levels: &[LevelError], truth: f64) -> contact_rates::verify::rates::Assessment {
    assess(levels, truth).expect("distinct h")
}

/// The table whose successive rates (h halved per level) are `rates`, starting at 1.
fn from_successive(rates: &[f64]) -> Vec<LevelError> {
    let mut e = vec![1.0];
    for r in rates {
        e.push(e.last().unwrap() * 2f64.powf(-r));
    }
    table(&e)
}

fn table(errors: &[f64]) -> Vec<LevelError> {
    errors
        .iter()
        .enumerate()
        .map(|(l, &e)| LevelError {
            level: l,
            h: 0.4 / 2f64.powi(l as i32),
            dofs: 100.0 * 4f64.powi(l as i32),
            error: e,
        })
        .collect()
}

#[test]
fn a_clean_power_law_is_fitted_over_every_level() {
    let a = assess_ok(&table(&[0.4, 0.2, 0.1, 0.05]), 0.0);
    assert_eq!(a.verdict, Verdict::Fitted);
    assert_eq!(a.used, vec![0, 1, 2, 3]);
    let f = a.fit.unwrap();
    assert!((f.rate - 1.0).abs() < 1e-12 && f.stderr < 1e-12);
    assert!((a.fit_dofs.unwrap().rate + 0.5).abs() < 1e-12);
}

#[test]
fn round_off_levels_are_marked_and_never_fitted() {
    // Level 1 at round-off (nts max_penetration of `rates` at level 1: 3.9e-17).
    let a = assess_ok(&table(&[1e-2, 3.9e-17, 2.5e-3, 1.25e-3]), 0.0);
    assert_eq!(a.roundoff, vec![1]);
    assert_eq!(
        a.used,
        vec![0, 2, 3],
        "levels used are exactly the fitted ones"
    );
    assert_eq!(a.successive[0], None);
    assert_eq!(a.successive[1], None);
    assert!((a.successive[2].unwrap() - 1.0).abs() < 1e-12);
    assert!((a.fit.unwrap().rate - 1.0).abs() < 1e-12);
    // Every level at round-off: exact, no rate.
    let a = assess_ok(&table(&[3e-12, 2e-12, 4e-12]), 0.0);
    assert_eq!(a.verdict, Verdict::RoundOff);
    assert!(a.fit.is_none() && a.used.is_empty());
}

#[test]
fn two_usable_levels_give_successive_rates_only() {
    // Three levels, the first at round-off: a line through two points is no fitted rate.
    let a = assess_ok(&table(&[1e-13, 0.2, 0.1]), 0.0);
    assert_eq!(a.verdict, Verdict::TooFewLevels);
    assert!(a.fit.is_none() && a.used.is_empty());
    assert!((a.successive[1].unwrap() - 1.0).abs() < 1e-12);
}

#[test]
fn levels_within_five_times_the_truths_error_are_left_out() {
    // Truth error 1e-3: the finest error 4e-3 is within 5x of it.
    let a = assess_ok(&table(&[4e-2, 2e-2, 1e-2, 4e-3]), 1e-3);
    assert_eq!(a.near_truth, vec![3]);
    assert_eq!(a.used, vec![0, 1, 2]);
    assert_eq!(a.verdict, Verdict::Fitted);
}

#[test]
fn a_stalled_quantity_is_called_non_converging_and_given_no_slope() {
    // nts l2_pressure of `patch`: 5e-2 at every level once the mesh is fine.
    let a = assess_ok(&table(&[0.1, 0.0705, 0.0702, 0.0694, 0.0709]), 0.0);
    assert_eq!(a.verdict, Verdict::NotConverging);
    assert!(a.fit.is_none() && a.used.is_empty());
}

#[test]
fn a_rate_whose_last_successive_rates_spread_is_pre_asymptotic() {
    // Successive rates 2, 0.32, 1 (not monotone: no trend): still fitted, but flagged.
    let a = assess_ok(&table(&[1.0, 0.25, 0.2, 0.1]), 0.0);
    assert_eq!(a.verdict, Verdict::PreAsymptotic);
    assert_eq!(a.used, vec![0, 1, 2, 3]);
    assert!(a.fit.is_some());
}

#[test]
fn committed_nts_band_stress_is_falling_not_a_fitted_1_2() {
    // rates-exact before issue 20: nts band_stress "1.216 ± 0.076, fitted" over all levels;
    // issue 60: "0.88 drifting" over levels 3-5. The last three successive rates 1.27, 0.94,
    // 0.82 fall strictly, by 0.45 end to end (> 0.1): in transition, no rate.
    let a = assess_ok(&from_successive(&[1.56, 1.46, 1.27, 0.94, 0.82]), 0.0);
    assert_eq!(a.verdict, Verdict::Falling);
    assert!(a.fit.is_none() && a.used.is_empty());
    assert!((a.last_rate().unwrap() - 0.82).abs() < 1e-12);
    // The last rate carried half a level on along the line through 1.27 and 0.82 (two
    // levels apart): 0.82 - 0.45 / 4.
    assert!((a.finest_slope.unwrap() - (0.82 - 0.45 / 4.0)).abs() < 1e-12);
    assert!((a.fit_all.unwrap().rate - 1.2).abs() < 0.05);
}

#[test]
fn committed_nts_pressure_weighted_has_no_window_of_agreeing_rates() {
    // rates-exact before issue 20: "1.128 ± 0.193, fitted"; then "0.542 drifting" over
    // levels 2-5. The last two successive rates 0.44, 0.61 spread by 0.17 > 0.1, and the
    // last three are not monotone: pre-asymptotic, the fit over every level flagged.
    let a = assess_ok(&from_successive(&[1.97, 2.19, 0.61, 0.44, 0.61]), 0.0);
    assert_eq!(a.verdict, Verdict::PreAsymptotic);
    assert_eq!(a.used, vec![0, 1, 2, 3, 4, 5]);
}

#[test]
fn a_clean_sequence_is_fitted_over_every_level() {
    let a = assess_ok(&from_successive(&[0.98, 1.01, 0.99, 1.0, 1.01]), 0.0);
    assert_eq!(a.verdict, Verdict::Fitted);
    assert_eq!(a.used, vec![0, 1, 2, 3, 4, 5]);
    assert!((a.fit.unwrap().rate - 1.0).abs() < 0.02);
}

#[test]
fn equal_h_at_two_levels_is_an_error_not_an_infinite_rate() {
    let mut t = table(&[0.4, 0.2, 0.1, 0.05]);
    t[2].h = t[1].h;
    let e = assess(&t, 0.0).unwrap_err();
    assert_eq!(e.levels, (1, 2));
    assert!(e.to_string().contains("same h"), "{e}");
}

#[test]
fn celik_worked_example_table_1() {
    // Celik et al. 2008, Table 1, column phi = 6.063, 5.972, 5.863 on N = 18000, 8000, 4500
    // cells (2D: r21 = sqrt(18000 / 8000) = 1.5, r32 = sqrt(8000 / 4500) = 4/3). By hand:
    // eps21 = 5.972 - 6.063 = -0.091, eps32 = 5.863 - 5.972 = -0.109, s = +1,
    // ln|eps32 / eps21| = ln 1.19780 = 0.180488; p0 = 0.180488 / ln 1.5 = 0.44514;
    // q(p0) = ln((1.5^0.44514 - 1) / ((4/3)^0.44514 - 1)) = ln(0.19785 / 0.13664) = 0.37007,
    // p1 = (0.180488 + 0.37007) / 0.405465 = 1.35784; then 1.50415, 1.52889, 1.53310,
    // 1.53382, 1.53394, ... -> p = 1.53397 (the paper: 1.53).
    // 1.5^p = 1.86102; GCI_fine = 1.25 * 0.091 / 0.86102 = 0.131869 (relative to phi1 =
    // 6.063: 2.17%, the paper's 2.2%); extrapolated phi = (1.86102 * 6.063 - 5.972) /
    // 0.86102 = 6.16850 (the paper: 6.1685).
    // At the check order 2: GCI_fine = 1.25 * 0.091 / 1.25 = 0.091, GCI_coarse = 1.25 *
    // 0.109 / (16/9 - 1) = 0.175179, ratio 0.175179 / (2.25 * 0.091) = 0.85558; at the
    // observed order the ratio is 1 (monotone convergence).
    let c = celik([1.0, 1.5, 2.0], [6.063, 5.972, 5.863]).unwrap();
    assert!((c.order - 1.53397).abs() < 1e-4, "{}", c.order);
    assert!(!c.oscillatory);
    assert!((c.gci_fine - 0.131869).abs() < 1e-5, "{}", c.gci_fine);
    assert!((c.gci_fine / 6.063 - 0.0217).abs() < 1e-4);
    assert!((c.asymptotic_ratio(2.0) - 0.85558).abs() < 1e-5);
    assert!((c.asymptotic_ratio(c.order) - 1.0).abs() < 1e-10);
    // Oscillatory: the middle value below both neighbours.
    let o = celik([1.0, 1.5, 2.0], [6.063, 5.972, 6.1]).unwrap();
    assert!(o.oscillatory);
    // An exact power law e = h^2 on a non-uniform ratio: p = 2 exactly.
    let p = celik([0.1, 0.17, 0.3], [0.01, 0.0289, 0.09]).unwrap();
    assert!((p.order - 2.0).abs() < 1e-9, "{}", p.order);
}
