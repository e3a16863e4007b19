//! The pictures of `cargo xtask eval --pictures DIR`: for a case that was not a success, B's
//! walls laid over A at the truth and at the pipeline's best candidate, with the world's true
//! obstacles and both robots' paths, so that one look shows why a pair failed.
//!
//! Each panel is drawn in A's frame, every cell as a `SCALE` x `SCALE` block:
//! - A's free space light grey, A's unknown cells mid grey;
//! - [`PENETRATED`] (yellow): cells the world fills that A nevertheless marks free (a noisy
//!   range sensor's long readings clear cells inside the obstacles: the range bias);
//! - [`A_WALL`] (red): A's walls where no wall of B lands, [`B_WALL`] (blue): B's walls (as
//!   the panel's transform places them) where A has none, [`BOTH`] (purple): both;
//! - each robot's path as dots ([`A_PATH`], [`B_PATH`]), where it saw its walls from.

use grid_core::{CellState, DVec2, OccupancyGrid, Rigid2};
use image::{Rgb, RgbImage};

/// Pixels per map cell.
pub const SCALE: u32 = 2;
/// Grey between the panels.
const GAP: u32 = 8;

/// A's free cells.
pub const FREE: [u8; 3] = [235, 235, 235];
/// A's unknown cells.
pub const UNKNOWN: [u8; 3] = [150, 150, 150];
/// Obstacle cells of the world that A marks free.
pub const PENETRATED: [u8; 3] = [255, 215, 110];
/// A's walls without a wall of B on them.
pub const A_WALL: [u8; 3] = [215, 0, 0];
/// B's walls without a wall of A under them.
pub const B_WALL: [u8; 3] = [0, 0, 225];
/// Walls of both maps.
pub const BOTH: [u8; 3] = [150, 0, 190];
/// A's path.
pub const A_PATH: [u8; 3] = [120, 0, 0];
/// B's path.
pub const B_PATH: [u8; 3] = [0, 0, 110];

/// What is drawn in every panel: A, B, which of A's cells the world fills, and the robots'
/// paths (A's in A's frame, B's in B's frame).
pub struct Scene<'a> {
    /// The first map: the panels' frame.
    pub a: &'a OccupancyGrid,
    /// The second map.
    pub b: &'a OccupancyGrid,
    /// Per cell of `a` (row-major), whether the world fills it.
    pub obstacle: Vec<bool>,
    /// A's path, in A's pixels.
    pub a_path: Vec<DVec2>,
    /// B's path, in B's pixels.
    pub b_path: Vec<DVec2>,
}

impl Scene<'_> {
    /// One panel: B laid over A by `b_to_a` (maps B's pixels to A's).
    pub fn panel(&self, b_to_a: &Rigid2) -> RgbImage {
        let (w, h) = (self.a.width(), self.a.height());
        let mut cells: Vec<[u8; 3]> = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                match self.a.state(x, y) {
                    CellState::Occupied => A_WALL,
                    CellState::Free if self.obstacle[i] => PENETRATED,
                    CellState::Free => FREE,
                    CellState::Unknown => UNKNOWN,
                }
            })
            .collect();
        let cell = |p: DVec2| {
            let q = p.round();
            (q.x >= 0.0 && q.y >= 0.0 && (q.x as usize) < w && (q.y as usize) < h)
                .then(|| q.y as usize * w + q.x as usize)
        };
        for y in 0..self.b.height() {
            for x in 0..self.b.width() {
                if self.b.state(x, y) != CellState::Occupied {
                    continue;
                }
                if let Some(i) = cell(b_to_a.apply(DVec2::new(x as f64, y as f64))) {
                    cells[i] = if cells[i] == A_WALL || cells[i] == BOTH {
                        BOTH
                    } else {
                        B_WALL
                    };
                }
            }
        }
        let a_path = self.a_path.iter().map(|&p| (p, A_PATH));
        let b_path = self.b_path.iter().map(|&p| (b_to_a.apply(p), B_PATH));
        for (p, colour) in a_path.chain(b_path) {
            if let Some(i) = cell(p) {
                cells[i] = colour;
            }
        }
        RgbImage::from_fn(w as u32 * SCALE, h as u32 * SCALE, |x, y| {
            Rgb(cells[(y / SCALE) as usize * w + (x / SCALE) as usize])
        })
    }
}

/// The panels side by side, on a dark background.
pub fn side_by_side(panels: &[RgbImage]) -> RgbImage {
    let w = panels.iter().map(|p| p.width() + GAP).sum::<u32>() + GAP;
    let h = panels.iter().map(|p| p.height()).max().unwrap_or(0) + 2 * GAP;
    let mut out = RgbImage::from_pixel(w, h, Rgb([60, 60, 60]));
    let mut x0 = GAP;
    for p in panels {
        image::imageops::replace(&mut out, p, x0 as i64, GAP as i64);
        x0 += p.width() + GAP;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use grid_core::{Pose2, UNKNOWN as U};

    /// A 6 x 4 map: free, with a wall cell at `(x, 1)` and an unknown last row.
    fn map(wall_x: usize) -> OccupancyGrid {
        let mut cells = vec![0u8; 24];
        cells[6 + wall_x] = 100;
        for c in &mut cells[18..] {
            *c = U;
        }
        OccupancyGrid::from_cells(6, 4, 0.05, Pose2::default(), cells).unwrap()
    }

    fn at(img: &RgbImage, x: u32, y: u32) -> [u8; 3] {
        // Every pixel of the cell's block has its colour.
        let c = img.get_pixel(x * SCALE, y * SCALE).0;
        assert_eq!(
            img.get_pixel(x * SCALE + SCALE - 1, y * SCALE + SCALE - 1)
                .0,
            c
        );
        c
    }

    #[test]
    fn walls_are_coloured_by_which_map_has_them() {
        let (a, b) = (map(2), map(1));
        let mut obstacle = vec![false; 24];
        obstacle[6 + 4] = true; // free in A, filled in the world
        obstacle[6 + 2] = true; // A's wall, filled in the world: stays a wall
        let scene = Scene {
            a: &a,
            b: &b,
            obstacle,
            a_path: vec![DVec2::new(0.0, 0.0)],
            b_path: vec![DVec2::new(4.0, 2.0)],
        };
        // B moved one cell right: its wall lands on A's.
        let img = scene.panel(&Rigid2::new(0.0, 1.0, 0.0));
        assert_eq!((img.width(), img.height()), (6 * SCALE, 4 * SCALE));
        assert_eq!(at(&img, 2, 1), BOTH);
        assert_eq!(at(&img, 4, 1), PENETRATED);
        assert_eq!(at(&img, 3, 1), FREE);
        assert_eq!(at(&img, 3, 3), UNKNOWN);
        assert_eq!(at(&img, 0, 0), A_PATH);
        assert_eq!(at(&img, 5, 2), B_PATH);
        // Not moved: the walls are side by side.
        let img = scene.panel(&Rigid2::default());
        assert_eq!(at(&img, 2, 1), A_WALL);
        assert_eq!(at(&img, 1, 1), B_WALL);
        assert_eq!(at(&img, 4, 2), B_PATH);
    }

    #[test]
    fn panels_sit_side_by_side_with_gaps() {
        let a = RgbImage::from_pixel(3, 5, Rgb([1, 1, 1]));
        let b = RgbImage::from_pixel(4, 2, Rgb([2, 2, 2]));
        let out = side_by_side(&[a, b]);
        assert_eq!((out.width(), out.height()), (3 + 4 + 3 * GAP, 5 + 2 * GAP));
        assert_eq!(out.get_pixel(GAP, GAP).0, [1, 1, 1]);
        assert_eq!(out.get_pixel(2 * GAP + 3, GAP + 1).0, [2, 2, 2]);
        assert_eq!(out.get_pixel(2 * GAP + 3, GAP + 2).0, [60, 60, 60]);
        assert_eq!(out.get_pixel(0, 0).0, [60, 60, 60]);
    }
}
