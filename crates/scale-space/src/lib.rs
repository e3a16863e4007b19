//! SIFT keypoint detection for occupancy grids: the grid → intensity mapping, a separable
//! Gaussian blur, the Gaussian/DoG scale space and the detection of DoG extrema with sub-pixel
//! refinement, following the IPOL "Anatomy of the SIFT method" (Rey-Otero & Delbracio 2014).
//!
//! It is for: turning an [`OccupancyGrid`] into scale-space [`Keypoint`]s in the grid's own
//! pixel frame (`x` column, `y` row from the top, integer values at pixel centres). It is not
//! for: orientations, descriptors or matching (crate `sift-desc`), nor registration.
//!
//! Entry points: [`detect_grid`] (grid in, keypoints out), or [`intensity_image`] +
//! [`ScaleSpace::build`] + [`ScaleSpace::detect`] to keep the pyramid for descriptors.
//!
//! # Defaults and why
//!
//! See "Measurements that chose the defaults" in the `sift-desc` crate docs for the tables
//! that chose the [`IntensityMapping`] default (unknown = occupied value), the first-octave sampling and
//! the crop; the scale-space constants are the IPOL ones unless stated on the field.

mod blur;
mod detect;
mod image;
mod pyramid;

pub use blur::{GaussianKernel, gaussian_blur, gaussian_blur_sampled};
pub use image::{
    CropRect, Image, IntensityMapping, intensity_image, intensity_image_in, known_bounding_box,
};
pub use pyramid::{Octave, ScaleSpace};

use grid_core::OccupancyGrid;

/// Errors of this crate.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// A configuration value is out of its valid range.
    #[error("invalid scale-space configuration: {0}")]
    Config(&'static str),
    /// The image is too small (under 2 x 2) or its data length does not match its size.
    #[error("image of {width} x {height} pixels is too small or inconsistent")]
    ImageSize {
        /// Width of the offending image.
        width: usize,
        /// Height of the offending image.
        height: usize,
    },
}

/// Parameters of the scale space and of the detector.
#[derive(Debug, Clone, PartialEq)]
pub struct ScaleSpaceConfig {
    /// Scales per octave (IPOL `n_spo`): default 3.
    pub n_spo: usize,
    /// Blur of the seed image in input pixels (IPOL `sigma_min`): default 1.6, twice IPOL's
    /// 0.8, since the first octave starts at half resolution (see `delta_min`).
    pub sigma_min: f32,
    /// Sampling distance of the first octave in input pixels (IPOL `delta_min`): 0.5 doubles
    /// the image like Lowe/IPOL, 1 samples every cell, 2 starts at half resolution (the input
    /// is blurred to `sigma_min` first, so then `sigma_min` must be at least `0.8 *
    /// delta_min`). Default 2.0 with `sigma_min` 1.6: the IPOL first octave (0.8 at 1)
    /// shifted up by one octave. A map's finest scale is its cell-level noise (speckle, ragged
    /// wall edges), and dropping it cost nothing end to end: on `cargo xtask eval --suites
    /// overlap,zero,paper,real,mismatch --cases 20 --seed 7` every row but one succeeded as
    /// often or more often (the real floors 5 -> 10 %, 15 -> 20 %, 45 -> 55 %; disaster 0.7
    /// overlap lost one case of twenty), and SIFT on a 2048 x 2048 pair took 187 ms instead
    /// of 302 ms (`cargo bench -p mapmerge --bench register`). The up-sampled octave
    /// (0.5) costs 4x the time and its keypoints are the least repeatable (see `sift-desc`).
    pub delta_min: f32,
    /// Blur assumed in the input (IPOL `sigma_in`): default 0.5.
    pub sigma_in: f32,
    /// DoG contrast threshold for images in `[0, 1]` (IPOL `C_DoG`): default `0.04 / 3`
    /// (Lowe/OpenCV's 0.04 over 3 scales).
    pub c_dog: f32,
    /// Edge threshold on the ratio of principal curvatures (IPOL `C_edge`): default 10. The
    /// curvatures come from the DoG's spatial Hessian, whose second differences along `x` and
    /// `y` are averaged over the 3 x 3 footprint of the cross difference (weights 1, 2, 1
    /// across), unlike IPOL's 3-point ones: with those, a wall's edge turned to a staircase by a
    /// rotation passed the test along its whole length (see `detect.rs` and docs/EVALUATION.md,
    /// "An edge test that does not depend on the edge's direction").
    pub c_edge: f32,
    /// Octaves are added while their short side has at least this many samples: default 12.
    pub min_octave_size: usize,
    /// At most this many octaves: default 8.
    pub max_octaves: usize,
    /// For [`detect_grid`]: crop to the bounding box of the known cells grown by this margin
    /// (cells), `None` to keep the whole grid. Default `Some(64)`: unknown surroundings only
    /// cost time, and a wide margin keeps the coarse-scale patches of keypoints near the map's
    /// edge inside the image (measured: more inliers than margins 4 and 16, see `sift-desc`).
    pub crop_margin: Option<usize>,
}

impl Default for ScaleSpaceConfig {
    fn default() -> Self {
        Self {
            n_spo: 3,
            sigma_min: 1.6,
            delta_min: 2.0,
            sigma_in: 0.5,
            c_dog: 0.04 / 3.0,
            c_edge: 10.0,
            min_octave_size: 12,
            max_octaves: 8,
            crop_margin: Some(64),
        }
    }
}

impl ScaleSpaceConfig {
    /// Check the ranges of the parameters.
    pub fn validate(&self) -> Result<(), Error> {
        if self.n_spo == 0 {
            return Err(Error::Config("n_spo must be at least 1"));
        }
        if !(self.sigma_min.is_finite() && self.sigma_min > 0.0) {
            return Err(Error::Config("sigma_min must be positive"));
        }
        if !(self.delta_min.is_finite() && self.delta_min > 0.0 && self.delta_min <= 2.0) {
            return Err(Error::Config("delta_min must be in (0, 2]"));
        }
        if self.delta_min > 1.0 && self.sigma_min < 0.8 * self.delta_min {
            return Err(Error::Config(
                "a first octave coarser than the input (delta_min > 1) needs sigma_min >= 0.8 delta_min, or it aliases",
            ));
        }
        if !(self.sigma_in.is_finite() && self.sigma_in >= 0.0) {
            return Err(Error::Config("sigma_in must be non-negative"));
        }
        if !(self.c_dog.is_finite() && self.c_dog >= 0.0) {
            return Err(Error::Config("c_dog must be non-negative"));
        }
        if !(self.c_edge.is_finite() && self.c_edge > 0.0) {
            return Err(Error::Config("c_edge must be positive"));
        }
        if self.min_octave_size < 3 || self.max_octaves == 0 {
            return Err(Error::Config(
                "min_octave_size must be at least 3 and max_octaves at least 1",
            ));
        }
        Ok(())
    }
}

/// A scale-space extremum, in the pixel frame of the original grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Keypoint {
    /// Column (pixel centres at integers).
    pub x: f64,
    /// Row from the top (pixel centres at integers).
    pub y: f64,
    /// Scale: the Gaussian blur, in grid pixels, at which the DoG is extremal.
    pub sigma: f64,
    /// Octave index (0 = finest).
    pub octave: usize,
    /// Discrete scale index inside the octave (`1..=n_spo`), i.e. which Gaussian image the
    /// descriptor should sample.
    pub scale_index: usize,
    /// Interpolated DoG value (negative for a bright blob on a dark background).
    pub response: f32,
}

/// Detect the keypoints of `grid`: intensity image (cropped per `config.crop_margin`), scale
/// space (built into `space`, reused), detection. Keypoints are appended to `out` in `grid`'s
/// pixel frame. Returns the offset of the image's pixel `(0, 0)` in the grid, needed to relate
/// `space` to grid coordinates; `Ok(None)` when the grid has no known cell (nothing appended).
pub fn detect_grid(
    grid: &OccupancyGrid,
    mapping: &IntensityMapping,
    config: &ScaleSpaceConfig,
    space: &mut ScaleSpace,
    out: &mut Vec<Keypoint>,
) -> Result<Option<(f64, f64)>, Error> {
    config.validate()?;
    let rect = match config.crop_margin {
        Some(margin) => match known_bounding_box(grid, margin) {
            Some(r) => r,
            None => return Ok(None),
        },
        None => CropRect {
            x0: 0,
            y0: 0,
            width: grid.width(),
            height: grid.height(),
        },
    };
    if rect.width < 2 || rect.height < 2 {
        return Ok(None);
    }
    let image = intensity_image_in(grid, mapping, rect);
    space.build(&image, config)?;
    let offset = (rect.x0 as f64, rect.y0 as f64);
    space.detect(offset, out);
    Ok(Some(offset))
}
