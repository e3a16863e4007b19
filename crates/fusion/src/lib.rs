//! Fusion: lay occupancy grid maps placed by rigid transforms onto one canvas and combine their
//! cells, and solve every map's pose from pairwise registrations.
//!
//! It is for: turning registered maps into one map ([`fuse`]) with the paper's rule (the
//! reliability-weighted mean of the maps known at a cell, each map's own cell where it alone is
//! known) or a conservative one, and turning pairwise answers into one pose per map
//! ([`solve_poses`]: a maximum-confidence spanning tree, then a joint least-squares
//! refinement over the loops). It is not for: finding the transforms (the `mapmerge` crate),
//! reading or writing files (`grid_core::io`).
//!
//! Frames: every pose here maps a pixel of an input map onto a pixel of the reference frame,
//! in the pixel convention of `grid_core` (`x` column, `y` row from the top). The fused map's
//! frame is the reference map's frame shifted by a whole number of cells, so that the
//! reference's cells are copied, not resampled, and the fused map's world coordinates are the
//! reference map's.

mod error;
mod fuse;
mod poses;

pub use error::{FusionError, Result};
pub use fuse::{FusedMap, FusionConfig, FusionRule, MapPlacement, fuse};
pub use poses::{
    EdgeResidual, EdgeStatus, PairEdge, PoseGraphConfig, PoseGraphSolution, solve_poses,
};
