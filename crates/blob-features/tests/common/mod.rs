//! Helpers shared by the integration tests, the examples and the benches: rasterised analytic
//! shapes, a BFS flood-fill labelling oracle and a synthetic obstacle map generator.
#![allow(dead_code)]

use std::collections::VecDeque;

use blob_features::Connectivity;
use grid_core::{OccupancyGrid, Pose2};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Flood-fill labelling (BFS, seeds in raster order): the oracle for the labeller.
pub fn bfs_labels(mask: &[u8], w: usize, h: usize, conn: Connectivity) -> (Vec<u32>, usize) {
    let mut labels = vec![0u32; w * h];
    let mut n = 0u32;
    let mut queue = VecDeque::new();
    let offsets: &[(isize, isize)] = match conn {
        Connectivity::Four => &[(1, 0), (-1, 0), (0, 1), (0, -1)],
        Connectivity::Eight => &[
            (1, 0),
            (-1, 0),
            (0, 1),
            (0, -1),
            (1, 1),
            (1, -1),
            (-1, 1),
            (-1, -1),
        ],
    };
    for start in 0..w * h {
        if mask[start] == 0 || labels[start] != 0 {
            continue;
        }
        n += 1;
        labels[start] = n;
        queue.push_back(start);
        while let Some(i) = queue.pop_front() {
            let (x, y) = ((i % w) as isize, (i / w) as isize);
            for &(dx, dy) in offsets {
                let (nx, ny) = (x + dx, y + dy);
                if nx < 0 || ny < 0 || nx >= w as isize || ny >= h as isize {
                    continue;
                }
                let j = ny as usize * w + nx as usize;
                if mask[j] != 0 && labels[j] == 0 {
                    labels[j] = n;
                    queue.push_back(j);
                }
            }
        }
    }
    (labels, n as usize)
}

/// An analytic shape, centred at `(cx, cy)`, major axis at `angle` (pixel convention).
#[derive(Debug, Clone, Copy)]
pub enum Analytic {
    /// Rectangle of half-extents `a` (along the axis) and `b`.
    Rect {
        cx: f64,
        cy: f64,
        a: f64,
        b: f64,
        angle: f64,
    },
    /// Ellipse of semi-axes `a` and `b`.
    Ellipse {
        cx: f64,
        cy: f64,
        a: f64,
        b: f64,
        angle: f64,
    },
    /// Right triangle with legs `a` along the axis and `b` across: not centrally symmetric.
    Triangle {
        cx: f64,
        cy: f64,
        a: f64,
        b: f64,
        angle: f64,
    },
}

impl Analytic {
    /// Whether the pixel centre `(x, y)` is inside.
    pub fn contains(&self, x: f64, y: f64) -> bool {
        let (cx, cy, a, b, angle) = self.params();
        let (s, c) = angle.sin_cos();
        let (dx, dy) = (x - cx, y - cy);
        let (u, v) = (c * dx + s * dy, -s * dx + c * dy);
        match self {
            Self::Rect { .. } => u.abs() <= a && v.abs() <= b,
            Self::Ellipse { .. } => (u / a).powi(2) + (v / b).powi(2) <= 1.0,
            // Vertices (0,0), (a,0), (0,b) in the local frame, shifted so the centroid is 0.
            Self::Triangle { .. } => {
                let (u, v) = (u + a / 3.0, v + b / 3.0);
                u >= 0.0 && v >= 0.0 && u / a + v / b <= 1.0
            }
        }
    }

    /// `(cx, cy, a, b, angle)`.
    pub fn params(&self) -> (f64, f64, f64, f64, f64) {
        match *self {
            Self::Rect {
                cx,
                cy,
                a,
                b,
                angle,
            }
            | Self::Ellipse {
                cx,
                cy,
                a,
                b,
                angle,
            }
            | Self::Triangle {
                cx,
                cy,
                a,
                b,
                angle,
            } => (cx, cy, a, b, angle),
        }
    }

    /// True area.
    pub fn area(&self) -> f64 {
        let (_, _, a, b, _) = self.params();
        match self {
            Self::Rect { .. } => 4.0 * a * b,
            Self::Ellipse { .. } => std::f64::consts::PI * a * b,
            Self::Triangle { .. } => 0.5 * a * b,
        }
    }

    /// Radius of a disc around the centre that contains the shape.
    pub fn radius(&self) -> f64 {
        let (_, _, a, b, _) = self.params();
        a.hypot(b)
    }

    /// Set every pixel inside to `value`.
    pub fn paint(&self, cells: &mut [u8], w: usize, h: usize, value: u8) {
        let (cx, cy, ..) = self.params();
        let r = self.radius().ceil() as isize + 1;
        for y in (cy as isize - r).max(0)..(cy as isize + r + 1).min(h as isize) {
            for x in (cx as isize - r).max(0)..(cx as isize + r + 1).min(w as isize) {
                if self.contains(x as f64, y as f64) {
                    cells[y as usize * w + x as usize] = value;
                }
            }
        }
    }
}

/// A `w x h` free map with one occupied shape per entry of `shapes`.
pub fn grid_with(shapes: &[Analytic], w: usize, h: usize) -> OccupancyGrid {
    let mut cells = vec![0u8; w * h];
    for s in shapes {
        s.paint(&mut cells, w, h, 100);
    }
    OccupancyGrid::from_cells(w, h, 0.05, Pose2::default(), cells).unwrap()
}

/// Scatter `count` non-overlapping shapes of varied kind, size (semi-axes 3..25 px) and
/// elongation inside the disc of radius `0.45 * min(w, h)` around the map centre (so that a
/// rotation about the centre keeps them on the canvas). Deterministic for a seed.
pub fn scatter(w: usize, h: usize, count: usize, seed: u64) -> Vec<Analytic> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (mx, my) = (w as f64 / 2.0, h as f64 / 2.0);
    let rmax = 0.45 * w.min(h) as f64;
    let mut out: Vec<Analytic> = Vec::new();
    let mut tries = 0;
    while out.len() < count && tries < count * 200 {
        tries += 1;
        let a = rng.random_range(4.0..25.0);
        let b = a / rng.random_range(1.0..6.0f64);
        let b = b.max(2.0);
        let angle = rng.random_range(-std::f64::consts::PI..std::f64::consts::PI);
        let rr = rmax * rng.random::<f64>().sqrt();
        let phi = rng.random_range(0.0..std::f64::consts::TAU);
        let (cx, cy) = (mx + rr * phi.cos(), my + rr * phi.sin());
        let shape = match rng.random_range(0..3) {
            0 => Analytic::Rect {
                cx,
                cy,
                a,
                b,
                angle,
            },
            1 => Analytic::Ellipse {
                cx,
                cy,
                a,
                b,
                angle,
            },
            _ => Analytic::Triangle {
                cx,
                cy,
                a: 2.0 * a,
                b: 2.0 * b,
                angle,
            },
        };
        if (cx - mx).hypot(cy - my) + shape.radius() > rmax {
            continue;
        }
        // Keep a clear gap so a 1 px closing cannot merge neighbours.
        if out.iter().all(|o| {
            let (ox, oy, ..) = o.params();
            (ox - cx).hypot(oy - cy) > o.radius() + shape.radius() + 4.0
        }) {
            out.push(shape);
        }
    }
    out
}

/// A random `0`/`1` mask with the given density, deterministic for a seed.
pub fn random_mask(w: usize, h: usize, density: f64, seed: u64) -> Vec<u8> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..w * h)
        .map(|_| u8::from(rng.random::<f64>() < density))
        .collect()
}

/// A synthetic floor-plan obstacle mask: a grid of rooms (walls 2 px thick, a doorway in each
/// wall) with furniture-like rectangles inside; about 6 % of the pixels are obstacles, close to
/// the share in the shared real maps. Deterministic for a seed.
pub fn floor_plan(w: usize, h: usize, room: usize, seed: u64) -> Vec<u8> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut m = vec![0u8; w * h];
    let door = room / 4;
    for y in 0..h {
        for x in 0..w {
            let (rx, ry) = (x % room, y % room);
            let wall = (rx < 2 && !(ry > room / 2 && ry < room / 2 + door))
                || (ry < 2 && !(rx > room / 3 && rx < room / 3 + door));
            if wall {
                m[y * w + x] = 1;
            }
        }
    }
    let rooms = (w / room + 1) * (h / room + 1);
    for _ in 0..rooms * 3 {
        let (bw, bh) = (rng.random_range(3..room / 4), rng.random_range(3..room / 4));
        let (x0, y0) = (rng.random_range(0..w - bw), rng.random_range(0..h - bh));
        for y in y0..y0 + bh {
            m[y * w + x0..y * w + x0 + bw].fill(1);
        }
    }
    m
}
