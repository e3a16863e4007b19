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
//!
//! ```
//! use fusion::{FusionConfig, MapPlacement, PairEdge, PoseGraphConfig, fuse, solve_poses};
//! use grid_core::{DVec2, OccupancyGrid, Pose2, Rigid2, UNKNOWN};
//!
//! // Two 4 x 1 maps of one corridor: B's cell x is A's cell x + 2.
//! let a = OccupancyGrid::from_cells(4, 1, 0.05, Pose2::default(), vec![100, 0, 0, 0]).unwrap();
//! let b = OccupancyGrid::from_cells(4, 1, 0.05, Pose2::default(), vec![0, 100, 0, UNKNOWN]).unwrap();
//! // A registration's answer (B's pixels onto A's) becomes B's pose in A's frame.
//! let edges = [PairEdge { a: 0, b: 1, b_to_a: Rigid2::new(0.0, 2.0, 0.0), weight: 1.0 }];
//! let centres = [DVec2::new(1.5, 0.0), DVec2::new(1.0, 0.0)];
//! let poses = solve_poses(&centres, 0, &edges, &PoseGraphConfig::default()).unwrap();
//! let placements = [
//!     MapPlacement { grid: &a, pose: poses.poses[0].unwrap(), weight: 0.75 },
//!     MapPlacement { grid: &b, pose: poses.poses[1].unwrap(), weight: 0.25 },
//! ];
//! let config = FusionConfig { margin: 0, ..FusionConfig::default() };
//! let fused = fuse(&a.geometry(), &placements, &config).unwrap();
//! // The canvas keeps one unknown cell each side; A's cell x is the fused cell x + 1.
//! let row: Vec<u8> = (1..6).map(|x| fused.grid.get(x, 1).unwrap()).collect();
//! // A alone, A alone, both free, 0.75 * free + 0.25 * occupied, B alone.
//! assert_eq!(row, [100, 0, 0, 25, 0]);
//! ```

mod error;
mod fuse;
mod poses;

pub use error::{FusionError, Result};
pub use fuse::{FusedMap, FusionConfig, FusionRule, MapPlacement, fuse};
pub use poses::{
    EdgeResidual, EdgeStatus, PairEdge, PoseGraphConfig, PoseGraphSolution, solve_poses,
};
