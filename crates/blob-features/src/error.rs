/// Result alias of this crate.
pub type Result<T, E = BlobError> = std::result::Result<T, E>;

/// What can go wrong when labelling a mask or extracting blobs.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BlobError {
    /// The mask does not have `width * height` entries.
    #[error("mask has {got} entries, expected {width} x {height} = {}", width * height)]
    MaskSize {
        /// Entries given.
        got: usize,
        /// Width in pixels.
        width: usize,
        /// Height in pixels.
        height: usize,
    },
    /// The image has more pixels than a `u32` label can address.
    #[error("{width} x {height} pixels is too large to label with 32-bit labels")]
    TooLarge {
        /// Width in pixels.
        width: usize,
        /// Height in pixels.
        height: usize,
    },
    /// A setting is out of its range ([`crate::BlobConfig::validate`],
    /// [`crate::MatchConfig::validate`]).
    #[error("invalid blob setting `{name}` = {value}: must be {rule}")]
    Setting {
        /// The field, as in the struct (`round_ratio`, `unknown` for `UnknownPolicy::Drop`).
        name: &'static str,
        /// The value given.
        value: f64,
        /// What it must be.
        rule: &'static str,
    },
}
