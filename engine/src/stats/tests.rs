//! The statistics against fixed reference values.
//!
//! The Mann-Whitney and A12 values are SciPy 1.17.1's (`pip install scipy
//! statsmodels` in a throwaway virtual environment), printed by:
//!
//! ```python
//! import numpy as np
//! from scipy.stats import mannwhitneyu, norm
//! from statsmodels.stats.multitest import multipletests
//! cases = {
//!  "small_no_ties": ([1.5, 3.2, 0.7, 4.4, 2.9], [5.1, 6.3, 2.0, 7.7, 8.8, 4.9]),
//!  "textbook_shier": ([19, 22, 16, 29, 24], [20, 11, 17, 12]),
//!  "ties": ([0.5, 0.7, 0.7, 0.9, 1.0, 1.0], [0.7, 1.0, 1.0, 1.0, 0.6]),
//!  "ten_vs_ten": ([0.61, 0.64, 0.58, 0.70, 0.66, 0.59, 0.72, 0.63, 0.68, 0.65],
//!                 [0.97, 0.95, 0.60, 0.99, 0.93, 0.96, 0.91, 0.98, 0.94, 0.62]),
//!  "ten_vs_ten_ties": ([120, 80, 200, 200, 160, 80, 240, 120, 100, 200],
//!                      [20, 40, 20, 60, 200, 40, 20, 80, 40, 60]),
//!  "identical": ([0.5]*4, [0.5]*4),
//!  "separated": ([1, 2, 3, 4, 5, 6, 7, 8], [9, 10, 11, 12, 13, 14, 15, 16]),
//!  "separated_10": (list(range(10)), list(range(10, 20))),
//!  "unequal": ([3.1, 2.2, 5.4], [1.0, 0.4, 2.5, 1.9, 0.8, 1.1, 2.0, 0.3, 1.4, 0.9, 1.7, 1.2]),
//!  "one_each": ([1.0], [2.0]),
//!  "large_unequal": (list(np.arange(0.0, 30.0, 1.5)), list(np.arange(0.25, 12.0, 0.5))),
//! }
//! for k, (a, b) in cases.items():
//!     r = mannwhitneyu(a, b, alternative="two-sided", method="auto")
//!     print(f"{k}: u1={r.statistic!r} p={r.pvalue!r} a12={r.statistic/(len(a)*len(b))!r}")
//! for ps in [[0.01, 0.04, 0.03, 0.005, 0.2], [0.5, 0.5, 0.001]]:
//!     print("holm", ps, list(multipletests(ps, method="holm")[1]))
//! for z in [0, 0.5, 1, 1.96, 2.5, 3, 4, 5, 6, 8, 10, 20, 30, 38]:
//!     print(f"sf {z} {norm.sf(z)!r}")
//! ```
//!
//! The textbook example is Rosie Shier's, "Statistics: 2.3 The Mann-Whitney
//! U Test" (Mathematics Learning Support Centre, 2004; also SciPy's
//! documentation's example): diagnosis ages of 5 men and 4 women, U = 3
//! (the smaller U; 17 the men's), two-sided exact p = 2 x 7 / 126.

use super::*;

/// Relative closeness (absolute near 0).
fn close(got: f64, want: f64, tol: f64) -> bool {
    (got - want).abs() <= tol * want.abs().max(1e-300) || got == want
}

fn check(name: &str, a: &[f64], b: &[f64], u1: f64, p: f64, a12_want: f64, method: Method) {
    let r = mann_whitney(a, b).unwrap();
    assert_eq!(r.u, u1, "{name}: u");
    assert!(close(r.p_value, p, 1e-12), "{name}: p {} against SciPy's {p}", r.p_value);
    assert_eq!(r.method, method, "{name}: method");
    let got = a12(a, b).unwrap();
    assert!(close(got, a12_want, 1e-15), "{name}: a12 {got} against {a12_want}");
    // The same test the other way round: U of the other sample, the same p.
    let back = mann_whitney(b, a).unwrap();
    assert_eq!(back.u, (a.len() * b.len()) as f64 - u1, "{name}: u backwards");
    assert!(close(back.p_value, p, 1e-12), "{name}: p backwards");
}

#[test]
fn mann_whitney_small_samples_without_ties_are_exact() {
    check(
        "small_no_ties",
        &[1.5, 3.2, 0.7, 4.4, 2.9],
        &[5.1, 6.3, 2.0, 7.7, 8.8, 4.9],
        3.0,
        0.030303030303030304,
        0.1,
        Method::Exact,
    );
    check(
        "separated",
        &[1., 2., 3., 4., 5., 6., 7., 8.],
        &[9., 10., 11., 12., 13., 14., 15., 16.],
        0.0,
        0.0001554001554001554,
        0.0,
        Method::Exact,
    );
    check(
        "unequal",
        &[3.1, 2.2, 5.4],
        &[1.0, 0.4, 2.5, 1.9, 0.8, 1.1, 2.0, 0.3, 1.4, 0.9, 1.7, 1.2],
        35.0,
        0.008791208791208791,
        0.9722222222222222,
        Method::Exact,
    );
    check("one_each", &[1.0], &[2.0], 0.0, 1.0, 0.0, Method::Exact);
}

#[test]
fn mann_whitney_matches_the_textbook_example() {
    let men = [19., 22., 16., 29., 24.];
    let women = [20., 11., 17., 12.];
    check("textbook_shier", &men, &women, 17.0, 0.1111111111111111, 0.85, Method::Exact);
    assert!(close(mann_whitney(&men, &women).unwrap().p_value, 2.0 * 7.0 / 126.0, 1e-15));
}

#[test]
fn mann_whitney_with_ties_or_large_samples_is_the_corrected_normal_approximation() {
    check(
        "ties",
        &[0.5, 0.7, 0.7, 0.9, 1.0, 1.0],
        &[0.7, 1.0, 1.0, 1.0, 0.6],
        12.0,
        0.6286884331574623,
        0.4,
        Method::Normal,
    );
    check(
        "ten_vs_ten",
        &[0.61, 0.64, 0.58, 0.70, 0.66, 0.59, 0.72, 0.63, 0.68, 0.65],
        &[0.97, 0.95, 0.60, 0.99, 0.93, 0.96, 0.91, 0.98, 0.94, 0.62],
        15.0,
        0.009108496398030965,
        0.15,
        Method::Normal,
    );
    check(
        "ten_vs_ten_ties",
        &[120., 80., 200., 200., 160., 80., 240., 120., 100., 200.],
        &[20., 40., 20., 60., 200., 40., 20., 80., 40., 60.],
        91.5,
        0.0017620592007453423,
        0.915,
        Method::Normal,
    );
    let ten: Vec<f64> = (0..10).map(f64::from).collect();
    let next: Vec<f64> = (10..20).map(f64::from).collect();
    check("separated_10", &ten, &next, 0.0, 0.00018267179110955002, 0.0, Method::Normal);
    let a: Vec<f64> = (0..20).map(|i| i as f64 * 1.5).collect();
    let b: Vec<f64> = (0..24).map(|i| 0.25 + i as f64 * 0.5).collect();
    check("large_unequal", &a, &b, 372.0, 0.0019385757421664124, 0.775, Method::Normal);
}

#[test]
fn identical_samples_give_p_one_and_a12_one_half() {
    check("identical", &[0.5; 4], &[0.5; 4], 8.0, 1.0, 0.5, Method::Normal);
    assert_eq!(magnitude(&[0.5; 4], &[0.5; 4]), Some(Magnitude::Negligible));
}

#[test]
fn missing_values_are_left_out_and_empty_samples_have_no_test() {
    assert_eq!(mann_whitney(&[], &[1.0]), None);
    assert_eq!(mann_whitney(&[f64::NAN], &[1.0]), None);
    assert_eq!(a12(&[1.0], &[]), None);
    let with_nan = mann_whitney(&[19., 22., f64::NAN, 16., 29., 24.], &[20., 11., 17., 12.]).unwrap();
    assert_eq!(with_nan, mann_whitney(&[19., 22., 16., 29., 24.], &[20., 11., 17., 12.]).unwrap());
}

#[test]
fn exact_counts_are_the_gaussian_binomial() {
    // [4 choose 2]_q = 1 + q + 2q^2 + q^3 + q^4.
    assert_eq!(u_counts(2, 2).unwrap(), vec![1, 1, 2, 1, 1]);
    // Every arrangement counted once: C(18, 8).
    assert_eq!(u_counts(8, 10).unwrap().iter().sum::<i128>(), 43_758);
    // 8 against 10,000 seeds fits in 128 bits.
    let big = u_counts(8, 10_000).unwrap();
    assert_eq!(big.len(), 80_001);
    assert_eq!(big[0], 1);
    assert_eq!(big[1], 1);
}

#[test]
fn normal_tail_matches_scipy() {
    for (z, want) in [
        (0.0, 0.5),
        (0.5, 0.3085375387259869),
        (1.0, 0.15865525393145707),
        (1.96, 0.024997895148220435),
        (2.5, 0.006209665325776132),
        (3.0, 0.0013498980316300933),
        (4.0, 3.167124183311986e-05),
        (5.0, 2.866515718791933e-07),
        (6.0, 9.865876450376946e-10),
        (8.0, 6.22096057427174e-16),
        (10.0, 7.61985302416047e-24),
        (20.0, 2.7536241186061556e-89),
        (30.0, 4.906713927147908e-198),
        (38.0, 0.0),
    ] {
        let got = normal_sf(z);
        assert!(close(got, want, 1e-12), "sf({z}) = {got}, SciPy {want}");
        assert!(close(normal_sf(-z), 1.0 - want, 1e-13), "sf(-{z})");
    }
    assert!(normal_sf(f64::NAN).is_nan());
    assert_eq!(normal_sf(f64::INFINITY), 0.0);
    assert_eq!(normal_sf(f64::NEG_INFINITY), 1.0);
}

#[test]
fn a12_sizes_use_vargha_and_delaneys_thresholds() {
    // 10 against 10: 100 pairs, so A = wins / 100 exactly.
    let b: Vec<f64> = (0..10).map(|i| i as f64 * 10.0).collect();
    // `a` wins `w` of the pairs: nine values above all of b's below ...
    let sample = |wins: usize| -> Vec<f64> {
        let mut a = vec![-1.0; 10];
        let mut left = wins;
        for x in a.iter_mut() {
            let take = left.min(10);
            // Above `take` of b's values.
            *x = if take == 0 { -1.0 } else { (take - 1) as f64 * 10.0 + 5.0 };
            left -= take;
        }
        a
    };
    for (wins, size) in [
        (50, Magnitude::Negligible),
        (55, Magnitude::Negligible),
        (56, Magnitude::Small),
        (63, Magnitude::Small),
        (64, Magnitude::Medium),
        (70, Magnitude::Medium),
        (71, Magnitude::Large),
        (100, Magnitude::Large),
        (44, Magnitude::Small),
        (45, Magnitude::Negligible),
        (36, Magnitude::Medium),
        (29, Magnitude::Large),
        (0, Magnitude::Large),
    ] {
        let a = sample(wins);
        assert_eq!(a12(&a, &b), Some(wins as f64 / 100.0), "{wins}");
        assert_eq!(magnitude(&a, &b), Some(size), "{wins}");
    }
}

#[test]
fn holm_matches_statsmodels() {
    assert_eq!(holm(&[0.01, 0.04, 0.03, 0.005, 0.2]), vec![0.04, 0.09, 0.09, 0.025, 0.2]);
    let got = holm(&[0.5, 0.5, 0.001]);
    assert_eq!(got, vec![1.0, 1.0, 0.003]);
    assert_eq!(holm(&[]), Vec::<f64>::new());
    assert_eq!(holm(&[0.3]), vec![0.3]);
    let with_nan = holm(&[0.01, f64::NAN, 0.04]);
    assert_eq!(with_nan[0], 0.02);
    assert!(with_nan[1].is_nan());
    assert_eq!(with_nan[2], 0.04);
}

#[test]
fn the_median_is_the_middle_or_the_mean_of_the_two_middles() {
    assert_eq!(median(&[]), None);
    assert_eq!(median(&[3.0]), Some(3.0));
    assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
    assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), Some(2.5));
    assert_eq!(median(&[f64::NAN, 1.0, 2.0]), Some(1.5));
}

/// The exact bootstrap distribution of the median of 9 distinct values:
/// the resample's median is the j-th value (from 0) or below with
/// probability P(Binomial(9, (j + 1) / 9) >= 5): 0.0014 for j = 0, 0.0304
/// for j = 1, 0.9696 for j = 6, 0.9986 for j = 7 (SciPy's `binom.sf(4, 9,
/// (j + 1) / 9)`). So the 2.5th percentile of 10,000 resamples is the
/// second value and the 97.5th the eighth, each by at least 3 standard
/// deviations of the resampling.
#[test]
fn the_bootstrap_interval_of_nine_values_is_the_exact_bootstraps() {
    let v: Vec<f64> = (1..=9).map(f64::from).collect();
    assert_eq!(median_ci(&v), Some(Interval { low: 2.0, high: 8.0 }));
}

#[test]
fn the_bootstrap_interval_is_deterministic_and_contains_the_median() {
    let v = [0.61, 0.64, 0.58, 0.70, 0.66, 0.59, 0.72, 0.63, 0.68, 0.65];
    let ci = median_ci(&v).unwrap();
    let mut reversed = v;
    reversed.reverse();
    assert_eq!(median_ci(&reversed), Some(ci), "the order of the values does not matter");
    let m = median(&v).unwrap();
    assert!(ci.low <= m && m <= ci.high && ci.low >= 0.58 && ci.high <= 0.72, "{ci:?}");
    assert_eq!(median_ci(&[0.5]), Some(Interval { low: 0.5, high: 0.5 }));
    assert_eq!(median_ci(&[0.5; 10]), Some(Interval { low: 0.5, high: 0.5 }));
    assert_eq!(median_ci(&[]), None);
    assert_eq!(median_ci(&[f64::NAN]), None);
}
