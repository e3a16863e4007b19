//! Nearest-occupied-cell transform: for every cell, which occupied cell is closest.
//!
//! Used to score hypotheses (how many walls of B land on walls of A) and to refine them (ICP
//! against A's walls). Grevera's "dead reckoning" two-pass propagation of nearest sites: linear
//! time, near-exact Euclidean distances, no per-query search.

use grid_core::{CellState, OccupancyGrid};

const NONE: u32 = u32::MAX;

/// For each cell of a grid, the nearest occupied cell and the distance to it.
#[derive(Debug, Clone)]
pub struct NearestOccupied {
    width: usize,
    height: usize,
    nearest: Vec<u32>,
    distance: Vec<f32>,
}

impl NearestOccupied {
    /// Build the transform of `grid`'s occupied cells.
    pub fn new(grid: &OccupancyGrid) -> Self {
        let (w, h) = (grid.width(), grid.height());
        let mut nearest = vec![NONE; w * h];
        let mut distance = vec![f32::INFINITY; w * h];
        for (i, &c) in grid.cells().iter().enumerate() {
            if OccupancyGrid::classify(c) == CellState::Occupied {
                nearest[i] = i as u32;
                distance[i] = 0.0;
            }
        }
        let mut out = Self {
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

    /// Nearest occupied cell `(x, y)` to cell `(x, y)` and its distance; `None` outside the grid
    /// or when the grid has no occupied cell.
    #[inline]
    pub fn nearest(&self, x: usize, y: usize) -> Option<((usize, usize), f32)> {
        if x >= self.width || y >= self.height {
            return None;
        }
        let i = y * self.width + x;
        let site = self.nearest[i];
        (site != NONE).then(|| {
            (
                (site as usize % self.width, site as usize / self.width),
                self.distance[i],
            )
        })
    }

    /// Distance from cell `(x, y)` to the nearest occupied cell (infinite when none).
    #[inline]
    pub fn distance(&self, x: usize, y: usize) -> f32 {
        if x >= self.width || y >= self.height {
            f32::INFINITY
        } else {
            self.distance[y * self.width + x]
        }
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
}
