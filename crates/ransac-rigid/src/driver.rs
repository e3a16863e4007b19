//! The one generic RANSAC loop: sample, estimate, score, locally optimise, keep the top k.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::consensus::Consensus;
use crate::estimator::Estimator;
use crate::sampler::Sampler;

/// Loop settings; see [`crate::RansacConfig`] for the defaults.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriverConfig {
    /// Hard cap on iterations (non-degenerate samples, each scored over all data).
    pub max_iterations: usize,
    /// Hard cap on samples drawn, degenerate ones included.
    pub max_draws: usize,
    /// Iterations always run, whatever the adaptive estimate says.
    pub min_iterations: usize,
    /// Desired probability of having drawn at least one all-inlier sample.
    pub confidence: f64,
    /// How many distinct hypotheses to keep.
    pub top_k: usize,
    /// Refit-on-inliers rounds after a hypothesis enters the top k.
    pub refine_iterations: usize,
    /// Seed of the ChaCha8 generator: same seed and data, same answer.
    pub seed: u64,
}

/// A model with its consensus score and inlier count.
#[derive(Debug, Clone, PartialEq)]
pub struct Scored<M> {
    /// The model.
    pub model: M,
    /// Consensus score (sum of [`Consensus::score`]).
    pub score: f64,
    /// Data within the threshold.
    pub inliers: usize,
}

/// What the loop found.
#[derive(Debug, Clone, PartialEq)]
pub struct DriverOutput<M> {
    /// Distinct hypotheses, best score first, at most `top_k`.
    pub hypotheses: Vec<Scored<M>>,
    /// Non-degenerate samples evaluated.
    pub iterations: usize,
    /// Samples drawn, degenerate ones included.
    pub draws: usize,
}

/// Iterations needed to draw an all-inlier sample with probability `confidence` when one draw
/// succeeds with probability `p_good` (Fischler & Bolles).
pub fn required_iterations(p_good: f64, confidence: f64, cap: usize) -> usize {
    if p_good.is_nan() || p_good <= 0.0 {
        return cap;
    }
    if p_good >= 1.0 {
        return 1;
    }
    let n = (1.0 - confidence).ln() / (1.0 - p_good).ln();
    if n.is_finite() && n < cap as f64 {
        n.ceil().max(1.0) as usize
    } else {
        cap
    }
}

/// Buffers the loop reuses, so an iteration allocates nothing.
struct Work<M> {
    sample: Vec<usize>,
    models: Vec<M>,
    residuals: Vec<f64>,
    inliers: Vec<usize>,
}

/// Run RANSAC with local optimisation over `data`.
///
/// Each non-degenerate sample yields 0..n models. A model that beats the best so far is
/// refined on its inliers (up to `refine_iterations` rounds, kept while the score does not
/// drop); a model that enters the top k is inserted so that the list stays pairwise distinct
/// under [`Estimator::is_same`]. After the loop every kept hypothesis is refined the same way
/// and the list rebuilt.
///
/// Stopping: the adaptive count is in draws, not iterations. Each draw is all-inlier with
/// probability [`Sampler::all_inlier_probability`] whether or not the pre-check
/// ([`Estimator::is_sample_valid`]) later rejects it, so after `required_iterations(p)` draws
/// an all-inlier sample has been seen with probability `confidence`; the pre-check only saves
/// the scoring of the rejected ones. At least `min_iterations` scored samples are run (draws
/// permitting), at most `max_iterations` scored and `max_draws` drawn.
pub fn run<E, S, C>(
    estimator: &E,
    sampler: &mut S,
    consensus: &C,
    data: &[E::Datum],
    config: &DriverConfig,
) -> DriverOutput<E::Model>
where
    E: Estimator,
    S: Sampler,
    C: Consensus,
{
    let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
    let weights: Vec<f64> = data.iter().map(|d| estimator.weight(d)).collect();
    let top_k = config.top_k.max(1);
    let mut top: Vec<Scored<E::Model>> = Vec::with_capacity(top_k + 1);
    let mut mask = vec![false; data.len()];
    let mut needed = config.max_draws;
    let mut work = Work {
        sample: Vec::with_capacity(2),
        models: Vec::with_capacity(2),
        residuals: Vec::with_capacity(data.len()),
        inliers: Vec::with_capacity(data.len()),
    };
    let (mut iterations, mut draws) = (0, 0);
    while iterations < config.max_iterations
        && draws < config.max_draws
        && (iterations < config.min_iterations || draws < needed)
    {
        draws += 1;
        sampler.sample(&mut rng, &mut work.sample);
        if work.sample.is_empty() || !estimator.is_sample_valid(data, &work.sample) {
            continue;
        }
        iterations += 1;
        work.models.clear();
        estimator.estimate(data, &work.sample, &mut work.models);
        for m in std::mem::take(&mut work.models).drain(..) {
            let (score, count) = evaluate(estimator, consensus, data, &weights, &m, &mut work);
            let enters = top.len() < top_k || top.last().is_some_and(|w| score > w.score);
            if !enters {
                continue;
            }
            // Local optimisation only for a new best (as in LO-RANSAC): near every draw enters
            // a top-k list of junk early on, and refitting each would cost more than the
            // search. The other top-k entries are refined once after the loop.
            let is_best = top.first().is_none_or(|b| score > b.score);
            let cand = if is_best {
                local_optimise(
                    estimator, consensus, data, &weights, config, m, score, count, &mut work,
                )
            } else {
                Scored {
                    model: m,
                    score,
                    inliers: count,
                }
            };
            let was_best = top.first().map(|b| b.score);
            insert_distinct(estimator, &mut top, cand, top_k);
            let best = &top[0];
            if was_best.is_none_or(|s| best.score > s) {
                estimator.residuals_sq(&best.model, data, &mut work.residuals);
                let t2 = consensus.threshold_sq();
                for (flag, &r) in mask.iter_mut().zip(&work.residuals) {
                    *flag = r <= t2;
                }
                let p = sampler.all_inlier_probability(&mask);
                needed = required_iterations(p, config.confidence, config.max_draws);
            }
        }
    }
    // Final polish: refine every kept hypothesis and rebuild the list, since two of them may
    // converge to one model.
    let mut polished = Vec::with_capacity(top.len());
    for h in top {
        let (score, count) = evaluate(estimator, consensus, data, &weights, &h.model, &mut work);
        let cand = local_optimise(
            estimator, consensus, data, &weights, config, h.model, score, count, &mut work,
        );
        insert_distinct(estimator, &mut polished, cand, top_k);
    }
    DriverOutput {
        hypotheses: polished,
        iterations,
        draws,
    }
}

fn evaluate<E: Estimator, C: Consensus>(
    estimator: &E,
    consensus: &C,
    data: &[E::Datum],
    weights: &[f64],
    model: &E::Model,
    work: &mut Work<E::Model>,
) -> (f64, usize) {
    estimator.residuals_sq(model, data, &mut work.residuals);
    let t2 = consensus.threshold_sq();
    let (mut score, mut count) = (0.0, 0);
    for (&r, &w) in work.residuals.iter().zip(weights) {
        score += consensus.score(r, w);
        count += usize::from(r <= t2);
    }
    (score, count)
}

#[allow(clippy::too_many_arguments)]
fn local_optimise<E: Estimator, C: Consensus>(
    estimator: &E,
    consensus: &C,
    data: &[E::Datum],
    weights: &[f64],
    config: &DriverConfig,
    mut model: E::Model,
    mut score: f64,
    mut count: usize,
    work: &mut Work<E::Model>,
) -> Scored<E::Model> {
    // `work.residuals` holds the residuals of `model` on entry and after every kept round.
    let t2 = consensus.threshold_sq();
    for _ in 0..config.refine_iterations {
        work.inliers.clear();
        work.inliers.extend(
            work.residuals
                .iter()
                .enumerate()
                .filter(|&(_, &r)| r <= t2)
                .map(|(i, _)| i),
        );
        let Some(refined) = estimator.refine(data, &work.inliers) else {
            break;
        };
        let (s, c) = evaluate(estimator, consensus, data, weights, &refined, work);
        // `>=`: an inlier count often ties after the refit, and the least-squares model on
        // the same inliers is the better one.
        if s >= score {
            let converged = s == score && c == count;
            (model, score, count) = (refined, s, c);
            if converged {
                break;
            }
        } else {
            break;
        }
    }
    Scored {
        model,
        score,
        inliers: count,
    }
}

/// Insert keeping `top` sorted by score (descending), pairwise distinct and at most `k` long.
fn insert_distinct<E: Estimator>(
    estimator: &E,
    top: &mut Vec<Scored<E::Model>>,
    cand: Scored<E::Model>,
    k: usize,
) {
    if top
        .iter()
        .any(|h| h.score >= cand.score && estimator.is_same(&h.model, &cand.model))
    {
        return;
    }
    top.retain(|h| !estimator.is_same(&h.model, &cand.model));
    let at = top.partition_point(|h| h.score >= cand.score);
    if at < k {
        top.insert(at, cand);
        top.truncate(k);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn required_iterations_matches_the_formula() {
        // 20 % inliers, 2-point samples: ln(0.001) / ln(0.96) = 169.2
        assert_eq!(required_iterations(0.04, 0.999, 10_000), 170);
        assert_eq!(required_iterations(0.04, 0.999, 100), 100);
        assert_eq!(required_iterations(0.0, 0.999, 77), 77);
        assert_eq!(required_iterations(1.0, 0.999, 77), 1);
    }
}
