use glam::DVec2;

use crate::OccupancyGrid;

/// Extracts features (keypoints, components, ...) from a grid into a caller-owned buffer.
///
/// `out` is appended to, not cleared, so a caller can reuse one allocation across maps.
pub trait FeatureExtractor {
    /// The feature type produced.
    type Feature;

    /// Append the features of `grid` to `out`.
    fn extract(&self, grid: &OccupancyGrid, out: &mut Vec<Self::Feature>);
}

impl<T: FeatureExtractor + ?Sized> FeatureExtractor for &T {
    type Feature = T::Feature;
    fn extract(&self, grid: &OccupancyGrid, out: &mut Vec<Self::Feature>) {
        (**self).extract(grid, out)
    }
}

impl<T: FeatureExtractor + ?Sized> FeatureExtractor for Box<T> {
    type Feature = T::Feature;
    fn extract(&self, grid: &OccupancyGrid, out: &mut Vec<Self::Feature>) {
        (**self).extract(grid, out)
    }
}

/// Which kind of evidence a correspondence comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EvidenceKind {
    /// Intensity keypoints (SIFT).
    Intensity,
    /// Area keypoints (connected components of obstacles).
    Area,
}

/// Orientation of a matched feature in each map, for features whose orientation fixes the
/// rotation on its own: `theta = a - b` modulo `period`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Orientation {
    /// Feature orientation in map A, radians (pixel convention).
    pub a: f64,
    /// Feature orientation in map B, radians (pixel convention).
    pub b: f64,
    /// Period of the orientation: `2 pi` for a directed angle, `pi` for an axis (second moments).
    pub period: f64,
}

/// A putative match between a point of map A and a point of map B, in pixel coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Correspondence {
    /// Position in map A.
    pub a: DVec2,
    /// Position in map B.
    pub b: DVec2,
    /// Orientation, when this correspondence alone fixes the rotation.
    pub orientation: Option<Orientation>,
    /// Match quality in `(0, 1]`, higher is better (e.g. `1 - ratio` of the ratio test).
    pub weight: f64,
    /// Where the correspondence comes from.
    pub kind: EvidenceKind,
}

/// Produces putative correspondences between two grids (feature extraction plus matching).
pub trait CorrespondenceSource {
    /// Append the correspondences from `b` to `a` to `out`.
    fn correspondences(&self, a: &OccupancyGrid, b: &OccupancyGrid, out: &mut Vec<Correspondence>);
}

impl<T: CorrespondenceSource + ?Sized> CorrespondenceSource for &T {
    fn correspondences(&self, a: &OccupancyGrid, b: &OccupancyGrid, out: &mut Vec<Correspondence>) {
        (**self).correspondences(a, b, out)
    }
}

impl<T: CorrespondenceSource + ?Sized> CorrespondenceSource for Box<T> {
    fn correspondences(&self, a: &OccupancyGrid, b: &OccupancyGrid, out: &mut Vec<Correspondence>) {
        (**self).correspondences(a, b, out)
    }
}
