//! Registration of one pair: correspondences → RANSAC hypotheses → refinement → verification.

use std::time::Instant;

use grid_core::{Correspondence, CorrespondenceSource, EvidenceKind, OccupancyGrid, Rigid2};
use ransac_rigid::{RansacConfig, estimate_rigid};

use crate::refine::{RefineConfig, refine};
use crate::verify::{PreparedMap, Verification, VerifyConfig, verify};

/// Everything that tunes [`register_with`], with documented defaults.
#[derive(Debug, Clone, Default)]
pub struct PairConfig {
    /// RANSAC settings (seed included: the result is deterministic for a seed).
    pub ransac: RansacConfig,
    /// ICP refinement of each candidate.
    pub refine: RefineConfig,
    /// Verification thresholds that decide acceptance.
    pub verify: VerifyConfig,
}

/// One candidate transform after refinement and verification.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Candidate {
    /// B→A transform, pixel convention.
    pub transform: Rigid2,
    /// RANSAC inliers of the hypothesis this candidate came from.
    pub ransac_inliers: usize,
    /// RANSAC's a-contrario confidence of that hypothesis.
    pub ransac_confidence: f64,
    /// The scores on the maps.
    pub verification: Verification,
    /// Whether it passes the verification thresholds.
    pub accepted: bool,
}

/// Wall-clock time of each stage, in milliseconds.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct Timings {
    /// Feature extraction and matching.
    pub correspondences_ms: f64,
    /// RANSAC.
    pub ransac_ms: f64,
    /// Precomputation of both maps for verification.
    pub prepare_ms: f64,
    /// Refinement and verification of all candidates.
    pub verify_ms: f64,
}

/// The answer for one pair.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Registration {
    /// The best verified candidate, if any passed verification.
    pub accepted: Option<Candidate>,
    /// Why the pair was declined, when it was.
    pub reason: Option<String>,
    /// Every candidate, best score first.
    pub candidates: Vec<Candidate>,
    /// Correspondences found, by kind.
    pub correspondences: KindTotals,
    /// RANSAC inliers of the accepted candidate's hypothesis, by kind.
    pub inliers: KindTotals,
    /// Stage timings.
    pub timings: Timings,
}

/// A count per evidence kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct KindTotals {
    /// From intensity keypoints (SIFT).
    pub intensity: usize,
    /// From area keypoints (components).
    pub area: usize,
}

impl KindTotals {
    fn of(corrs: &[Correspondence], indices: impl Iterator<Item = usize>) -> Self {
        let mut t = Self::default();
        for i in indices {
            match corrs[i].kind {
                EvidenceKind::Intensity => t.intensity += 1,
                EvidenceKind::Area => t.area += 1,
            }
        }
        t
    }
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// Register `b` onto `a` using the correspondences of `sources`.
///
/// Never fails: a pair without a trustworthy answer comes back with `accepted: None` and a
/// reason, which the binary turns into exit code 3.
pub fn register_with(
    a: &OccupancyGrid,
    b: &OccupancyGrid,
    sources: &[&dyn CorrespondenceSource],
    config: &PairConfig,
) -> Registration {
    let mut timings = Timings::default();
    let t0 = Instant::now();
    let mut corrs = Vec::new();
    for s in sources {
        s.correspondences(a, b, &mut corrs);
    }
    timings.correspondences_ms = ms(t0);
    let correspondences = KindTotals::of(&corrs, 0..corrs.len());
    let declined = |reason: String, timings, candidates| Registration {
        accepted: None,
        reason: Some(reason),
        candidates,
        correspondences,
        inliers: KindTotals::default(),
        timings,
    };

    let t0 = Instant::now();
    let ransac = match estimate_rigid(&corrs, &config.ransac) {
        Ok(r) => r,
        Err(e) => {
            timings.ransac_ms = ms(t0);
            return declined(format!("no transform hypothesis: {e}"), timings, Vec::new());
        }
    };
    timings.ransac_ms = ms(t0);

    let t0 = Instant::now();
    let (pa, pb) = rayon::join(
        || PreparedMap::new(a, &config.verify),
        || PreparedMap::new(b, &config.verify),
    );
    timings.prepare_ms = ms(t0);

    let t0 = Instant::now();
    let mut candidates: Vec<Candidate> = ransac
        .hypotheses
        .iter()
        .map(|h| {
            let transform = refine(&pa, &pb, &h.model, &config.refine).normalized();
            let verification = verify(&pa, &pb, &transform, &config.verify);
            Candidate {
                transform,
                ransac_inliers: h.inliers_count,
                ransac_confidence: h.confidence,
                accepted: verification.accepted(&config.verify),
                verification,
            }
        })
        .collect();
    timings.verify_ms = ms(t0);
    candidates.sort_by(|x, y| {
        y.accepted
            .cmp(&x.accepted)
            .then(y.verification.score().total_cmp(&x.verification.score()))
    });
    match candidates.first() {
        Some(best) if best.accepted => {
            // Inliers of the final (refined) transform, so the split by kind describes the answer.
            let t = best.transform;
            let close = corrs
                .iter()
                .enumerate()
                .filter(|(_, c)| (c.a - t.apply(c.b)).length() <= config.ransac.threshold_px);
            let inliers = KindTotals::of(&corrs, close.map(|(i, _)| i));
            Registration {
                accepted: Some(best.clone()),
                reason: None,
                candidates,
                correspondences,
                inliers,
                timings,
            }
        }
        Some(best) => {
            let v = &best.verification;
            let reason = format!(
                "no hypothesis passed verification (best: wall lift {:.2}, acceptance index {:.2}, overlap {:.1}% of the smaller map)",
                v.wall_lift,
                v.acceptance_index,
                100.0 * v.overlap_fraction
            );
            declined(reason, timings, candidates)
        }
        None => declined("RANSAC produced no hypothesis".into(), timings, candidates),
    }
}
