//! Nearest-occupied-cell transform: for every cell, which occupied cell is closest.
//!
//! Used to score hypotheses (how many walls of B land on walls of A) and to refine them (ICP
//! against A's walls). Grevera's "dead reckoning" two-pass propagation of nearest sites: linear
//! time, near-exact Euclidean distances, no per-query search.

use grid_core::{CellState, OccupancyGrid};

const NONE: u32 = u32::MAX;

/// For each cell of a grid, the nearest occupied cell and the distance to it.
///
/// Only the bounding box of the grid's known cells is computed: every occupied cell lies in
/// it, and the box is convex, so distances inside it are what the whole grid would give.
/// Outside it every cell is unknown, and queries there report no wall (a big canvas of
/// unknown around a map costs nothing).
#[derive(Debug, Clone)]
pub struct NearestOccupied {
    /// The computed window: first column and row, width and height.
    x0: usize,
    y0: usize,
    width: usize,
    height: usize,
    /// Nearest site per window cell, as a window index.
    nearest: Vec<u32>,
    distance: Vec<f32>,
}

impl NearestOccupied {
    /// Build the transform of `grid`'s occupied cells.
    pub fn new(grid: &OccupancyGrid) -> Self {
        // The loaders refuse maps without known cells; a grid built in code gets the whole grid.
        let (x0, y0, w, h) = grid
            .known_bounds(0)
            .unwrap_or((0, 0, grid.width(), grid.height()));
        let mut nearest = vec![NONE; w * h];
        let mut distance = vec![f32::INFINITY; w * h];
        let gw = grid.width();
        for y in 0..h {
            let row = &grid.cells()[(y0 + y) * gw + x0..][..w];
            for (x, &c) in row.iter().enumerate() {
                if OccupancyGrid::classify(c) == CellState::Occupied {
                    let i = y * w + x;
                    nearest[i] = i as u32;
                    distance[i] = 0.0;
                }
            }
        }
        let mut out = Self {
            x0,
            y0,
            width: w,
            height: h,
            nearest,
            distance,
        };
        const D: f32 = 1.0;
        const DD: f32 = std::f32::consts::SQRT_2;
        for y in 0..h {
            for x in 0..w {
                out.relax(x, y, x as isize - 1, y as isize - 1, DD);
                out.relax(x, y, x as isize, y as isize - 1, D);
                out.relax(x, y, x as isize + 1, y as isize - 1, DD);
                out.relax(x, y, x as isize - 1, y as isize, D);
            }
        }
        for y in (0..h).rev() {
            for x in (0..w).rev() {
                out.relax(x, y, x as isize + 1, y as isize, D);
                out.relax(x, y, x as isize - 1, y as isize + 1, DD);
                out.relax(x, y, x as isize, y as isize + 1, D);
                out.relax(x, y, x as isize + 1, y as isize + 1, DD);
            }
        }
        out
    }

    /// The computed window `(x0, y0, width, height)`: the bounding box of the known cells.
    pub fn window(&self) -> (usize, usize, usize, usize) {
        (self.x0, self.y0, self.width, self.height)
    }

    #[inline]
    fn relax(&mut self, x: usize, y: usize, nx: isize, ny: isize, step: f32) {
        if nx < 0 || ny < 0 || nx as usize >= self.width || ny as usize >= self.height {
            return;
        }
        let (i, n) = (y * self.width + x, ny as usize * self.width + nx as usize);
        if self.distance[n] + step < self.distance[i] {
            let site = self.nearest[n];
            let (sx, sy) = (site as usize % self.width, site as usize / self.width);
            let (dx, dy) = (sx as f32 - x as f32, sy as f32 - y as f32);
            self.nearest[i] = site;
            self.distance[i] = (dx * dx + dy * dy).sqrt();
        }
    }

    /// Window index of grid cell `(x, y)`, if it lies in the window (the layout of every
    /// per-cell array computed over [`Self::window`]).
    #[inline]
    pub(crate) fn index(&self, x: usize, y: usize) -> Option<usize> {
        let (x, y) = (x.wrapping_sub(self.x0), y.wrapping_sub(self.y0));
        (x < self.width && y < self.height).then(|| y * self.width + x)
    }

    /// Nearest occupied cell `(x, y)` to cell `(x, y)` and its distance; `None` outside the
    /// known window or when the grid has no occupied cell.
    #[inline]
    pub fn nearest(&self, x: usize, y: usize) -> Option<((usize, usize), f32)> {
        let i = self.index(x, y)?;
        let site = self.nearest[i];
        (site != NONE).then(|| {
            (
                (
                    self.x0 + site as usize % self.width,
                    self.y0 + site as usize / self.width,
                ),
                self.distance[i],
            )
        })
    }

    /// Distance from cell `(x, y)` to the nearest occupied cell (infinite when none, and
    /// outside the known window).
    #[inline]
    pub fn distance(&self, x: usize, y: usize) -> f32 {
        self.index(x, y).map_or(f32::INFINITY, |i| self.distance[i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use grid_core::{Pose2, UNKNOWN};

    #[test]
    fn matches_brute_force_on_scattered_sites() {
        let (w, h) = (37, 23);
        let mut cells = vec![0u8; w * h];
        let mut s = 12345u64;
        let mut sites = Vec::new();
        for (i, cell) in cells.iter_mut().enumerate() {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            if (s >> 40) % 29 == 0 {
                *cell = 100;
                sites.push((i % w, i / w));
            } else if (s >> 40) % 7 == 0 {
                *cell = UNKNOWN;
            }
        }
        let g = OccupancyGrid::from_cells(w, h, 0.05, Pose2::default(), cells).unwrap();
        let t = NearestOccupied::new(&g);
        let mut worst = 0.0f32;
        for y in 0..h {
            for x in 0..w {
                let exact = sites
                    .iter()
                    .map(|&(sx, sy)| {
                        ((sx as f32 - x as f32).powi(2) + (sy as f32 - y as f32).powi(2)).sqrt()
                    })
                    .fold(f32::INFINITY, f32::min);
                let (_, d) = t.nearest(x, y).unwrap();
                worst = worst.max(d - exact);
                assert!(d >= exact - 1e-4);
            }
        }
        // Dead reckoning is near-exact: errors stay well below one cell.
        assert!(worst < 0.5, "worst excess {worst}");
    }

    #[test]
    fn empty_grid_has_no_nearest() {
        let g = OccupancyGrid::from_cells(3, 2, 0.05, Pose2::default(), vec![0; 6]).unwrap();
        let t = NearestOccupied::new(&g);
        assert!(t.nearest(1, 1).is_none());
        assert_eq!(t.distance(1, 1), f32::INFINITY);
    }

    #[test]
    fn only_the_known_window_is_computed_and_it_is_exact() {
        // A 12 x 8 known patch with two walls on a 60 x 50 canvas of unknown.
        let (w, h) = (60, 50);
        let mut cells = vec![UNKNOWN; w * h];
        for y in 20..28 {
            for x in 30..42 {
                cells[y * w + x] = if (x == 30 && y < 25) || (y == 27 && x > 35) {
                    100
                } else {
                    0
                };
            }
        }
        let g = OccupancyGrid::from_cells(w, h, 0.05, Pose2::default(), cells.clone()).unwrap();
        let t = NearestOccupied::new(&g);
        assert_eq!(t.window(), (30, 20, 12, 8));
        for y in 20..28 {
            for x in 30..42 {
                let exact = (0..w * h)
                    .filter(|&i| cells[i] == 100)
                    .map(|i| {
                        let (sx, sy) = ((i % w) as f32, (i / w) as f32);
                        ((sx - x as f32).powi(2) + (sy - y as f32).powi(2)).sqrt()
                    })
                    .fold(f32::INFINITY, f32::min);
                let ((nx, ny), d) = t.nearest(x, y).unwrap();
                assert!((d - exact).abs() < 0.1, "({x}, {y}): {d} vs {exact}");
                assert_eq!(cells[ny * w + nx], 100, "the nearest site is a wall");
            }
        }
        // Outside the window: unknown, no wall reported.
        assert!(t.nearest(5, 5).is_none());
        assert_eq!(t.distance(29, 20), f32::INFINITY);
        assert_eq!(t.distance(42, 27), f32::INFINITY);
    }
}
