//! The sampler axis: which data indices form the next minimal sample.

use rand::{Rng, RngExt};

/// Draws minimal samples and knows how likely a draw is to be all-inlier (for the adaptive
/// iteration count).
pub trait Sampler {
    /// Replace `out` by the indices of the next sample.
    fn sample<R: Rng + ?Sized>(&mut self, rng: &mut R, out: &mut Vec<usize>);

    /// Probability that one draw contains only inliers when `inliers[i]` marks datum `i` as an
    /// inlier of the best model so far.
    fn all_inlier_probability(&self, inliers: &[bool]) -> f64;
}

/// Two distinct indices below `n` (`n >= 2`), uniformly up to a bias below `n / 2^32`.
///
/// One 64-bit draw split in two 32-bit halves, each scaled by a widening multiply (Lemire
/// without the rejection step): the draw loop is the hot path when inliers are rare.
fn two_distinct<R: Rng + ?Sized>(rng: &mut R, n: usize) -> (usize, usize) {
    let r = rng.next_u64();
    let scale = |half: u64, m: usize| ((u128::from(half) * m as u128) >> 32) as usize;
    let i = scale(r >> 32, n);
    let mut j = scale(r & 0xFFFF_FFFF, n - 1);
    if j >= i {
        j += 1;
    }
    (i, j)
}

/// Probability that two distinct uniform draws from `n` items, `k` of them inliers, are both
/// inliers.
fn pair_inlier_probability(k: usize, n: usize) -> f64 {
    if n < 2 || k < 2 {
        return 0.0;
    }
    (k as f64 / n as f64) * ((k - 1) as f64 / (n - 1) as f64)
}

/// Uniform 2-point samples over all data.
#[derive(Debug, Clone)]
pub struct UniformPairSampler {
    n: usize,
}

impl UniformPairSampler {
    /// A sampler over `n` data.
    pub fn new(n: usize) -> Self {
        Self { n }
    }
}

impl Sampler for UniformPairSampler {
    fn sample<R: Rng + ?Sized>(&mut self, rng: &mut R, out: &mut Vec<usize>) {
        out.clear();
        if self.n >= 2 {
            let (i, j) = two_distinct(rng, self.n);
            out.extend([i, j]);
        }
    }

    fn all_inlier_probability(&self, inliers: &[bool]) -> f64 {
        pair_inlier_probability(inliers.iter().filter(|&&b| b).count(), self.n)
    }
}

/// 1-point samples from the seeds (oriented area correspondences) with probability equal to
/// their share of the data, 2-point samples over all data otherwise.
///
/// Drawing by share keeps the mix proportional to the evidence: with no seeds it is the
/// uniform pair sampler, with only seeds it never wastes a draw on pairs.
#[derive(Debug, Clone)]
pub struct HybridSampler {
    n: usize,
    seeds: Vec<usize>,
    p_single: f64,
}

impl HybridSampler {
    /// A sampler over `n` data of which `seeds` (indices) can seed a 1-point hypothesis.
    pub fn new(n: usize, seeds: Vec<usize>) -> Self {
        let p_single = if n == 0 {
            0.0
        } else {
            seeds.len() as f64 / n as f64
        };
        Self { n, seeds, p_single }
    }

    /// Probability that a draw is a 1-point sample.
    pub fn single_point_share(&self) -> f64 {
        self.p_single
    }
}

impl Sampler for HybridSampler {
    fn sample<R: Rng + ?Sized>(&mut self, rng: &mut R, out: &mut Vec<usize>) {
        out.clear();
        if !self.seeds.is_empty() && (self.n < 2 || rng.random::<f64>() < self.p_single) {
            out.push(self.seeds[rng.random_range(0..self.seeds.len())]);
        } else if self.n >= 2 {
            let (i, j) = two_distinct(rng, self.n);
            out.extend([i, j]);
        }
    }

    fn all_inlier_probability(&self, inliers: &[bool]) -> f64 {
        let k = inliers.iter().filter(|&&b| b).count();
        let pair = pair_inlier_probability(k, self.n);
        if self.seeds.is_empty() {
            return pair;
        }
        let seed_in = self.seeds.iter().filter(|&&i| inliers[i]).count();
        let single = seed_in as f64 / self.seeds.len() as f64;
        self.p_single * single + (1.0 - self.p_single) * pair
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn hybrid_draws_singles_by_share_and_only_seeds() {
        let mut s = HybridSampler::new(10, vec![3, 7]);
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let mut out = Vec::new();
        let mut singles = 0;
        for _ in 0..10_000 {
            s.sample(&mut rng, &mut out);
            match out.as_slice() {
                [i] => {
                    assert!(*i == 3 || *i == 7);
                    singles += 1;
                }
                [i, j] => assert!(i != j && *i < 10 && *j < 10),
                other => panic!("{other:?}"),
            }
        }
        // Share 0.2: binomial sd over 10 000 draws is 40.
        assert!((1800..=2200).contains(&singles), "{singles}");
    }

    #[test]
    fn all_inlier_probability_mixes_both_kinds() {
        let s = HybridSampler::new(4, vec![0]);
        let mask = [true, true, false, true];
        // 1/4 * 1 + 3/4 * (3/4 * 2/3)
        assert!((s.all_inlier_probability(&mask) - (0.25 + 0.375)).abs() < 1e-12);
        let u = UniformPairSampler::new(4);
        assert!((u.all_inlier_probability(&mask) - 0.5).abs() < 1e-12);
    }

    #[test]
    fn pairs_cover_every_ordered_pair() {
        let mut s = UniformPairSampler::new(3);
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let mut seen = [[0u32; 3]; 3];
        let mut out = Vec::new();
        for _ in 0..6000 {
            s.sample(&mut rng, &mut out);
            seen[out[0]][out[1]] += 1;
        }
        for (i, row) in seen.iter().enumerate() {
            for (j, &c) in row.iter().enumerate() {
                if i == j {
                    assert_eq!(c, 0);
                } else {
                    assert!((850..=1150).contains(&c), "{i},{j}: {c}");
                }
            }
        }
    }
}
