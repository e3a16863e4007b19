use std::path::PathBuf;

/// Result alias of this crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything that can go wrong when building, reading or writing a grid.
///
/// Every variant that concerns a file names it, so that the binary can print one line that
/// tells the user which file is wrong and why.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A grid dimension is zero.
    #[error("zero-size map ({width} x {height} cells)")]
    ZeroSize {
        /// Width in cells.
        width: usize,
        /// Height in cells.
        height: usize,
    },
    /// The cell buffer does not have `width * height` entries.
    #[error("cell buffer has {got} entries, expected {expected}")]
    CellCount {
        /// Entries given.
        got: usize,
        /// `width * height`.
        expected: usize,
    },
    /// A `nav_msgs/OccupancyGrid` value outside `-1..=100`.
    #[error("occupancy value {value} at index {index} is outside -1..=100")]
    OccupancyValue {
        /// The offending value.
        value: i8,
        /// Its index in row-major order.
        index: usize,
    },
    /// The resolution is not a finite positive number.
    #[error("resolution {0} is not a positive finite number")]
    Resolution(f64),
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What the OS said.
        source: std::io::Error,
    },
    /// A file's content is not what it should be.
    #[error("{}: {reason}", path.display())]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong, in words a user can act on.
        reason: String,
    },
    /// [`crate::OccupancyGrid::resample`] would make a grid of more than 2^28 cells.
    #[error(
        "the map would be {width} x {height} cells at {resolution} m/cell, more than 2^28 \
         (268435456)"
    )]
    ResampleTooLarge {
        /// Width in cells it would have.
        width: f64,
        /// Height in cells it would have.
        height: f64,
        /// The resolution asked for.
        resolution: f64,
    },
    /// A map was read fine but holds no free or occupied cell, so there is nothing to register
    /// or merge. The loader never returns it (an all-unknown map is a valid file); callers that
    /// need known cells use [`crate::io::require_known_cells`].
    #[error("{}: the map has no free or occupied cell (every cell is unknown)", path.display())]
    AllUnknown {
        /// The map file.
        path: PathBuf,
    },
}
