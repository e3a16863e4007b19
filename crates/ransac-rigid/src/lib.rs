//! Robust rigid registration from putative correspondences: hybrid RANSAC that mixes 2-point
//! hypotheses (any two correspondences) with 1-point hypotheses (one area correspondence whose
//! orientation fixes the angle), plus an a-contrario confidence.
//!
//! It is for: turning `&[Correspondence]` into the [`Rigid2`](grid_core::Rigid2) mapping map B
//! onto map A, its inliers, the top-k distinct hypotheses and a confidence that means
//! something ([`confidence`]). It is not for: finding correspondences (feature crates), or
//! checking a hypothesis against the maps themselves (the pipeline's acceptance index).
//!
//! Invariant: deterministic for a given seed (ChaCha8). Split by axis of variation as in
//! kornia-rs: an [`Estimator`], a [`Sampler`], a [`Consensus`] rule and one generic loop,
//! [`driver::run`]; [`estimate_rigid`] wires the rigid versions together.

pub mod confidence;
mod consensus;
pub mod driver;
mod error;
mod estimator;
mod procrustes;
mod rigid;
mod sampler;

pub use consensus::{Consensus, InlierCount, Msac};
pub use error::RansacError;
pub use estimator::{
    Estimator, RigidEstimator, RigidEstimatorConfig, is_single_point_seed, orientation_usable,
};
pub use procrustes::fit_rigid_weighted;
pub use rigid::{Hypothesis, KindCounts, RansacConfig, RansacResult, Scoring, estimate_rigid};
pub use sampler::{HybridSampler, Sampler, UniformPairSampler};
