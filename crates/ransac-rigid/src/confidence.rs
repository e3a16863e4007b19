//! A-contrario confidence: how unlikely is this many inliers if the matches were random?
//!
//! Null hypothesis (as in ORSA, Moisan & Stival 2004): the correspondences pair A's points
//! with B's points at random. Under it, a correspondence is an inlier of a fixed transform `T`
//! with probability `p0`, measured on the data themselves: the share of shuffled pairs
//! `(a_i, b_j)`, `i != j`, with `|a_i - T(b_j)| <= threshold`. This accounts for features
//! crowding along walls, which a uniform-area estimate would miss. A hypothesis built from a
//! minimal sample of 2 that has `k` inliers among `n` correspondences then has
//!
//! `NFA = N_tests * P[Binomial(n - 2, p0) >= k - 2]`,
//!
//! with `N_tests = C(n, 2) + 2 n_seeds` the number of hypotheses the data can generate. By the
//! union bound, the probability that chance alone produced some hypothesis this good is at
//! most `NFA`, so the confidence is `1 - min(1, NFA)`. Duplicated correspondences (several
//! keypoints at one pixel) would inflate `k`, so `n` and `k` count distinct A pixels.

use grid_core::{Correspondence, Rigid2};
use rand::{Rng, RngExt};

/// Minimal sample size of the hypotheses whose chance is measured. 2-point samples are the
/// conservative choice: their two sample points are inliers for free.
const SAMPLE_SIZE: usize = 2;

/// Share of shuffled pairs `(a_i, T(b_j))`, `i != j`, within `threshold_px`.
///
/// Enumerates every pair when there are at most `max_pairs`, else draws `max_pairs` pairs from
/// `rng`. One pseudo-hit is added so an empty count never claims `p0 = 0`.
pub fn chance_inlier_rate<R: Rng + ?Sized>(
    data: &[Correspondence],
    model: &Rigid2,
    threshold_px: f64,
    max_pairs: usize,
    rng: &mut R,
) -> f64 {
    let n = data.len();
    if n < 2 {
        return 1.0;
    }
    let t2 = threshold_px * threshold_px;
    let (s, c) = model.theta.sin_cos();
    let hit = |i: usize, j: usize| {
        let b = data[j].b;
        let x = c * b.x - s * b.y + model.tx - data[i].a.x;
        let y = s * b.x + c * b.y + model.ty - data[i].a.y;
        x * x + y * y <= t2
    };
    let all = n * (n - 1);
    let (hits, pairs) = if all <= max_pairs.max(1) {
        let mut h = 0usize;
        for i in 0..n {
            for j in 0..n {
                h += usize::from(i != j && hit(i, j));
            }
        }
        (h, all)
    } else {
        let mut h = 0usize;
        for _ in 0..max_pairs {
            let i = rng.random_range(0..n);
            let mut j = rng.random_range(0..n - 1);
            if j >= i {
                j += 1;
            }
            h += usize::from(hit(i, j));
        }
        (h, max_pairs)
    };
    ((hits + 1) as f64 / (pairs + 1) as f64).min(1.0)
}

/// Natural log of `P[Binomial(n, p) >= k]`.
///
/// Returns 0 (probability 1) when `k` is at most the mean, which only overstates the tail.
pub fn ln_binomial_tail(n: usize, k: usize, p: f64) -> f64 {
    if k == 0 || p >= 1.0 {
        return 0.0;
    }
    if k > n || p <= 0.0 {
        return f64::NEG_INFINITY;
    }
    if k as f64 <= n as f64 * p {
        return 0.0;
    }
    let ln_choose: f64 = (0..k)
        .map(|i| ((n - i) as f64).ln() - ((i + 1) as f64).ln())
        .sum();
    let ln_pk = ln_choose + k as f64 * p.ln() + (n - k) as f64 * (-p).ln_1p();
    // Terms decrease from k on (k is above the mean): sum the ratios relative to the first.
    let odds = p / (1.0 - p);
    let (mut sum, mut term) = (1.0f64, 1.0f64);
    for j in k..n {
        term *= (n - j) as f64 / (j + 1) as f64 * odds;
        sum += term;
        if term < sum * 1e-17 {
            break;
        }
    }
    (ln_pk + sum.ln()).min(0.0)
}

/// `log10` of the number of false alarms of a hypothesis with `k` inliers among `n`
/// correspondences, `n_tests` possible hypotheses and chance rate `p0`.
pub fn log10_nfa(n: usize, k: usize, p0: f64, n_tests: f64) -> f64 {
    let s = SAMPLE_SIZE.min(k).min(n);
    let tail = ln_binomial_tail(n - s, k - s, p0);
    (n_tests.max(1.0).ln() + tail) / std::f64::consts::LN_10
}

/// Number of hypotheses `n` correspondences with `seeds` 1-point seeds can generate.
pub fn hypothesis_count(n: usize, seeds: usize) -> f64 {
    n as f64 * n.saturating_sub(1) as f64 / 2.0 + 2.0 * seeds as f64
}

/// The confidence `1 - min(1, NFA)` from `log10(NFA)`.
pub fn confidence_from_log10_nfa(log10_nfa: f64) -> f64 {
    if log10_nfa.is_nan() {
        return 0.0;
    }
    1.0 - 10f64.powf(log10_nfa).min(1.0)
}

/// Number of distinct A positions (rounded to the pixel) among the given correspondences.
pub fn distinct_a_pixels<'a, I: IntoIterator<Item = &'a Correspondence>>(
    items: I,
    buf: &mut Vec<(i64, i64)>,
) -> usize {
    buf.clear();
    buf.extend(
        items
            .into_iter()
            .map(|c| (c.a.x.round() as i64, c.a.y.round() as i64)),
    );
    buf.sort_unstable();
    buf.dedup();
    buf.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn exact_tail(n: usize, k: usize, p: f64) -> f64 {
        // Direct sum of pmf terms, for small n.
        let choose = |n: usize, r: usize| -> f64 {
            (0..r).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
        };
        (k..=n)
            .map(|j| choose(n, j) * p.powi(j as i32) * (1.0 - p).powi((n - j) as i32))
            .sum()
    }

    #[test]
    fn binomial_tail_matches_direct_sum() {
        for &(n, k, p) in &[(10, 3, 0.05), (40, 8, 0.01), (100, 5, 0.001), (7, 7, 0.3)] {
            let got = ln_binomial_tail(n, k, p).exp();
            let want = exact_tail(n, k, p);
            assert!(
                (got / want - 1.0).abs() < 1e-9,
                "{n} {k} {p}: {got} vs {want}"
            );
        }
        assert_eq!(ln_binomial_tail(10, 0, 0.1), 0.0);
        assert_eq!(ln_binomial_tail(10, 11, 0.1), f64::NEG_INFINITY);
        assert_eq!(ln_binomial_tail(100, 5, 0.2), 0.0, "k below the mean");
    }

    #[test]
    fn confidence_mapping() {
        assert_eq!(confidence_from_log10_nfa(0.5), 0.0);
        assert!((confidence_from_log10_nfa(-1.0) - 0.9).abs() < 1e-12);
        assert_eq!(confidence_from_log10_nfa(f64::NEG_INFINITY), 1.0);
        assert_eq!(confidence_from_log10_nfa(f64::NAN), 0.0);
    }
}
