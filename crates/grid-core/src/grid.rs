use glam::DVec2;

use crate::{Error, Result, Rigid2};

/// Cell value meaning "unknown" in [`OccupancyGrid::cells`].
///
/// Known cells hold their occupancy probability in percent, `0..=100`: the quantisation of
/// `nav_msgs/OccupancyGrid`, so that the ROS int8 encoding converts losslessly both ways.
pub const UNKNOWN: u8 = 255;

/// A 2-D pose `(x, y, yaw)` in metres and radians (counter-clockwise), as in a map_server
/// `origin:` entry.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct Pose2 {
    /// x in metres.
    pub x: f64,
    /// y in metres.
    pub y: f64,
    /// Yaw in radians, counter-clockwise.
    pub yaw: f64,
}

impl Pose2 {
    /// A pose from its three components.
    pub const fn new(x: f64, y: f64, yaw: f64) -> Self {
        Self { x, y, yaw }
    }
}

/// What a cell means once classified: free, occupied or unknown.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CellState {
    /// Probability at most [`OccupancyGrid::FREE_MAX_PERCENT`].
    Free,
    /// Probability at least [`OccupancyGrid::OCCUPIED_MIN_PERCENT`].
    Occupied,
    /// Unknown, or a probability between the two thresholds.
    Unknown,
}

/// Counts of free, occupied and unknown cells (as classified by [`OccupancyGrid::state`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct CellCounts {
    /// Free cells.
    pub free: usize,
    /// Occupied cells.
    pub occupied: usize,
    /// Unknown cells, including probabilities between the thresholds.
    pub unknown: usize,
}

/// Size, resolution and origin of a grid: everything needed to convert between pixel and world
/// coordinates, without the cells.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridGeometry {
    /// Width in cells (image columns).
    pub width: usize,
    /// Height in cells (image rows).
    pub height: usize,
    /// Edge length of a cell in metres.
    pub resolution: f64,
    /// Pose of the lower-left corner of the lower-left cell (the last image row), ROS convention.
    pub origin: Pose2,
}

impl GridGeometry {
    /// World coordinates (metres, map frame) of pixel coordinates `p` (`x` column, `y` row from
    /// the top, integer values at pixel centres).
    pub fn pixel_to_world(&self, p: DVec2) -> DVec2 {
        let r = self.resolution;
        let local = DVec2::new((p.x + 0.5) * r, (self.height as f64 - 0.5 - p.y) * r);
        DVec2::new(self.origin.x, self.origin.y) + DVec2::from_angle(self.origin.yaw).rotate(local)
    }

    /// Pixel coordinates of world point `w`; the inverse of [`Self::pixel_to_world`].
    pub fn world_to_pixel(&self, w: DVec2) -> DVec2 {
        let r = self.resolution;
        let local = DVec2::from_angle(-self.origin.yaw)
            .rotate(w - DVec2::new(self.origin.x, self.origin.y));
        DVec2::new(local.x / r - 0.5, self.height as f64 - 0.5 - local.y / r)
    }

    /// The geometry of the `width x height` region whose cell `(0, 0)` is cell `(x0, y0)` of
    /// this grid (`x0`, `y0` may be negative, the region may reach past the grid): the same
    /// resolution and yaw, the origin moved so that cell `p` of the region lies in the world
    /// where cell `p + (x0, y0)` of this grid lies.
    pub fn region(&self, x0: i64, y0: i64, width: usize, height: usize) -> GridGeometry {
        let r = self.resolution;
        let o = self.origin;
        // The lower-left corner of the region's lower-left cell, in this grid's frame.
        let corner = DVec2::new(
            x0 as f64 * r,
            (self.height as f64 - y0 as f64 - height as f64) * r,
        );
        let moved = DVec2::new(o.x, o.y) + DVec2::from_angle(o.yaw).rotate(corner);
        GridGeometry {
            width,
            height,
            resolution: r,
            origin: Pose2 {
                x: moved.x,
                y: moved.y,
                yaw: o.yaw,
            },
        }
    }
}

/// A 2-D occupancy grid map.
///
/// Cells are stored row-major, row 0 being the top row of the image file. Each cell is
/// [`UNKNOWN`] or an occupancy probability in percent (`0..=100`).
#[derive(Debug, Clone, PartialEq)]
pub struct OccupancyGrid {
    geometry: GridGeometry,
    cells: Vec<u8>,
}

impl OccupancyGrid {
    /// Probability (percent) at or below which a cell counts as free: map_saver's default.
    pub const FREE_MAX_PERCENT: u8 = 25;
    /// Probability (percent) at or above which a cell counts as occupied: map_saver's default.
    pub const OCCUPIED_MIN_PERCENT: u8 = 65;

    /// An all-unknown grid.
    pub fn new(width: usize, height: usize, resolution: f64, origin: Pose2) -> Result<Self> {
        Self::from_cells(
            width,
            height,
            resolution,
            origin,
            vec![UNKNOWN; width * height],
        )
    }

    /// A grid from row-major cells (`0..=100` percent or [`UNKNOWN`]; other values are taken as
    /// unknown).
    pub fn from_cells(
        width: usize,
        height: usize,
        resolution: f64,
        origin: Pose2,
        mut cells: Vec<u8>,
    ) -> Result<Self> {
        if width == 0 || height == 0 {
            return Err(Error::ZeroSize { width, height });
        }
        if !(resolution.is_finite() && resolution > 0.0) {
            return Err(Error::Resolution(resolution));
        }
        if cells.len() != width * height {
            return Err(Error::CellCount {
                got: cells.len(),
                expected: width * height,
            });
        }
        for c in &mut cells {
            if *c > 100 {
                *c = UNKNOWN;
            }
        }
        Ok(Self {
            geometry: GridGeometry {
                width,
                height,
                resolution,
                origin,
            },
            cells,
        })
    }

    /// A grid from the `nav_msgs/OccupancyGrid` int8 encoding (`-1` unknown, `0..=100` percent).
    ///
    /// Note that `nav_msgs/OccupancyGrid` stores rows bottom-up (row 0 is at the origin) while
    /// this grid stores them top-down like the image file; this conversion flips the rows.
    pub fn from_ros_data(
        width: usize,
        height: usize,
        resolution: f64,
        origin: Pose2,
        data: &[i8],
    ) -> Result<Self> {
        if data.len() != width * height {
            return Err(Error::CellCount {
                got: data.len(),
                expected: width * height,
            });
        }
        let mut cells = vec![UNKNOWN; data.len()];
        for (index, &value) in data.iter().enumerate() {
            let cell = match value {
                -1 => UNKNOWN,
                0..=100 => value as u8,
                _ => return Err(Error::OccupancyValue { value, index }),
            };
            let (x, y_ros) = (index % width, index / width);
            cells[(height - 1 - y_ros) * width + x] = cell;
        }
        Self::from_cells(width, height, resolution, origin, cells)
    }

    /// The `nav_msgs/OccupancyGrid` int8 encoding of this grid (rows bottom-up, as ROS has them).
    pub fn to_ros_data(&self) -> Vec<i8> {
        let (w, h) = (self.width(), self.height());
        let mut data = Vec::with_capacity(w * h);
        for y_ros in 0..h {
            let row = &self.cells[(h - 1 - y_ros) * w..(h - y_ros) * w];
            data.extend(row.iter().map(|&c| if c == UNKNOWN { -1 } else { c as i8 }));
        }
        data
    }

    /// Width in cells.
    pub fn width(&self) -> usize {
        self.geometry.width
    }

    /// Height in cells.
    pub fn height(&self) -> usize {
        self.geometry.height
    }

    /// Cell edge length in metres.
    pub fn resolution(&self) -> f64 {
        self.geometry.resolution
    }

    /// Pose of the lower-left corner of the lower-left cell.
    pub fn origin(&self) -> Pose2 {
        self.geometry.origin
    }

    /// Size, resolution and origin.
    pub fn geometry(&self) -> GridGeometry {
        self.geometry
    }

    /// Replace the origin pose.
    pub fn set_origin(&mut self, origin: Pose2) {
        self.geometry.origin = origin;
    }

    /// Row-major cells, [`UNKNOWN`] or percent.
    pub fn cells(&self) -> &[u8] {
        &self.cells
    }

    /// Mutable row-major cells. Writing a value above 100 other than [`UNKNOWN`] is a logic
    /// error; readers treat it as unknown.
    pub fn cells_mut(&mut self) -> &mut [u8] {
        &mut self.cells
    }

    /// The bounding box `(x0, y0, width, height)` of the known (free or occupied, per
    /// [`Self::classify`]) cells, grown by `margin` cells on each side and clipped to the grid;
    /// `None` when no cell is known. Everything outside it is unknown, so work that only
    /// concerns known cells can skip the rest of a big canvas.
    pub fn known_bounds(&self, margin: usize) -> Option<(usize, usize, usize, usize)> {
        let (w, h) = (self.width(), self.height());
        let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0usize, 0usize);
        for (y, row) in self.cells.chunks_exact(w.max(1)).enumerate() {
            if let Some(first) = first_known(row) {
                let last = last_known(row).unwrap_or(first);
                x0 = x0.min(first);
                x1 = x1.max(last);
                y0 = y0.min(y);
                y1 = y1.max(y);
            }
        }
        if x0 == usize::MAX {
            return None;
        }
        let (x0, y0) = (x0.saturating_sub(margin), y0.saturating_sub(margin));
        let (x1, y1) = (
            x1.saturating_add(margin).min(w - 1),
            y1.saturating_add(margin).min(h - 1),
        );
        Some((x0, y0, x1 - x0 + 1, y1 - y0 + 1))
    }

    /// Raw cell value at column `x`, row `y`, or `None` outside the grid.
    #[inline]
    pub fn get(&self, x: usize, y: usize) -> Option<u8> {
        (x < self.width() && y < self.height()).then(|| self.cells[y * self.width() + x])
    }

    /// Occupancy probability in `[0, 1]` at `(x, y)`, `None` when unknown or outside.
    #[inline]
    pub fn probability(&self, x: usize, y: usize) -> Option<f32> {
        match self.get(x, y)? {
            c if c <= 100 => Some(c as f32 / 100.0),
            _ => None,
        }
    }

    /// Set the cell at `(x, y)` to a probability (clamped to `[0, 1]`, rounded to percent) or to
    /// unknown. Panics outside the grid, like slice indexing.
    pub fn set_probability(&mut self, x: usize, y: usize, p: Option<f32>) {
        let w = self.width();
        assert!(
            x < w && y < self.height(),
            "cell ({x}, {y}) outside the grid"
        );
        self.cells[y * w + x] = match p {
            Some(p) if p.is_finite() => (p.clamp(0.0, 1.0) * 100.0).round() as u8,
            _ => UNKNOWN,
        };
    }

    /// Classify a raw cell value.
    #[inline]
    pub fn classify(cell: u8) -> CellState {
        match cell {
            c if c <= Self::FREE_MAX_PERCENT => CellState::Free,
            c if (Self::OCCUPIED_MIN_PERCENT..=100).contains(&c) => CellState::Occupied,
            _ => CellState::Unknown,
        }
    }

    /// Whether a raw cell value is known (free or occupied per [`Self::classify`]), without
    /// branches, so that a scan over many cells vectorises.
    #[inline]
    fn is_known(cell: u8) -> bool {
        (cell <= Self::FREE_MAX_PERCENT)
            | (cell.wrapping_sub(Self::OCCUPIED_MIN_PERCENT) <= 100 - Self::OCCUPIED_MIN_PERCENT)
    }

    /// Classified state at `(x, y)`; outside the grid is unknown.
    #[inline]
    pub fn state(&self, x: usize, y: usize) -> CellState {
        self.get(x, y).map_or(CellState::Unknown, Self::classify)
    }

    /// The mean pixel of the known (free or occupied) cells, `None` when no cell is known.
    pub fn known_centroid(&self) -> Option<DVec2> {
        let (mut sum, mut n) = (DVec2::ZERO, 0usize);
        for y in 0..self.height() {
            for x in 0..self.width() {
                if self.state(x, y) != CellState::Unknown {
                    sum += DVec2::new(x as f64, y as f64);
                    n += 1;
                }
            }
        }
        (n > 0).then(|| sum / n as f64)
    }

    /// Number of free, occupied and unknown cells.
    pub fn counts(&self) -> CellCounts {
        let mut counts = CellCounts::default();
        for &c in &self.cells {
            match Self::classify(c) {
                CellState::Free => counts.free += 1,
                CellState::Occupied => counts.occupied += 1,
                CellState::Unknown => counts.unknown += 1,
            }
        }
        counts
    }

    /// Resample this grid onto a `width x height` canvas with `self_to_out` (nearest neighbour):
    /// output cell `p` takes the cell of `self` at `self_to_out.inverse()(p)`, unknown outside.
    /// Resolution and origin are kept; the caller sets the origin it needs.
    pub fn warp(&self, self_to_out: &Rigid2, width: usize, height: usize) -> Result<Self> {
        let inv = self_to_out.inverse();
        let (s, c) = inv.theta.sin_cos();
        let mut cells = vec![UNKNOWN; width * height];
        for (y, row) in cells.chunks_mut(width.max(1)).enumerate() {
            for (x, cell) in row.iter_mut().enumerate() {
                let (xf, yf) = (x as f64, y as f64);
                let sx = (c * xf - s * yf + inv.tx).round();
                let sy = (s * xf + c * yf + inv.ty).round();
                if sx >= 0.0
                    && sy >= 0.0
                    && let Some(v) = self.get(sx as usize, sy as usize)
                {
                    *cell = v;
                }
            }
        }
        Self::from_cells(width, height, self.resolution(), self.origin(), cells)
    }

    /// The `width x height` region of this grid whose cell `(0, 0)` is cell `(x0, y0)` of this
    /// grid; `x0` and `y0` may be negative and the region may reach past the grid, where its
    /// cells are unknown. Cell `p` of the region is cell `p + (x0, y0)` of this grid, and the
    /// origin is moved so that both give it the same world coordinates.
    pub fn region(&self, x0: i64, y0: i64, width: usize, height: usize) -> Result<Self> {
        if width == 0 || height == 0 {
            return Err(Error::ZeroSize { width, height });
        }
        let mut cells = vec![UNKNOWN; width * height];
        // The columns of the region that lie inside the grid, and the first of them in it.
        let first = (-x0).clamp(0, width as i64) as usize;
        let last = (self.width() as i64 - x0).clamp(0, width as i64) as usize;
        let s0 = (x0 + first as i64) as usize;
        for (y, row) in cells.chunks_exact_mut(width).enumerate() {
            let Ok(sy) = usize::try_from(y0 + y as i64) else {
                continue;
            };
            if sy >= self.height() {
                break;
            }
            if first < last {
                let src = &self.cells[sy * self.width() + s0..][..last - first];
                row[first..last].copy_from_slice(src);
            }
        }
        let g = self.geometry.region(x0, y0, width, height);
        Self::from_cells(width, height, g.resolution, g.origin, cells)
    }

    /// This map at another `resolution` (metres per cell), covering the same ground: the
    /// origin (the lower-left corner of the lower-left cell, and the yaw) is kept, and the
    /// grid is as many cells wide and high as it takes to cover the old extent (rounded up,
    /// the extra cells unknown, at the right and the top).
    ///
    /// A new cell takes the highest occupancy among the old cells whose centres lie in it,
    /// unknown when all of those are (coarser: a wall any old cell held stays a wall, and a
    /// cell partly seen is known); when no old centre lies in it (finer), the old cell under
    /// its centre. So halving and doubling the resolution round-trips exactly, and at the
    /// same resolution the map is unchanged.
    ///
    /// `resolution` must be finite and positive ([`Error::Resolution`]), and the result at
    /// most 2^28 cells ([`Error::ResampleTooLarge`]).
    pub fn resample(&self, resolution: f64) -> Result<Self> {
        if !(resolution.is_finite() && resolution > 0.0) {
            return Err(Error::Resolution(resolution));
        }
        let ratio = resolution / self.resolution();
        // Rounding up, but a size that is whole up to rounding error stays whole.
        let cells_for = |n: usize| ((n as f64 / ratio) - 1e-9).ceil().max(1.0);
        let (wf, hf) = (cells_for(self.width()), cells_for(self.height()));
        if wf * hf > (1u64 << 28) as f64 {
            return Err(Error::ResampleTooLarge {
                width: wf,
                height: hf,
                resolution,
            });
        }
        let (w, h) = (wf as usize, hf as usize);
        // The old cells (counted from the lower-left, along one axis) whose centres lie in new
        // cell `k`: centres `(i + 0.5) r_old` in `[k r_new, (k + 1) r_new)`; else the old cell
        // under the new cell's centre. Clamped to the `n` old cells.
        let span = |k: usize, n: usize| {
            let lo = ((k as f64 * ratio - 0.5 - 1e-9).ceil().max(0.0) as usize).min(n);
            let hi = (((k + 1) as f64 * ratio - 0.5 - 1e-9).ceil().max(0.0) as usize).min(n);
            if lo < hi {
                lo..hi
            } else {
                let c = (((k as f64 + 0.5) * ratio) as usize).min(n.saturating_sub(1));
                // Past the old grid (the rounded-up margin): nothing.
                if ((k as f64 + 0.5) * ratio) < n as f64 {
                    c..c + 1
                } else {
                    0..0
                }
            }
        };
        let columns: Vec<_> = (0..w).map(|x| span(x, self.width())).collect();
        let mut cells = vec![UNKNOWN; w * h];
        for (y, row) in cells.chunks_exact_mut(w).enumerate() {
            // Rows are counted from the top in the grid, from the bottom here.
            let rows = span(h - 1 - y, self.height());
            for (cell, cols) in row.iter_mut().zip(&columns) {
                let mut best = UNKNOWN;
                for from_bottom in rows.clone() {
                    let old = &self.cells[(self.height() - 1 - from_bottom) * self.width()..];
                    for &v in &old[cols.clone()] {
                        // Known values are 0..=100, UNKNOWN is 255: the highest known one.
                        if v <= 100 && (best == UNKNOWN || v > best) {
                            best = v;
                        }
                    }
                }
                *cell = best;
            }
        }
        Self::from_cells(w, h, resolution, self.origin(), cells)
    }

    /// World coordinates of pixel coordinates `p`; see [`GridGeometry::pixel_to_world`].
    pub fn pixel_to_world(&self, p: DVec2) -> DVec2 {
        self.geometry.pixel_to_world(p)
    }

    /// Pixel coordinates of world point `w`; see [`GridGeometry::world_to_pixel`].
    pub fn world_to_pixel(&self, w: DVec2) -> DVec2 {
        self.geometry.world_to_pixel(w)
    }
}

/// Cells per block of the known-cell scans: each block is tested as a whole (a branch-free
/// fold, which vectorises) before the exact cell is looked for in it.
const SCAN_BLOCK: usize = 64;

/// Index of the first known cell of `row`.
fn first_known(row: &[u8]) -> Option<usize> {
    row.chunks(SCAN_BLOCK).enumerate().find_map(|(i, block)| {
        let any = block
            .iter()
            .fold(false, |a, &c| a | OccupancyGrid::is_known(c));
        any.then(|| {
            i * SCAN_BLOCK
                + block
                    .iter()
                    .position(|&c| OccupancyGrid::is_known(c))
                    .unwrap_or(0)
        })
    })
}

/// Index of the last known cell of `row`.
fn last_known(row: &[u8]) -> Option<usize> {
    row.rchunks(SCAN_BLOCK).enumerate().find_map(|(i, block)| {
        let any = block
            .iter()
            .fold(false, |a, &c| a | OccupancyGrid::is_known(c));
        // Blocks but the last one (at the row's start) are full, so this one starts here.
        let start = row.len() - i * SCAN_BLOCK - block.len();
        any.then(|| {
            start
                + block
                    .iter()
                    .rposition(|&c| OccupancyGrid::is_known(c))
                    .unwrap_or(0)
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn the_known_centroid_is_the_mean_of_the_known_cells() {
        // Known cells at (0, 0), (2, 0) and (2, 2); (1, 1) holds 50 %, which reads as unknown.
        let cells = vec![0, UNKNOWN, 100, UNKNOWN, 50, UNKNOWN, UNKNOWN, UNKNOWN, 0];
        let g = OccupancyGrid::from_cells(3, 3, 0.05, Pose2::default(), cells).unwrap();
        assert_eq!(g.known_centroid(), Some(DVec2::new(4.0 / 3.0, 2.0 / 3.0)));
        let blank = OccupancyGrid::new(2, 2, 0.05, Pose2::default()).unwrap();
        assert_eq!(blank.known_centroid(), None);
    }

    #[test]
    fn a_coarser_map_takes_the_highest_occupancy_of_each_block_and_keeps_its_origin() {
        // 5 x 3 cells at 0.05 m; at 0.1 m: 3 x 2 cells (rounded up), the blocks counted from
        // the lower-left corner, so the top row and the right column are half blocks.
        #[rustfmt::skip]
        let cells = vec![
            0,       UNKNOWN, 100,     UNKNOWN, 10,
            UNKNOWN, UNKNOWN, 0,       40,      UNKNOWN,
            UNKNOWN, 20,      70,      0,       UNKNOWN,
        ];
        let origin = Pose2::new(1.5, -2.0, 0.3);
        let g = OccupancyGrid::from_cells(5, 3, 0.05, origin, cells).unwrap();
        let c = g.resample(0.1).unwrap();
        assert_eq!((c.width(), c.height(), c.resolution()), (3, 2, 0.1));
        assert_eq!(c.origin(), origin);
        #[rustfmt::skip]
        let expected = vec![
            0,  100, 10,      // the top old row alone
            20, 70,  UNKNOWN, // old rows 1 and 2, two columns a cell; column 4 all unknown
        ];
        assert_eq!(c.cells(), expected.as_slice());
        // The lower-left corner of the grid is the same place in the world.
        let corner =
            |m: &OccupancyGrid| m.pixel_to_world(DVec2::new(-0.5, m.height() as f64 - 0.5));
        assert!((corner(&c) - corner(&g)).length() < 1e-12);
    }

    #[test]
    fn a_finer_map_repeats_each_cell_and_halving_it_again_gives_the_map_back() {
        let cells: Vec<u8> = vec![0, 100, UNKNOWN, 50, 25, 65];
        let g = OccupancyGrid::from_cells(3, 2, 0.1, Pose2::new(-4.0, 2.5, -1.0), cells).unwrap();
        let f = g.resample(0.05).unwrap();
        assert_eq!((f.width(), f.height()), (6, 4));
        for y in 0..4 {
            for x in 0..6 {
                assert_eq!(f.get(x, y), g.get(x / 2, y / 2), "cell ({x}, {y})");
            }
        }
        assert_eq!(f.resample(0.1).unwrap(), g);
        assert_eq!(g.resample(0.1).unwrap(), g);
        // A cell's centre keeps its world coordinates within half a new cell.
        let p = g.pixel_to_world(DVec2::new(2.0, 1.0));
        let q = f.world_to_pixel(p);
        assert!((q - DVec2::new(4.5, 2.5)).length() < 1e-9, "{q}");
    }

    #[test]
    fn resampling_refuses_a_resolution_that_is_not_positive_or_a_grid_too_large() {
        let g = OccupancyGrid::new(4, 4, 0.05, Pose2::default()).unwrap();
        for bad in [0.0, -0.1, f64::NAN, f64::INFINITY] {
            assert!(
                matches!(g.resample(bad), Err(Error::Resolution(_))),
                "{bad}"
            );
        }
        let big = OccupancyGrid::new(1000, 1000, 0.05, Pose2::default()).unwrap();
        assert!(matches!(
            big.resample(0.0001),
            Err(Error::ResampleTooLarge { .. })
        ));
    }

    #[test]
    fn a_region_copies_the_cells_it_covers_and_is_unknown_past_the_grid() {
        let (w, h) = (5, 4);
        let cells: Vec<u8> = (0..(w * h) as u8).collect();
        let origin = Pose2 {
            x: 1.5,
            y: -2.0,
            yaw: 0.3,
        };
        let g = OccupancyGrid::from_cells(w, h, 0.1, origin, cells).unwrap();
        // Reaching past every side: two columns and one row before the grid, two after.
        let r = g.region(-2, -1, w + 4, h + 3).unwrap();
        assert_eq!((r.width(), r.height()), (9, 7));
        for y in 0..7i64 {
            for x in 0..9i64 {
                let (sx, sy) = (x - 2, y - 1);
                let inside = (0..w as i64).contains(&sx) && (0..h as i64).contains(&sy);
                let want = if inside {
                    (sy as usize * w + sx as usize) as u8
                } else {
                    UNKNOWN
                };
                assert_eq!(r.get(x as usize, y as usize), Some(want), "cell ({x}, {y})");
            }
        }
        // Cell p of the region lies where cell p + (x0, y0) of the grid lies.
        for p in [
            DVec2::new(0.0, 0.0),
            DVec2::new(3.0, 5.0),
            DVec2::new(8.0, 6.0),
        ] {
            let (got, want) = (
                r.pixel_to_world(p),
                g.pixel_to_world(p + DVec2::new(-2.0, -1.0)),
            );
            assert!((got - want).length() < 1e-12, "{got} vs {want}");
        }
        // Inside the grid: exactly the cells; wholly outside: all unknown.
        let inner = g.region(1, 2, 3, 2).unwrap();
        assert_eq!(inner.cells(), &[11, 12, 13, 16, 17, 18]);
        let outside = g.region(10, -10, 2, 2).unwrap();
        assert_eq!(outside.cells(), &[UNKNOWN; 4]);
        assert!(matches!(
            g.region(0, 0, 0, 3),
            Err(Error::ZeroSize {
                width: 0,
                height: 3
            })
        ));
    }

    #[test]
    fn known_bounds_cover_free_and_occupied_cells_only() {
        let (w, h) = (20, 10);
        let mut cells = vec![UNKNOWN; w * h];
        cells[3 * w + 5] = 0; // free
        cells[6 * w + 12] = 100; // occupied
        cells[8 * w + 18] = 50; // between the thresholds: unknown to classify
        let g = OccupancyGrid::from_cells(w, h, 0.05, Pose2::default(), cells).unwrap();
        assert_eq!(g.known_bounds(0), Some((5, 3, 8, 4)));
        // Grown by 2, and clipped where the grid ends.
        assert_eq!(g.known_bounds(2), Some((3, 1, 12, 8)));
        assert_eq!(g.known_bounds(100), Some((0, 0, w, h)));
        let empty =
            OccupancyGrid::from_cells(w, h, 0.05, Pose2::default(), vec![UNKNOWN; w * h]).unwrap();
        assert_eq!(empty.known_bounds(3), None);
    }

    #[test]
    fn the_known_scans_agree_with_classify() {
        for c in 0..=255u8 {
            assert_eq!(
                OccupancyGrid::is_known(c),
                OccupancyGrid::classify(c) != CellState::Unknown,
                "value {c}"
            );
        }
        // Rows longer and shorter than a scan block, known cells at block edges.
        for len in [1usize, 5, 63, 64, 65, 130, 200] {
            for (a, b) in [(0, 0), (0, len - 1), (len / 2, len / 2), (len - 1, len - 1)] {
                let mut row = vec![UNKNOWN; len];
                row[a] = 0;
                row[b] = 100;
                assert_eq!(first_known(&row), Some(a), "len {len}, {a}..{b}");
                assert_eq!(last_known(&row), Some(b), "len {len}, {a}..{b}");
            }
            assert_eq!(first_known(&vec![50; len]), None);
            assert_eq!(last_known(&vec![UNKNOWN; len]), None);
        }
    }

    #[test]
    fn zero_size_is_refused() {
        assert!(matches!(
            OccupancyGrid::new(0, 3, 0.05, Pose2::default()),
            Err(Error::ZeroSize {
                width: 0,
                height: 3
            })
        ));
    }

    #[test]
    fn ros_data_flips_rows() {
        // 2 x 2: top row [0, 100], bottom row [unknown, 50].
        let g = OccupancyGrid::from_cells(2, 2, 0.1, Pose2::default(), vec![0, 100, UNKNOWN, 50])
            .unwrap();
        assert_eq!(g.to_ros_data(), vec![-1, 50, 0, 100]);
    }

    #[test]
    fn ros_data_rejects_out_of_range() {
        let err = OccupancyGrid::from_ros_data(2, 1, 0.1, Pose2::default(), &[0, 101]).unwrap_err();
        assert_eq!(
            err.to_string(),
            "occupancy value 101 at index 1 is outside -1..=100"
        );
    }

    #[test]
    fn pixel_centre_to_world_follows_conventions() {
        // W x H = 4 x 3, r = 0.5, origin (1, 2, 0): pixel (0, 2) is the lower-left cell.
        let geo = GridGeometry {
            width: 4,
            height: 3,
            resolution: 0.5,
            origin: Pose2::new(1.0, 2.0, 0.0),
        };
        assert_eq!(
            geo.pixel_to_world(DVec2::new(0.0, 2.0)),
            DVec2::new(1.25, 2.25)
        );
        assert_eq!(
            geo.pixel_to_world(DVec2::new(3.0, 0.0)),
            DVec2::new(2.75, 3.25)
        );
    }

    #[test]
    fn warp_by_quarter_turn() {
        // 3 x 2 map, cells 0..6 as distinct percents; turned by +90 deg into a 2 x 3 canvas.
        let g = OccupancyGrid::from_cells(3, 2, 0.05, Pose2::default(), vec![0, 1, 2, 3, 4, 5])
            .unwrap();
        let t = Rigid2::new(std::f64::consts::FRAC_PI_2, 1.0, 0.0);
        let w = g.warp(&t, 2, 3).unwrap();
        // B (x, y) -> A (1 - y, x): A row 0 = [B(0,1), B(0,0)], row 1 = [B(1,1), B(1,0)], ...
        assert_eq!(w.cells(), &[3, 0, 4, 1, 5, 2]);
    }

    proptest! {
        #[test]
        fn ros_int8_round_trip(w in 1usize..20, h in 1usize..20, seed in any::<u64>()) {
            let mut s = seed;
            let data: Vec<i8> = (0..w * h).map(|_| {
                s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                ((s >> 33) % 102) as i8 - 1
            }).collect();
            let g = OccupancyGrid::from_ros_data(w, h, 0.05, Pose2::new(1.0, -2.0, 0.3), &data).unwrap();
            prop_assert_eq!(g.to_ros_data(), data);
            let back = OccupancyGrid::from_ros_data(w, h, 0.05, g.origin(), &g.to_ros_data()).unwrap();
            prop_assert_eq!(back, g);
        }

        #[test]
        fn pixel_world_round_trip(x in -50.0f64..500.0, y in -50.0f64..500.0, ox in -20.0f64..20.0,
                                  oy in -20.0f64..20.0, yaw in -3.2f64..3.2, r in 0.01f64..1.0) {
            let geo = GridGeometry { width: 300, height: 200, resolution: r, origin: Pose2::new(ox, oy, yaw) };
            let p = DVec2::new(x, y);
            let back = geo.world_to_pixel(geo.pixel_to_world(p));
            prop_assert!((back - p).length() < 1e-8, "{p} -> {back}");
        }
    }
}
