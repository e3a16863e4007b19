//! Seeded worlds: a boolean obstacle raster in world cells (row 0 = top, pixel convention).

use std::f64::consts::TAU;

use glam::DVec2;
use grid_core::{CellState, OccupancyGrid, Pose2};
use rand::RngExt;
use rand_chacha::ChaCha8Rng;

use crate::{Error, Result};

/// Which kind of world to build.
#[derive(Debug, Clone, PartialEq)]
pub enum WorldKind {
    /// A bounded arena with scattered rubble of varied size, shape and orientation (rectangles,
    /// convex polygons, blobs) and broken wall segments; no regular corridors.
    Disaster,
    /// A structured indoor floor: rooms from a binary space partition, corridors, doors and
    /// furniture.
    Indoor,
    /// A given map: its free cells are the world's free space, everything else (occupied and
    /// unknown) is obstacle. `WorldConfig::width`/`height` are ignored.
    Grid(OccupancyGrid),
}

/// How to build a world.
#[derive(Debug, Clone, PartialEq)]
pub struct WorldConfig {
    /// The kind of world. Default: [`WorldKind::Disaster`].
    pub kind: WorldKind,
    /// Width in cells (ignored for [`WorldKind::Grid`]). Default 400.
    pub width: usize,
    /// Height in cells (ignored for [`WorldKind::Grid`]). Default 400.
    pub height: usize,
    /// Cell size in metres, copied into every generated map. Default 0.05.
    pub resolution: f64,
    /// Target fraction of the disaster arena covered by rubble (0..0.5). Default 0.10.
    pub clutter: f64,
}

impl Default for WorldConfig {
    fn default() -> Self {
        Self {
            kind: WorldKind::Disaster,
            width: 400,
            height: 400,
            resolution: 0.05,
            clutter: 0.10,
        }
    }
}

/// A world: a boolean obstacle raster. Cell `(x, y)` is column `x`, row `y` from the top, and
/// covers the square of side 1 centred on `(x, y)` in pixel coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct World {
    width: usize,
    height: usize,
    resolution: f64,
    occupied: Vec<bool>,
}

impl World {
    /// A world from a row-major obstacle raster.
    pub fn from_raster(
        width: usize,
        height: usize,
        resolution: f64,
        occupied: Vec<bool>,
    ) -> Result<Self> {
        if width < 8 || height < 8 {
            return Err(Error::WorldSize { width, height });
        }
        if occupied.len() != width * height {
            return Err(Error::RasterLen {
                got: occupied.len(),
                expected: width * height,
            });
        }
        if !(resolution.is_finite() && resolution > 0.0) {
            return Err(Error::Config(format!(
                "resolution {resolution} is not positive"
            )));
        }
        Ok(Self {
            width,
            height,
            resolution,
            occupied,
        })
    }

    /// Width in cells.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in cells.
    pub fn height(&self) -> usize {
        self.height
    }

    /// Cell size in metres.
    pub fn resolution(&self) -> f64 {
        self.resolution
    }

    /// Row-major obstacle raster.
    pub fn raster(&self) -> &[bool] {
        &self.occupied
    }

    /// Whether cell `(x, y)` is an obstacle; everything outside the raster is.
    #[inline]
    pub fn is_occupied(&self, x: i64, y: i64) -> bool {
        if x < 0 || y < 0 || x >= self.width as i64 || y >= self.height as i64 {
            return true;
        }
        self.occupied[y as usize * self.width + x as usize]
    }

    /// The world as a fully known occupancy grid (obstacle 100 %, free 0 %), origin at zero.
    pub fn to_grid(&self) -> OccupancyGrid {
        let cells = self
            .occupied
            .iter()
            .map(|&o| if o { 100 } else { 0 })
            .collect();
        // Sizes and resolution were validated on construction.
        OccupancyGrid::from_cells(
            self.width,
            self.height,
            self.resolution,
            Pose2::default(),
            cells,
        )
        .expect("validated world")
    }

    /// Number of free cells.
    pub fn free_cells(&self) -> usize {
        self.occupied.iter().filter(|&&o| !o).count()
    }

    /// Build a world from a config, deterministically from `rng`.
    pub fn generate(config: &WorldConfig, rng: &mut ChaCha8Rng) -> Result<Self> {
        if !(config.resolution.is_finite() && config.resolution > 0.0) {
            return Err(Error::Config(format!(
                "world resolution {} is not positive",
                config.resolution
            )));
        }
        match &config.kind {
            WorldKind::Grid(grid) => {
                let occupied = (0..grid.height())
                    .flat_map(|y| (0..grid.width()).map(move |x| (x, y)))
                    .map(|(x, y)| grid.state(x, y) != CellState::Free)
                    .collect();
                Self::from_raster(grid.width(), grid.height(), grid.resolution(), occupied)
            }
            kind => {
                let (w, h) = (config.width, config.height);
                if !(24..=20_000).contains(&w) || !(24..=20_000).contains(&h) {
                    return Err(Error::WorldSize {
                        width: w,
                        height: h,
                    });
                }
                if !(0.0..=0.5).contains(&config.clutter) {
                    return Err(Error::Config(format!(
                        "clutter {} outside 0..=0.5",
                        config.clutter
                    )));
                }
                let mut canvas = Canvas::new(w, h);
                if *kind == WorldKind::Disaster {
                    disaster(&mut canvas, config.clutter, rng);
                } else {
                    indoor(&mut canvas, rng);
                }
                Self::from_raster(w, h, config.resolution, canvas.cells)
            }
        }
    }
}

/// A drawing surface for the generators.
struct Canvas {
    w: usize,
    h: usize,
    cells: Vec<bool>,
    /// Cells that must stay free (doorways), so furniture does not block them.
    protected: Vec<bool>,
}

impl Canvas {
    fn new(w: usize, h: usize) -> Self {
        Self {
            w,
            h,
            cells: vec![false; w * h],
            protected: vec![false; w * h],
        }
    }

    fn set(&mut self, x: i64, y: i64, v: bool) {
        if x >= 0 && y >= 0 && (x as usize) < self.w && (y as usize) < self.h {
            let i = y as usize * self.w + x as usize;
            if !v || !self.protected[i] {
                self.cells[i] = v;
            }
        }
    }

    fn rect(&mut self, x0: i64, y0: i64, x1: i64, y1: i64, v: bool) {
        for y in y0.min(y1)..=y0.max(y1) {
            for x in x0.min(x1)..=x0.max(x1) {
                self.set(x, y, v);
            }
        }
    }

    fn protect(&mut self, x0: i64, y0: i64, x1: i64, y1: i64) {
        for y in y0.min(y1).max(0)..=y0.max(y1).min(self.h as i64 - 1) {
            for x in x0.min(x1).max(0)..=x0.max(x1).min(self.w as i64 - 1) {
                self.protected[y as usize * self.w + x as usize] = true;
            }
        }
    }

    /// Fill a simple polygon (even-odd rule, cell centres).
    fn polygon(&mut self, pts: &[DVec2]) {
        let (mut lo, mut hi) = (DVec2::splat(f64::MAX), DVec2::splat(f64::MIN));
        for p in pts {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
        let mut xs = Vec::new();
        for y in lo.y.floor() as i64..=hi.y.ceil() as i64 {
            let yc = y as f64;
            xs.clear();
            for (i, a) in pts.iter().enumerate() {
                let b = pts[(i + 1) % pts.len()];
                if (a.y <= yc) != (b.y <= yc) {
                    xs.push(a.x + (yc - a.y) / (b.y - a.y) * (b.x - a.x));
                }
            }
            xs.sort_by(f64::total_cmp);
            for pair in xs.chunks_exact(2) {
                for x in pair[0].ceil() as i64..=pair[1].floor() as i64 {
                    self.set(x, y, true);
                }
            }
        }
    }

    /// A thick straight segment.
    fn segment(&mut self, a: DVec2, b: DVec2, thickness: f64) {
        let d = b - a;
        let n = d.perp().normalize_or_zero() * (thickness * 0.5);
        self.polygon(&[a + n, b + n, b - n, a - n]);
        // Thin segments may miss every cell centre; stamp the centre line too.
        let steps = d.length().ceil() as usize * 2 + 1;
        for i in 0..=steps {
            let p = a + d * (i as f64 / steps as f64);
            self.set(p.x.round() as i64, p.y.round() as i64, true);
        }
    }

    fn border(&mut self, t: i64) {
        let (w, h) = (self.w as i64, self.h as i64);
        self.rect(0, 0, w - 1, t - 1, true);
        self.rect(0, h - t, w - 1, h - 1, true);
        self.rect(0, 0, t - 1, h - 1, true);
        self.rect(w - t, 0, w - 1, h - 1, true);
    }
}

fn disaster(c: &mut Canvas, clutter: f64, rng: &mut ChaCha8Rng) {
    let (w, h) = (c.w as f64, c.h as f64);
    // Feature sizes scale with the arena so a large world is not just a sea of tiny pebbles.
    let s = (w.min(h) / 150.0).max(0.35);
    c.border(2);
    let area = w * h;
    let mut covered = 0.0;
    let mut guard = 0;
    while covered < clutter * area && guard < 100_000 {
        guard += 1;
        let centre = DVec2::new(rng.random_range(0.0..w), rng.random_range(0.0..h));
        let angle = rng.random_range(0.0..TAU);
        let rot = DVec2::from_angle(angle);
        match rng.random_range(0..10u32) {
            // Rotated rectangles: slabs, vehicles, collapsed furniture.
            0..=2 => {
                let hw = rng.random_range(1.0..7.0) * s;
                let hh = rng.random_range(0.7..4.0) * s;
                let pts: Vec<_> = [(-hw, -hh), (hw, -hh), (hw, hh), (-hw, hh)]
                    .iter()
                    .map(|&(x, y)| centre + rot.rotate(DVec2::new(x, y)))
                    .collect();
                c.polygon(&pts);
                covered += 4.0 * hw * hh;
            }
            // Convex polygons.
            3..=4 => {
                let r = rng.random_range(1.5..6.0) * s;
                let n = rng.random_range(3..8usize);
                let mut angles: Vec<f64> = (0..n).map(|_| rng.random_range(0.0..TAU)).collect();
                angles.sort_by(f64::total_cmp);
                let pts: Vec<_> = angles
                    .iter()
                    .map(|&a| centre + DVec2::from_angle(a) * r * rng.random_range(0.7..1.0))
                    .collect();
                c.polygon(&pts);
                covered += 1.6 * r * r;
            }
            // Blobs: a radius that wobbles with a few harmonics.
            5..=6 => {
                let r = rng.random_range(1.5..7.0) * s;
                let harm: Vec<(f64, f64)> = (2..6)
                    .map(|_| (rng.random_range(0.0..0.25), rng.random_range(0.0..TAU)))
                    .collect();
                let pts: Vec<_> = (0..40)
                    .map(|i| {
                        let a = TAU * i as f64 / 40.0;
                        let k = harm
                            .iter()
                            .enumerate()
                            .map(|(j, (amp, ph))| amp * ((j as f64 + 2.0) * a + ph).sin())
                            .sum::<f64>();
                        centre + DVec2::from_angle(a) * r * (1.0 + k).max(0.3)
                    })
                    .collect();
                c.polygon(&pts);
                covered += 3.0 * r * r;
            }
            // Broken walls: a long thin segment with gaps, slightly kinked.
            7..=8 => {
                let len = rng.random_range(15.0..45.0) * s;
                let thick = rng.random_range(1.0..2.2);
                let mut p = centre - rot * (len * 0.5);
                let mut dir = rot;
                let mut done = 0.0;
                while done < len {
                    let piece = rng.random_range(3.0..14.0) * s;
                    let q = p + dir * piece;
                    if rng.random_bool(0.75) {
                        c.segment(p, q, thick);
                        covered += piece * thick;
                    }
                    p = q;
                    done += piece;
                    dir = dir.rotate(DVec2::from_angle(rng.random_range(-0.15..0.15)));
                }
            }
            // Small rubble pieces.
            _ => {
                for _ in 0..rng.random_range(3..10) {
                    let p = centre
                        + DVec2::new(rng.random_range(-6.0..6.0), rng.random_range(-6.0..6.0)) * s;
                    let r = rng.random_range(0.5..1.6) * s.sqrt();
                    let a = rng.random_range(0.0..TAU);
                    let pts: Vec<_> = (0..5)
                        .map(|i| p + DVec2::from_angle(a + TAU * i as f64 / 5.0) * r)
                        .collect();
                    c.polygon(&pts);
                    covered += 2.0 * r * r;
                }
            }
        }
    }
}

/// A rectangle of the floor plan, in cells, inclusive interior bounds.
#[derive(Clone, Copy)]
struct Rect {
    x0: i64,
    y0: i64,
    x1: i64,
    y1: i64,
}

fn indoor(c: &mut Canvas, rng: &mut ChaCha8Rng) {
    let (w, h) = (c.w as i64, c.h as i64);
    let scale = (w.min(h) as f64 / 150.0).max(0.4);
    let wall = if scale > 3.0 { 3 } else { 2 };
    let min_room = ((14.0 * scale) as i64).max(10);
    let corridor = ((6.0 * scale) as i64).max(5);
    let door = ((5.0 * scale) as i64).max(4);
    c.border(wall);
    let mut rooms = Vec::new();
    split(
        c,
        Rect {
            x0: wall,
            y0: wall,
            x1: w - 1 - wall,
            y1: h - 1 - wall,
        },
        0,
        &Params {
            wall,
            min_room,
            corridor,
            door,
        },
        rng,
        &mut rooms,
    );
    for r in rooms {
        furnish(c, r, scale, rng);
    }
}

struct Params {
    wall: i64,
    min_room: i64,
    corridor: i64,
    door: i64,
}

/// Binary space partition: split along the longer side with a wall (deep levels) or a corridor
/// between two walls (the first two levels), each wall pierced by doors.
fn split(
    c: &mut Canvas,
    r: Rect,
    depth: u32,
    p: &Params,
    rng: &mut ChaCha8Rng,
    rooms: &mut Vec<Rect>,
) {
    let (rw, rh) = (r.x1 - r.x0 + 1, r.y1 - r.y0 + 1);
    let with_corridor = depth < 2;
    let gap = if with_corridor {
        p.corridor + 2 * p.wall
    } else {
        p.wall
    };
    let vertical = if rw > rh * 5 / 4 {
        true
    } else if rh > rw * 5 / 4 {
        false
    } else {
        rng.random_bool(0.5)
    };
    let span = if vertical { rw } else { rh };
    if span < 2 * p.min_room + gap || (depth > 2 && rng.random_bool(0.15)) {
        rooms.push(r);
        return;
    }
    let at = rng.random_range(p.min_room..=span - p.min_room - gap);
    // Wall bands (absolute coordinate ranges along the split axis).
    let origin = if vertical { r.x0 } else { r.y0 };
    let bands: Vec<(i64, i64)> = if with_corridor {
        vec![
            (origin + at, origin + at + p.wall - 1),
            (origin + at + gap - p.wall, origin + at + gap - 1),
        ]
    } else {
        vec![(origin + at, origin + at + p.wall - 1)]
    };
    let (lo, hi) = if vertical { (r.y0, r.y1) } else { (r.x0, r.x1) };
    for &(b0, b1) in &bands {
        if vertical {
            c.rect(b0, lo, b1, hi, true);
        } else {
            c.rect(lo, b0, hi, b1, true);
        }
        // Doors: one per ~3 rooms' length along a corridor wall, at least one.
        let len = hi - lo + 1;
        let n_doors = if with_corridor {
            (len / (p.min_room * 2)).max(1)
        } else {
            1
        };
        for k in 0..n_doors {
            let seg = len / n_doors;
            let d_lo = lo + k * seg + 1;
            let d_hi = (lo + (k + 1) * seg - p.door - 1).max(d_lo);
            let d = rng.random_range(d_lo..=d_hi);
            // Keep a free zone on both sides of the doorway so furniture cannot block it.
            let reach = p.door;
            if vertical {
                c.rect(b0, d, b1, d + p.door - 1, false);
                c.protect(b0 - reach, d, b1 + reach, d + p.door - 1);
            } else {
                c.rect(d, b0, d + p.door - 1, b1, false);
                c.protect(d, b0 - reach, d + p.door - 1, b1 + reach);
            }
        }
    }
    if with_corridor {
        // Keep the corridor itself free of furniture.
        let (c0, c1) = (origin + at + p.wall, origin + at + gap - p.wall - 1);
        if vertical {
            c.protect(c0, lo, c1, hi);
        } else {
            c.protect(lo, c0, hi, c1);
        }
    }
    let (a, b) = if vertical {
        (
            Rect {
                x1: origin + at - 1,
                ..r
            },
            Rect {
                x0: origin + at + gap,
                ..r
            },
        )
    } else {
        (
            Rect {
                y1: origin + at - 1,
                ..r
            },
            Rect {
                y0: origin + at + gap,
                ..r
            },
        )
    };
    split(c, a, depth + 1, p, rng, rooms);
    split(c, b, depth + 1, p, rng, rooms);
}

/// Tables, shelves along walls and a few small items; protected doorway zones stay free.
fn furnish(c: &mut Canvas, r: Rect, scale: f64, rng: &mut ChaCha8Rng) {
    let (rw, rh) = (r.x1 - r.x0 + 1, r.y1 - r.y0 + 1);
    let clear = ((3.0 * scale) as i64).max(3);
    for _ in 0..rng.random_range(1..4) {
        let fw = (rng.random_range(2.0..6.0) * scale) as i64 + 1;
        let fh = (rng.random_range(2.0..4.0) * scale) as i64 + 1;
        if rng.random_bool(0.5) {
            // Shelf against a wall.
            let along = rng.random_range(0..4u32);
            let (x0, y0) = match along {
                0 => (r.x0 + rng.random_range(0..(rw - fw).max(1)), r.y0),
                1 => (r.x0 + rng.random_range(0..(rw - fw).max(1)), r.y1 - fh + 1),
                2 => (r.x0, r.y0 + rng.random_range(0..(rh - fh).max(1))),
                _ => (r.x1 - fw + 1, r.y0 + rng.random_range(0..(rh - fh).max(1))),
            };
            if along < 2 {
                c.rect(x0, y0, x0 + fw - 1, y0 + fh / 2, true);
            } else {
                c.rect(x0, y0, x0 + fh / 2, y0 + fw - 1, true);
            }
        } else if rw > fw + 2 * clear && rh > fh + 2 * clear {
            // Table in the room, away from the walls so the room stays passable.
            let x0 = r.x0 + clear + rng.random_range(0..(rw - fw - 2 * clear).max(1));
            let y0 = r.y0 + clear + rng.random_range(0..(rh - fh - 2 * clear).max(1));
            c.rect(x0, y0, x0 + fw - 1, y0 + fh - 1, true);
        }
    }
}
