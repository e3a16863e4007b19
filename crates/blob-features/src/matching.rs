//! Matching blobs of two maps by nearest neighbour in descriptor space.

use grid_core::{Correspondence, CorrespondenceSource, EvidenceKind, OccupancyGrid, Orientation};

use crate::{Blob, BlobScratch, Blobs, DESCRIPTOR_LEN};

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
}

impl Default for MatchConfig {
    fn default() -> Self {
        Self {
            ratio: 0.8,
            mutual: true,
            max_distance: 0.3,
        }
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
        let ba = &a[ia];
        let r = if d2.is_finite() && d2 > 0.0 {
            (d1 / d2).sqrt()
        } else {
            0.0
        };
        let weight = ((1.0 - r) * ba.reliability * qb.reliability).clamp(1e-3, 1.0);
        out.push(Correspondence {
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
            weight,
            kind: EvidenceKind::Area,
        });
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

impl CorrespondenceSource for BlobCorrespondences {
    fn correspondences(&self, a: &OccupancyGrid, b: &OccupancyGrid, out: &mut Vec<Correspondence>) {
        let mut scratch = BlobScratch::default();
        let (mut ba, mut bb) = (Vec::new(), Vec::new());
        self.blobs.extract_with(a, &mut scratch, &mut ba);
        self.blobs.extract_with(b, &mut scratch, &mut bb);
        match_blobs(&ba, &bb, &self.matching, out);
    }
}
