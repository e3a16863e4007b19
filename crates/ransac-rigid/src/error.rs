/// Everything that makes [`crate::estimate_rigid`] decline to answer.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RansacError {
    /// Fewer usable correspondences (finite positions, finite positive weight) than any
    /// hypothesis needs.
    #[error("{usable} usable correspondences, at least {needed} needed")]
    TooFewCorrespondences {
        /// Correspondences that passed the usability filter.
        usable: usize,
        /// The minimum needed.
        needed: usize,
    },
    /// Every drawn sample was degenerate (e.g. all points identical), so no hypothesis exists.
    #[error("no non-degenerate sample among {draws} draws")]
    NoHypothesis {
        /// Samples drawn before giving up.
        draws: usize,
    },
    /// A configuration value is out of its range.
    #[error("invalid configuration: {0}")]
    InvalidConfig(&'static str),
}
