//! Area keypoints for mapmerge: connected components of obstacle cells ("blobs"), their shape
//! moments, and matching them between two maps.
//!
//! When two robots sense differently (a failed sensor, a larger noise bound) intensity keypoints
//! become unstable, but obstacles still agree. Each matched pair of components fixes a full rigid
//! hypothesis on its own: the rotation from the difference of the major-axis angles (modulo pi)
//! and the translation from the centroids. This crate produces those matches as
//! [`grid_core::Correspondence`]s with `kind: EvidenceKind::Area` and an orientation of period
//! pi; it is not a robust estimator (that is `ransac-rigid`'s job) and it does not read map files.
//!
//! Pipeline: [`not_free_mask`] or [`obstacle_mask`] (+ optional [`close`]) → [`Labeler::label`] → per-component
//! [`Shape`] → [`Blob`] (orientation, reliability, rotation-invariant descriptor) →
//! [`match_blobs`]. [`Blobs`] implements [`grid_core::FeatureExtractor`] and
//! [`BlobCorrespondences`] implements [`grid_core::CorrespondenceSource`]; to match one map
//! against many, extract once with [`Blobs::extract_with`] and call [`match_blobs`] per pair.
//!
//! Strength and limit (numbers and commands in `MEASUREMENTS.md`): obstacles seen whole match
//! well (about 90 % of matches within 2 px on rigidly warped maps); on partial maps from noisy
//! lidars, where obstacles are thin one-sided traces, blobs give only a few true matches per
//! pair at 10 % range noise and almost none at 30 %.

mod error;
mod extract;
mod label;
mod mask;
mod matching;
mod moments;

pub use error::{BlobError, Result};
pub use extract::{
    Blob, BlobConfig, BlobScratch, Blobs, DESCRIPTOR_LEN, DescriptorKind, MaskKind, UnknownPolicy,
};
pub use label::{Connectivity, Labeler};
pub use mask::{close, not_free_mask, obstacle_mask};
pub use matching::{BlobCorrespondences, MatchConfig, match_blobs};
pub use moments::{BoundingBox, Shape};
