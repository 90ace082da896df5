//! Reference: SPEC section 5 (rates never overstate what was measured).
//! Goal: a synthetic error table with round-off levels, a two-point fit, a stalled quantity,
//! a pre-asymptotic one and levels too close to the truth is reported exactly as the rules
//! say: "levels used" are exactly the fitted levels, round-off is never fitted, no fitted
//! rate rests on fewer than 3 levels, a stalled quantity gets no slope.
//! Data: errors e = C h^p on h = 0.4, 0.2, 0.1, 0.05 with the deviations named per case.

use contact_rates::study::rates::{LevelError, Verdict, assess};

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
    let a = assess(&table(&[0.4, 0.2, 0.1, 0.05]), 0.0);
    assert_eq!(a.verdict, Verdict::Fitted);
    assert_eq!(a.used, vec![0, 1, 2, 3]);
    let f = a.fit.unwrap();
    assert!((f.rate - 1.0).abs() < 1e-12 && f.stderr < 1e-12);
    assert!((a.fit_dofs.unwrap().rate + 0.5).abs() < 1e-12);
}

#[test]
fn round_off_levels_are_marked_and_never_fitted() {
    // Level 1 at round-off (nts max_penetration of `rates` at level 1: 3.9e-17).
    let a = assess(&table(&[1e-2, 3.9e-17, 2.5e-3, 1.25e-3]), 0.0);
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
    let a = assess(&table(&[3e-12, 2e-12, 4e-12]), 0.0);
    assert_eq!(a.verdict, Verdict::RoundOff);
    assert!(a.fit.is_none() && a.used.is_empty());
}

#[test]
fn two_usable_levels_give_successive_rates_only() {
    // Three levels, the first at round-off: a line through two points is no fitted rate.
    let a = assess(&table(&[1e-13, 0.2, 0.1]), 0.0);
    assert_eq!(a.verdict, Verdict::TooFewLevels);
    assert!(a.fit.is_none() && a.used.is_empty());
    assert!((a.successive[1].unwrap() - 1.0).abs() < 1e-12);
}

#[test]
fn levels_within_five_times_the_truths_error_are_left_out() {
    // Truth error 1e-3: the finest error 4e-3 is within 5x of it.
    let a = assess(&table(&[4e-2, 2e-2, 1e-2, 4e-3]), 1e-3);
    assert_eq!(a.near_truth, vec![3]);
    assert_eq!(a.used, vec![0, 1, 2]);
    assert_eq!(a.verdict, Verdict::Fitted);
}

#[test]
fn a_stalled_quantity_is_called_non_converging_and_given_no_slope() {
    // nts l2_pressure of `patch`: 5e-2 at every level once the mesh is fine.
    let a = assess(&table(&[0.1, 0.0705, 0.0702, 0.0694, 0.0709]), 0.0);
    assert_eq!(a.verdict, Verdict::NotConverging);
    assert!(a.fit.is_none() && a.used.is_empty());
}

#[test]
fn a_rate_whose_last_successive_rates_spread_is_pre_asymptotic() {
    // Successive rates 2, 1, 0.32: still fitted, but flagged.
    let a = assess(&table(&[1.0, 0.25, 0.125, 0.1]), 0.0);
    assert_eq!(a.verdict, Verdict::PreAsymptotic);
    assert_eq!(a.used, vec![0, 1, 2, 3]);
    assert!(a.fit.is_some());
}
