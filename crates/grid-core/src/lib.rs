//! The smallest crate of mapmerge: the occupancy grid, the rigid 2-D transform, ROS map_server
//! I/O, and the few traits through which the other crates compose.
//!
//! It is for: holding a map (every cell unknown or an occupancy probability), converting
//! between the pixel convention and ROS world coordinates, reading and writing map_server
//! files. It is not for: feature extraction, registration or fusion — those crates depend on
//! this one and meet only through [`FeatureExtractor`] and [`CorrespondenceSource`].
//!
//! Conventions (fixed for the whole project): pixel `x` is the column, `y` the row counted from
//! the top row of the image file, integer coordinates are pixel centres. A registration result
//! is the [`Rigid2`] mapping a pixel of map B onto the same place in map A.

mod error;
mod grid;
pub mod io;
pub mod metrics;
mod traits;
mod transform;

pub use error::{Error, Result};
pub use glam::DVec2;
pub use grid::{CellCounts, CellState, GridGeometry, OccupancyGrid, Pose2, UNKNOWN};
pub use traits::{
    Correspondence, CorrespondenceSource, EvidenceKind, FeatureExtractor, Orientation,
};
pub use transform::{Rigid2, wrap_angle};
