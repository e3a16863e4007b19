//! The one error type of this crate.

use fusion::FusionError;
use ransac_rigid::RansacError;

use crate::settings::Rule;

/// What can go wrong in [`crate::register`], [`crate::register_with`] and
/// [`crate::team::merge_team`]. A pair without a trustworthy answer is not an error: it comes
/// back declined, with a reason.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A number of the settings is out of its range (NaN, a step of 0, a negative size ...).
    /// `name` is the setting's path from the config given, e.g. `pair.verify.min_wall_lift`.
    #[error("invalid setting `{name}` = {value}: must be {rule}")]
    Setting {
        /// Path of the setting, its fields joined by dots.
        name: String,
        /// The value given.
        value: f64,
        /// What it must be.
        rule: Rule,
    },
    /// The SIFT settings are invalid.
    #[error("invalid SIFT settings: {0}")]
    Sift(#[from] sift_desc::Error),
    /// The RANSAC settings (`pair.ransac`) are invalid.
    #[error("invalid RANSAC settings (pair.ransac): {0}")]
    Ransac(RansacError),
    /// Fusing a team's maps or solving their poses failed.
    #[error(transparent)]
    Fusion(#[from] FusionError),
    /// A team's inputs do not fit together: `weights` does not give one weight per map, or
    /// the reference is not a map.
    #[error("{0}")]
    Input(String),
}
