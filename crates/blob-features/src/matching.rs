//! Matching blobs of two maps by nearest neighbour in descriptor space.

use grid_core::{Correspondence, CorrespondenceSource, EvidenceKind, OccupancyGrid, Orientation};

use crate::{Blob, BlobConfig, BlobError, BlobScratch, Blobs, DESCRIPTOR_LEN, Result};

/// Matching settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MatchConfig {
    /// Lowe's ratio test: keep a match when `best / second_best` distance is below this.
    /// Default 0.8.
    pub ratio: f64,
    /// Keep a match only when each blob is the other's nearest neighbour. Default true.
    pub mutual: bool,
    /// Largest descriptor distance accepted at all (log units: 0.3 is about a 30 % size
    /// difference). Default 0.3.
    pub max_distance: f64,
    /// Candidates per blob of B. `1` (default) keeps the nearest neighbour after the ratio
    /// test and the mutual check; `k > 1` instead keeps the `k` nearest blobs of A within
    /// `max_distance` (no ratio test, no mutual check), weighted `1 / (1 + rank)`, for a robust
    /// estimator that prefers more true matches among more outliers (repetitive scenes).
    pub candidates: usize,
}

impl Default for MatchConfig {
    fn default() -> Self {
        Self {
            ratio: 0.8,
            mutual: true,
            max_distance: 0.3,
            candidates: 1,
        }
    }
}

impl MatchConfig {
    /// Checks the numbers: `ratio` and `max_distance` must be 0 or more (infinity allowed:
    /// it switches the test off). Both are compared squared, so a negative value would act as
    /// its absolute value, and a NaN would drop every match without a word.
    /// [`BlobCorrespondences::new`] calls it.
    pub fn validate(&self) -> Result<()> {
        for (name, value) in [("ratio", self.ratio), ("max_distance", self.max_distance)] {
            if value.is_nan() || value < 0.0 {
                return Err(BlobError::Setting {
                    name,
                    value,
                    rule: "0 or more",
                });
            }
        }
        Ok(())
    }
}

fn dist2(a: &[f64; DESCRIPTOR_LEN], b: &[f64; DESCRIPTOR_LEN]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

/// Nearest and second-nearest (squared distances) of `q` among `set`.
fn two_nearest(q: &Blob, set: &[Blob]) -> Option<(usize, f64, f64)> {
    let (mut best, mut d1, mut d2) = (usize::MAX, f64::INFINITY, f64::INFINITY);
    for (i, s) in set.iter().enumerate() {
        let d = dist2(&q.descriptor, &s.descriptor);
        if d < d1 {
            (d2, d1, best) = (d1, d, i);
        } else if d < d2 {
            d2 = d;
        }
    }
    (best != usize::MAX).then_some((best, d1, d2))
}

/// Append to `out` the matches of the blobs `b` (map B) among the blobs `a` (map A): each blob of
/// B takes its nearest neighbour in A's descriptor space if it passes the distance gate, the
/// ratio test and (optionally) the mutual check. Each match becomes a correspondence from B's
/// centroid to A's centroid, with both major-axis angles (period pi) when both blobs have one,
/// and weight `(1 - ratio) * reliability_a * reliability_b` (kept in `(0, 1]`).
///
/// Both blob lists must come from the same [`crate::DescriptorKind`].
pub fn match_blobs(a: &[Blob], b: &[Blob], config: &MatchConfig, out: &mut Vec<Correspondence>) {
    if config.candidates > 1 {
        return match_top_k(a, b, config, out);
    }
    let max_d2 = config.max_distance * config.max_distance;
    let ratio2 = config.ratio * config.ratio;
    for qb in b {
        let Some((ia, d1, d2)) = two_nearest(qb, a) else {
            return;
        };
        if d1 > max_d2 || (d2.is_finite() && d1 >= ratio2 * d2) {
            continue;
        }
        if config.mutual {
            let Some((back, _, _)) = two_nearest(&a[ia], b) else {
                continue;
            };
            if !std::ptr::eq(&b[back], qb) {
                continue;
            }
        }
        let r = if d2.is_finite() && d2 > 0.0 {
            (d1 / d2).sqrt()
        } else {
            0.0
        };
        out.push(correspondence(&a[ia], qb, 1.0 - r));
    }
}

/// The `k` nearest blobs of A for each blob of B (see [`MatchConfig::candidates`]).
fn match_top_k(a: &[Blob], b: &[Blob], config: &MatchConfig, out: &mut Vec<Correspondence>) {
    let max_d2 = config.max_distance * config.max_distance;
    let k = config.candidates;
    // (squared distance, index in a), kept sorted; one buffer for the whole call.
    let mut best: Vec<(f64, usize)> = Vec::with_capacity(k + 1);
    for qb in b {
        best.clear();
        for (i, s) in a.iter().enumerate() {
            let d = dist2(&qb.descriptor, &s.descriptor);
            if d > max_d2 || (best.len() == k && d >= best[k - 1].0) {
                continue;
            }
            let at = best.partition_point(|&(e, _)| e <= d);
            best.insert(at, (d, i));
            best.truncate(k);
        }
        for (rank, &(_, i)) in best.iter().enumerate() {
            out.push(correspondence(&a[i], qb, 1.0 / (1 + rank) as f64));
        }
    }
}

/// A correspondence from blob `qb` of B to blob `ba` of A with match quality `quality`.
fn correspondence(ba: &Blob, qb: &Blob, quality: f64) -> Correspondence {
    Correspondence {
        a: ba.shape.centroid,
        b: qb.shape.centroid,
        orientation: match (ba.orientation, qb.orientation) {
            (Some(oa), Some(ob)) => Some(Orientation {
                a: oa,
                b: ob,
                period: std::f64::consts::PI,
            }),
            _ => None,
        },
        weight: (quality * ba.reliability * qb.reliability).clamp(1e-3, 1.0),
        kind: EvidenceKind::Area,
    }
}

/// Blob extraction plus matching: implements [`CorrespondenceSource`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BlobCorrespondences {
    /// Extraction settings.
    pub blobs: Blobs,
    /// Matching settings.
    pub matching: MatchConfig,
}

impl BlobCorrespondences {
    /// A source with the given settings, checked ([`BlobConfig::validate`],
    /// [`MatchConfig::validate`]). The fields are public; a source built from them directly
    /// is not checked.
    pub fn new(blobs: BlobConfig, matching: MatchConfig) -> Result<Self> {
        blobs.validate()?;
        matching.validate()?;
        Ok(Self {
            blobs: Blobs::new(blobs),
            matching,
        })
    }
}

impl CorrespondenceSource for BlobCorrespondences {
    fn correspondences(&self, a: &OccupancyGrid, b: &OccupancyGrid, out: &mut Vec<Correspondence>) {
        let mut scratch = BlobScratch::default();
        let (mut ba, mut bb) = (Vec::new(), Vec::new());
        self.blobs.extract_with(a, &mut scratch, &mut ba);
        self.blobs.extract_with(b, &mut scratch, &mut bb);
        match_blobs(&ba, &bb, &self.matching, out);
    }
}
