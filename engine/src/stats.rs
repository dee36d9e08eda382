//! The statistics experiments are compared by: the median and its bootstrap
//! confidence interval, the Mann-Whitney U test, the Vargha-Delaney A12
//! effect size and the Holm correction. Pure functions of numbers: no I/O,
//! no clock, one seeded generator (the bootstrap's), so the same values
//! always give the same figures.
//!
//! Non-finite values (`NaN` is how a summary marks a missing figure) are
//! left out by every function here, so a sample is its finite values.
//!
//! No maintained crate did all of this: `statrs` (0.19) has a Mann-Whitney U
//! test with SciPy's choice of method, but its exact p-value enumerates every
//! arrangement of the ranks (exponential in the samples' sizes), and it has
//! no effect size, bootstrap or Holm correction; so the few functions are
//! written here and tested against SciPy's values on fixed data.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The finite values of `values`, sorted.
fn sorted(values: &[f64]) -> Vec<f64> {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    v.sort_by(f64::total_cmp);
    v
}

/// The median of sorted values: the middle value of an odd count, the mean
/// of the two middle values of an even count.
pub(crate) fn median_of_sorted(v: &[f64]) -> Option<f64> {
    let n = v.len();
    match n {
        0 => None,
        _ if n % 2 == 1 => Some(v[n / 2]),
        _ => Some((v[n / 2 - 1] + v[n / 2]) / 2.0),
    }
}

/// The median of the finite values: the middle value of an odd count, the
/// mean of the two middle values of an even count (`None` without any).
/// The engine's one median: summaries, sweeps, comparisons and pictures.
pub fn median(values: &[f64]) -> Option<f64> {
    median_of_sorted(&sorted(values))
}

/// A closed interval of values.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Interval {
    pub low: f64,
    pub high: f64,
}

/// Resamples drawn by [`median_ci`].
pub const BOOTSTRAP_RESAMPLES: usize = 10_000;

/// The seed of [`median_ci`]'s generator (ChaCha8).
pub const BOOTSTRAP_SEED: u64 = 51;

/// The percentile bootstrap 95% confidence interval of the median:
/// [`BOOTSTRAP_RESAMPLES`] resamples of the sorted finite values (drawn
/// with replacement by ChaCha8 seeded with [`BOOTSTRAP_SEED`], so the
/// interval depends on the values alone, not their order or the run), the
/// median of each, and their 2.5th and 97.5th percentiles by linear
/// interpolation between order statistics (NumPy's default `linear`). One
/// value gives the interval of that value; none gives `None`.
pub fn median_ci(values: &[f64]) -> Option<Interval> {
    let v = sorted(values);
    let n = v.len();
    if n == 0 || n > u32::MAX as usize {
        return None;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(BOOTSTRAP_SEED);
    let mut counts = vec![0u32; n];
    let mut medians = Vec::with_capacity(BOOTSTRAP_RESAMPLES);
    for _ in 0..BOOTSTRAP_RESAMPLES {
        counts.iter_mut().for_each(|c| *c = 0);
        for _ in 0..n {
            counts[rng.random_range(0..n as u32) as usize] += 1;
        }
        // The resample is sorted as `v` is: its k-th value is the first index
        // whose cumulative count passes k.
        let nth = |k: usize| {
            let mut seen = 0usize;
            for (i, &c) in counts.iter().enumerate() {
                seen += c as usize;
                if seen > k {
                    return v[i];
                }
            }
            v[n - 1]
        };
        medians.push(if n % 2 == 1 { nth(n / 2) } else { (nth(n / 2 - 1) + nth(n / 2)) / 2.0 });
    }
    medians.sort_by(f64::total_cmp);
    Some(Interval { low: percentile(&medians, 0.025), high: percentile(&medians, 0.975) })
}

/// The `q` quantile of sorted, non-empty values, by linear interpolation
/// between the order statistics (Hyndman and Fan's type 7).
fn percentile(v: &[f64], q: f64) -> f64 {
    let h = (v.len() - 1) as f64 * q;
    let lo = h.floor() as usize;
    let hi = (lo + 1).min(v.len() - 1);
    v[lo] + (h - lo as f64) * (v[hi] - v[lo])
}

/// How a p-value was computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Method {
    /// The exact distribution of U (no ties, and a sample of at most 8).
    #[serde(rename = "exact")]
    Exact,
    /// The normal approximation with the tie correction of the variance and
    /// a continuity correction of 0.5.
    #[serde(rename = "normal")]
    Normal,
}

impl Method {
    /// In a word, for a summary's table (whose text says what each is).
    pub fn words(self) -> &'static str {
        match self {
            Method::Exact => "exact",
            Method::Normal => "normal",
        }
    }
}

/// A two-sided Mann-Whitney U test of two samples.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct MannWhitney {
    /// U of the first sample: the pairs (a, b) with a > b, ties counted half.
    pub u: f64,
    pub p_value: f64,
    pub method: Method,
}

/// Largest sample, on the smaller side, for which the exact distribution is used.
const EXACT_MAX: usize = 8;

/// The two-sided Mann-Whitney U test of `a` against `b` (their finite
/// values; `None` when either has none), as SciPy's `mannwhitneyu(a, b,
/// alternative='two-sided', method='auto')` computes it:
///
/// - **exact** when there is no tie in the pooled values and the smaller
///   sample has at most 8 values: p = 2 P(U >= max(U_a, U_b)) (at most 1)
///   under the exact null distribution of U, the coefficients of the
///   Gaussian binomial coefficient \[n_a + n_b choose n_a\]_q, counted in
///   128-bit integers (the normal approximation below, should they not fit);
/// - otherwise (ties, or both samples larger than 8, e.g. 10 seeds against
///   10) the **normal approximation**: z = (max(U_a, U_b) - n_a n_b / 2 -
///   0.5) / s with s^2 = n_a n_b / 12 ((n + 1) - sum(t^3 - t) / (n (n -
///   1))), t the size of each group of tied values, and p = 2 P(Z > z) (at
///   most 1); when every value is tied, s = 0 and p = 1.
///
/// U is computed from average ranks.
pub fn mann_whitney(a: &[f64], b: &[f64]) -> Option<MannWhitney> {
    let (a, b) = (sorted(a), sorted(b));
    let (n1, n2) = (a.len(), b.len());
    if n1 == 0 || n2 == 0 {
        return None;
    }
    // Pool, rank (average ranks for ties) and count the ties' groups.
    let mut pooled: Vec<(f64, bool)> =
        a.iter().map(|&x| (x, true)).chain(b.iter().map(|&x| (x, false))).collect();
    pooled.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut rank_sum = 0.0;
    let mut tie_term = 0.0;
    let mut ties = false;
    let mut i = 0;
    while i < pooled.len() {
        let mut j = i + 1;
        while j < pooled.len() && pooled[j].0 == pooled[i].0 {
            j += 1;
        }
        let t = (j - i) as f64;
        // Ranks i+1 ..= j, averaged.
        let rank = (i + 1 + j) as f64 / 2.0;
        rank_sum += rank * pooled[i..j].iter().filter(|p| p.1).count() as f64;
        tie_term += t * t * t - t;
        ties |= j - i > 1;
        i = j;
    }
    let u1 = rank_sum - (n1 * (n1 + 1)) as f64 / 2.0;
    let u2 = (n1 * n2) as f64 - u1;
    let u = u1.max(u2);
    if !ties && n1.min(n2) <= EXACT_MAX {
        if let Some(p) = exact_p(u as u64, n1, n2) {
            return Some(MannWhitney { u: u1, p_value: p, method: Method::Exact });
        }
    }
    let n = (n1 + n2) as f64;
    let (m1, m2) = (n1 as f64, n2 as f64);
    let var = m1 * m2 / 12.0 * ((n + 1.0) - tie_term / (n * (n - 1.0)));
    let p = if pooled.first().map(|p| p.0) == pooled.last().map(|p| p.0) || var <= 0.0 {
        1.0
    } else {
        let z = (u - m1 * m2 / 2.0 - 0.5) / var.sqrt();
        (2.0 * normal_sf(z)).clamp(0.0, 1.0)
    };
    Some(MannWhitney { u: u1, p_value: p, method: Method::Normal })
}

/// 2 P(U >= u) under the null distribution of U for samples of `n1` and `n2`
/// values without ties (at most 1), or `None` if the counts overflow.
fn exact_p(u: u64, n1: usize, n2: usize) -> Option<f64> {
    let counts = u_counts(n1.min(n2), n1.max(n2))?;
    let total = counts.iter().try_fold(0i128, |s, &c| s.checked_add(c))?;
    let tail = counts.iter().skip(u as usize).try_fold(0i128, |s, &c| s.checked_add(c))?;
    Some((2.0 * tail as f64 / total as f64).min(1.0))
}

/// The number of arrangements of `k` and `n` values giving each U in 0 ..=
/// k n: the coefficients of prod_{i=1..k} (1 - q^(n+i)) / (1 - q^i), built
/// by multiplying and dividing one factor at a time (after step i, the
/// Gaussian binomial [n + i choose i]_q, whose coefficients are counts).
fn u_counts(k: usize, n: usize) -> Option<Vec<i128>> {
    let len = k.checked_mul(n)?.checked_add(1)?;
    let mut c = vec![0i128; len];
    c[0] = 1;
    for i in 1..=k {
        let degree = i * n;
        // Times (1 - q^(n+i)), from the top down.
        for u in (n + i..=degree).rev() {
            c[u] = c[u].checked_sub(c[u - n - i])?;
        }
        // Divided by (1 - q^i): d[u] = c[u] + d[u - i], from the bottom up.
        for u in i..=degree {
            c[u] = c[u].checked_add(c[u - i])?;
        }
    }
    Some(c)
}

/// P(Z > z) for the standard normal.
pub fn normal_sf(z: f64) -> f64 {
    0.5 * erfc(z / std::f64::consts::SQRT_2)
}

/// The complementary error function, to about 1e-15 relative (1e-13 far in the tail, where e^(-x^2) magnifies the rounding of x^2): below 0.8
/// from the series of erf (positive terms), above it from the continued
/// fraction of erfc evaluated from its 2000th term back.
fn erfc(x: f64) -> f64 {
    if x.is_nan() {
        return f64::NAN;
    }
    if x < 0.0 {
        return 2.0 - erfc(-x);
    }
    let two_over_sqrt_pi = std::f64::consts::FRAC_2_SQRT_PI;
    if x < 0.8 {
        // erf(x) = 2/sqrt(pi) e^(-x^2) sum_n 2^n x^(2n+1) / (1 3 5 ... (2n+1))
        let (mut term, mut sum) = (x, x);
        let mut n = 0.0;
        while term > 1e-17 * sum {
            n += 1.0;
            term *= 2.0 * x * x / (2.0 * n + 1.0);
            sum += term;
        }
        return 1.0 - two_over_sqrt_pi * (-x * x).exp() * sum;
    }
    if x > 27.0 {
        return 0.0;
    }
    // erfc(x) = e^(-x^2) / sqrt(pi) / (x + (1/2) / (x + 1 / (x + (3/2) / (x + ...))))
    let mut f = x;
    for k in (1..=2000).rev() {
        f = x + (k as f64 / 2.0) / f;
    }
    two_over_sqrt_pi / 2.0 * (-x * x).exp() / f
}

/// The Vargha-Delaney A12 of `a` against `b` (their finite values; `None`
/// when either has none): the probability that a value of `a` is larger
/// than a value of `b`, ties counted half (U_a / (n_a n_b)). 0.5: no
/// difference; above: `a` tends to be larger.
pub fn a12(a: &[f64], b: &[f64]) -> Option<f64> {
    let (wins, n) = a12_counts(a, b)?;
    Some(wins as f64 / 2.0 / n as f64)
}

/// Twice the pairs where `a` wins (a tie counts 1), and the number of pairs.
fn a12_counts(a: &[f64], b: &[f64]) -> Option<(u128, u128)> {
    let (a, b) = (sorted(a), sorted(b));
    if a.is_empty() || b.is_empty() {
        return None;
    }
    let mut wins = 0u128;
    for x in &a {
        // b is sorted: the values below x, and those equal to it.
        let below = b.partition_point(|y| y < x);
        let up_to = b.partition_point(|y| y <= x);
        wins += 2 * below as u128 + (up_to - below) as u128;
    }
    Some((wins, a.len() as u128 * b.len() as u128))
}

/// The size of an A12, in Vargha and Delaney's (2000) words.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Magnitude {
    Negligible,
    Small,
    Medium,
    Large,
}

impl Magnitude {
    pub fn words(self) -> &'static str {
        match self {
            Magnitude::Negligible => "negligible",
            Magnitude::Small => "small",
            Magnitude::Medium => "medium",
            Magnitude::Large => "large",
        }
    }
}

/// The size of `a`'s A12 against `b`: with A = max(A12, 1 - A12), small from
/// 0.56, medium from 0.64, large from 0.71 (Vargha and Delaney 2000),
/// negligible below; compared in whole counts, so 0.56 is exactly small.
pub fn magnitude(a: &[f64], b: &[f64]) -> Option<Magnitude> {
    let (wins, n) = a12_counts(a, b)?;
    // A = wins / 2n; A >= t/100 is 100 wins >= 2 n t.
    let wins = wins.max(2 * n - wins);
    let at_least = |t: u128| 100 * wins >= 2 * n * t;
    Some(if at_least(71) {
        Magnitude::Large
    } else if at_least(64) {
        Magnitude::Medium
    } else if at_least(56) {
        Magnitude::Small
    } else {
        Magnitude::Negligible
    })
}

/// Holm's (1979) step-down correction of `p_values`, in their order:
/// sorted ascending, the i-th (from 0) of m becomes the largest of
/// min(1, (m - j) p_j) over j <= i. A NaN stays NaN and is not counted.
pub fn holm(p_values: &[f64]) -> Vec<f64> {
    let mut order: Vec<usize> = (0..p_values.len()).filter(|&i| !p_values[i].is_nan()).collect();
    order.sort_by(|&i, &j| p_values[i].total_cmp(&p_values[j]));
    let m = order.len();
    let mut out = vec![f64::NAN; p_values.len()];
    let mut running: f64 = 0.0;
    for (rank, &i) in order.iter().enumerate() {
        running = running.max(((m - rank) as f64 * p_values[i]).min(1.0));
        out[i] = running;
    }
    out
}

#[cfg(test)]
mod tests;
