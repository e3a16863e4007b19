//! From a grid to blobs: mask, closing, labelling, moments, descriptors.

use grid_core::{FeatureExtractor, OccupancyGrid};

use crate::label::{Connectivity, Labeler};
use crate::moments::{Accumulator, Shape, accumulate};
use crate::{BlobError, Result, close, not_free_mask, obstacle_mask};

/// Length of the descriptor array of a [`Blob`] (unused trailing entries are zero).
pub const DESCRIPTOR_LEN: usize = 8;

/// Which rotation-invariant quantities make up a blob's descriptor. All entries are logarithms
/// (or log-scaled Hu invariants) so that a difference of 0.1 is about a 10 % change.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DescriptorKind {
    /// `[ln area, ln sqrt(major), ln sqrt(minor)]`: size and the two axis lengths.
    #[default]
    Axes,
    /// [`DescriptorKind::Axes`] plus `ln(perimeter / sqrt(area))` (compactness).
    AxesPerimeter,
    /// `[ln area, hu1 .. hu7]`: Hu's invariants (log-scaled) and size.
    Hu,
    /// [`DescriptorKind::Axes`] plus log-scaled `hu3 .. hu4` (the skew of the shape).
    AxesHu,
}

impl DescriptorKind {
    /// Number of used entries.
    pub fn dim(self) -> usize {
        match self {
            Self::Axes => 3,
            Self::AxesPerimeter => 4,
            Self::Hu => 8,
            Self::AxesHu => 5,
        }
    }

    fn compute(self, s: &Shape) -> [f64; DESCRIPTOR_LEN] {
        let mut d = [0.0; DESCRIPTOR_LEN];
        let la = (s.area as f64).ln();
        // Eigenvalues are at least 1/12 thanks to the unit-square term, so the logs are finite.
        let major = 0.5 * s.eigenvalues[0].max(1.0 / 12.0).ln();
        let minor = 0.5 * s.eigenvalues[1].max(1.0 / 12.0).ln();
        match self {
            Self::Axes => d[..3].copy_from_slice(&[la, major, minor]),
            Self::AxesPerimeter => {
                let compact = (s.perimeter.max(1) as f64 / (s.area as f64).sqrt()).ln();
                d[..4].copy_from_slice(&[la, major, minor, compact]);
            }
            Self::Hu => {
                d[0] = la;
                d[1..8].copy_from_slice(&s.hu);
            }
            Self::AxesHu => {
                // Hu's log scale spans decades; a tenth brings it near the other entries.
                d[..5].copy_from_slice(&[la, major, minor, 0.1 * s.hu[2], 0.1 * s.hu[3]]);
            }
        }
        d
    }
}

/// Which cells form the components.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MaskKind {
    /// Occupied cells ([`crate::obstacle_mask`]): components are the drawn obstacles themselves.
    Occupied,
    /// Occupied or unknown cells ([`crate::not_free_mask`]), keeping only the islands enclosed by
    /// free space (components touching the map border are dropped: that is the unexplored
    /// outside). An island is an obstacle's footprint as seen from all around, unknown interior
    /// included.
    #[default]
    NotFreeIslands,
}

/// What to do with components that border unknown space (their shape may continue where the
/// robot did not look).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum UnknownPolicy {
    /// Treat them like any other component.
    Keep,
    /// Scale their reliability by `1 - unknown_contact` (floored at 0.05).
    #[default]
    Downweight,
    /// Drop components whose unknown contact exceeds the given fraction.
    Drop(f64),
}

/// Extraction settings. The defaults come from `examples/measure_blobs.rs` (synthetic pairs) and from
/// simulated robot pairs (`mapsim`); each field says what was measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlobConfig {
    /// Which cells form components. Default [`MaskKind::NotFreeIslands`]: on simulated partial
    /// maps (`mapsim`, see MEASUREMENTS.md) the true partner of a blob ranked 1.8th on average
    /// in descriptor distance against 6th-25th with [`MaskKind::Occupied`], whose components
    /// are fragments of visible surfaces.
    pub mask: MaskKind,
    /// Component connectivity. Default [`Connectivity::Eight`]: diagonal walls stay whole.
    pub connectivity: Connectivity,
    /// Radius (px) of the morphological closing applied to the obstacle mask before labelling,
    /// so that a wall drawn with gaps by a noisy sensor stays one component. Default 1: a
    /// 200 px wall losing 10 % of its cells falls into 2.5 components at radius 0, 1.04 at
    /// radius 1 and 1.04 at radius 2 (20 % lost: 4.0 / 1.58 / 1.50), and a larger radius merges
    /// neighbouring obstacles.
    pub close_radius: usize,
    /// Components with fewer pixels are dropped (noise specks). Default 30: on simulated pairs
    /// (`mapsim`, see MEASUREMENTS.md) it raised the share of true matches over 12 px without
    /// losing any.
    pub min_area: usize,
    /// Above this `minor / major` eigenvalue ratio a component counts as round and gets no
    /// orientation. Default 0.6: on rigidly warped synthetic maps, true partners with roundness
    /// below 0.6 agree on the rotation within 3 degrees in 85-94 % of cases, above 0.6 in
    /// 33-71 % (`cargo run --release -p blob-features --example measure_blobs`).
    pub round_ratio: f64,
    /// Handling of components that border unknown cells. Default [`UnknownPolicy::Downweight`].
    pub unknown: UnknownPolicy,
    /// Descriptor used for matching. Default [`DescriptorKind::Axes`].
    pub descriptor: DescriptorKind,
}

impl BlobConfig {
    /// Checks the numbers: `round_ratio` and the fraction of [`UnknownPolicy::Drop`] must not
    /// be NaN (a NaN ratio would leave every blob without an orientation, a NaN fraction
    /// would keep every blob, both without a word). Any other value is a bar: above 1 every
    /// component counts as elongated, below 0 as round. [`BlobCorrespondences::new`] calls it.
    ///
    /// [`BlobCorrespondences::new`]: crate::BlobCorrespondences::new
    pub fn validate(&self) -> Result<()> {
        let not_nan = |name, value: f64| {
            if value.is_nan() {
                Err(BlobError::Setting {
                    name,
                    value,
                    rule: "a number (not NaN)",
                })
            } else {
                Ok(())
            }
        };
        not_nan("round_ratio", self.round_ratio)?;
        if let UnknownPolicy::Drop(max) = self.unknown {
            not_nan("unknown", max)?;
        }
        Ok(())
    }
}

impl Default for BlobConfig {
    fn default() -> Self {
        Self {
            mask: MaskKind::NotFreeIslands,
            connectivity: Connectivity::Eight,
            close_radius: 1,
            min_area: 30,
            round_ratio: 0.6,
            unknown: UnknownPolicy::Downweight,
            descriptor: DescriptorKind::Axes,
        }
    }
}

/// An area keypoint: one connected component of obstacle cells.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Blob {
    /// Label of the component (`1..=n`) in the label image of the extraction's window (see
    /// [`BlobScratch::window`]).
    pub label: u32,
    /// Moments and shape statistics.
    pub shape: Shape,
    /// Major-axis angle in `(-pi/2, pi/2]` (period pi), `None` when the component is too round
    /// (see [`BlobConfig::round_ratio`]).
    pub orientation: Option<f64>,
    /// Trust in `(0, 1]` (lowered by unknown contact, see [`UnknownPolicy`]).
    pub reliability: f64,
    /// Rotation-invariant descriptor ([`BlobConfig::descriptor`]), zero-padded.
    pub descriptor: [f64; DESCRIPTOR_LEN],
}

/// Caller-owned buffers for [`Blobs::extract_with`], reused across maps.
#[derive(Debug, Clone, Default)]
pub struct BlobScratch {
    /// Top-left cell of the window the buffers cover.
    origin: (usize, usize),
    /// Width and height of the window.
    size: (usize, usize),
    mask: Vec<u8>,
    tmp: Vec<u8>,
    labels: Vec<u32>,
    labeler: Labeler,
    /// Per label (index 0 the background), whether the moments skip it.
    skip: Vec<bool>,
    acc: Vec<Accumulator>,
}

impl BlobScratch {
    /// The window of the grid the last extraction worked on, `(x0, y0, width, height)`: the
    /// known cells' bounding box with a margin; [`Self::labels`] and [`Self::mask`] cover it.
    pub fn window(&self) -> (usize, usize, usize, usize) {
        let (w, h) = self.size;
        (self.origin.0, self.origin.1, w, h)
    }

    /// The label image of the last extraction (`0` background) over [`Self::window`],
    /// row-major; a [`Blob::label`] indexes it.
    pub fn labels(&self) -> &[u32] {
        &self.labels
    }

    /// The (closed) obstacle mask of the last extraction over [`Self::window`], row-major.
    pub fn mask(&self) -> &[u8] {
        &self.mask
    }
}

/// Blob extractor: implements [`FeatureExtractor`] with `Feature = Blob`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Blobs {
    /// Settings.
    pub config: BlobConfig,
}

impl Blobs {
    /// An extractor with the given settings.
    pub fn new(config: BlobConfig) -> Self {
        Self { config }
    }

    /// Append the blobs of `grid` to `out`, using `scratch` for all intermediate buffers.
    pub fn extract_with(
        &self,
        grid: &OccupancyGrid,
        scratch: &mut BlobScratch,
        out: &mut Vec<Blob>,
    ) {
        let c = &self.config;
        // Only the bounding box of the known cells, grown by a margin of unknown cells, can
        // hold a component: outside it every cell is unknown, which is background in the
        // occupied mask and, in the not-free mask, part of the surround that touches the border
        // and is dropped. The margin keeps the closing inside the box as on the whole grid (it
        // reaches 2 * radius cells), and keeps the surround connected around the box, so the
        // blobs are exactly those of the whole grid, at a fraction of the cost on a big canvas.
        scratch.origin = (0, 0);
        scratch.size = (0, 0);
        scratch.mask.clear();
        scratch.labels.clear();
        let Some((x0, y0, w, h)) = grid.known_bounds(2 * c.close_radius + 2) else {
            return;
        };
        let cropped;
        let grid = if (w, h) == (grid.width(), grid.height()) {
            grid
        } else {
            // Row by row as slices (a copy per row, not per cell).
            let mut cells = Vec::with_capacity(w * h);
            for row in grid.cells().chunks_exact(grid.width()).skip(y0).take(h) {
                cells.extend_from_slice(&row[x0..x0 + w]);
            }
            let Ok(g) = OccupancyGrid::from_cells(w, h, grid.resolution(), grid.origin(), cells)
            else {
                return;
            };
            cropped = g;
            &cropped
        };
        scratch.origin = (x0, y0);
        scratch.size = (w, h);
        match c.mask {
            MaskKind::Occupied => obstacle_mask(grid, &mut scratch.mask),
            MaskKind::NotFreeIslands => not_free_mask(grid, &mut scratch.mask),
        }
        // The mask has w * h entries by construction, so neither call below can fail on size;
        // the only possible error is an image beyond 32-bit labels, which yields no blob.
        if close(&mut scratch.mask, w, h, c.close_radius, &mut scratch.tmp).is_err() {
            return;
        }
        scratch.labeler.set_connectivity(c.connectivity);
        let Ok(n) = scratch
            .labeler
            .label(&scratch.mask, w, h, &mut scratch.labels)
        else {
            return;
        };
        // Not-free components that touch the window's border are the unknown surround, which
        // is dropped below: often most of the window, so they are not accumulated at all.
        scratch.skip.clear();
        scratch.skip.resize(n + 1, false);
        scratch.skip[0] = true;
        if c.mask == MaskKind::NotFreeIslands {
            let labels = &scratch.labels;
            let border = labels[..w]
                .iter()
                .chain(&labels[(h - 1) * w..])
                .chain(labels.iter().step_by(w))
                .chain(labels[w - 1..].iter().step_by(w));
            for &l in border {
                scratch.skip[l as usize] = true;
            }
        }
        accumulate(
            &scratch.labels,
            &scratch.mask,
            n,
            &scratch.skip,
            grid,
            (x0, y0),
            &mut scratch.acc,
        );
        for (i, acc) in scratch.acc.iter().enumerate() {
            if acc.area() < c.min_area.max(1) {
                continue;
            }
            // In the grid's frame; a component touching the window's border touches the
            // unknown surround.
            let shape = acc.shape();
            let b = &shape.bbox;
            if c.mask == MaskKind::NotFreeIslands
                && (b.min_x == x0
                    || b.min_y == y0
                    || b.max_x + 1 == x0 + w
                    || b.max_y + 1 == y0 + h)
            {
                continue;
            }
            let reliability = match c.unknown {
                UnknownPolicy::Keep => 1.0,
                UnknownPolicy::Downweight => (1.0 - shape.unknown_contact).max(0.05),
                UnknownPolicy::Drop(max) => {
                    if shape.unknown_contact > max {
                        continue;
                    }
                    1.0
                }
            };
            out.push(Blob {
                label: i as u32 + 1,
                orientation: (shape.roundness() <= c.round_ratio).then_some(shape.axis_angle),
                reliability,
                descriptor: c.descriptor.compute(&shape),
                shape,
            });
        }
    }
}

impl FeatureExtractor for Blobs {
    type Feature = Blob;

    /// Allocates fresh scratch buffers; use [`Blobs::extract_with`] in loops.
    fn extract(&self, grid: &OccupancyGrid, out: &mut Vec<Blob>) {
        self.extract_with(grid, &mut BlobScratch::default(), out);
    }
}
