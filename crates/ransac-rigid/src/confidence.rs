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

use grid_core::{Correspondence, DVec2, Rigid2};

/// Minimal sample size of the hypotheses whose chance is measured. 2-point samples are the
/// conservative choice: their two sample points are inliers for free.
const SAMPLE_SIZE: usize = 2;

/// A's points bucketed in a dense grid, to count chance pairs exactly.
///
/// Built once per correspondence set (it does not depend on the hypothesis). Cells are at
/// least the threshold wide and sized for about one point each, so counting the shuffled pairs
/// of one hypothesis visits at most 3 x 3 cells per B point: `O(n)` instead of `O(n²)`.
#[derive(Debug, Clone)]
pub struct ChanceGrid {
    threshold_px: f64,
    origin: DVec2,
    cell_px: f64,
    cols: usize,
    rows: usize,
    /// Cell `c` holds `points[start[c]..start[c + 1]]`.
    start: Vec<u32>,
    /// `(A point, correspondence index)` grouped by cell.
    points: Vec<(DVec2, u32)>,
}

impl ChanceGrid {
    /// Bucket the A points of `data` (all finite) for a `threshold_px` inlier threshold.
    pub fn new(data: &[Correspondence], threshold_px: f64) -> Self {
        let n = data.len().max(1);
        let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for c in data {
            lo = lo.min(c.a);
            hi = hi.max(c.a);
        }
        if data.is_empty() {
            (lo, hi) = (DVec2::ZERO, DVec2::ZERO);
        }
        let ext = (hi - lo).max(DVec2::splat(threshold_px));
        let mut cell_px = threshold_px.max((ext.x * ext.y / n as f64).sqrt());
        let dims = |s: f64| ((ext.x / s) as usize + 1, (ext.y / s) as usize + 1);
        // Thin point sets (a line of features) would otherwise get many empty cells.
        while dims(cell_px).0 * dims(cell_px).1 > 4 * n + 16 {
            cell_px *= 1.5;
        }
        let (cols, rows) = dims(cell_px);
        let index = |p: DVec2| {
            let q = ((p - lo) / cell_px).floor();
            (q.y as usize).min(rows - 1) * cols + (q.x as usize).min(cols - 1)
        };
        let mut start = vec![0u32; cols * rows + 1];
        for c in data {
            start[index(c.a) + 1] += 1;
        }
        for i in 1..start.len() {
            start[i] += start[i - 1];
        }
        let mut fill = start.clone();
        let mut points = vec![(DVec2::ZERO, 0u32); data.len()];
        for (i, c) in data.iter().enumerate() {
            let k = index(c.a);
            points[fill[k] as usize] = (c.a, i as u32);
            fill[k] += 1;
        }
        Self {
            threshold_px,
            origin: lo,
            cell_px,
            cols,
            rows,
            start,
            points,
        }
    }

    /// Share of shuffled pairs `(a_i, T(b_j))`, `i != j`, within the threshold: the chance
    /// inlier rate `p0` of `model`. Every pair is counted (no sampling); one pseudo-hit is
    /// added so that an empty count never claims `p0 = 0`.
    pub fn chance_inlier_rate(&self, data: &[Correspondence], model: &Rigid2) -> f64 {
        let n = data.len();
        if n < 2 {
            return 1.0;
        }
        let t = self.threshold_px;
        let t2 = t * t;
        let (s, c) = model.theta.sin_cos();
        let span = |v: f64, len: usize| -> Option<(usize, usize)> {
            let (a, b) = (
                ((v - t) / self.cell_px).floor(),
                ((v + t) / self.cell_px).floor(),
            );
            if b < 0.0 || a > (len - 1) as f64 {
                return None;
            }
            Some((a.max(0.0) as usize, (b as usize).min(len - 1)))
        };
        let mut hits = 0usize;
        for (j, d) in data.iter().enumerate() {
            let b = d.b;
            let p = DVec2::new(c * b.x - s * b.y + model.tx, s * b.x + c * b.y + model.ty);
            let q = p - self.origin;
            let (Some((x0, x1)), Some((y0, y1))) = (span(q.x, self.cols), span(q.y, self.rows))
            else {
                continue;
            };
            for y in y0..=y1 {
                let row = y * self.cols;
                let cells =
                    &self.points[self.start[row + x0] as usize..self.start[row + x1 + 1] as usize];
                hits += cells
                    .iter()
                    .filter(|e| e.1 as usize != j && e.0.distance_squared(p) <= t2)
                    .count();
            }
        }
        let pairs = n as f64 * (n - 1) as f64;
        ((hits as f64 + 1.0) / (pairs + 1.0)).min(1.0)
    }
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

    fn brute_force_rate(data: &[Correspondence], model: &Rigid2, t: f64) -> (usize, f64) {
        let mut hits = 0;
        for i in 0..data.len() {
            for j in 0..data.len() {
                hits += usize::from(
                    i != j && data[i].a.distance_squared(model.apply(data[j].b)) <= t * t,
                );
            }
        }
        let n = data.len() as f64;
        (hits, (hits as f64 + 1.0) / (n * (n - 1.0) + 1.0))
    }

    #[test]
    fn grid_count_equals_brute_force() {
        use grid_core::EvidenceKind;
        let corr = |a, b| Correspondence {
            a,
            b,
            orientation: None,
            weight: 1.0,
            kind: EvidenceKind::Intensity,
        };
        // A lattice with 2 px spacing and a 3 px threshold (many pairs near the boundary), and a
        // thin line of points (the grid must coarsen, not blow up).
        let lattice: Vec<_> = (0..200)
            .map(|i| {
                corr(
                    DVec2::new((i % 20) as f64 * 2.0, (i / 20) as f64 * 2.0 - 7.0),
                    DVec2::new((i % 13) as f64 * 2.5 + 0.3, (i / 13) as f64 * 1.5),
                )
            })
            .collect();
        let line: Vec<_> = (0..300)
            .map(|i| {
                let x = (i * 7 % 300) as f64 * 3.1;
                corr(
                    DVec2::new(x, 0.5 * (i % 3) as f64),
                    DVec2::new(x + 1.0, 1.0),
                )
            })
            .collect();
        for (data, model) in [
            (&lattice, Rigid2::new(0.3, -2.0, 1.0)),
            (&line, Rigid2::new(0.0, 0.5, -1.0)),
            (&line, Rigid2::new(0.01, -4.0, 0.0)),
        ] {
            let (hits, want) = brute_force_rate(data, &model, 3.0);
            assert!(hits > 50, "{hits}");
            let got = ChanceGrid::new(data, 3.0).chance_inlier_rate(data, &model);
            assert_eq!(got, want);
        }
    }

    #[test]
    fn confidence_mapping() {
        assert_eq!(confidence_from_log10_nfa(0.5), 0.0);
        assert!((confidence_from_log10_nfa(-1.0) - 0.9).abs() < 1e-12);
        assert_eq!(confidence_from_log10_nfa(f64::NEG_INFINITY), 1.0);
        assert_eq!(confidence_from_log10_nfa(f64::NAN), 0.0);
    }
}
