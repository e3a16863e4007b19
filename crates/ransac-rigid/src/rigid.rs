//! The public entry point: configuration, result, and [`estimate_rigid`].

use grid_core::{Correspondence, EvidenceKind, Rigid2};

use crate::RansacError;
use crate::confidence::{
    ChanceGrid, confidence_from_log10_nfa, distinct_a_pixels, hypothesis_count, log10_nfa,
};
use crate::consensus::{Consensus, InlierCount, Msac};
use crate::driver::{self, DriverConfig};
use crate::estimator::{RigidEstimator, RigidEstimatorConfig, is_single_point_seed};
use crate::sampler::HybridSampler;

/// How hypotheses are scored.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Scoring {
    /// Number of inliers.
    InlierCount,
    /// MSAC truncated quadratic, weighted by correspondence weight (the default).
    #[default]
    Msac,
}

/// Settings of [`estimate_rigid`]. Every field has a documented default.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct RansacConfig {
    /// Inlier threshold: `|a - T(b)|` in pixels. Default 3.0.
    pub threshold_px: f64,
    /// Hard cap on iterations (non-degenerate samples). Default 2000.
    pub max_iterations: usize,
    /// Iterations always run. Default 100.
    pub min_iterations: usize,
    /// Desired probability of having drawn at least one all-inlier sample; drives the adaptive
    /// iteration count. Default 0.999. (Not the result's confidence.)
    pub confidence: f64,
    /// Distinct hypotheses returned. Default 5.
    pub top_k: usize,
    /// Seed of the ChaCha8 generator. Default 0.
    pub seed: u64,
    /// Minimum distance between a 2-point sample's points, in both maps; closer pairs fix the
    /// angle poorly. Default 5.0 px.
    pub min_pair_distance_px: f64,
    /// Refit-on-inliers rounds for a hypothesis entering the top k. Default 3.
    pub refine_iterations: usize,
    /// Consensus score. Default [`Scoring::Msac`].
    pub scoring: Scoring,
    /// Whether oriented area correspondences give 1-point hypotheses. Default true.
    pub single_point: bool,
    /// Reject a 2-point hypothesis whose angle is farther than this (degrees) from the
    /// orientation difference of every oriented member of the sample. Default `None` (off).
    pub orientation_prune_deg: Option<f64>,
    /// Hypotheses closer than this in angle (degrees) ... Default 2.0.
    pub distinct_angle_deg: f64,
    /// ... and moving the centre of B's points less than this apart (pixels) are one
    /// hypothesis in the top-k list. Default 5.0.
    pub distinct_shift_px: f64,
    /// Cap on samples drawn, degenerate ones included; the adaptive count is in draws, since
    /// the cheap pre-checks reject most outlier pairs without scoring them. Default 200 000.
    pub max_draws: usize,
}

impl Default for RansacConfig {
    fn default() -> Self {
        Self {
            threshold_px: 3.0,
            max_iterations: 2000,
            min_iterations: 100,
            confidence: 0.999,
            top_k: 5,
            seed: 0,
            min_pair_distance_px: 5.0,
            refine_iterations: 3,
            scoring: Scoring::Msac,
            single_point: true,
            orientation_prune_deg: None,
            distinct_angle_deg: 2.0,
            distinct_shift_px: 5.0,
            max_draws: 200_000,
        }
    }
}

/// `x >= 0`, false for NaN.
fn non_negative(x: f64) -> bool {
    x >= 0.0
}

impl RansacConfig {
    /// Checks every setting: `Err(RansacError::InvalidConfig)` naming the first out of range.
    /// [`estimate_rigid`] calls it first.
    pub fn validate(&self) -> Result<(), RansacError> {
        let bad = |msg| Err(RansacError::InvalidConfig(msg));
        if !(self.threshold_px.is_finite() && self.threshold_px > 0.0) {
            return bad("threshold_px must be finite and positive");
        }
        if self.max_iterations == 0 || self.max_draws == 0 {
            return bad("max_iterations and max_draws must be at least 1");
        }
        if !(self.confidence > 0.0 && self.confidence < 1.0) {
            return bad("confidence must be in (0, 1)");
        }
        if self.top_k == 0 {
            return bad("top_k must be at least 1");
        }
        if !non_negative(self.min_pair_distance_px) {
            return bad("min_pair_distance_px must be non-negative");
        }
        if self.orientation_prune_deg.is_some_and(|d| !non_negative(d)) {
            return bad("orientation_prune_deg must be non-negative");
        }
        if !(non_negative(self.distinct_angle_deg) && non_negative(self.distinct_shift_px)) {
            return bad("distinct_angle_deg and distinct_shift_px must be non-negative");
        }
        Ok(())
    }
}

/// Inliers split by the kind of evidence.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct KindCounts {
    /// Inliers of kind [`EvidenceKind::Intensity`].
    pub intensity: usize,
    /// Inliers of kind [`EvidenceKind::Area`].
    pub area: usize,
}

/// One of the top-k distinct hypotheses.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Hypothesis {
    /// B→A transform, pixel convention, angle in `(-pi, pi]`.
    pub model: Rigid2,
    /// Correspondences within the threshold.
    pub inliers_count: usize,
    /// Consensus score (see [`Scoring`]).
    pub score: f64,
    /// `1 - min(1, NFA)`, see [`crate::confidence`].
    pub confidence: f64,
    /// `log10` of the number of false alarms; below 0 is meaningful.
    pub log10_nfa: f64,
}

/// What [`estimate_rigid`] found.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RansacResult {
    /// The best B→A transform (pixel convention), refined on its inliers.
    pub model: Rigid2,
    /// Indices into the input slice of the best model's inliers, ascending.
    pub inliers: Vec<usize>,
    /// The inliers by evidence kind.
    pub inlier_count_by_kind: KindCounts,
    /// Probability, lower bound, that the inliers are not explained by chance matches:
    /// `1 - min(1, NFA)`; see [`crate::confidence`].
    pub confidence: f64,
    /// `log10(NFA)` of the best model.
    pub log10_nfa: f64,
    /// The top-k distinct hypotheses, best score first; `hypotheses[0]` is `model`.
    pub hypotheses: Vec<Hypothesis>,
    /// Non-degenerate samples evaluated.
    pub iterations: usize,
    /// Input correspondences that were usable (finite, positive weight).
    pub usable: usize,
}

/// Whether a correspondence takes part: finite positions and a finite positive weight.
fn usable(c: &Correspondence) -> bool {
    c.a.is_finite() && c.b.is_finite() && c.weight.is_finite() && c.weight > 0.0
}

/// Estimate the rigid transform mapping B onto A from putative correspondences.
///
/// Hybrid RANSAC: 2-point samples over all correspondences, 1-point samples from area
/// correspondences with an orientation (period `pi` gives two candidates); deterministic for
/// a given `config.seed`. Unusable correspondences (non-finite, weight ≤ 0) are ignored.
///
/// ```
/// use grid_core::{Correspondence, DVec2, EvidenceKind, Rigid2};
/// use ransac_rigid::{RansacConfig, estimate_rigid};
///
/// let truth = Rigid2::new(0.5, 12.0, -3.0);
/// let corr = |b: DVec2, a: DVec2| Correspondence {
///     a, b, orientation: None, weight: 1.0, kind: EvidenceKind::Intensity,
/// };
/// let mut data: Vec<_> = (0..12)
///     .map(|i| DVec2::new((i * 37 % 100) as f64, (i * 61 % 90) as f64))
///     .map(|b| corr(b, truth.apply(b)))
///     .collect();
/// data.push(corr(DVec2::new(5.0, 5.0), DVec2::new(80.0, 1.0))); // an outlier
/// let r = estimate_rigid(&data, &RansacConfig::default()).unwrap();
/// assert!((r.model.theta - 0.5).abs() < 1e-9);
/// assert_eq!(r.inliers, (0..12).collect::<Vec<_>>());
/// assert!(r.confidence > 0.99);
/// ```
///
/// # Errors
/// [`RansacError::TooFewCorrespondences`] below 2 usable correspondences,
/// [`RansacError::NoHypothesis`] when every sample is degenerate (e.g. all points within
/// `min_pair_distance_px` of each other and no oriented area correspondence),
/// [`RansacError::InvalidConfig`] for an out-of-range setting.
pub fn estimate_rigid(
    correspondences: &[Correspondence],
    config: &RansacConfig,
) -> Result<RansacResult, RansacError> {
    config.validate()?;
    let index: Vec<usize> = (0..correspondences.len())
        .filter(|&i| usable(&correspondences[i]))
        .collect();
    if index.len() < 2 {
        return Err(RansacError::TooFewCorrespondences {
            usable: index.len(),
            needed: 2,
        });
    }
    let data: Vec<Correspondence> = index.iter().map(|&i| correspondences[i]).collect();
    let estimator = RigidEstimator::new(
        RigidEstimatorConfig {
            threshold_px: config.threshold_px,
            min_pair_distance_px: config.min_pair_distance_px,
            orientation_prune_rad: config.orientation_prune_deg.map(f64::to_radians),
            single_point: config.single_point,
            distinct_angle_rad: config.distinct_angle_deg.to_radians(),
            distinct_shift_px: config.distinct_shift_px,
        },
        &data,
    );
    let seeds: Vec<usize> = if config.single_point {
        (0..data.len())
            .filter(|&i| is_single_point_seed(&data[i]))
            .collect()
    } else {
        Vec::new()
    };
    let n_seeds = seeds.len();
    let mut sampler = HybridSampler::new(data.len(), seeds);
    let dc = DriverConfig {
        max_iterations: config.max_iterations,
        max_draws: config.max_draws,
        min_iterations: config.min_iterations,
        confidence: config.confidence,
        top_k: config.top_k,
        refine_iterations: config.refine_iterations,
        seed: config.seed,
    };
    let out = match config.scoring {
        Scoring::InlierCount => driver::run(
            &estimator,
            &mut sampler,
            &InlierCount::new(config.threshold_px),
            &data,
            &dc,
        ),
        Scoring::Msac => driver::run(
            &estimator,
            &mut sampler,
            &Msac::new(config.threshold_px),
            &data,
            &dc,
        ),
    };
    if out.hypotheses.is_empty() {
        return Err(RansacError::NoHypothesis { draws: out.draws });
    }

    let chance = ChanceGrid::new(&data, config.threshold_px);
    let mut pix = Vec::with_capacity(data.len());
    let n_distinct = distinct_a_pixels(&data, &mut pix);
    let n_tests = hypothesis_count(n_distinct, n_seeds);
    let t2 = Msac::new(config.threshold_px).threshold_sq();
    let mut best_inliers = Vec::new();
    let mut hypotheses = Vec::with_capacity(out.hypotheses.len());
    for (rank, h) in out.hypotheses.iter().enumerate() {
        let model = h.model.normalized();
        let (s, c) = model.theta.sin_cos();
        let inl: Vec<usize> = (0..data.len())
            .filter(|&i| {
                let b = data[i].b;
                let x = c * b.x - s * b.y + model.tx - data[i].a.x;
                let y = s * b.x + c * b.y + model.ty - data[i].a.y;
                x * x + y * y <= t2
            })
            .collect();
        let k = distinct_a_pixels(inl.iter().map(|&i| &data[i]), &mut pix);
        let p0 = chance.chance_inlier_rate(&data, &model);
        let l = log10_nfa(n_distinct, k, p0, n_tests);
        hypotheses.push(Hypothesis {
            model,
            inliers_count: inl.len(),
            score: h.score,
            confidence: confidence_from_log10_nfa(l),
            log10_nfa: l,
        });
        if rank == 0 {
            best_inliers = inl;
        }
    }
    let mut by_kind = KindCounts::default();
    for &i in &best_inliers {
        match data[i].kind {
            EvidenceKind::Intensity => by_kind.intensity += 1,
            EvidenceKind::Area => by_kind.area += 1,
        }
    }
    let best = &hypotheses[0];
    Ok(RansacResult {
        model: best.model,
        confidence: best.confidence,
        log10_nfa: best.log10_nfa,
        inliers: best_inliers.iter().map(|&i| index[i]).collect(),
        inlier_count_by_kind: by_kind,
        hypotheses,
        iterations: out.iterations,
        usable: data.len(),
    })
}
