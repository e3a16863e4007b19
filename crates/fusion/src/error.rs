/// Result alias of this crate.
pub type Result<T, E = FusionError> = std::result::Result<T, E>;

/// Everything that can go wrong when fusing maps or solving their poses.
#[derive(Debug, thiserror::Error)]
pub enum FusionError {
    /// Nothing to fuse.
    #[error("no maps to fuse")]
    NoMaps,
    /// A map's resolution differs from the reference's: a rigid pixel transform cannot place
    /// it.
    #[error(
        "map {index} has resolution {resolution} m/cell, the reference {reference} m/cell; resample it first"
    )]
    Resolution {
        /// Index of the map.
        index: usize,
        /// Its resolution.
        resolution: f64,
        /// The reference's resolution.
        reference: f64,
    },
    /// A weight (reliability) that is not a finite positive number.
    #[error("map {index}'s weight {weight} is not a finite number greater than 0")]
    Weight {
        /// Index of the map.
        index: usize,
        /// The weight given.
        weight: f64,
    },
    /// A pair edge's weight (confidence) that is not a finite positive number.
    #[error("pair edge {index}'s weight {weight} is not a finite number greater than 0")]
    EdgeWeight {
        /// Index of the edge.
        index: usize,
        /// The weight given.
        weight: f64,
    },
    /// A bound of [`crate::PoseGraphConfig`] that is NaN or negative (NaN would keep every
    /// loop, a wrong one included).
    #[error("pose graph setting {name} = {value}: must be 0 or more")]
    Setting {
        /// The field of [`crate::PoseGraphConfig`].
        name: &'static str,
        /// The value given.
        value: f64,
    },
    /// The reference map of the pose graph is not one of its maps.
    #[error("the reference map {reference} is not one of the {nodes} maps")]
    Reference {
        /// The reference given.
        reference: usize,
        /// Number of maps.
        nodes: usize,
    },
    /// A pose or pairwise transform with a NaN or infinite component.
    #[error("{what} is not finite")]
    NotFinite {
        /// Which pose or transform.
        what: String,
    },
    /// No map has a known cell.
    #[error("no map has a known cell")]
    NothingKnown,
    /// The fused canvas would exceed [`crate::FusionConfig::max_cells`].
    #[error("the fused map would be {width} x {height} cells, more than the limit of {max} cells")]
    TooLarge {
        /// Width in cells.
        width: u64,
        /// Height in cells.
        height: u64,
        /// The limit.
        max: usize,
    },
    /// An edge names a map that does not exist, or joins a map to itself.
    #[error("pair edge {index} joins maps {a} and {b}, but there are {nodes} maps")]
    BadEdge {
        /// Index of the edge.
        index: usize,
        /// Its first map.
        a: usize,
        /// Its second map.
        b: usize,
        /// Number of maps.
        nodes: usize,
    },
    /// The least-squares system could not be solved.
    #[error("the pose least-squares system has no finite solution")]
    Solve,
    /// Building the fused grid failed (a bug: the canvas is checked before).
    #[error(transparent)]
    Grid(#[from] grid_core::Error),
}
