//! Nearest-occupied-cell transform: for every cell, which occupied cell is closest.
//!
//! Used to score hypotheses (how many walls of B land on walls of A) and to refine them (ICP
//! against A's walls). An exact Euclidean distance transform that also keeps the nearest site,
//! computed separably, as Meijster, Roerdink & Hesselink (2000) and Felzenszwalb & Huttenlocher
//! (2012) do for the distance alone:
//! 1. *columns*: every cell gets the nearest occupied cell of its own column, the upper one on
//!    a tie. The rows are cut into blocks of `BLOCK` rows; within each block a sweep down keeps,
//!    per column, the last occupied cell so far and a sweep up the first one, and the nearer
//!    is stored; the blocks run in parallel, reading and writing along memory. A short
//!    sequential pass then gives each block, per column, the nearest occupied cells above and
//!    below it, for step 2 to compare with the one stored.
//! 2. *rows*: on each row, every column `x'` with a site from step 1 contributes the parabola
//!    `(x - x')^2 + g^2`, `g` the vertical distance to that site. Their lower envelope (one
//!    scan with a stack, crossings kept as exact fractions, then one scan to read it) gives
//!    every cell of the row its nearest column, and so its nearest site. The rows run in
//!    parallel.
//!
//! Linear time, and integer arithmetic up to the squared distance; the distance is its square
//! root rounded to f32 (correctly rounded below 4096 cells, where the squared distance is an
//! exact f32). Among equally near sites the one with the smallest column, then the smallest
//! row, is kept. So the result is exact, and the same whatever the number of threads.

use grid_core::{CellState, OccupancyGrid};
use rayon::prelude::*;

const NONE: u32 = u32::MAX;

/// Rows per block of step 1: a block of a 2048-column window's row indices is 256 KiB.
const BLOCK: usize = 32;

/// For each cell of a grid, the nearest occupied cell and the distance to it.
///
/// Only the bounding box of the grid's known cells is computed (grown by a margin with
/// [`Self::with_margin`]): every occupied cell lies in it, and the box is convex, so distances
/// inside it are what the whole grid would give. Outside it every cell is unknown, and queries
/// there report no wall (a big canvas of unknown around a map costs nothing).
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
    ///
    /// # Panics
    /// When the known window has `u32::MAX` cells or more, or a side longer than 2^20 cells
    /// (the loaders refuse such maps: [`grid_core::io::MAX_SIDE`]).
    pub fn new(grid: &OccupancyGrid) -> Self {
        Self::with_margin(grid, 0)
    }

    /// [`Self::new`] over the known cells' bounding box grown by `margin` cells on each side
    /// (clipped to the grid), for lookups of unknown cells just outside it.
    ///
    /// # Panics
    /// As [`Self::new`].
    pub fn with_margin(grid: &OccupancyGrid, margin: usize) -> Self {
        // The loaders refuse maps without known cells; a grid built in code gets the whole grid.
        let (x0, y0, w, h) =
            grid.known_bounds(margin)
                .unwrap_or((0, 0, grid.width(), grid.height()));
        // Window indices are u32 (NONE reserved); with sides up to 2^20, the products that
        // compare two crossings of parabolas stay below 2^62.
        assert!(
            w * h < NONE as usize && w.max(h) <= 1 << 20,
            "known window {w} x {h} too large"
        );
        let gw = grid.width();
        let cells = &grid.cells()[y0 * gw + x0..];
        // Step 1: per cell, the row of the nearest occupied cell of its column within its
        // block (NONE when there is none), in `nearest`, which step 2 overwrites row by row;
        // per block and column, the first and last occupied rows of the block.
        let mut nearest = vec![NONE; w * h];
        let mut ends: Vec<(Vec<u32>, Vec<u32>)> = nearest
            .par_chunks_mut(BLOCK * w)
            .enumerate()
            .map(|(k, rows)| column_block(&cells[k * BLOCK * gw..], gw, k * BLOCK, w, rows))
            .collect();
        // Turned into, per block and column, the nearest occupied rows below the block (the
        // first one of a later block) and above it (the last one of an earlier block).
        let mut carry = vec![NONE; w];
        for (_, last) in &mut ends {
            for (c, l) in carry.iter_mut().zip(last) {
                if *l != NONE {
                    std::mem::swap(c, l);
                } else {
                    *l = *c;
                }
            }
        }
        carry.fill(NONE);
        for (first, _) in ends.iter_mut().rev() {
            for (c, f) in carry.iter_mut().zip(first) {
                if *f != NONE {
                    std::mem::swap(c, f);
                } else {
                    *f = *c;
                }
            }
        }
        // Step 2: per row, the lower envelope of the columns' parabolas; the result replaces
        // step 1's in `nearest`.
        let mut distance = vec![f32::INFINITY; w * h];
        nearest
            .par_chunks_mut(w)
            .zip(distance.par_chunks_mut(w))
            .enumerate()
            .with_min_len(8)
            .for_each_init(
                || Vec::with_capacity(w),
                |envelope, (y, (near, dist))| {
                    let (below, above) = &ends[y / BLOCK];
                    row(envelope, y, above, below, near, dist);
                },
            );
        Self {
            x0,
            y0,
            width: w,
            height: h,
            nearest,
            distance,
        }
    }

    /// The computed window `(x0, y0, width, height)`: the bounding box of the known cells.
    pub fn window(&self) -> (usize, usize, usize, usize) {
        (self.x0, self.y0, self.width, self.height)
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
        self.nearest_at(i).map(|(site, d)| (self.cell(site), d))
    }

    /// [`Self::nearest`] by window index ([`Self::index`]): the nearest occupied cell's window
    /// index and its distance; `None` when the grid has no occupied cell.
    #[inline]
    pub(crate) fn nearest_at(&self, i: usize) -> Option<(usize, f32)> {
        let site = self.nearest[i];
        (site != NONE).then(|| (site as usize, self.distance[i]))
    }

    /// Grid cell `(x, y)` of window index `i` (the inverse of [`Self::index`]).
    #[inline]
    pub(crate) fn cell(&self, i: usize) -> (usize, usize) {
        (self.x0 + i % self.width, self.y0 + i / self.width)
    }

    /// The distances of the window's cells, row by row (the layout of [`Self::window`]).
    pub(crate) fn distances(&self) -> &[f32] {
        &self.distance
    }

    /// Distance from cell `(x, y)` to the nearest occupied cell (infinite when none, and
    /// outside the known window).
    #[inline]
    pub fn distance(&self, x: usize, y: usize) -> f32 {
        self.index(x, y).map_or(f32::INFINITY, |i| self.distance[i])
    }
}

/// Step 1 on the block of window rows from `y0`: `cells` starts at the block's first cell,
/// rows `stride` apart; `rows` (row-major, `w` wide) gets, per cell, the row of the nearest
/// occupied cell of its column within the block (the upper one on a tie) or NONE. Returns, per
/// column, the first and the last occupied row of the block (or NONE).
fn column_block(
    cells: &[u8],
    stride: usize,
    y0: usize,
    w: usize,
    rows: &mut [u32],
) -> (Vec<u32>, Vec<u32>) {
    // Down: the last occupied row at or above.
    let mut above = vec![NONE; w];
    for (j, dst) in rows.chunks_exact_mut(w).enumerate() {
        let (src, y) = (&cells[j * stride..][..w], (y0 + j) as u32);
        for ((a, &c), d) in above.iter_mut().zip(src).zip(dst) {
            if OccupancyGrid::classify(c) == CellState::Occupied {
                *a = y;
            }
            *d = *a;
        }
    }
    // Up: the first occupied row at or below, taken where it is strictly nearer. (`NONE - y`
    // exceeds every real distance, as rows are below 2^20.)
    let mut below = vec![NONE; w];
    for (j, dst) in rows.chunks_exact_mut(w).enumerate().rev() {
        let y = (y0 + j) as u32;
        for (b, d) in below.iter_mut().zip(dst) {
            let up = *d;
            if up == y {
                *b = y;
            }
            let to_up = if up == NONE {
                u32::MAX
            } else {
                y.wrapping_sub(up)
            };
            *d = if b.wrapping_sub(y) < to_up { *b } else { up };
        }
    }
    (below, above)
}

/// One parabola of a row's lower envelope: the squared distance `(x' - x)^2 + g2` from column
/// `x'` of the row to the nearest site of column `x`, `g2` the site's squared vertical distance
/// from the row.
#[derive(Clone, Copy)]
struct Parabola {
    x: i64,
    g2: i64,
    /// `x^2 + g2`: two parabolas cross at `(key_2 - key_1) / (2 (x_2 - x_1))`.
    key: i64,
    /// Where the parabola starts being the lowest: the abscissa `num / den` (`den > 0`) of its
    /// crossing with the previous parabola of the envelope; the first one has none.
    num: i64,
    den: i64,
    /// The site, as a window index.
    site: u32,
}

/// Step 2 on window row `y`. On entry `near` holds step 1's rows (nearest occupied in the
/// column within the block) and `above` and `below` the nearest occupied rows of each column
/// outside the block; on return `near` and `dist` hold the row's result. `envelope` is scratch.
fn row(
    envelope: &mut Vec<Parabola>,
    y: usize,
    above: &[u32],
    below: &[u32],
    near: &mut [u32],
    dist: &mut [f32],
) {
    let (w, yy) = (near.len(), y as u32);
    let env = envelope;
    env.clear();
    // The lower envelope over the reals (Felzenszwalb & Huttenlocher), with exact rational
    // crossings. A parabola is dropped when its successor crosses it no later than it starts:
    // on a tie at a column, the parabola of the smaller column stays the lowest there.
    let last = w as i64 - 1;
    let gap = |r: u32| if r == NONE { u32::MAX } else { r.abs_diff(yy) };
    for (x, ((&inside, &a), &b)) in near.iter().zip(above).zip(below).enumerate() {
        // The nearest of the three candidates, which lie in this order down the column; the
        // upper one on a tie.
        let (mut r, mut g) = (a, gap(a));
        if gap(inside) < g {
            (r, g) = (inside, gap(inside));
        }
        if gap(b) < g {
            (r, g) = (b, gap(b));
        }
        if r == NONE {
            continue;
        }
        let (x, g2) = (x as i64, g as i64 * g as i64);
        let mut p = Parabola {
            x,
            g2,
            key: x * x + g2,
            num: 0,
            den: 1,
            site: r * w as u32 + x as u32,
        };
        while let Some(top) = env.last() {
            (p.num, p.den) = (p.key - top.key, 2 * (x - top.x));
            // p crosses top at or before top's start: top is never the lowest.
            if env.len() > 1 && p.num * top.den <= top.num * p.den {
                env.pop();
                continue;
            }
            break;
        }
        // p is the lowest after its crossing: keep it if that is left of the last column.
        if env.is_empty() || p.num < last * p.den {
            env.push(p);
        }
    }
    if env.is_empty() {
        return; // No occupied cell anywhere: NONE (as step 1 left it) and infinity stay.
    }
    // Each parabola's stretch of columns, from the first after its crossing with the previous
    // one (the left one keeps a tie): squared distances, then the roots in one sweep.
    let start = |p: &Parabola| (p.num.div_euclid(p.den) + 1).clamp(0, w as i64) as usize;
    for (k, p) in env.iter().enumerate() {
        let from = if k == 0 { 0 } else { start(p) };
        let to = env.get(k + 1).map_or(w, start);
        if from >= to {
            continue;
        }
        near[from..to].fill(p.site);
        let (dx0, g2) = ((from as i64 - p.x) as i32, p.g2 as f32);
        for (d, dx) in dist[from..to].iter_mut().zip(dx0..) {
            *d = (dx as f32) * (dx as f32) + g2;
        }
    }
    for d in dist {
        *d = d.sqrt();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use grid_core::{Pose2, UNKNOWN};

    /// Brute force over `sites` for cell `(x, y)`: the exact distance and the site the
    /// transform must report (least squared distance, then least column, then least row).
    fn brute(sites: &[(usize, usize)], x: usize, y: usize) -> (f32, (usize, usize)) {
        let d2 = |&(sx, sy): &(usize, usize)| sx.abs_diff(x).pow(2) + sy.abs_diff(y).pow(2);
        let &site = sites.iter().min_by_key(|s| (d2(s), s.0, s.1)).unwrap();
        ((d2(&site) as f32).sqrt(), site)
    }

    /// Distance from site `(ax, ay)` to cell `(x, y)`, computed apart from the transform.
    fn euclid((ax, ay): (usize, usize), x: usize, y: usize) -> f32 {
        ((ax as f32 - x as f32).powi(2) + (ay as f32 - y as f32).powi(2)).sqrt()
    }

    /// Every cell of `t`'s window against brute force: exact distance, an occupied site at
    /// exactly that distance, and the tie rule of the module doc.
    fn check_exact(t: &NearestOccupied, cells: &[u8], w: usize) {
        let sites: Vec<_> = (0..cells.len())
            .filter(|&i| cells[i] == 100)
            .map(|i| (i % w, i / w))
            .collect();
        let (x0, y0, ww, wh) = t.window();
        for y in y0..y0 + wh {
            for x in x0..x0 + ww {
                let (exact, site) = brute(&sites, x, y);
                let ((nx, ny), d) = t.nearest(x, y).unwrap();
                assert!((d - exact).abs() < 1e-4, "({x}, {y}): {d} vs {exact}");
                assert_eq!(t.distance(x, y), d);
                assert_eq!(
                    cells[ny * w + nx],
                    100,
                    "({x}, {y}): the nearest site is a wall"
                );
                assert!((euclid((nx, ny), x, y) - exact).abs() < 1e-4, "({x}, {y})");
                assert_eq!((nx, ny), site, "({x}, {y}): tie rule");
            }
        }
    }

    /// Known cells `(x0, y0, x1, y1)`, the ends exclusive.
    type Window = (usize, usize, usize, usize);
    /// Whether cell `(x, y)` is a wall, given a random number.
    type Sites = dyn Fn(usize, usize, u64) -> bool;

    /// A `w` x `h` grid: cells for which `site` holds are walls, the others free except a
    /// sprinkling of unknown; all unknown outside `known` (x0, y0, x1, y1 exclusive).
    fn random_grid(
        (w, h): (usize, usize),
        known: Window,
        seed: u64,
        site: &Sites,
    ) -> (OccupancyGrid, Vec<u8>) {
        let mut s = seed;
        let mut cells = vec![UNKNOWN; w * h];
        for y in known.1..known.3 {
            for x in known.0..known.2 {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let r = s >> 33;
                cells[y * w + x] = if site(x, y, r) {
                    100
                } else if r.is_multiple_of(11) {
                    UNKNOWN
                } else {
                    0
                };
            }
        }
        // Pin the known window's corners so that it is exactly `known`.
        for (x, y) in [(known.0, known.1), (known.2 - 1, known.3 - 1)] {
            if cells[y * w + x] == UNKNOWN {
                cells[y * w + x] = 0;
            }
        }
        let g = OccupancyGrid::from_cells(w, h, 0.05, Pose2::default(), cells.clone()).unwrap();
        (g, cells)
    }

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
            if (s >> 40).is_multiple_of(29) {
                *cell = 100;
                sites.push((i % w, i / w));
            } else if (s >> 40).is_multiple_of(7) {
                *cell = UNKNOWN;
            }
        }
        let g = OccupancyGrid::from_cells(w, h, 0.05, Pose2::default(), cells).unwrap();
        let t = NearestOccupied::new(&g);
        for y in 0..h {
            for x in 0..w {
                let (exact, _) = brute(&sites, x, y);
                let ((nx, ny), d) = t.nearest(x, y).unwrap();
                assert!((d - exact).abs() < 1e-4, "({x}, {y}): {d} vs {exact}");
                assert!(
                    sites.contains(&(nx, ny)),
                    "({x}, {y}): the nearest site is a wall"
                );
                assert!((euclid((nx, ny), x, y) - exact).abs() < 1e-4, "({x}, {y})");
            }
        }
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
        check_exact(&t, &cells, w);
        // Outside the window: unknown, no wall reported.
        assert!(t.nearest(5, 5).is_none());
        assert_eq!(t.distance(29, 20), f32::INFINITY);
        assert_eq!(t.distance(42, 27), f32::INFINITY);
    }

    #[test]
    fn larger_random_grids_match_brute_force() {
        let size = (300, 211);
        let all = (0, 0, 300, 211);
        let inner = (13, 7, 290, 180); // 277 x 173: offset, and a short last block
        let cases: [(&str, Window, &Sites); 7] = [
            ("sparse", all, &|_, _, r| r % 1500 == 0),
            ("sparse, windowed", inner, &|_, _, r| r % 700 == 0),
            // Whole rows and columns without a site, and many equidistant sites (ties).
            ("lattice", all, &|x, y, _| x % 17 == 5 && y % 13 == 2),
            ("lattice, windowed", inner, &|x, y, _| {
                x % 6 == 0 && y % 4 == 0
            }),
            ("one site", all, &|x, y, _| (x, y) == (211, 3)),
            ("one column", inner, &|x, y, r| {
                x == 150 && (y == 7 || r % 40 == 0)
            }),
            ("one row and a corner", inner, &|x, y, _| {
                y == 100 || (x, y) == (289, 179)
            }),
        ];
        for (seed, (name, known, site)) in cases.into_iter().enumerate() {
            let (g, cells) = random_grid(size, known, seed as u64 + 1, site);
            let t = NearestOccupied::new(&g);
            let (x0, y0, x1, y1) = known;
            assert_eq!(t.window(), (x0, y0, x1 - x0, y1 - y0), "{name}");
            assert!(cells.contains(&100), "{name}");
            check_exact(&t, &cells, size.0);
        }
    }

    #[test]
    fn same_result_on_one_and_two_threads() {
        let (g, _) = random_grid((300, 211), (3, 2, 297, 209), 77, &|x, y, r| {
            r % 200 == 0 || (x % 23 == 0 && y % 19 == 0)
        });
        let on = |n: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .unwrap()
                .install(|| NearestOccupied::new(&g))
        };
        let (one, two) = (on(1), on(2));
        assert_eq!(one.window(), two.window());
        assert_eq!(one.nearest, two.nearest);
        let bits = |t: &NearestOccupied| t.distance.iter().map(|d| d.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&one), bits(&two));
    }
}
