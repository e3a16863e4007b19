//! The grid → intensity mapping and the small f32 image type of the scale space.

use grid_core::{CellState, OccupancyGrid};

/// A single-channel f32 image, row-major, values normally in `[0, 1]`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Image {
    /// Width in pixels (columns).
    pub width: usize,
    /// Height in pixels (rows).
    pub height: usize,
    /// Row-major pixels, `width * height` of them.
    pub data: Vec<f32>,
}

impl Image {
    /// A `width x height` image filled with `value`.
    pub fn filled(width: usize, height: usize, value: f32) -> Self {
        Self {
            width,
            height,
            data: vec![value; width * height],
        }
    }

    /// Resize to `width x height` keeping the allocation when possible; contents are unspecified.
    pub fn reshape(&mut self, width: usize, height: usize) {
        self.width = width;
        self.height = height;
        self.data.resize(width * height, 0.0);
    }

    /// Pixel at column `x`, row `y` (panics outside, like slice indexing).
    #[inline]
    pub fn at(&self, x: usize, y: usize) -> f32 {
        self.data[y * self.width + x]
    }

    /// Row `y` as a slice.
    #[inline]
    pub fn row(&self, y: usize) -> &[f32] {
        &self.data[y * self.width..(y + 1) * self.width]
    }
}

/// How occupancy cells become intensities.
///
/// Cells are classified with [`OccupancyGrid::state`] (free ≤ 25 %, occupied ≥ 65 %, anything
/// else unknown) and each class gets one grey value.
///
/// Default: free = 1, occupied = 0, unknown = 0 ("free space is bright, everything else is
/// dark"). Unknown takes the occupied value because real sensor maps mark walls only in part:
/// the outline of the free space then carries the structure whether or not a wall was seen, and
/// the known/unknown border does not add a third grey level whose edges produce spurious
/// keypoints. The measurement that chose it is in the crate docs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntensityMapping {
    /// Grey value of a free cell.
    pub free: f32,
    /// Grey value of an occupied cell.
    pub occupied: f32,
    /// Grey value of an unknown cell.
    pub unknown: f32,
}

impl Default for IntensityMapping {
    fn default() -> Self {
        Self::UNKNOWN_AS_OCCUPIED
    }
}

impl IntensityMapping {
    /// Free 1, occupied 0, unknown 0 (the default).
    pub const UNKNOWN_AS_OCCUPIED: Self = Self {
        free: 1.0,
        occupied: 0.0,
        unknown: 0.0,
    };
    /// Free 1, occupied 0, unknown 1: only the walls carry structure.
    pub const UNKNOWN_AS_FREE: Self = Self {
        free: 1.0,
        occupied: 0.0,
        unknown: 1.0,
    };
    /// Free 1, occupied 0, unknown 0.5: the raw map_server look (grey unknown).
    pub const UNKNOWN_GREY: Self = Self {
        free: 1.0,
        occupied: 0.0,
        unknown: 0.5,
    };

    /// The grey value of a raw cell value.
    #[inline]
    pub fn value(&self, cell: u8) -> f32 {
        match OccupancyGrid::classify(cell) {
            CellState::Free => self.free,
            CellState::Occupied => self.occupied,
            CellState::Unknown => self.unknown,
        }
    }
}

/// A rectangle of grid cells: columns `x0..x0 + width`, rows `y0..y0 + height`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CropRect {
    /// First column.
    pub x0: usize,
    /// First row.
    pub y0: usize,
    /// Number of columns.
    pub width: usize,
    /// Number of rows.
    pub height: usize,
}

/// The bounding box of the known (free or occupied) cells grown by `margin` on each side and
/// clipped to the grid; `None` when no cell is known.
pub fn known_bounding_box(grid: &OccupancyGrid, margin: usize) -> Option<CropRect> {
    let (x0, y0, width, height) = grid.known_bounds(margin)?;
    Some(CropRect {
        x0,
        y0,
        width,
        height,
    })
}

/// The intensity image of the whole grid (same size, same pixel frame).
pub fn intensity_image(grid: &OccupancyGrid, mapping: &IntensityMapping) -> Image {
    let rect = CropRect {
        x0: 0,
        y0: 0,
        width: grid.width(),
        height: grid.height(),
    };
    intensity_image_in(grid, mapping, rect)
}

/// The intensity image of the cells in `rect` (which must lie inside the grid): pixel `(x, y)`
/// of the result is cell `(rect.x0 + x, rect.y0 + y)`.
pub fn intensity_image_in(
    grid: &OccupancyGrid,
    mapping: &IntensityMapping,
    rect: CropRect,
) -> Image {
    let mut lut = [mapping.unknown; 256];
    for (c, v) in lut.iter_mut().enumerate() {
        *v = mapping.value(c as u8);
    }
    let gw = grid.width();
    let mut data = Vec::with_capacity(rect.width * rect.height);
    for y in rect.y0..rect.y0 + rect.height {
        let row = &grid.cells()[y * gw + rect.x0..y * gw + rect.x0 + rect.width];
        data.extend(row.iter().map(|&c| lut[c as usize]));
    }
    Image {
        width: rect.width,
        height: rect.height,
        data,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use grid_core::{Pose2, UNKNOWN};

    #[test]
    fn mapping_and_crop() {
        // 5 x 4 grid: known cells only at (1,1)=free and (3,2)=occupied.
        let mut cells = vec![UNKNOWN; 20];
        cells[5 + 1] = 0;
        cells[2 * 5 + 3] = 100;
        let g = OccupancyGrid::from_cells(5, 4, 0.05, Pose2::default(), cells).unwrap();
        let img = intensity_image(&g, &IntensityMapping::UNKNOWN_GREY);
        assert_eq!(img.at(1, 1), 1.0);
        assert_eq!(img.at(3, 2), 0.0);
        assert_eq!(img.at(0, 0), 0.5);
        let r = known_bounding_box(&g, 0).unwrap();
        assert_eq!(
            r,
            CropRect {
                x0: 1,
                y0: 1,
                width: 3,
                height: 2
            }
        );
        let r = known_bounding_box(&g, 1).unwrap();
        assert_eq!((r.x0, r.y0, r.width, r.height), (0, 0, 5, 4));
        let c = intensity_image_in(
            &g,
            &IntensityMapping::default(),
            known_bounding_box(&g, 0).unwrap(),
        );
        assert_eq!(c.data, vec![1.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        let empty = OccupancyGrid::new(3, 3, 0.05, Pose2::default()).unwrap();
        assert_eq!(known_bounding_box(&empty, 2), None);
    }
}
