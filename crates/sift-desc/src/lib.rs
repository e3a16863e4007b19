//! SIFT for occupancy grids, second half: orientation assignment, 128-D descriptors, ratio-test
//! matching, and the [`CorrespondenceSource`] the registration pipeline calls.
//!
//! It is for: [`Sift`] (a [`FeatureExtractor`] producing [`SiftFeature`]s from an
//! [`OccupancyGrid`]), [`match_features`], and [`SiftCorrespondences`] /
//! [`correspondences_from_features`] producing [`Correspondence`]s with orientations. It is
//! not for: keypoint detection (crate `scale-space`), robust estimation (RANSAC) or verification.
//!
//! The algorithm follows the IPOL "Anatomy of the SIFT method" (Rey-Otero & Delbracio 2014);
//! angles use the pixel convention of the project (`y` down, positive from `+x` towards `+y`),
//! so for a correct match `angle_a - angle_b` is the rotation of the B → A transform.
//!
//! To merge N maps, extract once per map with [`Sift::extract_features`] and call
//! [`correspondences_from_features`] per pair.

mod describe;
mod matching;

pub use describe::{
    DESCRIPTOR_LEN, DescriptorConfig, N_HIST, N_ORI, ORIENTATION_BINS, SiftFeature,
    describe_keypoint,
};
pub use matching::{Match, MatchConfig, distance_sq, match_features};
pub use scale_space::{IntensityMapping, Keypoint, ScaleSpace, ScaleSpaceConfig};

use std::f64::consts::TAU;

use grid_core::{
    Correspondence, CorrespondenceSource, DVec2, EvidenceKind, FeatureExtractor, OccupancyGrid,
    Orientation,
};
use rayon::prelude::*;

/// Errors of this crate.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// The scale-space part of the configuration is invalid.
    #[error(transparent)]
    ScaleSpace(#[from] scale_space::Error),
    /// The descriptor or matching part of the configuration is invalid.
    #[error("invalid SIFT configuration: {0}")]
    Config(&'static str),
}

/// Everything that parameterises extraction and matching.
#[derive(Debug, Clone, PartialEq)]
pub struct SiftConfig {
    /// Scale space and detector (defaults: see [`ScaleSpaceConfig`]).
    pub scale_space: ScaleSpaceConfig,
    /// Grid → intensity mapping (default: free 1, occupied and unknown 0).
    pub mapping: IntensityMapping,
    /// Orientation and descriptor parameters (IPOL defaults).
    pub descriptor: DescriptorConfig,
    /// Keep at most this many keypoints per grid, the largest `|DoG|` responses first, before
    /// orientation assignment: default 2000, which bounds matching time (quadratic in the
    /// feature count) at a negligible loss on the measured maps.
    pub max_keypoints: usize,
    /// Ratio-test threshold (nearest / second-nearest): default 0.65.
    pub ratio: f32,
    /// Mutual nearest neighbours only: default true.
    pub cross_check: bool,
}

impl Default for SiftConfig {
    fn default() -> Self {
        let m = MatchConfig::default();
        Self {
            scale_space: ScaleSpaceConfig::default(),
            mapping: IntensityMapping::default(),
            descriptor: DescriptorConfig::default(),
            max_keypoints: 2000,
            ratio: m.ratio,
            cross_check: m.cross_check,
        }
    }
}

impl SiftConfig {
    /// The matching part of the configuration.
    pub fn match_config(&self) -> MatchConfig {
        MatchConfig {
            ratio: self.ratio,
            cross_check: self.cross_check,
        }
    }

    /// Check the ranges of all parameters.
    pub fn validate(&self) -> Result<(), Error> {
        self.scale_space.validate()?;
        let d = &self.descriptor;
        let positive = |v: f32| v.is_finite() && v > 0.0;
        if !(positive(d.lambda_ori) && positive(d.lambda_descr) && positive(d.clamp)) {
            return Err(Error::Config(
                "lambda_ori, lambda_descr and clamp must be positive",
            ));
        }
        if !(d.peak_ratio.is_finite() && (0.0..=1.0).contains(&d.peak_ratio)) {
            return Err(Error::Config("peak_ratio must be in [0, 1]"));
        }
        if !(self.ratio.is_finite() && self.ratio > 0.0 && self.ratio <= 1.0) {
            return Err(Error::Config("ratio must be in (0, 1]"));
        }
        Ok(())
    }
}

/// The SIFT feature extractor for occupancy grids.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Sift {
    config: SiftConfig,
}

impl Sift {
    /// An extractor with a validated configuration.
    pub fn new(config: SiftConfig) -> Result<Self, Error> {
        config.validate()?;
        Ok(Self { config })
    }

    /// The configuration.
    pub fn config(&self) -> &SiftConfig {
        &self.config
    }

    /// Append the features of `grid` to `out`, reusing the pyramid buffers of `space`.
    ///
    /// Output order is deterministic (detection order: octave, scale, row, column, then one
    /// feature per orientation in increasing angle), whatever the rayon thread count.
    pub fn extract_with(
        &self,
        grid: &OccupancyGrid,
        space: &mut ScaleSpace,
        out: &mut Vec<SiftFeature>,
    ) {
        let c = &self.config;
        let mut keypoints = Vec::new();
        // The configuration was validated in `new`, so detection cannot fail.
        let Ok(Some(offset)) =
            scale_space::detect_grid(grid, &c.mapping, &c.scale_space, space, &mut keypoints)
        else {
            return;
        };
        if keypoints.len() > c.max_keypoints {
            // Strongest first; ties (equal responses) broken by detection order.
            let mut order: Vec<usize> = (0..keypoints.len()).collect();
            order.sort_by(|&i, &j| {
                keypoints[j]
                    .response
                    .abs()
                    .total_cmp(&keypoints[i].response.abs())
                    .then(i.cmp(&j))
            });
            order.truncate(c.max_keypoints);
            order.sort_unstable();
            keypoints = order.into_iter().map(|i| keypoints[i]).collect();
        }
        let space = &*space;
        let features: Vec<Vec<SiftFeature>> = keypoints
            .par_iter()
            .map_init(Vec::new, |buf, kp| {
                buf.clear();
                describe_keypoint(space, offset, kp, &c.descriptor, buf);
                buf.clone()
            })
            .collect();
        out.extend(features.into_iter().flatten());
    }

    /// The features of `grid` in a new vector.
    pub fn extract_features(&self, grid: &OccupancyGrid) -> Vec<SiftFeature> {
        let mut out = Vec::new();
        self.extract_with(grid, &mut ScaleSpace::new(), &mut out);
        out
    }
}

impl FeatureExtractor for Sift {
    type Feature = SiftFeature;

    fn extract(&self, grid: &OccupancyGrid, out: &mut Vec<SiftFeature>) {
        self.extract_with(grid, &mut ScaleSpace::new(), out);
    }
}

/// Match features of map A against features of map B and append one [`Correspondence`] per
/// accepted match: positions in each map's pixel frame, orientations with period `2 pi`,
/// weight `1 - ratio`, kind [`EvidenceKind::Intensity`]. Sorted by A's feature index.
pub fn correspondences_from_features(
    a: &[SiftFeature],
    b: &[SiftFeature],
    config: &MatchConfig,
    out: &mut Vec<Correspondence>,
) {
    let mut matches = Vec::new();
    match_features(a, b, config, &mut matches);
    out.extend(matches.iter().map(|m| {
        let (fa, fb) = (&a[m.a], &b[m.b]);
        Correspondence {
            a: DVec2::new(fa.keypoint.x, fa.keypoint.y),
            b: DVec2::new(fb.keypoint.x, fb.keypoint.y),
            orientation: Some(Orientation {
                a: fa.angle,
                b: fb.angle,
                period: TAU,
            }),
            weight: (1.0 - m.ratio as f64).clamp(f64::MIN_POSITIVE, 1.0),
            kind: EvidenceKind::Intensity,
        }
    }));
}

/// SIFT as a [`CorrespondenceSource`]: extract from both grids, match with the ratio test.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SiftCorrespondences {
    sift: Sift,
}

impl SiftCorrespondences {
    /// A correspondence source with a validated configuration.
    pub fn new(config: SiftConfig) -> Result<Self, Error> {
        Ok(Self {
            sift: Sift::new(config)?,
        })
    }

    /// The underlying extractor (to extract once and match many).
    pub fn sift(&self) -> &Sift {
        &self.sift
    }
}

impl CorrespondenceSource for SiftCorrespondences {
    fn correspondences(&self, a: &OccupancyGrid, b: &OccupancyGrid, out: &mut Vec<Correspondence>) {
        let mut space = ScaleSpace::new();
        let (mut fa, mut fb) = (Vec::new(), Vec::new());
        self.sift.extract_with(a, &mut space, &mut fa);
        self.sift.extract_with(b, &mut space, &mut fb);
        correspondences_from_features(&fa, &fb, &self.sift.config.match_config(), out);
    }
}
